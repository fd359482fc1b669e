/* bench_lens_rays - cost of camera rays through real lenses.
 *
 * For each shipped lens (wide open, focused at 3 m, full-frame film, 36 x 24
 * raster of 1 mm pixels ... camera-space rays): ns per camera ray with the
 * exit-pupil bounds and with plain rear-disk sampling (camera/lens.c), the
 * useful-ray fraction of each, the exit-pupil precomputation time, and the
 * whole "realistic" camera through the registry against a pinhole
 * ("perspective") and, if registered, "thinlens".  Each both one ray per call
 * (lf_lens_sample_ray, generate_ray) and in batches of 64
 * (lf_lens_sample_rays, generate_rays).  Medians of 5 repeats.
 *
 * usage: bench_lens_rays [rays-per-repeat (default 400000)] [lens-name-filter]
 *   (the filter, a substring such as "dgauss.50", keeps only matching lenses
 *   and skips the pinhole and thinlens rows: for callgrind runs)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera/lens.h"
#include "camera/lf_camera.h"
#include "bench/bench_util.h"

enum { REPEATS = 5 };

static double halton_slow(long i, int base)
{
    double f = 1, r = 0;
    for (; i > 0; i /= base) {
        f /= base;
        r += f * (i % base);
    }
    return r;
}

/* Sample points are precomputed so the timings hold only the camera's work. */
static double *samples;
static long n_samples;
static double halton(long i, int base)
{
    int d = base == 2 ? 0 : base == 3 ? 1 : base == 5 ? 2 : 3;
    return samples[4 * i + d];
}

/* registry camera parameters */
typedef struct store {
    const char *lensfile;
} store;
static double g_float(void *c, const char *name, double def)
{
    (void)c;
    if (!strcmp(name, "aperturediameter"))
        return 1000.0; /* wide open (clamped to the stop) */
    if (!strcmp(name, "focusdistance"))
        return 3.0;
    if (!strcmp(name, "fov"))
        return 40.0;
    return def;
}
static int g_int(void *c, const char *n, int def)
{
    (void)c, (void)n;
    return def;
}
static const char *g_string(void *c, const char *name, const char *def)
{
    store *s = c;
    return !strcmp(name, "lensfile") && s->lensfile ? s->lensfile : def;
}
static int g_floats(void *c, const char *n, double *o, int m)
{
    (void)c, (void)n, (void)o, (void)m;
    return 0;
}
static int g_image(void *c, const char *p, int *w, int *h, float **px, char *e, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(e, n, "no images (%s)", p);
    return -1;
}

enum { BATCH = 64 };

/* ns per generate_ray for a registered camera, and per ray through
 * generate_rays in batches of BATCH (*batch_ns; -1 without a batch entry);
 * also its setup time. */
static double camera_ns(const char *type, const char *lensfile, long n, double *setup_s, double *through,
                        double *batch_ns)
{
    store s = {lensfile};
    lf_camera_params p = {&s, g_float, g_int, g_int, g_string, g_floats, g_image};
    char err[1024] = "", warn[1024] = "";
    lf_camera_create_args a = {sizeof a, &p, 1440, 960, 43.27, 0, 1, LF_SOURCE_DIR "/scenes", err, sizeof err,
                               warn, sizeof warn};
    const lf_camera_type *t = lf_camera_find(type);
    if (!t)
        return -1;
    void *st;
    double t0 = lf_seconds();
    if (t->create(&a, &st)) {
        fprintf(stderr, "%s: %s\n", type, err);
        return -1;
    }
    *setup_s = lf_seconds() - t0;
    double ns[REPEATS];
    long ok = 0;
    for (int r = 0; r < REPEATS; r++) {
        double sink = 0;
        ok = 0;
        t0 = lf_seconds();
        for (long i = 0; i < n; i++) {
            lf_camera_sample cs = {halton(i, 2) * 1440, halton(i, 3) * 960, halton(i, 5), halton(i, 7), 0, 0.5};
            lf_camera_ray ray;
            ray.time = 0, ray.wavelength_nm = 0;
            double w = t->generate_ray(st, &cs, &ray);
            sink += w;
            ok += w > 0;
        }
        ns[r] = (lf_seconds() - t0) / n * 1e9;
        if (sink < 0)
            printf("?");
    }
    *through = (double)ok / n;
    double scalar_ns = bench_median(ns, REPEATS);
    *batch_ns = -1;
    if (t->generate_rays) {
        lf_camera_sample cs[BATCH];
        lf_camera_ray rays[BATCH];
        double w[BATCH];
        for (int r = 0; r < REPEATS; r++) {
            double sink = 0;
            t0 = lf_seconds();
            for (long i0 = 0; i0 < n; i0 += BATCH) {
                int m = n - i0 < BATCH ? (int)(n - i0) : BATCH;
                for (int j = 0; j < m; j++) {
                    long i = i0 + j;
                    cs[j] = (lf_camera_sample){halton(i, 2) * 1440, halton(i, 3) * 960, halton(i, 5), halton(i, 7),
                                               0, 0.5};
                    rays[j].time = 0, rays[j].wavelength_nm = 0;
                }
                t->generate_rays(st, m, cs, rays, w);
                for (int j = 0; j < m; j++)
                    sink += w[j];
            }
            ns[r] = (lf_seconds() - t0) / n * 1e9;
            if (sink < 0)
                printf("?");
        }
        *batch_ns = bench_median(ns, REPEATS);
    }
    t->destroy(st);
    return scalar_ns;
}

int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 400000;
    if (n <= 0)
        n = 400000;
    const char *filter = argc > 2 ? argv[2] : NULL;
    samples = malloc(sizeof(double) * 4 * (size_t)n);
    if (!samples)
        return 1;
    n_samples = n;
    for (long i = 0; i < n; i++)
        for (int d = 0; d < 4; d++)
            samples[4 * i + d] = halton_slow(i + 1, (int[]){2, 3, 5, 7}[d]);
    static const char *const lenses[] = {"dgauss.50mm.dat", "dgauss.100mm.dat", "wide.22mm.dat",
                                         "telephoto.250mm.dat", "fisheye.10mm.dat"};
    const double film_w = 36, film_h = 24, film_r = 0.5 * 43.2666;
    double setup, thr, pin_b = -1, thin_b = -1;
    double pin = filter ? -1 : camera_ns("perspective", NULL, n, &setup, &thr, &pin_b);
    double thin = !filter && lf_camera_find("thinlens") ? camera_ns("thinlens", NULL, n, &setup, &thr, &thin_b) : -1;
    printf("bench_lens_rays: %ld rays per repeat, median of %d; full-frame film, wide open, focus 3 m\n", n, REPEATS);
    if (pin > 0)
        printf("pinhole (perspective) camera: %.1f ns/ray, %.1f ns/ray in batches of %d\n", pin, pin_b, BATCH);
    if (thin > 0)
        printf("thinlens camera:              %.1f ns/ray, %.1f ns/ray in batches of %d\n", thin, thin_b, BATCH);
    printf("\n%-20s %8s %9s %9s %8s %9s %8s %10s %10s %9s %8s\n", "lens", "pupil s", "ns bound", "batch", "useful",
           "ns disk", "useful", "camera ns", "cam batch", "x pinhole", "setup s");
    for (size_t k = 0; k < sizeof lenses / sizeof lenses[0]; k++) {
        if (filter && !strstr(lenses[k], filter))
            continue;
        char path[1024];
        lf_error err = {0};
        snprintf(path, sizeof path, LF_SOURCE_DIR "/scenes/lenses/%s", lenses[k]);
        lf_lens L;
        if (lf_lens_load(path, &L, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        lf_lens_set_stop_diameter(&L, 1e3, NULL);
        if (lf_lens_focus_thick(&L, 3000.0, &L.film_distance_mm, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        lf_lens_pupil P;
        double build[REPEATS];
        for (int r = 0; r < REPEATS; r++) {
            double t0 = lf_seconds();
            lf_lens_pupil_build(&L, film_r, 0, &P);
            build[r] = lf_seconds() - t0;
        }
        double ns[2], useful[2];
        for (int mode = 0; mode < 2; mode++) {
            double t[REPEATS];
            long traced = 0, passed = 0;
            for (int r = 0; r < REPEATS; r++) {
                traced = passed = 0;
                double t0 = lf_seconds();
                for (long i = 0; i < n; i++) {
                    double fx = (halton(i, 2) - 0.5) * film_w, fy = (halton(i, 3) - 0.5) * film_h;
                    double u = halton(i, 5), v = halton(i, 7), rx, ry;
                    if (mode == 0 && !(lf_lens_pupil_sample(&P, fx, fy, u, v, &rx, &ry) > 0))
                        continue; /* no light at this film point: nothing traced */
                    traced++;
                    lf_lens_ray out;
                    passed += lf_lens_sample_ray(&L, &P, mode == 0, fx, fy, u, v, NULL, &out) > 0;
                }
                t[r] = (lf_seconds() - t0) / n * 1e9;
            }
            ns[mode] = bench_median(t, REPEATS);
            useful[mode] = traced ? (double)passed / traced : 0;
        }
        /* The same film samples with the bounds through lf_lens_sample_rays,
         * BATCH at a time (film points without light included: the batch
         * call skips them itself). */
        double tb[REPEATS];
        for (int r = 0; r < REPEATS; r++) {
            double fx[BATCH], fy[BATCH], u[BATCH], v[BATCH], w[BATCH], sink = 0;
            lf_lens_ray out[BATCH];
            double t0 = lf_seconds();
            for (long i0 = 0; i0 < n; i0 += BATCH) {
                int m = n - i0 < BATCH ? (int)(n - i0) : BATCH;
                for (int j = 0; j < m; j++) {
                    long i = i0 + j;
                    fx[j] = (halton(i, 2) - 0.5) * film_w, fy[j] = (halton(i, 3) - 0.5) * film_h;
                    u[j] = halton(i, 5), v[j] = halton(i, 7);
                }
                lf_lens_sample_rays(&L, &P, 1, m, fx, fy, u, v, NULL, NULL, NULL, out, w);
                for (int j = 0; j < m; j++)
                    sink += w[j];
            }
            tb[r] = (lf_seconds() - t0) / n * 1e9;
            if (sink < 0)
                printf("?");
        }
        double cam_b;
        double cam = camera_ns("realistic", path, n, &setup, &thr, &cam_b);
        printf("%-20s %8.3f %9.1f %9.1f %7.1f%% %9.1f %7.1f%% %10.1f %10.1f %9.1f %8.3f\n", lenses[k],
               bench_median(build, REPEATS), ns[0], bench_median(tb, REPEATS), 100 * useful[0], ns[1], 100 * useful[1], cam, cam_b,
               pin > 0 ? cam / pin : NAN, setup);
        lf_lens_free(&L);
    }
    printf("\npupil s: exit-pupil bound precomputation (64 bins x 16 strips); ns bound / ns disk: lens.c sampling\n"
           "+ tracing per film sample with the bounds / over the whole rear disk (lf_lens_sample_ray); batch: ns\n"
           "bound through lf_lens_sample_rays, %d rays per call; useful: rays that get through among those\n"
           "traced; camera ns: the registered \"realistic\" camera's generate_ray (raster -> camera space);\n"
           "cam batch: its generate_rays, %d rays per call; x pinhole: camera ns / the pinhole's; setup s: its\n"
           "create() (parse, focus, bounds, useful-fraction estimate)\n",
           BATCH, BATCH);
    return 0;
}
