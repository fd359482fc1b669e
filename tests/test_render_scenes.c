/* End-to-end renders with asserted numbers from geometry and radiometry:
 * pinhole projection of a small emitter, furnace tests, irradiance from
 * point/spot/distant/sphere/disk lights, determinism across thread counts,
 * and a camera loaded from a plugin. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lf_camera.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

static const lf_test_scene one_thread = {.threads = 1};

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double pixel_mean(const lf_image *img, int x0, int x1, int y0, int y1, int c)
{
    double s = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            s += lf_image_px(img, x, y)[c];
    return s / ((x1 - x0) * (y1 - y0));
}

/* pbrt-v4 LookAt + perspective projection, computed here from the
 * definitions (camera basis, pinhole projection, raster mapping). */
static void project(const double eye[3], const double look[3], const double up[3], double fov_deg, int W, int H,
                    const double p[3], double *rx, double *ry)
{
    double dir[3], right[3], nup[3], l;
    for (int i = 0; i < 3; i++)
        dir[i] = look[i] - eye[i];
    l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int i = 0; i < 3; i++)
        dir[i] /= l;
    double u[3] = {up[0], up[1], up[2]};
    l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int i = 0; i < 3; i++)
        u[i] /= l;
    right[0] = u[1] * dir[2] - u[2] * dir[1];
    right[1] = u[2] * dir[0] - u[0] * dir[2];
    right[2] = u[0] * dir[1] - u[1] * dir[0];
    l = sqrt(right[0] * right[0] + right[1] * right[1] + right[2] * right[2]);
    for (int i = 0; i < 3; i++)
        right[i] /= l;
    nup[0] = dir[1] * right[2] - dir[2] * right[1];
    nup[1] = dir[2] * right[0] - dir[0] * right[2];
    nup[2] = dir[0] * right[1] - dir[1] * right[0];
    double q[3] = {p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]};
    double xc = q[0] * right[0] + q[1] * right[1] + q[2] * right[2];
    double yc = q[0] * nup[0] + q[1] * nup[1] + q[2] * nup[2];
    double zc = q[0] * dir[0] + q[1] * dir[1] + q[2] * dir[2];
    double t = tan(fov_deg * M_PI / 360), aspect = (double)W / H;
    double sx = xc / zc / t, sy = yc / zc / t;
    if (aspect >= 1) {
        *rx = (sx + aspect) * H / 2;
        *ry = (1 - sy) * H / 2;
    } else {
        *rx = (sx + 1) * W / 2;
        *ry = (1 / aspect - sy) * W / 2;
    }
}

static void test_projection(void)
{
    const double eye[3] = {1, 2, -6}, look[3] = {0.3, 0.5, 0}, up[3] = {0.1, 1, 0};
    const double pts[][3] = {{0.3, 0.5, 0}, {1.2, 0.9, 0.5}, {-1.0, -0.2, 1.0}, {0.8, 1.6, -1.0}};
    const int W = 96, H = 64;
    const double fov = 40;
    for (int k = 0; k < 4; k++) {
        char scene[2048];
        snprintf(scene, sizeof scene,
                 "LookAt %g %g %g %g %g %g %g %g %g\n"
                 "Camera \"perspective\" \"float fov\" [%g]\n"
                 "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
                 "Sampler \"zsobol\" \"integer pixelsamples\" [256]\n"
                 "PixelFilter \"box\"\n"
                 "WorldBegin\n"
                 "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                 " Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
                 " Translate %g %g %g\n Shape \"sphere\" \"float radius\" [0.12]\nAttributeEnd\n",
                 eye[0], eye[1], eye[2], look[0], look[1], look[2], up[0], up[1], up[2], fov, W, H, pts[k][0],
                 pts[k][1], pts[k][2]);
        lf_image img;
        char msg[1024];
        if (render_text(scene, &(lf_test_scene){.threads = 2}, &img, msg, sizeof msg)) {
            CHECK_MSG(0, "render failed: %s", msg);
            continue;
        }
        double sw = 0, sx = 0, sy = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                double v = lf_image_px(&img, x, y)[1];
                sw += v;
                sx += v * (x + 0.5);
                sy += v * (y + 0.5);
            }
        double ex, ey;
        project(eye, look, up, fov, W, H, pts[k], &ex, &ey);
        CHECK_MSG(sw > 0, "emitter %d not visible", k);
        /* The emitter's image is ~3 px across, so its centroid resolves
         * sub-pixel positions; for this small angular size the centroid of
         * the projected disk differs from the projected centre by < 0.02 px,
         * and 256 stratified samples per pixel keep the noise below that. */
        CHECK_MSG(fabs(sx / sw - ex) <= 0.25 && fabs(sy / sw - ey) <= 0.25,
                  "emitter %d: centroid (%.3f, %.3f), projection predicts (%.3f, %.3f)", k, sx / sw, sy / sw, ex, ey);
        lf_image_free(&img);
    }
}

/* Diffuse sphere of albedo a under a uniform environment of radiance L:
 * pixels on the sphere are a*L (it is convex, so light reaches it directly),
 * background pixels L. */
static void test_furnace(double albedo, const char *sampler)
{
    const double L = 0.7;
    char scene[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 -4 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
             "Film \"rgb\" \"integer xresolution\" [48] \"integer yresolution\" [48]\n"
             "Sampler \"%s\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [5]\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n"
             "Material \"diffuse\" \"rgb reflectance\" [%g %g %g]\nShape \"sphere\" \"float radius\" [1]\n",
             sampler, L, L, L, albedo, albedo, albedo);
    lf_image img;
    char msg[1024];
    if (render_text(scene, &(lf_test_scene){.threads = 2}, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    /* The sphere (radius 1 at distance 4, fov 30) covers a disk of radius
     * tan(asin(1/4))/tan(15 deg) * 24 = 23.1 px; use pixels well inside and
     * well outside it. */
    double in_sum = 0, in_sum2 = 0, out_sum = 0, out_max_dev = 0;
    int n_in = 0, n_out = 0;
    double R = tan(asin(0.25)) / tan(15 * M_PI / 180) * 24;
    for (int y = 0; y < 48; y++)
        for (int x = 0; x < 48; x++) {
            double r = hypot(x + 0.5 - 24, y + 0.5 - 24);
            float *p = lf_image_px(&img, x, y);
            if (r < R - 2) {
                in_sum += p[0];
                in_sum2 += p[0] * p[0];
                n_in++;
                CHECK(p[0] == p[1] && p[1] == p[2]);
            } else if (r > R + 2) {
                out_sum += p[0];
                out_max_dev = fmax(out_max_dev, fabs(p[0] - L));
                n_out++;
            }
        }
    double mean = in_sum / n_in, sd = sqrt(fmax(0, in_sum2 / n_in - mean * mean));
    /* Noise margin: the mean of ~1500 pixels of 64 spp; 4 standard errors
     * of the measured per-pixel spread, plus float rounding. */
    CHECK_MSG(fabs(mean - albedo * L) <= 4 * sd / sqrt(n_in) + 1e-5, "%s furnace albedo %g: sphere mean %.6f, expected %.6f (sd %.4f)",
              sampler, albedo, mean, albedo * L, sd);
    CHECK_MSG(sd < 0.05 * albedo * L + 1e-6, "%s furnace: per-pixel spread %.4f too large", sampler, sd);
    CHECK_NEAR(out_sum / n_out, L, 1e-6); /* background: the environment itself, exact */
    CHECK(out_max_dev < 1e-6);
    lf_image_free(&img);
}

/* An orthographic camera looks straight down at a diffuse plane (albedo a)
 * lit by one light (the camera sits below the lights; it is not geometry); the radiance leaving the plane at the pixel under the
 * light is a/pi * E with E from the light's closed-form irradiance. */
static void test_irradiance(const char *light, double expected_E, const char *what)
{
    const double a = 0.5;
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0.5 0  0 0 0  0 0 1\nCamera \"orthographic\" \"float screenwindow\" [-0.05 0.05 -0.05 0.05]\n"
             "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [1024]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\n"
             "WorldBegin\n%s\n"
             "Material \"diffuse\" \"rgb reflectance\" [%g %g %g]\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-10 0 -10  10 0 -10  -10 0 10  10 0 10]\n",
             light, a, a, a);
    lf_image img;
    char msg[1024];
    if (render_text(scene, &(lf_test_scene){.threads = 2}, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "%s: render failed: %s", what, msg);
        return;
    }
    double v = pixel_mean(&img, 0, 8, 0, 8, 1);
    double expected = a / M_PI * expected_E;
    /* 64 pixels x 1024 samples; area-light estimates carry MC noise well
     * below 1%; point-like lights are exact up to the 0.05-unit footprint. */
    CHECK_MSG(fabs(v - expected) <= 0.01 * expected, "%s: radiance %.6f, expected a/pi*E = %.6f", what, v, expected);
    lf_image_free(&img);
}

static void test_lights(void)
{
    /* point light of intensity I at height h: E = I / h^2 */
    test_irradiance("LightSource \"point\" \"point3 from\" [0 2 0] \"rgb I\" [3 3 3]", 3.0 / 4, "point light");
    /* spot pointing down, well inside the cone: same as the point light */
    test_irradiance("LightSource \"spot\" \"point3 from\" [0 2 0] \"point3 to\" [0 0 0] \"rgb I\" [3 3 3] "
                    "\"float coneangle\" [30]",
                    3.0 / 4, "spot light");
    /* distant light at 60 degrees from the normal: E = L cos(60) */
    test_irradiance("LightSource \"distant\" \"point3 from\" [0 1 1.7320508] \"point3 to\" [0 0 0] \"rgb L\" [2 2 2]",
                    1.0, "distant light");
    /* emissive sphere radius r, centre at distance d seen at angle theta
     * from the normal (fully above the horizon): E = pi L (r/d)^2 cos(theta);
     * centre (1.5, 2, 0): d = 2.5, cos = 0.8 */
    test_irradiance("AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\nTranslate 1.5 2 0\n"
                    "Shape \"sphere\" \"float radius\" [0.5]\nAttributeEnd",
                    M_PI * 4 * 0.04 * 0.8, "sphere light");
    /* one-sided disk of radius R at height h facing down: E = pi L R^2/(h^2+R^2) */
    test_irradiance("AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\nTranslate 0 1 0\nRotate 90 1 0 0\n"
                    "Shape \"disk\" \"float radius\" [0.75]\nAttributeEnd",
                    M_PI * 2 * 0.5625 / (1 + 0.5625), "disk light");
    /* uniform environment L over the upper hemisphere: E = pi L */
    test_irradiance("LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]", M_PI * 0.5, "uniform sky");
}

/* Every light sampler converges to the same irradiance: a distant light at
 * 60 degrees (E = L cos 60 = 1), a point light at height 2 (E = I/h^2 =
 * 0.75) and a uniform sky (E = pi L = pi/2) over a diffuse plane; the
 * radiance is a/pi times their sum.  Sampling every light at every vertex
 * leaves no choice variance, while choosing one light by power adds it:
 * with 16 samples per pixel the pixel-to-pixel spread must be at least 2x
 * smaller (measured 4.6e-5 against 0.12: power rarely picks the point light
 * and then weights it by 1/pmf).  A uniform choice is as good here (4.6e-5):
 * the choice dimension is stratified over the 16 samples. */
static void test_light_samplers(void)
{
    const char *names[] = {"all", "power", "uniform", "bvh"};
    const double a = 0.5, expected = a / M_PI * (1.0 + 0.75 + M_PI * 0.5);
    double spread[4] = {0};
    for (int k = 0; k < 4; k++) {
        for (int spp = 16; spp <= 1024; spp *= 64) {
            char scene[2048];
            snprintf(scene, sizeof scene,
                     "LookAt 0 0.5 0  0 0 0  0 0 1\nCamera \"orthographic\" \"float screenwindow\" [-0.05 0.05 -0.05 0.05]\n"
                     "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [%d]\nPixelFilter \"box\"\n"
                     "Integrator \"path\" \"integer maxdepth\" [1] \"string lightsampler\" \"%s\"\n"
                     "WorldBegin\n"
                     "LightSource \"distant\" \"point3 from\" [0 1 1.7320508] \"point3 to\" [0 0 0] \"rgb L\" [2 2 2]\n"
                     "LightSource \"point\" \"point3 from\" [0 2 0] \"rgb I\" [3 3 3]\n"
                     "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
                     "Material \"diffuse\" \"rgb reflectance\" [%g %g %g]\n"
                     "Shape \"bilinearmesh\" \"point3 P\" [-10 0 -10  10 0 -10  -10 0 10  10 0 10]\n",
                     spp, names[k], a, a, a);
            lf_image img;
            char msg[1024];
            if (render_text(scene, &(lf_test_scene){.threads = 2}, &img, msg, sizeof msg)) {
                CHECK_MSG(0, "lightsampler %s: render failed: %s", names[k], msg);
                return;
            }
            double m = pixel_mean(&img, 0, 8, 0, 8, 1);
            if (spp == 1024) /* 64 pixels x 1024 samples: noise well below 1% */
                CHECK_MSG(fabs(m - expected) <= 0.01 * expected, "lightsampler %s: radiance %.6f, expected %.6f",
                          names[k], m, expected);
            else {
                double ss = 0;
                for (int y = 0; y < 8; y++)
                    for (int x = 0; x < 8; x++)
                        ss += pow(lf_image_px(&img, x, y)[1] - m, 2);
                spread[k] = sqrt(ss / 63);
            }
            lf_image_free(&img);
        }
    }
    CHECK_MSG(spread[0] < 0.5 * spread[1] && spread[0] <= 1.5 * spread[2],
              "sampling all lights should be much less noisy than choosing by power: spread all %.4g, power %.4g, "
              "uniform %.4g",
              spread[0], spread[1], spread[2]);
    CHECK_MSG(spread[3] == spread[0], "\"bvh\" with 3 lights should sample all of them (%.4g vs %.4g)", spread[3],
              spread[0]);
}

static void test_thread_determinism(void)
{
    const char *scene =
        "LookAt 0 1 -5 0 0.5 0 0 1 0\nCamera \"perspective\" \"float fov\" [40] \"float lensradius\" [0.05] "
        "\"float focaldistance\" [5]\n"
        "Film \"rgb\" \"integer xresolution\" [61] \"integer yresolution\" [37]\n"
        "Sampler \"zsobol\" \"integer pixelsamples\" [8]\nPixelFilter \"gaussian\"\n"
        "WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.4 0.5 0.6]\n"
        "LightSource \"point\" \"point3 from\" [1 3 -1] \"rgb I\" [5 5 5]\n"
        "Material \"diffuse\"\nShape \"bilinearmesh\" \"point3 P\" [-5 0 -5 5 0 -5 -5 0 5 5 0 5]\n"
        "Material \"dielectric\"\nTranslate 0 0.6 0\nShape \"sphere\" \"float radius\" [0.6]\n";
    lf_image a, b, c;
    char msg[1024];
    int ra = render_text(scene, &(lf_test_scene){.threads = 1}, &a, msg, sizeof msg);
    int rb = render_text(scene, &(lf_test_scene){.threads = 2}, &b, msg, sizeof msg);
    int rc = render_text(scene, &(lf_test_scene){.threads = 5}, &c, msg, sizeof msg);
    CHECK_MSG(ra == 0 && rb == 0 && rc == 0, "%s", msg);
    if (ra || rb || rc)
        return;
    size_t n = (size_t)a.width * a.height * 3 * sizeof(float);
    CHECK(memcmp(a.data, b.data, n) == 0);
    CHECK(memcmp(a.data, c.data, n) == 0);
    CHECK(lf_image_count_nonfinite(&a) == 0);
    lf_image_free(&a);
    lf_image_free(&b);
    lf_image_free(&c);
}

static void test_plugin_camera(void)
{
    char err[1024];
    if (!lf_camera_find("panorama"))
        CHECK_MSG(lf_camera_load_plugin(LF_PLUGIN_PATH, err, sizeof err) == 0, "%s", err);
    /* Camera at the origin looking along +z (no LookAt): an emitter on the
     * camera's +x axis sits at longitude +90 deg: x = W (1/2 + 90/360). */
    const char *scene = "Camera \"panorama\"\n"
                        "Film \"rgb\" \"integer xresolution\" [72] \"integer yresolution\" [36]\n"
                        "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
                        "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                        "Translate 5 0 0\nShape \"sphere\" \"float radius\" [0.05]\n";
    lf_image img;
    char msg[1024];
    if (render_text(scene, &(lf_test_scene){.threads = 2}, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "plugin render failed: %s", msg);
        return;
    }
    double sw = 0, sx = 0, sy = 0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            double v = lf_image_px(&img, x, y)[0];
            sw += v, sx += v * (x + 0.5), sy += v * (y + 0.5);
        }
    CHECK(sw > 0);
    CHECK_NEAR(sx / sw, 72 * 0.75, 0.25);
    CHECK_NEAR(sy / sw, 18, 0.25);
    lf_image_free(&img);
}

static void test_errors(void)
{
    lf_image img;
    char msg[1024] = "";
    CHECK(render_text("Camera \"perspective\" \"float fvo\" [30]\nWorldBegin\n", &one_thread, &img, msg, sizeof msg) !=
          0);
    CHECK_MSG(strstr(msg, "test.pbrt:1:") && strstr(msg, "fvo"), "message: %s", msg);
    CHECK(render_text("Camera \"nosuchcamera\"\nWorldBegin\n", &one_thread, &img, msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "nosuchcamera") && strstr(msg, "perspective"), "message: %s", msg);
    CHECK(render_text("WorldBegin\nShape \"sphere\" \"float radius\" [-1]\n", &one_thread, &img, msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "test.pbrt:2:"), "message: %s", msg);
    CHECK(render_text("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 5]\n",
                      &one_thread, &img, msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "out of range"), "message: %s", msg);
    CHECK(render_text("WorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1] \"float scael\" [2]\n", &one_thread, &img,
                      msg, sizeof msg) != 0);
    CHECK_MSG(strstr(msg, "scael"), "message: %s", msg);
    CHECK(render_text("Integrator \"path\" \"string lightsampler\" \"tree\"\nWorldBegin\n", &one_thread, &img, msg,
                      sizeof msg) !=
          0);
    CHECK_MSG(strstr(msg, "test.pbrt:1:") && strstr(msg, "lightsampler") && strstr(msg, "tree"), "message: %s", msg);
}

int main(void)
{
    test_projection();
    test_furnace(1.0, "zsobol");
    test_furnace(0.5, "zsobol");
    test_furnace(0.5, "independent");
    test_lights();
    test_light_samplers();
    test_thread_determinism();
    test_plugin_camera();
    test_errors();
    return lf_test_end();
}
