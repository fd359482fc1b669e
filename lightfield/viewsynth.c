/* Depth-based view synthesis (lf_depth.h; docs/depth.md has the details).
 *
 * 1. The reference view's disparity map is forward-warped ("splatted") to
 *    the target viewpoint and to each source view: every reference pixel
 *    covers the pixel centres within about half a pixel of where it lands,
 *    the nearest surface (largest disparity) wins; holes (disocclusions)
 *    take the farthest disparity around them, as the background is what
 *    appears there.
 * 2. Every target pixel is looked up (bicubic) in the views within a tent
 *    of radius 2 view steps (up to 16), weighted by the tent in (u, v) and
 *    by the resampling phase (sources whose pixel grid lands near the
 *    target pixel centre need less interpolation); a view whose own warped
 *    disparity there is clearly nearer sees an occluder and drops out.
 * 3. Near depth edges the nearest disparity within a pixel is primary and
 *    the others compete by photo-consistency (soft weights).
 * 4. Where the splatted confidence is low the result fades to the plane
 *    blend at plane_disparity (lf_lf_view_at). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_depth.h"
#include "../base/lf_parallel.h"

lf_lf_view_opts lf_lf_view_defaults(void)
{
    lf_lf_view_opts o;
    memset(&o, 0, sizeof o);
    o.depth = lf_lf_depth_defaults();
    o.min_confidence = -1;
    o.phase_floor = -1;
    return o;
}

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* Splat the reference disparity (and confidence, may be NULL) to a
 * viewpoint offset (du, dv) view steps from the reference (dv scaled). */
static void splat(const float *disp, const float *conf, int w, int h, double du, double dv, double ox, double oy,
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
    /* holes: farthest valid neighbour, grown until none is left */
    for (int pass = 0; pass < w + h; pass++) {
        int left = 0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                if (out[i] > -FLT_MAX)
                    continue;
                float best = FLT_MAX, bc = 0;
                for (int k = 0; k < 4; k++) {
                    int xx = x + (k == 0) - (k == 1), yy = y + (k == 2) - (k == 3);
                    if (xx < 0 || xx >= w || yy < 0 || yy >= h)
                        continue;
                    float v = out[(size_t)yy * w + xx];
                    if (v > -FLT_MAX && v < best)
                        best = v, bc = out_conf ? out_conf[(size_t)yy * w + xx] : 0;
                }
                if (best < FLT_MAX) {
                    /* marked as filled in this pass by storing after the scan would be cleaner;
                     * filling in place only lets the fill run further along the scan */
                    out[i] = best;
                    if (out_conf)
                        out_conf[i] = 0.5f * bc;
                } else {
                    left++;
                }
            }
        if (!left)
            break;
    }
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

#define VS_MAXSRC 16

typedef struct vs_ctx {
    const lf_lightfield *lf;
    int nsrc;
    int iu[VS_MAXSRC], iv[VS_MAXSRC];
    double wv[VS_MAXSRC];         /* angular (tent) weights */
    double du[VS_MAXSRC], dv[VS_MAXSRC]; /* source view minus target, view steps (dv scaled) */
    double ox[VS_MAXSRC], oy[VS_MAXSRC]; /* source minus target pixel offset (calibrated views) */
    const float *dt, *ct; /* target disparity, confidence */
    const float *ds[VS_MAXSRC];   /* source views' warped disparity */
    double phase0;        /* resampling-phase weight floor (<= 0: phase ignored) */
    const float *plane;   /* plane blend, RGB */
    float cmin;
    float *out;
} vs_ctx;

/* Colour of target pixel (x, y) at disparity d from the sources: visible
 * sources (their own warped disparity is not clearly nearer) weighted by
 * angular distance; returns the weighted colour variance across them (a
 * photo-consistency score), or -1 when no source sees the point. */
static double blend_at(const vs_ctx *c, int x, int y, float d, float rgb[3], float all[3], double *seen)
{
    int w = c->lf->ns, h = c->lf->nt;
    double acc[3] = {0, 0, 0}, sq = 0, wsum = 0, acc_all[3] = {0, 0, 0}, wall = 0;
    for (int k = 0; k < c->nsrc; k++) {
        /* I_target(x, y) = I_k(x - d (u_k - u), y - d (v_k - v)) */
        double sx = x - d * c->du[k] + c->ox[k], sy = y - d * c->dv[k] + c->oy[k];
        float col[3];
        sample(lf_lf_view(c->lf, c->iu[k], c->iv[k]), w, h, sx, sy, col);
        float dk = c->ds[k][(size_t)clampi((int)lrint(sy), 0, h - 1) * w + clampi((int)lrint(sx), 0, w - 1)];
        double vis = dk > d + 0.25f + 0.05f * fabsf(d) ? 0.0 : 1.0;
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
            if (dmax - dmin > 0.25f && best >= 0) {
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

int lf_lf_view_depth(const lf_lightfield *lf, double u, double v, const lf_lf_view_opts *o, lf_image *out,
                     lf_error *err)
{
    lf_lf_view_opts def = lf_lf_view_defaults();
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
        return lf_lf_view_at(lf, u, v, 0.0, out, err);
    lf_image disp = {0}, conf = {0};
    int rc;
    if (!o->disparity) {
        lf_lf_depth_opts dopt = o->depth;
        if (dopt.threads <= 0)
            dopt.threads = o->threads;
        if ((rc = lf_lf_depth(lf, &dopt, &disp, &conf, err)))
            return rc;
    }
    const float *D = o->disparity ? o->disparity->data : disp.data;
    const float *C = o->disparity ? (o->confidence ? o->confidence->data : NULL) : conf.data;
    vs_ctx c;
    memset(&c, 0, sizeof c);
    c.lf = lf;
    /* sources: the views within a tent of radius R view steps around the
     * target (R = 1: the 4 nearest, bilinear weights; R = 2: up to 16) */
    double R = o->radius > 0 ? o->radius : 2.0;
    c.phase0 = o->phase_floor < 0 ? 0.05 : o->phase_floor;
    int rr = (int)ceil(R - 1e-9);
    double st[4]; /* the target's (su, sv, ox, oy) */
    lf_lf_view_shift(lf, fu, fv, st);
    for (int iv = (int)floor(fv) - rr + 1; iv <= (int)floor(fv) + rr; iv++)
        for (int iu = (int)floor(fu) - rr + 1; iu <= (int)floor(fu) + rr; iu++) {
            if (iu < 0 || iv < 0 || iu >= lf->nu || iv >= lf->nv || c.nsrc >= VS_MAXSRC)
                continue;
            double wu = 1 - fabs(iu - fu) / R, wvv = 1 - fabs(iv - fv) / R;
            if (wu <= 1e-9 || wvv <= 1e-9)
                continue;
            c.iu[c.nsrc] = iu, c.iv[c.nsrc] = iv, c.wv[c.nsrc] = wu * wvv;
            double sk[4];
            lf_lf_view_shift(lf, iu, iv, sk);
            c.du[c.nsrc] = sk[0] - st[0], c.dv[c.nsrc] = sk[1] - st[1];
            c.ox[c.nsrc] = sk[2] - st[2], c.oy[c.nsrc] = sk[3] - st[3];
            c.nsrc++;
        }
    float *buf = malloc(sizeof(float) * np * (2 + (size_t)c.nsrc));
    lf_image plane = {0};
    if (!buf) {
        lf_image_free(&disp), lf_image_free(&conf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    float *dt = buf, *ct = buf + np;
    splat(D, C, w, h, st[0], st[1], st[2], st[3], dt, ct);
    for (int k = 0; k < c.nsrc; k++) {
        float *dk = buf + (2 + (size_t)k) * np;
        double sk[4];
        lf_lf_view_shift(lf, c.iu[k], c.iv[k], sk);
        splat(D, NULL, w, h, sk[0], sk[1], sk[2], sk[3], dk, NULL);
        c.ds[k] = dk;
    }
    c.dt = dt, c.ct = ct;
    c.cmin = o->min_confidence < 0 ? 0.05f : (float)o->min_confidence;
    if ((rc = lf_lf_view_at(lf, u, v, o->plane_disparity, &plane, err)) || (rc = lf_image_alloc(out, w, h, 3, err))) {
        free(buf), lf_image_free(&plane), lf_image_free(&disp), lf_image_free(&conf);
        return rc ? rc : LF_ERR_NOMEM;
    }
    c.plane = plane.data;
    c.out = out->data;
    lf_parallel_for(h, o->threads, 8, vs_rows, &c);
    free(buf), lf_image_free(&plane), lf_image_free(&disp), lf_image_free(&conf);
    return LF_OK;
}
