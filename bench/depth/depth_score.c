/* depth_score - scores a disparity map against ground truth as the HCI 4D
 * light-field benchmark's toolkit does, and draws the error images (the
 * depth failure-mode benchmark, bench/depth/run.sh; docs/depth.md).
 *
 *   depth_score D.pfm GT.pfm [--border 15] [--view CENTRE.png]
 *               [--error ERR.png] [--bad BAD.png] [--disp DISP.png]
 *
 * Prints one line of numbers:
 *   BadPix0.07 BadPix0.03 BadPix0.01 MSEx100 d_p1 d_p99 gt_p1 gt_p99
 * BadPix(t) = % of pixels with |d - gt| > t, MSE x 100 = 100 mean (d - gt)^2,
 * both over the image minus a 15-px border (the toolkit's, and
 * bench/bench_lf_backgammon.c's); d_p1 .. d_p99 and gt_p1 .. gt_p99 are
 * the 1st and 99th percentiles of the estimate and the truth there (a
 * range cut short shows as d_p99 < gt_p99).  Exit 1 on unreadable or
 * mismatched inputs, 2 on bad usage.
 *
 * Images (8-bit PNG, the map's size; the border is darkened):
 *   --error: d - gt, red where the estimate is nearer (larger disparity),
 *            blue where it is farther; brightness log-scaled from 0.01 px
 *            (black) through 0.07 (0.42) to 1 px and beyond (full colour).
 *   --bad:   the centre view in grey (--view; mid grey without it) with the
 *            pixels over 0.07 in red (nearer) or blue (farther).
 *   --disp:  the estimate beside the truth, one colour scale (turbo) over
 *            the truth's 1st..99th percentile range padded by 10 %. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/lf_image.h"


/* sRGB code value in [0, 1] to linear: lf_image_write encodes 8-bit files
 * with the sRGB curve, so colours chosen on screen are decoded first. */
static float srgb_to_linear(double v)
{
    v = v < 0 ? 0 : (v > 1 ? 1 : v);
    return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
}

static void put(lf_image *img, int x, int y, double r, double g, double b)
{
    float *p = img->data + ((size_t)y * img->width + x) * 3;
    p[0] = srgb_to_linear(r), p[1] = srgb_to_linear(g), p[2] = srgb_to_linear(b);
}

/* Turbo colour map (Mikhailov 2019), its published polynomial fit. */
static void turbo(double t, double *r, double *g, double *b)
{
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    *r = 0.13572138 + t * (4.61539260 + t * (-42.66032258 + t * (132.13108234 + t * (-152.94239396 + t * 59.28637943))));
    *g = 0.09140261 + t * (2.19418839 + t * (4.84296658 + t * (-14.18503333 + t * (4.27729857 + t * 2.82956604))));
    *b = 0.10667330 + t * (12.64194608 + t * (-60.58204836 + t * (110.36276771 + t * (-89.90310912 + t * 27.34824973))));
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The p-quantile (0..1) of v[0..n), which it sorts. */
static float quantile(float *v, size_t n, double p)
{
    qsort(v, n, sizeof *v, cmp_float);
    size_t i = (size_t)(p * (double)(n - 1) + 0.5);
    return v[i < n ? i : n - 1];
}

static int write_png(const char *path, const lf_image *img)
{
    lf_error err = {0};
    if (lf_image_write(path, img, NULL, NULL, &err)) {
        fprintf(stderr, "depth_score: %s\n", err.msg);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *dpath = NULL, *gpath = NULL, *view = NULL, *errpng = NULL, *badpng = NULL, *disppng = NULL;
    int border = 15;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--border") && i + 1 < argc)
            border = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--view") && i + 1 < argc)
            view = argv[++i];
        else if (!strcmp(argv[i], "--error") && i + 1 < argc)
            errpng = argv[++i];
        else if (!strcmp(argv[i], "--bad") && i + 1 < argc)
            badpng = argv[++i];
        else if (!strcmp(argv[i], "--disp") && i + 1 < argc)
            disppng = argv[++i];
        else if (argv[i][0] != '-' && !dpath)
            dpath = argv[i];
        else if (argv[i][0] != '-' && !gpath)
            gpath = argv[i];
        else {
            dpath = NULL;
            break;
        }
    }
    if (!dpath || !gpath || border < 0) {
        fprintf(stderr, "usage: depth_score D.pfm GT.pfm [--border 15] [--view CENTRE.png] [--error ERR.png] "
                        "[--bad BAD.png] [--disp DISP.png]\n");
        return 2;
    }
    lf_image d = {0}, gt = {0}, v = {0};
    lf_error err = {0};
    if (lf_image_read(dpath, &d, NULL, &err) || lf_image_read(gpath, &gt, NULL, &err)) {
        fprintf(stderr, "depth_score: %s\n", err.msg);
        return 1;
    }
    if (d.channels != 1 || gt.channels != 1 || d.width != gt.width || d.height != gt.height ||
        2 * border >= gt.width || 2 * border >= gt.height) {
        fprintf(stderr, "depth_score: %s (%dx%d, %d channels) and %s (%dx%d, %d channels) do not compare\n", dpath,
                d.width, d.height, d.channels, gpath, gt.width, gt.height, gt.channels);
        return 1;
    }
    if (view && (lf_image_read(view, &v, NULL, &err) || v.width != d.width || v.height != d.height)) {
        fprintf(stderr, "depth_score: %s: %s\n", view, err.code ? err.msg : "not the map's size");
        return 1;
    }
    const int w = gt.width, h = gt.height;
    const double t[3] = {0.07, 0.03, 0.01};
    size_t n = 0, bad[3] = {0, 0, 0};
    double se = 0;
    float *ds = malloc(sizeof(float) * (size_t)w * h), *gs = malloc(sizeof(float) * (size_t)w * h);
    if (!ds || !gs)
        return 1;
    for (int y = border; y < h - border; y++)
        for (int x = border; x < w - border; x++) {
            size_t i = (size_t)y * w + x;
            double e = (double)d.data[i] - gt.data[i];
            if (!isfinite(e))
                e = 1e3; /* a non-finite estimate is bad at every threshold */
            se += e * e;
            for (int k = 0; k < 3; k++)
                bad[k] += fabs(e) > t[k];
            ds[n] = isfinite(d.data[i]) ? d.data[i] : 0.f, gs[n] = gt.data[i];
            n++;
        }
    float dlo = quantile(ds, n, 0.01), dhi = quantile(ds, n, 0.99);
    float glo = quantile(gs, n, 0.01), ghi = quantile(gs, n, 0.99);
    printf("%.3f %.3f %.3f %.4f %.3f %.3f %.3f %.3f\n", 100.0 * bad[0] / n, 100.0 * bad[1] / n, 100.0 * bad[2] / n,
           100.0 * se / n, dlo, dhi, glo, ghi);

    int rc = 0;
    lf_image img = {0};
    if (errpng || badpng) {
        if (lf_image_alloc(&img, w, h, 3, &err))
            return 1;
        for (int pass = 0; pass < 2; pass++) {
            const char *path = pass ? badpng : errpng;
            if (!path)
                continue;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    size_t i = (size_t)y * w + x;
                    double e = (double)d.data[i] - gt.data[i];
                    int in = x >= border && x < w - border && y >= border && y < h - border;
                    double dim = in ? 1.0 : 0.35, r, g, b;
                    if (!isfinite(e))
                        e = 1e3;
                    if (pass == 0) {
                        double a = fabs(e) > 0.01 ? log10(fabs(e) / 0.01) / 2 : 0;
                        a = a > 1 ? 1 : a;
                        r = e > 0 ? a : 0.25 * a, g = 0.25 * a, b = e > 0 ? 0.25 * a : a;
                        if (!in)
                            r = g = b = 0.2;
                    } else {
                        double grey = 0.5;
                        if (v.data) {
                            const float *p = v.data + i * v.channels;
                            double lum = v.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
                            grey = 0.25 + 0.5 * pow(lum < 0 ? 0 : (lum > 1 ? 1 : lum), 1 / 2.2);
                        }
                        r = g = b = grey;
                        if (fabs(e) > 0.07)
                            r = e > 0 ? 1 : 0.1, g = 0.1, b = e > 0 ? 0.1 : 1;
                    }
                    put(&img, x, y, r * dim, g * dim, b * dim);
                }
            rc |= write_png(path, &img);
        }
        lf_image_free(&img);
    }
    if (disppng) {
        double pad = 0.1 * (ghi - glo) + 1e-3, lo = glo - pad, hi = ghi + pad;
        if (lf_image_alloc(&img, 2 * w, h, 3, &err))
            return 1;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int k = 0; k < 2; k++) {
                    double val = (k ? gt.data : d.data)[(size_t)y * w + x], r, g, b;
                    turbo((val - lo) / (hi - lo), &r, &g, &b);
                    put(&img, x + k * w, y, r, g, b);
                }
        rc |= write_png(disppng, &img);
        lf_image_free(&img);
    }
    free(ds), free(gs);
    lf_image_free(&d), lf_image_free(&gt), lf_image_free(&v);
    return rc;
}
