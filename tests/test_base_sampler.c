/* Sample sequences, reconstruction filters and tabulated distributions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_distrib.h"
#include "base/lf_filter.h"
#include "base/lf_sampler.h"
#include "lf_test.h"

/* A (0,m,2)-net in base 2: every elementary interval of area 2^-m, of every
 * shape 2^-a x 2^-(m-a), holds exactly one of the 2^m points. */
static int is_02_net(const float *x, const float *y, int m)
{
    int n = 1 << m;
    int *count = malloc(sizeof(int) * n);
    for (int a = 0; a <= m; a++) {
        int nx = 1 << a, ny = 1 << (m - a);
        memset(count, 0, sizeof(int) * n);
        for (int i = 0; i < n; i++) {
            int cx = (int)(x[i] * nx), cy = (int)(y[i] * ny);
            count[cy * nx + cx]++;
        }
        for (int i = 0; i < n; i++)
            if (count[i] != 1) {
                free(count);
                return 0;
            }
    }
    free(count);
    return 1;
}

static void test_sobol_stratification(void)
{
    lf_sampler s = {LF_SAMPLER_SOBOL, 7, 64, 0, 0};
    float x[64], y[64];
    int ok = 1;
    for (int px = 0; px < 5; px++)
        for (int pair = 0; pair < 6; pair++) {
            for (int i = 0; i < 64; i++) {
                lf_sample_stream st;
                lf_sample_start(&st, &s, px, 3 * px + 1, (uint32_t)i);
                for (int k = 0; k < pair; k++) {
                    float a, b;
                    lf_sample_2d(&st, &a, &b);
                }
                lf_sample_2d(&st, &x[i], &y[i]);
                if (!(x[i] >= 0 && x[i] < 1 && y[i] >= 0 && y[i] < 1))
                    ok = 0;
            }
            CHECK_MSG(is_02_net(x, y, 6), "pixel %d, dimension pair %d is not a (0,6,2)-net", px, pair);
        }
    CHECK(ok);
    /* the first 16 of 64 are a (0,4,2)-net too (progressive rendering) */
    CHECK(is_02_net(x, y, 4));
}

static void test_stratified(void)
{
    lf_sampler s = {LF_SAMPLER_STRATIFIED, 1, 12, 4, 3};
    int cells[12] = {0};
    for (int i = 0; i < 12; i++) {
        lf_sample_stream st;
        lf_sample_start(&st, &s, 9, 9, (uint32_t)i);
        float a, b;
        lf_sample_2d(&st, &a, &b);
        cells[(int)(b * 3) * 4 + (int)(a * 4)]++;
    }
    int ok = 1;
    for (int i = 0; i < 12; i++)
        ok &= cells[i] == 1;
    CHECK(ok);
}

static void test_independent_moments(void)
{
    /* mean 1/2 and variance 1/12; 200000 samples: sigma of the mean 6.5e-4,
     * tolerance 5 sigma */
    lf_sampler s = {LF_SAMPLER_INDEPENDENT, 3, 1, 0, 0};
    double sum = 0, sum2 = 0;
    int n = 200000;
    for (int i = 0; i < n; i++) {
        lf_sample_stream st;
        lf_sample_start(&st, &s, i % 500, i / 500, (uint32_t)i);
        float u = lf_sample_1d(&st);
        sum += u;
        sum2 += u * u;
    }
    CHECK_NEAR(sum / n, 0.5, 5 * sqrt(1.0 / 12 / n));
    CHECK_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12, 2e-3);
}

static void test_determinism(void)
{
    lf_sampler s = {LF_SAMPLER_SOBOL, 42, 16, 0, 0};
    lf_sample_stream a, b, c;
    lf_sample_start(&a, &s, 10, 20, 5);
    lf_sample_start(&b, &s, 10, 20, 5);
    lf_sample_start(&c, &s, 11, 20, 5);
    float a0 = lf_sample_1d(&a), b0 = lf_sample_1d(&b), c0 = lf_sample_1d(&c);
    CHECK(a0 == b0);
    CHECK(a0 != c0);
    lf_sampler s2 = s;
    s2.seed = 43;
    lf_sample_start(&c, &s2, 10, 20, 5);
    CHECK(lf_sample_1d(&c) != a0);
}

static double quad2d(const lf_filter *f, double (*g)(double, double))
{
    /* midpoint rule, 400 x 400 over the support */
    int n = 400;
    double hx = 2 * f->radius[0] / n, hy = 2 * f->radius[1] / n, s = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = -f->radius[0] + (i + .5) * hx, y = -f->radius[1] + (j + .5) * hy;
            s += lf_filter_eval(f, x, y) * g(x, y);
        }
    return s * hx * hy;
}
static double one(double x, double y) { (void)x, (void)y; return 1; }
static double xsq(double x, double y) { (void)y; return x * x; }

static void test_filters(void)
{
    lf_error err = {0};
    lf_filter f;
    CHECK(lf_filter_init(&f, LF_FILTER_BOX, NULL, &err) == 0);
    CHECK(f.radius[0] == 0.5);
    double dx, dy;
    CHECK(lf_filter_sample(&f, 0.999, 0.0, &dx, &dy) == 1.0);
    CHECK(dx <= 0.5 && dy >= -0.5);
    lf_filter_free(&f);

    /* Importance-sampled filters: E[w] = integral of f, E[w x^2]/E[w] =
     * second moment of f, both by quadrature of the analytic filter. */
    lf_filter_kind kinds[] = {LF_FILTER_GAUSSIAN, LF_FILTER_MITCHELL, LF_FILTER_LANCZOS, LF_FILTER_TRIANGLE};
    for (int k = 0; k < 4; k++) {
        CHECK(lf_filter_init(&f, kinds[k], NULL, &err) == 0);
        double I = quad2d(&f, one), M2 = quad2d(&f, xsq) / I;
        double sw = 0, swx2 = 0;
        /* A 1024^2 grid of u: filters with negative lobes give +-|integral|
         * weights, so the estimate converges slowly (about 1% at this size). */
        int n = 1024 * 1024;
        for (int i = 0; i < n; i++) {
            double u0 = ((i % 1024) + 0.5) / 1024, u1 = ((i / 1024) + 0.5) / 1024;
            double w = lf_filter_sample(&f, u0, u1, &dx, &dy);
            sw += w;
            swx2 += w * dx * dx;
        }
        CHECK_NEAR(sw / n, I, 0.01 * fabs(I));
        CHECK_NEAR(swx2 / sw, M2, 0.03 * M2);
        lf_filter_free(&f);
    }
    /* Mitchell with B = C = 1/3 integrates to 1 per axis. */
    lf_filter_init(&f, LF_FILTER_MITCHELL, NULL, &err);
    CHECK_NEAR(quad2d(&f, one), 1.0, 1e-3);
    lf_filter_free(&f);
}

static void test_distrib(void)
{
    double fn[4] = {1, 0, 3, 4};
    lf_distrib1d d;
    lf_error err = {0};
    CHECK(lf_distrib1d_init(&d, fn, 4, &err) == 0);
    CHECK_NEAR(d.integral, 2.0, 1e-12);
    int hist[4] = {0};
    for (int i = 0; i < 8000; i++) {
        double pdf;
        int idx;
        double x = lf_distrib1d_sample(&d, (i + 0.5) / 8000, &pdf, &idx);
        hist[idx]++;
        CHECK(x >= 0 && x < 1);
        CHECK_NEAR(pdf, fn[idx] / 2.0, 1e-12);
    }
    CHECK(hist[1] == 0);
    CHECK(hist[0] == 1000 && hist[2] == 3000 && hist[3] == 4000);
    CHECK_NEAR(lf_distrib1d_pmf(&d, 2), 3.0 / 8, 1e-12);
    lf_distrib1d_free(&d);

    double f2[6] = {1, 1, 2, 0, 0, 4}; /* 3 x 2 */
    lf_distrib2d d2;
    CHECK(lf_distrib2d_init(&d2, f2, 3, 2, &err) == 0);
    double u, v, pdf;
    lf_distrib2d_sample(&d2, 0.5, 0.9, &u, &v, &pdf);
    CHECK(v >= 0.5 && u >= 2.0 / 3);
    CHECK_NEAR(pdf, 4 / (8.0 / 6), 1e-9); /* f / mean(f) */
    CHECK_NEAR(lf_distrib2d_pdf(&d2, u, v), pdf, 1e-9);
    lf_distrib2d_free(&d2);
}

int main(void)
{
    test_sobol_stratification();
    test_stratified();
    test_independent_moments();
    test_determinism();
    test_filters();
    test_distrib();
    return lf_test_end();
}
