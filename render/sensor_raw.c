/* The image sensor behind the film: exposure -> photoelectrons -> noise ->
 * digital numbers (lf_sensor.h; formulas in docs/physics.md "Sensor",
 * the stages and their parameters in docs/sensor.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_color.h"
#include "base/lf_math.h"
#include "base/lf_parallel.h"
#include "render/lf_sensor.h"
#include "render/sensor_curves.h"

/* ---- radiometry ---- */

/* The spectral basis that turns the film's linear sRGB into spectral
 * radiance: three bands of a 6504 K black body (the white), blue
 * [360, 490), green [490, 590), red [590, 830] nm, scaled so that their sum
 * has pbrt-v4's luminance normalisation (int L ybar dlambda = CIE_Y_integral
 * for luminance 1).  A film RGB maps to band weights by T = P^-1 M (P: the
 * bands' XYZ, M: sRGB -> XYZ), so the spectrum has exactly the film's
 * colour (tristimulus values), though not the scene's spectrum (one RGB
 * triple cannot carry it). */
static const double band_edge[4] = {LF_CIE_LAMBDA_MIN, 490.0, 590.0, LF_CIE_LAMBDA_MAX};

static int band_of(double l)
{
    return l < band_edge[1] ? 2 : l < band_edge[2] ? 1 : 0; /* k: 0 red, 1 green, 2 blue */
}

static const double srgb_to_xyz[3][3] = {
    {0.4124564, 0.3575761, 0.1804375}, {0.2126729, 0.7151522, 0.0721750}, {0.0193339, 0.1191920, 0.9503041}};

/* The filter curve of colour c (0 R, 1 G, 2 B; 3 the monochrome sensor),
 * a quantum-efficiency shape: "cie1931" uses the CIE 1931 matching
 * functions xbar, ybar, zbar (each divided by its peak; ybar for
 * monochrome); a named camera's curves (render/sensor_curves.h) are
 * responses per unit energy, as pbrt-v4 uses them, so the QE shape is
 * rbar(lambda) / lambda over the largest such value of the three (the
 * channels keep the camera's balance; monochrome: green).  With it,
 * electrons are proportional to pbrt-v4's sensor RGB, int L rbar.
 * "ideal" is handled by the caller (its channels are the film's own). */
static double curve(const lf_camera_curves *cc, double peak, int c, double l)
{
    if (cc)
        return lf_camera_curve(cc, c == 3 ? 1 : c, l) / l / peak;
    double xyz[3];
    lf_cie_xyz_bar(l, xyz);
    static const double peak_cie[3] = {1.0622, 1.0, 1.7826}; /* the fit's maxima near 599, 556 and 446 nm */
    return c == 3 ? xyz[1] : xyz[c] / peak_cie[c];
}

/* The largest rbar / lambda of a camera's three curves, at 1 nm. */
static double curve_peak(const lf_camera_curves *cc)
{
    double m = 0;
    for (double l = LF_CIE_LAMBDA_MIN; cc && l <= LF_CIE_LAMBDA_MAX; l += 1.0)
        for (int c = 0; c < 3; c++)
            m = fmax(m, lf_camera_curve(cc, c, l) / l);
    return m;
}

/* Band weights per film RGB (T), photons of each band and the filters'
 * responses to each band, integrated at 1 nm. */
static int spectral_tables(const lf_camera_curves *cc, double T[3][3], double band_photons[3], double resp[4][3])
{
    double pk = curve_peak(cc);
    double norm = 0, P[3][3] = {{0}};
    for (double l = LF_CIE_LAMBDA_MIN; l <= LF_CIE_LAMBDA_MAX; l += 1.0) {
        double xyz[3];
        lf_cie_xyz_bar(l, xyz);
        norm += lf_planck(l, LF_SENSOR_WHITE_K) * xyz[1];
    }
    double scale = LF_CIE_Y_INTEGRAL / norm;
    memset(band_photons, 0, 3 * sizeof *band_photons);
    memset(resp, 0, 12 * sizeof **resp);
    for (double l = LF_CIE_LAMBDA_MIN; l <= LF_CIE_LAMBDA_MAX; l += 1.0) {
        double xyz[3], s = scale * lf_planck(l, LF_SENSOR_WHITE_K); /* W / (m^2 sr nm) per unit band weight */
        int k = band_of(l);
        lf_cie_xyz_bar(l, xyz);
        for (int i = 0; i < 3; i++)
            P[i][k] += s * xyz[i] / LF_CIE_Y_INTEGRAL;
        double photons = s * (l * 1e-9) / (LF_PLANCK_H * LF_LIGHT_C); /* per nm step */
        band_photons[k] += photons;
        for (int c = 0; c < 4; c++)
            resp[c][k] += photons * curve(cc, pk, c, l);
    }
    double Pi[3][3];
    if (lf_mat3_inverse(P, Pi))
        return -1;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            T[i][j] = 0;
            for (int k = 0; k < 3; k++)
                T[i][j] += Pi[i][k] * srgb_to_xyz[k][j];
        }
    return 0;
}

void lf_sensor_defaults(lf_sensor *s)
{
    memset(s, 0, sizeof *s);
    snprintf(s->curves, sizeof s->curves, "cie1931");
    s->cfa = LF_CFA_RGGB;
    s->qe = 0.5;
    s->fullwell = 20000;
    s->gain = 0.8;
    s->readnoise = 3;
    s->darkcurrent = 1;
    s->dsnu = 1;
    s->prnu = 0.005;
    s->blacklevel = 512;
    s->bits = 14;
    s->noise = 1;
    s->iso = 100;
    s->exposure_s = 1;
    s->pixel_pitch_m = 4e-6;
    s->full_width = 1;
}

int lf_sensor_prepare(lf_sensor *s, lf_error *err)
{
    const lf_camera_curves *cc = lf_camera_curves_find(s->curves);
    if (strcmp(s->curves, "cie1931") && strcmp(s->curves, "ideal") && !cc)
        return lf_error_set(err, LF_ERR_PARAM, "Film \"raw\": unknown \"sensor\" \"%s\"", s->curves);
    if (!(s->qe > 0 && s->qe <= 1) || !(s->fullwell > 0) || !(s->gain > 0) || !(s->readnoise >= 0) ||
        !(s->darkcurrent >= 0) || !(s->dsnu >= 0) || !(s->prnu >= 0 && s->prnu < 1) || !(s->blacklevel >= 0) ||
        s->bits < 1 || s->bits > 16 || !(s->iso > 0) || !(s->exposure_s >= 0) || !(s->pixel_pitch_m > 0) ||
        !isfinite(s->fullwell + s->gain + s->readnoise + s->darkcurrent + s->dsnu + s->blacklevel + s->pixel_pitch_m))
        return lf_error_set(err, LF_ERR_PARAM,
                            "Film \"raw\": needs 0 < qe <= 1, fullwell > 0, gain > 0, readnoise, darkcurrent, dsnu, "
                            "blacklevel >= 0, 0 <= prnu < 1, 1 <= bits <= 16 (got qe %g fullwell %g gain %g "
                            "readnoise %g darkcurrent %g dsnu %g prnu %g blacklevel %g bits %d)",
                            s->qe, s->fullwell, s->gain, s->readnoise, s->darkcurrent, s->dsnu, s->prnu, s->blacklevel,
                            s->bits);
    if (s->blacklevel >= ldexp(1.0, s->bits) - 1)
        return lf_error_set(err, LF_ERR_PARAM, "Film \"raw\": \"blacklevel\" %g leaves no room in %d bits",
                            s->blacklevel, s->bits);
    double T[3][3], bp[3], resp[4][3];
    if (spectral_tables(cc, T, bp, resp))
        return lf_error_set(err, LF_ERR_INTERNAL, "sensor: singular spectral basis");
    /* electrons per film unit: pixel area x qe x photons / (ISO/100), the
     * film holding exposure x ISO/100 */
    double area = s->pixel_pitch_m * s->pixel_pitch_m, f = area * s->qe / (s->iso / 100.0);
    int ideal = !strcmp(s->curves, "ideal");
    for (int k = 0; k < 3; k++) {
        s->photons_per_unit[k] = 0;
        for (int j = 0; j < 3; j++)
            s->photons_per_unit[k] += bp[j] * T[j][k];
    }
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            double r = 0;
            int row = s->cfa == LF_CFA_NONE ? 3 : c;
            for (int j = 0; j < 3; j++)
                r += resp[row][j] * T[j][k];
            if (ideal) /* the film's own channel, or all of them for a monochrome sensor */
                r = (s->cfa == LF_CFA_NONE || c == k) ? s->photons_per_unit[k] : 0.0;
            s->e_per_unit[c][k] = f * r;
        }
    return 0;
}

int lf_sensor_film_matrix(const char *curves, double white_k, float out[3][3], lf_error *err)
{
    const lf_camera_curves *cc = lf_camera_curves_find(curves);
    double T[3][3], bp[3], resp[4][3], F[3][3], Mi[3][3];
    if (!cc)
        return lf_error_set(err, LF_ERR_PARAM, "unknown camera curves \"%s\"", curves ? curves : "");
    if (spectral_tables(cc, T, bp, resp) || lf_camera_xyz_fit(cc, white_k, F) || lf_mat3_inverse(srgb_to_xyz, Mi))
        return lf_error_set(err, LF_ERR_INTERNAL, "sensor \"%s\": singular colour fit", curves);
    /* the photon-weighted responses back to energy: pbrt-v4's sensor RGB,
     * int L rbar dlambda / CIE_Y_integral, per unit band weight */
    double to_energy = LF_PLANCK_H * LF_LIGHT_C * curve_peak(cc) / 1e-9 / LF_CIE_Y_INTEGRAL;
    double cam[3][3], xyz[3][3];
    for (int c = 0; c < 3; c++) /* sensor RGB per film RGB */
        for (int k = 0; k < 3; k++) {
            cam[c][k] = 0;
            for (int j = 0; j < 3; j++)
                cam[c][k] += resp[c][j] * to_energy * T[j][k];
        }
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            xyz[i][k] = 0;
            for (int c = 0; c < 3; c++)
                xyz[i][k] += F[i][c] * cam[c][k];
        }
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double v = 0;
            for (int j = 0; j < 3; j++)
                v += Mi[i][j] * xyz[j][k];
            out[i][k] = (float)v;
        }
    return 0;
}

/* ---- counter-based random numbers ---- */

static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

typedef struct stream {
    uint64_t base, n;
} stream;

static stream stream_at(uint64_t key, uint64_t pixel)
{
    return (stream){mix64(key ^ mix64(pixel)), 0};
}

static double next_uniform(stream *st) /* in (0, 1) */
{
    return ((double)(mix64(st->base + st->n++) >> 11) + 0.5) * 0x1p-53;
}

double lf_sensor_uniform(uint64_t key, uint64_t pixel, uint64_t n)
{
    stream st = stream_at(key, pixel);
    st.n = n;
    return next_uniform(&st);
}

static double next_gauss(stream *st) /* Box-Muller, one of the pair */
{
    double u1 = next_uniform(st), u2 = next_uniform(st);
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* Poisson(mu): products of uniforms for small means; above 10 the
 * transformed rejection with squeeze of Hoermann, "The transformed
 * rejection method for generating Poisson random variables" (1993), PTRS. */
static double next_poisson(stream *st, double mu)
{
    if (!(mu > 0))
        return 0;
    if (mu < 10) {
        double l = exp(-mu), p = 1;
        int k = 0;
        do {
            k++;
            p *= next_uniform(st);
        } while (p > l);
        return k - 1;
    }
    double smu = sqrt(mu), lmu = log(mu);
    double b = 0.931 + 2.53 * smu, a = -0.059 + 0.02483 * b;
    double inv_alpha = 1.1239 + 1.1328 / (b - 3.4), vr = 0.9277 - 3.6224 / (b - 2);
    for (;;) {
        double u = next_uniform(st) - 0.5, v = next_uniform(st);
        double us = 0.5 - fabs(u);
        double k = floor((2 * a / us + b) * u + mu + 0.43);
        if (us >= 0.07 && v <= vr)
            return k;
        if (k < 0 || (us < 0.013 && v > us))
            continue;
        if (log(v) + log(inv_alpha) - log(a / (us * us) + b) <= -mu + k * lmu - lgamma(k + 1))
            return k;
    }
}

/* ---- the exposure ---- */

#define FPN_KEY 0x5eb50f1e0d5ea5e1ull /* the fixed patterns: one sensor for every frame */

double lf_sensor_white_level(const lf_sensor *s)
{
    double top = ldexp(1.0, s->bits) - 1;
    double sat = floor(s->fullwell * s->gain * s->iso / 100.0 + s->blacklevel + 0.5);
    return sat < top ? sat : top;
}

/* One site: mean electrons -> DN (the stages of lf_sensor.h). */
static float site_dn(const lf_sensor *s, double mu_e, uint64_t pixel, uint64_t temporal_key, double top)
{
    double e;
    if (s->noise) {
        /* the fixed patterns' draws have fixed places in the pixel's stream
         * (PRNU first, DSNU second), drawn only when asked for */
        stream fpn = stream_at(FPN_KEY, pixel);
        if (s->prnu > 0)
            mu_e *= fmax(0.0, 1.0 + s->prnu * next_gauss(&fpn));
        stream tmp = stream_at(temporal_key, pixel);
        e = next_poisson(&tmp, mu_e + s->darkcurrent * s->exposure_s);
        if (s->dsnu > 0) {
            fpn.n = 2;
            e += s->dsnu * next_gauss(&fpn);
        }
        e = fmin(fmax(e, 0.0), s->fullwell);
        if (s->readnoise > 0)
            e += s->readnoise * next_gauss(&tmp);
    } else {
        e = fmin(mu_e + s->darkcurrent * s->exposure_s, s->fullwell);
    }
    double dn = floor(e * s->gain * s->iso / 100.0 + s->blacklevel + 0.5);
    return (float)(dn < 0 ? 0 : dn > top ? top : dn);
}

typedef struct expose_job {
    const lf_sensor *s;
    const lf_image *film;
    lf_image *raw;
    int x0, y0;
    uint64_t temporal_key;
    double top;
} expose_job;

/* Rows [y0, y1): every site's value depends on its pixel alone, so rows can
 * run on any thread in any order. */
static void expose_rows(void *ctx, int y_begin, int y_end, int tid)
{
    (void)tid;
    const expose_job *j = ctx;
    const lf_sensor *s = j->s;
    for (int y = y_begin; y < y_end; y++) {
        int gy = y + j->y0;
        for (int x = 0; x < j->film->width; x++) {
            int gx = x + j->x0;
            const float *v = lf_image_px(j->film, x, y);
            const double *row = s->e_per_unit[lf_cfa_color(s->cfa, gx, gy)];
            double mu = row[0] * v[0] + row[1] * v[1] + row[2] * v[2];
            if (!(mu > 0)) /* out-of-gamut colours can ask for negative light; NaN
                              never reaches here */
                mu = 0;
            uint64_t pixel = (uint64_t)gy * (uint64_t)s->full_width + (uint64_t)gx;
            j->raw->data[(size_t)y * j->raw->width + x] = site_dn(s, mu, pixel, j->temporal_key, j->top);
        }
    }
}

int lf_sensor_expose(const lf_sensor *s, const lf_image *film, int x0, int y0, lf_image *raw, lf_error *err)
{
    if (film->channels < 3)
        return lf_error_set(err, LF_ERR_PARAM, "sensor: the film needs 3 channels, got %d", film->channels);
    if (lf_image_alloc(raw, film->width, film->height, 1, err))
        return err->code;
    expose_job j = {s, film, raw, x0, y0, mix64(0x7e3a0a11c0ffee5ull ^ (uint64_t)s->seed), ldexp(1.0, s->bits) - 1};
    lf_parallel_for(film->height, 0, 8, expose_rows, &j);
    return 0;
}

/* A named camera's ColorMatrix1 (XYZ -> camera, CalibrationIlluminant1
 * D65): the inverse of the least-squares fit under D65
 * (lf_camera_xyz_fit), scaled so that D65 white (Y = 1) gives a camera
 * neutral whose largest component is 1.  Electrons are proportional to the
 * fit's camera RGB (curve() above), so the scale is the only freedom. */
static void named_color_matrix(const lf_sensor *s, lf_raw_info *ri)
{
    const lf_camera_curves *cc = lf_camera_curves_find(s->curves);
    double F[3][3], Fi[3][3], w[3] = {0}, wmax = 0;
    if (!cc || s->cfa == LF_CFA_NONE || lf_camera_xyz_fit(cc, 6500.0, F) || lf_mat3_inverse(F, Fi))
        return;
    for (int c = 0; c < 3; c++) {
        for (int k = 0; k < 3; k++)
            w[c] += Fi[c][k] * (srgb_to_xyz[k][0] + srgb_to_xyz[k][1] + srgb_to_xyz[k][2]);
        wmax = fmax(wmax, w[c]);
    }
    if (!(wmax > 0))
        return;
    for (int c = 0; c < 3; c++)
        for (int j = 0; j < 3; j++)
            ri->color_matrix[3 * c + j] = Fi[c][j] / wmax;
}

void lf_sensor_raw_info(const lf_sensor *s, lf_raw_info *ri)
{
    memset(ri, 0, sizeof *ri);
    ri->cfa = s->cfa;
    ri->black_level = s->blacklevel;
    ri->white_level = lf_sensor_white_level(s);
    /* camera from XYZ = C M^-1, C the electrons per film unit; scaled so
     * that the film's white (XYZ = M 1) gives AsShotNeutral, largest 1 */
    double C[3][3], Mi[3][3], n[3], nmax = 0;
    memcpy(C, s->e_per_unit, sizeof C);
    if (s->cfa == LF_CFA_NONE)
        for (int c = 0; c < 3; c++)
            memcpy(C[c], s->e_per_unit[1], sizeof C[c]);
    lf_mat3_inverse(srgb_to_xyz, Mi);
    for (int c = 0; c < 3; c++) {
        n[c] = C[c][0] + C[c][1] + C[c][2];
        nmax = fmax(nmax, n[c]);
    }
    for (int c = 0; c < 3; c++) {
        ri->as_shot_neutral[c] = n[c] / nmax;
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int k = 0; k < 3; k++)
                v += C[c][k] * Mi[k][j];
            ri->color_matrix[3 * c + j] = v / nmax;
        }
    }
    named_color_matrix(s, ri);
    ri->dn_per_unit = nmax * s->gain * s->iso / 100.0;
    ri->iso = s->iso, ri->exposure_s = s->exposure_s;
}

/* ---- parameters, attributes, explanation ---- */

int lf_sensor_read_params(lf_sensor *s, lf_paramset *ps, const char *where, lf_error *err)
{
    const char *cfa = lf_params_string(ps, "cfa", lf_cfa_name(s->cfa));
    if (lf_cfa_parse(cfa, &s->cfa))
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: \"cfa\" must be \"rggb\", \"bggr\", \"grbg\", "
                            "\"gbrg\" or \"none\", got \"%s\"",
                            where, cfa);
    s->qe = lf_params_float(ps, "qe", s->qe);
    s->fullwell = lf_params_float(ps, "fullwell", s->fullwell);
    s->gain = lf_params_float(ps, "gain", s->gain);
    s->readnoise = lf_params_float(ps, "readnoise", s->readnoise);
    s->darkcurrent = lf_params_float(ps, "darkcurrent", s->darkcurrent);
    s->dsnu = lf_params_float(ps, "dsnu", s->dsnu);
    s->prnu = lf_params_float(ps, "prnu", s->prnu);
    s->blacklevel = lf_params_float(ps, "blacklevel", s->blacklevel);
    s->bits = lf_params_int(ps, "bits", s->bits);
    s->noise = lf_params_bool(ps, "noise", s->noise);
    lf_error e = {0};
    if (lf_sensor_prepare(s, &e))
        return lf_error_set(err, e.code, "%s: %s", where, e.msg);
    return 0;
}

#define K(name) LF_KEY_SENSOR_PREFIX name

int lf_sensor_to_attrs(const lf_sensor *s, lf_attrs *a, lf_error *err)
{
    int rc =
        lf_attrs_set_string(a, LF_KEY_FILM, "raw", err) | lf_attrs_set_string(a, K("curves"), s->curves, err) |
        lf_attrs_set_string(a, K("cfa"), lf_cfa_name(s->cfa), err) | lf_attrs_set_double(a, K("qe"), s->qe, err) |
        lf_attrs_set_double(a, K("fullwell"), s->fullwell, err) | lf_attrs_set_double(a, K("gain"), s->gain, err) |
        lf_attrs_set_double(a, K("readnoise"), s->readnoise, err) |
        lf_attrs_set_double(a, K("darkcurrent"), s->darkcurrent, err) |
        lf_attrs_set_double(a, K("dsnu"), s->dsnu, err) | lf_attrs_set_double(a, K("prnu"), s->prnu, err) |
        lf_attrs_set_double(a, K("blacklevel"), s->blacklevel, err) | lf_attrs_set_int(a, K("bits"), s->bits, err) |
        lf_attrs_set_int(a, K("noise"), s->noise, err) | lf_attrs_set_double(a, K("iso"), s->iso, err) |
        lf_attrs_set_double(a, K("exposure_s"), s->exposure_s, err) |
        lf_attrs_set_double(a, K("pixel_pitch_m"), s->pixel_pitch_m, err) |
        lf_attrs_set_int(a, K("seed"), (int)s->seed, err) | lf_attrs_set_int(a, K("full_width"), s->full_width, err);
    return rc ? (err && err->code ? err->code : LF_ERR_NOMEM) : 0;
}

static int attr_num(const lf_attrs *a, const char *name, double *out)
{
    const lf_attr *x = lf_attrs_get(a, name);
    if (!x)
        return -1;
    if (x->type == LF_ATTR_INT)
        *out = x->i;
    else if (x->type == LF_ATTR_DOUBLE || x->type == LF_ATTR_FLOAT)
        *out = x->d;
    else
        return -1;
    return 0;
}

int lf_sensor_from_attrs(const lf_attrs *a, lf_sensor *s, lf_error *err)
{
    const lf_attr *film = lf_attrs_get(a, LF_KEY_FILM);
    if (!film || film->type != LF_ATTR_STRING || strcmp(film->s, "raw"))
        return -1;
    lf_sensor_defaults(s);
    const lf_attr *cv = lf_attrs_get(a, K("curves")), *cfa = lf_attrs_get(a, K("cfa"));
    double v[15];
    static const char *const names[15] = {
        K("qe"),   K("fullwell"),   K("gain"),          K("readnoise"), K("darkcurrent"),
        K("dsnu"), K("prnu"),       K("blacklevel"),    K("bits"),      K("noise"),
        K("iso"),  K("exposure_s"), K("pixel_pitch_m"), K("seed"),      K("full_width")};
    int bad = !cv || cv->type != LF_ATTR_STRING || !cfa || cfa->type != LF_ATTR_STRING || lf_cfa_parse(cfa->s, &s->cfa);
    for (int i = 0; i < 15 && !bad; i++)
        bad = attr_num(a, names[i], &v[i]);
    if (bad)
        return lf_error_set(err, LF_ERR_PARAM, "the raw film's lensfield:sensor:* attributes are incomplete");
    snprintf(s->curves, sizeof s->curves, "%s", cv->s);
    s->qe = v[0], s->fullwell = v[1], s->gain = v[2], s->readnoise = v[3], s->darkcurrent = v[4], s->dsnu = v[5];
    s->prnu = v[6], s->blacklevel = v[7], s->bits = (int)v[8], s->noise = (int)v[9], s->iso = v[10];
    s->exposure_s = v[11], s->pixel_pitch_m = v[12], s->seed = (uint32_t)(int)v[13], s->full_width = (int)v[14];
    return lf_sensor_prepare(s, err);
}

void lf_sensor_explain(const lf_sensor *s, lf_strbuf *b)
{
    double K = s->gain * s->iso / 100.0;
    lf_strbuf_printf(b, "sensor (Film \"raw\"): %s curves, CFA %s, pixel pitch %.4g um, qe %g\n", s->curves,
                     lf_cfa_name(s->cfa), s->pixel_pitch_m * 1e6, s->qe);
    lf_strbuf_printf(b,
                     "  electrons per film unit (R,G,B film -> site R,G,B): [%.4g %.4g %.4g] "
                     "[%.4g %.4g %.4g] "
                     "[%.4g %.4g %.4g]\n",
                     s->e_per_unit[0][0], s->e_per_unit[0][1], s->e_per_unit[0][2], s->e_per_unit[1][0],
                     s->e_per_unit[1][1], s->e_per_unit[1][2], s->e_per_unit[2][0], s->e_per_unit[2][1],
                     s->e_per_unit[2][2]);
    if (!s->noise)
        lf_strbuf_printf(b, "  noise: off (\"noise\" false: the noiseless mean, nothing drawn)\n");
    else {
        lf_strbuf_printf(b, "  PRNU: %s\n", s->prnu > 0 ? "on (fixed gain pattern)" : "off (prnu 0)");
        lf_strbuf_printf(b, "  shot noise: on (Poisson on signal%s)\n", s->darkcurrent > 0 ? " + dark current" : "");
        lf_strbuf_printf(b, "  DSNU: %s\n", s->dsnu > 0 ? "on (fixed offset pattern)" : "off (dsnu 0)");
        lf_strbuf_printf(b, "  read noise: %s\n", s->readnoise > 0 ? "on (Gaussian)" : "off (readnoise 0)");
    }
    lf_strbuf_printf(b, "  dark current: %s (%g e-/s x %g s)\n", s->darkcurrent > 0 ? "on" : "off", s->darkcurrent,
                     s->exposure_s);
    lf_strbuf_printf(b,
                     "  full well %g e-, conversion gain %g DN/e- (gain %g x ISO "
                     "%g/100), black level %g DN, "
                     "%d-bit converter, white level %g DN\n",
                     s->fullwell, K, s->gain, s->iso, s->blacklevel, s->bits, lf_sensor_white_level(s));
}
