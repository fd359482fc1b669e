/* lftool - decode, refocus and re-view light-field raws (docs/lftool.md).
 *
 *   lftool info RAW.exr
 *   lftool decode RAW.exr -o DIR [--format exr|png] [--white WHITE.exr] [--layout hci]
 *   lftool calibrate WHITE.exr -o LAYOUT.exr [--grid square|hex]
 *   lftool refocus RAW.exr (--alpha A | --depth M | --disparity PX) [--aperture R | --views u0 u1 v0 v1]
 *                  [--method shift|fourier] -o OUT
 *   lftool stack|allfocus|depth RAW.exr --from D0 --to D1 [--steps N] -o OUT
 *   lftool view RAW.exr --u U --v V [--disparity PX] -o OUT
 *   lftool synth LF.exr OUT.exr [CS348B flags]
 *   lftool export-web RAW.exr -o DIR [--format jpg|png] [--from D0 --to D1] [--steps N]
 *   lftool serve DIR [--port P]
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

#include <arpa/inet.h>
#include <limits.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lightfield/lf_lightfield.h"

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
    "  depth RAW.exr -o OUT                  disparity map from a stack (same flags)\n"
    "  view RAW.exr --u U --v V -o OUT       view from (U, V) in view units from the centre [--disparity PX]\n"
    "  synth LF.exr OUT.exr                  CS348B virtual camera: --samplesperpixel N --focaldistance D\n"
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
    "other: --threads N, --allow-nonfinite (treat NaN/Inf raw pixels as missing samples), --help\n";

/* ---------- flags ---------- */

typedef struct opts {
    const char *cmd, *input, *output, *white, *format, *hci, *method, *coverage;
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
            if (strcmp(o->method, "shift") && strcmp(o->method, "fourier"))
                return usage("--method %s: expected shift or fourier", o->method);
        } else if (!strcmp(a, "--coverage"))
            STR(o->coverage);
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
} loaded;

static void unload(loaded *l)
{
    lf_lf_free(&l->lf);
    lf_image_free(&l->raw);
    lf_attrs_free(&l->attrs);
}

/* Reads the raw, resolves its layout (attributes + flags); decodes unless
 * layout_only. Prints the error and returns EXIT_INPUT on failure. */
static int load(const opts *o, loaded *l, int layout_only)
{
    memset(l, 0, sizeof *l);
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
    printf("%s: %d x %d raw, %d channels\n%s", o->input, l.raw.width, l.raw.height, l.raw.channels, buf);
    size_t bad = lf_image_count_nonfinite(&l.raw);
    if (bad)
        printf("non-finite pixel values: %zu\n", bad);
    unload(&l);
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
    const char *ext = o->hci ? "png" : (o->format ? o->format : "exr");
    if ((rc = make_dir(o->output))) {
        unload(&l);
        return rc;
    }
    char path[4096];
    for (int iv = 0; iv < lf->nv && !rc; iv++)
        for (int iu = 0; iu < lf->nu && !rc; iu++) {
            lf_image v = view_image(lf, iu, iv);
            if (o->hci)
                snprintf(path, sizeof path, "%s/input_Cam%03d.png", o->output, iv * lf->nu + iu);
            else
                snprintf(path, sizeof path, "%s/view_%02d_%02d.%s", o->output, iu, iv, ext);
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
    if (!rc && o->hci) {
        snprintf(path, sizeof path, "%s/parameters.cfg", o->output);
        FILE *f = fopen(path, "w");
        if (!f) {
            fprintf(stderr, "lftool: cannot write %s\n", path);
            rc = EXIT_INPUT;
        } else {
            const lf_lf_layout *y = &lf->layout;
            fprintf(f, "[intrinsics]\nwidth = %d\nheight = %d\n", lf->ns, lf->nt);
            if (y->kind == LF_LF_CAMERA_ARRAY && (y->have & LF_LF_HAVE_FOV)) {
                /* HCI gives focal length and sensor size in mm: use a 35 mm sensor across the width */
                double fpx = 0.5 * (lf->ns < lf->nt ? lf->ns : lf->nt) / tan(y->fov_deg * M_PI / 360);
                fprintf(f, "focal_length_mm = %.6g\nsensor_size_mm = 35\n", fpx * 35.0 / lf->ns);
            } else if (y->have & LF_LF_HAVE_MAIN_LENS) {
                fprintf(f, "focal_length_mm = %.6g\nfstop = %.6g\n", y->main_focal_mm, y->main_fstop);
            }
            fprintf(f, "\n[extrinsics]\nnum_cams_x = %d\nnum_cams_y = %d\n", lf->nu, lf->nv);
            if (y->kind == LF_LF_CAMERA_ARRAY && (y->have & LF_LF_HAVE_BOUNDS) && lf->nu > 1)
                fprintf(f, "baseline_mm = %.6g\n", 1000 * (y->grid_bounds[1] - y->grid_bounds[0]) / (lf->nu - 1));
            fprintf(f, "\n[meta]\nsource = lftool decode --layout hci\n");
            fclose(f);
        }
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
static int cmd_depth(const opts *o) { return cmd_allfocus_depth(o, 1); }

static int cmd_view(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    if (!o->have_u || !o->have_v)
        return usage("%s", "view needs --u U --v V");
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    double d = 0;
    if ((rc = focus_disparity(o, &l.lf, &d, 0))) {
        unload(&l);
        return rc;
    }
    lf_image out;
    lf_error err = {0};
    if (lf_lf_view_at(&l.lf, o->u, o->v, d, &out, &err)) {
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
    lf_image out, cov;
    size_t uncovered = 0;
    lf_error err = {0};
    clock_t c0 = clock();
    if (lf_lf_synth(&l.lf, &s, &out, &cov, &uncovered, &err)) {
        fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
        unload(&l);
        return EXIT_INPUT;
    }
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

/* ---------- export-web and serve (docs/web.md) ---------- */

/* Atlases stay within 4096 px a side: the texture size every WebGL 2
 * implementation in use supports (the spec's minimum is 2048). */
enum { WEB_MAX_TEXTURE = 4096, WEB_SEARCH_STEPS = 25, WEB_DEPTH_STEPS = 33 };

static int web_file_exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0 && S_ISREG(s.st_mode);
}

/* The page's hand-written files (index.html, lf.js) live in web/ of the
 * source tree, found from this file's compile-time path; $LF_WEB_DIR
 * overrides it, and an installed lftool looks next to its binary
 * (BIN/web, BIN/../share/lensfield/web). */
static int web_find_assets(char *dir, size_t n)
{
    enum { LEN = PATH_MAX + 64 };
    char cand[4][LEN];
    int k = 0;
    const char *env = getenv("LF_WEB_DIR");
    if (env && *env)
        snprintf(cand[k++], LEN, "%.*s", PATH_MAX, env);
    const char *src = __FILE__, *tail = strstr(src, "tools/lftool.c");
    if (tail)
        snprintf(cand[k++], LEN, "%.*sweb", (int)(tail - src), src);
    char exe[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0) {
        exe[len] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            snprintf(cand[k++], LEN, "%s/web", exe);
            snprintf(cand[k++], LEN, "%s/../share/lensfield/web", exe);
        }
    }
    for (int i = 0; i < k; i++) {
        char probe[LEN + 16];
        snprintf(probe, sizeof probe, "%.*s/index.html", (int)LEN - 1, cand[i]);
        if (web_file_exists(probe) && strlen(cand[i]) < n) {
            snprintf(dir, n, "%s", cand[i]);
            return 0;
        }
    }
    fprintf(stderr, "lftool: export-web: cannot find the page's files (web/index.html, web/lf.js); set LF_WEB_DIR\n");
    return EXIT_INPUT;
}

static long web_copy(const char *from, const char *to)
{
    char tmp[PATH_MAX + 8];
    snprintf(tmp, sizeof tmp, "%s.tmp", to);
    FILE *in = fopen(from, "rb"), *out = in ? fopen(tmp, "wb") : NULL;
    long total = 0;
    int ok = in && out;
    char buf[65536];
    size_t got;
    while (ok && (got = fread(buf, 1, sizeof buf, in)) > 0) {
        ok = fwrite(buf, 1, got, out) == got;
        total += (long)got;
    }
    if (in && ferror(in))
        ok = 0;
    if (in)
        fclose(in);
    if (out && fclose(out))
        ok = 0;
    if (!ok || rename(tmp, to)) {
        fprintf(stderr, "lftool: cannot copy %s to %s\n", from, to);
        remove(tmp);
        return -1;
    }
    return total;
}

/* Appends the file as a base64 data: URI string literal; returns its length. */
static long web_put_data_uri(FILE *js, const char *path, const char *mime)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "lftool: cannot read back %s\n", path);
        return -1;
    }
    long n = fprintf(js, "\"data:%s;base64,", mime);
    unsigned char in[3];
    size_t got;
    while ((got = fread(in, 1, 3, f)) > 0) {
        unsigned v = (unsigned)in[0] << 16 | (got > 1 ? (unsigned)in[1] << 8 : 0) | (got > 2 ? in[2] : 0);
        char q[4] = {b64[v >> 18 & 63], b64[v >> 12 & 63], got > 1 ? b64[v >> 6 & 63] : '=', got > 2 ? b64[v & 63] : '='};
        fwrite(q, 1, 4, js);
        n += 4;
    }
    fclose(f);
    fputc('"', js);
    return n + 1;
}

/* Writes img to a temporary file in dir and appends it to js as a data URI. */
static int web_put_image(FILE *js, const char *dir, const char *name, const char *ext, const lf_image *img)
{
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/.%s.%s", dir, name, ext);
    int rc = write_image(path, img, NULL);
    if (!rc && web_put_data_uri(js, path, strcmp(ext, "jpg") ? "image/png" : "image/jpeg") < 0)
        rc = EXIT_INPUT;
    remove(path);
    return rc;
}

/* Disparity map over [d0, d1] in n slices (full aperture). */
static int web_depth(const loaded *l, double d0, double d1, int n, lf_image *dm)
{
    lf_lf_refocus_opts ro = lf_lf_refocus_defaults();
    lf_image af;
    lf_error err = {0};
    if (lf_lf_allfocus(&l->lf, &ro, d0, d1, n, &af, dm, &err)) {
        fprintf(stderr, "lftool: export-web: %s\n", err.msg);
        return EXIT_INPUT;
    }
    lf_image_free(&af);
    return 0;
}

/* The range of disparities in the picture: the 2nd..98th percentile of a
 * coarse depth estimate over a wide search range, padded by one step. */
static void web_focus_range(const lf_image *dm, double d0, double d1, int n, double *q0, double *q1)
{
    size_t count[WEB_SEARCH_STEPS] = {0}, total = (size_t)dm->width * dm->height;
    double step = (d1 - d0) / (n - 1);
    for (size_t i = 0; i < total; i++) {
        int k = (int)floor((dm->data[i] - d0) / step + 0.5);
        count[k < 0 ? 0 : k >= n ? n - 1 : k]++;
    }
    size_t acc = 0;
    int lo = -1, hi = n - 1;
    for (int k = 0; k < n; k++) {
        acc += count[k];
        if (lo < 0 && acc > total / 50)
            lo = k;
        if (acc >= total - total / 50) {
            hi = k;
            break;
        }
    }
    lo = lo > 0 ? lo - 1 : 0, hi = hi < n - 1 ? hi + 1 : n - 1;
    if (hi - lo < 2)
        lo = lo > 0 ? lo - 1 : lo, hi = hi < n - 1 ? hi + 1 : hi;
    *q0 = d0 + lo * step, *q1 = d0 + hi * step;
}

/* Tiles n images of w x h into cols x rows (row-major from the top left). */
static int web_atlas(const float *const *src, int n, int w, int h, int cols, lf_image *atlas)
{
    int rows = (n + cols - 1) / cols;
    lf_error err = {0};
    if (lf_image_alloc(atlas, cols * w, rows * h, 3, &err)) {
        fprintf(stderr, "lftool: export-web: %s\n", err.msg);
        return EXIT_INPUT;
    }
    for (int k = 0; k < n; k++)
        for (int t = 0; t < h; t++)
            memcpy(lf_image_px(atlas, (k % cols) * w, (k / cols) * h + t), src[k] + (size_t)t * w * 3,
                   sizeof(float) * 3 * (size_t)w);
    return 0;
}

static int cmd_export_web(const opts *o)
{
    int rc = need_output(o);
    if (rc)
        return rc;
    char assets[PATH_MAX];
    if ((rc = web_find_assets(assets, sizeof assets)))
        return rc;
    int stack_n = o->have_steps ? o->steps : 9;
    if (stack_n < 2 || stack_n > 64)
        return usage("%s", "export-web: --steps (focal-stack slices) must be 2..64");
    if (o->have_from != o->have_to)
        return usage("%s", "export-web: give both --from and --to, or neither");
    const char *ext = o->format ? o->format : "jpg";
    loaded l;
    if ((rc = load(o, &l, 0)))
        return rc;
    const lf_lightfield *lf = &l.lf;
    if (lf->ns > WEB_MAX_TEXTURE || lf->nt > WEB_MAX_TEXTURE) {
        fprintf(stderr, "lftool: %s: views of %d x %d exceed the page's %d px texture limit\n", o->input, lf->ns,
                lf->nt, WEB_MAX_TEXTURE);
        unload(&l);
        return EXIT_INPUT;
    }
    for (int g = 0; g < 256; g++)
        if (lf_srgb_encode(lf_srgb_decode((unsigned char)g)) != g) {
            fprintf(stderr, "lftool: export-web: 8-bit sRGB round trip fails at %d\n", g);
            unload(&l);
            return EXIT_INPUT;
        }
    clock_t c0 = clock();

    /* focus range and per-pixel disparity (docs/lftool.md "Focal stack,
     * all-in-focus, depth"); the page maps a click to the median around it */
    double q0, q1;
    lf_image dm = {0};
    if (o->have_from) {
        q0 = o->from, q1 = o->to;
    } else {
        double d0 = -1, d1 = 1; /* plenoptic: d = 0 at the focus distance */
        if (lf->layout.kind == LF_LF_CAMERA_ARRAY)
            d0 = 0, d1 = lf->disp_per_inv_m > 0 ? lf->disp_per_inv_m / 0.5 : 4; /* infinity .. 0.5 m */
        if ((rc = web_depth(&l, d0, d1, WEB_SEARCH_STEPS, &dm))) {
            unload(&l);
            return rc;
        }
        web_focus_range(&dm, d0, d1, WEB_SEARCH_STEPS, &q0, &q1);
        lf_image_free(&dm);
    }
    if (!(q1 > q0)) {
        unload(&l);
        return usage("%s", "export-web: --to must be above --from");
    }
    if ((rc = web_depth(&l, q0, q1, WEB_DEPTH_STEPS, &dm)) || (rc = make_dir(o->output))) {
        lf_image_free(&dm);
        unload(&l);
        return rc;
    }
    /* 8-bit disparity: g = round((d - q0) / (q1 - q0) * 255), stored as a
     * grey PNG whose sRGB encoding gives back exactly g */
    lf_image grey = {dm.width, dm.height, 1, dm.data};
    for (size_t i = 0; i < (size_t)dm.width * dm.height; i++) {
        double g = floor((dm.data[i] - q0) / (q1 - q0) * 255 + 0.5);
        dm.data[i] = lf_srgb_decode((unsigned char)(g < 0 ? 0 : g > 255 ? 255 : g));
    }

    char path[PATH_MAX], tmp[PATH_MAX + 8];
    snprintf(path, sizeof path, "%s/data.js", o->output);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *js = fopen(tmp, "wb");
    if (!js) {
        fprintf(stderr, "lftool: cannot write %s: %s\n", tmp, strerror(errno));
        lf_image_free(&dm);
        unload(&l);
        return EXIT_INPUT;
    }
    int nviews = lf->nu * lf->nv;
    int cols = WEB_MAX_TEXTURE / lf->ns, rows_max = WEB_MAX_TEXTURE / lf->nt;
    cols = cols > nviews ? nviews : cols;
    /* as few atlases as fit, the views spread evenly over them: the page
     * allocates every layer of its texture array at the largest atlas size */
    int atlases = (nviews + cols * rows_max - 1) / (cols * rows_max);
    int per = cols * (((nviews + atlases - 1) / atlases + cols - 1) / cols);
    /* the input's file name, kept to what needs no escaping in a JS string */
    char source[256];
    const char *base = strrchr(o->input, '/') ? strrchr(o->input, '/') + 1 : o->input;
    size_t sl = 0;
    for (; base[sl] && sl < sizeof source - 1; sl++)
        source[sl] = base[sl] >= ' ' && base[sl] < 127 && base[sl] != '"' && base[sl] != '\\' && base[sl] != '<'
                         ? base[sl]
                         : '_';
    source[sl] = '\0';
    fprintf(js,
            "/* lensfield light field for the web page (lftool export-web; docs/web.md). */\n"
            "window.LF_DATA = {\n  \"version\": 1, \"source\": \"%s\",\n"
            "  \"nu\": %d, \"nv\": %d, \"ns\": %d, \"nt\": %d, \"dispVPerU\": %.9g,\n"
            "  \"dispAtInf\": %.9g, \"dispPerInvM\": %.9g, \"focusMin\": %.9g, \"focusMax\": %.9g,\n"
            "  \"views\": {\"cols\": %d, \"perAtlas\": %d, \"atlases\": [",
            source, lf->nu, lf->nv, lf->ns, lf->nt,
            lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0, lf->disp_at_inf, lf->disp_per_inv_m, q0, q1, cols, per);
    const float **src = malloc(sizeof *src * (size_t)(nviews > stack_n ? nviews : stack_n));
    if (!src)
        rc = EXIT_INPUT;
    for (int a = 0; a < atlases && !rc; a++) {
        int n = nviews - a * per < per ? nviews - a * per : per;
        for (int k = 0; k < n; k++)
            src[k] = lf_lf_view(lf, (a * per + k) % lf->nu, (a * per + k) / lf->nu);
        lf_image atlas;
        if ((rc = web_atlas(src, n, lf->ns, lf->nt, cols, &atlas)))
            break;
        char name[32];
        snprintf(name, sizeof name, "views%d", a);
        fputs(a ? ",\n    " : "\n    ", js);
        rc = web_put_image(js, o->output, name, ext, &atlas);
        lf_image_free(&atlas);
    }
    if (!rc) {
        fprintf(js, "]},\n  \"disparity\": {\"min\": %.9g, \"max\": %.9g, \"src\": ", q0, q1);
        rc = web_put_image(js, o->output, "disparity", "png", &grey);
    }
    /* focal stack over the same range: the page's fallback without WebGL 2 */
    lf_image *slices = rc ? NULL : calloc((size_t)stack_n, sizeof *slices);
    if (!rc && !slices)
        rc = EXIT_INPUT;
    if (!rc) {
        fprintf(js, "},\n  \"stack\": {\"disparities\": [");
        lf_lf_refocus_opts ro = lf_lf_refocus_defaults();
        ro.threads = o->threads;
        for (int k = 0; k < stack_n && !rc; k++) {
            lf_error err = {0};
            ro.disparity_px = q0 + (q1 - q0) * k / (stack_n - 1);
            fprintf(js, "%s%.9g", k ? ", " : "", ro.disparity_px);
            if (lf_lf_refocus(lf, &ro, &slices[k], &err)) {
                fprintf(stderr, "lftool: %s: %s\n", o->input, err.msg);
                rc = EXIT_INPUT;
            }
            src[k] = slices[k].data;
        }
        int scols = (int)ceil(sqrt((double)stack_n));
        lf_image atlas;
        if (!rc && !(rc = web_atlas(src, stack_n, lf->ns, lf->nt, scols, &atlas))) {
            fprintf(js, "], \"cols\": %d, \"src\": ", scols);
            rc = web_put_image(js, o->output, "stack", ext, &atlas);
            lf_image_free(&atlas);
        }
        for (int k = 0; k < stack_n; k++)
            lf_image_free(&slices[k]);
    }
    free(slices);
    free(src);
    if (!rc)
        fprintf(js, "}\n};\n");
    long data_bytes = ftell(js);
    if (fclose(js) || rc || rename(tmp, path)) {
        if (!rc)
            fprintf(stderr, "lftool: cannot write %s\n", path);
        remove(tmp);
        lf_image_free(&dm);
        unload(&l);
        return EXIT_INPUT;
    }
    long page = data_bytes;
    static const char *const files[] = {"index.html", "lf.js"};
    for (int i = 0; i < 2 && !rc; i++) {
        char from[PATH_MAX + 16];
        snprintf(from, sizeof from, "%s/%s", assets, files[i]);
        snprintf(path, sizeof path, "%s/%s", o->output, files[i]);
        long n = web_copy(from, path);
        if (n < 0)
            rc = EXIT_INPUT;
        page += n;
    }
    if (!rc)
        printf("%s: %d x %d views of %d x %d, focus %.4g .. %.4g px/view, %d-slice stack -> %s/index.html "
               "(%.1f KiB, %.2f s CPU)\n",
               o->input, lf->nu, lf->nv, lf->ns, lf->nt, q0, q1, stack_n, o->output, page / 1024.0,
               (double)(clock() - c0) / CLOCKS_PER_SEC);
    lf_image_free(&dm);
    unload(&l);
    return rc;
}

/* serve: a minimal static HTTP/1.0 server on 127.0.0.1, one request at a
 * time, for viewing an export over http:// rather than file://. */
static volatile sig_atomic_t serve_stop;
static void serve_on_signal(int sig)
{
    (void)sig;
    serve_stop = 1;
}

static int serve_reply(int fd, const char *status, const char *type, long length)
{
    char hdr[512];
    int n = snprintf(hdr, sizeof hdr,
                     "HTTP/1.0 %s\r\nContent-Type: %s\r\nContent-Length: %ld\r\nCache-Control: no-cache\r\n"
                     "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
                     status, type, length);
    return send(fd, hdr, (size_t)n, MSG_NOSIGNAL) < 0 ? -1 : 0;
}

static void serve_error(int fd, const char *status)
{
    if (!serve_reply(fd, status, "text/plain", (long)strlen(status) + 1))
        send(fd, status, strlen(status), MSG_NOSIGNAL), send(fd, "\n", 1, MSG_NOSIGNAL);
}

static const char *serve_type(const char *path)
{
    static const char *const types[][2] = {{".html", "text/html; charset=utf-8"},
                                           {".js", "text/javascript; charset=utf-8"},
                                           {".css", "text/css"},
                                           {".png", "image/png"},
                                           {".jpg", "image/jpeg"},
                                           {".json", "application/json"}};
    const char *dot = strrchr(path, '.');
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        if (!strcmp(dot, types[i][0]))
            return types[i][1];
    return "application/octet-stream";
}

/* Decodes %XX; fails on NUL, backslash, a ".." segment or a bad escape. */
static int serve_clean_path(const char *raw, char *out, size_t n)
{
    size_t k = 0;
    for (const char *p = raw; *p && *p != '?' && *p != '#'; p++) {
        int c = (unsigned char)*p;
        if (c == '%') {
            unsigned v;
            if (!p[1] || !p[2] || sscanf(p + 1, "%2x", &v) != 1)
                return -1;
            c = (int)v, p += 2;
        }
        if (c == 0 || c == '\\' || k + 1 >= n)
            return -1;
        out[k++] = (char)c;
    }
    out[k] = '\0';
    if (out[0] != '/')
        return -1;
    for (const char *s = out; (s = strstr(s, "..")) != NULL; s += 2)
        if (s[-1] == '/' && (s[2] == '/' || s[2] == '\0'))
            return -1;
    return 0;
}

static void serve_one(int fd, const char *root)
{
    char req[8192];
    size_t got = 0;
    while (got < sizeof req - 1) {
        ssize_t r = recv(fd, req + got, sizeof req - 1 - got, 0);
        if (r <= 0)
            break;
        got += (size_t)r;
        req[got] = '\0';
        if (strstr(req, "\r\n\r\n") || strstr(req, "\n\n"))
            break;
    }
    req[got] = '\0';
    char method[8], target[4096], rel[4096], full[PATH_MAX * 2], real[PATH_MAX];
    if (sscanf(req, "%7s %4095s", method, target) != 2) {
        serve_error(fd, "400 Bad Request");
        return;
    }
    int head = !strcmp(method, "HEAD");
    if (!head && strcmp(method, "GET")) {
        serve_error(fd, "405 Method Not Allowed");
        return;
    }
    if (serve_clean_path(target, rel, sizeof rel)) {
        serve_error(fd, "403 Forbidden");
        return;
    }
    snprintf(full, sizeof full, "%s%s%s", root, rel, rel[strlen(rel) - 1] == '/' ? "index.html" : "");
    /* the resolved file must lie inside the root (no symlink escapes either) */
    size_t rootlen = strlen(root);
    if (!realpath(full, real)) {
        serve_error(fd, "404 Not Found");
        return;
    }
    if (strncmp(real, root, rootlen) || real[rootlen] != '/') {
        serve_error(fd, "403 Forbidden");
        return;
    }
    FILE *f = fopen(real, "rb");
    struct stat st;
    if (!f || fstat(fileno(f), &st) || !S_ISREG(st.st_mode)) {
        if (f)
            fclose(f);
        serve_error(fd, "404 Not Found");
        return;
    }
    int failed = serve_reply(fd, "200 OK", serve_type(real), (long)st.st_size);
    char buf[65536];
    size_t n;
    while (!head && !failed && (n = fread(buf, 1, sizeof buf, f)) > 0)
        if (send(fd, buf, n, MSG_NOSIGNAL) < 0)
            break;
    fclose(f);
}

static int cmd_serve(const opts *o)
{
    char root[PATH_MAX];
    struct stat st;
    if (!realpath(o->input, root) || stat(root, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "lftool: serve: %s is not a directory\n", o->input);
        return EXIT_INPUT;
    }
    int s = socket(AF_INET, SOCK_STREAM, 0);
    int one = 1;
    struct sockaddr_in addr = {0};
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)o->port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK); /* never reachable from other machines */
    socklen_t alen = sizeof addr;
    if (s < 0 || setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
        bind(s, (struct sockaddr *)&addr, sizeof addr) || listen(s, 16) ||
        getsockname(s, (struct sockaddr *)&addr, &alen)) {
        fprintf(stderr, "lftool: serve: cannot listen on 127.0.0.1:%d: %s\n", o->port, strerror(errno));
        if (s >= 0)
            close(s);
        return EXIT_INPUT;
    }
    struct sigaction sa = {0};
    sa.sa_handler = serve_on_signal; /* no SA_RESTART: accept() returns EINTR */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    printf("serving %s at http://127.0.0.1:%d/ (Ctrl-C stops)\n", root, ntohs(addr.sin_port));
    fflush(stdout);
    while (!serve_stop) {
        int c = accept(s, NULL, NULL);
        if (c < 0) {
            if (errno == EINTR || errno == ECONNABORTED)
                continue;
            fprintf(stderr, "lftool: serve: accept: %s\n", strerror(errno));
            close(s);
            return EXIT_INPUT;
        }
        struct timeval tv = {5, 0}; /* a silent client cannot hold the server */
        setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        setsockopt(c, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        serve_one(c, root);
        close(c);
    }
    close(s);
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
