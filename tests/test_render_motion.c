/* Motion blur and shutters: streak lengths from projection, rolling-shutter
 * slant from speed x readout, static scenes unchanged, hard cases. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "render/lf_render.h"

static int render_text(const char *text, lf_image *img, char *msg, size_t n, char **explain)
{
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_string(text, "motion.pbrt", &d, &err)) {
        snprintf(msg, n, "%s", err.msg);
        return -1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.threads = 2;
    lf_renderer *r;
    int rc = lf_renderer_create(&d, &o, &r, &err);
    if (!rc) {
        if (explain)
            *explain = lf_renderer_explain(r);
        rc = lf_renderer_render(r, img, NULL, &err);
        if (!rc && lf_renderer_warnings(r))
            snprintf(msg, n, "%s", lf_renderer_warnings(r));
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    if (rc)
        snprintf(msg, n, "%s", err.msg);
    return rc;
}

/* Orthographic camera looking along +z from z = -5: screen x in [-4, 4] over
 * 128 px (16 px per unit), y in [-1, 1] over 32 px; camera +x = world +x. */
static const char *camera_ortho = "LookAt 0 0 -5 0 0 0 0 1 0\nCamera \"orthographic\" %s\n"
                                  "Film \"rgb\" \"integer xresolution\" [128] \"integer yresolution\" [32]\n"
                                  "Sampler \"zsobol\" \"integer pixelsamples\" [256]\nPixelFilter \"box\"\n";

/* Column sums of channel 0. */
static void column_sums(const lf_image *img, double *S)
{
    for (int x = 0; x < img->width; x++) {
        S[x] = 0;
        for (int y = 0; y < img->height; y++)
            S[x] += lf_image_px(img, x, y)[0];
    }
}

/* Width at half maximum with linear interpolation of the crossings. */
static double fwhm(const double *S, int n, double *left, double *right)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        m = fmax(m, S[i]);
    double h = m / 2;
    int a = 0, b = n - 1;
    while (a < n && S[a] < h)
        a++;
    while (b >= 0 && S[b] < h)
        b--;
    if (a == 0 || b == n - 1 || a > b)
        return -1;
    /* crossing between pixel centres a-1+0.5 and a+0.5 */
    double xl = (a - 1 + 0.5) + (h - S[a - 1]) / (S[a] - S[a - 1]);
    double xr = (b + 0.5) + (S[b] - h) / (S[b] - S[b + 1]);
    *left = xl;
    *right = xr;
    return xr - xl;
}

static double streak(double shutter_close, double dx, int segments, char **explain)
{
    char cam[256], scene[2048];
    snprintf(cam, sizeof cam, "\"float shutteropen\" [0] \"float shutterclose\" [%g]", shutter_close);
    char head[1024];
    snprintf(head, sizeof head, camera_ortho, cam);
    snprintf(scene, sizeof scene,
             "%sWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
             "Translate -2 0 0\nActiveTransform EndTime\nTranslate %g 0 0\nActiveTransform All\n"
             "Shape \"sphere\" \"float radius\" [0.1] \"integer motionsegments\" [%d]\nAttributeEnd\n",
             head, dx, segments);
    lf_image img;
    char msg[2048] = "";
    if (render_text(scene, &img, msg, sizeof msg, explain)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return -1;
    }
    double S[128], l, r;
    column_sums(&img, S);
    double w = fwhm(S, 128, &l, &r);
    lf_image_free(&img);
    return w;
}

static void test_streaks(void)
{
    /* The sphere (radius 0.1 = 1.6 px) moves dx units during the exposure
     * (TransformTimes 0..1, shutter 0..c): its column-sum profile is a box of
     * length 16 dx c px convolved with the disk's chord profile, whose half
     * maximum points are the centre's start and end positions: FWHM = 16 dx c.
     * Margin 1 px (the issue's), far above the MC noise of 256 spp x 32 rows. */
    char *plan = NULL;
    double full = streak(1.0, 3.0, 1, &plan);
    CHECK_MSG(fabs(full - 48.0) <= 1.0, "streak %.3f px, expected 48", full);
    CHECK_MSG(plan && strstr(plan, "motion blur: on"), "plan: %s", plan ? plan : "");
    free(plan);
    double half = streak(0.5, 3.0, 1, NULL);
    CHECK_MSG(fabs(half - 24.0) <= 1.0, "half-shutter streak %.3f px, expected 24", half);
    CHECK_NEAR(half / full, 0.5, 0.03);
    /* more keyframes along a straight line change nothing */
    double seg = streak(1.0, 3.0, 4, NULL);
    CHECK_NEAR(seg, full, 0.5);
}

static void test_camera_motion(void)
{
    /* The camera moves +2 units in x during the exposure: a static emitter
     * streaks 32 px (in the opposite direction). */
    const char *scene =
        "LookAt 0 0 -5 0 0 0 0 1 0\nActiveTransform EndTime\nTranslate -2 0 0\nActiveTransform All\n"
        "Camera \"orthographic\"\n"
        "Film \"rgb\" \"integer xresolution\" [128] \"integer yresolution\" [32]\n"
        "Sampler \"zsobol\" \"integer pixelsamples\" [256]\nPixelFilter \"box\"\n"
        "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
        "Shape \"sphere\" \"float radius\" [0.1]\nAttributeEnd\n";
    lf_image img;
    char msg[2048] = "";
    if (render_text(scene, &img, msg, sizeof msg, NULL)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    double S[128], l, r;
    column_sums(&img, S);
    double w = fwhm(S, 128, &l, &r);
    CHECK_MSG(fabs(w - 32.0) <= 1.0, "camera-motion streak %.3f px, expected 32", w);
    lf_image_free(&img);
}

static void test_rolling_shutter(void)
{
    /* A vertical bar moving +x at v = 2 units/s, exposure 0.01 s per row,
     * rows start 1.0 s apart top to bottom (readout 1 s over 32 rows): row
     * y's bar centre is displaced by v * (y + 0.5)/32 * 1 s, a slope of
     * 16 px/unit * 2 * 1/32 = 1 px per row. */
    const char *scene =
        "LookAt 0 0 -5 0 0 0 0 1 0\n"
        "Camera \"orthographic\" \"float shutteropen\" [0] \"float shutterclose\" [0.01]\n"
        "  \"string shutter\" \"rolling\" \"float readouttime\" [1]\n"
        "Film \"rgb\" \"integer xresolution\" [128] \"integer yresolution\" [32]\n"
        "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
        "TransformTimes 0 1.01\n"
        "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" true\n"
        "Translate -1 0 0\nActiveTransform EndTime\nTranslate 2.02 0 0\nActiveTransform All\n"
        "Shape \"trianglemesh\" \"point3 P\" [-0.1 -2 0  0.1 -2 0  0.1 2 0  -0.1 2 0]\n"
        "  \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n";
    lf_image img;
    char msg[2048] = "";
    char *plan = NULL;
    if (render_text(scene, &img, msg, sizeof msg, &plan)) {
        CHECK_MSG(0, "render failed: %s", msg);
        free(plan);
        return;
    }
    CHECK_MSG(plan && strstr(plan, "rolling shutter: on"), "plan: %s", plan ? plan : "");
    free(plan);
    /* least-squares slope of the per-row centroid */
    double sy = 0, sx = 0, sxy = 0, syy = 0;
    int n = 0;
    for (int y = 0; y < 32; y++) {
        double w = 0, c = 0;
        for (int x = 0; x < 128; x++) {
            double v = lf_image_px(&img, x, y)[0];
            w += v;
            c += v * (x + 0.5);
        }
        if (w <= 0)
            continue;
        c /= w;
        sy += y, sx += c, sxy += y * c, syy += (double)y * y;
        n++;
    }
    double slope = (n * sxy - sy * sx) / (n * syy - sy * sy);
    CHECK(n == 32);
    CHECK_MSG(fabs(slope - 1.0) <= 0.03, "rolling-shutter slope %.4f px/row, expected 1", slope);
    lf_image_free(&img);
}

static const char *static_scene =
    "LookAt 0 1 -4 0 0.5 0 0 1 0\nCamera \"perspective\" \"float fov\" [40] %s\n"
    "Film \"rgb\" \"integer xresolution\" [40] \"integer yresolution\" [30]\n"
    "Sampler \"zsobol\" \"integer pixelsamples\" [8]\n"
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.6 0.7]\n"
    "Material \"diffuse\"\nShape \"bilinearmesh\" \"point3 P\" [-5 0 -5 5 0 -5 -5 0 5 5 0 5]\n"
    "Translate 0 0.5 0\nShape \"sphere\" \"float radius\" [0.5]\n";

static void test_static_identical(void)
{
    /* Nothing moves: the shutter interval, a rolling shutter or a shutter
     * curve must not change a single bit (no time samples are drawn). */
    const char *cams[] = {"\"float shutteropen\" [0] \"float shutterclose\" [0]",
                          "\"float shutteropen\" [0] \"float shutterclose\" [1]",
                          "\"string shutter\" \"rolling\" \"float readouttime\" [0.5]",
                          "\"float shuttercurve\" [0 0 0.3 1 0.7 1 1 0]"};
    lf_image ref, img;
    char scene[2048], msg[2048] = "";
    char *plan = NULL;
    snprintf(scene, sizeof scene, static_scene, "");
    if (render_text(scene, &ref, msg, sizeof msg, &plan)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    CHECK(plan && strstr(plan, "motion blur: off"));
    free(plan);
    for (int i = 0; i < 4; i++) {
        snprintf(scene, sizeof scene, static_scene, cams[i]);
        if (render_text(scene, &img, msg, sizeof msg, NULL)) {
            CHECK_MSG(0, "render failed: %s", msg);
            continue;
        }
        /* exposure scale aside (shutter 0 renders black by the imaging ratio),
         * compare after dividing out the ratio of one pixel */
        double k = lf_image_px(&ref, 5, 5)[0] > 0 && lf_image_px(&img, 5, 5)[0] > 0
                       ? lf_image_px(&ref, 5, 5)[0] / lf_image_px(&img, 5, 5)[0]
                       : 0;
        int same = 1;
        size_t n = (size_t)img.width * img.height * 3;
        if (i == 0) {
            for (size_t j = 0; j < n; j++)
                same &= img.data[j] == 0.f; /* a zero-length exposure collects nothing */
        } else {
            for (size_t j = 0; j < n; j++)
                same &= fabs(img.data[j] * k - ref.data[j]) <= 1e-6 * fabs(ref.data[j]);
        }
        CHECK_MSG(same, "static scene changed with camera settings %d: %s", i, cams[i]);
        if (i == 1 || i == 2)
            CHECK(memcmp(img.data, ref.data, n * sizeof(float)) == 0); /* same exposure: bit-identical */
        lf_image_free(&img);
    }
    lf_image_free(&ref);
}

static void test_hard_cases(void)
{
    lf_image img;
    char scene[4096], msg[2048] = "";
    /* ray times at the ends of the motion: a shutter at t = 0 sees the
     * start position, at t = 1 the end position (x = -2 and +1 -> columns
     * 32 and 80 in pixel units 16 (x + 4)); Embree time 1 exactly is
     * reached (tau clamps to [0, 1]) */
    for (int end = 0; end < 2; end++) {
        /* a zero-length exposure collects nothing (imaging ratio 0), so a
         * 1e-6-long one at either end stands in for the instant */
        char cam[128], head[1024];
        snprintf(cam, sizeof cam, "\"float shutteropen\" [%g] \"float shutterclose\" [%g]", end ? 0.999999 : 0.0,
                 end ? 1.0 : 1e-6);
        snprintf(head, sizeof head, camera_ortho, cam);
        snprintf(scene, sizeof scene,
                 "%sWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                 "Translate -2 0 0\nActiveTransform EndTime\nTranslate 3 0 0\nActiveTransform All\n"
                 "Shape \"sphere\" \"float radius\" [0.2]\nAttributeEnd\n",
                 head);
        if (render_text(scene, &img, msg, sizeof msg, NULL)) {
            CHECK_MSG(0, "render failed: %s", msg);
            continue;
        }
        double S[128], sw = 0, sx = 0;
        column_sums(&img, S);
        for (int x = 0; x < 128; x++)
            sw += S[x], sx += S[x] * (x + 0.5);
        CHECK_MSG(sw > 0 && fabs(sx / sw - (end ? 80.0 : 32.0)) < 0.3, "t=%d: centroid %.3f", end, sx / sw);
        CHECK(lf_image_count_nonfinite(&img) == 0);
        lf_image_free(&img);
    }
    /* a singular keyframe is a clear error */
    char head[1024];
    snprintf(head, sizeof head, camera_ortho, "");
    snprintf(scene, sizeof scene,
             "%sWorldBegin\nActiveTransform EndTime\nScale 0 0 0\nActiveTransform All\nShape \"sphere\"\n", head);
    CHECK(render_text(scene, &img, msg, sizeof msg, NULL) != 0);
    CHECK_MSG(strstr(msg, "singular") && strstr(msg, "motion.pbrt:"), "message: %s", msg);
    /* enormous motion, 180 degrees in one segment, readout longer than the
     * exposure, shutteropen > shutterclose: finite images */
    const char *cases[] = {
        "Camera \"orthographic\"\n", "Translate 1e4 0 0", "",
        "Camera \"orthographic\"\n", "Rotate 180 0 0 1", "\"integer motionsegments\" [1]",
        "Camera \"orthographic\" \"string shutter\" \"rolling\" \"float readouttime\" [5] \"float shutterclose\" [0.1]\n",
        "Translate 1 0 0", "",
        "Camera \"orthographic\" \"float shutteropen\" [1] \"float shutterclose\" [0]\n", "Translate 1 0 0", ""};
    for (int i = 0; i < 4; i++) {
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 -5 0 0 0 0 1 0\n%s"
                 "Film \"rgb\" \"integer xresolution\" [32] \"integer yresolution\" [16]\n"
                 "Sampler \"zsobol\" \"integer pixelsamples\" [16]\n"
                 "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\nAttributeBegin\n"
                 "ActiveTransform EndTime\n%s\nActiveTransform All\n"
                 "Shape \"trianglemesh\" \"point3 P\" [-0.5 -0.5 0 0.5 -0.5 0 0 0.5 0] %s\nAttributeEnd\n",
                 cases[3 * i], cases[3 * i + 1], cases[3 * i + 2]);
        int rc = render_text(scene, &img, msg, sizeof msg, NULL);
        CHECK_MSG(rc == 0, "hard case %d failed: %s", i, msg);
        if (!rc) {
            CHECK(lf_image_count_nonfinite(&img) == 0);
            lf_image_free(&img);
        }
        if (i == 3)
            CHECK_MSG(strstr(msg, "swapping"), "shutteropen > shutterclose should warn: %s", msg);
    }
}

int main(void)
{
    test_streaks();
    test_camera_motion();
    test_rolling_shutter();
    test_static_identical();
    test_hard_cases();
    return lf_test_end();
}
