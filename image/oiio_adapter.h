/* oiio_adapter.h - the C face of OpenImageIO, private to image/.
 *
 * OpenImageIO is C++; this adapter keeps its exceptions and types out of
 * the C code.  It only moves pixels: tonemapping, sRGB conversion, atomic
 * renames and non-finite checks are done in image.c, so every format gets
 * the same behaviour.  No C++ exception escapes these functions.
 */
#ifndef LF_OIIO_ADAPTER_H
#define LF_OIIO_ADAPTER_H

#include "lf_image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lf_oiio_pixel_type {
    LF_OIIO_UINT8,
    LF_OIIO_FLOAT
} lf_oiio_pixel_type;

/* Writes interleaved pixels, row 0 at the top, to `file`; the format comes
 * from its extension.  `name` is the path shown in messages. */
int lf_oiio_write(const char *file, const char *name, int width, int height, int channels, lf_oiio_pixel_type type,
                  const void *pixels, lf_error *err);

typedef struct lf_oiio_read_info {
    int srgb_encoded;  /* integer pixels in the sRGB transfer curve: linearise */
    int alpha_channel; /* -1 if none; alpha is never linearised */
} lf_oiio_read_info;

/* Reads subimage 0, mip level 0 as float, integer formats scaled to [0,1].
 * Rejects absurd declared sizes before allocating. */
int lf_oiio_read(const char *file, const char *name, lf_image *img, lf_oiio_read_info *info, lf_error *err);

/* ---- the module boundary ----
 * OpenImageIO brings about 260 shared libraries whose symbol resolution
 * cost lfrender 0.3-0.6 s at every start, for images most runs never read
 * or write (EXR goes through OpenEXR, PNG through libpng).  So the adapter
 * is a separate shared object, liblf_oiio.so (oiio_adapter.cpp), which
 * image/oiio_loader.c dlopen()s the first time lf_oiio_write or
 * lf_oiio_read is called.  The module exports one function,
 * lf_oiio_module_init, taking the host's image helpers (so the module
 * links nothing of lensfield's but base/error.c) and returning its entry
 * points. */
#define LF_OIIO_MODULE_ABI 1
typedef struct lf_oiio_host {
    int abi; /* LF_OIIO_MODULE_ABI */
    int (*check_size)(long long width, long long height, long long channels, const char *what, int code,
                      lf_error *err);
    int (*alloc)(lf_image *img, int width, int height, int channels, lf_error *err);
    void (*free_image)(lf_image *img);
} lf_oiio_host;
typedef struct lf_oiio_module {
    int abi;
    int (*write)(const char *file, const char *name, int width, int height, int channels, lf_oiio_pixel_type type,
                 const void *pixels, lf_error *err);
    int (*read)(const char *file, const char *name, lf_image *img, lf_oiio_read_info *info, lf_error *err);
} lf_oiio_module;
typedef const lf_oiio_module *(*lf_oiio_module_init_fn)(const lf_oiio_host *host);

#ifdef __cplusplus
}
#endif
#endif
