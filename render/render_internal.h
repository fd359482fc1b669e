/* render_internal.h - the renderer's private headers at once (render/scene.h,
 * lights.h, media.h, integrator.h), and the ground-truth disparity geometry
 * of light-field cameras (render/disparity.c). */
#ifndef LF_RENDER_INTERNAL_H
#define LF_RENDER_INTERNAL_H

#include <stdint.h>

#include "base/lf_filter.h"
#include "camera/lf_camera.h"
#include "render/lf_render.h"
#include "render/integrator.h"
#include "render/lights.h"
#include "render/media.h"
#include "render/scene.h"

/* ---- ground-truth disparity of light-field cameras (render/disparity.c) ---- */
typedef struct lf_disparity_geom {
    int kind; /* LF_LIGHTFIELD_CAMERA_ARRAY_KIND or LF_LIGHTFIELD_PLENOPTIC_KIND */
    int xres, yres;
    double a, b; /* d = a + b / Z */
    /* camera array */
    int nx, ny, tw, th;
    double bounds[4], tan_half, screen[4], sx, sy;
    /* plenoptic */
    int hex, lx, ly;
    double pitch_px, row_px, cos_r, sin_r, origin[2], slope_per_px;
    double fmla_mm, sensor_offset_mm, zi_mm, f_mm;
} lf_disparity_geom;
enum { LF_LIGHTFIELD_CAMERA_ARRAY_KIND = 1, LF_LIGHTFIELD_PLENOPTIC_KIND = 2 };
/* From the camera's lensfield:* attributes; LF_ERR_PARAM for other cameras. */
int lf_disparity_geom_init(const lf_attrs *meta, int xres, int yres, lf_disparity_geom *g, lf_error *err);
/* Centre-view ray (camera space, unit direction) for the film point (fx, fy). */
void lf_disparity_centre_ray(const lf_disparity_geom *g, double fx, double fy, double o[3], double d[3]);

#endif
