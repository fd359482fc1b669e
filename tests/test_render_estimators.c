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
 * bounce reflects a of the uniform radiance). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "render/lf_render.h"

static int render_text(const char *text, uint32_t seed, lf_image *img, char *msg, size_t msg_size)
{
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_string(text, "test.pbrt", &d, &err)) {
        snprintf(msg, msg_size, "%s", err.msg);
        return -1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.threads = 2;
    o.seed = seed;
    o.has_seed = 1;
    lf_renderer *r;
    int rc = lf_renderer_create(&d, &o, &r, &err);
    if (!rc) {
        rc = lf_renderer_render(r, img, NULL, &err);
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    if (rc)
        snprintf(msg, msg_size, "%s", err.msg);
    return rc;
}

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
        if (render_text(scene, 11 + 7 * (uint32_t)k, &img, msg, sizeof msg)) {
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

int main(void)
{
    test_roulette_closed_sphere("sqrt", 0.8, 12);
    test_roulette_closed_sphere("pbrt", 0.8, 12);
    test_roulette_closed_sphere("sqrt", 0.5, 3);
    return lf_test_end();
}
