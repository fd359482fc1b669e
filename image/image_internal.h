/* image_internal.h - shared between the files of image/ only; not public.
 *
 * image.c owns the public entry points (format dispatch, atomic commit,
 * non-finite checks, tonemapping); exr.c and oiio_adapter.cpp only move
 * pixels between an lf_image and a file whose name they are given.
 */
#ifndef LF_IMAGE_INTERNAL_H
#define LF_IMAGE_INTERNAL_H

#include "lf_image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Limits on images we allocate, whether asked by a caller or declared by a
 * file header: a corrupt header must fail here, not in malloc. */
#define LF_IMAGE_MAX_PIXELS ((unsigned long long)1 << 31)
#define LF_IMAGE_MAX_BYTES ((unsigned long long)8 << 30)

/* 0 if width x height x channels floats is within the limits above, else
 * sets `code` naming `what` (a path, or "image") and returns it. */
int lf_image_check_size(long long width, long long height, long long channels, const char *what, int code,
                        lf_error *err);

/* 8-bit PNG (1-4 channels, sRGB-encoded pixels, row 0 at the top) through
 * libpng, into `file`; `name` is the path shown in messages (image/png.c). */
int lf_png_write(const char *file, const char *name, int width, int height, int channels,
                 const unsigned char *pixels, lf_error *err);

/* EXR via OpenEXRCore.  `file` is the file actually opened or created (for
 * writes, the temporary file); `name` is the path shown in messages. */
int lf_exr_write(const char *file, const char *name, const lf_image *img, const lf_attrs *attrs, int half,
                 const char *mono_name /* 1-channel images: the channel's name, NULL: Y */,
                 lf_error *err);
int lf_exr_read(const char *file, const char *name, lf_image *img, lf_attrs *attrs, lf_error *err);

/* PFM (pfm.c): 1 or 3 float channels, rows bottom-up in the file, either
 * byte order on read (the scale's sign), little-endian on write. */
int lf_pfm_write(const char *file, const char *name, const lf_image *img, lf_error *err);
int lf_pfm_read(const char *file, const char *name, lf_image *img, lf_error *err);

/* 1 if the first bytes of a file are the EXR magic number. */
int lf_exr_is_exr_magic(const unsigned char *bytes, size_t n);

#ifdef __cplusplus
}
#endif
#endif
