/* Thin-lens camera and aperture unit tests (lf_camera only): the thin lens
 * equation, magnification and FOV of the physical "thinlens" camera, its
 * ray weights (camera equation, cos^4), the sensor table, --explain facts,
 * unbiased aperture sampling for every shape, pbrt's perspective with
 * apertures, and the hard cases.  Every expected number is computed here
 * from the formulas in docs/physics.md, never copied from the program. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/aperture.h"
#include "camera/lf_camera.h"
#include "lf_test.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "tests/camera_store.h"

/* Ring image 64x64: transmission 1 for 0.4 < r < 0.9 (r in units of the
 * half-width), 0.5 in the inner disk r < 0.2, 0 elsewhere. */
enum { IMG = 64 };
static double ring_value(double x, double y)
{
    double r = hypot(x, y);
    return r > 0.4 && r < 0.9 ? 1.0 : (r < 0.2 ? 0.5 : 0.0);
}
static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    const store *s = c;
    if (s->image_kind == 0) {
        snprintf(err, n, "cannot open %s", path);
        return -1;
    }
    float *p = malloc(sizeof(float) * IMG * IMG);
    for (int y = 0; y < IMG; y++)
        for (int x = 0; x < IMG; x++) {
            double cx = (x + 0.5) / IMG * 2 - 1, cy = 1 - (y + 0.5) / IMG * 2;
            p[y * IMG + x] = s->image_kind == 2 ? 0.f : (float)ring_value(cx, cy);
        }
    *w = *h = IMG;
    *px = p;
    return 0;
}

static lf_camera_params params_of(store *s)
{
    lf_camera_params p = {s, g_float, g_int, g_bool, g_string, g_floats, g_image};
    return p;
}

static char last_warning[512];

static void *make(const char *type, store *s, int w, int h, char *err)
{
    lf_camera_params p = params_of(s);
    last_warning[0] = '\0';
    lf_camera_create_args a = {sizeof a, &p,  w,   h,   35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes", err, 512,
                               last_warning, sizeof last_warning};
    void *state = NULL;
    const lf_camera_type *t = lf_camera_find(type);
    if (!t || t->create(&a, &state))
        return NULL;
    return state;
}

static unsigned lcg_state = 2024u;
static double rnd(void)
{
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return (lcg_state >> 8) * 0x1p-24;
}

/* Where a ray crosses the plane z = Z. */
static void cross_plane(const lf_camera_ray *r, double Z, double *x, double *y)
{
    double t = (Z - r->origin[2]) / r->dir[2];
    *x = r->origin[0] + t * r->dir[0];
    *y = r->origin[1] + t * r->dir[1];
}

/* ---- apertures ---- */

/* Polar second moment of the regular n-gon with circumradius 1 about its
 * centre: a fan of n triangles (0, p, q), each \int |x|^2 = area/6 (|p|^2 +
 * |q|^2 + p.q). */
static double polygon_J(int n)
{
    double a = 2 * M_PI / n;
    return n * 0.5 * sin(a) / 6.0 * (2 + cos(a));
}

/* Checks sampling of one aperture: every point is open; area * E[w g]
 * equals \int g T dA for g = 1, x^2, y^2 and the quadrant indicator, with
 * the integrals from a 1500 x 1500 midpoint grid of the transmission (or
 * analytic values when given).  MC noise: 2^20 stratified samples, errors
 * well below the 0.5% tolerance; the grid's boundary error is below 0.3%. */
static void check_aperture(const char *what, store *s, double expected_area, double expected_x2, double expected_y2)
{
    lf_camera_params p = params_of(s);
    lf_aperture ap;
    lf_error err = {0};
    if (lf_aperture_parse(&p, &ap, &err)) {
        CHECK_MSG(0, "%s: %s", what, err.msg);
        return;
    }
    double area = lf_aperture_area(&ap);
    if (expected_area > 0)
        CHECK_MSG(fabs(area - expected_area) <= 1e-12 * expected_area + 1e-12, "%s: area %.9g, expected %.9g", what,
                  area, expected_area);
    /* grid integrals of the transmission over the bounding box */
    double ax = ap.anamorphic, g1 = 0, gx2 = 0, gy2 = 0, gq = 0;
    const int G = 1500;
    double ext = ap.kind == LF_APERTURE_IMAGE ? sqrt(2.0) : 1.0; /* rotated images reach the corners */
    double cell = (2 * ext * ax / G) * (2 * ext / G);
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            double x = ((i + 0.5) / G * 2 - 1) * ext * ax, y = ((j + 0.5) / G * 2 - 1) * ext;
            double t = lf_aperture_transmission(&ap, x, y);
            g1 += t * cell;
            gx2 += t * x * x * cell;
            gy2 += t * y * y * cell;
            if (x > 0 && y > 0)
                gq += t * cell;
        }
    CHECK_MSG(fabs(g1 - area) <= 0.003 * area, "%s: transmission integrates to %.6f, area says %.6f", what, g1, area);
    const int S = 1024; /* 1024 x 1024 jittered strata */
    double m1 = 0, mx2 = 0, my2 = 0, mq = 0;
    int closed = 0;
    unsigned seed = lcg_state;
    lcg_state = 99u;
    for (int j = 0; j < S; j++)
        for (int i = 0; i < S; i++) {
            double x, y;
            double w = lf_aperture_sample(&ap, (i + rnd()) / S, (j + rnd()) / S, &x, &y);
            if (w > 0 && lf_aperture_transmission(&ap, x, y) <= 0 &&
                lf_aperture_transmission(&ap, x * (1 - 1e-9), y * (1 - 1e-9)) <= 0)
                closed++;
            m1 += w;
            mx2 += w * x * x;
            my2 += w * y * y;
            mq += (x > 0 && y > 0) ? w : 0;
        }
    lcg_state = seed;
    double ns = (double)S * S;
    m1 *= area / ns, mx2 *= area / ns, my2 *= area / ns, mq *= area / ns;
    CHECK_MSG(closed == 0, "%s: %d samples landed where the aperture is closed", what, closed);
    CHECK_MSG(fabs(m1 - area) <= 1e-9 * area, "%s: area x mean weight %.9f vs area %.9f", what, m1, area);
    double ex2 = expected_x2 > 0 ? expected_x2 : gx2, ey2 = expected_y2 > 0 ? expected_y2 : gy2;
    CHECK_MSG(fabs(mx2 - ex2) <= 0.005 * ex2, "%s: \\int x^2: sampled %.6f, expected %.6f", what, mx2, ex2);
    CHECK_MSG(fabs(my2 - ey2) <= 0.005 * ey2, "%s: \\int y^2: sampled %.6f, expected %.6f", what, my2, ey2);
    CHECK_MSG(fabs(mq - gq) <= 0.005 * area, "%s: quadrant x>0,y>0: sampled %.6f, grid %.6f", what, mq, gq);
    if (expected_x2 > 0)
        CHECK_MSG(fabs(gx2 - expected_x2) <= 0.005 * expected_x2, "%s: grid \\int x^2 %.6f vs analytic %.6f", what, gx2,
                  expected_x2);
    lf_aperture_free(&ap);
}

static void test_apertures(void)
{
    /* circle, and an anamorphic ellipse (semi-axes a, 1): area pi a,
     * \int x^2 = pi a^3/4, \int y^2 = pi a/4 */
    store c = {{{"aperture", {0}, 0, "circular"}}, 1, 0};
    check_aperture("circle", &c, M_PI, M_PI / 4, M_PI / 4);
    store e = {{{"anamorphic", {1.5}, 1, NULL}}, 1, 0};
    check_aperture("anamorphic circle", &e, M_PI * 1.5, M_PI * 1.5 * 1.5 * 1.5 / 4, M_PI * 1.5 / 4);
    /* regular polygons: area (n/2) sin(2 pi/n); \int x^2 = \int y^2 = J/2 */
    for (int n = 3; n <= 9; n += 2) {
        store s = {{{"aperture", {0}, 0, "polygon"}, {"blades", {n}, 1, NULL}, {"aperturerotation", {17}, 1, NULL}},
                   3, 0};
        char what[64];
        snprintf(what, sizeof what, "%d-blade polygon", n);
        check_aperture(what, &s, 0.5 * n * sin(2 * M_PI / n), polygon_J(n) / 2, polygon_J(n) / 2);
    }
    store hex = {{{"aperture", {0}, 0, "polygon"}}, 1, 0};
    check_aperture("default polygon (6 blades)", &hex, 3 * sin(M_PI / 3), polygon_J(6) / 2, polygon_J(6) / 2);
    store sq = {{{"aperture", {0}, 0, "square"}, {"anamorphic", {2}, 1, NULL}}, 2, 0};
    /* axis-aligned square of half-side 1/sqrt2 stretched 2x in x */
    double hs = 1 / sqrt(2.0);
    /* -> the rectangle [-2hs, 2hs] x [-hs, hs] */
    check_aperture("anamorphic square", &sq, (4 * hs) * (2 * hs), (2 * pow(2 * hs, 3) / 3) * (2 * hs),
                   (4 * hs) * (2 * pow(hs, 3) / 3));
    /* 5-point star: pentagram with inner radius cos(72)/cos(36); area n r_i sin(pi/n) */
    double ri = cos(2 * M_PI / 5) / cos(M_PI / 5);
    store st = {{{"aperture", {0}, 0, "star"}}, 1, 0};
    check_aperture("star", &st, 5 * ri * sin(M_PI / 5), 0, 0);
    /* image: the ring 64x64 over [-1,1]^2; area = 4 x mean transmission
     * (pixel-exact count, since the image is piecewise constant) */
    store im = {{{"aperture", {0}, 0, "ring.png"}, {"aperturerotation", {30}, 1, NULL}}, 2, 1};
    double sum = 0;
    for (int y = 0; y < IMG; y++)
        for (int x = 0; x < IMG; x++)
            sum += ring_value((x + 0.5) / IMG * 2 - 1, 1 - (y + 0.5) / IMG * 2);
    check_aperture("image", &im, 4 * sum / (IMG * IMG), 0, 0);

    /* corners on the unit circle: the farthest sample of a polygon */
    store p5 = {{{"aperture", {0}, 0, "pentagon"}}, 1, 0};
    lf_camera_params pp = params_of(&p5);
    lf_aperture ap;
    lf_error err = {0};
    CHECK(lf_aperture_parse(&pp, &ap, &err) == 0);
    CHECK(ap.blades == 5);
    double rmax = 0;
    for (int i = 0; i < 100000; i++) {
        double x, y;
        lf_aperture_sample(&ap, rnd(), rnd(), &x, &y);
        rmax = fmax(rmax, hypot(x, y));
    }
    CHECK(rmax <= 1 + 1e-12 && rmax > 0.99);
    /* corner 0 points along +y; the opposite direction is an edge normal */
    CHECK(lf_aperture_transmission(&ap, 0, 0.999) > 0);
    CHECK(lf_aperture_transmission(&ap, 0, -cos(M_PI / 5) * 0.999) > 0);
    CHECK(lf_aperture_transmission(&ap, 0, -cos(M_PI / 5) * 1.001) == 0);
    lf_aperture_free(&ap);

    /* errors */
    store black = {{{"aperture", {0}, 0, "black_mask.png"}}, 1, 2};
    pp = params_of(&black);
    CHECK(lf_aperture_parse(&pp, &ap, &err) == LF_ERR_PARAM);
    CHECK_MSG(!strcmp(err.msg, "aperture image \"black_mask.png\" is all black: it lets no light through (white = "
                               "open, black = closed)"),
              "all-black image error: %s", err.msg);
    lf_error_clear(&err);
    store missing = {{{"aperture", {0}, 0, "nothere.exr"}}, 1, 0};
    pp = params_of(&missing);
    CHECK(lf_aperture_parse(&pp, &ap, &err) == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, "aperture image \"nothere.exr\": ") == err.msg, "missing image error: %s", err.msg);
    lf_error_clear(&err);
    store blades2 = {{{"aperture", {0}, 0, "polygon"}, {"blades", {2}, 1, NULL}}, 2, 0};
    pp = params_of(&blades2);
    CHECK(lf_aperture_parse(&pp, &ap, &err) == LF_ERR_PARAM && !strcmp(err.msg, "\"blades\" must be in 3..1000, got 2"));
    lf_error_clear(&err);
    store ana0 = {{{"anamorphic", {0}, 1, NULL}}, 1, 0};
    pp = params_of(&ana0);
    CHECK(lf_aperture_parse(&pp, &ap, &err) == LF_ERR_PARAM && !strcmp(err.msg, "\"anamorphic\" must be positive, got 0"));
}

/* ---- thinlens ---- */

static double thin_zs(double f, double zo)
{
    return 1.0 / (1.0 / f - 1.0 / zo); /* 1/f = 1/z_i + 1/z_o */
}

static void test_thinlens_geometry(void)
{
    const lf_camera_type *t = lf_camera_find("thinlens");
    CHECK(t != NULL);
    if (!t)
        return;
    char err[512] = "";
    /* 1:1 macro: focus at 2f puts the sensor at 2f, m = 1. */
    const double f = 0.05, N = 4, W = 360, H = 240;
    store s = {{{"focallength", {50}, 1, NULL}, {"fstop", {N}, 1, NULL}, {"focusdistance", {2 * f}, 1, NULL}}, 3, 0};
    void *c = make("thinlens", &s, (int)W, (int)H, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    CHECK(t->needs(c) == LF_CAMERA_NEEDS_LENS);
    double zs = thin_zs(f, 2 * f);
    CHECK_NEAR(zs, 2 * f, 1e-15);
    const double w = 0.036, h = 0.024, R = f / (2 * N);
    double film[][2] = {{180, 120}, {0, 0}, {359.9, 17.25}, {40.5, 230}};
    for (int i = 0; i < 4; i++) {
        double sx = (film[i][0] / W - 0.5) * w, sy = (0.5 - film[i][1] / H) * h;
        /* every lens point's ray passes through the conjugate point (sx, sy)/m
         * on the focus plane; m = 1 here, so the object is the film point's
         * mirror image at the same size */
        for (int k = 0; k < 16; k++) {
            lf_camera_sample cs = {film[i][0], film[i][1], rnd(), rnd(), 0, 0.5};
            lf_camera_ray r;
            double wt = t->generate_ray(c, &cs, &r);
            CHECK(wt > 0);
            double x, y;
            cross_plane(&r, 2 * f, &x, &y);
            CHECK_NEAR(x, sx, 1e-13);
            CHECK_NEAR(y, sy, 1e-13);
            CHECK(r.origin[2] == 0 && hypot(r.origin[0], r.origin[1]) <= R * (1 + 1e-12));
            /* weight = A_ap cos^4(theta) / z_s^2, theta of the ray film point -> lens point */
            double dx = r.origin[0] + sx, dy = r.origin[1] + sy;
            double cos2 = zs * zs / (dx * dx + dy * dy + zs * zs);
            CHECK_NEAR(wt, M_PI * R * R * cos2 * cos2 / (zs * zs), 1e-12 * wt);
        }
    }
    /* Upright, oriented like pbrt's perspective: the top-left pixel looks
     * left (-x) and up (+y). */
    lf_camera_sample tl = {0.5, 0.5, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r;
    t->generate_ray(c, &tl, &r);
    CHECK(r.dir[0] < 0 && r.dir[1] > 0 && r.dir[2] > 0);
    /* chief ray (lens centre: sample (0.5, 0.5)) at the left edge: half the FOV */
    lf_camera_sample le = {0, H / 2, 0.5, 0.5, 0, 0.5};
    t->generate_ray(c, &le, &r);
    CHECK(r.origin[0] == 0 && r.origin[1] == 0);
    CHECK_NEAR(2 * atan2(-r.dir[0], r.dir[2]), 2 * atan(w / (2 * zs)), 1e-12);
    t->destroy(c);

    /* FOV against the formula for several focus distances (focus breathing):
     * FOV = 2 atan(w / 2 z_s), z_s from the thin lens equation; top edge for
     * the vertical FOV with h = w H/W. */
    double focus[] = {1e6, 10, 2, 0.3, 0.06};
    for (int i = 0; i < 5; i++) {
        store s2 = {{{"focusdistance", {focus[i]}, 1, NULL}, {"sensor", {0}, 0, "apsc"}}, 2, 0};
        c = make("thinlens", &s2, 600, 400, err);
        CHECK_MSG(c != NULL, "%s", err);
        if (!c)
            continue;
        double z = thin_zs(0.05, focus[i]);
        lf_camera_sample right = {600, 200, 0.5, 0.5, 0, 0.5}, top = {300, 0, 0.5, 0.5, 0, 0.5};
        t->generate_ray(c, &right, &r);
        CHECK_NEAR(2 * atan2(r.dir[0], r.dir[2]), 2 * atan(0.0236 / (2 * z)), 1e-12);
        t->generate_ray(c, &top, &r);
        CHECK_NEAR(2 * atan2(r.dir[1], r.dir[2]), 2 * atan(0.0236 * 400 / 600 / (2 * z)), 1e-12);
        /* magnification: the chief ray of sensor point sx meets the focus
         * plane at sx / m, m = z_s / z_o */
        lf_camera_sample q = {450, 100, 0.5, 0.5, 0, 0.5};
        t->generate_ray(c, &q, &r);
        double x, y;
        cross_plane(&r, focus[i], &x, &y);
        double m = z / focus[i];
        CHECK_NEAR(x * m, (450.0 / 600 - 0.5) * 0.0236, 1e-12 * fmax(1, focus[i]));
        CHECK_NEAR(y * m, (0.5 - 100.0 / 400) * 0.0236 * 400 / 600, 1e-12 * fmax(1, focus[i]));
        t->destroy(c);
    }
}

/* The blur circle: the rim ray that reaches the edge of the blur disk of an
 * on-axis point at depth z passes through that point.  Geometry: the point
 * images at z_i; the ray from it through the rim (R, 0) reaches the sensor
 * at x = R (1 - z_s/z_i), i.e. radius C/2 = R |z_s - z_i| / z_i. */
static void test_thinlens_blur_circle(void)
{
    const lf_camera_type *t = lf_camera_find("thinlens");
    const double f = 0.085, N = 1.8, d = 3.0, W = 3000, H = 2000, w = 0.036;
    store s = {{{"focallength", {85}, 1, NULL}, {"fstop", {N}, 1, NULL}, {"focusdistance", {d}, 1, NULL}}, 3, 0};
    char err[512];
    void *c = make("thinlens", &s, (int)W, (int)H, err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    double zs = thin_zs(f, d), R = f / (2 * N), A = f / N;
    double depths[] = {0.7, 1.5, 2.5, 4.0, 20.0};
    for (int i = 0; i < 5; i++) {
        double z = depths[i], zi = thin_zs(f, z);
        double C = A * fabs(zs - zi) / zi;
        CHECK_NEAR(C, A * zs * fabs(1 / d - 1 / z), 1e-12); /* the two forms in docs/physics.md */
        double phys_x = R * (1 - zs / zi);                   /* physical film point */
        CHECK_NEAR(fabs(phys_x), C / 2, 1e-12);
        double sx = -phys_x; /* upright coordinate */
        lf_camera_sample cs = {(sx / w + 0.5) * W, H / 2, 1.0, 0.5, 0, 0.5}; /* lens (u,v) = (1, .5): rim point (R, 0) */
        lf_camera_ray r;
        CHECK(t->generate_ray(c, &cs, &r) > 0);
        CHECK_NEAR(r.origin[0], R, 1e-15);
        double x, y;
        cross_plane(&r, z, &x, &y);
        CHECK_MSG(fabs(x) < 1e-9 && fabs(y) < 1e-12, "depth %g: rim ray misses the axis point by %g m", z, x);
    }
    t->destroy(c);
}

/* Seed table of sensor sizes (issue 3), checked through the FOV each
 * produces at infinity focus with a 50 mm lens, the image aspect matching. */
static void test_sensor_table(void)
{
    static const struct {
        const char *name;
        double w, h;
    } table[] = {{"mediumformat", 53.7, 40.2}, {"fullframe", 36, 24},     {"apsh", 27.9, 18.6},
                 {"apsc", 23.6, 15.8},         {"fourthirds", 17.3, 13},  {"1inch", 13.2, 8.8},
                 {"1/1.63in", 8.38, 5.59},     {"1/2.3in", 6.16, 4.62},   {"1/3.2in", 4.54, 3.42}};
    const lf_camera_type *t = lf_camera_find("thinlens");
    for (int i = 0; i < 9; i++) {
        int Wp = 1000, Hp = (int)lround(1000 * table[i].h / table[i].w);
        store s = {{{"sensor", {0}, 0, table[i].name}, {"focusdistance", {1e6}, 1, NULL}}, 2, 0};
        char err[512] = "";
        void *c = make("thinlens", &s, Wp, Hp, err);
        CHECK_MSG(c != NULL, "sensor %s: %s", table[i].name, err);
        if (!c)
            continue;
        CHECK_MSG(last_warning[0] == '\0', "sensor %s at matching aspect warns: %s", table[i].name, last_warning);
        double zs = thin_zs(0.05, 1e6);
        lf_camera_sample right = {Wp, Hp / 2.0, 0.5, 0.5, 0, 0.5};
        lf_camera_ray r;
        t->generate_ray(c, &right, &r);
        CHECK_MSG(fabs(atan2(r.dir[0], r.dir[2]) - atan(table[i].w * 1e-3 / (2 * zs))) < 1e-12, "sensor %s width",
                  table[i].name);
        t->destroy(c);
    }
    /* a 1:1 image on a 3:2 sensor: the width is kept, with a warning */
    store s = {{{"sensor", {0}, 0, "fullframe"}}, 1, 0};
    char err[512];
    void *c = make("thinlens", &s, 100, 100, err);
    CHECK(c != NULL);
    CHECK_MSG(strstr(last_warning, "square") != NULL, "warning: %s", last_warning);
    t->destroy(c);
    store cs = {{{"sensorsize", {10, 5}, 2, NULL}}, 1, 0};
    c = make("thinlens", &cs, 200, 100, err);
    CHECK(c != NULL && last_warning[0] == '\0');
    t->destroy(c);
}

/* Reads "key...: value" from describe() output. */
static double fact(const char *text, const char *key)
{
    const char *p = strstr(text, key);
    if (!p)
        return NAN;
    p = strchr(p, ':');
    return p ? strtod(p + 1, NULL) : NAN;
}

static void test_explain(void)
{
    const lf_camera_type *t = lf_camera_find("thinlens");
    CHECK(t->describe != NULL);
    const double f = 0.035, N = 5.6, d = 4.0;
    store s = {{{"focallength", {35}, 1, NULL}, {"fstop", {N}, 1, NULL}, {"focusdistance", {d}, 1, NULL}}, 3, 0};
    char err[512];
    void *c = make("thinlens", &s, 1800, 1200, err);
    CHECK(c != NULL);
    char buf[4096];
    int n = t->describe(c, buf, sizeof buf);
    CHECK(n > 0 && n < (int)sizeof buf);
    CHECK(t->describe(c, NULL, 0) == n);
    double zs = thin_zs(f, d);
    double coc = hypot(36, 24) / 1500 * 1e-3; /* default: diagonal / 1500 */
    double Hf = f * f / (N * coc) + f;
    double near = d * (Hf - f) / (Hf + d - 2 * f), far = d * (Hf - f) / (Hf - d);
    double pitch = 0.036 / 1800;
    CHECK_NEAR(fact(buf, "sensor distance z_s"), zs * 1e3, 1e-6 * zs * 1e3);
    CHECK_NEAR(fact(buf, "magnification"), zs / d, 1e-5 * zs / d);
    CHECK_NEAR(fact(buf, "horizontal FOV"), 2 * atan(0.018 / zs) * 180 / M_PI, 1e-4);
    CHECK_NEAR(fact(buf, "vertical FOV"), 2 * atan(0.012 / zs) * 180 / M_PI, 1e-4);
    CHECK_NEAR(fact(buf, "diagonal FOV"), 2 * atan(hypot(0.018, 0.012) / zs) * 180 / M_PI, 1e-4);
    CHECK_NEAR(fact(buf, "circle of confusion"), coc * 1e3, 1e-6);
    CHECK_NEAR(fact(buf, "hyperfocal"), Hf, 1e-5 * Hf);
    CHECK_NEAR(fact(buf, "near limit"), near, 1e-5 * near);
    CHECK_NEAR(fact(buf, "far limit"), far, 1e-5 * far);
    CHECK_NEAR(fact(buf, "blur diameter at 8 m"), f / N * zs * fabs(1 / d - 1 / 8.0) / pitch, 1e-4);
    CHECK_NEAR(fact(buf, "blur diameter at infinity"), f / N * zs / d / pitch, 1e-4);
    t->destroy(c);
    /* beyond the hyperfocal distance the far limit is infinite */
    store s2 = {{{"focallength", {24}, 1, NULL}, {"fstop", {11}, 1, NULL}, {"focusdistance", {5}, 1, NULL},
                 {"coc", {0.03}, 1, NULL}},
                4, 0};
    c = make("thinlens", &s2, 300, 200, err);
    t->describe(c, buf, sizeof buf);
    CHECK(0.024 * 0.024 / (11 * 0.03e-3) + 0.024 < 5); /* H = 1.77 m < s */
    CHECK(strstr(buf, "far limit of acceptable sharpness: infinity") != NULL);
    t->destroy(c);
}

/* Hard cases: finite rays and weights everywhere, clear errors. */
static void check_finite(const char *what, const char *type, store *s, int W, int H)
{
    char err[512] = "";
    void *c = make(type, s, W, H, err);
    CHECK_MSG(c != NULL, "%s: %s", what, err);
    if (!c)
        return;
    const lf_camera_type *t = lf_camera_find(type);
    int bad = 0, zero = 0;
    for (int k = 0; k < 20000; k++) {
        lf_camera_sample cs = {rnd() * W, rnd() * H, rnd(), rnd(), 0, 0.5};
        if (k < 4) /* exact corners of film and lens */
            cs.film_x = k & 1 ? W : 0, cs.film_y = k & 2 ? H : 0, cs.lens_u = cs.lens_v = k < 2 ? 0 : 0x1.fffffp-1;
        lf_camera_ray r;
        double w = t->generate_ray(c, &cs, &r);
        double len = sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
        if (!(w >= 0) || !isfinite(w))
            bad++;
        else if (w == 0)
            zero++;
        else if (!(fabs(len - 1) < 1e-9) || !isfinite(r.origin[0]) || !isfinite(r.origin[1]) || !(r.dir[2] > 0))
            bad++;
    }
    CHECK_MSG(bad == 0, "%s: %d non-finite rays or weights", what, bad);
    CHECK_MSG(zero == 0, "%s: %d zero-weight rays", what, zero);
    t->destroy(c);
}

static void test_hard_cases(void)
{
    store s1 = {{{"fstop", {0.7}, 1, NULL}}, 1, 0};
    check_finite("f/0.7", "thinlens", &s1, 64, 48);
    store s2 = {{{"fstop", {64}, 1, NULL}}, 1, 0};
    check_finite("f/64", "thinlens", &s2, 64, 48);
    store s3 = {{{"focusdistance", {1e6}, 1, NULL}}, 1, 0};
    check_finite("focus at 1e6 m", "thinlens", &s3, 64, 48);
    store s4 = {{{"focusdistance", {1.0001 * 0.05}, 1, NULL}}, 1, 0};
    check_finite("focus at 1.0001 f", "thinlens", &s4, 64, 48);
    store s5 = {{{"aperture", {0}, 0, "star"}, {"fstop", {0.7}, 1, NULL}, {"anamorphic", {2}, 1, NULL}}, 3, 0};
    check_finite("star f/0.7 anamorphic", "thinlens", &s5, 64, 48);
    store s6 = {{{"aperture", {0}, 0, "ring.png"}}, 1, 1};
    check_finite("image aperture", "thinlens", &s6, 64, 48);
    store s7 = {{{"fov", {1e-4}, 1, NULL}, {"lensradius", {0.1}, 1, NULL}}, 2, 0};
    check_finite("perspective fov 1e-4 deg", "perspective", &s7, 64, 48);
    store s8 = {{{"fov", {179.9999}, 1, NULL}, {"lensradius", {0.1}, 1, NULL}, {"focaldistance", {0.01}, 1, NULL}},
                3, 0};
    check_finite("perspective fov 179.9999 deg", "perspective", &s8, 64, 48);

    /* 1.0001 f: z_s = f z_o/(z_o - f) = 10001 f, finite and in describe() */
    const lf_camera_type *t = lf_camera_find("thinlens");
    char err[512] = "", buf[4096];
    void *c = make("thinlens", &s4, 64, 48, err);
    t->describe(c, buf, sizeof buf);
    CHECK_NEAR(fact(buf, "sensor distance z_s"), thin_zs(0.05, 1.0001 * 0.05) * 1e3, 1e-3);
    CHECK(fabs(thin_zs(0.05, 1.0001 * 0.05) / 0.05 - 10001) < 1e-6);
    t->destroy(c);
    /* focus at 1e6 m: z_s = f within 2.5e-9 relative */
    c = make("thinlens", &s3, 64, 48, err);
    t->describe(c, buf, sizeof buf);
    CHECK_NEAR(fact(buf, "sensor distance z_s"), 50.0, 50.0 * 1e-7);
    t->destroy(c);

    /* errors that say what is wrong */
    store e1 = {{{"focusdistance", {0.04}, 1, NULL}}, 1, 0};
    CHECK(make("thinlens", &e1, 10, 10, err) == NULL);
    CHECK_MSG(strstr(err, "closer than the focal length") != NULL, "%s", err);
    store e1b = {{{"focusdistance", {0.05}, 1, NULL}}, 1, 0}; /* exactly f: image at infinity */
    CHECK(make("thinlens", &e1b, 10, 10, err) == NULL);
    store e2 = {{{"fstop", {0}, 1, NULL}}, 1, 0};
    CHECK(make("thinlens", &e2, 10, 10, err) == NULL && strstr(err, "fstop"));
    store e3 = {{{"focallength", {-50}, 1, NULL}}, 1, 0};
    CHECK(make("thinlens", &e3, 10, 10, err) == NULL && strstr(err, "focallength"));
    store e4 = {{{"sensor", {0}, 0, "vistavision"}}, 1, 0};
    CHECK(make("thinlens", &e4, 10, 10, err) == NULL && strstr(err, "vistavision") && strstr(err, "apsc"));
    store e5 = {{{"sensor", {0}, 0, "apsc"}, {"sensorsize", {10, 5}, 2, NULL}}, 2, 0};
    CHECK(make("thinlens", &e5, 10, 10, err) == NULL && strstr(err, "not both"));
    store e6 = {{{"aperture", {0}, 0, "allblack.png"}}, 1, 2};
    CHECK(make("thinlens", &e6, 10, 10, err) == NULL);
    CHECK_MSG(strstr(err, "allblack.png") && strstr(err, "all black"), "%s", err);
    CHECK(make("perspective", &e6, 10, 10, err) == NULL && strstr(err, "allblack.png"));
}

/* Camera equation on axis: for the centre film point and a circular
 * aperture of radius R at distance z_s, (1/z_s^2) \int cos^4 dA =
 * pi R^2 / (z_s^2 + R^2); the mean weight over the lens must equal it. */
static void test_thinlens_weights(void)
{
    const lf_camera_type *t = lf_camera_find("thinlens");
    double fst[] = {0.7, 2, 8};
    for (int i = 0; i < 3; i++) {
        store s = {{{"fstop", {fst[i]}, 1, NULL}, {"focusdistance", {1.5}, 1, NULL}}, 2, 0};
        char err[512];
        void *c = make("thinlens", &s, 100, 100, err);
        double zs = thin_zs(0.05, 1.5), R = 0.05 / (2 * fst[i]);
        double sum = 0;
        const int S = 512;
        for (int j = 0; j < S; j++)
            for (int k = 0; k < S; k++) {
                lf_camera_sample cs = {50, 50, (k + 0.5) / S, (j + 0.5) / S, 0, 0.5};
                lf_camera_ray r;
                sum += t->generate_ray(c, &cs, &r);
            }
        double expected = M_PI * R * R / (zs * zs + R * R);
        /* midpoint rule on 512^2 strata of a smooth integrand: < 1e-4 relative */
        CHECK_MSG(fabs(sum / (S * S) - expected) <= 1e-4 * expected, "f/%g: mean weight %.8g, expected %.8g", fst[i],
                  sum / (S * S), expected);
        t->destroy(c);
    }
}

/* ---- pbrt's perspective with apertures ---- */

static void test_perspective_apertures(void)
{
    const lf_camera_type *t = lf_camera_find("perspective");
    char err[512];
    /* zero lens radius equals the pinhole bit for bit, whatever the aperture */
    store pin = {{{"fov", {37}, 1, NULL}}, 1, 0};
    store zero = {{{"fov", {37}, 1, NULL},
                   {"lensradius", {0}, 1, NULL},
                   {"focaldistance", {2.5}, 1, NULL},
                   {"aperture", {0}, 0, "polygon"},
                   {"blades", {7}, 1, NULL}},
                  5, 0};
    void *a = make("perspective", &pin, 91, 57, err), *b = make("perspective", &zero, 91, 57, err);
    CHECK(a && b);
    CHECK(t->needs(a) == 0 && t->needs(b) == 0);
    int diff = 0;
    for (int k = 0; k < 5000; k++) {
        lf_camera_sample cs = {rnd() * 91, rnd() * 57, rnd(), rnd(), 0, 0.5};
        lf_camera_ray ra, rb;
        memset(&ra, 0, sizeof ra);
        memset(&rb, 0, sizeof rb);
        double wa = t->generate_ray(a, &cs, &ra), wb = t->generate_ray(b, &cs, &rb);
        if (wa != wb || memcmp(ra.origin, rb.origin, sizeof ra.origin) || memcmp(ra.dir, rb.dir, sizeof ra.dir))
            diff++;
    }
    CHECK_MSG(diff == 0, "%d rays differ between lensradius 0 and the pinhole", diff);
    t->destroy(a);
    t->destroy(b);

    /* A polygon lens: points inside the polygon of circumradius lensradius,
     * corners reached, and every ray still meets the pinhole ray on the
     * focus plane (pbrt semantics unchanged). */
    const double lr = 0.08, fd = 3.0;
    store poly = {{{"fov", {50}, 1, NULL},
                   {"lensradius", {lr}, 1, NULL},
                   {"focaldistance", {fd}, 1, NULL},
                   {"aperture", {0}, 0, "pentagon"}},
                  4, 0};
    void *c = make("perspective", &poly, 64, 64, err);
    CHECK_MSG(c != NULL, "%s", err);
    CHECK(t->needs(c) & LF_CAMERA_NEEDS_LENS);
    lf_camera_sample pc = {20.5, 40.25, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r0;
    t->generate_ray(c, &pc, &r0);
    double fx, fy;
    cross_plane(&r0, fd, &fx, &fy);
    double rmax = 0, ymax = 0, ymin = 0;
    int outside = 0;
    for (int k = 0; k < 20000; k++) {
        lf_camera_sample cs = pc;
        cs.lens_u = rnd(), cs.lens_v = rnd();
        lf_camera_ray r;
        if (t->generate_ray(c, &cs, &r) != 1.0) /* pbrt's weight, unchanged by the shape */
            outside++;
        double x, y;
        cross_plane(&r, fd, &x, &y);
        if (fabs(x - fx) > 1e-12 || fabs(y - fy) > 1e-12)
            outside++;
        double ox = r.origin[0] / lr, oy = r.origin[1] / lr;
        /* inside the pentagon with a corner up: every edge normal at
         * angle 90 + 36 + 72k degrees has projection <= cos 36 */
        for (int e = 0; e < 5; e++) {
            double a2 = M_PI / 2 + M_PI / 5 + 2 * M_PI * e / 5;
            if (ox * cos(a2) + oy * sin(a2) > cos(M_PI / 5) + 1e-12)
                outside++;
        }
        rmax = fmax(rmax, hypot(ox, oy));
        ymax = fmax(ymax, oy);
        ymin = fmin(ymin, oy);
    }
    CHECK_MSG(outside == 0, "%d lens points off the pentagon or rays off the focus point", outside);
    /* 20000 uniform points: P(y > 0.97) = 1.376 0.03^2 / 2.378 = 5.2e-4 per point, ~10 expected */
    CHECK_MSG(rmax <= 1 + 1e-12 && ymax > 0.97 && ymin < -cos(M_PI / 5) + 0.01 && ymin >= -cos(M_PI / 5) - 1e-12,
              "pentagon lens extent: r %.6f, y in [%.6f, %.6f]", rmax, ymin, ymax);
    t->destroy(c);
}

int main(void)
{
    test_apertures();
    test_thinlens_geometry();
    test_thinlens_blur_circle();
    test_sensor_table();
    test_explain();
    test_hard_cases();
    test_thinlens_weights();
    test_perspective_apertures();
    return lf_test_end();
}
