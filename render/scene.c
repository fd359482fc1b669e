/* Scene building: shape descriptions -> world-space geometry -> Embree.
 *
 * Triangles go to Embree triangle geometries; full spheres under a
 * similarity transform go to one Embree sphere-point geometry (exact
 * intersections, no tessellation); partial spheres, disks and bilinear
 * patches are tessellated finely enough that their area differs from the
 * analytic one by well under 0.1%.  Object instances are flattened. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render_internal.h"

void lf_warn_append(char **buf, const char *fmt, ...)
{
    char line[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    size_t old = *buf ? strlen(*buf) : 0, add = strlen(line);
    char *n = realloc(*buf, old + add + 2);
    if (!n)
        return;
    memcpy(n + old, line, add);
    n[old + add] = '\n';
    n[old + add + 1] = '\0';
    *buf = n;
}

/* The keyframes of a shape's motion over the TransformTimes interval (Embree
 * time 0..1), evenly spaced; n == 1 for a static shape. */
typedef struct motion {
    const lf_transform *keys;
    int n;
} motion;

typedef struct builder {
    lf_scene *s;
    lf_scene_desc *d;
    int cap_meshes, cap_spheres, cap_lights;
    lf_error *err;
} builder;

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

static void loc_prefix(char *buf, size_t n, const lf_loc *loc)
{
    snprintf(buf, n, "%s:%d:%d", loc->file ? loc->file : "<scene>", loc->line, loc->col);
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
    loc_prefix(where, sizeof where, &e->loc);
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

static int add_mesh_lights(builder *b, lf_mesh *m, int area_light)
{
    m->light_first = -1;
    if (area_light < 0)
        return 0;
    area_emission ae;
    if (read_area_light(b, area_light, &ae))
        return b->err->code;
    double total_area = 0;
    for (int t = 0; t < m->n_tris; t++) {
        const float *p0 = m->P + 3 * m->idx[3 * t], *p1 = m->P + 3 * m->idx[3 * t + 1], *p2 = m->P + 3 * m->idx[3 * t + 2];
        lf_vec3 e1 = lf_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        lf_vec3 e2 = lf_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        total_area += 0.5 * lf_length(lf_cross(e1, e2));
    }
    lf_vec3 L = ae.L;
    apply_area_power(&L, &ae, total_area);
    m->light_first = b->s->n_lights;
    int mesh_index = b->s->n_meshes; /* the mesh is pushed right after this */
    for (int t = 0; t < m->n_tris; t++) {
        const float *p0 = m->P + 3 * m->idx[3 * t], *p1 = m->P + 3 * m->idx[3 * t + 1], *p2 = m->P + 3 * m->idx[3 * t + 2];
        lf_vec3 e1 = lf_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        lf_vec3 e2 = lf_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        lf_light l = {0};
        l.kind = LF_LIGHT_TRIANGLE;
        l.L = L;
        l.mesh = mesh_index;
        l.prim = t;
        l.area = 0.5f * lf_length(lf_cross(e1, e2));
        l.twosided = ae.twosided;
        l.sphere = -1;
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
            loc_prefix(where, sizeof where, &sh->e.loc);
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
                loc_prefix(where, sizeof where, &sh->e.loc);
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
    m.material = sh->material;
    m.flip_normal = sh->reverse_orientation ^ lf_transform_swaps_handedness(xf);
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
    loc_prefix(where, sizeof where, &sh->e.loc);
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
    loc_prefix(where, sizeof where, &sh->e.loc);
    if (!fn)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: Shape \"plymesh\" needs \"string filename\"", where);
    if (lf_params_find(ps, "displacement"))
        lf_warn_append(&b->s->warnings, "%s: warning: plymesh displacement is not supported; rendering undisplaced",
                       where);
    char path[4096];
    if (fn[0] == '/' || !sh->base_dir || !sh->base_dir[0])
        snprintf(path, sizeof path, "%s", fn);
    else
        snprintf(path, sizeof path, "%s/%s", sh->base_dir, fn);
    lf_ply_mesh pm;
    lf_error perr = {0};
    if (lf_ply_read(path, &pm, &perr))
        return lf_error_set(b->err, perr.code, "%s: Shape \"plymesh\": %s", where, perr.msg);
    lf_ply_mesh copy = pm;
    return finish_mesh(b, sh, mo, copy.P, (int)copy.n_vertices, copy.N, copy.uv, copy.indices, (int)copy.n_triangles);
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
    loc_prefix(where, sizeof where, &sh->e.loc);
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
    if (full && scale > 0) {
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
                char where[512];
                loc_prefix(where, sizeof where, &sh->e.loc);
                lf_warn_append(&b->s->warnings, "%s: warning: a sphere whose scale changes during the shutter keeps its "
                               "starting radius", where);
            }
        }
        sp.object_to_world = *xf;
        sp.material = sh->material;
        sp.flip_normal = sh->reverse_orientation ^ lf_transform_swaps_handedness(xf);
        sp.light = -1;
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
    loc_prefix(where, sizeof where, &sh->e.loc);
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
    loc_prefix(where, sizeof where, &sh->e.loc);
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
    {"disk", shape_disk},                 {"bilinearmesh", shape_bilinearmesh},
};

static int build_shape(builder *b, lf_shape_desc *sh, const motion *mo)
{
    char where[512];
    loc_prefix(where, sizeof where, &sh->e.loc);
    if (sh->e.params.count && lf_params_peek(&sh->e.params, "alpha")) {
        lf_params_find(&sh->e.params, "alpha");
        lf_warn_append(&b->s->warnings, "%s: warning: \"alpha\" cut-outs are not supported; the shape is opaque", where);
    }
    for (size_t i = 0; i < sizeof shape_table / sizeof shape_table[0]; i++)
        if (strcmp(shape_table[i].name, sh->e.type) == 0) {
            if (shape_table[i].fn(b, sh, mo))
                return b->err->code;
            char ctx[256];
            snprintf(ctx, sizeof ctx, "Shape \"%s\"", sh->e.type);
            return lf_params_finish(&sh->e.params, ctx, b->err);
        }
    lf_warn_append(&b->s->warnings, "%s: warning: Shape \"%s\" is not supported; it is left out of the render", where,
                   sh->e.type);
    for (size_t i = 0; i < sh->e.params.count; i++)
        sh->e.params.items[i].used = 1;
    return 0;
}

int lf_scene_build_lights(lf_scene_desc *d, lf_scene *s, lf_error *err); /* lights.c */

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

static void rtc_error_cb(void *user, enum RTCError code, const char *str)
{
    (void)user;
    (void)code;
    (void)str;
}

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
    loc_prefix(where, sizeof where, &sh->e.loc);
    if (requested < 0 || requested > 1024)
        return lf_error_set(b->err, LF_ERR_PARAM, "%s: \"motionsegments\" must be in 1..1024, got %d", where, requested);
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
    if (segs > 1024)
        segs = 1024;
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

static int build_shape_moving(builder *b, lf_shape_desc *sh, const lf_anim_xform *inst)
{
    lf_transform *keys = NULL;
    int n = 0;
    if (motion_keys(b, sh, inst, &keys, &n))
        return b->err->code;
    motion mo = {keys, n};
    int rc = build_shape(b, sh, &mo);
    free(keys);
    return rc;
}

int lf_scene_build(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
    s->time0 = d->transform_start_time;
    s->time1 = d->transform_end_time;
    builder b = {s, d, 0, 0, 0, err};
    if (lf_materials_build(d, &s->materials, err))
        goto fail;
    if (lf_materials_warnings(s->materials))
        lf_warn_append(&s->warnings, "%s", lf_materials_warnings(s->materials));
    for (size_t i = 0; i < d->n_shapes; i++) {
        lf_shape_desc *sh = &d->shapes[i];
        if (sh->object >= 0)
            continue; /* instantiated below */
        if (build_shape_moving(&b, sh, NULL))
            goto fail;
    }
    for (size_t k = 0; k < d->n_instances; k++) {
        lf_instance_desc *in = &d->instances[k];
        for (size_t i = 0; i < d->n_shapes; i++) {
            lf_shape_desc *sh = &d->shapes[i];
            if (sh->object != in->object)
                continue;
            if (build_shape_moving(&b, sh, &in->instance_to_world))
                goto fail;
        }
    }
    if (lf_scene_build_lights(d, s, err))
        goto fail;

    /* Embree */
    s->device = rtcNewDevice("verbose=0");
    if (!s->device) {
        lf_error_set(err, LF_ERR_INTERNAL, "cannot create the Embree device (error %d)", (int)rtcGetDeviceError(NULL));
        goto fail;
    }
    rtcSetDeviceErrorFunction(s->device, rtc_error_cb, NULL);
    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    int n_moving_spheres = 0;
    for (int i = 0; i < s->n_spheres; i++)
        n_moving_spheres += s->spheres[i].n_keys > 1;
    s->n_geom = s->n_meshes + 1 + n_moving_spheres;
    s->geom_index = malloc(sizeof(int) * (size_t)s->n_geom);
    if (!s->geom_index) {
        lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        goto fail;
    }
    s->max_keys = 1;
    lf_vec3 bmin = lf_v3(INFINITY, INFINITY, INFINITY), bmax = lf_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int m = 0; m < s->n_meshes; m++) {
        lf_mesh *me = &s->meshes[m];
        RTCGeometry g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (me->n_keys > 1) {
            /* Motion: one vertex buffer per keyframe over Embree time 0..1. */
            rtcSetGeometryTimeStepCount(g, (unsigned)me->n_keys);
            s->moving_shapes++;
        }
        for (int k = 0; k < me->n_keys; k++)
            rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, (unsigned)k, RTC_FORMAT_FLOAT3,
                                       me->P + (size_t)k * 3 * me->n_verts, 0, 3 * sizeof(float), (size_t)me->n_verts);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, me->idx, 0, 3 * sizeof(int),
                                   (size_t)me->n_tris);
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(s->rtc, g);
        rtcReleaseGeometry(g);
        s->geom_index[id] = m;
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
    rtcCommitScene(s->rtc);
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
        for (int i = 0; i < s->n_lights; i++)
            s->lights[i].power = pw[i] = lf_light_power(s, &s->lights[i]);
        int rc = s->n_lights ? lf_distrib1d_init(&s->light_distrib, pw, s->n_lights, err) : 0;
        free(pw);
        if (rc)
            goto fail;
    }
    return 0;
fail:
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
    double one = 1;
    return lf_distrib1d_init(&s->light_distrib, &one, 1, err);
}

void lf_scene_free(lf_scene *s)
{
    if (s->rtc)
        rtcReleaseScene(s->rtc);
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
    if (s->n_lights)
        lf_distrib1d_free(&s->light_distrib);
    lf_materials_free(s->materials);
    free(s->warnings);
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
}

/* ---- intersection ---- */

lf_vec3 lf_offset_origin(lf_vec3 p, lf_vec3 ng, lf_vec3 w)
{
    /* Float error of an intersection point grows with its magnitude; a few
     * ulps of the largest coordinate (plus an absolute floor) clears it. */
    float m = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    float eps = 1e-6f + m * 4e-6f;
    return lf_madd(p, ng, lf_dot(ng, w) >= 0 ? eps : -eps);
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
    int gi = s->geom_index[rh.hit.geomID];
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
        if (sp->flip_normal)
            n = lf_neg(n);
        sc->ng = sc->ns = n;
        hit->material = sp->material;
        hit->light = sp->light;
        return 1;
    }
    hit->sphere = -1;
    hit->tau = tau;
    const lf_mesh *m = &s->meshes[gi];
    int t = (int)rh.hit.primID;
    int i0 = m->idx[3 * t], i1 = m->idx[3 * t + 1], i2 = m->idx[3 * t + 2];
    lf_vec3 p0 = lf_mesh_vertex_at(m, i0, tau), p1 = lf_mesh_vertex_at(m, i1, tau), p2 = lf_mesh_vertex_at(m, i2, tau);
    float b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1.f - b1 - b2;
    sc->p = lf_add(lf_add(lf_scale(p0, b0), lf_scale(p1, b1)), lf_scale(p2, b2));
    /* pbrt-v4 Triangle: n = normalize(cross(p0 - p2, p1 - p2)). */
    lf_vec3 n = lf_normalize(lf_cross(lf_sub(p0, p2), lf_sub(p1, p2)));
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
        }
    }
    sc->dpdu = lf_normalize(dpdu);
    if (m->N) {
        lf_vec3 n0 = lf_mesh_normal_at(m, i0, tau), n1 = lf_mesh_normal_at(m, i1, tau), n2 = lf_mesh_normal_at(m, i2, tau);
        lf_vec3 ns = lf_normalize(lf_add(lf_add(lf_scale(n0, b0), lf_scale(n1, b1)), lf_scale(n2, b2)));
        if (!(lf_dot(ns, ns) > 0))
            ns = n;
        /* pbrt: the geometric normal follows the shading normal's side. */
        if (lf_dot(n, ns) < 0)
            n = lf_neg(n);
        sc->ns = ns;
    } else {
        if (m->flip_normal)
            n = lf_neg(n);
        sc->ns = n;
    }
    sc->ng = n;
    hit->material = m->material;
    hit->light = m->light_first >= 0 ? m->light_first + t : -1;
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
