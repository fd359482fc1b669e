/* Layout of a raw light-field image: from lensfield:* attributes
 * (docs/lightfield-format.md), from explicit parameters, merged and checked. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/lf_keys.h"
#include "image/lf_layout_attrs.h"
#include "lf_lightfield.h"

void lf_lightfield_layout_init(lf_lightfield_layout *lay)
{
    memset(lay, 0, sizeof *lay);
}

/* The readers of the decoded attributes (image/lf_layout_attrs.h), strict:
 * 1 set (copied to v), 0 absent, -1 malformed (err says so). */
static int take_num(const lf_layout_attr *at, double *v, lf_error *err)
{
    if (at->state == LF_LAYOUT_ATTR_ABSENT)
        return 0;
    if (at->state == LF_LAYOUT_ATTR_SET) {
        *v = at->v[0];
        return 1;
    }
    lf_error_set(err, LF_ERR_PARSE, "attribute %s: expected a number", at->name);
    return -1;
}

static int take_vec(const lf_layout_attr *at, int n, double *v, lf_error *err)
{
    if (at->state == LF_LAYOUT_ATTR_ABSENT)
        return 0;
    if (at->state != LF_LAYOUT_ATTR_SET) {
        lf_error_set(err, LF_ERR_PARSE, "attribute %s: expected %d floats", at->name, n);
        return -1;
    }
    for (int i = 0; i < n; i++)
        v[i] = at->v[i];
    return 1;
}

/* Attribute values come from files: every number is range-checked before
 * it is converted or used (fuzzing found NaN pitches and 65536^2 grids). */
static int whole_in(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi && v == floor(v);
}

static int finite_within(const double *v, int n, double limit)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]) || fabs(v[i]) > limit)
            return 0;
    return 1;
}

static int kind_from_attrs(const lf_layout_attrs *la, lf_lightfield_layout *lay, lf_error *err)
{
    if (la->kind.state == LF_LAYOUT_ATTR_ABSENT)
        return LF_OK;
    if (la->kind.state != LF_LAYOUT_ATTR_SET)
        return lf_error_set(err, LF_ERR_PARSE, "attribute lensfield:kind: expected a string");
    if (la->kind_id == LF_LIGHTFIELD_KIND_UNKNOWN)
        return lf_error_set(err, LF_ERR_PARSE,
                            "attribute lensfield:kind is \"%s\" (expected camera-array or plenoptic)", la->kind.s);
    lay->kind = la->kind_id;
    lay->have |= LF_LIGHTFIELD_HAVE_KIND;
    return LF_OK;
}

/* The camera array's grid, bounds, field of view, tile and data-camera lens. */
static int camera_array_from_attrs(const lf_layout_attrs *la, lf_lightfield_layout *lay, lf_error *err)
{
    double v[4];
    int r;
    if ((r = take_vec(&la->cameras_per_dim, 2, v, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r) {
        if (!whole_in(v[0], 1, 4096) || !whole_in(v[1], 1, 4096))
            return lf_error_set(err, LF_ERR_PARSE,
                                "attribute lensfield:cameras_per_dim: expected whole numbers in 1..4096, got %g x %g",
                                v[0], v[1]);
        lay->cams_x = (int)v[0];
        lay->cams_y = (int)v[1];
        lay->have |= LF_LIGHTFIELD_HAVE_CAMS;
    }
    if ((r = take_vec(&la->camera_grid_bounds, 4, lay->grid_bounds, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r && !finite_within(lay->grid_bounds, 4, 1e12))
        return lf_error_set(err, LF_ERR_PARSE, "attribute lensfield:camera_grid_bounds: values must be finite");
    if (r)
        lay->have |= LF_LIGHTFIELD_HAVE_BOUNDS;
    if ((r = take_num(&la->fov_deg, &lay->fov_deg, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r)
        lay->have |= LF_LIGHTFIELD_HAVE_FOV;
    if ((r = take_vec(&la->tile_size, 2, v, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r) {
        if (!whole_in(v[0], 1, 1 << 20) || !whole_in(v[1], 1, 1 << 20))
            return lf_error_set(err, LF_ERR_PARSE, "attribute lensfield:tile_size: expected whole numbers in 1..2^20");
        lay->tile_w = (int)v[0];
        lay->tile_h = (int)v[1];
        lay->have |= LF_LIGHTFIELD_HAVE_TILE;
    }
    int lr = take_num(&la->lens_radius, &lay->lens_radius, err);
    int fd = take_num(&la->focal_distance, &lay->focal_distance, err);
    if (lr < 0 || fd < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (lr || fd)
        lay->have |= LF_LIGHTFIELD_HAVE_CAM_LENS;
    return LF_OK;
}

/* The microlens array: grid, pitch, rotation, offset and count. */
static int microlenses_from_attrs(const lf_layout_attrs *la, lf_lightfield_layout *lay, lf_error *err)
{
    if (la->grid.state != LF_LAYOUT_ATTR_ABSENT) {
        if (!la->grid_known)
            return lf_error_set(err, LF_ERR_PARSE, "attribute lensfield:grid: expected \"square\" or \"hex\"");
        lay->grid = la->grid_id;
        lay->have |= LF_LIGHTFIELD_HAVE_GRID;
    }
    double v[2];
    int r;
    if ((r = take_num(&la->microlens_pitch_px, &lay->pitch_px, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r)
        lay->have |= LF_LIGHTFIELD_HAVE_PITCH;
    if ((r = take_num(&la->microlens_rotation_rad, &lay->rotation_rad, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r)
        lay->have |= LF_LIGHTFIELD_HAVE_ROTATION;
    if ((r = take_vec(&la->microlens_offset_px, 2, lay->offset_px, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r)
        lay->have |= LF_LIGHTFIELD_HAVE_OFFSET;
    if ((r = take_vec(&la->microlens_count, 2, v, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r) {
        if (!whole_in(v[0], 1, 1 << 20) || !whole_in(v[1], 1, 1 << 20))
            return lf_error_set(err, LF_ERR_PARSE,
                                "attribute lensfield:microlens_count: expected whole numbers in 1..2^20");
        lay->lens_x = (int)v[0];
        lay->lens_y = (int)v[1];
        lay->have |= LF_LIGHTFIELD_HAVE_LENS_COUNT;
    }
    return LF_OK;
}

/* The main lens and the optional optics, the disparity range and the
 * convergence distance: a malformed one among the optics is reported after
 * the rest is read (the first message kept). */
static int optics_from_attrs(const lf_layout_attrs *la, lf_lightfield_layout *lay, lf_error *err)
{
    int n = 0, r;
    n += take_num(&la->main_focal_mm, &lay->main_focal_mm, err) > 0;
    n += take_num(&la->main_fstop, &lay->main_fstop, err) > 0;
    n += take_num(&la->mla_distance_mm, &lay->mla_distance_mm, err) > 0;
    n += take_num(&la->microlens_pitch_um, &lay->pitch_um, err) > 0;
    take_num(&la->focus_distance_m, &lay->focus_distance_m, err);
    take_num(&la->microlens_focal_mm, &lay->microlens_focal_mm, err);
    take_num(&la->sensor_offset_mm, &lay->sensor_offset_mm, err);
    if (!(isfinite(lay->microlens_focal_mm) && lay->microlens_focal_mm >= 0 && lay->microlens_focal_mm < 1e6 &&
          isfinite(lay->sensor_offset_mm) && fabs(lay->sensor_offset_mm) < 1e6))
        lay->microlens_focal_mm = 0, lay->sensor_offset_mm = 0;
    double rng[2];
    if ((r = take_vec(&la->disparity_range, 2, rng, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r && finite_within(rng, 2, 1e9) && rng[0] <= rng[1])
        lay->disp_min = rng[0], lay->disp_max = rng[1], lay->have |= LF_LIGHTFIELD_HAVE_DISP_RANGE;
    if ((r = take_num(&la->convergence_distance, &lay->convergence_m, err)) < 0)
        return err ? err->code : LF_ERR_PARSE;
    if (r && isfinite(lay->convergence_m) && lay->convergence_m > 0)
        lay->have |= LF_LIGHTFIELD_HAVE_CONVERGENCE;
    if (err && err->code)
        return err->code;
    if (n == 4)
        lay->have |= LF_LIGHTFIELD_HAVE_MAIN_LENS;
    return LF_OK;
}

int lf_lightfield_layout_from_attrs(const lf_attrs *a, lf_lightfield_layout *lay, lf_error *err)
{
    lf_lightfield_layout_init(lay);
    lf_layout_attrs la;
    lf_layout_attrs_decode(a, &la);
    int rc;
    if ((rc = kind_from_attrs(&la, lay, err)) || (rc = camera_array_from_attrs(&la, lay, err)) ||
        (rc = microlenses_from_attrs(&la, lay, err)) || (rc = optics_from_attrs(&la, lay, err)))
        return rc;
    double scalars[] = {lay->fov_deg, lay->pitch_px, lay->rotation_rad, lay->lens_radius, lay->focal_distance};
    if (((lay->have & LF_LIGHTFIELD_HAVE_FOV) && !(isfinite(lay->fov_deg) && lay->fov_deg > 0 && lay->fov_deg < 180)) ||
        ((lay->have & LF_LIGHTFIELD_HAVE_PITCH) && !(isfinite(lay->pitch_px) && lay->pitch_px > 0 && lay->pitch_px <= 1e6)) ||
        ((lay->have & LF_LIGHTFIELD_HAVE_OFFSET) && !finite_within(lay->offset_px, 2, 1e9)) ||
        !finite_within(scalars + 2, 1, 1e6) ||
        ((lay->have & LF_LIGHTFIELD_HAVE_CAM_LENS) && !finite_within(scalars + 3, 2, 1e12)))
        return lf_error_set(err, LF_ERR_PARSE,
                            "light-field layout attributes out of range (fov %g deg, pitch %g px, offset %g %g, "
                            "rotation %g)",
                            lay->fov_deg, lay->pitch_px, lay->offset_px[0], lay->offset_px[1], lay->rotation_rad);
    return LF_OK;
}

static int differs(double a, double b)
{
    return fabs(a - b) > 1e-6 * fmax(1.0, fmax(fabs(a), fabs(b)));
}

int lf_lightfield_layout_resolve(const lf_lightfield_layout *file, const lf_lightfield_layout *flags, int raw_w, int raw_h,
                         lf_lightfield_layout *out, lf_error *err)
{
    lf_lightfield_layout_init(out);
    lf_lightfield_layout f = flags ? *flags : *out;
    *out = *file;
    /* each flag that the file also gives must agree with it */
#define MERGE(bit, cond, what)                                                                       \
    if (f.have & (bit)) {                                                                            \
        if ((file->have & (bit)) && (cond))                                                          \
            return lf_error_set(err, LF_ERR_PARAM, "%s contradicts the file's attribute", what);     \
    }
    MERGE(LF_LIGHTFIELD_HAVE_KIND, f.kind != file->kind, "--kind (lensfield:kind)")
    MERGE(LF_LIGHTFIELD_HAVE_CAMS, f.cams_x != file->cams_x || f.cams_y != file->cams_y,
          "--camsperdim (lensfield:cameras_per_dim)")
    MERGE(LF_LIGHTFIELD_HAVE_BOUNDS,
          differs(f.grid_bounds[0], file->grid_bounds[0]) || differs(f.grid_bounds[1], file->grid_bounds[1]) ||
              differs(f.grid_bounds[2], file->grid_bounds[2]) || differs(f.grid_bounds[3], file->grid_bounds[3]),
          "--griddim (lensfield:camera_grid_bounds)")
    MERGE(LF_LIGHTFIELD_HAVE_FOV, differs(f.fov_deg, file->fov_deg), "--inputfov (lensfield:fov_deg)")
    MERGE(LF_LIGHTFIELD_HAVE_TILE, f.tile_w != file->tile_w || f.tile_h != file->tile_h, "--tilesize (lensfield:tile_size)")
    MERGE(LF_LIGHTFIELD_HAVE_GRID, f.grid != file->grid, "--grid (lensfield:grid)")
    MERGE(LF_LIGHTFIELD_HAVE_PITCH, differs(f.pitch_px, file->pitch_px), "--pitch (lensfield:microlens_pitch_px)")
    MERGE(LF_LIGHTFIELD_HAVE_ROTATION, differs(f.rotation_rad, file->rotation_rad),
          "--rotation (lensfield:microlens_rotation_rad)")
    MERGE(LF_LIGHTFIELD_HAVE_OFFSET, differs(f.offset_px[0], file->offset_px[0]) || differs(f.offset_px[1], file->offset_px[1]),
          "--offset (lensfield:microlens_offset_px)")
    MERGE(LF_LIGHTFIELD_HAVE_LENS_COUNT, f.lens_x != file->lens_x || f.lens_y != file->lens_y,
          "--lenscount (lensfield:microlens_count)")
#undef MERGE
    if (f.have & LF_LIGHTFIELD_HAVE_KIND)
        out->kind = f.kind;
    if (f.have & LF_LIGHTFIELD_HAVE_CAMS)
        out->cams_x = f.cams_x, out->cams_y = f.cams_y;
    if (f.have & LF_LIGHTFIELD_HAVE_BOUNDS)
        memcpy(out->grid_bounds, f.grid_bounds, sizeof f.grid_bounds);
    if (f.have & LF_LIGHTFIELD_HAVE_FOV)
        out->fov_deg = f.fov_deg;
    if (f.have & LF_LIGHTFIELD_HAVE_TILE)
        out->tile_w = f.tile_w, out->tile_h = f.tile_h;
    if (f.have & LF_LIGHTFIELD_HAVE_GRID)
        out->grid = f.grid;
    if (f.have & LF_LIGHTFIELD_HAVE_PITCH)
        out->pitch_px = f.pitch_px;
    if (f.have & LF_LIGHTFIELD_HAVE_ROTATION)
        out->rotation_rad = f.rotation_rad;
    if (f.have & LF_LIGHTFIELD_HAVE_OFFSET)
        memcpy(out->offset_px, f.offset_px, sizeof f.offset_px);
    if (f.have & LF_LIGHTFIELD_HAVE_LENS_COUNT)
        out->lens_x = f.lens_x, out->lens_y = f.lens_y;
    if ((f.have & LF_LIGHTFIELD_HAVE_MAIN_LENS) && !(file->have & LF_LIGHTFIELD_HAVE_MAIN_LENS)) {
        out->main_focal_mm = f.main_focal_mm, out->main_fstop = f.main_fstop;
        out->mla_distance_mm = f.mla_distance_mm, out->pitch_um = f.pitch_um;
    }
    out->have = file->have | f.have;

    if (!(out->have & LF_LIGHTFIELD_HAVE_KIND))
        return lf_error_set(err, LF_ERR_PARAM,
                            "no light-field layout: missing lensfield:kind (--kind camera-array|plenoptic); "
                            "a camera-array also needs lensfield:cameras_per_dim (--camsperdim NX NY), "
                            "a plenoptic raw lensfield:microlens_pitch_px (--pitch PX) and "
                            "lensfield:microlens_offset_px (--offset X Y) (or run lftool calibrate on a white image)");
    char missing[512] = "";
    if (out->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        if (!(out->have & LF_LIGHTFIELD_HAVE_CAMS))
            strcat(missing, " lensfield:cameras_per_dim (--camsperdim NX NY)");
        if (missing[0])
            return lf_error_set(err, LF_ERR_PARAM, "camera-array layout incomplete, missing:%s", missing);
        if (out->cams_x < 1 || out->cams_y < 1)
            return lf_error_set(err, LF_ERR_PARAM, "cameras per dimension must be >= 1 (got %d %d)", out->cams_x,
                                out->cams_y);
        if (!(out->have & LF_LIGHTFIELD_HAVE_TILE)) {
            if (raw_w % out->cams_x || raw_h % out->cams_y)
                return lf_error_set(err, LF_ERR_PARAM,
                                    "image %dx%d does not divide into %dx%d tiles; give lensfield:tile_size", raw_w,
                                    raw_h, out->cams_x, out->cams_y);
            out->tile_w = raw_w / out->cams_x;
            out->tile_h = raw_h / out->cams_y;
            out->have |= LF_LIGHTFIELD_HAVE_TILE;
        }
        if (out->tile_w < 1 || out->tile_h < 1 || (long)out->tile_w * out->cams_x > raw_w ||
            (long)out->tile_h * out->cams_y > raw_h)
            return lf_error_set(err, LF_ERR_PARAM, "%dx%d tiles of %dx%d do not fit the %dx%d image", out->cams_x,
                                out->cams_y, out->tile_w, out->tile_h, raw_w, raw_h);
    } else {
        if (!(out->have & LF_LIGHTFIELD_HAVE_PITCH))
            strcat(missing, " lensfield:microlens_pitch_px (--pitch PX)");
        if (!(out->have & LF_LIGHTFIELD_HAVE_OFFSET))
            strcat(missing, " lensfield:microlens_offset_px (--offset X Y)");
        if (missing[0])
            return lf_error_set(err, LF_ERR_PARAM,
                                "plenoptic layout incomplete, missing:%s (or run lftool calibrate on a white image)",
                                missing);
        if (!(out->pitch_px >= 2.0) || !isfinite(out->pitch_px) || out->pitch_px > 1e6)
            return lf_error_set(err, LF_ERR_PARAM, "microlens pitch %g px is out of range (need 2 .. 1e6)",
                                out->pitch_px);
        if (!finite_within(out->offset_px, 2, 1e9))
            return lf_error_set(err, LF_ERR_PARAM, "microlens offset (%g, %g) px is out of range", out->offset_px[0],
                                out->offset_px[1]);
        if (!(out->have & LF_LIGHTFIELD_HAVE_LENS_COUNT)) {
            double py = out->pitch_px * (out->grid == LF_LIGHTFIELD_GRID_HEX ? sqrt(3.0) / 2 : 1.0);
            out->lens_x = (int)floor((raw_w - out->offset_px[0]) / out->pitch_px) + 1;
            out->lens_y = (int)floor((raw_h - out->offset_px[1]) / py) + 1;
            out->have |= LF_LIGHTFIELD_HAVE_LENS_COUNT;
        }
        if (out->lens_x < 1 || out->lens_y < 1)
            return lf_error_set(err, LF_ERR_PARAM, "microlens count %d x %d is empty", out->lens_x, out->lens_y);
    }
    return LF_OK;
}

int lf_lightfield_layout_to_attrs(const lf_lightfield_layout *lay, lf_attrs *a, lf_error *err)
{
    int r = 0;
    float v[4];
    if (lay->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        r |= lf_attrs_set_string(a, LF_KEY_KIND, lf_lightfield_kind_name(LF_LIGHTFIELD_CAMERA_ARRAY), NULL);
        v[0] = (float)lay->cams_x, v[1] = (float)lay->cams_y;
        r |= lf_attrs_set_floats(a, LF_KEY_CAMERAS_PER_DIM, v, 2, NULL);
        if (lay->have & LF_LIGHTFIELD_HAVE_BOUNDS) {
            for (int i = 0; i < 4; i++)
                v[i] = (float)lay->grid_bounds[i];
            r |= lf_attrs_set_floats(a, LF_KEY_CAMERA_GRID_BOUNDS, v, 4, NULL);
        }
        if (lay->have & LF_LIGHTFIELD_HAVE_FOV)
            r |= lf_attrs_set_double(a, LF_KEY_FOV_DEG, lay->fov_deg, NULL);
        v[0] = (float)lay->tile_w, v[1] = (float)lay->tile_h;
        r |= lf_attrs_set_floats(a, LF_KEY_TILE_SIZE, v, 2, NULL);
        if (lay->have & LF_LIGHTFIELD_HAVE_CONVERGENCE)
            r |= lf_attrs_set_double(a, LF_KEY_CONVERGENCE_DISTANCE, lay->convergence_m, NULL);
    } else if (lay->kind == LF_LIGHTFIELD_PLENOPTIC) {
        r |= lf_attrs_set_string(a, LF_KEY_KIND, lf_lightfield_kind_name(LF_LIGHTFIELD_PLENOPTIC), NULL);
        r |= lf_attrs_set_string(a, LF_KEY_GRID, lf_lightfield_grid_name(lay->grid), NULL);
        r |= lf_attrs_set_double(a, LF_KEY_MICROLENS_PITCH_PX, lay->pitch_px, NULL);
        r |= lf_attrs_set_double(a, LF_KEY_MICROLENS_ROTATION_RAD, lay->rotation_rad, NULL);
        v[0] = (float)lay->offset_px[0], v[1] = (float)lay->offset_px[1];
        r |= lf_attrs_set_floats(a, LF_KEY_MICROLENS_OFFSET_PX, v, 2, NULL);
        v[0] = (float)lay->lens_x, v[1] = (float)lay->lens_y;
        r |= lf_attrs_set_floats(a, LF_KEY_MICROLENS_COUNT, v, 2, NULL);
        if (lay->have & LF_LIGHTFIELD_HAVE_MAIN_LENS) {
            r |= lf_attrs_set_double(a, LF_KEY_MAIN_FOCAL_MM, lay->main_focal_mm, NULL);
            r |= lf_attrs_set_double(a, LF_KEY_MAIN_FSTOP, lay->main_fstop, NULL);
            r |= lf_attrs_set_double(a, LF_KEY_MLA_DISTANCE_MM, lay->mla_distance_mm, NULL);
            r |= lf_attrs_set_double(a, LF_KEY_MICROLENS_PITCH_UM, lay->pitch_um, NULL);
        }
    }
    if (lay->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) {
        v[0] = (float)lay->disp_min, v[1] = (float)lay->disp_max;
        r |= lf_attrs_set_floats(a, LF_KEY_DISPARITY_RANGE, v, 2, NULL);
    }
    return r ? lf_error_set(err, LF_ERR_NOMEM, "out of memory writing layout attributes") : LF_OK;
}

static void describe_kind(const lf_lightfield_layout *l, char *buf, size_t n);

void lf_lightfield_layout_describe(const lf_lightfield_layout *l, char *buf, size_t n)
{
    describe_kind(l, buf, n);
    size_t k = strlen(buf);
    if ((l->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) && k < n)
        snprintf(buf + k, n - k, "disparity range %g .. %g px per view step\n", l->disp_min, l->disp_max);
}

static void describe_kind(const lf_lightfield_layout *l, char *buf, size_t n)
{
    if (n)
        buf[0] = '\0';
    if (l->kind == LF_LIGHTFIELD_CAMERA_ARRAY) {
        int k = snprintf(buf, n, "kind camera-array\ngrid %d x %d cameras\nviews %d\nview resolution %d x %d\n",
                         l->cams_x, l->cams_y, l->cams_x * l->cams_y, l->tile_w, l->tile_h);
        if (k > 0 && (size_t)k < n && (l->have & LF_LIGHTFIELD_HAVE_BOUNDS))
            k += snprintf(buf + k, n - (size_t)k, "camera grid bounds x [%g, %g] y [%g, %g]\n", l->grid_bounds[0],
                          l->grid_bounds[1], l->grid_bounds[2], l->grid_bounds[3]);
        if (k > 0 && (size_t)k < n && (l->have & LF_LIGHTFIELD_HAVE_FOV))
            k += snprintf(buf + k, n - (size_t)k, "fov %g deg\n", l->fov_deg);
        if (k > 0 && (size_t)k < n && (l->have & LF_LIGHTFIELD_HAVE_CAM_LENS))
            k += snprintf(buf + k, n - (size_t)k, "data camera lens radius %g, focal distance %g\n", l->lens_radius,
                          l->focal_distance);
        if (k > 0 && (size_t)k < n && (l->have & LF_LIGHTFIELD_HAVE_CONVERGENCE))
            k += snprintf(buf + k, n - (size_t)k, "sensors shifted: disparity 0 at depth %g\n", l->convergence_m);
    } else {
        int views = 2 * (int)floor((l->pitch_px - 1) / 2) + 1;
        int nt = l->grid == LF_LIGHTFIELD_GRID_HEX ? (int)floor((l->lens_y - 1) * sqrt(3.0) / 2) + 1 : l->lens_y;
        int k = snprintf(buf, n,
                         "kind plenoptic\ngrid %s, %d x %d microlenses, pitch %g px, rotation %g rad, offset (%g, %g) px\n"
                         "views %d x %d\nview resolution %d x %d\n",
                         l->grid == LF_LIGHTFIELD_GRID_HEX ? "hex" : "square", l->lens_x, l->lens_y, l->pitch_px,
                         l->rotation_rad, l->offset_px[0], l->offset_px[1], views, views, l->lens_x, nt);
        if (k > 0 && (size_t)k < n) {
            if (l->have & LF_LIGHTFIELD_HAVE_MAIN_LENS)
                snprintf(buf + k, n - (size_t)k,
                         "main lens f = %g mm, f/%g, focus %g m, microlens array at %g mm, microlens pitch %g um\n",
                         l->main_focal_mm, l->main_fstop, l->focus_distance_m, l->mla_distance_mm, l->pitch_um);
            else
                snprintf(buf + k, n - (size_t)k, "main lens: unknown (alpha/depth refocus unavailable)\n");
        }
    }
}
