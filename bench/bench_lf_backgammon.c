/* bench_lf_backgammon - depth and view synthesis on an HCI 4D light-field
 * benchmark scene (bench/lf_backgammon.sh passes the HCI backgammon folder).
 *
 *   bench_lf_backgammon DIR [--threads N] [--runs N] [--depth-only | --views-only]
 *                       [--save-disp FILE.pfm] [--baseline] [--calibrate]
 *
 * Depth: lf_lightfield_depth on the 9x9 views with no range given (estimated from
 * the data), median wall time of --runs (3) runs; scored as the benchmark
 * toolkit does against gt_disp_lowres.pfm: 15-px border excluded,
 * BadPix(t) = % of pixels with |d - gt| > t for t = 0.07, 0.03, 0.01 and
 * MSE x 100.  Views: from the 5x5 views with even indices, the 16 views
 * with both indices odd, synthesised with per-pixel geometry; mean PSNR in
 * 8-bit sRGB, 15-px border excluded.  --baseline also scores the previous
 * methods (82-slice focal-stack depth, plane blending at disparity 0).
 * --calibrate: also self-calibrate the view positions (lf_lightfield_calibrate_views)
 * from the depth and score the depth again; the views from the 5x5 views
 * calibrated the same way.
 * Diagnostics (environment): LFD_VERBOSE=1 per-view and per-disparity
 * breakdowns; LFD_GTVIEW=1 the views from the ground-truth map; LFD_HALF_GATE=-1
 * without the half gate of the occlusion subsets; LFD_THIN=-1
 * without the thin-structure step (LFD_THIN_RATIO its ratio); LFD_DUMP=DIR
 * writes the 5x5 map (disp5.f32, conf5.f32: 512 x 512 floats) and each
 * synthesised view (syn_R_C.f32: RGB floats, linear) for offline analysis;
 * LFD_DISPIN=FILE.f32 replaces the 5x5 map by such a file. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image/lf_image.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "bench/bench_util.h"

/* The views through the library's folder reader (lightfield/folder.c):
 * HCI layout, parameters.cfg, every view; then equalised as lf_lightfield_open
 * does (LFD_NOEQ=1: not). */
static int load_hci_views(const char *dir, lf_lightfield *lf)
{
    lf_lightfield_folder f;
    lf_lightfield_layout flags;
    lf_error err = {0};
    lf_lightfield_layout_init(&flags);
    int rc = lf_lightfield_folder_scan(dir, &f, &err) || lf_lightfield_folder_load(&f, &flags, lf, &err) ||
             (!getenv("LFD_NOEQ") && lf_lightfield_equalize(lf, &err));
    if (!rc && (lf->views_rescaled || lf->views_dark))
        printf("equalised: %d views rescaled (gains %.3f .. %.3f), %d dark views left out, %zu samples missing\n",
               lf->views_rescaled, lf->gain_lo, lf->gain_hi, lf->views_dark, lf->missing);
    if (rc)
        fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
    lf_lightfield_folder_free(&f);
    return rc;
}

/* A 1-channel PFM (image/pfm.c: rows bottom-up, either byte order). */
static int read_pfm(const char *path, lf_image *img)
{
    lf_error err = {0};
    if (lf_image_read(path, img, NULL, &err))
        return 1;
    if (img->channels != 1) {
        lf_image_free(img);
        return 1;
    }
    return 0;
}

static void write_pfm(const char *path, const lf_image *img)
{
    lf_error err = {0};
    if (lf_image_write(path, img, NULL, NULL, &err))
        fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
}

/* Raw native floats, for the diagnostics (LFD_DUMP, LFD_DISPIN). */
static void write_raw(const char *path, const float *v, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(v, sizeof(float), n, f) != n)
        fprintf(stderr, "bench_lf_backgammon: cannot write %s\n", path);
    if (f)
        fclose(f);
}

static int read_raw(const char *path, float *v, size_t n)
{
    FILE *f = fopen(path, "rb");
    size_t got = f ? fread(v, sizeof(float), n, f) : 0;
    if (f)
        fclose(f);
    if (got != n)
        fprintf(stderr, "bench_lf_backgammon: %s: expected %zu floats\n", path, n);
    return got == n;
}

static void score(const char *name, const lf_image *d, const lf_image *gt, double secs)
{
    const int border = 15;
    double se = 0;
    size_t n = 0, bad[3] = {0, 0, 0};
    const double t[3] = {0.07, 0.03, 0.01};
    for (int y = border; y < gt->height - border; y++)
        for (int x = border; x < gt->width - border; x++) {
            double e = d->data[(size_t)y * d->width + x] - gt->data[(size_t)y * gt->width + x];
            se += e * e;
            for (int k = 0; k < 3; k++)
                bad[k] += fabs(e) > t[k];
            n++;
        }
    double sum_e = 0;
    for (int y = border; y < gt->height - border; y++)
        for (int x = border; x < gt->width - border; x++)
            sum_e += d->data[(size_t)y * d->width + x] - gt->data[(size_t)y * gt->width + x];
    if (getenv("LFD_VERBOSE")) {
        printf("  mean signed error %.4f\n", sum_e / n);
        double bs[16] = {0}, ba[16] = {0};
        size_t bn[16] = {0}, bb[16] = {0};
        for (int y = border; y < gt->height - border; y++)
            for (int x = border; x < gt->width - border; x++) {
                double g = gt->data[(size_t)y * gt->width + x];
                double e = d->data[(size_t)y * d->width + x] - g;
                int k = (int)floor((g + 2) / 0.25);
                k = k < 0 ? 0 : (k > 15 ? 15 : k);
                bs[k] += e, ba[k] += fabs(e), bn[k]++, bb[k] += fabs(e) > 0.07;
            }
        for (int k = 0; k < 16; k++)
            if (bn[k])
                printf("  gt %5.2f..%5.2f: n %6zu mean err %+.4f mean |err| %.4f bad0.07 %5.1f %%\n", -2 + 0.25 * k,
                       -2 + 0.25 * (k + 1), bn[k], bs[k] / bn[k], ba[k] / bn[k], 100.0 * bb[k] / bn[k]);
    }
    printf("%-28s BadPix0.07 %6.2f %%  BadPix0.03 %6.2f %%  BadPix0.01 %6.2f %%  MSEx100 %7.3f", name,
           100.0 * bad[0] / n, 100.0 * bad[1] / n, 100.0 * bad[2] / n, 100.0 * se / n);
    if (secs > 0)
        printf("  time %.2f s", secs);
    printf("\n");
}

static double psnr8(const lf_image *a, const float *b, int border)
{
    double se = 0;
    size_t n = 0;
    for (int y = border; y < a->height - border; y++)
        for (int x = border; x < a->width - border; x++)
            for (int c = 0; c < 3; c++) {
                double e = (double)lf_srgb_encode(a->data[((size_t)y * a->width + x) * 3 + c]) -
                           (double)lf_srgb_encode(b[((size_t)y * a->width + x) * 3 + c]);
                se += e * e;
                n++;
            }
    return se > 0 ? 10 * log10(255.0 * 255.0 / (se / n)) : INFINITY;
}

int main(int argc, char **argv)
{
    const char *dir = NULL, *save = NULL;
    int threads = 2, runs = 3, do_depth = 1, do_views = 1, baseline = 0, calibrate = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--depth-only"))
            do_views = 0;
        else if (!strcmp(argv[i], "--views-only"))
            do_depth = 0;
        else if (!strcmp(argv[i], "--baseline"))
            baseline = 1;
        else if (!strcmp(argv[i], "--calibrate"))
            calibrate = 1;
        else if (!strcmp(argv[i], "--save-disp") && i + 1 < argc)
            save = argv[++i];
        else if (argv[i][0] != '-')
            dir = argv[i];
        else {
            dir = NULL;
            break;
        }
    }
    if (!dir) {
        fprintf(stderr, "usage: bench_lf_backgammon DIR [--threads N] [--runs N] [--depth-only|--views-only] "
                        "[--save-disp FILE.pfm] [--baseline] [--calibrate]\n");
        return 2;
    }
    lf_lightfield lf = {0};
    double t0 = lf_seconds();
    if (load_hci_views(dir, &lf))
        return 1;
    printf("%s: %dx%d views of %dx%d (loaded in %.2f s), %d threads\n", dir, lf.nu, lf.nv, lf.ns, lf.nt, lf_seconds() - t0,
           threads);
    lf_error err = {0};
    if (do_depth) {
        char gtp[4096];
        snprintf(gtp, sizeof gtp, "%s/gt_disp_lowres.pfm", dir);
        lf_image gt;
        if (read_pfm(gtp, &gt)) {
            fprintf(stderr, "bench_lf_backgammon: cannot read %s\n", gtp);
            return 1;
        }
        if (baseline) {
            lf_image af, dm;
            lf_lightfield_refocus_opts ro = lf_lightfield_refocus_defaults();
            ro.threads = threads;
            double s = lf_seconds();
            if (lf_lightfield_allfocus(&lf, &ro, -1.7, 0.7, 82, &af, &dm, &err)) {
                fprintf(stderr, "%s\n", err.msg);
                return 1;
            }
            score("focal stack (82 slices)", &dm, &gt, lf_seconds() - s);
            lf_image_free(&af), lf_image_free(&dm);
        }
        double times[16], cpus[16];
        if (runs > 16)
            runs = 16;
        lf_image disp = {0}, conf = {0};
        double r0 = 0, r1 = 0;
        if (!getenv("LFD_RANGE"))
            lf_lightfield_depth_range(&lf, threads, &r0, &r1, &err);
        printf("estimated disparity range %.3f .. %.3f px/view\n", r0, r1);
        for (int r = 0; r < runs; r++) {
            lf_image_free(&disp), lf_image_free(&conf);
            lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
            o.threads = threads;
            if (getenv("LFD_RANGE"))
                sscanf(getenv("LFD_RANGE"), "%lf %lf", &o.d0, &o.d1);
            if (getenv("LFD_STEP"))
                o.step = atof(getenv("LFD_STEP"));
            if (getenv("LFD_RADIUS"))
                o.radius = atoi(getenv("LFD_RADIUS"));
            if (getenv("LFD_EPS"))
                o.eps = atof(getenv("LFD_EPS"));
            if (getenv("LFD_MR"))
                o.median_radius = atoi(getenv("LFD_MR"));
            if (getenv("LFD_ALPHA"))
                o.defocus_weight = atof(getenv("LFD_ALPHA"));
            if (getenv("LFD_OCC"))
                o.occlusion = atoi(getenv("LFD_OCC"));
            if (getenv("LFD_INTERP"))
                o.interp = atoi(getenv("LFD_INTERP"));
            if (getenv("LFD_REFINE"))
                o.refine = atoi(getenv("LFD_REFINE"));
            if (getenv("LFD_THIN"))
                o.thin = atoi(getenv("LFD_THIN"));
            if (getenv("LFD_THIN_RATIO"))
                o.thin_ratio = atof(getenv("LFD_THIN_RATIO"));
            if (getenv("LFD_HALF_GATE"))
                o.half_gate = atoi(getenv("LFD_HALF_GATE"));
            double s = lf_seconds(), sc = bench_cpu_seconds();
            if (lf_lightfield_depth(&lf, &o, &disp, &conf, &err)) {
                fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                return 1;
            }
            times[r] = lf_seconds() - s, cpus[r] = bench_cpu_seconds() - sc;
        }
        qsort(times, (size_t)runs, sizeof(double), bench_cmp_double);
        qsort(cpus, (size_t)runs, sizeof(double), bench_cmp_double);
        score("lf_lightfield_depth (range auto)", &disp, &gt, times[runs / 2]);
        printf("  depth: median of %d runs: wall %.2f s, CPU %.2f s (all threads)\n", runs, times[runs / 2],
               cpus[runs / 2]);
        if (calibrate) { /* self-calibrated view positions, depth again */
            double *rep = malloc(sizeof(double) * 6 * lf.nu * lf.nv);
            double s = lf_seconds();
            if (!rep || lf_lightfield_calibrate_views(&lf, &disp, &conf, threads, rep, &err)) {
                fprintf(stderr, "bench_lf_backgammon: %s\n", rep ? err.msg : "out of memory");
                return 1;
            }
            double tc = lf_seconds() - s, worst = 0;
            for (int k = 0; k < lf.nu * lf.nv; k++) {
                int iu = k % lf.nu, iv = k / lf.nu;
                double e = fmax(fabs(rep[6 * k] - (iu - lf.nu / 2)), fabs(rep[6 * k + 1] - (iv - lf.nv / 2)));
                worst = e > worst ? e : worst;
                if (getenv("LFD_VERBOSE"))
                    printf("  view (%d,%d): su %+.4f sv %+.4f ox %+.4f oy %+.4f tiles %.0f rms %.4f px\n", iu, iv,
                           rep[6 * k], rep[6 * k + 1], rep[6 * k + 2], rep[6 * k + 3], rep[6 * k + 4], rep[6 * k + 5]);
            }
            printf("  calibrated view positions in %.2f s: largest departure from the grid %.4f view steps\n", tc, worst);
            free(rep);
            lf_image_free(&disp), lf_image_free(&conf);
            lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
            o.threads = threads;
            s = lf_seconds();
            if (lf_lightfield_depth(&lf, &o, &disp, &conf, &err)) {
                fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                return 1;
            }
            score("lf_lightfield_depth (calibrated)", &disp, &gt, lf_seconds() - s);
            free(lf.view_shift);
            lf.view_shift = NULL;
        }
        if (save) {
            write_pfm(save, &disp);
            /* previews: disparity, |error| (x5, clipped), confidence */
            lf_image pv;
            lf_image_alloc(&pv, disp.width * 4, disp.height, 1, &err);
            for (int y = 0; y < disp.height; y++)
                for (int x = 0; x < disp.width; x++) {
                    size_t i = (size_t)y * disp.width + x;
                    float a = (disp.data[i] + 2.f) / 3.f, b = fabsf(disp.data[i] - gt.data[i]) * 5.f, c = conf.data[i];
                    float *row = pv.data + (size_t)y * pv.width;
                    row[x] = powf(fminf(fmaxf(a, 0.f), 1.f), 2.2f);
                    row[x + disp.width] = powf(fminf(b, 1.f), 2.2f);
                    row[x + 2 * disp.width] = powf(fminf(fmaxf(c, 0.f), 1.f), 2.2f);
                    row[x + 3 * disp.width] = powf(fminf(fmaxf((gt.data[i] + 2.f) / 3.f, 0.f), 1.f), 2.2f);
                }
            char pp[4096];
            snprintf(pp, sizeof pp, "%s.png", save);
            lf_image_write(pp, &pv, NULL, NULL, &err);
            lf_image_free(&pv);
        }
        lf_image_free(&disp), lf_image_free(&conf), lf_image_free(&gt);
    }
    if (do_views) {
        /* 5x5 light field of the views with even indices */
        int n5 = (lf.nu + 1) / 2;
        lf_lightfield sub = {0};
        if (lf_lightfield_alloc(&sub, n5, n5, lf.ns, lf.nt, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        sub.disp_v_per_u = 1.0;
        if (!getenv("LFD_NOGAINW") && lf.view_gain && (sub.view_gain = malloc(sizeof(float) * n5 * n5)))
            for (int j = 0; j < n5; j++)
                for (int i = 0; i < n5; i++)
                    sub.view_gain[j * n5 + i] = lf.view_gain[2 * j * lf.nu + 2 * i];
        if (lf.valid && (sub.valid = malloc(sizeof(float) * n5 * n5 * (size_t)lf.ns * lf.nt)))
            for (int j = 0; j < n5; j++)
                for (int i = 0; i < n5; i++)
                    memcpy(sub.valid + ((size_t)j * n5 + i) * lf.ns * lf.nt,
                           lf.valid + ((size_t)2 * j * lf.nu + 2 * i) * lf.ns * lf.nt, sizeof(float) * lf.ns * lf.nt);
        for (int j = 0; j < n5; j++)
            for (int i = 0; i < n5; i++)
                memcpy(lf_lightfield_view(&sub, i, j), lf_lightfield_view(&lf, 2 * i, 2 * j), sizeof(float) * 3 * lf.ns * lf.nt);
        if (getenv("LFD_NOISE")) {
            /* robustness diagnostic: Gaussian noise of LFD_NOISE 8-bit sRGB levels on the source views
             * (added in sRGB, fixed seed), scored against the clean held-out views */
            double sig = atof(getenv("LFD_NOISE")) / 255.0;
            unsigned long long st = 12345;
            size_t nv = (size_t)n5 * n5 * lf.ns * lf.nt * 3;
            for (size_t i = 0; i < nv; i += 2) {
                double u1, u2;
                st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                u1 = ((st >> 11) + 0.5) / 9007199254740992.0;
                st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                u2 = ((st >> 11) + 0.5) / 9007199254740992.0;
                double r = sqrt(-2 * log(u1)), g[2] = {r * cos(6.283185307179586 * u2), r * sin(6.283185307179586 * u2)};
                for (int q = 0; q < 2 && i + q < nv; q++) {
                    float *p = &sub.data[i + q];
                    double e = lf_srgb_encode(*p) / 255.0 + sig * g[q];
                    e = e < 0 ? 0 : (e > 1 ? 1 : e);
                    *p = (float)(e <= 0.04045 ? e / 12.92 : pow((e + 0.055) / 1.055, 2.4));
                }
            }
        }
        lf_image sd = {0}, sc = {0};
        {
            lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
            o.threads = threads;
            if (getenv("LFD_INTERP"))
                o.interp = atoi(getenv("LFD_INTERP"));
            if (getenv("LFD_REFINE"))
                o.refine = atoi(getenv("LFD_REFINE"));
            if (getenv("LFD_THIN"))
                o.thin = atoi(getenv("LFD_THIN"));
            if (getenv("LFD_THIN_RATIO"))
                o.thin_ratio = atof(getenv("LFD_THIN_RATIO"));
            double s = lf_seconds();
            if (lf_lightfield_depth(&sub, &o, &sd, &sc, &err)) {
                fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                return 1;
            }
            printf("5x5 depth (range auto) %.2f s\n", lf_seconds() - s);
            if (getenv("LFD_VERBOSE")) { /* the 5x5 map (per view step of the 9x9 grid) against the ground truth */
                char gtp[4096];
                snprintf(gtp, sizeof gtp, "%s/gt_disp_lowres.pfm", dir);
                lf_image gt;
                if (!read_pfm(gtp, &gt)) {
                    lf_image half = sd;
                    half.data = malloc(sizeof(float) * sd.width * sd.height);
                    for (size_t i = 0; i < (size_t)sd.width * sd.height; i++)
                        half.data[i] = 0.5f * sd.data[i];
                    score("5x5 depth / 2", &half, &gt, 0);
                    free(half.data);
                    lf_image_free(&gt);
                }
            }
            if (calibrate) {
                s = lf_seconds();
                if (lf_lightfield_calibrate_views(&sub, &sd, &sc, threads, NULL, &err)) {
                    fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                    return 1;
                }
                lf_image_free(&sd), lf_image_free(&sc);
                if (lf_lightfield_depth(&sub, &o, &sd, &sc, &err)) {
                    fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                    return 1;
                }
                printf("5x5 views calibrated, depth again: %.2f s\n", lf_seconds() - s);
            }
            if (getenv("LFD_DISPIN") && !read_raw(getenv("LFD_DISPIN"), sd.data, (size_t)sd.width * sd.height))
                return 1;
            if (getenv("LFD_DUMP")) {
                char pp[4096];
                snprintf(pp, sizeof pp, "%s/disp5.f32", getenv("LFD_DUMP"));
                write_raw(pp, sd.data, (size_t)sd.width * sd.height);
                snprintf(pp, sizeof pp, "%s/conf5.f32", getenv("LFD_DUMP"));
                write_raw(pp, sc.data, (size_t)sc.width * sc.height);
            }
            if (getenv("LFD_GTVIEW")) { /* diagnostic: ground-truth geometry */
                char gtp[4096];
                snprintf(gtp, sizeof gtp, "%s/gt_disp_lowres.pfm", dir);
                lf_image gt;
                if (!read_pfm(gtp, &gt)) {
                    for (size_t i = 0; i < (size_t)gt.width * gt.height; i++)
                        sd.data[i] = 2 * gt.data[i], sc.data[i] = 1;
                    lf_image_free(&gt);
                }
            }
        }
        for (int method = baseline ? 0 : 1; method < 2; method++) {
            double sum = 0, worst = INFINITY, secs = 0;
            int count = 0;
            for (int r = 1; r < lf.nv; r += 2)
                for (int c = 1; c < lf.nu; c += 2) {
                    double u = c / 2.0 - (n5 - 1) / 2.0, v = r / 2.0 - (n5 - 1) / 2.0;
                    lf_image out;
                    double s = lf_seconds();
                    int rc;
                    if (method == 0) {
                        rc = lf_lightfield_view_at(&sub, u, v, 0.0, &out, &err);
                    } else {
                        lf_lightfield_view_opts vo = lf_lightfield_view_defaults();
                        vo.threads = threads;
                        vo.disparity = &sd, vo.confidence = &sc;
                        vo.blend = getenv("LFD_BLEND") && *getenv("LFD_BLEND") == '1'; /* diagnostic: the bicubic blend */
                        rc = lf_lightfield_view_depth(&sub, u, v, &vo, &out, &err);
                    }
                    secs += lf_seconds() - s;
                    if (rc) {
                        fprintf(stderr, "bench_lf_backgammon: %s\n", err.msg);
                        return 1;
                    }
                    double p = psnr8(&out, lf_lightfield_view(&lf, c, r), 15);
                    if (getenv("LFD_DUMP")) {
                        char pp[4096];
                        snprintf(pp, sizeof pp, "%s/syn_%d_%d.f32", getenv("LFD_DUMP"), r, c);
                        write_raw(pp, out.data, (size_t)3 * out.width * out.height);
                    }
                    if (getenv("LFD_VERBOSE")) {
                        /* split: pixels within 4 px of a disparity edge of the 5x5 map, and the rest */
                        double se[2] = {0, 0}, sb[2][12] = {{0}}, sdist[2][6] = {{0}};
                        size_t ndist[2][6] = {{0}};
                        size_t nn[2] = {0, 0}, nb[2][12] = {{0}};
                        const float *tv = lf_lightfield_view(&lf, c, r);
                        for (int y = 15; y < out.height - 15; y++)
                            for (int x = 15; x < out.width - 15; x++) {
                                float g = sd.data[(size_t)y * out.width + x];
                                int edge = 0, dist = 5, nearer = 0;
                                for (int j = -4; j <= 4; j++)
                                    for (int i = -4; i <= 4; i++)
                                        if (fabsf(sd.data[(size_t)(y + j) * out.width + x + i] - g) > 0.3f) {
                                            int dd = abs(i) > abs(j) ? abs(i) : abs(j);
                                            edge = 1;
                                            dist = dd < dist ? dd : dist;
                                            nearer |= sd.data[(size_t)(y + j) * out.width + x + i] < g;
                                        }
                                for (int ch = 0; ch < 3; ch++) {
                                    size_t q = ((size_t)y * out.width + x) * 3 + ch;
                                    double e = (double)lf_srgb_encode(out.data[q]) - lf_srgb_encode(tv[q]);
                                    se[edge] += e * e, nn[edge]++;
                                    int bi = (int)floor((g / 2 + 2) / 0.25);
                                    bi = bi < 0 ? 0 : (bi > 11 ? 11 : bi);
                                    sb[edge][bi] += e * e, nb[edge][bi]++;
                                    sdist[nearer][dist] += e * e, ndist[nearer][dist]++;
                                }
                            }
                        printf("  view r%d c%d: %.2f dB (away from edges %.2f dB, near edges %.2f dB, %.1f %% of pixels)\n",
                               r, c, p, 10 * log10(65025.0 * nn[0] / se[0]), 10 * log10(65025.0 * nn[1] / se[1]),
                               100.0 * nn[1] / (nn[0] + nn[1]));
                        if (r == 3 && c == 3)
                            for (int q = 0; q < 2; q++)
                                for (int dd = 1; dd <= (q ? 4 : 5); dd++)
                                    printf("    %s side of an edge %d px away: %.2f dB (%.1f %% of pixels)\n",
                                           q ? "nearer" : "farther", dd,
                                           10 * log10(65025.0 * ndist[q][dd] / (sdist[q][dd] + 1e-9)),
                                           100.0 * ndist[q][dd] / (nn[0] + nn[1]));
                        if (r == 3 && c == 3)
                            for (int bi = 0; bi < 12; bi++)
                                if (nb[0][bi] + nb[1][bi] > 300)
                                    printf("    d/step %5.2f..%5.2f: away %6.2f dB (%5.1f %%) near %6.2f dB (%5.1f %%)\n",
                                           -2 + 0.25 * bi, -1.75 + 0.25 * bi,
                                           10 * log10(65025.0 * nb[0][bi] / (sb[0][bi] + 1e-9)), 100.0 * nb[0][bi] / (nn[0] + nn[1]),
                                           10 * log10(65025.0 * nb[1][bi] / (sb[1][bi] + 1e-9)), 100.0 * nb[1][bi] / (nn[0] + nn[1]));
                    }
                    if (getenv("LFD_VERBOSE") && r == 3 && c == 3) {
                        lf_image_write("/tmp/lfd_v33.png", &out, NULL, NULL, &err);
                        for (size_t i = 0; i < (size_t)out.width * out.height * 3; i++)
                            out.data[i] = 0.5f + 4 * (out.data[i] - lf_lightfield_view(&lf, c, r)[i]);
                        lf_image_write("/tmp/lfd_v33_err.png", &out, NULL, NULL, &err);
                    }
                    sum += p, count++;
                    worst = p < worst ? p : worst;
                    lf_image_free(&out);
                }
            printf("%-28s mean PSNR %.2f dB (worst %.2f) over %d views, %.2f s per view\n",
                   method == 0 ? "views: plane d=0 (4 nearest)" : "views: per-pixel depth", sum / count, worst, count,
                   secs / count);
        }
        lf_lightfield_free(&sub);
        lf_image_free(&sd), lf_image_free(&sc);
    }
    lf_lightfield_free(&lf);
    return 0;
}
