/* lfrender - render a pbrt-v4 scene through lensfield's camera pack.
 *
 *   lfrender SCENE.pbrt [-o OUT.exr|OUT.png] [options]   (`lfrender --help`)
 *   lfrender merge PART.exr... -o OUT.exr
 *
 * Exit codes (tools/cli.h): 0 success; 1 the scene or the render failed
 * (message names file:line:column; a scene with several errors gets each, up
 * to 20, and something lensfield cannot render is an error unless
 * --allow-unsupported); 2 bad command line; 130 interrupted (SIGINT/SIGTERM)
 * after writing a checkpoint that --resume continues from.  No output file is
 * written on failure, and outputs are replaced atomically.
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/lf_file.h"
#include "base/lf_file_write.h"
#include "base/lf_keys.h"
#include "base/lf_progress.h"
#include "camera/lf_camera.h"
#include "cli.h"
#include "image/lf_image.h"
#include "image/lf_raw.h"
#include "render/lf_render.h"
#include "render/lf_sensor.h"
#include "scenefile/lf_scene_desc.h"

enum { MAX_PLUGINS = 16 };
typedef struct flags {
    const char *out, *checkpoint, *tile, *aov, *tonemap, *plugins[MAX_PLUGINS];
    int spp, threads, crop[4], spp_range[2], quiet, explain, white, part, resume, n_plugins, allow_unsupported;
    int have_seed, have_crop, have_spp_range;
    long long seed;
    double checkpoint_every, exposure;
} flags;

/* Film "raw": the sensor turns the film (region from full-film pixel x0, y0)
 * into a mosaic of DN, written as .exr or .dng. */
static int write_raw(const char *out, const lf_sensor *s, const lf_image *film, int x0, int y0, const lf_attrs *meta,
                     lf_error *err)
{
    lf_image raw;
    int rc = lf_sensor_expose(s, film, x0, y0, &raw, err);
    if (rc)
        return rc;
    lf_raw_info ri;
    lf_sensor_raw_info(s, &ri);
    ri.cfa = lf_cfa_shift(ri.cfa, x0, y0); /* a crop's pattern starts at its own first site */
    rc = lf_raw_write(out, &raw, &ri, meta, err);
    lf_image_free(&raw);
    return rc;
}

static int run_merge(void *ctx, int n, char **parts)
{
    const flags *f = ctx;
    lf_error err = {0};
    lf_image img;
    lf_attrs meta = {0};
    if (lf_output_is_input(f->out, (const char *const *)parts, n, &err)) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    int rc = lf_render_merge((const char **)parts, n, &img, &meta, &err);
    lf_sensor sensor;
    int raw = rc ? -1 : lf_sensor_from_attrs(&meta, &sensor, &err);
    if (!rc && raw == 0) { /* Film "raw": the sensor sees the merged film, as an unsplit render's */
        const lf_attr *pb = lf_attrs_get(&meta, LF_KEY_PIXEL_BOUNDS);
        rc = write_raw(f->out, &sensor, &img, pb ? (int)pb->v[0] : 0, pb ? (int)pb->v[2] : 0, &meta, &err);
        lf_image_free(&img);
    } else if (!rc && raw > 0) {
        rc = raw;
        lf_image_free(&img);
    } else if (!rc) { /* write as the unsplit render would: Film "savefp16" travels in the parts */
        const lf_attr *h = lf_attrs_get(&meta, LF_KEY_SAVEFP16);
        lf_write_opts wo = {.half = h && h->type == LF_ATTR_INT && h->i && lf_image_fits_half(&img)};
        rc = lf_image_write(f->out, &img, &meta, &wo, &err);
        lf_image_free(&img);
    }
    lf_attrs_free(&meta);
    if (rc)
        fprintf(stderr, "lfrender: %s\n", err.msg);
    return rc ? LF_EXIT_FAIL : LF_EXIT_OK;
}

/* The render options from the flags; 0, or 2 after a usage message. */
static int render_opts_from_flags(const flags *f, lf_render_opts *o)
{
    *o = lf_render_opts_default();
    o->spp = f->spp, o->threads = f->threads;
    o->seed = (uint32_t)f->seed, o->has_seed = f->have_seed;
    o->white = f->white, o->part = f->part, o->resume = f->resume;
    o->checkpoint_every = f->checkpoint_every;
    if (f->have_crop) {
        if (f->crop[1] <= f->crop[0] || f->crop[3] <= f->crop[2])
            return lf_cli_usage_error("lfrender", NULL, "--crop x0 x1 y0 y1 needs x0 < x1 and y0 < y1");
        memcpy(o->crop, f->crop, sizeof f->crop);
    }
    if (f->have_spp_range) {
        if (f->spp_range[1] <= f->spp_range[0])
            return lf_cli_usage_error("lfrender", NULL, "--spp-range A B needs A < B");
        o->spp_begin = f->spp_range[0], o->spp_end = f->spp_range[1], o->part = 1;
    }
    if (f->tile) {
        int ti, tn;
        char extra;
        if (sscanf(f->tile, "%d/%d%c", &ti, &tn, &extra) != 2 || tn < 1 || ti < 0 || ti >= tn)
            return lf_cli_usage_error("lfrender", NULL, "--tile wants I/N with 0 <= I < N, got \"%s\"", f->tile);
        o->tile_index = ti, o->tile_count = tn, o->part = 1;
    }
    return LF_EXIT_OK;
}

/* Parses the scene; prints every problem the parser found, one per line. */
static int parse_scene(const flags *f, const char *scene, lf_scene_desc *desc)
{
    lf_error err = {0};
    lf_parse_opts popts = {f->allow_unsupported, 0};
    char *errors = NULL;
    if (!lf_scene_parse_file_ex(scene, &popts, desc, &err, &errors))
        return LF_EXIT_OK;
    int count = 0;
    for (const char *line = errors; line && *line;) {
        const char *nl = strchr(line, '\n');
        int len = nl ? (int)(nl - line) : (int)strlen(line);
        fprintf(stderr, "lfrender: %.*s\n", len, line);
        count += line[0] != '(';
        line += len + (nl != NULL);
    }
    if (!errors)
        fprintf(stderr, "lfrender: %s\n", err.msg);
    else if (count > 1)
        fprintf(stderr, "lfrender: %d errors in %s; nothing written\n", count, scene);
    free(errors);
    return LF_EXIT_FAIL;
}

/* Before rendering: --explain, then the output's checks.  -1 to render,
 * else the exit code. */
static int check_output(const flags *f, lf_renderer *r, const lf_render_opts *o, const char **out)
{
    if (f->explain) {
        char *plan = lf_renderer_explain(r);
        if (plan)
            fputs(plan, stdout);
        else
            fprintf(stderr, "lfrender: out of memory for the effect plan\n");
        int rc = plan ? LF_EXIT_OK : LF_EXIT_FAIL;
        free(plan);
        return rc;
    }
    if (!*out)
        *out = lf_renderer_film_filename(r);
    if (o->part && !lf_path_has_ext(*out, ".exr"))
        return lf_cli_usage_error("lfrender", NULL, "parts (--spp-range, --tile, --part) must be written as .exr, "
                                  "not %s", *out);
    if (lf_renderer_sensor(r) && !o->part && !lf_path_has_ext(*out, ".exr") && !lf_path_has_ext(*out, ".dng"))
        return lf_cli_usage_error("lfrender", NULL, "Film \"raw\" writes a mosaic as .exr or .dng, not %s "
                                  "(develop it with lftool develop)", *out);
    if (f->aov && (o->part || !lf_path_has_ext(*out, ".exr")))
        return lf_cli_usage_error("lfrender", NULL, "--aov disparity needs an .exr output and an unsplit render (no "
                                  "--part, --tile, --spp-range)");
    lf_error err = {0};
    if (lf_output_is_input(*out, &o->scene_path, 1, &err) || lf_file_check_writable(*out, &err)) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    return -1;
}

/* Renders, then writes OUT (and the disparity AOV); an LF_ERR_* status. */
static int render_and_write(const flags *f, lf_renderer *r, const lf_render_opts *o, const char *out, lf_progress *pr)
{
    lf_image img;
    lf_attrs meta = {0};
    lf_error err = {0};
    lf_progress_start(pr);
    int rc = lf_renderer_render(r, &img, &meta, &err);
    if (!rc) {
        lf_render_stats st = lf_renderer_stats(r);
        if (st.nonfinite_samples)
            fprintf(stderr, "lfrender: warning: %lld samples had NaN/Inf radiance and were dropped "
                            "(recorded as lensfield:nonfinite_samples)\n", st.nonfinite_samples);
        lf_write_opts wo = lf_write_opts_picture(f->exposure, f->tonemap);
        wo.half = !o->part && lf_renderer_film_half(r); /* parts carry exact sums: 32-bit floats */
        if (wo.half && !lf_image_fits_half(&img)) { /* half floats top out at 65504: keep bright renders exact */
            fprintf(stderr, "lfrender: note: values above 65504 do not fit Film \"savefp16\"; "
                            "writing 32-bit float channels\n");
            wo.half = 0;
        }
        if (!f->quiet)
            fprintf(stderr, "lfrender: %lld camera paths in %.3f s: %.3f M paths/s, %.3f M rays/s\n",
                    st.camera_paths, st.seconds, st.camera_paths / st.seconds * 1e-6, st.rays / st.seconds * 1e-6);
        char aov[PATH_MAX];
        float range[2];
        if (f->aov && !(rc = lf_render_write_disparity(r, out, &meta, aov, sizeof aov, range, &err)) && !f->quiet)
            fprintf(stderr, "lfrender: wrote %s (disparity %.6g .. %.6g px per view step)\n", aov, range[0], range[1]);
        const lf_sensor *sensor = lf_renderer_sensor(r);
        if (!rc && sensor && !o->part) {
            const lf_attr *pb = lf_attrs_get(&meta, LF_KEY_PIXEL_BOUNDS);
            rc = write_raw(out, sensor, &img, pb ? (int)pb->v[0] : 0, pb ? (int)pb->v[2] : 0, &meta, &err);
        } else if (!rc) {
            rc = lf_image_write(out, &img, &meta, &wo, &err);
        }
        if (!rc && !f->quiet)
            fprintf(stderr, "lfrender: wrote %s\n", out);
        lf_image_free(&img);
    }
    if (rc)
        fprintf(stderr, "lfrender: %s\n", err.msg);
    else if (o->checkpoint_path)
        remove(o->checkpoint_path); /* finished: the checkpoint is no longer needed */
    lf_attrs_free(&meta);
    return rc;
}

static int run_render(void *ctx, int n, char **pos)
{
    (void)n;
    const flags *f = ctx;
    const char *scene = pos[0], *out = f->out;
    lf_render_opts o;
    int rc = render_opts_from_flags(f, &o);
    if (rc)
        return rc;
    for (int i = 0; i < f->n_plugins; i++) {
        char msg[1024]; /* the camera plugin ABI's convention (camera/lf_camera.h) */
        if (lf_camera_load_plugin(f->plugins[i], msg, sizeof msg)) {
            fprintf(stderr, "lfrender: %s\n", msg);
            return LF_EXIT_FAIL;
        }
    }
    /* from here on, SIGINT/SIGTERM stop the render and save a checkpoint */
    volatile sig_atomic_t *stop = o.checkpoint_every > 0 || o.resume || f->checkpoint ? lf_cli_stop_on_signals() : NULL;
    lf_scene_desc desc;
    if ((rc = parse_scene(f, scene, &desc)))
        return rc;
    o.scene_path = scene;
    lf_progress pr;
    o.progress = !f->quiet && isatty(2) ? lf_cli_progress : NULL;
    o.progress_ctx = &pr;
    lf_renderer *r;
    lf_error err = {0};
    if (lf_renderer_create(&desc, &o, &r, &err)) {
        fprintf(stderr, "lfrender: %s\n", err.msg);
        lf_scene_desc_free(&desc);
        return LF_EXIT_FAIL;
    }
    if (lf_renderer_warnings(r))
        fputs(lf_renderer_warnings(r), stderr);
    char ckpath[4200];
    if ((rc = check_output(f, r, &o, &out)) < 0) {
        lf_file_temp_clean(out); /* a killed run's half-written temporaries (issue 32) */
        if (stop) {
            snprintf(ckpath, sizeof ckpath, "%s.checkpoint.exr", out);
            o.checkpoint_path = f->checkpoint ? f->checkpoint : ckpath;
            lf_file_temp_clean(o.checkpoint_path);
            o.stop = stop;
            lf_renderer_set_opts(r, &o); /* the renderer copied the options at create */
        }
        rc = render_and_write(f, r, &o, out, &pr);
        rc = rc == LF_ERR_INTERRUPTED ? LF_EXIT_INTERRUPTED : (rc ? LF_EXIT_FAIL : LF_EXIT_OK);
    }
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    return rc;
}

int main(int argc, char **argv)
{
    flags f = {0};
    const lf_arg render_args[] = {
        {"--output", "-o", LF_ARG_STRING, &f.out, "OUT",
         "output image: .exr is linear float with lensfield:* metadata, .png/.jpg tonemapped sRGB (default: the "
         "Film's \"filename\")"},
        {"--spp", NULL, LF_ARG_INT, &f.spp, "N", "samples per pixel (default: the Sampler's \"pixelsamples\")",
         .min = 1, .max = 1 << 24, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX},
        {"--threads", NULL, LF_ARG_INT, &f.threads, "N",
         "render threads (default 0: all cores); never changes the result", .min = 0, .max = 1024,
         .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX},
        {"--seed", NULL, LF_ARG_LONG, &f.seed, "S", "sampler seed (default: the Sampler's \"seed\", 0)", .min = 0,
         .max = 4294967295.0, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX, .given = &f.have_seed},
        {"--crop", NULL, LF_ARG_INT, f.crop, "X0 X1 Y0 Y1", "render only pixels [X0,X1) x [Y0,Y1) of the film",
         .min = 0, .max = 65536, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX, .count = 4, .given = &f.have_crop},
        {"--exposure", NULL, LF_ARG_DOUBLE, &f.exposure, "EV", "8-bit outputs: scale by 2^EV before the tone curve",
         .min = -64, .max = 64, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX},
        {"--tonemap", NULL, LF_ARG_CHOICE, &f.tonemap, "CURVE", "8-bit outputs: the tone curve (default clamp)",
         .choices = "clamp|filmic|aces"},
        {"--quiet", NULL, LF_ARG_FLAG, &f.quiet, NULL, "no progress bar or summary"},
        {"--explain", NULL, LF_ARG_FLAG, &f.explain, NULL, "print the effect plan and exit without rendering"},
        {"--white", NULL, LF_ARG_FLAG, &f.white, NULL,
         "render the white image: same camera and film, a uniform environment of radiance 1 (flat field)"},
        {"--spp-range", NULL, LF_ARG_INT, f.spp_range, "A B", "render only sample indices [A, B) (a mergeable part)",
         .min = 0, .max = 1 << 24, .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX, .count = 2, .given = &f.have_spp_range},
        {"--tile", NULL, LF_ARG_STRING, &f.tile, "I/N", "render only row band I of N (0-based; a mergeable part)"},
        {"--part", NULL, LF_ARG_FLAG, &f.part, NULL, "write a mergeable part even without a split"},
        {"--checkpoint-every", NULL, LF_ARG_DOUBLE, &f.checkpoint_every, "S",
         "save the film every S seconds (default path OUT.checkpoint.exr); SIGINT/SIGTERM save one and exit 130",
         .min = 0, .flags = LF_ARG_MIN_OPEN},
        {"--checkpoint", NULL, LF_ARG_STRING, &f.checkpoint, "PATH", "where checkpoints go"},
        {"--resume", NULL, LF_ARG_FLAG, &f.resume, NULL, "continue from the checkpoint (same scene and settings)"},
        {"--camera-plugin", NULL, LF_ARG_LIST, f.plugins, "LIB.so", "load camera types from a shared object",
         .count = MAX_PLUGINS, .count_out = &f.n_plugins},
        {"--allow-unsupported", NULL, LF_ARG_FLAG, &f.allow_unsupported, NULL,
         "render a scene with shapes, lights, materials, textures or alpha cut-outs lensfield cannot render: left out "
         "or substituted, each with a warning (default: exit 1, docs/scene-format.md)"},
        {"--aov", NULL, LF_ARG_CHOICE, &f.aov, "disparity",
         "light-field cameras: also write OUT.disparity.exr, the ground-truth disparity (px per view step) of every "
         "pixel's view (docs/lightfield-format.md)",
         .choices = "disparity"},
    };
    const lf_arg merge_args[] = {
        {"--output", "-o", LF_ARG_STRING, &f.out, "OUT.exr", "the merged image", .flags = LF_ARG_REQUIRED},
    };
    const lf_command commands[] = {
        {NULL, "SCENE.pbrt [-o OUT.exr|OUT.png] [options]", "render a pbrt-v4 scene", render_args,
         LF_ARRAY_LEN(render_args), 1, 1, run_render,
         "Renders SCENE through lensfield's camera pack. The same seed gives the same image, bit for bit, on any "
         "number of threads; parts of a split render merge into exactly the unsplit image."},
        {"merge", "PART.exr... -o OUT.exr",
         "sum parts (--spp-range, --tile, --part) into the unsplit image, bit for bit", merge_args,
         LF_ARRAY_LEN(merge_args), 1, -1, run_merge, NULL},
    };
    const lf_tool tool = {"lfrender", "render pbrt-v4 scenes through lensfield's camera pack", LF_VERSION, commands,
                          LF_ARRAY_LEN(commands),
                          "Exit status: 0 success; 1 the scene or the render failed (the message names "
                          "file:line:column); 2 bad command line; 130 interrupted after saving a checkpoint."};
    return lf_cli_main(&tool, &f, argc, argv);
}
