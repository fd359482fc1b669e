/* lf_test_texture.h - a smooth procedural texture for the light-field tests
 * that synthesise views themselves (test_lightfield_depth, _grid, _range):
 * value noise, one unit per cell, in [0, 1), the same at every view so the
 * ground truth comes from the geometry alone; a seeded Gaussian for
 * the views' noise; and a supersampled pinhole view of a traced scene. */
#ifndef LF_TEST_TEXTURE_H
#define LF_TEST_TEXTURE_H

#include <math.h>
#include <stdint.h>

static inline double hash2(int i, int j)
{
    uint32_t h = (uint32_t)i * 374761393u + (uint32_t)j * 668265263u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return ((h ^ (h >> 16)) & 0xffffff) / 16777216.0;
}

/* smooth value noise, one unit per cell */
static inline double vnoise(double x, double y)
{
    int i = (int)floor(x), j = (int)floor(y);
    double fx = x - i, fy = y - j;
    fx = fx * fx * (3 - 2 * fx), fy = fy * fy * (3 - 2 * fy);
    double a = hash2(i, j), b = hash2(i + 1, j), c = hash2(i, j + 1), d = hash2(i + 1, j + 1);
    return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

/* Gaussian deviate (Box-Muller on a 64-bit LCG, state *st) */
static inline double lf_test_gauss(unsigned long long *st)
{
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    double a = ((*st >> 11) + 0.5) / 9007199254740992.0;
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    double b = ((*st >> 11) + 0.5) / 9007199254740992.0;
    return sqrt(-2 * log(a)) * cos(2 * M_PI * b);
}

/* A pinhole view, w x h px, focal length f px, principal point at the
 * image centre moved by (ox, oy) px, from (cx, cy, 0) looking along +z
 * with y up in the world: each pixel the mean of ss x ss rays, the colour
 * of a ray from trace(cx, cy, dx, dy, col) along (dx, dy, 1). */
typedef double (*lf_test_trace_fn)(double cx, double cy, double dx, double dy, float col[3]);
static inline void lf_test_render_view(float *dst, int w, int h, int ss, double f, double cx, double cy, double ox,
                                       double oy, lf_test_trace_fn trace)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc[3] = {0, 0, 0};
            for (int j = 0; j < ss; j++)
                for (int i = 0; i < ss; i++) {
                    double px = x + (i + 0.5) / ss - w / 2.0 - ox, py = y + (j + 0.5) / ss - h / 2.0 - oy;
                    float c[3];
                    trace(cx, cy, px / f, -py / f, c);
                    for (int k = 0; k < 3; k++)
                        acc[k] += c[k];
                }
            for (int k = 0; k < 3; k++)
                dst[((size_t)y * w + x) * 3 + k] = (float)(acc[k] / (ss * ss));
        }
}

/* A view of the tilted plane Z = z0 + gx X + gy Y textured with value
 * noise (two octaves), from the pinhole at (cx, cy, 0), w x h px, focal
 * length f px, ss x ss rays per pixel: grey level * (0.15 + 0.6 n) + 0.05 k
 * per channel k, plus Gaussian noise sigma of full scale from the LCG
 * state seed.  hit: the depth along (dx, dy, 1) and the point hit. */
static inline double lf_test_plane_hit(double z0, double gx, double gy, double cx, double cy, double dx, double dy,
                                       double *X, double *Y)
{
    double t = (z0 + gx * cx + gy * cy) / (1 - gx * dx - gy * dy);
    if (X)
        *X = cx + t * dx, *Y = cy + t * dy;
    return t;
}
static inline void lf_test_plane_view(float *dst, int w, int h, int ss, double f, double cx, double cy, double z0,
                                      double gx, double gy, double level, double sigma, unsigned long long seed)
{
    unsigned long long st = seed;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc = 0;
            for (int j = 0; j < ss; j++)
                for (int i = 0; i < ss; i++) {
                    double X, Y, dx = (x + (i + 0.5) / ss - w / 2.0) / f, dy = -(y + (j + 0.5) / ss - h / 2.0) / f;
                    lf_test_plane_hit(z0, gx, gy, cx, cy, dx, dy, &X, &Y);
                    acc += 0.6 * vnoise(X * 15, Y * 15) + 0.4 * vnoise(X * 6 + 7, Y * 6 + 3);
                }
            for (int k = 0; k < 3; k++)
                dst[((size_t)y * w + x) * 3 + k] =
                    (float)(level * (0.15 + 0.6 * acc / (ss * ss) + 0.05 * k) + sigma * lf_test_gauss(&st));
        }
}

#endif
