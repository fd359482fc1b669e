/* lf_test_tools.h - the tests' one way to run the tools and to render a
 * scene given as text (header-only, beside lf_test.h).
 *
 *   static char dir[256], out_text[65536];
 *   lf_test_run_setup(dir, 0, out_text, sizeof out_text);
 *   CHECK(run("%s info %s", LFTOOL, path) == 0 && strstr(out_text, "views"));
 *
 *   lf_image img;
 *   char msg[1024];
 *   CHECK(render_text(scene, &(lf_test_scene){.threads = 1}, &img, msg, sizeof msg) == 0);
 *
 * run() hands a printf-formatted command line to the shell with its stdout
 * and stderr in DIR/log.txt, copied into the buffer lf_test_run_setup named;
 * it returns the exit status (-1 when the command did not exit).
 * render_text() parses, builds and renders a scene through the library. */
#ifndef LF_TEST_TOOLS_H
#define LF_TEST_TOOLS_H

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "image/lf_image.h"
#include "render/lf_render.h"
#include "scenefile/lf_scene_desc.h"

/* Where run() works: the log goes to dir/log.txt; with in_dir the command
 * runs inside dir ("cd dir && { COMMAND ; }"); out receives the log. */
static struct {
    const char *dir;
    int in_dir;
    char *out;
    size_t out_size;
} lf_test_runner;

static inline void lf_test_run_setup(const char *dir, int in_dir, char *out, size_t out_size)
{
    lf_test_runner.dir = dir, lf_test_runner.in_dir = in_dir;
    lf_test_runner.out = out, lf_test_runner.out_size = out_size;
}

static inline int run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline int run(const char *fmt, ...)
{
    const char *dir = lf_test_runner.dir;
    char cmd[4096], full[4600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    if (lf_test_runner.in_dir)
        snprintf(full, sizeof full, "cd %s && { %s ; } > log.txt 2>&1", dir, cmd);
    else
        snprintf(full, sizeof full, "%s > %s/log.txt 2>&1", cmd, dir);
    int st = system(full);
    char path[512];
    snprintf(path, sizeof path, "%s/log.txt", dir);
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(lf_test_runner.out, 1, lf_test_runner.out_size - 1, f) : 0;
    lf_test_runner.out[n] = '\0';
    if (f)
        fclose(f);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* How render_text renders; every field 0 (or a NULL pointer) is the
 * default. */
typedef struct lf_test_scene {
    const char *name;    /* the file name messages carry and relative paths start from; NULL: "test.pbrt" */
    int threads;         /* 0: 2 */
    uint32_t seed;       /* with has_seed: instead of the Sampler's */
    int has_seed;
    int white;           /* the white image (flat field) */
    const int *crop;     /* x0 x1 y0 y1, or NULL */
    lf_attrs *meta;      /* the image's lensfield:* attributes, or NULL */
    char **explain;      /* the effect plan (malloc'd), or NULL */
    char **warnings;     /* a malloc'd copy of the renderer's warnings (NULL if none), or NULL */
    int warnings_in_msg; /* after a render, msg holds the renderer's warnings if there are any */
} lf_test_scene;

/* Parses, builds and renders text (img NULL: builds only).  0, or non-zero
 * with the message in msg (-1: the scene did not parse). */
static inline int render_text(const char *text, const lf_test_scene *s, lf_image *img, char *msg, size_t msg_size)
{
    static const lf_test_scene defaults;
    if (!s)
        s = &defaults;
    lf_scene_desc d;
    lf_error err = {0};
    if (lf_scene_parse_string(text, s->name ? s->name : "test.pbrt", &d, &err)) {
        snprintf(msg, msg_size, "%s", err.msg);
        return -1;
    }
    lf_render_opts o = lf_render_opts_default();
    o.threads = s->threads ? s->threads : 2;
    if (s->has_seed)
        o.seed = s->seed, o.has_seed = 1;
    o.white = s->white;
    if (s->crop)
        memcpy(o.crop, s->crop, sizeof o.crop);
    lf_renderer *r;
    int rc = lf_renderer_create(&d, &o, &r, &err);
    if (!rc) {
        if (s->explain)
            *s->explain = lf_renderer_explain(r);
        if (s->warnings && lf_renderer_warnings(r)) {
            *s->warnings = malloc(strlen(lf_renderer_warnings(r)) + 1);
            strcpy(*s->warnings, lf_renderer_warnings(r));
        }
        rc = img ? lf_renderer_render(r, img, s->meta, &err) : 0;
        if (!rc && s->warnings_in_msg && lf_renderer_warnings(r))
            snprintf(msg, msg_size, "%s", lf_renderer_warnings(r));
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    if (rc)
        snprintf(msg, msg_size, "%s", err.msg);
    return rc;
}

#endif
