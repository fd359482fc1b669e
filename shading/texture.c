/* texture.c - pbrt-v4 float and spectrum textures, evaluated at a hit's
 * (u, v) or position.
 *
 * Supported classes (pbrt-v4 parameter names and defaults, textures.cpp):
 * constant, scale, mix, directionmix, bilerp, checkerboard (2D and 3D),
 * dots, imagemap, and the noise textures fbm, wrinkled, windy (float only)
 * and marble (spectrum only), with the uv, spherical, cylindrical and
 * planar mappings.  The noise textures use pbrt's Perlin noise (noise.c)
 * with all their octaves, as pbrt does where a lookup's footprint is zero.
 * There are no ray differentials here, so textures are point-sampled: checkerboard is not
 * box-filtered and image maps are looked up bilinearly in the full-resolution
 * image whatever "filter" says ("point" is honoured).
 */
#include "lf_shading.h"

#include "base/lf_params.h"
#include "image/lf_image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

typedef enum tex_class {
    TEX_CONSTANT,
    TEX_SCALE,
    TEX_MIX,
    TEX_BILERP,
    TEX_CHECKER2D,
    TEX_CHECKER3D,
    TEX_IMAGE,
    TEX_DIRECTIONMIX,
    TEX_DOTS,
    TEX_FBM,
    TEX_WRINKLED,
    TEX_WINDY,
    TEX_MARBLE
} tex_class;

typedef enum map_kind { MAP_UV, MAP_SPHERICAL, MAP_CYLINDRICAL, MAP_PLANAR } map_kind;

typedef struct mapping2d {
    map_kind kind;
    float su, sv, du, dv;     /* uv */
    lf_vec3 v1, v2;           /* planar */
    lf_transform tex_from_world;
} mapping2d;

typedef enum wrap_mode { WRAP_REPEAT, WRAP_BLACK, WRAP_CLAMP } wrap_mode;

struct lf_texture {
    char *name;
    int is_float;
    tex_class cls;
    mapping2d map;
    lf_tex_input a, b, amount;  /* constant: a; scale: a (tex) * b (scale); mix, checkerboard: a, b, amount */
    lf_tex_input v00, v01, v10, v11; /* bilerp */
    lf_image img;                    /* imagemap */
    wrap_mode wrap;
    int point_filter, invert;
    float scale;                     /* imagemap, marble */
    lf_vec3 dir;                     /* directionmix: unit, world space */
    int octaves;                     /* fbm, wrinkled, marble */
    float omega, variation;          /* fbm, wrinkled, marble: "roughness"; marble: "variation" */
};

/* ------------------------------------------------------------- inputs */

static const lf_texture *find_texture(const lf_texture_list *texs, const char *name, int is_float)
{
    for (size_t i = texs ? texs->count : 0; i-- > 0;)
        if (texs->items[i] && texs->items[i]->is_float == is_float && strcmp(texs->items[i]->name, name) == 0)
            return texs->items[i];
    return NULL;
}

int lf_tex_input_read(lf_paramset *ps, const char *name, int is_float, lf_spectrum_kind kind, lf_vec3 def,
                      const lf_texture_list *texs, lf_tex_input *out, lf_error *err)
{
    out->tex = NULL;
    out->value = def;
    const lf_param *pk = lf_params_peek(ps, name);
    if (!pk)
        return LF_OK;
    if (pk->type == LF_PT_TEXTURE) {
        lf_param *p = lf_params_find(ps, name);
        const lf_loc *l = &p->loc;
        if (p->n_strs != 1)
            return lf_error_at(err, LF_ERR_PARAM, l, "texture parameter \"%s\" needs exactly one name", name);
        out->tex = find_texture(texs, p->strs[0], is_float);
        if (!out->tex) {
            const lf_texture *other = find_texture(texs, p->strs[0], !is_float);
            return lf_error_at(err, LF_ERR_PARAM, l, "%s texture \"%s\" (parameter \"%s\") is not defined%s",
                               is_float ? "float" : "spectrum", p->strs[0], name,
                               other ? (is_float ? " (there is a spectrum texture of that name)"
                                                 : " (there is a float texture of that name)")
                                     : "");
        }
        return LF_OK;
    }
    if (is_float) {
        float v = (float)lf_params_float(ps, name, def.x);
        out->value = lf_v3(v, v, v);
    } else {
        lf_params_rgb(ps, name, kind, def, &out->value);
    }
    return LF_OK;
}

float lf_tex_input_float(const lf_tex_input *in, const lf_shading_ctx *ctx)
{
    return in->tex ? lf_texture_float(in->tex, ctx) : in->value.x;
}

lf_vec3 lf_tex_input_rgb(const lf_tex_input *in, const lf_shading_ctx *ctx)
{
    return in->tex ? lf_texture_rgb(in->tex, ctx) : in->value;
}

/* ------------------------------------------------------------- mappings */

static float spherical_theta(lf_vec3 v) { return acosf(lf_clampf(v.z, -1.f, 1.f)); }
static float spherical_phi(lf_vec3 v)
{
    float p = atan2f(v.y, v.x);
    return p < 0.f ? p + 2.f * (float)LF_PI : p;
}

/* pbrt-v4 TextureMapping2D::Map: uv -> (su u + du, sv v + dv); the others
 * from the texture-space position (textures.h). */
static void map2d(const mapping2d *m, const lf_shading_ctx *ctx, float *s, float *t)
{
    switch (m->kind) {
    case MAP_UV:
        *s = m->su * ctx->uv.x + m->du;
        *t = m->sv * ctx->uv.y + m->dv;
        return;
    case MAP_SPHERICAL: {
        lf_vec3 v = lf_normalize(lf_xform_point(&m->tex_from_world, ctx->p));
        *s = spherical_theta(v) * (float)LF_INV_PI;
        *t = spherical_phi(v) * (float)LF_INV_2PI;
        return;
    }
    case MAP_CYLINDRICAL: {
        lf_vec3 p = lf_xform_point(&m->tex_from_world, ctx->p);
        *s = ((float)LF_PI + atan2f(p.y, p.x)) * (float)LF_INV_2PI;
        *t = p.z;
        return;
    }
    case MAP_PLANAR: {
        lf_vec3 p = lf_xform_point(&m->tex_from_world, ctx->p);
        *s = m->du + lf_dot(p, m->v1);
        *t = m->dv + lf_dot(p, m->v2);
        return;
    }
    }
    *s = *t = 0.f;
}

static int read_mapping(lf_texture_desc *td, mapping2d *m, lf_error *err)
{
    lf_paramset *ps = &td->e.params;
    const char *kind = lf_params_string(ps, "mapping", "uv");
    m->tex_from_world = lf_transform_inverse(&td->object_to_world);
    m->su = (float)lf_params_float(ps, "uscale", 1.0);
    m->sv = (float)lf_params_float(ps, "vscale", 1.0);
    m->du = (float)lf_params_float(ps, "udelta", 0.0);
    m->dv = (float)lf_params_float(ps, "vdelta", 0.0);
    if (strcmp(kind, "uv") == 0) {
        m->kind = MAP_UV;
    } else if (strcmp(kind, "spherical") == 0) {
        m->kind = MAP_SPHERICAL;
    } else if (strcmp(kind, "cylindrical") == 0) {
        m->kind = MAP_CYLINDRICAL;
    } else if (strcmp(kind, "planar") == 0) {
        double v[3];
        m->kind = MAP_PLANAR;
        m->v1 = lf_params_vector3(ps, "v1", v) ? lf_v3((float)v[0], (float)v[1], (float)v[2]) : lf_v3(1, 0, 0);
        m->v2 = lf_params_vector3(ps, "v2", v) ? lf_v3((float)v[0], (float)v[1], (float)v[2]) : lf_v3(0, 1, 0);
    } else {
        const lf_param *p = lf_params_peek(ps, "mapping");
        const lf_loc *l = p ? &p->loc : &td->e.loc;
        return lf_error_at(err, LF_ERR_PARAM, l,
                           "texture \"%s\": unknown mapping \"%s\" (uv, spherical, cylindrical, planar)", td->name,
                           kind);
    }
    return LF_OK;
}

/* ------------------------------------------------------------- images */

static const char *path_ext(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

/* 8-bit formats, which lf_image_read has already decoded from sRGB. */
static int is_8bit_format(const char *path)
{
    const char *e = path_ext(path);
    return !strcasecmp(e, "png") || !strcasecmp(e, "jpg") || !strcasecmp(e, "jpeg") || !strcasecmp(e, "tga") ||
           !strcasecmp(e, "bmp") || !strcasecmp(e, "gif");
}

int lf_shading_is_8bit_image(const char *path) { return is_8bit_format(path); }

static char *join_dir(const char *dir, size_t dl, const char *filename)
{
    size_t fl = strlen(filename);
    char *out = malloc(dl + fl + 2);
    if (!out)
        return NULL;
    memcpy(out, dir ? dir : "", dl);
    if (dl && out[dl - 1] != '/')
        out[dl++] = '/';
    memcpy(out + dl, filename, fl + 1);
    return out;
}

char *lf_shading_resolve_path(const char *scene_file, const char *scene_dir, const char *filename)
{
    size_t dl = 0;
    if (filename[0] != '/' && scene_file) {
        const char *slash = strrchr(scene_file, '/');
        if (slash)
            dl = (size_t)(slash - scene_file) + 1;
    }
    char *out = join_dir(scene_file, dl, filename);
    /* Not next to the naming file (a nested materials include naming
     * "textures/x.png"): the top-level scene's directory, where pbrt-v4
     * resolves every relative name.  The first candidate stays when neither
     * exists, so the message names it. */
    if (!out || filename[0] == '/' || !scene_dir || !scene_dir[0] || access(out, F_OK) == 0)
        return out;
    char *alt = join_dir(scene_dir, strlen(scene_dir), filename);
    if (alt && access(alt, F_OK) == 0) {
        free(out);
        return alt;
    }
    free(alt);
    return out;
}

static int read_imagemap(lf_texture_desc *td, const char *scene_dir, lf_texture *t, lf_warnings *warnings,
                         lf_error *err)
{
    lf_paramset *ps = &td->e.params;
    const lf_loc *l = &td->e.loc;
    const char *filename = lf_params_string(ps, "filename", NULL);
    if (!filename || !*filename)
        return lf_error_at(err, LF_ERR_PARAM, l, "imagemap texture \"%s\": \"filename\" must be given", td->name);
    const char *filter = lf_params_string(ps, "filter", "bilinear");
    if (strcmp(filter, "point") && strcmp(filter, "bilinear") && strcmp(filter, "trilinear") && strcmp(filter, "ewa") &&
        strcmp(filter, "EWA"))
        return lf_error_at(err, LF_ERR_PARAM, l, "imagemap texture \"%s\": unknown filter \"%s\"", td->name, filter);
    t->point_filter = strcmp(filter, "point") == 0;
    (void)lf_params_float(ps, "maxanisotropy", 8.0); /* EWA only; no differentials here */
    const char *wrap = lf_params_string(ps, "wrap", "repeat");
    if (!strcmp(wrap, "repeat"))
        t->wrap = WRAP_REPEAT;
    else if (!strcmp(wrap, "black"))
        t->wrap = WRAP_BLACK;
    else if (!strcmp(wrap, "clamp"))
        t->wrap = WRAP_CLAMP;
    else
        return lf_error_at(err, LF_ERR_UNSUPPORTED, l,
                           "imagemap texture \"%s\": wrap mode \"%s\" not supported (repeat, black, clamp)", td->name,
                           wrap);
    t->scale = (float)lf_params_float(ps, "scale", 1.0);
    t->invert = lf_params_bool(ps, "invert", 0);

    char *path = lf_shading_resolve_path(l->file, scene_dir, filename);
    if (!path)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    /* pbrt-v4's default encoding: sRGB for 8-bit files, linear otherwise;
     * floating-point images ignore it. */
    int eight_bit = is_8bit_format(path);
    const char *enc = lf_params_string(ps, "encoding", eight_bit ? "sRGB" : "linear");
    float gamma = 0.f; /* 0: sRGB, 1: linear, else gamma */
    if (!strcmp(enc, "sRGB"))
        gamma = 0.f;
    else if (!strcmp(enc, "linear"))
        gamma = 1.f;
    else if (!strncmp(enc, "gamma ", 6) && atof(enc + 6) > 0.0)
        gamma = (float)atof(enc + 6);
    else {
        free(path);
        return lf_error_at(err, LF_ERR_PARAM, l,
                           "imagemap texture \"%s\": unknown encoding \"%s\" (sRGB, linear, \"gamma x\")", td->name,
                           enc);
    }
    lf_error ierr = {0};
    if (lf_image_read(path, &t->img, NULL, &ierr)) {
        int code = ierr.code ? ierr.code : LF_ERR_IO;
        lf_error_at(err, code, l, "imagemap texture \"%s\": %s", td->name, ierr.msg);
        free(path);
        return code;
    }
    if (eight_bit && gamma != 0.f) {
        /* lf_image_read linearised the 8-bit codes with the sRGB curve;
         * recover the codes (exact for 8-bit data) and apply the encoding
         * the scene asked for.  Alpha (channel 3) is left alone. */
        size_t n = (size_t)t->img.width * (size_t)t->img.height;
        int nc = t->img.channels;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < nc && c < 3; c++) {
                float *v = &t->img.data[i * (size_t)nc + (size_t)c];
                float code = (float)lf_srgb_encode(*v) / 255.f;
                *v = gamma == 1.f ? code : powf(code, gamma);
            }
    } else if (!eight_bit && strcmp(enc, "linear") != 0 && lf_params_peek(ps, "encoding")) {
        lf_warn_at(warnings, &lf_params_peek(ps, "encoding")->loc,
                   "imagemap \"%s\": \"encoding\" ignored for a floating-point image", filename);
    }
    free(path);
    if (t->img.channels < 1) {
        return lf_error_at(err, LF_ERR_PARAM, l, "imagemap texture \"%s\": image has no channels", td->name);
    }
    return LF_OK;
}

static int wrap_coord(int i, int n, wrap_mode w, int *out)
{
    if (i >= 0 && i < n) {
        *out = i;
        return 1;
    }
    switch (w) {
    case WRAP_REPEAT:
        *out = ((i % n) + n) % n;
        return 1;
    case WRAP_CLAMP:
        *out = i < 0 ? 0 : n - 1;
        return 1;
    case WRAP_BLACK:
        break;
    }
    return 0;
}

/* Texel (x, y) as RGB: grey images replicate channel 0. */
static lf_vec3 texel(const lf_texture *t, int x, int y)
{
    int xi, yi;
    if (!wrap_coord(x, t->img.width, t->wrap, &xi) || !wrap_coord(y, t->img.height, t->wrap, &yi))
        return lf_v3(0, 0, 0);
    const float *p = lf_image_px(&t->img, xi, yi);
    if (t->img.channels >= 3)
        return lf_v3(p[0], p[1], p[2]);
    return lf_v3(p[0], p[0], p[0]);
}

/* pbrt-v4 Image::Bilerp: texel centres at (i + 0.5) / res; image row 0 is
 * the top, so the caller flips t. */
static lf_vec3 image_lookup(const lf_texture *t, float s, float tt)
{
    float x = s * (float)t->img.width - 0.5f, y = tt * (float)t->img.height - 0.5f;
    if (!isfinite(x) || !isfinite(y) || fabsf(x) > 1e9f || fabsf(y) > 1e9f)
        return lf_v3(0, 0, 0);
    if (t->point_filter)
        return texel(t, (int)floorf(x + 0.5f), (int)floorf(y + 0.5f));
    float fx = floorf(x), fy = floorf(y);
    int xi = (int)fx, yi = (int)fy;
    float dx = x - fx, dy = y - fy;
    lf_vec3 a = texel(t, xi, yi), b = texel(t, xi + 1, yi), c = texel(t, xi, yi + 1), d = texel(t, xi + 1, yi + 1);
    return lf_add(lf_add(lf_scale(a, (1 - dx) * (1 - dy)), lf_scale(b, dx * (1 - dy))),
                  lf_add(lf_scale(c, (1 - dx) * dy), lf_scale(d, dx * dy)));
}

/* ------------------------------------------------------------- evaluation */

/* Checkerboard weight of tex2 in [0, 1] (pbrt-v4 Checkerboard() with zero
 * filter width: 0 on even cells, 1 on odd ones). */
static float checker_weight(const lf_texture *t, const lf_shading_ctx *ctx)
{
    long sum;
    if (t->cls == TEX_CHECKER2D) {
        float s, tt;
        map2d(&t->map, ctx, &s, &tt);
        sum = (long)floorf(s) + (long)floorf(tt);
    } else {
        lf_vec3 p = lf_xform_point(&t->map.tex_from_world, ctx->p);
        sum = (long)floorf(p.x) + (long)floorf(p.y) + (long)floorf(p.z);
    }
    return (sum & 1) ? 1.f : 0.f;
}

/* pbrt-v4 InsidePolkaDot: one dot of radius 0.35 in the cells noise
 * switches on, its centre jittered by noise within the cell. */
static int inside_polka_dot(float s, float t)
{
    float sc = floorf(s + .5f), tc = floorf(t + .5f);
    if (!(lf_noise3(lf_v3(sc + .5f, tc + .5f, 0.5f)) > 0.f))
        return 0;
    const float radius = .35f, max_shift = 0.5f - radius;
    float s0 = sc + max_shift * lf_noise3(lf_v3(sc + 1.5f, tc + 2.8f, 0.5f));
    float t0 = tc + max_shift * lf_noise3(lf_v3(sc + 4.5f, tc + 9.8f, 0.5f));
    return (s - s0) * (s - s0) + (t - t0) * (t - t0) < radius * radius;
}

/* pbrt-v4 MarbleTexture: t = 0.5 + 0.5 sin(y + variation fbm(p)) picks a
 * point on a cubic Bezier spline through nine rock colours, times 1.5. */
static lf_vec3 marble(const lf_texture *t, lf_vec3 p)
{
    static const float colors[9][3] = {{.58f, .58f, .6f}, {.58f, .58f, .6f}, {.58f, .58f, .6f},
                                       {.5f, .5f, .5f},   {.6f, .59f, .58f}, {.58f, .58f, .6f},
                                       {.58f, .58f, .6f}, {.2f, .2f, .33f},  {.58f, .58f, .6f}};
    p = lf_scale(p, t->scale);
    float m = p.y + t->variation * lf_fbm(p, t->omega, t->octaves);
    float u = .5f + .5f * sinf(m);
    const int nseg = 9 - 3;
    int first = (int)floorf(u * (float)nseg);
    first = first < 0 ? 0 : first > nseg - 1 ? nseg - 1 : first;
    u = u * (float)nseg - (float)first;
    float out[3];
    for (int c = 0; c < 3; c++) { /* de Casteljau on the four control points */
        float a = lf_lerpf(u, colors[first][c], colors[first + 1][c]);
        float b = lf_lerpf(u, colors[first + 1][c], colors[first + 2][c]);
        float d = lf_lerpf(u, colors[first + 2][c], colors[first + 3][c]);
        out[c] = 1.5f * lf_lerpf(u, lf_lerpf(u, a, b), lf_lerpf(u, b, d));
    }
    return lf_v3(out[0], out[1], out[2]);
}

/* The noise-based and direction classes (pbrt-v4 textures.h). */
static lf_vec3 eval_procedural(const lf_texture *t, const lf_shading_ctx *ctx)
{
    lf_vec3 p = lf_xform_point(&t->map.tex_from_world, ctx->p);
    float v = 0.f;
    switch (t->cls) {
    case TEX_DIRECTIONMIX: {
        /* amount = |n . dir| with the geometric normal (pbrt's ctx.n). */
        float amt = lf_absdot(ctx->ng, t->dir);
        lf_vec3 r = lf_v3(0, 0, 0);
        if (amt != 0.f)
            r = lf_scale(lf_tex_input_rgb(&t->a, ctx), amt);
        if (amt != 1.f)
            r = lf_add(r, lf_scale(lf_tex_input_rgb(&t->b, ctx), 1.f - amt));
        return r;
    }
    case TEX_DOTS: {
        float s, tt;
        map2d(&t->map, ctx, &s, &tt);
        return inside_polka_dot(s, tt) ? lf_tex_input_rgb(&t->a, ctx) : lf_tex_input_rgb(&t->b, ctx);
    }
    case TEX_FBM:
        v = lf_fbm(p, t->omega, t->octaves);
        break;
    case TEX_WRINKLED:
        v = lf_turbulence(p, t->omega, t->octaves);
        break;
    case TEX_WINDY:
        v = fabsf(lf_fbm(lf_scale(p, .1f), .5f, 3)) * lf_fbm(p, .5f, 6);
        break;
    case TEX_MARBLE:
        return marble(t, p);
    default:
        break;
    }
    return lf_v3(v, v, v);
}

static lf_vec3 eval(const lf_texture *t, const lf_shading_ctx *ctx)
{
    switch (t->cls) {
    case TEX_DIRECTIONMIX:
    case TEX_DOTS:
    case TEX_FBM:
    case TEX_WRINKLED:
    case TEX_WINDY:
    case TEX_MARBLE:
        return eval_procedural(t, ctx);
    case TEX_CONSTANT:
        return t->a.value;
    case TEX_SCALE: {
        /* pbrt-v4 ScaleTexture: tex * scale, scale a float input. */
        float sc = lf_tex_input_float(&t->b, ctx);
        if (sc == 0.f)
            return lf_v3(0, 0, 0);
        return lf_scale(lf_tex_input_rgb(&t->a, ctx), sc);
    }
    case TEX_MIX: {
        float amt = lf_tex_input_float(&t->amount, ctx);
        lf_vec3 r = lf_v3(0, 0, 0);
        if (amt != 1.f)
            r = lf_scale(lf_tex_input_rgb(&t->a, ctx), 1.f - amt);
        if (amt != 0.f)
            r = lf_add(r, lf_scale(lf_tex_input_rgb(&t->b, ctx), amt));
        return r;
    }
    case TEX_BILERP: {
        float s, tt;
        map2d(&t->map, ctx, &s, &tt);
        /* pbrt-v4 BilerpTexture: (1-s)(1-t) v00 + (1-s) t v01 + s (1-t) v10 + s t v11 */
        return lf_add(lf_add(lf_scale(lf_tex_input_rgb(&t->v00, ctx), (1 - s) * (1 - tt)),
                             lf_scale(lf_tex_input_rgb(&t->v01, ctx), (1 - s) * tt)),
                      lf_add(lf_scale(lf_tex_input_rgb(&t->v10, ctx), s * (1 - tt)),
                             lf_scale(lf_tex_input_rgb(&t->v11, ctx), s * tt)));
    }
    case TEX_CHECKER2D:
    case TEX_CHECKER3D:
        return checker_weight(t, ctx) == 0.f ? lf_tex_input_rgb(&t->a, ctx) : lf_tex_input_rgb(&t->b, ctx);
    case TEX_IMAGE: {
        float s, tt;
        map2d(&t->map, ctx, &s, &tt);
        lf_vec3 v = lf_scale(image_lookup(t, s, 1.f - tt), t->scale);
        if (t->invert)
            v = lf_v3(fmaxf(0.f, 1.f - v.x), fmaxf(0.f, 1.f - v.y), fmaxf(0.f, 1.f - v.z));
        return v;
    }
    }
    return lf_v3(0, 0, 0);
}

float lf_texture_float(const lf_texture *t, const lf_shading_ctx *ctx)
{
    /* A float image texture reads channel 0 (pbrt-v4 MIPMap::Texel<Float>). */
    return eval(t, ctx).x;
}

lf_vec3 lf_texture_rgb(const lf_texture *t, const lf_shading_ctx *ctx)
{
    lf_vec3 v = eval(t, ctx);
    if (t->is_float)
        return lf_v3(v.x, v.x, v.x);
    return v;
}

const char *lf_texture_name(const lf_texture *t) { return t->name; }
int lf_texture_is_float(const lf_texture *t) { return t->is_float; }

/* ------------------------------------------------------------- building */

void lf_texture_free(lf_texture *t)
{
    if (!t)
        return;
    free(t->name);
    lf_image_free(&t->img);
    free(t);
}

static int input(lf_texture_desc *td, const lf_texture_list *texs, const char *name, float def_f, lf_tex_input *out,
                 lf_error *err)
{
    return lf_tex_input_read(&td->e.params, name, td->is_float, LF_SPECTRUM_UNBOUNDED,
                             lf_v3(def_f, def_f, def_f), texs, out, err);
}

static int float_input(lf_texture_desc *td, const lf_texture_list *texs, const char *name, float def,
                       lf_tex_input *out, lf_error *err)
{
    return lf_tex_input_read(&td->e.params, name, 1, LF_SPECTRUM_UNBOUNDED, lf_v3(def, def, def), texs, out, err);
}

/* The classes of eval_procedural.  Returns 1 (with *rc set) when cls is
 * one of them, 0 otherwise.  pbrt-v4 has fbm, wrinkled and windy only as
 * float textures and marble only as a spectrum one. */
static int read_procedural(lf_texture_desc *td, const lf_texture_list *texs, lf_texture *t, const char *cls,
                           int *rc, lf_error *err)
{
    lf_paramset *ps = &td->e.params;
    static const struct {
        const char *name;
        tex_class cls;
        int kinds; /* 1: float, 2: spectrum */
    } table[] = {{"directionmix", TEX_DIRECTIONMIX, 3}, {"dots", TEX_DOTS, 3},     {"fbm", TEX_FBM, 1},
                 {"wrinkled", TEX_WRINKLED, 1},        {"windy", TEX_WINDY, 1},   {"marble", TEX_MARBLE, 2}};
    size_t i = 0, n = sizeof table / sizeof table[0];
    while (i < n && strcmp(table[i].name, cls) != 0)
        i++;
    if (i == n)
        return 0;
    if (!(table[i].kinds & (td->is_float ? 1 : 2))) {
        *rc = lf_error_at(err, LF_ERR_PARAM, &td->e.loc, "texture \"%s\": pbrt-v4 has no %s \"%s\" texture (only %s)",
                          td->name, td->is_float ? "float" : "spectrum", cls, td->is_float ? "spectrum" : "float");
        return 1;
    }
    t->cls = table[i].cls;
    t->octaves = 8;
    t->omega = .5f;
    *rc = LF_OK;
    /* Only fbm, wrinkled and marble read octaves and roughness (elsewhere
     * pbrt leaves them unused, hence an error). */
    if (t->cls == TEX_FBM || t->cls == TEX_WRINKLED || t->cls == TEX_MARBLE) {
        t->octaves = lf_params_int(ps, "octaves", 8);
        t->omega = (float)lf_params_float(ps, "roughness", 0.5);
        if (t->octaves < 0 || t->octaves > 30) {
            const lf_param *p = lf_params_peek(ps, "octaves");
            *rc = lf_error_at(err, LF_ERR_PARAM, p ? &p->loc : &td->e.loc,
                              "texture \"%s\": \"octaves\" %d outside [0, 30]", td->name, t->octaves);
            return 1;
        }
    }
    switch (t->cls) {
    case TEX_DIRECTIONMIX: {
        double v[3];
        lf_vec3 d = lf_params_vector3(ps, "dir", v) ? lf_v3((float)v[0], (float)v[1], (float)v[2]) : lf_v3(0, 1, 0);
        d = lf_xform_vector(&td->object_to_world, d);
        if (!(lf_length(d) > 0.f))
            return (*rc = lf_error_at(err, LF_ERR_PARAM, &td->e.loc, "texture \"%s\": \"dir\" is zero", td->name)), 1;
        t->dir = lf_normalize(d);
        *rc = input(td, texs, "tex1", 0.f, &t->a, err);
        if (!*rc)
            *rc = input(td, texs, "tex2", 1.f, &t->b, err);
        break;
    }
    case TEX_DOTS:
        *rc = read_mapping(td, &t->map, err);
        if (!*rc)
            *rc = input(td, texs, "inside", 1.f, &t->a, err);
        if (!*rc)
            *rc = input(td, texs, "outside", 0.f, &t->b, err);
        break;
    case TEX_MARBLE:
        t->scale = (float)lf_params_float(ps, "scale", 1.0);
        t->variation = (float)lf_params_float(ps, "variation", 0.2);
        break;
    default:
        break;
    }
    return 1;
}

int lf_texture_new(lf_texture_desc *td, const lf_texture_list *texs, lf_warnings *warnings, lf_texture **out,
                   lf_error *err)
{
    *out = NULL;
    const lf_loc *l = &td->e.loc;
    const char *cls = td->e.type ? td->e.type : "";
    lf_texture *t = calloc(1, sizeof *t);
    if (!t)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    t->name = strdup(td->name ? td->name : "");
    t->is_float = td->is_float;
    t->map.tex_from_world = lf_transform_inverse(&td->object_to_world);
    int rc = t->name ? LF_OK : lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    if (rc || read_procedural(td, texs, t, cls, &rc, err)) {
    } else if (!strcmp(cls, "constant")) {
        t->cls = TEX_CONSTANT;
        rc = input(td, NULL, "value", 1.f, &t->a, err);
    } else if (!strcmp(cls, "scale")) {
        t->cls = TEX_SCALE;
        rc = input(td, texs, "tex", 1.f, &t->a, err);
        if (!rc)
            rc = float_input(td, texs, "scale", 1.f, &t->b, err);
    } else if (!strcmp(cls, "mix")) {
        t->cls = TEX_MIX;
        rc = input(td, texs, "tex1", 0.f, &t->a, err);
        if (!rc)
            rc = input(td, texs, "tex2", 1.f, &t->b, err);
        if (!rc)
            rc = float_input(td, texs, "amount", 0.5f, &t->amount, err);
    } else if (!strcmp(cls, "bilerp")) {
        t->cls = TEX_BILERP;
        rc = read_mapping(td, &t->map, err);
        if (!rc)
            rc = input(td, texs, "v00", 0.f, &t->v00, err);
        if (!rc)
            rc = input(td, texs, "v01", 1.f, &t->v01, err);
        if (!rc)
            rc = input(td, texs, "v10", 0.f, &t->v10, err);
        if (!rc)
            rc = input(td, texs, "v11", 1.f, &t->v11, err);
    } else if (!strcmp(cls, "checkerboard")) {
        int dim = lf_params_int(&td->e.params, "dimension", 2);
        if (dim != 2 && dim != 3) {
            const lf_param *p = lf_params_peek(&td->e.params, "dimension");
            const lf_loc *pl = p ? &p->loc : l;
            rc = lf_error_at(err, LF_ERR_PARAM, pl, "checkerboard texture \"%s\": dimension %d (must be 2 or 3)",
                             td->name, dim);
        } else {
            t->cls = dim == 2 ? TEX_CHECKER2D : TEX_CHECKER3D;
            if (dim == 2)
                rc = read_mapping(td, &t->map, err);
            if (!rc)
                rc = input(td, texs, "tex1", 1.f, &t->a, err);
            if (!rc)
                rc = input(td, texs, "tex2", 0.f, &t->b, err);
        }
    } else if (!strcmp(cls, "imagemap")) {
        t->cls = TEX_IMAGE;
        rc = read_mapping(td, &t->map, err);
        if (!rc)
            rc = read_imagemap(td, texs ? texs->scene_dir : NULL, t, warnings, err);
    } else {
        rc = lf_error_at(err, LF_ERR_UNSUPPORTED, l,
                         "texture \"%s\": %s texture class \"%s\" not supported (constant, scale, mix, "
                         "directionmix, bilerp, checkerboard, dots, fbm, wrinkled, windy, marble, imagemap)",
                         td->name, td->is_float ? "float" : "spectrum", cls);
    }
    if (!rc) {
        char ctx[256];
        snprintf(ctx, sizeof ctx, "Texture \"%s\" \"%s\"", td->name ? td->name : "", cls);
        rc = lf_params_finish(&td->e.params, ctx, err);
    }
    if (rc) {
        lf_texture_free(t);
        return rc;
    }
    *out = t;
    return LF_OK;
}
