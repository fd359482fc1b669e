/* Ranges that never cut silently (lf_lightfield_depth_range_report, lftool
 * depth): a 5 x 5 array of parallel pinholes (baseline B, focal length F
 * px, views 128 x 128) looks at a textured wall at disparity F B / Z_WALL
 * = 3 px/view and a textured square at F B / Z_NEAR = 11.5 px/view, beyond
 * the first sweep's 8 px/view.  Ground truth from the geometry: the
 * estimate must reach past 11.5 (widened, and saying from what), and the
 * square's disparity must come out right.  The tool must say where its
 * range came from: estimated (widened from ...), --from/--to, or the
 * folder's disp_min/disp_max. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lf_test.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lf_test_texture.h"

#define LFTOOL LF_BINARY_DIR "/bin/lftool"

enum { N = 5, W = 128, H = 128, SS = 3 };
static const double F = 128.0, B = 0.05;
static const double Z_WALL = F * B / 3.0, Z_NEAR = F * B / 11.5, HALF = 0.09; /* the square: |X|, |Y| < HALF at Z_NEAR */


/* depth of the first hit of the ray from (cx, cy, 0) along (dx, dy, 1), and its colour */
static double trace(double cx, double cy, double dx, double dy, float c[3])
{
    double X = cx + Z_NEAR * dx, Y = cy + Z_NEAR * dy, Z = Z_NEAR;
    int near = fabs(X) < HALF && fabs(Y) < HALF;
    if (!near)
        X = cx + Z_WALL * dx, Y = cy + Z_WALL * dy, Z = Z_WALL;
    if (c) {
        double n = 0.6 * vnoise(X * 90 + 31 * near, Y * 90) + 0.4 * vnoise(X * 35 + 7, Y * 35 + 3);
        c[0] = (float)(0.1 + 0.8 * n), c[1] = (float)(near ? 0.2 + 0.5 * n : 0.6 - 0.4 * n), c[2] = (float)(0.3 + 0.3 * n);
    }
    return Z;
}

static void make_lf(lf_lightfield *lf)
{
    lf_error err = {0};
    lf_lightfield_alloc(lf, N, N, W, H, &err);
    lf->disp_v_per_u = 1.0;
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++) {
            double cx = (u - (N - 1) / 2.0) * B, cy = -(v - (N - 1) / 2.0) * B;
            float *dst = lf_lightfield_view(lf, u, v);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    double acc[3] = {0, 0, 0};
                    for (int j = 0; j < SS; j++)
                        for (int i = 0; i < SS; i++) {
                            float c[3];
                            trace(cx, cy, (x + (i + 0.5) / SS - W / 2.0) / F, -(y + (j + 0.5) / SS - H / 2.0) / F, c);
                            for (int k = 0; k < 3; k++)
                                acc[k] += c[k];
                        }
                    for (int k = 0; k < 3; k++)
                        dst[((size_t)y * W + x) * 3 + k] = (float)(acc[k] / (SS * SS));
                }
        }
}

static char out_text[65536];

static int run(const char *dir, const char *cmd)
{
    char full[2048];
    snprintf(full, sizeof full, "%s > %s/log.txt 2>&1", cmd, dir);
    int st = system(full);
    snprintf(full, sizeof full, "%s/log.txt", dir);
    FILE *f = fopen(full, "rb");
    size_t n = f ? fread(out_text, 1, sizeof out_text - 1, f) : 0;
    out_text[n] = '\0';
    if (f)
        fclose(f);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int main(void)
{
    lf_lightfield lf = {0};
    make_lf(&lf);
    const double d_wall = F * B / Z_WALL, d_near = F * B / Z_NEAR;
    lf_error err = {0};

    /* the estimate: the first sweep stops at 8 px/view; the square's
     * pixels (16 % of the view) pile up on its end label, so that end is
     * widened, at most to a quarter of the view at the outermost view
     * (128 / 4 / 2 = 16 px/view) */
    double d0 = 0, d1 = 0;
    lf_lightfield_depth_range_info ri;
    CHECK_MSG(!lf_lightfield_depth_range_report(&lf, 2, &d0, &d1, &ri, &err), "%s", err.msg);
    printf("range %.3f .. %.3f (first %.3f .. %.3f, search %.3f .. %.3f)\n", d0, d1, ri.first_d0, ri.first_d1,
           ri.search_d0, ri.search_d1);
    CHECK(ri.widened);
    CHECK(ri.first_d1 <= 8.0 + 1e-9);
    CHECK(ri.search_d1 > 8.0 && ri.search_d1 <= 16.0 + 1e-9);
    CHECK(d0 <= d_wall && d1 >= d_near);
    CHECK(d1 <= d_near + 0.25 * (d_near - d_wall) + 1.0); /* padded, not the whole search */

    /* depth over the estimated range: the square's disparity right.  Inside
     * the square (3 px from its silhouette: the occlusion edge is not what
     * this checks) at least 95 % of the pixels within 0.1 px/view and the
     * median within 0.05 (the method's accuracy on textured fronto-parallel
     * surfaces, docs/depth.md, is a few hundredths) */
    lf_lightfield_depth_opts o = lf_lightfield_depth_defaults();
    o.threads = 2;
    lf_image disp = {0};
    CHECK_MSG(!lf_lightfield_depth(&lf, &o, &disp, NULL, &err), "%s", err.msg);
    int n = 0, good = 0;
    double *errs = malloc(sizeof(double) * W * H);
    for (int y = 0; y < H && disp.data; y++)
        for (int x = 0; x < W; x++) {
            int inside = 1;
            for (int j = -3; j <= 3; j += 6)
                for (int i = -3; i <= 3; i += 6)
                    if (trace(0, 0, (x + 0.5 + i - W / 2.0) / F, -(y + 0.5 + j - H / 2.0) / F, NULL) != Z_NEAR)
                        inside = 0;
            if (!inside)
                continue;
            double e = fabs(disp.data[(size_t)y * W + x] - d_near);
            errs[n++] = e;
            good += e <= 0.1;
        }
    int cmp_n = n;
    for (int i = 1; i < cmp_n; i++) /* insertion sort: a few thousand values */
        for (int j = i; j > 0 && errs[j - 1] > errs[j]; j--) {
            double t = errs[j];
            errs[j] = errs[j - 1], errs[j - 1] = t;
        }
    printf("square: %d px, %.1f %% within 0.1 px/view, median |error| %.4f\n", n, 100.0 * good / (n ? n : 1),
           n ? errs[n / 2] : -1.0);
    CHECK(n > 400);
    CHECK(good >= 0.95 * n);
    CHECK(n && errs[n / 2] <= 0.05);
    free(errs);
    lf_image_free(&disp);

    /* the tool says where the range came from */
    char base[] = "/tmp/lf_range_XXXXXX";
    CHECK(mkdtemp(base) != NULL);
    char dir[600], cmd[2048];
    snprintf(dir, sizeof dir, "%s/views", base);
    mkdir(dir, 0755);
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++) {
            char path[700];
            snprintf(path, sizeof path, "%s/scene_%02d_%02d.pfm", dir, v, u);
            lf_image img = {W, H, 3, lf_lightfield_view(&lf, u, v)};
            CHECK_MSG(!lf_image_write(path, &img, NULL, NULL, &err), "%s", err.msg);
        }
    snprintf(cmd, sizeof cmd, "%s depth %s -o %s/d.pfm --threads 2", LFTOOL, dir, base);
    CHECK(run(base, cmd) == 0);
    double t0 = 0, t1 = 0;
    const char *r = strstr(out_text, "(range ");
    CHECK_MSG(r && sscanf(r, "(range %lf .. %lf", &t0, &t1) == 2 && t0 <= d_wall && t1 >= d_near &&
                  strstr(out_text, "px/view, estimated, widened from "),
              "%s", out_text);
    snprintf(cmd, sizeof cmd, "%s depth %s -o %s/d.pfm --threads 2 --from 2 --to 13", LFTOOL, dir, base);
    CHECK(run(base, cmd) == 0);
    CHECK_MSG(strstr(out_text, "range 2 .. 13 px/view, --from/--to"), "%s", out_text);
    /* the HCI layout with parameters.cfg's disp_min/disp_max */
    snprintf(dir, sizeof dir, "%s/hci", base);
    lf.layout.kind = LF_LIGHTFIELD_CAMERA_ARRAY, lf.layout.cams_x = lf.layout.cams_y = N;
    lf.layout.disp_min = 2.5, lf.layout.disp_max = 12.5;
    lf.layout.have |= LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_DISP_RANGE;
    CHECK_MSG(!lf_lightfield_write_hci(dir, &lf, NULL, &err), "%s", err.msg);
    snprintf(cmd, sizeof cmd, "%s depth %s -o %s/d.pfm --threads 2", LFTOOL, dir, base);
    CHECK(run(base, cmd) == 0);
    CHECK_MSG(strstr(out_text, "range 2.5 .. 12.5 px/view, the folder's disp_min/disp_max"), "%s", out_text);
    snprintf(cmd, sizeof cmd, "rm -rf %s", base);
    CHECK(system(cmd) == 0);
    lf_lightfield_free(&lf);
    return lf_test_end();
}
