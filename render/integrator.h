/* integrator.h - the integrators (render/ only): their settings, the path
 * (render/path.c) and volumetric path (render/volpath.c) estimators,
 * and the steps both take at a vertex (MIS weights, BSDF continuation,
 * roulette) as inlines so each stays one loop. */
#ifndef LF_RENDER_INTEGRATOR_H
#define LF_RENDER_INTEGRATOR_H

#include <math.h>

#include "base/lf_sampler.h"
#include "render/lights.h"

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
/* Radiance along a camera ray that starts in `medium` (volumetric path
 * tracing: absorption, emission, single and multiple scattering with the
 * Henyey-Greenstein phase function, transmittance on shadow rays). */
lf_vec3 lf_volpath_li(const lf_scene *s, const lf_integrator *in, lf_vec3 o, lf_vec3 d, float tau, int medium,
                      lf_sample_stream *st, long long *rays);

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

/* The path's state between vertices, as both integrators carry it. */
typedef struct lf_path_state {
    lf_vec3 beta;        /* throughput */
    float p_b;           /* the last BSDF sample's pdf (MIS of emission hit next) */
    int specular_bounce; /* the last bounce was a delta lobe */
    float eta_scale;     /* product of eta^2 over transmissions (roulette) */
    lf_vec3 prev_p;      /* the last vertex */
} lf_path_state;

/* Material "subsurface" (render/subsurface.c).  lf_subsurface_enters: did
 * the BSDF sample d at hit h (reached from wo) cross into a subsurface
 * material?  Then lf_subsurface_walk walks its medium from h along *w (the
 * refracted direction) until the walker leaves, and turns the exit into
 * the path's next vertex: *h the exit hit, *bsdf its exit lobe, *w the
 * outward side (the vertex's wo), *ul a fresh light-choice value.
 * Returns 0 when the walk ends inside (absorbed, or lost on an open mesh). */
int lf_subsurface_enters(const lf_material *mat, const lf_hit *h, lf_vec3 wo, lf_vec3 d, lf_subsurface *out);
int lf_subsurface_walk(const lf_scene *s, const lf_subsurface *m, float tau, lf_sample_stream *st, long long *rays,
                       lf_path_state *ps, lf_hit *h, lf_bsdf *bsdf, lf_vec3 *w, float *ul);

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

#endif
