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
 *   camera_params every registered camera created from parameters decoded
 *                 from the bytes (type, film size, then name/value pairs with
 *                 any finite double, huge and tiny included), then 16 rays
 *                 generated, described and destroyed: a camera that accepts
 *                 its parameters must give finite rays with unit directions.
 *   folder        a folder of tiny views (HCI input_CamNNN, PREFIX_RR_CC, or
 *                 Stanford-style names with coordinates from the bytes; grid
 *                 size, gaps and an odd-sized view from the bytes) and a
 *                 parameters.cfg of the remaining bytes, opened with
 *                 lf_lightfield_open.
 */
#ifndef LF_FUZZ_ENTRY_H
#define LF_FUZZ_ENTRY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <dirent.h>
#include <math.h>
#include <sys/stat.h>

#include "base/lf_error.h"
#include "camera/lens.h"
#include "image/lf_image.h"
#include "camera/lf_camera.h"
#include "lightfield/lf_lightfield.h"
#include "lightfield/lf_source.h"
#include "scenefile/lf_scene_desc.h"

typedef enum lf_fuzz_target {
    LF_FUZZ_SCENE_PARSER,
    LF_FUZZ_PLY,
    LF_FUZZ_LENS_FILE,
    LF_FUZZ_LF_ATTRIBUTES,
    LF_FUZZ_IMAGE_EXR,
    LF_FUZZ_CAMERA_PARAMS,
    LF_FUZZ_FOLDER,
    LF_FUZZ_TARGET_COUNT
} lf_fuzz_target;

/* Directory names under fuzz/corpus/ and fuzz/regressions/. */
static const char *const lf_fuzz_target_names[LF_FUZZ_TARGET_COUNT] = {
    "scene_parser", "ply", "lens_file", "lf_attributes", "image_exr", "camera_params", "folder"};

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

/* ---- camera_params ---- */

typedef struct lf_fuzz_cam_params {
    const char *names[32];
    double values[32][4];
    int counts[32];
    const char *strings[32];
    int n;
} lf_fuzz_cam_params;

static const char *const lf_fuzz_cam_names[] = {
    "fov", "lensradius", "focaldistance", "screenwindow", "frameaspectratio", "aperturediameter", "focusdistance",
    "focallength", "fstop", "coc", "anamorphic", "aperturerotation", "blades", "cameragridbounds", "camerasperdim",
    "microlenses", "microlensfocallength", "pitch", "rotation", "sensoroffset", "sensorsize", "dispersion",
    "pupilbounds", "aperture", "grid", "lensfile", "lensmodel", "mapping", "sensor"};
static const char *const lf_fuzz_cam_strings[] = {
    "circular", "gaussian", "square", "hex", "hexagonal", "pentagon", "star", "scenes/lenses/dgauss.50mm.dat",
    "scenes/lenses/fisheye.10mm.dat", "scenes/lenses/wide.22mm.dat", "scenes/lenses/telephoto.250mm.dat",
    "equidistant", "equisolid", "orthographic", "stereographic", "equirectangular", "thick", "realistic", "full",
    "35mm", "apsc", "", "no such thing", "/nonexistent/lens.dat"};

static int lf_fuzz_cam_find(const lf_fuzz_cam_params *p, const char *name)
{
    for (int i = p->n - 1; i >= 0; i--)
        if (!strcmp(p->names[i], name))
            return i;
    return -1;
}
static double lf_fuzz_cam_float(void *ctx, const char *name, double def)
{
    int i = lf_fuzz_cam_find(ctx, name);
    return i >= 0 && !((lf_fuzz_cam_params *)ctx)->strings[i] ? ((lf_fuzz_cam_params *)ctx)->values[i][0] : def;
}
static int lf_fuzz_cam_int(void *ctx, const char *name, int def)
{
    double v = lf_fuzz_cam_float(ctx, name, NAN);
    return v >= -1e9 && v <= 1e9 ? (int)v : def; /* scene integers are ints: no other value can arrive */
}
static int lf_fuzz_cam_bool(void *ctx, const char *name, int def)
{
    double v = lf_fuzz_cam_float(ctx, name, NAN);
    return v == v ? v != 0 : def;
}
static const char *lf_fuzz_cam_string(void *ctx, const char *name, const char *def)
{
    int i = lf_fuzz_cam_find(ctx, name);
    return i >= 0 && ((lf_fuzz_cam_params *)ctx)->strings[i] ? ((lf_fuzz_cam_params *)ctx)->strings[i] : def;
}
static int lf_fuzz_cam_floats(void *ctx, const char *name, double *out, int max)
{
    lf_fuzz_cam_params *p = ctx;
    int i = lf_fuzz_cam_find(p, name);
    if (i < 0 || p->strings[i])
        return 0;
    for (int k = 0; k < p->counts[i] && k < max; k++)
        out[k] = p->values[i][k];
    return p->counts[i];
}
static int lf_fuzz_cam_image(void *ctx, const char *path, int *w, int *h, float **px, char *err, size_t n)
{
    (void)ctx, (void)path, (void)w, (void)h, (void)px;
    snprintf(err, n, "no images while fuzzing");
    return -1;
}
static void lf_fuzz_sink_s(void *c, const char *n, const char *v) { (void)c, (void)n, (void)v; }
static void lf_fuzz_sink_i(void *c, const char *n, int v) { (void)c, (void)n, (void)v; }
static void lf_fuzz_sink_d(void *c, const char *n, double v) { (void)c, (void)n, (void)v; }
static void lf_fuzz_sink_ds(void *c, const char *n, const double *v, int k) { (void)c, (void)n, (void)v, (void)k; }

/* A finite double from 8 bytes: the raw bits when finite, else a few
 * scales of the byte (so huge, tiny, zero and negative all come up). */
static double lf_fuzz_double(const uint8_t *b)
{
    double v;
    memcpy(&v, b, 8);
    if (isfinite(v))
        return v;
    static const double scales[] = {0, 1, -1, 1e-308, 1e308, -1e308, 1e19, 1e-9, 0.5, 1e6};
    return scales[b[0] % 10] * (1 + b[1] / 256.0);
}

static int lf_fuzz_camera_params(const uint8_t *data, size_t size)
{
    if (size < 4 || lf_camera_count() <= 0)
        return 0;
    const lf_camera_type *t = lf_camera_at(data[0] % lf_camera_count());
    int w = 1 + data[1] % 96, h = 1 + data[2] % 96;
    lf_fuzz_cam_params p = {{0}, {{0}}, {0}, {0}, 0};
    const int n_names = (int)(sizeof lf_fuzz_cam_names / sizeof *lf_fuzz_cam_names);
    const int n_strings = (int)(sizeof lf_fuzz_cam_strings / sizeof *lf_fuzz_cam_strings);
    const uint8_t *q = data + 3, *end = data + size;
    while (q + 2 <= end && p.n < 32) {
        p.names[p.n] = lf_fuzz_cam_names[q[0] % n_names];
        int kind = q[1] % 6; /* 0: string; 1..4: that many numbers */
        q += 2;
        if (kind == 0 || kind == 5) {
            if (q >= end)
                break;
            p.strings[p.n] = lf_fuzz_cam_strings[*q++ % n_strings];
        } else {
            if (end - q < 8 * kind)
                break;
            for (int k = 0; k < kind; k++, q += 8)
                p.values[p.n][k] = lf_fuzz_double(q);
            p.counts[p.n] = kind;
        }
        p.n++;
    }
    char cerr[1024] = "", cwarn[1024] = "";
    lf_camera_params cp = {&p, lf_fuzz_cam_float, lf_fuzz_cam_int, lf_fuzz_cam_bool, lf_fuzz_cam_string,
                           lf_fuzz_cam_floats, lf_fuzz_cam_image};
    lf_camera_create_args args = {sizeof args, &cp, w, h, 35.0, 0.0, 1.0, ".", cerr, sizeof cerr, cwarn,
                                  sizeof cwarn};
    void *state = NULL;
    if (t->create(&args, &state))
        return lf_fuzz_refused(cerr);
    int result = 0;
    t->needs(state);
    lf_camera_sample smp[16];
    lf_camera_ray rays[16];
    double wts[16];
    for (int i = 0; i < 16; i++) {
        smp[i] = (lf_camera_sample){(i % 4 + 0.5) * w / 4.0, (i / 4 + 0.5) * h / 4.0, (i % 3) / 3.0,
                                    (i % 5) / 5.0, 0.5, (i % 7) / 7.0};
        memset(&rays[i], 0, sizeof rays[i]);
        rays[i].time = 0.5;
    }
    lf_camera_generate_rays(t, state, 16, smp, rays, wts);
    for (int i = 0; i < 16 && !result; i++) {
        if (!(wts[i] > 0))
            continue;
        double len = sqrt(rays[i].dir[0] * rays[i].dir[0] + rays[i].dir[1] * rays[i].dir[1] +
                          rays[i].dir[2] * rays[i].dir[2]);
        int ok = isfinite(wts[i]) && fabs(len - 1) < 1e-3;
        for (int k = 0; k < 3; k++)
            ok = ok && isfinite(rays[i].origin[k]) && isfinite(rays[i].dir[k]);
        if (!ok) {
            fprintf(stderr, "lf_fuzz_camera_params: camera %s gave ray %d weight %g origin (%g %g %g) dir (%g %g %g)\n",
                    t->name, i, wts[i], rays[i].origin[0], rays[i].origin[1], rays[i].origin[2], rays[i].dir[0],
                    rays[i].dir[1], rays[i].dir[2]);
            result = -1;
        }
    }
    char desc[4096];
    if (t->describe)
        t->describe(state, desc, sizeof desc);
    lf_camera_attr_sink sink = {NULL, lf_fuzz_sink_s, lf_fuzz_sink_i, lf_fuzz_sink_d, lf_fuzz_sink_ds};
    if (t->metadata)
        t->metadata(state, &sink);
    t->destroy(state);
    return result;
}

/* ---- folder ---- */

static void lf_fuzz_rm_flat(const char *dir);
static char lf_fuzz_templates_dir[512];
static void lf_fuzz_templates_remove(void)
{
    lf_fuzz_rm_flat(lf_fuzz_templates_dir);
}

/* Two tiny views written once per process (removed at exit): 8 x 6 and
 * (odd) 6 x 8. */
static int lf_fuzz_view_templates(char *dir, size_t n)
{
    char *made = lf_fuzz_templates_dir;
    if (!made[0]) {
        atexit(lf_fuzz_templates_remove);
        const char *tmp = getenv("TMPDIR");
        snprintf(made, sizeof lf_fuzz_templates_dir, "%s/lf_fuzz_views_%ld", tmp && *tmp ? tmp : "/tmp", (long)getpid());
        mkdir(made, 0700);
        for (int k = 0; k < 2; k++) {
            lf_image img = {0};
            lf_error e = {0};
            if (lf_image_alloc(&img, k ? 6 : 8, k ? 8 : 6, 3, &e))
                return -1;
            for (size_t i = 0; i < 144; i++)
                img.data[i] = (float)((i * 37) % 11) / 11.0f;
            char path[600];
            snprintf(path, sizeof path, "%s/%s.exr", made, k ? "odd" : "view");
            int rc = lf_image_write(path, &img, NULL, NULL, &e);
            lf_image_free(&img);
            if (rc)
                return -1;
        }
    }
    snprintf(dir, n, "%s", made);
    return 0;
}

static void lf_fuzz_rm_flat(const char *dir)
{
    DIR *d = opendir(dir);
    char path[1200];
    for (struct dirent *e; d && (e = readdir(d));)
        if (e->d_name[0] != '.' || (e->d_name[1] && strcmp(e->d_name, "..")))
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name), unlink(path);
    if (d)
        closedir(d);
    rmdir(dir);
}

static int lf_fuzz_folder(const uint8_t *data, size_t size)
{
    char tdir[512], dir[600], from[700], to[1200];
    if (size < 5 || lf_fuzz_view_templates(tdir, sizeof tdir))
        return 0;
    int scheme = data[0] % 3, nu = 1 + data[1] % 9, nv = 1 + data[2] % 9, gaps = data[3], odd = data[4];
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/lf_fuzz_folder_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir))
        return 0;
    const uint8_t *q = data + 5, *end = data + size;
    for (int v = 0; v < nv; v++)
        for (int u = 0; u < nu; u++) {
            int i = v * nu + u;
            if (gaps & 1 && i % 8 == (gaps >> 1) % 8 && i > 0)
                continue; /* a missing view */
            if (scheme == 0)
                snprintf(to, sizeof to, "%s/input_Cam%03d.exr", dir, i);
            else if (scheme == 1)
                snprintf(to, sizeof to, "%s/view_%02d_%02d.exr", dir, v, u);
            else { /* Stanford: out_RR_CC_<y>_<x>.exr with camera coordinates from the bytes */
                double y = q + 8 <= end ? lf_fuzz_double(q) : -v, x = q + 16 <= end ? lf_fuzz_double(q + 8) : u;
                q += q + 16 <= end ? 16 : 0;
                snprintf(to, sizeof to, "%s/out_%02d_%02d_%.6g_%.6g_.exr", dir, v, u, y, x);
            }
            snprintf(from, sizeof from, "%s/%s.exr", tdir, odd % 16 == i + 1 ? "odd" : "view");
            if (link(from, to))
                continue;
        }
    snprintf(to, sizeof to, "%s/parameters.cfg", dir);
    FILE *f = fopen(to, "wb");
    if (f) {
        fwrite(q, 1, (size_t)(end - q), f);
        fclose(f);
    }
    lf_lightfield_source src;
    lf_lightfield_open_opts oo = {0};
    lf_error err = {0};
    int result = 0;
    if (lf_lightfield_open(dir, &oo, &src, &err))
        result = lf_fuzz_refused(err.msg);
    else {
        char desc[4096];
        lf_lightfield_source_describe(&src, desc, sizeof desc);
        lf_lightfield_close(&src);
    }
    lf_fuzz_rm_flat(dir);
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
    case LF_FUZZ_CAMERA_PARAMS: return lf_fuzz_camera_params(data, size);
    case LF_FUZZ_FOLDER: return lf_fuzz_folder(data, size);
    default: return 0;
    }
}

#endif
