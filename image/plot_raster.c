/* plot_raster.c - a drawing (base/lf_plot.h) in pixels, text included:
 * Cairo draws the lines, fills, dots and the labels (its toy text API, the
 * "sans-serif" face through fontconfig: DejaVu Sans on Debian), the same
 * primitives as the SVG, so the PNG reads on its own. */
#include <cairo.h>
#include <math.h>
#include <stdint.h>

#include "image/lf_image.h"

static double channel(unsigned c, int shift) { return (double)(c >> shift & 255u) / 255.0; }

static void set_color(cairo_t *cr, unsigned c)
{
    cairo_set_source_rgb(cr, channel(c, 16), channel(c, 8), channel(c, 0));
}

/* Off any sane canvas (or NaN): skipped, as the SVG viewer clips it. */
static int sane(const double *p, int n)
{
    for (int k = 0; k < 2 * n; k++)
        if (!(fabs(p[k]) < 1e6))
            return 0;
    return 1;
}

static void draw_prim(cairo_t *cr, const lf_plot_prim *q)
{
    if (!q->pts || q->n < 1 || !sane(q->pts, q->n))
        return;
    if (q->kind == LF_PLOT_DOT) {
        set_color(cr, q->color);
        cairo_arc(cr, q->pts[0], q->pts[1], 0.8, 0, 2 * M_PI);
        cairo_fill(cr);
    } else if (q->kind == LF_PLOT_TEXT) {
        if (!q->text)
            return;
        set_color(cr, 0x333333u); /* the SVG's text colour */
        cairo_move_to(cr, q->pts[0], q->pts[1]);
        cairo_show_text(cr, q->text);
    } else {
        cairo_new_path(cr);
        for (int j = 0; j < q->n; j++)
            cairo_line_to(cr, q->pts[2 * j], q->pts[2 * j + 1]);
        if (q->kind == LF_PLOT_POLYGON) {
            cairo_close_path(cr);
            set_color(cr, q->fill);
            cairo_fill_preserve(cr);
        }
        static const double dash[] = {6, 4};
        cairo_set_dash(cr, dash, q->dashed ? 2 : 0, 0);
        cairo_set_line_width(cr, q->width > 0 ? q->width : 1);
        set_color(cr, q->color);
        cairo_stroke(cr);
    }
}

int lf_image_from_plot(const lf_plot *plot, lf_image *out, lf_error *err)
{
    if (!(plot->w > 0 && plot->h > 0))
        return lf_error_set(err, LF_ERR_PARAM, "a drawing of %d x %d pixels", plot->w, plot->h);
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, plot->w, plot->h);
    cairo_t *cr = cairo_create(s);
    if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) {
        cairo_destroy(cr), cairo_surface_destroy(s);
        return lf_error_set(err, LF_ERR_NOMEM, "cannot draw %d x %d pixels (Cairo)", plot->w, plot->h);
    }
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 12);
    for (size_t i = 0; i < plot->n; i++)
        draw_prim(cr, &plot->p[i]);
    cairo_surface_flush(s);
    int rc = lf_image_alloc(out, plot->w, plot->h, 3, err);
    if (!rc) {
        /* RGB24: one native-endian 32-bit word per pixel, 0x00RRGGBB, sRGB */
        const unsigned char *data = cairo_image_surface_get_data(s);
        int stride = cairo_image_surface_get_stride(s);
        for (int y = 0; y < plot->h; y++)
            for (int x = 0; x < plot->w; x++) {
                uint32_t v = ((const uint32_t *)(const void *)(data + (size_t)y * (size_t)stride))[x];
                float *p = out->data + 3 * ((size_t)y * (size_t)plot->w + (size_t)x);
                p[0] = lf_srgb_decode((unsigned char)(v >> 16)), p[1] = lf_srgb_decode((unsigned char)(v >> 8));
                p[2] = lf_srgb_decode((unsigned char)v);
            }
    }
    cairo_destroy(cr);
    cairo_surface_destroy(s);
    return rc;
}
