/* fuzz_entry.h - the fuzzed entry points, shared by the libFuzzer targets
 * (fuzz/fuzz_*.c) and their replay test (tests/test_fuzz_regressions.c), so
 * a saved crasher runs through exactly the code that found it.
 *
 *   int rc = lf_fuzz_run(LF_FUZZ_SCENE_PARSER, data, size);
 *   // 0: the input was accepted, 1: it was refused with a message,
 *   // -1: it was refused WITHOUT a message (a contract violation: the
 *   //     fuzz targets abort() on it so libFuzzer saves the input).
 *
 * Header-only (static functions) because the replay test is one .c file and
 * tests/CMakeLists.txt builds each test from its own source alone.
 *
 * Targets:
 *   scene_parser  lf_scene_parse_string on the bytes (NUL-terminated copy),
 *                 then lf_scene_desc_free.
 *   ply           lf_ply_read of the bytes written to a temporary .ply file.
 *   lens_file     lf_lens_parse (camera/lens.h); on success also the paraxial
 *                 analysis and the thick-lens focus, which read every surface.
 *   lf_attributes lensfield:* attributes decoded from the bytes (a small
 *                 type/name/value encoding, below) -> lf_lightfield_layout_from_attrs
 *                 -> lf_lightfield_layout_resolve for a raw size taken from the bytes
 *                 -> lf_lightfield_decode of a small raw image.
 *   image_exr     lf_image_read (with attributes) of the bytes written to a
 *                 temporary file, then lf_lightfield_layout_from_attrs on what it read.
 */
#ifndef LF_FUZZ_ENTRY_H
#define LF_FUZZ_ENTRY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/lf_error.h"
#include "camera/lens.h"
#include "image/lf_image.h"
#include "lightfield/lf_lightfield.h"
#include "scenefile/lf_scene_desc.h"

typedef enum lf_fuzz_target {
    LF_FUZZ_SCENE_PARSER,
    LF_FUZZ_PLY,
    LF_FUZZ_LENS_FILE,
    LF_FUZZ_LF_ATTRIBUTES,
    LF_FUZZ_IMAGE_EXR,
    LF_FUZZ_TARGET_COUNT
} lf_fuzz_target;

/* Directory names under fuzz/corpus/ and fuzz/regressions/. */
static const char *const lf_fuzz_target_names[LF_FUZZ_TARGET_COUNT] = {
    "scene_parser", "ply", "lens_file", "lf_attributes", "image_exr"};

/* A refusal must say why. */
static int lf_fuzz_refused(const char *msg)
{
    return msg && msg[0] ? 1 : -1;
}

/* NUL-terminated copy of the input (parsers take C strings). */
static char *lf_fuzz_cstr(const uint8_t *data, size_t size)
{
    char *s = malloc(size + 1);
    if (!s)
        return NULL;
    if (size)
        memcpy(s, data, size);
    s[size] = '\0';
    return s;
}

/* Writes the input to a temporary file with the given suffix; returns its
 * path in buf (the caller unlinks it), or -1. */
static int lf_fuzz_temp_file(const uint8_t *data, size_t size, const char *suffix, char *buf, size_t n)
{
    const char *dir = getenv("TMPDIR");
    snprintf(buf, n, "%s/lf_fuzz_XXXXXX%s", dir && *dir ? dir : "/tmp", suffix);
    int fd = mkstemps(buf, (int)strlen(suffix));
    if (fd < 0)
        return -1;
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(fd, data + done, size - done);
        if (w <= 0) {
            close(fd);
            unlink(buf);
            return -1;
        }
        done += (size_t)w;
    }
    close(fd);
    return 0;
}

static int lf_fuzz_scene_parser(const uint8_t *data, size_t size)
{
    char *text = lf_fuzz_cstr(data, size);
    if (!text)
        return 0;
    /* Include/Import of a device file (/dev/zero, /dev/stdin) would read
     * forever: that is the caller's choice of path, not a parser bug. */
    if (strstr(text, "/dev/") || strstr(text, "/proc/") || strstr(text, "/sys/")) {
        free(text);
        return 0;
    }
    lf_scene_desc d;
    lf_error err = {0};
    /* A name in a directory that does not exist: relative Includes fail cleanly. */
    int rc = lf_scene_parse_string(text, "/nonexistent-lf-fuzz/fuzz.pbrt", &d, &err);
    free(text);
    if (rc == 0) {
        lf_scene_desc_free(&d);
        return 0;
    }
    return lf_fuzz_refused(err.msg);
}

static int lf_fuzz_ply(const uint8_t *data, size_t size)
{
    char path[512];
    if (lf_fuzz_temp_file(data, size, ".ply", path, sizeof path))
        return 0;
    lf_ply_mesh m;
    memset(&m, 0, sizeof m);
    lf_error err = {0};
    int rc = lf_ply_read(path, &m, &err);
    unlink(path);
    if (rc == 0) {
        /* every index must name a vertex */
        for (size_t i = 0; i < 3 * m.n_triangles; i++)
            if (m.indices[i] < 0 || (size_t)m.indices[i] >= m.n_vertices) {
                fprintf(stderr, "lf_fuzz_ply: accepted index %d of %zu vertices\n", m.indices[i], m.n_vertices);
                lf_ply_free(&m);
                return -1;
            }
        lf_ply_free(&m);
        return 0;
    }
    return lf_fuzz_refused(err.msg);
}

static int lf_fuzz_lens_file(const uint8_t *data, size_t size)
{
    char *text = lf_fuzz_cstr(data, size);
    if (!text)
        return 0;
    lf_lens lens;
    memset(&lens, 0, sizeof lens);
    lf_error err = {0};
    int rc = lf_lens_parse(text, "fuzz.dat", &lens, &err);
    free(text);
    if (rc != 0)
        return lf_fuzz_refused(err.msg);
    lf_lens_paraxial px;
    if (lf_lens_paraxial_analyse(&lens, &px) == 0) {
        double film = 0;
        (void)lf_lens_focus_thick(&lens, 1000.0, &film, NULL);
    }
    lf_lens_free(&lens);
    return 0;
}

/* The attribute encoding for lf_attributes: a sequence of records
 *   byte key     index into the name table below (mod its size)
 *   byte type    mod 4: 0 string, 1 int, 2 double, 3 floats
 *   value        string: byte length then that many bytes;
 *                int: 4 bytes; double: 8 bytes;
 *                floats: byte count (mod 9) then 4 bytes each.
 * The first 2 bytes give the raw image size (1..64 each). */
static const char *const lf_fuzz_attr_names[] = {
    "lensfield:kind", "lensfield:cameras_per_dim", "lensfield:camera_grid_bounds", "lensfield:fov_deg",
    "lensfield:tile_size", "lensfield:lens_radius", "lensfield:focal_distance", "lensfield:grid",
    "lensfield:microlens_pitch_px", "lensfield:microlens_rotation_rad", "lensfield:microlens_offset_px",
    "lensfield:microlens_count", "lensfield:microlens_pitch_um", "lensfield:microlens_focal_mm",
    "lensfield:main_focal_mm", "lensfield:main_fstop", "lensfield:focus_distance_m",
    "lensfield:mla_distance_mm", "lensfield:unknown"};

static int lf_fuzz_take(const uint8_t **p, const uint8_t *end, void *out, size_t n)
{
    if ((size_t)(end - *p) < n)
        return -1;
    memcpy(out, *p, n);
    *p += n;
    return 0;
}

static int lf_fuzz_lf_attributes(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    int raw_w = 1 + data[0] % 64, raw_h = 1 + data[1] % 64;
    const uint8_t *p = data + 2, *end = data + size;
    lf_attrs attrs = {0};
    const int n_names = (int)(sizeof lf_fuzz_attr_names / sizeof lf_fuzz_attr_names[0]);
    while (p + 2 <= end) {
        const char *name = lf_fuzz_attr_names[p[0] % n_names];
        int type = p[1] % 4;
        p += 2;
        if (type == 0) {
            uint8_t len;
            char s[256];
            if (lf_fuzz_take(&p, end, &len, 1) || lf_fuzz_take(&p, end, s, len))
                break;
            s[len] = '\0';
            lf_attrs_set_string(&attrs, name, s, NULL);
        } else if (type == 1) {
            int32_t v;
            if (lf_fuzz_take(&p, end, &v, 4))
                break;
            lf_attrs_set_int(&attrs, name, v, NULL);
        } else if (type == 2) {
            double v;
            if (lf_fuzz_take(&p, end, &v, 8))
                break;
            lf_attrs_set_double(&attrs, name, v, NULL);
        } else {
            uint8_t cnt;
            float v[8];
            if (lf_fuzz_take(&p, end, &cnt, 1))
                break;
            cnt %= 9;
            if (lf_fuzz_take(&p, end, v, 4u * cnt))
                break;
            lf_attrs_set_floats(&attrs, name, v, cnt, NULL);
        }
    }
    lf_lightfield_layout file, flags, lay;
    lf_error err = {0};
    int result = 0;
    if (lf_lightfield_layout_from_attrs(&attrs, &file, &err)) {
        result = lf_fuzz_refused(err.msg);
        goto done;
    }
    char desc[1024];
    lf_lightfield_layout_describe(&file, desc, sizeof desc);
    lf_lightfield_layout_init(&flags);
    if (lf_lightfield_layout_resolve(&file, &flags, raw_w, raw_h, &lay, &err)) {
        result = lf_fuzz_refused(err.msg);
        goto done;
    }
    lf_lightfield_layout_describe(&lay, desc, sizeof desc);
    lf_image raw = {0};
    if (lf_image_alloc(&raw, raw_w, raw_h, 3, &err) == 0) {
        for (size_t i = 0; i < (size_t)raw_w * raw_h * 3; i++)
            raw.data[i] = (float)(i % 7) / 7.0f;
        lf_lightfield lf;
        memset(&lf, 0, sizeof lf);
        lf_error derr = {0};
        if (lf_lightfield_decode(&raw, &lay, NULL, &lf, &derr) == 0)
            lf_lightfield_free(&lf);
        else
            result = lf_fuzz_refused(derr.msg);
        lf_image_free(&raw);
    }
done:
    lf_attrs_free(&attrs);
    return result;
}

static int lf_fuzz_image_exr(const uint8_t *data, size_t size)
{
    char path[512];
    if (lf_fuzz_temp_file(data, size, ".exr", path, sizeof path))
        return 0;
    lf_image img;
    lf_attrs attrs = {0};
    lf_error err = {0};
    int rc = lf_image_read(path, &img, &attrs, &err);
    unlink(path);
    if (rc != 0) {
        lf_attrs_free(&attrs);
        return lf_fuzz_refused(err.msg);
    }
    lf_lightfield_layout lay;
    lf_error lerr = {0};
    int result = 0;
    if (lf_lightfield_layout_from_attrs(&attrs, &lay, &lerr))
        result = lf_fuzz_refused(lerr.msg);
    lf_image_free(&img);
    lf_attrs_free(&attrs);
    return result;
}

static int lf_fuzz_run(lf_fuzz_target t, const uint8_t *data, size_t size)
{
    switch (t) {
    case LF_FUZZ_SCENE_PARSER: return lf_fuzz_scene_parser(data, size);
    case LF_FUZZ_PLY: return lf_fuzz_ply(data, size);
    case LF_FUZZ_LENS_FILE: return lf_fuzz_lens_file(data, size);
    case LF_FUZZ_LF_ATTRIBUTES: return lf_fuzz_lf_attributes(data, size);
    case LF_FUZZ_IMAGE_EXR: return lf_fuzz_image_exr(data, size);
    default: return 0;
    }
}

#endif
