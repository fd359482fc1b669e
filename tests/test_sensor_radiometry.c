/* Film "raw" radiometry and colour filters against docs/physics.md "Sensor":
 *  - a flat field of known radiance gives the mean electron count of the
 *    formula  N_e = A_pix qe t int L(lambda) S(lambda) lambda / (h c) dlambda,
 *    L(lambda) the film RGB's spectrum in the fixed basis (computed here from
 *    Planck's law and the CIE 1931 fit, not from the sensor's tables), within
 *    1 % with every noise term on and 0.1 % without;
 *  - a scene of one primary fills only its CFA sites with the "ideal" sensor;
 *  - nothing is drawn when a term is zero, and --explain says so;
 *  - frames differ by seed only in their temporal noise;
 *  - Film "rgb" "whitebalance" neutralises its illuminant (pbrt-v4). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_color.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_sensor.h"

enum { W = 64, H = 48 };

static int shoot(const char *sensor_params, const char *rgb, double t, unsigned seed, lf_image *raw, lf_sensor *s,
                 char **explain)
{
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"perspective\" \"float fov\" [40] \"float shutteropen\" [0] \"float shutterclose\" [%.17g]\n"
             "Film \"raw\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"float diagonal\" [0.4]\n"
             "  %s\n"
             "Sampler \"independent\" \"integer pixelsamples\" [1]\n"
             "WorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [%s]\n",
             t, W, H, sensor_params, rgb);
    lf_image film;
    lf_attrs meta = {0};
    char msg[1024];
    int rc = render_text(scene, &(lf_test_scene){.seed = seed, .has_seed = 1, .meta = &meta, .explain = explain},
                         &film, msg, sizeof msg);
    if (rc) {
        fprintf(stderr, "render: %s\n", msg);
        return rc;
    }
    lf_error err = {0};
    rc = lf_sensor_from_attrs(&meta, s, &err);
    if (!rc)
        rc = lf_sensor_expose(s, &film, 0, 0, raw, &err);
    if (rc)
        fprintf(stderr, "sensor: %s\n", err.msg);
    lf_image_free(&film);
    lf_attrs_free(&meta);
    return rc;
}

/* docs/physics.md "Sensor": photons per m^2 of the spectrum of film RGB rgb
 * (per second of exposure), weighted by curve (NULL: 1). */
static double photons(const double rgb[3], double (*curve)(double))
{
    static const double M[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                   {0.2126729, 0.7151522, 0.0721750},
                                   {0.0193339, 0.1191920, 0.9503041}};
    double norm = 0, P[3][3] = {{0}};
    for (double l = 360; l <= 830; l += 1) {
        double b[3];
        lf_cie_xyz_bar(l, b);
        norm += lf_planck(l, 6504) * b[1];
    }
    double scale = 106.856895 / norm;
    for (double l = 360; l <= 830; l += 1) {
        double b[3];
        lf_cie_xyz_bar(l, b);
        int k = l < 490 ? 2 : l < 590 ? 1 : 0;
        for (int i = 0; i < 3; i++)
            P[i][k] += scale * lf_planck(l, 6504) * b[i] / 106.856895;
    }
    /* band weights c solve P c = M rgb (Cramer's rule) */
    double xyz[3], c[3];
    for (int i = 0; i < 3; i++)
        xyz[i] = M[i][0] * rgb[0] + M[i][1] * rgb[1] + M[i][2] * rgb[2];
#define DET(a) (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) + \
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    double d = DET(P);
    for (int k = 0; k < 3; k++) {
        double Q[3][3];
        memcpy(Q, P, sizeof Q);
        for (int i = 0; i < 3; i++)
            Q[i][k] = xyz[i];
        c[k] = DET(Q) / d;
    }
    double n = 0;
    for (double l = 360; l <= 830; l += 1) {
        int k = l < 490 ? 2 : l < 590 ? 1 : 0;
        double L = c[k] * scale * lf_planck(l, 6504); /* W / (m^2 sr nm) */
        n += L * (l * 1e-9) / (6.62607015e-34 * 299792458.0) * (curve ? curve(l) : 1.0);
    }
    return n;
}

static double ybar(double l)
{
    double b[3];
    lf_cie_xyz_bar(l, b);
    return b[1];
}

/* Mean electrons over the sites of colour c (-1: all). */
static double mean_electrons(const lf_image *raw, const lf_sensor *s, int c)
{
    double sum = 0;
    int n = 0;
    for (int y = 0; y < raw->height; y++)
        for (int x = 0; x < raw->width; x++)
            if (c < 0 || lf_cfa_color(s->cfa, x, y) == c)
                sum += raw->data[(size_t)y * raw->width + x], n++;
    return (sum / n - s->blacklevel) / (s->gain * s->iso / 100);
}

static void flat_field(void)
{
    const double L = 2e-7, t = 0.5, qe = 0.55, iso = 200;
    double pitch = 0.4e-3 / hypot(W, H);
    static const char *const variants[2] = {"\"bool noise\" false", "\"float readnoise\" [4] \"float prnu\" [0.01]"};
    for (int v = 0; v < 2; v++) {
        char params[512];
        /* ideal panchromatic sensor: the whole spectrum */
        snprintf(params, sizeof params,
                 "\"string sensor\" \"ideal\" \"string cfa\" \"none\" \"float qe\" [%g] \"float iso\" [%g] "
                 "\"float gain\" [0.5] \"float fullwell\" [100000] \"integer bits\" [16] \"float darkcurrent\" [0] "
                 "\"float blacklevel\" [100] %s",
                 qe, iso, variants[v]);
        char rgb[64];
        snprintf(rgb, sizeof rgb, "%g %g %g", L, L, L);
        lf_image raw;
        lf_sensor s;
        if (shoot(params, rgb, t, 3, &raw, &s, NULL)) {
            CHECK(0);
            return;
        }
        double white[3] = {L, L, L};
        double expect = pitch * pitch * qe * t * photons(white, NULL);
        double got = mean_electrons(&raw, &s, -1);
        printf("flat field, ideal panchromatic, %s: %.2f e- (formula %.2f, %+.3f %%)\n", v ? "noise on" : "noiseless",
               got, expect, 100 * (got / expect - 1));
        CHECK_MSG(fabs(got / expect - 1) < (v ? 0.01 : 0.001), "%g vs %g", got, expect);
        lf_image_free(&raw);
        /* cie1931 green sites: ybar */
        snprintf(params, sizeof params,
                 "\"string sensor\" \"cie1931\" \"string cfa\" \"grbg\" \"float qe\" [%g] \"float iso\" [%g] "
                 "\"float gain\" [0.5] \"float fullwell\" [100000] \"integer bits\" [16] \"float darkcurrent\" [0] "
                 "\"float blacklevel\" [100] %s",
                 qe, iso, variants[v]);
        if (shoot(params, rgb, t, 3, &raw, &s, NULL)) {
            CHECK(0);
            return;
        }
        expect = pitch * pitch * qe * t * photons(white, ybar);
        got = mean_electrons(&raw, &s, 1);
        printf("flat field, cie1931 green sites, %s: %.2f e- (formula %.2f, %+.3f %%)\n", v ? "noise on" : "noiseless",
               got, expect, 100 * (got / expect - 1));
        CHECK_MSG(fabs(got / expect - 1) < (v ? 0.01 : 0.001), "%g vs %g", got, expect);
        lf_image_free(&raw);
    }
}

/* One primary: with the ideal sensor only its sites see light; the others
 * stay exactly at the black level (no read noise, DSNU or dark current
 * asked for, so none drawn). */
static void monochromatic(void)
{
    static const char *const rgb[3] = {"2e-4 0 0", "0 2e-4 0", "0 0 2e-4"};
    static const char *const cfas[2] = {"rggb", "gbrg"};
    for (int f = 0; f < 2; f++)
        for (int c = 0; c < 3; c++) {
            char params[512];
            snprintf(params, sizeof params,
                     "\"string sensor\" \"ideal\" \"string cfa\" \"%s\" \"float readnoise\" [0] \"float dsnu\" [0] "
                     "\"float darkcurrent\" [0] \"float blacklevel\" [64]",
                     cfas[f]);
            lf_image raw;
            lf_sensor s;
            char *plan = NULL;
            if (shoot(params, rgb[c], 0.01, 5, &raw, &s, &plan)) {
                CHECK(0);
                return;
            }
            int lit = 0, dark_ok = 1, n_own = 0;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    float v = raw.data[(size_t)y * W + x];
                    if (lf_cfa_color(s.cfa, x, y) == c)
                        lit += v > 64 + 100, n_own++;
                    else
                        dark_ok &= v == 64;
                }
            CHECK_MSG(lit == n_own && dark_ok, "cfa %s primary %d: %d of %d own sites lit, others black: %d", cfas[f],
                      c, lit, n_own, dark_ok);
            CHECK(plan && strstr(plan, "read noise: off") && strstr(plan, "DSNU: off") &&
                  strstr(plan, "dark current: off") && strstr(plan, "shot noise: on"));
            free(plan);
            lf_image_free(&raw);
        }
}

/* Two seeds: the same fixed pattern, different temporal noise; the same
 * seed: the same bits. */
static void seeds(void)
{
    const char *p = "\"float readnoise\" [0] \"float darkcurrent\" [0] \"float prnu\" [0] \"float dsnu\" [20]";
    lf_image a, b, c;
    lf_sensor s;
    char *plan = NULL;
    if (shoot(p, "0 0 0", 0.01, 1, &a, &s, NULL) || shoot(p, "0 0 0", 0.01, 2, &b, &s, NULL) ||
        shoot(p, "0 0 0", 0.01, 1, &c, &s, NULL)) {
        CHECK(0);
        return;
    }
    /* dark with only DSNU: the pattern is fixed, so equal across seeds */
    CHECK(!memcmp(a.data, b.data, sizeof(float) * W * H));
    lf_image_free(&a), lf_image_free(&b), lf_image_free(&c);
    if (shoot("", "1e-6 1e-6 1e-6", 0.01, 1, &a, &s, NULL) || shoot("", "1e-6 1e-6 1e-6", 0.01, 2, &b, &s, NULL) ||
        shoot("", "1e-6 1e-6 1e-6", 0.01, 1, &c, &s, &plan)) {
        CHECK(0);
        return;
    }
    CHECK(memcmp(a.data, b.data, sizeof(float) * W * H) != 0);
    CHECK(!memcmp(a.data, c.data, sizeof(float) * W * H));
    CHECK(plan && strstr(plan, "PRNU: on") && strstr(plan, "read noise: on"));
    free(plan);
    lf_image_free(&a), lf_image_free(&b), lf_image_free(&c);
    if (shoot("\"bool noise\" false", "1e-6 1e-6 1e-6", 0.01, 1, &a, &s, &plan) == 0) {
        CHECK(plan && strstr(plan, "noise: off"));
        free(plan);
        lf_image_free(&a);
    }
}

/* Film "rgb" "whitebalance" (pbrt-v4): a white lit by CIE illuminant A
 * (2856 K) comes out neutral when balanced for 2856 K, orange when not. */
static void white_balance(void)
{
    for (int wb = 0; wb < 2; wb++) {
        char scene[1024];
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\n"
                 "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8] \"float whitebalance\" [%d]\n"
                 "Sampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n"
                 "LightSource \"infinite\" \"spectrum L\" \"stdillum-A\"\n",
                 wb ? 2856 : 0);
        lf_image img;
        char msg[1024];
        if (render_text(scene, NULL, &img, msg, sizeof msg)) {
            CHECK_MSG(0, "%s", msg);
            return;
        }
        const float *p = img.data;
        double lo = fmin(p[0], fmin(p[1], p[2])), hi = fmax(p[0], fmax(p[1], p[2]));
        printf("illuminant A, whitebalance %d: (%.4f %.4f %.4f)\n", wb ? 2856 : 0, p[0], p[1], p[2]);
        if (wb)
            CHECK_MSG(hi / lo < 1.01, "balanced A is (%g %g %g)", p[0], p[1], p[2]);
        else
            CHECK_MSG(p[0] / p[2] > 3, "unbalanced A is (%g %g %g)", p[0], p[1], p[2]);
        lf_image_free(&img);
    }
}

int main(void)
{
    white_balance();
    flat_field();
    monochromatic();
    seeds();
    return lf_test_end();
}
