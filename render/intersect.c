/* Ray queries on the built scene: the closest hit, with everything the
 * integrators need (shading frame, (u,v) and their derivatives, the
 * instance's motion at the ray's time), and shadow-ray occlusion. */
#include <math.h>
#include <stdint.h>

#include "render/scene_build.h"

/* Embree asserts (and aborts) on a ray whose origin or direction is beyond
 * about 1.8e18 or not finite; the renderer refuses cameras that would make
 * one (renderer.c, check_camera_reach), and any other such ray is a miss
 * here rather than an abort.  NaN fails every comparison. */
static inline int ray_in_range(lf_vec3 o, lf_vec3 d)
{
    const float lim = 1e18f;
    return fabsf(o.x) <= lim && fabsf(o.y) <= lim && fabsf(o.z) <= lim && fabsf(d.x) <= lim && fabsf(d.y) <= lim &&
           fabsf(d.z) <= lim;
}

static void init_ray(struct RTCRayHit *rh, lf_vec3 o, lf_vec3 d, float tmax, float tau)
{
    rh->ray.org_x = o.x, rh->ray.org_y = o.y, rh->ray.org_z = o.z;
    rh->ray.dir_x = d.x, rh->ray.dir_y = d.y, rh->ray.dir_z = d.z;
    rh->ray.tnear = 0.f;
    rh->ray.tfar = tmax;
    rh->ray.time = tau;
    rh->ray.mask = 0xffffffffu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

static inline lf_vec3 rotate(const float R[3][3], lf_vec3 v)
{
    return lf_v3(R[0][0] * v.x + R[0][1] * v.y + R[0][2] * v.z, R[1][0] * v.x + R[1][1] * v.y + R[1][2] * v.z,
                 R[2][0] * v.x + R[2][1] * v.y + R[2][2] * v.z);
}

/* An instance's placement at a ray's time: x -> R (scale * x) + trans. */
typedef struct instance_xf {
    float R[3][3];
    lf_vec3 scale, cof, trans; /* cof: the cofactors of the scale, for normals (see mesh_hit) */
    int uniform_scale;
} instance_xf;

/* pbrt's decomposed interpolation (lf_decomposed_matrix) of an instance's
 * motion at Embree time tau, in float. */
static void instance_motion_at(const lf_instance *in, float tau, instance_xf *xf)
{
    float q[4];
    if (in->nlerp) {
        float l = 0;
        for (int i = 0; i < 4; i++) {
            q[i] = (1 - tau) * in->q0[i] + tau * in->q1[i];
            l += q[i] * q[i];
        }
        l = 1.f / sqrtf(l);
        for (int i = 0; i < 4; i++)
            q[i] *= l;
    } else {
        float phi = tau * in->theta, c = cosf(phi), sn = sinf(phi);
        for (int i = 0; i < 4; i++)
            q[i] = c * in->q0[i] + sn * in->qperp[i];
    }
    float x = q[0], y = q[1], z = q[2], w = q[3];
    float(*R)[3] = xf->R;
    R[0][0] = 1 - 2 * (y * y + z * z), R[0][1] = 2 * (x * y - z * w), R[0][2] = 2 * (x * z + y * w);
    R[1][0] = 2 * (x * y + z * w), R[1][1] = 1 - 2 * (x * x + z * z), R[1][2] = 2 * (y * z - x * w);
    R[2][0] = 2 * (x * z - y * w), R[2][1] = 2 * (y * z + x * w), R[2][2] = 1 - 2 * (x * x + y * y);
    lf_vec3 sc = lf_add(lf_scale(in->scale0, 1 - tau), lf_scale(in->scale1, tau));
    xf->scale = sc;
    xf->cof = lf_v3(sc.y * sc.z, sc.x * sc.z, sc.x * sc.y);
    xf->trans = lf_add(lf_scale(in->trans0, 1 - tau), lf_scale(in->trans1, tau));
    xf->uniform_scale = in->uniform_scale;
}

/* A normal to the world by (R S)^-T = R S^-1, up to the positive factor
 * |det S| (cof(S) = det(S) S^-1). */
static inline lf_vec3 instance_normal(const instance_xf *xf, lf_vec3 n)
{
    return rotate(xf->R, lf_scale(lf_mul(n, xf->cof), xf->cof.x * xf->scale.x < 0 ? -1.f : 1.f));
}

/* The shading context of a hit on triangle t of a mesh whose vertices (and
 * shading normals, or NULL) are p and nsv at the ray's time; b1, b2:
 * Embree's barycentrics; flip: reverse orientation XOR the world
 * transform's handedness swap.  Without xf, p and nsv are in world space.
 * With xf, p is in an instance's prototype space, and so is nsv when the
 * instance scales uniformly (else the caller has taken each vertex normal
 * to the world and normalised it, as the keyframed path does); the frame
 * goes to the world by M = R S: dp/du by M, shading normals by the inverse
 * transpose R S^-1, and the geometric normal, a cross product of edges, by
 * cross(M a, M b) = det(M) M^-T cross(a, b) = R (cof(S) cross(a, b)), which
 * keeps pbrt's orientation.  sc->p is then the caller's to set. */
/* pbrt-v4's triangle derivatives for bump mapping: dp/du, dp/dv from the
 * (u,v) of the corners (a coordinate system around n when degenerate); with
 * vertex normals, pbrt's shading tangents ss = (ns x dpdu) x ns... re-built
 * around the interpolated normal and dn/du, dn/dv from the normals. */
static void mesh_derivs(const lf_mesh *m, int t, const lf_vec3 p[3], const lf_vec3 *nsv, lf_vec3 n, float b0,
                        float b1, float b2, const instance_xf *xf, lf_shading_ctx *sc)
{
    int i0 = m->idx[3 * t], i1 = m->idx[3 * t + 1], i2 = m->idx[3 * t + 2];
    lf_vec2 uv0 = {0, 0}, uv1 = {1, 0}, uv2 = {1, 1};
    if (m->uv) {
        uv0 = (lf_vec2){m->uv[2 * i0], m->uv[2 * i0 + 1]};
        uv1 = (lf_vec2){m->uv[2 * i1], m->uv[2 * i1 + 1]};
        uv2 = (lf_vec2){m->uv[2 * i2], m->uv[2 * i2 + 1]};
    }
    float du02 = uv0.x - uv2.x, du12 = uv1.x - uv2.x, dv02 = uv0.y - uv2.y, dv12 = uv1.y - uv2.y;
    float det = du02 * dv12 - dv02 * du12;
    lf_vec3 dp02 = lf_sub(p[0], p[2]), dp12 = lf_sub(p[1], p[2]);
    lf_vec3 dpdu, dpdv, dndu = lf_v3(0, 0, 0), dndv = lf_v3(0, 0, 0);
    int ok = fabsf(det) >= 1e-9f;
    if (ok) {
        float inv = 1.f / det;
        dpdu = lf_scale(lf_sub(lf_scale(dp02, dv12), lf_scale(dp12, dv02)), inv);
        dpdv = lf_scale(lf_sub(lf_scale(dp12, du02), lf_scale(dp02, du12)), inv);
        lf_vec3 c = lf_cross(dpdu, dpdv);
        ok = lf_dot(c, c) > 0 && isfinite(c.x + c.y + c.z);
        if (ok && xf) {
            dpdu = rotate(xf->R, lf_mul(dpdu, xf->scale));
            dpdv = rotate(xf->R, lf_mul(dpdv, xf->scale));
        }
        if (ok && nsv) {
            lf_vec3 dn1 = lf_sub(nsv[0], nsv[2]), dn2 = lf_sub(nsv[1], nsv[2]);
            dndu = lf_scale(lf_sub(lf_scale(dn1, dv12), lf_scale(dn2, dv02)), inv);
            dndv = lf_scale(lf_sub(lf_scale(dn2, du02), lf_scale(dn1, du12)), inv);
        }
    }
    if (!ok)
        lf_basis(n, &dpdu, &dpdv);
    if (nsv) {
        lf_vec3 ns = lf_normalize(lf_add(lf_add(lf_scale(nsv[0], b0), lf_scale(nsv[1], b1)), lf_scale(nsv[2], b2)));
        lf_vec3 ts = lf_cross(ns, dpdu);
        if (lf_dot(ts, ts) > 0) {
            dpdu = lf_cross(ts, ns);
            dpdv = ts;
        } else {
            lf_basis(ns, &dpdu, &dpdv);
        }
    }
    sc->sdpdu = dpdu;
    sc->sdpdv = dpdv;
    sc->dndu = dndu;
    sc->dndv = dndv;
    sc->has_derivs = 1;
}

static void mesh_hit(const lf_mesh *m, int t, const lf_vec3 p[3], const lf_vec3 *nsv, float b1, float b2, int flip,
                     const instance_xf *xf, lf_hit *hit)
{
    lf_shading_ctx *sc = &hit->sc;
    int i0 = m->idx[3 * t], i1 = m->idx[3 * t + 1], i2 = m->idx[3 * t + 2];
    lf_vec3 p0 = p[0], p1 = p[1], p2 = p[2];
    float b0 = 1.f - b1 - b2;
    sc->p = lf_add(lf_add(lf_scale(p0, b0), lf_scale(p1, b1)), lf_scale(p2, b2));
    /* pbrt-v4 Triangle: n = normalize(cross(p0 - p2, p1 - p2)). */
    lf_vec3 n = lf_cross(lf_sub(p0, p2), lf_sub(p1, p2));
    if (xf)
        n = rotate(xf->R, lf_mul(n, xf->cof));
    n = lf_normalize(n);
    lf_vec2 uv0 = {0, 0}, uv1 = {1, 0}, uv2 = {1, 1};
    if (m->uv) {
        uv0 = (lf_vec2){m->uv[2 * i0], m->uv[2 * i0 + 1]};
        uv1 = (lf_vec2){m->uv[2 * i1], m->uv[2 * i1 + 1]};
        uv2 = (lf_vec2){m->uv[2 * i2], m->uv[2 * i2 + 1]};
    }
    sc->uv = (lf_vec2){b0 * uv0.x + b1 * uv1.x + b2 * uv2.x, b0 * uv0.y + b1 * uv1.y + b2 * uv2.y};
    /* dp/du from the uv parameterisation (pbrt's triangle derivatives). */
    float du02 = uv0.x - uv2.x, du12 = uv1.x - uv2.x, dv02 = uv0.y - uv2.y, dv12 = uv1.y - uv2.y;
    float det = du02 * dv12 - dv02 * du12;
    lf_vec3 dp02 = lf_sub(p0, p2), dp12 = lf_sub(p1, p2);
    lf_vec3 dpdu;
    if (fabsf(det) < 1e-9f) {
        lf_vec3 tt;
        lf_basis(n, &dpdu, &tt);
    } else {
        float inv = 1.f / det;
        dpdu = lf_scale(lf_sub(lf_scale(dp02, dv12), lf_scale(dp12, dv02)), inv);
        if (!(lf_dot(dpdu, dpdu) > 0) || !isfinite(dpdu.x)) {
            lf_vec3 tt;
            lf_basis(n, &dpdu, &tt);
        } else if (xf) {
            dpdu = rotate(xf->R, lf_mul(dpdu, xf->scale));
        }
    }
    sc->dpdu = lf_normalize(dpdu);
    sc->has_derivs = 0;
    if (m->bump)
        mesh_derivs(m, t, p, nsv, n, b0, b1, b2, xf, sc);
    if (nsv) {
        lf_vec3 ns = lf_add(lf_add(lf_scale(nsv[0], b0), lf_scale(nsv[1], b1)), lf_scale(nsv[2], b2));
        if (xf && xf->uniform_scale) /* the vertex normals' lengths all scale alike: blend, then transform */
            ns = instance_normal(xf, ns);
        ns = lf_normalize(ns);
        if (!(lf_dot(ns, ns) > 0))
            ns = n;
        /* pbrt: the geometric normal follows the shading normal's side. */
        if (lf_dot(n, ns) < 0)
            n = lf_neg(n);
        sc->ns = ns;
    } else {
        if (flip)
            n = lf_neg(n);
        sc->ns = n;
    }
    sc->ng = n;
    hit->material = m->material;
    hit->light = m->light_first >= 0 ? m->light_first + (m->light_quads ? t >> 1 : t) : -1;
    hit->medium_in = m->medium_in;
    hit->medium_out = m->medium_out;
}

int lf_scene_intersect(const lf_scene *s, lf_vec3 o, lf_vec3 d, float tmax, float tau, lf_hit *hit)
{
    if (!ray_in_range(o, d))
        return 0;
    struct RTCRayHit rh;
    init_ray(&rh, o, d, tmax, tau);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(s->rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    hit->t = rh.ray.tfar;
    hit->curve = 0;
    hit->curve_h = 0;
    lf_shading_ctx *sc = &hit->sc;
    int gi = rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID ? s->geom_index[rh.hit.geomID] : 0;
    if (gi < 0) {
        int si = gi == INT32_MIN ? (int)rh.hit.primID : -1 - gi;
        const lf_sphere *sp = &s->spheres[si];
        lf_vec3 c = lf_sphere_center_at(sp, tau);
        lf_vec3 p = lf_madd(o, d, rh.ray.tfar);
        lf_vec3 n = lf_normalize(lf_sub(p, c));
        p = lf_madd(c, n, sp->radius); /* re-project onto the surface */
        /* Object-space direction of the hit: the tangent dp/du and, when a
         * texture needs it, pbrt's (u,v) (lf_scene_sphere_uv) derive from it. */
        const double(*wo)[4] = sp->object_to_world.inv; /* world -> object, linear part */
        lf_vec3 dw = lf_sub(p, c);
        lf_vec3 q = lf_v3((float)(wo[0][0] * dw.x + wo[0][1] * dw.y + wo[0][2] * dw.z),
                          (float)(wo[1][0] * dw.x + wo[1][1] * dw.y + wo[1][2] * dw.z),
                          (float)(wo[2][0] * dw.x + wo[2][1] * dw.y + wo[2][2] * dw.z));
        sc->uv = (lf_vec2){0, 0};
        hit->sphere = si;
        hit->tau = tau;
        lf_vec3 dpdu_o = lf_v3(-q.y, q.x, 0);
        if (dpdu_o.x == 0 && dpdu_o.y == 0)
            dpdu_o = lf_v3(1, 0, 0);
        sc->dpdu = lf_normalize(lf_xform_vector(&sp->object_to_world, dpdu_o));
        sc->p = p;
        sc->has_derivs = 0;
        if (sp->bump) {
            /* pbrt-v4's full sphere: u = phi / 2pi, v from the bottom pole,
             * dp/du = 2pi (-y, x, 0), dp/dv = -pi (z cos phi, z sin phi,
             * -r sin theta) in object space; dn = dp / r (Weingarten). */
            float rho = sqrtf(q.x * q.x + q.y * q.y), r_o = lf_length(q);
            float cp = rho > 0 ? q.x / rho : 1.f, spn = rho > 0 ? q.y / rho : 0.f;
            lf_vec3 du_o = lf_v3(-2 * (float)LF_PI * q.y, 2 * (float)LF_PI * q.x, 0);
            lf_vec3 dv_o = lf_scale(lf_v3(q.z * cp, q.z * spn, -rho), -(float)LF_PI);
            sc->sdpdu = lf_xform_vector(&sp->object_to_world, du_o);
            sc->sdpdv = lf_xform_vector(&sp->object_to_world, dv_o);
            float inv_r = r_o > 0 ? 1.f / r_o : 0.f;
            sc->dndu = lf_scale(sc->sdpdu, inv_r * r_o / sp->radius);
            sc->dndv = lf_scale(sc->sdpdv, inv_r * r_o / sp->radius);
            sc->has_derivs = 1;
        }
        if (sp->flip_normal)
            n = lf_neg(n);
        sc->ng = sc->ns = n;
        hit->material = sp->material;
        hit->light = sp->light;
        hit->medium_in = sp->medium_in;
        hit->medium_out = sp->medium_out;
        return 1;
    }
    hit->sphere = -1;
    hit->tau = tau;
    int t = (int)rh.hit.primID;
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
        /* A rigidly moving instance: the hit is in its prototype's space.
         * The world point is where Embree found it on the ray; normals,
         * tangent and uv are computed in the prototype's space and go to the
         * world by pbrt's decomposed motion at the ray's time
         * (instance_motion_at: ~100 instructions where rtcGetGeometryTransform
         * takes ~470; Embree's slerp, with its fast acos, agrees with it to
         * ~2e-6 per matrix element). */
        const lf_instance *in = &s->instances[s->geom_index[rh.hit.instID[0]]];
        const lf_mesh *m = &s->meshes[s->protos[in->proto].mesh_first + (int)rh.hit.geomID];
        instance_xf xf;
        instance_motion_at(in, tau, &xf);
        lf_vec3 p[3], nv[3];
        for (int k = 0; k < 3; k++) {
            const float *q = m->P + 3 * (size_t)m->idx[3 * t + k];
            p[k] = lf_v3(q[0], q[1], q[2]);
            if (m->N) {
                q = m->N + 3 * (size_t)m->idx[3 * t + k];
                nv[k] = lf_v3(q[0], q[1], q[2]);
            }
        }
        if (m->N && !xf.uniform_scale) /* as the keyframed path: each vertex normal to the world, normalised */
            for (int k = 0; k < 3; k++)
                nv[k] = lf_normalize(instance_normal(&xf, nv[k]));
        int swap = xf.cof.x * xf.scale.x < 0; /* det S < 0 */
        mesh_hit(m, t, p, m->N ? nv : NULL, rh.hit.u, rh.hit.v, m->flip_normal ^ swap, &xf, hit);
        sc->p = lf_madd(o, d, rh.ray.tfar);
        return 1;
    }
    if (gi >= s->n_meshes) {
        lf_curve_hit(&s->curves[gi - s->n_meshes], rh.hit.primID, rh.hit.u, o, d, rh.ray.tfar, hit);
        hit->tau = tau;
        return 1;
    }
    const lf_mesh *m = &s->meshes[gi];
    int i0 = m->idx[3 * t], i1 = m->idx[3 * t + 1], i2 = m->idx[3 * t + 2];
    lf_vec3 p[3] = {lf_mesh_vertex_at(m, i0, tau), lf_mesh_vertex_at(m, i1, tau), lf_mesh_vertex_at(m, i2, tau)};
    lf_vec3 nw[3];
    if (m->N) {
        nw[0] = lf_mesh_normal_at(m, i0, tau);
        nw[1] = lf_mesh_normal_at(m, i1, tau);
        nw[2] = lf_mesh_normal_at(m, i2, tau);
    }
    mesh_hit(m, t, p, m->N ? nw : NULL, rh.hit.u, rh.hit.v, m->flip_normal, NULL, hit);
    return 1;
}

void lf_scene_sphere_uv(const lf_scene *s, lf_hit *hit)
{
    if (hit->sphere < 0)
        return;
    const lf_sphere *sp = &s->spheres[hit->sphere];
    const double(*wo)[4] = sp->object_to_world.inv;
    lf_vec3 dw = lf_sub(hit->sc.p, lf_sphere_center_at(sp, hit->tau));
    lf_vec3 q = lf_normalize(lf_v3((float)(wo[0][0] * dw.x + wo[0][1] * dw.y + wo[0][2] * dw.z),
                                   (float)(wo[1][0] * dw.x + wo[1][1] * dw.y + wo[1][2] * dw.z),
                                   (float)(wo[2][0] * dw.x + wo[2][1] * dw.y + wo[2][2] * dw.z)));
    /* pbrt's sphere: phi around z, theta from +z; u = phi / 2pi, v = (theta - pi) / -pi */
    float phi = atan2f(q.y, q.x);
    if (phi < 0)
        phi += (float)(2 * LF_PI);
    float theta = acosf(lf_clampf(q.z, -1, 1));
    hit->sc.uv = (lf_vec2){phi * (float)LF_INV_2PI, (theta - (float)LF_PI) / (float)-LF_PI};
}

int lf_scene_occluded(const lf_scene *s, lf_vec3 o, lf_vec3 d, float tmax, float tau)
{
    if (!ray_in_range(o, d))
        return 0;
    struct RTCRay r;
    r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
    r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
    r.tnear = 0.f;
    r.tfar = tmax;
    r.time = tau;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcOccluded1(s->rtc, &ctx, &r);
    return r.tfar < 0.f;
}
