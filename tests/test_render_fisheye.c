/* The ideal "fisheye" camera: for each mapping, known directions must come
 * from the film points the mapping's formula gives (r = f theta,
 * 2 f sin(theta/2), f sin(theta), 2 f tan(theta/2); the expected positions
 * are computed here from those formulas, independently of camera/fisheye.c,
 * which inverts them), no ray outside the image circle, the batch entry
 * equal to single rays, and end to end: the image circle's area under a
 * uniform sky and a small emitter imaged where the formula puts it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lf_camera.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct store {
    const char *mapping;
    double fov, focal; /* focal 0: not given */
} store;

static double g_float(void *c, const char *name, double def)
{
    store *s = c;
    if (!strcmp(name, "fov") && s->fov > 0)
        return s->fov;
    if (!strcmp(name, "focallength") && s->focal > 0)
        return s->focal;
    return def;
}
static int g_int(void *c, const char *name, int def)
{
    (void)c, (void)name;
    return def;
}
static const char *g_string(void *c, const char *name, const char *def)
{
    store *s = c;
    return !strcmp(name, "mapping") && s->mapping ? s->mapping : def;
}
static int g_floats(void *c, const char *name, double *out, int max)
{
    (void)c, (void)name, (void)out, (void)max;
    return 0;
}
static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images here (%s)", path);
    return -1;
}

static void *make(store *s, int w, int h, double diag, char *err, size_t err_size)
{
    lf_camera_params p = {s, g_float, g_int, g_int, g_string, g_floats, g_image};
    char warn[256] = "";
    lf_camera_create_args a = {sizeof a, &p, w, h, diag, 0.0, 1.0, ".", err, err_size, warn, sizeof warn};
    void *state = NULL;
    const lf_camera_type *t = lf_camera_find("fisheye");
    if (!t || t->create(&a, &state))
        return NULL;
    return state;
}

/* r / f of each mapping, written from the textbook formulas. */
static double forward(const char *m, double theta)
{
    if (!strcmp(m, "equisolid"))
        return 2 * sin(theta / 2);
    if (!strcmp(m, "orthographic"))
        return sin(theta);
    if (!strcmp(m, "stereographic"))
        return 2 * tan(theta / 2);
    return theta;
}

static void test_mappings(void)
{
    const lf_camera_type *t = lf_camera_find("fisheye");
    CHECK(t != NULL);
    if (!t)
        return;
    const char *maps[] = {"equidistant", "equisolid", "orthographic", "stereographic"};
    const int W = 640, H = 426;
    const double diag = 28.0, f = 8.0;
    /* The film from pbrt's diagonal and the image aspect. */
    double fw = diag * W / hypot(W, H), fh = diag * H / hypot(W, H);
    for (int m = 0; m < 4; m++) {
        double fov = m == 2 ? 180 : 170;
        store s = {maps[m], fov, f};
        char err[512] = "";
        void *c = make(&s, W, H, diag, err, sizeof err);
        CHECK_MSG(c != NULL, "%s: %s", maps[m], err);
        if (!c)
            continue;
        CHECK(t->needs(c) == 0);
        /* directions (theta, phi) inside the circle and on the film */
        double dirs[][2] = {{0, 0}, {5, 0}, {20, 90}, {35, 200}, {50, 330}, {60, 180}, {70, 12}};
        int checked = 0;
        for (int k = 0; k < 7; k++) {
            double th = dirs[k][0] * M_PI / 180, ph = dirs[k][1] * M_PI / 180;
            double r = f * forward(maps[m], th);
            double x = r * cos(ph), y = r * sin(ph);
            if (fabs(x) > fw / 2 || fabs(y) > fh / 2)
                continue;
            checked++;
            lf_camera_sample cs = {(x / fw + 0.5) * W, (0.5 - y / fh) * H, 0.5, 0.5, 0, 0.5};
            lf_camera_ray ray;
            double w = t->generate_ray(c, &cs, &ray);
            CHECK_MSG(w == 1.0, "%s theta %g: weight %g", maps[m], dirs[k][0], w);
            double e[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            for (int i = 0; i < 3; i++)
                CHECK_MSG(fabs(ray.dir[i] - e[i]) < 1e-9, "%s theta %g phi %g: dir[%d] %.12f, expected %.12f", maps[m],
                          dirs[k][0], dirs[k][1], i, ray.dir[i], e[i]);
            CHECK(ray.origin[0] == 0 && ray.origin[1] == 0 && ray.origin[2] == 0);
        }
        CHECK(checked >= 5);
        /* The image circle: the film point at theta = fov/2 + 0.5 deg has no
         * ray, the one at fov/2 - 0.5 deg has one (along +x, then along -y). */
        for (int side = 0; side < 2; side++) {
            double th_out = fmin(fov / 2 + 0.5, m == 2 ? 90.0 : 179.0) * M_PI / 180;
            double r_in = f * forward(maps[m], (fov / 2 - 0.5) * M_PI / 180);
            double r_out = m == 2 ? f * 1.0001 : f * forward(maps[m], th_out);
            lf_camera_sample in = {side ? W / 2.0 : (r_in / fw + 0.5) * W, side ? (0.5 + r_in / fh) * H : H / 2.0,
                                   0.5, 0.5, 0, 0.5};
            lf_camera_sample out = {side ? W / 2.0 : (r_out / fw + 0.5) * W, side ? (0.5 + r_out / fh) * H : H / 2.0,
                                    0.5, 0.5, 0, 0.5};
            lf_camera_ray ray;
            CHECK_MSG(t->generate_ray(c, &in, &ray) == 1.0, "%s: no ray just inside the circle", maps[m]);
            CHECK_NEAR(acos(ray.dir[2]) * 180 / M_PI, fov / 2 - 0.5, 1e-7);
            CHECK_MSG(t->generate_ray(c, &out, &ray) == 0.0, "%s: a ray outside the circle", maps[m]);
        }
        /* The batch entry gives the single rays to the bit (uneven count). */
        enum { NB = 77 };
        lf_camera_sample bs[NB];
        lf_camera_ray br[NB], sr;
        double bw[NB];
        for (int i = 0; i < NB; i++)
            bs[i] = (lf_camera_sample){fmod(i * 37.31, W), fmod(i * 19.7, H), 0.5, 0.5, 0, 0.5};
        t->generate_rays(c, NB, bs, br, bw);
        int same = 1;
        for (int i = 0; i < NB; i++) {
            double sw = t->generate_ray(c, &bs[i], &sr);
            same &= sw == bw[i] && !memcmp(sr.dir, br[i].dir, sizeof sr.dir) &&
                    !memcmp(sr.origin, br[i].origin, sizeof sr.origin);
        }
        CHECK_MSG(same, "%s: batch differs from single rays", maps[m]);
        t->destroy(c);
    }
}

/* Without "focallength" the circle (theta = fov/2) touches the shorter
 * film sides; the default mapping is equidistant, the default fov 180. */
static void test_circular_default(void)
{
    const lf_camera_type *t = lf_camera_find("fisheye");
    store s = {NULL, 0, 0};
    char err[512] = "";
    void *c = make(&s, 300, 200, 35.0, err, sizeof err);
    CHECK_MSG(c != NULL, "%s", err);
    if (!c)
        return;
    lf_camera_ray ray;
    /* top edge centre, just inside: theta -> 90 deg, straight up (+y) */
    lf_camera_sample top = {150, 1e-6, 0.5, 0.5, 0, 0.5};
    CHECK(t->generate_ray(c, &top, &ray) == 1.0);
    CHECK_NEAR(ray.dir[1], 1.0, 1e-6);
    /* half way to the top: equidistant, theta = 45 deg */
    lf_camera_sample mid = {150, 50, 0.5, 0.5, 0, 0.5};
    t->generate_ray(c, &mid, &ray);
    CHECK_NEAR(acos(ray.dir[2]), M_PI / 4, 1e-12);
    /* the left edge is outside the circle on a wide film */
    lf_camera_sample left = {1, 100, 0.5, 0.5, 0, 0.5};
    CHECK(t->generate_ray(c, &left, &ray) == 0.0);
    t->destroy(c);

    /* bad input is refused with a message */
    store bad = {"fishy", 0, 0};
    CHECK(make(&bad, 300, 200, 35.0, err, sizeof err) == NULL && strstr(err, "mapping"));
    store badfov = {"orthographic", 200, 0};
    CHECK(make(&badfov, 300, 200, 35.0, err, sizeof err) == NULL && strstr(err, "fov"));
    store badst = {"stereographic", 360, 0};
    CHECK(make(&badst, 300, 200, 35.0, err, sizeof err) == NULL && strstr(err, "fov"));
}

/* Under a uniform sky of radiance L the image is L inside the circle and 0
 * outside; with the box filter each pixel averages its area, so the image's
 * sum is L times the circle's area in pixels, pi R^2. */
static void test_render_circle(void)
{
    const int W = 120, H = 80;
    const double L = 0.6;
    char scene[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"fisheye\" \"string mapping\" \"equisolid\" \"float fov\" [160]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n",
             W, H, L, L, L);
    lf_image img;
    char msg[1024];
    if (render_text(scene, NULL, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    double sum = 0, worst_in = 0, worst_out = 0;
    double R = H / 2.0; /* circular: the circle touches the top and bottom */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float v = lf_image_px(&img, x, y)[1];
            sum += v;
            double r = hypot(x + 0.5 - W / 2.0, y + 0.5 - H / 2.0);
            if (r < R - 0.75)
                worst_in = fmax(worst_in, fabs(v - L));
            if (r > R + 0.75)
                worst_out = fmax(worst_out, fabs(v));
        }
    CHECK_MSG(worst_in < 1e-6, "inside the circle: off by %g", worst_in);
    CHECK_MSG(worst_out == 0, "outside the circle: %g", worst_out);
    /* Only the ~2 pi R rim pixels are estimated (coverage by 64 stratified
     * points, error well under 1/8 of a pixel each, mostly cancelling):
     * 0.2% of pi R^2 is 10 pixels' worth. */
    double expected = L * M_PI * R * R;
    CHECK_MSG(fabs(sum - expected) < 0.002 * expected, "image sum %.3f, expected L pi R^2 = %.3f", sum, expected);
    lf_image_free(&img);
}

/* A small emitting sphere at a known direction (theta, phi) from the
 * camera appears centred where r = f g(theta) puts it.  Camera space is
 * world space here (LookAt along +z, +y up: pbrt's camera x is world x). */
static void test_render_emitter(void)
{
    const int W = 200, H = 200;
    const double diag = 30.0, f = 7.0;
    const char *maps[] = {"equidistant", "stereographic"};
    for (int m = 0; m < 2; m++) {
        double th = 55 * M_PI / 180, ph = 140 * M_PI / 180, dist = 20, rad = 0.3;
        double p[3] = {dist * sin(th) * cos(ph), dist * sin(th) * sin(ph), dist * cos(th)};
        char scene[2048];
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"fisheye\" \"string mapping\" \"%s\" \"float focallength\" [%g]"
                 " \"float fov\" [180]\n"
                 "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"float diagonal\" [%g]\n"
                 "Sampler \"zsobol\" \"integer pixelsamples\" [16]\nPixelFilter \"box\"\n"
                 "WorldBegin\nAttributeBegin\nTranslate %.9g %.9g %.9g\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                 "Shape \"sphere\" \"float radius\" [%g]\nAttributeEnd\n",
                 maps[m], f, W, H, diag, p[0], p[1], p[2], rad);
        lf_image img;
        char msg[1024];
        if (render_text(scene, NULL, &img, msg, sizeof msg)) {
            CHECK_MSG(0, "render failed: %s", msg);
            continue;
        }
        double sx = 0, sy = 0, s = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                float v = lf_image_px(&img, x, y)[0];
                sx += v * (x + 0.5), sy += v * (y + 0.5), s += v;
            }
        double fw = diag / sqrt(2.0), mmpx = fw / W;
        double r = f * forward(maps[m], th);
        double ex = W / 2.0 + r * cos(ph) / mmpx, ey = H / 2.0 - r * sin(ph) / mmpx;
        CHECK(s > 0);
        /* The sphere spans about 2 * 0.3/20 rad; its image's centroid sits
         * within a tenth of a pixel of the centre's image (the mapping's
         * curvature over so small a disk moves it far less). */
        CHECK_MSG(hypot(sx / s - ex, sy / s - ey) < 0.1, "%s: emitter at (%.2f, %.2f) px, formula says (%.2f, %.2f)",
                  maps[m], sx / s, sy / s, ex, ey);
        lf_image_free(&img);
    }
}

int main(void)
{
    test_mappings();
    test_circular_default();
    test_render_circle();
    test_render_emitter();
    return lf_test_end();
}
