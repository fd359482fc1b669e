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
 * LF_SAMPLER_HALTON: pbrt-v4's HaltonSampler: one Halton sequence over the
 * image (pixels tiled every 128), whose first two dimensions (bases 2 and
 * 3) place the samples of a pixel inside it; dimension d >= 2 is the
 * radical inverse in the d-th prime base (wrapping to 2 after 1000), with
 * random digit permutations ("permutedigits", pbrt's default), Owen
 * scrambling ("owen") or none ("none").  Needs lf_sampler_prepare.
 * LF_SAMPLER_PMJ02BN: pbrt-v4's PMJ02BNSampler structure over progressive
 * (0,2) sequences (every power-of-two prefix a (0,2)-net, the property of
 * Christensen, Kensler and Kilpatrick's pmj02), generated at start-up by
 * nested scrambling of the first two Sobol dimensions; pbrt's tables are
 * also blue-noise optimised, these are not.  Pixel samples spread one
 * sequence over a tile of pixels (so neighbouring pixels are stratified
 * together), other dimension pairs take a per-pixel shuffle of the first
 * spp points of one of 5 sequences with a random toroidal shift (pbrt
 * shifts by a blue-noise texture), 1D values are shuffled jittered strata.
 * spp must be a power of 4.  Needs lf_sampler_prepare.
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
    LF_SAMPLER_INDEPENDENT,
    LF_SAMPLER_HALTON,
    LF_SAMPLER_PMJ02BN
} lf_sampler_kind;

typedef enum lf_halton_random {
    LF_HALTON_PERMUTE_DIGITS, /* pbrt-v4 "permutedigits" (default) */
    LF_HALTON_OWEN,           /* "owen" */
    LF_HALTON_NONE            /* "none" */
} lf_halton_random;

typedef struct lf_sampler {
    lf_sampler_kind kind;
    uint32_t seed;
    int spp;
    int strata_x, strata_y; /* stratified only: strata_x * strata_y == spp */
    /* halton (lf_sampler_prepare) */
    lf_halton_random randomize;
    int halton_scale[2], halton_exp[2]; /* 2^e0 and 3^e1 covering min(resolution, 128) */
    uint64_t halton_mult_inv[2];
    /* pmj02bn (lf_sampler_prepare; lf_sampler_free releases them) */
    float *pmj_sets;        /* LF_PMJ_SETS sequences of pmj_set_len points, x y interleaved */
    int pmj_set_len;
    float *pmj_pixel;       /* pmj_tile^2 pixels x spp in-pixel positions */
    int pmj_tile;
} lf_sampler;

enum { LF_PMJ_SETS = 5, LF_PMJ_MAX = 65536 };

/* Precomputes what halton and pmj02bn need for a film of xres x yres
 * (other kinds: nothing).  Returns 0, or -1 when out of memory or spp is
 * not allowed (pmj02bn: a power of 4 up to 65536). */
int lf_sampler_prepare(lf_sampler *s, int xres, int yres);
void lf_sampler_free(lf_sampler *s);

/* pmj02bn: n points (n a power of 2, <= LF_PMJ_MAX) of one progressive
 * (0,2) sequence generated from seed; xy receives 2n floats.  Every prefix
 * of 2^k points is a (0,k,2)-net in base 2.  Returns 0, or -1 for a bad n. */
int lf_pmj02bn_generate(uint32_t seed, int n, float *xy);

/* The state of one pixel sample: cheap to create, no allocation. */
typedef struct lf_sample_stream {
    const lf_sampler *s;
    uint64_t halton_index; /* halton: the sample's index in the image-wide sequence */
    int px, py;            /* pmj02bn: the pixel */
    uint32_t pixel_hash;
    uint32_t index;
    uint32_t rindex; /* index with its bits reversed (the Owen scramble works on it) */
    uint32_t dim;
} lf_sample_stream;

void lf_sample_start(lf_sample_stream *st, const lf_sampler *s, int px, int py, uint32_t index);
/* The same in two steps, for a renderer that draws many samples per pixel:
 * the pixel's hash once, then each sample from it.
 * lf_sample_start(st, s, px, py, i) ==
 * lf_sample_start_pixel(st, s, lf_sample_pixel_hash(s, px, py), px, py, i)
 * (the pixel itself is still needed by halton, whose index depends on it). */
uint32_t lf_sample_pixel_hash(const lf_sampler *s, int px, int py);
void lf_sample_start_pixel(lf_sample_stream *st, const lf_sampler *s, uint32_t pixel_hash, int px, int py,
                           uint32_t index);
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
/* The first value of lf_sample_2d_d's pair (the same dimensions consumed),
 * without computing the second. */
double lf_sample_1d_d(lf_sample_stream *st);
/* Three values drawn jointly, in two pair slots: with the Sobol sampler
 * the first three dimensions of one Owen-scrambled Sobol point (stratified
 * together, e.g. film position and time for motion blur), else a pair and
 * the first value of the next. */
void lf_sample_3d_d(lf_sample_stream *st, double *u0, double *u1, double *u2);

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
/* 64-bit integer hash (MurmurHash3's fmix64 finaliser): every input bit
 * reaches every output bit. */
static inline uint64_t lf_hash_u64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}
static inline uint32_t lf_hash_combine(uint32_t a, uint32_t b)
{
    return lf_hash_u32(a ^ (b + 0x9e3779b9u + (a << 6) + (a >> 2)));
}

#ifdef __cplusplus
}
#endif
#endif
