/* CS348B light-field synthesis on an analytic camera array (fronto-parallel
 * plane at depth Z): a pinhole at a data camera reproduces its tile, between
 * cameras the analytic view from there, and a lens radius blurs by the
 * thin-lens circle of confusion. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"

static const double FOV = 40;
static int g_edge; /* texture: 0 smooth colour, 1 slanted step edge X = 0.05 + Y/32 */
#define EDGE_X(Y) (0.05 + (Y) / 32.0)

static void texture(double X, double Y, float c[3])
{
    if (g_edge) {
        c[0] = c[1] = c[2] = X > EDGE_X(Y) ? 1.f : 0.f;
        return;
    }
    double a = sin(2 * M_PI * (3.1 * X + 1.3 * Y)), b = sin(2 * M_PI * (-1.7 * X + 2.9 * Y) + 0.7);
    c[0] = (float)(0.5 + 0.2 * a + 0.1 * b);
    c[1] = (float)(0.5 + 0.15 * b);
    c[2] = (float)(0.5 - 0.1 * a);
}

static void render_view(double cx, double cy, double Z, int w, int h, float *dst)
{
    double t = tan(FOV * M_PI / 360), half = 0.5 * (w < h ? w : h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double dx = (x + 0.5 - w / 2.0) / half * t, dy = -(y + 0.5 - h / 2.0) / half * t;
            texture(cx + dx * Z, cy + dy * Z, dst + ((size_t)y * w + x) * 3);
        }
}

static void make_lf(lf_lightfield *lf, int n, double b, double Z, int w, int h)
{
    lf_error err = {0};
    lf_lightfield_alloc(lf, n, n, w, h, &err);
    double minx = -b * (n - 1) / 2, maxy = b * (n - 1) / 2;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            render_view(minx + i * b, maxy - j * b, Z, w, h, lf_lightfield_view(lf, i, j));
    lf_lightfield_layout *l = &lf->layout;
    l->kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    l->cams_x = l->cams_y = n;
    l->grid_bounds[0] = minx, l->grid_bounds[1] = -minx, l->grid_bounds[2] = -maxy, l->grid_bounds[3] = maxy;
    l->fov_deg = FOV, l->tile_w = w, l->tile_h = h;
    l->have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_BOUNDS | LF_LIGHTFIELD_HAVE_FOV | LF_LIGHTFIELD_HAVE_TILE;
}


/* analytic thin-lens render of the step edge at depth zs (camera at the
 * origin, fov FOV across the shorter side): the estimator's reference */
static void thin_lens_edge(lf_image *img, double r, double fd, double zs, int spp)
{
    int w = img->width, h = img->height;
    double t = tan(FOV * M_PI / 360), half = 0.5 * (w < h ? w : h);
    unsigned s = 12345;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc = 0;
            for (int k = 0; k < spp; k++) {
                double u[4];
                for (int q = 0; q < 4; q++) {
                    s = s * 1664525u + 1013904223u;
                    u[q] = (s >> 8) / 16777216.0;
                }
                double dx = (x + u[0] - w / 2.0) / half * t, dy = -(y + u[1] - h / 2.0) / half * t;
                double rr = r * sqrt(u[2]), ph = 2 * M_PI * u[3];
                double lx = rr * cos(ph), ly = rr * sin(ph);
                double X = lx + (dx * fd - lx) * zs / fd; /* ray lens -> focal point, at zs */
                double Y = ly + (dy * fd - ly) * zs / fd;
                acc += X > EDGE_X(Y) ? 1 : 0;
            }
            float *p = lf_image_px(img, x, y);
            p[0] = p[1] = p[2] = (float)(acc / spp);
        }
}

/* Second moment (px^2) of the line spread along x: per row (its own
 * centroid), averaged over rows.  The edge slants by 1/32 px per row, so
 * over 64 rows its phase against the pixel grid is uniform and pixel
 * binning adds exactly 1/12 px^2 (Sheppard). */
static double edge_sigma(const lf_image *img)
{
    int w = img->width;
    double acc = 0;
    for (int y = 0; y < img->height; y++) {
        double s0 = 0, s1 = 0, s2 = 0;
        for (int x = 1; x < w; x++) {
            double l = lf_image_px(img, x, y)[1] - lf_image_px(img, x - 1, y)[1], xc = x;
            s0 += l, s1 += l * xc, s2 += l * xc * xc;
        }
        double mu = s1 / s0;
        acc += s2 / s0 - mu * mu;
    }
    return sqrt(acc / img->height);
}

int main(void)
{
    lf_error err = {0};
    /* 5 x 5 cameras 5 cm apart, 64 x 48 tiles, plane at 2 m */
    const int n = 5, w = 64, h = 48;
    const double b = 0.05, Z = 2;
    lf_lightfield lf;
    g_edge = 0;
    make_lf(&lf, n, b, Z, w, h);

    /* a pinhole at a data camera's position and orientation reproduces its tile */
    const int cams[3][2] = {{2, 2}, {0, 0}, {4, 1}};
    for (int k = 0; k < 3; k++) {
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = w, o.height = h, o.fov_deg = FOV;
        o.pos[0] = -b * (n - 1) / 2 + cams[k][0] * b;
        o.pos[1] = b * (n - 1) / 2 - cams[k][1] * b;
        o.focal_distance = Z;
        lf_image img, cov;
        size_t unc = 99;
        CHECK_MSG(lf_lightfield_synth(&lf, &o, &img, &cov, &unc, &err) == 0, "%s", err.msg);
        const float *tile = lf_lightfield_view(&lf, cams[k][0], cams[k][1]);
        double maxd = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            maxd = fmax(maxd, fabs(img.data[i] - tile[i]));
        printf("synth at camera (%d,%d): max |diff| vs its tile %.2g (tol 1e-5), uncovered %zu\n", cams[k][0],
               cams[k][1], maxd, unc);
        CHECK(maxd < 1e-5);
        CHECK(unc == 0);
        lf_image_free(&img), lf_image_free(&cov);
    }

    /* ... also at 16 samples per pixel: the views are pixel-integrated already,
     * so a pinhole whose pixels match the data pixels samples pixel centres
     * instead of integrating (blurring) a second time: > 60 dB */
    for (int k = 0; k < 2; k++) {
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = w, o.height = h, o.fov_deg = FOV, o.spp = 16, o.seed = 7;
        o.pos[0] = -b * (n - 1) / 2 + cams[k][0] * b;
        o.pos[1] = b * (n - 1) / 2 - cams[k][1] * b;
        lf_image img;
        CHECK_MSG(lf_lightfield_synth(&lf, &o, &img, NULL, NULL, &err) == 0, "%s", err.msg);
        const float *tile = lf_lightfield_view(&lf, cams[k][0], cams[k][1]);
        double se = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            se += (img.data[i] - tile[i]) * (double)(img.data[i] - tile[i]);
        double psnr = se > 0 ? 10 * log10(1.0 / (se / (w * h * 3))) : 999;
        printf("synth at camera (%d,%d), 16 spp: PSNR %.1f dB vs its tile (threshold 60)\n", cams[k][0], cams[k][1],
               psnr);
        CHECK(psnr > 60);
        lf_image_free(&img);
    }

    /* between cameras: a pinhole render from there (focal plane at the scene) */
    {
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = w, o.height = h, o.fov_deg = FOV;
        o.pos[0] = 0.37 * b, o.pos[1] = -0.71 * b;
        o.focal_distance = Z;
        lf_image img;
        CHECK(lf_lightfield_synth(&lf, &o, &img, NULL, NULL, &err) == 0);
        float *truth = malloc(sizeof(float) * w * h * 3);
        render_view(o.pos[0], o.pos[1], Z, w, h, truth);
        double se = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            se += (img.data[i] - truth[i]) * (img.data[i] - truth[i]);
        double psnr = 10 * log10(1.0 / (se / (w * h * 3)));
        printf("synth between cameras: PSNR %.2f dB vs analytic pinhole view (threshold 40)\n", psnr);
        CHECK(psnr > 40);
        /* the same with a wrong focal plane is visibly worse */
        o.focal_distance = 0.5 * Z;
        lf_image bad;
        CHECK(lf_lightfield_synth(&lf, &o, &bad, NULL, NULL, &err) == 0);
        se = 0;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            se += (bad.data[i] - truth[i]) * (bad.data[i] - truth[i]);
        double psnr_bad = 10 * log10(1.0 / (se / (w * h * 3)));
        printf("  with the focal plane at Z/2: %.2f dB\n", psnr_bad);
        CHECK(psnr_bad < psnr - 10);
        lf_image_free(&img), lf_image_free(&bad);
        free(truth);
    }

    /* rays that leave the captured aperture are reported */
    {
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = w, o.height = h, o.fov_deg = FOV;
        o.pos[0] = 1.0; /* far outside the grid, pinhole: every ray misses it */
        lf_image img, cov;
        size_t unc = 0;
        CHECK(lf_lightfield_synth(&lf, &o, &img, &cov, &unc, &err) == 0);
        CHECK(unc == (size_t)w * h);
        CHECK(cov.data[0] == 0.f);
        lf_image_free(&img), lf_image_free(&cov);
        /* looking sideways from inside the grid: partly outside the data cameras' view */
        o.pos[0] = 0, o.rot_deg[1] = 30;
        CHECK(lf_lightfield_synth(&lf, &o, &img, &cov, &unc, &err) == 0);
        printf("rotated 30 deg about y: %zu of %d pixels uncovered\n", unc, w * h);
        CHECK(unc > 0 && unc < (size_t)w * h);
        lf_image_free(&img), lf_image_free(&cov);
        o.lens_radius = 0.01, o.focal_distance = 0;
        CHECK(lf_lightfield_synth(&lf, &o, &img, &cov, &unc, &err) == LF_ERR_PARAM);
        lf_error_clear(&err);
    }
    lf_lightfield_free(&lf);

    /* blur: 9 x 9 cameras 10 cm apart, step edge on a plane at Zs = 2 m,
     * virtual lens radius r focused at fd = 1 m.  Thin lens: circle of
     * confusion D = 2 r F_px |1/fd - 1/Zs| px; a disk's line spread has
     * sigma = D/4.  Bilinear blending across cameras adds fx (1 - fx) b^2
     * to the aperture's variance (integrated over the disk below). */
    {
        const int nb = 9, wb = 128, hb = 64;
        const double bb = 0.1, Zs = 2, fd = 1, r = 0.2;
        g_edge = 1;
        make_lf(&lf, nb, bb, Zs, 256, 128);
        double F = 0.5 * hb / tan(FOV * M_PI / 360); /* output F_px (shorter side 64) */
        double Fin = 0.5 * 128 / tan(FOV * M_PI / 360);
        double k = F * fabs(1 / fd - 1 / Zs);
        double D = 2 * r * k;
        double s_in = F / Fin; /* one input pixel in output pixels */
        /* variance of the sampled camera-plane point: lens point p (uniform on
         * the disk) plus bilinear choice among cameras, fx (1 - fx) b^2 */
        double vq = 0;
        int nq = 0;
        for (int iy = 0; iy < 400; iy++)
            for (int ix = 0; ix < 400; ix++) {
                double px = r * ((ix + 0.5) / 200 - 1), py = r * ((iy + 0.5) / 200 - 1);
                if (px * px + py * py > r * r)
                    continue;
                double g = (px + bb * (nb - 1) / 2) / bb, fx = g - floor(g);
                vq += px * px + fx * (1 - fx) * bb * bb, nq++;
            }
        vq /= nq;
        /* + input pixel tent (1/6), output pixel jitter (1/12), pixel binning of the ESF (1/12) */
        double sigma_expect = sqrt(k * k * vq + s_in * s_in / 6 + 1.0 / 12 + 1.0 / 12);
        lf_lightfield_synth_opts o = lf_lightfield_synth_defaults();
        o.width = wb, o.height = hb, o.fov_deg = FOV;
        o.lens_radius = r, o.focal_distance = fd, o.spp = 256, o.seed = 3;
        lf_image img;
        CHECK_MSG(lf_lightfield_synth(&lf, &o, &img, NULL, NULL, &err) == 0, "%s", err.msg);
        double sigma = edge_sigma(&img);
        printf("blur: thin-lens D = %.2f px (disk sigma %.3f); expected sigma with camera blending %.3f, measured %.3f "
               "(tol 3%%)\n",
               D, D / 4, sigma_expect, sigma);
        CHECK(fabs(sigma - sigma_expect) < 0.03 * sigma_expect);
        /* the estimator itself, on an analytic thin-lens render: D/4 */
        lf_image ref;
        lf_image_alloc(&ref, wb, hb, 3, &err);
        thin_lens_edge(&ref, r, fd, Zs, 256);
        double sigma_ref = edge_sigma(&ref), ref_expect = sqrt(D * D / 16 + 1.0 / 12 + 1.0 / 12);
        printf("  analytic thin-lens render: sigma %.3f, expected %.3f (tol 3%%)\n", sigma_ref, ref_expect);
        CHECK(fabs(sigma_ref - ref_expect) < 0.03 * ref_expect);
        lf_image_free(&ref);
        lf_image_free(&img);
        /* pinhole: sharp */
        o.lens_radius = 0, o.spp = 16, o.focal_distance = Zs;
        CHECK(lf_lightfield_synth(&lf, &o, &img, NULL, NULL, &err) == 0);
        double s0 = edge_sigma(&img);
        printf("pinhole edge sigma %.3f px\n", s0);
        CHECK(s0 < 1.0);
        lf_image_free(&img);
        lf_lightfield_free(&lf);
    }
    return lf_test_end();
}
