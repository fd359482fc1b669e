/* Microlens-grid estimation from a white plenoptic image, for raws whose
 * metadata is missing (as real pipelines must, cf. Dansereau et al. 2013):
 *   1. the strongest non-DC peak of the spectrum of a central crop is a
 *      reciprocal lattice vector; the bin 60 or 90 degrees from it decides
 *      hex or square; pitch and rotation follow;
 *   2. the phases of two reciprocal vectors place the lattice (offset);
 *   3. brightness centroids of every whole microlens image, fitted by least
 *      squares to centre = o + lx a + ly b (lattice coordinates lx, ly),
 *      refine pitch |a|, rotation atan2(a) and offset, twice. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_math.h"
#include "fft_internal.h"
#include "lf_lightfield.h"

static double lum(const lf_image *im, int x, int y)
{
    const float *p = lf_image_px(im, x, y);
    double v = im->channels >= 3 ? (p[0] + p[1] + p[2]) / 3.0 : p[0];
    return isfinite(v) ? v : 0.0;
}

/* Solves the 3x3 system M x = r; returns 0 when singular. */
static int solve3(const double M[9], const double r[3], double x[3])
{
    double A[9];
    memcpy(A, M, sizeof A), memcpy(x, r, 3 * sizeof(double));
    return lf_solve(A, x, 3, 1);
}

/* Hann window weight of sample i of n (against leakage from a crop's edges). */
static double hann(int i, int n)
{
    return 0.5 - 0.5 * cos(2 * M_PI * (i + 0.5) / n);
}

/* The lattice's strongest reciprocal vector: length kr (bins of the N x N
 * crop's spectrum) and angle ka, and whether the lattice is hex. */
typedef struct lattice_peak {
    double kr, ka;
    int hex;
} lattice_peak;

/* 1. The strongest spectral peak of the windowed crop with a pitch between
 * 2.5 px and N/4, refined to sub-bin; hex or square from the bin 60 against
 * the bin 90 degrees away (unless the layout says). */
static int find_lattice_peak(const lf_image *white, int N, int x0, int y0, double mean, const lf_lightfield_layout *lay,
                             lattice_peak *pk, lf_error *err)
{
    float *F = calloc((size_t)N * N * 2, sizeof(float));
    if (!F)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++)
            F[2 * ((size_t)y * N + x)] = (float)((lum(white, x0 + x, y0 + y) - mean) * (hann(x, N) * hann(y, N)));
    lf_lightfield_fft2d(F, N, N, -1);
#define MAG(kx, ky) hypot(F[2 * ((size_t)(((ky) + N) % N) * N + (((kx) + N) % N))], \
                          F[2 * ((size_t)(((ky) + N) % N) * N + (((kx) + N) % N)) + 1])
    double best = 0;
    int bkx = 0, bky = 0;
    for (int ky = -N / 2 + 1; ky < N / 2; ky++)
        for (int kx = 0; kx < N / 2; kx++) {
            double r = hypot(kx, ky);
            if (r < 4 || r > N / 2.5)
                continue;
            double m = MAG(kx, ky);
            if (m > best)
                best = m, bkx = kx, bky = ky;
        }
    if (best <= 0) {
        free(F);
        return lf_error_set(err, LF_ERR_PARAM, "white image shows no microlens pattern");
    }
    /* sub-bin peak position (parabolic fit in each axis) */
    double fx = bkx, fy = bky;
    {
        double l = MAG(bkx - 1, bky), c = MAG(bkx, bky), r = MAG(bkx + 1, bky);
        double den = l - 2 * c + r;
        if (den < 0)
            fx += 0.5 * (l - r) / den;
        l = MAG(bkx, bky - 1), r = MAG(bkx, bky + 1);
        den = l - 2 * c + r;
        if (den < 0)
            fy += 0.5 * (l - r) / den;
    }
    double kr = hypot(fx, fy), ka = atan2(fy, fx);
    double m60 = 0, m90 = 0;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            double a60 = ka + M_PI / 3, a90 = ka + M_PI / 2;
            m60 = fmax(m60, MAG((int)lround(kr * cos(a60)) + dx, (int)lround(kr * sin(a60)) + dy));
            m90 = fmax(m90, MAG((int)lround(kr * cos(a90)) + dx, (int)lround(kr * sin(a90)) + dy));
        }
#undef MAG
    free(F);
    pk->kr = kr, pk->ka = ka;
    pk->hex = (lay->have & LF_LIGHTFIELD_HAVE_GRID) ? lay->grid == LF_LIGHTFIELD_GRID_HEX : m60 > m90;
    return LF_OK;
}

/* 2. The lattice's offset o from the phases of the reciprocal vectors k1
 * (angle ka) and k2 (ka + period), evaluated at their fractional
 * frequencies and referred to the crop centre (cxc, cyc), where the window
 * is centred. */
static int lattice_offset(const lf_image *white, int N, int x0, int y0, double mean, const lattice_peak *pk,
                          double period, double cxc, double cyc, double o[2], lf_error *err)
{
    double ph[2], kv[2][2];
    for (int q = 0; q < 2; q++) {
        double ang = pk->ka + q * period;
        kv[q][0] = pk->kr * cos(ang) / N, kv[q][1] = pk->kr * sin(ang) / N; /* cycles per pixel */
        double re = 0, im = 0;
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double w = hann(x, N) * hann(y, N);
                double v = (lum(white, x0 + x, y0 + y) - mean) * w;
                double t = -2 * M_PI * (kv[q][0] * (x0 + x + 0.5 - cxc) + kv[q][1] * (y0 + y + 0.5 - cyc));
                re += v * cos(t), im += v * sin(t);
            }
        ph[q] = atan2(im, re);
    }
    /* k . (o - centre) = -phase / 2 pi (cycles) */
    double det = kv[0][0] * kv[1][1] - kv[0][1] * kv[1][0];
    if (fabs(det) < 1e-12)
        return lf_error_set(err, LF_ERR_PARAM, "white image: degenerate microlens pattern");
    double r0 = -ph[0] / (2 * M_PI), r1 = -ph[1] / (2 * M_PI);
    o[0] = (r0 * kv[1][1] - r1 * kv[0][1]) / det + cxc, o[1] = (kv[0][0] * r1 - kv[1][0] * r0) / det + cyc;
    return LF_OK;
}

/* The lattice's shift (dx, dy) in the T x T tile at (tx, ty) from the
 * predicted one: the phases of the two reciprocal vectors k there against
 * those the offset o predicts. */
static void tile_lattice_shift(const lf_image *white, int tx, int ty, int T, const double k[2][2], const double o[2],
                               double *dx, double *dy)
{
    double tcx = tx + 0.5 * T, tcy = ty + 0.5 * T;
    double tmean = 0;
    for (int y = 0; y < T; y++)
        for (int x = 0; x < T; x++)
            tmean += lum(white, tx + x, ty + y);
    tmean /= (double)T * T;
    double dphi[2];
    for (int q = 0; q < 2; q++) {
        double re = 0, im = 0;
        for (int y = 0; y < T; y++) {
            double wy = hann(y, T);
            for (int x = 0; x < T; x++) {
                double w = wy * hann(x, T);
                double v = (lum(white, tx + x, ty + y) - tmean) * w;
                double t = -2 * M_PI * (k[q][0] * (tx + x + 0.5 - tcx) + k[q][1] * (ty + y + 0.5 - tcy));
                re += v * cos(t), im += v * sin(t);
            }
        }
        double pred = -2 * M_PI * (k[q][0] * (o[0] - tcx) + k[q][1] * (o[1] - tcy));
        double d = atan2(im, re) - pred;
        dphi[q] = d - 2 * M_PI * floor(d / (2 * M_PI) + 0.5);
    }
    /* k_q . delta = -dphi_q / 2 pi */
    double r0 = -dphi[0] / (2 * M_PI), r1 = -dphi[1] / (2 * M_PI);
    double dk = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    *dx = (r0 * k[1][1] - r1 * k[0][1]) / dk, *dy = (k[0][0] * r1 - k[1][0] * r0) / dk;
}

/* 3. Local phases in tiles across the image: each tile's two reciprocal-
 * vector phases give the lattice's shift there; a least-squares affine fit
 * of the shifts corrects offset o and lattice vectors a, b.  The fitted
 * region grows from the crop centre (cxc, cyc) as the estimate improves. */
static int refine_lattice(const lf_image *white, int N, double cxc, double cyc, int hex, double o[2], double a[2],
                          double b[2], lf_error *err)
{
    int W = white->width, H = white->height;
    double rowf = hex ? sqrt(3.0) / 2 : 1.0;
    int T = N < 128 ? N : 128;
    for (int iter = 0; iter < 6; iter++) {
        double reach = iter >= 4 ? 1e30 : 0.5 * N * (1 << iter);
        double e2[2] = {(hex ? 0.5 : 0.0) * a[0] + rowf * b[0], (hex ? 0.5 : 0.0) * a[1] + rowf * b[1]};
        double dE = a[0] * e2[1] - a[1] * e2[0];
        /* reciprocal basis: rows of E^{-T}, k_i . e_j = delta_ij */
        double k[2][2] = {{e2[1] / dE, -e2[0] / dE}, {-a[1] / dE, a[0] / dE}};
        double M[9] = {0}, rx[3] = {0}, ry[3] = {0};
        int n = 0;
        for (int ty = 0; ty + T <= H; ty += T / 2)
            for (int tx = 0; tx + T <= W; tx += T / 2) {
                double tcx = tx + 0.5 * T, tcy = ty + 0.5 * T;
                if (hypot(tcx - cxc, tcy - cyc) > reach)
                    continue;
                double dx, dy;
                tile_lattice_shift(white, tx, ty, T, k, o, &dx, &dy);
                double row[3] = {1, tcx - cxc, tcy - cyc};
                for (int u = 0; u < 3; u++) {
                    for (int v = 0; v < 3; v++)
                        M[u * 3 + v] += row[u] * row[v];
                    rx[u] += row[u] * dx, ry[u] += row[u] * dy;
                }
                n++;
            }
        double sx[3], sy[3];
        if (n < 3 || !solve3(M, rx, sx) || !solve3(M, ry, sy)) {
            if (iter == 0)
                return lf_error_set(err, LF_ERR_PARAM, "white image: too few tiles (%d) to fit the microlens grid", n);
            continue;
        }
        /* delta(x) = d0 + J (x - centre): move every centre by it */
        double J[4] = {sx[1], sx[2], sy[1], sy[2]};
        double no0 = o[0] + sx[0] + J[0] * (o[0] - cxc) + J[1] * (o[1] - cyc);
        double no1 = o[1] + sy[0] + J[2] * (o[0] - cxc) + J[3] * (o[1] - cyc);
        double na[2] = {a[0] + J[0] * a[0] + J[1] * a[1], a[1] + J[2] * a[0] + J[3] * a[1]};
        double nb[2] = {b[0] + J[0] * b[0] + J[1] * b[1], b[1] + J[2] * b[0] + J[3] * b[1]};
        o[0] = no0, o[1] = no1;
        memcpy(a, na, sizeof na), memcpy(b, nb, sizeof nb);
    }
    return LF_OK;
}

/* The fitted lattice into the layout, lens (0, 0) the first (even, for
 * hex) row and column near the top-left. */
static void store_lattice(lf_lightfield_layout *lay, int W, int H, int hex, double o[2], const double a[2],
                          const double b[2])
{
    double rowf = hex ? sqrt(3.0) / 2 : 1.0;
    double pitch = 0.5 * (hypot(a[0], a[1]) + hypot(b[0], b[1]));
    double rot = atan2(a[1], a[0]);
    double inv = 1.0 / (a[0] * b[1] - a[1] * b[0]);
    double lx = (-o[0] * b[1] + o[1] * b[0]) * inv, ly = (-a[0] * o[1] + a[1] * o[0]) * inv;
    int j0 = (int)ceil(ly / rowf - 0.5);
    if (hex && (j0 & 1))
        j0--;
    int i0 = (int)ceil(lx - 0.5);
    o[0] += i0 * a[0] + j0 * rowf * b[0];
    o[1] += i0 * a[1] + j0 * rowf * b[1];
    lay->kind = LF_LIGHTFIELD_PLENOPTIC;
    lay->grid = hex ? LF_LIGHTFIELD_GRID_HEX : LF_LIGHTFIELD_GRID_SQUARE;
    lay->pitch_px = pitch, lay->rotation_rad = rot;
    lay->offset_px[0] = o[0], lay->offset_px[1] = o[1];
    lay->lens_x = (int)floor((W - o[0]) / pitch) + 1;
    lay->lens_y = (int)floor((H - o[1]) / (pitch * rowf)) + 1;
    lay->have |= LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_GRID | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_ROTATION | LF_LIGHTFIELD_HAVE_OFFSET |
                 LF_LIGHTFIELD_HAVE_LENS_COUNT;
}

int lf_lightfield_calibrate(const lf_image *white, lf_lightfield_layout *lay, lf_error *err)
{
    int W = white->width, H = white->height;
    int N = 1;
    while (N * 2 <= W && N * 2 <= H && N < 512)
        N *= 2;
    if (N < 32)
        return lf_error_set(err, LF_ERR_PARAM, "white image %dx%d is too small to calibrate", W, H);
    int x0 = (W - N) / 2, y0 = (H - N) / 2;
    double mean = 0;
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++)
            mean += lum(white, x0 + x, y0 + y);
    mean /= (double)N * N;
    if (!(mean > 0))
        return lf_error_set(err, LF_ERR_PARAM, "white image is black");
    lattice_peak pk = {0};
    int rc = find_lattice_peak(white, N, x0, y0, mean, lay, &pk, err);
    if (rc)
        return rc;
    int hex = pk.hex;
    double pitch = hex ? 2.0 * N / (sqrt(3.0) * pk.kr) : N / pk.kr;
    /* square: reciprocal vectors along the rows; hex: 90 degrees from them (mod 60) */
    double period = hex ? M_PI / 3 : M_PI / 2;
    double rot = pk.ka - (hex ? M_PI / 2 : 0.0);
    rot -= period * floor(rot / period + 0.5);
    double cxc = x0 + 0.5 * N, cyc = y0 + 0.5 * N, o[2] = {0, 0};
    if ((rc = lattice_offset(white, N, x0, y0, mean, &pk, period, cxc, cyc, o, err)))
        return rc;
    double a[2] = {pitch * cos(rot), pitch * sin(rot)}, b[2] = {-pitch * sin(rot), pitch * cos(rot)};
    if ((rc = refine_lattice(white, N, cxc, cyc, hex, o, a, b, err)))
        return rc;
    store_lattice(lay, W, H, hex, o, a, b);
    return LF_OK;
}
