/* The spherical camera through the renderer: a small emitter placed in a
 * known world direction (camera frame = world frame by LookAt) lands at the
 * pixel the inverse of pbrt-v4's mapping gives, computed here from the
 * definitions: with the mapping's direction d = (w.x, w.z, w.y) (pbrt-v4
 * swaps y and z), equirectangular u = atan2(d.y, d.x) / 2 pi (in [0,1)),
 * v = acos(d.z) / pi; equal area: Clarke's sphere-to-square of d.  The
 * emitter's image centroid must be within 0.3 px of it. */
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

static void equal_area_inverse(const double d[3], double *u, double *v)
{
    double r = sqrt(fmax(0.0, 1 - fabs(d[2])));
    double phi = atan2(fabs(d[1]), fabs(d[0]));
    double b = r * phi / (M_PI / 2), a = r - b;
    if (d[2] < 0) {
        double t = a;
        a = 1 - b;
        b = 1 - t;
    }
    *u = (copysign(a, d[0]) + 1) / 2;
    *v = (copysign(b, d[1]) + 1) / 2;
}

static void check(const char *mapping, int W, int H, const double w0[3])
{
    double len = sqrt(w0[0] * w0[0] + w0[1] * w0[1] + w0[2] * w0[2]);
    double w[3] = {w0[0] / len, w0[1] / len, w0[2] / len};
    const double dist = 10, rad = 0.12;
    char scene[2048];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 0  0 0 1  0 1 0\n"
             "Camera \"spherical\" \"string mapping\" \"%s\"\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d]\n"
             "Sampler \"halton\" \"integer pixelsamples\" [16]\nPixelFilter \"box\"\n"
             "Integrator \"volpath\" \"integer maxdepth\" [1]\nWorldBegin\n"
             "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
             "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
             "Translate %.17g %.17g %.17g\nShape \"sphere\" \"float radius\" [%g]\nAttributeEnd\n",
             mapping, W, H, w[0] * dist, w[1] * dist, w[2] * dist, rad);
    lf_image img = {0};
    char msg[1024] = "";
    int rc = render_text(scene, NULL, &img, msg, sizeof msg);
    CHECK_MSG(rc == 0, "%s", msg);
    if (rc)
        return;
    double d[3] = {w[0], w[2], w[1]}, u, v;
    if (!strcmp(mapping, "equirectangular")) {
        double phi = atan2(d[1], d[0]);
        if (phi < 0)
            phi += 2 * M_PI;
        u = phi / (2 * M_PI);
        v = acos(d[2]) / M_PI;
    } else {
        equal_area_inverse(d, &u, &v);
    }
    double sx = 0, sy = 0, s = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double e = lf_image_px(&img, x, y)[1];
            sx += e * (x + 0.5), sy += e * (y + 0.5), s += e;
        }
    CHECK_MSG(s > 0, "%s: the emitter is not in the image", mapping);
    if (s > 0) {
        double cx = sx / s, cy = sy / s;
        CHECK_MSG(hypot(cx - u * W, cy - v * H) < 0.3, "%s %dx%d dir (%g %g %g): centroid (%g, %g), expected (%g, %g)",
                  mapping, W, H, w[0], w[1], w[2], cx, cy, u * W, v * H);
    }
    lf_image_free(&img);
}

int main(void)
{
    /* away from the image seams, the poles and the equal-area diagonals'
     * folds, so the emitter's image is one compact blob */
    static const double dirs[][3] = {{0.3, 0.2, 1}, {-1, 0.3, 0.4}, {0.5, -0.6, -0.7}, {1, 0.1, -0.3}};
    for (int i = 0; i < 4; i++) {
        check("equirectangular", 256, 128, dirs[i]);
        check("equalarea", 192, 192, dirs[i]);
    }
    return lf_test_end();
}
