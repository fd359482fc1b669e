/* lens_poly.h - a polynomial model of a compound lens's ray transfer, fitted
 * to exact traces at camera creation (private to camera/ and its tests).
 *
 * Follows the idea of Hanika & Dachsbacher, "Efficient Monte Carlo rendering
 * with realistic lenses" (Eurographics 2014) and Schrade, Hanika &
 * Dachsbacher, "Sparse high-degree polynomials for wide-angle lenses" (EGSR
 * 2016): replace the surface-by-surface trace by polynomials that map a ray
 * leaving the film to the ray leaving the front element, and decide
 * vignetting by testing fitted positions against the clear apertures.
 *
 *   lf_lens_poly poly;
 *   lf_lens_poly_opts o = lf_lens_poly_opts_default();
 *   o.pixel_mm = film_width_mm / width;                  // to report errors in pixels
 *   o.focus_distance_mm = 6130;
 *   lf_error err = {0};
 *   if (lf_lens_poly_fit(&lens, &pupil, &o, &poly, &err)) ...   // fit failed: err.msg
 *   if (poly.fit.p99_px > 0.1) ...                        // too poor: trace instead
 *   double w = lf_lens_poly_sample_ray(&lens, &poly, &pupil, 1, fx, fy, u, v, NULL, NULL, &ray);
 *   lf_lens_poly_free(&poly);
 *
 * What is fitted (lens space, mm; the film point rotated onto (r, 0), which
 * rotational symmetry allows, so the inputs are three, not four):
 *   inputs  r / film_radius, and the point (x, y) / rear_disk_radius where the
 *           film ray crosses the rear-vertex plane (equivalent to the film
 *           ray's direction: a linear change of variables);
 *   outputs the ray leaving the lens: its point (x, y) on the plane z = z_out
 *           just in front of the front element and its unit direction (dx, dy);
 *           (x^2 + y^2) / aperture^2 on the stop and on every surface that
 *           clips rays (degree 5 at most: they only place aperture edges);
 *           the ray's point (x, y) on the stop, for shaped apertures.
 * Mirror symmetry in y and the point symmetry (r, x, y) -> -(r, x, y) make
 * x-like outputs odd in total degree and even in y, y-like outputs odd in
 * total degree and odd in y, radii squared even in both: only those monomials
 * are fitted (least squares by Householder QR over a few thousand traced
 * samples of the exit-pupil bound; the degree is the lowest of 3, 5, 7, 9
 * whose validation error meets the target).
 *
 * Dispersion (a wavelength input) is not modelled: the camera traces instead.
 */
#ifndef LF_LENS_POLY_H
#define LF_LENS_POLY_H

#include <stddef.h>
#include <stdint.h>

#include "base/lf_error.h"
#include "lens.h"

#define LF_LENS_POLY_MAX_DEGREE 9
#define LF_LENS_POLY_MAX_CLIP 32

typedef struct lf_lens_poly_opts {
    double pixel_mm;          /* film pixel pitch, for errors in pixels (> 0) */
    double focus_distance_mm; /* plane (from the film) where errors are measured */
    double target_px;         /* stop raising the degree once p99 error is below this (default 0.05) */
    int max_degree;           /* 3..LF_LENS_POLY_MAX_DEGREE (default 9) */
    int fit_samples;          /* traced samples for the fit (default 8000) */
    int check_samples;        /* held-out samples for the error report (default 3000) */
    uint32_t seed;
} lf_lens_poly_opts;

lf_lens_poly_opts lf_lens_poly_opts_default(void);

/* Agreement with exact tracing on the same (film point, pupil sample) inputs. */
typedef struct lf_lens_poly_error {
    long samples;            /* pupil samples drawn */
    long both_passed;        /* samples that both models let through */
    double mismatch_fraction; /* samples one model lets through and the other blocks, / samples */
    double rms_px, p99_px, max_px; /* over both_passed: distance between the two rays' points on
                                    * the focus plane, divided by |magnification| and the pixel pitch */
    double mean_weight_traced, mean_weight_poly; /* over all samples (0 for blocked) */
    double weight_se;        /* standard error of the mean of (poly - traced) weights */
} lf_lens_poly_error;

typedef struct lf_lens_poly_fn {
    int n;          /* terms: the monomials of the output's parity class, in order */
    double *coef;
} lf_lens_poly_fn;

enum { LF_LENS_POLY_CLASS_X, LF_LENS_POLY_CLASS_Y, LF_LENS_POLY_CLASS_RADIAL, LF_LENS_POLY_CLASSES };

enum { LF_LENS_POLY_OUT_X, LF_LENS_POLY_OUT_Y, LF_LENS_POLY_OUT_DX, LF_LENS_POLY_OUT_DY, LF_LENS_POLY_STOP_X,
       LF_LENS_POLY_STOP_Y, LF_LENS_POLY_FIXED };

typedef struct lf_lens_poly {
    int degree;
    int n_mono[LF_LENS_POLY_CLASSES];          /* monomials per parity class */
    unsigned char (*exps[LF_LENS_POLY_CLASSES])[3]; /* their exponents of (r, x, y) */
    int max_degree[LF_LENS_POLY_CLASSES];
    int dense[LF_LENS_POLY_CLASSES];           /* no term dropped: monomials made by nested loops */
    lf_lens_poly_fn fn[LF_LENS_POLY_FIXED];
    int has_stop;
    double stop_radius_mm;
    int n_clip;
    int clip_surface[LF_LENS_POLY_MAX_CLIP];
    lf_lens_poly_fn clip[LF_LENS_POLY_MAX_CLIP]; /* (x^2 + y^2) / aperture^2 */
    double film_radius_mm, rear_disk_radius_mm, film_distance_mm, z_out_mm;
    double magnification;          /* |film size / focus-plane size| near the axis */
    lf_lens_poly_error fit;        /* held-out check at the chosen degree */
    double setup_seconds;          /* CPU time of the fit */
    long traces;
} lf_lens_poly;

/* Fits the lens as focused (lens->film_distance_mm) for film points up to
 * pupil->film_radius_mm, sampling the exit-pupil bound.  Returns 0, or
 * LF_ERR_NUMERIC (no light, singular fit) or LF_ERR_NOMEM with the message
 * in err. */
int lf_lens_poly_fit(const lf_lens *lens, const lf_lens_pupil *pupil, const lf_lens_poly_opts *opts,
                     lf_lens_poly *poly, lf_error *err);
void lf_lens_poly_free(lf_lens_poly *poly);

/* The polynomial's ray for the film point (fx, fy) aimed at the rear-plane
 * point (rx, ry): 1 and *out (lens space, d unit length) if it gets through,
 * 0 if an aperture blocks it.  stop_xy (optional) receives the point on the
 * stop in units of the stop radius, for shaped apertures. */
int lf_lens_poly_eval(const lf_lens_poly *poly, double fx, double fy, double rx, double ry, lf_lens_ray *out,
                      double stop_xy[2]);

/* One camera ray, as lf_lens_sample_ray but through the polynomial: the
 * same pupil sample for the same (u, v), the same weight
 * T cos^4(theta) / (pdf Z^2), 0 when blocked.  stop_shape may be NULL. */
double lf_lens_poly_sample_ray(const lf_lens *lens, const lf_lens_poly *poly, const lf_lens_pupil *pupil,
                               int use_bounds, double fx, double fy, double u, double v, lf_lens_stop_shape stop_shape,
                               const void *stop_ctx, lf_lens_ray *out);

/* Compares the polynomial with exact tracing over n film points on the film
 * disk and pupil samples (both drawn from seed), as lf_lens_poly_fit does for
 * its report. */
void lf_lens_poly_measure(const lf_lens *lens, const lf_lens_poly *poly, const lf_lens_pupil *pupil,
                          double focus_distance_mm, double pixel_mm, int n, uint32_t seed, lf_lens_poly_error *e);

#endif
