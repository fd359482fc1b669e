/* The lflens drawing (lens_analysis.h): cross-section with traced ray fans,
 * spot diagrams and distortion, as vector primitives (base/lf_plot.h: SVG
 * there, pixels with text in image/). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_buf.h"
#include "lens_analysis.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* A new primitive with room for n points, or NULL (plot->failed set). */
static lf_plot_prim *add(lf_plot *d, lf_plot_kind kind, unsigned color, int n)
{
    if (d->failed || lf_array_reserve((void **)&d->p, &d->cap, d->n + 1, sizeof *d->p)) {
        d->failed = 1;
        return NULL;
    }
    lf_plot_prim *q = &d->p[d->n];
    memset(q, 0, sizeof *q);
    q->pts = calloc((size_t)(n > 0 ? n : 1) * 2, sizeof(double));
    if (!q->pts) {
        d->failed = 1;
        return NULL;
    }
    d->n++;
    q->kind = kind, q->color = color, q->width = 1.0, q->n = n;
    return q;
}

static void line(lf_plot *d, double x0, double y0, double x1, double y1, unsigned color, double width, int dashed)
{
    lf_plot_prim *q = add(d, LF_PLOT_POLYLINE, color, 2);
    if (!q)
        return;
    q->pts[0] = x0, q->pts[1] = y0, q->pts[2] = x1, q->pts[3] = y1;
    q->width = width, q->dashed = dashed;
}

static void text(lf_plot *d, double x, double y, const char *s)
{
    lf_plot_prim *q = add(d, LF_PLOT_TEXT, 0x333333, 1);
    if (!q)
        return;
    q->pts[0] = x, q->pts[1] = y;
    q->text = strdup(s);
    if (!q->text)
        d->failed = 1;
}

static void frame(lf_plot *d, double x0, double y0, double x1, double y1)
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

/* The sag of a surface at height y, as a z position. */
static double surface_z(const lf_lens_surface *s, double zv, double y)
{
    if (s->radius_mm == 0.0)
        return zv;
    double R = s->radius_mm, q = R * R - y * y;
    return zv + R - (R > 0 ? 1.0 : -1.0) * sqrt(q > 0 ? q : 0);
}

static const unsigned fan_colors[3] = {0x1f5fbf, 0xc0392b, 0x27ae60};

typedef struct fan_draw {
    lf_plot *d;
    const view *v;
    double z_start, ymax;
    unsigned color;
} fan_draw;

static void draw_fan_ray(void *ctx, const lf_lens_ray *in, const double (*path)[3], int n, const lf_lens_ray *out)
{
    fan_draw *f = ctx;
    lf_plot_prim *q = add(f->d, LF_PLOT_POLYLINE, f->color, n + 2);
    if (!q)
        return;
    double t = (f->z_start - in->o[2]) / in->d[2];
    if (fabs(in->o[1] + t * in->d[1]) > f->ymax && in->d[1] != 0.0) /* keep the start inside the panel */
        t = ((in->d[1] > 0 ? -f->ymax : f->ymax) - in->o[1]) / in->d[1];
    q->pts[0] = vx(f->v, f->z_start), q->pts[1] = vy(f->v, in->o[1] + t * in->d[1]);
    for (int i = 0; i < n; i++)
        q->pts[2 + 2 * i] = vx(f->v, path[i][2]), q->pts[3 + 2 * i] = vy(f->v, path[i][1]);
    double tf = -out->o[2] / out->d[2];
    q->pts[2 + 2 * n] = vx(f->v, 0.0), q->pts[3 + 2 * n] = vy(f->v, out->o[1] + tf * out->d[1]);
    q->width = 0.7;
}

/* Panel 1: the elements, the stop, the film and three ray fans. */
static void draw_section(const lf_lens *L, const lf_lens_report *r, lf_plot *d, double half_fov)
{
    char buf[640];
    double px0 = 20, py0 = 20, px1 = 980, py1 = 460;
    frame(d, px0, py0, px1, py1);
    double zfront = L->s[0].z_mm - L->film_distance_mm, length = -zfront;
    double ymax = 0.5 * r->diagonal_mm;
    for (int i = 0; i < L->n; i++)
        ymax = fmax(ymax, L->s[i].aperture_radius_mm);
    ymax *= 1.15;
    double z0 = zfront - 0.25 * length, z1 = 0.04 * length;
    view v;
    v.sx = fmin((px1 - px0 - 20) / (z1 - z0), (py1 - py0 - 40) / (2.0 * ymax));
    v.ox = 0.5 * (px0 + px1) - v.sx * 0.5 * (z0 + z1);
    v.oy = 0.5 * (py0 + py1) + 10;
    line(d, vx(&v, z0), vy(&v, 0), vx(&v, z1), vy(&v, 0), 0xaaaaaa, 0.8, 1);
    enum { NA = 40 };
    for (int i = 0; i < L->n; i++) {
        const lf_lens_surface *s = &L->s[i];
        double zv = s->z_mm - L->film_distance_mm;
        if (s->radius_mm == 0.0) { /* the stop: two blades */
            double a = s->aperture_radius_mm, b = fmax(a * 1.35, a + 0.08 * ymax);
            line(d, vx(&v, zv), vy(&v, a), vx(&v, zv), vy(&v, b), 0x000000, 2.5, 0);
            line(d, vx(&v, zv), vy(&v, -a), vx(&v, zv), vy(&v, -b), 0x000000, 2.5, 0);
            continue;
        }
        if (s->ior > 1.0 && i + 1 < L->n) { /* glass from surface i to i + 1: its outline */
            const lf_lens_surface *t = &L->s[i + 1];
            double zt = t->z_mm - L->film_distance_mm;
            lf_plot_prim *q = add(d, LF_PLOT_POLYGON, 0x335577, 2 * NA + 4);
            if (!q)
                return;
            q->fill = 0xd6e6f5;
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
        } else if (!(i > 0 && L->s[i - 1].ior > 1.0)) { /* an air-air surface (unusual): its arc alone */
            lf_plot_prim *q = add(d, LF_PLOT_POLYLINE, 0x335577, NA);
            if (!q)
                return;
            for (int j = 0; j < NA; j++) {
                double y = -s->aperture_radius_mm + 2.0 * s->aperture_radius_mm * j / (NA - 1);
                q->pts[2 * j] = vx(&v, surface_z(s, zv, y)), q->pts[2 * j + 1] = vy(&v, y);
            }
        }
    }
    line(d, vx(&v, 0), vy(&v, 0.5 * r->diagonal_mm), vx(&v, 0), vy(&v, -0.5 * r->diagonal_mm), 0x000000, 2, 0);
    double fields[3] = {0.0, 0.7 * half_fov, half_fov};
    for (int f = 0; f < 3; f++) {
        double ext[4];
        if (lf_lens_beam_extent(L, fields[f], ext))
            continue;
        double w = ext[3] - ext[2];
        fan_draw fd = {d, &v, z0 + 0.05 * length, ymax, fan_colors[f]};
        if (lf_lens_collimated_beam(L, fields[f], 0, 0, 1, ext[2] + 0.04 * w, ext[3] - 0.04 * w, 11, draw_fan_ray,
                                    &fd) < 0)
            d->failed = 1;
    }
    snprintf(buf, sizeof buf, "%s  EFL %.2f mm  f/%.2f  stop %.3g mm  film %.3f mm behind the rear vertex", L->path,
             r->px.efl_mm, r->px.fnumber, 2.0 * L->s[r->px.stop].aperture_radius_mm, L->film_distance_mm);
    text(d, px0 + 8, py0 + 16, buf);
    snprintf(buf, sizeof buf, "ray fans: blue on axis, red %.1f deg, green %.1f deg (traced from the scene)",
             fields[1] * 180 / M_PI, fields[2] * 180 / M_PI);
    text(d, px0 + 8, py0 + 32, buf);
}

/* Panel 2: spot diagrams at 0, 0.5, 0.7 and 1 of the half field. */
static int draw_spots(const lf_lens *L, lf_plot *d, double half_fov, lf_error *err)
{
    char buf[640];
    double sx0 = 20, sy0 = 480, sx1 = 490, sy1 = 740;
    frame(d, sx0, sy0, sx1, sy1);
    const double sf[4] = {0.0, 0.5, 0.7, 1.0};
    lf_lens_spot spots[4];
    double extent = 1e-3;
    memset(spots, 0, sizeof spots);
    for (int k = 0; k < 4; k++) {
        if (lf_lens_spot_diagram(L, sf[k] * half_fov, 61, &spots[k], err)) {
            for (int j = 0; j < k; j++)
                lf_lens_spot_free(&spots[j]);
            return err ? err->code : LF_ERR_NOMEM;
        }
        for (int i = 0; i < spots[k].n; i++)
            extent = fmax(extent, fmax(fabs(spots[k].x[i]), fabs(spots[k].y[i])));
    }
    double cell = (sx1 - sx0 - 50) / 4.0;
    for (int k = 0; k < 4; k++) {
        double cx = sx0 + 25 + cell * (k + 0.5), cy = 0.5 * (sy0 + sy1) + 5;
        double sc = 0.45 * cell / extent;
        frame(d, cx - 0.47 * cell, cy - 0.47 * cell, cx + 0.47 * cell, cy + 0.47 * cell);
        for (int i = 0; i < spots[k].n; i++) {
            lf_plot_prim *q = add(d, LF_PLOT_DOT, fan_colors[k < 3 ? k : 2], 1);
            if (!q)
                break;
            q->pts[0] = cx + sc * spots[k].x[i], q->pts[1] = cy - sc * spots[k].y[i];
        }
        snprintf(buf, sizeof buf, "%.1f deg", sf[k] * half_fov * 180 / M_PI);
        text(d, cx - 0.45 * cell, cy - 0.5 * cell - 4, buf);
        snprintf(buf, sizeof buf, "rms %.0f um", spots[k].rms_mm * 1000);
        text(d, cx - 0.45 * cell, cy + 0.5 * cell + 14, buf);
        lf_lens_spot_free(&spots[k]);
    }
    snprintf(buf, sizeof buf, "spot diagrams (film at the focus above), box = %.0f um", 2 * extent / 0.45 * 0.47 * 1000);
    text(d, sx0 + 8, sy0 + 16, buf);
    return LF_OK;
}

/* Panel 3: distortion against field angle. */
static void draw_distortion(const lf_lens *L, const lf_lens_report *r, lf_plot *d)
{
    char buf[640];
    double dx0 = 510, dy0 = 480, dx1 = 980, dy1 = 740;
    frame(d, dx0, dy0, dx1, dy1);
    enum { ND = 60 };
    double th[ND], dist[ND], dmax = 1.0;
    int nd = lf_lens_distortion_curve(L, &r->px, r->image_circle_radius_mm, ND, th, dist);
    for (int i = 0; i < nd; i++)
        dmax = fmax(dmax, fabs(dist[i]));
    double thmax = nd ? th[nd - 1] : 1;
    double gx0 = dx0 + 40, gx1 = dx1 - 15, gy0 = dy0 + 30, gy1 = dy1 - 25;
    line(d, gx0, 0.5 * (gy0 + gy1), gx1, 0.5 * (gy0 + gy1), 0xaaaaaa, 0.8, 1);
    line(d, gx0, gy0, gx0, gy1, 0x666666, 1, 0);
    if (nd > 1) {
        lf_plot_prim *q = add(d, LF_PLOT_POLYLINE, 0x8e44ad, nd);
        if (q) {
            for (int i = 0; i < nd; i++) {
                q->pts[2 * i] = gx0 + (gx1 - gx0) * th[i] / thmax;
                q->pts[2 * i + 1] = 0.5 * (gy0 + gy1) - 0.5 * (gy1 - gy0) * dist[i] / dmax;
            }
            q->width = 1.8;
        }
    }
    snprintf(buf, sizeof buf, "distortion vs f tan(theta): +-%.3g%% full scale, 0..%.1f deg", dmax, thmax);
    text(d, dx0 + 8, dy0 + 16, buf);
}

int lf_lens_plot_build(const lf_lens *L, const lf_lens_report *r, lf_plot *d, lf_error *err)
{
    memset(d, 0, sizeof *d);
    d->w = 1000, d->h = 760;
    double half_fov = 0.5 * r->fov_traced_deg[2] * M_PI / 180.0 * 0.98;
    draw_section(L, r, d, half_fov);
    int rc = draw_spots(L, d, half_fov, err);
    if (rc)
        return rc;
    draw_distortion(L, r, d);
    if (d->failed)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory drawing %s", L->path);
    return LF_OK;
}
