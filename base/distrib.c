#include "lf_distrib.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lf_distrib1d_init(lf_distrib1d *d, const double *f, int n, lf_error *err)
{
    memset(d, 0, sizeof *d);
    d->n = n;
    d->func = malloc(sizeof(double) * (size_t)n);
    d->cdf = malloc(sizeof(double) * (size_t)(n + 1));
    if (!d->func || !d->cdf) {
        lf_distrib1d_free(d);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for a sampling table of %d entries", n);
    }
    d->cdf[0] = 0.0;
    for (int i = 0; i < n; i++) {
        double v = isfinite(f[i]) ? fabs(f[i]) : 0.0;
        d->func[i] = v;
        d->cdf[i + 1] = d->cdf[i] + v / n;
    }
    d->integral = d->cdf[n];
    if (d->integral <= 0.0) {
        for (int i = 1; i <= n; i++)
            d->cdf[i] = (double)i / n;
    } else {
        for (int i = 1; i <= n; i++)
            d->cdf[i] /= d->integral;
    }
    d->cdf[n] = 1.0;
    return 0;
}

void lf_distrib1d_free(lf_distrib1d *d)
{
    free(d->func);
    free(d->cdf);
    d->func = d->cdf = NULL;
}

static int find_cell(const double *cdf, int n, double u)
{
    int lo = 0, hi = n;
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    /* skip zero-width cells so a sample never lands where the density is 0 */
    while (lo < n - 1 && cdf[lo + 1] <= cdf[lo])
        lo++;
    return lo;
}

double lf_distrib1d_sample(const lf_distrib1d *d, double u, double *pdf, int *index)
{
    int i = find_cell(d->cdf, d->n, u);
    double w = d->cdf[i + 1] - d->cdf[i];
    double du = w > 0 ? (u - d->cdf[i]) / w : 0.5;
    if (du < 0)
        du = 0;
    if (du >= 1)
        du = 0x1.fffffffffffffp-1;
    if (pdf)
        *pdf = d->integral > 0 ? d->func[i] / d->integral : 1.0;
    if (index)
        *index = i;
    double x = (i + du) / d->n;
    return x < 1.0 ? x : 0x1.fffffffffffffp-1;
}

int lf_distrib1d_sample_discrete(const lf_distrib1d *d, double u, double *pmf, double *u_remapped)
{
    int i = find_cell(d->cdf, d->n, u);
    double w = d->cdf[i + 1] - d->cdf[i];
    if (pmf)
        *pmf = w;
    if (u_remapped)
        *u_remapped = w > 0 ? fmin((u - d->cdf[i]) / w, 0x1.fffffffffffffp-1) : 0.5;
    return i;
}

double lf_distrib1d_pmf(const lf_distrib1d *d, int i)
{
    return d->cdf[i + 1] - d->cdf[i];
}

int lf_distrib2d_init(lf_distrib2d *d, const double *f, int nu, int nv, lf_error *err)
{
    memset(d, 0, sizeof *d);
    d->nu = nu;
    d->nv = nv;
    d->conditional = calloc((size_t)nv, sizeof *d->conditional);
    double *marg = malloc(sizeof(double) * (size_t)nv);
    if (!d->conditional || !marg) {
        free(marg);
        lf_distrib2d_free(d);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for a %dx%d sampling table", nu, nv);
    }
    for (int v = 0; v < nv; v++) {
        if (lf_distrib1d_init(&d->conditional[v], f + (size_t)v * nu, nu, err)) {
            free(marg);
            lf_distrib2d_free(d);
            return err ? err->code : LF_ERR_NOMEM;
        }
        marg[v] = d->conditional[v].integral;
    }
    int rc = lf_distrib1d_init(&d->marginal, marg, nv, err);
    free(marg);
    if (rc)
        lf_distrib2d_free(d);
    return rc;
}

void lf_distrib2d_free(lf_distrib2d *d)
{
    if (d->conditional)
        for (int v = 0; v < d->nv; v++)
            lf_distrib1d_free(&d->conditional[v]);
    free(d->conditional);
    d->conditional = NULL;
    lf_distrib1d_free(&d->marginal);
}

void lf_distrib2d_sample(const lf_distrib2d *d, double u0, double u1, double *u, double *v, double *pdf)
{
    double pv, pu;
    int row;
    *v = lf_distrib1d_sample(&d->marginal, u1, &pv, &row);
    *u = lf_distrib1d_sample(&d->conditional[row], u0, &pu, NULL);
    *pdf = pv * pu;
}

double lf_distrib2d_pdf(const lf_distrib2d *d, double u, double v)
{
    int iu = (int)(u * d->nu), iv = (int)(v * d->nv);
    if (iu < 0)
        iu = 0;
    if (iu >= d->nu)
        iu = d->nu - 1;
    if (iv < 0)
        iv = 0;
    if (iv >= d->nv)
        iv = d->nv - 1;
    if (d->marginal.integral <= 0)
        return 1.0;
    return d->conditional[iv].func[iu] / d->marginal.integral;
}
