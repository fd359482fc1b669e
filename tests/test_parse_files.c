/* Files a scene names: gzip (base/lf_file.h), token-level Include, spectrum
 * files, collected errors and the unsupported rule (scenefile/parser.c).
 *
 * The gzip streams here are built by hand, independently of zlib: a gzip
 * header, deflate "stored" blocks (RFC 1951 3.2.4) and the CRC-32 / length
 * trailer (RFC 1952), so a decoder bug cannot hide behind the same library
 * on both sides. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/lf_color.h"
#include "base/lf_file.h"
#include "lf_test.h"
#include "scenefile/lf_scene_desc.h"

static char tmpdir[256];

static uint32_t crc32_ieee(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = c & 1 ? (c >> 1) ^ 0xedb88320u : c >> 1;
    }
    return c ^ 0xffffffffu;
}

/* A gzip member holding `data` in stored blocks of at most `block` bytes. */
static unsigned char *gzip_stored(const void *data, size_t n, size_t block, size_t *out_n)
{
    size_t nb = n / block + 1;
    unsigned char *g = malloc(10 + n + 5 * nb + 8), *q = g;
    const unsigned char h[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 0xff};
    memcpy(q, h, 10);
    q += 10;
    const unsigned char *d = data;
    size_t left = n;
    do {
        size_t len = left < block ? left : block;
        left -= len;
        *q++ = left == 0; /* BFINAL, BTYPE 00 */
        *q++ = (unsigned char)(len & 0xff), *q++ = (unsigned char)(len >> 8);
        *q++ = (unsigned char)(~len & 0xff), *q++ = (unsigned char)((~len >> 8) & 0xff);
        memcpy(q, d, len);
        q += len, d += len;
    } while (left);
    uint32_t crc = crc32_ieee(data, n), isize = (uint32_t)n;
    for (int k = 0; k < 4; k++)
        *q++ = (unsigned char)(crc >> (8 * k));
    for (int k = 0; k < 4; k++)
        *q++ = (unsigned char)(isize >> (8 * k));
    *out_n = (size_t)(q - g);
    return g;
}

static void write_bytes(const char *rel, const void *data, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, rel);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fwrite(data, 1, n, f);
    fclose(f);
}

static void write_text(const char *rel, const char *text) { write_bytes(rel, text, strlen(text)); }

static void write_gz(const char *rel, const char *text, size_t block)
{
    size_t n;
    unsigned char *g = gzip_stored(text, strlen(text), block, &n);
    write_bytes(rel, g, n);
    free(g);
}

static const char *path_of(const char *rel)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, rel);
    return buf[k];
}

static void test_file_read(void)
{
    const char *text = "hello, gzip\nsecond line\n";
    write_text("plain.txt", text);
    write_gz("packed.bin", text, 5); /* several stored blocks; the name does not say gzip */
    char *a, *b;
    size_t na, nb;
    int gz = -1;
    lf_error err = {0};
    CHECK(lf_file_read(path_of("plain.txt"), LF_FILE_MAX_DEFAULT, &a, &na, &gz, &err) == 0 && gz == 0);
    CHECK_MSG(lf_file_read(path_of("packed.bin"), LF_FILE_MAX_DEFAULT, &b, &nb, &gz, &err) == 0 && gz == 1, "%s",
              err.msg);
    CHECK(na == strlen(text) && nb == na && memcmp(a, text, na) == 0 && memcmp(b, text, nb) == 0);
    CHECK(a[na] == '\0' && b[nb] == '\0');
    free(a);
    free(b);

    /* two concatenated members read as one stream, as gunzip does */
    size_t n1, n2;
    unsigned char *g1 = gzip_stored("abc", 3, 64, &n1), *g2 = gzip_stored("defg", 4, 64, &n2);
    unsigned char *both = malloc(n1 + n2);
    memcpy(both, g1, n1);
    memcpy(both + n1, g2, n2);
    write_bytes("two.gz", both, n1 + n2);
    CHECK(lf_file_read(path_of("two.gz"), 1000, &a, &na, NULL, &err) == 0 && na == 7 && memcmp(a, "abcdefg", 7) == 0);
    free(a);

    /* truncated: clear error naming the file */
    write_bytes("cut.gz", g1, n1 - 6);
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("cut.gz"), 1000, &a, &na, NULL, &err) == LF_ERR_PARSE && a == NULL);
    CHECK_MSG(strstr(err.msg, path_of("cut.gz")) && strstr(err.msg, "corrupt gzip"), "%s", err.msg);
    /* a damaged CRC */
    g1[n1 - 8] ^= 0x55;
    write_bytes("crc.gz", g1, n1);
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("crc.gz"), 1000, &a, &na, NULL, &err) == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "crc.gz") && strstr(err.msg, "corrupt gzip"), "%s", err.msg);
    /* damaged block header (LEN and NLEN disagree) */
    g2[12] ^= 0xff;
    write_bytes("hdr.gz", g2, n2);
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("hdr.gz"), 1000, &a, &na, NULL, &err) == LF_ERR_PARSE);
    free(g1);
    free(g2);
    free(both);

    /* size limits fail loudly, plain and compressed */
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("plain.txt"), 10, &a, &na, NULL, &err) == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, "limit of 10 bytes"), "%s", err.msg);
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("packed.bin"), 10, &a, &na, NULL, &err) == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, "decompressed") && strstr(err.msg, "limit of 10 bytes"), "%s", err.msg);
    lf_error_clear(&err);
    CHECK(lf_file_read(path_of("missing"), 10, &a, &na, NULL, &err) == LF_ERR_IO && strstr(err.msg, "missing"));
    lf_error_clear(&err);
    CHECK(lf_file_read(tmpdir, 10, &a, &na, NULL, &err) == LF_ERR_IO && strstr(err.msg, "is a directory"));
    lf_error_clear(&err);
    CHECK(lf_file_read("/dev/zero", LF_FILE_MAX_DEFAULT, &a, &na, NULL, &err) == LF_ERR_IO &&
          strstr(err.msg, "is a device"));
}

static const char *HEAD = "Camera \"perspective\"\nWorldBegin\n";

/* pbrt-v4 includes tokens: a parameter list may run on across the end of an
 * included file (pbrt-v4-scenes' smoke-plume does this). */
static void test_include_tokens(void)
{
    char main_text[512];
    write_text("inc_head.pbrt", "Shape \"sphere\"\n  \"float radius\" 2.5\n");
    snprintf(main_text, sizeof main_text, "%sInclude \"inc_head.pbrt\"\n  \"float zmin\" -1\nShape \"disk\"\n", HEAD);
    write_text("inc_main.pbrt", main_text);
    lf_scene_desc d;
    lf_error err = {0};
    int rc = lf_scene_parse_file(path_of("inc_main.pbrt"), &d, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        CHECK(d.n_shapes == 2);
        const lf_param *r = lf_params_peek(&d.shapes[0].e.params, "radius");
        const lf_param *z = lf_params_peek(&d.shapes[0].e.params, "zmin");
        CHECK(r && r->nums[0] == 2.5 && z && z->nums[0] == -1);
        /* locations still name the file each token came from */
        CHECK(r && strstr(r->loc.file, "inc_head.pbrt") && r->loc.line == 2 && r->loc.col == 3);
        CHECK(z && strstr(z->loc.file, "inc_main.pbrt") && z->loc.line == 4 && z->loc.col == 3);
        CHECK(d.shapes[1].e.loc.line == 5);
        lf_scene_desc_free(&d);
    }
    /* a gzipped include (any name) parses to the same description */
    write_gz("inc_head.gz.pbrt", "Shape \"sphere\"\n  \"float radius\" 2.5\n", 7);
    snprintf(main_text, sizeof main_text, "%sInclude \"inc_head.gz.pbrt\"\n  \"float zmin\" -1\n", HEAD);
    write_gz("inc_main2.pbrt.gz", main_text, 11);
    rc = lf_scene_parse_file(path_of("inc_main2.pbrt.gz"), &d, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        const lf_param *r = lf_params_peek(&d.shapes[0].e.params, "radius");
        CHECK(d.n_shapes == 1 && r && r->nums[0] == 2.5 && r->loc.line == 2 && r->loc.col == 3);
        CHECK(lf_params_peek(&d.shapes[0].e.params, "zmin") != NULL);
        lf_scene_desc_free(&d);
    }
    /* an error inside the include still has its file:line:column */
    write_text("inc_bad.pbrt", "\n  Shape \"sphere\" \"float radius\" \"x\"\n");
    snprintf(main_text, sizeof main_text, "%sInclude \"inc_bad.pbrt\"\n", HEAD);
    write_text("inc_main3.pbrt", main_text);
    lf_error_clear(&err);
    CHECK(lf_scene_parse_file(path_of("inc_main3.pbrt"), &d, &err) == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "inc_bad.pbrt:2:33:"), "%s", err.msg);
    /* a corrupt gzipped include: the message names the file */
    unsigned char junk[] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, 0xff};
    write_bytes("inc_junk.pbrt", junk, sizeof junk);
    snprintf(main_text, sizeof main_text, "%sInclude \"inc_junk.pbrt\"\n", HEAD);
    write_text("inc_main4.pbrt", main_text);
    lf_error_clear(&err);
    CHECK(lf_scene_parse_file(path_of("inc_main4.pbrt"), &d, &err) == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "inc_main4.pbrt:3:1:") && strstr(err.msg, "inc_junk.pbrt") &&
                  strstr(err.msg, "corrupt gzip"),
              "%s", err.msg);
    /* binary garbage is shown as bytes, not raw */
    write_text("bin.pbrt", "\x01\x02garbage\n");
    lf_error_clear(&err);
    CHECK(lf_scene_parse_file(path_of("bin.pbrt"), &d, &err) == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "\\x01\\x02garbage"), "%s", err.msg);
}

/* Files are read through a 64 KiB window: every token must read the same
 * when the window ends inside it.  The Shape line is pushed across the
 * boundary a byte at a time, plain and gzipped (stored blocks of 4000
 * bytes, so inflate's output ends elsewhere too); the values, the decoded
 * string and the column must equal those of the text given whole. */
static void test_window_boundaries(void)
{
    const char *body = "Shape \"sphere\" \"float radius\" 2.5 # a comment\n"
                       "  \"string name\" \"ab\\\"cd\" \"float zmin\" [ -1.25e0 ]\nShape \"disk\"\n";
    size_t nh = strlen(HEAD), nb = strlen(body), bad = 0;
    char *text = malloc(nh + 100000 + nb + 1);
    CHECK(text != NULL);
    if (!text)
        return;
    for (size_t pad = 65536 - nh - 80; pad <= 65536 - nh + 8; pad++) {
        memcpy(text, HEAD, nh);
        memset(text + nh, ' ', pad);
        memcpy(text + nh + pad, body, nb + 1);
        write_text("window.pbrt", text);
        write_gz("window.pbrt.gz", text, 4000);
        for (int k = 0; k < 3; k++) {
            lf_scene_desc d;
            lf_error err = {0};
            int rc = k == 2 ? lf_scene_parse_string(text, "window.pbrt", &d, &err)
                            : lf_scene_parse_file(path_of(k ? "window.pbrt.gz" : "window.pbrt"), &d, &err);
            if (rc) {
                if (bad++ < 3)
                    CHECK_MSG(0, "pad %zu, %s: %s", pad, k == 2 ? "text" : k ? "gzip" : "file", err.msg);
                continue;
            }
            const lf_param *r = lf_params_peek(&d.shapes[0].e.params, "radius");
            const lf_param *n = lf_params_peek(&d.shapes[0].e.params, "name");
            const lf_param *z = lf_params_peek(&d.shapes[0].e.params, "zmin");
            int same = d.n_shapes == 2 && r && r->nums[0] == 2.5 && n && n->n_strs == 1 &&
                       !strcmp(n->strs[0], "ab\"cd") && z && z->n_nums == 1 && z->nums[0] == -1.25 &&
                       d.shapes[0].e.loc.line == 3 && d.shapes[0].e.loc.col == (long long)pad + 1 &&
                       z->loc.line == 4 && z->loc.col == 26 && d.shapes[1].e.loc.line == 5;
            if (!same && bad++ < 3)
                CHECK_MSG(0, "pad %zu (%s): values or places differ", pad, k == 2 ? "text" : k ? "gzip" : "file");
            lf_scene_desc_free(&d);
        }
    }
    CHECK_MSG(bad == 0, "%zu parses differed", bad);
    /* a gzipped scene cut short after 100 KB: the parse reads up to the
     * damage, then names the file and what is wrong with it */
    memset(text + nh, ' ', 100000);
    memcpy(text + nh + 100000, body, nb + 1);
    size_t ng;
    unsigned char *g = gzip_stored(text, strlen(text), 4000, &ng);
    write_bytes("cut.pbrt.gz", g, ng - 10);
    free(g);
    lf_scene_desc d;
    lf_error err = {0};
    CHECK(lf_scene_parse_file(path_of("cut.pbrt.gz"), &d, &err) == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "cannot read scene file") && strstr(err.msg, "cut.pbrt.gz") &&
                  strstr(err.msg, "truncated"),
              "%s", err.msg);
    free(text);
}

/* pbrt-v4 resolves names against the main file's directory; lensfield tries
 * the naming file's directory first, then the main one. */
static void test_nested_paths(void)
{
    write_text("geometry/a.pbrt", "Include \"geometry/b.pbrt\"\n");      /* main-relative */
    write_text("geometry/b.pbrt", "Include \"c.pbrt\"\n");               /* relative to itself */
    write_text("geometry/c.pbrt", "Material \"dielectric\" \"spectrum eta\" \"spds/test.spd\"\nShape \"disk\"\n");
    char text[256];
    snprintf(text, sizeof text, "%sInclude \"geometry/a.pbrt\"\n", HEAD);
    write_text("nested.pbrt", text);
    lf_scene_desc d;
    lf_error err = {0};
    int rc = lf_scene_parse_file(path_of("nested.pbrt"), &d, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        CHECK(d.n_shapes == 1 && d.n_materials == 1 && strstr(d.shapes[0].e.loc.file, "geometry/c.pbrt"));
        const lf_param *p = lf_params_peek(&d.materials[0].e.params, "eta");
        CHECK(p && p->n_nums == 8 && p->nums[0] == 300);
        CHECK(d.scene_dir && strcmp(d.scene_dir, tmpdir) == 0);
        lf_scene_desc_free(&d);
    }
    /* neither place: the message names the first candidate */
    write_text("geometry/d.pbrt", "Include \"nowhere.pbrt\"\n");
    snprintf(text, sizeof text, "%sInclude \"geometry/d.pbrt\"\n", HEAD);
    write_text("nested2.pbrt", text);
    lf_error_clear(&err);
    CHECK(lf_scene_parse_file(path_of("nested2.pbrt"), &d, &err) == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, "geometry/d.pbrt:1:1: cannot open included file") &&
                  strstr(err.msg, "geometry/nowhere.pbrt"),
              "%s", err.msg);
}

/* .spd files: the same numbers as inline pairs, gzipped or not. */
static void test_spectrum_files(void)
{
    write_text("spds/test.spd", "# a test spectrum\n300 1.5  # first\n400 1.45\n\n550 1.44\n800\t1.4\n");
    write_gz("spds/test.spd.gz", "300 1.5\n400 1.45\n550 1.44\n800 1.4\n", 9);
    write_text("spds/bad.spd", "300 1.5\n400 x\n");
    write_text("spds/odd.spd", "300 1.5 400\n");
    write_text("spds/down.spd", "300 1.5\n200 1.4\n");
    char text[1024];
    snprintf(text, sizeof text,
             "%sMaterial \"dielectric\" \"spectrum eta\" \"spds/test.spd\"\n"
             "Material \"dielectric\" \"spectrum eta\" \"spds/test.spd.gz\"\n"
             "Material \"dielectric\" \"spectrum eta\" [300 1.5 400 1.45 550 1.44 800 1.4]\n"
             "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"\n",
             HEAD);
    write_text("spd.pbrt", text);
    lf_scene_desc d;
    lf_error err = {0};
    int rc = lf_scene_parse_file(path_of("spd.pbrt"), &d, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        CHECK(d.n_materials == 4);
        const lf_param *in = lf_params_peek(&d.materials[2].e.params, "eta");
        for (int m = 0; m < 2; m++) {
            const lf_param *p = lf_params_peek(&d.materials[m].e.params, "eta");
            CHECK(p && in && p->type == LF_PT_SPECTRUM && p->n_strs == 0 && p->n_nums == in->n_nums);
            if (p && in && p->n_nums == in->n_nums)
                CHECK(memcmp(p->nums, in->nums, p->n_nums * sizeof *p->nums) == 0);
            /* and the same RGB through the renderer's conversion */
            lf_vec3 a, b;
            lf_paramset *ps = &d.materials[m].e.params, *pi = &d.materials[2].e.params;
            lf_params_rgb(ps, "eta", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &a);
            lf_params_rgb(pi, "eta", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &b);
            CHECK(a.x == b.x && a.y == b.y && a.z == b.z && a.y > 1.4f && a.y < 1.5f);
        }
        /* named spectra stay names */
        const lf_param *au = lf_params_peek(&d.materials[3].e.params, "eta");
        CHECK(au && au->n_strs == 1 && strcmp(au->strs[0], "metal-Au-eta") == 0);
        lf_scene_desc_free(&d);
    }
    const char *bad[][2] = {{"spds/bad.spd", "spds/bad.spd:2: spectrum file: expected a number, got \"x\""},
                            {"spds/odd.spd", "found 3 numbers"},
                            {"spds/down.spd", "wavelengths must increase"},
                            {"spds/none.spd", "not a named spectrum"}};
    for (int i = 0; i < 4; i++) {
        snprintf(text, sizeof text, "%sMaterial \"dielectric\"\n  \"spectrum eta\" \"%s\"\n", HEAD, bad[i][0]);
        lf_error_clear(&err);
        rc = lf_scene_parse_string(text, path_of("x.pbrt"), &d, &err);
        CHECK(rc != 0);
        CHECK_MSG(strstr(err.msg, "x.pbrt:4:3:") && strstr(err.msg, bad[i][1]), "%s", err.msg);
    }
}

/* A metal's spectrum from a file, reduced to RGB by the renderer, against an
 * independent integration here: the CIE 1931 observer through Wyman, Sloan
 * and Shirley's published multi-lobe fit (JCGT 2013), sRGB's XYZ->RGB
 * matrix, Simpson's rule at 0.25 nm over the table's piecewise-linear
 * interpolant, divided channel-wise by a constant 1 (docs/scene-format.md).
 * Data: gold n and k, Hagemann, Gudat and Kunz, DESY report SR-74/7 (1974),
 * table 5 (photon energies converted to nm). */
static double g3(double x, double mu, double s1, double s2)
{
    double t = (x - mu) / (x < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

static void cmf(double l, double xyz[3])
{
    xyz[0] = 1.056 * g3(l, 599.8, 37.9, 31.0) + 0.362 * g3(l, 442.0, 16.0, 26.7) - 0.065 * g3(l, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * g3(l, 568.8, 46.9, 40.5) + 0.286 * g3(l, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * g3(l, 437.0, 11.8, 36.0) + 0.681 * g3(l, 459.0, 26.0, 13.8);
}

static double lerp_table(const double *t, int n, double l)
{
    if (l < t[0] || l > t[2 * (n - 1)])
        return 0;
    for (int i = 0; i + 1 < n; i++)
        if (l <= t[2 * i + 2])
            return t[2 * i + 1] + (l - t[2 * i]) / (t[2 * i + 2] - t[2 * i]) * (t[2 * i + 3] - t[2 * i + 1]);
    return t[2 * n - 1];
}

static void independent_rgb(const double *t, int n, double rgb[3])
{
    static const double M[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                   {-0.9692660, 1.8760108, 0.0415560},
                                   {0.0556434, -0.2040259, 1.0572252}};
    double xyz[3] = {0, 0, 0}, wxyz[3] = {0, 0, 0};
    const double a = 360, b = 830, h = 0.25;
    int steps = (int)((b - a) / h);
    for (int i = 0; i <= steps; i++) {
        double l = a + i * h, w = (i == 0 || i == steps) ? 1 : (i % 2 ? 4 : 2), c[3];
        cmf(l, c);
        double v = lerp_table(t, n, l);
        for (int k = 0; k < 3; k++) {
            xyz[k] += w * v * c[k];
            wxyz[k] += w * c[k];
        }
    }
    for (int r = 0; r < 3; r++) {
        double num = 0, den = 0;
        for (int k = 0; k < 3; k++) {
            num += M[r][k] * xyz[k];
            den += M[r][k] * wxyz[k];
        }
        rgb[r] = num / den;
    }
}

static void test_metal_spectrum_rgb(void)
{
    static const double au_n[] = {281.7, 1.848, 295.2, 1.927, 309.9, 1.995, 326.2, 2.039, 344.4, 2.024, 359.3, 1.967,
                                  375.7, 1.960, 393.6, 1.960, 413.2, 1.950, 442.8, 1.826, 476.8, 1.541, 516.6, 0.878,
                                  563.5, 0.613, 619.9, 0.487, 826.5, 0.418, 1239.8, 0.375};
    static const double au_k[] = {281.7, 1.87, 295.2, 1.89, 309.9, 1.88, 326.2, 1.86, 344.4, 1.81, 359.3, 1.84,
                                  375.7, 1.88, 393.6, 1.89, 413.2, 1.86, 442.8, 1.81, 476.8, 1.71, 516.6, 2.01,
                                  563.5, 2.64, 619.9, 3.31, 826.5, 5.13, 1239.8, 8.36};
    const double *tabs[2] = {au_n, au_k};
    const char *files[2] = {"spds/au-n.spd", "spds/au-k.spd.gz"};
    for (int m = 0; m < 2; m++) {
        char text[2048] = "# gold (Hagemann et al. 1974)\n";
        for (int i = 0; i < 16; i++)
            snprintf(text + strlen(text), sizeof text - strlen(text), "%g %g\n", tabs[m][2 * i], tabs[m][2 * i + 1]);
        if (m)
            write_gz(files[m], text, 64);
        else
            write_text(files[m], text);
    }
    char scene[512];
    snprintf(scene, sizeof scene, "%sMaterial \"conductor\" \"spectrum eta\" \"%s\" \"spectrum k\" \"%s\"\n", HEAD,
             files[0], files[1]);
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_string(scene, path_of("au.pbrt"), &d, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return;
    }
    const char *names[2] = {"eta", "k"};
    for (int m = 0; m < 2; m++) {
        lf_vec3 c;
        CHECK(lf_params_rgb(&d.materials[0].e.params, names[m], LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &c) == 1);
        double want[3];
        independent_rgb(tabs[m], 16, want);
        /* 1 nm Riemann sum vs Simpson at 0.25 nm, float result: 2e-3 */
        CHECK_NEAR(c.x, want[0], 2e-3 * fabs(want[0]) + 1e-3);
        CHECK_NEAR(c.y, want[1], 2e-3 * fabs(want[1]) + 1e-3);
        CHECK_NEAR(c.z, want[2], 2e-3 * fabs(want[2]) + 1e-3);
    }
    /* gold: eta lowest in red, k highest in red */
    lf_vec3 eta, k;
    lf_params_rgb(&d.materials[0].e.params, "eta", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &eta);
    lf_params_rgb(&d.materials[0].e.params, "k", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &k);
    CHECK(eta.x < eta.y && eta.y < eta.z && k.x > k.y && k.y > k.z);
    lf_scene_desc_free(&d);
}

/* Errors are collected; unsupported features are errors unless allowed. */
static void test_errors_collected(void)
{
    const char *text = "Camera \"perspective\"\nWorldBegin\n"
                       "LightSource \"goniometric\" \"string filename\" \"x.exr\"\n" /* 3: unsupported */
                       "Shape \"sphere\" \"float radius\" [ 1\n"                  /* 4: unclosed [ */
                       "Bogus 1 2 3\n"                                             /* 5: unknown directive */
                       "Texture \"p\" \"float\" \"ptex\"\n"                       /* 6: unsupported */
                       "Shape \"sphere\" Shapo \"disk\"\n"
                       "LightSource \"projection\"\n"; /* 8: unsupported */
    lf_scene_desc d;
    lf_error err = {0};
    char *errors = NULL;
    int rc = lf_scene_parse_string_ex(text, "multi.pbrt", NULL, &d, &err, &errors);
    CHECK(rc != 0 && errors != NULL);
    int lines = 0;
    for (const char *p = errors; p && *p; p++)
        lines += *p == '\n';
    CHECK_MSG(lines == 6, "want 6 errors, got:\n%s", errors ? errors : "");
    const char *want[] = {"multi.pbrt:3:1: LightSource \"goniometric\" is not supported", "multi.pbrt:5:1: expected a value or ']'",
                          "multi.pbrt:5:1: unknown directive \"Bogus\"",
                          "multi.pbrt:6:1: Texture \"ptex\" is not supported",
                          "multi.pbrt:7:16: unknown directive \"Shapo\"",
                          "multi.pbrt:8:1: LightSource \"projection\" is not supported"};
    for (int i = 0; i < 6; i++)
        CHECK_MSG(errors && strstr(errors, want[i]), "missing \"%s\" in:\n%s", want[i], errors ? errors : "");
    CHECK(strstr(err.msg, want[0]) != NULL); /* err keeps the first */
    free(errors);

    /* the limit */
    char many[4096] = "WorldBegin\n";
    for (int i = 0; i < 30; i++)
        strcat(many, "Nope\n");
    lf_parse_opts o = {0, 7};
    rc = lf_scene_parse_string_ex(many, "many.pbrt", &o, &d, &err, &errors);
    lines = 0;
    for (const char *p = errors; p && *p; p++)
        lines += *p == '\n';
    CHECK(rc != 0 && lines == 8 && strstr(errors, "stopped after 7 errors"));
    free(errors);

    /* --allow-unsupported: warnings, the rest is kept */
    const char *text2 = "Camera \"perspective\"\nWorldBegin\n"
                        "Shape \"teapot\"\nMaterial \"velvet\" \"float eta\" 1.3\nShape \"sphere\"\n"
                        "LightSource \"goniometric\"\nMakeNamedMaterial \"m\" \"string type\" \"velvet\"\n"
                        "Texture \"w\" \"spectrum\" \"ptex\" \"float scale\" 2\n";
    lf_parse_opts allow = {1, 0};
    rc = lf_scene_parse_string_ex(text2, "allow.pbrt", &allow, &d, &err, &errors);
    CHECK_MSG(rc == 0, "%s", err.msg);
    if (!rc) {
        CHECK(d.n_shapes == 1 && strcmp(d.shapes[0].e.type, "sphere") == 0 && d.n_lights == 0);
        CHECK(d.n_materials == 2 && strcmp(d.materials[0].e.type, "diffuse") == 0 &&
              d.materials[0].e.params.count == 0 && strcmp(d.materials[1].e.type, "diffuse") == 0);
        CHECK(d.allow_unsupported == 1);
        CHECK(d.warnings && strstr(d.warnings, "allow.pbrt:3:1: warning: Shape: unknown shape \"teapot\" is not supported"));
        CHECK(d.warnings && strstr(d.warnings, "allow.pbrt:4:1: warning: Material: unknown material \"velvet\" is not "
                                               "supported; rendered as \"diffuse\" 0.5"));
        CHECK(d.warnings && strstr(d.warnings, "allow.pbrt:6:1: warning: LightSource \"goniometric\""));
        CHECK(d.warnings && strstr(d.warnings, "allow.pbrt:7:1: warning: MakeNamedMaterial: unknown material \"velvet\""));
        CHECK(d.n_textures == 1 && strcmp(d.textures[0].e.type, "constant") == 0 &&
              d.textures[0].e.params.count == 0);
        CHECK(d.warnings && strstr(d.warnings, "allow.pbrt:8:1: warning: Texture \"ptex\" is not supported; "
                                               "rendered as \"constant\" 1"));
        lf_scene_desc_free(&d);
    }
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lf_files_XXXXXX");
    CHECK(mkdtemp(tmpdir) != NULL);
    char sub[300];
    snprintf(sub, sizeof sub, "%s/spds", tmpdir);
    mkdir(sub, 0755);
    snprintf(sub, sizeof sub, "%s/geometry", tmpdir);
    mkdir(sub, 0755);
    test_file_read();
    test_include_tokens();
    test_window_boundaries();
    test_spectrum_files();
    test_nested_paths();
    test_metal_spectrum_rgb();
    test_errors_collected();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmpdir);
    return lf_test_end();
}
