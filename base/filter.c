#include "lf_filter.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double gaussian_1d(double x, double sigma, double r)
{
    double g = exp(-x * x / (2 * sigma * sigma)), gr = exp(-r * r / (2 * sigma * sigma));
    return g - gr > 0 ? g - gr : 0.0;
}

static double mitchell_1d(double x, double B, double C)
{
    x = fabs(x);
    if (x <= 1)
        return ((12 - 9 * B - 6 * C) * x * x * x + (-18 + 12 * B + 6 * C) * x * x + (6 - 2 * B)) / 6.0;
    if (x <= 2)
        return ((-B - 6 * C) * x * x * x + (6 * B + 30 * C) * x * x + (-12 * B - 48 * C) * x + (8 * B + 24 * C)) /
               6.0;
    return 0.0;
}

static double sinc(double x)
{
    if (fabs(x) < 1e-5)
        return 1.0;
    double px = 3.14159265358979323846 * x;
    return sin(px) / px;
}

double lf_filter_eval(const lf_filter *f, double x, double y)
{
    if (fabs(x) > f->radius[0] || fabs(y) > f->radius[1])
        return 0.0;
    switch (f->kind) {
    case LF_FILTER_BOX:
        return 1.0;
    case LF_FILTER_TRIANGLE:
        return fmax(0.0, f->radius[0] - fabs(x)) * fmax(0.0, f->radius[1] - fabs(y));
    case LF_FILTER_GAUSSIAN:
        return gaussian_1d(x, f->sigma, f->radius[0]) * gaussian_1d(y, f->sigma, f->radius[1]);
    case LF_FILTER_MITCHELL:
        /* pbrt scales the argument so the filter spans its radius: 2x/r. */
        return mitchell_1d(2 * x / f->radius[0], f->b, f->c) * mitchell_1d(2 * y / f->radius[1], f->b, f->c);
    case LF_FILTER_LANCZOS:
        return sinc(x) * sinc(x / f->tau) * sinc(y) * sinc(y / f->tau);
    }
    return 0.0;
}

int lf_filter_init(lf_filter *f, lf_filter_kind kind, const lf_filter_params *p, lf_error *err)
{
    lf_filter_params none = {0};
    if (!p)
        p = &none;
    memset(f, 0, sizeof *f);
    f->kind = kind;
    static const double def_radius[] = {0.5, 2.0, 1.5, 2.0, 4.0};
    double d = def_radius[kind];
    f->radius[0] = p->xradius > 0 ? p->xradius : d;
    f->radius[1] = p->yradius > 0 ? p->yradius : d;
    f->sigma = p->sigma > 0 ? p->sigma : 0.5;
    f->b = p->b_set ? p->b : 1.0 / 3.0;
    f->c = p->c_set ? p->c : 1.0 / 3.0;
    f->tau = p->tau > 0 ? p->tau : 3.0;
    if (kind == LF_FILTER_BOX)
        return 0;
    /* 32 cells per unit of radius, as pbrt-v4's FilterSampler. */
    f->nx = (int)(32 * f->radius[0]) * 2;
    f->ny = (int)(32 * f->radius[1]) * 2;
    if (f->nx < 2)
        f->nx = 2;
    if (f->ny < 2)
        f->ny = 2;
    f->f = malloc(sizeof(double) * f->nx * f->ny);
    f->cdf_row = malloc(sizeof(double) * (f->ny + 1));
    f->cdf_col = malloc(sizeof(double) * f->ny * (f->nx + 1));
    if (!f->f || !f->cdf_row || !f->cdf_col) {
        lf_filter_free(f);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for filter table");
    }
    double cw = 2 * f->radius[0] / f->nx, ch = 2 * f->radius[1] / f->ny;
    f->cdf_row[0] = 0;
    for (int j = 0; j < f->ny; j++) {
        double *cc = f->cdf_col + (size_t)j * (f->nx + 1);
        cc[0] = 0;
        for (int i = 0; i < f->nx; i++) {
            double x = -f->radius[0] + (i + 0.5) * cw, y = -f->radius[1] + (j + 0.5) * ch;
            double v = lf_filter_eval(f, x, y);
            f->f[j * f->nx + i] = v;
            cc[i + 1] = cc[i] + fabs(v);
        }
        f->cdf_row[j + 1] = f->cdf_row[j] + cc[f->nx];
    }
    f->integral_abs = f->cdf_row[f->ny] * cw * ch;
    return 0;
}

void lf_filter_free(lf_filter *f)
{
    free(f->f);
    free(f->cdf_row);
    free(f->cdf_col);
    f->f = f->cdf_row = f->cdf_col = NULL;
}

/* Finds i with cdf[i] <= u*total < cdf[i+1]; returns the offset within the cell. */
static int find_interval(const double *cdf, int n, double target, double *frac)
{
    int lo = 0, hi = n; /* cdf has n+1 entries */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= target)
            lo = mid;
        else
            hi = mid;
    }
    double w = cdf[lo + 1] - cdf[lo];
    *frac = w > 0 ? (target - cdf[lo]) / w : 0.5;
    if (*frac >= 1.0)
        *frac = 0x1.fffffffffffffp-1;
    return lo;
}

/* The tabulated filters: a cell by the tabulated |f|, uniform within it. */
double lf_filter_sample_table(const lf_filter *f, double u0, double u1, double *dx, double *dy)
{
    double fy, fx;
    int j = find_interval(f->cdf_row, f->ny, u1 * f->cdf_row[f->ny], &fy);
    const double *cc = f->cdf_col + (size_t)j * (f->nx + 1);
    int i = find_interval(cc, f->nx, u0 * cc[f->nx], &fx);
    double cw = 2 * f->radius[0] / f->nx, ch = 2 * f->radius[1] / f->ny;
    *dx = -f->radius[0] + (i + fx) * cw;
    *dy = -f->radius[1] + (j + fy) * ch;
    /* weight = f / pdf with pdf = |f_cell| / integral|f|: the sign of the
     * lobe times the absolute integral (the film divides by the weight sum). */
    double v = f->f[j * f->nx + i];
    return v < 0 ? -f->integral_abs : f->integral_abs;
}
