/* Depth on fine stripes (issue 28: repetitive texture).  A 7 x 7 camera
 * array (baseline B, focal length F px) looks at a plane tilted about the
 * vertical axis
 * painted with stripes 3.5 px apart in the image, in three bands: vertical,
 * horizontal and diagonal, nothing else; the views carry Gaussian noise of
 * 1 % (fixed seed), as a capture would.  The views along the
 * stripes see no change at any disparity (a flat, low cost), and those
 * across them see minima a period apart; the occlusion subsets' per-label
 * minimum takes both.  The line gate (docs/depth.md, stage 2) lets a line
 * of views compete only where it is the most informative subset.  Truth:
 * F B / Z of the plane at each pixel centre; nothing here comes from the
 * code under test. */
#include <math.h>
#include <stdlib.h>

#include "lf_test.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"

enum { N = 7, W = 96, H = 96, SS = 4 };
static const double F = 96.0, B = 0.02, Z = 2.0;
static const double GX = 0.3; /* the plane Z + GX X: d 0.87 .. 1.07 */
static const double PERIOD_PX = 3.5; /* stripe period in the image */

/* colour of the plane at (X, Y): stripes across the band's direction */
static void paint(double X, double Y, float col[3])
{
    double p = PERIOD_PX * Z / F; /* period on the plane */
    double a = Y > 0.25 ? X : (Y > -0.25 ? Y : (X + Y) / sqrt(2.0)); /* vertical, horizontal, diagonal bands */
    double s = 0.5 + 0.5 * sin(2 * M_PI * a / p);
    for (int k = 0; k < 3; k++)
        col[k] = (float)(0.15 + 0.6 * s + 0.05 * k);
}

/* Gaussian deviate (Box-Muller on a 64-bit LCG): the views' noise */
static double gauss(unsigned long long *st)
{
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    double a = ((*st >> 11) + 0.5) / 9007199254740992.0;
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    double b = ((*st >> 11) + 0.5) / 9007199254740992.0;
    return sqrt(-2 * log(a)) * cos(2 * M_PI * b);
}

static void render(int u, int v, float *dst)
{
    unsigned long long st = 1000003ULL * (unsigned long long)(v * N + u + 1);
    double cx = (u - (N - 1) / 2.0) * B, cy = -(v - (N - 1) / 2.0) * B;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double acc[3] = {0, 0, 0};
            for (int j = 0; j < SS; j++)
                for (int i = 0; i < SS; i++) {
                    double px = x + (i + 0.5) / SS - W / 2.0, py = y + (j + 0.5) / SS - H / 2.0;
                    float c[3];
                    double dx = px / F, dy = -py / F, t = (Z + GX * cx) / (1 - GX * dx);
                    paint(cx + t * dx, cy + t * dy, c);
                    for (int k = 0; k < 3; k++)
                        acc[k] += c[k];
                }
            for (int k = 0; k < 3; k++)
                dst[((size_t)y * W + x) * 3 + k] = (float)(acc[k] / (SS * SS) + 0.01 * gauss(&st));
        }
}

/* BadPix0.07 over the image minus an 8-px border, against the plane's
 * disparity at the pixel centre */
static double badpix(const float *d)
{
    size_t n = 0, bad = 0;
    for (int y = 8; y < H - 8; y++)
        for (int x = 8; x < W - 8; x++)
        {
            double dx = (x + 0.5 - W / 2.0) / F, t = Z / (1 - GX * dx);
            n++, bad += fabs(d[(size_t)y * W + x] - F * B / t) > 0.07;
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
        o.d0 = 0.3, o.d1 = 2.0; /* truth 0.96; 2.0 px/view is more than half a period at one view step */
        o.line_gate = k == 0 ? 0 : -1;
        lf_image d = {0};
        CHECK_MSG(lf_lightfield_depth(&lf, &o, &d, NULL, &err) == 0, "%s", err.msg);
        r[k] = d.data ? badpix(d.data) : 100;
        lf_image_free(&d);
    }
    printf("stripes 3.5 px apart (vertical, horizontal, diagonal bands) on a tilted plane: BadPix0.07 %.2f %% (without the line gate %.2f %%)\n",
           r[0], r[1]);
    /* measured 0.22 % and 5.22 % (docs/depth.md): the gate leaves a few
     * pixels, without it the lines' flat curves take whole patches */
    CHECK(r[0] < 1.5);
    CHECK(r[1] > r[0] + 3.0);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
