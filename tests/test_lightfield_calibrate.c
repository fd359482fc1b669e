/* Microlens-grid calibration from synthetic white images (square and hex,
 * rotated, non-integer pitch, disks separate or touching): the estimated
 * lattice puts every lens centre within 0.1 px of a true one. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lightfield/lf_lightfield.h"

static void centre(const lf_lightfield_layout *l, int i, int j, double *x, double *y)
{
    int hex = l->grid == LF_LIGHTFIELD_GRID_HEX;
    double lx = i * l->pitch_px + (hex && (j & 1) ? l->pitch_px / 2 : 0);
    double ly = j * l->pitch_px * (hex ? sqrt(3.0) / 2 : 1);
    double c = cos(l->rotation_rad), s = sin(l->rotation_rad);
    *x = l->offset_px[0] + c * lx - s * ly;
    *y = l->offset_px[1] + s * lx + c * ly;
}

/* distance from (x, y) to the nearest true lens centre */
static double nearest(const lf_lightfield_layout *l, double x, double y)
{
    double best = 1e30;
    for (int j = -3; j < 200; j++)
        for (int i = -3; i < 200; i++) {
            double cx, cy;
            centre(l, i, j, &cx, &cy);
            double d = hypot(cx - x, cy - y);
            if (d < best)
                best = d;
        }
    return best;
}

/* white image: a soft-edged, slightly vignetted disk of radius r * pitch per lens */
static void make_white(const lf_lightfield_layout *l, int w, int h, double r, lf_image *img)
{
    lf_error err = {0};
    lf_image_alloc(img, w, h, 3, &err);
    double R = r * l->pitch_px;
    for (int j = -2; j < l->lens_y + 2; j++)
        for (int i = -2; i < l->lens_x + 2; i++) {
            double cx, cy;
            centre(l, i, j, &cx, &cy);
            for (int y = (int)floor(cy - R - 1); y <= (int)ceil(cy + R + 1); y++)
                for (int x = (int)floor(cx - R - 1); x <= (int)ceil(cx + R + 1); x++) {
                    if (x < 0 || y < 0 || x >= w || y >= h)
                        continue;
                    double d = hypot(x + 0.5 - cx, y + 0.5 - cy);
                    double v = fmin(1.0, fmax(0.0, R - d + 0.5)) * (1 - 0.3 * (d / R) * (d / R));
                    float *p = lf_image_px(img, x, y);
                    if (v > p[0])
                        p[0] = p[1] = p[2] = (float)v;
                }
        }
}

static void check_case(const char *name, lf_lightfield_grid grid, double pitch, double rot, double ox, double oy, double r,
                       int w, int h)
{
    lf_error err = {0};
    lf_lightfield_layout truth, none, t;
    lf_lightfield_layout_init(&truth);
    lf_lightfield_layout_init(&none);
    truth.kind = LF_LIGHTFIELD_PLENOPTIC, truth.grid = grid, truth.pitch_px = pitch, truth.rotation_rad = rot;
    truth.offset_px[0] = ox, truth.offset_px[1] = oy;
    truth.have = LF_LIGHTFIELD_HAVE_KIND | LF_LIGHTFIELD_HAVE_GRID | LF_LIGHTFIELD_HAVE_PITCH | LF_LIGHTFIELD_HAVE_ROTATION | LF_LIGHTFIELD_HAVE_OFFSET;
    lf_lightfield_layout_resolve(&truth, &none, w, h, &t, &err);
    lf_image white;
    make_white(&t, w, h, r, &white);
    lf_lightfield_layout est;
    lf_lightfield_layout_init(&est);
    CHECK_MSG(lf_lightfield_calibrate(&white, &est, &err) == 0, "%s: %s", name, err.msg);
    /* every estimated centre inside the image lies on a true one */
    double worst = 0;
    for (int j = 0; j < est.lens_y; j++)
        for (int i = 0; i < est.lens_x; i++) {
            double x, y;
            centre(&est, i, j, &x, &y);
            if (x < 0 || y < 0 || x > w || y > h)
                continue;
            worst = fmax(worst, nearest(&t, x, y));
        }
    printf("%s: grid %s, pitch %.4f (true %.4f), rotation %.5f (true %.5f), offset (%.3f, %.3f); worst centre error "
           "%.3f px (tol 0.1)\n",
           name, est.grid == LF_LIGHTFIELD_GRID_HEX ? "hex" : "square", est.pitch_px, pitch, est.rotation_rad, rot,
           est.offset_px[0], est.offset_px[1], worst);
    CHECK(est.grid == grid);
    CHECK(fabs(est.pitch_px - pitch) < 0.01);
    CHECK(fabs(est.rotation_rad - rot) < 2e-3);
    CHECK(worst < 0.1);
    CHECK(est.offset_px[0] > -pitch && est.offset_px[0] < 1.5 * pitch && est.offset_px[1] > -pitch &&
          est.offset_px[1] < 2 * pitch);
    lf_image_free(&white);
}

int main(void)
{
    check_case("square, separate disks", LF_LIGHTFIELD_GRID_SQUARE, 10.3, 0.03, 3.2, 8.9, 0.42, 420, 330);
    check_case("square, touching disks", LF_LIGHTFIELD_GRID_SQUARE, 14.7, -0.012, 7.0, 6.1, 0.5, 600, 400);
    check_case("hex, separate disks", LF_LIGHTFIELD_GRID_HEX, 9.7, -0.02, 6.1, 6.4, 0.42, 400, 300);
    check_case("hex, touching disks", LF_LIGHTFIELD_GRID_HEX, 12.25, 0.04, 2.0, 9.5, 0.5, 520, 390);
    /* a flat image has no lattice */
    lf_image flat;
    lf_error err = {0};
    lf_image_alloc(&flat, 128, 128, 1, &err);
    for (int i = 0; i < 128 * 128; i++)
        flat.data[i] = 1.f;
    lf_lightfield_layout est;
    lf_lightfield_layout_init(&est);
    CHECK(lf_lightfield_calibrate(&flat, &est, &err) != 0);
    lf_image_free(&flat);
    return lf_test_end();
}
