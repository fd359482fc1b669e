/* test_image_io.c - lf_image files, attributes, sRGB and comparison.
 *
 * Every file lives in a fresh mkdtemp() directory under /tmp, which must
 * hold exactly the expected files after each step: a leftover temporary
 * file means an atomic write failed to clean up.
 */
#include "image/lf_image.h"

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lf_test.h"

/* Fixtures written by OpenImageIO's oiiotool (the C++ OpenEXR library, so an
 * independent writer) from a 6x5 RGBA image with value
 * (x + 8y)/64 + c/4 and a 3x2 Y image with value index/5 (OpenImageIO
 * stores UINT as the value times 2^32-1):
 *   oiiotool --nosoftwareattrib src4.exr --origin +3+2 -d half --tile 4 4 \
 *            --compression zip -o tiled4s.exr
 *   oiiotool --nosoftwareattrib src1.exr --origin -1-1 -d uint32 \
 *            --compression none -o uint1s.exr
 * and embedded with `xxd -i`. */
static const unsigned char tiled4s_exr[] = {
  0x76, 0x2f, 0x31, 0x01, 0x02, 0x02, 0x00, 0x00, 0x63, 0x61, 0x70, 0x44,
  0x61, 0x74, 0x65, 0x00, 0x73, 0x74, 0x72, 0x69, 0x6e, 0x67, 0x00, 0x13,
  0x00, 0x00, 0x00, 0x32, 0x30, 0x32, 0x36, 0x3a, 0x31, 0x31, 0x3a, 0x32,
  0x32, 0x20, 0x30, 0x38, 0x3a, 0x30, 0x30, 0x3a, 0x31, 0x33, 0x63, 0x68,
  0x61, 0x6e, 0x6e, 0x65, 0x6c, 0x73, 0x00, 0x63, 0x68, 0x6c, 0x69, 0x73,
  0x74, 0x00, 0x49, 0x00, 0x00, 0x00, 0x41, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x42, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00,
  0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x47, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x52, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00,
  0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x63, 0x6f, 0x6d, 0x70, 0x72,
  0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e, 0x00, 0x63, 0x6f, 0x6d, 0x70, 0x72,
  0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e, 0x00, 0x01, 0x00, 0x00, 0x00, 0x03,
  0x64, 0x61, 0x74, 0x61, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x00, 0x62,
  0x6f, 0x78, 0x32, 0x69, 0x00, 0x10, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00,
  0x00, 0x02, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00,
  0x00, 0x64, 0x69, 0x73, 0x70, 0x6c, 0x61, 0x79, 0x57, 0x69, 0x6e, 0x64,
  0x6f, 0x77, 0x00, 0x62, 0x6f, 0x78, 0x32, 0x69, 0x00, 0x10, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00,
  0x00, 0x04, 0x00, 0x00, 0x00, 0x6c, 0x69, 0x6e, 0x65, 0x4f, 0x72, 0x64,
  0x65, 0x72, 0x00, 0x6c, 0x69, 0x6e, 0x65, 0x4f, 0x72, 0x64, 0x65, 0x72,
  0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x70, 0x69, 0x78, 0x65, 0x6c, 0x41,
  0x73, 0x70, 0x65, 0x63, 0x74, 0x52, 0x61, 0x74, 0x69, 0x6f, 0x00, 0x66,
  0x6c, 0x6f, 0x61, 0x74, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80,
  0x3f, 0x73, 0x63, 0x72, 0x65, 0x65, 0x6e, 0x57, 0x69, 0x6e, 0x64, 0x6f,
  0x77, 0x43, 0x65, 0x6e, 0x74, 0x65, 0x72, 0x00, 0x76, 0x32, 0x66, 0x00,
  0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x73, 0x63, 0x72, 0x65, 0x65, 0x6e, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77,
  0x57, 0x69, 0x64, 0x74, 0x68, 0x00, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x00,
  0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x74, 0x69, 0x6c, 0x65,
  0x73, 0x00, 0x74, 0x69, 0x6c, 0x65, 0x64, 0x65, 0x73, 0x63, 0x00, 0x09,
  0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00,
  0x00, 0xad, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x05, 0x02, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x4f, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x80, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x44, 0x00, 0x00, 0x00, 0x78, 0x5e, 0x63, 0x58, 0xb0, 0x60, 0x81,
  0x02, 0x08, 0x1f, 0x00, 0x82, 0x06, 0x20, 0x40, 0xe6, 0x33, 0x00, 0xc1,
  0x84, 0x09, 0x13, 0x02, 0x90, 0xc4, 0x1c, 0x80, 0xfc, 0x0b, 0x48, 0xfc,
  0x5f, 0x40, 0x2d, 0x75, 0x40, 0x5c, 0x03, 0xc4, 0x3e, 0x4b, 0x5a, 0x9a,
  0x26, 0x42, 0xf9, 0xb5, 0x40, 0x5c, 0xd5, 0xd0, 0xd8, 0xd0, 0x0d, 0xe5,
  0xc3, 0xd4, 0x74, 0x00, 0x71, 0x3d, 0x92, 0x1a, 0x00, 0x9e, 0xc8, 0x41,
  0xb7, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x36, 0x00, 0x00, 0x00, 0x78, 0x5e, 0x6b,
  0x58, 0x90, 0xb0, 0xe0, 0xc1, 0x01, 0x87, 0x06, 0x06, 0x08, 0xcd, 0xe0,
  0x30, 0x61, 0x03, 0x98, 0xc5, 0x30, 0xc1, 0x00, 0x4c, 0x57, 0x35, 0xd4,
  0x35, 0xd4, 0x36, 0x94, 0x37, 0xf6, 0x01, 0xe9, 0xba, 0x86, 0xea, 0x86,
  0x2e, 0x30, 0x5d, 0xdb, 0xd0, 0xde, 0x50, 0x0f, 0x66, 0x01, 0x00, 0x2f,
  0x11, 0x20, 0xb8, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1d, 0x00, 0x00, 0x00, 0x78,
  0x5e, 0x63, 0x98, 0x30, 0x61, 0x42, 0x00, 0x08, 0x2f, 0x58, 0xb0, 0x40,
  0x01, 0x88, 0x63, 0x1b, 0x1a, 0x1a, 0xea, 0x81, 0xb8, 0x0e, 0x8a, 0x01,
  0xfe, 0x0c, 0x0f, 0xb9, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00,
  0x40, 0x3d, 0x50, 0x3d, 0x40, 0x3c, 0x50, 0x3c, 0x80, 0x3a, 0xa0, 0x3a,
  0x80, 0x38, 0xa0, 0x38
};

static const unsigned char uint1s_exr[] = {
  0x76, 0x2f, 0x31, 0x01, 0x02, 0x00, 0x00, 0x00, 0x63, 0x61, 0x70, 0x44,
  0x61, 0x74, 0x65, 0x00, 0x73, 0x74, 0x72, 0x69, 0x6e, 0x67, 0x00, 0x13,
  0x00, 0x00, 0x00, 0x32, 0x30, 0x32, 0x36, 0x3a, 0x31, 0x31, 0x3a, 0x32,
  0x32, 0x20, 0x30, 0x38, 0x3a, 0x30, 0x34, 0x3a, 0x30, 0x30, 0x63, 0x68,
  0x61, 0x6e, 0x6e, 0x65, 0x6c, 0x73, 0x00, 0x63, 0x68, 0x6c, 0x69, 0x73,
  0x74, 0x00, 0x13, 0x00, 0x00, 0x00, 0x59, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
  0x00, 0x63, 0x6f, 0x6d, 0x70, 0x72, 0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e,
  0x00, 0x63, 0x6f, 0x6d, 0x70, 0x72, 0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e,
  0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x64, 0x61, 0x74, 0x61, 0x57, 0x69,
  0x6e, 0x64, 0x6f, 0x77, 0x00, 0x62, 0x6f, 0x78, 0x32, 0x69, 0x00, 0x10,
  0x00, 0x00, 0x00, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x01,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x64, 0x69, 0x73, 0x70, 0x6c,
  0x61, 0x79, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x00, 0x62, 0x6f, 0x78,
  0x32, 0x69, 0x00, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x6c,
  0x69, 0x6e, 0x65, 0x4f, 0x72, 0x64, 0x65, 0x72, 0x00, 0x6c, 0x69, 0x6e,
  0x65, 0x4f, 0x72, 0x64, 0x65, 0x72, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00,
  0x70, 0x69, 0x78, 0x65, 0x6c, 0x41, 0x73, 0x70, 0x65, 0x63, 0x74, 0x52,
  0x61, 0x74, 0x69, 0x6f, 0x00, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x00, 0x04,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x73, 0x63, 0x72, 0x65, 0x65,
  0x6e, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x43, 0x65, 0x6e, 0x74, 0x65,
  0x72, 0x00, 0x76, 0x32, 0x66, 0x00, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x73, 0x63, 0x72, 0x65, 0x65, 0x6e,
  0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x57, 0x69, 0x64, 0x74, 0x68, 0x00,
  0x66, 0x6c, 0x6f, 0x61, 0x74, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x80, 0x3f, 0x00, 0x4b, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x5f,
  0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xff, 0xff, 0xff, 0xff, 0x0c,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0x33, 0x33, 0x33, 0x80,
  0x66, 0x66, 0x66, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x00, 0x00, 0x00, 0xff,
  0x99, 0x99, 0x99, 0xff, 0xcc, 0xcc, 0xcc, 0xff, 0xff, 0xff, 0xff
};


static char tmpdir[256];

static void path_in(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", tmpdir, name);
}

static int count_dir_entries(void)
{
    DIR *d = opendir(tmpdir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    if (d)
        closedir(d);
    return n;
}

static void clear_dir(void)
{
    DIR *d = opendir(tmpdir);
    struct dirent *e;
    char p[512];
    while (d && (e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        snprintf(p, sizeof p, "%s/%s", tmpdir, e->d_name);
        unlink(p);
    }
    if (d)
        closedir(d);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static unsigned char *slurp(const char *path, long *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)*size + 1);
    if (buf && fread(buf, 1, (size_t)*size, f) != (size_t)*size) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
}

static void spit(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(data, 1, size, f);
        fclose(f);
    }
}

/* Deterministic values covering signs, magnitudes and subnormals. */
static float test_value(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    uint32_t r = *state >> 8;
    switch (r % 5) {
    case 0:
        return (float)(r % 1000) / 999.0f;
    case 1:
        return -(float)(r % 777) * 3.5f;
    case 2:
        return 1e-40f * (float)(r % 7); /* subnormal */
    case 3:
        return 1e20f * (float)(r % 13);
    default:
        return (float)r * 1e-3f;
    }
}

static void fill_random(lf_image *img, uint32_t seed)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    for (size_t i = 0; i < n; i++)
        img->data[i] = test_value(&seed);
}

/* ------------------------------------------------------------------ sRGB */

static void test_srgb(void)
{
    CHECK(lf_srgb_encode(0.0f) == 0);
    CHECK(lf_srgb_encode(1.0f) == 255);
    CHECK(lf_srgb_encode(0.0031308f) == 10); /* 0.04045 * 255 = 10.31 */
    CHECK(lf_srgb_encode(0.5f) == 188);      /* 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5 */
    CHECK(lf_srgb_encode(0.18f) == 118);     /* 0.4614 * 255 = 117.66 */
    CHECK(lf_srgb_encode(-3.0f) == 0);
    CHECK(lf_srgb_encode(7.0f) == 255);
    CHECK(lf_srgb_encode(NAN) == 0);
    CHECK(lf_srgb_encode(INFINITY) == 255);
    CHECK(lf_srgb_decode(0) == 0.0f);
    CHECK_NEAR(lf_srgb_decode(255), 1.0, 1e-7);
    CHECK_NEAR(lf_srgb_decode(188), pow((188 / 255.0 + 0.055) / 1.055, 2.4), 1e-7);
    CHECK_NEAR(lf_srgb_decode(10), 10 / 255.0 / 12.92, 1e-9);
    int roundtrip = 1, monotonic = 1;
    for (int v = 0; v < 256; v++) {
        roundtrip &= lf_srgb_encode(lf_srgb_decode((unsigned char)v)) == v;
        if (v)
            monotonic &= lf_srgb_decode((unsigned char)v) > lf_srgb_decode((unsigned char)(v - 1));
    }
    CHECK(roundtrip);
    CHECK(monotonic);
}

/* ------------------------------------------------------------ attributes */

static const double test_m44[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0.1};
static const float test_floats[5] = {0.5f, -1.25f, 3e10f, 1e-30f, 0.1f};

static void set_test_attrs(lf_attrs *a)
{
    CHECK(lf_attrs_set_string(a, "lensfield:camera", "realistic", NULL) == 0);
    CHECK(lf_attrs_set_string(a, "lensfield:empty", "", NULL) == 0);
    CHECK(lf_attrs_set_int(a, "lensfield:spp", -123456, NULL) == 0);
    CHECK(lf_attrs_set_float(a, "lensfield:fstop", 2.8f, NULL) == 0);
    CHECK(lf_attrs_set_double(a, "lensfield:focus_distance", 1.0 / 3.0, NULL) == 0);
    CHECK(lf_attrs_set_floats(a, "lensfield:weights", test_floats, 5, NULL) == 0);
    CHECK(lf_attrs_set_m44d(a, "lensfield:camera_to_world", test_m44, NULL) == 0);
    /* Longer than the 31 bytes of a classic EXR name. */
    CHECK(lf_attrs_set_int(a, "lensfield:a_rather_long_attribute_name_over_31", 7, NULL) == 0);
}

static void check_test_attrs(const lf_attrs *a)
{
    const lf_attr *at = lf_attrs_get(a, "lensfield:camera");
    CHECK(at && at->type == LF_ATTR_STRING && strcmp(at->s, "realistic") == 0);
    at = lf_attrs_get(a, "lensfield:empty");
    CHECK(at && at->type == LF_ATTR_STRING && at->s && at->s[0] == '\0');
    at = lf_attrs_get(a, "lensfield:spp");
    CHECK(at && at->type == LF_ATTR_INT && at->i == -123456);
    at = lf_attrs_get(a, "lensfield:fstop");
    CHECK(at && at->type == LF_ATTR_FLOAT && at->d == (double)2.8f);
    at = lf_attrs_get(a, "lensfield:focus_distance");
    CHECK(at && at->type == LF_ATTR_DOUBLE && at->d == 1.0 / 3.0);
    at = lf_attrs_get(a, "lensfield:weights");
    CHECK(at && at->type == LF_ATTR_FLOATS && at->n == 5 && memcmp(at->v, test_floats, sizeof test_floats) == 0);
    at = lf_attrs_get(a, "lensfield:camera_to_world");
    CHECK(at && at->type == LF_ATTR_M44D && memcmp(at->m, test_m44, sizeof test_m44) == 0);
    at = lf_attrs_get(a, "lensfield:a_rather_long_attribute_name_over_31");
    CHECK(at && at->type == LF_ATTR_INT && at->i == 7);
}

static void test_attrs_api(void)
{
    lf_attrs a = {0};
    set_test_attrs(&a);
    check_test_attrs(&a);
    size_t n = a.count;
    /* Setting an existing name replaces it, even with another type. */
    CHECK(lf_attrs_set_int(&a, "lensfield:camera", 5, NULL) == 0);
    CHECK(a.count == n);
    const lf_attr *at = lf_attrs_get(&a, "lensfield:camera");
    CHECK(at && at->type == LF_ATTR_INT && at->i == 5);
    CHECK(lf_attrs_get(&a, "missing") == NULL);
    CHECK(lf_attrs_set_floats(&a, "empty_vector", NULL, 0, NULL) == 0);
    CHECK(lf_attrs_set_floats(&a, "bad", NULL, 3, NULL) != 0);
    for (int i = 0; i < 100; i++) { /* growth */
        char name[32];
        snprintf(name, sizeof name, "k%d", i);
        CHECK(lf_attrs_set_double(&a, name, i, NULL) == 0);
    }
    at = lf_attrs_get(&a, "k99");
    CHECK(at && at->d == 99.0);
    lf_attrs_free(&a);
    CHECK(a.count == 0 && a.items == NULL);
    lf_attrs_free(&a); /* twice is harmless */
    lf_attrs_free(NULL);
}

/* ------------------------------------------------------------------- EXR */

static void test_exr_float_roundtrip(void)
{
    const int counts[] = {1, 2, 3, 4, 12};
    for (size_t t = 0; t < sizeof counts / sizeof *counts; t++) {
        int nc = counts[t];
        lf_error err = {0};
        lf_image img, back = {0};
        CHECK(lf_image_alloc(&img, 37, 21, nc, &err) == 0); /* odd sizes: partial chunks */
        fill_random(&img, 1234u + (uint32_t)nc);
        lf_attrs a = {0}, got = {0};
        set_test_attrs(&a);
        char p[512];
        path_in(p, sizeof p, "float.exr");
        int rc = lf_image_write(p, &img, &a, NULL, &err);
        CHECK_MSG(rc == 0, "%d channels: %s", nc, err.msg);
        rc = lf_image_read(p, &back, &got, &err);
        CHECK_MSG(rc == 0, "%d channels: %s", nc, err.msg);
        CHECK(back.width == 37 && back.height == 21 && back.channels == nc);
        CHECK_MSG(back.data && memcmp(back.data, img.data, sizeof(float) * 37 * 21 * (size_t)nc) == 0,
                  "%d channels not bit-exact", nc);
        check_test_attrs(&got);
        /* Standard attributes of supported types come back too. */
        const lf_attr *par = lf_attrs_get(&got, "pixelAspectRatio");
        CHECK(par && par->type == LF_ATTR_FLOAT && par->d == 1.0);
        CHECK(count_dir_entries() == 1);
        lf_attrs_free(&a);
        lf_attrs_free(&got);
        lf_image_free(&img);
        lf_image_free(&back);
        clear_dir();
    }
}

static void test_exr_half_roundtrip(void)
{
    lf_error err = {0};
    lf_image img, back = {0};
    CHECK(lf_image_alloc(&img, 50, 33, 3, &err) == 0);
    uint32_t seed = 99;
    size_t n = (size_t)50 * 33 * 3;
    for (size_t i = 0; i < n; i++) {
        seed = seed * 1664525u + 1013904223u;
        /* spread over the normal half range, 2^-14 .. 2^15, both signs */
        float mag = ldexpf(1.0f + (float)(seed >> 9) / 8388608.0f, (int)(seed % 30) - 14);
        img.data[i] = (seed & 1) ? -mag : mag;
    }
    lf_write_opts opts = {.half = 1};
    char p[512];
    path_in(p, sizeof p, "half.exr");
    int rc = lf_image_write(p, &img, NULL, &opts, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    rc = lf_image_read(p, &back, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(back.channels == 3 && back.width == 50 && back.height == 33);
    double worst = 0.0;
    for (size_t i = 0; back.data && i < n; i++) {
        double rel = fabs((double)back.data[i] - img.data[i]) / fabs((double)img.data[i]);
        worst = rel > worst ? rel : worst;
    }
    CHECK_MSG(back.data && worst <= 1e-3, "worst relative error %g", worst);
    CHECK(worst > 0.0); /* it really was stored as half */
    lf_image_free(&back);

    /* A finite float beyond the half range would silently become Inf. */
    img.data[7] = 1e5f;
    lf_error err2 = {0};
    path_in(p, sizeof p, "overflow.exr");
    CHECK(lf_image_write(p, &img, NULL, &opts, &err2) == LF_ERR_NUMERIC);
    CHECK(file_size(p) == -1);
    lf_image_free(&img);
    clear_dir();
}

static void check_fixture_tiled(const char *p)
{
    lf_error err = {0};
    lf_image img = {0};
    int rc = lf_image_read(p, &img, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(img.width == 6 && img.height == 5 && img.channels == 4);
    int exact = img.data != NULL;
    for (int y = 0; exact && y < 5; y++)
        for (int x = 0; x < 6; x++)
            for (int c = 0; c < 4; c++)
                exact &= lf_image_px(&img, x, y)[c] == (x + 8 * y) / 64.0f + c / 4.0f;
    CHECK_MSG(exact, "tiled half fixture: wrong pixel values or channel order");
    lf_image_free(&img);
}

static void test_exr_fixtures(void)
{
    char p[512];
    path_in(p, sizeof p, "tiled.exr");
    spit(p, tiled4s_exr, sizeof tiled4s_exr);
    check_fixture_tiled(p);

    lf_error err = {0};
    lf_image img = {0};
    lf_attrs a = {0};
    path_in(p, sizeof p, "uint.exr");
    spit(p, uint1s_exr, sizeof uint1s_exr);
    int rc = lf_image_read(p, &img, &a, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(img.width == 3 && img.height == 2 && img.channels == 1);
    int exact = img.data != NULL;
    for (int i = 0; exact && i < 6; i++) {
        double want = i / 5.0 * 4294967295.0;
        exact &= img.data[i] == floorf(img.data[i]) && fabs(img.data[i] - want) <= 1e-6 * 4294967295.0;
    }
    CHECK_MSG(exact, "uint fixture: wrong pixel values");
    CHECK(img.data && img.data[0] == 0.0f && img.data[5] == 4294967295.0f);
    const lf_attr *cd = lf_attrs_get(&a, "capDate");
    CHECK(cd && cd->type == LF_ATTR_STRING && strlen(cd->s) == 19); /* "YYYY:MM:DD HH:MM:SS" */
    const lf_attr *sww = lf_attrs_get(&a, "screenWindowWidth");
    CHECK(sww && sww->type == LF_ATTR_FLOAT && sww->d == 1.0);
    lf_attrs_free(&a);
    lf_image_free(&img);
    clear_dir();
}

static void test_exr_bad_attrs(void)
{
    lf_error err = {0};
    lf_image img;
    CHECK(lf_image_alloc(&img, 4, 4, 3, &err) == 0);
    lf_attrs a = {0};
    /* "compression" is a required attribute of another type. */
    lf_attrs_set_string(&a, "compression", "zip", NULL);
    char p[512];
    path_in(p, sizeof p, "badattr.exr");
    int rc = lf_image_write(p, &img, &a, NULL, &err);
    CHECK(rc == LF_ERR_PARAM);
    CHECK_MSG(strstr(err.msg, "compression") != NULL, "%s", err.msg);
    CHECK(count_dir_entries() == 0);
    lf_attrs_free(&a);
    lf_image_free(&img);
}

/* ------------------------------------------------------- OpenImageIO ones */

/* Largest linear change that half an 8-bit step of sRGB code can cause
 * around linear value v: 0.5/255 times d(linear)/d(code) at the upper end
 * of the step (the derivative grows with the code value). */
static double srgb_quantisation_bound(double v)
{
    double c = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    c = fmin(1.0, c + 0.5 / 255.0);
    double slope = c <= 0.04045 ? 1.0 / 12.92 : 2.4 / 1.055 * pow((c + 0.055) / 1.055, 1.4);
    return 0.5 / 255.0 * slope + 1e-6;
}

static void test_png_roundtrip(void)
{
    lf_error err = {0};
    lf_image img, back = {0};
    CHECK(lf_image_alloc(&img, 256, 4, 4, &err) == 0);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 256; x++) {
            float *px = lf_image_px(&img, x, y);
            px[0] = x / 255.0f;
            px[1] = (255 - x) / 255.0f;
            px[2] = (x * y % 256) / 255.0f;
            px[3] = (x % 17) / 16.0f; /* alpha: linear 8-bit, no curve */
        }
    char p[512];
    path_in(p, sizeof p, "grad.PNG"); /* extension matching is case-insensitive */
    int rc = lf_image_write(p, &img, NULL, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    rc = lf_image_read(p, &back, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(back.width == 256 && back.height == 4 && back.channels == 4);
    int within = back.data != NULL, exact = back.data != NULL, alpha_ok = back.data != NULL;
    for (int y = 0; back.data && y < 4; y++)
        for (int x = 0; x < 256; x++)
            for (int c = 0; c < 4; c++) {
                float v = lf_image_px(&img, x, y)[c], r = lf_image_px(&back, x, y)[c];
                if (c == 3) {
                    alpha_ok &= fabsf(r - v) <= 0.5f / 255.0f + 1e-6f;
                    continue;
                }
                within &= fabs((double)r - v) <= srgb_quantisation_bound(v);
                /* and exactly what encode-then-decode of the value gives */
                exact &= fabsf(r - lf_srgb_decode(lf_srgb_encode(v))) <= 1e-6f;
            }
    CHECK_MSG(within, "PNG round trip beyond 8-bit sRGB quantisation");
    CHECK(exact);
    CHECK(alpha_ok);
    lf_image_free(&back);

    /* Exposure is in stops: +1 doubles before the curve. */
    lf_image one;
    CHECK(lf_image_alloc(&one, 1, 1, 3, &err) == 0);
    one.data[0] = one.data[1] = one.data[2] = 0.25f;
    lf_write_opts opts = {.exposure = 1.0f};
    path_in(p, sizeof p, "exposed.png");
    CHECK(lf_image_write(p, &one, NULL, &opts, &err) == 0);
    CHECK(lf_image_read(p, &back, NULL, &err) == 0);
    CHECK(back.data && back.data[0] == lf_srgb_decode(188));
    lf_image_free(&back);
    lf_image_free(&one);
    lf_image_free(&img);
    clear_dir();
}

static void test_other_formats(void)
{
    lf_error err = {0};
    lf_image img, back = {0};
    CHECK(lf_image_alloc(&img, 19, 7, 3, &err) == 0);
    for (int i = 0; i < 19 * 7 * 3; i++)
        img.data[i] = (float)i / 100.0f - 1.5f; /* negative and > 1: float formats keep them */
    char p[512];

    /* Float TIFF: linear and exact. */
    path_in(p, sizeof p, "float.tif");
    int rc = lf_image_write(p, &img, NULL, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    rc = lf_image_read(p, &back, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(back.data && back.channels == 3 && memcmp(back.data, img.data, sizeof(float) * 19 * 7 * 3) == 0);
    lf_image_free(&back);

    /* JPEG: lossy, 8-bit sRGB; compare on the [0,1] part. */
    for (int i = 0; i < 19 * 7 * 3; i++)
        img.data[i] = 0.5f;
    path_in(p, sizeof p, "flat.jpg");
    rc = lf_image_write(p, &img, NULL, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    rc = lf_image_read(p, &back, NULL, &err);
    CHECK_MSG(rc == 0, "%s", err.msg);
    CHECK(back.data && back.width == 19 && back.height == 7 && back.channels == 3);
    CHECK(back.data && fabsf(back.data[0] - 0.5f) < 0.01f);
    lf_image_free(&back);
    CHECK(count_dir_entries() == 2);
    lf_image_free(&img);
    clear_dir();
}

/* ---------------------------------------------------------- write errors */

static void test_nonfinite_refused(void)
{
    lf_error err = {0};
    lf_image img;
    CHECK(lf_image_alloc(&img, 8, 6, 3, &err) == 0);
    CHECK(lf_image_count_nonfinite(&img) == 0);
    char p[512], q[512];
    path_in(p, sizeof p, "target.exr");
    path_in(q, sizeof q, "target.png");
    CHECK(lf_image_write(p, &img, NULL, NULL, &err) == 0);
    long before_size;
    unsigned char *before = slurp(p, &before_size);

    lf_image_px(&img, 5, 2)[1] = NAN;
    lf_image_px(&img, 7, 4)[0] = INFINITY;
    lf_image_px(&img, 0, 5)[2] = -INFINITY;
    CHECK(lf_image_count_nonfinite(&img) == 3);
    const char *paths[2] = {p, q};
    for (int k = 0; k < 2; k++) {
        lf_error e = {0};
        int rc = lf_image_write(paths[k], &img, NULL, NULL, &e);
        CHECK(rc == LF_ERR_NUMERIC && e.code == LF_ERR_NUMERIC);
        CHECK_MSG(strstr(e.msg, "3 non-finite") && strstr(e.msg, "x=5 y=2") && strstr(e.msg, paths[k]), "%s",
                  e.msg);
    }
    /* The existing target is untouched, no new file appeared. */
    long after_size;
    unsigned char *after = slurp(p, &after_size);
    CHECK(before && after && before_size == after_size && memcmp(before, after, (size_t)before_size) == 0);
    CHECK(file_size(q) == -1);
    CHECK(count_dir_entries() == 1);
    free(before);
    free(after);

    /* allow_nonfinite writes them, and they read back. */
    lf_write_opts opts = {.allow_nonfinite = 1};
    CHECK(lf_image_write(p, &img, NULL, &opts, &err) == 0);
    lf_image back = {0};
    CHECK(lf_image_read(p, &back, NULL, &err) == 0);
    CHECK(back.data && isnan(lf_image_px(&back, 5, 2)[1]) && isinf(lf_image_px(&back, 7, 4)[0]));
    CHECK(lf_image_count_nonfinite(&back) == 3);
    lf_image_free(&back);
    lf_image_free(&img);
    clear_dir();
}

static void test_missing_directory(void)
{
    lf_image img;
    lf_error err = {0};
    CHECK(lf_image_alloc(&img, 2, 2, 3, &err) == 0);
    const char *names[] = {"no/such/dir/out.exr", "no/such/dir/out.png"};
    for (int k = 0; k < 2; k++) {
        char p[512];
        lf_error e = {0};
        path_in(p, sizeof p, names[k]);
        int rc = lf_image_write(p, &img, NULL, NULL, &e);
        CHECK(rc == LF_ERR_IO);
        CHECK_MSG(strstr(e.msg, p) != NULL, "message does not name the path: %s", e.msg);
    }
    CHECK(count_dir_entries() == 0);

    /* An unknown extension fails without leaving anything behind. */
    char p[512];
    lf_error e = {0};
    path_in(p, sizeof p, "out.notaformat");
    CHECK(lf_image_write(p, &img, NULL, NULL, &e) != 0);
    CHECK_MSG(strstr(e.msg, p) != NULL, "%s", e.msg);
    CHECK(count_dir_entries() == 0);
    lf_image_free(&img);
}

static void test_overwrite_is_atomic(void)
{
    lf_error err = {0};
    lf_image a, b, back = {0};
    CHECK(lf_image_alloc(&a, 5, 5, 3, &err) == 0);
    CHECK(lf_image_alloc(&b, 9, 3, 4, &err) == 0);
    fill_random(&b, 7);
    char p[512];
    path_in(p, sizeof p, "over.exr");
    CHECK(lf_image_write(p, &a, NULL, NULL, &err) == 0);
    chmod(p, 0640);
    CHECK(lf_image_write(p, &b, NULL, NULL, &err) == 0);
    CHECK(lf_image_read(p, &back, NULL, &err) == 0);
    CHECK(back.width == 9 && back.channels == 4);
    struct stat st;
    CHECK(stat(p, &st) == 0 && (st.st_mode & 0777) == 0640); /* permissions kept */
    CHECK(count_dir_entries() == 1);
    lf_image_free(&a);
    lf_image_free(&b);
    lf_image_free(&back);
    clear_dir();
}

/* ----------------------------------------------------------- read errors */

static void check_read_fails(const char *p, const char *what)
{
    lf_error err = {0};
    lf_image img = {0};
    lf_attrs a = {0};
    int rc = lf_image_read(p, &img, &a, &err);
    CHECK_MSG(rc == LF_ERR_IO || rc == LF_ERR_PARSE, "%s: rc %d", what, rc);
    CHECK_MSG(err.code == rc && strstr(err.msg, p) != NULL, "%s: %s", what, err.msg);
    CHECK_MSG(img.data == NULL && img.width == 0 && a.count == 0, "%s: output not left empty", what);
    lf_attrs_free(&a);
    lf_image_free(&img);
}

static void test_truncated(void)
{
    lf_error err = {0};
    lf_image img;
    CHECK(lf_image_alloc(&img, 64, 64, 3, &err) == 0);
    fill_random(&img, 5);
    const char *names[] = {"trunc.exr", "trunc.png", "trunc.tif", "trunc.jpg"};
    for (int k = 0; k < 4; k++) {
        char p[512];
        path_in(p, sizeof p, names[k]);
        for (int i = 0; i < 64 * 64 * 3; i++) /* in [0,1] so the PNG is not flat */
            img.data[i] = (float)((i * 7919) % 1000) / 999.0f;
        CHECK(lf_image_write(p, &img, NULL, NULL, &err) == 0);
        long size = file_size(p);
        CHECK(size > 100);
        CHECK(truncate(p, size / 2) == 0);
        check_read_fails(p, names[k]);
    }
    /* A PNG with one flipped byte inside its pixel data. */
    char p[512];
    path_in(p, sizeof p, "flipped.png");
    CHECK(lf_image_write(p, &img, NULL, NULL, &err) == 0);
    long size;
    unsigned char *png = slurp(p, &size);
    CHECK(png && size > 200);
    if (png) {
        png[size - 40] ^= 0x5a; /* inside the last IDAT, before IEND's 12 bytes */
        spit(p, png, (size_t)size);
        check_read_fails(p, "flipped byte in PNG");
    }
    free(png);
    lf_image_free(&img);
    clear_dir();
}

static void test_garbage(void)
{
    char p[512];
    unsigned char junk[3000];
    uint32_t s = 42;
    for (size_t i = 0; i < sizeof junk; i++) {
        s = s * 1664525u + 1013904223u;
        junk[i] = (unsigned char)(s >> 24);
    }
    const char *names[] = {"junk.exr", "junk.png", "junk.jpg", "junk.tif", "junk.hdr", "junk"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++) {
        path_in(p, sizeof p, names[k]);
        spit(p, junk, sizeof junk);
        check_read_fails(p, names[k]);
    }
    /* EXR magic followed by junk. */
    junk[0] = 0x76, junk[1] = 0x2f, junk[2] = 0x31, junk[3] = 0x01, junk[4] = 2;
    path_in(p, sizeof p, "magic.exr");
    spit(p, junk, sizeof junk);
    check_read_fails(p, "magic + junk");
    path_in(p, sizeof p, "empty.exr");
    spit(p, "", 0);
    check_read_fails(p, "empty file");
    path_in(p, sizeof p, "does-not-exist.exr");
    check_read_fails(p, "missing file");
    check_read_fails(tmpdir, "a directory");
    clear_dir();
}

static uint32_t crc32_png(const unsigned char *buf, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= buf[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24), p[1] = (unsigned char)(v >> 16), p[2] = (unsigned char)(v >> 8),
    p[3] = (unsigned char)v;
}

static void test_absurd_headers(void)
{
    char p[512];
    /* PNG: signature, IHDR of 100000 x 100000 RGB8 with a correct CRC,
     * a tiny IDAT and IEND.  The header is valid; the size is absurd. */
    unsigned char png[8 + 25 + 12 + 12];
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    memcpy(png, sig, 8);
    unsigned char *ihdr = png + 8;
    put_be32(ihdr, 13);
    memcpy(ihdr + 4, "IHDR", 4);
    put_be32(ihdr + 8, 100000);
    put_be32(ihdr + 12, 100000);
    ihdr[16] = 8, ihdr[17] = 2, ihdr[18] = 0, ihdr[19] = 0, ihdr[20] = 0;
    put_be32(ihdr + 21, crc32_png(ihdr + 4, 17));
    unsigned char *idat = ihdr + 25;
    put_be32(idat, 0);
    memcpy(idat + 4, "IDAT", 4);
    put_be32(idat + 8, crc32_png(idat + 4, 4));
    unsigned char *iend = idat + 12;
    put_be32(iend, 0);
    memcpy(iend + 4, "IEND", 4);
    put_be32(iend + 8, crc32_png(iend + 4, 4));
    path_in(p, sizeof p, "huge.png");
    spit(p, png, sizeof png);
    check_read_fails(p, "100000x100000 PNG");
    lf_error err = {0};
    lf_image img = {0};
    lf_image_read(p, &img, NULL, &err);
    CHECK_MSG(strstr(err.msg, "exceeds"), "rejected for the wrong reason: %s", err.msg);

    /* EXR: a valid file whose dataWindow is rewritten to 100000 x 100000,
     * then to 40000 x 40000 (under 2^31 pixels, but 4 float channels are
     * 25.6 GB). */
    lf_image small;
    CHECK(lf_image_alloc(&small, 8, 8, 4, &err) == 0);
    path_in(p, sizeof p, "huge.exr");
    CHECK(lf_image_write(p, &small, NULL, NULL, &err) == 0);
    lf_image_free(&small);
    long size;
    unsigned char *exr = slurp(p, &size);
    const int32_t maxes[2] = {99999, 39999};
    for (int k = 0; exr && k < 2; k++) {
        static const char key[] = "dataWindow\0box2i"; /* name, NUL, type, NUL, size */
        unsigned char *at = NULL;
        for (long i = 0; i + (long)sizeof key + 20 < size; i++)
            if (memcmp(exr + i, key, sizeof key) == 0) {
                at = exr + i + sizeof key + 4; /* skip the 4-byte size: xmin ymin xmax ymax */
                break;
            }
        CHECK(at != NULL);
        if (!at)
            break;
        for (int j = 2; j < 4; j++) { /* little-endian int32 xmax, ymax */
            at[4 * j + 0] = (unsigned char)(maxes[k] & 0xff);
            at[4 * j + 1] = (unsigned char)((maxes[k] >> 8) & 0xff);
            at[4 * j + 2] = (unsigned char)((maxes[k] >> 16) & 0xff);
            at[4 * j + 3] = (unsigned char)((maxes[k] >> 24) & 0xff);
        }
        spit(p, exr, (size_t)size);
        check_read_fails(p, k ? "40000x40000 RGBA EXR" : "100000x100000 EXR");
        lf_error e = {0};
        lf_image_read(p, &img, NULL, &e);
        CHECK_MSG(strstr(e.msg, "exceeds") || strstr(e.msg, "large"), "EXR %d: %s", k, e.msg);
    }
    free(exr);

    /* The same limits guard allocation requested by callers. */
    lf_error e = {0};
    CHECK(lf_image_alloc(&img, 100000, 100000, 3, &e) == LF_ERR_PARAM && img.data == NULL);
    clear_dir();
}

/* ------------------------------------------------------------ comparison */

static void test_mse_psnr(void)
{
    lf_error err = {0};
    lf_image a, b, c;
    CHECK(lf_image_alloc(&a, 2, 1, 1, &err) == 0);
    CHECK(lf_image_alloc(&b, 2, 1, 1, &err) == 0);
    b.data[0] = 0.1f;
    b.data[1] = 0.3f;
    double mse = -1, psnr = -1;
    CHECK(lf_image_mse(&a, &b, &mse, &err) == 0);
    /* ((0.1)^2 + (0.3)^2) / 2 in the floats actually stored */
    CHECK_NEAR(mse, ((double)0.1f * 0.1f + (double)0.3f * 0.3f) / 2, 1e-15);
    CHECK(lf_image_psnr(&a, &b, &psnr, &err) == 0);
    CHECK_NEAR(psnr, 10.0 * log10(1.0 / 0.05), 1e-5); /* 13.0103 dB */
    CHECK(lf_image_psnr(&a, &a, &psnr, &err) == 0 && isinf(psnr) && psnr > 0);
    CHECK(lf_image_mse(&b, &b, &mse, &err) == 0 && mse == 0.0);

    /* Channels common to both: an RGB image against its first channel. */
    CHECK(lf_image_alloc(&c, 2, 1, 3, &err) == 0);
    c.data[0] = 0.5f, c.data[1] = 9.0f, c.data[2] = 9.0f; /* pixel 0 */
    c.data[3] = 0.5f;                                     /* pixel 1, channel 0 */
    CHECK(lf_image_mse(&a, &c, &mse, &err) == 0);
    CHECK_NEAR(mse, 0.25, 1e-12);

    lf_image d;
    CHECK(lf_image_alloc(&d, 1, 2, 1, &err) == 0);
    lf_error e = {0};
    CHECK(lf_image_mse(&a, &d, &mse, &e) == LF_ERR_PARAM && e.code == LF_ERR_PARAM);
    lf_image_free(&a);
    lf_image_free(&b);
    lf_image_free(&c);
    lf_image_free(&d);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lf_test_image_io.XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    test_srgb();
    test_attrs_api();
    test_exr_float_roundtrip();
    test_exr_half_roundtrip();
    test_exr_fixtures();
    test_exr_bad_attrs();
    test_png_roundtrip();
    test_other_formats();
    test_nonfinite_refused();
    test_missing_directory();
    test_overwrite_is_atomic();
    test_truncated();
    test_garbage();
    test_absurd_headers();
    test_mse_psnr();
    clear_dir();
    rmdir(tmpdir);
    return lf_test_end();
}
