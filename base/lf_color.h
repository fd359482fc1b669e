/* lf_color.h - spectra to linear sRGB, for a renderer that shades in RGB.
 *
 * pbrt-v4 renders spectrally; lensfield renders in linear sRGB (Rec.709
 * primaries, D65 white), so every spectrum a scene file names is reduced to
 * RGB once, when it is read:
 *
 *   lf_vec3 c = lf_blackbody_rgb(3000.0);             // luminance 1
 *   double l[] = {400, 700}, v[] = {0.5, 0.5};
 *   lf_vec3 g = lf_spectrum_pairs_rgb(l, v, 2, LF_SPECTRUM_ALBEDO); // ~(0.5,0.5,0.5)
 *   lf_vec3 eta; lf_named_spectrum_rgb("metal-Cu-eta", &eta);
 *
 * Colour matching uses the CIE 1931 2-degree observer through the analytic
 * multi-lobe Gaussian fit of Wyman, Sloan & Shirley, "Simple Analytic
 * Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013.
 * Spectra are integrated from 360 to 830 nm in 1 nm steps.
 *
 * How each kind of spectrum is normalised (pbrt-v4 semantics, reduced to RGB):
 *   ILLUMINANT  XYZ of the spectrum scaled to Y = 1, then to sRGB.  pbrt-v4
 *               divides every light's spectrum by its photometric value, so a
 *               light of scale 1 has luminance 1 whatever its spectrum.
 *   ALBEDO      the reflectance is lit by an equal-energy illuminant and the
 *               result divided channel-wise by the RGB of a perfect white
 *               reflector under the same light, so a constant spectrum c gives
 *               exactly (c, c, c).  This is a white balance in linear sRGB,
 *               not a chromatic-adaptation transform (Bradford etc.), and one
 *               RGB triple cannot reproduce metamerism: an approximation good
 *               to a few per cent for smooth reflectance spectra.  Clamped to
 *               [0, 1].
 *   UNBOUNDED   as ALBEDO, not clamped (indices of refraction, k, scattering
 *               coefficients).
 */
#ifndef LF_COLOR_H
#define LF_COLOR_H

#include <stddef.h>

#include "lf_math.h"
#include "lf_params.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LF_CIE_LAMBDA_MIN 360.0
#define LF_CIE_LAMBDA_MAX 830.0

/* CIE 1931 colour matching functions x, y, z at lambda (nanometres),
 * Wyman et al. 2013 multi-lobe fit. */
void lf_cie_xyz_bar(double lambda_nm, double xyz[3]);

/* XYZ to linear sRGB (Rec.709 primaries, D65 white). */
lf_vec3 lf_xyz_to_linear_srgb(double X, double Y, double Z);

/* Planck's law: spectral radiance of a black body at temperature T (kelvin)
 * and wavelength lambda (nanometres), in W / (m^2 sr m).  0 for T <= 0. */
double lf_planck(double lambda_nm, double temperature_k);

/* A black body at T kelvin in linear sRGB, scaled to luminance Y = 1.
 * (0,0,0) for T <= 0. */
lf_vec3 lf_blackbody_rgb(double temperature_k);

/* A piecewise-linear spectrum given as n (wavelength nm, value) samples with
 * increasing wavelengths; zero outside [lambdas[0], lambdas[n-1]] as in
 * pbrt-v4.  Normalised according to `kind` (see above). */
lf_vec3 lf_spectrum_pairs_rgb(const double *lambdas, const double *values, size_t n,
                              lf_spectrum_kind kind);

/* pbrt-v4's built-in named spectra as RGB triples: "metal-<M>-eta" and
 * "metal-<M>-k" for M in Ag Al Au Cu CuZn MgO TiO2, "glass-<G>" for G in BK7
 * BAF10 FK51A LASF9 F5 F10 F11 (their refractive index n_d, grey), and the
 * illuminants "stdillum-A", "-D50", "-D65", "-F1".."-F12" and
 * "illum-acesD60" (their colour at luminance 1, see color.c).
 * Returns 0 and sets *out, or -1 if the name is unknown. */
int lf_named_spectrum_rgb(const char *name, lf_vec3 *out);

/* Reads a pbrt spectrum file (".spd"): whitespace-separated (wavelength nm,
 * value) pairs, '#' starts a comment to the end of the line; the file may be
 * gzipped.  *nums receives 2 * *n_pairs numbers (malloc'ed).  Wavelengths
 * must increase.  Errors name path:line. */
int lf_spectrum_file_read(const char *path, double **nums, size_t *n_pairs, lf_error *err);

/* Spectral camera rays (dispersion): a camera that samples wavelength picks
 * lambda uniformly in [LF_LAMBDA_MIN, LF_LAMBDA_MAX] nm; the radiance it
 * carries (RGB) is multiplied by this weight, the linear-sRGB response to
 * a unit monochromatic sample divided by its pdf and normalised so that the
 * weights average to (1,1,1) over the range: a grey scene stays grey, and
 * each wavelength only lights the channels it belongs to.  Channels can be
 * negative for saturated spectral colours (outside the sRGB gamut). */
#define LF_LAMBDA_MIN 360.0
#define LF_LAMBDA_MAX 830.0
lf_vec3 lf_wavelength_rgb_weight(double lambda_nm);

#ifdef __cplusplus
}
#endif
#endif
