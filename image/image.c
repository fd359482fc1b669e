/* image.c - lf_image memory, header attributes, sRGB, comparison, and the
 * format-independent half of reading and writing: extension dispatch,
 * non-finite checks, tonemapping to 8 bits and atomic replacement of the
 * target file.  Format codecs live in exr.c and oiio_adapter.cpp. */
#include "lf_image.h"
#include "base/lf_file_write.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "image_internal.h"
#include "oiio_adapter.h"

/* ---------------------------------------------------------------- images */

int lf_image_check_size(long long width, long long height, long long channels, const char *what, int code,
                        lf_error *err)
{
    if (width <= 0 || height <= 0 || channels <= 0)
        return lf_error_set(err, code, "%s: invalid image size %lldx%lld with %lld channels", what, width, height,
                            channels);
    /* Each factor is checked before multiplying so the products cannot
     * overflow even for sizes read from a hostile header. */
    unsigned long long w = (unsigned long long)width, h = (unsigned long long)height;
    unsigned long long c = (unsigned long long)channels;
    if (w > LF_IMAGE_MAX_PIXELS || h > LF_IMAGE_MAX_PIXELS || w * h > LF_IMAGE_MAX_PIXELS)
        return lf_error_set(err, code, "%s: image size %lldx%lld exceeds the limit of 2^31 pixels", what, width,
                            height);
    if (c > LF_IMAGE_MAX_BYTES || w * h * c > LF_IMAGE_MAX_BYTES / sizeof(float))
        return lf_error_set(err, code, "%s: image of %lldx%lld with %lld channels exceeds the 8 GiB limit", what,
                            width, height, channels);
    return LF_OK;
}

int lf_image_alloc(lf_image *img, int width, int height, int channels, lf_error *err)
{
    if (!img)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_alloc: img is NULL");
    memset(img, 0, sizeof *img);
    int rc = lf_image_check_size(width, height, channels, "lf_image_alloc", LF_ERR_PARAM, err);
    if (rc)
        return rc;
    size_t n = (size_t)width * (size_t)height * (size_t)channels;
    img->data = calloc(n, sizeof(float));
    if (!img->data)
        return lf_error_set(err, LF_ERR_NOMEM, "lf_image_alloc: out of memory for %dx%dx%d floats", width, height,
                            channels);
    img->width = width;
    img->height = height;
    img->channels = channels;
    return LF_OK;
}

void lf_image_free(lf_image *img)
{
    if (!img)
        return;
    free(img->data);
    memset(img, 0, sizeof *img);
}

size_t lf_image_count_nonfinite(const lf_image *img)
{
    if (!img || !img->data)
        return 0;
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels, bad = 0;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(img->data[i]))
            bad++;
    return bad;
}

/* ------------------------------------------------------------ attributes */

static void attr_free_value(lf_attr *at)
{
    free(at->s);
    free(at->v);
    at->s = NULL;
    at->v = NULL;
}

static int attrs_nomem(const char *name, lf_error *err)
{
    return lf_error_set(err, LF_ERR_NOMEM, "out of memory for attribute \"%s\"", name ? name : "");
}

/* Takes ownership of value's payload (s, v) whether it succeeds or not, so
 * callers never leak on the error path. */
static int attrs_put(lf_attrs *a, const char *name, lf_attr *value, lf_error *err)
{
    if (!a || !name) {
        attr_free_value(value);
        return lf_error_set(err, LF_ERR_PARAM, "an attribute needs a list and a name");
    }
    for (size_t i = 0; i < a->count; i++) {
        if (strcmp(a->items[i].name, name) == 0) {
            char *keep_name = a->items[i].name;
            attr_free_value(&a->items[i]);
            a->items[i] = *value;
            a->items[i].name = keep_name;
            return LF_OK;
        }
    }
    char *dup = strdup(name);
    if (!dup) {
        attr_free_value(value);
        return attrs_nomem(name, err);
    }
    if (a->count == a->cap) {
        size_t cap = a->cap ? a->cap * 2 : 8;
        lf_attr *items = realloc(a->items, cap * sizeof *items);
        if (!items) {
            free(dup);
            attr_free_value(value);
            return attrs_nomem(name, err);
        }
        a->items = items;
        a->cap = cap;
    }
    a->items[a->count] = *value;
    a->items[a->count].name = dup;
    a->count++;
    return LF_OK;
}

int lf_attrs_set_string(lf_attrs *a, const char *name, const char *value, lf_error *err)
{
    lf_attr v = {.type = LF_ATTR_STRING};
    v.s = strdup(value ? value : "");
    if (!v.s)
        return attrs_nomem(name, err);
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_int(lf_attrs *a, const char *name, int value, lf_error *err)
{
    lf_attr v = {.type = LF_ATTR_INT, .i = value};
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_float(lf_attrs *a, const char *name, float value, lf_error *err)
{
    lf_attr v = {.type = LF_ATTR_FLOAT, .d = value};
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_double(lf_attrs *a, const char *name, double value, lf_error *err)
{
    lf_attr v = {.type = LF_ATTR_DOUBLE, .d = value};
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_floats(lf_attrs *a, const char *name, const float *values, int n, lf_error *err)
{
    if (n < 0 || (n > 0 && !values))
        return lf_error_set(err, LF_ERR_PARAM, "attribute \"%s\": %d values", name ? name : "", n);
    lf_attr v = {.type = LF_ATTR_FLOATS, .n = n};
    if (n > 0) {
        v.v = malloc((size_t)n * sizeof(float));
        if (!v.v)
            return attrs_nomem(name, err);
        memcpy(v.v, values, (size_t)n * sizeof(float));
    }
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_m44d(lf_attrs *a, const char *name, const double m[16], lf_error *err)
{
    if (!m)
        return lf_error_set(err, LF_ERR_PARAM, "attribute \"%s\": no matrix", name ? name : "");
    lf_attr v = {.type = LF_ATTR_M44D};
    memcpy(v.m, m, sizeof v.m);
    return attrs_put(a, name, &v, err);
}

int lf_attrs_set_copy(lf_attrs *a, const lf_attr *x, lf_error *err)
{
    switch (x->type) {
    case LF_ATTR_STRING: return lf_attrs_set_string(a, x->name, x->s, err);
    case LF_ATTR_INT: return lf_attrs_set_int(a, x->name, x->i, err);
    case LF_ATTR_FLOAT: return lf_attrs_set_float(a, x->name, (float)x->d, err);
    case LF_ATTR_DOUBLE: return lf_attrs_set_double(a, x->name, x->d, err);
    case LF_ATTR_FLOATS: return lf_attrs_set_floats(a, x->name, x->v, x->n, err);
    case LF_ATTR_M44D: return lf_attrs_set_m44d(a, x->name, x->m, err);
    }
    return lf_error_set(err, LF_ERR_PARAM, "attribute \"%s\": unknown type %d", x->name ? x->name : "", (int)x->type);
}

const lf_attr *lf_attrs_get(const lf_attrs *a, const char *name)
{
    if (!a || !name)
        return NULL;
    for (size_t i = 0; i < a->count; i++)
        if (strcmp(a->items[i].name, name) == 0)
            return &a->items[i];
    return NULL;
}

void lf_attrs_free(lf_attrs *a)
{
    if (!a)
        return;
    for (size_t i = 0; i < a->count; i++) {
        free(a->items[i].name);
        attr_free_value(&a->items[i]);
    }
    free(a->items);
    memset(a, 0, sizeof *a);
}

/* Moves every attribute of src into dst (replacing same-named ones) and
 * empties src. */
static int attrs_move(lf_attrs *dst, lf_attrs *src)
{
    int rc = LF_OK;
    for (size_t i = 0; i < src->count; i++) {
        lf_attr *at = &src->items[i];
        if (!rc)
            rc = attrs_put(dst, at->name, at, NULL); /* takes the payload */
        else
            attr_free_value(at);
        free(at->name);
        at->s = NULL;
        at->v = NULL;
    }
    free(src->items);
    memset(src, 0, sizeof *src);
    return rc;
}

/* ------------------------------------------------------------------ sRGB */

/* IEC 61966-2-1 transfer functions, the exact piecewise curve. */
double lf_srgb_from_linear(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

unsigned char lf_srgb_encode(float linear)
{
    double v = linear;
    if (!(v > 0.0)) /* also catches NaN */
        v = 0.0;
    if (v > 1.0)
        v = 1.0;
    double c = lf_srgb_from_linear(v) * 255.0 + 0.5;
    return (unsigned char)(c > 255.0 ? 255.0 : c);
}

float lf_srgb_decode(unsigned char v)
{
    return (float)srgb_to_linear(v / 255.0);
}

/* Every channel but alpha from sRGB to linear, in place.  An 8-bit file
 * arrives as floats k / 255, so the curve is tabulated for the 256 codes,
 * in both ways the float can have been formed (k / 255 rounded once, or
 * k times 1/255f): the result is bit for bit what srgb_to_linear gives
 * (one pow per sample took 8 % of `lftool depth` on a 9 x 9 x 512^2 PNG
 * folder); other values (16-bit files) take the curve itself. */
static void srgb_decode_image(lf_image *img, int alpha_channel)
{
    float fa[256], fb[256], ta[256], tb[256];
    for (int k = 0; k < 256; k++) {
        fa[k] = (float)(k / 255.0), fb[k] = (float)k * (1.0f / 255.0f);
        ta[k] = (float)srgb_to_linear(fa[k]), tb[k] = (float)srgb_to_linear(fb[k]);
    }
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < n; p++)
        for (int c = 0; c < img->channels; c++) {
            if (c == alpha_channel)
                continue;
            float *v = &img->data[p * (size_t)img->channels + (size_t)c];
            float q = *v * 255.f + 0.5f;
            int k = q >= 0.f && q < 256.f ? (int)q : -1;
            if (k >= 0 && *v == fa[k])
                *v = ta[k];
            else if (k >= 0 && *v == fb[k])
                *v = tb[k];
            else
                *v = (float)srgb_to_linear(*v);
        }
}

/* ------------------------------------------------------------ comparison */

int lf_image_mse(const lf_image *a, const lf_image *b, double *mse, lf_error *err)
{
    if (!a || !b || !mse || !a->data || !b->data)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_mse: NULL image or result");
    if (a->width != b->width || a->height != b->height)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_mse: image sizes differ (%dx%d vs %dx%d)", a->width,
                            a->height, b->width, b->height);
    int nc = a->channels < b->channels ? a->channels : b->channels;
    double sum = 0.0;
    for (int y = 0; y < a->height; y++) {
        for (int x = 0; x < a->width; x++) {
            const float *pa = lf_image_px(a, x, y), *pb = lf_image_px(b, x, y);
            for (int c = 0; c < nc; c++) {
                double d = (double)pa[c] - (double)pb[c];
                sum += d * d;
            }
        }
    }
    *mse = sum / ((double)a->width * (double)a->height * (double)nc);
    return LF_OK;
}

int lf_image_psnr(const lf_image *a, const lf_image *b, double *psnr_db, lf_error *err)
{
    if (!psnr_db)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_psnr: NULL result");
    double mse;
    int rc = lf_image_mse(a, b, &mse, err);
    if (rc)
        return rc;
    /* peak = 1.0, so PSNR = 10 log10(1 / MSE) */
    *psnr_db = mse == 0.0 ? INFINITY : -10.0 * log10(mse);
    return LF_OK;
}

/* --------------------------------------------------------- file plumbing */

static const char *path_extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    return dot && dot != base ? dot + 1 : "";
}

static int ext_is(const char *ext, const char *const *list)
{
    for (; *list; list++)
        if (strcasecmp(ext, *list) == 0)
            return 1;
    return 0;
}

/* Formats OpenImageIO stores as float; every other format gets 8-bit sRGB. */
static const char *const float_exts[] = {"tif", "tiff", "hdr", "rgbe", NULL};

/* Linear floats -> 8-bit: exposure, clamp, sRGB curve.  Alpha (the last
 * channel of 2- and 4-channel images) is coverage, not light: it is only
 * clamped and quantised. */
static unsigned char *tonemap_8bit(const lf_image *img, float exposure, lf_tonemap op)
{
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
    unsigned char *out = malloc(n ? n : 1);
    if (!out)
        return NULL;
    float scale = exp2f(exposure);
    int alpha = (img->channels == 2 || img->channels == 4) ? img->channels - 1 : -1;
    for (size_t i = 0; i < n; i++) {
        int c = (int)(i % (size_t)img->channels);
        float v = img->data[i];
        if (c == alpha) {
            float a = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
            out[i] = (unsigned char)(a * 255.0f + 0.5f);
        } else {
            out[i] = lf_srgb_encode(op == LF_TONEMAP_CLAMP ? v * scale : lf_tonemap_apply(op, v * scale));
        }
    }
    return out;
}

/* Largest finite half is 65504; anything larger would be stored as Inf. */
#define LF_HALF_MAX 65504.0f

/* Number of values that are NaN or whose magnitude exceeds `limit` (Inf
 * always does); *first_pixel is the index (y * width + x) of the first. */
static size_t count_beyond(const lf_image *img, float limit, size_t *first_pixel)
{
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels, bad = 0;
    *first_pixel = 0;
    for (size_t i = 0; i < n; i++) {
        if (!(fabsf(img->data[i]) <= limit) || !isfinite(img->data[i])) {
            if (!bad)
                *first_pixel = i / (size_t)img->channels;
            bad++;
        }
    }
    return bad;
}

int lf_image_fits_half(const lf_image *img)
{
    size_t first;
    return count_beyond(img, LF_HALF_MAX, &first) == 0;
}

int lf_image_write(const char *path, const lf_image *img, const lf_attrs *attrs, const lf_write_opts *opts,
                   lf_error *err)
{
    static const lf_write_opts default_opts = {0};
    if (!opts)
        opts = &default_opts;
    if (!path || !*path)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_write: empty path");
    if (!img || !img->data)
        return lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': no image data", path);
    int rc = lf_image_check_size(img->width, img->height, img->channels, path, LF_ERR_PARAM, err);
    if (rc)
        return rc;
    const char *ext = path_extension(path);
    if (!*ext)
        return lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': no file extension to choose a format", path);
    int is_exr = strcasecmp(ext, "exr") == 0, is_pfm = strcasecmp(ext, "pfm") == 0;
    if (is_pfm && img->channels != 1 && img->channels != 3)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot write '%s': PFM holds 1 or 3 channels, the image has %d",
                            path, img->channels);

    if (!opts->allow_nonfinite) {
        size_t first, bad = count_beyond(img, INFINITY, &first);
        if (bad)
            return lf_error_set(err, LF_ERR_NUMERIC,
                                "refusing to write '%s': %zu non-finite value%s (NaN/Inf), first at pixel x=%d y=%d",
                                path, bad, bad == 1 ? "" : "s", (int)(first % (size_t)img->width),
                                (int)(first / (size_t)img->width));
        bad = is_exr && opts->half ? count_beyond(img, LF_HALF_MAX, &first) : 0;
        if (bad)
            return lf_error_set(err, LF_ERR_NUMERIC,
                                "refusing to write '%s' as half: %zu value%s beyond the half range (65504) would "
                                "become Inf, first at pixel x=%d y=%d",
                                path, bad, bad == 1 ? "" : "s", (int)(first % (size_t)img->width),
                                (int)(first / (size_t)img->width));
    }

    /* Convert before touching the file system, so running out of memory
     * leaves no temporary file behind. */
    unsigned char *bytes = NULL;
    int as_float = is_exr || is_pfm || ext_is(ext, float_exts);
    if (!as_float) {
        bytes = tonemap_8bit(img, opts->exposure, opts->tonemap);
        if (!bytes)
            return lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", path);
    }

    char tmp[PATH_MAX];
    rc = lf_file_temp_create(path, tmp, sizeof tmp, err);
    if (rc) {
        free(bytes);
        return rc;
    }
    if (is_exr)
        rc = lf_exr_write(tmp, path, img, attrs, opts->half, opts->mono_channel, err);
    else if (is_pfm)
        rc = lf_pfm_write(tmp, path, img, err);
    else if (as_float)
        rc = lf_oiio_write(tmp, path, img->width, img->height, img->channels, LF_OIIO_FLOAT, img->data, err);
    else if (strcasecmp(ext, "png") == 0 && img->channels <= 4)
        rc = lf_png_write(tmp, path, img->width, img->height, img->channels, bytes, err);
    else
        rc = lf_oiio_write(tmp, path, img->width, img->height, img->channels, LF_OIIO_UINT8, bytes, err);
    free(bytes);
    if (!rc)
        rc = lf_file_temp_commit(tmp, path, err);
    if (rc)
        unlink(tmp);
    return rc;
}

/* PNG structure check, run before OpenImageIO sees a PNG: OpenImageIO 2.4
 * leaves libpng's default error handler in place, which prints to stderr
 * ("libpng error: ...") before failing.  Walking the chunks (lengths within
 * the file, CRCs, IHDR first, IEND last) rejects truncated and corrupted
 * files ourselves, quietly; only a file with valid CRCs over an invalid
 * zlib stream still reaches libpng. */
static uint32_t png_crc_table[256];
static pthread_once_t png_crc_once = PTHREAD_ONCE_INIT;

static void png_crc_init(void)
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        png_crc_table[i] = c;
    }
}

static uint32_t png_crc_update(uint32_t crc, const unsigned char *buf, size_t n)
{
    const uint32_t *table = png_crc_table;
    pthread_once(&png_crc_once, png_crc_init);
    for (size_t i = 0; i < n; i++)
        crc = table[(crc ^ buf[i]) & 0xffu] ^ (crc >> 8);
    return crc;
}

static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

int lf_image_read_size(const char *path, int *width, int *height, int *channels, lf_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    /* signature, IHDR length and type, width, height, bit depth, colour type */
    unsigned char h[26];
    size_t got = fread(h, 1, sizeof h, f);
    fclose(f);
    if (got < 8 || memcmp(h, png_signature, 8) != 0)
        return LF_ERR_UNSUPPORTED; /* not a PNG: the caller reads it whole */
    static const int channels_of[7] = {1, 0, 3, 3, 2, 0, 4}; /* by PNG colour type; palette: RGB */
    if (got < sizeof h || memcmp(h + 12, "IHDR", 4) != 0 || h[25] > 6 || !channels_of[h[25]])
        return lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': corrupt PNG header", path);
    uint32_t w = be32(h + 16), ht = be32(h + 20);
    if (w == 0 || ht == 0 || w > 0x7fffffffu || ht > 0x7fffffffu)
        return lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PNG header claims %u x %u pixels", path, w, ht);
    *width = (int)w, *height = (int)ht, *channels = channels_of[h[25]];
    return LF_OK;
}

static int png_check(const char *path, lf_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    unsigned char head[8], buf[65536];
    int rc = LF_OK, chunks = 0, seen_end = 0;
    if (fread(head, 1, 8, f) != 8 || memcmp(head, png_signature, 8) != 0)
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': not a PNG file", path);
    while (!rc && !seen_end) {
        if (fread(head, 1, 8, f) != 8) {
            rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PNG truncated (no IEND chunk)", path);
            break;
        }
        uint32_t len = be32(head);
        char type[5] = {(char)head[4], (char)head[5], (char)head[6], (char)head[7], '\0'};
        if (len > 0x7fffffffu || (chunks == 0 && strcmp(type, "IHDR") != 0)) {
            rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': corrupt PNG chunk structure", path);
            break;
        }
        uint32_t crc = png_crc_update(0xffffffffu, head + 4, 4);
        for (uint32_t left = len; left > 0;) {
            size_t want = left < sizeof buf ? left : sizeof buf;
            if (fread(buf, 1, want, f) != want) {
                rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PNG truncated in chunk %s", path, type);
                break;
            }
            crc = png_crc_update(crc, buf, want);
            left -= (uint32_t)want;
        }
        if (rc)
            break;
        unsigned char stored[4];
        if (fread(stored, 1, 4, f) != 4) {
            rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PNG truncated in chunk %s", path, type);
            break;
        }
        if ((crc ^ 0xffffffffu) != be32(stored)) {
            rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': PNG chunk %s fails its CRC check", path, type);
            break;
        }
        seen_end = strcmp(type, "IEND") == 0;
        chunks++;
    }
    fclose(f);
    return rc;
}

int lf_image_read(const char *path, lf_image *img, lf_attrs *attrs, lf_error *err)
{
    if (img)
        memset(img, 0, sizeof *img);
    if (!path || !*path || !img)
        return lf_error_set(err, LF_ERR_PARAM, "lf_image_read: empty path or NULL image");

    /* Open it ourselves first: "missing" and "not a file" deserve plain
     * messages rather than whatever a codec makes of them. */
    /* O_NONBLOCK: opening a FIFO must not wait for a writer (it is then
     * refused as not a regular file); regular files ignore the flag. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return lf_error_set(err, LF_ERR_IO, "cannot read '%s': not a regular file", path);
    }
    unsigned char magic[4] = {0};
    ssize_t got = read(fd, magic, sizeof magic);
    close(fd);
    if (got <= 0)
        return lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': file is empty", path);

    lf_image tmp = {0};
    lf_attrs tmp_attrs = {0};
    int rc;
    int exr_magic = lf_exr_is_exr_magic(magic, (size_t)got);
    if (exr_magic) {
        rc = lf_exr_read(path, path, &tmp, attrs ? &tmp_attrs : NULL, err);
    } else if (strcasecmp(path_extension(path), "exr") == 0) {
        rc = lf_error_set(err, LF_ERR_PARSE, "cannot read '%s': not an OpenEXR file (bad magic number)", path);
    } else if (got >= 2 && magic[0] == 'P' && (magic[1] == 'F' || magic[1] == 'f')) {
        rc = lf_pfm_read(path, path, &tmp, err);
    } else {
        rc = (size_t)got >= 4 && memcmp(magic, png_signature, 4) == 0 ? png_check(path, err) : LF_OK;
        lf_oiio_read_info info = {0, -1};
        if (!rc)
            rc = lf_oiio_read(path, path, &tmp, &info, err);
        if (!rc && info.srgb_encoded)
            srgb_decode_image(&tmp, info.alpha_channel);
    }
    if (!rc && attrs && (rc = attrs_move(attrs, &tmp_attrs)) != 0)
        rc = lf_error_set(err, rc, "cannot read '%s': out of memory for header attributes", path);
    lf_attrs_free(&tmp_attrs);
    if (rc) {
        lf_image_free(&tmp);
        return rc;
    }
    *img = tmp;
    return LF_OK;
}
