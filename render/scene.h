/* scene.h - the renderer's built scene (render/ only): world-space meshes
 * and analytic spheres on Embree, rigidly moving prototypes placed by
 * Embree instances, the lights and media it holds, and the ray queries on
 * it.  Built by render/scene_build.c from an lf_scene_desc. */
#ifndef LF_RENDER_SCENE_H
#define LF_RENDER_SCENE_H

#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stddef.h>

#include "base/lf_distrib.h"
#include "base/lf_math.h"
#include "scenefile/lf_scene_desc.h"
#include "shading/lf_shading.h"

/* Defined in render/lights.h and render/media.h; the scene holds arrays. */
typedef struct lf_light lf_light;
typedef struct lf_medium lf_medium;

/* A triangle mesh (trianglemesh, plymesh, bilinearmesh, disk, and spheres
 * that Embree's sphere primitive cannot represent): world space, or the
 * space of a prototype that rigidly moving Embree instances place in the
 * world (proto >= 0; docs/motion.md). */
typedef struct lf_mesh {
    int n_tris, n_verts;
    int n_keys;    /* keyframes of its motion (1: static), evenly spaced in Embree time 0..1 */
    int proto;     /* -1: world space; else the lf_proto whose space P and N are in (n_keys 1) */
    int *idx;      /* 3 per triangle */
    float *P;      /* world (or prototype) space, 3 per vertex, n_keys blocks of 3 * n_verts */
    float *N;      /* shading normals in the same space and layout, or NULL */
    float *uv;     /* 2 per vertex, or NULL (pbrt defaults per triangle) */
    int material;
    int light_first;   /* index of the first triangle's light, -1 if not emissive */
    int light_quads;   /* emissive, and triangles 2k, 2k+1 form parallelogram k: one light each */
    int flip_normal;   /* reverse orientation XOR handedness swap */
    int medium_in, medium_out; /* MediumInterface (lf_scene.media indices, -1 vacuum); LF_MEDIUM_SAME: none */
    int bump;          /* its material has a displacement: hits carry (u,v) derivatives */
    /* pbrt-v4's "alpha": a hit is ignored when a hash of the hit point and
     * ray direction exceeds alpha (render/alpha.c); alpha_tex NULL and
     * alpha >= 1: opaque, no filter. */
    float alpha;
    const struct lf_texture *alpha_tex;
} lf_mesh;

/* pbrt-v4's Shape "curve" as Embree curve geometry (render/curves.c):
 * every segment is a cubic Bezier (B-splines and quadratics are converted,
 * as pbrt-v4 does), 4 control points of its own in world space.  "flat" and
 * "cylinder" are Embree's ray-facing flat curves (pbrt-v4's cylinder is a
 * flat curve whose shading normal is bent across the width); "ribbon" is
 * Embree's normal-oriented curve. */
enum { LF_CURVE_FLAT, LF_CURVE_CYLINDER, LF_CURVE_RIBBON };
typedef struct lf_curve {
    int n_segs;
    int type;          /* LF_CURVE_* */
    float *cp;         /* 4 (x, y, z, radius) per control point, 4 control points per segment */
    unsigned *first;   /* Embree index buffer: segment k starts at control point 4 k */
    float *nrm;        /* ribbon: 3 per control point (Bezier of the normal), else NULL */
    float u_step;      /* segment k covers pbrt's u in [k u_step, (k + 1) u_step] */
    int tess;          /* Embree's tessellation rate: quads per segment */
    int material;
    int flip_normal;
    int medium_in, medium_out;
    float alpha;       /* as lf_mesh */
    const struct lf_texture *alpha_tex;
} lf_curve;

typedef struct lf_sphere {
    lf_vec3 center;     /* at the first keyframe */
    float radius;
    int n_keys;         /* 1: static */
    lf_vec3 *centers;   /* n_keys centres when moving, else NULL */
    lf_transform object_to_world; /* for pbrt's (u,v) parameterisation */
    int material;
    int light;         /* -1 if not emissive */
    int flip_normal;
    int medium_in, medium_out; /* as lf_mesh */
    int bump;                  /* as lf_mesh */
    int textured;              /* its material reads textures: hits need pbrt's (u,v) */
} lf_sphere;

/* A shape whose MediumInterface does not change the medium (none given,
 * or the same medium on both sides): rays keep the medium they are in. */
enum { LF_MEDIUM_SAME = -2 };

/* Keyframe segment and blend for Embree time tau in [0,1] over n keys. */
static inline int lf_key_segment(int n_keys, float tau, float *frac)
{
    float x = tau * (float)(n_keys - 1);
    int k = (int)x;
    if (k >= n_keys - 1)
        k = n_keys - 2;
    if (k < 0)
        k = 0;
    *frac = x - (float)k;
    return k;
}

static inline lf_vec3 lf_sphere_center_at(const lf_sphere *sp, float tau)
{
    if (sp->n_keys <= 1)
        return sp->center;
    float f;
    int k = lf_key_segment(sp->n_keys, tau, &f);
    return lf_add(lf_scale(sp->centers[k], 1.f - f), lf_scale(sp->centers[k + 1], f));
}

/* Per-vertex 3-vector i of keyframed mesh data (P or N, n_keys blocks) at
 * Embree time tau: linear between keyframes, as Embree. */
static inline lf_vec3 lf_mesh_attr_at(const lf_mesh *m, const float *data, int i, float tau)
{
    const float *p = data + 3 * (size_t)i;
    if (m->n_keys <= 1)
        return lf_v3(p[0], p[1], p[2]);
    float f;
    int k = lf_key_segment(m->n_keys, tau, &f);
    const float *a = p + (size_t)k * 3 * m->n_verts, *b = a + (size_t)3 * m->n_verts;
    return lf_v3(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]));
}
static inline lf_vec3 lf_mesh_vertex_at(const lf_mesh *m, int i, float tau) { return lf_mesh_attr_at(m, m->P, i, tau); }
static inline lf_vec3 lf_mesh_normal_at(const lf_mesh *m, int i, float tau) { return lf_mesh_attr_at(m, m->N, i, tau); }

/* A static Embree scene of meshes in their own space, placed in the world
 * by lf_instance geometries.  Its meshes are s->meshes[mesh_first ..
 * mesh_first + n_meshes), attached with geomID = mesh index - mesh_first. */
typedef struct lf_proto {
    RTCScene rtc;
    int mesh_first, n_meshes;
    lf_vec3 bmin, bmax; /* bounds in its own space */
} lf_proto;

/* A rigidly moving placement of a prototype: an Embree instance with two
 * time steps given as quaternion decompositions, so Embree slerps the
 * rotation (pbrt's decomposed interpolation) instead of moving vertices
 * along chords.  Hits go to the world by the same interpolation at the
 * ray's time, evaluated from the fields below (render/intersect.c,
 * instance_motion_at; rtcGetGeometryTransform agrees to ~2e-6 but costs
 * ~470 instructions a hit). */
typedef struct lf_instance {
    RTCGeometry geom;  /* owned by the top-level scene */
    int proto;
    lf_decomposed key[2]; /* its motion at Embree time 0 and 1 */
    /* The same motion for hits, precomputed: rotation q(tau) = cos(tau
     * theta) q0 + sin(tau theta) qperp (nlerp of q0, q1 when they are within
     * Embree's and pbrt's lerp threshold), axis scales and translation lerped. */
    float q0[4], q1[4], qperp[4], theta;
    int nlerp;
    int uniform_scale; /* the same scale on all axes at both keys */
    lf_vec3 scale0, scale1, trans0, trans1;
} lf_instance;

typedef struct lf_scene {
    RTCDevice device;
    atomic_int rtc_error_claimed; /* the first Embree error message is kept */
    char rtc_error_msg[256];
    RTCScene rtc;
    lf_mesh *meshes;
    int n_meshes;
    lf_sphere *spheres;
    int n_spheres;
    unsigned sphere_geom_id; /* the static spheres' geometry; RTC_INVALID_GEOMETRY_ID if none */
    int *geom_index;         /* top-level geomID -> mesh index (>= 0; n_meshes + k: curve k) or -1 - sphere index (moving
                                sphere); for an instance, the lf_instance index (hit.instID[0]) */
    int n_geom;
    lf_proto *protos;
    int n_protos;
    lf_instance *instances;
    int n_instances;
    lf_curve *curves;        /* geom_index n_meshes + k is curve k */
    int n_curves;
    int moving_shapes;       /* meshes or spheres with more than one keyframe, plus moving instances */
    int max_keys;            /* of the keyframed meshes and spheres */
    int motion_rigid_shapes; /* Shape directives (per ObjectInstance) moved as rigid Embree instances */
    int motion_keyframed_shapes; /* ... moved by keyframed vertices or sphere centres */
    double time0, time1;     /* TransformTimes: scene time of Embree time 0 and 1 */
    lf_light *lights;
    int n_lights;
    int *infinite_lights;    /* indices of infinite lights */
    int n_infinite;
    /* Lights next-event estimation samples: all but uniform infinite lights
     * (a constant environment is sampled at least as well by the BSDF, so
     * sampling it too would only add shadow rays; MIS gives its BSDF-sampled
     * hits full weight).  The power distribution gives the others 0. */
    int *nee_lights;
    int n_nee_lights;
    lf_distrib1d light_distrib; /* light selection by power */
    lf_vec3 bounds_min, bounds_max;
    float scene_radius;
    lf_vec3 scene_center;
    long long n_triangles;
    lf_materials *materials;
    lf_medium *media;        /* MakeNamedMedium "homogeneous" */
    int n_media;
    int camera_medium;       /* medium camera rays start in (-1: vacuum) */
    int has_media;           /* some medium is reachable (the camera or a shape's MediumInterface):
                                the volumetric integrator runs; otherwise the surface-only one */
    lf_warnings warnings;
} lf_scene;

int lf_scene_build(lf_scene_desc *d, lf_scene *s, lf_error *err);
/* A scene with no geometry and a uniform environment of radiance 1. */
int lf_scene_build_white(lf_scene *s, lf_error *err);
void lf_scene_free(lf_scene *s);
/* How the moving shapes move, for --explain (one clause, no newline). */
void lf_scene_motion_summary(const lf_scene *s, char *buf, size_t n);
/* Passes on a block of warnings gathered below (the scene description's,
 * the materials'): a blank line closes each block, as lfrender has always
 * printed them.  block may be NULL (none). */
static inline void lf_warn_block(lf_warnings *w, const char *block)
{
    if (!block)
        return;
    lf_warn_text(w, block);
    lf_warn_text(w, "\n");
}

/* A surface hit, everything the integrator needs. */
typedef struct lf_hit {
    float t;
    lf_shading_ctx sc; /* p, ng (facing the normal's side: not flipped to the ray), ns, dpdu, uv */
    int material;
    int light;         /* -1 if not emissive */
    int sphere;        /* analytic sphere index, or -1; its uv is filled by lf_scene_sphere_uv */
    float tau;         /* Embree time of the ray that found it */
    int medium_in, medium_out; /* the shape's MediumInterface; medium_in LF_MEDIUM_SAME: no transition */
    /* On a Shape "curve" hit (curve 1): pbrt-v4's h in [-1,1] across the
     * width (2 v - 1, v = sc.uv.y), as its HairMaterial reads it; sc.dpdu is
     * then the tangent dP/du along the curve (docs/scene-format.md, Curves). */
    int curve;
    float curve_h;
} lf_hit;

/* ---- intersection (render/intersect.c) ---- */
/* tau: Embree ray time in [0,1] (scene time mapped over TransformTimes). */
int lf_scene_intersect(const lf_scene *s, lf_vec3 o, lf_vec3 d, float tmax, float tau, lf_hit *hit);
int lf_scene_occluded(const lf_scene *s, lf_vec3 o, lf_vec3 d, float tmax, float tau);
/* Fills hit->sc.uv for sphere hits (deferred: only textured materials read it). */
void lf_scene_sphere_uv(const lf_scene *s, lf_hit *hit);
/* Origin offset off a surface to avoid self-intersection, on the side of w. */
static inline lf_vec3 lf_offset_origin(lf_vec3 p, lf_vec3 ng, lf_vec3 w)
{
    /* Float error of an intersection point grows with its magnitude; a few
     * ulps of the largest coordinate (plus an absolute floor) clears it.
     * (Selects, not fmaxf: the coordinates are finite, and fmaxf's NaN
     * rule makes it a libm call.) */
    float ax = fabsf(p.x), ay = fabsf(p.y), az = fabsf(p.z);
    float m = ax > ay ? ax : ay;
    m = m > az ? m : az;
    float eps = 1e-6f + m * 4e-6f;
    return lf_madd(p, ng, lf_dot(ng, w) >= 0 ? eps : -eps);
}

#endif
