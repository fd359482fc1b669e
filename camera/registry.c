/* The camera registry: built-ins are rows of a static table; plugins loaded
 * at run time are appended to a second table with the same row type. */
#include <dlfcn.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include "camera_internal.h"
static const lf_camera_type *const builtin[] = {
    &lf_camera_perspective,
    &lf_camera_orthographic,
    &lf_camera_thinlens,
    &lf_camera_realistic,
    &lf_camera_fisheye,
    &lf_camera_lightfield,
    &lf_camera_plenoptic,
    &lf_camera_spherical,
};
#define N_BUILTIN ((int)(sizeof builtin / sizeof builtin[0]))

enum { MAX_PLUGIN_TYPES = 64 };
static const lf_camera_type *plugin_types[MAX_PLUGIN_TYPES];
/* Version-1 types, copied into full version-2 records (batch entry NULL):
 * their own struct ends before generate_rays and must not be read past. */
static lf_camera_type legacy_types[MAX_PLUGIN_TYPES];

/* The size of a version-1 type record: everything up to and including
 * `metadata`. */
#define LF_CAMERA_TYPE_V1_SIZE (offsetof(lf_camera_type, metadata) + sizeof(((lf_camera_type *)0)->metadata))
/* Loading is serialised by a mutex; the count is published with release
 * semantics after its rows are written, so a lookup on another thread sees
 * either the old table or the complete new one. */
static atomic_int n_plugin_types;
static pthread_mutex_t plugin_lock = PTHREAD_MUTEX_INITIALIZER;

int lf_camera_count(void)
{
    return N_BUILTIN + atomic_load_explicit(&n_plugin_types, memory_order_acquire);
}

const lf_camera_type *lf_camera_at(int i)
{
    if (i < 0 || i >= lf_camera_count())
        return NULL;
    return i < N_BUILTIN ? builtin[i] : plugin_types[i - N_BUILTIN];
}

const lf_camera_type *lf_camera_find(const char *name)
{
    for (int i = 0; i < lf_camera_count(); i++)
        if (strcmp(lf_camera_at(i)->name, name) == 0)
            return lf_camera_at(i);
    return NULL;
}

void lf_camera_generate_rays(const lf_camera_type *t, const void *state, int n, const lf_camera_sample *samples,
                             lf_camera_ray *rays, double *weights)
{
    if (t->generate_rays) {
        t->generate_rays(state, n, samples, rays, weights);
        return;
    }
    for (int i = 0; i < n; i++)
        weights[i] = t->generate_ray(state, &samples[i], &rays[i]);
}

typedef const lf_camera_type *const *(*plugin_entry_fn)(int *count);

static int load_plugin_locked(const char *path, lf_error *err);

/* The installed header keeps the ABI's char buffer (lf_camera.h needs no
 * lensfield library); the loader itself reports into an lf_error. */
int lf_camera_load_plugin(const char *path, char *err, size_t err_size)
{
    lf_error e = {0};
    pthread_mutex_lock(&plugin_lock);
    int rc = load_plugin_locked(path, &e);
    pthread_mutex_unlock(&plugin_lock);
    return lf_cam_error(rc, &e, err, err_size) ? -1 : 0;
}

static int load_plugin_locked(const char *path, lf_error *err)
{
    int n_loaded = atomic_load_explicit(&n_plugin_types, memory_order_relaxed);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h)
        return lf_error_set(err, LF_ERR_IO, "cannot load camera plugin %s: %s", path, dlerror());
    plugin_entry_fn entry;
    *(void **)&entry = dlsym(h, "lf_camera_plugin_types");
    if (!entry) {
        lf_error_set(err, LF_ERR_UNSUPPORTED, "camera plugin %s does not export lf_camera_plugin_types()", path);
        dlclose(h);
        return err->code;
    }
    int count = 0;
    const lf_camera_type *const *types = entry(&count);
    if (!types || count <= 0) {
        lf_error_set(err, LF_ERR_UNSUPPORTED, "camera plugin %s registers no camera types", path);
        dlclose(h);
        return err->code;
    }
    for (int i = 0; i < count; i++) {
        const lf_camera_type *t = types[i];
        if (!t || t->abi_version < 1u || t->abi_version > LF_CAMERA_ABI_VERSION) {
            lf_error_set(err, LF_ERR_UNSUPPORTED,
                         "camera plugin %s: type %d has ABI version %u, this lfrender reads 1..%u", path, i,
                         t ? t->abi_version : 0u, LF_CAMERA_ABI_VERSION);
            dlclose(h);
            return err->code;
        }
        if (!t->name || !t->create || !t->generate_ray || !t->destroy || !t->needs) {
            lf_error_set(err, LF_ERR_UNSUPPORTED, "camera plugin %s: type %d lacks a name or a required function", path,
                         i);
            dlclose(h);
            return err->code;
        }
        if (lf_camera_find(t->name)) {
            lf_error_set(err, LF_ERR_PARAM, "camera plugin %s: a camera named \"%s\" is already registered", path,
                         t->name);
            dlclose(h);
            return err->code;
        }
    }
    if (n_loaded + count > MAX_PLUGIN_TYPES) {
        lf_error_set(err, LF_ERR_UNSUPPORTED, "camera plugin %s: too many plugin camera types (limit %d)", path,
                     MAX_PLUGIN_TYPES);
        dlclose(h);
        return err->code;
    }
    for (int i = 0; i < count; i++) {
        const lf_camera_type *t = types[i];
        if (t->abi_version == 1u) {
            lf_camera_type *c = &legacy_types[n_loaded];
            memset(c, 0, sizeof *c);
            memcpy(c, t, LF_CAMERA_TYPE_V1_SIZE);
            t = c;
        }
        plugin_types[n_loaded++] = t;
    }
    atomic_store_explicit(&n_plugin_types, n_loaded, memory_order_release);
    /* The handle stays open for the life of the process: the types live in it. */
    return 0;
}
