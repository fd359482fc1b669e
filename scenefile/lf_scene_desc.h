/* lf_scene_desc.h - what a pbrt-v4 scene file says, before anything is built.
 *
 * The parser (scenefile/parser.c) fills an lf_scene_desc from a .pbrt file,
 * following pbrt-v4's semantics: graphics state with AttributeBegin/End,
 * the current transformation matrix (two of them, for TransformTimes /
 * ActiveTransform), named coordinate systems, named materials and textures,
 * area lights attached to following shapes, object instancing.  It resolves
 * names to indices and includes, but it does not interpret shape, material or
 * light parameters: the scene builder (render/scene_build.c) does, and calls
 * lf_params_finish() on every set it consumed so unused parameters are
 * reported with their location.
 *
 *   lf_scene_desc d;
 *   lf_error err = {0};
 *   if (lf_scene_parse_file("scenes/demo.pbrt", &d, &err)) ... err.msg ...
 *   ...
 *   lf_scene_desc_free(&d);
 */
#ifndef LF_SCENE_DESC_H
#define LF_SCENE_DESC_H

#include <stddef.h>

#include "base/lf_error.h"
#include "base/lf_math.h"
#include "base/lf_params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A transform that may move during the shutter interval: pbrt-v4's pair of
 * CTMs at TransformTimes start and end.  animated == 0 means xf[0] == xf[1]. */
typedef struct lf_anim_xform {
    lf_transform xf[2];
    double time[2];
    int animated;
} lf_anim_xform;

/* A directive with a type word and parameters: Film, Sampler, Integrator,
 * PixelFilter, Accelerator, Material, Texture, LightSource, ... */
typedef struct lf_entity {
    char *type;      /* e.g. "perspective", "sphere", "diffuse"; NULL if absent */
    lf_paramset params;
    lf_loc loc;      /* where the directive was written */
} lf_entity;

typedef struct lf_camera_desc {
    lf_entity e;                  /* type NULL when the scene has no Camera: perspective defaults */
    lf_anim_xform world_to_camera; /* the CTM when Camera was seen */
    const char *medium;           /* the exterior medium current at Camera (pbrt-v4's CameraMedium); NULL: none */
} lf_camera_desc;

/* MakeNamedMedium "name" "string type" ... (params include "type"). */
typedef struct lf_medium_desc {
    lf_entity e;                   /* e.type: NULL (the type is the "string type" parameter) */
    char *name;
    lf_transform medium_to_world;  /* the CTM at MakeNamedMedium */
} lf_medium_desc;

typedef struct lf_texture_desc {
    lf_entity e;        /* e.type is the texture class: "checkerboard", "imagemap", "scale", ... */
    char *name;
    int is_float;       /* Texture "name" "float" ...; otherwise "spectrum" */
    lf_transform object_to_world;
} lf_texture_desc;

typedef struct lf_material_desc {
    lf_entity e;        /* e.type is the material type: "diffuse", "conductor", ... */
    char *name;         /* for MakeNamedMaterial; NULL for anonymous Material */
} lf_material_desc;

typedef struct lf_light_desc {
    lf_entity e;        /* "point", "spot", "distant", "infinite", "goniometric", ... */
    lf_anim_xform light_to_world;
    int reverse_orientation;
} lf_light_desc;

typedef struct lf_shape_desc {
    lf_entity e;                 /* "sphere", "trianglemesh", "plymesh", "bilinearmesh", "disk", ... */
    lf_anim_xform object_to_world;
    int material;                /* index into materials; -1: the default diffuse 0.5 */
    int area_light;              /* index into area_lights; -1: not emissive */
    int reverse_orientation;
    int object;                  /* -1, or index of the object (ObjectBegin) it belongs to */
    const char *base_dir;        /* directory of the file that named it, for plymesh paths */
    /* MediumInterface current at the shape: medium names ("" = vacuum), or
     * NULL for both when no MediumInterface is in effect. */
    const char *medium_inside, *medium_outside;
} lf_shape_desc;

typedef struct lf_object_desc {  /* ObjectBegin "name" ... ObjectEnd */
    char *name;
    lf_anim_xform object_to_world; /* the CTM at ObjectBegin */
} lf_object_desc;

typedef struct lf_instance_desc { /* ObjectInstance "name" */
    int object;                   /* index into objects */
    lf_anim_xform instance_to_world;
    lf_loc loc;
} lf_instance_desc;

typedef struct lf_scene_desc {
    lf_camera_desc camera;
    lf_entity film, sampler, integrator, filter, accelerator; /* type NULL when absent */
    double transform_start_time, transform_end_time;          /* TransformTimes (default 0 1) */

    lf_texture_desc *textures;   size_t n_textures;
    lf_material_desc *materials; size_t n_materials;
    lf_light_desc *lights;       size_t n_lights;
    lf_entity *area_lights;      size_t n_area_lights;        /* AreaLightSource entities */
    lf_shape_desc *shapes;       size_t n_shapes;
    lf_object_desc *objects;     size_t n_objects;
    lf_instance_desc *instances; size_t n_instances;
    lf_medium_desc *media;       size_t n_media;              /* MakeNamedMedium, in order */

    /* Warnings for unsupported-but-harmless directives, one per line,
     * "file:line:col: warning: ...".  NULL if none. */
    char *warnings;

    /* Set from lf_parse_opts: directives lensfield refuses (see
     * docs/scene-format.md) were dropped with a warning instead of failing;
     * the scene builder does the same for what only it can judge. */
    int allow_unsupported;
    /* Directory of the top-level scene file (kept in strings): where pbrt-v4
     * resolves relative file names; the scene builder falls back to it. */
    const char *scene_dir;

    /* Storage owned by the description (file names for lf_loc, base dirs). */
    char **strings; size_t n_strings;
} lf_scene_desc;

/* Parses a scene file (and its Include/Import files). On failure returns an
 * LF_ERR_* code, err->msg names file:line:col and what was expected, and *out
 * holds nothing that needs freeing. */
int lf_scene_parse_file(const char *path, lf_scene_desc *out, lf_error *err);
/* Parses from memory; `name` is used in messages and as the base for relative
 * Include paths (its directory). */
int lf_scene_parse_string(const char *text, const char *name, lf_scene_desc *out, lf_error *err);
void lf_scene_desc_free(lf_scene_desc *d);

/* Errors are collected: after an error the parser goes on at the next
 * directive, so one run reports every problem (up to max_errors). */
#define LF_PARSE_MAX_ERRORS 20
typedef struct lf_parse_opts {
    int allow_unsupported; /* shapes, lights, materials lensfield cannot render
                              are left out with a warning instead of failing */
    int max_errors;        /* 0: LF_PARSE_MAX_ERRORS */
} lf_parse_opts;

/* As above; opts may be NULL (defaults).  On failure, err holds the first
 * error and *errors (when errors is not NULL) every error found, one per
 * line, malloc'ed (free it); on success *errors is NULL. */
int lf_scene_parse_file_ex(const char *path, const lf_parse_opts *opts, lf_scene_desc *out, lf_error *err,
                           char **errors);
int lf_scene_parse_string_ex(const char *text, const char *name, const lf_parse_opts *opts, lf_scene_desc *out,
                             lf_error *err, char **errors);

/* A triangle mesh as read from a PLY file (plymesh) - quads are split into
 * two triangles, as pbrt does. Arrays are malloc'ed; free with lf_ply_free. */
typedef struct lf_ply_mesh {
    float *P;      size_t n_vertices; /* 3 per vertex */
    float *N;      /* 3 per vertex, or NULL */
    float *uv;     /* 2 per vertex, or NULL */
    int *indices;  size_t n_triangles; /* 3 per triangle */
} lf_ply_mesh;

int lf_ply_read(const char *path, lf_ply_mesh *out, lf_error *err);
void lf_ply_free(lf_ply_mesh *m);

#ifdef __cplusplus
}
#endif
#endif
