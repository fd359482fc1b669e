/* test_shading_bsdf.c - every BSDF lobe: sampling agrees with evaluation,
 * pdfs integrate to the non-specular fraction, reciprocity, energy, Fresnel
 * and grazing-angle robustness.
 *
 * Monte Carlo checks use fixed seeds and a tolerance of 3 standard errors of
 * the difference of the two estimates (plus 2e-3 absolute for float
 * round-off and table interpolation), computed from the samples themselves. */
#include "shading/lf_shading.h"

#include "lf_test.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* PCG32 (O'Neill 2014): a small deterministic generator. */
typedef struct rng {
    uint64_t state;
} rng;
static float rnd(rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + 1442695040888963407ULL;
    uint32_t x = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    uint32_t v = (x >> rot) | (x << ((-rot) & 31));
    return (float)(v >> 8) * 0x1p-24f;
}

static lf_vec3 uniform_sphere(float u0, float u1)
{
    float z = 1.f - 2.f * u0, r = sqrtf(fmaxf(0.f, 1.f - z * z)), phi = 2.f * (float)LF_PI * u1;
    return lf_v3(r * cosf(phi), r * sinf(phi), z);
}

static lf_vec3 from_local(const lf_bsdf *b, lf_vec3 v)
{
    return lf_add(lf_add(lf_scale(b->s, v.x), lf_scale(b->t, v.y)), lf_scale(b->n, v.z));
}

static float comp(lf_vec3 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }
static int finite3(lf_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

typedef struct stat {
    double sum, sum2;
    long n;
} stat;
static void stat_add(stat *s, double v)
{
    s->sum += v;
    s->sum2 += v * v;
}
static double stat_mean(const stat *s) { return s->sum / (double)s->n; }
static double stat_se(const stat *s)
{
    double m = stat_mean(s);
    double var = s->sum2 / (double)s->n - m * m;
    return sqrt(fmax(var, 0.0) / (double)s->n);
}

static lf_coat_table coat15; /* eta 1.5 */

typedef struct config {
    const char *name;
    lf_bsdf b;
    int reflection_only; /* reciprocity test applies to every pair */
    int energy_bounded;  /* albedo (with eta^2 for transmission) <= 1 */
} config;

static lf_shading_ctx test_ctx(int tilted)
{
    lf_shading_ctx c;
    memset(&c, 0, sizeof c);
    if (tilted) {
        c.ns = lf_normalize(lf_v3(0.3f, -0.2f, 0.9f));
        c.dpdu = lf_v3(1.f, 0.2f, 0.1f);
    } else {
        c.ns = lf_v3(0, 0, 1);
        c.dpdu = lf_v3(1, 0, 0);
    }
    c.ng = c.ns;
    return c;
}

static lf_microfacet mf(float rx, float ry)
{
    lf_microfacet m = {lf_roughness_to_alpha(rx), lf_roughness_to_alpha(ry)};
    return m;
}

static int make_configs(config *cf, int tilted)
{
    int n = 0;
    lf_shading_ctx ctx = test_ctx(tilted);
    lf_vec3 cu_eta = lf_v3(0.200438f, 0.924033f, 1.10221f), cu_k = lf_v3(3.91295f, 2.45285f, 2.14219f);
#define ADD(nm, refl, energy, setup)        \
    do {                                    \
        cf[n].name = nm;                    \
        lf_bsdf_frame(&cf[n].b, &ctx);      \
        setup;                              \
        cf[n].reflection_only = refl;       \
        cf[n].energy_bounded = energy;      \
        n++;                                \
    } while (0)
    ADD("diffuse", 1, 1, lf_bsdf_set_diffuse(&cf[n].b, lf_v3(0.8f, 0.5f, 0.2f)));
    ADD("diffusetransmission", 0, 1,
        lf_bsdf_set_diffuse_transmission(&cf[n].b, lf_v3(0.25f, 0.5f, 0.1f), lf_v3(0.6f, 0.25f, 0.3f)));
    ADD("conductor smooth", 1, 1, lf_bsdf_set_conductor(&cf[n].b, cu_eta, cu_k, mf(0, 0)));
    ADD("conductor r0.1", 1, 1, lf_bsdf_set_conductor(&cf[n].b, cu_eta, cu_k, mf(0.1f, 0.1f)));
    ADD("conductor r0.5", 1, 1, lf_bsdf_set_conductor(&cf[n].b, cu_eta, cu_k, mf(0.5f, 0.5f)));
    ADD("conductor aniso", 1, 1, lf_bsdf_set_conductor(&cf[n].b, cu_eta, cu_k, mf(0.05f, 0.3f)));
    ADD("dielectric smooth", 0, 1, lf_bsdf_set_dielectric(&cf[n].b, 1.5f, mf(0, 0)));
    ADD("dielectric r0.1", 0, 1, lf_bsdf_set_dielectric(&cf[n].b, 1.5f, mf(0.1f, 0.1f)));
    ADD("dielectric r0.5", 0, 1, lf_bsdf_set_dielectric(&cf[n].b, 1.5f, mf(0.5f, 0.5f)));
    ADD("dielectric aniso", 0, 1, lf_bsdf_set_dielectric(&cf[n].b, 1.33f, mf(0.3f, 0.08f)));
    ADD("dielectric eta1", 0, 1, lf_bsdf_set_dielectric(&cf[n].b, 1.0f, mf(0.3f, 0.3f)));
    ADD("thindielectric", 0, 1, lf_bsdf_set_thin_dielectric(&cf[n].b, 1.5f));
    ADD("coateddiffuse smooth", 1, 1, lf_bsdf_set_coated_diffuse(&cf[n].b, &coat15, mf(0, 0), lf_v3(0.9f, 0.5f, 0.1f)));
    ADD("coateddiffuse r0.3", 1, 1,
        lf_bsdf_set_coated_diffuse(&cf[n].b, &coat15, mf(0.3f, 0.3f), lf_v3(0.9f, 0.5f, 0.1f)));
    ADD("coatedconductor smooth/smooth", 1, 1,
        lf_bsdf_set_coated_conductor(&cf[n].b, &coat15, mf(0, 0), cu_eta, cu_k, mf(0, 0)));
    ADD("coatedconductor smooth/r0.3", 1, 1,
        lf_bsdf_set_coated_conductor(&cf[n].b, &coat15, mf(0, 0), cu_eta, cu_k, mf(0.3f, 0.3f)));
    ADD("coatedconductor r0.2/smooth", 1, 1,
        lf_bsdf_set_coated_conductor(&cf[n].b, &coat15, mf(0.2f, 0.2f), cu_eta, cu_k, mf(0, 0)));
    ADD("coatedconductor r0.2/r0.4", 1, 1,
        lf_bsdf_set_coated_conductor(&cf[n].b, &coat15, mf(0.2f, 0.2f), cu_eta, cu_k, mf(0.4f, 0.4f)));
#undef ADD
    return n;
}

/* (a) sampling vs evaluation, (b) pdf normalisation, sample/pdf/f
 * consistency and (e) energy, for one BSDF and one wo (local). */
static void check_sampling(const config *c, lf_vec3 wo_local, uint64_t seed)
{
    const lf_bsdf *b = &c->b;
    lf_vec3 wo = from_local(b, lf_normalize(wo_local));
    rng r = {seed};
    enum { NS = 100000, NU = 400000 };
    stat s_ns[3] = {{0}}, s_un[3] = {{0}}, s_pdf = {0}, s_energy = {0}, s_ok = {0};
    int bad_sample = 0, inconsistent = 0;
    for (int i = 0; i < NS; i++) {
        struct lf_bsdf_sample s;
        float uc = rnd(&r), u0 = rnd(&r), u1 = rnd(&r);
        int ok = lf_bsdf_sample(b, wo, uc, u0, u1, &s);
        double e = 0.0;
        double ns_v[3] = {0, 0, 0};
        if (ok) {
            float cosi = fabsf(lf_dot(s.wi, b->n));
            if (!finite3(s.f) || !(s.pdf > 0.f) || !isfinite(s.pdf) || fabsf(lf_length(s.wi) - 1.f) > 1e-3f)
                bad_sample++;
            double w = lf_luminance(s.f) * cosi / s.pdf;
            e = w * (s.transmission ? (double)s.eta * s.eta : 1.0);
            if (!s.specular) {
                for (int k = 0; k < 3; k++)
                    ns_v[k] = comp(s.f, k) * cosi / s.pdf;
                /* Sampled values agree with lf_bsdf_f and lf_bsdf_pdf (to 0.5%:
                 * the world/local round trip of a near-grazing refracted wi
                 * costs ~1e-3 relative in float). */
                float pdf = lf_bsdf_pdf(b, wo, s.wi);
                lf_vec3 f = lf_bsdf_f(b, wo, s.wi);
                if (fabsf(pdf - s.pdf) > 5e-3f * s.pdf + 1e-6f || fabsf(f.x - s.f.x) > 5e-3f * s.f.x + 1e-6f) {
                    inconsistent++;
                    fprintf(stderr, "  %s: wi (%g %g %g) pdf %g vs %g f %g vs %g\n", c->name, lf_dot(s.wi, b->s), lf_dot(s.wi, b->t), lf_dot(s.wi, b->n), s.pdf, pdf, s.f.x, f.x);
                }
            }
        }
        stat_add(&s_ok, ok && !s.specular ? 1.0 : 0.0);
        stat_add(&s_energy, e);
        for (int k = 0; k < 3; k++)
            stat_add(&s_ns[k], ns_v[k]);
    }
    for (int i = 0; i < NU; i++) {
        lf_vec3 wi = uniform_sphere(rnd(&r), rnd(&r));
        lf_vec3 f = lf_bsdf_f(b, wo, wi);
        float p = lf_bsdf_pdf(b, wo, wi);
        double cosi = fabsf(lf_dot(wi, b->n)), inv = 4.0 * LF_PI;
        for (int k = 0; k < 3; k++)
            stat_add(&s_un[k], comp(f, k) * cosi * inv);
        stat_add(&s_pdf, p * inv);
    }
    for (int k = 0; k < 3; k++)
        s_ns[k].n = NS, s_un[k].n = NU;
    s_pdf.n = NU;
    s_energy.n = NS;
    s_ok.n = NS;

    CHECK_MSG(bad_sample == 0, "%s wo.z=%g: %d non-finite or bad samples", c->name, wo_local.z, bad_sample);
    CHECK_MSG(inconsistent == 0, "%s wo.z=%g: %d samples disagree with f/pdf", c->name, wo_local.z, inconsistent);
    for (int k = 0; k < 3; k++) {
        double a = stat_mean(&s_ns[k]), u = stat_mean(&s_un[k]);
        double tol = 3.0 * sqrt(pow(stat_se(&s_ns[k]), 2) + pow(stat_se(&s_un[k]), 2)) + 2e-3;
        CHECK_MSG(fabs(a - u) <= tol, "%s wo.z=%g ch%d: sampled %.5f vs uniform %.5f (tol %.5f)", c->name,
                  wo_local.z, k, a, u, tol);
    }
    /* (b): integral of the pdf equals the fraction of non-specular samples
     * returned (1 for a lobe that never fails and has no delta part). */
    double ip = stat_mean(&s_pdf), fr = stat_mean(&s_ok);
    double tol = 3.0 * sqrt(pow(stat_se(&s_pdf), 2) + pow(stat_se(&s_ok), 2)) + 2e-3;
    CHECK_MSG(fabs(ip - fr) <= tol, "%s wo.z=%g: integral pdf %.5f vs non-specular fraction %.5f (tol %.5f)",
              c->name, wo_local.z, ip, fr, tol);
    if (c->energy_bounded) {
        double en = stat_mean(&s_energy);
        CHECK_MSG(en <= 1.0 + 3.0 * stat_se(&s_energy) + 2e-3, "%s wo.z=%g: albedo %.5f > 1", c->name,
                  wo_local.z, en);
    }
}

static void check_reciprocity(const config *c, uint64_t seed)
{
    rng r = {seed};
    int bad = 0;
    for (int i = 0; i < 2000; i++) {
        lf_vec3 a = uniform_sphere(rnd(&r), rnd(&r)), b = uniform_sphere(rnd(&r), rnd(&r));
        if (c->reflection_only == 0) { /* reflection pairs only */
            lf_vec3 al = lf_v3(lf_dot(a, c->b.s), lf_dot(a, c->b.t), lf_dot(a, c->b.n));
            lf_vec3 bl = lf_v3(lf_dot(b, c->b.s), lf_dot(b, c->b.t), lf_dot(b, c->b.n));
            if (al.z * bl.z <= 0.f)
                continue;
        }
        lf_vec3 f1 = lf_bsdf_f(&c->b, a, b), f2 = lf_bsdf_f(&c->b, b, a);
        for (int k = 0; k < 3; k++)
            if (fabsf(comp(f1, k) - comp(f2, k)) > 1e-4f * fmaxf(fabsf(comp(f1, k)), 1.f))
                bad++;
    }
    CHECK_MSG(bad == 0, "%s: %d non-reciprocal pairs", c->name, bad);
}

/* (h) grazing: wo.z = 1e-7, wi exactly tangent; everything stays finite. */
static void check_grazing(const config *c)
{
    const lf_bsdf *b = &c->b;
    lf_vec3 wos[4] = {lf_v3(1.f, 0.f, 1e-7f), lf_v3(-0.6f, 0.8f, 1e-7f), lf_v3(1.f, 0.f, -1e-7f),
                      lf_v3(0.f, 1.f, 0.f)};
    lf_vec3 wis[4] = {lf_v3(0.f, 1.f, 0.f), lf_v3(-1.f, 0.f, 0.f), lf_v3(0.f, 0.f, 1.f), lf_v3(0.6f, 0.f, 0.8f)};
    int bad = 0;
    rng r = {99};
    for (int i = 0; i < 4; i++) {
        lf_vec3 wo = from_local(b, lf_normalize(wos[i]));
        for (int j = 0; j < 4; j++) {
            lf_vec3 wi = from_local(b, wis[j]);
            if (!finite3(lf_bsdf_f(b, wo, wi)) || !isfinite(lf_bsdf_pdf(b, wo, wi)))
                bad++;
        }
        for (int j = 0; j < 200; j++) {
            struct lf_bsdf_sample s;
            if (lf_bsdf_sample(b, wo, rnd(&r), rnd(&r), rnd(&r), &s) &&
                (!finite3(s.f) || !isfinite(s.pdf) || !finite3(s.wi) || !(s.pdf > 0.f)))
                bad++;
        }
    }
    CHECK_MSG(bad == 0, "%s: %d non-finite values at grazing angles", c->name, bad);
}

static void check_fresnel(void)
{
    /* (f) normal incidence ((n-1)/(n+1))^2, either side. */
    float etas[3] = {1.33f, 1.5f, 2.4f};
    for (int i = 0; i < 3; i++) {
        float n = etas[i], r0 = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
        CHECK_NEAR(lf_fresnel_dielectric(1.f, n), r0, 1e-6);
        CHECK_NEAR(lf_fresnel_dielectric(-1.f, n), r0, 1e-6);
        /* Total internal reflection beyond asin(1/n) from inside. */
        float crit = asinf(1.f / n);
        CHECK(lf_fresnel_dielectric(-cosf(crit + 0.01f), n) == 1.f);
        CHECK(lf_fresnel_dielectric(-cosf(crit - 0.01f), n) < 1.f);
    }
    /* Conductor at normal incidence: ((eta-1)^2 + k^2) / ((eta+1)^2 + k^2). */
    float ce[3] = {0.200438f, 0.924033f, 1.10221f}, ck[3] = {3.91295f, 2.45285f, 2.14219f};
    for (int i = 0; i < 3; i++) {
        double e = ce[i], k = ck[i];
        double ref = ((e - 1) * (e - 1) + k * k) / ((e + 1) * (e + 1) + k * k);
        CHECK_NEAR(lf_fresnel_conductor(1.f, ce[i], ck[i]), ref, 1e-5);
    }
    /* (g) through the BSDF: a smooth conductor sample at normal incidence
     * has f cos / pdf = that reflectance per channel. */
    lf_shading_ctx ctx = test_ctx(0);
    lf_bsdf b;
    lf_bsdf_frame(&b, &ctx);
    lf_bsdf_set_conductor(&b, lf_v3(ce[0], ce[1], ce[2]), lf_v3(ck[0], ck[1], ck[2]), mf(0, 0));
    struct lf_bsdf_sample s;
    CHECK(lf_bsdf_sample(&b, lf_v3(0, 0, 1), 0.5f, 0.5f, 0.5f, &s) && s.specular);
    CHECK(lf_bsdf_is_specular(&b));
    for (int i = 0; i < 3; i++) {
        double e = ce[i], k = ck[i];
        double ref = ((e - 1) * (e - 1) + k * k) / ((e + 1) * (e + 1) + k * k);
        CHECK_NEAR(comp(s.f, i) * s.wi.z / s.pdf, ref, 1e-5);
    }

    /* Smooth dielectric: reflection chosen with probability F; from inside
     * beyond the critical angle always reflected. */
    lf_bsdf_set_dielectric(&b, 1.5f, mf(0, 0));
    float ang[3] = {0.f, 0.8f, 1.3f};
    rng r = {7};
    for (int a = 0; a < 3; a++) {
        lf_vec3 wo = lf_v3(sinf(ang[a]), 0.f, cosf(ang[a]));
        float F = lf_fresnel_dielectric(wo.z, 1.5f);
        int nref = 0, N = 200000;
        for (int i = 0; i < N; i++)
            if (lf_bsdf_sample(&b, wo, rnd(&r), rnd(&r), rnd(&r), &s) && !s.transmission)
                nref++;
        double p = (double)nref / N, se = sqrt(F * (1 - F) / N);
        CHECK_MSG(fabs(p - F) <= 3 * se + 1e-4, "reflection fraction %.5f vs F %.5f", p, F);
        /* The transmitted direction obeys Snell's law and the eta^2 scaling. */
        CHECK(lf_bsdf_sample(&b, wo, 0.9999f, 0.f, 0.f, &s) && s.transmission);
        CHECK_NEAR(sqrtf(s.wi.x * s.wi.x + s.wi.y * s.wi.y) * 1.5f, sinf(ang[a]), 1e-5);
        CHECK_NEAR(s.f.x * fabsf(s.wi.z) / s.pdf, 1.f / (1.5f * 1.5f), 1e-5);
        CHECK_NEAR(s.eta, 1.5f, 1e-6);
    }
    float crit = asinf(1.f / 1.5f);
    lf_vec3 wo_in = lf_v3(sinf(crit + 0.05f), 0.f, -cosf(crit + 0.05f));
    int all_refl = 1;
    for (int i = 0; i < 1000; i++)
        if (!lf_bsdf_sample(&b, wo_in, rnd(&r), rnd(&r), rnd(&r), &s) || s.transmission ||
            fabsf(s.f.x * fabsf(s.wi.z) / s.pdf - 1.f) > 1e-5f)
            all_refl = 0;
    CHECK(all_refl);

    /* eta = 1, smooth: straight pass-through with weight 1. */
    lf_bsdf_set_dielectric(&b, 1.0f, mf(0, 0));
    lf_vec3 wo = lf_normalize(lf_v3(0.3f, 0.4f, 0.8f));
    CHECK(lf_bsdf_sample(&b, wo, 0.3f, 0.3f, 0.3f, &s) && s.transmission);
    CHECK_NEAR(lf_dot(s.wi, wo), -1.f, 1e-6);
    CHECK_NEAR(s.f.x * fabsf(s.wi.z) / s.pdf, 1.f, 1e-5);

    /* Thin dielectric: R + R T^2 / (1 - R^2) at normal incidence. */
    lf_bsdf_set_thin_dielectric(&b, 1.5f);
    float R0 = 0.04f, Rt = R0 + R0 * (1 - R0) * (1 - R0) / (1 - R0 * R0);
    CHECK(lf_bsdf_sample(&b, lf_v3(0, 0, 1), 0.f, 0.f, 0.f, &s) && !s.transmission);
    CHECK_NEAR(s.pdf, Rt, 1e-6);
    CHECK(lf_bsdf_sample(&b, lf_v3(0, 0, 1), 0.99f, 0.f, 0.f, &s) && s.transmission);
    CHECK_NEAR(s.wi.z, -1.f, 1e-7);
    CHECK_NEAR(s.f.x * fabsf(s.wi.z) / s.pdf, 1.f, 1e-5);
}

/* (d) diffuse white furnace: reflectance 1 gives albedo exactly 1 (each
 * cosine-weighted sample has weight exactly 1); reflectance a gives a. */
static void check_furnace(void)
{
    lf_shading_ctx ctx = test_ctx(1);
    lf_bsdf b;
    lf_bsdf_frame(&b, &ctx);
    float refl[3] = {1.f, 0.37f, 0.f};
    rng r = {11};
    for (int k = 0; k < 3; k++) {
        lf_bsdf_set_diffuse(&b, lf_v3(refl[k], refl[k], refl[k]));
        double sum = 0, maxdev = 0;
        int N = 20000, got = 0;
        lf_vec3 wo = from_local(&b, lf_normalize(lf_v3(0.5f, 0.1f, 0.6f)));
        for (int i = 0; i < N; i++) {
            struct lf_bsdf_sample s;
            if (!lf_bsdf_sample(&b, wo, rnd(&r), rnd(&r), rnd(&r), &s))
                continue;
            got++;
            double w = s.f.x * fabs(lf_dot(s.wi, b.n)) / s.pdf;
            sum += w;
            maxdev = fmax(maxdev, fabs(w - refl[k]));
        }
        CHECK_MSG(refl[k] == 0.f || got == N, "diffuse %g: %d of %d samples", refl[k], got, N);
        CHECK_NEAR(got ? sum / got : 0.0, refl[k], 1e-5);
        CHECK_NEAR(maxdev, 0.0, 1e-4);
    }
    /* Coated diffuse with a white base loses nothing: albedo 1 up to the
     * coat table's quadrature error (about 1e-2 for rough coats) and
     * 3 sigma of noise. */
    float rough[2] = {0.f, 0.3f};
    for (int k = 0; k < 2; k++) {
        lf_bsdf_set_coated_diffuse(&b, &coat15, mf(rough[k], rough[k]), lf_v3(1, 1, 1));
        float mus[3] = {0.95f, 0.5f, 0.15f};
        for (int m = 0; m < 3; m++) {
            lf_vec3 wo = from_local(&b, lf_v3(sqrtf(1 - mus[m] * mus[m]), 0.f, mus[m]));
            stat st = {0};
            int N = 200000;
            for (int i = 0; i < N; i++) {
                struct lf_bsdf_sample s;
                double w = 0;
                if (lf_bsdf_sample(&b, wo, rnd(&r), rnd(&r), rnd(&r), &s))
                    w = s.f.x * fabs(lf_dot(s.wi, b.n)) / s.pdf;
                stat_add(&st, w);
            }
            st.n = N;
            double tol = 3 * stat_se(&st) + (rough[k] > 0.f ? 0.015 : 2e-3);
            CHECK_MSG(fabs(stat_mean(&st) - 1.0) <= tol, "coated white furnace rough %g mu %g: %.5f (tol %.4f)",
                      rough[k], mus[m], stat_mean(&st), tol);
        }
    }
}

static void check_coat_table(void)
{
    /* The smooth row is the Fresnel curve; its hemispherical (cosine
     * weighted) average for eta 1.5 is the external diffuse reflectance of
     * glass, 0.0918 (e.g. Kelemen & Szirmay-Kalos 2001; Judd 1942). */
    CHECK_NEAR(coat15.hemispherical[0], 0.0918, 5e-4);
    CHECK_NEAR(coat15.albedo[0][LF_COAT_N_COS - 1], 0.04, 1e-6);
    int mono = 1;
    for (int a = 0; a < LF_COAT_N_ALPHA; a++)
        for (int c = 0; c < LF_COAT_N_COS; c++)
            if (!(coat15.albedo[a][c] >= 0.f && coat15.albedo[a][c] <= 1.f))
                mono = 0;
    CHECK(mono);
}

static void check_specular_flags(void)
{
    lf_shading_ctx ctx = test_ctx(0);
    lf_bsdf b;
    lf_bsdf_frame(&b, &ctx);
    CHECK(lf_bsdf_is_specular(&b)); /* NONE: nothing to light-sample */
    lf_bsdf_set_diffuse(&b, lf_v3(0.5f, 0.5f, 0.5f));
    CHECK(!lf_bsdf_is_specular(&b));
    lf_bsdf_set_dielectric(&b, 1.5f, mf(0, 0));
    CHECK(lf_bsdf_is_specular(&b));
    lf_bsdf_set_dielectric(&b, 1.5f, mf(0.2f, 0.2f));
    CHECK(!lf_bsdf_is_specular(&b));
    lf_bsdf_set_thin_dielectric(&b, 1.5f);
    CHECK(lf_bsdf_is_specular(&b));
    lf_bsdf_set_coated_diffuse(&b, &coat15, mf(0, 0), lf_v3(0.5f, 0.5f, 0.5f));
    CHECK(!lf_bsdf_is_specular(&b));
    /* Specular lobes evaluate to zero. */
    lf_bsdf_set_conductor(&b, lf_v3(0.2f, 0.9f, 1.1f), lf_v3(3.9f, 2.4f, 2.1f), mf(0, 0));
    CHECK(lf_is_black(lf_bsdf_f(&b, lf_v3(0, 0, 1), lf_v3(0, 0, 1))));
    CHECK(lf_bsdf_pdf(&b, lf_v3(0, 0, 1), lf_v3(0, 0, 1)) == 0.f);
    /* Anisotropy follows dpdu: a highlight stretched along u (the rougher
     * axis) is wider along s than along t. */
    lf_bsdf_set_conductor(&b, lf_v3(0.2f, 0.9f, 1.1f), lf_v3(3.9f, 2.4f, 2.1f), mf(0.4f, 0.01f));
    lf_vec3 wo = lf_v3(0, 0, 1);
    float fu = lf_bsdf_f(&b, wo, lf_normalize(lf_v3(0.3f, 0.f, 1.f))).x;
    float fv = lf_bsdf_f(&b, wo, lf_normalize(lf_v3(0.f, 0.3f, 1.f))).x;
    CHECK_MSG(fu > 4.f * fv, "fu %g fv %g", fu, fv); /* D ratio alone is 8.9 here */
}

int main(void)
{
    lf_coat_table_init(&coat15, 1.5f);
    check_coat_table();
    check_fresnel();
    check_furnace();
    check_specular_flags();

    config cf[32];
    for (int tilted = 0; tilted < 2; tilted++) {
        int n = make_configs(cf, tilted);
        lf_vec3 wos[5] = {lf_v3(0.f, 0.f, 1.f), lf_v3(0.5f, 0.3f, 0.8f), lf_v3(-0.7f, 0.2f, 0.3f),
                          lf_v3(0.9f, 0.f, 0.08f), lf_v3(0.3f, -0.4f, -0.6f)};
        for (int i = 0; i < n; i++) {
            for (int w = 0; w < 5; w++) {
                if (tilted && w != 1 && w != 4)
                    continue; /* the tilted frame: two directions suffice */
                check_sampling(&cf[i], wos[w], 1000u + (uint64_t)(i * 17 + w + 100 * tilted));
            }
            check_reciprocity(&cf[i], 5000u + (uint64_t)i);
            check_grazing(&cf[i]);
        }
    }
    /* (h) again with roughness exactly 1 (alpha 1). */
    lf_shading_ctx ctx = test_ctx(0);
    config rough[4];
    memset(rough, 0, sizeof rough);
    for (int i = 0; i < 4; i++)
        lf_bsdf_frame(&rough[i].b, &ctx);
    rough[0].name = "conductor r1";
    lf_bsdf_set_conductor(&rough[0].b, lf_v3(0.2f, 0.9f, 1.1f), lf_v3(3.9f, 2.4f, 2.1f), mf(1, 1));
    rough[1].name = "dielectric r1";
    lf_bsdf_set_dielectric(&rough[1].b, 1.5f, mf(1, 1));
    rough[2].name = "coateddiffuse r1";
    lf_bsdf_set_coated_diffuse(&rough[2].b, &coat15, mf(1, 1), lf_v3(0.5f, 0.5f, 0.5f));
    rough[3].name = "coatedconductor r1";
    lf_bsdf_set_coated_conductor(&rough[3].b, &coat15, mf(1, 1), lf_v3(0.2f, 0.9f, 1.1f), lf_v3(3.9f, 2.4f, 2.1f),
                                 mf(1, 1));
    for (int i = 0; i < 4; i++) {
        rough[i].energy_bounded = 1;
        check_grazing(&rough[i]);
        check_sampling(&rough[i], lf_v3(0.4f, 0.1f, 0.7f), 9000u + (uint64_t)i);
    }
    return lf_test_end();
}
