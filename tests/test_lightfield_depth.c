/* Depth estimation and depth-based view synthesis on analytic light fields
 * with known geometry: a camera array (pinholes on a plane, baseline B,
 * focal length F px) looks at a tilted textured plane and, in the second
 * scene, a textured box face occluding it.  Every view pixel is the average
 * of 4 x 4 rays intersected exactly with the surfaces, so the views are
 * pixel-integrated like real captures; the ground-truth disparity of the
 * centre view is F B / Z at each pixel centre (lf_lightfield.h convention:
 * a point moves by -d px when the viewpoint moves one view to the right).
 * Nothing here comes from the code under test. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lf_test_texture.h"

enum { N = 7, W = 96, H = 96, SS = 4 };
static const double F = 96.0, B = 0.02;
/* background plane Z = Z0 + GX X + GY Y; box face at ZB over [BX0,BX1] x [BY0,BY1] */
static const double Z0 = 2.0, GX = 0.3, GY = 0.1;
static const double ZB = 1.2, BX0 = -0.16, BX1 = 0.06, BY0 = -0.10, BY1 = 0.13;
static int g_box;
static double g_ox, g_oy; /* pixel offset of the rendered view (principal point), section 5 */


static void surface_colour(int box, double X, double Y, float c[3])
{
    double n = 0.6 * vnoise(X * 15, Y * 15) + 0.4 * vnoise(X * 6 + 7, Y * 6 + 3);
    double s = 0.5 + 0.5 * sin(2 * M_PI * (4.1 * X + 2.3 * Y));
    if (box)
        c[0] = (float)(0.25 + 0.6 * n), c[1] = (float)(0.1 + 0.3 * n * s), c[2] = (float)(0.1 + 0.2 * n);
    else
        c[0] = (float)(0.1 + 0.3 * n * s), c[1] = (float)(0.2 + 0.5 * n), c[2] = (float)(0.3 + 0.5 * n);
}

/* ray from camera (cx, cy, 0) along (dx, dy, 1): depth of the first hit, colour */
static double trace(double cx, double cy, double dx, double dy, float col[3])
{
    if (g_box == 2) {
        /* thin structures at ZB (1 px there = ZB / F = 0.0125): a wedge
         * along x tapering from 4 px to nothing, and a rod 1 px wide
         * rising at about 21 degrees */
        double X = cx + ZB * dx, Y = cy + ZB * dy;
        double hw = X >= -0.30 && X <= 0.30 ? 0.5 * 0.05 * (0.30 - X) / 0.60 : -1;
        double e = (Y + 0.30 - (X + 0.35) * 0.25 / 0.65) * 0.65 / sqrt(0.65 * 0.65 + 0.25 * 0.25);
        if (fabs(Y - 0.15) <= hw || (X >= -0.35 && X <= 0.30 && fabs(e) <= 0.5 * 0.0125)) {
            if (col) { /* the background's texture darkened: a faint line, as wires and tips are */
                surface_colour(0, X, Y, col);
                col[0] *= 0.7f, col[1] *= 0.7f, col[2] *= 0.7f;
            }
            return ZB;
        }
    } else if (g_box) {
        double X = cx + ZB * dx, Y = cy + ZB * dy;
        if (X >= BX0 && X <= BX1 && Y >= BY0 && Y <= BY1) {
            if (col)
                surface_colour(1, X, Y, col);
            return ZB;
        }
    }
    double t = (Z0 + GX * cx + GY * cy) / (1 - GX * dx - GY * dy);
    if (col)
        surface_colour(0, cx + t * dx, cy + t * dy, col);
    return t;
}

/* camera of view (fu, fv) (fractional view indices allowed), y up in the world */
static void render(double fu, double fv, float *dst)
{
    double cx = (fu - (N - 1) / 2.0) * B, cy = -(fv - (N - 1) / 2.0) * B;
    lf_test_render_view(dst, W, H, SS, F, cx, cy, g_ox, g_oy, trace);
}

static void make_lf(lf_lightfield *lf)
{
    lf_error err = {0};
    lf_lightfield_alloc(lf, N, N, W, H, &err);
    lf->disp_v_per_u = 1.0;
    /* as a CS348B camera array (synth): cameras on z = 0, y up, fov across W */
    lf_lightfield_layout *l = &lf->layout;
    l->kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    l->cams_x = l->cams_y = N;
    l->grid_bounds[0] = l->grid_bounds[2] = -B * (N - 1) / 2;
    l->grid_bounds[1] = l->grid_bounds[3] = B * (N - 1) / 2;
    l->fov_deg = 2 * atan(W / 2.0 / F) * 180 / M_PI, l->tile_w = W, l->tile_h = H;
    l->have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_BOUNDS | LF_LIGHTFIELD_HAVE_FOV | LF_LIGHTFIELD_HAVE_TILE;
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++)
            render(u, v, lf_lightfield_view(lf, u, v));
}

static void ground_truth(float *gt)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            gt[(size_t)y * W + x] = (float)(F * B / trace(0, 0, (x + 0.5 - W / 2.0) / F, -(y + 0.5 - H / 2.0) / F, NULL));
}

typedef struct scores {
    double bad07, bad30, mse100, mean_abs;
} scores;

/* over pixels with mask (NULL: all), 8-px border excluded */
static scores score(const float *d, const float *gt, const unsigned char *mask)
{
    scores s = {0, 0, 0, 0};
    size_t n = 0;
    for (int y = 8; y < H - 8; y++)
        for (int x = 8; x < W - 8; x++) {
            size_t i = (size_t)y * W + x;
            if (mask && !mask[i])
                continue;
            double e = d[i] - gt[i];
            s.bad07 += fabs(e) > 0.07, s.bad30 += fabs(e) > 0.3, s.mse100 += e * e, s.mean_abs += fabs(e);
            n++;
        }
    if (n)
        s.bad07 *= 100.0 / n, s.bad30 *= 100.0 / n, s.mse100 *= 100.0 / n, s.mean_abs /= n;
    return s;
}

static double psnr(const float *a, const float *b, int border)
{
    double se = 0;
    size_t n = 0;
    for (int y = border; y < H - border; y++)
        for (int x = border; x < W - border; x++)
            for (int k = 0; k < 3; k++) {
                double e = a[((size_t)y * W + x) * 3 + k] - b[((size_t)y * W + x) * 3 + k];
                se += e * e, n++;
            }
    return se > 0 ? 10 * log10(1.0 / (se / n)) : 999;
}

/* Band-limited texture for the resampling-phase check: a sum of sinusoids
 * with frequencies up to 0.42 cycles per pixel, exact at any position. */
static double bl_tex(double x, double y, int ch)
{
    double v = 0.5;
    for (int k = 0; k < 12; k++) {
        double a = 2 * M_PI * hash2(k, 1), r = 0.12 + 0.30 * hash2(k, 2), ph = 2 * M_PI * hash2(k, 3 + ch);
        v += 0.035 * sin(2 * M_PI * r * (x * cos(a) + y * sin(a)) + ph);
    }
    return v;
}

int main(void)
{
    lf_error err = {0};
    float *gt = malloc(sizeof(float) * W * H);
    unsigned char *band_out = calloc(W * H, 1), *band_in = calloc(W * H, 1);
    float *truth = malloc(sizeof(float) * W * H * 3);

    /* ---- 1. tilted plane: range estimated from the data ---- */
    g_box = 0;
    lf_lightfield lf = {0};
    make_lf(&lf);
    ground_truth(gt);
    float gmin = 1e9f, gmax = -1e9f;
    for (int i = 0; i < W * H; i++)
        gmin = gt[i] < gmin ? gt[i] : gmin, gmax = gt[i] > gmax ? gt[i] : gmax;
    double r0, r1;
    CHECK_MSG(lf_lightfield_depth_range(&lf, 2, &r0, &r1, &err) == 0, "%s", err.msg);
    printf("tilted plane: true disparity %.3f .. %.3f, estimated search range %.3f .. %.3f\n", gmin, gmax, r0, r1);
    /* the search range must hold every true disparity, and not be absurdly wide
     * (at most 3x the true span plus 1 px/view) */
    CHECK(r0 <= gmin && r1 >= gmax);
    CHECK(r1 - r0 <= 3 * (gmax - gmin) + 1.0);
    lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
    lf_image d, c;
    CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, &c, &err) == 0, "%s", err.msg);
    scores s = score(d.data, gt, NULL);
    printf("  depth: BadPix0.07 %.2f %%, MSE x 100 %.4f, mean |err| %.4f px/view\n", s.bad07, s.mse100, s.mean_abs);
    /* targets: the benchmark goal (BadPix0.07 <= 5 %, MSE x 100 <= 4) with a
     * 2.5x margin for a clean, fully textured, occlusion-free scene */
    CHECK(s.bad07 < 2.0);
    CHECK(s.mse100 < 1.6);
    int conf_ok = 1;
    for (int i = 0; i < W * H; i++)
        conf_ok &= c.data[i] >= 0 && c.data[i] <= 1 && isfinite(d.data[i]);
    CHECK(conf_ok);
    lf_image_free(&d), lf_image_free(&c);
    {
        /* sub-label precision: labels are 0.2 px of shift at the outermost view
         * (3 steps) apart, 0.067 px/view; the cubic lookups and the
         * Gauss-Newton refinement must place the plane well inside a label
         * (mean |err| below a quarter label) and beat the bilinear,
         * label-and-parabola estimate (measured: 0.0030 against 0.0066) */
        lf_lightfield_depth_opts ob = lf_lightfield_depth_defaults();
        ob.interp = 1, ob.refine = -1;
        lf_image db;
        CHECK_MSG(lf_lightfield_depth(&lf, &ob, &db, NULL, &err) == 0, "%s", err.msg);
        scores sb = score(db.data, gt, NULL);
        printf("  sub-label: mean |err| %.4f px/view (bilinear lookups, no refinement: %.4f)\n", s.mean_abs,
               sb.mean_abs);
        CHECK(s.mean_abs < 0.25 * 0.2 / 3);
        CHECK(s.mean_abs < 0.8 * sb.mean_abs);
        lf_image_free(&db);
    }

    {
        /* a range wider than 512 labels at the default spacing (0.2 px at the
         * outermost view: 0.067 px/view here, so -18 .. 18 would be 541
         * labels) spreads the labels instead of failing; the plane is still
         * found (labels 0.07 px/view apart, refined within them) */
        lf_lightfield_depth_opts ow = lf_lightfield_depth_defaults();
        ow.d0 = -18, ow.d1 = 18;
        lf_image dw;
        CHECK_MSG(lf_lightfield_depth(&lf, &ow, &dw, NULL, &err) == 0, "%s", err.msg);
        scores sw = score(dw.data, gt, NULL);
        printf("  range -18 .. 18 px/view: BadPix0.07 %.2f %%, MSE x 100 %.4f\n", sw.bad07, sw.mse100);
        CHECK(sw.bad07 < 2.0);
        CHECK(sw.mse100 < 1.6);
        lf_image_free(&dw);
    }

    /* missing samples (lf->valid, as decode marks them; their data are 0): a
     * 40 x 40 block missing in 36 of the 48 other views must not disturb the
     * map there (the mask is honoured; the minimum over view subsets would
     * mostly tolerate the zeros anyway, so this is a robustness check) */
    lf.valid = malloc(sizeof(float) * (size_t)N * N * W * H);
    for (size_t i = 0; i < (size_t)N * N * W * H; i++)
        lf.valid[i] = 1.f;
    for (int k = 0, m = 0; m < 36; k++) { /* every view but the centre's row and column */
        int iu = k % N, iv = k / N;
        if (iu == N / 2 || iv == N / 2)
            continue;
        m++;
        for (int y = 30; y < 70; y++)
            for (int x = 30; x < 70; x++) {
                lf.valid[((size_t)(iv * N + iu) * H + y) * W + x] = 0.f;
                memset(lf_lightfield_view(&lf, iu, iv) + ((size_t)y * W + x) * 3, 0, 3 * sizeof(float));
            }
    }
    CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
    s = score(d.data, gt, NULL);
    printf("  depth with missing samples: BadPix0.07 %.2f %%, MSE x 100 %.4f\n", s.bad07, s.mse100);
    CHECK(s.bad07 < 2.0);
    CHECK(s.mse100 < 1.6);
    {
        /* and a view between the cameras from those views: the missing
         * samples (0) left out, the view as good as from complete views
         * below (> 45 dB) */
        lf_lightfield_view_opts mvo = lf_lightfield_view_defaults();
        mvo.disparity = &d;
        lf_image mv;
        CHECK_MSG(lf_lightfield_view_depth(&lf, 0.5, -1.5, &mvo, &mv, &err) == 0, "%s", err.msg);
        render(3.5, 1.5, truth);
        double pm = psnr(mv.data, truth, 8);
        printf("  view (0.5, -1.5) with missing samples: %.2f dB\n", pm);
        CHECK(pm > 45);
        lf_image_free(&mv);
    }
    lf_image_free(&d);
    free(lf.valid);
    lf.valid = NULL;
    for (int v = 0; v < N; v++) /* restore the views */
        for (int u = 0; u < N; u++)
            render(u, v, lf_lightfield_view(&lf, u, v));

    /* a view at a position between the data cameras, against its analytic render */
    lf_lightfield_view_opts vo = lf_lightfield_view_defaults();
    lf_image view;
    CHECK_MSG(lf_lightfield_view_depth(&lf, 0.5, -1.5, &vo, &view, &err) == 0, "%s", err.msg);
    render(3.5, 1.5, truth);
    double p_depth = psnr(view.data, truth, 8);
    lf_image_free(&view);
    CHECK(lf_lightfield_view_at(&lf, 0.5, -1.5, 0.0, &view, &err) == 0);
    double p_plane = psnr(view.data, truth, 8);
    lf_image_free(&view);
    printf("  view (0.5, -1.5): per-pixel depth %.2f dB, plane d=0 %.2f dB\n", p_depth, p_plane);
    /* the textures are band-limited (detail of 4 px and more), so with good
     * geometry the view is resampled almost exactly: 45 dB (an RMS error of
     * 0.56 % of full scale), and at least 6 dB better than the plane blend */
    CHECK(p_depth > 45);
    CHECK(p_depth > p_plane + 6);
    /* at a data view: that view, exactly */
    CHECK(lf_lightfield_view_depth(&lf, 1, 1, &vo, &view, &err) == 0);
    CHECK(psnr(view.data, lf_lightfield_view(&lf, 4, 4), 0) > 200);
    lf_image_free(&view);
    {
        /* ---- vignetted capture (decoded plenoptic sets): a known smooth gain
         * field on the outer ring of views, the corner views dark.
         * lf_lightfield_equalize must find the dark views, give the ring back its
         * brightness (the field, exp(quadratic), is in its model; parallax
         * moves texture across the cells, which its robust fit must not
         * follow), leave the inner views bit-identical, and the range
         * estimate and the depth must hold as on the clean views ---- */
        lf_lightfield vg = {0};
        CHECK(lf_lightfield_alloc(&vg, N, N, W, H, &err) == 0);
        vg.disp_v_per_u = 1.0;
        memcpy(vg.data, lf.data, sizeof(float) * 3 * N * N * W * H);
        static const double chg[3] = {0.5, 0.55, 0.45};
        for (int v = 0; v < N; v++)
            for (int u = 0; u < N; u++) {
                int ring = abs(u - N / 2) + abs(v - N / 2);
                float *p = lf_lightfield_view(&vg, u, v);
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++) {
                        double xx = (x + 0.5) / W * 2 - 1, yy = (y + 0.5) / H * 2 - 1;
                        for (int ch = 0; ch < 3; ch++) {
                            double g = ring >= 5 ? 0.02 : ring == 4 ? chg[ch] * exp(-0.4 * xx * xx + 0.2 * xx * yy) : 1;
                            p[((size_t)y * W + x) * 3 + ch] *= (float)g;
                        }
                    }
            }
        CHECK_MSG(lf_lightfield_equalize(&vg, &err) == 0, "%s", err.msg);
        int ndark = 0, dark_ok = 1, inner_same = 1, nring = 0;
        double ring_err = 0, ring_ref = 0;
        for (int v = 0; v < N; v++)
            for (int u = 0; u < N; u++) {
                int ring = abs(u - N / 2) + abs(v - N / 2);
                const float *a = lf_lightfield_view(&vg, u, v), *b = lf_lightfield_view(&lf, u, v);
                const float *va = vg.valid ? vg.valid + ((size_t)v * N + u) * W * H : NULL;
                if (ring >= 5) {
                    ndark++;
                    for (int i = 0; i < W * H; i++)
                        dark_ok &= va && va[i] == 0.f;
                } else if (ring == 4) {
                    nring++;
                    for (int i = 0; i < W * H * 3; i++)
                        ring_err += (double)(a[i] - b[i]) * (a[i] - b[i]), ring_ref += (double)b[i] * b[i];
                } else {
                    inner_same &= memcmp(a, b, sizeof(float) * 3 * W * H) == 0;
                    for (int i = 0; va && i < W * H; i++)
                        inner_same &= va[i] == 1.f;
                }
            }
        double rel = sqrt(ring_err / ring_ref);
        printf("vignetted views: %d dark left out (of %d), %d rescaled (of %d), gains %.3f .. %.3f, "
               "relative RMS error of the rescaled views %.4f\n",
               vg.views_dark, ndark, vg.views_rescaled, nring, vg.gain_lo, vg.gain_hi, rel);
        CHECK(vg.views_dark == ndark && dark_ok);
        CHECK(vg.views_rescaled == nring);
        CHECK(inner_same);
        /* the texture's contrast is about 50 %: a gain off by 1 % gives 1 % */
        CHECK(rel < 0.01);
        /* the ring's luminance gain is 0.5 exp(-0.4 x^2 + 0.2 x y) (the channels'
         * factors average 0.5): 0.5 e^-0.6 = 0.27 at two corners, 0.5 at x = 0;
         * a view's mean gain is 0.5 times the field's mean over the image */
        double fmean = 0;
        for (int j = 0; j < 200; j++)
            for (int i = 0; i < 200; i++) {
                double xx = (i + 0.5) / 100 - 1, yy = (j + 0.5) / 100 - 1;
                fmean += exp(-0.4 * xx * xx + 0.2 * xx * yy) / 40000;
            }
        CHECK(vg.gain_lo > 0.95 * 0.5 * exp(-0.6) && vg.gain_hi < 1.05 * 0.5);
        CHECK(vg.view_gain && fabs(vg.view_gain[0 * N + 2] - 0.5 * fmean) < 0.02 && vg.view_gain[3 * N + 3] == 1.f);
        double v0, v1;
        CHECK_MSG(lf_lightfield_depth_range(&vg, 2, &v0, &v1, &err) == 0, "%s", err.msg);
        printf("  range %.3f .. %.3f (clean views: %.3f .. %.3f)\n", v0, v1, r0, r1);
        CHECK(v0 <= gmin && v1 >= gmax);
        CHECK(v1 - v0 <= 3 * (gmax - gmin) + 1.0);
        lf_image dv;
        CHECK_MSG(lf_lightfield_depth(&vg, &o, &dv, NULL, &err) == 0, "%s", err.msg);
        scores sv = score(dv.data, gt, NULL);
        printf("  depth: BadPix0.07 %.2f %%, MSE x 100 %.4f (clean: %.2f %%, %.4f)\n", sv.bad07, sv.mse100, s.bad07,
               s.mse100);
        CHECK(sv.bad07 < 2.0);
        CHECK(sv.mse100 < 1.6);
        lf_image_free(&dv);
        lf_lightfield_free(&vg);
    }
    lf_lightfield_free(&lf);

    /* ---- 2. a box face occluding the plane ---- */
    g_box = 1;
    make_lf(&lf);
    ground_truth(gt);
    /* bands of 1..3 px on each side of the box outline in the centre view */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int in = gt[(size_t)y * W + x] > 1.4f, near = 0;
            for (int j = -3; j <= 3 && !near; j++)
                for (int i = -3; i <= 3; i++) {
                    int xx = x + i, yy = y + j;
                    if (xx < 0 || yy < 0 || xx >= W || yy >= H)
                        continue;
                    if ((gt[(size_t)yy * W + xx] > 1.4f) != in)
                        near = 1;
                }
            if (near)
                (in ? band_in : band_out)[(size_t)y * W + x] = 1;
        }
    scores so[2], sb[2], si[2];
    for (int occ = 0; occ < 2; occ++) {
        o = lf_lightfield_depth_defaults();
        o.occlusion = occ ? 2 : 0;
        CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
        so[occ] = score(d.data, gt, NULL);
        sb[occ] = score(d.data, gt, band_out);
        si[occ] = score(d.data, gt, band_in);
        printf("box, occlusion model %s: BadPix0.07 %.2f %%, MSE x 100 %.3f; background within 3 px of the outline: "
               "BadPix0.3 %.1f %%; box within 3 px: BadPix0.3 %.1f %%\n",
               occ ? "on " : "off", so[occ].bad07, so[occ].mse100, sb[occ].bad30, si[occ].bad30);
        if (occ) {
            /* view synthesis across the occlusion boundary */
            lf_image conf = {0};
            lf_image_free(&d);
            CHECK(lf_lightfield_depth(&lf, &o, &d, &conf, &err) == 0);
            vo = lf_lightfield_view_defaults();
            vo.disparity = &d, vo.confidence = &conf;
            render(2.5, 3.5, truth);
            CHECK(lf_lightfield_view_depth(&lf, -0.5, 0.5, &vo, &view, &err) == 0);
            p_depth = psnr(view.data, truth, 8);
            lf_image_free(&view);
            CHECK(lf_lightfield_view_at(&lf, -0.5, 0.5, 0.0, &view, &err) == 0);
            p_plane = psnr(view.data, truth, 8);
            lf_image_free(&view);
            CHECK(lf_lightfield_view_at(&lf, -0.5, 0.5, 1.0, &view, &err) == 0);
            double p_plane1 = psnr(view.data, truth, 8);
            lf_image_free(&view);
            printf("  view (-0.5, 0.5): per-pixel depth %.2f dB, plane d=0 %.2f dB, plane d=1 %.2f dB\n", p_depth,
                   p_plane, p_plane1);
            /* occlusion edges cost some accuracy against the plane-only scene:
             * 40 dB, and 5 dB better than either plane */
            CHECK(p_depth > 40);
            CHECK(p_depth > p_plane + 5 && p_depth > p_plane1 + 5);
            /* synth (CS348B virtual camera) with per-pixel geometry: a pinhole at
             * view position (2.5, 3.5) against its analytic render, with the
             * estimated map; the focal-plane geometry (plane at the
             * background's centre depth Z0) for comparison */
            lf_lightfield_synth_opts so_ = lf_lightfield_synth_defaults();
            so_.width = W, so_.height = H, so_.fov_deg = lf.layout.fov_deg, so_.spp = 4, so_.seed = 5;
            so_.pos[0] = (2.5 - (N - 1) / 2.0) * B, so_.pos[1] = -(3.5 - (N - 1) / 2.0) * B;
            so_.focal_distance = Z0;
            lf_image sy;
            CHECK(lf_lightfield_synth(&lf, &so_, &sy, NULL, NULL, &err) == 0);
            double p_syn_plane = psnr(sy.data, truth, 8);
            lf_image_free(&sy);
            so_.disparity = &d;
            CHECK_MSG(lf_lightfield_synth(&lf, &so_, &sy, NULL, NULL, &err) == 0, "%s", err.msg);
            double p_syn_depth = psnr(sy.data, truth, 8);
            lf_image_free(&sy);
            printf("  synth at (2.5, 3.5): per-pixel depth %.2f dB, focal plane at Z0 %.2f dB\n", p_syn_depth,
                   p_syn_plane);
            /* synth looks the cameras up bilinearly (lf_lightfield_view_depth bicubically),
             * so it stays below the view synthesis: 39 dB, and better than the
             * best single focal plane */
            CHECK(p_syn_depth > 39);
            CHECK(p_syn_depth > p_syn_plane + 1);
            /* a disparity map of the wrong size is refused */
            lf_image small;
            lf_image_alloc(&small, W / 2, H / 2, 1, &err);
            vo.disparity = &small, vo.confidence = NULL;
            CHECK(lf_lightfield_view_depth(&lf, -0.5, 0.5, &vo, &view, &err) == LF_ERR_PARAM);
            lf_image_free(&small), lf_image_free(&conf);
        }
        lf_image_free(&d);
    }
    /* with the occlusion model: the whole map near the benchmark goal, and at
     * most 10 % of the background next to the box taken for the box
     * (fattening); without it the band is worse by at least 2 points */
    CHECK(so[1].bad07 < 6.0);
    CHECK(so[1].mse100 < 4.0);
    CHECK(sb[1].bad30 < 10.0);
    CHECK(si[1].bad30 < 10.0);
    CHECK(sb[0].bad30 > sb[1].bad30 + 2.0);
    {
        /* disocclusions: from view position (5.5, 5.5), 2.5 view steps from
         * the reference in each axis, the background beside the box's edges
         * that the reference view does not see (a band up to 1.6 px wide
         * and the box's width long), with the ground-truth map.  Each
         * target pixel centre is traced; a background hit that the box
         * hides from the centre camera is in the band.  The hole's
         * disparity comes from the background around it, so the band must
         * come out nearly as well as the rest of the background (it once
         * faded to the plane blend along the band) */
        lf_image gtm;
        CHECK(lf_image_alloc(&gtm, W, H, 1, &err) == 0);
        memcpy(gtm.data, gt, sizeof(float) * W * H);
        vo = lf_lightfield_view_defaults();
        vo.disparity = &gtm;
        render(5.5, 5.5, truth);
        CHECK(lf_lightfield_view_depth(&lf, 2.5, 2.5, &vo, &view, &err) == 0);
        lf_image pl;
        CHECK(lf_lightfield_view_at(&lf, 2.5, 2.5, 1.0, &pl, &err) == 0);
        double cx = 2.5 * B, cy = -2.5 * B, se[2] = {0, 0}, sp = 0;
        size_t nb[2] = {0, 0};
        for (int y = 8; y < H - 8; y++)
            for (int x = 8; x < W - 8; x++) {
                double dx = (x + 0.5 - W / 2.0) / F, dy = -(y + 0.5 - H / 2.0) / F;
                double t = trace(cx, cy, dx, dy, NULL);
                if (t == ZB)
                    continue;
                double X = cx + t * dx, Y = cy + t * dy;
                int hidden = trace(0, 0, X / t, Y / t, NULL) == ZB;
                /* only pixels wholly on the background (mixed outline pixels are the two-layer step's) */
                int mixed = 0;
                for (int j = 0; j < SS; j++)
                    for (int i = 0; i < SS; i++)
                        mixed |= trace(cx, cy, (x + (i + 0.5) / SS - W / 2.0) / F, -(y + (j + 0.5) / SS - H / 2.0) / F,
                                       NULL) == ZB;
                if (mixed)
                    continue;
                for (int k = 0; k < 3; k++) {
                    size_t q = ((size_t)y * W + x) * 3 + k;
                    double e = view.data[q] - truth[q], ep = pl.data[q] - truth[q];
                    se[hidden] += e * e, nb[hidden]++;
                    sp += hidden ? ep * ep : 0;
                }
            }
        double p_hole = 10 * log10(nb[1] / se[1]), p_bg = 10 * log10(nb[0] / se[0]), p_pl = 10 * log10(nb[1] / sp);
        printf("  disocclusion at (2.5, 2.5), ground-truth map: background hidden from the reference %.2f dB "
               "(%zu px; the plane blend at the background's d = 1: %.2f dB), the rest of the background %.2f dB\n",
               p_hole, nb[1] / 3, p_pl, p_bg);
        CHECK(nb[1] / 3 >= 20);
        CHECK(p_hole > p_pl + 5);
        lf_image_free(&view), lf_image_free(&gtm), lf_image_free(&pl);
    }
    lf_lightfield_free(&lf);

    /* ---- 3. thin structures ----
     * The wedge (4 px down to nothing) and the 1-px rod of trace() in front
     * of the tilted plane (disparity 1.6 against 0.77 .. 1.15 px/view).
     * The structures carry the background's texture darkened by 30 %: to
     * the colour guide a faint line.  The aggregation's windows (radius 4,
     * as for views 512 px wide) are wider than a structure and hand most of
     * its pixels to the background.  The thin-structure step must bring back
     * most of the pixels whose centre lies on a structure (recall: within
     * 0.3 px/view of the truth): at least 65 %, 40 points more than without
     * it.  It may grow the structures a little: a pixel less than half
     * covered mixes structure and background, and against a faint texture
     * it is about as consistent with either; at most 10 % of the background
     * pixels next to a structure may be taken for it (fattening), and the
     * map as a whole must improve (BadPix0.07). */
    {
        g_box = 2;
        make_lf(&lf);
        ground_truth(gt);
        double rec[2], fat[2], bad[2];
        for (int on = 0; on < 2; on++) {
            o = lf_lightfield_depth_defaults();
            o.thin = on ? 0 : -1;
            o.radius = 4; /* the window of views 512 px wide (the default is a 128th of the side) */
            CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
            size_t ns_ = 0, ok = 0, nb_ = 0, nf = 0;
            for (int y = 8; y < H - 8; y++)
                for (int x = 8; x < W - 8; x++) {
                    size_t i = (size_t)y * W + x;
                    int fg = gt[i] > 1.4f, next = 0;
                    for (int j = -1; j <= 1; j++)
                        for (int k = -1; k <= 1; k++)
                            next |= gt[(size_t)(y + j) * W + x + k] > 1.4f;
                    if (fg)
                        ns_++, ok += fabsf(d.data[i] - gt[i]) < 0.3f;
                    else if (next)
                        nb_++, nf += fabsf(d.data[i] - gt[i]) > 0.3f;
                }
            rec[on] = 100.0 * ok / (ns_ ? ns_ : 1), fat[on] = 100.0 * nf / (nb_ ? nb_ : 1);
            bad[on] = score(d.data, gt, NULL).bad07;
            printf("thin structures, thin step %s: %zu structure pixels, recall %.1f %%; %zu background pixels next "
                   "to them, fattening %.1f %%; BadPix0.07 %.2f %%\n",
                   on ? "on " : "off", ns_, rec[on], nb_, fat[on], bad[on]);
            lf_image_free(&d);
        }
        CHECK(rec[1] >= 65);
        CHECK(rec[1] >= rec[0] + 40);
        CHECK(fat[1] <= 10);
        CHECK(bad[1] < bad[0]);
        lf_lightfield_free(&lf);
    }

    /* ---- 4. resampling phase ----
     * A fronto-parallel plane at d = 2/3 px/view with a texture of detail up
     * to 0.42 cycles/px: view (iu, iv) is T(x + d du, y + d dv), du, dv the
     * offsets from the centre view.  At (0.5, 0.5) the 4 nearest views sit
     * 1/3 px off the target's pixel grid (interpolated), the next ring at
     * 1.5 views lands exactly on it (shift 1 px).
     * Bicubic blend (blend = 1): phase weighting leans on the exact samples:
     * with the tent of radius 2 and floor 0.05 the weights of the 16 views
     * are, per view, 4 x 0.56/(4/9+0.05) (both axes off the grid),
     * 8 x 0.19/(2/9+0.05) (one axis) and 4 x 0.06/0.05 (none), so at most
     * half of the weight carries an interpolation error (6 dB): asserted with
     * half that margin against the 4 nearest views without phase weights.
     * Scattered-data fit (default): the views within 3 steps put samples at
     * offsets 0, 1/3 and 2/3 px in both axes around every target pixel,
     * three times the grid's sampling rate, so the texture (below the
     * single grid's Nyquist limit but not below the fit's) is reconstructed
     * from exact samples at the centre: asserted 3 dB above the blend. */
    {
        enum { N4 = 7 };
        const double d4 = 2.0 / 3.0;
        lf_lightfield pl = {0};
        CHECK(lf_lightfield_alloc(&pl, N4, N4, W, H, &err) == 0);
        pl.disp_v_per_u = 1.0;
        for (int iv = 0; iv < N4; iv++)
            for (int iu = 0; iu < N4; iu++) {
                float *v = lf_lightfield_view(&pl, iu, iv);
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++)
                        for (int ch = 0; ch < 3; ch++)
                            v[((size_t)y * W + x) * 3 + ch] =
                                (float)bl_tex(x + d4 * (iu - N4 / 2), y + d4 * (iv - N4 / 2), ch);
            }
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                for (int ch = 0; ch < 3; ch++)
                    truth[((size_t)y * W + x) * 3 + ch] = (float)bl_tex(x + d4 * 0.5, y + d4 * 0.5, ch);
        lf_image dm;
        CHECK(lf_image_alloc(&dm, W, H, 1, &err) == 0);
        for (int i = 0; i < W * H; i++)
            dm.data[i] = (float)d4;
        lf_lightfield_view_opts po = lf_lightfield_view_defaults();
        po.disparity = &dm;
        CHECK(lf_lightfield_view_depth(&pl, 0.5, 0.5, &po, &view, &err) == 0);
        double p_fit = psnr(view.data, truth, 8);
        lf_image_free(&view);
        po.blend = 1;
        CHECK(lf_lightfield_view_depth(&pl, 0.5, 0.5, &po, &view, &err) == 0);
        double p_phase = psnr(view.data, truth, 8);
        lf_image_free(&view);
        po.radius = 1, po.phase_floor = 0;
        CHECK(lf_lightfield_view_depth(&pl, 0.5, 0.5, &po, &view, &err) == 0);
        double p_near4 = psnr(view.data, truth, 8);
        lf_image_free(&view);
        printf("resampling phase, plane d = 2/3, view (0.5, 0.5): scattered-data fit %.2f dB; blend: 16 views "
               "phase-weighted %.2f dB, 4 nearest %.2f dB\n",
               p_fit, p_phase, p_near4);
        CHECK(p_phase > p_near4 + 3);
        CHECK(p_fit > p_phase + 3);
        /* The fit must not buy its resolution with noise: the same views
         * with Gaussian noise of standard deviation 0.01 (one noisy view on
         * its own: 40 dB; fixed seed), where each method's error is its
         * interpolation error plus the noise it passes on (the blend
         * averages 16 lookups; the fit a quadratic over the samples of
         * 36 views): the fit stays at least 3 dB ahead. */
        {
            unsigned long long st = 7;
            for (size_t q = 0; q < (size_t)N4 * N4 * W * H * 3; q++) {
                double a = 0;
                for (int r = 0; r < 12; r++) { /* Irwin-Hall: sum of 12 uniforms - 6 ~ N(0, 1) */
                    st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                    a += (double)(st >> 11) / 9007199254740992.0;
                }
                pl.data[q] += (float)(0.01 * (a - 6));
            }
            po = lf_lightfield_view_defaults();
            po.disparity = &dm;
            CHECK(lf_lightfield_view_depth(&pl, 0.5, 0.5, &po, &view, &err) == 0);
            double n_fit = psnr(view.data, truth, 8);
            lf_image_free(&view);
            po.blend = 1;
            CHECK(lf_lightfield_view_depth(&pl, 0.5, 0.5, &po, &view, &err) == 0);
            double n_phase = psnr(view.data, truth, 8);
            lf_image_free(&view);
            printf("  with noise 0.01: scattered-data fit %.2f dB, blend %.2f dB\n", n_fit, n_phase);
            CHECK(n_fit > n_phase + 3);
        }
        lf_image_free(&dm);
        lf_lightfield_free(&pl);
    }

    /* ---- 5. self-calibration of view positions ----
     * The tilted plane seen by cameras off their grid: view (iu, iv) at
     * (iu + eu, iv + ev), |eu|, |ev| <= 0.25 view steps, and its pixel grid
     * offset by (ox, oy), |ox|, |oy| <= 0.4 px (the centre view exact).  In
     * the model I_ref(x, y) = I_k(x - d su + ox, y - d sv + oy) the truth is
     * su = iu - 3 + eu, sv = iv - 3 + ev and the offsets as rendered.
     * Calibrating from the nominal grid's depth, then once more from the
     * calibrated depth, must recover them where it matters: the shift each
     * view's model predicts over the scene's disparities (0.77 .. 1.15; over
     * so small a spread baseline and offset trade off) within 0.15 px (tile
     * shifts scatter by ~0.03 px, depth-map errors of 0.01..0.03 px/view
     * times baselines up to 3.25 add as much) and at most a third of the
     * uncalibrated error; the depth and a new view must come back to the
     * quality of the regular grid (section 1: BadPix0.07 < 2 %, > 45 dB)
     * and the view gain at least 3 dB over the nominal grid. */
    {
        g_box = 0;
        lf_lightfield pl = {0};
        make_lf(&pl);
        double te[N * N][4];
        for (int iv = 0; iv < N; iv++)
            for (int iu = 0; iu < N; iu++) {
                int k = iv * N + iu, ctr = iu == N / 2 && iv == N / 2;
                te[k][0] = ctr ? 0 : 0.5 * (hash2(iu, 40 + iv) - 0.5);
                te[k][1] = ctr ? 0 : 0.5 * (hash2(iu, 60 + iv) - 0.5);
                te[k][2] = ctr ? 0 : 0.8 * (hash2(iu, 80 + iv) - 0.5);
                te[k][3] = ctr ? 0 : 0.8 * (hash2(iu, 90 + iv) - 0.5);
                g_ox = te[k][2], g_oy = te[k][3];
                render(iu + te[k][0], iv + te[k][1], lf_lightfield_view(&pl, iu, iv));
            }
        g_ox = g_oy = 0;
        ground_truth(gt);
        lf_lightfield_depth_opts co = lf_lightfield_depth_defaults();
        lf_image d0, c0;
        CHECK_MSG(lf_lightfield_depth(&pl, &co, &d0, &c0, &err) == 0, "%s", err.msg);
        scores s_nom = score(d0.data, gt, NULL);
        double rep[N * N * 6];
        CHECK_MSG(lf_lightfield_calibrate_views(&pl, &d0, &c0, 2, rep, &err) == 0, "%s", err.msg);
        lf_image_free(&d0), lf_image_free(&c0);
        CHECK_MSG(lf_lightfield_depth(&pl, &co, &d0, &c0, &err) == 0, "%s", err.msg);
        CHECK_MSG(lf_lightfield_calibrate_views(&pl, &d0, &c0, 2, rep, &err) == 0, "%s", err.msg);
        /* the error that matters: of the predicted shift -d su + o over the
         * scene's disparities (baseline and offset trade off against each
         * other the less the disparities spread) */
        double gmin5 = 1e9, gmax5 = -1e9, worst_shift = 0, worst_nominal = 0;
        for (int i = 0; i < W * H; i++)
            gmin5 = gt[i] < gmin5 ? gt[i] : gmin5, gmax5 = gt[i] > gmax5 ? gt[i] : gmax5;
        int fitted = 0;
        for (int k = 0; k < N * N; k++) {
            double esu = rep[6 * k] - (k % N - N / 2 + te[k][0]), esv = rep[6 * k + 1] - (k / N - N / 2 + te[k][1]);
            double eox = rep[6 * k + 2] - te[k][2], eoy = rep[6 * k + 3] - te[k][3];
            fitted += rep[6 * k + 4] >= 8;
            for (int e = 0; e < 2; e++) {
                double dd = e ? gmax5 : gmin5, ex = -dd * esu + eox, ey = -dd * esv + eoy;
                double m = sqrt(ex * ex + ey * ey);
                worst_shift = m > worst_shift || !isfinite(m) ? m : worst_shift;
                double nx = dd * te[k][0] - te[k][2], ny = dd * te[k][1] - te[k][3];
                worst_nominal = fmax(worst_nominal, sqrt(nx * nx + ny * ny));
            }
            if (getenv("LFT_VERBOSE"))
                printf("  view %d,%d: su %+.4f sv %+.4f ox %+.4f oy %+.4f  tiles %.0f rms %.4f\n", k % N, k / N, esu,
                       esv, eox, eoy, rep[6 * k + 4], rep[6 * k + 5]);
        }
        lf_image_free(&d0), lf_image_free(&c0);
        CHECK_MSG(lf_lightfield_depth(&pl, &co, &d0, &c0, &err) == 0, "%s", err.msg);
        scores s_cal = score(d0.data, gt, NULL);
        printf("perturbed views: %d of %d fitted, predicted shift error at most %.4f px over d %.2f .. %.2f "
               "(nominal grid %.4f px); depth BadPix0.07 %.2f %% (nominal grid %.2f %%), MSE x 100 %.4f (%.4f)\n",
               fitted, N * N - 1, worst_shift, gmin5, gmax5, worst_nominal, s_cal.bad07, s_nom.bad07, s_cal.mse100,
               s_nom.mse100);
        CHECK(fitted == N * N - 1);
        CHECK(worst_shift < 0.15);
        CHECK(worst_shift < worst_nominal / 3);
        CHECK(s_cal.bad07 < 2.0);
        CHECK(s_cal.mse100 < 1.6);
        /* a view between the calibrated cameras: at the position interpolated
         * between its 4 neighbours (lf_lightfield_view_shift) */
        double st[4] = {0, 0, 0, 0};
        for (int k = 0; k < 4; k++) {
            int iu = 3 + (k & 1), iv = 1 + (k >> 1);
            for (int i = 0; i < 4; i++)
                st[i] += 0.25 * te[iv * N + iu][i];
        }
        g_ox = st[2], g_oy = st[3];
        render(3.5 + st[0], 1.5 + st[1], truth);
        g_ox = g_oy = 0;
        lf_lightfield_view_opts cvo = lf_lightfield_view_defaults();
        cvo.disparity = &d0, cvo.confidence = &c0;
        CHECK(lf_lightfield_view_depth(&pl, 0.5, -1.5, &cvo, &view, &err) == 0);
        double p_cal = psnr(view.data, truth, 8);
        lf_image_free(&view);
        double *keep = pl.view_shift;
        pl.view_shift = NULL;
        CHECK(lf_lightfield_view_depth(&pl, 0.5, -1.5, &cvo, &view, &err) == 0);
        double p_nom = psnr(view.data, truth, 8);
        lf_image_free(&view);
        pl.view_shift = keep;
        printf("  view (0.5, -1.5): calibrated %.2f dB, nominal grid %.2f dB\n", p_cal, p_nom);
        CHECK(p_cal > 45);
        CHECK(p_cal > p_nom + 3);
        /* bad input */
        lf_image small;
        lf_image_alloc(&small, W / 2, H / 2, 1, &err);
        CHECK(lf_lightfield_calibrate_views(&pl, &small, NULL, 2, NULL, &err) == LF_ERR_PARAM);
        lf_image_free(&small);
        lf_image_free(&d0), lf_image_free(&c0);
        lf_lightfield_free(&pl);
    }

    /* ---- 3. bad input ---- */
    lf_lightfield one = {0};
    lf_lightfield_alloc(&one, 1, 1, 16, 16, &err);
    CHECK(lf_lightfield_depth(&one, NULL, &d, NULL, &err) == LF_ERR_PARAM);
    lf_lightfield_free(&one);

    free(gt), free(band_out), free(band_in), free(truth);
    return lf_test_end();
}
