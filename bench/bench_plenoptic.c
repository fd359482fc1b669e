/* bench_plenoptic: cost of the plenoptic camera against the thin lens and
 * the pinhole.
 *
 *   build/bin/bench_plenoptic [repeats]
 *
 * Part 1, camera only: generate_ray calls per second (one thread, 2^20
 * stratified samples per repeat) for "perspective" (pinhole), "thinlens"
 * (or perspective + lensradius when thinlens is not registered) and
 * "plenoptic" (the demo's matched design, 15 px per microlens, and a
 * focused-plenoptic variant whose sensor points see several microlenses).
 * Part 2, whole renders of the light-field demo world
 * (scenes/lightfield/world.pbrt, 480 x 320, 4 spp, maxdepth 3, 2 threads):
 * camera paths per second with each camera.  Prints medians over the
 * repeats (default 5) and the ratios; docs/lightfield.md records the
 * figures with the machine and date.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera/lf_camera.h"
#include "render/lf_render.h"
#include "bench/bench_util.h"

#include "tests/camera_store.h"

static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images (%s)", path);
    return -1;
}

enum { W = 960, H = 640 };

/* generate_ray calls per second, median over repeats; -1 if the camera fails */
static double camera_rate(const char *type, store *s, int repeats, double *zero_fraction)
{
    const lf_camera_type *t = lf_camera_find(type);
    if (!t)
        return -1;
    char err[512] = "", warn[512] = "";
    lf_camera_params p = {s, g_float, g_int, g_bool, g_string, g_floats, g_image};
    lf_camera_create_args a = {sizeof a, &p, W, H, 35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes", err, sizeof err,
                               warn, sizeof warn};
    void *c = NULL;
    if (t->create(&a, &c)) {
        fprintf(stderr, "%s: %s\n", type, err);
        return -1;
    }
    const int n = 1 << 20, side = 1 << 10;
    double rates[32], sink = 0;
    long zero = 0;
    for (int r = 0; r < repeats; r++) {
        double t0 = lf_seconds();
        for (int k = 0; k < n; k++) {
            /* film point on a 1024 x 1024 lattice over the film, lens point by a
             * 2-d additive recurrence (R2), so both cover their domains */
            double fx = ((k % side) + 0.5) / side * W, fy = ((k / side) + 0.5) / side * H;
            double lu = fmod(0.5 + k * 0.7548776662466927, 1.0), lv = fmod(0.5 + k * 0.5698402909980532, 1.0);
            lf_camera_sample cs = {fx, fy, lu, lv, 0.0, 0.5};
            lf_camera_ray ray;
            double w = t->generate_ray(c, &cs, &ray);
            sink += w + ray.dir[2] * (w > 0);
            zero += !(w > 0);
        }
        rates[r] = n / (lf_seconds() - t0);
    }
    if (sink == 12345.678)
        printf("(unlikely)\n");
    *zero_fraction = (double)zero / ((double)n * repeats);
    t->destroy(c);
    return bench_median(rates, repeats);
}

/* camera paths per second of a whole render of the demo world */
static double render_rate(const char *camera_line, int repeats)
{
    char text[2048];
    snprintf(text, sizeof text,
             "LookAt 0 0 0  0 0 1  0 1 0\n%s\n"
             "Film \"rgb\" \"integer xresolution\" [480] \"integer yresolution\" [320]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [4]\nIntegrator \"path\" \"integer maxdepth\" [3]\n"
             "PixelFilter \"box\"\nWorldBegin\nInclude \"world.pbrt\"\n",
             camera_line);
    double rates[32];
    for (int r = 0; r < repeats; r++) {
        lf_scene_desc d;
        lf_error err = {0};
        if (lf_scene_parse_string(text, LF_SOURCE_DIR "/scenes/lightfield/bench.pbrt", &d, &err)) {
            fprintf(stderr, "parse: %s\n", err.msg);
            return -1;
        }
        lf_render_opts o = lf_render_opts_default();
        o.threads = 2;
        lf_renderer *rd;
        if (lf_renderer_create(&d, &o, &rd, &err)) {
            fprintf(stderr, "create: %s\n", err.msg);
            lf_scene_desc_free(&d);
            return -1;
        }
        lf_image img;
        if (lf_renderer_render(rd, &img, NULL, &err)) {
            fprintf(stderr, "render: %s\n", err.msg);
            lf_renderer_free(rd);
            lf_scene_desc_free(&d);
            return -1;
        }
        lf_render_stats st = lf_renderer_stats(rd);
        rates[r] = st.camera_paths / st.seconds;
        lf_image_free(&img);
        lf_renderer_free(rd);
        lf_scene_desc_free(&d);
    }
    return bench_median(rates, repeats);
}

int main(int argc, char **argv)
{
    int repeats = argc > 1 ? atoi(argv[1]) : 5;
    if (repeats < 1 || repeats > 31)
        repeats = 5;
    printf("bench_plenoptic: %d repeats, medians; film %dx%d\n\n", repeats, W, H);
    printf("camera only (generate_ray, 1 thread, 2^20 samples):\n");
    store pin = {{{"fov", {36}, 1, NULL}}, 1};
    int have_thin = lf_camera_find("thinlens") != NULL;
    store thin = {{{"focallength", {50}, 1, NULL}, {"fstop", {2.8}, 1, NULL}, {"focusdistance", {2.5}, 1, NULL}}, 3};
    store thin_p = {{{"fov", {36}, 1, NULL}, {"lensradius", {0.00893}, 1, NULL}, {"focaldistance", {2.5}, 1, NULL}}, 3};
    store plen = {{{"focallength", {50}, 1, NULL}, {"fstop", {2.8}, 1, NULL}, {"focusdistance", {2.5}, 1, NULL},
                   {"microlenses", {64}, 1, NULL}},
                  4};
    store plen2 = {{{"focallength", {50}, 1, NULL}, {"fstop", {2.8}, 1, NULL}, {"focusdistance", {2.5}, 1, NULL},
                    {"microlenses", {64}, 1, NULL}, {"sensoroffset", {0.6}, 1, NULL}},
                   5};
    double z0, z1, z2, z3;
    double r_pin = camera_rate("perspective", &pin, repeats, &z0);
    double r_thin = have_thin ? camera_rate("thinlens", &thin, repeats, &z1) : camera_rate("perspective", &thin_p, repeats, &z1);
    double r_plen = camera_rate("plenoptic", &plen, repeats, &z2);
    double r_plen2 = camera_rate("plenoptic", &plen2, repeats, &z3);
    printf("  %-34s %8.2f M rays/s\n", "perspective (pinhole)", r_pin * 1e-6);
    printf("  %-34s %8.2f M rays/s  (%.2fx pinhole)\n", have_thin ? "thinlens 50mm f/2.8" : "perspective + lensradius",
           r_thin * 1e-6, r_thin / r_pin);
    printf("  %-34s %8.2f M rays/s  (%.2fx thin lens; %.1f%% weight 0)\n", "plenoptic 64 lenses, matched", r_plen * 1e-6,
           r_plen / r_thin, 100 * z2);
    printf("  %-34s %8.2f M rays/s  (%.2fx thin lens; %.1f%% weight 0)\n", "plenoptic 2.0 (sensoroffset 0.6mm)",
           r_plen2 * 1e-6, r_plen2 / r_thin, 100 * z3);

    printf("\nwhole render, scenes/lightfield/world.pbrt, 480x320, 4 spp, maxdepth 3, 2 threads:\n");
    double p_pin = render_rate("Camera \"perspective\" \"float fov\" [25.6]", repeats);
    double p_thin = have_thin ? render_rate("Camera \"thinlens\" \"float fstop\" [2.8] \"float focusdistance\" [2.5]", repeats)
                              : render_rate("Camera \"perspective\" \"float fov\" [25.6] \"float lensradius\" [0.00893] "
                                            "\"float focaldistance\" [2.5]",
                                            repeats);
    double p_plen = render_rate("Camera \"plenoptic\" \"float fstop\" [2.8] \"float focusdistance\" [2.5] "
                                "\"integer microlenses\" [32]",
                                repeats);
    printf("  %-34s %8.3f M paths/s\n", "perspective (pinhole)", p_pin * 1e-6);
    printf("  %-34s %8.3f M paths/s  (%.2fx pinhole)\n", have_thin ? "thinlens" : "perspective + lensradius",
           p_thin * 1e-6, p_thin / p_pin);
    printf("  %-34s %8.3f M paths/s  (%.2fx thin lens)\n", "plenoptic 32 lenses, matched", p_plen * 1e-6,
           p_plen / p_thin);
    return 0;
}
