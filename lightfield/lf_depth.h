/* lf_depth.h - disparity from a 4D light field and depth-based view synthesis.
 *
 *   lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();   // range from the data
 *   o.d0 = -1.7, o.d1 = 0.7;                        // or a known range
 *   lf_image disp, conf; lf_error err = {0};
 *   if (lf_lightfield_depth(&lf, &o, &disp, &conf, &err)) fail(err.msg);
 *
 * Disparity d of the reference view (iu, iv) = ((nu-1)/2, (nv-1)/2) (integer
 * division: the centre view of an odd grid) in pixels per view step, as in
 * lf_lightfield.h: I_ref(x, y) = I_(iu,iv)(x - d (iu - iu_ref),
 * y - d r (iv - iv_ref)), r = lf->disp_v_per_u.  The method (docs/depth.md):
 *   0. noisy views (the reference's noise 2 % of its level or more) are
 *      smoothed by a Gaussian of 0.7 px first (prefilter);
 *   1. cost volume over disparity labels (views looked up by Keys cubic
 *      convolution): per view a truncated absolute
 *      colour difference to the reference pixel (correspondence) and the
 *      difference between the views' mean and the reference pixel
 *      (defocus cue); for occlusions the cost of a label is the smallest over
 *      the 8 half apertures (views on one side of a line through the
 *      reference, 45 degree steps) and the full aperture (Wang et al. 2015);
 *   2. edge-aware aggregation: every cost slice filtered by a guided filter
 *      guided by the reference view (He et al. 2010; Hosni et al. 2013),
 *      then semi-global aggregation along 4 paths (Hirschmueller 2008),
 *      its jump penalty lowered at colour edges;
 *   3. winner-take-all on the semi-global sum, sub-label refinement by a
 *      parabola through the filtered costs at the minimum and its neighbours;
 *   4. confidence from the filtered cost curve, and a confidence- and
 *      colour-weighted median filter guided by the reference view;
 *   4b. thin structures the aggregation erased (a wire, a wedge's tip: a
 *      pixel or two wide) come back where the pixel's own cost curve is
 *      decisive and a neighbour carries the same disparity;
 *   5. a Gauss-Newton step on the views' photo-consistency (robust weights,
 *      same-surface window) refines the disparity continuously, away from
 *      depth edges.
 * No learned parts.  Runs on o.threads threads (bands of rows, cost slices). */
#ifndef LF_DEPTH_H
#define LF_DEPTH_H

#include "lf_lightfield.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_lightfield_depth_opts {
    double d0, d1;       /* disparity search range (px per view); d0 >= d1: estimate from the data */
    double step;         /* label spacing (px per view); <= 0: auto (about 0.05 px shift at the widest view) */
    int radius;          /* guided-filter radius (px); <= 0: auto (shorter side / 128, at least 2) */
    double eps;          /* guided-filter regulariser (colour guide in [0,1]); <= 0: 1e-3 */
    int occlusion;       /* 0: full aperture only; 1: best of 8 half apertures too; 2 (default): and of
                          * the 4 lines through the reference */
    int half_gate;       /* occlusion 2: a half aperture competes only where its cost contrast is the
                          * largest of the 12 subsets' (stripes, repetitive texture); 0 default (on), < 0 off */
    double defocus_weight; /* weight of the defocus cue against correspondence; < 0: default (docs/depth.md) */
    int median_radius;   /* weighted-median radius; 0: off; < 0: 3 */
    int refine;          /* Gauss-Newton refinement steps after the labels: 0 default (1), < 0 off */
    int interp;          /* views' sub-pixel lookup in the cost volume: 0 (default) Keys cubic, 1 bilinear */
    int noise_aware;     /* 1: views carry sensor noise (a dim or low-sample capture): each view's difference
                          * scaled so that every label's noise costs the same (docs/depth.md, "Noisy views");
                          * 0 (default): only on views the prefilter smoothed (with the smoothed noise's
                          * model), off on others, as for clean renders, where it costs precision; < 0 off */
    int thin;            /* thin-structure recovery after the median: 0 default (on), < 0 off */
    double thin_ratio;   /* its decisiveness: the pixel's own cost minimum below this times the cost at
                          * the aggregated disparity; <= 0: 0.2 */
    int plain;           /* > 0: plain regions (curves flat within the views' noise) take the far end of
                          * the evidence of their colour around them (a textured object before a plain
                          * wall); 0 (default): off, the benchmark's held-out half did not confirm it
                          * (docs/depth.md, "Plain regions") */
    double prefilter;    /* Gaussian pre-smoothing of the views before matching, sigma in px: 0 default
                          * (auto: 0.7 where the views' noise is 2 % of their level or more, docs/depth.md,
                          * "Pre-smoothing noisy views"), < 0 off, > 0 that sigma */
    int wide_window;     /* a second, wider guided filter blended in where the first leaves a pixel unsure:
                          * 0 default (on for views the prefilter smoothed, 4 times the radius), < 0 off,
                          * > 0 on with that radius (px) */
    int sgm;             /* semi-global aggregation after the guided filter: 0 default (on), < 0 off */
    double sgm_p1, sgm_p2, sgm_edge; /* its penalties and edge scale; <= 0: defaults (docs/depth.md) */
    int threads;         /* <= 0: 2 */
    /* Called now and then from the calling thread with the work done of
     * `total` (done == total once, at the end); NULL: none.  The library
     * never prints: a tool draws the bar (base/lf_progress.h). */
    void (*progress)(void *ctx, long done, long total);
    void *progress_ctx;
} lf_lightfield_depth_opts;
lf_lightfield_depth_opts lf_lightfield_depth_defaults(void);

/* The views' noise as lf_lightfield_depth's prefilter judges it: Immerkaer's
 * estimate on the reference's sRGB-encoded grey over its flatter half,
 * over its mean level (0.02 or more: the views are pre-smoothed by
 * default); -1 when it cannot be measured. */
double lf_lightfield_depth_noise_ratio(const lf_lightfield *lf, lf_error *err);
#define LF_DEPTH_PREFILTER_NOISE 0.02 /* the ratio from which the default pre-smooths */
/* The Gaussian sigma (px) lf_lightfield_depth smooths the views by under
 * opts o (0: none): o->prefilter when > 0, none when < 0, and by default
 * 0.7 where the noise ratio above is LF_DEPTH_PREFILTER_NOISE or more
 * (views with missing samples: none).  *noise_ratio (may be NULL): the
 * ratio measured, -1 when not measured.  A tool passes the sigma back in
 * o->prefilter (-1 for none) to run and report the same choice. */
int lf_lightfield_depth_prefilter(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, double *sigma,
                                  double *noise_ratio, lf_error *err);

/* Disparity map (1 channel) and, when confidence is non-NULL, a confidence
 * map in [0, 1] (1: a single sharp cost minimum).  Needs at least 2 views. */
int lf_lightfield_depth(const lf_lightfield *lf, const lf_lightfield_depth_opts *o, lf_image *disparity, lf_image *confidence,
                lf_error *err);

/* The disparity range the scene occupies, estimated by a coarse sweep at
 * quarter resolution (first over -8 .. 8 px per view, or less where the
 * views are small), kept to the confident pixels' 1st..99th percentile and
 * padded by 5% and one coarse step.  Widened where the data goes beyond:
 * when the views allow more than 8 px per view (shifts up to a quarter of
 * the view at the outermost view), a sweep over that whole range at the
 * same label count finds the percentiles beyond the first sweep's ends; an
 * end the data reaches (the 1st or 99th percentile on the end label) is
 * doubled; the sweep is re-run over the widened range.  *d0 < *d1 on
 * success. */
int lf_lightfield_depth_range(const lf_lightfield *lf, int threads, double *d0, double *d1, lf_error *err);

/* What the range estimate did, for the tool to say. */
typedef struct lf_lightfield_depth_range_info {
    double first_d0, first_d1;   /* the first sweep's estimate (px per view) */
    double search_d0, search_d1; /* the last sweep's search range */
    int widened;                 /* 1: the data reached an end of the first sweep, which was widened */
    /* the check at full resolution (fine texture the reduced views lose):
     * samples swept, how many were confirmed by their neighbours, and
     * whether their winners widened the range */
    int full_samples, full_confirmed, full_widened;
    double full_lo, full_hi; /* the confirmed winners' 1st..99th percentile */
} lf_lightfield_depth_range_info;

/* lf_lightfield_depth_range, reporting into *info (NULL: as above). */
int lf_lightfield_depth_range_report(const lf_lightfield *lf, int threads, double *d0, double *d1,
                                     lf_lightfield_depth_range_info *info, lf_error *err);

/* A view at centred view coordinates (u, v) inside the captured aperture
 * with per-pixel geometry: a disparity map of the reference view (given, or
 * estimated with lf_lightfield_depth) is forward-warped to (u, v) with a z-buffer
 * (nearer disparities win).  Every pixel of the views within 3 view steps
 * that sees the point (its own warped depth agrees, no nearer surface
 * within a pixel) lands at a sub-pixel offset from the target pixel; a
 * Gaussian-weighted quadratic fit to those samples (multi-view
 * scattered-data reconstruction) gives the pixel.  blend = 1 instead
 * blends bicubic lookups of the views within 2 steps weighted by angular
 * distance and resampling phase.  Where confidence is low or no view sees
 * the point the plane at plane_disparity is used.  At a view position it
 * returns that view exactly. */
typedef struct lf_lightfield_view_opts {
    const lf_image *disparity;  /* NULL: estimated (lf_lightfield_depth with depth) */
    const lf_image *confidence; /* NULL with a given disparity: all 1 */
    lf_lightfield_depth_opts depth;
    double plane_disparity;     /* fallback plane */
    double min_confidence;      /* below it the plane takes over gradually; < 0: 0.05 */
    double radius;              /* source views: tent of this radius in view steps, at most 4;
                                   <= 0: 3 (blend: 2; 1: the 4 nearest) */
    int blend;                  /* 0: scattered-data fit; 1: bicubic blend of lookups */
    double kernel;              /* fit: Gaussian sigma in px; <= 0: 0.35 */
    double phase_floor;         /* blend: resampling-phase weight 1/(fx(1-fx)+fy(1-fy)+floor); < 0: 0.05; 0: off */
    int threads;
} lf_lightfield_view_opts;
lf_lightfield_view_opts lf_lightfield_view_defaults(void);
int lf_lightfield_view_depth(const lf_lightfield *lf, double u, double v, const lf_lightfield_view_opts *o, lf_image *out,
                     lf_error *err);

/* Self-calibration of the views' effective positions (real captures: a
 * decoded Lytro image, a hand-held or gantry array) from a disparity map of
 * the reference view (and its confidence, may be NULL):
 *   I_ref(x, y) = I_k(x - d su_k + ox_k, y - d sv_k + oy_k)
 * per view k: (su, sv) its baseline in view steps (nominally iu - iu_ref,
 * (iv - iv_ref) r), (ox, oy) a constant pixel offset.  Fitted robustly to
 * the measured shifts of textured tiles of near-constant disparity
 * (docs/depth.md); a view with fewer than 8 usable tiles keeps its nominal
 * position.  Stores the result in lf->view_shift, which lf_lightfield_depth and
 * lf_lightfield_view_depth then use.  report (may be NULL): 6 doubles per view
 * (su, sv, ox, oy, tiles used, rms residual px; NaN offsets when not fitted). */
int lf_lightfield_calibrate_views(lf_lightfield *lf, const lf_image *disparity, const lf_image *confidence, int threads,
                          double *report, lf_error *err);
/* (su, sv, ox, oy) of the viewpoint at fractional view indices (fu, fv):
 * nominal without calibration, else interpolated between the views. */
void lf_lightfield_view_shift(const lf_lightfield *lf, double fu, double fv, double s[4]);

#ifdef __cplusplus
}
#endif
#endif
