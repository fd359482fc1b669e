/* lf_shading.h - surface shading: BSDFs, materials and textures (pbrt-v4 names).
 *
 * A scene description's Texture, Material and MakeNamedMaterial directives are
 * built once into an lf_materials; at a ray hit the integrator asks a
 * material for a BSDF and evaluates or samples it:
 *
 *   lf_materials *mats;
 *   if (lf_materials_build(&desc, &mats, &err)) ... err.msg ...
 *   const lf_material *m = lf_materials_get(mats, shape->material); // -1: default
 *   if (lf_material_is_interface(m)) continue the ray;
 *   m = lf_material_resolve(m, &ctx, u_mix);   // picks a "mix" component
 *   lf_bsdf b; lf_material_bsdf(m, &ctx, &b);
 *   struct lf_bsdf_sample s;
 *   if (lf_bsdf_sample(&b, wo, uc, u0, u1, &s)) beta *= s.f * |cos(wi, ns)| / s.pdf;
 *   ...
 *   lf_materials_free(mats);
 *
 * Conventions (as pbrt-v4's BSDF): directions are world space unit vectors
 * pointing away from the surface; f excludes the cosine factor; pdfs are per
 * unit solid angle; BSDFs are built for radiance transport (pbrt's
 * TransportMode::Radiance: refraction scales by 1/eta^2).  Colours are linear
 * RGB; there is no spectral rendering, so dispersive glasses use their index
 * at 550 nm.
 *
 * Everything here is thread-safe after lf_materials_build: BSDFs are fixed
 * size values on the caller's stack, materials and textures are read only.
 */
#ifndef LF_SHADING_H
#define LF_SHADING_H

#include "base/lf_error.h"
#include "base/lf_math.h"
#include "scenefile/lf_scene_desc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The local geometry at a hit, world space.  ng and ns are unit, ns on the
 * same side as ng; dpdu orients anisotropic roughness (may be zero). */
typedef struct lf_shading_ctx {
    lf_vec3 p, ng, ns, dpdu;
    lf_vec2 uv;
    /* For bump mapping only (has_derivs set by the renderer for surfaces
     * whose material has a "displacement", lf_material_bumps): pbrt-v4's
     * shading.dpdu and shading.dpdv (not normalised; with shading normals
     * the tangents re-orthogonalised around ns as pbrt's triangles do) and
     * the normal's derivatives dndu, dndv. */
    lf_vec3 sdpdu, sdpdv, dndu, dndv;
    int has_derivs;
} lf_shading_ctx;

/* ------------------------------------------------------------------ BSDF */

/* Trowbridge-Reitz (GGX) roughness along the frame's s and t axes.  Below
 * LF_SMOOTH_ALPHA in both, a surface is a perfect specular one (pbrt-v4's
 * TrowbridgeReitzDistribution::EffectivelySmooth). */
#define LF_SMOOTH_ALPHA 1e-3f
typedef struct lf_microfacet {
    float alpha_x, alpha_y;
} lf_microfacet;

/* pbrt-v4 RoughnessToAlpha: alpha = sqrt(roughness). */
float lf_roughness_to_alpha(float roughness);

/* Directional albedo of a GGX dielectric coat's reflection, tabulated over
 * alpha in [0, 1] and cos(theta) in [0, 1] for one index of refraction; the
 * coated BSDFs use it to know how much light enters the coat (see bsdf.c). */
#define LF_COAT_N_ALPHA 17
#define LF_COAT_N_COS 33
typedef struct lf_coat_table {
    float eta;
    float albedo[LF_COAT_N_ALPHA][LF_COAT_N_COS];
    float hemispherical[LF_COAT_N_ALPHA]; /* 2 * integral of albedo(mu) mu dmu */
} lf_coat_table;
void lf_coat_table_init(lf_coat_table *t, float eta);

typedef enum lf_lobe_kind {
    LF_LOBE_NONE,                  /* no scattering (interface material) */
    LF_LOBE_DIFFUSE,               /* Lambertian reflection */
    LF_LOBE_DIFFUSE_TRANSMISSION,  /* Lambertian reflection + transmission */
    LF_LOBE_CONDUCTOR,             /* Fresnel conductor, smooth or GGX */
    LF_LOBE_DIELECTRIC,            /* Fresnel dielectric, smooth or GGX (Walter 2007) */
    LF_LOBE_THIN_DIELECTRIC,       /* thin slab: specular reflection + straight transmission */
    LF_LOBE_COATED_DIFFUSE,        /* dielectric coat over a Lambertian base */
    LF_LOBE_COATED_CONDUCTOR,      /* dielectric coat over a conductor */
    LF_LOBE_MEASURED,              /* RGL measured BRDF (measured.c) */
    LF_LOBE_HAIR,                  /* Chiang et al. 2016 hair fibre (hair.c) */
    LF_LOBE_NORMALIZED_FRESNEL     /* a subsurface walk's exit (pbrt-v4 NormalizedFresnelBxDF) */
} lf_lobe_kind;

typedef struct lf_measured lf_measured; /* a loaded RGL .bsdf file (measured.c) */

/* pbrt-v4's HairBxDF at one hit, precomputed (hair.c, lf_hair_setup). */
typedef struct lf_hair {
    float h, eta, gamma_o, s;
    lf_vec3 sigma_a;
    float v[4];                          /* longitudinal variances, p = 0, 1, 2, 3+ */
    float sin2k_alpha[3], cos2k_alpha[3]; /* scale tilt for p = 0, 1, 2 */
} lf_hair;

/* A BSDF: a shading frame and one tagged lobe set (the coated ones hold a
 * coat lobe plus a base lobe).  Fixed size, no allocation; the coated kinds
 * point at a table owned by their material (or by the caller). */
typedef struct lf_bsdf {
    lf_vec3 s, t, n; /* shading frame: n = ns, s along dpdu projected */
    lf_lobe_kind kind;
    union {
        struct { lf_vec3 r; } diffuse;
        struct { lf_vec3 r, t; } diffuse_transmission;
        struct { lf_vec3 eta, k; lf_microfacet mf; } conductor;
        struct { float eta; lf_microfacet mf; } dielectric;
        struct { float eta; } thin;
        struct {
            float eta;                   /* coat index */
            lf_microfacet coat;
            const lf_coat_table *table;  /* for eta */
            lf_vec3 r;                   /* diffuse base reflectance */
            lf_vec3 eta_b, k_b;          /* conductor base, relative to the coat */
            lf_microfacet base;
            float thickness;             /* layer depth for exp(-thickness / cos) attenuation; 0 by default */
        } coated;
        struct { const lf_measured *data; } measured;
        lf_hair hair; /* frame: s along the fibre (dpdu), n = ns */
        struct { float eta, c; } nfresnel; /* c: 2 int (1 - Fr(mu)) mu dmu */
    } u;
} lf_bsdf;

/* The sample is `struct lf_bsdf_sample` (no typedef): in C a typedef and the
 * function lf_bsdf_sample() cannot share the name, the struct tag can. */
struct lf_bsdf_sample {
    lf_vec3 wi;
    lf_vec3 f;        /* BSDF value, no cosine */
    float pdf;        /* solid angle; for a specular sample, the discrete probability */
    int specular;     /* wi came from a delta lobe */
    int transmission; /* wi is on the other side of the surface than wo */
    float eta;        /* relative index crossed (transmission through dielectrics), else 1 */
};

/* Constructors, for tests and for callers that build BSDFs directly.
 * lf_bsdf_frame sets the frame from ctx (ns, dpdu) and kind NONE. */
void lf_bsdf_frame(lf_bsdf *b, const lf_shading_ctx *ctx);
void lf_bsdf_set_diffuse(lf_bsdf *b, lf_vec3 r);
void lf_bsdf_set_diffuse_transmission(lf_bsdf *b, lf_vec3 r, lf_vec3 t);
void lf_bsdf_set_conductor(lf_bsdf *b, lf_vec3 eta, lf_vec3 k, lf_microfacet mf);
void lf_bsdf_set_dielectric(lf_bsdf *b, float eta, lf_microfacet mf);
void lf_bsdf_set_thin_dielectric(lf_bsdf *b, float eta);
/* table must be built for eta and outlive b. */
void lf_bsdf_set_coated_diffuse(lf_bsdf *b, const lf_coat_table *table, lf_microfacet coat, lf_vec3 r);
/* eta_b, k_b: the conductor's own index (divided by the coat's here, as pbrt-v4 does). */
void lf_bsdf_set_coated_conductor(lf_bsdf *b, const lf_coat_table *table, lf_microfacet coat, lf_vec3 eta_b,
                                  lf_vec3 k_b, lf_microfacet base);

/* data must outlive b. */
void lf_bsdf_set_measured(lf_bsdf *b, const lf_measured *data);
/* Light leaving a subsurface medium of index eta through its surface
 * (pbrt-v4's NormalizedFresnelBxDF, the BSSRDF's S_w): f = eta^2 (1 -
 * Fr(cos theta_i)) / (c pi) on wo's side of the surface, c its
 * normalisation (lf_normalized_fresnel_c), so that the cosine-weighted
 * integral is eta^2: the eta^2 undoes the 1/eta^2 of radiance entering
 * through the dielectric. */
void lf_bsdf_set_normalized_fresnel(lf_bsdf *b, float eta, float c);
float lf_normalized_fresnel_c(float eta);

lf_vec3 lf_bsdf_f(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi);  /* no cosine; 0 for specular lobes */
float lf_bsdf_pdf(const lf_bsdf *b, lf_vec3 wo, lf_vec3 wi);  /* pdf of lf_bsdf_sample's non-specular parts */
/* uc picks a lobe, (u0, u1) a direction.  Returns 0 when there is no sample. */
int lf_bsdf_sample(const lf_bsdf *b, lf_vec3 wo, float uc, float u0, float u1, struct lf_bsdf_sample *s);
int lf_bsdf_is_specular(const lf_bsdf *b); /* every lobe is a delta: skip light sampling */

/* Fresnel reflectance: dielectric with relative index eta (cos_i < 0: from
 * inside) and conductor with complex index eta + i k (Born & Wolf; pbrt-v4
 * FrDielectric / FrComplex). */
float lf_fresnel_dielectric(float cos_i, float eta);
float lf_fresnel_conductor(float cos_i, float eta, float k);

/* -------------------------------------------------------------- textures */

typedef struct lf_texture lf_texture;
float lf_texture_float(const lf_texture *t, const lf_shading_ctx *ctx);
lf_vec3 lf_texture_rgb(const lf_texture *t, const lf_shading_ctx *ctx);

/* ------------------------------------------------------------- materials */

typedef struct lf_material lf_material;
typedef struct lf_materials lf_materials;

/* Builds every Texture and every Material / MakeNamedMaterial of d; material
 * index i is d->materials[i].  Parameters are checked with lf_params_finish
 * (d's paramsets are marked as used, hence not const). */
int lf_materials_build(lf_scene_desc *d, lf_materials **out, lf_error *err);
void lf_materials_free(lf_materials *m); /* accepts NULL */
/* "file:line:col: warning: ..." lines for read-but-ignored parameters, or NULL. */
const char *lf_materials_warnings(const lf_materials *m);
/* index -1: pbrt's default material, diffuse with reflectance 0.5. */
const lf_material *lf_materials_get(const lf_materials *m, int index);
/* The texture named `name` of the given kind, NULL if none (for tests). */
const lf_texture *lf_materials_texture(const lf_materials *m, const char *name, int is_float);

/* pbrt's "interface" (also Material "" and "none"): no surface, rays pass straight through. */
int lf_material_is_interface(const lf_material *mat);
/* Does any input of the material (or of a mix's components) come from a
 * texture?  If not, the surface's (u,v) is never read and a renderer may
 * skip computing it. */
int lf_material_uses_textures(const lf_material *mat);
/* Has the material (or a mix's component) a "displacement"?  Then the
 * renderer fills the ctx derivatives (has_derivs) at its hits. */
int lf_material_bumps(const lf_material *mat);
/* pbrt-v4's BumpMap: the shading normal and tangent of ctx perturbed by the
 * displacement d: finite differences of d over du = dv = 0.0005 in (u,v)
 * (pbrt's step when a hit has no uv differentials, as lensfield's have
 * not), dp/du' = sdpdu + (d(u+du) - d) / du ns + d dndu, likewise for v;
 * ns' = normalize(dp/du' x dp/dv') on the side of ng.  Writes the bumped
 * context to out (ns, dpdu changed). */
/* (lf_bump_shading, below lf_tex_input) */
/* A "mix" material picks one of its two materials: the second with
 * probability "amount" (pbrt-v4 MixMaterial::ChooseMaterial), using u in
 * [0,1); nested mixes are resolved with u re-stretched.  Any other material
 * returns itself. */
const lf_material *lf_material_resolve(const lf_material *mat, const lf_shading_ctx *ctx, float u);
/* The BSDF at ctx.  A mix is resolved with a hash of ctx->p, as pbrt-v4
 * does; an interface gives kind LF_LOBE_NONE (no scattering). */
void lf_material_bsdf(const lf_material *mat, const lf_shading_ctx *ctx, lf_bsdf *out);
/* The material's pbrt type name ("diffuse", "mix", ...). */
const char *lf_material_type(const lf_material *mat);

/* ------------------------------------------------------------------------
 * Building blocks shared by render/material*.c and render/texture*.c.  Other
 * modules should not need them. */

/* A material or texture parameter that may be a constant or a texture. */
typedef struct lf_tex_input {
    const lf_texture *tex; /* NULL: constant */
    lf_vec3 value;         /* the constant (float inputs: all three equal) */
} lf_tex_input;

/* The textures built so far, in d->textures order (a texture may only use
 * textures declared before it, as in pbrt-v4). */
typedef struct lf_texture_list {
    lf_texture **items;
    size_t count;
    const char *scene_dir; /* top-level scene's directory, for file names (may be NULL) */
} lf_texture_list;

/* Reads parameter `name` of ps: "texture name" -> that texture (which must
 * exist with the right kind, else LF_ERR_PARAM with the parameter's
 * location); a float (is_float) or any spectrum form (lf_params_rgb) ->
 * a constant; absent -> def.  Type errors are left in ps->error for
 * lf_params_finish. */
int lf_tex_input_read(lf_paramset *ps, const char *name, int is_float, lf_spectrum_kind kind, lf_vec3 def,
                      const lf_texture_list *texs, lf_tex_input *out, lf_error *err);
float lf_tex_input_float(const lf_tex_input *in, const lf_shading_ctx *ctx);
lf_vec3 lf_tex_input_rgb(const lf_tex_input *in, const lf_shading_ctx *ctx);
void lf_bump_shading(const lf_tex_input *disp, const lf_shading_ctx *ctx, lf_shading_ctx *out);

/* Builds d's texture td (which may use the textures in texs); warnings go
 * to *warnings. */
int lf_texture_new(lf_texture_desc *td, const lf_texture_list *texs, lf_warnings *warnings, lf_texture **out,
                   lf_error *err);
void lf_texture_free(lf_texture *t); /* accepts NULL */
const char *lf_texture_name(const lf_texture *t);
int lf_texture_is_float(const lf_texture *t);

/* Perlin's improved noise as pbrt-v4 (util/noise.cpp): 0 at every integer
 * lattice point, in about [-1, 1]; lf_fbm sums `octaves` octaves at
 * frequencies 1.99^i with weights omega^i; lf_turbulence sums |noise| the
 * same way plus 0.2 omega^octaves (pbrt's clamped partial octave).  Both are
 * pbrt's FBm / Turbulence with zero filter width (no ray differentials). */
float lf_noise3(lf_vec3 p);
float lf_fbm(lf_vec3 p, float omega, int octaves);
float lf_turbulence(lf_vec3 p, float omega, int octaves);

/* pbrt-v4's PiecewiseLinear2D: a bilinearly interpolated table of nx x ny
 * values over [0,1]^2, optionally one per point of a grid of up to three
 * parameters (interpolated linearly between grid points; the data is laid
 * out [param 0][param 1]...[y][x]).  With build_cdf the table is a density
 * normalised over the square that can be sampled and inverted; without, it
 * is only evaluated and keeps its values. */
#define LF_PL2D_MAX_PARAMS 3
typedef struct lf_pl2d {
    int nx, ny, ndim;
    int param_size[LF_PL2D_MAX_PARAMS], param_stride[LF_PL2D_MAX_PARAMS];
    float *param_values[LF_PL2D_MAX_PARAMS];
    float *data, *marginal_cdf, *conditional_cdf;
} lf_pl2d;
int lf_pl2d_init(lf_pl2d *t, const float *data, int nx, int ny, int ndim, const int *param_res,
                 const float *const *param_values, int build_cdf);
void lf_pl2d_free(lf_pl2d *t);
float lf_pl2d_eval(const lf_pl2d *t, float x, float y, const float *param);
/* (*x, *y): uniform in, warped out; returns the density there. */
float lf_pl2d_sample(const lf_pl2d *t, float *x, float *y, const float *param);
/* The inverse of lf_pl2d_sample; returns the density at the input point. */
float lf_pl2d_invert(const lf_pl2d *t, float *x, float *y, const float *param);

/* An RGL ".bsdf" file (Dupuy & Jakob 2018) read as pbrt-v4 reads it;
 * errors name the path.  The BRDF functions work in the local shading frame
 * (z = normal) and are two-sided like pbrt's. */
int lf_measured_load(const char *path, lf_measured **out, lf_error *err);
void lf_measured_free(lf_measured *m); /* accepts NULL */
lf_vec3 lf_measured_f(const lf_measured *m, lf_vec3 wo, lf_vec3 wi);
float lf_measured_pdf(const lf_measured *m, lf_vec3 wo, lf_vec3 wi);
int lf_measured_sample(const lf_measured *m, lf_vec3 wo, float u0, float u1, lf_vec3 *wi, lf_vec3 *f, float *pdf);

/* pbrt-v4's HairBxDF (hair.c), in the local frame (x along the fibre, z
 * the surface normal): h in [-1, 1] across the fibre, eta its index,
 * sigma_a its absorption per unit of fibre radius, beta_m / beta_n the
 * longitudinal / azimuthal roughness in [0, 1], alpha the scale tilt in
 * degrees.  f includes pbrt's 1/|cos theta_i|. */
void lf_hair_setup(lf_hair *hp, float h, float eta, lf_vec3 sigma_a, float beta_m, float beta_n, float alpha_deg);
lf_vec3 lf_hair_f(const lf_hair *hp, lf_vec3 wo, lf_vec3 wi);
float lf_hair_pdf(const lf_hair *hp, lf_vec3 wo, lf_vec3 wi);
int lf_hair_sample(const lf_hair *hp, lf_vec3 wo, float uc, float u0, float u1, lf_vec3 *wi, lf_vec3 *f,
                   float *pdf);
lf_vec3 lf_hair_sigma_a_from_concentration(float eumelanin, float pheomelanin);
lf_vec3 lf_hair_sigma_a_from_reflectance(lf_vec3 c, float beta_n);

/* Subsurface scattering (Material "subsurface"): the medium inside a
 * surface of this material at ctx, with its coefficients already scaled
 * by "scale"; returns 0 for any other material.  eta is the boundary's
 * index. */
typedef struct lf_subsurface {
    lf_vec3 sigma_a, sigma_s;
    float g, eta, exit_c; /* exit_c: lf_normalized_fresnel_c(eta) */
} lf_subsurface;
int lf_material_subsurface(const lf_material *mat, const lf_shading_ctx *ctx, lf_subsurface *out);
/* pbrt-v4's table of measured media (Jensen et al. 2001; Narasimhan et
 * al. 2006): sigma_a and reduced sigma_s' in mm^-1; 0 if the name is known. */
int lf_named_medium(const char *name, lf_vec3 *sigma_a, lf_vec3 *sigma_s);
/* The single-scattering albedo whose random walk in a semi-infinite
 * medium reflects the diffuse albedo r (Chiang, Kutz and Burley 2016's
 * fit), per channel. */
lf_vec3 lf_subsurface_albedo_from_reflectance(lf_vec3 r);

/* Index of refraction of pbrt-v4's named glasses ("glass-BK7", ...) at
 * lambda_nm, from Schott's Sellmeier coefficients; 0 if the name is unknown. */
float lf_named_glass_eta(const char *name, float lambda_nm);

/* `filename` resolved against the directory of the scene file that named it;
 * if nothing is there, against scene_dir (the top-level scene's directory,
 * where pbrt-v4's ResolveFilename looks; NULL: none); absolute names
 * unchanged.  Malloc'ed; NULL when out of memory.  For the texture,
 * material and environment-map files. */
char *lf_shading_resolve_path(const char *scene_file, const char *scene_dir, const char *filename);
/* Is the file an 8-bit format (PNG, JPEG, ...), which lf_image_read decodes
 * from sRGB? */
int lf_shading_is_8bit_image(const char *path);

/* Normal maps ("string normalmap"), read once per resolved path: the cache
 * owns the images (lf_normal_map_get creates it on first use). */
typedef struct lf_normal_maps lf_normal_maps;
struct lf_image;
/* The map at path, read with a linear encoding as pbrt-v4 does; an error
 * (no file, fewer than three channels) without a location: callers add it. */
int lf_normal_map_get(lf_normal_maps **cache, const char *path, const struct lf_image **out, lf_error *err);
void lf_normal_maps_free(lf_normal_maps *c); /* accepts NULL */
/* pbrt-v4's NormalMap: the map's rgb at (u, 1 - v) (bilinear, repeat) as
 * 2 rgb - 1, normalised, in the frame x = dp/du orthogonalised against ns,
 * y = ns x x, z = ns, becomes the shading normal (on ng's side); dp/du is
 * re-orthogonalised around it.  Writes the new context to out. */
void lf_normal_map_shading(const struct lf_image *map, const lf_shading_ctx *ctx, lf_shading_ctx *out);

#ifdef __cplusplus
}
#endif
#endif
