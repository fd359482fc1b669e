/* material.c - pbrt-v4 materials: parameters in, BSDFs out.
 *
 * Parameter names, defaults and semantics follow pbrt-v4 (materials.cpp and
 * the file-format documentation).  Supported: diffuse, conductor,
 * dielectric, thindielectric, diffusetransmission, coateddiffuse,
 * coatedconductor (both approximated: see the comment in bsdf.c), mix,
 * measured (RGL .bsdf files, measured.c), hair (hair.c), subsurface (a
 * random walk in the renderer, render/subsurface.c) and interface ("",
 * "none").  "displacement" bump-maps the shading normal (lf_bump_shading);
 * "normalmap" replaces it from a tangent-space image (normalmap.c), and
 * wins over "displacement" as in pbrt-v4.
 */
#include "lf_shading.h"

#include "base/lf_color.h"
#include "base/lf_params.h"
#include "image/lf_image.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum mat_kind {
    MAT_INTERFACE,
    MAT_DIFFUSE,
    MAT_CONDUCTOR,
    MAT_DIELECTRIC,
    MAT_THIN_DIELECTRIC,
    MAT_DIFFUSE_TRANSMISSION,
    MAT_COATED_DIFFUSE,
    MAT_COATED_CONDUCTOR,
    MAT_MIX,
    MAT_MEASURED,
    MAT_HAIR,
    MAT_SUBSURFACE
} mat_kind;

/* Hair absorption given as sigma_a, as a colour (reflectance) or as
 * melanin concentrations (pbrt-v4 HairMaterial, in that priority). */
typedef enum hair_mode { HAIR_SIGMA_A, HAIR_REFLECTANCE, HAIR_MELANIN } hair_mode;

/* Roughness inputs as pbrt-v4 reads them: uroughness / vroughness, each
 * falling back to roughness. */
typedef struct roughness {
    lf_tex_input u, v;
    int remap;
} roughness;

struct lf_material {
    mat_kind kind;
    const char *type; /* pbrt's name, a string literal */
    lf_tex_input reflectance, transmittance, eta_c, k_c;
    int from_reflectance; /* conductor given by "reflectance" */
    roughness rough, rough_b;
    float eta;            /* dielectric / coat index */
    float scale;          /* diffusetransmission */
    float thickness;      /* coated */
    lf_coat_table *table; /* coated: albedo of the coat for eta */
    /* mix */
    const lf_material *mix[2];
    int mix_index[2];
    lf_tex_input amount;
    lf_measured *measured;     /* measured: the file's tables, owned */
    hair_mode hair;            /* hair: sigma_a, reflectance (in "reflectance") or melanin */
    lf_tex_input sigma_a, eumelanin, pheomelanin, beta_m, beta_n, alpha, eta_tex;
    /* subsurface: sigma_a (above) and sigma_s, or reflectance and mfp */
    lf_tex_input sigma_s, mfp;
    int ss_from_reflectance;
    float ss_g, ss_exit_c;
    lf_tex_input displacement; /* bump map (pbrt-v4 "float displacement"), when bump */
    int bump;
    const lf_image *normal_map; /* "normalmap", owned by lf_materials' cache; NULL if none */
    lf_loc loc;
};

struct lf_materials {
    lf_material *items;
    size_t count;
    lf_material def; /* index -1 */
    lf_texture_list texs;
    lf_warnings warnings;
    lf_normal_maps *nmaps; /* one image per normal map file */
};

/* --------------------------------------------------------- named glasses */

/* Schott catalogue Sellmeier coefficients (B1 B2 B3, C1 C2 C3 in um^2):
 * n^2 = 1 + sum B_i l^2 / (l^2 - C_i), l in micrometres.  pbrt-v4 tabulates
 * these glasses as spectra; "glass-F5/F10/F11" are Schott SF5/SF10/SF11. */
static const struct {
    const char *name;
    double b[3], c[3];
} glasses[] = {
    {"glass-BK7", {1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653}},
    {"glass-BAF10", {1.5851495, 0.143559385, 1.08521269}, {0.00926681282, 0.0424489805, 105.613573}},
    {"glass-FK51A", {0.971247817, 0.216901417, 0.904651666}, {0.00472301995, 0.0153575612, 168.68133}},
    {"glass-LASF9", {2.00029547, 0.298926886, 1.80691843}, {0.0121426017, 0.0538736236, 156.530829}},
    {"glass-F5", {1.52481889, 0.187085527, 1.42729015}, {0.011254756, 0.0588995392, 129.141675}},
    {"glass-F10", {1.61625977, 0.259229334, 1.07762317}, {0.0127534559, 0.0581983954, 116.60768}},
    {"glass-F11", {1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}},
};

float lf_named_glass_eta(const char *name, float lambda_nm)
{
    for (size_t i = 0; i < sizeof glasses / sizeof glasses[0]; i++) {
        if (strcmp(name, glasses[i].name) != 0)
            continue;
        double l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3), n2 = 1.0;
        for (int k = 0; k < 3; k++)
            n2 += glasses[i].b[k] * l2 / (l2 - glasses[i].c[k]);
        return (float)sqrt(n2);
    }
    return 0.f;
}

/* --------------------------------------------------------- reading */

static int read_roughness(lf_paramset *ps, const char *prefix, const lf_texture_list *texs, roughness *r,
                          lf_error *err)
{
    char un[64], vn[64], rn[64];
    snprintf(un, sizeof un, "%suroughness", prefix);
    snprintf(vn, sizeof vn, "%svroughness", prefix);
    snprintf(rn, sizeof rn, "%sroughness", prefix);
    lf_vec3 zero = lf_v3(0, 0, 0);
    int rc = LF_OK;
    int has_u = lf_params_peek(ps, un) != NULL, has_v = lf_params_peek(ps, vn) != NULL;
    if (has_u)
        rc = lf_tex_input_read(ps, un, 1, LF_SPECTRUM_UNBOUNDED, zero, texs, &r->u, err);
    if (!rc && has_v)
        rc = lf_tex_input_read(ps, vn, 1, LF_SPECTRUM_UNBOUNDED, zero, texs, &r->v, err);
    if (!rc && (!has_u || !has_v)) {
        lf_tex_input both;
        rc = lf_tex_input_read(ps, rn, 1, LF_SPECTRUM_UNBOUNDED, zero, texs, &both, err);
        if (!has_u)
            r->u = both;
        if (!has_v)
            r->v = both;
    }
    r->remap = lf_params_bool(ps, "remaproughness", 1);
    return rc;
}

static lf_microfacet eval_roughness(const roughness *r, const lf_shading_ctx *ctx)
{
    float u = fmaxf(0.f, lf_tex_input_float(&r->u, ctx)), v = fmaxf(0.f, lf_tex_input_float(&r->v, ctx));
    lf_microfacet m = {r->remap ? lf_roughness_to_alpha(u) : u, r->remap ? lf_roughness_to_alpha(v) : v};
    return m;
}

/* pbrt-v4 reads a dielectric's "eta" as a float or a spectrum; without
 * spectral rendering we take its value at 550 nm (named glasses from their
 * Sellmeier fit, sampled spectra interpolated, rgb: its green). */
static int read_eta(lf_paramset *ps, const char *name, float def, float *eta, lf_error *err)
{
    *eta = def;
    const lf_param *pk = lf_params_peek(ps, name);
    if (!pk)
        return LF_OK;
    const lf_loc *l = &pk->loc;
    if (pk->type == LF_PT_SPECTRUM && pk->n_strs == 1 && pk->n_nums == 0) {
        float n = lf_named_glass_eta(pk->strs[0], 550.f);
        if (n > 0.f) {
            lf_params_find(ps, name);
            *eta = n;
            return LF_OK;
        }
        lf_vec3 c;
        if (lf_params_rgb(ps, name, LF_SPECTRUM_UNBOUNDED, lf_v3(def, def, def), &c))
            *eta = c.y;
        return LF_OK;
    }
    if (pk->type == LF_PT_SPECTRUM && pk->n_strs == 0 && pk->n_nums >= 2 && pk->n_nums % 2 == 0) {
        lf_params_find(ps, name);
        const double *v = pk->nums;
        size_t n = pk->n_nums / 2;
        double x = v[1];
        if (550.0 >= v[2 * (n - 1)])
            x = v[2 * (n - 1) + 1];
        for (size_t i = 0; i + 1 < n; i++)
            if (550.0 >= v[2 * i] && 550.0 <= v[2 * i + 2]) {
                double t = (550.0 - v[2 * i]) / (v[2 * i + 2] - v[2 * i]);
                x = v[2 * i + 1] + t * (v[2 * i + 3] - v[2 * i + 1]);
                break;
            }
        *eta = (float)x;
    } else if (pk->type == LF_PT_TEXTURE) {
        lf_params_find(ps, name);
        return lf_error_at(err, LF_ERR_UNSUPPORTED, l,
                           "\"%s\" must be a float or a spectrum, not a texture (as in pbrt-v4)", name);
    } else if (pk->type == LF_PT_FLOAT) {
        *eta = (float)lf_params_float(ps, name, def);
    } else {
        lf_vec3 c;
        if (lf_params_rgb(ps, name, LF_SPECTRUM_UNBOUNDED, lf_v3(def, def, def), &c))
            *eta = c.y;
    }
    /* pbrt-v4 treats an index of 0 (a spectrum undefined there) as 1. */
    if (*eta == 0.f)
        *eta = 1.f;
    if (!(*eta > 0.f) || !isfinite(*eta))
        return lf_error_at(err, LF_ERR_PARAM, l, "\"%s\" must be positive, got %g", name, *eta);
    return LF_OK;
}

/* Conductor index: "eta"/"k" (default copper) or "reflectance", never both. */
static int read_conductor(lf_paramset *ps, const char *prefix, const lf_texture_list *texs, lf_material *m,
                          const lf_loc *loc, lf_error *err)
{
    char en[64], kn[64];
    snprintf(en, sizeof en, "%seta", prefix);
    snprintf(kn, sizeof kn, "%sk", prefix);
    int has_eta = lf_params_peek(ps, en) != NULL, has_k = lf_params_peek(ps, kn) != NULL;
    int has_r = lf_params_peek(ps, "reflectance") != NULL;
    if (has_r && (has_eta || has_k))
        return lf_error_at(err, LF_ERR_PARAM, loc,
                           "%s material: give either \"reflectance\" or \"%s\" and \"%s\", not both", m->type, en, kn);
    if (has_r) {
        m->from_reflectance = 1;
        return lf_tex_input_read(ps, "reflectance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0, 0, 0), texs, &m->reflectance, err);
    }
    lf_vec3 cu_eta, cu_k;
    if (lf_named_spectrum_rgb("metal-Cu-eta", &cu_eta) || lf_named_spectrum_rgb("metal-Cu-k", &cu_k)) {
        /* Fallback if the colour module lacks the table: common RGB fits. */
        cu_eta = lf_v3(0.200438f, 0.924033f, 1.10221f);
        cu_k = lf_v3(3.91295f, 2.45285f, 2.14219f);
    }
    int rc = lf_tex_input_read(ps, en, 0, LF_SPECTRUM_UNBOUNDED, cu_eta, texs, &m->eta_c, err);
    if (!rc)
        rc = lf_tex_input_read(ps, kn, 0, LF_SPECTRUM_UNBOUNDED, cu_k, texs, &m->k_c, err);
    return rc;
}

static void conductor_index(const lf_material *m, const lf_shading_ctx *ctx, lf_vec3 *eta, lf_vec3 *k)
{
    if (m->from_reflectance) {
        /* pbrt-v4 ConductorMaterial: eta = 1, k = 2 sqrt(r) / sqrt(1 - r),
         * which gives normal-incidence reflectance r. */
        lf_vec3 r = lf_tex_input_rgb(&m->reflectance, ctx);
        float c[3] = {r.x, r.y, r.z};
        for (int i = 0; i < 3; i++) {
            float x = lf_clampf(c[i], 0.f, 0.9999f);
            c[i] = 2.f * sqrtf(x) / sqrtf(1.f - x);
        }
        *eta = lf_v3(1, 1, 1);
        *k = lf_v3(c[0], c[1], c[2]);
        return;
    }
    *eta = lf_tex_input_rgb(&m->eta_c, ctx);
    *k = lf_tex_input_rgb(&m->k_c, ctx);
}

/* Layered-material parameters that pbrt-v4's random walk uses and our
 * closed-form approximation does not: read them, warn when they matter. */
static int read_layer_extras(lf_paramset *ps, const lf_texture_list *texs, lf_material *m, lf_warnings *warnings,
                             lf_error *err)
{
    lf_tex_input thick, albedo, g;
    int rc = lf_tex_input_read(ps, "thickness", 1, LF_SPECTRUM_UNBOUNDED, lf_v3(0.01f, 0.01f, 0.01f), texs, &thick, err);
    if (!rc)
        rc = lf_tex_input_read(ps, "albedo", 0, LF_SPECTRUM_ALBEDO, lf_v3(0, 0, 0), texs, &albedo, err);
    if (!rc)
        rc = lf_tex_input_read(ps, "g", 1, LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), texs, &g, err);
    if (rc)
        return rc;
    if (thick.tex) {
        lf_warn_at(warnings, &lf_params_peek(ps, "thickness")->loc,
                   "%s: a textured \"thickness\" is not supported; using 0.01", m->type);
        m->thickness = 0.01f;
    } else {
        m->thickness = fmaxf(0.f, thick.value.x);
    }
    if (albedo.tex || !lf_is_black(albedo.value))
        lf_warn_at(warnings, &lf_params_peek(ps, "albedo")->loc,
                   "%s: scattering inside the coat (\"albedo\") is not simulated; the layer is treated as clear",
                   m->type);
    if (g.tex || g.value.x != 0.f)
        lf_warn_at(warnings, &lf_params_peek(ps, "g")->loc, "%s: \"g\" ignored (no scattering in the coat)", m->type);
    int maxdepth = lf_params_int(ps, "maxdepth", 10), nsamples = lf_params_int(ps, "nsamples", 1);
    if (maxdepth != 10)
        lf_warn_at(warnings, &lf_params_peek(ps, "maxdepth")->loc,
                   "%s: \"maxdepth\" ignored (the layers are summed in closed form)", m->type);
    if (nsamples != 1)
        lf_warn_at(warnings, &lf_params_peek(ps, "nsamples")->loc,
                   "%s: \"nsamples\" ignored (the layers are summed in closed form)", m->type);
    return LF_OK;
}

static int read_measured(lf_paramset *ps, const char *scene_dir, lf_material *m, const lf_loc *loc, lf_error *err)
{
    const char *fn = lf_params_string(ps, "filename", "");
    const lf_param *p = lf_params_peek(ps, "filename");
    if (!fn || !*fn)
        return lf_error_at(err, LF_ERR_PARAM, loc, "measured material: \"string filename\" is required");
    char *path = lf_shading_resolve_path(p->loc.file, scene_dir, fn);
    if (!path)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    lf_error lerr = {0};
    int rc = lf_measured_load(path, &m->measured, &lerr);
    if (rc)
        lf_error_at(err, rc, &p->loc, "measured material: %s", lerr.msg);
    free(path);
    return rc;
}

/* pbrt-v4 HairMaterial::Create: sigma_a wins over reflectance (or its old
 * name "color"), which wins over the melanin concentrations; with none of
 * them, eumelanin 1.3 (brown hair). */
static int read_hair(lf_paramset *ps, const lf_texture_list *texs, lf_material *m, lf_warnings *warnings,
                     const lf_loc *loc, lf_error *err)
{
    lf_vec3 z = lf_v3(0, 0, 0);
    int has_s = lf_params_peek(ps, "sigma_a") != NULL;
    const char *rname = lf_params_peek(ps, "reflectance") ? "reflectance" : "color";
    int has_r = lf_params_peek(ps, rname) != NULL;
    int has_e = lf_params_peek(ps, "eumelanin") != NULL, has_p = lf_params_peek(ps, "pheomelanin") != NULL;
    int rc = lf_tex_input_read(ps, "sigma_a", 0, LF_SPECTRUM_UNBOUNDED, z, texs, &m->sigma_a, err);
    if (!rc)
        rc = lf_tex_input_read(ps, rname, 0, LF_SPECTRUM_ALBEDO, z, texs, &m->reflectance, err);
    if (!rc)
        rc = lf_tex_input_read(ps, "eumelanin", 1, LF_SPECTRUM_UNBOUNDED, lf_v3(has_e || has_p ? 0.f : 1.3f, 0, 0),
                               texs, &m->eumelanin, err);
    if (!rc)
        rc = lf_tex_input_read(ps, "pheomelanin", 1, LF_SPECTRUM_UNBOUNDED, z, texs, &m->pheomelanin, err);
    const struct { const char *name; float def; lf_tex_input *in; } fl[] = {
        {"eta", 1.55f, &m->eta_tex}, {"beta_m", 0.3f, &m->beta_m}, {"beta_n", 0.3f, &m->beta_n}, {"alpha", 2.f, &m->alpha}};
    for (int i = 0; i < 4 && !rc; i++)
        rc = lf_tex_input_read(ps, fl[i].name, 1, LF_SPECTRUM_UNBOUNDED, lf_v3(fl[i].def, fl[i].def, fl[i].def), texs,
                               fl[i].in, err);
    if (rc)
        return rc;
    m->hair = has_s ? HAIR_SIGMA_A : has_r ? HAIR_REFLECTANCE : HAIR_MELANIN;
    const char *ignored[] = {has_s ? rname : NULL, has_s || has_r ? "eumelanin" : NULL,
                             has_s || has_r ? "pheomelanin" : NULL};
    const char *why = has_s ? "sigma_a" : rname;
    for (int i = 0; i < 3; i++)
        if (ignored[i] && lf_params_peek(ps, ignored[i]))
            lf_warn_at(warnings, &lf_params_peek(ps, ignored[i])->loc,
                       "hair: ignoring \"%s\" since \"%s\" was provided (as pbrt-v4)", ignored[i], why);
    (void)loc;
    return LF_OK;
}

static lf_vec3 clamp01(lf_vec3 c)
{
    return lf_v3(lf_clampf(c.x, 0.f, 1.f), lf_clampf(c.y, 0.f, 1.f), lf_clampf(c.z, 0.f, 1.f));
}

/* pbrt-v4 SubsurfaceMaterial::Create: the medium by "name" (pbrt's
 * measured table, g forced to 0), by "sigma_a" and "sigma_s", by
 * "reflectance" and "mfp", or pbrt's default (skim-milk-like) coefficients;
 * "scale" multiplies the coefficients (or mfp), "eta" is the boundary's
 * index, roughness its GGX roughness. */
static int read_subsurface(lf_paramset *ps, const lf_texture_list *texs, lf_material *m, lf_warnings *warnings,
                           const lf_loc *loc, lf_error *err)
{
    m->kind = MAT_SUBSURFACE;
    m->type = "subsurface";
    m->ss_g = (float)lf_params_float(ps, "g", 0.0);
    const char *name = lf_params_string(ps, "name", "");
    int rc = LF_OK;
    if (name && *name) {
        const lf_param *p = lf_params_peek(ps, "name");
        lf_vec3 sa, ss;
        if (lf_named_medium(name, &sa, &ss))
            return lf_error_at(err, LF_ERR_PARAM, &p->loc,
                               "subsurface: named medium \"%s\" not found (pbrt-v4's names: \"Skin1\", \"Wholemilk\", "
                               "\"Ketchup\", ...; docs/scene-format.md)",
                               name);
        if (m->ss_g != 0.f)
            lf_warn_at(warnings, &lf_params_peek(ps, "g")->loc,
                       "subsurface: non-zero \"g\" ignored with named scattering coefficients (as pbrt-v4)");
        m->ss_g = 0.f; /* the table holds reduced scattering coefficients */
        m->sigma_a.value = sa;
        m->sigma_s.value = ss;
    } else {
        int has_a = lf_params_peek(ps, "sigma_a") != NULL, has_s = lf_params_peek(ps, "sigma_s") != NULL;
        if (has_a != has_s)
            return lf_error_at(err, LF_ERR_PARAM, loc, "subsurface: \"%s\" given without \"%s\"",
                               has_a ? "sigma_a" : "sigma_s", has_a ? "sigma_s" : "sigma_a");
        if (has_a) {
            rc = lf_tex_input_read(ps, "sigma_a", 0, LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), texs, &m->sigma_a, err);
            if (!rc)
                rc = lf_tex_input_read(ps, "sigma_s", 0, LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), texs, &m->sigma_s, err);
        } else if (lf_params_peek(ps, "reflectance")) {
            m->ss_from_reflectance = 1;
            rc = lf_tex_input_read(ps, "reflectance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0, 0, 0), texs, &m->reflectance, err);
            if (!rc)
                rc = lf_tex_input_read(ps, "mfp", 0, LF_SPECTRUM_UNBOUNDED, lf_v3(1, 1, 1), texs, &m->mfp, err);
        } else {
            m->sigma_a.value = lf_v3(.0011f, .0024f, .014f);
            m->sigma_s.value = lf_v3(2.55f, 3.21f, 3.77f);
        }
    }
    if (rc)
        return rc;
    m->scale = (float)lf_params_float(ps, "scale", 1.0);
    m->eta = (float)lf_params_float(ps, "eta", 1.33);
    if (!(m->eta > 0.f))
        return lf_error_at(err, LF_ERR_PARAM, loc, "subsurface: \"eta\" must be positive, got %g", m->eta);
    m->ss_exit_c = lf_normalized_fresnel_c(m->eta);
    return read_roughness(ps, "", texs, &m->rough, err);
}

static float hash_position(lf_vec3 p);

int lf_material_subsurface(const lf_material *mat, const lf_shading_ctx *ctx, lf_subsurface *out)
{
    if (mat->kind == MAT_MIX) /* the component lf_material_bsdf chose at this point */
        mat = lf_material_resolve(mat, ctx, hash_position(ctx->p));
    if (mat->kind != MAT_SUBSURFACE)
        return 0;
    if (mat->ss_from_reflectance) {
        /* sigma_t = 1 / mfp, split by the albedo whose walk reflects r */
        lf_vec3 mfp = lf_scale(lf_tex_input_rgb(&mat->mfp, ctx), mat->scale);
        lf_vec3 a = lf_subsurface_albedo_from_reflectance(clamp01(lf_tex_input_rgb(&mat->reflectance, ctx)));
        float mf[3] = {mfp.x, mfp.y, mfp.z}, al[3] = {a.x, a.y, a.z}, sa[3], ss[3];
        for (int c = 0; c < 3; c++) {
            float st = mf[c] > 0.f ? 1.f / mf[c] : 1e30f;
            ss[c] = al[c] * st;
            sa[c] = (1.f - al[c]) * st;
        }
        out->sigma_a = lf_v3(sa[0], sa[1], sa[2]);
        out->sigma_s = lf_v3(ss[0], ss[1], ss[2]);
    } else {
        lf_vec3 a = lf_scale(lf_tex_input_rgb(&mat->sigma_a, ctx), mat->scale);
        lf_vec3 b = lf_scale(lf_tex_input_rgb(&mat->sigma_s, ctx), mat->scale);
        out->sigma_a = lf_v3(fmaxf(a.x, 0.f), fmaxf(a.y, 0.f), fmaxf(a.z, 0.f));
        out->sigma_s = lf_v3(fmaxf(b.x, 0.f), fmaxf(b.y, 0.f), fmaxf(b.z, 0.f));
    }
    out->g = mat->ss_g;
    out->eta = mat->eta;
    out->exit_c = mat->ss_exit_c;
    return 1;
}

static int read_measured_or_hair(lf_paramset *ps, const char *type, const lf_texture_list *texs, lf_material *m,
                                 lf_warnings *warnings, const lf_loc *loc, lf_error *err)
{
    if (!strcmp(type, "measured")) {
        m->kind = MAT_MEASURED;
        m->type = "measured";
        return read_measured(ps, texs ? texs->scene_dir : NULL, m, loc, err);
    }
    m->kind = MAT_HAIR;
    m->type = "hair";
    return read_hair(ps, texs, m, warnings, loc, err);
}

/* pbrt-v4 resolves the name as other files and reads each file once. */
static int read_normal_map(lf_materials *ms, const char *fn, const lf_loc *loc, lf_material *m, lf_error *err)
{
    char *path = lf_shading_resolve_path(loc->file, ms->texs.scene_dir, fn);
    if (!path)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    lf_error ierr = {0};
    int rc = lf_normal_map_get(&ms->nmaps, path, &m->normal_map, &ierr);
    free(path);
    if (rc)
        return lf_error_at(err, rc, loc, "%s: \"normalmap\": %s", m->type, ierr.msg);
    return LF_OK;
}

static int build_one(lf_material_desc *md, lf_materials *ms, lf_material *m, lf_error *err)
{
    lf_paramset *ps = &md->e.params;
    const lf_texture_list *texs = &ms->texs;
    const lf_loc *loc = &md->e.loc;
    const char *type = md->e.type ? md->e.type : "";
    int rc = LF_OK;
    m->loc = *loc;
    m->mix_index[0] = m->mix_index[1] = -1;
    if (!strcmp(type, "") || !strcmp(type, "none") || !strcmp(type, "interface")) {
        m->kind = MAT_INTERFACE;
        m->type = "interface";
    } else if (!strcmp(type, "diffuse")) {
        m->kind = MAT_DIFFUSE;
        m->type = "diffuse";
        rc = lf_tex_input_read(ps, "reflectance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0.5f, 0.5f, 0.5f), texs,
                               &m->reflectance, err);
    } else if (!strcmp(type, "conductor")) {
        m->kind = MAT_CONDUCTOR;
        m->type = "conductor";
        rc = read_conductor(ps, "", texs, m, loc, err);
        if (!rc)
            rc = read_roughness(ps, "", texs, &m->rough, err);
    } else if (!strcmp(type, "dielectric") || !strcmp(type, "thindielectric")) {
        int thin = type[0] == 't';
        m->kind = thin ? MAT_THIN_DIELECTRIC : MAT_DIELECTRIC;
        m->type = thin ? "thindielectric" : "dielectric";
        rc = read_eta(ps, "eta", 1.5f, &m->eta, err);
        if (!rc && !thin)
            rc = read_roughness(ps, "", texs, &m->rough, err);
    } else if (!strcmp(type, "diffusetransmission")) {
        m->kind = MAT_DIFFUSE_TRANSMISSION;
        m->type = "diffusetransmission";
        rc = lf_tex_input_read(ps, "reflectance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0.25f, 0.25f, 0.25f), texs,
                               &m->reflectance, err);
        if (!rc)
            rc = lf_tex_input_read(ps, "transmittance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0.25f, 0.25f, 0.25f), texs,
                                   &m->transmittance, err);
        m->scale = (float)lf_params_float(ps, "scale", 1.0);
    } else if (!strcmp(type, "coateddiffuse")) {
        m->kind = MAT_COATED_DIFFUSE;
        m->type = "coateddiffuse";
        rc = lf_tex_input_read(ps, "reflectance", 0, LF_SPECTRUM_ALBEDO, lf_v3(0.5f, 0.5f, 0.5f), texs,
                               &m->reflectance, err);
        if (!rc)
            rc = read_roughness(ps, "", texs, &m->rough, err);
        if (!rc)
            rc = read_eta(ps, "eta", 1.5f, &m->eta, err);
        if (!rc)
            rc = read_layer_extras(ps, texs, m, &ms->warnings, err);
    } else if (!strcmp(type, "coatedconductor")) {
        m->kind = MAT_COATED_CONDUCTOR;
        m->type = "coatedconductor";
        rc = read_roughness(ps, "interface.", texs, &m->rough, err);
        if (!rc)
            rc = read_eta(ps, "interface.eta", 1.5f, &m->eta, err);
        if (!rc)
            rc = read_roughness(ps, "conductor.", texs, &m->rough_b, err);
        if (!rc)
            rc = read_conductor(ps, "conductor.", texs, m, loc, err);
        if (!rc)
            rc = read_layer_extras(ps, texs, m, &ms->warnings, err);
        /* read_roughness read "remaproughness" twice; both see the same value. */
        m->rough_b.remap = m->rough.remap;
    } else if (!strcmp(type, "mix")) {
        m->kind = MAT_MIX;
        m->type = "mix";
        size_t n = 0;
        const char *const *names = lf_params_strings(ps, "materials", &n);
        const lf_param *p = lf_params_peek(ps, "materials");
        const lf_loc *pl = p ? &p->loc : loc;
        if (!names || n != 2) {
            rc = lf_error_at(err, LF_ERR_PARAM, pl, "mix material needs \"string materials\" with two names");
        } else {
            /* The names are resolved by link_mixes once every material is read. */
            m->mix_index[0] = m->mix_index[1] = -2;
        }
        if (!rc)
            rc = lf_tex_input_read(ps, "amount", 1, LF_SPECTRUM_UNBOUNDED, lf_v3(0.5f, 0.5f, 0.5f), texs, &m->amount,
                                   err);
    } else if (!strcmp(type, "measured") || !strcmp(type, "hair")) {
        rc = read_measured_or_hair(ps, type, texs, m, &ms->warnings, loc, err);
    } else if (!strcmp(type, "subsurface")) {
        rc = read_subsurface(ps, texs, m, &ms->warnings, loc, err);
    } else {
        return lf_error_at(err, LF_ERR_UNSUPPORTED, loc, "unknown material \"%s\"", type);
    }
    if (rc)
        return rc;

    /* Common to every pbrt-v4 material; not supported here. */
    if (m->kind != MAT_INTERFACE && m->kind != MAT_MIX) {
        if (lf_params_peek(ps, "displacement")) {
            rc = lf_tex_input_read(ps, "displacement", 1, LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), texs,
                                   &m->displacement, err);
            if (rc)
                return rc;
            m->bump = 1;
        }
        const lf_param *np = lf_params_peek(ps, "normalmap");
        const char *fn = np ? lf_params_string(ps, "normalmap", "") : NULL;
        if (fn && *fn) {
            rc = read_normal_map(ms, fn, &np->loc, m, err);
            if (rc)
                return rc;
        }
    }
    if (m->kind == MAT_COATED_DIFFUSE || m->kind == MAT_COATED_CONDUCTOR) {
        m->table = malloc(sizeof *m->table);
        if (!m->table)
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        lf_coat_table_init(m->table, m->eta);
    }
    char ctx[256];
    if (md->name)
        snprintf(ctx, sizeof ctx, "MakeNamedMaterial \"%s\" (type \"%s\")", md->name, type);
    else
        snprintf(ctx, sizeof ctx, "Material \"%s\"", type);
    return lf_params_finish(ps, ctx, err);
}

/* Links each mix to its two named materials and rejects cycles. */
static int link_mixes(lf_scene_desc *d, lf_materials *ms, lf_error *err)
{
    for (size_t i = 0; i < ms->count; i++) {
        lf_material *m = &ms->items[i];
        if (m->kind != MAT_MIX)
            continue;
        const lf_param *p = lf_params_peek(&d->materials[i].e.params, "materials");
        for (int k = 0; k < 2; k++) {
            const char *name = p->strs[k];
            int found = -1;
            for (size_t j = ms->count; j-- > 0;)
                if (d->materials[j].name && strcmp(d->materials[j].name, name) == 0) {
                    found = (int)j;
                    break;
                }
            if (found < 0)
                return lf_error_at(err, LF_ERR_PARAM, &p->loc, "mix material: named material \"%s\" is not defined",
                                   name);
            m->mix_index[k] = found;
            m->mix[k] = &ms->items[found];
        }
    }
    /* A mix that reaches itself would recurse forever when resolved. */
    for (size_t i = 0; i < ms->count; i++) {
        if (ms->items[i].kind != MAT_MIX)
            continue;
        /* Depth-first walk bounded by the material count. */
        int stack[64], depth[64], top = 0;
        stack[top] = (int)i;
        depth[top++] = 0;
        while (top > 0) {
            top--;
            int cur = stack[top], dd = depth[top];
            const lf_material *m = &ms->items[cur];
            if (m->kind != MAT_MIX)
                continue;
            for (int k = 0; k < 2; k++) {
                int nx = m->mix_index[k];
                if (nx == (int)i || dd + 1 > (int)ms->count || top >= 62) {
                    const lf_loc *l = &ms->items[i].loc;
                    return lf_error_at(err, LF_ERR_PARAM, l,
                                       "mix material \"%s\" contains itself (or nests too deeply)",
                                       d->materials[i].name ? d->materials[i].name : "");
                }
                stack[top] = nx;
                depth[top++] = dd + 1;
            }
        }
    }
    return LF_OK;
}

int lf_materials_build(lf_scene_desc *d, lf_materials **out, lf_error *err)
{
    *out = NULL;
    lf_materials *ms = calloc(1, sizeof *ms);
    if (!ms)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    ms->def.kind = MAT_DIFFUSE;
    ms->def.type = "diffuse";
    ms->def.reflectance.value = lf_v3(0.5f, 0.5f, 0.5f);
    ms->def.mix_index[0] = ms->def.mix_index[1] = -1;
    ms->texs.scene_dir = d->scene_dir;
    int rc = LF_OK;
    if (d->n_textures) {
        ms->texs.items = calloc(d->n_textures, sizeof *ms->texs.items);
        if (!ms->texs.items)
            rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; !rc && i < d->n_textures; i++) {
        rc = lf_texture_new(&d->textures[i], &ms->texs, &ms->warnings, &ms->texs.items[i], err);
        if (!rc)
            ms->texs.count = i + 1;
    }
    if (!rc && d->n_materials) {
        ms->items = calloc(d->n_materials, sizeof *ms->items);
        if (!ms->items)
            rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; !rc && i < d->n_materials; i++) {
        ms->count = i + 1;
        rc = build_one(&d->materials[i], ms, &ms->items[i], err);
    }
    if (!rc)
        rc = link_mixes(d, ms, err);
    if (rc) {
        lf_materials_free(ms);
        return rc;
    }
    *out = ms;
    return LF_OK;
}

void lf_materials_free(lf_materials *ms)
{
    if (!ms)
        return;
    for (size_t i = 0; i < ms->count; i++) {
        free(ms->items[i].table);
        lf_measured_free(ms->items[i].measured);
    }
    free(ms->items);
    for (size_t i = 0; i < ms->texs.count; i++)
        lf_texture_free(ms->texs.items[i]);
    free(ms->texs.items);
    lf_warnings_free(&ms->warnings);
    lf_normal_maps_free(ms->nmaps);
    free(ms);
}

const char *lf_materials_warnings(const lf_materials *ms) { return ms ? lf_warnings_text(&ms->warnings) : NULL; }

const lf_material *lf_materials_get(const lf_materials *ms, int index)
{
    if (index < 0 || (size_t)index >= ms->count)
        return &ms->def;
    return &ms->items[index];
}

const lf_texture *lf_materials_texture(const lf_materials *ms, const char *name, int is_float)
{
    for (size_t i = ms->texs.count; i-- > 0;)
        if (lf_texture_is_float(ms->texs.items[i]) == is_float && strcmp(lf_texture_name(ms->texs.items[i]), name) == 0)
            return ms->texs.items[i];
    return NULL;
}

/* --------------------------------------------------------- evaluation */

int lf_material_is_interface(const lf_material *mat) { return mat->kind == MAT_INTERFACE; }

int lf_material_uses_textures(const lf_material *mat)
{
    for (int depth = 0; depth < 64 && mat; depth++) {
        const lf_tex_input *in[] = {&mat->reflectance, &mat->transmittance, &mat->eta_c,   &mat->k_c,
                                    &mat->rough.u,     &mat->rough.v,       &mat->rough_b.u, &mat->rough_b.v,
                                    &mat->amount,      &mat->displacement, &mat->sigma_a,   &mat->eumelanin,
                                    &mat->pheomelanin, &mat->beta_m,       &mat->beta_n,    &mat->alpha,
                                    &mat->eta_tex,     &mat->sigma_s,      &mat->mfp};
        for (size_t i = 0; i < sizeof in / sizeof in[0]; i++)
            if (in[i]->tex)
                return 1;
        if (mat->kind == MAT_HAIR || mat->normal_map) /* h across the fibre is the hit's v; maps read (u,v) */
            return 1;
        if (mat->kind != MAT_MIX)
            return 0;
        if (lf_material_uses_textures(mat->mix[0]))
            return 1;
        mat = mat->mix[1];
    }
    return 0;
}
const char *lf_material_type(const lf_material *mat) { return mat->type; }

int lf_material_bumps(const lf_material *mat)
{
    for (int depth = 0; depth < 64 && mat; depth++) {
        if (mat->bump)
            return 1;
        if (mat->kind != MAT_MIX)
            return 0;
        if (lf_material_bumps(mat->mix[0]))
            return 1;
        mat = mat->mix[1];
    }
    return 0;
}

void lf_bump_shading(const lf_tex_input *disp, const lf_shading_ctx *ctx, lf_shading_ctx *out)
{
    *out = *ctx;
    if (!ctx->has_derivs)
        return;
    const float du = 0.0005f, dv = 0.0005f;
    lf_shading_ctx sh = *ctx;
    sh.p = lf_madd(ctx->p, ctx->sdpdu, du);
    sh.uv.x = ctx->uv.x + du;
    float d_u = lf_tex_input_float(disp, &sh);
    sh.p = lf_madd(ctx->p, ctx->sdpdv, dv);
    sh.uv.x = ctx->uv.x;
    sh.uv.y = ctx->uv.y + dv;
    float d_v = lf_tex_input_float(disp, &sh);
    float d = lf_tex_input_float(disp, ctx);
    lf_vec3 dpdu = lf_add(lf_add(ctx->sdpdu, lf_scale(ctx->ns, (d_u - d) / du)), lf_scale(ctx->dndu, d));
    lf_vec3 dpdv = lf_add(lf_add(ctx->sdpdv, lf_scale(ctx->ns, (d_v - d) / dv)), lf_scale(ctx->dndv, d));
    lf_vec3 n = lf_cross(dpdu, dpdv);
    float len2 = lf_dot(n, n);
    if (!(len2 > 0) || !isfinite(len2))
        return;
    n = lf_scale(n, 1.f / sqrtf(len2));
    if (lf_dot(n, ctx->ng) < 0) /* pbrt: the shading normal follows the geometric one's side */
        n = lf_neg(n);
    out->ns = n;
    float tl = lf_dot(dpdu, dpdu);
    if (tl > 0 && isfinite(tl))
        out->dpdu = lf_scale(dpdu, 1.f / sqrtf(tl));
}

const lf_material *lf_material_resolve(const lf_material *mat, const lf_shading_ctx *ctx, float u)
{
    for (int guard = 0; mat->kind == MAT_MIX && guard < 64; guard++) {
        float amt = lf_tex_input_float(&mat->amount, ctx);
        /* pbrt-v4 MixMaterial::ChooseMaterial: materials[1] with probability amount. */
        int pick;
        if (amt <= 0.f)
            pick = 0;
        else if (amt >= 1.f)
            pick = 1;
        else {
            pick = u < amt;
            /* Re-stretch u so a nested mix gets a fresh uniform value. */
            u = pick ? u / amt : (u - amt) / (1.f - amt);
            u = lf_clampf(u, 0.f, LF_ONE_MINUS_EPS);
        }
        mat = mat->mix[pick];
    }
    return mat;
}

/* A hash of the hit position to a uniform value in [0,1): pbrt-v4 chooses
 * mix components with HashFloat(p, ...), deterministic per point. */
static float hash_position(lf_vec3 p)
{
    uint32_t b[3];
    memcpy(&b[0], &p.x, 4);
    memcpy(&b[1], &p.y, 4);
    memcpy(&b[2], &p.z, 4);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 3; i++) {
        h ^= b[i];
        h *= 0xff51afd7ed558ccdull; /* MurmurHash3 fmix64 steps */
        h ^= h >> 33;
    }
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return (float)(h >> 40) * 0x1p-24f;
}


/* pbrt-v4 HairMaterial::GetBxDF: h = -1 + 2 v (curves put v across the
 * width; on other shapes it is whatever their v is), parameters clamped as
 * pbrt clamps them. */
static void hair_bsdf(const lf_material *mat, const lf_shading_ctx *ctx, lf_bsdf *out)
{
    float bm = lf_clampf(lf_tex_input_float(&mat->beta_m, ctx), 0.f, 1.f);
    float bn = lf_clampf(lf_tex_input_float(&mat->beta_n, ctx), 0.f, 1.f);
    float alpha = lf_tex_input_float(&mat->alpha, ctx), eta = lf_tex_input_float(&mat->eta_tex, ctx);
    lf_vec3 sa;
    if (mat->hair == HAIR_SIGMA_A) {
        sa = lf_tex_input_rgb(&mat->sigma_a, ctx);
        sa = lf_v3(fmaxf(sa.x, 0.f), fmaxf(sa.y, 0.f), fmaxf(sa.z, 0.f));
    } else if (mat->hair == HAIR_REFLECTANCE) {
        sa = lf_hair_sigma_a_from_reflectance(clamp01(lf_tex_input_rgb(&mat->reflectance, ctx)), bn);
    } else {
        sa = lf_hair_sigma_a_from_concentration(fmaxf(0.f, lf_tex_input_float(&mat->eumelanin, ctx)),
                                                fmaxf(0.f, lf_tex_input_float(&mat->pheomelanin, ctx)));
    }
    out->kind = LF_LOBE_HAIR;
    lf_hair_setup(&out->u.hair, -1.f + 2.f * ctx->uv.y, eta, sa, bm, bn, alpha);
}

void lf_material_bsdf(const lf_material *mat, const lf_shading_ctx *ctx, lf_bsdf *out)
{
    if (mat->kind == MAT_MIX)
        mat = lf_material_resolve(mat, ctx, hash_position(ctx->p));
    lf_shading_ctx bumped;
    if (mat->normal_map) {
        lf_normal_map_shading(mat->normal_map, ctx, &bumped);
        ctx = &bumped;
    } else if (mat->bump && ctx->has_derivs) {
        lf_bump_shading(&mat->displacement, ctx, &bumped);
        ctx = &bumped;
    }
    lf_bsdf_frame(out, ctx);
    switch (mat->kind) {
    case MAT_INTERFACE:
    case MAT_MIX:
        return;
    case MAT_DIFFUSE:
        lf_bsdf_set_diffuse(out, clamp01(lf_tex_input_rgb(&mat->reflectance, ctx)));
        return;
    case MAT_CONDUCTOR: {
        lf_vec3 eta, k;
        conductor_index(mat, ctx, &eta, &k);
        lf_bsdf_set_conductor(out, eta, k, eval_roughness(&mat->rough, ctx));
        return;
    }
    case MAT_DIELECTRIC:
        lf_bsdf_set_dielectric(out, mat->eta, eval_roughness(&mat->rough, ctx));
        return;
    case MAT_THIN_DIELECTRIC:
        lf_bsdf_set_thin_dielectric(out, mat->eta);
        return;
    case MAT_DIFFUSE_TRANSMISSION:
        lf_bsdf_set_diffuse_transmission(out, clamp01(lf_scale(lf_tex_input_rgb(&mat->reflectance, ctx), mat->scale)),
                                         clamp01(lf_scale(lf_tex_input_rgb(&mat->transmittance, ctx), mat->scale)));
        return;
    case MAT_COATED_DIFFUSE:
        lf_bsdf_set_coated_diffuse(out, mat->table, eval_roughness(&mat->rough, ctx),
                                   clamp01(lf_tex_input_rgb(&mat->reflectance, ctx)));
        out->u.coated.thickness = mat->thickness;
        return;
    case MAT_COATED_CONDUCTOR: {
        lf_vec3 eta, k;
        conductor_index(mat, ctx, &eta, &k);
        lf_bsdf_set_coated_conductor(out, mat->table, eval_roughness(&mat->rough, ctx), eta, k,
                                     eval_roughness(&mat->rough_b, ctx));
        out->u.coated.thickness = mat->thickness;
        return;
    }
    case MAT_MEASURED:
        lf_bsdf_set_measured(out, mat->measured);
        return;
    case MAT_HAIR:
        hair_bsdf(mat, ctx, out);
        return;
    case MAT_SUBSURFACE: /* the boundary; the renderer walks the inside (render/subsurface.c) */
        lf_bsdf_set_dielectric(out, mat->eta, eval_roughness(&mat->rough, ctx));
        return;
    }
}
