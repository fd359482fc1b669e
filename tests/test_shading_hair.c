/* test_shading_hair.c - Material "hair", pbrt-v4's HairBxDF (Chiang et al.
 * 2016).  A fibre that absorbs nothing (sigma_a = 0) scatters all the light
 * it receives: the integral of f |cos theta_i| over the sphere is 1 for
 * every wo and h, estimated here by Monte Carlo both with uniform sphere
 * sampling (jittered-stratified in (sin theta, phi), 8 independent
 * replicates per (wo, h) give the standard error) and with the BSDF's own
 * sampling (fixed seeds; the check is |estimate - 1| < 1 % + 3 standard
 * errors, with the standard error itself required below 0.3 %).
 * The sampling pdf follows f's shape: with sigma_a = 0 each sample's weight
 * f |cos| / pdf is 1, the pdf integrates to 1 and equals lf_hair_pdf.  The
 * material's three absorption parametrisations are checked against
 * pbrt-v4's formulas. */
#include "scenefile/lf_scene_desc.h"
#include "shading/lf_shading.h"

#include "lf_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static unsigned long long rng;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1p-53;
}

static lf_vec3 uniform_sphere(void)
{
    double z = 1 - 2 * urand(), r = sqrt(fmax(0, 1 - z * z)), ph = 2 * M_PI * urand();
    return lf_v3((float)(r * cos(ph)), (float)(r * sin(ph)), (float)z);
}

typedef struct stats {
    double mean, se;
} stats;

/* BSDF sampling: E[f |cos theta_i| / pdf] over random wo, h; channel y. */
static stats furnace_bsdf(float beta_m, float beta_n, lf_vec3 sigma_a, int n)
{
    double s = 0, s2 = 0;
    for (int k = 0; k < n; k++) {
        lf_hair hp;
        lf_hair_setup(&hp, (float)(urand() * 2 - 1), 1.55f, sigma_a, beta_m, beta_n, 2.f);
        lf_vec3 wo = uniform_sphere(), wi, f;
        float pdf;
        double v = 0;
        if (lf_hair_sample(&hp, wo, (float)urand(), (float)urand(), (float)urand(), &wi, &f, &pdf) && pdf > 0)
            v = f.y * fabs(wi.z) / pdf;
        s += v;
        s2 += v * v;
    }
    stats st = {s / n, sqrt(fmax(0, s2 / n - (s / n) * (s / n)) / n)};
    return st;
}

/* Uniform sphere sampling for one (wo, h): wi = (sin t, cos t cos phi,
 * cos t sin phi) with sin t and phi uniform (Archimedes), pdf 1 / (4 pi),
 * jittered on an m x m grid; the mean and standard error of 8 replicates. */
static stats furnace_uniform(const lf_hair *hp, lf_vec3 wo, int m)
{
    double rep[8], mean = 0, var = 0;
    for (int r = 0; r < 8; r++) {
        double s = 0;
        for (int i = 0; i < m; i++)
            for (int j = 0; j < m; j++) {
                double st = -1 + 2 * (i + urand()) / m, ph = 2 * M_PI * (j + urand()) / m, ct = sqrt(1 - st * st);
                lf_vec3 wi = lf_v3((float)st, (float)(ct * cos(ph)), (float)(ct * sin(ph)));
                s += lf_hair_f(hp, wo, wi).y * fabs(wi.z) * 4 * M_PI;
            }
        rep[r] = s / ((double)m * m);
        mean += rep[r] / 8;
    }
    for (int r = 0; r < 8; r++)
        var += (rep[r] - mean) * (rep[r] - mean) / 7;
    stats st = {mean, sqrt(var / 8)};
    return st;
}

static void test_white_furnace(void)
{
    const float params[][2] = {{0.2f, 0.2f}, {0.3f, 0.3f}, {0.5f, 0.7f}, {0.9f, 0.9f}};
    for (size_t i = 0; i < sizeof params / sizeof params[0]; i++) {
        rng = 0x9E3779B97F4A7C15ull + i;
        double worst = 0, worst_se = 0;
        for (int k = 0; k < 6; k++) {
            lf_hair hp;
            lf_hair_setup(&hp, (float)(urand() * 2 - 1), 1.55f, lf_v3(0, 0, 0), params[i][0], params[i][1], 2.f);
            stats u = furnace_uniform(&hp, uniform_sphere(), params[i][0] < 0.25f ? 240 : 128);
            CHECK_MSG(u.se < 0.003 && fabs(u.mean - 1) < 0.01 + 3 * u.se, "h %g: uniform estimate %g +- %g", hp.h,
                      u.mean, u.se);
            if (fabs(u.mean - 1) > worst)
                worst = fabs(u.mean - 1), worst_se = u.se;
        }
        stats b = furnace_bsdf(params[i][0], params[i][1], lf_v3(0, 0, 0), 100000);
        printf("white furnace beta_m %.1f beta_n %.1f: uniform, worst of 6 (wo, h): |E - 1| = %.4f +- %.4f; "
               "BSDF sampling %.5f +- %.5f\n",
               params[i][0], params[i][1], worst, worst_se, b.mean, b.se);
        CHECK_MSG(b.se < 0.003 && fabs(b.mean - 1) < 0.01 + 3 * b.se, "BSDF-sampled estimate %g +- %g", b.mean, b.se);
    }
    /* an absorbing fibre: less than 1, and both estimators agree */
    rng = 77;
    lf_hair hp;
    lf_hair_setup(&hp, 0.4f, 1.55f, lf_v3(0.5f, 0.5f, 0.5f), 0.3f, 0.3f, 2.f);
    lf_vec3 wo = lf_normalize(lf_v3(0.2f, 0.6f, -0.5f));
    stats u = furnace_uniform(&hp, wo, 160);
    double s = 0, s2 = 0;
    const int n = 100000;
    for (int k = 0; k < n; k++) {
        lf_vec3 wi, f;
        float pdf;
        double v = 0;
        if (lf_hair_sample(&hp, wo, (float)urand(), (float)urand(), (float)urand(), &wi, &f, &pdf) && pdf > 0)
            v = f.y * fabs(wi.z) / pdf;
        s += v;
        s2 += v * v;
    }
    double bm = s / n, bse = sqrt(fmax(0, s2 / n - bm * bm) / n);
    printf("sigma_a 0.5: uniform %.4f +- %.4f, BSDF sampling %.4f +- %.4f\n", u.mean, u.se, bm, bse);
    CHECK_MSG(u.mean < 0.9 && fabs(u.mean - bm) < 3 * sqrt(u.se * u.se + bse * bse) + 0.003,
              "absorbing fibre: %g vs %g", u.mean, bm);
}

/* pdf vs f: sample weights, pdf normalisation, lf_hair_pdf agreement. */
static void test_sampling_shape(void)
{
    rng = 12345;
    int bad_weight = 0, bad_pdf = 0, n = 20000;
    for (int k = 0; k < n; k++) {
        lf_hair hp;
        float bm = (float)(0.2 + 0.7 * urand()), bn = (float)(0.2 + 0.7 * urand());
        lf_hair_setup(&hp, (float)(urand() * 2 - 1), 1.55f, lf_v3(0, 0, 0), bm, bn, 2.f);
        lf_vec3 wo = uniform_sphere(), wi, f;
        float pdf;
        if (!lf_hair_sample(&hp, wo, (float)urand(), (float)urand(), (float)urand(), &wi, &f, &pdf))
            continue;
        double w = f.y * fabs(wi.z) / pdf;
        bad_weight += !(w > 0.99 && w < 1.01);
        float p2 = lf_hair_pdf(&hp, wo, wi);
        bad_pdf += fabs(p2 - pdf) > 1e-3 * pdf;
    }
    /* a few samples graze |wi.z| = 0 or land where cos is rounded: allow 0.1 % */
    CHECK_MSG(bad_weight <= n / 1000, "%d of %d sample weights outside [0.99, 1.01]", bad_weight, n);
    CHECK_MSG(bad_pdf <= n / 1000, "%d of %d sample pdfs differ from lf_hair_pdf", bad_pdf, n);
    /* the pdf integrates to 1 over the sphere (uniform estimate) */
    lf_hair hp;
    lf_hair_setup(&hp, 0.3f, 1.55f, lf_v3(0.2f, 0.4f, 0.8f), 0.4f, 0.5f, 2.f);
    lf_vec3 wo = lf_normalize(lf_v3(0.3f, 0.5f, 0.8f));
    double s = 0, s2 = 0;
    const int N = 400000;
    for (int k = 0; k < N; k++) {
        double v = lf_hair_pdf(&hp, wo, uniform_sphere()) * 4 * M_PI;
        s += v;
        s2 += v * v;
    }
    double mean = s / N, se = sqrt(fmax(0, s2 / N - mean * mean) / N);
    printf("pdf mass %.4f +- %.4f\n", mean, se);
    CHECK_MSG(fabs(mean - 1) < 0.01 + 3 * se, "pdf integrates to %g +- %g", mean, se);
}

static lf_vec3 hair_sigma(const char *params, float v)
{
    char text[512];
    snprintf(text, sizeof text, "WorldBegin\nMaterial \"hair\" %s\n", params);
    lf_scene_desc d;
    lf_error err = {0};
    lf_vec3 out = lf_v3(-1, -1, -1);
    if (lf_scene_parse_string(text, "hair.pbrt", &d, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return out;
    }
    lf_materials *m = NULL;
    int rc = lf_materials_build(&d, &m, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        lf_shading_ctx c;
        memset(&c, 0, sizeof c);
        c.ns = c.ng = lf_v3(0, 0, 1);
        c.dpdu = lf_v3(1, 0, 0);
        c.uv.y = v;
        lf_bsdf b;
        lf_material_bsdf(lf_materials_get(m, 0), &c, &b);
        CHECK(b.kind == LF_LOBE_HAIR);
        CHECK_NEAR(b.u.hair.h, -1 + 2 * v, 1e-6); /* h from the surface's v */
        out = b.u.hair.sigma_a;
    }
    lf_materials_free(m);
    lf_scene_desc_free(&d);
    return out;
}

static void test_parametrisations(void)
{
    /* default: eumelanin 1.3, sigma_a = 1.3 (0.419, 0.697, 1.37) */
    lf_vec3 s = hair_sigma("", 0.25f);
    CHECK_NEAR(s.x, 1.3 * 0.419, 1e-5);
    CHECK_NEAR(s.z, 1.3 * 1.37, 1e-5);
    s = hair_sigma("\"float eumelanin\" 0.5 \"float pheomelanin\" 2", 0.5f);
    CHECK_NEAR(s.x, 0.5 * 0.419 + 2 * 0.187, 1e-5);
    CHECK_NEAR(s.y, 0.5 * 0.697 + 2 * 0.4, 1e-5);
    CHECK_NEAR(s.z, 0.5 * 1.37 + 2 * 1.05, 1e-5);
    s = hair_sigma("\"rgb sigma_a\" [0.1 0.2 0.3]", 0.9f);
    CHECK_NEAR(s.x, 0.1, 1e-6);
    CHECK_NEAR(s.z, 0.3, 1e-6);
    /* reflectance c -> sigma_a = (ln c / poly(beta_n))^2 (Chiang et al. eq. 6) */
    s = hair_sigma("\"rgb reflectance\" [0.5 0.3 0.1] \"float beta_n\" 0.4", 0.1f);
    double bn = 0.4, poly = 5.969 - 0.215 * bn + 2.532 * bn * bn - 10.73 * pow(bn, 3) + 5.574 * pow(bn, 4) +
                            0.245 * pow(bn, 5);
    CHECK_NEAR(s.x, pow(log(0.5) / poly, 2), 1e-5);
    CHECK_NEAR(s.z, pow(log(0.1) / poly, 2), 1e-5);
    s = hair_sigma("\"rgb color\" [0.5 0.3 0.1] \"float beta_n\" 0.4", 0.1f); /* pbrt's older name */
    CHECK_NEAR(s.y, pow(log(0.3) / poly, 2), 1e-5);
}

int main(void)
{
    test_white_furnace();
    test_sampling_shape();
    test_parametrisations();
    return lf_test_end();
}
