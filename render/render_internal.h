/* Private structures of the renderer (render/ only). */
#ifndef LF_RENDER_INTERNAL_H
#define LF_RENDER_INTERNAL_H

#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "base/lf_distrib.h"
#include "base/lf_filter.h"
#include "base/lf_math.h"
#include "base/lf_sampler.h"
#include "camera/lf_camera.h"
#include "lf_render.h"
#include "shading/lf_shading.h"

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
} lf_mesh;

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

/* A homogeneous participating medium (pbrt-v4 "homogeneous"), per RGB
 * channel, "scale" applied (render/media.c). */
typedef struct lf_medium {
    lf_vec3 sigma_a, sigma_s, sigma_t;
    lf_vec3 Le;          /* emitted radiance, Lescale applied; emission is sigma_a Le per unit length */
    float g;             /* Henyey-Greenstein asymmetry */
    int scatters;        /* sigma_s > 0 in some channel */
    int emits;           /* sigma_a Le > 0 in some channel */
} lf_medium;

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
 * ray's time, evaluated from the fields below (render/scene.c,
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

typedef enum lf_light_kind {
    LF_LIGHT_POINT,
    LF_LIGHT_SPOT,
    LF_LIGHT_DISTANT,
    LF_LIGHT_INFINITE_UNIFORM,
    LF_LIGHT_INFINITE_IMAGE,
    LF_LIGHT_TRIANGLE,
    LF_LIGHT_PARALLELOGRAM, /* two triangles of a static mesh, sampled as one (uniform area) */
    LF_LIGHT_SPHERE
} lf_light_kind;

typedef struct lf_envmap {
    int width, height;       /* square, pbrt-v4 equal-area octahedral layout */
    float *rgb;
    lf_distrib2d distrib;
    lf_transform light_to_world;
} lf_envmap;

typedef struct lf_light {
    lf_light_kind kind;
    lf_vec3 L;          /* radiance (area, infinite, distant) or intensity (point, spot), scale applied */
    lf_vec3 pos;        /* point, spot */
    lf_vec3 dir;        /* spot axis; distant: direction light travels FROM (towards the light) */
    float cos_total, cos_start; /* spot */
    int mesh, prim;     /* triangle; parallelogram: its first triangle */
    int quad[3];        /* parallelogram: vertex indices of a corner and of the ends of its two edges */
    int sphere;         /* sphere */
    float area;
    int twosided;
    lf_envmap *env;     /* infinite image */
    double power;       /* for the light-selection distribution */
} lf_light;

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
    int *geom_index;         /* top-level geomID -> mesh index (>= 0) or -1 - sphere index (moving
                                sphere); for an instance, the lf_instance index (hit.instID[0]) */
    int n_geom;
    lf_proto *protos;
    int n_protos;
    lf_instance *instances;
    int n_instances;
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
    char *warnings;
} lf_scene;

int lf_scene_build(lf_scene_desc *d, lf_scene *s, lf_error *err);
/* A scene with no geometry and a uniform environment of radiance 1. */
int lf_scene_build_white(lf_scene *s, lf_error *err);
void lf_scene_free(lf_scene *s);
/* How the moving shapes move, for --explain (one clause, no newline). */
void lf_scene_motion_summary(const lf_scene *s, char *buf, size_t n);
/* Appends a warning line to a malloc'ed buffer. */
void lf_warn_append(char **buf, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* A surface hit, everything the integrator needs. */
typedef struct lf_hit {
    float t;
    lf_shading_ctx sc; /* p, ng (facing the normal's side: not flipped to the ray), ns, dpdu, uv */
    int material;
    int light;         /* -1 if not emissive */
    int sphere;        /* analytic sphere index, or -1; its uv is filled by lf_scene_sphere_uv */
    float tau;         /* Embree time of the ray that found it */
    int medium_in, medium_out; /* the shape's MediumInterface; medium_in LF_MEDIUM_SAME: no transition */
} lf_hit;

/* ---- lights (render/lights.c) ---- */
typedef struct lf_light_sample {
    lf_vec3 wi;     /* towards the light */
    lf_vec3 Li;
    float pdf;      /* solid angle (1 for delta lights) */
    float dist;     /* distance to the sampled point (INFINITY for infinite/distant) */
    int delta;
} lf_light_sample;

/* tau: the path's Embree time (moving area lights are sampled where they are then). */
int lf_light_sample_li(const lf_scene *s, const lf_light *l, lf_vec3 p, float tau, float u0, float u1,
                       lf_light_sample *ls);
/* Solid-angle pdf of sampling direction wi from p that hits the light at hit
 * (area lights) or escapes (infinite). */
float lf_light_pdf_li(const lf_scene *s, const lf_light *l, lf_vec3 p, lf_vec3 wi, const lf_hit *hit);
/* Emitted radiance from an area light's surface towards -w (w = ray direction). */
lf_vec3 lf_light_area_le(const lf_light *l, const lf_hit *hit, lf_vec3 w);
/* Radiance arriving along a ray direction from an infinite light. */
lf_vec3 lf_light_infinite_le(const lf_light *l, lf_vec3 dir);
double lf_light_power(const lf_scene *s, const lf_light *l);
int lf_envmap_load(const char *path, lf_envmap *env, lf_error *err);
void lf_envmap_free(lf_envmap *env);
lf_vec3 lf_equal_area_square_to_sphere(float u, float v);
void lf_equal_area_sphere_to_square(lf_vec3 d, float *u, float *v);

/* ---- intersection (render/scene.c) ---- */
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

/* ---- integrator (render/integrator.c) ---- */
/* How next-event estimation picks lights ("string lightsampler"). */
typedef enum lf_light_sampler {
    LF_LIGHTS_AUTO,    /* "bvh" (pbrt-v4's default name): ALL up to LF_LIGHTS_ALL_MAX lights, else POWER */
    LF_LIGHTS_POWER,   /* one light per vertex, chosen by power */
    LF_LIGHTS_UNIFORM, /* one light per vertex, chosen uniformly */
    LF_LIGHTS_ALL      /* every light at every vertex (lensfield extension "all") */
} lf_light_sampler;
enum { LF_LIGHTS_ALL_MAX = 8 };

/* Russian roulette rule (Integrator "string russianroulette"). */
typedef enum lf_rr_rule { LF_RR_SQRT, LF_RR_PBRT } lf_rr_rule;

typedef struct lf_integrator {
    int volumetric;    /* "volpath" (the default): media are rendered; "path" ignores them (pbrt-v4) */
    int max_depth;
    int regularize;
    lf_light_sampler light_sampler;
    lf_rr_rule rr_rule; /* survival probability sqrt(max beta) or max beta */
    int rr_depth;       /* roulette only at depth > rr_depth (2; pbrt-v4: 1) */
} lf_integrator;

/* The strategy in effect for a scene (AUTO resolved by its light count). */
static inline lf_light_sampler lf_light_sampler_for(const lf_integrator *in, const lf_scene *s)
{
    if (in->light_sampler == LF_LIGHTS_AUTO)
        return s->n_nee_lights <= LF_LIGHTS_ALL_MAX ? LF_LIGHTS_ALL : LF_LIGHTS_POWER;
    return in->light_sampler;
}

/* Radiance along a world-space camera ray. rays counts traced rays. */
lf_vec3 lf_path_li(const lf_scene *s, const lf_integrator *in, lf_vec3 o, lf_vec3 d, float tau, lf_sample_stream *st,
                   long long *rays);
/* Probability that NEE samples light `light` at a vertex (1 when all are). */
double lf_light_pmf(const lf_scene *s, lf_light_sampler ls, int light);

/* ---- shared by the path and volumetric path integrators ---- */

/* Veach's power heuristic (beta = 2) for a sample of pdf a against b. */
static inline float lf_power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    if (isinf(a2))
        return 1.f;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0.f;
}

/* Light a path meets by BSDF (or phase) sampling, added to *L: at the camera
 * or after a specular bounce in full, otherwise MIS-weighted against next-
 * event estimation, which would have found the same light from prev_p with
 * pdf pmf * pdf_li (pbrt-v4's PathIntegrator). */
static inline void lf_add_bsdf_sampled_light(lf_vec3 *L, const lf_scene *s, lf_light_sampler lsm, int light,
                                             lf_vec3 Le, lf_vec3 beta, int unweighted, float p_b, lf_vec3 prev_p,
                                             lf_vec3 d, const lf_hit *h)
{
    if (unweighted) {
        *L = lf_add(*L, lf_mul(beta, Le));
    } else {
        float p_l = (float)lf_light_pmf(s, lsm, light) * lf_light_pdf_li(s, &s->lights[light], prev_p, d, h);
        *L = lf_add(*L, lf_scale(lf_mul(beta, Le), lf_power_heuristic(p_b, p_l)));
    }
}

/* The infinite lights seen by a ray that escaped the scene. */
static inline void lf_add_escaped_light(lf_vec3 *L, const lf_scene *s, lf_light_sampler lsm, lf_vec3 beta,
                                        int unweighted, float p_b, lf_vec3 prev_p, lf_vec3 d)
{
    for (int k = 0; k < s->n_infinite; k++) {
        lf_vec3 Le = lf_light_infinite_le(&s->lights[s->infinite_lights[k]], d);
        if (!lf_is_black(Le))
            lf_add_bsdf_sampled_light(L, s, lsm, s->infinite_lights[k], Le, beta, unweighted, p_b, prev_p, d, NULL);
    }
}

/* The sample pair of light l's position: point, spot and distant lights
 * take none (their direction is fixed), so the pair is skipped without
 * computing it; the dimensions consumed are the same either way. */
static inline void lf_light_pair(const lf_light *l, lf_sample_stream *st, float *u0, float *u1)
{
    if (l->kind == LF_LIGHT_POINT || l->kind == LF_LIGHT_SPOT || l->kind == LF_LIGHT_DISTANT) {
        lf_sample_skip(st);
        *u0 = *u1 = 0.5f;
    } else {
        lf_sample_2d(st, u0, u1);
    }
}

/* The light one-sample NEE uses at a vertex (strategies UNIFORM and POWER),
 * chosen with ul; *pmf its probability (0: none). */
static inline int lf_pick_light(const lf_scene *s, lf_light_sampler lsm, float ul, double *pmf)
{
    if (lsm == LF_LIGHTS_UNIFORM) {
        int k = (int)(ul * s->n_nee_lights);
        *pmf = 1.0 / s->n_nee_lights;
        return s->nee_lights[k < s->n_nee_lights ? k : s->n_nee_lights - 1];
    }
    double ur;
    return lf_distrib1d_sample_discrete(&s->light_distrib, ul, pmf, &ur);
}

/* The path's state between vertices, as both integrators carry it. */
typedef struct lf_path_state {
    lf_vec3 beta;        /* throughput */
    float p_b;           /* the last BSDF sample's pdf (MIS of emission hit next) */
    int specular_bounce; /* the last bounce was a delta lobe */
    float eta_scale;     /* product of eta^2 over transmissions (roulette) */
    lf_vec3 prev_p;      /* the last vertex */
} lf_path_state;

/* Continues a path from surface hit h by sampling its BSDF (the vertex's
 * direction pair is drawn here): updates the state and the ray (o, d).
 * Returns 0 when the path ends (no valid sample). */
static inline int lf_bsdf_continue(const lf_bsdf *bsdf, const lf_hit *h, lf_vec3 wo, float uc, lf_sample_stream *st,
                                   lf_path_state *ps, lf_vec3 *o, lf_vec3 *d)
{
    float u0, u1;
    lf_sample_2d(st, &u0, &u1);
    struct lf_bsdf_sample bs;
    if (!lf_bsdf_sample(bsdf, wo, uc, u0, u1, &bs) || !(bs.pdf > 0) || lf_is_black(bs.f))
        return 0;
    float cosi = lf_absdot(bs.wi, bsdf->n);
    ps->beta = lf_mul(ps->beta, lf_scale(bs.f, cosi / bs.pdf));
    ps->p_b = bs.pdf;
    ps->specular_bounce = bs.specular;
    if (bs.transmission && bs.eta > 0)
        ps->eta_scale *= bs.eta * bs.eta;
    ps->prev_p = h->sc.p;
    *o = lf_offset_origin(h->sc.p, h->sc.ng, bs.wi);
    *d = bs.wi;
    return 1;
}

/* The BSDF at a surface vertex and the two sample values it may spend on
 * choosing a light and a lobe: one 2D sample drawn only when a choice exists,
 * else one skipped, so later dimensions line up whatever the surface.
 * Returns whether the BSDF is specular. */
static inline int lf_surface_vertex(const lf_scene *s, lf_light_sampler lsm, lf_hit *h, const lf_material *mat,
                                    lf_sample_stream *st, lf_bsdf *bsdf, float *ul, float *uc)
{
    if (h->sphere >= 0 && s->spheres[h->sphere].textured)
        lf_scene_sphere_uv(s, h);
    lf_material_bsdf(mat, &h->sc, bsdf);
    int specular = bsdf->kind != LF_LOBE_DIFFUSE && lf_bsdf_is_specular(bsdf); /* diffuse: never, without a call */
    int need_light_choice = !specular && s->n_nee_lights > 1 && lsm != LF_LIGHTS_ALL;
    int need_lobe_choice = bsdf->kind != LF_LOBE_DIFFUSE;
    *ul = *uc = 0.5f;
    if (need_light_choice || need_lobe_choice)
        lf_sample_2d(st, ul, uc);
    else
        lf_sample_skip(st);
    return specular;
}

/* Russian roulette on the throughput beta * eta_scale (the integrator's
 * "russianroulette" rule, docs/scene-format.md): survival probability p,
 * survivors weighted 1/p, so the estimate stays unbiased for any p > 0.
 * One 1D sample is drawn or skipped either way.  Returns 0 to end the path. */
static inline int lf_roulette(const lf_integrator *in, lf_vec3 *beta, float eta_scale, int depth,
                              lf_sample_stream *st)
{
    float m = lf_maxc(lf_scale(*beta, eta_scale));
    if (m < 1.f && depth > in->rr_depth) {
        float p = in->rr_rule == LF_RR_SQRT ? sqrtf(m) : m;
        if (lf_sample_1d(st) >= p)
            return 0;
        *beta = lf_scale(*beta, 1.f / p);
    } else {
        lf_sample_skip(st);
    }
    return lf_maxc(*beta) > 0;
}

/* The emission of an area light the ray hit. */
static inline void lf_add_hit_emission(lf_vec3 *L, const lf_scene *s, lf_light_sampler lsm, const lf_hit *h,
                                       lf_vec3 beta, int unweighted, float p_b, lf_vec3 prev_p, lf_vec3 d)
{
    if (h->light < 0)
        return;
    lf_vec3 Le = lf_light_area_le(&s->lights[h->light], h, d);
    if (!lf_is_black(Le))
        lf_add_bsdf_sampled_light(L, s, lsm, h->light, Le, beta, unweighted, p_b, prev_p, d, h);
}

/* ---- participating media (render/media.c) ---- */
/* Reads the MakeNamedMedium directives into s->media (grid media are
 * refused with their location). */
int lf_media_build(lf_scene_desc *d, lf_scene *s, lf_error *err);
/* Index of a named medium: -1 for NULL or "" (vacuum); an unknown name is
 * an error naming loc. */
int lf_media_lookup(const lf_scene_desc *d, const char *name, const lf_loc *loc, const char *what, int *index,
                    lf_error *err);
/* Radiance along a camera ray that starts in `medium` (volumetric path
 * tracing: absorption, emission, single and multiple scattering with the
 * Henyey-Greenstein phase function, transmittance on shadow rays). */
lf_vec3 lf_volpath_li(const lf_scene *s, const lf_integrator *in, lf_vec3 o, lf_vec3 d, float tau, int medium,
                      lf_sample_stream *st, long long *rays);

#endif
