/* IEEE 754 half-precision storage for light fields: conversions, and the
 * half-float copy that refocusing can stream at half the memory traffic. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "half_internal.h"
#include "lf_lightfield.h"

uint16_t lf_lightfield_float_to_half(float f)
{
    uint32_t x;
    memcpy(&x, &f, 4);
    uint32_t sign = (x >> 16) & 0x8000u, e = (x >> 23) & 0xffu, m = x & 0x7fffffu;
    if (e == 0xff) /* Inf, NaN */
        return (uint16_t)(sign | 0x7c00u | (m ? 0x200u : 0));
    int exp = (int)e - 127 + 15;
    if (exp >= 31)
        return (uint16_t)(sign | 0x7c00u);
    if (exp <= 0) { /* subnormal half or zero */
        if (exp < -10)
            return (uint16_t)sign;
        m |= 0x800000u;
        int shift = 14 - exp;
        uint32_t h = m >> shift, rem = m & ((1u << shift) - 1), halfway = 1u << (shift - 1);
        if (rem > halfway || (rem == halfway && (h & 1)))
            h++;
        return (uint16_t)(sign | h);
    }
    uint32_t h = ((uint32_t)exp << 10) | (m >> 13), rem = m & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1)))
        h++; /* may carry into the exponent: still correct, up to Inf */
    return (uint16_t)(sign | h);
}

float lf_lightfield_half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu, x;
    if (e == 0) {
        if (!m) {
            x = sign;
        } else { /* subnormal: normalise */
            int s = 0;
            while (!(m & 0x400u))
                m <<= 1, s++;
            x = sign | ((uint32_t)(127 - 15 + 1 - s) << 23) | ((m & 0x3ffu) << 13);
        }
    } else if (e == 31) {
        x = sign | 0x7f800000u | (m << 13);
    } else {
        x = sign | ((e + 127 - 15) << 23) | (m << 13);
    }
    float f;
    memcpy(&f, &x, 4);
    return f;
}

int lf_lightfield_make_half(lf_lightfield *lf, lf_error *err)
{
    size_t n = (size_t)lf->nu * lf->nv * lf->ns * lf->nt * 3;
    if (!lf->half) {
        lf->half = malloc(n * sizeof(uint16_t));
        if (!lf->half)
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the half-float copy");
    }
    size_t overflow = 0;
    for (size_t i = 0; i < n; i++) {
        lf->half[i] = lf_lightfield_float_to_half(lf->data[i]);
        overflow += (lf->half[i] & 0x7c00u) == 0x7c00u && isfinite(lf->data[i]);
    }
    if (overflow) {
        free(lf->half);
        lf->half = NULL;
        return lf_error_set(err, LF_ERR_NUMERIC, "%zu light-field values exceed the half-float range (65504)",
                            overflow);
    }
    return LF_OK;
}
