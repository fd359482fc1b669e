/* lf_sensor.h - the image sensor behind the film (Film "raw", docs/sensor.md).
 *
 * The renderer's film holds exposure in linear sRGB (the film value is
 * radiance times the camera's ray weight times the shutter time times
 * ISO/100, pbrt-v4's imaging ratio).  The sensor turns it into a raw mosaic
 * of digital numbers, stage by stage, and draws only what the scene asks for:
 *
 *   exposure (film RGB / (ISO/100))                         J/m^2 per unit
 *   -> photoelectrons: spectral radiance from RGB (a fixed linear basis,
 *      docs/physics.md "Sensor"), photons via lambda/(h c), quantum
 *      efficiency qe x the named curve of the site's filter, pixel area
 *   -> PRNU (fixed gain pattern)  -> Poisson shot noise on signal + dark
 *      current x time  -> DSNU (fixed offset pattern)  -> full-well clip
 *   -> read noise  -> gain x ISO/100 (DN per electron) + black level
 *   -> N-bit converter (round, clamp to [0, 2^bits - 1]).
 *
 * Every random number is a hash of (seed, pixel index in the full film,
 * draw): temporal noise follows the Sampler's seed, the fixed patterns
 * (DSNU, PRNU) follow only the pixel (one sensor, many frames), so a split,
 * merged or resumed render gives the same bits.
 *
 *   lf_sensor s; lf_sensor_defaults(&s);  ... set fields ...
 *   lf_sensor_prepare(&s, &err);                // response matrices
 *   lf_image raw; lf_sensor_expose(&s, &film, x0, y0, &raw, &err);
 */
#ifndef LF_SENSOR_H
#define LF_SENSOR_H

#include <stdint.h>

#include "base/lf_buf.h"
#include "base/lf_error.h"
#include "base/lf_keys.h"
#include "base/lf_params.h"
#include "image/lf_image.h"
#include "image/lf_raw.h"

#ifdef __cplusplus
extern "C" {
#endif


typedef struct lf_sensor {
    /* Film "raw" parameters (docs/scene-format.md) */
    char curves[32];      /* "sensor": cie1931, ideal or a camera of render/sensor_curves.h */
    lf_cfa cfa;
    double qe;            /* peak quantum efficiency */
    double fullwell;      /* electrons */
    double gain;          /* DN per electron at ISO 100 */
    double readnoise;     /* electrons RMS */
    double darkcurrent;   /* electrons per second */
    double dsnu;          /* electrons RMS, fixed pattern */
    double prnu;          /* fraction RMS, fixed pattern */
    double blacklevel;    /* DN */
    int bits;
    int noise;            /* 0: the noiseless mean (no term drawn) */
    /* from the rest of the scene */
    double iso;
    double exposure_s;    /* shutter interval x mean shutter efficiency */
    double pixel_pitch_m;
    uint32_t seed;        /* the Sampler's seed: temporal noise */
    int full_width;       /* the film's width: pixel index = y * full_width + x */
    /* derived by lf_sensor_prepare */
    double e_per_unit[3][3]; /* electrons per film unit: [site colour][film R,G,B] (row 1 for "none") */
    double photons_per_unit[3]; /* photons per m^2 per film unit of sRGB primary k (no QE) */
} lf_sensor;

void lf_sensor_defaults(lf_sensor *s);
/* Film "raw" parameters from a Film's parameter list (those of Film "rgb"
 * are read by the renderer); LF_ERR_PARAM naming `where` for bad values. */
int lf_sensor_read_params(lf_sensor *s, lf_paramset *ps, const char *where, lf_error *err);
/* Checks the values and computes the response matrices. */
int lf_sensor_prepare(lf_sensor *s, lf_error *err);
/* film: 3 channels (the film region starting at full-film pixel (x0, y0));
 * raw: 1 channel of DN, allocated here. */
int lf_sensor_expose(const lf_sensor *s, const lf_image *film, int x0, int y0, lf_image *raw, lf_error *err);
/* The raw's colour metadata (CFA, black/white level, ColorMatrix1,
 * AsShotNeutral, DN per film white unit). */
void lf_sensor_raw_info(const lf_sensor *s, lf_raw_info *ri);
/* The saturation DN: min(fullwell x K + black, 2^bits - 1); K = gain x ISO/100. */
double lf_sensor_white_level(const lf_sensor *s);
/* All parameters as lensfield:sensor:* attributes (+ lensfield:film "raw"),
 * and back (merge builds the sensor of its parts). from_attrs returns -1
 * when a has no sensor (Film "rgb"), 0 when read, or an LF_ERR_* status. */
int lf_sensor_to_attrs(const lf_sensor *s, lf_attrs *a, lf_error *err);
int lf_sensor_from_attrs(const lf_attrs *a, lf_sensor *s, lf_error *err);
/* Film "rgb" with a named camera's curves (pbrt-v4's PixelSensor): the
 * matrix taking the film's linear sRGB (as a spectrum in the fixed basis)
 * through the camera's curves and the least-squares XYZ-from-camera fit for
 * the white illuminant at white_k (lf_camera_xyz_fit) back to linear sRGB.
 * LF_ERR_PARAM for a name that is not a camera of the table. */
int lf_sensor_film_matrix(const char *curves, double white_k, float out[3][3], lf_error *err);
/* The stages the scene asked for, one line each (lfrender --explain). */
void lf_sensor_explain(const lf_sensor *s, lf_strbuf *b);

/* Radiometry, exposed for tests and docs: Planck white basis temperature
 * and the physical constants used. */
#define LF_SENSOR_WHITE_K 6504.0
#define LF_PLANCK_H 6.62607015e-34
#define LF_LIGHT_C 299792458.0
#define LF_CIE_Y_INTEGRAL 106.856895

/* Counter-based random numbers (for tests): uniform in (0,1) and the n-th
 * of a pixel's stream. */
double lf_sensor_uniform(uint64_t key, uint64_t pixel, uint64_t n);

#ifdef __cplusplus
}
#endif
#endif
