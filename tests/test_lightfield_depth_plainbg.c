/* A textured object before a plain background (issue 28: occlusion edges
 * against plain backgrounds; docs/depth.md, "Plain regions"): a camera
 * array (7 x 7 pinholes, baseline B, focal length F px) looks at a
 * textured square at Z = 1.5 m before a plain grey wall at Z = 3 m that
 * carries only a sparse lattice of small grey marks.  Between the marks
 * every label explains the wall equally well, and the aggregation hands
 * the wall whatever reaches it: beside the square, the square's
 * disparity.  The plain-region step gives the wall the far end of the
 * evidence of its own colour (its marks).  Clean views, then views with
 * 1 % Gaussian noise (fixed seed), where the wall's curves are noise and
 * the plain test must measure that.  Ground truth: F B / Z at each pixel
 * centre; nothing here comes from the code under test. */
#include <math.h>
#include <stdlib.h>

#include "lf_test.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lf_test_texture.h"

enum { N = 7, W = 112, H = 112, SS = 2 };
static const double F = 112.0, B = 0.02;
static const double ZF = 1.5, ZW = 3.0; /* the square, the wall */
static const double HS = 0.25;          /* the square's half side (m): 37 px in the centre view */
static const double MARK = 0.35;        /* the marks' lattice on the wall (m): 13 px */

/* the colour seen along the ray from (cx, cy, 0) in direction (dx, dy, 1);
 * returns the depth hit */
static double trace(double cx, double cy, double dx, double dy, float col[3])
{
    double X = cx + ZF * dx, Y = cy + ZF * dy;
    if (fabs(X) < HS && fabs(Y) < HS) {
        if (col) {
            double n = 0.6 * vnoise(X * 60, Y * 60) + 0.4 * vnoise(X * 25 + 7, Y * 25 + 3);
            col[0] = (float)(0.2 + 0.6 * n), col[1] = (float)(0.15 + 0.4 * n), col[2] = (float)(0.1 + 0.3 * n);
        }
        return ZF;
    }
    X = cx + ZW * dx, Y = cy + ZW * dy;
    if (col) {
        /* a mark: a 4 x 4 cm square at each lattice point (about 1.5 px) */
        double mx = X / MARK - floor(X / MARK), my = Y / MARK - floor(Y / MARK);
        float g = mx < 0.12 && my < 0.12 ? 0.4f : 0.5f;
        col[0] = g, col[1] = g, col[2] = 0.95f * g;
    }
    return ZW;
}

static void render(int u, int v, float *dst)
{
    double cx = (u - (N - 1) / 2.0) * B, cy = -(v - (N - 1) / 2.0) * B;
    lf_test_render_view(dst, W, H, SS, F, cx, cy, 0, 0, trace);
}

/* BadPix0.07 over the wall pixels (8-px image border left out) more than
 * 1 px outside the square's outline in the centre view, and over the band
 * from 1 to 12 px outside it, where the square's disparity spreads. */
static void score(const float *d, double *bad_wall, double *bad_band)
{
    size_t nw = 0, bw = 0, nb = 0, bb = 0;
    double half = HS / ZF * F; /* the outline's half side in px */
    for (int y = 8; y < H - 8; y++)
        for (int x = 8; x < W - 8; x++) {
            double px = x + 0.5 - W / 2.0, py = y + 0.5 - H / 2.0;
            double out = fmax(fabs(px), fabs(py)) - half; /* px outside the outline */
            if (out <= 1)
                continue;
            double z = trace(0, 0, px / F, -py / F, NULL);
            int bad = fabs(d[(size_t)y * W + x] - F * B / z) > 0.07;
            nw++, bw += bad;
            if (out <= 12)
                nb++, bb += bad;
        }
    *bad_wall = 100.0 * bw / nw, *bad_band = 100.0 * bb / nb;
}

/* r: wall and band BadPix0.07 with the plain step (opt-in), then without. */
static void run_case(double noise, double r[4])
{
    lf_error err = {0};
    lf_lightfield lf = {0};
    CHECK_MSG(lf_lightfield_alloc(&lf, N, N, W, H, &err) == 0, "%s", err.msg);
    lf.disp_v_per_u = 1.0;
    unsigned long long st = 12345;
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++) {
            float *view = lf_lightfield_view(&lf, u, v);
            render(u, v, view);
            for (size_t i = 0; noise > 0 && i < (size_t)W * H * 3; i++)
                view[i] += (float)(noise * lf_test_gauss(&st));
        }
    /* the wall at 0.747 px/view, the square at 1.493 */
    lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
    o.d0 = 0.5, o.d1 = 1.7;
    for (int k = 0; k < 2; k++) {
        lf_image d = {0};
        o.plain = k == 0 ? 1 : 0;
        CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
        if (d.data)
            score(d.data, &r[2 * k], &r[2 * k + 1]);
        lf_image_free(&d);
    }
    lf_lightfield_free(&lf);
}

int main(void)
{
    double c[4], n[4];
    run_case(0, c);
    printf("clean views: wall BadPix0.07 %.1f %% (without the plain step %.1f %%), 1-12 px outside the outline "
           "%.1f %% (%.1f %%)\n", c[0], c[2], c[1], c[3]);
    run_case(0.01, n);
    printf("1 %% noise: wall %.1f %% (without %.1f %%), band %.1f %% (%.1f %%)\n", n[0], n[2], n[1], n[3]);
    /* Without the step the square's disparity spreads over the wall beside
     * it (a third of the band wrong, clean or noisy).  With it the wall
     * takes its marks' disparity: the marks are 1.5-px features, so their
     * own estimates spread by a few hundredths of a px/view; bounds of 5 %
     * of the wall and 10 % of the band (the band holds the outline's mixed
     * pixels) leave room for that, and the case must need the step: the
     * band without it at least 20 points worse. */
    CHECK(c[0] < 5.0 && c[1] < 10.0);
    CHECK(c[3] > c[1] + 20.0);
    /* noisy views: the plain test is relative to the noise a flat field
     * gives, so the noisy wall is plain too */
    CHECK(n[0] < 5.0 && n[1] < 10.0);
    CHECK(n[3] > n[1] + 20.0);
    return lf_test_end();
}
