/* pbrt-v4's "spherical" camera: every direction around the camera origin,
 * one image.
 *
 * The raster position is divided by the full film resolution, giving
 * (u, v) in [0,1]^2 with v = 0 at the top row, and mapped to a direction by
 * "string mapping":
 *   "equirectangular": theta = pi v (polar angle from +z), phi = 2 pi u, and
 *       direction (sin theta cos phi, sin theta sin phi, cos theta);
 *   "equalarea" (pbrt-v4's default): Clarke's octahedral equal-area map of
 *       the square onto the sphere (the layout of pbrt-v4's image infinite
 *       lights, so a render can be used as an environment map); the image
 *       must be square.
 * Then y and z are exchanged (pbrt-v4 does so that the "up" pole of the
 * parameterisation is camera +y): equirectangular, the top row looks along
 * camera +y, the bottom row along -y and the centre along -x; equal area,
 * the centre looks along +y and the four corners along -y.
 * Every ray starts at the camera origin with weight 1.
 *
 * pbrt-v4 also accepts and ignores the projective parameters (screenwindow,
 * frameaspectratio, lensradius, focaldistance); so does this camera. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "camera_internal.h"

typedef struct spherical {
    int equal_area;
    int width, height;
} spherical;

static int spherical_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    const char *m = p->get_string(p->ctx, "mapping", "equalarea");
    int equal_area;
    if (strcmp(m, "equalarea") == 0)
        equal_area = 1;
    else if (strcmp(m, "equirectangular") == 0)
        equal_area = 0;
    else {
        snprintf(a->error, a->error_size,
                 "unknown \"mapping\" \"%s\" for the spherical camera: must be \"equalarea\" or \"equirectangular\"", m);
        return -1;
    }
    if (equal_area && a->image_width != a->image_height) {
        snprintf(a->error, a->error_size,
                 "the spherical camera's \"equalarea\" mapping needs a square image, got %d x %d "
                 "(use \"string mapping\" \"equirectangular\" for a 2:1 panorama)",
                 a->image_width, a->image_height);
        return -1;
    }
    /* Accepted and ignored, as pbrt-v4 does. */
    double sw[4];
    (void)p->get_floats(p->ctx, "screenwindow", sw, 4);
    (void)p->get_float(p->ctx, "frameaspectratio", 1.0);
    (void)p->get_float(p->ctx, "lensradius", 0.0);
    (void)p->get_float(p->ctx, "focaldistance", 1e6);
    spherical *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->equal_area = equal_area;
    c->width = a->image_width;
    c->height = a->image_height;
    *state = c;
    return 0;
}

static uint32_t spherical_needs(const void *state)
{
    (void)state;
    return 0u;
}

/* Clarke's equal-area octahedral map of [0,1]^2 onto the unit sphere: the
 * square's diamond |x| + |y| <= 1 (x, y in [-1,1]) is the z >= 0
 * hemisphere, the corners fold onto z < 0; the distance r = 1 - |1 - |x| -
 * |y|| from the nearest pole sets z = +-(1 - r^2), and the position along
 * the diamond's edge sets the azimuth within the quadrant. */
static void equal_area_dir(double u, double v, double *d)
{
    /* Wrap positions outside the square (filter tails at the border) the
     * way pbrt-v4's WrapEqualAreaSquare does: across an edge the map
     * continues mirrored. */
    if (u < 0) {
        u = -u;
        v = 1 - v;
    } else if (u > 1) {
        u = 2 - u;
        v = 1 - v;
    }
    if (v < 0) {
        u = 1 - u;
        v = -v;
    } else if (v > 1) {
        u = 1 - u;
        v = 2 - v;
    }
    double x = 2 * u - 1, y = 2 * v - 1;
    double ax = fabs(x), ay = fabs(y);
    double sd = 1 - (ax + ay);
    double r = 1 - fabs(sd);
    double phi = (r == 0 ? 1 : (ay - ax) / r + 1) * (M_PI / 4);
    double z = copysign(1 - r * r, sd);
    double s = r * sqrt(fmax(0.0, 2 - r * r));
    d[0] = copysign(cos(phi), x) * s;
    d[1] = copysign(sin(phi), y) * s;
    d[2] = z;
}

static double spherical_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const spherical *c = state;
    double u = s->film_x / c->width, v = s->film_y / c->height, d[3];
    if (c->equal_area) {
        equal_area_dir(u, v, d);
    } else {
        double theta = M_PI * v, phi = 2 * M_PI * u;
        double st = sin(theta);
        d[0] = st * cos(phi), d[1] = st * sin(phi), d[2] = cos(theta);
    }
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    r->origin[0] = r->origin[1] = r->origin[2] = 0.0;
    /* pbrt-v4 swaps y and z after the mapping. */
    r->dir[0] = d[0] / len, r->dir[1] = d[2] / len, r->dir[2] = d[1] / len;
    return 1.0;
}

static void spherical_destroy(void *state) { free(state); }

static int spherical_describe(const void *state, char *buf, size_t size)
{
    const spherical *c = state;
    int n = 0;
    if (c->equal_area)
        LF_CAM_APPEND("model: spherical, equal-area octahedral mapping (Clarke; pbrt-v4's \"equalarea\"), "
                      "every pixel the same solid angle 4 pi / %d sr\n",
                      c->width * c->height);
    else
        LF_CAM_APPEND("model: spherical, equirectangular mapping: %g deg of azimuth per pixel column, "
                      "%g deg of polar angle per row, top row towards camera +y\n",
                      360.0 / c->width, 180.0 / c->height);
    LF_CAM_APPEND("defocus: none (every ray leaves the camera origin)\n");
    return n;
}

static void spherical_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const spherical *c = state;
    sink->set_string(sink->ctx, LF_KEY_PROJECTION, c->equal_area ? "equalarea" : "equirectangular");
}

const lf_camera_type lf_camera_spherical = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "spherical",
    .create = spherical_create,
    .needs = spherical_needs,
    .generate_ray = spherical_generate_ray,
    .generate_rays = NULL, /* the host loops over generate_ray (a few sin/cos per ray) */
    .destroy = spherical_destroy,
    .describe = spherical_describe,
    .metadata = spherical_metadata,
};
