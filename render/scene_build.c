/* Scene building: a scene description -> an lf_scene on Embree, in
 * stages: materials and media, shapes (render/shapes.c) placed by their
 * motion (render/motion.c), lights (render/lights.c); then the Embree scene
 * of meshes, analytic spheres (render/sphere_geometry.c) and rigidly moving
 * instances; its bounds; the light-selection distribution. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/lights.h"
#include "render/media.h"
#include "render/scene_build.h"

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

/* A triangle geometry for a mesh (one vertex buffer per keyframe over
 * Embree time 0..1 when it moves), attached with geomID id (or the next
 * free one for RTC_INVALID_GEOMETRY_ID). */
unsigned lf_attach_mesh(RTCDevice device, RTCScene scene, const lf_mesh *me, unsigned id)
{
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (me->n_keys > 1)
        rtcSetGeometryTimeStepCount(g, (unsigned)me->n_keys);
    for (int k = 0; k < me->n_keys; k++)
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, (unsigned)k, RTC_FORMAT_FLOAT3,
                                   me->P + (size_t)k * 3 * me->n_verts, 0, 3 * sizeof(float), (size_t)me->n_verts);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, me->idx, 0, 3 * sizeof(int),
                               (size_t)me->n_tris);
    lf_alpha_attach(g, me);
    rtcCommitGeometry(g);
    if (id == RTC_INVALID_GEOMETRY_ID)
        id = rtcAttachGeometry(scene, g);
    else
        rtcAttachGeometryByID(scene, g, id);
    rtcReleaseGeometry(g);
    return id;
}

/* Materials, media, every shape (instanced objects' shapes through their
 * instances) and the lights, as lf_scene data: no Embree yet. */
static int read_description(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    lf_scene_builder b = {s, d, 0, 0, 0, 0, 0, 0, err, -1, NULL, 1.f, NULL};
    b.object_proto = malloc(sizeof(int) * (d->n_objects ? d->n_objects : 1));
    if (!b.object_proto)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < d->n_objects; i++)
        b.object_proto[i] = -2;
    int rc = lf_materials_build(d, &s->materials, err);
    if (!rc)
        rc = lf_media_build(d, s, err);
    if (!rc)
        rc = lf_media_lookup(d, d->camera.medium, &d->camera.e.loc, "the camera's medium", &s->camera_medium, err);
    if (!rc)
        lf_warn_block(&s->warnings, lf_materials_warnings(s->materials));
    for (size_t i = 0; i < d->n_shapes && !rc; i++)
        if (d->shapes[i].object < 0) /* instantiated below */
            rc = lf_build_shape_moving(&b, &d->shapes[i], NULL);
    for (size_t k = 0; k < d->n_instances && !rc; k++)
        rc = lf_build_object_instance(&b, &d->instances[k]);
    free(b.object_proto);
    if (!rc)
        rc = lf_scene_build_lights(d, s, err);
    return rc;
}

/* Media cost only when a ray can enter one. */
static int reaches_media(const lf_scene *s)
{
    int has_media = s->camera_medium >= 0;
    for (int i = 0; i < s->n_meshes && !has_media; i++)
        has_media = s->meshes[i].medium_in != LF_MEDIUM_SAME;
    for (int i = 0; i < s->n_spheres && !has_media; i++)
        has_media = s->spheres[i].medium_in != LF_MEDIUM_SAME;
    return has_media;
}

/* The Embree device, the top-level scene and the table from its geometry
 * IDs to meshes, spheres and instances. */
static int new_embree_scene(lf_scene *s, lf_error *err)
{
    s->device = rtcNewDevice("verbose=0");
    if (!s->device)
        return lf_error_set(err, LF_ERR_INTERNAL, "cannot create the Embree device (error %d)",
                            (int)rtcGetDeviceError(NULL));
    rtcSetDeviceErrorFunction(s->device, rtc_error_cb, s);
    s->rtc = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    int n_moving_spheres = 0;
    for (int i = 0; i < s->n_spheres; i++)
        n_moving_spheres += s->spheres[i].n_keys > 1;
    s->n_geom = s->n_meshes + 1 + n_moving_spheres + s->n_instances + s->n_curves;
    s->geom_index = malloc(sizeof(int) * (size_t)s->n_geom);
    if (!s->geom_index)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    return 0;
}

/* The meshes in world space (static or keyframed), growing the bounds. */
static void attach_world_meshes(lf_scene *s, lf_vec3 *bmin, lf_vec3 *bmax)
{
    s->max_keys = 1;
    for (int m = 0; m < s->n_meshes; m++) {
        lf_mesh *me = &s->meshes[m];
        if (me->proto >= 0)
            continue; /* in its prototype's scene (lf_attach_instances) */
        unsigned id = lf_attach_mesh(s->device, s->rtc, me, RTC_INVALID_GEOMETRY_ID);
        s->geom_index[id] = m;
        if (me->n_keys > 1)
            s->moving_shapes++;
        if (me->n_keys > s->max_keys)
            s->max_keys = me->n_keys;
        for (size_t v = 0; v < (size_t)me->n_verts * me->n_keys; v++) {
            const float *p = me->P + 3 * v;
            *bmin = lf_v3(fminf(bmin->x, p[0]), fminf(bmin->y, p[1]), fminf(bmin->z, p[2]));
            *bmax = lf_v3(fmaxf(bmax->x, p[0]), fmaxf(bmax->y, p[1]), fmaxf(bmax->z, p[2]));
        }
    }
}

/* Builds the BVHs.  The error callback stays quiet (it may run on render
 * threads); what went wrong while building is an error here. */
static int commit_embree_scene(lf_scene *s, lf_error *err)
{
    rtcCommitScene(s->rtc);
    enum RTCError e = rtcGetDeviceError(s->device);
    if (e != RTC_ERROR_NONE)
        return lf_error_set(err, LF_ERR_INTERNAL, "Embree could not build the scene (error %d%s%s)", (int)e,
                            s->rtc_error_msg[0] ? ": " : "", s->rtc_error_msg);
    return 0;
}

static void set_bounds(lf_scene *s, lf_vec3 bmin, lf_vec3 bmax)
{
    if (bmin.x > bmax.x)
        bmin = bmax = lf_v3(0, 0, 0);
    s->bounds_min = bmin;
    s->bounds_max = bmax;
    s->scene_center = lf_scale(lf_add(bmin, bmax), 0.5f);
    s->scene_radius = fmaxf(lf_length(lf_sub(bmax, bmin)) * 0.5f, 1e-3f);
}

/* Light powers (infinite and distant lights need the scene radius for
 * theirs) and the distribution next-event estimation picks lights by. */
static int prepare_light_selection(lf_scene *s, lf_error *err)
{
    double *pw = malloc(sizeof(double) * (size_t)(s->n_lights ? s->n_lights : 1));
    if (!pw)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    s->nee_lights = malloc(sizeof(int) * (size_t)(s->n_lights ? s->n_lights : 1));
    if (!s->nee_lights) {
        free(pw);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
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
    return rc;
}

int lf_scene_build(lf_scene_desc *d, lf_scene *s, lf_error *err)
{
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
    s->time0 = d->transform_start_time;
    s->time1 = d->transform_end_time;
    lf_vec3 bmin = lf_v3(INFINITY, INFINITY, INFINITY), bmax = lf_v3(-INFINITY, -INFINITY, -INFINITY);
    if (read_description(d, s, err))
        goto fail;
    s->has_media = reaches_media(s);
    if (new_embree_scene(s, err))
        goto fail;
    /* Geometry IDs follow this order: world meshes, spheres, instances. */
    attach_world_meshes(s, &bmin, &bmax);
    lf_attach_spheres(s, &bmin, &bmax);
    lf_attach_instances(s, &bmin, &bmax);
    lf_attach_curves(s, &bmin, &bmax);
    if (commit_embree_scene(s, err))
        goto fail;
    set_bounds(s, bmin, bmax);
    if (prepare_light_selection(s, err))
        goto fail;
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
    lf_curves_free(s);
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
    lf_media_free(s);
    lf_warnings_free(&s->warnings);
    memset(s, 0, sizeof *s);
    s->sphere_geom_id = RTC_INVALID_GEOMETRY_ID;
}
