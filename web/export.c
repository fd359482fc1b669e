/* The web export of a light field (lf_web.h, docs/web.md): view atlases,
 * an 8-bit disparity map and a focal stack, embedded as data: URIs in
 * data.js beside the page's own index.html and lf.js. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/lf_buf.h"
#include "base/lf_file_write.h"
#include "image/lf_image.h"
#include "lf_web.h"

enum { SEARCH_STEPS = 25, DEPTH_STEPS = 33 };

lf_web_export_opts lf_web_export_defaults(void)
{
    lf_web_export_opts o = {0};
    o.format = "jpg";
    o.stack_slices = 9;
    return o;
}

static int is_file(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0 && S_ISREG(s.st_mode);
}

int lf_web_find_assets(char *dir, size_t n, lf_error *err)
{
    enum { LEN = PATH_MAX + 64 };
    char cand[4][LEN];
    int k = 0;
    const char *env = getenv("LF_WEB_DIR");
    if (env && *env)
        snprintf(cand[k++], LEN, "%.*s", PATH_MAX, env);
    /* this file's compile-time path: <source>/web/export.c */
    const char *src = __FILE__, *tail = strstr(src, "web/export.c");
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
        if (is_file(probe) && strlen(cand[i]) < n) {
            snprintf(dir, n, "%s", cand[i]);
            return LF_OK;
        }
    }
    return lf_error_set(err, LF_ERR_IO, "cannot find the page's files (web/index.html, web/lf.js); set LF_WEB_DIR");
}

int lf_web_base64(lf_strbuf *out, const unsigned char *in, size_t n)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < n; i += 3) {
        size_t got = n - i < 3 ? n - i : 3;
        unsigned v = (unsigned)in[i] << 16 | (got > 1 ? (unsigned)in[i + 1] << 8 : 0) | (got > 2 ? in[i + 2] : 0);
        char q[4] = {b64[v >> 18 & 63], b64[v >> 12 & 63], got > 1 ? b64[v >> 6 & 63] : '=',
                     got > 2 ? b64[v & 63] : '='};
        if (lf_strbuf_append(out, q, 4))
            return -1;
    }
    return 0;
}

/* Reads a whole (small) file into memory. */
static int slurp(const char *path, unsigned char **data, size_t *len, lf_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot read %s: %s", path, strerror(errno));
    lf_strbuf b = {0};
    char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0)
        lf_strbuf_append(&b, buf, got);
    int bad = ferror(f);
    fclose(f);
    if (bad || b.failed) {
        lf_strbuf_free(&b);
        return lf_error_set(err, bad ? LF_ERR_IO : LF_ERR_NOMEM, "cannot read %s", path);
    }
    *len = b.len;
    *data = (unsigned char *)lf_strbuf_take(&b);
    return *data ? LF_OK : lf_error_set(err, LF_ERR_NOMEM, "out of memory reading %s", path);
}

/* Encodes img as PNG or JPEG (through a hidden temporary file in dir) and
 * appends it to js as a quoted data: URI. */
static int put_image(lf_strbuf *js, const char *dir, const char *name, const char *ext, const lf_image *img,
                     lf_error *err)
{
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/.%s.%ld.%s", dir, name, (long)getpid(), ext);
    int rc = lf_image_write(path, img, NULL, NULL, err);
    unsigned char *data = NULL;
    size_t len = 0;
    if (!rc)
        rc = slurp(path, &data, &len, err);
    remove(path);
    if (rc)
        return rc;
    lf_strbuf_printf(js, "\"data:%s;base64,", strcmp(ext, "jpg") ? "image/png" : "image/jpeg");
    lf_web_base64(js, data, len);
    lf_strbuf_puts(js, "\"");
    free(data);
    return js->failed ? lf_error_set(err, LF_ERR_NOMEM, "out of memory encoding %s", name) : LF_OK;
}

void lf_web_focus_range(const float *dm, size_t total, double d0, double d1, int n, double *q0, double *q1)
{
    size_t count[256] = {0};
    if (n > 256)
        n = 256;
    double step = (d1 - d0) / (n - 1);
    for (size_t i = 0; i < total; i++) {
        double k = floor((dm[i] - d0) / step + 0.5);
        count[!(k > 0) ? 0 : k >= n - 1 ? n - 1 : (int)k]++;
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
static int atlas_of(const float *const *src, int n, int w, int h, int cols, lf_image *atlas, lf_error *err)
{
    int rows = (n + cols - 1) / cols;
    if (lf_image_alloc(atlas, cols * w, rows * h, 3, err))
        return err ? err->code : LF_ERR_NOMEM;
    for (int k = 0; k < n; k++)
        for (int t = 0; t < h; t++)
            memcpy(lf_image_px(atlas, (k % cols) * w, (k / cols) * h + t), src[k] + (size_t)t * w * 3,
                   sizeof(float) * 3 * (size_t)w);
    return LF_OK;
}

/* The view atlases: as few as fit the texture limit, the views spread
 * evenly over them (the page allocates every layer at the largest size). */
static int put_views(lf_strbuf *js, const lf_lightfield *lf, const char *dir, const char *ext, int *n_atlases,
                     lf_error *err)
{
    int nviews = lf->nu * lf->nv;
    int cols = LF_WEB_MAX_TEXTURE / lf->ns, rows_max = LF_WEB_MAX_TEXTURE / lf->nt;
    cols = cols > nviews ? nviews : cols;
    int atlases = (nviews + cols * rows_max - 1) / (cols * rows_max);
    int per = cols * (((nviews + atlases - 1) / atlases + cols - 1) / cols);
    const float **src = malloc(sizeof *src * (size_t)per);
    if (!src)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    lf_strbuf_printf(js, "  \"views\": {\"cols\": %d, \"perAtlas\": %d, \"atlases\": [", cols, per);
    int rc = LF_OK;
    for (int a = 0; a < atlases && !rc; a++) {
        int n = nviews - a * per < per ? nviews - a * per : per;
        for (int k = 0; k < n; k++)
            src[k] = lf_lightfield_view(lf, (a * per + k) % lf->nu, (a * per + k) / lf->nu);
        lf_image atlas;
        if ((rc = atlas_of(src, n, lf->ns, lf->nt, cols, &atlas, err)))
            break;
        char name[32];
        snprintf(name, sizeof name, "views%d", a);
        lf_strbuf_puts(js, a ? ",\n    " : "\n    ");
        rc = put_image(js, dir, name, ext, &atlas, err);
        lf_image_free(&atlas);
    }
    lf_strbuf_puts(js, "]},\n");
    free(src);
    *n_atlases = atlases;
    return rc;
}

/* The focal stack over [q0, q1]: the page's fallback without WebGL 2. */
static int put_stack(lf_strbuf *js, const lf_lightfield *lf, const char *dir, const lf_web_export_opts *o, double q0,
                     double q1, lf_error *err)
{
    int n = o->stack_slices;
    lf_image *slices = calloc((size_t)n, sizeof *slices);
    const float **src = calloc((size_t)n, sizeof *src);
    int rc = slices && src ? LF_OK : lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    lf_strbuf_puts(js, "  \"stack\": {\"disparities\": [");
    lf_lightfield_refocus_opts ro = lf_lightfield_refocus_defaults();
    ro.threads = o->threads;
    for (int k = 0; k < n && !rc; k++) {
        ro.disparity_px = q0 + (q1 - q0) * k / (n - 1);
        lf_strbuf_printf(js, "%s%.9g", k ? ", " : "", ro.disparity_px);
        rc = lf_lightfield_refocus(lf, &ro, &slices[k], err);
        src[k] = slices[k].data;
    }
    int cols = (int)ceil(sqrt((double)n));
    lf_image atlas;
    if (!rc && !(rc = atlas_of(src, n, lf->ns, lf->nt, cols, &atlas, err))) {
        lf_strbuf_printf(js, "], \"cols\": %d, \"src\": ", cols);
        rc = put_image(js, dir, "stack", o->format, &atlas, err);
        lf_image_free(&atlas);
    }
    lf_strbuf_puts(js, "}\n");
    for (int k = 0; slices && k < n; k++)
        lf_image_free(&slices[k]);
    free(slices);
    free(src);
    return rc;
}

/* Copies an asset file into the page directory; adds its size to *bytes. */
static int copy_asset(const char *assets, const char *out_dir, const char *name, long *bytes, lf_error *err)
{
    char from[PATH_MAX + 16], to[PATH_MAX + 16];
    snprintf(from, sizeof from, "%s/%s", assets, name);
    snprintf(to, sizeof to, "%s/%s", out_dir, name);
    unsigned char *data;
    size_t len;
    int rc = slurp(from, &data, &len, err);
    if (rc)
        return rc;
    rc = lf_file_write_atomic(to, data, len, err);
    free(data);
    if (!rc)
        *bytes += (long)len;
    return rc;
}

/* The source name, kept to what needs no escaping in a JS string. */
static void safe_name(const char *in, char *out, size_t n)
{
    const char *base = in && strrchr(in, '/') ? strrchr(in, '/') + 1 : in ? in : "";
    size_t k = 0;
    for (; base[k] && k < n - 1; k++)
        out[k] = base[k] >= ' ' && base[k] < 127 && base[k] != '"' && base[k] != '\\' && base[k] != '<' ? base[k] : '_';
    out[k] = '\0';
}

static int export_into(const lf_lightfield *lf, const char *out_dir, const lf_web_export_opts *o, lf_web_export_info *info,
                  lf_error *err)
{
    memset(info, 0, sizeof *info);
    const char *ext = o->format ? o->format : "jpg";
    if (strcmp(ext, "jpg") && strcmp(ext, "png"))
        return lf_error_set(err, LF_ERR_PARAM, "the page's images are jpg or png, not \"%s\"", ext);
    if (o->stack_slices < 2 || o->stack_slices > 64)
        return lf_error_set(err, LF_ERR_PARAM, "the focal stack needs 2..64 slices, not %d", o->stack_slices);
    if (o->have_range && !(o->focus_max > o->focus_min))
        return lf_error_set(err, LF_ERR_PARAM, "the focus range needs max > min (%g .. %g)", o->focus_min,
                            o->focus_max);
    if (lf->ns > LF_WEB_MAX_TEXTURE || lf->nt > LF_WEB_MAX_TEXTURE)
        return lf_error_set(err, LF_ERR_PARAM, "views of %d x %d exceed the page's %d px texture limit", lf->ns, lf->nt,
                            LF_WEB_MAX_TEXTURE);
    char assets[PATH_MAX];
    if (o->assets_dir)
        snprintf(assets, sizeof assets, "%s", o->assets_dir);
    else if (lf_web_find_assets(assets, sizeof assets, err))
        return err ? err->code : LF_ERR_IO;

    /* focus range and per-pixel disparity (docs/lftool.md "Focal stack,
     * all-in-focus, depth"); the page maps a click to the median around it */
    lf_lightfield_refocus_opts ro = lf_lightfield_refocus_defaults();
    ro.threads = o->threads;
    lf_image af = {0}, dm = {0};
    double q0 = o->focus_min, q1 = o->focus_max;
    int rc = LF_OK;
    if (!o->have_range) {
        double d0 = -1, d1 = 1; /* plenoptic: d = 0 at the focus distance */
        if (lf->layout.kind == LF_LIGHTFIELD_CAMERA_ARRAY)
            d0 = 0, d1 = lf->disp_per_inv_m > 0 ? lf->disp_per_inv_m / 0.5 : 4; /* infinity .. 0.5 m */
        rc = lf_lightfield_allfocus(lf, &ro, d0, d1, SEARCH_STEPS, &af, &dm, err);
        if (!rc)
            lf_web_focus_range(dm.data, (size_t)dm.width * dm.height, d0, d1, SEARCH_STEPS, &q0, &q1);
        lf_image_free(&af);
        lf_image_free(&dm);
    }
    if (!rc)
        rc = lf_lightfield_allfocus(lf, &ro, q0, q1, DEPTH_STEPS, &af, &dm, err);
    lf_image_free(&af);
    if (rc)
        return rc;
    /* 8-bit disparity: g = round((d - q0) / (q1 - q0) * 255), stored as a
     * grey PNG whose sRGB encoding gives back exactly g */
    for (size_t i = 0; i < (size_t)dm.width * dm.height; i++) {
        double g = floor((dm.data[i] - q0) / (q1 - q0) * 255 + 0.5);
        dm.data[i] = lf_srgb_decode((unsigned char)(!(g > 0) ? 0 : g > 255 ? 255 : g));
    }
    lf_image grey = {dm.width, dm.height, 1, dm.data};

    char source[256];
    safe_name(o->source, source, sizeof source);
    lf_strbuf js = {0};
    lf_strbuf_printf(&js,
                     "/* lensfield light field for the web page (lftool export-web; docs/web.md). */\n"
                     "window.LF_DATA = {\n  \"version\": 1, \"source\": \"%s\",\n"
                     "  \"nu\": %d, \"nv\": %d, \"ns\": %d, \"nt\": %d, \"dispVPerU\": %.9g,\n"
                     "  \"dispAtInf\": %.9g, \"dispPerInvM\": %.9g, \"focusMin\": %.9g, \"focusMax\": %.9g,\n",
                     source, lf->nu, lf->nv, lf->ns, lf->nt, lf->disp_v_per_u > 0 ? lf->disp_v_per_u : 1.0,
                     lf->disp_at_inf, lf->disp_per_inv_m, q0, q1);
    rc = put_views(&js, lf, out_dir, ext, &info->atlases, err);
    if (!rc) {
        lf_strbuf_printf(&js, "  \"disparity\": {\"min\": %.9g, \"max\": %.9g, \"src\": ", q0, q1);
        rc = put_image(&js, out_dir, "disparity", "png", &grey, err);
        lf_strbuf_puts(&js, "},\n");
    }
    if (!rc)
        rc = put_stack(&js, lf, out_dir, o, q0, q1, err);
    lf_strbuf_puts(&js, "};\n");
    lf_image_free(&dm);
    if (!rc && js.failed)
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory building data.js");
    char path[PATH_MAX + 16];
    snprintf(path, sizeof path, "%s/data.js", out_dir);
    if (!rc)
        rc = lf_file_write_atomic(path, js.s, js.len, err);
    info->page_bytes = (long)js.len;
    lf_strbuf_free(&js);
    if (!rc)
        rc = copy_asset(assets, out_dir, "index.html", &info->page_bytes, err);
    if (!rc)
        rc = copy_asset(assets, out_dir, "lf.js", &info->page_bytes, err);
    info->focus_min = q0;
    info->focus_max = q1;
    return rc;
}

/* Written into a staging folder beside dir and moved into place
 * (base/lf_file_write.h), so a failure leaves no half-written folder. */
int lf_web_export(const lf_lightfield *lf, const char *dir, const lf_web_export_opts *o, lf_web_export_info *info,
                  lf_error *err)
{
    char stage[PATH_MAX];
    int rc = lf_dir_stage_begin(dir, stage, sizeof stage, err);
    if (rc)
        return rc;
    rc = export_into(lf, stage, o, info, err);
    if (rc) {
        lf_dir_stage_abort(stage);
        return rc;
    }
    return lf_dir_stage_commit(stage, dir, err);
}
