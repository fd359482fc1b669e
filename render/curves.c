/* pbrt-v4's Shape "curve" on Embree's curve primitives.
 *
 * Parameters as pbrt-v4's CreateCurves: "point3 P" control points,
 * "string basis" "bezier" (default) or "bspline", "integer degree" 3 or 2,
 * "string type" "flat" (default), "cylinder" or "ribbon", "float width"
 * (1) or "width0"/"width1" (linear along the whole curve), "normal N" (one
 * per segment end, ribbons only), "integer splitdepth" (accepted: Embree
 * intersects the curve directly, with no subdivision).  Every segment
 * becomes a cubic Bezier with its own 4 control points: B-splines by the
 * change of basis, quadratics by degree elevation, as pbrt-v4 converts
 * them.  The radius control values are w/2 at thirds of the segment's
 * width ramp, so the Bezier interpolates the width linearly as pbrt does.
 *
 * Hits follow pbrt-v4's Curve::Intersect: u runs along the whole curve,
 * v across the width (v = 1/2 on the centre line, towards dp/dv =
 * cross(ray direction, dp/du) for flat curves and cross(n, dp/du) for
 * ribbons); the normal is cross(dp/du, dp/dv), bent by lerp(v, -90, 90)
 * degrees about dp/du for "cylinder". */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/media.h"
#include "render/scene_build.h"

typedef struct curve_build {
    lf_vec3 *bz;    /* 4 object-space control points per segment */
    float *w;       /* width at both ends, 2 per segment */
    lf_vec3 *n;     /* ribbon: normals at both ends, 2 per segment, else NULL */
    int n_segs;
    int tess; /* Embree tessellation rate */
} curve_build;

static lf_vec3 lerp3(float t, lf_vec3 a, lf_vec3 b) { return lf_add(a, lf_scale(lf_sub(b, a), t)); }

/* The 4 cubic Bezier control points of segment k of P. */
static void segment_bezier(const lf_vec3 *P, int k, int degree, int bspline, lf_vec3 out[4])
{
    if (degree == 3 && !bspline) {
        memcpy(out, P + 3 * k, 4 * sizeof *out);
    } else if (degree == 3) {
        /* uniform cubic B-spline -> Bezier (the change of basis) */
        const lf_vec3 *p = P + k;
        out[0] = lf_scale(lf_add(lf_add(p[0], lf_scale(p[1], 4)), p[2]), 1.f / 6);
        out[1] = lf_scale(lf_add(lf_scale(p[1], 2), p[2]), 1.f / 3);
        out[2] = lf_scale(lf_add(p[1], lf_scale(p[2], 2)), 1.f / 3);
        out[3] = lf_scale(lf_add(lf_add(p[1], lf_scale(p[2], 4)), p[3]), 1.f / 6);
    } else {
        lf_vec3 q[3];
        if (!bspline) {
            memcpy(q, P + 2 * k, 3 * sizeof *q);
        } else { /* quadratic B-spline -> quadratic Bezier */
            const lf_vec3 *p = P + k;
            q[0] = lf_scale(lf_add(p[0], p[1]), 0.5f);
            q[1] = p[1];
            q[2] = lf_scale(lf_add(p[1], p[2]), 0.5f);
        }
        /* degree elevation: the same curve as a cubic */
        out[0] = q[0];
        out[1] = lerp3(2.f / 3, q[0], q[1]);
        out[2] = lerp3(2.f / 3, q[2], q[1]);
        out[3] = q[2];
    }
}

/* Reads the parameters into object-space Bezier segments. */
static int read_curve(lf_scene_builder *b, lf_shape_desc *sh, int *type, curve_build *cb)
{
    lf_paramset *ps = &sh->e.params;
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    size_t np = 0, nn = 0;
    const double *P = lf_params_nums(ps, "P", LF_PT_POINT3, &np);
    const double *N = lf_params_nums(ps, "N", LF_PT_NORMAL3, &nn);
    const char *basis = lf_params_string(ps, "basis", "bezier");
    const char *ts = lf_params_string(ps, "type", "flat");
    int degree = lf_params_int(ps, "degree", 3);
    float width = (float)lf_params_float(ps, "width", 1.0);
    float w0 = (float)lf_params_float(ps, "width0", width), w1 = (float)lf_params_float(ps, "width1", width);
    int split = lf_params_int(ps, "splitdepth", 3);
    cb->tess = 1 << (split < 4 ? 4 : split > 8 ? 8 : split);
    if (ps->error.code)
        return lf_params_finish(ps, "Shape \"curve\"", b->err);
    int bspline = !strcmp(basis, "bspline");
    if (!bspline && strcmp(basis, "bezier"))
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"curve\": basis \"%s\" (expected \"bezier\" or \"bspline\")",
                            where, basis);
    *type = !strcmp(ts, "flat") ? LF_CURVE_FLAT : !strcmp(ts, "cylinder") ? LF_CURVE_CYLINDER
                                               : !strcmp(ts, "ribbon") ? LF_CURVE_RIBBON : -1;
    if (*type < 0)
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: Shape \"curve\": type \"%s\" (expected \"flat\", \"cylinder\" or \"ribbon\")", where, ts);
    if (degree != 2 && degree != 3)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"curve\": degree %d (expected 2 or 3)", where, degree);
    int n = (int)(np / 3);
    int segs = bspline ? n - degree : (n - 1) / degree;
    if (!P || np % 3 || n < degree + 1 || (!bspline && (n - 1) % degree))
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: Shape \"curve\": %d control points do not make %s segments of degree %d", where, n,
                            basis, degree);
    if (*type == LF_CURVE_RIBBON && (!N || nn != 3 * (size_t)(segs + 1)))
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: Shape \"curve\": a ribbon needs \"normal N\" with %d normals (one per segment end), got "
                            "%zu",
                            where, segs + 1, nn / 3);
    if (*type != LF_CURVE_RIBBON && N)
        lf_warn_at(&b->s->warnings, &sh->e.loc, "curve normals \"N\" are only used by ribbons; ignored");
    if (!(w0 >= 0) || !(w1 >= 0) || !isfinite(w0) || !isfinite(w1))
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"curve\": widths must be finite and >= 0", where);
    lf_vec3 *pts = malloc(sizeof *pts * (size_t)n);
    cb->bz = malloc(sizeof *cb->bz * 4 * (size_t)segs);
    cb->w = malloc(sizeof *cb->w * 2 * (size_t)segs);
    cb->n = *type == LF_CURVE_RIBBON ? malloc(sizeof *cb->n * 2 * (size_t)segs) : NULL;
    if (!pts || !cb->bz || !cb->w || (*type == LF_CURVE_RIBBON && !cb->n)) {
        free(pts);
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; i < n; i++)
        pts[i] = lf_v3((float)P[3 * i], (float)P[3 * i + 1], (float)P[3 * i + 2]);
    for (int k = 0; k < segs; k++) {
        segment_bezier(pts, k, degree, bspline, cb->bz + 4 * k);
        cb->w[2 * k] = lf_lerpf((float)k / segs, w0, w1);
        cb->w[2 * k + 1] = lf_lerpf((float)(k + 1) / segs, w0, w1);
        if (cb->n)
            for (int e = 0; e < 2; e++)
                cb->n[2 * k + e] = lf_v3((float)N[3 * (k + e)], (float)N[3 * (k + e) + 1], (float)N[3 * (k + e) + 2]);
    }
    free(pts);
    cb->n_segs = segs;
    return 0;
}

static int push_curve(lf_scene_builder *b, const lf_curve *c)
{
    if (b->s->n_curves == b->cap_curves) {
        int nc = b->cap_curves ? 2 * b->cap_curves : 8;
        lf_curve *a = realloc(b->s->curves, sizeof *a * (size_t)nc);
        if (!a)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        b->s->curves = a;
        b->cap_curves = nc;
    }
    b->s->curves[b->s->n_curves++] = *c;
    return 0;
}

/* World-space Embree buffers from the object-space segments. */
static int world_curve(lf_scene_builder *b, const lf_transform *xf, const curve_build *cb, lf_curve *c)
{
    /* widths scale with the transform's mean linear scale (cube root of
     * |det|): exact for similarity transforms, which is what curves get */
    double det = 0;
    const double(*m)[4] = xf->m;
    det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
          m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    float scale = (float)cbrt(fabs(det));
    size_t ncp = 4 * (size_t)cb->n_segs;
    c->cp = malloc(sizeof(float) * 4 * ncp);
    c->first = malloc(sizeof(unsigned) * (size_t)cb->n_segs);
    c->nrm = cb->n ? malloc(sizeof(float) * (3 * ncp + 1)) : NULL;
    if (!c->cp || !c->first || (cb->n && !c->nrm))
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    for (int k = 0; k < cb->n_segs; k++) {
        c->first[k] = 4u * (unsigned)k;
        for (int j = 0; j < 4; j++) {
            lf_vec3 p = lf_xform_point(xf, cb->bz[4 * k + j]);
            float *q = c->cp + 4 * (4 * (size_t)k + j);
            q[0] = p.x, q[1] = p.y, q[2] = p.z;
            q[3] = 0.5f * scale * lf_lerpf(j / 3.f, cb->w[2 * k], cb->w[2 * k + 1]);
            if (c->nrm) {
                /* the normal's Bezier: n0 twice, then n1 twice */
                lf_vec3 nv = lf_normalize(lf_xform_normal(xf, cb->n[2 * k + (j >= 2)]));
                float *r = c->nrm + 3 * (4 * (size_t)k + j);
                r[0] = nv.x, r[1] = nv.y, r[2] = nv.z;
            }
            if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2]) || !isfinite(q[3]))
                return lf_error_set(b->err, LF_ERR_NUMERIC, "Shape \"curve\": a control point is not finite");
        }
    }
    if (c->nrm)
        c->nrm[3 * ncp] = 0; /* padding: Embree reads with 16-byte loads */
    c->n_segs = cb->n_segs;
    c->u_step = 1.f / (float)cb->n_segs;
    c->tess = cb->tess;
    return 0;
}

int lf_build_curve(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
{
    if (sh->area_light >= 0) {
        if (!b->d->allow_unsupported)
            return lf_error_at(b->err, LF_ERR_UNSUPPORTED, &sh->e.loc,
                               "area lights on Shape \"curve\" are not supported (--allow-unsupported renders the "
                               "curve without emission)");
        lf_warn_at(&b->s->warnings, &sh->e.loc, "area lights on curves are not supported; the curve does not emit");
    }
    if (mo->n > 1)
        lf_warn_at(&b->s->warnings, &sh->e.loc, "moving curves are not supported; the curve stays where it is at the "
                                                "shutter's opening");
    curve_build cb = {0};
    lf_curve c = {0};
    int rc = read_curve(b, sh, &c.type, &cb);
    if (!rc)
        rc = world_curve(b, &mo->keys[0], &cb, &c);
    free(cb.bz), free(cb.w), free(cb.n);
    c.material = sh->material;
    c.flip_normal = sh->reverse_orientation ^ lf_transform_swaps_handedness(&mo->keys[0]);
    c.alpha = b->alpha;
    c.alpha_tex = b->alpha_tex;
    c.medium_in = c.medium_out = LF_MEDIUM_SAME;
    if (!rc && (sh->medium_inside || sh->medium_outside)) {
        int i, o;
        rc = lf_media_lookup(b->d, sh->medium_inside, &sh->e.loc, "MediumInterface (inside)", &i, b->err) ||
             lf_media_lookup(b->d, sh->medium_outside, &sh->e.loc, "MediumInterface (outside)", &o, b->err);
        if (!rc && i != o)
            c.medium_in = i, c.medium_out = o;
    }
    if (!rc)
        rc = push_curve(b, &c);
    if (rc) {
        free(c.cp), free(c.first), free(c.nrm);
        return b->err->code ? b->err->code : rc;
    }
    return 0;
}

void lf_attach_curves(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax)
{
    for (int k = 0; k < s->n_curves; k++) {
        lf_curve *c = &s->curves[k];
        RTCGeometry g = rtcNewGeometry(s->device, c->type == LF_CURVE_RIBBON ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE
                                                                            : RTC_GEOMETRY_TYPE_FLAT_BEZIER_CURVE);
        size_t ncp = 4 * (size_t)c->n_segs;
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, c->cp, 0, 4 * sizeof(float), ncp);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, c->first, 0, sizeof(unsigned),
                                   (size_t)c->n_segs);
        if (c->nrm)
            rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, c->nrm, 0, 3 * sizeof(float),
                                       ncp);
        /* Embree intersects flat and ribbon curves as this many ray-facing
         * quads per segment (its default, 4, shortens bent curves' silhouettes
         * by a few %): 2^splitdepth as pbrt-v4's subdivision, at least 16 */
        rtcSetGeometryTessellationRate(g, (float)c->tess);
        lf_alpha_attach_curve(g, c);
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(s->rtc, g);
        rtcReleaseGeometry(g);
        s->geom_index[id] = s->n_meshes + k;
        /* control points bound a Bezier (convex hull), widened by the radius */
        for (size_t i = 0; i < ncp; i++) {
            const float *q = c->cp + 4 * i;
            *bmin = lf_v3(fminf(bmin->x, q[0] - q[3]), fminf(bmin->y, q[1] - q[3]), fminf(bmin->z, q[2] - q[3]));
            *bmax = lf_v3(fmaxf(bmax->x, q[0] + q[3]), fmaxf(bmax->y, q[1] + q[3]), fmaxf(bmax->z, q[2] + q[3]));
        }
    }
}

void lf_curves_free(lf_scene *s)
{
    for (int k = 0; k < s->n_curves; k++)
        free(s->curves[k].cp), free(s->curves[k].first), free(s->curves[k].nrm);
    free(s->curves);
    s->curves = NULL;
    s->n_curves = 0;
}

/* Cubic Bezier value and derivative of 4 control values, stride apart. */
static void bezier(const float *c, int stride, int dim, float u, float *val, float *der)
{
    float v = 1 - u;
    float b0 = v * v * v, b1 = 3 * u * v * v, b2 = 3 * u * u * v, b3 = u * u * u;
    float d0 = -3 * v * v, d1 = 3 * v * v - 6 * u * v, d2 = 6 * u * v - 3 * u * u, d3 = 3 * u * u;
    for (int i = 0; i < dim; i++) {
        float p0 = c[i], p1 = c[stride + i], p2 = c[2 * stride + i], p3 = c[3 * stride + i];
        val[i] = b0 * p0 + b1 * p1 + b2 * p2 + b3 * p3;
        if (der)
            der[i] = d0 * p0 + d1 * p1 + d2 * p2 + d3 * p3;
    }
}

/* Rodrigues: v rotated by angle a (radians) about unit axis k. */
static lf_vec3 rotate_about(lf_vec3 v, lf_vec3 k, float a)
{
    float c = cosf(a), s = sinf(a);
    return lf_add(lf_add(lf_scale(v, c), lf_scale(lf_cross(k, v), s)), lf_scale(k, lf_dot(k, v) * (1 - c)));
}

void lf_curve_hit(const lf_curve *c, unsigned prim, float u, lf_vec3 o, lf_vec3 d, float t, lf_hit *hit)
{
    const float *cp = c->cp + 16 * (size_t)prim;
    float val[4], der[4];
    bezier(cp, 4, 4, u, val, der);
    lf_vec3 C = lf_v3(val[0], val[1], val[2]), T = lf_v3(der[0], der[1], der[2]);
    float width = 2 * val[3];
    lf_vec3 p = lf_madd(o, d, t);
    lf_vec3 Tn = lf_normalize(T);
    if (!(lf_dot(Tn, Tn) > 0))
        lf_basis(lf_normalize(d), &Tn, &C); /* a degenerate tangent: any direction across the ray */
    lf_vec3 across;
    if (c->nrm) {
        float nv[3];
        bezier(c->nrm + 12 * (size_t)prim, 3, 3, u, nv, NULL);
        across = lf_normalize(lf_cross(lf_v3(nv[0], nv[1], nv[2]), Tn));
    } else {
        across = lf_normalize(lf_cross(d, Tn));
    }
    if (!(lf_dot(across, across) > 0)) /* looking along the tangent */
        lf_basis(Tn, &across, &C);
    /* v from the hit's offset from the centre line along dp/dv (pbrt's
     * edge function sign and distance over the width) */
    C = lf_v3(val[0], val[1], val[2]);
    float v = width > 0 ? lf_clampf(0.5f + lf_dot(lf_sub(p, C), across) / width, 0.f, 1.f) : 0.5f;
    lf_vec3 dpdv = across;
    if (c->type == LF_CURVE_CYLINDER) /* pbrt-v4: Rotate(-lerp(v, -90, 90) degrees, dp/du) */
        dpdv = rotate_about(across, Tn, -(float)(LF_PI / 180) * lf_lerpf(v, -90.f, 90.f));
    lf_vec3 n = lf_normalize(lf_cross(Tn, dpdv));
    if (c->flip_normal)
        n = lf_neg(n);
    lf_shading_ctx *sc = &hit->sc;
    sc->p = p;
    sc->ng = sc->ns = n;
    sc->dpdu = Tn;
    sc->uv = (lf_vec2){((float)prim + u) * c->u_step, v};
    sc->has_derivs = 0;
    hit->curve = 1;
    hit->curve_h = 2 * v - 1;
    hit->material = c->material;
    hit->light = -1;
    hit->sphere = -1;
    hit->medium_in = c->medium_in;
    hit->medium_out = c->medium_out;
}
