/* subsurface.c - Material "subsurface" rendered by a random walk: the
 * volumetric path inside the closed surface, as an equivalent of pbrt-v4's
 * tabulated BSSRDF (photon beam diffusion).
 *
 * A path that the surface's dielectric BSDF refracts inside walks the
 * homogeneous medium (sigma_a, sigma_s, Henyey-Greenstein g): free flights
 * drawn with the spectral MIS of render/volpath.c (one channel chosen
 * uniformly, weight sigma_s T / mean(sigma_t T)), until a flight reaches
 * the surface.  There the walker is reflected back in with the Fresnel
 * reflectance of leaving a medium of index eta (total internal reflection
 * included), or leaves: the exit point becomes a path vertex whose BSDF is
 * pbrt-v4's NormalizedFresnelBxDF (S_w, lf_bsdf_set_normalized_fresnel),
 * so light is sampled there and the path continues as from any surface.
 *
 * Against pbrt-v4: pbrt finds an exit point by probe rays against a
 * diffusion profile fitted for a semi-infinite slab; the walk follows the
 * actual geometry (thin parts transmit, corners lose light as they
 * should) and needs no table.  Both use S_w for the exit direction.  The
 * walk takes the boundary to be the surface it meets next, whatever its
 * material; a walk on an open mesh that escapes is lost. */
#include <math.h>

#include "render/integrator.h"
#include "render/media.h"

/* Walks longer than this are cut (a bias below 1e-6 for albedo <= 0.999). */
#define WALK_MAX_STEPS 8192

static lf_vec3 transmittance(lf_vec3 sigma, float t)
{
    return lf_v3(sigma.x > 0 ? expf(-sigma.x * t) : 1.f, sigma.y > 0 ? expf(-sigma.y * t) : 1.f,
                 sigma.z > 0 ? expf(-sigma.z * t) : 1.f);
}

int lf_subsurface_enters(const lf_material *mat, const lf_hit *h, lf_vec3 wo, lf_vec3 d, lf_subsurface *out)
{
    if (lf_dot(wo, h->sc.ng) * lf_dot(d, h->sc.ng) >= 0.f)
        return 0;
    return lf_material_subsurface(mat, &h->sc, out);
}

/* The walker at the boundary hit b heading along dir leaves (returns 1)
 * or is reflected back (dir updated), by the Fresnel reflectance of the
 * medium-to-outside interface. */
static int boundary(const lf_subsurface *m, const lf_hit *b, lf_vec3 *dir, float u)
{
    float c = lf_dot(*dir, b->sc.ng);
    lf_vec3 n_out = c > 0.f ? b->sc.ng : lf_neg(b->sc.ng);
    float fr = m->eta == 1.f ? 0.f : lf_fresnel_dielectric(-fabsf(c), m->eta);
    if (u >= fr)
        return 1;
    *dir = lf_sub(*dir, lf_scale(n_out, 2.f * lf_dot(*dir, n_out)));
    return 0;
}

int lf_subsurface_walk(const lf_scene *s, const lf_subsurface *m, float tau, lf_sample_stream *st, long long *rays,
                       lf_path_state *ps, lf_hit *h, lf_bsdf *bsdf, lf_vec3 *wo, float *ul)
{
    lf_vec3 sigma_t = lf_add(m->sigma_a, m->sigma_s);
    lf_vec3 dir = *wo; /* on entry: the refracted direction */
    lf_vec3 o = lf_offset_origin(h->sc.p, h->sc.ng, dir);
    for (int step = 0; step < WALK_MAX_STEPS; step++) {
        lf_hit b;
        (*rays)++;
        if (!lf_scene_intersect(s, o, dir, INFINITY, tau, &b))
            return 0; /* an open surface: the walker is lost */
        float uc, ut;
        lf_sample_2d(st, &uc, &ut);
        int c = (int)(uc * 3.f);
        float sc = c <= 0 ? sigma_t.x : c == 1 ? sigma_t.y : sigma_t.z;
        float t = sc > 0.f ? -logf(1.f - ut) / sc : INFINITY;
        if (t < b.t) {
            lf_vec3 T = transmittance(sigma_t, t);
            float pdf = (sigma_t.x * T.x + sigma_t.y * T.y + sigma_t.z * T.z) / 3.f;
            if (!(pdf > 0.f))
                return 0;
            ps->beta = lf_scale(lf_mul(ps->beta, lf_mul(m->sigma_s, T)), 1.f / pdf);
            float u0, u1;
            lf_sample_2d(st, &u0, &u1);
            o = lf_madd(o, dir, t);
            dir = lf_hg_direction(m->g, dir, u0, u1); /* its own pdf: weight 1 */
            /* roulette on the throughput: absorbed walkers end unbiasedly */
            float q = lf_maxc(ps->beta);
            if (q < 1.f && step > 4) {
                if (lf_sample_1d(st) >= q)
                    return 0;
                ps->beta = lf_scale(ps->beta, 1.f / q);
            }
            if (!(lf_maxc(ps->beta) > 0.f))
                return 0;
            continue;
        }
        lf_vec3 T = transmittance(sigma_t, b.t);
        float pass = (T.x + T.y + T.z) / 3.f;
        if (!(pass > 0.f))
            return 0;
        ps->beta = lf_scale(lf_mul(ps->beta, T), 1.f / pass);
        if (!boundary(m, &b, &dir, lf_sample_1d(st))) {
            o = lf_offset_origin(b.sc.p, b.sc.ng, dir);
            continue;
        }
        /* The exit: a vertex with the S_w lobe on the outside. */
        lf_vec3 n_out = lf_dot(dir, b.sc.ng) > 0.f ? b.sc.ng : lf_neg(b.sc.ng);
        *h = b;
        lf_shading_ctx cx = b.sc;
        cx.ns = n_out;
        lf_bsdf_frame(bsdf, &cx);
        lf_bsdf_set_normalized_fresnel(bsdf, m->eta, m->exit_c);
        *wo = n_out;
        ps->eta_scale /= m->eta * m->eta; /* undo the entry's eta^2 */
        float unused;
        lf_sample_2d(st, ul, &unused);
        return 1;
    }
    return 0;
}
