/* lfrender - render a pbrt-v4 scene through lensfield's camera pack.
 *
 * usage: lfrender SCENE.pbrt [-o OUT.exr|OUT.png] [--spp N] [--threads N]
 *                 [--seed S] [--crop x0 x1 y0 y1] [--quiet] [--explain] [--white]
 *                 [--camera-plugin LIB.so]...
 *
 * Exit codes: 0 success; 1 the scene or the render failed (message names
 * file:line:column); 2 bad command line.  No output file is written on
 * failure, and outputs are replaced atomically.
 */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "camera/lf_camera.h"
#include "image/lf_image.h"
#include "render/lf_render.h"
#include "render/lf_scene_desc.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: lfrender SCENE.pbrt [-o OUT.exr|OUT.png] [--spp N] [--threads N] [--seed S]\n"
               "                [--crop x0 x1 y0 y1] [--quiet] [--explain] [--camera-plugin LIB.so]\n"
               "\n"
               "  -o PATH           output image; .exr is linear float with lensfield:* metadata,\n"
               "                    .png/.jpg are tonemapped sRGB (default: the Film's \"filename\")\n"
               "  --spp N           samples per pixel (default: the Sampler's \"pixelsamples\")\n"
               "  --threads N       render threads (default: all cores); never changes the result\n"
               "  --seed S          sampler seed (default: the Sampler's \"seed\", 0)\n"
               "  --crop x0 x1 y0 y1  render only pixels [x0,x1) x [y0,y1) of the film\n"
               "  --quiet           no progress bar or summary\n"
               "  --explain         print the effect plan and exit without rendering\n"
               "  --white           render the white image: same camera and film, a uniform\n"
               "                    environment of radiance 1 and nothing else (flat field)\n"
               "  --camera-plugin L load camera types from the shared object L\n");
}

static int parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || end == s || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

typedef struct progress {
    double t0, last;
    int enabled;
} progress;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void on_progress(void *ctx, long done, long total)
{
    progress *p = ctx;
    double t = now();
    if (!p->enabled || (t - p->last < 0.2 && done < total))
        return;
    p->last = t;
    double frac = (double)done / total, el = t - p->t0;
    double eta = frac > 0 ? el * (1 - frac) / frac : 0;
    int width = 40, fill = (int)(frac * width);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    fprintf(stderr, "\r[%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs ", bar, 100 * frac, el, eta);
    if (done == total)
        fputc('\n', stderr);
    fflush(stderr);
}

/* mkdir -p for the output's directory. */
static int ensure_parent_dir(const char *path)
{
    char buf[PATH_MAX];
    snprintf(buf, sizeof buf, "%s", path);
    char *slash = strrchr(buf, '/');
    if (!slash || slash == buf)
        return 0;
    *slash = '\0';
    for (char *p = buf + 1; *p; p++)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) && errno != EEXIST)
                return -1;
            *p = '/';
        }
    if (mkdir(buf, 0777) && errno != EEXIST)
        return -1;
    return 0;
}

/* Checked before hours of rendering: can we create a file beside the output? */
static int check_writable(const char *path, char *msg, size_t n)
{
    if (ensure_parent_dir(path)) {
        snprintf(msg, n, "cannot create the directory of %s: %s", path, strerror(errno));
        return -1;
    }
    char probe[PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(probe, sizeof probe, "%.*s/.lfrender-probe-%ld", (int)(slash - path), path, (long)getpid());
    else
        snprintf(probe, sizeof probe, ".lfrender-probe-%ld", (long)getpid());
    FILE *f = fopen(probe, "wb");
    if (!f) {
        snprintf(msg, n, "cannot write %s: %s", path, strerror(errno));
        return -1;
    }
    fclose(f);
    remove(probe);
    return 0;
}

int main(int argc, char **argv)
{
    const char *scene = NULL, *out = NULL;
    lf_render_opts o = lf_render_opts_default();
    int quiet = 0, explain = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        long v;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-o") && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(a, "--spp") && i + 1 < argc) {
            if (parse_int(argv[++i], 1, 1 << 24, &v)) {
                fprintf(stderr, "lfrender: --spp expects an integer from 1 to 16777216, got \"%s\"\n", argv[i]);
                return 2;
            }
            o.spp = (int)v;
        } else if (!strcmp(a, "--threads") && i + 1 < argc) {
            if (parse_int(argv[++i], 1, 1024, &v)) {
                fprintf(stderr, "lfrender: --threads expects an integer from 1 to 1024, got \"%s\"\n", argv[i]);
                return 2;
            }
            o.threads = (int)v;
        } else if (!strcmp(a, "--seed") && i + 1 < argc) {
            if (parse_int(argv[++i], 0, 4294967295L, &v)) {
                fprintf(stderr, "lfrender: --seed expects a non-negative integer, got \"%s\"\n", argv[i]);
                return 2;
            }
            o.seed = (uint32_t)v;
            o.has_seed = 1;
        } else if (!strcmp(a, "--crop") && i + 4 < argc) {
            for (int k = 0; k < 4; k++) {
                if (parse_int(argv[i + 1 + k], 0, 65536, &v)) {
                    fprintf(stderr, "lfrender: --crop expects 4 pixel coordinates x0 x1 y0 y1, got \"%s\"\n",
                            argv[i + 1 + k]);
                    return 2;
                }
                o.crop[k] = (int)v;
            }
            if (o.crop[1] <= o.crop[0] || o.crop[3] <= o.crop[2]) {
                fprintf(stderr, "lfrender: --crop x0 x1 y0 y1 needs x0 < x1 and y0 < y1\n");
                return 2;
            }
            i += 4;
        } else if (!strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--explain")) {
            explain = 1;
        } else if (!strcmp(a, "--white")) {
            o.white = 1;
        } else if (!strcmp(a, "--camera-plugin") && i + 1 < argc) {
            char msg[1024];
            if (lf_camera_load_plugin(argv[++i], msg, sizeof msg)) {
                fprintf(stderr, "lfrender: %s\n", msg);
                return 1;
            }
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "lfrender: unknown or incomplete option \"%s\"\n", a);
            usage(stderr);
            return 2;
        } else if (!scene) {
            scene = a;
        } else {
            fprintf(stderr, "lfrender: more than one scene given (\"%s\" and \"%s\")\n", scene, a);
            return 2;
        }
    }
    if (!scene) {
        usage(stderr);
        return 2;
    }
    lf_error err = {0};
    lf_scene_desc desc;
    if (lf_scene_parse_file(scene, &desc, &err)) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        return 1;
    }
    o.scene_path = scene;
    progress pr = {now(), 0, !quiet && isatty(2)};
    o.progress = on_progress;
    o.progress_ctx = &pr;
    lf_renderer *r;
    if (lf_renderer_create(&desc, &o, &r, &err)) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        lf_scene_desc_free(&desc);
        return 1;
    }
    if (lf_renderer_warnings(r))
        fputs(lf_renderer_warnings(r), stderr);
    if (explain) {
        char *plan = lf_renderer_explain(r);
        fputs(plan ? plan : "", stdout);
        free(plan);
        lf_renderer_free(r);
        lf_scene_desc_free(&desc);
        return 0;
    }
    if (!out)
        out = lf_renderer_film_filename(r);
    char msg[1200];
    if (check_writable(out, msg, sizeof msg)) {
        fprintf(stderr, "lfrender: %s\n", msg);
        lf_renderer_free(r);
        lf_scene_desc_free(&desc);
        return 1;
    }
    lf_image img;
    lf_attrs meta = {0};
    pr.t0 = now();
    int rc = lf_renderer_render(r, &img, &meta, &err);
    if (!rc) {
        lf_render_stats st = lf_renderer_stats(r);
        if (st.nonfinite_samples)
            fprintf(stderr, "lfrender: warning: %lld samples had NaN/Inf radiance and were dropped "
                            "(recorded as lensfield:nonfinite_samples)\n", st.nonfinite_samples);
        lf_write_opts wo = {0};
        wo.half = lf_renderer_film_half(r);
        if (wo.half) {
            /* Half floats top out at 65504: keep bright renders exact in float. */
            size_t n = (size_t)img.width * img.height * img.channels;
            for (size_t k = 0; k < n; k++)
                if (img.data[k] > 65504.f) {
                    fprintf(stderr, "lfrender: note: values above 65504 do not fit Film \"savefp16\"; "
                                    "writing 32-bit float channels\n");
                    wo.half = 0;
                    break;
                }
        }
        if (!quiet)
            fprintf(stderr, "lfrender: %lld camera paths in %.3f s: %.3f M paths/s, %.3f M rays/s\n",
                    st.camera_paths, st.seconds, st.camera_paths / st.seconds * 1e-6, st.rays / st.seconds * 1e-6);
        rc = lf_image_write(out, &img, &meta, &wo, &err);
        if (!rc && !quiet)
            fprintf(stderr, "lfrender: wrote %s\n", out);
        lf_image_free(&img);
    }
    if (rc)
        fprintf(stderr, "lfrender: %s\n", err.msg);
    lf_attrs_free(&meta);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    return rc ? 1 : 0;
}
