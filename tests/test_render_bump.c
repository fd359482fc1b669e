/* Bump mapping ("float displacement", pbrt-v4's BumpMap) against geometry:
 *   - a plane z = 0, (u,v) = ((x+1)/2, (y+1)/2) (dp/du = (2,0,0)), displaced
 *     by the linear ramp d = k u: the bumped surface p + d n has tangent
 *     dp/du + k n, so its normal tilts by atan(k / |dp/du|) towards -x.  A
 *     diffuse plane (albedo 0.5) under a distant light of irradiance pi
 *     from direction l, direct light only, has radiance 0.5 cos(n', l):
 *     checked for l along the expected tilted normal (0.5) and mirrored
 *     (0.5 cos 2 tilt), within 0.2 % (the render is deterministic: one
 *     delta light, one bounce);
 *   - zero displacement (constant, or a texture that is 0) leaves the
 *     shading unchanged: the same image as without displacement, on a
 *     plane, on a sphere and on a mesh with tilted vertex normals;
 *   - the material unit: lf_bump_shading with a ramp gives the analytic
 *     normal for arbitrary tangent lengths. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"
#include "shading/lf_shading.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double mean_g(const lf_image *img)
{
    double m = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            m += lf_image_px(img, x, y)[1];
    return m / ((double)img->width * img->height);
}

/* The plane seen from +z by an orthographic camera, lit from direction l. */
static double render_plane(const char *material, const double l[3], char *msg, size_t n)
{
    char scene[4096];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 5  0 0 0  0 1 0\n"
             "Camera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
             "Film \"rgb\" \"integer xresolution\" [8] \"integer yresolution\" [8]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [4]\n"
             "Integrator \"volpath\" \"integer maxdepth\" [1]\n"
             "PixelFilter \"box\"\nWorldBegin\n"
             "LightSource \"distant\" \"point3 from\" [%.17g %.17g %.17g] \"point3 to\" [0 0 0] \"rgb L\" [%.17g "
             "%.17g %.17g]\n"
             "Texture \"ramp\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" %.17g \"float v11\" "
             "%.17g\n"
             "Texture \"zero\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" 0 \"float v11\" 0\n"
             "%s\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
             "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n",
             l[0], l[1], l[2], M_PI, M_PI, M_PI, 2 * tan(30 * M_PI / 180), 2 * tan(30 * M_PI / 180), material);
    lf_image img = {0};
    if (render_text(scene, NULL, &img, msg, n))
        return -1;
    double v = mean_g(&img);
    lf_image_free(&img);
    return v;
}

static void test_ramp(void)
{
    char msg[1024] = "";
    /* k = 2 tan 30 deg over |dp/du| = 2: the normal tilts 30 degrees
     * towards -x: n' = (-sin 30, 0, cos 30). */
    const double t = 30 * M_PI / 180;
    double along[3] = {-sin(t), 0, cos(t)}, mirrored[3] = {sin(t), 0, cos(t)}, up[3] = {0, 0, 1};
    const char *bumped = "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"texture displacement\" \"ramp\"";
    double a = render_plane(bumped, along, msg, sizeof msg);
    CHECK_MSG(a >= 0, "%s", msg);
    CHECK_MSG(fabs(a / 0.5 - 1) < 0.002, "light along the tilted normal: %g, want 0.5", a);
    double b = render_plane(bumped, mirrored, msg, sizeof msg);
    CHECK_MSG(fabs(b / (0.5 * cos(2 * t)) - 1) < 0.002, "light mirrored: %g, want %g", b, 0.5 * cos(2 * t));
    double c = render_plane(bumped, up, msg, sizeof msg);
    CHECK_MSG(fabs(c / (0.5 * cos(t)) - 1) < 0.002, "light along the geometric normal: %g, want %g", c,
              0.5 * cos(t));
    /* zero displacement: unchanged */
    const char *plain = "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]";
    const char *zero_c = "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"float displacement\" 0";
    const char *zero_t = "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"texture displacement\" \"zero\"";
    double p = render_plane(plain, mirrored, msg, sizeof msg);
    CHECK_NEAR(p, 0.5 * cos(t), 1e-3);
    CHECK_NEAR(render_plane(zero_c, mirrored, msg, sizeof msg), p, 1e-6);
    CHECK_NEAR(render_plane(zero_t, mirrored, msg, sizeof msg), p, 1e-6);
}

/* A sphere and a mesh with tilted vertex normals: zero displacement renders
 * the same image as none. */
static void test_zero_curved(void)
{
    static const char *shapes[] = {
        "Shape \"sphere\" \"float radius\" 1\n",
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
        "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n"
        "  \"normal N\" [-0.3 -0.2 1  0.4 -0.1 1  0.2 0.3 1  -0.1 0.25 1]\n"};
    static const char *mats[] = {"Material \"diffuse\" \"rgb reflectance\" [0.6 0.6 0.6]",
                                 "Material \"diffuse\" \"rgb reflectance\" [0.6 0.6 0.6] \"float displacement\" 0"};
    for (int s = 0; s < 2; s++) {
        lf_image img[2] = {{0}, {0}};
        for (int m = 0; m < 2; m++) {
            char scene[4096], msg[1024] = "";
            snprintf(scene, sizeof scene,
                     "LookAt 0.3 0.2 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
                     "Film \"rgb\" \"integer xresolution\" [24] \"integer yresolution\" [24]\n"
                     "Sampler \"independent\" \"integer pixelsamples\" [4]\n"
                     "Integrator \"volpath\" \"integer maxdepth\" [1]\nPixelFilter \"box\"\nWorldBegin\n"
                     "LightSource \"distant\" \"point3 from\" [1 2 3] \"point3 to\" [0 0 0]\n%s\n%s",
                     mats[m], shapes[s]);
            int rc = render_text(scene, NULL, &img[m], msg, sizeof msg);
            CHECK_MSG(rc == 0, "%s", msg);
        }
        double worst = 0;
        if (img[0].data && img[1].data)
            for (int i = 0; i < 24 * 24 * img[0].channels; i++)
                worst = fmax(worst, fabs(img[0].data[i] - img[1].data[i]));
        CHECK_MSG(img[0].data && worst < 1e-4, "shape %d: zero displacement changes a pixel by %g", s, worst);
        lf_image_free(&img[0]);
        lf_image_free(&img[1]);
    }
}

/* lf_bump_shading directly: a ramp d = k u on a tangent frame with
 * |dp/du| = a and |dp/dv| = b gives n' = normalize(a b n - k b s_hat) ... i.e.
 * (dp/du + k n) x dp/dv normalised. */
static void test_unit(void)
{
    lf_scene_desc d;
    lf_error err = {0};
    const char *text = "WorldBegin\nTexture \"r\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 "
                       "\"float v10\" 0.7 \"float v11\" 0.7\n";
    CHECK(lf_scene_parse_string(text, "t.pbrt", &d, &err) == 0);
    lf_materials *mats = NULL;
    CHECK_MSG(lf_materials_build(&d, &mats, &err) == 0, "%s", err.msg);
    const lf_texture *tex = mats ? lf_materials_texture(mats, "r", 1) : NULL;
    CHECK(tex != NULL);
    if (tex) {
        lf_tex_input in = {tex, {0, 0, 0}};
        const double a = 3.0, b = 0.5, k = 0.7;
        lf_shading_ctx c = {0};
        c.p = lf_v3(0, 0, 0);
        c.ng = c.ns = lf_v3(0, 1, 0);
        c.dpdu = lf_v3(1, 0, 0);
        c.uv = (lf_vec2){0.25f, 0.5f};
        c.sdpdu = lf_v3((float)a, 0, 0);
        c.sdpdv = lf_v3(0, 0, (float)-b); /* u x v = +y */
        c.has_derivs = 1;
        lf_shading_ctx o;
        lf_bump_shading(&in, &c, &o);
        /* (a, k, 0) x (0, 0, -b) = (-k b, a b, 0) */
        double nx = -k * b, ny = a * b, len = hypot(nx, ny);
        CHECK_NEAR(o.ns.x, nx / len, 1e-4);
        CHECK_NEAR(o.ns.y, ny / len, 1e-4);
        CHECK_NEAR(o.ns.z, 0, 1e-6);
        c.has_derivs = 0; /* no derivatives: nothing changes */
        lf_bump_shading(&in, &c, &o);
        CHECK(o.ns.x == 0 && o.ns.y == 1 && o.ns.z == 0);
    }
    lf_materials_free(mats);
    lf_scene_desc_free(&d);
}

int main(void)
{
    test_ramp();
    test_zero_curved();
    test_unit();
    return lf_test_end();
}
