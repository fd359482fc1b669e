#include "lf_color.h"
#include "lf_file.h"

#include <pthread.h>
#include <stdlib.h>

#include <string.h>

/* One lobe of the Wyman-Sloan-Shirley fit: a Gaussian with a different
 * width on each side of its mean (JCGT 2(2) 2013, eq. 2). */
static double piecewise_gaussian(double x, double mean, double sigma_below, double sigma_above)
{
    double t = (x - mean) / (x < mean ? sigma_below : sigma_above);
    return exp(-0.5 * t * t);
}

void lf_cie_xyz_bar(double lambda_nm, double xyz[3])
{
    double l = lambda_nm;
    /* Multi-lobe fit, JCGT 2013 Table 1 (CIE 1931 2-degree observer). */
    xyz[0] = 1.056 * piecewise_gaussian(l, 599.8, 37.9, 31.0) + 0.362 * piecewise_gaussian(l, 442.0, 16.0, 26.7) -
             0.065 * piecewise_gaussian(l, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * piecewise_gaussian(l, 568.8, 46.9, 40.5) + 0.286 * piecewise_gaussian(l, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * piecewise_gaussian(l, 437.0, 11.8, 36.0) + 0.681 * piecewise_gaussian(l, 459.0, 26.0, 13.8);
}

lf_vec3 lf_xyz_to_linear_srgb(double X, double Y, double Z)
{
    /* sRGB (IEC 61966-2-1) primaries and D65 white; matrix as tabulated by
     * B. Lindbloom, "RGB/XYZ Matrices".  Its inverse's middle row is the
     * luminance weights (0.2126, 0.7152, 0.0722) used by lf_luminance. */
    double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
    double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
    double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
    return lf_v3((float)r, (float)g, (float)b);
}

double lf_planck(double lambda_nm, double temperature_k)
{
    if (temperature_k <= 0.0)
        return 0.0;
    const double c = 299792458.0;     /* speed of light, m/s */
    const double h = 6.62606957e-34;  /* Planck, J s */
    const double kb = 1.3806488e-23;  /* Boltzmann, J/K */
    double l = lambda_nm * 1e-9;
    return (2.0 * h * c * c) / (pow(l, 5.0) * (exp((h * c) / (l * kb * temperature_k)) - 1.0));
}

/* Integrates f(lambda) against the matching functions over 360-830 nm in
 * 1 nm steps (a Riemann sum: the fit is smooth, 1 nm is well below its
 * narrowest lobe). */
typedef double (*spectrum_fn)(double lambda_nm, const void *ctx);

static void integrate_xyz(spectrum_fn f, const void *ctx, double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    for (double l = LF_CIE_LAMBDA_MIN; l <= LF_CIE_LAMBDA_MAX; l += 1.0) {
        double s = f(l, ctx);
        if (s == 0.0)
            continue;
        double bar[3];
        lf_cie_xyz_bar(l, bar);
        for (int i = 0; i < 3; i++)
            xyz[i] += s * bar[i];
    }
}

static double blackbody_fn(double lambda_nm, const void *ctx)
{
    return lf_planck(lambda_nm, *(const double *)ctx);
}

static lf_vec3 xyz_to_rgb_unit_luminance(const double xyz[3])
{
    if (!(xyz[1] > 0.0))
        return lf_v3(0.f, 0.f, 0.f);
    return lf_xyz_to_linear_srgb(xyz[0] / xyz[1], 1.0, xyz[2] / xyz[1]);
}

lf_vec3 lf_blackbody_rgb(double temperature_k)
{
    if (!(temperature_k > 0.0))
        return lf_v3(0.f, 0.f, 0.f);
    double xyz[3];
    integrate_xyz(blackbody_fn, &temperature_k, xyz);
    return xyz_to_rgb_unit_luminance(xyz);
}

typedef struct pairs_ctx {
    const double *lambdas, *values;
    size_t n;
} pairs_ctx;

/* pbrt-v4 PiecewiseLinearSpectrum: linear between samples, 0 outside. */
static double pairs_fn(double lambda_nm, const void *vctx)
{
    const pairs_ctx *p = vctx;
    if (p->n == 0 || lambda_nm < p->lambdas[0] || lambda_nm > p->lambdas[p->n - 1])
        return 0.0;
    if (p->n == 1)
        return p->values[0];
    size_t lo = 0, hi = p->n - 1; /* binary search: lambdas[lo] <= l <= lambdas[hi] */
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (p->lambdas[mid] <= lambda_nm)
            lo = mid;
        else
            hi = mid;
    }
    double span = p->lambdas[hi] - p->lambdas[lo];
    double t = span > 0.0 ? (lambda_nm - p->lambdas[lo]) / span : 0.0;
    return p->values[lo] + t * (p->values[hi] - p->values[lo]);
}

static double one_fn(double lambda_nm, const void *ctx)
{
    (void)lambda_nm;
    (void)ctx;
    return 1.0;
}

lf_vec3 lf_spectrum_pairs_rgb(const double *lambdas, const double *values, size_t n, lf_spectrum_kind kind)
{
    pairs_ctx ctx = {lambdas, values, n};
    double xyz[3];
    integrate_xyz(pairs_fn, &ctx, xyz);
    if (kind == LF_SPECTRUM_ILLUMINANT)
        return xyz_to_rgb_unit_luminance(xyz);

    /* Reflectance under an equal-energy illuminant, white-balanced so the
     * perfect white reflector maps to (1,1,1); see lf_color.h. */
    double white[3];
    integrate_xyz(one_fn, NULL, white);
    lf_vec3 w = lf_xyz_to_linear_srgb(white[0], white[1], white[2]);
    lf_vec3 c = lf_xyz_to_linear_srgb(xyz[0], xyz[1], xyz[2]);
    c = lf_v3(c.x / w.x, c.y / w.y, c.z / w.z);
    if (kind == LF_SPECTRUM_ALBEDO)
        c = lf_v3(lf_clampf(c.x, 0.f, 1.f), lf_clampf(c.y, 0.f, 1.f), lf_clampf(c.z, 0.f, 1.f));
    return c;
}

/* CIE standard illuminant A: relative spectral power (CIE 15:2004 eq. 2.1). */
static double illum_a_fn(double lambda_nm, const void *ctx)
{
    (void)ctx;
    const double c2 = 1.435e7; /* nm K, the value that defines A */
    return 100.0 * pow(560.0 / lambda_nm, 5.0) * (exp(c2 / (2848.0 * 560.0)) - 1.0) /
           (exp(c2 / (2848.0 * lambda_nm)) - 1.0);
}

typedef struct named_spectrum {
    const char *name;
    float rgb[3];
} named_spectrum;

/* Conductors: eta and k reduced to RGB at roughly 650/550/450 nm.  Ag, Al,
 * Au, Cu, MgO and TiO2 are the values of Tungsten's ComplexIorData.hpp
 * (B. Bitterli; integrated from Mitsuba's tabulated Palik / Rakic data).
 * Brass (CuZn) is the widely circulated RGB triple for Querry's 1985 brass
 * measurements, which pbrt-v4's metal-CuZn spectra also tabulate.
 * Glasses: the Schott catalogue n_d (587.6 nm) of the glass pbrt-v4 tabulates
 * under that name; note that pbrt's "glass-F5/F10/F11" hold the dense flints
 * SF5, SF10 and SF11.  Dispersion is lost: a single index per glass. */
static const named_spectrum named_spectra[] = {
    {"metal-Ag-eta", {0.1552646f, 0.1167233f, 0.1383807f}},
    {"metal-Ag-k", {4.8283433f, 3.1222459f, 2.1469504f}},
    {"metal-Al-eta", {1.6574600f, 0.8803690f, 0.5212287f}},
    {"metal-Al-k", {9.2238692f, 6.2695232f, 4.8370012f}},
    {"metal-Au-eta", {0.1431190f, 0.3749570f, 1.4424786f}},
    {"metal-Au-k", {3.9831604f, 2.3857207f, 1.6032153f}},
    {"metal-Cu-eta", {0.2004377f, 0.9240334f, 1.1022120f}},
    {"metal-Cu-k", {3.9129485f, 2.4528477f, 2.1421880f}},
    {"metal-CuZn-eta", {0.444f, 0.527f, 1.094f}},
    {"metal-CuZn-k", {3.695f, 2.765f, 1.829f}},
    {"metal-MgO-eta", {2.0895886f, 1.6507225f, 1.5948760f}},
    {"metal-MgO-k", {0.f, 0.f, 0.f}},
    {"metal-TiO2-eta", {3.4566203f, 2.8017077f, 2.9051485f}},
    {"metal-TiO2-k", {0.0001027f, 0.f, 0.0006357f}}, /* Tungsten lists -0.00009 for green: absorption >= 0 */
    {"glass-BK7", {1.5168f, 1.5168f, 1.5168f}},
    {"glass-BAF10", {1.67003f, 1.67003f, 1.67003f}},
    {"glass-FK51A", {1.48656f, 1.48656f, 1.48656f}},
    {"glass-LASF9", {1.85025f, 1.85025f, 1.85025f}},
    {"glass-F5", {1.67270f, 1.67270f, 1.67270f}},   /* SF5 */
    {"glass-F10", {1.72825f, 1.72825f, 1.72825f}},  /* SF10 */
    {"glass-F11", {1.78472f, 1.78472f, 1.78472f}},  /* SF11 */
};

int lf_named_spectrum_rgb(const char *name, lf_vec3 *out)
{
    if (!name)
        return -1;
    for (size_t i = 0; i < sizeof named_spectra / sizeof named_spectra[0]; i++)
        if (strcmp(named_spectra[i].name, name) == 0) {
            *out = lf_v3(named_spectra[i].rgb[0], named_spectra[i].rgb[1], named_spectra[i].rgb[2]);
            return 0;
        }
    /* Standard illuminants.  Lights are normalised to luminance 1, so an
     * illuminant is fully described by its chromaticity: its RGB at Y = 1.
     * Illuminant A is CIE's Planckian formula (CIE 15:2004, S_A with
     * c2 = 1.435e-2 m K at 2848 K), integrated like any other spectrum; the
     * daylight and fluorescent illuminants use the CIE 1931 2-degree
     * chromaticities of their tabulated spectra (CIE 15:2004 tables T.3 and
     * T.8; ACES D60 as SMPTE ST 2065-1 defines it).  D65 is the sRGB white,
     * so it gives (1, 1, 1); A and the warm F lamps come out orange. */
    if (strcmp(name, "stdillum-A") == 0) {
        double xyz[3];
        integrate_xyz(illum_a_fn, NULL, xyz);
        *out = xyz_to_rgb_unit_luminance(xyz);
        return 0;
    }
    static const struct {
        const char *name;
        double x, y;
    } illuminants[] = {
        {"stdillum-D50", 0.34567, 0.35850}, {"stdillum-D65", 0.31272, 0.32903}, {"illum-acesD60", 0.32168, 0.33767},
        {"stdillum-F1", 0.31310, 0.33727},  {"stdillum-F2", 0.37208, 0.37529},  {"stdillum-F3", 0.40910, 0.39430},
        {"stdillum-F4", 0.44018, 0.40329},  {"stdillum-F5", 0.31379, 0.34531},  {"stdillum-F6", 0.37790, 0.38835},
        {"stdillum-F7", 0.31292, 0.32933},  {"stdillum-F8", 0.34588, 0.35875},  {"stdillum-F9", 0.37417, 0.37281},
        {"stdillum-F10", 0.34609, 0.35986}, {"stdillum-F11", 0.38052, 0.37713}, {"stdillum-F12", 0.43695, 0.40441},
    };
    for (size_t i = 0; i < sizeof illuminants / sizeof illuminants[0]; i++)
        if (strcmp(illuminants[i].name, name) == 0) {
            double x = illuminants[i].x, y = illuminants[i].y;
            lf_vec3 c = lf_xyz_to_linear_srgb(x / y, 1.0, (1.0 - x - y) / y);
            /* D65 is the sRGB white point: snap the 1e-4 rounding of the
             * published chromaticities so it is exactly white. */
            if (strcmp(name, "stdillum-D65") == 0)
                c = lf_v3(1.f, 1.f, 1.f);
            *out = c;
            return 0;
        }
    return -1;
}

static double wl_norm[3];
static pthread_once_t wl_once = PTHREAD_ONCE_INIT;

/* normalisation: the mean over the range of the RGB response */
static void wl_norm_init(void)
{
    double sum[3] = {0, 0, 0};
    int n = 0;
    for (double l = LF_LAMBDA_MIN; l <= LF_LAMBDA_MAX; l += 1.0, n++) {
        double xyz[3];
        lf_cie_xyz_bar(l, xyz);
        lf_vec3 c = lf_xyz_to_linear_srgb(xyz[0], xyz[1], xyz[2]);
        sum[0] += c.x, sum[1] += c.y, sum[2] += c.z;
    }
    for (int k = 0; k < 3; k++)
        wl_norm[k] = sum[k] / n;
}

lf_vec3 lf_wavelength_rgb_weight(double lambda_nm)
{
    pthread_once(&wl_once, wl_norm_init);
    double *norm = wl_norm;
    double xyz[3];
    lf_cie_xyz_bar(lambda_nm, xyz);
    lf_vec3 c = lf_xyz_to_linear_srgb(xyz[0], xyz[1], xyz[2]);
    return lf_v3((float)(c.x / norm[0]), (float)(c.y / norm[1]), (float)(c.z / norm[2]));
}

int lf_spectrum_file_read(const char *path, double **nums, size_t *n_pairs, lf_error *err)
{
    *nums = NULL;
    *n_pairs = 0;
    char *text;
    size_t len;
    /* Measured spectra have at most a few thousand samples; 64 MiB is far
     * beyond any real file and keeps a wrong path from eating memory. */
    int rc = lf_file_read(path, (size_t)64 << 20, &text, &len, NULL, err);
    if (rc)
        return rc;
    size_t n = 0, cap = 0;
    double *v = NULL;
    int line = 1;
    const char *p = text, *end = text + len;
    while (p < end) {
        char c = *p;
        if (c == '\n') {
            line++;
            p++;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == ',') {
            p++;
        } else if (c == '#') {
            while (p < end && *p != '\n')
                p++;
        } else {
            char *e;
            double x = strtod(p, &e);
            if (e == p || !isfinite(x) || (e < end && !strchr(" \t\r\n\f\v,#", *e))) {
                const char *w = p;
                while (w < end && !strchr(" \t\r\n\f\v,#", *w))
                    w++;
                rc = lf_error_at(err, LF_ERR_PARSE, &(lf_loc){path, line, 0},
                                 "spectrum file: expected a number, got \"%.*s\"", (int)((w - p) > 40 ? 40 : (w - p)), p);
                break;
            }
            if (n == cap) {
                cap = cap ? 2 * cap : 256;
                double *nv = realloc(v, cap * sizeof *nv);
                if (!nv) {
                    rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory", path);
                    break;
                }
                v = nv;
            }
            if (n % 2 == 0 && n >= 2 && !(x > v[n - 2])) {
                rc = lf_error_at(err, LF_ERR_PARSE, &(lf_loc){path, line, 0},
                                 "spectrum file: wavelengths must increase (%g after %g)", x, v[n - 2]);
                break;
            }
            v[n++] = x;
            p = e;
        }
    }
    free(text);
    if (!rc && (n < 2 || n % 2))
        rc = lf_error_set(err, LF_ERR_PARSE, "%s: spectrum file needs (wavelength, value) pairs, found %zu number%s",
                          path, n, n == 1 ? "" : "s");
    if (rc) {
        free(v);
        return rc;
    }
    *nums = v;
    *n_pairs = n / 2;
    return LF_OK;
}
