/* scene_build.h - the state shared by the files that build an lf_scene
 * from its description (render/ only): shapes.c turns shapes into meshes
 * and spheres, motion.c moves them (keyframes, or prototypes placed by rigid
 * Embree instances), sphere_geometry.c and scene_build.c hand them to
 * Embree. */
#ifndef LF_RENDER_SCENE_BUILD_H
#define LF_RENDER_SCENE_BUILD_H

#include "render/scene.h"

/* The keyframes of a shape's motion over the TransformTimes interval (Embree
 * time 0..1), evenly spaced; n == 1 for a static shape. */
typedef struct lf_shape_motion {
    const lf_transform *keys;
    int n;
} lf_shape_motion;

/* What building the scene carries from shape to shape. */
typedef struct lf_scene_builder {
    lf_scene *s;
    lf_scene_desc *d;
    int cap_meshes, cap_spheres, cap_lights, cap_protos, cap_instances, cap_curves;
    lf_error *err;
    int proto;         /* the lf_proto being built (meshes go to its space), or -1: world */
    int *object_proto; /* per ObjectBegin: its shared lf_proto, -1 none, -2 not built yet */
    /* The "alpha" of the shape being built (render/alpha.c), copied into
     * each mesh it makes: 1 and NULL when opaque. */
    float alpha;
    const struct lf_texture *alpha_tex;
} lf_scene_builder;

/* Reads a shape's "float alpha" / "texture alpha" into b->alpha and
 * b->alpha_tex (render/alpha.c). */
int lf_read_shape_alpha(lf_scene_builder *b, lf_shape_desc *sh);
/* Sets the alpha filter on a mesh's geometry when it is not opaque. */
void lf_alpha_attach(RTCGeometry g, const lf_mesh *me);
/* pbrt-v4's AlphaMasked for area lights: alpha 0 masks, 1 does not, in
 * between a hash of the point and its (u,v) decides. */
int lf_alpha_masked(float alpha, const struct lf_texture *tex, lf_vec3 p, lf_vec2 uv);
/* The same for a curve's geometry. */
void lf_alpha_attach_curve(RTCGeometry g, const lf_curve *c);
/* Shape "curve" (render/curves.c). */
int lf_build_curve(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo);
/* Embree geometry for the curves, growing the bounds. */
void lf_attach_curves(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax);
void lf_curves_free(lf_scene *s);
/* Fills hit for a hit on curve c (segment prim, Embree's u), ray o + t d. */
void lf_curve_hit(const lf_curve *c, unsigned prim, float u, lf_vec3 o, lf_vec3 d, float t, lf_hit *hit);

/* One shape (render/shapes.c), its vertices placed by the keyframes mo. */
int lf_build_shape(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo);
/* Whether shapes.c builds shapes of this type. */
int lf_shape_known(const char *type);

/* One shape, moving or not, optionally under an animated instance
 * transform inst (render/motion.c). */
int lf_build_shape_moving(lf_scene_builder *b, lf_shape_desc *sh, const lf_anim_xform *inst);
/* An ObjectInstance (render/motion.c). */
int lf_build_object_instance(lf_scene_builder *b, const lf_instance_desc *in);

/* Embree geometry for what was built, each growing the world bounds
 * [*bmin, *bmax]: the analytic spheres (render/sphere_geometry.c), the
 * prototypes and their instances (render/motion.c). */
void lf_attach_spheres(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax);
void lf_attach_instances(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax);
/* A triangle geometry for a mesh (render/scene_build.c). */
unsigned lf_attach_mesh(RTCDevice device, RTCScene scene, const lf_mesh *me, unsigned id);

#endif
