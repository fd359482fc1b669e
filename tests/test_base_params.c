/* Parameter lists (base/params.c) and spectrum-to-RGB conversion (base/color.c). */
#include <stdlib.h>
#include <string.h>

#include "base/lf_color.h"
#include "base/lf_params.h"
#include "lf_test.h"

static char *dupstr(const char *s)
{
    char *d = malloc(strlen(s) + 1);
    strcpy(d, s);
    return d;
}

/* Adds a numeric parameter written at file:line:col. */
static void add_nums(lf_paramset *ps, lf_param_type t, const char *name, const double *v, size_t n, int line, int col)
{
    lf_param p = {0};
    p.type = t;
    p.name = dupstr(name);
    p.nums = malloc((n ? n : 1) * sizeof *p.nums);
    memcpy(p.nums, v, n * sizeof *v);
    p.n_nums = n;
    p.loc = (lf_loc){"scene.pbrt", line, col};
    CHECK(lf_params_add(ps, &p) == LF_OK);
}

static void add_str(lf_paramset *ps, lf_param_type t, const char *name, const char *s, int line, int col)
{
    lf_param p = {0};
    p.type = t;
    p.name = dupstr(name);
    p.strs = malloc(sizeof *p.strs);
    p.strs[0] = dupstr(s);
    p.n_strs = 1;
    p.loc = (lf_loc){"scene.pbrt", line, col};
    CHECK(lf_params_add(ps, &p) == LF_OK);
}

static void add_bool(lf_paramset *ps, const char *name, int v)
{
    lf_param p = {0};
    p.type = LF_PT_BOOL;
    p.name = dupstr(name);
    p.bools = malloc(1);
    p.bools[0] = (unsigned char)v;
    p.n_bools = 1;
    p.loc = (lf_loc){"scene.pbrt", 1, 1};
    CHECK(lf_params_add(ps, &p) == LF_OK);
}

static void test_type_names(void)
{
    lf_param_type t;
    CHECK(lf_param_type_from_name("float", &t) == 0 && t == LF_PT_FLOAT);
    CHECK(lf_param_type_from_name("integer", &t) == 0 && t == LF_PT_INTEGER);
    CHECK(lf_param_type_from_name("point", &t) == 0 && t == LF_PT_POINT3);
    CHECK(lf_param_type_from_name("vector", &t) == 0 && t == LF_PT_VECTOR3);
    CHECK(lf_param_type_from_name("normal", &t) == 0 && t == LF_PT_NORMAL3);
    CHECK(lf_param_type_from_name("normal3", &t) == 0 && t == LF_PT_NORMAL3);
    CHECK(lf_param_type_from_name("color", &t) == 0 && t == LF_PT_RGB);
    CHECK(lf_param_type_from_name("blackbody", &t) == 0 && t == LF_PT_BLACKBODY);
    CHECK(lf_param_type_from_name("texture", &t) == 0 && t == LF_PT_TEXTURE);
    CHECK(lf_param_type_from_name("flot", &t) == -1);
    CHECK(strcmp(lf_param_type_name(LF_PT_POINT2), "point2") == 0);
    CHECK(strcmp(lf_param_type_name(LF_PT_SPECTRUM), "spectrum") == 0);
}

static void test_lookups(void)
{
    lf_paramset ps = {0};
    double fov = 45, n = 7, p3[3] = {1, 2, 3}, v3[3] = {0, 0, 1}, p2[2] = {4, 5}, list[4] = {1, 2, 3, 4};
    add_nums(&ps, LF_PT_FLOAT, "fov", &fov, 1, 2, 10);
    add_nums(&ps, LF_PT_INTEGER, "pixelsamples", &n, 1, 3, 10);
    add_nums(&ps, LF_PT_POINT3, "from", p3, 3, 4, 10);
    add_nums(&ps, LF_PT_VECTOR3, "dir", v3, 3, 5, 10);
    add_nums(&ps, LF_PT_POINT2, "uv0", p2, 2, 6, 10);
    add_nums(&ps, LF_PT_FLOAT, "list", list, 4, 7, 10);
    add_str(&ps, LF_PT_STRING, "filename", "out.exr", 8, 10);
    add_bool(&ps, "twosided", 1);

    CHECK_NEAR(lf_params_float(&ps, "fov", 90), 45, 0);
    CHECK_NEAR(lf_params_float(&ps, "absent", 90), 90, 0);
    CHECK(lf_params_int(&ps, "pixelsamples", 16) == 7);
    double o3[3] = {0};
    CHECK(lf_params_point3(&ps, "from", o3) == 1);
    CHECK(o3[0] == 1 && o3[1] == 2 && o3[2] == 3);
    CHECK(lf_params_point3(&ps, "nothere", o3) == 0);
    CHECK(lf_params_vector3(&ps, "dir", o3) == 1 && o3[2] == 1);
    double o2[2];
    CHECK(lf_params_point2(&ps, "uv0", o2) == 1 && o2[0] == 4 && o2[1] == 5);
    size_t cnt = 0;
    const double *l = lf_params_nums(&ps, "list", LF_PT_FLOAT, &cnt);
    CHECK(l && cnt == 4 && l[3] == 4);
    CHECK(strcmp(lf_params_string(&ps, "filename", "x"), "out.exr") == 0);
    CHECK(strcmp(lf_params_string(&ps, "nofile", "dflt"), "dflt") == 0);
    CHECK(lf_params_bool(&ps, "twosided", 0) == 1);
    CHECK(lf_params_bool(&ps, "nobool", 1) == 1);
    const char *const *strs = lf_params_strings(&ps, "filename", &cnt);
    CHECK(strs && cnt == 1 && strcmp(strs[0], "out.exr") == 0);
    CHECK(lf_params_error(&ps)->code == LF_OK);

    /* Everything was read: finish succeeds. */
    lf_error err = {0};
    CHECK(lf_params_finish(&ps, "Camera \"perspective\"", &err) == LF_OK);

    /* peek does not mark used; find does. */
    double r = 1;
    add_nums(&ps, LF_PT_FLOAT, "radius", &r, 1, 9, 3);
    CHECK(lf_params_peek(&ps, "radius") != NULL);
    CHECK(lf_params_finish(&ps, "Shape \"sphere\"", &err) == LF_ERR_PARAM);
    CHECK_MSG(strcmp(err.msg, "scene.pbrt:9:3: unused parameter \"float radius\" in Shape \"sphere\"") == 0, "%s",
              err.msg);
    lf_error_clear(&err);
    CHECK(lf_params_find(&ps, "radius") != NULL);
    CHECK(lf_params_finish(&ps, "Shape \"sphere\"", &err) == LF_OK);
    lf_params_free(&ps);
    CHECK(ps.items == NULL && ps.count == 0);
}

static void test_type_mismatch(void)
{
    lf_paramset ps = {0};
    double fov = 45, two[2] = {1, 2};
    add_nums(&ps, LF_PT_INTEGER, "fov", &fov, 1, 3, 14);
    add_nums(&ps, LF_PT_FLOAT, "lensradius", two, 2, 4, 8);
    CHECK_NEAR(lf_params_float(&ps, "fov", 90), 90, 0); /* default on mismatch */
    CHECK(lf_params_error(&ps)->code == LF_ERR_PARAM);
    const char *msg = lf_params_error(&ps)->msg;
    CHECK_MSG(strcmp(msg, "scene.pbrt:3:14: parameter \"fov\" is declared integer, expected float") == 0, "%s", msg);
    /* Only the first error is kept, but a wrong count is an error too. */
    CHECK_NEAR(lf_params_float(&ps, "lensradius", 0.5), 0.5, 0);
    lf_error err = {0};
    CHECK(lf_params_finish(&ps, "Camera \"perspective\"", &err) == LF_ERR_PARAM);
    CHECK_MSG(strstr(err.msg, "scene.pbrt:3:14: parameter \"fov\" is declared integer") != NULL, "%s", err.msg);
    lf_params_free(&ps);

    lf_paramset q = {0};
    add_nums(&q, LF_PT_FLOAT, "lensradius", two, 2, 4, 8);
    CHECK_NEAR(lf_params_float(&q, "lensradius", 0.5), 0.5, 0);
    msg = lf_params_error(&q)->msg;
    CHECK_MSG(strstr(msg, "scene.pbrt:4:8:") && strstr(msg, "expects 1 value, got 2"), "%s", msg);
    lf_params_free(&q);

    lf_paramset s = {0};
    add_str(&s, LF_PT_STRING, "fov", "wide", 5, 2);
    CHECK(lf_params_int(&s, "fov", 3) == 3);
    msg = lf_params_error(&s)->msg;
    CHECK_MSG(strstr(msg, "declared string, expected integer") != NULL, "%s", msg);
    lf_params_free(&s);
}

static void test_unused_message(void)
{
    lf_paramset ps = {0};
    double v = 30;
    add_nums(&ps, LF_PT_FLOAT, "fvo", &v, 1, 2, 20);
    lf_error err = {0};
    CHECK(lf_params_finish(&ps, "Camera \"perspective\"", &err) == LF_ERR_PARAM);
    CHECK_MSG(strcmp(err.msg, "scene.pbrt:2:20: unused parameter \"float fvo\" in Camera \"perspective\"") == 0, "%s",
              err.msg);
    lf_params_free(&ps);
}

static void test_copy_and_defaults(void)
{
    lf_paramset ps = {0}, defaults = {0}, copy;
    double r = 3, d = 2, a = 0.5;
    add_nums(&ps, LF_PT_FLOAT, "radius", &r, 1, 1, 1);
    add_nums(&defaults, LF_PT_FLOAT, "radius", &d, 1, 1, 1);
    add_nums(&defaults, LF_PT_FLOAT, "alpha", &a, 1, 1, 1);
    CHECK(lf_params_merge_defaults(&ps, &defaults) == LF_OK);
    CHECK(ps.count == 2);
    CHECK_NEAR(lf_params_float(&ps, "radius", 0), 3, 0); /* own value wins */
    CHECK_NEAR(lf_params_peek(&ps, "alpha")->nums[0], 0.5, 0);
    lf_error err = {0};
    /* A default nobody read is not a typo (pbrt-v4 mayBeUnused). */
    CHECK(lf_params_finish(&ps, "Shape \"sphere\"", &err) == LF_OK);

    CHECK(lf_params_copy(&copy, &ps) == LF_OK);
    CHECK(copy.count == 2 && copy.items[0].used == 0 && copy.items[1].used == 0);
    CHECK(copy.items[0].nums != ps.items[0].nums);
    copy.items[0].nums[0] = 99;
    CHECK_NEAR(ps.items[0].nums[0], 3, 0);
    lf_params_free(&copy);
    lf_params_free(&ps);
    lf_params_free(&defaults);
}

static void test_color_functions(void)
{
    /* Wyman et al.'s fit against the CIE 1931 table (CIE 15:2004):
     * ybar(555) = 1.0000, xbar(600) = 1.0622, zbar(450) = 1.7471. */
    double b[3];
    lf_cie_xyz_bar(555, b);
    CHECK_NEAR(b[1], 1.0, 0.01);
    lf_cie_xyz_bar(600, b);
    CHECK_NEAR(b[0], 1.0622, 0.03);
    lf_cie_xyz_bar(450, b);
    CHECK_NEAR(b[2], 1.7471, 0.05);

    /* D65 white (X, Z) = (0.95047, 1.08883) at Y = 1 is sRGB (1,1,1). */
    lf_vec3 w = lf_xyz_to_linear_srgb(0.95047, 1.0, 1.08883);
    CHECK_NEAR(w.x, 1, 1e-3);
    CHECK_NEAR(w.y, 1, 1e-3);
    CHECK_NEAR(w.z, 1, 1e-3);

    /* Planck's law evaluated by hand (CODATA 2018 constants). */
    CHECK_NEAR(lf_planck(500, 5000) / 12107190590398.125, 1.0, 1e-5);
    CHECK_NEAR(lf_planck(1000, 300) / 1.76806737832943e-07, 1.0, 1e-4);
    CHECK(lf_planck(500, 0) == 0);

    /* Blackbody: luminance 1; 6504 K is near the D65 white; 3000 K is warm. */
    double temps[] = {2700, 6504, 10000};
    for (int i = 0; i < 3; i++) {
        lf_vec3 c = lf_blackbody_rgb(temps[i]);
        CHECK_NEAR(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z, 1.0, 1e-3);
    }
    lf_vec3 d65 = lf_blackbody_rgb(6504);
    CHECK(fabsf(d65.x - d65.y) < 0.1f && fabsf(d65.y - d65.z) < 0.1f && fabsf(d65.x - d65.z) < 0.1f);
    lf_vec3 warm = lf_blackbody_rgb(3000);
    CHECK(warm.x > warm.y && warm.y > warm.z);
    lf_vec3 cool = lf_blackbody_rgb(12000);
    CHECK(cool.z > cool.x);

    /* Spectra given as pairs. */
    double l2[2] = {360, 830}, ones[2] = {1, 1}, halves[2] = {0.5, 0.5};
    lf_vec3 c = lf_spectrum_pairs_rgb(l2, ones, 2, LF_SPECTRUM_ALBEDO);
    CHECK_NEAR(c.x, 1, 1e-4);
    CHECK_NEAR(c.y, 1, 1e-4);
    CHECK_NEAR(c.z, 1, 1e-4);
    c = lf_spectrum_pairs_rgb(l2, halves, 2, LF_SPECTRUM_UNBOUNDED);
    CHECK_NEAR(c.x, 0.5, 1e-4);
    CHECK_NEAR(c.z, 0.5, 1e-4);
    /* 400-700 nm misses only the faint tails of the matching functions. */
    double l3[2] = {400, 700};
    c = lf_spectrum_pairs_rgb(l3, halves, 2, LF_SPECTRUM_ALBEDO);
    CHECK_NEAR(c.x, 0.5, 0.02);
    CHECK_NEAR(c.y, 0.5, 0.02);
    CHECK_NEAR(c.z, 0.5, 0.02);
    /* A step to long wavelengths is red; albedo is clamped, unbounded not. */
    double lstep[4] = {360, 599, 600, 830}, vstep[4] = {0, 0, 1, 1};
    c = lf_spectrum_pairs_rgb(lstep, vstep, 4, LF_SPECTRUM_ALBEDO);
    CHECK(c.x > 0.5f && c.y < 0.5f && c.z < 0.1f);
    CHECK(c.z >= 0.f && c.x <= 1.f);
    double big[2] = {3, 3};
    c = lf_spectrum_pairs_rgb(l2, big, 2, LF_SPECTRUM_UNBOUNDED);
    CHECK_NEAR(c.y, 3, 1e-3);
    c = lf_spectrum_pairs_rgb(l2, big, 2, LF_SPECTRUM_ALBEDO);
    CHECK_NEAR(c.y, 1, 0);
    /* Illuminants are normalised to luminance 1 whatever their scale. */
    c = lf_spectrum_pairs_rgb(l2, big, 2, LF_SPECTRUM_ILLUMINANT);
    CHECK_NEAR(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z, 1.0, 1e-3);

    lf_vec3 n;
    CHECK(lf_named_spectrum_rgb("metal-Cu-eta", &n) == 0);
    CHECK_NEAR(n.x, 0.200, 1e-3);
    CHECK_NEAR(n.y, 0.924, 1e-3);
    CHECK_NEAR(n.z, 1.102, 1e-3);
    CHECK(lf_named_spectrum_rgb("metal-Au-k", &n) == 0);
    CHECK_NEAR(n.x, 3.983, 1e-3);
    CHECK_NEAR(n.z, 1.603, 1e-3);
    CHECK(lf_named_spectrum_rgb("metal-Al-k", &n) == 0 && fabsf(n.x - 9.224f) < 1e-3f);
    CHECK(lf_named_spectrum_rgb("metal-Ag-eta", &n) == 0 && fabsf(n.y - 0.117f) < 1e-3f);
    const char *names[] = {"metal-CuZn-eta", "metal-CuZn-k", "metal-MgO-eta", "metal-MgO-k", "metal-TiO2-eta",
                           "metal-TiO2-k",   "glass-BAF10",  "glass-FK51A",   "glass-LASF9", "glass-F5",
                           "glass-F10",      "glass-F11",    "stdillum-A",    "illum-acesD60"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        CHECK_MSG(lf_named_spectrum_rgb(names[i], &n) == 0, "%s", names[i]);
    CHECK(lf_named_spectrum_rgb("glass-BK7", &n) == 0);
    CHECK_NEAR(n.x, 1.5168, 1e-4);
    CHECK_NEAR(n.z, 1.5168, 1e-4);
    CHECK(lf_named_spectrum_rgb("stdillum-D65", &n) == 0 && n.x == 1.f && n.y == 1.f && n.z == 1.f);
    CHECK(lf_named_spectrum_rgb("metal-Xx-eta", &n) == -1);
    /* Illuminant A is a Planckian radiator at 2848 K with CIE's old
     * c2 = 1.435e-2 m K, i.e. at 2848 * 1.4388 / 1.435 = 2855.5 K with
     * today's c2: the independent route is the black body. */
    lf_vec3 bb = lf_blackbody_rgb(2848.0 * 1.438777 / 1.435);
    CHECK(lf_named_spectrum_rgb("stdillum-A", &n) == 0);
    CHECK_NEAR(n.x, bb.x, 2e-3);
    CHECK_NEAR(n.y, bb.y, 2e-3);
    CHECK_NEAR(n.z, bb.z, 2e-3);
    CHECK(n.x > 1.2f && n.z < 0.5f); /* orange */
    /* The chromaticity route: D65's published (x, y) is the sRGB white to
     * 1e-3 before the snap; luminance is 1 for every illuminant. */
    const char *ill[] = {"stdillum-D50", "illum-acesD60", "stdillum-F1", "stdillum-F4", "stdillum-F7",
                         "stdillum-F11", "stdillum-F12"};
    for (size_t i = 0; i < sizeof ill / sizeof ill[0]; i++) {
        CHECK(lf_named_spectrum_rgb(ill[i], &n) == 0);
        CHECK_NEAR(0.2126 * n.x + 0.7152 * n.y + 0.0722 * n.z, 1.0, 1e-3);
    }
    lf_vec3 d65c = lf_xyz_to_linear_srgb(0.31272 / 0.32903, 1.0, (1 - 0.31272 - 0.32903) / 0.32903);
    CHECK_NEAR(d65c.x, 1.0, 2e-3);
    CHECK_NEAR(d65c.z, 1.0, 2e-3);
    lf_vec3 f7, f12;
    lf_named_spectrum_rgb("stdillum-F7", &f7); /* a D65 simulator: near white */
    lf_named_spectrum_rgb("stdillum-F12", &f12); /* 3000 K: warm */
    CHECK(fabsf(f7.x - 1.f) < 0.02f && fabsf(f7.z - 1.f) < 0.03f && f12.x > 1.2f && f12.z < 0.6f);
}

static void test_params_rgb(void)
{
    lf_paramset ps = {0};
    double rgb[3] = {0.2, 0.4, 0.6}, T = 6504, grey = 0.25, pairs[4] = {360, 1, 830, 1};
    add_nums(&ps, LF_PT_RGB, "reflectance", rgb, 3, 1, 1);
    add_nums(&ps, LF_PT_BLACKBODY, "L", &T, 1, 2, 1);
    add_nums(&ps, LF_PT_FLOAT, "grey", &grey, 1, 3, 1);
    add_nums(&ps, LF_PT_SPECTRUM, "flat", pairs, 4, 4, 1);
    add_str(&ps, LF_PT_SPECTRUM, "eta", "metal-Au-eta", 5, 1);
    lf_vec3 def = lf_v3(9, 9, 9), c;
    CHECK(lf_params_rgb(&ps, "reflectance", LF_SPECTRUM_ALBEDO, def, &c) == 1);
    CHECK_NEAR(c.x, 0.2, 1e-6);
    CHECK_NEAR(c.z, 0.6, 1e-6);
    CHECK(lf_params_rgb(&ps, "L", LF_SPECTRUM_ILLUMINANT, def, &c) == 1);
    CHECK_NEAR(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z, 1.0, 1e-3);
    CHECK(fabsf(c.x - c.y) < 0.1f && fabsf(c.y - c.z) < 0.1f);
    CHECK(lf_params_rgb(&ps, "grey", LF_SPECTRUM_ALBEDO, def, &c) == 1);
    CHECK(c.x == 0.25f && c.y == 0.25f && c.z == 0.25f);
    CHECK(lf_params_rgb(&ps, "flat", LF_SPECTRUM_ALBEDO, def, &c) == 1);
    CHECK_NEAR(c.x, 1, 1e-3);
    CHECK_NEAR(c.y, 1, 1e-3);
    CHECK_NEAR(c.z, 1, 1e-3);
    CHECK(lf_params_rgb(&ps, "eta", LF_SPECTRUM_UNBOUNDED, def, &c) == 1);
    CHECK_NEAR(c.x, 0.143, 1e-3);
    CHECK_NEAR(c.z, 1.442, 1e-3);
    CHECK(lf_params_rgb(&ps, "absent", LF_SPECTRUM_ALBEDO, def, &c) == 0);
    CHECK(c.x == 9.f);
    CHECK(lf_params_error(&ps)->code == LF_OK);
    lf_error err = {0};
    CHECK(lf_params_finish(&ps, "Material \"diffuse\"", &err) == LF_OK);
    lf_params_free(&ps);

    /* Errors: unknown name, albedo > 1, decreasing wavelengths, wrong type. */
    lf_paramset bad = {0};
    add_str(&bad, LF_PT_SPECTRUM, "eta", "metal-Xx-eta", 7, 12);
    CHECK(lf_params_rgb(&bad, "eta", LF_SPECTRUM_UNBOUNDED, def, &c) == 1);
    CHECK(c.x == 9.f);
    const char *msg = lf_params_error(&bad)->msg;
    CHECK_MSG(!strcmp(msg, "scene.pbrt:7:12: spectrum parameter \"eta\": unknown named spectrum \"metal-Xx-eta\" "
                           "(the scene parser reads spectrum files)"),
              "%s", msg);
    lf_params_free(&bad);

    lf_paramset hi = {0};
    double over[3] = {1.5, 0.2, 0.2};
    add_nums(&hi, LF_PT_RGB, "reflectance", over, 3, 2, 5);
    lf_params_rgb(&hi, "reflectance", LF_SPECTRUM_ALBEDO, def, &c);
    CHECK_MSG(strstr(lf_params_error(&hi)->msg, "greater than 1") != NULL, "%s", lf_params_error(&hi)->msg);
    lf_params_free(&hi);
    lf_paramset hi2 = {0};
    add_nums(&hi2, LF_PT_RGB, "L", over, 3, 2, 5);
    CHECK(lf_params_rgb(&hi2, "L", LF_SPECTRUM_ILLUMINANT, def, &c) == 1 && c.x == 1.5f);
    CHECK(lf_params_error(&hi2)->code == LF_OK);
    lf_params_free(&hi2);

    lf_paramset dec = {0};
    double back[4] = {700, 1, 400, 1};
    add_nums(&dec, LF_PT_SPECTRUM, "s", back, 4, 1, 1);
    lf_params_rgb(&dec, "s", LF_SPECTRUM_ALBEDO, def, &c);
    msg = lf_params_error(&dec)->msg;
    CHECK_MSG(!strcmp(msg, "scene.pbrt:1:1: spectrum parameter \"s\": wavelengths must increase (400 after 700)"), "%s",
              msg);
    lf_params_free(&dec);

    lf_paramset wrong = {0};
    add_str(&wrong, LF_PT_STRING, "reflectance", "red", 3, 3);
    lf_params_rgb(&wrong, "reflectance", LF_SPECTRUM_ALBEDO, def, &c);
    msg = lf_params_error(&wrong)->msg;
    CHECK_MSG(strstr(msg, "scene.pbrt:3:3: parameter \"reflectance\" is declared string") != NULL, "%s", msg);
    lf_params_free(&wrong);
}

/* base/lf_error.h: the one location formatter, errors with a place, and the
 * one warning channel, against the formats its header documents. */
static void test_loc_format(void)
{
    char b[64];
    lf_loc full = {"scene.pbrt", 3, 7}, nocol = {"scene.pbrt", 3, 0}, noline = {"scene.pbrt", 0, 5},
           nofile = {NULL, 2, 1};
    CHECK(lf_loc_format(b, sizeof b, &full) == 14 && !strcmp(b, "scene.pbrt:3:7"));
    CHECK(lf_loc_format(b, sizeof b, &nocol) == 12 && !strcmp(b, "scene.pbrt:3"));
    CHECK(lf_loc_format(b, sizeof b, &noline) == 10 && !strcmp(b, "scene.pbrt"));
    CHECK(lf_loc_format(b, sizeof b, &nofile) == 13 && !strcmp(b, "<unknown>:2:1"));
    CHECK(lf_loc_format(b, sizeof b, NULL) == 9 && !strcmp(b, "<unknown>"));
    /* snprintf semantics: truncated to n bytes, the full length returned */
    CHECK(lf_loc_format(b, 6, &full) == 14 && !strcmp(b, "scene"));
}

static void test_error_at(void)
{
    lf_error e = {0};
    lf_loc at = {"a.pbrt", 12, 4};
    CHECK(lf_error_at(&e, LF_ERR_PARSE, &at, "unknown directive \"%s\"", "Foo") == LF_ERR_PARSE);
    CHECK(e.code == LF_ERR_PARSE && !strcmp(e.msg, "a.pbrt:12:4: unknown directive \"Foo\""));
    /* the first error is kept: the root cause is what the caller sees */
    CHECK(lf_error_at(&e, LF_ERR_PARAM, &at, "later") == LF_ERR_PARAM);
    CHECK(e.code == LF_ERR_PARSE && !strcmp(e.msg, "a.pbrt:12:4: unknown directive \"Foo\""));
    CHECK(lf_error_set(&e, LF_ERR_IO, "also later") == LF_ERR_IO && e.code == LF_ERR_PARSE);

    lf_error_clear(&e);
    CHECK(e.code == LF_OK && e.msg[0] == '\0');
    CHECK(lf_error_at(&e, LF_ERR_IO, NULL, "no place %d", 5) == LF_ERR_IO && !strcmp(e.msg, "no place 5"));
    lf_error_clear(&e);
    lf_loc col0 = {"b.pbrt", 9, 0}, line0 = {"b.pbrt", 0, 0}, nofile = {NULL, 1, 2};
    lf_error_at(&e, LF_ERR_PARAM, &col0, "x");
    CHECK(!strcmp(e.msg, "b.pbrt:9: x"));
    lf_error_clear(&e);
    lf_error_at(&e, LF_ERR_PARAM, &line0, "x");
    CHECK(!strcmp(e.msg, "b.pbrt: x"));
    lf_error_clear(&e);
    lf_error_at(&e, LF_ERR_PARAM, &nofile, "x");
    CHECK(!strcmp(e.msg, "<unknown>:1:2: x"));
    /* a NULL error is allowed and still returns the code */
    CHECK(lf_error_at(NULL, LF_ERR_NOMEM, &at, "x") == LF_ERR_NOMEM);
}

static void test_warnings(void)
{
    lf_warnings w = {0};
    CHECK(lf_warnings_text(&w) == NULL && w.count == 0);
    lf_loc at = {"s.pbrt", 3, 1}, col0 = {"s.pbrt", 4, 0}, nofile = {NULL, 5, 6};
    lf_warn_at(&w, &at, "\"%s\" is ignored", "x");
    CHECK(w.count == 1 && !strcmp(lf_warnings_text(&w), "s.pbrt:3:1: warning: \"x\" is ignored\n"));
    lf_warn_at(&w, NULL, "plain");
    lf_warn_at(&w, &col0, "c");
    lf_warn_at(&w, &nofile, "n");
    CHECK(w.count == 4);
    CHECK(!strcmp(lf_warnings_text(&w), "s.pbrt:3:1: warning: \"x\" is ignored\nwarning: plain\n"
                                        "s.pbrt:4: warning: c\n<unknown>:5:6: warning: n\n"));
    lf_warnings_free(&w);
    CHECK(lf_warnings_text(&w) == NULL && w.count == 0 && w.len == 0);

    /* lf_warn_text: lines as they are, a newline added when missing, one
     * warning per line */
    lf_warn_text(&w, "a.pbrt:1:1: warning: one\nb.pbrt:2:2: warning: two\nthree");
    CHECK(w.count == 3 && !strcmp(lf_warnings_text(&w), "a.pbrt:1:1: warning: one\nb.pbrt:2:2: warning: two\nthree\n"));
    lf_warn_text(&w, "");
    lf_warn_text(&w, NULL);
    CHECK(w.count == 3);
    lf_warnings_free(&w);

    /* many warnings grow the buffer past its first allocation; none lost */
    char expect[64];
    for (int i = 0; i < 1000; i++)
        lf_warn_at(&w, &at, "number %d", i);
    CHECK(w.count == 1000 && w.lost == 0 && w.cap > 256 && w.len == strlen(w.text));
    const char *t = lf_warnings_text(&w);
    snprintf(expect, sizeof expect, "s.pbrt:3:1: warning: number %d\n", 0);
    CHECK(!strncmp(t, expect, strlen(expect)));
    snprintf(expect, sizeof expect, "s.pbrt:3:1: warning: number %d\n", 999);
    CHECK(w.len >= strlen(expect) && !strcmp(t + w.len - strlen(expect), expect));
    int lines = 0;
    for (const char *c = t; *c; c++)
        lines += *c == '\n';
    CHECK(lines == 1000);
    lf_warnings_free(&w);
    lf_warn_at(NULL, &at, "ignored"); /* a NULL channel is allowed */
}

int main(void)
{
    test_loc_format();
    test_error_at();
    test_warnings();
    test_type_names();
    test_lookups();
    test_type_mismatch();
    test_unused_message();
    test_copy_and_defaults();
    test_color_functions();
    test_params_rgb();
    return lf_test_end();
}
