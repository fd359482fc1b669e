/* The sensor stage's cost (Film "raw", render/lf_sensor.h): lf_sensor_expose
 * on a 12-megapixel film (4000 x 3000, a mid-grey scene with a gradient) with
 * every noise term on, with only shot noise, and noiseless; medians of 5 runs,
 * one thread (the stage runs after the render, on the calling thread).
 * Prints nanoseconds per pixel and milliseconds per megapixel. */
#include <stdio.h>

#include "bench_util.h"
#include "render/lf_sensor.h"

int main(void)
{
    enum { W = 4000, H = 3000, RUNS = 5 };
    lf_image film;
    lf_error err = {0};
    if (lf_image_alloc(&film, W, H, 3, &err))
        return 1;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = lf_image_px(&film, x, y);
            p[0] = p[1] = p[2] = (float)(2e-7 * (0.1 + (double)x / W)); /* about 100 .. 15000 e- */
        }
    static const char *const names[3] = {"all noise terms", "shot noise only", "noiseless"};
    for (int v = 0; v < 3; v++) {
        lf_sensor s;
        lf_sensor_defaults(&s);
        s.full_width = W;
        if (v == 1)
            s.readnoise = s.darkcurrent = s.dsnu = s.prnu = 0;
        if (v == 2)
            s.noise = 0;
        if (lf_sensor_prepare(&s, &err))
            return 1;
        double t[RUNS];
        for (int r = 0; r < RUNS; r++) {
            lf_image raw;
            double t0 = lf_seconds();
            if (lf_sensor_expose(&s, &film, 0, 0, &raw, &err))
                return 1;
            t[r] = lf_seconds() - t0;
            lf_image_free(&raw);
        }
        double m = bench_median(t, RUNS);
        printf("sensor stage, %s: %.1f ns/pixel, %.1f ms per megapixel (12 MP in %.3f s)\n", names[v],
               m * 1e9 / ((double)W * H), m * 1e3 / (W * H * 1e-6), m);
    }
    lf_image_free(&film);
    return 0;
}
