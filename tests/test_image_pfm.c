/* PFM (Portable Float Map) through lf_image_read / lf_image_write: files
 * built byte by byte here (both byte orders, rows bottom-up), round trips
 * of 1 and 3 channels, and malformed files named in clear errors. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"

static char dir[256];

static void put_f32(unsigned char *p, float v, int big)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    for (int i = 0; i < 4; i++)
        p[big ? 3 - i : i] = (unsigned char)(u >> (8 * i));
}

static void write_bytes(const char *path, const void *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    fwrite(b, 1, n, f);
    fclose(f);
}

/* A 3 x 2 grey image whose top row is 1 2 3 and bottom row 4 5 6: the file
 * stores the bottom row first. */
static void test_hand_built(int big)
{
    char path[512];
    snprintf(path, sizeof path, "%s/hand_%s.pfm", dir, big ? "be" : "le");
    unsigned char buf[256];
    int n = snprintf((char *)buf, sizeof buf, "Pf\n3 2\n%s\n", big ? "1.0" : "-1.0");
    const float file_order[6] = {4, 5, 6, 1, 2, 3};
    for (int i = 0; i < 6; i++)
        put_f32(buf + n + 4 * i, file_order[i], big);
    write_bytes(path, buf, (size_t)n + 24);
    lf_image img;
    lf_error err = {0};
    CHECK(lf_image_read(path, &img, NULL, &err) == 0);
    CHECK(img.width == 3 && img.height == 2 && img.channels == 1);
    if (img.data) {
        const float top_first[6] = {1, 2, 3, 4, 5, 6};
        CHECK(memcmp(img.data, top_first, sizeof top_first) == 0);
    }
    lf_image_free(&img);
}

/* What lf_image_write produces, byte for byte: header, then little-endian
 * floats, bottom row first. */
static void test_written_bytes(void)
{
    lf_image img;
    lf_error err = {0};
    CHECK(lf_image_alloc(&img, 2, 2, 3, &err) == 0);
    for (int i = 0; i < 12; i++)
        img.data[i] = (float)(i + 0.25 * i * i);
    char path[512];
    snprintf(path, sizeof path, "%s/rgb.pfm", dir);
    CHECK(lf_image_write(path, &img, NULL, NULL, &err) == 0);
    unsigned char got[256];
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(got, 1, sizeof got, f) : 0;
    if (f)
        fclose(f);
    unsigned char want[256];
    int h = snprintf((char *)want, sizeof want, "PF\n2 2\n-1.0\n");
    for (int y = 1, k = 0; y >= 0; y--)
        for (int i = 0; i < 6; i++, k++)
            put_f32(want + h + 4 * k, img.data[y * 6 + i], 0);
    CHECK(n == (size_t)h + 48);
    CHECK(n == (size_t)h + 48 && memcmp(got, want, n) == 0);
    /* and back */
    lf_image back;
    CHECK(lf_image_read(path, &back, NULL, &err) == 0);
    CHECK(back.width == 2 && back.height == 2 && back.channels == 3 && back.data &&
          memcmp(back.data, img.data, 12 * sizeof(float)) == 0);
    lf_image_free(&back);
    lf_image_free(&img);
}

static void test_round_trip_grey(void)
{
    lf_image img, back;
    lf_error err = {0};
    CHECK(lf_image_alloc(&img, 17, 5, 1, &err) == 0);
    for (int i = 0; i < 85; i++)
        img.data[i] = (float)(-1.7 + 0.0371 * i * (i % 3 ? 1 : -1));
    char path[512];
    snprintf(path, sizeof path, "%s/grey.pfm", dir);
    CHECK(lf_image_write(path, &img, NULL, NULL, &err) == 0);
    CHECK(lf_image_read(path, &back, NULL, &err) == 0);
    CHECK(back.width == 17 && back.height == 5 && back.channels == 1 && back.data &&
          memcmp(back.data, img.data, 85 * sizeof(float)) == 0);
    lf_image_free(&back);
    /* 2 or 4 channels do not fit PFM: refused, nothing written */
    lf_image two;
    CHECK(lf_image_alloc(&two, 2, 2, 2, &err) == 0);
    snprintf(path, sizeof path, "%s/two.pfm", dir);
    lf_error e2 = {0};
    CHECK(lf_image_write(path, &two, NULL, NULL, &e2) != 0);
    CHECK(strstr(e2.msg, "two.pfm") && strstr(e2.msg, "1 or 3 channels"));
    CHECK(access(path, F_OK) != 0);
    lf_image_free(&two);
    lf_image_free(&img);
}

static void expect_bad(const char *name, const void *bytes, size_t n, const char *what)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    write_bytes(path, bytes, n);
    lf_image img;
    lf_error err = {0};
    CHECK_MSG(lf_image_read(path, &img, NULL, &err) != 0, "%s read", name);
    CHECK_MSG(strstr(err.msg, name) && strstr(err.msg, what), "%s: message \"%s\" lacks \"%s\"", name, err.msg, what);
}

static void test_malformed(void)
{
    unsigned char trunc[64];
    int n = snprintf((char *)trunc, sizeof trunc, "PF\n4 4\n-1\n");
    memset(trunc + n, 0, 20);
    expect_bad("short.pfm", trunc, (size_t)n + 20, "ends early");
    expect_bad("header.pfm", "PF\n4\n", 5, "header");
    expect_bad("size.pfm", "Pf\n-3 2\n-1\n", 11, "bad PFM header");
    expect_bad("scale.pfm", "Pf\n3 2\n0\n", 9, "bad PFM header");
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/test_image_pfm.XXXXXX", P_tmpdir);
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_hand_built(0);
    test_hand_built(1);
    test_written_bytes();
    test_round_trip_grey();
    test_malformed();
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) {
    }
    return lf_test_end();
}
