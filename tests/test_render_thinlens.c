/* Rendered thin-lens tests with numbers from optics, not from pictures:
 *   - defocus: the blur disk of a small out-of-focus emitter has the
 *     effective diameter 2 sqrt(flux / (pi plateau)) the formula predicts,
 *     for pbrt's perspective (2 r F_px |1/d - 1/z|) and for the physical
 *     thinlens (C = A |z_s - z_i| / z_i), within 2%;
 *   - a 5-blade aperture blurs into a pentagon with its corners on that
 *     circle: extents along a corner and along an edge normal;
 *   - exposure: 2x shutter time, 2x ISO, one stop;
 *   - flat field: a uniform sky through the thinlens falls off as the exact
 *     disk integral (1/z_s^2) \int cos^4 dA, i.e. cos^4 theta for a small
 *     aperture, across the frame.
 * Monte Carlo tests use the fixed seed in their scene and state their noise
 * margins next to the assertion. */
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

/* Flux (sum of pixel values) and plateau (mean over pixels whose whole
 * area lies within plateau_r of the centre (cx, cy), raster units). */
static void disk_stats(const lf_image *img, double cx, double cy, double plateau_r, double *flux, double *plateau)
{
    double f = 0, p = 0;
    int np = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++) {
            double v = lf_image_px(img, x, y)[1];
            f += v;
            double dx = fmax(fabs(x - cx), fabs(x + 1 - cx)), dy = fmax(fabs(y - cy), fabs(y + 1 - cy));
            if (hypot(dx, dy) <= plateau_r) {
                p += v;
                np++;
            }
        }
    *flux = f;
    *plateau = np ? p / np : 0;
}

static const char *emitter_fmt = "WorldBegin\n"
                                 "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
                                 " Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
                                 " Translate %.9g %.9g %.9g\n Shape \"sphere\" \"float radius\" [%.9g]\nAttributeEnd\n";

static int verbose;

/* Thinlens: f = 50 mm, N = 8, focus 2 m, an emitter of radius rho at depth
 * z on the axis; full frame sensor with the resolution that makes the blur
 * ~64 px (3:2 image), only the 128 x 128 pixels around the centre rendered
 * (pixelbounds). */
static void test_thinlens_defocus(double z, int spp, unsigned seed)
{
    const double f = 0.05, N = 8, d = 2;
    const double zs = 1 / (1 / f - 1 / d), zi = 1 / (1 / f - 1 / z), A = f / N;
    const double C = A * fabs(zs - zi) / zi; /* blur circle on the sensor, m */
    const int W = 2 * (int)lround(0.036 / (C / 64) / 2), H = W / 3 * 2 / 2 * 2; /* even sizes */
    const double pitch = 0.036 / W;
    const double C_px = C / pitch;
    /* emitter: its own (chief-ray) image on the sensor is ~ 0.28 C across */
    const double e_px = 0.28 * C_px, rho = e_px * pitch / 2 * z / zs;
    char scene[4096];
    int n = snprintf(scene, sizeof scene,
                     "Camera \"thinlens\" \"float focallength\" [50] \"float fstop\" [8] \"float focusdistance\" [2]\n"
                     "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
                     " \"integer pixelbounds\" [%d %d %d %d]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [%d] \"integer seed\" [%u]\n"
                     "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [1]\n",
                     W, H, W / 2 - 64, W / 2 + 64, H / 2 - 64, H / 2 + 64, spp, seed);
    snprintf(scene + n, sizeof scene - n, emitter_fmt, 0.0, 0.0, z, rho);
    lf_image img;
    char msg[1024];
    if (render_text(scene, NULL, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    double flux, plateau;
    disk_stats(&img, 64, 64, 0.8 * (C_px - e_px) / 2, &flux, &plateau);
    double D = 2 * sqrt(flux / (M_PI * plateau));
    if (verbose)
        printf("thinlens z=%g seed %u spp %d: C %.3f px, D_eff %.3f px (%.3f%%)\n", z, seed, spp, C_px, D,
               100 * (D / C_px - 1));
    CHECK_MSG(fabs(D / C_px - 1) <= 0.02, "thinlens depth %g m: effective blur diameter %.3f px, C = %.3f px", z, D,
              C_px);
    lf_image_free(&img);
}

/* pbrt's perspective: blur in pixels 2 r F_px |1/d - 1/z|, F_px = (shorter
 * side / 2) / tan(fov/2). */
static void test_perspective_defocus(double z, int spp, unsigned seed)
{
    const double fov = 10, d = 2;
    const double Fpx = 64 / tan(fov * M_PI / 360);
    const double r = 64 / (2 * Fpx * fabs(1 / d - 1 / z)); /* a ~64 px blur */
    const double B = 2 * r * Fpx * fabs(1 / d - 1 / z);
    const double e_px = 0.28 * B, rho = e_px / 2 * z / Fpx;
    char scene[4096];
    int n = snprintf(scene, sizeof scene,
                     "Camera \"perspective\" \"float fov\" [%g] \"float lensradius\" [%g] \"float focaldistance\" [%g]\n"
                     "Film \"rgb\" \"integer xresolution\" [128] \"integer yresolution\" [128]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [%d] \"integer seed\" [%u]\n"
                     "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [1]\n",
                     fov, r, d, spp, seed);
    snprintf(scene + n, sizeof scene - n, emitter_fmt, 0.0, 0.0, z, rho);
    lf_image img;
    char msg[1024];
    if (render_text(scene, NULL, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return;
    }
    double flux, plateau;
    disk_stats(&img, 64, 64, 0.8 * (B - e_px) / 2, &flux, &plateau);
    double D = 2 * sqrt(flux / (M_PI * plateau));
    if (verbose)
        printf("perspective z=%g seed %u spp %d: B %.3f px, D_eff %.3f px (%.3f%%)\n", z, seed, spp, B, D,
               100 * (D / B - 1));
    CHECK_MSG(fabs(D / B - 1) <= 0.02, "perspective depth %g m: effective blur diameter %.3f px, formula %.3f px", z, D,
              B);
    lf_image_free(&img);
}

/* E|X - a| for X uniform on [-h, h] and a distributed as the x marginal of
 * the uniform disk of radius rho (density 2 sqrt(rho^2 - a^2) / (pi rho^2)):
 * midpoint quadrature. */
static double mean_abs_offset(double h, double rho)
{
    const int n = 1000;
    double s = 0, wsum = 0;
    for (int i = 0; i < n; i++) {
        double x = -h + (i + 0.5) * 2 * h / n;
        for (int j = 0; j < n; j++) {
            double a = -rho + (j + 0.5) * 2 * rho / n;
            double w = sqrt(rho * rho - a * a);
            s += w * fabs(x - a);
            wsum += w;
        }
    }
    return s / wsum;
}

/* A 5-blade aperture (a corner pointing up on the lens) blurs an emitter
 * beyond the focus plane into an upright pentagon with its corners on the
 * blur circle of radius Rc px.  Extents are measured as the integrated
 * coverage (value / centre plateau) along a strip 2h px wide through the
 * centre: upwards (a corner) and downwards (an edge normal).  Geometry of
 * the expected values: the edge is flat across the strip, so its extent is
 * the apothem Rc cos(pi/5) exactly; at the corner the boundary drops by
 * |x| tan(pi/5) off the axis, and the emitter's own image (a uniform disk of
 * radius rho px) smears it, so the strip sees Rc - tan(pi/5) E|X - a|. */
static void pentagon_extents(const lf_image *img, double cx, double cy, int h, double plateau, double *up,
                             double *down)
{
    double u = 0, dn = 0;
    for (int x = (int)cx - h; x < (int)cx + h; x++)
        for (int y = 0; y < img->height; y++) {
            double v = lf_image_px(img, x, y)[1] / plateau;
            if (y < cy)
                u += v;
            else
                dn += v;
        }
    *up = u / (2 * h);
    *down = dn / (2 * h);
}

static void check_pentagon(const char *what, const char *camera, int W, int H, int x0, int y0, double Rc, double z,
                           double rho_world, double rho_px, int spp, unsigned seed)
{
    char scene[4096];
    int n = snprintf(scene, sizeof scene,
                     "%s \"string aperture\" \"pentagon\"\n"
                     "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
                     " \"integer pixelbounds\" [%d %d %d %d]\n"
                     "Sampler \"zsobol\" \"integer pixelsamples\" [%d] \"integer seed\" [%u]\n"
                     "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [1]\n",
                     camera, W, H, x0, x0 + 128, y0, y0 + 128, spp, seed);
    snprintf(scene + n, sizeof scene - n, emitter_fmt, 0.0, 0.0, z, rho_world);
    lf_image img;
    char msg[1024];
    if (render_text(scene, NULL, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "%s: render failed: %s", what, msg);
        return;
    }
    double flux, plateau;
    const double apothem = Rc * cos(M_PI / 5);
    disk_stats(&img, 64, 64, 0.8 * (apothem - rho_px), &flux, &plateau);
    const int h = 4;
    double up, down;
    pentagon_extents(&img, 64, 64, h, plateau, &up, &down);
    double corner = Rc - tan(M_PI / 5) * mean_abs_offset(h, rho_px);
    double ratio = (up / corner * Rc) / down; /* the strip's corner loss undone */
    if (verbose)
        printf("%s seed %u spp %d: up %.3f (expect %.3f), down %.3f (expect %.3f), ratio %.4f (1/cos36 = %.4f)\n",
               what, seed, spp, up, corner, down, apothem, ratio, 1 / cos(M_PI / 5));
    /* Noise: over seeds the extents scatter by ~0.3%; the margin is 2%. */
    CHECK_MSG(fabs(ratio * cos(M_PI / 5) - 1) <= 0.02, "%s: corner/edge extent ratio %.4f, expected 1/cos(pi/5) = %.4f",
              what, ratio, 1 / cos(M_PI / 5));
    CHECK_MSG(fabs(up / corner - 1) <= 0.02, "%s: corner extent %.3f px, blur circle radius gives %.3f px", what, up,
              corner);
    CHECK_MSG(fabs(down / apothem - 1) <= 0.02, "%s: edge extent %.3f px, Rc cos(pi/5) = %.3f px", what, down,
              apothem);
    lf_image_free(&img);
}

static void test_pentagon_bokeh(int spp, unsigned seed)
{
    /* perspective: fov 10 on 128 x 128, lens radius r, focus 2 m, emitter at
     * 20 m: blur circle radius Rc = r F_px |1/d - 1/z| = 48 px */
    {
        const double fov = 10, d = 2, z = 20, Fpx = 64 / tan(fov * M_PI / 360);
        const double Rc = 48, r = Rc / (Fpx * fabs(1 / d - 1 / z));
        const double rho_px = 16, rho = rho_px * z / Fpx;
        char cam[512];
        snprintf(cam, sizeof cam,
                 "Camera \"perspective\" \"float fov\" [%g] \"float lensradius\" [%.9g] \"float focaldistance\" [%g]",
                 fov, r, d);
        check_pentagon("perspective pentagon", cam, 128, 128, 0, 0, Rc, z, rho, rho_px, spp, seed);
    }
    /* thinlens f = 50 mm f/8 focused at 2 m, emitter at 20 m: blur circle
     * C = A |z_s - z_i| / z_i, pitch chosen so that C = 96 px (Rc = 48) */
    {
        const double f = 0.05, N = 8, d = 2, z = 20;
        const double zs = 1 / (1 / f - 1 / d), zi = 1 / (1 / f - 1 / z), C = f / N * fabs(zs - zi) / zi;
        const int W = 2 * (int)lround(0.036 / (C / 96) / 2), H = W / 3 * 2 / 2 * 2;
        const double pitch = 0.036 / W, Rc = C / pitch / 2;
        const double rho_px = 16, rho = rho_px * pitch * z / zs;
        check_pentagon("thinlens pentagon",
                       "Camera \"thinlens\" \"float focallength\" [50] \"float fstop\" [8] \"float focusdistance\" [2]",
                       W, H, W / 2 - 64, H / 2 - 64, Rc, z, rho, rho_px, spp, seed);
    }
}

/* Irradiance at a film point at distance r off the axis from a uniform
 * radiance L seen through a circular aperture of radius R at distance z
 * (parallel planes): E = (1/z^2) \int L cos^4 dA = pi L F with the
 * point-to-parallel-disk configuration factor
 *   F = 1/2 [1 - (z^2 + r^2 - R^2) / sqrt((z^2 + r^2 + R^2)^2 - 4 r^2 R^2)]
 * (Howell, catalog of configuration factors, B-13). */
static double disk_irradiance(double L, double z, double r, double R)
{
    double a = z * z + r * r;
    return M_PI * L * 0.5 * (1 - (a - R * R) / sqrt((a + R * R) * (a + R * R) - 4 * r * r * R * R));
}

/* Renders the uniform sky L through the thinlens (f = 50 mm, focus 1e6 m,
 * full frame, 96 x 64 pixels) with the given f-number, shutter and ISO. */
static int render_sky(double L, double N, double shutter, double iso, int spp, lf_image *img)
{
    char scene[2048], msg[1024];
    snprintf(scene, sizeof scene,
             "Camera \"thinlens\" \"float focallength\" [50] \"float fstop\" [%.9g] \"float focusdistance\" [1e6]\n"
             " \"float shutteropen\" [0] \"float shutterclose\" [%g]\n"
             "Film \"rgb\" \"integer xresolution\" [96] \"integer yresolution\" [64] \"float iso\" [%g]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [%d] \"integer seed\" [3]\n"
             "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [1]\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n",
             N, shutter, iso, spp, L, L, L);
    if (render_text(scene, NULL, img, msg, sizeof msg)) {
        CHECK_MSG(0, "sky render failed: %s", msg);
        return -1;
    }
    return 0;
}

/* Flat field: every pixel against the exact disk integral (<0.5%: the only
 * noise is cos^4 varying over the lens, < 0.05% at 64 spp; evaluating at
 * the pixel centre instead of averaging over the pixel is < 1e-4), and the
 * falloff against cos^4(theta) of the chief ray within 2% (for f/8 the exact
 * integral differs from cos^4 by < 0.5% even in the corners). */
static void test_flat_field(void)
{
    const double L = 0.8, N = 8, f = 0.05, zs = 1 / (1 / f - 1 / 1e6), R = f / (2 * N);
    lf_image img;
    if (render_sky(L, N, 1, 100, 64, &img))
        return;
    const double pitch = 0.036 / 96;
    double E0 = disk_irradiance(L, zs, 0, R);
    /* the camera equation on axis: pi L / (1 + 4 N^2) ~ pi L / (4 N^2) */
    CHECK_NEAR(E0, M_PI * L / (1 + (zs / R) * (zs / R)), 1e-15);
    CHECK_NEAR(E0, M_PI * L / (1 + 4 * N * N), 1e-6 * E0); /* z_s = f (1 + 5e-8) */
    double centre = (lf_image_px(&img, 47, 31)[1] + lf_image_px(&img, 48, 32)[1] + lf_image_px(&img, 47, 32)[1] +
                     lf_image_px(&img, 48, 31)[1]) / 4;
    int bad_exact = 0, bad_cos4 = 0;
    double worst_exact = 0, worst_cos4 = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 96; x++) {
            double sx = (x + 0.5 - 48) * pitch, sy = (32 - y - 0.5) * pitch, r = hypot(sx, sy);
            double v = lf_image_px(&img, x, y)[1];
            double exact = disk_irradiance(L, zs, r, R);
            double c2 = zs * zs / (zs * zs + r * r), cos4 = c2 * c2;
            /* the 4 centre pixels are 0.7 px (0.27 mm) off the axis: cos^4 there is 1 - 6e-5 */
            double e1 = fabs(v / exact - 1), e2 = fabs(v / centre / cos4 - 1);
            worst_exact = fmax(worst_exact, e1);
            worst_cos4 = fmax(worst_cos4, e2);
            bad_exact += e1 > 0.005;
            bad_cos4 += e2 > 0.02;
        }
    CHECK_MSG(bad_exact == 0, "flat field: %d pixels off the exact disk integral by > 0.5%% (worst %.4f%%)", bad_exact,
              100 * worst_exact);
    CHECK_MSG(bad_cos4 == 0, "flat field: %d pixels off cos^4 by > 2%% (worst %.4f%%)", bad_cos4, 100 * worst_cos4);
    if (verbose)
        printf("flat field: worst vs exact %.4f%%, vs cos^4 %.4f%%\n", 100 * worst_exact, 100 * worst_cos4);
    /* the corner pixel is really darker: cos^4 of the half-diagonal angle */
    double rc = hypot(47.5, 31.5) * pitch, c2 = zs * zs / (zs * zs + rc * rc);
    CHECK(lf_image_px(&img, 0, 0)[1] < centre * (c2 * c2 + 0.01));
    lf_image_free(&img);
}

/* Mean of the central 16 x 16 pixels of the 96 x 64 sky image. */
static double centre_block(const lf_image *img)
{
    double s = 0;
    for (int y = 24; y < 40; y++)
        for (int x = 40; x < 56; x++)
            s += lf_image_px(img, x, y)[1];
    return s / 256;
}

/* The same block divided by the exact irradiance of each pixel centre. */
static double block_vs_exact(const lf_image *img, double N)
{
    const double f = 0.05, zs = 1 / (1 / f - 1 / 1e6), R = f / (2 * N), pitch = 0.036 / 96;
    double s = 0, e = 0;
    for (int y = 24; y < 40; y++)
        for (int x = 40; x < 56; x++) {
            s += lf_image_px(img, x, y)[1];
            e += disk_irradiance(1, zs, hypot((x + 0.5 - 48) * pitch, (32 - y - 0.5) * pitch), R);
        }
    return s / e;
}

static double image_mean(const lf_image *img)
{
    double s = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            s += lf_image_px(img, x, y)[1];
    return s / (img->width * img->height);
}

/* Exposure: the host's imaging ratio (shutter time x ISO / 100) and the
 * f-number.  Time and ISO draw the very same rays, so the ratio is 2 up to
 * float rounding.  One stop (N -> N / sqrt 2) doubles the aperture area;
 * the exact irradiance ratio on the axis is (1 + 4 N^2) / (1 + 2 N^2) (the
 * disk integral), which is 2 within 1% at f/8 (and 1.89 at f/2: the
 * finite-aperture cos^4 correction is real, not noise). */
static void test_exposure(void)
{
    lf_image a, b, c, d2, e, g;
    if (render_sky(1, 8, 1, 100, 32, &a) || render_sky(1, 8, 2, 100, 32, &b) || render_sky(1, 8, 1, 200, 32, &c) ||
        render_sky(1, 8 / sqrt(2), 1, 100, 32, &d2) || render_sky(1, 2, 1, 100, 32, &e) ||
        render_sky(1, 2 / sqrt(2), 1, 100, 32, &g))
        return;
    double ma = image_mean(&a);
    CHECK_NEAR(image_mean(&b) / ma, 2.0, 1e-5);
    CHECK_NEAR(image_mean(&c) / ma, 2.0, 1e-5);
    /* the central 16 x 16 pixels against the exact disk integral per pixel
     * (32 spp: Sobol noise of cos^4 over the lens < 0.05% on the block) */
    double ra = block_vs_exact(&a, 8), rd = block_vs_exact(&d2, 8 / sqrt(2)), re = block_vs_exact(&e, 2),
           rg = block_vs_exact(&g, 2 / sqrt(2));
    CHECK_MSG(fabs(ra - 1) < 0.002 && fabs(rd - 1) < 0.002 && fabs(re - 1) < 0.002 && fabs(rg - 1) < 0.002,
              "centre block / exact irradiance: f/8 %.5f, f/5.66 %.5f, f/2 %.5f, f/1.41 %.5f", ra, rd, re, rg);
    double ca = centre_block(&a), cd = centre_block(&d2), ce = centre_block(&e), cg = centre_block(&g);
    double r8 = (1 + 4 * 64.0) / (1 + 2 * 64.0), r2 = (1 + 4 * 4.0) / (1 + 2 * 4.0);
    CHECK_MSG(fabs(cd / ca / r8 - 1) < 0.003, "one stop at f/8: ratio %.5f, on-axis exact %.5f", cd / ca, r8);
    CHECK_MSG(fabs(cd / ca / 2 - 1) < 0.01, "one stop at f/8: ratio %.5f, not 2 within 1%%", cd / ca);
    CHECK_MSG(fabs(cg / ce / r2 - 1) < 0.003, "one stop at f/2: ratio %.5f, on-axis exact %.5f", cg / ce, r2);
    if (verbose)
        printf("exposure: block/exact %.5f %.5f %.5f %.5f; one stop f/8 %.5f (exact %.5f), f/2 %.5f (exact %.5f)\n", ra,
               rd, re, rg, cd / ca, r8, cg / ce, r2);
    lf_image_free(&a), lf_image_free(&b), lf_image_free(&c), lf_image_free(&d2), lf_image_free(&e), lf_image_free(&g);
}

static void test_scene_errors_and_explain(void)
{
    lf_scene_desc d;
    lf_error err = {0};
    const char *bad = "Camera \"thinlens\" \"float focusdistance\" [0.03]\nWorldBegin\n";
    CHECK(lf_scene_parse_string(bad, "near.pbrt", &d, &err) == 0);
    lf_render_opts o = lf_render_opts_default();
    lf_renderer *r = NULL;
    CHECK(lf_renderer_create(&d, &o, &r, &err) != 0);
    CHECK_MSG(strstr(err.msg, "closer than the focal length") && strstr(err.msg, "near.pbrt:1"), "%s", err.msg);
    lf_scene_desc_free(&d);

    lf_error err2 = {0};
    const char *ok = "Camera \"thinlens\" \"float focallength\" [85] \"float fstop\" [1.4] \"string aperture\" \"polygon\"\n"
                     "Film \"rgb\" \"integer xresolution\" [60] \"integer yresolution\" [40]\nWorldBegin\n";
    CHECK(lf_scene_parse_string(ok, "ok.pbrt", &d, &err2) == 0);
    if (lf_renderer_create(&d, &o, &r, &err2)) {
        CHECK_MSG(0, "%s", err2.msg);
    } else {
        char *plan = lf_renderer_explain(r);
        const char *keys[] = {"sensor distance z_s", "magnification", "horizontal FOV", "hyperfocal",
                              "near limit",          "far limit",     "blur diameter at infinity", "polygon"};
        for (int i = 0; i < 8; i++)
            CHECK_MSG(plan && strstr(plan, keys[i]), "--explain lacks \"%s\"", keys[i]);
        CHECK(plan && strstr(plan, "defocus: on"));
        free(plan);
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
}

int main(int argc, char **argv)
{
    verbose = argc > 1;
    if (argc > 2) {
        int spp = atoi(argv[2]);
        for (unsigned s = 1; s <= 4; s++) {
            test_thinlens_defocus(0.5, spp, s);
            test_thinlens_defocus(20, spp, s);
            test_perspective_defocus(0.5, spp, s);
            test_perspective_defocus(20, spp, s);
            test_pentagon_bokeh(spp, s);
        }
        return lf_test_end();
    }
    test_thinlens_defocus(0.5, 256, 7);
    test_thinlens_defocus(20, 256, 7);
    test_perspective_defocus(0.5, 256, 7);
    test_perspective_defocus(20, 256, 7);
    test_pentagon_bokeh(512, 7);
    test_flat_field();
    test_exposure();
    test_scene_errors_and_explain();
    return lf_test_end();
}
