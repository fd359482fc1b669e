/* Folders of views (lightfield/folder.c): the HCI layout with
 * parameters.cfg, PREFIX_RR_CC names 0- and 1-based, 8-bit PNG, 16-bit PNG
 * (built byte by byte here: sRGB decoded with the formula) and EXR views;
 * every failure named (missing view, extra view, different sizes,
 * unreadable file, bad cfg line, two sets); the HCI writer read back. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static char root[256];

static void sh(const char *fmt, const char *a)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, fmt, a, a);
    if (system(cmd)) {
    }
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
}

/* ---- a 16-bit PNG, uncompressed (stored deflate blocks) ---- */
static uint32_t crc_table[256];
static uint32_t crc(const unsigned char *b, size_t n, uint32_t c)
{
    if (!crc_table[1])
        for (uint32_t i = 0; i < 256; i++) {
            uint32_t v = i;
            for (int k = 0; k < 8; k++)
                v = v & 1 ? 0xedb88320u ^ (v >> 1) : v >> 1;
            crc_table[i] = v;
        }
    c = ~c;
    for (size_t i = 0; i < n; i++)
        c = crc_table[(c ^ b[i]) & 0xff] ^ (c >> 8);
    return ~c;
}
static void be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24), p[1] = (unsigned char)(v >> 16), p[2] = (unsigned char)(v >> 8),
    p[3] = (unsigned char)v;
}
static void chunk(FILE *f, const char *type, const unsigned char *data, uint32_t n)
{
    unsigned char h[8];
    be32(h, n);
    memcpy(h + 4, type, 4);
    fwrite(h, 1, 8, f);
    if (n)
        fwrite(data, 1, n, f);
    uint32_t c = crc((const unsigned char *)type, 4, 0);
    c = crc(data, n, c);
    be32(h, c);
    fwrite(h, 1, 4, f);
}
/* RGB, 16 bits per sample, big-endian samples v[(y * w + x) * 3 + c] */
static void write_png16(const char *path, int w, int h, const uint16_t *v)
{
    size_t row = 1 + (size_t)w * 6, raw_n = row * h;
    unsigned char *raw = malloc(raw_n);
    for (int y = 0; y < h; y++) {
        raw[y * row] = 0; /* filter: none */
        for (int i = 0; i < w * 3; i++) {
            raw[y * row + 1 + 2 * i] = (unsigned char)(v[(size_t)y * w * 3 + i] >> 8);
            raw[y * row + 2 + 2 * i] = (unsigned char)v[(size_t)y * w * 3 + i];
        }
    }
    /* zlib stream: header, one stored block (raw_n < 65536), adler32 */
    size_t zn = 2 + 5 + raw_n + 4;
    unsigned char *z = malloc(zn);
    z[0] = 0x78, z[1] = 0x01;
    z[2] = 1, z[3] = (unsigned char)raw_n, z[4] = (unsigned char)(raw_n >> 8);
    z[5] = (unsigned char)~raw_n, z[6] = (unsigned char)(~raw_n >> 8);
    memcpy(z + 7, raw, raw_n);
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < raw_n; i++)
        a = (a + raw[i]) % 65521, b = (b + a) % 65521;
    be32(z + 7 + raw_n, b << 16 | a);
    FILE *f = fopen(path, "wb");
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    fwrite(sig, 1, 8, f);
    unsigned char ihdr[13];
    be32(ihdr, (uint32_t)w), be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 16, ihdr[9] = 2, ihdr[10] = ihdr[11] = ihdr[12] = 0;
    chunk(f, "IHDR", ihdr, 13);
    chunk(f, "IDAT", z, (uint32_t)zn);
    chunk(f, "IEND", NULL, 0);
    fclose(f);
    free(raw), free(z);
}

/* the sRGB transfer curve, decoded (IEC 61966-2-1) */
static double srgb_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* view k's pixel (x, y), channel c: distinct per view, pixel and channel */
static float pattern(int k, int x, int y, int c)
{
    return (float)(0.05 + 0.9 * fmod(0.137 * k + 0.071 * x + 0.033 * y + 0.29 * c, 1.0));
}

static void write_view(const char *path, int k, int w, int h)
{
    lf_image img;
    lf_error err = {0};
    lf_image_alloc(&img, w, h, 3, &err);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                lf_image_px(&img, x, y)[c] = pattern(k, x, y, c);
    CHECK(lf_image_write(path, &img, NULL, NULL, &err) == 0);
    lf_image_free(&img);
}

static int scan_load(const char *dir, lf_lightfield_folder *f, lf_lightfield *lf, lf_error *err)
{
    memset(lf, 0, sizeof *lf);
    int rc = lf_lightfield_folder_scan(dir, f, err);
    if (!rc)
        rc = lf_lightfield_folder_load(f, NULL, lf, err);
    return rc;
}

/* Every view of lf equals the file read on its own (placement). */
static int views_match_files(const lf_lightfield_folder *f, const lf_lightfield *lf)
{
    int ok = 1;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            lf_image img;
            lf_error err = {0};
            if (lf_image_read(f->files[iv * lf->nu + iu], &img, NULL, &err))
                return 0;
            ok &= memcmp(img.data, lf_lightfield_view(lf, iu, iv), sizeof(float) * 3 * lf->ns * lf->nt) == 0;
            lf_image_free(&img);
        }
    return ok;
}

enum { W = 8, H = 6 };
static const char *cfg_text =
    "[intrinsics]\nfocal_length_mm = 50.0\nimage_resolution_x_px = 8\nimage_resolution_y_px = 6\n"
    "sensor_size_mm = 36.0\nfstop = 100.0\n\n[extrinsics]\nnum_cams_x = 3\nnum_cams_y = 2\nbaseline_mm = 20.0\n"
    "focus_distance_m = 3.0\n\n[meta]\nscene = test\ndisp_min = -0.5\ndisp_max = 1.25\n";

static void make_hci(const char *dir)
{
    sh("rm -rf %s && mkdir -p %s", dir);
    char path[600];
    for (int k = 0; k < 6; k++) {
        snprintf(path, sizeof path, "%s/input_Cam%03d.png", dir, k);
        write_view(path, k, W, H);
    }
    snprintf(path, sizeof path, "%s/parameters.cfg", dir);
    write_text(path, cfg_text);
}

static void test_hci(void)
{
    char dir[512], path[700];
    snprintf(dir, sizeof dir, "%s/hci", root);
    make_hci(dir);
    snprintf(path, sizeof path, "%s/LICENSE.txt", dir); /* other files are ignored */
    write_text(path, "x");
    lf_lightfield_folder f;
    lf_lightfield lf;
    lf_error err = {0};
    CHECK_MSG(scan_load(dir, &f, &lf, &err) == 0, "%s", err.msg);
    CHECK(f.kind == LF_LIGHTFIELD_FOLDER_HCI && lf.nu == 3 && lf.nv == 2 && lf.ns == W && lf.nt == H);
    if (lf.data) {
        CHECK(views_match_files(&f, &lf));
        /* view (2, 1) is file 1 * 3 + 2 = 5, 8-bit sRGB linearised */
        float v = lf_lightfield_view(&lf, 2, 1)[(3 * W + 4) * 3 + 1];
        double byte = floor(255 * (1.055 * pow(pattern(5, 4, 3, 1), 1 / 2.4) - 0.055) + 0.5);
        CHECK_NEAR(v, srgb_linear(byte / 255), 1e-6);
    }
    /* geometry from parameters.cfg: F = 50 / 36 * 8 px (sensor across the
     * longer side), baseline 2 cm, disparity 0 at 3 m */
    double F = 50.0 / 36 * 8;
    CHECK(lf.layout.kind == LF_LIGHTFIELD_CAMERA_ARRAY && lf.layout.cams_x == 3 && lf.layout.cams_y == 2);
    CHECK_NEAR(lf.disp_per_inv_m, F * 0.02, 1e-9);
    CHECK_NEAR(lf.disp_at_inf, -F * 0.02 / 3, 1e-9);
    CHECK_NEAR(lf.layout.fov_deg, 2 * atan(3 / F) * 180 / M_PI, 1e-9);
    CHECK_NEAR(lf.layout.grid_bounds[1] - lf.layout.grid_bounds[0], 0.04, 1e-12);
    CHECK_NEAR(lf.layout.grid_bounds[3] - lf.layout.grid_bounds[2], 0.02, 1e-12);
    CHECK((lf.layout.have & LF_LIGHTFIELD_HAVE_DISP_RANGE) && lf.layout.disp_min == -0.5 && lf.layout.disp_max == 1.25);
    double d;
    CHECK(lf_lightfield_depth_to_disparity(&lf, 3.0, &d, &err) == 0 && fabs(d) < 1e-12);
    lf_lightfield_free(&lf);
    lf_lightfield_folder_free(&f);

    /* flags that contradict the folder fail; agreeing ones pass */
    lf_lightfield_layout fl;
    lf_lightfield_layout_init(&fl);
    fl.cams_x = 2, fl.cams_y = 3, fl.have = LF_LIGHTFIELD_HAVE_CAMS;
    lf_error e2 = {0};
    CHECK(lf_lightfield_folder_scan(dir, &f, &e2) == 0);
    CHECK(lf_lightfield_folder_load(&f, &fl, &lf, &e2) != 0 && strstr(e2.msg, "--camsperdim"));
    lf_lightfield_folder_free(&f);

    /* no parameters.cfg: a square count of views makes the grid */
    snprintf(path, sizeof path, "%s/hci_nocfg", root);
    sh("rm -rf %s && mkdir -p %s", path);
    for (int k = 0; k < 4; k++) {
        char p2[800];
        snprintf(p2, sizeof p2, "%s/input_Cam%03d.png", path, k);
        write_view(p2, k, W, H);
    }
    lf_error e3 = {0};
    CHECK_MSG(scan_load(path, &f, &lf, &e3) == 0, "%s", e3.msg);
    CHECK(lf.nu == 2 && lf.nv == 2 && lf.disp_per_inv_m == 0);
    lf_lightfield_free(&lf);
    lf_lightfield_folder_free(&f);
}

/* One failure: scan or load fails and the message names each of `names`. */
static void expect_fail(const char *dir, const char *a, const char *b)
{
    lf_lightfield_folder f;
    lf_lightfield lf;
    lf_error err = {0};
    int rc = scan_load(dir, &f, &lf, &err);
    CHECK_MSG(rc != 0, "%s loaded", dir);
    CHECK_MSG(strstr(err.msg, a) != NULL, "\"%s\" lacks \"%s\"", err.msg, a);
    if (b)
        CHECK_MSG(strstr(err.msg, b) != NULL, "\"%s\" lacks \"%s\"", err.msg, b);
    if (!rc)
        lf_lightfield_free(&lf);
    lf_lightfield_folder_free(&f);
}

static void test_hci_failures(void)
{
    char dir[512], path[700];
    snprintf(dir, sizeof dir, "%s/bad", root);
    /* a missing view */
    make_hci(dir);
    snprintf(path, sizeof path, "%s/input_Cam004.png", dir);
    remove(path);
    expect_fail(dir, "input_Cam004.png", "missing");
    /* more views than the cfg's grid */
    make_hci(dir);
    snprintf(path, sizeof path, "%s/input_Cam006.png", dir);
    write_view(path, 6, W, H);
    expect_fail(dir, "input_Cam006.png", "3 x 2");
    /* views of different sizes */
    make_hci(dir);
    snprintf(path, sizeof path, "%s/input_Cam003.png", dir);
    write_view(path, 3, W, H - 1);
    expect_fail(dir, "input_Cam003.png", "8 x 5");
    /* an unreadable view */
    make_hci(dir);
    snprintf(path, sizeof path, "%s/input_Cam002.png", dir);
    write_text(path, "not a png");
    expect_fail(dir, "input_Cam002.png", NULL);
    /* a size the cfg contradicts */
    make_hci(dir);
    for (int k = 0; k < 6; k++) {
        snprintf(path, sizeof path, "%s/input_Cam%03d.png", dir, k);
        write_view(path, k, W + 2, H);
    }
    expect_fail(dir, "parameters.cfg", "10 x 6");
    /* bad cfg lines: no '=', a number that is not one, a broken section */
    const char *bad[][2] = {{"baseline_mm 20\n", "parameters.cfg:11:"},
                            {"baseline_mm = 2O\n", "parameters.cfg:11: baseline_mm"},
                            {"[extrinsics\n", "parameters.cfg:11:"}};
    for (int i = 0; i < 3; i++) {
        make_hci(dir);
        snprintf(path, sizeof path, "%s/parameters.cfg", dir);
        char text[2048];
        snprintf(text, sizeof text, "%.*s%s", (int)(strstr(cfg_text, "baseline_mm") - cfg_text), cfg_text, bad[i][0]);
        write_text(path, text);
        expect_fail(dir, bad[i][1], NULL);
    }
}

static void test_rowcol(void)
{
    char dir[512], path[800];
    /* 0-based EXR, Lytro-decoder style, 2 rows x 3 columns */
    snprintf(dir, sizeof dir, "%s/lytro", root);
    sh("rm -rf %s && mkdir -p %s", dir);
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 3; c++) {
            snprintf(path, sizeof path, "%s/scene_%02d_%02d.exr", dir, r, c);
            write_view(path, 10 * r + c, W, H);
        }
    snprintf(path, sizeof path, "%s/scene_depth.png", dir); /* no row/column: ignored */
    write_view(path, 99, 3, 3);
    lf_lightfield_folder f;
    lf_lightfield lf;
    lf_error err = {0};
    CHECK_MSG(scan_load(dir, &f, &lf, &err) == 0, "%s", err.msg);
    CHECK(f.kind == LF_LIGHTFIELD_FOLDER_ROWCOL && f.base == 0 && lf.nu == 3 && lf.nv == 2);
    if (lf.data) {
        /* EXR is linear float: row 1, column 2 holds pattern 12 exactly */
        CHECK(lf_lightfield_view(&lf, 2, 1)[(2 * W + 5) * 3 + 2] == pattern(12, 5, 2, 2));
        CHECK(lf_lightfield_view(&lf, 0, 1)[0] == pattern(10, 0, 0, 0));
    }
    lf_lightfield_free(&lf);
    lf_lightfield_folder_free(&f);
    /* a missing view named by row and column */
    snprintf(path, sizeof path, "%s/scene_01_00.exr", dir);
    remove(path);
    expect_fail(dir, "row 1 column 0", "scene_RR_CC");

    /* 1-based 16-bit PNG, Stanford-archive style names with positions */
    snprintf(dir, sizeof dir, "%s/stanford", root);
    sh("rm -rf %s && mkdir -p %s", dir);
    uint16_t px[W * H * 3];
    for (int r = 1; r <= 2; r++)
        for (int c = 1; c <= 2; c++) {
            for (int i = 0; i < W * H * 3; i++)
                px[i] = (uint16_t)((i * 997 + r * 4099 + c * 13) % 65536);
            snprintf(path, sizeof path, "%s/out_%02d_%02d_%.1f_%.1f.png", dir, r, c, -3.1 * c, 11.2 * r);
            write_png16(path, W, H, px);
        }
    CHECK_MSG(scan_load(dir, &f, &lf, &err) == 0, "%s", err.msg);
    CHECK(f.base == 1 && lf.nu == 2 && lf.nv == 2 && lf.ns == W && lf.nt == H);
    if (lf.data) {
        /* row 2, column 1 = view (0, 1); sample i of it */
        int i = (3 * W + 2) * 3 + 1;
        double c16 = (double)((i * 997 + 2 * 4099 + 1 * 13) % 65536) / 65535;
        CHECK_NEAR(lf_lightfield_view(&lf, 0, 1)[i], srgb_linear(c16), 2e-6);
    }
    lf_lightfield_free(&lf);
    lf_lightfield_folder_free(&f);
    /* rows from 1, columns from 0: refused */
    snprintf(path, sizeof path, "%s/out_01_00_0.0_0.0.png", dir);
    write_png16(path, W, H, px);
    expect_fail(dir, "rows start at 1 and columns at 0", NULL);
    remove(path);
    /* two sets in one folder */
    snprintf(path, sizeof path, "%s/other_01_01.png", dir);
    write_png16(path, W, H, px);
    expect_fail(dir, "two sets", "other_01_01.png");
    remove(path);
    /* nothing that looks like views */
    snprintf(dir, sizeof dir, "%s/empty", root);
    sh("rm -rf %s && mkdir -p %s", dir);
    expect_fail(dir, "no light-field views", "input_CamNNN");
}

/* lf_lightfield_write_hci, read back by the folder reader. */
static void test_write_hci(void)
{
    lf_lightfield lf;
    lf_error err = {0};
    CHECK(lf_lightfield_alloc(&lf, 3, 3, 10, 7, &err) == 0);
    for (int k = 0; k < 9; k++)
        for (int p = 0; p < 70; p++)
            for (int c = 0; c < 3; c++)
                lf.data[((size_t)k * 70 + p) * 3 + c] = (float)srgb_linear(pattern(k, p % 10, p / 10, c));
    lf_lightfield_layout lay;
    lf_lightfield_layout_init(&lay);
    lay.kind = LF_LIGHTFIELD_CAMERA_ARRAY, lay.cams_x = lay.cams_y = 3, lay.tile_w = 10, lay.tile_h = 7;
    lay.grid_bounds[0] = -0.05, lay.grid_bounds[1] = 0.05, lay.grid_bounds[2] = -0.05, lay.grid_bounds[3] = 0.05;
    lay.fov_deg = 35;
    lay.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_TILE | LF_LIGHTFIELD_HAVE_BOUNDS | LF_LIGHTFIELD_HAVE_FOV;
    lf_lightfield_set_geometry(&lf, &lay);
    lf_image gt;
    CHECK(lf_image_alloc(&gt, 10, 7, 1, &err) == 0);
    for (int p = 0; p < 70; p++)
        gt.data[p] = (float)(-0.3 + 0.021 * p);
    char dir[512], path[700];
    snprintf(dir, sizeof dir, "%s/written", root);
    CHECK_MSG(lf_lightfield_write_hci(dir, &lf, &gt, &err) == 0, "%s", err.msg);
    lf_lightfield_folder f;
    lf_lightfield back;
    CHECK_MSG(scan_load(dir, &f, &back, &err) == 0, "%s", err.msg);
    CHECK(back.nu == 3 && back.nv == 3 && back.ns == 10 && back.nt == 7);
    if (back.data) {
        /* 8-bit sRGB: within half a code value, in the encoded domain */
        double worst = 0;
        for (size_t i = 0; i < (size_t)9 * 70 * 3; i++) {
            double v = back.data[i], enc = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
            double e = fabs(pattern((int)(i / 210), (int)(i / 3 % 70) % 10, (int)(i / 3 % 70) / 10, (int)(i % 3)) - enc);
            worst = e > worst ? e : worst;
        }
        CHECK_MSG(worst < 0.5 / 255 + 1e-6, "worst %g", worst);
    }
    CHECK_NEAR(back.layout.fov_deg, 35, 1e-6);
    CHECK_NEAR(back.layout.grid_bounds[1] - back.layout.grid_bounds[0], 0.1, 1e-9);
    CHECK_NEAR(back.disp_per_inv_m, lf.disp_per_inv_m, 1e-6 * lf.disp_per_inv_m);
    CHECK(back.layout.have & LF_LIGHTFIELD_HAVE_DISP_RANGE);
    CHECK_NEAR(back.layout.disp_min, -0.3, 1e-6);
    CHECK_NEAR(back.layout.disp_max, -0.3 + 0.021 * 69, 1e-6);
    CHECK(f.gt_disparity != NULL);
    lf_image g2;
    snprintf(path, sizeof path, "%s/gt_disp_lowres.pfm", dir);
    CHECK(lf_image_read(path, &g2, NULL, &err) == 0);
    CHECK(g2.width == 10 && g2.height == 7 && g2.data && memcmp(g2.data, gt.data, 70 * sizeof(float)) == 0);
    lf_image_free(&g2);
    lf_lightfield_free(&back);
    lf_lightfield_folder_free(&f);
    lf_image_free(&gt);
    lf_lightfield_free(&lf);
}

int main(void)
{
    snprintf(root, sizeof root, "%s/test_lf_folder.XXXXXX", P_tmpdir);
    if (!mkdtemp(root)) {
        perror("mkdtemp");
        return 1;
    }
    test_hci();
    test_hci_failures();
    test_rowcol();
    test_write_hci();
    sh("rm -rf %s #%s", root);
    return lf_test_end();
}
