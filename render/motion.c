/* Motion (docs/motion.md): the keyframes of a shape's motion, and rigid
 * motion as Embree instances.  A shape that moves rigidly (rotation, axis
 * scales, translation) is built once in its own space into a static child
 * scene (lf_proto) and placed by an Embree instance whose two time steps are
 * quaternion decompositions, so the rotation is slerped exactly as pbrt's
 * decomposed interpolation and rays traverse a static BVH.  Shapes that ask
 * for "motionsegments", emitters, full spheres and motions Embree's
 * decomposition cannot represent get keyframed vertices (or centres).
 * Static object instances are flattened. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/scene_build.h"

/* Embree takes at most RTC_MAX_TIME_STEP_COUNT (129) time steps per geometry. */
#define MAX_MOTION_SEGMENTS (RTC_MAX_TIME_STEP_COUNT - 1)

/* Keyframes for a (possibly animated) object-to-world transform, optionally
 * composed with an animated instance transform.  pbrt interpolates the
 * decomposed transform (rigid rotation); Embree interpolates vertices
 * linearly between time steps, so a rotation is followed by N segments:
 * "integer motionsegments" (a lensfield extension) or, by default, one
 * segment per 5 degrees of rotation (a pure translation needs one). */
static int motion_keys(lf_scene_builder *b, lf_shape_desc *sh, const lf_anim_xform *inst, lf_transform **keys, int *n)
{
    const lf_anim_xform *ax = &sh->object_to_world;
    int animated = ax->animated || (inst && inst->animated);
    int requested = lf_params_int(&sh->e.params, "motionsegments", 0);
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (requested < 0 || requested > MAX_MOTION_SEGMENTS)
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: \"motionsegments\" must be in 1..%d (Embree's limit of %d time steps), got %d", where,
                            MAX_MOTION_SEGMENTS, RTC_MAX_TIME_STEP_COUNT, requested);
    if (!animated) {
        *keys = malloc(sizeof(lf_transform));
        if (!*keys)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        (*keys)[0] = inst ? lf_transform_compose(&inst->xf[0], &ax->xf[0]) : ax->xf[0];
        *n = 1;
        return 0;
    }
    lf_decomposed da[2], di[2];
    for (int k = 0; k < 2; k++) {
        if (lf_transform_decompose(&ax->xf[k], &da[k]) || (inst && lf_transform_decompose(&inst->xf[k], &di[k])))
            return lf_error_set(b->err, LF_ERR_NUMERIC,
                                "%s: Shape \"%s\": its %s motion keyframe transform is degenerate (singular)", where,
                                sh->e.type, k ? "end" : "start");
    }
    double dot_a =
        fabs(da[0].q[0] * da[1].q[0] + da[0].q[1] * da[1].q[1] + da[0].q[2] * da[1].q[2] + da[0].q[3] * da[1].q[3]);
    double angle = 2 * acos(dot_a < 1 ? dot_a : 1) * 180 / LF_PI;
    if (inst) {
        double dot_i =
            fabs(di[0].q[0] * di[1].q[0] + di[0].q[1] * di[1].q[1] + di[0].q[2] * di[1].q[2] + di[0].q[3] * di[1].q[3]);
        angle += 2 * acos(dot_i < 1 ? dot_i : 1) * 180 / LF_PI;
    }
    int segs = requested > 0 ? requested : (int)ceil(angle / 5.0);
    if (segs < 1)
        segs = 1;
    if (segs > MAX_MOTION_SEGMENTS)
        segs = MAX_MOTION_SEGMENTS;
    *keys = malloc(sizeof(lf_transform) * (size_t)(segs + 1));
    if (!*keys)
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    for (int k = 0; k <= segs; k++) {
        double f = (double)k / segs;
        lf_transform t = ax->animated ? lf_decomposed_interpolate(&da[0], &da[1], f) : ax->xf[0];
        if (k == 0)
            t = ax->xf[0];
        else if (k == segs)
            t = ax->xf[1];
        if (inst) {
            lf_transform ti = inst->animated ? lf_decomposed_interpolate(&di[0], &di[1], f) : inst->xf[0];
            if (k == 0)
                ti = inst->xf[0];
            else if (k == segs)
                ti = inst->xf[1];
            t = lf_transform_compose(&ti, &t);
        }
        (*keys)[k] = t;
    }
    *n = segs + 1;
    return 0;
}

static double peek_num(const lf_paramset *ps, const char *name, double def)
{
    const lf_param *p = lf_params_peek(ps, name);
    return p && p->n_nums >= 1 ? p->nums[0] : def;
}

/* May this shape's motion be a rigid Embree instance (docs/motion.md)?  Not
 * when it asks for piecewise-linear keyframes ("motionsegments": the course
 * notes' segment figures depend on them), not an emitter (light sampling
 * reads its world-space keyframed vertices), not a full sphere (analytic
 * spheres move their centre, already cheap), not an unknown shape. */
static int shape_can_instance(const lf_shape_desc *sh)
{
    const lf_paramset *ps = &sh->e.params;
    if (sh->area_light >= 0 || lf_params_peek(ps, "motionsegments"))
        return 0;
    if (!lf_shape_known(sh->e.type) || strcmp(sh->e.type, "curve") == 0) /* curves live in world space */
        return 0;
    if (strcmp(sh->e.type, "sphere") == 0) {
        double r = peek_num(ps, "radius", 1.0), z0 = peek_num(ps, "zmin", -r), z1 = peek_num(ps, "zmax", r);
        return !(fmin(z0, z1) <= -r && fmax(z0, z1) >= r && peek_num(ps, "phimax", 360.0) >= 360.0);
    }
    return 1;
}

/* pbrt's decomposition M = T R S (polar: S symmetric) is Embree's
 * RTCQuaternionDecomposition T R S (S upper triangular scale/skew/shift)
 * when S is diagonal: a rotation with scales along the object's axes.
 * Embree then lerps S and T and slerps R (shortest arc, plain lerp above a
 * quaternion dot of 0.9995) exactly as lf_decomposed_matrix does. */
static int stretch_is_diagonal(const lf_decomposed *d)
{
    double diag = fmax(fabs(d->s[0][0]), fmax(fabs(d->s[1][1]), fabs(d->s[2][2])));
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != j && !(fabs(d->s[i][j]) <= 1e-7 * diag))
                return 0;
    return diag > 0 && isfinite(diag);
}

/* Decomposes a two-key motion for an Embree instance; -1 if singular or not
 * representable.  Key 1's quaternion is put on key 0's hemisphere so the
 * float copy Embree gets takes the same (shortest) arc as ours. */
static int rigid_motion(const lf_transform *x0, const lf_transform *x1, lf_decomposed d[2])
{
    if (lf_transform_decompose(x0, &d[0]) || lf_transform_decompose(x1, &d[1]))
        return -1;
    if (!stretch_is_diagonal(&d[0]) || !stretch_is_diagonal(&d[1]))
        return -1;
    for (int i = 0; i < 3; i++) /* a scale lerping through 0 would make Embree's transform singular */
        if (!(d[0].s[i][i] * d[1].s[i][i] > 0))
            return -1;
    double dot = 0;
    for (int i = 0; i < 4; i++)
        dot += d[0].q[i] * d[1].q[i];
    if (dot < 0)
        for (int i = 0; i < 4; i++)
            d[1].q[i] = -d[1].q[i];
    return 0;
}

/* pbrt's motion of a shape at fraction f: its own decomposed interpolation,
 * composed with an instance's (as motion_keys). */
static void reference_motion(const lf_anim_xform *ax, const lf_anim_xform *inst, double f, double m[4][4])
{
    lf_decomposed a[2], i[2];
    lf_transform t = ax->xf[0];
    if (ax->animated && !lf_transform_decompose(&ax->xf[0], &a[0]) && !lf_transform_decompose(&ax->xf[1], &a[1]))
        t = lf_decomposed_interpolate(&a[0], &a[1], f);
    if (inst) {
        lf_transform ti = inst->xf[0];
        if (inst->animated && !lf_transform_decompose(&inst->xf[0], &i[0]) &&
            !lf_transform_decompose(&inst->xf[1], &i[1]))
            ti = lf_decomposed_interpolate(&i[0], &i[1], f);
        t = lf_transform_compose(&ti, &t);
    }
    memcpy(m, t.m, sizeof t.m);
}

/* The whole world motion of a shape (its own animated transform composed
 * with an instance's) as one two-key decomposed motion: -1 unless that
 * reproduces pbrt's composed interpolation (checked at interior times; a
 * rotating instance around a shape that itself rotates about another
 * point, or a non-uniform static instance scale, does not). */
static int shape_rigid_motion(const lf_shape_desc *sh, const lf_anim_xform *inst, lf_decomposed w[2])
{
    const lf_anim_xform *ax = &sh->object_to_world;
    lf_transform x[2];
    for (int k = 0; k < 2; k++)
        x[k] = inst ? lf_transform_compose(&inst->xf[k], &ax->xf[k]) : ax->xf[k];
    if (rigid_motion(&x[0], &x[1], w))
        return -1;
    if (!inst)
        return 0; /* exactly pbrt's interpolation of the shape's own keys */
    for (int k = 1; k < 8; k++) {
        double ref[4][4], got[4][4], scale = 1, err = 0;
        reference_motion(ax, inst, k / 8.0, ref);
        lf_decomposed_matrix(&w[0], &w[1], k / 8.0, got);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) {
                scale = fmax(scale, fabs(ref[i][j]));
                err = fmax(err, fabs(ref[i][j] - got[i][j]));
            }
        if (!(err <= 1e-6 * scale))
            return -1;
    }
    return 0;
}

static int begin_proto(lf_scene_builder *b)
{
    lf_scene *s = b->s;
    if (s->n_protos == b->cap_protos) {
        int nc = b->cap_protos ? 2 * b->cap_protos : 8;
        lf_proto *n = realloc(s->protos, sizeof *n * (size_t)nc);
        if (!n)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        s->protos = n;
        b->cap_protos = nc;
    }
    lf_proto *p = &s->protos[s->n_protos];
    memset(p, 0, sizeof *p);
    p->mesh_first = s->n_meshes;
    b->proto = s->n_protos++;
    return 0;
}

/* Closes the prototype being built; *index is -1 if it got no geometry
 * (unsupported shapes), and the prototype is dropped. */
static void end_proto(lf_scene_builder *b, int *index)
{
    lf_scene *s = b->s;
    lf_proto *p = &s->protos[b->proto];
    p->n_meshes = s->n_meshes - p->mesh_first;
    lf_vec3 lo = lf_v3(INFINITY, INFINITY, INFINITY), hi = lf_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int m = p->mesh_first; m < s->n_meshes; m++)
        for (int v = 0; v < s->meshes[m].n_verts; v++) {
            const float *q = s->meshes[m].P + 3 * (size_t)v;
            lo = lf_v3(fminf(lo.x, q[0]), fminf(lo.y, q[1]), fminf(lo.z, q[2]));
            hi = lf_v3(fmaxf(hi.x, q[0]), fmaxf(hi.y, q[1]), fmaxf(hi.z, q[2]));
        }
    p->bmin = lo;
    p->bmax = hi;
    *index = b->proto;
    if (p->n_meshes == 0) { /* prototypes are built one after another: this is the last */
        *index = -1;
        s->n_protos--;
    }
    b->proto = -1;
}

static int push_instance(lf_scene_builder *b, int proto, const lf_decomposed w[2])
{
    lf_scene *s = b->s;
    if (s->n_instances == b->cap_instances) {
        int nc = b->cap_instances ? 2 * b->cap_instances : 8;
        lf_instance *n = realloc(s->instances, sizeof *n * (size_t)nc);
        if (!n)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        s->instances = n;
        b->cap_instances = nc;
    }
    lf_instance *in = &s->instances[s->n_instances++];
    memset(in, 0, sizeof *in);
    in->proto = proto;
    in->key[0] = w[0];
    in->key[1] = w[1];
    /* q1 is on q0's hemisphere (rigid_motion) */
    double dot = 0, perp[4], len = 0;
    for (int i = 0; i < 4; i++)
        dot += w[0].q[i] * w[1].q[i];
    for (int i = 0; i < 4; i++) {
        perp[i] = w[1].q[i] - dot * w[0].q[i];
        len += perp[i] * perp[i];
    }
    in->nlerp = dot > 0.9995 || !(len > 0);
    in->theta = (float)acos(dot < 1 ? dot : 1);
    for (int i = 0; i < 4; i++) {
        in->q0[i] = (float)w[0].q[i];
        in->q1[i] = (float)w[1].q[i];
        in->qperp[i] = in->nlerp ? 0.f : (float)(perp[i] / sqrt(len));
    }
    in->scale0 = lf_v3((float)w[0].s[0][0], (float)w[0].s[1][1], (float)w[0].s[2][2]);
    in->scale1 = lf_v3((float)w[1].s[0][0], (float)w[1].s[1][1], (float)w[1].s[2][2]);
    in->trans0 = lf_v3((float)w[0].t[0], (float)w[0].t[1], (float)w[0].t[2]);
    in->trans1 = lf_v3((float)w[1].t[0], (float)w[1].t[1], (float)w[1].t[2]);
    in->uniform_scale = 1;
    for (int k = 0; k < 2; k++)
        for (int i = 1; i < 3; i++)
            if (fabs(w[k].s[i][i] - w[k].s[0][0]) > 1e-6 * fabs(w[k].s[0][0]))
                in->uniform_scale = 0;
    return 0;
}

/* Builds shapes into a new prototype: one shape in its object space
 * (sh != NULL), or every instanceable static shape of ObjectBegin `object`
 * in the object's space, shared by all its moving instances. */
static int build_proto(lf_scene_builder *b, lf_shape_desc *sh, int object, int *index)
{
    if (begin_proto(b))
        return b->err->code;
    if (sh) {
        lf_transform id = lf_transform_identity();
        lf_shape_motion mo = {&id, 1};
        if (lf_build_shape(b, sh, &mo)) {
            b->proto = -1;
            return b->err->code;
        }
    } else {
        for (size_t i = 0; i < b->d->n_shapes; i++) {
            lf_shape_desc *o = &b->d->shapes[i];
            if (o->object != object || o->object_to_world.animated || !shape_can_instance(o))
                continue;
            lf_shape_motion mo = {&o->object_to_world.xf[0], 1};
            if (lf_build_shape(b, o, &mo)) {
                b->proto = -1;
                return b->err->code;
            }
        }
    }
    end_proto(b, index);
    return 0;
}

int lf_build_shape_moving(lf_scene_builder *b, lf_shape_desc *sh, const lf_anim_xform *inst)
{
    lf_transform *keys = NULL;
    int n = 0;
    if (motion_keys(b, sh, inst, &keys, &n))
        return b->err->code;
    lf_decomposed w[2];
    if (n > 1 && shape_can_instance(sh) && !shape_rigid_motion(sh, inst, w)) {
        free(keys);
        int proto;
        if (build_proto(b, sh, -1, &proto) || (proto >= 0 && push_instance(b, proto, w)))
            return b->err->code;
        b->s->motion_rigid_shapes += proto >= 0; /* else it made no geometry */
        return 0;
    }
    lf_shape_motion mo = {keys, n};
    int rc = lf_build_shape(b, sh, &mo);
    free(keys);
    if (n > 1)
        b->s->motion_keyframed_shapes++;
    return rc;
}

/* An ObjectInstance: a moving rigid instance transform places the object's
 * shared prototype (its static, instanceable shapes) as one Embree
 * instance; its other shapes, and everything of a static instance, are
 * flattened as before. */
int lf_build_object_instance(lf_scene_builder *b, const lf_instance_desc *in)
{
    const lf_anim_xform *ix = &in->instance_to_world;
    lf_decomposed w[2];
    int proto = -1;
    if (ix->animated && !rigid_motion(&ix->xf[0], &ix->xf[1], w)) {
        if (b->object_proto[in->object] == -2 && build_proto(b, NULL, in->object, &b->object_proto[in->object]))
            return b->err->code;
        proto = b->object_proto[in->object];
        if (proto >= 0 && push_instance(b, proto, w))
            return b->err->code;
    }
    for (size_t i = 0; i < b->d->n_shapes; i++) {
        lf_shape_desc *sh = &b->d->shapes[i];
        if (sh->object != in->object)
            continue;
        if (proto >= 0 && !sh->object_to_world.animated && shape_can_instance(sh)) {
            b->s->motion_rigid_shapes++;
            continue;
        }
        if (lf_build_shape_moving(b, sh, ix))
            return b->err->code;
    }
    return 0;
}

/* Our decomposition (diagonal stretch, checked by rigid_motion) in Embree's
 * terms: scale = the stretch's diagonal, no skew or shift, quaternion
 * (r, i, j, k) = (w, x, y, z). */
static void embree_decomposition(const lf_decomposed *d, struct RTCQuaternionDecomposition *qd)
{
    rtcInitQuaternionDecomposition(qd);
    rtcQuaternionDecompositionSetScale(qd, (float)d->s[0][0], (float)d->s[1][1], (float)d->s[2][2]);
    rtcQuaternionDecompositionSetQuaternion(qd, (float)d->q[3], (float)d->q[0], (float)d->q[1], (float)d->q[2]);
    rtcQuaternionDecompositionSetTranslation(qd, (float)d->t[0], (float)d->t[1], (float)d->t[2]);
}

/* Static prototype scenes, and the instances that place them. */
void lf_attach_instances(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax)
{
    for (int p = 0; p < s->n_protos; p++) {
        lf_proto *pr = &s->protos[p];
        pr->rtc = rtcNewScene(s->device);
        rtcSetSceneBuildQuality(pr->rtc, RTC_BUILD_QUALITY_HIGH);
        for (int m = 0; m < pr->n_meshes; m++)
            lf_attach_mesh(s->device, pr->rtc, &s->meshes[pr->mesh_first + m], (unsigned)m);
        rtcCommitScene(pr->rtc);
    }
    for (int i = 0; i < s->n_instances; i++) {
        lf_instance *in = &s->instances[i];
        const lf_proto *pr = &s->protos[in->proto];
        RTCGeometry g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, pr->rtc);
        rtcSetGeometryTimeStepCount(g, 2);
        for (unsigned k = 0; k < 2; k++) {
            struct RTCQuaternionDecomposition qd;
            embree_decomposition(&in->key[k], &qd);
            rtcSetGeometryTransformQuaternion(g, k, &qd);
        }
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(s->rtc, g);
        rtcReleaseGeometry(g); /* the scene keeps it alive; in->geom is valid as long as s->rtc */
        in->geom = g;
        s->geom_index[id] = i;
        s->moving_shapes++;
        /* World bounds over the motion: the prototype's box at 17 times. */
        for (int k = 0; k <= 16; k++) {
            double m4[4][4];
            lf_decomposed_matrix(&in->key[0], &in->key[1], k / 16.0, m4);
            for (int c = 0; c < 8; c++) {
                double q[3] = {c & 1 ? pr->bmax.x : pr->bmin.x, c & 2 ? pr->bmax.y : pr->bmin.y,
                               c & 4 ? pr->bmax.z : pr->bmin.z};
                float w[3];
                for (int r = 0; r < 3; r++)
                    w[r] = (float)(m4[r][0] * q[0] + m4[r][1] * q[1] + m4[r][2] * q[2] + m4[r][3]);
                *bmin = lf_v3(fminf(bmin->x, w[0]), fminf(bmin->y, w[1]), fminf(bmin->z, w[2]));
                *bmax = lf_v3(fmaxf(bmax->x, w[0]), fmaxf(bmax->y, w[1]), fmaxf(bmax->z, w[2]));
            }
        }
    }
}

void lf_scene_motion_summary(const lf_scene *s, char *buf, size_t n)
{
    int rigid = s->motion_rigid_shapes, keyed = s->motion_keyframed_shapes;
    char a[256] = "", k[256] = "";
    if (rigid)
        snprintf(a, sizeof a,
                 "%d as rigid Embree instance%s (%d instance%s of %d prototype%s: quaternion motion, static BVHs)",
                 rigid, rigid == 1 ? "" : "s", s->n_instances, s->n_instances == 1 ? "" : "s", s->n_protos,
                 s->n_protos == 1 ? "" : "s");
    if (keyed)
        snprintf(k, sizeof k,
                 "%d with keyframed vertices or centres (up to %d keyframes = %d segments, on Embree "
                 "motion-BVH nodes)",
                 keyed, s->max_keys, s->max_keys - 1);
    snprintf(buf, n, "%d moving shape%s: %s%s%s", rigid + keyed, rigid + keyed == 1 ? "" : "s", a,
             rigid && keyed ? ", " : "", k);
}
