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

/* The white image with each microlens image flattened: every pixel divided
 * by FLAT_LEVEL times the brightest pixel within a pitch of it (a separable
 * running maximum), clamped to 1.  What remains is the aperture images'
 * outline, which the lens geometry places, without the shading inside them
 * (cos^4 falloff, vignetting) that pulls the lattice's Fourier phases off
 * axis.  The level is low so that the outline is the disk's rim: on
 * scenes/sensor/plenoptic-iso100.pbrt's white image the pitch comes out
 * 8.99999 px for 9 (8.98959 unflattened); 0.3: 8.99973, 0.5: 8.99889. */
#define FLAT_LEVEL 0.2

static int flatten_white(const lf_image *w, int r, lf_image *out, lf_error *err)
{
    int W = w->width, H = w->height;
    float *lum = malloc(sizeof *lum * (size_t)W * H), *rowmax = malloc(sizeof *rowmax * (size_t)W * H);
    if (!lum || !rowmax || lf_image_alloc(out, W, H, 3, err)) {
        free(lum), free(rowmax);
        return err && err->code ? err->code : lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const float *p = w->data + i * w->channels;
        float v = w->channels >= 3 ? (p[0] + p[1] + p[2]) / 3 : p[0];
        lum[i] = isfinite(v) ? v : 0.f;
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float m = 0;
            for (int k = x - r < 0 ? 0 : x - r; k <= x + r && k < W; k++)
                m = fmaxf(m, lum[(size_t)y * W + k]);
            rowmax[(size_t)y * W + x] = m;
        }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float m = 0;
            for (int k = y - r < 0 ? 0 : y - r; k <= y + r && k < H; k++)
                m = fmaxf(m, rowmax[(size_t)k * W + x]);
            float v = m > 0 ? fminf(lum[(size_t)y * W + x] / (float)(FLAT_LEVEL * m), 1.f) : 0.f;
            float *o = lf_image_px(out, x, y);
            o[0] = o[1] = o[2] = v;
        }
    free(lum), free(rowmax);
    return LF_OK;
}

int lf_lightfield_calibrate_white(const lf_image *white, lf_lightfield_layout *lay, lf_error *err)
{
    lf_lightfield_layout first = *lay; /* a grid kind the caller fixed holds for both passes */
    int rc = lf_lightfield_calibrate(white, &first, err);
    if (rc)
        return rc;
    lf_image flat;
    if ((rc = flatten_white(white, (int)ceil(first.pitch_px), &flat, err)))
        return rc;
    rc = lf_lightfield_calibrate(&flat, lay, err);
    lf_image_free(&flat);
    return rc;
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
