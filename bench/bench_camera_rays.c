/* bench_camera_rays: nanoseconds per camera ray (one thread) for pbrt's
 * pinhole, pbrt's perspective with a lens, and the physical thinlens with
 * each aperture shape: one ray per generate_ray call, and in batches of 64
 * through generate_rays (what lfrender calls); the ratio to the pinhole.
 *
 *   build/bin/bench_camera_rays [samples_millions=2] [repeats=7]
 *
 * Each configuration draws the same 65536 pre-generated samples (fits in
 * cache, so memory traffic is not measured) over and over until the sample
 * count is reached; the figure is the median over the repeats.
 * docs/thinlens.md records the output with the machine and date. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera/lf_camera.h"
#include "bench/bench_util.h"

typedef struct kv {
    const char *name;
    double v;
    const char *s;
} kv;
typedef struct config {
    const char *label;
    const char *camera;
    kv p[6];
} config;

static const kv *find(void *ctx, const char *name)
{
    const config *c = ctx;
    for (int i = 0; i < 6 && c->p[i].name; i++)
        if (!strcmp(c->p[i].name, name))
            return &c->p[i];
    return NULL;
}
static double g_float(void *ctx, const char *name, double def)
{
    const kv *k = find(ctx, name);
    return k && !k->s ? k->v : def;
}
static int g_int(void *ctx, const char *name, int def)
{
    const kv *k = find(ctx, name);
    return k && !k->s ? (int)k->v : def;
}
static int g_bool(void *ctx, const char *name, int def)
{
    return g_int(ctx, name, def);
}
static const char *g_string(void *ctx, const char *name, const char *def)
{
    const kv *k = find(ctx, name);
    return k && k->s ? k->s : def;
}
static int g_floats(void *ctx, const char *name, double *out, int max)
{
    (void)ctx, (void)name, (void)out, (void)max;
    return 0;
}
/* The image aperture: a 256 x 256 heart-free, honest test pattern: an
 * annulus with a soft (graded) rim, so the sampling table is non-trivial. */
static int g_image(void *ctx, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)ctx, (void)path, (void)err, (void)n;
    const int S = 256;
    float *p = malloc(sizeof(float) * S * S);
    if (!p)
        return -1;
    for (int y = 0; y < S; y++)
        for (int x = 0; x < S; x++) {
            double r = hypot((x + 0.5) / S * 2 - 1, (y + 0.5) / S * 2 - 1);
            p[y * S + x] = r < 0.3 ? 0.f : r < 0.9 ? 1.f : r < 1 ? (float)((1 - r) * 10) : 0.f;
        }
    *w = *h = S;
    *px = p;
    return 0;
}

enum { NS = 65536, W = 1920, H = 1280 };

int main(int argc, char **argv)
{
    double millions = argc > 1 ? atof(argv[1]) : 2.0;
    int repeats = argc > 2 ? atoi(argv[2]) : 7;
    if (!(millions > 0) || repeats < 1 || repeats > 101) {
        fprintf(stderr, "usage: bench_camera_rays [samples_millions>0] [repeats 1..101]\n");
        return 2;
    }
    long total = ((long)(millions * 1e6) + 63) / 64 * 64; /* whole batches */
    static const config configs[] = {
        {"pinhole (perspective, lensradius 0)", "perspective", {{"fov", 40, NULL}}},
        {"perspective + lens, circle", "perspective",
         {{"fov", 40, NULL}, {"lensradius", 0.05, NULL}, {"focaldistance", 3, NULL}}},
        {"perspective + lens, 6-blade polygon", "perspective",
         {{"fov", 40, NULL}, {"lensradius", 0.05, NULL}, {"focaldistance", 3, NULL}, {"aperture", 0, "polygon"}}},
        {"thinlens, circle", "thinlens", {{"fstop", 2, NULL}, {"focusdistance", 3, NULL}}},
        {"thinlens, 6-blade polygon", "thinlens",
         {{"fstop", 2, NULL}, {"focusdistance", 3, NULL}, {"aperture", 0, "polygon"}, {"blades", 6, NULL}}},
        {"thinlens, 5-point star", "thinlens",
         {{"fstop", 2, NULL}, {"focusdistance", 3, NULL}, {"aperture", 0, "star"}}},
        {"thinlens, image (256x256)", "thinlens",
         {{"fstop", 2, NULL}, {"focusdistance", 3, NULL}, {"aperture", 0, "ring.exr"}}},
    };
    const int nc = (int)(sizeof configs / sizeof configs[0]);
    lf_camera_sample *samples = malloc(sizeof *samples * NS);
    if (!samples)
        return 1;
    unsigned st = 12345u;
    for (int i = 0; i < NS; i++) {
        double u[4];
        for (int k = 0; k < 4; k++) {
            st = st * 1664525u + 1013904223u;
            u[k] = (st >> 8) * 0x1p-24;
        }
        lf_camera_sample s = {u[0] * W, u[1] * H, u[2], u[3], 0.0, 0.5};
        samples[i] = s;
    }
    printf("ns per camera ray (ray generation only, 1 thread, %dx%d film), median of %d repeats of %ld samples\n", W,
           H, repeats, total);
    printf("%-40s %10s %10s %12s %10s\n", "camera", "ns/ray", "vs pinhole", "batch ns/ray", "vs pinhole");
    double pinhole = 0, pinhole_b = 0, checksum = 0;
    enum { B = 64 };
    lf_camera_ray rays[B];
    double weights[B];
    for (int c = 0; c < nc; c++) {
        lf_camera_params p = {(void *)&configs[c], g_float, g_int, g_bool, g_string, g_floats, g_image};
        char err[512] = "", warn[512] = "";
        lf_camera_create_args a = {sizeof a, &p, W, H, 35.0, 0.0, 1.0, ".", err, sizeof err, warn, sizeof warn};
        const lf_camera_type *t = lf_camera_find(configs[c].camera);
        void *state = NULL;
        if (!t || t->create(&a, &state)) {
            fprintf(stderr, "%s: %s\n", configs[c].label, err);
            return 1;
        }
        double times[101];
        for (int r = 0; r < repeats; r++) {
            double t0 = lf_seconds(), acc = 0;
            for (long i = 0; i < total; i++) {
                lf_camera_ray ray;
                acc += t->generate_ray(state, &samples[i & (NS - 1)], &ray) * ray.dir[2];
            }
            times[r] = (lf_seconds() - t0) / (double)total * 1e9;
            checksum += acc;
        }
        qsort(times, (size_t)repeats, sizeof times[0], bench_cmp_double);
        double med = times[repeats / 2];
        for (int r = 0; r < repeats; r++) {
            double t0 = lf_seconds(), acc = 0;
            for (long i = 0; i < total; i += B) {
                lf_camera_generate_rays(t, state, B, &samples[i & (NS - 1)], rays, weights);
                for (int k = 0; k < B; k++)
                    acc += weights[k] * rays[k].dir[2];
            }
            times[r] = (lf_seconds() - t0) / (double)total * 1e9;
            checksum += acc;
        }
        qsort(times, (size_t)repeats, sizeof times[0], bench_cmp_double);
        double med_b = times[repeats / 2];
        if (c == 0)
            pinhole = med, pinhole_b = med_b;
        printf("%-40s %10.2f %10.2f %12.2f %10.2f\n", configs[c].label, med, med / pinhole, med_b,
               med_b / pinhole_b);
        t->destroy(state);
    }
    printf("(checksum %g)\n", checksum);
    free(samples);
    return 0;
}
