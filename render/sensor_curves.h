/* sensor_curves.h - pbrt-v4's named camera sensitivity curves (measured
 * data in render/sensor_curves.c, source and licence there and in
 * THIRD-PARTY.md), CIE daylight, and the camera-to-XYZ fit of pbrt-v4's
 * PixelSensor (docs/sensor.md "Named camera curves").
 *
 *   const lf_camera_curves *c = lf_camera_curves_find("nikon_d850");
 *   double g = lf_camera_curve(c, 1, 532.0);      // green, linear between samples
 *   double F[3][3]; lf_camera_xyz_fit(c, 6500, F); // XYZ = F camera RGB
 */
#ifndef LF_SENSOR_CURVES_H
#define LF_SENSOR_CURVES_H

#ifdef __cplusplus
extern "C" {
#endif

#define LF_CAMERA_CURVE_COUNT 17
#define LF_CAMERA_CURVE_SAMPLES 35 /* 380, 390, ..., 720 nm */
#define LF_CAMERA_CURVE_LAMBDA0 380.0
#define LF_CAMERA_CURVE_STEP 10.0

typedef struct lf_camera_curves {
    const char *name;                            /* pbrt-v4's Film "sensor" name */
    double v[3][LF_CAMERA_CURVE_SAMPLES];        /* R, G, B relative sensitivity */
} lf_camera_curves;

extern const lf_camera_curves lf_camera_curve_table[LF_CAMERA_CURVE_COUNT];

/* NULL for a name not in the table. */
const lf_camera_curves *lf_camera_curves_find(const char *name);
/* Channel c (0 R, 1 G, 2 B) at lambda nm: linear between samples, 0 outside
 * [380, 720] (pbrt-v4's piecewise-linear spectrum). */
double lf_camera_curve(const lf_camera_curves *cc, int c, double lambda_nm);

/* CIE daylight basis S0, S1, S2: 300..830 nm every 5 nm. */
#define LF_CIE_S_COUNT 107
#define LF_CIE_S_LAMBDA0 300.0
#define LF_CIE_S_STEP 5.0
extern const double lf_cie_daylight_s[3][LF_CIE_S_COUNT];

/* pbrt-v4's white illuminant at T kelvin (relative spectral power): CIE
 * daylight (CIE 15:2004, S0 + M1 S1 + M2 S2, linear between the 5 nm
 * samples) for a correlated temperature T x 1.4388/1.4380 from 4000 K, a
 * black body at that temperature below (scaled to a comparable size). */
double lf_white_illuminant(double lambda_nm, double temperature_k);

/* The 3x3 matrix F with XYZ = F (r, g, b) for the camera's responses
 * r = int L rbar dlambda / CIE_Y_integral (pbrt-v4's sensor RGB), fitted by
 * linear least squares over the reflectances of lf_camera_fit_reflectance
 * lit by the white illuminant at `white_k` (the camera's side) and by D65
 * (the XYZ side), the XYZ scaled by int I ybar / int I gbar as pbrt-v4
 * does, so that a grey lit by the illuminant keeps its luminance.
 * Integrals at 1 nm over 360..830 nm.  Returns 0, or -1 if singular. */
int lf_camera_xyz_fit(const lf_camera_curves *cc, double white_k, double F[3][3]);

/* The fit's training set: LF_CAMERA_FIT_COUNT smooth reflectances
 * (docs/sensor.md): greys, Gaussian bands and sigmoid edges. */
#define LF_CAMERA_FIT_COUNT 24
double lf_camera_fit_reflectance(int i, double lambda_nm);

#ifdef __cplusplus
}
#endif
#endif
