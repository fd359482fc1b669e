/* hair.c - the hair fibre BSDF of Chiang, Bitterli, Tappan and Burley,
 * "A Practical and Controllable Hair and Fur Model for Production Path
 * Tracing" (EGSR 2016), as pbrt-v4's HairBxDF implements it (PBR 4th ed.,
 * sec. 9.9): a dielectric cylinder of index eta and absorption sigma_a
 * whose scattering is summed over the paths R (p = 0), TT (1), TRT (2) and
 * the rest (3+), each the product of a longitudinal lobe M_p (d'Eon et
 * al. 2011, variance v_p from beta_m), an attenuation A_p (Fresnel and
 * absorption along the refracted chord) and an azimuthal lobe N_p (a
 * trimmed logistic of scale s from beta_n around the exit angle Phi(p)),
 * with the cuticle scales tilting M_p by 2^k alpha.
 *
 * Local frame: x along the fibre, (y, z) across it with z the surface
 * normal; h in [-1, 1] is where the ray met the fibre's width. */
#include "lf_shading.h"

#include <math.h>

#define PI_F ((float)LF_PI)
#define P_MAX 3

static float sqrf(float x) { return x * x; }
static float safe_sqrt(float x) { return sqrtf(fmaxf(0.f, x)); }
static float safe_asin(float x) { return asinf(lf_clampf(x, -1.f, 1.f)); }

/* Modified Bessel function of the first kind, order 0: its series
 * sum (x/2)^2k / (k!)^2, summed to convergence (pbrt stops at 10 terms,
 * which loses ~2 % of M_p's peak where log_i0 switches at x = 12). */
static float bessel_i0(float x)
{
    double q = 0.25 * (double)x * x, term = 1.0, val = 1.0;
    for (int k = 1; k < 60 && term > 1e-9 * val; k++) {
        term *= q / ((double)k * k);
        val += term;
    }
    return (float)val;
}

static float log_i0(float x)
{
    if (x > 12.f) /* asymptotic expansion */
        return x + 0.5f * (-logf(2.f * PI_F) + logf(1.f / x) + 1.f / (8.f * x));
    return logf(bessel_i0(x));
}

/* Longitudinal scattering (d'Eon et al. 2011), in log space for small v. */
static float hair_mp(float cos_i, float cos_o, float sin_i, float sin_o, float v)
{
    float a = cos_i * cos_o / v, b = sin_i * sin_o / v;
    if (v <= .1f)
        return expf(log_i0(a) - b - 1.f / v + 0.6931f + logf(1.f / (2.f * v)));
    return expf(-b) * bessel_i0(a) / (sinhf(1.f / v) * 2.f * v);
}

/* Attenuation of each path: Fresnel f at the entry, transmittance T per
 * chord; the p = 3+ term sums the geometric series. */
static void hair_ap(float cos_o, float eta, float h, lf_vec3 T, lf_vec3 ap[P_MAX + 1])
{
    float cos_gamma_o = safe_sqrt(1.f - h * h);
    float f = lf_fresnel_dielectric(cos_o * cos_gamma_o, eta);
    ap[0] = lf_v3(f, f, f);
    ap[1] = lf_scale(T, sqrf(1.f - f));
    for (int p = 2; p < P_MAX; p++)
        ap[p] = lf_scale(lf_mul(ap[p - 1], T), f);
    lf_vec3 tf = lf_scale(T, f), last = lf_mul(ap[P_MAX - 1], tf);
    ap[P_MAX] = lf_v3(tf.x < 1.f ? last.x / (1.f - tf.x) : 0.f, tf.y < 1.f ? last.y / (1.f - tf.y) : 0.f,
                      tf.z < 1.f ? last.z / (1.f - tf.z) : 0.f);
}

static float hair_phi(int p, float gamma_o, float gamma_t) { return 2.f * p * gamma_t - 2.f * gamma_o + p * PI_F; }

static float logistic(float x, float s)
{
    x = fabsf(x);
    float e = expf(-x / s);
    return e / (s * sqrf(1.f + e));
}

static float logistic_cdf(float x, float s) { return 1.f / (1.f + expf(-x / s)); }

static float trimmed_logistic(float x, float s, float a, float b)
{
    return logistic(x, s) / (logistic_cdf(b, s) - logistic_cdf(a, s));
}

static float sample_trimmed_logistic(float u, float s, float a, float b)
{
    float k = logistic_cdf(b, s) - logistic_cdf(a, s);
    float x = -s * logf(1.f / (u * k + logistic_cdf(a, s)) - 1.f);
    return lf_clampf(x, a, b);
}

static float hair_np(float phi, int p, float s, float gamma_o, float gamma_t)
{
    float dphi = phi - hair_phi(p, gamma_o, gamma_t);
    dphi = remainderf(dphi, 2.f * PI_F); /* into [-pi, pi] */
    return trimmed_logistic(dphi, s, -PI_F, PI_F);
}

void lf_hair_setup(lf_hair *hp, float h, float eta, lf_vec3 sigma_a, float beta_m, float beta_n, float alpha_deg)
{
    hp->h = lf_clampf(h, -1.f, 1.f);
    hp->eta = eta;
    hp->sigma_a = sigma_a;
    hp->gamma_o = safe_asin(hp->h);
    /* Chiang et al.'s fits of the lobe widths to their roughness controls */
    float bm2 = beta_m * beta_m, bm20 = powf(beta_m, 20.f);
    hp->v[0] = sqrf(0.726f * beta_m + 0.812f * bm2 + 3.7f * bm20);
    hp->v[1] = .25f * hp->v[0];
    hp->v[2] = 4.f * hp->v[0];
    hp->v[3] = hp->v[2];
    const float sqrt_pi_over_8 = 0.626657069f;
    hp->s = sqrt_pi_over_8 * (0.265f * beta_n + 1.194f * sqrf(beta_n) + 5.372f * powf(beta_n, 22.f));
    hp->sin2k_alpha[0] = sinf(alpha_deg * PI_F / 180.f);
    hp->cos2k_alpha[0] = safe_sqrt(1.f - sqrf(hp->sin2k_alpha[0]));
    for (int i = 1; i < 3; i++) {
        hp->sin2k_alpha[i] = 2.f * hp->cos2k_alpha[i - 1] * hp->sin2k_alpha[i - 1];
        hp->cos2k_alpha[i] = sqrf(hp->cos2k_alpha[i - 1]) - sqrf(hp->sin2k_alpha[i - 1]);
    }
}

/* theta_o tilted by the scales for path p: R by -2 alpha, TT by alpha,
 * TRT by 4 alpha (pbrt's index order 1, 0, 2); 3+ untilted. */
static void tilt(const lf_hair *hp, int p, float sin_o, float cos_o, float *sp, float *cp)
{
    if (p == 0) {
        *sp = sin_o * hp->cos2k_alpha[1] - cos_o * hp->sin2k_alpha[1];
        *cp = cos_o * hp->cos2k_alpha[1] + sin_o * hp->sin2k_alpha[1];
    } else if (p == 1) {
        *sp = sin_o * hp->cos2k_alpha[0] + cos_o * hp->sin2k_alpha[0];
        *cp = cos_o * hp->cos2k_alpha[0] - sin_o * hp->sin2k_alpha[0];
    } else if (p == 2) {
        *sp = sin_o * hp->cos2k_alpha[2] + cos_o * hp->sin2k_alpha[2];
        *cp = cos_o * hp->cos2k_alpha[2] - sin_o * hp->sin2k_alpha[2];
    } else {
        *sp = sin_o;
        *cp = cos_o;
    }
    *cp = fabsf(*cp); /* out-of-range cos from the tilt */
}

/* gamma_t, the refracted ray's offset angle, and the chord transmittance. */
static float refracted(const lf_hair *hp, float sin_o, float cos_o, lf_vec3 *T)
{
    float sin_t = sin_o / hp->eta, cos_t = safe_sqrt(1.f - sqrf(sin_t));
    float etap = safe_sqrt(hp->eta * hp->eta - sqrf(sin_o)) / cos_o;
    float sin_gt = hp->h / etap, cos_gt = safe_sqrt(1.f - sqrf(sin_gt));
    if (T) {
        float len = 2.f * cos_gt / cos_t;
        *T = lf_v3(expf(-hp->sigma_a.x * len), expf(-hp->sigma_a.y * len), expf(-hp->sigma_a.z * len));
    }
    return safe_asin(sin_gt);
}

lf_vec3 lf_hair_f(const lf_hair *hp, lf_vec3 wo, lf_vec3 wi)
{
    float sin_o = wo.x, cos_o = safe_sqrt(1.f - sqrf(sin_o)), phi_o = atan2f(wo.z, wo.y);
    float sin_i = wi.x, cos_i = safe_sqrt(1.f - sqrf(sin_i)), phi_i = atan2f(wi.z, wi.y);
    lf_vec3 T;
    float gamma_t = refracted(hp, sin_o, cos_o, &T);
    lf_vec3 ap[P_MAX + 1];
    hair_ap(cos_o, hp->eta, hp->h, T, ap);
    float phi = phi_i - phi_o;
    lf_vec3 sum = lf_v3(0, 0, 0);
    for (int p = 0; p < P_MAX; p++) {
        float sp, cp;
        tilt(hp, p, sin_o, cos_o, &sp, &cp);
        float w = hair_mp(cos_i, cp, sin_i, sp, hp->v[p]) * hair_np(phi, p, hp->s, hp->gamma_o, gamma_t);
        sum = lf_add(sum, lf_scale(ap[p], w));
    }
    sum = lf_add(sum, lf_scale(ap[P_MAX], hair_mp(cos_i, cos_o, sin_i, sin_o, hp->v[P_MAX]) / (2.f * PI_F)));
    if (fabsf(wi.z) > 0.f) /* pbrt divides out the cosine the integrator applies */
        sum = lf_scale(sum, 1.f / fabsf(wi.z));
    return sum;
}

/* Each path's share of the attenuation (luminance-free: channel mean). */
static void ap_pdf(const lf_hair *hp, float sin_o, float cos_o, float pdf[P_MAX + 1])
{
    lf_vec3 T, ap[P_MAX + 1];
    refracted(hp, sin_o, cos_o, &T);
    hair_ap(cos_o, hp->eta, hp->h, T, ap);
    float sum = 0.f;
    for (int p = 0; p <= P_MAX; p++)
        sum += (ap[p].x + ap[p].y + ap[p].z) / 3.f;
    for (int p = 0; p <= P_MAX; p++)
        pdf[p] = sum > 0.f ? (ap[p].x + ap[p].y + ap[p].z) / 3.f / sum : 0.f;
}

static float pdf_terms(const lf_hair *hp, float sin_o, float cos_o, float sin_i, float cos_i, float dphi,
                       float gamma_t, const float apdf[P_MAX + 1])
{
    float pdf = 0.f;
    for (int p = 0; p < P_MAX; p++) {
        float sp, cp;
        tilt(hp, p, sin_o, cos_o, &sp, &cp);
        pdf += hair_mp(cos_i, cp, sin_i, sp, hp->v[p]) * apdf[p] * hair_np(dphi, p, hp->s, hp->gamma_o, gamma_t);
    }
    return pdf + hair_mp(cos_i, cos_o, sin_i, sin_o, hp->v[P_MAX]) * apdf[P_MAX] / (2.f * PI_F);
}

float lf_hair_pdf(const lf_hair *hp, lf_vec3 wo, lf_vec3 wi)
{
    float sin_o = wo.x, cos_o = safe_sqrt(1.f - sqrf(sin_o)), phi_o = atan2f(wo.z, wo.y);
    float sin_i = wi.x, cos_i = safe_sqrt(1.f - sqrf(sin_i)), phi_i = atan2f(wi.z, wi.y);
    float gamma_t = refracted(hp, sin_o, cos_o, NULL);
    float apdf[P_MAX + 1];
    ap_pdf(hp, sin_o, cos_o, apdf);
    return pdf_terms(hp, sin_o, cos_o, sin_i, cos_i, phi_i - phi_o, gamma_t, apdf);
}

int lf_hair_sample(const lf_hair *hp, lf_vec3 wo, float uc, float u0, float u1, lf_vec3 *wi_out, lf_vec3 *f,
                   float *pdf)
{
    float sin_o = wo.x, cos_o = safe_sqrt(1.f - sqrf(sin_o)), phi_o = atan2f(wo.z, wo.y);
    float apdf[P_MAX + 1];
    ap_pdf(hp, sin_o, cos_o, apdf);
    /* pick the path p with uc, then stretch uc back to [0, 1) for N_p */
    int p = 0;
    float cdf = 0.f;
    while (p < P_MAX && uc >= cdf + apdf[p]) {
        cdf += apdf[p];
        p++;
    }
    if (!(apdf[p] > 0.f))
        return 0;
    uc = lf_clampf((uc - cdf) / apdf[p], 0.f, LF_ONE_MINUS_EPS);
    float sp, cp;
    tilt(hp, p, sin_o, cos_o, &sp, &cp);
    /* M_p: cos theta from the lobe's exponential form, then rotate */
    float v = hp->v[p];
    float cos_t = 1.f + v * logf(fmaxf(u0, 1e-5f) + (1.f - u0) * expf(-2.f / v));
    float sin_t = safe_sqrt(1.f - sqrf(cos_t));
    float sin_i = -cos_t * sp + sin_t * cosf(2.f * PI_F * u1) * cp;
    float cos_i = safe_sqrt(1.f - sqrf(sin_i));
    float gamma_t = refracted(hp, sin_o, cos_o, NULL);
    float dphi = p < P_MAX ? hair_phi(p, hp->gamma_o, gamma_t) + sample_trimmed_logistic(uc, hp->s, -PI_F, PI_F)
                           : 2.f * PI_F * uc;
    float phi_i = phi_o + dphi;
    lf_vec3 wi = lf_v3(sin_i, cos_i * cosf(phi_i), cos_i * sinf(phi_i));
    *wi_out = wi;
    *pdf = pdf_terms(hp, sin_o, cos_o, sin_i, cos_i, dphi, gamma_t, apdf);
    *f = lf_hair_f(hp, wo, wi);
    return *pdf > 0.f;
}

/* Eumelanin and pheomelanin absorption per unit concentration (Donner and
 * Jensen's values as pbrt-v4 takes them, RGB). */
lf_vec3 lf_hair_sigma_a_from_concentration(float ce, float cp)
{
    return lf_v3(ce * 0.419f + cp * 0.187f, ce * 0.697f + cp * 0.4f, ce * 1.37f + cp * 1.05f);
}

/* Chiang et al.'s inverse of the multiple-scattering colour: the sigma_a
 * that makes a fibre with azimuthal roughness beta_n look like colour c. */
lf_vec3 lf_hair_sigma_a_from_reflectance(lf_vec3 c, float beta_n)
{
    float d = 5.969f - 0.215f * beta_n + 2.532f * sqrf(beta_n) - 10.73f * powf(beta_n, 3.f) +
              5.574f * powf(beta_n, 4.f) + 0.245f * powf(beta_n, 5.f);
    float ch[3] = {c.x, c.y, c.z};
    for (int i = 0; i < 3; i++)
        ch[i] = sqrf(logf(fmaxf(ch[i], 1e-6f)) / d);
    return lf_v3(ch[0], ch[1], ch[2]);
}
