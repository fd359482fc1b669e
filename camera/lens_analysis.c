/* Whole-lens analysis for lflens and the docs (lens_analysis.h): the
 * report, collimated beams, spot diagrams and distortion.  Everything here
 * is built from lens.h's exact tracer and paraxial analysis. */
#include "lens_analysis.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_buf.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

int lf_lens_report_compute(lf_lens *L, double sensor_w, double sensor_h, double focus_m, lf_lens_report *r,
                           lf_error *err)
{
    memset(r, 0, sizeof *r);
    if (lf_lens_paraxial_analyse(L, &r->px))
        return lf_error_set(err, LF_ERR_PARAM, "%s: the lens has no focal power (afocal)", L->path);
    r->sensor_w_mm = sensor_w;
    r->sensor_h_mm = sensor_h;
    r->diagonal_mm = hypot(sensor_w, sensor_h);
    r->focus_m = focus_m;
    double D = isinf(focus_m) ? INFINITY : focus_m * 1000.0;
    int rc = lf_lens_focus_thick(L, D, &r->film_thick_mm, err);
    if (rc)
        return rc;
    if (lf_lens_focus_search(L, D, &r->film_search_mm, NULL))
        r->film_search_mm = NAN;
    r->closest_focus_m = lf_lens_closest_focus_mm(&r->px) * 1e-3;
    L->film_distance_mm = r->film_thick_mm;
    r->working_fnumber = lf_lens_working_fnumber(L, &r->px, D, r->film_thick_mm);
    double half[3] = {0.5 * sensor_w, 0.5 * sensor_h, 0.5 * r->diagonal_mm};
    r->image_circle_radius_mm = lf_lens_image_circle_radius(L, half[2]);
    if (r->image_circle_radius_mm <= 0.0)
        return lf_error_set(err, LF_ERR_PARAM, "%s admits no light: no ray from the film centre gets through",
                            L->path);
    for (int k = 0; k < 3; k++) {
        r->fov_paraxial_deg[k] = 2.0 * atan(half[k] / r->px.efl_mm) * 180.0 / M_PI;
        double rr = half[k] < r->image_circle_radius_mm ? half[k] : r->image_circle_radius_mm, th = 0;
        if (lf_lens_field_angle(L, rr, &th) == 0)
            r->fov_traced_deg[k] = 2.0 * th * 180.0 / M_PI;
    }
    return LF_OK;
}

/* Half-width of the region a beam is scanned over: beyond every element. */
static double beam_rho(const lf_lens *L)
{
    double rho = 0.0;
    for (int i = 0; i < L->n; i++)
        if (L->s[i].aperture_radius_mm > rho)
            rho = L->s[i].aperture_radius_mm;
    return 1.6 * rho;
}

int lf_lens_collimated_beam(const lf_lens *L, double theta, double a0, double a1, int na, double b0, double b1,
                            int nb, lf_lens_beam_fn fn, void *ctx)
{
    double zf = L->s[0].z_mm - L->film_distance_mm;
    double d[3] = {0, sin(theta), cos(theta)}, e2[3] = {0, cos(theta), -sin(theta)};
    double back = 3.0 * beam_rho(L) + lf_lens_total_length_mm(L);
    double(*path)[3] = malloc((size_t)(L->n + 1) * sizeof *path);
    if (!path)
        return -1;
    int passed = 0;
    for (int j = 0; j < nb; j++)
        for (int i = 0; i < na; i++) {
            double a = na > 1 ? a0 + (a1 - a0) * i / (na - 1) : 0.5 * (a0 + a1);
            double b = nb > 1 ? b0 + (b1 - b0) * j / (nb - 1) : 0.5 * (b0 + b1);
            lf_lens_ray in, out;
            for (int k = 0; k < 3; k++) {
                in.o[k] = (k == 2 ? zf : 0.0) - back * d[k] + b * e2[k] + (k == 0 ? a : 0.0);
                in.d[k] = d[k];
            }
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
    /* the grid coordinate, recovered from the start point */
    double v = e->sagittal ? in->o[0] : in->o[1] * cos(e->theta) - in->o[2] * sin(e->theta);
    if (v < e->lo)
        e->lo = v;
    if (v > e->hi)
        e->hi = v;
}

int lf_lens_beam_extent(const lf_lens *L, double theta, double ext[4])
{
    double rho = beam_rho(L), zf = L->s[0].z_mm - L->film_distance_mm;
    double bias = -zf * sin(theta); /* b = o_y cos - o_z sin - bias */
    extent_acc e = {INFINITY, -INFINITY, theta, 0};
    if (lf_lens_collimated_beam(L, theta, 0, 0, 1, -rho, rho, 801, grow_extent, &e) <= 0)
        return -1;
    double step = 2.0 * rho / 800;
    ext[2] = e.lo - bias - step;
    ext[3] = e.hi - bias + step;
    double mid = 0.5 * (ext[2] + ext[3]);
    extent_acc s = {INFINITY, -INFINITY, theta, 1};
    if (lf_lens_collimated_beam(L, theta, -rho, rho, 801, mid, mid, 1, grow_extent, &s) < 0)
        return -1;
    if (!(s.hi >= s.lo))
        s.lo = -rho, s.hi = rho;
    ext[0] = s.lo - step;
    ext[1] = s.hi + step;
    return 0;
}

typedef struct spot_acc {
    double *x, *y;
    size_t n, cap_x, cap_y;
    int failed;
} spot_acc;

static void collect_spot(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out)
{
    (void)in, (void)path, (void)n;
    spot_acc *s = ctx;
    if (s->failed || lf_array_reserve((void **)&s->x, &s->cap_x, s->n + 1, sizeof *s->x) ||
        lf_array_reserve((void **)&s->y, &s->cap_y, s->n + 1, sizeof *s->y)) {
        s->failed = 1;
        return;
    }
    double t = -out->o[2] / out->d[2]; /* to the film plane z = 0 */
    s->x[s->n] = out->o[0] + t * out->d[0];
    s->y[s->n] = out->o[1] + t * out->d[1];
    s->n++;
}

int lf_lens_spot_diagram(const lf_lens *L, double theta, int grid, lf_lens_spot *spot, lf_error *err)
{
    memset(spot, 0, sizeof *spot);
    spot->field_rad = theta;
    double ext[4];
    if (lf_lens_beam_extent(L, theta, ext))
        return LF_OK; /* no light at this field: an empty diagram */
    spot_acc acc = {0};
    if (lf_lens_collimated_beam(L, theta, ext[0], ext[1], grid, ext[2], ext[3], grid, collect_spot, &acc) < 0 ||
        acc.failed) {
        free(acc.x);
        free(acc.y);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory tracing the spot diagram of %s", L->path);
    }
    double cx = 0, cy = 0, ss = 0;
    for (size_t i = 0; i < acc.n; i++)
        cx += acc.x[i], cy += acc.y[i];
    if (acc.n)
        cx /= (double)acc.n, cy /= (double)acc.n;
    for (size_t i = 0; i < acc.n; i++) {
        acc.x[i] -= cx, acc.y[i] -= cy;
        ss += acc.x[i] * acc.x[i] + acc.y[i] * acc.y[i];
    }
    spot->x = acc.x;
    spot->y = acc.y;
    spot->n = (int)acc.n;
    spot->cx = cx;
    spot->cy = cy;
    spot->rms_mm = acc.n ? sqrt(ss / (double)acc.n) : 0.0;
    return LF_OK;
}

void lf_lens_spot_free(lf_lens_spot *spot)
{
    free(spot->x);
    free(spot->y);
    memset(spot, 0, sizeof *spot);
}

int lf_lens_distortion_curve(const lf_lens *L, const lf_lens_paraxial *px, double image_circle_mm, int n,
                             double *theta_deg, double *percent)
{
    lf_lens at_infinity = *L;
    at_infinity.film_distance_mm = px->bfl_mm;
    int count = 0;
    for (int i = 1; i <= n; i++) {
        double r = image_circle_mm * i / n, t;
        if (lf_lens_chief_ray_angle(&at_infinity, r, &t) || t > 89.0 * M_PI / 180.0 || t <= 0)
            continue;
        theta_deg[count] = t * 180 / M_PI;
        percent[count] = 100.0 * (r / (px->efl_mm * tan(t)) - 1.0);
        count++;
    }
    return count;
}
