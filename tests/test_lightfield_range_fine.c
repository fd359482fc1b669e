/* An estimated range on fine periodic texture (issue 28 point 3, "ranges
 * never cut silently"; docs/depth.md, "The range checked at full
 * resolution"): a 9 x 9 array of parallel pinholes (baseline B, focal
 * length F px, views 192 x 192) looks at a fronto-parallel plane of checks
 * rotated 10 degrees that fills the view, at depth Z, so the disparity is
 * F B / Z everywhere.  The range is estimated on views reduced 4 x 4, where
 * checks of 2.5-4 px alias; the estimate (lf_lightfield_depth_range_report,
 * as lftool depth uses it) must still hold the true disparity, for 3
 * periods x 3 disparities.  And on a plane of smooth texture, where the
 * reduced views see everything, the check must find the truth without
 * widening past it (no false minima far out). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lf_test.h"
#include "lf_test_texture.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"

enum { N = 9, W = 192, H = 192, SS = 3 };
static const double F = 192.0, B = 0.0125;
static double g_z, g_period_px; /* the plane's depth; the checks' period in image px (0: smooth texture) */

static double trace(double cx, double cy, double dx, double dy, float c[3])
{
    double X = cx + g_z * dx, Y = cy + g_z * dy;
    double v;
    if (g_period_px > 0) {
        double p = g_period_px * g_z / F, a = 10 * M_PI / 180; /* the period on the plane */
        double s = (cos(a) * X + sin(a) * Y) / p, t = (-sin(a) * X + cos(a) * Y) / p;
        v = ((int)floor(s) + (int)floor(t)) & 1 ? 0.8 : 0.2;
    } else {
        v = 0.2 + 0.6 * (0.6 * vnoise(X * 400, Y * 400) + 0.4 * vnoise(X * 150 + 7, Y * 150 + 3));
    }
    c[0] = (float)v, c[1] = (float)(0.5 * v + 0.2), c[2] = (float)(0.9 - 0.6 * v);
    return g_z;
}

static void make_lf(lf_lightfield *lf, double disparity, double period_px)
{
    g_z = F * B / disparity, g_period_px = period_px;
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++)
            lf_test_render_view(lf_lightfield_view(lf, u, v), W, H, SS, F, (u - (N - 1) / 2.0) * B,
                                -(v - (N - 1) / 2.0) * B, 0, 0, trace);
}

int main(void)
{
    lf_lightfield lf = {0};
    lf_error err = {0};
    CHECK_MSG(!lf_lightfield_alloc(&lf, N, N, W, H, &err), "%s", err.msg);
    lf.disp_v_per_u = 1.0;
    const double periods[3] = {2.5, 3.0, 4.0}, disps[3] = {0.8, 1.2, 1.6};
    int held = 0;
    for (int pi = 0; pi < 3; pi++)
        for (int di = 0; di < 3; di++) {
            make_lf(&lf, disps[di], periods[pi]);
            double d0 = 0, d1 = 0;
            lf_lightfield_depth_range_info ri;
            CHECK_MSG(!lf_lightfield_depth_range_report(&lf, 2, &d0, &d1, &ri, &err), "%s", err.msg);
            int ok = d0 <= disps[di] && disps[di] <= d1;
            held += ok;
            printf("checks %.1f px at %.1f px/view: range %.3f .. %.3f (%s), full-resolution check: %d of %d "
                   "samples confirmed, %.3f .. %.3f%s\n",
                   periods[pi], disps[di], d0, d1, ok ? "holds" : "MISSES", ri.full_confirmed, ri.full_samples,
                   ri.full_lo, ri.full_hi, ri.full_widened ? ", widened" : "");
            CHECK_MSG(ok, "checks of %.1f px at %.1f px/view: range %.3f .. %.3f", periods[pi], disps[di], d0, d1);
        }
    printf("%d of 9 ranges hold the truth\n", held);

    /* smooth texture at 1.2 px/view: the estimate holds the truth, and the
     * check confirms it (most samples, winners within 0.1 px/view of it)
     * without reaching far out */
    make_lf(&lf, 1.2, 0);
    double d0 = 0, d1 = 0;
    lf_lightfield_depth_range_info ri;
    CHECK_MSG(!lf_lightfield_depth_range_report(&lf, 2, &d0, &d1, &ri, &err), "%s", err.msg);
    printf("smooth texture at 1.2 px/view: range %.3f .. %.3f, check %d of %d confirmed, %.3f .. %.3f%s\n", d0, d1,
           ri.full_confirmed, ri.full_samples, ri.full_lo, ri.full_hi, ri.full_widened ? ", widened" : "");
    CHECK(d0 <= 1.2 && d1 >= 1.2);
    CHECK(ri.full_confirmed >= ri.full_samples / 2);
    CHECK(fabs(ri.full_lo - 1.2) <= 0.1 && fabs(ri.full_hi - 1.2) <= 0.1);
    CHECK(d1 - d0 <= 1.0);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
