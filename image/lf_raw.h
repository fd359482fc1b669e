/* lf_raw.h - raw sensor images: colour filter arrays, raw files, develop.
 *
 * A raw image is an lf_image of one channel of digital numbers (DN, floats
 * that are integers) behind a colour filter array, with the metadata a raw
 * developer needs (lf_raw_info).  Files:
 *   - EXR: one channel named "raw", attributes lensfield:cfa,
 *     lensfield:blacklevel, lensfield:whitelevel, lensfield:color_matrix
 *     (DNG ColorMatrix1, XYZ -> camera), lensfield:as_shot_neutral.
 *   - DNG (image/dng.c, our own minimal TIFF writer): 16-bit CFA mosaic,
 *     CFARepeatPatternDim, CFAPattern, BlackLevel, WhiteLevel,
 *     ColorMatrix1, AsShotNeutral, DNGVersion 1.4 - what LibRaw and
 *     darktable need.
 *
 *   lf_raw_info ri; lf_image raw;
 *   lf_raw_read("shot.exr", &raw, &ri, &err);
 *   lf_image rgb; lf_raw_develop(&raw, &ri, NULL, &rgb, &err);   // linear sRGB
 */
#ifndef LF_RAW_H
#define LF_RAW_H

#include "base/lf_error.h"
#include "image/lf_image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The 2x2 Bayer layouts, named by their top-left 2x2 block read row by row. */
typedef enum lf_cfa {
    LF_CFA_NONE = 0, /* monochrome: every site sees the same filter */
    LF_CFA_RGGB,
    LF_CFA_BGGR,
    LF_CFA_GRBG,
    LF_CFA_GBRG
} lf_cfa;

/* "rggb", "bggr", "grbg", "gbrg", "none" -> 0 and *out; -1 otherwise. */
int lf_cfa_parse(const char *name, lf_cfa *out);
const char *lf_cfa_name(lf_cfa cfa);
/* The colour (0 red, 1 green, 2 blue) of site (x, y); 1 for LF_CFA_NONE. */
static inline int lf_cfa_color(lf_cfa cfa, int x, int y)
{
    static const unsigned char pat[5][4] = {{1, 1, 1, 1}, {0, 1, 1, 2}, {2, 1, 1, 0}, {1, 0, 2, 1}, {1, 2, 0, 1}};
    return pat[cfa][((y & 1) << 1) | (x & 1)];
}

/* The layout seen from site (dx, dy) of cfa: a crop's own pattern. */
static inline lf_cfa lf_cfa_shift(lf_cfa cfa, int dx, int dy)
{
    static const lf_cfa by_origin[4][5] = {
        {LF_CFA_NONE, LF_CFA_RGGB, LF_CFA_BGGR, LF_CFA_GRBG, LF_CFA_GBRG},  /* even, even */
        {LF_CFA_NONE, LF_CFA_GRBG, LF_CFA_GBRG, LF_CFA_RGGB, LF_CFA_BGGR},  /* odd x */
        {LF_CFA_NONE, LF_CFA_GBRG, LF_CFA_GRBG, LF_CFA_BGGR, LF_CFA_RGGB},  /* odd y */
        {LF_CFA_NONE, LF_CFA_BGGR, LF_CFA_RGGB, LF_CFA_GBRG, LF_CFA_GRBG}}; /* odd x and y */
    return by_origin[((dy & 1) << 1) | (dx & 1)][cfa];
}

typedef struct lf_raw_info {
    lf_cfa cfa;
    double black_level, white_level; /* DN */
    double color_matrix[9];          /* XYZ (D65) -> camera, row-major (DNG ColorMatrix1) */
    double as_shot_neutral[3];       /* camera response to white, largest 1 (DNG AsShotNeutral) */
    double dn_per_unit;              /* DN per unit of the film's white, after white balance; 0: unknown */
    double iso, exposure_s;          /* EXIF ISOSpeedRatings and ExposureTime in the DNG; 0: not written */
} lf_raw_info;

/* Raw attributes <-> lf_raw_info.  lf_raw_info_from_attrs: LF_ERR_PARAM when
 * lensfield:cfa, lensfield:blacklevel or lensfield:whitelevel is missing;
 * the colour matrix defaults to sRGB's, the neutral to (1,1,1). */
int lf_raw_info_to_attrs(const lf_raw_info *ri, lf_attrs *a, lf_error *err);
int lf_raw_info_from_attrs(const lf_attrs *a, lf_raw_info *ri, lf_error *err);

/* Writes a raw (1 channel of DN) as .exr (channel "raw", 32-bit float) or
 * .dng (16-bit), atomically.  The DN must be integers in [0, 65535]. */
int lf_raw_write(const char *path, const lf_image *raw, const lf_raw_info *ri, const lf_attrs *attrs,
                 lf_error *err);
/* The DNG writer alone (image/dng.c). */
int lf_dng_write(const char *path, const lf_image *raw, const lf_raw_info *ri, lf_error *err);
/* Reads a raw EXR (one channel and lensfield:cfa ...) or a DNG written by
 * lf_dng_write. attrs may be NULL. */
int lf_raw_read(const char *path, lf_image *raw, lf_raw_info *ri, lf_attrs *attrs, lf_error *err);

/* Demosaicing: Malvar, He & Cutler, "High-quality linear interpolation for
 * demosaicing of Bayer-patterned color images", ICASSP 2004 (the 5x5
 * gradient-corrected bilinear filters).  in: one channel, any values;
 * out: 3 channels.  mask (may be NULL): per site a region label (>= 0) or
 * -1 (no data); a site only takes neighbours with its own label, so two
 * microlens images are never mixed (filters renormalised to the kept taps,
 * falling back to the bilinear filter's kept taps). */
int lf_demosaic_mhc(const lf_image *in, lf_cfa cfa, const int *mask, lf_image *out, lf_error *err);

typedef struct lf_develop_opts {
    int no_white_balance; /* keep the camera's white */
    int film_units;       /* scale by dn_per_unit (the renderer's film values) instead of white - black */
    const int *mask;      /* demosaic within regions (lf_demosaic_mhc), NULL: none */
} lf_develop_opts;
/* Black level, normalisation ((DN - black) / (white - black): the white
 * level develops to 1; or / dn_per_unit with film_units),
 * demosaic (Malvar-He-Cutler), white balance (divide by AsShotNeutral),
 * colour matrix (camera -> XYZ -> linear sRGB).  opts may be NULL. */
int lf_raw_develop(const lf_image *raw, const lf_raw_info *ri, const lf_develop_opts *opts, lf_image *out,
                   lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
