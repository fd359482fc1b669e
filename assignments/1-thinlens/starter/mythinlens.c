/* Assignment 1 starter: your thin-lens camera as an lfrender plugin.
 *
 * Build against the public camera header only (no lensfield rebuild):
 *   cc -shared -fPIC -O2 -I /path/to/lensfield/camera mythinlens.c -o libmythinlens.so -lm
 * Render with it (change Camera "thinlens" to Camera "mythinlens" in a copy
 * of the scene; the parameters are the same):
 *   lfrender --camera-plugin ./libmythinlens.so bokeh.pbrt --spp 64 -o bokeh.png
 * The reference solution is the built-in "thinlens" camera (docs/thinlens.md).
 *
 * As given, the camera is a PINHOLE with the right field of view: it builds,
 * loads and renders, but has no defocus and no cos^4 falloff.  Fill in the
 * TODOs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lf_camera.h"

typedef struct mythinlens {
    int width, height;
    double f, fstop, focus;     /* metres, f-number, metres */
    double sensor_w, sensor_h;  /* metres */
    double z_s;                 /* lens-to-sensor distance, metres */
    double aperture_radius;     /* metres */
} mythinlens;

static int create(const lf_camera_create_args *a, void **state)
{
    mythinlens *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    const lf_camera_params *p = a->params;
    c->width = a->image_width;
    c->height = a->image_height;
    c->f = p->get_float(p->ctx, "focallength", 50) * 1e-3;
    c->fstop = p->get_float(p->ctx, "fstop", 2.8);
    c->focus = p->get_float(p->ctx, "focusdistance", 10);
    double size[2] = {36, 24};
    p->get_floats(p->ctx, "sensorsize", size, 2);
    c->sensor_w = size[0] * 1e-3;
    c->sensor_h = c->sensor_w * c->height / c->width; /* square pixels */
    if (!(c->f > 0 && c->fstop > 0 && c->focus > c->f)) {
        snprintf(a->error, a->error_size, "need focallength > 0, fstop > 0 and focusdistance > focallength");
        free(c);
        return -1;
    }
    /* TODO 1: the thin lens equation gives the sensor distance z_s for the
     * focus distance (1/f = 1/z_s + 1/z_o).  The starter uses z_s = f. */
    c->z_s = c->f;
    /* TODO 2: the aperture radius from f and N. */
    c->aperture_radius = 0;
    *state = c;
    return 0;
}

static uint32_t needs(const void *state)
{
    const mythinlens *c = state;
    return c->aperture_radius > 0 ? LF_CAMERA_NEEDS_LENS : 0;
}

static double generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const mythinlens *c = state;
    /* upright sensor coordinates of the film sample (raster y grows down) */
    double sx = (s->film_x / c->width - 0.5) * c->sensor_w;
    double sy = (0.5 - s->film_y / c->height) * c->sensor_h;
    /* pinhole ray through the lens centre */
    double d[3] = {sx, sy, c->z_s};
    /* TODO 3: sample a point on the lens disk from (s->lens_u, s->lens_v)
     * and aim the ray at the point of the focus plane z = focus that the
     * chief ray reaches (docs/thinlens.md, "Geometry"). */
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    r->origin[0] = r->origin[1] = r->origin[2] = 0;
    for (int k = 0; k < 3; k++)
        r->dir[k] = d[k] / len;
    /* TODO 4: the weight is the exposure the ray carries:
     * A_aperture cos^4(theta) / z_s^2 (docs/thinlens.md, "Exposure"). */
    return 1.0;
}

static void destroy(void *state) { free(state); }

static const lf_camera_type mythinlens_type = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "mythinlens",
    .create = create,
    .needs = needs,
    .generate_ray = generate_ray,
    .destroy = destroy,
    /* optional: .describe, .metadata, and .generate_rays (many rays at once) */
};

const lf_camera_type *const *lf_camera_plugin_types(int *count)
{
    static const lf_camera_type *const types[] = {&mythinlens_type};
    *count = 1;
    return types;
}
