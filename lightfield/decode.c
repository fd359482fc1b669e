/* Decoding raw images into L(u, v, s, t): camera-array tiles and plenoptic
 * microlens images (square or hex grids, any pitch and rotation). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_lightfield.h"

int lf_lightfield_alloc(lf_lightfield *lf, int nu, int nv, int ns, int nt, lf_error *err)
{
    memset(lf, 0, sizeof *lf);
    if (nu < 1 || nv < 1 || ns < 1 || nt < 1)
        return lf_error_set(err, LF_ERR_PARAM, "empty light field %d x %d views of %d x %d", nu, nv, ns, nt);
    /* 2^31 samples (24 GiB of RGB floats) is more than any raw can hold;
     * a bigger request comes from a corrupt layout, not from data. */
    double samples = (double)nu * nv * ns * nt;
    if (samples > 2147483648.0)
        return lf_error_set(err, LF_ERR_PARAM, "light field of %d x %d views of %d x %d is too large", nu, nv, ns, nt);
    size_t n = (size_t)nu * nv * ns * nt * 3;
    lf->data = calloc(n, sizeof(float));
    if (!lf->data)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for a %d x %d x %d x %d light field", nu, nv, ns, nt);
    lf->nu = nu, lf->nv = nv, lf->ns = ns, lf->nt = nt;
    lf->disp_v_per_u = 1.0;
    return LF_OK;
}

void lf_lightfield_free(lf_lightfield *lf)
{
    if (!lf)
        return;
    free(lf->data);
    free(lf->valid);
    free(lf->half);
    free(lf->view_shift);
    free(lf->view_gain);
    memset(lf, 0, sizeof *lf);
}

static int ensure_valid(lf_lightfield *lf, lf_error *err)
{
    if (lf->valid)
        return LF_OK;
    size_t n = (size_t)lf->nu * lf->nv * lf->ns * lf->nt;
    lf->valid = malloc(n * sizeof(float));
    if (!lf->valid)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the validity mask");
    for (size_t i = 0; i < n; i++)
        lf->valid[i] = 1.f;
    return LF_OK;
}

/* RGB of raw pixel (x, y); grey images replicate their one channel. */
static inline void raw_rgb(const lf_image *raw, int x, int y, float c[3])
{
    const float *p = lf_image_px(raw, x, y);
    if (raw->channels >= 3)
        c[0] = p[0], c[1] = p[1], c[2] = p[2];
    else
        c[0] = c[1] = c[2] = p[0];
}

/* Bilinear sample at continuous pixel coordinates (centres at +0.5).
 * Returns 0 when the footprint leaves the image or touches a non-finite value. */
static int raw_bilinear(const lf_image *raw, double px, double py, float out[3])
{
    double xi = px - 0.5, yi = py - 0.5;
    if (!(xi >= -1e-9 && yi >= -1e-9 && xi <= raw->width - 1 + 1e-9 && yi <= raw->height - 1 + 1e-9))
        return 0;
    int x0 = (int)floor(xi), y0 = (int)floor(yi);
    if (x0 > raw->width - 1)
        x0 = raw->width - 1;
    if (y0 > raw->height - 1)
        y0 = raw->height - 1;
    if (x0 < 0)
        x0 = 0;
    if (y0 < 0)
        y0 = 0;
    float fx = (float)(xi - x0), fy = (float)(yi - y0);
    if (fx < 0.f)
        fx = 0.f;
    if (fy < 0.f)
        fy = 0.f;
    int x1 = x0 + 1 < raw->width ? x0 + 1 : x0, y1 = y0 + 1 < raw->height ? y0 + 1 : y0;
    float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
    out[0] = out[1] = out[2] = 0.f;
    for (int k = 0; k < 4; k++) {
        if (w[k] == 0.f)
            continue;
        float c[3];
        raw_rgb(raw, xs[k], ys[k], c);
        for (int ch = 0; ch < 3; ch++) {
            if (!isfinite(c[ch]))
                return 0;
            out[ch] += w[k] * c[ch];
        }
    }
    return 1;
}

static int decode_camera_array(const lf_image *raw, const lf_lightfield_layout *l, lf_lightfield *lf, lf_error *err)
{
    if (lf_lightfield_alloc(lf, l->cams_x, l->cams_y, l->tile_w, l->tile_h, err))
        return err ? err->code : LF_ERR_NOMEM;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            float *v = lf_lightfield_view(lf, iu, iv);
            for (int t = 0; t < lf->nt; t++)
                for (int s = 0; s < lf->ns; s++) {
                    float c[3];
                    raw_rgb(raw, iu * l->tile_w + s, iv * l->tile_h + t, c);
                    float *o = v + ((size_t)t * lf->ns + s) * 3;
                    int bad = !isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2]);
                    if (bad) {
                        if (ensure_valid(lf, err))
                            return err ? err->code : LF_ERR_NOMEM;
                        lf->valid[((size_t)(iv * lf->nu + iu) * lf->nt + t) * lf->ns + s] = 0.f;
                        lf->missing++;
                        c[0] = c[1] = c[2] = 0.f;
                    }
                    o[0] = c[0], o[1] = c[1], o[2] = c[2];
                }
        }
    return LF_OK;
}

int lf_lightfield_plenoptic_views(const lf_lightfield_layout *l)
{
    return 2 * (int)floor((l->pitch_px - 1) / 2) + 1;
}

/* Samples every microlens (i, j) at centre - (u, v) for each view: the result
 * is indexed by lens (lens_x x lens_y), one validity flag per sample. */
static int decode_lenses(const lf_image *raw, const lf_lightfield_layout *l, lf_lightfield *lf, lf_error *err)
{
    /* A layout must fit its raw: the views of a lens come from its own
     * pixels, so views x lenses cannot much exceed the raw's pixel count. */
    double lens_px = l->pitch_px * l->pitch_px * (double)l->lens_x * l->lens_y;
    if (l->pitch_px > 2.0 * (raw->width > raw->height ? raw->width : raw->height) ||
        lens_px > 16.0 * ((double)raw->width + l->pitch_px) * ((double)raw->height + l->pitch_px))
        return lf_error_set(err, LF_ERR_PARAM,
                            "microlens layout (%d x %d lenses of pitch %g px) does not fit the %d x %d raw",
                            l->lens_x, l->lens_y, l->pitch_px, raw->width, raw->height);
    int n = lf_lightfield_plenoptic_views(l), half = n / 2;
    if (lf_lightfield_alloc(lf, n, n, l->lens_x, l->lens_y, err) || ensure_valid(lf, err))
        return err ? err->code : LF_ERR_NOMEM;
    double c = cos(l->rotation_rad), s = sin(l->rotation_rad);
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    double row = l->pitch_px * (hex ? sqrt(3.0) / 2 : 1.0);
    for (int j = 0; j < l->lens_y; j++)
        for (int i = 0; i < l->lens_x; i++) {
            double lx = i * l->pitch_px + (hex && (j & 1) ? l->pitch_px / 2 : 0), ly = j * row;
            /* the ordinary rotation matrix applied to pixel coordinates */
            double cx = l->offset_px[0] + c * lx - s * ly, cy = l->offset_px[1] + s * lx + c * ly;
            for (int iv = 0; iv < n; iv++)
                for (int iu = 0; iu < n; iu++) {
                    /* pixel offset (du, dv) sees the aperture at (du, -dv) (camera space, y
                     * up; docs/lightfield-format.md): view +u (right) is du > 0, view +v
                     * (down, camera -y) is dv > 0 */
                    float rgb[3];
                    size_t idx = ((size_t)(iv * n + iu) * lf->nt + j) * lf->ns + i;
                    if (raw_bilinear(raw, cx + (iu - half), cy + (iv - half), rgb)) {
                        memcpy(lf->data + idx * 3, rgb, sizeof rgb);
                    } else {
                        lf->valid[idx] = 0.f;
                    }
                }
        }
    return LF_OK;
}

/* Hex rows (odd rows shifted by half a pitch, rows sqrt(3)/2 pitch apart)
 * resampled to a square grid of one pitch: linear along each row, then
 * linear between rows (exact for fields linear in position). */
static int hex_to_rect(const lf_lightfield *h, lf_lightfield *r, lf_error *err)
{
    int nt = (int)floor((h->nt - 1) * sqrt(3.0) / 2 + 1e-9) + 1;
    if (lf_lightfield_alloc(r, h->nu, h->nv, h->ns, nt, err) || ensure_valid(r, err))
        return err ? err->code : LF_ERR_NOMEM;
    const double row = sqrt(3.0) / 2;
    for (int view = 0; view < h->nu * h->nv; view++) {
        const float *hd = h->data + (size_t)view * h->ns * h->nt * 3;
        const float *hv = h->valid + (size_t)view * h->ns * h->nt;
        float *rd = r->data + (size_t)view * r->ns * r->nt * 3;
        float *rv = r->valid + (size_t)view * r->ns * r->nt;
        for (int t = 0; t < nt; t++) {
            double y = t / row;
            int j0 = (int)floor(y + 1e-12);
            double fy = y - j0;
            if (fy < 1e-9)
                fy = 0;
            for (int s = 0; s < r->ns; s++) {
                double acc[3] = {0, 0, 0};
                int ok = 1;
                for (int dj = 0; dj < 2 && ok; dj++) {
                    double wy = dj ? fy : 1 - fy;
                    if (wy == 0)
                        continue;
                    int j = j0 + dj;
                    if (j >= h->nt) {
                        ok = 0;
                        break;
                    }
                    double x = s - ((j & 1) ? 0.5 : 0.0);
                    int i0 = (int)floor(x);
                    double fx = x - i0;
                    for (int di = 0; di < 2; di++) {
                        double w = wy * (di ? fx : 1 - fx);
                        if (w == 0)
                            continue;
                        int i = i0 + di;
                        if (i < 0 || i >= h->ns || hv[(size_t)j * h->ns + i] == 0.f) {
                            ok = 0;
                            break;
                        }
                        const float *p = hd + ((size_t)j * h->ns + i) * 3;
                        acc[0] += w * p[0], acc[1] += w * p[1], acc[2] += w * p[2];
                    }
                }
                size_t o = (size_t)t * r->ns + s;
                if (ok) {
                    rd[o * 3] = (float)acc[0], rd[o * 3 + 1] = (float)acc[1], rd[o * 3 + 2] = (float)acc[2];
                } else {
                    rv[o] = 0.f;
                }
            }
        }
    }
    return LF_OK;
}

void lf_lightfield_set_geometry(lf_lightfield *lf, const lf_lightfield_layout *l)
{
    lf->layout = *l;
    lf->disp_v_per_u = 1.0;
    if (l->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        double bx = l->cams_x > 1 ? (l->grid_bounds[1] - l->grid_bounds[0]) / (l->cams_x - 1) : 0;
        double by = l->cams_y > 1 ? (l->grid_bounds[3] - l->grid_bounds[2]) / (l->cams_y - 1) : 0;
        if ((l->have & LF_LIGHTFIELD_HAVE_BOUNDS) && (l->have & LF_LIGHTFIELD_HAVE_FOV)) {
            double fpx = 0.5 * (l->tile_w < l->tile_h ? l->tile_w : l->tile_h) / tan(l->fov_deg * M_PI / 360);
            double b = bx > 0 ? bx : by;
            lf->disp_per_inv_m = fpx * b;
            if (bx > 0 && by > 0)
                lf->disp_v_per_u = by / bx;
            /* sensors shifted so that disparity vanishes at the convergence depth (HCI) */
            if ((l->have & LF_LIGHTFIELD_HAVE_CONVERGENCE) && l->convergence_m > 0)
                lf->disp_at_inf = -lf->disp_per_inv_m / l->convergence_m;
        }
    } else if (l->have & LF_LIGHTFIELD_HAVE_MAIN_LENS) {
        double f = l->main_focal_mm * 1e-3, F = l->mla_distance_mm * 1e-3;
        double du = f / (2 * l->main_fstop) * 2 / l->pitch_px; /* lens metres per one-pixel view step */
        double k = du / (l->pitch_um * 1e-6);
        /* Exact when the microlens focal length is known (docs/lightfield-format.md,
         * "Disparity"): a pixel offset of one pixel under a microlens sees the main
         * lens (z_i / d) pixels away, and microlens images are P = p (z_i + d) / z_i
         * pixels apart, so k = (pixel z_i / d) / p = (z_i + d) / (d P) (d: microlens
         * to sensor).  The aperture-based estimate above equals it for matched
         * f-numbers up to a factor z_i / (z_i + d). */
        double d = (l->microlens_focal_mm + l->sensor_offset_mm) * 1e-3;
        if (l->microlens_focal_mm > 0 && d > 0 && F > 0)
            k = (F + d) / (d * l->pitch_px);
        lf->disp_per_alpha = k;
        lf->disp_at_inf = k * (1 - F / f);
        lf->disp_per_inv_m = k * F;
    }
}

static size_t count_missing(const lf_lightfield *lf)
{
    if (!lf->valid)
        return 0;
    size_t n = (size_t)lf->nu * lf->nv * lf->ns * lf->nt, m = 0;
    for (size_t i = 0; i < n; i++)
        m += lf->valid[i] == 0.f;
    return m;
}

static int decode_plenoptic(const lf_image *raw, const lf_lightfield_layout *l, lf_lightfield *lf, lf_error *err)
{
    return decode_lenses(raw, l, lf, err);
}

int lf_lightfield_decode(const lf_image *raw, const lf_lightfield_layout *l, const lf_image *white, lf_lightfield *lf,
                 lf_error *err)
{
    memset(lf, 0, sizeof *lf);
    if (!raw || !raw->data || raw->channels < 1)
        return lf_error_set(err, LF_ERR_PARAM, "no raw image");
    if (white && (white->width != raw->width || white->height != raw->height))
        return lf_error_set(err, LF_ERR_PARAM, "white image is %dx%d, raw is %dx%d", white->width, white->height,
                            raw->width, raw->height);
    size_t nonfinite = lf_image_count_nonfinite(raw);
    int rc;
    lf_lightfield a = {0}, w = {0};
    if (l->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        rc = decode_camera_array(raw, l, &a, err);
        if (!rc && white)
            rc = decode_camera_array(white, l, &w, err);
    } else if (l->kind == LF_LIGHTFIELD_PLENOPTIC) {
        rc = decode_plenoptic(raw, l, &a, err);
        if (!rc && white)
            rc = decode_plenoptic(white, l, &w, err);
    } else {
        rc = lf_error_set(err, LF_ERR_PARAM, "layout has no kind");
    }
    if (!rc && white) {
        /* devignetting: divide by white, guard small values */
        size_t n = (size_t)a.nu * a.nv * a.ns * a.nt;
        double maxw = 0;
        for (size_t i = 0; i < n; i++) {
            if (w.valid && w.valid[i] == 0.f)
                continue;
            double m = (w.data[i * 3] + w.data[i * 3 + 1] + w.data[i * 3 + 2]) / 3;
            if (m > maxw)
                maxw = m;
        }
        rc = ensure_valid(&a, err);
        for (size_t i = 0; !rc && i < n; i++) {
            float *p = a.data + i * 3, *q = w.data + i * 3;
            double m = (q[0] + q[1] + q[2]) / 3;
            if ((w.valid && w.valid[i] == 0.f) || !(m > 0.05 * maxw)) {
                a.valid[i] = 0.f;
                p[0] = p[1] = p[2] = 0.f;
                continue;
            }
            for (int c = 0; c < 3; c++)
                p[c] = q[c] > 1e-6f * (float)maxw ? p[c] / q[c] : (float)(p[c] / m);
        }
    }
    lf_lightfield_free(&w);
    if (!rc && l->kind == LF_LIGHTFIELD_PLENOPTIC && l->grid == LF_LIGHTFIELD_GRID_HEX) {
        lf_lightfield r = {0};
        rc = hex_to_rect(&a, &r, err);
        lf_lightfield_free(&a);
        a = r;
    }
    if (rc) {
        lf_lightfield_free(&a);
        return rc;
    }
    *lf = a;
    lf->missing = count_missing(lf);
    lf->nonfinite = nonfinite;
    lf_lightfield_set_geometry(lf, l);
    return LF_OK;
}

int lf_lightfield_alpha_to_disparity(const lf_lightfield *lf, double alpha, double *disp, lf_error *err)
{
    if (lf->disp_per_alpha == 0)
        return lf_error_set(err, LF_ERR_PARAM,
                            "alpha needs a plenoptic raw with main-lens metadata (lensfield:main_focal_mm, "
                            "main_fstop, mla_distance_mm, microlens_pitch_um); use --disparity");
    if (!(alpha > 0) || !isfinite(alpha))
        return lf_error_set(err, LF_ERR_PARAM, "alpha must be > 0 (got %g)", alpha);
    *disp = lf->disp_per_alpha * (1 - 1 / alpha);
    return LF_OK;
}

int lf_lightfield_depth_to_disparity(const lf_lightfield *lf, double z, double *disp, lf_error *err)
{
    if (lf->disp_per_inv_m == 0)
        return lf_error_set(err, LF_ERR_PARAM,
                            "depth needs the capture geometry: camera-array lensfield:camera_grid_bounds and "
                            "fov_deg (--griddim, --inputfov), or plenoptic main-lens metadata; use --disparity");
    if (!(z > 0) || !isfinite(z))
        return lf_error_set(err, LF_ERR_PARAM, "depth must be > 0 (got %g)", z);
    double near = lf->disp_per_inv_m / z;
    *disp = lf->disp_at_inf + near;
    /* The two terms cancel at the depth the capture focused on: what is left
     * there is rounding (the terms themselves come from a chain of metadata
     * arithmetic: 15 ulps seen on the plenoptic demo at 0.5 m), and that
     * depth is disparity 0.  1e-11 of the terms is far below any shift that
     * moves a pixel. */
    if (fabs(*disp) <= 1e-11 * fmax(fabs(lf->disp_at_inf), fabs(near)))
        *disp = 0;
    return LF_OK;
}
