/* bench_lightfield - light-field throughput (not a test): medians of repeats.
 *
 *   build/bin/bench_lightfield [--quick]
 *
 * refocus: 9 x 9 views of 512 x 512 RGB float (and half), 2 threads, a new sub-pixel
 *          disparity each frame; the plain sum of the 81 views (disparity 0)
 *          is the memory-bandwidth reference.
 * fourier: 9 x 9 x 256 x 256 (the 4D spectrum of 512 x 512 views needs
 *          0.8 GB): precomputation once, then per-frame time.
 * decode:  a 4096 x 4096 plenoptic raw (square grid, pitch 10.3 px, rotated).
 * synth:   600 x 600, 64 spp, from 16 x 16 cameras of 128 x 128 pixels.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image/lf_image.h"
#include "lightfield/lf_lightfield.h"
#include "bench/bench_util.h"

static void fill(lf_lightfield *lf)
{
    size_t n = (size_t)lf->nu * lf->nv * lf->ns * lf->nt * 3;
    unsigned s = 1;
    for (size_t i = 0; i < n; i++) {
        s = s * 1664525u + 1013904223u;
        lf->data[i] = (float)(s >> 8) / 16777216.0f;
    }
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && !strcmp(argv[1], "--quick");
    lf_error err = {0};
    char model[256] = "unknown";
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        char line[512];
        while (fgets(line, sizeof line, f))
            if (!strncmp(line, "model name", 10)) {
                char *c = strchr(line, ':');
                if (c)
                    snprintf(model, sizeof model, "%s", c + 2);
                model[strcspn(model, "\n")] = 0;
                break;
            }
        fclose(f);
    }
    printf("machine: %s\n", model);
    int reps = quick ? 5 : 21;

    /* refocus */
    {
        lf_lightfield lf;
        if (lf_lightfield_alloc(&lf, 9, 9, 512, 512, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        fill(&lf);
        lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults();
        o.threads = 2;
        double t[64];
        lf_image img;
        for (int pass = 0; pass < 2; pass++) {
            double cpu[64];
            for (int k = 0; k < reps; k++) {
                o.disparity_px = pass ? 0.0 : 0.37 + 0.113 * k;
                double t0 = lf_seconds(), c0 = bench_cpu_seconds();
                lf_lightfield_refocus(&lf, &o, &img, &err);
                t[k] = lf_seconds() - t0, cpu[k] = bench_cpu_seconds() - c0;
                lf_image_free(&img);
            }
            double m = bench_median(t, reps);
            printf("refocus 9x9x512x512 RGB float, 2 threads, %s: median %.1f ms = %.1f frames/s, %.1f ms CPU "
                   "(%d frames)\n",
                   pass ? "disparity 0 (plain sum of views)" : "sub-pixel disparities", m * 1e3, 1 / m,
                   bench_median(cpu, reps) * 1e3, reps);
        }
        /* half-float storage */
        if (lf_lightfield_make_half(&lf, &err) == 0) {
            o.use_half = 1;
            double cpu[64];
            for (int k = 0; k < reps; k++) {
                o.disparity_px = 0.37 + 0.113 * k;
                double t0 = lf_seconds(), c0 = bench_cpu_seconds();
                lf_lightfield_refocus(&lf, &o, &img, &err);
                t[k] = lf_seconds() - t0, cpu[k] = bench_cpu_seconds() - c0;
                lf_image_free(&img);
            }
            double m = bench_median(t, reps);
            printf("refocus 9x9x512x512 RGB half, 2 threads, sub-pixel disparities: median %.1f ms = %.1f frames/s, "
                   "%.1f ms CPU (%d frames)\n",
                   m * 1e3, 1 / m, bench_median(cpu, reps) * 1e3, reps);
        }
        lf_lightfield_free(&lf);
    }

    /* Fourier slice */
    {
        lf_lightfield lf;
        lf_lightfield_alloc(&lf, 9, 9, 256, 256, &err);
        fill(&lf);
        lf_lightfield_fourier *fs = NULL;
        double t0 = lf_seconds();
        if (lf_lightfield_fourier_new(&lf, NULL, 2.0, &fs, &err)) {
            fprintf(stderr, "%s\n", err.msg);
        } else {
            double pre = lf_seconds() - t0, t[64];
            for (int k = 0; k < reps; k++) {
                lf_image img;
                double t1 = lf_seconds();
                lf_lightfield_fourier_refocus(fs, 0.37 + 0.113 * k, &img, &err);
                t[k] = lf_seconds() - t1;
                lf_image_free(&img);
            }
            double m = bench_median(t, reps);
            lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults();
            double ts[64];
            for (int k = 0; k < reps; k++) {
                lf_image img;
                o.disparity_px = 0.37 + 0.113 * k;
                double t1 = lf_seconds();
                lf_lightfield_refocus(&lf, &o, &img, &err);
                ts[k] = lf_seconds() - t1;
                lf_image_free(&img);
            }
            printf("fourier slice 9x9x256x256 (u,v padded to 18x18): precompute %.2f s, per frame median %.1f ms "
                   "(shift-and-add on the same field: %.1f ms)\n",
                   pre, m * 1e3, bench_median(ts, reps) * 1e3);
            lf_lightfield_fourier_release(fs);
        }
        lf_lightfield_free(&lf);
    }

    /* decode */
    {
        lf_image raw;
        if (lf_image_alloc(&raw, 4096, 4096, 3, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        for (size_t i = 0; i < (size_t)4096 * 4096 * 3; i++)
            raw.data[i] = (float)((i * 2654435761u) >> 8 & 0xffff) / 65536.0f;
        lf_lightfield_layout lay, none, r;
        lf_lightfield_layout_init(&lay);
        lf_lightfield_layout_init(&none);
        lay.kind = LF_LIGHTFIELD_PLENOPTIC, lay.pitch_px = 10.3, lay.rotation_rad = 0.01;
        lay.offset_px[0] = lay.offset_px[1] = 5.2;
        lay.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_ROTATION | LF_LIGHTFIELD_HAVE_OFFSET;
        lf_lightfield_layout_resolve(&lay, &none, 4096, 4096, &r, &err);
        int n = quick ? 1 : 3;
        double t[8];
        lf_lightfield lf = {0};
        for (int k = 0; k < n; k++) {
            double t0 = lf_seconds();
            lf_lightfield_decode(&raw, &r, NULL, &lf, &err);
            t[k] = lf_seconds() - t0;
            if (k + 1 < n)
                lf_lightfield_free(&lf);
        }
        printf("decode 4096x4096 plenoptic raw (pitch 10.3 px, %d x %d lenses -> %d x %d views of %d x %d): median %.0f ms "
               "(%d runs, 1 thread)\n",
               r.lens_x, r.lens_y, lf.nu, lf.nv, lf.ns, lf.nt, bench_median(t, n) * 1e3, n);
        lf_lightfield_free(&lf);
        lf_image_free(&raw);
    }

    /* synth */
    {
        lf_lightfield lf;
        lf_lightfield_alloc(&lf, 16, 16, 128, 128, &err);
        fill(&lf);
        lf_lightfield_layout *l = &lf.layout;
        l->kind = LF_LIGHTFIELD_CAMERA_ARRAY, l->cams_x = l->cams_y = 16;
        l->grid_bounds[0] = l->grid_bounds[2] = -0.5, l->grid_bounds[1] = l->grid_bounds[3] = 0.5;
        l->fov_deg = 40, l->tile_w = l->tile_h = 128;
        l->have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_BOUNDS | LF_LIGHTFIELD_HAVE_FOV | LF_LIGHTFIELD_HAVE_TILE;
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = o.height = 600, o.fov_deg = 35, o.spp = 64, o.lens_radius = 0.05, o.focal_distance = 3;
        o.pos[2] = -0.2, o.threads = 2;
        int n = quick ? 1 : 3;
        double t[8], cpu[8];
        for (int k = 0; k < n; k++) {
            lf_image img;
            double t0 = lf_seconds(), c0 = bench_cpu_seconds();
            lf_lightfield_synth(&lf, &o, &img, NULL, NULL, &err);
            t[k] = lf_seconds() - t0, cpu[k] = bench_cpu_seconds() - c0;
            lf_image_free(&img);
        }
        double mc = bench_median(cpu, n);
        printf("synth 600x600, 64 spp, lens radius 0.05, 16x16 cameras of 128x128, 2 threads: median %.2f s wall, "
               "%.2f s CPU = %.0f ns CPU per sample (%d runs; target: under 2 s on 2 cores)\n",
               bench_median(t, n), mc, mc * 1e9 / (600.0 * 600 * 64), n);
        lf_lightfield_free(&lf);
    }
    return 0;
}
