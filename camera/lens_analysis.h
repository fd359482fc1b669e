/* lens_analysis.h - what a lens prescription does as a whole: first-order
 * data for a sensor and a focus distance, traced field of view, spot
 * diagrams, distortion, and a cross-section drawing (lflens is a thin CLI
 * over this).  Units: millimetres, lens space as in lens.h (film at z = 0,
 * light travelling +z).
 *
 *   lf_lens_report r; lf_error err = {0};
 *   if (lf_lens_report_compute(&lens, 36, 24, INFINITY, &r, &err)) ... err.msg ...
 *   lf_lens_spot s;                     // film at lens.film_distance_mm (set by the report)
 *   lf_lens_spot_diagram(&lens, 10 * M_PI / 180, 61, &s, &err); ... s.rms_mm ...; lf_lens_spot_free(&s);
 *   lf_plot plot; lf_lens_plot_build(&lens, &r, &plot, &err);
 *   char *svg = lf_plot_svg(&plot);     // or lf_image_from_plot() (image/: pixels, with text)
 *   lf_plot_free(&plot);
 */
#ifndef LF_LENS_ANALYSIS_H
#define LF_LENS_ANALYSIS_H

#include "base/lf_error.h"
#include "base/lf_plot.h"
#include "lens.h"

typedef struct lf_lens_report {
    lf_lens_paraxial px;
    double sensor_w_mm, sensor_h_mm, diagonal_mm;
    double focus_m;            /* from the film; INFINITY for infinity */
    double film_thick_mm;      /* film distance of the thick-lens focus (set on the lens) */
    double film_search_mm;     /* exact best-focus search; NAN if it failed */
    double closest_focus_m;    /* unit magnification, thick-lens model */
    double working_fnumber;    /* at the focus distance */
    double fov_paraxial_deg[3]; /* horizontal, vertical, diagonal: 2 atan(half / efl) */
    double fov_traced_deg[3];   /* the same from traced central rays (within the image circle) */
    double image_circle_radius_mm;
} lf_lens_report;

/* Analyses the lens for a sensor (mm) focused at focus_m (INFINITY allowed)
 * and leaves lens->film_distance_mm at the thick-lens focus.  Fails (with a
 * message naming the lens) for an afocal lens, an impossible focus
 * distance, or a lens that admits no light. */
int lf_lens_report_compute(lf_lens *lens, double sensor_w_mm, double sensor_h_mm, double focus_m, lf_lens_report *r,
                           lf_error *err);

/* Called for each ray of a beam that gets through: its start, the hit
 * points (n of them) and the ray leaving the rear element. */
typedef void (*lf_lens_beam_fn)(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n,
                                const lf_lens_ray *out);

/* Parallel rays at field angle theta (radians, meridional plane y-z)
 * through a grid of na x nb starting points: a in [a0, a1] along x, b in
 * [b0, b1] across the beam in the meridional plane.  Returns how many pass
 * (-1 when memory runs out). */
int lf_lens_collimated_beam(const lf_lens *lens, double theta, double a0, double a1, int na, double b0, double b1,
                            int nb, lf_lens_beam_fn fn, void *ctx);
/* The extent of the beam at theta that gets through: a in [ext[0], ext[1]],
 * b in [ext[2], ext[3]] (fine scans, one grid step of margin).  0, or -1
 * when nothing passes. */
int lf_lens_beam_extent(const lf_lens *lens, double theta, double ext[4]);

typedef struct lf_lens_spot {
    double field_rad;
    int n;          /* rays that reached the film */
    double *x, *y;  /* film positions relative to the centroid, mm */
    double cx, cy;  /* centroid on the film, mm */
    double rms_mm;  /* RMS distance from the centroid */
} lf_lens_spot;

/* Spot diagram of a collimated beam at field angle theta on the film at
 * lens->film_distance_mm: a grid x grid sampling of the passing beam
 * (uniform in the entrance beam's cross-section).  A field that admits no
 * light gives n = 0 (not an error). */
int lf_lens_spot_diagram(const lf_lens *lens, double theta, int grid, lf_lens_spot *spot, lf_error *err);
void lf_lens_spot_free(lf_lens_spot *spot);

/* Distortion of the image of infinity against f tan(theta), at n film radii
 * evenly spaced up to image_circle_mm (film at the back focal distance):
 * theta_deg[k], percent[k] = 100 (r / (efl tan theta) - 1).  Returns the
 * number of points written (radii whose chief ray, through the centre of
 * the stop, does not get through or passes 89 degrees are skipped). */
int lf_lens_distortion_curve(const lf_lens *lens, const lf_lens_paraxial *px, double image_circle_mm, int n,
                             double *theta_deg, double *percent);

/* ---- drawings: a list of vector primitives (base/lf_plot.h) ---- */

/* The cross-section with traced ray fans (on axis, 0.7 and full field),
 * spot diagrams at four field angles and the distortion curve. */
int lf_lens_plot_build(const lf_lens *lens, const lf_lens_report *r, lf_plot *plot, lf_error *err);

#endif
