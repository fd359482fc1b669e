/* Shapes as the renderer's geometry: triangle meshes (trianglemesh,
 * plymesh, loopsubdiv, and tessellated partial spheres, disks and bilinear
 * patches, fine enough that their area differs from the analytic one by
 * well under 0.1%) and analytic spheres for full spheres under a similarity
 * transform; emissive shapes get their area lights.  Vertices are placed by
 * the keyframes render/motion.c chose, in world space or a prototype's. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/lf_subdiv.h"
#include "render/lights.h"
#include "render/media.h"
#include "render/scene_build.h"

/* A shape's MediumInterface as medium indices; *in = LF_MEDIUM_SAME when
 * it changes nothing (none given, or one medium on both sides). */
static int shape_media(lf_scene_builder *b, const lf_shape_desc *sh, int *in, int *out)
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

static int push_mesh(lf_scene_builder *b, lf_mesh *m)
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

static int push_light(lf_scene_builder *b, const lf_light *l)
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

static int read_area_light(lf_scene_builder *b, int index, area_emission *ae)
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
static int add_mesh_lights(lf_scene_builder *b, lf_mesh *m, int area_light)
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
    /* an alpha-masked emitter is masked per triangle point: no quads */
    int quads = m->n_keys == 1 && !m->N && m->n_tris % 2 == 0 && m->n_tris > 0 && m->alpha >= 1 && !m->alpha_tex;
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
        l.has_alpha = m->alpha < 1 || m->alpha_tex;
        l.alpha = m->alpha;
        l.alpha_tex = m->alpha_tex;
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
static int finish_mesh(lf_scene_builder *b, const lf_shape_desc *sh, const lf_shape_motion *mo, float *P, int nv, float *N,
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
    m.alpha = b->alpha;
    m.alpha_tex = b->alpha_tex;
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

static int shape_trianglemesh(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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

static int shape_plymesh(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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
static int shape_loopsubdiv(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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

static int tessellate(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo, surface_fn f, const double *prm, int nu,
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
    /* pbrt-v4's quadrics: the normal cross(dp/du, dp/dv) (outward) is
     * flipped when ReverseOrientation XOR the transform swaps handedness;
     * the tessellation's vertex normals carry that side (the geometric
     * normal and an area light's emitting side follow them). */
    if (N && (sh->reverse_orientation ^ lf_transform_swaps_handedness(&mo->keys[0])))
        for (int k = 0; k < 3 * nv; k++)
            N[k] = -N[k];
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

static int shape_sphere(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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
    /* An alpha-cut sphere is tessellated: the alpha filter is on meshes. */
    int full = zmin <= -r && zmax >= r && phimax >= 360.0 && b->alpha >= 1 && !b->alpha_tex;
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

static int shape_disk(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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

/* pbrt's cylinder: phi = u phimax around z, z from zmin (v = 0) to zmax;
 * the outward normal is cross(dp/du, dp/dv). */
static void cylinder_surface(const double *prm, double u, double v, double out[3], double nrm[3])
{
    double r = prm[0], z0 = prm[1], z1 = prm[2], phimax = prm[3];
    double phi = u * phimax;
    nrm[0] = cos(phi), nrm[1] = sin(phi), nrm[2] = 0;
    out[0] = r * nrm[0], out[1] = r * nrm[1], out[2] = z0 + v * (z1 - z0);
}

static int shape_cylinder(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
{
    lf_paramset *ps = &sh->e.params;
    double r = lf_params_float(ps, "radius", 1.0), zmin = lf_params_float(ps, "zmin", -1.0),
           zmax = lf_params_float(ps, "zmax", 1.0), phimax = lf_params_float(ps, "phimax", 360.0);
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (!(r > 0) || !isfinite(r) || !isfinite(zmin) || !isfinite(zmax))
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"cylinder\": need a positive radius and finite zmin, zmax",
                            where);
    /* pbrt-v4 orders zmin, zmax and clamps phimax to [0, 360] */
    double prm[4] = {r, fmin(zmin, zmax), fmax(zmin, zmax), lf_clampd(phimax, 0, 360) * LF_PI / 180};
    if (prm[1] == prm[2] || prm[3] == 0)
        return 0; /* no area: nothing to intersect, as in pbrt */
    /* 1024 segments around: the polygon's silhouette width and area differ
     * from the circle's by 1 - cos(pi/1024) = 4.7e-6 at most. */
    int nu = (int)ceil(1024 * prm[3] / (2 * LF_PI));
    return tessellate(b, sh, mo, cylinder_surface, prm, nu < 4 ? 4 : nu, 1, 1);
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

static int shape_bilinearmesh(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
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

typedef int (*shape_fn)(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo);
static const struct {
    const char *name;
    shape_fn fn;
} shape_table[] = {
    {"trianglemesh", shape_trianglemesh}, {"plymesh", shape_plymesh}, {"sphere", shape_sphere},
    {"disk", shape_disk},                 {"bilinearmesh", shape_bilinearmesh}, {"loopsubdiv", shape_loopsubdiv},
    {"cylinder", shape_cylinder},         {"curve", lf_build_curve},
};

int lf_shape_known(const char *type)
{
    for (size_t i = 0; i < sizeof shape_table / sizeof shape_table[0]; i++)
        if (strcmp(shape_table[i].name, type) == 0)
            return 1;
    return 0;
}

int lf_build_shape(lf_scene_builder *b, lf_shape_desc *sh, const lf_shape_motion *mo)
{
    char where[512];
    lf_loc_format(where, sizeof where, &sh->e.loc);
    if (lf_shape_known(sh->e.type) && lf_read_shape_alpha(b, sh))
        return b->err->code;
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
