/* depth_internal.h - stages of lf_lightfield_depth split out of depth.c
 * (not public; docs/depth.md has the method). */
#ifndef LF_LIGHTFIELD_DEPTH_INTERNAL_H
#define LF_LIGHTFIELD_DEPTH_INTERNAL_H

#include <float.h>
#include <stdlib.h>

#include "base/lf_error.h"
#include "lightfield/lf_lightfield.h"

/* Semi-global aggregation (Hirschmueller 2008) of cost[label][pixel]
 * (w x h pixels, nlabels slices) along 4 paths (left, right, up, down):
 * sum (same layout) receives the sum of the 4 path costs.  p1: the
 * penalty of a one-label step between neighbours; p2: of a larger jump,
 * divided by (1 + dI / edge) where dI is the largest channel difference of
 * the neighbours' colours in refs (RGB interleaved, w x h), so depth jumps
 * where the colour does.  threads as lf_parallel_for. */
int lf_depth_sgm(const float *cost, float *sum, int w, int h, int nlabels, const float *refs, float p1, float p2,
                 float edge, int threads, lf_error *err);

/* Plain regions (docs/depth.md, "Plain regions, noise-relative"): the
 * 4-connected pixels marked in plain (1: the cost curve is flat within the
 * views' noise) whose 5 x 5 mean colours in refs (square-root encoded RGB,
 * w x h) lie within 0.02 of the region's mean form regions; a region of at
 * least 0.1 % of the image takes, where map is nearer, the lower quartile
 * of map over its evidence: pixels within 2 px that are not plain, have 2
 * or more of 8 neighbours not plain, a confidence (conf) of at least 0.3
 * and a colour within 0.04 of the region's mean. */
int lf_depth_plain_fill(float *map, const unsigned char *plain, const float *conf, const float *refs, int w, int h,
                        lf_error *err);

/* What the full-resolution check of a range found. */
typedef struct lf_depth_range_check_info {
    int samples, confirmed; /* sample pixels swept; confident ones confirmed by their neighbours */
    double lo, hi;          /* the confirmed winners' 1st and 99th percentiles (confirmed >= 20) */
    int widened;            /* 1: *d0 or *d1 moved out to them */
} lf_depth_range_check_info;

/* The full-resolution check of an estimated range [*d0, *d1] (px/view;
 * docs/depth.md, "The range checked at full resolution"): a 3 x 3 window
 * every 24 px of the reference, swept at half-pixel steps at the outermost
 * view (m view steps from the reference) over the disparities up to lim
 * at which every view stays inside the image; the winners that are
 * confident and agree with 2 or more of their 8 neighbouring samples widen
 * the range to their 1st..99th percentile (never narrow it). */
int lf_depth_range_check(const lf_lightfield *lf, int threads, double lim, double m, double *d0, double *d1,
                         lf_depth_range_check_info *info, lf_error *err);

/* A winner's confidence: the best cost more than LF_DEPTH_CONFIDENCE_AWAY
 * labels from the minimum, minus the minimum, over the curve's mean, times
 * LF_DEPTH_CONFIDENCE_GAIN, at most 1 (the main method and the range's
 * full-resolution check). */
#define LF_DEPTH_CONFIDENCE_GAIN 4.f
#define LF_DEPTH_CONFIDENCE_AWAY 2

/* That confidence of a curve of L costs cv[l * stride] whose minimum is at
 * label best and whose costs sum to sum, in [0, 1]. */
static inline float lf_depth_curve_confidence(const float *cv, size_t stride, int L, int best, float sum)
{
    float c2 = FLT_MAX, cb = cv[(size_t)best * stride];
    for (int l = 0; l < L; l++)
        if (abs(l - best) > LF_DEPTH_CONFIDENCE_AWAY && cv[(size_t)l * stride] < c2)
            c2 = cv[(size_t)l * stride];
    float mean = sum / L;
    float conf = c2 < FLT_MAX && mean > 0 ? (c2 - cb) / (mean + 1e-6f) : 0.f;
    conf = conf * LF_DEPTH_CONFIDENCE_GAIN;
    return conf > 1.f ? 1.f : (conf < 0.f ? 0.f : conf);
}

/* The variance, in units of the views' per-texel noise variance, of a
 * 4-tap lookup with weights w of noise whose texels k apart are correlated
 * by rho[k] (rho NULL: white noise, the sum of w^2).  depth.c whitens
 * pre-smoothed views by it. */
double lf_depth_noise_variance(const float w[4], const double rho[4]);
/* rho of white noise after the pre-smoothing by a Gaussian of sigma px
 * (its sampled kernel, radius ceil(3 sigma) up to LF_DEPTH_SMOOTH_MAX_R,
 * against itself): rho[0] = 1. */
#define LF_DEPTH_SMOOTH_MAX_R 8
void lf_depth_smoothed_noise_correlation(double sigma, double rho[4]);

/* View (iu, iv)'s offset from the reference: out[0], out[1] its baseline
 * in view steps (v scaled by disp_v_per_u), out[2], out[3] a constant pixel
 * offset (0, or lf->view_shift's calibration). */
static inline void lf_depth_view_offset(const lf_lightfield *lf, int iu, int iv, double out[4])
{
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    out[0] = iu - (lf->nu - 1) / 2, out[1] = (iv - (lf->nv - 1) / 2) * rv, out[2] = out[3] = 0;
    if (lf->view_shift)
        for (int i = 0; i < 4; i++)
            out[i] = lf->view_shift[4 * ((size_t)iv * lf->nu + iu) + i];
}

/* qsort's comparison of floats, ascending */
static inline int lf_depth_cmpf(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

#endif
