/* Real compound lenses (see lens.h): prescription parser, paraxial y-nu
 * analysis, exact tracing with Snell's law, focusing, exit-pupil bounds.
 *
 * References: Kolb, Mitchell & Hanrahan 1995; pbrt-v4 RealisticCamera
 * (TraceLensesFromFilm, FocusThickLens, FocusBinarySearch, BoundExitPupil,
 * SampleExitPupil); W. Smith, Modern Lens Design (y-nu trace).
 */
#include "lens.h"
#include "base/lf_file.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_math.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---------------------------------------------------------------- parsing */

/* 0, or what is wrong with tok as a number (for the message). */
static const char *parse_number(const char *tok, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(tok, &end);
    if (end == tok || *end)
        return "is not a number";
    if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return "is too large (beyond double precision's range)";
    if (errno == ERANGE)
        return "is too small (it underflows double precision: below 2.2e-308, denormal or zero)";
    *out = v;
    return 0;
}

static void cauchy_fit(lf_lens_surface *s)
{
    /* n(lambda) = A + B / lambda^2 through n_d, with n_F - n_C = (n_d - 1) / V_d. */
    s->cauchy_a = s->ior, s->cauchy_b = 0.0;
    if (s->abbe > 0.0 && s->ior > 1.0) {
        double lf = LF_LENS_LAMBDA_F * 1e-3, lc = LF_LENS_LAMBDA_C * 1e-3, ld = LF_LENS_LAMBDA_D * 1e-3;
        s->cauchy_b = (s->ior - 1.0) / (s->abbe * (1.0 / (lf * lf) - 1.0 / (lc * lc)));
        s->cauchy_a = s->ior - s->cauchy_b / (ld * ld);
    }
}

int lf_lens_parse(const char *text, const char *filename, lf_lens *lens, lf_error *err)
{
    memset(lens, 0, sizeof *lens);
    lens->stop = -1;
    snprintf(lens->path, sizeof lens->path, "%s", filename);
    int cap = 0, line_no = 0;
    const char *p = text;
    while (*p) {
        line_no++;
        lf_loc at = {filename, line_no, 0};
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char line[1024];
        if (len >= sizeof line) {
            lf_error_at(err, LF_ERR_PARSE, &at, "line too long");
            goto fail;
        }
        memcpy(line, p, len);
        line[len] = 0;
        p = eol ? eol + 1 : p + len;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = 0;
        char *tok[8], *save = NULL;
        int nt = 0;
        for (char *t = strtok_r(line, " \t\r,", &save); t; t = strtok_r(NULL, " \t\r,", &save)) {
            if (nt < 8)
                tok[nt] = t;
            nt++;
        }
        if (nt == 0)
            continue;
        if (nt != 4 && nt != 5) {
            lf_error_at(err, LF_ERR_PARSE, &at, "expected 4 or 5 columns (radius thickness ior aperture [abbe]), got %d",
                        nt);
            goto fail;
        }
        double v[5] = {0, 0, 0, 0, 0};
        static const char *const col[5] = {"radius", "thickness", "ior", "aperture", "abbe"};
        for (int i = 0; i < nt; i++) {
            const char *why = parse_number(tok[i], &v[i]);
            if (why) {
                lf_error_at(err, LF_ERR_PARSE, &at, "%s \"%s\" %s", col[i], tok[i], why);
                goto fail;
            }
        }
        if (v[1] < 0.0) {
            lf_error_at(err, LF_ERR_PARSE, &at, "thickness %g must be >= 0", v[1]);
            goto fail;
        }
        if (v[2] != 0.0 && v[2] < 1.0) {
            lf_error_at(err, LF_ERR_PARSE, &at, "ior %g must be >= 1 (0 or 1 = air)", v[2]);
            goto fail;
        }
        if (!(v[3] > 0.0)) {
            lf_error_at(err, LF_ERR_PARSE, &at, "aperture diameter %g must be > 0", v[3]);
            goto fail;
        }
        if (v[0] != 0.0 && v[3] > 2.0 * fabs(v[0])) {
            lf_error_at(err, LF_ERR_PARSE, &at, "aperture diameter %g exceeds the sphere's diameter 2|%g|", v[3], v[0]);
            goto fail;
        }
        if (v[4] < 0.0) {
            lf_error_at(err, LF_ERR_PARSE, &at, "Abbe number %g must be >= 0", v[4]);
            goto fail;
        }
        if (v[0] == 0.0 && lens->stop >= 0) {
            lf_error_at(err, LF_ERR_PARSE, &at, "a second aperture stop (radius 0); the first is on line %d",
                        lens->s[lens->stop].line);
            goto fail;
        }
        if (lens->n == cap) {
            cap = cap ? 2 * cap : 16;
            lf_lens_surface *ns = realloc(lens->s, (size_t)cap * sizeof *ns);
            if (!ns) {
                lf_error_at(err, LF_ERR_NOMEM, &(lf_loc){filename, 0, 0}, "out of memory");
                goto fail;
            }
            lens->s = ns;
        }
        lf_lens_surface *s = &lens->s[lens->n];
        memset(s, 0, sizeof *s);
        s->radius_mm = v[0];
        s->thickness_mm = v[1];
        s->ior = v[2] == 0.0 ? 1.0 : v[2];
        s->aperture_radius_mm = 0.5 * v[3];
        s->abbe = s->ior > 1.0 ? v[4] : 0.0;
        s->line = line_no;
        cauchy_fit(s);
        if (s->abbe > 0.0)
            lens->has_abbe = 1;
        if (v[0] == 0.0) {
            lens->stop = lens->n;
            lens->stop_max_radius_mm = s->aperture_radius_mm;
        }
        lens->n++;
    }
    if (lens->n == 0) {
        lf_error_at(err, LF_ERR_PARSE, &(lf_loc){filename, 0, 0},
                    "no lens surfaces (expected rows: radius thickness ior aperture [abbe])");
        goto fail;
    }
    if (lens->s[lens->n - 1].ior != 1.0) {
        lf_error_at(err, LF_ERR_PARSE, &(lf_loc){filename, lens->s[lens->n - 1].line, 0},
                    "the last surface must leave into air (ior 0 or 1), got %g", lens->s[lens->n - 1].ior);
        goto fail;
    }
    double z = 0.0;
    for (int i = lens->n - 1; i >= 0; i--) {
        lens->s[i].z_mm = z;
        if (i > 0)
            z -= lens->s[i - 1].thickness_mm;
    }
    lens->film_distance_mm = lens->s[lens->n - 1].thickness_mm;
    return 0;
fail:
    free(lens->s);
    lens->s = NULL;
    lens->n = 0;
    return err && err->code ? err->code : LF_ERR_PARSE;
}

int lf_lens_load(const char *path, lf_lens *lens, lf_error *err)
{
    memset(lens, 0, sizeof *lens);
    /* The prescription may be gzipped (the magic bytes decide). */
    char *buf;
    size_t len;
    lf_error ferr = {0};
    if (lf_file_read(path, (size_t)1 << 24, &buf, &len, NULL, &ferr)) {
        return lf_error_set(err, ferr.code, "lens file %s", ferr.msg);
    }
    buf[len] = 0;
    if (strlen(buf) != len) {
        free(buf);
        return lf_error_set(err, LF_ERR_PARSE, "%s: not a text lens file (contains NUL bytes)", path);
    }
    int rc = lf_lens_parse(buf, path, lens, err);
    free(buf);
    return rc;
}

void lf_lens_free(lf_lens *lens)
{
    if (!lens)
        return;
    free(lens->s);
    lens->s = NULL;
    lens->n = 0;
}

int lf_lens_set_stop_diameter(lf_lens *lens, double diameter_mm, lf_warnings *w)
{
    if (lens->stop < 0)
        return 0;
    double r = 0.5 * diameter_mm;
    if (r > lens->stop_max_radius_mm) {
        lf_warn_at(w, NULL, "aperture diameter %g mm is larger than the stop of %s (%g mm); clamping it", diameter_mm,
                   lens->path, 2.0 * lens->stop_max_radius_mm);
        lens->s[lens->stop].aperture_radius_mm = lens->stop_max_radius_mm;
        return 1;
    }
    lens->s[lens->stop].aperture_radius_mm = r;
    return 0;
}

static inline double ior_at(const lf_lens_surface *s, double inv_l2)
{
    return inv_l2 > 0.0 && s->cauchy_b != 0.0 ? s->cauchy_a + s->cauchy_b * inv_l2 : s->ior;
}

static inline double inv_lambda2(const lf_lens *lens, double lambda_nm)
{
    if (!lens->dispersive || !(lambda_nm > 0.0))
        return 0.0;
    double l = lambda_nm * 1e-3;
    return 1.0 / (l * l);
}

double lf_lens_ior(const lf_lens *lens, int i, double lambda_nm)
{
    return ior_at(&lens->s[i], inv_lambda2(lens, lambda_nm));
}

double lf_lens_total_length_mm(const lf_lens *lens)
{
    return -lens->s[0].z_mm;
}

/* --------------------------------------------------------------- paraxial */

static double n_after(const lf_lens *L, int i)
{
    return L->s[i].ior;
}
static double n_before(const lf_lens *L, int i)
{
    return i > 0 ? L->s[i - 1].ior : 1.0;
}
static double curvature(const lf_lens_surface *s)
{
    return s->radius_mm != 0.0 ? 1.0 / s->radius_mm : 0.0;
}

/* y-nu trace, light going toward the film, through surfaces a..b: (y, u)
 * given at the vertex of a in the medium before it; returned at the vertex of
 * b after refraction.  n'u' = nu - y (n' - n) / R, then y += t u'. */
static void ynu_forward(const lf_lens *L, int a, int b, double *y, double *u)
{
    for (int i = a; i <= b; i++) {
        double n = n_before(L, i), np = n_after(L, i);
        *u = (n * *u - *y * (np - n) * curvature(&L->s[i])) / np;
        if (i < b)
            *y += L->s[i].thickness_mm * *u;
    }
}

/* The same with light going toward the scene, through surfaces a..b (a >= b):
 * seen from behind, every radius changes sign and the media swap. */
static void ynu_reverse(const lf_lens *L, int a, int b, double *y, double *u)
{
    for (int i = a; i >= b; i--) {
        double n = n_after(L, i), np = n_before(L, i);
        *u = (n * *u + *y * (np - n) * curvature(&L->s[i])) / np;
        if (i > b)
            *y += L->s[i - 1].thickness_mm * *u;
    }
}

int lf_lens_paraxial_analyse(const lf_lens *L, lf_lens_paraxial *px)
{
    memset(px, 0, sizeof *px);
    int last = L->n - 1;
    px->total_length_mm = lf_lens_total_length_mm(L);
    double y = 1.0, u = 0.0;
    ynu_forward(L, 0, last, &y, &u);
    if (!(fabs(u) > 1e-15))
        return -1; /* afocal */
    px->efl_mm = -1.0 / u;
    px->bfl_mm = -y / u;
    double yr = 1.0, ur = 0.0;
    ynu_reverse(L, last, 0, &yr, &ur);
    if (!(fabs(ur) > 1e-15))
        return -1;
    px->ffl_mm = -yr / ur;
    px->front_principal_mm = px->efl_mm - px->ffl_mm;
    px->rear_principal_mm = px->bfl_mm - px->efl_mm;
    /* The stop: the radius-0 row, else the surface that limits the axial beam. */
    int s = L->stop;
    if (s < 0) {
        double best = INFINITY;
        y = 1.0, u = 0.0;
        for (int i = 0; i <= last; i++) {
            double ratio = L->s[i].aperture_radius_mm / fabs(y);
            if (ratio < best)
                best = ratio, s = i;
            ynu_forward(L, i, i, &y, &u);
            if (i < last)
                y += L->s[i].thickness_mm * u;
        }
    }
    px->stop = s;
    double a = L->s[s].aperture_radius_mm;
    /* Entrance pupil: the stop seen through the surfaces in front of it,
     * located by the ray from the stop's centre; size from n u / n' u'. */
    if (s == 0) {
        px->entrance_pupil_mm = 0.0;
        px->entrance_pupil_diameter_mm = 2.0 * a;
    } else {
        y = L->s[s - 1].thickness_mm, u = 1.0;
        ynu_reverse(L, s - 1, 0, &y, &u);
        px->entrance_pupil_mm = y / u;
        px->entrance_pupil_diameter_mm = 2.0 * a * fabs(n_before(L, s) / u);
    }
    if (s == last) {
        px->exit_pupil_mm = 0.0;
        px->exit_pupil_diameter_mm = 2.0 * a;
    } else {
        y = L->s[s].thickness_mm, u = 1.0;
        ynu_forward(L, s + 1, last, &y, &u);
        px->exit_pupil_mm = -y / u;
        px->exit_pupil_diameter_mm = 2.0 * a * fabs(n_after(L, s) / u);
    }
    px->fnumber = px->efl_mm / px->entrance_pupil_diameter_mm;
    return 0;
}

static double hiatus(const lf_lens_paraxial *px)
{
    /* H' - H along the light, both measured from the front vertex. */
    return px->total_length_mm + px->rear_principal_mm - px->front_principal_mm;
}

double lf_lens_paraxial_focus_distance(const lf_lens *L, const lf_lens_paraxial *px, double film_distance_mm)
{
    (void)L;
    double f = px->efl_mm, v = film_distance_mm - px->rear_principal_mm;
    if (!(v > f))
        return INFINITY;
    double s = 1.0 / (1.0 / f - 1.0 / v);
    return s + v + hiatus(px);
}

double lf_lens_working_fnumber(const lf_lens *L, const lf_lens_paraxial *px, double focus_distance_mm,
                               double film_distance_mm)
{
    int last = L->n - 1, s = px->stop;
    double y, u;
    if (isinf(focus_distance_mm)) {
        y = 1.0, u = 0.0;
    } else {
        double l = focus_distance_mm - film_distance_mm - px->total_length_mm; /* object to front vertex */
        u = 1.0, y = l;
    }
    /* Height at the stop, then scale the ray to fill it. */
    double ys = y, us = u;
    if (s > 0) {
        ynu_forward(L, 0, s - 1, &ys, &us);
        ys += L->s[s - 1].thickness_mm * us;
    }
    ynu_forward(L, 0, last, &y, &u);
    if (!(fabs(ys) > 0.0) || !(fabs(u) > 0.0))
        return INFINITY;
    double scale = L->s[s].aperture_radius_mm / fabs(ys);
    return 1.0 / (2.0 * fabs(u) * scale);
}

/* --------------------------------------------------------------- focusing */

double lf_lens_closest_focus_mm(const lf_lens_paraxial *px)
{
    return 4.0 * px->efl_mm + hiatus(px);
}

int lf_lens_focus_thick(const lf_lens *L, double D, double *film_distance_mm, lf_error *err)
{
    lf_lens_paraxial px;
    if (lf_lens_paraxial_analyse(L, &px)) {
        return lf_error_set(err, LF_ERR_PARAM, "%s: the lens has no focal power (afocal): it cannot focus", L->path);
    }
    double f = px.efl_mm;
    if (!(f > 0.0)) {
        return lf_error_set(err, LF_ERR_PARAM, "%s: negative focal length %g mm: the lens forms no real image", L->path, f);
    }
    if (isinf(D)) {
        *film_distance_mm = px.bfl_mm;
        return 0;
    }
    /* Thin lens between the principal planes: 1/s + 1/s' = 1/f with
     * s + s' = D - hiatus; the root with the film nearer the lens (pbrt-v4
     * FocusThickLens). */
    double e = D - hiatus(&px), c = e * (e - 4.0 * f);
    if (!(D > 0.0) || !(e > 4.0 * f) || !(c > 0.0)) {
        return lf_error_set(err, LF_ERR_PARAM,
                 "focus distance %g m is closer than %s can focus: the closest is %.4g m from the film "
                 "(unit magnification)",
                 D * 1e-3, L->path, lf_lens_closest_focus_mm(&px) * 1e-3);
    }
    double v = 2.0 * f * e / (e + sqrt(c)); /* the smaller root, without cancellation */
    *film_distance_mm = px.rear_principal_mm + v;
    if (!(*film_distance_mm > 0.0)) {
        return lf_error_set(err, LF_ERR_PARAM, "%s: focusing at %g m would put the film inside the lens (%g mm)", L->path, D * 1e-3,
                 *film_distance_mm);
    }
    return 0;
}

static double spot_rms(const lf_lens *L0, const lf_lens_paraxial *px, double D, double film_d, int *n_pass)
{
    lf_lens L = *L0;
    L.film_distance_mm = film_d;
    L.dispersive = 0;
    double z_front = -(film_d + px->total_length_mm);
    double z_ep = z_front + px->entrance_pupil_mm;
    double r_ep = 0.5 * px->entrance_pupil_diameter_mm;
    double z_start = z_front - L.s[0].aperture_radius_mm - 1.0; /* in front of any rim */
    enum { K = 128 };
    double sw = 0, sy2 = 0;
    *n_pass = 0;
    for (int k = 0; k < K; k++) {
        double h = (k + 0.5) / K * 2.0 * r_ep;
        lf_lens_ray in, out;
        if (isinf(D)) { /* parallel light at height h */
            in = (lf_lens_ray){{0, h, z_start}, {0, 0, 1}};
        } else {
            in = (lf_lens_ray){{0, 0, -D}, {0, h, z_ep + D}};
            double l = sqrt(in.d[1] * in.d[1] + in.d[2] * in.d[2]);
            in.d[1] /= l, in.d[2] /= l;
        }
        if (lf_lens_trace_from_scene(&L, &in, &out, NULL) != LF_LENS_PASSED)
            continue;
        double t = -out.o[2] / out.d[2];
        double yf = out.o[1] + t * out.d[1];
        sw += h, sy2 += h * yf * yf; /* weight: the annulus' area */
        (*n_pass)++;
    }
    return sw > 0 ? sqrt(sy2 / sw) : INFINITY;
}

int lf_lens_focus_search(const lf_lens *L, double D, double *film_distance_mm, lf_error *err)
{
    double d0;
    int rc = lf_lens_focus_thick(L, D, &d0, err);
    if (rc)
        return rc;
    lf_lens_paraxial px;
    lf_lens_paraxial_analyse(L, &px);
    double Dm = D;
    double lo = d0 - 0.05 * px.efl_mm, hi = d0 + 0.05 * px.efl_mm;
    if (lo < 1e-3)
        lo = 1e-3;
    int np;
    if (!isfinite(spot_rms(L, &px, Dm, d0, &np)) || np < 3) {
        return lf_error_set(err, LF_ERR_PARAM, "%s: no real ray from the axial object point at %g m reaches the film", L->path,
                 Dm * 1e-3);
    }
    /* Golden-section search for the smallest RMS spot. */
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double a = lo, b = hi, c = b - g * (b - a), d = a + g * (b - a);
    double fc = spot_rms(L, &px, Dm, c, &np), fd = spot_rms(L, &px, Dm, d, &np);
    for (int it = 0; it < 80 && b - a > 1e-9; it++) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = b - g * (b - a);
            fc = spot_rms(L, &px, Dm, c, &np);
        } else {
            a = c, c = d, fc = fd;
            d = a + g * (b - a);
            fd = spot_rms(L, &px, Dm, d, &np);
        }
    }
    *film_distance_mm = 0.5 * (a + b);
    return 0;
}

/* ---------------------------------------------------------- exact tracing
 *
 * A unit ray o + t d meets the sphere of centre c and radius R where
 * t = -b -+ sqrt(R^2 - q), with b = (o - c).d and q = |(o - c) x d|^2 the
 * squared distance of the centre from the ray's line; at the hit point the
 * angle of incidence has sin^2 = q / R^2 and cos = sqrt(R^2 - q) / |R|.
 * So Snell's law's cos(theta_t) = sqrt(1 - eta^2 q / R^2) needs only q, and
 * the two square roots of a surface run side by side instead of one after
 * the other (a trace is one serial chain through the surfaces: latency is
 * its cost).  The root and the normal's orientation are fixed per surface
 * and direction (the ray's d.z has a known sign, checked after every
 * surface): from the film the nearer root is taken where R < 0 (pbrt:
 * (d.z > 0) xor (R < 0)) and the normal (p - c) / R is flipped to face the
 * ray; from the scene the nearer root where R > 0, the normal as it is. */

typedef struct surf_k {
    int stop;              /* radius 0 */
    double zv;             /* vertex z (lens space) */
    double zc, R, R2, inv_R2, abs_inv_r; /* sphere: centre z, radius, R^2, 1/R^2, 1/|R| */
    double k, sgn;         /* normal facing the ray = (p - c) k; t = -b + sgn sqrt(R^2 - q) */
    double ap, ap2;        /* clear radius, squared */
    double eta, eta2;      /* n_i / n_t at n_d, squared */
    double na, nb;         /* n_d after / before the surface */
    double ca_a, cb_a, ca_b, cb_b; /* their Cauchy A, B (B = 0: not dispersive) */
} surf_k;

/* Surface i's constants for a ray going toward the scene (from_film) or
 * the film: those the intersection needs, then those only refraction needs
 * (the scalar trace computes the second part only for rays that hit). */
static inline void surf_hit_constants(const lf_lens *L, int i, int from_film, surf_k *c)
{
    const lf_lens_surface *s = &L->s[i];
    c->stop = s->radius_mm == 0.0;
    c->zv = s->z_mm - L->film_distance_mm;
    c->ap = s->aperture_radius_mm;
    c->ap2 = c->ap * c->ap;
    double R = s->radius_mm; /* (unused for the stop) */
    c->R = R;
    c->zc = c->zv + R;
    c->R2 = R * R;
    c->sgn = from_film ? copysign(1.0, R) : -copysign(1.0, R);
}

static inline void surf_refract_constants(const lf_lens *L, int i, int from_film, surf_k *c)
{
    const lf_lens_surface *s = &L->s[i];
    double inv_r = 1.0 / c->R;
    c->inv_R2 = inv_r * inv_r;
    c->abs_inv_r = fabs(inv_r);
    c->k = from_film ? -inv_r : inv_r;
    c->na = s->ior, c->nb = i > 0 ? L->s[i - 1].ior : 1.0;
    c->eta = from_film ? c->na / c->nb : c->nb / c->na;
    c->eta2 = c->eta * c->eta;
    c->ca_a = s->cauchy_a, c->cb_a = s->cauchy_b;
    c->ca_b = i > 0 ? L->s[i - 1].cauchy_a : 1.0, c->cb_b = i > 0 ? L->s[i - 1].cauchy_b : 0.0;
}

static inline void surf_constants(const lf_lens *L, int i, int from_film, surf_k *c)
{
    memset(c, 0, sizeof *c);
    surf_hit_constants(L, i, from_film, c);
    if (!c->stop)
        surf_refract_constants(L, i, from_film, c);
}

/* The sphere step, shared by the scalar and the batch paths (the same
 * operations in the same order, so both give the same bits), in two parts.
 * sphere_hit: o moves to the hit point; valid if disc >= 0, t >= 0,
 * side <= 0 (not the sphere's far side) and r2 <= ap^2.  q and sq are kept
 * for sphere_refract. */
static inline __attribute__((always_inline)) void sphere_hit(const surf_k *s, double *ox, double *oy, double *oz,
                                                            double dx, double dy, double dz, double *q_out,
                                                            double *sq_out, double *disc_out, double *t_out,
                                                            double *side_out, double *r2_out)
{
    const double x = *ox, y = *oy, zo = *oz - s->zc;
    double cx = y * dz - zo * dy, cy = zo * dx - x * dz, cz = x * dy - y * dx;
    double q = cx * cx + cy * cy + cz * cz;
    double b = x * dx + y * dy + zo * dz;
    double disc = s->R2 - q;
    double sq = sqrt(disc);
    double t = -b + s->sgn * sq;
    double px = x + t * dx, py = y + t * dy, pz = *oz + t * dz;
    *ox = px, *oy = py, *oz = pz;
    *q_out = q, *sq_out = sq, *disc_out = disc, *t_out = t, *side_out = (pz - s->zc) * s->R;
    *r2_out = px * px + py * py;
}

/* sphere_refract: d becomes the refracted direction at the hit point p;
 * valid if sin2_t < 1 (no total internal reflection). */
static inline __attribute__((always_inline)) void sphere_refract(const surf_k *s, double eta, double eta2, double q,
                                                                double sq, double px, double py, double pz,
                                                                double *dx, double *dy, double *dz,
                                                                double *sin2_t_out)
{
    double sin2_t = eta2 * (q * s->inv_R2);
    double cos_t = sqrt(1.0 - sin2_t);
    double g = eta * (sq * s->abs_inv_r) - cos_t; /* eta cos(theta_i) - cos(theta_t) */
    double k = s->k;
    *dx = eta * *dx + g * (px * k);
    *dy = eta * *dy + g * (py * k);
    *dz = eta * *dz + g * ((pz - s->zc) * k);
    *sin2_t_out = sin2_t;
}

/* eta at wavelength 1 / sqrt(inv_l2) um (ior_at() of both media). */
static inline double surf_eta(const surf_k *s, double inv_l2, int from_film)
{
    double na = inv_l2 > 0.0 && s->cb_a != 0.0 ? s->ca_a + s->cb_a * inv_l2 : s->na;
    double nb = inv_l2 > 0.0 && s->cb_b != 0.0 ? s->ca_b + s->cb_b * inv_l2 : s->nb;
    return from_film ? na / nb : nb / na;
}

static lf_lens_status trace(const lf_lens *L, const lf_lens_ray *in, lf_lens_ray *out, lf_lens_trace_opts *opts,
                            int from_film)
{
    double o[3] = {in->o[0], in->o[1], in->o[2]}, d[3] = {in->d[0], in->d[1], in->d[2]};
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double inv_l2 = opts ? inv_lambda2(L, opts->lambda_nm) : 0.0;
    if (opts) {
        opts->path_count = 0;
        opts->transmission = 1.0;
    }
    if (!(dl > 0.0) || !isfinite(dl))
        return LF_LENS_BACKWARDS;
    double inv_dl = 1.0 / dl;
    d[0] *= inv_dl, d[1] *= inv_dl, d[2] *= inv_dl;
    const double dir = from_film ? -1.0 : 1.0; /* sign of d.z the system needs */
    if (!(d[2] * dir > 0.0))
        return LF_LENS_BACKWARDS;
    int n = L->n;
    for (int k = 0; k < n; k++) {
        int i = from_film ? n - 1 - k : k;
        surf_k c;
        surf_hit_constants(L, i, from_film, &c);
        if (c.stop) {
            double t = (c.zv - o[2]) / d[2];
            if (!(t >= 0.0))
                return LF_LENS_MISSED;
            o[0] = o[0] + t * d[0], o[1] = o[1] + t * d[1], o[2] = c.zv;
            double r2 = o[0] * o[0] + o[1] * o[1];
            if (r2 > c.ap2)
                return LF_LENS_STOPPED;
            if (opts && opts->stop_shape) {
                double tr = opts->stop_shape(opts->stop_ctx, o[0] / c.ap, o[1] / c.ap);
                if (!(tr > 0.0))
                    return LF_LENS_STOPPED;
                opts->transmission = tr;
            }
        } else {
            double q, sq, disc, t, side, r2, sin2_t;
            sphere_hit(&c, &o[0], &o[1], &o[2], d[0], d[1], d[2], &q, &sq, &disc, &t, &side, &r2);
            if (!(disc >= 0.0) || !(t >= 0.0) || side > 0.0)
                return LF_LENS_MISSED;
            if (r2 > c.ap2)
                return LF_LENS_CLIPPED;
            surf_refract_constants(L, i, from_film, &c);
            double eta = c.eta, eta2 = c.eta2;
            if (inv_l2 > 0.0)
                eta = surf_eta(&c, inv_l2, from_film), eta2 = eta * eta;
            sphere_refract(&c, eta, eta2, q, sq, o[0], o[1], o[2], &d[0], &d[1], &d[2], &sin2_t);
            if (sin2_t >= 1.0)
                return LF_LENS_TIR;
            /* d is unit length by construction; renormalised at the end */
            if (!(d[2] * dir > 0.0))
                return LF_LENS_BACKWARDS;
        }
        if (opts && opts->path) {
            memcpy(opts->path[opts->path_count], o, sizeof o);
            opts->path_count++;
        }
    }
    if (out) {
        inv_dl = 1.0 / sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        d[0] *= inv_dl, d[1] *= inv_dl, d[2] *= inv_dl;
        memcpy(out->o, o, sizeof o);
        memcpy(out->d, d, sizeof d);
    }
    return LF_LENS_PASSED;
}

lf_lens_status lf_lens_trace_from_film(const lf_lens *L, const lf_lens_ray *in, lf_lens_ray *out,
                                       lf_lens_trace_opts *opts)
{
    return trace(L, in, out, opts, 1);
}

lf_lens_status lf_lens_trace_from_scene(const lf_lens *L, const lf_lens_ray *in, lf_lens_ray *out,
                                        lf_lens_trace_opts *opts)
{
    return trace(L, in, out, opts, 0);
}

/* ----------------------------------------------------- exit-pupil bounds */

double lf_lens_rear_disk_radius(const lf_lens *L, double film_radius_mm)
{
    const lf_lens_surface *r = &L->s[L->n - 1];
    double R = r->aperture_radius_mm, sag = 0.0;
    if (r->radius_mm != 0.0)
        sag = fabs(r->radius_mm) - sqrt(r->radius_mm * r->radius_mm - R * R);
    double Z = L->film_distance_mm;
    double zmin = Z - sag > 1e-6 ? Z - sag : 1e-6;
    /* A ray through the rear surface inside R crosses the vertex plane at
     * most sag * tan(theta) further out, tan(theta) <= (r_film + R) / zmin. */
    return (R + sag * (film_radius_mm + R) / zmin) * 1.001 + 1e-6;
}

typedef struct pupil_ctx {
    const lf_lens *L;
    double fx;     /* film point (fx, 0, 0) */
    double Z;      /* rear plane at z = -Z */
    const double *lambda;
    int n_lambda;
    long long traces;
} pupil_ctx;

static int passes(pupil_ctx *c, double x, double y)
{
    lf_lens_ray in = {{c->fx, 0, 0}, {x - c->fx, y, -c->Z}};
    for (int k = 0; k < c->n_lambda; k++) {
        lf_lens_trace_opts o = {0};
        o.lambda_nm = c->lambda[k];
        c->traces++;
        if (trace(c->L, &in, NULL, &o, 1) == LF_LENS_PASSED)
            return 1;
    }
    return 0;
}

enum { BISECT = 16 };

/* Edge between a passing and a failing coordinate along x (on the line y =
 * other) or along y (on the line x = other). */
static double bisect_edge(pupil_ctx *c, int along_y, double other, double pass, double fail)
{
    for (int i = 0; i < BISECT; i++) {
        double m = 0.5 * (pass + fail);
        if (along_y ? passes(c, other, m) : passes(c, m, other))
            pass = m;
        else
            fail = m;
    }
    return pass;
}
static double bisect_x(pupil_ctx *c, double y, double x_pass, double x_fail) { return bisect_edge(c, 0, y, x_pass, x_fail); }
static double bisect_y(pupil_ctx *c, double x, double y_pass, double y_fail) { return bisect_edge(c, 1, x, y_pass, y_fail); }

/* Stack room for the chief-ray search; longer prescriptions skip it. */
#define LF_LENS_MAX_SURFACES 64

/* Where a meridional ray from the film point, aimed at rear-plane x, crosses
 * the stop plane (traced with the stop opened to its full clear radius);
 * 0 if it does not get that far. */
static int stop_crossing(pupil_ctx *c, const lf_lens *open, double x, double *h)
{
    double path[LF_LENS_MAX_SURFACES + 1][3];
    lf_lens_ray in = {{c->fx, 0, 0}, {x - c->fx, 0, -c->Z}};
    lf_lens_trace_opts o = {0};
    o.lambda_nm = c->n_lambda ? c->lambda[0] : 0.0;
    o.path = path;
    c->traces++;
    trace(open, &in, NULL, &o, 1);
    int k = open->n - 1 - open->stop; /* surfaces are met rear first */
    if (o.path_count <= k)
        return 0;
    *h = path[k][0];
    return 1;
}

/* The rear-plane x of the chief ray (through the stop centre) by scan and
 * bisection of the stop crossing; 0 if there is none. */
static int chief_ray_x(pupil_ctx *c, double rs, double *x_out)
{
    const lf_lens *L = c->L;
    if (L->stop < 0 || L->n > LF_LENS_MAX_SURFACES)
        return 0;
    lf_lens_surface surf[LF_LENS_MAX_SURFACES];
    memcpy(surf, L->s, sizeof(lf_lens_surface) * (size_t)L->n);
    double full = L->stop_max_radius_mm > surf[L->stop].aperture_radius_mm ? L->stop_max_radius_mm
                                                                           : surf[L->stop].aperture_radius_mm;
    surf[L->stop].aperture_radius_mm = full > 0 ? full : 1e9;
    lf_lens open = *L;
    open.s = surf;
    enum { M = 96 };
    double step = 2.0 * rs / (M - 1), prev_x = 0, prev_h = 0;
    int have_prev = 0;
    for (int i = 0; i < M; i++) {
        double x = -rs + i * step, h;
        if (!stop_crossing(c, &open, x, &h)) {
            have_prev = 0;
            continue;
        }
        if (have_prev && (prev_h <= 0) != (h <= 0)) {
            double a = prev_x, b = x, ha = prev_h;
            for (int it = 0; it < 60; it++) {
                double m = 0.5 * (a + b), hm;
                if (!stop_crossing(c, &open, m, &hm))
                    break;
                if ((ha <= 0) == (hm <= 0))
                    a = m, ha = hm;
                else
                    b = m;
            }
            *x_out = 0.5 * (a + b);
            return 1;
        }
        prev_x = x, prev_h = h, have_prev = 1;
    }
    return 0;
}

/* The passing interval on the meridional line y = 0; 0 if none. */
static int meridional_interval(pupil_ctx *c, double rs, double *xlo, double *xhi)
{
    enum { M = 96 };
    int first = -1, last = -1;
    double step = 2.0 * rs / (M - 1);
    for (int i = 0; i < M; i++)
        if (passes(c, -rs + i * step, 0.0)) {
            if (first < 0)
                first = i;
            last = i;
        }
    if (first < 0) {
        /* A stop much smaller than the scan step (f/1000 and beyond) lets
         * light through a sliver the grid misses: find the chief ray, the
         * one through the stop's centre, and start from it. */
        double xc;
        if (!chief_ray_x(c, rs, &xc) || !passes(c, xc, 0.0))
            return 0;
        double lo = xc, hi = xc, w = 1e-9 * rs;
        while (lo - w > -rs && passes(c, lo - w, 0.0))
            lo -= w, w *= 2;
        while (hi + w < rs && passes(c, hi + w, 0.0))
            hi += w, w *= 2;
        *xlo = bisect_x(c, 0.0, lo, lo - w > -rs ? lo - w : -rs);
        *xhi = bisect_x(c, 0.0, hi, hi + w < rs ? hi + w : rs);
        return 1;
    }
    *xlo = first > 0 ? bisect_x(c, 0.0, -rs + first * step, -rs + (first - 1) * step) : -rs;
    *xhi = last < M - 1 ? bisect_x(c, 0.0, -rs + last * step, -rs + (last + 1) * step) : rs;
    return 1;
}

typedef struct film_region {
    int lit;
    double xlo0, xhi0; /* interval on y = 0 */
    double y_max, x_top; /* highest passing point */
} film_region;

/* The region of the rear plane lit from film point (fx, 0): on the
 * mirror-symmetric, (nearly) convex region every horizontal line meets an
 * interval that shrinks away from y = 0, so its outline follows from the
 * y = 0 interval and the top edge h(x). */
static void film_region_find(pupil_ctx *c, double rs, film_region *fr)
{
    memset(fr, 0, sizeof *fr);
    if (!meridional_interval(c, rs, &fr->xlo0, &fr->xhi0))
        return;
    fr->lit = 1;
    enum { K = 16 };
    double w = fr->xhi0 - fr->xlo0, best = -1.0, bx = 0.5 * (fr->xlo0 + fr->xhi0);
    int bk = 0;
    for (int k = 0; k < K; k++) {
        double x = fr->xlo0 + (k + 0.5) / K * w;
        if (!passes(c, x, 0.0))
            continue;
        double h = bisect_y(c, x, 0.0, rs);
        if (h > best)
            best = h, bx = x, bk = k;
    }
    if (best < 0.0) {
        fr->y_max = 0.0, fr->x_top = bx;
        return;
    }
    /* Golden-section refinement of the top around the best column. */
    double a = fr->xlo0 + (bk - 0.5) / K * w, b = fr->xlo0 + (bk + 1.5) / K * w;
    if (a < fr->xlo0)
        a = fr->xlo0;
    if (b > fr->xhi0)
        b = fr->xhi0;
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    double h1 = passes(c, x1, 0) ? bisect_y(c, x1, 0.0, rs) : 0.0;
    double h2 = passes(c, x2, 0) ? bisect_y(c, x2, 0.0, rs) : 0.0;
    for (int it = 0; it < 10; it++) {
        if (h1 > h2) {
            b = x2, x2 = x1, h2 = h1;
            x1 = b - g * (b - a);
            h1 = passes(c, x1, 0) ? bisect_y(c, x1, 0.0, rs) : 0.0;
        } else {
            a = x1, x1 = x2, h1 = h2;
            x2 = a + g * (b - a);
            h2 = passes(c, x2, 0) ? bisect_y(c, x2, 0.0, rs) : 0.0;
        }
        if (h1 > best)
            best = h1, bx = x1;
        if (h2 > best)
            best = h2, bx = x2;
    }
    fr->y_max = best, fr->x_top = bx;
}

int lf_lens_pupil_build(const lf_lens *L, double film_radius_mm, int lambda_spread, lf_lens_pupil *P)
{
    memset(P, 0, sizeof *P);
    P->film_radius_mm = film_radius_mm;
    P->n_bins = LF_LENS_PUPIL_BINS;
    P->bins_per_mm = P->n_bins / film_radius_mm;
    P->rear_disk_radius_mm = lf_lens_rear_disk_radius(L, film_radius_mm);
    if (lambda_spread && L->dispersive) {
        P->lambda_nm[0] = 360.0, P->lambda_nm[1] = 0.0, P->lambda_nm[2] = 830.0;
        P->n_lambda = 3;
    } else {
        P->lambda_nm[0] = 0.0;
        P->n_lambda = 1;
    }
    double rs = P->rear_disk_radius_mm;
    pupil_ctx c = {L, 0.0, L->film_distance_mm, P->lambda_nm, P->n_lambda, 0};
    enum { NR = 3 }; /* film radii per bin: both ends and the middle */
    film_region prev_end;
    int have_prev = 0, lit_bins = 0;
    const double margin = 2e-3 * rs;
    for (int b = 0; b < P->n_bins; b++) {
        lf_lens_pupil_bin *bin = &P->bin[b];
        memset(bin, 0, sizeof *bin);
        double r0 = (double)b / P->n_bins * film_radius_mm, r1 = (double)(b + 1) / P->n_bins * film_radius_mm;
        film_region fr[NR];
        double fx[NR];
        for (int k = 0; k < NR; k++) {
            fx[k] = r0 + (r1 - r0) * k / (NR - 1);
            if (k == 0 && have_prev) {
                fr[0] = prev_end;
                continue;
            }
            c.fx = fx[k];
            film_region_find(&c, rs, &fr[k]);
        }
        prev_end = fr[NR - 1];
        have_prev = 1;
        double ymax = 0.0;
        int lit = 0;
        for (int k = 0; k < NR; k++)
            if (fr[k].lit) {
                lit = 1;
                if (fr[k].y_max > ymax)
                    ymax = fr[k].y_max;
            }
        if (!lit)
            continue;
        ymax = ymax * 1.002 + margin;
        double h = ymax / LF_LENS_PUPIL_STRIPS;
        for (int j = 0; j < LF_LENS_PUPIL_STRIPS; j++)
            bin->xlo[j] = INFINITY, bin->xhi[j] = -INFINITY;
        for (int k = 0; k < NR; k++) {
            if (!fr[k].lit)
                continue;
            c.fx = fx[k];
            for (int j = 0; j < LF_LENS_PUPIL_STRIPS; j++) {
                double y = j * h; /* the strip's edge nearest the axis holds its widest line */
                double lo, hi;
                if (j == 0) {
                    lo = fr[k].xlo0, hi = fr[k].xhi0;
                } else {
                    if (y > fr[k].y_max)
                        break;
                    double seed = fr[k].x_top;
                    if (!passes(&c, seed, y)) {
                        /* not quite convex: fall back to a scan of the line */
                        int found = 0;
                        for (int q = 0; q < 32 && !found; q++) {
                            double x = fr[k].xlo0 + (q + 0.5) / 32 * (fr[k].xhi0 - fr[k].xlo0);
                            if (passes(&c, x, y))
                                seed = x, found = 1;
                        }
                        if (!found)
                            continue;
                    }
                    lo = bisect_x(&c, y, seed, fr[k].xlo0 - 1e-9);
                    hi = bisect_x(&c, y, seed, fr[k].xhi0 + 1e-9);
                }
                if (lo < bin->xlo[j])
                    bin->xlo[j] = lo;
                if (hi > bin->xhi[j])
                    bin->xhi[j] = hi;
            }
        }
        /* The strip above the last computed line inherits it (convexity). */
        double area = 0.0;
        bin->cdf[0] = 0.0;
        for (int j = 0; j < LF_LENS_PUPIL_STRIPS; j++) {
            if (bin->xhi[j] >= bin->xlo[j]) {
                bin->xlo[j] -= margin, bin->xhi[j] += margin;
            } else {
                bin->xlo[j] = bin->xhi[j] = 0.0;
            }
            area += (bin->xhi[j] - bin->xlo[j]) * h;
            bin->cdf[j + 1] = area;
        }
        if (!(area > 0.0))
            continue;
        for (int j = 1; j <= LF_LENS_PUPIL_STRIPS; j++)
            bin->cdf[j] /= area;
        bin->y_max = ymax;
        bin->area = 2.0 * area;
        bin->pdf = 1.0 / bin->area;
        lit_bins++;
    }
    P->traces = c.traces;
    return lit_bins;
}

/* lf_lens_pupil_sample in stages, shared with lf_lens_sample_rays (which
 * runs each stage over a chunk of rays: the first and last vectorise, the
 * middle one reads the bins).
 * Stage 1: the film point's bin (by its distance r from the axis; the
 * clamp comes before the conversion, so no value of r overflows it) and the
 * rotation (cs, sn) of (r, 0) onto the film point; v picks the half of the
 * bound (sign: +1 for y >= 0) and is rescaled to [0, 1) within it. */
static inline int pupil_stage1(const lf_lens_pupil *P, double fx, double fy, double v, double *cs, double *sn,
                               double *v_half, double *sign)
{
    double r = sqrt(fx * fx + fy * fy), fb = r * P->bins_per_mm, top = P->n_bins - 1;
    fb = fb >= top ? top : fb > 0.0 ? fb : 0.0;
    double inv_r = 1.0 / r;
    *cs = r > 0.0 ? fx * inv_r : 1.0;
    *sn = r > 0.0 ? fy * inv_r : 0.0;
    v *= 2.0;
    double lower = v >= 1.0;
    *v_half = v - lower;
    *sign = 1.0 - 2.0 * lower;
    return (int)fb;
}

/* Stage 2: the strip, the last j < LF_LENS_PUPIL_STRIPS with cdf[j] <= v
 * (cdf is non-decreasing from cdf[0] = 0), by branch-free bisection. */
static inline int pupil_stage2(const lf_lens_pupil_bin *bin, double v)
{
    _Static_assert(LF_LENS_PUPIL_STRIPS == 16, "the bisection below has 4 steps");
    int j = v >= bin->cdf[8] ? 8 : 0;
    j += v >= bin->cdf[j + 4] ? 4 : 0;
    j += v >= bin->cdf[j + 2] ? 2 : 0;
    j += v >= bin->cdf[j + 1] ? 1 : 0;
    return j;
}

/* Stage 3: the point of strip j (its cdf values c0, c1 and x extent) at
 * height v in it and u across, rotated to the film point's angle. */
static inline void pupil_stage3(double c0, double c1, double xlo, double xhi, double y_max, double j, double u,
                                double v, double sign, double cs, double sn, double *rx, double *ry)
{
    double span = c1 - c0, tq = (v - c0) / span;
    double t = span > 0.0 ? tq : 0.5;
    t = t < 0.0 ? 0.0 : t;
    t = t > 1.0 ? 1.0 : t;
    double h = y_max * (1.0 / LF_LENS_PUPIL_STRIPS);
    double x = xlo + u * (xhi - xlo);
    double y = sign * (j + t) * h;
    *rx = cs * x - sn * y;
    *ry = sn * x + cs * y;
}

double lf_lens_pupil_sample(const lf_lens_pupil *P, double film_x, double film_y, double u, double v, double *rx,
                            double *ry)
{
    double cs, sn, vh, sign;
    const lf_lens_pupil_bin *bin = &P->bin[pupil_stage1(P, film_x, film_y, v, &cs, &sn, &vh, &sign)];
    if (!(bin->area > 0.0))
        return 0.0;
    int j = pupil_stage2(bin, vh);
    pupil_stage3(bin->cdf[j], bin->cdf[j + 1], bin->xlo[j], bin->xhi[j], bin->y_max, j, u, vh, sign, cs, sn, rx, ry);
    return bin->pdf;
}

int lf_lens_pupil_contains(const lf_lens_pupil *P, double film_x, double film_y, double rx, double ry)
{
    double cs, sn, vh, sign;
    const lf_lens_pupil_bin *bin = &P->bin[pupil_stage1(P, film_x, film_y, 0.0, &cs, &sn, &vh, &sign)];
    if (!(bin->area > 0.0))
        return 0;
    double x = cs * rx + sn * ry, y = fabs(-sn * rx + cs * ry); /* rotate back to the film point (r, 0) */
    if (!(y <= bin->y_max))
        return 0;
    int j = (int)(y / (bin->y_max / LF_LENS_PUPIL_STRIPS));
    if (j >= LF_LENS_PUPIL_STRIPS)
        j = LF_LENS_PUPIL_STRIPS - 1;
    return x >= bin->xlo[j] && x <= bin->xhi[j];
}

/* The rear-plane point a camera ray is aimed at and its pdf (per mm^2); 0:
 * the film point gets no light.  Shared by the scalar and batch paths. */
static inline double rear_point(const lf_lens_pupil *P, int use_bounds, double fx, double fy, double u, double v,
                                double *rx, double *ry)
{
    if (use_bounds)
        return lf_lens_pupil_sample(P, fx, fy, u, v, rx, ry);
    double R = P->rear_disk_radius_mm;
    lf_concentric_disk(u, v, rx, ry);
    *rx *= R, *ry *= R;
    return 1.0 / (M_PI * R * R);
}

double lf_lens_sample_ray(const lf_lens *L, const lf_lens_pupil *P, int use_bounds, double fx, double fy, double u,
                          double v, lf_lens_trace_opts *opts, lf_lens_ray *out)
{
    double rx, ry, pdf = rear_point(P, use_bounds, fx, fy, u, v, &rx, &ry);
    if (!(pdf > 0.0))
        return 0.0;
    double Z = L->film_distance_mm;
    lf_lens_ray in = {{fx, fy, 0.0}, {rx - fx, ry - fy, -Z}};
    double l = sqrt(in.d[0] * in.d[0] + in.d[1] * in.d[1] + Z * Z);
    double cos_t = Z * (1.0 / l);
    lf_lens_trace_opts local = {0};
    if (!opts)
        opts = &local;
    if (trace(L, &in, out, opts, 1) != LF_LENS_PASSED)
        return 0.0;
    double c2 = cos_t * cos_t;
    double w = opts->transmission * c2 * c2 / (pdf * Z * Z);
    return isfinite(w) && w > 0.0 ? w : 0.0;
}

/* --------------------------------------------------------- batched camera rays
 *
 * lf_lens_sample_rays: the computation of lf_lens_sample_ray, operation for
 * operation, for chunks of LANES rays in structure-of-arrays form, every
 * ray of a chunk taken through surface k before surface k + 1.  One ray's
 * trace is a serial chain (per sphere: a cross product, a square root, the
 * hit point, the refracted direction, on to the next sphere), so the scalar
 * path mostly waits on latencies; the rays of a chunk are independent, the
 * lane loops are branch-free (everything computed, then the ray's alive flag
 * cleared where a test fails; failed rays carry garbage to the end of the
 * chunk) and GCC vectorises them: AVX2 (4 doubles) where the CPU has it,
 * SSE2 (2) otherwise.  No FMA contraction (ISO C mode), so the results are
 * bit-identical to the scalar path's.  A chunk stops early once no ray is
 * alive. */
enum { LANES = 32 };

typedef struct batch_chunk {
    double ox[LANES], oy[LANES], oz[LANES];
    double dx[LANES], dy[LANES], dz[LANES];
    double il2[LANES];   /* 1 / lambda_um^2, 0 for n_d */
    double tr[LANES];    /* stop-shape transmission */
    union {
        double alive[LANES];      /* 1: still traced, 0: blocked (a double: SSE2 selects it in the lane loops) */
        uint64_t alive_bits[LANES]; /* the same, for a vectorisable "any alive?" */
    };
} batch_chunk;

static int batch_generic_only;

void lf_lens_batch_force_generic(int on)
{
    batch_generic_only = on;
}

/* The AVX2 kernel: x86 with GCC or Clang (function-level target attributes;
 * the CPU is asked at run time, so the binary still runs on any x86-64). */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define LF_LENS_AVX2_KERNEL 1
#endif

int lf_lens_batch_uses_avx2(void)
{
#ifdef LF_LENS_AVX2_KERNEL
    return !batch_generic_only && __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

/* A chunk through sphere s: eta (n_i / n_t) per lane, or eta[0] for all. */
static inline __attribute__((always_inline)) void sphere_lanes(const surf_k *s, const double *eta,
                                                              const double *eta2, const int per_lane, batch_chunk *c)
{
    const surf_k sk = *s; /* a local copy: the lane stores below cannot alias it */
    const double e0 = eta[0], e20 = eta2[0];
    for (int j = 0; j < LANES; j++) {
        double ox = c->ox[j], oy = c->oy[j], oz = c->oz[j], dx = c->dx[j], dy = c->dy[j], dz = c->dz[j];
        double q, sq, disc, t, side, r2, sin2_t;
        sphere_hit(&sk, &ox, &oy, &oz, dx, dy, dz, &q, &sq, &disc, &t, &side, &r2);
        sphere_refract(&sk, per_lane ? eta[j] : e0, per_lane ? eta2[j] : e20, q, sq, ox, oy, oz, &dx, &dy, &dz,
                       &sin2_t);
        int ok = (disc >= 0.0) & (t >= 0.0) & !(side > 0.0) & !(r2 > sk.ap2) & !(sin2_t >= 1.0) & (dz * -1.0 > 0.0);
        c->alive[j] = ok ? c->alive[j] : 0.0;
        c->ox[j] = ox, c->oy[j] = oy, c->oz[j] = oz;
        c->dx[j] = dx, c->dy[j] = dy, c->dz[j] = dz;
    }
}

/* One chunk through all surfaces (S in trace order, rear first). */
static inline __attribute__((always_inline)) void batch_trace_body(const surf_k *S, int ns, int dispersive,
                                                                  lf_lens_stop_shape shape, const void *ctx,
                                                                  batch_chunk *c)
{
    for (int k = 0; k < ns; k++) {
        const surf_k *s = &S[k];
        if (s->stop) {
            const double zv = s->zv, ap2 = s->ap2;
            for (int j = 0; j < LANES; j++) {
                double t = (zv - c->oz[j]) / c->dz[j];
                double px = c->ox[j] + t * c->dx[j], py = c->oy[j] + t * c->dy[j];
                double r2 = px * px + py * py;
                int ok = (t >= 0.0) & !(r2 > ap2);
                c->alive[j] = ok ? c->alive[j] : 0.0;
                c->ox[j] = px, c->oy[j] = py, c->oz[j] = zv;
            }
            if (shape)
                for (int j = 0; j < LANES; j++)
                    if (c->alive[j] != 0.0) {
                        double tr = shape(ctx, c->ox[j] / s->ap, c->oy[j] / s->ap);
                        if (!(tr > 0.0))
                            c->alive[j] = 0.0;
                        c->tr[j] = tr;
                    }
        } else if (dispersive) {
            /* surf_eta() without branches */
            const double ca_a = s->ca_a, cb_a = s->cb_a, na_d = s->na, ca_b = s->ca_b, cb_b = s->cb_b, nb_d = s->nb;
            const int da = cb_a != 0.0, db = cb_b != 0.0;
            double eta[LANES], eta2[LANES];
            for (int j = 0; j < LANES; j++) {
                double l2 = c->il2[j];
                int lit = l2 > 0.0;
                double na_l = ca_a + cb_a * l2, nb_l = ca_b + cb_b * l2;
                double na = lit & da ? na_l : na_d;
                double nb = lit & db ? nb_l : nb_d;
                double e = na / nb;
                eta[j] = e, eta2[j] = e * e;
            }
            sphere_lanes(s, eta, eta2, 1, c);
        } else {
            sphere_lanes(s, &s->eta, &s->eta2, 0, c);
        }
        uint64_t any = 0;
        for (int j = 0; j < LANES; j++)
            any |= c->alive_bits[j];
        if (!any)
            break;
    }
}

typedef struct batch_args {
    const lf_lens *L;
    const lf_lens_pupil *P;
    const surf_k *S; /* L's surfaces in trace order */
    int use_bounds, n;
    const double *film_x, *film_y, *u, *v, *lambda_nm;
    lf_lens_stop_shape stop_shape;
    const void *stop_ctx;
    lf_lens_ray *out;
    double *weights;
    const lf_lens_ray *in; /* lf_lens_trace_rays_from_film: these rays instead of samples */
    unsigned char *passed;
} batch_args;

/* lf_lens_sample_rays' work, chunk by chunk.  always_inline: compiled once
 * per target, in the two callers below (so the pupil sampling and the
 * prologue and epilogue loops vectorise with AVX2 too). */
static inline __attribute__((always_inline)) void batch_rays_body(const batch_args *a)
{
    const lf_lens *L = a->L;
    const lf_lens_pupil *P = a->P;
    const double Z = L->film_distance_mm;
    for (int i0 = 0; i0 < a->n; i0 += LANES) {
        int m = a->n - i0 < LANES ? a->n - i0 : LANES;
        batch_chunk c;
        double pdf[LANES], rx[LANES], ry[LANES], cos_t[LANES], ul[LANES], vl[LANES];
        int dispersive = 0;
        if (a->in) {
            /* lf_lens_trace_rays_from_film: trace()'s prologue for the given rays */
            for (int j = 0; j < LANES; j++) {
                const lf_lens_ray *r = &a->in[i0 + (j < m ? j : 0)];
                double dx = r->d[0], dy = r->d[1], dz = r->d[2];
                c.ox[j] = r->o[0], c.oy[j] = r->o[1], c.oz[j] = r->o[2];
                c.dx[j] = dx, c.dy[j] = dy, c.dz[j] = dz;
            }
            for (int j = 0; j < LANES; j++) {
                double dx = c.dx[j], dy = c.dy[j], dz = c.dz[j];
                double dl = sqrt(dx * dx + dy * dy + dz * dz), inv_dl = 1.0 / dl;
                dx *= inv_dl, dy *= inv_dl, dz *= inv_dl;
                int ok = (j < m) & (dl > 0.0) & (dl <= DBL_MAX) & (dz * -1.0 > 0.0);
                c.alive[j] = ok ? 1.0 : 0.0;
                c.dx[j] = dx, c.dy[j] = dy, c.dz[j] = dz;
                c.il2[j] = 0.0, c.tr[j] = 1.0;
            }
            batch_trace_body(a->S, L->n, 0, NULL, NULL, &c);
            for (int j = 0; j < LANES; j++) {
                double dx = c.dx[j], dy = c.dy[j], dz = c.dz[j];
                double inv_dl = 1.0 / sqrt(dx * dx + dy * dy + dz * dz);
                c.dx[j] = dx * inv_dl, c.dy[j] = dy * inv_dl, c.dz[j] = dz * inv_dl;
            }
            for (int j = 0; j < m; j++) {
                int i = i0 + j;
                a->passed[i] = c.alive[j] != 0.0;
                if (c.alive[j] != 0.0) {
                    lf_lens_ray *o = &a->out[i];
                    o->o[0] = c.ox[j], o->o[1] = c.oy[j], o->o[2] = c.oz[j];
                    o->d[0] = c.dx[j], o->d[1] = c.dy[j], o->d[2] = c.dz[j];
                }
            }
            continue;
        }
        for (int j = 0; j < m; j++) {
            int i = i0 + j;
            c.ox[j] = a->film_x[i], c.oy[j] = a->film_y[i], ul[j] = a->u[i], vl[j] = a->v[i];
            c.il2[j] = a->lambda_nm ? inv_lambda2(L, a->lambda_nm[i]) : 0.0;
            dispersive |= c.il2[j] > 0.0;
        }
        for (int j = m; j < LANES; j++) /* padding */
            c.ox[j] = c.oy[j] = ul[j] = vl[j] = c.il2[j] = 0.0;
        /* The rear-plane points: rear_point(), the pupil bound in stages. */
        if (a->use_bounds) {
            double cs[LANES], sn[LANES], vh[LANES], sign[LANES], c0[LANES], c1[LANES], xlo[LANES], xhi[LANES],
                y_max[LANES], jd[LANES];
            int b[LANES];
            for (int j = 0; j < LANES; j++)
                b[j] = pupil_stage1(P, c.ox[j], c.oy[j], vl[j], &cs[j], &sn[j], &vh[j], &sign[j]);
            for (int j = 0; j < LANES; j++) {
                const lf_lens_pupil_bin *bin = &P->bin[b[j]];
                int k = pupil_stage2(bin, vh[j]);
                c0[j] = bin->cdf[k], c1[j] = bin->cdf[k + 1], xlo[j] = bin->xlo[k], xhi[j] = bin->xhi[k];
                y_max[j] = bin->y_max, jd[j] = k;
                pdf[j] = bin->area > 0.0 && j < m ? bin->pdf : 0.0;
            }
            for (int j = 0; j < LANES; j++)
                pupil_stage3(c0[j], c1[j], xlo[j], xhi[j], y_max[j], jd[j], ul[j], vh[j], sign[j], cs[j], sn[j],
                             &rx[j], &ry[j]);
        } else {
            for (int j = 0; j < LANES; j++) {
                rx[j] = ry[j] = 0.0;
                pdf[j] = j < m ? rear_point(P, 0, c.ox[j], c.oy[j], ul[j], vl[j], &rx[j], &ry[j]) : 0.0;
            }
        }
        /* lf_lens_sample_ray's and trace()'s prologue */
        for (int j = 0; j < LANES; j++) {
            double dx = rx[j] - c.ox[j], dy = ry[j] - c.oy[j], dz = -Z;
            double dl = sqrt(dx * dx + dy * dy + dz * dz), inv_dl = 1.0 / dl;
            cos_t[j] = Z * inv_dl;
            dx *= inv_dl, dy *= inv_dl, dz *= inv_dl;
            int ok = (pdf[j] > 0.0) & (dl > 0.0) & (dl <= DBL_MAX) & (dz * -1.0 > 0.0);
            c.alive[j] = ok ? 1.0 : 0.0;
            c.oz[j] = 0.0;
            c.dx[j] = dx, c.dy[j] = dy, c.dz[j] = dz;
            c.tr[j] = 1.0;
        }
        batch_trace_body(a->S, L->n, dispersive, a->stop_shape, a->stop_ctx, &c);
        /* trace()'s and lf_lens_sample_ray's epilogue */
        double w[LANES];
        for (int j = 0; j < LANES; j++) {
            double dx = c.dx[j], dy = c.dy[j], dz = c.dz[j];
            double inv_dl = 1.0 / sqrt(dx * dx + dy * dy + dz * dz);
            c.dx[j] = dx * inv_dl, c.dy[j] = dy * inv_dl, c.dz[j] = dz * inv_dl;
            double c2 = cos_t[j] * cos_t[j];
            double wj = c.tr[j] * c2 * c2 / (pdf[j] * Z * Z);
            int ok = (c.alive[j] != 0.0) & (wj > 0.0) & (wj <= DBL_MAX);
            w[j] = ok ? wj : 0.0;
        }
        for (int j = 0; j < m; j++) {
            int i = i0 + j;
            a->weights[i] = w[j];
            if (c.alive[j] != 0.0) {
                lf_lens_ray *o = &a->out[i];
                o->o[0] = c.ox[j], o->o[1] = c.oy[j], o->o[2] = c.oz[j];
                o->d[0] = c.dx[j], o->d[1] = c.dy[j], o->d[2] = c.dz[j];
            }
        }
    }
}

#ifdef LF_LENS_AVX2_KERNEL
__attribute__((target("avx2"))) static void batch_rays_avx2(const batch_args *a)
{
    batch_rays_body(a);
}
#endif

static void batch_rays_generic(const batch_args *a)
{
    batch_rays_body(a);
}

void lf_lens_sample_rays(const lf_lens *L, const lf_lens_pupil *P, int use_bounds, int n, const double *film_x,
                         const double *film_y, const double *u, const double *v, const double *lambda_nm,
                         lf_lens_stop_shape stop_shape, const void *stop_ctx, lf_lens_ray *out, double *weights)
{
    if (n <= 0)
        return;
    if (L->n > LF_LENS_MAX_SURFACES) {
        for (int i = 0; i < n; i++) {
            lf_lens_trace_opts o = {0};
            o.lambda_nm = lambda_nm ? lambda_nm[i] : 0.0;
            o.stop_shape = stop_shape, o.stop_ctx = stop_ctx;
            weights[i] = lf_lens_sample_ray(L, P, use_bounds, film_x[i], film_y[i], u[i], v[i], &o, &out[i]);
        }
        return;
    }
    surf_k S[LF_LENS_MAX_SURFACES];
    for (int k = 0; k < L->n; k++)
        surf_constants(L, L->n - 1 - k, 1, &S[k]);
    batch_args a = {L, P, S, use_bounds, n, film_x, film_y, u, v, lambda_nm, stop_shape, stop_ctx, out, weights,
                    NULL, NULL};
#ifdef LF_LENS_AVX2_KERNEL
    if (lf_lens_batch_uses_avx2()) {
        batch_rays_avx2(&a);
        return;
    }
#endif
    batch_rays_generic(&a);
}

void lf_lens_trace_rays_from_film(const lf_lens *L, int n, const lf_lens_ray *in, lf_lens_ray *out,
                                  unsigned char *passed)
{
    if (n <= 0)
        return;
    if (L->n > LF_LENS_MAX_SURFACES) {
        for (int i = 0; i < n; i++)
            passed[i] = trace(L, &in[i], &out[i], NULL, 1) == LF_LENS_PASSED;
        return;
    }
    surf_k S[LF_LENS_MAX_SURFACES];
    for (int k = 0; k < L->n; k++)
        surf_constants(L, L->n - 1 - k, 1, &S[k]);
    batch_args a = {L, NULL, S, 0, n, NULL, NULL, NULL, NULL, NULL, NULL, NULL, out, NULL, in, passed};
#ifdef LF_LENS_AVX2_KERNEL
    if (lf_lens_batch_uses_avx2()) {
        batch_rays_avx2(&a);
        return;
    }
#endif
    batch_rays_generic(&a);
}

/* ------------------------------------------------------------------ field */

int lf_lens_field_angle(const lf_lens *L, double film_r, double *theta)
{
    double rs = lf_lens_rear_disk_radius(L, film_r);
    pupil_ctx c = {L, film_r, L->film_distance_mm, NULL, 1, 0};
    double lam = 0.0;
    c.lambda = &lam;
    double lo, hi;
    if (!meridional_interval(&c, rs, &lo, &hi))
        return -1;
    double xm = 0.5 * (lo + hi);
    lf_lens_ray in = {{film_r, 0, 0}, {xm - film_r, 0, -L->film_distance_mm}}, out;
    if (trace(L, &in, &out, NULL, 1) != LF_LENS_PASSED)
        return -1;
    double dz = -out.d[2];
    *theta = atan2(sqrt(out.d[0] * out.d[0] + out.d[1] * out.d[1]), dz);
    return 0;
}

int lf_lens_chief_ray_angle(const lf_lens *L, double film_r, double *theta)
{
    double rs = lf_lens_rear_disk_radius(L, film_r);
    pupil_ctx c = {L, film_r, L->film_distance_mm, NULL, 1, 0};
    double lam = 0.0, xc;
    c.lambda = &lam;
    if (!chief_ray_x(&c, rs, &xc))
        return -1;
    lf_lens_ray in = {{film_r, 0, 0}, {xc - film_r, 0, -L->film_distance_mm}}, out;
    if (trace(L, &in, &out, NULL, 1) != LF_LENS_PASSED)
        return -1;
    *theta = atan2(sqrt(out.d[0] * out.d[0] + out.d[1] * out.d[1]), -out.d[2]);
    return 0;
}

double lf_lens_image_circle_radius(const lf_lens *L, double r_max)
{
    double th;
    if (lf_lens_field_angle(L, r_max, &th) == 0)
        return r_max;
    double lo = 0.0, hi = r_max;
    if (lf_lens_field_angle(L, 0.0, &th) != 0)
        return 0.0;
    for (int i = 0; i < 40; i++) {
        double m = 0.5 * (lo + hi);
        if (lf_lens_field_angle(L, m, &th) == 0)
            lo = m;
        else
            hi = m;
    }
    return lo;
}

/* ---------------------------------------------------------------- sensors */

static const struct {
    const char *name;
    double w, h;
} sensors[] = {
    {"fullframe", 36.0, 24.0},   {"apsc", 23.6, 15.8},    {"apsh", 27.9, 18.6},
    {"mediumformat", 53.7, 40.2}, {"fourthirds", 17.3, 13.0}, {"1inch", 13.2, 8.8},
    {"1/1.63in", 8.38, 5.59},    {"1/2.3in", 6.16, 4.62}, {"1/3.2in", 4.54, 3.42},
};

int lf_lens_sensor_size(const char *name, double *w, double *h)
{
    for (size_t i = 0; i < sizeof sensors / sizeof sensors[0]; i++)
        if (!strcmp(sensors[i].name, name)) {
            *w = sensors[i].w, *h = sensors[i].h;
            return 0;
        }
    return -1;
}

const char *lf_lens_sensor_names(void)
{
    return "fullframe, apsc, apsh, mediumformat, fourthirds, 1inch, 1/1.63in, 1/2.3in, 1/3.2in";
}
