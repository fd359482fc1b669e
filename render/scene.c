/* Scene building: shape descriptions -> world-space geometry -> Embree.
 *
 * Triangles go to Embree triangle geometries; full spheres under a
 * similarity transform go to one Embree sphere-point geometry (exact
 * intersections, no tessellation); partial spheres, disks and bilinear
 * patches are tessellated finely enough that their area differs from the
 * analytic one by well under 0.1%.  Static object instances are flattened.
 *
 * Motion (docs/motion.md): a shape that moves rigidly (rotation, axis
 * scales, translation) is built once in its own space into a static child
 * scene (lf_proto) and placed by an Embree instance whose two time steps are
 * quaternion decompositions, so the rotation is slerped exactly as pbrt's
 * decomposed interpolation and rays traverse a static BVH.  Shapes that ask
 * for "motionsegments", emitters, full spheres and motions Embree's
 * decomposition cannot represent get keyframed vertices (or centres). */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/lf_subdiv.h"
#include "render/lights.h"
#include "render/media.h"
#include "render/scene.h"

/* The keyframes of a shape's motion over the TransformTimes interval (Embree
 * time 0..1), evenly spaced; n == 1 for a static shape. */
typedef struct motion {
    const lf_transform *keys;
    int n;
} motion;

typedef struct builder {
    lf_scene *s;
    lf_scene_desc *d;
    int cap_meshes, cap_spheres, cap_lights, cap_protos, cap_instances;
    lf_error *err;
    int proto;         /* the lf_proto being built (meshes go to its space), or -1: world */
    int *object_proto; /* per ObjectBegin: its shared lf_proto, -1 none, -2 not built yet */
} builder;

/* A shape's MediumInterface as medium indices; *in = LF_MEDIUM_SAME when
 * it changes nothing (none given, or one medium on both sides). */
static int shape_media(builder *b, const lf_shape_desc *sh, int *in, int *out)
{
    *in = *out = LF_MEDIUM_SAME;
    if (!sh->medium_inside && !sh->medium_outside)
        return 0;
    int i, o;
    if (lf_media_lookup(b->d, sh->medium_inside, &sh->e.loc, "MediumInterface (inside)", &i, b->err) ||
        lf_media_lookup(b->d, sh->medium_outside, &sh->e.loc, "MediumInterface (outside)", &o, b->err))
        return b->err->code;
    if (i != o)
        *in = i, *out = o;
    return 0;
}

static int push_mesh(builder *b, lf_mesh *m)
{
    if (b->s->n_meshes == b->cap_meshes) {
        int nc = b->cap_meshes ? b->cap_meshes * 2 : 16;
        lf_mesh *n = realloc(b->s->meshes, sizeof *n * nc);
        if (!n)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        b->s->meshes = n;
        b->cap_meshes = nc;
    }
    b->s->meshes[b->s->n_meshes++] = *m;
    return 0;
}

static int push_light(builder *b, const lf_light *l)
{
    if (b->s->n_lights == b->cap_lights) {
        int nc = b->cap_lights ? b->cap_lights * 2 : 16;
        lf_light *n = realloc(b->s->lights, sizeof *n * nc);
        if (!n)
            return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
        b->s->lights = n;
        b->cap_lights = nc;
    }
    b->s->lights[b->s->n_lights++] = *l;
    return 0;
}

/* Area light parameters shared by every emissive shape (AreaLightSource "diffuse"). */
typedef struct area_emission {
    lf_vec3 L;
    int twosided;
    double power;
} area_emission;

static int read_area_light(builder *b, int index, area_emission *ae)
{
    lf_entity *e = &b->d->area_lights[index];
    char where[512];
    lf_loc_format(where, sizeof where, &e->loc);
    if (strcmp(e->type, "diffuse") != 0)
        return lf_error_set(b->err, LF_ERR_UNSUPPORTED, "%s: unknown area light \"%s\" (expected \"diffuse\")", where,
                            e->type);
    lf_paramset *ps = &e->params;
    lf_vec3 L;
    lf_params_rgb(ps, "L", LF_SPECTRUM_ILLUMINANT, lf_v3(1, 1, 1), &L);
    double scale = lf_params_float(ps, "scale", 1.0);
    ae->twosided = lf_params_bool(ps, "twosided", 0);
    ae->power = lf_params_float(ps, "power", -1.0);
    if (lf_params_peek(ps, "filename")) {
        lf_params_find(ps, "filename");
        return lf_error_set(b->err, LF_ERR_UNSUPPORTED, "%s: image-textured area lights (\"filename\") are not supported",
                            where);
    }
    if (lf_params_finish(ps, "AreaLightSource \"diffuse\"", b->err))
        return b->err ? b->err->code : LF_ERR_PARAM;
    ae->L = lf_scale(L, (float)scale);
    return 0;
}

/* pbrt-v4 "power" for area lights: scale so the emitted power is phi. */
static void apply_area_power(lf_vec3 *L, const area_emission *ae, double area)
{
    if (ae->power <= 0 || area <= 0)
        return;
    double k_e = lf_luminance(*L) * (ae->twosided ? 2.0 : 1.0) * area * LF_PI;
    if (k_e > 0)
        *L = lf_scale(*L, (float)(ae->power / k_e));
}

static lf_vec3 mesh_p(const lf_mesh *m, int i) { return lf_v3(m->P[3 * i], m->P[3 * i + 1], m->P[3 * i + 2]); }

/* Twice the area of the triangle a, b, c (vertex indices) or the area of
 * the parallelogram with corner a and edges to b and c. */
static float mesh_span(const lf_mesh *m, int a, int b, int c)
{
    return lf_length(lf_cross(lf_sub(mesh_p(m, b), mesh_p(m, a)), lf_sub(mesh_p(m, c), mesh_p(m, a))));
}

/* Whether triangles t and t + 1 of a static mesh form a planar
 * parallelogram, wound the same way (a quad as pbrt's bilinear patches and
 * most trianglemesh quads are written): they share one edge, the diagonal
 * (s0, s1), and the other two vertices x, y satisfy x + y = s0 + s1.  Then
 * q[0] = x is a corner and q[1] = s0, q[2] = s1 the ends of its edges. */
static int triangle_pair_parallelogram(const lf_mesh *m, int t, int q[3])
{
    const int *A = m->idx + 3 * t, *B = A + 3;
    int shared[2], ns = 0, x = -1, y = -1;
    for (int i = 0; i < 3; i++) {
        int in_b = A[i] == B[0] || A[i] == B[1] || A[i] == B[2];
        if (in_b && ns < 2)
            shared[ns++] = A[i];
        else if (!in_b)
            x = A[i];
    }
    for (int i = 0; i < 3; i++)
        if (B[i] != A[0] && B[i] != A[1] && B[i] != A[2])
            y = B[i];
    if (ns != 2 || x < 0 || y < 0)
        return 0;
    lf_vec3 px = mesh_p(m, x), py = mesh_p(m, y), s0 = mesh_p(m, shared[0]), s1 = mesh_p(m, shared[1]);
    lf_vec3 e1 = lf_sub(s0, px), e2 = lf_sub(s1, px), gap = lf_sub(lf_add(px, py), lf_add(s0, s1));
    float tol = 1e-5f * (lf_length(e1) + lf_length(e2));
    if (!(fabsf(gap.x) <= tol && fabsf(gap.y) <= tol && fabsf(gap.z) <= tol))
        return 0;
    /* the same winding: both triangles' normals point the same way */
    lf_vec3 na = lf_cross(lf_sub(mesh_p(m, A[1]), mesh_p(m, A[0])), lf_sub(mesh_p(m, A[2]), mesh_p(m, A[0])));
    lf_vec3 nb = lf_cross(lf_sub(mesh_p(m, B[1]), mesh_p(m, B[0])), lf_sub(mesh_p(m, B[2]), mesh_p(m, B[0])));
    if (!(lf_dot(na, nb) > 0) || !(lf_length(lf_cross(e1, e2)) > 0))
        return 0;
    q[0] = x, q[1] = shared[0], q[2] = shared[1];
    return 1;
}

/* One light per emissive triangle, or per parallelogram when the whole mesh
 * is static, has no vertex normals and pairs its triangles into
 * parallelograms: a quad light is then one light, sampled uniformly over
 * its area, as pbrt-v4 makes one light of a bilinear patch.  Either way the
 * sum is the same emitter; one light instead of two halves one shadow ray
 * per vertex where every light is sampled (docs/performance.md). */
static int add_mesh_lights(builder *b, lf_mesh *m, int area_light)
{
    m->light_first = -1;
    m->light_quads = 0;
    if (area_light < 0)
        return 0;
    area_emission ae;
    if (read_area_light(b, area_light, &ae))
        return b->err->code;
    double total_area = 0;
    for (int t = 0; t < m->n_tris; t++)
        total_area += 0.5 * mesh_span(m, m->idx[3 * t], m->idx[3 * t + 1], m->idx[3 * t + 2]);
    lf_vec3 L = ae.L;
    apply_area_power(&L, &ae, total_area);
    int quads = m->n_keys == 1 && !m->N && m->n_tris % 2 == 0 && m->n_tris > 0;
    for (int t = 0; quads && t < m->n_tris; t += 2) {
        int q[3];
        quads = triangle_pair_parallelogram(m, t, q);
    }
    m->light_first = b->s->n_lights;
    m->light_quads = quads;
    int mesh_index = b->s->n_meshes; /* the mesh is pushed right after this */
    for (int t = 0; t < m->n_tris; t += quads ? 2 : 1) {
        lf_light l = {0};
        l.L = L;
        l.mesh = mesh_index;
        l.prim = t;
        l.twosided = ae.twosided;
        l.sphere = -1;
        if (quads) {
            triangle_pair_parallelogram(m, t, l.quad);
            l.kind = LF_LIGHT_PARALLELOGRAM;
            l.area = mesh_span(m, l.quad[0], l.quad[1], l.quad[2]);
        } else {
            l.kind = LF_LIGHT_TRIANGLE;
            l.area = 0.5f * mesh_span(m, m->idx[3 * t], m->idx[3 * t + 1], m->idx[3 * t + 2]);
        }
        if (push_light(b, &l))
            return b->err->code;
    }
    return 0;
}

/* Transforms a mesh given in object space into world space and pushes it. */
static int finish_mesh(builder *b, const lf_shape_desc *sh, const motion *mo, float *P, int nv, float *N,
                       float *uv, int *idx, int nt)
{
    for (int i = 0; i < 3 * nt; i++)
        if (idx[i] < 0 || idx[i] >= nv) {
            char where[512];
            lf_loc_format(where, sizeof where, &sh->e.loc);
            int bad = idx[i];
            free(P), free(N), free(uv), free(idx);
            return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"%s\": vertex index %d out of range (%d vertices)",
                                where, sh->e.type, bad, nv);
        }
    /* World-space vertices (and normals) per keyframe, one block per key,
     * plus one float of padding: Embree reads vertices with 16-byte loads. */
    size_t block = (size_t)3 * nv;
    float *PW = malloc(sizeof(float) * (block * mo->n + 1));
    float *NW = N ? malloc(sizeof(float) * (block * mo->n + 1)) : NULL;
    if (!PW || (N && !NW)) {
        free(PW), free(NW), free(P), free(N), free(uv), free(idx);
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    }
    PW[block * mo->n] = 0;
    for (int k = 0; k < mo->n; k++)
        for (int i = 0; i < nv; i++) {
            lf_vec3 p = lf_xform_point(&mo->keys[k], lf_v3(P[3 * i], P[3 * i + 1], P[3 * i + 2]));
            if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z)) {
                char where[512];
                lf_loc_format(where, sizeof where, &sh->e.loc);
                free(PW), free(NW), free(P), free(N), free(uv), free(idx);
                return lf_error_set(b->err, LF_ERR_NUMERIC, "%s: Shape \"%s\": vertex %d is not finite", where,
                                    sh->e.type, i);
            }
            float *pw = PW + k * block + 3 * i;
            pw[0] = p.x, pw[1] = p.y, pw[2] = p.z;
            if (N) {
                lf_vec3 n = lf_normalize(lf_xform_normal(&mo->keys[k], lf_v3(N[3 * i], N[3 * i + 1], N[3 * i + 2])));
                float *nw = NW + k * block + 3 * i;
                nw[0] = n.x, nw[1] = n.y, nw[2] = n.z;
            }
        }
    free(P);
    free(N);
    P = PW;
    N = NW;
    const lf_transform *xf = &mo->keys[0];
    lf_mesh m = {0};
    m.n_tris = nt;
    m.n_verts = nv;
    m.n_keys = mo->n;
    m.idx = idx;
    m.P = P;
    m.N = N;
    m.uv = uv;
    m.proto = b->proto;
    m.material = sh->material;
    m.flip_normal = sh->reverse_orientation ^ lf_transform_swaps_handedness(xf);
    m.bump = lf_material_bumps(lf_materials_get(b->s->materials, sh->material));
    if (shape_media(b, sh, &m.medium_in, &m.medium_out)) {
        free(P), free(N), free(uv), free(idx);
        return b->err->code;
    }
    if (b->proto >= 0 && sh->area_light >= 0) { /* never routed here: emitters keep keyframes */
        free(P), free(N), free(uv), free(idx);
        return lf_error_set(b->err, LF_ERR_INTERNAL, "internal: an emissive shape in an instance prototype");
    }
    if (add_mesh_lights(b, &m, sh->area_light) || push_mesh(b, &m)) {
        free(P), free(N), free(uv), free(idx);
        return b->err->code;
    }
    b->s->n_triangles += nt;
    return 0;
}

static float *dup_floats(const double *v, size_t n)
{
    float *f = malloc(sizeof(float) * (n ? n : 1));
    if (f)
        for (size_t i = 0; i < n; i++)
            f[i] = (float)v[i];
    return f;
}

static int shape_trianglemesh(builder *b, lf_shape_desc *sh, const motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    size_t np = 0, ni = 0, nn = 0, nuv = 0;
    const double *P = lf_params_nums(ps, "P", LF_PT_POINT3, &np);
    const double *I = lf_params_nums(ps, "indices", LF_PT_INTEGER, &ni);
    const double *N = lf_params_nums(ps, "N", LF_PT_NORMAL3, &nn);
    const double *UV = lf_params_nums(ps, "uv", LF_PT_POINT2, &nuv);
    lf_params_find(ps, "S");
    lf_params_find(ps, "faceIndices");
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!P || np < 9 || np % 3)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"trianglemesh\" needs \"point3 P\" with at least 3 points",
                            where);
    int nv = (int)(np / 3);
    if (!I) {
        if (nv != 3)
            return lf_error_set(b->err, LF_ERR_PARAM,
                                "%s: Shape \"trianglemesh\" without \"integer indices\" must have exactly 3 vertices",
                                where);
    } else if (ni % 3 || ni == 0) {
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"trianglemesh\": %zu indices is not a multiple of 3",
                            where, ni);
    }
    if (N && nn != np)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: \"normal N\" has %zu values, expected %zu (one per vertex)",
                            where, nn, np);
    if (UV && nuv != 2 * (size_t)nv)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: \"point2 uv\" has %zu values, expected %d (one per vertex)",
                            where, nuv, 2 * nv);
    int nt = I ? (int)(ni / 3) : 1;
    int *idx = malloc(sizeof(int) * 3 * nt);
    float *fp = dup_floats(P, np), *fn = N ? dup_floats(N, nn) : NULL, *fuv = UV ? dup_floats(UV, nuv) : NULL;
    if (!idx || !fp || (N && !fn) || (UV && !fuv)) {
        free(idx), free(fp), free(fn), free(fuv);
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; i < 3 * nt; i++)
        idx[i] = I ? (int)I[i] : i;
    return finish_mesh(b, sh, mo, fp, nv, fn, fuv, idx, nt);
}

static int shape_plymesh(builder *b, lf_shape_desc *sh, const motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    const char *fn = lf_params_string(ps, "filename", NULL);
    lf_params_find(ps, "displacement.edgelength");
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!fn)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"plymesh\" needs \"string filename\"", where);
    if (lf_params_find(ps, "displacement"))
        lf_warn_at(&b->s->warnings, &sh->e.loc, "plymesh displacement is not supported; rendering undisplaced");
    char path[4096];
    if (fn[0] == '/' || !sh->base_dir || !sh->base_dir[0])
        snprintf(path, sizeof path, "%s", fn);
    else
        snprintf(path, sizeof path, "%s/%s", sh->base_dir, fn);
    /* Not next to the file that names it: relative to the top-level file,
     * where pbrt-v4 looks (nested geometry files name meshes that way). */
    if (fn[0] != '/' && access(path, F_OK) != 0 && b->d->scene_dir && b->d->scene_dir[0]) {
        char alt[4096];
        snprintf(alt, sizeof alt, "%s/%s", b->d->scene_dir, fn);
        if (access(alt, F_OK) == 0)
            memcpy(path, alt, sizeof path);
    }
    lf_ply_mesh pm;
    lf_error perr = {0};
    if (lf_ply_read(path, &pm, &perr))
        return lf_error_set(b->err, perr.code, "%s: Shape \"plymesh\": %s", where, perr.msg);
    lf_ply_mesh copy = pm;
    return finish_mesh(b, sh, mo, copy.P, (int)copy.n_vertices, copy.N, copy.uv, copy.indices, (int)copy.n_triangles);
}

/* pbrt-v4's "loopsubdiv": the limit surface of the control mesh after
 * "levels" Loop subdivisions, with limit-surface normals (render/lf_subdiv.h). */
static int shape_loopsubdiv(builder *b, lf_shape_desc *sh, const motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    size_t np = 0, ni = 0;
    int levels = lf_params_int(ps, "levels", 3);
    const double *P = lf_params_nums(ps, "P", LF_PT_POINT3, &np);
    const double *I = lf_params_nums(ps, "indices", LF_PT_INTEGER, &ni);
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (ps->error.code)
        return lf_params_finish(ps, "Shape \"loopsubdiv\"", b->err);
    if (!P || np < 9)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"loopsubdiv\" needs \"point3 P\" with at least 3 points",
                            where);
    if (!I || ni == 0 || ni % 3)
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: Shape \"loopsubdiv\" needs \"integer indices\", 3 per triangle (got %zu)", where, ni);
    int *idx = malloc(ni * sizeof *idx);
    if (!idx)
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < ni; i++)
        idx[i] = I[i] < 0 || I[i] > INT_MAX ? -1 : (int)I[i];
    lf_ply_mesh m;
    lf_error e = {0};
    int rc = lf_loop_subdivide(P, np / 3, idx, ni / 3, levels, &m, &e);
    free(idx);
    if (rc)
        return lf_error_set(b->err, rc, "%s: Shape \"loopsubdiv\": %s", where, e.msg);
    /* pbrt-v4 negates a mesh's normals under ReverseOrientation. */
    if (sh->reverse_orientation)
        for (size_t i = 0; i < 3 * m.n_vertices; i++)
            m.N[i] = -m.N[i];
    return finish_mesh(b, sh, mo, m.P, (int)m.n_vertices, m.N, NULL, m.indices, (int)m.n_triangles);
}

/* Tessellated parametric surface: f(u, v) -> object-space point, on a grid. */
typedef void (*surface_fn)(const double *prm, double u, double v, double out[3], double nrm[3]);

static int tessellate(builder *b, lf_shape_desc *sh, const motion *mo, surface_fn f, const double *prm, int nu,
                      int nv_, int with_normals)
{
    int nv = (nu + 1) * (nv_ + 1), nt = 2 * nu * nv_;
    float *P = malloc(sizeof(float) * 3 * nv), *N = with_normals ? malloc(sizeof(float) * 3 * nv) : NULL;
    float *UV = malloc(sizeof(float) * 2 * nv);
    int *idx = malloc(sizeof(int) * 3 * nt);
    if (!P || !UV || !idx || (with_normals && !N)) {
        free(P), free(N), free(UV), free(idx);
        return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
    }
    for (int j = 0; j <= nv_; j++)
        for (int i = 0; i <= nu; i++) {
            double p[3], n[3];
            double u = (double)i / nu, v = (double)j / nv_;
            f(prm, u, v, p, n);
            int k = j * (nu + 1) + i;
            P[3 * k] = (float)p[0], P[3 * k + 1] = (float)p[1], P[3 * k + 2] = (float)p[2];
            if (N)
                N[3 * k] = (float)n[0], N[3 * k + 1] = (float)n[1], N[3 * k + 2] = (float)n[2];
            UV[2 * k] = (float)u, UV[2 * k + 1] = (float)v;
        }
    int t = 0;
    for (int j = 0; j < nv_; j++)
        for (int i = 0; i < nu; i++) {
            int a = j * (nu + 1) + i, bb = a + 1, c = a + nu + 1, d = c + 1;
            idx[3 * t] = a, idx[3 * t + 1] = bb, idx[3 * t + 2] = d, t++;
            idx[3 * t] = a, idx[3 * t + 1] = d, idx[3 * t + 2] = c, t++;
        }
    /* Drop triangles that collapsed at poles or the disk centre. */
    int w = 0;
    for (int k = 0; k < nt; k++) {
        const float *p0 = P + 3 * idx[3 * k], *p1 = P + 3 * idx[3 * k + 1], *p2 = P + 3 * idx[3 * k + 2];
        lf_vec3 e1 = lf_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        lf_vec3 e2 = lf_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        if (lf_length(lf_cross(e1, e2)) > 0) {
            memmove(idx + 3 * w, idx + 3 * k, sizeof(int) * 3);
            w++;
        }
    }
    return finish_mesh(b, sh, mo, P, nv, N, UV, idx, w);
}

/* pbrt's sphere: (u,v) -> phi = u phimax, theta from zmin to zmax. */
static void sphere_surface(const double *prm, double u, double v, double out[3], double nrm[3])
{
    double r = prm[0], thmin = prm[1], thmax = prm[2], phimax = prm[3];
    double th = thmin + v * (thmax - thmin), phi = u * phimax;
    nrm[0] = sin(th) * cos(phi), nrm[1] = sin(th) * sin(phi), nrm[2] = cos(th);
    out[0] = r * nrm[0], out[1] = r * nrm[1], out[2] = r * nrm[2];
}

static void disk_surface(const double *prm, double u, double v, double out[3], double nrm[3])
{
    double h = prm[0], r = prm[1], ri = prm[2], phimax = prm[3];
    double phi = u * phimax, rr = r - v * (r - ri); /* pbrt: v = 0 at the outer rim */
    out[0] = rr * cos(phi), out[1] = rr * sin(phi), out[2] = h;
    nrm[0] = 0, nrm[1] = 0, nrm[2] = 1;
}

/* Similarity transform (rotation * uniform scale + translation)? Returns the scale. */
static double similarity_scale(const lf_transform *xf)
{
    double c[3];
    for (int j = 0; j < 3; j++)
        c[j] = sqrt(xf->m[0][j] * xf->m[0][j] + xf->m[1][j] * xf->m[1][j] + xf->m[2][j] * xf->m[2][j]);
    if (fabs(c[0] - c[1]) > 1e-9 * c[0] || fabs(c[0] - c[2]) > 1e-9 * c[0])
        return 0;
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++) {
            double d = xf->m[0][i] * xf->m[0][j] + xf->m[1][i] * xf->m[1][j] + xf->m[2][i] * xf->m[2][j];
            if (fabs(d) > 1e-9 * c[0] * c[0])
                return 0;
        }
    if (xf->m[3][0] != 0 || xf->m[3][1] != 0 || xf->m[3][2] != 0 || xf->m[3][3] != 1)
        return 0;
    return c[0];
}

static int shape_sphere(builder *b, lf_shape_desc *sh, const motion *mo)
{
    const lf_transform *xf = &mo->keys[0];
    lf_paramset *ps = &sh->e.params;
    double r = lf_params_float(ps, "radius", 1.0);
    double zmin = lf_params_float(ps, "zmin", -r), zmax = lf_params_float(ps, "zmax", r);
    double phimax = lf_params_float(ps, "phimax", 360.0);
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!(r > 0) || !isfinite(r))
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"sphere\": radius must be positive and finite, got %g",
                            where, r);
    zmin = lf_clampd(fmin(zmin, zmax), -r, r);
    zmax = lf_clampd(fmax(zmin, zmax), -r, r);
    phimax = lf_clampd(phimax, 0, 360);
    double scale = similarity_scale(xf);
    int full = zmin <= -r && zmax >= r && phimax >= 360.0;
    for (int k = 1; k < mo->n && scale > 0; k++)
        if (similarity_scale(&mo->keys[k]) <= 0)
            scale = 0; /* sheared somewhere along the motion: tessellate */
    if (full && scale > 0 && b->proto < 0) {
        if (b->s->n_spheres == b->cap_spheres) {
            int nc = b->cap_spheres ? 2 * b->cap_spheres : 8;
            lf_sphere *n = realloc(b->s->spheres, sizeof *n * nc);
            if (!n)
                return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
            b->s->spheres = n;
            b->cap_spheres = nc;
        }
        lf_sphere sp = {0};
        sp.center = lf_xform_point(xf, lf_v3(0, 0, 0));
        sp.radius = (float)(r * scale);
        sp.n_keys = 1;
        if (mo->n > 1) {
            /* A moving sphere: its centre per keyframe (radius from the first;
             * a changing scale would need an ellipsoid). */
            sp.centers = malloc(sizeof(lf_vec3) * (size_t)mo->n);
            if (!sp.centers)
                return lf_error_set(b->err, LF_ERR_NOMEM, "out of memory");
            for (int k = 0; k < mo->n; k++)
                sp.centers[k] = lf_xform_point(&mo->keys[k], lf_v3(0, 0, 0));
            sp.n_keys = mo->n;
            double s1 = similarity_scale(&mo->keys[mo->n - 1]);
            if (fabs(s1 - scale) > 1e-6 * scale) {
                lf_warn_at(&b->s->warnings, &sh->e.loc,
                           "a sphere whose scale changes during the shutter keeps its "
                           "starting radius");
            }
        }
        sp.object_to_world = *xf;
        sp.material = sh->material;
        sp.flip_normal = sh->reverse_orientation ^ lf_transform_swaps_handedness(xf);
        sp.light = -1;
        sp.bump = lf_material_bumps(lf_materials_get(b->s->materials, sh->material));
        sp.textured = lf_material_uses_textures(lf_materials_get(b->s->materials, sh->material));
        if (shape_media(b, sh, &sp.medium_in, &sp.medium_out)) {
            free(sp.centers);
            return b->err->code;
        }
        if (sh->area_light >= 0) {
            area_emission ae;
            if (read_area_light(b, sh->area_light, &ae))
                return b->err->code;
            lf_light l = {0};
            l.kind = LF_LIGHT_SPHERE;
            l.L = ae.L;
            l.area = (float)(4 * LF_PI * sp.radius * sp.radius);
            apply_area_power(&l.L, &ae, l.area);
            l.twosided = ae.twosided;
            l.sphere = b->s->n_spheres;
            l.mesh = -1;
            sp.light = b->s->n_lights;
            if (push_light(b, &l))
                return b->err->code;
        }
        b->s->spheres[b->s->n_spheres++] = sp;
        return 0;
    }
    /* Partial or non-uniformly scaled: tessellate (1024 x 512 segments keeps
     * the area error below 1e-5 relative). */
    double prm[4] = {r, acos(lf_clampd(zmax / r, -1, 1)), acos(lf_clampd(zmin / r, -1, 1)), phimax * LF_PI / 180};
    int nu = (int)ceil(256 * phimax / 360.0);
    return tessellate(b, sh, mo, sphere_surface, prm, nu < 4 ? 4 : nu, 128, 1);
}

static int shape_disk(builder *b, lf_shape_desc *sh, const motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    double prm[4] = {lf_params_float(ps, "height", 0.0), lf_params_float(ps, "radius", 1.0),
                     lf_params_float(ps, "innerradius", 0.0), lf_params_float(ps, "phimax", 360.0)};
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!(prm[1] > 0) || !(prm[2] >= 0) || prm[2] >= prm[1])
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"disk\": need 0 <= innerradius < radius", where);
    prm[3] = lf_clampd(prm[3], 0, 360) * LF_PI / 180;
    /* 512 segments: polygon area / circle area = sinc-like 1 - 2.5e-5. */
    int nu = (int)ceil(512 * prm[3] / (2 * LF_PI));
    return tessellate(b, sh, mo, disk_surface, prm, nu < 4 ? 4 : nu, 1, 1);
}

static void bilinear_surface(const double *prm, double u, double v, double out[3], double nrm[3])
{
    const double *p00 = prm, *p10 = prm + 3, *p01 = prm + 6, *p11 = prm + 9;
    double du[3], dv[3];
    for (int k = 0; k < 3; k++) {
        out[k] = (1 - u) * (1 - v) * p00[k] + u * (1 - v) * p10[k] + (1 - u) * v * p01[k] + u * v * p11[k];
        du[k] = (1 - v) * (p10[k] - p00[k]) + v * (p11[k] - p01[k]);
        dv[k] = (1 - u) * (p01[k] - p00[k]) + u * (p11[k] - p10[k]);
    }
    nrm[0] = du[1] * dv[2] - du[2] * dv[1];
    nrm[1] = du[2] * dv[0] - du[0] * dv[2];
    nrm[2] = du[0] * dv[1] - du[1] * dv[0];
    double l = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (l > 0)
        nrm[0] /= l, nrm[1] /= l, nrm[2] /= l;
}

static int shape_bilinearmesh(builder *b, lf_shape_desc *sh, const motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    size_t np = 0, ni = 0;
    const double *P = lf_params_nums(ps, "P", LF_PT_POINT3, &np);
    const double *I = lf_params_nums(ps, "indices", LF_PT_INTEGER, &ni);
    lf_params_find(ps, "uv");
    lf_params_find(ps, "N");
    lf_params_find(ps, "faceIndices");
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!P || np % 3 || np < 12)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"bilinearmesh\" needs \"point3 P\" with at least 4 points",
                            where);
    int nv = (int)(np / 3);
    if (!I && nv != 4)
        return lf_error_set(b->err, LF_ERR_PARAM,
                            "%s: Shape \"bilinearmesh\" without \"integer indices\" must have exactly 4 vertices", where);
    if (I && (ni % 4 || ni == 0))
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"bilinearmesh\": %zu indices is not a multiple of 4",
                            where, ni);
    int npatch = I ? (int)(ni / 4) : 1;
    for (int k = 0; k < npatch; k++) {
        double prm[12];
        for (int c = 0; c < 4; c++) {
            int vi = I ? (int)I[4 * k + c] : c;
            if (vi < 0 || vi >= nv)
                return lf_error_set(b->err, LF_ERR_PARAM, "%s: bilinearmesh index %d out of range", where, vi);
            memcpy(prm + 3 * c, P + 3 * vi, sizeof(double) * 3);
        }
        /* A planar patch whose corners form a parallelogram is exactly two
         * triangles; otherwise a 16x16 grid. */
        double skew = 0;
        for (int c = 0; c < 3; c++)
            skew = fmax(skew, fabs(prm[c] + prm[9 + c] - prm[3 + c] - prm[6 + c]));
        int n = skew == 0 ? 1 : 16;
        if (tessellate(b, sh, mo, bilinear_surface, prm, n, n, 0))
            return b->err->code;
    }
    return 0;
}

typedef int (*shape_fn)(builder *b, lf_shape_desc *sh, const motion *mo);
static const struct {
    const char *name;
    shape_fn fn;
} shape_table[] = {
    {"trianglemesh", shape_trianglemesh}, {"plymesh", shape_plymesh}, {"sphere", shape_sphere},
    {"disk", shape_disk},                 {"bilinearmesh", shape_bilinearmesh}, {"loopsubdiv", shape_loopsubdiv},
};

static int build_shape(builder *b, lf_shape_desc *sh, const motion *mo)
{
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    const lf_param *alpha = sh->e.params.count ? lf_params_peek(&sh->e.params, "alpha") : NULL;
    if (alpha) {
        /* "float alpha" 1 changes nothing; anything else cuts the shape,
         * which lensfield cannot: the shape would show where the scene
         * has a hole (the unsupported rule, docs/scene-format.md). */
        int opaque = alpha->type == LF_PT_FLOAT && alpha->n_nums == 1 && alpha->nums[0] == 1.0;
        lf_params_find(&sh->e.params, "alpha");
        if (!opaque && !b->d->allow_unsupported)
            return lf_error_set(b->err, LF_ERR_UNSUPPORTED,
                                "%s: Shape \"%s\": \"alpha\" cut-outs are not supported (--allow-unsupported renders "
                                "the shape opaque)",
                                where, sh->e.type);
        if (!opaque)
            lf_warn_at(&b->s->warnings, &sh->e.loc, "\"alpha\" cut-outs are not supported; the shape is opaque");
    }
    for (size_t i = 0; i < sizeof shape_table / sizeof shape_table[0]; i++)
        if (strcmp(shape_table[i].name, sh->e.type) == 0) {
            if (shape_table[i].fn(b, sh, mo))
                return b->err->code;
            char ctx[256];
            snprintf(ctx, sizeof ctx, "Shape \"%s\"", sh->e.type);
            return lf_params_finish(&sh->e.params, ctx, b->err);
        }
    /* The parser refuses these already; a description built otherwise
     * gets the same rule. */
    if (!b->d->allow_unsupported)
        return lf_error_set(b->err, LF_ERR_UNSUPPORTED,
                            "%s: Shape \"%s\" is not supported (--allow-unsupported renders the scene without it)",
                            where, sh->e.type);
    lf_warn_at(&b->s->warnings, &sh->e.loc, "Shape \"%s\" is not supported; it is left out of the render", sh->e.type);
    for (size_t i = 0; i < sh->e.params.count; i++)
        sh->e.params.items[i].used = 1;
    return 0;
}

/* ---- analytic spheres as Embree user geometry ----
 * Measured cheaper per ray than Embree's sphere-point primitive (callgrind:
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
    float b = -lf_dot(f, d) / a;          /* t of the closest point */
    lf_vec3 l = lf_madd(f, d, b);         /* closest point - centre */
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

/* Embree's error callback may run on any thread: keep the first message
 * (claimed with an atomic flag) so the build error below can name it. */
static void rtc_error_cb(void *user, enum RTCError code, const char *str)
{
    lf_scene *s = user;
    (void)code;
    if (!s || atomic_exchange(&s->rtc_error_claimed, 1))
        return;
    snprintf(s->rtc_error_msg, sizeof s->rtc_error_msg, "%s", str ? str : "");
}

/* Embree takes at most RTC_MAX_TIME_STEP_COUNT (129) time steps per geometry. */
#define MAX_MOTION_SEGMENTS (RTC_MAX_TIME_STEP_COUNT - 1)

/* Keyframes for a (possibly animated) object-to-world transform, optionally
 * composed with an animated instance transform.  pbrt interpolates the
 * decomposed transform (rigid rotation); Embree interpolates vertices
 * linearly between time steps, so a rotation is followed by N segments:
 * "integer motionsegments" (a lensfield extension) or, by default, one
 * segment per 5 degrees of rotation (a pure translation needs one). */
static int motion_keys(builder *b, lf_shape_desc *sh, const lf_anim_xform *inst, lf_transform **keys, int *n)
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
        if (lf_transform_decompose(&ax->xf[k], &da[k]) ||
            (inst && lf_transform_decompose(&inst->xf[k], &di[k])))
            return lf_error_set(b->err, LF_ERR_NUMERIC,
                                "%s: Shape \"%s\": its %s motion keyframe transform is degenerate (singular)", where,
                                sh->e.type, k ? "end" : "start");
    }
    double dot_a = fabs(da[0].q[0] * da[1].q[0] + da[0].q[1] * da[1].q[1] + da[0].q[2] * da[1].q[2] +
                        da[0].q[3] * da[1].q[3]);
    double angle = 2 * acos(dot_a < 1 ? dot_a : 1) * 180 / LF_PI;
    if (inst) {
        double dot_i = fabs(di[0].q[0] * di[1].q[0] + di[0].q[1] * di[1].q[1] + di[0].q[2] * di[1].q[2] +
                            di[0].q[3] * di[1].q[3]);
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

/* ---- rigid motion as Embree instances ---- */

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
    int known = 0;
    for (size_t i = 0; i < sizeof shape_table / sizeof shape_table[0]; i++)
        known |= strcmp(shape_table[i].name, sh->e.type) == 0;
    if (!known)
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

static int begin_proto(builder *b)
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
static void end_proto(builder *b, int *index)
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

static int push_instance(builder *b, int proto, const lf_decomposed w[2])
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
static int build_proto(builder *b, lf_shape_desc *sh, int object, int *index)
{
    if (begin_proto(b))
        return b->err->code;
    if (sh) {
        lf_transform id = lf_transform_identity();
        motion mo = {&id, 1};
        if (build_shape(b, sh, &mo)) {
            b->proto = -1;
            return b->err->code;
        }
    } else {
        for (size_t i = 0; i < b->d->n_shapes; i++) {
            lf_shape_desc *o = &b->d->shapes[i];
            if (o->object != object || o->object_to_world.animated || !shape_can_instance(o))
                continue;
            motion mo = {&o->object_to_world.xf[0], 1};
            if (build_shape(b, o, &mo)) {
                b->proto = -1;
                return b->err->code;
            }
        }
    }
    end_proto(b, index);
    return 0;
}

static int build_shape_moving(builder *b, lf_shape_desc *sh, const lf_anim_xform *inst)
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
    motion mo = {keys, n};
    int rc = build_shape(b, sh, &mo);
    free(keys);
    if (n > 1)
        b->s->motion_keyframed_shapes++;
    return rc;
}

/* An ObjectInstance: a moving rigid instance transform places the object's
 * shared prototype (its static, instanceable shapes) as one Embree
 * instance; its other shapes, and everything of a static instance, are
 * flattened as before. */
static int build_object_instance(builder *b, const lf_instance_desc *in)
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
        if (build_shape_moving(b, sh, ix))
            return b->err->code;
    }
    return 0;
}

/* A triangle geometry for a mesh (one vertex buffer per keyframe over
 * Embree time 0..1 when it moves), attached with geomID id (or the next
 * free one for RTC_INVALID_GEOMETRY_ID). */
static unsigned attach_mesh(RTCDevice device, RTCScene scene, const lf_mesh *me, unsigned id)
{
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (me->n_keys > 1)
        rtcSetGeometryTimeStepCount(g, (unsigned)me->n_keys);
    for (int k = 0; k < me->n_keys; k++)
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, (unsigned)k, RTC_FORMAT_FLOAT3,
                                   me->P + (size_t)k * 3 * me->n_verts, 0, 3 * sizeof(float), (size_t)me->n_verts);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, me->idx, 0, 3 * sizeof(int),
                               (size_t)me->n_tris);
    rtcCommitGeometry(g);
    if (id == RTC_INVALID_GEOMETRY_ID)
        id = rtcAttachGeometry(scene, g);
    else
        rtcAttachGeometryByID(scene, g, id);
    rtcReleaseGeometry(g);
    return id;
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
        snprintf(k, sizeof k, "%d with keyframed vertices or centres (up to %d keyframes = %d segments, on Embree "
                 "motion-BVH nodes)", keyed, s->max_keys, s->max_keys - 1);
    snprintf(buf, n, "%d moving shape%s: %s%s%s", rigid + keyed, rigid + keyed == 1 ? "" : "s", a,
             rigid && keyed ? ", " : "", k);
}

int lf_scene_build(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
    s->time0 = d->transform_start_time;
    s->time1 = d->transform_end_time;
    builder b = {s, d, 0, 0, 0, 0, 0, err, -1, NULL};
    b.object_proto = malloc(sizeof(int) * (d->n_objects ? d->n_objects : 1));
    if (!b.object_proto) {
        lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < d->n_objects; i++)
        b.object_proto[i] = -2;
    if (lf_materials_build(d, &s->materials, err))
        goto fail;
    if (lf_media_build(d, s, err))
        goto fail;
    if (lf_media_lookup(d, d->camera.medium, &d->camera.e.loc, "the camera's medium", &s->camera_medium, err))
        goto fail;
    lf_warn_block(&s->warnings, lf_materials_warnings(s->materials));
    for (size_t i = 0; i < d->n_shapes; i++) {
        lf_shape_desc *sh = &d->shapes[i];
        if (sh->object >= 0)
            continue; /* instantiated below */
        if (build_shape_moving(&b, sh, NULL))
            goto fail;
    }
    for (size_t k = 0; k < d->n_instances; k++)
        if (build_object_instance(&b, &d->instances[k]))
            goto fail;
    free(b.object_proto);
    b.object_proto = NULL;
    if (lf_scene_build_lights(d, s, err))
        goto fail;
    /* Media cost only when a ray can enter one. */
    s->has_media = s->camera_medium >= 0;
    for (int i = 0; i < s->n_meshes && !s->has_media; i++)
        s->has_media = s->meshes[i].medium_in != LF_MEDIUM_SAME;
    for (int i = 0; i < s->n_spheres && !s->has_media; i++)
        s->has_media = s->spheres[i].medium_in != LF_MEDIUM_SAME;

    /* Embree */
    s->device = rtcNewDevice("verbose=0");
    if (!s->device) {
        lf_error_set(err, LF_ERR_INTERNAL, "cannot create the Embree device (error %d)", (int)rtcGetDeviceError(NULL));
        goto fail;
    }
    rtcSetDeviceErrorFunction(s->device, rtc_error_cb, s);
    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    int n_moving_spheres = 0;
    for (int i = 0; i < s->n_spheres; i++)
        n_moving_spheres += s->spheres[i].n_keys > 1;
    s->n_geom = s->n_meshes + 1 + n_moving_spheres + s->n_instances;
    s->geom_index = malloc(sizeof(int) * (size_t)s->n_geom);
    if (!s->geom_index) {
        lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        goto fail;
    }
    s->max_keys = 1;
    lf_vec3 bmin = lf_v3(INFINITY, INFINITY, INFINITY), bmax = lf_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int m = 0; m < s->n_meshes; m++) {
        lf_mesh *me = &s->meshes[m];
        if (me->proto >= 0)
            continue; /* in its prototype's scene, below */
        unsigned id = attach_mesh(s->device, s->rtc, me, RTC_INVALID_GEOMETRY_ID);
        s->geom_index[id] = m;
        if (me->n_keys > 1)
            s->moving_shapes++;
        if (me->n_keys > s->max_keys)
            s->max_keys = me->n_keys;
        for (size_t v = 0; v < (size_t)me->n_verts * me->n_keys; v++) {
            const float *p = me->P + 3 * v;
            bmin = lf_v3(fminf(bmin.x, p[0]), fminf(bmin.y, p[1]), fminf(bmin.z, p[2]));
            bmax = lf_v3(fmaxf(bmax.x, p[0]), fmaxf(bmax.y, p[1]), fmaxf(bmax.z, p[2]));
        }
    }
    if (s->n_spheres) {
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
                bmin = lf_v3(fminf(bmin.x, c.x - sp->radius), fminf(bmin.y, c.y - sp->radius),
                             fminf(bmin.z, c.z - sp->radius));
                bmax = lf_v3(fmaxf(bmax.x, c.x + sp->radius), fmaxf(bmax.y, c.y + sp->radius),
                             fmaxf(bmax.z, c.z + sp->radius));
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
    /* Rigidly moving shapes: static prototype scenes placed by instances. */
    for (int p = 0; p < s->n_protos; p++) {
        lf_proto *pr = &s->protos[p];
        pr->rtc = rtcNewScene(s->device);
        rtcSetSceneBuildQuality(pr->rtc, RTC_BUILD_QUALITY_HIGH);
        for (int m = 0; m < pr->n_meshes; m++)
            attach_mesh(s->device, pr->rtc, &s->meshes[pr->mesh_first + m], (unsigned)m);
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
                bmin = lf_v3(fminf(bmin.x, w[0]), fminf(bmin.y, w[1]), fminf(bmin.z, w[2]));
                bmax = lf_v3(fmaxf(bmax.x, w[0]), fmaxf(bmax.y, w[1]), fmaxf(bmax.z, w[2]));
            }
        }
    }
    rtcCommitScene(s->rtc);
    {
        /* The error callback stays quiet (it may run on render threads);
         * what went wrong while building is an error here. */
        enum RTCError e = rtcGetDeviceError(s->device);
        if (e != RTC_ERROR_NONE) {
            lf_error_set(err, LF_ERR_INTERNAL, "Embree could not build the scene (error %d%s%s)", (int)e,
                         s->rtc_error_msg[0] ? ": " : "", s->rtc_error_msg);
            goto fail;
        }
    }
    if (bmin.x > bmax.x)
        bmin = bmax = lf_v3(0, 0, 0);
    s->bounds_min = bmin;
    s->bounds_max = bmax;
    s->scene_center = lf_scale(lf_add(bmin, bmax), 0.5f);
    s->scene_radius = fmaxf(lf_length(lf_sub(bmax, bmin)) * 0.5f, 1e-3f);
    /* Infinite and distant lights need the scene radius for their power. */
    {
        double *pw = malloc(sizeof(double) * (size_t)(s->n_lights ? s->n_lights : 1));
        if (!pw) {
            lf_error_set(err, LF_ERR_NOMEM, "out of memory");
            goto fail;
        }
        s->nee_lights = malloc(sizeof(int) * (size_t)(s->n_lights ? s->n_lights : 1));
        if (!s->nee_lights) {
            free(pw);
            lf_error_set(err, LF_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (int i = 0; i < s->n_lights; i++) {
            s->lights[i].power = lf_light_power(s, &s->lights[i]);
            int nee = s->lights[i].kind != LF_LIGHT_INFINITE_UNIFORM;
            pw[i] = nee ? s->lights[i].power : 0.0;
            if (nee)
                s->nee_lights[s->n_nee_lights++] = i;
        }
        int rc = s->n_lights ? lf_distrib1d_init(&s->light_distrib, pw, s->n_lights, err) : 0;
        free(pw);
        if (rc)
            goto fail;
    }
    return 0;
fail:
    free(b.object_proto);
    lf_scene_free(s);
    return err && err->code ? err->code : LF_ERR_INTERNAL;
}

int lf_scene_build_white(lf_scene *s, lf_error *err)
{
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
    s->lights = calloc(1, sizeof *s->lights);
    s->infinite_lights = malloc(sizeof(int));
    s->device = rtcNewDevice("verbose=0");
    if (!s->lights || !s->infinite_lights || !s->device) {
        lf_scene_free(s);
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot set up the white scene");
    }
    s->rtc = rtcNewScene(s->device);
    rtcCommitScene(s->rtc);
    s->lights[0].kind = LF_LIGHT_INFINITE_UNIFORM;
    s->lights[0].L = lf_v3(1, 1, 1);
    s->lights[0].mesh = s->lights[0].sphere = -1;
    s->n_lights = 1;
    s->infinite_lights[0] = 0;
    s->n_infinite = 1;
    s->scene_radius = 1;
    s->camera_medium = -1;
    double one = 1;
    return lf_distrib1d_init(&s->light_distrib, &one, 1, err);
}

void lf_scene_free(lf_scene *s)
{
    if (s->rtc)
        rtcReleaseScene(s->rtc);
    for (int p = 0; p < s->n_protos; p++)
        if (s->protos[p].rtc)
            rtcReleaseScene(s->protos[p].rtc);
    free(s->protos);
    free(s->instances);
    if (s->device)
        rtcReleaseDevice(s->device);
    for (int i = 0; i < s->n_meshes; i++) {
        free(s->meshes[i].idx);
        free(s->meshes[i].P);
        free(s->meshes[i].N);
        free(s->meshes[i].uv);
    }
    free(s->meshes);
    for (int i = 0; i < s->n_spheres; i++)
        free(s->spheres[i].centers);
    free(s->spheres);
    free(s->geom_index);
    for (int i = 0; i < s->n_lights; i++)
        if (s->lights[i].env) {
            lf_envmap_free(s->lights[i].env);
            free(s->lights[i].env);
        }
    free(s->lights);
    free(s->infinite_lights);
    free(s->nee_lights);
    if (s->n_lights)
        lf_distrib1d_free(&s->light_distrib);
    lf_materials_free(s->materials);
    free(s->media);
    lf_warnings_free(&s->warnings);
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
}

/* ---- intersection ---- */

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
    struct RTCRayHit rh;
    init_ray(&rh, o, d, tmax, tau);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(s->rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    hit->t = rh.ray.tfar;
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
