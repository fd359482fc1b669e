/* Camera pack tests: pbrt-v4 projection formulas for the projective cameras,
 * thin-lens focusing, and properties every registered camera must have. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera_internal.h"
#include "camera/lf_camera.h"
#include "lf_test.h"

/* A tiny parameter store standing in for the scene file. */
typedef struct kv {
    const char *name;
    double v[4];
    int n;
} kv;
typedef struct store {
    kv items[8];
    int n;
} store;

static const kv *find(store *s, const char *name)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->items[i].name, name))
            return &s->items[i];
    return NULL;
}
static double g_float(void *c, const char *name, double def)
{
    const kv *k = find(c, name);
    return k ? k->v[0] : def;
}
static int g_int(void *c, const char *name, int def)
{
    const kv *k = find(c, name);
    return k ? (int)k->v[0] : def;
}
static int g_bool(void *c, const char *name, int def)
{
    return g_int(c, name, def);
}
/* The realistic camera needs a prescription: it gets the shipped double
 * Gauss (relative to scenes/).  Other cameras (plenoptic takes an optional
 * lensfile) keep their defaults. */
static const char *current_camera = "";
static const char *current_aperture = NULL; /* "string aperture", when set */
static const char *g_string(void *c, const char *name, const char *def)
{
    (void)c;
    if (!strcmp(name, "lensfile") && !strcmp(current_camera, "realistic"))
        return "lenses/dgauss.50mm.dat";
    if (!strcmp(name, "mapping") && !strcmp(current_camera, "spherical"))
        return "equirectangular"; /* equal area needs a square image (tests/test_camera_spherical.c) */
    if (!strcmp(name, "aperture") && current_aperture)
        return current_aperture;
    return def;
}
static int g_floats(void *c, const char *name, double *out, int max)
{
    const kv *k = find(c, name);
    if (!k)
        return 0;
    for (int i = 0; i < k->n && i < max; i++)
        out[i] = k->v[i];
    return k->n;
}

static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images in this test (%s)", path);
    return -1;
}

static void *make(const char *type, store *s, int w, int h, char *err)
{
    lf_camera_params p = {s, g_float, g_int, g_bool, g_string, g_floats, g_image};
    char warn[256] = "";
    lf_camera_create_args a = {sizeof a, &p, w, h, 35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes", err, 512, warn, sizeof warn};
    void *state = NULL;
    const lf_camera_type *t = lf_camera_find(type);
    if (!t || t->create(&a, &state))
        return NULL;
    return state;
}

static void test_perspective_projection(void)
{
    /* pbrt: fov spans the shorter axis; raster (0,0) top-left, screen y up.
     * A pixel at raster (x, y) of a W x H image looks along
     * ((2x/H - W/H) tan(fov/2), (1 - 2y/H) tan(fov/2), 1) for W >= H. */
    store s = {{{"fov", {40}, 1}}, 1};
    char err[512];
    int W = 300, H = 200;
    void *c = make("perspective", &s, W, H, err);
    CHECK(c != NULL);
    const lf_camera_type *t = lf_camera_find("perspective");
    CHECK(t->needs(c) == 0); /* pinhole: no lens samples */
    double th = tan(20 * M_PI / 180);
    double pts[][2] = {{0, 0}, {150, 100}, {299.5, 10.25}, {37, 199}};
    for (int i = 0; i < 4; i++) {
        lf_camera_sample cs = {pts[i][0], pts[i][1], 0.5, 0.5, 0, 0.5};
        lf_camera_ray r;
        double w = t->generate_ray(c, &cs, &r);
        CHECK(w == 1.0);
        double ex = (2 * pts[i][0] / H - (double)W / H) * th, ey = (1 - 2 * pts[i][1] / H) * th;
        CHECK_NEAR(r.dir[0] / r.dir[2], ex, 1e-12);
        CHECK_NEAR(r.dir[1] / r.dir[2], ey, 1e-12);
        CHECK_NEAR(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2], 1.0, 1e-12);
        CHECK(r.origin[0] == 0 && r.origin[1] == 0 && r.origin[2] == 0);
    }
    t->destroy(c);

    /* Tall image: the fov spans x. */
    c = make("perspective", &s, 100, 400, err);
    lf_camera_sample edge = {100, 200, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r;
    t->generate_ray(c, &edge, &r);
    CHECK_NEAR(atan2(r.dir[0], r.dir[2]) * 180 / M_PI, 20.0, 1e-9);
    t->destroy(c);
}

static void test_thin_lens_focus(void)
{
    /* pbrt semantics: every lens sample of a pixel meets the pinhole ray on
     * the plane z = focaldistance. */
    store s = {{{"fov", {50}, 1}, {"lensradius", {0.1}, 1}, {"focaldistance", {3.5}, 1}}, 3};
    char err[512];
    void *c = make("perspective", &s, 64, 64, err);
    const lf_camera_type *t = lf_camera_find("perspective");
    CHECK(t->needs(c) & LF_CAMERA_NEEDS_LENS);
    lf_camera_sample pin = {10.3, 50.7, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r0;
    t->generate_ray(c, &pin, &r0); /* lens (0.5, 0.5) is the disk centre */
    CHECK_NEAR(r0.origin[0], 0, 1e-15);
    double fx = r0.dir[0] / r0.dir[2] * 3.5, fy = r0.dir[1] / r0.dir[2] * 3.5;
    double max_r = 0;
    for (int i = 0; i < 64; i++) {
        lf_camera_sample cs = pin;
        cs.lens_u = (i % 8 + 0.5) / 8;
        cs.lens_v = (i / 8 + 0.5) / 8;
        lf_camera_ray r;
        CHECK(t->generate_ray(c, &cs, &r) == 1.0);
        double k = (3.5 - r.origin[2]) / r.dir[2];
        CHECK_NEAR(r.origin[0] + k * r.dir[0], fx, 1e-12);
        CHECK_NEAR(r.origin[1] + k * r.dir[1], fy, 1e-12);
        max_r = fmax(max_r, hypot(r.origin[0], r.origin[1]));
    }
    CHECK(max_r <= 0.1 + 1e-12 && max_r > 0.07);
    t->destroy(c);
}

static void test_orthographic(void)
{
    store s = {{{"screenwindow", {-2, 2, -1, 1}, 4}}, 1};
    char err[512];
    void *c = make("orthographic", &s, 200, 100, err);
    const lf_camera_type *t = lf_camera_find("orthographic");
    lf_camera_sample cs = {50, 25, 0.5, 0.5, 0, 0.5};
    lf_camera_ray r;
    t->generate_ray(c, &cs, &r);
    CHECK_NEAR(r.origin[0], -1.0, 1e-12); /* x: -2 + 50/200*4 */
    CHECK_NEAR(r.origin[1], 0.5, 1e-12);  /* y:  1 - 25/100*2 */
    CHECK(r.dir[0] == 0 && r.dir[1] == 0 && r.dir[2] == 1);
    t->destroy(c);
}

static void test_bad_parameters(void)
{
    char err[512] = "";
    store s = {{{"fov", {180}, 1}}, 1};
    CHECK(make("perspective", &s, 10, 10, err) == NULL);
    CHECK(strstr(err, "fov") != NULL);
    store s2 = {{{"lensradius", {-1}, 1}}, 1};
    CHECK(make("perspective", &s2, 10, 10, err) == NULL);
    store s3 = {{{"screenwindow", {0, 1}, 2}}, 1};
    CHECK(make("orthographic", &s3, 10, 10, err) == NULL);
}

/* Every registered camera: finite weights >= 0, unit directions, and the
 * same ray for the same sample (no hidden state). */
static void test_all_cameras_properties(void)
{
    CHECK(lf_camera_count() >= 2);
    for (int i = 0; i < lf_camera_count(); i++) {
        const lf_camera_type *t = lf_camera_at(i);
        current_camera = t->name;
        CHECK(t->abi_version == LF_CAMERA_ABI_VERSION);
        store s = {{{"lensradius", {0.05}, 1}}, 1};
        char err[512] = "";
        void *c = make(t->name, &s, 37, 23, err);
        CHECK_MSG(c != NULL, "camera %s: %s", t->name, err);
        if (!c)
            continue;
        unsigned state = 12345;
        int bad = 0;
        for (int k = 0; k < 20000; k++) {
            double u[6];
            for (int j = 0; j < 6; j++) {
                state = state * 1664525u + 1013904223u;
                u[j] = (state >> 8) * 0x1p-24;
            }
            /* include the exact corners and edges */
            if (k < 4) {
                u[0] = k & 1 ? 0x1.fffffep-1 : 0;
                u[1] = k & 2 ? 0x1.fffffep-1 : 0;
                u[2] = u[3] = k < 2 ? 0 : 0x1.fffffep-1;
            }
            lf_camera_sample cs = {u[0] * 37, u[1] * 23, u[2], u[3], u[4], u[5]};
            lf_camera_ray r, r2;
            double w = t->generate_ray(c, &cs, &r), w2 = t->generate_ray(c, &cs, &r2);
            double len = sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
            if (!(w >= 0) || !isfinite(w) || w != w2 || (w > 0 && fabs(len - 1) > 1e-9) ||
                memcmp(r.dir, r2.dir, sizeof r.dir) != 0)
                bad++;
        }
        CHECK_MSG(bad == 0, "camera %s: %d bad rays", t->name, bad);
        t->destroy(c);
    }
}

/* The branch-free concentric mapping with its polynomial sine and cosine
 * gives pbrt's points: r (cos phi, sin phi) with phi = pi/4 b/a (|a| > |b|)
 * or pi/2 - pi/4 a/b, computed here with libm. */
static void test_concentric_disk(void)
{
    double worst = 0;
    unsigned st = 99;
    for (int k = 0; k < 100000; k++) {
        double u, v;
        st = st * 1664525u + 1013904223u;
        u = (st >> 8) * 0x1p-24;
        st = st * 1664525u + 1013904223u;
        v = (st >> 8) * 0x1p-24;
        if (k < 9)
            u = (k % 3) * 0.5, v = (k / 3) * 0.5; /* centre, edges, corners, diagonals */
        double a = 2 * u - 1, b = 2 * v - 1, x, y, ex, ey;
        if (a == 0 && b == 0)
            ex = ey = 0;
        else if (fabs(a) > fabs(b))
            ex = a * cos(M_PI / 4 * (b / a)), ey = a * sin(M_PI / 4 * (b / a));
        else
            ex = b * cos(M_PI / 2 - M_PI / 4 * (a / b)), ey = b * sin(M_PI / 2 - M_PI / 4 * (a / b));
        lf_concentric_disk(u, v, &x, &y);
        double e = fmax(fabs(x - ex), fabs(y - ey));
        worst = e > worst ? e : worst;
    }
    CHECK_MSG(worst < 1e-15, "concentric disk differs from libm's by %g", worst);
}

/* generate_rays (what lfrender calls) gives exactly the rays and weights
 * of generate_ray, for every built-in camera and every aperture path,
 * including batches that end mid-chunk. */
static void test_batch_equals_single(void)
{
    struct {
        const char *camera, *aperture;
        store s;
    } cfg[] = {
        {"perspective", NULL, {{{"fov", {40}, 1}}, 1}},
        {"perspective", NULL, {{{"fov", {40}, 1}, {"lensradius", {0.05}, 1}, {"focaldistance", {3}, 1}}, 3}},
        {"perspective", "polygon", {{{"lensradius", {0.05}, 1}, {"anamorphic", {1.5}, 1}}, 2}},
        {"orthographic", NULL, {{{"lensradius", {0.05}, 1}, {"focaldistance", {2}, 1}}, 2}},
        {"orthographic", NULL, {{{"screenwindow", {-2, 2, -1, 1}, 4}}, 1}},
        {"thinlens", NULL, {{{"fstop", {2}, 1}, {"focusdistance", {3}, 1}}, 2}},
        {"thinlens", NULL, {{{"fstop", {1.4}, 1}, {"anamorphic", {1.33}, 1}}, 2}},
        {"thinlens", "polygon", {{{"blades", {7}, 1}, {"aperturerotation", {10}, 1}}, 2}},
        {"thinlens", "star", {{{"fstop", {4}, 1}}, 1}},
        {"realistic", NULL, {{{"aperturediameter", {20}, 1}}, 1}},
        {"lightfield", NULL, {{{"lensradius", {0.05}, 1}}, 1}},
        {"plenoptic", NULL, {{{"fstop", {2}, 1}}, 1}},
    };
    enum { N = 1237 }; /* not a multiple of any chunk size */
    lf_camera_sample *cs = malloc(sizeof *cs * N);
    lf_camera_ray *r1 = malloc(sizeof *r1 * N), *r2 = malloc(sizeof *r2 * N);
    double *w1 = malloc(sizeof *w1 * N), *w2 = malloc(sizeof *w2 * N);
    unsigned st = 7;
    for (int i = 0; i < N; i++) {
        double u[4];
        for (int j = 0; j < 4; j++) {
            st = st * 1664525u + 1013904223u;
            u[j] = (st >> 8) * 0x1p-24;
        }
        if (i < 4)
            u[2] = i & 1 ? 0.5 : 0x1.fffffep-1, u[3] = i & 2 ? 0.5 : 0; /* lens centre and edges */
        lf_camera_sample s = {u[0] * 64, u[1] * 48, u[2], u[3], 0.25, 0.5};
        cs[i] = s;
    }
    for (size_t c = 0; c < sizeof cfg / sizeof cfg[0]; c++) {
        const lf_camera_type *t = lf_camera_find(cfg[c].camera);
        current_camera = cfg[c].camera;
        current_aperture = cfg[c].aperture;
        char err[512] = "";
        void *state = make(cfg[c].camera, &cfg[c].s, 64, 48, err);
        current_aperture = NULL;
        CHECK_MSG(state != NULL, "%s: %s", cfg[c].camera, err);
        if (!state)
            continue;
        for (int i = 0; i < N; i++) {
            r1[i].time = r2[i].time = 0.25, r1[i].wavelength_nm = r2[i].wavelength_nm = 0;
            w1[i] = t->generate_ray(state, &cs[i], &r1[i]);
        }
        /* uneven batch sizes: 1, 2, 3, ... */
        for (int i = 0, n = 1; i < N; i += n, n++)
            lf_camera_generate_rays(t, state, i + n <= N ? n : N - i, cs + i, r2 + i, w2 + i);
        int differ = 0, lit = 0;
        for (int i = 0; i < N; i++) {
            lit += w1[i] > 0;
            if (w1[i] != w2[i] || (w1[i] > 0 && (memcmp(r1[i].origin, r2[i].origin, sizeof r1[i].origin) ||
                                                  memcmp(r1[i].dir, r2[i].dir, sizeof r1[i].dir))))
                differ++;
        }
        CHECK_MSG(differ == 0, "%s (config %zu): %d of %d batch rays differ from single rays", cfg[c].camera, c,
                  differ, N);
        CHECK_MSG(lit > N / 2, "%s (config %zu): only %d of %d rays carry weight", cfg[c].camera, c, lit, N);
        t->destroy(state);
    }
    free(cs), free(r1), free(r2), free(w1), free(w2);
}

int main(void)
{
    test_concentric_disk();
    test_batch_equals_single();
    test_perspective_projection();
    test_thin_lens_focus();
    test_orthographic();
    test_bad_parameters();
    test_all_cameras_properties();
    return lf_test_end();
}
