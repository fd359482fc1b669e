/* Camera pack tests: pbrt-v4 projection formulas for the projective cameras,
 * thin-lens focusing, and properties every registered camera must have. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
static const char *g_string(void *c, const char *name, const char *def)
{
    (void)c;
    if (!strcmp(name, "lensfile") && !strcmp(current_camera, "realistic"))
        return "lenses/dgauss.50mm.dat";
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

int main(void)
{
    test_perspective_projection();
    test_thin_lens_focus();
    test_orthographic();
    test_bad_parameters();
    test_all_cameras_properties();
    return lf_test_end();
}
