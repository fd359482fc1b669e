/* An example camera plugin: an equirectangular (latitude-longitude)
 * panorama, as pbrt's "spherical" camera with "mapping" "equirect".
 * It needs nothing from lensfield but camera/lf_camera.h:
 *
 *   cc -shared -fPIC -I camera example_camera.c -o libexample_camera.so
 *   lfrender --camera-plugin ./libexample_camera.so scene.pbrt
 *
 * with `Camera "panorama" "float hfov" [360]` in the scene. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lf_camera.h"

#ifndef M_PI /* strict ISO C does not define it */
#define M_PI 3.14159265358979323846
#endif

typedef struct panorama {
    int width, height;
    double hfov_rad, vfov_rad;
} panorama;

static int pano_create(const lf_camera_create_args *a, void **state)
{
    panorama *p = malloc(sizeof *p);
    if (!p) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    p->width = a->image_width;
    p->height = a->image_height;
    double hfov = a->params->get_float(a->params->ctx, "hfov", 360.0);
    double vfov = a->params->get_float(a->params->ctx, "vfov", 180.0);
    if (!(hfov > 0 && hfov <= 360 && vfov > 0 && vfov <= 180)) {
        snprintf(a->error, a->error_size, "need 0 < hfov <= 360 and 0 < vfov <= 180, got %g and %g", hfov, vfov);
        free(p);
        return -1;
    }
    p->hfov_rad = hfov * M_PI / 180;
    p->vfov_rad = vfov * M_PI / 180;
    *state = p;
    return 0;
}

static uint32_t pano_needs(const void *state)
{
    (void)state;
    return 0;
}

static double pano_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const panorama *p = state;
    /* longitude grows to the right, latitude upwards; the image centre looks along +z */
    double lon = (s->film_x / p->width - 0.5) * p->hfov_rad;
    double lat = (0.5 - s->film_y / p->height) * p->vfov_rad;
    r->origin[0] = r->origin[1] = r->origin[2] = 0;
    r->dir[0] = cos(lat) * sin(lon);
    r->dir[1] = sin(lat);
    r->dir[2] = cos(lat) * cos(lon);
    return 1.0;
}

static void pano_destroy(void *state)
{
    free(state);
}

static int pano_describe(const void *state, char *buf, size_t size)
{
    const panorama *p = state;
    return snprintf(buf, size, "model: equirectangular panorama (plugin), %g x %g degrees\n",
                    p->hfov_rad * 180 / M_PI, p->vfov_rad * 180 / M_PI);
}

static const lf_camera_type panorama_type = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "panorama",
    .create = pano_create,
    .needs = pano_needs,
    .generate_ray = pano_generate_ray,
    .destroy = pano_destroy,
    .describe = pano_describe,
    .metadata = NULL,
};

static const lf_camera_type *const types[] = {&panorama_type};

const lf_camera_type *const *lf_camera_plugin_types(int *count)
{
    *count = 1;
    return types;
}
