/* lf_plot.h - a drawing as a list of vector primitives (pixels, y down),
 * and its SVG document.  Built by camera/ (lflens's lens drawing), drawn to
 * pixels with text by image/ (lf_image_from_plot, Cairo): the list sits
 * here, below both, so neither depends on the other.
 *
 *   lf_plot plot; ... fill plot.p[0 .. plot.n) ...
 *   char *svg = lf_plot_svg(&plot);      // or lf_image_from_plot (image/lf_image.h)
 *   lf_plot_free(&plot);
 */
#ifndef LF_PLOT_H
#define LF_PLOT_H

#include <stddef.h>

typedef enum { LF_PLOT_POLYLINE, LF_PLOT_POLYGON, LF_PLOT_DOT, LF_PLOT_TEXT } lf_plot_kind;

/* Text is drawn in the "sans-serif" face at 12 px, #333 (the SVG's
 * <text> and image/'s pixels alike). */

typedef struct lf_plot_prim {
    lf_plot_kind kind;
    double *pts; /* x0 y0 x1 y1 ... (pixels); text: its baseline's left end */
    int n;       /* points */
    unsigned color, fill; /* 0xRRGGBB */
    double width;
    int dashed;
    char *text;
} lf_plot_prim;

typedef struct lf_plot {
    lf_plot_prim *p;
    size_t n, cap;
    int w, h;
    int failed; /* memory ran out while drawing */
} lf_plot;

/* The drawing as an SVG document (malloc'd; NULL when memory runs out). */
char *lf_plot_svg(const lf_plot *plot);
void lf_plot_free(lf_plot *plot);

#endif
