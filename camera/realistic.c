/* pbrt-v4's "realistic" camera: rays traced from the film through a real
 * lens prescription (Kolb, Mitchell & Hanrahan 1995).
 *
 * Parameters (pbrt-v4 names and defaults):
 *   "string lensfile"        .dat prescription, relative to the scene file (required)
 *   "float aperturediameter" stop diameter in mm (default 1), clamped to the file's stop
 *   "float focusdistance"    metres from the film to the plane in focus (default 10)
 *   "string aperture"        circular | square | pentagon | star | polygon | image file
 *                            (camera/aperture.h; also "blades", "aperturerotation", "anamorphic")
 *   "bool dispersion"        lensfield extension (default false): with Abbe numbers in the
 *                            lens file, n depends on wavelength and rays sample it
 *   "string lensmodel"       lensfield extension: "traced" (default, Snell's law at every
 *                            surface) or "polynomial" (camera/lens_poly.h: a fitted ray
 *                            transfer; traced instead, with a warning, where the fit is poor)
 *   "bool pupilbounds"       lensfield extension (default true): aim film rays at the
 *                            exit-pupil bound; false: at the whole rear disk (for comparison)
 * The film's physical size comes from Film "diagonal" (mm) and the image aspect.
 *
 * Camera space is pbrt's: the film centre at the origin, the lens in front of
 * it along +z; a ray starts on the front element (metres).  Film point
 * (-x, y) in lens space for raster (x, y), as pbrt-v4, so the inverted image
 * comes out upright.  The lens work (tracing, focusing, exit-pupil bounds)
 * is camera/lens.c; generate_rays traces its rays side by side through
 * lf_lens_sample_rays (bit-identical to generate_ray, several times faster).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/lf_keys.h"
#include "base/lf_color.h"
#include "aperture.h"
#include "camera_internal.h"
#include "lens.h"
#include "lens_poly.h"

typedef struct realistic {
    lf_lens lens;
    lf_lens_paraxial px;
    lf_lens_pupil pupil;
    lf_aperture aperture;
    int shaped; /* aperture other than the plain circle */
    int width, height;
    double film_w_mm, film_h_mm, diagonal_mm;
    double focus_distance_mm, film_distance_search_mm, working_fnumber;
    double useful_fraction, lit_film_fraction, setup_seconds;
    int pupil_bounds;     /* "pupilbounds": sample the exit-pupil bound (else the rear disk) */
    int use_poly;         /* "lensmodel" "polynomial" and the fit is good enough */
    int poly_requested;
    lf_lens_poly poly;
} realistic;

/* The polynomial is used when 99% of its rays land within this many pixels
 * of the traced ones on the focus plane and it blocks or passes the same
 * rays but for 1%; otherwise the camera traces (docs/realistic.md). */
#define POLY_MAX_P99_PX 0.1
#define POLY_MAX_MISMATCH 0.01

static double stop_shape(const void *ctx, double x, double y)
{
    return lf_aperture_transmission(ctx, x, y);
}

static void film_point(const realistic *c, double raster_x, double raster_y, double *fx, double *fy)
{
    /* pbrt-v4: pFilm = (-p.x, p.y) with p the raster point mapped onto the
     * physical extent [-w/2, w/2] x [-h/2, h/2]. */
    *fx = -(-0.5 * c->film_w_mm + raster_x / c->width * c->film_w_mm);
    *fy = -0.5 * c->film_h_mm + raster_y / c->height * c->film_h_mm;
}

static void realistic_free(realistic *c)
{
    lf_lens_free(&c->lens);
    lf_lens_poly_free(&c->poly);
    lf_aperture_free(&c->aperture);
    free(c);
}

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Fraction of traced rays that get through, from a fixed stratified set of
 * film and pupil samples (deterministic, a few thousand traces). */
static void estimate_useful_fraction(realistic *c)
{
    enum { N = 48 };
    long traced = 0, passed = 0, film_lit = 0;
    uint32_t s = 12345u;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double rx, ry, fx, fy;
            film_point(c, (i + 0.5) / N * c->width, (j + 0.5) / N * c->height, &fx, &fy);
            int lit = 0;
            for (int k = 0; k < 2; k++) {
                s = s * 1664525u + 1013904223u;
                double u = (s >> 8) * (1.0 / 16777216.0);
                s = s * 1664525u + 1013904223u;
                double v = (s >> 8) * (1.0 / 16777216.0);
                if (!(lf_lens_pupil_sample(&c->pupil, fx, fy, u, v, &rx, &ry) > 0.0))
                    continue;
                lit = 1;
                traced++;
                lf_lens_ray out;
                if (lf_lens_sample_ray(&c->lens, &c->pupil, 1, fx, fy, u, v, NULL, &out) > 0.0)
                    passed++;
            }
            film_lit += lit;
        }
    c->useful_fraction = traced ? (double)passed / traced : 0.0;
    c->lit_film_fraction = (double)film_lit / (N * N);
}

/* The create call's warnings, joined by "; " in its buffer (the plugin
 * ABI's char buffer); *wlen is the length written so far. */
static void warn(const lf_camera_create_args *a, size_t *wlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void warn(const lf_camera_create_args *a, size_t *wlen, const char *fmt, ...)
{
    if (!a->warning || *wlen + 1 >= a->warning_size)
        return;
    int n = snprintf(a->warning + *wlen, a->warning_size - *wlen, "%s", *wlen ? "; " : "");
    *wlen += n > 0 ? (size_t)n : 0;
    if (*wlen < a->warning_size) {
        va_list ap;
        va_start(ap, fmt);
        n = vsnprintf(a->warning + *wlen, a->warning_size - *wlen, fmt, ap);
        va_end(ap);
        *wlen += n > 0 ? (size_t)n : 0;
    }
    if (*wlen >= a->warning_size)
        *wlen = a->warning_size - 1;
}

/* The camera's own parameters, pbrt-v4's names and defaults. */
typedef struct realistic_params {
    const char *lensfile, *lensmodel;
    double aperture_diameter, focus_m;
    int dispersion;
} realistic_params;

/* Checks the parameters and the film (read before the aperture's). */
static int check_params(const lf_camera_create_args *a, realistic *c, const realistic_params *rp, lf_error *err)
{
    if (!rp->lensfile[0])
        return lf_error_set(err, LF_ERR_PARAM,
                            "\"string lensfile\" is required: the realistic camera has no default lens (pbrt-v4: "
                            "\"No lens description file supplied!\"); see scenes/lenses/");
    if (strcmp(rp->lensmodel, "traced") && strcmp(rp->lensmodel, "polynomial"))
        return lf_error_set(err, LF_ERR_PARAM, "\"string lensmodel\" must be \"traced\" or \"polynomial\", got \"%s\"",
                            rp->lensmodel);
    c->poly_requested = !strcmp(rp->lensmodel, "polynomial");
    if (!(rp->aperture_diameter > 0.0) || !isfinite(rp->aperture_diameter))
        return lf_error_set(err, LF_ERR_PARAM, "\"aperturediameter\" must be > 0 mm, got %g", rp->aperture_diameter);
    if (!(rp->focus_m > 0.0) || !isfinite(rp->focus_m))
        return lf_error_set(err, LF_ERR_PARAM, "\"focusdistance\" must be > 0 m, got %g", rp->focus_m);
    if (!(a->film_diagonal_mm > 0.0) || !isfinite(a->film_diagonal_mm) || a->image_width <= 0 ||
        a->image_height <= 0)
        return lf_error_set(err, LF_ERR_PARAM, "film diagonal (%g mm) and resolution must be positive",
                            a->film_diagonal_mm);
    return LF_OK;
}

/* Loads the prescription (path: relative to the scene file), sets the stop
 * and dispersion and focuses the lens (Kolb et al.'s thick-lens focusing,
 * with the search as a cross-check for --explain). */
static int load_lens(const lf_camera_create_args *a, realistic *c, const realistic_params *rp, const char *path,
                     size_t *wlen, lf_error *err)
{
    int rc = lf_lens_load(path, &c->lens, err);
    if (rc)
        return rc;
    if (rp->dispersion && !c->lens.has_abbe)
        warn(a, wlen, "\"dispersion\" is on but %s has no Abbe numbers (5th column): rendering without dispersion",
             path);
    c->lens.dispersive = rp->dispersion && c->lens.has_abbe;
    if (c->lens.stop < 0) {
        warn(a, wlen, "%s has no aperture stop (radius 0 row): \"aperturediameter\" is ignored", path);
    } else {
        lf_warnings lw = {0};
        char msg[1536];
        lf_lens_set_stop_diameter(&c->lens, rp->aperture_diameter, &lw);
        for (const char *t = lf_warnings_text(&lw); lf_cam_next_warning(&t, msg, sizeof msg);)
            warn(a, wlen, "%s", msg);
        lf_warnings_free(&lw);
    }
    if (lf_lens_paraxial_analyse(&c->lens, &c->px))
        return lf_error_set(err, LF_ERR_PARAM, "%s: the lens has no focal power (afocal)", path);
    c->focus_distance_mm = rp->focus_m * 1000.0;
    rc = lf_lens_focus_thick(&c->lens, c->focus_distance_mm, &c->lens.film_distance_mm, err);
    if (rc)
        return rc;
    if (lf_lens_focus_search(&c->lens, c->focus_distance_mm, &c->film_distance_search_mm, NULL))
        c->film_distance_search_mm = NAN;
    c->working_fnumber = lf_lens_working_fnumber(&c->lens, &c->px, c->focus_distance_mm, c->lens.film_distance_mm);
    return LF_OK;
}

/* pbrt-v4: the physical film extent from the diagonal and the aspect
 * ratio; then the exit-pupil bounds over the film's half diagonal. */
static int place_film(const lf_camera_create_args *a, realistic *c, const char *path, lf_error *err)
{
    double aspect = (double)a->image_height / a->image_width;
    c->diagonal_mm = a->film_diagonal_mm;
    c->film_w_mm = sqrt(c->diagonal_mm * c->diagonal_mm / (1.0 + aspect * aspect));
    c->film_h_mm = aspect * c->film_w_mm;
    if (lf_lens_pupil_build(&c->lens, 0.5 * c->diagonal_mm, c->lens.dispersive, &c->pupil) == 0)
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s admits no light: no ray from the film gets through all %d surfaces (stop diameter "
                            "%g mm, film %g mm behind the rear vertex)",
                            path, c->lens.n,
                            c->lens.stop >= 0 ? 2.0 * c->lens.s[c->lens.stop].aperture_radius_mm : 0.0,
                            c->lens.film_distance_mm);
    return LF_OK;
}

/* "lensmodel" "polynomial": fits the ray transfer and uses it when it is
 * close enough to tracing; otherwise warns and traces. */
static void try_polynomial(const lf_camera_create_args *a, realistic *c, const char *path, size_t *wlen)
{
    if (c->poly_requested && c->lens.dispersive) {
        warn(a, wlen, "\"lensmodel\" \"polynomial\" has no wavelength input: tracing %s instead (dispersion is on)",
             path);
        return;
    }
    if (!c->poly_requested)
        return;
    lf_lens_poly_opts po = lf_lens_poly_opts_default();
    po.pixel_mm = c->film_w_mm / c->width;
    po.focus_distance_mm = c->focus_distance_mm;
    lf_error perr = {0};
    if (lf_lens_poly_fit(&c->lens, &c->pupil, &po, &c->poly, &perr)) {
        warn(a, wlen, "\"lensmodel\" \"polynomial\": %.255s; tracing %s instead", perr.msg, path);
    } else if (!(c->poly.fit.p99_px <= POLY_MAX_P99_PX) || !(c->poly.fit.mismatch_fraction <= POLY_MAX_MISMATCH)) {
        warn(a, wlen,
             "\"lensmodel\" \"polynomial\": the best fit (degree %d) of %s puts 1%% of rays %.2g pixels or "
             "more from the traced ones and passes or blocks %.2g%% of rays differently (limits %g px, %g%%); "
             "tracing instead",
             c->poly.degree, path, c->poly.fit.p99_px, 100.0 * c->poly.fit.mismatch_fraction, POLY_MAX_P99_PX,
             100.0 * POLY_MAX_MISMATCH);
    } else {
        c->use_poly = 1;
    }
}

static int realistic_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    double t0 = seconds();
    realistic *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->width = a->image_width;
    c->height = a->image_height;
    realistic_params rp;
    rp.lensfile = p->get_string(p->ctx, "lensfile", "");
    rp.aperture_diameter = p->get_float(p->ctx, "aperturediameter", 1.0);
    rp.focus_m = p->get_float(p->ctx, "focusdistance", 10.0);
    rp.dispersion = p->get_bool(p->ctx, "dispersion", 0);
    rp.lensmodel = p->get_string(p->ctx, "lensmodel", "traced");
    c->pupil_bounds = p->get_bool(p->ctx, "pupilbounds", 1);
    lf_error err = {0};
    if (lf_cam_error(lf_aperture_parse(p, &c->aperture, &err), &err, a->error, a->error_size)) {
        free(c);
        return -1;
    }
    c->shaped = c->aperture.kind != LF_APERTURE_CIRCLE || c->aperture.anamorphic != 1.0;
    char path[4096];
    if (rp.lensfile[0] == '/' || !a->scene_dir || !a->scene_dir[0])
        snprintf(path, sizeof path, "%s", rp.lensfile);
    else
        snprintf(path, sizeof path, "%s/%s", a->scene_dir, rp.lensfile);
    size_t wlen = a->warning && a->warning_size ? strlen(a->warning) : 0;
    int rc = check_params(a, c, &rp, &err);
    if (!rc)
        rc = load_lens(a, c, &rp, path, &wlen, &err);
    if (!rc)
        rc = place_film(a, c, path, &err);
    if (lf_cam_error(rc, &err, a->error, a->error_size)) {
        realistic_free(c);
        return -1;
    }
    try_polynomial(a, c, path, &wlen);
    estimate_useful_fraction(c);
    c->setup_seconds = seconds() - t0;
    *state = c;
    return 0;
}

static uint32_t realistic_needs(const void *state)
{
    const realistic *c = state;
    return LF_CAMERA_NEEDS_LENS | (c->lens.dispersive ? LF_CAMERA_NEEDS_WAVELENGTH : 0u);
}

/* Lens space (mm, z toward the film) -> camera space (m, z into the scene);
 * weight 0: the camera's "no ray".  Both lens models return a unit d. */
static inline void to_camera(const lf_lens_ray *out, double w, lf_camera_ray *r)
{
    if (!(w > 0.0)) {
        r->origin[0] = r->origin[1] = r->origin[2] = 0.0;
        r->dir[0] = r->dir[1] = 0.0, r->dir[2] = 1.0;
        return;
    }
    r->origin[0] = out->o[0] * 1e-3, r->origin[1] = out->o[1] * 1e-3, r->origin[2] = -out->o[2] * 1e-3;
    r->dir[0] = out->d[0], r->dir[1] = out->d[1], r->dir[2] = -out->d[2];
}

static inline double wavelength_nm(const lf_camera_sample *s)
{
    return LF_LAMBDA_MIN + s->wavelength_u * (LF_LAMBDA_MAX - LF_LAMBDA_MIN);
}

static double realistic_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const realistic *c = state;
    double fx, fy;
    film_point(c, s->film_x, s->film_y, &fx, &fy);
    lf_lens_trace_opts opts = {0};
    if (c->lens.dispersive) {
        opts.lambda_nm = wavelength_nm(s);
        r->wavelength_nm = opts.lambda_nm;
    }
    if (c->shaped) {
        opts.stop_shape = stop_shape;
        opts.stop_ctx = &c->aperture;
    }
    lf_lens_ray out;
    double w = c->use_poly ? lf_lens_poly_sample_ray(&c->lens, &c->poly, &c->pupil, c->pupil_bounds, fx, fy, s->lens_u,
                                                     s->lens_v, opts.stop_shape, opts.stop_ctx, &out)
                           : lf_lens_sample_ray(&c->lens, &c->pupil, c->pupil_bounds, fx, fy, s->lens_u, s->lens_v,
                                                &opts, &out);
    to_camera(&out, w, r);
    return w > 0.0 ? w : 0.0;
}

/* generate_rays: for the traced model, chunks through lf_lens_sample_rays
 * (the rays of a chunk traced side by side, surface by surface); the
 * polynomial model evaluates one ray at a time. */
static void realistic_generate_rays(const void *state, int n, const lf_camera_sample *s, lf_camera_ray *r,
                                    double *weights)
{
    const realistic *c = state;
    if (c->use_poly) {
        for (int i = 0; i < n; i++)
            weights[i] = realistic_generate_ray(state, &s[i], &r[i]);
        return;
    }
    enum { CHUNK = 64 };
    double fx[CHUNK], fy[CHUNK], u[CHUNK], v[CHUNK], lambda[CHUNK], w[CHUNK];
    lf_lens_ray out[CHUNK];
    const int dispersive = c->lens.dispersive;
    for (int i0 = 0; i0 < n; i0 += CHUNK) {
        int m = n - i0 < CHUNK ? n - i0 : CHUNK;
        for (int j = 0; j < m; j++) {
            const lf_camera_sample *sj = &s[i0 + j];
            film_point(c, sj->film_x, sj->film_y, &fx[j], &fy[j]);
            u[j] = sj->lens_u, v[j] = sj->lens_v;
            if (dispersive)
                r[i0 + j].wavelength_nm = lambda[j] = wavelength_nm(sj);
        }
        lf_lens_sample_rays(&c->lens, &c->pupil, c->pupil_bounds, m, fx, fy, u, v, dispersive ? lambda : NULL,
                            c->shaped ? stop_shape : NULL, &c->aperture, out, w);
        for (int j = 0; j < m; j++) {
            to_camera(&out[j], w[j], &r[i0 + j]);
            weights[i0 + j] = w[j] > 0.0 ? w[j] : 0.0;
        }
    }
}

static void realistic_destroy(void *state)
{
    if (state)
        realistic_free(state);
}

static int realistic_describe(const void *state, char *buf, size_t size)
{
    const realistic *c = state;
    const lf_lens *L = &c->lens;
    double stop_d = L->stop >= 0 ? 2.0 * L->s[L->stop].aperture_radius_mm : 0.0;
    double stop_max = L->stop >= 0 ? 2.0 * L->stop_max_radius_mm : 0.0;
    static const char *const shapes[] = {"circular", "polygon", "star", "image"};
    char model[512];
    if (c->use_poly)
        snprintf(model, sizeof model,
                 "polynomial (fitted ray transfer, degree %d, %d clipping surfaces + stop, fit %.3f s; against "
                 "tracing: rms %.3g px, 99%% within %.3g px on the focus plane, %.2g%% of rays passed/blocked "
                 "differently)",
                 c->poly.degree, c->poly.n_clip, c->poly.setup_seconds, c->poly.fit.rms_px, c->poly.fit.p99_px,
                 100.0 * c->poly.fit.mismatch_fraction);
    else
        snprintf(model, sizeof model, "traced (Snell's law at every surface)%s",
                 c->poly_requested ? "; \"polynomial\" was asked for but is not accurate enough or not possible here"
                                   : "");
    int n = snprintf(
        buf, size,
        "model: real compound lens traced from the film (Kolb et al. 1995; pbrt-v4 \"realistic\"): %s, %d surfaces\n"
        "effective focal length: %.4g mm (paraxial y-nu trace)\n"
        "f-number: working f/%.3g at the focus distance, f/%.3g at infinity (stop %.4g mm of %.4g mm)\n"
        "focus distance: %.4g m from the film; film %.4f mm behind the rear vertex (thick-lens model, as pbrt-v4; "
        "exact best-focus search: %.4f mm)\n"
        "film: %.4g x %.4g mm (diagonal %.4g mm)\n"
        "pupils: entrance %.4g mm wide, %.4g mm behind the front vertex; exit %.4g mm wide, %.4g mm from the rear "
        "vertex\n"
        "lens model: %s\n"
        "exit-pupil bounds: %s%d film-radius bins x %d strips, %lld rays traced; camera set-up %.3f s\n"
        "expected useful-ray fraction: %.1f%% of traced camera rays (%.1f%% of the film receives light)\n"
        "aperture: %s%s\n"
        "dispersion: %s\n",
        L->path, L->n, c->px.efl_mm, c->working_fnumber, c->px.fnumber, stop_d, stop_max,
        c->focus_distance_mm * 1e-3, L->film_distance_mm, c->film_distance_search_mm, c->film_w_mm, c->film_h_mm,
        c->diagonal_mm, c->px.entrance_pupil_diameter_mm, c->px.entrance_pupil_mm, c->px.exit_pupil_diameter_mm,
        c->px.exit_pupil_mm, model,
        c->pupil_bounds ? "" : "off (\"pupilbounds\" false: rays aimed at the whole rear disk; built for the polynomial's "
                               "domain) ",
        c->pupil.n_bins, LF_LENS_PUPIL_STRIPS, c->pupil.traces, c->setup_seconds,
        100.0 * c->useful_fraction, 100.0 * c->lit_film_fraction, shapes[c->aperture.kind],
        c->aperture.anamorphic != 1.0 ? " (anamorphic)" : "",
        L->dispersive ? "on (Cauchy n(lambda) = A + B/lambda^2 through n_d and V_d; rays sample 360-830 nm)"
        : L->has_abbe ? "off (the lens has Abbe numbers: \"bool dispersion\" true turns it on)"
                      : "off (no Abbe numbers in the lens file)");
    return n;
}

static void realistic_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const realistic *c = state;
    sink->set_string(sink->ctx, LF_KEY_LENS_FILE, c->lens.path);
    sink->set_double(sink->ctx, LF_KEY_LENS_EFL_MM, c->px.efl_mm);
    sink->set_double(sink->ctx, LF_KEY_LENS_WORKING_FNUMBER, c->working_fnumber);
    sink->set_double(sink->ctx, LF_KEY_FOCUS_DISTANCE_M, c->focus_distance_mm * 1e-3);
    sink->set_double(sink->ctx, LF_KEY_LENS_FILM_DISTANCE_MM, c->lens.film_distance_mm);
    sink->set_int(sink->ctx, LF_KEY_LENS_DISPERSION, c->lens.dispersive);
    sink->set_string(sink->ctx, LF_KEY_LENS_MODEL, c->use_poly ? "polynomial" : "traced");
    /* film to the front principal plane H: where a thin lens standing in for
     * this lens goes (bench/accuracy.sh) */
    sink->set_double(sink->ctx, LF_KEY_LENS_FRONT_PRINCIPAL_FROM_FILM_MM,
                     c->lens.film_distance_mm + c->px.total_length_mm - c->px.front_principal_mm);
}

const lf_camera_type lf_camera_realistic = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "realistic",
    .create = realistic_create,
    .needs = realistic_needs,
    .generate_ray = realistic_generate_ray,
    .destroy = realistic_destroy,
    .describe = realistic_describe,
    .metadata = realistic_metadata,
    .generate_rays = realistic_generate_rays,
};
