/* The renderer: reads Film, Sampler, PixelFilter, Integrator and Camera,
 * builds the scene, and renders tiles on a pool of threads. */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

#include "base/lf_buf.h"
#include "base/lf_keys.h"
#include "base/lf_parallel.h"
#include "base/lf_suggest.h"
#include "base/lf_progress.h"
#include "base/lf_color.h"
#include "render/film.h"
#include "render/integrator_params.h"
#include "render/lf_sensor.h"
#include "render/sensor_curves.h"
#include "render/render_internal.h"

#define LF_VERSION_STRING "lensfield " LF_VERSION /* LF_VERSION: CMake's project version (lf_base) */

struct lf_renderer {
    lf_scene scene;
    lf_integrator integrator;
    lf_sampler sampler;
    lf_filter filter;
    const lf_camera_type *camera_type;
    void *camera;
    uint32_t camera_needs;
    lf_transform camera_to_world;
    lf_dvec3 camera_origin_world; /* camera_to_world applied to (0,0,0) */
    double shutter_open, shutter_close;
    double imaging_ratio; /* exposure time * ISO / 100 (pbrt-v4 PixelSensor) */
    int xres, yres;
    int px0, px1, py0, py1; /* pixel bounds rendered */
    double diagonal_mm;
    int save_half;
    double max_component;
    char *film_filename;
    int raw;                  /* Film "raw": the sensor turns the film into a mosaic (lf_sensor.h) */
    lf_sensor sensor;
    int has_wb;               /* Film "whitebalance" (pbrt-v4): von Kries in Bradford space, per sample */
    float wb[3][3];
    char *camera_name;
    char *sampler_name;
    char *filter_name;
    char *integrator_name;
    char *scene_path;
    lf_warnings warnings;
    lf_render_opts opts;
    int threads;
    lf_render_stats stats;
    lf_transform world_to_camera;
    int white;
    /* motion and shutters */
    int time_needed;          /* something moves: draw a time sample per camera ray */
    int camera_moving;
    lf_decomposed camera_keys[2];
    lf_motion_pair camera_motion; /* camera_keys prepared for per-sample evaluation */
    lf_motion_table camera_table; /* ... and tabulated (n 0: none, evaluated exactly) */
    double time0, time1;      /* TransformTimes */
    int rolling;              /* rolling shutter */
    double readout;           /* seconds from the first to the last row (column) starting */
    int readout_dir;          /* 0 top->bottom, 1 bottom->top, 2 left->right, 3 right->left */
    int has_curve;
    lf_distrib1d curve;       /* shutter efficiency over the exposure, importance sampled */
    double curve_mean;        /* mean efficiency: the effective fraction of the exposure */
    /* splitting and checkpoints */
    int spp_begin, spp_end;   /* sample index range rendered */
    char settings[1024];      /* what must agree between parts of one render */
    char scene_hash[32];
};

lf_render_opts lf_render_opts_default(void)
{
    lf_render_opts o;
    memset(&o, 0, sizeof o);
    return o;
}

static char *dupstr(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* An options-block directive (Film, Sampler, PixelFilter, Integrator,
 * Camera) as the readers take it: its parameters (an empty list when the
 * scene leaves the directive out), its type or pbrt's default, and
 * "file:line:col" for messages. */
typedef struct option_entity {
    lf_paramset *ps, empty;
    const char *type;
    const lf_loc *loc;
    char where[512];
} option_entity;

static void option_entity_init(option_entity *o, lf_entity *e, const char *default_type)
{
    memset(&o->empty, 0, sizeof o->empty);
    o->ps = e->type ? &e->params : &o->empty;
    o->type = e->type ? e->type : default_type;
    o->loc = &e->loc;
    lf_loc_format(o->where, sizeof o->where, &e->loc);
}

/* Reports the directive's unused or mistyped parameters ("Sampler \"halton\""). */
static int option_entity_finish(const option_entity *o, const char *directive, lf_error *err)
{
    char ctx[128];
    snprintf(ctx, sizeof ctx, "%s \"%s\"", directive, o->type);
    return lf_params_finish(o->ps, ctx, err);
}

/* ---- camera parameter adaptor (the plugin ABI's lf_camera_params) ---- */
typedef struct camera_param_ctx {
    lf_paramset *ps;
    const char *scene_dir;
} camera_param_ctx;

static double cp_float(void *ctx, const char *name, double def)
{
    return lf_params_float(((camera_param_ctx *)ctx)->ps, name, def);
}
static int cp_int(void *ctx, const char *name, int def)
{
    return lf_params_int(((camera_param_ctx *)ctx)->ps, name, def);
}
static int cp_bool(void *ctx, const char *name, int def)
{
    return lf_params_bool(((camera_param_ctx *)ctx)->ps, name, def);
}
static const char *cp_string(void *ctx, const char *name, const char *def)
{
    return lf_params_string(((camera_param_ctx *)ctx)->ps, name, def);
}
static int cp_image(void *ctx, const char *path, int *width, int *height, float **pixels, char *msg, size_t msg_size)
{
    const camera_param_ctx *c = ctx;
    char full[4096];
    if (path[0] == '/' || !c->scene_dir || !c->scene_dir[0])
        snprintf(full, sizeof full, "%s", path);
    else
        snprintf(full, sizeof full, "%s/%s", c->scene_dir, path);
    lf_image img;
    lf_error err = {0};
    if (lf_image_read(full, &img, NULL, &err)) {
        snprintf(msg, msg_size, "%s", err.msg);
        return -1;
    }
    size_t n = (size_t)img.width * img.height;
    float *g = malloc(sizeof(float) * (n ? n : 1));
    if (!g) {
        lf_image_free(&img);
        snprintf(msg, msg_size, "out of memory reading %s", full);
        return -1;
    }
    int nc = img.channels >= 3 ? 3 : 1;
    for (size_t i = 0; i < n; i++) {
        float s = 0;
        for (int k = 0; k < nc; k++)
            s += img.data[i * img.channels + k];
        g[i] = s / nc;
    }
    *width = img.width;
    *height = img.height;
    *pixels = g;
    lf_image_free(&img);
    return 0;
}
static int cp_floats(void *ctx, const char *name, double *out, int max)
{
    lf_paramset *ps = ((camera_param_ctx *)ctx)->ps;
    const lf_param *p = lf_params_peek(ps, name);
    if (!p)
        return 0;
    size_t n = 0;
    const double *v = lf_params_nums(ps, name, p->type == LF_PT_INTEGER ? LF_PT_INTEGER : LF_PT_FLOAT, &n);
    if (!v)
        return 0;
    for (size_t i = 0; i < n && (int)i < max; i++)
        out[i] = v[i];
    return (int)n;
}

/* A pixel coordinate from a scene's number, held within +-2^30 before the
 * conversion (a double beyond int's range is undefined behaviour to
 * convert); the crop check then reports it as outside the film. */
static int pixel_index(double v)
{
    if (!(v > -1073741824.0)) /* also NaN */
        return -1073741824;
    return v < 1073741824.0 ? (int)v : 1073741824;
}

/* The chromaticity of pbrt-v4's white-balance illuminant at T kelvin: CIE
 * daylight (CIE 15:2004 eq. 3.3-3.4) from 4000 K, a black body below. */
static void illuminant_xy(double t, double *x, double *y)
{
    double cct = t * 1.4388 / 1.4380; /* pbrt-v4: the old value of c2 */
    if (cct < 4000) {
        double X = 0, Y = 0, Z = 0;
        for (double l = LF_CIE_LAMBDA_MIN; l <= LF_CIE_LAMBDA_MAX; l += 1) {
            double b[3], p = lf_planck(l, cct);
            lf_cie_xyz_bar(l, b);
            X += p * b[0], Y += p * b[1], Z += p * b[2];
        }
        *x = X / (X + Y + Z), *y = Y / (X + Y + Z);
        return;
    }
    double c3 = cct * cct * cct;
    *x = cct <= 7000 ? -4.607e9 / c3 + 2.9678e6 / (cct * cct) + 0.09911e3 / cct + 0.244063
                     : -2.0064e9 / c3 + 1.9018e6 / (cct * cct) + 0.24748e3 / cct + 0.23704;
    *y = -3 * *x * *x + 2.870 * *x - 0.275;
}

/* White balance from the illuminant at T to sRGB's D65 (pbrt-v4's
 * WhiteBalance: von Kries scaling in Bradford's cone space), as one matrix
 * on linear sRGB. */
static void white_balance_matrix(double t, float out[3][3])
{
    static const double B[3][3] = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};
    static const double Bi[3][3] = {{0.9869929, -0.1470543, 0.1599627},
                                    {0.4323053, 0.5183603, 0.0492912},
                                    {-0.0085287, 0.0400428, 0.9684867}};
    static const double M[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                   {0.2126729, 0.7151522, 0.0721750},
                                   {0.0193339, 0.1191920, 0.9503041}};
    static const double Mi[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                    {-0.9692660, 1.8760108, 0.0415560},
                                    {0.0556434, -0.2040259, 1.0572252}};
    double x, y, src[3], dst[3], ws[3] = {0}, wd[3] = {0};
    illuminant_xy(t, &x, &y);
    src[0] = x / y, src[1] = 1, src[2] = (1 - x - y) / y;
    dst[0] = 0.3127 / 0.3290, dst[1] = 1, dst[2] = (1 - 0.3127 - 0.3290) / 0.3290;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            ws[i] += B[i][k] * src[k], wd[i] += B[i][k] * dst[k];
    double A[3][3], C[3][3];
    for (int i = 0; i < 3; i++) /* diag(wd/ws) B M */
        for (int j = 0; j < 3; j++) {
            A[i][j] = 0;
            for (int k = 0; k < 3; k++)
                A[i][j] += B[i][k] * M[k][j];
            A[i][j] *= wd[i] / ws[i];
        }
    for (int i = 0; i < 3; i++) /* Bi A */
        for (int j = 0; j < 3; j++) {
            C[i][j] = 0;
            for (int k = 0; k < 3; k++)
                C[i][j] += Bi[i][k] * A[k][j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int k = 0; k < 3; k++)
                v += Mi[i][k] * C[k][j];
            out[i][j] = (float)v;
        }
}

/* Film "sensor" and "whitebalance" (pbrt-v4 meanings): cie1931 is white
 * balanced by von Kries scaling when asked; a named camera's curves go
 * through its XYZ fit for the white illuminant (6500 K unless told), which
 * is pbrt-v4's white balance for such a sensor. */
static int read_film_sensor(lf_renderer *r, option_entity *oe, lf_error *err)
{
    lf_paramset *ps = oe->ps;
    const char *sensor = lf_params_string(ps, "sensor", "cie1931");
    double wb = lf_params_float(ps, "whitebalance", 0.0);
    int named = lf_camera_curves_find(sensor) != NULL;
    if (strcmp(sensor, "cie1931") && strcmp(sensor, "ideal") && !named) {
        lf_strbuf names = {0};
        for (int i = 0; i < LF_CAMERA_CURVE_COUNT; i++)
            lf_strbuf_printf(&names, "%s\"%s\"", i ? ", " : "", lf_camera_curve_table[i].name);
        lf_error_set(err, LF_ERR_PARAM,
                     "%s: unknown Film \"sensor\" \"%s\" (\"cie1931\", \"ideal\" or one of pbrt-v4's cameras: %s)",
                     oe->where, sensor, names.s ? names.s : "");
        lf_strbuf_free(&names);
        return err->code;
    }
    if (!(wb >= 0) || wb > 1e6)
        return lf_error_set(err, LF_ERR_PARAM, "%s: Film \"whitebalance\" must be 0 (none) or a temperature in K",
                            oe->where);
    if (named && wb == 0)
        wb = 6500; /* pbrt-v4: a camera's curves are white balanced for 6500 K unless told */
    if (r->raw) {
        snprintf(r->sensor.curves, sizeof r->sensor.curves, "%s", sensor);
        if (lf_params_peek(ps, "whitebalance") && wb != 0)
            lf_warn_at(&r->warnings, oe->loc,
                       "Film \"raw\": \"whitebalance\" %g is not applied to raw data (a developer white balances "
                       "it with AsShotNeutral)",
                       wb);
    } else if (named) {
        snprintf(r->sensor.curves, sizeof r->sensor.curves, "%s", sensor); /* for --explain */
        r->has_wb = 1;
        if (lf_sensor_film_matrix(sensor, wb, r->wb, err))
            return err->code;
    } else if (wb != 0) {
        r->has_wb = 1;
        white_balance_matrix(wb, r->wb);
    }
    return 0;
}

static int read_film(lf_renderer *r, lf_scene_desc *d, lf_error *err)
{
    lf_entity *f = &d->film;
    option_entity oe;
    option_entity_init(&oe, f, "rgb");
    lf_paramset *ps = oe.ps;
    const char *where = oe.where;
    r->raw = f->type && !strcmp(f->type, "raw");
    if (f->type && strcmp(f->type, "rgb") != 0 && !r->raw)
        lf_warn_at(&r->warnings, oe.loc, "Film \"%s\" is rendered as Film \"rgb\"", f->type);
    r->xres = lf_params_int(ps, "xresolution", 1280);
    r->yres = lf_params_int(ps, "yresolution", 720);
    r->film_filename = dupstr(lf_params_string(ps, "filename", "pbrt.exr"));
    r->diagonal_mm = lf_params_float(ps, "diagonal", 35.0);
    double iso = lf_params_float(ps, "iso", 100.0);
    r->save_half = lf_params_bool(ps, "savefp16", 1);
    r->max_component = lf_params_float(ps, "maxcomponentvalue", INFINITY);
    lf_sensor_defaults(&r->sensor);
    if (read_film_sensor(r, &oe, err))
        return err->code;
    if (r->raw && lf_sensor_read_params(&r->sensor, ps, where, err))
        return err->code;
    r->sensor.iso = iso;
    if (r->xres <= 0 || r->yres <= 0 || r->xres > 65536 || r->yres > 65536)
        return lf_error_set(err, LF_ERR_PARAM, "%s: Film resolution %dx%d is out of range (1..65536)", where, r->xres,
                            r->yres);
    if (!(iso > 0))
        return lf_error_set(err, LF_ERR_PARAM, "%s: Film \"iso\" must be positive", where);
    if (!(r->max_component > 0)) /* a clamp at or below 0 makes every pixel that value */
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: Film \"maxcomponentvalue\" must be > 0 (each sample's largest RGB component is "
                            "clamped to it), got %g",
                            where, r->max_component);
    r->imaging_ratio = iso / 100.0; /* times exposure time, applied once the shutter is known */
    /* pbrt-v4: cropwindow in NDC, pixelbounds in pixels (pixelbounds wins). */
    double cw[4] = {0, 1, 0, 1};
    size_t n = 0;
    const double *c = lf_params_nums(ps, "cropwindow", LF_PT_FLOAT, &n);
    if (c) {
        if (n != 4)
            return lf_error_set(err, LF_ERR_PARAM, "%s: \"cropwindow\" needs 4 values", where);
        memcpy(cw, c, sizeof cw);
    }
    r->px0 = pixel_index(ceil(r->xres * fmin(cw[0], cw[1])));
    r->px1 = pixel_index(ceil(r->xres * fmax(cw[0], cw[1])));
    r->py0 = pixel_index(ceil(r->yres * fmin(cw[2], cw[3])));
    r->py1 = pixel_index(ceil(r->yres * fmax(cw[2], cw[3])));
    const double *pb = lf_params_nums(ps, "pixelbounds", LF_PT_INTEGER, &n);
    if (pb) {
        if (n != 4)
            return lf_error_set(err, LF_ERR_PARAM, "%s: \"pixelbounds\" needs 4 values", where);
        r->px0 = pixel_index(pb[0]), r->px1 = pixel_index(pb[1]), r->py0 = pixel_index(pb[2]),
        r->py1 = pixel_index(pb[3]);
    }
    if (lf_params_finish(ps, r->raw ? "Film \"raw\"" : "Film \"rgb\"", err))
        return err->code;
    return 0;
}

static int read_sampler(lf_renderer *r, lf_scene_desc *d, lf_error *err)
{
    option_entity oe;
    option_entity_init(&oe, &d->sampler, "zsobol");
    lf_paramset *ps = oe.ps;
    const char *type = oe.type, *where = oe.where;
    r->sampler.spp = lf_params_int(ps, "pixelsamples", 16);
    r->sampler.seed = (uint32_t)lf_params_int(ps, "seed", 0);
    if (!strcmp(type, "halton")) {
        /* pbrt-v4: "permutedigits" (default), "owen", "none"; "fastowen" is refused there too */
        const char *rz = lf_params_string(ps, "randomization", "permutedigits");
        r->sampler.kind = LF_SAMPLER_HALTON;
        if (!strcmp(rz, "permutedigits"))
            r->sampler.randomize = LF_HALTON_PERMUTE_DIGITS;
        else if (!strcmp(rz, "owen"))
            r->sampler.randomize = LF_HALTON_OWEN;
        else if (!strcmp(rz, "none"))
            r->sampler.randomize = LF_HALTON_NONE;
        else
            return lf_error_set(err, LF_ERR_PARAM,
                                "%s: Sampler \"halton\": \"randomization\" must be \"permutedigits\", \"owen\" or "
                                "\"none\", got \"%s\"",
                                where, rz);
    } else if (!strcmp(type, "pmj02bn")) {
        r->sampler.kind = LF_SAMPLER_PMJ02BN;
    } else if (!strcmp(type, "zsobol") || !strcmp(type, "sobol") || !strcmp(type, "paddedsobol")) {
        lf_params_string(ps, "randomization", NULL);
        r->sampler.kind = LF_SAMPLER_SOBOL;
    } else if (!strcmp(type, "stratified")) {
        r->sampler.kind = LF_SAMPLER_STRATIFIED;
        int xs = lf_params_int(ps, "xsamples", 4), ys = lf_params_int(ps, "ysamples", 4);
        lf_params_bool(ps, "jitter", 1);
        if (xs <= 0 || ys <= 0)
            return lf_error_set(err, LF_ERR_PARAM, "%s: stratified xsamples/ysamples must be positive", where);
        r->sampler.strata_x = xs;
        r->sampler.strata_y = ys;
        r->sampler.spp = xs * ys;
    } else if (!strcmp(type, "independent")) {
        r->sampler.kind = LF_SAMPLER_INDEPENDENT;
    } else {
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "%s: unknown Sampler \"%s\"", where, type);
    }
    r->sampler_name = dupstr(type);
    if (r->opts.spp > 0) {
        r->sampler.spp = r->opts.spp;
        if (r->sampler.kind == LF_SAMPLER_STRATIFIED) {
            int sx = (int)floor(sqrt((double)r->opts.spp));
            while (r->opts.spp % sx)
                sx--;
            r->sampler.strata_x = sx;
            r->sampler.strata_y = r->opts.spp / sx;
        }
    }
    if (r->opts.has_seed)
        r->sampler.seed = r->opts.seed;
    if (r->sampler.spp <= 0)
        return lf_error_set(err, LF_ERR_PARAM, "%s: pixelsamples must be positive, got %d", where, r->sampler.spp);
    if (r->sampler.kind == LF_SAMPLER_PMJ02BN) {
        /* pbrt-v4 rounds the count up to a power of 4 */
        int n = 1;
        while (n < r->sampler.spp && n < LF_PMJ_MAX)
            n *= 4;
        if (r->sampler.spp > LF_PMJ_MAX)
            return lf_error_set(err, LF_ERR_PARAM, "%s: Sampler \"pmj02bn\" takes at most %d samples per pixel, got %d",
                                where, LF_PMJ_MAX, r->sampler.spp);
        if (n != r->sampler.spp) {
            /* a note, not a warning: pbrt-v4 does the same */
            char note[1024];
            snprintf(note, sizeof note,
                     "%s: note: Sampler \"pmj02bn\": %d samples per pixel is not a power of 4; rounded up to %d "
                     "(as pbrt-v4)",
                     where, r->sampler.spp, n);
            lf_warn_text(&r->warnings, note);
        }
        r->sampler.spp = n;
    }
    if (lf_sampler_prepare(&r->sampler, r->xres, r->yres))
        return lf_error_set(err, LF_ERR_NOMEM, "%s: cannot prepare Sampler \"%s\" (out of memory)", where, type);
    return option_entity_finish(&oe, "Sampler", err);
}

static int read_filter(lf_renderer *r, lf_scene_desc *d, lf_error *err)
{
    option_entity oe;
    option_entity_init(&oe, &d->filter, "gaussian");
    lf_paramset *ps = oe.ps;
    const char *type = oe.type, *where = oe.where;
    static const struct {
        const char *name;
        lf_filter_kind kind;
    } kinds[] = {{"box", LF_FILTER_BOX},
                 {"triangle", LF_FILTER_TRIANGLE},
                 {"gaussian", LF_FILTER_GAUSSIAN},
                 {"mitchell", LF_FILTER_MITCHELL},
                 {"lanczos", LF_FILTER_LANCZOS}};
    int k = -1;
    for (int i = 0; i < 5; i++)
        if (!strcmp(type, kinds[i].name))
            k = i;
    if (k < 0)
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "%s: unknown PixelFilter \"%s\"", where, type);
    lf_filter_params fp = {0};
    fp.xradius = lf_params_float(ps, "xradius", -1);
    fp.yradius = lf_params_float(ps, "yradius", -1);
    if (kinds[k].kind == LF_FILTER_GAUSSIAN)
        fp.sigma = lf_params_float(ps, "sigma", 0.5);
    if (kinds[k].kind == LF_FILTER_MITCHELL) {
        fp.b = lf_params_float(ps, "B", 1.0 / 3), fp.b_set = 1;
        fp.c = lf_params_float(ps, "C", 1.0 / 3), fp.c_set = 1;
    }
    if (kinds[k].kind == LF_FILTER_LANCZOS)
        fp.tau = lf_params_float(ps, "tau", 3.0);
    if (lf_filter_init(&r->filter, kinds[k].kind, &fp, err))
        return err->code;
    r->filter_name = dupstr(type);
    return option_entity_finish(&oe, "PixelFilter", err);
}

static int read_integrator(lf_renderer *r, lf_scene_desc *d, lf_error *err)
{
    option_entity oe;
    option_entity_init(&oe, &d->integrator, "volpath");
    lf_paramset *ps = oe.ps;
    const char *type = oe.type, *where = oe.where;
    if (!strcmp(type, "ambientocclusion") || !strcmp(type, "aov"))
        return lf_error_set(err, LF_ERR_UNSUPPORTED,
                            "%s: Integrator \"%s\" is not supported (it computes something other than radiance)", where,
                            type);
    if (strcmp(type, "path") && strcmp(type, "volpath"))
        lf_warn_at(&r->warnings, oe.loc,
                   "Integrator \"%s\" is not implemented; using \"path\", which converges to the same "
                   "image%s",
                   type, lf_integrator_accept_params(type, ps) ? " (its own parameters are read and not used)" : "");
    r->integrator.volumetric = strcmp(type, "path") != 0;
    r->integrator.max_depth = lf_params_int(ps, "maxdepth", 5);
    r->integrator.regularize = lf_params_bool(ps, "regularize", 0);
    /* pbrt-v4's names; "bvh" (its default) is our automatic choice: every
     * light at every vertex for a few lights, otherwise one by power. */
    const char *ls = lf_params_string(ps, "lightsampler", "bvh");
    if (!strcmp(ls, "bvh"))
        r->integrator.light_sampler = LF_LIGHTS_AUTO;
    else if (!strcmp(ls, "power"))
        r->integrator.light_sampler = LF_LIGHTS_POWER;
    else if (!strcmp(ls, "uniform"))
        r->integrator.light_sampler = LF_LIGHTS_UNIFORM;
    else if (!strcmp(ls, "all"))
        r->integrator.light_sampler = LF_LIGHTS_ALL;
    else
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: \"lightsampler\" must be \"bvh\", \"power\", \"uniform\" or \"all\", got \"%s\"", where,
                            ls);
    /* Extension: the Russian roulette rule (docs/scene-format.md). */
    const char *rr = lf_params_string(ps, "russianroulette", "sqrt");
    if (!strcmp(rr, "sqrt"))
        r->integrator.rr_rule = LF_RR_SQRT, r->integrator.rr_depth = 2;
    else if (!strcmp(rr, "pbrt"))
        r->integrator.rr_rule = LF_RR_PBRT, r->integrator.rr_depth = 1;
    else
        return lf_error_set(err, LF_ERR_PARAM, "%s: \"russianroulette\" must be \"sqrt\" or \"pbrt\", got \"%s\"",
                            where, rr);
    lf_params_find(ps, "strategy");
    lf_params_find(ps, "bidirectional");
    lf_params_find(ps, "visualizestrategies");
    lf_params_find(ps, "visualizeweights");
    if (r->integrator.max_depth < 0)
        return lf_error_set(err, LF_ERR_PARAM, "%s: maxdepth must be >= 0", where);
    r->integrator_name = dupstr(type);
    return option_entity_finish(&oe, "Integrator", err);
}

/* The shutter every camera shares (read by the host): open and close times,
 * global or rolling, readout time and direction (docs/motion.md). */
#define LF_SHUTTER_TIME_MAX 1e9

static int read_shutter(lf_renderer *r, const option_entity *oe, lf_error *err)
{
    lf_paramset *ps = oe->ps;
    const char *where = oe->where;
    r->shutter_open = lf_params_float(ps, "shutteropen", 0.0);
    r->shutter_close = lf_params_float(ps, "shutterclose", 1.0);
    /* Beyond a billion seconds (32 years) the exposure scale overflows
     * float radiance: every sample would be dropped as Inf, a black image. */
    if (!(fabs(r->shutter_open) <= LF_SHUTTER_TIME_MAX && fabs(r->shutter_close) <= LF_SHUTTER_TIME_MAX))
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: \"shutteropen\" %g and \"shutterclose\" %g must lie within +-%g seconds", where,
                            r->shutter_open, r->shutter_close, LF_SHUTTER_TIME_MAX);
    if (r->shutter_close < r->shutter_open) {
        lf_warn_at(&r->warnings, oe->loc, "shutterclose < shutteropen; swapping them (as pbrt does)");
        double t = r->shutter_open;
        r->shutter_open = r->shutter_close;
        r->shutter_close = t;
    }
    /* Shutter extensions (docs/motion.md), read by the host for every camera. */
    const char *shutter = lf_params_string(ps, "shutter", "global");
    if (!strcmp(shutter, "rolling"))
        r->rolling = 1;
    else if (strcmp(shutter, "global"))
        return lf_error_set(err, LF_ERR_PARAM, "%s: \"shutter\" must be \"global\" or \"rolling\", got \"%s\"", where,
                            shutter);
    r->readout = lf_params_float(ps, "readouttime", 0.0);
    const char *dir = lf_params_string(ps, "readoutdirection", "toptobottom");
    static const char *dirs[] = {"toptobottom", "bottomtotop", "lefttoright", "righttoleft"};
    r->readout_dir = -1;
    for (int i = 0; i < 4; i++)
        if (!strcmp(dir, dirs[i]))
            r->readout_dir = i;
    if (r->readout_dir < 0)
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: \"readoutdirection\" must be toptobottom, bottomtotop, lefttoright or righttoleft, got "
                            "\"%s\"",
                            where, dir);
    if (!(r->readout >= 0) || !isfinite(r->readout))
        return lf_error_set(err, LF_ERR_PARAM, "%s: \"readouttime\" must be >= 0", where);
    if (r->readout > 0 && !r->rolling)
        lf_warn_at(&r->warnings, oe->loc, "\"readouttime\" only matters with \"shutter\" \"rolling\"");
    return 0;
}

/* "shuttercurve": (time fraction, efficiency) pairs over the exposure,
 * piecewise linear, tabulated finely for importance sampling; sets
 * r->curve_mean, the effective fraction of the exposure. */
static int read_shutter_curve(lf_renderer *r, lf_paramset *ps, const char *where, lf_error *err)
{
    size_t ncurve = 0;
    const double *curve = lf_params_nums(ps, "shuttercurve", LF_PT_FLOAT, &ncurve);
    r->curve_mean = 1.0;
    if (curve) {
        if (ncurve < 4 || ncurve % 2)
            return lf_error_set(err, LF_ERR_PARAM,
                                "%s: \"shuttercurve\" needs (time efficiency) pairs, at least 2, got %zu numbers", where,
                                ncurve);
        int np = (int)(ncurve / 2);
        for (int i = 0; i < np; i++)
            if (curve[2 * i] < 0 || curve[2 * i] > 1 || curve[2 * i + 1] < 0 || (i && curve[2 * i] < curve[2 * i - 2]))
                return lf_error_set(err, LF_ERR_PARAM,
                                    "%s: \"shuttercurve\" times must rise within [0,1] and efficiencies be >= 0", where);
        enum { NB = 1024 };
        double tab[NB], sum = 0;
        for (int i = 0; i < NB; i++) {
            double x = (i + 0.5) / NB, v = 0;
            if (x <= curve[0])
                v = curve[1];
            else if (x >= curve[2 * np - 2])
                v = curve[2 * np - 1];
            else
                for (int k = 0; k + 1 < np; k++)
                    if (x >= curve[2 * k] && x <= curve[2 * k + 2]) {
                        double w = curve[2 * k + 2] - curve[2 * k];
                        double f = w > 0 ? (x - curve[2 * k]) / w : 0;
                        v = curve[2 * k + 1] + f * (curve[2 * k + 3] - curve[2 * k + 1]);
                        break;
                    }
            tab[i] = v;
            sum += v;
        }
        if (!(sum > 0))
            return lf_error_set(err, LF_ERR_PARAM, "%s: \"shuttercurve\" never opens (all efficiencies 0)", where);
        if (lf_distrib1d_init(&r->curve, tab, NB, err))
            return err->code;
        r->has_curve = 1;
        r->curve_mean = sum / NB;
    }
    return 0;
}

/* The camera model itself, created through the registry from its
 * parameters (the plugin ABI's lf_camera_params). */
static int create_camera(lf_renderer *r, lf_camera_desc *cd, const option_entity *oe, lf_error *err)
{
    lf_paramset *ps = oe->ps;
    const char *type = oe->type, *where = oe->where;
    char cerr[1024] = "", cwarn[1024] = "";
    char scene_dir[4096] = ".";
    const char *scene_file = cd->e.loc.file ? cd->e.loc.file : r->scene_path;
    if (scene_file) {
        const char *slash = strrchr(scene_file, '/');
        if (slash)
            snprintf(scene_dir, sizeof scene_dir, "%.*s", (int)(slash - scene_file), scene_file);
    }
    camera_param_ctx cpc = {ps, scene_dir};
    lf_camera_params cp = {&cpc, cp_float, cp_int, cp_bool, cp_string, cp_floats, cp_image};
    lf_camera_create_args args = {sizeof args,   &cp,  r->xres,       r->yres,       r->diagonal_mm, r->shutter_open,
                                  r->shutter_close, scene_dir, cerr, sizeof cerr, cwarn,       sizeof cwarn};
    if (r->camera_type->create(&args, &r->camera)) {
        r->camera = NULL;
        return lf_error_set(err, LF_ERR_PARAM, "%s: Camera \"%s\": %s", where, type, cerr[0] ? cerr : "cannot create");
    }
    if (cwarn[0])
        lf_warn_at(&r->warnings, oe->loc, "Camera \"%s\": %s", type, cwarn);
    r->camera_needs = r->camera_type->needs(r->camera);
    r->camera_name = dupstr(type);
    return 0;
}

/* Where the camera is, and how it moves over the shutter. */
static int read_camera_motion(lf_renderer *r, lf_scene_desc *d, const char *where, lf_error *err)
{
    lf_camera_desc *cd = &d->camera;
    r->world_to_camera = cd->world_to_camera.xf[0];
    r->camera_to_world = lf_transform_inverse(&cd->world_to_camera.xf[0]);
    r->camera_origin_world = lf_xform_point_d(&r->camera_to_world, (lf_dvec3){0, 0, 0});
    r->time0 = d->transform_start_time;
    r->time1 = d->transform_end_time;
    if (cd->world_to_camera.animated) {
        /* Camera motion: camera-to-world interpolated rigidly (pbrt's
         * AnimatedTransform) at each ray's time. */
        for (int k = 0; k < 2; k++) {
            lf_transform c2w = lf_transform_inverse(&cd->world_to_camera.xf[k]);
            if (lf_transform_decompose(&c2w, &r->camera_keys[k]))
                return lf_error_set(err, LF_ERR_NUMERIC, "%s: the camera's %s motion keyframe is degenerate (singular)",
                                    where, k ? "end" : "start");
        }
        lf_motion_pair_prepare(&r->camera_keys[0], &r->camera_keys[1], &r->camera_motion);
        /* Per ray, a lerp in a table within 1e-9 of the exact matrix (60x
         * below a float direction's precision) costs a tenth of the
         * quaternion slerp; beyond 16384 steps (a rotation of over about
         * 2.5 turns) the exact evaluation. */
        lf_motion_table_init(&r->camera_motion, 1e-9, 16384, &r->camera_table);
        r->camera_moving = 1;
    }
    return 0;
}

/* Embree asserts that a ray's origin and direction are within about 1.8e18
 * (its FLT_LARGE) and aborts otherwise; a camera a scene placed that far is
 * refused here with its parameters named, long before, at a bound (1e15
 * scene units) that still leaves float rays a thousand-fold margin. */
#define LF_SCENE_COORD_MAX 1e15

static int coord_ok(lf_dvec3 v)
{
    return fabs(v.x) <= LF_SCENE_COORD_MAX && fabs(v.y) <= LF_SCENE_COORD_MAX && fabs(v.z) <= LF_SCENE_COORD_MAX;
}

static int camera_to_world_ok(const lf_transform *c2w)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!(fabs(c2w->m[i][j]) <= LF_SCENE_COORD_MAX))
                return 0;
    return 1;
}

/* The camera's placement and a few of its rays (the film's corners, edges
 * and centre, the lens's rim and centre, the shutter's ends) in world
 * space: finite and within LF_SCENE_COORD_MAX, or the render is refused. */
static int check_camera_reach(lf_renderer *r, const char *where, lf_error *err)
{
    lf_transform keys[2];
    int nk = 1;
    keys[0] = r->camera_to_world;
    if (r->camera_moving) {
        lf_motion_pair_matrix(&r->camera_motion, 0, keys[0].m);
        lf_motion_pair_matrix(&r->camera_motion, 1, keys[1].m);
        nk = 2;
    }
    for (int k = 0; k < nk; k++)
        if (!camera_to_world_ok(&keys[k]))
            return lf_error_set(err, LF_ERR_NUMERIC,
                                "%s: the camera's %splacement (its transform) is out of range: every coordinate must "
                                "be finite with |coordinate| <= %g scene units",
                                where, nk == 2 ? (k ? "end " : "start ") : "", LF_SCENE_COORD_MAX);
    static const double film[3] = {0, 0.5, 1}, lens[3] = {0.001, 0.5, 0.999};
    enum { N = 9 * 9 };
    lf_camera_sample cs[N];
    lf_camera_ray cr[N];
    double w[N];
    for (int t = 0; t < nk; t++) {
        double time = t ? r->shutter_close : r->shutter_open;
        for (int i = 0; i < N; i++) {
            int f = i / 9, l = i % 9;
            cs[i] = (lf_camera_sample){film[f % 3] * r->xres, film[f / 3] * r->yres, lens[l % 3], lens[l / 3], time, 0.5};
            cr[i].time = time;
            cr[i].wavelength_nm = 0;
        }
        lf_camera_generate_rays(r->camera_type, r->camera, N, cs, cr, w);
        for (int i = 0; i < N; i++) {
            if (!(w[i] > 0) || !isfinite(w[i]))
                continue; /* vignetted: not traced */
            lf_dvec3 o = lf_xform_point_d(&keys[t], (lf_dvec3){cr[i].origin[0], cr[i].origin[1], cr[i].origin[2]});
            lf_dvec3 d = lf_xform_vector_d(&keys[t], (lf_dvec3){cr[i].dir[0], cr[i].dir[1], cr[i].dir[2]});
            double dl = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
            if (!coord_ok(o) || !(dl > 0) || !isfinite(dl))
                return lf_error_set(err, LF_ERR_NUMERIC,
                                    "%s: Camera \"%s\": its rays are out of range (origin %g %g %g, direction %g %g "
                                    "%g in world space): a ray must start within |coordinate| <= %g scene units and "
                                    "have a finite, non-zero direction; check the camera's size, focus and screen "
                                    "parameters and its transform",
                                    where, r->camera_name, o.x, o.y, o.z, d.x, d.y, d.z, LF_SCENE_COORD_MAX);
        }
    }
    return 0;
}

static int make_camera(lf_renderer *r, lf_scene_desc *d, lf_error *err)
{
    lf_camera_desc *cd = &d->camera;
    option_entity oe;
    option_entity_init(&oe, &cd->e, "perspective");
    const char *type = oe.type, *where = oe.where;
    r->camera_type = lf_camera_find(type);
    if (!r->camera_type) {
        char names[512] = "";
        lf_suggest s = lf_suggest_begin(type);
        for (int i = 0; i < lf_camera_count(); i++) {
            strncat(names, i ? ", " : "", sizeof names - strlen(names) - 1);
            strncat(names, lf_camera_at(i)->name, sizeof names - strlen(names) - 1);
            lf_suggest_consider(&s, lf_camera_at(i)->name);
        }
        if (lf_suggest_best(&s))
            return lf_error_set(err, LF_ERR_UNSUPPORTED, "%s: unknown camera \"%s\" (did you mean \"%s\"?)", where,
                                type, lf_suggest_best(&s));
        return lf_error_set(err, LF_ERR_UNSUPPORTED, "%s: unknown camera \"%s\" (registered: %s)", where, type, names);
    }
    int rc = read_shutter(r, &oe, err);
    if (!rc)
        rc = read_shutter_curve(r, oe.ps, where, err);
    if (rc)
        return rc;
    r->imaging_ratio *= (r->shutter_close - r->shutter_open) * r->curve_mean;
    rc = create_camera(r, cd, &oe, err);
    if (!rc)
        rc = read_camera_motion(r, d, where, err);
    if (!rc)
        rc = check_camera_reach(r, where, err);
    if (rc)
        return rc;
    return option_entity_finish(&oe, "Camera", err);
}

static void sink_string(void *ctx, const char *name, const char *value);
static void sink_int(void *ctx, const char *name, int value);
static void sink_double(void *ctx, const char *name, double value);
static void sink_doubles(void *ctx, const char *name, const double *v, int n);

/* The sensor's share of the scene: exposure time, seed, and the pixel
 * pitch - the camera's sensor width over the film's width where the camera
 * has a physical sensor (thinlens, plenoptic), else the Film "diagonal". */
static int prepare_sensor(lf_renderer *r, lf_error *err)
{
    lf_sensor *s = &r->sensor;
    s->exposure_s = (r->shutter_close - r->shutter_open) * r->curve_mean;
    s->seed = r->sampler.seed;
    s->full_width = r->xres;
    s->pixel_pitch_m = r->diagonal_mm * 1e-3 / hypot(r->xres, r->yres);
    lf_attrs meta = {0};
    if (r->camera_type->metadata) {
        lf_camera_attr_sink sink = {&meta, sink_string, sink_int, sink_double, sink_doubles};
        r->camera_type->metadata(r->camera, &sink);
    }
    const lf_attr *sz = lf_attrs_get(&meta, LF_KEY_SENSOR_SIZE_MM);
    if (sz && sz->type == LF_ATTR_FLOATS && sz->n == 2 && sz->v[0] > 0)
        s->pixel_pitch_m = sz->v[0] * 1e-3 / r->xres;
    lf_attrs_free(&meta);
    return lf_sensor_prepare(s, err);
}

const lf_sensor *lf_renderer_sensor(const lf_renderer *r)
{
    return r->raw ? &r->sensor : NULL;
}

int lf_renderer_create(lf_scene_desc *d, const lf_render_opts *opts, lf_renderer **out, lf_error *err)
{
    *out = NULL;
    lf_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    r->opts = *opts;
    r->scene_path = dupstr(opts->scene_path);
    lf_warn_block(&r->warnings, d->warnings);
    if (read_film(r, d, err) || read_sampler(r, d, err) || read_filter(r, d, err) || read_integrator(r, d, err) ||
        make_camera(r, d, err))
        goto fail;
    if (opts->crop[1] > opts->crop[0]) {
        r->px0 = opts->crop[0], r->px1 = opts->crop[1], r->py0 = opts->crop[2], r->py1 = opts->crop[3];
    }
    if (opts->tile_count > 0) {
        /* row band tile_index of tile_count within the crop window */
        if (opts->tile_index < 0 || opts->tile_index >= opts->tile_count) {
            lf_error_set(err, LF_ERR_PARAM, "tile %d/%d: the index must be in 0..%d", opts->tile_index,
                         opts->tile_count, opts->tile_count - 1);
            goto fail;
        }
        int rows = r->py1 - r->py0;
        int y0 = r->py0 + (int)((long long)rows * opts->tile_index / opts->tile_count);
        int y1 = r->py0 + (int)((long long)rows * (opts->tile_index + 1) / opts->tile_count);
        r->py0 = y0, r->py1 = y1;
    }
    r->spp_begin = 0;
    r->spp_end = r->sampler.spp;
    if (opts->spp_end > 0) {
        if (opts->spp_begin < 0 || opts->spp_begin >= opts->spp_end || opts->spp_end > r->sampler.spp) {
            lf_error_set(err, LF_ERR_PARAM, "sample range [%d, %d) is not within the %d samples per pixel",
                         opts->spp_begin, opts->spp_end, r->sampler.spp);
            goto fail;
        }
        r->spp_begin = opts->spp_begin;
        r->spp_end = opts->spp_end;
    }
    /* What parts of one render must share (checked by merge and resume). */
    {
        uint64_t hsh = 1469598103934665603ull;
        FILE *f = opts->scene_path ? fopen(opts->scene_path, "rb") : NULL;
        if (f) {
            int ch;
            while ((ch = fgetc(f)) != EOF)
                hsh = (hsh ^ (uint64_t)(unsigned char)ch) * 1099511628211ull;
            fclose(f);
        }
        snprintf(r->scene_hash, sizeof r->scene_hash, "%016llx", (unsigned long long)hsh);
        snprintf(r->settings, sizeof r->settings,
                 "scene %s; film %dx%d; camera %s; spp %d; seed %u; sampler %s; filter %s; maxdepth %d; white %d",
                 r->scene_hash, r->xres, r->yres, r->camera_name, r->sampler.spp, r->sampler.seed, r->sampler_name,
                 r->filter_name, r->integrator.max_depth, opts->white);
    }
    if (r->px0 < 0 || r->py0 < 0 || r->px1 > r->xres || r->py1 > r->yres || r->px1 <= r->px0 || r->py1 <= r->py0) {
        lf_error_set(err, LF_ERR_PARAM, "crop window [%d,%d) x [%d,%d) is empty or outside the %dx%d film", r->px0,
                     r->px1, r->py0, r->py1, r->xres, r->yres);
        goto fail;
    }
    r->white = opts->white;
    if (opts->white) {
        /* The white image ignores the world: mark its parameters read. */
        for (size_t i = 0; i < d->n_shapes; i++)
            for (size_t k = 0; k < d->shapes[i].e.params.count; k++)
                d->shapes[i].e.params.items[k].used = 1;
        if (lf_scene_build_white(&r->scene, err))
            goto fail;
    } else if (lf_scene_build(d, &r->scene, err)) {
        goto fail;
    }
    lf_warn_block(&r->warnings, lf_warnings_text(&r->scene.warnings));
    if (r->scene.has_media && !r->integrator.volumetric) {
        lf_warn_at(&r->warnings, &d->integrator.loc,
                   "Integrator \"path\" ignores participating media (as pbrt-v4's); \"volpath\" "
                   "renders them");
    }
    if (!r->white && r->scene.n_lights == 0) /* a black image is all such a scene can make */
        lf_warn_at(&r->warnings, NULL, "%s: the image will be black",
                   r->scene.n_meshes + r->scene.n_spheres + r->scene.n_instances
                       ? "nothing lights the world (no LightSource and no AreaLightSource)"
                       : "the world is empty (no shapes and no lights)");
    if (d->accelerator.type)
        for (size_t i = 0; i < d->accelerator.params.count; i++)
            d->accelerator.params.items[i].used = 1; /* Embree builds its own BVH */
    /* Time is sampled only when something moves: a static scene renders the
     * same bits whatever the shutter says, and pays nothing for it. */
    r->time_needed = (r->scene.moving_shapes > 0 || r->camera_moving) && r->shutter_close >= r->shutter_open;
    if (r->raw && prepare_sensor(r, err))
        goto fail;
    long nproc = sysconf(_SC_NPROCESSORS_ONLN);
    r->threads = opts->threads > 0 ? opts->threads : (nproc > 0 ? (int)nproc : 1);
    *out = r;
    return 0;
fail:
    lf_renderer_free(r);
    return err && err->code ? err->code : LF_ERR_INTERNAL;
}

void lf_renderer_set_opts(lf_renderer *r, const lf_render_opts *opts)
{
    r->opts.checkpoint_path = opts->checkpoint_path;
    r->opts.checkpoint_every = opts->checkpoint_every;
    r->opts.resume = opts->resume;
    r->opts.stop = opts->stop;
    r->opts.progress = opts->progress;
    r->opts.progress_ctx = opts->progress_ctx;
}

const char *lf_renderer_warnings(const lf_renderer *r) { return lf_warnings_text(&r->warnings); }

const char *lf_renderer_film_filename(const lf_renderer *r)
{
    return r->film_filename;
}

int lf_renderer_film_half(const lf_renderer *r)
{
    return r->save_half;
}

lf_render_stats lf_renderer_stats(const lf_renderer *r)
{
    return r->stats;
}

void lf_renderer_free(lf_renderer *r)
{
    if (!r)
        return;
    if (r->camera && r->camera_type)
        r->camera_type->destroy(r->camera);
    lf_sampler_free(&r->sampler);
    lf_motion_table_free(&r->camera_table);
    if (r->scene.device || r->scene.meshes || r->scene.materials)
        lf_scene_free(&r->scene);
    if (r->has_curve)
        lf_distrib1d_free(&r->curve);
    lf_filter_free(&r->filter);
    free(r->film_filename);
    free(r->camera_name);
    free(r->sampler_name);
    free(r->filter_name);
    free(r->integrator_name);
    free(r->scene_path);
    lf_warnings_free(&r->warnings);
    free(r);
}

/* ---- the effect plan ---- */

char *lf_renderer_explain(const lf_renderer *r)
{
    lf_strbuf b = {0};
    const lf_scene *s = &r->scene;
    lf_strbuf_printf(&b, "scene: %s\n", r->scene_path ? r->scene_path : "(memory)");
    lf_strbuf_printf(&b, "film: %dx%d, rendering pixels [%d,%d) x [%d,%d), diagonal %g mm\n", r->xres, r->yres,
            r->px0, r->px1, r->py0, r->py1, r->diagonal_mm);
    lf_strbuf_printf(&b, "camera: \"%s\"\n", r->camera_name);
    if (r->camera_type->describe) {
        char desc[4096];
        int n = r->camera_type->describe(r->camera, desc, sizeof desc);
        if (n > 0) {
            char *line = desc, *nl;
            while (line && *line) {
                nl = strchr(line, '\n');
                if (nl)
                    *nl = '\0';
                lf_strbuf_printf(&b, "  %s\n", line);
                line = nl ? nl + 1 : NULL;
            }
        }
    }
    lf_strbuf_printf(&b, "effects:\n");
    lf_strbuf_printf(&b, "  defocus: %s\n",
            r->camera_needs & LF_CAMERA_NEEDS_LENS ? "on (the camera samples its lens)"
                                                   : "off (pinhole: no lens samples drawn)");
    if (r->time_needed) {
        char shapes[512];
        lf_scene_motion_summary(s, shapes, sizeof shapes);
        lf_strbuf_printf(&b, "  motion blur: on (%s; camera %s); one time sample per camera ray in [%g, %g]\n",
                shapes, r->camera_moving ? "moving" : "static", r->shutter_open,
                r->shutter_close + (r->rolling ? r->readout : 0));
    } else {
        lf_strbuf_printf(&b, "  motion blur: off (nothing moves%s; static BVH, no time samples)\n",
                r->shutter_close > r->shutter_open ? "" : " and the shutter is an instant");
    }
    if (r->rolling)
        lf_strbuf_printf(&b, "  rolling shutter: on, readout %g s %s, exposure %g s per row%s\n", r->readout,
                (const char *[]){"top to bottom", "bottom to top", "left to right", "right to left"}[r->readout_dir],
                r->shutter_close - r->shutter_open, r->time_needed ? "" : " (nothing moves: no visible effect)");
    else
        lf_strbuf_printf(&b, "  rolling shutter: off (global shutter %g..%g)\n", r->shutter_open, r->shutter_close);
    if (r->has_curve)
        lf_strbuf_printf(&b, "  shutter curve: mean efficiency %.4g, times importance-sampled\n", r->curve_mean);
    lf_strbuf_printf(&b, "  dispersion: %s\n",
            r->camera_needs & LF_CAMERA_NEEDS_WAVELENGTH ? "on (the camera samples wavelength)"
                                                         : "off (no wavelength samples)");
    lf_strbuf_printf(&b, "  exposure: imaging ratio %g (shutter %g s x ISO/100)\n", r->imaging_ratio,
            r->shutter_close - r->shutter_open);
    lf_strbuf_printf(&b, "sampler: %s (%s), %d spp, seed %u\n", r->sampler_name,
            r->sampler.kind == LF_SAMPLER_SOBOL        ? "Owen-scrambled Sobol, padded pairs"
            : r->sampler.kind == LF_SAMPLER_HALTON
                ? (r->sampler.randomize == LF_HALTON_OWEN   ? "image-wide Halton, Owen-scrambled digits"
                   : r->sampler.randomize == LF_HALTON_NONE ? "image-wide Halton, not randomised"
                                                            : "image-wide Halton, random digit permutations")
            : r->sampler.kind == LF_SAMPLER_PMJ02BN    ? "progressive multi-jittered (0,2) with blue noise"
            : r->sampler.kind == LF_SAMPLER_STRATIFIED ? "jittered strata"
                                                       : "independent uniform",
            r->sampler.spp, r->sampler.seed);
    lf_strbuf_printf(&b, "filter: %s, radius %g x %g\n", r->filter_name, r->filter.radius[0], r->filter.radius[1]);
    char rr[96];
    snprintf(rr, sizeof rr, "Russian roulette %s after depth %d",
             r->integrator.rr_rule == LF_RR_SQRT ? "p = sqrt(max throughput)" : "p = max throughput (pbrt-v4)",
             r->integrator.rr_depth);
    if (s->has_media && r->integrator.volumetric)
        lf_strbuf_printf(&b,
                "integrator: %s -> volumetric path tracing with NEE + MIS, maxdepth %d, %s; %d "
                "homogeneous media (closed-form transmittance, spectral-MIS distance sampling, Henyey-Greenstein), "
                "camera in %s\n",
                r->integrator_name, r->integrator.max_depth, rr, s->n_media,
                s->camera_medium >= 0 ? "a medium" : "vacuum");
    else
        lf_strbuf_printf(&b, "integrator: %s -> path tracing with NEE + MIS, maxdepth %d, %s%s\n",
                r->integrator_name, r->integrator.max_depth, rr,
                s->n_media ? " (media defined but no ray can enter one, or ignored by \"path\")" : "");
    lf_strbuf_printf(&b, "geometry: %lld triangles in %d meshes, %d analytic spheres (Embree %s)\n",
            s->n_triangles, s->n_meshes, s->n_spheres,
            s->moving_shapes ? "BVH with motion nodes for the moving shapes" : "static BVH");
    int counts[LF_LIGHT_SPHERE + 1] = {0};
    for (int i = 0; i < s->n_lights; i++)
        counts[s->lights[i].kind]++;
    lf_light_sampler lsm = lf_light_sampler_for(&r->integrator, s);
    lf_strbuf_printf(&b,
            "lights: %d (point %d, spot %d, distant %d, infinite %d, image infinite %d, area triangles %d, area "
            "quads %d, area spheres %d), %s\n",
            s->n_lights, counts[LF_LIGHT_POINT], counts[LF_LIGHT_SPOT], counts[LF_LIGHT_DISTANT],
            counts[LF_LIGHT_INFINITE_UNIFORM], counts[LF_LIGHT_INFINITE_IMAGE], counts[LF_LIGHT_TRIANGLE],
            counts[LF_LIGHT_PARALLELOGRAM], counts[LF_LIGHT_SPHERE],
            lsm == LF_LIGHTS_ALL       ? "every light sampled at every vertex (one shadow ray each)"
            : lsm == LF_LIGHTS_UNIFORM ? "one light per vertex, chosen uniformly"
                                       : "one light per vertex, chosen by power");
    if (r->raw)
        lf_sensor_explain(&r->sensor, &b);
    else if (lf_camera_curves_find(r->sensor.curves))
        lf_strbuf_printf(&b,
                         "sensor: none (Film \"rgb\": noiseless linear exposure through the %s curves and their XYZ "
                         "fit)\n",
                         r->sensor.curves);
    else
        lf_strbuf_printf(&b, "sensor: none (Film \"rgb\": noiseless linear exposure%s)\n",
                         r->has_wb ? ", white balanced" : "");
    lf_strbuf_printf(&b, "threads: %d\n", r->threads);
    if (b.failed) { /* out of memory: no half a plan */
        lf_strbuf_free(&b);
        return NULL;
    }
    return lf_strbuf_take(&b);
}

/* ---- rendering ---- */

enum { TILE = 16 };

typedef struct job {
    lf_renderer *r;
    lf_image *img;
    lf_pixel_acc *acc;        /* per-pixel sums when writing parts or checkpoints, else NULL */
    int tiles_x, tiles_y;
    atomic_long done_tiles;
    atomic_uchar *tile_done;  /* 1 once a tile's pixels are final */
    int *order;               /* tiles still to render, in order */
    int n_order;
    atomic_llong rays, paths, nonfinite, zero_weight;
    pthread_mutex_t progress_lock;
} job;

/* Scene time of a camera ray: within the exposure [open, close] (shifted
 * per row or column by a rolling shutter's readout), distributed by the
 * shutter efficiency curve when there is one. */
static double shutter_time(const lf_renderer *r, double u, double film_x, double film_y)
{
    double x = u;
    if (r->has_curve)
        x = lf_distrib1d_sample(&r->curve, u, NULL, NULL);
    double start = r->shutter_open;
    if (r->rolling) {
        double f;
        switch (r->readout_dir) {
        case 1: f = 1 - film_y / r->yres; break;
        case 2: f = film_x / r->xres; break;
        case 3: f = 1 - film_x / r->xres; break;
        default: f = film_y / r->yres; break;
        }
        start += lf_clampd(f, 0, 1) * r->readout;
    }
    return start + x * (r->shutter_close - r->shutter_open);
}

/* One camera sample waiting for its ray: the pixel it belongs to, its
 * sample stream (positioned after the camera's dimensions, so the path goes
 * on drawing from it), filter weight and motion parameter. */
typedef struct pending {
    lf_sample_stream st;
    int pixel; /* index within the tile */
    double fw, tau;
} pending;

enum { BATCH = 32 }; /* camera rays generated together (lf_camera_type.generate_rays) */

/* Traces one camera ray and adds its contribution to the pixel's exact
 * fixed-point sums (integer sums: the order of samples does not matter, so
 * batching and splitting renders never change a bit). */
static void trace_camera_ray(const lf_renderer *r, pending *p, const lf_camera_ray *cr, double w, lf_pixel_acc *acc,
                             long long *rays, long long *nonfinite, long long *zero_weight)
{
    acc->v[3] += lf_acc_quantize(p->fw);
    if (!(w > 0) || !isfinite(w)) {
        (*zero_weight)++;
        return;
    }
    lf_transform moving;
    const lf_transform *c2w = &r->camera_to_world;
    if (r->camera_moving) {
        /* forward matrix only: the ray needs no inverse */
        if (r->camera_table.n)
            lf_motion_table_matrix(&r->camera_table, p->tau, moving.m);
        else
            lf_motion_pair_matrix(&r->camera_motion, p->tau, moving.m);
        c2w = &moving;
    }
    /* Rays from the camera's centre (pinhole, fisheye) start at its world
     * position: computed once for a still camera, the translation column of
     * a moving one's matrix (the same numbers as transforming 0). */
    int centre = cr->origin[0] == 0 && cr->origin[1] == 0 && cr->origin[2] == 0;
    lf_dvec3 o = centre && !r->camera_moving ? r->camera_origin_world
                 : centre ? (lf_dvec3){moving.m[0][3], moving.m[1][3], moving.m[2][3]} /* M (0,0,0,1): exact */
                          : lf_xform_point_d(c2w, (lf_dvec3){cr->origin[0], cr->origin[1], cr->origin[2]});
    lf_dvec3 d = lf_xform_vector_d(c2w, (lf_dvec3){cr->dir[0], cr->dir[1], cr->dir[2]});
    double dl = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    lf_vec3 of = lf_v3((float)o.x, (float)o.y, (float)o.z);
    lf_vec3 df = lf_v3((float)(d.x / dl), (float)(d.y / dl), (float)(d.z / dl));
    lf_vec3 L = r->scene.has_media && r->integrator.volumetric
                    ? lf_volpath_li(&r->scene, &r->integrator, of, df, (float)p->tau, r->scene.camera_medium, &p->st,
                                    rays)
                    : lf_path_li(&r->scene, &r->integrator, of, df, (float)p->tau, &p->st, rays);
    L = lf_scale(L, (float)w * (float)r->imaging_ratio);
    if (r->has_wb)
        L = lf_v3(r->wb[0][0] * L.x + r->wb[0][1] * L.y + r->wb[0][2] * L.z,
                  r->wb[1][0] * L.x + r->wb[1][1] * L.y + r->wb[1][2] * L.z,
                  r->wb[2][0] * L.x + r->wb[2][1] * L.y + r->wb[2][2] * L.z);
    if ((r->camera_needs & LF_CAMERA_NEEDS_WAVELENGTH) && cr->wavelength_nm > 0)
        L = lf_mul(L, lf_wavelength_rgb_weight(cr->wavelength_nm));
    if (!isfinite(L.x) || !isfinite(L.y) || !isfinite(L.z)) {
        (*nonfinite)++;
        return;
    }
    if (isfinite(r->max_component)) {
        float m = lf_maxc(L);
        if (m > r->max_component)
            L = lf_scale(L, (float)(r->max_component / m));
    }
    acc->v[0] += lf_acc_quantize(p->fw * L.x);
    acc->v[1] += lf_acc_quantize(p->fw * L.y);
    acc->v[2] += lf_acc_quantize(p->fw * L.z);
}

/* A tile: its camera samples are drawn pixel by pixel and sample by sample,
 * their rays generated BATCH at a time (so a camera can trace them side by
 * side), then each path is traced. */
static void render_tile(job *jb, int tile, long long *rays, long long *paths, long long *nonfinite,
                        long long *zero_weight)
{
    lf_renderer *r = jb->r;
    int tx = tile % jb->tiles_x, ty = tile / jb->tiles_x;
    int x0 = r->px0 + tx * TILE, y0 = r->py0 + ty * TILE;
    int x1 = x0 + TILE < r->px1 ? x0 + TILE : r->px1, y1 = y0 + TILE < r->py1 ? y0 + TILE : r->py1;
    int tw = x1 - x0, th = y1 - y0;
    int need_lens = (r->camera_needs & LF_CAMERA_NEEDS_LENS) != 0;
    int need_wl = (r->camera_needs & LF_CAMERA_NEEDS_WAVELENGTH) != 0;
    lf_pixel_acc acc[TILE * TILE];
    memset(acc, 0, sizeof acc);
    pending pend[BATCH];
    lf_camera_sample cs[BATCH];
    lf_camera_ray cr[BATCH];
    double w[BATCH];
    int nb = 0;
    int spp = r->spp_end - r->spp_begin;
    long long total = (long long)tw * th * spp;
    /* pixel and sample index of path k = pixel * spp + (i - spp_begin),
     * stepped rather than divided; the pixel's sample hash once per pixel */
    int pixel = 0, i = r->spp_begin, x = x0, y = y0;
    uint32_t pixel_hash = lf_sample_pixel_hash(&r->sampler, x, y);
    for (long long k = 0; k < total; k++) {
        if (i == r->spp_end) {
            i = r->spp_begin;
            pixel++;
            if (++x == x1)
                x = x0, y++;
            pixel_hash = lf_sample_pixel_hash(&r->sampler, x, y);
        }
        pending *p = &pend[nb];
        lf_camera_sample *c = &cs[nb];
        p->pixel = pixel;
        lf_sample_start_pixel(&p->st, &r->sampler, pixel_hash, x, y, (uint32_t)i++);
        /* Film position and time are drawn together (lf_sample_3d_d): motion
         * blur integrates over both at once, so their joint stratification
         * pays where separate draws would only stratify each alone. */
        double fu, fv, ut = 0, dx, dy;
        if (r->time_needed)
            lf_sample_3d_d(&p->st, &fu, &fv, &ut);
        else
            lf_sample_2d_d(&p->st, &fu, &fv);
        p->fw = lf_filter_sample(&r->filter, fu, fv, &dx, &dy);
        c->film_x = x + 0.5 + dx;
        c->film_y = y + 0.5 + dy;
        c->lens_u = c->lens_v = 0.5;
        if (need_lens)
            lf_sample_2d_d(&p->st, &c->lens_u, &c->lens_v);
        p->tau = 0;
        c->time = r->shutter_open;
        if (r->time_needed) {
            c->time = shutter_time(r, ut, c->film_x, c->film_y);
            double tau = r->time1 > r->time0 ? (c->time - r->time0) / (r->time1 - r->time0) : 0;
            p->tau = tau < 0 ? 0 : (tau > 1 ? 1 : tau); /* Embree asserts 0 <= time <= 1 */
        }
        c->wavelength_u = 0.5;
        if (need_wl) {
            c->wavelength_u = lf_sample_1d_d(&p->st);
        }
        cr[nb].time = c->time;
        cr[nb].wavelength_nm = 0;
        if (++nb < BATCH && k + 1 < total)
            continue;
        lf_camera_generate_rays(r->camera_type, r->camera, nb, cs, cr, w);
        *paths += nb;
        for (int j = 0; j < nb; j++)
            trace_camera_ray(r, &pend[j], &cr[j], w[j], &acc[pend[j].pixel], rays, nonfinite, zero_weight);
        nb = 0;
    }
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const lf_pixel_acc *a = &acc[(y - y0) * tw + (x - x0)];
            float *px = lf_image_px(jb->img, x - r->px0, y - r->py0);
            for (int c = 0; c < 3; c++)
                px[c] = lf_acc_value(a, c);
            if (jb->acc)
                jb->acc[(size_t)(y - r->py0) * jb->img->width + (x - r->px0)] = *a;
        }
}

/* Tiles jb->order[k0, k1) (lf_parallel_fn: the threads take tiles one at a
 * time, in order, from base/lf_parallel.h's counter). */
static void render_tiles(void *arg, int k0, int k1, int tid)
{
    (void)tid;
    job *jb = arg;
#if defined(__SSE__) || defined(__x86_64__)
    /* Denormals slow float math by orders of magnitude and carry no light. */
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    long long rays = 0, paths = 0, nonfinite = 0, zero_weight = 0;
    int total = jb->tiles_x * jb->tiles_y;
    volatile int *stop = jb->r->opts.stop;
    for (int k = k0; k < k1; k++) {
        if (stop && *stop)
            break;
        int t = jb->order[k];
        render_tile(jb, t, &rays, &paths, &nonfinite, &zero_weight);
        atomic_store_explicit(&jb->tile_done[t], 1, memory_order_release);
        long done = atomic_fetch_add(&jb->done_tiles, 1) + 1;
        if (jb->r->opts.progress) {
            pthread_mutex_lock(&jb->progress_lock);
            jb->r->opts.progress(jb->r->opts.progress_ctx, done, total);
            pthread_mutex_unlock(&jb->progress_lock);
        }
    }
    atomic_fetch_add(&jb->rays, rays);
    atomic_fetch_add(&jb->paths, paths);
    atomic_fetch_add(&jb->nonfinite, nonfinite);
    atomic_fetch_add(&jb->zero_weight, zero_weight);
}

static void sink_string(void *ctx, const char *name, const char *value)
{
    lf_attrs_set_string(ctx, name, value, NULL);
}
static void sink_int(void *ctx, const char *name, int value)
{
    lf_attrs_set_int(ctx, name, value, NULL);
}
static void sink_double(void *ctx, const char *name, double value)
{
    lf_attrs_set_double(ctx, name, value, NULL);
}
static void sink_doubles(void *ctx, const char *name, const double *v, int n)
{
    float tmp[64];
    if (n > 64)
        n = 64;
    for (int i = 0; i < n; i++)
        tmp[i] = (float)v[i];
    lf_attrs_set_floats(ctx, name, tmp, n, NULL);
}

int lf_renderer_disparity(lf_renderer *r, lf_image *out, lf_error *err)
{
    memset(out, 0, sizeof *out);
    lf_attrs meta = {0};
    if (r->camera_type->metadata) {
        lf_camera_attr_sink sink = {&meta, sink_string, sink_int, sink_double, sink_doubles};
        r->camera_type->metadata(r->camera, &sink);
    }
    lf_disparity_geom g;
    int rc = lf_disparity_geom_init(&meta, r->xres, r->yres, &g, err);
    lf_attrs_free(&meta);
    if (rc)
        return rc;
    if ((rc = lf_image_alloc(out, r->px1 - r->px0, r->py1 - r->py0, 1, err)))
        return rc;
    /* the scene and camera as they are when the shutter opens */
    double tau = r->time1 > r->time0 ? (r->shutter_open - r->time0) / (r->time1 - r->time0) : 0;
    tau = tau < 0 ? 0 : tau > 1 ? 1 : tau;
    lf_transform moving;
    const lf_transform *c2w = &r->camera_to_world;
    if (r->camera_moving) {
        lf_motion_pair_matrix(&r->camera_motion, tau, moving.m);
        c2w = &moving;
    }
    for (int y = r->py0; y < r->py1; y++)
        for (int x = r->px0; x < r->px1; x++) {
            double o[3], d[3];
            lf_disparity_centre_ray(&g, x + 0.5, y + 0.5, o, d);
            lf_dvec3 ow = lf_xform_point_d(c2w, (lf_dvec3){o[0], o[1], o[2]});
            lf_dvec3 dw = lf_xform_vector_d(c2w, (lf_dvec3){d[0], d[1], d[2]});
            double len = sqrt(dw.x * dw.x + dw.y * dw.y + dw.z * dw.z);
            lf_hit hit;
            float disp = (float)g.a; /* nothing hit: infinitely far */
            if (lf_scene_intersect(&r->scene, lf_v3((float)ow.x, (float)ow.y, (float)ow.z),
                                   lf_v3((float)(dw.x / len), (float)(dw.y / len), (float)(dw.z / len)), INFINITY,
                                   (float)tau, &hit)) {
                /* world distance / |M d| = camera-space distance along the unit d */
                double z = o[2] + hit.t / len * d[2];
                if (z > 0)
                    disp = (float)(g.a + g.b / z);
            }
            out->data[(size_t)(y - r->py0) * out->width + (x - r->px0)] = disp;
        }
    return LF_OK;
}

/* ---- parts and checkpoints ---- */

/* The image written for parts and checkpoints: RGB preview, then the four
 * accumulators as 24-bit limbs (film.h). */
static int acc_image(const job *jb, const unsigned char *done, lf_image *out, lf_error *err)
{
    const lf_image *img = jb->img;
    if (lf_image_alloc(out, img->width, img->height, 3 + LF_ACC_CHANNELS, err))
        return err->code;
    for (int ty = 0; ty < jb->tiles_y; ty++)
        for (int tx = 0; tx < jb->tiles_x; tx++) {
            int t = ty * jb->tiles_x + tx;
            if (done && !done[t])
                continue;
            for (int y = ty * TILE; y < (ty + 1) * TILE && y < img->height; y++)
                for (int x = tx * TILE; x < (tx + 1) * TILE && x < img->width; x++) {
                    float *o = lf_image_px(out, x, y);
                    const lf_pixel_acc *a = &jb->acc[(size_t)y * img->width + x];
                    for (int c = 0; c < 3; c++)
                        o[c] = lf_acc_value(a, c);
                    for (int k = 0; k < 4; k++)
                        lf_acc_to_limbs(a->v[k], o + 3 + LF_ACC_LIMBS * k);
                }
        }
    return 0;
}

static void done_tiles_hex(const job *jb, const unsigned char *done, char *buf, size_t n)
{
    int total = jb->tiles_x * jb->tiles_y;
    size_t k = 0;
    for (int t = 0; t < total && k + 1 < n; t += 4) {
        int v = 0;
        for (int b = 0; b < 4 && t + b < total; b++)
            if (done[t + b])
                v |= 1 << b;
        buf[k++] = "0123456789abcdef"[v];
    }
    buf[k] = '\0';
}

static void part_attrs(const lf_renderer *r, lf_attrs *meta)
{
    lf_attrs_set_string(meta, LF_KEY_SETTINGS, r->settings, NULL);
    lf_attrs_set_int(meta, LF_KEY_SPP_BEGIN, r->spp_begin, NULL);
    lf_attrs_set_int(meta, LF_KEY_SPP_END, r->spp_end, NULL);
    lf_attrs_set_int(meta, LF_KEY_SPP_TOTAL, r->sampler.spp, NULL);
    float res[2] = {(float)r->xres, (float)r->yres};
    lf_attrs_set_floats(meta, LF_KEY_FULL_RESOLUTION, res, 2, NULL);
    float crop[4] = {(float)r->px0, (float)r->px1, (float)r->py0, (float)r->py1};
    lf_attrs_set_floats(meta, LF_KEY_PIXEL_BOUNDS, crop, 4, NULL);
}

static int write_checkpoint(const lf_renderer *r, const job *jb, lf_error *err)
{
    /* One snapshot of which tiles are final, used for both the pixels and
     * the list, so a tile finishing meanwhile cannot be listed without its
     * pixels. */
    int ntiles = jb->tiles_x * jb->tiles_y;
    unsigned char *done = malloc((size_t)ntiles);
    if (!done)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (int t = 0; t < ntiles; t++)
        done[t] = atomic_load_explicit(&jb->tile_done[t], memory_order_acquire);
    lf_image ck;
    if (acc_image(jb, done, &ck, err)) {
        free(done);
        return err->code;
    }
    lf_attrs a = {0};
    part_attrs(r, &a);
    int total = jb->tiles_x * jb->tiles_y;
    char *hex = malloc((size_t)total / 4 + 2);
    if (!hex) {
        free(done);
        lf_image_free(&ck);
        lf_attrs_free(&a);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    done_tiles_hex(jb, done, hex, (size_t)total / 4 + 2);
    free(done);
    lf_attrs_set_string(&a, LF_KEY_DONE_TILES, hex, err);
    lf_attrs_set_int(&a, LF_KEY_CHECKPOINT, 1, err);
    free(hex);
    lf_write_opts wo = {0};
    int rc = lf_image_write(r->opts.checkpoint_path, &ck, &a, &wo, err);
    lf_image_free(&ck);
    lf_attrs_free(&a);
    return rc;
}

/* Loads a checkpoint written by the same scene and settings: its finished
 * tiles are copied and skipped. */
static int load_checkpoint(lf_renderer *r, job *jb, lf_error *err)
{
    lf_image ck;
    lf_attrs a = {0};
    lf_error e = {0};
    if (lf_image_read(r->opts.checkpoint_path, &ck, &a, &e))
        return lf_error_set(err, e.code, "cannot resume: %s", e.msg);
    const lf_attr *st = lf_attrs_get(&a, LF_KEY_SETTINGS), *hex = lf_attrs_get(&a, LF_KEY_DONE_TILES);
    const lf_attr *b0 = lf_attrs_get(&a, LF_KEY_SPP_BEGIN), *b1 = lf_attrs_get(&a, LF_KEY_SPP_END);
    const lf_attr *pb = lf_attrs_get(&a, LF_KEY_PIXEL_BOUNDS);
    int ok = st && st->type == LF_ATTR_STRING && !strcmp(st->s, r->settings) && hex && hex->type == LF_ATTR_STRING &&
             b0 && b1 && b0->i == r->spp_begin && b1->i == r->spp_end && pb && pb->n == 4 && pb->v[0] == r->px0 &&
             pb->v[1] == r->px1 && pb->v[2] == r->py0 && pb->v[3] == r->py1 && ck.width == jb->img->width &&
             ck.height == jb->img->height && ck.channels == 3 + LF_ACC_CHANNELS;
    if (!ok) {
        lf_image_free(&ck);
        lf_attrs_free(&a);
        return lf_error_set(err, LF_ERR_PARAM,
                            "cannot resume from %s: it was written by a different scene, settings, sample range or "
                            "crop",
                            r->opts.checkpoint_path);
    }
    int total = jb->tiles_x * jb->tiles_y;
    size_t nhex = strlen(hex->s);
    for (int t = 0; t < total; t++) {
        size_t k = (size_t)t / 4;
        if (k >= nhex)
            break;
        char ch = hex->s[k];
        int v = ch >= '0' && ch <= '9' ? ch - '0' : (ch >= 'a' && ch <= 'f' ? ch - 'a' + 10 : 0);
        if (!(v & (1 << (t % 4))))
            continue;
        int tx = t % jb->tiles_x, ty = t / jb->tiles_x;
        for (int y = ty * TILE; y < (ty + 1) * TILE && y < ck.height; y++)
            for (int x = tx * TILE; x < (tx + 1) * TILE && x < ck.width; x++) {
                const float *in = lf_image_px(&ck, x, y);
                lf_pixel_acc *acc = &jb->acc[(size_t)y * ck.width + x];
                for (int c = 0; c < 4; c++)
                    acc->v[c] = lf_acc_from_limbs(in + 3 + LF_ACC_LIMBS * c);
                float *px = lf_image_px(jb->img, x, y);
                for (int c = 0; c < 3; c++)
                    px[c] = lf_acc_value(acc, c);
            }
        atomic_store(&jb->tile_done[t], 1);
    }
    lf_image_free(&ck);
    lf_attrs_free(&a);
    return 0;
}

/* Renders on worker threads while the calling thread watches: periodic
 * checkpoints and stop requests; a stopped render leaves a final
 * checkpoint of every finished tile. */
static int render_watched(lf_renderer *r, job *jb, int total, lf_error *err)
{
    int rc = 0;
    lf_parallel_job *pj = lf_parallel_start(jb->n_order, r->threads, 1, render_tiles, jb);
    double last = lf_seconds();
    for (;;) {
        long done = atomic_load(&jb->done_tiles);
        if (done >= total || (r->opts.stop && *r->opts.stop))
            break;
        struct timespec ts = {0, 20 * 1000 * 1000};
        nanosleep(&ts, NULL);
        if (r->opts.checkpoint_every > 0 && lf_seconds() - last >= r->opts.checkpoint_every) {
            lf_error cerr = {0};
            if (write_checkpoint(r, jb, &cerr) && !rc)
                rc = lf_error_set(err, cerr.code, "checkpoint: %s", cerr.msg);
            last = lf_seconds();
        }
    }
    lf_parallel_join(pj);
    if (atomic_load(&jb->done_tiles) < total) {
        /* stopped: the final checkpoint holds every finished tile */
        lf_error cerr = {0};
        if (write_checkpoint(r, jb, &cerr))
            rc = lf_error_set(err, cerr.code, "final checkpoint: %s", cerr.msg);
        else
            rc = lf_error_set(err, LF_ERR_INTERRUPTED,
                              "interrupted with %ld of %d tiles done; checkpoint written to %s (continue with "
                              "--resume)",
                              atomic_load(&jb->done_tiles), total, r->opts.checkpoint_path);
    }
    return rc;
}

/* What the image's lensfield:* attributes record of this render. */
/* The render's lensfield:* metadata; LF_ERR_NOMEM (in err) if an attribute
 * could not be stored. */
static int render_attrs(const lf_renderer *r, lf_attrs *meta, lf_error *err)
{
    lf_attrs_set_string(meta, LF_KEY_VERSION, LF_VERSION_STRING, err);
    lf_attrs_set_string(meta, LF_KEY_CAMERA, r->camera_name, err);
    if (r->scene_path)
        lf_attrs_set_string(meta, LF_KEY_SCENE, r->scene_path, err);
    lf_attrs_set_int(meta, LF_KEY_SPP, r->spp_end - r->spp_begin, err);
    lf_attrs_set_string(meta, LF_KEY_SCENE_HASH, r->scene_hash, err);
    lf_attrs_set_int(meta, LF_KEY_SAVEFP16, r->save_half, err);
    if (r->opts.part) {
        lf_attrs_set_int(meta, LF_KEY_PART, 1, err);
        part_attrs(r, meta);
    }
    lf_attrs_set_int(meta, LF_KEY_SEED, (int)r->sampler.seed, err);
    lf_attrs_set_string(meta, LF_KEY_SAMPLER, r->sampler_name, err);
    lf_attrs_set_string(meta, LF_KEY_FILTER, r->filter_name, err);
    lf_attrs_set_int(meta, LF_KEY_MAXDEPTH, r->integrator.max_depth, err);
    lf_attrs_set_double(meta, LF_KEY_RENDER_TIME_S, r->stats.seconds, err);
    lf_attrs_set_int(meta, LF_KEY_THREADS, r->threads, err);
    float res[2] = {(float)r->xres, (float)r->yres};
    lf_attrs_set_floats(meta, LF_KEY_FULL_RESOLUTION, res, 2, err);
    float crop[4] = {(float)r->px0, (float)r->px1, (float)r->py0, (float)r->py1};
    lf_attrs_set_floats(meta, LF_KEY_PIXEL_BOUNDS, crop, 4, err);
    lf_attrs_set_double(meta, LF_KEY_FILM_DIAGONAL_MM, r->diagonal_mm, err);
    lf_attrs_set_double(meta, LF_KEY_SHUTTER_OPEN, r->shutter_open, err);
    lf_attrs_set_double(meta, LF_KEY_SHUTTER_CLOSE, r->shutter_close, err);
    lf_attrs_set_double(meta, LF_KEY_IMAGING_RATIO, r->imaging_ratio, err);
    lf_attrs_set_int(meta, LF_KEY_NONFINITE_SAMPLES, (int)r->stats.nonfinite_samples, err);
    double m[16];
    for (int i = 0; i < 16; i++)
        m[i] = r->world_to_camera.m[i / 4][i % 4];
    lf_attrs_set_m44d(meta, LF_KEY_WORLD_TO_CAMERA, m, err);
    if (r->white)
        lf_attrs_set_int(meta, LF_KEY_WHITE, 1, err);
    lf_attrs_set_string(meta, LF_KEY_SHUTTER, r->rolling ? "rolling" : "global", err);
    if (r->rolling) {
        lf_attrs_set_double(meta, LF_KEY_READOUT_TIME, r->readout, err);
        lf_attrs_set_string(meta, LF_KEY_READOUT_DIRECTION,
                            (const char *[]){"toptobottom", "bottomtotop", "lefttoright", "righttoleft"}[r->readout_dir], err);
    }
    if (r->has_curve)
        lf_attrs_set_double(meta, LF_KEY_SHUTTER_EFFICIENCY, r->curve_mean, err);
    lf_attrs_set_int(meta, LF_KEY_MOTION_BLUR, r->time_needed, err);
    if (r->raw)
        lf_sensor_to_attrs(&r->sensor, meta, err);
    if (r->camera_type->metadata) {
        lf_camera_attr_sink sink = {meta, sink_string, sink_int, sink_double, sink_doubles};
        r->camera_type->metadata(r->camera, &sink);
    }
    return err ? err->code : 0;
}

int lf_renderer_render(lf_renderer *r, lf_image *img, lf_attrs *meta, lf_error *err)
{
    int w = r->px1 - r->px0, h = r->py1 - r->py0;
    if (lf_image_alloc(img, w, h, 3, err))
        return err->code;
    job jb;
    memset(&jb, 0, sizeof jb);
    jb.r = r;
    jb.img = img;
    jb.tiles_x = (w + TILE - 1) / TILE;
    jb.tiles_y = (h + TILE - 1) / TILE;
    int total = jb.tiles_x * jb.tiles_y;
    jb.tile_done = calloc((size_t)total, sizeof *jb.tile_done);
    jb.order = malloc(sizeof(int) * (size_t)total);
    int need_acc = r->opts.part || r->opts.checkpoint_path;
    if (need_acc)
        jb.acc = calloc((size_t)w * h, sizeof *jb.acc);
    if (!jb.tile_done || !jb.order || (need_acc && !jb.acc)) {
        free(jb.tile_done), free(jb.order), free(jb.acc);
        lf_image_free(img);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory for a %dx%d film", w, h);
    }
    struct stat ck_stat;
    int have_checkpoint = r->opts.checkpoint_path && stat(r->opts.checkpoint_path, &ck_stat) == 0;
    /* --resume without a checkpoint yet (killed before the first one) starts over */
    if (r->opts.resume && have_checkpoint && load_checkpoint(r, &jb, err)) {
        free(jb.tile_done), free(jb.order), free(jb.acc);
        lf_image_free(img);
        return err->code;
    }
    for (int t = 0; t < total; t++)
        if (!atomic_load(&jb.tile_done[t]))
            jb.order[jb.n_order++] = t;
    atomic_store(&jb.done_tiles, total - jb.n_order);
    pthread_mutex_init(&jb.progress_lock, NULL);
    double t0 = lf_seconds();
    int rc = 0;
    if (!r->opts.checkpoint_path) {
        lf_parallel_for(jb.n_order, r->threads, 1, render_tiles, &jb); /* the calling thread renders too */
    } else {
        rc = render_watched(r, &jb, total, err);
    }
    pthread_mutex_destroy(&jb.progress_lock);
    if (!rc && r->opts.part) {
        lf_image part;
        if (acc_image(&jb, NULL, &part, err))
            rc = err->code;
        else {
            lf_image_free(img);
            *img = part;
        }
    }
    free(jb.tile_done);
    free(jb.order);
    free(jb.acc);
    if (rc) {
        lf_image_free(img);
        return rc;
    }
    r->stats.seconds = lf_seconds() - t0;
    r->stats.rays = jb.rays;
    r->stats.camera_paths = jb.paths;
    r->stats.nonfinite_samples = jb.nonfinite;
    r->stats.zero_weight_camera_rays = jb.zero_weight;
    if (meta && render_attrs(r, meta, err))
        return err->code;
    return 0;
}
