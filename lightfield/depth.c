/* Disparity from a 4D light field (lf_depth.h; docs/depth.md has the
 * method, its references and measurements).
 *
 * Layout of the work: the cost volume cost[label][pixel] is built in bands
 * of rows (threads take bands), views read in place (RGB interleaved);
 * for one label every view is shifted by a constant sub-pixel offset, so
 * the cubic (or bilinear) weights are constant along a row and the inner
 * loops are plain multiply-adds over contiguous floats (vectorised, AVX2
 * clone).  Then each cost slice is filtered (guided filter, threads take
 * slices), then aggregated semi-globally (depth_sgm.c), then per pixel the minimum, parabola refinement and confidence,
 * then the weighted median, then the thin-structure step (the unaggregated
 * full-aperture winner, tracked while the volume is built, tested per
 * pixel), then a Gauss-Newton refinement (views outer, rows in parallel). */
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lf_depth.h"
#include "base/lf_parallel.h"
#include "lightfield/depth_internal.h"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define LF_HOT_LOOP __attribute__((optimize("-ftree-vectorize", "-fvect-cost-model=dynamic"), target_clones("avx512f", "avx2", "default")))
#else
#define LF_HOT_LOOP
#endif

enum { NGROUPS = 16, NFIELDS = 5, MAX_LABELS = 512 };
/* labels whose sums the cost volume's row loop keeps at once (cost_rows):
 * 4 x 160 kB at 512 px, within a core's L2 */
enum { LABEL_BLOCK = 4 };
/* cost_rows' scratch per thread before the half gate's curves: the groups'
 * sums, combine_row's 5 rows, 3 spare rows, the vertical pass (3
 * planes), the reference row's planes, track_full's 5 rows, the gate's
 * per-pixel sums (ns doubles); the first 14 rows after the groups' sums are
 * the gate's contrasts once the row's labels are done; the groups' sums
 * for LABEL_BLOCK labels */
#define COST_ROW_SCRATCH(ns) ((size_t)(NGROUPS * NFIELDS * LABEL_BLOCK + 5 + 3 + 3 + 3 + 5 + 2) * (ns) + 26)

/* Tuning constants the options do not expose (docs/depth.md, "Method",
 * gives each one's measurements). */
/* per-view L1 colour difference truncated here (units of the reference's
 * mean channel sum): a view that sees an occluder costs no more than this */
static const float COST_TRUNCATION = 0.5f;
/* the defocus cue against correspondence: a tie-breaker, more costs
 * sub-pixel precision on noisy texture (the ablation) */
static const float DEFAULT_DEFOCUS_WEIGHT = 0.1f;
/* guided-filter radius: the shorter side over this (4 px at 512), at least
 * MIN_GUIDE_RADIUS so the window spans more than a pixel's neighbours */
static const int GUIDE_RADIUS_DIVISOR = 128;
static const int MIN_GUIDE_RADIUS = 2;
/* guided-filter regulariser for a guide in [0, 1]: keeps colour edges of
 * a few percent */
static const float DEFAULT_GUIDE_EPS = 1e-3f;
/* weighted median over a 7 x 7 window: removes isolated outliers */
static const int DEFAULT_MEDIAN_RADIUS = 3;
/* a zero-confidence neighbour still votes a little, so a window never has
 * no weight */
static const float MEDIAN_CONFIDENCE_FLOOR = 1e-3f;
/* colour weight exp(-|dI|^2 / sigma2) on the square-root encoded
 * reference, the median's and the refinement's */
static const float COLOUR_SIGMA2 = 0.02f;
/* thin structures: a candidate is nearer than the map by more than this
 * shift (px) at the widest view, and joins a neighbour within
 * THIN_SAME_SHIFT_PX; about the label spacing's precision */
static const double THIN_MIN_SHIFT_PX = 0.6;
static const double THIN_SAME_SHIFT_PX = 0.3;
/* the candidate's cost below this times the map's: fewest bad pixels on the
 * tests' rendered structures (ratios 0.05 .. 0.5 in docs/depth.md) */
static const float DEFAULT_THIN_RATIO = 0.2f;
/* Cauchy scale of the refinement's residuals, in units of the mean channel
 * sum: a few noise levels, so a view seeing an occluder drops out */
static const float REFINE_CAUCHY_C = 0.003f;
/* one Gauss-Newton step: a second changes nothing measurable at twice the cost */
static const int DEFAULT_REFINE_STEPS = 1;
/* the refinement sums a 5 x 5 window and moves at most 2 labels: further
 * is the labels' job */
static const int REFINE_RADIUS = 2;
static const double REFINE_MAX_STEP_LABELS = 2.0;
/* threads when the options say none */
static const int DEFAULT_THREADS = 2;

/* Plain pixels: the unaggregated curve's mean exceeds its minimum by less
 * than half an 8-bit code step in one channel (noise-free views), or by
 * less than the 99th percentile of what pure noise gives, relative to the
 * curve's mean (noisy views; measured by noise_contrast_ratio). */
static const float PLAIN_ABS_CONTRAST = 1e-3f;
static const double PLAIN_NOISE_QUANTILE = 0.99;
/* the simulated field: noise of 5 % of the level (far from the
 * truncation), a fixed seed */
static const double PLAIN_SIM_NOISE = 0.05;
/* Pre-smoothing (docs/depth.md, "Pre-smoothing noisy views"): views whose
 * noise (Immerkaer's estimate on the reference, sRGB-encoded grey, over
 * the flatter half of its pixels) is at least LF_DEPTH_PREFILTER_NOISE of
 * their mean level are blurred by a Gaussian of PREFILTER_SIGMA px before
 * matching; both chosen on the benchmark's tune half and backgammon. */
static const double PREFILTER_SIGMA = 0.7;
/* On pre-smoothed views the noise left still outweighs weak texture in a
 * window of the guided filter's radius: the cost is also filtered with a
 * window WIDE_WINDOW_FACTOR times wider, and a pixel whose narrow-window
 * curve has confidence c < WIDE_WINDOW_CONFIDENCE takes c / that of it and
 * the rest from the wide one (docs/depth.md, "Noisy views: whitened and a
 * wider window"); both chosen on the benchmark's tune half. */
enum { WIDE_WINDOW_FACTOR = 4 };
static const float WIDE_WINDOW_CONFIDENCE = 0.2f;
/* semi-global aggregation: penalties in units of the cost's mean contrast,
 * and the colour step (square-root encoded) that halves P2 */
static const double DEFAULT_SGM_P1 = 0.05;
static const double DEFAULT_SGM_P2 = 8.0;
static const double DEFAULT_SGM_EDGE = 0.05;

lf_lightfield_depth_opts lf_lightfield_depth_defaults(void)
{
    lf_lightfield_depth_opts o;
    memset(&o, 0, sizeof o);
    o.occlusion = 2;
    o.defocus_weight = -1;
    o.median_radius = -1;
    return o;
}

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* One non-reference view: its data, offset from the reference and angular group. */
typedef struct dview {
    const float *data;
    const float *valid; /* NULL: every sample valid */
    double du, dv; /* view steps from the reference (dv already scaled by disp_v_per_u) */
    double ox, oy; /* constant pixel offset (calibrated views) */
    int group;     /* 2k: on the ray at k*45 degrees; 2k+1: strictly inside octant k */
} dview;

/* Progress through the two long stages, the cost volume (a row: nlabels
 * units) and its aggregation (a slice: nt units), taken as equally long.
 * Only the calling thread (tid 0 of lf_parallel_for) calls the options'
 * callback, so it needs no lock. */
typedef struct depth_progress {
    const lf_lightfield_depth_opts *o;
    atomic_long done;
    long total;
} depth_progress;

static void progress_add(depth_progress *p, long units, int tid)
{
    if (!p || !p->o->progress)
        return;
    long done = atomic_fetch_add(&p->done, units) + units;
    if (tid == 0 && done < p->total) /* depth_core reports the end */
        p->o->progress(p->o->progress_ctx, done, p->total);
}

/* One view's constant shift at one label, what every row of the volume
 * needs of it (computed once, build_cost_volume). */
typedef struct label_view {
    int ix, iy;         /* whole-pixel part of the shift (floor) */
    float fx, fy;       /* its fraction */
    float wx[4], wy[4]; /* Keys weights of the fraction (the cubic lookup) */
    int xa, xb;         /* the columns whose lookup stays inside the view (xa > xb: none) */
    float gain;         /* the view's difference is scaled by this (noise_gain, or 1) */
} label_view;

typedef struct cost_ctx {
    const lf_lightfield *lf;
    const dview *views;
    int nviews;
    const label_view *lv; /* [label][view] */
    const float *ref;    /* reference view, RGB */
    const float *ref_valid; /* its validity (when lf->valid) */
    int nlabels;
    double d0, step;
    float tau;           /* truncation of the per-view colour difference (after scaling) */
    float scale;         /* colour scale: 1 / mean channel sum of the reference */
    float alpha;         /* defocus weight */
    int occlusion;
    int cubic;           /* 1: views looked up by Keys cubic convolution, 0: bilinear */
    int half_gate;       /* 1: a half aperture competes only where its contrast is the best (select_subsets) */
    float *cost;         /* [label][pixel] */
    float *rawd;         /* NULL, or per pixel the winner of the unaggregated full-aperture cost */
    float *scratch;      /* per thread: COST_ROW_SCRATCH(ns) + 12 * labels * ns floats */
    size_t scratch_per_thread;
    depth_progress *progress; /* or NULL */
} cost_ctx;

/* Group of offset (du, dv): rays at multiples of 45 degrees and the open
 * octants between them, numbered counter-clockwise from +u. */
static int view_group(double du, double dv)
{
    double a = atan2(dv, du);
    if (a < 0)
        a += 2 * M_PI;
    double q = a / (M_PI / 4);
    double k = floor(q + 0.5);
    if (fabs(q - k) < 1e-9)
        return (2 * ((int)k % 8));
    return 2 * ((int)floor(q) % 8) + 1;
}

/* acc fields: 0 truncated |diff| sum, 1..3 signed diff per channel, 4 count. */
LF_HOT_LOOP static void view_row(float *restrict acc, int ns, const float *restrict a0, const float *restrict a1,
                                 const float *restrict b0, const float *restrict b1, const float *restrict c, float w00,
                                 float w01, float w10, float w11, float scale, float tau, int xa, int xb)
{
    float *restrict sad = acc, *restrict s0 = acc + ns, *restrict s1 = acc + 2 * ns, *restrict s2 = acc + 3 * ns,
                    *restrict n = acc + 4 * ns;
    for (int x = xa; x <= xb; x++) {
        int k = 3 * x;
        float e0 = (w00 * a0[k] + w01 * a1[k] + w10 * b0[k] + w11 * b1[k] - c[k]) * scale;
        float e1 = (w00 * a0[k + 1] + w01 * a1[k + 1] + w10 * b0[k + 1] + w11 * b1[k + 1] - c[k + 1]) * scale;
        float e2 = (w00 * a0[k + 2] + w01 * a1[k + 2] + w10 * b0[k + 2] + w11 * b1[k + 2] - c[k + 2]) * scale;
        float ad = fabsf(e0) + fabsf(e1) + fabsf(e2);
        sad[x] += ad < tau ? ad : tau;
        s0[x] += e0, s1[x] += e1, s2[x] += e2;
        n[x] += 1.f;
    }
}

/* The same where the light field marks missing samples (lf->valid): a
 * view counts at a pixel only when every texel it interpolates is valid. */
LF_HOT_LOOP static void view_row_masked(float *restrict acc, int ns, const float *restrict a0, const float *restrict a1,
                                        const float *restrict b0, const float *restrict b1, const float *restrict ma0,
                                        const float *restrict ma1, const float *restrict mb0, const float *restrict mb1,
                                        const float *restrict c, const float *restrict mc, float w00, float w01,
                                        float w10, float w11, float scale, float tau, int xa, int xb)
{
    float *restrict sad = acc, *restrict s0 = acc + ns, *restrict s1 = acc + 2 * ns, *restrict s2 = acc + 3 * ns,
                    *restrict n = acc + 4 * ns;
    for (int x = xa; x <= xb; x++) {
        int k = 3 * x;
        float m = w00 * ma0[x] + w01 * ma1[x] + w10 * mb0[x] + w11 * mb1[x];
        float ok = m > 0.999f && mc[x] > 0.5f ? 1.f : 0.f;
        float e0 = (w00 * a0[k] + w01 * a1[k] + w10 * b0[k] + w11 * b1[k] - c[k]) * scale * ok;
        float e1 = (w00 * a0[k + 1] + w01 * a1[k + 1] + w10 * b0[k + 1] + w11 * b1[k + 1] - c[k + 1]) * scale * ok;
        float e2 = (w00 * a0[k + 2] + w01 * a1[k + 2] + w10 * b0[k + 2] + w11 * b1[k + 2] - c[k + 2]) * scale * ok;
        float ad = fabsf(e0) + fabsf(e1) + fabsf(e2);
        sad[x] += ad < tau ? ad : tau;
        s0[x] += e0, s1[x] += e1, s2[x] += e2;
        n[x] += ok;
    }
}

/* Keys cubic convolution (a = -1/2) weights of the taps at -1, 0, 1, 2 for
 * a sample at phase f in [0, 1). */
static inline void keys4(double f, float w[4])
{
    double t = 1 + f;
    w[0] = (float)(((-0.5 * t + 2.5) * t - 4) * t + 2);
    w[1] = (float)((1.5 * f - 2.5) * f * f + 1);
    t = 1 - f;
    w[2] = (float)((1.5 * t - 2.5) * t * t + 1);
    t = 2 - f;
    w[3] = (float)(((-0.5 * t + 2.5) * t - 4) * t + 2);
}

/* The vertical pass of the separable cubic lookup: o0[i] (o1, o2) = the 4
 * rows weighted by v at pixel i (interleaved RGB rows in, n pixels), one
 * plane per channel out, so the horizontal pass reads each contiguously. */
LF_HOT_LOOP static void vcomb3(float *restrict o0, float *restrict o1, float *restrict o2, const float *restrict r0,
                               const float *restrict r1, const float *restrict r2, const float *restrict r3, float v0,
                               float v1, float v2, float v3, int n)
{
    for (int i = 0; i < n; i++) {
        int k = 3 * i;
        o0[i] = v0 * r0[k] + v1 * r1[k] + v2 * r2[k] + v3 * r3[k];
        o1[i] = v0 * r0[k + 1] + v1 * r1[k + 1] + v2 * r2[k + 1] + v3 * r3[k + 1];
        o2[i] = v0 * r0[k + 2] + v1 * r1[k + 2] + v2 * r2[k + 2] + v3 * r3[k + 2];
    }
}

/* An interleaved RGB row (n pixels) split into planes (the reference
 * row, read by the horizontal pass beside vcomb3's planes). */
LF_HOT_LOOP static void deinterleave3(const float *restrict t, float *restrict p0, float *restrict p1,
                                      float *restrict p2, int n)
{
    for (int i = 0; i < n; i++)
        p0[i] = t[3 * i], p1[i] = t[3 * i + 1], p2[i] = t[3 * i + 2];
}

/* view_row with the horizontal pass of the cubic lookup, on planes: t0[x]
 * (t1, t2) is the vertically combined row's channel at column x + ix - 1,
 * c0 (c1, c2) the reference row's. */
LF_HOT_LOOP static void view_row_cubic(float *restrict acc, int ns, const float *restrict t0, const float *restrict t1,
                                       const float *restrict t2, const float *restrict c0, const float *restrict c1,
                                       const float *restrict c2, float h0, float h1, float h2, float h3, float scale,
                                       float tau, int xa, int xb)
{
    float *restrict sad = acc, *restrict s0 = acc + ns, *restrict s1 = acc + 2 * ns, *restrict s2 = acc + 3 * ns,
                    *restrict n = acc + 4 * ns;
    for (int x = xa; x <= xb; x++) {
        float e0 = (h0 * t0[x] + h1 * t0[x + 1] + h2 * t0[x + 2] + h3 * t0[x + 3] - c0[x]) * scale;
        float e1 = (h0 * t1[x] + h1 * t1[x + 1] + h2 * t1[x + 2] + h3 * t1[x + 3] - c1[x]) * scale;
        float e2 = (h0 * t2[x] + h1 * t2[x + 1] + h2 * t2[x + 2] + h3 * t2[x + 3] - c2[x]) * scale;
        float ad = fabsf(e0) + fabsf(e1) + fabsf(e2);
        sad[x] += ad < tau ? ad : tau;
        s0[x] += e0, s1[x] += e1, s2[x] += e2;
        n[x] += 1.f;
    }
}

/* One view subset's cost from its sums: the mean truncated difference plus
 * alpha times the mean signed difference's L1 norm; worst without views. */
static inline float subset_cost(float sad, float s0, float s1, float s2, float n, float alpha, float worst)
{
    float nn = n > 0.f ? n : 1.f;
    float c = (sad + alpha * (fabsf(s0) + fabsf(s1) + fabsf(s2))) / nn;
    return n > 0.f ? c : worst;
}

/* The cost of the line of groups a and b (two opposite rays) at x. */
static inline float line_cost(const float *a, const float *b, int x, int ns, float alpha, float worst)
{
    return subset_cost(a[x] + b[x], a[ns + x] + b[ns + x], a[2 * ns + x] + b[2 * ns + x], a[3 * ns + x] + b[3 * ns + x],
                       a[4 * ns + x] + b[4 * ns + x], alpha, worst);
}

/* cost = min over half apertures h of  sad/n + alpha * |sum diff| / n, a
 * half being 9 consecutive groups (rays h-2..h+2 and the octants between);
 * w: 5 * ns scratch. */
LF_HOT_LOOP static void combine_row(const float *restrict acc, float *restrict w, float *restrict out, int ns,
                                    float alpha, float worst, int occlusion, float *restrict sub, size_t sstride)
{
    float *restrict w0 = w, *restrict w1 = w + ns, *restrict w2 = w + 2 * ns, *restrict w3 = w + 3 * ns,
                    *restrict w4 = w + 4 * ns;
    for (int x = 0; x < ns; x++)
        out[x] = worst, w0[x] = w1[x] = w2[x] = w3[x] = w4[x] = 0.f;
    if (!occlusion) {
        for (int g = 0; g < NGROUPS; g++) {
            const float *a = acc + (size_t)g * NFIELDS * ns;
            for (int x = 0; x < ns; x++) {
                w0[x] += a[x], w1[x] += a[ns + x], w2[x] += a[2 * ns + x], w3[x] += a[3 * ns + x];
                w4[x] += a[4 * ns + x];
            }
        }
        for (int x = 0; x < ns; x++) {
            float n = w4[x] > 0.f ? w4[x] : 1.f;
            float c = (w0[x] + alpha * (fabsf(w1[x]) + fabsf(w2[x]) + fabsf(w3[x]))) / n;
            out[x] = w4[x] > 0.f ? c : worst;
        }
        return;
    }
    for (int j = -4; j <= 4; j++) {
        const float *a = acc + (size_t)((j + NGROUPS) % NGROUPS) * NFIELDS * ns;
        for (int x = 0; x < ns; x++) {
            w0[x] += a[x], w1[x] += a[ns + x], w2[x] += a[2 * ns + x], w3[x] += a[3 * ns + x];
            w4[x] += a[4 * ns + x];
        }
    }
    for (int h = 0; h < 8; h++) {
        /* two copies of the loop, with and without the subset's row, so
         * that neither has a branch (both vectorise) */
        if (sub) {
            float *restrict so = sub + (size_t)h * sstride;
            for (int x = 0; x < ns; x++) {
                float c = subset_cost(w0[x], w1[x], w2[x], w3[x], w4[x], alpha, worst);
                out[x] = c < out[x] ? c : out[x];
                so[x] = c;
            }
        } else {
            for (int x = 0; x < ns; x++) {
                float c = subset_cost(w0[x], w1[x], w2[x], w3[x], w4[x], alpha, worst);
                out[x] = c < out[x] ? c : out[x];
            }
        }
        if (h == 7) {
            if (occlusion < 2)
                break;
            /* lines through the reference (two opposite rays): a pixel between
             * two occluders is seen by the views along their direction */
            for (int k = 0; k < 4; k++) {
                const float *a = acc + (size_t)(2 * k) * NFIELDS * ns, *b = acc + (size_t)(2 * k + 8) * NFIELDS * ns;
                float *restrict so = sub ? sub + (size_t)(8 + k) * sstride : NULL;
                if (so)
                    for (int x = 0; x < ns; x++) {
                        float c = line_cost(a, b, x, ns, alpha, worst);
                        out[x] = c < out[x] ? c : out[x];
                        so[x] = c;
                    }
                else
                    for (int x = 0; x < ns; x++) {
                        float c = line_cost(a, b, x, ns, alpha, worst);
                        out[x] = c < out[x] ? c : out[x];
                    }
            }
            break;
        }
        /* slide: groups 2h-4, 2h-3 leave, 2h+5, 2h+6 enter */
        for (int q = 0; q < 2; q++) {
            const float *o = acc + (size_t)((2 * h - 4 + q + NGROUPS) % NGROUPS) * NFIELDS * ns;
            const float *i = acc + (size_t)((2 * h + 5 + q) % NGROUPS) * NFIELDS * ns;
            for (int x = 0; x < ns; x++) {
                w0[x] += i[x] - o[x], w1[x] += i[ns + x] - o[ns + x], w2[x] += i[2 * ns + x] - o[2 * ns + x];
                w3[x] += i[3 * ns + x] - o[3 * ns + x], w4[x] += i[4 * ns + x] - o[4 * ns + x];
            }
        }
    }
}

/* The full aperture's correspondence cost of label l (every view's
 * truncated difference, no defocus term) and the running winner
 * over the labels: best cost, its label, the costs of the labels either
 * side (for the parabola), the previous label's cost; r: 5 * ns, w: 2 * ns
 * scratch. */
LF_HOT_LOOP static void track_full(const float *restrict acc, float *restrict w, float *restrict r, int ns, int l)
{
    float *restrict w0 = w, *restrict w4 = w + ns;
    float *restrict bc = r, *restrict bl = r + ns, *restrict pc = r + 2 * ns, *restrict nc = r + 3 * ns,
                    *restrict lc = r + 4 * ns;
    for (int x = 0; x < ns; x++)
        w0[x] = acc[x], w4[x] = acc[4 * ns + x];
    for (int g = 1; g < NGROUPS; g++) {
        const float *a = acc + (size_t)g * NFIELDS * ns;
        for (int x = 0; x < ns; x++)
            w0[x] += a[x], w4[x] += a[4 * ns + x];
    }
    for (int x = 0; x < ns; x++) {
        float c = w4[x] > 0.f ? w0[x] / w4[x] : FLT_MAX;
        if (l == 0 || c < bc[x]) {
            bc[x] = c, bl[x] = (float)l, pc[x] = l > 0 ? lc[x] : FLT_MAX, nc[x] = FLT_MAX;
        } else if ((float)(l - 1) == bl[x]) {
            nc[x] = c;
        }
        lc[x] = c;
    }
}

/* Per pixel of a row, which half apertures compete (occlusion 2, the
 * gate on).  Each half's curve has false minima of its own where the
 * texture repeats or runs along some of its views (stripes, checks, the
 * grout of a floor seen at a grazing angle), and a per-label minimum over
 * the 8 halves takes every one of them: the curve handed on is their
 * union.  Wang et al. (ICCV 2015) take one half per pixel, the one the
 * occluding edge's orientation picks; here it is the half whose curve has
 * the largest contrast (mean minus minimum over the labels), and a half
 * competes only where its contrast is the largest of all 12 subsets'.  The
 * 4 lines always compete: a gap between two occluders is seen only along
 * one of them.  sub[s][l][x], s < 8 the halves; the least into cost. */
LF_HOT_LOOP static void select_subsets(const float *restrict sub, int L, int ns, float *restrict cost, size_t np,
                                       float *restrict con, double *restrict m)
{
    /* loops over x innermost (contiguous, vectorised); per pixel the same
     * sums in the same order as a loop over the labels per pixel */
    float *restrict best = con + (size_t)12 * ns, *restrict mn = best + ns;
    for (int x = 0; x < ns; x++)
        best[x] = 0;
    for (int s = 0; s < 12; s++) {
        const float *c = sub + (size_t)s * L * ns;
        float *cs = con + (size_t)s * ns;
        for (int x = 0; x < ns; x++)
            m[x] = 0, mn[x] = FLT_MAX;
        for (int l = 0; l < L; l++) {
            const float *cl = c + (size_t)l * ns;
            for (int x = 0; x < ns; x++) {
                float v = cl[x];
                m[x] += v, mn[x] = v < mn[x] ? v : mn[x];
            }
        }
        for (int x = 0; x < ns; x++) {
            cs[x] = (float)(m[x] / L) - mn[x];
            best[x] = cs[x] > best[x] ? cs[x] : best[x];
        }
    }
    for (int l = 0; l < L; l++) {
        float *o = cost + (size_t)l * np;
        for (int x = 0; x < ns; x++)
            o[x] = FLT_MAX;
        for (int s = 0; s < 12; s++) {
            const float *q = sub + ((size_t)s * L + l) * ns, *cs = con + (size_t)s * ns;
            if (s >= 8)
                for (int x = 0; x < ns; x++)
                    o[x] = q[x] < o[x] ? q[x] : o[x];
            else
                for (int x = 0; x < ns; x++)
                    o[x] = cs[x] >= best[x] && q[x] < o[x] ? q[x] : o[x];
        }
    }
}

/* One view's correspondence at one label along row y, added to its
 * group's sums in acc (the label's NGROUPS x NFIELDS rows); vp: the
 * cubic lookup's vertical pass, 3 planes of vps floats; cp: the reference
 * row's planes. */
static void add_view_row(const cost_ctx *c, const dview *v, const label_view *s, int y, float *acc, float *vp,
                         size_t vps, const float *cp)
{
    int ns = c->lf->ns, nt = c->lf->nt;
    int ix = s->ix, xa = s->xa, xb = s->xb;
    int r0 = y + s->iy, r1 = s->fy > 0.f ? r0 + 1 : r0;
    if (r0 < 0 || r1 > nt - 1 || xa > xb)
        return;
    float *a = acc + (size_t)v->group * NFIELDS * ns;
    if (c->cubic && !v->valid) {
        /* separable Keys cubic: rows r0-1 .. r0+2 (clamped), columns ix-1 .. ix+2 */
        const float *rr[4];
        for (int m = 0; m < 4; m++)
            rr[m] = v->data + (size_t)clampi(r0 - 1 + m, 0, nt - 1) * ns * 3;
        size_t c0 = 3 * (size_t)(xa + ix - 1);
        int n = xb - xa + 4;
        vcomb3(vp + xa, vp + vps + xa, vp + 2 * vps + xa, rr[0] + c0, rr[1] + c0, rr[2] + c0, rr[3] + c0, s->wy[0],
               s->wy[1], s->wy[2], s->wy[3], n);
        view_row_cubic(a, ns, vp, vp + vps, vp + 2 * vps, cp, cp + ns, cp + 2 * ns, s->wx[0], s->wx[1], s->wx[2],
                       s->wx[3], c->scale * s->gain, c->tau, xa, xb);
        return;
    }
    const float *cref = c->ref + (size_t)y * ns * 3;
    float fx = s->fx, fy = s->fy;
    const float *row0 = v->data + (size_t)r0 * ns * 3 + 3 * (ptrdiff_t)ix;
    const float *row1 = v->data + (size_t)r1 * ns * 3 + 3 * (ptrdiff_t)ix;
    int dx1 = fx > 0.f ? 3 : 0;
    float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
    if (v->valid) {
        /* NaN never enters: invalid texels are read as 0 (decode stores 0 there) and masked */
        const float *m0 = v->valid + (size_t)r0 * ns + ix, *m1 = v->valid + (size_t)r1 * ns + ix;
        int mx1 = fx > 0.f ? 1 : 0;
        view_row_masked(a, ns, row0, row0 + dx1, row1, row1 + dx1, m0, m0 + mx1, m1, m1 + mx1, cref,
                        c->ref_valid + (size_t)y * ns, w00, w01, w10, w11, c->scale * s->gain, c->tau, xa, xb);
    } else {
        view_row(a, ns, row0, row0 + dx1, row1, row1 + dx1, cref, w00, w01, w10, w11, c->scale * s->gain, c->tau, xa,
                 xb);
    }
}

/* Rows [y0, y1) of the volume.  Labels are taken LABEL_BLOCK at a time,
 * views outer: a view's rows, read again for the next labels of the block
 * (their shifts differ by a fraction of a pixel), are still in cache.
 * Each label's sums still add the views in order. */
static void cost_rows(void *vctx, int y0, int y1, int tid)
{
    cost_ctx *c = vctx;
    const lf_lightfield *lf = c->lf;
    int ns = lf->ns;
    size_t np = (size_t)ns * lf->nt, gs = (size_t)NGROUPS * NFIELDS * ns;
    float *acc = c->scratch + (size_t)tid * c->scratch_per_thread; /* LABEL_BLOCK labels' group sums */
    float *w = acc + LABEL_BLOCK * gs;
    /* 3 * ns + 12 unused while the labels run: with w, vp and cp, the 14 rows
     * of select_subsets' contrasts */
    float *vp = w + 5 * (size_t)ns + 3 * (size_t)ns + 12; /* 3 planes of ns + 4: the cubic lookup's vertical pass */
    size_t vps = (size_t)ns + 4;
    float *cp = vp + 3 * vps; /* 3 * ns: the reference row's planes */
    float *rt = cp + 3 * (size_t)ns; /* 5 * ns: the full aperture's winner (track_full) */
    double *gm = (double *)(rt + 5 * (size_t)ns + (ns & 1)); /* ns: select_subsets' sums (8-byte aligned) */
    float *sub = c->half_gate && c->occlusion >= 2 ? (float *)(gm + ns) : NULL; /* [subset][label][x] */
    float worst = c->tau * (1 + c->alpha);
    for (int y = y0; y < y1; y++) {
        deinterleave3(c->ref + (size_t)y * ns * 3, cp, cp + ns, cp + 2 * ns, ns);
        for (int l0 = 0; l0 < c->nlabels; l0 += LABEL_BLOCK) {
            int nb = c->nlabels - l0 < LABEL_BLOCK ? c->nlabels - l0 : LABEL_BLOCK;
            memset(acc, 0, sizeof(float) * gs * (size_t)nb);
            for (int k = 0; k < c->nviews; k++)
                for (int j = 0; j < nb; j++)
                    add_view_row(c, &c->views[k], &c->lv[(size_t)(l0 + j) * c->nviews + k], y, acc + j * gs, vp,
                                 vps, cp);
            for (int j = 0; j < nb; j++) {
                int l = l0 + j;
                combine_row(acc + j * gs, w, c->cost + (size_t)l * np + (size_t)y * ns, ns, c->alpha, worst,
                            c->occlusion, sub ? sub + (size_t)l * ns : NULL, (size_t)c->nlabels * ns);
                if (c->rawd)
                    track_full(acc + j * gs, w, rt, ns, l);
            }
        }
        if (sub)
            select_subsets(sub, c->nlabels, ns, c->cost + (size_t)y * ns, np, w, gm);
        if (c->rawd)
            for (int x = 0; x < ns; x++) {
                double off = 0, cm = rt[2 * ns + x], cp = rt[3 * ns + x], cb = rt[x];
                if (cm < FLT_MAX && cp < FLT_MAX && cm - 2 * cb + cp > 1e-12) {
                    off = 0.5 * (cm - cp) / (cm - 2 * cb + cp);
                    off = off < -0.5 ? -0.5 : (off > 0.5 ? 0.5 : off);
                }
                c->rawd[(size_t)y * ns + x] = (float)(c->d0 + c->step * (rt[ns + x] + off));
            }
        progress_add(c->progress, c->nlabels, tid);
    }
}

/* ---------- guided filter (He, Sun, Tang 2010) ---------- */

/* Mean over the (2r+1)^2 window clipped to the image; tmp: w*h floats. */
LF_HOT_LOOP static void box_mean(const float *restrict in, float *restrict out, float *restrict tmp, int w, int h, int r)
{
    /* horizontal sums */
    for (int y = 0; y < h; y++) {
        const float *a = in + (size_t)y * w;
        float *t = tmp + (size_t)y * w;
        float s = 0;
        for (int x = 0; x <= r && x < w; x++)
            s += a[x];
        for (int x = 0; x < w; x++) {
            t[x] = s;
            if (x + r + 1 < w)
                s += a[x + r + 1];
            if (x - r >= 0)
                s -= a[x - r];
        }
    }
    /* vertical running sums: each output row from the previous one (vectorises across x) */
    for (int y = 0; y < h; y++) {
        int ya = y - r < 0 ? 0 : y - r, yb = y + r > h - 1 ? h - 1 : y + r;
        float *o = out + (size_t)y * w;
        if (y == 0) {
            for (int x = 0; x < w; x++)
                o[x] = 0;
            for (int yy = ya; yy <= yb; yy++) {
                const float *t = tmp + (size_t)yy * w;
                for (int x = 0; x < w; x++)
                    o[x] += t[x];
            }
        } else {
            const float *p = out + (size_t)(y - 1) * w;
            int yin = y + r, yout = y - r - 1;
            const float *ti = yin <= h - 1 ? tmp + (size_t)yin * w : NULL;
            const float *to = yout >= 0 ? tmp + (size_t)yout * w : NULL;
            if (ti && to)
                for (int x = 0; x < w; x++)
                    o[x] = p[x] + ti[x] - to[x];
            else if (ti)
                for (int x = 0; x < w; x++)
                    o[x] = p[x] + ti[x];
            else if (to)
                for (int x = 0; x < w; x++)
                    o[x] = p[x] - to[x];
            else
                for (int x = 0; x < w; x++)
                    o[x] = p[x];
        }
    }
    /* normalise: count = (columns in window) * (rows in window) */
    for (int y = 0; y < h; y++) {
        int ny = (y + r > h - 1 ? h - 1 : y + r) - (y - r < 0 ? 0 : y - r) + 1;
        float *o = out + (size_t)y * w;
        for (int x = 0; x < w; x++) {
            int nx = (x + r > w - 1 ? w - 1 : x + r) - (x - r < 0 ? 0 : x - r) + 1;
            o[x] /= (float)(nx * ny);
        }
    }
}

typedef struct gf_ctx {
    int w, h, r;
    const float *I;    /* guide, 3 planes */
    const float *mI;   /* its window means, 3 planes */
    const float *Sinv; /* (Sigma + eps U)^-1 per pixel, 6 planes: xx xy xz yy yz zz */
    float *cost;       /* slices filtered in place */
    float *scratch;    /* per thread: 10 * w * h */
    size_t per_thread;
    depth_progress *progress; /* or NULL */
} gf_ctx;

LF_HOT_LOOP static void mul_arr(const float *restrict x, const float *restrict y, float *restrict o, size_t n)
{
    for (size_t i = 0; i < n; i++)
        o[i] = x[i] * y[i];
}

LF_HOT_LOOP static void gf_coeffs(const float *restrict mp, float *restrict m0, float *restrict m1,
                                  float *restrict m2, const float *restrict mI, const float *restrict S,
                                  float *restrict b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        float c0 = m0[i] - mI[i] * mp[i], c1 = m1[i] - mI[n + i] * mp[i], c2 = m2[i] - mI[2 * n + i] * mp[i];
        float a0 = S[i] * c0 + S[n + i] * c1 + S[2 * n + i] * c2;
        float a1 = S[n + i] * c0 + S[3 * n + i] * c1 + S[4 * n + i] * c2;
        float a2 = S[2 * n + i] * c0 + S[4 * n + i] * c1 + S[5 * n + i] * c2;
        m0[i] = a0, m1[i] = a1, m2[i] = a2;
        b[i] = mp[i] - a0 * mI[i] - a1 * mI[n + i] - a2 * mI[2 * n + i];
    }
}

LF_HOT_LOOP static void gf_out(const float *restrict a0, const float *restrict a1, const float *restrict a2,
                               const float *restrict b, const float *restrict I, float *restrict q, size_t n)
{
    for (size_t i = 0; i < n; i++)
        q[i] = a0[i] * I[i] + a1[i] * I[n + i] + a2[i] * I[2 * n + i] + b[i];
}

/* Colour guided filter of each cost slice (He, Sun, Tang 2010, eqs. for a
 * colour guide): q = mean(a) . I + mean(b), a = (Sigma + eps U)^-1 cov(I, p). */
static void gf_slices(void *vctx, int l0, int l1, int tid)
{
    gf_ctx *g = vctx;
    size_t np = (size_t)g->w * g->h;
    float *s = g->scratch + (size_t)tid * g->per_thread;
    float *mp = s, *m0 = s + np, *m1 = s + 2 * np, *m2 = s + 3 * np, *b = s + 4 * np, *t = s + 5 * np,
          *tmp = s + 6 * np, *o0 = s + 7 * np, *o1 = s + 8 * np, *o2 = s + 9 * np;
    for (int l = l0; l < l1; l++) {
        float *p = g->cost + (size_t)l * np;
        box_mean(p, mp, tmp, g->w, g->h, g->r);
        float *mc[3] = {m0, m1, m2};
        for (int c = 0; c < 3; c++) {
            mul_arr(g->I + c * np, p, t, np);
            box_mean(t, mc[c], tmp, g->w, g->h, g->r);
        }
        gf_coeffs(mp, m0, m1, m2, g->mI, g->Sinv, b, np);
        box_mean(m0, o0, tmp, g->w, g->h, g->r);
        box_mean(m1, o1, tmp, g->w, g->h, g->r);
        box_mean(m2, o2, tmp, g->w, g->h, g->r);
        box_mean(b, mp, tmp, g->w, g->h, g->r);
        gf_out(o0, o1, o2, mp, g->I, p, np);
        progress_add(g->progress, g->h, tid);
    }
}

/* ---------- winner-take-all, sub-label, confidence ---------- */

typedef struct wta_ctx {
    int w, h, nlabels;
    double d0, step;
    const float *cost; /* the filtered costs: the parabola */
    const float *sel;  /* the volume the label is chosen on (cost, or the semi-global sum) */
    float *disp, *conf;
} wta_ctx;

static void wta_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    wta_ctx *c = vctx;
    size_t np = (size_t)c->w * c->h;
    int L = c->nlabels;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < c->w; x++) {
            size_t i = (size_t)y * c->w + x;
            int best = 0;
            float cb = FLT_MAX, sum = 0;
            const float *cv = c->cost; /* the confidence: the data's own curve, not the propagated one */
            for (int l = 0; l < L; l++) {
                float v = c->sel[(size_t)l * np + i];
                if (v < cb)
                    cb = v, best = l;
            }
            for (int l = 0; l < L; l++)
                sum += cv[(size_t)l * np + i];
            /* the sub-label offset from the filtered costs: the semi-global
             * sum is piecewise linear in the label near its minimum (P1) */
            double off = 0;
            if (best > 0 && best < L - 1) {
                double c0 = c->cost[(size_t)best * np + i];
                double cm = c->cost[(size_t)(best - 1) * np + i], cp = c->cost[(size_t)(best + 1) * np + i];
                double den = cm - 2.0 * c0 + cp;
                if (den > 1e-12)
                    off = 0.5 * (cm - cp) / den;
                off = off < -0.5 ? -0.5 : (off > 0.5 ? 0.5 : off);
            }
            c->disp[i] = (float)(c->d0 + c->step * (best + off));
            /* confidence: the minimum against the best cost away from it
             * (more than 2 labels off), relative to the curve's mean */
            c->conf[i] = lf_depth_curve_confidence(cv + i, np, L, best, sum);
        }
}

/* ---------- thin structures ---------- */

/* Photo-consistency of pixel (x, y) at disparity d over the full aperture:
 * the mean over the views of the squared difference to the reference of
 * the square-root encoded colour (closer to perceptual steps than linear).
 * A thin structure is the nearest surface, so every view sees it. */
static float pixel_cost(const cost_ctx *c, const float *map, float map_max, int x, int y, double d)
{
    const lf_lightfield *lf = c->lf;
    int ns = lf->ns, nt = lf->nt;
    const float *p = c->ref + ((size_t)y * ns + x) * 3;
    if (c->ref_valid && c->ref_valid[(size_t)y * ns + x] <= 0.5f)
        return 0.f;
    float rp[3];
    for (int ch = 0; ch < 3; ch++)
        rp[ch] = sqrtf(p[ch] * c->scale > 0 ? p[ch] * c->scale : 0.f);
    double sum = 0;
    int n = 0;
    for (int k = 0; k < c->nviews; k++) {
        const dview *v = &c->views[k];
        double sx = x - d * v->du + v->ox, sy = y - d * v->dv + v->oy;
        if (!(sx >= 1 && sy >= 1 && sx < ns - 2 && sy < nt - 2)) /* ix, iy below in [1, ns - 3], [1, nt - 3] */
            continue;
        int ix = (int)sx, iy = (int)sy; /* floor: positive here */
        float fx = (float)(sx - ix), fy = (float)(sy - iy);
        if (map) {
            /* occluded in view k when a nearer pixel q = p + t (du, dv) of
             * the map lands on the sample: d_q >= d + t within half a pixel */
            double L = fabs(v->du) > fabs(v->dv) ? fabs(v->du) : fabs(v->dv);
            int J = L > 0 ? (int)ceil((map_max - d) * L + 0.5) : 0, occ = 0;
            for (int j = 1; j <= J && !occ; j++) {
                double t = j / L;
                int qx = (int)lrint(x + t * v->du), qy = (int)lrint(y + t * v->dv);
                if (qx < 0 || qy < 0 || qx >= ns || qy >= nt)
                    break;
                float dq = map[(size_t)qy * ns + qx];
                occ = dq >= d + t - 0.5 / L && dq > d + c->step * 2;
            }
            if (occ)
                continue;
        }
        float val[3] = {0, 0, 0};
        if (c->cubic && !v->valid) {
            float wy[4], wx[4];
            keys4(fy, wy);
            keys4(fx, wx);
            for (int m = 0; m < 4; m++) {
                const float *row = v->data + ((size_t)(iy - 1 + m) * ns + ix - 1) * 3;
                for (int q = 0; q < 4; q++)
                    for (int ch = 0; ch < 3; ch++)
                        val[ch] += wy[m] * wx[q] * row[3 * q + ch];
            }
        } else {
            float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
            size_t i00 = (size_t)iy * ns + ix, i10 = i00 + ns;
            if (v->valid && w00 * v->valid[i00] + w01 * v->valid[i00 + 1] + w10 * v->valid[i10] +
                                    w11 * v->valid[i10 + 1] < 0.999f)
                continue;
            for (int ch = 0; ch < 3; ch++)
                val[ch] = w00 * v->data[3 * i00 + ch] + w01 * v->data[3 * i00 + 3 + ch] + w10 * v->data[3 * i10 + ch] +
                          w11 * v->data[3 * i10 + 3 + ch];
        }
        for (int ch = 0; ch < 3; ch++) {
            float e = sqrtf(val[ch] * c->scale > 0 ? val[ch] * c->scale : 0.f) - rp[ch];
            sum += e * e;
        }
        n++;
    }
    return n ? (float)(sum / n) : FLT_MAX;
}

typedef struct thin_ctx {
    const cost_ctx *cc;
    int w, h;
    const float *disp;  /* after the median */
    const float *rawd;  /* per-pixel winner of the unaggregated costs */
    unsigned char *cand;
    float *out;
    float tol_d, tol_s, ratio, map_max;
} thin_ctx;

/* Candidates: the unaggregated winner is more than tol_d away from the
 * aggregated disparity and its cost is below ratio times the cost there. */
static void thin_cand_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    thin_ctx *t = vctx;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < t->w; x++) {
            size_t i = (size_t)y * t->w + x;
            t->cand[i] = 0;
            if (t->rawd[i] - t->disp[i] <= t->tol_d) /* nearer: a thin structure occludes what is behind */
                continue;
            /* the structure: every view sees it; at the map's disparity: the views the map says see it */
            float cr = pixel_cost(t->cc, NULL, 0, x, y, t->rawd[i]);
            float cd = pixel_cost(t->cc, t->disp, t->map_max, x, y, t->disp[i]);
            t->cand[i] = cr < t->ratio * cd;
        }
}

/* A candidate is taken when a neighbour carries its disparity: another
 * candidate, or a pixel of the map (the structure continues there). */
static void thin_take_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    thin_ctx *t = vctx;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < t->w; x++) {
            size_t i = (size_t)y * t->w + x;
            float d = t->disp[i];
            if (t->cand[i]) {
                float r = t->rawd[i];
                /* not an edge grown by a pixel: a mixed pixel on a surface's
                 * outline against a plain background is as consistent with
                 * the surface as with the background, so a candidate with
                 * the surface on one side (x or y) needs the structure to go
                 * on at the other side too */
                int grown = 0;
                for (int ax = 0; ax < 2 && !grown; ax++) {
                    int own[2], surf[2];
                    for (int sgn = 0; sgn < 2; sgn++) {
                        int xx = x + (ax == 0 ? (sgn ? 1 : -1) : 0), yy = y + (ax == 1 ? (sgn ? 1 : -1) : 0);
                        own[sgn] = surf[sgn] = 0;
                        if (xx < 0 || yy < 0 || xx >= t->w || yy >= t->h)
                            continue;
                        size_t q = (size_t)yy * t->w + xx;
                        surf[sgn] = fabsf(t->disp[q] - r) < t->tol_s;
                        own[sgn] = surf[sgn] || (t->cand[q] && fabsf(t->rawd[q] - r) < t->tol_s);
                    }
                    grown = (surf[0] && !own[1]) || (surf[1] && !own[0]);
                }
                if (grown)
                    r = d;
                for (int j = -1; j <= 1 && d != r; j++)
                    for (int k = -1; k <= 1; k++) {
                        int xx = x + k, yy = y + j;
                        if ((!j && !k) || xx < 0 || yy < 0 || xx >= t->w || yy >= t->h)
                            continue;
                        size_t q = (size_t)yy * t->w + xx;
                        if ((t->cand[q] && fabsf(t->rawd[q] - r) < t->tol_s) || fabsf(t->disp[q] - r) < t->tol_s) {
                            d = r;
                            break;
                        }
                    }
            }
            t->out[i] = d;
        }
}

/* ---------- continuous refinement (Gauss-Newton on photo-consistency) ---------- */

/* Derivatives of the Keys weights (keys4) with respect to the sample position. */
static inline void keys4d(double f, float w[4])
{
    double t = 1 + f;
    w[0] = (float)(-1.5 * t * t + 5 * t - 4);
    w[1] = (float)(4.5 * f * f - 5 * f);
    t = 1 - f;
    w[2] = (float)(-(4.5 * t * t - 5 * t));
    t = 2 - f;
    w[3] = (float)(-(-1.5 * t * t + 5 * t - 4));
}

typedef struct gn_ctx {
    int w, h;
    const dview *v;
    const float *img;  /* the view's data, RGB */
    const float *ref, *disp; /* reference view; disparity */
    float *A, *B;      /* per pixel: sums of rho J^2 and rho J r over the views */
    float scale, c2;
} gn_ctx;

/* Per pixel, at its own disparity d: the residual r = I_k(x - d du + ox, ...) - I_ref
 * of one view (cubic lookup) and its derivative J with respect to d, with a
 * Cauchy weight rho = 1 / (1 + |r|^2 / c^2) that lets a view seeing an
 * occluder drop out; added to A and B. */
LF_HOT_LOOP static void gn_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    gn_ctx *c = vctx;
    const dview *v = c->v;
    int w = c->w, h = c->h;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            double d = c->disp[i];
            const float *p = c->ref + 3 * i;
            double sx = x - d * v->du + v->ox, sy = y - d * v->dv + v->oy;
            if (!(sx >= 1 && sy >= 1 && sx < w - 2 && sy < h - 2)) /* ix, iy below in [1, w - 3], [1, h - 3] */
                continue;
            int ix = (int)sx, iy = (int)sy; /* floor: positive here */
            float wx[4], wy[4], gx[4], gy[4];
            keys4(sx - ix, wx), keys4(sy - iy, wy), keys4d(sx - ix, gx), keys4d(sy - iy, gy);
            float val[3] = {0, 0, 0}, dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
            /* unrolled: the sums stay in registers (the same additions in the same order) */
#pragma GCC unroll 4
            for (int m = 0; m < 4; m++) {
                const float *row = c->img + ((size_t)(iy - 1 + m) * w + ix - 1) * 3;
                float hv[3] = {0, 0, 0}, hg[3] = {0, 0, 0};
#pragma GCC unroll 4
                for (int n = 0; n < 4; n++)
#pragma GCC unroll 3
                    for (int ch = 0; ch < 3; ch++)
                        hv[ch] += wx[n] * row[3 * n + ch], hg[ch] += gx[n] * row[3 * n + ch];
#pragma GCC unroll 3
                for (int ch = 0; ch < 3; ch++)
                    val[ch] += wy[m] * hv[ch], dx[ch] += wy[m] * hg[ch], dy[ch] += gy[m] * hv[ch];
            }
            double rr = 0, jj = 0, jr = 0;
            for (int ch = 0; ch < 3; ch++) {
                double r = (val[ch] - p[ch]) * c->scale, j = -(v->du * dx[ch] + v->dv * dy[ch]) * c->scale;
                rr += r * r, jj += j * j, jr += j * r;
            }
            double rho = 1.0 / (1.0 + rr / c->c2);
            c->A[i] += (float)(rho * jj), c->B[i] += (float)(rho * jr);
        }
}

/* Edge-aware weight of a neighbour by its colour difference to the centre
 * pixel (RGB in the working scale): exp(-|p - q|^2 / sigma2). */
static inline float colour_affinity(const float *p, const float *q, float sigma2)
{
    float e0 = p[0] - q[0], e1 = p[1] - q[1], e2 = p[2] - q[2];
    return expf(-(e0 * e0 + e1 * e1 + e2 * e2) / sigma2);
}

typedef struct gnagg_ctx {
    int w, h, r;
    const float *A, *B, *disp, *refs;
    float *out;
    float dmax, sigma2;
} gnagg_ctx;

/* d = sum_q w_q (A_q d_q - b_q) / sum_q w_q A_q over the window: the
 * linearised costs of the neighbours on the same surface (disparity within
 * dmax, colour weight as the median's) added up; the step is at most dmax. */
static void gnagg_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    gnagg_ctx *c = vctx;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < c->w; x++) {
            size_t i = (size_t)y * c->w + x;
            float d = c->disp[i];
            const float *p = c->refs + 3 * i;
            double sa = 0, sb = 0;
            for (int yy = y - c->r; yy <= y + c->r; yy++) {
                if (yy < 0 || yy >= c->h)
                    continue;
                for (int xx = x - c->r; xx <= x + c->r; xx++) {
                    if (xx < 0 || xx >= c->w)
                        continue;
                    size_t j = (size_t)yy * c->w + xx;
                    if (fabsf(c->disp[j] - d) > c->dmax) /* near a depth edge: views are partly occluded */
                        goto keep;
                    float wt = colour_affinity(p, c->refs + 3 * j, c->sigma2);
                    sa += wt * c->A[j], sb += wt * c->B[j];
                }
            }
            float nd = d;
            if (sa > 1e-9) {
                double t = sb / sa;
                nd = (float)(t < d - c->dmax ? d - c->dmax : (t > d + c->dmax ? d + c->dmax : t));
            }
            c->out[i] = nd;
            continue;
        keep:
            c->out[i] = d;
        }
}

/* ---------- weighted median (guided by the reference colour) ---------- */

typedef struct wm_ctx {
    int w, h, r;
    const float *disp, *conf, *ref; /* ref: RGB in the working scale */
    float *out;
    float sigma2;
    float *scratch; /* per thread: 2 * (2r+1)^2 */
    size_t per_thread;
} wm_ctx;

typedef struct dw {
    float d, w;
} dw;

static void wm_rows(void *vctx, int y0, int y1, int tid)
{
    wm_ctx *c = vctx;
    dw *buf = (dw *)(c->scratch + (size_t)tid * c->per_thread);
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < c->w; x++) {
            size_t i = (size_t)y * c->w + x;
            const float *p = c->ref + 3 * i;
            int n = 0;
            float wsum = 0;
            for (int yy = y - c->r; yy <= y + c->r; yy++) {
                if (yy < 0 || yy >= c->h)
                    continue;
                for (int xx = x - c->r; xx <= x + c->r; xx++) {
                    if (xx < 0 || xx >= c->w)
                        continue;
                    size_t j = (size_t)yy * c->w + xx;
                    float wt = colour_affinity(p, c->ref + 3 * j, c->sigma2) * (c->conf[j] + MEDIAN_CONFIDENCE_FLOOR);
                    buf[n].d = c->disp[j], buf[n].w = wt;
                    wsum += wt, n++;
                }
            }
            for (int k = 1; k < n; k++) { /* insertion sort: n is small */
                dw t = buf[k];
                int j = k - 1;
                while (j >= 0 && buf[j].d > t.d) {
                    buf[j + 1] = buf[j];
                    j--;
                }
                buf[j + 1] = t;
            }
            float half = 0.5f * wsum, s = 0;
            float med = c->disp[i];
            for (int k = 0; k < n; k++) {
                s += buf[k].w;
                if (s >= half) {
                    med = buf[k].d;
                    break;
                }
            }
            c->out[i] = med;
        }
}

/* ---------- driver: the method's stages in order (docs/depth.md) ---------- */

/* The largest view offset from the reference, in view steps (v scaled). */
static double widest_view(const lf_lightfield *lf)
{
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    double m = iu0 > lf->nu - 1 - iu0 ? iu0 : lf->nu - 1 - iu0;
    double mv = (iv0 > lf->nv - 1 - iv0 ? iv0 : lf->nv - 1 - iv0) * rv;
    return m > mv ? m : mv;
}

/* What the stages share: the light field's shape, the labels, the views
 * and the working buffers (allocated at once, so a big volume fails before
 * any work). */
typedef struct depth_work {
    const lf_lightfield *lf;
    const lf_lightfield_depth_opts *o;
    int ns, nt, threads, nlabels, nviews;
    size_t np;
    double d0, step;
    const float *ref;   /* reference view, RGB */
    float scale;        /* colour scale: 1 / mean channel sum of the reference */
    dview *views;       /* the other views */
    label_view *lv;     /* [label][view]: each view's shift at each label */
    float *cost;        /* [label][pixel]; scratch for the stages after the minimum */
    float *sel;         /* NULL, or the semi-global sum the labels are chosen on (same layout) */
    float *scratch;     /* per thread: the larger of the cost rows' and the guided filter's needs */
    size_t per_thread;
    float *guide;       /* 14 planes: guide (3), its means (3), inverse covariances (6), 2 temporaries */
    float *disp, *conf; /* winner-take-all disparity and confidence */
    float *refs;        /* square-root encoded reference in the working scale (median, refinement) */
    float *rawd;        /* NULL, or per pixel the winner of the unaggregated full-aperture cost */
    unsigned char *plain; /* NULL, or per pixel 1 where the unaggregated curve is flat within the noise */
    int smoothed;       /* 1: the views were pre-smoothed, their noise correlated by rho */
    double rho[4];      /* the noise's correlation between texels 0 .. 3 apart (smoothed views) */
    cost_ctx cc;
    depth_progress progress;
} depth_work;

static void depth_work_free(depth_work *w)
{
    free(w->views), free(w->lv), free(w->cost), free(w->sel), free(w->scratch), free(w->guide), free(w->disp), free(w->refs);
    free(w->rawd), free(w->plain);
}

static int depth_work_alloc(depth_work *w, const lf_lightfield *lf, const lf_lightfield_depth_opts *o, int nl,
                            double d0, double step, lf_error *err)
{
    int ns = lf->ns, nt = lf->nt;
    size_t np = (size_t)ns * nt;
    /* the row's per-subset curves (the half gate): 12 x labels x ns */
    size_t cost_scratch = COST_ROW_SCRATCH(ns) + (size_t)12 * nl * ns;
    cost_scratch = (cost_scratch + 15) / 16 * 16; /* each thread's part 64-byte aligned (the doubles in it too) */
    size_t gf_scratch = 10 * np;
    *w = (depth_work){
        .lf = lf,
        .o = o,
        .ns = ns,
        .nt = nt,
        .threads = o->threads > 0 ? o->threads : DEFAULT_THREADS,
        .nlabels = nl,
        .np = np,
        .d0 = d0,
        .step = step,
        .ref = lf_lightfield_view(lf, (lf->nu - 1) / 2, (lf->nv - 1) / 2),
        .per_thread = cost_scratch > gf_scratch ? cost_scratch : gf_scratch,
    };
    w->views = malloc(sizeof *w->views * (size_t)lf->nu * lf->nv);
    w->lv = malloc(sizeof *w->lv * (size_t)lf->nu * lf->nv * nl);
    w->cost = malloc(sizeof(float) * np * (size_t)nl);
    w->scratch = malloc(sizeof(float) * w->per_thread * (size_t)w->threads);
    w->guide = malloc(sizeof(float) * np * 14), w->disp = malloc(sizeof(float) * np * 2);
    w->conf = w->disp ? w->disp + np : NULL;
    w->refs = malloc(sizeof(float) * np * 3);
    if (!w->views || !w->lv || !w->cost || !w->scratch || !w->guide || !w->disp || !w->refs)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for a %d-label cost volume of %dx%d", nl, ns, nt);
    return LF_OK;
}

/* Every view but the reference, with its offset in view steps (nominal, or
 * calibrated: lf->view_shift) and its angular group. */
static void collect_views(depth_work *w)
{
    const lf_lightfield *lf = w->lf;
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    w->nviews = 0;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            if (iu == iu0 && iv == iv0)
                continue;
            dview *v = &w->views[w->nviews++];
            v->data = lf_lightfield_view(lf, iu, iv);
            v->valid = lf->valid ? lf->valid + ((size_t)iv * lf->nu + iu) * w->np : NULL;
            /* the angular group from the grid: calibrated positions a little
             * off a row or diagonal still belong to it */
            v->group = view_group(iu - iu0, (iv - iv0) * rv);
            double off[4];
            lf_depth_view_offset(lf, iu, iv, off);
            v->du = off[0], v->dv = off[1], v->ox = off[2], v->oy = off[3];
        }
}

/* Costs in units of the reference's mean channel sum, so the truncation and
 * the colour weights do not depend on exposure. */
static float reference_colour_scale(const float *ref, size_t np)
{
    double msum = 0;
    for (size_t i = 0; i < np * 3; i++)
        msum += ref[i];
    msum /= (double)np;
    return msum > 1e-12 ? (float)(1.0 / msum) : 1.f;
}

/* The gain that gives a view's difference to the reference, looked up at
 * a sub-pixel phase with separable weights wx, wy (4 taps each), the noise
 * of a whole-pixel lookup.  Noise of variance s^2 per texel makes the
 * difference's variance s^2 (1 + Vx Vy), Vx and Vy the lookup's variance
 * along each axis (lf_depth_noise_variance): for white noise (rho NULL) the
 * sums of the squared weights, 2 s^2 at a whole pixel and 1.41 s^2 at half
 * a pixel in x and y for the cubic; for pre-smoothed views, whose noise is
 * correlated by rho between texels k apart (the blur's kernel against
 * itself), sum_ij w_i w_j rho(|i - j|).  Unscaled, the labels whose phases
 * smooth the noise most cost least wherever noise is a large part of the
 * difference, and a noisy surface's disparities pile up at them; scaled by
 * sqrt(2 / (1 + Vx Vy)) every label's noise costs the same (docs/depth.md,
 * "Noisy views"). */
static float noise_gain(const float wx[4], const float wy[4], const double *rho)
{
    double vx = lf_depth_noise_variance(wx, rho), vy = lf_depth_noise_variance(wy, rho);
    return (float)sqrt(2.0 / (1.0 + vx * vy));
}

double lf_depth_noise_variance(const float w[4], const double rho[4])
{
    double v = 0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            v += (double)w[i] * w[j] * (rho ? rho[abs(i - j)] : i == j);
    return v;
}

/* The normalised Gaussian kernel of sigma px the views are pre-smoothed
 * by: k[0 .. 2r], r = ceil(3 sigma) within 1 .. LF_DEPTH_SMOOTH_MAX_R. */
static int smoothing_kernel(double sigma, float k[2 * LF_DEPTH_SMOOTH_MAX_R + 1])
{
    int r = (int)ceil(3 * sigma);
    r = r > LF_DEPTH_SMOOTH_MAX_R ? LF_DEPTH_SMOOTH_MAX_R : (r < 1 ? 1 : r);
    double ks = 0;
    for (int i = -r; i <= r; i++)
        ks += k[i + r] = (float)exp(-0.5 * i * i / (sigma * sigma));
    for (int i = 0; i <= 2 * r; i++)
        k[i] = (float)(k[i] / ks);
    return r;
}

void lf_depth_smoothed_noise_correlation(double sigma, double rho[4])
{
    float k[2 * LF_DEPTH_SMOOTH_MAX_R + 1];
    int r = smoothing_kernel(sigma, k);
    double e = 0;
    for (int i = 0; i <= 2 * r; i++)
        e += (double)k[i] * k[i];
    for (int m = 0; m < 4; m++) {
        double c = 0;
        for (int i = 0; i + m <= 2 * r; i++)
            c += (double)k[i] * k[i + m];
        rho[m] = c / e;
    }
}

/* View v's shift at disparity d, I_ref(x, y) = I_v(x - d du + ox, y - d dv
 * + oy), split as the row loop reads it; the columns it may read: with
 * the cubic lookup (views without missing samples) ix-1 .. ix+2, else
 * ix .. ix+1. */
static label_view label_shift(const dview *v, double d, int ns, int cubic, int noise_aware, const double *rho)
{
    label_view s;
    double sx = -d * v->du + v->ox, sy = -d * v->dv + v->oy;
    s.ix = (int)floor(sx), s.iy = (int)floor(sy);
    s.fx = (float)(sx - s.ix), s.fy = (float)(sy - s.iy);
    keys4(sx - s.ix, s.wx);
    keys4(sy - s.iy, s.wy);
    if (cubic && !v->valid) {
        s.xa = 1 - s.ix > 0 ? 1 - s.ix : 0;
        s.xb = ns - 3 - s.ix < ns - 1 ? ns - 3 - s.ix : ns - 1;
    } else {
        s.xa = s.ix < 0 ? -s.ix : 0;
        s.xb = ns - 1 - (s.fx > 0.f ? s.ix + 1 : s.ix);
        s.xb = s.xb > ns - 1 ? ns - 1 : s.xb;
    }
    s.gain = 1.f;
    if (noise_aware) {
        float lx[4] = {1 - s.fx, s.fx, 0, 0}, ly[4] = {1 - s.fy, s.fy, 0, 0};
        s.gain = cubic && !v->valid ? noise_gain(s.wx, s.wy, rho) : noise_gain(lx, ly, NULL);
    }
    return s;
}

/* Stages 1-2: the cost volume with its occlusion-aware view subsets, and
 * (thin structures on) the unaggregated full-aperture winner per pixel. */
static int build_cost_volume(depth_work *w, lf_error *err)
{
    const lf_lightfield_depth_opts *o = w->o;
    if (o->thin >= 0 && !(w->rawd = malloc(sizeof(float) * w->np)))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    w->cc = (cost_ctx){
        .lf = w->lf,
        .views = w->views,
        .nviews = w->nviews,
        .lv = w->lv,
        .ref = w->ref,
        .ref_valid = NULL,
        .nlabels = w->nlabels,
        .d0 = w->d0,
        .step = w->step,
        .tau = COST_TRUNCATION,
        .scale = w->scale,
        .alpha = o->defocus_weight >= 0 ? (float)o->defocus_weight : DEFAULT_DEFOCUS_WEIGHT,
        .occlusion = o->occlusion,
        .cubic = o->interp != 1,
        .half_gate = o->half_gate >= 0,
        .cost = w->cost,
        .rawd = w->rawd,
        .scratch = w->scratch,
        .scratch_per_thread = w->per_thread,
        .progress = &w->progress,
    };
    const lf_lightfield *lf = w->lf;
    for (int l = 0; l < w->nlabels; l++)
        for (int k = 0; k < w->nviews; k++)
            w->lv[(size_t)l * w->nviews + k] = label_shift(&w->views[k], w->d0 + w->step * l, w->ns, w->cc.cubic,
                                                          o->noise_aware > 0 || (o->noise_aware == 0 && w->smoothed),
                                                          w->smoothed ? w->rho : NULL);
    if (lf->valid)
        w->cc.ref_valid = lf->valid + ((size_t)((lf->nv - 1) / 2) * lf->nu + (lf->nu - 1) / 2) * w->np;
    lf_parallel_for(w->nt, w->threads, 4, cost_rows, &w->cc);
    return LF_OK;
}

/* The guided filter's per-pixel (Sigma + eps U)^-1 of the guide in a
 * (2r+1)^2 window, 6 planes xx xy xz yy yz zz, by the adjugate. */
static void guide_inverse_covariance(float *I, float *mI, float *Sinv, float *tmp, float *t2, int ns, int nt, int r,
                                     float eps)
{
    size_t np = (size_t)ns * nt;
    static const int pa[6] = {0, 0, 0, 1, 1, 2}, pb[6] = {0, 1, 2, 1, 2, 2};
    for (int k = 0; k < 6; k++) {
        mul_arr(I + pa[k] * np, I + pb[k] * np, t2, np);
        box_mean(t2, Sinv + k * np, tmp, ns, nt, r);
    }
    for (size_t i = 0; i < np; i++) {
        double m0 = mI[i], m1 = mI[np + i], m2 = mI[2 * np + i];
        double xx = Sinv[i] - m0 * m0 + eps, xy = Sinv[np + i] - m0 * m1, xz = Sinv[2 * np + i] - m0 * m2;
        double yy = Sinv[3 * np + i] - m1 * m1 + eps, yz = Sinv[4 * np + i] - m1 * m2;
        double zz = Sinv[5 * np + i] - m2 * m2 + eps;
        double c00 = yy * zz - yz * yz, c01 = xz * yz - xy * zz, c02 = xy * yz - xz * yy;
        double c11 = xx * zz - xz * xz, c12 = xy * xz - xx * yz, c22 = xx * yy - xy * xy;
        double det = xx * c00 + xy * c01 + xz * c02;
        double id = det > 1e-30 ? 1.0 / det : 0.0;
        Sinv[i] = (float)(c00 * id), Sinv[np + i] = (float)(c01 * id), Sinv[2 * np + i] = (float)(c02 * id);
        Sinv[3 * np + i] = (float)(c11 * id), Sinv[4 * np + i] = (float)(c12 * id);
        Sinv[5 * np + i] = (float)(c22 * id);
    }
}

/* Whether stage 3 adds the wide window (opts wide_window). */
static int wide_window_on(const lf_lightfield_depth_opts *o, int smoothed)
{
    return o->wide_window > 0 || (o->wide_window == 0 && smoothed);
}

/* The wide window's blend (aggregate_cost_volume): per pixel, the narrow
 * window's curve where it is confident, the wide one's where it is not. */
typedef struct blend_ctx {
    float *cost;       /* the narrow window's volume, blended in place */
    const float *wide; /* the wide window's */
    int w, L;
    size_t np;
} blend_ctx;

static void blend_rows(void *vctx, int y0, int y1, int tid)
{
    (void)tid;
    blend_ctx *c = vctx;
    size_t np = c->np;
    for (size_t i = (size_t)y0 * c->w; i < (size_t)y1 * c->w; i++) {
        float cb = FLT_MAX, sum = 0;
        int best = 0;
        for (int l = 0; l < c->L; l++) {
            float v = c->cost[(size_t)l * np + i];
            sum += v;
            if (v < cb)
                cb = v, best = l;
        }
        float a = lf_depth_curve_confidence(c->cost + i, np, c->L, best, sum) / WIDE_WINDOW_CONFIDENCE;
        a = a > 1.f ? 1.f : a;
        if (a >= 1.f)
            continue;
        for (int l = 0; l < c->L; l++) {
            size_t k = (size_t)l * np + i;
            c->cost[k] = a * c->cost[k] + (1.f - a) * c->wide[k];
        }
    }
}

/* The guided filter of radius r over every slice of cost, guide I (3
 * planes) with its statistics for r computed into the work's planes. */
static void guided_filter_volume(depth_work *w, float *cost, int r, float eps)
{
    size_t np = w->np;
    int ns = w->ns, nt = w->nt;
    float *I = w->guide, *mI = w->guide + 3 * np, *Sinv = w->guide + 6 * np, *tmp = w->guide + 12 * np,
          *t2 = w->guide + 13 * np;
    for (int ch = 0; ch < 3; ch++)
        box_mean(I + ch * np, mI + ch * np, tmp, ns, nt, r);
    guide_inverse_covariance(I, mI, Sinv, tmp, t2, ns, nt, r, eps);
    gf_ctx gc = {
        .w = ns, .h = nt, .r = r, .I = I, .mI = mI, .Sinv = Sinv,
        .cost = cost, .scratch = w->scratch, .per_thread = w->per_thread, .progress = &w->progress,
    };
    lf_parallel_for(w->nlabels, w->threads, 1, gf_slices, &gc);
}

/* Stage 3: edge-aware aggregation, every cost slice through a colour
 * guided filter guided by the reference; on pre-smoothed (noisy) views
 * also through one WIDE_WINDOW_FACTOR times wider, blended in where the
 * narrow one leaves a pixel unsure. */
static int aggregate_cost_volume(depth_work *w, lf_error *err)
{
    const lf_lightfield_depth_opts *o = w->o;
    int ns = w->ns, nt = w->nt;
    size_t np = w->np;
    /* guide: the reference colour, square-root encoded (closer to perceptual
     * steps than linear) and normalised to [0, 1] */
    float *I = w->guide;
    float gmax = 0;
    for (size_t i = 0; i < np; i++)
        for (int ch = 0; ch < 3; ch++) {
            float v = w->ref[3 * i + ch];
            v = v > 0 ? sqrtf(v) : 0.f;
            I[ch * np + i] = v;
            gmax = v > gmax ? v : gmax;
        }
    for (size_t i = 0; i < 3 * np; i++)
        I[i] = gmax > 0 ? I[i] / gmax : 0.f;
    int r = o->radius > 0 ? o->radius : (ns < nt ? ns : nt) / GUIDE_RADIUS_DIVISOR;
    if (r < MIN_GUIDE_RADIUS)
        r = MIN_GUIDE_RADIUS;
    float eps = o->eps > 0 ? (float)o->eps : DEFAULT_GUIDE_EPS;
    int wide = wide_window_on(o, w->smoothed);
    float *raw = NULL;
    size_t nv = np * (size_t)w->nlabels;
    if (wide) {
        if (!(raw = malloc(sizeof(float) * nv)))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the wide window's cost volume (%d labels)",
                                w->nlabels);
        memcpy(raw, w->cost, sizeof(float) * nv);
    }
    guided_filter_volume(w, w->cost, r, eps);
    if (!wide)
        return LF_OK;
    int rw = o->wide_window > 0 ? o->wide_window : WIDE_WINDOW_FACTOR * r;
    int lim = (ns < nt ? ns : nt) / 2 - 1;
    guided_filter_volume(w, raw, rw < lim ? rw : lim, eps);
    blend_ctx bc = {.cost = w->cost, .wide = raw, .w = ns, .L = w->nlabels, .np = np};
    lf_parallel_for(nt, w->threads, 8, blend_rows, &bc);
    free(raw);
    return LF_OK;
}

/* Stages 4-5: winner-take-all, the parabola's sub-label offset, and the
 * confidence of the aggregated cost curve. */
static void winner_take_all(depth_work *w)
{
    wta_ctx wc = {
        .w = w->ns, .h = w->nt, .nlabels = w->nlabels, .d0 = w->d0, .step = w->step,
        .cost = w->cost, .sel = w->sel ? w->sel : w->cost, .disp = w->disp, .conf = w->conf,
    };
    lf_parallel_for(w->nt, w->threads, 8, wta_rows, &wc);
}

/* The reference colour the median and the refinement weigh neighbours by:
 * square-root encoded in the working scale. */
static void encode_reference(depth_work *w)
{
    for (size_t i = 0; i < w->np; i++)
        for (int ch = 0; ch < 3; ch++) {
            float v = w->ref[3 * i + ch] * w->scale;
            w->refs[3 * i + ch] = v > 0 ? sqrtf(v) : 0.f;
        }
}

/* Stage 6: the confidence- and colour-weighted median of the
 * winner-take-all map into out (a copy when the median is off). */
static int weighted_median(depth_work *w, float *out, lf_error *err)
{
    int mr = w->o->median_radius < 0 ? DEFAULT_MEDIAN_RADIUS : w->o->median_radius;
    if (mr <= 0) {
        memcpy(out, w->disp, sizeof(float) * w->np);
        return LF_OK;
    }
    size_t wpt = 2 * (size_t)(2 * mr + 1) * (2 * mr + 1);
    if (wpt * w->threads > w->per_thread * w->threads)
        return lf_error_set(err, LF_ERR_NOMEM, "median radius %d too large", mr);
    wm_ctx wm = {
        .w = w->ns, .h = w->nt, .r = mr, .disp = w->disp, .conf = w->conf, .ref = w->refs,
        .out = out, .sigma2 = COLOUR_SIGMA2, .scratch = w->scratch, .per_thread = wpt,
    };
    lf_parallel_for(w->nt, w->threads, 4, wm_rows, &wm);
    return LF_OK;
}

/* Stage 7: thin structures (a wire, a wedge's tip) a pixel or two wide lose
 * to the window of the aggregation; where the pixel's own costs are
 * decisive (ratio) and a neighbour carries the same disparity, they come
 * back (docs/depth.md).  map: the median's output, updated in place. */
static int recover_thin_structures(depth_work *w, float *map, lf_error *err)
{
    if (!w->rawd)
        return LF_OK;
    double m = widest_view(w->lf);
    m = m > 0 ? m : 1;
    unsigned char *cand = malloc(w->np);
    if (!cand)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    float *tout = w->cost; /* the cost volume is no longer needed */
    thin_ctx tc = {
        .cc = &w->cc,
        .w = w->ns,
        .h = w->nt,
        .disp = map,
        .rawd = w->rawd,
        .cand = cand,
        .out = tout,
        .tol_d = (float)(THIN_MIN_SHIFT_PX / m),
        .tol_s = (float)(THIN_SAME_SHIFT_PX / m),
        .ratio = w->o->thin_ratio > 0 ? (float)w->o->thin_ratio : DEFAULT_THIN_RATIO,
        .map_max = -FLT_MAX,
    };
    for (size_t i = 0; i < w->np; i++)
        tc.map_max = map[i] > tc.map_max ? map[i] : tc.map_max;
    lf_parallel_for(w->nt, w->threads, 8, thin_cand_rows, &tc);
    lf_parallel_for(w->nt, w->threads, 8, thin_take_rows, &tc);
    for (size_t i = 0; i < w->np; i++)
        map[i] = tout[i];
    free(cand);
    return LF_OK;
}

/* Stage 8: continuous sub-label refinement, Gauss-Newton steps on the
 * views' photo-consistency around the labelled disparity (docs/depth.md).
 * map: updated in place. */
static void refine_disparity(depth_work *w, float *map)
{
    const lf_lightfield_depth_opts *o = w->o;
    if (o->refine < 0)
        return;
    int iters = o->refine > 0 ? o->refine : DEFAULT_REFINE_STEPS;
    size_t np = w->np;
    float *A = w->cost, *B = w->cost + np, *tmpd = w->cost + 2 * np; /* the cost volume is no longer needed */
    for (int it = 0; it < iters; it++) {
        memset(A, 0, sizeof(float) * 2 * np);
        for (int k = 0; k < w->nviews; k++) {
            if (w->views[k].valid)
                continue;
            gn_ctx gc = {
                .w = w->ns, .h = w->nt, .v = &w->views[k], .img = w->views[k].data, .ref = w->ref, .disp = map,
                .A = A, .B = B, .scale = w->scale, .c2 = REFINE_CAUCHY_C * REFINE_CAUCHY_C,
            };
            lf_parallel_for(w->nt, w->threads, 8, gn_rows, &gc);
        }
        for (size_t i = 0; i < np; i++)
            B[i] = A[i] * map[i] - B[i];
        gnagg_ctx ga = {
            .w = w->ns, .h = w->nt, .r = REFINE_RADIUS, .A = A, .B = B, .disp = map, .refs = w->refs,
            .out = tmpd, .dmax = (float)(REFINE_MAX_STEP_LABELS * w->step), .sigma2 = COLOUR_SIGMA2,
        };
        lf_parallel_for(w->nt, w->threads, 4, gnagg_rows, &ga);
        memcpy(map, tmpd, sizeof(float) * np);
    }
}

/* Standard normal deviates from a fixed-seed xorshift generator (the
 * simulated noise field must be the same on every run). */
static double gauss_next(uint64_t *s)
{
    double u[2];
    for (int k = 0; k < 2; k++) {
        *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
        u[k] = ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
    }
    return sqrt(-2.0 * log(u[0])) * cos(2.0 * M_PI * u[1]);
}

/* The contrast a curve of pure noise has, relative to its mean: the
 * views' geometry, labels, subsets and gate of w run on a flat field of the
 * reference's mean colour with white noise on every view, and the 99th
 * percentile of (mean - min) / mean over the pixels every view covers at
 * every label.  Scale-free: it holds for any noise level well under the
 * truncation, so the noise need not be measured. */
static int noise_contrast_ratio(const depth_work *w, double *ratio, lf_error *err)
{
    const lf_lightfield *lf = w->lf;
    double dmax = fmax(fabs(w->d0), fabs(w->d0 + w->step * (w->nlabels - 1))), mx = 0, my = 0;
    for (int k = 0; k < w->nviews; k++) {
        const dview *v = &w->views[k];
        mx = fmax(mx, dmax * fabs(v->du) + fabs(v->ox));
        my = fmax(my, dmax * fabs(v->dv) + fabs(v->oy));
    }
    int bx = (int)ceil(mx) + 3, by = (int)ceil(my) + 3;
    lf_lightfield s = *lf;
    s.ns = 2 * bx + 48, s.nt = 2 * by + 16;
    s.valid = NULL, s.missing = 0, s.half = NULL, s.view_gain = NULL;
    size_t vnp = (size_t)s.ns * s.nt, nview = (size_t)s.nu * s.nv;
    if (!(s.data = malloc(sizeof(float) * 3 * vnp * nview)))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the noise field");
    double mean[3] = {0, 0, 0};
    for (size_t i = 0; i < w->np; i++)
        for (int c = 0; c < 3; c++)
            mean[c] += w->ref[3 * i + c];
    uint64_t seed = 0x9e3779b97f4a7c15ull;
    for (size_t i = 0; i < 3 * vnp * nview; i++) {
        double m = mean[i % 3] / (double)w->np;
        s.data[i] = (float)(m * (1.0 + PLAIN_SIM_NOISE * gauss_next(&seed)));
    }
    lf_lightfield_depth_opts so = *w->o;
    so.thin = -1, so.progress = NULL;
    depth_work sw;
    int rc = depth_work_alloc(&sw, &s, &so, w->nlabels, w->d0, w->step, err);
    float *r = NULL;
    if (!rc) {
        sw.progress.o = &so, sw.progress.total = 1;
        sw.smoothed = w->smoothed;
        memcpy(sw.rho, w->rho, sizeof sw.rho);
        atomic_init(&sw.progress.done, 0);
        collect_views(&sw);
        sw.scale = reference_colour_scale(sw.ref, sw.np);
        rc = build_cost_volume(&sw, err);
    }
    size_t n = 0;
    if (!rc && !(r = malloc(sizeof(float) * sw.np)))
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (int y = by; !rc && y < s.nt - by; y++)
        for (int x = bx; x < s.ns - bx; x++) {
            size_t i = (size_t)y * s.ns + x;
            float mn = FLT_MAX, sum = 0;
            for (int l = 0; l < sw.nlabels; l++) {
                float v = sw.cost[(size_t)l * sw.np + i];
                sum += v, mn = v < mn ? v : mn;
            }
            float avg = sum / sw.nlabels;
            if (avg > 0)
                r[n++] = (avg - mn) / avg;
        }
    if (!rc) {
        qsort(r, n, sizeof *r, lf_depth_cmpf);
        *ratio = n ? r[(size_t)(PLAIN_NOISE_QUANTILE * (double)(n - 1))] : 0;
    }
    free(r), free(s.data);
    depth_work_free(&sw);
    return rc;
}

/* The plain pixels (see PLAIN_ABS_CONTRAST) of the unaggregated volume,
 * before the filter overwrites it. */
static int mark_plain(depth_work *w, lf_error *err)
{
    if (w->o->plain <= 0)
        return LF_OK;
    double ratio = 0;
    int rc = noise_contrast_ratio(w, &ratio, err);
    if (rc)
        return rc;
    float *mn = w->disp, *sum = w->disp + w->np; /* free until the minimum */
    if (!(w->plain = malloc(w->np)))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < w->np; i++)
        mn[i] = FLT_MAX, sum[i] = 0;
    for (int l = 0; l < w->nlabels; l++) {
        const float *c = w->cost + (size_t)l * w->np;
        for (size_t i = 0; i < w->np; i++)
            sum[i] += c[i], mn[i] = c[i] < mn[i] ? c[i] : mn[i];
    }
    for (size_t i = 0; i < w->np; i++) {
        float avg = sum[i] / w->nlabels, t = (float)ratio * avg;
        w->plain[i] = avg - mn[i] < (t > PLAIN_ABS_CONTRAST ? t : PLAIN_ABS_CONTRAST);
    }
    return LF_OK;
}

/* Stage 3b: semi-global aggregation over the filtered volume, its
 * penalties in units of the volume's mean cost contrast (mean over pixels
 * of the curve's mean minus its minimum), so they follow the cost's scale. */
static int semi_global(depth_work *w, lf_error *err)
{
    const lf_lightfield_depth_opts *o = w->o;
    if (o->sgm < 0)
        return LF_OK;
    double contrast = 0;
    for (size_t i = 0; i < w->np; i++) {
        float mn = FLT_MAX, sum = 0;
        for (int l = 0; l < w->nlabels; l++) {
            float v = w->cost[(size_t)l * w->np + i];
            sum += v, mn = v < mn ? v : mn;
        }
        contrast += sum / w->nlabels - mn;
    }
    contrast /= (double)w->np;
    double p1 = o->sgm_p1 > 0 ? o->sgm_p1 : DEFAULT_SGM_P1, p2 = o->sgm_p2 > 0 ? o->sgm_p2 : DEFAULT_SGM_P2;
    double edge = o->sgm_edge > 0 ? o->sgm_edge : DEFAULT_SGM_EDGE;
    if (!(w->sel = malloc(sizeof(float) * w->np * (size_t)w->nlabels)))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for semi-global aggregation (%d labels)", w->nlabels);
    return lf_depth_sgm(w->cost, w->sel, w->ns, w->nt, w->nlabels, w->refs, (float)(p1 * contrast),
                        (float)(p2 * contrast), (float)edge, w->threads, err);
}

/* Labels from d0 to d1 at about step apart: at least 3 (the parabola needs
 * neighbours). */
static int label_count(double d0, double d1, double step)
{
    int nl = (int)floor((d1 - d0) / step + 0.5) + 1;
    return nl < 3 ? 3 : nl;
}

/* smoothed: the Gaussian sigma the views were pre-smoothed by (0: none) */
static int depth_core(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, double d0, double d1, double step,
                      double smoothed, lf_image *disparity, lf_image *confidence, lf_error *err)
{
    int nl = label_count(d0, d1, step);
    if (nl > MAX_LABELS)
        return lf_error_set(err, LF_ERR_PARAM, "disparity range %g .. %g in steps of %g gives %d labels (at most %d)",
                            d0, d1, step, nl, MAX_LABELS);
    step = (d1 - d0) / (nl - 1);
    depth_work w;
    int rc = depth_work_alloc(&w, lf, o, nl, d0, step, err);
    if (rc)
        goto done;
    w.smoothed = smoothed > 0;
    if (w.smoothed)
        lf_depth_smoothed_noise_correlation(smoothed, w.rho);
    w.progress.o = o, w.progress.total = (wide_window_on(o, w.smoothed) ? 3L : 2L) * w.nt * nl;
    atomic_init(&w.progress.done, 0);
    collect_views(&w);
    w.scale = reference_colour_scale(w.ref, w.np);
    if ((rc = build_cost_volume(&w, err)) || (rc = mark_plain(&w, err)))
        goto done;
    if ((rc = aggregate_cost_volume(&w, err)))
        goto done;
    encode_reference(&w);
    if ((rc = semi_global(&w, err)))
        goto done;
    winner_take_all(&w);
    if (lf_image_alloc(disparity, w.ns, w.nt, 1, err)) {
        rc = err ? err->code : LF_ERR_NOMEM;
        goto done;
    }
    if ((rc = weighted_median(&w, disparity->data, err)) || (rc = recover_thin_structures(&w, disparity->data, err))) {
        lf_image_free(disparity);
        goto done;
    }
    if (w.plain && (rc = lf_depth_plain_fill(disparity->data, w.plain, w.conf, w.refs, w.ns, w.nt, err))) {
        lf_image_free(disparity);
        goto done;
    }
    refine_disparity(&w, disparity->data);
    if (confidence) {
        if (lf_image_alloc(confidence, w.ns, w.nt, 1, err)) {
            rc = err ? err->code : LF_ERR_NOMEM;
            lf_image_free(disparity);
            goto done;
        }
        memcpy(confidence->data, w.conf, sizeof(float) * w.np);
    }
    if (o->progress)
        o->progress(o->progress_ctx, w.progress.total, w.progress.total);
done:
    depth_work_free(&w);
    return rc;
}

/* The views' noise relative to their level: Immerkaer's estimate (1996),
 * sqrt(pi / 2) / 6 times the mean |I * [1 -2 1; -2 4 -2; 1 -2 1]|, of
 * the reference's sRGB-encoded grey over the half of its pixels with the
 * smaller gradient (texture and edges read as noise too), divided by the
 * mean grey.  -1 when it cannot be measured. */
static double view_noise_ratio(const lf_lightfield *lf, lf_error *err, int *rc)
{
    int w = lf->ns, h = lf->nt;
    size_t np = (size_t)w * h, ni = (size_t)(w - 2) * (h - 2);
    *rc = LF_OK;
    if (w < 8 || h < 8)
        return -1;
    float *g = malloc(sizeof(float) * np), *grad = malloc(sizeof(float) * ni), *lap = malloc(sizeof(float) * ni);
    float *sorted = malloc(sizeof(float) * ni);
    if (!g || !grad || !lap || !sorted) {
        free(g), free(grad), free(lap), free(sorted);
        *rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        return -1;
    }
    const float *ref = lf_lightfield_view(lf, (lf->nu - 1) / 2, (lf->nv - 1) / 2);
    double mean = 0;
    for (size_t i = 0; i < np; i++) {
        double v = (ref[3 * i] + ref[3 * i + 1] + ref[3 * i + 2]) / 3.0;
        g[i] = (float)lf_srgb_from_linear(v < 0 ? 0 : (v > 1 ? 1 : v));
        mean += g[i];
    }
    mean /= (double)np;
    size_t k = 0;
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++, k++) {
            const float *r0 = g + (size_t)(y - 1) * w + x, *r1 = r0 + w, *r2 = r1 + w;
            float l = r0[-1] - 2 * r0[0] + r0[1] - 2 * r1[-1] + 4 * r1[0] - 2 * r1[1] + r2[-1] - 2 * r2[0] + r2[1];
            lap[k] = fabsf(l);
            grad[k] = sorted[k] = fabsf(r1[1] - r1[-1]) + fabsf(r2[0] - r0[0]);
        }
    qsort(sorted, ni, sizeof(float), lf_depth_cmpf);
    float med = sorted[(ni - 1) / 2];
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < ni; i++)
        if (grad[i] <= med)
            sum += lap[i], n++;
    free(g), free(grad), free(lap), free(sorted);
    if (!n || !(mean > 1e-6))
        return -1;
    return sqrt(M_PI / 2) / 6 * (sum / (double)n) / mean;
}

double lf_lightfield_depth_noise_ratio(const lf_lightfield *lf, lf_error *err)
{
    int rc;
    return lf && lf->data ? view_noise_ratio(lf, err, &rc) : -1;
}

int lf_lightfield_depth_prefilter(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, double *sigma,
                                  double *noise_ratio, lf_error *err)
{
    int rc = LF_OK;
    double ratio = -1;
    *sigma = o->prefilter > 0 ? o->prefilter : 0;
    /* views with missing samples are not smoothed: a blur spreads the holes */
    if (o->prefilter == 0 && !lf->valid) {
        ratio = view_noise_ratio(lf, err, &rc);
        *sigma = !rc && ratio >= LF_DEPTH_PREFILTER_NOISE ? PREFILTER_SIGMA : 0;
    }
    if (noise_ratio)
        *noise_ratio = ratio;
    return rc;
}

typedef struct blur_ctx {
    const lf_lightfield *lf;
    float *out;
    const float *k;
    int r;
    float *scratch; /* per thread: one view */
} blur_ctx;

/* Views [v0, v1) blurred by the separable kernel k (2 r + 1 taps, borders
 * clamped). */
static void blur_views(void *vctx, int v0, int v1, int tid)
{
    blur_ctx *c = vctx;
    int w = c->lf->ns, h = c->lf->nt, r = c->r;
    size_t vn = (size_t)w * h * 3;
    float *tmp = c->scratch + (size_t)tid * vn;
    for (int v = v0; v < v1; v++) {
        const float *src = c->lf->data + (size_t)v * vn;
        float *dst = c->out + (size_t)v * vn;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int ch = 0; ch < 3; ch++) {
                    float a = 0;
                    for (int i = -r; i <= r; i++)
                        a += c->k[i + r] * src[((size_t)y * w + clampi(x + i, 0, w - 1)) * 3 + ch];
                    tmp[((size_t)y * w + x) * 3 + ch] = a;
                }
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int ch = 0; ch < 3; ch++) {
                    float a = 0;
                    for (int i = -r; i <= r; i++)
                        a += c->k[i + r] * tmp[((size_t)clampi(y + i, 0, h - 1) * w + x) * 3 + ch];
                    dst[((size_t)y * w + x) * 3 + ch] = a;
                }
    }
}

/* depth_core on the views blurred by a Gaussian of sigma px. */
static int depth_core_smoothed(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, double sigma, double d0,
                               double d1, double step, lf_image *disparity, lf_image *confidence, lf_error *err)
{
    float k[2 * LF_DEPTH_SMOOTH_MAX_R + 1];
    int r = smoothing_kernel(sigma, k);
    size_t n = (size_t)lf->nu * lf->nv * lf->ns * lf->nt * 3;
    int threads = lf_parallel_threads(o->threads > 0 ? o->threads : DEFAULT_THREADS);
    lf_lightfield b = *lf;
    b.half = NULL;
    b.data = malloc(sizeof(float) * n);
    float *scratch = malloc(sizeof(float) * (size_t)lf->ns * lf->nt * 3 * (size_t)threads);
    if (!b.data || !scratch) {
        free(b.data), free(scratch);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the smoothed views");
    }
    blur_ctx bc = {lf, b.data, k, r, scratch};
    lf_parallel_for(lf->nu * lf->nv, threads, 1, blur_views, &bc);
    free(scratch);
    int rc = depth_core(&b, o, d0, d1, step, sigma, disparity, confidence, err);
    free(b.data);
    return rc;
}

static int check_lf(const lf_lightfield *lf, lf_error *err)
{
    if (!lf || !lf->data || lf->nu * lf->nv < 2 || lf->ns < 8 || lf->nt < 8)
        return lf_error_set(err, LF_ERR_PARAM, "depth needs at least 2 views of at least 8x8 pixels");
    return LF_OK;
}

int lf_lightfield_depth(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, lf_image *disparity, lf_image *confidence,
                lf_error *err)
{
    lf_lightfield_depth_opts def = lf_lightfield_depth_defaults();
    if (!o)
        o = &def;
    int rc = check_lf(lf, err);
    if (rc)
        return rc;
    double d0 = o->d0, d1 = o->d1;
    if (!isfinite(d0) || !isfinite(d1))
        return lf_error_set(err, LF_ERR_PARAM, "disparity range must be finite");
    if (d0 >= d1 && (rc = lf_lightfield_depth_range(lf, o->threads, &d0, &d1, err)))
        return rc;
    double m = widest_view(lf);
    double step = o->step > 0 ? o->step : 0.2 / m;
    /* a wide range on a big grid (a gantry's 17 x 17 views, disparities of
     * several px per view) at the default spacing would pass the label
     * limit: the labels spread out instead (the refinement and the
     * sub-label fit keep the precision) */
    if (o->step <= 0 && (d1 - d0) / step + 1 > MAX_LABELS)
        step = (d1 - d0) / (MAX_LABELS - 1);
    /* noisy views are matched pre-smoothed */
    double sigma;
    if ((rc = lf_lightfield_depth_prefilter(lf, o, &sigma, NULL, err)))
        return rc;
    if (sigma > 0)
        return depth_core_smoothed(lf, o, sigma, d0, d1, step, disparity, confidence, err);
    return depth_core(lf, o, d0, d1, step, 0, disparity, confidence, err);
}

/* The views box-averaged f x f (calibrated offsets and missing samples
 * carried over). */
static int shrink_lightfield(const lf_lightfield *lf, int f, lf_lightfield *out, lf_error *err)
{
    int rc;
    lf_lightfield small = {0};
    if ((rc = lf_lightfield_alloc(&small, lf->nu, lf->nv, lf->ns / f, lf->nt / f, err)))
        return rc;
    small.disp_v_per_u = lf->disp_v_per_u;
    if (lf->view_shift) { /* calibrated views: offsets in the smaller pixels */
        small.view_shift = malloc(sizeof(double) * 4 * (size_t)lf->nu * lf->nv);
        if (!small.view_shift) {
            lf_lightfield_free(&small);
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        }
        for (int k = 0; k < lf->nu * lf->nv; k++)
            for (int i = 0; i < 4; i++)
                small.view_shift[4 * k + i] = lf->view_shift[4 * k + i] / (i >= 2 ? f : 1);
    }
    size_t snp = (size_t)small.ns * small.nt;
    if (lf->valid) { /* a small sample is valid when all its f x f samples are */
        if (!(small.valid = malloc(sizeof(float) * snp * (size_t)lf->nu * lf->nv))) {
            lf_lightfield_free(&small);
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        }
        for (int k = 0; k < lf->nu * lf->nv; k++)
            for (int y = 0; y < small.nt; y++)
                for (int x = 0; x < small.ns; x++) {
                    float ok = 1.f;
                    for (int j = 0; j < f; j++)
                        for (int i = 0; i < f; i++)
                            if (lf->valid[(size_t)k * lf->ns * lf->nt + (size_t)(y * f + j) * lf->ns + x * f + i] == 0.f)
                                ok = 0.f;
                    small.valid[(size_t)k * snp + (size_t)y * small.ns + x] = ok;
                }
    }
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            const float *src = lf_lightfield_view(lf, iu, iv);
            float *dst = lf_lightfield_view(&small, iu, iv);
            for (int y = 0; y < small.nt; y++)
                for (int x = 0; x < small.ns; x++)
                    for (int c = 0; c < 3; c++) {
                        float s = 0;
                        for (int j = 0; j < f; j++)
                            for (int i = 0; i < f; i++)
                                s += src[((size_t)(y * f + j) * lf->ns + (x * f + i)) * 3 + c];
                        dst[((size_t)y * small.ns + x) * 3 + c] = s / (float)(f * f);
                    }
        }
    *out = small;
    return LF_OK;
}

/* One coarse sweep over [s0, s1] (px/view at the small views' scale): the
 * 1st..99th percentile of the confident pixels' disparities into *lo, *hi
 * (same scale).  interior: pixels whose minimum is an end label are left
 * out (the wide sweep: at the views' limit nothing confirms a minimum, and
 * periodic texture has false minima everywhere, including there). */
static int range_pass(const lf_lightfield *small, int threads, double s0, double s1, double step, int interior,
                      double *lo, double *hi, lf_error *err)
{
    lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
    o.threads = threads;
    o.occlusion = 0;
    o.median_radius = 0;
    o.refine = -1, o.interp = 1, o.thin = -1, o.plain = -1; /* the range needs no sub-label precision */
    o.radius = 2;
    lf_image disp = {0}, conf = {0};
    int rc = depth_core(small, &o, s0, s1, step, 0, &disp, &conf, err);
    if (rc)
        return rc;
    size_t np = (size_t)small->ns * small->nt, n = 0;
    float *vals = malloc(sizeof(float) * np);
    if (!vals) {
        lf_image_free(&disp), lf_image_free(&conf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (int pass = 0; pass < 2 && n < np / 20; pass++) {
        n = 0;
        float thr = pass == 0 ? 0.3f : 0.f;
        for (size_t i = 0; i < np; i++)
            if ((conf.data[i] > thr || pass == 1) &&
                (!interior || (disp.data[i] > s0 + 0.5 * step && disp.data[i] < s1 - 0.5 * step)))
                vals[n++] = disp.data[i];
    }
    qsort(vals, n, sizeof(float), lf_depth_cmpf);
    *lo = vals[(size_t)(0.01 * (n - 1))], *hi = vals[(size_t)(0.99 * (n - 1))];
    free(vals);
    lf_image_free(&disp), lf_image_free(&conf);
    return LF_OK;
}

int lf_lightfield_depth_range(const lf_lightfield *lf, int threads, double *d0, double *d1, lf_error *err)
{
    return lf_lightfield_depth_range_report(lf, threads, d0, d1, NULL, err);
}

int lf_lightfield_depth_range_report(const lf_lightfield *lf, int threads, double *d0, double *d1,
                                     lf_lightfield_depth_range_info *info, lf_error *err)
{
    int rc = check_lf(lf, err);
    if (rc)
        return rc;
    /* quarter resolution by 4x4 box averaging: disparities shrink by 4 */
    int f = (lf->ns >= 64 && lf->nt >= 64) ? 4 : 1;
    lf_lightfield small;
    if ((rc = shrink_lightfield(lf, f, &small, err)))
        return rc;
    double m = widest_view(lf);
    /* the widest search the views allow: shifts up to a quarter of the view
     * at the outermost view.  The first sweep stops at 8 px/view (the common
     * case, at its cost); an end the data reaches is widened below. */
    double view_lim = (lf->ns < lf->nt ? lf->ns : lf->nt) / 4.0 / (m > 0 ? m : 1);
    double lim0 = view_lim > 8 ? 8 : view_lim, a = -lim0, b = lim0;
    double step = 0.25 / m; /* 0.25 px at the outermost view, at quarter resolution */
    double first_labels = (b - a) / f / step;
    double lo = 0, hi = 0;
    if (info)
        memset(info, 0, sizeof *info);
    for (int round = 0;; round++) {
        if ((rc = range_pass(&small, threads, a / f, b / f, step, 0, &lo, &hi, err)))
            break;
        lo *= f, hi *= f;
        double pad = 0.05 * (hi - lo) + step * f;
        if (info && round == 0) {
            info->first_d0 = lo - pad < a ? a : lo - pad;
            info->first_d1 = hi + pad > b ? b : hi + pad;
        }
        /* an end the data reaches: the 1st or 99th percentile sits on the
         * end label, so more than the 1% the percentile drops have their
         * cost still falling toward that end (a minimum inside the range
         * would land a parabola offset or more inside).  Double that end,
         * up to the view's limit; the label count stays that of the first
         * sweep (coarser steps: the range needs no precision) */
        double na = lo <= a + 0.5 * step * f && a > -view_lim ? fmax(2 * a, -view_lim) : a;
        double nb = hi >= b - 0.5 * step * f && b < view_lim ? fmin(2 * b, view_lim) : b;
        /* a disparity far beyond the first sweep matches nowhere in it, so
         * its cost need not fall toward the end: one sweep over the whole
         * range the views allow, at the first sweep's label count, says
         * whether more than 1% of the confident pixels lie beyond */
        if (round == 0 && view_lim > lim0) {
            double ws = fmax(step, 2 * view_lim / f / first_labels), wlo, whi;
            if ((rc = range_pass(&small, threads, -view_lim / f, view_lim / f, ws, 1, &wlo, &whi, err)))
                break;
            wlo *= f, whi *= f;
            double wpad = 0.05 * (whi - wlo) + ws * f;
            if (whi > b + ws * f)
                nb = fmax(nb, fmin(whi + wpad, view_lim));
            if (wlo < a - ws * f)
                na = fmin(na, fmax(wlo - wpad, -view_lim));
        }
        if (na == a && nb == b) {
            *d0 = lo - pad, *d1 = hi + pad;
            if (*d0 < a)
                *d0 = a;
            if (*d1 > b)
                *d1 = b;
            if (!(*d0 < *d1))
                *d0 = a, *d1 = b;
            /* what the reduced views lost (fine periodic texture) is
             * checked at full resolution; it can only widen */
            if (f > 1) {
                lf_depth_range_check_info ci;
                if ((rc = lf_depth_range_check(lf, threads, view_lim, m, d0, d1, &ci, err)))
                    break;
                if (info) {
                    info->full_samples = ci.samples, info->full_confirmed = ci.confirmed;
                    info->full_widened = ci.widened, info->full_lo = ci.lo, info->full_hi = ci.hi;
                }
            }
            break;
        }
        a = na, b = nb;
        step = fmax(step, (b - a) / f / first_labels);
        if (info)
            info->widened = 1;
    }
    if (info)
        info->search_d0 = a, info->search_d1 = b;
    lf_lightfield_free(&small);
    return rc;
}

