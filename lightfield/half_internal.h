/* half_internal.h - half-float conversions shared by lightfield/ sources (not public). */
#ifndef LF_LIGHTFIELD_HALF_INTERNAL_H
#define LF_LIGHTFIELD_HALF_INTERNAL_H

#include <stdint.h>

uint16_t lf_lightfield_float_to_half(float f); /* round to nearest even */
float lf_lightfield_half_to_float(uint16_t h);

#endif
