/* The pbrt-v4 scene parser (scenefile/parser.c): every directive, and the
 * messages for malformed input.  Expected matrices are worked out by hand in
 * the comments. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lf_test.h"
#include "scenefile/lf_scene_desc.h"

static int parse(const char *text, lf_scene_desc *d, lf_error *err)
{
    lf_error_clear(err);
    return lf_scene_parse_string(text, "test.pbrt", d, err);
}

/* Parses text that must be valid; failures print the message. */
static int parse_ok(const char *text, lf_scene_desc *d)
{
    lf_error err = {0};
    int rc = parse(text, d, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    return rc == LF_OK;
}

/* Parses text that must fail with `code` and a message containing `want`. */
static void parse_fails(const char *text, int code, const char *want)
{
    lf_scene_desc d;
    lf_error err = {0};
    int rc = parse(text, &d, &err);
    CHECK_MSG(rc == code, "rc %d (want %d) for: %s -> %s", rc, code, text, err.msg);
    CHECK_MSG(strstr(err.msg, want) != NULL, "message \"%s\" lacks \"%s\"", err.msg, want);
    /* On failure *out holds nothing. */
    CHECK(d.shapes == NULL && d.n_shapes == 0 && d.strings == NULL && d.warnings == NULL && d.camera.e.type == NULL);
}

static int mat_near(const double m[4][4], const double want[4][4], double tol)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            if (fabs(m[r][c] - want[r][c]) > tol)
                return 0;
    return 1;
}

static void print_mat(const double m[4][4])
{
    for (int r = 0; r < 4; r++)
        fprintf(stderr, "  %g %g %g %g\n", m[r][0], m[r][1], m[r][2], m[r][3]);
}

#define CHECK_MAT(m, ...)                                  \
    do {                                                   \
        const double want_[4][4] = __VA_ARGS__;            \
        int ok_ = mat_near((m), want_, 1e-9);              \
        CHECK(ok_);                                        \
        if (!ok_)                                          \
            print_mat(m);                                  \
    } while (0)

#define IDENTITY {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}

static lf_dvec3 xp(const lf_transform *t, double x, double y, double z)
{
    lf_dvec3 p = {x, y, z};
    return lf_xform_point_d(t, p);
}

static lf_dvec3 xv(const lf_transform *t, double x, double y, double z)
{
    lf_dvec3 v = {x, y, z};
    return lf_xform_vector_d(t, v);
}

#define CHECK_VEC(v, X, Y, Z)          \
    do {                               \
        lf_dvec3 v_ = (v);             \
        CHECK_NEAR(v_.x, (X), 1e-9);   \
        CHECK_NEAR(v_.y, (Y), 1e-9);   \
        CHECK_NEAR(v_.z, (Z), 1e-9);   \
    } while (0)

static void test_transforms(void)
{
    lf_scene_desc d;
    /* Translate then Scale: CTM = T(1,2,3) * S(2,2,2), whose upper 3x4 is
     * [2 0 0 1; 0 2 0 2; 0 0 2 3]; (1,1,1) -> (3,4,5). */
    if (parse_ok("WorldBegin\nTranslate 1 2 3\nScale 2 2 2\nShape \"sphere\"\n", &d)) {
        CHECK(d.n_shapes == 1);
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].m, {{2, 0, 0, 1}, {0, 2, 0, 2}, {0, 0, 2, 3}, {0, 0, 0, 1}});
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].inv,
                  {{0.5, 0, 0, -0.5}, {0, 0.5, 0, -1}, {0, 0, 0.5, -1.5}, {0, 0, 0, 1}});
        CHECK_VEC(xp(&d.shapes[0].object_to_world.xf[0], 1, 1, 1), 3, 4, 5);
        CHECK(d.shapes[0].object_to_world.animated == 0);
        CHECK(d.shapes[0].material == -1 && d.shapes[0].area_light == -1 && d.shapes[0].object == -1);
        CHECK(strcmp(d.shapes[0].e.type, "sphere") == 0);
        CHECK(d.shapes[0].e.loc.line == 4 && d.shapes[0].e.loc.col == 1);
        CHECK(strcmp(d.shapes[0].e.loc.file, "test.pbrt") == 0);
        CHECK(strcmp(d.shapes[0].base_dir, ".") == 0);
        CHECK(d.camera.e.type == NULL); /* no Camera directive */
        CHECK(d.film.type == NULL && d.sampler.type == NULL);
        CHECK(d.transform_start_time == 0 && d.transform_end_time == 1);
        lf_scene_desc_free(&d);
        CHECK(d.shapes == NULL && d.n_shapes == 0);
    }

    /* Scale then Translate composes the other way: S(2) * T(1,2,3). */
    if (parse_ok("WorldBegin Scale 2 2 2 Translate 1 2 3 Shape \"sphere\"", &d)) {
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].m, {{2, 0, 0, 2}, {0, 2, 0, 4}, {0, 0, 2, 6}, {0, 0, 0, 1}});
        lf_scene_desc_free(&d);
    }

    /* pbrt lists matrices column-major: the translation is elements 13-15. */
    if (parse_ok("WorldBegin\nConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nShape \"sphere\"\n"
                 "Translate 1 0 0 ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 5 6 7 1] Shape \"sphere\"\n"
                 "Transform [2 0 0 0 0 3 0 0 0 0 4 0 1 1 1 1] Shape \"sphere\"\n"
                 "Identity Shape \"sphere\"\n"
                 "Transform 1 0 0 0 0 1 0 0 0 0 1 0 -1 -2 -3 1 Shape \"sphere\"\n",
                 &d)) {
        CHECK(d.n_shapes == 5);
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].m, {{1, 0, 0, 5}, {0, 1, 0, 6}, {0, 0, 1, 7}, {0, 0, 0, 1}});
        /* ConcatTransform post-multiplies: T(5,6,7) * T(1,0,0) * T(5,6,7). */
        CHECK_MAT(d.shapes[1].object_to_world.xf[0].m, {{1, 0, 0, 11}, {0, 1, 0, 12}, {0, 0, 1, 14}, {0, 0, 0, 1}});
        /* Transform replaces the CTM. */
        CHECK_MAT(d.shapes[2].object_to_world.xf[0].m, {{2, 0, 0, 1}, {0, 3, 0, 1}, {0, 0, 4, 1}, {0, 0, 0, 1}});
        CHECK_MAT(d.shapes[3].object_to_world.xf[0].m, IDENTITY);
        /* Brackets are optional. */
        CHECK_MAT(d.shapes[4].object_to_world.xf[0].m, {{1, 0, 0, -1}, {0, 1, 0, -2}, {0, 0, 1, -3}, {0, 0, 0, 1}});
        lf_scene_desc_free(&d);
    }

    /* Rotate 90 about z maps x to y and y to -x. */
    if (parse_ok("WorldBegin Rotate 90 0 0 1 Shape \"sphere\"", &d)) {
        CHECK_VEC(xv(&d.shapes[0].object_to_world.xf[0], 1, 0, 0), 0, 1, 0);
        CHECK_VEC(xv(&d.shapes[0].object_to_world.xf[0], 0, 1, 0), -1, 0, 0);
        lf_scene_desc_free(&d);
    }

    /* LookAt from (0,0,5) to the origin, up +y.  pbrt is left-handed: the
     * camera looks down its +z, so world origin is at camera (0,0,5) and
     * world +x is camera -x. */
    if (parse_ok("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\n", &d)) {
        const lf_transform *w2c = &d.camera.world_to_camera.xf[0];
        CHECK(strcmp(d.camera.e.type, "perspective") == 0);
        CHECK_VEC(xp(w2c, 0, 0, 0), 0, 0, 5);
        CHECK_VEC(xp(w2c, 0, 0, 5), 0, 0, 0);
        CHECK_VEC(xv(w2c, 1, 0, 0), -1, 0, 0);
        CHECK_VEC(xv(w2c, 0, 1, 0), 0, 1, 0);
        CHECK(d.camera.world_to_camera.animated == 0);
        CHECK_NEAR(lf_params_float(&d.camera.e.params, "fov", 90), 45, 0);
        CHECK(d.camera.e.loc.line == 2 && d.camera.e.loc.col == 1);
        lf_scene_desc_free(&d);
    }

    /* Pre-world transforms are reset by WorldBegin. */
    if (parse_ok("Translate 1 2 3 WorldBegin Shape \"sphere\"", &d)) {
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].m, IDENTITY);
        lf_scene_desc_free(&d);
    }
}

static void test_camera_coordsys(void)
{
    lf_scene_desc d;
    /* CoordSysTransform "camera" puts the CTM at the camera: camera-to-world,
     * which maps the camera origin to the eye (1,2,3). */
    if (parse_ok("LookAt 1 2 3  1 2 4  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                 "Translate 10 0 0\nCoordinateSystem \"moved\"\n"
                 "AttributeBegin CoordSysTransform \"camera\" Shape \"disk\" AttributeEnd\n"
                 "Identity CoordSysTransform \"moved\" Shape \"sphere\"\n"
                 "CoordSysTransform \"world\" Shape \"sphere\"\n"
                 "CoordSysTransform \"nosuch\"\n",
                 &d)) {
        CHECK(d.n_shapes == 3);
        const lf_transform *c2w = &d.shapes[0].object_to_world.xf[0];
        CHECK_VEC(xp(c2w, 0, 0, 0), 1, 2, 3);
        CHECK_VEC(xv(c2w, 0, 0, 1), 0, 0, 1); /* looks down world +z */
        lf_transform prod = lf_transform_compose(&d.camera.world_to_camera.xf[0], c2w);
        CHECK(mat_near(prod.m, (const double[4][4])IDENTITY, 1e-9));
        CHECK_MAT(d.shapes[1].object_to_world.xf[0].m, {{1, 0, 0, 10}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}});
        CHECK_MAT(d.shapes[2].object_to_world.xf[0].m, IDENTITY);
        CHECK_MSG(d.warnings && strstr(d.warnings, "test.pbrt:9:19: warning: couldn't find named coordinate system "
                                                   "\"nosuch\""),
                  "%s", d.warnings ? d.warnings : "(none)");
        lf_scene_desc_free(&d);
    }
}

static void test_attributes(void)
{
    lf_scene_desc d;
    /* AttributeEnd restores the CTM, the material and reverse orientation. */
    if (parse_ok("WorldBegin\nMaterial \"diffuse\"\nAttributeBegin\n  Translate 0 0 1\n  Material \"conductor\"\n"
                 "  ReverseOrientation\n  Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n",
                 &d)) {
        CHECK(d.n_materials == 2 && d.n_shapes == 2);
        CHECK(strcmp(d.materials[0].e.type, "diffuse") == 0 && d.materials[0].name == NULL);
        CHECK(strcmp(d.materials[1].e.type, "conductor") == 0);
        CHECK(d.shapes[0].material == 1 && d.shapes[0].reverse_orientation == 1);
        CHECK_VEC(xp(&d.shapes[0].object_to_world.xf[0], 0, 0, 0), 0, 0, 1);
        CHECK(d.shapes[1].material == 0 && d.shapes[1].reverse_orientation == 0);
        CHECK_MAT(d.shapes[1].object_to_world.xf[0].m, IDENTITY);
        lf_scene_desc_free(&d);
    }

    /* An area light attaches to the shapes of its block only. */
    if (parse_ok("WorldBegin\nShape \"sphere\"\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n"
                 "Shape \"disk\"\nShape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n",
                 &d)) {
        CHECK(d.n_area_lights == 1 && d.n_shapes == 4);
        CHECK(strcmp(d.area_lights[0].type, "diffuse") == 0);
        CHECK(d.area_lights[0].loc.line == 4);
        lf_vec3 L;
        CHECK(lf_params_rgb(&d.area_lights[0].params, "L", LF_SPECTRUM_ILLUMINANT, lf_v3(0, 0, 0), &L) == 1);
        CHECK(L.x == 4.f && L.y == 4.f && L.z == 4.f);
        CHECK(d.shapes[0].area_light == -1);
        CHECK(d.shapes[1].area_light == 0 && d.shapes[2].area_light == 0);
        CHECK(d.shapes[3].area_light == -1);
        lf_scene_desc_free(&d);
    }

    /* Attribute defaults: merged into following shapes, overridden by the
     * shape's own value, gone after AttributeEnd, never "unused". */
    if (parse_ok("WorldBegin\nAttributeBegin\nAttribute \"shape\" \"float radius\" 2 \"float alpha\" 1\n"
                 "Attribute \"shape\" \"float radius\" 5\n"
                 "Shape \"sphere\"\nShape \"sphere\" \"float radius\" 3\nShape \"disk\"\n"
                 "Attribute \"light\" \"float scale\" 7\nLightSource \"point\"\n"
                 "Attribute \"material\" \"float roughness\" 0.1\nMaterial \"conductor\"\n"
                 "Attribute \"texture\" \"float uscale\" 4\nTexture \"t\" \"float\" \"checkerboard\"\n"
                 "AttributeEnd\nShape \"sphere\"\n",
                 &d)) {
        CHECK(d.n_shapes == 4);
        CHECK_NEAR(lf_params_float(&d.shapes[0].e.params, "radius", 1), 5, 0); /* later Attribute wins */
        CHECK_NEAR(lf_params_float(&d.shapes[1].e.params, "radius", 1), 3, 0);
        CHECK_NEAR(lf_params_float(&d.shapes[0].e.params, "alpha", 0), 1, 0);
        lf_error err = {0};
        CHECK(lf_params_finish(&d.shapes[2].e.params, "Shape \"disk\"", &err) == LF_OK);
        CHECK(lf_params_peek(&d.shapes[3].e.params, "radius") == NULL);
        CHECK_NEAR(lf_params_float(&d.lights[0].e.params, "scale", 1), 7, 0);
        CHECK_NEAR(lf_params_float(&d.materials[0].e.params, "roughness", 0), 0.1, 0);
        CHECK_NEAR(lf_params_float(&d.textures[0].e.params, "uscale", 0), 4, 0);
        lf_scene_desc_free(&d);
    }

    /* TransformBegin/End (deprecated) restore only the CTM. */
    if (parse_ok("WorldBegin\nTransformBegin\nTranslate 1 0 0\nMaterial \"diffuse\"\nTransformEnd\nShape \"sphere\"\n",
                 &d)) {
        CHECK_MAT(d.shapes[0].object_to_world.xf[0].m, IDENTITY);
        CHECK(d.shapes[0].material == 0);
        CHECK_MSG(d.warnings && strstr(d.warnings, "test.pbrt:2:1: warning: TransformBegin/End are deprecated"), "%s",
                  d.warnings ? d.warnings : "(none)");
        lf_scene_desc_free(&d);
    }

    /* An unclosed AttributeBegin is only a warning. */
    if (parse_ok("WorldBegin\nAttributeBegin\nShape \"sphere\"\n", &d)) {
        CHECK(d.n_shapes == 1);
        CHECK_MSG(d.warnings && strstr(d.warnings, "test.pbrt:2:1: warning: AttributeBegin without AttributeEnd"),
                  "%s", d.warnings ? d.warnings : "(none)");
        lf_scene_desc_free(&d);
    }
}

static void test_materials_textures(void)
{
    lf_scene_desc d;
    if (parse_ok("WorldBegin\n"
                 "MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0.1 0.1]\n"
                 "MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\"\n"
                 "NamedMaterial \"gold\"\nShape \"sphere\"\n"
                 "NamedMaterial \"red\"\nShape \"sphere\"\n"
                 "Material \"dielectric\"\nShape \"sphere\"\n"
                 "NamedMaterial \"later\"\nShape \"sphere\"\n"
                 "MakeNamedMaterial \"later\" \"string type\" \"coateddiffuse\"\n",
                 &d)) {
        CHECK(d.n_materials == 4 && d.n_shapes == 4);
        CHECK(strcmp(d.materials[1].name, "gold") == 0 && strcmp(d.materials[1].e.type, "conductor") == 0);
        CHECK(lf_params_peek(&d.materials[1].e.params, "type") == NULL); /* moved to e.type */
        CHECK(d.materials[1].e.params.count == 1);
        CHECK(d.shapes[0].material == 1);
        CHECK(d.shapes[1].material == 0);
        CHECK(d.shapes[2].material == 2 && d.materials[2].name == NULL);
        CHECK(d.shapes[3].material == 3 && strcmp(d.materials[3].name, "later") == 0);
        lf_vec3 eta;
        CHECK(lf_params_rgb(&d.materials[1].e.params, "eta", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &eta) == 1);
        CHECK_NEAR(eta.z, 1.442, 1e-3);
        lf_scene_desc_free(&d);
    }

    if (parse_ok("WorldBegin\nTranslate 0 0 2\n"
                 "Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"rgb tex1\" [1 0 0]\n"
                 "Texture \"checks\" \"float\" \"imagemap\" \"string filename\" \"a.png\"\n",
                 &d)) {
        CHECK(d.n_textures == 2);
        CHECK(strcmp(d.textures[0].name, "checks") == 0 && d.textures[0].is_float == 0);
        CHECK(strcmp(d.textures[0].e.type, "checkerboard") == 0);
        CHECK(d.textures[1].is_float == 1 && strcmp(d.textures[1].e.type, "imagemap") == 0);
        CHECK_VEC(xp(&d.textures[0].object_to_world, 0, 0, 0), 0, 0, 2);
        CHECK(d.textures[0].e.loc.line == 3);
        lf_scene_desc_free(&d);
    }
}

static void test_lights_options(void)
{
    lf_scene_desc d;
    if (parse_ok("Film \"rgb\" \"integer xresolution\" 320 \"string filename\" \"o.exr\"\n"
                 "Sampler \"halton\" \"integer pixelsamples\" 16\nIntegrator \"path\" \"integer maxdepth\" 5\n"
                 "PixelFilter \"gaussian\"\nAccelerator \"bvh\"\nColorSpace \"srgb\"\n"
                 "Option \"bool disablepixeljitter\" true\n"
                 "WorldBegin\nAttributeBegin\nTranslate 1 2 3\nReverseOrientation\n"
                 "LightSource \"point\" \"blackbody I\" 3000\nAttributeEnd\n"
                 "LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3]\n"
                 "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"\"\n"
                 "MediumInterface \"fog\"\nShape \"sphere\"\nWorldEnd\n",
                 &d)) {
        CHECK(strcmp(d.film.type, "rgb") == 0 && lf_params_int(&d.film.params, "xresolution", 0) == 320);
        CHECK(strcmp(d.sampler.type, "halton") == 0 && lf_params_int(&d.sampler.params, "pixelsamples", 0) == 16);
        CHECK(strcmp(d.integrator.type, "path") == 0);
        CHECK(strcmp(d.filter.type, "gaussian") == 0 && strcmp(d.accelerator.type, "bvh") == 0);
        CHECK(d.n_lights == 2);
        CHECK(strcmp(d.lights[0].e.type, "point") == 0);
        CHECK_VEC(xp(&d.lights[0].light_to_world.xf[0], 0, 0, 0), 1, 2, 3);
        CHECK(d.lights[0].reverse_orientation == 1 && d.lights[1].reverse_orientation == 0);
        CHECK_MAT(d.lights[1].light_to_world.xf[0].m, IDENTITY);
        const lf_param *bb = lf_params_peek(&d.lights[0].e.params, "I");
        CHECK(bb && bb->type == LF_PT_BLACKBODY && bb->n_nums == 1 && bb->nums[0] == 3000);
        const char *w = d.warnings ? d.warnings : "";
        CHECK_MSG(strstr(w, "test.pbrt:6:1: warning: ColorSpace \"srgb\" ignored"), "%s", w);
        CHECK_MSG(strstr(w, "test.pbrt:7:1: warning: Option \"disablepixeljitter\" ignored"), "%s", w);
        /* media are kept: MediumInterface with one name sets both sides */
        CHECK(d.n_media == 1 && !strcmp(d.media[0].name, "fog") && d.media[0].e.loc.line == 15);
        CHECK(!strcmp(lf_params_string(&d.media[0].e.params, "type", ""), "homogeneous"));
        CHECK(d.n_shapes == 1 && d.shapes[0].medium_inside && !strcmp(d.shapes[0].medium_inside, "fog") &&
              !strcmp(d.shapes[0].medium_outside, "fog"));
        CHECK(d.camera.medium == NULL);
        CHECK_MSG(strstr(w, "test.pbrt:19:1: warning: WorldEnd"), "%s", w);
        lf_scene_desc_free(&d);
    }
    /* Attribute "medium" gives MakeNamedMedium defaults; a MediumInterface
     * before Camera is the camera's medium (its exterior name) */
    if (parse_ok("MakeNamedMedium \"air\" \"string type\" \"homogeneous\"\n"
                 "MediumInterface \"\" \"air\"\nCamera \"perspective\"\nWorldBegin\n"
                 "AttributeBegin\nAttribute \"medium\" \"float g\" 0.3\n"
                 "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"air\"\n"
                 "Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n",
                 &d)) {
        CHECK(d.camera.medium && !strcmp(d.camera.medium, "air"));
        CHECK(d.n_media == 2 && lf_params_float(&d.media[1].e.params, "g", 0) == 0.3);
        CHECK(lf_params_float(&d.media[0].e.params, "g", 0) == 0);
        CHECK(d.n_shapes == 2 && !strcmp(d.shapes[0].medium_inside, "fog") &&
              !strcmp(d.shapes[0].medium_outside, "air"));
        /* AttributeEnd restores the interface in effect before (camera's) */
        CHECK(d.shapes[1].medium_inside && !strcmp(d.shapes[1].medium_inside, "") &&
              !strcmp(d.shapes[1].medium_outside, "air"));
        lf_scene_desc_free(&d);
    }
}

static void test_motion(void)
{
    lf_scene_desc d;
    /* ActiveTransform EndTime changes only the second CTM. */
    if (parse_ok("TransformTimes 0 2\nWorldBegin\nTranslate 0 1 0\nActiveTransform EndTime\nTranslate 1 0 0\n"
                 "ActiveTransform All\nShape \"sphere\"\nActiveTransform StartTime\nScale 2 2 2\n"
                 "ActiveTransform All\nShape \"sphere\"\nObjectBegin \"o\"\nObjectEnd\nObjectInstance \"o\"\n",
                 &d)) {
        const lf_anim_xform *a = &d.shapes[0].object_to_world;
        CHECK_MAT(a->xf[0].m, {{1, 0, 0, 0}, {0, 1, 0, 1}, {0, 0, 1, 0}, {0, 0, 0, 1}});
        CHECK_MAT(a->xf[1].m, {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 0}, {0, 0, 0, 1}});
        CHECK(a->animated == 1);
        CHECK(a->time[0] == 0 && a->time[1] == 2);
        CHECK(d.transform_start_time == 0 && d.transform_end_time == 2);
        const lf_anim_xform *b = &d.shapes[1].object_to_world;
        CHECK_MAT(b->xf[0].m, {{2, 0, 0, 0}, {0, 2, 0, 1}, {0, 0, 2, 0}, {0, 0, 0, 1}});
        CHECK_MAT(b->xf[1].m, {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 0}, {0, 0, 0, 1}});
        CHECK(d.instances[0].instance_to_world.animated == 1);
        lf_scene_desc_free(&d);
    }
    /* The active flags are part of the attribute state. */
    if (parse_ok("WorldBegin AttributeBegin ActiveTransform StartTime AttributeEnd Translate 1 0 0 Shape \"disk\"",
                 &d)) {
        CHECK(d.shapes[0].object_to_world.animated == 0);
        CHECK_VEC(xp(&d.shapes[0].object_to_world.xf[1], 0, 0, 0), 1, 0, 0);
        lf_scene_desc_free(&d);
    }
}

static void test_objects(void)
{
    lf_scene_desc d;
    if (parse_ok("WorldBegin\nObjectInstance \"early\"\n"
                 "ObjectBegin \"tree\"\nShape \"sphere\"\nShape \"disk\"\nObjectEnd\n"
                 "ObjectBegin \"early\"\nShape \"sphere\"\nObjectEnd\n"
                 "Shape \"bilinearmesh\"\nTranslate 5 0 0\nObjectInstance \"tree\"\n",
                 &d)) {
        CHECK(d.n_objects == 2 && d.n_instances == 2 && d.n_shapes == 4);
        CHECK(strcmp(d.objects[0].name, "tree") == 0 && strcmp(d.objects[1].name, "early") == 0);
        CHECK(d.shapes[0].object == 0 && d.shapes[1].object == 0 && d.shapes[2].object == 1);
        CHECK(d.shapes[3].object == -1);
        CHECK(d.instances[0].object == 1); /* used before it was defined */
        CHECK(d.instances[1].object == 0);
        CHECK_VEC(xp(&d.instances[1].instance_to_world.xf[0], 0, 0, 0), 5, 0, 0);
        CHECK(d.instances[1].loc.line == 12 && d.instances[1].loc.col == 1);
        lf_scene_desc_free(&d);
    }
    /* ObjectBegin opens an attribute block: the CTM comes back at ObjectEnd. */
    if (parse_ok("WorldBegin ObjectBegin \"o\" Translate 1 1 1 Shape \"sphere\" ObjectEnd Shape \"sphere\"", &d)) {
        CHECK_VEC(xp(&d.shapes[0].object_to_world.xf[0], 0, 0, 0), 1, 1, 1);
        CHECK_MAT(d.shapes[1].object_to_world.xf[0].m, IDENTITY);
        lf_scene_desc_free(&d);
    }
}

static void test_values(void)
{
    lf_scene_desc d;
    if (parse_ok("# a comment line\nWorldBegin # trailing comment\n"
                 "Shape \"trianglemesh\" \"point P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n"
                 "  \"normal N\" [0 0 1 0 0 1 0 0 1] \"point2 uv\" [0 0 1 0 0 1]\n"
                 "  \"bool a\" true \"bool b\" \"false\" \"bool c\" [ false \"true\" ]\n"
                 "  \"float nums\" [+1 -.5 1e2 .25 -3E-1 7.]\n"
                 "  \"string s\" \"with \\\"quotes\\\" and \\\\\" \"color c2\" [.1 .2 .3]\n"
                 "  \"vector v\" [1 2 3] \"texture tex\" \"checks\" \"spectrum sp\" [400 0.5 700 0.5]\n"
                 "  \"float empty\" [ ]\n",
                 &d)) {
        lf_paramset *ps = &d.shapes[0].e.params;
        const lf_param *p = lf_params_peek(ps, "P");
        CHECK(p && p->type == LF_PT_POINT3 && p->n_nums == 9 && p->nums[3] == 1);
        p = lf_params_peek(ps, "indices");
        CHECK(p && p->type == LF_PT_INTEGER && p->n_nums == 3 && p->nums[2] == 2);
        CHECK(lf_params_peek(ps, "N")->type == LF_PT_NORMAL3);
        CHECK(lf_params_peek(ps, "uv")->type == LF_PT_POINT2);
        CHECK(lf_params_bool(ps, "a", 0) == 1 && lf_params_bool(ps, "b", 1) == 0);
        p = lf_params_peek(ps, "c");
        CHECK(p && p->n_bools == 2 && p->bools[0] == 0 && p->bools[1] == 1);
        size_t n;
        const double *v = lf_params_nums(ps, "nums", LF_PT_FLOAT, &n);
        CHECK(v && n == 6);
        if (v && n == 6) {
            CHECK(v[0] == 1 && v[1] == -0.5 && v[2] == 100 && v[3] == 0.25 && v[4] == -0.3 && v[5] == 7);
        }
        CHECK(strcmp(lf_params_string(ps, "s", ""), "with \"quotes\" and \\") == 0);
        CHECK(lf_params_peek(ps, "c2")->type == LF_PT_RGB);
        CHECK(lf_params_peek(ps, "v")->type == LF_PT_VECTOR3);
        p = lf_params_peek(ps, "tex");
        CHECK(p && p->type == LF_PT_TEXTURE && strcmp(p->strs[0], "checks") == 0);
        p = lf_params_peek(ps, "sp");
        CHECK(p && p->type == LF_PT_SPECTRUM && p->n_nums == 4);
        p = lf_params_peek(ps, "empty");
        CHECK(p && p->n_nums == 0);
        p = lf_params_peek(ps, "P");
        CHECK(p && p->loc.line == 3 && p->loc.col == 22);
        lf_scene_desc_free(&d);
    }
}

static char tmpdir[256];

static void write_file(const char *rel, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, rel);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(text, f);
    fclose(f);
}

static void test_include(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lf_parse_XXXXXX");
    CHECK(mkdtemp(tmpdir) != NULL);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/sub", tmpdir);
    CHECK(mkdir(sub, 0700) == 0);
    write_file("main.pbrt", "Camera \"perspective\"\nWorldBegin\nTranslate 1 0 0\nInclude \"sub/geom.pbrt\"\n"
                            "Shape \"sphere\"\nImport \"sub/more.pbrt\"\n");
    /* geom.pbrt includes inc2.pbrt relative to its own directory. */
    write_file("sub/geom.pbrt", "Translate 0 1 0\nShape \"plymesh\" \"string filename\" \"mesh.ply\"\n"
                                "Include \"inc2.pbrt\"\n");
    write_file("sub/inc2.pbrt", "Material \"diffuse\"\n");
    write_file("sub/more.pbrt", "Shape \"disk\"\n");
    write_file("sub/mesh.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                               "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    write_file("missing.pbrt", "WorldBegin\n\nShape \"sphere\"\n   Include \"nothere.pbrt\"\n");
    write_file("bad.pbrt", "WorldBegin\nInclude \"sub/broken.pbrt\"\n");
    write_file("sub/broken.pbrt", "Shape \"sphere\"\n\n  Shape \"sphere\" \"float radius\" [ 1\n");
    write_file("self.pbrt", "Include \"self.pbrt\"\n");

    char path[512];
    lf_scene_desc d;
    lf_error err = {0};
    snprintf(path, sizeof path, "%s/main.pbrt", tmpdir);
    int rc = lf_scene_parse_file(path, &d, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (rc == LF_OK) {
        CHECK(d.n_shapes == 3);
        /* The included file shares the graphics state: CTM and material
         * carry over in both directions, as if the text were pasted. */
        CHECK_VEC(xp(&d.shapes[0].object_to_world.xf[0], 0, 0, 0), 1, 1, 0);
        CHECK(d.shapes[1].material == 0);
        CHECK_VEC(xp(&d.shapes[1].object_to_world.xf[0], 0, 0, 0), 1, 1, 0);
        char want[600];
        snprintf(want, sizeof want, "%s/sub/geom.pbrt", tmpdir);
        CHECK_MSG(strcmp(d.shapes[0].e.loc.file, want) == 0, "%s", d.shapes[0].e.loc.file);
        CHECK(d.shapes[0].e.loc.line == 2);
        CHECK(strcmp(d.shapes[0].base_dir, sub) == 0);
        CHECK(strcmp(d.shapes[1].e.loc.file, path) == 0);
        CHECK(strcmp(d.shapes[2].e.type, "disk") == 0);
        /* The plymesh path resolves against base_dir. */
        char ply[600];
        snprintf(ply, sizeof ply, "%s/%s", d.shapes[0].base_dir, lf_params_string(&d.shapes[0].e.params, "filename", ""));
        lf_ply_mesh m;
        lf_error perr = {0};
        CHECK_MSG(lf_ply_read(ply, &m, &perr) == LF_OK, "%s", perr.msg);
        CHECK(m.n_vertices == 3 && m.n_triangles == 1);
        lf_ply_free(&m);
        lf_scene_desc_free(&d);
    }

    /* A missing include names the resolved path and the Include's location. */
    snprintf(path, sizeof path, "%s/missing.pbrt", tmpdir);
    rc = lf_scene_parse_file(path, &d, &err);
    CHECK(rc == LF_ERR_IO);
    char want[700];
    snprintf(want, sizeof want, "%s/missing.pbrt:4:4: cannot open included file \"%s/nothere.pbrt\"", tmpdir, tmpdir);
    CHECK_MSG(strstr(err.msg, want) != NULL, "%s", err.msg);
    CHECK(d.shapes == NULL && d.strings == NULL);

    /* Errors inside an included file name that file. */
    lf_error_clear(&err);
    snprintf(path, sizeof path, "%s/bad.pbrt", tmpdir);
    rc = lf_scene_parse_file(path, &d, &err);
    CHECK(rc == LF_ERR_PARSE);
    snprintf(want, sizeof want, "%s/sub/broken.pbrt:3:33: unclosed '['", tmpdir);
    CHECK_MSG(strstr(err.msg, want) != NULL, "%s", err.msg);

    lf_error_clear(&err);
    snprintf(path, sizeof path, "%s/self.pbrt", tmpdir);
    rc = lf_scene_parse_file(path, &d, &err);
    CHECK(rc == LF_ERR_PARSE);
    CHECK_MSG(strstr(err.msg, "nested more than") != NULL, "%s", err.msg);

    lf_error_clear(&err);
    snprintf(path, sizeof path, "%s/absent.pbrt", tmpdir);
    rc = lf_scene_parse_file(path, &d, &err);
    CHECK(rc == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, path) != NULL, "%s", err.msg);

    const char *files[] = {"main.pbrt", "missing.pbrt", "bad.pbrt", "self.pbrt", "sub/geom.pbrt", "sub/inc2.pbrt",
                           "sub/more.pbrt", "sub/mesh.ply", "sub/broken.pbrt"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", tmpdir, files[i]);
        unlink(path);
    }
    rmdir(sub);
    rmdir(tmpdir);
}

static void test_string_name_dir(void)
{
    /* parse_string: Include resolves against the directory of `name`. */
    lf_scene_desc d;
    lf_error err = {0};
    int rc = lf_scene_parse_string("WorldBegin\nShape \"plymesh\"\n", "scenes/demo/x.pbrt", &d, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (!rc) {
        CHECK(strcmp(d.shapes[0].base_dir, "scenes/demo") == 0);
        CHECK(strcmp(d.shapes[0].e.loc.file, "scenes/demo/x.pbrt") == 0);
        lf_scene_desc_free(&d);
    }
    rc = lf_scene_parse_string("WorldBegin\nInclude \"nope.pbrt\"", "scenes/demo/x.pbrt", &d, &err);
    CHECK(rc == LF_ERR_IO);
    CHECK_MSG(strstr(err.msg, "scenes/demo/x.pbrt:2:1: cannot open included file \"scenes/demo/nope.pbrt\""), "%s",
              err.msg);
}

static void test_errors(void)
{
    parse_fails("WorldBegin\nShape \"sphere", LF_ERR_PARSE, "test.pbrt:2:7: unterminated string");
    parse_fails("WorldBegin\nShape \"sph\nere\"", LF_ERR_PARSE, "test.pbrt:2:7: unterminated string");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\" [ 1", LF_ERR_PARSE,
                "test.pbrt:2:31: unclosed '[' in parameter \"float radius\"");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\" [ 1\nShape \"disk\"", LF_ERR_PARSE,
                "test.pbrt:3:1: expected a value or ']' to close the '[' at 2:31, got \"Shape\"");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\" [ 1 [ 2 ] ]", LF_ERR_PARSE,
                "test.pbrt:2:35: expected a value or ']'");
    parse_fails("WorldBegin\n]\n", LF_ERR_PARSE, "test.pbrt:2:1: expected a directive, got ']'");
    parse_fails("WorldBegin\n[ 1 ]\n", LF_ERR_PARSE, "test.pbrt:2:1: expected a directive, got '['");
    parse_fails("WorldBegin\nShape 3\n", LF_ERR_PARSE, "test.pbrt:2:7: Shape expects a quoted string");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\" \"big\"\n", LF_ERR_PARSE,
                "test.pbrt:2:31: parameter \"float radius\" expects numbers, got string \"big\"");
    parse_fails("WorldBegin\nShape \"plymesh\" \"string filename\" 3\n", LF_ERR_PARSE,
                "test.pbrt:2:35: parameter \"string filename\" expects a quoted string, got number 3");
    parse_fails("Translate 1 \"a\" 3\n", LF_ERR_PARSE, "test.pbrt:1:13: Translate expects 3 numbers, got string \"a\"");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\"", LF_ERR_PARSE,
                "test.pbrt:2:30: parameter \"float radius\" has no value: expected a value or '[', got end of file");
    parse_fails("WorldBegin\nShape \"sphere\" \"float radius\"\nShape \"disk\"", LF_ERR_PARSE,
                "test.pbrt:3:1: parameter \"float radius\" has no value");
    parse_fails("LookAt 0 0 5 0 0 0 0 1\nWorldBegin\n", LF_ERR_PARSE,
                "test.pbrt:2:1: LookAt expects 9 numbers, got \"WorldBegin\" after 8");
    parse_fails("LookAt 0 0 5 0 0 0", LF_ERR_PARSE, "test.pbrt:1:19: LookAt expects 9 numbers, got end of file");
    parse_fails("Translate 1 2\nWorldBegin", LF_ERR_PARSE, "test.pbrt:2:1: Translate expects 3 numbers");
    parse_fails("Scale 1 2", LF_ERR_PARSE, "Scale expects 3 numbers");
    parse_fails("Rotate 90 0 1", LF_ERR_PARSE, "Rotate expects 4 numbers");
    parse_fails("Transform [1 0 0 0 0 1 0 0 0 0 1 0]", LF_ERR_PARSE,
                "test.pbrt:1:35: Transform expects 16 numbers, got 12");
    parse_fails("ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 5]", LF_ERR_PARSE,
                "test.pbrt:1:50: ConcatTransform expects 16 numbers: expected ']'");
    parse_fails("LookAt 0 0 5 0 0 0 0 0 1", LF_ERR_PARSE, "test.pbrt:1:1: LookAt:");
    parse_fails("Camera \"perspective\" \"flot fov\" 45", LF_ERR_PARSE,
                "test.pbrt:1:22: unknown parameter type \"flot\" in \"flot fov\"");
    parse_fails("Camera \"perspective\" \"floatfov\" 45", LF_ERR_PARSE,
                "test.pbrt:1:22: malformed parameter declaration \"floatfov\"");
    parse_fails("Camera \"perspective\" \"float fov extra\" 45", LF_ERR_PARSE, "malformed parameter declaration");
    parse_fails("WorldBegin\nAttributeEnd\n", LF_ERR_PARSE,
                "test.pbrt:2:1: AttributeEnd without a matching AttributeBegin");
    parse_fails("WorldBegin\nTransformEnd\n", LF_ERR_PARSE, "test.pbrt:2:1: TransformEnd without a matching");
    parse_fails("WorldBegin\nAttributeBegin\nTransformEnd\n", LF_ERR_PARSE,
                "test.pbrt:3:1: mismatched nesting: TransformEnd closes the AttributeBegin at test.pbrt:2:1");
    parse_fails("WorldBegin\nObjectBegin \"o\"\nAttributeEnd\n", LF_ERR_PARSE,
                "test.pbrt:3:1: mismatched nesting: AttributeEnd closes the ObjectBegin");
    parse_fails("WorldBegin\n  Fooo 1 2\n", LF_ERR_PARSE, "test.pbrt:2:3: unknown directive \"Fooo\"");
    parse_fails("WorldBegin\nCamera \"perspective\"\n", LF_ERR_PARSE,
                "test.pbrt:2:1: Camera not allowed inside world block");
    parse_fails("WorldBegin\nFilm \"rgb\"\n", LF_ERR_PARSE, "test.pbrt:2:1: Film not allowed inside world block");
    parse_fails("WorldBegin\nSampler \"halton\"\n", LF_ERR_PARSE, "Sampler not allowed inside world block");
    parse_fails("WorldBegin\nIntegrator \"path\"\n", LF_ERR_PARSE, "Integrator not allowed inside world block");
    parse_fails("WorldBegin\nPixelFilter \"box\"\n", LF_ERR_PARSE, "PixelFilter not allowed inside world block");
    parse_fails("WorldBegin\nAccelerator \"bvh\"\n", LF_ERR_PARSE, "Accelerator not allowed inside world block");
    parse_fails("WorldBegin\nTransformTimes 0 1\n", LF_ERR_PARSE, "TransformTimes not allowed inside world block");
    parse_fails("WorldBegin\nWorldBegin\n", LF_ERR_PARSE, "test.pbrt:2:1: WorldBegin not allowed inside world block");
    parse_fails("Shape \"sphere\"\n", LF_ERR_PARSE, "test.pbrt:1:1: Shape not allowed before WorldBegin");
    parse_fails("Material \"diffuse\"\n", LF_ERR_PARSE, "Material not allowed before WorldBegin");
    parse_fails("LightSource \"point\"\n", LF_ERR_PARSE, "LightSource not allowed before WorldBegin");
    parse_fails("AttributeBegin\n", LF_ERR_PARSE, "AttributeBegin not allowed before WorldBegin");
    parse_fails("Import \"x.pbrt\"\n", LF_ERR_PARSE, "Import is only allowed inside the world block");
    parse_fails("Camera \"perspective\"\n", LF_ERR_PARSE, "test.pbrt:2:1: end of file before WorldBegin");
    parse_fails("Translate nan 0 0", LF_ERR_NUMERIC, "test.pbrt:1:11: non-finite number \"nan\"");
    parse_fails("Translate 1e999 0 0", LF_ERR_NUMERIC, "test.pbrt:1:11: non-finite number \"1e999\"");
    parse_fails("Translate -inf 0 0", LF_ERR_NUMERIC, "test.pbrt:1:11: non-finite number");
    parse_fails("WorldBegin Shape \"sphere\" \"float radius\" [ inf ]", LF_ERR_NUMERIC,
                "test.pbrt:1:44: non-finite number \"inf\"");
    parse_fails("Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 nan 1]", LF_ERR_NUMERIC, "non-finite number");
    parse_fails("Translate 1.2.3 0 0", LF_ERR_PARSE, "test.pbrt:1:11: invalid number \"1.2.3\"");
    parse_fails("WorldBegin\nNamedMaterial \"nosuch\"\nShape \"sphere\"\n", LF_ERR_PARSE,
                "test.pbrt:2:15: NamedMaterial \"nosuch\" is not defined");
    parse_fails("WorldBegin\nObjectInstance \"nosuch\"\n", LF_ERR_PARSE,
                "test.pbrt:2:16: ObjectInstance \"nosuch\": no such object");
    parse_fails("WorldBegin\nMakeNamedMaterial \"m\" \"rgb reflectance\" [1 1 1]\n", LF_ERR_PARSE,
                "test.pbrt:2:19: MakeNamedMaterial \"m\": needs a \"string type\" parameter");
    parse_fails("WorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n"
                "MakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n",
                LF_ERR_PARSE, "test.pbrt:3:19: named material \"m\" redefined (first defined at test.pbrt:2:1)");
    parse_fails("WorldBegin\nTexture \"t\" \"color\" \"constant\"\n", LF_ERR_PARSE,
                "test.pbrt:2:13: texture type \"color\" unknown");
    parse_fails("WorldBegin\nTexture \"t\" \"float\" \"constant\"\nTexture \"t\" \"float\" \"constant\"\n",
                LF_ERR_PARSE, "test.pbrt:3:9: float texture \"t\" redefined");
    parse_fails("WorldBegin\nObjectBegin \"a\"\nObjectBegin \"b\"\n", LF_ERR_PARSE,
                "test.pbrt:3:1: ObjectBegin \"b\" inside the definition of object \"a\"");
    parse_fails("WorldBegin\nObjectBegin \"a\"\nObjectEnd\nObjectBegin \"a\"\n", LF_ERR_PARSE,
                "test.pbrt:4:13: object \"a\" redefined");
    parse_fails("WorldBegin\nObjectEnd\n", LF_ERR_PARSE, "test.pbrt:2:1: ObjectEnd outside of an object definition");
    parse_fails("WorldBegin\nObjectBegin \"a\"\nObjectInstance \"a\"\n", LF_ERR_PARSE,
                "test.pbrt:3:1: ObjectInstance \"a\" inside the definition");
    parse_fails("WorldBegin\nShape \"sphere\" \"integer n\" 2.5\n", LF_ERR_PARSE,
                "test.pbrt:2:28: parameter \"integer n\" expects integers, got number 2.5");
    parse_fails("WorldBegin\nShape \"sphere\" \"bool b\" 1\n", LF_ERR_PARSE,
                "test.pbrt:2:25: parameter \"bool b\" expects true or false, got number 1");
    parse_fails("WorldBegin\nShape \"sphere\" \"bool b\" \"yes\"\n", LF_ERR_PARSE, "expects true or false");
    parse_fails("WorldBegin\nShape \"sphere\" \"float f\" true\n", LF_ERR_PARSE, "expects numbers, got \"true\"");
    parse_fails("WorldBegin\nShape \"sphere\" \"rgb c\" [1 1]\n", LF_ERR_PARSE,
                "test.pbrt:2:16: parameter \"rgb c\" needs 3 values, got 2");
    parse_fails("WorldBegin\nShape \"sphere\" \"point3 P\" [1 1 1 2]\n", LF_ERR_PARSE, "not a multiple of 3");
    parse_fails("WorldBegin\nShape \"sphere\" \"point2 uv\" [1 1 1]\n", LF_ERR_PARSE, "not a multiple of 2");
    parse_fails("WorldBegin\nLightSource \"point\" \"blackbody I\" [3000 1]\n", LF_ERR_PARSE, "needs 1 value");
    parse_fails("WorldBegin\nShape \"sphere\" \"spectrum s\" [400 1 500]\n", LF_ERR_PARSE, "(wavelength, value) pairs");
    parse_fails("WorldBegin\nShape \"sphere\" \"spectrum s\" [\"a\" \"b\"]\n", LF_ERR_PARSE,
                "(wavelength, value) pairs or one spectrum name");
    parse_fails("ActiveTransform Sometimes\n", LF_ERR_PARSE,
                "test.pbrt:1:17: ActiveTransform expects StartTime, EndTime or All, got \"Sometimes\"");
    parse_fails("WorldBegin\nAttribute \"camera\" \"float fov\" 3\n", LF_ERR_PARSE,
                "test.pbrt:2:11: unknown attribute target \"camera\"");
    parse_fails("WorldBegin\nShape \"a\\qb\"\n", LF_ERR_PARSE, "test.pbrt:2:7: unknown escape sequence");
    parse_fails("Option 3\n", LF_ERR_PARSE, "test.pbrt:1:8: Option expects a \"type name\" value pair");
    parse_fails("CoordinateSystem 3\n", LF_ERR_PARSE, "test.pbrt:1:18: CoordinateSystem expects a quoted string");
    parse_fails("\"WorldBegin\"\n", LF_ERR_PARSE, "test.pbrt:1:1: expected a directive, got string \"WorldBegin\"");
    parse_fails("3\n", LF_ERR_PARSE, "test.pbrt:1:1: expected a directive, got number 3");
}

/* A scene file in the repository, read with repo-relative paths (tests run
 * from the repo root). */
static void test_data_scene(void)
{
    lf_scene_desc d;
    lf_error err = {0};
    int rc = lf_scene_parse_file("tests/data/parse/scene.pbrt", &d, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (rc)
        return;
    CHECK(strcmp(d.camera.e.type, "perspective") == 0);
    CHECK_NEAR(lf_params_float(&d.camera.e.params, "fov", 90), 40, 0);
    /* Camera at (0,1,5) looking at the origin: the eye maps to the camera origin. */
    CHECK_VEC(xp(&d.camera.world_to_camera.xf[0], 0, 1, 5), 0, 0, 0);
    CHECK(lf_params_int(&d.film.params, "xresolution", 0) == 64);
    CHECK(strcmp(lf_params_string(&d.film.params, "filename", ""), "out/scene.exr") == 0);
    CHECK(d.n_lights == 1 && d.n_area_lights == 1 && d.n_materials == 1 && d.n_shapes == 2);
    const lf_shape_desc *quad = &d.shapes[0], *disk = &d.shapes[1];
    CHECK(strcmp(quad->e.type, "plymesh") == 0 && quad->material == 0 && quad->area_light == -1);
    CHECK(strcmp(quad->base_dir, "tests/data/parse/parts") == 0);
    CHECK(strcmp(quad->e.loc.file, "tests/data/parse/parts/quad.pbrt") == 0 && quad->e.loc.line == 3);
    CHECK_VEC(xp(&quad->object_to_world.xf[0], 1, 0, 1), 2, 0, 2);
    CHECK(disk->material == -1 && disk->area_light == 0);
    CHECK_VEC(xp(&disk->object_to_world.xf[0], 0, 0, 0), 0, 3, 0);
    lf_vec3 eta;
    CHECK(lf_params_rgb(&d.materials[0].e.params, "eta", LF_SPECTRUM_UNBOUNDED, lf_v3(0, 0, 0), &eta) == 1);
    CHECK_NEAR(eta.z, 1.094, 1e-3);
    CHECK(d.warnings == NULL);

    char ply[512];
    snprintf(ply, sizeof ply, "%s/%s", quad->base_dir, lf_params_string(&d.shapes[0].e.params, "filename", ""));
    lf_ply_mesh m;
    rc = lf_ply_read(ply, &m, &err);
    CHECK_MSG(rc == LF_OK, "%s", err.msg);
    if (!rc) {
        CHECK(m.n_vertices == 4 && m.n_triangles == 2 && m.uv && !m.N);
        CHECK(m.indices[3] == 0 && m.indices[4] == 2 && m.indices[5] == 3);
        CHECK(m.P[6] == 1.f && m.P[8] == 1.f && m.uv[5] == 1.f);
        lf_ply_free(&m);
    }
    /* Every parameter the builder would read, read: nothing unused. */
    CHECK(lf_params_finish(&d.shapes[0].e.params, "Shape \"plymesh\"", &err) == LF_OK);
    CHECK(lf_params_finish(&d.shapes[1].e.params, "Shape \"disk\"", &err) == LF_ERR_PARAM);
    CHECK_MSG(strstr(err.msg, "tests/data/parse/scene.pbrt:22:16: unused parameter \"float radius\" in Shape \"disk\""),
              "%s", err.msg);
    lf_scene_desc_free(&d);
}

/* Did you mean (issue 33): directives and types get the nearest known name;
 * a misspelt block keyword ends the parse with that one error. */
static void test_suggestions(void)
{
    parse_fails("WorldBegin\nShpae \"sphere\"\n", LF_ERR_PARSE,
                "test.pbrt:2:1: unknown directive \"Shpae\" (did you mean Shape?)");
    parse_fails("WorldBegin\nShape \"spere\"\n", LF_ERR_PARSE,
                "test.pbrt:2:1: Shape: unknown shape \"spere\" (did you mean \"sphere\"?)");
    parse_fails("WorldBegin\nLightSource \"spot_\"\n", LF_ERR_PARSE, "(did you mean \"spot\"?)");
    parse_fails("WorldBegin\nTexture \"t\" \"float\" \"imagemp\"\n", LF_ERR_PARSE,
                "(did you mean \"imagemap\"?)");
    const char *cascade[] = {"WorldBgin", "AttributeBgin", "AtributeEnd", "ObjectBegn"};
    for (int i = 0; i < 4; i++) {
        char text[512], *errors = NULL;
        /* with WorldBegin itself misspelt every world directive after it would be an error */
        snprintf(text, sizeof text,
                 "Camera \"perspective\"\n%s%s\nLightSource \"point\"\nShape \"sphere\"\n"
                 "Material \"diffuse\"\nAttributeEnd\nObjectEnd\nShape \"sphere\"\n", i ? "WorldBegin\n" : "",
                 cascade[i]);
        lf_scene_desc d;
        lf_error err = {0};
        int rc = lf_scene_parse_string_ex(text, "t.pbrt", NULL, &d, &err, &errors);
        int lines = 0;
        for (const char *c = errors; c && *c; c++)
            lines += *c == '\n';
        CHECK_MSG(rc == LF_ERR_PARSE && lines == 1 && strstr(errors, "stopped reading"), "%s: %s", cascade[i],
                  errors ? errors : err.msg);
        free(errors);
    }
    /* a misspelt word near no block keyword does not stop the parse */
    char *errors = NULL;
    lf_scene_desc d;
    lf_error err = {0};
    CHECK(lf_scene_parse_string_ex("WorldBegin\nShpae \"sphere\"\nFoo\n", "t.pbrt", NULL, &d, &err, &errors));
    CHECK_MSG(errors && strstr(errors, "t.pbrt:3:1: unknown directive \"Foo\"\n"), "%s", errors ? errors : "");
    free(errors);
}

int main(void)
{
    test_suggestions();
    test_transforms();
    test_camera_coordsys();
    test_attributes();
    test_materials_textures();
    test_lights_options();
    test_motion();
    test_objects();
    test_values();
    test_include();
    test_string_name_dir();
    test_errors();
    test_data_scene();
    return lf_test_end();
}
