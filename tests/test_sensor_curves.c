/* pbrt-v4's named camera curves (render/sensor_curves.c, docs/sensor.md
 * "Named camera curves"):
 *  - the transcription's structure: the 17 names of pbrt-v4, 35 samples
 *    380..720 nm each, every green peaking at exactly 1 at 520 nm, each
 *    camera's three 720 nm samples equal (as printed in pbrt-v4), and linear
 *    interpolation between samples, zero outside;
 *  - the XYZ fit: this test's own least-squares fit (its own daylight from
 *    the CIE S basis, trapezoid rule on the 10 nm samples) matches the
 *    library's within 1 % of its largest entry, and the fitted matrix maps
 *    the camera responses of four reflectances outside the training set to
 *    their XYZ under D65 within 0.05 (a white's Y is about 1; no camera here
 *    meets the Luther condition, so the fit has colour errors of its own:
 *    at most 0.035 for these cameras and reflectances);
 *  - Film "rgb" renders a constant emission as M^-1 F (int L rbar / CIE_Y),
 *    L the film colour's spectrum in the fixed basis, within 0.3 %;
 *  - Film "raw" green sites of a flat field hold the electrons of the
 *    physics.md formula with the QE shape rbar(lambda)/lambda, within 0.3 %;
 *  - a flat colour's raw, developed with its ColorMatrix1 and AsShotNeutral,
 *    equals the Film "rgb" render through the same camera within 1.5 %;
 *  - an unknown name is an error, in Film "rgb", Film "raw" and the sensor. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_color.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_sensor.h"
#include "render/sensor_curves.h"

#define CIE_Y 106.856895

static const double srgb_to_xyz[3][3] = {
    {0.4124564, 0.3575761, 0.1804375}, {0.2126729, 0.7151522, 0.0721750}, {0.0193339, 0.1191920, 0.9503041}};

static void structure(void)
{
    static const char *const pbrt_names[LF_CAMERA_CURVE_COUNT] = {
        "canon_eos_100d",    "canon_eos_1dx_mkii", "canon_eos_200d",     "canon_eos_200d_mkii", "canon_eos_5d",
        "canon_eos_5d_mkii", "canon_eos_5d_mkiii", "canon_eos_5d_mkiv",  "canon_eos_5ds",       "canon_eos_m",
        "hasselblad_l1d_20c", "nikon_d810",        "nikon_d850",         "sony_ilce_6400",      "sony_ilce_7m3",
        "sony_ilce_7rm3",    "sony_ilce_9"};
    for (int i = 0; i < LF_CAMERA_CURVE_COUNT; i++) {
        const lf_camera_curves *cc = lf_camera_curves_find(pbrt_names[i]);
        CHECK_MSG(cc != NULL, "%s missing", pbrt_names[i]);
        if (!cc)
            continue;
        int argmax = -1, in_range = 1;
        double gmax = 0;
        for (int k = 0; k < LF_CAMERA_CURVE_SAMPLES; k++) {
            if (cc->v[1][k] > gmax)
                gmax = cc->v[1][k], argmax = k;
            for (int c = 0; c < 3; c++)
                in_range &= cc->v[c][k] > 0 && cc->v[c][k] <= 1 + 1e-15;
        }
        CHECK_MSG(fabs(gmax - 1) < 1e-15 && argmax == 14, "%s: green peak %.17g at sample %d", cc->name, gmax, argmax);
        CHECK_MSG(in_range, "%s: a sample outside (0, 1]", cc->name);
        CHECK_MSG(cc->v[0][34] == cc->v[1][34] && cc->v[1][34] == cc->v[2][34], "%s: 720 nm samples differ",
                  cc->name);
        /* red peaks at 590-600 nm, blue at 450-470 nm for every camera */
        double rmax = 0, bmax = 0;
        int ra = 0, ba = 0;
        for (int k = 0; k < LF_CAMERA_CURVE_SAMPLES; k++) {
            if (cc->v[0][k] > rmax)
                rmax = cc->v[0][k], ra = k;
            if (cc->v[2][k] > bmax)
                bmax = cc->v[2][k], ba = k;
        }
        CHECK_MSG(ra >= 21 && ra <= 22 && ba >= 7 && ba <= 10, "%s: red peak at %d nm, blue at %d nm", cc->name,
                  380 + 10 * ra, 380 + 10 * ba);
        double mid = lf_camera_curve(cc, 0, 385.0), want = 0.5 * (cc->v[0][0] + cc->v[0][1]);
        CHECK(fabs(mid - want) < 1e-15 * want + 1e-300);
        CHECK(lf_camera_curve(cc, 1, 720.0) == cc->v[1][34]);
        CHECK(lf_camera_curve(cc, 2, 379.9) == 0 && lf_camera_curve(cc, 2, 720.1) == 0);
    }
    CHECK(lf_camera_curves_find("canon_eos_7d") == NULL && lf_camera_curves_find("cie1931") == NULL);
}

/* CIE daylight at correlated colour temperature cct (CIE 15:2004), on the
 * 5 nm samples of the S basis: sample index k. */
static double daylight_at(int k, double cct)
{
    double x = cct <= 7000 ? -4.607e9 / pow(cct, 3) + 2.9678e6 / (cct * cct) + 99.11 / cct + 0.244063
                           : -2.0064e9 / pow(cct, 3) + 1.9018e6 / (cct * cct) + 247.48 / cct + 0.23704;
    double y = -3 * x * x + 2.87 * x - 0.275;
    double m = 0.0241 + 0.2562 * x - 0.7341 * y;
    return lf_cie_daylight_s[0][k] + (-1.3515 - 1.7703 * x + 5.9114 * y) / m * lf_cie_daylight_s[1][k] +
           (0.0300 - 31.4424 * x + 30.0717 * y) / m * lf_cie_daylight_s[2][k];
}

static double d65_nm(double l) /* on the 10 nm and 5 nm grids only */
{
    return daylight_at((int)lround((l - 300) / 5), 6500 * 1.4388 / 1.4380);
}

typedef double (*refl_fn)(double);
static double test_refl_green(double l) { return 0.1 + 0.7 * exp(-0.5 * pow((l - 525) / 45, 2)); }
static double test_refl_red(double l) { return 0.08 + 0.75 / (1 + exp(-(l - 605) / 22)); }
static double test_refl_purple(double l)
{
    return 0.06 + 0.6 * exp(-0.5 * pow((l - 440) / 30, 2)) + 0.6 / (1 + exp(-(l - 640) / 20));
}
static double test_refl_sky(double l) { return 0.1 + 0.5 / (1 + exp((l - 520) / 30)); }

/* Camera responses (10 nm trapezoid on the table's own samples) and XYZ
 * (5 nm trapezoid, 360..830) of reflectance r, pbrt-v4's normalisation:
 * camera / int D65 gbar, XYZ / int D65 ybar x (int D65 ybar / int D65 gbar). */
static void project(const lf_camera_curves *cc, double (*r)(double), int train, double cam[3], double xyz[3])
{
    double g = 0, yi = 0, yd = 0;
    memset(cam, 0, 3 * sizeof *cam), memset(xyz, 0, 3 * sizeof *xyz);
    for (int k = 0; k < LF_CAMERA_CURVE_SAMPLES; k++) {
        double l = 380 + 10 * k, w = (k == 0 || k == LF_CAMERA_CURVE_SAMPLES - 1) ? 5 : 10;
        double rho = r ? r(l) : lf_camera_fit_reflectance(train, l), I = d65_nm(l);
        g += w * I * cc->v[1][k];
        for (int c = 0; c < 3; c++)
            cam[c] += w * rho * I * cc->v[c][k];
    }
    for (double l = 360; l <= 830; l += 5) {
        double w = (l == 360 || l == 830) ? 2.5 : 5, b[3], rho = r ? r(l) : lf_camera_fit_reflectance(train, l);
        lf_cie_xyz_bar(l, b);
        yd += w * d65_nm(l) * b[1];
        for (int c = 0; c < 3; c++)
            xyz[c] += w * rho * d65_nm(l) * b[c];
    }
    yi = yd; /* the illuminant is D65 on both sides here */
    for (int c = 0; c < 3; c++)
        cam[c] /= g, xyz[c] = xyz[c] / yd * (yi / g);
}

static void solve3(const double A[3][3], const double b[3], double x[3]) /* Cramer */
{
#define DET(a) (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) + \
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    double d = DET(A);
    for (int k = 0; k < 3; k++) {
        double Q[3][3];
        memcpy(Q, A, sizeof Q);
        for (int i = 0; i < 3; i++)
            Q[i][k] = b[i];
        x[k] = DET(Q) / d;
    }
}

static void fit(void)
{
    static const char *const cams[3] = {"canon_eos_5d", "nikon_d850", "sony_ilce_9"};
    static const refl_fn tests[4] = {test_refl_green, test_refl_red, test_refl_purple, test_refl_sky};
    for (int n = 0; n < 3; n++) {
        const lf_camera_curves *cc = lf_camera_curves_find(cams[n]);
        double F[3][3];
        CHECK(cc && lf_camera_xyz_fit(cc, 6500, F) == 0);
        if (!cc)
            continue;
        /* this test's own normal equations over the same training set */
        double A[3][3] = {{0}}, B[3][3] = {{0}}, G[3][3];
        for (int i = 0; i < LF_CAMERA_FIT_COUNT; i++) {
            double cam[3], xyz[3];
            project(cc, NULL, i, cam, xyz);
            for (int j = 0; j < 3; j++)
                for (int k = 0; k < 3; k++)
                    A[j][k] += cam[j] * cam[k], B[j][k] += xyz[j] * cam[k];
        }
        for (int row = 0; row < 3; row++)
            solve3(A, B[row], G[row]); /* A symmetric: row of G solves A g = B row */
        double big = 0, diff = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                big = fmax(big, fabs(F[i][j])), diff = fmax(diff, fabs(F[i][j] - G[i][j]));
        printf("%s: XYZ = F cam, F = [%.4f %.4f %.4f; %.4f %.4f %.4f; %.4f %.4f %.4f]; own fit differs by %.2e of "
               "its largest entry\n",
               cams[n], F[0][0], F[0][1], F[0][2], F[1][0], F[1][1], F[1][2], F[2][0], F[2][1], F[2][2], diff / big);
        CHECK_MSG(diff < 0.01 * big, "%s: fit differs by %g (largest entry %g)", cams[n], diff, big);
        /* reflectances it was not fitted on */
        for (int t = 0; t < 4; t++) {
            double cam[3], xyz[3], got[3], err = 0;
            project(cc, tests[t], 0, cam, xyz);
            for (int i = 0; i < 3; i++) {
                got[i] = F[i][0] * cam[0] + F[i][1] * cam[1] + F[i][2] * cam[2];
                err = fmax(err, fabs(got[i] - xyz[i]));
            }
            printf("  reflectance %d: XYZ %.4f %.4f %.4f, from the camera %.4f %.4f %.4f (largest error %.4f)\n", t,
                   xyz[0], xyz[1], xyz[2], got[0], got[1], got[2], err);
            CHECK_MSG(err < 0.05, "%s reflectance %d: error %g", cams[n], t, err);
        }
    }
}

/* The spectrum of film RGB rgb in the fixed basis (docs/physics.md
 * "Sensor": three bands of a 6504 K black body, luminance-normalised), at
 * lambda: computed here from Planck's law and the CIE fit. */
static double basis_spectrum(const double rgb[3], double lambda)
{
    double norm = 0, P[3][3] = {{0}}, xyz[3], c[3];
    for (double l = 360; l <= 830; l += 1) {
        double b[3];
        lf_cie_xyz_bar(l, b);
        norm += lf_planck(l, 6504) * b[1];
    }
    double scale = CIE_Y / norm;
    for (double l = 360; l <= 830; l += 1) {
        double b[3];
        lf_cie_xyz_bar(l, b);
        int k = l < 490 ? 2 : l < 590 ? 1 : 0;
        for (int i = 0; i < 3; i++)
            P[i][k] += scale * lf_planck(l, 6504) * b[i] / CIE_Y;
    }
    for (int i = 0; i < 3; i++)
        xyz[i] = srgb_to_xyz[i][0] * rgb[0] + srgb_to_xyz[i][1] * rgb[1] + srgb_to_xyz[i][2] * rgb[2];
    solve3(P, xyz, c);
    int k = lambda < 490 ? 2 : lambda < 590 ? 1 : 0;
    return c[k] * scale * lf_planck(lambda, 6504);
}

/* The table's channel c at lambda, linear between its 10 nm samples. */
static double table_at(const lf_camera_curves *cc, int c, double l)
{
    if (l < 380 || l > 720)
        return 0;
    int k = (int)((l - 380) / 10);
    if (k >= 34)
        return cc->v[c][34];
    double t = (l - 380 - 10 * k) / 10;
    return (1 - t) * cc->v[c][k] + t * cc->v[c][k + 1];
}

static void film_rgb(void)
{
    const double rgb[3] = {0.6, 0.3, 0.15};
    const char *cam = "nikon_d850";
    char scene[1024], msg[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\n"
             "Film \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4] \"string sensor\" \"%s\"\n"
             "Sampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [%g %g %g]\n",
             cam, rgb[0], rgb[1], rgb[2]);
    lf_image img;
    if (render_text(scene, NULL, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "%s", msg);
        return;
    }
    const lf_camera_curves *cc = lf_camera_curves_find(cam);
    double F[3][3], c[3] = {0}, xyz[3], want[3];
    CHECK(lf_camera_xyz_fit(cc, 6500, F) == 0);
    for (double l = 360; l <= 830; l += 1) { /* trapezoid at 1 nm (ends are zero) */
        double L = basis_spectrum(rgb, l);
        for (int k = 0; k < 3; k++)
            c[k] += L * table_at(cc, k, l) / CIE_Y;
    }
    for (int i = 0; i < 3; i++)
        xyz[i] = F[i][0] * c[0] + F[i][1] * c[1] + F[i][2] * c[2];
    double M[3][3];
    memcpy(M, srgb_to_xyz, sizeof M);
    solve3(M, xyz, want);
    const float *p = img.data;
    printf("Film \"rgb\" %s, emission (%.2f %.2f %.2f): (%.5f %.5f %.5f), expected (%.5f %.5f %.5f)\n", cam, rgb[0],
           rgb[1], rgb[2], p[0], p[1], p[2], want[0], want[1], want[2]);
    for (int k = 0; k < 3; k++)
        CHECK_MSG(fabs(p[k] / want[k] - 1) < 0.003, "channel %d: %g vs %g", k, p[k], want[k]);
    lf_image_free(&img);
}

static void film_raw(void)
{
    enum { W = 32, H = 24 };
    const double L = 2e-7, t = 0.5, qe = 0.6, pitch = 0.4e-3 / hypot(W, H);
    const char *cam = "canon_eos_5d_mkiv";
    char scene[2048], msg[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"perspective\" \"float shutteropen\" [0] \"float shutterclose\" [%g]\n"
             "Film \"raw\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"float diagonal\" [0.4]\n"
             "  \"string sensor\" \"%s\" \"string cfa\" \"grbg\" \"float qe\" [%g] \"bool noise\" false\n"
             "  \"float gain\" [0.5] \"float fullwell\" [100000] \"integer bits\" [16] \"float darkcurrent\" [0]\n"
             "  \"float blacklevel\" [100]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [%g %g %g]\n",
             t, W, H, cam, qe, L, L, L);
    lf_image film, raw;
    lf_attrs meta = {0};
    lf_sensor s;
    lf_error err = {0};
    if (render_text(scene, &(lf_test_scene){.meta = &meta}, &film, msg, sizeof msg)) {
        CHECK_MSG(0, "%s", msg);
        return;
    }
    CHECK(lf_sensor_from_attrs(&meta, &s, &err) == 0 && lf_sensor_expose(&s, &film, 0, 0, &raw, &err) == 0);
    const lf_camera_curves *cc = lf_camera_curves_find(cam);
    double peak = 0, n = 0, white[3] = {L, L, L};
    for (double l = 360; l <= 830; l += 1)
        for (int c = 0; c < 3; c++)
            peak = fmax(peak, table_at(cc, c, l) / l);
    for (double l = 360; l <= 830; l += 1) /* photons x QE, the QE shape rbar / lambda at peak qe */
        n += basis_spectrum(white, l) * (l * 1e-9) / (6.62607015e-34 * 299792458.0) * table_at(cc, 1, l) / l / peak;
    double expect = pitch * pitch * qe * t * n, sum = 0;
    int count = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (lf_cfa_color(s.cfa, x, y) == 1)
                sum += raw.data[(size_t)y * W + x], count++;
    double got = (sum / count - 100) / (0.5 * s.iso / 100);
    printf("Film \"raw\" %s green sites: %.2f e- (formula %.2f, %+.3f %%)\n", cam, got, expect,
           100 * (got / expect - 1));
    CHECK_MSG(fabs(got / expect - 1) < 0.003, "%g vs %g", got, expect);
    /* ColorMatrix1 = F^-1 scaled: D65 white maps to a neutral of largest component 1 */
    lf_raw_info ri;
    lf_sensor_raw_info(&s, &ri);
    double F[3][3], w[3], wmax = 0;
    CHECK(lf_camera_xyz_fit(cc, 6500, F) == 0);
    for (int c = 0; c < 3; c++) {
        w[c] = 0;
        for (int j = 0; j < 3; j++)
            w[c] += ri.color_matrix[3 * c + j] * (srgb_to_xyz[j][0] + srgb_to_xyz[j][1] + srgb_to_xyz[j][2]);
        wmax = fmax(wmax, w[c]);
    }
    double maxoff = 0; /* F x ColorMatrix is a multiple of the identity */
    double scale = F[1][0] * ri.color_matrix[1] + F[1][1] * ri.color_matrix[4] + F[1][2] * ri.color_matrix[7];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = F[i][0] * ri.color_matrix[j] + F[i][1] * ri.color_matrix[3 + j] + F[i][2] * ri.color_matrix[6 + j];
            maxoff = fmax(maxoff, fabs(v - (i == j ? scale : 0)));
        }
    CHECK_MSG(fabs(wmax - 1) < 1e-9 && maxoff < 1e-9 * fabs(scale), "colour matrix: white max %g, off %g", wmax,
              maxoff);
    lf_image_free(&film), lf_image_free(&raw), lf_attrs_free(&meta);
}

/* The raw's ColorMatrix1 and AsShotNeutral carry the same colour as the
 * Film "rgb" render: a flat colour through sony_ilce_9, noiseless, developed
 * (lf_raw_develop: white balance, the matrix, the film's units) equals the
 * Film "rgb" render of the same scene within 1.5 % per channel (the
 * developer balances by AsShotNeutral, the camera's measured white, where
 * Film "rgb" uses the fit alone; DN near 2700 round at 0.04 %). */
static void develop_matches_rgb(void)
{
    const char *cam = "sony_ilce_9";
    lf_image img[2], raw, dev;
    lf_attrs meta = {0};
    for (int f = 0; f < 2; f++) {
        char scene[2048], msg[1024];
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 0  0 0 1  0 1 0\n"
                 "Camera \"perspective\" \"float shutteropen\" [0] \"float shutterclose\" [0.01]\n"
                 "Film \"%s\" \"integer xresolution\" [16] \"integer yresolution\" [16] \"float diagonal\" [0.1]\n"
                 "  \"string sensor\" \"%s\" %s\n"
                 "Sampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n"
                 "LightSource \"infinite\" \"rgb L\" [0.6e-3 0.3e-3 0.15e-3]\n",
                 f ? "raw" : "rgb", cam,
                 f ? "\"bool noise\" false \"integer bits\" [16] \"float fullwell\" [200000] \"float gain\" [0.3]" : "");
        if (render_text(scene, f ? &(lf_test_scene){.meta = &meta} : NULL, &img[f], msg, sizeof msg)) {
            CHECK_MSG(0, "%s", msg);
            return;
        }
    }
    lf_sensor s;
    lf_raw_info ri;
    lf_error err = {0};
    CHECK(lf_sensor_from_attrs(&meta, &s, &err) == 0 && lf_sensor_expose(&s, &img[1], 0, 0, &raw, &err) == 0);
    lf_sensor_raw_info(&s, &ri);
    CHECK(lf_raw_develop(&raw, &ri, &(lf_develop_opts){.film_units = 1}, &dev, &err) == 0);
    const float *a = lf_image_px(&img[0], 8, 8), *b = lf_image_px(&dev, 8, 8);
    printf("Film \"raw\" %s developed: (%.4g %.4g %.4g), Film \"rgb\": (%.4g %.4g %.4g)\n", cam, b[0], b[1], b[2],
           a[0], a[1], a[2]);
    for (int k = 0; k < 3; k++)
        CHECK_MSG(fabs(b[k] / a[k] - 1) < 0.015, "channel %d: developed %g, rgb %g", k, b[k], a[k]);
    lf_image_free(&img[0]), lf_image_free(&img[1]), lf_image_free(&raw), lf_image_free(&dev), lf_attrs_free(&meta);
}

static void unknown(void)
{
    static const char *const films[2] = {"rgb", "raw"};
    for (int f = 0; f < 2; f++) {
        char scene[512], msg[1024];
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\n"
                 "Film \"%s\" \"integer xresolution\" [4] \"integer yresolution\" [4] \"string sensor\" \"canon_eos_7d\"\n"
                 "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n",
                 films[f]);
        lf_image img;
        int rc = render_text(scene, NULL, &img, msg, sizeof msg);
        CHECK_MSG(rc != 0 && strstr(msg, "unknown Film \"sensor\" \"canon_eos_7d\"") && strstr(msg, "nikon_d850"),
                  "Film \"%s\": rc %d, %s", films[f], rc, msg);
        if (!rc)
            lf_image_free(&img);
    }
    lf_sensor s;
    lf_error err = {0};
    lf_sensor_defaults(&s);
    snprintf(s.curves, sizeof s.curves, "canon_eos_7d");
    CHECK(lf_sensor_prepare(&s, &err) == LF_ERR_PARAM);
    float m[3][3];
    CHECK(lf_sensor_film_matrix("cie1931", 6500, m, &err) == LF_ERR_PARAM);
}

int main(void)
{
    structure();
    fit();
    film_rgb();
    film_raw();
    develop_matches_rgb();
    unknown();
    return lf_test_end();
}
