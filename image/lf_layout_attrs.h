/* lf_layout_attrs.h - the lensfield:* layout attributes of a light-field
 * image (docs/lightfield-format.md), decoded once for every reader: the
 * light-field decoder (lightfield/layout.c, strict: a malformed attribute is
 * an error) and the renderer's disparity AOV (render/disparity.c, lenient:
 * a malformed attribute counts as missing).  The decoder only sorts each
 * attribute into absent / set / malformed and copies its value; range
 * checks and what is required are the readers' business.
 *
 *   lf_layout_attrs la;
 *   lf_layout_attrs_decode(&img_attrs, &la);
 *   if (la.fov_deg.state == LF_LAYOUT_ATTR_SET) use(la.fov_deg.v[0]);
 *   if (la.kind.state == LF_LAYOUT_ATTR_SET && la.kind_id == LF_LIGHTFIELD_PLENOPTIC) ...
 */
#ifndef LF_LAYOUT_ATTRS_H
#define LF_LAYOUT_ATTRS_H

#include "image/lf_image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The light-field kinds and microlens grids lensfield:kind and
 * lensfield:grid name (the one declaration; lf_lightfield.h uses them). */
typedef enum lf_lightfield_kind { LF_LIGHTFIELD_KIND_UNKNOWN = 0, LF_LIGHTFIELD_CAMERA_ARRAY, LF_LIGHTFIELD_PLENOPTIC } lf_lightfield_kind;
typedef enum lf_lightfield_grid { LF_LIGHTFIELD_GRID_SQUARE = 0, LF_LIGHTFIELD_GRID_HEX } lf_lightfield_grid;

/* Their names in the attributes ("camera-array", "plenoptic"; "square",
 * "hex"); NULL for LF_LIGHTFIELD_KIND_UNKNOWN. */
const char *lf_lightfield_kind_name(lf_lightfield_kind kind);
const char *lf_lightfield_grid_name(lf_lightfield_grid grid);

typedef enum lf_layout_attr_state {
    LF_LAYOUT_ATTR_ABSENT = 0,
    LF_LAYOUT_ATTR_SET,       /* of the expected type (and length, for a vector) */
    LF_LAYOUT_ATTR_MALFORMED, /* another type or length; v and s untouched */
    LF_LAYOUT_ATTR_LIST       /* a number given as a list of several floats: v[0] is the first */
} lf_layout_attr_state;

typedef struct lf_layout_attr {
    const char *name; /* the attribute's name (base/lf_keys.h), for messages */
    lf_layout_attr_state state;
    double v[4];      /* a number: v[0]; a vector: its values */
    const char *s;    /* a string: borrowed from the attribute list */
} lf_layout_attr;

typedef struct lf_layout_attrs {
    /* strings */
    lf_layout_attr kind;           /* lensfield:kind */
    lf_lightfield_kind kind_id;    /* UNKNOWN unless kind is set to a known name */
    lf_layout_attr grid;           /* lensfield:grid */
    int grid_known;                /* grid is set to a known name ... */
    lf_lightfield_grid grid_id;    /* ... this one */
    /* camera array */
    lf_layout_attr cameras_per_dim;    /* 2 */
    lf_layout_attr camera_grid_bounds; /* 4 */
    lf_layout_attr fov_deg;
    lf_layout_attr tile_size;          /* 2 */
    lf_layout_attr lens_radius, focal_distance;
    lf_layout_attr convergence_distance;
    /* plenoptic */
    lf_layout_attr microlens_pitch_px, microlens_rotation_rad;
    lf_layout_attr microlens_offset_px, microlens_count; /* 2 each */
    lf_layout_attr main_focal_mm, main_fstop, mla_distance_mm, microlens_pitch_um;
    lf_layout_attr focus_distance_m, microlens_focal_mm, sensor_offset_mm;
    lf_layout_attr sensor_size_mm;     /* 2 */
    /* any kind */
    lf_layout_attr disparity_range;    /* 2 */
} lf_layout_attrs;

/* Decodes every layout attribute of a (which may be NULL or empty: all
 * absent).  Never fails: the readers decide what a malformed one means.
 * The strings stay owned by a. */
void lf_layout_attrs_decode(const lf_attrs *a, lf_layout_attrs *out);

#ifdef __cplusplus
}
#endif
#endif
