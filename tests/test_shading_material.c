/* test_shading_material.c - materials and textures built from scene text:
 * parameter defaults and semantics, texture lookups (checkerboard, image
 * maps with pbrt's t flip, scale, mix), mix materials, warnings and errors
 * with file:line:col. */
#include "image/lf_image.h"
#include "scenefile/lf_scene_desc.h"
#include "shading/lf_shading.h"

#include "lf_test.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#define DIR LF_BINARY_DIR "/test_shading_material.d"
#define SCENE DIR "/scene.pbrt"

static lf_shading_ctx ctx_uv(float u, float v)
{
    lf_shading_ctx c;
    memset(&c, 0, sizeof c);
    c.ns = c.ng = lf_v3(0, 0, 1);
    c.dpdu = lf_v3(1, 0, 0);
    c.uv.x = u;
    c.uv.y = v;
    return c;
}

/* Parses text and builds materials; returns the build status. */
static int build(const char *text, lf_scene_desc *d, lf_materials **m, lf_error *err)
{
    memset(d, 0, sizeof *d);
    *m = NULL;
    int rc = lf_scene_parse_string(text, SCENE, d, err);
    if (rc)
        return -1000 - rc; /* a parse failure is a test-scene bug */
    return lf_materials_build(d, m, err);
}

/* Builds text that must fail (in the parser, which refuses unsupported and
 * unknown types, or in the material builder); checks the message names the
 * file and line. */
static void expect_error(const char *text, int line, const char *needle)
{
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    char where[512];
    snprintf(where, sizeof where, "scene.pbrt:%d:", line);
    CHECK_MSG(rc != 0, "expected an error for \"%s\", got %d (%s)", needle, rc, err.msg);
    CHECK_MSG(strstr(err.msg, where) != NULL, "message lacks %s: %s", where, err.msg);
    CHECK_MSG(strstr(err.msg, needle) != NULL, "message lacks \"%s\": %s", needle, err.msg);
    CHECK(m == NULL);
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static int write_test_images(void)
{
    lf_error err = {0};
    if (mkdir(DIR, 0777) != 0 && errno != EEXIST)
        return -1;
    /* 4 x 2 RGB: R = x + 10 y, G = 1, B = y (row 0 at the top). */
    lf_image img;
    if (lf_image_alloc(&img, 4, 2, 3, &err))
        return -1;
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++) {
            float *p = lf_image_px(&img, x, y);
            p[0] = (float)(x + 10 * y);
            p[1] = 1.f;
            p[2] = (float)y;
        }
    int rc = lf_image_write(DIR "/ramp.exr", &img, NULL, NULL, &err);
    lf_image_free(&img);
    if (rc) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    /* 1 x 1 8-bit PNG of linear 0.2: code round(255 * srgb(0.2)) = 124. */
    if (lf_image_alloc(&img, 1, 1, 3, &err))
        return -1;
    img.data[0] = img.data[1] = img.data[2] = 0.2f;
    rc = lf_image_write(DIR "/grey.png", &img, NULL, NULL, &err);
    lf_image_free(&img);
    if (rc)
        fprintf(stderr, "%s\n", err.msg);
    return rc ? -1 : 0;
}

static void test_textures(void)
{
    const char *text =
        "WorldBegin\n"
        "Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" [4] \"float vscale\" [4]\n"
        "    \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1]\n"
        "Texture \"fchecks\" \"float\" \"checkerboard\" \"float udelta\" [0.5]\n"
        "Texture \"c3\" \"float\" \"checkerboard\" \"integer dimension\" [3]\n"
        "Texture \"ramp\" \"spectrum\" \"imagemap\" \"string filename\" \"ramp.exr\"\n"
        "Texture \"rampc\" \"spectrum\" \"imagemap\" \"string filename\" \"ramp.exr\" \"string wrap\" \"clamp\"\n"
        "Texture \"rampb\" \"spectrum\" \"imagemap\" \"string filename\" \"ramp.exr\" \"string wrap\" \"black\"\n"
        "Texture \"rampf\" \"float\" \"imagemap\" \"string filename\" \"ramp.exr\" \"float scale\" [2]\n"
        "    \"string filter\" \"trilinear\" \"float maxanisotropy\" [4]\n"
        "Texture \"rampp\" \"float\" \"imagemap\" \"string filename\" \"ramp.exr\" \"string filter\" \"point\"\n"
        "Texture \"grey\" \"float\" \"imagemap\" \"string filename\" \"grey.png\"\n"
        "Texture \"greylin\" \"float\" \"imagemap\" \"string filename\" \"grey.png\" \"string encoding\" \"linear\"\n"
        "Texture \"greyinv\" \"float\" \"imagemap\" \"string filename\" \"grey.png\" \"string encoding\" \"linear\"\n"
        "    \"bool invert\" true\n"
        "Texture \"quarter\" \"float\" \"constant\" \"float value\" [0.25]\n"
        "Texture \"sc\" \"spectrum\" \"scale\" \"texture tex\" \"checks\" \"texture scale\" \"quarter\"\n"
        "Texture \"mx\" \"spectrum\" \"mix\" \"rgb tex1\" [1 1 1] \"rgb tex2\" [0 0.5 0] \"float amount\" [0.25]\n"
        "Texture \"mxdef\" \"float\" \"mix\"\n"
        "Texture \"mxt\" \"spectrum\" \"mix\" \"texture tex1\" \"checks\" \"texture tex2\" \"mx\" \"texture amount\" \"fchecks\"\n"
        "Material \"diffuse\" \"texture reflectance\" \"checks\"\n";
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    CHECK_MSG(rc == 0, "build: %s", err.msg);
    if (rc) {
        lf_scene_desc_free(&d);
        return;
    }
    CHECK(lf_materials_warnings(m) == NULL);
    const lf_texture *checks = lf_materials_texture(m, "checks", 0);
    CHECK(checks != NULL && lf_materials_texture(m, "checks", 1) == NULL);
    lf_shading_ctx c;
    /* Checkerboard: s = 4u, t = 4v; even floor(s) + floor(t) -> tex1. */
    c = ctx_uv(0.1f, 0.1f);
    CHECK(lf_texture_rgb(checks, &c).x == 1.f && lf_texture_rgb(checks, &c).z == 0.f);
    c = ctx_uv(0.3f, 0.1f);
    CHECK(lf_texture_rgb(checks, &c).z == 1.f && lf_texture_rgb(checks, &c).x == 0.f);
    c = ctx_uv(0.3f, 0.3f);
    CHECK(lf_texture_rgb(checks, &c).x == 1.f);
    c = ctx_uv(-0.1f, 0.1f); /* floor(-0.4) = -1: odd */
    CHECK(lf_texture_rgb(checks, &c).z == 1.f);
    /* Float checkerboard, defaults tex1 = 1, tex2 = 0, udelta shifts s. */
    const lf_texture *fch = lf_materials_texture(m, "fchecks", 1);
    c = ctx_uv(0.2f, 0.2f); /* s = 0.7 */
    CHECK(lf_texture_float(fch, &c) == 1.f);
    c = ctx_uv(0.6f, 0.2f); /* s = 1.1 */
    CHECK(lf_texture_float(fch, &c) == 0.f);
    /* 3D checkerboard on the (identity) texture-space position. */
    const lf_texture *c3 = lf_materials_texture(m, "c3", 1);
    c = ctx_uv(0, 0);
    c.p = lf_v3(0.5f, 0.5f, 0.5f);
    CHECK(lf_texture_float(c3, &c) == 1.f);
    c.p = lf_v3(1.5f, 0.5f, 0.5f);
    CHECK(lf_texture_float(c3, &c) == 0.f);

    /* Image map, bilinear; texel centres at ((x + .5) / 4, (y + .5) / 2) in
     * (s, 1 - t): row 0 (the top) is at v = 0.75. */
    const lf_texture *ramp = lf_materials_texture(m, "ramp", 0);
    c = ctx_uv(0.375f, 0.75f); /* texel (1, 0) */
    CHECK_NEAR(lf_texture_rgb(ramp, &c).x, 1.0, 1e-5);
    CHECK_NEAR(lf_texture_rgb(ramp, &c).z, 0.0, 1e-5);
    c = ctx_uv(0.375f, 0.25f); /* texel (1, 1): bottom row */
    CHECK_NEAR(lf_texture_rgb(ramp, &c).x, 11.0, 1e-5);
    CHECK_NEAR(lf_texture_rgb(ramp, &c).z, 1.0, 1e-5);
    c = ctx_uv(0.5f, 0.5f); /* halfway between texels 1, 2 and rows 0, 1 */
    CHECK_NEAR(lf_texture_rgb(ramp, &c).x, 1.5 + 5.0, 1e-5);
    CHECK_NEAR(lf_texture_rgb(ramp, &c).y, 1.0, 1e-5);
    c = ctx_uv(0.0f, 0.75f); /* x = -0.5: repeat blends texel 3 and 0 */
    CHECK_NEAR(lf_texture_rgb(ramp, &c).x, 1.5, 1e-5);
    c = ctx_uv(1.375f, 1.75f); /* repeat in both directions */
    CHECK_NEAR(lf_texture_rgb(ramp, &c).x, 1.0, 1e-4);
    const lf_texture *rampc = lf_materials_texture(m, "rampc", 0), *rampb = lf_materials_texture(m, "rampb", 0);
    c = ctx_uv(0.0f, 0.75f);
    CHECK_NEAR(lf_texture_rgb(rampc, &c).x, 0.0, 1e-5); /* clamp: texel 0 twice */
    c = ctx_uv(0.875f + 0.125f, 0.75f);                /* x = 3.5: texel 3 and beyond */
    CHECK_NEAR(lf_texture_rgb(rampc, &c).x, 3.0, 1e-5);
    CHECK_NEAR(lf_texture_rgb(rampb, &c).x, 1.5, 1e-5); /* black beyond the edge */
    /* Float image map: channel 0 (pbrt-v4), times "scale". */
    const lf_texture *rampf = lf_materials_texture(m, "rampf", 1);
    c = ctx_uv(0.5f, 0.5f);
    CHECK_NEAR(lf_texture_float(rampf, &c), 2.0 * 6.5, 1e-4);
    const lf_texture *rampp = lf_materials_texture(m, "rampp", 1);
    c = ctx_uv(0.40f, 0.30f); /* x = 1.1, y = 0.9: nearest texel (1, 1) */
    CHECK_NEAR(lf_texture_float(rampp, &c), 11.0, 1e-5);
    /* 8-bit encodings: sRGB (default) decodes code 124 to ~0.2; "linear"
     * takes 124 / 255; invert gives 1 - that. */
    c = ctx_uv(0.5f, 0.5f);
    CHECK_NEAR(lf_texture_float(lf_materials_texture(m, "grey", 1), &c), lf_srgb_decode(124), 1e-6);
    CHECK_NEAR(lf_texture_float(lf_materials_texture(m, "grey", 1), &c), 0.2, 2e-3);
    CHECK_NEAR(lf_texture_float(lf_materials_texture(m, "greylin", 1), &c), 124.0 / 255.0, 1e-6);
    CHECK_NEAR(lf_texture_float(lf_materials_texture(m, "greyinv", 1), &c), 1.0 - 124.0 / 255.0, 1e-6);

    /* scale: checks * 0.25; mix: (1 - 0.25) tex1 + 0.25 tex2. */
    c = ctx_uv(0.1f, 0.1f);
    lf_vec3 v = lf_texture_rgb(lf_materials_texture(m, "sc", 0), &c);
    CHECK_NEAR(v.x, 0.25, 1e-6);
    CHECK_NEAR(v.z, 0.0, 1e-6);
    v = lf_texture_rgb(lf_materials_texture(m, "mx", 0), &c);
    CHECK_NEAR(v.x, 0.75, 1e-6);
    CHECK_NEAR(v.y, 0.75 + 0.125, 1e-6);
    /* pbrt-v4 mix defaults: tex1 0, tex2 1, amount 0.5. */
    CHECK_NEAR(lf_texture_float(lf_materials_texture(m, "mxdef", 1), &c), 0.5, 1e-6);
    /* Textured amount: fchecks is 1 at s = 0.7 -> all tex2 ("mx"), and 0
     * at s = 1.1 -> all tex1 ("checks": red, as floor(4u) + floor(4v) = 2). */
    c = ctx_uv(0.2f, 0.2f);
    v = lf_texture_rgb(lf_materials_texture(m, "mxt", 0), &c);
    CHECK_NEAR(v.x, 0.75, 1e-6);
    CHECK_NEAR(v.y, 0.875, 1e-6);
    c = ctx_uv(0.6f, 0.2f);
    v = lf_texture_rgb(lf_materials_texture(m, "mxt", 0), &c);
    CHECK_NEAR(v.x, 1.0, 1e-6);
    CHECK_NEAR(v.z, 0.0, 1e-6);

    /* A material using the texture. */
    lf_bsdf b;
    c = ctx_uv(0.3f, 0.1f);
    lf_material_bsdf(lf_materials_get(m, 0), &c, &b);
    CHECK(b.kind == LF_LOBE_DIFFUSE && b.u.diffuse.r.z == 1.f && b.u.diffuse.r.x == 0.f);
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static void test_materials(void)
{
    const char *text =
        "WorldBegin\n"
        "Material \"conductor\"\n"                                                          /* 0 */
        "Material \"conductor\" \"rgb reflectance\" [0.8 0.5 0.2] \"float roughness\" [0.04]\n" /* 1 */
        "Material \"conductor\" \"float uroughness\" [0.04] \"float vroughness\" [0.09]\n"
        "    \"bool remaproughness\" false\n"                                                /* 2 */
        "MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\"\n"
        "    \"spectrum k\" \"metal-Au-k\" \"float roughness\" [0.01]\n"                      /* 3 */
        "MakeNamedMaterial \"glass\" \"string type\" \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n" /* 4 */
        "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"gold\" \"glass\"]\n"
        "    \"float amount\" [0.3]\n"                                                       /* 5 */
        "Material \"dielectric\" \"float eta\" [1.33] \"float roughness\" [0.25]\n"           /* 6 */
        "Material \"thindielectric\"\n"                                                     /* 7 */
        "Material \"coateddiffuse\" \"float roughness\" [0.1] \"rgb reflectance\" [0.2 0.4 0.6]\n" /* 8 */
        "Material \"coatedconductor\" \"float interface.roughness\" [0.04] \"float conductor.roughness\" [0.25]\n" /* 9 */
        "Material \"diffusetransmission\" \"float scale\" [2]\n"                             /* 10 */
        "Material \"interface\"\n"                                                          /* 11 */
        "Material \"\"\n"                                                                   /* 12 */
        "Material \"coateddiffuse\" \"float g\" [0.3] \"float thickness\" [0.05]\n"           /* 13 */
        "Material \"diffuse\" \"float displacement\" [0.1] \"string normalmap\" \"\"\n"      /* 14 */
        "Material \"dielectric\" \"spectrum eta\" [400 1.6 500 1.55 600 1.5]\n";             /* 15 */
    lf_scene_desc d;
    lf_materials *m;
    lf_error err = {0};
    int rc = build(text, &d, &m, &err);
    CHECK_MSG(rc == 0, "build: %s", err.msg);
    if (rc) {
        lf_scene_desc_free(&d);
        return;
    }
    lf_shading_ctx c = ctx_uv(0.5f, 0.5f);
    lf_bsdf b;
    /* Default material: diffuse 0.5. */
    lf_material_bsdf(lf_materials_get(m, -1), &c, &b);
    CHECK(b.kind == LF_LOBE_DIFFUSE && b.u.diffuse.r.x == 0.5f && b.u.diffuse.r.z == 0.5f);
    /* Conductor default: copper, smooth. */
    lf_material_bsdf(lf_materials_get(m, 0), &c, &b);
    CHECK(b.kind == LF_LOBE_CONDUCTOR && lf_bsdf_is_specular(&b));
    CHECK(b.u.conductor.k.x > 2.f && b.u.conductor.eta.x < 0.5f);
    /* "reflectance": eta 1, k such that the normal-incidence reflectance is r. */
    lf_material_bsdf(lf_materials_get(m, 1), &c, &b);
    CHECK_NEAR(lf_fresnel_conductor(1.f, b.u.conductor.eta.x, b.u.conductor.k.x), 0.8, 1e-5);
    CHECK_NEAR(lf_fresnel_conductor(1.f, b.u.conductor.eta.z, b.u.conductor.k.z), 0.2, 1e-5);
    CHECK_NEAR(b.u.conductor.mf.alpha_x, 0.2, 1e-6); /* remapped: sqrt(0.04) */
    lf_material_bsdf(lf_materials_get(m, 2), &c, &b);
    CHECK_NEAR(b.u.conductor.mf.alpha_x, 0.04, 1e-7);
    CHECK_NEAR(b.u.conductor.mf.alpha_y, 0.09, 1e-7);
    /* Named glass at 550 nm; mix picks "glass" (materials[1]) with probability 0.3. */
    lf_material_bsdf(lf_materials_get(m, 4), &c, &b);
    CHECK(b.kind == LF_LOBE_DIELECTRIC);
    CHECK_NEAR(b.u.dielectric.eta, lf_named_glass_eta("glass-BK7", 550.f), 1e-6);
    CHECK_NEAR(b.u.dielectric.eta, 1.5185, 5e-4);
    const lf_material *mix = lf_materials_get(m, 5);
    CHECK(strcmp(lf_material_type(mix), "mix") == 0);
    CHECK(lf_material_resolve(mix, &c, 0.1f) == lf_materials_get(m, 4));
    CHECK(lf_material_resolve(mix, &c, 0.5f) == lf_materials_get(m, 3));
    int n_glass = 0, N = 20000;
    for (int i = 0; i < N; i++) {
        lf_shading_ctx ci = ctx_uv(0, 0);
        ci.p = lf_v3(0.001f * (float)i, 0.37f, -2.f);
        lf_material_bsdf(mix, &ci, &b);
        n_glass += b.kind == LF_LOBE_DIELECTRIC;
    }
    /* Binomial: 3 sigma of 0.3 over 20000 hashed positions is 0.0098. */
    CHECK_NEAR((double)n_glass / N, 0.3, 0.0098);
    lf_material_bsdf(lf_materials_get(m, 6), &c, &b);
    CHECK_NEAR(b.u.dielectric.eta, 1.33, 1e-6);
    CHECK_NEAR(b.u.dielectric.mf.alpha_x, 0.5, 1e-6);
    lf_material_bsdf(lf_materials_get(m, 7), &c, &b);
    CHECK(b.kind == LF_LOBE_THIN_DIELECTRIC && b.u.thin.eta == 1.5f);
    lf_material_bsdf(lf_materials_get(m, 8), &c, &b);
    CHECK(b.kind == LF_LOBE_COATED_DIFFUSE && b.u.coated.eta == 1.5f);
    CHECK_NEAR(b.u.coated.thickness, 0.01, 1e-7);
    CHECK_NEAR(b.u.coated.r.y, 0.4, 1e-6);
    lf_material_bsdf(lf_materials_get(m, 9), &c, &b);
    CHECK(b.kind == LF_LOBE_COATED_CONDUCTOR);
    CHECK_NEAR(b.u.coated.coat.alpha_x, 0.2, 1e-6);
    CHECK_NEAR(b.u.coated.base.alpha_x, 0.5, 1e-6);
    lf_material_bsdf(lf_materials_get(m, 10), &c, &b);
    CHECK(b.kind == LF_LOBE_DIFFUSE_TRANSMISSION);
    CHECK_NEAR(b.u.diffuse_transmission.r.x, 0.5, 1e-6);
    CHECK_NEAR(b.u.diffuse_transmission.t.y, 0.5, 1e-6);
    CHECK(lf_material_is_interface(lf_materials_get(m, 11)));
    CHECK(lf_material_is_interface(lf_materials_get(m, 12)));
    CHECK(!lf_material_is_interface(lf_materials_get(m, 0)));
    lf_material_bsdf(lf_materials_get(m, 15), &c, &b);
    CHECK_NEAR(b.u.dielectric.eta, 1.525, 1e-5); /* interpolated at 550 nm */

    /* Warnings: g (line 18) only: "displacement" is a bump map, an empty
     * "normalmap" means none (as in pbrt-v4; maps themselves are tested in
     * test_render_normalmap); the default thickness and maxdepth warn about
     * nothing. */
    const char *w = lf_materials_warnings(m);
    CHECK(w != NULL);
    if (w) {
        CHECK_MSG(strstr(w, "scene.pbrt:18:") && strstr(w, "\"g\""), "%s", w);
        CHECK_MSG(!strstr(w, "scene.pbrt:19:") && !strstr(w, "displacement"), "%s", w);
        CHECK_MSG(!strstr(w, "normalmap"), "%s", w);
        CHECK_MSG(strstr(w, "warning:"), "%s", w);
        CHECK_MSG(!strstr(w, "scene.pbrt:13:"), "%s", w);
    }
    lf_materials_free(m);
    lf_scene_desc_free(&d);
}

static void test_glasses(void)
{
    /* Catalogue n_d (587.56 nm) values from Schott's data sheets. */
    struct {
        const char *name;
        double nd;
    } g[] = {{"glass-BK7", 1.5168}, {"glass-BAF10", 1.6700}, {"glass-FK51A", 1.4866}, {"glass-LASF9", 1.8503},
             {"glass-F5", 1.6727},  {"glass-F10", 1.7283},   {"glass-F11", 1.7847}};
    for (size_t i = 0; i < sizeof g / sizeof g[0]; i++)
        CHECK_NEAR(lf_named_glass_eta(g[i].name, 587.56f), g[i].nd, 5e-4);
    CHECK(lf_named_glass_eta("glass-XYZ", 550.f) == 0.f);
}

static void test_errors(void)
{
    expect_error("WorldBegin\n\nMaterial \"foo\"\n", 3, "unknown material \"foo\"");
    expect_error("WorldBegin\nMaterial \"diffuse\"\n  \"texture reflectance\" \"nope\"\n", 3, "\"nope\"");
    expect_error("WorldBegin\nMaterial \"conductor\" \"rgb roughness\" [0.1 0.1 0.1]\n", 2, "roughness");
    expect_error("WorldBegin\nMaterial \"diffuse\" \"float roughnes\" [0.1]\n", 2, "roughnes");
    expect_error("WorldBegin\nTexture \"t\" \"spectrum\" \"constant\" \"rgb value\" [1 1 1]\n"
                 "Material \"conductor\" \"texture roughness\" \"t\"\n",
                 3, "float texture \"t\"");
    expect_error("WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n"
                 "Material \"mix\" \"string materials\" [\"a\" \"b\"]\n",
                 3, "\"b\" is not defined");
    expect_error("WorldBegin\nMaterial \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"spectrum eta\" \"metal-Au-eta\"\n",
                 2, "not both");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"ptex\"\n", 2, "not supported");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"imagemap\" \"string filename\" \"missing.exr\"\n", 2,
                 "missing.exr");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"checkerboard\" \"string mapping\" \"uvw\"\n", 2, "uvw");
    expect_error("WorldBegin\nTexture \"t\" \"float\" \"scale\" \"texture tex\" \"later\"\n"
                 "Texture \"later\" \"float\" \"constant\"\n",
                 2, "\"later\"");
    expect_error("WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"mix\" \"string materials\" [\"a\" \"a\"]\n", 2,
                 "contains itself");
}

int main(void)
{
    int images = write_test_images();
    CHECK_MSG(images == 0, "could not write test images under %s", DIR);
    if (images == 0)
        test_textures();
    test_materials();
    test_glasses();
    test_errors();
    return lf_test_end();
}
