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

/* The mean of v[0..n) without its `drop` largest values (sorts v): robust to
 * a few fireflies. */
static double trimmed_mean(double *v, size_t n, size_t drop)
{
    qsort(v, n, sizeof *v, cmp_double);
    size_t keep = n - drop;
    double sum = 0;
    for (size_t i = 0; i < keep; i++)
        sum += v[i];
    return keep ? sum / (double)keep : 0;
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
    double m = trimmed_mean(e, np, np / 1000);
    free(e);
    return m;
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
    double m = trimmed_mean(t, np, np / 200);
    free(t);
    return m;
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

/* Clips the region [x0,x1) x [y0,y1) to the image. */
static void clip_region(const lf_image *im, int *x0, int *y0, int *x1, int *y1)
{
    *x0 = *x0 < 0 ? 0 : *x0, *y0 = *y0 < 0 ? 0 : *y0;
    *x1 = *x1 > im->width ? im->width : *x1, *y1 = *y1 > im->height ? im->height : *y1;
}

/* Contrast energy of a region: mean over pixels of the squared differences
 * of Rec. 709 luminance to the right and lower neighbours, over the squared
 * mean luminance (scale-free, so an exposure change does not move it).
 * Defocus blur lowers it; noise raises it a little. */
double lf_grade_sharpness(const lf_image *im, int x0, int y0, int x1, int y1)
{
    clip_region(im, &x0, &y0, &x1, &y1);
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

/* ---- physical measurements of a wrong image (docs/grading.md, "Measurements") ---- */

static double lum_at(const lf_image *im, int x, int y)
{
    const float *p = lf_image_px(im, x, y);
    return im->channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
}

/* bilinear luminance at (x, y) in pixel-centre coordinates; -1 outside */
static double lum_bilinear(const lf_image *im, double x, double y)
{
    x -= 0.5, y -= 0.5;
    if (x < 0 || y < 0 || x > im->width - 1 || y > im->height - 1)
        return -1;
    int x0 = (int)x, y0 = (int)y, x1 = x0 + 1 < im->width ? x0 + 1 : x0, y1 = y0 + 1 < im->height ? y0 + 1 : y0;
    double fx = x - x0, fy = y - y0;
    return (1 - fy) * ((1 - fx) * lum_at(im, x0, y0) + fx * lum_at(im, x1, y0)) +
           fy * ((1 - fx) * lum_at(im, x0, y1) + fx * lum_at(im, x1, y1));
}

/* relative residual of s ~ k a (k fitted) over the given pairs */
static double fit_residual(const double *s, const double *a, long n)
{
    double sa = 0, aa = 0, ss = 0;
    for (long i = 0; i < n; i++)
        sa += s[i] * a[i], aa += a[i] * a[i], ss += s[i] * s[i];
    if (!(aa > 0) || !(ss > 0))
        return INFINITY;
    double k = sa / aa;
    return (ss - 2 * k * sa + k * k * aa) / ss;
}

static double scale_residual(const lf_image *S, const lf_image *A, double scale)
{
    long n = 0, cap = (long)S->width * S->height;
    double *s = malloc(sizeof *s * (size_t)cap), *a = malloc(sizeof *a * (size_t)cap);
    if (!s || !a) {
        free(s), free(a);
        return INFINITY;
    }
    double cx = 0.5 * S->width, cy = 0.5 * S->height;
    /* the central 80 %: both images have content there for scales 0.8 .. 1.25 */
    for (int y = S->height / 10; y < S->height - S->height / 10; y++)
        for (int x = S->width / 10; x < S->width - S->width / 10; x++) {
            double v = lum_bilinear(A, cx + (x + 0.5 - cx) * scale, cy + (y + 0.5 - cy) * scale);
            if (v < 0)
                continue;
            s[n] = lum_at(S, x, y), a[n] = v, n++;
        }
    double r = n > 16 ? fit_residual(s, a, n) : INFINITY;
    free(s), free(a);
    return r;
}

/* The magnification of the submission's content against the reference's:
 * the factor m with S(x) ~ k A(c + (x - c) m), m > 1 when the submission
 * sees a wider field (tan of the half angle m times the reference's).
 * Searched over 0.8 .. 1.25 in 1 % steps, then a parabola. */
double lf_grade_fit_scale(const lf_image *S, const lf_image *A)
{
    enum { N = 45 };
    double best = INFINITY, r[N], lm[N];
    int bi = N / 2;
    for (int i = 0; i < N; i++) {
        lm[i] = log(0.8) + (log(1.25) - log(0.8)) * i / (N - 1);
        r[i] = scale_residual(S, A, exp(lm[i]));
        if (r[i] < best)
            best = r[i], bi = i;
    }
    double l = lm[bi];
    /* only a magnification that explains most of the difference counts */
    if (!(best < 0.5 * scale_residual(S, A, 1.0)))
        return 1.0;
    if (bi > 0 && bi < N - 1) {
        double den = r[bi - 1] - 2 * r[bi] + r[bi + 1];
        if (den > 0)
            l += 0.5 * (r[bi - 1] - r[bi + 1]) / den * (lm[1] - lm[0]);
    }
    return exp(l);
}

/* luminance of img blurred by a uniform disc of diameter d pixels */
static void disc_blur(const lf_image *im, double d, double *out)
{
    int w = im->width, h = im->height, rad = (int)ceil(0.5 * d);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (d < 1) {
                out[(size_t)y * w + x] = lum_at(im, x, y);
                continue;
            }
            double s = 0, wsum = 0;
            for (int dy = -rad; dy <= rad; dy++)
                for (int dx = -rad; dx <= rad; dx++) {
                    if (dx * dx + dy * dy > 0.25 * d * d)
                        continue;
                    int xx = x + dx, yy = y + dy;
                    xx = xx < 0 ? 0 : xx >= w ? w - 1 : xx;
                    yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
                    s += lum_at(im, xx, yy), wsum++;
                }
            out[(size_t)y * w + x] = s / wsum;
        }
}

/* Extra blur: the disc diameter (pixels, 0..12) whose blur of the reference
 * best matches the submission (> 0: the submission is blurrier), or minus
 * the one whose blur of the submission best matches the reference (< 0: the
 * submission is sharper).  Whole-image least squares with a fitted gain. */
double lf_grade_fit_blur(const lf_image *S, const lf_image *A)
{
    size_t n = (size_t)S->width * S->height;
    double *bs = malloc(sizeof *bs * n), *ba = malloc(sizeof *ba * n), *ls = malloc(sizeof *ls * n),
           *la = malloc(sizeof *la * n);
    if (!bs || !ba || !ls || !la) {
        free(bs), free(ba), free(ls), free(la);
        return 0;
    }
    disc_blur(S, 0, ls);
    disc_blur(A, 0, la);
    double r0 = fit_residual(ls, la, (long)n), best = r0, bd = 0;
    for (double d = 1.5; d <= 12.01; d += 0.5) {
        disc_blur(A, d, ba);
        double r = fit_residual(ls, ba, (long)n);
        if (r < best)
            best = r, bd = d;
        disc_blur(S, d, bs);
        r = fit_residual(la, bs, (long)n);
        if (r < best)
            best = r, bd = -d;
    }
    free(bs), free(ba), free(ls), free(la);
    return best < 0.5 * r0 ? bd : 0; /* only a blur that explains most of the difference */
}

/* Equivalent diameter (pixels) of n bright discs in [x0,x1) x [y0,y1): the
 * pixels brighter than halfway from the region's median to its maximum,
 * as n equal discs.  0 when the region holds no highlight. */
double lf_grade_highlight_diameter(const lf_image *im, int x0, int y0, int x1, int y1, int n)
{
    clip_region(im, &x0, &y0, &x1, &y1);
    if (x1 <= x0 || y1 <= y0 || n < 1)
        return 0;
    size_t m = (size_t)(x1 - x0) * (y1 - y0), k = 0;
    double *v = malloc(sizeof *v * m), mx = 0;
    if (!v)
        return 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            v[k] = lum_at(im, x, y);
            mx = fmax(mx, v[k]);
            k++;
        }
    /* median by partial selection sort would do; a copy sorted is simpler */
    double *c = malloc(sizeof *c * m);
    if (!c) {
        free(v);
        return 0;
    }
    memcpy(c, v, sizeof *c * m);
    for (size_t i = 0; i <= m / 2; i++) /* selection up to the median: regions are small */
        for (size_t j = i + 1; j < m; j++)
            if (c[j] < c[i]) {
                double t = c[i];
                c[i] = c[j], c[j] = t;
            }
    double med = c[m / 2], thr = 0.5 * (med + mx);
    free(c);
    size_t above = 0;
    for (size_t i = 0; i < m; i++)
        above += v[i] > thr;
    free(v);
    if (!(mx > 2 * med + 1e-6))
        return 0;
    return 2 * sqrt((double)above / (n * M_PI));
}
