/* A noiseless mosaic of the demo scene (scenes/sensor/demo-raw.pbrt, its
 * centre, at 64 samples per pixel; "ideal" filter curves), developed (black level, Malvar-He-Cutler, white balance, colour
 * matrix), against the Film "rgb" render of the same scene: at least 38 dB.
 * Both pictures are exposed alike (the film's mean to 18 % grey), clamped
 * and sRGB-encoded before the comparison, as a viewer sees them.  Also: the
 * Film "rgb" render is the raw film's own exposure, bit for bit, and MHC
 * reproduces a linear ramp exactly (its kernels are exact on linear
 * signals, Malvar et al. 2004). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_file.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_sensor.h"

static const int crop[4] = {160, 480, 106, 320};

static char *read_text(const char *path)
{
    char *t = NULL;
    size_t n;
    lf_error err = {0};
    return lf_file_read(path, 1 << 20, &t, &n, NULL, &err) ? NULL : t;
}

/* Replaces the first `from` in s with `to` (s has room). */
static void replace(char *s, const char *from, const char *to)
{
    char *p = strstr(s, from);
    if (!p)
        return;
    size_t nf = strlen(from), nt = strlen(to);
    memmove(p + nt, p + nf, strlen(p + nf) + 1);
    memcpy(p, to, nt);
}

static void picture(lf_image *img, double k)
{
    for (size_t i = 0; i < (size_t)img->width * img->height * img->channels; i++)
        img->data[i] = lf_srgb_encode((float)fmin(fmax(img->data[i] * k, 0.0), 1.0)) / 255.0f;
}

/* 2x2 box binning: the mosaic's own resolution, where every colour is sampled */
static void bin2(lf_image *img)
{
    lf_image b;
    lf_error err = {0};
    lf_image_alloc(&b, img->width / 2, img->height / 2, 3, &err);
    for (int y = 0; y < b.height; y++)
        for (int x = 0; x < b.width; x++)
            for (int c = 0; c < 3; c++)
                lf_image_px(&b, x, y)[c] = 0.25f * (lf_image_px(img, 2 * x, 2 * y)[c] + lf_image_px(img, 2 * x + 1, 2 * y)[c] +
                                                    lf_image_px(img, 2 * x, 2 * y + 1)[c] +
                                                    lf_image_px(img, 2 * x + 1, 2 * y + 1)[c]);
    lf_image_free(img);
    *img = b;
}

static void ramp(void)
{
    lf_image m, out;
    lf_error err = {0};
    lf_image_alloc(&m, 32, 32, 1, &err);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            int c = lf_cfa_color(LF_CFA_GRBG, x, y);
            m.data[y * 32 + x] = (float)(0.01 * x + 0.02 * y + 0.1 * c); /* three linear planes */
        }
    CHECK(lf_demosaic_mhc(&m, LF_CFA_GRBG, NULL, &out, &err) == 0);
    double worst = 0;
    for (int y = 2; y < 30; y++)
        for (int x = 2; x < 30; x++)
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(lf_image_px(&out, x, y)[c] - (0.01 * x + 0.02 * y + 0.1 * c)));
    CHECK_MSG(worst < 1e-5, "MHC on linear planes: error %g", worst);
    lf_image_free(&m), lf_image_free(&out);
}

int main(void)
{
    ramp();
    char *text = read_text("scenes/sensor/demo-raw.pbrt");
    CHECK(text != NULL);
    if (!text)
        return lf_test_end();
    char *rgb_text = malloc(strlen(text) + 64);
    strcpy(rgb_text, text);
    replace(rgb_text, "Film \"raw\"", "Film \"rgb\"");
    replace(rgb_text, "\"string cfa\" \"rggb\"", "");
    lf_image film, film_rgb, raw, dev;
    lf_attrs meta = {0};
    char msg[1024];
    lf_error err = {0};
    lf_sensor s;
    /* the Film "rgb" render is the raw film's own exposure, bit for bit (a
     * small crop at the scene's 16 spp) ... */
    static const int small[4] = {300, 340, 200, 230};
    int ok = render_text(text, &(lf_test_scene){.crop = small}, &film, msg, sizeof msg) == 0 &&
             render_text(rgb_text, &(lf_test_scene){.crop = small}, &film_rgb, msg, sizeof msg) == 0;
    CHECK_MSG(ok, "%s", msg);
    if (!ok)
        return lf_test_end();
    CHECK(!memcmp(film.data, film_rgb.data, sizeof(float) * 3 * film.width * film.height));
    lf_image_free(&film), lf_image_free(&film_rgb);
    /* ... so the raw render's film at 64 spp is the Film "rgb" render: the
     * render's own Monte Carlo noise is white at the pixel scale, which no
     * mosaic can carry (16 spp: 34.6 dB) */
    replace(text, "pixelsamples\" [16]", "pixelsamples\" [64]");
    ok = render_text(text, &(lf_test_scene){.crop = crop, .meta = &meta}, &film, msg, sizeof msg) == 0 &&
         lf_sensor_from_attrs(&meta, &s, &err) == 0 && lf_image_alloc(&film_rgb, film.width, film.height, 3, &err) == 0;
    CHECK_MSG(ok, "%s %s", msg, err.msg);
    if (!ok)
        return lf_test_end();
    memcpy(film_rgb.data, film.data, sizeof(float) * 3 * film.width * film.height);
    s.noise = 0;
    lf_raw_info ri;
    lf_sensor_raw_info(&s, &ri);
    ri.cfa = lf_cfa_shift(ri.cfa, crop[0], crop[2]);
    lf_develop_opts d = {.film_units = 1};
    CHECK(lf_sensor_expose(&s, &film, crop[0], crop[2], &raw, &err) == 0 &&
          lf_raw_develop(&raw, &ri, &d, &dev, &err) == 0);
    lf_image dev_lin = {0}, film_lin = {0};
    lf_image_alloc(&dev_lin, dev.width, dev.height, 3, &err);
    lf_image_alloc(&film_lin, dev.width, dev.height, 3, &err);
    memcpy(dev_lin.data, dev.data, sizeof(float) * 3 * dev.width * dev.height);
    memcpy(film_lin.data, film_rgb.data, sizeof(float) * 3 * dev.width * dev.height);
    double mean = 0;
    for (size_t i = 0; i < (size_t)film.width * film.height * 3; i++)
        mean += film_rgb.data[i];
    mean /= (double)film.width * film.height * 3;
    picture(&film_rgb, 0.18 / mean);
    picture(&dev, 0.18 / mean);
    double psnr = 0;
    CHECK(lf_image_psnr(&dev, &film_rgb, &psnr, &err) == 0);
    printf("demo (%dx%d centre), noiseless mosaic developed vs Film \"rgb\": %.2f dB\n", film.width, film.height,
           psnr);
    CHECK_MSG(psnr >= 38, "%.2f dB", psnr);
    bin2(&dev_lin), bin2(&film_lin);
    picture(&dev_lin, 0.18 / mean), picture(&film_lin, 0.18 / mean);
    double psnr2 = 0;
    lf_image_psnr(&dev_lin, &film_lin, &psnr2, &err);
    printf("  ... both binned 2x2 (the mosaic's own resolution): %.2f dB\n", psnr2);
    lf_image_free(&dev_lin), lf_image_free(&film_lin);
    lf_image_free(&film), lf_image_free(&film_rgb), lf_image_free(&raw), lf_image_free(&dev);
    lf_attrs_free(&meta);
    free(text), free(rgb_text);
    return lf_test_end();
}
