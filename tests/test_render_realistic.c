/* Renders through real lens prescriptions (Camera "realistic"), with
 * numbers from physics: a point at the focus distance is imaged sharpest,
 * the centre of a flat field receives pi / (4 N_w^2) (an aplanatic lens:
 * sin(alpha') = 1 / (2 N_w)), the stopped-down lens falls off like cos^4 of
 * the image-side chief-ray angle (natural vignetting) and the open lens
 * falls off further (mechanical vignetting), and the fisheye draws a circle
 * of radius f * theta for its published 155.9 degree field. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/lf_camera.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static const lf_test_scene realistic = {.name = LF_SOURCE_DIR "/scenes/test.pbrt"};

/* RMS radius (pixels) of the green channel about its centroid. */
static double blur_rms(const lf_image *img, double *total)
{
    double sw = 0, sx = 0, sy = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++) {
            double v = lf_image_px(img, x, y)[1];
            sw += v, sx += v * (x + 0.5), sy += v * (y + 0.5);
        }
    *total = sw;
    if (!(sw > 0))
        return INFINITY;
    double cx = sx / sw, cy = sy / sw, s2 = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++) {
            double v = lf_image_px(img, x, y)[1];
            s2 += v * ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy));
        }
    return sqrt(s2 / sw);
}

static void test_focus(void)
{
    /* A small emitter 1 m in front of the film on the axis; the lens focused
     * at 0.8, 0.9, 1, 1.1, 1.25 m.  Blur grows with |1/v - 1/v_focus|. */
    const double fd[5] = {0.8, 0.9, 1.0, 1.1, 1.25};
    double rms[5];
    for (int k = 0; k < 5; k++) {
        char scene[2048], msg[1024];
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 0  0 0 1  0 1 0\n"
                 "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.50mm.dat\"\n"
                 "  \"float aperturediameter\" [17.1] \"float focusdistance\" [%g]\n"
                 "Film \"rgb\" \"integer xresolution\" [64] \"integer yresolution\" [64] \"float diagonal\" [4]\n"
                 "Sampler \"zsobol\" \"integer pixelsamples\" [64]\n"
                 "PixelFilter \"box\"\n"
                 "WorldBegin\n"
                 "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [1000 1000 1000]\n"
                 " Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
                 " Translate 0 0 1.0\n Shape \"sphere\" \"float radius\" [0.0005]\nAttributeEnd\n",
                 fd[k]);
        lf_image img;
        if (render_text(scene, &realistic, &img, msg, sizeof msg)) {
            CHECK_MSG(0, "render failed: %s", msg);
            return;
        }
        double total;
        rms[k] = blur_rms(&img, &total);
        CHECK(total > 0);
        lf_image_free(&img);
    }
    for (int k = 0; k < 5; k++)
        if (k != 2)
            CHECK_MSG(rms[2] < rms[k], "blur at the focus distance %.3g px is not below %.3g px (focus %g m)", rms[2],
                      rms[k], fd[k]);
    /* Blur grows monotonically away from focus on both sides. */
    CHECK(rms[0] > rms[1] && rms[4] > rms[3]);
}

/* Mean of the green channel over pixels [x0,x1) x [y0,y1). */
static double mean(const lf_image *img, int x0, int x1, int y0, int y1)
{
    double s = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            s += lf_image_px(img, x, y)[1];
    return s / ((x1 - x0) * (y1 - y0));
}

static int flat_field(const char *lens, double aperture_mm, int w, int h, double diag, lf_image *img)
{
    char scene[2048], msg[1024];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"realistic\" \"string lensfile\" \"lenses/%s\"\n"
             "  \"float aperturediameter\" [%g] \"float focusdistance\" [10]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"float diagonal\" [%g]\n"
             "Sampler \"zsobol\" \"integer pixelsamples\" [1024]\n"
             "PixelFilter \"box\"\n"
             "WorldBegin\n"
             "LightSource \"infinite\" \"rgb L\" [1 1 1]\n",
             lens, aperture_mm, w, h, diag);
    if (render_text(scene, &realistic, img, msg, sizeof msg)) {
        CHECK_MSG(0, "render failed: %s", msg);
        return -1;
    }
    return 0;
}

/* First-order optics of scenes/lenses/dgauss.50mm.dat, computed here with
 * ray-transfer matrices on (y, n u) from the prescription rows (the input
 * data, repeated), independently of camera/lens.c. */
static const double dgauss50[11][4] = {
    {29.475, 3.76, 1.67, 25.2}, {84.83, 0.12, 1, 25.2},   {19.275, 4.025, 1.67, 23}, {40.77, 3.275, 1.699, 23},
    {12.75, 5.705, 1, 18},      {0, 4.5, 1, 17.1},        {-14.495, 1.18, 1.603, 17}, {40.77, 6.065, 1.658, 20},
    {-20.385, 0.19, 1, 20},     {437.065, 3.22, 1.717, 20}, {-39.73, 0, 1, 20}};
typedef struct m2 {
    double a, b, c, d;
} m2;
static m2 mul(m2 x, m2 y)
{
    return (m2){x.a * y.a + x.b * y.c, x.a * y.b + x.b * y.d, x.c * y.a + x.d * y.c, x.c * y.b + x.d * y.d};
}
static m2 rows_matrix(int i0, int i1) /* vertex of i0 to vertex of i1 */
{
    m2 m = {1, 0, 0, 1};
    for (int i = i0; i <= i1; i++) {
        double n = i > 0 ? dgauss50[i - 1][2] : 1.0, np = dgauss50[i][2];
        double power = dgauss50[i][0] != 0 ? (np - n) / dgauss50[i][0] : 0.0;
        m = mul((m2){1, 0, -power, 1}, m);
        if (i < i1)
            m = mul((m2){1, dgauss50[i][1] / np, 0, 1}, m);
    }
    return m;
}

static void test_flat_field(void)
{
    m2 m = rows_matrix(0, 10);
    double efl = -1 / m.c, bfl = -m.a / m.c, ffl = -m.d / m.c, len = 0;
    for (int i = 0; i < 10; i++)
        len += dgauss50[i][1];
    m2 front = mul((m2){1, dgauss50[4][1], 0, 1}, rows_matrix(0, 4)); /* front vertex -> stop */
    double ep_full = 17.1 / fabs(front.a);
    m2 rear = mul(rows_matrix(6, 10), (m2){1, dgauss50[5][1], 0, 1}); /* stop -> rear vertex */
    double xp_from_rear = -rear.b / rear.d;
    /* Film distance at 10 m: thin lens between the principal planes
     * (H = F + f from the front vertex, H' = F' - f from the rear vertex). */
    const double D = 10000.0, hiatus = len + (bfl - efl) - (efl - ffl);
    double e = D - hiatus, v = 2 * efl * e / (e + sqrt(e * (e - 4 * efl)));
    double film = (bfl - efl) + v;
    double mag = v / (e - v);
    lf_image open, stopped;
    /* 36 x 24 pixels of 1 mm on a full-frame film. */
    if (flat_field("dgauss.50mm.dat", 17.1, 36, 24, hypot(36, 24), &open) ||
        flat_field("dgauss.50mm.dat", 17.1 / 4, 36, 24, hypot(36, 24), &stopped))
        return;
    for (int s = 0; s < 2; s++) {
        const lf_image *img = s ? &stopped : &open;
        /* Working f-number N_w = N (1 + m / m_p); the pupil magnification m_p
         * is ~1 for the nearly symmetric double Gauss, so N (1 + m) to 0.1%. */
        double N = efl / (ep_full / (s ? 4 : 1)) * (1 + mag);
        double want = M_PI / (4 * N * N);
        double centre = mean(img, 17, 19, 11, 13);
        /* Aberrations of the open f/2 lens bend the sine condition by a few
         * per cent; stopped down to f/8 it holds to well under 1 per cent. */
        double tol = s ? 0.02 : 0.06;
        CHECK_MSG(fabs(centre - want) <= tol * want, "%s: centre %.5f, pi/(4 N^2) = %.5f",
                  s ? "f/8" : "f/2", centre, want);
    }
    /* Natural vignetting, stopped down: cos^4 of the image-side chief ray
     * angle at 17.5 mm from the centre, to 6% (pupil aberrations). */
    double theta = atan(17.5 / (film - xp_from_rear));
    double c4 = pow(cos(theta), 4);
    double edge_stopped = 0.5 * (mean(&stopped, 35, 36, 11, 13) + mean(&stopped, 0, 1, 11, 13));
    double ratio_stopped = edge_stopped / mean(&stopped, 17, 19, 11, 13);
    CHECK_MSG(fabs(ratio_stopped - c4) <= 0.06 * c4, "f/8 edge/centre %.4f, cos^4 %.4f", ratio_stopped, c4);
    /* Mechanical vignetting, open: the rims of the outer elements cut the
     * oblique beam, so the edge falls much further than cos^4. */
    double edge_open = 0.5 * (mean(&open, 35, 36, 11, 13) + mean(&open, 0, 1, 11, 13));
    double ratio_open = edge_open / mean(&open, 17, 19, 11, 13);
    CHECK_MSG(ratio_open < 0.6 * ratio_stopped, "f/2 edge/centre %.4f not below 0.6 x f/8's %.4f", ratio_open,
              ratio_stopped);
    /* Falloff is monotonic along the horizontal midline (right half). */
    int mono = 1;
    for (int x = 19; x < 36; x++)
        mono &= mean(&open, x, x + 1, 11, 13) <= mean(&open, x - 1, x, 11, 13) * 1.01;
    CHECK(mono);
    lf_image_free(&open);
    lf_image_free(&stopped);
}

static void test_fisheye_circle(void)
{
    /* Square 48 x 48 film, 35 mm diagonal (24.75 mm wide): the fisheye's
     * image circle (published field 155.9 deg, equidistant r = f theta with
     * f = 9.99 mm: r = 13.6 mm) fits inside the film's diagonal. */
    lf_image img;
    const int W = 48;
    const double width = 35.0 / sqrt(2.0), pitch = width / W;
    if (flat_field("fisheye.10mm.dat", 6.08, W, W, 35.0, &img))
        return;
    double r_lit_max = 0, r_dark_min = INFINITY;
    int nonneg = 1;
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            double v = lf_image_px(&img, x, y)[1];
            double r = hypot((x + 0.5 - 0.5 * W) * pitch, (y + 0.5 - 0.5 * W) * pitch);
            nonneg &= v >= 0 && isfinite(v);
            if (v > 0 && r > r_lit_max)
                r_lit_max = r;
            if (v == 0 && r < r_dark_min)
                r_dark_min = r;
        }
    CHECK(nonneg);
    const double r_expect = 9.99 * (155.9 / 2) * M_PI / 180.0;
    /* The boundary is a circle: lit and dark pixels meet within ~2 pixels
     * (a pixel's half diagonal on each side), at f theta to 8%. */
    CHECK_MSG(r_dark_min > r_lit_max - 2.0 * pitch * M_SQRT2, "lit up to %.2f mm, dark from %.2f mm", r_lit_max,
              r_dark_min);
    CHECK_MSG(fabs(r_lit_max - r_expect) < 0.08 * r_expect, "image circle radius %.2f mm, f theta = %.2f mm",
              r_lit_max, r_expect);
    CHECK(lf_image_px(&img, 0, 0)[1] == 0.0f);      /* corners dark */
    CHECK(lf_image_px(&img, W / 2, W / 2)[1] > 0.0f); /* centre lit */
    lf_image_free(&img);
}

int main(void)
{
    test_focus();
    test_flat_field();
    test_fisheye_circle();
    return lf_test_end();
}
