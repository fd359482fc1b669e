/* plot.c - a drawing's primitive list as SVG (lf_plot.h). */
#include <stdlib.h>
#include <string.h>

#include "base/lf_buf.h"
#include "base/lf_plot.h"

char *lf_plot_svg(const lf_plot *d)
{
    lf_strbuf b = {0};
    lf_strbuf_printf(&b, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n",
                     d->w, d->h, d->w, d->h);
    lf_strbuf_puts(&b, "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n");
    for (size_t i = 0; i < d->n; i++) {
        const lf_plot_prim *q = &d->p[i];
        if (q->kind == LF_PLOT_DOT) {
            lf_strbuf_printf(&b, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"0.8\" fill=\"#%06x\"/>\n", q->pts[0], q->pts[1],
                             q->color);
        } else if (q->kind == LF_PLOT_TEXT) {
            lf_strbuf_printf(&b, "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" font-size=\"12\" fill=\"#333\">",
                             q->pts[0], q->pts[1]);
            for (const char *c = q->text ? q->text : ""; *c; c++)
                if (*c == '<')
                    lf_strbuf_puts(&b, "&lt;");
                else if (*c == '&')
                    lf_strbuf_puts(&b, "&amp;");
                else
                    lf_strbuf_append(&b, c, 1);
            lf_strbuf_puts(&b, "</text>\n");
        } else {
            lf_strbuf_printf(&b, "<%s points=\"", q->kind == LF_PLOT_POLYGON ? "polygon" : "polyline");
            for (int j = 0; j < q->n; j++)
                lf_strbuf_printf(&b, "%.2f,%.2f ", q->pts[2 * j], q->pts[2 * j + 1]);
            if (q->kind == LF_PLOT_POLYGON)
                lf_strbuf_printf(&b, "\" fill=\"#%06x", q->fill);
            else
                lf_strbuf_puts(&b, "\" fill=\"none");
            lf_strbuf_printf(&b, "\" stroke=\"#%06x\" stroke-width=\"%.2f\"%s/>\n", q->color, q->width,
                             q->dashed ? " stroke-dasharray=\"6,4\"" : "");
        }
    }
    lf_strbuf_puts(&b, "</svg>\n");
    if (b.failed) {
        lf_strbuf_free(&b);
        return NULL;
    }
    return lf_strbuf_take(&b);
}

void lf_plot_free(lf_plot *d)
{
    for (size_t i = 0; i < d->n; i++) {
        free(d->p[i].pts);
        free(d->p[i].text);
    }
    free(d->p);
    memset(d, 0, sizeof *d);
}
