/* lflens - analyse and draw real lens prescriptions (pbrt .dat files).
 *
 * usage: lflens info LENS.dat [--aperture MM] [--focus M] [--sensor NAME|--diagonal MM] [--json]
 *        lflens plot LENS.dat -o OUT.svg|OUT.png [--aperture MM] [--focus M] [--sensor NAME|--diagonal MM]
 *
 *   info  paraxial analysis (y-nu trace): focal lengths, principal planes,
 *         pupils, f-numbers, field of view for the sensor, the film position
 *         that focuses at --focus (thick-lens estimate and exact best-focus
 *         search), closest focus.  --json prints one object with efl_mm,
 *         bfl_mm, ffl_mm, fnumber, entrance_pupil_mm, exit_pupil_mm, fov_deg
 *         (diameters for the pupils; the traced diagonal field of view) and more.
 *   plot  the lens cross-section with traced ray fans (on-axis, 0.7 field,
 *         full field), a spot diagram at four field angles and the distortion
 *         curve, in one drawing.  SVG has labels; PNG is the same drawing
 *         rasterised without text.
 *
 *   --aperture MM   stop diameter (default: the file's full stop)
 *   --focus M       focus distance from the film in metres (default: infinity)
 *   --sensor NAME   fullframe, apsc, apsh, mediumformat, fourthirds, 1inch, 1/1.63in,
 *                   1/2.3in, 1/3.2in (default fullframe)
 *   --diagonal MM   a film of this diagonal with a 3:2 aspect
 *
 * Exit codes: 0 success; 1 bad lens file or impossible request (message
 * names file:line); 2 bad command line.  Outputs are written atomically.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "camera/lens.h"
#include "image/lf_image.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct options {
    const char *lens_path, *out_path, *sensor;
    double aperture_mm, focus_m, diagonal_mm;
    int json;
} options;

static void usage(FILE *f)
{
    fprintf(f, "usage: lflens info LENS.dat [--aperture MM] [--focus M] [--sensor NAME|--diagonal MM] [--json]\n"
               "       lflens plot LENS.dat -o OUT.svg|OUT.png [--aperture MM] [--focus M]\n"
               "                   [--sensor NAME|--diagonal MM]\n"
               "sensors: %s\n",
            lf_lens_sensor_names());
}

static int parse_positive(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v > 0.0) || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* Returns 0, or 2 after printing a usage error. */
static int parse_args(int argc, char **argv, int want_out, options *o)
{
    memset(o, 0, sizeof *o);
    o->focus_m = INFINITY;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--json") && !want_out) {
            o->json = 1;
            continue;
        }
        int takes = !strcmp(a, "--aperture") || !strcmp(a, "--focus") || !strcmp(a, "--sensor") ||
                    !strcmp(a, "--diagonal") || (want_out && !strcmp(a, "-o"));
        if (takes && !val) {
            fprintf(stderr, "lflens: %s needs a value\n", a);
            return 2;
        }
        if (!strcmp(a, "--aperture")) {
            if (parse_positive(val, &o->aperture_mm)) {
                fprintf(stderr, "lflens: --aperture wants a diameter in mm > 0, got \"%s\"\n", val);
                return 2;
            }
        } else if (!strcmp(a, "--focus")) {
            if (!strcmp(val, "inf") || !strcmp(val, "infinity"))
                o->focus_m = INFINITY;
            else if (parse_positive(val, &o->focus_m)) {
                fprintf(stderr, "lflens: --focus wants metres > 0 (or inf), got \"%s\"\n", val);
                return 2;
            }
        } else if (!strcmp(a, "--sensor")) {
            double w, h;
            if (lf_lens_sensor_size(val, &w, &h)) {
                fprintf(stderr, "lflens: unknown sensor \"%s\" (known: %s)\n", val, lf_lens_sensor_names());
                return 2;
            }
            o->sensor = val;
        } else if (!strcmp(a, "--diagonal")) {
            if (parse_positive(val, &o->diagonal_mm)) {
                fprintf(stderr, "lflens: --diagonal wants mm > 0, got \"%s\"\n", val);
                return 2;
            }
        } else if (want_out && !strcmp(a, "-o")) {
            o->out_path = val;
        } else if (a[0] == '-') {
            fprintf(stderr, "lflens: unknown option %s\n", a);
            usage(stderr);
            return 2;
        } else if (!o->lens_path) {
            o->lens_path = a;
            continue;
        } else {
            fprintf(stderr, "lflens: unexpected argument %s\n", a);
            return 2;
        }
        i++;
    }
    if (!o->lens_path) {
        fprintf(stderr, "lflens: no lens file given\n");
        usage(stderr);
        return 2;
    }
    if (o->sensor && o->diagonal_mm > 0) {
        fprintf(stderr, "lflens: give --sensor or --diagonal, not both\n");
        return 2;
    }
    if (want_out) {
        const char *dot = o->out_path ? strrchr(o->out_path, '.') : NULL;
        if (!dot || (strcmp(dot, ".svg") && strcmp(dot, ".png"))) {
            fprintf(stderr, "lflens: plot needs -o OUT.svg or -o OUT.png\n");
            return 2;
        }
    }
    return 0;
}

/* Everything both subcommands need: the lens focused, its paraxial data and
 * its field. */
typedef struct analysis {
    lf_lens lens;
    lf_lens_paraxial px;
    double sensor_w, sensor_h, diagonal;
    double film_thick, film_search, closest_m, working_n;
    double fov_par[3], fov_traced[3]; /* horizontal, vertical, diagonal (deg) */
    double image_circle_r;
    int clamped;
} analysis;

static int analyse(const options *o, analysis *an)
{
    memset(an, 0, sizeof *an);
    char err[1024];
    if (lf_lens_load(o->lens_path, &an->lens, err, sizeof err)) {
        fprintf(stderr, "lflens: %s\n", err);
        return 1;
    }
    lf_lens *L = &an->lens;
    if (o->aperture_mm > 0) {
        char warn[1024] = "";
        an->clamped = lf_lens_set_stop_diameter(L, o->aperture_mm, warn, sizeof warn);
        if (an->clamped)
            fprintf(stderr, "lflens: warning: %s\n", warn);
        if (L->stop < 0)
            fprintf(stderr, "lflens: warning: %s has no aperture stop row; --aperture ignored\n", o->lens_path);
    }
    if (lf_lens_paraxial_analyse(L, &an->px)) {
        fprintf(stderr, "lflens: %s: the lens has no focal power (afocal)\n", o->lens_path);
        return 1;
    }
    if (o->sensor) {
        lf_lens_sensor_size(o->sensor, &an->sensor_w, &an->sensor_h);
    } else if (o->diagonal_mm > 0) {
        an->sensor_w = o->diagonal_mm * 3.0 / sqrt(13.0);
        an->sensor_h = o->diagonal_mm * 2.0 / sqrt(13.0);
    } else {
        lf_lens_sensor_size("fullframe", &an->sensor_w, &an->sensor_h);
    }
    an->diagonal = hypot(an->sensor_w, an->sensor_h);
    double D = isinf(o->focus_m) ? INFINITY : o->focus_m * 1000.0;
    if (lf_lens_focus_thick(L, D, &an->film_thick, err, sizeof err)) {
        fprintf(stderr, "lflens: %s\n", err);
        return 1;
    }
    if (lf_lens_focus_search(L, D, &an->film_search, err, sizeof err))
        an->film_search = NAN;
    an->closest_m = lf_lens_closest_focus_mm(&an->px) * 1e-3;
    L->film_distance_mm = an->film_thick;
    an->working_n = lf_lens_working_fnumber(L, &an->px, D, an->film_thick);
    double half[3] = {0.5 * an->sensor_w, 0.5 * an->sensor_h, 0.5 * an->diagonal};
    an->image_circle_r = lf_lens_image_circle_radius(L, half[2]);
    if (an->image_circle_r <= 0.0) {
        fprintf(stderr, "lflens: %s admits no light: no ray from the film centre gets through\n", o->lens_path);
        return 1;
    }
    for (int k = 0; k < 3; k++) {
        an->fov_par[k] = 2.0 * atan(half[k] / an->px.efl_mm) * 180.0 / M_PI;
        double r = half[k] < an->image_circle_r ? half[k] : an->image_circle_r, th = 0;
        if (lf_lens_field_angle(L, r, &th) == 0)
            an->fov_traced[k] = 2.0 * th * 180.0 / M_PI;
    }
    return 0;
}

static int cmd_info(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, 0, &o);
    if (rc)
        return rc;
    analysis an;
    if (analyse(&o, &an)) {
        lf_lens_free(&an.lens);
        return 1;
    }
    const lf_lens *L = &an.lens;
    const lf_lens_paraxial *p = &an.px;
    double stop_d = 2.0 * L->s[p->stop].aperture_radius_mm;
    if (o.json) {
        char focus[64];
        if (isinf(o.focus_m))
            snprintf(focus, sizeof focus, "\"inf\"");
        else
            snprintf(focus, sizeof focus, "%.6g", o.focus_m);
        printf("{\"lens\": \"%s\", \"surfaces\": %d, \"efl_mm\": %.6g, \"bfl_mm\": %.6g, \"ffl_mm\": %.6g, "
               "\"front_principal_mm\": %.6g, \"rear_principal_mm\": %.6g, \"total_length_mm\": %.6g, "
               "\"stop_diameter_mm\": %.6g, \"fnumber\": %.6g, \"working_fnumber\": %.6g, "
               "\"entrance_pupil_mm\": %.6g, \"entrance_pupil_z_mm\": %.6g, \"exit_pupil_mm\": %.6g, "
               "\"exit_pupil_z_mm\": %.6g, \"sensor_mm\": [%.6g, %.6g], \"fov_deg\": %.6g, "
               "\"fov_traced_deg\": [%.6g, %.6g, %.6g], \"fov_paraxial_deg\": [%.6g, %.6g, %.6g], "
               "\"image_circle_mm\": %.6g, \"focus_m\": %s, \"film_distance_thick_mm\": %.6g, "
               "\"film_distance_search_mm\": %.6g, \"closest_focus_m\": %.6g, \"abbe\": %s}\n",
               o.lens_path, L->n, p->efl_mm, p->bfl_mm, p->ffl_mm, p->front_principal_mm, p->rear_principal_mm,
               p->total_length_mm, stop_d, p->fnumber, an.working_n, p->entrance_pupil_diameter_mm,
               p->entrance_pupil_mm, p->exit_pupil_diameter_mm, p->exit_pupil_mm, an.sensor_w, an.sensor_h,
               an.fov_traced[2], an.fov_traced[0], an.fov_traced[1], an.fov_traced[2], an.fov_par[0], an.fov_par[1],
               an.fov_par[2], 2.0 * an.image_circle_r, focus, an.film_thick,
               isfinite(an.film_search) ? an.film_search : -1.0, an.closest_m, L->has_abbe ? "true" : "false");
    } else {
        printf("lens:                  %s (%d surfaces, stop on line %d)%s\n", o.lens_path, L->n,
               L->s[p->stop].line, L->has_abbe ? ", Abbe numbers present" : "");
        printf("effective focal length %.4f mm\n", p->efl_mm);
        printf("back focal distance    %.4f mm (rear vertex to F')\n", p->bfl_mm);
        printf("front focal distance   %.4f mm (F to front vertex; > 0: F in front of the lens)\n", p->ffl_mm);
        printf("principal planes       H %.4f mm from the front vertex, H' %.4f mm from the rear vertex\n",
               p->front_principal_mm, p->rear_principal_mm);
        printf("total length           %.4f mm (front vertex to rear vertex)\n", p->total_length_mm);
        printf("aperture stop          %.4g mm diameter (file: %.4g mm)\n", stop_d,
               L->stop >= 0 ? 2.0 * L->stop_max_radius_mm : stop_d);
        printf("entrance pupil         %.4f mm diameter, %.4f mm from the front vertex\n",
               p->entrance_pupil_diameter_mm, p->entrance_pupil_mm);
        printf("exit pupil             %.4f mm diameter, %.4f mm from the rear vertex\n", p->exit_pupil_diameter_mm,
               p->exit_pupil_mm);
        printf("f-number               f/%.3f at infinity; working f/%.3f at the focus distance\n", p->fnumber,
               an.working_n);
        printf("sensor                 %.4g x %.4g mm (diagonal %.4g mm)%s%s\n", an.sensor_w, an.sensor_h,
               an.diagonal, o.sensor ? ", " : "", o.sensor ? o.sensor : "");
        printf("field of view          paraxial %.2f x %.2f deg (diagonal %.2f); traced %.2f x %.2f deg (diagonal "
               "%.2f)\n",
               an.fov_par[0], an.fov_par[1], an.fov_par[2], an.fov_traced[0], an.fov_traced[1], an.fov_traced[2]);
        if (an.image_circle_r < 0.5 * an.diagonal)
            printf("image circle           %.3f mm diameter: smaller than the sensor diagonal\n",
                   2.0 * an.image_circle_r);
        if (isinf(o.focus_m))
            printf("focus at infinity      film %.4f mm behind the rear vertex (thick lens = BFL); exact best-focus "
                   "search %.4f mm\n",
                   an.film_thick, an.film_search);
        else {
            char label[64];
            snprintf(label, sizeof label, "focus at %.4g m", o.focus_m);
            printf("%-23sfilm %.4f mm behind the rear vertex (thick-lens estimate); exact best-focus search %.4f mm\n",
                   label, an.film_thick, an.film_search);
        }
        printf("closest focus          %.4f m from the film (unit magnification, thick-lens model)\n", an.closest_m);
    }
    lf_lens_free(&an.lens);
    return 0;
}

/* ------------------------------------------------------------- drawing */

typedef struct prim {
    int kind; /* 0 polyline, 1 polygon (filled in SVG), 2 dot, 3 text */
    double *pts;
    int n;
    unsigned color, fill;
    double width;
    int dashed;
    char text[640];
} prim;

typedef struct drawing {
    prim *p;
    int n, cap;
    int w, h;
} drawing;

static prim *add(drawing *d, int kind, unsigned color)
{
    if (d->n == d->cap) {
        d->cap = d->cap ? 2 * d->cap : 256;
        d->p = realloc(d->p, (size_t)d->cap * sizeof *d->p);
        if (!d->p) {
            fprintf(stderr, "lflens: out of memory\n");
            exit(1);
        }
    }
    prim *q = &d->p[d->n++];
    memset(q, 0, sizeof *q);
    q->kind = kind, q->color = color, q->width = 1.0;
    return q;
}

static void line(drawing *d, double x0, double y0, double x1, double y1, unsigned color, double width, int dashed)
{
    prim *q = add(d, 0, color);
    q->pts = malloc(4 * sizeof(double));
    q->pts[0] = x0, q->pts[1] = y0, q->pts[2] = x1, q->pts[3] = y1;
    q->n = 2, q->width = width, q->dashed = dashed;
}

static void text(drawing *d, double x, double y, const char *s)
{
    prim *q = add(d, 3, 0x333333);
    q->pts = malloc(2 * sizeof(double));
    q->pts[0] = x, q->pts[1] = y, q->n = 1;
    snprintf(q->text, sizeof q->text, "%s", s);
}

static void dot(drawing *d, double x, double y, unsigned color)
{
    prim *q = add(d, 2, color);
    q->pts = malloc(2 * sizeof(double));
    q->pts[0] = x, q->pts[1] = y, q->n = 1;
}

static void frame(drawing *d, double x0, double y0, double x1, double y1)
{
    line(d, x0, y0, x1, y0, 0x999999, 1, 0);
    line(d, x1, y0, x1, y1, 0x999999, 1, 0);
    line(d, x1, y1, x0, y1, 0x999999, 1, 0);
    line(d, x0, y1, x0, y0, 0x999999, 1, 0);
}

/* Panel mapping: lens space (z, y) mm -> pixels, equal scale on both axes. */
typedef struct view {
    double sx, ox, oy; /* px = ox + sx z, py = oy - sx y */
} view;

static double vx(const view *v, double z)
{
    return v->ox + v->sx * z;
}
static double vy(const view *v, double y)
{
    return v->oy - v->sx * y;
}

static double surface_z(const lf_lens_surface *s, double zv, double y)
{
    if (s->radius_mm == 0.0)
        return zv;
    double R = s->radius_mm, q = R * R - y * y;
    return zv + R - (R > 0 ? 1.0 : -1.0) * sqrt(q > 0 ? q : 0);
}

static const unsigned fan_colors[3] = {0x1f5fbf, 0xc0392b, 0x27ae60};

/* A collimated fan at field angle theta in the meridional plane; calls back
 * with each passing ray's path.  Returns the number that passed. */
typedef void (*fan_fn)(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out);

static double beam_rho(const lf_lens *L)
{
    double rho = 0.0;
    for (int i = 0; i < L->n; i++)
        if (L->s[i].aperture_radius_mm > rho)
            rho = L->s[i].aperture_radius_mm;
    return 1.6 * rho;
}

/* Parallel rays at field angle theta (meridional plane y-z) through the grid
 * a in [a0, a1] (x) by b in [b0, b1] (across the beam in the meridional
 * plane).  Calls back with each passing ray's path; returns how many pass. */
static int collimated_beam(const lf_lens *L, double theta, double a0, double a1, int nx, double b0, double b1, int ny,
                           fan_fn fn, void *ctx)
{
    double zf = L->s[0].z_mm - L->film_distance_mm;
    double d[3] = {0, sin(theta), cos(theta)}, e2[3] = {0, cos(theta), -sin(theta)};
    double back = 3.0 * beam_rho(L) + lf_lens_total_length_mm(L);
    double (*path)[3] = malloc((size_t)(L->n + 1) * sizeof *path);
    int passed = 0;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double a = nx > 1 ? a0 + (a1 - a0) * i / (nx - 1) : 0.5 * (a0 + a1);
            double b = ny > 1 ? b0 + (b1 - b0) * j / (ny - 1) : 0.5 * (b0 + b1);
            lf_lens_ray in, out;
            for (int k = 0; k < 3; k++)
                in.o[k] = (k == 2 ? zf : 0.0) - back * d[k] + b * e2[k] + (k == 0 ? a : 0.0), in.d[k] = d[k];
            lf_lens_trace_opts o = {0};
            o.path = path;
            if (lf_lens_trace_from_scene(L, &in, &out, &o) != LF_LENS_PASSED)
                continue;
            passed++;
            if (fn)
                fn(ctx, &in, (const double(*)[3])path, o.path_count, &out);
        }
    free(path);
    return passed;
}

typedef struct extent_acc {
    double lo, hi, theta;
    int sagittal;
} extent_acc;

static void grow_extent(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out)
{
    (void)path, (void)n, (void)out;
    extent_acc *e = ctx;
    /* recover the grid coordinate from the start point */
    double v = e->sagittal ? in->o[0] : in->o[1] * cos(e->theta) - in->o[2] * sin(e->theta);
    if (v < e->lo)
        e->lo = v;
    if (v > e->hi)
        e->hi = v;
}

/* The passing beam's extent across (b) and along x (a), by two fine scans. */
static int beam_extent(const lf_lens *L, double theta, double *a0, double *a1, double *b0, double *b1)
{
    double rho = beam_rho(L), zf = L->s[0].z_mm - L->film_distance_mm;
    double back = 3.0 * rho + lf_lens_total_length_mm(L);
    (void)back;
    double bias = -zf * sin(theta); /* b = o_y cos - o_z sin - bias */
    extent_acc e = {INFINITY, -INFINITY, theta, 0};
    if (!collimated_beam(L, theta, 0, 0, 1, -rho, rho, 801, grow_extent, &e))
        return -1;
    double step = 2.0 * rho / 800;
    *b0 = e.lo - bias - step, *b1 = e.hi - bias + step;
    extent_acc s = {INFINITY, -INFINITY, theta, 1};
    collimated_beam(L, theta, -rho, rho, 801, *b0 + 0.5 * (*b1 - *b0), *b0 + 0.5 * (*b1 - *b0), 1, grow_extent, &s);
    if (!(s.hi >= s.lo))
        s.lo = -rho, s.hi = rho;
    *a0 = s.lo - step, *a1 = s.hi + step;
    return 0;
}

typedef struct fan_draw {
    drawing *d;
    const view *v;
    double z_start, ymax;
    unsigned color;
} fan_draw;

static void draw_fan_ray(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out)
{
    fan_draw *f = ctx;
    prim *q = add(f->d, 0, f->color);
    q->pts = malloc((size_t)(n + 2) * 2 * sizeof(double));
    double t = (f->z_start - in->o[2]) / in->d[2];
    if (fabs(in->o[1] + t * in->d[1]) > f->ymax && in->d[1] != 0.0) /* keep the start inside the panel */
        t = ((in->d[1] > 0 ? -f->ymax : f->ymax) - in->o[1]) / in->d[1];
    q->pts[0] = vx(f->v, f->z_start), q->pts[1] = vy(f->v, in->o[1] + t * in->d[1]);
    for (int i = 0; i < n; i++)
        q->pts[2 + 2 * i] = vx(f->v, path[i][2]), q->pts[3 + 2 * i] = vy(f->v, path[i][1]);
    double tf = -out->o[2] / out->d[2];
    q->pts[2 + 2 * n] = vx(f->v, 0.0), q->pts[3 + 2 * n] = vy(f->v, out->o[1] + tf * out->d[1]);
    q->n = n + 2;
    q->width = 0.7;
}

typedef struct spot_acc {
    double *x, *y;
    int n, cap;
} spot_acc;

static void collect_spot(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out)
{
    (void)in, (void)path, (void)n;
    spot_acc *s = ctx;
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->x = realloc(s->x, (size_t)s->cap * sizeof(double));
        s->y = realloc(s->y, (size_t)s->cap * sizeof(double));
        if (!s->x || !s->y) {
            fprintf(stderr, "lflens: out of memory\n");
            exit(1);
        }
    }
    double t = -out->o[2] / out->d[2];
    s->x[s->n] = out->o[0] + t * out->d[0];
    s->y[s->n] = out->o[1] + t * out->d[1];
    s->n++;
}

static void build_drawing(const analysis *an, drawing *d)
{
    const lf_lens *L = &an->lens;
    d->w = 1000, d->h = 760;
    char buf[640];
    /* --- panel 1: cross-section with ray fans --- */
    double px0 = 20, py0 = 20, px1 = 980, py1 = 460;
    frame(d, px0, py0, px1, py1);
    double zfront = L->s[0].z_mm - L->film_distance_mm, length = -zfront;
    double ymax = 0.5 * an->diagonal;
    for (int i = 0; i < L->n; i++)
        if (L->s[i].aperture_radius_mm > ymax)
            ymax = L->s[i].aperture_radius_mm;
    ymax *= 1.15;
    double z0 = zfront - 0.25 * length, z1 = 0.04 * length;
    view v;
    v.sx = fmin((px1 - px0 - 20) / (z1 - z0), (py1 - py0 - 40) / (2.0 * ymax));
    v.ox = 0.5 * (px0 + px1) - v.sx * 0.5 * (z0 + z1);
    v.oy = 0.5 * (py0 + py1) + 10;
    line(d, vx(&v, z0), vy(&v, 0), vx(&v, z1), vy(&v, 0), 0xaaaaaa, 0.8, 1);
    /* glass: outline of each element (surface i to i+1 when the medium between is glass) */
    for (int i = 0; i < L->n; i++) {
        const lf_lens_surface *s = &L->s[i];
        double zv = s->z_mm - L->film_distance_mm;
        if (s->radius_mm == 0.0) {
            double a = s->aperture_radius_mm, b = fmax(a * 1.35, a + 0.08 * ymax);
            line(d, vx(&v, zv), vy(&v, a), vx(&v, zv), vy(&v, b), 0x000000, 2.5, 0);
            line(d, vx(&v, zv), vy(&v, -a), vx(&v, zv), vy(&v, -b), 0x000000, 2.5, 0);
            continue;
        }
        if (s->ior > 1.0 && i + 1 < L->n) {
            const lf_lens_surface *t = &L->s[i + 1];
            double zt = t->z_mm - L->film_distance_mm;
            enum { NA = 40 };
            prim *q = add(d, 1, 0x335577);
            q->fill = 0xd6e6f5;
            q->pts = malloc((2 * NA + 4) * 2 * sizeof(double));
            int k = 0;
            double ea = fmax(s->aperture_radius_mm, t->radius_mm != 0 ? t->aperture_radius_mm : 0);
            for (int j = 0; j < NA; j++) {
                double y = -s->aperture_radius_mm + 2.0 * s->aperture_radius_mm * j / (NA - 1);
                q->pts[k++] = vx(&v, surface_z(s, zv, y)), q->pts[k++] = vy(&v, y);
            }
            if (ea > s->aperture_radius_mm) /* flat rim out to the larger element */
                q->pts[k++] = vx(&v, surface_z(s, zv, s->aperture_radius_mm)), q->pts[k++] = vy(&v, ea);
            for (int j = NA - 1; j >= 0; j--) {
                double y = -t->aperture_radius_mm + 2.0 * t->aperture_radius_mm * j / (NA - 1);
                q->pts[k++] = vx(&v, surface_z(t, zt, y)), q->pts[k++] = vy(&v, y);
            }
            if (ea > s->aperture_radius_mm)
                q->pts[k++] = vx(&v, surface_z(s, zv, -s->aperture_radius_mm)), q->pts[k++] = vy(&v, -ea);
            q->n = k / 2;
            q->width = 1.2;
        } else if (!(i > 0 && L->s[i - 1].ior > 1.0)) {
            /* an air-air surface (unusual): draw its arc alone */
            enum { NA = 40 };
            prim *q = add(d, 0, 0x335577);
            q->pts = malloc(NA * 2 * sizeof(double));
            for (int j = 0; j < NA; j++) {
                double y = -s->aperture_radius_mm + 2.0 * s->aperture_radius_mm * j / (NA - 1);
                q->pts[2 * j] = vx(&v, surface_z(s, zv, y)), q->pts[2 * j + 1] = vy(&v, y);
            }
            q->n = NA;
        }
    }
    line(d, vx(&v, 0), vy(&v, 0.5 * an->diagonal), vx(&v, 0), vy(&v, -0.5 * an->diagonal), 0x000000, 2, 0);
    double half_fov = 0.5 * an->fov_traced[2] * M_PI / 180.0 * 0.98;
    double fields[3] = {0.0, 0.7 * half_fov, half_fov};
    for (int f = 0; f < 3; f++) {
        double a0, a1, b0, b1;
        if (beam_extent(L, fields[f], &a0, &a1, &b0, &b1))
            continue;
        double w = b1 - b0;
        fan_draw fd = {d, &v, z0 + 0.05 * length, ymax, fan_colors[f]};
        collimated_beam(L, fields[f], 0, 0, 1, b0 + 0.04 * w, b1 - 0.04 * w, 11, draw_fan_ray, &fd);
    }
    snprintf(buf, sizeof buf, "%s  EFL %.2f mm  f/%.2f  stop %.3g mm  film %.3f mm behind the rear vertex",
             L->path, an->px.efl_mm, an->px.fnumber, 2.0 * L->s[an->px.stop].aperture_radius_mm,
             L->film_distance_mm);
    text(d, px0 + 8, py0 + 16, buf);
    snprintf(buf, sizeof buf, "ray fans: blue on axis, red %.1f deg, green %.1f deg (traced from the scene)",
             fields[1] * 180 / M_PI, fields[2] * 180 / M_PI);
    text(d, px0 + 8, py0 + 32, buf);
    /* --- panel 2: spot diagrams at 0, 0.5, 0.7, 1.0 of the half field --- */
    double sx0 = 20, sy0 = 480, sx1 = 490, sy1 = 740;
    frame(d, sx0, sy0, sx1, sy1);
    double sf[4] = {0.0, 0.5, 0.7, 1.0};
    spot_acc spots[4];
    double extent = 1e-3;
    for (int k = 0; k < 4; k++) {
        memset(&spots[k], 0, sizeof spots[k]);
        double a0, a1, b0, b1;
        if (beam_extent(L, sf[k] * half_fov, &a0, &a1, &b0, &b1) == 0)
            collimated_beam(L, sf[k] * half_fov, a0, a1, 61, b0, b1, 61, collect_spot, &spots[k]);
        double cx = 0, cy = 0;
        for (int i = 0; i < spots[k].n; i++)
            cx += spots[k].x[i], cy += spots[k].y[i];
        if (spots[k].n)
            cx /= spots[k].n, cy /= spots[k].n;
        for (int i = 0; i < spots[k].n; i++) {
            spots[k].x[i] -= cx, spots[k].y[i] -= cy;
            extent = fmax(extent, fmax(fabs(spots[k].x[i]), fabs(spots[k].y[i])));
        }
    }
    double cell = (sx1 - sx0 - 50) / 4.0;
    for (int k = 0; k < 4; k++) {
        double cx = sx0 + 25 + cell * (k + 0.5), cy = 0.5 * (sy0 + sy1) + 5;
        double sc = 0.45 * cell / extent;
        frame(d, cx - 0.47 * cell, cy - 0.47 * cell, cx + 0.47 * cell, cy + 0.47 * cell);
        double rms = 0;
        for (int i = 0; i < spots[k].n; i++) {
            dot(d, cx + sc * spots[k].x[i], cy - sc * spots[k].y[i], fan_colors[k < 3 ? k : 2]);
            rms += spots[k].x[i] * spots[k].x[i] + spots[k].y[i] * spots[k].y[i];
        }
        rms = spots[k].n ? sqrt(rms / spots[k].n) : 0;
        snprintf(buf, sizeof buf, "%.1f deg", sf[k] * half_fov * 180 / M_PI);
        text(d, cx - 0.45 * cell, cy - 0.5 * cell - 4, buf);
        snprintf(buf, sizeof buf, "rms %.0f um", rms * 1000);
        text(d, cx - 0.45 * cell, cy + 0.5 * cell + 14, buf);
        free(spots[k].x);
        free(spots[k].y);
    }
    snprintf(buf, sizeof buf, "spot diagrams (film at the focus above), box = %.0f um", 2 * extent / 0.45 * 0.47 * 1000);
    text(d, sx0 + 8, sy0 + 16, buf);
    /* --- panel 3: distortion vs field angle --- */
    double dx0 = 510, dy0 = 480, dx1 = 980, dy1 = 740;
    frame(d, dx0, dy0, dx1, dy1);
    enum { ND = 60 };
    double th[ND], dist[ND];
    int nd = 0;
    double dmax = 1.0;
    lf_lens Linf = *L;
    Linf.film_distance_mm = an->px.bfl_mm; /* distortion of the image of infinity */
    for (int i = 1; i <= ND; i++) {
        double r = an->image_circle_r * i / ND, t;
        if (lf_lens_field_angle(&Linf, r, &t) || t > 89.0 * M_PI / 180.0 || t <= 0)
            continue;
        th[nd] = t * 180 / M_PI;
        dist[nd] = 100.0 * (r / (an->px.efl_mm * tan(t)) - 1.0);
        dmax = fmax(dmax, fabs(dist[nd]));
        nd++;
    }
    double thmax = nd ? th[nd - 1] : 1;
    double gx0 = dx0 + 40, gx1 = dx1 - 15, gy0 = dy0 + 30, gy1 = dy1 - 25;
    line(d, gx0, 0.5 * (gy0 + gy1), gx1, 0.5 * (gy0 + gy1), 0xaaaaaa, 0.8, 1);
    line(d, gx0, gy0, gx0, gy1, 0x666666, 1, 0);
    if (nd > 1) {
        prim *q = add(d, 0, 0x8e44ad);
        q->pts = malloc((size_t)nd * 2 * sizeof(double));
        for (int i = 0; i < nd; i++) {
            q->pts[2 * i] = gx0 + (gx1 - gx0) * th[i] / thmax;
            q->pts[2 * i + 1] = 0.5 * (gy0 + gy1) - 0.5 * (gy1 - gy0) * dist[i] / dmax;
        }
        q->n = nd, q->width = 1.8;
    }
    snprintf(buf, sizeof buf, "distortion vs f tan(theta): +-%.3g%% full scale, 0..%.1f deg", dmax, thmax);
    text(d, dx0 + 8, dy0 + 16, buf);
}

static int write_svg(const drawing *d, const char *path)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "lflens: cannot write %s: %s\n", tmp, strerror(errno));
        return 1;
    }
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n", d->w,
            d->h, d->w, d->h);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"#ffffff\"/>\n");
    for (int i = 0; i < d->n; i++) {
        const prim *q = &d->p[i];
        if (q->kind == 2) {
            fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"0.8\" fill=\"#%06x\"/>\n", q->pts[0], q->pts[1], q->color);
        } else if (q->kind == 3) {
            fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" font-size=\"12\" fill=\"#333\">",
                    q->pts[0], q->pts[1]);
            for (const char *c = q->text; *c; c++)
                if (*c == '<')
                    fputs("&lt;", f);
                else if (*c == '&')
                    fputs("&amp;", f);
                else
                    fputc(*c, f);
            fputs("</text>\n", f);
        } else {
            fprintf(f, "<%s points=\"", q->kind == 1 ? "polygon" : "polyline");
            for (int j = 0; j < q->n; j++)
                fprintf(f, "%.2f,%.2f ", q->pts[2 * j], q->pts[2 * j + 1]);
            fprintf(f, "\" fill=\"");
            if (q->kind == 1)
                fprintf(f, "#%06x", q->fill);
            else
                fputs("none", f);
            fprintf(f, "\" stroke=\"#%06x\" stroke-width=\"%.2f\"%s/>\n", q->color, q->width,
                    q->dashed ? " stroke-dasharray=\"6,4\"" : "");
        }
    }
    fputs("</svg>\n", f);
    if (fclose(f) || rename(tmp, path)) {
        fprintf(stderr, "lflens: cannot write %s: %s\n", path, strerror(errno));
        unlink(tmp);
        return 1;
    }
    return 0;
}

static void put(lf_image *img, int x, int y, unsigned c)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height)
        return;
    float *p = lf_image_px(img, x, y);
    p[0] = lf_srgb_decode((unsigned char)(c >> 16)), p[1] = lf_srgb_decode((unsigned char)(c >> 8 & 255)),
    p[2] = lf_srgb_decode((unsigned char)(c & 255));
}

static void raster_line(lf_image *img, double x0, double y0, double x1, double y1, unsigned c, int dashed)
{
    double len = fmax(fabs(x1 - x0), fabs(y1 - y0));
    int n = (int)ceil(len) + 1;
    for (int i = 0; i <= n; i++) {
        double t = (double)i / n;
        if (dashed && ((int)(t * len) / 5) % 2)
            continue;
        put(img, (int)floor(x0 + t * (x1 - x0)), (int)floor(y0 + t * (y1 - y0)), c);
    }
}

static int write_png(const drawing *d, const char *path)
{
    lf_image img;
    lf_error err = {0};
    if (lf_image_alloc(&img, d->w, d->h, 3, &err)) {
        fprintf(stderr, "lflens: %s\n", err.msg);
        return 1;
    }
    for (size_t i = 0; i < (size_t)d->w * d->h * 3; i++)
        img.data[i] = 1.0f;
    for (int i = 0; i < d->n; i++) {
        const prim *q = &d->p[i];
        if (q->kind == 2) {
            put(&img, (int)q->pts[0], (int)q->pts[1], q->color);
        } else if (q->kind == 0 || q->kind == 1) {
            for (int j = 0; j + 1 < q->n; j++)
                raster_line(&img, q->pts[2 * j], q->pts[2 * j + 1], q->pts[2 * j + 2], q->pts[2 * j + 3], q->color,
                            q->dashed);
            if (q->kind == 1 && q->n > 2)
                raster_line(&img, q->pts[2 * q->n - 2], q->pts[2 * q->n - 1], q->pts[0], q->pts[1], q->color, 0);
        }
    }
    int rc = lf_image_write(path, &img, NULL, NULL, &err);
    lf_image_free(&img);
    if (rc) {
        fprintf(stderr, "lflens: %s\n", err.msg);
        return 1;
    }
    return 0;
}

static int cmd_plot(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, 1, &o);
    if (rc)
        return rc;
    analysis an;
    if (analyse(&o, &an)) {
        lf_lens_free(&an.lens);
        return 1;
    }
    drawing d = {0};
    build_drawing(&an, &d);
    const char *dot = strrchr(o.out_path, '.');
    rc = !strcmp(dot, ".svg") ? write_svg(&d, o.out_path) : write_png(&d, o.out_path);
    for (int i = 0; i < d.n; i++)
        free(d.p[i].pts);
    free(d.p);
    lf_lens_free(&an.lens);
    return rc;
}

static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
} commands[] = {{"info", cmd_info}, {"plot", cmd_plot}};

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        usage(stdout);
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(argv[1], commands[i].name))
            return commands[i].run(argc, argv);
    fprintf(stderr, "lflens: unknown command \"%s\"\n", argv[1]);
    usage(stderr);
    return 2;
}
