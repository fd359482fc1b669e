/* lf_filter.h - pixel reconstruction filters, sampled by importance.
 *
 * As in pbrt-v4, a camera sample's film offset is drawn from the filter
 * itself (f(x,y) / integral) and the sample carries weight f/pdf, so every
 * sample lands in exactly one pixel: no splatting across pixels, and
 * rendering stays deterministic whatever the tile and thread layout.
 * Box is sampled exactly; the others through a tabulated |f| distribution
 * (weights keep the sign of negative lobes, e.g. Mitchell, Lanczos).
 */
#ifndef LF_FILTER_H
#define LF_FILTER_H

#include "lf_error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lf_filter_kind {
    LF_FILTER_BOX,
    LF_FILTER_TRIANGLE,
    LF_FILTER_GAUSSIAN,
    LF_FILTER_MITCHELL,
    LF_FILTER_LANCZOS
} lf_filter_kind;

typedef struct lf_filter {
    lf_filter_kind kind;
    double radius[2];
    double sigma;     /* gaussian */
    double b, c;      /* mitchell */
    double tau;       /* lanczos */
    /* tabulated sampling (not box) */
    int nx, ny;
    double *f;        /* nx*ny signed values */
    double *cdf_row;  /* marginal over rows, ny+1 */
    double *cdf_col;  /* conditional per row, ny*(nx+1) */
    double integral_abs;
} lf_filter;

/* The shape parameters of a filter; a value <= 0 (or NaN) takes pbrt-v4's
 * default: box radius 0.5; gaussian radius 1.5, sigma 0.5; mitchell radius 2,
 * B = C = 1/3; lanczos radius 4, tau 3; triangle radius 2. */
typedef struct lf_filter_params {
    double xradius, yradius, sigma, b, c, tau;
    int b_set, c_set; /* B and C may legitimately be 0 */
} lf_filter_params;

/* Sets up and tabulates a filter; returns 0 or LF_ERR_NOMEM. p may be NULL. */
int lf_filter_init(lf_filter *f, lf_filter_kind kind, const lf_filter_params *p, lf_error *err);
void lf_filter_free(lf_filter *f);
double lf_filter_eval(const lf_filter *f, double x, double y);
/* Maps u in [0,1)^2 to an offset (dx, dy) from the pixel centre; returns the
 * weight.  The box (uniform offsets, weight 1) inline: it runs per camera ray. */
double lf_filter_sample_table(const lf_filter *f, double u0, double u1, double *dx, double *dy);
static inline double lf_filter_sample(const lf_filter *f, double u0, double u1, double *dx, double *dy)
{
    if (f->kind == LF_FILTER_BOX) {
        *dx = (2 * u0 - 1) * f->radius[0];
        *dy = (2 * u1 - 1) * f->radius[1];
        return 1.0;
    }
    return lf_filter_sample_table(f, u0, u1, dx, dy);
}

#ifdef __cplusplus
}
#endif
#endif
