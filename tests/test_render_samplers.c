/* pbrt-v4's halton and pmj02bn samplers render a known integral without
 * bias: a white Lambertian plane lit by a square emitter of radiance 1 at
 * height c above it has radiance F (the point-to-rectangle form factor,
 * closed form for a rectangle parallel to the plane) wherever it is seen;
 * direct light only (maxdepth 1).  The expected value is the form factor at
 * each pixel's centre (the view covers a 0.1-unit patch, over which F
 * varies by < 0.1 %), averaged over the image.  Margin 1.5 % (4096 paths
 * whose per-path spread, light sampling against BSDF sampling with MIS, is
 * below 0.3 of the mean: 1 sigma ~ 0.5 % for independent samples, less for
 * these stratified ones).  Also: the renderer rounds pmj02bn's count up to
 * a power of 4 with a note, and refuses halton's "fastowen". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Form factor from the origin's surface element (normal +z) to the
 * rectangle [0,a] x [0,b] at height c, and its signed combination for any
 * rectangle parallel to the plane. */
static double ff_corner(double a, double b, double c)
{
    double A = a / c, B = b / c, sa = sqrt(1 + A * A), sb = sqrt(1 + B * B);
    return (A / sa * atan(B / sa) + B / sb * atan(A / sb)) / (2 * M_PI);
}
static double form_factor(double x0, double y0, double x1, double x2, double y1, double y2, double c)
{
    return ff_corner(x2 - x0, y2 - y0, c) - ff_corner(x1 - x0, y2 - y0, c) - ff_corner(x2 - x0, y1 - y0, c) +
           ff_corner(x1 - x0, y1 - y0, c);
}

static const double cam[3] = {1.5, 0.2, 0.6}, c = 1.0, h = 0.5; /* light [-h,h]^2 at z = c */
enum { RES = 8 };

/* The analytic mean over pixel centres: pinhole rays of the perspective
 * camera (pbrt's screen window, fov across the shorter axis) hit z = 0. */
static double expected(double fov_deg)
{
    double f[3] = {-cam[0], -cam[1], -cam[2]}, len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= len;
    /* LookAt with up +z: pbrt's camera x = up x forward... built as right = normalize(up x f), u = f x right */
    double up[3] = {0, 0, 1};
    double r[3] = {up[1] * f[2] - up[2] * f[1], up[2] * f[0] - up[0] * f[2], up[0] * f[1] - up[1] * f[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        r[k] /= rl;
    double u[3] = {f[1] * r[2] - f[2] * r[1], f[2] * r[0] - f[0] * r[2], f[0] * r[1] - f[1] * r[0]};
    double t = tan(fov_deg * M_PI / 360), sum = 0;
    for (int py = 0; py < RES; py++)
        for (int px = 0; px < RES; px++) {
            double sx = (-1 + 2 * (px + 0.5) / RES) * t, sy = (1 - 2 * (py + 0.5) / RES) * t;
            double d[3];
            for (int k = 0; k < 3; k++)
                d[k] = f[k] + sx * r[k] + sy * u[k];
            double s = -cam[2] / d[2];
            sum += form_factor(cam[0] + s * d[0], cam[1] + s * d[1], -h, h, -h, h, c);
        }
    return sum / (RES * RES);
}

static void test_known_integral(const char *sampler)
{
    const double fov = 2.0;
    char scene[4096];
    snprintf(scene, sizeof scene,
             "LookAt %g %g %g  0 0 0  0 0 1\n"
             "Camera \"perspective\" \"float fov\" [%g]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler %s \"integer pixelsamples\" [64]\n"
             "Integrator \"volpath\" \"integer maxdepth\" [1]\n"
             "PixelFilter \"box\" \"float xradius\" 0.5 \"float yradius\" 0.5\nWorldBegin\n"
             "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" true\n"
             "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
             "  \"point3 P\" [%g %g %g  %g %g %g  %g %g %g  %g %g %g]\nAttributeEnd\n"
             "Material \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
             "  \"point3 P\" [-20 -20 0  20 -20 0  20 20 0  -20 20 0]\n",
             cam[0], cam[1], cam[2], fov, RES, RES, sampler, -h, -h, c, h, -h, c, h, h, c, -h, h, c);
    lf_image img = {0};
    char msg[1024] = "";
    int rc = render_text(scene, NULL, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s: %s", sampler, msg);
    if (rc)
        return;
    double m = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++)
            m += lf_image_px(&img, x, y)[1];
    m /= RES * RES;
    double want = expected(fov);
    CHECK_MSG(fabs(m / want - 1) < 0.015, "Sampler %s: rendered %g, form factor %g", sampler, m, want);
    if (getenv("LF_VERBOSE"))
        printf("%s: rendered %.6g, form factor %.6g\n", sampler, m, want);
    lf_image_free(&img);
}

int main(void)
{
    test_known_integral("\"halton\"");
    test_known_integral("\"halton\" \"string randomization\" \"owen\"");
    test_known_integral("\"halton\" \"string randomization\" \"none\"");
    test_known_integral("\"pmj02bn\"");
    test_known_integral("\"independent\" \"integer seed\" 4");

    char *warn = NULL, msg[1024] = "";
    int rc = render_text("Sampler \"pmj02bn\" \"integer pixelsamples\" 20\nWorldBegin\n",
                         &(lf_test_scene){.warnings = &warn}, NULL, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    CHECK_MSG(warn && strstr(warn, "rounded up to 64"), "%s", warn ? warn : "(no warnings)");
    free(warn);
    rc = render_text("Sampler \"halton\" \"string randomization\" \"fastowen\"\nWorldBegin\n", NULL, NULL, msg,
                     sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:1:1") && strstr(msg, "fastowen"), "%s", msg);
    return lf_test_end();
}
