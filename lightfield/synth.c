/* CS348B light-field synthesis: a virtual thin-lens camera anywhere in space
 * renders from a camera-array light field (Levoy & Hanrahan 1996; the
 * virtual focal plane follows Isaksen, McMillan & Gortler 2000).
 *
 * Speed (docs/lftool.md, Benchmarks): samples go through in groups of 4, one
 * per lane of a 4-float vector (GCC/Clang vector extensions: SSE2 on x86-64,
 * plain code elsewhere).  The geometry runs in float in grid-relative
 * coordinates (origin at the grid's top-left camera, y down), so positions
 * stay small; the per-pixel film position is added in double first.  Random
 * numbers are counter-based (splitmix64 of the pixel's key), rows are handed
 * to the threads one at a time (base/lf_parallel.h), and texels are read from the views in place
 * (RGB interleaved per row) with 4-float loads. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_parallel.h"
#include "lf_lightfield.h"

lf_lightfield_synth_opts lf_lightfield_synth_defaults(void)
{
    lf_lightfield_synth_opts o;
    memset(&o, 0, sizeof o);
    o.spp = 1;
    o.seed = 1;
    return o;
}

typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));

enum { SYNTH_GROUPS = 4, SYNTH_BATCH = 4 * SYNTH_GROUPS }; /* samples set up before their lookups */

typedef struct synth_ctx {
    const lf_lightfield *lf;
    const lf_lightfield_synth_opts *o;
    double R[9];                   /* virtual camera to grid space */
    double in_tan, in_half;        /* data cameras: tan(fov/2), half shorter side (px) */
    double in_scale;               /* in_half / in_tan */
    double out_tan, out_half;      /* virtual camera */
    double minx, maxy, bx, by;     /* camera grid */
    double inv_bx, inv_by;
    /* Grid-relative space: x - minx, maxy - y, z (camera (i, j) at (i bx, j by, 0)).
     * Focal point (finite focus) or ray direction (infinity) of film
     * position (sx, sy) px: F0 + sx FX + sy FY; lens point (lx, ly) on the
     * unit disk: pos + lx LX + ly LY (lens radius folded in). */
    double F0[3], FX[3], FY[3], pos[3];
    float fFX[3], fFY[3], fLX[3], fLY[3], fpos[3];
    float fns, fnt, fbx, fby, finv_bx, finv_by, fscale;
    size_t view_texels;            /* ns * nt */
    size_t last_texel;             /* texels in lf->data - 1: the one a 4-float load must not start at */
    size_t cam_view[4];            /* view index steps to the 4 cameras (0 along a 1-wide grid) */
    size_t cam_texel[4];           /* the same in texels */
    lf_image *out, *cov;
    float *strata[LF_PARALLEL_MAX_THREADS]; /* per thread: film strata FU, FV, FW and the lens permutation */
    size_t uncovered[LF_PARALLEL_MAX_THREADS]; /* per thread: pixels with no covered sample */
    /* per-pixel geometry (o->disparity): reference camera, map range */
    const float *disp;
    double ref_x, ref_y;           /* reference camera, grid-relative */
    float dmin, dmax;
} synth_ctx;

static inline uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
/* counter-based stream: value n of key s is mix64(s + n * golden) (splitmix64) */
static inline uint64_t next64(uint64_t *s) { return mix64(*s += 0x9e3779b97f4a7c15ull); }

static inline v4f vsplat(float a) { return (v4f){a, a, a, a}; }
static inline v4f vsel(v4i m, v4f a, v4f b) { return (v4f)(((v4i)a & m) | ((v4i)b & ~m)); }
static inline v4f vmin(v4f a, v4f b) { return vsel(a < b, a, b); }
static inline v4f vmax(v4f a, v4f b) { return vsel(a > b, a, b); }
static inline v4f vload(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* Shirley's concentric square-to-disk map of (a, b) in [0,1)^2, 4 lanes;
 * sin and cos on [-pi/4, pi/4] by Taylor polynomials (errors < 3e-7). */
static inline void concentric4(v4f a, v4f b, v4f *x, v4f *y)
{
    const v4f one = vsplat(1), zero = vsplat(0);
    a = a * 2 - one, b = b * 2 - one;
    v4f aa = vmax(a, -a), ab = vmax(b, -b);
    v4i wide = aa > ab; /* |a| > |b|: theta = pi/4 b/a from the x axis, else from the y axis */
    v4f num = vsel(wide, b, a), r = vsel(wide, a, b);
    v4f q = num / vsel(r != zero, r, one); /* r == 0 only at the centre (a = b = 0) */
    v4f th = q * (float)(M_PI / 4), t2 = th * th;
    v4f sn = th * (one - t2 * (1.f / 6) * (one - t2 * (1.f / 20) * (one - t2 * (1.f / 42) * (one - t2 * (1.f / 72)))));
    v4f cs = one - t2 * 0.5f * (one - t2 * (1.f / 12) * (one - t2 * (1.f / 30) * (one - t2 * (1.f / 56) * (one - t2 * (1.f / 90)))));
    *x = r * vsel(wide, cs, sn), *y = r * vsel(wide, sn, cs);
}

/* Four samples after the geometry: lane = sample.  hit: the ray meets the
 * camera plane inside the grid; camera c = (i0 + (c & 1), j0 + (c >> 1)) of
 * lane s sees the focal point at pixel (P + (c & 1) SX, Q + (c >> 1) SY) of
 * its view (0..ns, 0..nt being the view's edges) with weight w[c] (0 when
 * not hit, or for cameras off a 1-wide grid). */
typedef struct synth_group {
    v4f P, Q, SX, SY, w[4];
    v4i view; /* index of view (i0, j0) */
} synth_group;

/* Disparity of the reference view at pixel position (px, py) (0..ns edges),
 * bilinear between texel centres; < 0 outside the view. */
static inline float ref_disparity(const synth_ctx *c, float px, float py)
{
    const int ns = c->lf->ns, nt = c->lf->nt;
    if (!(px >= 0 && py >= 0 && px <= (float)ns && py <= (float)nt))
        return -1.f;
    float xi = fminf(fmaxf(px - 0.5f, 0), (float)(ns - 1)), yi = fminf(fmaxf(py - 0.5f, 0), (float)(nt - 1));
    int x0 = (int)xi, y0 = (int)yi, x1 = x0 + 1 < ns ? x0 + 1 : x0, y1 = y0 + 1 < nt ? y0 + 1 : y0;
    float fx = xi - (float)x0, fy = yi - (float)y0;
    const float *d = c->disp;
    return (1 - fy) * ((1 - fx) * d[(size_t)y0 * ns + x0] + fx * d[(size_t)y0 * ns + x1]) +
           fy * ((1 - fx) * d[(size_t)y1 * ns + x0] + fx * d[(size_t)y1 * ns + x1]);
}

/* First hit of the line o + t dir (t > 0) with the surface of the reference
 * disparity map (grid-relative space; disparity d <-> depth fscale bx / d):
 * marched from the nearest to the farthest disparity of the map, the
 * crossing interpolated linearly.  Returns 0 when the ray meets no surface
 * (then *hit is untouched). */
static int depth_hit(const synth_ctx *c, const double o[3], const double dir[3], double hit[3])
{
    if (!(fabs(dir[2]) > 1e-12))
        return 0;
    const double k = c->in_scale * c->bx; /* d = k / z */
    const double step = 0.05;
    double prev_gap = 0, prev_d = 0;
    int have_prev = 0;
    for (double d = c->dmax + step; d >= c->dmin - step; d -= step) {
        double dd = d > 1e-3 ? d : 1e-3, z = k / dd, t = (z - o[2]) / dir[2];
        if (t <= 0) {
            have_prev = 0;
            continue;
        }
        double x = o[0] + t * dir[0], y = o[1] + t * dir[1];
        float ds = ref_disparity(c, (float)(c->lf->ns * 0.5 + (x - c->ref_x) * c->in_scale / z),
                                 (float)(c->lf->nt * 0.5 + (y - c->ref_y) * c->in_scale / z));
        if (ds < -0.5f) { /* outside the reference view */
            have_prev = 0;
            continue;
        }
        double gap = d - ds; /* > 0: the ray point is in front of the surface */
        if (gap <= 0) {
            double dh = have_prev ? prev_d - prev_gap * (d - prev_d) / (gap - prev_gap) : d;
            dh = dh > 1e-3 ? dh : 1e-3;
            double zh = k / dh, th = (zh - o[2]) / dir[2];
            hit[0] = o[0] + th * dir[0], hit[1] = o[1] + th * dir[1], hit[2] = zh;
            return 1;
        }
        prev_gap = gap, prev_d = d, have_prev = 1;
    }
    return 0;
}

/* Geometry of 4 samples: film offsets (jx, jy) px from pixel (x, y), whose
 * focal point (or direction) Fp is given; lens points (lx, ly) on the unit
 * disk; lanes with live == 0 are not samples. */
static inline void group_setup(const synth_ctx *c, int finite_focus, const float Fp[3], v4f jx, v4f jy, v4f lx,
                               v4f ly, v4i live, synth_group *g)
{
    const lf_lightfield *lf = c->lf;
    const v4f zero = vsplat(0), one = vsplat(1);
    v4f f0 = Fp[0] + jx * c->fFX[0] + jy * c->fFY[0];
    v4f f1 = Fp[1] + jx * c->fFX[1] + jy * c->fFY[1];
    v4f f2 = Fp[2] + jx * c->fFX[2] + jy * c->fFY[2];
    v4f cx, cy, A;
    v4i hit;
    if (c->disp) {
        /* per-pixel geometry: the surface point replaces the focal point */
        for (int s = 0; s < 4; s++) {
            double o[3], dir[3], h[3];
            for (int a = 0; a < 3; a++) {
                float fa = a == 0 ? f0[s] : (a == 1 ? f1[s] : f2[s]);
                float la = a == 0 ? c->fLX[0] * lx[s] + c->fLY[0] * ly[s]
                                  : (a == 1 ? c->fLX[1] * lx[s] + c->fLY[1] * ly[s] : c->fLX[2] * lx[s] + c->fLY[2] * ly[s]);
                o[a] = c->fpos[a] + la;
                dir[a] = finite_focus ? fa - o[a] : fa;
            }
            if (live[s] && depth_hit(c, o, dir, h)) {
                f0[s] = (float)h[0], f1[s] = (float)h[1], f2[s] = (float)h[2];
            } else if (!finite_focus && fabs(dir[2]) > 1e-12) { /* no surface: the far end of the map */
                double z = c->in_scale * c->bx / (c->dmin > 1e-3 ? c->dmin : 1e-3), t = (z - o[2]) / dir[2];
                f0[s] = (float)(o[0] + t * dir[0]), f1[s] = (float)(o[1] + t * dir[1]), f2[s] = (float)z;
            }
        }
        finite_focus = 1;
    }
    if (finite_focus) {
        /* origin on the lens, through the focal point f */
        v4f o0 = c->fpos[0] + lx * c->fLX[0] + ly * c->fLY[0];
        v4f o1 = c->fpos[1] + lx * c->fLX[1] + ly * c->fLY[1];
        v4f o2 = c->fpos[2] + lx * c->fLX[2] + ly * c->fLY[2];
        v4f d0 = f0 - o0, d1 = f1 - o1, d2 = f2 - o2;
        hit = live & (d2 != zero) & (f2 > vsplat(1e-12f));
        v4f inv = one / vsel(hit, d2 * f2, one); /* one division for 1/d2 and 1/f2 */
        v4f t = -o2 * f2 * inv;
        cx = o0 + t * d0, cy = o1 + t * d1;
        A = c->fscale * d2 * inv; /* the focal point is at the same depth for every data camera */
    } else {
        /* pinhole at pos, direction f: every camera looks the direction up */
        hit = live & (f2 > vsplat(1e-12f));
        v4f inv = one / vsel(hit, f2, one);
        cx = c->fpos[0] - c->fpos[2] * f0 * inv, cy = c->fpos[1] - c->fpos[2] * f1 * inv;
        A = c->fscale * inv;
    }
    /* grid cell; eps: rays on the outer cameras stay in despite float rounding */
    const float eps = 1e-5f;
    v4f fi = zero, fj = zero, i0 = zero, j0 = zero, ax = zero, ay = zero;
    if (lf->nu > 1) {
        fi = cx * c->finv_bx;
        hit &= (fi >= vsplat(-eps)) & (fi <= vsplat(lf->nu - 1 + eps));
        i0 = __builtin_convertvector(__builtin_convertvector(vmin(vmax(fi, zero), vsplat((float)(lf->nu - 2))), v4i), v4f);
        ax = vmin(vmax(fi - i0, zero), one);
    }
    if (lf->nv > 1) {
        fj = cy * c->finv_by;
        hit &= (fj >= vsplat(-eps)) & (fj <= vsplat(lf->nv - 1 + eps));
        j0 = __builtin_convertvector(__builtin_convertvector(vmin(vmax(fj, zero), vsplat((float)(lf->nv - 2))), v4i), v4f);
        ay = vmin(vmax(fj - j0, zero), one);
    }
    if (finite_focus) {
        /* camera (i, j) at (i bx, j by) sees f at ns/2 + (f0 - i bx) A, nt/2 + (f1 - j by) A; a 1-wide grid's
         * camera follows the ray's crossing */
        v4f X0 = lf->nu > 1 ? i0 * c->fbx : cx, Y0 = lf->nv > 1 ? j0 * c->fby : cy;
        g->P = c->fns * 0.5f + (f0 - X0) * A, g->SX = -c->fbx * A;
        g->Q = c->fnt * 0.5f + (f1 - Y0) * A, g->SY = -c->fby * A;
    } else {
        g->P = c->fns * 0.5f + f0 * A, g->SX = zero;
        g->Q = c->fnt * 0.5f + f1 * A, g->SY = zero;
    }
    /* lanes not hit: position 0, weight 0 (NaN and infinities stay out) */
    g->P = vsel(hit, g->P, zero), g->Q = vsel(hit, g->Q, zero);
    g->SX = vsel(hit, g->SX, zero), g->SY = vsel(hit, g->SY, zero);
    v4f bx = one - ax, by = one - ay;
    g->w[0] = vsel(hit, bx * by, zero), g->w[1] = vsel(hit, ax * by, zero);
    g->w[2] = vsel(hit, bx * ay, zero), g->w[3] = vsel(hit, ax * ay, zero);
    g->view = __builtin_convertvector(j0 * (float)lf->nu + i0, v4i); /* exact below 2^24 views */
    if (c->disp) {
        /* visibility: a data camera whose line of sight to the surface point
         * meets a clearly nearer surface first sees an occluder there; it
         * drops out and the others' weights are renormalised */
        const double k = c->in_scale * c->bx;
        for (int s = 0; s < 4; s++) {
            if (!hit[s])
                continue;
            double S[3] = {f0[s], f1[s], f2[s]}, dS = k / S[2], wsum = 0, wvis = 0;
            float keep[4];
            for (int q = 0; q < 4; q++) {
                keep[q] = 1.f;
                float wq = g->w[q][s];
                wsum += wq;
                if (!(wq > 0))
                    continue;
                double C[3] = {(lf->nu > 1 ? i0[s] * c->bx : cx[s]) + ((q & 1) && lf->nu > 1 ? c->bx : 0),
                               (lf->nv > 1 ? j0[s] * c->by : cy[s]) + ((q & 2) && lf->nv > 1 ? c->by : 0), 0};
                double dir[3] = {S[0] - C[0], S[1] - C[1], S[2] - C[2]}, h[3];
                if (depth_hit(c, C, dir, h) && k / h[2] > dS + 0.15 + 0.05 * fabs(dS))
                    keep[q] = 0.f;
                wvis += wq * keep[q];
            }
            if (wvis > 0 && wvis < wsum)
                for (int q = 0; q < 4; q++)
                    g->w[q][s] = g->w[q][s] * keep[q] * (float)(wsum / wvis);
        }
    }
}

/* Data camera view `view` (mask m) at pixel (px, py), 0 <= px <= ns and
 * 0 <= py <= nt: bilinear over its valid texels (clamped to the outer
 * texel centres, never a neighbour's).  Returns 0 when none has weight. */
static int lookup_masked(const synth_ctx *c, size_t view, float px, float py, float rgb[3])
{
    const lf_lightfield *lf = c->lf;
    const int ns = lf->ns, nt = lf->nt;
    float xi = fminf(fmaxf(px - 0.5f, 0), (float)(ns - 1)), yi = fminf(fmaxf(py - 0.5f, 0), (float)(nt - 1));
    int x0 = (int)xi, y0 = (int)yi;
    float fx = xi - (float)x0, fy = yi - (float)y0;
    size_t t[4];
    t[0] = view * c->view_texels + (size_t)y0 * ns + x0;
    t[1] = t[0] + (x0 + 1 < ns), t[2] = t[0] + (y0 + 1 < nt ? (size_t)ns : 0), t[3] = t[2] + (x0 + 1 < ns);
    float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy}, s = 0;
    for (int k = 0; k < 4; k++)
        s += w[k] *= lf->valid[t[k]];
    if (!(s > 0))
        return 0;
    for (int ch = 0; ch < 3; ch++) {
        float v = 0;
        for (int k = 0; k < 4; k++)
            v += w[k] * lf->data[t[k] * 3 + ch];
        rgb[ch] = v / s;
    }
    return 1;
}

/* Adds the radiance of a group's covered samples to acc (lanes 0..2: RGB);
 * returns how many samples were covered.  Each data camera that sees the
 * focal point is looked up bilinearly inside its own tile; the cameras'
 * weights are renormalised over those that see it. */
static inline int group_gather(const synth_ctx *c, const synth_group *g, v4f acc[4])
{
    const lf_lightfield *lf = c->lf;
    const v4f zero = vsplat(0), one = vsplat(1), fns = vsplat(c->fns), fnt = vsplat(c->fnt);
    v4f px[4], py[4], w[4], wsum = zero;
    v4i ok[4], dropped = {0, 0, 0, 0};
    for (int k = 0; k < 4; k++) {
        px[k] = k & 1 ? g->P + g->SX : g->P;
        py[k] = k & 2 ? g->Q + g->SY : g->Q;
        v4i had = g->w[k] > zero;
        ok[k] = had & (px[k] >= zero) & (px[k] <= fns) & (py[k] >= zero) & (py[k] <= fnt);
        w[k] = vsel(ok[k], g->w[k], zero);
        wsum += w[k];
        dropped |= had & ~ok[k];
    }
    if (lf->valid) { /* rare: per sample, dropping cameras that see only invalid texels */
        int n = 0;
        for (int s = 0; s < 4; s++) {
            float a[3] = {0, 0, 0}, ws = 0;
            for (int k = 0; k < 4; k++) {
                float rgb[3];
                if (!ok[k][s] || !lookup_masked(c, (size_t)g->view[s] + c->cam_view[k], px[k][s], py[k][s], rgb))
                    continue;
                for (int ch = 0; ch < 3; ch++)
                    a[ch] += w[k][s] * rgb[ch];
                ws += w[k][s];
            }
            if (ws > 0) {
                for (int ch = 0; ch < 3; ch++)
                    acc[0][ch] += a[ch] / ws;
                n++;
            }
        }
        return n;
    }
    v4i cov = wsum > zero;
    /* renormalise only samples that dropped a camera (else the weights sum to 1) */
    v4f scale = vsel(dropped, one / vsel(cov, wsum, one), one);
    const float *d = c->lf->data;
    size_t base[4]; /* first texel of view (i0, j0) */
    for (int s = 0; s < 4; s++)
        base[s] = (size_t)g->view[s] * c->view_texels;
    for (int k = 0; k < 4; k++) {
        if (!(ok[k][0] | ok[k][1] | ok[k][2] | ok[k][3]))
            continue;
        /* clamped to the outer texel centres; lanes not looked up stay in range too */
        v4f xi = vmin(vmax(px[k] - 0.5f, zero), fns - one), yi = vmin(vmax(py[k] - 0.5f, zero), fnt - one);
        v4i x0 = __builtin_convertvector(xi, v4i), y0 = __builtin_convertvector(yi, v4i);
        v4f fx = xi - __builtin_convertvector(x0, v4f), fy = yi - __builtin_convertvector(y0, v4f);
        v4f ws = w[k] * scale, gx = one - fx, gy = one - fy;
        v4f a00 = gx * gy * ws, a10 = fx * gy * ws, a01 = gx * fy * ws, a11 = fx * fy * ws;
        v4i off = y0 * lf->ns + x0;                                       /* texel (x0, y0) in its view */
        v4i dx = (x0 < lf->ns - 1) & 1, dy = (y0 < lf->nt - 1) & lf->ns; /* to (x0 + 1, y0 + 1), clamped */
        v4f sum = zero;
#pragma GCC unroll 4
        for (int s = 0; s < 4; s++) {
            if (!ok[k][s])
                continue;
            size_t t00 = base[s] + c->cam_texel[k] + (size_t)off[s];
            size_t t10 = t00 + (size_t)dx[s], t01 = t00 + (size_t)dy[s], t11 = t01 + (size_t)dx[s];
            if (t11 < c->last_texel) { /* 4-float loads; the 4th lane (next texel's red) is never stored */
                sum += vload(d + t00 * 3) * a00[s] + vload(d + t10 * 3) * a10[s] + vload(d + t01 * 3) * a01[s] +
                       vload(d + t11 * 3) * a11[s];
            } else { /* the last texel of the last view: no float after it */
                float v[4] = {0, 0, 0, 0};
                for (int ch = 0; ch < 3; ch++)
                    v[ch] = d[t00 * 3 + ch] * a00[s] + d[t10 * 3 + ch] * a10[s] + d[t01 * 3 + ch] * a01[s] +
                            d[t11 * 3 + ch] * a11[s];
                sum += vload(v);
            }
        }
        acc[k] += sum;
    }
    return -(cov[0] + cov[1] + cov[2] + cov[3]);
}

/* The stratum table of spp samples (padded to a multiple of 4): film
 * strata in order (column FU, row FV, width FW), then room for the lens
 * strata's per-pixel permutation.  m columns by rows = ceil(spp / m)
 * strata; a last, partial row spreads its samples over the full width, so
 * every spp covers the pixel (and the lens) uniformly.  NULL: no memory. */
static float *strata_new(int spp)
{
    const int spp4 = (spp + 3) & ~3, m = (int)ceil(sqrt((double)spp)), rows = (spp + m - 1) / m;
    float *FU = malloc(sizeof(float) * (size_t)spp4 * 4);
    if (!FU)
        return NULL;
    float *FV = FU + spp4, *FW = FV + spp4;
    uint32_t *perm = (uint32_t *)(FW + spp4);
    for (int k = 0; k < spp4; k++) {
        int row = k / m, in_row = spp - row * m < m ? spp - row * m : m;
        if (in_row < 1)
            in_row = 1; /* padding lanes past spp */
        FW[k] = 1.0f / (float)in_row;
        FU[k] = (float)(k % m) * FW[k];
        FV[k] = (float)row / (float)rows;
        perm[k] = 0;
    }
    return FU;
}

/* Rows [y0, y1) on thread tid (lf_parallel_fn). */
static void synth_rows(void *arg, int y0, int y1, int tid)
{
    synth_ctx *c = arg;
    const lf_lightfield_synth_opts *o = c->o;
    const int spp = o->spp > 0 ? o->spp : 1, spp4 = (spp + 3) & ~3;
    const int m = (int)ceil(sqrt((double)spp)), rows = (spp + m - 1) / m;
    const float u24 = 1.0f / 16777216.0f;
    const int finite_focus = o->focal_distance > 0, lens = o->lens_radius > 0;
    /* lens strata: a random permutation of the film strata per pixel, so
     * film and lens positions are uncorrelated */
    float *FU = c->strata[tid], *FV = FU + spp4, *FW = FV + spp4;
    uint32_t *perm = (uint32_t *)(FW + spp4);
    const float inv_rows = 1.0f / (float)rows;
    synth_group groups[SYNTH_GROUPS];
    const v4i lane = {0, 1, 2, 3};
    const v4f half = vsplat(0.5f);
    for (int y = y0; y < y1; y++) {
        float *row = lf_image_px(c->out, 0, y);
        for (int x = 0; x < o->width; x++) {
            /* counter-based: the pixel's stream depends on (seed, x, y) only */
            uint64_t st = mix64(((uint64_t)o->seed << 40) ^ ((uint64_t)y << 20) ^ (uint64_t)x);
            if (spp > 1 && lens) {
                for (int k = 0; k < spp; k++)
                    perm[k] = (uint32_t)k;
                uint64_t r = 0;
                for (int k = spp - 1, have = 0; k > 0; k--) { /* Fisher-Yates, 32 bits a draw */
                    if (!have)
                        r = next64(&st), have = 2;
                    uint32_t q = (uint32_t)(((r & 0xffffffffu) * (uint64_t)(k + 1)) >> 32), tmp = perm[k];
                    r >>= 32, have--;
                    perm[k] = perm[q], perm[q] = tmp;
                }
            }
            /* focal point (or direction) of the pixel's corner, in double, then float */
            float Fp[3];
            for (int a = 0; a < 3; a++)
                Fp[a] = (float)(c->F0[a] + x * c->FX[a] + y * c->FY[a]);
            double total[3] = {0, 0, 0};
            int covered = 0;
            for (int k0 = 0; k0 < spp; k0 += SYNTH_BATCH) {
                int n = spp - k0 < SYNTH_BATCH ? spp - k0 : SYNTH_BATCH, ng = (n + 3) / 4;
                for (int q = 0; q < ng; q++) {
                    const int kq = k0 + 4 * q;
                    v4i live = lane < n - 4 * q;
                    v4f jx = half, jy = half, lx = vsplat(0), ly = vsplat(0); /* spp 1: pixel and lens centre */
                    if (spp > 1) {
                        /* 24-bit uniforms, two per 64-bit draw, stratified */
                        uint64_t a0 = next64(&st), a1 = next64(&st), a2 = next64(&st), a3 = next64(&st);
                        v4i hi = {(int)(a0 >> 40), (int)(a1 >> 40), (int)(a2 >> 40), (int)(a3 >> 40)};
                        v4i lo = {(int)((uint32_t)a0 >> 8), (int)((uint32_t)a1 >> 8), (int)((uint32_t)a2 >> 8),
                                  (int)((uint32_t)a3 >> 8)};
                        jx = vload(FU + kq) + __builtin_convertvector(hi, v4f) * u24 * vload(FW + kq);
                        jy = vload(FV + kq) + __builtin_convertvector(lo, v4f) * u24 * inv_rows;
                        if (lens) {
                            uint64_t b0 = next64(&st), b1 = next64(&st), b2 = next64(&st), b3 = next64(&st);
                            v4i bh = {(int)(b0 >> 40), (int)(b1 >> 40), (int)(b2 >> 40), (int)(b3 >> 40)};
                            v4i bl = {(int)((uint32_t)b0 >> 8), (int)((uint32_t)b1 >> 8), (int)((uint32_t)b2 >> 8),
                                      (int)((uint32_t)b3 >> 8)};
                            const uint32_t *p = perm + kq;
                            v4f su = {FU[p[0]], FU[p[1]], FU[p[2]], FU[p[3]]};
                            v4f sv = {FV[p[0]], FV[p[1]], FV[p[2]], FV[p[3]]};
                            v4f sw = {FW[p[0]], FW[p[1]], FW[p[2]], FW[p[3]]};
                            v4f lu = su + __builtin_convertvector(bh, v4f) * u24 * sw;
                            v4f lv = sv + __builtin_convertvector(bl, v4f) * u24 * inv_rows;
                            concentric4(lu, lv, &lx, &ly);
                        }
                    }
                    group_setup(c, finite_focus, Fp, jx, jy, lx, ly, live, &groups[q]);
                }
                v4f acc[4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
                for (int q = 0; q < ng; q++)
                    covered += group_gather(c, &groups[q], acc);
                v4f a = (acc[0] + acc[1]) + (acc[2] + acc[3]); /* float sums of a batch, then double */
                total[0] += a[0], total[1] += a[1], total[2] += a[2];
            }
            float *px = row + (size_t)x * 3;
            double inv_cov = covered ? 1.0 / covered : 0;
            for (int ch = 0; ch < 3; ch++)
                px[ch] = (float)(total[ch] * inv_cov);
            if (c->cov)
                *lf_image_px(c->cov, x, y) = (float)covered / spp;
            if (!covered)
                c->uncovered[tid]++;
        }
    }
}

static int check_synth_inputs(const lf_lightfield *lf, const lf_lightfield_synth_opts *o, lf_error *err)
{
    const lf_lightfield_layout *l = &lf->layout;
    if (l->kind != LF_LIGHTFIELD_CAMERA_ARRAY)
        return lf_error_set(err, LF_ERR_PARAM, "synth needs a camera-array light field");
    if (!(l->have & LF_LIGHTFIELD_HAVE_BOUNDS) || !(l->have & LF_LIGHTFIELD_HAVE_FOV))
        return lf_error_set(err, LF_ERR_PARAM, "synth needs%s%s",
                            (l->have & LF_LIGHTFIELD_HAVE_BOUNDS) ? "" : " lensfield:camera_grid_bounds (--griddim minx maxx miny maxy)",
                            (l->have & LF_LIGHTFIELD_HAVE_FOV) ? "" : " lensfield:fov_deg (--inputfov DEG)");
    if (o->width < 1 || o->height < 1 || !(o->fov_deg > 0 && o->fov_deg < 180) || !(l->fov_deg > 0 && l->fov_deg < 180))
        return lf_error_set(err, LF_ERR_PARAM, "synth: bad output size %dx%d or fov (out %g, in %g degrees)", o->width,
                            o->height, o->fov_deg, l->fov_deg);
    if (o->lens_radius < 0 || (o->lens_radius > 0 && !(o->focal_distance > 0)))
        return lf_error_set(err, LF_ERR_PARAM, "synth: a lens radius needs a focal distance > 0");
    return LF_OK;
}

/* The virtual camera's rotation R = Rz Ry Rx from its Euler angles (degrees). */
static void camera_rotation(const double rot_deg[3], double R[9])
{
    double ax = rot_deg[0] * M_PI / 180, ay = rot_deg[1] * M_PI / 180, az = rot_deg[2] * M_PI / 180;
    double Rx[9] = {1, 0, 0, 0, cos(ax), -sin(ax), 0, sin(ax), cos(ax)};
    double Ry[9] = {cos(ay), 0, sin(ay), 0, 1, 0, -sin(ay), 0, cos(ay)};
    double Rz[9] = {cos(az), -sin(az), 0, sin(az), cos(az), 0, 0, 0, 1};
    double T[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            T[i * 3 + j] = 0;
            for (int k = 0; k < 3; k++)
                T[i * 3 + j] += Ry[i * 3 + k] * Rx[k * 3 + j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            R[i * 3 + j] = 0;
            for (int k = 0; k < 3; k++)
                R[i * 3 + j] += Rz[i * 3 + k] * T[k * 3 + j];
        }
}

/* The data cameras' projection and grid (spacing, top-left camera). */
static void setup_camera_grid(synth_ctx *c, const lf_lightfield *lf, const lf_lightfield_synth_opts *o)
{
    const lf_lightfield_layout *l = &lf->layout;
    c->in_tan = tan(l->fov_deg * M_PI / 360), c->in_half = 0.5 * (lf->ns < lf->nt ? lf->ns : lf->nt);
    c->in_scale = c->in_half / c->in_tan;
    c->out_tan = tan(o->fov_deg * M_PI / 360), c->out_half = 0.5 * (o->width < o->height ? o->width : o->height);
    c->minx = l->grid_bounds[0], c->maxy = l->grid_bounds[3];
    c->bx = lf->nu > 1 ? (l->grid_bounds[1] - l->grid_bounds[0]) / (lf->nu - 1) : 1;
    c->by = lf->nv > 1 ? (l->grid_bounds[3] - l->grid_bounds[2]) / (lf->nv - 1) : 1;
    c->inv_bx = 1 / c->bx, c->inv_by = 1 / c->by;
    if (lf->nu == 1)
        c->minx = 0.5 * (l->grid_bounds[0] + l->grid_bounds[1]);
    if (lf->nv == 1)
        c->maxy = 0.5 * (l->grid_bounds[2] + l->grid_bounds[3]);
}

/* Film and lens positions to grid-relative space (synth_ctx). */
static void setup_film(synth_ctx *c, const lf_lightfield *lf, const lf_lightfield_synth_opts *o)
{
    const double k = c->out_tan / c->out_half, fd = o->focal_distance > 0 ? o->focal_distance : 1;
    const double origin[3] = {c->minx, c->maxy, 0}, flip[3] = {1, -1, 1};
    for (int a = 0; a < 3; a++) {
        const double r0 = flip[a] * c->R[a * 3], r1 = flip[a] * c->R[a * 3 + 1], r2 = flip[a] * c->R[a * 3 + 2];
        c->pos[a] = flip[a] * (o->pos[a] - origin[a]);
        c->F0[a] = fd * (r2 - o->width * 0.5 * k * r0 + o->height * 0.5 * k * r1) + (o->focal_distance > 0 ? c->pos[a] : 0);
        c->FX[a] = fd * k * r0, c->FY[a] = -fd * k * r1;
        c->fFX[a] = (float)c->FX[a], c->fFY[a] = (float)c->FY[a], c->fpos[a] = (float)c->pos[a];
        c->fLX[a] = (float)(o->lens_radius * r0), c->fLY[a] = (float)(o->lens_radius * r1);
    }
    c->fns = (float)lf->ns, c->fnt = (float)lf->nt, c->fbx = (float)c->bx, c->fby = (float)c->by;
}

/* The reference view's disparity map (synth --geometry depth): its range
 * and the reference camera's grid position. */
static int setup_disparity(synth_ctx *c, const lf_lightfield *lf, const lf_image *dm, lf_error *err)
{
    if (dm->width != lf->ns || dm->height != lf->nt || dm->channels != 1 || !dm->data)
        return lf_error_set(err, LF_ERR_PARAM, "synth: the disparity map must be 1 channel, %dx%d like the views", lf->ns,
                            lf->nt);
    c->disp = dm->data;
    c->dmin = FLT_MAX, c->dmax = -FLT_MAX;
    for (size_t i = 0; i < (size_t)lf->ns * lf->nt; i++) {
        if (!isfinite(dm->data[i]))
            return lf_error_set(err, LF_ERR_NUMERIC, "synth: non-finite value in the disparity map");
        c->dmin = fminf(c->dmin, dm->data[i]), c->dmax = fmaxf(c->dmax, dm->data[i]);
    }
    c->ref_x = ((lf->nu - 1) / 2) * c->bx, c->ref_y = ((lf->nv - 1) / 2) * c->by;
    if (lf->nu == 1)
        c->ref_x = 0;
    if (lf->nv == 1)
        c->ref_y = 0;
    return LF_OK;
}

int lf_lightfield_synth(const lf_lightfield *lf, const lf_lightfield_synth_opts *o, lf_image *out, lf_image *coverage,
                size_t *uncovered, lf_error *err)
{
    const lf_lightfield_layout *l = &lf->layout;
    int rc = check_synth_inputs(lf, o, err);
    if (rc)
        return rc;
    synth_ctx c;
    memset(&c, 0, sizeof c);
    c.lf = lf, c.o = o;
    /* The views are already integrated over their pixels.  A pinhole
     * virtual camera whose pixels subtend no more than a data pixel gets
     * each pixel from the reconstruction at its centre: jittering over the
     * pixel would integrate a second time and blur (at a data camera's own
     * position, fov and size this reproduces the view exactly).  Larger
     * virtual pixels (minification) and lenses keep their samples. */
    lf_lightfield_synth_opts centred;
    {
        double out_px = tan(o->fov_deg * M_PI / 360) / (0.5 * (o->width < o->height ? o->width : o->height));
        double in_px = tan(l->fov_deg * M_PI / 360) / (0.5 * (lf->ns < lf->nt ? lf->ns : lf->nt));
        if (o->lens_radius == 0 && o->spp > 1 && out_px <= in_px * (1 + 1e-9)) {
            centred = *o;
            centred.spp = 1;
            c.o = o = &centred;
        }
    }
    camera_rotation(o->rot_deg, c.R);
    setup_camera_grid(&c, lf, o);
    if (lf_image_alloc(out, o->width, o->height, 3, err))
        return err ? err->code : LF_ERR_NOMEM;
    if (coverage && lf_image_alloc(coverage, o->width, o->height, 1, err)) {
        lf_image_free(out);
        return err ? err->code : LF_ERR_NOMEM;
    }
    c.out = out, c.cov = coverage;
    setup_film(&c, lf, o);
    if (o->disparity && (rc = setup_disparity(&c, lf, o->disparity, err)))
        goto fail;
    c.finv_bx = (float)c.inv_bx, c.finv_by = (float)c.inv_by, c.fscale = (float)c.in_scale;
    c.view_texels = (size_t)lf->ns * lf->nt;
    c.last_texel = (size_t)lf->nu * lf->nv * c.view_texels - 1;
    for (int q = 0; q < 4; q++)
        c.cam_view[q] = (size_t)((q & 1) && lf->nu > 1) + (size_t)((q & 2) && lf->nv > 1) * lf->nu,
        c.cam_texel[q] = c.cam_view[q] * c.view_texels;
    int nth = o->threads > 0 ? o->threads : 2;
    if (nth > LF_PARALLEL_MAX_THREADS)
        nth = LF_PARALLEL_MAX_THREADS;
    if (nth > o->height)
        nth = o->height;
    for (int t = 0; t < nth; t++)
        if (!(c.strata[t] = strata_new(o->spp > 0 ? o->spp : 1))) {
            for (int q = 0; q < t; q++)
                free(c.strata[q]);
            rc = lf_error_set(err, LF_ERR_NOMEM, "synth: out of memory for %d samples per pixel", o->spp);
            goto fail;
        }
    lf_parallel_for(o->height, nth, 1, synth_rows, &c);
    size_t unc = 0;
    for (int t = 0; t < nth; t++) {
        free(c.strata[t]);
        unc += c.uncovered[t];
    }
    if (uncovered)
        *uncovered = unc;
    return LF_OK;
fail:
    lf_image_free(out);
    if (coverage)
        lf_image_free(coverage);
    return rc;
}
