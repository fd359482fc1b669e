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
#include <sys/stat.h>
#include <time.h>

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "web/lf_web.h"

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_USAGE = 2 };

static const char *usage_text =
    "usage: lftool COMMAND INPUT [flags]\n"
    "commands:\n"
    "  info RAW.exr                          layout from the lensfield:* attributes\n"
    "  decode RAW.exr -o DIR                 sub-aperture views + mosaic [--format exr|png] [--white W.exr]\n"
    "                                        [--layout hci]\n"
    "  calibrate WHITE.exr -o OUT.exr        estimate the microlens grid; OUT carries the layout attributes\n"
    "  refocus RAW.exr -o OUT                --alpha A | --depth M | --disparity PX; [--aperture R]\n"
    "                                        [--views u0 u1 v0 v1] [--method shift|fourier] [--oversample S]\n"
    "  stack RAW.exr -o DIR                  focal stack --from D0 --to D1 [--steps N] (disparities)\n"
    "  allfocus RAW.exr -o OUT               all-in-focus image from a stack (same flags)\n"
    "  depth RAW.exr -o OUT.exr|.pfm         disparity map of the centre view (docs/depth.md) [--from D0 --to D1]\n"
    "                                        [--confidence CONF.exr] [--method stack: focal-stack contrast]\n"
    "  view RAW.exr --u U --v V -o OUT       view from (U, V) in view units from the centre, per-pixel depth\n"
    "                                        [--disparity-map D.exr [--confidence C.exr]]; plane blend:\n"
    "                                        --geometry plane [--disparity PX]\n"
    "  synth LF.exr OUT.exr                  CS348B virtual camera: --samplesperpixel N --focaldistance D\n"
    "                                        [--geometry depth [--disparity-map D.exr]]\n"
    "                                        --camerapos x y z --camerarot x y z --inputfov DEG --outputfov DEG\n"
    "                                        --lensradius R --griddim minx maxx miny maxy --camsperdim nx ny\n"
    "                                        --outputdim w h [--coverage COV.exr] [--seed S]\n"
    "  export-web RAW.exr -o DIR             static web page: click to focus, drag to move the viewpoint\n"
    "                                        [--format jpg|png] [--from D0 --to D1] [--steps N] (docs/web.md)\n"
    "  serve DIR [--port P]                  serve DIR on http://127.0.0.1:P/ (default 8000) until Ctrl-C\n"
    "layout flags (when the file lacks attributes; they must agree with it otherwise):\n"
    "  --kind camera-array|plenoptic --camsperdim NX NY --griddim MINX MAXX MINY MAXY --inputfov DEG\n"
    "  --tilesize W H --grid square|hex --pitch PX --rotation RAD --offset X Y --lenscount NX NY\n"
    "  --mainlens FOCAL_MM FSTOP MLA_DISTANCE_MM MICROLENS_PITCH_UM\n"
    "other: --threads N, --allow-nonfinite (treat NaN/Inf raw pixels as missing samples), --help\n"
    "every RAW.exr / LF.exr may also be a folder of views (docs/lightfield-format.md): the HCI layout\n"
    "  (input_CamNNN.png + parameters.cfg) or PREFIX_RR_CC[...].png|exr (row, column; from 0 or 1);\n"
    "  decode --layout hci writes the HCI layout (with gt_disp_lowres.pfm when the raw has disparity)\n";

/* ---------- flags ---------- */

typedef struct opts {
    const char *cmd, *input, *output, *white, *format, *hci, *method, *coverage;
    const char *confidence, *dispmap, *geometry; /* depth, view, synth */
    lf_lf_layout flags;
    int have_alpha, have_depth, have_disp, have_aperture, have_views, have_from, have_to;
    double alpha, depth, disp, aperture, from, to, u, v, oversample;
    int have_u, have_v;
    int views[4], steps, threads, allow_nonfinite;
    /* synth */
    lf_lf_synth_opts synth;
    int have_outfov, have_outdim, have_pos, have_focal;
    /* export-web, serve */
    int port, have_steps;
} opts;

static int usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "lftool: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(lftool --help for usage)\n");
    return EXIT_USAGE;
}

static int num(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return s[0] && !*end && !errno && isfinite(*v);
}

/* Reads n numbers after flag argv[*i]; returns 0 on success. */
static int nums(int argc, char **argv, int *i, int n, double *v)
{
    if (*i + n >= argc)
        return usage("%s needs more values", argv[*i]);
    for (int k = 0; k < n; k++)
        if (!num(argv[*i + 1 + k], &v[k]))
            return usage("%s: not a number", argv[*i + 1 + k]);
    *i += n;
    return 0;
}

static int parse(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    lf_lf_layout_init(&o->flags);
    o->synth = lf_lf_synth_defaults();
    o->steps = 9;
    o->oversample = 2;
    o->port = 8000;
    o->cmd = argv[1];
    int positional = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        double v[4];
        lf_lf_layout *f = &o->flags;
#define NUMS(n)                                 \
    do {                                        \
        int rc_ = nums(argc, argv, &i, n, v);   \
        if (rc_)                                \
            return rc_;                         \
    } while (0)
#define STR(dst)                                           \
    do {                                                   \
        if (i + 1 >= argc)                                 \
            return usage("%s needs a value", a);           \
        dst = argv[++i];                                   \
    } while (0)
        if (!strcmp(a, "-o") || !strcmp(a, "--output"))
            STR(o->output);
        else if (!strcmp(a, "--white"))
            STR(o->white);
        else if (!strcmp(a, "--format")) {
            STR(o->format);
            if (!strcmp(o->cmd, "export-web")) {
                if (strcmp(o->format, "jpg") && strcmp(o->format, "png"))
                    return usage("--format %s: expected jpg or png", o->format);
            } else if (strcmp(o->format, "exr") && strcmp(o->format, "png"))
                return usage("--format %s: expected exr or png", o->format);
        } else if (!strcmp(a, "--layout")) {
            STR(o->hci);
            if (strcmp(o->hci, "hci"))
                return usage("--layout %s: only hci is known", o->hci);
        } else if (!strcmp(a, "--method")) {
            STR(o->method);
            if (strcmp(o->method, "shift") && strcmp(o->method, "fourier") && strcmp(o->method, "stack"))
                return usage("--method %s: expected shift or fourier (refocus) or stack (depth)", o->method);
        } else if (!strcmp(a, "--coverage"))
            STR(o->coverage);
        else if (!strcmp(a, "--confidence"))
            STR(o->confidence);
        else if (!strcmp(a, "--disparity-map"))
            STR(o->dispmap);
        else if (!strcmp(a, "--geometry")) {
            STR(o->geometry);
            if (strcmp(o->geometry, "plane") && strcmp(o->geometry, "depth"))
                return usage("--geometry %s: expected plane or depth", o->geometry);
        }
        else if (!strcmp(a, "--alpha"))
            {
            NUMS(1);
            o->alpha = v[0], o->have_alpha = 1;
        }
        else if (!strcmp(a, "--depth"))
            {
            NUMS(1);
            o->depth = v[0], o->have_depth = 1;
        }
        else if (!strcmp(a, "--disparity"))
            {
            NUMS(1);
            o->disp = v[0], o->have_disp = 1;
        }
        else if (!strcmp(a, "--aperture"))
            {
            NUMS(1);
            o->aperture = v[0], o->have_aperture = 1;
        }
        else if (!strcmp(a, "--views")) {
            NUMS(4);
            for (int k = 0; k < 4; k++)
                o->views[k] = (int)v[k];
            o->have_views = 1;
        } else if (!strcmp(a, "--oversample"))
            {
            NUMS(1);
            o->oversample = v[0];
        }
        else if (!strcmp(a, "--from"))
            {
            NUMS(1);
            o->from = v[0], o->have_from = 1;
        }
        else if (!strcmp(a, "--to"))
            {
            NUMS(1);
            o->to = v[0], o->have_to = 1;
        }
        else if (!strcmp(a, "--steps"))
            {
            NUMS(1);
            o->steps = (int)v[0], o->have_steps = 1;
        }
        else if (!strcmp(a, "--u"))
            {
            NUMS(1);
            o->u = v[0], o->have_u = 1;
        }
        else if (!strcmp(a, "--v"))
            {
            NUMS(1);
            o->v = v[0], o->have_v = 1;
        }
        else if (!strcmp(a, "--threads"))
            {
            NUMS(1);
            o->threads = (int)v[0], o->synth.threads = (int)v[0];
        }
        else if (!strcmp(a, "--port")) {
            NUMS(1);
            if (v[0] < 0 || v[0] > 65535 || v[0] != (int)v[0])
                return usage("--port %s: expected an integer 0..65535", argv[i]);
            o->port = (int)v[0];
        } else if (!strcmp(a, "--allow-nonfinite"))
            o->allow_nonfinite = 1;
        /* layout flags */
        else if (!strcmp(a, "--kind")) {
            const char *k;
            STR(k);
            if (!strcmp(k, "camera-array"))
                f->kind = LF_LF_CAMERA_ARRAY;
            else if (!strcmp(k, "plenoptic"))
                f->kind = LF_LF_PLENOPTIC;
            else
                return usage("--kind %s: expected camera-array or plenoptic", k);
            f->have |= LF_LF_HAVE_KIND;
        } else if (!strcmp(a, "--camsperdim"))
            {
            NUMS(2);
            f->cams_x = (int)v[0], f->cams_y = (int)v[1], f->have |= LF_LF_HAVE_CAMS | LF_LF_HAVE_KIND,
                     f->kind = LF_LF_CAMERA_ARRAY;
        }
        else if (!strcmp(a, "--griddim")) {
            NUMS(4);
            memcpy(f->grid_bounds, v, sizeof f->grid_bounds);
            f->have |= LF_LF_HAVE_BOUNDS;
        } else if (!strcmp(a, "--inputfov"))
            {
            NUMS(1);
            f->fov_deg = v[0], f->have |= LF_LF_HAVE_FOV;
        }
        else if (!strcmp(a, "--tilesize"))
            {
            NUMS(2);
            f->tile_w = (int)v[0], f->tile_h = (int)v[1], f->have |= LF_LF_HAVE_TILE;
        }
        else if (!strcmp(a, "--grid")) {
            const char *g;
            STR(g);
            if (strcmp(g, "square") && strcmp(g, "hex"))
                return usage("--grid %s: expected square or hex", g);
            f->grid = strcmp(g, "hex") ? LF_LF_GRID_SQUARE : LF_LF_GRID_HEX;
            f->have |= LF_LF_HAVE_GRID;
        } else if (!strcmp(a, "--pitch"))
            {
            NUMS(1);
            f->pitch_px = v[0], f->have |= LF_LF_HAVE_PITCH;
        }
        else if (!strcmp(a, "--rotation"))
            {
            NUMS(1);
            f->rotation_rad = v[0], f->have |= LF_LF_HAVE_ROTATION;
        }
        else if (!strcmp(a, "--offset"))
            {
            NUMS(2);
            f->offset_px[0] = v[0], f->offset_px[1] = v[1], f->have |= LF_LF_HAVE_OFFSET;
        }
        else if (!strcmp(a, "--lenscount"))
            {
            NUMS(2);
            f->lens_x = (int)v[0], f->lens_y = (int)v[1], f->have |= LF_LF_HAVE_LENS_COUNT;
        }
        else if (!strcmp(a, "--mainlens")) {
            NUMS(4);
            f->main_focal_mm = v[0], f->main_fstop = v[1], f->mla_distance_mm = v[2], f->pitch_um = v[3];
            f->have |= LF_LF_HAVE_MAIN_LENS;
        }
        /* synth (CS348B names) */
        else if (!strcmp(a, "--samplesperpixel"))
            {
            NUMS(1);
            o->synth.spp = (int)v[0];
        }
        else if (!strcmp(a, "--focaldistance"))
            {
            NUMS(1);
            o->synth.focal_distance = v[0], o->have_focal = 1;
        }
        else if (!strcmp(a, "--camerapos"))
            {
            NUMS(3);
            memcpy(o->synth.pos, v, sizeof o->synth.pos), o->have_pos = 1;
        }
        else if (!strcmp(a, "--camerarot"))
            {
            NUMS(3);
            memcpy(o->synth.rot_deg, v, sizeof o->synth.rot_deg);
        }
        else if (!strcmp(a, "--outputfov"))
            {
            NUMS(1);
            o->synth.fov_deg = v[0], o->have_outfov = 1;
        }
        else if (!strcmp(a, "--lensradius"))
            {
            NUMS(1);
            o->synth.lens_radius = v[0];
        }
        else if (!strcmp(a, "--outputdim"))
            {
            NUMS(2);
            o->synth.width = (int)v[0], o->synth.height = (int)v[1], o->have_outdim = 1;
        }
        else if (!strcmp(a, "--seed"))
            {
            NUMS(1);
            o->synth.seed = (uint32_t)v[0];
        }
        else if (a[0] == '-' && a[1])
            return usage("unknown flag %s", a);
        else if (positional == 0)
            o->input = a, positional++;
        else if (positional == 1 && !strcmp(o->cmd, "synth") && !o->output)
            o->output = a, positional++;
        else
            return usage("unexpected argument %s", a);
#undef NUMS
#undef STR
    }
    if (!o->input)
        return usage("%s needs an input file", o->cmd);
    return 0;
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
    if (lf_image_write(path, img, a, NULL, &err)) {
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
    const lf_attr *a = lf_attrs_get(&l->attrs, "lensfield:disparity_file");
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
    lf_attrs_set_double(&a, "lensfield:refocus_disparity_px", ro.disparity_px);
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
        lf_attrs_set_double(&a, "lensfield:refocus_disparity_px", ro.disparity_px);
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
static const char *depth_range(const opts *o, const lf_attrs *attrs, double *d0, double *d1)
{
    *d0 = *d1 = 0;
    if (o->have_from && o->have_to) {
        *d0 = o->from, *d1 = o->to;
        return "--from/--to";
    }
    const lf_attr *a = lf_attrs_get(attrs, "lensfield:disp_min"), *b = lf_attrs_get(attrs, "lensfield:disp_max");
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
    const char *src = depth_range(o, &l.attrs, &d.d0, &d.d1);
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
    if (lf_lf_depth(&l.lf, &d, &disp, o->confidence ? &conf : NULL, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
    lf_attrs a = {0};
    float range[2] = {(float)d.d0, (float)d.d1};
    lf_attrs_set_floats(&a, "lensfield:disparity_search_range", range, 2);
    lf_attrs_set_string(&a, "lensfield:disparity_convention",
                        "I_centre(x, y) = I_(iu,iv)(x - d (iu - iu_c), y - d (iv - iv_c)), px per view step");
    rc = write_image(o->output, &disp, &a);
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
    lf_attrs_set_int(&a, "lensfield:white", 1);
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

typedef struct command {
    const char *name;
    int (*run)(const opts *o);
} command;

static const command commands[] = {
    {"info", cmd_info},       {"decode", cmd_decode},     {"calibrate", cmd_calibrate}, {"refocus", cmd_refocus},
    {"stack", cmd_stack},     {"allfocus", cmd_allfocus}, {"depth", cmd_depth},         {"view", cmd_view},
    {"synth", cmd_synth},     {"export-web", cmd_export_web}, {"serve", cmd_serve},
};

int main(int argc, char **argv)
{
    if (argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
        fputs(usage_text, stdout);
        return EXIT_OK;
    }
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(argv[1], commands[i].name)) {
            opts o;
            int rc = parse(argc, argv, &o);
            if (rc)
                return rc;
            return commands[i].run(&o);
        }
    return usage("unknown command %s", argv[1]);
}
