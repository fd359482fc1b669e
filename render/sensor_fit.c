/* Named camera curves: lookup, interpolation, pbrt-v4's white illuminant
 * and the least-squares camera-to-XYZ fit (render/sensor_curves.h; the
 * data in render/sensor_curves.c; docs/sensor.md "Named camera curves"). */
#include <math.h>
#include <string.h>

#include "base/lf_color.h"
#include "base/lf_math.h"
#include "render/lf_sensor.h"
#include "render/sensor_curves.h"

const lf_camera_curves *lf_camera_curves_find(const char *name)
{
    for (int i = 0; name && i < LF_CAMERA_CURVE_COUNT; i++)
        if (!strcmp(name, lf_camera_curve_table[i].name))
            return &lf_camera_curve_table[i];
    return NULL;
}

/* Linear interpolation in a table of n samples from l0 every step; 0
 * outside (pbrt-v4's piecewise-linear spectra). */
static double table_lerp(const double *v, int n, double l0, double step, double l)
{
    double u = (l - l0) / step;
    if (!(u >= 0) || u > n - 1)
        return 0;
    int i = (int)u;
    if (i >= n - 1)
        return v[n - 1];
    double t = u - i;
    return (1 - t) * v[i] + t * v[i + 1];
}

double lf_camera_curve(const lf_camera_curves *cc, int c, double lambda_nm)
{
    return table_lerp(cc->v[c], LF_CAMERA_CURVE_SAMPLES, LF_CAMERA_CURVE_LAMBDA0, LF_CAMERA_CURVE_STEP, lambda_nm);
}

double lf_white_illuminant(double lambda_nm, double temperature_k)
{
    double cct = temperature_k * 1.4388 / 1.4380; /* pbrt-v4: the old value of c2 */
    if (cct < 4000) /* CIE daylight is defined from 4000 K */
        return 100.0 * lf_planck(lambda_nm, cct) / lf_planck(560.0, cct);
    /* CIE 15:2004 eq. 3.3-3.6: chromaticity of daylight, then M1, M2 */
    double c3 = cct * cct * cct;
    double x = cct <= 7000 ? -4.607e9 / c3 + 2.9678e6 / (cct * cct) + 0.09911e3 / cct + 0.244063
                           : -2.0064e9 / c3 + 1.9018e6 / (cct * cct) + 0.24748e3 / cct + 0.23704;
    double y = -3 * x * x + 2.870 * x - 0.275;
    double m = 0.0241 + 0.2562 * x - 0.7341 * y;
    double m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m, m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
    double s[3];
    for (int k = 0; k < 3; k++)
        s[k] = table_lerp(lf_cie_daylight_s[k], LF_CIE_S_COUNT, LF_CIE_S_LAMBDA0, LF_CIE_S_STEP, lambda_nm);
    return s[0] + m1 * s[1] + m2 * s[2];
}

/* The training reflectances: four greys, twelve Gaussian bands (centres
 * 410..685 nm, sigma 35 nm) and eight sigmoid edges (long-pass at 480..630,
 * short-pass at 450..600 nm, 15 nm wide), all within [0.05, 0.9]: smooth
 * spectra spanning the hues of natural surfaces.  pbrt-v4 fits over the 24
 * ColorChecker patches (BabelColor data used by pbrt with permission, so
 * not redistributed here). */
double lf_camera_fit_reflectance(int i, double l)
{
    static const double grey[4] = {0.05, 0.2, 0.45, 0.9};
    if (i < 4)
        return grey[i];
    if (i < 16) {
        double c = 410.0 + 25.0 * (i - 4), d = (l - c) / 35.0;
        return 0.05 + 0.8 * exp(-0.5 * d * d);
    }
    if (i < 20)
        return 0.05 + 0.85 / (1 + exp(-(l - (480.0 + 50.0 * (i - 16))) / 15.0));
    return 0.05 + 0.85 / (1 + exp((l - (450.0 + 50.0 * (i - 20))) / 15.0));
}

int lf_camera_xyz_fit(const lf_camera_curves *cc, double white_k, double F[3][3])
{
    enum { N = LF_CAMERA_FIT_COUNT };
    double cam[N][3] = {{0}}, xyz[N][3] = {{0}}, g_i = 0, y_i = 0, y_d = 0;
    for (double l = LF_CIE_LAMBDA_MIN; l <= LF_CIE_LAMBDA_MAX; l += 1.0) {
        double I = lf_white_illuminant(l, white_k), D = lf_white_illuminant(l, 6500.0); /* D65 */
        double b[3], r[3];
        lf_cie_xyz_bar(l, b);
        for (int c = 0; c < 3; c++)
            r[c] = lf_camera_curve(cc, c, l);
        g_i += I * r[1], y_i += I * b[1], y_d += D * b[1];
        for (int i = 0; i < N; i++) {
            double rho = lf_camera_fit_reflectance(i, l);
            for (int c = 0; c < 3; c++)
                cam[i][c] += rho * I * r[c], xyz[i][c] += rho * D * b[c];
        }
    }
    if (!(g_i > 0) || !(y_d > 0))
        return -1;
    /* F minimises sum_i |F cam_i - xyz_i|^2: F = (sum xyz cam^T)(sum cam cam^T)^-1 */
    double A[3][3] = {{0}}, B[3][3] = {{0}}, Ai[3][3];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) {
                double cj = cam[i][j] / g_i, ck = cam[i][k] / g_i;
                A[j][k] += cj * ck;
                B[j][k] += xyz[i][j] / y_d * (y_i / g_i) * ck;
            }
    if (lf_mat3_inverse(A, Ai))
        return -1;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            F[i][j] = 0;
            for (int k = 0; k < 3; k++)
                F[i][j] += B[i][k] * Ai[k][j];
        }
    return 0;
}
