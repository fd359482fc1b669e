/* lensfield_capi.c - the C side of the Python module (python/lensfield/):
 * liblensfield.so, a flat C API over lightfield/, render/ and image/ that
 * ctypes calls (docs/python.md says why ctypes and not a CPython extension).
 *
 * Each call does what one lftool or lfrender command does between reading
 * its flags and writing its file, with the same library calls in the same
 * order, so Python's arrays equal the tools' files bit for bit.  Nothing here
 * prints; errors come back in an lf_error (scene errors: every line).
 * Images the library allocates are handed over as heap lf_image structs that
 * Python wraps without copying and releases with lfpy_image_release.
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_error.h"
#include "base/lf_keys.h"
#include "image/lf_image.h"
#include "lightfield/lf_depth.h"
#include "lightfield/lf_lightfield.h"
#include "lightfield/lf_source.h"
#include "render/lf_render.h"
#include "scenefile/lf_scene_desc.h"

#define LFPY_API __attribute__((visibility("default")))

/* ---------- layout keywords: lftool's layout flags (apply_flags) ---------- */

enum {
    LFPY_KIND = 1 << 0, LFPY_CAMS = 1 << 1, LFPY_GRIDDIM = 1 << 2, LFPY_FOV = 1 << 3, LFPY_TILE = 1 << 4,
    LFPY_GRID = 1 << 5, LFPY_PITCH = 1 << 6, LFPY_ROTATION = 1 << 7, LFPY_OFFSET = 1 << 8,
    LFPY_LENSES = 1 << 9, LFPY_MAINLENS = 1 << 10
};

typedef struct lfpy_layout {
    unsigned given;  /* LFPY_* bits: which keywords were passed */
    int plenoptic;   /* kind */
    int hex;         /* grid */
    int cams[2], tile[2], lenses[2];
    double griddim[4], fov, pitch, rotation, offset[2], mainlens[4];
} lfpy_layout;

/* lftool's apply_flags(), keyword for flag. */
static void layout_from_keywords(const lfpy_layout *k, lf_lightfield_layout *f)
{
    lf_lightfield_layout_init(f);
    const struct {
        unsigned bit, have;
    } map[] = {{LFPY_KIND, LF_LIGHTFIELD_HAVE_KIND},      {LFPY_CAMS, LF_LIGHTFIELD_HAVE_CAMS | LF_LIGHTFIELD_HAVE_KIND},
               {LFPY_GRIDDIM, LF_LIGHTFIELD_HAVE_BOUNDS}, {LFPY_FOV, LF_LIGHTFIELD_HAVE_FOV},
               {LFPY_TILE, LF_LIGHTFIELD_HAVE_TILE},      {LFPY_GRID, LF_LIGHTFIELD_HAVE_GRID},
               {LFPY_PITCH, LF_LIGHTFIELD_HAVE_PITCH},    {LFPY_ROTATION, LF_LIGHTFIELD_HAVE_ROTATION},
               {LFPY_OFFSET, LF_LIGHTFIELD_HAVE_OFFSET},  {LFPY_LENSES, LF_LIGHTFIELD_HAVE_LENS_COUNT},
               {LFPY_MAINLENS, LF_LIGHTFIELD_HAVE_MAIN_LENS}};
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (k->given & map[i].bit)
            f->have |= map[i].have;
    f->kind = (k->given & LFPY_CAMS) || ((k->given & LFPY_KIND) && !k->plenoptic) ? LF_LIGHTFIELD_CAMERA_ARRAY
                                                                                    : LF_LIGHTFIELD_PLENOPTIC;
    f->grid = (k->given & LFPY_GRID) && k->hex ? LF_LIGHTFIELD_GRID_HEX : LF_LIGHTFIELD_GRID_SQUARE;
    f->cams_x = k->cams[0], f->cams_y = k->cams[1];
    memcpy(f->grid_bounds, k->griddim, sizeof f->grid_bounds);
    f->fov_deg = k->fov, f->pitch_px = k->pitch, f->rotation_rad = k->rotation;
    f->tile_w = k->tile[0], f->tile_h = k->tile[1];
    f->offset_px[0] = k->offset[0], f->offset_px[1] = k->offset[1];
    f->lens_x = k->lenses[0], f->lens_y = k->lenses[1];
    f->main_focal_mm = k->mainlens[0], f->main_fstop = k->mainlens[1];
    f->mla_distance_mm = k->mainlens[2], f->pitch_um = k->mainlens[3];
}

/* ---------- light fields ---------- */

typedef struct lfpy_lightfield {
    lf_lightfield_source src; /* opened: the source; wrapped: src.lf borrows the caller's data */
    int borrowed;
    char *path;
    /* --calibrate-views replaces lf.view_shift for one call (the CLI starts
     * from a fresh light field each time): such a call holds the lock for
     * writing, every other call for reading, so Python threads may share a
     * light field */
    pthread_rwlock_t lock;
} lfpy_lightfield;

typedef struct lfpy_info {
    int nu, nv, ns, nt;
    float *data;
    double disp_v_per_u, disp_per_inv_m, disp_at_inf, disp_per_alpha;
    size_t missing, nonfinite;
    int is_folder, has_valid;
    float *valid;
} lfpy_info;

LFPY_API int lfpy_open(const char *path, const lfpy_layout *keywords, const char *white, int allow_nonfinite,
                       lfpy_lightfield **out, lf_error *err)
{
    *out = NULL;
    lfpy_lightfield *h = calloc(1, sizeof *h);
    char *p = strdup(path);
    if (!h || !p) {
        free(h), free(p);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    lf_lightfield_layout flags;
    layout_from_keywords(keywords, &flags);
    lf_lightfield_open_opts oo = {&flags, white, allow_nonfinite, 0, 0};
    int rc = lf_lightfield_open(p, &oo, &h->src, err);
    if (rc) {
        free(h), free(p);
        return rc;
    }
    h->path = p;
    pthread_rwlock_init(&h->lock, NULL);
    *out = h;
    return LF_OK;
}

/* A light field over the caller's views (nv rows of nu views of ns x nt RGB
 * floats, the layout of lf_lightfield.data); nothing is copied. */
LFPY_API int lfpy_wrap(float *data, int nu, int nv, int ns, int nt, double disp_v_per_u, lfpy_lightfield **out,
                       lf_error *err)
{
    *out = NULL;
    if (nu < 1 || nv < 1 || ns < 1 || nt < 1)
        return lf_error_set(err, LF_ERR_PARAM, "a light field needs at least 1 view of 1 x 1 pixels");
    lfpy_lightfield *h = calloc(1, sizeof *h);
    if (!h)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    lf_lightfield *lf = &h->src.lf;
    lf->nu = nu, lf->nv = nv, lf->ns = ns, lf->nt = nt;
    lf->data = data;
    lf->disp_v_per_u = disp_v_per_u > 0 ? disp_v_per_u : 1.0;
    lf_lightfield_layout_init(&lf->layout);
    h->borrowed = 1;
    pthread_rwlock_init(&h->lock, NULL);
    *out = h;
    return LF_OK;
}

LFPY_API void lfpy_close(lfpy_lightfield *h)
{
    if (!h)
        return;
    if (h->borrowed) {
        h->src.lf.data = NULL; /* the caller's */
        free(h->src.lf.view_shift);
        free(h->src.lf.half);
    } else {
        lf_lightfield_close(&h->src);
    }
    pthread_rwlock_destroy(&h->lock);
    free(h->path);
    free(h);
}

LFPY_API void lfpy_info_get(const lfpy_lightfield *h, lfpy_info *i)
{
    const lf_lightfield *lf = &h->src.lf;
    memset(i, 0, sizeof *i);
    i->nu = lf->nu, i->nv = lf->nv, i->ns = lf->ns, i->nt = lf->nt;
    i->data = lf->data;
    i->disp_v_per_u = lf->disp_v_per_u, i->disp_per_inv_m = lf->disp_per_inv_m;
    i->disp_at_inf = lf->disp_at_inf, i->disp_per_alpha = lf->disp_per_alpha;
    i->missing = lf->missing, i->nonfinite = lf->nonfinite;
    i->is_folder = h->src.folder.dir != NULL;
    i->valid = lf->valid, i->has_valid = lf->valid != NULL;
}

/* What `lftool info` prints. */
LFPY_API void lfpy_describe(const lfpy_lightfield *h, char *buf, size_t n)
{
    if (h->borrowed) {
        lf_lightfield_layout_describe(&h->src.lf.layout, buf, n);
        return;
    }
    lf_lightfield_source_describe(&h->src, buf, n);
}

/* ---------- images and attributes handed to Python ---------- */

LFPY_API lf_image *lfpy_image_new(void)
{
    return calloc(1, sizeof(lf_image));
}

LFPY_API void lfpy_image_release(lf_image *img)
{
    if (img)
        lf_image_free(img);
    free(img);
}

LFPY_API lf_attrs *lfpy_attrs_new(void)
{
    return calloc(1, sizeof(lf_attrs));
}

LFPY_API void lfpy_attrs_release(lf_attrs *a)
{
    if (a)
        lf_attrs_free(a);
    free(a);
}

LFPY_API size_t lfpy_attrs_count(const lf_attrs *a)
{
    return a->count;
}

LFPY_API const lf_attr *lfpy_attrs_item(const lf_attrs *a, size_t i)
{
    return i < a->count ? &a->items[i] : NULL;
}

/* One setter for every type (lf_attr_type); returns 0 or LF_ERR_NOMEM. */
LFPY_API int lfpy_attrs_set(lf_attrs *a, const char *name, int type, const char *s, int i, double d, const float *v,
                            int n, const double *m)
{
    switch (type) {
    case LF_ATTR_STRING:
        return lf_attrs_set_string(a, name, s, NULL);
    case LF_ATTR_INT:
        return lf_attrs_set_int(a, name, i, NULL);
    case LF_ATTR_FLOAT:
        return lf_attrs_set_float(a, name, (float)d, NULL);
    case LF_ATTR_DOUBLE:
        return lf_attrs_set_double(a, name, d, NULL);
    case LF_ATTR_FLOATS:
        return lf_attrs_set_floats(a, name, v, n, NULL);
    case LF_ATTR_M44D:
        return lf_attrs_set_m44d(a, name, m, NULL);
    }
    return LF_ERR_PARAM;
}

LFPY_API void lfpy_free(void *p)
{
    free(p);
}

LFPY_API const char *lfpy_version(void)
{
    return LF_VERSION;
}

/* ---------- depth: lftool depth (cmd_depth, allfocus_depth) ---------- */

typedef struct lfpy_depth_args {
    int have_range;  /* --from/--to */
    double from, to;
    int have_steps, steps;
    int have_aperture;
    double aperture;
    int have_views, views[4];
    int threads;
    int calibrate_views;
    int stack;       /* --method stack */
    int confidence;  /* also the confidence map */
    int noisy;       /* --noisy: noise_aware */
    int plain;       /* --plain-regions */
    int have_prefilter;
    double prefilter; /* --prefilter SIGMA (0: never) */
} lfpy_depth_args;

static lf_lightfield_refocus_opts aperture_opts(int have_aperture, double aperture, int have_views, const int views[4],
                                                int threads)
{
    lf_lightfield_refocus_opts r = lf_lightfield_refocus_defaults();
    if (have_aperture)
        r.aperture_radius = aperture;
    if (have_views)
        r.u0 = views[0], r.u1 = views[1], r.v0 = views[2], r.v1 = views[3];
    r.threads = threads;
    return r;
}

/* range_out: the disparity range searched; range_source: where it came from
 * ("--from/--to", the source's statement, "estimated"), as lftool prints. */
static int depth(lfpy_lightfield *h, const lfpy_depth_args *a, lf_image *disp, lf_image *conf, double range_out[2],
                 const char **range_source, lf_error *err)
{
    lf_lightfield *lf = &h->src.lf;
    *range_source = "--from/--to";
    if (a->stack) { /* focal-stack contrast, as allfocus_depth */
        double d0 = a->have_range ? a->from : -1, d1 = a->have_range ? a->to : 1;
        int steps = a->have_steps ? a->steps : 9;
        lf_lightfield_refocus_opts ro = aperture_opts(a->have_aperture, a->aperture, a->have_views, a->views, a->threads);
        lf_image af = {0};
        int rc = lf_lightfield_allfocus(lf, &ro, d0, d1, steps, &af, disp, err);
        lf_image_free(&af);
        range_out[0] = d0, range_out[1] = d1;
        return rc;
    }
    lf_lightfield_depth_opts d = lf_lightfield_depth_defaults();
    d.threads = a->threads, d.noise_aware = a->noisy, d.plain = a->plain;
    if (a->have_prefilter) /* else auto, as lftool */
        d.prefilter = a->prefilter > 0 ? a->prefilter : -1;
    if (a->have_range)
        d.d0 = a->from, d.d1 = a->to;
    else if (h->borrowed || !(*range_source = lf_lightfield_source_disparity_range(&h->src, &d.d0, &d.d1)))
        *range_source = "estimated";
    if (d.d0 >= d.d1 && lf_lightfield_depth_range(lf, a->threads, &d.d0, &d.d1, err))
        return err->code;
    if (a->have_steps)
        d.step = (d.d1 - d.d0) / (a->steps - 1);
    range_out[0] = d.d0, range_out[1] = d.d1;
    if (!a->calibrate_views)
        return lf_lightfield_depth(lf, &d, disp, a->confidence ? conf : NULL, err);
    /* depth on the nominal grid, view positions fitted to it, depth again;
     * the fitted positions last for this call only, as in the CLI */
    double *saved = lf->view_shift;
    lf->view_shift = NULL;
    int rc = lf_lightfield_depth(lf, &d, disp, conf, err) ||
             lf_lightfield_calibrate_views(lf, disp, conf, a->threads, NULL, err);
    lf_image_free(disp), lf_image_free(conf);
    if (!rc)
        rc = lf_lightfield_depth(lf, &d, disp, a->confidence ? conf : NULL, err);
    free(lf->view_shift);
    lf->view_shift = saved;
    return rc ? (err->code ? err->code : LF_ERR_INTERNAL) : LF_OK;
}

/* ---------- focus: one of alpha, depth, disparity (focus_disparity) ---------- */

typedef struct lfpy_focus {
    int have_alpha, have_depth, have_disp;
    double alpha, depth, disp;
} lfpy_focus;

static int focus_disparity(const lf_lightfield *lf, const lfpy_focus *f, double *d, lf_error *err)
{
    if (f->have_alpha + f->have_depth + f->have_disp > 1)
        return lf_error_set(err, LF_ERR_PARAM, "give one of alpha, depth, disparity");
    *d = f->have_disp ? f->disp : 0;
    if (f->have_alpha)
        return lf_lightfield_alpha_to_disparity(lf, f->alpha, d, err);
    if (f->have_depth)
        return lf_lightfield_depth_to_disparity(lf, f->depth, d, err);
    return LF_OK;
}

/* ---------- refocus: lftool refocus (cmd_refocus) ---------- */

typedef struct lfpy_refocus_args {
    lfpy_focus focus;
    int have_aperture;
    double aperture;
    int have_views, views[4];
    int threads;
    int fourier;
    double oversample;
} lfpy_refocus_args;

/* warning (n bytes) gets lftool's outside-the-refocusable-range text, or "". */
static int refocus(lfpy_lightfield *h, const lfpy_refocus_args *a, lf_image *out, double *disparity, char *warning,
                   size_t n, lf_error *err)
{
    const lf_lightfield *lf = &h->src.lf;
    const lfpy_focus *f = &a->focus;
    warning[0] = 0;
    if (f->have_alpha + f->have_depth + f->have_disp != 1)
        return lf_error_set(err, LF_ERR_PARAM, "refocus needs exactly one of alpha, depth, disparity");
    lf_lightfield_refocus_opts ro = aperture_opts(a->have_aperture, a->aperture, a->have_views, a->views, a->threads);
    int rc = focus_disparity(lf, f, &ro.disparity_px, err);
    if (rc)
        return rc;
    *disparity = ro.disparity_px;
    char range[256], asked[96];
    if (lf_lightfield_refocus_outside(lf, ro.disparity_px, range, sizeof range)) {
        if (f->have_depth)
            snprintf(asked, sizeof asked, "depth %g m", f->depth);
        else if (f->have_alpha)
            snprintf(asked, sizeof asked, "alpha %g", f->alpha);
        else
            snprintf(asked, sizeof asked, "disparity %g px/view", ro.disparity_px);
        snprintf(warning, n,
                 "%s (disparity %.3g px/view) is outside the refocusable range (%s): the sub-aperture views are "
                 "blurred there, so the result is softer than a photograph focused at that depth",
                 asked, ro.disparity_px, range);
    }
    if (a->fourier) {
        lf_lightfield_fourier *fs = NULL;
        rc = lf_lightfield_fourier_new(lf, &ro, a->oversample, &fs, err) ||
             lf_lightfield_fourier_refocus(fs, ro.disparity_px, out, err);
        lf_lightfield_fourier_release(fs);
        return rc ? (err->code ? err->code : LF_ERR_INTERNAL) : LF_OK;
    }
    return lf_lightfield_refocus(lf, &ro, out, err);
}

/* ---------- view: lftool view (cmd_view) ---------- */

typedef struct lfpy_view_args {
    double u, v;
    lfpy_focus focus;
    int geometry;    /* -1: as lftool without --geometry; 0: depth; 1: plane */
    const lf_image *disparity_map, *confidence; /* NULL: none */
    int calibrate_views;
    int threads;
} lfpy_view_args;

static int check_map(const lf_image *m, const lf_lightfield *lf, const char *what, lf_error *err)
{
    if (m->width != lf->ns || m->height != lf->nt || m->channels != 1)
        return lf_error_set(err, LF_ERR_PARAM, "%s is %d x %d x %d; the views need %d x %d x 1", what, m->width,
                            m->height, m->channels, lf->ns, lf->nt);
    return LF_OK;
}

static int view(lfpy_lightfield *h, const lfpy_view_args *a, lf_image *out, lf_error *err)
{
    lf_lightfield *lf = &h->src.lf;
    const lfpy_focus *f = &a->focus;
    int plane = a->geometry >= 0 ? a->geometry == 1 : (f->have_alpha + f->have_depth + f->have_disp) > 0;
    if (plane && a->disparity_map)
        return lf_error_set(err, LF_ERR_PARAM, "disparity_map needs geometry=\"depth\"");
    if (a->confidence && !a->disparity_map)
        return lf_error_set(err, LF_ERR_PARAM, "confidence goes with disparity_map");
    double d = 0;
    int rc = focus_disparity(lf, f, &d, err);
    if (rc)
        return rc;
    if (a->disparity_map && (check_map(a->disparity_map, lf, "disparity_map", err) ||
                             (a->confidence && check_map(a->confidence, lf, "confidence", err))))
        return err->code;
    if (plane)
        return lf_lightfield_view_at(lf, a->u, a->v, d, out, err);
    lf_lightfield_view_opts vo = lf_lightfield_view_defaults();
    vo.threads = a->threads;
    vo.plane_disparity = d;
    vo.disparity = a->disparity_map;
    vo.confidence = a->disparity_map ? a->confidence : NULL;
    if (!a->calibrate_views)
        return lf_lightfield_view_depth(lf, a->u, a->v, &vo, out, err);
    /* calibrate_for_view, the fitted positions for this call only */
    double *saved = lf->view_shift;
    lf->view_shift = NULL;
    if (a->disparity_map) {
        rc = lf_lightfield_calibrate_views(lf, a->disparity_map, a->confidence, a->threads, NULL, err);
    } else {
        lf_image ed = {0}, ec = {0};
        lf_lightfield_depth_opts dopt = lf_lightfield_depth_defaults();
        dopt.threads = a->threads;
        rc = lf_lightfield_depth(lf, &dopt, &ed, &ec, err) ||
             lf_lightfield_calibrate_views(lf, &ed, &ec, a->threads, NULL, err);
        lf_image_free(&ed), lf_image_free(&ec);
    }
    if (!rc)
        rc = lf_lightfield_view_depth(lf, a->u, a->v, &vo, out, err);
    free(lf->view_shift);
    lf->view_shift = saved;
    return rc ? (err->code ? err->code : LF_ERR_INTERNAL) : LF_OK;
}

/* ---------- the light-field calls, under the light field's lock ---------- */

static void lock(lfpy_lightfield *h, int calibrate)
{
    if (calibrate)
        pthread_rwlock_wrlock(&h->lock);
    else
        pthread_rwlock_rdlock(&h->lock);
}

LFPY_API int lfpy_depth(lfpy_lightfield *h, const lfpy_depth_args *a, lf_image *disp, lf_image *conf,
                        double range_out[2], const char **range_source, lf_error *err)
{
    lock(h, a->calibrate_views && !a->stack);
    int rc = depth(h, a, disp, conf, range_out, range_source, err);
    pthread_rwlock_unlock(&h->lock);
    return rc;
}

LFPY_API int lfpy_refocus(lfpy_lightfield *h, const lfpy_refocus_args *a, lf_image *out, double *disparity,
                          char *warning, size_t n, lf_error *err)
{
    lock(h, 0);
    int rc = refocus(h, a, out, disparity, warning, n, err);
    pthread_rwlock_unlock(&h->lock);
    return rc;
}

LFPY_API int lfpy_view(lfpy_lightfield *h, const lfpy_view_args *a, lf_image *out, lf_error *err)
{
    lock(h, a->calibrate_views);
    int rc = view(h, a, out, err);
    pthread_rwlock_unlock(&h->lock);
    return rc;
}

/* ---------- render: lfrender SCENE (run_render) ---------- */

typedef struct lfpy_render_args {
    int spp, threads;
    int has_seed;
    unsigned seed;
    int have_crop, crop[4];
    int allow_unsupported;
    int white;
} lfpy_render_args;

/* warnings: the renderer's notes, errors: every parse error, one a line
 * (both malloc'ed or NULL; lfpy_free).  *half: Film "savefp16", as lfrender
 * writes the EXR.  stop: set non-zero to stop after the tiles in flight. */
LFPY_API int lfpy_render(const char *scene, const lfpy_render_args *a, volatile int *stop, lf_image *img,
                         lf_attrs *meta, int *half, char **warnings, char **errors, lf_error *err)
{
    *warnings = *errors = NULL;
    *half = 0;
    lf_render_opts o = lf_render_opts_default();
    o.spp = a->spp, o.threads = a->threads;
    o.seed = a->seed, o.has_seed = a->has_seed;
    o.white = a->white;
    if (a->have_crop) {
        if (a->crop[1] <= a->crop[0] || a->crop[3] <= a->crop[2])
            return lf_error_set(err, LF_ERR_PARAM, "crop (x0, x1, y0, y1) needs x0 < x1 and y0 < y1");
        memcpy(o.crop, a->crop, sizeof o.crop);
    }
    lf_scene_desc desc;
    lf_parse_opts popts = {a->allow_unsupported, 0};
    int rc = lf_scene_parse_file_ex(scene, &popts, &desc, err, errors);
    if (rc)
        return rc;
    o.scene_path = scene;
    lf_renderer *r;
    if ((rc = lf_renderer_create(&desc, &o, &r, err))) {
        lf_scene_desc_free(&desc);
        return rc;
    }
    if (lf_renderer_warnings(r))
        *warnings = strdup(lf_renderer_warnings(r));
    o.stop = stop;
    lf_renderer_set_opts(r, &o);
    rc = lf_renderer_render(r, img, meta, err);
    if (!rc && *stop) { /* stopped without a checkpoint: the image is partial */
        lf_image_free(img);
        rc = lf_error_set(err, LF_ERR_INTERRUPTED, "interrupted");
    }
    if (!rc)
        *half = lf_renderer_film_half(r) && lf_image_fits_half(img);
    lf_renderer_free(r);
    lf_scene_desc_free(&desc);
    return rc;
}

/* ---------- files ---------- */

/* lf_image_write with a tool's picture options (--exposure, --tonemap). */
LFPY_API int lfpy_write(const char *path, const lf_image *img, const lf_attrs *attrs, double exposure,
                        const char *tonemap, int half, lf_error *err)
{
    lf_write_opts wo = lf_write_opts_picture(exposure, tonemap);
    wo.half = half;
    return lf_image_write(path, img, attrs, &wo, err);
}

/* A disparity map as lftool depth writes it (lensfield:disparity_* attributes). */
LFPY_API int lfpy_write_disparity(const char *path, const lf_image *disp, double d0, double d1, lf_error *err)
{
    lf_write_opts wo = lf_write_opts_picture(0, NULL);
    return lf_lightfield_write_disparity(path, disp, d0, d1, &wo, err);
}

LFPY_API int lfpy_read(const char *path, lf_image *img, lf_attrs *attrs, lf_error *err)
{
    return lf_image_read(path, img, attrs, err);
}
