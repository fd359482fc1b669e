/* Shift-and-add and Fourier slice refocusing, view interpolation: on a camera
 * array looking at a fronto-parallel textured plane, built analytically here
 * (view (i,j) of the plane at depth Z is the texture seen from camera (i,j);
 * its disparity is F_px * b / Z), so expected values do not depend on the
 * code under test. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"

enum { N = 9, W = 64, H = 64 };
static const double FOV = 40, Z = 2, B = 0.05; /* degrees, metres, baseline */

/* smooth colour texture on the plane (world metres) */
static void texture(double X, double Y, float c[3])
{
    double a = sin(2 * M_PI * (3.1 * X + 1.3 * Y)), b = sin(2 * M_PI * (-1.7 * X + 2.9 * Y) + 0.7);
    double e = cos(2 * M_PI * (2.3 * X - 0.9 * Y) + 0.3);
    c[0] = (float)(0.5 + 0.2 * a + 0.1 * b);
    c[1] = (float)(0.5 + 0.15 * b + 0.1 * e);
    c[2] = (float)(0.5 + 0.2 * e - 0.05 * a);
}

static double fpx(void) { return 0.5 * W / tan(FOV * M_PI / 360); }

/* pinhole view from camera-plane point (cx, cy) looking along +z */
static void render_view(double cx, double cy, float *dst)
{
    double t = tan(FOV * M_PI / 360), half = 0.5 * W;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dx = (x + 0.5 - W / 2.0) / half * t, dy = -(y + 0.5 - H / 2.0) / half * t;
            texture(cx + dx * Z, cy + dy * Z, dst + ((size_t)y * W + x) * 3);
        }
}

static void make_lf(lf_lightfield *lf)
{
    lf_error err = {0};
    lf_lightfield_alloc(lf, N, N, W, H, &err);
    double minx = -B * (N - 1) / 2, maxy = B * (N - 1) / 2;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            render_view(minx + i * B, maxy - j * B, lf_lightfield_view(lf, i, j));
    lf_lightfield_layout *l = &lf->layout;
    l->kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    l->cams_x = l->cams_y = N;
    l->grid_bounds[0] = minx, l->grid_bounds[1] = -minx, l->grid_bounds[2] = -maxy, l->grid_bounds[3] = maxy;
    l->fov_deg = FOV, l->tile_w = W, l->tile_h = H;
    l->have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_BOUNDS | LF_LIGHTFIELD_HAVE_FOV | LF_LIGHTFIELD_HAVE_TILE;
    lf->disp_per_inv_m = fpx() * B;
    lf->disp_v_per_u = 1;
}

/* PSNR over the interior [m, W-m) x [m, H-m) */
static double psnr_interior(const lf_image *a, const float *b, int m)
{
    double se = 0;
    size_t n = 0;
    for (int y = m; y < H - m; y++)
        for (int x = m; x < W - m; x++)
            for (int c = 0; c < 3; c++) {
                double d = lf_image_px(a, x, y)[c] - b[((size_t)y * W + x) * 3 + c];
                se += d * d, n++;
            }
    return se == 0 ? INFINITY : 10 * log10(1.0 / (se / n));
}

int main(void)
{
    lf_lightfield lf;
    make_lf(&lf);
    lf_error err = {0};
    const double d_plane = fpx() * B / Z; /* 2.197 px per view step */
    const int margin = (int)ceil(d_plane * (N - 1) / 2) + 2;
    float *centre = lf_lightfield_view(&lf, N / 2, N / 2);

    /* depth -> disparity uses F_px b / Z */
    double d = 0;
    CHECK(lf_lightfield_depth_to_disparity(&lf, Z, &d, &err) == 0);
    CHECK_NEAR(d, d_plane, 1e-9);
    CHECK(lf_lightfield_alpha_to_disparity(&lf, 1.0, &d, &err) != 0); /* no main lens: alpha refused */
    CHECK(strstr(err.msg, "alpha") != NULL);
    lf_error_clear(&err);

    /* refocus at the plane's disparity reproduces the sharp texture */
    lf_lightfield_refocus_opts o = lf_lightfield_refocus_defaults();
    o.disparity_px = d_plane;
    lf_image img;
    CHECK_MSG(lf_lightfield_refocus(&lf, &o, &img, &err) == 0, "%s", err.msg);
    double p_focus = psnr_interior(&img, centre, margin);
    printf("refocus at plane disparity %.3f px: PSNR %.2f dB vs the sharp centre view (threshold 40)\n", d_plane,
           p_focus);
    CHECK(p_focus > 40);
    lf_image_free(&img);

    /* refocus elsewhere is blurred: at least 10 dB worse */
    o.disparity_px = 0;
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == 0);
    double p_off = psnr_interior(&img, centre, margin);
    printf("refocus at disparity 0: PSNR %.2f dB (must be 10 dB below)\n", p_off);
    CHECK(p_off < p_focus - 10);
    /* d = 0 (alpha = 1) is the plain average of all views */
    double maxdiff = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                double s = 0;
                for (int v = 0; v < N * N; v++)
                    s += lf.data[(size_t)v * W * H * 3 + ((size_t)y * W + x) * 3 + c];
                double e = fabs(s / (N * N) - lf_image_px(&img, x, y)[c]);
                if (e > maxdiff)
                    maxdiff = e;
            }
    printf("disparity 0 vs plain mean of views: max |diff| %.2g (tol 1e-6)\n", maxdiff);
    CHECK(maxdiff < 1e-6);
    lf_image_free(&img);

    /* thread count does not change the result */
    lf_image one, two;
    o.disparity_px = 1.37;
    o.threads = 1;
    CHECK(lf_lightfield_refocus(&lf, &o, &one, &err) == 0);
    o.threads = 2;
    CHECK(lf_lightfield_refocus(&lf, &o, &two, &err) == 0);
    CHECK(memcmp(one.data, two.data, sizeof(float) * W * H * 3) == 0);
    lf_image_free(&one);

    /* half-float storage: the same refocus within half precision (2^-11 relative) */
    CHECK(lf_lightfield_make_half(&lf, &err) == 0);
    o.use_half = 1;
    CHECK(lf_lightfield_refocus(&lf, &o, &one, &err) == 0);
    double hmax = 0;
    for (size_t i = 0; i < (size_t)W * H * 3; i++)
        hmax = fmax(hmax, fabs(one.data[i] - two.data[i]));
    printf("half-float refocus vs float: max |diff| %.2g (tol 5e-4)\n", hmax);
    CHECK(hmax < 5e-4 && hmax > 0);
    lf_image_free(&one);
    o.use_half = 0;

    /* synthetic aperture: radius 0 selects the centre view only; a window selects one view */
    o = lf_lightfield_refocus_defaults();
    o.disparity_px = d_plane;
    o.aperture_radius = 0;
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == 0);
    CHECK(memcmp(img.data, centre, sizeof(float) * W * H * 3) == 0);
    lf_image_free(&img);
    o.aperture_radius = -1;
    o.disparity_px = 0;
    o.u0 = o.u1 = 2, o.v0 = o.v1 = 5;
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == 0);
    CHECK(memcmp(img.data, lf_lightfield_view(&lf, 2, 5), sizeof(float) * W * H * 3) == 0);
    lf_image_free(&img);
    o.u0 = 20, o.u1 = 30;
    CHECK(lf_lightfield_refocus(&lf, &o, &img, &err) == LF_ERR_PARAM); /* empty aperture */
    lf_error_clear(&err);

    /* view interpolation: at a view position it is that view, exactly */
    CHECK(lf_lightfield_view_at(&lf, -2, 1, 0, &img, &err) == 0);
    CHECK(memcmp(img.data, lf_lightfield_view(&lf, 2, 5), sizeof(float) * W * H * 3) == 0);
    lf_image_free(&img);
    /* between views, reprojected at the plane's disparity: the analytic view from there */
    float *truth = malloc(sizeof(float) * W * H * 3);
    render_view(0.35 * B, -0.6 * B, truth); /* u = 0.35, v = +0.6 (down) */
    CHECK(lf_lightfield_view_at(&lf, 0.35, 0.6, d_plane, &img, &err) == 0);
    double p_view = psnr_interior(&img, truth, 4);
    printf("view at (0.35, 0.6): PSNR %.2f dB vs analytic view (threshold 40)\n", p_view);
    CHECK(p_view > 40);
    lf_image_free(&img);
    CHECK(lf_lightfield_view_at(&lf, 4.5, 0, 0, &img, &err) == LF_ERR_PARAM); /* outside the aperture */
    CHECK(strstr(err.msg, "outside") != NULL);
    lf_error_clear(&err);

    /* Fourier slice agrees with shift-and-add away from the border */
    lf_lightfield_fourier *fs = NULL;
    CHECK_MSG(lf_lightfield_fourier_new(&lf, NULL, 2.0, &fs, &err) == 0, "%s", err.msg);
    const double ds[3] = {d_plane, 0.0, -1.3};
    for (int k = 0; k < 3 && fs; k++) {
        o = lf_lightfield_refocus_defaults();
        o.disparity_px = ds[k];
        lf_image a, b;
        CHECK(lf_lightfield_refocus(&lf, &o, &a, &err) == 0);
        CHECK_MSG(lf_lightfield_fourier_refocus(fs, ds[k], &b, &err) == 0, "%s", err.msg);
        int m = (int)ceil(fabs(ds[k]) * (N - 1) / 2) + 2;
        double p = psnr_interior(&b, a.data, m);
        printf("Fourier slice vs shift-and-add at d = %.3f: PSNR %.2f dB over [%d, %d) (threshold 35)\n", ds[k], p, m,
               W - m);
        CHECK(p > 35);
        lf_image_free(&a), lf_image_free(&b);
    }
    lf_lightfield_fourier_release(fs);

    /* all-in-focus and disparity from a stack: the plane's disparity is found */
    lf_image af, dm;
    o = lf_lightfield_refocus_defaults();
    CHECK(lf_lightfield_allfocus(&lf, &o, 0, 4, 21, &af, &dm, &err) == 0);
    double dsum = 0;
    int dn = 0;
    for (int y = margin; y < H - margin; y++)
        for (int x = margin; x < W - margin; x++)
            dsum += dm.data[(size_t)y * W + x], dn++;
    printf("depth from focus: mean disparity %.3f (plane %.3f, step 0.2)\n", dsum / dn, d_plane);
    CHECK_NEAR(dsum / dn, d_plane, 0.3);
    lf_image_free(&af), lf_image_free(&dm);

    free(truth);
    lf_image_free(&two);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
