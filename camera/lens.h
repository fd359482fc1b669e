/* lens.h - real compound lenses: prescriptions, paraxial analysis, exact ray
 * tracing, focusing and exit-pupil bounds (private to camera/ and tools/).
 *
 * Follows Kolb, Mitchell & Hanrahan, "A Realistic Camera Model for Computer
 * Graphics" (SIGGRAPH 1995) and pbrt-v4's RealisticCamera.
 *
 *   lf_lens lens;
 *   lf_error err = {0};
 *   if (lf_lens_load("scenes/lenses/dgauss.50mm.dat", &lens, &err)) ... err.msg ...
 *   lf_lens_paraxial px; lf_lens_paraxial_analyse(&lens, &px);   // px.efl_mm ...
 *   lf_lens_set_stop_diameter(&lens, 10.0, &warnings);          // lf_warnings: a clamp
 *   lf_lens_focus_thick(&lens, 1000.0, &lens.film_distance_mm, &err);
 *   lf_lens_pupil pupil; lf_lens_pupil_build(&lens, 43.3, 0, &pupil);
 *   double w = lf_lens_sample_ray(&lens, &pupil, 1, fx, fy, u, v, NULL, &ray);
 *   lf_lens_sample_rays(&lens, &pupil, 1, n, fxs, fys, us, vs, NULL, NULL, NULL, rays, ws); // n at once
 *   lf_lens_free(&lens);
 *
 * Units: millimetres throughout.  LENS SPACE is pbrt's: the optical axis is
 * z, the film is the plane z = 0, the lens lies at negative z (the rear
 * vertex at z = -film_distance_mm, the front vertex further out), so light
 * from the scene travels +z.  pbrt's camera space is lens space with z
 * flipped (camera z points into the scene); the camera does that flip.
 *
 * Axial positions in lf_lens_paraxial are measured along the direction of
 * light (from the scene toward the film), from the vertex named in the field.
 *
 * Prescription (.dat, pbrt's format plus an optional Abbe column): one
 * surface per line, front (scene side) first:
 *     radius  thickness  ior  aperture_diameter  [abbe]
 * radius 0 is the aperture stop; ior is n_d of the medium AFTER the surface
 * (toward the film), 0 or 1 meaning air; thickness is the distance to the next
 * surface (the last one's is the design's back focal distance: focusing
 * replaces it); '#' starts a comment.
 */
#ifndef LF_LENS_H
#define LF_LENS_H

#include <stddef.h>

#include "base/lf_error.h"

#define LF_LENS_LAMBDA_D 587.56 /* helium d line, nm: n_d */
#define LF_LENS_LAMBDA_F 486.13 /* hydrogen F line */
#define LF_LENS_LAMBDA_C 656.27 /* hydrogen C line */

typedef struct lf_lens_surface {
    double radius_mm;          /* signed radius of curvature; 0 = aperture stop */
    double thickness_mm;       /* to the next surface */
    double ior;                /* n_d after the surface; 1 for air (0 in the file is read as 1) */
    double aperture_radius_mm; /* half the clear diameter (the stop: as set) */
    double abbe;               /* V_d of the medium after the surface; 0 = none */
    double cauchy_a, cauchy_b; /* n(lambda) = a + b / lambda_um^2 (b = 0: no dispersion) */
    double z_mm;               /* vertex position relative to the rear vertex (<= 0) */
    int line;                  /* line in the lens file */
} lf_lens_surface;

typedef struct lf_lens {
    lf_lens_surface *s;
    int n;
    int stop;                   /* index of the radius-0 row, -1 if none */
    double stop_max_radius_mm;  /* the stop's clear radius in the file */
    double film_distance_mm;    /* rear vertex to film (pbrt: the last thickness) */
    int has_abbe;               /* some glass has an Abbe number */
    int dispersive;             /* trace with n(lambda) (set by the user of the lens) */
    char path[512];
} lf_lens;

/* Parses prescription text; `filename` is used in messages
 * ("x.dat:7: expected 4 or 5 columns ..., got 3").  0, or LF_ERR_PARSE
 * (LF_ERR_NOMEM) with the message in err. */
int lf_lens_parse(const char *text, const char *filename, lf_lens *lens, lf_error *err);
/* Reads (at most 16 MiB, gzip-aware) and parses a file; LF_ERR_IO when it
 * cannot be read. */
int lf_lens_load(const char *path, lf_lens *lens, lf_error *err);
void lf_lens_free(lf_lens *lens);
/* Sets the stop's clear diameter (pbrt "aperturediameter"), clamped to the
 * file's value with a warning in w (may be NULL).  Returns 1 if clamped, 0
 * if not. */
int lf_lens_set_stop_diameter(lf_lens *lens, double diameter_mm, lf_warnings *w);
/* Index of refraction after surface i at a wavelength (nm); lambda <= 0 or a
 * non-dispersive lens gives n_d. */
double lf_lens_ior(const lf_lens *lens, int i, double lambda_nm);
double lf_lens_total_length_mm(const lf_lens *lens); /* front vertex to rear vertex */

/* ---- paraxial (first-order) analysis: y-nu ray trace ---- */
typedef struct lf_lens_paraxial {
    double efl_mm;              /* effective focal length */
    double bfl_mm;              /* rear vertex -> rear focal point F' */
    double ffl_mm;              /* front focal point F -> front vertex (> 0: F in front of the lens) */
    double front_principal_mm;  /* H, from the front vertex */
    double rear_principal_mm;   /* H', from the rear vertex */
    double entrance_pupil_mm;   /* entrance pupil position, from the front vertex */
    double entrance_pupil_diameter_mm;
    double exit_pupil_mm;       /* exit pupil position, from the rear vertex */
    double exit_pupil_diameter_mm;
    double fnumber;             /* efl / entrance pupil diameter (object at infinity) */
    double total_length_mm;     /* front vertex -> rear vertex */
    int stop;                   /* surface used as the aperture stop */
} lf_lens_paraxial;

/* 0, or -1 if the lens has no power (afocal) or no stop can be found. */
int lf_lens_paraxial_analyse(const lf_lens *lens, lf_lens_paraxial *px);
/* Paraxial distance from the film to the object in focus for a film
 * distance (mm); INFINITY at or beyond the focal plane. */
double lf_lens_paraxial_focus_distance(const lf_lens *lens, const lf_lens_paraxial *px, double film_distance_mm);
/* Working f-number 1 / (2 |u'|) of the paraxial marginal ray from an axial
 * object at `focus_distance_mm` from the film with the lens at film_distance_mm
 * (INFINITY: parallel light). */
double lf_lens_working_fnumber(const lf_lens *lens, const lf_lens_paraxial *px, double focus_distance_mm,
                               double film_distance_mm);

/* ---- focusing (distances from the film, as pbrt's "focusdistance") ---- */
/* Closest focus of the thick-lens model: 4 f + hiatus (unit magnification). */
double lf_lens_closest_focus_mm(const lf_lens_paraxial *px);
/* pbrt-v4 FocusThickLens: film distance from the thick-lens (cardinal point)
 * model.  0, or LF_ERR_PARAM with a message if the lens cannot focus there
 * (afocal, negative focal length, closer than possible). */
int lf_lens_focus_thick(const lf_lens *lens, double focus_distance_mm, double *film_distance_mm, lf_error *err);
/* Exact search: the film distance that minimises the RMS spot radius of real
 * rays from the axial point at focus_distance_mm through the whole stop
 * (golden-section search around the thick-lens estimate). */
int lf_lens_focus_search(const lf_lens *lens, double focus_distance_mm, double *film_distance_mm, lf_error *err);

/* ---- exact ray tracing (Snell's law at spherical surfaces) ---- */
typedef struct lf_lens_ray {
    double o[3], d[3]; /* lens space, mm; d unit length */
} lf_lens_ray;

typedef enum lf_lens_status {
    LF_LENS_PASSED = 0,
    LF_LENS_MISSED,       /* missed a surface's sphere, or hit its far side */
    LF_LENS_CLIPPED,      /* outside an element's clear aperture */
    LF_LENS_STOPPED,      /* blocked by the aperture stop (or its shape) */
    LF_LENS_TIR,          /* total internal reflection */
    LF_LENS_BACKWARDS     /* would travel against the system (grazing) */
} lf_lens_status;

/* Optional aperture shape at the stop: transmission in [0,1] of the point
 * (x, y) in units of the stop radius.  NULL: a circle. */
typedef double (*lf_lens_stop_shape)(const void *ctx, double x, double y);

typedef struct lf_lens_trace_opts {
    double lambda_nm;             /* 0: n_d */
    lf_lens_stop_shape stop_shape;
    const void *stop_ctx;
    double (*path)[3];            /* optional: receives every hit point (n + 1 room) */
    int path_count;               /* out: points written to path */
    double transmission;          /* out: stop-shape transmission (1 for a circle) */
} lf_lens_trace_opts;

/* Film -> scene (ray travels -z, starting at or behind the rear element). */
lf_lens_status lf_lens_trace_from_film(const lf_lens *lens, const lf_lens_ray *in, lf_lens_ray *out,
                                       lf_lens_trace_opts *opts);
/* Scene -> film (ray travels +z, starting in front of the front element). */
lf_lens_status lf_lens_trace_from_scene(const lf_lens *lens, const lf_lens_ray *in, lf_lens_ray *out,
                                        lf_lens_trace_opts *opts);

/* ---- exit-pupil bounds on the rear-vertex plane (z = -film_distance) ----
 * Per film-radius bin, the region of the rear plane through which a film
 * point at (r, 0) sends rays that get through, bounded by horizontal strips
 * (mirror-symmetric in y; rotated to the film point's angle when sampled). */
#define LF_LENS_PUPIL_BINS 64
#define LF_LENS_PUPIL_STRIPS 16 /* per half (y >= 0) */

typedef struct lf_lens_pupil_bin {
    double y_max;                        /* half height of the bound; 0: no light */
    double xlo[LF_LENS_PUPIL_STRIPS], xhi[LF_LENS_PUPIL_STRIPS];
    double cdf[LF_LENS_PUPIL_STRIPS + 1]; /* cumulative strip areas, normalised */
    double area;                          /* both halves, mm^2 */
    double pdf;                           /* 1 / area: the sampling density, per mm^2 */
} lf_lens_pupil_bin;

typedef struct lf_lens_pupil {
    double film_radius_mm;  /* bins span [0, film_radius_mm] */
    double bins_per_mm;     /* n_bins / film_radius_mm */
    double rear_disk_radius_mm; /* disk on the rear plane holding every ray that gets through */
    double lambda_nm[3];    /* wavelengths the bounds hold for (0: n_d) */
    int n_lambda;
    int n_bins;
    lf_lens_pupil_bin bin[LF_LENS_PUPIL_BINS];
    long long traces;       /* rays traced to build it */
} lf_lens_pupil;

/* Builds the bounds for film points up to film_radius_mm (half the film
 * diagonal).  With lambda_spread the bounds hold for every wavelength in
 * [LF_LAMBDA_MIN, LF_LAMBDA_MAX] (union of n(360), n_d, n(830)).
 * Returns the number of bins with light (0: the lens admits no light). */
int lf_lens_pupil_build(const lf_lens *lens, double film_radius_mm, int lambda_spread, lf_lens_pupil *pupil);
/* Samples a point of the bound for the film point (x, y); returns the pdf
 * (1 / bound area, per mm^2) or 0 if that film point gets no light. */
double lf_lens_pupil_sample(const lf_lens_pupil *pupil, double film_x, double film_y, double u, double v,
                            double *rear_x, double *rear_y);

/* Is the rear-plane point (rx, ry) inside the bound used for film point
 * (film_x, film_y)?  (Tests check that no ray that gets through lies outside.) */
int lf_lens_pupil_contains(const lf_lens_pupil *pupil, double film_x, double film_y, double rx, double ry);

/* One camera ray: film point (lens space mm) -> ray leaving the front
 * element.  use_bounds 0: sample the whole rear disk
 * (pupil->rear_disk_radius_mm) instead of the exit-pupil bound.
 * Returns the weight T cos^4(theta) / (pdf Z^2) (Kolb et al. 1995, the
 * course notes' E = (1/Z^2) Int L cos^4 dA''; pbrt-v4), or 0 when the ray
 * does not get through (never NaN). */
double lf_lens_sample_ray(const lf_lens *lens, const lf_lens_pupil *pupil, int use_bounds, double film_x,
                          double film_y, double u, double v, lf_lens_trace_opts *opts, lf_lens_ray *out);
/* Batch form of lf_lens_sample_ray (the camera's hot path): for every i < n,
 * the same as
 *     lf_lens_trace_opts o = {0};
 *     o.lambda_nm = lambda_nm ? lambda_nm[i] : 0;
 *     o.stop_shape = stop_shape, o.stop_ctx = stop_ctx;
 *     weights[i] = lf_lens_sample_ray(lens, pupil, use_bounds, film_x[i], film_y[i], u[i], v[i], &o, &out[i]);
 * bit for bit: the same pupil sample, vignetting tests and weight; out[i] is
 * written when the ray gets through the lens (as lf_lens_sample_ray does).
 * lambda_nm and stop_shape may be NULL; the stop shape is called once per
 * ray that reaches the stop.  Rays are traced in chunks, surface by surface
 * in structure-of-arrays form (AVX2 where the CPU has it): several times
 * faster per ray than the scalar call (docs/realistic.md). */
void lf_lens_sample_rays(const lf_lens *lens, const lf_lens_pupil *pupil, int use_bounds, int n, const double *film_x,
                         const double *film_y, const double *u, const double *v, const double *lambda_nm,
                         lf_lens_stop_shape stop_shape, const void *stop_ctx, lf_lens_ray *out, double *weights);
/* Batch form of lf_lens_trace_from_film without options: passed[i] is 1
 * and out[i] is written where lf_lens_trace_from_film(lens, &in[i],
 * &out[i], NULL) returns LF_LENS_PASSED (the same bits), else 0 (out[i]
 * untouched).  Same kernels as lf_lens_sample_rays. */
void lf_lens_trace_rays_from_film(const lf_lens *lens, int n, const lf_lens_ray *in, lf_lens_ray *out,
                                  unsigned char *passed);
/* 1 if lf_lens_sample_rays runs its AVX2 kernel on this CPU.  Tests force
 * the generic (SSE2) kernel with lf_lens_batch_force_generic(1) to check
 * both (not thread-safe: call before rendering). */
int lf_lens_batch_uses_avx2(void);
void lf_lens_batch_force_generic(int on);
/* Radius of a disk on the rear-vertex plane that every ray from a film point
 * within film_radius_mm that gets through crosses (rear aperture plus the
 * lateral travel across the rear surface's sag). */
double lf_lens_rear_disk_radius(const lf_lens *lens, double film_radius_mm);

/* ---- field ---- */
/* The "central" ray of the meridional fan from the film point (r, 0): aimed at
 * the middle of the passing interval on the rear plane.  Returns 0 and the
 * field angle (radians from the axis, object side), or -1 if no light. */
int lf_lens_field_angle(const lf_lens *lens, double film_r_mm, double *theta);
/* The chief ray from the film point (r, 0): through the centre of the
 * aperture stop.  0 and its field angle (radians, object side), or -1 if it
 * does not get through (or the lens has no stop row). */
int lf_lens_chief_ray_angle(const lf_lens *lens, double film_r_mm, double *theta);
/* Largest film radius (up to r_max) that receives light: the image circle. */
double lf_lens_image_circle_radius(const lf_lens *lens, double r_max_mm);

/* Sensor table (mm): fullframe, apsc, apsh, mediumformat, fourthirds, 1inch,
 * 1/1.63in, 1/2.3in, 1/3.2in.  0, or -1 if unknown. */
int lf_lens_sensor_size(const char *name, double *width_mm, double *height_mm);
/* Comma-separated list of the names, for messages. */
const char *lf_lens_sensor_names(void);

#endif
