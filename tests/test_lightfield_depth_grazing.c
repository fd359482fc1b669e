/* Depth on a floor seen at a grazing angle (issue 28: slanted planes): a
 * 7 x 7 camera array (baseline B, focal length F px) looks along a plane
 * Z = Z0 + GY Y textured with value noise (views with Gaussian noise of
 * 1 %, fixed seed, as a capture has), its horizon just above the
 * image: disparity runs from 0.17 px/view at the top (11 m) to 1.74 at the
 * bottom (1.1 m), and the texture is compressed vertically toward the top.
 * Each of the 8 half apertures has false minima of its own there, and a
 * per-label minimum over the halves takes all of them; the half gate
 * (docs/depth.md, stage 2) lets only the most informative half compete.
 * Truth: F B / Z of the plane at each pixel centre; nothing here comes
 * from the code under test. */
#include <math.h>

#include "lf_test.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lf_test_texture.h"

enum { N = 7, W = 96, H = 96, SS = 4 };
static const double F = 96.0, B = 0.02, Z0 = 2.0, GY = 2.0;

/* ray from camera (0, cy, 0) along (., dy, 1): depth of the plane */
static double hit(double cy, double dy)
{
    return (Z0 + GY * cy) / (1 - GY * dy);
}

static void render(int u, int v, float *dst)
{
    double cx = (u - (N - 1) / 2.0) * B, cy = -(v - (N - 1) / 2.0) * B;
    unsigned long long st = 1000003ULL * (unsigned long long)(v * N + u + 1);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double acc = 0;
            for (int j = 0; j < SS; j++)
                for (int i = 0; i < SS; i++) {
                    double dx = (x + (i + 0.5) / SS - W / 2.0) / F, dy = -(y + (j + 0.5) / SS - H / 2.0) / F;
                    double t = hit(cy, dy), X = cx + t * dx, Y = cy + t * dy;
                    acc += 0.6 * vnoise(X * 15, Y * 15) + 0.4 * vnoise(X * 6 + 7, Y * 6 + 3);
                }
            for (int k = 0; k < 3; k++)
                dst[((size_t)y * W + x) * 3 + k] = (float)(0.15 + 0.6 * acc / (SS * SS) + 0.05 * k + 0.01 * lf_test_gauss(&st));
        }
}

/* BadPix0.07 over the image minus an 8-px border */
static double badpix(const float *d)
{
    size_t n = 0, bad = 0;
    for (int y = 8; y < H - 8; y++)
        for (int x = 8; x < W - 8; x++) {
            double dy = -(y + 0.5 - H / 2.0) / F;
            n++, bad += fabs(d[(size_t)y * W + x] - F * B / hit(0, dy)) > 0.07;
        }
    return 100.0 * bad / n;
}

int main(void)
{
    lf_error err = {0};
    lf_lightfield lf = {0};
    CHECK_MSG(lf_lightfield_alloc(&lf, N, N, W, H, &err) == 0, "%s", err.msg);
    lf.disp_v_per_u = 1.0;
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++)
            render(u, v, lf_lightfield_view(&lf, u, v));
    double r[2];
    for (int k = 0; k < 2; k++) {
        lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
        o.d0 = 0.0, o.d1 = 2.0; /* the truth spans 0.17 .. 1.74 inside the border */
        o.half_gate = k == 0 ? 0 : -1;
        lf_image d = {0};
        CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
        r[k] = d.data ? badpix(d.data) : 100;
        lf_image_free(&d);
    }
    printf("floor at a grazing angle: BadPix0.07 %.2f %% (without the half gate %.2f %%)\n", r[0], r[1]);
    /* measured 0.59 % and 2.20 % (docs/depth.md); the views are fixed (seeded
     * noise), so the margins only allow for floating-point differences */
    CHECK(r[0] < 1.2);
    CHECK(r[1] > r[0] + 1.0);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
