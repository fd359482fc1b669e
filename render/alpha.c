/* pbrt-v4's "alpha" on any shape: a stochastic cut-out.  pbrt-v4's
 * GeometricPrimitive ignores a hit when a hash of the ray exceeds the alpha
 * there, and traces on from the hit (so the next surface is judged with a
 * fresh hash); camera, indirect and shadow rays alike.  Here the test runs
 * inside Embree, as an intersection and occlusion filter on the shape's
 * geometry, so no ray is re-traced: the hash is of the hit point and the
 * ray direction, which gives every hit along a ray its own independent
 * uniform number as pbrt-v4's re-spawned rays do. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/lf_sampler.h"
#include "render/scene_build.h"

int lf_read_shape_alpha(lf_scene_builder *b, lf_shape_desc *sh)
{
    b->alpha = 1.f;
    b->alpha_tex = NULL;
    lf_paramset *ps = &sh->e.params;
    const lf_param *p = ps->count ? lf_params_peek(ps, "alpha") : NULL;
    if (!p)
        return 0;
    if (p->type == LF_PT_TEXTURE) {
        lf_params_find(ps, "alpha");
        const char *name = p->n_strs ? p->strs[0] : "";
        b->alpha_tex = lf_materials_texture(b->s->materials, name, 1);
        if (!b->alpha_tex)
            return lf_error_at(b->err, LF_ERR_PARAM, &p->loc, "Shape \"%s\": no float texture named \"%s\" for \"alpha\"",
                               sh->e.type, name);
        return 0;
    }
    /* "float alpha": read with the type check every float has */
    double a = lf_params_float(ps, "alpha", 1.0);
    if (!isfinite(a))
        return lf_error_at(b->err, LF_ERR_PARAM, &p->loc, "Shape \"%s\": \"alpha\" must be finite", sh->e.type);
    b->alpha = (float)a;
    return 0;
}

/* A uniform number in [0,1) from a point and a direction (pbrt-v4's
 * HashFloat(o, d) in spirit: a pure function, so renders are repeatable). */
static float hash_float(const float p[3], const float d[3])
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int i = 0; i < 3; i++) {
        uint32_t a, c;
        memcpy(&a, &p[i], 4);
        memcpy(&c, &d[i], 4);
        h = lf_hash_u64(h ^ (((uint64_t)a << 32) | c));
    }
    return (float)(h >> 40) * 0x1p-24f;
}

/* The alpha of mesh me at the hit (triangle prim, barycentrics b1, b2,
 * point p): its constant, or its float texture at pbrt's (u,v). */
static float mesh_alpha_at(const lf_mesh *me, unsigned prim, float b1, float b2, const float p[3])
{
    if (!me->alpha_tex)
        return me->alpha;
    lf_shading_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    int i0 = me->idx[3 * prim], i1 = me->idx[3 * prim + 1], i2 = me->idx[3 * prim + 2];
    float b0 = 1.f - b1 - b2;
    lf_vec2 uv0 = {0, 0}, uv1 = {1, 0}, uv2 = {1, 1}; /* pbrt's defaults */
    if (me->uv) {
        uv0 = (lf_vec2){me->uv[2 * i0], me->uv[2 * i0 + 1]};
        uv1 = (lf_vec2){me->uv[2 * i1], me->uv[2 * i1 + 1]};
        uv2 = (lf_vec2){me->uv[2 * i2], me->uv[2 * i2 + 1]};
    }
    ctx.uv = (lf_vec2){b0 * uv0.x + b1 * uv1.x + b2 * uv2.x, b0 * uv0.y + b1 * uv1.y + b2 * uv2.y};
    ctx.p = lf_v3(p[0], p[1], p[2]);
    ctx.ng = ctx.ns = lf_v3(0, 0, 1);
    return lf_texture_float(me->alpha_tex, &ctx);
}

/* Whether the hit survives the alpha test. */
static int alpha_keeps(const lf_mesh *me, unsigned prim, float b1, float b2, const float o[3], const float d[3],
                       float t)
{
    float p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    float a = mesh_alpha_at(me, prim, b1, b2, p);
    if (a >= 1.f)
        return 1;
    if (!(a > 0.f))
        return 0;
    return hash_float(p, d) <= a;
}

/* One filter for both queries: N is 1 (rtcIntersect1, rtcOccluded1). */
static void alpha_filter(const struct RTCFilterFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0])
        return;
    const lf_mesh *me = a->geometryUserPtr;
    /* With N == 1 the SOA packets are the single-ray structs (the RTCRayN
     * accessors are C++ only). */
    const struct RTCRay *r = (const struct RTCRay *)a->ray;
    const struct RTCHit *h = (const struct RTCHit *)a->hit;
    float o[3] = {r->org_x, r->org_y, r->org_z}, d[3] = {r->dir_x, r->dir_y, r->dir_z};
    if (!alpha_keeps(me, h->primID, h->u, h->v, o, d, r->tfar))
        a->valid[0] = 0;
}

void lf_alpha_attach(RTCGeometry g, const lf_mesh *me)
{
    if (!me->alpha_tex && me->alpha >= 1.f)
        return;
    rtcSetGeometryUserData(g, (void *)me);
    rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
    rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
}

/* Curves: pbrt's (u, v) from Embree's segment parameter and its v across
 * the width (both in [0,1], as pbrt-v4's). */
static void curve_alpha_filter(const struct RTCFilterFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0])
        return;
    const lf_curve *c = a->geometryUserPtr;
    const struct RTCRay *r = (const struct RTCRay *)a->ray;
    const struct RTCHit *h = (const struct RTCHit *)a->hit;
    float o[3] = {r->org_x, r->org_y, r->org_z}, d[3] = {r->dir_x, r->dir_y, r->dir_z};
    float p[3] = {o[0] + r->tfar * d[0], o[1] + r->tfar * d[1], o[2] + r->tfar * d[2]};
    float al = c->alpha;
    if (c->alpha_tex) {
        lf_shading_ctx ctx;
        memset(&ctx, 0, sizeof ctx);
        ctx.uv = (lf_vec2){((float)h->primID + h->u) * c->u_step, h->v};
        ctx.p = lf_v3(p[0], p[1], p[2]);
        ctx.ng = ctx.ns = lf_v3(0, 0, 1);
        al = lf_texture_float(c->alpha_tex, &ctx);
    }
    if (al >= 1.f)
        return;
    if (!(al > 0.f) || hash_float(p, d) > al)
        a->valid[0] = 0;
}

void lf_alpha_attach_curve(RTCGeometry g, const lf_curve *c)
{
    rtcSetGeometryUserData(g, (void *)c);
    if (!c->alpha_tex && c->alpha >= 1.f)
        return;
    rtcSetGeometryIntersectFilterFunction(g, curve_alpha_filter);
    rtcSetGeometryOccludedFilterFunction(g, curve_alpha_filter);
}

int lf_alpha_masked(float alpha, const struct lf_texture *tex, lf_vec3 p, lf_vec2 uv)
{
    float a = alpha;
    if (tex) {
        lf_shading_ctx ctx;
        memset(&ctx, 0, sizeof ctx);
        ctx.p = p, ctx.uv = uv;
        ctx.ng = ctx.ns = lf_v3(0, 0, 1);
        a = lf_texture_float(tex, &ctx);
    }
    if (a >= 1.f)
        return 0;
    if (!(a > 0.f))
        return 1;
    float pp[3] = {p.x, p.y, p.z}, q[3] = {uv.x, uv.y, 0.f};
    return hash_float(pp, q) > a;
}
