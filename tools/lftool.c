/* lftool - decode, refocus and re-view light fields (docs/lftool.md;
 * `lftool --help`, `lftool COMMAND --help`).  IN is a light-field raw or a
 * folder of views (HCI layout or PREFIX_RR_CC names).  The work is done by
 * lightfield/ (lf_lightfield.h, lf_source.h, lf_depth.h) and web/
 * (lf_web.h); this file holds the flag tables and prints.
 *
 * Exit codes: 0 ok, 1 bad input (the message names the file and what is
 * missing or wrong), 2 usage.
 */
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/lf_file_write.h"
#include "base/lf_keys.h"
#include "base/lf_progress.h"
#include "cli.h"
#include "image/lf_image.h"
#include "image/lf_raw.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lightfield/lf_source.h"
#include "web/lf_web.h"

/* ---------- flags (one table per command; `lftool COMMAND --help`) ---------- */

typedef struct opts {
    const char *cmd, *input, *output, *white, *format, *hci, *method, *coverage;
    const char *confidence, *dispmap, *geometry, *grid; /* depth, view, synth; folders */
    lf_lightfield_layout flags;
    int have_alpha, have_depth, have_disp, have_aperture, have_views, have_from, have_to, have_u, have_v;
    double alpha, depth, disp, aperture, from, to, u, v, oversample;
    int views[4], steps, threads, allow_nonfinite, calibrate_views, no_wb, film_units, noisy, plain_regions;
    double prefilter; /* depth --prefilter: the views' Gaussian pre-smoothing (px), 0 off */
    int have_prefilter;
    lf_lightfield_synth_opts synth;
    int have_outfov, have_outdim, have_pos, have_focal; /* synth */
    int port, have_steps;                               /* export-web, serve */
    double exposure;                                    /* 8-bit outputs */
    const char *tonemap;
    /* the layout (CS348B names) and synth camera, turned into flags and synth by apply_flags() */
    struct gathered_flags {
        const char *kind, *grid;
        int cams[2], tile[2], lenses[2], outdim[2], spp;
        double griddim[4], fov, pitch, rotation, offset[2], mainlens[4], pos[3], rot[3], focal, outfov, lensradius;
        long long seed;
        int g_kind, g_cams, g_griddim, g_fov, g_tile, g_grid, g_pitch, g_rot, g_offset, g_lenses, g_main, g_spp, g_seed;
    } fl;
} opts;

static int usage(const opts *o, const char *msg) { return lf_cli_usage_error("lftool", o->cmd, "%s", msg); }

#define R_MIN(lo) .min = (lo), .flags = LF_ARG_HAS_MIN
#define R_POS .min = 0, .flags = LF_ARG_MIN_OPEN
#define R_IN(lo, hi) .min = (lo), .max = (hi), .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX

/* Layout flags: for raws without lensfield:* attributes (they must agree
 * with the file otherwise). */
#define LAYOUT_FLAGS                                                                                               \
    {"--kind", NULL, LF_ARG_CHOICE, &o.fl.kind, "KIND", "layout: camera-array or plenoptic",                       \
     .choices = "camera-array|plenoptic", .given = &o.fl.g_kind},                                                  \
        {"--camsperdim", NULL, LF_ARG_INT, o.fl.cams, "NX NY", "layout: data cameras per row and column",          \
         R_IN(1, 4096), .count = 2, .given = &o.fl.g_cams},                                                        \
        {"--griddim", NULL, LF_ARG_DOUBLE, o.fl.griddim, "MINX MAXX MINY MAXY", "layout: camera grid bounds (m)",  \
         .count = 4, .given = &o.fl.g_griddim},                                                                    \
        {"--inputfov", NULL, LF_ARG_DOUBLE, &o.fl.fov, "DEG", "layout: the data cameras' field of view",           \
         .min = 0, .max = 180, .flags = LF_ARG_MIN_OPEN | LF_ARG_MAX_OPEN, .given = &o.fl.g_fov},                  \
        {"--tilesize", NULL, LF_ARG_INT, o.fl.tile, "W H", "layout: tile of one data camera (px)", R_IN(1, 1 << 20), \
         .count = 2, .given = &o.fl.g_tile},                                                                       \
        {"--grid", NULL, LF_ARG_CHOICE, &o.fl.grid, "GRID", "layout: microlens grid square or hex",                \
         .choices = "square|hex", .given = &o.fl.g_grid},                                                          \
        {"--pitch", NULL, LF_ARG_DOUBLE, &o.fl.pitch, "PX", "layout: microlens pitch (px)", R_POS,                 \
         .given = &o.fl.g_pitch},                                                                                  \
        {"--rotation", NULL, LF_ARG_DOUBLE, &o.fl.rotation, "RAD", "layout: microlens grid rotation",              \
         .given = &o.fl.g_rot},                                                                                    \
        {"--offset", NULL, LF_ARG_DOUBLE, o.fl.offset, "X Y", "layout: first microlens centre (px)", .count = 2,   \
         .given = &o.fl.g_offset},                                                                                 \
        {"--lenscount", NULL, LF_ARG_INT, o.fl.lenses, "NX NY", "layout: microlenses per row and column",          \
         R_IN(1, 1 << 20), .count = 2, .given = &o.fl.g_lenses},                                                   \
        {"--mainlens", NULL, LF_ARG_DOUBLE, o.fl.mainlens, "FOCAL_MM FSTOP MLA_DISTANCE_MM PITCH_UM",              \
         "layout: the plenoptic camera's main lens and microlens array", R_POS, .count = 4, .given = &o.fl.g_main}, \
        {"--threads", NULL, LF_ARG_INT, &o.threads, "N", "threads (default 0: all cores)", R_IN(0, 1024)},         \
        {"--allow-nonfinite", NULL, LF_ARG_FLAG, &o.allow_nonfinite, NULL,                                         \
         "treat NaN/Inf raw pixels as missing samples instead of failing"},                                        \
        {"--grid-order", NULL, LF_ARG_CHOICE, &o.grid, "HOW", "folders: check the views' order against their parallax " \
         "(default), read it as named, or reorder it", .choices = "check|off|transpose|flip-x|flip-y"}

#define OUTPUT_FLAG(what) {"--output", "-o", LF_ARG_STRING, &o.output, "OUT", what, .flags = LF_ARG_REQUIRED}
#define PICTURE_FLAGS                                                                                              \
    {"--exposure", NULL, LF_ARG_DOUBLE, &o.exposure, "EV", "8-bit outputs: scale by 2^EV before the tone curve",   \
     R_IN(-64, 64)},                                                                                               \
        {"--tonemap", NULL, LF_ARG_CHOICE, &o.tonemap, "CURVE", "8-bit outputs: the tone curve (default clamp)",   \
         .choices = "clamp|filmic|aces"}
#define FOCUS_FLAGS                                                                                                \
    {"--alpha", NULL, LF_ARG_DOUBLE, &o.alpha, "A", "synthetic film at alpha F (Ng 2005)", R_POS,                  \
     .given = &o.have_alpha},                                                                                      \
        {"--depth", NULL, LF_ARG_DOUBLE, &o.depth, "M", "the depth brought into focus (m)", R_POS,                 \
         .given = &o.have_depth},                                                                                  \
        {"--disparity", NULL, LF_ARG_DOUBLE, &o.disp, "PX", "the disparity brought into focus (px per view)",      \
         .given = &o.have_disp}
#define APERTURE_FLAGS                                                                                             \
    {"--aperture", NULL, LF_ARG_DOUBLE, &o.aperture, "R", "synthetic aperture radius (views from the centre)",     \
     R_MIN(0), .given = &o.have_aperture},                                                                         \
        {"--views", NULL, LF_ARG_INT, o.views, "U0 U1 V0 V1", "use only views [U0,U1] x [V0,V1]",                  \
         R_IN(0, 1 << 20), .count = 4, .given = &o.have_views}
#define RANGE_FLAGS(lo)                                                                                            \
    {"--from", NULL, LF_ARG_DOUBLE, &o.from, "D0", "lowest disparity (px per view)", .given = &o.have_from},       \
        {"--to", NULL, LF_ARG_DOUBLE, &o.to, "D1", "highest disparity (px per view)", .given = &o.have_to},        \
        {"--steps", NULL, LF_ARG_INT, &o.steps, "N", "slices between them", R_IN(lo, 4096),                        \
         .given = &o.have_steps}

/* Turns the gathered layout and synth flags (o->fl) into o->flags and o->synth. */
static void apply_flags(opts *o)
{
    const struct gathered_flags *fl = &o->fl;
    lf_lightfield_layout *f = &o->flags;
    lf_lightfield_layout_init(f);
    const struct {
        int given;
        unsigned have;
    } given[] = {{fl->g_kind, LF_LIGHTFIELD_HAVE_KIND},   {fl->g_cams, LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_KIND},
                 {fl->g_griddim, LF_LIGHTFIELD_HAVE_BOUNDS}, {fl->g_fov, LF_LIGHTFIELD_HAVE_FOV},
                 {fl->g_tile, LF_LIGHTFIELD_HAVE_TILE},    {fl->g_grid, LF_LIGHTFIELD_HAVE_GRID},
                 {fl->g_pitch, LF_LIGHTFIELD_HAVE_PITCH},  {fl->g_rot, LF_LIGHTFIELD_HAVE_ROTATION},
                 {fl->g_offset, LF_LIGHTFIELD_HAVE_OFFSET}, {fl->g_lenses, LF_LIGHTFIELD_HAVE_LENS_COUNT},
                 {fl->g_main, LF_LIGHTFIELD_HAVE_MAIN_LENS}};
    for (size_t i = 0; i < LF_ARRAY_LEN(given); i++)
        if (given[i].given)
            f->have |= given[i].have;
    f->kind = fl->g_cams || (fl->g_kind && strcmp(fl->kind, "plenoptic")) ? LF_LIGHTFIELD_CAMERA_ARRAY : LF_LIGHTFIELD_PLENOPTIC;
    f->grid = fl->g_grid && !strcmp(fl->grid, "hex") ? LF_LIGHTFIELD_GRID_HEX : LF_LIGHTFIELD_GRID_SQUARE;
    f->cams_x = fl->cams[0], f->cams_y = fl->cams[1];
    memcpy(f->grid_bounds, fl->griddim, sizeof f->grid_bounds);
    f->fov_deg = fl->fov, f->pitch_px = fl->pitch, f->rotation_rad = fl->rotation;
    f->tile_w = fl->tile[0], f->tile_h = fl->tile[1];
    f->offset_px[0] = fl->offset[0], f->offset_px[1] = fl->offset[1];
    f->lens_x = fl->lenses[0], f->lens_y = fl->lenses[1];
    f->main_focal_mm = fl->mainlens[0], f->main_fstop = fl->mainlens[1];
    f->mla_distance_mm = fl->mainlens[2], f->pitch_um = fl->mainlens[3];
    lf_lightfield_synth_opts *s = &o->synth;
    *s = lf_lightfield_synth_defaults();
    s->threads = o->threads;
    if (fl->g_spp)
        s->spp = fl->spp;
    if (fl->g_seed)
        s->seed = (uint32_t)fl->seed;
    s->focal_distance = fl->focal, s->lens_radius = fl->lensradius, s->fov_deg = fl->outfov;
    memcpy(s->pos, fl->pos, sizeof s->pos);
    memcpy(s->rot_deg, fl->rot, sizeof s->rot_deg);
    s->width = fl->outdim[0], s->height = fl->outdim[1];
}

/* ---------- helpers ---------- */

/* Every command starts here: its name, IN (and OUT) and the flags' values. */
static const opts *begin(void *ctx, const char *cmd, int n, char **pos)
{
    opts *o = ctx;
    o->cmd = cmd, o->input = pos[0];
    if (n > 1)
        o->output = pos[1];
    apply_flags(o);
    return o;
}

/* Prints a library error (after the input's name when given): exit 1. */
static int fail(const lf_error *err, const char *name)
{
    fprintf(stderr, "lftool: %s%s%s\n", name ? name : "", name ? ": " : "", err->msg);
    return LF_EXIT_FAIL;
}

/* No output may be one of the inputs (issue 32): refused before reading.
 * --confidence is written by depth and read by view and synth. */
static int refuse_overwrite(const opts *o)
{
    int conf_out = !strcmp(o->cmd, "depth");
    const char *in[] = {o->input, o->white, o->dispmap, conf_out ? NULL : o->confidence};
    const char *out[] = {o->output, o->coverage, conf_out ? o->confidence : NULL};
    lf_error err = {0};
    for (int i = 0; i < 3; i++)
        if (lf_output_is_input(out[i], in, 4, &err))
            return fail(&err, NULL);
    return LF_EXIT_OK;
}

/* Reads the raw (or folder of views) and resolves its layout (attributes +
 * flags); decodes unless layout_only. */
static int load(const opts *o, lf_lightfield_source *s, int layout_only)
{
    lf_error err = {0};
    if (refuse_overwrite(o))
        return LF_EXIT_FAIL;
    lf_lightfield_open_opts oo = {&o->flags, o->white, o->allow_nonfinite, layout_only, .grid = o->grid, .threads = o->threads};
    if (lf_lightfield_open(o->input, &oo, s, &err))
        return fail(&err, NULL);
    if (lf_warnings_text(&s->warnings))
        fprintf(stderr, "lftool: %s", lf_warnings_text(&s->warnings));
    if (!s->folder.dir && s->lf.nonfinite)
        fprintf(stderr, "lftool: %s: warning: %zu non-finite pixel values excluded as missing samples\n", o->input,
                s->lf.nonfinite);
    return LF_EXIT_OK;
}

static int write_image(const opts *o, const char *path, const lf_image *img, const lf_attrs *a)
{
    lf_error err = {0};
    lf_write_opts wo = lf_write_opts_picture(o->exposure, o->tonemap);
    return lf_image_write(path, img, a, &wo, &err) ? fail(&err, NULL) : LF_EXIT_OK;
}

/* ---------- commands ---------- */

static int cmd_info(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "info", n, pos);
    lf_lightfield_source s;
    int rc = load(o, &s, 1);
    if (rc)
        return rc;
    char buf[4096];
    lf_lightfield_source_describe(&s, buf, sizeof buf);
    fputs(buf, stdout);
    lf_lightfield_close(&s);
    return LF_EXIT_OK;
}

/* A raw mosaic (Film "raw" EXR or DNG) to a picture: black level,
 * Malvar-He-Cutler demosaicing, white balance, colour matrix, tone curve. */
static int cmd_develop(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "develop", n, pos);
    if (refuse_overwrite(o))
        return LF_EXIT_FAIL;
    lf_image raw, rgb;
    lf_raw_info ri;
    lf_error err = {0};
    if (lf_raw_read(o->input, &raw, &ri, NULL, &err))
        return fail(&err, NULL);
    lf_develop_opts d = {o->no_wb, o->film_units};
    int rc = lf_raw_develop(&raw, &ri, &d, &rgb, &err);
    lf_image_free(&raw);
    if (rc)
        return fail(&err, o->input);
    rc = write_image(o, o->output, &rgb, NULL);
    if (!rc)
        printf("%s: %d x %d %s mosaic developed (Malvar-He-Cutler, white balance%s, %s) -> %s\n", o->input,
               rgb.width, rgb.height, lf_cfa_name(ri.cfa), o->no_wb ? " off" : "",
               o->film_units && ri.dn_per_unit > 0 ? "in the film's units" : "white level = 1", o->output);
    lf_image_free(&rgb);
    return rc;
}

/* The HCI benchmark layout, with the centre view's ground truth when known. */
static int decode_hci(const opts *o, const lf_lightfield_source *s)
{
    const lf_lightfield *lf = &s->lf;
    lf_image gt;
    lf_error err = {0};
    int no_centre;
    if (lf_lightfield_source_gt_disparity(s, &gt, &no_centre, &err))
        return fail(&err, NULL);
    if (no_centre)
        fprintf(stderr, "lftool: %s: note: %d x %d views have no centre view; gt_disp_lowres.pfm not written\n",
                o->input, lf->nu, lf->nv);
    int rc = lf_lightfield_write_hci(o->output, lf, gt.data ? &gt : NULL, &err) ? fail(&err, NULL) : LF_EXIT_OK;
    if (!rc)
        printf("%s: %d x %d views of %d x %d -> %s (HCI layout%s; %zu missing samples)\n", o->input, lf->nu, lf->nv,
               lf->ns, lf->nt, o->output, gt.data ? ", gt_disp_lowres.pfm" : "", lf->missing);
    lf_image_free(&gt);
    return rc;
}

static int cmd_decode(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "decode", n, pos);
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    const lf_lightfield *lf = &s.lf;
    lf_error err = {0};
    lf_write_opts wo = lf_write_opts_picture(o->exposure, o->tonemap);
    if (o->hci)
        rc = decode_hci(o, &s);
    else if (lf_lightfield_write_views(lf, o->output, o->format ? o->format : "exr", &wo, &err))
        rc = fail(&err, NULL);
    else
        printf("%s: %d x %d views of %d x %d -> %s (%zu missing samples)\n", o->input, lf->nu, lf->nv, lf->ns, lf->nt,
               o->output, lf->missing);
    lf_lightfield_close(&s);
    return rc;
}

/* disparity from at most one of --alpha, --depth, --disparity (0 if none) */
static int focus_disparity(const opts *o, const lf_lightfield *lf, double *d)
{
    if (o->have_alpha + o->have_depth + o->have_disp > 1)
        return usage(o, "give one of --alpha, --depth, --disparity");
    lf_error err = {0};
    *d = o->have_disp ? o->disp : 0;
    if ((o->have_alpha && lf_lightfield_alpha_to_disparity(lf, o->alpha, d, &err)) ||
        (o->have_depth && lf_lightfield_depth_to_disparity(lf, o->depth, d, &err)))
        return fail(&err, o->input);
    return LF_EXIT_OK;
}

static lf_lightfield_refocus_opts aperture_opts(const opts *o)
{
    lf_lightfield_refocus_opts r = lf_lightfield_refocus_defaults();
    if (o->have_aperture)
        r.aperture_radius = o->aperture;
    if (o->have_views)
        r.u0 = o->views[0], r.u1 = o->views[1], r.v0 = o->views[2], r.v1 = o->views[3];
    r.threads = o->threads;
    return r;
}

static int cmd_refocus(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "refocus", n, pos);
    if (o->have_alpha + o->have_depth + o->have_disp != 1)
        return usage(o, "refocus needs exactly one of --alpha A, --depth METRES, --disparity PX");
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    lf_lightfield_refocus_opts ro = aperture_opts(o);
    lf_error err = {0};
    lf_image out = {0};
    char range[256], asked[96];
    if ((rc = focus_disparity(o, &s.lf, &ro.disparity_px)))
        goto done;
    if (lf_lightfield_refocus_outside(&s.lf, ro.disparity_px, range, sizeof range)) { /* done, with a warning */
        if (o->have_depth)
            snprintf(asked, sizeof asked, "depth %g m", o->depth);
        else if (o->have_alpha)
            snprintf(asked, sizeof asked, "alpha %g", o->alpha);
        else
            snprintf(asked, sizeof asked, "disparity %g px/view", ro.disparity_px);
        fprintf(stderr,
                "lftool: warning: %s: %s (disparity %.3g px/view) is outside the refocusable range (%s): the "
                "sub-aperture views are blurred there, so the result is softer than a photograph focused at that "
                "depth\n",
                o->input, asked, ro.disparity_px, range);
    }
    if (o->method && !strcmp(o->method, "fourier")) {
        lf_lightfield_fourier *f = NULL;
        rc = lf_lightfield_fourier_new(&s.lf, &ro, o->oversample, &f, &err) ||
             lf_lightfield_fourier_refocus(f, ro.disparity_px, &out, &err);
        lf_lightfield_fourier_release(f);
    } else {
        rc = lf_lightfield_refocus(&s.lf, &ro, &out, &err);
    }
    lf_write_opts wo = lf_write_opts_picture(o->exposure, o->tonemap);
    if (rc)
        rc = fail(&err, o->input);
    else if (lf_lightfield_write_refocused(o->output, &out, ro.disparity_px, &wo, &err))
        rc = fail(&err, NULL);
    else
        printf("%s: refocused at disparity %.6g px/view -> %s\n", o->input, ro.disparity_px, o->output);
done:
    lf_image_free(&out);
    lf_lightfield_close(&s);
    return rc;
}

/* --from/--to, each defaulting to the disparities of the largest aperture,
 * -1 and +1 px per view */
static void stack_range(const opts *o, double *d0, double *d1)
{
    *d0 = o->have_from ? o->from : -1, *d1 = o->have_to ? o->to : 1;
}

static int cmd_stack(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "stack", n, pos);
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    double d0, d1;
    stack_range(o, &d0, &d1);
    lf_error err = {0};
    if (lf_dir_create(o->output, &err))
        rc = fail(&err, NULL);
    lf_lightfield_refocus_opts ro = aperture_opts(o);
    for (int k = 0; k < o->steps && !rc; k++) {
        ro.disparity_px = d0 + (d1 - d0) * k / (o->steps - 1);
        lf_image out;
        if (lf_lightfield_refocus(&s.lf, &ro, &out, &err)) {
            rc = fail(&err, o->input);
            break;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/stack_%03d.%s", o->output, k, o->format ? o->format : "exr");
        lf_write_opts wo = lf_write_opts_picture(o->exposure, o->tonemap);
        rc = lf_lightfield_write_refocused(path, &out, ro.disparity_px, &wo, &err) ? fail(&err, NULL) : LF_EXIT_OK;
        lf_image_free(&out);
    }
    if (!rc)
        printf("%s: %d slices, disparity %g .. %g -> %s\n", o->input, o->steps, d0, d1, o->output);
    lf_lightfield_close(&s);
    return rc;
}

static int allfocus_depth(const opts *o, int want_depth)
{
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    double d0, d1;
    stack_range(o, &d0, &d1);
    lf_lightfield_refocus_opts ro = aperture_opts(o);
    lf_image af = {0}, dm = {0};
    lf_error err = {0};
    if (lf_lightfield_allfocus(&s.lf, &ro, d0, d1, o->steps, &af, &dm, &err))
        rc = fail(&err, o->input);
    else if (!(rc = write_image(o, o->output, want_depth ? &dm : &af, NULL)))
        printf("%s: %s from %d slices (disparity %g .. %g) -> %s\n", o->input,
               want_depth ? "disparity map" : "all-in-focus", o->steps, d0, d1, o->output);
    lf_image_free(&af), lf_image_free(&dm);
    lf_lightfield_close(&s);
    return rc;
}

static int cmd_allfocus(void *ctx, int n, char **pos)
{
    return allfocus_depth(begin(ctx, "allfocus", n, pos), 0);
}

static int cmd_depth(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "depth", n, pos);
    if (o->method && !strcmp(o->method, "stack"))
        return allfocus_depth(o, 1);
    if (o->have_from != o->have_to)
        return usage(o, "depth: give both --from and --to, or neither (range from the file or the data)");
    if (o->have_from && !(o->from < o->to))
        return usage(o, "depth: --from must be below --to");
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    lf_lightfield_depth_opts d = lf_lightfield_depth_defaults();
    lf_progress pr;
    lf_progress_start(&pr);
    d.threads = o->threads, d.progress = isatty(2) ? lf_cli_progress : NULL, d.progress_ctx = &pr;
    d.noise_aware = o->noisy;
    d.plain = o->plain_regions;
    if (o->have_prefilter) /* else auto */
        d.prefilter = o->prefilter > 0 ? o->prefilter : -1;
    const char *src = "--from/--to";
    if (o->have_from)
        d.d0 = o->from, d.d1 = o->to;
    else if (!(src = lf_lightfield_source_disparity_range(&s, &d.d0, &d.d1)))
        src = "estimated";
    lf_error err = {0};
    lf_image disp = {0}, conf = {0};
    lf_lightfield_depth_range_info ri = {0};
    char srcbuf[160];
    if (d.d0 >= d.d1 && lf_lightfield_depth_range_report(&s.lf, o->threads, &d.d0, &d.d1, &ri, &err))
        goto failed;
    if (!strcmp(src, "estimated") && (ri.widened || ri.full_widened)) { /* the data reached past the estimate */
        int k = 0;
        if (ri.widened)
            k = snprintf(srcbuf, sizeof srcbuf, "estimated, widened from %.4g .. %.4g", ri.first_d0, ri.first_d1);
        if (ri.full_widened)
            snprintf(srcbuf + k, sizeof srcbuf - (size_t)k, "%s full-resolution check found %.4g .. %.4g",
                     k ? ";" : "estimated, widened: the", ri.full_lo, ri.full_hi);
        src = srcbuf;
    }
    if (o->have_steps)
        d.step = (d.d1 - d.d0) / (o->steps - 1);
    double sigma, noise; /* the views' pre-smoothing, chosen once, run and reported as chosen */
    if (lf_lightfield_depth_prefilter(&s.lf, &d, &sigma, &noise, &err))
        goto failed;
    d.prefilter = sigma > 0 ? sigma : -1;
    if (o->calibrate_views) { /* depth on the nominal grid, view positions fitted to it */
        if (lf_lightfield_depth(&s.lf, &d, &disp, &conf, &err) ||
            lf_lightfield_calibrate_views(&s.lf, &disp, &conf, o->threads, NULL, &err))
            goto failed;
        lf_image_free(&disp), lf_image_free(&conf);
    }
    if (lf_lightfield_depth(&s.lf, &d, &disp, o->confidence ? &conf : NULL, &err))
        goto failed;
    lf_write_opts wo = lf_write_opts_picture(o->exposure, o->tonemap);
    rc = lf_lightfield_write_disparity(o->output, &disp, d.d0, d.d1, &wo, &err) ? fail(&err, NULL) : LF_EXIT_OK;
    if (!rc && o->confidence)
        rc = write_image(o, o->confidence, &conf, NULL);
    char smooth[160] = "";
    if (sigma > 0 && noise >= 0) /* the default's choice, and why */
        snprintf(smooth, sizeof smooth,
                 ", views pre-smoothed: noise %.1f %% of their level; matched whitened, with a wider window where unsure",
                 100 * noise);
    else if (sigma > 0)
        snprintf(smooth, sizeof smooth, ", views pre-smoothed by %.3g px; matched whitened, with a wider window where unsure",
                 sigma);
    if (!rc)
        printf("%s: disparity map (range %.4g .. %.4g px/view, %s%s) -> %s%s%s\n", o->input, d.d0, d.d1, src, smooth,
               o->output, o->confidence ? ", confidence -> " : "", o->confidence ? o->confidence : "");
    else /* no half-written result: the disparity map goes with its confidence */
        remove(o->output);
    goto done;
failed:
    rc = fail(&err, o->input);
done:
    lf_image_free(&disp), lf_image_free(&conf);
    lf_lightfield_close(&s);
    return rc;
}

/* --calibrate-views for view: fit the views to the given map, or to one
 * estimated on the nominal grid. */
static int calibrate_for_view(const opts *o, lf_lightfield *lf, const lf_image *dm, const lf_image *cm, lf_error *err)
{
    if (o->dispmap)
        return lf_lightfield_calibrate_views(lf, dm, o->confidence ? cm : NULL, o->threads, NULL, err);
    lf_image ed = {0}, ec = {0};
    lf_lightfield_depth_opts dopt = lf_lightfield_depth_defaults();
    dopt.threads = o->threads;
    int rc = lf_lightfield_depth(lf, &dopt, &ed, &ec, err) || lf_lightfield_calibrate_views(lf, &ed, &ec, o->threads, NULL, err);
    lf_image_free(&ed), lf_image_free(&ec);
    return rc;
}

static int cmd_view(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "view", n, pos);
    /* per-pixel geometry by default; the plane blend with --geometry plane
     * (or, as before, when a focus plane is given without --geometry) */
    int plane = o->geometry ? !strcmp(o->geometry, "plane") : (o->have_alpha + o->have_depth + o->have_disp) > 0;
    if (plane && o->dispmap)
        return usage(o, "--disparity-map needs --geometry depth");
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    double d = 0;
    lf_image out = {0}, dm = {0}, cm = {0};
    lf_error err = {0};
    if ((rc = focus_disparity(o, &s.lf, &d)))
        goto done;
    if (!plane && o->dispmap &&
        (lf_lightfield_read_map(o->dispmap, &s.lf, &dm, &err) ||
         (o->confidence && lf_lightfield_read_map(o->confidence, &s.lf, &cm, &err)))) {
        rc = fail(&err, NULL);
        goto done;
    }
    if (!plane && o->calibrate_views && calibrate_for_view(o, &s.lf, &dm, &cm, &err))
        rc = LF_EXIT_FAIL;
    else if (plane)
        rc = lf_lightfield_view_at(&s.lf, o->u, o->v, d, &out, &err);
    else {
        lf_lightfield_view_opts vo = lf_lightfield_view_defaults();
        vo.threads = o->threads;
        vo.plane_disparity = d;
        vo.disparity = o->dispmap ? &dm : NULL;
        vo.confidence = o->dispmap && o->confidence ? &cm : NULL;
        rc = lf_lightfield_view_depth(&s.lf, o->u, o->v, &vo, &out, &err);
    }
    rc = rc ? fail(&err, o->input) : write_image(o, o->output, &out, NULL);
    if (!rc)
        printf("%s: view at u %g, v %g (%s) -> %s\n", o->input, o->u, o->v, plane ? "plane" : "depth", o->output);
done:
    lf_image_free(&out), lf_image_free(&dm), lf_image_free(&cm);
    lf_lightfield_close(&s);
    return rc;
}

static int cmd_synth(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "synth", n, pos);
    if (o->dispmap && !(o->geometry && !strcmp(o->geometry, "depth")))
        return usage(o, "--disparity-map needs --geometry depth");
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    lf_lightfield_synth_opts so = o->synth;
    unsigned set = (o->have_outfov ? LF_LIGHTFIELD_SYNTH_SET_FOV : 0) | (o->have_outdim ? LF_LIGHTFIELD_SYNTH_SET_SIZE : 0) |
                   (o->have_pos ? LF_LIGHTFIELD_SYNTH_SET_POS : 0) | (o->have_focal ? LF_LIGHTFIELD_SYNTH_SET_FOCAL : 0);
    lf_image out = {0}, cov = {0}, dm = {0};
    size_t uncovered = 0;
    lf_error err = {0};
    if (lf_lightfield_synth_prepare(&s.lf, set, &so, &err))
        goto failed;
    if (o->geometry && !strcmp(o->geometry, "depth")) { /* per-pixel geometry (docs/depth.md) */
        lf_lightfield_depth_opts dop = lf_lightfield_depth_defaults();
        dop.threads = o->threads;
        if (o->dispmap && lf_lightfield_read_map(o->dispmap, &s.lf, &dm, &err)) {
            rc = fail(&err, NULL);
            goto done;
        }
        if (!o->dispmap && lf_lightfield_depth(&s.lf, &dop, &dm, NULL, &err))
            goto failed;
        so.disparity = &dm;
    }
    if (lf_lightfield_synth(&s.lf, &so, &out, &cov, &uncovered, &err))
        goto failed;
    rc = write_image(o, o->output, &out, NULL);
    if (!rc && o->coverage)
        rc = write_image(o, o->coverage, &cov, NULL);
    if (!rc)
        printf("%s: %dx%d, %d spp -> %s\n", o->input, so.width, so.height, so.spp, o->output);
    if (!rc && uncovered)
        fprintf(stderr, "lftool: %s: %zu of %d pixels have no ray inside the captured aperture%s\n", o->input,
                uncovered, so.width * so.height, o->coverage ? " (see the coverage mask)" : "");
    goto done;
failed:
    rc = fail(&err, o->input);
done:
    lf_image_free(&out), lf_image_free(&cov), lf_image_free(&dm);
    lf_lightfield_close(&s);
    return rc;
}

static int cmd_calibrate(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "calibrate", n, pos);
    lf_image white;
    lf_attrs a = {0}; /* only the estimated layout: the input's own header is not carried over */
    lf_error err = {0};
    if (refuse_overwrite(o))
        return LF_EXIT_FAIL;
    if (lf_image_read(o->input, &white, NULL, &err))
        return fail(&err, NULL);
    lf_lightfield_layout lay;
    lf_lightfield_layout_init(&lay);
    if (o->flags.have & LF_LIGHTFIELD_HAVE_GRID)
        lay.grid = o->flags.grid, lay.have |= LF_LIGHTFIELD_HAVE_GRID;
    int rc = LF_EXIT_FAIL;
    if (lf_lightfield_calibrate_white(&white, &lay, &err) || lf_lightfield_layout_to_attrs(&lay, &a, &err))
        fail(&err, o->input);
    else if (lf_attrs_set_int(&a, LF_KEY_WHITE, 1, &err))
        fail(&err, NULL);
    else if (!(rc = write_image(o, o->output, &white, &a))) {
        char buf[1024];
        lf_lightfield_layout_describe(&lay, buf, sizeof buf);
        printf("%s: estimated layout -> %s\n%s", o->input, o->output, buf);
        printf("flags: --kind plenoptic --grid %s --pitch %.6g --rotation %.6g --offset %.6g %.6g --lenscount %d %d\n",
               lay.grid == LF_LIGHTFIELD_GRID_HEX ? "hex" : "square", lay.pitch_px, lay.rotation_rad, lay.offset_px[0],
               lay.offset_px[1], lay.lens_x, lay.lens_y);
    }
    lf_image_free(&white), lf_attrs_free(&a);
    return rc;
}

/* ---------- export-web and serve (web/lf_web.h, docs/web.md) ---------- */

static int cmd_export_web(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "export-web", n, pos);
    if (o->have_from != o->have_to)
        return usage(o, "export-web: give both --from and --to, or neither");
    lf_web_export_opts wo = lf_web_export_defaults();
    wo.format = o->format ? o->format : "jpg";
    wo.stack_slices = o->have_steps ? o->steps : 9;
    wo.have_range = o->have_from, wo.focus_min = o->from, wo.focus_max = o->to;
    wo.threads = o->threads;
    wo.source = o->input;
    lf_lightfield_source s;
    int rc = load(o, &s, 0);
    if (rc)
        return rc;
    clock_t c0 = clock();
    lf_web_export_info info;
    lf_error err = {0};
    if (lf_web_export(&s.lf, o->output, &wo, &info, &err)) {
        fprintf(stderr, "lftool: export-web: %s: %s\n", o->input, err.msg);
        lf_lightfield_close(&s);
        return LF_EXIT_FAIL;
    }
    printf("%s: %d x %d views of %d x %d, focus %.4g .. %.4g px/view, %d-slice stack -> %s/index.html "
           "(%.1f KiB, %.2f s CPU)\n",
           o->input, s.lf.nu, s.lf.nv, s.lf.ns, s.lf.nt, info.focus_min, info.focus_max, wo.stack_slices, o->output,
           info.page_bytes / 1024.0, (double)(clock() - c0) / CLOCKS_PER_SEC);
    lf_lightfield_close(&s);
    return LF_EXIT_OK;
}

static int cmd_serve(void *ctx, int n, char **pos)
{
    const opts *o = begin(ctx, "serve", n, pos);
    lf_web_server *srv;
    lf_error err = {0};
    if (lf_web_server_open(o->input, o->port, &srv, &err)) {
        fprintf(stderr, "lftool: serve: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    volatile sig_atomic_t *stop = lf_cli_stop_on_signals();
    printf("serving %s at http://127.0.0.1:%d/ (Ctrl-C stops)\n", lf_web_server_root(srv), lf_web_server_port(srv));
    fflush(stdout);
    int rc = lf_web_server_run(srv, stop, &err);
    lf_web_server_close(srv);
    if (rc) {
        fprintf(stderr, "lftool: serve: %s\n", err.msg);
        return LF_EXIT_FAIL;
    }
    printf("stopped\n");
    return LF_EXIT_OK;
}

#define CMD(name, syn, sum, args, fn, desc) {name, syn, sum, args, LF_ARRAY_LEN(args), 1, 1, fn, desc}

/* The flag tables (and the *_FLAGS macros) point into o, the options every command gets. */
int main(int argc, char **argv)
{
    opts o = {.steps = 9, .oversample = 2, .port = 8000};
    const lf_arg info_args[] = {LAYOUT_FLAGS};
    const lf_arg decode_args[] = {
        OUTPUT_FLAG("folder of views (view_ROW_COL) and mosaic"), LAYOUT_FLAGS, PICTURE_FLAGS,
        {"--format", NULL, LF_ARG_CHOICE, &o.format, "FMT", "views as exr (default) or png", .choices = "exr|png"},
        {"--white", NULL, LF_ARG_STRING, &o.white, "WHITE.exr", "divide by a white image (devignetting)"},
        {"--layout", NULL, LF_ARG_CHOICE, &o.hci, "hci",
         "write the HCI benchmark layout (input_CamNNN.png, parameters.cfg, gt_disp_lowres.pfm)", .choices = "hci"},
    };
    const lf_arg calibrate_args[] = {
        OUTPUT_FLAG("the white image with the estimated layout attributes"),
        {"--grid", NULL, LF_ARG_CHOICE, &o.fl.grid, "GRID", "microlens grid square or hex (default: estimated)",
         .choices = "square|hex", .given = &o.fl.g_grid},
    };
    const lf_arg refocus_args[] = {
        OUTPUT_FLAG("the refocused image"), FOCUS_FLAGS, APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
        {"--white", NULL, LF_ARG_STRING, &o.white, "WHITE.exr", "divide by a white image (devignetting)"},
        {"--method", NULL, LF_ARG_CHOICE, &o.method, "METHOD", "shift-and-add (default) or Fourier slice",
         .choices = "shift|fourier"},
        {"--oversample", NULL, LF_ARG_DOUBLE, &o.oversample, "S", "Fourier slice: spectrum oversampling (default 2)",
         R_IN(1, 8)},
    };
    const lf_arg stack_args[] = {
        OUTPUT_FLAG("folder of slices stack_NNN"), RANGE_FLAGS(2), APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
        {"--format", NULL, LF_ARG_CHOICE, &o.format, "FMT", "slices as exr (default) or png", .choices = "exr|png"},
    };
    const lf_arg allfocus_args[] = {
        OUTPUT_FLAG("the all-in-focus image"), RANGE_FLAGS(2), APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
    };
    const lf_arg depth_args[] = {
        OUTPUT_FLAG("disparity map: .exr/.pfm values, .png a colour map with a legend"), RANGE_FLAGS(3), APERTURE_FLAGS,
        LAYOUT_FLAGS,
        {"--confidence", NULL, LF_ARG_STRING, &o.confidence, "C.exr", "also write the confidence map"},
        {"--calibrate-views", NULL, LF_ARG_FLAG, &o.calibrate_views, NULL,
         "fit each view's position and pixel offset to the data first (docs/depth.md)"},
        {"--noisy", NULL, LF_ARG_FLAG, &o.noisy, NULL,
         "the views carry sensor noise (a dim or low-sample capture): match so that no disparity is favoured by "
         "how the lookup smooths the noise (docs/depth.md, \"Noisy views\")"},
        {"--plain-regions", NULL, LF_ARG_FLAG, &o.plain_regions, NULL,
         "untextured regions take the far end of the evidence of their colour around them (a textured object "
         "before a plain wall; docs/depth.md, \"Plain regions\")"},
        {"--prefilter", NULL, LF_ARG_DOUBLE, &o.prefilter, "SIGMA",
         "smooth the views by a Gaussian of SIGMA px before matching, 0: never (default: 0.7 where the views' "
         "noise is 2 % of their level or more; smoothed views are matched with the noise whitened and a wider "
         "window where unsure; docs/depth.md, \"Pre-smoothing noisy views\")",
         R_IN(0, 4), .given = &o.have_prefilter},
        {"--method", NULL, LF_ARG_CHOICE, &o.method, "METHOD",
         "volume: cost volume with occlusion handling (default); stack: focal-stack contrast",
         .choices = "volume|stack"},
    };
    const lf_arg view_args[] = {
        OUTPUT_FLAG("the synthesized view"), FOCUS_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
        {"--u", NULL, LF_ARG_DOUBLE, &o.u, "U", "viewpoint, in view steps right of the centre", .given = &o.have_u,
         .flags = LF_ARG_REQUIRED},
        {"--v", NULL, LF_ARG_DOUBLE, &o.v, "V", "viewpoint, in view steps below the centre", .given = &o.have_v,
         .flags = LF_ARG_REQUIRED},
        {"--geometry", NULL, LF_ARG_CHOICE, &o.geometry, "GEOM",
         "depth: per-pixel disparity (default); plane: blend on one plane", .choices = "depth|plane"},
        {"--disparity-map", NULL, LF_ARG_STRING, &o.dispmap, "D.exr", "use this disparity map instead of estimating"},
        {"--confidence", NULL, LF_ARG_STRING, &o.confidence, "C.exr", "its confidence (with --disparity-map)"},
        {"--calibrate-views", NULL, LF_ARG_FLAG, &o.calibrate_views, NULL,
         "fit each view's position and pixel offset to the data first (docs/depth.md)"},
    };
    const lf_arg synth_args[] = {
        LAYOUT_FLAGS, PICTURE_FLAGS,
        {"--samplesperpixel", NULL, LF_ARG_INT, &o.fl.spp, "N", "samples per pixel", R_IN(1, 1 << 20),
         .given = &o.fl.g_spp},
        {"--focaldistance", NULL, LF_ARG_DOUBLE, &o.fl.focal, "D", "virtual focal plane distance", R_POS,
         .given = &o.have_focal},
        {"--camerapos", NULL, LF_ARG_DOUBLE, o.fl.pos, "X Y Z", "virtual camera position", .count = 3,
         .given = &o.have_pos},
        {"--camerarot", NULL, LF_ARG_DOUBLE, o.fl.rot, "X Y Z", "virtual camera rotation (degrees)", .count = 3},
        {"--outputfov", NULL, LF_ARG_DOUBLE, &o.fl.outfov, "DEG", "virtual camera field of view", .min = 0, .max = 180,
         .flags = LF_ARG_MIN_OPEN | LF_ARG_MAX_OPEN, .given = &o.have_outfov},
        {"--lensradius", NULL, LF_ARG_DOUBLE, &o.fl.lensradius, "R", "virtual lens radius (0: pinhole)", R_MIN(0)},
        {"--outputdim", NULL, LF_ARG_INT, o.fl.outdim, "W H", "output size in pixels", R_IN(1, 65536), .count = 2,
         .given = &o.have_outdim},
        {"--coverage", NULL, LF_ARG_STRING, &o.coverage, "COV.exr", "also write where rays left the captured aperture"},
        {"--seed", NULL, LF_ARG_LONG, &o.fl.seed, "S", "sampler seed", R_IN(0, 4294967295.0), .given = &o.fl.g_seed},
        {"--geometry", NULL, LF_ARG_CHOICE, &o.geometry, "GEOM", "depth: look data up on the estimated surface",
         .choices = "depth|plane"},
        {"--disparity-map", NULL, LF_ARG_STRING, &o.dispmap, "D.exr", "with --geometry depth: this disparity map"},
    };
    const lf_arg web_args[] = {
        OUTPUT_FLAG("folder for index.html, lf.js and data.js"), LAYOUT_FLAGS,
        {"--format", NULL, LF_ARG_CHOICE, &o.format, "FMT", "atlases as jpg (default) or png", .choices = "jpg|png"},
        {"--from", NULL, LF_ARG_DOUBLE, &o.from, "D0", "lowest disparity (px per view)", .given = &o.have_from},
        {"--to", NULL, LF_ARG_DOUBLE, &o.to, "D1", "highest disparity (px per view)", .given = &o.have_to},
        {"--steps", NULL, LF_ARG_INT, &o.steps, "N", "focal-stack slices (default 9)", R_IN(2, 64),
         .given = &o.have_steps},
    };
    const lf_arg develop_args[] = {
        OUTPUT_FLAG("the picture (.exr linear sRGB, .png tone-mapped)"), PICTURE_FLAGS,
        {"--no-white-balance", NULL, LF_ARG_FLAG, &o.no_wb, NULL, "keep the camera's white (no AsShotNeutral)"},
        {"--film-units", NULL, LF_ARG_FLAG, &o.film_units, NULL,
         "EXR raws from lfrender: values in the renderer's film units (lensfield:dn_per_unit), not white level = 1"},
    };
    const lf_arg serve_args[] = {
        {"--port", NULL, LF_ARG_INT, &o.port, "P", "port on 127.0.0.1 (default 8000; 0: any free)", R_IN(0, 65535)},
    };
    const lf_command commands[] = {
        CMD("info", "IN", "describe a light-field raw or folder of views", info_args, cmd_info, NULL),
        CMD("decode", "IN -o DIR [--format exr|png] [--white W.exr] [--layout hci]",
            "sub-aperture views and a mosaic, or the HCI benchmark layout", decode_args, cmd_decode, NULL),
        CMD("calibrate", "WHITE.exr -o OUT.exr [--grid square|hex]", "estimate the microlens grid from a white image",
            calibrate_args, cmd_calibrate, NULL),
        CMD("refocus", "IN (--alpha A | --depth M | --disparity PX) -o OUT [options]",
            "refocus after capture (shift-and-add or Fourier slice)", refocus_args, cmd_refocus,
            "Refocusing outside the refocusable range (Ng 2005) is done, with a warning: the sub-aperture views are "
            "themselves blurred there."),
        CMD("stack", "IN --from D0 --to D1 [--steps N] -o DIR", "a focal stack over a disparity range", stack_args,
            cmd_stack, NULL),
        CMD("allfocus", "IN --from D0 --to D1 [--steps N] -o OUT", "an all-in-focus image from a focal stack",
            allfocus_args, cmd_allfocus, NULL),
        CMD("depth", "IN -o OUT.exr|.pfm|.png [--from D0 --to D1] [--confidence C.exr]",
            "disparity map of the centre view (docs/depth.md)", depth_args, cmd_depth,
            "Without --from/--to the range comes from the input's metadata or is estimated from the data. Output in "
            "the HCI benchmark's convention: a point moves by -d pixels when the viewpoint moves one view right."),
        CMD("view", "IN --u U --v V -o OUT [--geometry depth|plane] [--disparity-map D.exr]",
            "synthesize a view from another viewpoint", view_args, cmd_view, NULL),
        {"synth", "LF OUT.exr [CS348B flags]", "the CS348B virtual camera between the data cameras", synth_args,
         LF_ARRAY_LEN(synth_args), 2, 2, cmd_synth, NULL},
        CMD("export-web", "IN -o DIR [--format jpg|png] [--from D0 --to D1] [--steps N]",
            "a living picture for the web: click to focus, drag to move (docs/web.md)", web_args, cmd_export_web, NULL),
        CMD("develop", "RAW -o OUT.png|exr", "develop a Film \"raw\" mosaic (EXR or DNG) into a picture",
            develop_args, cmd_develop,
            "Black level and white level from the raw, Malvar-He-Cutler (ICASSP 2004) demosaicing, white balance by "
            "AsShotNeutral, colour matrix (DNG ColorMatrix1) to linear sRGB; PNG adds --exposure and --tonemap."),
        CMD("serve", "DIR [--port P]", "serve DIR on http://127.0.0.1:P/ until Ctrl-C", serve_args, cmd_serve, NULL),
    };
    const lf_tool tool = {
        "lftool", "decode, refocus and re-view light fields", LF_VERSION, commands, LF_ARRAY_LEN(commands),
        "IN is a light-field raw (EXR with lensfield:* attributes, or any image plus layout flags) or a folder of "
        "views: the HCI layout (input_CamNNN.png + parameters.cfg) or PREFIX_RR_CC.png|exr "
        "(docs/lightfield-format.md). "
        "Exit status: 0 success; 1 bad input (the message names the file); 2 bad command line."};
    return lf_cli_main(&tool, &o, argc, argv);
}
