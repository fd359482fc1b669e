/* Depth-based view synthesis (lf_depth.h; docs/depth.md has the details).
 *
 * 1. The reference view's disparity map is forward-warped ("splatted") to
 *    the target viewpoint and to each source view: every reference pixel
 *    covers the pixel centres within about half a pixel of where it lands,
 *    the nearest surface (largest disparity) wins; holes (disocclusions)
 *    take the farthest disparity around them, as the background is what
 *    appears there.
 * 2. Scattered-data fit (default): every pixel of every view within a tent
 *    of radius 3 view steps lands, via the target pixel's disparity, at a
 *    sub-pixel offset from the target pixel centre; views at other
 *    viewpoints land at other phases, so together they sample the
 *    (pixel-integrated) image more densely than one grid.  A Gaussian-
 *    weighted (sigma 0.35 px) quadratic fit to the samples gives the value
 *    at the centre; a sample whose own warped disparity, or a neighbour's,
 *    is clearly nearer sees (part of) an occluder and drops out.  Blend
 *    (blend = 1): bicubic lookups in the views within 2 view steps weighted
 *    by the tent and the resampling phase.
 * 3. Near depth edges the nearest disparity within a pixel is primary; with
 *    the fit, the outline's mixed pixels are unmixed against the parallax-
 *    shifted backgrounds (two_layer); with the blend, the candidates compete
 *    by photo-consistency (soft weights).
 * 4. Where the splatted confidence is low the result fades to the plane
 *    blend at plane_disparity (lf_lightfield_view_at). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_math.h"
#include "lf_depth.h"
#include "base/lf_parallel.h"

lf_lightfield_view_opts lf_lightfield_view_defaults(void)
{
    lf_lightfield_view_opts o;
    memset(&o, 0, sizeof o);
    o.depth = lf_lightfield_depth_defaults();
    o.min_confidence = -1;
    o.phase_floor = -1;
    return o;
}

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* The visibility test: a source whose warped disparity at the looked-up
 * spot is nearer than d by more than this sees an occluder there. */
static inline float occluder_tol(float d) { return d + 0.25f + 0.05f * fabsf(d); }

/* Splat the reference disparity (and confidence, may be NULL) to a
 * viewpoint offset (du, dv) view steps from the reference (dv scaled).
 * Returns 0 when out of memory. */
static int splat(const float *disp, const float *conf, int w, int h, double du, double dv, double ox, double oy,
                 float *out, float *out_conf)
{
    size_t np = (size_t)w * h;
    for (size_t i = 0; i < np; i++)
        out[i] = -FLT_MAX;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float d = disp[i];
            /* I_target(x', y') = I_ref(x' + d du, y' + d dv): x' = x - d du.
             * The footprint: every pixel centre within 0.5 (+ a little) of
             * the landing point, so a surface shifted by exactly half a
             * pixel leaves no holes (nearest-pixel rounding would). */
            double xf = x - d * du + ox, yf = y - d * dv + oy;
            int xa = (int)ceil(xf - 0.51), xb = (int)floor(xf + 0.51);
            int ya = (int)ceil(yf - 0.51), yb = (int)floor(yf + 0.51);
            for (int yt = ya; yt <= yb; yt++)
                for (int xt = xa; xt <= xb; xt++) {
                    if (xt < 0 || xt >= w || yt < 0 || yt >= h)
                        continue;
                    size_t j = (size_t)yt * w + xt;
                    if (d > out[j]) {
                        out[j] = d;
                        if (out_conf)
                            out_conf[j] = conf ? conf[i] : 1.f;
                    }
                }
        }
    /* holes (disocclusions): the background is what appears there.  The
     * nearest seen pixels left, right, above and below a hole pixel are its
     * candidates; the farthest surface among them (within the occluder
     * tolerance of the smallest disparity) is the background, and of its
     * candidates the nearest gives the disparity, with its confidence
     * halved per pixel of distance.  (Growing the hole from its rim lets
     * the nearer side fill a thin strip, or the fill run along the scan.) */
    int *cand = malloc(sizeof(int) * np * 4); /* nearest seen pixel left, right, above, below (-1: none) */
    if (!cand)
        return 0;
    for (int y = 0; y < h; y++)
        for (int x = 0, l = -1, r = -1; x < w; x++) {
            size_t i = (size_t)y * w + x, ir = (size_t)y * w + (w - 1 - x);
            l = out[i] > -FLT_MAX ? (int)i : l;
            r = out[ir] > -FLT_MAX ? (int)ir : r;
            cand[4 * i] = l, cand[4 * ir + 1] = r;
        }
    for (int x = 0; x < w; x++)
        for (int y = 0, u = -1, d = -1; y < h; y++) {
            size_t i = (size_t)y * w + x, id = (size_t)(h - 1 - y) * w + x;
            u = out[i] > -FLT_MAX ? (int)i : u;
            d = out[id] > -FLT_MAX ? (int)id : d;
            cand[4 * i + 2] = u, cand[4 * id + 3] = d;
        }
    float dfar = FLT_MAX;
    for (size_t i = 0; i < np; i++)
        dfar = out[i] > -FLT_MAX && out[i] < dfar ? out[i] : dfar;
    for (size_t i = 0; i < np; i++) {
        if (out[i] > -FLT_MAX)
            continue;
        const int *q = cand + 4 * i;
        float dmin = FLT_MAX, dist = FLT_MAX, best = dfar < FLT_MAX ? dfar : 0.f, bc = 0;
        for (int e = 0; e < 4; e++)
            if (q[e] >= 0 && out[q[e]] < dmin)
                dmin = out[q[e]];
        for (int e = 0; e < 4; e++) {
            if (q[e] < 0 || out[q[e]] > occluder_tol(dmin))
                continue;
            /* the candidate shares the row (e < 2) or the column */
            float de = (float)(e < 2 ? abs(q[e] - (int)i) : abs(q[e] - (int)i) / w);
            if (de < dist)
                dist = de, best = out[q[e]], bc = (out_conf ? out_conf[q[e]] : 0) * powf(0.5f, de);
        }
        out[i] = best;
        if (out_conf)
            out_conf[i] = bc;
    }
    free(cand);
    return 1;
}

/* Cubic convolution weights (Keys 1981, a = -0.5) for fraction t in [0, 1). */
static inline void cubic_w(float t, float w[4])
{
    float t2 = t * t, t3 = t2 * t;
    w[0] = -0.5f * t3 + t2 - 0.5f * t;
    w[1] = 1.5f * t3 - 2.5f * t2 + 1.f;
    w[2] = -1.5f * t3 + 2.f * t2 + 0.5f * t;
    w[3] = 0.5f * t3 - 0.5f * t2;
}

/* Bicubic sample of an RGB view at (x, y), clamped to the view: the views
 * are pixel-integrated samples of textures with detail up to the pixel
 * scale, which bilinear interpolation visibly blurs. */
static void sample(const float *img, int w, int h, double x, double y, float rgb[3])
{
    x = x < 0 ? 0 : (x > w - 1 ? w - 1 : x);
    y = y < 0 ? 0 : (y > h - 1 ? h - 1 : y);
    int x0 = (int)floor(x), y0 = (int)floor(y);
    float wx[4], wy[4];
    cubic_w((float)(x - x0), wx);
    cubic_w((float)(y - y0), wy);
    float a[3] = {0, 0, 0};
    for (int j = 0; j < 4; j++) {
        const float *row = img + (size_t)clampi(y0 - 1 + j, 0, h - 1) * w * 3;
        float r[3] = {0, 0, 0};
        for (int i = 0; i < 4; i++) {
            const float *p = row + (size_t)clampi(x0 - 1 + i, 0, w - 1) * 3;
            r[0] += wx[i] * p[0], r[1] += wx[i] * p[1], r[2] += wx[i] * p[2];
        }
        a[0] += wy[j] * r[0], a[1] += wy[j] * r[1], a[2] += wy[j] * r[2];
    }
    rgb[0] = a[0], rgb[1] = a[1], rgb[2] = a[2];
}

#define VS_MAXSRC 64

typedef struct vs_ctx {
    const lf_lightfield *lf;
    int nsrc;
    int iu[VS_MAXSRC], iv[VS_MAXSRC];
    double wv[VS_MAXSRC];         /* angular (tent) weights */
    double du[VS_MAXSRC], dv[VS_MAXSRC]; /* source view minus target, view steps (dv scaled) */
    double ox[VS_MAXSRC], oy[VS_MAXSRC]; /* source minus target pixel offset (calibrated views) */
    const float *dt, *ct; /* target disparity, confidence */
    const float *ds[VS_MAXSRC];   /* source views' warped disparity */
    const float *dx[VS_MAXSRC];   /* the same, largest over 3 x 3 (a pixel next to a nearer surface may mix it in) */
    double phase0;        /* resampling-phase weight floor (<= 0: phase ignored) */
    const float *plane;   /* plane blend, RGB */
    float cmin;
    float *out;
    int blend;     /* 1: bicubic blend (phase-weighted); 0: scattered-data fit */
    double sigma;  /* Gaussian kernel of the fit, px */
} vs_ctx;


/* Scattered-data fit at kernel width sigma: every pixel of every visible
 * source lands, via d, at an offset from the target pixel centre; a
 * Gaussian-weighted least-squares quadratic in the offset gives the value
 * at the centre (samples marked invalid in lf->valid left out).  Returns the variance gain of that value, wsum (A^-1)_00
 * (1 for a plain mean; large when the samples do not pin the centre down),
 * or -1 when nothing is seen; *res the weighted residual (photo-consistency). */
static double fit_sigma(const vs_ctx *c, int x, int y, float d, double sigma, float rgb[3], double *seen,
                        double *res)
{
    int w = c->lf->ns, h = c->lf->nt;
    enum { nb = 6 }; /* 1, x, y, x^2, xy, y^2 */
    double A[36] = {0}, b[6][4] = {{0}}, wsum = 0, sq = 0;
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    double is2 = 1.0 / (2 * sigma * sigma);
    double r2max = 9 * sigma * sigma;
    int rad = (int)ceil(3 * sigma);
    float dtol = occluder_tol(d);
    for (int k = 0; k < c->nsrc; k++) {
        double sx = x - d * c->du[k] + c->ox[k], sy = y - d * c->dv[k] + c->oy[k];
        if (sx < -0.5 || sy < -0.5 || sx > w - 0.5 || sy > h - 0.5)
            continue;
        float dk = c->ds[k][(size_t)clampi((int)lrint(sy), 0, h - 1) * w + clampi((int)lrint(sx), 0, w - 1)];
        if (dk > dtol)
            continue;
        const float *img = lf_lightfield_view(c->lf, c->iu[k], c->iv[k]);
        const float *valid = c->lf->valid ? c->lf->valid + ((size_t)c->iv[k] * c->lf->nu + c->iu[k]) * (size_t)w * h : NULL;
        int xc = (int)lrint(sx), yc = (int)lrint(sy);
        for (int j = yc - rad; j <= yc + rad; j++) {
            if (j < 0 || j >= h)
                continue;
            double ey = j - sy;
            for (int i = xc - rad; i <= xc + rad; i++) {
                if (i < 0 || i >= w)
                    continue;
                double ex = i - sx, r2 = ex * ex + ey * ey;
                if (r2 > r2max)
                    continue;
                if (c->dx[k][(size_t)j * w + i] > dtol || (valid && valid[(size_t)j * w + i] == 0.f))
                    continue;
                double wk = c->wv[k] * exp(-r2 * is2);
                double f[6] = {1, ex, ey, ex * ex, ex * ey, ey * ey};
                const float *p = img + ((size_t)j * w + i) * 3;
                for (int a = 0; a < nb; a++) {
                    double wf = wk * f[a];
                    for (int bb = a; bb < nb; bb++)
                        A[a * nb + bb] += wf * f[bb];
                    b[a][0] += wf * p[0], b[a][1] += wf * p[1], b[a][2] += wf * p[2];
                }
                wsum += wk;
                sq += wk * ((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
                if (r2 <= 1)
                    for (int ch = 0; ch < 3; ch++) {
                        lo[ch] = p[ch] < lo[ch] ? p[ch] : lo[ch];
                        hi[ch] = p[ch] > hi[ch] ? p[ch] : hi[ch];
                    }
            }
        }
    }
    *seen = wsum;
    if (wsum <= 1e-6)
        return -1;
    for (int a = 0; a < nb; a++)
        for (int bb = 0; bb < a; bb++)
            A[a * nb + bb] = A[bb * nb + a];
    double rhs[6][3];
    for (int a = 0; a < nb; a++)
        rhs[a][0] = b[a][0], rhs[a][1] = b[a][1], rhs[a][2] = b[a][2];
    /* a little ridge on the higher terms keeps degenerate layouts finite */
    for (int a = 1; a < nb; a++)
        A[a * nb + a] += 1e-4 * wsum;
    for (int a = 0; a < nb; a++)
        b[a][3] = a == 0;
    if (!lf_solve(A, &b[0][0], nb, 4)) {
        for (int ch = 0; ch < 3; ch++)
            rgb[ch] = (float)(rhs[0][ch] / wsum);
        *res = 0;
        return 1e30;
    }
    double cb = 0;
    for (int a = 0; a < nb; a++)
        cb += b[a][0] * rhs[a][0] + b[a][1] * rhs[a][1] + b[a][2] * rhs[a][2];
    for (int ch = 0; ch < 3; ch++) {
        rgb[ch] = (float)b[0][ch];
        /* never outside the samples within 1 px: bounds what noise or an
         * ill-placed sample can do to an extrapolating fit */
        if (lo[ch] <= hi[ch])
            rgb[ch] = rgb[ch] < lo[ch] ? lo[ch] : (rgb[ch] > hi[ch] ? hi[ch] : rgb[ch]);
    }
    double r = (sq - cb) / wsum;
    *res = r > 0 ? r : 0;
    return wsum * b[0][3];
}

/* The fit at the smallest kernel whose centre value the samples pin down:
 * where every source lands at the same phase (e.g. all half a pixel off)
 * a narrow quadratic is undetermined (variance gain of the centre value
 * over a plain weighted mean above 1e4), and a wider kernel makes it an
 * interpolation over the neighbours. */
static double fit_at(const vs_ctx *c, int x, int y, float d, float rgb[3], double *seen)
{
    static const double scale[4] = {1.0, 1.43, 2.0, 2.86};
    double res = 0;
    for (int q = 0; q < 4; q++) {
        double g = fit_sigma(c, x, y, d, c->sigma * scale[q], rgb, seen, &res);
        if (g < 0)
            return -1;
        if (g <= 1e4)
            break;
    }
    return res;
}

/* Colour of target pixel (x, y) at disparity d from the sources that see
 * it: the scattered-data fit, or (blend) the bicubic lookups of the
 * visible sources weighted by angular distance and resampling phase.
 * Returns a photo-consistency score (the fit's weighted residual, or the
 * weighted colour variance across the sources), -1 when no source sees
 * the point (rgb then the blend of all sources). */
static double blend_at(const vs_ctx *c, int x, int y, float d, float rgb[3], float all[3], double *seen)
{
    if (!c->blend) {
        double v = fit_at(c, x, y, d, rgb, seen);
        if (v >= 0)
            return v;
    }
    int w = c->lf->ns, h = c->lf->nt;
    double acc[3] = {0, 0, 0}, sq = 0, wsum = 0, acc_all[3] = {0, 0, 0}, wall = 0;
    for (int k = 0; k < c->nsrc; k++) {
        /* I_target(x, y) = I_k(x - d (u_k - u), y - d (v_k - v)) */
        double sx = x - d * c->du[k] + c->ox[k], sy = y - d * c->dv[k] + c->oy[k];
        float col[3];
        sample(lf_lightfield_view(c->lf, c->iu[k], c->iv[k]), w, h, sx, sy, col);
        float dk = c->ds[k][(size_t)clampi((int)lrint(sy), 0, h - 1) * w + clampi((int)lrint(sx), 0, w - 1)];
        double vis = dk > occluder_tol(d) ? 0.0 : 1.0;
        double inside = (sx < 0 || sy < 0 || sx > w - 1 || sy > h - 1) ? 0.1 : 1.0;
        double wk = c->wv[k] * inside;
        if (c->phase0 > 0) {
            /* resampling phase: a source whose pixel grid lands on the
             * target's pixel centres is read without interpolation; half a
             * pixel off, interpolation loses texture at the pixel scale.
             * Weight by 1 / (fx (1 - fx) + fy (1 - fy) + floor). */
            double fx = sx - floor(sx), fy = sy - floor(sy);
            wk /= fx * (1 - fx) + fy * (1 - fy) + c->phase0;
        }
        for (int ch = 0; ch < 3; ch++)
            acc_all[ch] += wk * col[ch];
        wall += wk;
        wk *= vis;
        for (int ch = 0; ch < 3; ch++)
            acc[ch] += wk * col[ch];
        sq += wk * ((double)col[0] * col[0] + (double)col[1] * col[1] + (double)col[2] * col[2]);
        wsum += wk;
    }
    for (int ch = 0; ch < 3; ch++)
        all[ch] = (float)(wall > 0 ? acc_all[ch] / wall : 0);
    *seen = wsum;
    if (wsum <= 1e-6) {
        for (int ch = 0; ch < 3; ch++)
            rgb[ch] = all[ch];
        return -1;
    }
    double m2 = 0;
    for (int ch = 0; ch < 3; ch++) {
        rgb[ch] = (float)(acc[ch] / wsum);
        m2 += (double)rgb[ch] * rgb[ch];
    }
    double var = sq / wsum - m2;
    return var > 0 ? var : 0;
}

/* Background colour at target position (xf, yf) on the surface at
 * disparity db: bicubic lookups in the sources that see it clear of
 * nearer surfaces (within a pixel), weighted by angular distance.
 * Returns 0 when no source sees it. */
static int bg_at(const vs_ctx *c, double xf, double yf, float db, float rgb[3])
{
    int w = c->lf->ns, h = c->lf->nt;
    double acc[3] = {0, 0, 0}, wsum = 0;
    float tol = occluder_tol(db);
    for (int k = 0; k < c->nsrc; k++) {
        double sx = xf - db * c->du[k] + c->ox[k], sy = yf - db * c->dv[k] + c->oy[k];
        if (sx < 0 || sy < 0 || sx > w - 1 || sy > h - 1)
            continue;
        if (c->dx[k][(size_t)lrint(sy) * w + lrint(sx)] > tol)
            continue;
        float col[3];
        sample(lf_lightfield_view(c->lf, c->iu[k], c->iv[k]), w, h, sx, sy, col);
        for (int ch = 0; ch < 3; ch++)
            acc[ch] += c->wv[k] * col[ch];
        wsum += c->wv[k];
    }
    if (wsum <= 1e-9)
        return 0;
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = (float)(acc[ch] / wsum);
    return 1;
}

/* Two layers at a depth edge: the views' pixels on the nearer surface's
 * outline (disparity df) mix its colour F with whatever lies behind by a
 * coverage alpha that travels with the outline, I_k = alpha F + (1 - alpha)
 * B_k, while the background behind (disparity db) differs from view to
 * view by parallax.  With B_k looked up where the views see the background
 * clear, least squares over the views gives 1 - alpha = Cov(B, I) / Var(B)
 * (multi-background matting, as triangulation matting with backgrounds
 * that parallax provides) and the target pixel is
 * I_fit + (1 - alpha) (B_t - mean(B)): ifit the scattered-data fit at df
 * (which averages the views' mixes), B_t the target's own background.
 * Returns 0 when fewer than 3 views constrain it. */
static int two_layer(const vs_ctx *c, int x, int y, float df, float db, const float bt[3], const float ifit[3],
                     float rgb[3])
{
    int w = c->lf->ns, h = c->lf->nt;
    double W = 0, sI[3] = {0, 0, 0}, sB[3] = {0, 0, 0}, sBI = 0, sBB = 0;
    float tol = occluder_tol(df);
    int n = 0;
    for (int k = 0; k < c->nsrc; k++) {
        double sx = x - df * c->du[k] + c->ox[k], sy = y - df * c->dv[k] + c->oy[k];
        if (sx < 0 || sy < 0 || sx > w - 1 || sy > h - 1)
            continue;
        if (c->ds[k][(size_t)lrint(sy) * w + lrint(sx)] > tol)
            continue;
        float I[3], B[3];
        if (!bg_at(c, x - (df - db) * c->du[k], y - (df - db) * c->dv[k], db, B))
            continue;
        sample(lf_lightfield_view(c->lf, c->iu[k], c->iv[k]), w, h, sx, sy, I);
        double wk = c->wv[k];
        for (int ch = 0; ch < 3; ch++) {
            sI[ch] += wk * I[ch], sB[ch] += wk * B[ch];
            sBI += wk * (double)B[ch] * I[ch], sBB += wk * (double)B[ch] * B[ch];
        }
        W += wk, n++;
    }
    if (n < 3)
        return 0;
    double cov = sBI / W, var = sBB / W;
    for (int ch = 0; ch < 3; ch++)
        cov -= sB[ch] * sI[ch] / (W * W), var -= sB[ch] * sB[ch] / (W * W);
    /* a weak prior (alpha 1/2, worth a colour spread of 0.01) where the
     * backgrounds hardly differ; then alpha hardly matters either */
    const double lam = 1e-4;
    double oma = (cov + lam * 0.5) / (var + lam);
    oma = oma < 0 ? 0 : (oma > 1 ? 1 : oma);
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = (float)(ifit[ch] + oma * (bt[ch] - sB[ch] / W));
    return 1;
}

static void vs_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    vs_ctx *c = vctx;
    int w = c->lf->ns, h = c->lf->nt;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            /* near a depth edge the splatted map is only pixel-accurate and the
             * views' edge pixels are antialiased mixes, which travel with the
             * occluding (nearer) surface: the nearest disparity within one
             * pixel is the primary one; the pixel's own and the farthest
             * around compete by photo-consistency */
            float dpix = c->dt[i], dmin = dpix, dmax = dpix;
            for (int j = -1; j <= 1; j++)
                for (int k = -1; k <= 1; k++) {
                    int xx = clampi(x + k, 0, w - 1), yy = clampi(y + j, 0, h - 1);
                    float v = c->dt[(size_t)yy * w + xx];
                    dmin = v < dmin ? v : dmin, dmax = v > dmax ? v : dmax;
                }
            float d = dmax;
            float px[3], all[3];
            double seen, seen2;
            double best = blend_at(c, x, y, d, px, all, &seen);
            float bt[3], tl[3];
            double sb;
            if (!c->blend && dmax - dmin > 0.25f && best >= 0 && blend_at(c, x, y, dmin, bt, all, &sb) >= 0 &&
                two_layer(c, x, y, dmax, dmin, bt, px, tl)) {
                px[0] = tl[0], px[1] = tl[1], px[2] = tl[2];
            } else if (dmax - dmin > 0.25f && best >= 0) {
                /* soft choice: candidates weighted by 1 / (variance + floor);
                 * a mixed edge pixel then gets a mix too */
                const double floor_v = 1e-4;
                double wsum = 1.0 / (best + floor_v), acc[3] = {px[0] * wsum, px[1] * wsum, px[2] * wsum};
                float cand[2] = {dpix, dmin};
                for (int q = 0; q < 2; q++) {
                    if (cand[q] == d || (q == 1 && cand[1] == cand[0]))
                        continue;
                    float p2[3], a2[3];
                    double v = blend_at(c, x, y, cand[q], p2, a2, &seen2);
                    /* a candidate fewer sources see would win by seeing less */
                    if (v < 0 || seen2 < seen - 1e-6)
                        continue;
                    double wq = 1.0 / (v + floor_v);
                    for (int ch = 0; ch < 3; ch++)
                        acc[ch] += wq * p2[ch];
                    wsum += wq;
                }
                for (int ch = 0; ch < 3; ch++)
                    px[ch] = (float)(acc[ch] / wsum);
            }
            float *o = c->out + 3 * i;
            float a = c->cmin > 0 ? c->ct[i] / c->cmin : 1.f;
            a = a > 1.f ? 1.f : a;
            for (int ch = 0; ch < 3; ch++)
                o[ch] = a * px[ch] + (1 - a) * c->plane[3 * i + ch];
        }
}

int lf_lightfield_view_depth(const lf_lightfield *lf, double u, double v, const lf_lightfield_view_opts *o, lf_image *out,
                     lf_error *err)
{
    lf_lightfield_view_opts def = lf_lightfield_view_defaults();
    if (!o)
        o = &def;
    double fu = u + (lf->nu - 1) / 2.0, fv = v + (lf->nv - 1) / 2.0;
    if (!(fu >= -1e-9 && fu <= lf->nu - 1 + 1e-9 && fv >= -1e-9 && fv <= lf->nv - 1 + 1e-9))
        return lf_error_set(err, LF_ERR_PARAM, "view (%g, %g) is outside the captured aperture u in [%g, %g], v in [%g, %g]",
                            u, v, -(lf->nu - 1) / 2.0, (lf->nu - 1) / 2.0, -(lf->nv - 1) / 2.0, (lf->nv - 1) / 2.0);
    int w = lf->ns, h = lf->nt;
    size_t np = (size_t)w * h;
    if (o->disparity && (o->disparity->width != w || o->disparity->height != h))
        return lf_error_set(err, LF_ERR_PARAM, "disparity map is %dx%d, the views are %dx%d", o->disparity->width,
                            o->disparity->height, w, h);
    if (o->confidence && (o->confidence->width != w || o->confidence->height != h))
        return lf_error_set(err, LF_ERR_PARAM, "confidence map is %dx%d, the views are %dx%d", o->confidence->width,
                            o->confidence->height, w, h);
    /* exactly at a view: that view */
    if (fabs(fu - lrint(fu)) < 1e-9 && fabs(fv - lrint(fv)) < 1e-9)
        return lf_lightfield_view_at(lf, u, v, 0.0, out, err);
    lf_image disp = {0}, conf = {0};
    int rc;
    if (!o->disparity) {
        lf_lightfield_depth_opts dopt = o->depth;
        if (dopt.threads <= 0)
            dopt.threads = o->threads;
        if ((rc = lf_lightfield_depth(lf, &dopt, &disp, &conf, err)))
            return rc;
    }
    const float *D = o->disparity ? o->disparity->data : disp.data;
    const float *C = o->disparity ? (o->confidence ? o->confidence->data : NULL) : conf.data;
    vs_ctx c;
    memset(&c, 0, sizeof c);
    c.lf = lf;
    /* sources: the views within a tent of radius R view steps around the
     * target (R = 1: the 4 nearest, bilinear weights; R = 3: up to 36;
     * at most 4: 64) */
    c.blend = o->blend;
    c.sigma = o->kernel > 0 ? o->kernel : 0.35;
    double R = o->radius > 0 ? o->radius : (o->blend ? 2.0 : 3.0);
    R = R > 4 ? 4 : R;
    c.phase0 = o->phase_floor < 0 ? 0.05 : o->phase_floor;
    int rr = (int)ceil(R - 1e-9);
    double st[4]; /* the target's (su, sv, ox, oy) */
    lf_lightfield_view_shift(lf, fu, fv, st);
    for (int iv = (int)floor(fv) - rr + 1; iv <= (int)floor(fv) + rr; iv++)
        for (int iu = (int)floor(fu) - rr + 1; iu <= (int)floor(fu) + rr; iu++) {
            if (iu < 0 || iv < 0 || iu >= lf->nu || iv >= lf->nv || c.nsrc >= VS_MAXSRC)
                continue;
            double wu = 1 - fabs(iu - fu) / R, wvv = 1 - fabs(iv - fv) / R;
            if (wu <= 1e-9 || wvv <= 1e-9)
                continue;
            /* a view lf_lightfield_equalize brightened carries noise grown by 1 / gain: inverse-variance weight */
            double g = lf->view_gain ? lf->view_gain[(size_t)iv * lf->nu + iu] : 1.0;
            g = g < 1 ? g : 1;
            c.iu[c.nsrc] = iu, c.iv[c.nsrc] = iv, c.wv[c.nsrc] = wu * wvv * g * g;
            double sk[4];
            lf_lightfield_view_shift(lf, iu, iv, sk);
            c.du[c.nsrc] = sk[0] - st[0], c.dv[c.nsrc] = sk[1] - st[1];
            c.ox[c.nsrc] = sk[2] - st[2], c.oy[c.nsrc] = sk[3] - st[3];
            c.nsrc++;
        }
    float *buf = malloc(sizeof(float) * np * (2 + 2 * (size_t)c.nsrc));
    lf_image plane = {0};
    if (!buf) {
        lf_image_free(&disp), lf_image_free(&conf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    float *dt = buf, *ct = buf + np;
    int ok = splat(D, C, w, h, st[0], st[1], st[2], st[3], dt, ct);
    for (int k = 0; k < c.nsrc && ok; k++) {
        float *dk = buf + (2 + (size_t)k) * np;
        double sk[4];
        lf_lightfield_view_shift(lf, c.iu[k], c.iv[k], sk);
        ok = splat(D, NULL, w, h, sk[0], sk[1], sk[2], sk[3], dk, NULL);
        c.ds[k] = dk;
        float *dxk = buf + (2 + (size_t)c.nsrc + k) * np;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                float m = -FLT_MAX;
                for (int j = -1; j <= 1; j++)
                    for (int i = -1; i <= 1; i++) {
                        float v = dk[(size_t)clampi(y + j, 0, h - 1) * w + clampi(x + i, 0, w - 1)];
                        m = v > m ? v : m;
                    }
                dxk[(size_t)y * w + x] = m;
            }
        c.dx[k] = dxk;
    }
    if (!ok) {
        free(buf), lf_image_free(&disp), lf_image_free(&conf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    c.dt = dt, c.ct = ct;
    c.cmin = o->min_confidence < 0 ? 0.05f : (float)o->min_confidence;
    if ((rc = lf_lightfield_view_at(lf, u, v, o->plane_disparity, &plane, err)) || (rc = lf_image_alloc(out, w, h, 3, err))) {
        free(buf), lf_image_free(&plane), lf_image_free(&disp), lf_image_free(&conf);
        return rc ? rc : LF_ERR_NOMEM;
    }
    c.plane = plane.data;
    c.out = out->data;
    lf_parallel_for(h, o->threads, 8, vs_rows, &c);
    free(buf), lf_image_free(&plane), lf_image_free(&disp), lf_image_free(&conf);
    return LF_OK;
}
