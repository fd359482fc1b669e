/* Homogeneous participating media against physics (render/media.c):
 *   - an absorbing slab of thickness d in front of a uniform sky transmits
 *     exp(-sigma_a d) per channel (within 1 %; deterministic);
 *   - a slab with scattering seen against black, lit by a distant light at
 *     40 degrees with maxdepth 1 (single scattering only), shows the
 *     single-scattering integral
 *         L = int_0^d sigma_s p_HG(Theta) E exp(-sigma_t z / cos th) exp(-sigma_t z) dz,
 *     evaluated here by quadrature (Theta: the angle between the light's
 *     travel and the scattered direction, textbook HG form);
 *   - furnace: a sphere of non-absorbing medium (albedo 1, chromatic
 *     sigma_s, g = 0.6) inside a uniform sky of radiance 1 looks exactly like
 *     the sky (energy conservation);
 *   - a camera inside a medium (the MediumInterface current at Camera) sees
 *     an emitter at distance D dimmed by exp(-sigma_t D), with the medium's
 *     own emission sigma_a Le (1 - exp(-sigma_t D)) / sigma_t added;
 *   - a nanovdb medium whose file is missing is an error naming file:line:column and the file;
 *     media nobody can enter leave the surface integrator in charge;
 *     Integrator "path" ignores media with a warning (as pbrt-v4).
 * Monte Carlo margins are stated at each assertion; seeds are fixed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void mean_rgb(const lf_image *img, double m[3])
{
    m[0] = m[1] = m[2] = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            for (int c = 0; c < 3; c++)
                m[c] += lf_image_px(img, x, y)[c];
    for (int c = 0; c < 3; c++)
        m[c] /= (double)img->width * img->height;
}

/* A closed box [-w,w]^2 x [0,d] with outward-facing triangles, as a medium
 * boundary ("interface" material). */
static void box_shape(char *buf, size_t n, double w, double d)
{
    snprintf(buf, n,
             "Material \"interface\"\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 2 1 0 3 2  4 5 6 4 6 7  0 5 4 0 1 5  1 6 5 1 2 6  "
             "2 7 6 2 3 7  3 4 7 3 0 4]\n"
             "  \"point3 P\" [%g %g 0  %g %g 0  %g %g 0  %g %g 0  %g %g %g  %g %g %g  %g %g %g  %g %g %g]\n",
             -w, -w, w, -w, w, w, -w, w, -w, -w, d, w, -w, d, w, w, d, -w, w, d);
}

static void test_absorbing_slab(void)
{
    static const double thick[] = {1.0, 2.5};
    for (int k = 0; k < 2; k++) {
        double d = thick[k];
        char box[1024], scene[4096];
        box_shape(box, sizeof box, 3, d);
        snprintf(scene, sizeof scene,
                 "LookAt 0 0 -5  0 0 0  0 1 0\n"
                 "Camera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
                 "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
                 "Sampler \"independent\" \"integer pixelsamples\" [4] \"integer seed\" [3]\n"
                 "PixelFilter \"box\"\nWorldBegin\n"
                 "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                 "MakeNamedMedium \"ink\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.25 0.5 1] "
                 "\"rgb sigma_s\" [0 0 0] \"float scale\" 2\n"
                 "AttributeBegin\nMediumInterface \"ink\" \"\"\n%sAttributeEnd\n",
                 box);
        lf_image img = {0};
        char msg[1024] = "";
        int rc = render_text(scene, NULL, &img, msg, sizeof msg);
        CHECK_MSG(rc == 0, "%s", msg);
        if (rc)
            continue;
        double m[3];
        mean_rgb(&img, m);
        static const double sa[3] = {0.5, 1.0, 2.0}; /* sigma_a times scale */
        for (int c = 0; c < 3; c++) {
            double want = exp(-sa[c] * d);
            /* no randomness in a purely absorbing medium: 1 % is the acceptance bound */
            CHECK_MSG(fabs(m[c] / want - 1) < 0.01, "slab d=%g channel %d: %g, exp(-sigma_t d) = %g", d, c, m[c], want);
        }
        lf_image_free(&img);
    }
}

/* Textbook Henyey-Greenstein in the scattering angle Theta (between the
 * travel directions before and after). */
static double hg(double g, double cos_theta)
{
    return (1 - g * g) / (4 * M_PI * pow(1 + g * g - 2 * g * cos_theta, 1.5));
}

static void test_single_scattering(void)
{
    const double d = 1.0, th = 40 * M_PI / 180, g = 0.3;
    const double ss[3] = {0.3, 0.6, 0.3}, sa[3] = {0.1, 0.2, 0.6};
    char box[1024], scene[4096];
    box_shape(box, sizeof box, 50, d);
    /* The light travels along (0, -sin th, cos th): it enters through the
     * z = 0 face, on the camera's side. */
    snprintf(scene, sizeof scene,
             "LookAt 0 0 -5  0 0 0  0 1 0\n"
             "Camera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [256] \"integer seed\" [11]\n"
             "Integrator \"volpath\" \"integer maxdepth\" [1]\n"
             "PixelFilter \"box\"\nWorldBegin\n"
             "LightSource \"distant\" \"point3 from\" [0 %.17g %.17g] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n"
             "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [%g %g %g] "
             "\"rgb sigma_s\" [%g %g %g] \"float g\" %g\n"
             "AttributeBegin\nMediumInterface \"fog\" \"\"\n%sAttributeEnd\n",
             sin(th), -cos(th), sa[0], sa[1], sa[2], ss[0], ss[1], ss[2], g, box);
    lf_image img = {0};
    char msg[1024] = "";
    int rc = render_text(scene, NULL, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (rc)
        return;
    double m[3];
    mean_rgb(&img, m);
    /* Travel of the light (0, -sin, cos); scattered towards the camera (0, 0, -1). */
    double cos_theta = -cos(th);
    for (int c = 0; c < 3; c++) {
        double st = ss[c] + sa[c], sum = 0;
        int n = 20000;
        for (int i = 0; i < n; i++) {
            double z = (i + 0.5) * d / n;
            sum += ss[c] * hg(g, cos_theta) * exp(-st * z / cos(th)) * exp(-st * z) * (d / n);
        }
        /* 65536 paths; the per-path spread is about the mean, so 1 sigma is
         * ~0.5 %: 3 % is > 5 sigma. */
        CHECK_MSG(fabs(m[c] / sum - 1) < 0.03, "single scattering channel %d: rendered %g, quadrature %g", c, m[c],
                  sum);
    }
    lf_image_free(&img);
}

static void test_furnace(void)
{
    const char *scene = "LookAt 0 0 -5  0 0 0  0 1 0\n"
                        "Camera \"perspective\" \"float fov\" [20]\n"
                        "Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n"
                        "Sampler \"independent\" \"integer pixelsamples\" [512] \"integer seed\" [5]\n"
                        "Integrator \"volpath\" \"integer maxdepth\" [1000]\n"
                        "PixelFilter \"box\"\nWorldBegin\n"
                        "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                        "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0 0 0] "
                        "\"rgb sigma_s\" [0.5 1 2] \"float g\" 0.6\n"
                        "AttributeBegin\nMediumInterface \"fog\" \"\"\nMaterial \"interface\"\n"
                        "Shape \"sphere\" \"float radius\" 1\nAttributeEnd\n";
    lf_image img = {0};
    char msg[1024] = "";
    int rc = render_text(scene, NULL, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (rc)
        return;
    double m[3];
    mean_rgb(&img, m);
    /* 131072 paths; per-path standard deviation below 1 in every channel
     * (the channel weights sigma_s,c T_c / p(t) stay O(1)), so 1 sigma of
     * the mean is < 0.003: 1.5 % is > 5 sigma. */
    for (int c = 0; c < 3; c++)
        CHECK_MSG(fabs(m[c] - 1) < 0.015, "furnace channel %d: %g, want 1", c, m[c]);
    lf_image_free(&img);
}

static void test_camera_medium(void)
{
    /* Fog everywhere: the camera is declared inside it.  An emitting quad
     * at distance D = 4 fills the view. */
    const char *scene = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.2 0.3] "
                        "\"rgb sigma_s\" [0 0 0] \"rgb Le\" [0.5 0.5 0.5] \"float Lescale\" 2\n"
                        "MediumInterface \"\" \"fog\"\n"
                        "LookAt 0 0 -4  0 0 0  0 1 0\n"
                        "Camera \"perspective\" \"float fov\" [10]\n"
                        "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
                        "Sampler \"independent\" \"integer pixelsamples\" [4]\n"
                        "PixelFilter \"box\"\nWorldBegin\n"
                        "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\n"
                        "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
                        "Shape \"bilinearmesh\" \"point3 P\" [-5 -5 0  -5 5 0  5 -5 0  5 5 0]\n"
                        "AttributeEnd\n";
    lf_image img = {0};
    char msg[1024] = "";
    int rc = render_text(scene, NULL, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (rc)
        return;
    static const double sa[3] = {0.1, 0.2, 0.3};
    /* Every pixel: the rays travel 4 / cos(angle) <= 4.02 (fov 10 deg); check the centre 2x2. */
    for (int c = 0; c < 3; c++) {
        double v = 0;
        for (int y = 3; y < 5; y++)
            for (int x = 3; x < 5; x++)
                v += lf_image_px(&img, x, y)[c] / 4;
        double D = 4.0, T = exp(-sa[c] * D);
        double want = 2 * T + 1.0 * (1 - T); /* emitter through the fog + sigma_a Le (1-T)/sigma_t, Le = 1 */
        /* off-axis rays in the centre pixels are < 0.05 % longer */
        CHECK_MSG(fabs(v / want - 1) < 0.002, "camera in fog, channel %d: %g, want %g", c, v, want);
    }
    lf_image_free(&img);
}

static void test_refusals(void)
{
    /* nanovdb without its file: an error naming the file (grid media,
     * nanovdb included, are tested in test_render_pbrt_v4.c) */
    const char *nvdb = "WorldBegin\n"
                       "  MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"x.nvdb\"\n"
                       "MediumInterface \"smoke\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\n";
    {
        char msg[1024] = "";
        int rc = render_text(nvdb, NULL, NULL, msg, sizeof msg);
        CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:3: MakeNamedMedium") && strstr(msg, "x.nvdb"), "nanovdb: rc %d: %s",
                  rc, msg);
    }
    /* a grid without its grid is an error, as in pbrt-v4 */
    static const char *types[] = {"uniformgrid", "rgbgrid"};
    for (int i = 0; i < 2; i++) {
        char scene[1024];
        snprintf(scene, sizeof scene,
                 "WorldBegin\n"
                 "  MakeNamedMedium \"smoke\" \"string type\" \"%s\"\n"
                 "MediumInterface \"smoke\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\n",
                 types[i]);
        char msg[1024] = "";
        int rc = render_text(scene, NULL, NULL, msg, sizeof msg);
        CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:2:3: MakeNamedMedium") && strstr(msg, types[i] == types[0] ? "density" : "sigma_a"),
                  "%s: rc %d: %s", types[i], rc, msg);
    }
    char msg[1024] = "";
    int rc = render_text("WorldBegin\nMediumInterface \"nowhere\" \"\"\nShape \"sphere\"\n", NULL, NULL, msg,
                         sizeof msg);
    CHECK_MSG(rc != 0 && strstr(msg, "test.pbrt:3:1:") && strstr(msg, "nowhere"), "%s", msg);
}

/* Media no ray can enter cost nothing: the surface integrator runs. */
static void test_fast_path(void)
{
    char *ex = NULL, msg[1024] = "";
    int rc = render_text("WorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                         "Shape \"sphere\"\n", &(lf_test_scene){.explain = &ex}, NULL, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    CHECK_MSG(ex && !strstr(ex, "volumetric"), "%s", ex ? ex : "");
    free(ex);
    ex = NULL;
    rc = render_text("WorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                     "MediumInterface \"fog\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\n",
                     &(lf_test_scene){.explain = &ex}, NULL, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    CHECK_MSG(ex && strstr(ex, "volumetric"), "%s", ex ? ex : "");
    free(ex);
    /* "path" ignores media as pbrt-v4's PathIntegrator, and says so */
    lf_scene_desc d;
    lf_error err = {0};
    const char *text = "Integrator \"path\"\nWorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                       "MediumInterface \"fog\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\n";
    CHECK(lf_scene_parse_string(text, "test.pbrt", &d, &err) == 0);
    lf_render_opts o = lf_render_opts_default();
    lf_renderer *r = NULL;
    CHECK_MSG(lf_renderer_create(&d, &o, &r, &err) == 0, "%s", err.msg);
    const char *w = r ? lf_renderer_warnings(r) : NULL;
    CHECK_MSG(w && strstr(w, "test.pbrt:1:1") && strstr(w, "ignores participating media"), "%s", w ? w : "");
    lf_renderer_free(r);
    lf_scene_desc_free(&d);
}

int main(void)
{
    test_absorbing_slab();
    test_single_scattering();
    test_furnace();
    test_camera_medium();
    test_refusals();
    test_fast_path();
    return lf_test_end();
}
