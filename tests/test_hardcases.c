/* Hard cases that must stay numerically stable (issue 9).
 *
 * Cameras: EVERY registered camera (lf_camera_count) is created with its
 * defaults and, for the cameras whose parameters are documented
 * (docs/thinlens.md, the camera sources), with a matrix of extreme values: f/0.7 and
 * f/64, focus at 1e6 m and at the nearest focus, fov near 0 and near 180
 * degrees, 1e-6 m and 1e6 m lens radii / focus distances / grid bounds,
 * 1x1 and 2000x3 films.  Rays over random samples and the extreme samples
 * (0, 1 - eps, exact film corners) must have finite weights >= 0, unit
 * directions and finite origins when the weight is > 0, and be identical
 * when the same sample is asked twice.  Parameters a camera must refuse
 * give an error message, not a crash.
 *
 * Renders (physics): a diffuse sphere of albedo a under a uniform sky L shows
 * a L (a convex object sees only the sky: one bounce, exact) at scene scales
 * 1, 1e-6 and 1e6; denormal radiance stays finite and non-negative; a camera
 * grazing a huge diffuse plane sees a L below the horizon and L above.
 *
 * LF_QUICK=1 (sanitizer builds) divides the ray and sample counts by 8;
 * LF_HARDCASE_VERBOSE=1 prints each refusal's message.
 * A failure here is a finding to report, not a margin to widen: every
 * assertion prints the camera and parameters it used. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lf_camera.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int quick;

/* Per camera: cases accepted / refused with a message, printed at the end
 * so a matrix that is refused wholesale is visible. */
static struct {
    const char *name;
    int accepted, refused;
} tally[32];
static void count_case(const char *name, int accepted)
{
    for (int i = 0; i < 32; i++)
        if (!tally[i].name || !strcmp(tally[i].name, name)) {
            tally[i].name = name;
            accepted ? tally[i].accepted++ : tally[i].refused++;
            return;
        }
}

/* ---- a typed parameter store standing in for the scene file ---- */
typedef struct kv {
    const char *name;
    double v[4];
    int n;          /* number of values; 0 with s set: a string */
    const char *s;
} kv;
typedef struct store {
    kv items[10];
    int n;
} store;
/* What the camera's lookups see: the store, which items it read (the host
 * reports unread ones as errors), and whether "lensfile" has a default. */
typedef struct lookup_ctx {
    const store *s;
    int used[10];
    int default_lensfile;
} lookup_ctx;

static const kv *find(void *c, const char *name)
{
    lookup_ctx *x = c;
    for (int i = 0; i < x->s->n; i++)
        if (!strcmp(x->s->items[i].name, name)) {
            x->used[i] = 1;
            return &x->s->items[i];
        }
    return NULL;
}
static double g_float(void *c, const char *name, double def)
{
    const kv *k = find(c, name);
    return k && k->n ? k->v[0] : def;
}
static int g_int(void *c, const char *name, int def)
{
    const kv *k = find(c, name);
    return k && k->n ? (int)k->v[0] : def;
}
static int g_bool(void *c, const char *name, int def)
{
    return g_int(c, name, def);
}
/* "realistic" needs a lens file: it gets the shipped double Gauss unless the
 * store names another (paths relative to scenes/).  Other cameras see only
 * what the store says (plenoptic changes mode with a lensfile). */
static const char *g_string(void *c, const char *name, const char *def)
{
    const kv *k = find(c, name);
    if (k && k->s)
        return k->s;
    if (!strcmp(name, "lensfile") && ((lookup_ctx *)c)->default_lensfile)
        return "lenses/dgauss.50mm.dat";
    return def;
}
static int g_floats(void *c, const char *name, double *out, int max)
{
    const kv *k = find(c, name);
    if (!k)
        return 0;
    for (int i = 0; i < k->n && i < max; i++)
        out[i] = k->v[i];
    return k->n;
}
static int g_image(void *c, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)c, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images in this test (%s)", path);
    return -1;
}

static void store_str(const store *s, char *buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; i < s->n && len < n; i++) {
        const kv *k = &s->items[i];
        if (k->s)
            len += (size_t)snprintf(buf + len, n - len, " %s=\"%s\"", k->name, k->s);
        else {
            len += (size_t)snprintf(buf + len, n - len, " %s=[", k->name);
            for (int j = 0; j < k->n && len < n; j++)
                len += (size_t)snprintf(buf + len, n - len, "%s%g", j ? " " : "", k->v[j]);
            if (len < n)
                len += (size_t)snprintf(buf + len, n - len, "]");
        }
    }
    if (!s->n)
        snprintf(buf, n, " (defaults)");
}

/* Returns create's status; *unread (may be NULL) gets the number of store
 * items the camera never looked up. */
static int create(const lf_camera_type *t, store *s, int w, int h, void **state, char *err, size_t err_size,
                  int *unread)
{
    lookup_ctx x;
    memset(&x, 0, sizeof x);
    x.s = s;
    x.default_lensfile = !strcmp(t->name, "realistic");
    lf_camera_params p = {&x, g_float, g_int, g_bool, g_string, g_floats, g_image};
    char warn[512] = "";
    lf_camera_create_args a = {sizeof a, &p, w, h, 35.0, 0.0, 1.0, LF_SOURCE_DIR "/scenes",
                               err, err_size, warn, sizeof warn};
    err[0] = '\0';
    *state = NULL;
    int rc = t->create(&a, state);
    if (unread) {
        *unread = 0;
        for (int i = 0; i < s->n; i++)
            *unread += !x.used[i];
    }
    return rc;
}

/* ---- ray properties ---- */
static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
static double rnd(void)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1p-53;
}

#define ONE_MINUS 0x1.fffffffffffffp-1 /* largest double below 1 */

/* Checks n random rays and every combination of extreme samples; returns
 * the number of bad rays (and prints the first). */
static int check_rays(const lf_camera_type *t, const void *c, int W, int H, int n, const char *what)
{
    static const double ext[] = {0.0, ONE_MINUS, 0.5, 0x1p-30};
    const int n_ext = 4;
    int bad = 0, passed = 0;
    /* extreme combinations first, then random */
    int total = n_ext * n_ext * n_ext * n_ext * 2 + n;
    for (int k = 0; k < total; k++) {
        lf_camera_sample cs;
        if (k < n_ext * n_ext * n_ext * n_ext * 2) {
            int q = k;
            double fx = ext[q % n_ext]; q /= n_ext;
            double fy = ext[q % n_ext]; q /= n_ext;
            double lu = ext[q % n_ext]; q /= n_ext;
            double lv = ext[q % n_ext]; q /= n_ext;
            double wl = q ? ONE_MINUS : 0.0;
            /* exact film corners too: film_x = W, film_y = H */
            double x = fx == ONE_MINUS ? (double)W : fx * W, y = fy == ONE_MINUS ? (double)H : fy * H;
            cs = (lf_camera_sample){x, y, lu, lv, wl, wl};
        } else {
            cs = (lf_camera_sample){rnd() * W, rnd() * H, rnd(), rnd(), rnd(), rnd()};
        }
        lf_camera_ray r, r2;
        memset(&r, 0, sizeof r);
        memset(&r2, 0, sizeof r2);
        r.time = r2.time = cs.time;
        double w = t->generate_ray(c, &cs, &r), w2 = t->generate_ray(c, &cs, &r2);
        const char *why = NULL;
        double len = sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
        if (!isfinite(w) || !(w >= 0))
            why = "weight not finite and >= 0";
        else if (memcmp(&w, &w2, sizeof w) != 0)
            why = "weight differs for the same sample";
        else if (w > 0 && !(fabs(len - 1) <= 1e-9))
            why = "direction not unit length";
        else if (w > 0 && !(isfinite(r.origin[0]) && isfinite(r.origin[1]) && isfinite(r.origin[2])))
            why = "origin not finite";
        else if (w > 0 && (memcmp(r.origin, r2.origin, sizeof r.origin) || memcmp(r.dir, r2.dir, sizeof r.dir) ||
                           memcmp(&r.wavelength_nm, &r2.wavelength_nm, sizeof r.wavelength_nm)))
            why = "ray differs for the same sample";
        if (why) {
            if (!bad)
                fprintf(stderr,
                        "HARD CASE FAILED (camera %s%s, %dx%d): %s: sample film (%.17g, %.17g) lens (%.17g, %.17g) "
                        "time %g wl %g -> weight %.17g origin (%g %g %g) dir (%g %g %g) |dir| %.17g\n",
                        t->name, what, W, H, why, cs.film_x, cs.film_y, cs.lens_u, cs.lens_v, cs.time,
                        cs.wavelength_u, w, r.origin[0], r.origin[1], r.origin[2], r.dir[0], r.dir[1], r.dir[2],
                        len);
            bad++;
        } else if (w > 0) {
            passed++;
        }
    }
    (void)passed;
    return bad;
}

/* must_accept: documented-valid parameters; otherwise a refusal with a
 * message is acceptable.  Returns 1 if the camera accepted. */
static int run_case(const lf_camera_type *t, store *s, int W, int H, int must_accept)
{
    char what[512], err[1024];
    store_str(s, what, sizeof what);
    void *c;
    int rc = create(t, s, W, H, &c, err, sizeof err, NULL);
    if (rc) {
        CHECK_MSG(!must_accept, "camera %s%s (%dx%d) refused documented-valid parameters: %s", t->name, what, W, H,
                  err);
        CHECK_MSG(err[0] != '\0', "camera %s%s (%dx%d) refused without an error message", t->name, what, W, H);
        count_case(t->name, 0);
        if (getenv("LF_HARDCASE_VERBOSE"))
            printf("refused: camera %s%s (%dx%d): %s\n", t->name, what, W, H, err);
        return 0;
    }
    int n = quick ? 250 : 2000;
    int bad = check_rays(t, c, W, H, n, what);
    CHECK_MSG(bad == 0, "camera %s%s (%dx%d): %d bad rays (first printed above)", t->name, what, W, H, bad);
    t->destroy(c);
    count_case(t->name, 1);
    return 1;
}

/* Parameters the camera must refuse with a message. */
static void must_refuse(const char *name, store *s)
{
    const lf_camera_type *t = lf_camera_find(name);
    if (!t)
        return;
    char what[512], err[1024];
    store_str(s, what, sizeof what);
    void *c;
    int unread = 0;
    int rc = create(t, s, 37, 23, &c, err, sizeof err, &unread);
    /* A parameter the camera did not read is refused by the host ("unused
     * parameter", with its file:line:col), so that counts as a refusal. */
    CHECK_MSG(rc != 0 || unread, "camera %s%s: accepted parameters it must refuse", name, what);
    if (rc)
        CHECK_MSG(err[0] != '\0', "camera %s%s: refused without an error message", name, what);
    else
        t->destroy(c);
}

#define KV1(n, x) {n, {x}, 1, NULL}
#define KVS(n, str) {n, {0}, 0, str}

static void test_every_camera_defaults(void)
{
    static const int sizes[][2] = {{37, 23}, {1, 1}, {2000, 3}, {3, 2000}};
    CHECK(lf_camera_count() >= 2);
    for (int i = 0; i < lf_camera_count(); i++) {
        const lf_camera_type *t = lf_camera_at(i);
        for (int k = 0; k < 4; k++) {
            store s = {{{0}}, 0};
            /* defaults must work at an ordinary size; odd sizes may be refused with a message
             * (the spherical camera's default equal-area mapping needs a square image) */
            int sq = k == 0 && !strcmp(t->name, "spherical");
            run_case(t, &s, sizes[k][0], sq ? sizes[k][0] : sizes[k][1], k == 0);
        }
    }
}

static void test_projective(void)
{
    static const double fovs[] = {1e-4, 0.01, 1, 90, 179, 179.9999};
    static const double radii[] = {0, 1e-6, 1, 1e6};
    static const double focus[] = {1e-6, 1, 1e6};
    const lf_camera_type *t = lf_camera_find("perspective");
    if (t)
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 4; b++)
                for (int c = 0; c < 3; c++) {
                    store s = {{KV1("fov", fovs[a]), KV1("lensradius", radii[b]), KV1("focaldistance", focus[c])}, 3};
                    run_case(t, &s, 37, 23, 1);
                }
    t = lf_camera_find("spherical");
    if (t) {
        static const int dims[][2] = {{37, 23}, {1, 1}, {2000, 3}, {3, 2000}};
        for (int k = 0; k < 4; k++) {
            store s = {{KVS("mapping", "equirectangular")}, 1};
            run_case(t, &s, dims[k][0], dims[k][1], 1);
        }
        store s = {{KVS("mapping", "equalarea")}, 1};
        run_case(t, &s, 1, 1, 1);
        run_case(t, &s, 2000, 2000, 1);
    }
    t = lf_camera_find("orthographic");
    if (t) {
        static const double win[] = {1e-6, 1, 1e6};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 4; b++)
                for (int c = 0; c < 3; c++) {
                    kv sw = {"screenwindow", {-win[a], win[a], -win[a], win[a]}, 4, NULL};
                    store s = {{sw, KV1("lensradius", radii[b]), KV1("focaldistance", focus[c])}, 3};
                    run_case(t, &s, 37, 23, 1);
                }
    }
    /* pbrt: fov must be in (0, 180) */
    static const double bad_fov[] = {0, 180, -5, 1e9, NAN, INFINITY};
    for (int a = 0; a < 6; a++) {
        store s = {{KV1("fov", bad_fov[a])}, 1};
        must_refuse("perspective", &s);
    }
    store s = {{KV1("lensradius", -1)}, 1};
    must_refuse("perspective", &s);
}

static void test_thinlens(void)
{
    const lf_camera_type *t = lf_camera_find("thinlens");
    if (!t)
        return;
    static const double fstops[] = {0.7, 1.4, 64};
    /* 1e6 m: the documented practical infinity; 1.0001 f: the nearest focus */
    static const double focal_mm[] = {50, 10, 600};
    static const char *apertures[] = {"circular", "polygon", "star"};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            for (int c = 0; c < 2; c++)
                for (int d = 0; d < 3; d++) {
                    double zo = c == 0 ? 1e6 : 1.0001 * focal_mm[b] * 1e-3;
                    store s = {{KV1("fstop", fstops[a]), KV1("focallength", focal_mm[b]), KV1("focusdistance", zo),
                                KVS("aperture", apertures[d])},
                               4};
                    run_case(t, &s, 37, 23, 1);
                }
    /* blade and anamorphic extremes */
    static const double blades[] = {3, 1000};
    static const double anam[] = {1e-3, 1e3};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
            store s = {{KVS("aperture", "polygon"), KV1("blades", blades[a]), KV1("anamorphic", anam[b]),
                        KV1("fstop", 0.7)},
                       4};
            run_case(t, &s, 37, 23, 0);
        }
    /* documented refusals (docs/thinlens.md, "Hard cases") */
    static const double bad_fstop[] = {0, -1, NAN};
    for (int a = 0; a < 3; a++) {
        store s = {{KV1("fstop", bad_fstop[a])}, 1};
        must_refuse("thinlens", &s);
    }
    static const double bad_f[] = {0, -50};
    for (int a = 0; a < 2; a++) {
        store s = {{KV1("focallength", bad_f[a])}, 1};
        must_refuse("thinlens", &s);
    }
    static const double bad_focus[] = {0.05, 0.01, 0, -1, INFINITY, NAN};
    for (int a = 0; a < 6; a++) {
        store s = {{KV1("focusdistance", bad_focus[a])}, 1};
        must_refuse("thinlens", &s);
    }
    store s = {{KVS("aperture", "polygon"), KV1("blades", 2)}, 2};
    must_refuse("thinlens", &s);
    store s2 = {{KVS("sensor", "nosuchsensor")}, 1};
    must_refuse("thinlens", &s2);
}

static void test_realistic(void)
{
    const lf_camera_type *t = lf_camera_find("realistic");
    if (!t)
        return;
    static const char *lenses[] = {"lenses/dgauss.50mm.dat", "lenses/dgauss.100mm.dat", "lenses/fisheye.10mm.dat",
                                   "lenses/telephoto.250mm.dat", "lenses/wide.22mm.dat"};
    /* 0.5 mm: beyond f/44 on every shipped lens; 1000 mm: clamped to the
     * stop, with a warning */
    static const double apd[] = {0.5, 1000};
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 2; b++)
            for (int d = 0; d < 2; d++) {
                /* focus at 1e6 m must work; dispersion on and off */
                store s = {{KVS("lensfile", lenses[a]), KV1("aperturediameter", apd[b]), KV1("focusdistance", 1e6),
                            KV1("dispersion", d)},
                           4};
                run_case(t, &s, 37, 23, 1);
            }
    /* A pinhole-sized stop (0.01 mm): light does get through physically,
     * but the exit-pupil search may not find it; a refusal must say so. */
    for (int a = 0; a < 5; a++)
        for (int c = 0; c < 2; c++) {
            store s = {{KVS("lensfile", lenses[a]), KV1("aperturediameter", 0.01), KV1("focusdistance", c ? 1e6 : 10)},
                       3};
            run_case(t, &s, 37, 23, 0);
        }
    /* The nearest focus: the camera's own refusal of 1 mm names the closest
     * distance ("the closest is X m"); 1.001 X must be accepted, at full
     * aperture and f/64-like. */
    for (int a = 0; a < 5; a++) {
        store s = {{KVS("lensfile", lenses[a]), KV1("focusdistance", 1e-3)}, 2};
        char err[1024];
        void *c;
        if (!create(t, &s, 37, 23, &c, err, sizeof err, NULL)) {
            t->destroy(c);
            continue;
        }
        const char *at = strstr(err, "the closest is ");
        double closest = at ? atof(at + strlen("the closest is ")) : 0;
        CHECK_MSG(closest > 0, "realistic %s: the too-close message names no closest distance: %s", lenses[a], err);
        if (!(closest > 0))
            continue;
        static const double stops[] = {1000, 0.5};
        for (int b = 0; b < 2; b++) {
            store n = {{KVS("lensfile", lenses[a]), KV1("focusdistance", 1.001 * closest),
                        KV1("aperturediameter", stops[b])},
                       3};
            run_case(t, &n, 37, 23, 1);
        }
    }
    /* near focus: accepted or refused with a message ("closer than possible") */
    static const double near_m[] = {0.2, 0.5, 1e-3};
    for (int a = 0; a < 5; a++)
        for (int c = 0; c < 3; c++) {
            store s = {{KVS("lensfile", lenses[a]), KV1("focusdistance", near_m[c])}, 2};
            run_case(t, &s, 37, 23, 0);
        }
    store s1 = {{KVS("lensfile", "lenses/no-such-lens.dat")}, 1};
    must_refuse("realistic", &s1);
    store s2 = {{KV1("aperturediameter", 0)}, 1};
    must_refuse("realistic", &s2);
    store s3 = {{KV1("focusdistance", 0)}, 1};
    must_refuse("realistic", &s3);
    store s4 = {{KV1("focusdistance", NAN)}, 1};
    must_refuse("realistic", &s4);
}

static void test_lightfield(void)
{
    const lf_camera_type *t = lf_camera_find("lightfield");
    if (!t)
        return;
    static const double scale[] = {1e-6, 1, 1e6};
    static const double fovs[] = {1e-3, 90, 179.999};
    static const double dims[][2] = {{1, 1}, {4, 3}, {16, 16}};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            for (int c = 0; c < 3; c++) {
                kv cd = {"camerasperdim", {dims[c][0], dims[c][1]}, 2, NULL};
                kv gb = {"cameragridbounds", {-scale[a], scale[a], -scale[a], scale[a]}, 4, NULL};
                store s = {{KV1("fov", fovs[b]), cd, gb, KV1("lensradius", scale[a] * 0.1),
                            KV1("focaldistance", scale[a] * 10)},
                           5};
                run_case(t, &s, 64, 48, 0);
            }
    kv cd0 = {"camerasperdim", {0, 0}, 2, NULL};
    store s1 = {{cd0}, 1};
    must_refuse("lightfield", &s1);
    store s2 = {{KV1("fov", 0)}, 1};
    must_refuse("lightfield", &s2);
    kv gbn = {"cameragridbounds", {1, -1, 0, 0}, 4, NULL};
    store s3 = {{gbn}, 1};
    must_refuse("lightfield", &s3);
}

static void test_plenoptic(void)
{
    const lf_camera_type *t = lf_camera_find("plenoptic");
    if (!t)
        return;
    static const double fstops[] = {0.7, 64};
    static const double focus[] = {1e6, 0.0501};
    static const char *grids[] = {"square", "hex"};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int c = 0; c < 2; c++) {
                store s = {{KV1("fstop", fstops[a]), KV1("focusdistance", focus[b]), KVS("grid", grids[c]),
                            KV1("rotation", c ? 0.5 : 0)},
                           4};
                run_case(t, &s, 120, 80, 0);
            }
    /* with a real main lens (lensfile): the stop, focus near and far */
    static const double stop_mm[] = {0.5, 1000};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
            store s = {{KVS("lensfile", "lenses/dgauss.50mm.dat"), KV1("aperturediameter", stop_mm[a]),
                        KV1("focusdistance", b ? 1e6 : 0.25)},
                       3};
            run_case(t, &s, 120, 80, 0);
        }
    store s1 = {{KV1("fstop", 0)}, 1};
    must_refuse("plenoptic", &s1);
    store s2 = {{KVS("grid", "triangle")}, 1};
    must_refuse("plenoptic", &s2);
}

static const lf_test_scene hardcase = {.name = "hardcase.pbrt"};

/* Furnace at scale k: camera at distance 4k, sphere of radius k. */
static void test_furnace_scaled(double k)
{
    const double L = 0.7, albedo = 0.6;
    int spp = quick ? 16 : 64;
    char scene[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 %.17g 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
             "Film \"rgb\" \"integer xresolution\" [32] \"integer yresolution\" [32]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [%d]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [5]\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n"
             "Material \"diffuse\" \"rgb reflectance\" [%g %g %g]\nShape \"sphere\" \"float radius\" [%.17g]\n",
             -4 * k, spp, L, L, L, albedo, albedo, albedo, k);
    lf_image img;
    char msg[1024];
    if (render_text(scene, &hardcase, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "HARD CASE: furnace at scale %g failed to render: %s", k, msg);
        return;
    }
    /* disk of radius tan(asin(1/4)) / tan(15 deg) * 16 = 15.4 px */
    double R = tan(asin(0.25)) / tan(15 * M_PI / 180) * 16;
    double s = 0, s2 = 0, out_dev = 0;
    int n = 0, nonfinite = 0;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            float *p = lf_image_px(&img, x, y);
            for (int c = 0; c < 3; c++)
                nonfinite += !isfinite(p[c]);
            double r = hypot(x + 0.5 - 16, y + 0.5 - 16);
            if (r < R - 2) {
                s += p[0], s2 += p[0] * p[0], n++;
            } else if (r > R + 2) {
                out_dev = fmax(out_dev, fabs(p[0] - L));
            }
        }
    double mean = s / n, sd = sqrt(fmax(0, s2 / n - mean * mean));
    CHECK_MSG(nonfinite == 0, "HARD CASE: furnace at scale %g: %d non-finite values", k, nonfinite);
    /* Noise margin: 4 standard errors of the per-pixel spread over ~500
     * pixels, plus float rounding.  Expected a L exactly (convex sphere). */
    CHECK_MSG(fabs(mean - albedo * L) <= 4 * sd / sqrt(n) + 1e-4,
              "HARD CASE: furnace at scale %g: sphere mean %.6f, expected a L = %.6f (sd %.4f, n %d)", k, mean,
              albedo * L, sd, n);
    CHECK_MSG(out_dev <= 1e-5, "HARD CASE: furnace at scale %g: sky pixels deviate from L by %g", k, out_dev);
    lf_image_free(&img);
}

static void test_denormal_radiance(void)
{
    /* 1e-40 is a float denormal.  Render threads flush denormals to zero,
     * so 0 is acceptable; anything non-finite, negative or larger than the
     * input radiance is not. */
    const double L = 1e-40;
    char scene[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 -4 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [4]\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n"
             "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\nShape \"sphere\" \"float radius\" [1]\n",
             L, L, L);
    lf_image img;
    char msg[1024];
    if (render_text(scene, &hardcase, &img, msg, sizeof msg)) {
        /* a clear refusal is allowed */
        CHECK_MSG(msg[0] != '\0', "denormal radiance: refused without a message");
        return;
    }
    int bad = 0;
    for (size_t i = 0; i < (size_t)img.width * img.height * img.channels; i++)
        bad += !(isfinite(img.data[i]) && img.data[i] >= 0 && img.data[i] <= 1.01 * L);
    CHECK_MSG(bad == 0, "HARD CASE: denormal radiance: %d values not finite or outside [0, L]", bad);
    lf_image_free(&img);
}

static void test_grazing_plane(void)
{
    /* A diffuse plane y = 0, 2e4 wide, camera 1e-3 above it looking along
     * +z: every visible point of the plane sees the whole upper hemisphere
     * as sky (radiance a L), and rays above the horizon see L.  The rows near
     * the horizon meet the plane at grazing angles of ~1e-7 rad. */
    const double L = 0.5, albedo = 0.8;
    int spp = quick ? 16 : 64;
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0.001 0 0 0.001 1 0 1 0\nCamera \"perspective\" \"float fov\" [40]\n"
             "Film \"rgb\" \"integer xresolution\" [24] \"integer yresolution\" [24]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [%d]\nPixelFilter \"box\"\n"
             "Integrator \"path\" \"integer maxdepth\" [5]\n"
             "WorldBegin\nLightSource \"infinite\" \"rgb L\" [%g %g %g]\n"
             "Material \"diffuse\" \"rgb reflectance\" [%g %g %g]\n"
             "Shape \"trianglemesh\" \"point3 P\" [-1e4 0 -1e4  1e4 0 -1e4  1e4 0 1e4  -1e4 0 1e4]\n"
             "  \"integer indices\" [0 1 2 0 2 3]\n",
             spp, L, L, L, albedo, albedo, albedo);
    lf_image img;
    char msg[1024];
    if (render_text(scene, &hardcase, &img, msg, sizeof msg)) {
        CHECK_MSG(0, "HARD CASE: grazing plane failed to render: %s", msg);
        return;
    }
    /* The horizon is the row y = 12 (the plane's edge at 1e4 is 1e-7 rad
     * below it).  Rows 0..10 see sky, rows 14..23 the plane. */
    double sky = 0, ground = 0, ground2 = 0;
    int n_sky = 0, n_ground = 0, nonfinite = 0;
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 24; x++) {
            float *p = lf_image_px(&img, x, y);
            for (int c = 0; c < 3; c++)
                nonfinite += !isfinite(p[c]);
            if (y <= 10)
                sky = fmax(sky, fabs(p[0] - L)), n_sky++;
            else if (y >= 14)
                ground += p[0], ground2 += p[0] * p[0], n_ground++;
        }
    CHECK_MSG(nonfinite == 0, "HARD CASE: grazing plane: %d non-finite values", nonfinite);
    CHECK_MSG(sky <= 1e-5, "HARD CASE: grazing plane: sky rows deviate from L by %g", sky);
    double mean = ground / n_ground, sd = sqrt(fmax(0, ground2 / n_ground - mean * mean));
    /* 4 standard errors over 240 pixels; self-intersection ("acne") would
     * darken the grazing rows far beyond this. */
    CHECK_MSG(fabs(mean - albedo * L) <= 4 * sd / sqrt(n_ground) + 1e-4,
              "HARD CASE: grazing plane: ground mean %.6f, expected a L = %.6f (sd %.4f)", mean, albedo * L, sd);
    lf_image_free(&img);
}

int main(void)
{
    const char *q = getenv("LF_QUICK");
    quick = q && *q && strcmp(q, "0");
    test_every_camera_defaults();
    test_projective();
    test_thinlens();
    test_realistic();
    test_lightfield();
    test_plenoptic();
    test_furnace_scaled(1.0);
    test_furnace_scaled(1e-6);
    test_furnace_scaled(1e6);
    test_denormal_radiance();
    test_grazing_plane();
    for (int i = 0; i < 32 && tally[i].name; i++)
        printf("camera %-13s %4d cases accepted, %3d refused with a message\n", tally[i].name, tally[i].accepted,
               tally[i].refused);
    return lf_test_end();
}
