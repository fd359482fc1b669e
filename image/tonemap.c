/* Tone curves for 8-bit output and the colour map for scalar images
 * (lf_image.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lf_image.h"

/* Hable's filmic curve ("Uncharted 2 tone mapping", GDC 2010): shoulder
 * strength A, linear strength B, linear angle C, toe strength D, toe
 * numerator E, toe denominator F, normalised so the white point W maps
 * to 1, with his exposure bias of 2. */
static float hable(float x)
{
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

float lf_tonemap_apply(lf_tonemap op, float x)
{
    if (!(x > 0.0f)) /* negatives and NaN: black */
        return 0.0f;
    float y;
    switch (op) {
    case LF_TONEMAP_FILMIC: {
        const float W = 11.2f;
        y = hable(2.0f * x) / hable(W);
        break;
    }
    case LF_TONEMAP_ACES: /* Narkowicz 2015, "ACES Filmic Tone Mapping Curve" */
        y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
        break;
    default:
        y = x;
        break;
    }
    return y < 1.0f ? y : 1.0f;
}

int lf_tonemap_parse(const char *name, lf_tonemap *op)
{
    static const char *const names[] = {"clamp", "filmic", "aces"};
    for (int i = 0; i < 3; i++)
        if (name && !strcmp(name, names[i])) {
            *op = (lf_tonemap)i;
            return 0;
        }
    return -1;
}

/* matplotlib's viridis at nine even stops (sRGB, 0..255). */
static const unsigned char viridis[9][3] = {{0x44, 0x01, 0x54}, {0x47, 0x2d, 0x7b}, {0x3b, 0x52, 0x8b},
                                            {0x2c, 0x72, 0x8e}, {0x21, 0x91, 0x8c}, {0x28, 0xae, 0x80},
                                            {0x5e, 0xc9, 0x62}, {0xad, 0xdc, 0x30}, {0xfd, 0xe7, 0x25}};

/* t in [0, 1] -> linear RGB (interpolated in sRGB, as the map is defined). */
static void colour_at(double t, float rgb[3])
{
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double f = t * 8.0;
    int i = (int)f < 7 ? (int)f : 7;
    double w = f - i;
    for (int c = 0; c < 3; c++) {
        double v = ((1 - w) * viridis[i][c] + w * viridis[i + 1][c]) / 255.0;
        rgb[c] = (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
    }
}

/* 3 x 5 pixel glyphs for the legend: digits, '.', '-', 'e', '+'. */
static const char *glyph(char ch)
{
    static const char *const digits[10] = {"111101101101111", "010110010010111", "111001111100111", "111001111001111",
                                           "101101111001001", "111100111001111", "111100111101111", "111001001001001",
                                           "111101111101111", "111101111001111"};
    if (ch >= '0' && ch <= '9')
        return digits[ch - '0'];
    switch (ch) {
    case '.':
        return "000000000000010";
    case '-':
        return "000000111000000";
    case '+':
        return "000010111010000";
    case 'e':
        return "000111111100111";
    default:
        return "000000000000000";
    }
}

/* Writes text at (x, y) (top-left) in white, each glyph pixel scale x scale. */
static void draw_text(lf_image *img, int x, int y, int scale, const char *text)
{
    for (const char *p = text; *p; p++, x += 4 * scale) {
        const char *g = glyph(*p);
        for (int r = 0; r < 5; r++)
            for (int c = 0; c < 3; c++)
                if (g[r * 3 + c] == '1')
                    for (int dy = 0; dy < scale; dy++)
                        for (int dx = 0; dx < scale; dx++) {
                            int px = x + c * scale + dx, py = y + r * scale + dy;
                            if (px >= 0 && py >= 0 && px < img->width && py < img->height) {
                                float *q = lf_image_px(img, px, py);
                                q[0] = q[1] = q[2] = 1.0f;
                            }
                        }
    }
}

int lf_image_colormap(const lf_image *src, double lo, double hi, lf_image *out, lf_error *err)
{
    if (!(hi > lo) || !isfinite(lo) || !isfinite(hi))
        return lf_error_set(err, LF_ERR_PARAM, "colour map range %g .. %g is empty", lo, hi);
    int w = src->width, scale = w >= 240 ? 2 : 1, text_h = 5 * scale;
    int bar_h = w >= 32 ? 4 * scale + 2 : 0, legend = bar_h ? bar_h + text_h + 4 * scale : 0;
    int rc = lf_image_alloc(out, w, src->height + legend, 3, err);
    if (rc)
        return rc;
    for (int y = 0; y < src->height; y++)
        for (int x = 0; x < w; x++) {
            float v = lf_image_px(src, x, y)[0], *q = lf_image_px(out, x, y);
            if (isfinite(v))
                colour_at((v - lo) / (hi - lo), q);
            else
                q[0] = q[1] = q[2] = 0.2f;
        }
    if (!legend)
        return LF_OK;
    int y0 = src->height + scale; /* the strip is black; the bar runs lo (left) to hi (right) */
    for (int x = 0; x < w; x++) {
        float rgb[3];
        colour_at((x + 0.5) / w, rgb);
        for (int y = y0; y < y0 + bar_h - 2; y++)
            memcpy(lf_image_px(out, x, y), rgb, sizeof rgb);
    }
    char a[32], b[32];
    snprintf(a, sizeof a, "%.4g", lo);
    snprintf(b, sizeof b, "%.4g", hi);
    int ty = y0 + bar_h + scale, bw = (int)strlen(b) * 4 * scale;
    draw_text(out, scale, ty, scale, a);
    draw_text(out, w - bw - scale, ty, scale, b);
    return LF_OK;
}

lf_write_opts lf_write_opts_picture(double exposure_ev, const char *tonemap)
{
    lf_write_opts wo = {0};
    wo.exposure = (float)exposure_ev;
    if (tonemap && lf_tonemap_parse(tonemap, &wo.tonemap))
        wo.tonemap = LF_TONEMAP_CLAMP;
    return wo;
}
