/* camera_store.h - a parameter store standing in for a scene file, for the
 * tests and benchmarks that create cameras through the plugin ABI
 * (lf_camera_params) without the renderer.  The including file supplies
 * g_image (the aperture-image loader it wants).
 *
 *   store s = {{{"fov", {40}, 1}, {"lensfile", {0}, 0, "dgauss.dat"}}, 2};
 *   lf_camera_params p = {&s, g_float, g_int, g_bool, g_string, g_floats, g_image};
 */
#ifndef LF_TESTS_CAMERA_STORE_H
#define LF_TESTS_CAMERA_STORE_H

#include <string.h>

typedef struct kv {
    const char *name;
    double v[4];
    int n;         /* numbers given */
    const char *s; /* a string value instead (numbers ignored) */
} kv;
typedef struct store {
    kv items[16];
    int n;
    int image_kind; /* for the including file's g_image */
} store;

static inline const kv *find(const store *s, const char *name)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->items[i].name, name))
            return &s->items[i];
    return NULL;
}
static inline double g_float(void *c, const char *name, double def)
{
    const kv *k = find(c, name);
    return k && !k->s ? k->v[0] : def;
}
static inline int g_int(void *c, const char *name, int def)
{
    const kv *k = find(c, name);
    return k && !k->s ? (int)k->v[0] : def;
}
static inline int g_bool(void *c, const char *name, int def)
{
    return g_int(c, name, def);
}
static inline const char *g_string(void *c, const char *name, const char *def)
{
    const kv *k = find(c, name);
    return k && k->s ? k->s : def;
}
static inline int g_floats(void *c, const char *name, double *out, int max)
{
    const kv *k = find(c, name);
    if (!k || k->s)
        return 0;
    for (int i = 0; i < k->n && i < max; i++)
        out[i] = k->v[i];
    return k->n;
}

#endif
