/* EMVA 1288 photon-transfer test of Film "raw" (docs/sensor.md): flat-field
 * renders at 52 exposure times, two frames each (two Sampler seeds: the
 * temporal noise differs, the fixed patterns do not), dark frames at each
 * time, and the standard's figures computed as the standard computes them
 * (EMVA 1288 Release 3.1, sections 6.3-6.6 and 8):
 *   mean        mu_y = 1/(2N) sum (y_A + y_B)
 *   variance    sigma_y^2 = 1/(2N) sum ((y_A - mu_A) - (y_B - mu_B))^2
 *   gain K      slope of sigma_y^2 - sigma_y.dark^2 against mu_y - mu_y.dark
 *               over 0..70 % of saturation (least squares through the origin)
 *   saturation  the exposure of the largest variance; mu_e.sat = (mu_y - mu_y.dark) / K
 *   read noise  sigma_d = sqrt(sigma_y.dark^2(t -> 0) - 1/12) / K (the dark
 *               variance extrapolated to zero time: dark current adds shot noise)
 *   linearity   mu_y - mu_y.dark against exposure, fitted through the origin
 *               over 5..95 % of saturation; the largest relative deviation
 *               below 90 % of saturation.
 * Expected values come from the parameters: K = gain x ISO/100, read noise,
 * full well, dark current.  Noise margins: 128 x 128 pixels per frame, so a
 * variance carries about sqrt(2/16384) = 1.1 % noise; K is fitted over 12
 * points (about 0.4 %); read noise to 1 %; the saturation point is bracketed
 * by exposure steps of 0.6 % of the full well, whose shot noise (0.4 %)
 * puts the largest variance about two of its sigma below the well. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_sensor.h"

enum { W = 128, H = 128, N_LOW = 12, N_HIGH = 40, N_T = N_LOW + N_HIGH };

static const double GAIN = 0.2, ISO = 400, FULLWELL = 60000, READNOISE = 6, DARK = 2, DSNU = 2, PRNU = 0.002;

/* A flat field: the pinhole sees a uniform environment of radiance L, so the
 * film is exactly L x t x ISO/100 everywhere. */
static int frame(double t, unsigned seed, lf_image *raw, lf_sensor *sensor_out)
{
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"perspective\" \"float fov\" [40] \"float shutteropen\" [0] \"float shutterclose\" [%.17g]\n"
             "Film \"raw\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"float diagonal\" [0.5]\n"
             "  \"string sensor\" \"ideal\" \"string cfa\" \"none\" \"float qe\" [0.6] \"float iso\" [%g]\n"
             "  \"float gain\" [%g] \"float fullwell\" [%g] \"float readnoise\" [%g] \"float darkcurrent\" [%g]\n"
             "  \"float dsnu\" [%g] \"float prnu\" [%g] \"float blacklevel\" [256] \"integer bits\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [1]\n"
             "WorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [1e-7 1e-7 1e-7]\n",
             t, W, H, ISO, GAIN, FULLWELL, READNOISE, DARK, DSNU, PRNU);
    lf_image film;
    lf_attrs meta = {0};
    char msg[1024];
    int rc = render_text(scene, &(lf_test_scene){.seed = seed, .has_seed = 1, .meta = &meta}, &film, msg, sizeof msg);
    if (rc) {
        fprintf(stderr, "render: %s\n", msg);
        return rc;
    }
    lf_sensor s;
    lf_error err = {0};
    rc = lf_sensor_from_attrs(&meta, &s, &err);
    if (!rc)
        rc = lf_sensor_expose(&s, &film, 0, 0, raw, &err);
    if (!rc && sensor_out)
        *sensor_out = s;
    lf_image_free(&film);
    lf_attrs_free(&meta);
    return rc;
}

/* A dark frame: the same sensor with the light blocked (a zero film). */
static int dark_frame(const lf_sensor *s, unsigned seed, lf_image *raw)
{
    lf_image zero;
    lf_error err = {0};
    if (lf_image_alloc(&zero, W, H, 3, &err))
        return 1;
    lf_sensor d = *s;
    d.seed = seed;
    int rc = lf_sensor_expose(&d, &zero, 0, 0, raw, &err);
    lf_image_free(&zero);
    return rc;
}

/* The standard's mean and temporal variance of a pair of frames. */
static void pair_stats(const lf_image *a, const lf_image *b, double *mean, double *var)
{
    size_t n = (size_t)W * H;
    double ma = 0, mb = 0, v = 0;
    for (size_t i = 0; i < n; i++)
        ma += a->data[i], mb += b->data[i];
    ma /= n, mb /= n;
    for (size_t i = 0; i < n; i++) {
        double d = (a->data[i] - ma) - (b->data[i] - mb);
        v += d * d;
    }
    *mean = 0.5 * (ma + mb);
    *var = v / (2.0 * n);
}

int main(void)
{
    /* exposure time that fills the well: electrons per second from the
     * sensor's own photon table is what the flat-field test checks; here the
     * times only need to span 0..105 % of it */
    lf_image a, b;
    lf_sensor s;
    if (frame(1.0, 1, &a, &s)) {
        CHECK(0);
        return lf_test_end();
    }
    lf_image_free(&a);
    double film_unit = 1e-7 * ISO / 100; /* film value per second */
    double e_per_s = (s.e_per_unit[1][0] + s.e_per_unit[1][1] + s.e_per_unit[1][2]) * film_unit + DARK;
    double t_sat = FULLWELL / e_per_s;
    double t[N_T], mu[N_T], var[N_T], mu_d[N_T], var_d[N_T];
    for (int i = 0; i < N_T; i++)
        t[i] = i < N_LOW ? t_sat * 0.7 * (i + 1) / N_LOW : t_sat * (0.8 + 0.25 * (i - N_LOW) / (N_HIGH - 1));
    int ok = 1;
    for (int i = 0; i < N_T && ok; i++) {
        lf_sensor si;
        ok = !frame(t[i], 11, &a, &si) && !frame(t[i], 12, &b, NULL);
        if (ok) {
            pair_stats(&a, &b, &mu[i], &var[i]);
            lf_image_free(&a), lf_image_free(&b);
            ok = !dark_frame(&si, 21, &a) && !dark_frame(&si, 22, &b);
        }
        if (ok) {
            pair_stats(&a, &b, &mu_d[i], &var_d[i]);
            lf_image_free(&a), lf_image_free(&b);
        }
    }
    CHECK(ok);
    if (!ok)
        return lf_test_end();
    double K_expected = GAIN * ISO / 100;
    /* saturation: the exposure of the largest variance */
    int isat = 0;
    for (int i = 1; i < N_T; i++)
        if (var[i] > var[isat])
            isat = i;
    double mu_y_sat = mu[isat] - mu_d[isat];
    if (getenv("LF_EMVA_DUMP"))
        for (int i = 0; i < N_T; i++)
            printf("t %g mu %g var %g\n", t[i], mu[i] - mu_d[i], var[i] - var_d[i]);
    /* K: slope through the origin over 0..70 % of saturation */
    double sxy = 0, sxx = 0;
    for (int i = 0; i < N_T; i++) {
        double x = mu[i] - mu_d[i], y = var[i] - var_d[i];
        if (x <= 0.7 * mu_y_sat)
            sxy += x * y, sxx += x * x;
    }
    double K = sxy / sxx;
    printf("EMVA 1288: K = %.5f DN/e- (expected %.5f, %+.2f %%)\n", K, K_expected, 100 * (K / K_expected - 1));
    CHECK_MSG(fabs(K / K_expected - 1) < 0.02, "K %g vs %g", K, K_expected);
    /* saturation capacity */
    double mu_e_sat = mu_y_sat / K;
    double dark_e = DARK * t[isat];
    printf("EMVA 1288: saturation capacity %.1f e- (full well %g minus dark %.1f e-: %+.2f %%)\n", mu_e_sat,
           FULLWELL, dark_e, 100 * (mu_e_sat / (FULLWELL - dark_e) - 1));
    CHECK_MSG(fabs(mu_e_sat / (FULLWELL - dark_e) - 1) < 0.02, "saturation %g e- vs %g", mu_e_sat, FULLWELL - dark_e);
    /* read noise: dark variance extrapolated to t = 0 (linear fit in t) */
    double st = 0, sv = 0, stt = 0, stv = 0;
    for (int i = 0; i < N_T; i++)
        st += t[i], sv += var_d[i], stt += t[i] * t[i], stv += t[i] * var_d[i];
    double slope = (N_T * stv - st * sv) / (N_T * stt - st * st), var0 = (sv - slope * st) / N_T;
    double sigma_d = sqrt(var0 - 1.0 / 12.0) / K;
    printf("EMVA 1288: read noise %.3f e- (expected %g, %+.2f %%); dark-current variance %.2f e-/s (expected %g)\n",
           sigma_d, READNOISE, 100 * (sigma_d / READNOISE - 1), slope / (K * K), DARK);
    CHECK_MSG(fabs(sigma_d / READNOISE - 1) < 0.05, "read noise %g vs %g", sigma_d, READNOISE);
    CHECK_MSG(fabs(slope / (K * K) / DARK - 1) < 0.1, "dark variance slope %g vs %g", slope / (K * K), DARK);
    /* dark signal linear in time: mu_y.dark = black + K (dark current t) */
    double maxdev = 0;
    for (int i = 0; i < N_T; i++) {
        double expect = 256 + K_expected * DARK * t[i];
        maxdev = fmax(maxdev, fabs(mu_d[i] - expect));
    }
    printf("EMVA 1288: dark signal vs black + K x dark current x t: largest deviation %.3f DN\n", maxdev);
    CHECK_MSG(maxdev < 0.5, "dark signal deviates by %g DN", maxdev);
    /* linearity: fit through the origin over 5..95 % of saturation */
    double sxh = 0, shh = 0;
    for (int i = 0; i < N_T; i++) {
        double y = mu[i] - mu_d[i];
        if (y >= 0.05 * mu_y_sat && y <= 0.95 * mu_y_sat)
            sxh += t[i] * y, shh += t[i] * t[i];
    }
    double a_fit = sxh / shh, le = 0;
    for (int i = 0; i < N_T; i++) {
        double y = mu[i] - mu_d[i];
        if (y >= 0.05 * mu_y_sat && y <= 0.9 * mu_y_sat)
            le = fmax(le, fabs(y - a_fit * t[i]) / (a_fit * t[i]));
    }
    printf("EMVA 1288: non-linearity %.3f %% below 90 %% of saturation\n", 100 * le);
    CHECK_MSG(le < 0.01, "non-linearity %g", le);
    return lf_test_end();
}
