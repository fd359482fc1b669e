/* film.h - exact pixel accumulators (private to render/).
 *
 * Every sample's weighted radiance is rounded to a multiple of 2^-32 and
 * summed as a 128-bit integer.  Integer addition is associative, so sums of
 * sample ranges computed on different machines add up to exactly the sum of
 * an unsplit render, and a pixel value (sum / weight) is bit-identical
 * however the render was split or resumed.  Resolution 2.3e-10 per sample,
 * range +-2^63 per pixel: far beyond any image's needs.
 *
 * In files, each 128-bit accumulator is stored as its low 96 bits (two's
 * complement) in four float channels of 24 bits each (exact in float).
 */
#ifndef LF_FILM_H
#define LF_FILM_H

#include <math.h>
#include <stdint.h>

typedef __int128 lf_acc_t;

typedef struct lf_pixel_acc {
    lf_acc_t v[4]; /* R, G, B, weight */
} lf_pixel_acc;

#define LF_ACC_SCALE 4294967296.0 /* 2^32 */
#define LF_ACC_LIMBS 4
#define LF_ACC_CHANNELS (4 * LF_ACC_LIMBS)

static inline lf_acc_t lf_acc_quantize(double v)
{
    /* per-sample magnitude is bounded (|v| < 2^30) so llrint cannot overflow */
    if (!(v > -1073741824.0))
        v = -1073741824.0;
    if (!(v < 1073741824.0))
        v = 1073741824.0;
    return (lf_acc_t)llrint(v * LF_ACC_SCALE);
}

static inline float lf_acc_value(const lf_pixel_acc *a, int c)
{
    return a->v[3] != 0 ? (float)((double)a->v[c] / (double)a->v[3]) : 0.f;
}

static inline void lf_acc_to_limbs(lf_acc_t v, float *out)
{
    unsigned __int128 u = (unsigned __int128)v;
    for (int i = 0; i < LF_ACC_LIMBS; i++)
        out[i] = (float)(uint32_t)((u >> (24 * i)) & 0xffffffu);
}

static inline lf_acc_t lf_acc_from_limbs(const float *in)
{
    unsigned __int128 u = 0;
    for (int i = 0; i < LF_ACC_LIMBS; i++) {
        float f = in[i];
        uint32_t limb = (f >= 0 && f < 16777216.f) ? (uint32_t)f : 0;
        u |= (unsigned __int128)limb << (24 * i);
    }
    /* sign-extend from bit 95 */
    if (u & ((unsigned __int128)1 << 95))
        u |= ~(((unsigned __int128)1 << 96) - 1);
    return (lf_acc_t)u;
}

#endif
