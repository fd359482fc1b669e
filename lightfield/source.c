/* Opening light fields as the tools take them, and writing views
 * (lf_source.h). */
#include "lf_source.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/lf_file.h"
#include "base/lf_file_write.h"
#include "base/lf_keys.h"

void lf_lightfield_close(lf_lightfield_source *src)
{
    lf_lightfield_free(&src->lf);
    lf_image_free(&src->raw);
    lf_attrs_free(&src->attrs);
    lf_lightfield_folder_free(&src->folder);
    lf_warnings_free(&src->warnings);
}

/* Fails (and empties src) with the message of e, prefixed by the path. */
static int fail_named(lf_lightfield_source *src, const lf_error *e, lf_error *err)
{
    lf_lightfield_close(src);
    return lf_error_set(err, e->code ? e->code : LF_ERR_INTERNAL, "%s: %s", src->path, e->msg);
}

static int nonfinite_error(lf_lightfield_source *src, size_t count, lf_error *err)
{
    lf_lightfield_close(src);
    return lf_error_set(err, LF_ERR_NUMERIC,
                        "%s: %zu non-finite pixel values (NaN/Inf); pass --allow-nonfinite to treat them as missing "
                        "samples",
                        src->path, count);
}

static int reorder(lf_lightfield_source *src, int transpose, int flip_x, int flip_y, lf_error *err)
{
    int rc = lf_lightfield_grid_reorder(&src->lf, transpose, flip_x, flip_y, err);
    if (!rc && transpose) { /* the layout's grid turns with the views */
        lf_lightfield_layout *l[2] = {&src->lf.layout, &src->layout};
        for (int i = 0; i < 2; i++) {
            int c = l[i]->cams_x;
            l[i]->cams_x = l[i]->cams_y, l[i]->cams_y = c;
            double b0 = l[i]->grid_bounds[0], b1 = l[i]->grid_bounds[1];
            l[i]->grid_bounds[0] = l[i]->grid_bounds[2], l[i]->grid_bounds[1] = l[i]->grid_bounds[3];
            l[i]->grid_bounds[2] = b0, l[i]->grid_bounds[3] = b1;
        }
    }
    return rc;
}

/* The grid checked against its parallax (lf_lightfield_grid_parallax):
 * rows and columns swapped when both neighbour pairs say so, one axis
 * mirrored when the pairs' disparities disagree in sign and the stated range
 * (else the one-signed disparities of parallel cameras) says which; refused
 * with the flag that fixes it when one pair alone disagrees. */
static int check_grid(const lf_lightfield_open_opts *o, lf_lightfield_source *src, lf_error *err)
{
    const char *g = o->grid ? o->grid : "check";
    if (!strcmp(g, "off"))
        return LF_OK;
    if (strcmp(g, "check"))
        return reorder(src, !strcmp(g, "transpose"), !strcmp(g, "flip-x"), !strcmp(g, "flip-y"), err);
    lf_lightfield_parallax *p = &src->parallax;
    int rc = lf_lightfield_grid_parallax(&src->lf, p, err);
    if (rc)
        return rc;
    src->parallax_measured = 1;
    if (p->row.axis == 1 && p->col.axis == 0) {
        if ((rc = reorder(src, 1, 0, 0, err)) || (rc = lf_lightfield_grid_parallax(&src->lf, p, err)))
            return rc;
        lf_warn_at(&src->warnings, NULL,
                   "%s: rows and columns swapped (the parallax between row neighbours runs along y, between column "
                   "neighbours along x): views transposed (--grid-order off reads them as named)",
                   src->path);
    } else if (p->row.axis == 1 || p->col.axis == 0) {
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: the parallax between %s neighbours runs along %s, but the other pair's does not: give "
                            "--grid-order transpose if rows and columns are swapped, --grid-order off to read the views as named",
                            src->path, p->row.axis == 1 ? "row" : "column", p->row.axis == 1 ? "y" : "x");
    }
    if (p->row.axis != 0 || p->col.axis != 1 || p->both < 8 || p->same_sign > 0.2 * p->both)
        return LF_OK;
    /* one axis runs backwards: flip the one whose sign disagrees with the
     * stated range, else with the other's one-signed disparities */
    const lf_lightfield_layout *l = &src->lf.layout;
    int want = (l->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) && l->disp_min >= 0   ? 1
               : (l->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) && l->disp_max <= 0 ? -1
               : p->row.positive >= 0.8 || p->col.positive >= 0.8            ? 1
               : p->row.positive <= 0.2 || p->col.positive <= 0.2            ? -1
                                                                              : 0;
    int row_ok = want > 0 ? p->row.positive >= 0.5 : p->row.positive < 0.5;
    int col_ok = want > 0 ? p->col.positive >= 0.5 : p->col.positive < 0.5;
    if (!want || row_ok == col_ok)
        return lf_error_set(err, LF_ERR_PARAM,
                            "%s: the parallax between row neighbours and between column neighbours have opposite signs: "
                            "one axis runs backwards; give --grid-order flip-x (a row's views run right to left) or --grid-order "
                            "flip-y (a column's run bottom to top), or --grid-order off to read the views as named",
                            src->path);
    if ((rc = reorder(src, 0, !row_ok, !col_ok, err)) || (rc = lf_lightfield_grid_parallax(&src->lf, p, err)))
        return rc;
    lf_warn_at(&src->warnings, NULL,
               "%s: %s (its parallax has the sign opposite to the %s): views mirrored (--grid-order off reads them as named)",
               src->path, !row_ok ? "a row's views run right to left" : "a column's views run bottom to top",
               (l->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) ? "folder's disp_min/disp_max" : "other axis's");
    return LF_OK;
}

static int open_folder(const lf_lightfield_open_opts *o, const lf_lightfield_layout *flags, lf_lightfield_source *src, lf_error *err)
{
    if (o->white)
        return lf_error_set(err, LF_ERR_PARAM, "%s: --white applies to raws, not to a folder of views", src->path);
    if (lf_lightfield_folder_scan(src->path, &src->folder, err) || lf_lightfield_folder_load_threads(&src->folder, flags, o->threads, &src->lf, err)) {
        lf_lightfield_close(src);
        return err ? err->code : LF_ERR_IO;
    }
    src->layout = src->lf.layout;
    if (src->lf.nonfinite && !o->allow_nonfinite)
        return nonfinite_error(src, src->lf.nonfinite, err);
    lf_error e = {0};
    if (check_grid(o, src, &e))
        return fail_named(src, &e, err);
    if (!o->no_equalize && lf_lightfield_equalize_threads(&src->lf, o->threads, &e))
        return fail_named(src, &e, err);
    return LF_OK;
}

/* A raw or white image as the tools take it: a mosaic (DNG, or one channel
 * with lensfield:cfa) says so in *mosaic with its raw info. */
static int read_any(const char *path, lf_image *img, lf_attrs *attrs, lf_raw_info *ri, int *mosaic, lf_error *err)
{
    *mosaic = 0;
    if (lf_path_has_ext(path, ".dng")) {
        *mosaic = 1;
        return lf_raw_read(path, img, ri, NULL, err);
    }
    lf_attrs a = {0};
    int rc = lf_image_read(path, img, &a, err);
    if (!rc && img->channels == 1 && lf_raw_info_from_attrs(&a, ri, NULL) == 0)
        *mosaic = 1;
    if (attrs && !rc)
        *attrs = a;
    else
        lf_attrs_free(&a);
    return rc;
}

/* The layout: the raw's attributes and the flags; when they leave it
 * incomplete and a white image is given, the microlens grid calibrated from
 * the white image (a mosaic through its grey version). */
static int resolve_layout(const lf_lightfield_open_opts *o, const lf_lightfield_layout *flags, const lf_image *white,
                          const lf_raw_info *wri, int white_mosaic, lf_lightfield_source *src, lf_error *e)
{
    lf_lightfield_layout file;
    if (lf_lightfield_layout_from_attrs(&src->attrs, &file, e))
        return e->code;
    lf_error first = {0};
    if (!lf_lightfield_layout_resolve(&file, flags, src->raw.width, src->raw.height, &src->layout, &first))
        return LF_OK;
    if (!o->white || !white->data || (file.have & LF_LIGHTFIELD_HAVE_PITCH)) {
        *e = first;
        return first.code;
    }
    lf_image grey = {0};
    int rc = white_mosaic ? lf_lightfield_mosaic_grey(white, wri, &grey, e) : 0;
    lf_lightfield_layout cal;
    lf_lightfield_layout_init(&cal);
    if (!rc)
        rc = lf_lightfield_calibrate_white(white_mosaic ? &grey : white, &cal, e);
    lf_image_free(&grey);
    if (!rc)
        rc = lf_lightfield_layout_resolve(&cal, flags, src->raw.width, src->raw.height, &src->layout, e);
    return rc;
}

int lf_lightfield_open(const char *path, const lf_lightfield_open_opts *o, lf_lightfield_source *src, lf_error *err)
{
    memset(src, 0, sizeof *src);
    src->path = path;
    lf_lightfield_layout none;
    lf_lightfield_layout_init(&none);
    const lf_lightfield_layout *flags = o->flags ? o->flags : &none;
    if (lf_lightfield_is_folder(path))
        return open_folder(o, flags, src, err);
    /* The layout alone needs no pixels where the header gives the size (a
     * PNG: no attributes, no non-finite values); otherwise read it all. */
    lf_error he = {0};
    int hrc = o->layout_only && !o->white ? lf_image_read_size(path, &src->raw.width, &src->raw.height,
                                                               &src->raw.channels, &he)
                                          : LF_ERR_UNSUPPORTED;
    if (hrc && hrc != LF_ERR_UNSUPPORTED) {
        if (err)
            *err = he;
        return hrc;
    }
    lf_raw_info ri, wri;
    int mosaic = 0, white_mosaic = 0;
    if (hrc && read_any(path, &src->raw, &src->attrs, &ri, &mosaic, err))
        return err ? err->code : LF_ERR_IO;
    lf_image white = {0};
    if (o->white && read_any(o->white, &white, NULL, &wri, &white_mosaic, err)) {
        lf_lightfield_close(src);
        return err ? err->code : LF_ERR_IO;
    }
    lf_error e = {0};
    if (resolve_layout(o, flags, &white, &wri, white_mosaic, src, &e)) {
        lf_image_free(&white);
        return fail_named(src, &e, err);
    }
    src->raw_nonfinite = lf_image_count_nonfinite(&src->raw);
    int rc = LF_OK;
    if (o->layout_only)
        goto done;
    if (src->raw_nonfinite && !o->allow_nonfinite) {
        lf_image_free(&white);
        return nonfinite_error(src, src->raw_nonfinite, err);
    }
    /* mosaics: developed within microlens cells (white and raw alike), then
     * decoded and devignetted as any RGB raw */
    lf_image dev;
    if (mosaic && !(rc = lf_lightfield_develop_mosaic(&src->raw, &ri, &src->layout, &dev, &e))) {
        lf_image_free(&src->raw);
        src->raw = dev;
    }
    if (!rc && white_mosaic && !(rc = lf_lightfield_develop_mosaic(&white, &wri, &src->layout, &dev, &e))) {
        lf_image_free(&white);
        white = dev;
    }
    if (!rc)
        rc = lf_lightfield_decode(&src->raw, &src->layout, o->white ? &white : NULL, &src->lf, &e);
done:
    lf_image_free(&white);
    return rc ? fail_named(src, &e, err) : LF_OK;
}

static size_t describe_pair(const char *name, const char *expect, const lf_lightfield_pair_parallax *q, char *buf, size_t n)
{
    if (q->axis < 0)
        return (size_t)snprintf(buf, n, "%s neighbours: cannot tell (%d of %d blocks textured, %d voted)", name,
                                q->textured, q->blocks, q->votes_x + q->votes_y);
    return (size_t)snprintf(buf, n, "%s neighbours along %s%s (%+.3g px/view, %d of %d votes)", name,
                            q->axis ? "y" : "x", strcmp(expect, q->axis ? "y" : "x") ? " (!)" : "", q->disparity,
                            q->axis ? q->votes_y : q->votes_x, q->votes_x + q->votes_y);
}

/* "parallax: row neighbours along x (+1.02 px/view, ...), column neighbours along y (...)" */
static size_t describe_parallax(const lf_lightfield_parallax *p, char *buf, size_t n)
{
    size_t k = (size_t)snprintf(buf, n, "parallax: ");
    if (k < n)
        k += describe_pair("row", "x", &p->row, buf + k, n - k);
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, ", ");
    if (k < n)
        k += describe_pair("column", "y", &p->col, buf + k, n - k);
    if (k < n && p->both)
        k += (size_t)snprintf(buf + k, n - k, ", one sign on %d of %d blocks", p->same_sign, p->both);
    if (k < n)
        k += (size_t)snprintf(buf + k, n - k, "\n");
    return k < n ? k : n - 1;
}

void lf_lightfield_source_describe(const lf_lightfield_source *src, char *buf, size_t n)
{
    char lay[2048];
    lf_lightfield_layout_describe(&src->layout, lay, sizeof lay);
    const lf_lightfield *lf = &src->lf;
    const lf_lightfield_folder *f = &src->folder;
    size_t k;
    if (f->dir) {
        k = (size_t)snprintf(buf, n, "%s: folder of %d x %d views (%s layout, %s)\n%s", src->path, lf->nu, lf->nv,
                             f->kind == LF_LIGHTFIELD_FOLDER_HCI ? "HCI" : "row/column", f->pattern, lay);
        if (k < n && lf->disp_per_inv_m > 0)
            k += (size_t)snprintf(buf + k, n - k, "disparity %.6g + %.6g / depth px per view step\n", lf->disp_at_inf,
                                  lf->disp_per_inv_m);
        if (k < n && src->parallax_measured)
            k += describe_parallax(&src->parallax, buf + k, n - k);
        if (k < n && f->gt_disparity)
            k += (size_t)snprintf(buf + k, n - k, "ground-truth disparity: %s\n", f->gt_disparity);
        if (k < n && lf->views_rescaled)
            k += (size_t)snprintf(buf + k, n - k,
                                  "vignetting: %d views rescaled to the centre view's brightness (gains %.2f .. %.2f)\n",
                                  lf->views_rescaled, lf->gain_lo, lf->gain_hi);
        if (k < n && lf->views_dark)
            k += (size_t)snprintf(buf + k, n - k, "dark views left out: %d\n", lf->views_dark);
        if (k < n && lf->missing > lf->nonfinite)
            k += (size_t)snprintf(buf + k, n - k, "missing samples: %zu\n", lf->missing);
        if (k < n && lf->nonfinite)
            snprintf(buf + k, n - k, "non-finite pixel values: %zu\n", lf->nonfinite);
        return;
    }
    k = (size_t)snprintf(buf, n, "%s: %d x %d raw, %d channels\n%s", src->path, src->raw.width, src->raw.height,
                         src->raw.channels, lay);
    if (k < n && src->raw_nonfinite)
        snprintf(buf + k, n - k, "non-finite pixel values: %zu\n", src->raw_nonfinite);
}

int lf_lightfield_source_gt_disparity(const lf_lightfield_source *src, lf_image *gt, int *no_centre, lf_error *err)
{
    memset(gt, 0, sizeof *gt);
    *no_centre = 0;
    if (src->folder.dir)
        return src->folder.gt_disparity ? lf_image_read(src->folder.gt_disparity, gt, NULL, err) : LF_OK;
    const lf_attr *a = lf_attrs_get(&src->attrs, LF_KEY_DISPARITY_FILE);
    if (!a || a->type != LF_ATTR_STRING || !a->s[0])
        return LF_OK;
    const lf_lightfield *lf = &src->lf;
    if (lf->nu % 2 == 0 || lf->nv % 2 == 0) {
        *no_centre = 1;
        return LF_OK;
    }
    char path[PATH_MAX];
    const char *slash = strrchr(src->path, '/');
    if (a->s[0] == '/' || !slash)
        snprintf(path, sizeof path, "%s", a->s);
    else
        snprintf(path, sizeof path, "%.*s/%s", (int)(slash - src->path), src->path, a->s);
    lf_image raw = {0};
    lf_lightfield d = {0};
    lf_error e = {0};
    int rc = lf_image_read(path, &raw, NULL, &e);
    if (!rc && (raw.width != src->raw.width || raw.height != src->raw.height))
        rc = lf_error_set(&e, LF_ERR_PARAM, "%s is %d x %d, the raw %d x %d", path, raw.width, raw.height,
                          src->raw.width, src->raw.height);
    if (!rc)
        rc = lf_lightfield_decode(&raw, &src->layout, NULL, &d, &e) || lf_image_alloc(gt, d.ns, d.nt, 1, &e);
    if (!rc) {
        const float *v = lf_lightfield_view(&d, d.nu / 2, d.nv / 2);
        for (size_t i = 0; i < (size_t)d.ns * d.nt; i++)
            gt->data[i] = v[i * 3];
    }
    lf_image_free(&raw);
    lf_lightfield_free(&d);
    if (rc) {
        lf_image_free(gt);
        return lf_error_set(err, e.code ? e.code : LF_ERR_INTERNAL, "%s: disparity: %s", src->path, e.msg);
    }
    return LF_OK;
}

const char *lf_lightfield_source_disparity_range(const lf_lightfield_source *src, double *d0, double *d1)
{
    const lf_lightfield_layout *lay = &src->lf.layout;
    *d0 = *d1 = 0;
    if ((lay->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) && lay->disp_min < lay->disp_max) { /* a folder's parameters.cfg */
        *d0 = lay->disp_min, *d1 = lay->disp_max; /* a raw's: lfrender --aov disparity's ground-truth range */
        return src->folder.dir ? "the folder's disp_min/disp_max" : LF_KEY_DISPARITY_RANGE;
    }
    const lf_attr *a = lf_attrs_get(&src->attrs, LF_KEY_DISP_MIN), *b = lf_attrs_get(&src->attrs, LF_KEY_DISP_MAX);
    if (a && b) {
        double x = a->type == LF_ATTR_INT ? a->i : a->d, y = b->type == LF_ATTR_INT ? b->i : b->d;
        if (isfinite(x) && isfinite(y) && x < y) {
            *d0 = x, *d1 = y;
            return "lensfield:disp_min/max";
        }
    }
    return NULL;
}

int lf_lightfield_read_map(const char *path, const lf_lightfield *lf, lf_image *m, lf_error *err)
{
    lf_image img;
    memset(m, 0, sizeof *m);
    if (lf_image_read(path, &img, NULL, err))
        return err ? err->code : LF_ERR_IO;
    int rc = LF_OK;
    if (img.width != lf->ns || img.height != lf->nt)
        rc = lf_error_set(err, LF_ERR_PARAM, "%s: map is %dx%d, the views are %dx%d", path, img.width, img.height,
                          lf->ns, lf->nt);
    else if (!(rc = lf_image_alloc(m, img.width, img.height, 1, err))) {
        for (size_t i = 0; i < (size_t)img.width * img.height; i++)
            m->data[i] = img.data[i * img.channels];
        if (lf_image_count_nonfinite(m)) {
            lf_image_free(m);
            rc = lf_error_set(err, LF_ERR_NUMERIC, "%s: non-finite values in the map", path);
        }
    }
    lf_image_free(&img);
    return rc;
}

static int write_views_into(const lf_lightfield *lf, const char *dir, const char *ext, const lf_write_opts *wo,
                      lf_error *err)
{
    char path[PATH_MAX + 64];
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++) {
            lf_image v = {lf->ns, lf->nt, 3, lf_lightfield_view(lf, iu, iv)};
            snprintf(path, sizeof path, "%s/view_%02d_%02d.%s", dir, iv, iu, ext); /* row, column */
            if (lf_image_write(path, &v, NULL, wo, err))
                return err ? err->code : LF_ERR_IO;
        }
    /* mosaic: views tiled as the cameras sit (view (0,0) top-left) */
    lf_image m;
    if (lf_image_alloc(&m, lf->ns * lf->nu, lf->nt * lf->nv, 3, err))
        return err ? err->code : LF_ERR_NOMEM;
    for (int iv = 0; iv < lf->nv; iv++)
        for (int iu = 0; iu < lf->nu; iu++)
            for (int t = 0; t < lf->nt; t++)
                memcpy(lf_image_px(&m, iu * lf->ns, iv * lf->nt + t), lf_lightfield_view(lf, iu, iv) + (size_t)t * lf->ns * 3,
                       sizeof(float) * 3 * lf->ns);
    snprintf(path, sizeof path, "%s/mosaic.%s", dir, ext);
    int rc = lf_image_write(path, &m, NULL, wo, err);
    lf_image_free(&m);
    return rc;
}

/* Written into a staging folder beside dir and moved into place
 * (base/lf_file_write.h), so a failure leaves no half-written folder. */
int lf_lightfield_write_views(const lf_lightfield *lf, const char *dir, const char *ext, const lf_write_opts *wo,
                              lf_error *err)
{
    char stage[PATH_MAX];
    int rc = lf_dir_stage_begin(dir, stage, sizeof stage, err);
    if (rc)
        return rc;
    rc = write_views_into(lf, stage, ext, wo, err);
    if (rc) {
        lf_dir_stage_abort(stage);
        return rc;
    }
    return lf_dir_stage_commit(stage, dir, err);
}

int lf_lightfield_write_refocused(const char *path, const lf_image *img, double disparity_px, const lf_write_opts *wo,
                          lf_error *err)
{
    lf_attrs a = {0};
    int rc = lf_attrs_set_double(&a, LF_KEY_REFOCUS_DISPARITY_PX, disparity_px, NULL)
                 ? lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", path)
                 : lf_image_write(path, img, &a, wo, err);
    lf_attrs_free(&a);
    return rc;
}

int lf_lightfield_write_disparity(const char *path, const lf_image *disp, double d0, double d1, const lf_write_opts *wo,
                          lf_error *err)
{
    int rc;
    if (lf_path_has_ext(path, ".png") || lf_path_has_ext(path, ".jpg") || lf_path_has_ext(path, ".jpeg")) {
        lf_image pic;
        if ((rc = lf_image_colormap(disp, d0, d1, &pic, err)))
            return rc;
        rc = lf_image_write(path, &pic, NULL, wo, err);
        lf_image_free(&pic);
        return rc;
    }
    lf_attrs a = {0};
    float range[2] = {(float)d0, (float)d1};
    if (lf_attrs_set_floats(&a, LF_KEY_DISPARITY_SEARCH_RANGE, range, 2, NULL) ||
        lf_attrs_set_string(&a, LF_KEY_DISPARITY_CONVENTION,
                            "I_centre(x, y) = I_(iu,iv)(x - d (iu - iu_c), y - d (iv - iv_c)), px per view step",
                            NULL))
        rc = lf_error_set(err, LF_ERR_NOMEM, "cannot write '%s': out of memory", path);
    else
        rc = lf_image_write(path, disp, &a, wo, err);
    lf_attrs_free(&a);
    return rc;
}

int lf_lightfield_refocus_outside(const lf_lightfield *lf, double d, char *buf, size_t n)
{
    if (lf->disp_per_alpha == 0 || !(fabs(d) > 1.0 + 1e-9))
        return 0;
    /* |d| <= 1 with d = (1 - 1/alpha) / b and depth z from d = d_inf + k / z */
    double k = lf->disp_per_inv_m, d_inf = lf->disp_at_inf, b = 1.0 / lf->disp_per_alpha;
    char far[32], amax[32];
    if (k > 0 && -1.0 - d_inf > 0)
        snprintf(far, sizeof far, "%.4g m", k / (-1.0 - d_inf));
    else
        snprintf(far, sizeof far, "infinity");
    if (b < 1.0)
        snprintf(amax, sizeof amax, "%.5g", 1.0 / (1.0 - b));
    else
        snprintf(amax, sizeof amax, "infinity");
    snprintf(buf, n, "Ng 2005: |disparity| <= 1 px/view, alpha %.5g .. %s, depths %.4g m .. %s", 1.0 / (1.0 + b),
             amax, k > 0 && 1.0 - d_inf > 0 ? k / (1.0 - d_inf) : INFINITY, far);
    return 1;
}

int lf_lightfield_synth_prepare(const lf_lightfield *lf, unsigned set, lf_lightfield_synth_opts *s, lf_error *err)
{
    const lf_lightfield_layout *y = &lf->layout;
    if (y->kind != LF_LIGHTFIELD_CAMERA_ARRAY)
        return lf_error_set(err, LF_ERR_PARAM, "synth needs a camera-array light field (lensfield:kind camera-array)");
    char missing[256] = "";
    if (!(y->have & LF_LIGHTFIELD_HAVE_BOUNDS))
        strcat(missing, " lensfield:camera_grid_bounds (--griddim minx maxx miny maxy)");
    if (!(y->have & LF_LIGHTFIELD_HAVE_FOV))
        strcat(missing, " lensfield:fov_deg (--inputfov DEG)");
    if (missing[0])
        return lf_error_set(err, LF_ERR_PARAM, "synth needs:%s", missing);
    if (!(set & LF_LIGHTFIELD_SYNTH_SET_FOV))
        s->fov_deg = y->fov_deg;
    if (!(set & LF_LIGHTFIELD_SYNTH_SET_SIZE))
        s->width = lf->ns, s->height = lf->nt;
    if (!(set & LF_LIGHTFIELD_SYNTH_SET_POS)) {
        s->pos[0] = 0.5 * (y->grid_bounds[0] + y->grid_bounds[1]);
        s->pos[1] = 0.5 * (y->grid_bounds[2] + y->grid_bounds[3]);
        s->pos[2] = 0;
    }
    if (!(set & LF_LIGHTFIELD_SYNTH_SET_FOCAL) && (y->have & LF_LIGHTFIELD_HAVE_CAM_LENS) && y->focal_distance > 0)
        s->focal_distance = y->focal_distance;
    return LF_OK;
}
