/* Ground-truth disparity of light-field renders (docs/lightfield-format.md,
 * "Disparity AOV").  The geometry comes from the camera's own layout
 * attributes (lensfield:kind and what it fixes), so any camera that
 * describes itself as a camera array or a plenoptic camera gets it.
 *
 * For each film pixel: the centre-view ray of the view that pixel belongs
 * to (camera space) and the affine map d = a + b / Z from the depth Z
 * (camera-space z of the first hit) to the disparity in px per view step,
 * lensfield's (and the HCI benchmark's) convention: a point's image moves by
 * -d pixels when the viewpoint moves one view step to the right.
 *
 *  - camera array: the data camera of the pixel's tile, ray through the
 *    pixel centre from the camera's centre (its lens centre with a thin
 *    lens); a = 0, b = F_px * B, F_px the focal length in pixels (half the
 *    tile's shorter side over tan(fov/2)), B the spacing of neighbouring
 *    cameras along x (along y when there is one column).
 *  - plenoptic: the pixel's microlens (nearest image centre G); the chief
 *    ray from the microlens centre through the main lens's centre, direction
 *    ((G - c) pixel / (z_i + d), 1) upright (c the sensor centre, d the
 *    microlens-to-sensor distance, z_i the main lens to the array); with
 *    k = (z_i + d) / (d P) (P: image pitch in pixels), a = k (1 - z_i / f),
 *    b = k z_i.  Exact for the thin main lens; paraxial for a compound one
 *    (its equivalent thin lens, from the principal planes).
 */
#include <math.h>
#include <string.h>

#include "image/lf_layout_attrs.h"
#include "render_internal.h"

/* The decoded attributes (image/lf_layout_attrs.h), read leniently: a
 * malformed one counts as missing; a number given as a list is its first. */
static int get_num(const lf_layout_attr *at, double *v)
{
    if (at->state != LF_LAYOUT_ATTR_SET && at->state != LF_LAYOUT_ATTR_LIST)
        return 0;
    *v = at->v[0];
    return 1;
}

static int get_vec(const lf_layout_attr *at, int n, double *v)
{
    if (at->state != LF_LAYOUT_ATTR_SET)
        return 0;
    for (int i = 0; i < n; i++)
        v[i] = at->v[i];
    return 1;
}

static int camera_array_geom(const lf_layout_attrs *la, lf_disparity_geom *g, lf_error *err)
{
    double dims[2], tile[2], fov;
    if (!get_vec(&la->cameras_per_dim, 2, dims) || !get_vec(&la->tile_size, 2, tile) ||
        !get_vec(&la->camera_grid_bounds, 4, g->bounds) || !get_num(&la->fov_deg, &fov))
        return lf_error_set(err, LF_ERR_PARAM,
                            "disparity AOV: the camera array's attributes are incomplete (cameras_per_dim, "
                            "tile_size, camera_grid_bounds, fov_deg)");
    g->kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    g->nx = (int)dims[0], g->ny = (int)dims[1], g->tw = (int)tile[0], g->th = (int)tile[1];
    if (g->nx < 1 || g->ny < 1 || g->tw < 1 || g->th < 1 || !(fov > 0 && fov < 180))
        return lf_error_set(err, LF_ERR_PARAM, "disparity AOV: bad camera-array attributes");
    g->tan_half = tan(fov * M_PI / 360);
    double aspect = (double)g->tw / g->th;
    if (aspect > 1.0)
        g->screen[0] = -aspect, g->screen[1] = aspect, g->screen[2] = -1.0, g->screen[3] = 1.0;
    else
        g->screen[0] = -1.0, g->screen[1] = 1.0, g->screen[2] = -1.0 / aspect, g->screen[3] = 1.0 / aspect;
    g->sx = (g->screen[1] - g->screen[0]) / g->tw;
    g->sy = (g->screen[3] - g->screen[2]) / g->th;
    double fpx = 0.5 * (g->tw < g->th ? g->tw : g->th) / g->tan_half;
    double bx = g->nx > 1 ? (g->bounds[1] - g->bounds[0]) / (g->nx - 1) : 0;
    double by = g->ny > 1 ? (g->bounds[3] - g->bounds[2]) / (g->ny - 1) : 0;
    g->a = 0;
    g->b = fpx * (bx > 0 ? bx : by);
    return LF_OK;
}

static int plenoptic_geom(const lf_layout_attrs *la, int xres, lf_disparity_geom *g, lf_error *err)
{
    double sensor[2], off[2], count[2], rot = 0;
    if (!get_num(&la->microlens_pitch_px, &g->pitch_px) || !get_vec(&la->microlens_offset_px, 2, off) ||
        !get_vec(&la->microlens_count, 2, count) || !get_vec(&la->sensor_size_mm, 2, sensor) ||
        !get_num(&la->microlens_focal_mm, &g->fmla_mm) || !get_num(&la->mla_distance_mm, &g->zi_mm) ||
        !get_num(&la->main_focal_mm, &g->f_mm))
        return lf_error_set(err, LF_ERR_PARAM,
                            "disparity AOV: the plenoptic camera's attributes are incomplete (microlens pitch, "
                            "offset, count and focal length, sensor size, main lens)");
    get_num(&la->microlens_rotation_rad, &rot);
    get_num(&la->sensor_offset_mm, &g->sensor_offset_mm);
    g->kind = LF_LIGHTFIELD_PLENOPTIC;
    g->hex = la->grid_known && la->grid_id == LF_LIGHTFIELD_GRID_HEX;
    g->cos_r = cos(rot), g->sin_r = sin(rot);
    g->origin[0] = off[0], g->origin[1] = off[1];
    g->lx = (int)count[0], g->ly = (int)count[1];
    g->row_px = g->pitch_px * (g->hex ? sqrt(3.0) / 2 : 1.0);
    double d = g->fmla_mm + g->sensor_offset_mm, zi = g->zi_mm;
    double pixel = sensor[0] / xres; /* mm */
    if (!(g->pitch_px > 0) || !(d > 0) || !(zi > 0) || !(g->f_mm > 0) || !(pixel > 0) || g->lx < 1 || g->ly < 1)
        return lf_error_set(err, LF_ERR_PARAM, "disparity AOV: bad plenoptic attributes");
    g->slope_per_px = pixel / (zi + d);
    double kk = (zi + d) / (d * g->pitch_px);
    g->a = kk * (1 - zi / g->f_mm);
    g->b = kk * zi * 1e-3; /* Z in metres (camera space) */
    return LF_OK;
}

int lf_disparity_geom_init(const lf_attrs *meta, int xres, int yres, lf_disparity_geom *g, lf_error *err)
{
    memset(g, 0, sizeof *g);
    lf_layout_attrs la;
    lf_layout_attrs_decode(meta, &la);
    if (la.kind.state != LF_LAYOUT_ATTR_SET)
        return lf_error_set(err, LF_ERR_PARAM,
                            "the disparity AOV needs a light-field camera (Camera \"lightfield\" or \"plenoptic\", or a "
                            "camera writing lensfield:kind)");
    g->xres = xres, g->yres = yres;
    if (la.kind_id == LF_LIGHTFIELD_CAMERA_ARRAY)
        return camera_array_geom(&la, g, err);
    if (la.kind_id == LF_LIGHTFIELD_PLENOPTIC)
        return plenoptic_geom(&la, xres, g, err);
    return lf_error_set(err, LF_ERR_PARAM, "the disparity AOV needs a camera array or a plenoptic camera, not \"%s\"",
                        la.kind.s);
}

static double grid_position(double lo, double hi, int k, int n)
{
    return n == 1 ? 0.5 * (lo + hi) : lo + k * (hi - lo) / (n - 1);
}

void lf_disparity_centre_ray(const lf_disparity_geom *g, double fx, double fy, double o[3], double d[3])
{
    if (g->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        int i = (int)floor(fx / g->tw), j = (int)floor(fy / g->th);
        i = i < 0 ? 0 : i >= g->nx ? g->nx - 1 : i;
        j = j < 0 ? 0 : j >= g->ny ? g->ny - 1 : j;
        double lx = fx - (double)i * g->tw, ly = fy - (double)j * g->th;
        o[0] = grid_position(g->bounds[0], g->bounds[1], i, g->nx);
        o[1] = grid_position(g->bounds[3], g->bounds[2], j, g->ny);
        o[2] = 0;
        d[0] = (g->screen[0] + lx * g->sx) * g->tan_half;
        d[1] = (g->screen[3] - ly * g->sy) * g->tan_half;
        d[2] = 1;
    } else {
        /* nearest microlens image centre, lattice frame */
        double dx = fx - g->origin[0], dy = fy - g->origin[1];
        double la = g->cos_r * dx + g->sin_r * dy, lb = -g->sin_r * dx + g->cos_r * dy;
        int j0 = (int)floor(lb / g->row_px + 0.5);
        double best = INFINITY, ga = 0, gb = 0;
        for (int j = j0 - 1; j <= j0 + 1; j++) {
            int jj = j < 0 ? 0 : j >= g->ly ? g->ly - 1 : j;
            double sh = g->hex && (jj & 1) ? 0.5 * g->pitch_px : 0.0;
            int i = (int)floor((la - sh) / g->pitch_px + 0.5);
            i = i < 0 ? 0 : i >= g->lx ? g->lx - 1 : i;
            double ca = i * g->pitch_px + sh, cb = jj * g->row_px;
            double dist = (la - ca) * (la - ca) + (lb - cb) * (lb - cb);
            if (dist < best)
                best = dist, ga = ca, gb = cb;
        }
        double gx = g->origin[0] + g->cos_r * ga - g->sin_r * gb;
        double gy = g->origin[1] + g->sin_r * ga + g->cos_r * gb;
        /* upright offset from the sensor centre, then the chief ray (camera
         * space = upright point-reflected; the ray continues away from G) */
        double ux = gx - 0.5 * g->xres, uy = 0.5 * g->yres - gy;
        o[0] = o[1] = o[2] = 0;
        d[0] = ux * g->slope_per_px;
        d[1] = uy * g->slope_per_px;
        d[2] = 1;
    }
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    d[0] /= n, d[1] /= n, d[2] /= n;
}
