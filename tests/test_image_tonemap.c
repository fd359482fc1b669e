/* test_image_tonemap.c - tone curves for 8-bit output and the colour map of
 * scalar images, against the published curves written out here. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"

static double srgb_to_linear(double v)
{
    v /= 255.0;
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

int main(void)
{
    /* clamp: the identity up to white */
    CHECK_NEAR(lf_tonemap_apply(LF_TONEMAP_CLAMP, 0.25f), 0.25, 0);
    CHECK_NEAR(lf_tonemap_apply(LF_TONEMAP_CLAMP, 7.0f), 1.0, 0);
    /* ACES (Narkowicz 2015): x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14) */
    for (double x = 0.05; x < 3; x += 0.37) {
        double want = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
        CHECK_NEAR(lf_tonemap_apply(LF_TONEMAP_ACES, (float)x), want > 1 ? 1 : want, 1e-6);
    }
    /* filmic (Hable 2010): white point 11.2 reached at 11.2 / 2 (bias 2) */
    CHECK_NEAR(lf_tonemap_apply(LF_TONEMAP_FILMIC, 5.6f), 1.0, 1e-6);
    double A = 0.15, B = 0.5, C = 0.1, D = 0.2, E = 0.02, F = 0.3;
#define HABLE(x) (((x) * (A * (x) + C * B) + D * E) / ((x) * (A * (x) + B) + D * F) - E / F)
    CHECK_NEAR(lf_tonemap_apply(LF_TONEMAP_FILMIC, 0.5f), HABLE(1.0) / HABLE(11.2), 1e-6);
    /* every curve: 0 at 0 (and for negatives or NaN), monotonic, at most 1 */
    for (int op = 0; op < 3; op++) {
        CHECK(lf_tonemap_apply((lf_tonemap)op, 0.0f) == 0.0f);
        CHECK(lf_tonemap_apply((lf_tonemap)op, -1.0f) == 0.0f);
        CHECK(lf_tonemap_apply((lf_tonemap)op, NAN) == 0.0f);
        float prev = 0;
        int mono = 1;
        for (float x = 0.001f; x < 100; x *= 1.1f) {
            float y = lf_tonemap_apply((lf_tonemap)op, x);
            mono &= y >= prev && y <= 1.0f;
            prev = y;
        }
        CHECK(mono);
    }
    lf_tonemap t;
    CHECK(lf_tonemap_parse("aces", &t) == 0 && t == LF_TONEMAP_ACES);
    CHECK(lf_tonemap_parse("filmic", &t) == 0 && t == LF_TONEMAP_FILMIC);
    CHECK(lf_tonemap_parse("reinhard", &t) == -1);

    /* An 8-bit file carries the curve: linear 1.0 at +1 EV through ACES. */
    char dir[] = "/tmp/lf_tonemap_XXXXXX", path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/t.png", dir);
    lf_image img, back;
    lf_error err = {0};
    CHECK(lf_image_alloc(&img, 4, 2, 3, &err) == 0);
    for (int i = 0; i < 24; i++)
        img.data[i] = 1.0f;
    lf_write_opts wo = {0};
    wo.exposure = 1.0f;
    wo.tonemap = LF_TONEMAP_ACES;
    CHECK(lf_image_write(path, &img, NULL, &wo, &err) == 0);
    CHECK(lf_image_read(path, &back, NULL, &err) == 0);
    double x = 2.0, aces2 = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    CHECK_NEAR(back.data[0], aces2, 0.01); /* 8-bit quantisation */
    lf_image_free(&back);
    lf_image_free(&img);
    remove(path);
    rmdir(dir);

    /* The colour map: lo -> viridis' first stop, hi -> its last, NaN grey,
     * a legend strip below with the range written in white. */
    lf_image s, c;
    CHECK(lf_image_alloc(&s, 64, 8, 1, &err) == 0);
    for (int i = 0; i < 64 * 8; i++)
        s.data[i] = (float)(-2.0 + 5.0 * (i % 64) / 63.0);
    s.data[5] = NAN;
    CHECK(lf_image_colormap(&s, -2.0, 3.0, &c, &err) == 0);
    CHECK(c.width == 64 && c.height > 8 && c.channels == 3);
    CHECK_NEAR(lf_image_px(&c, 0, 1)[0], srgb_to_linear(0x44), 1e-4);
    CHECK_NEAR(lf_image_px(&c, 0, 1)[2], srgb_to_linear(0x54), 1e-4);
    CHECK_NEAR(lf_image_px(&c, 63, 1)[1], srgb_to_linear(0xe7), 1e-4);
    CHECK_NEAR(lf_image_px(&c, 5, 0)[0], 0.2, 1e-6);
    int white = 0;
    for (int y = 8; y < c.height; y++)
        for (int xx = 0; xx < 64; xx++)
            white += lf_image_px(&c, xx, y)[1] == 1.0f;
    CHECK(white > 10);
    lf_image_free(&c);
    CHECK(lf_image_colormap(&s, 1.0, 1.0, &c, &err) != 0);
    lf_image_free(&s);
    return lf_test_end();
}
