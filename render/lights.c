/* Light sources with pbrt-v4 parameters and semantics: point, spot,
 * distant, infinite (uniform or equal-area octahedral image) and diffuse
 * area lights on triangles, parallelograms (quads of two triangles) and spheres.  Spectra become linear sRGB; an RGB
 * light of "scale" 1 renders its RGB values (pbrt-v4 divides lights by the
 * photometric value of their illuminant, which is 1 for RGB illuminants).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/lf_image.h"
#include "render/lights.h"
#include "render/scene_build.h"

/* Clarberg's equal-area mapping between the unit square and the sphere, as
 * pbrt-v4 uses for environment maps (octahedral layout). */
lf_vec3 lf_equal_area_square_to_sphere(float pu, float pv)
{
    float u = 2 * pu - 1, v = 2 * pv - 1;
    float up = fabsf(u), vp = fabsf(v);
    float sd = 1 - (up + vp);
    float d = fabsf(sd);
    float r = 1 - d;
    float phi = (r == 0 ? 1 : (vp - up) / r + 1) * (float)(LF_PI / 4);
    float z = copysignf(1 - r * r, sd);
    float cphi = copysignf(cosf(phi), u), sphi = copysignf(sinf(phi), v);
    float s = r * sqrtf(fmaxf(0.f, 2 - r * r));
    return lf_v3(cphi * s, sphi * s, z);
}

void lf_equal_area_sphere_to_square(lf_vec3 d, float *ou, float *ov)
{
    float x = fabsf(d.x), y = fabsf(d.y), z = fabsf(d.z);
    float r = sqrtf(fmaxf(0.f, 1 - z));
    float a = fmaxf(x, y), b = fminf(x, y);
    b = a == 0 ? 0 : b / a;
    float phi = atanf(b) * (float)(2 / LF_PI);
    if (x < y)
        phi = 1 - phi;
    float v = phi * r, u = r - v;
    if (d.z < 0) {
        float t = u;
        u = v;
        v = t;
        u = 1 - u;
        v = 1 - v;
    }
    u = copysignf(u, d.x);
    v = copysignf(v, d.y);
    *ou = lf_clampf((u + 1) * 0.5f, 0.f, LF_ONE_MINUS_EPS);
    *ov = lf_clampf((v + 1) * 0.5f, 0.f, LF_ONE_MINUS_EPS);
}

int lf_envmap_load(const char *path, lf_envmap *env, lf_error *err)
{
    memset(env, 0, sizeof *env);
    lf_image img;
    lf_error ierr = {0};
    if (lf_image_read(path, &img, NULL, &ierr))
        return lf_error_set(err, ierr.code, "%s", ierr.msg);
    if (img.width != img.height) {
        lf_image_free(&img);
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: environment maps must be square (pbrt-v4's equal-area octahedral layout), got %dx%d",
                            path, img.width, img.height);
    }
    size_t n = (size_t)img.width * img.height;
    env->width = img.width;
    env->height = img.height;
    env->rgb = malloc(sizeof(float) * 3 * n);
    double *f = malloc(sizeof(double) * n);
    if (!env->rgb || !f) {
        free(f);
        lf_image_free(&img);
        lf_envmap_free(env);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for %s", path);
    }
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        const float *px = img.data + i * img.channels;
        for (int c = 0; c < 3; c++) {
            float v = px[img.channels >= 3 ? c : 0];
            if (!isfinite(v) || v < 0) {
                bad++;
                v = 0;
            }
            env->rgb[3 * i + c] = v;
        }
        f[i] = (env->rgb[3 * i] + env->rgb[3 * i + 1] + env->rgb[3 * i + 2]) / 3.0;
    }
    lf_image_free(&img);
    if (bad) {
        free(f);
        lf_envmap_free(env);
        return lf_error_set(err, LF_ERR_NUMERIC, "%s: %zu pixel values are negative, NaN or Inf", path, bad);
    }
    int rc = lf_distrib2d_init(&env->distrib, f, env->width, env->height, err);
    free(f);
    if (rc)
        lf_envmap_free(env);
    return rc;
}

void lf_envmap_free(lf_envmap *env)
{
    free(env->rgb);
    env->rgb = NULL;
    if (env->distrib.conditional)
        lf_distrib2d_free(&env->distrib);
}

static lf_vec3 env_lookup(const lf_envmap *env, float u, float v)
{
    /* nearest texel: the sampling density is piecewise constant per texel,
     * so Le and pdf agree exactly (no bias between the MIS strategies). */
    int x = (int)(u * env->width), y = (int)(v * env->height);
    x = x < 0 ? 0 : (x >= env->width ? env->width - 1 : x);
    y = y < 0 ? 0 : (y >= env->height ? env->height - 1 : y);
    const float *p = env->rgb + 3 * ((size_t)y * env->width + x);
    return lf_v3(p[0], p[1], p[2]);
}

lf_vec3 lf_light_infinite_le(const lf_light *l, lf_vec3 dir)
{
    if (l->kind == LF_LIGHT_INFINITE_UNIFORM)
        return l->L;
    lf_transform w2l = lf_transform_inverse(&l->env->light_to_world);
    lf_vec3 wl = lf_normalize(lf_xform_vector(&w2l, dir));
    float u, v;
    lf_equal_area_sphere_to_square(wl, &u, &v);
    return lf_mul(l->L, env_lookup(l->env, u, v));
}

lf_vec3 lf_light_area_le(const lf_light *l, const lf_hit *hit, lf_vec3 w)
{
    if (!l->twosided && lf_dot(hit->sc.ng, w) >= 0)
        return lf_v3(0, 0, 0);
    if (l->has_alpha && lf_alpha_masked(l->alpha, l->alpha_tex, hit->sc.p, hit->sc.uv))
        return lf_v3(0, 0, 0);
    return l->L;
}

static float smoothstep(float x, float a, float b)
{
    if (a == b)
        return x < a ? 0.f : 1.f;
    float t = lf_clampf((x - a) / (b - a), 0, 1);
    return t * t * (3 - 2 * t);
}

/* Point and spot lights: the one direction to the light, inverse-square
 * falloff, the spot's smoothstep cone. */
static int sample_point_li(const lf_light *l, lf_vec3 p, lf_light_sample *ls)
{
    lf_vec3 d = lf_sub(l->pos, p);
    float d2 = lf_dot(d, d);
    if (!(d2 > 0))
        return 0;
    float dist = sqrtf(d2);
    ls->wi = lf_scale(d, 1.f / dist);
    ls->dist = dist;
    ls->pdf = 1;
    ls->delta = 1;
    float k = 1.f / d2;
    if (l->kind == LF_LIGHT_SPOT)
        k *= smoothstep(lf_dot(lf_neg(ls->wi), l->dir), l->cos_total, l->cos_start);
    ls->Li = lf_scale(l->L, k);
    return k > 0;
}

/* An environment map: a texel by its importance (the distribution over the
 * equal-area square), then a direction in it. */
static int sample_envmap_li(const lf_light *l, float u0, float u1, lf_light_sample *ls)
{
    double u, v, pdf;
    lf_distrib2d_sample(&l->env->distrib, u0, u1, &u, &v, &pdf);
    if (!(pdf > 0))
        return 0;
    lf_vec3 wl = lf_equal_area_square_to_sphere((float)u, (float)v);
    ls->wi = lf_normalize(lf_xform_vector(&l->env->light_to_world, wl));
    ls->pdf = (float)(pdf * LF_INV_4PI); /* equal-area: dA = dw / 4pi */
    ls->dist = INFINITY;
    ls->Li = lf_mul(l->L, env_lookup(l->env, (float)u, (float)v));
    return 1;
}

/* A triangle or parallelogram area light: a uniform point on it at Embree
 * time tau, as a solid-angle pdf from p. */
static int sample_mesh_li(const lf_scene *s, const lf_light *l, lf_vec3 p, float tau, float u0, float u1,
                          lf_light_sample *ls)
{
    const lf_mesh *m = &s->meshes[l->mesh];
    int t = l->prim;
    lf_vec3 pa = lf_mesh_vertex_at(m, m->idx[3 * t], tau), pb = lf_mesh_vertex_at(m, m->idx[3 * t + 1], tau),
            pc = lf_mesh_vertex_at(m, m->idx[3 * t + 2], tau);
    lf_vec3 n = lf_normalize(lf_cross(lf_sub(pa, pc), lf_sub(pb, pc)));
    lf_vec3 q;
    if (l->kind == LF_LIGHT_PARALLELOGRAM) {
        /* uniform over the parallelogram (a static mesh without vertex
         * normals: lf_mesh.light_quads) */
        lf_vec3 c = lf_mesh_vertex_at(m, l->quad[0], tau);
        lf_vec3 e1 = lf_sub(lf_mesh_vertex_at(m, l->quad[1], tau), c);
        lf_vec3 e2 = lf_sub(lf_mesh_vertex_at(m, l->quad[2], tau), c);
        q = lf_add(c, lf_add(lf_scale(e1, u0), lf_scale(e2, u1)));
        if (m->flip_normal)
            n = lf_neg(n);
    } else {
        /* uniform barycentrics (Heitz's low-distortion square-to-triangle) */
        float b0, b1;
        if (u0 < u1) {
            b0 = u0 / 2;
            b1 = u1 - b0;
        } else {
            b1 = u1 / 2;
            b0 = u0 - b1;
        }
        float b2 = 1 - b0 - b1;
        q = lf_add(lf_add(lf_scale(pa, b0), lf_scale(pb, b1)), lf_scale(pc, b2));
        if (l->has_alpha) {
            /* pbrt-v4's DiffuseAreaLight emits nothing where alpha masks */
            lf_vec2 uv0 = {0, 0}, uv1 = {1, 0}, uv2 = {1, 1};
            if (m->uv) {
                const float *u = m->uv;
                uv0 = (lf_vec2){u[2 * m->idx[3 * t]], u[2 * m->idx[3 * t] + 1]};
                uv1 = (lf_vec2){u[2 * m->idx[3 * t + 1]], u[2 * m->idx[3 * t + 1] + 1]};
                uv2 = (lf_vec2){u[2 * m->idx[3 * t + 2]], u[2 * m->idx[3 * t + 2] + 1]};
            }
            lf_vec2 uv = {b0 * uv0.x + b1 * uv1.x + b2 * uv2.x, b0 * uv0.y + b1 * uv1.y + b2 * uv2.y};
            if (lf_alpha_masked(l->alpha, l->alpha_tex, q, uv))
                return 0;
        }
        if (m->N) {
            lf_vec3 na = lf_mesh_normal_at(m, m->idx[3 * t], tau), nb = lf_mesh_normal_at(m, m->idx[3 * t + 1], tau),
                    nc = lf_mesh_normal_at(m, m->idx[3 * t + 2], tau);
            lf_vec3 ns = lf_add(lf_add(lf_scale(na, b0), lf_scale(nb, b1)), lf_scale(nc, b2));
            if (lf_dot(n, ns) < 0)
                n = lf_neg(n);
        } else if (m->flip_normal) {
            n = lf_neg(n);
        }
    }
    lf_vec3 d = lf_sub(q, p);
    float d2 = lf_dot(d, d);
    if (!(d2 > 0) || !(l->area > 0))
        return 0;
    float dist = sqrtf(d2);
    ls->wi = lf_scale(d, 1.f / dist);
    float cosl = lf_dot(n, ls->wi); /* light normal vs direction from the light to p is -wi */
    if (!l->twosided && cosl >= 0)
        return 0;
    if (cosl == 0)
        return 0;
    ls->pdf = d2 / (fabsf(cosl) * l->area);
    ls->dist = dist;
    ls->Li = l->L;
    return isfinite(ls->pdf);
}

/* A sphere light: a direction in the cone the sphere subtends from p
 * (uniform in solid angle), then the near intersection along it. */
static int sample_sphere_li(const lf_scene *s, const lf_light *l, lf_vec3 p, float tau, float u0, float u1,
                            lf_light_sample *ls)
{
    const lf_sphere *sp = &s->spheres[l->sphere];
    lf_vec3 dc = lf_sub(lf_sphere_center_at(sp, tau), p);
    float dc2 = lf_dot(dc, dc), r = sp->radius;
    if (dc2 <= r * r * 1.0001f)
        return 0; /* inside or on the sphere: light sampling skipped, BSDF sampling still finds it */
    float dcl = sqrtf(dc2);
    lf_vec3 wc = lf_scale(dc, 1.f / dcl), s1, s2;
    lf_basis(wc, &s1, &s2);
    float sin2 = r * r / dc2, cos_max = sqrtf(fmaxf(0.f, 1 - sin2));
    /* For tiny cones the float subtraction 1 - cos loses precision;
     * 1 - cos_max = sin2 / (1 + cos_max) keeps it. */
    float one_minus_cos = sin2 / (1 + cos_max);
    float c = 1 - u0 * one_minus_cos;
    float sn = sqrtf(fmaxf(0.f, 1 - c * c));
    float phi = u1 * (float)(2 * LF_PI);
    lf_vec3 w = lf_add(lf_add(lf_scale(s1, sn * cosf(phi)), lf_scale(s2, sn * sinf(phi))), lf_scale(wc, c));
    /* distance to the near intersection along w */
    float b = lf_dot(w, dc);
    float disc = b * b - (dc2 - r * r);
    float t = b - sqrtf(fmaxf(0.f, disc));
    ls->wi = w;
    ls->dist = t;
    ls->pdf = 1.f / ((float)(2 * LF_PI) * one_minus_cos);
    ls->Li = sp->flip_normal && !l->twosided ? lf_v3(0, 0, 0) : l->L;
    return !lf_is_black(ls->Li) && isfinite(ls->pdf);
}

int lf_light_sample_li(const lf_scene *s, const lf_light *l, lf_vec3 p, float tau, float u0, float u1,
                       lf_light_sample *ls)
{
    ls->delta = 0;
    switch (l->kind) {
    case LF_LIGHT_POINT:
    case LF_LIGHT_SPOT:
        return sample_point_li(l, p, ls);
    case LF_LIGHT_DISTANT:
        ls->wi = l->dir;
        ls->dist = INFINITY;
        ls->pdf = 1;
        ls->delta = 1;
        ls->Li = l->L;
        return 1;
    case LF_LIGHT_INFINITE_UNIFORM: {
        /* uniform sphere */
        float z = 1 - 2 * u0, r = sqrtf(fmaxf(0.f, 1 - z * z)), phi = (float)(2 * LF_PI) * u1;
        ls->wi = lf_v3(r * cosf(phi), r * sinf(phi), z);
        ls->pdf = (float)LF_INV_4PI;
        ls->dist = INFINITY;
        ls->Li = l->L;
        return 1;
    }
    case LF_LIGHT_INFINITE_IMAGE:
        return sample_envmap_li(l, u0, u1, ls);
    case LF_LIGHT_TRIANGLE:
    case LF_LIGHT_PARALLELOGRAM:
        return sample_mesh_li(s, l, p, tau, u0, u1, ls);
    case LF_LIGHT_SPHERE:
        return sample_sphere_li(s, l, p, tau, u0, u1, ls);
    }
    return 0;
}

float lf_light_pdf_li(const lf_scene *s, const lf_light *l, lf_vec3 p, lf_vec3 wi, const lf_hit *hit)
{
    switch (l->kind) {
    case LF_LIGHT_INFINITE_UNIFORM:
        return (float)LF_INV_4PI;
    case LF_LIGHT_INFINITE_IMAGE: {
        lf_transform w2l = lf_transform_inverse(&l->env->light_to_world);
        lf_vec3 wl = lf_normalize(lf_xform_vector(&w2l, wi));
        float u, v;
        lf_equal_area_sphere_to_square(wl, &u, &v);
        return (float)(lf_distrib2d_pdf(&l->env->distrib, u, v) * LF_INV_4PI);
    }
    case LF_LIGHT_TRIANGLE:
    case LF_LIGHT_PARALLELOGRAM: { /* uniform by area: the same density on either kind */
        float cosl = fabsf(lf_dot(hit->sc.ng, wi));
        lf_vec3 d = lf_sub(hit->sc.p, p);
        float d2 = lf_dot(d, d);
        if (cosl == 0 || !(l->area > 0))
            return 0;
        return d2 / (cosl * l->area);
    }
    case LF_LIGHT_SPHERE: {
        const lf_sphere *sp = &s->spheres[l->sphere];
        lf_vec3 dc = lf_sub(lf_sphere_center_at(sp, hit->tau), p);
        float dc2 = lf_dot(dc, dc), r = sp->radius;
        if (dc2 <= r * r * 1.0001f)
            return 0;
        float sin2 = r * r / dc2, cos_max = sqrtf(fmaxf(0.f, 1 - sin2));
        return 1.f / ((float)(2 * LF_PI) * (sin2 / (1 + cos_max)));
    }
    default:
        return 0; /* delta lights are never hit */
    }
}

double lf_light_power(const lf_scene *s, const lf_light *l)
{
    double lum = fmax(0.0, lf_luminance(l->L));
    double r = s->scene_radius;
    switch (l->kind) {
    case LF_LIGHT_POINT:
        return 4 * LF_PI * lum;
    case LF_LIGHT_SPOT:
        return 2 * LF_PI * lum * (1 - 0.5 * (l->cos_start + l->cos_total));
    case LF_LIGHT_DISTANT:
        return LF_PI * r * r * lum;
    case LF_LIGHT_INFINITE_UNIFORM:
        return 4 * LF_PI * LF_PI * r * r * lum;
    case LF_LIGHT_INFINITE_IMAGE: {
        double sum = 0;
        size_t n = (size_t)l->env->width * l->env->height;
        for (size_t i = 0; i < n; i++)
            sum += lf_luminance(lf_v3(l->env->rgb[3 * i], l->env->rgb[3 * i + 1], l->env->rgb[3 * i + 2]));
        return 4 * LF_PI * LF_PI * r * r * lum * sum / (double)n;
    }
    case LF_LIGHT_TRIANGLE:
    case LF_LIGHT_PARALLELOGRAM:
    case LF_LIGHT_SPHERE:
        return LF_PI * (l->twosided ? 2 : 1) * l->area * lum;
    }
    return 0;
}

/* ---- LightSource directives ---- */

/* Point and spot lights ("power", when given, sets the intensity). */
static void read_point_light(lf_paramset *ps, const char *type, const lf_transform *xf, double scale, lf_light *l)
{
    lf_vec3 I;
    lf_params_rgb(ps, "I", LF_SPECTRUM_ILLUMINANT, lf_v3(1, 1, 1), &I);
    double from[3] = {0, 0, 0}, to[3] = {0, 0, 1};
    lf_params_point3(ps, "from", from);
    double power = lf_params_float(ps, "power", -1);
    l->pos = lf_xform_point(xf, lf_v3((float)from[0], (float)from[1], (float)from[2]));
    l->L = lf_scale(I, (float)scale);
    if (!strcmp(type, "spot")) {
        lf_params_point3(ps, "to", to);
        double cone = lf_params_float(ps, "coneangle", 30.0), delta = lf_params_float(ps, "conedeltaangle", 5.0);
        l->kind = LF_LIGHT_SPOT;
        l->dir = lf_normalize(
            lf_xform_vector(xf, lf_v3((float)(to[0] - from[0]), (float)(to[1] - from[1]), (float)(to[2] - from[2]))));
        l->cos_total = cosf(lf_radians((float)cone));
        l->cos_start = cosf(lf_radians((float)(cone - delta)));
        if (power > 0) {
            double k_e = 2 * LF_PI * (1 - 0.5 * (l->cos_start + l->cos_total)) * lf_luminance(I);
            if (k_e > 0)
                l->L = lf_scale(I, (float)(scale * power / k_e));
        }
    } else {
        l->kind = LF_LIGHT_POINT;
        if (power > 0 && lf_luminance(I) > 0)
            l->L = lf_scale(I, (float)(scale * power / (4 * LF_PI * lf_luminance(I))));
    }
}

/* A distant light ("illuminance", when given, sets the radiance). */
static void read_distant_light(lf_paramset *ps, const lf_transform *xf, double scale, lf_light *l)
{
    lf_vec3 L;
    lf_params_rgb(ps, "L", LF_SPECTRUM_ILLUMINANT, lf_v3(1, 1, 1), &L);
    double from[3] = {0, 0, 0}, to[3] = {0, 0, 1};
    lf_params_point3(ps, "from", from);
    lf_params_point3(ps, "to", to);
    double E = lf_params_float(ps, "illuminance", -1);
    l->kind = LF_LIGHT_DISTANT;
    l->dir = lf_normalize(
        lf_xform_vector(xf, lf_v3((float)(from[0] - to[0]), (float)(from[1] - to[1]), (float)(from[2] - to[2]))));
    l->L = lf_scale(L, (float)scale);
    if (E > 0 && lf_luminance(L) > 0)
        l->L = lf_scale(L, (float)(scale * E / lf_luminance(L)));
}

/* Illuminance of the upper hemisphere (+z in light space) of an
 * environment map at scale 1. */
static double envmap_upper_illuminance(const lf_envmap *env)
{
    double sum = 0;
    int w = env->width;
    for (int y = 0; y < w; y++)
        for (int x = 0; x < w; x++) {
            lf_vec3 d = lf_equal_area_square_to_sphere((x + .5f) / w, (y + .5f) / w);
            if (d.z > 0) {
                const float *p = env->rgb + 3 * ((size_t)y * w + x);
                sum += lf_luminance(lf_v3(p[0], p[1], p[2])) * d.z;
            }
        }
    return sum * 4 * LF_PI / ((double)w * w);
}

/* An infinite light: uniform radiance "L", or an environment map
 * "filename" (relative to the scene file that names it, else to the
 * top-level scene's directory, as pbrt-v4 resolves it). */
static int read_infinite_light(lf_scene *s, lf_light_desc *ld, const char *scene_dir, const lf_transform *xf,
                               double scale, const char *where, lf_light *l, lf_error *err)
{
    lf_paramset *ps = &ld->e.params;
    const char *fn = lf_params_string(ps, "filename", NULL);
    int has_L = lf_params_peek(ps, "L") != NULL;
    lf_vec3 L;
    lf_params_rgb(ps, "L", LF_SPECTRUM_ILLUMINANT, lf_v3(1, 1, 1), &L);
    double E = lf_params_float(ps, "illuminance", -1);
    if (lf_params_find(ps, "portal"))
        lf_warn_at(&s->warnings, &ld->e.loc, "infinite light \"portal\" is ignored (no portal sampling)");
    if (fn && has_L)
        return lf_error_set(err, LF_ERR_PARAM, "%s: infinite light: give either \"L\" or \"filename\", not both",
                            where);
    if (fn) {
        char *path = lf_shading_resolve_path(ld->e.loc.file, scene_dir, fn);
        if (!path)
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        l->env = calloc(1, sizeof *l->env);
        if (!l->env) {
            free(path);
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        }
        lf_error lerr = {0};
        int lrc = lf_envmap_load(path, l->env, &lerr);
        free(path);
        if (lrc) {
            free(l->env);
            l->env = NULL;
            return lf_error_set(err, lerr.code, "%s: infinite light: %s", where, lerr.msg);
        }
        l->env->light_to_world = *xf;
        l->kind = LF_LIGHT_INFINITE_IMAGE;
        l->L = lf_v3((float)scale, (float)scale, (float)scale);
        if (E > 0) {
            double Eimg = envmap_upper_illuminance(l->env);
            if (Eimg > 0)
                l->L = lf_scale(l->L, (float)(E / Eimg));
        }
    } else {
        l->kind = LF_LIGHT_INFINITE_UNIFORM;
        l->L = lf_scale(L, (float)scale);
        if (E > 0 && lf_luminance(L) > 0)
            l->L = lf_scale(L, (float)(scale * E / (LF_PI * lf_luminance(L))));
    }
    return 0;
}

static int light_from_desc(lf_scene *s, const lf_scene_desc *d, lf_light_desc *ld, lf_light *l, int *skip,
                           lf_error *err)
{
    lf_paramset *ps = &ld->e.params;
    char where[512];
    lf_loc_format(where, sizeof where, &ld->e.loc);
    const lf_transform *xf = &ld->light_to_world.xf[0];
    memset(l, 0, sizeof *l);
    l->mesh = l->sphere = -1;
    double scale = lf_params_float(ps, "scale", 1.0);
    *skip = 0;
    const char *type = ld->e.type;
    if (!strcmp(type, "point") || !strcmp(type, "spot")) {
        read_point_light(ps, type, xf, scale, l);
    } else if (!strcmp(type, "distant")) {
        read_distant_light(ps, xf, scale, l);
    } else if (!strcmp(type, "infinite")) {
        int rc = read_infinite_light(s, ld, d->scene_dir, xf, scale, where, l, err);
        if (rc)
            return rc;
    } else {
        if (!d->allow_unsupported)
            return lf_error_set(err, LF_ERR_UNSUPPORTED,
                                "%s: LightSource \"%s\" is not supported (--allow-unsupported renders the scene "
                                "without it)",
                                where, type);
        lf_warn_at(&s->warnings, &ld->e.loc, "LightSource \"%s\" is not supported; it is left out", type);
        for (size_t i = 0; i < ps->count; i++)
            ps->items[i].used = 1;
        *skip = 1;
        return 0;
    }
    char ctx[128];
    snprintf(ctx, sizeof ctx, "LightSource \"%s\"", type);
    if (lf_params_finish(ps, ctx, err))
        return err ? err->code : LF_ERR_PARAM;
    if (!isfinite(lf_maxc(l->L)) || lf_maxc(l->L) < 0)
        return lf_error_set(err, LF_ERR_NUMERIC, "%s: light emission is negative or not finite", where);
    return 0;
}

double lf_light_pmf(const lf_scene *s, lf_light_sampler ls, int light)
{
    if (s->lights[light].kind == LF_LIGHT_INFINITE_UNIFORM)
        return 0.0; /* never sampled by NEE (lf_scene.nee_lights) */
    switch (ls) {
    case LF_LIGHTS_ALL:
        return 1.0;
    case LF_LIGHTS_UNIFORM:
        return 1.0 / s->n_nee_lights;
    default:
        return lf_distrib1d_pmf(&s->light_distrib, light);
    }
}

int lf_scene_build_lights(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    for (size_t i = 0; i < d->n_lights; i++) {
        lf_light l;
        int skip;
        if (light_from_desc(s, d, &d->lights[i], &l, &skip, err))
            return err ? err->code : LF_ERR_PARAM;
        if (skip)
            continue;
        lf_light *n = realloc(s->lights, sizeof *n * (size_t)(s->n_lights + 1));
        if (!n) {
            if (l.env) {
                lf_envmap_free(l.env);
                free(l.env);
            }
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        }
        s->lights = n;
        s->lights[s->n_lights++] = l;
    }
    for (int i = 0; i < s->n_lights; i++)
        if (s->lights[i].kind == LF_LIGHT_INFINITE_UNIFORM || s->lights[i].kind == LF_LIGHT_INFINITE_IMAGE) {
            int *n = realloc(s->infinite_lights, sizeof(int) * (size_t)(s->n_infinite + 1));
            if (!n)
                return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
            s->infinite_lights = n;
            s->infinite_lights[s->n_infinite++] = i;
        }
    return 0;
}
