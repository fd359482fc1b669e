/* Photometric equalisation of a folder's views against the centre view
 * (lf_lightfield_equalize, docs/lightfield-format.md "Vignetted views").
 *
 * Decoded plenoptic captures (Lytro sets written as one PNG per view) keep
 * the main lens's vignetting: the views near the rim of the aperture are
 * dimmer than the centre, and the corner views are dark or black.  A
 * correspondence cost or a view blend that takes those values as they are
 * sees every surface change colour from view to view.  Vignetting is smooth
 * across the image, so each view's gain against the centre view is modelled
 * per colour channel as exp(quadratic in x, y), fitted robustly to the
 * log-ratios of the two views' means over a grid of cells: parallax moves
 * content across a cell's boundary and makes some ratios wrong, which the
 * robust weights (Cauchy, scale 0.05) leave out.  Cells where a view keeps
 * less than a tenth of the centre's brightness are dark: their samples are
 * marked missing, and a view with no usable cell is missing whole. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_math.h"
#include "base/lf_parallel.h"
#include "lf_lightfield.h"

enum { CELLS = 16, NPAR = 6 };
#define DARK_RATIO 0.1
/* a field is applied when it departs from 1 by more than 2 % on average over
 * the cells, or by more than 8 % at some cell: parallax and noise leave a fitted
 * field near 1 (HCI backgammon, 80 views: at most 0.4 % on average, 3.4 % at
 * the worst cell) */
#define APPLY_MEAN 0.02
#define APPLY_MAX 0.08

static void basis(double x, double y, double b[NPAR])
{
    b[0] = 1, b[1] = x, b[2] = y, b[3] = x * x, b[4] = x * y, b[5] = y * y;
}

/* Robust fit of log-ratio samples y at cell centres (x, yy) in [-1, 1]:
 * least squares, then iteratively reweighted with Cauchy weights.  A small
 * ridge on the non-constant terms keeps a fit over few cells bounded. */
static int fit_field(const double *cx, const double *cy, const double *y, const int *use, int n, double p[NPAR])
{
    double *w = malloc(sizeof(double) * (size_t)n);
    if (!w)
        return 1;
    for (int i = 0; i < n; i++)
        w[i] = use[i] ? 1.0 : 0.0;
    int rc = 0;
    for (int it = 0; it < 8 && !rc; it++) {
        double a[NPAR][NPAR] = {{0}}, r[NPAR] = {0}, b[NPAR], wsum = 0;
        for (int i = 0; i < n; i++) {
            if (w[i] <= 0)
                continue;
            basis(cx[i], cy[i], b);
            for (int j = 0; j < NPAR; j++) {
                r[j] += w[i] * b[j] * y[i];
                for (int k = 0; k < NPAR; k++)
                    a[j][k] += w[i] * b[j] * b[k];
            }
            wsum += w[i];
        }
        for (int j = 1; j < NPAR; j++)
            a[j][j] += 1e-3 * wsum;
        if (!lf_solve(&a[0][0], r, NPAR, 1)) {
            rc = 1;
            break;
        }
        memcpy(p, r, sizeof r);
        const double c = 0.05; /* Cauchy scale in log gain: 5 % */
        for (int i = 0; i < n; i++) {
            if (!use[i])
                continue;
            basis(cx[i], cy[i], b);
            double e = y[i];
            for (int j = 0; j < NPAR; j++)
                e -= p[j] * b[j];
            w[i] = 1.0 / (1.0 + (e / c) * (e / c));
        }
    }
    free(w);
    return rc;
}


/* Integral image (ns + 1) x (nt + 1) of value x valid per channel, and of the
 * valid count (4 doubles per entry). */
static void integral(const float *img, const float *valid, int ns, int nt, double *I)
{
    size_t w1 = (size_t)ns + 1;
    memset(I, 0, sizeof(double) * 4 * w1);
    for (int y = 0; y < nt; y++) {
        double row[4] = {0, 0, 0, 0};
        double *cur = I + (size_t)(y + 1) * w1 * 4;
        const double *up = cur - w1 * 4;
        cur[0] = cur[1] = cur[2] = cur[3] = 0;
        for (int x = 0; x < ns; x++) {
            size_t p = (size_t)y * ns + x;
            if (!valid || valid[p] != 0.f)
                row[0] += img[p * 3], row[1] += img[p * 3 + 1], row[2] += img[p * 3 + 2], row[3] += 1;
            for (int c = 0; c < 4; c++)
                cur[(x + 1) * 4 + c] = up[(x + 1) * 4 + c] + row[c];
        }
    }
}

static void box_sum(const double *I, int ns, int x0, int y0, int x1, int y1, double out[4])
{
    size_t w1 = (size_t)ns + 1;
    for (int c = 0; c < 4; c++)
        out[c] = I[((size_t)y1 * w1 + x1) * 4 + c] - I[((size_t)y0 * w1 + x1) * 4 + c] -
                 I[((size_t)y1 * w1 + x0) * 4 + c] + I[((size_t)y0 * w1 + x0) * 4 + c];
}

/* Per cell of the centre view, its sums (cm) and those of the view's window
 * moved by (sx, sy) (vm), both clipped to the image; (cx, cy) the view
 * window's centre in [-1, 1]. */
static void cell_sums(const double *ir, const double *iv, int ns, int nt, int nc, int sx, int sy, double *cm,
                      double *vm, double *cx, double *cy)
{
    for (int j = 0; j < nc; j++)
        for (int i = 0; i < nc; i++) {
            size_t c = (size_t)j * nc + i;
            int x0 = i * ns / nc, x1 = (i + 1) * ns / nc, y0 = j * nt / nc, y1 = (j + 1) * nt / nc;
            x0 = x0 > -sx ? x0 : -sx, x1 = x1 < ns - sx ? x1 : ns - sx;
            y0 = y0 > -sy ? y0 : -sy, y1 = y1 < nt - sy ? y1 : nt - sy;
            if (x1 <= x0 || y1 <= y0) {
                memset(cm + 4 * c, 0, 4 * sizeof(double)), memset(vm + 4 * c, 0, 4 * sizeof(double));
                cx[c] = cy[c] = 0;
                continue;
            }
            box_sum(ir, ns, x0, y0, x1, y1, cm + 4 * c);
            box_sum(iv, ns, x0 + sx, y0 + sy, x1 + sx, y1 + sy, vm + 4 * c);
            cx[c] = (x0 + x1 + 2.0 * sx) / ns - 1, cy[c] = (y0 + y1 + 2.0 * sy) / nt - 1;
        }
}

/* The k-th smallest of a[0 .. n-1] (quickselect; a is reordered): the
 * value a sort would put at a[k], without sorting (called 2 x 129 times per
 * view). */
static double kth_smallest(double *a, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = a[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (a[i] < pivot)
                i++;
            while (a[j] > pivot)
                j--;
            if (i <= j) {
                double t = a[i];
                a[i] = a[j], a[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return a[k];
    }
    return a[k];
}

/* How far the cells' log luminance ratios spread (median absolute deviation
 * from their median): least where the shift undoes the parallax, whatever
 * the gain.  HUGE_VAL when fewer than half the cells can say. */
static double ratio_spread(const double *cm, const double *vm, size_t ncell, double *tmp)
{
    size_t n = 0;
    for (size_t c = 0; c < ncell; c++) {
        const double *a = cm + 4 * c, *b = vm + 4 * c;
        double la = a[0] + a[1] + a[2], lb = b[0] + b[1] + b[2];
        if (a[3] >= 16 && b[3] >= 16 && la > 1e-3 * a[3] && lb > 1e-6 * b[3])
            tmp[n++] = log((lb / b[3]) / (la / a[3]));
    }
    if (n < ncell / 2 || n == 0)
        return HUGE_VAL;
    double med = kth_smallest(tmp, n, n / 2);
    for (size_t i = 0; i < n; i++)
        tmp[i] = fabs(tmp[i] - med);
    return kth_smallest(tmp, n, n / 2);
}

/* What the per-view stages share: the cell grid, its buffers and the
 * centre view's integral image. */
typedef struct eq_work {
    int ns, nt, nc;
    size_t ncell;
    double *cm, *vm; /* per cell: r g b sums and the valid count; centre view, this view */
    double *cx, *cy; /* per cell: the view window's centre in [-1, 1] */
    double *ly, *tmp;
    int *use;
    double *ir, *iv; /* integral images of the centre view and of this view */
} eq_work;

/* One view's gain against the centre: its parallax shift, dark cells and
 * fitted log-gain fields, and how far the fields stray from 1. */
typedef struct view_fit {
    int bsx, bsy;
    int dark[CELLS * CELLS], ndark, ncells;
    double par[3][NPAR];
    int fitted;
    double dev, devsum, glo, ghi, gsum;
    int ngain;
} view_fit;

/* The parallax first: the whole-pixel shift of one disparity d,
 * (-d du, -d dv), that makes the cells' brightness ratios most alike, d
 * searched so the shift moves a pixel at a time, up to an eighth of the
 * view; leaves w's cell sums at that shift. */
static void parallax_shift(eq_work *w, double du, double dv, view_fit *f)
{
    double m = fmax(fabs(du), fabs(dv));
    int K = (w->ns < w->nt ? w->ns : w->nt) / 8, bsx = 0, bsy = 0;
    double best = HUGE_VAL;
    for (int q = 0; q <= 2 * K; q++) {
        int kk = (q + 1) / 2 * (q % 2 ? 1 : -1); /* 0, 1, -1, 2, -2, ...: ties keep the smaller shift */
        double d = kk / m;
        int sx = (int)lround(-d * du), sy = (int)lround(-d * dv);
        cell_sums(w->ir, w->iv, w->ns, w->nt, w->nc, sx, sy, w->cm, w->vm, w->cx, w->cy);
        double sp = ratio_spread(w->cm, w->vm, w->ncell, w->tmp);
        if (sp < best)
            best = sp, bsx = sx, bsy = sy;
    }
    cell_sums(w->ir, w->iv, w->ns, w->nt, w->nc, bsx, bsy, w->cm, w->vm, w->cx, w->cy);
    f->bsx = bsx, f->bsy = bsy;
}

/* Dark cells: the view keeps under a tenth of the centre's brightness.  A
 * few dark cells are the scene (a bright thing in the centre view, a dark
 * one where parallax puts the view's cell): they stay, and the robust fit
 * leaves them out; vignetting darkens a quarter of the view or more. */
static void find_dark_cells(const eq_work *w, view_fit *f)
{
    const double *cm = w->cm, *vm = w->vm;
    f->ndark = 0, f->ncells = 0;
    for (size_t c = 0; c < w->ncell; c++) {
        double rl = cm[4 * c] + cm[4 * c + 1] + cm[4 * c + 2], vl = vm[4 * c] + vm[4 * c + 1] + vm[4 * c + 2];
        f->dark[c] = cm[4 * c + 3] > 0 && rl > 0 && (vm[4 * c + 3] == 0 || vl / vm[4 * c + 3] < DARK_RATIO * rl / cm[4 * c + 3]);
        f->ndark += f->dark[c];
        f->ncells += cm[4 * c + 3] > 0;
    }
    if (f->ndark < f->ncells / 4)
        f->ndark = 0, memset(f->dark, 0, sizeof f->dark);
}

/* Per channel the log-gain field, fitted robustly to the cells' log
 * ratios; f->fitted = 0 when a channel has too few usable cells or no fit. */
static void fit_gain_fields(eq_work *w, view_fit *f)
{
    const double *cm = w->cm, *vm = w->vm;
    f->fitted = 1;
    for (int ch = 0; ch < 3 && f->fitted; ch++) {
        int nuse = 0;
        for (size_t c = 0; c < w->ncell; c++) {
            /* a ratio of cell means needs both means well above the data's noise floor */
            w->use[c] = !f->dark[c] && cm[4 * c + 3] >= 16 && vm[4 * c + 3] >= 16 &&
                        cm[4 * c + ch] > 1e-3 * cm[4 * c + 3] && vm[4 * c + ch] > 1e-3 * vm[4 * c + 3];
            w->ly[c] = w->use[c] ? log((vm[4 * c + ch] / vm[4 * c + 3]) / (cm[4 * c + ch] / cm[4 * c + 3])) : 0;
            nuse += w->use[c];
        }
        if (nuse < NPAR * 2 || fit_field(w->cx, w->cy, w->ly, w->use, (int)w->ncell, f->par[ch]))
            f->fitted = 0;
    }
}

/* The fields' largest and mean deviation from 1 over the cells that are
 * not dark, and the range and sum of the luminance gain there. */
static void gain_deviation(const eq_work *w, view_fit *f)
{
    f->dev = 0, f->devsum = 0, f->glo = INFINITY, f->ghi = 0, f->gsum = 0, f->ngain = 0;
    if (!f->fitted)
        return;
    for (size_t c = 0; c < w->ncell; c++) {
        if (f->dark[c])
            continue;
        double b[NPAR], lum = 0;
        basis(w->cx[c], w->cy[c], b);
        for (int ch = 0; ch < 3; ch++) {
            double e = 0;
            for (int j = 0; j < NPAR; j++)
                e += f->par[ch][j] * b[j];
            double g = exp(e);
            f->dev = fmax(f->dev, fabs(g - 1)), f->devsum += fabs(g - 1) / 3;
            lum += g / 3;
        }
        f->glo = fmin(f->glo, lum), f->ghi = fmax(f->ghi, lum);
        f->gsum += lum, f->ngain++;
    }
}

/* Sample p of a view marked missing (counted once) and zeroed. */
static void mark_missing(lf_lightfield *lf, float *view, float *valid, size_t p)
{
    if (valid[p] != 0.f)
        lf->missing++;
    valid[p] = 0.f;
    view[p * 3] = view[p * 3 + 1] = view[p * 3 + 2] = 0.f;
}

/* The view's pixels in dark cells (of the centre cell each shows, through
 * the parallax shift) marked missing; the rest divided by the gain fields
 * when rescale. */
static void correct_view(lf_lightfield *lf, float *view, float *valid, const eq_work *w, const view_fit *f,
                         int rescale)
{
    int ns = w->ns, nt = w->nt, nc = w->nc;
    for (int y = 0; y < nt; y++) {
        double yy = (y + 0.5) / nt * 2 - 1;
        int yc = y - f->bsy < 0 ? 0 : (y - f->bsy >= nt ? nt - 1 : y - f->bsy), cj = yc * nc / nt;
        for (int x = 0; x < ns; x++) {
            size_t p = (size_t)y * ns + x;
            int xc = x - f->bsx < 0 ? 0 : (x - f->bsx >= ns ? ns - 1 : x - f->bsx); /* the centre's cell it shows */
            if (f->ndark && f->dark[(size_t)cj * nc + (size_t)(xc * nc / ns)]) {
                mark_missing(lf, view, valid, p);
                continue;
            }
            if (!rescale)
                continue;
            double xx = (x + 0.5) / ns * 2 - 1, b[NPAR];
            basis(xx, yy, b);
            for (int ch = 0; ch < 3; ch++) {
                double e = 0;
                for (int j = 0; j < NPAR; j++)
                    e += f->par[ch][j] * b[j];
                view[p * 3 + ch] = (float)(view[p * 3 + ch] / exp(e));
            }
        }
    }
}

/* The rescaled view's mean gain and the light field's gain range. */
static int record_gain(lf_lightfield *lf, int k, const view_fit *f, lf_error *err)
{
    if (!lf->view_gain) {
        if (!(lf->view_gain = malloc(sizeof(float) * (size_t)lf->nu * lf->nv)))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the view gains");
        for (int i = 0; i < lf->nu * lf->nv; i++)
            lf->view_gain[i] = 1.f;
    }
    lf->view_gain[k] = (float)(f->gsum / f->ngain);
    if (lf->views_rescaled == 0)
        lf->gain_lo = (float)f->glo, lf->gain_hi = (float)f->ghi;
    else
        lf->gain_lo = fminf(lf->gain_lo, (float)f->glo), lf->gain_hi = fmaxf(lf->gain_hi, (float)f->ghi);
    lf->views_rescaled++;
    return LF_OK;
}

/* View k (not the centre) against the centre view: its shift, dark
 * cells and gain fields (reads the light field only, so views are
 * measured in parallel). */
static void measure_view(const lf_lightfield *lf, eq_work *w, int k, view_fit *f)
{
    size_t np = (size_t)w->ns * w->nt;
    int iu = k % lf->nu, iv = k / lf->nu, iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    double rv = lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0;
    integral(lf->data + (size_t)k * np * 3, lf->valid ? lf->valid + (size_t)k * np : NULL, w->ns, w->nt, w->iv);
    parallax_shift(w, iu - iu0, (iv - iv0) * rv, f);
    find_dark_cells(w, f);
    fit_gain_fields(w, f);
    if (f->fitted || f->ndark >= f->ncells / 2)
        gain_deviation(w, f);
}

/* View k as measured: left alone, rescaled, or marked missing in its
 * dark cells or whole. */
static int apply_view(lf_lightfield *lf, const eq_work *w, int k, const view_fit *f, lf_error *err)
{
    size_t np = (size_t)w->ns * w->nt;
    float *view = lf->data + (size_t)k * np * 3;
    if (!f->fitted && f->ndark == 0)
        return LF_OK; /* too little texture to say anything: leave the view */
    if (!f->fitted && f->ndark < f->ncells / 2)
        return LF_OK;
    int whole_dark = !f->fitted || f->ndark == f->ncells;
    int rescale = f->ngain > 0 && (f->devsum / f->ngain > APPLY_MEAN || f->dev > APPLY_MAX);
    if (!whole_dark && !rescale && f->ndark == 0)
        return LF_OK;
    if ((f->ndark || whole_dark) && !lf->valid) {
        if (!(lf->valid = malloc(sizeof(float) * np * (size_t)lf->nu * lf->nv)))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the validity mask");
        for (size_t i = 0; i < np * (size_t)lf->nu * lf->nv; i++)
            lf->valid[i] = 1.f;
    }
    float *valid = lf->valid ? lf->valid + (size_t)k * np : NULL;
    if (whole_dark) {
        for (size_t p = 0; p < np; p++)
            mark_missing(lf, view, valid, p);
        lf->views_dark++;
        return LF_OK;
    }
    correct_view(lf, view, valid, w, f, rescale);
    return rescale ? record_gain(lf, k, f, err) : LF_OK;
}

/* Per thread, the cell buffers and this view's integral image. */
typedef struct eq_thread {
    double *means, *cx, *iv;
    int *use;
} eq_thread;

typedef struct eq_ctx {
    const lf_lightfield *lf;
    eq_work base; /* the shared part: sizes and the centre's integral image */
    eq_thread *t;
    view_fit *fits;
    int centre;
} eq_ctx;

static void measure_views(void *vctx, int k0, int k1, int tid)
{
    eq_ctx *c = vctx;
    eq_thread *t = &c->t[tid];
    eq_work w = c->base;
    w.cm = t->means, w.vm = t->means + 4 * w.ncell;
    w.cx = t->cx, w.cy = t->cx + w.ncell, w.ly = t->cx + 2 * w.ncell, w.tmp = t->cx + 3 * w.ncell;
    w.use = t->use, w.iv = t->iv;
    for (int k = k0; k < k1; k++)
        if (k != c->centre)
            measure_view(c->lf, &w, k, &c->fits[k]);
}

int lf_lightfield_equalize(lf_lightfield *lf, lf_error *err)
{
    return lf_lightfield_equalize_threads(lf, 0, err);
}

int lf_lightfield_equalize_threads(lf_lightfield *lf, int threads, lf_error *err)
{
    lf->views_rescaled = lf->views_dark = 0;
    lf->gain_lo = lf->gain_hi = 1;
    if (!lf->data || lf->nu * lf->nv < 2)
        return LF_OK;
    int ns = lf->ns, nt = lf->nt, nc = CELLS, n = lf->nu * lf->nv;
    if (ns < 2 * nc || nt < 2 * nc)
        nc = (ns < nt ? ns : nt) / 2;
    if (nc < 2)
        return LF_OK;
    size_t np = (size_t)ns * nt, ncell = (size_t)nc * nc, nint = 4 * ((size_t)ns + 1) * ((size_t)nt + 1);
    int iu0 = (lf->nu - 1) / 2, iv0 = (lf->nv - 1) / 2;
    int nth = lf_parallel_threads(threads);
    nth = nth < n ? nth : n;
    eq_ctx c = {.lf = lf, .centre = iv0 * lf->nu + iu0};
    c.base = (eq_work){.ns = ns, .nt = nt, .nc = nc, .ncell = ncell};
    c.base.ir = malloc(sizeof(double) * nint);
    c.t = calloc((size_t)nth, sizeof *c.t);
    c.fits = calloc((size_t)n, sizeof *c.fits);
    int rc = !c.base.ir || !c.t || !c.fits;
    for (int i = 0; i < nth && !rc; i++) {
        eq_thread *t = &c.t[i];
        t->means = malloc(sizeof(double) * 4 * ncell * 2), t->cx = malloc(sizeof(double) * ncell * 4);
        t->use = malloc(sizeof(int) * ncell), t->iv = malloc(sizeof(double) * nint);
        rc = !t->means || !t->cx || !t->use || !t->iv;
    }
    if (rc) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory for the view gains");
        goto done;
    }
    const float *refv = lf->valid ? lf->valid + (size_t)c.centre * np : NULL;
    integral(lf_lightfield_view(lf, iu0, iv0), refv, ns, nt, c.base.ir);
    lf_parallel_for(n, nth, 1, measure_views, &c);
    /* applied in view order: the mask, the counts and the gain range as
     * one view after the other gave them */
    for (int k = 0; k < n && !rc; k++)
        if (k != c.centre)
            rc = apply_view(lf, &c.base, k, &c.fits[k], err);
done:
    for (int i = 0; c.t && i < nth; i++)
        free(c.t[i].means), free(c.t[i].cx), free(c.t[i].use), free(c.t[i].iv);
    free(c.t), free(c.fits), free(c.base.ir);
    return rc;
}
