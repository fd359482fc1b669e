/* disparity.h - the ground-truth disparity of light-field cameras
 * (render/disparity.c, `lfrender --aov disparity`): the geometry of a camera
 * array or plenoptic camera read back from its lensfield:* layout attributes
 * (decoded by image/lf_layout_attrs.h, as lftool reads them), and the centre
 * view's ray through a film point. */
#ifndef LF_RENDER_DISPARITY_H
#define LF_RENDER_DISPARITY_H

#include "base/lf_error.h"
#include "image/lf_image.h"
#include "image/lf_layout_attrs.h"

typedef struct lf_disparity_geom {
    lf_lightfield_kind kind; /* LF_LIGHTFIELD_CAMERA_ARRAY or LF_LIGHTFIELD_PLENOPTIC */
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
/* From the camera's lensfield:* attributes; LF_ERR_PARAM for other cameras. */
int lf_disparity_geom_init(const lf_attrs *meta, int xres, int yres, lf_disparity_geom *g, lf_error *err);
/* Centre-view ray (camera space, unit direction) for the film point (fx, fy). */
void lf_disparity_centre_ray(const lf_disparity_geom *g, double fx, double fy, double o[3], double d[3]);

#endif
