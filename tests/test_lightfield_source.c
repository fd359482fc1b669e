/* Opening light fields and writing views (lightfield/source.c,
 * lf_source.h), on a 3 x 3 camera-array raw built here whose every sample
 * is a known function of (view, pixel, channel): decoding must put raw
 * pixel (iu*tw + s, iv*th + t) at view (iu, iv), pixel (s, t)
 * (docs/lightfield-format.md), so the mosaic of the views is the raw
 * itself.  Also the ground-truth disparity of the centre view, maps,
 * stated disparity ranges, the refocusable range (from its formula) and
 * the synth camera's defaults. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/lf_keys.h"
#include "lf_test.h"
#include "lightfield/lf_source.h"

enum { NU = 3, NV = 3, TW = 4, TH = 5 };
static char dir[256];

static float sample(int iu, int iv, int s, int t, int c)
{
    return (float)(iu + 10 * iv) + 0.01f * (float)(s + 8 * t) + 0.25f * (float)c;
}

/* A camera-array raw with its layout attributes (and extra attributes). */
static int write_raw(const char *path, float nan_at, const char *disp_file, int with_range)
{
    lf_image raw;
    lf_error err = {0};
    if (lf_image_alloc(&raw, NU * TW, NV * TH, 3, &err))
        return -1;
    for (int iv = 0; iv < NV; iv++)
        for (int iu = 0; iu < NU; iu++)
            for (int t = 0; t < TH; t++)
                for (int s = 0; s < TW; s++)
                    for (int c = 0; c < 3; c++)
                        lf_image_px(&raw, iu * TW + s, iv * TH + t)[c] = sample(iu, iv, s, t, c);
    if (nan_at >= 0)
        raw.data[(size_t)nan_at] = NAN;
    lf_lightfield_layout lay;
    lf_lightfield_layout_init(&lay);
    lay.kind = LF_LIGHTFIELD_CAMERA_ARRAY, lay.cams_x = NU, lay.cams_y = NV, lay.tile_w = TW, lay.tile_h = TH;
    lay.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_TILE;
    lf_attrs a = {0};
    int rc = lf_lightfield_layout_to_attrs(&lay, &a, &err);
    if (disp_file)
        lf_attrs_set_string(&a, LF_KEY_DISPARITY_FILE, disp_file, NULL);
    if (with_range)
        lf_attrs_set_double(&a, LF_KEY_DISP_MIN, -1.5, NULL), lf_attrs_set_double(&a, LF_KEY_DISP_MAX, 2.5, NULL);
    lf_write_opts wo = {.allow_nonfinite = 1};
    if (!rc)
        rc = lf_image_write(path, &raw, &a, &wo, &err);
    if (rc)
        fprintf(stderr, "write_raw: %s\n", err.msg);
    lf_attrs_free(&a);
    lf_image_free(&raw);
    return rc;
}

static void test_open_and_views(void)
{
    char raw_path[300], views[300], p[400];
    snprintf(raw_path, sizeof raw_path, "%s/raw.exr", dir);
    CHECK(write_raw(raw_path, -1, NULL, 1) == 0);
    lf_lightfield_source src;
    lf_error err = {0};
    lf_lightfield_open_opts oo = {0};
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &err) == 0);
    CHECK(src.lf.nu == NU && src.lf.nv == NV && src.lf.ns == TW && src.lf.nt == TH);
    CHECK(src.folder.dir == NULL && src.raw_nonfinite == 0);
    int bad = 0;
    for (int iv = 0; iv < NV; iv++)
        for (int iu = 0; iu < NU; iu++)
            for (int t = 0; t < TH; t++)
                for (int s = 0; s < TW; s++)
                    for (int c = 0; c < 3; c++)
                        bad += lf_lightfield_view(&src.lf, iu, iv)[(t * TW + s) * 3 + c] != sample(iu, iv, s, t, c);
    CHECK_MSG(bad == 0, "%d decoded samples differ from the raw's", bad);

    char text[4096];
    lf_lightfield_source_describe(&src, text, sizeof text);
    snprintf(p, sizeof p, "%s: %d x %d raw, 3 channels\n", raw_path, NU * TW, NV * TH);
    CHECK_MSG(!strncmp(text, p, strlen(p)), "describe: %s", text);

    /* the disparity range the file states */
    double d0, d1;
    const char *from = lf_lightfield_source_disparity_range(&src, &d0, &d1);
    CHECK(from && !strcmp(from, "lensfield:disp_min/max") && d0 == -1.5 && d1 == 2.5);

    /* views and the mosaic: the mosaic of a camera array's views is its raw */
    snprintf(views, sizeof views, "%s/views", dir);
    CHECK(lf_lightfield_write_views(&src.lf, views, "exr", NULL, &err) == 0);
    lf_image v, m, raw;
    snprintf(p, sizeof p, "%s/view_01_02.exr", views); /* row 1, column 2 */
    CHECK(lf_image_read(p, &v, NULL, &err) == 0);
    CHECK(v.width == TW && v.height == TH && lf_image_px(&v, 3, 4)[2] == sample(2, 1, 3, 4, 2));
    snprintf(p, sizeof p, "%s/mosaic.exr", views);
    CHECK(lf_image_read(p, &m, NULL, &err) == 0);
    CHECK(lf_image_read(raw_path, &raw, NULL, &err) == 0);
    CHECK(m.width == raw.width && m.height == raw.height && m.channels == 3 &&
          !memcmp(m.data, raw.data, sizeof(float) * 3 * raw.width * raw.height));
    lf_image_free(&v), lf_image_free(&m), lf_image_free(&raw);
    /* a folder that cannot be created is named */
    snprintf(p, sizeof p, "%s/raw.exr/sub", dir);
    lf_error e2 = {0};
    CHECK(lf_lightfield_write_views(&src.lf, p, "exr", NULL, &e2) == LF_ERR_IO && strstr(e2.msg, "cannot create directory"));

    /* maps of the views' size: channel 0, size and values checked */
    lf_image map;
    snprintf(p, sizeof p, "%s/views/view_00_00.exr", dir);
    CHECK(lf_lightfield_read_map(p, &src.lf, &map, &err) == 0);
    CHECK(map.channels == 1 && map.width == TW && map.data[2 * TW + 1] == sample(0, 0, 1, 2, 0));
    lf_image_free(&map);
    lf_error e3 = {0};
    CHECK(lf_lightfield_read_map(raw_path, &src.lf, &map, &e3) == LF_ERR_PARAM && strstr(e3.msg, "map is 12x15"));
    lf_image nanmap;
    CHECK(lf_image_alloc(&nanmap, TW, TH, 1, &err) == 0);
    nanmap.data[5] = NAN;
    snprintf(p, sizeof p, "%s/nan.exr", dir);
    lf_write_opts wo = {.allow_nonfinite = 1};
    CHECK(lf_image_write(p, &nanmap, NULL, &wo, &err) == 0);
    lf_error e4 = {0};
    CHECK(lf_lightfield_read_map(p, &src.lf, &map, &e4) == LF_ERR_NUMERIC && strstr(e4.msg, "non-finite"));
    lf_image_free(&nanmap);

    /* the disparity writer: values with the search range, or a colour picture
     * (maps narrower than 32 px get no legend strip) */
    lf_image disp;
    CHECK(lf_image_alloc(&disp, TW, TH, 1, &err) == 0);
    for (int i = 0; i < TW * TH; i++)
        disp.data[i] = -1 + 0.1f * i;
    lf_attrs a = {0};
    snprintf(p, sizeof p, "%s/disp.exr", dir);
    CHECK(lf_lightfield_write_disparity(p, &disp, -1, 1, NULL, &err) == 0);
    CHECK(lf_image_read(p, &m, &a, &err) == 0 && m.data[7] == disp.data[7]);
    const lf_attr *r = lf_attrs_get(&a, LF_KEY_DISPARITY_SEARCH_RANGE);
    CHECK(r && r->type == LF_ATTR_FLOATS && r->n == 2 && r->v[0] == -1 && r->v[1] == 1);
    lf_image_free(&m), lf_attrs_free(&a);
    snprintf(p, sizeof p, "%s/refocused.exr", dir);
    CHECK(lf_lightfield_write_refocused(p, &disp, -0.75, NULL, &err) == 0);
    CHECK(lf_image_read(p, &m, &a, &err) == 0 && m.data[3] == disp.data[3]);
    r = lf_attrs_get(&a, LF_KEY_REFOCUS_DISPARITY_PX);
    CHECK(r && (r->type == LF_ATTR_DOUBLE || r->type == LF_ATTR_FLOAT) && r->d == -0.75);
    lf_image_free(&m), lf_attrs_free(&a);
    snprintf(p, sizeof p, "%s/disp.png", dir);
    CHECK(lf_lightfield_write_disparity(p, &disp, -1, 1, NULL, &err) == 0);
    CHECK(lf_image_read(p, &m, NULL, &err) == 0 && m.channels >= 3 && m.width == TW && m.height == TH);
    lf_image_free(&m), lf_image_free(&disp);
    lf_lightfield_close(&src);

    /* layout only: nothing decoded */
    oo.layout_only = 1;
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &err) == 0 && src.lf.data == NULL && src.layout.cams_x == NU);
    lf_lightfield_close(&src);
}

static void test_nonfinite(void)
{
    char raw_path[300];
    snprintf(raw_path, sizeof raw_path, "%s/nan_raw.exr", dir);
    CHECK(write_raw(raw_path, 3 * (NU * TW + 1), NULL, 0) == 0); /* pixel (1, 1) of view (0, 0) */
    lf_lightfield_source src;
    lf_error err = {0};
    lf_lightfield_open_opts oo = {0};
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &err) == LF_ERR_NUMERIC);
    CHECK_MSG(strstr(err.msg, "1 non-finite pixel values") && strstr(err.msg, raw_path), "%s", err.msg);
    CHECK(src.lf.data == NULL && src.raw.data == NULL);
    oo.allow_nonfinite = 1;
    lf_error e2 = {0};
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &e2) == 0 && src.lf.nonfinite == 1 && src.raw_nonfinite == 1);
    lf_lightfield_close(&src);
    /* a folder of views takes no white image */
    oo.white = raw_path;
    lf_error e3 = {0};
    CHECK(lf_lightfield_open(dir, &oo, &src, &e3) != 0);
}

static void test_gt_disparity(void)
{
    /* the disparity render: a raw of the same layout whose channel 0 is the disparity */
    char raw_path[300], disp_path[300];
    snprintf(raw_path, sizeof raw_path, "%s/gt_raw.exr", dir);
    snprintf(disp_path, sizeof disp_path, "%s/gt_raw.disparity.exr", dir);
    CHECK(write_raw(raw_path, -1, "gt_raw.disparity.exr", 0) == 0);
    CHECK(write_raw(disp_path, -1, NULL, 0) == 0);
    lf_lightfield_source src;
    lf_error err = {0};
    lf_lightfield_open_opts oo = {0};
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &err) == 0);
    lf_image gt;
    int no_centre = -1;
    CHECK(lf_lightfield_source_gt_disparity(&src, &gt, &no_centre, &err) == 0 && no_centre == 0);
    CHECK(gt.data && gt.width == TW && gt.height == TH && gt.channels == 1);
    CHECK(gt.data && gt.data[3 * TW + 2] == sample(1, 1, 2, 3, 0)); /* the centre view (1, 1) */
    lf_image_free(&gt);
    lf_lightfield_close(&src);
    /* a raw without lensfield:disparity_file has none */
    snprintf(raw_path, sizeof raw_path, "%s/raw.exr", dir);
    CHECK(lf_lightfield_open(raw_path, &oo, &src, &err) == 0);
    CHECK(lf_lightfield_source_gt_disparity(&src, &gt, &no_centre, &err) == 0 && gt.data == NULL);
    lf_lightfield_close(&src);
}

static void test_refocus_range(void)
{
    /* d = P (1 - 1/alpha) with P = disp_per_alpha = 4, so b = 1/P = 0.25 and
     * |d| <= 1 is alpha in [1/(1+b), 1/(1-b)] = [0.8, 1.3333]; d = d_inf + k/z
     * with d_inf = -0.5, k = 2: d = 1 at z = k/(1 - d_inf) = 1.333 m, d = -1
     * never (k/(-1 - d_inf) < 0): the far end is infinity. */
    lf_lightfield lf;
    memset(&lf, 0, sizeof lf);
    lf.disp_per_alpha = 4, lf.disp_at_inf = -0.5, lf.disp_per_inv_m = 2;
    char buf[256];
    CHECK(lf_lightfield_refocus_outside(&lf, 0.999, buf, sizeof buf) == 0);
    CHECK(lf_lightfield_refocus_outside(&lf, -1.0, buf, sizeof buf) == 0);
    CHECK(lf_lightfield_refocus_outside(&lf, 1.2, buf, sizeof buf) == 1);
    CHECK_MSG(strstr(buf, "alpha 0.8 .. 1.3333") && strstr(buf, "depths 1.333 m .. infinity"), "%s", buf);
    lf.disp_at_inf = -3; /* far end d = -1 at z = 2 / 2 = 1 m; near end d = 1 at z = 2 / 4 = 0.5 m */
    CHECK(lf_lightfield_refocus_outside(&lf, -1.5, buf, sizeof buf) == 1 && strstr(buf, "depths 0.5 m .. 1 m"));
    lf.disp_per_alpha = 0; /* not plenoptic: no alpha, no warning */
    CHECK(lf_lightfield_refocus_outside(&lf, 5, buf, sizeof buf) == 0);
}

static void test_synth_prepare(void)
{
    lf_lightfield lf;
    memset(&lf, 0, sizeof lf);
    lf.ns = 40, lf.nt = 30;
    lf_lightfield_layout *y = &lf.layout;
    y->kind = LF_LIGHTFIELD_CAMERA_ARRAY, y->have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_BOUNDS;
    y->grid_bounds[0] = -1, y->grid_bounds[1] = 3, y->grid_bounds[2] = 2, y->grid_bounds[3] = 4;
    lf_lightfield_synth_opts s = lf_lightfield_synth_defaults();
    lf_error err = {0};
    CHECK(lf_lightfield_synth_prepare(&lf, 0, &s, &err) == LF_ERR_PARAM);
    CHECK_MSG(strstr(err.msg, "lensfield:fov_deg (--inputfov DEG)") && !strstr(err.msg, "grid_bounds"), "%s", err.msg);
    y->have |= LF_LIGHTFIELD_HAVE_FOV | LF_LIGHTFIELD_HAVE_CAM_LENS, y->fov_deg = 33, y->focal_distance = 7;
    lf_error e2 = {0};
    CHECK(lf_lightfield_synth_prepare(&lf, 0, &s, &e2) == 0);
    CHECK(s.fov_deg == 33 && s.width == 40 && s.height == 30 && s.focal_distance == 7);
    CHECK(s.pos[0] == 1 && s.pos[1] == 3 && s.pos[2] == 0); /* the grid's centre */
    s = lf_lightfield_synth_defaults();
    s.fov_deg = 10, s.width = 8, s.height = 6, s.pos[0] = 9, s.focal_distance = 2;
    CHECK(lf_lightfield_synth_prepare(&lf, LF_LIGHTFIELD_SYNTH_SET_FOV | LF_LIGHTFIELD_SYNTH_SET_SIZE | LF_LIGHTFIELD_SYNTH_SET_POS |
                                       LF_LIGHTFIELD_SYNTH_SET_FOCAL, &s, &e2) == 0);
    CHECK(s.fov_deg == 10 && s.width == 8 && s.height == 6 && s.pos[0] == 9 && s.focal_distance == 2);
    y->kind = LF_LIGHTFIELD_PLENOPTIC;
    lf_error e3 = {0};
    CHECK(lf_lightfield_synth_prepare(&lf, 0, &s, &e3) == LF_ERR_PARAM && strstr(e3.msg, "camera-array"));
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/test_lightfield_source.%ld", LF_BINARY_DIR, (long)getpid());
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    CHECK(system(cmd) == 0);
    test_open_and_views();
    test_nonfinite();
    test_gt_disparity();
    test_refocus_range();
    test_synth_prepare();
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
    return lf_test_end();
}
