/* test_render_material_scenes.c - the example scenes of issue 30's materials
 * and textures (scenes/pbrt-v4/{textures,measured,hair,subsurface,normalmap}.pbrt)
 * parse, build with every parameter used and nothing refused or warned
 * about, and render to finite, lit images.  Each scene's subject is checked
 * by a number the scene predicts: see the per-scene comments. */
#include "render/lf_render.h"

#include "lf_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Renders path with spp samples; returns the image (caller frees) or a
 * failed check. */
static int render_file(const char *path, int spp, lf_image *img)
{
    lf_scene_desc d;
    lf_error err = {0};
    memset(img, 0, sizeof *img);
    if (lf_scene_parse_file(path, &d, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return -1;
    }
    CHECK_MSG(d.warnings == NULL, "%s: parser warnings:\n%s", path, d.warnings);
    lf_render_opts o = lf_render_opts_default();
    o.threads = 2;
    o.spp = spp;
    lf_renderer *r = NULL;
    int rc = lf_renderer_create(&d, &o, &r, &err);
    CHECK_MSG(rc == 0, "%s: %s", path, err.msg);
    if (!rc) {
        const char *w = lf_renderer_warnings(r);
        CHECK_MSG(w == NULL, "%s: warnings:\n%s", path, w);
        rc = lf_renderer_render(r, img, NULL, &err);
        CHECK_MSG(rc == 0, "%s: %s", path, err.msg);
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    return rc;
}

/* Mean of channel c over the pixel box [x0, x1) x [y0, y1); counts non-finite pixels. */
static double box_mean(const lf_image *img, int c, int x0, int x1, int y0, int y1, int *bad)
{
    double s = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            float v = lf_image_px(img, x, y)[c];
            if (!isfinite(v))
                (*bad)++;
            else
                s += v;
        }
    return s / ((double)(x1 - x0) * (y1 - y0));
}

/* textures.pbrt: seven spheres; each texture must vary across its sphere
 * (a texture that fell back to a constant would not), and the directionmix
 * sphere is redder at its top (normal along "dir" = +y: tex1, red) than at
 * its side (tex2, blue). */
static void test_textures_scene(void)
{
    lf_image img;
    if (render_file(LF_SOURCE_DIR "/scenes/pbrt-v4/textures.pbrt", 8, &img))
        return;
    int bad = 0;
    double all = box_mean(&img, 1, 0, img.width, 0, img.height, &bad);
    CHECK_MSG(bad == 0 && all > 0.05, "mean %g, %d non-finite pixels", all, bad);
    /* directionmix sphere: centre (1.2, -0.15, 0) at distance 7, fov 32 on
     * the 240-pixel height: pixel (271.8, 152.9), radius 29.9 px.  Near its
     * top the normal is close to +y (tex1, red), near its right edge to +x
     * (tex2, blue). */
    double top_r = box_mean(&img, 0, 268, 276, 126, 130, &bad);
    double top_b = box_mean(&img, 2, 268, 276, 126, 130, &bad);
    double side_r = box_mean(&img, 0, 294, 299, 150, 156, &bad);
    double side_b = box_mean(&img, 2, 294, 299, 150, 156, &bad);
    CHECK_MSG(top_r > 2 * top_b && side_b > 2 * side_r, "directionmix: top r %g b %g, side r %g b %g", top_r, top_b, side_r,
              side_b);
    lf_image_free(&img);
}

/* measured.pbrt: the measured gold (a GGX conductor tabulated in the
 * file) beside pbrt's analytic rough conductor of a similar colour: both
 * spheres gold (red above blue), of similar brightness (within 25 %: the
 * Fresnel curves differ). */
static void test_measured_scene(void)
{
    lf_image img;
    if (render_file(LF_SOURCE_DIR "/scenes/pbrt-v4/measured.pbrt", 16, &img))
        return;
    int bad = 0;
    double lr = box_mean(&img, 0, 95, 120, 85, 110, &bad), lb = box_mean(&img, 2, 95, 120, 85, 110, &bad);
    double rr = box_mean(&img, 0, 200, 225, 85, 110, &bad), rb = box_mean(&img, 2, 200, 225, 85, 110, &bad);
    CHECK_MSG(bad == 0 && lr > 1.2 * lb && rr > 1.2 * rb && fabs(lr / rr - 1) < 0.25,
              "measured r %g b %g, conductor r %g b %g, %d non-finite", lr, lb, rr, rb, bad);
    lf_image_free(&img);
}

/* hair.pbrt: three tufts; the eumelanin one is brown (red above blue), the
 * sigma_a (0.6, 2.8, 3.5) one red (red well above green), the blonde
 * reflectance one brighter than the brown one. */
static void test_hair_scene(void)
{
    lf_image img;
    if (render_file(LF_SOURCE_DIR "/scenes/pbrt-v4/hair.pbrt", 8, &img))
        return;
    int bad = 0;
    double m[3][3];
    const int cx[3] = {90, 180, 270};
    for (int t = 0; t < 3; t++)
        for (int c = 0; c < 3; c++)
            m[t][c] = box_mean(&img, c, cx[t] - 25, cx[t] + 25, 95, 140, &bad);
    CHECK_MSG(bad == 0 && m[0][0] > 1.15 * m[0][2] && m[2][0] > 1.3 * m[2][1] && m[1][1] > m[0][1],
              "brown %g %g %g, blonde %g %g %g, red %g %g %g, %d non-finite", m[0][0], m[0][1], m[0][2], m[1][0],
              m[1][1], m[1][2], m[2][0], m[2][1], m[2][2], bad);
    lf_image_free(&img);
}

/* subsurface.pbrt: skin (Skin1) is red above blue, ketchup red far above
 * green, and the back-lit 1 mm slab passes light (brighter than the grey
 * wall behind the spheres would be without it: above the sky's 0.15). */
static void test_subsurface_scene(void)
{
    lf_image img;
    if (render_file(LF_SOURCE_DIR "/scenes/pbrt-v4/subsurface.pbrt", 8, &img))
        return;
    int bad = 0;
    double skin_r = box_mean(&img, 0, 63, 83, 90, 110, &bad), skin_b = box_mean(&img, 2, 63, 83, 90, 110, &bad);
    double ket_r = box_mean(&img, 0, 150, 170, 90, 110, &bad), ket_g = box_mean(&img, 1, 150, 170, 90, 110, &bad);
    double slab = box_mean(&img, 1, 140, 180, 25, 45, &bad);
    printf("skin r %g b %g, ketchup r %g g %g, slab %g\n", skin_r, skin_b, ket_r, ket_g, slab);
    CHECK_MSG(bad == 0 && skin_r > 1.2 * skin_b && ket_r > 3 * ket_g && slab > 0.3,
              "skin r %g b %g, ketchup r %g g %g, slab %g, %d non-finite", skin_r, skin_b, ket_r, ket_g, slab, bad);
    lf_image_free(&img);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* normalmap.pbrt: under a distant light of irradiance pi at angle theta
 * (cos = 2.2 / |(-2, 2.2, 1)|) a plain diffuse square (albedo 0.5) has
 * radiance 0.5 cos theta everywhere.  The normal-mapped square's domes
 * (caps tilting up to asin(1 / 1.4) = 45.6 deg, about theta) reach close to
 * 0.5 facing the light and 0 facing away; the flat ground between them
 * (56 % of the area) stays at the plain value, so the median does.  Which
 * image half holds which square is found from the spread (the plain one
 * has none), not assumed. */
static void test_normalmap_scene(void)
{
    lf_image img;
    if (render_file(LF_SOURCE_DIR "/scenes/pbrt-v4/normalmap.pbrt", 4, &img))
        return;
    const double plain = 0.5 * 2.2 / sqrt(4 + 2.2 * 2.2 + 1);
    float *v[2];
    int n = 130 * 130, bad = 0;
    double lo[2], hi[2], med[2];
    for (int h = 0; h < 2; h++) {
        v[h] = malloc(sizeof(float) * (size_t)n);
        if (!v[h])
            return;
        int k = 0;
        for (int y = 15; y < 145; y++)
            for (int x = 0; x < 130; x++) {
                float g = lf_image_px(&img, (h ? 175 : 15) + x, y)[1];
                bad += !isfinite(g);
                v[h][k++] = g;
            }
        qsort(v[h], (size_t)n, sizeof(float), cmp_float);
        lo[h] = v[h][0], hi[h] = v[h][n - 1], med[h] = v[h][n / 2];
        free(v[h]);
    }
    int m = hi[1] - lo[1] > hi[0] - lo[0]; /* the mapped half */
    printf("normalmap: plain %g..%g, mapped %g..%g median %g, want plain %g\n", lo[1 - m], hi[1 - m], lo[m], hi[m],
           med[m], plain);
    CHECK_MSG(bad == 0, "%d non-finite pixels", bad);
    CHECK_MSG(fabs(lo[1 - m] / plain - 1) < 0.01 && fabs(hi[1 - m] / plain - 1) < 0.01, "plain square %g..%g, want %g",
              lo[1 - m], hi[1 - m], plain);
    CHECK_MSG(fabs(med[m] / plain - 1) < 0.02, "mapped square's median %g, want %g", med[m], plain);
    CHECK_MSG(hi[m] > 1.3 * plain && lo[m] < 0.3 * plain, "mapped square %g..%g, want beyond %g..%g", lo[m], hi[m],
              0.3 * plain, 1.3 * plain);
    lf_image_free(&img);
}

int main(void)
{
    test_normalmap_scene();
    test_subsurface_scene();
    test_textures_scene();
    test_measured_scene();
    test_hair_scene();
    return lf_test_end();
}
