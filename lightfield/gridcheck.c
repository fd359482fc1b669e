/* A folder's grid checked against its parallax (lf_lightfield.h,
 * lf_lightfield_grid_parallax): the centre view against its right and lower
 * neighbours, block by block, by a 1-D shift search along x and along y on
 * the gradient magnitude of log luminance (an exposure gain between views
 * cancels in the log).  A block votes for the axis whose best shift matches
 * clearly better than the other axis's; blocks without texture, or whose
 * parallax is under half a pixel, abstain. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_lightfield.h"

enum {
    WORK_SIZE = 512,  /* larger views are box-averaged to about this size (docs/lightfield-format.md: the cost) */
    BLOCK = 16,       /* block side at the working size */
    SUBSTEPS = 4,     /* shifts in quarter pixels */
    MIN_VOTES = 8,    /* fewer voting blocks: cannot tell */
    MAX_SHIFT = 16,   /* px per view step at the working size */
};
static const double BETTER = 0.7;    /* a block votes when its best cost on one axis is below 0.7 x the other's */
static const double MAJORITY = 0.75; /* share of the votes an axis needs */
static const double MIN_SHIFT = 0.5; /* px at the working size: below it x and y shifts match alike */
static const double AMBIGUOUS = 1.25; /* a second minimum within 25% of the best: a repetitive texture */

/* gradient magnitude of log luminance of view (iu, iv), box-averaged f x f */
static float *gradient_view(const lf_lightfield *lf, int iu, int iv, int f, int w, int h)
{
    float *lum = malloc(sizeof(float) * (size_t)w * h), *g = calloc((size_t)w * h, sizeof(float));
    if (!lum || !g) {
        free(lum), free(g);
        return NULL;
    }
    const float *src = lf_lightfield_view(lf, iu, iv);
    double mean = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s = 0;
            for (int j = 0; j < f; j++)
                for (int i = 0; i < f; i++) {
                    const float *p = src + ((size_t)(y * f + j) * lf->ns + (x * f + i)) * 3;
                    s += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                }
            lum[(size_t)y * w + x] = (float)(s / (f * f));
            mean += s / (f * f);
        }
    mean /= (double)w * h;
    float eps = (float)(1e-2 * (mean > 0 ? mean : 1));
    for (size_t i = 0; i < (size_t)w * h; i++)
        lum[i] = logf((lum[i] > 0 ? lum[i] : 0) + eps);
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++) {
            size_t i = (size_t)y * w + x;
            float gx = 0.5f * (lum[i + 1] - lum[i - 1]), gy = 0.5f * (lum[i + w] - lum[i - w]);
            g[i] = sqrtf(gx * gx + gy * gy);
        }
    free(lum);
    return g;
}

static float sample(const float *g, int w, int h, double x, double y)
{
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0;
    if (x0 < 0 || y0 < 0 || x0 + 1 >= w || y0 + 1 >= h)
        return -1.f;
    const float *p = g + (size_t)y0 * w + x0;
    return (float)((1 - fy) * ((1 - fx) * p[0] + fx * p[1]) + fy * ((1 - fx) * p[w] + fx * p[w + 1]));
}

/* Mean absolute difference of block (bx, by) of a against b shifted by s
 * along axis (0 x, 1 y). */
static double block_cost(const float *a, const float *b, int w, int h, int bx, int by, int axis, double s)
{
    double c = 0;
    int n = 0;
    if (s == floor(s)) {
        /* a whole-pixel shift: sample() gives the pixel itself (the other
         * weights are 0), so read it (4 in 5 of the shifts searched) */
        int sx = axis == 0 ? (int)s : 0, sy = axis == 1 ? (int)s : 0;
        for (int y = by; y < by + BLOCK; y++)
            for (int x = bx; x < bx + BLOCK; x++) {
                int x0 = x + sx, y0 = y + sy;
                if (x0 >= 0 && y0 >= 0 && x0 + 1 < w && y0 + 1 < h)
                    c += fabs(a[(size_t)y * w + x] - b[(size_t)y0 * w + x0]), n++;
            }
        return n ? c / n : INFINITY;
    }
    for (int y = by; y < by + BLOCK; y++)
        for (int x = bx; x < bx + BLOCK; x++) {
            float v = sample(b, w, h, x + (axis == 0 ? s : 0), y + (axis == 1 ? s : 0));
            if (v >= 0)
                c += fabs(a[(size_t)y * w + x] - v), n++;
        }
    return n ? c / n : INFINITY;
}

/* Best shift (px) along axis of b against a over one block, and its cost:
 * whole pixels first, then quarter pixels around the best.  *unique is 0
 * when another local minimum 2 px or more away costs nearly as much (a
 * repetitive texture: the shift is ambiguous). */
static double best_shift(const float *a, const float *b, int w, int h, int bx, int by, int axis, int smax,
                         double *cost, int *unique)
{
    double best = INFINITY, bs = 0, c[2 * MAX_SHIFT + 1];
    for (int k = -smax; k <= smax; k++) {
        c[k + smax] = block_cost(a, b, w, h, bx, by, axis, k);
        if (c[k + smax] < best)
            best = c[k + smax], bs = k;
    }
    *unique = 1;
    for (int k = 1; k < 2 * smax; k++)
        if (fabs(k - smax - bs) >= 2 && c[k] <= c[k - 1] && c[k] <= c[k + 1] && c[k] < AMBIGUOUS * best)
            *unique = 0;
    double centre = bs;
    for (int k = -SUBSTEPS + 1; k < SUBSTEPS; k++) {
        double s = centre + (double)k / SUBSTEPS, cs = k ? block_cost(a, b, w, h, bx, by, axis, s) : best;
        if (cs < best)
            best = cs, bs = s;
    }
    *cost = best;
    return bs;
}

static int cmpd(const void *p, const void *q)
{
    double x = *(const double *)p, y = *(const double *)q;
    return (x > y) - (x < y);
}

/* One neighbour pair: axis votes and the median disparity of the
 * winning axis (px/view at full size; d: the centre's point is found at
 * x - d in the neighbour).  shifts[k] gets each block's winning shift
 * (NAN: abstained), for the sign comparison across pairs. */
static void measure_pair(const float *a, const float *b, int w, int h, int f, int smax, lf_lightfield_pair_parallax *pp,
                         double *shifts, double *tmp)
{
    int nbx = (w - 2 * smax - 2) / BLOCK, nby = (h - 2 * smax - 2) / BLOCK, vx = 0, vy = 0, nt = 0;
    double gmean = 0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        gmean += a[i];
    gmean /= (double)w * h;
    for (int j = 0; j < nby; j++)
        for (int i = 0; i < nbx; i++) {
            int bx = smax + 1 + i * BLOCK, by = smax + 1 + j * BLOCK, k = j * nbx + i;
            shifts[k] = NAN;
            double e = 0; /* texture: the block's gradient against the view's mean */
            for (int y = by; y < by + BLOCK; y++)
                for (int x = bx; x < bx + BLOCK; x++)
                    e += a[(size_t)y * w + x];
            if (e / (BLOCK * BLOCK) < 0.25 * gmean || gmean < 1e-4)
                continue;
            nt++;
            double cx, cy;
            int ux, uy;
            double sx = best_shift(a, b, w, h, bx, by, 0, smax, &cx, &ux), sy = best_shift(a, b, w, h, bx, by, 1, smax, &cy, &uy);
            if (cx < BETTER * cy && fabs(sx) >= MIN_SHIFT && ux)
                vx++, shifts[k] = sx;
            else if (cy < BETTER * cx && fabs(sy) >= MIN_SHIFT && uy)
                vy++, shifts[k] = sy;
        }
    pp->blocks = nbx * nby, pp->textured = nt, pp->votes_x = vx, pp->votes_y = vy;
    int v = vx + vy;
    pp->axis = -1;
    if (v >= MIN_VOTES && vx >= MAJORITY * v)
        pp->axis = 0;
    else if (v >= MIN_VOTES && vy >= MAJORITY * v)
        pp->axis = 1;
    int n = 0, pos = 0;
    for (int k = 0; k < nbx * nby; k++)
        if (!isnan(shifts[k]))
            tmp[n++] = -shifts[k] * f, pos += shifts[k] < 0;
    if (n) {
        qsort(tmp, (size_t)n, sizeof(double), cmpd);
        pp->disparity = tmp[n / 2];
        pp->positive = (double)pos / n;
    }
}

int lf_lightfield_grid_parallax(const lf_lightfield *lf, lf_lightfield_parallax *p, lf_error *err)
{
    memset(p, 0, sizeof *p);
    p->row.axis = p->col.axis = -1;
    int iu = (lf->nu - 1) / 2, iv = (lf->nv - 1) / 2;
    int small = lf->ns < lf->nt ? lf->ns : lf->nt;
    int f = small > WORK_SIZE ? small / WORK_SIZE : 1, w = lf->ns / f, h = lf->nt / f;
    int smax = (w < h ? w : h) / 8; /* up to 1/8 of the view per view step */
    if (smax > MAX_SHIFT)
        smax = MAX_SHIFT;
    if (w < 2 * BLOCK + 2 * smax + 2 || h < 2 * BLOCK + 2 * smax + 2)
        return LF_OK; /* too small to tell */
    int nb = ((w - 2 * smax - 2) / BLOCK) * ((h - 2 * smax - 2) / BLOCK);
    float *c = gradient_view(lf, iu, iv, f, w, h);
    float *r = iu + 1 < lf->nu ? gradient_view(lf, iu + 1, iv, f, w, h) : NULL;
    float *d = iv + 1 < lf->nv ? gradient_view(lf, iu, iv + 1, f, w, h) : NULL;
    double *sr = malloc(sizeof(double) * nb * 3), *sd = sr + nb, *tmp = sr + 2 * (size_t)nb;
    int rc = LF_OK;
    if (!c || (iu + 1 < lf->nu && !r) || (iv + 1 < lf->nv && !d) || !sr) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory for the grid check");
        goto done;
    }
    for (int k = 0; k < nb; k++)
        sr[k] = sd[k] = NAN;
    if (r)
        measure_pair(c, r, w, h, f, smax, &p->row, sr, tmp);
    if (d)
        measure_pair(c, d, w, h, f, smax, &p->col, sd, tmp);
    /* blocks where both pairs voted: same sign in a regular grid */
    for (int k = 0; k < nb; k++)
        if (!isnan(sr[k]) && !isnan(sd[k]))
            p->both++, p->same_sign += (sr[k] > 0) == (sd[k] > 0);
done:
    free(c), free(r), free(d), free(sr);
    return rc;
}

/* views (iu, iv) -> transposed, then mirrored */
int lf_lightfield_grid_reorder(lf_lightfield *lf, int transpose, int flip_x, int flip_y, lf_error *err)
{
    size_t vs = (size_t)lf->ns * lf->nt * 3, n = (size_t)lf->nu * lf->nv;
    float *data = malloc(sizeof(float) * vs * n);
    float *valid = lf->valid ? malloc(sizeof(float) * (size_t)lf->ns * lf->nt * n) : NULL;
    if (!data || (lf->valid && !valid)) {
        free(data), free(valid);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory to reorder the views");
    }
    int nu = transpose ? lf->nv : lf->nu, nv = transpose ? lf->nu : lf->nv;
    for (int v = 0; v < nv; v++)
        for (int u = 0; u < nu; u++) {
            int su = flip_x ? nu - 1 - u : u, sv = flip_y ? nv - 1 - v : v; /* in the transposed grid */
            int ou = transpose ? sv : su, ov = transpose ? su : sv;         /* in the stored grid */
            size_t from = (size_t)ov * lf->nu + ou, to = (size_t)v * nu + u;
            memcpy(data + to * vs, lf->data + from * vs, sizeof(float) * vs);
            if (valid)
                memcpy(valid + to * vs / 3, lf->valid + from * vs / 3, sizeof(float) * vs / 3);
        }
    free(lf->data), free(lf->valid);
    lf->data = data, lf->valid = valid, lf->nu = nu, lf->nv = nv;
    return LF_OK;
}
