/* lights.h - the renderer's lights (render/ only): point, spot, distant,
 * infinite (uniform or an equal-area environment map), triangle,
 * parallelogram and sphere area lights; sampling them from a point, their
 * pdfs and powers, and how next-event estimation picks one
 * (render/lights.c). */
#ifndef LF_RENDER_LIGHTS_H
#define LF_RENDER_LIGHTS_H

#include "base/lf_sampler.h"
#include "render/scene.h"

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

struct lf_light {
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
    /* An emitting shape's "alpha" (render/alpha.c): pbrt-v4's area light
     * emits nothing where AlphaMasked says so (has_alpha 0: no alpha). */
    int has_alpha;
    float alpha;
    const struct lf_texture *alpha_tex;
};

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
/* Reads the scene description's light sources into s->lights. */
int lf_scene_build_lights(lf_scene_desc *d, lf_scene *s, lf_error *err);

/* How next-event estimation picks lights ("string lightsampler"). */
typedef enum lf_light_sampler {
    LF_LIGHTS_AUTO,    /* "bvh" (pbrt-v4's default name): ALL up to LF_LIGHTS_ALL_MAX lights, else POWER */
    LF_LIGHTS_POWER,   /* one light per vertex, chosen by power */
    LF_LIGHTS_UNIFORM, /* one light per vertex, chosen uniformly */
    LF_LIGHTS_ALL      /* every light at every vertex (lensfield extension "all") */
} lf_light_sampler;
enum { LF_LIGHTS_ALL_MAX = 8 };

/* Probability that NEE samples light `light` at a vertex (1 when all are). */
double lf_light_pmf(const lf_scene *s, lf_light_sampler ls, int light);

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

#endif
