/* Unidirectional path tracing with next-event estimation and multiple
 * importance sampling (power heuristic), Russian roulette and maxdepth,
 * following pbrt-v4's PathIntegrator so that scenes converge to the same
 * images.  Per bounce the sampler uses four dimension pairs, in this order:
 *   (light choice, BSDF lobe choice), light position, BSDF direction,
 *   (roulette, unused);
 * when every light is sampled at every vertex ("lightsampler" "all", and
 * "bvh" with few lights), the light position takes one pair per light.
 * A pair nobody needs (one light and a one-lobe BSDF; no roulette yet) is
 * skipped without computing it: samples are the most expensive part of a
 * path after ray casting. */
#include <math.h>
#include <stdlib.h>

#include "render/integrator.h"

/* Light li's direct contribution at a non-specular surface, sampled with
 * (u0, u1) and chosen with probability pmf; MIS-weighted. */
static lf_vec3 light_direct(const lf_scene *s, const lf_hit *h, const lf_bsdf *bsdf, lf_vec3 wo, int li, double pmf,
                            float u0, float u1, long long *rays)
{
    const lf_light *l = &s->lights[li];
    lf_light_sample ls;
    if (!lf_light_sample_li(s, l, h->sc.p, h->tau, u0, u1, &ls) || !(ls.pdf > 0) || lf_is_black(ls.Li))
        return lf_v3(0, 0, 0);
    lf_vec3 f = lf_bsdf_f(bsdf, wo, ls.wi);
    float cosi = lf_absdot(ls.wi, bsdf->n); /* the (maybe bumped) shading normal */
    if (lf_is_black(f) || cosi == 0)
        return lf_v3(0, 0, 0);
    lf_vec3 o = lf_offset_origin(h->sc.p, h->sc.ng, ls.wi);
    float tmax = isinf(ls.dist) ? INFINITY : ls.dist * (1.f - 1e-4f);
    (*rays)++;
    if (lf_scene_occluded(s, o, ls.wi, tmax, h->tau))
        return lf_v3(0, 0, 0);
    float p_l = (float)pmf * ls.pdf;
    float w = 1.f;
    if (!ls.delta)
        w = lf_power_heuristic(p_l, lf_bsdf_pdf(bsdf, wo, ls.wi));
    return lf_scale(lf_mul(f, ls.Li), cosi * w / p_l);
}

/* Direct lighting at a non-specular surface: every light once (ALL), or
 * one light chosen with ul. */
static lf_vec3 sample_direct(const lf_scene *s, lf_light_sampler lsm, const lf_hit *h, const lf_bsdf *bsdf,
                             lf_vec3 wo, float ul, lf_sample_stream *st, long long *rays)
{
    float u0, u1;
    if (lsm == LF_LIGHTS_ALL) {
        lf_vec3 L = lf_v3(0, 0, 0);
        for (int k = 0; k < s->n_nee_lights; k++) {
            lf_light_pair(&s->lights[s->nee_lights[k]], st, &u0, &u1);
            L = lf_add(L, light_direct(s, h, bsdf, wo, s->nee_lights[k], 1.0, u0, u1, rays));
        }
        return L;
    }
    double pmf;
    int li = lf_pick_light(s, lsm, ul, &pmf);
    lf_light_pair(&s->lights[li], st, &u0, &u1);
    if (!(pmf > 0))
        return lf_v3(0, 0, 0);
    return light_direct(s, h, bsdf, wo, li, pmf, u0, u1, rays);
}

lf_vec3 lf_path_li(const lf_scene *s, const lf_integrator *in, lf_vec3 o, lf_vec3 d, float tau, lf_sample_stream *st,
                   long long *rays)
{
    lf_vec3 L = lf_v3(0, 0, 0);
    lf_path_state ps = {lf_v3(1, 1, 1), 1.f, 0, 1.f, o};
    int depth = 0;
    const lf_light_sampler lsm = lf_light_sampler_for(in, s);
    int passes = 0;
    for (;;) {
        lf_hit h;
        (*rays)++;
        if (!lf_scene_intersect(s, o, d, INFINITY, tau, &h)) {
            lf_add_escaped_light(&L, s, lsm, ps.beta, depth == 0 || ps.specular_bounce, ps.p_b, ps.prev_p, d);
            break;
        }
        lf_vec3 wo = lf_neg(d);
        lf_add_hit_emission(&L, s, lsm, &h, ps.beta, depth == 0 || ps.specular_bounce, ps.p_b, ps.prev_p, d);
        const lf_material *mat = lf_materials_get(s->materials, h.material);
        if (lf_material_is_interface(mat)) {
            /* No surface here (pbrt "interface"): continue the ray unchanged. */
            o = lf_offset_origin(h.sc.p, h.sc.ng, d);
            if (++passes > 256)
                break;
            continue;
        }
        if (depth++ == in->max_depth)
            break;
        lf_bsdf bsdf;
        float ul, uc;
        int specular = lf_surface_vertex(s, lsm, &h, mat, st, &bsdf, &ul, &uc), alive = 0;
        lf_subsurface sss;
        for (int walked = 0;; walked = 1) { /* the vertex; for subsurface, then the walk's exit */
            if (!specular && s->n_nee_lights > 0)
                L = lf_add(L, lf_mul(ps.beta, sample_direct(s, lsm, &h, &bsdf, wo, ul, st, rays)));
            else
                lf_sample_skip(st);
            if (!lf_bsdf_continue(&bsdf, &h, wo, uc, st, &ps, &o, &d))
                break;
            if ((alive = walked || !lf_subsurface_enters(mat, &h, wo, d, &sss)))
                break;
            wo = d;
            if (!lf_subsurface_walk(s, &sss, tau, st, rays, &ps, &h, &bsdf, &wo, &ul))
                break;
            specular = 0;
        }
        if (!alive)
            break;
        /* Russian roulette (render_internal.h).  pbrt-v4's rule: p = max
         * component, after depth 1.  The default, "sqrt": p = sqrt(max
         * component) (Cycles' rule), and not before depth 2: ending paths
         * early kills the bright direct light their next vertices would have
         * gathered, which costs far more variance than the rays it saves
         * (docs/performance.md, issue 21). */
        if (!lf_roulette(in, &ps.beta, ps.eta_scale, depth, st))
            break;
    }
    return L;
}
