/* The camera-array light-field camera "lightfield" (CS348B assignment 3):
 * a grid of identical pinhole data cameras, each rendering into its own
 * equal tile of the shared film.  docs/lightfield.md is the user's page;
 * docs/lightfield-format.md fixes the attributes written into the EXR.
 *
 * Parameters (defaults where read):
 *   "float fov"                 each data camera's field of view across its tile's shorter side (90, as pbrt)
 *   "integer camerasperdim"     [nx ny] data cameras per row and column ([1 1]: one camera)
 *   "float cameragridbounds"    [minx maxx miny maxy] on the camera-space plane z = 0 ([-0.5 0.5 -0.5 0.5])
 *   "float lensradius", "float focaldistance"   optional thin lens per data camera (pbrt semantics)
 *
 * Layout (docs/physics.md "Light fields"): the film is cut into nx x ny tiles of
 * W/nx x H/ny pixels (the resolution must divide).  Tile column i holds the
 * camera at x_i = minx + i (maxx - minx)/(nx - 1), tile row j the camera at
 * y_j = maxy - j (maxy - miny)/(ny - 1): seen from behind the grid looking
 * along +z (camera +x right, +y up), the top-left camera is in the top-left
 * tile.  A single camera along an axis sits at the bounds' midpoint.  Inside
 * its tile a data camera is exactly pbrt's perspective camera with the tile
 * as its film: ray origin (x_i, y_j, 0), direction through the tile's screen
 * window, every data camera looking along +z.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_keys.h"
#include "camera_internal.h"

typedef struct lightfield {
    int nx, ny;                /* data cameras per row, per column */
    double bounds[4];          /* minx maxx miny maxy */
    double fov_deg, tan_half_fov;
    double lens_radius, focal_distance;
    int tile_w, tile_h;        /* pixels per tile */
    double screen[4];          /* each tile's screen window x0 x1 y0 y1 (pbrt) */
    double sx, sy;             /* screen units per pixel */
} lightfield;

/* Camera position along one axis: outermost cameras on the bounds. */
static double grid_position(double lo, double hi, int k, int n)
{
    if (n == 1)
        return 0.5 * (lo + hi);
    return lo + k * (hi - lo) / (n - 1);
}

static int lightfield_create(const lf_camera_create_args *a, void **state)
{
    const lf_camera_params *p = a->params;
    lightfield *c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(a->error, a->error_size, "out of memory");
        return -1;
    }
    c->fov_deg = p->get_float(p->ctx, "fov", 90.0);
    double dims[2] = {1, 1};
    int nd = p->get_floats(p->ctx, "camerasperdim", dims, 2);
    double b[4] = {-0.5, 0.5, -0.5, 0.5};
    int nb = p->get_floats(p->ctx, "cameragridbounds", b, 4);
    c->lens_radius = p->get_float(p->ctx, "lensradius", 0.0);
    c->focal_distance = p->get_float(p->ctx, "focaldistance", 1e6);
    const char *msg = NULL;
    char buf[256];
    if (!(c->fov_deg > 0.0 && c->fov_deg < 180.0))
        snprintf(buf, sizeof buf, "\"fov\" must be in (0, 180) degrees, got %g", c->fov_deg), msg = buf;
    else if (nd != 0 && nd != 2)
        snprintf(buf, sizeof buf, "\"camerasperdim\" needs 2 values [nx ny], got %d", nd), msg = buf;
    else if (!(dims[0] >= 1 && dims[1] >= 1 && dims[0] <= 65536 && dims[1] <= 65536) || dims[0] != floor(dims[0]) ||
             dims[1] != floor(dims[1]))
        snprintf(buf, sizeof buf, "\"camerasperdim\" must be two integers >= 1, got [%g %g]", dims[0], dims[1]),
            msg = buf;
    else if (nb != 0 && nb != 4)
        snprintf(buf, sizeof buf, "\"cameragridbounds\" needs 4 values [minx maxx miny maxy], got %d", nb), msg = buf;
    else if (!isfinite(b[0]) || !isfinite(b[1]) || !isfinite(b[2]) || !isfinite(b[3]) || b[1] < b[0] || b[3] < b[2])
        snprintf(buf, sizeof buf, "\"cameragridbounds\" [%g %g %g %g] must be finite with minx <= maxx, miny <= maxy",
                 b[0], b[1], b[2], b[3]),
            msg = buf;
    else if (!(c->lens_radius >= 0.0) || !isfinite(c->lens_radius))
        snprintf(buf, sizeof buf, "\"lensradius\" must be >= 0, got %g", c->lens_radius), msg = buf;
    else if (!(c->focal_distance > 0.0) || !isfinite(c->focal_distance))
        snprintf(buf, sizeof buf, "\"focaldistance\" must be > 0, got %g", c->focal_distance), msg = buf;
    if (msg) {
        snprintf(a->error, a->error_size, "%s", msg);
        free(c);
        return -1;
    }
    c->nx = (int)dims[0];
    c->ny = (int)dims[1];
    memcpy(c->bounds, b, sizeof b);
    if (a->image_width % c->nx || a->image_height % c->ny) {
        snprintf(a->error, a->error_size,
                 "the film resolution %dx%d is not divisible by \"camerasperdim\" [%d %d]: every data camera needs an "
                 "equal whole-pixel tile (e.g. %dx%d)",
                 a->image_width, a->image_height, c->nx, c->ny, (a->image_width / c->nx > 0 ? a->image_width / c->nx : 1) * c->nx,
                 (a->image_height / c->ny > 0 ? a->image_height / c->ny : 1) * c->ny);
        free(c);
        return -1;
    }
    c->tile_w = a->image_width / c->nx;
    c->tile_h = a->image_height / c->ny;
    c->tan_half_fov = tan(c->fov_deg * 0.5 * M_PI / 180.0);
    /* pbrt's screen window for the tile: "fov" spans the shorter side */
    double aspect = (double)c->tile_w / c->tile_h;
    if (aspect > 1.0)
        c->screen[0] = -aspect, c->screen[1] = aspect, c->screen[2] = -1.0, c->screen[3] = 1.0;
    else
        c->screen[0] = -1.0, c->screen[1] = 1.0, c->screen[2] = -1.0 / aspect, c->screen[3] = 1.0 / aspect;
    c->sx = (c->screen[1] - c->screen[0]) / c->tile_w;
    c->sy = (c->screen[3] - c->screen[2]) / c->tile_h;
    *state = c;
    return 0;
}

static uint32_t lightfield_needs(const void *state)
{
    const lightfield *c = state;
    return c->lens_radius > 0.0 ? LF_CAMERA_NEEDS_LENS : 0u;
}

static double lightfield_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const lightfield *c = state;
    int i = (int)floor(s->film_x / c->tile_w), j = (int)floor(s->film_y / c->tile_h);
    /* film positions on the outer edge (or a filter's reach beyond it) stay with the border tile */
    i = i < 0 ? 0 : i >= c->nx ? c->nx - 1 : i;
    j = j < 0 ? 0 : j >= c->ny ? c->ny - 1 : j;
    double lx = s->film_x - (double)i * c->tile_w, ly = s->film_y - (double)j * c->tile_h;
    /* the data camera: origin on z = 0, row j counted from the top (max y) */
    double o[3] = {grid_position(c->bounds[0], c->bounds[1], i, c->nx),
                   grid_position(c->bounds[3], c->bounds[2], j, c->ny), 0.0};
    /* pbrt-v4 PerspectiveCamera with the tile as the film (camera/projective.c) */
    double px = c->screen[0] + lx * c->sx;
    double py = c->screen[3] - ly * c->sy;
    double d[3] = {px * c->tan_half_fov, py * c->tan_half_fov, 1.0};
    double inv = 1.0 / sqrt(d[0] * d[0] + d[1] * d[1] + 1.0);
    d[0] *= inv, d[1] *= inv, d[2] *= inv;
    if (c->lens_radius > 0.0) {
        double ux, uy;
        lf_concentric_disk(s->lens_u, s->lens_v, &ux, &uy);
        double ft = c->focal_distance / d[2];
        double f[3] = {d[0] * ft, d[1] * ft, d[2] * ft}; /* relative to the data camera */
        double e[3] = {f[0] - ux * c->lens_radius, f[1] - uy * c->lens_radius, f[2]};
        double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        if (!(len > 0.0) || !isfinite(len))
            return 0.0;
        o[0] += ux * c->lens_radius, o[1] += uy * c->lens_radius;
        d[0] = e[0] / len, d[1] = e[1] / len, d[2] = e[2] / len;
    }
    memcpy(r->origin, o, sizeof o);
    memcpy(r->dir, d, sizeof d);
    return 1.0;
}

static void lightfield_destroy(void *state)
{
    free(state);
}

static int lightfield_describe(const void *state, char *buf, size_t size)
{
    const lightfield *c = state;
    double bx = c->nx > 1 ? (c->bounds[1] - c->bounds[0]) / (c->nx - 1) : 0.0;
    double by = c->ny > 1 ? (c->bounds[3] - c->bounds[2]) / (c->ny - 1) : 0.0;
    double fpx = (c->tile_w < c->tile_h ? c->tile_w : c->tile_h) * 0.5 / c->tan_half_fov;
    int n = snprintf(buf, size,
                     "model: camera array (CS348B light field): %d x %d pinhole data cameras on the plane z = 0\n"
                     "grid bounds: x [%g, %g], y [%g, %g] (outermost cameras on the bounds)\n"
                     "baseline between neighbours: %g (x), %g (y)\n"
                     "tile: %d x %d pixels per data camera; tile (i, j) = camera column i, row j from the top\n"
                     "fov: %g deg across the tile's shorter side (focal length %.6g px)\n"
                     "disparity of a point at depth Z between neighbours: %.6g px x (baseline x) / Z\n",
                     c->nx, c->ny, c->bounds[0], c->bounds[1], c->bounds[2], c->bounds[3], bx, by, c->tile_w,
                     c->tile_h, c->fov_deg, fpx, fpx);
    if (n < 0 || (size_t)n >= size)
        return n;
    if (c->lens_radius > 0.0)
        n += snprintf(buf + n, size - n,
                      "defocus: thin lens per data camera, radius %g, focal distance %g (pbrt semantics)\n",
                      c->lens_radius, c->focal_distance);
    else
        n += snprintf(buf + n, size - n, "defocus: none (pinhole data cameras)\n");
    return n;
}

/* docs/lightfield-format.md, "camera-array" */
static void lightfield_metadata(const void *state, const lf_camera_attr_sink *sink)
{
    const lightfield *c = state;
    sink->set_string(sink->ctx, LF_KEY_KIND, "camera-array");
    double dims[2] = {c->nx, c->ny};
    sink->set_doubles(sink->ctx, LF_KEY_CAMERAS_PER_DIM, dims, 2);
    sink->set_doubles(sink->ctx, LF_KEY_CAMERA_GRID_BOUNDS, c->bounds, 4);
    sink->set_double(sink->ctx, LF_KEY_FOV_DEG, c->fov_deg);
    double tile[2] = {c->tile_w, c->tile_h};
    sink->set_doubles(sink->ctx, LF_KEY_TILE_SIZE, tile, 2);
    if (c->lens_radius > 0.0) {
        sink->set_double(sink->ctx, LF_KEY_LENS_RADIUS, c->lens_radius);
        sink->set_double(sink->ctx, LF_KEY_FOCAL_DISTANCE, c->focal_distance);
    }
}

const lf_camera_type lf_camera_lightfield = {
    .abi_version = LF_CAMERA_ABI_VERSION,
    .name = "lightfield",
    .create = lightfield_create,
    .needs = lightfield_needs,
    .generate_ray = lightfield_generate_ray,
    .destroy = lightfield_destroy,
    .describe = lightfield_describe,
    .metadata = lightfield_metadata,
};
