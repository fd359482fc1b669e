/* Light fields from raw sensor mosaics (lf_source.h): the microlens grid
 * from a white mosaic, and demosaicing that keeps to each microlens image. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_source.h"

int lf_lightfield_lens_labels(const lf_lightfield_layout *l, int w, int h, int **labels, lf_error *err)
{
    *labels = malloc(sizeof **labels * (size_t)w * h);
    if (!*labels)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for %dx%d microlens labels", w, h);
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    double c = cos(l->rotation_rad), s = sin(l->rotation_rad), p = l->pitch_px, row = p * (hex ? sqrt(3.0) / 2 : 1.0);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            /* lattice coordinates (the inverse of decode's rotation), then the
             * nearest of the neighbouring centres: the microlens's Voronoi cell */
            double dx = x + 0.5 - l->offset_px[0], dy = y + 0.5 - l->offset_px[1];
            double lx = c * dx + s * dy, ly = -s * dx + c * dy;
            int j0 = (int)floor(ly / row + 0.5), best = -1;
            double best_d = INFINITY;
            for (int j = j0 - 1; j <= j0 + 1; j++) {
                double sx = hex && (j & 1) ? p / 2 : 0;
                int i0 = (int)floor((lx - sx) / p + 0.5);
                for (int i = i0 - 1; i <= i0 + 1; i++) {
                    double ex = lx - (i * p + sx), ey = ly - j * row, d = ex * ex + ey * ey;
                    if (d < best_d) {
                        best_d = d;
                        best = i >= 0 && j >= 0 && i < l->lens_x && j < l->lens_y ? j * l->lens_x + i : -1;
                    }
                }
            }
            (*labels)[(size_t)y * w + x] = best;
        }
    return LF_OK;
}

int lf_lightfield_mosaic_grey(const lf_image *raw, const lf_raw_info *ri, lf_image *grey, lf_error *err)
{
    double sum[3] = {0}, n[3] = {0};
    for (int y = 0; y < raw->height; y++)
        for (int x = 0; x < raw->width; x++) {
            int c = lf_cfa_color(ri->cfa, x, y);
            sum[c] += raw->data[(size_t)y * raw->width + x] - ri->black_level, n[c]++;
        }
    if (lf_image_alloc(grey, raw->width, raw->height, 3, err))
        return err->code;
    for (int y = 0; y < raw->height; y++)
        for (int x = 0; x < raw->width; x++) {
            int c = lf_cfa_color(ri->cfa, x, y);
            double mean = n[c] > 0 ? sum[c] / n[c] : 0;
            float v = mean > 0 ? (float)((raw->data[(size_t)y * raw->width + x] - ri->black_level) / mean) : 0.f;
            float *o = lf_image_px(grey, x, y);
            o[0] = o[1] = o[2] = v;
        }
    return LF_OK;
}

int lf_lightfield_develop_mosaic(const lf_image *raw, const lf_raw_info *ri, const lf_lightfield_layout *l,
                                 lf_image *rgb, lf_error *err)
{
    int *labels = NULL;
    int rc = lf_lightfield_lens_labels(l, raw->width, raw->height, &labels, err);
    if (rc)
        return rc;
    lf_develop_opts o = {.mask = labels};
    rc = lf_raw_develop(raw, ri, &o, rgb, err);
    free(labels);
    return rc;
}
