#include "lf_sampler.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

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
static uint32_t sobol1_rev_table[4][256], sobol2_rev_table[4][256];
static pthread_once_t sobol_once = PTHREAD_ONCE_INIT;

static void sobol_table(const uint32_t v[32], uint32_t table[4][256])
{
    for (int byte = 0; byte < 4; byte++)
        for (int b = 0; b < 256; b++) {
            uint32_t x = 0;
            for (int k = 0; k < 8; k++)
                if (b & (1 << k))
                    x ^= v[8 * byte + k];
            table[byte][b] = reverse_bits(x);
        }
}

static void sobol_tables_init(void)
{
    uint32_t v[32];
    v[0] = 0x80000000u;
    for (int k = 1; k < 32; k++)
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    sobol_table(v, sobol1_rev_table);
    /* Dimension 2 (Joe and Kuo's third): primitive polynomial x^2 + x + 1,
     * m_1 = 1, m_2 = 3, m_k = 2 m_{k-1} ^ 4 m_{k-2} ^ m_{k-2}; as 32-bit
     * direction numbers v_k = m_k 2^(32-k): v_k = v_{k-1} ^ v_{k-2} ^ v_{k-2} >> 2
     * (0x80000000, 0xc0000000, 0x60000000, 0x90000000, 0xe8000000, ...). */
    v[0] = 0x80000000u, v[1] = 0xc0000000u;
    for (int k = 2; k < 32; k++)
        v[k] = v[k - 1] ^ v[k - 2] ^ (v[k - 2] >> 2);
    sobol_table(v, sobol2_rev_table);
}

static inline uint32_t sobol2_rev(uint32_t i)
{
    return sobol2_rev_table[0][i & 0xffu] ^ sobol2_rev_table[1][(i >> 8) & 0xffu] ^
           sobol2_rev_table[2][(i >> 16) & 0xffu] ^ sobol2_rev_table[3][i >> 24];
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
static inline uint32_t seed_c(uint32_t h)
{
    return h * 0x7feb352du + 0x846ca68bu;
}

static uint64_t halton_pixel_index(const lf_sampler *s, int px, int py, uint32_t index);
static void halton_pair(lf_sample_stream *st, uint32_t dim, uint32_t *a, uint32_t *b);
static void pmj_pair(lf_sample_stream *st, uint32_t dim, uint32_t h, uint32_t *a, uint32_t *b);

uint32_t lf_sample_pixel_hash(const lf_sampler *s, int px, int py)
{
    if (s->kind == LF_SAMPLER_SOBOL)
        pthread_once(&sobol_once, sobol_tables_init);
    return lf_hash_combine(lf_hash_combine(s->seed, (uint32_t)px), (uint32_t)py);
}

void lf_sample_start_pixel(lf_sample_stream *st, const lf_sampler *s, uint32_t pixel_hash, int px, int py,
                           uint32_t index)
{
    st->s = s;
    st->pixel_hash = pixel_hash;
    st->index = index;
    st->rindex = reverse_bits(index);
    st->dim = 0;
    st->px = px;
    st->py = py;
    st->halton_index = s->kind == LF_SAMPLER_HALTON ? halton_pixel_index(s, px, py, index) : 0;
}

/* A random permutation of [0, n) chosen by h, element i: a bijection on
 * the next power of two (lk_permute keeps every low bit range bijective)
 * walked until it lands below n. */
static uint32_t permute_index(uint32_t i, uint32_t n, uint32_t h)
{
    uint32_t mask = 1;
    while (mask < n)
        mask <<= 1;
    mask -= 1;
    uint32_t k = i;
    do {
        k = (lk_permute(k, h) ^ (h >> 7)) & mask;
    } while (k >= n);
    return k;
}

void lf_sample_start(lf_sample_stream *st, const lf_sampler *s, int px, int py, uint32_t index)
{
    lf_sample_start_pixel(st, s, lf_sample_pixel_hash(s, px, py), px, py, index);
}

static inline __attribute__((always_inline)) void sample_pair(lf_sample_stream *st, uint32_t *a, uint32_t *b)
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
    case LF_SAMPLER_HALTON:
        halton_pair(st, pair * 2, a, b);
        return;
    case LF_SAMPLER_PMJ02BN:
        pmj_pair(st, pair * 2, h, a, b);
        return;
    case LF_SAMPLER_INDEPENDENT:
    default:
        *a = lf_hash_combine(h, st->index * 2u);
        *b = lf_hash_combine(h, st->index * 2u + 1u);
        return;
    }
}

/* The first value of the next pair, the second not computed where that
 * saves work: the Sobol sampler's 1D value needs only the first Sobol
 * dimension of the pair (the same bits sample_pair's a would be). */
static uint32_t sample_first(lf_sample_stream *st)
{
    if (st->s->kind == LF_SAMPLER_SOBOL) {
        uint32_t h = lf_hash_combine(st->pixel_hash, st->dim >> 1);
        st->dim += 2;
        uint32_t i = reverse_bits(lk_permute(st->rindex, h));
        return reverse_bits(lk_permute(i, seed_a(h)));
    }
    uint32_t a, b;
    sample_pair(st, &a, &b);
    return a;
}

float lf_sample_1d(lf_sample_stream *st)
{
    if (st->s->kind == LF_SAMPLER_PMJ02BN && st->dim > 0) {
        /* pbrt-v4 PMJ02BNSampler::Get1D: a shuffled stratum, jittered */
        uint32_t h = lf_hash_combine(st->pixel_hash, st->dim >> 1);
        st->dim += 2;
        uint32_t n = (uint32_t)st->s->spp;
        uint32_t k = permute_index(st->index % n, n, h);
        float f = (float)((k + (lf_hash_u32(h ^ 0x51ed270bu) >> 8) * 0x1p-24) / n);
        return f < 0x1.fffffep-1f ? f : 0x1.fffffep-1f;
    }
    return to_unit(sample_first(st));
}

double lf_sample_1d_d(lf_sample_stream *st) { return (sample_first(st) + 0.5) * 0x1p-32; }

void lf_sample_3d_d(lf_sample_stream *st, double *u0, double *u1, double *u2)
{
    uint32_t a, b, c;
    if (st->s->kind == LF_SAMPLER_SOBOL) {
        /* the first three Sobol dimensions of one shuffled index, each
         * Owen-scrambled on its own: jointly a (1, m, 3)-net over any 2^m
         * consecutive samples of the pixel, while (u0, u1) stays a
         * (0, m, 2)-net and u2 a (0, m, 1)-net as separate draws would be
         * (a fourth dimension would make the lens pair (2, 3) a (1, m, 2)-net,
         * a loss for it: not done); the second pair slot is unused */
        uint32_t h = lf_hash_combine(st->pixel_hash, st->dim >> 1);
        st->dim += 4;
        uint32_t i = reverse_bits(lk_permute(st->rindex, h));
        a = reverse_bits(lk_permute(i, seed_a(h)));
        b = reverse_bits(lk_permute(sobol1_rev(i), seed_b(h)));
        c = reverse_bits(lk_permute(sobol2_rev(i), seed_c(h)));
    } else {
        sample_pair(st, &a, &b);
        c = sample_first(st);
    }
    *u0 = (a + 0.5) * 0x1p-32;
    *u1 = (b + 0.5) * 0x1p-32;
    *u2 = (c + 0.5) * 0x1p-32;
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

/* ------------------------------------------------------------------ Halton */

enum { N_PRIMES = 1000, HALTON_MAX_RES = 128 };
static int primes[N_PRIMES];
static pthread_once_t primes_once = PTHREAD_ONCE_INIT;

static void primes_init(void)
{
    int n = 0;
    for (int c = 2; n < N_PRIMES; c++) {
        int prime = 1;
        for (int k = 0; k < n && primes[k] * primes[k] <= c; k++)
            if (c % primes[k] == 0) {
                prime = 0;
                break;
            }
        if (prime)
            primes[n++] = c;
    }
}

/* x^-1 mod n (gcd(x, n) = 1), by the extended Euclidean algorithm. */
static uint64_t mult_inverse(int64_t x, int64_t n)
{
    int64_t r0 = n, r1 = x % n, t0 = 0, t1 = 1;
    while (r1) {
        int64_t q = r0 / r1, r = r0 - q * r1, t = t0 - q * t1;
        r0 = r1, r1 = r, t0 = t1, t1 = t;
    }
    return (uint64_t)(t0 < 0 ? t0 + n : t0);
}

/* The index whose first nd base-b digits, reversed, are the digits of v. */
static uint64_t inverse_radical_inverse(uint64_t v, int b, int nd)
{
    uint64_t idx = 0;
    for (int i = 0; i < nd; i++) {
        uint64_t digit = v % (uint64_t)b;
        v /= (uint64_t)b;
        idx = idx * (uint64_t)b + digit;
    }
    return idx;
}

/* pbrt-v4's HaltonSampler: the image-wide index of this pixel's sample.
 * The first two dimensions are radical inverses in bases 2 and 3, scaled
 * so that 2^e0 x 3^e1 of them cover the (tiled) pixel grid: a pixel's
 * samples are the indices whose leading digits name it, found by the
 * Chinese remainder theorem. */
static uint64_t halton_pixel_index(const lf_sampler *s, int px, int py, uint32_t index)
{
    uint64_t stride = (uint64_t)s->halton_scale[0] * (uint64_t)s->halton_scale[1];
    uint64_t hi = 0;
    if (stride > 1) {
        int pm[2] = {((px % HALTON_MAX_RES) + HALTON_MAX_RES) % HALTON_MAX_RES,
                     ((py % HALTON_MAX_RES) + HALTON_MAX_RES) % HALTON_MAX_RES};
        for (int i = 0; i < 2; i++) {
            uint64_t off = inverse_radical_inverse((uint64_t)pm[i], i == 0 ? 2 : 3, s->halton_exp[i]);
            hi += off * (stride / (uint64_t)s->halton_scale[i]) % stride * s->halton_mult_inv[i] % stride;
        }
        hi %= stride;
    }
    return hi + (uint64_t)index * stride;
}

static double radical_inverse(int b, uint64_t a)
{
    double inv = 1.0 / b, f = inv, r = 0;
    while (a) {
        uint64_t next = a / (uint64_t)b;
        r += (double)(a - next * (uint64_t)b) * f;
        f *= inv;
        a = next;
    }
    return r;
}

/* Radical inverse with every digit mapped through a permutation of
 * [0, b): per digit position ("permutedigits") or per prefix of the
 * permuted digits so far ("owen": nested scrambling).  Digits beyond the
 * index's own are zeros that the permutation moves too, down to 2^-32. */
static double scrambled_radical_inverse(int b, uint64_t a, uint32_t seed, int owen)
{
    double inv = 1.0 / b, f = inv, r = 0;
    uint64_t prefix = 0;
    for (int k = 0; (double)(b - 1) * f >= 0x1p-33 && k < 64; k++) {
        uint64_t next = a / (uint64_t)b;
        uint32_t digit = (uint32_t)(a - next * (uint64_t)b);
        uint32_t h = owen ? lf_hash_combine(seed, (uint32_t)(prefix ^ (prefix >> 32)) + (uint32_t)k * 0x9e3779b9u)
                          : lf_hash_combine(seed, (uint32_t)k);
        digit = permute_index(digit, (uint32_t)b, h);
        prefix = prefix * (uint64_t)b + digit;
        r += digit * f;
        f *= inv;
        a = next;
    }
    return r;
}

static uint32_t unit_to_u32(double x)
{
    double v = x * 4294967296.0;
    return v >= 4294967295.0 ? 0xffffffffu : v <= 0 ? 0u : (uint32_t)v;
}

static double halton_dim(const lf_sampler *s, uint64_t hi, uint32_t d)
{
    if (d >= N_PRIMES)
        d = 2 + (d - 2) % (N_PRIMES - 2); /* pbrt-v4 wraps to dimension 2 */
    int b = primes[d];
    if (s->randomize == LF_HALTON_NONE)
        return radical_inverse(b, hi);
    uint32_t seed = lf_hash_combine(lf_hash_u32(s->seed ^ 0x68bc21ebu), d);
    return scrambled_radical_inverse(b, hi, seed, s->randomize == LF_HALTON_OWEN);
}

static void halton_pair(lf_sample_stream *st, uint32_t dim, uint32_t *a, uint32_t *b)
{
    const lf_sampler *s = st->s;
    uint64_t hi = st->halton_index;
    if (dim == 0) {
        /* the pixel sample: the digits below the pixel's (pbrt: not scrambled) */
        *a = unit_to_u32(radical_inverse(2, hi >> s->halton_exp[0]));
        *b = unit_to_u32(radical_inverse(3, hi / (uint64_t)s->halton_scale[1]));
        return;
    }
    *a = unit_to_u32(halton_dim(s, hi, dim));
    *b = unit_to_u32(halton_dim(s, hi, dim + 1));
}

/* ----------------------------------------------------------------- pmj02bn */

/* A progressive (0,2) sequence: the first two Sobol dimensions (van der
 * Corput and the Pascal-matrix dimension, a (0,2)-sequence in base 2)
 * under nested uniform (Owen) scrambling with seeds from `seed`.  Every
 * prefix of 2^k points is a (0,k,2)-net, the defining property of
 * Christensen, Kensler and Kilpatrick's pmj02 sequences; Helmer,
 * Christensen and Kensler (2021) generate pmj02 stochastically in just
 * this way.  pbrt-v4's tables are further optimised for blue noise by best
 * candidate; these points are not. */
int lf_pmj02bn_generate(uint32_t seed, int n, float *xy)
{
    if (n < 1 || n > LF_PMJ_MAX || (n & (n - 1)))
        return -1;
    pthread_once(&sobol_once, sobol_tables_init);
    uint32_t sa = lf_hash_combine(seed, 0x6a09e667u), sb = lf_hash_combine(seed, 0xbb67ae85u);
    for (int i = 0; i < n; i++) {
        uint32_t x = reverse_bits(lk_permute((uint32_t)i, sa)); /* dim 0 = reverse(i) */
        uint32_t y = reverse_bits(lk_permute(sobol1_rev((uint32_t)i), sb));
        /* lk_permute(v, s) applied to bit-reversed v is a nested scramble
         * of v's binary digits (see sample_pair) */
        xy[2 * i] = (float)((x >> 8) * 0x1p-24);
        xy[2 * i + 1] = (float)((y >> 8) * 0x1p-24);
    }
    return 0;
}

static void pmj_pair(lf_sample_stream *st, uint32_t dim, uint32_t h, uint32_t *a, uint32_t *b)
{
    const lf_sampler *s = st->s;
    uint32_t n = (uint32_t)s->spp, i = st->index % n;
    if (dim == 0) {
        /* pbrt-v4: one sequence spread over a tile of pixels */
        int T = s->pmj_tile;
        int tx = ((st->px % T) + T) % T, ty = ((st->py % T) + T) % T;
        const float *p = s->pmj_pixel + 2 * ((size_t)(ty * T + tx) * n + i);
        *a = unit_to_u32(p[0]);
        *b = unit_to_u32(p[1]);
        return;
    }
    uint32_t k = permute_index(i, n, h);
    uint32_t set = dim / 2 < LF_PMJ_SETS ? dim / 2 : lf_hash_u32(h) % LF_PMJ_SETS;
    const float *p = s->pmj_sets + 2 * ((size_t)set * s->pmj_set_len + k);
    double x = p[0] + (lf_hash_u32(h ^ 0x2545f491u) >> 8) * 0x1p-24;
    double y = p[1] + (lf_hash_u32(h ^ 0x9e3779b9u) >> 8) * 0x1p-24;
    *a = unit_to_u32(x >= 1 ? x - 1 : x);
    *b = unit_to_u32(y >= 1 ? y - 1 : y);
}

/* -------------------------------------------------------------- preparing */

int lf_sampler_prepare(lf_sampler *s, int xres, int yres)
{
    if (s->kind == LF_SAMPLER_HALTON) {
        pthread_once(&primes_once, primes_init);
        int res[2] = {xres, yres};
        for (int i = 0; i < 2; i++) {
            int b = i == 0 ? 2 : 3, scale = 1, e = 0, lim = res[i] < HALTON_MAX_RES ? res[i] : HALTON_MAX_RES;
            while (scale < lim) {
                scale *= b;
                e++;
            }
            s->halton_scale[i] = scale;
            s->halton_exp[i] = e;
        }
        s->halton_mult_inv[0] = s->halton_scale[0] > 1 ? mult_inverse(s->halton_scale[1], s->halton_scale[0]) : 0;
        s->halton_mult_inv[1] = s->halton_scale[1] > 1 ? mult_inverse(s->halton_scale[0], s->halton_scale[1]) : 0;
        return 0;
    }
    if (s->kind != LF_SAMPLER_PMJ02BN)
        return 0;
    int n = s->spp;
    if (n < 1 || n > LF_PMJ_MAX || (n & (n - 1)) || ((31 - __builtin_clz((unsigned)n)) & 1))
        return -1; /* a power of 4 */
    lf_sampler_free(s);
    s->pmj_set_len = n;
    s->pmj_sets = malloc(sizeof(float) * 2 * (size_t)n * LF_PMJ_SETS);
    /* the pixel tile: T x T pixels share one sequence of T^2 spp <= 65536 points */
    int T = 1;
    while ((size_t)(2 * T) * (2 * T) * n <= LF_PMJ_MAX)
        T *= 2;
    size_t np = (size_t)T * T * n;
    float *tile = malloc(sizeof(float) * 2 * np);
    s->pmj_pixel = malloc(sizeof(float) * 2 * np);
    int *stored = calloc((size_t)T * T, sizeof(int));
    int rc = -1;
    if (!s->pmj_sets || !tile || !s->pmj_pixel || !stored)
        goto done;
    for (int k = 0; k < LF_PMJ_SETS; k++)
        if (lf_pmj02bn_generate(0x5eed0000u + (uint32_t)k, n, s->pmj_sets + 2 * (size_t)k * n))
            goto done;
    if (lf_pmj02bn_generate(0x5eed0000u, (int)np, tile))
        goto done;
    /* Each tile pixel receives the points that fall in it (a (0,2)-net
     * over T^2 n points puts exactly n in each of the T x T squares). */
    for (size_t i = 0; i < np; i++) {
        double x = tile[2 * i] * T, y = tile[2 * i + 1] * T;
        int cx = (int)x, cy = (int)y;
        if (cx >= T)
            cx = T - 1;
        if (cy >= T)
            cy = T - 1;
        int pix = cy * T + cx;
        if (stored[pix] >= n)
            goto done; /* cannot happen for a valid net */
        float *q = s->pmj_pixel + 2 * ((size_t)pix * n + stored[pix]++);
        q[0] = (float)(x - cx);
        q[1] = (float)(y - cy);
    }
    s->pmj_tile = T;
    rc = 0;
done:
    free(tile);
    free(stored);
    if (rc)
        lf_sampler_free(s);
    return rc;
}

void lf_sampler_free(lf_sampler *s)
{
    free(s->pmj_sets);
    free(s->pmj_pixel);
    s->pmj_sets = s->pmj_pixel = NULL;
    s->pmj_set_len = s->pmj_tile = 0;
}
