/* test_shading_textures.c - pbrt-v4's procedural textures (directionmix,
 * dots, fbm, wrinkled, windy, marble, bilerp) built from scene text and
 * checked against their formulas at sample points.  The formulas are
 * recomputed here from an independent Perlin-noise implementation (the
 * gradient table written out as vectors, Bernstein form for marble's spline)
 * and from noise's own properties (zero on the integer lattice). */
#include "scenefile/lf_scene_desc.h"
#include "shading/lf_shading.h"

#include "lf_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------ reference Perlin noise */

/* Ken Perlin's permutation (Improving Noise, 2002), the table pbrt uses. */
static const int PERM[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,
    8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,
    117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,
    71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,
    55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,
    18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,
    124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,
    28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,
    129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,
    67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};

/* pbrt's 16 gradients (hash & 15), written out as vectors. */
static const double GRAD[16][3] = {{1, 1, 0},  {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                   {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                                   {1, 1, 0},  {-1, 1, 0}, {0, 1, -1}, {0, -1, -1}};

static int hash3(int x, int y, int z)
{
    int m = 255;
    return PERM[(PERM[(PERM[x & m] + y) & m] + z) & m];
}

static double quintic(double t) { return t * t * t * (10 - 15 * t + 6 * t * t); }

/* The sum over the 8 cell corners of weight x (gradient . offset). */
static double ref_noise(double x, double y, double z)
{
    double fx = floor(x), fy = floor(y), fz = floor(z);
    double d[3] = {x - fx, y - fy, z - fz};
    int c[3] = {(int)fx, (int)fy, (int)fz};
    double sum = 0;
    for (int k = 0; k < 8; k++) {
        int o[3] = {k & 1, (k >> 1) & 1, (k >> 2) & 1};
        const double *g = GRAD[hash3(c[0] + o[0], c[1] + o[1], c[2] + o[2]) & 15];
        double dot = 0, w = 1;
        for (int a = 0; a < 3; a++) {
            dot += g[a] * (d[a] - o[a]);
            w *= o[a] ? quintic(d[a]) : 1 - quintic(d[a]);
        }
        sum += w * dot;
    }
    return sum;
}

static double ref_fbm(const double p[3], double omega, int oct, int absolute)
{
    double s = 0, f = 1, w = 1;
    for (int i = 0; i < oct; i++, f *= 1.99, w *= omega) {
        double n = ref_noise(f * p[0], f * p[1], f * p[2]);
        s += w * (absolute ? fabs(n) : n);
    }
    return absolute ? s + 0.2 * w : s;
}

/* ------------------------------------------------------------- helpers */

static lf_shading_ctx ctx_at(double x, double y, double z)
{
    lf_shading_ctx c;
    memset(&c, 0, sizeof c);
    c.p = lf_v3((float)x, (float)y, (float)z);
    c.ns = c.ng = lf_v3(0, 0, 1);
    c.dpdu = lf_v3(1, 0, 0);
    return c;
}

static unsigned long long rng = 0x853c49e6748fea9bull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * 0x1p-53;
}

static int build(const char *text, lf_scene_desc *d, lf_materials **m, lf_error *err)
{
    memset(d, 0, sizeof *d);
    *m = NULL;
    int rc = lf_scene_parse_string(text, "tex.pbrt", d, err);
    return rc ? -1000 - rc : lf_materials_build(d, m, err);
}

/* ------------------------------------------------------------- tests */

static void test_noise(void)
{
    /* A permutation of 0..255. */
    int seen[256] = {0};
    for (int i = 0; i < 256; i++)
        seen[PERM[i]]++;
    for (int i = 0; i < 256; i++)
        CHECK(seen[i] == 1);
    /* Zero on the lattice (each corner's offset is zero there). */
    for (int i = -7; i <= 7; i += 2)
        for (int j = -5; j <= 9; j += 7)
            CHECK(lf_noise3(lf_v3((float)i, (float)j, (float)(i * j % 11))) == 0.f);
    double maxdiff = 0, maxabs = 0, mean = 0;
    const int n = 4000;
    for (int k = 0; k < n; k++) {
        double x = urand() * 600 - 300, y = urand() * 600 - 300, z = urand() * 20 - 10;
        double r = ref_noise(x, y, z), got = lf_noise3(lf_v3((float)x, (float)y, (float)z));
        /* float inputs: compare at the float-rounded point */
        r = ref_noise((float)x, (float)y, (float)z);
        maxdiff = fmax(maxdiff, fabs(r - got));
        maxabs = fmax(maxabs, fabs(got));
        mean += got / n;
    }
    CHECK_MSG(maxdiff < 2e-5, "noise differs from the reference by %g", maxdiff);
    CHECK(maxabs <= 1.05 && maxabs > 0.5); /* range about [-1, 1] */
    CHECK_MSG(fabs(mean) < 0.03, "noise mean %g (symmetric gradients: 0)", mean);
}

static void test_noise_textures(void)
{
    /* The texture's CTM maps texture space to world: p_tex = (p_world - (1, 2, 3)) / 2. */
    const char *text = "WorldBegin\nAttributeBegin\nTranslate 1 2 3\nScale 2 2 2\n"
                       "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 5 \"float roughness\" 0.6\n"
                       "Texture \"w\" \"float\" \"wrinkled\" \"integer octaves\" 4 \"float roughness\" 0.4\n"
                       "Texture \"wd\" \"float\" \"windy\"\n"
                       "Texture \"m\" \"spectrum\" \"marble\" \"float scale\" 3 \"float variation\" 0.7 "
                       "\"integer octaves\" 6 \"float roughness\" 0.55\n"
                       "Texture \"fd\" \"float\" \"fbm\"\n"
                       "AttributeEnd\n";
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (rc)
        return;
    const lf_texture *f = lf_materials_texture(m, "f", 1), *w = lf_materials_texture(m, "w", 1),
                     *wd = lf_materials_texture(m, "wd", 1), *mb = lf_materials_texture(m, "m", 0),
                     *fd = lf_materials_texture(m, "fd", 1);
    CHECK(f && w && wd && mb && fd);
    if (!(f && w && wd && mb && fd))
        return;
    static const double C[9][3] = {{.58, .58, .6}, {.58, .58, .6}, {.58, .58, .6}, {.5, .5, .5}, {.6, .59, .58},
                                   {.58, .58, .6}, {.58, .58, .6}, {.2, .2, .33},  {.58, .58, .6}};
    double worst[5] = {0};
    for (int k = 0; k < 300; k++) {
        double pw[3] = {urand() * 20 - 10, urand() * 20 - 10, urand() * 20 - 10};
        lf_shading_ctx c = ctx_at(pw[0], pw[1], pw[2]);
        double p[3] = {((float)pw[0] - 1) / 2, ((float)pw[1] - 2) / 2, ((float)pw[2] - 3) / 2};
        worst[0] = fmax(worst[0], fabs(lf_texture_float(f, &c) - ref_fbm(p, 0.6, 5, 0)));
        worst[1] = fmax(worst[1], fabs(lf_texture_float(w, &c) - ref_fbm(p, 0.4, 4, 1)));
        double p10[3] = {p[0] * .1, p[1] * .1, p[2] * .1};
        worst[2] = fmax(worst[2], fabs(lf_texture_float(wd, &c) - fabs(ref_fbm(p10, .5, 3, 0)) * ref_fbm(p, .5, 6, 0)));
        worst[3] = fmax(worst[3], fabs(lf_texture_float(fd, &c) - ref_fbm(p, .5, 8, 0)));
        /* marble: t = 1/2 + sin(3 y + 0.7 fbm(3 p)) / 2 on a 6-segment cubic Bezier (Bernstein form) */
        double p3[3] = {3 * p[0], 3 * p[1], 3 * p[2]};
        double t = .5 + .5 * sin(p3[1] + 0.7 * ref_fbm(p3, 0.55, 6, 0));
        int first = (int)floor(t * 6);
        first = first > 5 ? 5 : first;
        double u = t * 6 - first, b[4] = {(1 - u) * (1 - u) * (1 - u), 3 * (1 - u) * (1 - u) * u, 3 * (1 - u) * u * u,
                                         u * u * u};
        lf_vec3 got = lf_texture_rgb(mb, &c);
        double g3[3] = {got.x, got.y, got.z};
        for (int ch = 0; ch < 3; ch++) {
            double want = 0;
            for (int q = 0; q < 4; q++)
                want += 1.5 * b[q] * C[first + q][ch];
            worst[4] = fmax(worst[4], fabs(g3[ch] - want));
        }
    }
    const char *names[5] = {"fbm", "wrinkled", "windy", "fbm defaults", "marble"};
    /* float evaluation of up to 8 octaves against double: a few 1e-5;
     * marble's sin(3y) amplifies the fbm's rounding by the Bezier slope. */
    const double tol[5] = {1e-4, 1e-4, 1e-4, 1e-4, 3e-3};
    for (int i = 0; i < 5; i++)
        CHECK_MSG(worst[i] < tol[i], "%s: max error %g against the formula", names[i], worst[i]);
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static void test_dots_bilerp_dirmix(void)
{
    const char *text = "WorldBegin\n"
                       "Texture \"dots\" \"spectrum\" \"dots\" \"rgb inside\" [1 0 0] \"rgb outside\" [0 0 1] "
                       "\"float uscale\" 4 \"float vscale\" 4\n"
                       "Texture \"fdots\" \"float\" \"dots\"\n"
                       "Texture \"bl\" \"spectrum\" \"bilerp\" \"rgb v00\" [1 0 0] \"rgb v01\" [0 1 0] "
                       "\"rgb v10\" [0 0 1] \"rgb v11\" [1 1 1]\n"
                       "Texture \"fbl\" \"float\" \"bilerp\" \"float v00\" 2 \"float v11\" 5 \"float udelta\" 0.5\n"
                       "AttributeBegin\nRotate 90 1 0 0\n" /* dir (0 1 0) becomes (0 0 1) */
                       "Texture \"dm\" \"spectrum\" \"directionmix\" \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 1 0]\n"
                       "AttributeEnd\n"
                       "Texture \"fdm\" \"float\" \"directionmix\" \"vector3 dir\" [1 1 0] \"texture tex1\" \"fbl\"\n";
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (rc)
        return;
    const lf_texture *dots = lf_materials_texture(m, "dots", 0), *fdots = lf_materials_texture(m, "fdots", 1),
                     *bl = lf_materials_texture(m, "bl", 0), *fbl = lf_materials_texture(m, "fbl", 1),
                     *dm = lf_materials_texture(m, "dm", 0), *fdm = lf_materials_texture(m, "fdm", 1);
    /* dots: a dot of radius 0.35 in cell (s+1/2, t+1/2) if noise > 0 there, centre jittered by noise. */
    int bad = 0, inside = 0, n = 2000;
    for (int k = 0; k < n; k++) {
        double u = urand() * 5, v = urand() * 5;
        lf_shading_ctx c = ctx_at(0, 0, 0);
        c.uv = (lf_vec2){(float)u, (float)v};
        double s = (float)u * 4.0f, t = (float)v * 4.0f;
        double sc = floor(s + .5), tc = floor(t + .5);
        int in = 0;
        if (ref_noise(sc + .5, tc + .5, .5) > 0) {
            double s0 = sc + 0.15 * ref_noise(sc + 1.5, tc + 2.8, .5), t0 = tc + 0.15 * ref_noise(sc + 4.5, tc + 9.8, .5);
            in = (s - s0) * (s - s0) + (t - t0) * (t - t0) < 0.35 * 0.35;
        }
        inside += in;
        lf_vec3 got = lf_texture_rgb(dots, &c);
        bad += in ? !(got.x == 1 && got.z == 0) : !(got.x == 0 && got.z == 1);
        /* the float texture at unscaled (u, v): inside 1, outside 0 */
        double s1 = (float)u, t1 = (float)v, sc1 = floor(s1 + .5), tc1 = floor(t1 + .5);
        int in1 = 0;
        if (ref_noise(sc1 + .5, tc1 + .5, .5) > 0) {
            double s0 = sc1 + 0.15 * ref_noise(sc1 + 1.5, tc1 + 2.8, .5);
            double t0 = tc1 + 0.15 * ref_noise(sc1 + 4.5, tc1 + 9.8, .5);
            in1 = (s1 - s0) * (s1 - s0) + (t1 - t0) * (t1 - t0) < 0.35 * 0.35;
        }
        bad += lf_texture_float(fdots, &c) != (float)in1;
    }
    CHECK_MSG(bad <= 2, "dots: %d of %d lookups disagree with the formula (boundary rounding allows 2)", bad, 2 * n);
    CHECK_MSG(inside > n / 20 && inside < n / 2, "dots: %d of %d inside", inside, n);

    /* bilerp: (1-s)(1-t) v00 + (1-s) t v01 + s (1-t) v10 + s t v11 */
    for (int k = 0; k < 50; k++) {
        double s = urand() * 1.4 - 0.2, t = urand() * 1.4 - 0.2;
        lf_shading_ctx c = ctx_at(0, 0, 0);
        c.uv = (lf_vec2){(float)s, (float)t};
        lf_vec3 got = lf_texture_rgb(bl, &c);
        CHECK_NEAR(got.x, (1 - s) * (1 - t) + s * t, 1e-5);
        CHECK_NEAR(got.y, (1 - s) * t + s * t, 1e-5);
        CHECK_NEAR(got.z, s * (1 - t) + s * t, 1e-5);
        double s2 = s + 0.5; /* udelta 0.5; defaults v01 = 1, v10 = 0 */
        CHECK_NEAR(lf_texture_float(fbl, &c), (1 - s2) * (1 - t) * 2 + (1 - s2) * t * 1 + s2 * t * 5, 1e-5);
    }
    /* directionmix: |ng . dir| tex1 + (1 - |ng . dir|) tex2, dir through the CTM. */
    for (int k = 0; k < 50; k++) {
        double th = urand() * M_PI, ph = urand() * 2 * M_PI;
        lf_shading_ctx c = ctx_at(0, 0, 0);
        c.uv = (lf_vec2){0.25f, 0.75f};
        c.ng = lf_v3((float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th));
        double a = fabs(cos(th));
        lf_vec3 got = lf_texture_rgb(dm, &c);
        CHECK_NEAR(got.x, a, 1e-5);
        CHECK_NEAR(got.y, 1 - a, 1e-5);
        double a2 = fabs(sin(th) * (cos(ph) + sin(ph))) / sqrt(2.0);
        double bil = 0.25 * 0.25 * 2 + 0.25 * 0.75 * 1 + 0.75 * 0.75 * 5; /* fbl at s = t = 0.75 */
        CHECK_NEAR(lf_texture_float(fdm, &c), a2 * bil + (1 - a2) * 1.0, 1e-4);
    }
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static void expect_error(const char *text, const char *needle)
{
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    CHECK_MSG(rc != 0 && strstr(err.msg, "tex.pbrt:2:") && strstr(err.msg, needle), "want \"%s\": rc %d, %s", needle,
              rc, err.msg);
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static void test_errors(void)
{
    expect_error("WorldBegin\nTexture \"t\" \"spectrum\" \"fbm\"\n", "no spectrum \"fbm\"");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"marble\"\n", "no float \"marble\"");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"windy\" \"integer octaves\" 3\n", "octaves");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"fbm\" \"integer octaves\" 99\n", "octaves");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"ptex\" \"string filename\" \"a.ptx\"\n", "not supported");
}

int main(void)
{
    test_noise();
    test_noise_textures();
    test_dots_bilerp_dirmix();
    test_errors();
    return lf_test_end();
}
