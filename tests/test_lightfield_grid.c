/* A folder's grid checked against its parallax (lf_lightfield_grid_parallax,
 * lf_lightfield_open): a 5 x 5 camera array of parallel pinholes (baseline
 * B, focal length F px) looks at a textured plane at Z0 and a textured box
 * face at ZB, so every disparity is F B / Z > 0 (1.6 and 3.2 px/view).  The
 * views are written as PREFIX_RR_CC.pfm, then renamed as a swapped export
 * (RR and CC exchanged) and a mirrored one (a row's views right to left):
 * both must be detected and read back as the views that were rendered.  A
 * textureless grid must say it cannot tell and be left as named. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lf_test.h"
#include "lightfield/lf_source.h"
#include "lf_test_texture.h"

enum { N = 5, W = 160, H = 160, SS = 2 };
static const double F = 160.0, B = 0.02, Z0 = 2.0, ZB = 1.0;
static int g_flat;


/* view (u, v): camera at ((u - 2) B, -(v - 2) B), y up in the world, rows down */
static void render(int u, int v, float *dst)
{
    double cx = (u - (N - 1) / 2.0) * B, cy = -(v - (N - 1) / 2.0) * B;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double acc = 0;
            for (int j = 0; j < SS; j++)
                for (int i = 0; i < SS; i++) {
                    double dx = (x + (i + 0.5) / SS - W / 2.0) / F, dy = -(y + (j + 0.5) / SS - H / 2.0) / F;
                    double X = cx + ZB * dx, Y = cy + ZB * dy;
                    int box = fabs(X) < 0.05 && fabs(Y) < 0.05;
                    if (!box)
                        X = cx + Z0 * dx, Y = cy + Z0 * dy;
                    acc += g_flat ? 0.5 : 0.2 + 0.6 * vnoise(X * 60 + 11 * box, Y * 60);
                }
            float val = (float)(acc / (SS * SS));
            if (g_flat) /* a flat grey wall with faint sensor noise */
                val += (float)(0.002 * (hash2(x + 1000 * u, y + 1000 * v) - 0.5));
            for (int c = 0; c < 3; c++)
                dst[((size_t)y * W + x) * 3 + c] = val * (c == 0 ? 1.0f : c == 1 ? 0.9f : 0.8f);
        }
}

static void make_lf(lf_lightfield *lf)
{
    lf_error err = {0};
    lf_lightfield_alloc(lf, N, N, W, H, &err);
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++)
            render(u, v, lf_lightfield_view(lf, u, v));
}

/* view (u, v) written as PREFIX_RR_CC.pfm with RR, CC from name(u, v) */
static void write_folder(const char *dir, const lf_lightfield *lf, int how)
{
    mkdir(dir, 0755);
    for (int v = 0; v < N; v++)
        for (int u = 0; u < N; u++) {
            int rr = v, cc = u;
            if (how == 1) /* swapped: the row number names the column */
                rr = u, cc = v;
            else if (how == 2) /* mirrored: a row's views right to left */
                cc = N - 1 - u;
            char path[512];
            snprintf(path, sizeof path, "%s/scene_%02d_%02d.pfm", dir, rr, cc);
            lf_image img = {W, H, 3, lf_lightfield_view(lf, u, v)};
            lf_error err = {0};
            CHECK_MSG(!lf_image_write(path, &img, NULL, NULL, &err), "%s", err.msg);
        }
}

static int same_views(const lf_lightfield *a, const lf_lightfield *b)
{
    return a->nu == b->nu && a->nv == b->nv &&
           !memcmp(a->data, b->data, sizeof(float) * (size_t)a->nu * a->nv * a->ns * a->nt * 3);
}

/* opens dir with the grid check (no brightness equalisation: the views must
 * come back as written) */
static int open_dir(const char *dir, const char *grid, lf_lightfield_source *s, lf_error *err)
{
    lf_lightfield_open_opts o = {0};
    o.no_equalize = 1, o.grid = grid;
    return lf_lightfield_open(dir, &o, s, err);
}

int main(void)
{
    char base[] = "/tmp/lf_grid_XXXXXX";
    CHECK(mkdtemp(base) != NULL);
    char ok[600], swapped[600], mirrored[600], flat[600];
    snprintf(ok, sizeof ok, "%s/ok", base);
    snprintf(swapped, sizeof swapped, "%s/swapped", base);
    snprintf(mirrored, sizeof mirrored, "%s/mirrored", base);
    snprintf(flat, sizeof flat, "%s/flat", base);
    lf_lightfield lf = {0}, grey = {0};
    make_lf(&lf);
    g_flat = 1;
    make_lf(&grey);
    write_folder(ok, &lf, 0);
    write_folder(swapped, &lf, 1);
    write_folder(mirrored, &lf, 2);
    write_folder(flat, &grey, 0);

    lf_error err = {0};
    lf_lightfield_source s;
    /* a grid read as captured: row neighbours along x, column neighbours
     * along y, disparity between the plane's 1.6 and the box's 3.2 px/view */
    CHECK_MSG(!open_dir(ok, NULL, &s, &err), "%s", err.msg);
    CHECK(s.parallax_measured);
    CHECK(s.parallax.row.axis == 0 && s.parallax.col.axis == 1);
    CHECK(s.parallax.row.disparity > F * B / Z0 - 0.3 && s.parallax.row.disparity < F * B / ZB + 0.3);
    CHECK(s.parallax.col.disparity > F * B / Z0 - 0.3 && s.parallax.col.disparity < F * B / ZB + 0.3);
    CHECK(lf_warnings_text(&s.warnings) == NULL);
    CHECK(same_views(&s.lf, &lf));
    char buf[4096];
    lf_lightfield_source_describe(&s, buf, sizeof buf);
    CHECK_MSG(strstr(buf, "parallax: row neighbours along x (+1.") && strstr(buf, "column neighbours along y (+1."),
              "%s", buf);
    lf_lightfield_close(&s);

    /* swapped: detected, transposed back, with a note */
    CHECK_MSG(!open_dir(swapped, NULL, &s, &err), "%s", err.msg);
    const char *w = lf_warnings_text(&s.warnings);
    CHECK_MSG(w && strstr(w, "rows and columns swapped") && strstr(w, "--grid-order off"), "%s", w ? w : "(none)");
    CHECK(same_views(&s.lf, &lf));
    CHECK(s.parallax.row.axis == 0 && s.parallax.col.axis == 1);
    lf_lightfield_close(&s);
    /* read as named on request */
    CHECK_MSG(!open_dir(swapped, "off", &s, &err), "%s", err.msg);
    CHECK(!s.parallax_measured && lf_warnings_text(&s.warnings) == NULL && !same_views(&s.lf, &lf));
    lf_lightfield_close(&s);
    CHECK_MSG(!open_dir(swapped, "transpose", &s, &err), "%s", err.msg);
    CHECK(same_views(&s.lf, &lf));
    lf_lightfield_close(&s);

    /* mirrored: the rows' parallax has the sign opposite to the columns'
     * and the columns' is one-signed (parallel cameras): rows flipped */
    CHECK_MSG(!open_dir(mirrored, NULL, &s, &err), "%s", err.msg);
    w = lf_warnings_text(&s.warnings);
    CHECK_MSG(w && strstr(w, "a row's views run right to left"), "%s", w ? w : "(none)");
    CHECK(same_views(&s.lf, &lf));
    CHECK(s.parallax.row.disparity > 0 && s.parallax.col.disparity > 0);
    lf_lightfield_close(&s);

    /* textureless: cannot tell, left as named, said by info */
    CHECK_MSG(!open_dir(flat, NULL, &s, &err), "%s", err.msg);
    CHECK(s.parallax_measured && s.parallax.row.axis == -1 && s.parallax.col.axis == -1);
    CHECK(lf_warnings_text(&s.warnings) == NULL);
    CHECK(same_views(&s.lf, &grey));
    lf_lightfield_source_describe(&s, buf, sizeof buf);
    CHECK_MSG(strstr(buf, "row neighbours: cannot tell") && strstr(buf, "column neighbours: cannot tell"), "%s", buf);
    lf_lightfield_close(&s);

    lf_lightfield_free(&lf);
    lf_lightfield_free(&grey);
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf %s", base);
    CHECK(system(cmd) == 0);
    return lf_test_end();
}
