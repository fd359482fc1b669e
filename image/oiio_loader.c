/* lf_oiio_write / lf_oiio_read for the rest of image/: the OpenImageIO
 * adapter module (liblf_oiio.so, oiio_adapter.cpp) is loaded on the first
 * call, once per process, so a program that only touches EXR and PNG never
 * maps OpenImageIO and its ~260 libraries (oiio_adapter.h says why).
 *
 * Where the module is looked for, first found wins:
 *   1. $LF_OIIO_MODULE (a path to the .so);
 *   2. beside the running executable (build/bin/ keeps it next to lfrender);
 *   3. ../lib/lensfield/ relative to the executable (an installed layout);
 *   4. where this build put it (LF_OIIO_MODULE_PATH, set by CMake), for
 *      test and bench programs that live in other build directories.
 * A missing module is an error naming the paths tried, not a crash. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image_internal.h"
#include "oiio_adapter.h"

#ifndef LF_OIIO_MODULE_PATH
#define LF_OIIO_MODULE_PATH ""
#endif
#define LF_OIIO_MODULE_NAME "liblf_oiio.so"

static pthread_once_t once = PTHREAD_ONCE_INIT;
static const lf_oiio_module *module;
static char load_error[2048];

static const lf_oiio_host host = {LF_OIIO_MODULE_ABI, lf_image_check_size, lf_image_alloc, lf_image_free};

static int try_load(const char *path, char *tried, size_t tried_size)
{
    size_t n = strlen(tried);
    snprintf(tried + n, tried_size - n, "%s%s", n ? ", " : "", path);
    if (access(path, F_OK) != 0)
        return 0;
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        snprintf(load_error, sizeof load_error, "cannot load the OpenImageIO module %s: %s", path, dlerror());
        return -1;
    }
    lf_oiio_module_init_fn init;
    *(void **)&init = dlsym(h, "lf_oiio_module_init");
    const lf_oiio_module *m = init ? init(&host) : NULL;
    if (!m || m->abi != LF_OIIO_MODULE_ABI) {
        snprintf(load_error, sizeof load_error, "%s is not a lensfield OpenImageIO module of ABI version %d", path,
                 LF_OIIO_MODULE_ABI);
        dlclose(h);
        return -1;
    }
    module = m; /* the handle stays open for the life of the process */
    return 1;
}

static void load_module(void)
{
    char tried[4096] = "";
    const char *env = getenv("LF_OIIO_MODULE");
    if (env && *env) {
        if (try_load(env, tried, sizeof tried) == 0)
            snprintf(load_error, sizeof load_error, "LF_OIIO_MODULE=%s does not exist", env);
        return;
    }
    char exe[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0) {
        exe[len] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = 0;
            char path[PATH_MAX + 64];
            snprintf(path, sizeof path, "%s/%s", exe, LF_OIIO_MODULE_NAME);
            int rc = try_load(path, tried, sizeof tried);
            if (rc)
                return;
            snprintf(path, sizeof path, "%s/../lib/lensfield/%s", exe, LF_OIIO_MODULE_NAME);
            if ((rc = try_load(path, tried, sizeof tried)) != 0)
                return;
        }
    }
    if (*LF_OIIO_MODULE_PATH && try_load(LF_OIIO_MODULE_PATH, tried, sizeof tried) != 0)
        return;
    snprintf(load_error, sizeof load_error,
             "the OpenImageIO module %s was not found (looked for %s; set LF_OIIO_MODULE to its path)",
             LF_OIIO_MODULE_NAME, tried);
}

static const lf_oiio_module *get_module(void)
{
    pthread_once(&once, load_module);
    return module;
}

int lf_oiio_write(const char *file, const char *name, int width, int height, int channels, lf_oiio_pixel_type type,
                  const void *pixels, lf_error *err)
{
    const lf_oiio_module *m = get_module();
    if (!m)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot write '%s': %s", name, load_error);
    return m->write(file, name, width, height, channels, type, pixels, err);
}

int lf_oiio_read(const char *file, const char *name, lf_image *img, lf_oiio_read_info *info, lf_error *err)
{
    const lf_oiio_module *m = get_module();
    if (!m)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "cannot read '%s': %s", name, load_error);
    return m->read(file, name, img, info, err);
}
