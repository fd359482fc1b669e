/* Shift-and-add refocusing (Ng 2005, sub-aperture form), view interpolation,
 * focal stacks, all-in-focus and disparity maps. */
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "half_internal.h"
#include "lf_lightfield.h"
#include "base/lf_parallel.h"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#include <immintrin.h>
#define LF_HAVE_F16C_PATH 1
#endif

lf_lightfield_refocus_opts lf_lightfield_refocus_defaults(void)
{
    lf_lightfield_refocus_opts o;
    memset(&o, 0, sizeof o);
    o.aperture_radius = -1;
    o.u1 = o.v1 = -1;
    return o;
}

/* Synthetic-aperture weight of view (iu, iv): 1 inside the disk and window. */
static float view_weight(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, int iu, int iv)
{
    if (o->u1 >= 0 && (iu < o->u0 || iu > o->u1))
        return 0.f;
    if (o->v1 >= 0 && (iv < o->v0 || iv > o->v1))
        return 0.f;
    if (o->aperture_radius >= 0) {
        double u = iu - (lf->nu - 1) / 2.0, v = iv - (lf->nv - 1) / 2.0;
        if (u * u + v * v > o->aperture_radius * o->aperture_radius + 1e-9)
            return 0.f;
    }
    return 1.f;
}

typedef struct view_shift {
    const float *data, *valid;
    const uint16_t *half; /* non-NULL: read half floats instead of data */
    int ix, iy;          /* integer part of the source offset */
    float fx, fy, w;     /* fractional part, aperture weight */
} view_shift;

typedef struct refocus_job {
    const lf_lightfield *lf;
    const view_shift *views;
    int nviews;
    float inv_wsum;
    lf_image *out;
    float *wacc[LF_PARALLEL_MAX_THREADS]; /* masked path: per thread, ns weights per row of a block */
} refocus_job;

enum { BLOCK_ROWS = 16 };

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* acc[k] += a*r0[k] + b*r0[k+3] + c*r1[k] + e*r1[k+3], k over n floats.
 * The inner loops are the whole cost of refocusing: ask for vectorisation
 * (-O2's cost model refuses loops with an epilogue) and an AVX2 clone. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define LF_HOT_LOOP __attribute__((optimize("-ftree-vectorize", "-fvect-cost-model=dynamic"), target_clones("avx2", "default")))
#else
#define LF_HOT_LOOP
#endif
LF_HOT_LOOP static void accumulate_row(float *restrict acc, const float *restrict r0, const float *restrict r1, float a, float b,
                           float c, float e, int n)
{
    if (b == 0.f && c == 0.f && e == 0.f) {
        for (int k = 0; k < n; k++)
            acc[k] += a * r0[k];
    } else if (c == 0.f && e == 0.f) {
        for (int k = 0; k < n; k++)
            acc[k] += a * r0[k] + b * r0[k + 3];
    } else {
        for (int k = 0; k < n; k++)
            acc[k] += a * r0[k] + b * r0[k + 3] + c * r1[k] + e * r1[k + 3];
    }
}

/* The same over half-float rows: F16C converts 8 values per instruction. */
#ifdef LF_HAVE_F16C_PATH
__attribute__((target("avx2,fma,f16c"))) static void accumulate_row_half_f16c(float *restrict acc,
                                                                                const uint16_t *restrict r0,
                                                                                const uint16_t *restrict r1, float a,
                                                                                float b, float c, float e, int n)
{
    __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b), vc = _mm256_set1_ps(c), ve = _mm256_set1_ps(e);
    int k = 0;
    if (b == 0.f && c == 0.f && e == 0.f) {
        for (; k + 8 <= n; k += 8) {
            __m256 x = _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(r0 + k)));
            _mm256_storeu_ps(acc + k, _mm256_fmadd_ps(va, x, _mm256_loadu_ps(acc + k)));
        }
    } else {
        for (; k + 8 <= n; k += 8) {
            __m256 s = _mm256_loadu_ps(acc + k);
            s = _mm256_fmadd_ps(va, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(r0 + k))), s);
            s = _mm256_fmadd_ps(vb, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(r0 + k + 3))), s);
            s = _mm256_fmadd_ps(vc, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(r1 + k))), s);
            s = _mm256_fmadd_ps(ve, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(r1 + k + 3))), s);
            _mm256_storeu_ps(acc + k, s);
        }
    }
    for (; k < n; k++)
        acc[k] += a * lf_lightfield_half_to_float(r0[k]) + b * lf_lightfield_half_to_float(r0[k + 3]) +
                  c * lf_lightfield_half_to_float(r1[k]) + e * lf_lightfield_half_to_float(r1[k + 3]);
}
#endif

static void accumulate_row_half(float *restrict acc, const uint16_t *restrict r0, const uint16_t *restrict r1,
                                float a, float b, float c, float e, int n)
{
#ifdef LF_HAVE_F16C_PATH
    /* relaxed atomics: every thread computes the same answer */
    static atomic_int f16c = -1;
    int have = atomic_load_explicit(&f16c, memory_order_relaxed);
    if (have < 0) {
        have = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("f16c");
        atomic_store_explicit(&f16c, have, memory_order_relaxed);
    }
    if (have) {
        accumulate_row_half_f16c(acc, r0, r1, a, b, c, e, n);
        return;
    }
#endif
    for (int k = 0; k < n; k++)
        acc[k] += a * lf_lightfield_half_to_float(r0[k]) + b * lf_lightfield_half_to_float(r0[k + 3]) +
                  c * lf_lightfield_half_to_float(r1[k]) + e * lf_lightfield_half_to_float(r1[k + 3]);
}

/* one value of a view row, float or half */
static inline float rowval(const view_shift *v, size_t i)
{
    return v->half ? lf_lightfield_half_to_float(v->half[i]) : v->data[i];
}

/* Blocks [b0, b1) of BLOCK_ROWS rows (lf_parallel_for): every row sums the
 * views in the same order whichever thread takes it. */
static void refocus_blocks(void *ctx, int b0, int b1, int tid)
{
    refocus_job *j = ctx;
    const lf_lightfield *lf = j->lf;
    const int ns = lf->ns, nt = lf->nt;
    const size_t row = (size_t)ns * 3;
    float *wacc = j->wacc[tid];
    for (int yb = b0 * BLOCK_ROWS; yb < b1 * BLOCK_ROWS && yb < nt; yb += BLOCK_ROWS) {
        int ye = yb + BLOCK_ROWS < nt ? yb + BLOCK_ROWS : nt;
        if (wacc)
            memset(wacc, 0, sizeof(float) * (size_t)BLOCK_ROWS * ns);
        for (int vi = 0; vi < j->nviews; vi++) {
            const view_shift *v = &j->views[vi];
            float w00 = v->w * (1 - v->fx) * (1 - v->fy), w10 = v->w * v->fx * (1 - v->fy);
            float w01 = v->w * (1 - v->fx) * v->fy, w11 = v->w * v->fx * v->fy;
            /* interior columns: x + ix and x + ix + 1 both inside the view */
            int xa = clampi(-v->ix, 0, ns), xb = clampi(ns - 1 - v->ix, xa, ns);
            for (int y = yb; y < ye; y++) {
                float *acc = j->out->data + (size_t)y * row;
                int sy0 = clampi(y + v->iy, 0, nt - 1), sy1 = clampi(y + v->iy + 1, 0, nt - 1);
                const float *r0 = v->data + (size_t)sy0 * row, *r1 = v->data + (size_t)sy1 * row;
                size_t o0 = (size_t)sy0 * row, o1 = (size_t)sy1 * row; /* row offsets, for rowval */
                if (!v->valid) {
                    if (xb > xa && v->half)
                        accumulate_row_half(acc + 3 * xa, v->half + o0 + 3 * (xa + v->ix),
                                            v->half + o1 + 3 * (xa + v->ix), w00, w10, w01, w11, 3 * (xb - xa));
                    else if (xb > xa)
                        accumulate_row(acc + 3 * xa, r0 + 3 * (xa + v->ix), r1 + 3 * (xa + v->ix), w00, w10, w01,
                                       w11, 3 * (xb - xa));
                    for (int x = 0; x < ns; x++) {
                        if (x == xa && xb > xa)
                            x = xb;
                        if (x >= ns)
                            break;
                        int sx0 = clampi(x + v->ix, 0, ns - 1), sx1 = clampi(x + v->ix + 1, 0, ns - 1);
                        for (int c = 0; c < 3; c++)
                            acc[3 * x + c] += w00 * rowval(v, o0 + 3 * sx0 + c) + w10 * rowval(v, o0 + 3 * sx1 + c) +
                                              w01 * rowval(v, o1 + 3 * sx0 + c) + w11 * rowval(v, o1 + 3 * sx1 + c);
                    }
                } else {
                    /* masked: every tap weighted by its validity, weights accumulated */
                    const float *m0 = v->valid + (size_t)sy0 * ns, *m1 = v->valid + (size_t)sy1 * ns;
                    float *wa = wacc + (size_t)(y - yb) * ns;
                    for (int x = 0; x < ns; x++) {
                        int sx0 = clampi(x + v->ix, 0, ns - 1), sx1 = clampi(x + v->ix + 1, 0, ns - 1);
                        float a = w00 * m0[sx0], b = w10 * m0[sx1], c = w01 * m1[sx0], e = w11 * m1[sx1];
                        wa[x] += a + b + c + e;
                        for (int ch = 0; ch < 3; ch++)
                            acc[3 * x + ch] += a * rowval(v, o0 + 3 * sx0 + ch) + b * rowval(v, o0 + 3 * sx1 + ch) +
                                               c * rowval(v, o1 + 3 * sx0 + ch) + e * rowval(v, o1 + 3 * sx1 + ch);
                    }
                }
            }
        }
        for (int y = yb; y < ye; y++) {
            float *acc = j->out->data + (size_t)y * row;
            if (wacc) {
                const float *wa = wacc + (size_t)(y - yb) * ns;
                for (int x = 0; x < ns; x++) {
                    float s = wa[x] > 1e-6f ? 1.f / wa[x] : 0.f;
                    acc[3 * x] *= s, acc[3 * x + 1] *= s, acc[3 * x + 2] *= s;
                }
            } else {
                for (size_t k = 0; k < row; k++)
                    acc[k] *= j->inv_wsum;
            }
        }
    }
}

int lf_lightfield_refocus(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, lf_image *out, lf_error *err)
{
    lf_lightfield_refocus_opts def = lf_lightfield_refocus_defaults();
    if (!o)
        o = &def;
    if (!isfinite(o->disparity_px))
        return lf_error_set(err, LF_ERR_PARAM, "disparity must be finite");
    if (o->use_half && !lf->half)
        return lf_error_set(err, LF_ERR_PARAM, "half-float refocusing needs lf_lightfield_make_half first");
    view_shift *vs = malloc(sizeof *vs * (size_t)lf->nu * lf->nv);
    if (!vs)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    int n = 0;
    double wsum = 0;
    double dx = o->disparity_px, dy = o->disparity_px * lf->disp_v_per_u;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            float w = view_weight(lf, o, iu, iv);
            if (w == 0.f)
                continue;
            /* L(u, v, s - d u, t - d v) */
            double sx = -dx * (iu - (lf->nu - 1) / 2.0), sy = -dy * (iv - (lf->nv - 1) / 2.0);
            view_shift *v = &vs[n++];
            v->data = lf_lightfield_view(lf, iu, iv);
            v->half = o->use_half ? lf->half + (v->data - lf->data) : NULL;
            v->valid = lf->valid ? lf->valid + ((size_t)iv * lf->nu + iu) * lf->ns * lf->nt : NULL;
            v->ix = (int)floor(sx), v->iy = (int)floor(sy);
            v->fx = (float)(sx - v->ix), v->fy = (float)(sy - v->iy);
            v->w = w;
            wsum += w;
        }
    if (n == 0) {
        free(vs);
        return lf_error_set(err, LF_ERR_PARAM, "the synthetic aperture selects no view");
    }
    if (lf_image_alloc(out, lf->ns, lf->nt, 3, err)) {
        free(vs);
        return err ? err->code : LF_ERR_NOMEM;
    }
    refocus_job job = {lf, vs, n, (float)(1.0 / wsum), out, {NULL}};
    int rc = LF_OK, nblocks = (lf->nt + BLOCK_ROWS - 1) / BLOCK_ROWS;
    int nth = lf_parallel_threads(o->threads);
    for (int t = 0; lf->valid && t < nth && !rc; t++)
        if (!(job.wacc[t] = malloc(sizeof(float) * (size_t)BLOCK_ROWS * lf->ns)))
            rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    if (!rc)
        lf_parallel_for(nblocks, o->threads, 1, refocus_blocks, &job);
    for (int t = 0; t < nth; t++)
        free(job.wacc[t]);
    free(vs);
    if (rc)
        lf_image_free(out);
    return rc;
}

/* Bilinear sample of one view at continuous (x, y) (pixel-index space),
 * clamped to the view; validity-weighted. Returns the weight used. */
static float sample_view(const lf_lightfield *lf, int iu, int iv, double x, double y, float rgb[3])
{
    const float *d = lf_lightfield_view(lf, iu, iv);
    const float *m = lf->valid ? lf->valid + ((size_t)iv * lf->nu + iu) * lf->ns * lf->nt : NULL;
    int x0 = (int)floor(x), y0 = (int)floor(y);
    float fx = (float)(x - x0), fy = (float)(y - y0);
    float acc[3] = {0, 0, 0}, wsum = 0;
    for (int k = 0; k < 4; k++) {
        float w = (k & 1 ? fx : 1 - fx) * (k & 2 ? fy : 1 - fy);
        if (w == 0.f)
            continue;
        int xx = clampi(x0 + (k & 1), 0, lf->ns - 1), yy = clampi(y0 + (k >> 1), 0, lf->nt - 1);
        size_t i = (size_t)yy * lf->ns + xx;
        if (m)
            w *= m[i];
        for (int c = 0; c < 3; c++)
            acc[c] += w * d[i * 3 + c];
        wsum += w;
    }
    for (int c = 0; c < 3; c++)
        rgb[c] = wsum > 0 ? acc[c] / wsum : 0.f;
    return wsum;
}

int lf_lightfield_view_at(const lf_lightfield *lf, double u, double v, double disp, lf_image *out, lf_error *err)
{
    double fu = u + (lf->nu - 1) / 2.0, fv = v + (lf->nv - 1) / 2.0;
    if (!(fu >= -1e-9 && fu <= lf->nu - 1 + 1e-9 && fv >= -1e-9 && fv <= lf->nv - 1 + 1e-9))
        return lf_error_set(err, LF_ERR_PARAM, "view (%g, %g) is outside the captured aperture u in [%g, %g], v in [%g, %g]",
                            u, v, -(lf->nu - 1) / 2.0, (lf->nu - 1) / 2.0, -(lf->nv - 1) / 2.0, (lf->nv - 1) / 2.0);
    int u0 = clampi((int)floor(fu), 0, lf->nu > 1 ? lf->nu - 2 : 0), v0 = clampi((int)floor(fv), 0, lf->nv > 1 ? lf->nv - 2 : 0);
    double au = fu - u0, av = fv - v0;
    if (lf_image_alloc(out, lf->ns, lf->nt, 3, err))
        return err ? err->code : LF_ERR_NOMEM;
    double dy = disp * lf->disp_v_per_u;
    for (int y = 0; y < lf->nt; y++)
        for (int x = 0; x < lf->ns; x++) {
            double acc[3] = {0, 0, 0}, wsum = 0;
            for (int k = 0; k < 4; k++) {
                int iu = u0 + (k & 1), iv = v0 + (k >> 1);
                double w = (k & 1 ? au : 1 - au) * (k & 2 ? av : 1 - av);
                if (w == 0 || iu >= lf->nu || iv >= lf->nv)
                    continue;
                /* a point of disparity d seen at x from (fu,fv) is at x - d (iu - fu) in view iu */
                float c[3];
                float vw = sample_view(lf, iu, iv, x - disp * (iu - fu), y - dy * (iv - fv), c);
                if (vw <= 0)
                    continue;
                for (int ch = 0; ch < 3; ch++)
                    acc[ch] += w * c[ch];
                wsum += w;
            }
            float *p = lf_image_px(out, x, y);
            for (int ch = 0; ch < 3; ch++)
                p[ch] = wsum > 0 ? (float)(acc[ch] / wsum) : 0.f;
        }
    return LF_OK;
}

/* Local contrast: squared Laplacian of luminance, box-summed over (2r+1)^2. */
static void contrast(const lf_image *img, float *out, int r)
{
    int w = img->width, h = img->height;
    float *lap = calloc((size_t)w * h, sizeof(float));
    if (!lap)
        return;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
#define LUM(xx, yy)                                                                                          \
    (0.2126f * lf_image_px(img, clampi(xx, 0, w - 1), clampi(yy, 0, h - 1))[0] +                             \
     0.7152f * lf_image_px(img, clampi(xx, 0, w - 1), clampi(yy, 0, h - 1))[1] +                             \
     0.0722f * lf_image_px(img, clampi(xx, 0, w - 1), clampi(yy, 0, h - 1))[2])
            float l = 4 * LUM(x, y) - LUM(x - 1, y) - LUM(x + 1, y) - LUM(x, y - 1) - LUM(x, y + 1);
#undef LUM
            lap[(size_t)y * w + x] = l * l;
        }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float s = 0;
            for (int dy = -r; dy <= r; dy++)
                for (int dx = -r; dx <= r; dx++)
                    s += lap[(size_t)clampi(y + dy, 0, h - 1) * w + clampi(x + dx, 0, w - 1)];
            out[(size_t)y * w + x] = s;
        }
    free(lap);
}

int lf_lightfield_allfocus(const lf_lightfield *lf, const lf_lightfield_refocus_opts *o, double d0, double d1, int n,
                   lf_image *allfocus, lf_image *disparity, lf_error *err)
{
    if (n < 2)
        return lf_error_set(err, LF_ERR_PARAM, "a focal stack needs at least 2 slices (got %d)", n);
    size_t np = (size_t)lf->ns * lf->nt;
    float *best = malloc(np * sizeof(float)), *c = malloc(np * sizeof(float));
    if (!best || !c || lf_image_alloc(allfocus, lf->ns, lf->nt, 3, err) ||
        (disparity && lf_image_alloc(disparity, lf->ns, lf->nt, 1, err))) {
        free(best), free(c);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i < np; i++)
        best[i] = -1.f;
    lf_lightfield_refocus_opts ro = o ? *o : lf_lightfield_refocus_defaults();
    int rc = LF_OK;
    for (int k = 0; k < n && !rc; k++) {
        ro.disparity_px = d0 + (d1 - d0) * k / (n - 1);
        lf_image slice;
        if ((rc = lf_lightfield_refocus(lf, &ro, &slice, err)))
            break;
        contrast(&slice, c, 2);
        for (size_t i = 0; i < np; i++)
            if (c[i] > best[i]) {
                best[i] = c[i];
                memcpy(allfocus->data + i * 3, slice.data + i * 3, 3 * sizeof(float));
                if (disparity)
                    disparity->data[i] = (float)ro.disparity_px;
            }
        lf_image_free(&slice);
    }
    free(best), free(c);
    return rc;
}
