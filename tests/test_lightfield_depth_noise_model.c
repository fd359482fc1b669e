/* The noise model the depth whitens pre-smoothed views by (docs/depth.md,
 * "Noisy views: whitened and a wider window"; lightfield/depth_internal.h
 * lf_depth_noise_variance, lf_depth_smoothed_noise_correlation).
 *
 * Independent computation: a long row of white Gaussian noise (fixed seed)
 * is smoothed here by a sampled Gaussian of sigma px (radius ceil(3 sigma),
 * normalised: the recipe docs/depth.md gives for the pre-smoothing), then
 * looked up at a sub-pixel phase t with Keys' cubic convolution weights
 * (a = -1/2, from the kernel's formula), and the lookup's variance measured,
 * in units of the smoothed row's.  The model must give it within 1.5 %:
 * the Monte Carlo estimate of a variance from n samples whose correlation
 * sums to S = sum_k rho(k)^2 has relative standard deviation sqrt(2 S / n),
 * under 0.3 % here (n = 2^21, S < 3), so 1.5 % is 5 standard deviations.
 * White noise (sigma 0) must give the sum of the squared weights.  And the
 * whitened differences' variance 1 + Vx Vy times the gain^2 must be the
 * same at every phase: the point of the whitening.  The white-noise
 * model must miss the smoothed rows' variance at half a pixel by more than
 * 3 %, so the comparison can fail. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lf_test.h"
#include "lf_test_texture.h"
#include "lightfield/depth_internal.h"

enum { N = 1 << 21 };

/* Keys' cubic convolution kernel, a = -1/2 */
static double keys(double x)
{
    const double a = -0.5;
    x = fabs(x);
    if (x <= 1)
        return (a + 2) * x * x * x - (a + 3) * x * x + 1;
    if (x < 2)
        return a * x * x * x - 5 * a * x * x + 8 * a * x - 4 * a;
    return 0;
}

/* the lookup's variance at phase t over the smoothed row s, in units of
 * the row's own variance */
static double measured(const double *s, double t, float w[4])
{
    for (int j = 0; j < 4; j++)
        w[j] = (float)keys(t - (j - 1)); /* taps at -1, 0, 1, 2 from the sample */
    double sum = 0, sum2 = 0, r = 0, r2 = 0;
    int n = 0;
    for (int i = 1; i + 2 < N; i++) {
        double y = 0;
        for (int j = 0; j < 4; j++)
            y += w[j] * s[i - 1 + j];
        sum += y, sum2 += y * y, r += s[i], r2 += s[i] * s[i], n++;
    }
    double vy = sum2 / n - (sum / n) * (sum / n), vs = r2 / n - (r / n) * (r / n);
    return vy / vs;
}

int main(void)
{
    double *x = malloc(sizeof(double) * N), *s = malloc(sizeof(double) * N);
    CHECK(x && s);
    if (!x || !s)
        return lf_test_end();
    unsigned long long st = 20261128ULL;
    for (int i = 0; i < N; i++)
        x[i] = lf_test_gauss(&st);
    const double sigmas[] = {0, 0.7, 1.5};
    const double phases[] = {0, 0.25, 0.5};
    for (int si = 0; si < 3; si++) {
        double sg = sigmas[si];
        if (sg > 0) { /* the sampled Gaussian, radius ceil(3 sigma), normalised */
            int r = (int)ceil(3 * sg);
            double k[32], ks = 0;
            for (int i = -r; i <= r; i++)
                ks += k[i + r] = exp(-0.5 * i * i / (sg * sg));
            for (int i = 0; i < N; i++) {
                double a = 0;
                for (int j = -r; j <= r; j++) {
                    int m = i + j < 0 ? 0 : (i + j >= N ? N - 1 : i + j);
                    a += k[j + r] / ks * x[m];
                }
                s[i] = a;
            }
        } else {
            for (int i = 0; i < N; i++)
                s[i] = x[i];
        }
        double rho[4];
        if (sg > 0)
            lf_depth_smoothed_noise_correlation(sg, rho);
        double whitened[3];
        for (int pi = 0; pi < 3; pi++) {
            float w[4];
            double mv = measured(s, phases[pi], w);
            double model = lf_depth_noise_variance(w, sg > 0 ? rho : NULL);
            printf("sigma %.1f, phase %.2f: lookup variance %.4f measured, %.4f modelled (%+.2f %%)\n", sg, phases[pi],
                   mv, model, 100 * (model / mv - 1));
            CHECK_MSG(fabs(model / mv - 1) < 0.015, "sigma %g phase %g", sg, phases[pi]);
            if (sg > 0 && phases[pi] == 0.5) { /* the white model is wrong here: the test can tell */
                double white = lf_depth_noise_variance(w, NULL);
                printf("  (the white-noise model would say %.4f)\n", white);
                CHECK(fabs(white / mv - 1) > 0.03);
            }
            if (sg == 0) {
                double sw2 = 0;
                for (int j = 0; j < 4; j++)
                    sw2 += (double)w[j] * w[j];
                CHECK_NEAR(model, sw2, 1e-9);
            }
            /* a view's difference to the reference in 2-D at phase (t, t):
             * variance 1 + V^2, times the gain^2 2 / (1 + V^2) */
            double v2 = model * model;
            whitened[pi] = (1 + mv * mv) * 2 / (1 + v2);
        }
        printf("sigma %.1f: whitened difference variance %.4f / %.4f / %.4f at phases 0 / 0.25 / 0.5 (2 at each)\n", sg,
               whitened[0], whitened[1], whitened[2]);
        for (int pi = 0; pi < 3; pi++)
            CHECK_NEAR(whitened[pi], 2.0, 0.06);
    }
    free(x), free(s);
    return lf_test_end();
}
