/* Estimator changes must leave every image the same in expectation.  Each
 * check renders a scene with a closed-form answer over several fixed seeds
 * and asserts that the mean over the seeds lies within 4 standard errors
 * (estimated from the spread of the per-seed means) of the exact value,
 * plus float rounding; a biased estimator (e.g. Russian roulette without
 * its 1/p weight, which loses a few percent here) fails by many standard
 * errors.
 *
 * Inside a closed diffuse sphere of albedo a whose surface also emits Le
 * (two-sided), every path bounces until maxdepth or Russian roulette ends
 * it, and the radiance seen is exactly Le (1 + a + a^2 + ... + a^D) for
 * maxdepth D: the emission reached at each of the D+1 vertices of a path,
 * attenuated by a per bounce (the sphere sees only itself, and a diffuse
 * bounce reflects a of the uniform radiance).
 *
 * Under a one-sided polygonal emitter of radiance L, a diffuse floor of
 * reflectance rho seen with maxdepth 1 (direct light only) has radiance
 * rho L F, where F is the form factor from the floor point to the polygon:
 * Lambert's contour formula F = |sum_i beta_i n . (r_i x r_i+1) / |r_i x r_i+1|| / 2 pi
 * over the polygon's edges (r_i from the point to vertex i, beta_i the angle
 * between r_i and r_i+1).  It checks the light sampling of quads (one light
 * per parallelogram, sampled by area) against that of single triangles. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

static double image_mean(const lf_image *img, int c)
{
    double s = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            s += lf_image_px(img, x, y)[c];
    return s / ((double)img->width * img->height);
}

/* Mean over `seeds` renders of the image mean (channel c) and its standard
 * error. */
static int mean_over_seeds(const char *scene, int seeds, int c, double *mean, double *se)
{
    double s = 0, s2 = 0;
    for (int k = 0; k < seeds; k++) {
        lf_image img;
        char msg[1024];
        if (render_text(scene, &(lf_test_scene){.seed = 11 + 7 * (uint32_t)k, .has_seed = 1}, &img, msg, sizeof msg)) {
            CHECK_MSG(0, "render failed: %s", msg);
            return -1;
        }
        double m = image_mean(&img, c);
        s += m, s2 += m * m;
        lf_image_free(&img);
    }
    *mean = s / seeds;
    *se = sqrt(fmax(0.0, (s2 / seeds - *mean * *mean) / (seeds - 1)));
    return 0;
}

static void test_roulette_closed_sphere(const char *rule, double albedo, int maxdepth)
{
    const double Le = 0.25;
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" [60]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [64]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [%d] \"string russianroulette\" \"%s\"\n"
             "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [%g %g %g]\n"
             "AreaLightSource \"diffuse\" \"rgb L\" [%g %g %g] \"bool twosided\" true\n"
             "Shape \"sphere\" \"float radius\" [1]\n",
             maxdepth, rule, albedo, albedo, albedo, Le, Le, Le);
    double expected = 0;
    for (int k = 0; k <= maxdepth; k++)
        expected += Le * pow(albedo, k);
    const int seeds = 8;
    double mean, se;
    if (mean_over_seeds(scene, seeds, 1, &mean, &se))
        return;
    /* Margin: 4 standard errors of the mean over 8 seeds (each seed's mean
     * is over 16384 paths), plus 1e-5 relative for float sums. */
    CHECK_MSG(fabs(mean - expected) <= 4 * se + 1e-5 * expected,
              "roulette \"%s\", albedo %g, maxdepth %d: mean %.6f, exact %.6f (standard error %.6f, off by %.1f)",
              rule, albedo, maxdepth, mean, expected, se, fabs(mean - expected) / fmax(se, 1e-12));
    /* the check has teeth: the standard error is far below what losing
     * the deeper bounces would cost */
    CHECK_MSG(se < 0.002 * expected, "roulette \"%s\": standard error %.6f too large to tell bias (%.6f)", rule, se,
              expected);
}

/* Lambert's contour formula: the form factor from a point with normal n to
 * the polygon V (nv vertices). */
static double polygon_form_factor(const double p[3], const double n[3], const double (*V)[3], int nv)
{
    double sum = 0;
    for (int i = 0; i < nv; i++) {
        const double *a = V[i], *b = V[(i + 1) % nv];
        double ra[3] = {a[0] - p[0], a[1] - p[1], a[2] - p[2]}, rb[3] = {b[0] - p[0], b[1] - p[1], b[2] - p[2]};
        double c[3] = {ra[1] * rb[2] - ra[2] * rb[1], ra[2] * rb[0] - ra[0] * rb[2], ra[0] * rb[1] - ra[1] * rb[0]};
        double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double beta = atan2(lc, ra[0] * rb[0] + ra[1] * rb[1] + ra[2] * rb[2]); /* the angle between ra, rb */
        sum += beta * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / lc;
    }
    return fabs(sum) / (2 * LF_PI);
}

/* A floor at z = 0 (reflectance rho) under the polygon V at height 1, which
 * `shape` makes (its emission facing down); a 16 x 16 camera at height 0.5
 * looks straight down with a 4-degree field.  Expected: the mean over the
 * pixel centres of rho L F (the form factor changes by 1e-4 over the
 * footprint, so the centres stand for the pixels to far better than the
 * margin). */
static void test_polygon_light(const char *what, const char *shape, const double (*V)[3], int nv)
{
    const double rho = 0.6, L = 2, h_cam = 0.5, fov = 4;
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 %g  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [%g]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [16]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [1]\n"
             "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [%g %g %g]\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-9 -9 0  9 -9 0  -9 9 0  9 9 0]\n"
             "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
             "AreaLightSource \"diffuse\" \"rgb L\" [%g %g %g]\n%s\nAttributeEnd\n",
             h_cam, fov, rho, rho, rho, L, L, L, shape);
    double expected = 0, t = tan(fov / 2 * LF_PI / 180);
    const double up[3] = {0, 0, 1};
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++) {
            double p[3] = {((i + 0.5) / 8 - 1) * t * h_cam, ((j + 0.5) / 8 - 1) * t * h_cam, 0};
            expected += rho * L * polygon_form_factor(p, up, V, nv) / 256;
        }
    const int seeds = 8;
    double mean, se;
    if (mean_over_seeds(scene, seeds, 0, &mean, &se))
        return;
    /* Margin: 4 standard errors over 8 seeds plus 1e-4 relative (float
     * geometry and the pixel-centre approximation). */
    CHECK_MSG(fabs(mean - expected) <= 4 * se + 1e-4 * expected,
              "%s: floor radiance %.6f, Lambert's formula %.6f (standard error %.6f, off by %.1f)", what, mean,
              expected, se, fabs(mean - expected) / fmax(se, 1e-12));
    CHECK_MSG(se < 0.003 * expected, "%s: standard error %.6f too large to tell a bias (%.6f)", what, se, expected);
}

/* How many lights of each kind the scene made (from the effect plan). */
static void check_light_kinds(const char *what, const char *shape, const char *expect)
{
    char scene[1024];
    snprintf(scene, sizeof scene,
             "Camera \"perspective\"\nWorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n%s\n", shape);
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_string(scene, "test.pbrt", &d, &err)) {
        CHECK_MSG(0, "%s: %s", what, err.msg);
        return;
    }
    lf_render_opts o = lf_render_opts_default();
    lf_renderer *r;
    if (lf_renderer_create(&d, &o, &r, &err)) {
        CHECK_MSG(0, "%s: %s", what, err.msg);
        lf_scene_desc_free(&d);
        return;
    }
    char *plan = lf_renderer_explain(r);
    CHECK_MSG(plan && strstr(plan, expect), "%s: expected \"%s\" in the plan:\n%s", what, expect, plan ? plan : "");
    free(plan);
    lf_renderer_free(r);
    lf_scene_desc_free(&d);
}

int main(void)
{
    /* a rectangle as a bilinear patch: one quad light */
    const double rect[4][3] = {{-1, -0.5, 1}, {-1, 0.5, 1}, {1, 0.5, 1}, {1, -0.5, 1}};
    const char *rect_bilinear = "Shape \"bilinearmesh\" \"point3 P\" [-1 -0.5 1  -1 0.5 1  1 -0.5 1  1 0.5 1]";
    check_light_kinds("bilinear rectangle", rect_bilinear, "area triangles 0, area quads 1,");
    test_polygon_light("bilinear rectangle", rect_bilinear, rect, 4);
    /* a skewed parallelogram off-centre as two triangles: one quad light */
    const double par[4][3] = {{-0.6, -0.7, 1}, {0.4, -0.7, 1}, {1.0, 0.5, 1}, {0.0, 0.5, 1}};
    const char *par_mesh = "Shape \"trianglemesh\" \"integer indices\" [0 2 1  0 3 2] "
                           "\"point3 P\" [-0.6 -0.7 1  0.4 -0.7 1  1.0 0.5 1  0.0 0.5 1]";
    check_light_kinds("parallelogram mesh", par_mesh, "area triangles 0, area quads 1,");
    test_polygon_light("parallelogram mesh", par_mesh, par, 4);
    /* a trapezoid is no parallelogram: two triangle lights */
    const double trap[4][3] = {{-1, -0.6, 1}, {1, -0.6, 1}, {0.5, 0.6, 1}, {-0.5, 0.6, 1}};
    const char *trap_mesh = "Shape \"trianglemesh\" \"integer indices\" [0 2 1  0 3 2] "
                            "\"point3 P\" [-1 -0.6 1  1 -0.6 1  0.5 0.6 1  -0.5 0.6 1]";
    check_light_kinds("trapezoid mesh", trap_mesh, "area triangles 2, area quads 0,");
    test_polygon_light("trapezoid mesh", trap_mesh, trap, 4);

    test_roulette_closed_sphere("sqrt", 0.8, 12);
    test_roulette_closed_sphere("pbrt", 0.8, 12);
    test_roulette_closed_sphere("sqrt", 0.5, 3);
    return lf_test_end();
}
