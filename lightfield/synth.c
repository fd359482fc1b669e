/* CS348B light-field synthesis: a virtual thin-lens camera anywhere in space
 * renders from a camera-array light field (Levoy & Hanrahan 1996; the
 * virtual focal plane follows Isaksen, McMillan & Gortler 2000). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "lf_lightfield.h"

lf_lf_synth_opts lf_lf_synth_defaults(void)
{
    lf_lf_synth_opts o;
    memset(&o, 0, sizeof o);
    o.spp = 1;
    o.seed = 1;
    return o;
}

typedef struct synth_ctx {
    const lf_lightfield *lf;
    const lf_lf_synth_opts *o;
    double R[9];                   /* virtual camera to grid space */
    double in_tan, in_half;        /* data cameras: tan(fov/2), half shorter side (px) */
    double in_scale;               /* in_half / in_tan */
    double out_tan, out_half;      /* virtual camera */
    double minx, maxy, bx, by;     /* camera grid */
    double inv_bx, inv_by;
    lf_image *out, *cov;
    int y0, y1;
    size_t uncovered;
} synth_ctx;

static uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
static double rnd(uint64_t *s) { return (splitmix(s) >> 11) * (1.0 / 9007199254740992.0); }

/* sin and cos on [-pi/4, pi/4] by Taylor polynomials (errors < 3e-7). */
static inline void sincos_quarter(double x, double *sn, double *cs)
{
    double x2 = x * x;
    *sn = x * (1 - x2 / 6 * (1 - x2 / 20 * (1 - x2 / 42 * (1 - x2 / 72))));
    *cs = 1 - x2 / 2 * (1 - x2 / 12 * (1 - x2 / 30 * (1 - x2 / 56 * (1 - x2 / 90))));
}

/* Shirley's concentric square-to-disk map. */
static void concentric(double a, double b, double *x, double *y)
{
    a = 2 * a - 1, b = 2 * b - 1;
    if (a == 0 && b == 0) {
        *x = *y = 0;
        return;
    }
    double sn, cs;
    if (fabs(a) > fabs(b)) {
        sincos_quarter(M_PI / 4 * (b / a), &sn, &cs);
        *x = a * cs, *y = a * sn;
    } else {
        /* phi = pi/2 - theta: cos phi = sin theta, sin phi = cos theta */
        sincos_quarter(M_PI / 4 * (a / b), &sn, &cs);
        *x = b * sn, *y = b * cs;
    }
}

/* Looks up data camera (i, j) where it sees the point at relative position
 * (qx, qy) * z (tangents qx = rel.x / rel.z, qy = rel.y / rel.z): bilinear
 * inside its own tile only.  Returns 0 when outside its view. */
static inline int lookup(const synth_ctx *c, int i, int j, double qx, double qy, float rgb[3])
{
    const lf_lightfield *lf = c->lf;
    double px = lf->ns * 0.5 + qx * c->in_scale;
    double py = lf->nt * 0.5 - qy * c->in_scale;
    if (!(px >= 0 && px <= lf->ns && py >= 0 && py <= lf->nt))
        return 0;
    double xi = px - 0.5, yi = py - 0.5;
    if (xi < 0)
        xi = 0;
    if (yi < 0)
        yi = 0;
    if (xi > lf->ns - 1)
        xi = lf->ns - 1;
    if (yi > lf->nt - 1)
        yi = lf->nt - 1;
    int x0 = (int)xi, y0 = (int)yi;
    int x1 = x0 + 1 < lf->ns ? x0 + 1 : x0, y1 = y0 + 1 < lf->nt ? y0 + 1 : y0;
    float fx = (float)(xi - x0), fy = (float)(yi - y0);
    const float *d = lf_lf_view(lf, i, j);
    const float *m = lf->valid ? lf->valid + ((size_t)j * lf->nu + i) * lf->ns * lf->nt : NULL;
    size_t k00 = (size_t)y0 * lf->ns + x0, k10 = (size_t)y0 * lf->ns + x1;
    size_t k01 = (size_t)y1 * lf->ns + x0, k11 = (size_t)y1 * lf->ns + x1;
    float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
    if (m) {
        w00 *= m[k00], w10 *= m[k10], w01 *= m[k01], w11 *= m[k11];
        float s = w00 + w10 + w01 + w11;
        if (s <= 0)
            return 0;
        s = 1 / s;
        w00 *= s, w10 *= s, w01 *= s, w11 *= s;
    }
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = w00 * d[k00 * 3 + ch] + w10 * d[k10 * 3 + ch] + w01 * d[k01 * 3 + ch] + w11 * d[k11 * 3 + ch];
    return 1;
}

/* Radiance along one ray (origin o, direction d, focal point f or NULL for
 * infinity), grid space.  Returns 0 when the ray is not covered. */
static inline int radiance(const synth_ctx *c, const double o[3], const double d[3], const double *f, float rgb[3])
{
    const lf_lightfield *lf = c->lf;
    if (d[2] == 0)
        return 0;
    double t = -o[2] / d[2];
    double cx = o[0] + t * d[0], cy = o[1] + t * d[1];
    double fi = lf->nu > 1 ? (cx - c->minx) * c->inv_bx : 0, fj = lf->nv > 1 ? (c->maxy - cy) * c->inv_by : 0;
    const double eps = 1e-9;
    if (fi < -eps || fi > lf->nu - 1 + eps || fj < -eps || fj > lf->nv - 1 + eps)
        return 0;
    int i0 = (int)floor(fi), j0 = (int)floor(fj);
    if (i0 > lf->nu - 2)
        i0 = lf->nu - 2;
    if (j0 > lf->nv - 2)
        j0 = lf->nv - 2;
    if (i0 < 0)
        i0 = 0;
    if (j0 < 0)
        j0 = 0;
    double ax = lf->nu > 1 ? fi - i0 : 0, ay = lf->nv > 1 ? fj - j0 : 0;
    double acc[3] = {0, 0, 0}, wsum = 0;
    /* the focal point is at the same depth for every data camera: one division */
    double inv_z;
    if (f) {
        if (!(f[2] > 1e-12))
            return 0;
        inv_z = 1.0 / f[2];
    } else {
        if (!(d[2] > 1e-12))
            return 0;
        inv_z = 1.0 / d[2];
    }
    for (int k = 0; k < 4; k++) {
        int i = i0 + (k & 1), j = j0 + (k >> 1);
        double w = (k & 1 ? ax : 1 - ax) * (k & 2 ? ay : 1 - ay);
        if (w <= 0 || i >= lf->nu || j >= lf->nv)
            continue;
        double qx, qy;
        if (f) {
            double C0 = lf->nu > 1 ? c->minx + i * c->bx : cx, C1 = lf->nv > 1 ? c->maxy - j * c->by : cy;
            qx = (f[0] - C0) * inv_z, qy = (f[1] - C1) * inv_z;
        } else {
            qx = d[0] * inv_z, qy = d[1] * inv_z;
        }
        float s[3];
        if (!lookup(c, i, j, qx, qy, s))
            continue;
        acc[0] += w * s[0], acc[1] += w * s[1], acc[2] += w * s[2];
        wsum += w;
    }
    if (wsum <= 0)
        return 0;
    for (int ch = 0; ch < 3; ch++)
        rgb[ch] = (float)(acc[ch] / wsum);
    return 1;
}

static void *synth_worker(void *arg)
{
    synth_ctx *c = arg;
    const lf_lf_synth_opts *o = c->o;
    int spp = o->spp > 0 ? o->spp : 1;
    int m = (int)ceil(sqrt((double)spp));
    int finite_focus = o->focal_distance > 0;
    const double out_k = c->out_tan / c->out_half;
    /* lens strata are a random permutation of the film strata per pixel, so
     * film and lens positions are uncorrelated */
    int *perm = malloc(sizeof(int) * (size_t)spp);
    if (!perm)
        return NULL;
    for (int y = c->y0; y < c->y1; y++)
        for (int x = 0; x < o->width; x++) {
            uint64_t st = ((uint64_t)o->seed << 40) ^ ((uint64_t)y << 20) ^ (uint64_t)x;
            splitmix(&st);
            for (int k = 0; k < spp; k++)
                perm[k] = k;
            for (int k = spp - 1; k > 0; k--) {
                int r = (int)(((splitmix(&st) >> 32) * (uint64_t)(k + 1)) >> 32), tmp = perm[k];
                perm[k] = perm[r], perm[r] = tmp;
            }
            double acc[3] = {0, 0, 0};
            int covered = 0;
            for (int k = 0; k < spp; k++) {
                double jx = 0.5, jy = 0.5, lu = 0.5, lv = 0.5;
                if (spp > 1) {
                    jx = (k % m + rnd(&st)) / m, jy = (k / m + rnd(&st)) / m;
                    int l = perm[k];
                    lu = (l % m + rnd(&st)) / m, lv = (l / m + rnd(&st)) / m;
                    if (lv >= 1)
                        lv = rnd(&st);
                }
                /* camera space: pbrt perspective, fov across the shorter side */
                double dc[3] = {(x + jx - o->width * 0.5) * out_k, -(y + jy - o->height * 0.5) * out_k, 1.0};
                double pl[3] = {0, 0, 0};
                if (o->lens_radius > 0) {
                    concentric(lu, lv, &pl[0], &pl[1]);
                    pl[0] *= o->lens_radius, pl[1] *= o->lens_radius;
                }
                double fc[3], dir_c[3];
                if (finite_focus) {
                    for (int a = 0; a < 3; a++)
                        fc[a] = dc[a] * o->focal_distance, dir_c[a] = fc[a] - pl[a];
                } else {
                    memcpy(dir_c, dc, sizeof dc);
                }
                double ow[3], dw[3], fw[3];
                for (int a = 0; a < 3; a++) {
                    ow[a] = o->pos[a], dw[a] = 0, fw[a] = o->pos[a];
                    for (int b = 0; b < 3; b++) {
                        ow[a] += c->R[a * 3 + b] * pl[b];
                        dw[a] += c->R[a * 3 + b] * dir_c[b];
                        if (finite_focus)
                            fw[a] += c->R[a * 3 + b] * fc[b];
                    }
                }
                float rgb[3];
                if (radiance(c, ow, dw, finite_focus ? fw : NULL, rgb)) {
                    acc[0] += rgb[0], acc[1] += rgb[1], acc[2] += rgb[2];
                    covered++;
                }
            }
            float *p = lf_image_px(c->out, x, y);
            for (int ch = 0; ch < 3; ch++)
                p[ch] = covered ? (float)(acc[ch] / covered) : 0.f;
            if (c->cov)
                *lf_image_px(c->cov, x, y) = (float)covered / spp;
            if (!covered)
                c->uncovered++;
        }
    free(perm);
    return NULL;
}

int lf_lf_synth(const lf_lightfield *lf, const lf_lf_synth_opts *o, lf_image *out, lf_image *coverage,
                size_t *uncovered, lf_error *err)
{
    const lf_lf_layout *l = &lf->layout;
    if (l->kind != LF_LF_CAMERA_ARRAY)
        return lf_error_set(err, LF_ERR_PARAM, "synth needs a camera-array light field");
    if (!(l->have & LF_LF_HAVE_BOUNDS) || !(l->have & LF_LF_HAVE_FOV))
        return lf_error_set(err, LF_ERR_PARAM, "synth needs%s%s",
                            (l->have & LF_LF_HAVE_BOUNDS) ? "" : " lensfield:camera_grid_bounds (--griddim minx maxx miny maxy)",
                            (l->have & LF_LF_HAVE_FOV) ? "" : " lensfield:fov_deg (--inputfov DEG)");
    if (o->width < 1 || o->height < 1 || !(o->fov_deg > 0 && o->fov_deg < 180) || !(l->fov_deg > 0 && l->fov_deg < 180))
        return lf_error_set(err, LF_ERR_PARAM, "synth: bad output size %dx%d or fov (out %g, in %g degrees)", o->width,
                            o->height, o->fov_deg, l->fov_deg);
    if (o->lens_radius < 0 || (o->lens_radius > 0 && !(o->focal_distance > 0)))
        return lf_error_set(err, LF_ERR_PARAM, "synth: a lens radius needs a focal distance > 0");
    synth_ctx c;
    memset(&c, 0, sizeof c);
    c.lf = lf, c.o = o;
    double ax = o->rot_deg[0] * M_PI / 180, ay = o->rot_deg[1] * M_PI / 180, az = o->rot_deg[2] * M_PI / 180;
    double Rx[9] = {1, 0, 0, 0, cos(ax), -sin(ax), 0, sin(ax), cos(ax)};
    double Ry[9] = {cos(ay), 0, sin(ay), 0, 1, 0, -sin(ay), 0, cos(ay)};
    double Rz[9] = {cos(az), -sin(az), 0, sin(az), cos(az), 0, 0, 0, 1};
    double T[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            T[i * 3 + j] = 0;
            for (int k = 0; k < 3; k++)
                T[i * 3 + j] += Ry[i * 3 + k] * Rx[k * 3 + j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            c.R[i * 3 + j] = 0;
            for (int k = 0; k < 3; k++)
                c.R[i * 3 + j] += Rz[i * 3 + k] * T[k * 3 + j];
        }
    c.in_tan = tan(l->fov_deg * M_PI / 360), c.in_half = 0.5 * (lf->ns < lf->nt ? lf->ns : lf->nt);
    c.in_scale = c.in_half / c.in_tan;
    c.out_tan = tan(o->fov_deg * M_PI / 360), c.out_half = 0.5 * (o->width < o->height ? o->width : o->height);
    c.minx = l->grid_bounds[0], c.maxy = l->grid_bounds[3];
    c.bx = lf->nu > 1 ? (l->grid_bounds[1] - l->grid_bounds[0]) / (lf->nu - 1) : 1;
    c.by = lf->nv > 1 ? (l->grid_bounds[3] - l->grid_bounds[2]) / (lf->nv - 1) : 1;
    c.inv_bx = 1 / c.bx, c.inv_by = 1 / c.by;
    if (lf->nu == 1)
        c.minx = 0.5 * (l->grid_bounds[0] + l->grid_bounds[1]);
    if (lf->nv == 1)
        c.maxy = 0.5 * (l->grid_bounds[2] + l->grid_bounds[3]);
    if (lf_image_alloc(out, o->width, o->height, 3, err))
        return err ? err->code : LF_ERR_NOMEM;
    if (coverage && lf_image_alloc(coverage, o->width, o->height, 1, err)) {
        lf_image_free(out);
        return err ? err->code : LF_ERR_NOMEM;
    }
    c.out = out, c.cov = coverage;
    int nth = o->threads > 0 ? o->threads : 2;
    if (nth > 64)
        nth = 64;
    synth_ctx jobs[64];
    pthread_t tid[64];
    int created[64] = {0};
    for (int t = 0; t < nth; t++) {
        jobs[t] = c;
        jobs[t].y0 = o->height * t / nth, jobs[t].y1 = o->height * (t + 1) / nth;
    }
    for (int t = 1; t < nth; t++)
        created[t] = pthread_create(&tid[t], NULL, synth_worker, &jobs[t]) == 0;
    synth_worker(&jobs[0]);
    size_t unc = jobs[0].uncovered;
    for (int t = 1; t < nth; t++) {
        if (created[t])
            pthread_join(tid[t], NULL);
        else
            synth_worker(&jobs[t]);
        unc += jobs[t].uncovered;
    }
    if (uncovered)
        *uncovered = unc;
    return LF_OK;
}
