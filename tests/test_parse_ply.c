/* PLY reading (scenefile/ply.c): the same quad + triangle written as ascii,
 * binary little- and big-endian with different scalar types, read back. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lf_test.h"
#include "scenefile/lf_scene_desc.h"

static char dir[256];
static char paths[32][512];
static int n_paths;

static const char *tmp_path(const char *name)
{
    char *p = paths[n_paths++];
    snprintf(p, 512, "%s/%s", dir, name);
    return p;
}

/* The test mesh: a unit quad 0-1-2-3 and a triangle 1-4-2 beside it. */
static const double V[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0.5, 0}};
static const double UV[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {2, 0.5}};
/* pbrt splits a quad (a,b,c,d) into (a,b,c) (a,c,d). */
static const int TRIS[3][3] = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};

static void check_mesh(const lf_ply_mesh *m, int want_normals, int want_uv)
{
    CHECK(m->n_vertices == 5);
    CHECK(m->n_triangles == 3);
    if (m->n_vertices != 5 || m->n_triangles != 3)
        return;
    for (int i = 0; i < 5; i++)
        for (int k = 0; k < 3; k++)
            CHECK_NEAR(m->P[3 * i + k], V[i][k], 1e-6);
    for (int t = 0; t < 3; t++)
        for (int k = 0; k < 3; k++)
            CHECK(m->indices[3 * t + k] == TRIS[t][k]);
    CHECK((m->N != NULL) == want_normals);
    if (m->N)
        for (int i = 0; i < 5; i++)
            CHECK(m->N[3 * i] == 0.f && m->N[3 * i + 1] == 0.f && m->N[3 * i + 2] == 1.f);
    CHECK((m->uv != NULL) == want_uv);
    if (m->uv)
        for (int i = 0; i < 5; i++) {
            CHECK_NEAR(m->uv[2 * i], UV[i][0], 1e-6);
            CHECK_NEAR(m->uv[2 * i + 1], UV[i][1], 1e-6);
        }
}

/* Writes v as a `size`-byte scalar in the given byte order, independent of
 * the host's. */
static void put_bytes(FILE *f, uint64_t bits, int size, int big)
{
    for (int i = 0; i < size; i++) {
        int shift = big ? 8 * (size - 1 - i) : 8 * i;
        fputc((int)((bits >> shift) & 0xff), f);
    }
}

static void put_float(FILE *f, float v, int big)
{
    uint32_t b;
    memcpy(&b, &v, 4);
    put_bytes(f, b, 4, big);
}

static void put_double(FILE *f, double v, int big)
{
    uint64_t b;
    memcpy(&b, &v, 8);
    put_bytes(f, b, 8, big);
}

static void test_ascii(void)
{
    const char *p = tmp_path("ascii.ply");
    FILE *f = fopen(p, "w");
    fputs("ply\r\nformat ascii 1.0\r\ncomment made by a test\r\nelement vertex 5\r\n"
          "property float x\r\nproperty float y\r\nproperty float z\r\n"
          "property float texture_u\r\nproperty float texture_v\r\n"
          "element face 2\r\nproperty list uchar int vertex_indices\r\nend_header\r\n",
          f);
    for (int i = 0; i < 5; i++)
        fprintf(f, "%g %g %g %g %g\r\n", V[i][0], V[i][1], V[i][2], UV[i][0], UV[i][1]);
    fputs("4 0 1 2 3\r\n3 1 4 2\r\n", f);
    fclose(f);
    lf_ply_mesh m;
    lf_error err = {0};
    int rc = lf_ply_read(p, &m, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (!rc) {
        check_mesh(&m, 0, 1);
        lf_ply_free(&m);
        CHECK(m.P == NULL && m.indices == NULL);
    }
}

static void test_binary_le(void)
{
    const char *p = tmp_path("le.ply");
    FILE *f = fopen(p, "wb");
    fputs("ply\nformat binary_little_endian 1.0\nelement vertex 5\n"
          "property float x\nproperty float y\nproperty float z\n"
          "property float nx\nproperty float ny\nproperty float nz\n"
          "property uchar red\nproperty float u\nproperty float v\n"
          "element edge 2\nproperty int a\nproperty list uchar float weights\n"
          "element face 2\nproperty int flags\nproperty list uchar int vertex_indices\nend_header\n",
          f);
    for (int i = 0; i < 5; i++) {
        for (int k = 0; k < 3; k++)
            put_float(f, (float)V[i][k], 0);
        put_float(f, 0, 0);
        put_float(f, 0, 0);
        put_float(f, 1, 0);
        fputc(200, f);
        put_float(f, (float)UV[i][0], 0);
        put_float(f, (float)UV[i][1], 0);
    }
    for (int e = 0; e < 2; e++) { /* skipped element with a list */
        put_bytes(f, 7, 4, 0);
        fputc(2, f);
        put_float(f, 0.5f, 0);
        put_float(f, 0.25f, 0);
    }
    put_bytes(f, 0xdeadbeef, 4, 0);
    fputc(4, f);
    for (int k = 0; k < 4; k++)
        put_bytes(f, (uint64_t)k, 4, 0);
    put_bytes(f, 1, 4, 0);
    fputc(3, f);
    put_bytes(f, 1, 4, 0);
    put_bytes(f, 4, 4, 0);
    put_bytes(f, 2, 4, 0);
    fclose(f);
    lf_ply_mesh m;
    lf_error err = {0};
    int rc = lf_ply_read(p, &m, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (!rc) {
        check_mesh(&m, 1, 1);
        lf_ply_free(&m);
    }

    /* The same file cut short: truncated data names the path. */
    FILE *in = fopen(p, "rb");
    fseek(in, 0, SEEK_END);
    long len = ftell(in);
    fseek(in, 0, SEEK_SET);
    char *buf = malloc((size_t)len);
    CHECK(fread(buf, 1, (size_t)len, in) == (size_t)len);
    fclose(in);
    const char *t = tmp_path("truncated.ply");
    FILE *out = fopen(t, "wb");
    fwrite(buf, 1, (size_t)len - 6, out);
    fclose(out);
    free(buf);
    rc = lf_ply_read(t, &m, &err);
    CHECK(rc == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, t) && strstr(err.msg, "unexpected end of data"), "%s", err.msg);
    CHECK(m.P == NULL && m.indices == NULL);
}

static void test_binary_be(void)
{
    const char *p = tmp_path("be.ply");
    FILE *f = fopen(p, "wb");
    fputs("ply\nformat binary_big_endian 1.0\nobj_info big endian doubles\nelement vertex 5\n"
          "property double x\nproperty double y\nproperty double z\nproperty int16 extra\n"
          "property float32 s\nproperty float32 t\n"
          "element face 3\nproperty list ushort uint vertex_index\nend_header\n",
          f);
    for (int i = 0; i < 5; i++) {
        for (int k = 0; k < 3; k++)
            put_double(f, V[i][k], 1);
        put_bytes(f, (uint16_t)-3, 2, 1);
        put_float(f, (float)UV[i][0], 1);
        put_float(f, (float)UV[i][1], 1);
    }
    put_bytes(f, 4, 2, 1);
    for (int k = 0; k < 4; k++)
        put_bytes(f, (uint64_t)k, 4, 1);
    put_bytes(f, 3, 2, 1);
    put_bytes(f, 1, 4, 1);
    put_bytes(f, 4, 4, 1);
    put_bytes(f, 2, 4, 1);
    /* A pentagon, fan-triangulated: (0,1,2) (0,2,3) (0,3,4). */
    put_bytes(f, 5, 2, 1);
    for (int k = 0; k < 5; k++)
        put_bytes(f, (uint64_t)k, 4, 1);
    fclose(f);
    lf_ply_mesh m;
    lf_error err = {0};
    int rc = lf_ply_read(p, &m, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (!rc) {
        CHECK(m.n_triangles == 6);
        /* The first three are the quad and triangle; check them and the fan. */
        size_t keep = m.n_triangles;
        m.n_triangles = 3;
        check_mesh(&m, 0, 1);
        m.n_triangles = keep;
        static const int fan[3][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
        for (int t = 0; t < 3; t++)
            for (int k = 0; k < 3; k++)
                CHECK(m.indices[3 * (3 + t) + k] == fan[t][k]);
        lf_ply_free(&m);
    }
}

static void expect_fail(const char *name, const char *text, int code, const char *want)
{
    const char *p = tmp_path(name);
    FILE *f = fopen(p, "w");
    fputs(text, f);
    fclose(f);
    lf_ply_mesh m;
    lf_error err = {0};
    int rc = lf_ply_read(p, &m, &err);
    CHECK_MSG(rc == code, "%s: rc %d: %s", name, rc, err.msg);
    char full[700];
    snprintf(full, sizeof full, "%s%s", p, want);
    CHECK_MSG(strstr(err.msg, full) != NULL, "message \"%s\" lacks \"%s\"", err.msg, full);
    CHECK(m.P == NULL && m.N == NULL && m.uv == NULL && m.indices == NULL);
}

#define HDR "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
#define FACE "element face 1\nproperty list uchar int vertex_indices\nend_header\n"

static void test_malformed(void)
{
    /* 9 header lines and 3 vertex lines: the face is on line 13. */
    expect_fail("range.ply", HDR FACE "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", LF_ERR_PARSE,
                ":13: vertex index out of range: 9 in face 0 (3 vertices)");
    expect_fail("negative.ply", HDR FACE "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", LF_ERR_PARSE,
                ":13: vertex index out of range");
    expect_fail("short.ply", HDR FACE "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", LF_ERR_PARSE,
                ":13: unexpected end of data reading list \"vertex_indices\" of face 0");
    expect_fail("garbage.ply", HDR FACE "0 0 0\n1 abc 0\n", LF_ERR_PARSE, ":11: bad value for \"y\" of vertex 1");
    expect_fail("nan.ply", HDR FACE "0 0 0\n1 nan 0\n", LF_ERR_PARSE, ":11: bad value for \"y\" of vertex 1");
    expect_fail("fracindex.ply", HDR FACE "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", LF_ERR_PARSE, ":13: bad value in list");
    expect_fail("magic.ply", "plx\nformat ascii 1.0\n", LF_ERR_PARSE, ":1: not a PLY file");
    expect_fail("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", LF_ERR_PARSE,
                ":2: bad PLY header: unknown format binary_middle_endian");
    expect_fail("version.ply", "ply\nformat ascii 2.0\nend_header\n", LF_ERR_PARSE,
                ":2: bad PLY header: unsupported version 2.0");
    expect_fail("noend.ply", HDR "element face 0\n", LF_ERR_PARSE, ":7: bad PLY header: end of file before end_header");
    expect_fail("orphan.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n", LF_ERR_PARSE,
                ":3: bad PLY header: property before any element");
    expect_fail("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty flaot x\nend_header\n", LF_ERR_PARSE,
                ":4: bad PLY header: unknown property type x");
    expect_fail("keyword.ply", "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n", LF_ERR_PARSE,
                ":3: bad PLY header: unknown keyword elemnt");
    expect_fail("noformat.ply", "ply\nelement vertex 0\nend_header\n", LF_ERR_PARSE, ":3: bad PLY header: no format");
    expect_fail("nox.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\n" FACE "0 0\n3 0 0 0\n",
                LF_ERR_PARSE, ": no \"vertex\" element with x, y and z");
    expect_fail("noface.ply", HDR "end_header\n0 0 0\n1 0 0\n0 1 0\n", LF_ERR_PARSE, ": no \"face\" element");

    lf_ply_mesh m;
    lf_error err = {0};
    const char *missing = tmp_path("does-not-exist.ply");
    CHECK(lf_ply_read(missing, &m, &err) == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, missing) != NULL, "%s", err.msg);
    n_paths--; /* never created */

    /* A lone "u" (no "v") or "nx" (no "ny nz") is skipped, not half-read. */
    const char *partial = tmp_path("partial.ply");
    FILE *pf = fopen(partial, "w");
    fputs(HDR "property float u\nproperty float nx\n" FACE "0 0 0 5 1\n1 0 0 5 1\n0 1 0 5 1\n3 0 1 2\n", pf);
    fclose(pf);
    CHECK_MSG(lf_ply_read(partial, &m, &err) == LF_OK, "%s", err.msg);
    CHECK(m.uv == NULL && m.N == NULL && m.n_triangles == 1 && m.P[3] == 1.f);
    lf_ply_free(&m);

    /* Degenerate faces (fewer than 3 vertices) are dropped, as in pbrt. */
    const char *p = tmp_path("degenerate.ply");
    FILE *f = fopen(p, "w");
    fputs(HDR "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"
              "3 0 1 2\n",
          f);
    fclose(f);
    lf_error_clear(&err);
    CHECK_MSG(lf_ply_read(p, &m, &err) == LF_OK, "%s", err.msg);
    CHECK(m.n_triangles == 1);
    lf_ply_free(&m);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/lf_ply_XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_ascii();
    test_binary_le();
    test_binary_be();
    test_malformed();
    for (int i = 0; i < n_paths; i++)
        unlink(paths[i]);
    rmdir(dir);
    return lf_test_end();
}
