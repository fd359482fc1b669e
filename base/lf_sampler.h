/* lf_sampler.h - per-pixel sample sequences, deterministic for a seed.
 *
 * Every sample value is a pure function of (seed, pixel, sample index,
 * dimension), so results do not depend on which thread renders which pixel
 * or in what order.
 *
 * LF_SAMPLER_SOBOL: Owen-scrambled Sobol points, shuffled per pixel and
 * padded pairwise (Burley 2020, "Practical Hash-based Owen Scrambling"):
 * every pair of dimensions is the 2D Sobol (0,2)-sequence with its own index
 * shuffle and its own nested-uniform scramble, so each 2D projection is well
 * stratified for power-of-two sample counts.  pbrt-v4's zsobol, sobol,
 * paddedsobol, pmj02bn and halton map to it.
 * LF_SAMPLER_STRATIFIED: jittered strata (x by y) in each 2D pair, strata
 * permuted independently per pair.
 * LF_SAMPLER_INDEPENDENT: uniform random numbers (a hash, no state).
 */
#ifndef LF_SAMPLER_H
#define LF_SAMPLER_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lf_sampler_kind {
    LF_SAMPLER_SOBOL,
    LF_SAMPLER_STRATIFIED,
    LF_SAMPLER_INDEPENDENT
} lf_sampler_kind;

typedef struct lf_sampler {
    lf_sampler_kind kind;
    uint32_t seed;
    int spp;
    int strata_x, strata_y; /* stratified only: strata_x * strata_y == spp */
} lf_sampler;

/* The state of one pixel sample: cheap to create, no allocation. */
typedef struct lf_sample_stream {
    const lf_sampler *s;
    uint32_t pixel_hash;
    uint32_t index;
    uint32_t rindex; /* index with its bits reversed (the Owen scramble works on it) */
    uint32_t dim;
} lf_sample_stream;

void lf_sample_start(lf_sample_stream *st, const lf_sampler *s, int px, int py, uint32_t index);
/* The same in two steps, for a renderer that draws many samples per pixel:
 * the pixel's hash once, then each sample from it.
 * lf_sample_start(st, s, px, py, i) ==
 * lf_sample_start_pixel(st, s, lf_sample_pixel_hash(s, px, py), i). */
uint32_t lf_sample_pixel_hash(const lf_sampler *s, int px, int py);
void lf_sample_start_pixel(lf_sample_stream *st, const lf_sampler *s, uint32_t pixel_hash, uint32_t index);
/* Next 1D value in [0,1). */
float lf_sample_1d(lf_sample_stream *st);
/* Next 2D value in [0,1)^2 (consumes a dimension pair). */
void lf_sample_2d(lf_sample_stream *st, float *u0, float *u1);
/* Advances past one dimension pair without computing it, so that a value
 * a path does not need costs nothing while later dimensions keep their
 * place (the layout per bounce stays fixed). */
static inline void lf_sample_skip(lf_sample_stream *st)
{
    st->dim += 2;
}
/* The same as doubles, for camera coordinates. */
void lf_sample_2d_d(lf_sample_stream *st, double *u0, double *u1);

/* Hash helpers shared by anything that needs decorrelated seeds (inline:
 * several run for every sample dimension pair). */
/* 32-bit integer hash (Chris Wellons' "lowbias32" finaliser). */
static inline uint32_t lf_hash_u32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
static inline uint32_t lf_hash_combine(uint32_t a, uint32_t b)
{
    return lf_hash_u32(a ^ (b + 0x9e3779b9u + (a << 6) + (a >> 2)));
}

#ifdef __cplusplus
}
#endif
#endif
