/* lf_distrib.h - piecewise-constant 1D and 2D distributions for importance
 * sampling tabulated functions (environment maps, emitter power). */
#ifndef LF_DISTRIB_H
#define LF_DISTRIB_H

#include <stddef.h>

#include "lf_error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lf_distrib1d {
    int n;
    double *func; /* n values, |f| */
    double *cdf;  /* n+1 values, cdf[n] == 1 (uniform if the integral is 0) */
    double integral; /* sum(func)/n: the integral over [0,1) */
} lf_distrib1d;

int lf_distrib1d_init(lf_distrib1d *d, const double *f, int n, lf_error *err);
void lf_distrib1d_free(lf_distrib1d *d);
/* Returns the continuous sample in [0,1); *pdf is the density there, *index the cell. */
double lf_distrib1d_sample(const lf_distrib1d *d, double u, double *pdf, int *index);
/* Discrete sampling of a cell with probability func[i]/sum. */
int lf_distrib1d_sample_discrete(const lf_distrib1d *d, double u, double *pmf, double *u_remapped);
double lf_distrib1d_pmf(const lf_distrib1d *d, int i);

typedef struct lf_distrib2d {
    int nu, nv;
    lf_distrib1d *conditional; /* nv rows of nu */
    lf_distrib1d marginal;     /* over rows */
} lf_distrib2d;

/* f is nv rows of nu values (row-major). */
int lf_distrib2d_init(lf_distrib2d *d, const double *f, int nu, int nv, lf_error *err);
void lf_distrib2d_free(lf_distrib2d *d);
/* Samples (u, v) in [0,1)^2 with density *pdf with respect to area in [0,1)^2. */
void lf_distrib2d_sample(const lf_distrib2d *d, double u0, double u1, double *u, double *v, double *pdf);
double lf_distrib2d_pdf(const lf_distrib2d *d, double u, double v);

#ifdef __cplusplus
}
#endif
#endif
