/* depth_range.c - the full-resolution check of an estimated disparity
 * range (docs/depth.md, "The range checked at full resolution").
 *
 * The range is estimated on views reduced 4 x 4, where checks of 2.5-3 px
 * are gone and what is left matches anywhere: the estimate can then miss
 * the truth.  At full resolution the views' different baselines leave the
 * true disparity as the one minimum they share (Okutomi and Kanade's
 * multi-baseline argument).  Two things keep false minima out:
 * - the same views at every label: a sample sweeps only the disparities at
 *   which every view's lookup stays inside the image, so a label is never
 *   scored on fewer views than its neighbours (fine texture finds
 *   decisive-looking minima where only a few views remain);
 * - a minimum confirmed by its neighbourhood: a sample counts only when
 *   two or more of its 8 neighbours on the sample grid found the same
 *   disparity within a tolerance, confidently. */
#include "lightfield/depth_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_parallel.h"

enum { RC_GRID = 24, RC_WIN = 1 }; /* sample spacing; window half size (3 x 3) */
static const float RC_TRUNC = 0.5f;        /* truncation of a view's grey difference, in mean levels */
static const float RC_CONFIDENT = 0.3f;    /* a sample's confidence to count */
static const double RC_AGREE_PX = 1.0;     /* neighbours agree within this many px at the outermost view */
static const int RC_MIN_COUNT = 20;        /* confirmed samples needed to widen anything */

typedef struct rc_view {
    const float *grey, *valid; /* the view's mean of R, G, B; its missing samples (or NULL) */
    double du, dv, ox, oy;
} rc_view;

typedef struct rc_ctx {
    const lf_lightfield *lf;
    const rc_view *views;
    int nviews, gx, gy;
    double lim, step, scale;
    const float *ref, *ref_valid; /* the reference, grey */
    float *win;  /* per sample: winning disparity, or NAN */
    float *conf; /* per sample: confidence */
} rc_ctx;

/* A view on a row, column or diagonal through the reference (not it). */
static int is_star(int du, int dv)
{
    return (du || dv) && (!du || !dv || abs(du) == abs(dv));
}

static void to_grey(const float *rgb, float *g, size_t np)
{
    for (size_t i = 0; i < np; i++)
        g[i] = (rgb[3 * i] + rgb[3 * i + 1] + rgb[3 * i + 2]) * (1.f / 3.f);
}

/* The largest |d| at which every view's 3 x 3 window around (x, y) is
 * looked up inside the image (bilinear: x - d du + ox in [0, ns - 2]). */
static double sample_reach(const rc_ctx *c, int x, int y)
{
    const lf_lightfield *lf = c->lf;
    double reach = c->lim;
    for (int k = 0; k < c->nviews; k++) {
        const rc_view *v = &c->views[k];
        double xs[2] = {x - RC_WIN + v->ox, x + RC_WIN + v->ox}, ys[2] = {y - RC_WIN + v->oy, y + RC_WIN + v->oy};
        double lo[2] = {0, 0}, hi[2] = {lf->ns - 2, lf->nt - 2}, dd[2] = {v->du, v->dv};
        for (int a = 0; a < 2; a++) {
            const double *p = a ? ys : xs;
            double s = dd[a];
            if (s == 0) {
                if (p[0] < lo[a] || p[1] > hi[a])
                    return 0;
                continue;
            }
            /* p - d s stays in [lo, hi] for |d| <= r */
            double r0 = (p[0] - lo[a]) / fabs(s), r1 = (hi[a] - p[1]) / fabs(s);
            double r = r0 < r1 ? r0 : r1;
            reach = r < reach ? r : reach;
        }
    }
    return reach > 0 ? reach : 0;
}

static void rc_samples(void *vctx, int i0, int i1, int tid)
{
    (void)tid;
    rc_ctx *c = vctx;
    const lf_lightfield *lf = c->lf;
    int ns = lf->ns;
    for (int i = i0; i < i1; i++) {
        int gx = i % c->gx, gy = i / c->gx;
        int x = RC_GRID / 2 + gx * RC_GRID, y = RC_GRID / 2 + gy * RC_GRID;
        c->win[i] = NAN, c->conf[i] = 0.f;
        double reach = sample_reach(c, x, y);
        int half = (int)floor(reach / c->step);
        if (half < LF_DEPTH_CONFIDENCE_AWAY + 2)
            continue;
        if (c->ref_valid) {
            int ok = 1;
            for (int j = -RC_WIN; j <= RC_WIN; j++)
                for (int q = -RC_WIN; q <= RC_WIN; q++)
                    ok = ok && c->ref_valid[(size_t)(y + j) * ns + x + q] > 0.5f;
            if (!ok)
                continue;
        }
        int L = 2 * half + 1, best = -1, nbad = 0;
        float *cost = malloc(sizeof(float) * (size_t)L);
        if (!cost)
            continue; /* a sample less; the check only ever widens */
        double sum = 0;
        for (int l = 0; l < L; l++) {
            double d = (l - half) * c->step, acc = 0;
            int n = 0;
            for (int k = 0; k < c->nviews; k++) {
                const rc_view *v = &c->views[k];
                double sx0 = -d * v->du + v->ox, sy0 = -d * v->dv + v->oy;
                int ix = (int)floor(sx0), iy = (int)floor(sy0);
                float fx = (float)(sx0 - ix), fy = (float)(sy0 - iy);
                float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
                for (int j = -RC_WIN; j <= RC_WIN; j++)
                    for (int q = -RC_WIN; q <= RC_WIN; q++) {
                        size_t p00 = (size_t)(y + j + iy) * ns + (size_t)(x + q + ix), p10 = p00 + (size_t)ns;
                        if (v->valid && w00 * v->valid[p00] + w01 * v->valid[p00 + 1] + w10 * v->valid[p10] +
                                                w11 * v->valid[p10 + 1] < 0.999f) {
                            nbad++;
                            continue;
                        }
                        const float *g = v->grey;
                        float val = w00 * g[p00] + w01 * g[p00 + 1] + w10 * g[p10] + w11 * g[p10 + 1];
                        float ad = fabsf(val - c->ref[(size_t)(y + j) * ns + (size_t)(x + q)]) * (float)c->scale;
                        acc += ad < RC_TRUNC ? ad : RC_TRUNC;
                        n++;
                    }
            }
            cost[l] = n ? (float)(acc / n) : FLT_MAX;
            sum += cost[l] < FLT_MAX ? cost[l] : RC_TRUNC;
            if (best < 0 || cost[l] < cost[best])
                best = l;
        }
        /* missing samples change the views' set from label to label */
        if (nbad == 0 && best > 0 && best < L - 1) {
            float conf = lf_depth_curve_confidence(cost, 1, L, best, (float)sum);
            double cm = cost[best - 1], c0 = cost[best], cp = cost[best + 1], den = cm - 2 * c0 + cp;
            double off = den > 1e-12 ? 0.5 * (cm - cp) / den : 0;
            off = off < -0.5 ? -0.5 : (off > 0.5 ? 0.5 : off);
            c->win[i] = (float)((best - half + off) * c->step);
            c->conf[i] = conf;
        }
        free(cost);
    }
}

int lf_depth_range_check(const lf_lightfield *lf, int threads, double lim, double m, double *d0, double *d1,
                         lf_depth_range_check_info *info, lf_error *err)
{
    memset(info, 0, sizeof *info);
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    int gx = (lf->ns - RC_GRID / 2 - RC_WIN) / RC_GRID, gy = (lf->nt - RC_GRID / 2 - RC_WIN) / RC_GRID;
    if (gx < 3 || gy < 3 || m <= 0 || !(lim > 0))
        return LF_OK; /* too small to say anything */
    /* the views on the rows, columns and diagonals through the reference
     * (the star): baselines of every length along 4 directions are what
     * the multi-baseline argument needs, at 32 of a 9 x 9 grid's 80 views */
    int nv = 0;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++)
            nv += is_star(iu - iu0, iv - iv0);
    size_t np = (size_t)lf->ns * lf->nt;
    rc_view *views = malloc(sizeof *views * (size_t)(nv ? nv : 1));
    float *win = malloc(sizeof(float) * 2 * (size_t)gx * gy);
    float *vals = malloc(sizeof(float) * (size_t)gx * gy);
    float *grey = malloc(sizeof(float) * np * (size_t)(nv + 1));
    if (!views || !win || !vals || !grey) {
        free(views), free(win), free(vals), free(grey);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    int n = 0;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            if (!is_star(iu - iu0, iv - iv0))
                continue;
            rc_view *v = &views[n];
            to_grey(lf_lightfield_view(lf, iu, iv), grey + (size_t)(n + 1) * np, np);
            v->grey = grey + (size_t)(n + 1) * np;
            n++;
            v->valid = lf->valid ? lf->valid + ((size_t)iv * lf->nu + iu) * np : NULL;
            double off[4];
            lf_depth_view_offset(lf, iu, iv, off);
            v->du = off[0], v->dv = off[1], v->ox = off[2], v->oy = off[3];
        }
    const float *ref = grey;
    to_grey(lf_lightfield_view(lf, iu0, iv0), grey, np);
    double msum = 0;
    for (size_t i = 0; i < np; i++)
        msum += ref[i];
    msum /= (double)np;
    rc_ctx c = {
        .lf = lf,
        .views = views,
        .nviews = n,
        .gx = gx,
        .gy = gy,
        .lim = lim,
        .step = 0.5 / m, /* half a pixel at the outermost view */
        .scale = msum > 1e-12 ? 1.0 / msum : 1.0,
        .ref = ref,
        .ref_valid = lf->valid ? lf->valid + ((size_t)iv0 * lf->nu + iu0) * np : NULL,
        .win = win,
        .conf = win + (size_t)gx * gy,
    };
    if (n > 0)
        lf_parallel_for(gx * gy, threads, 1, rc_samples, &c);
    /* confirmed: confident, and 2 or more of the 8 grid neighbours
     * confidently within RC_AGREE_PX at the outermost view */
    size_t nc = 0;
    double tol = RC_AGREE_PX / m;
    for (int y = 0; y < gy; y++)
        for (int x = 0; x < gx; x++) {
            size_t i = (size_t)y * gx + x;
            if (!(c.conf[i] >= RC_CONFIDENT) || isnan(win[i]))
                continue;
            int agree = 0;
            for (int j = -1; j <= 1; j++)
                for (int q = -1; q <= 1; q++) {
                    int xx = x + q, yy = y + j;
                    if ((!j && !q) || xx < 0 || yy < 0 || xx >= gx || yy >= gy)
                        continue;
                    size_t k = (size_t)yy * gx + xx;
                    agree += c.conf[k] >= RC_CONFIDENT && fabsf(win[k] - win[i]) <= tol;
                }
            if (agree >= 2)
                vals[nc++] = win[i];
        }
    info->samples = gx * gy, info->confirmed = (int)nc;
    if (nc >= (size_t)RC_MIN_COUNT) {
        qsort(vals, nc, sizeof(float), lf_depth_cmpf);
        double lo = vals[(size_t)(0.01 * (double)(nc - 1))], hi = vals[(size_t)(0.99 * (double)(nc - 1))];
        double pad = 0.05 * (hi - lo) + 2 * c.step;
        info->lo = lo, info->hi = hi;
        if (lo < *d0)
            *d0 = lo - pad, info->widened = 1;
        if (hi > *d1)
            *d1 = hi + pad, info->widened = 1;
    }
    free(views), free(win), free(vals), free(grey);
    return LF_OK;
}
