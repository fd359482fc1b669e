#include "lf_sampler.h"

#include <pthread.h>

static inline uint32_t reverse_bits(uint32_t x)
{
    x = __builtin_bswap32(x);
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

/* Laine-Karras style hash that only lets each bit depend on lower bits;
 * applied to bit-reversed values it is a nested uniform (Owen) scramble
 * (Burley 2020, improved constants from Nathan Vegdahl's analysis). */
static inline uint32_t lk_permute(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}


/* First two Sobol dimensions: dimension 0 is the van der Corput sequence
 * (bit reversal); dimension 1 has direction numbers v_k = v_{k-1} ^ (v_{k-1} >> 1).
 * Dimension 1 is linear over GF(2) in the index bits, so it is evaluated a
 * byte at a time from four 256-entry tables; the tables hold the
 * bit-reversed values, which is the form the Owen scramble consumes. */
static uint32_t sobol1_rev_table[4][256];
static pthread_once_t sobol_once = PTHREAD_ONCE_INIT;

static void sobol_tables_init(void)
{
    uint32_t v[32];
    v[0] = 0x80000000u;
    for (int k = 1; k < 32; k++)
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    for (int byte = 0; byte < 4; byte++)
        for (int b = 0; b < 256; b++) {
            uint32_t x = 0;
            for (int k = 0; k < 8; k++)
                if (b & (1 << k))
                    x ^= v[8 * byte + k];
            sobol1_rev_table[byte][b] = reverse_bits(x);
        }
}

/* reverse_bits(sobol dimension 1 of index i) */
static inline uint32_t sobol1_rev(uint32_t i)
{
    return sobol1_rev_table[0][i & 0xffu] ^ sobol1_rev_table[1][(i >> 8) & 0xffu] ^
           sobol1_rev_table[2][(i >> 16) & 0xffu] ^ sobol1_rev_table[3][i >> 24];
}

static float to_unit(uint32_t x)
{
    float f = (float)(x >> 8) * 0x1p-24f;
    return f;
}

/* Per-dimension scramble seeds from the pair's hash h: odd multipliers are
 * bijections, so distinct h give distinct seeds, and h is already a
 * well-mixed hash of (seed, pixel, pair). */
static inline uint32_t seed_a(uint32_t h)
{
    return h * 0x2c1b3c6du + 0x68e31da4u;
}
static inline uint32_t seed_b(uint32_t h)
{
    return h * 0x297a2d39u + 0xb5297a4du;
}

uint32_t lf_sample_pixel_hash(const lf_sampler *s, int px, int py)
{
    if (s->kind == LF_SAMPLER_SOBOL)
        pthread_once(&sobol_once, sobol_tables_init);
    return lf_hash_combine(lf_hash_combine(s->seed, (uint32_t)px), (uint32_t)py);
}

void lf_sample_start_pixel(lf_sample_stream *st, const lf_sampler *s, uint32_t pixel_hash, uint32_t index)
{
    st->s = s;
    st->pixel_hash = pixel_hash;
    st->index = index;
    st->rindex = reverse_bits(index);
    st->dim = 0;
}

void lf_sample_start(lf_sample_stream *st, const lf_sampler *s, int px, int py, uint32_t index)
{
    lf_sample_start_pixel(st, s, lf_sample_pixel_hash(s, px, py), index);
}

static void sample_pair(lf_sample_stream *st, uint32_t *a, uint32_t *b)
{
    uint32_t pair = st->dim >> 1;
    st->dim += 2;
    uint32_t h = lf_hash_combine(st->pixel_hash, pair);
    switch (st->s->kind) {
    case LF_SAMPLER_SOBOL: {
        /* Owen scrambling is reverse o hash o reverse; the reversals that
         * cancel are left out:
         *   i = owen(index)            shuffled index
         *   a = owen(dim0(i)) = reverse(lk(i))           since dim0 = reverse
         *   b = owen(dim1(i)) = reverse(lk(reverse(dim1(i)))) */
        uint32_t i = reverse_bits(lk_permute(st->rindex, h));
        *a = reverse_bits(lk_permute(i, seed_a(h)));
        *b = reverse_bits(lk_permute(sobol1_rev(i), seed_b(h)));
        return;
    }
    case LF_SAMPLER_STRATIFIED: {
        uint32_t nx = (uint32_t)st->s->strata_x, ny = (uint32_t)st->s->strata_y, n = nx * ny;
        /* A random permutation of the strata: index -> stratum via a
         * bijective hash on [0, n) by cycle-walking on the next power of two. */
        uint32_t mask = 1;
        while (mask < n)
            mask <<= 1;
        mask -= 1;
        uint32_t k = st->index % n;
        do {
            k = (lk_permute(k, h) ^ (h >> 7)) & mask;
        } while (k >= n);
        uint32_t jx = lf_hash_combine(h, st->index * 2u + 1u), jy = lf_hash_combine(h, st->index * 2u + 2u);
        double fx = ((k % nx) + (jx >> 8) * 0x1p-24) / nx;
        double fy = ((k / nx) + (jy >> 8) * 0x1p-24) / ny;
        *a = (uint32_t)(fx * 4294967296.0);
        *b = (uint32_t)(fy * 4294967296.0);
        return;
    }
    case LF_SAMPLER_INDEPENDENT:
    default:
        *a = lf_hash_combine(h, st->index * 2u);
        *b = lf_hash_combine(h, st->index * 2u + 1u);
        return;
    }
}

float lf_sample_1d(lf_sample_stream *st)
{
    if (st->s->kind == LF_SAMPLER_SOBOL) {
        /* a 1D value needs only the first Sobol dimension of the pair */
        uint32_t h = lf_hash_combine(st->pixel_hash, st->dim >> 1);
        st->dim += 2;
        uint32_t i = reverse_bits(lk_permute(st->rindex, h));
        return to_unit(reverse_bits(lk_permute(i, seed_a(h))));
    }
    uint32_t a, b;
    sample_pair(st, &a, &b);
    return to_unit(a);
}

void lf_sample_2d(lf_sample_stream *st, float *u0, float *u1)
{
    uint32_t a, b;
    sample_pair(st, &a, &b);
    *u0 = to_unit(a);
    *u1 = to_unit(b);
}

void lf_sample_2d_d(lf_sample_stream *st, double *u0, double *u1)
{
    uint32_t a, b;
    sample_pair(st, &a, &b);
    *u0 = (a + 0.5) * 0x1p-32;
    *u1 = (b + 0.5) * 0x1p-32;
}
