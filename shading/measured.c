/* measured.c - RGL measured BRDFs (Dupuy & Jakob, "An Adaptive
 * Parameterization for Efficient Material Acquisition and Rendering",
 * SIGGRAPH Asia 2018) read from their ".bsdf" tensor files and evaluated
 * and sampled as pbrt-v4's MeasuredBxDF does.
 *
 * The file is a "tensor_file": named little-endian arrays.  theta_i and
 * phi_i (radians) are the incident directions the data was measured at;
 * ndf and sigma the microfacet distribution D and its projected area over
 * the unit square (theta2u, phi2u); vndf the visible-normal distribution
 * and luminance a sampling density, both conditional 2D tables over
 * (phi_i, theta_i); spectra the reflectance ratio at each wavelength over
 * the same (pre-warp) square.  f(wo, wi) = R(u) D(wm) / (4 sigma(wi)
 * cos(theta_i)) where u is where vndf's warp sends wm (its inverse).
 *
 * Without spectral rendering the spectra are reduced once, at load, to
 * linear sRGB reflectance ratios (each wavelength's weight is the RGB of a
 * unit hat spectrum there, lf_spectrum_pairs_rgb), and the RGB table is
 * interpolated like pbrt's spectral one. */
#include "lf_shading.h"

#include "base/lf_color.h"
#include "base/lf_file.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define PI_F ((float)LF_PI)

/* ------------------------------------------- piecewise-linear 2D tables */

/* The last index i in [0, n-2] with pred(i) true for a pred that is true
 * then false (pbrt's FindInterval). */
static int find_interval(int n, const float *v, int stride, float x)
{
    int lo = 0, hi = n - 2;
    if (hi < 0)
        return 0;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (v[(size_t)mid * (size_t)stride] <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* The parameters' interpolation: slice offset and the weight of each of
 * the 2^ndim corner slices. */
typedef struct pl_params {
    size_t slice;
    float w[LF_PL2D_MAX_PARAMS][2];
} pl_params;

static void pl_locate(const lf_pl2d *t, const float *param, pl_params *pp)
{
    pp->slice = 0;
    for (int d = 0; d < t->ndim; d++) {
        if (t->param_size[d] == 1) {
            pp->w[d][0] = 1.f;
            pp->w[d][1] = 0.f;
            continue;
        }
        const float *pv = t->param_values[d];
        int i = find_interval(t->param_size[d], pv, 1, param[d]);
        float w1 = (param[d] - pv[i]) / (pv[i + 1] - pv[i]);
        w1 = lf_clampf(w1, 0.f, 1.f);
        pp->w[d][1] = w1;
        pp->w[d][0] = 1.f - w1;
        pp->slice += (size_t)t->param_stride[d] * (size_t)i;
    }
}

/* arr[i + slice offset] interpolated over the parameter corners; size is
 * the per-slice element count of arr. */
static float pl_lookup(const lf_pl2d *t, const float *arr, size_t i, size_t size, const pl_params *pp)
{
    float sum = 0.f;
    for (int c = 0; c < (1 << t->ndim); c++) {
        float w = 1.f;
        size_t off = pp->slice;
        for (int d = 0; d < t->ndim; d++) {
            int bit = (c >> d) & 1;
            w *= pp->w[d][bit];
            off += bit ? (size_t)t->param_stride[d] : 0;
        }
        if (w != 0.f)
            sum += w * arr[off * size + i];
    }
    return sum;
}

void lf_pl2d_free(lf_pl2d *t)
{
    if (!t)
        return;
    for (int d = 0; d < LF_PL2D_MAX_PARAMS; d++)
        free(t->param_values[d]);
    free(t->data);
    free(t->marginal_cdf);
    free(t->conditional_cdf);
    memset(t, 0, sizeof *t);
}

/* pbrt-v4 PiecewiseLinear2D: the CDFs of each slice integrate the bilinear
 * interpolant by the trapezoid rule; a sampled table (build_cdf) is
 * normalised to a density on [0,1]^2, a plain one keeps its values. */
static void pl_build_slice(lf_pl2d *t, const float *in, float *data, float *marg, float *cond)
{
    int nx = t->nx, ny = t->ny;
    for (int y = 0; y < ny; y++) {
        double sum = 0.0;
        size_t i = (size_t)y * (size_t)nx;
        cond[i] = 0.f;
        for (int x = 0; x < nx - 1; x++, i++) {
            sum += .5 * ((double)in[i] + (double)in[i + 1]);
            cond[i + 1] = (float)sum;
        }
    }
    marg[0] = 0.f;
    double sum = 0.0;
    for (int y = 0; y < ny - 1; y++) {
        sum += .5 * ((double)cond[(size_t)(y + 1) * nx - 1] + (double)cond[(size_t)(y + 2) * nx - 1]);
        marg[y + 1] = (float)sum;
    }
    float norm = marg[ny - 1] > 0.f ? 1.f / marg[ny - 1] : 0.f;
    for (size_t i = 0; i < (size_t)nx * ny; i++) {
        cond[i] *= norm;
        data[i] = in[i] * norm;
    }
    for (int y = 0; y < ny; y++)
        marg[y] *= norm;
}

int lf_pl2d_init(lf_pl2d *t, const float *data, int nx, int ny, int ndim, const int *param_res,
                 const float *const *param_values, int build_cdf)
{
    memset(t, 0, sizeof *t);
    if (nx < 2 || ny < 2 || ndim < 0 || ndim > LF_PL2D_MAX_PARAMS)
        return LF_ERR_PARAM;
    t->nx = nx;
    t->ny = ny;
    t->ndim = ndim;
    size_t slices = 1;
    for (int d = ndim - 1; d >= 0; d--) {
        if (param_res[d] < 1)
            return LF_ERR_PARAM;
        t->param_size[d] = param_res[d];
        t->param_values[d] = malloc(sizeof(float) * (size_t)param_res[d]);
        if (!t->param_values[d])
            return lf_pl2d_free(t), LF_ERR_NOMEM;
        memcpy(t->param_values[d], param_values[d], sizeof(float) * (size_t)param_res[d]);
        t->param_stride[d] = param_res[d] > 1 ? (int)slices : 0;
        slices *= (size_t)param_res[d];
    }
    size_t n = (size_t)nx * (size_t)ny;
    t->data = malloc(sizeof(float) * slices * n);
    if (build_cdf) {
        t->marginal_cdf = malloc(sizeof(float) * slices * (size_t)ny);
        t->conditional_cdf = malloc(sizeof(float) * slices * n);
    }
    if (!t->data || (build_cdf && (!t->marginal_cdf || !t->conditional_cdf)))
        return lf_pl2d_free(t), LF_ERR_NOMEM;
    for (size_t s = 0; s < slices; s++) {
        if (build_cdf)
            pl_build_slice(t, data + s * n, t->data + s * n, t->marginal_cdf + s * ny, t->conditional_cdf + s * n);
        else /* Evaluate multiplies by (nx-1)(ny-1) */
            for (size_t i = 0; i < n; i++)
                t->data[s * n + i] = data[s * n + i] / (float)((nx - 1) * (ny - 1));
    }
    return LF_OK;
}

float lf_pl2d_eval(const lf_pl2d *t, float px, float py, const float *param)
{
    pl_params pp;
    pl_locate(t, param, &pp);
    px *= (float)(t->nx - 1);
    py *= (float)(t->ny - 1);
    int ox = (int)px, oy = (int)py;
    ox = ox < 0 ? 0 : ox > t->nx - 2 ? t->nx - 2 : ox;
    oy = oy < 0 ? 0 : oy > t->ny - 2 ? t->ny - 2 : oy;
    float w1x = px - (float)ox, w1y = py - (float)oy, w0x = 1.f - w1x, w0y = 1.f - w1y;
    size_t size = (size_t)t->nx * t->ny, i = (size_t)ox + (size_t)oy * t->nx;
    float v00 = pl_lookup(t, t->data, i, size, &pp), v10 = pl_lookup(t, t->data, i + 1, size, &pp);
    float v01 = pl_lookup(t, t->data, i + t->nx, size, &pp), v11 = pl_lookup(t, t->data, i + t->nx + 1, size, &pp);
    return (w0y * (w0x * v00 + w1x * v10) + w1y * (w0x * v01 + w1x * v11)) * (float)((t->nx - 1) * (t->ny - 1));
}

/* Solves the linear-density CDF c0 u + (c1 - c0) u^2 / 2 = x on [0,1]. */
static float invert_linear(float x, float c0, float c1)
{
    if (fabsf(c0 - c1) < 1e-4f * (c0 + c1))
        return (c0 + c1) > 0.f ? 2.f * x / (c0 + c1) : 0.f;
    return (c0 - sqrtf(fmaxf(0.f, c0 * c0 - 2.f * x * (c0 - c1)))) / (c0 - c1);
}

/* The last index whose interpolated value is < x (pbrt's FindInterval on
 * a CDF row of n values at arr[base ...]). */
static int find_cdf(const lf_pl2d *t, const float *arr, size_t base, size_t size, int n, float x,
                    const pl_params *pp, const float *arr2, float blend)
{
    int lo = 0, hi = n - 2;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        float v = pl_lookup(t, arr, base + (size_t)mid, size, pp);
        if (arr2)
            v = (1.f - blend) * v + blend * pl_lookup(t, arr2, base + (size_t)mid, size, pp);
        if (v < x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

float lf_pl2d_sample(const lf_pl2d *t, float *ux, float *uy, const float *param)
{
    float sx = lf_clampf(*ux, 1.f - LF_ONE_MINUS_EPS, LF_ONE_MINUS_EPS);
    float sy = lf_clampf(*uy, 1.f - LF_ONE_MINUS_EPS, LF_ONE_MINUS_EPS);
    pl_params pp;
    pl_locate(t, param, &pp);
    int nx = t->nx, ny = t->ny;
    size_t ssize = (size_t)nx * ny;
    /* the row from the marginal CDF, then the fraction within it */
    int row = find_cdf(t, t->marginal_cdf, 0, (size_t)ny, ny, sy, &pp, NULL, 0.f);
    sy -= pl_lookup(t, t->marginal_cdf, (size_t)row, (size_t)ny, &pp);
    size_t off = (size_t)row * nx;
    float r0 = pl_lookup(t, t->conditional_cdf, off + nx - 1, ssize, &pp);
    float r1 = pl_lookup(t, t->conditional_cdf, off + 2 * (size_t)nx - 1, ssize, &pp);
    sy = invert_linear(sy, r0, r1);
    /* the column from the conditional CDF blended between the two rows */
    sx *= (1.f - sy) * r0 + sy * r1;
    int col = find_cdf(t, t->conditional_cdf, off, ssize, nx, sx, &pp, t->conditional_cdf + nx, sy);
    sx -= (1.f - sy) * pl_lookup(t, t->conditional_cdf, off + col, ssize, &pp) +
          sy * pl_lookup(t, t->conditional_cdf + nx, off + col, ssize, &pp);
    off += (size_t)col;
    float v00 = pl_lookup(t, t->data, off, ssize, &pp), v10 = pl_lookup(t, t->data + 1, off, ssize, &pp);
    float v01 = pl_lookup(t, t->data + nx, off, ssize, &pp), v11 = pl_lookup(t, t->data + nx + 1, off, ssize, &pp);
    float c0 = (1.f - sy) * v00 + sy * v01, c1 = (1.f - sy) * v10 + sy * v11;
    sx = invert_linear(sx, c0, c1);
    *ux = ((float)col + sx) / (float)(nx - 1);
    *uy = ((float)row + sy) / (float)(ny - 1);
    return ((1.f - sx) * c0 + sx * c1) * (float)((nx - 1) * (ny - 1));
}

float lf_pl2d_invert(const lf_pl2d *t, float *px, float *py, const float *param)
{
    pl_params pp;
    pl_locate(t, param, &pp);
    int nx = t->nx, ny = t->ny;
    size_t ssize = (size_t)nx * ny;
    float x = *px * (float)(nx - 1), y = *py * (float)(ny - 1);
    int ix = (int)x, iy = (int)y;
    ix = ix < 0 ? 0 : ix > nx - 2 ? nx - 2 : ix;
    iy = iy < 0 ? 0 : iy > ny - 2 ? ny - 2 : iy;
    x -= (float)ix;
    y -= (float)iy;
    size_t off = (size_t)ix + (size_t)iy * nx;
    float v00 = pl_lookup(t, t->data, off, ssize, &pp), v10 = pl_lookup(t, t->data + 1, off, ssize, &pp);
    float v01 = pl_lookup(t, t->data + nx, off, ssize, &pp), v11 = pl_lookup(t, t->data + nx + 1, off, ssize, &pp);
    float c0 = (1.f - y) * v00 + y * v01, c1 = (1.f - y) * v10 + y * v11;
    float pdf = (1.f - x) * c0 + x * c1;
    x *= c0 + .5f * x * (c1 - c0);
    x += (1.f - y) * pl_lookup(t, t->conditional_cdf, off, ssize, &pp) +
         y * pl_lookup(t, t->conditional_cdf + nx, off, ssize, &pp);
    size_t roff = (size_t)iy * nx;
    float r0 = pl_lookup(t, t->conditional_cdf, roff + nx - 1, ssize, &pp);
    float r1 = pl_lookup(t, t->conditional_cdf, roff + 2 * (size_t)nx - 1, ssize, &pp);
    x /= (1.f - y) * r0 + y * r1;
    y *= r0 + .5f * y * (r1 - r0);
    y += pl_lookup(t, t->marginal_cdf, (size_t)iy, (size_t)ny, &pp);
    *px = x;
    *py = y;
    return pdf * (float)((nx - 1) * (ny - 1));
}

/* ------------------------------------------------------- tensor files */

typedef struct tensor_field {
    char name[64];
    int dtype; /* 1 uint8 ... 10 float32, 11 float64 */
    int ndim;
    uint64_t shape[8];
    const unsigned char *data; /* into the file buffer */
    size_t count;
} tensor_field;

static uint64_t rd_le(const unsigned char *p, int n)
{
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

static const int dtype_size[12] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 2, 4, 8};

/* Parses the field table of a tensor file held in buf (pbrt-v4's Tensor):
 * "tensor_file\0", version 1.0, a u32 field count, then per field a u16
 * name length and name, u16 rank, u8 type, u64 offset and rank u64 sizes. */
static int tensor_parse(const char *path, const unsigned char *buf, size_t len, tensor_field *fields, int max_fields,
                        int *n_out, lf_error *err)
{
    if (len < 18 || memcmp(buf, "tensor_file", 12) != 0)
        return lf_error_set(err, LF_ERR_PARSE, "%s: not a tensor file (\"tensor_file\" header missing)", path);
    if (buf[12] != 1 || buf[13] != 0)
        return lf_error_set(err, LF_ERR_PARSE, "%s: tensor file version %d.%d (1.0 expected)", path, buf[12], buf[13]);
    uint64_t n = rd_le(buf + 14, 4);
    size_t pos = 18;
    if (n > (uint64_t)max_fields)
        return lf_error_set(err, LF_ERR_PARSE, "%s: %llu fields (at most %d)", path, (unsigned long long)n,
                            max_fields);
    for (uint64_t k = 0; k < n; k++) {
        tensor_field *f = &fields[k];
        if (pos + 2 > len)
            goto truncated;
        size_t nl = (size_t)rd_le(buf + pos, 2);
        pos += 2;
        if (pos + nl + 11 > len || nl >= sizeof f->name)
            goto truncated;
        memcpy(f->name, buf + pos, nl);
        f->name[nl] = 0;
        pos += nl;
        f->ndim = (int)rd_le(buf + pos, 2);
        f->dtype = buf[pos + 2];
        uint64_t offset = rd_le(buf + pos + 3, 8);
        pos += 11;
        if (f->ndim > 8 || f->dtype < 1 || f->dtype > 11 || pos + 8 * (size_t)f->ndim > len)
            goto truncated;
        uint64_t count = 1;
        for (int d = 0; d < f->ndim; d++, pos += 8) {
            f->shape[d] = rd_le(buf + pos, 8);
            if (f->shape[d] > ((uint64_t)1 << 32) || (f->shape[d] && count > UINT64_MAX / f->shape[d]))
                goto truncated;
            count *= f->shape[d];
        }
        if (offset > len || count > (len - offset) / (uint64_t)dtype_size[f->dtype])
            return lf_error_set(err, LF_ERR_PARSE, "%s: field \"%s\" runs past the end of the file", path, f->name);
        f->data = buf + offset;
        f->count = (size_t)count;
    }
    *n_out = (int)n;
    return LF_OK;
truncated:
    return lf_error_set(err, LF_ERR_PARSE, "%s: truncated or corrupt tensor field table", path);
}

static const tensor_field *tensor_get(const tensor_field *f, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (strcmp(f[i].name, name) == 0)
            return &f[i];
    return NULL;
}

/* The field as floats (float32 in the files pbrt reads; copied, since the
 * buffer need not be aligned; the files are little-endian, as is every
 * host lensfield builds on). */
static float *tensor_floats(const tensor_field *f)
{
    float *out = malloc(sizeof(float) * (f->count ? f->count : 1));
    if (out)
        memcpy(out, f->data, sizeof(float) * f->count);
    return out;
}

/* ------------------------------------------------------ the BRDF data */

struct lf_measured {
    lf_pl2d ndf, sigma, vndf, luminance, rgb;
    int isotropic;
};

void lf_measured_free(lf_measured *m)
{
    if (!m)
        return;
    lf_pl2d_free(&m->ndf);
    lf_pl2d_free(&m->sigma);
    lf_pl2d_free(&m->vndf);
    lf_pl2d_free(&m->luminance);
    lf_pl2d_free(&m->rgb);
    free(m);
}

/* pbrt-v4 MeasuredBRDF::Create's structure check. */
static int check_structure(const tensor_field *const *f)
{
    const tensor_field *th = f[0], *ph = f[1], *ndf = f[2], *sig = f[3], *vndf = f[4], *sp = f[5], *lum = f[6],
                       *wl = f[7], *desc = f[8], *jac = f[9];
    for (int i = 0; i < 10; i++)
        if (!f[i])
            return 0;
    return desc->ndim == 1 && desc->dtype == 1 && th->ndim == 1 && th->dtype == 10 && ph->ndim == 1 &&
           ph->dtype == 10 && wl->ndim == 1 && wl->dtype == 10 && ndf->ndim == 2 && ndf->dtype == 10 &&
           sig->ndim == 2 && sig->dtype == 10 && vndf->ndim == 4 && vndf->dtype == 10 &&
           vndf->shape[0] == ph->shape[0] && vndf->shape[1] == th->shape[0] && lum->ndim == 4 && lum->dtype == 10 &&
           lum->shape[0] == ph->shape[0] && lum->shape[1] == th->shape[0] && lum->shape[2] == lum->shape[3] &&
           sp->dtype == 10 && sp->ndim == 5 && sp->shape[0] == ph->shape[0] && sp->shape[1] == th->shape[0] &&
           sp->shape[2] == wl->shape[0] && sp->shape[3] == sp->shape[4] && lum->shape[2] == sp->shape[3] &&
           lum->shape[3] == sp->shape[4] && jac->ndim == 1 && jac->shape[0] == 1 && jac->dtype == 1 &&
           ph->shape[0] >= 1 && th->shape[0] >= 1 && wl->shape[0] >= 1 && ndf->shape[0] >= 2 && ndf->shape[1] >= 2 &&
           sig->shape[0] >= 2 && sig->shape[1] >= 2 && vndf->shape[2] >= 2 && vndf->shape[3] >= 2 &&
           sp->shape[3] >= 2;
}

/* The spectra table [phi][theta][lambda][n][n] reduced to RGB
 * [phi][theta][3][n][n]: linear in the spectrum, so each wavelength's
 * weight is the RGB of a unit hat there. */
static float *spectra_to_rgb(const tensor_field *sp, const tensor_field *wl)
{
    size_t nw = (size_t)wl->shape[0], cells = (size_t)sp->shape[3] * sp->shape[4];
    size_t slices = (size_t)sp->shape[0] * sp->shape[1];
    float *lam = tensor_floats(wl), *spec = tensor_floats(sp);
    double *l = malloc(sizeof(double) * nw), *hat = calloc(nw, sizeof(double));
    lf_vec3 *weight = malloc(sizeof(lf_vec3) * nw);
    float *out = malloc(sizeof(float) * slices * 3 * cells);
    if (lam && spec && l && hat && weight && out) {
        for (size_t k = 0; k < nw; k++)
            l[k] = lam[k];
        for (size_t k = 0; k < nw; k++) {
            hat[k] = 1.0;
            weight[k] = nw == 1 ? lf_v3(1, 1, 1) : lf_spectrum_pairs_rgb(l, hat, nw, LF_SPECTRUM_UNBOUNDED);
            hat[k] = 0.0;
        }
        for (size_t s = 0; s < slices; s++)
            for (size_t i = 0; i < cells; i++) {
                double c[3] = {0, 0, 0};
                for (size_t k = 0; k < nw; k++) {
                    double v = spec[(s * nw + k) * cells + i];
                    c[0] += v * weight[k].x;
                    c[1] += v * weight[k].y;
                    c[2] += v * weight[k].z;
                }
                for (int ch = 0; ch < 3; ch++)
                    out[(s * 3 + (size_t)ch) * cells + i] = (float)c[ch];
            }
    } else {
        free(out);
        out = NULL;
    }
    free(lam);
    free(spec);
    free(l);
    free(hat);
    free(weight);
    return out;
}

/* The tables of a checked file (pbrt-v4 MeasuredBRDF::Create). */
static int build_tables(lf_measured *m, const tensor_field *const *f)
{
    const tensor_field *th = f[0], *ph = f[1], *ndf = f[2], *sig = f[3], *vndf = f[4], *sp = f[5], *lum = f[6],
                       *wl = f[7];
    float *theta = tensor_floats(th), *phi = tensor_floats(ph), *a = NULL;
    float chan[3] = {0, 1, 2};
    int rc = theta && phi ? LF_OK : LF_ERR_NOMEM;
    int res2[2] = {(int)ph->shape[0], (int)th->shape[0]}, res3[3] = {res2[0], res2[1], 3};
    const float *vals2[2] = {phi, theta}, *vals3[3] = {phi, theta, chan};
    if (!rc && (a = tensor_floats(ndf)))
        rc = lf_pl2d_init(&m->ndf, a, (int)ndf->shape[1], (int)ndf->shape[0], 0, NULL, NULL, 0);
    else if (!rc)
        rc = LF_ERR_NOMEM;
    free(a);
    a = NULL;
    if (!rc && (a = tensor_floats(sig)))
        rc = lf_pl2d_init(&m->sigma, a, (int)sig->shape[1], (int)sig->shape[0], 0, NULL, NULL, 0);
    else if (!rc)
        rc = LF_ERR_NOMEM;
    free(a);
    a = NULL;
    if (!rc && (a = tensor_floats(vndf)))
        rc = lf_pl2d_init(&m->vndf, a, (int)vndf->shape[3], (int)vndf->shape[2], 2, res2, vals2, 1);
    else if (!rc)
        rc = LF_ERR_NOMEM;
    free(a);
    a = NULL;
    if (!rc && (a = tensor_floats(lum)))
        rc = lf_pl2d_init(&m->luminance, a, (int)lum->shape[3], (int)lum->shape[2], 2, res2, vals2, 1);
    else if (!rc)
        rc = LF_ERR_NOMEM;
    free(a);
    a = NULL;
    if (!rc && (a = spectra_to_rgb(sp, wl)))
        rc = lf_pl2d_init(&m->rgb, a, (int)sp->shape[4], (int)sp->shape[3], 3, res3, vals3, 0);
    else if (!rc)
        rc = LF_ERR_NOMEM;
    free(a);
    free(theta);
    free(phi);
    return rc;
}

/* A 1-D float32 field of strictly increasing finite values (the tables
 * interpolate between neighbours). */
static int increasing(const tensor_field *f)
{
    float prev = -INFINITY;
    for (size_t i = 0; i < f->count; i++) {
        float v;
        memcpy(&v, f->data + 4 * i, 4);
        if (!isfinite(v) || !(v > prev))
            return 0;
        prev = v;
    }
    return 1;
}

int lf_measured_load(const char *path, lf_measured **out, lf_error *err)
{
    *out = NULL;
    char *buf = NULL;
    size_t len = 0;
    int rc = lf_file_read(path, LF_FILE_MAX_DEFAULT, &buf, &len, NULL, err);
    if (rc)
        return rc;
    tensor_field fields[32];
    int n = 0;
    rc = tensor_parse(path, (const unsigned char *)buf, len, fields, 32, &n, err);
    const char *names[10] = {"theta_i", "phi_i",      "ndf",         "sigma",   "vndf",
                             "spectra", "luminance", "wavelengths", "description", "jacobian"};
    const tensor_field *f[10];
    for (int i = 0; i < 10; i++)
        f[i] = rc ? NULL : tensor_get(fields, n, names[i]);
    if (!rc && check_structure(f) && (!increasing(f[0]) || !increasing(f[1]) || !increasing(f[7])))
        rc = lf_error_set(err, LF_ERR_PARSE, "%s: theta_i, phi_i and wavelengths must be finite and increasing", path);
    else if (!rc && !check_structure(f))
        rc = lf_error_set(err, LF_ERR_PARSE,
                          "%s: invalid BRDF file structure (pbrt-v4 reads theta_i, phi_i, ndf, sigma, vndf, "
                          "luminance, spectra, wavelengths, description and jacobian with their shapes)",
                          path);
    lf_measured *m = rc ? NULL : calloc(1, sizeof *m);
    if (!rc && !m)
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    if (!rc) {
        m->isotropic = f[1]->shape[0] <= 2;
        if (!m->isotropic) {
            /* pbrt-v4 reads only files covering the full circle of phi_i */
            float p0, p1;
            memcpy(&p0, f[1]->data, 4);
            memcpy(&p1, f[1]->data + 4 * (f[1]->shape[0] - 1), 4);
            int reduction = (int)rint(2.0 * LF_PI / (double)(p1 - p0));
            if (reduction != 1)
                rc = lf_error_set(err, LF_ERR_UNSUPPORTED, "%s: phi_i symmetry reduction %d (!= 1) not supported",
                                  path, reduction);
        }
    }
    if (!rc && build_tables(m, f))
        rc = lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory or degenerate table", path);
    free(buf);
    if (rc) {
        lf_measured_free(m);
        return rc;
    }
    *out = m;
    return LF_OK;
}

/* ------------------------------------------------------- evaluation */

/* Dupuy & Jakob's warped coordinates: theta = (pi/2) u^2 spreads the
 * table's resolution towards the pole; phi maps [-pi, pi] to [0, 1]. */
static float theta2u(float theta) { return sqrtf(fmaxf(0.f, theta * (2.f / PI_F))); }
static float phi2u(float phi) { return (phi + PI_F) / (2.f * PI_F); }
static float u2theta(float u) { return u * u * (PI_F / 2.f); }
static float u2phi(float u) { return (2.f * u - 1.f) * PI_F; }

/* theta of a unit vector, accurate near the pole (acos is not, and the
 * warp's Jacobian vanishes there as theta^1.5). */
static float theta_of(lf_vec3 w) { return atan2f(sqrtf(w.x * w.x + w.y * w.y), w.z); }

/* The half vector of (wo, wi) in the table's square: theta_m, and phi_m
 * relative to phi_o for an isotropic file. */
static void half_coords(const lf_measured *m, lf_vec3 wo, lf_vec3 wm, float *ux, float *uy)
{
    float phi_o = atan2f(wo.y, wo.x);
    float theta_m = theta_of(wm), phi_m = atan2f(wm.y, wm.x);
    *ux = theta2u(theta_m);
    float v = phi2u(m->isotropic ? phi_m - phi_o : phi_m);
    *uy = v - floorf(v);
}

/* R(u) D(wm) / (4 sigma(wo) |cos theta_i|) with the reflectance ratio R
 * read at the pre-warp position u for incidence wo (both upper side). */
static lf_vec3 brdf_value(const lf_measured *m, lf_vec3 wo, lf_vec3 wi, float sx, float sy, float mx, float my)
{
    float theta_o = theta_of(wo), phi_o = atan2f(wo.y, wo.x);
    float p3[3] = {phi_o, theta_o, 0.f}, c[3];
    for (int ch = 0; ch < 3; ch++) {
        p3[2] = (float)ch;
        c[ch] = fmaxf(0.f, lf_pl2d_eval(&m->rgb, sx, sy, p3));
    }
    float sig = lf_pl2d_eval(&m->sigma, theta2u(theta_o), phi2u(phi_o), NULL);
    float d = lf_pl2d_eval(&m->ndf, mx, my, NULL);
    float den = 4.f * sig * fabsf(wi.z);
    if (!(den > 0.f))
        return lf_v3(0, 0, 0);
    return lf_scale(lf_v3(c[0], c[1], c[2]), d / den);
}

lf_vec3 lf_measured_f(const lf_measured *m, lf_vec3 wo, lf_vec3 wi)
{
    if (!(wo.z * wi.z > 0.f))
        return lf_v3(0, 0, 0);
    if (wo.z < 0.f) { /* two-sided, as pbrt */
        wo = lf_neg(wo);
        wi = lf_neg(wi);
    }
    lf_vec3 h = lf_add(wo, wi);
    if (!(lf_dot(h, h) > 0.f))
        return lf_v3(0, 0, 0);
    lf_vec3 wm = lf_normalize(h);
    float mx, my;
    half_coords(m, wo, wm, &mx, &my);
    float params[2] = {atan2f(wo.y, wo.x), theta_of(wo)};
    float sx = mx, sy = my;
    lf_pl2d_invert(&m->vndf, &sx, &sy, params);
    return brdf_value(m, wo, wi, sx, sy, mx, my);
}

/* d omega_i / d(u_m) = 4 (wo . wm) 2 pi^2 u sin(theta_m): the half-vector
 * warp's Jacobian times the reflection's. */
static float warp_jacobian(lf_vec3 wo, lf_vec3 wm, float ux)
{
    float sin_m = sqrtf(wm.x * wm.x + wm.y * wm.y);
    return 4.f * lf_dot(wo, wm) * fmaxf(2.f * PI_F * PI_F * ux * sin_m, 1e-6f);
}

float lf_measured_pdf(const lf_measured *m, lf_vec3 wo, lf_vec3 wi)
{
    if (!(wo.z * wi.z > 0.f))
        return 0.f;
    if (wo.z < 0.f) {
        wo = lf_neg(wo);
        wi = lf_neg(wi);
    }
    lf_vec3 h = lf_add(wo, wi);
    if (!(lf_dot(h, h) > 0.f))
        return 0.f;
    lf_vec3 wm = lf_normalize(h);
    float mx, my;
    half_coords(m, wo, wm, &mx, &my);
    float params[2] = {atan2f(wo.y, wo.x), theta_of(wo)};
    float sx = mx, sy = my;
    float vndf_pdf = lf_pl2d_invert(&m->vndf, &sx, &sy, params);
    float lum_pdf = lf_pl2d_eval(&m->luminance, sx, sy, params);
    return vndf_pdf * lum_pdf / warp_jacobian(wo, wm, mx);
}

int lf_measured_sample(const lf_measured *m, lf_vec3 wo, float u0, float u1, lf_vec3 *wi_out, lf_vec3 *f,
                       float *pdf)
{
    int flip = wo.z <= 0.f;
    if (flip)
        wo = lf_neg(wo);
    float phi_o = atan2f(wo.y, wo.x), params[2] = {phi_o, theta_of(wo)};
    float sx = u1, sy = u0; /* pbrt swaps the two sample values here */
    float lum_pdf = lf_pl2d_sample(&m->luminance, &sx, &sy, params);
    float mx = sx, my = sy;
    float vndf_pdf = lf_pl2d_sample(&m->vndf, &mx, &my, params);
    float theta_m = u2theta(mx), phi_m = u2phi(my) + (m->isotropic ? phi_o : 0.f);
    float st = sinf(theta_m);
    lf_vec3 wm = lf_v3(st * cosf(phi_m), st * sinf(phi_m), cosf(theta_m));
    lf_vec3 wi = lf_sub(lf_scale(wm, 2.f * lf_dot(wo, wm)), wo);
    if (!(wi.z > 0.f))
        return 0;
    *f = brdf_value(m, wo, wi, sx, sy, mx, my);
    *pdf = vndf_pdf * lum_pdf / warp_jacobian(wo, wm, mx);
    *wi_out = flip ? lf_neg(wi) : wi;
    return *pdf > 0.f;
}
