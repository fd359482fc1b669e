/* lf_image.h - float images, their files and their comparison.
 *
 * An lf_image is a packed, row-major array of `channels` floats per pixel,
 * row 0 at the top.  Files:
 *   - EXR (OpenEXRCore): linear float (or half) RGB/RGBA/Y, with typed header
 *     attributes - lensfield writes its own as "lensfield:<key>".
 *   - PFM (pfm.c): 1 or 3 float channels, rows stored bottom-up, either
 *     byte order read (the scale's sign), little-endian written.
 *   - PNG, JPEG, TIFF, HDR, ... (OpenImageIO, behind image/oiio_adapter.cpp):
 *     8-bit outputs are tonemapped: exposure, clamp, sRGB transfer curve.
 * Writes are atomic: data goes to a temporary file beside the target, which
 * is renamed over it only when complete, so a crash never leaves a
 * half-written image.  Non-finite pixels are never written silently:
 * lf_image_write fails with LF_ERR_NUMERIC unless opts->allow_nonfinite.
 *
 *   lf_image img; lf_image_alloc(&img, 640, 480, 3, &err);
 *   lf_attrs a = {0}; lf_attrs_set_string(&a, "lensfield:camera", "perspective", &err);
 *   lf_image_write("out/demo.exr", &img, &a, NULL, &err);
 *   lf_attrs_free(&a); lf_image_free(&img);
 */
#ifndef LF_IMAGE_H
#define LF_IMAGE_H

#include <stddef.h>

#include "base/lf_error.h"
#include "base/lf_plot.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_image {
    int width, height, channels;
    float *data; /* width * height * channels floats */
} lf_image;

int lf_image_alloc(lf_image *img, int width, int height, int channels, lf_error *err); /* zero-filled */
void lf_image_free(lf_image *img);
static inline float *lf_image_px(const lf_image *img, int x, int y)
{
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
}

/* Header attributes (EXR).  Names are free-form; lensfield uses "lensfield:*". */
typedef enum lf_attr_type {
    LF_ATTR_STRING,
    LF_ATTR_INT,
    LF_ATTR_FLOAT,
    LF_ATTR_DOUBLE,
    LF_ATTR_FLOATS, /* a float vector of any length (EXR "floatvector") */
    LF_ATTR_M44D    /* 16 doubles, row-major */
} lf_attr_type;

typedef struct lf_attr {
    char *name;
    lf_attr_type type;
    char *s;         /* STRING */
    int i;           /* INT */
    double d;        /* FLOAT, DOUBLE */
    float *v;        /* FLOATS */
    int n;           /* FLOATS count */
    double m[16];    /* M44D */
} lf_attr;

typedef struct lf_attrs {
    lf_attr *items;
    size_t count, cap;
} lf_attrs;

/* Setters replace an attribute of the same name.  Return 0, or an LF_ERR_*
 * status with the message in err (may be NULL): LF_ERR_NOMEM ("out of
 * memory for attribute \"NAME\""), or LF_ERR_PARAM for a missing list,
 * name or value.  Callers that word the failure themselves (with the file
 * being written, say) pass NULL. */
int lf_attrs_set_string(lf_attrs *a, const char *name, const char *value, lf_error *err);
int lf_attrs_set_int(lf_attrs *a, const char *name, int value, lf_error *err);
int lf_attrs_set_float(lf_attrs *a, const char *name, float value, lf_error *err);
int lf_attrs_set_double(lf_attrs *a, const char *name, double value, lf_error *err);
int lf_attrs_set_floats(lf_attrs *a, const char *name, const float *v, int n, lf_error *err);
int lf_attrs_set_m44d(lf_attrs *a, const char *name, const double m[16], lf_error *err);
/* Sets a copy of attribute x (its name, type and value) in a. */
int lf_attrs_set_copy(lf_attrs *a, const lf_attr *x, lf_error *err);
const lf_attr *lf_attrs_get(const lf_attrs *a, const char *name);
void lf_attrs_free(lf_attrs *a);

/* Tone curves for 8-bit outputs, applied per channel after the exposure
 * and before the sRGB transfer curve (docs/design.md "Output images"). */
typedef enum lf_tonemap {
    LF_TONEMAP_CLAMP = 0, /* min(x, 1): linear up to white */
    LF_TONEMAP_FILMIC,    /* Hable's filmic curve (Uncharted 2), white point 11.2, exposure bias 2 */
    LF_TONEMAP_ACES       /* Narkowicz's fit of the ACES reference rendering + sRGB display transform */
} lf_tonemap;

typedef struct lf_write_opts {
    int half;            /* EXR: store HALF instead of FLOAT */
    float exposure;      /* 8-bit outputs: multiply by 2^exposure before tonemapping */
    int allow_nonfinite; /* write NaN/Inf instead of failing */
    lf_tonemap tonemap;  /* 8-bit outputs: the tone curve (default clamp) */
    const char *mono_channel; /* EXR, 1-channel images: the channel's name (NULL: "Y") */
} lf_write_opts;

/* The tone curve alone: linear scene value (after exposure) -> linear
 * display value in [0, 1]. */
float lf_tonemap_apply(lf_tonemap op, float x);
/* "clamp", "filmic", "aces" -> 0 and *op; -1 for another name. */
int lf_tonemap_parse(const char *name, lf_tonemap *op);
/* Write options for 8-bit pictures from a tool's --exposure EV and
 * --tonemap NAME (NULL or an unknown name: clamp); the rest default. */
lf_write_opts lf_write_opts_picture(double exposure_ev, const char *tonemap);

/* A scalar image (channel 0 of src) as a colour picture: values in [lo, hi]
 * through the viridis colour map (NaN/Inf grey), with a legend strip below
 * (the colour bar and the range's two ends written in digits), as linear
 * RGB ready for an 8-bit writer.  For depth and disparity maps. */
int lf_image_colormap(const lf_image *src, double lo, double hi, lf_image *out, lf_error *err);

/* Format from the extension (.exr, .png, .jpg, .tif, .hdr, .pfm ...).
 * opts may be NULL.  attrs may be NULL; formats without headers drop them. */
int lf_image_write(const char *path, const lf_image *img, const lf_attrs *attrs, const lf_write_opts *opts,
                   lf_error *err);
/* Reads any format OpenImageIO or OpenEXR reads; 8-bit sRGB files are
 * linearised.  attrs may be NULL.  Rejects absurd sizes (over 2^31 pixels)
 * with a clear error rather than trying to allocate. */
int lf_image_read(const char *path, lf_image *img, lf_attrs *attrs, lf_error *err);

/* The size of an image without its pixels, from the header, where the
 * format allows it cheaply (PNG: its IHDR chunk); LF_ERR_UNSUPPORTED for
 * other formats, whose callers read the image.  A 2 MB PNG can declare 25000
 * x 25000 pixels (7.5 GB as floats): describing it must not decode it. */
int lf_image_read_size(const char *path, int *width, int *height, int *channels, lf_error *err);

/* Number of NaN or Inf values. */
size_t lf_image_count_nonfinite(const lf_image *img);
/* 1 when every value is finite with magnitude <= 65504, the largest half
 * float (an EXR written with opts.half keeps every value). */
int lf_image_fits_half(const lf_image *img);

/* Linear -> 8-bit sRGB (exposure in stops, clamp, sRGB curve), for previews. */
unsigned char lf_srgb_encode(float linear);
/* The sRGB transfer curve itself (IEC 61966-2-1), linear [0, 1] -> code [0, 1]. */
double lf_srgb_from_linear(double linear);
float lf_srgb_decode(unsigned char v);

/* Comparison, over channels common to both, skipping nothing: images must
 * have equal size (else LF_ERR_PARAM).  */
int lf_image_mse(const lf_image *a, const lf_image *b, double *mse, lf_error *err);
/* PSNR in dB with peak 1.0 (+inf when identical). */
int lf_image_psnr(const lf_image *a, const lf_image *b, double *psnr_db, lf_error *err);

/* A drawing (base/lf_plot.h) in pixels, its labels drawn too (Cairo, the
 * "sans-serif" face at 12 px as the SVG asks): linear RGB on white, the
 * drawing's size, for lf_image_write (PNG). */
int lf_image_from_plot(const lf_plot *plot, lf_image *out, lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
