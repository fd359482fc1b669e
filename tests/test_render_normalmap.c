/* Normal maps ("string normalmap", pbrt-v4's NormalMap) against geometry.
 * The plane z = 0, (u,v) = ((x+1)/2, (y+1)/2), so dp/du = (2,0,0) and the
 * tangent frame is x = +x, y = ns x x = +y, z = +z; a diffuse plane
 * (albedo 0.5) under a distant light of radiance pi from direction l,
 * direct light only, has radiance 0.5 max(0, n'.l) with n' the map's
 * normal in world space.  The renders are deterministic (one delta light,
 * one bounce), so they are compared within 0.2 %.
 *   - a flat map (every texel (0.5, 0.5, 1), EXR) renders the plane, a
 *     sphere and a mesh with vertex normals exactly as without the map;
 *   - an 8-bit PNG with one texel code (R, G, B) tilts the normal to
 *     normalize(2 code / 255 - 1) (linear, not sRGB-decoded, as pbrt-v4
 *     reads normal maps), for three light directions;
 *   - a map whose four quadrants tilt differently gives each quadrant of
 *     the image its predicted brightness; where u and v grow on the image
 *     is found from renders of bilerp reflectance ramps, independently of
 *     the map (catches u or v flips in the lookup);
 *   - a tangent frame with dp/du along +y (the plane's uv turned): the map's
 *     x tilt follows dp/du;
 *   - a missing map file is an error naming file:line:col. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_render.h"
#include "shading/lf_shading.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define RES 16
static char dir[64] = "/tmp/lf_nmap_XXXXXX";

/* Writes a w x h RGB map whose texel (x, y) (row 0 at the top) is f(x, y). */
static void write_map(const char *path, int w, int h, void (*f)(int, int, int, int, float *))
{
    lf_image img = {0};
    lf_error err = {0};
    CHECK(lf_image_alloc(&img, w, h, 3, &err) == 0);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            f(x, y, w, h, lf_image_px(&img, x, y));
    CHECK_MSG(lf_image_write(path, &img, NULL, NULL, &err) == 0, "%s", err.msg);
    lf_image_free(&img);
}

static void flat_texel(int x, int y, int w, int h, float *p)
{
    (void)x, (void)y, (void)w, (void)h;
    p[0] = p[1] = 0.5f, p[2] = 1.f;
}

/* PNG codes: the writer sRGB-encodes, so store decode(code) to get code. */
static const unsigned char CODE[3] = {200, 128, 240};
static void code_texel(int x, int y, int w, int h, float *p)
{
    (void)x, (void)y, (void)w, (void)h;
    for (int c = 0; c < 3; c++)
        p[c] = lf_srgb_decode(CODE[c]);
}

/* Quadrants: tangent x tilt +A where u < 1/2 (image left), -A right;
 * tangent y tilt +B where v > 1/2 (image top rows, pbrt looks up 1 - v),
 * -B in the bottom rows. */
static const float A = 0.6f, B = 0.35f;
static void quad_texel(int x, int y, int w, int h, float *p)
{
    float tx = x < w / 2 ? A : -A, ty = y < h / 2 ? B : -B;
    p[0] = 0.5f * (tx + 1), p[1] = 0.5f * (ty + 1), p[2] = 1.f; /* z = 1 before normalising */
}

static int render_scene(const char *material, const char *shape, const double l[3], lf_image *img)
{
    char scene[4096], msg[1024] = "";
    snprintf(scene, sizeof scene,
             "LookAt 0 0 5  0 0 0  0 1 0\n"
             "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"independent\" \"integer pixelsamples\" [4]\n"
             "Integrator \"volpath\" \"integer maxdepth\" [1]\n"
             "PixelFilter \"box\"\nWorldBegin\n"
             "LightSource \"distant\" \"point3 from\" [%.17g %.17g %.17g] \"point3 to\" [0 0 0] \"rgb L\" [%.17g "
             "%.17g %.17g]\n"
             "Texture \"uramp\" \"spectrum\" \"bilerp\" \"rgb v00\" [0.2 0.2 0.2] \"rgb v01\" [0.2 0.2 0.2] "
             "\"rgb v10\" [0.8 0.8 0.8] \"rgb v11\" [0.8 0.8 0.8]\n"
             "Texture \"vramp\" \"spectrum\" \"bilerp\" \"rgb v00\" [0.2 0.2 0.2] \"rgb v10\" [0.2 0.2 0.2] "
             "\"rgb v01\" [0.8 0.8 0.8] \"rgb v11\" [0.8 0.8 0.8]\n"
             "%s\n%s",
             RES, RES, l[0], l[1], l[2], M_PI, M_PI, M_PI, material, shape);
    int rc = render_text(scene, NULL, img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    return rc;
}

static const char *PLANE = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
                           "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n";

/* Mean green over image pixels [x0, x1) x [y0, y1). */
static double region(const lf_image *img, int x0, int x1, int y0, int y1)
{
    double m = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            m += lf_image_px(img, x, y)[1];
    return m / ((double)(x1 - x0) * (y1 - y0));
}

static double expected(double nx, double ny, double nz, const double l[3])
{
    double nl = sqrt(nx * nx + ny * ny + nz * nz), ll = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    double c = (nx * l[0] + ny * l[1] + nz * l[2]) / (nl * ll);
    return 0.5 * fmax(0.0, c);
}

static void test_flat(void)
{
    char path[128], mat[512];
    snprintf(path, sizeof path, "%s/flat.exr", dir);
    write_map(path, 8, 8, flat_texel);
    static const char *shapes[] = {
        NULL, "Shape \"sphere\" \"float radius\" 0.9\n",
        "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
        "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1]\n"
        "  \"normal N\" [-0.3 -0.2 1  0.4 -0.1 1  0.2 0.3 1  -0.1 0.25 1]\n"};
    const double l[3] = {1, 2, 3};
    for (int s = 0; s < 3; s++) {
        lf_image a = {0}, b = {0};
        render_scene("Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]", shapes[s] ? shapes[s] : PLANE, l, &a);
        snprintf(mat, sizeof mat, "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"string normalmap\" \"%s\"",
                 path);
        render_scene(mat, shapes[s] ? shapes[s] : PLANE, l, &b);
        double worst = 0;
        if (a.data && b.data)
            for (int i = 0; i < RES * RES * a.channels; i++)
                worst = fmax(worst, fabs(a.data[i] - b.data[i]));
        CHECK_MSG(a.data && b.data && worst < 1e-5, "shape %d: a flat map changes a pixel by %g", s, worst);
        lf_image_free(&a);
        lf_image_free(&b);
    }
}

static void test_png_tilt(void)
{
    char path[128], mat[512];
    snprintf(path, sizeof path, "%s/tilt.png", dir);
    write_map(path, 4, 4, code_texel);
    snprintf(mat, sizeof mat, "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"string normalmap\" \"%s\"",
             path);
    double n[3];
    for (int c = 0; c < 3; c++)
        n[c] = 2.0 * CODE[c] / 255.0 - 1.0; /* linear codes */
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double lights[3][3] = {{n[0] / len, n[1] / len, n[2] / len}, {-0.4, 0.1, 1}, {0, 0, 1}};
    for (int k = 0; k < 3; k++) {
        lf_image img = {0};
        if (render_scene(mat, PLANE, lights[k], &img))
            continue;
        double got = region(&img, 0, RES, 0, RES), want = expected(n[0], n[1], n[2], lights[k]);
        CHECK_MSG(fabs(got / want - 1) < 0.002, "light %d: %g, want %g", k, got, want);
        /* sRGB-decoded codes would tilt far less: make sure the test can tell. */
        double s[3];
        for (int c = 0; c < 3; c++)
            s[c] = 2.0 * lf_srgb_decode(CODE[c]) - 1.0;
        if (k == 0)
            CHECK(fabs(expected(s[0], s[1], s[2], lights[k]) / want - 1) > 0.01);
        lf_image_free(&img);
    }
}

/* Which image half holds u > 1/2 (returns +1 if the right half, -1 if the
 * left) from a reflectance ramp; likewise v (+1: bottom half). */
static int ramp_side(const char *tex, int along_x)
{
    char mat[256];
    snprintf(mat, sizeof mat, "Material \"diffuse\" \"texture reflectance\" \"%s\"", tex);
    const double up[3] = {0, 0, 1};
    lf_image img = {0};
    if (render_scene(mat, PLANE, up, &img))
        return 0;
    double lo = along_x ? region(&img, 0, RES / 2, 0, RES) : region(&img, 0, RES, 0, RES / 2);
    double hi = along_x ? region(&img, RES / 2, RES, 0, RES) : region(&img, 0, RES, RES / 2, RES);
    lf_image_free(&img);
    CHECK(fabs(hi - lo) > 0.05);
    return hi > lo ? 1 : -1;
}

static void test_quadrants(void)
{
    char path[128], mat[512];
    snprintf(path, sizeof path, "%s/quad.exr", dir);
    write_map(path, RES, RES, quad_texel);
    int ux = ramp_side("uramp", 1), vy = ramp_side("vramp", 0);
    CHECK(ux != 0 && vy != 0);
    snprintf(mat, sizeof mat, "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"string normalmap\" \"%s\"",
             path);
    const double l[3] = {0.5, 0.3, 1};
    lf_image img = {0};
    if (render_scene(mat, PLANE, l, &img) || !ux || !vy)
        return;
    for (int uh = 0; uh < 2; uh++)     /* 0: u < 1/2 */
        for (int vh = 0; vh < 2; vh++) { /* 0: v < 1/2 */
            /* Image columns/rows of that quadrant, 2 pixels clear of the
             * blends at the quadrant edges and the repeat wrap. */
            int right = (uh == 1) == (ux > 0), bottom = (vh == 1) == (vy > 0);
            int x0 = right ? RES / 2 + 2 : 2, y0 = bottom ? RES / 2 + 2 : 2;
            double got = region(&img, x0, x0 + RES / 2 - 4, y0, y0 + RES / 2 - 4);
            double tx = uh == 0 ? A : -A, ty = vh == 1 ? B : -B;
            double want = expected(tx, ty, 1, l);
            CHECK_MSG(fabs(got / want - 1) < 0.002, "quadrant u%d v%d: %g, want %g", uh, vh, got, want);
        }
    lf_image_free(&img);
}

/* The plane's uv turned: u grows along +y, v along +x, so dp/du = (0,2,0),
 * y = ns x dp/du = (-1,0,0) (ns = +z: the winding is unchanged).  The
 * map's tangent tilt (A, B) is world (-B, A, 1). */
static void test_turned_frame(void)
{
    char path[128], mat[512];
    snprintf(path, sizeof path, "%s/const.exr", dir);
    write_map(path, 4, 4, code_texel); /* any constant: the EXR stores decode(CODE) */
    double t[3];
    for (int c = 0; c < 3; c++)
        t[c] = 2.0 * lf_srgb_decode(CODE[c]) - 1.0; /* EXR: linear floats as stored */
    snprintf(mat, sizeof mat, "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5] \"string normalmap\" \"%s\"",
             path);
    const char *turned = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n"
                         "  \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"point2 uv\" [0 0 0 1 1 1 1 0]\n";
    const double lights[2][3] = {{0.3, 0.6, 1}, {-0.5, -0.2, 1}};
    for (int k = 0; k < 2; k++) {
        lf_image img = {0};
        if (render_scene(mat, turned, lights[k], &img))
            continue;
        double got = region(&img, 0, RES, 0, RES), want = expected(-t[1], t[0], t[2], lights[k]);
        CHECK_MSG(fabs(got / want - 1) < 0.002, "turned frame, light %d: %g, want %g", k, got, want);
        lf_image_free(&img);
    }
}

static void test_missing(void)
{
    char msg[1024] = "";
    const char *scene = "Camera \"orthographic\"\nFilm \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4]\n"
                        "WorldBegin\n"
                        "Material \"diffuse\" \"string normalmap\" \"no-such-map.png\"\n"
                        "Shape \"sphere\"\n";
    lf_image img = {0};
    int rc = render_text(scene, &(lf_test_scene){.name = "nm.pbrt"}, &img, msg, sizeof msg);
    CHECK(rc != 0);
    CHECK_MSG(strstr(msg, "nm.pbrt:4:") && strstr(msg, "normalmap") && strstr(msg, "no-such-map.png"), "%s", msg);
    lf_image_free(&img);
}

int main(void)
{
    CHECK(mkdtemp(dir) != NULL);
    test_flat();
    test_png_tilt();
    test_quadrants();
    test_turned_frame();
    test_missing();
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
