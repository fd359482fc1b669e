/* Raw sensor images: CFA names, raw files, demosaicing and developing
 * (lf_raw.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_file.h"
#include "base/lf_keys.h"
#include "image/lf_raw.h"

#define KEY_CFA LF_KEY_CFA
#define KEY_BLACK LF_KEY_BLACKLEVEL
#define KEY_WHITE LF_KEY_WHITELEVEL
#define KEY_MATRIX LF_KEY_COLOR_MATRIX
#define KEY_NEUTRAL LF_KEY_AS_SHOT_NEUTRAL
#define KEY_DN_PER_UNIT LF_KEY_DN_PER_UNIT

static const char *const cfa_names[5] = {"none", "rggb", "bggr", "grbg", "gbrg"};

int lf_cfa_parse(const char *name, lf_cfa *out)
{
    for (int i = 0; i < 5; i++)
        if (name && !strcmp(name, cfa_names[i])) {
            *out = (lf_cfa)i;
            return 0;
        }
    return -1;
}

const char *lf_cfa_name(lf_cfa cfa)
{
    return (unsigned)cfa < 5 ? cfa_names[cfa] : "none";
}

static const double srgb_to_xyz[9] = {0.4124564, 0.3575761, 0.1804375, 0.2126729, 0.7151522,
                                      0.0721750, 0.0193339, 0.1191920, 0.9503041};

static int inv3(const double *a, double *o)
{
    double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                 a[2] * (a[3] * a[7] - a[4] * a[6]);
    if (!(fabs(det) > 1e-300))
        return -1;
    o[0] = (a[4] * a[8] - a[5] * a[7]) / det, o[1] = (a[2] * a[7] - a[1] * a[8]) / det;
    o[2] = (a[1] * a[5] - a[2] * a[4]) / det, o[3] = (a[5] * a[6] - a[3] * a[8]) / det;
    o[4] = (a[0] * a[8] - a[2] * a[6]) / det, o[5] = (a[2] * a[3] - a[0] * a[5]) / det;
    o[6] = (a[3] * a[7] - a[4] * a[6]) / det, o[7] = (a[1] * a[6] - a[0] * a[7]) / det;
    o[8] = (a[0] * a[4] - a[1] * a[3]) / det;
    return 0;
}

int lf_raw_info_to_attrs(const lf_raw_info *ri, lf_attrs *a, lf_error *err)
{
    float m[9], n[3];
    for (int i = 0; i < 9; i++)
        m[i] = (float)ri->color_matrix[i];
    for (int i = 0; i < 3; i++)
        n[i] = (float)ri->as_shot_neutral[i];
    int rc = lf_attrs_set_string(a, KEY_CFA, lf_cfa_name(ri->cfa), err) |
             lf_attrs_set_float(a, KEY_BLACK, (float)ri->black_level, err) |
             lf_attrs_set_float(a, KEY_WHITE, (float)ri->white_level, err) |
             lf_attrs_set_floats(a, KEY_MATRIX, m, 9, err) | lf_attrs_set_floats(a, KEY_NEUTRAL, n, 3, err) |
             lf_attrs_set_double(a, KEY_DN_PER_UNIT, ri->dn_per_unit, err);
    return rc ? (err && err->code ? err->code : LF_ERR_NOMEM) : 0;
}

static int attr_number(const lf_attrs *a, const char *name, double *out)
{
    const lf_attr *x = lf_attrs_get(a, name);
    if (!x)
        return -1;
    if (x->type == LF_ATTR_INT)
        *out = x->i;
    else if (x->type == LF_ATTR_FLOAT || x->type == LF_ATTR_DOUBLE)
        *out = x->d;
    else
        return -1;
    return 0;
}

int lf_raw_info_from_attrs(const lf_attrs *a, lf_raw_info *ri, lf_error *err)
{
    memset(ri, 0, sizeof *ri);
    const lf_attr *cfa = lf_attrs_get(a, KEY_CFA);
    if (!cfa || cfa->type != LF_ATTR_STRING || lf_cfa_parse(cfa->s, &ri->cfa) ||
        attr_number(a, KEY_BLACK, &ri->black_level) || attr_number(a, KEY_WHITE, &ri->white_level))
        return lf_error_set(err, LF_ERR_PARAM, "not a raw image: it needs %s, %s and %s", KEY_CFA, KEY_BLACK,
                            KEY_WHITE);
    /* defaults: a camera whose channels are linear sRGB's */
    double mi[9];
    inv3(srgb_to_xyz, mi);
    memcpy(ri->color_matrix, mi, sizeof mi);
    ri->as_shot_neutral[0] = ri->as_shot_neutral[1] = ri->as_shot_neutral[2] = 1;
    const lf_attr *m = lf_attrs_get(a, KEY_MATRIX), *n = lf_attrs_get(a, KEY_NEUTRAL);
    if (m && m->type == LF_ATTR_FLOATS && m->n == 9)
        for (int i = 0; i < 9; i++)
            ri->color_matrix[i] = m->v[i];
    if (n && n->type == LF_ATTR_FLOATS && n->n == 3)
        for (int i = 0; i < 3; i++)
            ri->as_shot_neutral[i] = n->v[i];
    if (attr_number(a, KEY_DN_PER_UNIT, &ri->dn_per_unit))
        ri->dn_per_unit = 0;
    if (!(ri->white_level > ri->black_level))
        return lf_error_set(err, LF_ERR_PARAM, "raw: white level %g is not above the black level %g",
                            ri->white_level, ri->black_level);
    return 0;
}

static int check_dn(const lf_image *raw, const char *path, lf_error *err)
{
    if (raw->channels != 1)
        return lf_error_set(err, LF_ERR_PARAM, "%s: a raw has one channel, not %d", path, raw->channels);
    for (size_t i = 0; i < (size_t)raw->width * raw->height; i++) {
        float v = raw->data[i];
        if (!(v >= 0 && v <= 65535) || v != floorf(v))
            return lf_error_set(err, LF_ERR_NUMERIC, "%s: raw value %g at pixel %zu is not an integer in 0..65535",
                                path, v, i);
    }
    return 0;
}

int lf_raw_write(const char *path, const lf_image *raw, const lf_raw_info *ri, const lf_attrs *attrs,
                 lf_error *err)
{
    int rc = check_dn(raw, path, err);
    if (rc)
        return rc;
    if (lf_path_has_ext(path, ".dng"))
        return lf_dng_write(path, raw, ri, err);
    if (!lf_path_has_ext(path, ".exr"))
        return lf_error_set(err, LF_ERR_PARAM, "a raw is written as .exr or .dng, not %s", path);
    lf_attrs a = {0};
    for (size_t i = 0; attrs && i < attrs->count && !rc; i++)
        rc = lf_attrs_set_copy(&a, &attrs->items[i], err);
    if (!rc)
        rc = lf_raw_info_to_attrs(ri, &a, err);
    lf_write_opts wo = {0};
    wo.mono_channel = "raw";
    if (!rc)
        rc = lf_image_write(path, raw, &a, &wo, err);
    lf_attrs_free(&a);
    return rc;
}

int lf_dng_read(const char *path, lf_image *raw, lf_raw_info *ri, lf_error *err);

int lf_raw_read(const char *path, lf_image *raw, lf_raw_info *ri, lf_attrs *attrs, lf_error *err)
{
    memset(raw, 0, sizeof *raw);
    if (lf_path_has_ext(path, ".dng"))
        return lf_dng_read(path, raw, ri, err);
    lf_attrs a = {0};
    int rc = lf_image_read(path, raw, &a, err);
    if (!rc && raw->channels != 1)
        rc = lf_error_set(err, LF_ERR_PARAM, "%s: a raw has one channel, not %d", path, raw->channels);
    if (!rc) {
        lf_error e = {0};
        if (lf_raw_info_from_attrs(&a, ri, &e))
            rc = lf_error_set(err, e.code, "%s: %s", path, e.msg);
    }
    if (rc)
        lf_image_free(raw);
    if (attrs && !rc)
        *attrs = a;
    else
        lf_attrs_free(&a);
    return rc;
}

/* ---- demosaicing ---- */

/* Malvar-He-Cutler 5x5 kernels (x8), indexed [dy+2][dx+2]. */
static const float k_g_at_rb[5][5] = {
    {0, 0, -1, 0, 0}, {0, 0, 2, 0, 0}, {-1, 2, 4, 2, -1}, {0, 0, 2, 0, 0}, {0, 0, -1, 0, 0}};
/* the colour whose neighbours lie left and right (a green site in that colour's row) */
static const float k_row[5][5] = {
    {0, 0, 0.5f, 0, 0}, {0, -1, 0, -1, 0}, {-1, 4, 5, 4, -1}, {0, -1, 0, -1, 0}, {0, 0, 0.5f, 0, 0}};
static const float k_col[5][5] = {
    {0, 0, -1, 0, 0}, {0, -1, 4, -1, 0}, {0.5f, 0, 5, 0, 0.5f}, {0, -1, 4, -1, 0}, {0, 0, -1, 0, 0}};
/* red at a blue site and blue at a red site (diagonal neighbours) */
static const float k_diag[5][5] = {
    {0, 0, -1.5f, 0, 0}, {0, 2, 0, 2, 0}, {-1.5f, 0, 6, 0, -1.5f}, {0, 2, 0, 2, 0}, {0, 0, -1.5f, 0, 0}};

typedef struct mosaic {
    const lf_image *in;
    lf_cfa cfa;
    const int *mask;
} mosaic;

static int site_ok(const mosaic *m, int x, int y, int label)
{
    if (x < 0 || y < 0 || x >= m->in->width || y >= m->in->height)
        return 0;
    return !m->mask || m->mask[(size_t)y * m->in->width + x] == label;
}

static float at(const mosaic *m, int x, int y)
{
    return m->in->data[(size_t)y * m->in->width + x];
}

/* Colour c at (x, y): the MHC kernel when all its taps are usable, else the
 * mean of the usable sites of colour c in the 3x3 (then 5x5) neighbourhood. */
static float interp(const mosaic *m, int x, int y, int c, const float (*k)[5], int label)
{
    int full = 1;
    float sum = 0;
    for (int dy = -2; dy <= 2 && full; dy++)
        for (int dx = -2; dx <= 2; dx++) {
            if (k[dy + 2][dx + 2] == 0)
                continue;
            if (!site_ok(m, x + dx, y + dy, label)) {
                full = 0;
                break;
            }
            sum += k[dy + 2][dx + 2] * at(m, x + dx, y + dy);
        }
    if (full)
        return sum / 8.0f;
    for (int r = 1; r <= 2; r++) {
        float s = 0;
        int n = 0;
        for (int dy = -r; dy <= r; dy++)
            for (int dx = -r; dx <= r; dx++)
                if (site_ok(m, x + dx, y + dy, label) && lf_cfa_color(m->cfa, x + dx, y + dy) == c)
                    s += at(m, x + dx, y + dy), n++;
        if (n)
            return s / n;
    }
    return 0;
}

int lf_demosaic_mhc(const lf_image *in, lf_cfa cfa, const int *mask, lf_image *out, lf_error *err)
{
    if (in->channels != 1)
        return lf_error_set(err, LF_ERR_PARAM, "demosaic: the mosaic needs one channel, got %d", in->channels);
    if (lf_image_alloc(out, in->width, in->height, 3, err))
        return err->code;
    mosaic m = {in, cfa, mask};
    for (int y = 0; y < in->height; y++)
        for (int x = 0; x < in->width; x++) {
            float *o = lf_image_px(out, x, y);
            int label = mask ? mask[(size_t)y * in->width + x] : 0;
            float v = at(&m, x, y);
            if (cfa == LF_CFA_NONE || label < 0) {
                o[0] = o[1] = o[2] = label < 0 ? 0.f : v;
                continue;
            }
            int c = lf_cfa_color(cfa, x, y);
            o[c] = v;
            if (c == 1) {
                /* a green site: which colour shares its row? */
                int row_c = lf_cfa_color(cfa, x + 1, y);
                o[row_c] = interp(&m, x, y, row_c, k_row, label);
                o[2 - row_c] = interp(&m, x, y, 2 - row_c, k_col, label);
            } else {
                o[1] = interp(&m, x, y, 1, k_g_at_rb, label);
                o[2 - c] = interp(&m, x, y, 2 - c, k_diag, label);
            }
        }
    return 0;
}

/* ---- developing ---- */

int lf_raw_develop(const lf_image *raw, const lf_raw_info *ri, const lf_develop_opts *opts, lf_image *out,
                   lf_error *err)
{
    lf_develop_opts o = opts ? *opts : (lf_develop_opts){0};
    double scale = o.film_units && ri->dn_per_unit > 0 ? ri->dn_per_unit : ri->white_level - ri->black_level;
    if (!(scale > 0))
        return lf_error_set(err, LF_ERR_PARAM, "develop: white level must be above the black level");
    lf_image lin;
    if (lf_image_alloc(&lin, raw->width, raw->height, 1, err))
        return err->code;
    for (size_t i = 0; i < (size_t)raw->width * raw->height; i++)
        lin.data[i] = (float)((raw->data[i] - ri->black_level) / scale);
    int rc = lf_demosaic_mhc(&lin, ri->cfa, o.mask, out, err);
    lf_image_free(&lin);
    if (rc || ri->cfa == LF_CFA_NONE)
        return rc;
    /* camera -> linear sRGB: inverse of (camera from sRGB) = CM M, each row
     * divided by its white (the row sums, AsShotNeutral) so that white
     * balanced white stays white (as dcraw normalises its matrices) */
    double cam_from_srgb[9], srgb_from_cam[9], wb[3];
    for (int i = 0; i < 3; i++) {
        double rowsum = 0;
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int k = 0; k < 3; k++)
                v += ri->color_matrix[3 * i + k] * srgb_to_xyz[3 * k + j];
            cam_from_srgb[3 * i + j] = v;
            rowsum += v;
        }
        double n = ri->as_shot_neutral[i] > 0 ? ri->as_shot_neutral[i] : rowsum;
        for (int j = 0; j < 3; j++)
            cam_from_srgb[3 * i + j] /= n;
        wb[i] = o.no_white_balance ? 1.0 : 1.0 / n;
    }
    if (inv3(cam_from_srgb, srgb_from_cam)) {
        lf_image_free(out);
        return lf_error_set(err, LF_ERR_PARAM, "develop: the colour matrix is singular");
    }
    for (size_t i = 0; i < (size_t)out->width * out->height; i++) {
        float *p = out->data + 3 * i;
        double c[3] = {p[0] * wb[0], p[1] * wb[1], p[2] * wb[2]};
        for (int j = 0; j < 3; j++)
            p[j] = (float)(srgb_from_cam[3 * j] * c[0] + srgb_from_cam[3 * j + 1] * c[1] +
                           srgb_from_cam[3 * j + 2] * c[2]);
    }
    return 0;
}
