/* A camera plugin as it was built against camera ABI version 1: its type
 * record ends at `metadata` (version 2 appended `generate_rays`).  The
 * loader must accept it and never read past the end of its record; the
 * test places the record at the very end of a page-aligned region so a
 * read past it would be a fault, not a silent pass.
 *
 * The camera is a plain pinhole looking down +z with a 90 degree
 * horizontal field of view. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "lf_camera.h"

/* lf_camera_type as version 1 declared it. */
typedef struct camera_type_v1 {
    uint32_t abi_version;
    const char *name;
    int (*create)(const lf_camera_create_args *args, void **state);
    uint32_t (*needs)(const void *state);
    double (*generate_ray)(const void *state, const lf_camera_sample *sample, lf_camera_ray *ray);
    void (*destroy)(void *state);
    int (*describe)(const void *state, char *buf, size_t size);
    void (*metadata)(const void *state, const lf_camera_attr_sink *sink);
} camera_type_v1;

typedef struct legacy {
    int width, height;
} legacy;

static int legacy_create(const lf_camera_create_args *a, void **state)
{
    legacy *c = malloc(sizeof *c);
    if (!c)
        return -1;
    c->width = a->image_width, c->height = a->image_height;
    *state = c;
    return 0;
}
static uint32_t legacy_needs(const void *state)
{
    (void)state;
    return 0;
}
static double legacy_generate_ray(const void *state, const lf_camera_sample *s, lf_camera_ray *r)
{
    const legacy *c = state;
    double x = 2.0 * s->film_x / c->width - 1.0, y = (1.0 - 2.0 * s->film_y / c->height) * c->height / c->width;
    double l = sqrt(x * x + y * y + 1.0);
    r->origin[0] = r->origin[1] = r->origin[2] = 0.0;
    r->dir[0] = x / l, r->dir[1] = y / l, r->dir[2] = 1.0 / l;
    return 1.0;
}
static void legacy_destroy(void *state)
{
    free(state);
}

static const camera_type_v1 legacy_type = {1u, "legacy_pinhole", legacy_create, legacy_needs, legacy_generate_ray,
                                           legacy_destroy, NULL, NULL};

const lf_camera_type *const *lf_camera_plugin_types(int *count)
{
    /* the record ends exactly where an inaccessible page begins */
    static const lf_camera_type *types[1];
    long page = sysconf(_SC_PAGESIZE);
    char *mem = mmap(NULL, (size_t)(2 * page), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mem == MAP_FAILED) {
        *count = 0;
        return NULL;
    }
    mprotect(mem + page, (size_t)page, PROT_NONE);
    camera_type_v1 *t = (camera_type_v1 *)(mem + page - sizeof(camera_type_v1));
    memcpy(t, &legacy_type, sizeof *t);
    types[0] = (const lf_camera_type *)(const void *)t;
    *count = 1;
    return (const lf_camera_type *const *)types;
}
