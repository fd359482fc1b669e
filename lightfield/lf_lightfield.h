/* lf_lightfield.h - 4D light fields: layout, decode, refocus, views, synthesis.
 *
 * lightfield/ knows nothing of the renderer: it works on any raw image plus a
 * layout, read from the `lensfield:*` attributes of docs/lightfield-format.md
 * or given explicitly (tools pass flags).  Uses image/ and base/ only.
 *
 *   lf_lightfield_layout file, flags, lay; lf_lightfield lf = {0}; lf_error err = {0};
 *   lf_lightfield_layout_from_attrs(&attrs, &file);        // what the file says
 *   lf_lightfield_layout_init(&flags); ...set flags.*, flags.have |= LF_LIGHTFIELD_HAVE_...;
 *   if (lf_lightfield_layout_resolve(&file, &flags, raw.width, raw.height, &lay, &err)) fail(err.msg);
 *   lf_lightfield_decode(&raw, &lay, NULL, &lf, &err);      // or a white image to devignet
 *   lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults(); o.disparity_px = 1.5;
 *   lf_image out; lf_lightfield_refocus(&lf, &o, &out, &err);
 *   lf_lightfield_free(&lf);
 *
 * Conventions (docs/lftool.md has the long form):
 *   - Views (iu, iv): iu grows with the viewpoint's camera-space x (right),
 *     iv grows with decreasing camera-space y (down), so view (0,0) is the
 *     top-left camera seen from behind, as tile (0,0) of a camera-array raw.
 *     Centred view coordinates are u = iu - (nu-1)/2, v = iv - (nv-1)/2.
 *   - (s, t): pixel column and row in a view, row 0 at the top.
 *   - Disparity d (pixels per view step): a scene point's image moves by -d
 *     pixels in s when the viewpoint moves one view step to +u (likewise t, v).
 *     A camera array sees d = F_px * b / Z > 0; a plenoptic capture has d = 0
 *     at the focus distance, d > 0 nearer, d < 0 farther.  Refocusing at d
 *     averages L(u, v, s - d u, t - d v): points with disparity d come out sharp.
 *   - alpha (Ng 2005): d = (1 - 1/alpha) * du / p, du the lens distance between
 *     views, p the microlens pitch (metres); depth z: 1/z + 1/(alpha F) = 1/f.
 *     Ng's x'/alpha magnification is left out: outputs stay on the (s,t) grid.
 */
#ifndef LF_LIGHTFIELD_H
#define LF_LIGHTFIELD_H

#include <stddef.h>
#include <stdint.h>

#include "base/lf_error.h"
#include "image/lf_image.h"
#include "image/lf_layout_attrs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* lf_lightfield_kind, lf_lightfield_grid: image/lf_layout_attrs.h (the attributes name them). */

/* Which fields of an lf_lightfield_layout are known. */
enum {
    LF_LIGHTFIELD_HAVE_KIND = 1u << 0,
    LF_LIGHTFIELD_HAVE_CAMS = 1u << 1,        /* cams_x, cams_y */
    LF_LIGHTFIELD_HAVE_BOUNDS = 1u << 2,      /* grid_bounds */
    LF_LIGHTFIELD_HAVE_FOV = 1u << 3,         /* fov_deg */
    LF_LIGHTFIELD_HAVE_TILE = 1u << 4,        /* tile_w, tile_h */
    LF_LIGHTFIELD_HAVE_CAM_LENS = 1u << 5,    /* lens_radius, focal_distance */
    LF_LIGHTFIELD_HAVE_GRID = 1u << 6,        /* grid */
    LF_LIGHTFIELD_HAVE_PITCH = 1u << 7,       /* pitch_px */
    LF_LIGHTFIELD_HAVE_ROTATION = 1u << 8,    /* rotation_rad */
    LF_LIGHTFIELD_HAVE_OFFSET = 1u << 9,      /* offset_px */
    LF_LIGHTFIELD_HAVE_LENS_COUNT = 1u << 10, /* lens_x, lens_y */
    LF_LIGHTFIELD_HAVE_MAIN_LENS = 1u << 11,  /* main_focal_mm, main_fstop, mla_distance_mm, pitch_um */
    LF_LIGHTFIELD_HAVE_DISP_RANGE = 1u << 12, /* disp_min, disp_max */
    LF_LIGHTFIELD_HAVE_CONVERGENCE = 1u << 13 /* convergence_m */
};

typedef struct lf_lightfield_layout {
    unsigned have; /* LF_LIGHTFIELD_HAVE_* bits */
    lf_lightfield_kind kind;
    /* camera-array (CS348B Camera "lightfield") */
    int cams_x, cams_y;
    double grid_bounds[4]; /* minx maxx miny maxy on the z = 0 plane */
    double fov_deg;        /* per data camera, across the tile's shorter side */
    int tile_w, tile_h;
    double convergence_m;  /* sensors shifted so that disparity is 0 at this depth (HCI); 0: parallel */
    double lens_radius, focal_distance;
    /* plenoptic (Ng 2005) */
    lf_lightfield_grid grid;
    double pitch_px, rotation_rad, offset_px[2];
    int lens_x, lens_y;
    double pitch_um, microlens_focal_mm, main_focal_mm, main_fstop, focus_distance_m, mla_distance_mm;
    double sensor_offset_mm; /* plenoptic: sensor behind the microlens focal plane (0: plenoptic 1.0) */
    /* any kind: the scene's disparity range (px per view step) when the data says it */
    double disp_min, disp_max;
} lf_lightfield_layout;

void lf_lightfield_layout_init(lf_lightfield_layout *lay);
/* Fills what the lensfield:* attributes give; never fails on missing ones
 * (returns LF_ERR_PARSE only for an attribute of the wrong type or value). */
int lf_lightfield_layout_from_attrs(const lf_attrs *attrs, lf_lightfield_layout *lay, lf_error *err);
/* Merges the file's layout with explicit parameters (flags): a field in both
 * must agree (else LF_ERR_PARAM naming the attribute and the flag); then
 * derives what follows from the raw size (tile size, lens count) and fails
 * with LF_ERR_PARAM listing every missing attribute with its flag. */
int lf_lightfield_layout_resolve(const lf_lightfield_layout *file, const lf_lightfield_layout *flags, int raw_w, int raw_h,
                         lf_lightfield_layout *out, lf_error *err);
/* Writes the layout as lensfield:* attributes (the format decode reads). */
int lf_lightfield_layout_to_attrs(const lf_lightfield_layout *lay, lf_attrs *attrs, lf_error *err);
/* One-paragraph human description (info). */
void lf_lightfield_layout_describe(const lf_lightfield_layout *lay, char *buf, size_t n);

/* A decoded 4D light field L(u, v, s, t), RGB float. */
typedef struct lf_lightfield {
    int nu, nv; /* views */
    int ns, nt; /* view width, height */
    float *data;  /* view (iu,iv) at data + (iv*nu + iu) * ns*nt*3, rows top first */
    float *valid; /* NULL when every sample is valid, else ns*nt per view, 1 or 0 */
    size_t missing;   /* samples marked invalid */
    size_t nonfinite; /* raw values that were NaN/Inf (their samples are invalid) */
    int views_rescaled, views_dark; /* lf_lightfield_equalize: views divided by their gain field, dark views left out */
    float gain_lo, gain_hi;         /* the rescaled views' brightness gains against the centre view */
    float *view_gain; /* NULL: every view as bright as the centre; else per view its mean gain before
                       * lf_lightfield_equalize divided it out (its noise grew by 1 / gain: view synthesis weighs it by gain^2) */
    /* geometry for parameter conversions (0 when unknown) */
    double disp_v_per_u;    /* d_v / d_u for one depth (camera arrays with unequal baselines) */
    double disp_per_inv_m;  /* d = disp_at_inf + disp_per_inv_m / Z */
    double disp_at_inf;
    double disp_per_alpha;  /* d = disp_per_alpha * (1 - 1/alpha); 0: alpha unavailable */
    lf_lightfield_layout layout;
    uint16_t *half; /* optional IEEE half copy of data (lf_lightfield_make_half), same layout */
    double *view_shift; /* NULL: the nominal grid; else per view (su, sv, ox, oy), lf_lightfield_calibrate_views */
} lf_lightfield;

static inline float *lf_lightfield_view(const lf_lightfield *lf, int iu, int iv)
{
    return lf->data + ((size_t)iv * (size_t)lf->nu + (size_t)iu) * (size_t)lf->ns * (size_t)lf->nt * 3;
}

int lf_lightfield_alloc(lf_lightfield *lf, int nu, int nv, int ns, int nt, lf_error *err);

/* Photometric equalisation against the centre view (vignetted captures, e.g.
 * decoded Lytro sets): each view's gain is fitted per channel as a smooth
 * field, exp(quadratic in x, y), robustly to the log-ratios of cell means on
 * a 16 x 16 grid of the centre view's cells, each compared with the view's
 * window at the whole-pixel parallax shift that makes the ratios most alike;
 * a view whose field departs from 1 by more than 2 % on average (or 8 % at a
 * cell) is divided by it.  Cells under a tenth of the centre's brightness are marked
 * missing (lf->valid), a view dark everywhere is missing whole.  Sets
 * views_rescaled, views_dark, gain_lo/hi; adds to missing. */
int lf_lightfield_equalize(lf_lightfield *lf, lf_error *err);
/* The same on `threads` threads (<= 0: every core): views measured in
 * parallel, applied in view order (the same result). */
int lf_lightfield_equalize_threads(lf_lightfield *lf, int threads, lf_error *err);
void lf_lightfield_free(lf_lightfield *lf); /* accepts a zeroed struct */

/* Decodes a raw image (any channel count: 1 is grey, RGB(A) used as RGB).
 * white may be NULL; when given (same layout) every sample is divided by the
 * white sample, and samples where white < 5% of its maximum are
 * marked missing.  Non-finite raw values are counted and marked missing. */
/* Views per side of a plenoptic decode: the odd count 2*floor((pitch-1)/2)+1. */
int lf_lightfield_plenoptic_views(const lf_lightfield_layout *lay);
int lf_lightfield_decode(const lf_image *raw, const lf_lightfield_layout *lay, const lf_image *white, lf_lightfield *lf,
                 lf_error *err);

/* Adds (or refreshes) the half-float copy lf->half of lf->data, for
 * refocusing at half the memory traffic (values round to nearest even;
 * magnitudes above 65504 become infinite, so refocus refuses such fields). */
int lf_lightfield_make_half(lf_lightfield *lf, lf_error *err);

/* Conversions; fail with LF_ERR_PARAM when the layout lacks what they need. */
int lf_lightfield_alpha_to_disparity(const lf_lightfield *lf, double alpha, double *disp, lf_error *err);
int lf_lightfield_depth_to_disparity(const lf_lightfield *lf, double depth_m, double *disp, lf_error *err);

/* Shift-and-add refocusing with bilinear sub-pixel interpolation (clamped at
 * view borders).  Views weighted by the synthetic aperture: a disk of radius
 * aperture_radius (view units, centred; < 0: all views) intersected with the
 * view window [u0,u1]x[v0,v1] (indices, inclusive; u1 < 0: all). */
typedef struct lf_lightfield_refocus_opts {
    double disparity_px; /* along u; along v it is scaled by lf->disp_v_per_u */
    double aperture_radius;
    int u0, u1, v0, v1;
    int threads; /* <= 0: 2 */
    int use_half; /* read the half-float copy (lf_lightfield_make_half): half the memory traffic */
} lf_lightfield_refocus_opts;
lf_lightfield_refocus_opts lf_lightfield_refocus_defaults(void);
int lf_lightfield_refocus(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, lf_image *out, lf_error *err);

/* A view at centred view coordinates (u, v) inside the captured aperture,
 * blended bilinearly from the 4 nearest views after reprojecting them to the
 * plane of disparity disparity_px (0: plain blending).  At a view position it
 * returns that view exactly. */
int lf_lightfield_view_at(const lf_lightfield *lf, double u, double v, double disparity_px, lf_image *out, lf_error *err);

/* Fourier slice refocusing (Ng 2005 SIGGRAPH).  Precompute: per-view 2D FFT
 * (views zero-padded to powers of two), DFT over (u,v) zero-padded to
 * P = oversample * n (rounded up), pre-divided by the Kaiser-Bessel kernel's
 * transform; per frame: 4x4-tap Kaiser-Bessel slice, inverse 2D FFT. */
typedef struct lf_lightfield_fourier lf_lightfield_fourier;
int lf_lightfield_fourier_new(const lf_lightfield *lf, const lf_lightfield_refocus_opts *aperture, double oversample,
                      lf_lightfield_fourier **out, lf_error *err);
int lf_lightfield_fourier_refocus(const lf_lightfield_fourier *f, double disparity_px, lf_image *out, lf_error *err);
void lf_lightfield_fourier_release(lf_lightfield_fourier *f);

/* Focal stack, all-in-focus image and disparity map from a stack over
 * [d0, d1] in n steps: per pixel the slice with the largest local contrast
 * (squared Laplacian of luminance over a (2r+1)^2 window). */
int lf_lightfield_allfocus(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, double d0, double d1, int n,
                   lf_image *allfocus, lf_image *disparity, lf_error *err);

/* CS348B virtual camera (Levoy & Hanrahan 1996, Isaksen et al. 2000).  Each
 * ray meets the camera plane z = 0 (4 nearest data cameras, bilinear weights)
 * and the virtual focal plane (the thin lens's plane of focus, at
 * focal_distance along the view axis); each data camera is looked up where it
 * sees that focal point, bilinearly inside its own tile (never a neighbour's). */
typedef struct lf_lightfield_synth_opts {
    int width, height;       /* outputdim */
    double fov_deg;          /* outputfov (shorter side, pbrt) */
    double pos[3];           /* camerapos, camera space of the grid */
    double rot_deg[3];       /* camerarot: R = Rz * Ry * Rx (x applied first) */
    double lens_radius;      /* 0: pinhole */
    double focal_distance;   /* <= 0: infinity (pinhole only) */
    int spp;                 /* 1: pixel and lens centre; else stratified jitter (a pinhole whose
                              * pixels are no larger than the data pixels samples pixel centres) */
    uint32_t seed;
    int threads;             /* <= 0: 2 */
    /* Per-pixel geometry (NULL: the focal plane, as above): the centre
     * view's disparity map (ns x nt, 1 channel; lf_lightfield_depth).  Each ray is
     * intersected with that surface (marched in disparity steps of 0.05
     * px/view from near to far) and the data cameras are looked up where
     * they see the hit point instead of the focal point. */
    const lf_image *disparity;
} lf_lightfield_synth_opts;
lf_lightfield_synth_opts lf_lightfield_synth_defaults(void);
/* coverage may be NULL; else a 1-channel image: fraction of samples whose ray
 * stayed inside the captured aperture and the data cameras' fields of view.
 * uncovered (may be NULL) gets the count of pixels with no covered sample. */
int lf_lightfield_synth(const lf_lightfield *lf, const lf_lightfield_synth_opts *o, lf_image *out, lf_image *coverage,
                size_t *uncovered, lf_error *err);

/* Folders of views (docs/lightfield-format.md, "Folders of views"):
 *   - HCI benchmark layout: input_CamNNN.<ext>, NNN = row * num_cams_x + column
 *     from the top-left view, with parameters.cfg (optional when the view
 *     count is a square or the flags give the grid);
 *   - views named <prefix>_RR_CC<suffix>.<ext> (row, column, 0- or 1-based;
 *     the last pair of all-digit '_' fields), e.g. decoded Lytro captures
 *     scene_05_07.png and the Stanford archive's out_05_07_-3.1_11.2.png.
 * Views are PNG (8/16-bit, sRGB decoded to linear), EXR, TIFF or PFM.
 *
 *   lf_lightfield_folder f; lf_lightfield lf;
 *   if (lf_lightfield_is_folder(path)) {
 *       lf_lightfield_folder_scan(path, &f, &err);            // names and parameters.cfg only
 *       lf_lightfield_folder_load(&f, &flags, &lf, &err);      // reads every view
 *       lf_lightfield_folder_free(&f);
 *   }
 */
typedef enum lf_lightfield_folder_kind { LF_LIGHTFIELD_FOLDER_HCI = 1, LF_LIGHTFIELD_FOLDER_ROWCOL } lf_lightfield_folder_kind;
typedef struct lf_lightfield_folder {
    lf_lightfield_folder_kind kind;
    char *dir;
    int nu, nv;      /* views per row, per column */
    int base;        /* ROWCOL: index of the first row and column (0 or 1) */
    char **files;    /* nu * nv paths; view (iu, iv) at iv * nu + iu */
    lf_lightfield_layout layout; /* what the folder says: camera array, cams, tile size when cfg gives it, ... */
    int cfg_w, cfg_h;    /* image_resolution_x/y_px of parameters.cfg (0: not given) */
    double focal_mm, sensor_mm; /* parameters.cfg focal_length_mm, sensor_size_mm (longer side); 0: not given */
    char *gt_disparity;  /* gt_disp_lowres.pfm beside the views, or NULL */
    char pattern[256];   /* how views are named, for messages: "input_Cam%03d.png", "scene_RR_CC.png" */
} lf_lightfield_folder;

int lf_lightfield_is_folder(const char *path);
/* Lists the views and reads parameters.cfg.  Fails (LF_ERR_PARSE / LF_ERR_IO)
 * naming the missing view files, or the cfg line that is wrong. */
int lf_lightfield_folder_scan(const char *dir, lf_lightfield_folder *f, lf_error *err);
/* Reads every view into *lf (same layout as lf_lightfield_decode gives), merges the
 * folder's layout with flags as lf_lightfield_layout_resolve does, sets the
 * geometry.  Views must all be readable and of one size; errors name the
 * file(s).  Non-finite values become missing samples (lf->nonfinite). */
int lf_lightfield_folder_load(const lf_lightfield_folder *f, const lf_lightfield_layout *flags, lf_lightfield *lf, lf_error *err);
/* The same on `threads` threads (<= 0: every core; lf_parallel_for): the
 * views are decoded in parallel, the result and the messages are the same. */
int lf_lightfield_folder_load_threads(const lf_lightfield_folder *f, const lf_lightfield_layout *flags, int threads,
                                      lf_lightfield *lf, lf_error *err);
void lf_lightfield_folder_free(lf_lightfield_folder *f);
/* Writes the HCI layout: input_CamNNN.png (8-bit sRGB), parameters.cfg
 * (camera arrays: focal length, sensor size, baseline; disparity range when
 * known) and, when disparity is given (the centre view's, 1 channel),
 * gt_disp_lowres.pfm.  Camera arrays only need cams; the cfg gets what the
 * layout knows. */
int lf_lightfield_write_hci(const char *dir, const lf_lightfield *lf, const lf_image *disparity, lf_error *err);

/* The parallax between the centre view and one neighbour
 * (lf_lightfield_grid_parallax). */
typedef struct lf_lightfield_pair_parallax {
    int axis;           /* the axis the parallax runs along: 0 x, 1 y, -1 cannot tell (too little texture or parallax) */
    double disparity;   /* median over the voting blocks, px per view step (the centre's point is at x - d there) */
    double positive;    /* share of the voting blocks with d > 0 */
    int blocks, textured, votes_x, votes_y;
} lf_lightfield_pair_parallax;
typedef struct lf_lightfield_parallax {
    lf_lightfield_pair_parallax row; /* centre view against its right neighbour (iu + 1) */
    lf_lightfield_pair_parallax col; /* against its lower neighbour (iv + 1) */
    int both, same_sign;             /* blocks where both pairs voted; of them, with one sign of d */
} lf_lightfield_parallax;

/* Measures the direction of parallax between the centre view and its right
 * and lower neighbours (lightfield/gridcheck.c: 16 x 16 blocks, a 1-D shift
 * search along x and along y on the gradient of log luminance, so exposure
 * does not matter).  In a grid read as it was captured, row neighbours move
 * along x and column neighbours along y, with one sign of d per block. */
int lf_lightfield_grid_parallax(const lf_lightfield *lf, lf_lightfield_parallax *p, lf_error *err);
/* Reorders the views: transposed (view (iu, iv) becomes (iv, iu)), then
 * mirrored along the rows (flip_x) and the columns (flip_y). */
int lf_lightfield_grid_reorder(lf_lightfield *lf, int transpose, int flip_x, int flip_y, lf_error *err);

/* Fills the geometry fields of lf (disp_per_inv_m, ...) from lf->layout's
 * values: lf_lightfield_decode and lf_lightfield_folder_load call it. */
void lf_lightfield_set_geometry(lf_lightfield *lf, const lf_lightfield_layout *lay);

/* Microlens-grid estimate from a white plenoptic image: pitch, rotation,
 * offset, square or hex (peak detection + lattice fit).  Sets kind, grid,
 * pitch, rotation, offset and lens count in *lay. */
int lf_lightfield_calibrate(const lf_image *white, lf_lightfield_layout *lay, lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
