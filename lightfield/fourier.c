/* Fourier slice refocusing (Ng 2005, "Fourier Slice Photography").
 *
 * A photograph refocused at disparity d is, in the frequency domain, a 2D
 * slice of the 4D spectrum of L: with the (s,t) transform of each view
 * L^(u, k) and the (u,v) transform S(m, k) = sum_u L^(u, k) e^{-2 pi i m u / P},
 * shift-and-add's E^(k) = (1/N) sum_u L^(u, k) e^{-2 pi i k d u / Ps} is
 * S(m = k d P / Ps, k) / N.
 *   - (s,t): each view is zero-padded to powers of two Ps x Pt (no more: the
 *     transform is periodic, so pixels within the largest shift of a border
 *     mix with the opposite border).
 *   - (u,v): the DFT is evaluated on P = ceil(oversample * n) points (zero
 *     padding by oversample) and the slice at fractional m interpolates with
 *     a 4-tap Kaiser-Bessel kernel (beta from Beatty et al. 2005).  The
 *     kernel's roll-off is pre-compensated exactly by dividing each view by
 *     the kernel's continuous transform at its u (Ng's pre-multiplication).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fft_internal.h"
#include "lf_lightfield.h"

/* Kaiser-Bessel kernel width (taps) and table size */
enum { KB_WIDTH = 4, KB_TABLE = 4096 };

struct lf_lightfield_fourier {
    int ns, nt, Ps, Pt, Pu, Pv, nu, nv;
    double cu, cv;     /* half-integer part of the centred view coordinates */
    double wsum;       /* sum of aperture weights */
    double beta;
    float kb_tab[KB_TABLE + 1];
    double disp_v_per_u;
    float *S;          /* [kt][ks <= Ps/2][mv][mu][ch] complex (re, im) */
};


static double bessel_i0(double x)
{
    double s = 1, t = 1;
    for (int k = 1; k < 60; k++) {
        t *= (x / (2 * k)) * (x / (2 * k));
        s += t;
        if (t < 1e-17 * s)
            break;
    }
    return s;
}

static double kb_exact(double x, double beta)
{
    double r = 2 * x / KB_WIDTH;
    if (fabs(r) >= 1)
        return 0;
    return bessel_i0(beta * sqrt(1 - r * r)) / bessel_i0(beta);
}

/* Tabulated kernel for the per-frame slice (linear interpolation of 4096
 * samples over [0, 2]: relative error ~1e-7). */
static double kb_from(const float *tab, double x)
{
    double a = fabs(x) * (KB_TABLE / (KB_WIDTH / 2.0));
    int i = (int)a;
    if (i >= KB_TABLE)
        return 0;
    return tab[i] + (a - i) * (tab[i + 1] - tab[i]);
}

/* Continuous transform of the kernel at frequency f (Simpson's rule). */
static double kb_hat(double f, double beta)
{
    const int n = 512;
    double h = (double)KB_WIDTH / n, s = 0;
    for (int i = 0; i <= n; i++) {
        double x = -KB_WIDTH / 2.0 + i * h;
        double w = (i == 0 || i == n) ? 1 : (i & 1 ? 4 : 2);
        s += w * kb_exact(x, beta) * cos(2 * M_PI * x * f);
    }
    return s * h / 3;
}

static int next_pow2(int n)
{
    int p = 1;
    while (p < n)
        p <<= 1;
    return p;
}

/* In-place radix-2 FFT of n complex floats with stride (in complex units).
 * sign -1 forward, +1 inverse (unnormalised). */
void lf_lightfield_fft1d(float *a, int n, int stride, int sign)
{
    for (int i = 1, j = 0; i < n; i++) {
        int bit = n >> 1;
        for (; j & bit; bit >>= 1)
            j ^= bit;
        j ^= bit;
        if (i < j) {
            float *p = a + 2 * (size_t)i * stride, *q = a + 2 * (size_t)j * stride;
            float t0 = p[0], t1 = p[1];
            p[0] = q[0], p[1] = q[1], q[0] = t0, q[1] = t1;
        }
    }
    for (int len = 2; len <= n; len <<= 1) {
        double ang = sign * 2 * M_PI / len;
        /* twiddles by recurrence in double (no trig per butterfly group) */
        double cr = 1, ci = 0, dr = cos(ang), di = sin(ang);
        for (int k = 0; k < len / 2; k++) {
            float wr = (float)cr, wi = (float)ci;
            double t = cr * dr - ci * di;
            ci = cr * di + ci * dr, cr = t;
            for (int i = 0; i < n; i += len) {
                float *p = a + 2 * (size_t)(i + k) * stride, *q = a + 2 * (size_t)(i + k + len / 2) * stride;
                float xr = q[0] * wr - q[1] * wi, xi = q[0] * wi + q[1] * wr;
                q[0] = p[0] - xr, q[1] = p[1] - xi;
                p[0] += xr, p[1] += xi;
            }
        }
    }
}

void lf_lightfield_fft2d(float *a, int w, int h, int sign)
{
    for (int y = 0; y < h; y++)
        lf_lightfield_fft1d(a + 2 * (size_t)y * w, w, 1, sign);
    for (int x = 0; x < w; x++)
        lf_lightfield_fft1d(a + 2 * (size_t)x, h, w, sign);
}

/* The synthetic aperture's weight of each view, divided by the Kaiser-Bessel
 * window's transform at the view's integer offset (iu - ou, iv - ov) (the
 * gridding's deapodisation); f->wsum the weights' sum. */
static void aperture_weights(lf_lightfield_fourier *f, const lf_lightfield *lf, const lf_lightfield_refocus_opts *ap,
                             int ou, int ov, double *au)
{
    f->wsum = 0;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            lf_lightfield_refocus_opts o = *ap;
            double w = 1;
            if (o.u1 >= 0 && (iu < o.u0 || iu > o.u1))
                w = 0;
            if (o.v1 >= 0 && (iv < o.v0 || iv > o.v1))
                w = 0;
            if (o.aperture_radius >= 0) {
                double u = iu - (lf->nu - 1) / 2.0, v = iv - (lf->nv - 1) / 2.0;
                if (u * u + v * v > o.aperture_radius * o.aperture_radius + 1e-9)
                    w = 0;
            }
            f->wsum += w;
            au[iv * lf->nu + iu] = w / (kb_hat((double)(iu - ou) / f->Pu, f->beta) * kb_hat((double)(iv - ov) / f->Pv, f->beta));
        }
}

/* Per view and channel the 2D FFT over (s, t), zero-padded to Ps x Pt, half
 * spectrum (hs columns) kept in Lhat; buf: Ps * Pt complex scratch. */
static void view_spectra(const lf_lightfield_fourier *f, const lf_lightfield *lf, float *buf, float *Lhat, size_t nfreq,
                         int hs)
{
    for (int vi = 0; vi < lf->nu * lf->nv; vi++) {
        const float *view = lf->data + (size_t)vi * lf->ns * lf->nt * 3;
        for (int ch = 0; ch < 3; ch++) {
            memset(buf, 0, sizeof(float) * 2 * (size_t)f->Ps * f->Pt);
            for (int t = 0; t < lf->nt; t++)
                for (int s = 0; s < lf->ns; s++)
                    buf[2 * ((size_t)t * f->Ps + s)] = view[((size_t)t * lf->ns + s) * 3 + ch];
            lf_lightfield_fft2d(buf, f->Ps, f->Pt, -1);
            float *dst = Lhat + 2 * nfreq * ((size_t)vi * 3 + ch);
            for (int kt = 0; kt < f->Pt; kt++)
                memcpy(dst + 2 * (size_t)kt * hs, buf + 2 * (size_t)kt * f->Ps, sizeof(float) * 2 * hs);
        }
    }
}

/* The weighted DFT over (u, v) of every (s, t) frequency into f->S,
 * separable: u first into tmp, then v. */
static int angular_dft(lf_lightfield_fourier *f, const lf_lightfield *lf, const double *au, const float *Lhat,
                       size_t nfreq, size_t cell, int ou, int ov, lf_error *err)
{
    double *tw_u = malloc(sizeof(double) * 2 * f->Pu * lf->nu), *tw_v = malloc(sizeof(double) * 2 * f->Pv * lf->nv);
    double *tmp = malloc(sizeof(double) * 2 * f->Pu * lf->nv);
    if (!tw_u || !tw_v || !tmp) {
        free(tw_u), free(tw_v), free(tmp);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (int m = 0; m < f->Pu; m++)
        for (int iu = 0; iu < lf->nu; iu++) {
            double a = -2 * M_PI * m * (iu - ou) / f->Pu;
            tw_u[2 * (m * lf->nu + iu)] = cos(a), tw_u[2 * (m * lf->nu + iu) + 1] = sin(a);
        }
    for (int m = 0; m < f->Pv; m++)
        for (int iv = 0; iv < lf->nv; iv++) {
            double a = -2 * M_PI * m * (iv - ov) / f->Pv;
            tw_v[2 * (m * lf->nv + iv)] = cos(a), tw_v[2 * (m * lf->nv + iv) + 1] = sin(a);
        }
    for (size_t k = 0; k < nfreq; k++)
        for (int ch = 0; ch < 3; ch++) {
            for (int mu = 0; mu < f->Pu; mu++)
                for (int iv = 0; iv < lf->nv; iv++) {
                    double re = 0, im = 0;
                    for (int iu = 0; iu < lf->nu; iu++) {
                        int vi = iv * lf->nu + iu;
                        const float *x = Lhat + 2 * (nfreq * ((size_t)vi * 3 + ch) + k);
                        double c = tw_u[2 * (mu * lf->nu + iu)], s = tw_u[2 * (mu * lf->nu + iu) + 1];
                        re += au[vi] * (x[0] * c - x[1] * s);
                        im += au[vi] * (x[0] * s + x[1] * c);
                    }
                    tmp[2 * (mu * lf->nv + iv)] = re, tmp[2 * (mu * lf->nv + iv) + 1] = im;
                }
            for (int mv = 0; mv < f->Pv; mv++)
                for (int mu = 0; mu < f->Pu; mu++) {
                    double re = 0, im = 0;
                    for (int iv = 0; iv < lf->nv; iv++) {
                        const double *x = tmp + 2 * (mu * lf->nv + iv);
                        double c = tw_v[2 * (mv * lf->nv + iv)], s = tw_v[2 * (mv * lf->nv + iv) + 1];
                        re += x[0] * c - x[1] * s;
                        im += x[0] * s + x[1] * c;
                    }
                    float *d = f->S + 2 * (k * cell + ((size_t)mv * f->Pu + mu) * 3 + ch);
                    d[0] = (float)re, d[1] = (float)im;
                }
        }
    free(tw_u), free(tw_v), free(tmp);
    return LF_OK;
}

int lf_lightfield_fourier_new(const lf_lightfield *lf, const lf_lightfield_refocus_opts *ap, double oversample, lf_lightfield_fourier **out,
                      lf_error *err)
{
    *out = NULL;
    if (lf->valid)
        return lf_error_set(err, LF_ERR_UNSUPPORTED,
                            "Fourier slice refocusing needs a light field without missing samples (%zu missing)",
                            lf->missing);
    if (!(oversample >= 1))
        oversample = 2;
    lf_lightfield_refocus_opts def = lf_lightfield_refocus_defaults();
    if (!ap)
        ap = &def;
    lf_lightfield_fourier *f = calloc(1, sizeof *f);
    if (!f)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    f->ns = lf->ns, f->nt = lf->nt, f->nu = lf->nu, f->nv = lf->nv;
    f->Ps = next_pow2(lf->ns), f->Pt = next_pow2(lf->nt);
    f->Pu = (int)ceil(oversample * lf->nu), f->Pv = (int)ceil(oversample * lf->nv);
    f->disp_v_per_u = lf->disp_v_per_u;
    double sigma = oversample;
    double b2 = (KB_WIDTH / sigma) * (KB_WIDTH / sigma) * (sigma - 0.5) * (sigma - 0.5) - 0.8;
    f->beta = M_PI * sqrt(b2 > 0.1 ? b2 : 0.1);
    for (int i = 0; i <= KB_TABLE; i++)
        f->kb_tab[i] = (float)kb_exact(i * (KB_WIDTH / 2.0) / KB_TABLE, f->beta);
    int hs = f->Ps / 2 + 1;
    size_t nfreq = (size_t)hs * f->Pt, cell = (size_t)f->Pu * f->Pv * 3;
    int nviews = lf->nu * lf->nv;
    float *Lhat = malloc(sizeof(float) * 2 * nfreq * 3 * (size_t)nviews);
    float *buf = malloc(sizeof(float) * 2 * (size_t)f->Ps * f->Pt);
    f->S = malloc(sizeof(float) * 2 * nfreq * cell);
    double *au = NULL;
    int rc = LF_OK;
    if (!Lhat || !buf || !f->S) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory for the 4D spectrum (%.0f MB)",
                          sizeof(float) * 2.0 * nfreq * cell / 1e6);
        goto done;
    }
    /* integer view offsets u_i (centred, rounded down) and their weights a_u */
    int ou = lf->nu / 2, ov = lf->nv / 2;
    f->cu = (lf->nu - 1) / 2.0 - ou, f->cv = (lf->nv - 1) / 2.0 - ov; /* u_c = u_i - cu... see slice */
    if (!(au = malloc(sizeof(double) * (size_t)nviews))) {
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        goto done;
    }
    aperture_weights(f, lf, ap, ou, ov, au);
    if (f->wsum == 0) {
        rc = lf_error_set(err, LF_ERR_PARAM, "the synthetic aperture selects no view");
        goto done;
    }
    view_spectra(f, lf, buf, Lhat, nfreq, hs);
    rc = angular_dft(f, lf, au, Lhat, nfreq, cell, ou, ov, err);
done:
    free(au), free(Lhat), free(buf);
    if (rc)
        lf_lightfield_fourier_release(f);
    else
        *out = f;
    return rc;
}

static int wrap(int j, int n)
{
    j %= n;
    return j < 0 ? j + n : j;
}

int lf_lightfield_fourier_refocus(const lf_lightfield_fourier *f, double disp, lf_image *out, lf_error *err)
{
    if (!isfinite(disp))
        return lf_error_set(err, LF_ERR_PARAM, "disparity must be finite");
    int hs = f->Ps / 2 + 1;
    size_t cell = (size_t)f->Pu * f->Pv * 3;
    float *spec = calloc((size_t)f->Ps * f->Pt * 2 * 3, sizeof(float));
    if (!spec)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    size_t plane = (size_t)f->Ps * f->Pt * 2;
    double dx = disp, dy = disp * f->disp_v_per_u;
    for (int kt = 0; kt < f->Pt; kt++) {
        int ft = kt <= f->Pt / 2 ? kt : kt - f->Pt;
        double mv = ft * dy * f->Pv / f->Pt;
        int jv = (int)floor(mv) - 1;
        double kv[KB_WIDTH];
        for (int b = 0; b < KB_WIDTH; b++)
            kv[b] = kb_from(f->kb_tab, mv - (jv + b));
        for (int ks = 0; ks < hs; ks++) {
            double mu = ks * dx * f->Pu / f->Ps;
            int ju = (int)floor(mu) - 1;
            double ku[KB_WIDTH];
            for (int a = 0; a < KB_WIDTH; a++)
                ku[a] = kb_from(f->kb_tab, mu - (ju + a));
            const float *S = f->S + 2 * ((size_t)kt * hs + ks) * cell;
            double acc[3][2] = {{0, 0}, {0, 0}, {0, 0}};
            for (int b = 0; b < KB_WIDTH; b++) {
                int rv = wrap(jv + b, f->Pv);
                for (int a = 0; a < KB_WIDTH; a++) {
                    double w = ku[a] * kv[b];
                    const float *x = S + 2 * (((size_t)rv * f->Pu + wrap(ju + a, f->Pu)) * 3);
                    for (int ch = 0; ch < 3; ch++)
                        acc[ch][0] += w * x[2 * ch], acc[ch][1] += w * x[2 * ch + 1];
                }
            }
            /* u_c = u_i - cu: phase e^{+2 pi i m cu / P} restores the centring */
            double ph = 2 * M_PI * (mu * f->cu / f->Pu + mv * f->cv / f->Pv);
            double c = cos(ph) / f->wsum, s = sin(ph) / f->wsum;
            for (int ch = 0; ch < 3; ch++) {
                float *d = spec + ch * plane + 2 * ((size_t)kt * f->Ps + ks);
                d[0] = (float)(acc[ch][0] * c - acc[ch][1] * s);
                d[1] = (float)(acc[ch][0] * s + acc[ch][1] * c);
            }
        }
    }
    /* Hermitian completion, inverse transform */
    for (int ch = 0; ch < 3; ch++) {
        float *p = spec + ch * plane;
        for (int kt = 0; kt < f->Pt; kt++)
            for (int ks = hs; ks < f->Ps; ks++) {
                const float *q = p + 2 * ((size_t)((f->Pt - kt) % f->Pt) * f->Ps + (f->Ps - ks));
                float *d = p + 2 * ((size_t)kt * f->Ps + ks);
                d[0] = q[0], d[1] = -q[1];
            }
        lf_lightfield_fft2d(p, f->Ps, f->Pt, +1);
    }
    if (lf_image_alloc(out, f->ns, f->nt, 3, err)) {
        free(spec);
        return err ? err->code : LF_ERR_NOMEM;
    }
    float norm = 1.f / ((float)f->Ps * f->Pt);
    for (int t = 0; t < f->nt; t++)
        for (int s = 0; s < f->ns; s++)
            for (int ch = 0; ch < 3; ch++)
                lf_image_px(out, s, t)[ch] = spec[ch * plane + 2 * ((size_t)t * f->Ps + s)] * norm;
    free(spec);
    return LF_OK;
}

void lf_lightfield_fourier_release(lf_lightfield_fourier *f)
{
    if (!f)
        return;
    free(f->S);
    free(f);
}
