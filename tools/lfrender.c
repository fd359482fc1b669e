/* lfrender - render a pbrt-v4 scene through lensfield's camera pack.
 *
 * usage: lfrender SCENE.pbrt [-o OUT.exr|OUT.png] [--spp N] [--threads N]
 *                 [--seed S] [--crop x0 x1 y0 y1] [--quiet] [--explain] [--white]
 *                 [--spp-range A B] [--tile I/N] [--part]
 *                 [--checkpoint-every SECONDS] [--checkpoint PATH] [--resume]
 *                 [--camera-plugin LIB.so]... [--allow-unsupported]
 *        lfrender merge PART.exr... -o OUT.exr
 *
 * Exit codes: 0 success; 1 the scene or the render failed (message names
 * file:line:column; a scene with several errors gets each, up to 20, and
 * something lensfield cannot render is an error unless --allow-unsupported);
 * 2 bad command line; 130 interrupted (SIGINT/SIGTERM)
 * after writing a checkpoint that --resume continues from.  No output file is written on
 * failure, and outputs are replaced atomically.
 */
#include <errno.h>
#include <signal.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
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
               "  --spp-range A B   render only sample indices [A, B) of every pixel (a mergeable part)\n"
               "  --tile I/N        render only row band I of N (0-based; a mergeable part)\n"
               "  --part            write a mergeable part even without a split\n"
               "  --checkpoint-every S  save the film every S seconds (default path OUT.checkpoint.exr);\n"
               "                    SIGINT/SIGTERM save a final checkpoint and exit 130\n"
               "  --checkpoint PATH where checkpoints go\n"
               "  --resume          continue from the checkpoint (same scene and settings)\n"
               "  --camera-plugin L load camera types from the shared object L\n"
               "  --allow-unsupported  render a scene with shapes, lights, materials, textures or\n"
               "                    alpha cut-outs lensfield cannot render: left out or substituted,\n"
               "                    each with a warning (default: exit 1, docs/scene-format.md)\n"
               "\n"
               "       lfrender merge PART.exr... -o OUT.exr   sum parts into the unsplit image, bit for bit\n");
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

static volatile int stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static int merge_main(int argc, char **argv)
{
    const char *out = NULL;
    const char **parts = calloc((size_t)argc, sizeof *parts);
    int n = 0;
    if (!parts)
        return 1;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "-o") && i + 1 < argc)
            out = argv[++i];
        else if (argv[i][0] == '-') {
            fprintf(stderr, "lfrender merge: unknown option \"%s\"\nusage: lfrender merge PART.exr... -o OUT.exr\n",
                    argv[i]);
            free(parts);
            return 2;
        } else
            parts[n++] = argv[i];
    }
    if (!out || !n) {
        fprintf(stderr, "usage: lfrender merge PART.exr... -o OUT.exr\n");
        free(parts);
        return 2;
    }
    lf_error err = {0};
    lf_image img;
    lf_attrs meta = {0};
    int rc = lf_render_merge(parts, n, &img, &meta, &err);
    if (!rc) {
        /* write as the unsplit render would: Film "savefp16" travels in the parts */
        lf_write_opts wo = {0};
        const lf_attr *h = lf_attrs_get(&meta, "lensfield:savefp16");
        wo.half = h && h->type == LF_ATTR_INT && h->i;
        for (size_t k = 0; wo.half && k < (size_t)img.width * img.height * img.channels; k++)
            if (img.data[k] > 65504.f)
                wo.half = 0;
        rc = lf_image_write(out, &img, &meta, &wo, &err);
        lf_image_free(&img);
    }
    lf_attrs_free(&meta);
    free(parts);
    if (rc) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "merge"))
        return merge_main(argc, argv);
    const char *scene = NULL, *out = NULL, *checkpoint = NULL;
    lf_render_opts o = lf_render_opts_default();
    int quiet = 0, explain = 0, allow_unsupported = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        long v;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-o") && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(a, "--allow-unsupported")) {
            allow_unsupported = 1;
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
        } else if (!strcmp(a, "--part")) {
            o.part = 1;
        } else if (!strcmp(a, "--resume")) {
            o.resume = 1;
        } else if (!strcmp(a, "--checkpoint") && i + 1 < argc) {
            checkpoint = argv[++i];
        } else if (!strcmp(a, "--checkpoint-every") && i + 1 < argc) {
            char *end;
            double v = strtod(argv[++i], &end);
            if (*end || !(v > 0)) {
                fprintf(stderr, "lfrender: --checkpoint-every expects seconds > 0, got \"%s\"\n", argv[i]);
                return 2;
            }
            o.checkpoint_every = v;
        } else if (!strcmp(a, "--spp-range") && i + 2 < argc) {
            long b0, b1;
            if (parse_int(argv[i + 1], 0, 1 << 24, &b0) || parse_int(argv[i + 2], 1, 1 << 24, &b1) || b1 <= b0) {
                fprintf(stderr, "lfrender: --spp-range expects A B with 0 <= A < B\n");
                return 2;
            }
            o.spp_begin = (int)b0, o.spp_end = (int)b1, o.part = 1;
            i += 2;
        } else if (!strcmp(a, "--tile") && i + 1 < argc) {
            int ti, tn;
            char extra;
            if (sscanf(argv[++i], "%d/%d%c", &ti, &tn, &extra) != 2 || tn < 1 || ti < 0 || ti >= tn) {
                fprintf(stderr, "lfrender: --tile expects I/N with 0 <= I < N, got \"%s\"\n", argv[i]);
                return 2;
            }
            o.tile_index = ti, o.tile_count = tn, o.part = 1;
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
    if (o.checkpoint_every > 0 || o.resume || checkpoint) {
        /* from here on, SIGINT/SIGTERM stop the render and save a checkpoint */
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigaction(SIGINT, &sa, NULL);
        sigaction(SIGTERM, &sa, NULL);
    }
    lf_error err = {0};
    lf_scene_desc desc;
    lf_parse_opts popts = {allow_unsupported, 0};
    char *errors = NULL;
    if (lf_scene_parse_file_ex(scene, &popts, &desc, &err, &errors)) {
        /* every problem the parser found, one per line */
        int n = 0;
        for (const char *line = errors; line && *line;) {
            const char *nl = strchr(line, '\n');
            int len = nl ? (int)(nl - line) : (int)strlen(line);
            fprintf(stderr, "lfrender: %.*s\n", len, line);
            n += line[0] != '(';
            line += len + (nl != NULL);
        }
        if (!errors)
            fprintf(stderr, "lfrender: %s\n", err.msg);
        else if (n > 1)
            fprintf(stderr, "lfrender: %d errors in %s; nothing written\n", n, scene);
        free(errors);
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
    if (o.part && (strlen(out) < 4 || strcasecmp(out + strlen(out) - 4, ".exr"))) {
        fprintf(stderr, "lfrender: parts (--spp-range, --tile, --part) must be written as .exr, not %s\n", out);
        lf_renderer_free(r);
        lf_scene_desc_free(&desc);
        return 2;
    }
    char ckpath[4200];
    if (o.checkpoint_every > 0 || o.resume || checkpoint) {
        if (!checkpoint) {
            snprintf(ckpath, sizeof ckpath, "%s.checkpoint.exr", out);
            checkpoint = ckpath;
        }
        o.checkpoint_path = checkpoint;
        o.stop = &stop_requested;
        /* the renderer copied the options at create: hand it the new ones */
        lf_renderer_set_opts(r, &o);
    }
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
        wo.half = o.part ? 0 : lf_renderer_film_half(r); /* parts carry exact sums: 32-bit floats */
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
    else if (o.checkpoint_path)
        remove(o.checkpoint_path); /* finished: the checkpoint is no longer needed */
    lf_attrs_free(&meta);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    return rc == LF_ERR_INTERRUPTED ? 130 : (rc ? 1 : 0);
}
