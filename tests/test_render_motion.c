/* Motion blur and shutters: streak lengths from projection, rolling-shutter
 * slant from speed x readout, static scenes unchanged, hard cases. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"
#include "render/render_internal.h"

/* errors name motion.pbrt; after a render, msg holds the renderer's warnings */
#define MOTION_SCENE .name = "motion.pbrt", .warnings_in_msg = 1
static const lf_test_scene motion_scene = {MOTION_SCENE};

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
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = explain}, &img, msg, sizeof msg)) {
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
    if (render_text(scene, &motion_scene, &img, msg, sizeof msg)) {
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
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = &plan}, &img, msg, sizeof msg)) {
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
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = &plan}, &ref, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    CHECK(plan && strstr(plan, "motion blur: off"));
    free(plan);
    for (int i = 0; i < 4; i++) {
        snprintf(scene, sizeof scene, static_scene, cams[i]);
        if (render_text(scene, &motion_scene, &img, msg, sizeof msg)) {
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
        if (render_text(scene, &motion_scene, &img, msg, sizeof msg)) {
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
    CHECK(render_text(scene, &motion_scene, &img, msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "singular") && strstr(msg, "motion.pbrt:"), "message: %s", msg);
    /* more segments than Embree's 129 time steps is a clear error, not a
     * silently static shape */
    snprintf(scene, sizeof scene,
             "%sWorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n"
             "Shape \"sphere\" \"integer motionsegments\" [129]\n", head);
    CHECK(render_text(scene, &motion_scene, &img, msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "motionsegments") && strstr(msg, "motion.pbrt:10:"), "message: %s", msg);
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
        int rc = render_text(scene, &motion_scene, &img, msg, sizeof msg);
        CHECK_MSG(rc == 0, "hard case %d failed: %s", i, msg);
        if (!rc) {
            CHECK(lf_image_count_nonfinite(&img) == 0);
            lf_image_free(&img);
        }
        if (i == 3)
            CHECK_MSG(strstr(msg, "swapping"), "shutteropen > shutterclose should warn: %s", msg);
    }
}

/* ---- rigid motion as Embree instances (docs/motion.md) ---- */

/* Builds the scene of a text (no camera needed) for ray queries. */
static int build_scene_text(const char *text, lf_scene_desc *d, lf_scene *s)
{
    lf_error err = {0};
    if (lf_scene_parse_string(text, "motion.pbrt", d, &err)) {
        CHECK_MSG(0, "parse failed: %s", err.msg);
        return -1;
    }
    if (lf_scene_build(d, s, &err)) {
        CHECK_MSG(0, "build failed: %s", err.msg);
        lf_scene_desc_free(d);
        return -1;
    }
    return 0;
}

static double vdist(lf_vec3 a, lf_vec3 b) { return lf_length(lf_sub(a, b)); }

static void test_instance_rotation_exact(void)
{
    /* A unit quad in the plane z = 1 of its object space (shading normals
     * and uv given) turns 90 degrees about +y during the shutter; pbrt's
     * decomposed interpolation (a slerp) turns it by 90 t degrees:
     * x' = cos(a) x + sin(a) z, z' = -sin(a) x + cos(a) z.  At t = 0.5 the
     * plane has normal m = (sin 45, 0, cos 45) and passes at distance 1
     * from the origin (m.p = 1), so a ray from (x0, y0, -5) along +z hits
     * at t = 5 + (1 - m.x x0) / m.z, with shading normal m, the geometric
     * normal +-m on its side, dp/du rotated and the uv of the object point
     * hit.  A one-segment keyframe would
     * put the plane at distance cos 45 = 0.707 instead (17% off). */
    const char *text =
        "WorldBegin\nAttributeBegin\nActiveTransform EndTime\nRotate 90 0 1 0\nActiveTransform All\n"
        "Shape \"trianglemesh\" \"point3 P\" [-1 -1 1  1 -1 1  1 1 1  -1 1 1] \"integer indices\" [0 1 2 0 2 3]\n"
        "  \"normal N\" [0 0 1 0 0 1 0 0 1 0 0 1] \"point2 uv\" [0 0 1 0 1 1 0 1]\nAttributeEnd\n";
    lf_scene_desc d;
    lf_scene s;
    if (build_scene_text(text, &d, &s))
        return;
    CHECK_MSG(s.n_instances == 1 && s.motion_rigid_shapes == 1 && s.motion_keyframed_shapes == 0,
              "instances %d, rigid %d, keyframed %d", s.n_instances, s.motion_rigid_shapes, s.motion_keyframed_shapes);
    const double xs[3] = {0.3, 0.9, 0.5}, ys[3] = {0.2, -0.6, 0.7}; /* inside the quad at every time */
    const float taus[3] = {0.f, 0.5f, 1.f};
    for (int it = 0; it < 3; it++) {
        double a = LF_PI / 2 * taus[it], sa = sin(a), ca = cos(a);
        lf_vec3 m = lf_v3((float)sa, 0, (float)ca);
        for (int k = 0; k < 3; k++) {
            lf_hit h;
            lf_vec3 o = lf_v3((float)xs[k], (float)ys[k], -5), dir = lf_v3(0, 0, 1);
            double xo = (xs[k] - sa * 1) / ca; /* object x of the hit (x' = ca x + sa z, z = 1) */
            if (it == 2) /* at 90 degrees the plane is x = 1: rays along +z graze it; look along -x instead */
                o = lf_v3(5, (float)ys[k], (float)xs[k]), dir = lf_v3(-1, 0, 0), xo = -xs[k];
            int hit = lf_scene_intersect(&s, o, dir, INFINITY, taus[it], &h);
            CHECK_MSG(hit, "tau %g ray %d missed", taus[it], k);
            if (!hit)
                continue;
            double t_exp = it == 2 ? 5 - 1 : 5 + (1 - sa * xs[k]) / ca;
            CHECK_MSG(fabs(h.t - t_exp) <= 1e-4 * t_exp, "tau %g ray %d: t %.7f, analytic %.7f", taus[it], k, h.t,
                      t_exp);
            /* world point, normals, tangent */
            lf_vec3 p_exp = lf_madd(o, dir, (float)t_exp);
            CHECK_MSG(vdist(h.sc.p, p_exp) <= 1e-4 * t_exp, "tau %g ray %d: p off by %g", taus[it], k,
                      vdist(h.sc.p, p_exp));
            CHECK_MSG(vdist(h.sc.ns, m) <= 1e-4, "tau %g: shading normal (%g %g %g)", taus[it], h.sc.ns.x, h.sc.ns.y,
                      h.sc.ns.z);
            CHECK_MSG(fabs(fabs(lf_dot(h.sc.ng, m)) - 1) <= 1e-4 && lf_dot(h.sc.ng, h.sc.ns) > 0,
                      "tau %g: geometric normal (%g %g %g)", taus[it], h.sc.ng.x, h.sc.ng.y, h.sc.ng.z);
            lf_vec3 dpdu_exp = lf_v3((float)ca, 0, (float)-sa); /* object +x rotated */
            CHECK_MSG(vdist(h.sc.dpdu, dpdu_exp) <= 1e-4, "tau %g: dpdu (%g %g %g)", taus[it], h.sc.dpdu.x,
                      h.sc.dpdu.y, h.sc.dpdu.z);
            CHECK_MSG(fabs(h.sc.uv.x - (xo + 1) / 2) <= 1e-4 && fabs(h.sc.uv.y - (ys[k] + 1) / 2) <= 1e-4,
                      "tau %g ray %d: uv (%g %g), expected (%g %g)", taus[it], k, h.sc.uv.x, h.sc.uv.y, (xo + 1) / 2,
                      (ys[k] + 1) / 2);
            /* shadow rays see the surface at the same place */
            CHECK(!lf_scene_occluded(&s, o, dir, (float)t_exp * 0.999f, taus[it]));
            CHECK(lf_scene_occluded(&s, o, dir, (float)t_exp * 1.001f, taus[it]));
        }
    }
    lf_scene_free(&s);
    lf_scene_desc_free(&d);
}

static void test_instance_frame_matches_keyframes(void)
{
    /* The world-space shading frame of instance hits (normal orientation
     * under mirroring scales and ReverseOrientation, shading normals under
     * non-uniform scales, dp/du, uv, material) equals the keyframed path's
     * at the same ray and time.  128 segments of a 100 degree turn deviate
     * from the rigid motion by a sagitta of 2.3e-5 of the size: margin 1e-3. */
    const char *variants[] = {
        "Scale -1 1 1\n", "",
        "Scale 0.5 2 1\nReverseOrientation\n", "",
        "Scale 2 -0.5 1.5\n", "\"normal N\" [0 0 1 0.3 0 1 0 0.4 1] \"point2 uv\" [0 0 2 0 0 3]",
    };
    for (int v = 0; v < 3; v++) {
        lf_scene_desc d[2];
        lf_scene s[2];
        int ok = 1;
        for (int keyed = 0; keyed < 2; keyed++) {
            char text[2048];
            snprintf(text, sizeof text,
                     "WorldBegin\nAttributeBegin\nMaterial \"diffuse\"\nTranslate 0.2 0.1 0\n"
                     "ActiveTransform EndTime\nRotate 100 0.2 1 0.3\nActiveTransform All\n%s"
                     "Shape \"trianglemesh\" \"point3 P\" [-0.6 -0.5 0.1 0.7 -0.4 -0.1 0 0.6 0] %s %s\n"
                     "AttributeEnd\n",
                     variants[2 * v], variants[2 * v + 1], keyed ? "\"integer motionsegments\" [128]" : "");
            if (build_scene_text(text, &d[keyed], &s[keyed])) {
                ok = 0;
                if (keyed) {
                    lf_scene_free(&s[0]);
                    lf_scene_desc_free(&d[0]);
                }
                break;
            }
        }
        if (!ok)
            continue;
        CHECK(s[0].n_instances == 1 && s[1].n_instances == 0);
        const float taus[4] = {0.f, 0.37f, 0.5f, 1.f};
        int compared = 0;
        for (int it = 0; it < 4; it++)
            for (int k = 0; k < 25; k++) {
                lf_vec3 o = lf_v3(-0.4f + 0.2f * (float)(k % 5), -0.4f + 0.2f * (float)(k / 5), -4);
                lf_vec3 dir = lf_normalize(lf_v3(0.05f, -0.02f, 1));
                lf_hit a, b;
                int ha = lf_scene_intersect(&s[0], o, dir, INFINITY, taus[it], &a);
                int hb = lf_scene_intersect(&s[1], o, dir, INFINITY, taus[it], &b);
                if (!ha || !hb || fabsf(a.t - b.t) > 1e-3f)
                    continue; /* near an edge one may miss: compare where both hit */
                compared++;
                CHECK_MSG(vdist(a.sc.ng, b.sc.ng) < 1e-3 && vdist(a.sc.ns, b.sc.ns) < 1e-3 &&
                              vdist(a.sc.dpdu, b.sc.dpdu) < 1e-3 && vdist(a.sc.p, b.sc.p) < 1e-3,
                          "variant %d tau %g: ng (%g %g %g) vs (%g %g %g), ns (%g %g %g) vs (%g %g %g)", v, taus[it],
                          a.sc.ng.x, a.sc.ng.y, a.sc.ng.z, b.sc.ng.x, b.sc.ng.y, b.sc.ng.z, a.sc.ns.x, a.sc.ns.y,
                          a.sc.ns.z, b.sc.ns.x, b.sc.ns.y, b.sc.ns.z);
                CHECK(fabsf(a.sc.uv.x - b.sc.uv.x) < 1e-3f && fabsf(a.sc.uv.y - b.sc.uv.y) < 1e-3f);
                CHECK(a.material == b.material && a.light == -1 && b.light == -1);
            }
        CHECK_MSG(compared >= 30, "variant %d: only %d rays hit both", v, compared);
        for (int keyed = 0; keyed < 2; keyed++) {
            lf_scene_free(&s[keyed]);
            lf_scene_desc_free(&d[keyed]);
        }
    }
}

static void test_instance_composition(void)
{
    /* A shape with its own motion inside an ObjectInstance: one instance
     * when the composition is one decomposed two-key motion (a static
     * translation around a turning shape), keyframes when it is not (a
     * non-uniform static scale around a turning shape; two turns about
     * different axes; a scale flipping sign).  Where it is an instance, its
     * hits agree with the keyframed path's (margin as above). */
    const char *object =
        "WorldBegin\nObjectBegin \"o\"\nAttributeBegin\nActiveTransform EndTime\nRotate 90 0 0 1\n"
        "ActiveTransform All\n"
        "Shape \"trianglemesh\" \"point3 P\" [-0.6 -0.5 0.1 0.7 -0.4 -0.1 0 0.6 0] %s\nAttributeEnd\nObjectEnd\n";
    const struct {
        const char *instance;
        int instanced;
    } cases[] = {
        {"Translate 2 0.5 0\n", 1},
        {"Scale 2 1 1\n", 0},
        {"ActiveTransform EndTime\nRotate 60 1 0 0\nActiveTransform All\n", 0},
        {"ActiveTransform EndTime\nScale -1 1 1\nActiveTransform All\n", 0},
    };
    for (int c = 0; c < 4; c++) {
        lf_scene_desc d[2];
        lf_scene s[2];
        int built = 0;
        for (int keyed = 0; keyed < 2; keyed++) {
            char head[1024], text[2048];
            snprintf(head, sizeof head, object, keyed ? "\"integer motionsegments\" [128]" : "");
            snprintf(text, sizeof text, "%sAttributeBegin\n%sObjectInstance \"o\"\nAttributeEnd\n", head,
                     cases[c].instance);
            if (build_scene_text(text, &d[keyed], &s[keyed]))
                break;
            built++;
        }
        if (built == 2) {
            CHECK_MSG(s[0].n_instances == cases[c].instanced && s[0].motion_rigid_shapes == cases[c].instanced &&
                          s[0].motion_keyframed_shapes == !cases[c].instanced,
                      "case %d: %d instances, %d keyframed", c, s[0].n_instances, s[0].motion_keyframed_shapes);
            int compared = 0;
            for (int k = 0; k < 49; k++) {
                lf_vec3 o = lf_v3(1.4f + 0.2f * (float)(k % 7), -0.1f + 0.2f * (float)(k / 7), -4);
                lf_hit a, b;
                float tau = 0.1f + 0.8f * (float)k / 48;
                if (lf_scene_intersect(&s[0], o, lf_v3(0, 0, 1), INFINITY, tau, &a) &&
                    lf_scene_intersect(&s[1], o, lf_v3(0, 0, 1), INFINITY, tau, &b)) {
                    compared++;
                    CHECK_MSG(fabsf(a.t - b.t) < 1e-3f && vdist(a.sc.ng, b.sc.ng) < 1e-3, "case %d tau %g", c, tau);
                }
            }
            CHECK_MSG(c != 0 || compared >= 10, "case %d: %d rays compared", c, compared);
        }
        for (int keyed = 0; keyed < built; keyed++) {
            lf_scene_free(&s[keyed]);
            lf_scene_desc_free(&d[keyed]);
        }
    }
}

static void test_instance_half_turn(void)
{
    /* A bar 2 long and 0.2 wide turns 180 degrees about z in one step.
     * Keyframed vertices move along chords through the axis: at mid-shutter
     * a one-segment bar has collapsed to a point.  The instance is rigid: at
     * t = 0.5 it lies along y (a ray at (0, 0.9) hits, one at (0.9, 0)
     * misses) and at t = 0.25 along the diagonal pbrt's interpolation
     * chooses (computed here with lf_decomposed_interpolate), 0.9 from the
     * axis. */
    const char *fmt =
        "WorldBegin\nAttributeBegin\nActiveTransform EndTime\nRotate 180 0 0 1\nActiveTransform All\n"
        "Shape \"trianglemesh\" \"point3 P\" [-1 -0.1 0  1 -0.1 0  1 0.1 0  -1 0.1 0]\n"
        "  \"integer indices\" [0 1 2 0 2 3] %s\nAttributeEnd\n";
    for (int keyed = 0; keyed < 2; keyed++) {
        char text[1024];
        snprintf(text, sizeof text, fmt, keyed ? "\"integer motionsegments\" [1]" : "");
        lf_scene_desc d;
        lf_scene s;
        if (build_scene_text(text, &d, &s))
            return;
        CHECK(s.n_instances == (keyed ? 0 : 1));
        lf_hit h;
        int along_y = lf_scene_intersect(&s, lf_v3(0, 0.9f, -5), lf_v3(0, 0, 1), INFINITY, 0.5f, &h);
        int along_x = lf_scene_intersect(&s, lf_v3(0.9f, 0, -5), lf_v3(0, 0, 1), INFINITY, 0.5f, &h);
        if (keyed) {
            CHECK_MSG(!along_y && !along_x, "one keyframed segment collapses the bar at mid-shutter");
        } else {
            CHECK_MSG(along_y && fabs(h.t - 5) < 1e-4, "the rigid bar lies along y at t = 0.5");
            CHECK_MSG(!along_x, "the rigid bar left the x axis at t = 0.5");
            /* pbrt's decomposed interpolation at t = 0.25 */
            lf_decomposed a, b;
            lf_transform x0 = lf_transform_identity(), x1 = lf_transform_rotate(180, 0, 0, 1);
            CHECK(lf_transform_decompose(&x0, &a) == 0 && lf_transform_decompose(&x1, &b) == 0);
            lf_transform q = lf_decomposed_interpolate(&a, &b, 0.25);
            lf_vec3 tip = lf_xform_point(&q, lf_v3(0.9f, 0, 0)), other = lf_v3(tip.y, -tip.x, 0);
            CHECK_MSG(fabs(lf_length(tip) - 0.9) < 1e-6 && fabs(fabsf(tip.x) - 0.9 * sqrt(0.5)) < 1e-5,
                      "tip (%g %g)", tip.x, tip.y);
            CHECK_MSG(lf_scene_intersect(&s, lf_v3(tip.x, tip.y, -5), lf_v3(0, 0, 1), INFINITY, 0.25f, &h) &&
                          fabs(h.t - 5) < 1e-4,
                      "the rigid bar follows pbrt's slerp at t = 0.25");
            CHECK(!lf_scene_intersect(&s, lf_v3(other.x, other.y, -5), lf_v3(0, 0, 1), INFINITY, 0.25f, &h));
        }
        lf_scene_free(&s);
        lf_scene_desc_free(&d);
    }
}

static const char *turning_scene =
    "LookAt 0 0 -4 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [40]\n"
    "Film \"rgb\" \"integer xresolution\" [48] \"integer yresolution\" [48]\n"
    "Sampler \"zsobol\" \"integer pixelsamples\" [16]\nPixelFilter \"box\"\n"
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.8 0.8 0.8]\n"
    "Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" [16] \"float vscale\" [4]\n"
    "  \"rgb tex1\" [0.9 0.9 0.9] \"rgb tex2\" [0.05 0.05 0.05]\n"
    "AttributeBegin\nMaterial \"diffuse\" \"texture reflectance\" \"checks\"\n"
    "ActiveTransform EndTime\nRotate 90 0 0 1\nActiveTransform All\n"
    "Shape \"disk\" \"float radius\" [1] %s\nAttributeEnd\n"
    "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.7 0.3 0.2]\nTranslate 0.6 0.4 -0.8\n"
    "ActiveTransform EndTime\nTranslate 0 -0.5 0\nRotate 120 1 1 0\nActiveTransform All\nScale 0.3 0.5 0.2\n"
    "Shape \"trianglemesh\" \"point3 P\" [-1 -1 -1 1 -1 -1 1 1 -1 -1 1 -1 -1 -1 1 1 -1 1 1 1 1 -1 1 1]\n"
    "  \"integer indices\" [0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 3 7 6 3 6 2 0 4 7 0 7 3 1 2 6 1 6 5] %s\n"
    "AttributeEnd\n";

static double rms_diff(const lf_image *a, const lf_image *b)
{
    size_t n = (size_t)a->width * a->height * 3;
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += (double)(a->data[i] - b->data[i]) * (a->data[i] - b->data[i]);
    return sqrt(s / (double)n);
}

static void test_instance_matches_keyframes(void)
{
    /* A checkered disk turning 90 degrees about its axis and a box under
     * axis scales turning 120 degrees about (1,1,0) while it translates:
     * the rigid instances against 128 keyframed segments (the most Embree
     * takes: 129 time steps; chord sagitta r (1 - cos(0.94 deg / 2)) =
     * 3.4e-5 r, 1/1000 px here) must render
     * the same image.  Margin: with the same seed the sample streams agree,
     * so the difference is far below the Monte Carlo noise, measured here
     * as the RMS difference of two seeds of the keyframed render; the
     * instanced render must be within 10% of that noise.  One segment
     * (chords through the disk's rim) is far outside it. */
    char scene[4096];
    lf_image inst, keyed, keyed2, coarse;
    char msg[2048] = "";
    char *plan = NULL;
    snprintf(scene, sizeof scene, turning_scene, "", "");
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = &plan}, &inst, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    CHECK_MSG(plan && strstr(plan, "2 moving shapes: 2 as rigid Embree instances (2 instances of 2 prototypes"),
              "plan: %s", plan ? plan : "");
    free(plan);
    const char *segs128 = "\"integer motionsegments\" [128]";
    snprintf(scene, sizeof scene, turning_scene, segs128, segs128);
    plan = NULL;
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = &plan}, &keyed, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        lf_image_free(&inst);
        return;
    }
    CHECK_MSG(plan && strstr(plan, "2 moving shapes: 2 with keyframed vertices"), "plan: %s", plan ? plan : "");
    free(plan);
    char *seed2 = strstr(scene, "[16]");
    char scene2[4096];
    snprintf(scene2, sizeof scene2, "%.*s[16] \"integer seed\" [7]%s", (int)(seed2 - scene), scene, seed2 + 4);
    snprintf(scene, sizeof scene, turning_scene, "\"integer motionsegments\" [1]", "\"integer motionsegments\" [1]");
    if (render_text(scene2, &motion_scene, &keyed2, msg, sizeof msg) ||
        render_text(scene, &motion_scene, &coarse, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        lf_image_free(&inst);
        lf_image_free(&keyed);
        return;
    }
    double noise = rms_diff(&keyed, &keyed2), d = rms_diff(&inst, &keyed), dc = rms_diff(&coarse, &keyed);
    CHECK_MSG(noise > 0 && d <= 0.1 * noise, "instanced vs 256 segments: RMS %.3g, noise (two seeds) %.3g", d, noise);
    CHECK_MSG(dc > 0.5 * noise, "one segment should differ visibly: RMS %.3g, noise %.3g", dc, noise);
    CHECK(lf_image_count_nonfinite(&inst) == 0);
    lf_image_free(&inst);
    lf_image_free(&keyed);
    lf_image_free(&keyed2);
    lf_image_free(&coarse);
}

static void test_object_instance_streaks(void)
{
    /* ObjectInstance with an animated instance transform: one prototype
     * (a 0.2-unit white square facing the camera, lit head-on by a distant
     * light, black background) placed by two moving instances, in the upper
     * half moving 3 units and in the lower half 1.5 units during the
     * exposure.  Column sums of each half: a box of 16 dx px convolved with
     * the square's 3.2 px, whose half-maximum points are the centre's start
     * and end: FWHM 48 and 24 px (margin 1 px, as test_streaks). */
    char head[1024], scene[4096];
    snprintf(head, sizeof head, camera_ortho, "");
    snprintf(scene, sizeof scene,
             "%sWorldBegin\nLightSource \"distant\" \"point3 from\" [0 0 -5] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n"
             "ObjectBegin \"tile\"\nMaterial \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
             "Shape \"trianglemesh\" \"point3 P\" [-0.1 -0.1 0 0.1 -0.1 0 0.1 0.1 0 -0.1 0.1 0]\n"
             "  \"integer indices\" [0 1 2 0 2 3]\nObjectEnd\n"
             "AttributeBegin\nTranslate -2 0.5 0\nActiveTransform EndTime\nTranslate 3 0 0\nActiveTransform All\n"
             "ObjectInstance \"tile\"\nAttributeEnd\n"
             "AttributeBegin\nTranslate -2 -0.5 0\nActiveTransform EndTime\nTranslate 1.5 0 0\nRotate 90 0 0 1\n"
             "ActiveTransform All\nObjectInstance \"tile\"\nAttributeEnd\n",
             head);
    lf_image img;
    char msg[2048] = "";
    char *plan = NULL;
    if (render_text(scene, &(lf_test_scene){MOTION_SCENE, .explain = &plan}, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        free(plan);
        return;
    }
    CHECK_MSG(plan && strstr(plan, "2 moving shapes: 2 as rigid Embree instances (2 instances of 1 prototype"),
              "plan: %s", plan ? plan : "");
    free(plan);
    for (int half = 0; half < 2; half++) {
        double S[128], l, r;
        for (int x = 0; x < 128; x++) {
            S[x] = 0;
            for (int y = 16 * half; y < 16 * half + 16; y++)
                S[x] += lf_image_px(&img, x, y)[0];
        }
        double w = fwhm(S, 128, &l, &r), expect = half ? 24.0 : 48.0;
        CHECK_MSG(fabs(w - expect) <= 1.0, "instance %d streak %.3f px, expected %g", half, w, expect);
        CHECK_MSG(fabs(l - 32.0) <= 1.0, "instance %d streak starts at %.3f px, expected 32", half, l);
    }
    CHECK(lf_image_count_nonfinite(&img) == 0);
    lf_image_free(&img);
}

/* The per-sample camera interpolation (lf_motion_pair, prepared once) gives
 * lf_decomposed_matrix's matrices; and for a turn about one axis, pbrt's
 * slerp is the rotation by the same fraction of the angle. */
static void test_motion_pair(void)
{
    const double angles[] = {0.01, 3, 30, 120, 179.9, 250};
    double worst = 0, worst_rot = 0, worst_table = 0;
    for (int a = 0; a < 6; a++) {
        for (int variant = 0; variant < 4; variant++) {
            lf_transform x0 = lf_transform_translate(1, -2, 3), x1;
            lf_transform r = lf_transform_rotate(angles[a], 0.3, 1, -0.2);
            lf_transform t = lf_transform_translate(-4, 0.5, 2);
            x1 = lf_transform_compose(&t, &r);
            if (variant == 1) { /* non-uniform scale at both keys */
                lf_transform sc = lf_transform_scale(2, 0.5, 1.5);
                x0 = lf_transform_compose(&x0, &sc);
                x1 = lf_transform_compose(&x1, &sc);
            } else if (variant == 2) { /* mirrored */
                lf_transform sc = lf_transform_scale(-1, 1, 1);
                x0 = lf_transform_compose(&x0, &sc);
                x1 = lf_transform_compose(&x1, &sc);
            } else if (variant == 3) { /* a scale that changes */
                lf_transform sc = lf_transform_scale(1.5, 0.8, 1);
                x1 = lf_transform_compose(&x1, &sc);
            }
            lf_decomposed da, db;
            CHECK(lf_transform_decompose(&x0, &da) == 0 && lf_transform_decompose(&x1, &db) == 0);
            lf_motion_pair mp;
            lf_motion_pair_prepare(&da, &db, &mp);
            const double fs[] = {0, 1e-9, 0.1, 0.37, 0.5, 0.999, 1};
            for (int k = 0; k < 7; k++) {
                double m1[4][4], m2[4][4];
                lf_decomposed_matrix(&da, &db, fs[k], m1);
                lf_motion_pair_matrix(&mp, fs[k], m2);
                for (int i = 0; i < 4; i++)
                    for (int j = 0; j < 4; j++)
                        worst = fmax(worst, fabs(m1[i][j] - m2[i][j]));
                if (variant == 0 && angles[a] < 180 && !mp.lerp) {
                    /* the rotation part is Rotate(f angle) about the same axis
                     * (below ~3.6 degrees pbrt switches to a normalised lerp) */
                    lf_transform rf = lf_transform_rotate(fs[k] * angles[a], 0.3, 1, -0.2);
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++)
                            worst_rot = fmax(worst_rot, fabs(m2[i][j] - rf.m[i][j]));
                }
            }
            /* the table the renderer lerps in: within its bound of the
             * exact matrices, between its rows too (997 times, prime) */
            lf_motion_table tb;
            CHECK(lf_motion_table_init(&mp, 1e-9, 1 << 22, &tb) == 1 && tb.n >= 1);
            for (int k = 0; k <= 997 && tb.m; k++) {
                double m1[4][4], m2[4][4];
                lf_motion_pair_matrix(&mp, k / 997.0, m1);
                lf_motion_table_matrix(&tb, k / 997.0, m2);
                for (int i = 0; i < 4; i++)
                    for (int j = 0; j < 4; j++)
                        worst_table = fmax(worst_table, fabs(m1[i][j] - m2[i][j]));
            }
            lf_motion_table_free(&tb);
        }
    }
    CHECK_MSG(worst < 1e-13, "prepared interpolation differs from lf_decomposed_matrix by %g", worst);
    CHECK_MSG(worst_table <= 1e-9, "the motion table departs from the exact matrices by %g (bound 1e-9)", worst_table);
    /* the table is the exact matrices when it must: too many steps, none */
    {
        lf_decomposed da, db;
        lf_transform x0 = lf_transform_identity(), x1 = lf_transform_rotate(170, 0, 1, 0);
        CHECK(lf_transform_decompose(&x0, &da) == 0 && lf_transform_decompose(&x1, &db) == 0);
        lf_motion_pair mp;
        lf_motion_pair_prepare(&da, &db, &mp);
        lf_motion_table tb;
        CHECK(lf_motion_table_init(&mp, 1e-9, 100, &tb) == 0 && tb.n == 0 && !tb.m);
    }
    CHECK_MSG(worst_rot < 1e-12, "slerp differs from the rotation by the same fraction by %g", worst_rot);
}

int main(void)
{
    test_motion_pair();
    test_streaks();
    test_camera_motion();
    test_rolling_shutter();
    test_static_identical();
    test_hard_cases();
    test_instance_rotation_exact();
    test_instance_frame_matches_keyframes();
    test_instance_composition();
    test_instance_half_turn();
    test_instance_matches_keyframes();
    test_object_instance_streaks();
    return lf_test_end();
}
