/* fft_internal.h - the small radix-2 FFT shared by lightfield/ sources (not public). */
#ifndef LF_LIGHTFIELD_FFT_INTERNAL_H
#define LF_LIGHTFIELD_FFT_INTERNAL_H

/* In-place FFT of n (a power of two) interleaved complex floats spaced
 * `stride` complex values apart; sign -1 forward, +1 inverse (unnormalised). */
void lf_lightfield_fft1d(float *a, int n, int stride, int sign);
/* Rows then columns of a w x h interleaved complex array (powers of two). */
void lf_lightfield_fft2d(float *a, int w, int h, int sign);

#endif
