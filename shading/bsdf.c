/* bsdf.c - BSDF lobes: evaluation, sampling and pdfs in a local shading frame.
 *
 * Follows pbrt-v4 (Pharr, Jakob, Humphreys, "Physically Based Rendering",
 * 4th ed., ch. 9-10): the local frame has the shading normal along +z,
 * lobes are two-sided where pbrt's are, and the formulas cite the book.
 */
#include "lf_shading.h"

#include <complex.h>
#include <math.h>
#include <string.h>

#define PI_F ((float)LF_PI)

static float sqrf(float x) { return x * x; }

/* ------------------------------------------------------------ frame */

void lf_bsdf_frame(lf_bsdf *b, const lf_shading_ctx *ctx)
{
    memset(b, 0, sizeof *b);
    b->n = ctx->ns;
    /* Gram-Schmidt dpdu against ns so anisotropic roughness follows u. */
    lf_vec3 s = lf_sub(ctx->dpdu, lf_scale(b->n, lf_dot(b->n, ctx->dpdu)));
    float len = lf_length(s);
    if (len > 1e-8f && isfinite(len)) {
        b->s = lf_scale(s, 1.f / len);
        b->t = lf_cross(b->n, b->s);
    } else {
        lf_basis(b->n, &b->s, &b->t);
    }
    b->kind = LF_LOBE_NONE;
}

static inline lf_vec3 to_local(const lf_bsdf *b, lf_vec3 v) { return lf_v3(lf_dot(v, b->s), lf_dot(v, b->t), lf_dot(v, b->n)); }

static lf_vec3 to_world(const lf_bsdf *b, lf_vec3 v)
{
    return lf_add(lf_add(lf_scale(b->s, v.x), lf_scale(b->t, v.y)), lf_scale(b->n, v.z));
}

static int same_hemisphere(lf_vec3 a, lf_vec3 b) { return a.z * b.z > 0.f; }

static lf_vec3 reflect(lf_vec3 wo, lf_vec3 n) { return lf_sub(lf_scale(n, 2.f * lf_dot(wo, n)), wo); }

/* Snell refraction of wi about n (pbrt-v4 eq. 9.4 and Refract()): eta is
 * the relative index t/i for wi on n's side; flipped when wi is below. */
static int refract(lf_vec3 wi, lf_vec3 n, float eta, float *etap, lf_vec3 *wt)
{
    float cos_i = lf_dot(n, wi);
    if (cos_i < 0.f) {
        eta = 1.f / eta;
        cos_i = -cos_i;
        n = lf_neg(n);
    }
    float sin2_i = fmaxf(0.f, 1.f - cos_i * cos_i);
    float sin2_t = sin2_i / (eta * eta);
    if (sin2_t >= 1.f)
        return 0;
    float cos_t = sqrtf(1.f - sin2_t);
    *wt = lf_add(lf_scale(lf_neg(wi), 1.f / eta), lf_scale(n, cos_i / eta - cos_t));
    if (etap)
        *etap = eta;
    return 1;
}

/* Cosine-weighted hemisphere (Malley's method) on the upper side. */
static lf_vec3 sample_cosine(float u0, float u1)
{
    float r = sqrtf(u0), phi = 2.f * PI_F * u1;
    float x = r * cosf(phi), y = r * sinf(phi);
    float z2 = 1.f - x * x - y * y; /* a select, not fmaxf (a libm call) */
    return lf_v3(x, y, sqrtf(z2 > 0.f ? z2 : 0.f));
}

/* ---------------------------------------------------------- Fresnel */

/* Unpolarised Fresnel reflectance of a dielectric interface (pbrt-v4
 * FrDielectric, eq. 9.5-9.6). */
float lf_fresnel_dielectric(float cos_i, float eta)
{
    cos_i = lf_clampf(cos_i, -1.f, 1.f);
    if (cos_i < 0.f) {
        eta = 1.f / eta;
        cos_i = -cos_i;
    }
    float sin2_i = 1.f - cos_i * cos_i;
    float sin2_t = sin2_i / (eta * eta);
    if (sin2_t >= 1.f)
        return 1.f; /* total internal reflection */
    float cos_t = sqrtf(fmaxf(0.f, 1.f - sin2_t));
    float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return (r_parl * r_parl + r_perp * r_perp) * 0.5f;
}

/* Conductor: the same formulas with a complex index eta + i k (pbrt-v4
 * FrComplex, eq. 9.8); double precision since k can be ~10. */
float lf_fresnel_conductor(float cos_i, float eta_r, float k)
{
    double c = lf_clampd(cos_i, 0.0, 1.0);
    double complex eta = eta_r + k * I;
    double sin2_i = 1.0 - c * c;
    double complex sin2_t = sin2_i / (eta * eta);
    double complex cos_t = csqrt(1.0 - sin2_t);
    double complex r_parl = (eta * c - cos_t) / (eta * c + cos_t);
    double complex r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    double a = creal(r_parl) * creal(r_parl) + cimag(r_parl) * cimag(r_parl);
    double p = creal(r_perp) * creal(r_perp) + cimag(r_perp) * cimag(r_perp);
    double r = 0.5 * (a + p);
    return (float)(isfinite(r) ? lf_clampd(r, 0.0, 1.0) : 1.0);
}

static lf_vec3 fresnel_conductor3(float cos_i, lf_vec3 eta, lf_vec3 k)
{
    return lf_v3(lf_fresnel_conductor(cos_i, eta.x, k.x), lf_fresnel_conductor(cos_i, eta.y, k.y),
                 lf_fresnel_conductor(cos_i, eta.z, k.z));
}

/* ------------------------------------------- Trowbridge-Reitz (GGX) */

float lf_roughness_to_alpha(float roughness) { return sqrtf(fmaxf(roughness, 0.f)); }

static int mf_smooth(lf_microfacet mf) { return fmaxf(mf.alpha_x, mf.alpha_y) < LF_SMOOTH_ALPHA; }

/* D(wm) = 1 / (pi ax ay ((x/ax)^2 + (y/ay)^2 + z^2)^2), pbrt-v4 eq. 9.16
 * rewritten without tan^2 so it stays finite at grazing angles. */
static float mf_D(lf_microfacet mf, lf_vec3 m)
{
    float e = sqrf(m.x / mf.alpha_x) + sqrf(m.y / mf.alpha_y) + m.z * m.z;
    if (!(e > 0.f))
        return 0.f;
    return 1.f / (PI_F * mf.alpha_x * mf.alpha_y * e * e);
}

/* Smith Lambda (pbrt-v4 eq. 9.22): (sqrt(1 + alpha^2 tan^2) - 1) / 2. */
static float mf_lambda(lf_microfacet mf, lf_vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 == 0.f)
        return INFINITY;
    float a2t2 = (sqrf(mf.alpha_x * w.x) + sqrf(mf.alpha_y * w.y)) / z2;
    return (sqrtf(1.f + a2t2) - 1.f) * 0.5f;
}

static float mf_G1(lf_microfacet mf, lf_vec3 w) { return 1.f / (1.f + mf_lambda(mf, w)); }
static float mf_G(lf_microfacet mf, lf_vec3 wo, lf_vec3 wi)
{
    return 1.f / (1.f + mf_lambda(mf, wo) + mf_lambda(mf, wi));
}

/* Distribution of visible normals D_w(wm) = G1(w) max(0, w.wm) D(wm) / cos(w)
 * (Heitz 2018, eq. 3; pbrt-v4 eq. 9.23), which is also the sampling pdf. */
static float mf_pdf_visible(lf_microfacet mf, lf_vec3 w, lf_vec3 wm)
{
    float cz = fabsf(w.z);
    if (cz == 0.f)
        return 0.f;
    return mf_G1(mf, w) / cz * mf_D(mf, wm) * fabsf(lf_dot(w, wm));
}

/* Visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of
 * Visible Normals"; pbrt-v4 TrowbridgeReitzDistribution::Sample_wm). */
static lf_vec3 mf_sample_visible(lf_microfacet mf, lf_vec3 w, float u0, float u1)
{
    lf_vec3 wh = lf_normalize(lf_v3(mf.alpha_x * w.x, mf.alpha_y * w.y, w.z));
    if (wh.z < 0.f)
        wh = lf_neg(wh);
    lf_vec3 t1 = wh.z < 0.99999f ? lf_normalize(lf_cross(lf_v3(0, 0, 1), wh)) : lf_v3(1, 0, 0);
    lf_vec3 t2 = lf_cross(wh, t1);
    float r = sqrtf(u0), phi = 2.f * PI_F * u1;
    float px = r * cosf(phi), py = r * sinf(phi);
    float h = sqrtf(fmaxf(0.f, 1.f - px * px));
    py = lf_lerpf((1.f + wh.z) * 0.5f, h, py);
    float pz = sqrtf(fmaxf(0.f, 1.f - px * px - py * py));
    lf_vec3 nh = lf_add(lf_add(lf_scale(t1, px), lf_scale(t2, py)), lf_scale(wh, pz));
    return lf_normalize(lf_v3(mf.alpha_x * nh.x, mf.alpha_y * nh.y, fmaxf(1e-6f, nh.z)));
}

/* Microfacet reflection pdf: D_wo(wm) / (4 |wo.wm|) (pbrt-v4 eq. 9.28). */
static float mf_reflection_pdf(lf_microfacet mf, lf_vec3 wo, lf_vec3 wi)
{
    if (!same_hemisphere(wo, wi))
        return 0.f;
    lf_vec3 wm = lf_add(wo, wi);
    if (lf_dot(wm, wm) == 0.f)
        return 0.f;
    wm = lf_normalize(wm);
    if (wm.z < 0.f)
        wm = lf_neg(wm);
    float d = fabsf(lf_dot(wo, wm));
    if (d == 0.f)
        return 0.f;
    return mf_pdf_visible(mf, wo, wm) / (4.f * d);
}

/* Microfacet reflection without the Fresnel factor: D G / (4 cos_o cos_i)
 * (Torrance-Sparrow, pbrt-v4 eq. 9.33).  *wm_out gets the half vector. */
static float mf_reflection(lf_microfacet mf, lf_vec3 wo, lf_vec3 wi, lf_vec3 *wm_out)
{
    if (!same_hemisphere(wo, wi))
        return 0.f;
    float co = fabsf(wo.z), ci = fabsf(wi.z);
    if (co == 0.f || ci == 0.f)
        return 0.f;
    lf_vec3 wm = lf_add(wo, wi);
    if (lf_dot(wm, wm) == 0.f)
        return 0.f;
    wm = lf_normalize(wm);
    *wm_out = wm;
    return mf_D(mf, wm) * mf_G(mf, wo, wi) / (4.f * co * ci);
}

/* ------------------------------------------------------- conductor */

static lf_vec3 conductor_f(lf_vec3 eta, lf_vec3 k, lf_microfacet mf, lf_vec3 wo, lf_vec3 wi)
{
    if (mf_smooth(mf))
        return lf_v3(0, 0, 0);
    lf_vec3 wm;
    float base = mf_reflection(mf, wo, wi, &wm);
    if (base == 0.f)
        return lf_v3(0, 0, 0);
    return lf_scale(fresnel_conductor3(fabsf(lf_dot(wo, wm)), eta, k), base);
}

/* Samples the conductor lobe alone; returns 0 when there is no sample. */
static int conductor_sample(lf_vec3 eta, lf_vec3 k, lf_microfacet mf, lf_vec3 wo, float u0, float u1,
                            struct lf_bsdf_sample *s)
{
    if (wo.z == 0.f)
        return 0;
    if (mf_smooth(mf)) {
        s->wi = lf_v3(-wo.x, -wo.y, wo.z);
        float c = fabsf(wo.z);
        s->f = lf_scale(fresnel_conductor3(c, eta, k), 1.f / c);
        s->pdf = 1.f;
        s->specular = 1;
        return 1;
    }
    lf_vec3 wm = mf_sample_visible(mf, wo, u0, u1);
    lf_vec3 wi = reflect(wo, wm);
    if (!same_hemisphere(wo, wi))
        return 0;
    s->wi = wi;
    s->f = conductor_f(eta, k, mf, wo, wi);
    s->pdf = mf_reflection_pdf(mf, wo, wi);
    return s->pdf > 0.f;
}

/* ------------------------------------------------------ dielectric */

/* Rough dielectric BSDF (Walter et al. 2007, "Microfacet Models for
 * Refraction through Rough Surfaces"; pbrt-v4 DielectricBxDF::f/PDF).
 * Computes f and the sampling pdf together since both need wm and F. */
static float dielectric_eval(float eta, lf_microfacet mf, lf_vec3 wo, lf_vec3 wi, float *pdf)
{
    *pdf = 0.f;
    if (eta == 1.f || mf_smooth(mf))
        return 0.f;
    float co = wo.z, ci = wi.z;
    if (co == 0.f || ci == 0.f)
        return 0.f;
    int reflect_ = co * ci > 0.f;
    float etap = 1.f;
    if (!reflect_)
        etap = co > 0.f ? eta : 1.f / eta;
    /* Generalised half vector (Walter eq. 16): wm ~ wo + etap wi. */
    lf_vec3 wm = lf_add(lf_scale(wi, etap), wo);
    if (lf_dot(wm, wm) == 0.f)
        return 0.f;
    wm = lf_normalize(wm);
    if (wm.z < 0.f)
        wm = lf_neg(wm);
    /* Back-facing microfacets do not contribute. */
    if (lf_dot(wm, wi) * ci < 0.f || lf_dot(wm, wo) * co < 0.f)
        return 0.f;
    float F = lf_fresnel_dielectric(lf_dot(wo, wm), eta);
    float R = F, T = 1.f - F;
    float pr = R, pt = T;
    if (pr + pt <= 0.f)
        return 0.f;
    if (reflect_) {
        float d = fabsf(lf_dot(wo, wm));
        if (d == 0.f)
            return 0.f;
        *pdf = mf_pdf_visible(mf, wo, wm) / (4.f * d) * pr / (pr + pt);
        return mf_D(mf, wm) * mf_G(mf, wo, wi) * F / fabsf(4.f * ci * co);
    }
    float denom = sqrf(lf_dot(wi, wm) + lf_dot(wo, wm) / etap);
    if (!(denom > 0.f))
        return 0.f;
    float dwm_dwi = fabsf(lf_dot(wi, wm)) / denom; /* Walter eq. 17 */
    *pdf = mf_pdf_visible(mf, wo, wm) * dwm_dwi * pt / (pr + pt);
    float ft = mf_D(mf, wm) * T * mf_G(mf, wo, wi) *
               fabsf(lf_dot(wi, wm) * lf_dot(wo, wm) / (ci * co * denom));
    return ft / sqrf(etap); /* radiance transport: pbrt-v4 eq. 9.35 */
}

static int dielectric_sample(float eta, lf_microfacet mf, lf_vec3 wo, float uc, float u0, float u1,
                             struct lf_bsdf_sample *s)
{
    if (wo.z == 0.f)
        return 0;
    if (eta == 1.f || mf_smooth(mf)) {
        /* Specular: reflect with probability F, else refract (pbrt-v4 9.5.1). */
        float R = lf_fresnel_dielectric(wo.z, eta), T = 1.f - R;
        if (uc < R / (R + T)) {
            s->wi = lf_v3(-wo.x, -wo.y, wo.z);
            s->f = lf_v3(R, R, R);
            s->f = lf_scale(s->f, 1.f / fabsf(s->wi.z));
            s->pdf = R / (R + T);
            s->specular = 1;
            return 1;
        }
        lf_vec3 wi;
        float etap;
        if (!refract(wo, lf_v3(0, 0, 1), eta, &etap, &wi) || wi.z == 0.f)
            return 0;
        float ft = T / fabsf(wi.z) / (etap * etap);
        s->wi = wi;
        s->f = lf_v3(ft, ft, ft);
        s->pdf = T / (R + T);
        s->specular = 1;
        s->transmission = 1;
        s->eta = etap;
        return 1;
    }
    lf_vec3 wm = mf_sample_visible(mf, wo, u0, u1);
    float R = lf_fresnel_dielectric(lf_dot(wo, wm), eta), T = 1.f - R;
    lf_vec3 wi;
    if (uc < R / (R + T)) {
        wi = reflect(wo, wm);
        if (!same_hemisphere(wo, wi))
            return 0;
    } else {
        float etap;
        if (!refract(wo, wm, eta, &etap, &wi) || same_hemisphere(wo, wi) || wi.z == 0.f)
            return 0;
        s->transmission = 1;
        s->eta = etap;
    }
    /* Evaluate f and pdf in closed form for the chosen wi, exactly as
     * lf_bsdf_f / lf_bsdf_pdf would, so MIS weights agree. */
    float pdf;
    float f = dielectric_eval(eta, mf, wo, wi, &pdf);
    if (!(pdf > 0.f))
        return 0;
    s->wi = wi;
    s->f = lf_v3(f, f, f);
    s->pdf = pdf;
    return 1;
}

/* ---------------------------------------------------------- coated */

/* The coated BSDFs are an approximation of pbrt-v4's stochastic layered
 * BSDF (CoatedDiffuseBxDF / CoatedConductorBxDF), in the spirit of
 * Weidlich & Wilkie 2007 and Kelemen & Szirmay-Kalos 2001:
 *
 *   f = f_coat(wo, wi) + (1 - E(cos_o)) (1 - E(cos_i)) f_base'
 *
 * where f_coat is the coat's (smooth or GGX) dielectric reflection, E(mu)
 * its directional albedo (tabulated: lf_coat_table), so 1 - E is the energy
 * entering the coat.  For a Lambertian base of albedo r, the light that
 * enters bounces between base and coat; summing the series (Kelemen 2001,
 * eq. 11) gives
 *
 *   f_base' = r / (pi eta^2 (1 - r F_int)),  F_int = 1 - (1 - E_avg) / eta^2
 *
 * with E_avg the hemispherical average of E: the 1/eta^2 is the radiance
 * compression of light leaving a dense medium, and 1 - F_int the fraction
 * of the base's diffuse light that escapes (by reciprocity of the coat,
 * eta^2 (1 - F_int) = 1 - E_avg).  The directional albedo is then
 * E_i + (1 - E_i) r (1 - F_int) / (1 - r F_int) <= 1, with equality for
 * r = 1: energy conserving, reciprocal, white furnace exact for a white base.
 * For a conductor base f_base' is the conductor lobe with the index
 * relative to the coat, evaluated at the outside directions (refraction of
 * the base lobe and coat-conductor interreflection are ignored).
 * The layer's "thickness" attenuates each of the two passes by
 * exp(-thickness / cos_t) at the refracted angle, as pbrt-v4's LayeredBxDF
 * does between its interfaces (internal re-bounces are not attenuated).
 * Not modelled: scattering in the layer (albedo, g) and anisotropic coats
 * beyond using sqrt(ax ay) for the table lookup. */

static float coat_lookup_alpha(const lf_coat_table *t, float alpha, float *frac, int *ia)
{
    float a = lf_clampf(alpha, 0.f, 1.f) * (float)(LF_COAT_N_ALPHA - 1);
    int i = (int)a;
    if (i >= LF_COAT_N_ALPHA - 1)
        i = LF_COAT_N_ALPHA - 2;
    *frac = a - (float)i;
    *ia = i;
    (void)t;
    return a;
}

/* Directional albedo of the coat's reflection at cos_theta = mu. */
static float coat_albedo(const lf_coat_table *t, lf_microfacet mf, float mu)
{
    if (mf_smooth(mf))
        return lf_fresnel_dielectric(mu, t->eta);
    float frac, fc;
    int ia;
    coat_lookup_alpha(t, sqrtf(mf.alpha_x * mf.alpha_y), &frac, &ia);
    float c = lf_clampf(mu, 0.f, 1.f) * (float)(LF_COAT_N_COS - 1);
    int ic = (int)c;
    if (ic >= LF_COAT_N_COS - 1)
        ic = LF_COAT_N_COS - 2;
    fc = c - (float)ic;
    float a0 = lf_lerpf(fc, t->albedo[ia][ic], t->albedo[ia][ic + 1]);
    float a1 = lf_lerpf(fc, t->albedo[ia + 1][ic], t->albedo[ia + 1][ic + 1]);
    return lf_lerpf(frac, a0, a1);
}

static float coat_hemispherical(const lf_coat_table *t, lf_microfacet mf)
{
    if (mf_smooth(mf))
        return t->hemispherical[0];
    float frac;
    int ia;
    coat_lookup_alpha(t, sqrtf(mf.alpha_x * mf.alpha_y), &frac, &ia);
    return lf_lerpf(frac, t->hemispherical[ia], t->hemispherical[ia + 1]);
}

/* GGX reflection of a dielectric coat, Fresnel included. */
static float coat_reflection_f(float eta, lf_microfacet mf, lf_vec3 wo, lf_vec3 wi)
{
    lf_vec3 wm;
    float base = mf_reflection(mf, wo, wi, &wm);
    if (base == 0.f)
        return 0.f;
    return base * lf_fresnel_dielectric(fabsf(lf_dot(wo, wm)), eta);
}

void lf_coat_table_init(lf_coat_table *t, float eta)
{
    memset(t, 0, sizeof *t);
    t->eta = eta;
    /* Deterministic quadrature: E(mu) = integral of f cos dwi, importance
     * sampled with visible normals on a fixed 24x24 stratified grid (the
     * estimator weight is F G / G1(wo), Heitz 2018 eq. 19). */
    enum { N = 24 };
    for (int ia = 0; ia < LF_COAT_N_ALPHA; ia++) {
        float alpha = (float)ia / (float)(LF_COAT_N_ALPHA - 1);
        lf_microfacet mf = {alpha, alpha};
        double hemi = 0.0;
        for (int ic = 0; ic < LF_COAT_N_COS; ic++) {
            float mu = (float)ic / (float)(LF_COAT_N_COS - 1);
            mu = fmaxf(mu, 1e-4f);
            double e = 0.0;
            if (alpha < LF_SMOOTH_ALPHA) {
                e = lf_fresnel_dielectric(mu, eta);
            } else {
                lf_vec3 wo = lf_v3(sqrtf(fmaxf(0.f, 1.f - mu * mu)), 0.f, mu);
                for (int i = 0; i < N; i++)
                    for (int j = 0; j < N; j++) {
                        lf_vec3 wm = mf_sample_visible(mf, wo, ((float)i + 0.5f) / N, ((float)j + 0.5f) / N);
                        lf_vec3 wi = reflect(wo, wm);
                        if (wi.z <= 0.f)
                            continue;
                        float F = lf_fresnel_dielectric(lf_dot(wo, wm), eta);
                        e += F * mf_G(mf, wo, wi) / mf_G1(mf, wo);
                    }
                e /= (double)(N * N);
            }
            t->albedo[ia][ic] = (float)e;
        }
        /* Hemispherical average 2 int E(mu) mu dmu, trapezoid rule. */
        for (int ic = 0; ic + 1 < LF_COAT_N_COS; ic++) {
            double m0 = (double)ic / (LF_COAT_N_COS - 1), m1 = (double)(ic + 1) / (LF_COAT_N_COS - 1);
            hemi += (t->albedo[ia][ic] * m0 + t->albedo[ia][ic + 1] * m1) * 0.5 * (m1 - m0);
        }
        t->hemispherical[ia] = (float)(2.0 * hemi);
    }
    /* The smooth row: integrate F finely, as it has a steep grazing rise. */
    double hemi = 0.0;
    const int M = 4096;
    for (int i = 0; i < M; i++) {
        double mu = (i + 0.5) / M;
        hemi += lf_fresnel_dielectric((float)mu, eta) * mu;
    }
    t->hemispherical[0] = (float)(2.0 * hemi / M);
}

/* Attenuation of one vertical pass through the layer along the direction
 * refracted from outside direction cosine mu: exp(-thickness / cos_t)
 * (pbrt-v4 LayeredBxDF's Tr() with the layer's unit extinction). */
static float layer_tr(float thickness, float eta, float mu)
{
    if (thickness <= 0.f)
        return 1.f;
    float cos_t = sqrtf(fmaxf(0.f, 1.f - (1.f - mu * mu) / (eta * eta)));
    return cos_t > 0.f ? expf(-thickness / cos_t) : 0.f;
}

/* Light reaching the base from both directions, (1 - E_o)(1 - E_i). */
static float coat_transmit(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi)
{
    const lf_coat_table *t = b->u.coated.table;
    float mo = fabsf(wo.z), mi = fabsf(wi.z);
    float tr = (1.f - coat_albedo(t, b->u.coated.coat, mo)) * (1.f - coat_albedo(t, b->u.coated.coat, mi));
    if (b->u.coated.thickness > 0.f)
        tr *= layer_tr(b->u.coated.thickness, b->u.coated.eta, mo) * layer_tr(b->u.coated.thickness, b->u.coated.eta, mi);
    return tr;
}

static lf_vec3 coated_diffuse_base(const lf_bsdf *b)
{
    float eta = b->u.coated.eta;
    float fint = 1.f - (1.f - coat_hemispherical(b->u.coated.table, b->u.coated.coat)) / (eta * eta);
    lf_vec3 r = b->u.coated.r;
    float k = (float)LF_INV_PI / (eta * eta);
    return lf_v3(r.x * k / (1.f - r.x * fint), r.y * k / (1.f - r.y * fint), r.z * k / (1.f - r.z * fint));
}

/* Probability of sampling the coat rather than the base, from their
 * albedo estimates at wo. */
static float coated_coat_prob(const lf_bsdf *b, lf_vec3 wo)
{
    float mu = fabsf(wo.z);
    float ec = coat_albedo(b->u.coated.table, b->u.coated.coat, mu);
    float eb;
    if (b->kind == LF_LOBE_COATED_DIFFUSE) {
        lf_vec3 r = b->u.coated.r;
        eb = (r.x + r.y + r.z) / 3.f;
    } else {
        lf_vec3 F = fresnel_conductor3(mu, b->u.coated.eta_b, b->u.coated.k_b);
        eb = (F.x + F.y + F.z) / 3.f;
    }
    eb *= 1.f - ec;
    if (ec + eb <= 0.f)
        return 0.5f;
    return ec / (ec + eb);
}

static int coated_base_smooth(const lf_bsdf *b)
{
    return b->kind == LF_LOBE_COATED_CONDUCTOR && mf_smooth(b->u.coated.base);
}

/* Non-delta parts of the coated BSDF; wo, wi already flipped to wo.z > 0. */
static lf_vec3 coated_f(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi)
{
    if (!same_hemisphere(wo, wi) || wo.z == 0.f || wi.z == 0.f)
        return lf_v3(0, 0, 0);
    float fc = mf_smooth(b->u.coated.coat) ? 0.f : coat_reflection_f(b->u.coated.eta, b->u.coated.coat, wo, wi);
    lf_vec3 f = lf_v3(fc, fc, fc);
    float tr = coat_transmit(b, wo, wi);
    if (b->kind == LF_LOBE_COATED_DIFFUSE)
        f = lf_add(f, lf_scale(coated_diffuse_base(b), tr));
    else if (!coated_base_smooth(b))
        f = lf_add(f, lf_scale(conductor_f(b->u.coated.eta_b, b->u.coated.k_b, b->u.coated.base, wo, wi), tr));
    return f;
}

static float coated_pdf(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi)
{
    if (!same_hemisphere(wo, wi))
        return 0.f;
    float pc = coated_coat_prob(b, wo);
    float pdf = 0.f;
    if (!mf_smooth(b->u.coated.coat))
        pdf += pc * mf_reflection_pdf(b->u.coated.coat, wo, wi);
    if (b->kind == LF_LOBE_COATED_DIFFUSE)
        pdf += (1.f - pc) * fabsf(wi.z) * (float)LF_INV_PI;
    else if (!coated_base_smooth(b))
        pdf += (1.f - pc) * mf_reflection_pdf(b->u.coated.base, wo, wi);
    return pdf;
}

static int coated_sample(const lf_bsdf *b, lf_vec3 wo, float uc, float u0, float u1, struct lf_bsdf_sample *s)
{
    if (wo.z == 0.f)
        return 0;
    float pc = coated_coat_prob(b, wo);
    int coat_smooth = mf_smooth(b->u.coated.coat), base_smooth = coated_base_smooth(b);
    float mu = fabsf(wo.z);
    lf_vec3 mirror = lf_v3(-wo.x, -wo.y, wo.z);
    if (coat_smooth && base_smooth) {
        /* Both deltas point the same way: one specular lobe. */
        float Fc = lf_fresnel_dielectric(mu, b->u.coated.eta);
        lf_vec3 Fm = fresnel_conductor3(mu, b->u.coated.eta_b, b->u.coated.k_b);
        s->wi = mirror;
        s->f = lf_scale(lf_add(lf_v3(Fc, Fc, Fc), lf_scale(Fm, coat_transmit(b, wo, mirror))), 1.f / mu);
        s->pdf = 1.f;
        s->specular = 1;
        return 1;
    }
    if (uc < pc) {
        if (coat_smooth) {
            float Fc = lf_fresnel_dielectric(mu, b->u.coated.eta);
            s->wi = mirror;
            s->f = lf_v3(Fc / mu, Fc / mu, Fc / mu);
            s->pdf = pc;
            s->specular = 1;
            return 1;
        }
        lf_vec3 wm = mf_sample_visible(b->u.coated.coat, wo, u0, u1);
        s->wi = reflect(wo, wm);
    } else if (b->kind == LF_LOBE_COATED_DIFFUSE) {
        s->wi = sample_cosine(u0, u1);
    } else if (base_smooth) {
        float tr = coat_transmit(b, wo, mirror);
        s->wi = mirror;
        s->f = lf_scale(fresnel_conductor3(mu, b->u.coated.eta_b, b->u.coated.k_b), tr / mu);
        s->pdf = 1.f - pc;
        s->specular = 1;
        return 1;
    } else {
        lf_vec3 wm = mf_sample_visible(b->u.coated.base, wo, u0, u1);
        s->wi = reflect(wo, wm);
    }
    if (!same_hemisphere(wo, s->wi) || s->wi.z == 0.f)
        return 0;
    s->f = coated_f(b, wo, s->wi);
    s->pdf = coated_pdf(b, wo, s->wi);
    return s->pdf > 0.f;
}

/* ----------------------------------------------------- constructors */

void lf_bsdf_set_diffuse(lf_bsdf *b, lf_vec3 r)
{
    b->kind = LF_LOBE_DIFFUSE;
    b->u.diffuse.r = r;
}

void lf_bsdf_set_diffuse_transmission(lf_bsdf *b, lf_vec3 r, lf_vec3 t)
{
    b->kind = LF_LOBE_DIFFUSE_TRANSMISSION;
    b->u.diffuse_transmission.r = r;
    b->u.diffuse_transmission.t = t;
}

void lf_bsdf_set_conductor(lf_bsdf *b, lf_vec3 eta, lf_vec3 k, lf_microfacet mf)
{
    b->kind = LF_LOBE_CONDUCTOR;
    b->u.conductor.eta = eta;
    b->u.conductor.k = k;
    b->u.conductor.mf = mf;
}

void lf_bsdf_set_dielectric(lf_bsdf *b, float eta, lf_microfacet mf)
{
    b->kind = LF_LOBE_DIELECTRIC;
    b->u.dielectric.eta = eta;
    b->u.dielectric.mf = mf;
}

void lf_bsdf_set_thin_dielectric(lf_bsdf *b, float eta)
{
    b->kind = LF_LOBE_THIN_DIELECTRIC;
    b->u.thin.eta = eta;
}

void lf_bsdf_set_normalized_fresnel(lf_bsdf *b, float eta, float c)
{
    b->kind = LF_LOBE_NORMALIZED_FRESNEL;
    b->u.nfresnel.eta = eta;
    b->u.nfresnel.c = c;
}

/* c = 2 int_0^1 (1 - Fr(mu, eta)) mu dmu by the midpoint rule (Fr is
 * smooth; 256 points are exact to ~1e-5). */
float lf_normalized_fresnel_c(float eta)
{
    double sum = 0.0;
    for (int i = 0; i < 256; i++) {
        double mu = (i + 0.5) / 256.0;
        sum += (1.0 - lf_fresnel_dielectric((float)mu, eta)) * mu;
    }
    return (float)(2.0 * sum / 256.0);
}

static lf_vec3 nfresnel_f(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi)
{
    if (!same_hemisphere(wo, wi) || !(b->u.nfresnel.c > 0.f))
        return lf_v3(0, 0, 0);
    float eta = b->u.nfresnel.eta;
    float v = eta * eta * (1.f - lf_fresnel_dielectric(fabsf(wi.z), eta)) / (b->u.nfresnel.c * PI_F);
    return lf_v3(v, v, v);
}

void lf_bsdf_set_measured(lf_bsdf *b, const lf_measured *data)
{
    b->kind = LF_LOBE_MEASURED;
    b->u.measured.data = data;
}

void lf_bsdf_set_coated_diffuse(lf_bsdf *b, const lf_coat_table *table, lf_microfacet coat, lf_vec3 r)
{
    b->kind = LF_LOBE_COATED_DIFFUSE;
    b->u.coated.eta = table->eta;
    b->u.coated.table = table;
    b->u.coated.coat = coat;
    b->u.coated.r = r;
}

void lf_bsdf_set_coated_conductor(lf_bsdf *b, const lf_coat_table *table, lf_microfacet coat, lf_vec3 eta_b,
                                  lf_vec3 k_b, lf_microfacet base)
{
    b->kind = LF_LOBE_COATED_CONDUCTOR;
    b->u.coated.eta = table->eta;
    b->u.coated.table = table;
    b->u.coated.coat = coat;
    b->u.coated.eta_b = lf_scale(eta_b, 1.f / table->eta);
    b->u.coated.k_b = lf_scale(k_b, 1.f / table->eta);
    b->u.coated.base = base;
}

/* ------------------------------------------------------- interface */

/* Thin dielectric slab: R' = R + T^2 R / (1 - R^2) after summing the
 * internal bounces (pbrt-v4 ThinDielectricBxDF, eq. 9.9). */
static void thin_rt(float eta, float cos_o, float *R, float *T)
{
    float r = lf_fresnel_dielectric(fabsf(cos_o), eta), t = 1.f - r;
    if (r < 1.f) {
        r += t * t * r / (1.f - r * r);
        t = 1.f - r;
    }
    *R = r;
    *T = t;
}

lf_vec3 lf_bsdf_f(const lf_bsdf *b, lf_vec3 wo_w, lf_vec3 wi_w)
{
    lf_vec3 wo = to_local(b, wo_w), wi = to_local(b, wi_w);
    lf_vec3 zero = lf_v3(0, 0, 0);
    switch (b->kind) {
    case LF_LOBE_DIFFUSE:
        return same_hemisphere(wo, wi) ? lf_scale(b->u.diffuse.r, (float)LF_INV_PI) : zero;
    case LF_LOBE_DIFFUSE_TRANSMISSION:
        if (wo.z == 0.f || wi.z == 0.f)
            return zero;
        return lf_scale(same_hemisphere(wo, wi) ? b->u.diffuse_transmission.r : b->u.diffuse_transmission.t,
                        (float)LF_INV_PI);
    case LF_LOBE_CONDUCTOR:
        return conductor_f(b->u.conductor.eta, b->u.conductor.k, b->u.conductor.mf, wo, wi);
    case LF_LOBE_DIELECTRIC: {
        float pdf, f = dielectric_eval(b->u.dielectric.eta, b->u.dielectric.mf, wo, wi, &pdf);
        return lf_v3(f, f, f);
    }
    case LF_LOBE_COATED_DIFFUSE:
    case LF_LOBE_COATED_CONDUCTOR:
        if (wo.z < 0.f) { /* two-sided, as pbrt-v4's coated materials */
            wo = lf_neg(wo);
            wi = lf_neg(wi);
        }
        return coated_f(b, wo, wi);
    case LF_LOBE_MEASURED:
        return lf_measured_f(b->u.measured.data, wo, wi);
    case LF_LOBE_HAIR:
        return lf_hair_f(&b->u.hair, wo, wi);
    case LF_LOBE_NORMALIZED_FRESNEL:
        return nfresnel_f(b, wo, wi);
    case LF_LOBE_THIN_DIELECTRIC:
    case LF_LOBE_NONE:
        break;
    }
    return zero;
}

float lf_bsdf_pdf(const lf_bsdf *b, lf_vec3 wo_w, lf_vec3 wi_w)
{
    lf_vec3 wo = to_local(b, wo_w), wi = to_local(b, wi_w);
    switch (b->kind) {
    case LF_LOBE_DIFFUSE:
        return same_hemisphere(wo, wi) ? fabsf(wi.z) * (float)LF_INV_PI : 0.f;
    case LF_LOBE_DIFFUSE_TRANSMISSION: {
        float pr = lf_maxc(b->u.diffuse_transmission.r), pt = lf_maxc(b->u.diffuse_transmission.t);
        if (pr + pt <= 0.f || wo.z == 0.f)
            return 0.f;
        float p = fabsf(wi.z) * (float)LF_INV_PI;
        return same_hemisphere(wo, wi) ? p * pr / (pr + pt) : p * pt / (pr + pt);
    }
    case LF_LOBE_CONDUCTOR:
        if (mf_smooth(b->u.conductor.mf))
            return 0.f;
        return mf_reflection_pdf(b->u.conductor.mf, wo, wi);
    case LF_LOBE_DIELECTRIC: {
        float pdf;
        dielectric_eval(b->u.dielectric.eta, b->u.dielectric.mf, wo, wi, &pdf);
        return pdf;
    }
    case LF_LOBE_COATED_DIFFUSE:
    case LF_LOBE_COATED_CONDUCTOR:
        if (wo.z < 0.f) {
            wo = lf_neg(wo);
            wi = lf_neg(wi);
        }
        return coated_pdf(b, wo, wi);
    case LF_LOBE_MEASURED:
        return lf_measured_pdf(b->u.measured.data, wo, wi);
    case LF_LOBE_HAIR:
        return lf_hair_pdf(&b->u.hair, wo, wi);
    case LF_LOBE_NORMALIZED_FRESNEL:
        return same_hemisphere(wo, wi) ? fabsf(wi.z) * (float)LF_INV_PI : 0.f;
    case LF_LOBE_THIN_DIELECTRIC:
    case LF_LOBE_NONE:
        break;
    }
    return 0.f;
}

static int sample_local(const lf_bsdf *b, lf_vec3 wo, float uc, float u0, float u1, struct lf_bsdf_sample *s)
{
    switch (b->kind) {
    case LF_LOBE_DIFFUSE: {
        if (wo.z == 0.f)
            return 0;
        lf_vec3 wi = sample_cosine(u0, u1);
        if (wo.z < 0.f)
            wi.z = -wi.z;
        s->wi = wi;
        s->f = lf_scale(b->u.diffuse.r, (float)LF_INV_PI);
        s->pdf = fabsf(wi.z) * (float)LF_INV_PI;
        return s->pdf > 0.f;
    }
    case LF_LOBE_DIFFUSE_TRANSMISSION: {
        float pr = lf_maxc(b->u.diffuse_transmission.r), pt = lf_maxc(b->u.diffuse_transmission.t);
        if (pr + pt <= 0.f || wo.z == 0.f)
            return 0;
        lf_vec3 wi = sample_cosine(u0, u1);
        float p = fabsf(wi.z) * (float)LF_INV_PI;
        if (uc < pr / (pr + pt)) {
            if (wo.z < 0.f)
                wi.z = -wi.z;
            s->f = lf_scale(b->u.diffuse_transmission.r, (float)LF_INV_PI);
            s->pdf = p * pr / (pr + pt);
        } else {
            if (wo.z > 0.f)
                wi.z = -wi.z;
            s->f = lf_scale(b->u.diffuse_transmission.t, (float)LF_INV_PI);
            s->pdf = p * pt / (pr + pt);
            s->transmission = 1;
        }
        s->wi = wi;
        return s->pdf > 0.f;
    }
    case LF_LOBE_CONDUCTOR:
        return conductor_sample(b->u.conductor.eta, b->u.conductor.k, b->u.conductor.mf, wo, u0, u1, s);
    case LF_LOBE_DIELECTRIC:
        return dielectric_sample(b->u.dielectric.eta, b->u.dielectric.mf, wo, uc, u0, u1, s);
    case LF_LOBE_THIN_DIELECTRIC: {
        if (wo.z == 0.f)
            return 0;
        float R, T;
        thin_rt(b->u.thin.eta, wo.z, &R, &T);
        float c = fabsf(wo.z);
        if (uc < R / (R + T)) {
            s->wi = lf_v3(-wo.x, -wo.y, wo.z);
            s->f = lf_v3(R / c, R / c, R / c);
            s->pdf = R / (R + T);
        } else {
            s->wi = lf_neg(wo);
            s->f = lf_v3(T / c, T / c, T / c);
            s->pdf = T / (R + T);
            s->transmission = 1;
        }
        s->specular = 1;
        return 1;
    }
    case LF_LOBE_COATED_DIFFUSE:
    case LF_LOBE_COATED_CONDUCTOR: {
        int flip = wo.z < 0.f;
        if (flip)
            wo = lf_neg(wo);
        if (!coated_sample(b, wo, uc, u0, u1, s))
            return 0;
        if (flip)
            s->wi = lf_neg(s->wi);
        return 1;
    }
    case LF_LOBE_MEASURED:
        return lf_measured_sample(b->u.measured.data, wo, u0, u1, &s->wi, &s->f, &s->pdf);
    case LF_LOBE_NORMALIZED_FRESNEL: {
        if (wo.z == 0.f)
            return 0;
        lf_vec3 wi = sample_cosine(u0, u1);
        if (wo.z < 0.f)
            wi.z = -wi.z;
        s->wi = wi;
        s->f = nfresnel_f(b, wo, wi);
        s->pdf = fabsf(wi.z) * (float)LF_INV_PI;
        return s->pdf > 0.f;
    }
    case LF_LOBE_HAIR:
        if (!lf_hair_sample(&b->u.hair, wo, uc, u0, u1, &s->wi, &s->f, &s->pdf))
            return 0;
        s->transmission = s->wi.z * wo.z < 0.f;
        return 1;
    case LF_LOBE_NONE:
        break;
    }
    return 0;
}

int lf_bsdf_sample(const lf_bsdf *b, lf_vec3 wo_w, float uc, float u0, float u1, struct lf_bsdf_sample *s)
{
    memset(s, 0, sizeof *s);
    s->eta = 1.f;
    lf_vec3 wo = to_local(b, wo_w);
    if (!sample_local(b, wo, uc, u0, u1, s))
        return 0;
    if (!(s->pdf > 0.f) || !isfinite(s->pdf) || !isfinite(s->f.x) || !isfinite(s->f.y) || !isfinite(s->f.z))
        return 0;
    s->wi = to_world(b, s->wi);
    return 1;
}

int lf_bsdf_is_specular(const lf_bsdf *b)
{
    switch (b->kind) {
    case LF_LOBE_CONDUCTOR:
        return mf_smooth(b->u.conductor.mf);
    case LF_LOBE_DIELECTRIC:
        return b->u.dielectric.eta == 1.f || mf_smooth(b->u.dielectric.mf);
    case LF_LOBE_THIN_DIELECTRIC:
        return 1;
    case LF_LOBE_COATED_CONDUCTOR:
        return mf_smooth(b->u.coated.coat) && mf_smooth(b->u.coated.base);
    case LF_LOBE_NONE: /* nothing to light-sample either */
        return 1;
    case LF_LOBE_DIFFUSE:
    case LF_LOBE_DIFFUSE_TRANSMISSION:
    case LF_LOBE_COATED_DIFFUSE:
    case LF_LOBE_MEASURED:
    case LF_LOBE_HAIR:
    case LF_LOBE_NORMALIZED_FRESNEL:
        break;
    }
    return 0;
}
