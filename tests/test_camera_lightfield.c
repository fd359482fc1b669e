/* Light-field cameras without the renderer: the camera-array layout of
 * "lightfield" (CS348B) and the microlens geometry and radiometry of
 * "plenoptic" (Ng 2005).  Expected numbers come from the thin-lens and
 * pinhole formulas of docs/physics.md and the layout of
 * docs/lightfield-format.md, computed here; Monte Carlo estimates use fixed
 * stratified samples, so they are deterministic. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lens.h"
#include "camera/lf_camera.h"
#include "lf_test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "tests/camera_store.h"

static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images in this test (%s)", path);
    return -1;
}

static char last_warning[1024];

static void *make(const char *type, store *s, int w, int h, char *err)
{
    lf_camera_params p = {s, g_float, g_int, g_bool, g_string, g_floats, g_image};
    last_warning[0] = '\0';
    lf_camera_create_args a = {sizeof a, &p, w, h, 35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes", err, 512,
                               last_warning, sizeof last_warning};
    void *state = NULL;
    const lf_camera_type *t = lf_camera_find(type);
    if (!t || t->create(&a, &state))
        return NULL;
    return state;
}

/* ---- a metadata sink that keeps what the camera writes ---- */
typedef struct attr {
    char name[64];
    char str[64];
    double v[8];
    int n;
} attr;
typedef struct attrs {
    attr a[40];
    int n;
} attrs;

static attr *attr_new(attrs *s, const char *name)
{
    attr *a = &s->a[s->n < 40 ? s->n++ : 39];
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%s", name);
    return a;
}
static void s_string(void *ctx, const char *name, const char *value)
{
    snprintf(attr_new(ctx, name)->str, 64, "%s", value);
}
static void s_int(void *ctx, const char *name, int value)
{
    attr *a = attr_new(ctx, name);
    a->v[0] = value, a->n = 1;
}
static void s_double(void *ctx, const char *name, double value)
{
    attr *a = attr_new(ctx, name);
    a->v[0] = value, a->n = 1;
}
static void s_doubles(void *ctx, const char *name, const double *v, int n)
{
    attr *a = attr_new(ctx, name);
    for (int i = 0; i < n && i < 8; i++)
        a->v[i] = v[i];
    a->n = n;
}
static const attr *get(const attrs *s, const char *name)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->a[i].name, name))
            return &s->a[i];
    return NULL;
}
static void collect(const char *type, const void *cam, attrs *out)
{
    memset(out, 0, sizeof *out);
    lf_camera_attr_sink sink = {out, s_string, s_int, s_double, s_doubles};
    lf_camera_find(type)->metadata(cam, &sink);
}

/* ======================= camera array ======================= */

static void test_array_layout(void)
{
    /* 3 x 2 cameras on [-1, 1] x [-0.5, 0.5], 90 x 40 film: 30 x 20 tiles */
    store s = {{{"fov", {40}, 1, NULL},
                {"camerasperdim", {3, 2}, 2, NULL},
                {"cameragridbounds", {-1, 1, -0.5, 0.5}, 4, NULL}},
               3};
    char err[512] = "";
    void *c = make("lightfield", &s, 90, 40, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    const lf_camera_type *t = lf_camera_find("lightfield");
    CHECK(t->needs(c) == 0);
    const double th = tan(20 * M_PI / 180), tw = 30, tht = 20;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 3; i++) {
            const double lp[][2] = {{0.25, 0.5}, {15, 10}, {29.75, 19.5}, {3.3, 17.1}};
            for (int k = 0; k < 4; k++) {
                lf_camera_sample cs = {i * tw + lp[k][0], j * tht + lp[k][1], 0.5, 0.5, 0, 0.5};
                lf_camera_ray r;
                double w = t->generate_ray(c, &cs, &r);
                CHECK(w == 1.0);
                /* x_i = minx + i (maxx - minx)/(nx - 1); row j from the top */
                CHECK_NEAR(r.origin[0], -1.0 + i * 1.0, 1e-15);
                CHECK_NEAR(r.origin[1], 0.5 - j * 1.0, 1e-15);
                CHECK(r.origin[2] == 0.0);
                /* pbrt perspective for a 30 x 20 film (wide: fov spans y) */
                double ex = (2 * lp[k][0] / tht - tw / tht) * th, ey = (1 - 2 * lp[k][1] / tht) * th;
                CHECK_NEAR(r.dir[0] / r.dir[2], ex, 1e-12);
                CHECK_NEAR(r.dir[1] / r.dir[2], ey, 1e-12);
                CHECK_NEAR(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2], 1.0, 1e-12);
            }
        }
    /* the top-left camera (seen from behind: -x, +y) is in the top-left tile */
    lf_camera_sample tl = {1, 1, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r;
    t->generate_ray(c, &tl, &r);
    CHECK(r.origin[0] < 0 && r.origin[1] > 0);

    attrs m;
    collect("lightfield", c, &m);
    const attr *a = get(&m, "lensfield:kind");
    CHECK(a && !strcmp(a->str, "camera-array"));
    a = get(&m, "lensfield:cameras_per_dim");
    CHECK(a && a->n == 2 && a->v[0] == 3 && a->v[1] == 2);
    a = get(&m, "lensfield:camera_grid_bounds");
    CHECK(a && a->n == 4 && a->v[0] == -1 && a->v[1] == 1 && a->v[2] == -0.5 && a->v[3] == 0.5);
    a = get(&m, "lensfield:fov_deg");
    CHECK(a && a->v[0] == 40);
    a = get(&m, "lensfield:tile_size");
    CHECK(a && a->n == 2 && a->v[0] == 30 && a->v[1] == 20);
    CHECK(get(&m, "lensfield:lens_radius") == NULL); /* pinhole data cameras */
    char desc[2048];
    CHECK(t->describe(c, desc, sizeof desc) > 0 && strstr(desc, "3 x 2") != NULL);
    t->destroy(c);
}

static void test_array_single_and_lens(void)
{
    /* nx = ny = 1: the camera sits at the bounds' midpoint */
    store s = {{{"cameragridbounds", {0.2, 0.6, -0.4, 0.0}, 4, NULL}}, 1};
    char err[512] = "";
    const lf_camera_type *t = lf_camera_find("lightfield");
    void *c = make("lightfield", &s, 31, 17, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (c) {
        lf_camera_sample cs = {30.9, 0.1, 0.5, 0.5, 0, 0.5};
        lf_camera_ray r;
        t->generate_ray(c, &cs, &r);
        CHECK_NEAR(r.origin[0], 0.4, 1e-15);
        CHECK_NEAR(r.origin[1], -0.2, 1e-15);
        t->destroy(c);
    }
    /* resolution not divisible by the grid: an error that says so */
    store s2 = {{{"camerasperdim", {4, 4}, 2, NULL}}, 1};
    CHECK(make("lightfield", &s2, 30, 32, err) == NULL);
    CHECK_MSG(strstr(err, "divisible") != NULL, "%s", err);
    store s3 = {{{"camerasperdim", {0, 2}, 2, NULL}}, 1};
    CHECK(make("lightfield", &s3, 30, 32, err) == NULL);

    /* per-camera thin lens, pbrt semantics: every lens sample of a pixel
     * meets the data camera's pinhole ray on the plane z = focaldistance */
    store s4 = {{{"camerasperdim", {2, 2}, 2, NULL},
                 {"cameragridbounds", {-1, 1, -1, 1}, 4, NULL},
                 {"fov", {30}, 1, NULL},
                 {"lensradius", {0.05}, 1, NULL},
                 {"focaldistance", {4}, 1, NULL}},
                5};
    c = make("lightfield", &s4, 40, 40, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    CHECK(t->needs(c) & LF_CAMERA_NEEDS_LENS);
    lf_camera_sample pin = {27.3, 5.9, 0.5, 0.5, 0, 0.5}; /* tile (1, 0): camera (1, 1) */
    lf_camera_ray r0;
    t->generate_ray(c, &pin, &r0);
    CHECK_NEAR(r0.origin[0], 1.0, 1e-15);
    CHECK_NEAR(r0.origin[1], 1.0, 1e-15);
    double fx = 1.0 + r0.dir[0] / r0.dir[2] * 4, fy = 1.0 + r0.dir[1] / r0.dir[2] * 4;
    double max_r = 0;
    for (int k = 0; k < 64; k++) {
        lf_camera_sample cs = pin;
        cs.lens_u = (k % 8 + 0.5) / 8, cs.lens_v = (k / 8 + 0.5) / 8;
        lf_camera_ray r;
        CHECK(t->generate_ray(c, &cs, &r) == 1.0);
        double q = (4 - r.origin[2]) / r.dir[2];
        CHECK_NEAR(r.origin[0] + q * r.dir[0], fx, 1e-12);
        CHECK_NEAR(r.origin[1] + q * r.dir[1], fy, 1e-12);
        max_r = fmax(max_r, hypot(r.origin[0] - 1, r.origin[1] - 1));
    }
    CHECK(max_r <= 0.05 + 1e-12 && max_r > 0.035);
    attrs m;
    collect("lightfield", c, &m);
    const attr *a = get(&m, "lensfield:lens_radius");
    CHECK(a && a->v[0] == 0.05);
    a = get(&m, "lensfield:focal_distance");
    CHECK(a && a->v[0] == 4);
    t->destroy(c);
}

/* ======================= plenoptic ======================= */

/* Image centre of microlens (i, j) in pixels, from the metadata and the
 * formula of docs/lightfield-format.md. */
typedef struct layout {
    int hex;
    double pitch, rot, off[2], count[2];
} layout;

static void read_layout(const attrs *m, layout *L)
{
    const attr *a = get(m, "lensfield:grid");
    L->hex = a && !strcmp(a->str, "hex");
    a = get(m, "lensfield:microlens_pitch_px");
    L->pitch = a ? a->v[0] : NAN;
    a = get(m, "lensfield:microlens_rotation_rad");
    L->rot = a ? a->v[0] : NAN;
    a = get(m, "lensfield:microlens_offset_px");
    L->off[0] = a ? a->v[0] : NAN, L->off[1] = a ? a->v[1] : NAN;
    a = get(m, "lensfield:microlens_count");
    L->count[0] = a ? a->v[0] : NAN, L->count[1] = a ? a->v[1] : NAN;
}

static void centre(const layout *L, int i, int j, double *x, double *y)
{
    double a = i * L->pitch + (L->hex && (j & 1) ? L->pitch / 2 : 0);
    double b = j * L->pitch * (L->hex ? sqrt(3.0) / 2 : 1);
    *x = L->off[0] + cos(L->rot) * a - sin(L->rot) * b;
    *y = L->off[1] + sin(L->rot) * a + cos(L->rot) * b;
}

static double attr_v(const attrs *m, const char *name)
{
    const attr *a = get(m, name);
    return a ? a->v[0] : NAN;
}

/* Irradiance of one pixel from fixed strata: n x n film positions times
 * n x n lens samples (deterministic). */
static double pixel_irradiance(const lf_camera_type *t, const void *c, int x, int y, int n)
{
    double sum = 0;
    for (int f = 0; f < n * n; f++)
        for (int l = 0; l < n * n; l++) {
            lf_camera_sample cs = {x + (f % n + 0.5) / n, y + (f / n + 0.5) / n, (l % n + 0.5) / n,
                                   (l / n + 0.5) / n, 0, 0.5};
            lf_camera_ray r;
            sum += t->generate_ray(c, &cs, &r);
        }
    return sum / (n * n * n * n);
}

static void test_plenoptic_geometry(void)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    CHECK(t != NULL);
    if (!t)
        return;
    /* defaults: 50 mm f/2.8 focused at 1 m; full frame */
    store s = {{{"microlenses", {10}, 1, NULL}}, 1};
    char err[512] = "";
    void *c = make("plenoptic", &s, 200, 100, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    CHECK(t->needs(c) == LF_CAMERA_NEEDS_LENS);
    attrs m;
    collect("plenoptic", c, &m);
    const attr *a = get(&m, "lensfield:kind");
    CHECK(a && !strcmp(a->str, "plenoptic"));
    double zi = 50.0 / (1 - 0.05); /* 1/f = 1/z_i + 1/z_o, mm */
    CHECK_NEAR(attr_v(&m, "lensfield:mla_distance_mm"), zi, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:main_focal_mm"), 50, 1e-12);
    CHECK_NEAR(attr_v(&m, "lensfield:main_fstop"), 2.8, 1e-12);
    CHECK_NEAR(attr_v(&m, "lensfield:focus_distance_m"), 1, 1e-12);
    CHECK_NEAR(attr_v(&m, "lensfield:sensor_offset_mm"), 0, 1e-12);
    a = get(&m, "lensfield:sensor_size_mm");
    CHECK(a && a->n == 2 && fabs(a->v[0] - 36) < 1e-9 && fabs(a->v[1] - 18) < 1e-9); /* 2:1 image, square pixels */
    /* 10 images across 200 px: spacing 20 px = p (z_i + f_mla)/z_i with
     * the matched f_mla = p z_i / D (D = 50/2.8 mm) */
    layout L;
    read_layout(&m, &L);
    CHECK_NEAR(L.pitch, 20, 1e-9);
    double p_mm = attr_v(&m, "lensfield:microlens_pitch_um") * 1e-3, fm = attr_v(&m, "lensfield:microlens_focal_mm");
    double D = 50 / 2.8;
    CHECK_NEAR(fm, p_mm * zi / D, 1e-9);                     /* f-numbers matched */
    CHECK_NEAR(p_mm * (zi + fm) / zi / 0.18, 20.0, 1e-9);   /* 36 mm / 200 px = 0.18 mm pixels */
    CHECK(L.count[0] == 10 && L.count[1] == 5);             /* 100 px / 20: five rows, none partial */
    /* docs/lightfield-format.md: the pixel at (du, dv) from its image centre
     * sees, through its microlens's centre (u = v = 0.5), the main-lens
     * point (du, -dv) x pixel x z_i / f_mla in camera space */
    {
        double gx, gy;
        centre(&L, 3, 1, &gx, &gy);
        const double dd[][2] = {{-3, 0}, {0, 4}, {5, -2}};
        for (int k = 0; k < 3; k++) {
            lf_camera_sample cs = {gx + dd[k][0], gy + dd[k][1], 0.5, 0.5, 0, 0.5};
            lf_camera_ray r;
            CHECK(t->generate_ray(c, &cs, &r) > 0);
            CHECK_NEAR(r.origin[0], dd[k][0] * 0.18e-3 * zi / fm, 1e-12);
            CHECK_NEAR(r.origin[1], -dd[k][1] * 0.18e-3 * zi / fm, 1e-12);
        }
    }
    CHECK_NEAR(L.off[0], 10, 1e-9);                         /* tiles exactly: first centre half a pitch in */
    CHECK_NEAR(L.off[1], 10, 1e-9);
    CHECK(strstr(last_warning, "mismatch") == NULL); /* only the 36x24 -> 36x18 aspect note */
    CHECK(strstr(last_warning, "36 x 18") != NULL);
    t->destroy(c);

    /* focused at infinity ("focusdistance" 0): z_i = f, and every ray
     * through one point of the microlens array leaves the main lens along
     * the same direction (the MLA is conjugate to infinity) */
    store s2 = {{{"microlenses", {8}, 1, NULL}, {"focusdistance", {0}, 1, NULL}, {"fstop", {4}, 1, NULL}}, 3};
    c = make("plenoptic", &s2, 96, 64, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    collect("plenoptic", c, &m);
    CHECK(attr_v(&m, "lensfield:mla_distance_mm") == 50.0);
    CHECK(isinf(attr_v(&m, "lensfield:focus_distance_m")));
    read_layout(&m, &L);
    /* rays from many pixels under microlens (2, 1) aimed at its centre
     * (u = v = 0.5: the middle of the cell): the main lens maps the MLA point
     * c to the direction of the chief ray through c, i.e. all parallel */
    double gx, gy;
    centre(&L, 2, 1, &gx, &gy);
    double d0[3] = {0, 0, 0};
    int n = 0, bad = 0;
    for (int k = 0; k < 25; k++) {
        lf_camera_sample cs = {gx + (k % 5 - 2) * 1.3, gy + (k / 5 - 2) * 1.3, 0.5, 0.5, 0, 0.5};
        lf_camera_ray r;
        double w = t->generate_ray(c, &cs, &r);
        if (!(w > 0))
            continue;
        if (n++ == 0)
            memcpy(d0, r.dir, sizeof d0);
        else if (fabs(r.dir[0] - d0[0]) > 1e-12 || fabs(r.dir[1] - d0[1]) > 1e-12)
            bad++;
    }
    CHECK(n >= 9 && bad == 0);
    /* and that direction is the image centre's chief ray, with pbrt's
     * orientation: raster right -> +x, raster down -> -y, projected from
     * the main-lens centre at distance z_i + f_mla */
    double pix = 36.0 / 96, zs = 50.0 + attr_v(&m, "lensfield:microlens_focal_mm");
    double ex = (gx - 48) * pix / zs, ey = -(gy - 32) * pix / zs;
    CHECK_NEAR(d0[0] / d0[2], ex, 1e-9);
    CHECK_NEAR(d0[1] / d0[2], ey, 1e-9);
    t->destroy(c);
}

/* Matched f-numbers: images touch along the axes and do not overlap (the
 * microlens each pixel's light came through is found from the ray by
 * undoing the thin main lens); the corners of each cell stay dark; a white
 * image is brightest at the microlens centres, with the centre pixel's
 * irradiance (1/d^2) \int_cell cos^4 dA; and the flux through a microlens
 * equals what the main aperture sends into the microlens's cell. */
static void test_plenoptic_matched(double fstop, int pitch_px)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    const int nl = 7, W = nl * pitch_px, H = W; /* odd count: the middle image centred on the axis */
    store s = {{{"microlenses", {nl}, 1, NULL}, {"fstop", {fstop}, 1, NULL}, {"sensorsize", {2.1, 2.1}, 2, NULL},
                {"focusdistance", {2}, 1, NULL}},
               4};
    char err[512] = "";
    void *c = make("plenoptic", &s, W, H, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    CHECK_MSG(last_warning[0] == '\0', "matched design warned: %s", last_warning);
    attrs m;
    collect("plenoptic", c, &m);
    layout L;
    read_layout(&m, &L);
    CHECK_NEAR(L.pitch, pitch_px, 1e-9);
    double f = 0.05, zi = attr_v(&m, "lensfield:mla_distance_mm") * 1e-3, R = f / (2 * fstop);
    double fm = attr_v(&m, "lensfield:microlens_focal_mm") * 1e-3, p = attr_v(&m, "lensfield:microlens_pitch_um") * 1e-6;
    double pix = 2.1e-3 / W, zs = zi + fm;
    /* the lens a ray came through: back through the thin main lens to the MLA */
    int mid = nl / 2, overlap = 0, corner_lit = 0, inner_dark = 0, not_brightest = 0;
    double flux = 0;
    for (int y = (mid - 1) * pitch_px; y < (mid + 2) * pitch_px; y++)
        for (int x = (mid - 1) * pitch_px; x < (mid + 2) * pitch_px; x++) {
            int lens_seen = -1, n = 4;
            double sum = 0;
            for (int k = 0; k < n * n * n * n; k++) {
                int fi = k % (n * n), li = k / (n * n);
                lf_camera_sample cs = {x + (fi % n + 0.5) / n, y + (fi / n + 0.5) / n, (li % n + 0.5) / n,
                                       (li / n + 0.5) / n, 0, 0.5};
                lf_camera_ray r;
                double w = t->generate_ray(c, &cs, &r);
                sum += w;
                if (!(w > 0))
                    continue;
                /* upright lateral coordinates are camera space negated */
                double hx = -r.origin[0], hy = -r.origin[1];
                double sx = -r.dir[0] / r.dir[2] + hx / f, sy = -r.dir[1] / r.dir[2] + hy / f;
                double mx = hx - sx * zi, my = hy - sy * zi; /* on the MLA */
                int li2 = (int)floor(mx / p + nl / 2.0), lj2 = (int)floor(-my / p + nl / 2.0);
                int id = lj2 * nl + li2;
                if (lens_seen >= 0 && id != lens_seen)
                    overlap++;
                lens_seen = id;
                if (li2 != x / pitch_px || lj2 != y / pitch_px)
                    overlap++; /* light from a lens other than the one whose image this is */
            }
            double E = sum / (n * n * n * n);
            /* position relative to the image centre, pixels */
            double gx, gy;
            int i = x / pitch_px, j = y / pitch_px;
            centre(&L, i, j, &gx, &gy);
            double dx = x + 0.5 - gx, dy = y + 0.5 - gy, rr = hypot(dx, dy);
            /* the image is the aperture disk (diameter P - p f_mla/z_i) widened
             * by the microlens: corners beyond P/2 + 1 px are dark, the inner
             * disk lit */
            if (rr > pitch_px / 2.0 + 0.75)
                corner_lit += E > 0;
            if (rr < pitch_px / 2.0 - 1.5)
                inner_dark += !(E > 0);
            if (i == mid && j == mid)
                flux += E * pix * pix;
            if (fabs(dx) < 0.5 && fabs(dy) < 0.5) {
                /* centre pixel: the brightest of its image */
                double Ec = E;
                for (int yy = j * pitch_px; yy < (j + 1) * pitch_px; yy += 2)
                    for (int xx = i * pitch_px; xx < (i + 1) * pitch_px; xx += 2)
                        if ((xx != x || yy != y) && pixel_irradiance(t, c, xx, yy, 3) > Ec * (1 + 1e-3))
                            not_brightest++;
                if (i == mid && j == mid) {
                    E = pixel_irradiance(t, c, x, y, 12); /* midpoint strata bias ~ 1/n^2 on the cos^4 falloff */
                    /* (1/d^2) \int_cell cos^4 dA averaged over the pixel, by
                     * midpoint quadrature (d = f_mla) */
                    double q = 0;
                    int Q = 24;
                    for (int a = 0; a < Q * Q; a++)
                        for (int b = 0; b < 4; b++) {
                            double psx = ((b % 2 + 0.5) / 2 - 0.5) * pix, psy = ((b / 2 + 0.5) / 2 - 0.5) * pix;
                            double mx = ((a % Q + 0.5) / Q - 0.5) * p - psx, my = ((a / Q + 0.5) / Q - 0.5) * p - psy;
                            double c2 = fm * fm / (fm * fm + mx * mx + my * my);
                            q += c2 * c2 / (fm * fm) * (p * p) / (Q * Q) / 4;
                        }
                    CHECK_MSG(fabs(E / q - 1) < 1e-3, "centre pixel irradiance %.6g, expected %.6g", E, q);
                }
            }
        }
    CHECK_MSG(overlap == 0, "f/%g: %d samples came through a neighbouring microlens", fstop, overlap);
    CHECK_MSG(corner_lit == 0, "f/%g: %d corner pixels lit", fstop, corner_lit);
    CHECK_MSG(inner_dark == 0, "f/%g: %d pixels inside the aperture image dark", fstop, inner_dark);
    CHECK_MSG(not_brightest == 0, "f/%g: %d pixels brighter than their microlens centre", fstop, not_brightest);
    /* Flux through the middle microlens from the main aperture (radiance 1):
     * \int_cell \int_disk z_i^2 / r^4 dA dA' (the thin-lens camera's
     * irradiance integrated over the cell), by quadrature.  The ideal
     * (paraxial) microlens shears slopes, conserving d^2(slope) rather than
     * projected solid angle, so the sensor side's cos^4 is taken at slopes
     * displaced by (m - c)/f_mla (uniform over +-1/(2 N_mla)): to second
     * order the sensor receives 1 - 1/(3 N_mla^2) of it; the margin covers
     * the fourth-order terms and the 4x4x4x4 strata. */
    double phi = 0;
    int Q = 20;
    for (int a = 0; a < Q * Q; a++) {
        double mx = ((a % Q + 0.5) / Q - 0.5) * p, my = ((a / Q + 0.5) / Q - 0.5) * p;
        for (int b = 0; b < Q * Q; b++) {
            double rho = R * sqrt((b % Q + 0.5) / Q), th = 2 * M_PI * (b / Q + 0.5) / Q;
            double lx = rho * cos(th) - mx, ly = rho * sin(th) - my;
            double r2 = lx * lx + ly * ly + zi * zi;
            phi += zi * zi / (r2 * r2) * (p * p / (Q * Q)) * (M_PI * R * R / (Q * Q));
        }
    }
    double Nm = fm / p, expect = phi * (1 - 1 / (3 * Nm * Nm));
    CHECK_MSG(fabs(flux / expect - 1) < 0.004 + 1 / (Nm * Nm * Nm * Nm),
              "f/%g: flux through the middle microlens %.6g, expected %.6g (thin-lens flux %.6g)", fstop, flux, expect,
              phi);
    (void)zs;
    t->destroy(c);
}

/* Hard cases from the issue. */
static void test_plenoptic_hard_cases(void)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    char err[512] = "";
    attrs m;
    layout L;
    /* a grid that does not divide the sensor: 100 um lenses on 3.6 mm x
     * 2.4 mm -> the spacing in pixels is 100 um (z_i + f_mla)/z_i / 24 um,
     * and the count includes the partial lenses at both borders */
    store s = {{{"pitch", {100}, 1, NULL}, {"sensorsize", {3.6, 2.4}, 2, NULL}}, 2};
    void *c = make("plenoptic", &s, 150, 100, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (c) {
        collect("plenoptic", c, &m);
        read_layout(&m, &L);
        double zi = attr_v(&m, "lensfield:mla_distance_mm"), fm = attr_v(&m, "lensfield:microlens_focal_mm");
        double P = 0.1 * (zi + fm) / zi / 0.024;
        CHECK_NEAR(L.pitch, P, 1e-9);
        /* lenses whose cell [x - P/2, x + P/2] meets [0, 150): the grid is centred on the sensor */
        int nx0 = (int)ceil(150 / P), ny0 = (int)ceil(100 / P);
        CHECK(L.count[0] == nx0 && L.count[1] == ny0);
        CHECK_NEAR(L.off[0], 75 - (nx0 - 1) * P / 2, 1e-9);
        CHECK(L.off[0] - P / 2 < 0 && L.off[0] + (L.count[0] - 1) * P + P / 2 > 150); /* partial at both ends */
        int bad = 0, lit_border = 0;
        for (int y = 0; y < 100; y += 3)
            for (int x = 0; x < 150; x += (y == 0 || y >= 99) ? 1 : 149) {
                double E = pixel_irradiance(t, c, x, y, 2);
                bad += !isfinite(E) || E < 0;
                lit_border += E > 0;
            }
        CHECK(bad == 0);
        CHECK(lit_border > 20); /* the partial lenses pass light */
        t->destroy(c);
    }
    /* one pixel per microlens, and 64 x 64 pixels per microlens */
    int per[2] = {1, 64};
    for (int k = 0; k < 2; k++) {
        int n = k ? 3 : 48;
        store s1 = {{{"microlenses", {n}, 1, NULL}, {"sensorsize", {4.8, 4.8}, 2, NULL}}, 2};
        c = make("plenoptic", &s1, n * per[k], n * per[k], err);
        CHECK_MSG(c != NULL, "%s", err);
        if (!c)
            continue;
        collect("plenoptic", c, &m);
        read_layout(&m, &L);
        CHECK_NEAR(L.pitch, per[k], 1e-9);
        CHECK(L.count[0] == n && L.count[1] == n);
        int bad = 0;
        double centre_E = 0;
        for (int q = 0; q < 200; q++) {
            int x = (q * 37) % (n * per[k]), y = (q * 53) % (n * per[k]);
            double E = pixel_irradiance(t, c, x, y, 2);
            bad += !isfinite(E) || E < 0;
        }
        double gx, gy;
        centre(&L, n / 2, n / 2, &gx, &gy);
        /* 12^4 strata: the lit region has sharp edges inside a 1 px pixel */
        centre_E = pixel_irradiance(t, c, (int)gx, (int)gy, k ? 4 : 12);
        CHECK(bad == 0);
        CHECK(centre_E > 0);
        if (k == 0) {
            /* one pixel per lens: the pixel collects all the flux through its
             * lens, the thin-lens irradiance pi/(4 N_image^2) (1 - 1/(4 N^2))
             * (cos^4 averaged over the aperture, second order) on the cell
             * area p^2, spread over the pixel (p (z_i + f_mla)/z_i)^2, times
             * the paraxial-microlens factor 1 - 1/(3 N^2) (see
             * test_plenoptic_matched); 1.5 % covers the fourth-order terms */
            double zi = attr_v(&m, "lensfield:mla_distance_mm"), D = 50 / 2.8, Ni = zi / D;
            double fm = attr_v(&m, "lensfield:microlens_focal_mm");
            double e = M_PI / (4 * Ni * Ni) * (1 - 1 / (4 * Ni * Ni)) * (1 - 1 / (3 * Ni * Ni)) * pow(zi / (zi + fm), 2);
            CHECK_MSG(fabs(centre_E / e - 1) < 0.015, "1 px per lens: %.5g vs expected %.5g", centre_E, e);
        }
        t->destroy(c);
    }
    /* hex grid with rotation: the layout formula with sqrt(3)/2 row spacing
     * and the odd-row half-pitch shift, rotated; the centre pixel of a
     * microlens image sees the main-lens centre (its ray leaves the origin) */
    store s3 = {{{"microlenses", {12}, 1, NULL},
                 {"grid", {0}, 0, "hex"},
                 {"rotation", {10}, 1, NULL},
                 {"sensorsize", {6, 4}, 2, NULL}},
                4};
    c = make("plenoptic", &s3, 180, 120, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (c) {
        collect("plenoptic", c, &m);
        read_layout(&m, &L);
        CHECK(L.hex);
        CHECK_NEAR(L.rot, 10 * M_PI / 180, 1e-12);
        CHECK_NEAR(L.pitch, 15, 1e-9);
        /* every image centre inside the sensor is a lens of the counted range,
         * and its centre pixel's chief ray passes the main-lens centre */
        int checked = 0, off_centre = 0;
        double worst = 0;
        for (int j = 0; j < L.count[1]; j++)
            for (int i = 0; i < L.count[0]; i++) {
                double gx, gy;
                centre(&L, i, j, &gx, &gy);
                if (gx < 8 || gy < 8 || gx > 172 || gy > 112)
                    continue;
                /* the ray through the cell centre (u = v = 0.5 picks the
                 * middle candidate, so use the nearest-lens case: sample the
                 * image centre with several lens samples and keep the ray
                 * with the smallest origin) */
                double best = 1e9, hx = 0, hy = 0;
                int lit = 0;
                for (int q = 0; q < 144; q++) {
                    lf_camera_sample cs = {gx, gy, (q % 12 + 0.5) / 12, (q / 12 + 0.5) / 12, 0, 0.5};
                    lf_camera_ray r;
                    if (t->generate_ray(c, &cs, &r) > 0) {
                        best = fmin(best, hypot(r.origin[0], r.origin[1]));
                        hx += r.origin[0], hy += r.origin[1], lit++;
                    }
                }
                /* a sensor point at an image centre sees, through its
                 * microlens, the cell's shape around the main-lens centre
                 * (h = m - c for d = f_mla): the centroid of those points is
                 * the origin and some come within p/4 of it */
                double p = attr_v(&m, "lensfield:microlens_pitch_um") * 1e-6;
                double cen = lit ? hypot(hx / lit, hy / lit) : 1e9;
                worst = fmax(worst, cen);
                off_centre += lit < 144 || best > p / 4 || cen > p / 10;
                checked++;
            }
        CHECK(checked >= 60);
        CHECK_MSG(off_centre == 0, "hex: %d image centres do not see the main-lens centre (worst %g m)", off_centre,
                  worst);
        /* the lattice covers the sensor: a lens image centre within P/sqrt(3) of every sensor point */
        int uncovered = 0;
        for (int y = 0; y <= 120; y += 4)
            for (int x = 0; x <= 180; x += 4) {
                double best = 1e9;
                for (int j = 0; j < L.count[1]; j++)
                    for (int i = 0; i < L.count[0]; i++) {
                        double gx, gy;
                        centre(&L, i, j, &gx, &gy);
                        best = fmin(best, hypot(gx - x, gy - y));
                    }
                uncovered += best > 15 / sqrt(3.0) + 1e-9;
            }
        CHECK_MSG(uncovered == 0, "hex: %d sensor points outside every lens cell", uncovered);
        t->destroy(c);
    }
    /* f-number mismatch: which way the images overlap, in the warning */
    store s4 = {{{"microlenses", {20}, 1, NULL}, {"microlensfocallength", {1.0}, 1, NULL}}, 2};
    c = make("plenoptic", &s4, 200, 100, err); /* f/2.8 main lens, f_mla 1 mm at 1.8 mm pitch: f/0.56 */
    CHECK_MSG(c != NULL, "%s", err);
    CHECK_MSG(strstr(last_warning, "leave gaps") != NULL, "%s", last_warning);
    if (c)
        t->destroy(c);
    store s5 = {{{"microlenses", {20}, 1, NULL}, {"microlensfocallength", {8.0}, 1, NULL}}, 2};
    c = make("plenoptic", &s5, 200, 100, err); /* f_mla 8 mm: f/5.1 microlenses behind an f/2.95 cone */
    CHECK_MSG(c != NULL, "%s", err);
    CHECK_MSG(strstr(last_warning, "microlens images overlap") != NULL, "%s", last_warning);
    if (c) {
        /* and the overlap is real: some pixel gets light through two lenses,
         * i.e. more than one candidate passes (irradiance where the matched
         * design has a dark corner) */
        collect("plenoptic", c, &m);
        read_layout(&m, &L);
        double gx, gy;
        centre(&L, 10, 2, &gx, &gy);
        double E = pixel_irradiance(t, c, (int)(gx + L.pitch / 2), (int)(gy + L.pitch / 2), 3);
        CHECK(E > 0);
        t->destroy(c);
    }
    /* bad parameters */
    store s6 = {{{"pitch", {50}, 1, NULL}, {"microlenses", {10}, 1, NULL}}, 2};
    CHECK(make("plenoptic", &s6, 100, 100, err) == NULL);
    store s7 = {{{"grid", {0}, 0, "triangle"}}, 1};
    CHECK(make("plenoptic", &s7, 100, 100, err) == NULL && strstr(err, "grid"));
    store s8 = {{{"focusdistance", {0.03}, 1, NULL}}, 1};
    CHECK(make("plenoptic", &s8, 100, 100, err) == NULL && strstr(err, "focusdistance"));
    store s9 = {{{"sensoroffset", {-50}, 1, NULL}}, 1};
    CHECK(make("plenoptic", &s9, 100, 100, err) == NULL);
}

/* Plenoptic 2.0: with the sensor moved off the microlens focal plane, a
 * sensor point sees the main lens through several microlenses, and still
 * every weight is finite and the rays leave through the main aperture. */
static void test_plenoptic_focused(void)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    store s = {{{"microlenses", {10}, 1, NULL}, {"sensoroffset", {0.3}, 1, NULL}}, 2};
    char err[512] = "";
    void *c = make("plenoptic", &s, 200, 100, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    attrs m;
    collect("plenoptic", c, &m);
    CHECK_NEAR(attr_v(&m, "lensfield:sensor_offset_mm"), 0.3, 1e-12);
    double R = 0.05 / 2.8 / 2;
    int bad = 0, outside = 0;
    for (int q = 0; q < 4000; q++) {
        lf_camera_sample cs = {(q * 0.618034) - floor(q * 0.618034 / 200) * 200, fmod(q * 0.414214, 100),
                               fmod(q * 0.7548777, 1), fmod(q * 0.5698403, 1), 0, 0.5};
        lf_camera_ray r;
        double w = t->generate_ray(c, &cs, &r);
        bad += !isfinite(w) || w < 0;
        if (w > 0)
            outside += hypot(r.origin[0], r.origin[1]) > R * (1 + 1e-12);
    }
    CHECK(bad == 0 && outside == 0);
    t->destroy(c);
}

/* A compound main lens (scenes/lenses/dgauss.50mm.dat).  The expected
 * numbers come from the lens library's paraxial analysis (camera/lens.h),
 * not from the camera: the working f-number at the focus distance sets the
 * matched microlens focal length f_mla = p N_w, the paraxial exit pupil at Z
 * in front of the MLA sets the image spacing p (Z + f_mla)/Z.  Light that
 * reaches the sensor is traced back through the prescription (from the
 * scene side) to the MLA to see which microlens it came through. */
static void test_plenoptic_compound(double mla_scale, double *outside_fraction)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    const double stop_mm = 8, focus_m = 2, p_um = 100;
    lf_lens lens;
    char err[512] = ""; /* the camera plugins' message buffer */
    lf_error lerr = {0};
    if (lf_lens_load(LF_SOURCE_DIR "/scenes/lenses/dgauss.50mm.dat", &lens, &lerr)) {
        CHECK_MSG(0, "%s", lerr.msg);
        return;
    }
    lf_lens_set_stop_diameter(&lens, stop_mm, NULL);
    lf_lens_paraxial px;
    CHECK(lf_lens_paraxial_analyse(&lens, &px) == 0);
    CHECK(lf_lens_focus_thick(&lens, focus_m * 1e3, &lens.film_distance_mm, &lerr) == 0);
    double Nw = lf_lens_working_fnumber(&lens, &px, focus_m * 1e3, lens.film_distance_mm);
    double Z = lens.film_distance_mm - px.exit_pupil_mm; /* mm, MLA -> exit pupil */
    double p = p_um * 1e-3, fm = p * Nw * mla_scale, Pimg = p * (Z + fm) / Z;
    const int nl = 7, W = 77, H = 77, mid = nl / 2;
    double pix = Pimg / 11.02; /* mm; 6.99 images across: 7 lenses, the middle one on the axis */
    store s = {{{"lensfile", {0}, 0, "lenses/dgauss.50mm.dat"},
                {"aperturediameter", {stop_mm}, 1, NULL},
                {"focusdistance", {focus_m}, 1, NULL},
                {"pitch", {p_um}, 1, NULL},
                {"microlensfocallength", {fm}, 1, NULL},
                {"sensorsize", {W * pix, H * pix}, 2, NULL}},
               6};
    void *c = make("plenoptic", &s, W, H, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c) {
        lf_lens_free(&lens);
        return;
    }
    if (mla_scale == 1.0)
        CHECK_MSG(last_warning[0] == '\0', "matched compound design warned: %s", last_warning);
    else
        CHECK_MSG(strstr(last_warning, "microlens images overlap") != NULL, "%s", last_warning);
    attrs m;
    collect("plenoptic", c, &m);
    layout L;
    read_layout(&m, &L);
    CHECK_MSG(fabs(L.pitch - 11.02) < 1e-6, "image spacing %.9g px, expected 11.02 (p (Z + f_mla)/Z)", L.pitch);
    CHECK(L.count[0] == nl && L.count[1] == nl);
    const attr *a = get(&m, "lensfield:lens_file");
    CHECK(a && strstr(a->str, "dgauss.50mm.dat"));
    CHECK_NEAR(attr_v(&m, "lensfield:lens_efl_mm"), px.efl_mm, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:lens_working_fnumber"), Nw, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:lens_film_distance_mm"), lens.film_distance_mm, 1e-9);
    /* the equivalent thin lens: f = EFL, z_i from H', same image-side cone,
     * in focus at z_o (from H) with 1/z_o + 1/z_i = 1/f */
    double zi = lens.film_distance_mm - px.rear_principal_mm;
    CHECK_NEAR(attr_v(&m, "lensfield:main_focal_mm"), px.efl_mm, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:mla_distance_mm"), zi, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:main_fstop"), px.efl_mm * Nw / zi, 1e-9);
    CHECK_NEAR(attr_v(&m, "lensfield:focus_distance_m"), 1e-3 / (1 / px.efl_mm - 1 / zi), 1e-9);
    /* H (the camera origin) to the MLA, for the back-trace */
    double h2mla = lens.film_distance_mm + px.total_length_mm - px.front_principal_mm;

    /* every weight finite and >= 0, every direction unit, over the sensor */
    int bad = 0, lit = 0;
    for (int q = 0; q < 20000; q++) {
        lf_camera_sample cs = {fmod(q * 0.618034, W), fmod(q * 0.414214, H), fmod(q * 0.7548777, 1),
                               fmod(q * 0.5698403, 1), 0, 0.5};
        lf_camera_ray r;
        double w = t->generate_ray(c, &cs, &r);
        bad += !isfinite(w) || w < 0;
        if (w > 0) {
            lit++;
            double l = sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
            bad += fabs(l - 1) > 1e-12 || !(r.dir[2] > 0) || !isfinite(r.origin[0] + r.origin[1] + r.origin[2]);
        }
    }
    CHECK_MSG(bad == 0 && lit > 5000, "%d bad rays, %d lit of 20000", bad, lit);

    /* Which microlens each ray came through: camera -> lens space, back
     * through the prescription to the MLA plane z = 0.  Weighted fraction of
     * the light in the middle 3 x 3 images that arrives outside the image
     * cell (nearest image centre) of its own microlens. */
    double w_all = 0, w_out = 0;
    int n = 4, traced_back_failed = 0;
    for (int y = (mid - 1) * 11; y < (mid + 2) * 11 + 1; y++)
        for (int x = (mid - 1) * 11; x < (mid + 2) * 11 + 1; x++)
            for (int k = 0; k < n * n * n * n; k++) {
                int fi = k % (n * n), li = k / (n * n);
                lf_camera_sample cs = {x + (fi % n + 0.5) / n, y + (fi / n + 0.5) / n, (li % n + 0.5) / n,
                                       (li / n + 0.5) / n, 0, 0.5};
                lf_camera_ray r;
                double w = t->generate_ray(c, &cs, &r);
                if (!(w > 0))
                    continue;
                /* light travels -dir (camera), i.e. (-dx, -dy, +dz) in lens space; start 1 mm upstream */
                lf_lens_ray in = {{r.origin[0] * 1e3 + r.dir[0], r.origin[1] * 1e3 + r.dir[1],
                                   -r.origin[2] * 1e3 - h2mla - r.dir[2]},
                                  {-r.dir[0], -r.dir[1], r.dir[2]}},
                            out;
                if (lf_lens_trace_from_scene(&lens, &in, &out, NULL) != LF_LENS_PASSED) {
                    traced_back_failed++;
                    continue;
                }
                double tt = -out.o[2] / out.d[2];
                double ux = -(out.o[0] + tt * out.d[0]), uy = -(out.o[1] + tt * out.d[1]); /* upright, mm */
                int li2 = (int)floor(ux / p + nl / 2.0), lj2 = (int)floor(-uy / p + nl / 2.0);
                /* the sample's own cell: nearest image centre */
                int ci = (int)floor((cs.film_x - L.off[0]) / L.pitch + 0.5);
                int cj = (int)floor((cs.film_y - L.off[1]) / L.pitch + 0.5);
                w_all += w;
                if (li2 != ci || lj2 != cj)
                    w_out += w;
            }
    CHECK(traced_back_failed == 0);
    *outside_fraction = w_all > 0 ? w_out / w_all : 1;
    printf("note: compound main lens (dgauss 50 mm, stop %g mm, working f/%.4g), f_mla = %.2f p N_w: %.4f%% of the "
           "light lands outside its microlens's image cell\n",
           stop_mm, Nw, mla_scale, 100 * *outside_fraction);
    t->destroy(c);
    lf_lens_free(&lens);
}

static void test_plenoptic_compound_cases(void)
{
    double matched = 1, mismatched = 0;
    test_plenoptic_compound(1.0, &matched);
    test_plenoptic_compound(1.5, &mismatched);
    /* matched: images touch and do not overlap (0 for the paraxial design;
     * what remains is the real lens's pupil aberration); a microlens 1.5x
     * too slow spills a large share into the neighbours */
    CHECK_MSG(matched < 0.002, "matched: %.4f of the light outside its image", matched);
    CHECK_MSG(mismatched > 0.05, "mismatched: only %.4f of the light outside its image", mismatched);
    /* errors: unknown file, no focal power is the lens library's */
    store s = {{{"lensfile", {0}, 0, "lenses/nonexistent.dat"}}, 1};
    char err[512] = "";
    CHECK(make("plenoptic", &s, 40, 40, err) == NULL && strstr(err, "nonexistent"));
}

int main(void)
{
    test_array_layout();
    test_array_single_and_lens();
    test_plenoptic_geometry();
    test_plenoptic_matched(2.8, 11);
    test_plenoptic_matched(8.0, 9);
    test_plenoptic_hard_cases();
    test_plenoptic_focused();
    test_plenoptic_compound_cases();
    return lf_test_end();
}
