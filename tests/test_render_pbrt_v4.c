/* pbrt-v4 scene semantics from issue 30, against independent numbers:
 *   - a disk area light under ReverseOrientation is the same emitter as the
 *     disk turned around (Rotate 180 about x): seen from below it shows its
 *     L exactly, and it lights a floor below it equally (mean within the
 *     stated Monte Carlo margin);
 *   - a parameter given twice in one statement takes the last value
 *     (pbrt-v4's ParameterDictionary); the same name with another type is
 *     still an unused parameter;
 *   - bdpt, mlt, sppm and lightpath accept pbrt-v4's parameters and render
 *     with the path tracer and a note; a wrong type is still an error;
 *   - "alpha": a black plane cut by a float checkerboard alpha (0.25 and 1,
 *     mean 0.625) passes 1 - 0.625 of a uniform sky to camera rays, and of
 *     a distant light's irradiance to a floor below it through shadow
 *     rays (closed forms; Bernoulli noise margins stated below); alpha 0
 *     hides a sphere;
 *   - silhouettes: a black cylinder (and a quarter of one), a partial disk
 *     (inner radius, phimax) and, in test_curves, curves in front of a sky
 *     of 1 hide the fraction of an orthographic window their projected
 *     area says (2 r (zmax - zmin) phi-clipped; (phimax / 2) (r^2 - ri^2)).
 * Seeds are fixed; margins are stated at each assertion. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <unistd.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"
#include "render/nanovdb_adapter.h"
#include "render/render_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double mean_channel(const lf_image *img, int c, int x0, int x1, int y0, int y1)
{
    double s = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            s += lf_image_px(img, x, y)[c];
    return s / ((double)(x1 - x0) * (y1 - y0));
}

static int render(const char *scene, lf_image *img, char *msg, size_t n)
{
    return render_text(scene, &(lf_test_scene){.threads = 2}, img, msg, n);
}

/* ---- disk light and ReverseOrientation ---- */
static void disk_scene(char *buf, size_t n, const char *orient, int floor)
{
    snprintf(buf, n,
             "LookAt 0 0 -5  0 0 0  0 1 0\n"
             "Camera \"orthographic\" \"float screenwindow\" [-0.4 0.4 -0.4 0.4]\n"
             "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [%d] \"integer seed\" [5]\n"
             "PixelFilter \"box\"\nWorldBegin\n"
             "AttributeBegin\n%s\nAreaLightSource \"diffuse\" \"rgb L\" [2 3 4]\n"
             "Shape \"disk\" \"float radius\" 1\nAttributeEnd\n%s",
             floor ? 256 : 1, orient,
             floor ? "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
                     "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
                     "  \"point3 P\" [-3 -3 -1  3 -3 -1  3 3 -1  -3 3 -1]\n"
                   : "");
}

static void test_disk_reverse_orientation(void)
{
    static const char *orients[3] = {"", "ReverseOrientation", "Rotate 180 1 0 0"};
    /* Seen from below (camera at z = -5 looking up +z): the plain disk faces
     * away (black), the reversed and the turned disk show L exactly. */
    for (int k = 0; k < 3; k++) {
        char scene[2048], msg[1024] = "";
        disk_scene(scene, sizeof scene, orients[k], 0);
        lf_image img = {0};
        int rc = render(scene, &img, msg, sizeof msg);
        CHECK_MSG(rc == 0, "%s", msg);
        if (rc)
            continue;
        double want[3] = {k ? 2 : 0, k ? 3 : 0, k ? 4 : 0};
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean_channel(&img, c, 2, 6, 2, 6), want[c], 1e-5);
        lf_image_free(&img);
    }
    /* The same emitters lighting a floor at z = -1 (next-event estimation
     * and BSDF hits both see the emitting side). */
    double floor_mean[3];
    for (int k = 0; k < 3; k++) {
        char scene[2048], msg[1024] = "", *q;
        disk_scene(scene, sizeof scene, orients[k], 1);
        /* a camera between disk and floor, looking down at the floor */
        q = strstr(scene, "LookAt 0 0 -5  0 0 0");
        memcpy(q, "LookAt 0 0 -.5 0 0 -1", 21);
        lf_image img = {0};
        int rc = render(scene, &img, msg, sizeof msg);
        CHECK_MSG(rc == 0, "%s", msg);
        floor_mean[k] = rc ? -1 : mean_channel(&img, 0, 0, 8, 0, 8);
        if (!rc)
            lf_image_free(&img);
    }
    /* Radiance of a Lambertian floor of albedo 0.5 on the axis of a disk of
     * radius 1 at height 1 emitting L = 2: E = pi L r^2 / (r^2 + h^2), so
     * Lo = 0.5 / pi * E = 0.5 * 2 * 1 / 2 = 0.5 at the centre; across the
     * 0.8 x 0.8 window the off-axis disk form factor is lower, by < 10 %.
     * The plain disk emits upwards: nothing reaches the floor. */
    CHECK_NEAR(floor_mean[0], 0.0, 1e-6);
    CHECK_MSG(floor_mean[1] > 0.45 && floor_mean[1] < 0.51, "reversed disk lights the floor: %g", floor_mean[1]);
    /* same emitter, independent samples: 256 spp x 64 pixels, relative
     * noise of the mean well under 1 %; 3 % margin */
    CHECK_MSG(fabs(floor_mean[1] - floor_mean[2]) < 0.03 * floor_mean[2], "reversed %g vs turned %g", floor_mean[1],
              floor_mean[2]);
}

/* ---- a parameter given twice ---- */
static void test_duplicate_parameters(void)
{
    char *ex = NULL, msg[1024] = "";
    int rc = render_text("LookAt 0 0 -5 0 0 0 0 1 0\n"
                         "Camera \"perspective\" \"float fov\" 30 \"float fov\" 45\n"
                         "Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
                         "WorldBegin\nShape \"sphere\"\n",
                         &(lf_test_scene){.explain = &ex}, NULL, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    CHECK_MSG(ex && strstr(ex, "fov 45"), "the last fov wins: %s", ex ? ex : "");
    free(ex);
    /* another type under the same name is not a duplicate: pbrt-v4 reads
     * the type it asks for and reports the other unused */
    rc = render_text("Camera \"perspective\" \"float fov\" 30 \"integer fov\" 45\nWorldBegin\nShape \"sphere\"\n", NULL,
                     NULL, msg, sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:1:"), "%s", msg);
}

/* ---- integrators rendered by the path tracer ---- */
static void test_integrator_params(void)
{
    static const char *cases[] = {
        "Integrator \"sppm\" \"float radius\" 0.05 \"integer photonsperiteration\" 1000 \"integer seed\" 3 "
        "\"integer maxdepth\" 4",
        "Integrator \"bdpt\" \"integer maxdepth\" 4 \"bool visualizestrategies\" false \"bool visualizeweights\" false "
        "\"bool regularize\" true",
        "Integrator \"mlt\" \"integer bootstrapsamples\" 1000 \"integer chains\" 10 \"integer mutationsperpixel\" 8 "
        "\"float largestepprobability\" 0.3 \"float sigma\" 0.01",
        "Integrator \"lightpath\" \"integer maxdepth\" 3",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char scene[1024], msg[1024] = "", *warn = NULL;
        snprintf(scene, sizeof scene, "%s\nFilm \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\n"
                 "WorldBegin\nLightSource \"infinite\"\nShape \"sphere\"\n", cases[i]);
        int rc = render_text(scene, &(lf_test_scene){.warnings = &warn}, NULL, msg, sizeof msg);
        CHECK_MSG(rc == 0, "%s: %s", cases[i], msg);
        CHECK_MSG(warn && strstr(warn, "test.pbrt:1:1") && strstr(warn, "using \"path\""), "%s", warn ? warn : "");
        free(warn);
    }
    char msg[1024] = "";
    int rc = render_text("Integrator \"sppm\" \"integer radius\" 1\nWorldBegin\nShape \"sphere\"\n", NULL, NULL, msg,
                         sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "radius"), "a mistyped sppm radius is an error: %s", msg);
    rc = render_text("Integrator \"path\" \"float radius\" 1\nWorldBegin\nShape \"sphere\"\n", NULL, NULL, msg,
                     sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "unused parameter"), "path has no radius: %s", msg);
}

/* ---- alpha cut-outs ---- */
#define ALPHA_PLANE                                                                                          \
    "Texture \"a\" \"float\" \"checkerboard\" \"float tex1\" 0.25 \"float tex2\" 1 \"float uscale\" 4 " \
    "\"float vscale\" 4\n"                                                                                   \
    "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n"                                     \
    "Shape \"trianglemesh\" \"texture alpha\" \"a\" \"integer indices\" [0 1 2 0 2 3]\n"                   \
    "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\nAttributeEnd\n"

static void test_alpha(void)
{
    const double pass = 1 - (0.25 + 1) / 2; /* 1 - mean alpha */
    char msg[1024] = "";
    lf_image img = {0};
    /* camera rays: 16 x 16 pixels x 64 spp, half of them on checks of
     * alpha 0.25 (Bernoulli 0.75): std of the mean 0.5 sqrt(0.1875 / 8192)
     * = 0.0024; margin 0.012 (5 sigma) */
    int rc = render("LookAt 0 0 5  0 0 0  0 1 0\n"
                    "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"
                    "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
                    "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [11]\n"
                    "PixelFilter \"box\"\nWorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n" ALPHA_PLANE,
                    &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        CHECK_NEAR(mean_channel(&img, 1, 0, 16, 0, 16), pass, 0.012);
        lf_image_free(&img);
    }
    /* shadow rays: a floor (albedo 0.5) at z = -1 under a vertical distant
     * light of irradiance 1, seen from between plane and floor: radiance
     * 0.5 / pi x (1 - mean alpha); same noise as above, relative margin 4 % */
    rc = render("LookAt 0 0 -0.5  0 0 -1  0 1 0\n"
                "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"
                "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
                "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [12]\n"
                "PixelFilter \"box\"\nWorldBegin\n"
                "LightSource \"distant\" \"point3 from\" [0 0 1] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n" ALPHA_PLANE
                "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
                "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
                "  \"point3 P\" [-9 -9 -1  9 -9 -1  9 9 -1  -9 9 -1]\n",
                &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        double want = 0.5 / M_PI * pass;
        CHECK_NEAR(mean_channel(&img, 1, 0, 16, 0, 16), want, 0.04 * want);
        lf_image_free(&img);
    }
    /* alpha 0: the sphere is not there (every sample sees the sky of 1) */
    rc = render("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"orthographic\"\n"
                "Film \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4]\n"
                "Sampler \"independent\" \"integer pixelsamples\" [4]\nWorldBegin\n"
                "LightSource \"infinite\" \"rgb L\" [1 1 1]\nShape \"sphere\" \"float alpha\" 0\n",
                &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        CHECK_NEAR(mean_channel(&img, 0, 0, 4, 0, 4), 1.0, 1e-6);
        lf_image_free(&img);
    }
    /* an area light with alpha 0 emits nothing, as pbrt-v4's
     * DiffuseAreaLight where AlphaMasked (kroken's disabled sphere light):
     * neither seen nor sampled, the floor under it stays black */
    rc = render("LookAt 0 0 -0.5  0 0 -1  0 1 0\nCamera \"orthographic\"\n"
                "Film \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4]\n"
                "Sampler \"independent\" \"integer pixelsamples\" [16]\nWorldBegin\n"
                "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [5 5 5]\nReverseOrientation\n"
                "Shape \"sphere\" \"float radius\" 0.3 \"float alpha\" 0\nAttributeEnd\n"
                "AttributeBegin\nTranslate 0 0 1\nAreaLightSource \"diffuse\" \"rgb L\" [5 5 5]\n"
                "Shape \"trianglemesh\" \"float alpha\" 0 \"integer indices\" [0 1 2 0 2 3] "
                "\"point3 P\" [-1 -1 0 1 -1 0 1 1 0 -1 1 0]\nAttributeEnd\n"
                "Material \"diffuse\"\nShape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] "
                "\"point3 P\" [-9 -9 -1 9 -9 -1 9 9 -1 -9 9 -1]\n",
                &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        CHECK_NEAR(mean_channel(&img, 0, 0, 4, 0, 4), 0.0, 1e-9);
        lf_image_free(&img);
    }
    /* a texture that is not there names the shape's parameter */
    rc = render_text("WorldBegin\nShape \"sphere\" \"texture alpha\" \"nope\"\n", NULL, NULL, msg, sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:") && strstr(msg, "nope"), "%s", msg);
}

/* ---- silhouettes against geometry ---- */
/* Fraction of an orthographic window [-w,w]^2 the black shapes in `shapes`
 * hide from a sky of 1 (camera at `eye` looking at the origin, up `up`). */
static double covered_fraction(const char *eye_up, double w, const char *shapes)
{
    char scene[8192], msg[1024] = "";
    snprintf(scene, sizeof scene,
             "LookAt %s\nCamera \"orthographic\" \"float screenwindow\" [%g %g %g %g]\n"
             "Film \"rgb\" \"integer xresolution\" [48] \"integer yresolution\" [48]\n"
             "Sampler \"stratified\" \"integer xsamples\" [6] \"integer ysamples\" [6] \"integer seed\" [3]\n"
             "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [1]\nWorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [1 1 1]\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n%s",
             eye_up, -w, w, -w, w, shapes);
    lf_image img = {0};
    int rc = render(scene, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (rc)
        return -1;
    double f = 1 - mean_channel(&img, 0, 0, img.width, 0, img.height);
    lf_image_free(&img);
    return f;
}

/* Stratified 6x6 per pixel on 48x48 pixels: only pixels on an edge are
 * partly covered; their error is below 1/36 of a pixel's area each, so a
 * silhouette of perimeter P (in pixels) is off by less than P/36 pixel
 * areas: ~0.1 % of the window for these shapes.  Margin 0.003 absolute. */
static void test_silhouettes(void)
{
    /* side view of a cylinder r 0.5, z in [-0.6, 0.6]: 2 r x 1.2 of 4 */
    double f = covered_fraction("0 -5 0  0 0 0  0 0 1", 1,
                                "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -0.6 \"float zmax\" 0.6\n");
    CHECK_NEAR(f, 1.0 * 1.2 / 4, 0.003);
    /* phimax 90: x = r cos(phi) spans [0, r] */
    f = covered_fraction("0 -5 0  0 0 0  0 0 1", 1,
                         "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -0.6 \"float zmax\" 0.6 "
                         "\"float phimax\" 90\n");
    CHECK_NEAR(f, 0.5 * 1.2 / 4, 0.003);
    /* zmin > zmax is ordered as pbrt-v4 does */
    f = covered_fraction("0 -5 0  0 0 0  0 0 1", 1,
                         "Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" 0.6 \"float zmax\" -0.6\n");
    CHECK_NEAR(f, 1.0 * 1.2 / 4, 0.003);
    /* partial disk, face on: (270/360) pi (1 - 0.25) of 2.4^2 */
    f = covered_fraction("0 0 5  0 0 0  0 1 0", 1.2,
                         "Shape \"disk\" \"float radius\" 1 \"float innerradius\" 0.5 \"float phimax\" 270\n");
    CHECK_NEAR(f, 0.75 * M_PI * 0.75 / (2.4 * 2.4), 0.003);
}

/* ---- curves ---- */
static void test_curves(void)
{
    static const struct {
        const char *shape;
        double area;
    } cases[] = {
        /* straight cubic Bezier along x, length 1.6, width 0.2 */
        {"\"point3 P\" [-0.8 0 0 -0.3 0 0 0.3 0 0 0.8 0 0] \"float width\" 0.2", 1.6 * 0.2},
        {"\"point3 P\" [-0.8 0 0 -0.3 0 0 0.3 0 0 0.8 0 0] \"float width\" 0.2 \"string type\" \"cylinder\"",
         1.6 * 0.2},
        /* tapered 0.1 -> 0.3: a trapezoid of mean width 0.2 */
        {"\"point3 P\" [-0.8 0 0 -0.3 0 0 0.3 0 0 0.8 0 0] \"float width0\" 0.1 \"float width1\" 0.3", 1.6 * 0.2},
        /* two segments sharing an end point */
        {"\"point3 P\" [-0.8 0 0 -0.6 0 0 -0.2 0 0 0 0 0 0.2 0 0 0.6 0 0 0.8 0 0] \"float width\" 0.2", 1.6 * 0.2},
        /* uniform cubic B-spline of collinear points -1.2 -0.4 0.4 1.2: one
         * segment from (p0 + 4 p1 + p2) / 6 = -0.4 to 0.4 */
        {"\"point3 P\" [-1.2 0 0 -0.4 0 0 0.4 0 0 1.2 0 0] \"string basis\" \"bspline\" \"float width\" 0.2",
         0.8 * 0.2},
        /* quadratic Bezier (degree 2) */
        {"\"point3 P\" [-0.8 0 0 0 0 0 0.8 0 0] \"integer degree\" 2 \"float width\" 0.2", 1.6 * 0.2},
        /* ribbon facing the camera (+z), and edge-on (normals +y) */
        {"\"point3 P\" [-0.8 0 0 -0.3 0 0 0.3 0 0 0.8 0 0] \"float width\" 0.2 \"string type\" \"ribbon\" "
         "\"normal N\" [0 0 1 0 0 1] \"integer splitdepth\" 5",
         1.6 * 0.2},
        {"\"point3 P\" [-0.8 0 0 -0.3 0 0 0.3 0 0 0.8 0 0] \"float width\" 0.2 \"string type\" \"ribbon\" "
         "\"normal N\" [0 1 0 0 1 0]",
         0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char shape[1024];
        snprintf(shape, sizeof shape, "Shape \"curve\" %s\n", cases[i].shape);
        double f = covered_fraction("0 0 5  0 0 0  0 1 0", 1, shape);
        CHECK_MSG(fabs(f - cases[i].area / 4) < 0.003, "%s: covered %g, geometry %g", cases[i].shape, f,
                  cases[i].area / 4);
    }
    /* a bent curve in the view plane: a band of width w around it covers
     * w x its arc length (Steiner; the ends are cut square), the length by
     * quadrature of |B'(u)| (2000 midpoint steps) */
    {
        static const double P[4][2] = {{-0.8, -0.4}, {-0.4, 0.6}, {0.4, 0.6}, {0.8, -0.4}};
        double L = 0;
        for (int i = 0; i < 2000; i++) {
            double u = (i + 0.5) / 2000, v = 1 - u, dx = 0, dy = 0;
            double db[4] = {-3 * v * v, 3 * v * v - 6 * u * v, 6 * u * v - 3 * u * u, 3 * u * u};
            for (int k = 0; k < 4; k++)
                dx += db[k] * P[k][0], dy += db[k] * P[k][1];
            L += sqrt(dx * dx + dy * dy) / 2000;
        }
        double f = covered_fraction("0 0 5  0 0 0  0 1 0", 1,
                                    "Shape \"curve\" \"point3 P\" [-0.8 -0.4 0 -0.4 0.6 0 0.4 0.6 0 0.8 -0.4 0] "
                                    "\"float width\" 0.1\n");
        CHECK_NEAR(f, 0.1 * L / 4, 0.003);
    }
    /* hit data: rays along -z at (x, y) onto a flat curve along +x */
    lf_scene_desc d;
    lf_scene s;
    lf_error err = {0};
    const char *text = "WorldBegin\nShape \"curve\" \"point3 P\" [-1 0 0 -0.33333333 0 0 0.33333333 0 0 1 0 0] "
                       "\"float width\" 0.4\n";
    if (lf_scene_parse_string(text, "curve.pbrt", &d, &err) == 0) {
        if (lf_scene_build(&d, &s, &err) == 0) {
            static const float xs[3] = {-0.5f, 0.f, 0.6f}, ys[3] = {0.1f, -0.15f, 0.f};
            for (int k = 0; k < 3; k++) {
                lf_hit h;
                int got = lf_scene_intersect(&s, lf_v3(xs[k], ys[k], 5), lf_v3(0, 0, -1), 100, 0, &h);
                CHECK(got);
                if (!got)
                    continue;
                CHECK_NEAR(h.t, 5, 1e-4);
                CHECK(h.curve == 1);
                CHECK_NEAR(h.curve_h, -2 * ys[k] / 0.4, 2e-3);
                CHECK_NEAR(h.sc.uv.y, 0.5 - ys[k] / 0.4, 1e-3);
                /* control points at thirds: x = -1 + 2 u */
                CHECK_NEAR(h.sc.uv.x, (xs[k] + 1) / 2, 1e-3);
                CHECK_NEAR(h.sc.dpdu.x, 1, 1e-5);
                CHECK_NEAR(fabsf(h.sc.ng.z), 1, 1e-5);
            }
            lf_scene_free(&s);
        } else {
            CHECK_MSG(0, "%s", err.msg);
        }
        lf_scene_desc_free(&d);
    } else {
        CHECK_MSG(0, "%s", err.msg);
    }
    /* ribbons need their normals */
    char msg[1024] = "";
    int rc = render_text("WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 0 0 2 0 0 3 0 0] \"string type\" "
                         "\"ribbon\"\n",
                         NULL, NULL, msg, sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:") && strstr(msg, "normal N"), "%s", msg);
}

/* ---- heterogeneous media ---- */
#define BOX_M1_1                                                                                             \
    "Shape \"trianglemesh\" \"integer indices\" [0 2 1 0 3 2  4 5 6 4 6 7  0 5 4 0 1 5  1 6 5 1 2 6  "      \
    "2 7 6 2 3 7  3 4 7 3 0 4]\n"                                                                              \
    "  \"point3 P\" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]\n"

/* int_0^1 of pbrt's SampledGrid along one axis of n samples v (the other
 * axes constant): linear between sample centres (i + 1/2) / n, falling to
 * half the end sample at the faces (its neighbour outside counts 0). */
static double grid_line_integral(const double *v, int n)
{
    double knots_u[16], knots_f[16];
    int k = 0;
    knots_u[k] = 0, knots_f[k++] = v[0] / 2;
    for (int i = 0; i < n; i++)
        knots_u[k] = (i + 0.5) / n, knots_f[k++] = v[i];
    knots_u[k] = 1, knots_f[k++] = v[n - 1] / 2;
    double I = 0;
    for (int i = 0; i + 1 < k; i++)
        I += (knots_u[i + 1] - knots_u[i]) * (knots_f[i] + knots_f[i + 1]) / 2;
    return I;
}

/* 4 x 3 x 3 density samples varying along x only: constant in y and z
 * over the middle half of the box, where the cameras look. */
static void density_grid(char *buf, size_t n, const double *vx)
{
    size_t o = (size_t)snprintf(buf, n, "\"float density\" [");
    for (int z = 0; z < 3; z++)
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 4; x++)
                o += (size_t)snprintf(buf + o, n - o, "%g ", vx[x]);
    snprintf(buf + o, n - o, "] \"integer nx\" 4 \"integer ny\" 3 \"integer nz\" 3");
}

static void test_grid_media(void)
{
    static const double vx[4] = {0.5, 2, 1, 3}, sa[3] = {0.3, 0.15, 0.6};
    double I = grid_line_integral(vx, 4);
    char grid[1024], scene[8192], msg[1024] = "";
    density_grid(grid, sizeof grid, vx);
    /* camera rays along +x through the box [-1,1]^3 (length 2), the sky behind */
    snprintf(scene, sizeof scene,
             "LookAt -5 0 0  0 0 0  0 0 1\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [21]\nPixelFilter \"box\"\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
             "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" %s \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1] "
             "\"rgb sigma_a\" [%g %g %g] \"rgb sigma_s\" [0 0 0]\n"
             "AttributeBegin\nMediumInterface \"g\" \"\"\nMaterial \"interface\"\n" BOX_M1_1 "AttributeEnd\n",
             grid, sa[0], sa[1], sa[2]);
    lf_image img = {0};
    int rc = render(scene, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        /* 16384 paths, each channel's weight bounded by ~2: std of the mean
         * < 0.01; margin 0.03 absolute */
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean_channel(&img, c, 0, 16, 0, 16), exp(-2 * sa[c] * I), 0.03);
        lf_image_free(&img);
    }
    /* the same medium between a vertical distant light and a floor
     * (albedo 0.5) at z = -1.5: radiance 0.5 / pi x exp(-2 sigma_a I), the
     * box turned so its density varies along z (the light's way) */
    snprintf(scene, sizeof scene,
             "LookAt 0 0 -1.2  0 0 -1.5  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [16] \"integer seed\" [22]\nPixelFilter \"box\"\n"
             "WorldBegin\nLightSource \"distant\" \"point3 from\" [0 0 1] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n"
             "AttributeBegin\nRotate 90 0 1 0\n"
             "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" %s \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1] "
             "\"rgb sigma_a\" [%g %g %g] \"rgb sigma_s\" [0 0 0]\nAttributeEnd\n"
             "AttributeBegin\nMediumInterface \"g\" \"\"\nMaterial \"interface\"\n" BOX_M1_1 "AttributeEnd\n"
             "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point3 P\" [-9 -9 -1.5 9 -9 -1.5 9 9 -1.5 -9 9 -1.5]\n",
             grid, sa[0], sa[1], sa[2]);
    rc = render(scene, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        /* Rotate 90 about y takes medium +x to world -z: the light travels
         * down through x from 1 to -1, the same integral.  Ratio tracking is
         * unbiased with a small variance: relative margin 3 % */
        for (int c = 0; c < 3; c++) {
            double want = 0.5 / M_PI * exp(-2 * sa[c] * I);
            CHECK_NEAR(mean_channel(&img, c, 0, 16, 0, 16), want, 0.03 * want);
        }
        lf_image_free(&img);
    }
    /* emission: a pure absorber emitting Le shows Le (1 - exp(-tau)) */
    snprintf(scene, sizeof scene,
             "LookAt -5 0 0  0 0 0  0 0 1\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [23]\nPixelFilter \"box\"\n"
             "WorldBegin\n"
             "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" %s \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1] "
             "\"rgb sigma_a\" [%g %g %g] \"rgb sigma_s\" [0 0 0] \"rgb Le\" [2 1 0.5]\n"
             "AttributeBegin\nMediumInterface \"g\" \"\"\nMaterial \"interface\"\n" BOX_M1_1 "AttributeEnd\n",
             grid, sa[0], sa[1], sa[2]);
    rc = render(scene, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        static const double Le[3] = {2, 1, 0.5};
        for (int c = 0; c < 3; c++) {
            double want = Le[c] * (1 - exp(-2 * sa[c] * I));
            CHECK_NEAR(mean_channel(&img, c, 0, 16, 0, 16), want, 0.04 * Le[c]);
        }
        lf_image_free(&img);
    }
}

/* Media that only scatter, in a sky of 1: the furnace shows 1. */
static void test_grid_furnace(void)
{
    static const char *media[2] = {
        "\"string type\" \"rgbgrid\" \"integer nx\" 2 \"integer ny\" 1 \"integer nz\" 1 "
        "\"rgb sigma_s\" [2 1 4  0.5 3 1] \"rgb sigma_a\" [0 0 0 0 0 0] \"float g\" 0.5",
        "\"string type\" \"cloud\" \"rgb sigma_a\" [0 0 0] \"rgb sigma_s\" [3 2.5 3.5] \"float g\" -0.3",
    };
    for (int i = 0; i < 2; i++) {
        char scene[4096], msg[1024] = "";
        snprintf(scene, sizeof scene,
                 "LookAt -5 0.3 0.2  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 30\n"
                 "Film \"rgb\" \"integer xresolution\" [12] \"integer yresolution\" [12]\n"
                 "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [24]\n"
                 "Integrator \"volpath\" \"integer maxdepth\" 200\n"
                 "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                 "MakeNamedMedium \"g\" %s \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1]\n"
                 "AttributeBegin\nMediumInterface \"g\" \"\"\nMaterial \"interface\"\n" BOX_M1_1 "AttributeEnd\n",
                 media[i]);
        lf_image img = {0};
        int rc = render(scene, &img, msg, sizeof msg);
        CHECK_MSG(rc == 0, "%s", msg);
        if (rc)
            continue;
        /* energy is conserved; 9216 paths of bounded weight: margin 3 % */
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean_channel(&img, c, 0, 12, 0, 12), 1.0, 0.03);
        lf_image_free(&img);
    }
}

/* nanovdb: a dense 4 x 5 x 5 grid, voxel 0.5, index (0,0,0) at (-1,-1,-1);
 * density varies along x only.  Along x, index [0, 4] (world [-1, 1]) is
 * inside the world box; the samples are at index 0..3 and the one at 4 is
 * background 0, so int d dx = h (sum of the trapezoids).  In y and z the
 * value is constant over index [0, 4], world [-1, 1], where the camera
 * looks. */
static void test_nanovdb(void)
{
    static const double vx[4] = {0.5, 2, 1, 3}, sa[3] = {0.3, 0.15, 0.6}, h = 0.5;
    float vals[4 * 5 * 5];
    for (int i = 0; i < 4 * 5 * 5; i++)
        vals[i] = (float)vx[i % 4];
    char dir[] = "/tmp/lf_nvdb_XXXXXX", path[256], err[512] = "";
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/grid.nvdb", dir);
    const double origin[3] = {-1, -1, -1};
    int rc = lf_nvdb_write_dense(path, "density", 4, 5, 5, vals, h, origin, err, sizeof err);
    CHECK_MSG(rc == 0, "%s", err);
    double I = 0;
    for (int i = 0; i < 4; i++)
        I += (vx[i] + (i < 3 ? vx[i + 1] : 0)) / 2;
    I *= h;
    char scene[8192], msg[1024] = "";
    snprintf(scene, sizeof scene,
             "LookAt -5 0 0  0 0 0  0 0 1\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [64] \"integer seed\" [25]\nPixelFilter \"box\"\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
             "MakeNamedMedium \"v\" \"string type\" \"nanovdb\" \"string filename\" \"%s\" "
             "\"rgb sigma_a\" [%g %g %g] \"rgb sigma_s\" [0 0 0]\n"
             "AttributeBegin\nMediumInterface \"v\" \"\"\nMaterial \"interface\"\n" BOX_M1_1 "AttributeEnd\n",
             path, sa[0], sa[1], sa[2]);
    lf_image img = {0};
    rc = render(scene, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (!rc) {
        /* as the uniformgrid camera test: margin 0.03 absolute */
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean_channel(&img, c, 0, 16, 0, 16), exp(-sa[c] * I), 0.03);
        lf_image_free(&img);
    }
    /* a grid name the file lacks, and a missing file, name the medium */
    snprintf(scene, sizeof scene,
             "WorldBegin\nMakeNamedMedium \"v\" \"string type\" \"nanovdb\" \"string filename\" \"%s\" "
             "\"string gridname\" \"smoke\"\n",
             path);
    rc = render_text(scene, NULL, NULL, msg, sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:1") && strstr(msg, "smoke"), "%s", msg);
    rc = render_text("WorldBegin\nMakeNamedMedium \"v\" \"string type\" \"nanovdb\" \"string filename\" "
                     "\"/nonexistent/x.nvdb\"\n",
                     NULL, NULL, msg, sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:1") && strstr(msg, "x.nvdb"), "%s", msg);
    remove(path);
    rmdir(dir);
}

/* ---- the example scenes ---- */
static void test_scene_files(void)
{
    const char *dir = LF_SOURCE_DIR "/scenes/pbrt-v4";
    DIR *dd = opendir(dir);
    CHECK_MSG(dd != NULL, "%s", dir);
    if (!dd)
        return;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dd))) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".pbrt"))
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        lf_scene_desc d;
        lf_error err = {0};
        if (lf_scene_parse_file(path, &d, &err)) {
            CHECK_MSG(0, "%s: %s", e->d_name, err.msg);
            continue;
        }
        lf_render_opts o = lf_render_opts_default();
        o.spp = 2, o.threads = 2;
        o.crop[0] = 130, o.crop[1] = 178, o.crop[2] = 90, o.crop[3] = 122;
        lf_renderer *r = NULL;
        lf_image img = {0};
        int rc = lf_renderer_create(&d, &o, &r, &err);
        if (!rc)
            rc = lf_renderer_render(r, &img, NULL, &err);
        CHECK_MSG(rc == 0, "%s: %s", e->d_name, err.msg);
        if (!rc) {
            const char *w = lf_renderer_warnings(r);
            CHECK_MSG(!w || !*w, "%s warns: %s", e->d_name, w);
            double sum = 0;
            int bad = 0;
            for (int y = 0; y < img.height; y++)
                for (int x = 0; x < img.width; x++)
                    for (int c = 0; c < 3; c++) {
                        float v = lf_image_px(&img, x, y)[c];
                        bad += !(v >= 0) || !isfinite(v);
                        sum += v;
                    }
            CHECK_MSG(!bad && sum > 0, "%s: %d bad pixels, sum %g", e->d_name, bad, sum);
            lf_image_free(&img);
        }
        lf_renderer_free(r);
        lf_scene_desc_free(&d);
        n++;
    }
    closedir(dd);
    CHECK_MSG(n >= 4, "%d scenes in %s", n, dir);
}

int main(void)
{
    test_disk_reverse_orientation();
    test_duplicate_parameters();
    test_integrator_params();
    test_alpha();
    test_silhouettes();
    test_curves();
    test_grid_media();
    test_grid_furnace();
    test_nanovdb();
    test_scene_files();
    return lf_test_end();
}
