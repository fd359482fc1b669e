/* A minimal DNG (Adobe DNG 1.4, a TIFF/EP file) writer and the reader of
 * what it writes: one little-endian IFD holding the raw mosaic itself
 * (NewSubFileType 0), 16 bits per sample, uncompressed, one strip, with the
 * CFA and colour tags a raw developer needs (lf_raw.h). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_file.h"
#include "base/lf_file_write.h"
#include "image/lf_raw.h"

enum { T_BYTE = 1, T_ASCII = 2, T_SHORT = 3, T_LONG = 4, T_RATIONAL = 5, T_SRATIONAL = 10 };

typedef struct tag {
    uint16_t id, type;
    uint32_t count;
    unsigned char data[72]; /* the value bytes (little-endian), at most 9 rationals */
} tag;

static size_t type_size(int t)
{
    return t == T_SHORT ? 2 : t == T_LONG ? 4 : (t == T_RATIONAL || t == T_SRATIONAL) ? 8 : 1;
}

static void put16(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }
static void put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static uint32_t get16(const unsigned char *p) { return p[0] | (uint32_t)p[1] << 8; }
static uint32_t get32(const unsigned char *p)
{
    return p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static tag t_short(uint16_t id, int n, const uint32_t *v)
{
    tag t = {id, T_SHORT, (uint32_t)n, {0}};
    for (int i = 0; i < n; i++)
        put16(t.data + 2 * i, v[i]);
    return t;
}
static tag t_long(uint16_t id, uint32_t v)
{
    tag t = {id, T_LONG, 1, {0}};
    put32(t.data, v);
    return t;
}
static tag t_bytes(uint16_t id, int type, int n, const unsigned char *v)
{
    tag t = {id, (uint16_t)type, (uint32_t)n, {0}};
    memcpy(t.data, v, (size_t)n);
    return t;
}
/* rationals with denominator 10^6 (signed or not) */
static tag t_rational(uint16_t id, int type, int n, const double *v)
{
    tag t = {id, (uint16_t)type, (uint32_t)n, {0}};
    for (int i = 0; i < n; i++) {
        double x = round(v[i] * 1e6);
        x = x > 2147483647.0 ? 2147483647.0 : x < -2147483647.0 ? -2147483647.0 : x;
        put32(t.data + 8 * i, (uint32_t)(int32_t)x);
        put32(t.data + 8 * i + 4, 1000000u);
    }
    return t;
}

enum { N_TAGS = 29 };

/* The IFD's tags in ascending order (TIFF requires it); strip offset last
 * patched once the layout is known. */
static int make_tags(const lf_image *raw, const lf_raw_info *ri, tag *t)
{
    int n = 0, mono = ri->cfa == LF_CFA_NONE;
    uint32_t v[4];
    static const unsigned char make[] = "lensfield", model[] = "lensfield simulated sensor";
    t[n++] = t_long(254, 0);
    t[n++] = t_long(256, (uint32_t)raw->width);
    t[n++] = t_long(257, (uint32_t)raw->height);
    v[0] = 16, t[n++] = t_short(258, 1, v);
    v[0] = 1, t[n++] = t_short(259, 1, v);
    v[0] = mono ? 34892 : 32803, t[n++] = t_short(262, 1, v); /* LinearRaw or CFA */
    t[n++] = t_bytes(271, T_ASCII, sizeof make, make);
    t[n++] = t_bytes(272, T_ASCII, sizeof model, model);
    t[n++] = t_long(273, 0); /* StripOffsets: patched */
    v[0] = 1, t[n++] = t_short(274, 1, v);
    v[0] = 1, t[n++] = t_short(277, 1, v);
    t[n++] = t_long(278, (uint32_t)raw->height);
    t[n++] = t_long(279, (uint32_t)raw->width * (uint32_t)raw->height * 2u);
    v[0] = 1, t[n++] = t_short(284, 1, v);
    t[n++] = t_bytes(305, T_ASCII, sizeof make, make);
    if (!mono) {
        v[0] = 2, v[1] = 2, t[n++] = t_short(33421, 2, v);
        unsigned char pat[4];
        for (int i = 0; i < 4; i++)
            pat[i] = (unsigned char)lf_cfa_color(ri->cfa, i & 1, i >> 1);
        t[n++] = t_bytes(33422, T_BYTE, 4, pat);
    }
    if (ri->exposure_s > 0) { /* ExposureTime, rational seconds */
        tag e = {33434, T_RATIONAL, 1, {0}};
        double den = ri->exposure_s < 1 ? 1e9 : 1e3, num = round(ri->exposure_s * den);
        put32(e.data, (uint32_t)(num < 4e9 ? num : 4e9)), put32(e.data + 4, (uint32_t)den);
        t[n++] = e;
    }
    if (ri->iso > 0 && ri->iso < 65536)
        v[0] = (uint32_t)lround(ri->iso), t[n++] = t_short(34855, 1, v); /* ISOSpeedRatings */
    static const unsigned char version[4] = {1, 4, 0, 0}, backward[4] = {1, 1, 0, 0}, planes[3] = {0, 1, 2};
    t[n++] = t_bytes(50706, T_BYTE, 4, version);
    t[n++] = t_bytes(50707, T_BYTE, 4, backward);
    t[n++] = t_bytes(50708, T_ASCII, sizeof model, model);
    if (!mono) {
        t[n++] = t_bytes(50710, T_BYTE, 3, planes);
        v[0] = 1, t[n++] = t_short(50711, 1, v);
    }
    t[n++] = t_long(50714, (uint32_t)lround(ri->black_level));
    t[n++] = t_long(50717, (uint32_t)lround(ri->white_level));
    if (!mono) {
        t[n++] = t_rational(50721, T_SRATIONAL, 9, ri->color_matrix);
        t[n++] = t_rational(50728, T_RATIONAL, 3, ri->as_shot_neutral);
        v[0] = 21, t[n++] = t_short(50778, 1, v); /* CalibrationIlluminant1: D65 */
    }
    return n;
}

int lf_dng_write(const char *path, const lf_image *raw, const lf_raw_info *ri, lf_error *err)
{
    tag t[N_TAGS];
    int n = make_tags(raw, ri, t);
    size_t ifd = 8, ifd_size = 2 + 12 * (size_t)n + 4, extra = 0;
    for (int i = 0; i < n; i++) {
        size_t sz = type_size(t[i].type) * t[i].count;
        if (sz > 4)
            extra += (sz + 1) & ~(size_t)1;
    }
    size_t pixels = ifd + ifd_size + extra, total = pixels + (size_t)raw->width * raw->height * 2;
    unsigned char *buf = calloc(1, total);
    if (!buf)
        return lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", path);
    memcpy(buf, "II*\0", 4);
    put32(buf + 4, (uint32_t)ifd);
    put16(buf + ifd, (uint32_t)n);
    size_t off = ifd + ifd_size;
    for (int i = 0; i < n; i++) {
        unsigned char *e = buf + ifd + 2 + 12 * (size_t)i;
        if (t[i].id == 273)
            put32(t[i].data, (uint32_t)pixels);
        size_t sz = type_size(t[i].type) * t[i].count;
        put16(e, t[i].id), put16(e + 2, t[i].type), put32(e + 4, t[i].count);
        if (sz <= 4)
            memcpy(e + 8, t[i].data, sz);
        else {
            put32(e + 8, (uint32_t)off);
            memcpy(buf + off, t[i].data, sz);
            off += (sz + 1) & ~(size_t)1;
        }
    }
    put32(buf + ifd + 2 + 12 * (size_t)n, 0); /* no next IFD */
    for (size_t i = 0; i < (size_t)raw->width * raw->height; i++)
        put16(buf + pixels + 2 * i, (uint32_t)raw->data[i]);
    int rc = lf_file_write_atomic(path, buf, total, err);
    free(buf);
    return rc;
}

/* ---- reading what lf_dng_write writes ---- */

static const unsigned char *tag_value(const unsigned char *f, size_t size, const unsigned char *e, size_t need)
{
    if (need <= 4)
        return e + 8;
    uint32_t off = get32(e + 8);
    return off <= size && need <= size - off ? f + off : NULL;
}

static double rational(const unsigned char *p, int sgn)
{
    uint32_t d = get32(p + 4);
    double num = sgn ? (double)(int32_t)get32(p) : (double)get32(p);
    return d ? num / d : 0;
}

int lf_dng_read(const char *path, lf_image *raw, lf_raw_info *ri, lf_error *err)
{
    char *fc = NULL;
    size_t size = 0;
    int gz = 0;
    int rc = lf_file_read(path, (size_t)1 << 33, &fc, &size, &gz, err);
    if (rc)
        return rc;
    unsigned char *f = (unsigned char *)fc;
    memset(ri, 0, sizeof *ri);
    ri->as_shot_neutral[0] = ri->as_shot_neutral[1] = ri->as_shot_neutral[2] = 1;
    uint32_t w = 0, h = 0, bits = 0, strip = 0, photometric = 0;
    unsigned char pat[4] = {0};
    int have_pat = 0, have_matrix = 0;
    uint32_t ifd = size >= 8 && !memcmp(f, "II*\0", 4) ? get32(f + 4) : 0;
    uint32_t n = ifd && ifd + 2 <= size ? get16(f + ifd) : 0;
    if (!n || ifd + 2 + 12ull * n > size) {
        free(f);
        return lf_error_set(err, LF_ERR_PARSE, "%s: not a little-endian DNG written by lensfield", path);
    }
    for (uint32_t i = 0; i < n; i++) {
        const unsigned char *e = f + ifd + 2 + 12 * i;
        uint32_t id = get16(e), type = get16(e + 2), count = get32(e + 4);
        const unsigned char *v = tag_value(f, size, e, type_size((int)type) * count);
        if (!v)
            continue;
        uint32_t first = type == T_SHORT ? get16(v) : type == T_LONG ? get32(v) : v[0];
        switch (id) {
        case 256: w = first; break;
        case 257: h = first; break;
        case 258: bits = first; break;
        case 262: photometric = first; break;
        case 273: strip = first; break;
        case 33422: if (count == 4) memcpy(pat, v, 4), have_pat = 1; break;
        case 50714: ri->black_level = type == T_RATIONAL ? rational(v, 0) : first; break;
        case 50717: ri->white_level = first; break;
        case 50721:
            if (count == 9 && type == T_SRATIONAL) {
                for (int k = 0; k < 9; k++)
                    ri->color_matrix[k] = rational(v + 8 * k, 1);
                have_matrix = 1;
            }
            break;
        case 50728:
            if (count == 3)
                for (int k = 0; k < 3; k++)
                    ri->as_shot_neutral[k] = rational(v + 8 * k, 0);
            break;
        default: break;
        }
    }
    ri->cfa = LF_CFA_NONE;
    for (int c = LF_CFA_RGGB; have_pat && c <= LF_CFA_GBRG; c++)
        if (pat[0] == lf_cfa_color((lf_cfa)c, 0, 0) && pat[1] == lf_cfa_color((lf_cfa)c, 1, 0) &&
            pat[2] == lf_cfa_color((lf_cfa)c, 0, 1) && pat[3] == lf_cfa_color((lf_cfa)c, 1, 1))
            ri->cfa = (lf_cfa)c;
    int ok = w && h && w <= 65536 && h <= 65536 && bits == 16 && strip && strip <= size &&
             (size_t)w * h * 2 <= size - strip && (photometric == 34892 || (photometric == 32803 && have_pat &&
                                                                               ri->cfa != LF_CFA_NONE && have_matrix));
    if (ok && !(rc = lf_image_alloc(raw, (int)w, (int)h, 1, err)))
        for (size_t i = 0; i < (size_t)w * h; i++)
            raw->data[i] = (float)get16(f + strip + 2 * i);
    free(f);
    if (!ok)
        return lf_error_set(err, LF_ERR_PARSE, "%s: a DNG lensfield cannot read (it reads one uncompressed 16-bit "
                            "mosaic in IFD 0, as lensfield writes)", path);
    return rc;
}
