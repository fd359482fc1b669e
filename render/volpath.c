/* The volumetric path tracer (Integrator "volpath", the default) over the
 * homogeneous media of render/media.c.
 *
 * pbrt-v4's VolPathIntegrator restricted to homogeneous media,
 * where the transmittance exp(-sigma_t t) is known in closed form, so no
 * majorant (delta) tracking is needed.  RGB has three extinction
 * coefficients; a scattering distance is drawn from one channel chosen
 * uniformly and weighted by the one-sample MIS (balance heuristic) pdf
 * averaged over the channels (Chiang et al. 2016, "spectral MIS"):
 *   p(t) = 1/3 sum_c sigma_t,c exp(-sigma_t,c t),  P(t >= t_s) = 1/3 sum_c exp(-sigma_t,c t_s),
 * which is unbiased in every channel and never divides by a channel's own
 * small probability.  A purely absorbing medium is not sampled at all:
 * the throughput is multiplied by exp(-sigma_t t_s).  Medium emission is
 * integrated in closed form along each segment, sigma_a Le (1 -
 * exp(-sigma_t t_s)) / sigma_t.  At a scattering vertex the path does next
 * event estimation (shadow rays carry the transmittance of every medium
 * they cross; interface surfaces let them through) MIS-weighted against
 * phase-function sampling, then samples the Henyey-Greenstein lobe
 * exactly (weight 1).  Sample dimensions: one pair per segment (channel,
 * distance), then the four pairs per vertex of the surface integrator. */
#include <math.h>

#include "render/integrator.h"
#include "render/media.h"

/* exp(-sigma t) per channel; a zero coefficient transmits everything, even
 * over an infinite distance. */
static lf_vec3 transmittance(lf_vec3 sigma, float t)
{
    return lf_v3(sigma.x > 0 ? expf(-sigma.x * t) : 1.f, sigma.y > 0 ? expf(-sigma.y * t) : 1.f,
                 sigma.z > 0 ? expf(-sigma.z * t) : 1.f);
}

/* pbrt-v4's Henyey-Greenstein phase function of the angle between wo
 * (towards where the path came from) and wi. */
static float hg_phase(float g, lf_vec3 wo, lf_vec3 wi)
{
    float c = lf_dot(wo, wi);
    float denom = 1 + g * g + 2 * g * c;
    return (1 - g * g) / (4 * (float)LF_PI * denom * sqrtf(fmaxf(denom, 1e-12f)));
}

lf_vec3 lf_hg_direction(float g, lf_vec3 d, float u0, float u1)
{
    float cos_t;
    if (fabsf(g) < 1e-3f) {
        cos_t = 1 - 2 * u0;
    } else {
        float q = (1 - g * g) / (1 - g + 2 * g * u0);
        cos_t = (1 + g * g - q * q) / (2 * g);
    }
    cos_t = fminf(1.f, fmaxf(-1.f, cos_t));
    float sin_t = sqrtf(fmaxf(0.f, 1 - cos_t * cos_t));
    float phi = 2 * (float)LF_PI * u1;
    lf_vec3 t1, t2;
    lf_basis(d, &t1, &t2);
    lf_vec3 wi = lf_add(lf_scale(d, cos_t), lf_add(lf_scale(t1, sin_t * cosf(phi)), lf_scale(t2, sin_t * sinf(phi))));
    return lf_normalize(wi);
}

/* Samples wi around the forward direction d = -wo by the HG lobe; the
 * weight is 1 and the pdf the phase value. */
static lf_vec3 hg_sample(float g, lf_vec3 wo, float u0, float u1, float *pdf)
{
    lf_vec3 wi = lf_hg_direction(g, lf_neg(wo), u0, u1);
    *pdf = hg_phase(g, wo, wi);
    return wi;
}

/* The medium a ray continues in after it leaves a hit towards w. */
static inline int medium_after(const lf_hit *h, lf_vec3 w, int current)
{
    if (h->medium_in == LF_MEDIUM_SAME)
        return current;
    return lf_dot(w, h->sc.ng) > 0 ? h->medium_out : h->medium_in;
}

/* Transmittance of one segment in medium `medium` (>= 0): closed form for
 * homogeneous media, ratio tracking for heterogeneous ones. */
static lf_vec3 medium_tr(const lf_scene *s, int medium, lf_vec3 o, lf_vec3 d, float t)
{
    const lf_medium *m = &s->media[medium];
    if (m->hetero)
        return lf_medium_tr(m, o, d, t, lf_medium_seed(t, 0.f, o, d));
    return transmittance(m->sigma_t, t);
}

/* Transmittance from o along unit d over distance tmax (INFINITY: to the
 * environment), starting in `medium`: interface surfaces (no material)
 * are passed and change the medium, any other surface blocks.  Returns
 * black when blocked. */
static lf_vec3 shadow_tr(const lf_scene *s, lf_vec3 o, lf_vec3 d, float tmax, float tau, int medium,
                         long long *rays)
{
    lf_vec3 T = lf_v3(1, 1, 1);
    for (int pass = 0; pass < 256; pass++) {
        lf_hit h;
        (*rays)++;
        if (!lf_scene_intersect(s, o, d, tmax, tau, &h)) {
            if (medium >= 0)
                T = lf_mul(T, medium_tr(s, medium, o, d, tmax));
            return T;
        }
        if (!lf_material_is_interface(lf_materials_get(s->materials, h.material)))
            return lf_v3(0, 0, 0);
        if (medium >= 0)
            T = lf_mul(T, medium_tr(s, medium, o, d, h.t));
        if (!(lf_maxc(T) > 0))
            return T;
        medium = medium_after(&h, d, medium);
        o = lf_offset_origin(h.sc.p, h.sc.ng, d);
        if (isfinite(tmax))
            tmax -= h.t;
        if (!(tmax > 0))
            return T;
    }
    return lf_v3(0, 0, 0);
}

/* A scattering vertex: a surface (bsdf set) or a point in a medium (g). */
typedef struct vertex {
    lf_vec3 p, wo;
    const lf_hit *h;    /* surface: the hit; NULL in a medium */
    const lf_bsdf *bsdf;
    float g;
    int medium;         /* medium at a medium vertex; at a surface, the ray's medium before the hit */
} vertex;

/* Light li's MIS-weighted contribution at vertex v (pmf: the chance NEE
 * picked it), sampled with (u0, u1). */
static lf_vec3 vol_light_direct(const lf_scene *s, const vertex *v, int li, double pmf, float u0, float u1,
                                float tau, long long *rays)
{
    const lf_light *l = &s->lights[li];
    lf_light_sample ls;
    if (!lf_light_sample_li(s, l, v->p, tau, u0, u1, &ls) || !(ls.pdf > 0) || lf_is_black(ls.Li))
        return lf_v3(0, 0, 0);
    lf_vec3 f;
    float scatter_pdf;
    lf_vec3 o = v->p;
    int medium = v->medium;
    if (v->h) {
        float cosi = lf_absdot(ls.wi, v->bsdf->n);
        f = lf_scale(lf_bsdf_f(v->bsdf, v->wo, ls.wi), cosi);
        if (lf_is_black(f))
            return lf_v3(0, 0, 0);
        scatter_pdf = lf_bsdf_pdf(v->bsdf, v->wo, ls.wi);
        o = lf_offset_origin(v->p, v->h->sc.ng, ls.wi);
        medium = medium_after(v->h, ls.wi, v->medium);
    } else {
        float ph = hg_phase(v->g, v->wo, ls.wi);
        f = lf_v3(ph, ph, ph);
        scatter_pdf = ph;
    }
    float tmax = isinf(ls.dist) ? INFINITY : ls.dist * (1.f - 1e-4f);
    lf_vec3 T = shadow_tr(s, o, ls.wi, tmax, tau, medium, rays);
    if (lf_is_black(T))
        return lf_v3(0, 0, 0);
    float p_l = (float)pmf * ls.pdf;
    float w = ls.delta ? 1.f : lf_power_heuristic(p_l, scatter_pdf);
    return lf_scale(lf_mul(lf_mul(f, ls.Li), T), w / p_l);
}

static lf_vec3 vol_sample_direct(const lf_scene *s, lf_light_sampler lsm, const vertex *v, float ul, float tau,
                                 lf_sample_stream *st, long long *rays)
{
    float u0, u1;
    if (lsm == LF_LIGHTS_ALL) {
        lf_vec3 L = lf_v3(0, 0, 0);
        for (int k = 0; k < s->n_nee_lights; k++) {
            lf_light_pair(&s->lights[s->nee_lights[k]], st, &u0, &u1);
            L = lf_add(L, vol_light_direct(s, v, s->nee_lights[k], 1.0, u0, u1, tau, rays));
        }
        return L;
    }
    double pmf;
    int li = lf_pick_light(s, lsm, ul, &pmf);
    lf_light_pair(&s->lights[li], st, &u0, &u1);
    if (!(pmf > 0))
        return lf_v3(0, 0, 0);
    return vol_light_direct(s, v, li, pmf, u0, u1, tau, rays);
}

/* What a path carries through lf_volpath_li, for medium_scatter. */
typedef struct path_ctx {
    const lf_scene *s;
    const lf_integrator *in;
    lf_light_sampler lsm;
    float tau;
    lf_sample_stream *st;
    long long *rays;
    lf_path_state *ps;
    lf_vec3 *L;
    int *depth;
} path_ctx;

/* A real scattering event in a medium at p (the path came along *d, its
 * weight already includes sigma_s): next-event estimation, then the new
 * direction from the Henyey-Greenstein lobe.  0: the path ends. */
static int medium_scatter(path_ctx *c, float g, int medium, lf_vec3 p, lf_vec3 *o, lf_vec3 *d)
{
    const lf_scene *s = c->s;
    lf_path_state *ps = c->ps;
    if (!(lf_maxc(ps->beta) > 0) || (*c->depth)++ == c->in->max_depth)
        return 0;
    lf_vec3 wo = lf_neg(*d);
    float ul = 0.5f, uunused;
    int need_light_choice = s->n_nee_lights > 1 && c->lsm != LF_LIGHTS_ALL;
    if (need_light_choice)
        lf_sample_2d(c->st, &ul, &uunused);
    else
        lf_sample_skip(c->st);
    if (s->n_nee_lights > 0) {
        vertex v = {p, wo, NULL, NULL, g, medium};
        *c->L = lf_add(*c->L, lf_mul(ps->beta, vol_sample_direct(s, c->lsm, &v, ul, c->tau, c->st, c->rays)));
    } else {
        lf_sample_skip(c->st);
    }
    float u0, u1, ppdf;
    lf_sample_2d(c->st, &u0, &u1);
    *d = hg_sample(g, wo, u0, u1, &ppdf);
    ps->p_b = ppdf;
    ps->specular_bounce = 0;
    ps->prev_p = p;
    *o = p;
    return lf_roulette(c->in, &ps->beta, ps->eta_scale, *c->depth, c->st);
}

/* A segment of length t_s in heterogeneous medium `medium` by delta
 * tracking: -1 the path ends, 0 it reaches the segment's end, 1 it
 * scattered (and *o, *d are the new ray). */
static int hetero_segment(path_ctx *c, int medium, lf_vec3 *o, lf_vec3 *d, float t_s)
{
    const lf_medium *m = &c->s->media[medium];
    float uc, ut, t_ev = 0;
    lf_sample_2d(c->st, &uc, &ut);
    int ev = lf_medium_track(m, *o, *d, t_s, lf_medium_seed(uc, ut, *o, *d), &c->ps->beta, m->emits ? c->L : NULL,
                             &t_ev);
    if (ev <= 0)
        return ev;
    return medium_scatter(c, m->g, medium, lf_madd(*o, *d, t_ev), o, d) ? 1 : -1;
}

lf_vec3 lf_volpath_li(const lf_scene *s, const lf_integrator *in, lf_vec3 o, lf_vec3 d, float tau, int medium,
                      lf_sample_stream *st, long long *rays)
{
    lf_vec3 L = lf_v3(0, 0, 0);
    lf_path_state ps = {lf_v3(1, 1, 1), 1.f, 0, 1.f, o};
    int depth = 0;
    const lf_light_sampler lsm = lf_light_sampler_for(in, s);
    int passes = 0;
    path_ctx pc = {s, in, lsm, tau, st, rays, &ps, &L, &depth};
    for (;;) {
        lf_hit h;
        (*rays)++;
        int hit = lf_scene_intersect(s, o, d, INFINITY, tau, &h);
        float t_s = hit ? h.t : INFINITY;
        if (medium >= 0 && s->media[medium].hetero) {
            int ev = hetero_segment(&pc, medium, &o, &d, t_s);
            if (ev < 0)
                break;
            if (ev > 0)
                continue;
        } else if (medium >= 0) {
            const lf_medium *m = &s->media[medium];
            /* Emission along the whole segment, in closed form. */
            if (m->emits) {
                lf_vec3 T = transmittance(m->sigma_t, t_s), e;
                e.x = m->sigma_t.x > 0 ? m->sigma_a.x * m->Le.x * (1 - T.x) / m->sigma_t.x : 0;
                e.y = m->sigma_t.y > 0 ? m->sigma_a.y * m->Le.y * (1 - T.y) / m->sigma_t.y : 0;
                e.z = m->sigma_t.z > 0 ? m->sigma_a.z * m->Le.z * (1 - T.z) / m->sigma_t.z : 0;
                L = lf_add(L, lf_mul(ps.beta, e));
            }
            float uc, ut;
            lf_sample_2d(st, &uc, &ut);
            if (!m->scatters) {
                ps.beta = lf_mul(ps.beta, transmittance(m->sigma_t, t_s));
            } else {
                int c = (int)(uc * 3.f);
                float sc = c <= 0 ? m->sigma_t.x : c == 1 ? m->sigma_t.y : m->sigma_t.z;
                float t = sc > 0 ? -logf(1.f - ut) / sc : INFINITY;
                if (t < t_s) {
                    /* A scattering event at distance t. */
                    lf_vec3 T = transmittance(m->sigma_t, t);
                    float pdf = (m->sigma_t.x * T.x + m->sigma_t.y * T.y + m->sigma_t.z * T.z) / 3.f;
                    if (!(pdf > 0))
                        break;
                    ps.beta = lf_scale(lf_mul(ps.beta, lf_mul(m->sigma_s, T)), 1.f / pdf);
                    if (!medium_scatter(&pc, m->g, medium, lf_madd(o, d, t), &o, &d))
                        break;
                    continue;
                }
                lf_vec3 T = transmittance(m->sigma_t, t_s);
                float pass = (T.x + T.y + T.z) / 3.f;
                if (!(pass > 0))
                    break;
                ps.beta = lf_scale(lf_mul(ps.beta, T), 1.f / pass);
            }
            if (!(lf_maxc(ps.beta) > 0))
                break;
        } else {
            lf_sample_skip(st);
        }
        if (!hit) {
            lf_add_escaped_light(&L, s, lsm, ps.beta, depth == 0 || ps.specular_bounce, ps.p_b, ps.prev_p, d);
            break;
        }
        lf_vec3 wo = lf_neg(d);
        lf_add_hit_emission(&L, s, lsm, &h, ps.beta, depth == 0 || ps.specular_bounce, ps.p_b, ps.prev_p, d);
        const lf_material *mat = lf_materials_get(s->materials, h.material);
        if (lf_material_is_interface(mat)) {
            /* A medium boundary without a surface: continue, maybe in another medium. */
            medium = medium_after(&h, d, medium);
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
            vertex v = {h.sc.p, wo, &h, &bsdf, 0.f, medium};
            if (!specular && s->n_nee_lights > 0)
                L = lf_add(L, lf_mul(ps.beta, vol_sample_direct(s, lsm, &v, ul, tau, st, rays)));
            else
                lf_sample_skip(st);
            if (!lf_bsdf_continue(&bsdf, &h, wo, uc, st, &ps, &o, &d))
                break;
            if ((alive = walked || !lf_subsurface_enters(mat, &h, wo, d, &sss)))
                break;
            wo = d; /* the walk's medium is the material's, not the scene's */
            if (!lf_subsurface_walk(s, &sss, tau, st, rays, &ps, &h, &bsdf, &wo, &ul))
                break;
            specular = 0;
        }
        if (!alive)
            break;
        medium = medium_after(&h, d, medium);
        if (!lf_roulette(in, &ps.beta, ps.eta_scale, depth, st))
            break;
    }
    return L;
}
