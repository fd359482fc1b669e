/* metrics.c - image comparison that tolerates Monte Carlo noise.
 *
 * The decision metric is the relative MSE of the submission against a
 * reference, divided by the relative MSE between two references rendered
 * with different seeds at the same sample count: for an independent render
 * of the right image both are sums of two equal variances, so the ratio is
 * about 1; a wrong image adds its squared bias.  relMSE is the common
 * renderer-comparison form (x - r)^2 / (r^2 + eps) (e.g. Rousselle et al.
 * 2011), here with the largest 0.1% of per-pixel terms left out so that one
 * firefly does not decide a grade. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grade_internal.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

double lf_grade_relmse(const lf_image *a, const lf_image *ref)
{
    if (a->width != ref->width || a->height != ref->height)
        return INFINITY;
    int ch = a->channels < ref->channels ? a->channels : ref->channels;
    if (ch > 3)
        ch = 3;
    size_t np = (size_t)a->width * (size_t)a->height;
    double *e = malloc(np * sizeof *e);
    if (!e)
        return INFINITY;
    for (size_t i = 0; i < np; i++) {
        double s = 0;
        for (int c = 0; c < ch; c++) {
            double x = a->data[i * (size_t)a->channels + (size_t)c], r = ref->data[i * (size_t)ref->channels + (size_t)c];
            double d = x - r;
            s += d * d / (r * r + 0.01);
        }
        e[i] = isfinite(s) ? s / ch : 1e30;
    }
    qsort(e, np, sizeof *e, cmp_double);
    size_t keep = np - np / 1000;
    double sum = 0;
    for (size_t i = 0; i < keep; i++)
        sum += e[i];
    free(e);
    return keep ? sum / (double)keep : 0;
}

/* Per-pixel squared error of x against reference a, in units of the local
 * Monte Carlo noise: (x - a)^2 / (N + floor), N the 5x5 box average of
 * (a - b)^2 (b: the same reference, another seed), which estimates the
 * variance of a difference of two independent renders, i.e. what an
 * independent correct image shows.  A local estimate keeps a noisy region
 * (bokeh, caustics) from hiding a bias in a clean one.  The floor
 * (1e-5 + 1e-4 a^2) covers noise-free pixels and 8-bit quantisation. */
static double *noise_terms(const lf_image *x, const lf_image *ref, const lf_image *a, const lf_image *b)
{
    int w = a->width, h = a->height;
    int ch = x->channels < a->channels ? x->channels : a->channels;
    if (ch > 3)
        ch = 3;
    size_t np = (size_t)w * (size_t)h;
    double *d2 = malloc(np * sizeof *d2), *t = malloc(np * sizeof *t);
    if (!d2 || !t) {
        free(d2), free(t);
        return NULL;
    }
    for (size_t i = 0; i < np; i++) {
        double s = 0;
        for (int c = 0; c < ch; c++) {
            double d = (double)a->data[i * (size_t)a->channels + c] - b->data[i * (size_t)b->channels + c];
            s += d * d;
        }
        d2[i] = isfinite(s) ? s / ch : 0;
    }
    for (int y = 0; y < h; y++)
        for (int xx = 0; xx < w; xx++) {
            double n = 0;
            int k = 0;
            for (int v = y - 2; v <= y + 2; v++)
                for (int u = xx - 2; u <= xx + 2; u++)
                    if (u >= 0 && v >= 0 && u < w && v < h)
                        n += d2[(size_t)v * w + u], k++;
            n /= k;
            size_t i = (size_t)y * w + xx;
            double s = 0;
            for (int c = 0; c < ch; c++) {
                double r = ref->data[i * (size_t)ref->channels + c], e = x->data[i * (size_t)x->channels + c] - r;
                s += e * e / (n + 1e-5 + 1e-4 * r * r);
            }
            t[i] = isfinite(s) ? s / ch : 1e30;
        }
    free(d2);
    return t;
}

double lf_grade_noise_ratio(const lf_image *x, const lf_image *ref, const lf_image *a, const lf_image *b)
{
    if (x->width != a->width || x->height != a->height || b->width != a->width || b->height != a->height ||
        ref->width != a->width || ref->height != a->height)
        return INFINITY;
    double *t = noise_terms(x, ref, a, b);
    if (!t)
        return INFINITY;
    size_t np = (size_t)a->width * a->height;
    qsort(t, np, sizeof *t, cmp_double);
    size_t keep = np - np / 200;
    double sum = 0;
    for (size_t i = 0; i < keep; i++)
        sum += t[i];
    free(t);
    return keep ? sum / (double)keep : 0;
}

static double luma8(const lf_image *im, size_t i)
{
    const float *p = im->data + i * (size_t)im->channels;
    double y = im->channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
    return lf_srgb_encode((float)y) / 255.0;
}

double lf_grade_ssim(const lf_image *a, const lf_image *b)
{
    if (a->width != b->width || a->height != b->height)
        return NAN;
    int w = a->width, h = a->height, r = 3;
    size_t np = (size_t)w * (size_t)h;
    double *x = malloc(np * sizeof *x), *y = malloc(np * sizeof *y);
    if (!x || !y) {
        free(x), free(y);
        return NAN;
    }
    for (size_t i = 0; i < np; i++)
        x[i] = luma8(a, i), y[i] = luma8(b, i);
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03; /* Wang et al. 2004, L = 1 */
    double total = 0;
    long count = 0;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
            int n = 0;
            for (int v = j - r; v <= j + r; v++)
                for (int u = i - r; u <= i + r; u++) {
                    if (u < 0 || v < 0 || u >= w || v >= h)
                        continue;
                    double p = x[(size_t)v * w + u], q = y[(size_t)v * w + u];
                    sx += p, sy += q, sxx += p * p, syy += q * q, sxy += p * q, n++;
                }
            double mx = sx / n, my = sy / n;
            double vx = sxx / n - mx * mx, vy = syy / n - my * my, cxy = sxy / n - mx * my;
            total += (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            count++;
        }
    free(x), free(y);
    return count ? total / count : NAN;
}

void lf_grade_quantize8(lf_image *img)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    for (size_t i = 0; i < n; i++)
        img->data[i] = lf_srgb_decode(lf_srgb_encode(img->data[i]));
}

/* black (at or below the noise level) -> blue -> green -> yellow -> red
 * (100x the noise level and more), on a log scale */
int lf_grade_heatmap(const lf_image *x, const lf_image *a, const lf_image *b, lf_image *out)
{
    lf_error err = {0};
    if (lf_image_alloc(out, a->width, a->height, 3, &err))
        return -1;
    double *t = noise_terms(x, a, a, b);
    if (!t)
        return 0;
    static const float stops[5][3] = {{0, 0, 0}, {0, 0.2f, 1}, {0, 0.8f, 0.2f}, {1, 0.9f, 0}, {1, 0, 0}};
    for (size_t i = 0; i < (size_t)a->width * a->height; i++) {
        double v = log10(fmax(t[i], 1.0)) * 2.0; /* 0..4 over 1..100x */
        if (!isfinite(v) || v > 4)
            v = 4;
        int k = (int)v;
        if (k > 3)
            k = 3;
        double f = v - k;
        for (int c = 0; c < 3; c++)
            out->data[i * 3 + c] = lf_srgb_decode((unsigned char)(255 * ((1 - f) * stops[k][c] + f * stops[k + 1][c])));
    }
    free(t);
    return 0;
}

/* Variants as images: mistakes that are a function of the right image. */
int lf_grade_post(const char *op, lf_image *img, lf_error *err)
{
    int nx, ny;
    char mode[8];
    double t;
    if (sscanf(op, "flip_tiles:%d:%d:%7s", &nx, &ny, mode) == 3) {
        if (nx < 1 || ny < 1 || img->width % nx || img->height % ny)
            return lf_error_set(err, LF_ERR_PARAM, "post %s: %dx%d tiles do not divide %dx%d", op, nx, ny,
                                img->width, img->height);
        int fx = strchr(mode, 'h') != NULL, fy = strchr(mode, 'v') != NULL;
        lf_image src = *img, dst;
        if (lf_image_alloc(&dst, img->width, img->height, img->channels, err))
            return err->code;
        int tw = img->width / nx, th = img->height / ny;
        for (int y = 0; y < img->height; y++)
            for (int x = 0; x < img->width; x++) {
                int ti = x / tw, tj = y / th;
                int si = fx ? nx - 1 - ti : ti, sj = fy ? ny - 1 - tj : tj;
                memcpy(lf_image_px(&dst, x, y), lf_image_px(&src, si * tw + x % tw, sj * th + y % th),
                       sizeof(float) * (size_t)img->channels);
            }
        lf_image_free(img);
        *img = dst;
        return 0;
    }
    if (sscanf(op, "no_cos4:%lf", &t) == 1) {
        /* divide by cos^4 of the chief ray: tan(theta) = r / (W/2) * tan(hfov/2) */
        double s = t / (img->width / 2.0);
        for (int y = 0; y < img->height; y++)
            for (int x = 0; x < img->width; x++) {
                double dx = (x + 0.5 - img->width / 2.0) * s, dy = (y + 0.5 - img->height / 2.0) * s;
                double c2 = 1.0 / (1.0 + dx * dx + dy * dy); /* cos^2 */
                float *p = lf_image_px(img, x, y);
                for (int c = 0; c < img->channels; c++)
                    p[c] = (float)(p[c] / (c2 * c2));
            }
        return 0;
    }
    return lf_error_set(err, LF_ERR_PARAM, "unknown post-processing op '%s'", op);
}

/* Contrast energy of a region: mean over pixels of the squared differences
 * of Rec. 709 luminance to the right and lower neighbours, over the squared
 * mean luminance (scale-free, so an exposure change does not move it).
 * Defocus blur lowers it; noise raises it a little. */
double lf_grade_sharpness(const lf_image *im, int x0, int y0, int x1, int y1)
{
    if (x0 < 0)
        x0 = 0;
    if (y0 < 0)
        y0 = 0;
    if (x1 > im->width)
        x1 = im->width;
    if (y1 > im->height)
        y1 = im->height;
    double e = 0, m = 0;
    long n = 0;
    int c = im->channels;
    for (int y = y0; y < y1 - 1; y++)
        for (int x = x0; x < x1 - 1; x++) {
            const float *p = lf_image_px(im, x, y), *r = lf_image_px(im, x + 1, y), *d = lf_image_px(im, x, y + 1);
            double l = c >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
            double lr = c >= 3 ? 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2] : r[0];
            double ld = c >= 3 ? 0.2126 * d[0] + 0.7152 * d[1] + 0.0722 * d[2] : d[0];
            e += (l - lr) * (l - lr) + (l - ld) * (l - ld);
            m += l;
            n++;
        }
    if (n == 0 || !(m > 0))
        return 0;
    m /= (double)n;
    return e / (double)n / (m * m);
}

/* Mean of all channels (brightness ratios). */
double lf_grade_mean(const lf_image *im)
{
    double s = 0;
    size_t n = (size_t)im->width * im->height * im->channels;
    for (size_t i = 0; i < n; i++)
        s += isfinite(im->data[i]) ? im->data[i] : 0;
    return n ? s / (double)n : 0;
}
