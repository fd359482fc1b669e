/* Aperture (bokeh) shapes for the lens cameras: see aperture.h.
 *
 * Shapes live in units of the aperture radius.  Polygons and stars are fans
 * of equal-area triangles around the centre, so a uniform point is a uniform
 * triangle (chosen by the first sample dimension) and a uniform point in it
 * (sqrt warp along the radius, linear along the rim): exact, no rejection.
 * The circle uses pbrt's concentric mapping unchanged, so a circular
 * aperture on pbrt's perspective camera draws bit-identical lens points.
 * Image apertures are sampled proportionally to transmission from a
 * piecewise-constant 2D table, which makes every sample's weight exactly 1.
 */
#include "aperture.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera_internal.h"

/* Inner radius of the star with n points whose edges lie on the lines
 * joining every second outer vertex (the {n/2} star polygon: a pentagram for
 * n = 5, a hexagram for 6).  For n < 5 those lines do not make a star; use
 * half the outer radius. */
static double star_inner_radius(int n)
{
    return n >= 5 ? cos(2.0 * M_PI / n) / cos(M_PI / n) : 0.5;
}

static double polygon_area(int n)
{
    return 0.5 * n * sin(2.0 * M_PI / n);
}

static double star_area(int n)
{
    return n * star_inner_radius(n) * sin(M_PI / n);
}

/* The shape's kind, with the blade count and rotation it implies. */
static int parse_kind(const char *shape, lf_aperture *a, int *default_blades, double *base_rotation, lf_error *err)
{
    *default_blades = 6;
    *base_rotation = 0.0;
    if (!strcmp(shape, "circular") || !strcmp(shape, "circle")) {
        a->kind = LF_APERTURE_CIRCLE;
    } else if (!strcmp(shape, "polygon")) {
        a->kind = LF_APERTURE_POLYGON;
    } else if (!strcmp(shape, "square")) {
        a->kind = LF_APERTURE_POLYGON;
        *default_blades = 4;
        *base_rotation = M_PI / 4.0; /* sides horizontal and vertical */
    } else if (!strcmp(shape, "pentagon")) {
        a->kind = LF_APERTURE_POLYGON;
        *default_blades = 5;
    } else if (!strcmp(shape, "star")) {
        a->kind = LF_APERTURE_STAR;
        *default_blades = 5;
    } else if (shape[0] == '\0') {
        return lf_error_set(err, LF_ERR_PARAM,
                            "\"aperture\" is empty (want circular, polygon, square, pentagon, star or an image)");
    } else {
        a->kind = LF_APERTURE_IMAGE;
    }
    return LF_OK;
}

/* Polygons and stars: the area and the closed outline.  Polygons have their
 * corners on the unit circle; stars alternate outer and inner vertices. */
static int build_outline(lf_aperture *a, lf_error *err)
{
    int n = a->blades, star = a->kind == LF_APERTURE_STAR, m = star ? 2 * n : n;
    a->area = star ? star_area(n) : polygon_area(n);
    a->corners = malloc(sizeof *a->corners * (size_t)(m + 1));
    if (!a->corners)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    double ri = star_inner_radius(n);
    for (int k = 0; k <= m; k++) {
        double t = M_PI / 2.0 + a->rotation_rad + (star ? M_PI : 2.0 * M_PI) * (k % m) / n;
        double r = star && (k & 1) ? ri : 1.0;
        a->corners[k][0] = r * cos(t);
        a->corners[k][1] = r * sin(t);
    }
    return LF_OK;
}

/* An image aperture: the file's grey transmission, clamped to [0,1], and
 * the table that samples it. */
static int load_image(const lf_camera_params *p, const char *shape, lf_aperture *a, lf_error *err)
{
    char msg[512] = "";
    int w = 0, h = 0;
    float *px = NULL;
    if (p->load_image(p->ctx, shape, &w, &h, &px, msg, sizeof msg))
        return lf_error_set(err, LF_ERR_IO, "aperture image \"%s\": %s", shape, msg[0] ? msg : "cannot read it");
    if (w <= 0 || h <= 0 || !px) {
        free(px);
        return lf_error_set(err, LF_ERR_PARAM, "aperture image \"%s\" is empty", shape);
    }
    size_t n = (size_t)w * h;
    double *f = malloc(sizeof(double) * n);
    if (!f) {
        free(px);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for aperture image \"%s\"", shape);
    }
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        /* transmission is a fraction: NaN/negative -> 0, above 1 -> 1 */
        float t = px[i];
        t = t > 0.f ? (t < 1.f ? t : 1.f) : 0.f;
        px[i] = t;
        f[i] = t;
        sum += t;
    }
    if (!(sum > 0)) {
        free(f);
        free(px);
        return lf_error_set(err, LF_ERR_PARAM,
                            "aperture image \"%s\" is all black: it lets no light through (white = open, black = "
                            "closed)",
                            shape);
    }
    lf_error e = {0};
    if (lf_distrib2d_init(&a->distrib, f, w, h, &e)) {
        free(f);
        free(px);
        return lf_error_set(err, e.code, "aperture image \"%s\": %s", shape, e.msg);
    }
    free(f);
    a->img = px;
    a->img_w = w;
    a->img_h = h;
    a->area = 4.0 * sum / (double)n; /* the image fills [-1,1]^2 */
    return LF_OK;
}

int lf_aperture_parse(const lf_camera_params *p, lf_aperture *a, lf_error *err)
{
    memset(a, 0, sizeof *a);
    const char *shape = p->get_string(p->ctx, "aperture", "circular");
    int default_blades;
    double base_rotation;
    int rc = parse_kind(shape, a, &default_blades, &base_rotation, err);
    if (rc)
        return rc;
    a->blades = p->get_int(p->ctx, "blades", default_blades);
    double rot_deg = p->get_float(p->ctx, "aperturerotation", 0.0);
    a->anamorphic = p->get_float(p->ctx, "anamorphic", 1.0);
    if ((a->kind == LF_APERTURE_POLYGON || a->kind == LF_APERTURE_STAR) && (a->blades < 3 || a->blades > 1000))
        return lf_error_set(err, LF_ERR_PARAM, "\"blades\" must be in 3..1000, got %d", a->blades);
    if (!isfinite(rot_deg))
        return lf_error_set(err, LF_ERR_PARAM, "\"aperturerotation\" must be finite");
    if (!(a->anamorphic > 0.0) || !isfinite(a->anamorphic))
        return lf_error_set(err, LF_ERR_PARAM, "\"anamorphic\" must be positive, got %g", a->anamorphic);
    a->rotation_rad = base_rotation + rot_deg * M_PI / 180.0;
    switch (a->kind) {
    case LF_APERTURE_CIRCLE:
        a->area = M_PI;
        break;
    case LF_APERTURE_POLYGON:
    case LF_APERTURE_STAR:
        rc = build_outline(a, err);
        break;
    case LF_APERTURE_IMAGE:
        rc = load_image(p, shape, a, err);
        break;
    }
    if (rc)
        return rc;
    a->area *= a->anamorphic;
    return LF_OK;
}

/* Uniform point in the triangle (0, p, q): s = sqrt(u) along the radius,
 * v along the edge p -> q. */
static void fan_triangle(double u, double v, double px, double py, double qx, double qy, double *x, double *y)
{
    double s = sqrt(u);
    *x = s * ((1.0 - v) * px + v * qx);
    *y = s * ((1.0 - v) * py + v * qy);
}

/* Picks triangle k of m equal ones with the first dimension and rescales it. */
static int pick(double u, int m, double *u_rest)
{
    double t = u * m;
    int k = (int)t;
    if (k >= m)
        k = m - 1;
    if (k < 0)
        k = 0;
    *u_rest = fmin(fmax(t - k, 0.0), 1.0);
    return k;
}

double lf_aperture_sample(const lf_aperture *a, double u, double v, double *x, double *y)
{
    double px, py;
    switch (a->kind) {
    case LF_APERTURE_CIRCLE:
        /* rotation is meaningless for a circle; skipping it keeps pbrt's lens points */
        lf_concentric_disk(u, v, &px, &py);
        *x = px * a->anamorphic;
        *y = py;
        return 1.0;
    case LF_APERTURE_POLYGON: {
        double ur;
        int k = pick(u, a->blades, &ur);
        /* the rotation is in the corners: no rotation step */
        fan_triangle(ur, v, a->corners[k][0], a->corners[k][1], a->corners[k + 1][0], a->corners[k + 1][1], x, y);
        *x *= a->anamorphic;
        return 1.0;
    }
    case LF_APERTURE_STAR: {
        double ur;
        int k = pick(u, 2 * a->blades, &ur);
        /* triangles alternate outer -> inner and inner -> next outer vertex */
        fan_triangle(ur, v, a->corners[k][0], a->corners[k][1], a->corners[k + 1][0], a->corners[k + 1][1], x, y);
        *x *= a->anamorphic;
        return 1.0;
    }
    case LF_APERTURE_IMAGE: {
        double iu, iv, pdf;
        lf_distrib2d_sample(&a->distrib, u, v, &iu, &iv, &pdf);
        if (!(pdf > 0))
            return 0.0;
        px = 2.0 * iu - 1.0;
        py = 1.0 - 2.0 * iv; /* row 0 is the top of the image */
        break;
    }
    default:
        return 0.0;
    }
    if (a->rotation_rad != 0.0) {
        double c = cos(a->rotation_rad), s = sin(a->rotation_rad);
        double rx = c * px - s * py, ry = s * px + c * py;
        px = rx, py = ry;
    }
    *x = px * a->anamorphic;
    *y = py;
    return 1.0;
}

double lf_aperture_transmission(const lf_aperture *a, double x, double y)
{
    x /= a->anamorphic;
    if (a->kind != LF_APERTURE_CIRCLE && a->rotation_rad != 0.0) {
        double c = cos(a->rotation_rad), s = sin(a->rotation_rad);
        double rx = c * x + s * y, ry = -s * x + c * y;
        x = rx, y = ry;
    }
    switch (a->kind) {
    case LF_APERTURE_CIRCLE:
        return x * x + y * y <= 1.0 ? 1.0 : 0.0;
    case LF_APERTURE_POLYGON:
    case LF_APERTURE_STAR: {
        int n = a->blades;
        double r = hypot(x, y);
        if (r == 0.0)
            return 1.0;
        if (r > 1.0)
            return 0.0;
        /* angle from the nearest corner (corner 0 points along +y), folded
         * into [0, pi/n] by the shape's mirror symmetry */
        double sector = 2.0 * M_PI / n;
        double phi = atan2(y, x) - M_PI / 2.0;
        phi = fmod(phi, sector);
        if (phi < 0)
            phi += sector;
        if (phi > sector / 2.0)
            phi = sector - phi;
        double qx = r * cos(phi), qy = r * sin(phi); /* corner at (1, 0) */
        /* inside iff on the origin's side of the edge from (1,0) to the
         * next vertex: the mid-edge point for polygons, the inner vertex for stars */
        double ex, ey;
        if (a->kind == LF_APERTURE_POLYGON) {
            ex = cos(sector), ey = sin(sector); /* next corner: edge (1,0)->(ex,ey) */
        } else {
            double ri = star_inner_radius(n);
            ex = ri * cos(M_PI / n), ey = ri * sin(M_PI / n);
        }
        /* sign of cross(e - c, q - c), c = (1, 0); for q = origin it is ey > 0 */
        double side_q = (ex - 1.0) * qy - ey * (qx - 1.0);
        return side_q >= 0.0 ? 1.0 : 0.0;
    }
    case LF_APERTURE_IMAGE: {
        if (x < -1.0 || x >= 1.0 || y <= -1.0 || y > 1.0)
            return 0.0;
        int ix = (int)((x + 1.0) * 0.5 * a->img_w), iy = (int)((1.0 - y) * 0.5 * a->img_h);
        if (ix >= a->img_w)
            ix = a->img_w - 1;
        if (iy >= a->img_h)
            iy = a->img_h - 1;
        if (ix < 0)
            ix = 0;
        if (iy < 0)
            iy = 0;
        return a->img[(size_t)iy * a->img_w + ix];
    }
    }
    return 0.0;
}

double lf_aperture_area(const lf_aperture *a)
{
    return a->area;
}

void lf_aperture_free(lf_aperture *a)
{
    if (!a)
        return;
    if (a->kind == LF_APERTURE_IMAGE) {
        lf_distrib2d_free(&a->distrib);
        free(a->img);
    }
    free(a->corners);
    a->corners = NULL;
    a->img = NULL;
}

const char *lf_aperture_name(const lf_aperture *a)
{
    switch (a->kind) {
    case LF_APERTURE_CIRCLE:
        return "circular";
    case LF_APERTURE_POLYGON:
        return "polygon";
    case LF_APERTURE_STAR:
        return "star";
    case LF_APERTURE_IMAGE:
        return "image";
    }
    return "?";
}
