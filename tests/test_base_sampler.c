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

/* A (t,m,3)-net in base 2: every elementary box of volume 2^(t-m), of
 * every shape 2^-a x 2^-b x 2^-c (a + b + c = m - t), holds exactly 2^t of
 * the 2^m points. */
static int is_t3_net(const double *x, const double *y, const double *z, int m, int t)
{
    int n = 1 << m, ok = 1;
    int *count = malloc(sizeof(int) * n);
    for (int a = 0; a <= m - t; a++)
        for (int b = 0; a + b <= m - t; b++) {
            int c = m - t - a - b, na = 1 << a, nb = 1 << b, nc = 1 << c, boxes = na * nb * nc;
            memset(count, 0, sizeof(int) * boxes);
            for (int i = 0; i < n; i++)
                count[((int)(z[i] * nc) * nb + (int)(y[i] * nb)) * na + (int)(x[i] * na)]++;
            for (int k = 0; k < boxes; k++)
                ok &= count[k] == 1 << t;
        }
    free(count);
    return ok;
}

/* lf_sample_3d_d (film position and time drawn together): the first three
 * Sobol dimensions, which form a (1,m,3)-net (Joe and Kuo's t-value for
 * three dimensions), each coordinate a (0,m,1)-net, over each pixel's 2^m
 * samples and after it; two pair slots consumed. */
static void test_sobol_3d(void)
{
    lf_sampler s = {LF_SAMPLER_SOBOL, 11, 64, 0, 0};
    double x[64], y[64], z[64];
    for (int px = 0; px < 4; px++) {
        int ok = 1, layout = 1;
        for (int i = 0; i < 64; i++) {
            lf_sample_stream st, st2;
            lf_sample_start(&st, &s, px, 2 * px + 5, (uint32_t)i);
            st2 = st;
            lf_sample_3d_d(&st, &x[i], &y[i], &z[i]);
            ok &= x[i] > 0 && x[i] < 1 && y[i] > 0 && y[i] < 1 && z[i] > 0 && z[i] < 1;
            /* the next pair is the third slot's */
            float a, b, a2, b2;
            lf_sample_skip(&st2);
            lf_sample_skip(&st2);
            lf_sample_2d(&st, &a, &b);
            lf_sample_2d(&st2, &a2, &b2);
            layout &= a == a2 && b == b2;
        }
        CHECK_MSG(ok, "pixel %d: a value outside (0, 1)", px);
        CHECK_MSG(layout, "pixel %d: lf_sample_3d_d does not take exactly two pair slots", px);
        CHECK_MSG(is_t3_net(x, y, z, 6, 1), "pixel %d: (u0, u1, u2) is not a (1,6,3)-net", px);
        /* and the check can fail: Sobol's first three dimensions are no (0,m,3)-net */
        CHECK_MSG(is_t3_net(x, y, z, 6, 0) == 0, "pixel %d: unexpectedly a (0,6,3)-net", px);
        for (int d = 0; d < 3; d++) {
            const double *u = d == 0 ? x : d == 1 ? y : z;
            int seen[64] = {0}, strat = 1;
            for (int i = 0; i < 64; i++)
                strat &= !seen[(int)(u[i] * 64)]++;
            CHECK_MSG(strat, "pixel %d: coordinate %d is not stratified over 64 samples", px, d);
        }
    }
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

/* Exactly one point in each box [i/bx^a, (i+1)/bx^a) x [j/by^b, ...).
 * Radical inverses land exactly on box edges (1/3 is point 1's y), which
 * the 32-bit values of lf_sample_2d_d truncate to up to 2^-32 below: the
 * box index is taken 1e-9 up, far less than the smallest digit (5^-9) of
 * the indices used here. */
static int stratified_boxes(const double *x, const double *y, int n, int nx, int ny)
{
    if (nx * ny != n)
        return 0;
    int *count = calloc((size_t)n, sizeof(int));
    int ok = 1;
    for (int i = 0; i < n; i++) {
        int cx = (int)((x[i] + 1e-9) * nx), cy = (int)((y[i] + 1e-9) * ny);
        if (cx < 0 || cx >= nx || cy < 0 || cy >= ny || count[cy * nx + cx]++)
            ok = 0;
    }
    free(count);
    return ok;
}

/* pbrt-v4's Halton sampler: inside a pixel, the first 2^a 3^b samples
 * stratify the pixel in 2^a x 3^b boxes (radical-inverse intervals of the
 * digits below the pixel's); dimensions 2 and 3 (bases 5 and 7) stratify
 * 5^a x 7^b boxes with every randomisation (digit permutations and Owen
 * scrambling keep each digit position a bijection). */
static void test_halton(void)
{
    static const lf_halton_random rz[3] = {LF_HALTON_PERMUTE_DIGITS, LF_HALTON_OWEN, LF_HALTON_NONE};
    static const int res[][2] = {{640, 480}, {37, 23}, {1, 1}, {300, 2}};
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++) {
            lf_sampler s = {LF_SAMPLER_HALTON, 9, 216, 0, 0};
            s.randomize = rz[r];
            CHECK(lf_sampler_prepare(&s, res[k][0], res[k][1]) == 0);
            static const int pix[][2] = {{0, 0}, {5, 3}, {130, 7}, {639, 479}};
            for (int q = 0; q < 4; q++) {
                int px = pix[q][0] % res[k][0], py = pix[q][1] % res[k][1];
                double x[245], y[245], u[245], v[245]; /* 245 = 5 x 49 */
                for (int i = 0; i < 245; i++) {
                    lf_sample_stream st;
                    lf_sample_start(&st, &s, px, py, (uint32_t)i);
                    lf_sample_2d_d(&st, &x[i], &y[i]);
                    lf_sample_2d_d(&st, &u[i], &v[i]);
                }
                CHECK_MSG(stratified_boxes(x, y, 6, 2, 3) && stratified_boxes(x, y, 36, 4, 9) &&
                              stratified_boxes(x, y, 216, 8, 27),
                          "halton pixel samples, randomization %d, res %dx%d, pixel %d %d", r, res[k][0], res[k][1],
                          px, py);
                CHECK_MSG(stratified_boxes(u, v, 35, 5, 7) && stratified_boxes(u, v, 175, 25, 7) &&
                              stratified_boxes(u, v, 245, 5, 49),
                          "halton dimensions 2,3, randomization %d, res %dx%d", r, res[k][0], res[k][1]);
            }
            /* the unrandomised sequence is the textbook Halton: pixel (0,0)'s
             * first sample is index 0 and dimension 2 is 0 */
            if (rz[r] == LF_HALTON_NONE) {
                lf_sample_stream st;
                lf_sample_start(&st, &s, 0, 0, 1);
                double a, b;
                lf_sample_2d_d(&st, &a, &b);
                float c, d;
                lf_sample_2d(&st, &c, &d);
                /* index stride = 2^e0 3^e1; dimension 2 = radical inverse base 5 of it */
                uint64_t stride = (uint64_t)s.halton_scale[0] * s.halton_scale[1];
                double ri5 = 0, f = 0.2;
                for (uint64_t t = stride; t; t /= 5, f /= 5)
                    ri5 += (double)(t % 5) * f;
                CHECK_NEAR(c, ri5, 1e-6);
            }
            lf_sampler_free(&s);
        }
    /* different pixels get different samples */
    lf_sampler s = {LF_SAMPLER_HALTON, 1, 4, 0, 0};
    CHECK(lf_sampler_prepare(&s, 64, 64) == 0);
    lf_sample_stream a, b;
    lf_sample_start(&a, &s, 3, 4, 0);
    lf_sample_start(&b, &s, 4, 3, 0);
    CHECK(a.halton_index != b.halton_index);
}

/* pmj02bn: every power-of-two prefix of a generated sequence is a
 * (0,k,2)-net; the in-pixel samples (a tile of pixels shares one sequence)
 * form a (0,2)-net in every pixel; the other pairs are a shuffle of the
 * first spp points of a sequence, toroidally shifted (so each pixel's spp
 * values still have one point per 1/spp column and per 1/spp row). */
static void test_pmj02bn(void)
{
    int n = 1 << 14;
    float *xy = malloc(sizeof(float) * 2 * (size_t)n);
    float *x = malloc(sizeof(float) * (size_t)n), *y = malloc(sizeof(float) * (size_t)n);
    CHECK(lf_pmj02bn_generate(3, n, xy) == 0);
    for (int i = 0; i < n; i++)
        x[i] = xy[2 * i], y[i] = xy[2 * i + 1];
    for (int m = 0; m <= 14; m++)
        CHECK_MSG(is_02_net(x, y, m), "pmj02 prefix of 2^%d points is not a (0,%d,2)-net", m, m);
    CHECK(lf_pmj02bn_generate(3, 3, xy) != 0);
    free(xy), free(x), free(y);

    static const int spps[] = {1, 4, 16, 64};
    for (int k = 0; k < 4; k++) {
        lf_sampler s = {LF_SAMPLER_PMJ02BN, 5, spps[k], 0, 0};
        CHECK(lf_sampler_prepare(&s, 200, 100) == 0);
        int spp = spps[k], m = 0;
        while ((1 << m) < spp)
            m++;
        float px[64], py[64], ux[64], uy[64];
        int bad = 0, badcols = 0;
        for (int p = 0; p < 50; p++) {
            for (int i = 0; i < spp; i++) {
                lf_sample_stream st;
                lf_sample_start(&st, &s, 3 * p + 1, 7 * p + 2, (uint32_t)i);
                double a, b;
                lf_sample_2d_d(&st, &a, &b);
                px[i] = (float)a, py[i] = (float)b;
                lf_sample_2d(&st, &ux[i], &uy[i]);
            }
            bad += !is_02_net(px, py, m);
            /* shifted (0,2) points: one per column and per row, cyclically */
            int cols[64] = {0}, rows[64] = {0};
            for (int i = 0; i < spp; i++) {
                cols[(int)(ux[i] * spp) % spp]++;
                rows[(int)(uy[i] * spp) % spp]++;
            }
            for (int i = 0; i < spp; i++)
                badcols += cols[i] > 2 || rows[i] > 2; /* a shift can split one stratum's point pair */
        }
        CHECK_MSG(bad == 0, "pmj02bn spp %d: %d pixels whose samples are not a (0,2)-net", spp, bad);
        CHECK_MSG(badcols == 0, "pmj02bn spp %d: shifted pairs pile up", spp);
        lf_sampler_free(&s);
    }
    lf_sampler s = {LF_SAMPLER_PMJ02BN, 5, 8, 0, 0};
    CHECK(lf_sampler_prepare(&s, 10, 10) != 0); /* not a power of 4 */
}

int main(void)
{
    test_sobol_stratification();
    test_sobol_3d();
    test_stratified();
    test_independent_moments();
    test_determinism();
    test_filters();
    test_distrib();
    test_halton();
    test_pmj02bn();
    return lf_test_end();
}
