/* Self-calibration of the views' positions from the data (lf_depth.h).
 *
 * Model: I_ref(x, y) = I_k(x - d su_k + ox_k, y - d sv_k + oy_k), d the
 * reference view's disparity, (su, sv) the view's effective baseline in
 * view steps (nominally iu - iu_ref, (iv - iv_ref) r) and (ox, oy) a
 * constant sub-pixel offset (principal point).  For each view, the shift of
 * every textured tile of near-constant disparity is measured (integer
 * search around the nominal prediction, then Lucas-Kanade to sub-pixel on
 * the grey image) and (su, ox), (sv, oy) are fitted to the tiles' shifts
 * against their disparity by least squares, refitted twice on the inliers
 * (residual within 1 px, then within 0.25 px): a tile on the wrong period
 * of a texture or across an occluder does not pull the fit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_depth.h"
#include "base/lf_parallel.h"

void lf_lightfield_view_shift(const lf_lightfield *lf, double fu, double fv, double s[4])
{
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    if (!lf->view_shift) {
        s[0] = fu - iu0, s[1] = (fv - iv0) * rv, s[2] = s[3] = 0;
        return;
    }
    /* bilinear between the calibrated views around (fu, fv) */
    int u0 = (int)floor(fu), v0 = (int)floor(fv);
    u0 = u0 < 0 ? 0 : (u0 > lf->nu - 2 ? (lf->nu > 1 ? lf->nu - 2 : 0) : u0);
    v0 = v0 < 0 ? 0 : (v0 > lf->nv - 2 ? (lf->nv > 1 ? lf->nv - 2 : 0) : v0);
    double au = fu - u0, av = fv - v0;
    s[0] = s[1] = s[2] = s[3] = 0;
    double wsum = 0;
    for (int k = 0; k < 4; k++) {
        int iu = u0 + (k & 1), iv = v0 + (k >> 1);
        if (iu >= lf->nu || iv >= lf->nv)
            continue;
        double w = (k & 1 ? au : 1 - au) * (k & 2 ? av : 1 - av);
        const double *p = lf->view_shift + 4 * ((size_t)iv * lf->nu + iu);
        /* extrapolate linearly outside the grid: the nominal part carries it */
        double nu_ = iu - iu0, nv_ = (iv - iv0) * rv;
        s[0] += w * (p[0] - nu_), s[1] += w * (p[1] - nv_), s[2] += w * p[2], s[3] += w * p[3];
        wsum += w;
    }
    if (wsum > 0)
        for (int i = 0; i < 4; i++)
            s[i] /= wsum;
    s[0] += fu - iu0, s[1] += (fv - iv0) * rv;
}

typedef struct cal_ctx {
    const lf_lightfield *lf;
    const float *grey;   /* all views, grey */
    const float *disp, *conf;
    int tile, ntx, nty;
    double *out;         /* per view: su, sv, ox, oy, tiles used, rms */
    int *ok;
} cal_ctx;

static inline float bil(const float *I, int w, int h, double x, double y)
{
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0;
    if (x0 < 0)
        x0 = 0, fx = 0;
    if (y0 < 0)
        y0 = 0, fy = 0;
    if (x0 > w - 2)
        x0 = w - 2, fx = 1;
    if (y0 > h - 2)
        y0 = h - 2, fy = 1;
    const float *p = I + (size_t)y0 * w + x0;
    return (float)((1 - fy) * ((1 - fx) * p[0] + fx * p[1]) + fy * ((1 - fx) * p[w] + fx * p[w + 1]));
}

static void fit(const double *td, const double *ts, const int *use, int n, double *a, double *b)
{
    double sdd = 0, sd = 0, s1 = 0, ss = 0, sds = 0;
    for (int i = 0; i < n; i++)
        if (use[i])
            sdd += td[i] * td[i], sd += td[i], s1 += 1, ss += ts[i], sds += td[i] * ts[i];
    double det = sdd * s1 - sd * sd;
    if (s1 < 2 || det <= 1e-12 * s1 * s1) { /* no disparity spread: offset only, slope kept */
        double m = 0;
        for (int i = 0; i < n; i++)
            if (use[i])
                m += ts[i] - *a * td[i];
        *b = s1 > 0 ? m / s1 : 0;
        return;
    }
    *a = (sds * s1 - sd * ss) / det;
    *b = (sdd * ss - sd * sds) / det;
}

/* Lucas-Kanade on the translation (sx, sy) of the T x T tile at (x0, y0)
 * of the reference into img; 0 when the tile lacks texture in both
 * directions (np: the tile's pixel count). */
static int track_translation(const float *img, const float *ref, int w, int h, int x0, int y0, int T, double np,
                             double *sx, double *sy)
{
    for (int it = 0; it < 15; it++) {
        double a = 0, b = 0, cc = 0, ex = 0, ey = 0;
        for (int y = y0; y < y0 + T; y++)
            for (int x = x0; x < x0 + T; x++) {
                double X = x + *sx, Y = y + *sy;
                double gx = bil(img, w, h, X + 0.5, Y) - bil(img, w, h, X - 0.5, Y);
                double gy = bil(img, w, h, X, Y + 0.5) - bil(img, w, h, X, Y - 0.5);
                double r = bil(img, w, h, X, Y) - ref[(size_t)y * w + x];
                a += gx * gx, b += gx * gy, cc += gy * gy, ex += gx * r, ey += gy * r;
            }
        double det = a * cc - b * b;
        /* texture in both directions: the smaller eigenvalue of the structure tensor */
        double lmin = (a + cc) / 2 - sqrt((a - cc) * (a - cc) / 4 + b * b);
        if (det <= 0 || lmin < 1e-6 * np)
            return 0;
        double ux = -(cc * ex - b * ey) / det, uy = -(a * ey - b * ex) / det;
        *sx += ux, *sy += uy;
        if (fabs(ux) + fabs(uy) < 1e-4)
            break;
    }
    return 1;
}

/* The shift (sx, sy) of the tile at (x0, y0) in view img against the
 * reference and the tile's mean disparity md; 0 when the tile is not of
 * near-constant, confident disparity or its shift cannot be measured. */
static int tile_shift(const cal_ctx *c, const float *img, const float *ref, int x0, int y0, double nsu, double nsv,
                      double *md_out, double *sx_out, double *sy_out)
{
    int w = c->lf->ns, h = c->lf->nt, T = c->tile;
    double md = 0, m2 = 0, mc = 0;
    for (int y = y0; y < y0 + T; y++)
        for (int x = x0; x < x0 + T; x++) {
            double d = c->disp[(size_t)y * w + x];
            md += d, m2 += d * d, mc += c->conf ? c->conf[(size_t)y * w + x] : 1;
        }
    double np = (double)T * T;
    md /= np, m2 = m2 / np - md * md, mc /= np;
    if (m2 > 0.05 * 0.05 || mc < 0.3)
        return 0;
    /* integer search within 3 px of the nominal prediction */
    double px = -md * nsu, py = -md * nsv;
    int cx = (int)lrint(px), cy = (int)lrint(py);
    double best = INFINITY;
    int bxs = cx, bys = cy;
    for (int dy = cy - 3; dy <= cy + 3; dy++)
        for (int dx = cx - 3; dx <= cx + 3; dx++) {
            if (x0 + dx < 0 || y0 + dy < 0 || x0 + T + dx > w || y0 + T + dy > h)
                continue;
            double s = 0;
            for (int y = y0; y < y0 + T; y++)
                for (int x = x0; x < x0 + T; x++) {
                    double r = img[(size_t)(y + dy) * w + x + dx] - ref[(size_t)y * w + x];
                    s += r * r;
                }
            if (s < best)
                best = s, bxs = dx, bys = dy;
        }
    if (!isfinite(best))
        return 0;
    double sx = bxs, sy = bys;
    if (!track_translation(img, ref, w, h, x0, y0, T, np, &sx, &sy) || fabs(sx - bxs) > 1 || fabs(sy - bys) > 1)
        return 0;
    *md_out = md, *sx_out = sx, *sy_out = sy;
    return 1;
}

/* (su, ox), (sv, oy) fitted to the n tiles' shifts (tx, ty) against their
 * -disparity td, refitted on the inliers (within 1 px, then 0.25 px); o:
 * su, sv, ox, oy, tiles used, rms.  0 when fewer than 8 tiles remain. */
static int fit_view_shift(const double *td, const double *tx, const double *ty, int *use, int n, double nsu, double nsv,
                          double *o)
{
    double su = nsu, ox = 0, sv = nsv, oy = 0;
    for (int i = 0; i < n; i++)
        use[i] = 1;
    for (int pass = 0; pass < 3; pass++) {
        if (pass) {
            double lim = pass == 1 ? 1.0 : 0.25;
            int m = 0;
            for (int i = 0; i < n; i++) {
                double ex = tx[i] - (su * td[i] + ox), ey = ty[i] - (sv * td[i] + oy);
                use[i] = ex * ex + ey * ey <= lim * lim;
                m += use[i];
            }
            if (m < 8)
                break;
        }
        fit(td, tx, use, n, &su, &ox);
        fit(td, ty, use, n, &sv, &oy);
    }
    int m = 0;
    double se = 0;
    for (int i = 0; i < n; i++)
        if (use[i]) {
            double ex = tx[i] - (su * td[i] + ox), ey = ty[i] - (sv * td[i] + oy);
            se += ex * ex + ey * ey, m++;
        }
    if (m < 8)
        return 0;
    o[0] = su, o[1] = sv, o[2] = ox, o[3] = oy, o[4] = m, o[5] = sqrt(se / m);
    return 1;
}

static void cal_views(void *vctx, int k0, int k1, int tid)
{
    (void)tid;
    cal_ctx *c = vctx;
    const lf_lightfield *lf = c->lf;
    int w = lf->ns, h = lf->nt, T = c->tile;
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    const float *ref = c->grey + ((size_t)iv0 * lf->nu + iu0) * w * h;
    size_t nmax = (size_t)c->ntx * c->nty;
    double *td = malloc(sizeof(double) * nmax * 3);
    int *use = malloc(sizeof(int) * nmax);
    if (!td || !use) {
        free(td), free(use);
        return;
    }
    double *tx = td + nmax, *ty = td + 2 * nmax;
    for (int k = k0; k < k1; k++) {
        int iu = k % lf->nu, iv = k / lf->nu;
        double *o = c->out + 6 * (size_t)k;
        double nsu = iu - iu0, nsv = (iv - iv0) * rv;
        o[0] = nsu, o[1] = nsv, o[2] = o[3] = o[4] = o[5] = 0;
        if (iu == iu0 && iv == iv0) {
            c->ok[k] = 1;
            continue;
        }
        const float *img = c->grey + (size_t)k * w * h;
        int n = 0;
        int margin = T / 2;
        for (int by = 0; by < c->nty; by++)
            for (int bx = 0; bx < c->ntx; bx++) {
                double md, sx, sy;
                if (!tile_shift(c, img, ref, margin + bx * T, margin + by * T, nsu, nsv, &md, &sx, &sy))
                    continue;
                /* shift s = -d su + o */
                td[n] = -md, tx[n] = sx, ty[n] = sy, n++;
            }
        if (n >= 8 && fit_view_shift(td, tx, ty, use, n, nsu, nsv, o))
            c->ok[k] = 1;
    }
    free(td), free(use);
}

int lf_lightfield_calibrate_views(lf_lightfield *lf, const lf_image *disparity, const lf_image *confidence, int threads,
                          double *report, lf_error *err)
{
    if (!lf || !lf->data || lf->nu * lf->nv < 2)
        return lf_error_set(err, LF_ERR_PARAM, "view calibration needs at least 2 views");
    int w = lf->ns, h = lf->nt;
    if (!disparity || disparity->width != w || disparity->height != h)
        return lf_error_set(err, LF_ERR_PARAM, "view calibration needs a disparity map of the views' size %dx%d", w, h);
    if (confidence && (confidence->width != w || confidence->height != h))
        return lf_error_set(err, LF_ERR_PARAM, "confidence map is %dx%d, the views are %dx%d", confidence->width,
                            confidence->height, w, h);
    int nviews = lf->nu * lf->nv;
    /* tiles: 1/32 of the shorter side, 8 .. 16 px */
    int tile = (w < h ? w : h) / 32;
    tile = tile < 8 ? 8 : (tile > 16 ? 16 : tile);
    cal_ctx c;
    memset(&c, 0, sizeof c);
    c.lf = lf, c.tile = tile;
    c.ntx = (w - tile) / tile, c.nty = (h - tile) / tile;
    if (c.ntx < 1 || c.nty < 1)
        return lf_error_set(err, LF_ERR_PARAM, "views of %dx%d are too small to calibrate", w, h);
    c.disp = disparity->data, c.conf = confidence ? confidence->data : NULL;
    float *grey = malloc(sizeof(float) * (size_t)w * h * nviews);
    double *out = malloc(sizeof(double) * 6 * nviews);
    int *ok = calloc((size_t)nviews, sizeof(int));
    double *shift = malloc(sizeof(double) * 4 * nviews);
    if (!grey || !out || !ok || !shift) {
        free(grey), free(out), free(ok), free(shift);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for view calibration");
    }
    size_t np = (size_t)w * h;
    for (int k = 0; k < nviews; k++) {
        const float *v = lf->data + (size_t)k * np * 3;
        for (size_t i = 0; i < np; i++)
            grey[(size_t)k * np + i] = (v[3 * i] + v[3 * i + 1] + v[3 * i + 2]) * (1.f / 3.f);
    }
    c.grey = grey, c.out = out, c.ok = ok;
    lf_parallel_for(nviews, threads > 0 ? threads : 2, 1, cal_views, &c);
    int nok = 0;
    for (int k = 0; k < nviews; k++) {
        for (int i = 0; i < 4; i++)
            shift[4 * k + i] = out[6 * k + i];
        nok += ok[k];
        if (report)
            for (int i = 0; i < 6; i++)
                report[6 * k + i] = ok[k] ? out[6 * k + i] : (i < 2 ? out[6 * k + i] : (i == 4 ? 0 : NAN));
    }
    free(grey), free(out), free(ok);
    free(lf->view_shift);
    lf->view_shift = shift;
    (void)nok;
    return LF_OK;
}
