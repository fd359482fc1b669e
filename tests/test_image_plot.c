/* A drawing's pixels carry its labels (issue 33: `lflens plot -o x.png` drew
 * no text).  lf_image_from_plot (image/plot_raster.c, Cairo) is what lflens
 * writes as PNG.  A label is found in the drawing's pixels by rendering the
 * same label alone with the same font and correlating: the drawing with the
 * label matches the label alone in the label's box, the drawing without it
 * has no ink there, and another label in that box does not match; the PNG
 * file written and read back holds the same pixels. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"

static void add(lf_plot *d, lf_plot_kind kind, unsigned color, int n, const double *pts, const char *text)
{
    lf_plot_prim *p = realloc(d->p, sizeof *p * (d->n + 1));
    if (!p) {
        d->failed = 1;
        return;
    }
    d->p = p;
    lf_plot_prim *q = &d->p[d->n++];
    memset(q, 0, sizeof *q);
    q->kind = kind, q->color = color, q->n = n, q->width = 1;
    q->pts = malloc(sizeof(double) * 2 * (size_t)n);
    memcpy(q->pts, pts, sizeof(double) * 2 * (size_t)n);
    q->text = text ? strdup(text) : NULL;
}

/* A 400 x 140 drawing: a frame, an axis with ticks, and (when asked) the
 * title at baseline (20, 40) and an axis label at (20, 110). */
static void drawing(lf_plot *d, const char *title, const char *label)
{
    memset(d, 0, sizeof *d);
    d->w = 400, d->h = 140;
    double frame[] = {5, 5, 395, 5, 395, 135, 5, 135, 5, 5};
    add(d, LF_PLOT_POLYLINE, 0x999999, 5, frame, NULL);
    double axis[] = {20, 80, 380, 80};
    add(d, LF_PLOT_POLYLINE, 0x000000, 2, axis, NULL);
    for (int k = 0; k <= 6; k++) {
        double tick[] = {20 + 60 * k, 80, 20 + 60 * k, 86};
        add(d, LF_PLOT_POLYLINE, 0x000000, 2, tick, NULL);
    }
    if (title) {
        double at[] = {20, 40};
        add(d, LF_PLOT_TEXT, 0x333333, 1, at, title);
    }
    if (label) {
        double at[] = {20, 110};
        add(d, LF_PLOT_TEXT, 0x333333, 1, at, label);
    }
}

/* ink (1 - luminance) of pixel (x, y) */
static double ink(const lf_image *im, int x, int y)
{
    const float *p = lf_image_px(im, x, y);
    return 1.0 - (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
}

/* The title's box: baseline 40, 12 px text (ascent ~9-12 px, descent ~3). */
enum { BX0 = 15, BX1 = 300, BY0 = 24, BY1 = 46 };

static int inked(const lf_image *im)
{
    int n = 0;
    for (int y = BY0; y < BY1; y++)
        for (int x = BX0; x < BX1; x++)
            n += ink(im, x, y) > 0.5;
    return n;
}

/* normalised cross-correlation of the ink of a and b over the box */
static double correlation(const lf_image *a, const lf_image *b)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n = 0;
    for (int y = BY0; y < BY1; y++)
        for (int x = BX0; x < BX1; x++) {
            double u = ink(a, x, y), v = ink(b, x, y);
            sa += u, sb += v, saa += u * u, sbb += v * v, sab += u * v, n++;
        }
    double cov = sab / n - sa / n * sb / n, va = saa / n - sa / n * sa / n, vb = sbb / n - sb / n * sb / n;
    return va > 0 && vb > 0 ? cov / sqrt(va * vb) : 0;
}

int main(void)
{
    const char *title = "f/2.8 dgauss 50 mm: spot diagrams, 0.7 field";
    lf_plot full, none, alone, other;
    drawing(&full, title, "field angle (deg)");
    drawing(&none, NULL, NULL);
    memset(&alone, 0, sizeof alone);
    alone.w = 400, alone.h = 140;
    double at[] = {20, 40};
    add(&alone, LF_PLOT_TEXT, 0x333333, 1, at, title);
    drawing(&other, "distortion vs f tan(theta)", "field angle (deg)");
    CHECK(!full.failed && !none.failed && !alone.failed && !other.failed);

    lf_image a = {0}, n = {0}, l = {0}, o = {0};
    lf_error err = {0};
    CHECK(lf_image_from_plot(&full, &a, &err) == 0);
    CHECK(lf_image_from_plot(&none, &n, &err) == 0);
    CHECK(lf_image_from_plot(&alone, &l, &err) == 0);
    CHECK(lf_image_from_plot(&other, &o, &err) == 0);
    CHECK(a.width == 400 && a.height == 140 && a.channels == 3);
    if (a.data && n.data && l.data && o.data) {
        /* the lines are drawn: the axis row is dark, the background white */
        CHECK(ink(&a, 200, 80) > 0.5 && ink(&a, 200, 60) < 0.01);
        /* no text, no ink in the title's box; the title puts ink there */
        int ink_none = inked(&n), ink_full = inked(&a), ink_alone = inked(&l);
        CHECK_MSG(ink_none == 0, "%d inked pixels in the empty title box", ink_none);
        CHECK_MSG(ink_full > 150 && abs(ink_full - ink_alone) <= ink_alone / 50,
                  "title box: %d inked pixels in the drawing, %d for the title alone", ink_full, ink_alone);
        /* ... and it is the title: it correlates with the title drawn alone,
         * not with another label in the same place */
        double c_same = correlation(&a, &l), c_other = correlation(&o, &l);
        printf("title box: %d inked pixels; correlation with the title alone %.4f, another label %.4f\n", ink_full,
               c_same, c_other);
        CHECK(c_same > 0.99);
        CHECK(c_other < 0.5);
        /* the PNG written holds the same labels (what lflens plot -o x.png writes) */
        char dir[] = "/tmp/lf_plot_XXXXXX", path[64];
        CHECK(mkdtemp(dir) != NULL);
        snprintf(path, sizeof path, "%s/plot.png", dir);
        lf_image back = {0};
        CHECK(lf_image_write(path, &a, NULL, NULL, &err) == 0);
        CHECK(lf_image_read(path, &back, NULL, &err) == 0);
        if (back.data && back.width == a.width && back.height == a.height)
            CHECK_MSG(correlation(&back, &l) > 0.99, "PNG: %.4f", correlation(&back, &l));
        else
            CHECK_MSG(0, "%s: %s", path, err.msg);
        lf_image_free(&back);
        unlink(path);
        rmdir(dir);
    }
    /* a drawing of no size is refused, not drawn */
    lf_plot empty = {0};
    lf_image e = {0};
    lf_error eerr = {0};
    CHECK(lf_image_from_plot(&empty, &e, &eerr) == LF_ERR_PARAM);
    lf_image_free(&a), lf_image_free(&n), lf_image_free(&l), lf_image_free(&o);
    lf_plot_free(&full), lf_plot_free(&none), lf_plot_free(&alone), lf_plot_free(&other);
    return lf_test_end();
}
