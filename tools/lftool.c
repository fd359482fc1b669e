/* lftool - decode, refocus and re-view light-field raws (docs/lftool.md).
 *
 *   lftool info RAW.exr
 *   lftool decode RAW.exr -o DIR [--format exr|png] [--white WHITE.exr] [--layout hci]
 *   lftool calibrate WHITE.exr -o LAYOUT.exr [--grid square|hex]
 *   lftool refocus RAW.exr (--alpha A | --depth M | --disparity PX) [--aperture R | --views u0 u1 v0 v1]
 *                  [--method shift|fourier] -o OUT
 *   lftool stack|allfocus RAW.exr --from D0 --to D1 [--steps N] -o OUT
 *   lftool depth RAW.exr [--from D0 --to D1] [--confidence C.exr] -o OUT.exr|.pfm
 *   lftool view RAW.exr --u U --v V [--geometry plane --disparity PX | --disparity-map D.exr] -o OUT
 *   lftool synth LF.exr OUT.exr [CS348B flags]
 *   lftool export-web RAW.exr -o DIR [--format jpg|png] [--from D0 --to D1] [--steps N]
 *   lftool serve DIR [--port P]
 *
 * RAW may also be a folder of views (HCI layout or PREFIX_RR_CC names).
 *
 * Exit codes: 0 ok, 1 bad input (the message names the file and what is
 * missing or wrong), 2 usage.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include "base/lf_keys.h"
#include "cli.h"
#include "image/lf_image.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "web/lf_web.h"

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_USAGE = 2 };

/* ---------- flags (one table per command; `lftool COMMAND --help`) ---------- */

typedef struct opts {
    const char *cmd, *input, *output, *white, *format, *hci, *method, *coverage;
    const char *confidence, *dispmap, *geometry; /* depth, view, synth */
    lf_lf_layout flags;
    int have_alpha, have_depth, have_disp, have_aperture, have_views, have_from, have_to;
    double alpha, depth, disp, aperture, from, to, u, v, oversample;
    int have_u, have_v;
    int views[4], steps, threads, allow_nonfinite, calibrate_views;
    /* synth */
    lf_lf_synth_opts synth;
    int have_outfov, have_outdim, have_pos, have_focal;
    /* export-web, serve */
    int port, have_steps;
    /* 8-bit outputs */
    double exposure;
    const char *tonemap;
} opts;

static opts opt = {.steps = 9, .oversample = 2, .port = 8000};

/* Flags whose values are gathered first and turned into opt's fields by
 * apply_flags(): the layout (CS348B names) and the synth camera. */
static struct {
    const char *kind, *grid;
    int cams[2], tile[2], lenses[2], outdim[2], spp;
    double griddim[4], fov, pitch, rotation, offset[2], mainlens[4], pos[3], rot[3], focal, outfov, lensradius;
    long long seed;
    int g_kind, g_cams, g_griddim, g_fov, g_tile, g_grid, g_pitch, g_rot, g_offset, g_lenses, g_main, g_spp, g_rot3,
        g_lensradius, g_seed;
} fl;

static int usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "lftool: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(lftool %s --help for its flags)\n", opt.cmd ? opt.cmd : "COMMAND");
    return EXIT_USAGE;
}

#define R_MIN(lo) .min = (lo), .flags = LF_ARG_HAS_MIN
#define R_POS .min = 0, .flags = LF_ARG_MIN_OPEN
#define R_IN(lo, hi) .min = (lo), .max = (hi), .flags = LF_ARG_HAS_MIN | LF_ARG_HAS_MAX

/* Layout flags: for raws without lensfield:* attributes (they must agree
 * with the file otherwise). */
#define LAYOUT_FLAGS                                                                                               \
    {"--kind", NULL, LF_ARG_CHOICE, &fl.kind, "KIND", "layout: camera-array or plenoptic",                         \
     .choices = "camera-array|plenoptic", .given = &fl.g_kind},                                                    \
        {"--camsperdim", NULL, LF_ARG_INT, fl.cams, "NX NY", "layout: data cameras per row and column",           \
         R_IN(1, 4096), .count = 2, .given = &fl.g_cams},                                                          \
        {"--griddim", NULL, LF_ARG_DOUBLE, fl.griddim, "MINX MAXX MINY MAXY", "layout: camera grid bounds (m)",   \
         .count = 4, .given = &fl.g_griddim},                                                                      \
        {"--inputfov", NULL, LF_ARG_DOUBLE, &fl.fov, "DEG", "layout: the data cameras' field of view",            \
         .min = 0, .max = 180, .flags = LF_ARG_MIN_OPEN | LF_ARG_MAX_OPEN, .given = &fl.g_fov},                     \
        {"--tilesize", NULL, LF_ARG_INT, fl.tile, "W H", "layout: tile of one data camera (px)", R_IN(1, 1 << 20), \
         .count = 2, .given = &fl.g_tile},                                                                         \
        {"--grid", NULL, LF_ARG_CHOICE, &fl.grid, "GRID", "layout: microlens grid square or hex",                  \
         .choices = "square|hex", .given = &fl.g_grid},                                                            \
        {"--pitch", NULL, LF_ARG_DOUBLE, &fl.pitch, "PX", "layout: microlens pitch (px)", R_POS, .given = &fl.g_pitch}, \
        {"--rotation", NULL, LF_ARG_DOUBLE, &fl.rotation, "RAD", "layout: microlens grid rotation",                \
         .given = &fl.g_rot},                                                                                      \
        {"--offset", NULL, LF_ARG_DOUBLE, fl.offset, "X Y", "layout: first microlens centre (px)", .count = 2,     \
         .given = &fl.g_offset},                                                                                   \
        {"--lenscount", NULL, LF_ARG_INT, fl.lenses, "NX NY", "layout: microlenses per row and column",           \
         R_IN(1, 1 << 20), .count = 2, .given = &fl.g_lenses},                                                     \
        {"--mainlens", NULL, LF_ARG_DOUBLE, fl.mainlens, "FOCAL_MM FSTOP MLA_DISTANCE_MM PITCH_UM",                \
         "layout: the plenoptic camera's main lens and microlens array", R_POS, .count = 4, .given = &fl.g_main},    \
        {"--threads", NULL, LF_ARG_INT, &opt.threads, "N", "threads (default 0: all cores)", R_IN(0, 1024)},       \
        {"--allow-nonfinite", NULL, LF_ARG_FLAG, &opt.allow_nonfinite, NULL,                                      \
         "treat NaN/Inf raw pixels as missing samples instead of failing"}

#define OUTPUT_FLAG(what) {"--output", "-o", LF_ARG_STRING, &opt.output, "OUT", what, .flags = LF_ARG_REQUIRED}
#define PICTURE_FLAGS                                                                                              \
    {"--exposure", NULL, LF_ARG_DOUBLE, &opt.exposure, "EV", "8-bit outputs: scale by 2^EV before the tone curve",  \
     R_IN(-64, 64)},                                                                                                \
        {"--tonemap", NULL, LF_ARG_CHOICE, &opt.tonemap, "CURVE", "8-bit outputs: the tone curve (default clamp)", \
         .choices = "clamp|filmic|aces"}
#define FOCUS_FLAGS                                                                                                \
    {"--alpha", NULL, LF_ARG_DOUBLE, &opt.alpha, "A", "synthetic film at alpha F (Ng 2005)", R_POS,               \
     .given = &opt.have_alpha},                                                                                    \
        {"--depth", NULL, LF_ARG_DOUBLE, &opt.depth, "M", "the depth brought into focus (m)", R_POS,              \
         .given = &opt.have_depth},                                                                                \
        {"--disparity", NULL, LF_ARG_DOUBLE, &opt.disp, "PX", "the disparity brought into focus (px per view)",    \
         .given = &opt.have_disp}
#define APERTURE_FLAGS                                                                                             \
    {"--aperture", NULL, LF_ARG_DOUBLE, &opt.aperture, "R", "synthetic aperture radius (views from the centre)",   \
     R_MIN(0), .given = &opt.have_aperture},                                                                       \
        {"--views", NULL, LF_ARG_INT, opt.views, "U0 U1 V0 V1", "use only views [U0,U1] x [V0,V1]",                \
         R_IN(0, 1 << 20), .count = 4, .given = &opt.have_views}
#define RANGE_FLAGS(lo)                                                                                            \
    {"--from", NULL, LF_ARG_DOUBLE, &opt.from, "D0", "lowest disparity (px per view)", .given = &opt.have_from},   \
        {"--to", NULL, LF_ARG_DOUBLE, &opt.to, "D1", "highest disparity (px per view)", .given = &opt.have_to},    \
        {"--steps", NULL, LF_ARG_INT, &opt.steps, "N", "slices between them", R_IN(lo, 4096),                     \
         .given = &opt.have_steps}

static const lf_arg info_args[] = {LAYOUT_FLAGS};
static const lf_arg decode_args[] = {
    OUTPUT_FLAG("folder of views (view_ROW_COL) and mosaic"), LAYOUT_FLAGS, PICTURE_FLAGS,
    {"--format", NULL, LF_ARG_CHOICE, &opt.format, "FMT", "views as exr (default) or png", .choices = "exr|png"},
    {"--white", NULL, LF_ARG_STRING, &opt.white, "WHITE.exr", "divide by a white image (devignetting)"},
    {"--layout", NULL, LF_ARG_CHOICE, &opt.hci, "hci",
     "write the HCI benchmark layout (input_CamNNN.png, parameters.cfg, gt_disp_lowres.pfm)", .choices = "hci"},
};
static const lf_arg calibrate_args[] = {
    OUTPUT_FLAG("the white image with the estimated layout attributes"),
    {"--grid", NULL, LF_ARG_CHOICE, &fl.grid, "GRID", "microlens grid square or hex (default: estimated)",
     .choices = "square|hex", .given = &fl.g_grid},
};
static const lf_arg refocus_args[] = {
    OUTPUT_FLAG("the refocused image"), FOCUS_FLAGS, APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
    {"--white", NULL, LF_ARG_STRING, &opt.white, "WHITE.exr", "divide by a white image (devignetting)"},
    {"--method", NULL, LF_ARG_CHOICE, &opt.method, "METHOD", "shift-and-add (default) or Fourier slice",
     .choices = "shift|fourier"},
    {"--oversample", NULL, LF_ARG_DOUBLE, &opt.oversample, "S", "Fourier slice: spectrum oversampling (default 2)",
     R_IN(1, 8)},
};
static const lf_arg stack_args[] = {
    OUTPUT_FLAG("folder of slices stack_NNN"), RANGE_FLAGS(2), APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
    {"--format", NULL, LF_ARG_CHOICE, &opt.format, "FMT", "slices as exr (default) or png", .choices = "exr|png"},
};
static const lf_arg allfocus_args[] = {
    OUTPUT_FLAG("the all-in-focus image"), RANGE_FLAGS(2), APERTURE_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
};
static const lf_arg depth_args[] = {
    OUTPUT_FLAG("disparity map: .exr/.pfm values, .png a colour map with a legend"), RANGE_FLAGS(3), APERTURE_FLAGS,
    LAYOUT_FLAGS,
    {"--confidence", NULL, LF_ARG_STRING, &opt.confidence, "C.exr", "also write the confidence map"},
    {"--calibrate-views", NULL, LF_ARG_FLAG, &opt.calibrate_views, NULL,
     "fit each view's position and pixel offset to the data first (docs/depth.md)"},
    {"--method", NULL, LF_ARG_CHOICE, &opt.method, "METHOD",
     "volume: cost volume with occlusion handling (default); stack: focal-stack contrast",
     .choices = "volume|stack"},
};
static const lf_arg view_args[] = {
    OUTPUT_FLAG("the synthesized view"), FOCUS_FLAGS, LAYOUT_FLAGS, PICTURE_FLAGS,
    {"--u", NULL, LF_ARG_DOUBLE, &opt.u, "U", "viewpoint, in view steps right of the centre", .given = &opt.have_u,
     .flags = LF_ARG_REQUIRED},
    {"--v", NULL, LF_ARG_DOUBLE, &opt.v, "V", "viewpoint, in view steps below the centre", .given = &opt.have_v,
     .flags = LF_ARG_REQUIRED},
    {"--geometry", NULL, LF_ARG_CHOICE, &opt.geometry, "GEOM",
     "depth: per-pixel disparity (default); plane: blend on one plane", .choices = "depth|plane"},
    {"--disparity-map", NULL, LF_ARG_STRING, &opt.dispmap, "D.exr", "use this disparity map instead of estimating"},
    {"--confidence", NULL, LF_ARG_STRING, &opt.confidence, "C.exr", "its confidence (with --disparity-map)"},
    {"--calibrate-views", NULL, LF_ARG_FLAG, &opt.calibrate_views, NULL,
     "fit each view's position and pixel offset to the data first (docs/depth.md)"},
};
static const lf_arg synth_args[] = {
    LAYOUT_FLAGS, PICTURE_FLAGS,
    {"--samplesperpixel", NULL, LF_ARG_INT, &fl.spp, "N", "samples per pixel", R_IN(1, 1 << 20), .given = &fl.g_spp},
    {"--focaldistance", NULL, LF_ARG_DOUBLE, &fl.focal, "D", "virtual focal plane distance", R_POS,
     .given = &opt.have_focal},
    {"--camerapos", NULL, LF_ARG_DOUBLE, fl.pos, "X Y Z", "virtual camera position", .count = 3,
     .given = &opt.have_pos},
    {"--camerarot", NULL, LF_ARG_DOUBLE, fl.rot, "X Y Z", "virtual camera rotation (degrees)", .count = 3,
     .given = &fl.g_rot3},
    {"--outputfov", NULL, LF_ARG_DOUBLE, &fl.outfov, "DEG", "virtual camera field of view", .min = 0, .max = 180,
     .flags = LF_ARG_MIN_OPEN | LF_ARG_MAX_OPEN, .given = &opt.have_outfov},
    {"--lensradius", NULL, LF_ARG_DOUBLE, &fl.lensradius, "R", "virtual lens radius (0: pinhole)", R_MIN(0),
     .given = &fl.g_lensradius},
    {"--outputdim", NULL, LF_ARG_INT, fl.outdim, "W H", "output size in pixels", R_IN(1, 65536), .count = 2,
     .given = &opt.have_outdim},
    {"--coverage", NULL, LF_ARG_STRING, &opt.coverage, "COV.exr", "also write where rays left the captured aperture"},
    {"--seed", NULL, LF_ARG_LONG, &fl.seed, "S", "sampler seed", R_IN(0, 4294967295.0), .given = &fl.g_seed},
    {"--geometry", NULL, LF_ARG_CHOICE, &opt.geometry, "GEOM", "depth: look data up on the estimated surface",
     .choices = "depth|plane"},
    {"--disparity-map", NULL, LF_ARG_STRING, &opt.dispmap, "D.exr", "with --geometry depth: this disparity map"},
};
static const lf_arg web_args[] = {
    OUTPUT_FLAG("folder for index.html, lf.js and data.js"), LAYOUT_FLAGS,
    {"--format", NULL, LF_ARG_CHOICE, &opt.format, "FMT", "atlases as jpg (default) or png", .choices = "jpg|png"},
    {"--from", NULL, LF_ARG_DOUBLE, &opt.from, "D0", "lowest disparity (px per view)", .given = &opt.have_from},
    {"--to", NULL, LF_ARG_DOUBLE, &opt.to, "D1", "highest disparity (px per view)", .given = &opt.have_to},
    {"--steps", NULL, LF_ARG_INT, &opt.steps, "N", "focal-stack slices (default 9)", R_IN(2, 64),
     .given = &opt.have_steps},
};
static const lf_arg serve_args[] = {
    {"--port", NULL, LF_ARG_INT, &opt.port, "P", "port on 127.0.0.1 (default 8000; 0: any free)", R_IN(0, 65535)},
};

/* Turns the gathered layout and synth flags into opt.flags and opt.synth. */
static void apply_flags(void)
{
    lf_lf_layout *f = &opt.flags;
    lf_lf_layout_init(f);
    if (fl.g_kind)
        f->kind = strcmp(fl.kind, "plenoptic") ? LF_LF_CAMERA_ARRAY : LF_LF_PLENOPTIC, f->have |= LF_LF_HAVE_KIND;
    if (fl.g_cams)
        f->cams_x = fl.cams[0], f->cams_y = fl.cams[1], f->kind = LF_LF_CAMERA_ARRAY,
        f->have |= LF_LF_HAVE_CAMS | LF_LF_HAVE_KIND;
    if (fl.g_griddim)
        memcpy(f->grid_bounds, fl.griddim, sizeof f->grid_bounds), f->have |= LF_LF_HAVE_BOUNDS;
    if (fl.g_fov)
        f->fov_deg = fl.fov, f->have |= LF_LF_HAVE_FOV;
    if (fl.g_tile)
        f->tile_w = fl.tile[0], f->tile_h = fl.tile[1], f->have |= LF_LF_HAVE_TILE;
    if (fl.g_grid)
        f->grid = strcmp(fl.grid, "hex") ? LF_LF_GRID_SQUARE : LF_LF_GRID_HEX, f->have |= LF_LF_HAVE_GRID;
    if (fl.g_pitch)
        f->pitch_px = fl.pitch, f->have |= LF_LF_HAVE_PITCH;
    if (fl.g_rot)
        f->rotation_rad = fl.rotation, f->have |= LF_LF_HAVE_ROTATION;
    if (fl.g_offset)
        f->offset_px[0] = fl.offset[0], f->offset_px[1] = fl.offset[1], f->have |= LF_LF_HAVE_OFFSET;
    if (fl.g_lenses)
        f->lens_x = fl.lenses[0], f->lens_y = fl.lenses[1], f->have |= LF_LF_HAVE_LENS_COUNT;
    if (fl.g_main)
        f->main_focal_mm = fl.mainlens[0], f->main_fstop = fl.mainlens[1], f->mla_distance_mm = fl.mainlens[2],
        f->pitch_um = fl.mainlens[3], f->have |= LF_LF_HAVE_MAIN_LENS;
    lf_lf_synth_opts *s = &opt.synth;
    *s = lf_lf_synth_defaults();
    s->threads = opt.threads;
    if (fl.g_spp)
        s->spp = fl.spp;
    if (opt.have_focal)
        s->focal_distance = fl.focal;
    if (opt.have_pos)
        memcpy(s->pos, fl.pos, sizeof s->pos);
    if (fl.g_rot3)
        memcpy(s->rot_deg, fl.rot, sizeof s->rot_deg);
    if (opt.have_outfov)
        s->fov_deg = fl.outfov;
    if (fl.g_lensradius)
        s->lens_radius = fl.lensradius;
    if (opt.have_outdim)
        s->width = fl.outdim[0], s->height = fl.outdim[1];
    if (fl.g_seed)
        s->seed = (uint32_t)fl.seed;
}

/* ---------- loading ---------- */

typedef struct loaded {
    lf_image raw;
    lf_attrs attrs;
    lf_lf_layout layout;
    lf_lightfield lf;
    lf_lf_folder folder; /* when the input is a folder of views (folder.dir != NULL) */
} loaded;

static void unload(loaded *l)
{
    lf_lf_free(&l->lf);
    lf_image_free(&l->raw);
    lf_attrs_free(&l->attrs);
    lf_lf_folder_free(&l->folder);
}

/* A folder of views (docs/lightfield-format.md): every view is read, even
 * for info, so a missing or unreadable view is reported at once. */
static int load_folder(const opts *o, loaded *l)
{
    lf_error err = {0};
    if (o->white) {
        fprintf(stderr, "lftool: %s: --white applies to raws, not to a folder of views\n", o->input);
        return EXIT_INPUT;
    }
    if (lf_lf_folder_scan(o->input, &l->folder, &err) || lf_lf_folder_load(&l->folder, &o->flags, &l->lf, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        unload(l);
        return EXIT_INPUT;
    }
    l->layout = l->lf.layout;
    if (l->lf.nonfinite && !o->allow_nonfinite) {
        fprintf(stderr,
                "lftool: %s: %zu non-finite pixel values (NaN/Inf); pass --allow-nonfinite to treat them as "
                "missing samples\n",
                o->input, l->lf.nonfinite);
        unload(l);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

/* Reads the raw (or folder of views), resolves its layout (attributes +
 * flags); decodes unless layout_only. Prints the error and returns
 * EXIT_INPUT on failure. */
static int load(const opts *o, loaded *l, int layout_only)
{
    memset(l, 0, sizeof *l);
    if (lf_lf_is_folder(o->input))
        return load_folder(o, l);
    lf_error err = {0};
    if (lf_image_read(o->input, &l->raw, &l->attrs, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        return EXIT_INPUT;
    }
    lf_lf_layout file;
    if (lf_lf_layout_from_attrs(&l->attrs, &file, &err) ||
        lf_lf_layout_resolve(&file, &o->flags, l->raw.width, l->raw.height, &l->layout, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(l);
        return EXIT_INPUT;
    }
    size_t bad = lf_image_count_nonfinite(&l->raw);
    if (bad && !o->allow_nonfinite && !layout_only) {
        fprintf(stderr,
                "lftool: %s: %zu non-finite pixel values (NaN/Inf); pass --allow-nonfinite to treat them as "
                "missing samples\n",
                o->input, bad);
        unload(l);
        return EXIT_INPUT;
    }
    if (layout_only)
        return EXIT_OK;
    lf_image white = {0};
    if (o->white && lf_image_read(o->white, &white, NULL, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        unload(l);
        return EXIT_INPUT;
    }
    int rc = lf_lf_decode(&l->raw, &l->layout, o->white ? &white : NULL, &l->lf, &err);
    lf_image_free(&white);
    if (rc) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(l);
        return EXIT_INPUT;
    }
    if (l->lf.nonfinite)
        fprintf(stderr, "lftool: %s: warning: %zu non-finite pixel values excluded as missing samples\n", o->input,
                l->lf.nonfinite);
    return EXIT_OK;
}

static int write_image(const char *path, const lf_image *img, const lf_attrs *a)
{
    lf_error err = {0};
    lf_write_opts wo = {0};
    wo.exposure = (float)opt.exposure;
    if (opt.tonemap)
        lf_tonemap_parse(opt.tonemap, &wo.tonemap);
    if (lf_image_write(path, img, a, &wo, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

static int need_output(const opts *o)
{
    if (!o->output)
        return usage("%s needs -o OUTPUT", o->cmd);
    return 0;
}

static int make_dir(const char *dir)
{
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "lftool: cannot create directory %s: %s\n", dir, strerror(errno));
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

static lf_image view_image(const lf_lightfield *lf, int iu, int iv)
{
    lf_image v = {lf->ns, lf->nt, 3, lf_lf_view(lf, iu, iv)};
    return v;
}

/* ---------- commands ---------- */

static int cmd_info(const opts *o)
{
    loaded l;
    int rc = load(o, &l, 1);
    if (rc)
        return rc;
    char buf[2048];
    lf_lf_layout_describe(&l.layout, buf, sizeof buf);
    if (l.folder.dir) {
        printf("%s: folder of %d x %d views (%s layout, %s)\n%s", o->input, l.lf.nu, l.lf.nv,
               l.folder.kind == LF_LF_FOLDER_HCI ? "HCI" : "row/column", l.folder.pattern, buf);
        if (l.lf.disp_per_inv_m > 0)
            printf("disparity %.6g + %.6g / depth px per view step\n", l.lf.disp_at_inf, l.lf.disp_per_inv_m);
        if (l.folder.gt_disparity)
            printf("ground-truth disparity: %s\n", l.folder.gt_disparity);
        if (l.lf.nonfinite)
            printf("non-finite pixel values: %zu\n", l.lf.nonfinite);
        unload(&l);
        return EXIT_OK;
    }
    printf("%s: %d x %d raw, %d channels\n%s", o->input, l.raw.width, l.raw.height, l.raw.channels, buf);
    size_t bad = lf_image_count_nonfinite(&l.raw);
    if (bad)
        printf("non-finite pixel values: %zu\n", bad);
    unload(&l);
    return EXIT_OK;
}

/* The centre view's ground-truth disparity (docs/lightfield-format.md,
 * "Disparity AOV"): from the render's disparity image named by the raw's
 * lensfield:disparity_file, decoded with the raw's layout, or a folder's
 * gt_disp_lowres.pfm.  *gt stays empty when there is none. */
static int centre_disparity(const opts *o, const loaded *l, lf_image *gt)
{
    memset(gt, 0, sizeof *gt);
    lf_error err = {0};
    if (l->folder.dir) {
        if (l->folder.gt_disparity && lf_image_read(l->folder.gt_disparity, gt, NULL, &err)) {
            fprintf(stderr, "lftool: %s\n", err.msg);
            return EXIT_INPUT;
        }
        return EXIT_OK;
    }
    const lf_attr *a = lf_attrs_get(&l->attrs, LF_KEY_DISPARITY_FILE);
    if (!a || a->type != LF_ATTR_STRING || !a->s[0])
        return EXIT_OK;
    if (l->lf.nu % 2 == 0 || l->lf.nv % 2 == 0) {
        fprintf(stderr, "lftool: %s: note: %d x %d views have no centre view; gt_disp_lowres.pfm not written\n",
                o->input, l->lf.nu, l->lf.nv);
        return EXIT_OK;
    }
    char path[PATH_MAX];
    const char *slash = strrchr(o->input, '/');
    if (a->s[0] == '/' || !slash)
        snprintf(path, sizeof path, "%s", a->s);
    else
        snprintf(path, sizeof path, "%.*s/%s", (int)(slash - o->input), o->input, a->s);
    lf_image raw = {0};
    lf_lightfield d = {0};
    if (lf_image_read(path, &raw, NULL, &err) ||
        (raw.width != l->raw.width || raw.height != l->raw.height
             ? lf_error_set(&err, LF_ERR_PARAM, "%s is %d x %d, the raw %d x %d", path, raw.width, raw.height,
                            l->raw.width, l->raw.height)
             : 0) ||
        lf_lf_decode(&raw, &l->layout, NULL, &d, &err) || lf_image_alloc(gt, d.ns, d.nt, 1, &err)) {
        fprintf(stderr, "lftool: %s: disparity: %s\n", o->input, err.msg);
        lf_image_free(&raw), lf_lf_free(&d), lf_image_free(gt);
        return EXIT_INPUT;
    }
    const float *v = lf_lf_view(&d, d.nu / 2, d.nv / 2);
    for (size_t i = 0; i < (size_t)d.ns * d.nt; i++)
        gt->data[i] = v[i * 3];
    lf_image_free(&raw), lf_lf_free(&d);
    return EXIT_OK;
}

static int cmd_decode(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    const lf_lightfield *lf = &l.lf;
    if (o->hci) {
        lf_image gt;
        lf_error err = {0};
        if (!(rc = centre_disparity(o, &l, &gt)) && lf_lf_write_hci(o->output, lf, gt.data ? &gt : NULL, &err)) {
            fprintf(stderr, "lftool: %s\n", err.msg);
            rc = EXIT_INPUT;
        }
        if (!rc)
            printf("%s: %d x %d views of %d x %d -> %s (HCI layout%s; %zu missing samples)\n", o->input, lf->nu,
                   lf->nv, lf->ns, lf->nt, o->output, gt.data ? ", gt_disp_lowres.pfm" : "", lf->missing);
        lf_image_free(&gt);
        unload(&l);
        return rc;
    }
    const char *ext = o->format ? o->format : "exr";
    if ((rc = make_dir(o->output))) {
        unload(&l);
        return rc;
    }
    char path[4096];
    for (int iv = 0; iv < lf->nv && !rc; iv++)
        for (int iu = 0; iu < lf->nu && !rc; iu++) {
            lf_image v = view_image(lf, iu, iv);
            snprintf(path, sizeof path, "%s/view_%02d_%02d.%s", o->output, iv, iu, ext); /* row, column */
            rc = write_image(path, &v, NULL);
        }
    /* mosaic: views tiled as the cameras sit (view (0,0) top-left) */
    lf_image m;
    lf_error err = {0};
    if (!rc && !lf_image_alloc(&m, lf->ns * lf->nu, lf->nt * lf->nv, 3, &err)) {
        for (int iv = 0; iv < lf->nv; iv++)
            for (int iu = 0; iu < lf->nu; iu++)
                for (int t = 0; t < lf->nt; t++)
                    memcpy(lf_image_px(&m, iu * lf->ns, iv * lf->nt + t), lf_lf_view(lf, iu, iv) + (size_t)t * lf->ns * 3,
                           sizeof(float) * 3 * lf->ns);
        snprintf(path, sizeof path, "%s/mosaic.%s", o->output, ext);
        rc = write_image(path, &m, NULL);
        lf_image_free(&m);
    }
    if (!rc)
        printf("%s: %d x %d views of %d x %d -> %s (%zu missing samples)\n", o->input, lf->nu, lf->nv, lf->ns, lf->nt,
               o->output, lf->missing);
    unload(&l);
    return rc;
}

/* disparity from exactly one of --alpha, --depth, --disparity */
static int focus_disparity(const opts *o, const lf_lightfield *lf, double *d, int required)
{
    int n = o->have_alpha + o->have_depth + o->have_disp;
    if (n > 1)
        return usage("%s", "give one of --alpha, --depth, --disparity");
    if (n == 0) {
        if (required)
            return usage("%s", "refocus needs --alpha A, --depth METRES or --disparity PX");
        *d = 0;
        return 0;
    }
    lf_error err = {0};
    int rc = 0;
    if (o->have_alpha)
        rc = lf_lf_alpha_to_disparity(lf, o->alpha, d, &err);
    else if (o->have_depth)
        rc = lf_lf_depth_to_disparity(lf, o->depth, d, &err);
    else
        *d = o->disp;
    if (rc) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        return EXIT_INPUT;
    }
    return 0;
}

static lf_lf_refocus_opts aperture_opts(const opts *o)
{
    lf_lf_refocus_opts r = lf_lf_refocus_defaults();
    if (o->have_aperture)
        r.aperture_radius = o->aperture;
    if (o->have_views)
        r.u0 = o->views[0], r.u1 = o->views[1], r.v0 = o->views[2], r.v1 = o->views[3];
    r.threads = o->threads;
    return r;
}

/* Ng 2005's range of exact refocusing of a plenoptic raw (docs/lightfield.md,
 * "Refocusable range"): |d| <= 1 px/view, i.e. |1 - 1/alpha| <= P p / D.
 * Outside it the sub-aperture views are themselves blurred: warn, go on. */
static void refocus_range_warning(const opts *o, const lf_lightfield *lf, double d)
{
    if (lf->disp_per_alpha == 0 || !(fabs(d) > 1.0 + 1e-9))
        return;
    double k = lf->disp_per_inv_m, d_inf = lf->disp_at_inf, b = 1.0 / lf->disp_per_alpha;
    char asked[96], far[32], amax[32];
    if (o->have_depth)
        snprintf(asked, sizeof asked, "depth %g m", o->depth);
    else if (o->have_alpha)
        snprintf(asked, sizeof asked, "alpha %g", o->alpha);
    else
        snprintf(asked, sizeof asked, "disparity %g px/view", d);
    if (k > 0 && -1.0 - d_inf > 0)
        snprintf(far, sizeof far, "%.4g m", k / (-1.0 - d_inf));
    else
        snprintf(far, sizeof far, "infinity");
    if (b < 1.0)
        snprintf(amax, sizeof amax, "%.5g", 1.0 / (1.0 - b));
    else
        snprintf(amax, sizeof amax, "infinity");
    fprintf(stderr,
            "lftool: warning: %s: %s (disparity %.3g px/view) is outside the refocusable range (Ng 2005: "
            "|disparity| <= 1 px/view, alpha %.5g .. %s, depths %.4g m .. %s): the sub-aperture views are blurred "
            "there, so the result is softer than a photograph focused at that depth\n",
            o->input, asked, d, 1.0 / (1.0 + b), amax, k > 0 && 1.0 - d_inf > 0 ? k / (1.0 - d_inf) : INFINITY, far);
}

static int cmd_refocus(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    if (o->have_alpha + o->have_depth + o->have_disp != 1)
        return usage("%s", "refocus needs exactly one of --alpha A, --depth METRES, --disparity PX");
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    lf_lf_refocus_opts ro = aperture_opts(o);
    if ((rc = focus_disparity(o, &l.lf, &ro.disparity_px, 1))) {
        unload(&l);
        return rc;
    }
    refocus_range_warning(o, &l.lf, ro.disparity_px);
    lf_error err = {0};
    lf_image out = {0};
    if (o->method && !strcmp(o->method, "fourier")) {
        lf_lf_fourier *f = NULL;
        rc = lf_lf_fourier_new(&l.lf, &ro, o->oversample, &f, &err) ||
             lf_lf_fourier_refocus(f, ro.disparity_px, &out, &err);
        lf_lf_fourier_release(f);
    } else {
        rc = lf_lf_refocus(&l.lf, &ro, &out, &err);
    }
    if (rc) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    lf_attrs a = {0};
    lf_attrs_set_double(&a, LF_KEY_REFOCUS_DISPARITY_PX, ro.disparity_px);
    rc = write_image(o->output, &out, &a);
    if (!rc)
        printf("%s: refocused at disparity %.6g px/view -> %s\n", o->input, ro.disparity_px, o->output);
    lf_attrs_free(&a);
    lf_image_free(&out);
    unload(&l);
    return rc;
}

static int stack_range(const opts *o, const lf_lightfield *lf, double *d0, double *d1)
{
    if (!o->have_from || !o->have_to) {
        /* default: the disparities of the largest aperture, +-1 px per view */
        (void)lf;
        *d0 = o->have_from ? o->from : -1, *d1 = o->have_to ? o->to : 1;
    } else {
        *d0 = o->from, *d1 = o->to;
    }
    if (o->steps < 2)
        return usage("%s", "--steps must be >= 2");
    return 0;
}

static int cmd_stack(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    double d0, d1;
    if ((rc = stack_range(o, &l.lf, &d0, &d1)) || (rc = make_dir(o->output))) {
        unload(&l);
        return rc;
    }
    lf_lf_refocus_opts ro = aperture_opts(o);
    for (int k = 0; k < o->steps && !rc; k++) {
        ro.disparity_px = d0 + (d1 - d0) * k / (o->steps - 1);
        lf_image out;
        lf_error err = {0};
        if (lf_lf_refocus(&l.lf, &ro, &out, &err)) {
            fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
            rc = EXIT_INPUT;
            break;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/stack_%03d.%s", o->output, k, o->format ? o->format : "exr");
        lf_attrs a = {0};
        lf_attrs_set_double(&a, LF_KEY_REFOCUS_DISPARITY_PX, ro.disparity_px);
        rc = write_image(path, &out, &a);
        lf_attrs_free(&a);
        lf_image_free(&out);
    }
    if (!rc)
        printf("%s: %d slices, disparity %g .. %g -> %s\n", o->input, o->steps, d0, d1, o->output);
    unload(&l);
    return rc;
}

static int cmd_allfocus_depth(const opts *o, int want_depth)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    double d0, d1;
    if ((rc = stack_range(o, &l.lf, &d0, &d1))) {
        unload(&l);
        return rc;
    }
    lf_lf_refocus_opts ro = aperture_opts(o);
    lf_image af, dm;
    lf_error err = {0};
    if (lf_lf_allfocus(&l.lf, &ro, d0, d1, o->steps, &af, &dm, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    rc = write_image(o->output, want_depth ? &dm : &af, NULL);
    if (!rc)
        printf("%s: %s from %d slices (disparity %g .. %g) -> %s\n", o->input, want_depth ? "disparity map" : "all-in-focus",
               o->steps, d0, d1, o->output);
    lf_image_free(&af), lf_image_free(&dm);
    unload(&l);
    return rc;
}

static int cmd_allfocus(const opts *o) { return cmd_allfocus_depth(o, 0); }
/* Disparity range for depth: --from/--to, else lensfield:disp_min/max of
 * the input (a benchmark folder's [meta] disp_min/disp_max), else 0 0
 * (estimated from the data).  Returns the source's name. */
static const char *depth_range(const opts *o, const lf_attrs *attrs, const lf_lf_layout *lay, double *d0, double *d1)
{
    *d0 = *d1 = 0;
    if (o->have_from && o->have_to) {
        *d0 = o->from, *d1 = o->to;
        return "--from/--to";
    }
    if ((lay->have & LF_LF_HAVE_DISP_RANGE) && lay->disp_min < lay->disp_max) { /* a folder's parameters.cfg */
        *d0 = lay->disp_min, *d1 = lay->disp_max;
        return "the folder's disp_min/disp_max";
    }
    const lf_attr *a = lf_attrs_get(attrs, LF_KEY_DISP_MIN), *b = lf_attrs_get(attrs, LF_KEY_DISP_MAX);
    if (a && b) {
        double x = a->type == LF_ATTR_INT ? a->i : a->d, y = b->type == LF_ATTR_INT ? b->i : b->d;
        if (isfinite(x) && isfinite(y) && x < y) {
            *d0 = x, *d1 = y;
            return "lensfield:disp_min/max";
        }
    }
    return "estimated";
}

static int cmd_depth(const opts *o)
{
    if (o->method && !strcmp(o->method, "stack"))
        return cmd_allfocus_depth(o, 1);
    int rc = need_output(o);
    if (rc)
        return rc;
    if (o->have_from != o->have_to)
        return usage("%s", "depth: give both --from and --to, or neither (range from the file or the data)");
    if (o->have_from && !(o->from < o->to))
        return usage("%s", "depth: --from must be below --to");
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    lf_lf_depth_opts d = lf_lf_depth_defaults();
    d.threads = o->threads;
    const char *src = depth_range(o, &l.attrs, &l.lf.layout, &d.d0, &d.d1);
    lf_error err = {0};
    if (d.d0 >= d.d1 && lf_lf_depth_range(&l.lf, o->threads, &d.d0, &d.d1, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    if (o->have_steps) {
        if (o->steps < 3) {
            unload(&l);
            return usage("%s", "--steps must be >= 3");
        }
        d.step = (d.d1 - d.d0) / (o->steps - 1);
    }
    lf_image disp, conf;
    if (o->calibrate_views) { /* depth on the nominal grid, view positions fitted to it */
        if (lf_lf_depth(&l.lf, &d, &disp, &conf, &err) ||
            lf_lf_calibrate_views(&l.lf, &disp, &conf, o->threads, NULL, &err)) {
            fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
            unload(&l);
            return EXIT_INPUT;
        }
        lf_image_free(&disp), lf_image_free(&conf);
    }
    if (lf_lf_depth(&l.lf, &d, &disp, o->confidence ? &conf : NULL, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    lf_attrs a = {0};
    float range[2] = {(float)d.d0, (float)d.d1};
    lf_attrs_set_floats(&a, LF_KEY_DISPARITY_SEARCH_RANGE, range, 2);
    lf_attrs_set_string(&a, LF_KEY_DISPARITY_CONVENTION,
                        "I_centre(x, y) = I_(iu,iv)(x - d (iu - iu_c), y - d (iv - iv_c)), px per view step");
    const char *dot = strrchr(o->output, '.');
    if (dot && (!strcasecmp(dot, ".png") || !strcasecmp(dot, ".jpg") || !strcasecmp(dot, ".jpeg"))) {
        /* a picture of the map: the colour map over the search range, with its legend */
        lf_image pic;
        if (lf_image_colormap(&disp, d.d0, d.d1, &pic, &err)) {
            fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
            rc = EXIT_INPUT;
        } else {
            rc = write_image(o->output, &pic, NULL);
            lf_image_free(&pic);
        }
    } else {
        rc = write_image(o->output, &disp, &a);
    }
    if (!rc && o->confidence)
        rc = write_image(o->confidence, &conf, NULL);
    if (!rc)
        printf("%s: disparity map (range %.4g .. %.4g px/view, %s) -> %s%s%s\n", o->input, d.d0, d.d1, src, o->output,
               o->confidence ? ", confidence -> " : "", o->confidence ? o->confidence : "");
    if (rc) /* no half-written result: the disparity map goes with its confidence */
        remove(o->output);
    lf_attrs_free(&a);
    lf_image_free(&disp);
    if (o->confidence)
        lf_image_free(&conf);
    unload(&l);
    return rc;
}

/* A 1-channel map of the views' size (first channel of a colour image). */
static int read_map(const char *path, const lf_lightfield *lf, lf_image *m)
{
    lf_image img;
    lf_error err = {0};
    if (lf_image_read(path, &img, NULL, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        return EXIT_INPUT;
    }
    if (img.width != lf->ns || img.height != lf->nt) {
        fprintf(stderr, "lftool: %s: map is %dx%d, the views are %dx%d\n", path, img.width, img.height, lf->ns, lf->nt);
        lf_image_free(&img);
        return EXIT_INPUT;
    }
    if (lf_image_alloc(m, img.width, img.height, 1, &err)) {
        lf_image_free(&img);
        fprintf(stderr, "lftool: %s\n", err.msg);
        return EXIT_INPUT;
    }
    for (size_t i = 0; i < (size_t)img.width * img.height; i++)
        m->data[i] = img.data[i * img.channels];
    lf_image_free(&img);
    if (lf_image_count_nonfinite(m)) {
        fprintf(stderr, "lftool: %s: non-finite values in the map\n", path);
        lf_image_free(m);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

static int cmd_view(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    if (!o->have_u || !o->have_v)
        return usage("%s", "view needs --u U --v V");
    /* per-pixel geometry by default; the plane blend with --geometry plane
     * (or, as before, when a focus plane is given without --geometry) */
    int plane = o->geometry ? !strcmp(o->geometry, "plane") : (o->have_alpha + o->have_depth + o->have_disp) > 0;
    if (plane && o->dispmap)
        return usage("%s", "--disparity-map needs --geometry depth");
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    double d = 0;
    if ((rc = focus_disparity(o, &l.lf, &d, 0))) {
        unload(&l);
        return rc;
    }
    lf_image out, dm = {0}, cm = {0};
    lf_error err = {0};
    if (!plane && o->dispmap &&
        ((rc = read_map(o->dispmap, &l.lf, &dm)) || (o->confidence && (rc = read_map(o->confidence, &l.lf, &cm))))) {
        lf_image_free(&dm);
        unload(&l);
        return rc;
    }
    if (!plane && o->calibrate_views) { /* from the given map, or one estimated on the nominal grid */
        lf_image ed = {0}, ec = {0};
        lf_lf_depth_opts dopt = lf_lf_depth_defaults();
        dopt.threads = o->threads;
        rc = o->dispmap ? lf_lf_calibrate_views(&l.lf, &dm, o->confidence ? &cm : NULL, o->threads, NULL, &err)
                        : (lf_lf_depth(&l.lf, &dopt, &ed, &ec, &err) ||
                           lf_lf_calibrate_views(&l.lf, &ed, &ec, o->threads, NULL, &err));
        lf_image_free(&ed), lf_image_free(&ec);
        if (rc) {
            fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
            lf_image_free(&dm), lf_image_free(&cm);
            unload(&l);
            return EXIT_INPUT;
        }
    }
    if (plane)
        rc = lf_lf_view_at(&l.lf, o->u, o->v, d, &out, &err);
    else {
        lf_lf_view_opts vo = lf_lf_view_defaults();
        vo.threads = o->threads;
        vo.plane_disparity = d;
        vo.disparity = o->dispmap ? &dm : NULL;
        vo.confidence = o->dispmap && o->confidence ? &cm : NULL;
        rc = lf_lf_view_depth(&l.lf, o->u, o->v, &vo, &out, &err);
    }
    lf_image_free(&dm), lf_image_free(&cm);
    if (rc) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    rc = write_image(o->output, &out, NULL);
    lf_image_free(&out);
    unload(&l);
    return rc;
}

static int cmd_synth(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    const lf_lf_layout *y = &l.lf.layout;
    if (y->kind != LF_LF_CAMERA_ARRAY) {
        fprintf(stderr, "lftool: %s: synth needs a camera-array light field (lensfield:kind camera-array)\n", o->input);
        unload(&l);
        return EXIT_INPUT;
    }
    char missing[256] = "";
    if (!(y->have & LF_LF_HAVE_BOUNDS))
        strcat(missing, " lensfield:camera_grid_bounds (--griddim minx maxx miny maxy)");
    if (!(y->have & LF_LF_HAVE_FOV))
        strcat(missing, " lensfield:fov_deg (--inputfov DEG)");
    if (missing[0]) {
        fprintf(stderr, "lftool: %s: synth needs:%s\n", o->input, missing);
        unload(&l);
        return EXIT_INPUT;
    }
    lf_lf_synth_opts s = o->synth;
    if (!o->have_outfov)
        s.fov_deg = y->fov_deg;
    if (!o->have_outdim)
        s.width = l.lf.ns, s.height = l.lf.nt;
    if (!o->have_pos) {
        s.pos[0] = 0.5 * (y->grid_bounds[0] + y->grid_bounds[1]);
        s.pos[1] = 0.5 * (y->grid_bounds[2] + y->grid_bounds[3]);
        s.pos[2] = 0;
    }
    if (!o->have_focal && (y->have & LF_LF_HAVE_CAM_LENS) && y->focal_distance > 0)
        s.focal_distance = y->focal_distance;
    lf_image out, cov, dm = {0};
    size_t uncovered = 0;
    lf_error err = {0};
    if (o->geometry && !strcmp(o->geometry, "depth")) { /* per-pixel geometry (docs/depth.md) */
        lf_lf_depth_opts dop = lf_lf_depth_defaults();
        dop.threads = o->threads;
        if (o->dispmap)
            rc = read_map(o->dispmap, &l.lf, &dm);
        else if (lf_lf_depth(&l.lf, &dop, &dm, NULL, &err)) {
            fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
            rc = EXIT_INPUT;
        }
        if (rc) {
            unload(&l);
            return rc;
        }
        s.disparity = &dm;
    } else if (o->dispmap) {
        unload(&l);
        return usage("%s", "--disparity-map needs --geometry depth");
    }
    clock_t c0 = clock();
    if (lf_lf_synth(&l.lf, &s, &out, &cov, &uncovered, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        lf_image_free(&dm);
        unload(&l);
        return EXIT_INPUT;
    }
    lf_image_free(&dm);
    (void)c0;
    rc = write_image(o->output, &out, NULL);
    if (!rc && o->coverage)
        rc = write_image(o->coverage, &cov, NULL);
    if (!rc) {
        printf("%s: %dx%d, %d spp -> %s\n", o->input, s.width, s.height, s.spp, o->output);
        if (uncovered)
            fprintf(stderr, "lftool: %s: %zu of %d pixels have no ray inside the captured aperture%s\n", o->input,
                    uncovered, s.width * s.height, o->coverage ? " (see the coverage mask)" : "");
    }
    lf_image_free(&out), lf_image_free(&cov);
    unload(&l);
    return rc;
}

static int cmd_calibrate(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    lf_image white;
    lf_attrs a = {0}; /* only the estimated layout: the input's own header is not carried over */
    lf_error err = {0};
    if (lf_image_read(o->input, &white, NULL, &err)) {
        fprintf(stderr, "lftool: %s\n", err.msg);
        return EXIT_INPUT;
    }
    lf_lf_layout lay;
    lf_lf_layout_init(&lay);
    if (o->flags.have & LF_LF_HAVE_GRID)
        lay.grid = o->flags.grid, lay.have |= LF_LF_HAVE_GRID;
    if (lf_lf_calibrate(&white, &lay, &err) || lf_lf_layout_to_attrs(&lay, &a, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        lf_image_free(&white), lf_attrs_free(&a);
        return EXIT_INPUT;
    }
    lf_attrs_set_int(&a, LF_KEY_WHITE, 1);
    rc = write_image(o->output, &white, &a);
    if (!rc) {
        char buf[1024];
        lf_lf_layout_describe(&lay, buf, sizeof buf);
        printf("%s: estimated layout -> %s\n%s", o->input, o->output, buf);
        printf("flags: --kind plenoptic --grid %s --pitch %.6g --rotation %.6g --offset %.6g %.6g --lenscount %d %d\n",
               lay.grid == LF_LF_GRID_HEX ? "hex" : "square", lay.pitch_px, lay.rotation_rad, lay.offset_px[0],
               lay.offset_px[1], lay.lens_x, lay.lens_y);
    }
    lf_image_free(&white), lf_attrs_free(&a);
    return rc;
}

/* ---------- export-web and serve (web/lf_web.h, docs/web.md) ---------- */

static int cmd_export_web(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    if (o->have_from != o->have_to)
        return usage("%s", "export-web: give both --from and --to, or neither");
    lf_web_export_opts wo = lf_web_export_defaults();
    wo.format = o->format ? o->format : "jpg";
    wo.stack_slices = o->have_steps ? o->steps : 9;
    wo.have_range = o->have_from, wo.focus_min = o->from, wo.focus_max = o->to;
    wo.threads = o->threads;
    wo.source = o->input;
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    clock_t c0 = clock();
    lf_web_export_info info;
    lf_error err = {0};
    if (lf_web_export(&l.lf, o->output, &wo, &info, &err)) {
        fprintf(stderr, "lftool: export-web: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    printf("%s: %d x %d views of %d x %d, focus %.4g .. %.4g px/view, %d-slice stack -> %s/index.html "
           "(%.1f KiB, %.2f s CPU)\n",
           o->input, l.lf.nu, l.lf.nv, l.lf.ns, l.lf.nt, info.focus_min, info.focus_max, wo.stack_slices, o->output,
           info.page_bytes / 1024.0, (double)(clock() - c0) / CLOCKS_PER_SEC);
    unload(&l);
    return EXIT_OK;
}

static volatile sig_atomic_t serve_stop;
static void serve_on_signal(int sig)
{
    (void)sig;
    serve_stop = 1;
}

static int cmd_serve(const opts *o)
{
    lf_web_server *srv;
    lf_error err = {0};
    if (lf_web_server_open(o->input, o->port, &srv, &err)) {
        fprintf(stderr, "lftool: serve: %s\n", err.msg);
        return EXIT_INPUT;
    }
    struct sigaction sa = {0};
    sa.sa_handler = serve_on_signal; /* no SA_RESTART: accept() returns EINTR */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    printf("serving %s at http://127.0.0.1:%d/ (Ctrl-C stops)\n", lf_web_server_root(srv), lf_web_server_port(srv));
    fflush(stdout);
    int rc = LF_OK;
    while (!serve_stop && (rc == LF_OK || rc == LF_ERR_INTERRUPTED))
        rc = lf_web_server_serve_one(srv, &err);
    lf_web_server_close(srv);
    if (rc != LF_OK && rc != LF_ERR_INTERRUPTED) {
        fprintf(stderr, "lftool: serve: %s\n", err.msg);
        return EXIT_INPUT;
    }
    printf("stopped\n");
    return EXIT_OK;
}

#define RUNNER(name, fn)                  \
    static int run_##fn(int n, char **pos) \
    {                                     \
        opt.cmd = name;                   \
        opt.input = pos[0];               \
        if (n > 1)                        \
            opt.output = pos[1];          \
        apply_flags();                    \
        return fn(&opt);                  \
    }
RUNNER("info", cmd_info)
RUNNER("decode", cmd_decode)
RUNNER("calibrate", cmd_calibrate)
RUNNER("refocus", cmd_refocus)
RUNNER("stack", cmd_stack)
RUNNER("allfocus", cmd_allfocus)
RUNNER("depth", cmd_depth)
RUNNER("view", cmd_view)
RUNNER("synth", cmd_synth)
RUNNER("export-web", cmd_export_web)
RUNNER("serve", cmd_serve)

#define CMD(name, syn, sum, args, fn, desc) {name, syn, sum, args, LF_ARRAY_LEN(args), 1, 1, run_##fn, desc}
static const lf_command commands[] = {
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
     LF_ARRAY_LEN(synth_args), 2, 2, run_cmd_synth, NULL},
    CMD("export-web", "IN -o DIR [--format jpg|png] [--from D0 --to D1] [--steps N]",
        "a living picture for the web: click to focus, drag to move (docs/web.md)", web_args, cmd_export_web, NULL),
    CMD("serve", "DIR [--port P]", "serve DIR on http://127.0.0.1:P/ until Ctrl-C", serve_args, cmd_serve, NULL),
};

static const lf_tool tool = {
    "lftool", "decode, refocus and re-view light fields", LF_VERSION, commands, LF_ARRAY_LEN(commands),
    "IN is a light-field raw (EXR with lensfield:* attributes, or any image plus layout flags) or a folder of "
    "views: the HCI layout (input_CamNNN.png + parameters.cfg) or PREFIX_RR_CC.png|exr (docs/lightfield-format.md). "
    "Exit status: 0 success; 1 bad input (the message names the file); 2 bad command line."};

int main(int argc, char **argv)
{
    return lf_cli_main(&tool, argc, argv);
}
