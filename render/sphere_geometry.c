/* Analytic spheres as Embree user geometry: one geometry for the static
 * spheres, one with a time step per keyframe for each moving sphere. */
#include <math.h>
#include <stdint.h>

#include "render/scene_build.h"

/* Measured cheaper per ray than Embree's sphere-point primitive (callgrind:
 * docs/performance.md) and exact.  The intersection follows Haines et al.,
 * "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing Gems,
 * 2019): the discriminant is computed from the vector to the closest point
 * of the line, which keeps small spheres far from the origin accurate. */
static void sphere_bounds_fn(const struct RTCBoundsFunctionArguments *a)
{
    const lf_sphere *sp = (const lf_sphere *)a->geometryUserPtr + a->primID;
    lf_vec3 c = sp->n_keys > 1 ? sp->centers[a->timeStep] : sp->center;
    a->bounds_o->lower_x = c.x - sp->radius;
    a->bounds_o->lower_y = c.y - sp->radius;
    a->bounds_o->lower_z = c.z - sp->radius;
    a->bounds_o->upper_x = c.x + sp->radius;
    a->bounds_o->upper_y = c.y + sp->radius;
    a->bounds_o->upper_z = c.z + sp->radius;
}

/* Static-sphere geometry: moving spheres live in their own geometries and
 * get empty bounds here, which Embree skips. */
static void static_sphere_bounds_fn(const struct RTCBoundsFunctionArguments *a)
{
    const lf_sphere *sp = (const lf_sphere *)a->geometryUserPtr + a->primID;
    if (sp->n_keys > 1) {
        a->bounds_o->lower_x = a->bounds_o->lower_y = a->bounds_o->lower_z = 1.f;
        a->bounds_o->upper_x = a->bounds_o->upper_y = a->bounds_o->upper_z = -1.f;
        return;
    }
    sphere_bounds_fn(a);
}

/* Nearest root in (tnear, tfar), or -1. d need not be unit length. */
static float sphere_hit_t(const lf_sphere *sp, lf_vec3 center, const float o[3], const float dir[3], float tnear,
                          float tfar)
{
    lf_vec3 d = lf_v3(dir[0], dir[1], dir[2]);
    lf_vec3 f = lf_v3(o[0] - center.x, o[1] - center.y, o[2] - center.z);
    float a = lf_dot(d, d);
    float b = -lf_dot(f, d) / a;  /* t of the closest point */
    lf_vec3 l = lf_madd(f, d, b); /* closest point - centre */
    float r2 = sp->radius * sp->radius;
    float disc = r2 - lf_dot(l, l);
    if (disc < 0)
        return -1;
    float c = lf_dot(f, f) - r2;
    float q = b + copysignf(sqrtf(disc / a), b); /* the far-from-cancellation root */
    float t0 = q != 0 ? c / (a * q) : 0, t1 = q;
    if (t0 > t1) {
        float tmp = t0;
        t0 = t1;
        t1 = tmp;
    }
    if (t0 > tnear && t0 < tfar)
        return t0;
    if (t1 > tnear && t1 < tfar)
        return t1;
    return -1;
}

static void sphere_intersect_fn(const struct RTCIntersectFunctionNArguments *a)
{
    if (!a->valid[0])
        return;
    const lf_sphere *sp = (const lf_sphere *)a->geometryUserPtr + a->primID;
    struct RTCRayHit *rh = (struct RTCRayHit *)a->rayhit; /* N == 1: rtcIntersect1 */
    float o[3] = {rh->ray.org_x, rh->ray.org_y, rh->ray.org_z}, d[3] = {rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z};
    lf_vec3 c = lf_sphere_center_at(sp, rh->ray.time);
    float t = sphere_hit_t(sp, c, o, d, rh->ray.tnear, rh->ray.tfar);
    if (t < 0)
        return;
    rh->ray.tfar = t;
    rh->hit.u = rh->hit.v = 0;
    rh->hit.Ng_x = o[0] + t * d[0] - c.x;
    rh->hit.Ng_y = o[1] + t * d[1] - c.y;
    rh->hit.Ng_z = o[2] + t * d[2] - c.z;
    rh->hit.primID = a->primID;
    rh->hit.geomID = a->geomID;
    rh->hit.instID[0] = a->context->instID[0];
}

static void sphere_occluded_fn(const struct RTCOccludedFunctionNArguments *a)
{
    if (!a->valid[0])
        return;
    const lf_sphere *sp = (const lf_sphere *)a->geometryUserPtr + a->primID;
    struct RTCRay *r = (struct RTCRay *)a->ray;
    float o[3] = {r->org_x, r->org_y, r->org_z}, d[3] = {r->dir_x, r->dir_y, r->dir_z};
    if (sphere_hit_t(sp, lf_sphere_center_at(sp, r->time), o, d, r->tnear, r->tfar) >= 0)
        r->tfar = -INFINITY;
}

void lf_attach_spheres(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax)
{
    if (!s->n_spheres)
        return;
    RTCGeometry g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, (unsigned)s->n_spheres);
    rtcSetGeometryUserData(g, s->spheres);
    rtcSetGeometryBoundsFunction(g, static_sphere_bounds_fn, NULL);
    rtcSetGeometryIntersectFunction(g, sphere_intersect_fn);
    rtcSetGeometryOccludedFunction(g, sphere_occluded_fn);
    rtcCommitGeometry(g);
    s->sphere_geom_id = rtcAttachGeometry(s->rtc, g);
    rtcReleaseGeometry(g);
    s->geom_index[s->sphere_geom_id] = INT32_MIN;
    for (int i = 0; i < s->n_spheres; i++) {
        lf_sphere *sp = &s->spheres[i];
        for (int k = 0; k < sp->n_keys; k++) {
            lf_vec3 c = sp->n_keys > 1 ? sp->centers[k] : sp->center;
            *bmin = lf_v3(fminf(bmin->x, c.x - sp->radius), fminf(bmin->y, c.y - sp->radius),
                          fminf(bmin->z, c.z - sp->radius));
            *bmax = lf_v3(fmaxf(bmax->x, c.x + sp->radius), fmaxf(bmax->y, c.y + sp->radius),
                          fmaxf(bmax->z, c.z + sp->radius));
        }
        if (sp->n_keys > 1) {
            /* A moving sphere: its own geometry with one time step per keyframe. */
            RTCGeometry gm = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(gm, 1);
            rtcSetGeometryTimeStepCount(gm, (unsigned)sp->n_keys);
            rtcSetGeometryUserData(gm, sp);
            rtcSetGeometryBoundsFunction(gm, sphere_bounds_fn, NULL);
            rtcSetGeometryIntersectFunction(gm, sphere_intersect_fn);
            rtcSetGeometryOccludedFunction(gm, sphere_occluded_fn);
            rtcCommitGeometry(gm);
            unsigned id = rtcAttachGeometry(s->rtc, gm);
            rtcReleaseGeometry(gm);
            s->geom_index[id] = -1 - i;
            s->moving_shapes++;
            if (sp->n_keys > s->max_keys)
                s->max_keys = sp->n_keys;
        }
    }
}
