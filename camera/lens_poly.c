/* Polynomial ray transfer of a compound lens, fitted to exact traces
 * (camera/lens_poly.h; Hanika & Dachsbacher 2014, Schrade et al. 2016). */
#include "lens_poly.h"

#include <math.h>

#include "base/lf_math.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

lf_lens_poly_opts lf_lens_poly_opts_default(void)
{
    lf_lens_poly_opts o = {0};
    o.pixel_mm = 0.01;
    o.focus_distance_mm = 10000.0;
    o.target_px = 0.05;
    o.max_degree = LF_LENS_POLY_MAX_DEGREE;
    o.fit_samples = 8000;
    o.check_samples = 3000;
    o.seed = 1;
    return o;
}

/* CPU time of this thread: the set-up cost without the other processes
 * sharing the machine. */
static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* xorshift64*: a deterministic stream for fit and check samples. */
static double rnd(uint64_t *s)
{
    *s ^= *s >> 12, *s ^= *s << 25, *s ^= *s >> 27;
    return ((*s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static uint64_t rng_seed(uint32_t seed, uint64_t stream)
{
    uint64_t s = (seed + 1ull) * 0x9E3779B97F4A7C15ull ^ (stream * 0xD1B54A32D192ED03ull);
    return s ? s : 1;
}

/* ------------------------------------------------------------- monomials */

/* Parity classes (see the header): which outputs may use monomial r^i x^j y^k. */
#define RADIAL_MAX_DEGREE 5

static int in_class(int cls, int i, int j, int k)
{
    int odd = (i + j + k) & 1, yodd = k & 1;
    switch (cls) {
    case LF_LENS_POLY_CLASS_X: return odd && !yodd;
    case LF_LENS_POLY_CLASS_Y: return odd && yodd;
    default: return !odd && !yodd;
    }
}

static int output_class(int out)
{
    switch (out) {
    case LF_LENS_POLY_OUT_Y:
    case LF_LENS_POLY_OUT_DY:
    case LF_LENS_POLY_STOP_Y: return LF_LENS_POLY_CLASS_Y;
    default: return LF_LENS_POLY_CLASS_X;
    }
}

/* Monomials of each class up to the degree (the radial class: up to
 * RADIAL_MAX_DEGREE; the clipping tests only place each aperture's edge, where
 * a small error merely passes or blocks a ray in a thin rim, counted as
 * mismatches). */
static int build_monomials(lf_lens_poly *P, int degree)
{
    P->degree = degree;
    for (int cls = 0; cls < LF_LENS_POLY_CLASSES; cls++) {
        int max_deg = cls == LF_LENS_POLY_CLASS_RADIAL && degree > RADIAL_MAX_DEGREE ? RADIAL_MAX_DEGREE : degree;
        P->exps[cls] = malloc((size_t)(max_deg + 1) * (max_deg + 2) * (max_deg + 3) / 6 * sizeof *P->exps[cls]);
        if (!P->exps[cls])
            return -1;
        /* loop-nest order (r, then x, then y), as monomials_dense makes them */
        int n = 0;
        for (int i = 0; i <= max_deg; i++)
            for (int j = 0; i + j <= max_deg; j++)
                for (int k = 0; i + j + k <= max_deg; k++)
                    if (in_class(cls, i, j, k)) {
                        P->exps[cls][n][0] = (unsigned char)i, P->exps[cls][n][1] = (unsigned char)j;
                        P->exps[cls][n][2] = (unsigned char)k;
                        n++;
                    }
        P->n_mono[cls] = n;
        P->max_degree[cls] = max_deg;
        P->dense[cls] = 1;
    }
    return 0;
}

typedef struct powers {
    double a[LF_LENS_POLY_MAX_DEGREE + 1], b[LF_LENS_POLY_MAX_DEGREE + 1], c[LF_LENS_POLY_MAX_DEGREE + 1];
} powers;

static void make_powers(int degree, double a, double b, double c, powers *pw)
{
    pw->a[0] = pw->b[0] = pw->c[0] = 1.0;
    for (int d = 1; d <= degree; d++)
        pw->a[d] = pw->a[d - 1] * a, pw->b[d] = pw->b[d - 1] * b, pw->c[d] = pw->c[d - 1] * c;
}

static void monomials(const lf_lens_poly *P, int cls, const powers *pw, double *m)
{
    if (P->dense[cls]) {
        /* every monomial of the class, in loop-nest order: one product each */
        int D = P->max_degree[cls], n = 0;
        int even_total = cls == LF_LENS_POLY_CLASS_RADIAL, odd_y = cls == LF_LENS_POLY_CLASS_Y;
        for (int i = 0; i <= D; i++)
            for (int j = 0; i + j <= D; j++) {
                double rx = pw->a[i] * pw->b[j];
                /* k: parity fixed by the class (y odd or even) and the total's parity */
                int k0 = odd_y ? 1 : 0;
                if (((i + j + k0) & 1) != !even_total)
                    continue; /* no k of this parity makes the total's parity right */
                for (int k = k0; i + j + k <= D; k += 2)
                    m[n++] = rx * pw->c[k];
            }
        return;
    }
    const unsigned char(*e)[3] = P->exps[cls];
    for (int t = 0; t < P->n_mono[cls]; t++)
        m[t] = pw->a[e[t][0]] * pw->b[e[t][1]] * pw->c[e[t][2]];
}

/* Four partial sums: independent chains the CPU can overlap. */
static inline double eval_fn(const lf_lens_poly_fn *f, const double *m)
{
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    int t = 0;
    for (; t + 4 <= f->n; t += 4) {
        s0 += f->coef[t] * m[t];
        s1 += f->coef[t + 1] * m[t + 1];
        s2 += f->coef[t + 2] * m[t + 2];
        s3 += f->coef[t + 3] * m[t + 3];
    }
    for (; t < f->n; t++)
        s0 += f->coef[t] * m[t];
    return (s0 + s1) + (s2 + s3);
}

static void fn_free(lf_lens_poly_fn *f)
{
    free(f->coef);
    f->coef = NULL, f->n = 0;
}

void lf_lens_poly_free(lf_lens_poly *P)
{
    if (!P)
        return;
    for (int c = 0; c < LF_LENS_POLY_CLASSES; c++) {
        free(P->exps[c]);
        P->exps[c] = NULL;
    }
    for (int o = 0; o < LF_LENS_POLY_FIXED; o++)
        fn_free(&P->fn[o]);
    for (int c = 0; c < P->n_clip; c++)
        fn_free(&P->clip[c]);
    P->n_clip = 0;
}

/* -------------------------------------------------------- least squares */

/* Solves min |A x - b_k| for k < nrhs by Householder QR.  A is rows x cols,
 * column-major, overwritten; B is rows x nrhs column-major, overwritten; X
 * receives cols x nrhs.  -1 if A is (numerically) rank deficient. */
static int least_squares(double *A, int rows, int cols, double *B, int nrhs, double *X)
{
    double max_diag = 0.0;
    for (int k = 0; k < cols; k++) {
        double *ak = A + (size_t)k * rows;
        double norm = 0.0;
        for (int i = k; i < rows; i++)
            norm += ak[i] * ak[i];
        norm = sqrt(norm);
        if (norm > max_diag)
            max_diag = norm;
        if (!(norm > 1e-13 * max_diag) || norm == 0.0)
            return -1;
        double alpha = ak[k] > 0.0 ? -norm : norm;
        /* v = a_k - alpha e_k, stored in place; H = I - 2 v v^T / (v^T v) */
        ak[k] -= alpha;
        double vtv = 0.0;
        for (int i = k; i < rows; i++)
            vtv += ak[i] * ak[i];
        for (int j = k + 1; j < cols + nrhs; j++) {
            double *col = j < cols ? A + (size_t)j * rows : B + (size_t)(j - cols) * rows;
            double dot = 0.0;
            for (int i = k; i < rows; i++)
                dot += ak[i] * col[i];
            double f = 2.0 * dot / vtv;
            for (int i = k; i < rows; i++)
                col[i] -= f * ak[i];
        }
        ak[k] = alpha; /* R's diagonal; the rest of v is no longer needed */
    }
    for (int r = 0; r < nrhs; r++) {
        const double *b = B + (size_t)r * rows;
        double *x = X + (size_t)r * cols;
        for (int k = cols - 1; k >= 0; k--) {
            double s = b[k];
            for (int j = k + 1; j < cols; j++)
                s -= A[(size_t)j * rows + k] * x[j];
            x[k] = s / A[(size_t)k * rows + k];
        }
    }
    return 0;
}

/* ------------------------------------------------------------ samples */

typedef struct fit_sample {
    double in[3];     /* r / film_radius, x / rear_disk, y / rear_disk */
    double out[LF_LENS_POLY_FIXED];
    float *radial;    /* (x^2 + y^2) / aperture^2 per surface (real apertures) */
} fit_sample;

/* Front-most point of the front element: the fitted rays start on the plane
 * just in front of it. */
static double output_plane(const lf_lens *L)
{
    const lf_lens_surface *s = &L->s[0];
    double zv = s->z_mm - L->film_distance_mm, sag = 0.0;
    if (s->radius_mm < 0.0) {
        double R = -s->radius_mm, a = s->aperture_radius_mm < R ? s->aperture_radius_mm : R;
        sag = R - sqrt(R * R - a * a);
    }
    return zv - sag - 1e-3;
}

static void rotate(double cs, double sn, double x, double y, double *ox, double *oy)
{
    *ox = cs * x - sn * y;
    *oy = sn * x + cs * y;
}

static double focus_plane_x(const lf_lens_ray *r, double D, double *y)
{
    double t = (-D - r->o[2]) / r->d[2];
    *y = r->o[1] + t * r->d[1];
    return r->o[0] + t * r->d[0];
}

int lf_lens_poly_eval(const lf_lens_poly *P, double fx, double fy, double rx, double ry, lf_lens_ray *out,
                      double stop_xy[2])
{
    double r = sqrt(fx * fx + fy * fy);
    double cs = r > 0.0 ? fx / r : 1.0, sn = r > 0.0 ? fy / r : 0.0;
    /* rotate the rear-plane point into the frame where the film point is (r, 0) */
    double x = cs * rx + sn * ry, y = -sn * rx + cs * ry;
    double mr[64], mx[128], my[128];
    powers pw;
    make_powers(P->degree, r / P->film_radius_mm, x / P->rear_disk_radius_mm, y / P->rear_disk_radius_mm, &pw);
    monomials(P, LF_LENS_POLY_CLASS_RADIAL, &pw, mr);
    /* the surfaces that clip most often come first: most blocked rays stop early */
    for (int c = 0; c < P->n_clip; c++)
        if (!(eval_fn(&P->clip[c], mr) < 1.0))
            return 0;
    monomials(P, LF_LENS_POLY_CLASS_X, &pw, mx);
    monomials(P, LF_LENS_POLY_CLASS_Y, &pw, my);
    if (stop_xy && P->has_stop) {
        double sx = eval_fn(&P->fn[LF_LENS_POLY_STOP_X], mx) / P->stop_radius_mm;
        double sy = eval_fn(&P->fn[LF_LENS_POLY_STOP_Y], my) / P->stop_radius_mm;
        rotate(cs, sn, sx, sy, &stop_xy[0], &stop_xy[1]);
    } else if (stop_xy) {
        stop_xy[0] = stop_xy[1] = 0.0;
    }
    double dx = eval_fn(&P->fn[LF_LENS_POLY_OUT_DX], mx), dy = eval_fn(&P->fn[LF_LENS_POLY_OUT_DY], my);
    double s2 = dx * dx + dy * dy;
    if (!(s2 < 1.0))
        return 0;
    double ox = eval_fn(&P->fn[LF_LENS_POLY_OUT_X], mx), oy = eval_fn(&P->fn[LF_LENS_POLY_OUT_Y], my);
    rotate(cs, sn, ox, oy, &out->o[0], &out->o[1]);
    out->o[2] = P->z_out_mm;
    rotate(cs, sn, dx, dy, &out->d[0], &out->d[1]);
    out->d[2] = -sqrt(1.0 - s2);
    return 1;
}

double lf_lens_poly_sample_ray(const lf_lens *L, const lf_lens_poly *P, const lf_lens_pupil *pupil, int use_bounds,
                               double fx, double fy, double u, double v, lf_lens_stop_shape stop_shape,
                               const void *stop_ctx, lf_lens_ray *out)
{
    double rx, ry, pdf;
    if (use_bounds) {
        pdf = lf_lens_pupil_sample(pupil, fx, fy, u, v, &rx, &ry);
        if (!(pdf > 0.0))
            return 0.0;
    } else {
        /* Same samples as lf_lens_sample_ray; the polynomial is only valid
         * inside the bound, and nothing outside it gets through anyway. */
        double R = pupil->rear_disk_radius_mm;
        lf_concentric_disk(u, v, &rx, &ry);
        rx *= R, ry *= R;
        pdf = 1.0 / (M_PI * R * R);
        if (!lf_lens_pupil_contains(pupil, fx, fy, rx, ry))
            return 0.0;
    }
    double stop_xy[2];
    if (!lf_lens_poly_eval(P, fx, fy, rx, ry, out, stop_shape ? stop_xy : NULL))
        return 0.0;
    double T = 1.0;
    if (stop_shape) {
        T = stop_shape(stop_ctx, stop_xy[0], stop_xy[1]);
        if (!(T > 0.0))
            return 0.0;
    }
    double Z = L->film_distance_mm;
    double dx = rx - fx, dy = ry - fy;
    double c2 = Z * Z / (dx * dx + dy * dy + Z * Z);
    double w = T * c2 * c2 / (pdf * Z * Z);
    return isfinite(w) && w > 0.0 ? w : 0.0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void lf_lens_poly_measure(const lf_lens *L, const lf_lens_poly *P, const lf_lens_pupil *pupil,
                          double focus_distance_mm, double pixel_mm, int n, uint32_t seed, lf_lens_poly_error *e)
{
    memset(e, 0, sizeof *e);
    double *err = malloc((size_t)(n > 0 ? n : 1) * sizeof *err);
    uint64_t s = rng_seed(seed, 2);
    double sum_t = 0, sum_p = 0, sum_d = 0, sum_d2 = 0, sum_e2 = 0;
    long both = 0, mismatch = 0;
    for (int i = 0; i < n; i++) {
        double rr = pupil->film_radius_mm * sqrt(rnd(&s)), phi = 2.0 * M_PI * rnd(&s);
        double fx = rr * cos(phi), fy = rr * sin(phi), u = rnd(&s), v = rnd(&s);
        lf_lens_ray rt, rp;
        double wt = lf_lens_sample_ray(L, pupil, 1, fx, fy, u, v, NULL, &rt);
        double wp = lf_lens_poly_sample_ray(L, P, pupil, 1, fx, fy, u, v, NULL, NULL, &rp);
        sum_t += wt, sum_p += wp, sum_d += wp - wt, sum_d2 += (wp - wt) * (wp - wt);
        if ((wt > 0.0) != (wp > 0.0))
            mismatch++;
        if (wt > 0.0 && wp > 0.0) {
            double yt, yp;
            double xt = focus_plane_x(&rt, focus_distance_mm, &yt), xp = focus_plane_x(&rp, focus_distance_mm, &yp);
            double d = hypot(xt - xp, yt - yp) * P->magnification / pixel_mm;
            if (!isfinite(d))
                d = 1e30;
            if (err)
                err[both] = d;
            sum_e2 += d * d;
            both++;
        }
    }
    e->samples = n;
    e->both_passed = both;
    e->mismatch_fraction = n ? (double)mismatch / n : 0.0;
    if (n) {
        e->mean_weight_traced = sum_t / n, e->mean_weight_poly = sum_p / n;
        double md = sum_d / n, var = sum_d2 / n - md * md;
        e->weight_se = sqrt(var > 0.0 ? var / n : 0.0);
    }
    if (both && err) {
        qsort(err, (size_t)both, sizeof *err, cmp_double);
        e->rms_px = sqrt(sum_e2 / both);
        e->p99_px = err[(long)(0.99 * (both - 1))];
        e->max_px = err[both - 1];
    }
    free(err);
}

static double target_of(const fit_sample *f, const int *clip_surface, int out)
{
    return out < LF_LENS_POLY_FIXED ? f->out[out] : f->radial[clip_surface[out - LF_LENS_POLY_FIXED]];
}

/* Fits every output at one degree over the samples, then drops the terms
 * that matter least (Schrade et al. 2016 keep a sparse subset of a
 * high-degree polynomial): per output, terms sorted by their RMS
 * contribution |coef| rms(monomial) are dropped while the dropped
 * contributions sum to less than the output's budget; a term any output of
 * the class keeps stays, and the class is refitted on what is left.
 * 0, or -1. */
static int fit_degree(lf_lens_poly *P, int degree, const fit_sample *S, int ns, const int *clip_surface, int n_clip,
                      const double *budget)
{
    lf_lens_poly_free(P);
    if (build_monomials(P, degree))
        return -1;
    int rc = -1;
    double *A = NULL, *B = NULL, *X = NULL;
    powers pw;
    for (int cls = 0; cls < LF_LENS_POLY_CLASSES; cls++) {
        int cols = P->n_mono[cls];
        int outs[LF_LENS_POLY_FIXED + LF_LENS_POLY_MAX_CLIP], nout = 0;
        if (cls == LF_LENS_POLY_CLASS_RADIAL) {
            for (int c = 0; c < n_clip; c++)
                outs[nout++] = LF_LENS_POLY_FIXED + c;
        } else {
            for (int o = 0; o < LF_LENS_POLY_FIXED; o++)
                if (output_class(o) == cls && (P->has_stop || (o != LF_LENS_POLY_STOP_X && o != LF_LENS_POLY_STOP_Y)))
                    outs[nout++] = o;
        }
        if (!nout)
            continue;
        free(A), free(B), free(X);
        A = malloc((size_t)ns * cols * sizeof *A);
        B = malloc((size_t)ns * nout * sizeof *B);
        X = malloc((size_t)cols * nout * sizeof *X);
        if (!A || !B || !X)
            goto done;
        double m[128], rms[128] = {0};
        for (int pass = 0; pass < 2; pass++) {
            for (int i = 0; i < ns; i++) {
                make_powers(degree, S[i].in[0], S[i].in[1], S[i].in[2], &pw);
                monomials(P, cls, &pw, m);
                for (int c = 0; c < cols; c++) {
                    A[(size_t)c * ns + i] = m[c];
                    rms[c] += m[c] * m[c];
                }
                for (int o = 0; o < nout; o++)
                    B[(size_t)o * ns + i] = target_of(&S[i], clip_surface, outs[o]);
            }
            if (least_squares(A, ns, cols, B, nout, X))
                goto done;
            if (pass == 1 || !budget)
                break;
            int keep[128] = {0};
            for (int o = 0; o < nout; o++) {
                double contrib[128], dropped = 0.0;
                int order[128];
                for (int c = 0; c < cols; c++) {
                    contrib[c] = fabs(X[(size_t)o * cols + c]) * sqrt(rms[c] / ns);
                    order[c] = c;
                }
                for (int a = 1; a < cols; a++) /* insertion sort, ascending contribution */
                    for (int b = a; b > 0 && contrib[order[b]] < contrib[order[b - 1]]; b--) {
                        int t = order[b];
                        order[b] = order[b - 1], order[b - 1] = t;
                    }
                for (int c = 0; c < cols; c++) {
                    dropped += contrib[order[c]];
                    if (dropped > budget[outs[o]])
                        keep[order[c]] = 1;
                }
            }
            int kept = 0;
            for (int c = 0; c < cols; c++)
                if (keep[c]) {
                    memmove(P->exps[cls][kept], P->exps[cls][c], sizeof P->exps[cls][c]);
                    kept++;
                }
            if (kept == 0)
                kept = 1; /* keep the leading (linear or constant) term */
            if (kept < cols)
                P->dense[cls] = 0;
            P->n_mono[cls] = cols = kept;
            memset(rms, 0, sizeof rms);
        }
        for (int o = 0; o < nout; o++) {
            lf_lens_poly_fn *f = outs[o] < LF_LENS_POLY_FIXED ? &P->fn[outs[o]] : &P->clip[outs[o] - LF_LENS_POLY_FIXED];
            f->coef = malloc((size_t)cols * sizeof *f->coef);
            if (!f->coef)
                goto done;
            memcpy(f->coef, X + (size_t)o * cols, (size_t)cols * sizeof *f->coef);
            f->n = cols;
        }
        if (cls == LF_LENS_POLY_CLASS_RADIAL)
            P->n_clip = n_clip;
    }
    for (int c = 0; c < n_clip; c++)
        P->clip_surface[c] = clip_surface[c];
    rc = 0;
done:
    free(A), free(B), free(X);
    return rc;
}

/* The caller's options with the degree and sample count clamped to what
 * the fit supports. */
static lf_lens_poly_opts fit_options(const lf_lens_poly_opts *opts_in)
{
    lf_lens_poly_opts o = opts_in ? *opts_in : lf_lens_poly_opts_default();
    if (o.max_degree < 3)
        o.max_degree = 3;
    if (o.max_degree > LF_LENS_POLY_MAX_DEGREE)
        o.max_degree = LF_LENS_POLY_MAX_DEGREE;
    if (o.fit_samples < 500)
        o.fit_samples = 500;
    return o;
}

/* The fit's samples: exact traces through a copy of the lens with every
 * clear aperture grown 3% (and the stop 3%), so the samples cover both
 * sides of each aperture's edge: the fitted radii then place the edges,
 * and the outer-ray fit holds up to them.  Fills S (and each sample's
 * radii in `radial`), counts per surface the samples it clips (clip_count
 * may be NULL); returns how many samples got through, or -1 when out of
 * memory. */
static int trace_fit_samples(const lf_lens *L, const lf_lens_pupil *pupil, const lf_lens_poly_opts *o, lf_lens_poly *P,
                             fit_sample *S, float *radial, long *clip_count)
{
    int n = L->n;
    lf_lens grown = *L;
    grown.s = malloc((size_t)n * sizeof *grown.s);
    double(*path)[3] = malloc((size_t)(n + 1) * sizeof *path);
    if (!grown.s || !path) {
        free(grown.s), free(path);
        return -1;
    }
    memcpy(grown.s, L->s, (size_t)n * sizeof *grown.s);
    for (int i = 0; i < n; i++) {
        double a = grown.s[i].aperture_radius_mm * 1.03, R = fabs(grown.s[i].radius_mm);
        grown.s[i].aperture_radius_mm = grown.s[i].radius_mm != 0.0 && a > R ? R : a;
    }
    uint64_t s = rng_seed(o->seed, 1);
    int ns = 0;
    for (int i = 0; i < o->fit_samples; i++) {
        /* film radius stratified uniformly in r (the edge of the field is
         * where vignetting and distortion change fastest), pupil from the bound */
        double r = pupil->film_radius_mm * (i + rnd(&s)) / o->fit_samples, rx, ry;
        if (!(lf_lens_pupil_sample(pupil, r, 0.0, rnd(&s), rnd(&s), &rx, &ry) > 0.0))
            continue;
        lf_lens_ray in = {{r, 0.0, 0.0}, {rx - r, ry, -L->film_distance_mm}}, out;
        lf_lens_trace_opts to = {0};
        to.path = path;
        P->traces++;
        if (lf_lens_trace_from_film(&grown, &in, &out, &to) != LF_LENS_PASSED)
            continue;
        fit_sample *f = &S[ns];
        f->in[0] = r / P->film_radius_mm;
        f->in[1] = rx / P->rear_disk_radius_mm;
        f->in[2] = ry / P->rear_disk_radius_mm;
        double t = (P->z_out_mm - out.o[2]) / out.d[2];
        f->out[LF_LENS_POLY_OUT_X] = out.o[0] + t * out.d[0];
        f->out[LF_LENS_POLY_OUT_Y] = out.o[1] + t * out.d[1];
        f->out[LF_LENS_POLY_OUT_DX] = out.d[0];
        f->out[LF_LENS_POLY_OUT_DY] = out.d[1];
        f->radial = radial + (size_t)ns * n;
        for (int k = 0; k < to.path_count && k < n; k++) {
            int surf = n - 1 - k; /* the path runs from the rear surface forward */
            double x = path[k][0], y = path[k][1], ap = L->s[surf].aperture_radius_mm;
            f->radial[surf] = (float)((x * x + y * y) / (ap * ap));
            if (surf == L->stop)
                f->out[LF_LENS_POLY_STOP_X] = x, f->out[LF_LENS_POLY_STOP_Y] = y;
            if (clip_count && f->radial[surf] > 1.0f)
                clip_count[surf]++;
        }
        ns++;
    }
    free(path);
    free(grown.s);
    return ns;
}

/* Surfaces that clip more than 0.02% of the samples (the stop always),
 * most often clipping first.  Returns their count. */
static int clipping_surfaces(const lf_lens *L, const long *clip_count, int ns, int clip_surface[LF_LENS_POLY_MAX_CLIP])
{
    int n_clip = 0;
    for (int i = 0; i < L->n && clip_count; i++)
        if ((i == L->stop || clip_count[i] * 5000 > ns) && n_clip < LF_LENS_POLY_MAX_CLIP) {
            int j = n_clip++;
            while (j > 0 && clip_count[clip_surface[j - 1]] < clip_count[i]) {
                clip_surface[j] = clip_surface[j - 1];
                j--;
            }
            clip_surface[j] = i;
        }
    return n_clip;
}

/* Magnification near the axis: a ray from just off the axis through the
 * centre of the rear plane, met on the focus plane; 1 when that fails. */
static double axial_magnification(const lf_lens *L, const lf_lens_poly *P, double focus_distance_mm)
{
    double delta = 1e-3 * P->film_radius_mm, m = 0.0;
    lf_lens_ray in = {{delta, 0.0, 0.0}, {-delta, 0.0, -L->film_distance_mm}}, out;
    double y;
    if (lf_lens_trace_from_film(L, &in, &out, NULL) == LF_LENS_PASSED) {
        double X = focus_plane_x(&out, focus_distance_mm, &y);
        m = fabs(delta / X);
    }
    return !(m > 0.0) || !isfinite(m) ? 1.0 : m;
}

/* Error budgets per output for dropping terms.  A point error dp on the
 * output plane moves the ray's point on the focus plane by dp, a direction
 * error dd by about D dd; on the film both shrink by the magnification.  A
 * tenth of the target each; radii squared to 0.2% of the aperture's. */
static void error_budgets(const lf_lens_poly_opts *o, const lf_lens_poly *P, int n_clip,
                          double budget[LF_LENS_POLY_FIXED + LF_LENS_POLY_MAX_CLIP])
{
    double film_mm = o->target_px * o->pixel_mm, D = o->focus_distance_mm;
    budget[LF_LENS_POLY_OUT_X] = budget[LF_LENS_POLY_OUT_Y] = 0.1 * film_mm / P->magnification;
    budget[LF_LENS_POLY_OUT_DX] = budget[LF_LENS_POLY_OUT_DY] = 0.1 * film_mm / (P->magnification * D);
    budget[LF_LENS_POLY_STOP_X] = budget[LF_LENS_POLY_STOP_Y] = 0.002 * P->stop_radius_mm;
    for (int c = 0; c < n_clip; c++)
        budget[LF_LENS_POLY_FIXED + c] = 0.002;
}

/* Raises the degree 3, 5, 7, 9 until the held-out error meets the target,
 * and leaves P fitted at the best degree tried, with its report in P->fit. */
static int choose_degree(const lf_lens *L, const lf_lens_pupil *pupil, const lf_lens_poly_opts *o, lf_lens_poly *P,
                         const fit_sample *S, int ns, const int *clip_surface, int n_clip, const double *budget,
                         lf_error *err)
{
    int best_degree = -1;
    double best_p99 = INFINITY;
    for (int d = 3; d <= o->max_degree; d += 2) {
        if (fit_degree(P, d, S, ns, clip_surface, n_clip, budget))
            continue;
        lf_lens_poly_measure(L, P, pupil, o->focus_distance_mm, o->pixel_mm, o->check_samples, o->seed, &P->fit);
        double score = P->fit.p99_px + 10.0 * P->fit.mismatch_fraction; /* 1% mismatches ~ 0.1 px */
        if (score < best_p99)
            best_p99 = score, best_degree = d;
        if (P->fit.p99_px <= o->target_px && P->fit.mismatch_fraction < 0.005)
            break;
    }
    if (best_degree < 0)
        return lf_error_set(err, LF_ERR_NUMERIC, "polynomial lens: the least-squares fit is singular");
    if (best_degree != P->degree) {
        if (fit_degree(P, best_degree, S, ns, clip_surface, n_clip, budget))
            return lf_error_set(err, LF_ERR_NUMERIC, "polynomial lens: the least-squares fit is singular");
        lf_lens_poly_measure(L, P, pupil, o->focus_distance_mm, o->pixel_mm, o->check_samples, o->seed, &P->fit);
    }
    return LF_OK;
}

int lf_lens_poly_fit(const lf_lens *L, const lf_lens_pupil *pupil, const lf_lens_poly_opts *opts_in,
                     lf_lens_poly *P, lf_error *err)
{
    double t0 = seconds();
    lf_lens_poly_opts o = fit_options(opts_in);
    memset(P, 0, sizeof *P);
    P->film_radius_mm = pupil->film_radius_mm;
    P->rear_disk_radius_mm = pupil->rear_disk_radius_mm;
    P->film_distance_mm = L->film_distance_mm;
    P->z_out_mm = output_plane(L);
    P->has_stop = L->stop >= 0;
    P->stop_radius_mm = P->has_stop ? L->s[L->stop].aperture_radius_mm : 0.0;
    int n = L->n;
    if (!(P->film_radius_mm > 0.0) || !(P->rear_disk_radius_mm > 0.0) || !(P->film_distance_mm > 0.0))
        return lf_error_set(err, LF_ERR_NUMERIC, "polynomial lens: no film or pupil to fit");

    fit_sample *S = calloc((size_t)o.fit_samples, sizeof *S);
    float *radial = malloc((size_t)o.fit_samples * n * sizeof *radial);
    long clipped[LF_LENS_POLY_MAX_CLIP * 4] = {0};
    long *clip_count = n <= (int)(sizeof clipped / sizeof clipped[0]) ? clipped : NULL;
    int ns = S && radial ? trace_fit_samples(L, pupil, &o, P, S, radial, clip_count) : -1;
    if (ns < 0) {
        free(S), free(radial);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    int clip_surface[LF_LENS_POLY_MAX_CLIP];
    int n_clip = clipping_surfaces(L, clip_count, ns, clip_surface);
    int rc;
    if (ns < 200) {
        rc = lf_error_set(err, LF_ERR_NUMERIC, "polynomial lens: only %d of %d fit samples get through", ns,
                          o.fit_samples);
    } else {
        P->magnification = axial_magnification(L, P, o.focus_distance_mm);
        double budget[LF_LENS_POLY_FIXED + LF_LENS_POLY_MAX_CLIP];
        error_budgets(&o, P, n_clip, budget);
        rc = choose_degree(L, pupil, &o, P, S, ns, clip_surface, n_clip, budget, err);
        if (!rc)
            P->traces += 2L * o.check_samples;
    }
    free(S), free(radial);
    if (rc)
        lf_lens_poly_free(P);
    P->setup_seconds = seconds() - t0;
    return rc;
}
