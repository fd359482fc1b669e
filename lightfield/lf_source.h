/* lf_source.h - opening a light field the way the tools take one: a raw
 * image (decoded with its lensfield:* layout, or explicit layout flags) or
 * a folder of views; its ground-truth disparity; per-pixel maps of the
 * views' size; writing views, mosaics and focal stacks.  Errors name the
 * file; nothing is printed (warnings come back as counts or flags).
 *
 *   lf_lightfield_source src; lf_error err = {0};
 *   lf_lightfield_open_opts oo = {.flags = &flags};
 *   if (lf_lightfield_open("raw.exr", &oo, &src, &err)) ... err.msg ...;
 *   ... src.lf ...
 *   lf_lightfield_close(&src);
 */
#ifndef LF_SOURCE_H
#define LF_SOURCE_H

#include "image/lf_raw.h"
#include "lf_lightfield.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_lightfield_source {
    const char *path;     /* as given to lf_lightfield_open (not copied) */
    lf_image raw;         /* the raw image (empty for a folder) */
    lf_attrs attrs;       /* its attributes */
    lf_lightfield_layout layout;  /* the resolved layout */
    lf_lightfield lf;     /* the decoded light field (empty when layout_only) */
    lf_lightfield_folder folder;  /* a folder of views when folder.dir != NULL */
    size_t raw_nonfinite; /* the raw's NaN/Inf values */
    int parallax_measured;         /* folders: the grid was checked against its parallax */
    lf_lightfield_parallax parallax; /* what the check measured (after any correction) */
    lf_warnings warnings;          /* notes for the tool to print: a corrected grid */
} lf_lightfield_source;

typedef struct lf_lightfield_open_opts {
    const lf_lightfield_layout *flags; /* explicit layout (may be NULL) */
    const char *white;         /* raws: divide by this white image (NULL: none) */
    int allow_nonfinite;       /* NaN/Inf samples become missing instead of failing */
    int layout_only;           /* raws: resolve the layout, do not decode (nor check values) */
    int no_equalize;           /* folders: keep the views' brightness as read (no lf_lightfield_equalize) */
    const char *grid;          /* folders: NULL or "check" (the grid checked against its parallax, swapped or
                                * mirrored rows/columns corrected with a note), "off" (as named), "transpose",
                                * "flip-x", "flip-y" (that correction, unchecked) */
    int threads;               /* folders: views decoded on this many threads (<= 0: every core) */
} lf_lightfield_open_opts;

/* Reads a raw or a folder of views (every view is read, even with
 * layout_only, so a missing view is reported at once).  Fails with
 * LF_ERR_NUMERIC on non-finite values unless allow_nonfinite; on failure
 * *src is left empty.  src->lf.nonfinite counts the excluded samples. */
int lf_lightfield_open(const char *path, const lf_lightfield_open_opts *o, lf_lightfield_source *src, lf_error *err);

/* Raw sensor mosaics (Film "raw" EXR, DNG): lf_lightfield_open develops them
 * (black level, white balance, colour matrix) with demosaicing kept inside
 * each microlens image, and, when the raw gives no layout and a white image
 * is given, calibrates the microlens grid from the white image alone
 * (lf_lightfield_calibrate on its grey version), as LFToolbox does with
 * Lytro white images.  The pieces: */
/* Per pixel, the index (j * lens_x + i) of the microlens whose cell holds
 * its centre, or -1 outside the grid; malloc'ed. */
int lf_lightfield_lens_labels(const lf_lightfield_layout *l, int w, int h, int **labels, lf_error *err);
/* A mosaic as grey: each site minus black, divided by the mean of its CFA colour. */
int lf_lightfield_mosaic_grey(const lf_image *raw, const lf_raw_info *ri, lf_image *grey, lf_error *err);
/* The microlens grid from a white image alone: lf_lightfield_calibrate,
 * then again on the white image with each microlens image flattened (its
 * outline kept, its shading removed; lightfield/mosaic.c). */
int lf_lightfield_calibrate_white(const lf_image *white, lf_lightfield_layout *lay, lf_error *err);
/* A mosaic developed to RGB, demosaicing within microlens cells. */
int lf_lightfield_develop_mosaic(const lf_image *raw, const lf_raw_info *ri, const lf_lightfield_layout *l,
                                 lf_image *rgb, lf_error *err);
void lf_lightfield_close(lf_lightfield_source *src); /* accepts a zeroed struct */

/* What `lftool info` says about a source: its kind, size and layout. */
void lf_lightfield_source_describe(const lf_lightfield_source *src, char *buf, size_t n);

/* The centre view's ground-truth disparity (docs/lightfield-format.md,
 * "Disparity AOV"): a raw's lensfield:disparity_file (relative to the raw's
 * folder), decoded with the raw's layout, or a folder's gt_disp_lowres.pfm.
 * *gt stays empty when there is none; *no_centre is set (and *gt left empty)
 * when the view grid has no centre view (even count). */
int lf_lightfield_source_gt_disparity(const lf_lightfield_source *src, lf_image *gt, int *no_centre, lf_error *err);

/* A disparity range the source states: a folder's disp_min/disp_max or a
 * raw's lensfield:disparity_range (lfrender --aov disparity), else the raw's
 * lensfield:disp_min/max.  Returns a name for the source of the range ("the
 * folder's disp_min/disp_max", "lensfield:disparity_range",
 * "lensfield:disp_min/max"), or
 * NULL (and 0 0) when it states none. */
const char *lf_lightfield_source_disparity_range(const lf_lightfield_source *src, double *d0, double *d1);

/* A 1-channel map of the views' size: the first channel of the image at
 * path, which must be ns x nt with finite values. */
int lf_lightfield_read_map(const char *path, const lf_lightfield *lf, lf_image *map, lf_error *err);

/* The folder dir (created when missing) gets every view as
 * view_ROW_COL.EXT and mosaic.EXT, the views tiled as the cameras sit. */
int lf_lightfield_write_views(const lf_lightfield *lf, const char *dir, const char *ext, const lf_write_opts *wo,
                      lf_error *err);

/* The folder dir (created when missing) gets a focal stack: n >= 2 slices
 * stack_NNN.EXT refocused at disparities d0 .. d1 (o->disparity_px is
 * ignored), each with lensfield:refocus_disparity_px. */
int lf_lightfield_write_stack(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, double d0, double d1, int n,
                      const char *dir, const char *ext, const lf_write_opts *wo, lf_error *err);

/* Writes a refocused image with lensfield:refocus_disparity_px, the
 * disparity (px per view step) it is focused at. */
int lf_lightfield_write_refocused(const char *path, const lf_image *img, double disparity_px, const lf_write_opts *wo,
                          lf_error *err);

/* Writes the centre view's disparity map disp (1 channel, searched over
 * [d0, d1]): EXR/PFM get the values, with lensfield:disparity_search_range
 * and lensfield:disparity_convention; PNG/JPEG a picture of them, the
 * colour map over [d0, d1] with its legend (lf_image_colormap). */
int lf_lightfield_write_disparity(const char *path, const lf_image *disp, double d0, double d1, const lf_write_opts *wo,
                          lf_error *err);

/* Ng 2005's range of exact refocusing of a plenoptic capture
 * (docs/lightfield.md, "Refocusable range"): |d| <= 1 px/view.  Returns 1
 * and describes the range in buf ("Ng 2005: |disparity| <= 1 px/view,
 * alpha A0 .. A1, depths Z0 m .. Z1") when disparity d is outside it; 0 when
 * it is inside or the light field has no alpha (not plenoptic). */
int lf_lightfield_refocus_outside(const lf_lightfield *lf, double d, char *buf, size_t n);

/* Which camera fields of a CS348B synth camera the caller set; the others
 * come from the light field (lf_lightfield_synth_prepare). */
enum {
    LF_LIGHTFIELD_SYNTH_SET_FOV = 1u << 0,   /* else the data cameras' fov */
    LF_LIGHTFIELD_SYNTH_SET_SIZE = 1u << 1,  /* else the views' size */
    LF_LIGHTFIELD_SYNTH_SET_POS = 1u << 2,   /* else the grid's centre */
    LF_LIGHTFIELD_SYNTH_SET_FOCAL = 1u << 3  /* else the data cameras' focal distance when the layout has one */
};
/* Checks that lf is a camera array with the geometry synth needs (the
 * message names each missing attribute and its flag) and fills the fields
 * of *s not in `set`. */
int lf_lightfield_synth_prepare(const lf_lightfield *lf, unsigned set, lf_lightfield_synth_opts *s, lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
