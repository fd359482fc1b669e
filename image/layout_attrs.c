/* The lensfield:* layout attributes, decoded once (lf_layout_attrs.h). */
#include <string.h>

#include "base/lf_keys.h"
#include "image/lf_layout_attrs.h"

static const char *const kind_names[] = {NULL, "camera-array", "plenoptic"};
static const char *const grid_names[] = {"square", "hex"};

const char *lf_lightfield_kind_name(lf_lightfield_kind kind)
{
    return kind == LF_LIGHTFIELD_CAMERA_ARRAY || kind == LF_LIGHTFIELD_PLENOPTIC ? kind_names[kind] : NULL;
}

const char *lf_lightfield_grid_name(lf_lightfield_grid grid)
{
    return grid_names[grid == LF_LIGHTFIELD_GRID_HEX];
}

/* A number: an int, a float, a double or a one-float list; a longer list is
 * LF_LAYOUT_ATTR_LIST (its first value kept), anything else malformed. */
static lf_layout_attr number(const lf_attrs *a, const char *name)
{
    lf_layout_attr r = {.name = name};
    const lf_attr *at = lf_attrs_get(a, name);
    if (!at)
        return r;
    r.state = LF_LAYOUT_ATTR_MALFORMED;
    switch (at->type) {
    case LF_ATTR_INT: r.v[0] = at->i, r.state = LF_LAYOUT_ATTR_SET; break;
    case LF_ATTR_FLOAT:
    case LF_ATTR_DOUBLE: r.v[0] = at->d, r.state = LF_LAYOUT_ATTR_SET; break;
    case LF_ATTR_FLOATS:
        if (at->n >= 1)
            r.v[0] = at->v[0], r.state = at->n == 1 ? LF_LAYOUT_ATTR_SET : LF_LAYOUT_ATTR_LIST;
        break;
    default: break;
    }
    return r;
}

/* A vector: a list of exactly n floats (n <= 4). */
static lf_layout_attr vector(const lf_attrs *a, const char *name, int n)
{
    lf_layout_attr r = {.name = name};
    const lf_attr *at = lf_attrs_get(a, name);
    if (!at)
        return r;
    r.state = LF_LAYOUT_ATTR_MALFORMED;
    if (at->type == LF_ATTR_FLOATS && at->n == n) {
        for (int i = 0; i < n; i++)
            r.v[i] = at->v[i];
        r.state = LF_LAYOUT_ATTR_SET;
    }
    return r;
}

static lf_layout_attr string(const lf_attrs *a, const char *name)
{
    lf_layout_attr r = {.name = name};
    const lf_attr *at = lf_attrs_get(a, name);
    if (!at)
        return r;
    r.state = LF_LAYOUT_ATTR_MALFORMED;
    if (at->type == LF_ATTR_STRING)
        r.s = at->s, r.state = LF_LAYOUT_ATTR_SET;
    return r;
}

void lf_layout_attrs_decode(const lf_attrs *a, lf_layout_attrs *out)
{
    *out = (lf_layout_attrs){
        .kind = string(a, LF_KEY_KIND),
        .grid = string(a, LF_KEY_GRID),
        .cameras_per_dim = vector(a, LF_KEY_CAMERAS_PER_DIM, 2),
        .camera_grid_bounds = vector(a, LF_KEY_CAMERA_GRID_BOUNDS, 4),
        .fov_deg = number(a, LF_KEY_FOV_DEG),
        .tile_size = vector(a, LF_KEY_TILE_SIZE, 2),
        .lens_radius = number(a, LF_KEY_LENS_RADIUS),
        .focal_distance = number(a, LF_KEY_FOCAL_DISTANCE),
        .convergence_distance = number(a, LF_KEY_CONVERGENCE_DISTANCE),
        .microlens_pitch_px = number(a, LF_KEY_MICROLENS_PITCH_PX),
        .microlens_rotation_rad = number(a, LF_KEY_MICROLENS_ROTATION_RAD),
        .microlens_offset_px = vector(a, LF_KEY_MICROLENS_OFFSET_PX, 2),
        .microlens_count = vector(a, LF_KEY_MICROLENS_COUNT, 2),
        .main_focal_mm = number(a, LF_KEY_MAIN_FOCAL_MM),
        .main_fstop = number(a, LF_KEY_MAIN_FSTOP),
        .mla_distance_mm = number(a, LF_KEY_MLA_DISTANCE_MM),
        .microlens_pitch_um = number(a, LF_KEY_MICROLENS_PITCH_UM),
        .focus_distance_m = number(a, LF_KEY_FOCUS_DISTANCE_M),
        .microlens_focal_mm = number(a, LF_KEY_MICROLENS_FOCAL_MM),
        .sensor_offset_mm = number(a, LF_KEY_SENSOR_OFFSET_MM),
        .sensor_size_mm = vector(a, LF_KEY_SENSOR_SIZE_MM, 2),
        .disparity_range = vector(a, LF_KEY_DISPARITY_RANGE, 2),
    };
    if (out->kind.state == LF_LAYOUT_ATTR_SET)
        for (int k = LF_LIGHTFIELD_CAMERA_ARRAY; k <= LF_LIGHTFIELD_PLENOPTIC; k++)
            if (!strcmp(out->kind.s, kind_names[k]))
                out->kind_id = (lf_lightfield_kind)k;
    if (out->grid.state == LF_LAYOUT_ATTR_SET)
        for (int g = LF_LIGHTFIELD_GRID_SQUARE; g <= LF_LIGHTFIELD_GRID_HEX; g++)
            if (!strcmp(out->grid.s, grid_names[g]))
                out->grid_known = 1, out->grid_id = (lf_lightfield_grid)g;
}
