/* Semi-global aggregation of the depth cost volume (depth_internal.h;
 * H. Hirschmueller, Stereo processing by semiglobal matching and mutual
 * information, TPAMI 2008).  Along each path r the cost
 *
 *   L_r(p, l) = C(p, l) + min(L_r(p-r, l), L_r(p-r, l+-1) + P1,
 *                             min_k L_r(p-r, k) + P2(p)) - min_k L_r(p-r, k)
 *
 * and the volume becomes sum_r L_r.  Layout: the volume is [label][pixel],
 * so the vertical paths run down and up a band of columns at once (the
 * inner loop over x, contiguous); the horizontal ones transpose a row into
 * [x][label] first.  The vertical sums go to the output volume, the
 * horizontal pass of a row adds its own. */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "lightfield/depth_internal.h"
#include "base/lf_parallel.h"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define LF_HOT_LOOP __attribute__((optimize("-ftree-vectorize", "-fvect-cost-model=dynamic"), target_clones("avx2", "default")))
#else
#define LF_HOT_LOOP
#endif

enum { BAND = 64 }; /* columns per vertical job */

typedef struct sgm_ctx {
    const float *cost;
    float *vsum;
    const float *refs;
    int w, h, L;
    float p1, p2, inv_edge;
    float *scratch;
    size_t per_thread;
} sgm_ctx;

/* P2 between pixels i and j: lower across a colour edge. */
static inline float jump_penalty(const sgm_ctx *c, size_t i, size_t j)
{
    const float *a = c->refs + 3 * i, *b = c->refs + 3 * j;
    float d = 0;
    for (int k = 0; k < 3; k++) {
        float e = a[k] > b[k] ? a[k] - b[k] : b[k] - a[k];
        d = e > d ? e : d;
    }
    float p = c->p2 / (1.f + d * c->inv_edge);
    return p > c->p1 ? p : c->p1;
}

/* One step of the recursion for n lanes: cur[l][x] from prev[l][x] and the
 * lanes' prev minima mp[x] and jump penalties p2[x]; lanes stride apart in
 * cost (n = 1 for a horizontal path). */
LF_HOT_LOOP static void sgm_step(const float *restrict cost, size_t cstride, const float *restrict prev,
                                 float *restrict cur, const float *restrict mp, const float *restrict p2, int n, int L,
                                 float p1)
{
    for (int l = 0; l < L; l++) {
        const float *pl = prev + (size_t)l * n;
        const float *pm = l > 0 ? prev + (size_t)(l - 1) * n : pl;
        const float *pp = l < L - 1 ? prev + (size_t)(l + 1) * n : pl;
        float *cl = cur + (size_t)l * n;
        const float *cc = cost + (size_t)l * cstride;
        for (int x = 0; x < n; x++) {
            float a = pm[x] < pp[x] ? pm[x] : pp[x];
            a += p1;
            float b = mp[x] + p2[x];
            float v = pl[x] < a ? pl[x] : a;
            v = v < b ? v : b;
            cl[x] = cc[x] + v - mp[x];
        }
    }
}

/* The minima over labels of cur[l][x] per lane into mp. */
LF_HOT_LOOP static void lane_min(const float *restrict cur, float *restrict mp, int n, int L)
{
    for (int x = 0; x < n; x++)
        mp[x] = FLT_MAX;
    for (int l = 0; l < L; l++)
        for (int x = 0; x < n; x++)
            mp[x] = cur[(size_t)l * n + x] < mp[x] ? cur[(size_t)l * n + x] : mp[x];
}

/* Down and up paths over columns [b * BAND, ...): their sum into vsum. */
static void sgm_vertical(void *vctx, int b0, int b1, int tid)
{
    sgm_ctx *c = vctx;
    size_t np = (size_t)c->w * c->h;
    float *s = c->scratch + (size_t)tid * c->per_thread;
    for (int b = b0; b < b1; b++) {
        int x0 = b * BAND, n = c->w - x0 < BAND ? c->w - x0 : BAND;
        float *prev = s, *cur = s + (size_t)c->L * n, *mp = s + 2 * (size_t)c->L * n, *p2 = mp + n;
        for (int dir = 0; dir < 2; dir++)
            for (int k = 0; k < c->h; k++) {
                int y = dir == 0 ? k : c->h - 1 - k;
                size_t row = (size_t)y * c->w + x0;
                if (k == 0) {
                    for (int l = 0; l < c->L; l++)
                        memcpy(cur + (size_t)l * n, c->cost + (size_t)l * np + row, sizeof(float) * n);
                } else {
                    size_t prow = row + (dir == 0 ? -(size_t)c->w : (size_t)c->w);
                    for (int x = 0; x < n; x++)
                        p2[x] = jump_penalty(c, row + x, prow + x);
                    sgm_step(c->cost + row, np, prev, cur, mp, p2, n, c->L, c->p1);
                }
                lane_min(cur, mp, n, c->L);
                for (int l = 0; l < c->L; l++) {
                    float *o = c->vsum + (size_t)l * np + row;
                    const float *v = cur + (size_t)l * n;
                    for (int x = 0; x < n; x++)
                        o[x] = dir == 0 ? v[x] : o[x] + v[x];
                }
                float *t = prev;
                prev = cur, cur = t;
            }
    }
}

/* Left and right paths of rows [y0, y1), added to vsum. */
static void sgm_horizontal(void *vctx, int y0, int y1, int tid)
{
    sgm_ctx *c = vctx;
    size_t np = (size_t)c->w * c->h;
    int w = c->w, L = c->L;
    float *s = c->scratch + (size_t)tid * c->per_thread;
    float *T = s, *R = s + (size_t)w * L, *prev = R + (size_t)w * L, *cur = prev + L;
    for (int y = y0; y < y1; y++) {
        size_t row = (size_t)y * w;
        for (int l = 0; l < L; l++)
            for (int x = 0; x < w; x++)
                T[(size_t)x * L + l] = c->cost[(size_t)l * np + row + x];
        for (int dir = 0; dir < 2; dir++) {
            float mp = 0;
            for (int k = 0; k < w; k++) {
                int x = dir == 0 ? k : w - 1 - k;
                const float *cx = T + (size_t)x * L;
                if (k == 0) {
                    memcpy(cur, cx, sizeof(float) * L);
                } else {
                    float p2 = jump_penalty(c, row + x, row + x + (dir == 0 ? -1 : 1));
                    sgm_step(cx, 1, prev, cur, &mp, &p2, 1, L, c->p1);
                }
                lane_min(cur, &mp, 1, L);
                float *r = R + (size_t)x * L;
                for (int l = 0; l < L; l++)
                    r[l] = dir == 0 ? cur[l] : r[l] + cur[l];
                float *t = prev;
                prev = cur, cur = t;
            }
        }
        for (int l = 0; l < L; l++)
            for (int x = 0; x < w; x++)
                c->vsum[(size_t)l * np + row + x] += R[(size_t)x * L + l];
    }
}

int lf_depth_sgm(const float *cost, float *sum, int w, int h, int nlabels, const float *refs, float p1, float p2,
                 float edge, int threads, lf_error *err)
{
    int nt = lf_parallel_threads(threads);
    size_t vneed = 2 * (size_t)nlabels * BAND + 2 * BAND, hneed = 2 * (size_t)w * nlabels + 2 * (size_t)nlabels;
    sgm_ctx c = {
        .cost = cost, .vsum = sum, .refs = refs, .w = w, .h = h, .L = nlabels, .p1 = p1, .p2 = p2,
        .inv_edge = edge > 0 ? 1.f / edge : 0.f, .per_thread = vneed > hneed ? vneed : hneed,
    };
    c.scratch = malloc(sizeof(float) * c.per_thread * (size_t)nt);
    if (!c.scratch)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for semi-global aggregation (%d labels)", nlabels);
    lf_parallel_for((w + BAND - 1) / BAND, threads, 1, sgm_vertical, &c);
    lf_parallel_for(h, threads, 4, sgm_horizontal, &c);
    free(c.scratch);
    return LF_OK;
}
