/* Pre-smoothing noisy views (lf_lightfield_depth_opts.prefilter, lftool
 * depth --prefilter; docs/depth.md, "Pre-smoothing noisy views").  A 7 x 7
 * camera array (baseline B, focal length F px) looks at a tilted plane
 * Z = Z0 + GX X + GY Y textured with value noise.  Truth: F B / Z at each
 * pixel centre, from the geometry.
 * - A dim capture: the texture at 0.03 .. 0.17 of full scale, Gaussian
 *   noise of 1 % of full scale on every view (fixed seeds).  The default
 *   (auto) finds the views noisy (in sRGB codes, where a picture shows it,
 *   the noise reads as 3 % of the level) and smooths them: BadPix0.07 must be at
 *   most half of what the same views give with it off, and below 5 %.
 * - Dimmer still, 2 % noise: the pre-smoothed views are also matched with
 *   their noise whitened (lf_depth_noise_variance) and a 4 x wider window
 *   where the narrow one is unsure (docs/depth.md, "Noisy views: whitened
 *   and a wider window").  The default must stay below 2 % where each
 *   part turned off costs: whitening off at least 5 times as many bad
 *   pixels, the wide window off at least twice as many.
 * - Without noise the default must leave the views alone: the map is the
 *   one prefilter off gives, to the bit, while an explicit sigma changes
 *   it (so the comparison can fail). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_texture.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"

enum { N = 7, W = 96, H = 96, SS = 2, BORDER = 8 };
static const double F = 96.0, B = 0.02, Z0 = 2.0, GX = 0.3, GY = 0.1;
static const double D0 = 0.6, D1 = 1.4;

static double hit(double cx, double cy, double dx, double dy, double *X, double *Y)
{
    return lf_test_plane_hit(Z0, GX, GY, cx, cy, dx, dy, X, Y);
}

/* level: the texture's scale (1: 0.15 .. 0.85 of full scale); sigma: the
 * noise, of full scale */
static void make_lf(lf_lightfield *lf, double level, double sigma)
{
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++)
            lf_test_plane_view(lf_lightfield_view(lf, u, v), W, H, SS, F, (u - (N - 1) / 2.0) * B,
                               -(v - (N - 1) / 2.0) * B, Z0, GX, GY, level, sigma,
                               104729ULL * (unsigned long long)(v * N + u + 1));
}

/* BadPix0.07 (%) of map against F B / Z, BORDER px left out */
static double badpix(const lf_image *d)
{
    int n = 0, bad = 0;
    for (int y = BORDER; y < H - BORDER; y++)
        for (int x = BORDER; x < W - BORDER; x++) {
            double truth = F * B / hit(0, 0, (x + 0.5 - W / 2.0) / F, -(y + 0.5 - H / 2.0) / F, NULL, NULL);
            bad += fabs(d->data[(size_t)y * W + x] - truth) > 0.07;
            n++;
        }
    return 100.0 * bad / n;
}

static int depth_with(const lf_lightfield *lf, double prefilter, int wide_window, int noise_aware, lf_image *out)
{
    lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
    o.threads = 2, o.d0 = D0, o.d1 = D1, o.prefilter = prefilter;
    o.wide_window = wide_window, o.noise_aware = noise_aware;
    lf_error err = {0};
    int rc = lf_lightfield_depth(lf, &o, out, NULL, &err);
    if (rc)
        printf("depth: %s\n", err.msg);
    return rc;
}

static int depth(const lf_lightfield *lf, double prefilter, lf_image *out)
{
    return depth_with(lf, prefilter, 0, 0, out);
}

int main(void)
{
    lf_lightfield lf = {0};
    lf_error err = {0};
    CHECK_MSG(!lf_lightfield_alloc(&lf, N, N, W, H, &err), "%s", err.msg);
    lf.disp_v_per_u = 1.0;

    make_lf(&lf, 0.2, 0.01);
    double nr = lf_lightfield_depth_noise_ratio(&lf, &err);
    printf("dim noisy views: noise ratio %.4f (pre-smoothed from %.2f)\n", nr, LF_DEPTH_PREFILTER_NOISE);
    CHECK(nr >= LF_DEPTH_PREFILTER_NOISE);
    lf_image a = {0}, off = {0};
    CHECK(!depth(&lf, 0, &a) && !depth(&lf, -1, &off));
    double ba = badpix(&a), bo = badpix(&off);
    printf("dim views (0.03 .. 0.17 of full scale), 1 %% noise: BadPix0.07 %.2f %% by default (auto), %.2f %% with the views' pre-smoothing off\n", ba, bo);
    CHECK(ba <= 0.5 * bo);
    CHECK(ba < 5.0);
    lf_image_free(&a), lf_image_free(&off);

    make_lf(&lf, 0.2, 0.02);
    lf_image nw = {0}, nn = {0};
    CHECK(!depth(&lf, 0, &a) && !depth_with(&lf, 0, 0, -1, &nw) && !depth_with(&lf, 0, -1, 0, &nn));
    double b2 = badpix(&a), bw = badpix(&nw), bn = badpix(&nn);
    printf("dim views, 2 %% noise: BadPix0.07 %.2f %% by default, %.2f %% with the whitening off, %.2f %% with the wide "
           "window off\n", b2, bw, bn);
    CHECK(b2 < 2.0);
    CHECK(bw >= 5 * b2 && bw > 2.0);
    CHECK(bn >= 2 * b2 && bn > 1.0);
    lf_image_free(&a), lf_image_free(&nw), lf_image_free(&nn);

    make_lf(&lf, 1, 0);
    nr = lf_lightfield_depth_noise_ratio(&lf, &err);
    printf("clean views: noise ratio %.4f\n", nr);
    CHECK(nr >= 0 && nr < LF_DEPTH_PREFILTER_NOISE);
    lf_image e = {0};
    CHECK(!depth(&lf, 0, &a) && !depth(&lf, -1, &off) && !depth(&lf, 0.7, &e));
    int same = a.data && off.data && !memcmp(a.data, off.data, sizeof(float) * W * H);
    int differs = e.data && off.data && memcmp(e.data, off.data, sizeof(float) * W * H);
    printf("no noise: BadPix0.07 %.2f %% by default, %.2f %% off (%s), %.2f %% with sigma 0.7\n", badpix(&a),
           badpix(&off), same ? "the same map" : "DIFFERENT maps", badpix(&e));
    CHECK(same);
    CHECK(differs);
    lf_image_free(&a), lf_image_free(&off), lf_image_free(&e);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
