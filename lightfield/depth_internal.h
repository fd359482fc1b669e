/* depth_internal.h - stages of lf_lightfield_depth split out of depth.c
 * (not public; docs/depth.md has the method). */
#ifndef LF_LIGHTFIELD_DEPTH_INTERNAL_H
#define LF_LIGHTFIELD_DEPTH_INTERNAL_H

#include "base/lf_error.h"

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

/* qsort's comparison of floats, ascending */
static inline int lf_depth_cmpf(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

#endif
