/* normalmap.c - pbrt-v4 "string normalmap": tangent-space normal maps.
 *
 * As pbrt-v4 (materials.h NormalMap, scene.cpp): the image is read once per
 * file with a linear encoding (8-bit codes / 255, no sRGB curve), its first
 * three channels are the tangent-space normal as 2 rgb - 1, looked up
 * bilinearly at (u, 1 - v) with repeat wrapping; the tangent frame is
 * x = dp/du (orthogonalised), z = the shading normal, y = z x x.
 */
#include "lf_shading.h"

#include "image/lf_image.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct nmap_entry {
    char *path;
    lf_image img;
} nmap_entry;

struct lf_normal_maps {
    nmap_entry **items; /* separately allocated: materials keep pointers to their images */
    size_t count;
};

void lf_normal_maps_free(lf_normal_maps *c)
{
    if (!c)
        return;
    for (size_t i = 0; i < c->count; i++) {
        free(c->items[i]->path);
        lf_image_free(&c->items[i]->img);
        free(c->items[i]);
    }
    free(c->items);
    free(c);
}

/* Undoes lf_image_read's sRGB decoding of 8-bit formats: pbrt-v4 reads
 * normal maps with ColorEncoding::Linear.  The continuous inverse of the
 * sRGB curve, so 16-bit PNGs keep their precision. */
static void undo_srgb(lf_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    int nc = img->channels;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < nc && c < 3; c++) {
            float *v = &img->data[i * (size_t)nc + (size_t)c];
            double x = *v > 0.f ? (*v < 1.f ? *v : 1.0) : 0.0;
            *v = (float)(x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055);
        }
}

int lf_normal_map_get(lf_normal_maps **cache, const char *path, const lf_image **out, lf_error *err)
{
    *out = NULL;
    if (!*cache) {
        *cache = calloc(1, sizeof **cache);
        if (!*cache)
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    lf_normal_maps *c = *cache;
    for (size_t i = 0; i < c->count; i++)
        if (strcmp(c->items[i]->path, path) == 0) {
            *out = &c->items[i]->img;
            return LF_OK;
        }
    nmap_entry *e = calloc(1, sizeof *e);
    nmap_entry **grown = realloc(c->items, (c->count + 1) * sizeof *grown);
    if (grown)
        c->items = grown;
    if (!e || !grown || !(e->path = strdup(path))) {
        free(e);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    int rc = lf_image_read(path, &e->img, NULL, err);
    if (!rc && (e->img.channels < 3 || e->img.width < 1 || e->img.height < 1)) {
        rc = lf_error_set(err, LF_ERR_PARAM, "%s: normal map image must contain R, G, and B channels", path);
        lf_image_free(&e->img);
    }
    if (rc) {
        free(e->path);
        free(e);
        return rc;
    }
    if (lf_shading_is_8bit_image(path))
        undo_srgb(&e->img);
    c->items[c->count++] = e;
    *out = &e->img;
    return LF_OK;
}

static lf_vec3 texel_repeat(const lf_image *m, int x, int y)
{
    x = ((x % m->width) + m->width) % m->width;
    y = ((y % m->height) + m->height) % m->height;
    const float *p = lf_image_px(m, x, y);
    return lf_v3(p[0], p[1], p[2]);
}

/* pbrt-v4 Image::Bilerp with WrapMode::Repeat; row 0 is the image's top. */
static lf_vec3 bilerp_repeat(const lf_image *m, float s, float t)
{
    float x = s * (float)m->width - 0.5f, y = t * (float)m->height - 0.5f;
    if (!isfinite(x) || !isfinite(y) || fabsf(x) > 1e9f || fabsf(y) > 1e9f)
        return lf_v3(0.5f, 0.5f, 1.f); /* the unperturbed normal */
    float fx = floorf(x), fy = floorf(y), dx = x - fx, dy = y - fy;
    int xi = (int)fx, yi = (int)fy;
    lf_vec3 a = texel_repeat(m, xi, yi), b = texel_repeat(m, xi + 1, yi);
    lf_vec3 c = texel_repeat(m, xi, yi + 1), d = texel_repeat(m, xi + 1, yi + 1);
    return lf_add(lf_add(lf_scale(a, (1 - dx) * (1 - dy)), lf_scale(b, dx * (1 - dy))),
                  lf_add(lf_scale(c, (1 - dx) * dy), lf_scale(d, dx * dy)));
}

void lf_normal_map_shading(const lf_image *map, const lf_shading_ctx *ctx, lf_shading_ctx *out)
{
    *out = *ctx;
    lf_vec3 rgb = bilerp_repeat(map, ctx->uv.x, 1.f - ctx->uv.y);
    lf_vec3 nt = lf_sub(lf_scale(rgb, 2.f), lf_v3(1, 1, 1));
    float l2 = lf_dot(nt, nt);
    if (!(l2 > 0) || !isfinite(l2))
        return;
    nt = lf_scale(nt, 1.f / sqrtf(l2));
    /* Tangent frame.  pbrt's shading dp/du is already orthogonal to the
     * shading normal; lensfield's ctx->dpdu is the geometric one, so
     * Gram-Schmidt it (the same direction pbrt's triangles compute). */
    lf_vec3 z = ctx->ns;
    lf_vec3 u = ctx->has_derivs ? ctx->sdpdu : ctx->dpdu;
    lf_vec3 x = lf_sub(u, lf_scale(z, lf_dot(z, u)));
    float xl = lf_dot(x, x);
    if (!(xl > 1e-20f) || !isfinite(xl)) {
        lf_vec3 t;
        lf_basis(z, &x, &t);
    } else {
        x = lf_scale(x, 1.f / sqrtf(xl));
    }
    lf_vec3 y = lf_cross(z, x);
    lf_vec3 n = lf_add(lf_add(lf_scale(x, nt.x), lf_scale(y, nt.y)), lf_scale(z, nt.z));
    n = lf_normalize(n);
    /* pbrt recomputes dp/du by Gram-Schmidt against n and dp/dv = n x dp/du,
     * so normalize(dp/du x dp/dv) is n itself, then faces it to ng's side. */
    lf_vec3 du = lf_sub(x, lf_scale(n, lf_dot(n, x)));
    float dl = lf_dot(du, du);
    if (!(dl > 1e-20f) || !isfinite(dl))
        return; /* the map's normal lies along dp/du: no tangent plane left */
    du = lf_scale(du, 1.f / sqrtf(dl));
    if (ctx->has_derivs) {
        out->sdpdu = lf_scale(du, lf_length(ctx->sdpdu));
        out->sdpdv = lf_scale(lf_cross(n, du), lf_length(ctx->sdpdv));
    }
    if (lf_dot(n, ctx->ng) < 0)
        n = lf_neg(n);
    out->ns = n;
    out->dpdu = du;
}
