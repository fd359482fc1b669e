/* Real compound lenses (camera/lens.c, camera/realistic.c): paraxial values
 * against independent computations (published EFLs, the lensmaker's
 * equation, ray-transfer matrices), Snell's law and total internal
 * reflection, focusing, unbiased exit-pupil sampling, dispersion, and the
 * hard cases (bad files, impossible focus, no light). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <dirent.h>
#include <string.h>
#include <unistd.h>

#include "camera/lens.h"
#include "camera/lf_camera.h"
#include "lf_test.h"

#define LENSES LF_SOURCE_DIR "/scenes/lenses/"

static int load(const char *name, lf_lens *L)
{
    lf_error err = {0};
    char path[1024];
    snprintf(path, sizeof path, "%s%s", LENSES, name);
    if (lf_lens_load(path, L, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return -1;
    }
    return 0;
}

static int parse(const char *text, lf_lens *L)
{
    lf_error err = {0};
    if (lf_lens_parse(text, "test.dat", L, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return -1;
    }
    return 0;
}

/* ---- independent paraxial optics: 2x2 ray-transfer matrices on (y, n u) ---- */
typedef struct m2 {
    double a, b, c, d;
} m2;
static m2 mul(m2 x, m2 y) /* x * y: y acts first */
{
    return (m2){x.a * y.a + x.b * y.c, x.a * y.b + x.b * y.d, x.c * y.a + x.d * y.c, x.c * y.b + x.d * y.d};
}
/* Surfaces i0..i1 (vertex of i0 to vertex of i1, refraction at both ends). */
static m2 system_matrix(const lf_lens *L, int i0, int i1)
{
    m2 m = {1, 0, 0, 1};
    for (int i = i0; i <= i1; i++) {
        double n = i > 0 ? L->s[i - 1].ior : 1.0, np = L->s[i].ior;
        double power = L->s[i].radius_mm != 0.0 ? (np - n) / L->s[i].radius_mm : 0.0;
        m = mul((m2){1, 0, -power, 1}, m);
        if (i < i1)
            m = mul((m2){1, L->s[i].thickness_mm / np, 0, 1}, m);
    }
    return m;
}

static void test_shipped_efl(void)
{
    /* Independent paraxial values from the issue (published designs, scaled). */
    static const struct {
        const char *file;
        double efl;
    } lenses[] = {{"dgauss.50mm.dat", 50.36},
                  {"wide.22mm.dat", 22.02},
                  {"telephoto.250mm.dat", 249.57},
                  {"fisheye.10mm.dat", 9.99},
                  {"dgauss.100mm.dat", 100.72}};
    for (size_t k = 0; k < sizeof lenses / sizeof lenses[0]; k++) {
        lf_lens L;
        if (load(lenses[k].file, &L))
            continue;
        lf_lens_paraxial px;
        CHECK(lf_lens_paraxial_analyse(&L, &px) == 0);
        CHECK_MSG(fabs(px.efl_mm - lenses[k].efl) <= 0.005 * lenses[k].efl, "%s: efl %g, want %g",
                  lenses[k].file, px.efl_mm, lenses[k].efl);
        /* The same lens through matrices: EFL = -1/C, BFL = -A/C, FFL = -D/C. */
        m2 m = system_matrix(&L, 0, L.n - 1);
        CHECK_NEAR(px.efl_mm, -1.0 / m.c, 1e-9 * lenses[k].efl);
        CHECK_NEAR(px.bfl_mm, -m.a / m.c, 1e-9 * lenses[k].efl);
        CHECK_NEAR(px.ffl_mm, -m.d / m.c, 1e-9 * lenses[k].efl);
        /* Pupils: the planes conjugate to the stop (B = 0), magnification A or 1/D. */
        int s = px.stop;
        CHECK(s == L.stop);
        if (s > 0) {
            m2 f = system_matrix(&L, 0, s - 1);
            f = mul((m2){1, L.s[s - 1].thickness_mm / L.s[s - 1].ior, 0, 1}, f); /* to the stop plane */
            CHECK_NEAR(px.entrance_pupil_mm, f.b / f.a, 1e-9 * lenses[k].efl);
            CHECK_NEAR(px.entrance_pupil_diameter_mm, 2 * L.s[s].aperture_radius_mm / fabs(f.a), 1e-9 * lenses[k].efl);
        }
        if (s < L.n - 1) {
            m2 r = system_matrix(&L, s + 1, L.n - 1);
            r = mul(r, (m2){1, L.s[s].thickness_mm / L.s[s].ior, 0, 1});
            CHECK_NEAR(px.exit_pupil_mm, -r.b / r.d, 1e-9 * lenses[k].efl);
            CHECK_NEAR(px.exit_pupil_diameter_mm, 2 * L.s[s].aperture_radius_mm / fabs(r.d), 1e-9 * lenses[k].efl);
        }
        CHECK_NEAR(px.fnumber, px.efl_mm / px.entrance_pupil_diameter_mm, 1e-12);
        /* Exact tracing agrees with paraxial optics near the axis: a parallel
         * ray at 1 um crosses the axis at the back focal distance. */
        L.film_distance_mm = px.bfl_mm;
        lf_lens_ray in = {{0, 1e-3, L.s[0].z_mm - L.film_distance_mm - 5.0}, {0, 0, 1}}, out;
        CHECK(lf_lens_trace_from_scene(&L, &in, &out, NULL) == LF_LENS_PASSED);
        double t = -out.o[1] / out.d[1];
        double z_cross = out.o[2] + t * out.d[2]; /* film at 0: should be ~0 */
        CHECK_MSG(fabs(z_cross) < 1e-4 * lenses[k].efl, "%s: paraxial focus off by %g mm", lenses[k].file, z_cross);
        lf_lens_free(&L);
    }
}

static void test_singlet(void)
{
    /* Lensmaker's equation for a thick singlet:
     * 1/f = (n-1) (1/R1 - 1/R2 + (n-1) d / (n R1 R2)),  BFL = f (1 - (n-1) d / (n R1)). */
    const double R1 = 50, R2 = -80, d = 6, n = 1.5;
    char text[256];
    snprintf(text, sizeof text, "# singlet\n%g %g %g 20\n%g 40 1 20\n", R1, d, n, R2);
    lf_lens L;
    if (parse(text, &L))
        return;
    lf_lens_paraxial px;
    CHECK(lf_lens_paraxial_analyse(&L, &px) == 0);
    double f = 1.0 / ((n - 1) * (1 / R1 - 1 / R2 + (n - 1) * d / (n * R1 * R2)));
    CHECK_NEAR(px.efl_mm, f, 1e-9 * f);
    CHECK_NEAR(px.bfl_mm, f * (1 - (n - 1) * d / (n * R1)), 1e-9 * f);
    CHECK_NEAR(px.ffl_mm, f * (1 + (n - 1) * d / (n * R2)), 1e-9 * f);
    lf_lens_free(&L);
    /* Thin-lens limit: d -> 0 gives 1/f = (n-1)(1/R1 - 1/R2) and BFL = f. */
    snprintf(text, sizeof text, "%g 1e-6 %g 20\n%g 40 1 20\n", R1, n, R2);
    if (parse(text, &L))
        return;
    CHECK(lf_lens_paraxial_analyse(&L, &px) == 0);
    double thin = 1.0 / ((n - 1) * (1 / R1 - 1 / R2));
    CHECK_NEAR(px.efl_mm, thin, 1e-6 * thin);
    CHECK_NEAR(px.bfl_mm, thin, 1e-6 * thin);
    /* Thin lens with no explicit stop: the lens rim is the stop, so f/N = f / 20 mm. */
    CHECK(L.stop == -1);
    CHECK_NEAR(px.entrance_pupil_diameter_mm, 20.0, 1e-6);
    CHECK_NEAR(px.fnumber, thin / 20.0, 1e-6);
    /* Thin lens focus: 1/u + 1/v = 1/f with D = u + v (distances from the film). */
    double D = 1000, v;
    lf_error err = {0};
    CHECK(lf_lens_focus_thick(&L, D, &v, &err) == 0);
    double u = D - v;
    CHECK_NEAR(1 / u + 1 / v, 1 / thin, 1e-6 / thin);
    lf_lens_free(&L);
}

/* Snell's law at each surface of a traced path: n1 sin(t1) = n2 sin(t2). */
static void test_snell(void)
{
    lf_lens L;
    if (parse("40 8 1.7 30\n-60 50 1 30\n", &L))
        return;
    L.film_distance_mm = 50;
    double path[3][3];
    lf_lens_trace_opts o = {0};
    o.path = path;
    double dir[3] = {0.1, 0.2, 1.0};
    double l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    lf_lens_ray in = {{-3, -6, -100}, {dir[0] / l, dir[1] / l, dir[2] / l}}, out;
    CHECK(lf_lens_trace_from_scene(&L, &in, &out, &o) == LF_LENS_PASSED);
    CHECK(o.path_count == 2);
    /* directions before/inside/after from the path points */
    double d0[3], d1[3], d2[3] = {out.d[0], out.d[1], out.d[2]};
    for (int k = 0; k < 3; k++)
        d0[k] = in.d[k], d1[k] = path[1][k] - path[0][k];
    l = sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
    for (int k = 0; k < 3; k++)
        d1[k] /= l;
    const double *dirs[3] = {d0, d1, d2};
    const double ior[3] = {1.0, 1.7, 1.0};
    for (int sidx = 0; sidx < 2; sidx++) {
        double R = L.s[sidx].radius_mm, zc = L.s[sidx].z_mm - L.film_distance_mm + R;
        double nrm[3] = {path[sidx][0] / R, path[sidx][1] / R, (path[sidx][2] - zc) / R};
        double sin_in, sin_out, c;
        c = nrm[0] * dirs[sidx][0] + nrm[1] * dirs[sidx][1] + nrm[2] * dirs[sidx][2];
        sin_in = sqrt(1 - c * c);
        c = nrm[0] * dirs[sidx + 1][0] + nrm[1] * dirs[sidx + 1][1] + nrm[2] * dirs[sidx + 1][2];
        sin_out = sqrt(1 - c * c);
        CHECK_NEAR(ior[sidx] * sin_in, ior[sidx + 1] * sin_out, 1e-12);
        /* hit points lie on the spheres */
        double r2 = path[sidx][0] * path[sidx][0] + path[sidx][1] * path[sidx][1] +
                    (path[sidx][2] - zc) * (path[sidx][2] - zc);
        CHECK_NEAR(sqrt(r2), fabs(R), 1e-9);
    }
    /* The refracted ray stays in the plane of incidence: (d0 x n) . d1 = 0. */
    lf_lens_free(&L);
}

static void test_tir_grazing_stop(void)
{
    /* n = 1.8 meniscus with a near-flat rear: a ray from the film parallel to
     * the axis meets the front surface (R = 10) at sin(i) = h / 10 and is
     * totally reflected when 1.8 h / 10 > 1. */
    lf_lens L;
    if (parse("10 4 1.8 19\n-1e6 20 1 19\n", &L))
        return;
    L.film_distance_mm = 20;
    lf_lens_ray out;
    lf_lens_ray in = {{0, 7, 0}, {0, 0, -1}}; /* 1.8 * 0.7 = 1.26 > 1 */
    CHECK(lf_lens_trace_from_film(&L, &in, &out, NULL) == LF_LENS_TIR);
    in.o[1] = 3; /* 1.8 * 0.3 = 0.54 */
    CHECK(lf_lens_trace_from_film(&L, &in, &out, NULL) == LF_LENS_PASSED);
    /* Grazing incidence on a full hemisphere (R = 10, clear diameter 20):
     * rays tangent to the sphere and just inside it never give NaN. */
    lf_lens G;
    if (parse("10 10 1.5 20\n-10 30 1 20\n", &G))
        return;
    G.film_distance_mm = 30;
    double zfront = G.s[0].z_mm - G.film_distance_mm;
    int finite = 1, n_pass = 0;
    for (int k = 0; k <= 200; k++) {
        double h = 10.0 - 1e-3 * k * k / 40000.0 * 10; /* 10 down to 9.999 */
        if (k == 200)
            h = 10.0; /* exactly tangent */
        lf_lens_ray g = {{0, h, zfront - 20}, {0, 0, 1}};
        lf_lens_status st = lf_lens_trace_from_scene(&G, &g, &out, NULL);
        if (st == LF_LENS_PASSED) {
            n_pass++;
            for (int c = 0; c < 3; c++)
                finite &= isfinite(out.o[c]) && isfinite(out.d[c]);
        }
    }
    CHECK(finite);
    /* Camera weights for a sweep of directions, including grazing ones. */
    lf_lens_pupil P;
    CHECK(lf_lens_pupil_build(&G, 20.0, 0, &P) > 0);
    int ok = 1;
    for (int i = 0; i < 2000; i++) {
        double u = (i % 50 + 0.5) / 50, v = (i / 50 + 0.5) / 40;
        double w1 = lf_lens_sample_ray(&G, &P, 1, 19.9 * u - 9.95, 0.3, u, v, NULL, &out);
        double w2 = lf_lens_sample_ray(&G, &P, 0, 19.9 * v - 9.95, 19.9 * u - 9.95, u, v, NULL, &out);
        ok &= isfinite(w1) && w1 >= 0 && isfinite(w2) && w2 >= 0;
    }
    CHECK(ok);
    /* The stop blocks what falls outside it. */
    lf_lens S;
    if (parse("50 5 1.5 30\n0 5 1 10\n-50 40 1 30\n", &S))
        return;
    S.film_distance_mm = 40;
    lf_lens_ray s_in = {{0, 8, -100}, {0, 0, 1}};
    CHECK(lf_lens_trace_from_scene(&S, &s_in, &out, NULL) == LF_LENS_STOPPED);
    s_in.o[1] = 2;
    CHECK(lf_lens_trace_from_scene(&S, &s_in, &out, NULL) == LF_LENS_PASSED);
    lf_lens_free(&L);
    lf_lens_free(&G);
    lf_lens_free(&S);
}

static void test_parse_errors(void)
{
    static const struct {
        const char *text, *want;
    } bad[] = {
        {"# c\n50 5 1.5 20\n-50 40 1\n", "test.dat:3: expected 4 or 5 columns (radius thickness ior aperture [abbe]), got 3"},
        {"50 5 1.5 20\n-50 40 1 20 0 7\n", "test.dat:2: expected 4 or 5 columns"},
        {"50 5 1.5x 20\n-50 40 1 20\n", "test.dat:1: ior \"1.5x\" is not a number"},
        {"50 5 1.5 120\n-50 40 1 20\n", "test.dat:1: aperture diameter 120 exceeds"},
        {"50 5 1.5 20\n0 1 0 10\n0 1 0 10\n-50 40 1 20\n", "test.dat:3: a second aperture stop"},
        {"50 -5 1.5 20\n-50 40 1 20\n", "test.dat:1: thickness"},
        {"50 5 0.5 20\n-50 40 1 20\n", "test.dat:1: ior 0.5"},
        {"# nothing\n\n", "no lens surfaces"},
        {"50 5 1.5 20\n-50 40 1.5 20\n", "test.dat:2: the last surface must leave into air"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        lf_lens L;
        lf_error err = {0};
        CHECK(lf_lens_parse(bad[i].text, "test.dat", &L, &err) != 0);
        CHECK_MSG(strstr(err.msg, bad[i].want) != NULL, "got \"%s\", want \"%s\"", err.msg, bad[i].want);
    }
    lf_lens L;
    lf_error err = {0};
    CHECK(lf_lens_load(LF_SOURCE_DIR "/scenes/lenses/no-such.dat", &L, &err) != 0);
    CHECK(strstr(err.msg, "no-such.dat") != NULL && err.code == LF_ERR_IO);
}

static void test_focus(void)
{
    lf_lens L;
    if (load("dgauss.50mm.dat", &L))
        return;
    lf_lens_paraxial px;
    lf_lens_paraxial_analyse(&L, &px);
    /* Independent: the paraxial image of an axial point at D from the film
     * (matrix B element of T(v) M T(u) vanishes, u + L + v = D), by bisection. */
    m2 m = system_matrix(&L, 0, L.n - 1);
    double len = lf_lens_total_length_mm(&L);
    const double Ds[3] = {500, 2000, 10000};
    for (int k = 0; k < 3; k++) {
        double lo = px.bfl_mm, hi = px.bfl_mm + 60;
#define B_OF(v) mul((m2){1, (v), 0, 1}, mul(m, (m2){1, Ds[k] - len - (v), 0, 1})).b
        double b_lo = B_OF(lo);
        CHECK(b_lo * B_OF(hi) < 0); /* the image lies in the bracket */
        for (int it = 0; it < 200; it++) {
            double v = 0.5 * (lo + hi);
            if ((B_OF(v) > 0) == (b_lo > 0))
                lo = v;
            else
                hi = v;
        }
#undef B_OF
        double v_ref = 0.5 * (lo + hi), v;
        lf_error err = {0};
        CHECK(lf_lens_focus_thick(&L, Ds[k], &v, &err) == 0);
        CHECK_NEAR(v, v_ref, 1e-6);
        CHECK_NEAR(lf_lens_paraxial_focus_distance(&L, &px, v_ref), Ds[k], 1e-6 * Ds[k]);
        /* Stopped down to 2 mm (f/25), real rays focus where paraxial ones do,
         * to 20 um: a tenth of the depth of focus +-N c (c = 0.03 mm). */
        lf_lens S = L;
        lf_lens_surface surf[32];
        memcpy(surf, L.s, sizeof(lf_lens_surface) * L.n);
        S.s = surf;
        lf_lens_set_stop_diameter(&S, 2.0, NULL);
        double v_search;
        CHECK(lf_lens_focus_search(&S, Ds[k], &v_search, &err) == 0);
        CHECK_NEAR(v_search, v_ref, 0.02);
    }
    /* Closer than possible: a clear error, the film distance untouched. */
    double v = -1;
    lf_error err = {0};
    CHECK(lf_lens_focus_thick(&L, 100.0, &v, &err) != 0);
    CHECK(v == -1);
    CHECK_MSG(strstr(err.msg, "closer than") != NULL, "%s", err.msg);
    /* ... and the closest possible (unit magnification) is 4f + hiatus. */
    CHECK(lf_lens_focus_thick(&L, lf_lens_closest_focus_mm(&px) * 1.0001, &v, &err) == 0);
    CHECK_NEAR(v, px.rear_principal_mm + 2 * px.efl_mm, 0.02 * px.efl_mm);
    /* Aperture larger than the stop: clamped with a warning. */
    lf_warnings warn = {0};
    CHECK(lf_lens_set_stop_diameter(&L, 40.0, &warn) == 1);
    CHECK_NEAR(L.s[L.stop].aperture_radius_mm, 17.1 / 2, 1e-12);
    const char *wt = lf_warnings_text(&warn);
    CHECK(warn.count == 1 && strstr(wt, "warning: aperture diameter 40 mm is larger than the stop of ") == wt);
    CHECK(strstr(lf_warnings_text(&warn), "(17.1 mm); clamping it\n") != NULL);
    CHECK(lf_lens_set_stop_diameter(&L, 10.0, &warn) == 0 && warn.count == 1); /* within the stop: no warning */
    lf_warnings_free(&warn);
    lf_lens_free(&L);
}

/* Deterministic uniform numbers. */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static void test_pupil_unbiased(void)
{
    static const char *const files[] = {"dgauss.50mm.dat", "wide.22mm.dat", "telephoto.250mm.dat",
                                        "fisheye.10mm.dat", "dgauss.100mm.dat"};
    const double film_w = 36, film_h = 24, film_r = 0.5 * hypot(36, 24);
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        lf_lens L;
        if (load(files[k], &L))
            continue;
        lf_lens_set_stop_diameter(&L, 1e3, NULL); /* wide open: the hardest bounds */
        lf_error err = {0};
        CHECK(lf_lens_focus_thick(&L, 10000.0, &L.film_distance_mm, &err) == 0);
        lf_lens_pupil P;
        CHECK(lf_lens_pupil_build(&L, film_r, 0, &P) > 0);
        uint64_t seed = 1234 + k;
        /* (1) Useful-ray fraction over the film, among film points that get light. */
        long traced = 0, passed = 0;
        for (int i = 0; i < 40000; i++) {
            double fx = (rnd(&seed) - 0.5) * film_w, fy = (rnd(&seed) - 0.5) * film_h;
            double u = rnd(&seed), v = rnd(&seed), rx, ry;
            if (!(lf_lens_pupil_sample(&P, fx, fy, u, v, &rx, &ry) > 0))
                continue;
            traced++;
            lf_lens_ray out;
            passed += lf_lens_sample_ray(&L, &P, 1, fx, fy, u, v, NULL, &out) > 0;
        }
        double frac = traced ? (double)passed / traced : 0;
        CHECK_MSG(frac >= 0.70, "%s: useful-ray fraction %.3f < 0.70", files[k], frac);
        /* (2) Conservative bounds: every ray that gets through from the whole
         * rear disk starts inside the bound (no light is lost). */
        long outside = 0, through = 0;
        for (int i = 0; i < 300000; i++) {
            double fx = (rnd(&seed) - 0.5) * film_w, fy = (rnd(&seed) - 0.5) * film_h;
            double a = 2 * M_PI * rnd(&seed), r = P.rear_disk_radius_mm * sqrt(rnd(&seed));
            double rx = r * cos(a), ry = r * sin(a);
            lf_lens_ray in = {{fx, fy, 0}, {rx - fx, ry - fy, -L.film_distance_mm}};
            if (lf_lens_trace_from_film(&L, &in, NULL, NULL) != LF_LENS_PASSED)
                continue;
            through++;
            outside += !lf_lens_pupil_contains(&P, fx, fy, rx, ry);
        }
        CHECK_MSG(through > 1000, "%s: only %ld rays got through", files[k], through);
        CHECK_MSG(outside == 0, "%s: %ld of %ld passing rays outside the pupil bound", files[k], outside, through);
        /* (3) Mean weight at fixed film points: bounds vs rear-disk sampling,
         * equal within 4 combined standard errors (estimated from the samples). */
        const double fr[2] = {0.0, 0.8};
        for (int j = 0; j < 2; j++) {
            double fx = fr[j] * film_r * 0.8, fy = fr[j] * film_r * 0.6;
            double m[2], se[2];
            for (int mode = 0; mode < 2; mode++) {
                long n = mode ? 1000000 : 50000;
                double s1 = 0, s2 = 0;
                for (long i = 0; i < n; i++) {
                    lf_lens_ray out;
                    double w = lf_lens_sample_ray(&L, &P, !mode, fx, fy, rnd(&seed), rnd(&seed), NULL, &out);
                    s1 += w, s2 += w * w;
                }
                m[mode] = s1 / n;
                se[mode] = sqrt(fmax(s2 / n - m[mode] * m[mode], 0) / n);
            }
            double tol = 4 * sqrt(se[0] * se[0] + se[1] * se[1]);
            CHECK_MSG(fabs(m[0] - m[1]) <= tol, "%s film (%g,%g): bounds %.6g vs rear disk %.6g (tol %.3g)", files[k],
                      fx, fy, m[0], m[1], tol);
            if (m[1] > 0)
                CHECK_MSG(tol < 0.08 * m[1], "%s: the comparison is too noisy (tol %.3g of %.3g)", files[k], tol, m[1]);
        }
        lf_lens_free(&L);
    }
}

static void test_dispersion(void)
{
    /* Cauchy fit: n(d) = n_d and (n_d - 1) / (n_F - n_C) = V_d. */
    lf_lens L;
    if (parse("60 5 1.6 30 40\n-200 95 1 30\n", &L))
        return;
    L.dispersive = 1;
    CHECK_NEAR(lf_lens_ior(&L, 0, LF_LENS_LAMBDA_D), 1.6, 1e-12);
    double nF = lf_lens_ior(&L, 0, LF_LENS_LAMBDA_F), nC = lf_lens_ior(&L, 0, LF_LENS_LAMBDA_C);
    CHECK_NEAR(0.6 / (nF - nC), 40.0, 1e-9);
    CHECK(lf_lens_ior(&L, 0, 400) > lf_lens_ior(&L, 0, 700)); /* normal dispersion */
    CHECK(lf_lens_ior(&L, 1, 400) == 1.0);
    /* Longitudinal colour of the singlet: the paraxial focus at each
     * wavelength follows the lensmaker's equation with n(lambda). */
    const double R1 = 60, R2 = -200, d = 5;
    lf_lens_paraxial px;
    lf_lens_paraxial_analyse(&L, &px);
    L.film_distance_mm = px.bfl_mm;
    const double lams[3] = {LF_LENS_LAMBDA_F, LF_LENS_LAMBDA_D, LF_LENS_LAMBDA_C};
    for (int k = 0; k < 3; k++) {
        double n = lf_lens_ior(&L, 0, lams[k]);
        double f = 1.0 / ((n - 1) * (1 / R1 - 1 / R2 + (n - 1) * d / (n * R1 * R2)));
        double bfl = f * (1 - (n - 1) * d / (n * R1));
        lf_lens_trace_opts o = {0};
        o.lambda_nm = lams[k];
        lf_lens_ray in = {{0, 1e-3, -200}, {0, 0, 1}}, out;
        CHECK(lf_lens_trace_from_scene(&L, &in, &out, &o) == LF_LENS_PASSED);
        double t = -out.o[1] / out.d[1];
        double z = out.o[2] + t * out.d[2] + L.film_distance_mm; /* from the rear vertex */
        CHECK_NEAR(z, bfl, 1e-4);
    }
    /* Without dispersion every wavelength sees n_d. */
    L.dispersive = 0;
    CHECK(lf_lens_ior(&L, 0, 400) == 1.6);
    lf_lens_free(&L);
}

/* ---- the camera through the registry ---- */
typedef struct store {
    const char *lensfile;
    double aperture, focus;
    int dispersion;
    const char *shape, *model; /* "aperture", "lensmodel"; NULL: default */
    int no_bounds;             /* "pupilbounds" false */
} store;
static double g_float(void *c, const char *name, double def)
{
    store *s = c;
    if (!strcmp(name, "aperturediameter") && s->aperture > 0)
        return s->aperture;
    if (!strcmp(name, "focusdistance") && s->focus > 0)
        return s->focus;
    return def;
}
static int g_int(void *c, const char *name, int def)
{
    (void)c, (void)name;
    return def;
}
static int g_bool(void *c, const char *name, int def)
{
    store *s = c;
    if (!strcmp(name, "pupilbounds"))
        return !s->no_bounds;
    return !strcmp(name, "dispersion") ? s->dispersion : def;
}
static const char *g_string(void *c, const char *name, const char *def)
{
    store *s = c;
    if (!strcmp(name, "aperture") && s->shape)
        return s->shape;
    if (!strcmp(name, "lensmodel") && s->model)
        return s->model;
    return !strcmp(name, "lensfile") && s->lensfile ? s->lensfile : def;
}
static int g_floats(void *c, const char *name, double *out, int max)
{
    (void)c, (void)name, (void)out, (void)max;
    return 0;
}
static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images here (%s)", path);
    return -1;
}

static void *make_camera(const char *type, store *s, int w, int h, char *err, char *warn)
{
    lf_camera_params p = {s, g_float, g_int, g_bool, g_string, g_floats, g_image};
    lf_camera_create_args a = {sizeof a, &p, w, h, 35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes", err, 512, warn, 512};
    void *state = NULL;
    const lf_camera_type *t = lf_camera_find(type);
    if (!t || t->create(&a, &state))
        return NULL;
    return state;
}

static void *make(store *s, int w, int h, char *err, char *warn)
{
    return make_camera("realistic", s, w, h, err, warn);
}

static void test_camera(void)
{
    const lf_camera_type *t = lf_camera_find("realistic");
    CHECK(t != NULL);
    if (!t)
        return;
    char err[512] = "", warn[512] = "";
    store s = {"lenses/dgauss.50mm.dat", 8.0, 3.0, 0, NULL, NULL, 0};
    void *c = make(&s, 90, 60, err, warn);
    CHECK_MSG(c != NULL, "%s", err);
    if (c) {
        CHECK(t->needs(c) == LF_CAMERA_NEEDS_LENS);
        int ok = 1, through = 0;
        double sum_x_left = 0, sum_y_top = 0;
        for (int i = 0; i < 20000; i++) {
            lf_camera_sample cs = {(i % 100 + 0.5) * 0.9, (i / 100 % 200 + 0.5) * 0.3, (i * 0.618034) - floor(i * 0.618034),
                                   (i * 0.754878) - floor(i * 0.754878), 0, 0.5};
            lf_camera_ray r = {{0}, {0}, 0, 0};
            double w = t->generate_ray(c, &cs, &r);
            ok &= isfinite(w) && w >= 0 && r.wavelength_nm == 0;
            if (w > 0) {
                through++;
                double l = sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
                ok &= fabs(l - 1) < 1e-9 && r.dir[2] > 0 && r.origin[2] > 0.03 && r.origin[2] < 0.08;
                if (cs.film_x < 20)
                    sum_x_left += r.dir[0];
                if (cs.film_y < 15)
                    sum_y_top += r.dir[1];
            }
        }
        CHECK(ok);
        CHECK(through > 10000);
        /* pbrt's orientation: the left of the image looks left (-x), the top looks up (+y). */
        CHECK(sum_x_left < 0);
        CHECK(sum_y_top > 0);
        char desc[4096];
        CHECK(t->describe(c, desc, sizeof desc) > 0);
        CHECK(strstr(desc, "effective focal length: 50.36") != NULL);
        t->destroy(c);
    }
    /* Dispersion: needs wavelength, sets it as the ABI says. */
    store sd = {"lenses/dgauss.100mm.dat", 30.0, 5.0, 1, NULL, NULL, 0};
    c = make(&sd, 30, 20, err, warn);
    CHECK_MSG(c != NULL, "%s", err);
    if (c) {
        CHECK(t->needs(c) == (LF_CAMERA_NEEDS_LENS | LF_CAMERA_NEEDS_WAVELENGTH));
        lf_camera_sample cs = {15, 10, 0.5, 0.5, 0, 0.25};
        lf_camera_ray r = {{0}, {0}, 0, 0};
        t->generate_ray(c, &cs, &r);
        CHECK_NEAR(r.wavelength_nm, 360.0 + 0.25 * (830.0 - 360.0), 1e-9);
        t->destroy(c);
    }
    /* Hard cases through the camera. */
    store none = {NULL, 0, 0, 0, NULL, NULL, 0};
    CHECK(make(&none, 30, 20, err, warn) == NULL);
    CHECK(strstr(err, "lensfile") != NULL);
    store too_close = {"lenses/dgauss.50mm.dat", 8.0, 0.1, 0, NULL, NULL, 0};
    CHECK(make(&too_close, 30, 20, err, warn) == NULL);
    CHECK_MSG(strstr(err, "closer than") != NULL, "%s", err);
    warn[0] = 0;
    store big = {"lenses/wide.22mm.dat", 100.0, 3.0, 0, NULL, NULL, 0};
    c = make(&big, 30, 20, err, warn);
    CHECK(c != NULL);
    /* the lens library's warning reaches the ABI's buffer as its bare message */
    size_t wn = strlen(warn);
    CHECK_MSG(strstr(warn, "aperture diameter 100 mm is larger than the stop of ") == warn && wn > 13 &&
                  !strcmp(warn + wn - 13, "; clamping it"),
              "warning: %s", warn);
    if (c)
        t->destroy(c);
    /* A lens that admits no light: the rear element sits outside the beam
     * of the front one (a 1 um stop). */
    char tmpl[] = "/tmp/lf_lens_XXXXXX";
    int fd = mkstemp(tmpl);
    CHECK(fd >= 0);
    if (fd >= 0) {
        const char *text = "50 5 1.5 30\n0 5 0 1e-6\n-50 40 1 30\n";
        CHECK(write(fd, text, strlen(text)) == (ssize_t)strlen(text));
        close(fd);
        store dark = {tmpl, 1e-6, 3.0, 0, NULL, NULL, 0};
        CHECK(make(&dark, 30, 20, err, warn) == NULL);
        CHECK_MSG(strstr(err, "admits no light") != NULL, "%s", err);
        /* A typo in a file: file:line in the camera's message. */
        FILE *f = fopen(tmpl, "w");
        fputs("# test\n50 5 1.5 30\n0 5 0 10\n-50 40 1\n", f);
        fclose(f);
        store typo = {tmpl, 5, 3.0, 0, NULL, NULL, 0};
        CHECK(make(&typo, 30, 20, err, warn) == NULL);
        char want[128];
        snprintf(want, sizeof want, "%s:4: expected 4 or 5 columns", tmpl);
        CHECK_MSG(strstr(err, want) != NULL, "%s", err);
        unlink(tmpl);
    }
}

/* ---- the batch path: lf_lens_sample_rays against lf_lens_sample_ray ---- */

/* A shaped stop with partial transmission that counts its calls (the batch
 * must call it for exactly the rays the scalar path calls it for). */
typedef struct shape_calls {
    long n;
} shape_calls;
static double odd_shape(const void *ctx, double x, double y)
{
    ((shape_calls *)ctx)->n++;
    if (x > 0.6 || y < -0.7 || x * x + y * y > 1.0)
        return 0.0;
    return x * x + y * y < 0.25 ? 1.0 : 0.5 + 0.25 * y;
}

/* lens.c's concentric mapping, to recover the rear point of a disk sample
 * (only for counting why rays fail). */
static void disk_point(double u, double v, double R, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0, r, th;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    if (fabs(a) > fabs(b))
        r = a, th = (M_PI / 4.0) * (b / a);
    else
        r = b, th = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    *x = r * cos(th) * R, *y = r * sin(th) * R;
}

static int close_rel(double a, double b, double scale)
{
    return fabs(a - b) <= 1e-9 * (fabs(a) > scale ? fabs(a) : scale);
}

typedef struct batch_stats {
    long rays, passed, identical;
    long status[LF_LENS_BACKWARDS + 1]; /* why the blocked rays failed (scalar trace) */
} batch_stats;

/* n rays both ways; every weight, pass/fail, output ray and stop-shape call
 * count must agree (to 1e-9 relative: FMA contraction may differ; the
 * current kernels are bit-identical, counted in st->identical). */
static void compare_batch(const char *what, const lf_lens *L, const lf_lens_pupil *P, int use_bounds, int n,
                          const double *fx, const double *fy, const double *u, const double *v, const double *lambda,
                          int shaped, batch_stats *st)
{
    lf_lens_ray *rs = malloc(sizeof *rs * (size_t)n), *rb = malloc(sizeof *rb * (size_t)n);
    double *ws = malloc(sizeof *ws * (size_t)n), *wb = malloc(sizeof *wb * (size_t)n);
    if (!rs || !rb || !ws || !wb) {
        CHECK(0);
        free(rs), free(rb), free(ws), free(wb);
        return;
    }
    const lf_lens_ray sentinel = {{1234.5, 1234.5, 1234.5}, {6789.0, 6789.0, 6789.0}};
    for (int i = 0; i < n; i++)
        rs[i] = rb[i] = sentinel;
    shape_calls cs = {0}, cb = {0};
    for (int i = 0; i < n; i++) {
        lf_lens_trace_opts o = {0};
        o.lambda_nm = lambda ? lambda[i] : 0.0;
        if (shaped)
            o.stop_shape = odd_shape, o.stop_ctx = &cs;
        ws[i] = lf_lens_sample_ray(L, P, use_bounds, fx[i], fy[i], u[i], v[i], &o, &rs[i]);
    }
    lf_lens_sample_rays(L, P, use_bounds, n, fx, fy, u, v, lambda, shaped ? odd_shape : NULL, &cb, rb, wb);
    long bad = 0, first = -1;
    for (int i = 0; i < n; i++) {
        int ok = (ws[i] > 0.0) == (wb[i] > 0.0) && close_rel(ws[i], wb[i], 1e-300) && isfinite(wb[i]) &&
                 wb[i] >= 0.0;
        int written_s = memcmp(&rs[i], &sentinel, sizeof sentinel) != 0;
        int written_b = memcmp(&rb[i], &sentinel, sizeof sentinel) != 0;
        ok &= written_s == written_b;
        if (written_s && written_b)
            for (int k = 0; k < 3; k++)
                ok &= close_rel(rs[i].o[k], rb[i].o[k], 1.0) && close_rel(rs[i].d[k], rb[i].d[k], 1.0);
        if (!ok && first < 0)
            first = i;
        bad += !ok;
        st->identical += ws[i] == wb[i] && (!written_s || !memcmp(&rs[i], &rb[i], sizeof rs[i]));
        st->passed += ws[i] > 0.0;
        if (!(ws[i] > 0.0)) {
            /* why: trace the same film ray (scalar) */
            double rx, ry;
            if (use_bounds) {
                if (!(lf_lens_pupil_sample(P, fx[i], fy[i], u[i], v[i], &rx, &ry) > 0.0))
                    continue;
            } else {
                disk_point(u[i], v[i], P->rear_disk_radius_mm, &rx, &ry);
            }
            lf_lens_ray in = {{fx[i], fy[i], 0}, {rx - fx[i], ry - fy[i], -L->film_distance_mm}};
            lf_lens_trace_opts o = {0};
            shape_calls calls = {0};
            o.lambda_nm = lambda ? lambda[i] : 0.0;
            if (shaped)
                o.stop_shape = odd_shape, o.stop_ctx = &calls;
            st->status[lf_lens_trace_from_film(L, &in, NULL, &o)]++;
        }
    }
    st->rays += n;
    CHECK_MSG(bad == 0, "%s: %ld of %d rays differ; first %ld: film (%g, %g) u,v (%g, %g): scalar w %.17g, batch %.17g",
              what, bad, n, first, first >= 0 ? fx[first] : 0, first >= 0 ? fy[first] : 0,
              first >= 0 ? u[first] : 0, first >= 0 ? v[first] : 0, first >= 0 ? ws[first] : 0,
              first >= 0 ? wb[first] : 0);
    CHECK_MSG(cs.n == cb.n, "%s: stop shape called %ld times by the scalar path, %ld by the batch", what, cs.n, cb.n);
    /* Every chunk size: the first k rays alone give the same weights. */
    for (int k = 1; k <= 40 && k <= n; k += 3) {
        lf_lens_sample_rays(L, P, use_bounds, k, fx, fy, u, v, lambda, shaped ? odd_shape : NULL, &cb, rb, wb);
        int same = 1;
        for (int i = 0; i < k; i++)
            same &= (ws[i] > 0.0) == (wb[i] > 0.0) && close_rel(ws[i], wb[i], 1e-300);
        CHECK_MSG(same, "%s: n = %d differs", what, k);
    }
    free(rs), free(rb), free(ws), free(wb);
}

/* Film points over the film (and past its corners and its diagonal), the
 * exact corners and centre; pupil samples including 0 and the largest value
 * below 1; wavelengths over 360..830 nm and some 0 (n_d). */
static int batch_inputs(int n, double film_w, double film_h, uint64_t seed, double *fx, double *fy, double *u,
                        double *v, double *lambda)
{
    static const double edge[] = {0.0, 0.5, 0.999999999999999889, 0.25, 0.75};
    int k = 0;
    for (int cx = -1; cx <= 1; cx++)
        for (int cy = -1; cy <= 1; cy++)
            for (int e = 0; e < 25; e++, k++) {
                fx[k] = 0.5 * film_w * cx, fy[k] = 0.5 * film_h * cy;
                u[k] = edge[e % 5], v[k] = edge[e / 5];
                lambda[k] = e % 3 ? 360.0 + 470.0 * e / 24.0 : 0.0;
            }
    for (; k < n; k++) {
        fx[k] = (rnd(&seed) - 0.5) * 1.1 * film_w, fy[k] = (rnd(&seed) - 0.5) * 1.1 * film_h;
        u[k] = rnd(&seed), v[k] = rnd(&seed);
        lambda[k] = k % 7 ? 360.0 + 470.0 * rnd(&seed) : 0.0;
    }
    return k;
}

static void test_batch_matches_scalar(void)
{
    enum { N = 12000 };
    double *fx = malloc(sizeof(double) * N), *fy = malloc(sizeof(double) * N), *u = malloc(sizeof(double) * N),
           *v = malloc(sizeof(double) * N), *lam = malloc(sizeof(double) * N);
    CHECK(fx && fy && u && v && lam);
    if (!fx || !fy || !u || !v || !lam)
        return;
    const double film_w = 36, film_h = 24, film_r = 0.5 * hypot(36, 24);
    const int have_avx2 = lf_lens_batch_uses_avx2();
    batch_stats st;
    memset(&st, 0, sizeof st);
    /* Every shipped lens. */
    DIR *dir = opendir(LENSES);
    CHECK(dir != NULL);
    int n_lenses = 0;
    for (struct dirent *de; dir && (de = readdir(dir));) {
        size_t len = strlen(de->d_name);
        if (len < 5 || strcmp(de->d_name + len - 4, ".dat"))
            continue;
        lf_lens L;
        if (load(de->d_name, &L))
            continue;
        n_lenses++;
        char what[512];
        lf_error err = {0};
        CHECK(lf_lens_focus_thick(&L, 3000.0, &L.film_distance_mm, &err) == 0);
        /* Glass gets dispersion for the wavelength cases (Cauchy B = 0.005 um^2
         * through n_d) unless the file has Abbe numbers. */
        lf_lens D = L;
        lf_lens_surface surf[64];
        CHECK(L.n <= 64);
        memcpy(surf, L.s, sizeof(lf_lens_surface) * (size_t)L.n);
        D.s = surf;
        if (!D.has_abbe)
            for (int i = 0; i < D.n; i++)
                if (surf[i].ior > 1.0) {
                    double ld = LF_LENS_LAMBDA_D * 1e-3;
                    surf[i].cauchy_b = 0.005;
                    surf[i].cauchy_a = surf[i].ior - 0.005 / (ld * ld);
                }
        D.has_abbe = 1, D.dispersive = 1;
        for (int stop = 0; stop < 2; stop++) {
            /* wide open, then at a third of the stop: many rays stopped */
            lf_lens_set_stop_diameter(&L, stop ? 2.0 / 3.0 * L.stop_max_radius_mm : 1e3, NULL);
            lf_lens_set_stop_diameter(&D, stop ? 2.0 / 3.0 * L.stop_max_radius_mm : 1e3, NULL);
            lf_lens_pupil P, PD;
            CHECK(lf_lens_pupil_build(&L, film_r, 0, &P) > 0);
            CHECK(lf_lens_pupil_build(&D, film_r, 1, &PD) > 0);
            int n = batch_inputs(N, film_w, film_h, 99 + n_lenses + stop, fx, fy, u, v, lam);
            for (int generic = 0; generic <= have_avx2; generic++) {
                lf_lens_batch_force_generic(generic);
                for (int use_bounds = 1; use_bounds >= 0; use_bounds--)
                    for (int shaped = 0; shaped < 2; shaped++) {
                        snprintf(what, sizeof what, "%s %s, %s, %s%s", de->d_name, stop ? "stopped down" : "wide open",
                                 use_bounds ? "pupil bounds" : "rear disk", shaped ? "shaped stop" : "round stop",
                                 generic ? ", generic kernel" : "");
                        compare_batch(what, &L, &P, use_bounds, n, fx, fy, u, v, NULL, shaped, &st);
                        strcat(what, ", dispersion");
                        compare_batch(what, &D, &PD, use_bounds, n, fx, fy, u, v, lam, shaped, &st);
                    }
            }
            lf_lens_batch_force_generic(0);
        }
        /* lf_lens_trace_rays_from_film against lf_lens_trace_from_film:
         * film rays, rays starting behind the film, turned back (d.z > 0),
         * of zero length. */
        enum { NT = 3001 };
        lf_lens_set_stop_diameter(&L, 1e3, NULL);
        lf_lens_ray in[NT], out_s[NT], out_b[NT];
        unsigned char passed[NT];
        uint64_t ts = 31 + n_lenses;
        lf_lens_pupil PT;
        CHECK(lf_lens_pupil_build(&L, film_r, 0, &PT) > 0);
        for (int i = 0; i < NT; i++) {
            double ox = (rnd(&ts) - 0.5) * film_w, oy = (rnd(&ts) - 0.5) * film_h, oz = i % 5 == 0 ? 2.0 : 0.0;
            double rx = 0, ry = 0; /* aimed at the exit-pupil bound (the axis if the point gets no light) */
            lf_lens_pupil_sample(&PT, ox, oy, rnd(&ts), rnd(&ts), &rx, &ry);
            in[i] = (lf_lens_ray){{ox, oy, oz}, {rx - ox, ry - oy, -L.film_distance_mm - oz}};
            if (i % 97 == 0)
                in[i].d[2] = -in[i].d[2];
            if (i % 101 == 0)
                in[i].d[0] = in[i].d[1] = in[i].d[2] = 0.0;
        }
        for (int generic = 0; generic <= have_avx2; generic++) {
            lf_lens_batch_force_generic(generic);
            memset(out_b, 0, sizeof out_b);
            lf_lens_trace_rays_from_film(&L, NT, in, out_b, passed);
            int bad = 0, through = 0;
            for (int i = 0; i < NT; i++) {
                int p = lf_lens_trace_from_film(&L, &in[i], &out_s[i], NULL) == LF_LENS_PASSED;
                through += p;
                bad += p != passed[i] || (p && memcmp(&out_s[i], &out_b[i], sizeof out_s[i]));
            }
            CHECK_MSG(bad == 0 && through > NT / 20, "%s: lf_lens_trace_rays_from_film: %d of %d rays differ (%d pass)",
                      de->d_name, bad, NT, through);
        }
        lf_lens_batch_force_generic(0);
        lf_lens_free(&L);
    }
    if (dir)
        closedir(dir);
    CHECK(n_lenses >= 5);
    /* Total internal reflection and grazing rays: the meniscus and the
     * hemisphere of test_tir_grazing_stop; rays that meet the far side of a
     * small rear sphere (its centre in front of the film): sampled over the
     * whole rear disk. */
    static const struct {
        const char *text;
        double film_distance, film_size;
    } odd[] = {{"10 4 1.8 19\n-1e6 20 1 19\n", 20, 20},
               {"10 10 1.5 20\n-10 30 1 20\n", 30, 20},
               {"5 1 1.5 9.99\n5 20 1 9.99\n", 20, 60}};
    for (size_t k = 0; k < sizeof odd / sizeof odd[0]; k++) {
        lf_lens L;
        if (parse(odd[k].text, &L))
            continue;
        L.film_distance_mm = odd[k].film_distance;
        lf_lens_pupil P;
        CHECK(lf_lens_pupil_build(&L, 0.7 * odd[k].film_size, 0, &P) > 0);
        int n = batch_inputs(N, odd[k].film_size, odd[k].film_size, 7 + k, fx, fy, u, v, lam);
        for (int generic = 0; generic <= have_avx2; generic++) {
            lf_lens_batch_force_generic(generic);
            char what[128];
            snprintf(what, sizeof what, "test lens %zu%s", k, generic ? ", generic kernel" : "");
            compare_batch(what, &L, &P, 0, n, fx, fy, u, v, NULL, 0, &st);
            compare_batch(what, &L, &P, 1, n, fx, fy, u, v, NULL, 1, &st);
        }
        lf_lens_batch_force_generic(0);
        lf_lens_free(&L);
    }
    /* Random prescriptions: strongly curved surfaces (clear apertures up to
     * the full hemisphere), thick glass, a stop somewhere, rays over the
     * whole rear disk: rays that meet a sphere's far side, graze, reflect
     * totally, miss. */
    uint64_t seed = 4242;
    int n_random = 0;
    for (int k = 0; k < 40; k++) {
        char text[1024] = "";
        int ns = 2 + (int)(rnd(&seed) * 4), stop_at = (int)(rnd(&seed) * (ns + 1)), len = 0;
        for (int i = 0; i < ns; i++) {
            double R = (4.0 + 40.0 * rnd(&seed) * rnd(&seed)) * (rnd(&seed) < 0.5 ? -1 : 1);
            double ap = 2.0 * fabs(R) * (0.5 + 0.5 * rnd(&seed)), ior = i == ns - 1 ? 1.0 : 1.0 + rnd(&seed);
            len += snprintf(text + len, sizeof text - len, "%.6g %.6g %.6g %.6g %g\n", R, 0.5 + 8.0 * rnd(&seed),
                            ior, ap, ior > 1.0 ? 25.0 + 40.0 * rnd(&seed) : 0.0);
            if (i == stop_at)
                len += snprintf(text + len, sizeof text - len, "0 %.6g 1 %.6g\n", 0.5 + 3.0 * rnd(&seed),
                                2.0 + 10.0 * rnd(&seed));
        }
        lf_lens L;
        if (lf_lens_parse(text, "random.dat", &L, NULL))
            continue; /* e.g. glass right after a stop row (ior 1 there): skip */
        L.film_distance_mm = 5.0 + 40.0 * rnd(&seed);
        L.dispersive = k % 2;
        lf_lens_pupil P;
        if (lf_lens_pupil_build(&L, 12.0, L.dispersive, &P) == 0) {
            lf_lens_free(&L);
            continue;
        }
        n_random++;
        int n = batch_inputs(4000, 18.0, 12.0, 500 + k, fx, fy, u, v, lam);
        for (int generic = 0; generic <= have_avx2; generic++) {
            lf_lens_batch_force_generic(generic);
            char what[128];
            snprintf(what, sizeof what, "random lens %d%s", k, generic ? ", generic kernel" : "");
            compare_batch(what, &L, &P, 0, n, fx, fy, u, v, L.dispersive ? lam : NULL, k % 3 == 0, &st);
            compare_batch(what, &L, &P, 1, n, fx, fy, u, v, L.dispersive ? lam : NULL, k % 3 == 1, &st);
        }
        lf_lens_batch_force_generic(0);
        lf_lens_free(&L);
    }
    CHECK_MSG(n_random >= 20, "only %d random lenses admit light", n_random);
    /* The comparison covered every way a ray can fail. */
    CHECK_MSG(st.status[LF_LENS_MISSED] > 0 && st.status[LF_LENS_CLIPPED] > 0 && st.status[LF_LENS_STOPPED] > 0 &&
                  st.status[LF_LENS_TIR] > 0 && st.passed > st.rays / 4,
              "coverage: %ld rays, %ld passed, missed %ld, clipped %ld, stopped %ld, TIR %ld, backwards %ld", st.rays,
              st.passed, st.status[LF_LENS_MISSED], st.status[LF_LENS_CLIPPED], st.status[LF_LENS_STOPPED],
              st.status[LF_LENS_TIR], st.status[LF_LENS_BACKWARDS]);
    printf("batch vs scalar: %ld rays (%s), %ld passed, %ld bit-identical; blocked: missed %ld, clipped %ld, "
           "stopped %ld, TIR %ld, backwards %ld\n",
           st.rays, have_avx2 ? "AVX2 and generic kernels" : "generic kernel", st.passed, st.identical,
           st.status[LF_LENS_MISSED], st.status[LF_LENS_CLIPPED], st.status[LF_LENS_STOPPED], st.status[LF_LENS_TIR],
           st.status[LF_LENS_BACKWARDS]);
    free(fx), free(fy), free(u), free(v), free(lam);
}

/* The camera's batch entry against its scalar one, for the traced model
 * (round and shaped apertures, dispersion, rear-disk sampling) and the
 * polynomial one, and for the plenoptic camera with a compound main lens
 * (lf_lens_trace_rays_from_film): the same weights and rays, time and
 * wavelength kept. */
static void test_camera_batch(void)
{
    static const struct {
        const char *type;
        store s;
    } configs[] = {
        {"realistic", {"lenses/dgauss.50mm.dat", 8.0, 3.0, 0, NULL, NULL, 0}},
        {"realistic", {"lenses/dgauss.100mm.dat", 30.0, 5.0, 1, "star", NULL, 0}},
        {"realistic", {"lenses/fisheye.10mm.dat", 100.0, 1.0, 0, "pentagon", NULL, 0}},
        {"realistic", {"lenses/wide.22mm.dat", 100.0, 2.0, 0, NULL, NULL, 1}},
        {"realistic", {"lenses/telephoto.250mm.dat", 100.0, 10.0, 0, NULL, "polynomial", 0}},
        {"plenoptic", {"lenses/dgauss.50mm.dat", 10.0, 2.0, 0, NULL, NULL, 0}},
    };
    enum { N = 3001 };
    lf_camera_sample *cs = malloc(sizeof *cs * N);
    lf_camera_ray *r1 = malloc(sizeof *r1 * N), *r2 = malloc(sizeof *r2 * N);
    double *w1 = malloc(sizeof *w1 * N), *w2 = malloc(sizeof *w2 * N);
    CHECK(cs && r1 && r2 && w1 && w2);
    for (size_t k = 0; cs && r1 && r2 && w1 && w2 && k < sizeof configs / sizeof configs[0]; k++) {
        char err[512] = "", warn[512] = "";
        store s = configs[k].s;
        const lf_camera_type *t = lf_camera_find(configs[k].type);
        CHECK_MSG(t && t->generate_rays, "%s has no generate_rays", configs[k].type);
        if (!t || !t->generate_rays)
            continue;
        void *c = make_camera(configs[k].type, &s, 96, 64, err, warn);
        CHECK_MSG(c != NULL, "%s %s: %s", configs[k].type, s.lensfile, err);
        if (!c)
            continue;
        uint64_t seed = 77 + k;
        for (int i = 0; i < N; i++) {
            cs[i] = (lf_camera_sample){rnd(&seed) * 97 - 0.5, rnd(&seed) * 65 - 0.5, rnd(&seed), rnd(&seed),
                                       0.25 + i, rnd(&seed)};
            if (i < 4) /* the film's corners */
                cs[i].film_x = i & 1 ? 96 : 0, cs[i].film_y = i & 2 ? 64 : 0;
            r1[i] = r2[i] = (lf_camera_ray){{0}, {0}, cs[i].time, 0.0};
        }
        for (int i = 0; i < N; i++)
            w1[i] = t->generate_ray(c, &cs[i], &r1[i]);
        /* in uneven pieces: chunk boundaries anywhere */
        for (int i0 = 0, m = 1; i0 < N; i0 += m, m = m * 3 % 211 + 1)
            t->generate_rays(c, i0 + m <= N ? m : N - i0, &cs[i0], &r2[i0], &w2[i0]);
        int bad = 0, through = 0;
        for (int i = 0; i < N; i++) {
            int ok = (w1[i] > 0) == (w2[i] > 0) && close_rel(w1[i], w2[i], 1e-300) && r1[i].time == r2[i].time &&
                     r1[i].wavelength_nm == r2[i].wavelength_nm;
            for (int q = 0; q < 3; q++)
                ok &= close_rel(r1[i].origin[q], r2[i].origin[q], 1e-3) && close_rel(r1[i].dir[q], r2[i].dir[q], 1.0);
            bad += !ok;
            through += w1[i] > 0;
        }
        CHECK_MSG(bad == 0, "%s %s: %d of %d camera rays differ between generate_ray and generate_rays",
                  configs[k].type, s.lensfile, bad, N);
        /* (the wide angle over its whole rear disk: about 1% get through) */
        CHECK_MSG(through > (s.no_bounds ? N / 500 : N / 10), "%s %s: only %d rays got through", configs[k].type,
                  s.lensfile, through);
        if (s.dispersion)
            CHECK(r2[N - 1].wavelength_nm > 359.0);
        t->destroy(c);
    }
    free(cs), free(r1), free(r2), free(w1), free(w2);
}

static void test_sensors(void)
{
    double w, h;
    CHECK(lf_lens_sensor_size("fullframe", &w, &h) == 0 && w == 36 && h == 24);
    CHECK(lf_lens_sensor_size("1/2.3in", &w, &h) == 0 && w == 6.16 && h == 4.62);
    CHECK(lf_lens_sensor_size("nope", &w, &h) != 0);
}

int main(void)
{
    test_shipped_efl();
    test_singlet();
    test_snell();
    test_tir_grazing_stop();
    test_parse_errors();
    test_focus();
    test_pupil_unbiased();
    test_dispersion();
    test_camera();
    test_batch_matches_scalar();
    test_camera_batch();
    test_sensors();
    return lf_test_end();
}
