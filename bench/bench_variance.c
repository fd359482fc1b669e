/* Error per sample, load-independently: renders a scene at several sample
 * counts over several seeds and prints the relative RMSE against a
 * converged reference (mean over the seeds with its standard error), the
 * mean image's relative bias against the reference (a biased estimator
 * shows here), and the rays per camera path (the cost that does not depend
 * on the machine's load).  No wall-clock time decides anything here.
 *
 *   bench_variance SCENE.pbrt [--ref REF.exr | --ref-spp N] [--spp "1 4 16"]
 *                  [--seeds K] [--threads T] [--save-ref OUT.exr]
 *   bench_variance --rmse REF.exr IMG.exr...   (another renderer's images:
 *                  relative RMSE of each against REF, as below)
 *
 * The reference is rendered with seed 1000 at --ref-spp (default 4096)
 * unless --ref names an EXR of the same size (e.g. one written earlier with
 * --save-ref, or another renderer's).  Errors are over all pixels and R, G,
 * B, divided by the reference's mean; the reference's own noise adds
 * e^2 N / N_ref to e^2 and is divided out as in bench/peers/eq_report.py
 * (when the reference was rendered here, or --ref comes with --ref-spp;
 * otherwise the --ref image is taken as exact). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/lf_render.h"

static int render(const char *path, int spp, uint32_t seed, int threads, lf_image *img, double *rays_per_path)
{
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_file(path, &d, &err)) {
        fprintf(stderr, "bench_variance: %s\n", err.msg);
        return -1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.spp = spp;
    o.seed = seed;
    o.has_seed = 1;
    o.threads = threads;
    o.scene_path = path;
    lf_renderer *r;
    int rc = lf_renderer_create(&d, &o, &r, &err);
    if (!rc) {
        rc = lf_renderer_render(r, img, NULL, &err);
        lf_render_stats s = lf_renderer_stats(r);
        if (rays_per_path)
            *rays_per_path = s.camera_paths ? (double)s.rays / s.camera_paths : 0;
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    if (rc)
        fprintf(stderr, "bench_variance: %s\n", err.msg);
    return rc;
}

static double img_mean(const lf_image *a)
{
    double s = 0;
    for (int y = 0; y < a->height; y++)
        for (int x = 0; x < a->width; x++)
            for (int c = 0; c < 3; c++)
                s += lf_image_px(a, x, y)[c];
    return s / (3.0 * a->width * a->height);
}

static double img_mse(const lf_image *a, const lf_image *b)
{
    double s = 0;
    for (int y = 0; y < a->height; y++)
        for (int x = 0; x < a->width; x++)
            for (int c = 0; c < 3; c++) {
                double d = lf_image_px(a, x, y)[c] - lf_image_px(b, x, y)[c];
                s += d * d;
            }
    return s / (3.0 * a->width * a->height);
}

static int rmse_mode(int argc, char **argv)
{
    lf_image ref;
    lf_error err = {0};
    if (lf_image_read(argv[2], &ref, NULL, &err)) {
        fprintf(stderr, "bench_variance: %s\n", err.msg);
        return 1;
    }
    double mref = img_mean(&ref);
    for (int i = 3; i < argc; i++) {
        lf_image img;
        if (lf_image_read(argv[i], &img, NULL, &err) || img.width != ref.width || img.height != ref.height) {
            fprintf(stderr, "bench_variance: %s: %s\n", argv[i], err.msg[0] ? err.msg : "size differs from the reference");
            return 1;
        }
        printf("%s\trel. RMSE %.5f\trel. mean %+.5f\n", argv[i], sqrt(img_mse(&img, &ref)) / mref,
               img_mean(&img) / mref - 1);
        lf_image_free(&img);
    }
    lf_image_free(&ref);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 4 && !strcmp(argv[1], "--rmse"))
        return rmse_mode(argc, argv);
    const char *scene = NULL, *ref_path = NULL, *save_ref = NULL, *spps = "1 4 16";
    int ref_spp = 4096, seeds = 8, threads = 2, ref_spp_given = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--ref") && i + 1 < argc)
            ref_path = argv[++i];
        else if (!strcmp(argv[i], "--ref-spp") && i + 1 < argc)
            ref_spp = atoi(argv[++i]), ref_spp_given = 1;
        else if (!strcmp(argv[i], "--spp") && i + 1 < argc)
            spps = argv[++i];
        else if (!strcmp(argv[i], "--seeds") && i + 1 < argc)
            seeds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--save-ref") && i + 1 < argc)
            save_ref = argv[++i];
        else if (argv[i][0] != '-' && !scene)
            scene = argv[i];
        else {
            fprintf(stderr, "usage: bench_variance SCENE.pbrt [--ref REF.exr | --ref-spp N] [--spp \"1 4 16\"] "
                            "[--seeds K] [--threads T] [--save-ref OUT.exr]\n");
            return 2;
        }
    }
    if (!scene || seeds < 2) {
        fprintf(stderr, "bench_variance: need a scene and at least 2 seeds\n");
        return 2;
    }
    lf_image ref;
    lf_error err = {0};
    int ref_n = 0; /* 0: exact */
    if (ref_path) {
        if (lf_image_read(ref_path, &ref, NULL, &err)) {
            fprintf(stderr, "bench_variance: %s\n", err.msg);
            return 1;
        }
        if (ref_spp_given) /* a reference of that many samples, independent of these */
            ref_n = ref_spp;
    } else {
        if (render(scene, ref_spp, 1000, threads, &ref, NULL))
            return 1;
        ref_n = ref_spp;
        if (save_ref && lf_image_write(save_ref, &ref, NULL, NULL, &err))
            fprintf(stderr, "bench_variance: %s\n", err.msg);
    }
    double mref = img_mean(&ref);
    printf("scene %s, reference %s (mean %.6g), %d seeds\n", scene, ref_path ? ref_path : "rendered here", mref, seeds);
    printf("| spp | rel. RMSE | std. error | rel. bias of the mean image | rays per path |\n|---|---|---|---|---|\n");
    char buf[256];
    snprintf(buf, sizeof buf, "%s", spps);
    for (char *tok = strtok(buf, " ,"); tok; tok = strtok(NULL, " ,")) {
        int spp = atoi(tok);
        double se = 0, se2 = 0, rpp = 0;
        lf_image sum = {0};
        for (int k = 0; k < seeds; k++) {
            lf_image img;
            double rp;
            if (render(scene, spp, 1 + (uint32_t)k, threads, &img, &rp))
                return 1;
            if (img.width != ref.width || img.height != ref.height) {
                fprintf(stderr, "bench_variance: reference is %dx%d, render %dx%d\n", ref.width, ref.height, img.width,
                        img.height);
                return 1;
            }
            double e2 = img_mse(&img, &ref) / (mref * mref);
            if (ref_n)
                e2 /= 1.0 + (double)spp / ref_n;
            double e = sqrt(e2);
            se += e, se2 += e * e, rpp += rp;
            if (!sum.data) {
                sum = img;
            } else {
                for (int y = 0; y < img.height; y++)
                    for (int x = 0; x < img.width; x++)
                        for (int c = 0; c < 3; c++)
                            lf_image_px(&sum, x, y)[c] += lf_image_px(&img, x, y)[c];
                lf_image_free(&img);
            }
        }
        double m = se / seeds, var = fmax(0, se2 / seeds - m * m) * seeds / (seeds - 1);
        double bias = (img_mean(&sum) / seeds - mref) / mref;
        printf("| %d | %.5f | %.5f | %+.5f | %.3f |\n", spp, m, sqrt(var / seeds), bias, rpp / seeds);
        fflush(stdout);
        lf_image_free(&sum);
    }
    lf_image_free(&ref);
    return 0;
}
