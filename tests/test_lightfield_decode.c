/* Layouts and decoding: synthetic plenoptic raws built here (square and hex
 * grids, rotated, non-integer pitch) decode to the views encoded in them;
 * camera-array tiles; white-image devignetting; missing and non-finite
 * samples; layouts from attributes, flags, contradictions, missing fields. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"

/* Lens centre in pixels, the format's formula (docs/lightfield-format.md). */
static void lens_centre(const lf_lightfield_layout *l, int i, int j, double *x, double *y)
{
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    double lx = i * l->pitch_px + (hex && (j & 1) ? l->pitch_px / 2 : 0);
    double ly = j * l->pitch_px * (hex ? sqrt(3.0) / 2 : 1);
    double c = cos(l->rotation_rad), s = sin(l->rotation_rad);
    *x = l->offset_px[0] + c * lx - s * ly;
    *y = l->offset_px[1] + s * lx + c * ly;
}

/* Per-lens linear microimage: value(i, j, du, dv, ch) = A + B du + C dv, where
 * (du, dv) is the pixel offset from the lens centre.  A is a function of the
 * lens's lattice position (linear for hex, so resampling is exact). */
static double lensA(const lf_lightfield_layout *l, int i, int j, int ch)
{
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    double lx = i + (hex && (j & 1) ? 0.5 : 0), ly = j * (hex ? sqrt(3.0) / 2 : 1);
    if (hex)
        return 0.3 + 0.01 * lx + 0.007 * ly + 0.1 * ch;
    return 0.4 + 0.3 * sin(1.7 * i + 0.3 * ch) * cos(0.9 * j); /* arbitrary per lens */
}
static const double LB[3] = {0.011, -0.007, 0.004}, LC[3] = {-0.005, 0.009, 0.006};

/* nearest lens by brute force over a neighbourhood of the rounded guess */
static void nearest_lens(const lf_lightfield_layout *l, double px, double py, int *bi, int *bj)
{
    double c = cos(l->rotation_rad), s = sin(l->rotation_rad);
    double rx = px - l->offset_px[0], ry = py - l->offset_px[1];
    double lx = c * rx + s * ry, ly = -s * rx + c * ry; /* inverse rotation */
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    int gj = (int)lround(ly / (l->pitch_px * (hex ? sqrt(3.0) / 2 : 1))), gi = (int)lround(lx / l->pitch_px);
    double best = 1e30;
    for (int j = gj - 2; j <= gj + 2; j++)
        for (int i = gi - 2; i <= gi + 2; i++) {
            double x, y;
            lens_centre(l, i, j, &x, &y);
            double d = (x - px) * (x - px) + (y - py) * (y - py);
            if (d < best)
                best = d, *bi = i, *bj = j;
        }
}

static void make_raw(const lf_lightfield_layout *l, int w, int h, lf_image *raw, const lf_image *white)
{
    lf_error err = {0};
    lf_image_alloc(raw, w, h, 3, &err);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int i = 0, j = 0;
            double cx, cy;
            nearest_lens(l, x + 0.5, y + 0.5, &i, &j);
            lens_centre(l, i, j, &cx, &cy);
            for (int ch = 0; ch < 3; ch++) {
                double v = lensA(l, i, j, ch) + LB[ch] * (x + 0.5 - cx) + LC[ch] * (y + 0.5 - cy);
                if (white)
                    v *= lf_image_px(white, x, y)[ch];
                lf_image_px(raw, x, y)[ch] = (float)v;
            }
        }
}

/* view (iu, iv) of lens (i, j) samples pixel offset +(u, v) (a pixel right
 * of its image centre sees the right of the aperture): expected value */
static double expected(const lf_lightfield_layout *l, int i, int j, int ou, int ov, int ch)
{
    return lensA(l, i, j, ch) + LB[ch] * ou + LC[ch] * ov;
}

static void test_square(void)
{
    lf_error err = {0};
    lf_lightfield_layout file, flags, lay;
    lf_lightfield_layout_init(&file);
    lf_lightfield_layout_init(&flags);
    file.kind = LF_LIGHTFIELD_PLENOPTIC, file.grid = LF_LIGHTFIELD_GRID_SQUARE;
    file.pitch_px = 10.3, file.rotation_rad = 0.03, file.offset_px[0] = 3.2, file.offset_px[1] = 8.9;
    file.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_GRID | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_ROTATION | LF_LIGHTFIELD_HAVE_OFFSET;
    const int w = 211, h = 187;
    CHECK_MSG(lf_lightfield_layout_resolve(&file, &flags, w, h, &lay, &err) == 0, "%s", err.msg);
    CHECK(lay.lens_x == 21 && lay.lens_y == 18);
    lf_image raw;
    make_raw(&lay, w, h, &raw, NULL);
    lf_lightfield lf;
    CHECK_MSG(lf_lightfield_decode(&raw, &lay, NULL, &lf, &err) == 0, "%s", err.msg);
    CHECK(lf.nu == 9 && lf.nv == 9 && lf.ns == 21 && lf.nt == 18);
    /* views whose bilinear footprint stays in its own lens (|o| <= 3 at this
     * pitch and rotation) are exact; samples off the sensor are missing */
    double maxerr = 0;
    int checked = 0, missing_ok = 1;
    for (int iv = 0; iv < 9; iv++)
        for (int iu = 0; iu < 9; iu++)
            for (int j = 0; j < lf.nt; j++)
                for (int i = 0; i < lf.ns; i++) {
                    int ou = iu - 4, ov = iv - 4;
                    double cx, cy;
                    lens_centre(&lay, i, j, &cx, &cy);
                    double sx = cx + ou - 0.5, sy = cy + ov - 0.5; /* pixel-index position */
                    int off = sx < 0 || sy < 0 || sx > w - 1 || sy > h - 1;
                    float valid = lf.valid ? lf.valid[((size_t)(iv * 9 + iu) * lf.nt + j) * lf.ns + i] : 1.f;
                    if (off != (valid == 0.f))
                        missing_ok = 0;
                    if (off || abs(ou) > 3 || abs(ov) > 3)
                        continue;
                    const float *p = lf_lightfield_view(&lf, iu, iv) + ((size_t)j * lf.ns + i) * 3;
                    for (int ch = 0; ch < 3; ch++)
                        maxerr = fmax(maxerr, fabs(p[ch] - expected(&lay, i, j, ou, ov, ch)));
                    checked++;
                }
    printf("square decode (pitch 10.3, rotation 0.03): %d samples, max error %.2g (tol 1e-5), %zu missing\n", checked,
           maxerr, lf.missing);
    CHECK(checked > 10000);
    CHECK(maxerr < 1e-5);
    CHECK(missing_ok);
    CHECK(lf.missing > 0);
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
}

static void test_hex(void)
{
    lf_error err = {0};
    lf_lightfield_layout lay, none;
    lf_lightfield_layout_init(&lay);
    lf_lightfield_layout_init(&none);
    lay.kind = LF_LIGHTFIELD_PLENOPTIC, lay.grid = LF_LIGHTFIELD_GRID_HEX;
    lay.pitch_px = 9.7, lay.rotation_rad = -0.02, lay.offset_px[0] = 6.1, lay.offset_px[1] = 6.4;
    lay.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_GRID | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_ROTATION | LF_LIGHTFIELD_HAVE_OFFSET;
    const int w = 200, h = 170;
    lf_lightfield_layout r;
    CHECK(lf_lightfield_layout_resolve(&lay, &none, w, h, &r, &err) == 0);
    lf_image raw;
    make_raw(&r, w, h, &raw, NULL);
    lf_lightfield lf;
    CHECK_MSG(lf_lightfield_decode(&raw, &r, NULL, &lf, &err) == 0, "%s", err.msg);
    int nt = (int)floor((r.lens_y - 1) * sqrt(3.0) / 2) + 1;
    CHECK(lf.nu == 9 && lf.ns == r.lens_x && lf.nt == nt);
    /* output (s, t) sits at lattice position (s, t) pitches: A there, exactly */
    double maxerr = 0;
    int checked = 0;
    for (int iv = 2; iv <= 6; iv++)
        for (int iu = 2; iu <= 6; iu++)
            for (int t = 0; t < lf.nt; t++)
                for (int s = 0; s < lf.ns; s++) {
                    size_t k = ((size_t)(iv * 9 + iu) * lf.nt + t) * lf.ns + s;
                    if (lf.valid && lf.valid[k] == 0.f)
                        continue;
                    for (int ch = 0; ch < 3; ch++) {
                        double e = 0.3 + 0.01 * s + 0.007 * t + 0.1 * ch + LB[ch] * (iu - 4) + LC[ch] * (iv - 4);
                        maxerr = fmax(maxerr, fabs(lf.data[k * 3 + ch] - e));
                    }
                    checked++;
                }
    printf("hex decode (pitch 9.7, rotation -0.02) -> %d x %d rectangular: %d samples, max error %.2g (tol 1e-5)\n",
           lf.ns, lf.nt, checked, maxerr);
    CHECK(checked > 7000); /* of 25 x 20 x 17 */
    CHECK(maxerr < 1e-5);
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
}

/* Integer pitch, centres on pixel centres: samples fall on pixels, so a
 * vignetted raw divided by its white image gives back the scene exactly. */
static void test_white_and_nonfinite(void)
{
    lf_error err = {0};
    lf_lightfield_layout lay, none;
    lf_lightfield_layout_init(&lay);
    lf_lightfield_layout_init(&none);
    lay.kind = LF_LIGHTFIELD_PLENOPTIC;
    lay.pitch_px = 9, lay.offset_px[0] = 4.5, lay.offset_px[1] = 4.5;
    lay.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_OFFSET;
    lay.main_focal_mm = 50, lay.main_fstop = 4, lay.mla_distance_mm = 52, lay.pitch_um = 90;
    lay.have |= LF_LIGHTFIELD_HAVE_MAIN_LENS;
    lf_lightfield_layout r;
    CHECK(lf_lightfield_layout_resolve(&lay, &none, 90, 72, &r, &err) == 0);
    CHECK(r.lens_x == 10 && r.lens_y == 8);
    lf_image white, raw;
    lf_image_alloc(&white, 90, 72, 3, &err);
    for (int y = 0; y < 72; y++)
        for (int x = 0; x < 90; x++) {
            double du = (x % 9) - 4, dv = (y % 9) - 4, rr = (du * du + dv * dv) / 16.0;
            for (int ch = 0; ch < 3; ch++)
                lf_image_px(&white, x, y)[ch] = (float)(rr > 1.0 ? 0.01 : 1.0 - 0.5 * rr); /* corners dark */
        }
    make_raw(&r, 90, 72, &raw, &white);
    lf_lightfield lf;
    CHECK_MSG(lf_lightfield_decode(&raw, &r, &white, &lf, &err) == 0, "%s", err.msg);
    double maxerr = 0;
    size_t dark = 0, dark_missing = 0;
    for (int iv = 0; iv < 9; iv++)
        for (int iu = 0; iu < 9; iu++) {
            int ou = iu - 4, ov = iv - 4;
            int is_dark = (ou * ou + ov * ov) / 16.0 > 1.0;
            for (int j = 0; j < lf.nt; j++)
                for (int i = 0; i < lf.ns; i++) {
                    size_t k = ((size_t)(iv * 9 + iu) * lf.nt + j) * lf.ns + i;
                    if (is_dark) {
                        dark++;
                        dark_missing += lf.valid && lf.valid[k] == 0.f;
                        continue;
                    }
                    for (int ch = 0; ch < 3; ch++)
                        maxerr = fmax(maxerr, fabs(lf.data[k * 3 + ch] - expected(&r, i, j, ou, ov, ch)));
                }
        }
    printf("devignetting by white: max error %.2g (tol 1e-5), dark corner samples missing %zu of %zu\n", maxerr,
           dark_missing, dark);
    CHECK(maxerr < 1e-5);
    CHECK(dark > 0 && dark_missing == dark);

    /* alpha = 1 is the plain average of the (valid) views */
    double d = 1;
    CHECK(lf_lightfield_alpha_to_disparity(&lf, 1.0, &d, &err) == 0);
    CHECK(d == 0);
    /* depth: the plane conjugate to the microlens array (1/z + 1/F = 1/f) has d = 0 */
    double zf = 1.0 / (1.0 / 0.050 - 1.0 / 0.052);
    CHECK(lf_lightfield_depth_to_disparity(&lf, zf, &d, &err) == 0);
    CHECK_MSG(d == 0, "disparity %g at the focused depth: exactly 0, not rounding", d); /* issue 33 */
    {   /* the README's plenoptic demo at its 0.5 m focus printed "disparity 2.9976e-15": its
         * terms carry ~15 ulps of metadata arithmetic; 40 ulps still snap to 0 */
        double keep = lf.disp_at_inf;
        lf.disp_at_inf *= 1 + 40 * DBL_EPSILON;
        CHECK(lf_lightfield_depth_to_disparity(&lf, zf, &d, &err) == 0);
        CHECK_MSG(d == 0, "disparity %g at the focused depth with 40 ulps of rounding in the terms", d);
        lf.disp_at_inf = keep;
    }
    CHECK(lf_lightfield_depth_to_disparity(&lf, zf * (1 + 1e-9), &d, &err) == 0);
    CHECK(d < 0 && d > -1e-6); /* a plane just beyond it is not snapped */
    CHECK(lf_lightfield_depth_to_disparity(&lf, zf / 2, &d, &err) == 0);
    CHECK(d > 0); /* nearer than focus: positive disparity */
    /* alpha for a depth: 1/z + 1/(alpha F) = 1/f, same disparity both ways */
    double z = 0.8, alpha = 1.0 / (0.052 * (1.0 / 0.050 - 1.0 / z)), da, dz;
    CHECK(lf_lightfield_alpha_to_disparity(&lf, alpha, &da, &err) == 0);
    CHECK(lf_lightfield_depth_to_disparity(&lf, z, &dz, &err) == 0);
    CHECK_NEAR(da, dz, 1e-9);
    lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults();
    lf_image img;
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == 0);
    double maxd = 0;
    for (int t = 0; t < lf.nt; t++)
        for (int s = 0; s < lf.ns; s++)
            for (int ch = 0; ch < 3; ch++) {
                double sum = 0, n = 0;
                for (int v = 0; v < 81; v++) {
                    size_t k = ((size_t)v * lf.nt + t) * lf.ns + s;
                    float m = lf.valid ? lf.valid[k] : 1.f;
                    sum += m * lf.data[k * 3 + ch], n += m;
                }
                maxd = fmax(maxd, fabs(sum / n - lf_image_px(&img, s, t)[ch]));
            }
    printf("alpha = 1 refocus vs plain mean of valid views: max |diff| %.2g (tol 1e-6)\n", maxd);
    CHECK(maxd < 1e-6);
    lf_image_free(&img);
    lf_lightfield_free(&lf);

    /* non-finite raw pixels: counted, their samples missing, never averaged in */
    lf_image_px(&raw, 40, 31)[1] = NAN;
    lf_image_px(&raw, 13, 50)[0] = INFINITY;
    lf_image_px(&raw, 77, 9)[2] = NAN;
    CHECK(lf_lightfield_decode(&raw, &r, NULL, &lf, &err) == 0);
    CHECK(lf.nonfinite == 3);
    CHECK(lf.missing >= 3);
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == 0);
    CHECK(lf_image_count_nonfinite(&img) == 0);
    lf_image_free(&img);
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
    lf_image_free(&white);
}

static void test_layouts(void)
{
    lf_error err = {0};
    lf_attrs a = {0};
    lf_lightfield_layout file, flags, out;
    lf_lightfield_layout_init(&flags);
    /* nothing at all: the message lists what is missing */
    CHECK(lf_lightfield_layout_from_attrs(&a, &file, &err) == 0);
    CHECK(lf_lightfield_layout_resolve(&file, &flags, 64, 64, &out, &err) == LF_ERR_PARAM);
    CHECK(strstr(err.msg, "lensfield:kind") && strstr(err.msg, "--camsperdim") && strstr(err.msg, "--pitch"));
    lf_error_clear(&err);
    /* camera-array attributes, as lfrender writes them */
    lf_attrs_set_string(&a, "lensfield:kind", "camera-array", NULL);
    float cams[2] = {4, 3}, bounds[4] = {-0.3f, 0.3f, -0.2f, 0.2f};
    lf_attrs_set_floats(&a, "lensfield:cameras_per_dim", cams, 2, NULL);
    lf_attrs_set_floats(&a, "lensfield:camera_grid_bounds", bounds, 4, NULL);
    lf_attrs_set_double(&a, "lensfield:fov_deg", 30, NULL);
    CHECK(lf_lightfield_layout_from_attrs(&a, &file, &err) == 0);
    CHECK(lf_lightfield_layout_resolve(&file, &flags, 80, 45, &out, &err) == 0);
    CHECK(out.tile_w == 20 && out.tile_h == 15);
    CHECK(lf_lightfield_layout_resolve(&file, &flags, 81, 45, &out, &err) == LF_ERR_PARAM); /* does not divide */
    lf_error_clear(&err);
    /* agreeing flags pass, contradicting ones fail naming both */
    flags.cams_x = 4, flags.cams_y = 3, flags.have = LF_LIGHTFIELD_HAVE_CAMS;
    CHECK(lf_lightfield_layout_resolve(&file, &flags, 80, 45, &out, &err) == 0);
    flags.fov_deg = 35, flags.have |= LF_LIGHTFIELD_HAVE_FOV;
    CHECK(lf_lightfield_layout_resolve(&file, &flags, 80, 45, &out, &err) == LF_ERR_PARAM);
    CHECK(strstr(err.msg, "--inputfov") && strstr(err.msg, "lensfield:fov_deg"));
    lf_error_clear(&err);
    /* flags alone describe a raw without attributes */
    lf_lightfield_layout empty;
    lf_lightfield_layout_init(&empty);
    flags.kind = LF_LIGHTFIELD_CAMERA_ARRAY, flags.have |= LF_LIGHTFIELD_HAVE_KIND;
    CHECK(lf_lightfield_layout_resolve(&empty, &flags, 80, 45, &out, &err) == 0);
    /* a camera array without cameras per dim lists it */
    lf_lightfield_layout_init(&flags);
    flags.kind = LF_LIGHTFIELD_CAMERA_ARRAY, flags.have = LF_LIGHTFIELD_HAVE_KIND;
    CHECK(lf_lightfield_layout_resolve(&empty, &flags, 80, 45, &out, &err) == LF_ERR_PARAM);
    CHECK(strstr(err.msg, "lensfield:cameras_per_dim") && strstr(err.msg, "--camsperdim"));
    lf_error_clear(&err);
    /* round trip through attributes */
    lf_attrs b = {0};
    CHECK(lf_lightfield_layout_resolve(&file, NULL, 80, 45, &out, &err) == 0);
    CHECK(lf_lightfield_layout_to_attrs(&out, &b, &err) == 0);
    lf_lightfield_layout back;
    CHECK(lf_lightfield_layout_from_attrs(&b, &back, &err) == 0);
    CHECK(back.cams_x == 4 && back.cams_y == 3 && back.tile_w == 20 && fabs(back.fov_deg - 30) < 1e-9);
    CHECK(fabs(back.grid_bounds[2] + 0.2) < 1e-6);
    /* wrong types are parse errors */
    lf_attrs_set_string(&a, "lensfield:kind", "hologram", NULL);
    CHECK(lf_lightfield_layout_from_attrs(&a, &file, &err) == LF_ERR_PARSE);
    lf_error_clear(&err);
    lf_attrs_free(&a);
    lf_attrs_free(&b);

    /* camera-array decode: tile (i, j) is view (i, j) */
    lf_image raw;
    lf_image_alloc(&raw, 80, 45, 1, &err);
    for (int y = 0; y < 45; y++)
        for (int x = 0; x < 80; x++)
            lf_image_px(&raw, x, y)[0] = (float)(x / 20 + 10 * (y / 15)) + 0.001f * (x % 20);
    lf_lightfield lf;
    CHECK(lf_lightfield_decode(&raw, &out, NULL, &lf, &err) == 0);
    CHECK(lf.nu == 4 && lf.nv == 3 && lf.ns == 20 && lf.nt == 15);
    CHECK(lf_lightfield_view(&lf, 3, 2)[3 * 5 + 1] == (float)(3 + 20) + 0.005f);
    CHECK(lf_lightfield_view(&lf, 1, 0)[0] == 1.f);
    CHECK(lf.valid == NULL && lf.missing == 0);
    lf_lightfield_free(&lf);
    lf_image_free(&raw);
}

/* The layout attributes are decoded once (image/lf_layout_attrs.h) for a
 * strict reader (lf_lightfield_layout_from_attrs: a malformed attribute is
 * an error) and a lenient one (the renderer's disparity AOV: missing). */
static void test_layout_attr_decoding(void)
{
    lf_attrs a = {0};
    lf_layout_attrs la;
    lf_layout_attrs_decode(&a, &la);
    CHECK(la.kind.state == LF_LAYOUT_ATTR_ABSENT && la.fov_deg.state == LF_LAYOUT_ATTR_ABSENT);
    CHECK(la.kind_id == LF_LIGHTFIELD_KIND_UNKNOWN && !la.grid_known);
    float two[2] = {35, 40}, three[3] = {1, 2, 3};
    lf_attrs_set_int(&a, "lensfield:kind", 1, NULL);
    lf_attrs_set_int(&a, "lensfield:microlens_pitch_px", 9, NULL);
    lf_attrs_set_floats(&a, "lensfield:fov_deg", two, 2, NULL);
    lf_attrs_set_floats(&a, "lensfield:tile_size", three, 3, NULL);
    lf_attrs_set_string(&a, "lensfield:grid", "triangle", NULL);
    lf_layout_attrs_decode(&a, &la);
    CHECK(la.kind.state == LF_LAYOUT_ATTR_MALFORMED);
    CHECK(la.microlens_pitch_px.state == LF_LAYOUT_ATTR_SET && la.microlens_pitch_px.v[0] == 9);
    CHECK(la.fov_deg.state == LF_LAYOUT_ATTR_LIST && la.fov_deg.v[0] == 35);
    CHECK(la.tile_size.state == LF_LAYOUT_ATTR_MALFORMED);
    CHECK(la.grid.state == LF_LAYOUT_ATTR_SET && !la.grid_known && !strcmp(la.grid.s, "triangle"));
    CHECK(!strcmp(la.fov_deg.name, "lensfield:fov_deg"));
    /* strict: each of those is an error naming the attribute */
    lf_lightfield_layout lay;
    lf_error err = {0};
    CHECK(lf_lightfield_layout_from_attrs(&a, &lay, &err) == LF_ERR_PARSE && strstr(err.msg, "lensfield:kind"));
    lf_error_clear(&err);
    lf_attrs_set_string(&a, "lensfield:kind", "plenoptic", NULL);
    CHECK(lf_lightfield_layout_from_attrs(&a, &lay, &err) == LF_ERR_PARSE);
    CHECK(!strcmp(err.msg, "attribute lensfield:fov_deg: expected a number"));
    lf_error_clear(&err);
    lf_attrs_set_double(&a, "lensfield:fov_deg", 35, NULL);
    CHECK(lf_lightfield_layout_from_attrs(&a, &lay, &err) == LF_ERR_PARSE);
    CHECK(!strcmp(err.msg, "attribute lensfield:tile_size: expected 2 floats"));
    lf_error_clear(&err);
    lf_attrs_set_floats(&a, "lensfield:tile_size", two, 2, NULL);
    CHECK(lf_lightfield_layout_from_attrs(&a, &lay, &err) == LF_ERR_PARSE && strstr(err.msg, "lensfield:grid"));
    lf_error_clear(&err);
    lf_attrs_set_string(&a, "lensfield:grid", "hex", NULL);
    lf_layout_attrs_decode(&a, &la);
    CHECK(la.kind_id == LF_LIGHTFIELD_PLENOPTIC && la.grid_known && la.grid_id == LF_LIGHTFIELD_GRID_HEX);
    CHECK(lf_lightfield_layout_from_attrs(&a, &lay, &err) == 0);
    CHECK(lay.kind == LF_LIGHTFIELD_PLENOPTIC && lay.grid == LF_LIGHTFIELD_GRID_HEX && lay.pitch_px == 9);
    CHECK(lay.fov_deg == 35 && lay.tile_w == 35 && lay.tile_h == 40);
    /* the names round-trip */
    CHECK(!strcmp(lf_lightfield_kind_name(LF_LIGHTFIELD_CAMERA_ARRAY), "camera-array"));
    CHECK(lf_lightfield_kind_name(LF_LIGHTFIELD_KIND_UNKNOWN) == NULL);
    CHECK(!strcmp(lf_lightfield_grid_name(LF_LIGHTFIELD_GRID_SQUARE), "square"));
    lf_attrs_free(&a);
}

int main(void)
{
    test_layouts();
    test_layout_attr_decoding();
    test_square();
    test_hex();
    test_white_and_nonfinite();
    return lf_test_end();
}
