/* Folders of views: the HCI benchmark layout and <prefix>_RR_CC names
 * (docs/lightfield-format.md, "Folders of views"), read into the same
 * L(u, v, s, t) as a decoded raw; and the HCI layout written back. */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/lf_file_write.h"
#include "base/lf_parallel.h"
#include "lf_lightfield.h"

enum { MAX_SIDE = 4096 };

int lf_lightfield_is_folder(const char *path)
{
    struct stat st;
    return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

void lf_lightfield_folder_free(lf_lightfield_folder *f)
{
    if (!f)
        return;
    if (f->files)
        for (int i = 0; i < f->nu * f->nv; i++)
            free(f->files[i]);
    free(f->files);
    free(f->dir);
    free(f->gt_disparity);
    memset(f, 0, sizeof *f);
}

static char *join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s", dir, name);
    return p;
}

static const char *extension(const char *name)
{
    const char *dot = strrchr(name, '.');
    return dot ? dot + 1 : "";
}

static int is_image_name(const char *name)
{
    static const char *const exts[] = {"png", "exr", "tif", "tiff", "pfm", "jpg", "jpeg", NULL};
    const char *e = extension(name);
    for (int i = 0; exts[i]; i++)
        if (!strcasecmp(e, exts[i]))
            return 1;
    return 0;
}

typedef struct names {
    char **v;
    size_t n, cap;
} names;

static void names_free(names *s)
{
    for (size_t i = 0; i < s->n; i++)
        free(s->v[i]);
    free(s->v);
    memset(s, 0, sizeof *s);
}

static int names_list(const char *dir, names *out, lf_error *err)
{
    memset(out, 0, sizeof *out);
    DIR *d = opendir(dir);
    if (!d)
        return lf_error_set(err, LF_ERR_IO, "cannot open the folder '%s': %s", dir, strerror(errno));
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        if (out->n == out->cap) {
            size_t cap = out->cap ? 2 * out->cap : 64;
            char **v = realloc(out->v, cap * sizeof *v);
            if (!v)
                break;
            out->v = v, out->cap = cap;
        }
        if (!(out->v[out->n] = strdup(e->d_name)))
            break;
        out->n++;
    }
    int bad = e != NULL;
    closedir(d);
    if (bad) {
        names_free(out);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory listing '%s'", dir);
    }
    return LF_OK;
}

/* ---------- parameters.cfg ---------- */

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

typedef struct cfg_key {
    const char *section, *key;
    double *dst;
    int *seen;
} cfg_key;

/* The keys lensfield uses; others are kept by the benchmark and ignored here. */
static int read_cfg(const char *path, lf_lightfield_folder *f, lf_error *err)
{
    /* non-blocking open, regular files only: a FIFO named parameters.cfg
     * must not hang the reader */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return lf_error_set(err, LF_ERR_IO, "cannot read '%s': not a regular file", path);
    }
    FILE *in = fdopen(fd, "r");
    if (!in) {
        close(fd);
        return lf_error_set(err, LF_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    }
    double focal = 0, sensor = 0, resx = 0, resy = 0, camsx = 0, camsy = 0, base = 0, focus = 0, dmin = 0, dmax = 0;
    int s_focal = 0, s_sensor = 0, s_resx = 0, s_resy = 0, s_cx = 0, s_cy = 0, s_base = 0, s_focus = 0, s_dmin = 0,
        s_dmax = 0;
    const cfg_key keys[] = {
        {"intrinsics", "focal_length_mm", &focal, &s_focal},
        {"intrinsics", "sensor_size_mm", &sensor, &s_sensor},
        {"intrinsics", "image_resolution_x_px", &resx, &s_resx},
        {"intrinsics", "image_resolution_y_px", &resy, &s_resy},
        {"extrinsics", "num_cams_x", &camsx, &s_cx},
        {"extrinsics", "num_cams_y", &camsy, &s_cy},
        {"extrinsics", "baseline_mm", &base, &s_base},
        {"extrinsics", "focus_distance_m", &focus, &s_focus},
        {"meta", "disp_min", &dmin, &s_dmin},
        {"meta", "disp_max", &dmax, &s_dmax},
    };
    char line[1024], section[64] = "";
    int lineno = 0, rc = LF_OK;
    while (!rc && fgets(line, sizeof line, in)) {
        lineno++;
        lf_loc at = {.file = path, .line = lineno};
        if (!strchr(line, '\n') && !feof(in)) {
            rc = lf_error_at(err, LF_ERR_PARSE, &at, "line longer than %zu characters", sizeof line - 2);
            break;
        }
        char *s = trim(line);
        if (!*s || *s == '#' || *s == ';')
            continue;
        if (*s == '[') {
            char *close = strchr(s, ']');
            if (!close || close[1] || close - s - 1 >= (long)sizeof section || close == s + 1) {
                rc = lf_error_at(err, LF_ERR_PARSE, &at, "expected a section header like [intrinsics], got \"%s\"", s);
                break;
            }
            *close = '\0';
            snprintf(section, sizeof section, "%s", trim(s + 1));
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) {
            rc = lf_error_at(err, LF_ERR_PARSE, &at, "expected \"key = value\" or a [section], got \"%s\"", s);
            break;
        }
        *eq = '\0';
        char *key = trim(s), *val = trim(eq + 1);
        if (!*key) {
            rc = lf_error_at(err, LF_ERR_PARSE, &at, "expected \"key = value\", the key is empty");
            break;
        }
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
            if (strcmp(key, keys[k].key) || (section[0] && strcmp(section, keys[k].section)))
                continue;
            char *end;
            errno = 0;
            double v = strtod(val, &end);
            if (!*val || *end || errno || !isfinite(v)) {
                rc = lf_error_at(err, LF_ERR_PARSE, &at, "%s: expected a number, got \"%s\"", key, val);
                break;
            }
            *keys[k].dst = v;
            *keys[k].seen = 1;
        }
    }
    if (!rc && ferror(in))
        rc = lf_error_set(err, LF_ERR_IO, "cannot read '%s'", path);
    fclose(in);
    if (rc)
        return rc;
    const lf_loc file = {.file = path}; /* the whole file: "path: message" */
#define WHOLE(v, lo, hi) ((v) >= (lo) && (v) <= (hi) && (v) == floor(v))
    if ((s_cx && !WHOLE(camsx, 1, MAX_SIDE)) || (s_cy && !WHOLE(camsy, 1, MAX_SIDE)))
        return lf_error_at(err, LF_ERR_PARSE, &file, "num_cams_x / num_cams_y must be whole numbers in 1..%d (got %g, %g)",
                           MAX_SIDE, camsx, camsy);
    if (s_cx != s_cy)
        return lf_error_at(err, LF_ERR_PARSE, &file, "give both num_cams_x and num_cams_y");
    if ((s_resx && !WHOLE(resx, 1, 1 << 20)) || (s_resy && !WHOLE(resy, 1, 1 << 20)))
        return lf_error_at(err, LF_ERR_PARSE, &file, "image_resolution_x_px / _y_px must be whole numbers >= 1");
    if ((s_focal && !(focal > 0)) || (s_sensor && !(sensor > 0)) || (s_base && !(base > 0)) ||
        (s_focus && !(focus > 0)))
        return lf_error_at(err, LF_ERR_PARSE, &file,
                           "focal_length_mm, sensor_size_mm, baseline_mm and focus_distance_m must be > 0");
    if (s_dmin != s_dmax || (s_dmin && !(dmin <= dmax)))
        return lf_error_at(err, LF_ERR_PARSE, &file, "give both disp_min and disp_max, disp_min <= disp_max");
#undef WHOLE
    lf_lightfield_layout *L = &f->layout;
    if (s_cx) {
        f->nu = (int)camsx, f->nv = (int)camsy;
        L->cams_x = f->nu, L->cams_y = f->nv, L->have |= LF_LIGHTFIELD_HAVE_CAMS;
    }
    f->cfg_w = s_resx ? (int)resx : 0;
    f->cfg_h = s_resy ? (int)resy : 0;
    if (s_base && s_cx) {
        /* cameras on the z = 0 plane, centred; metres */
        double b = base * 1e-3;
        L->grid_bounds[0] = -0.5 * b * (f->nu - 1), L->grid_bounds[1] = 0.5 * b * (f->nu - 1);
        L->grid_bounds[2] = -0.5 * b * (f->nv - 1), L->grid_bounds[3] = 0.5 * b * (f->nv - 1);
        L->have |= LF_LIGHTFIELD_HAVE_BOUNDS;
    }
    if (s_focal && s_sensor) {
        /* HCI: the sensor size spans the longer image side; the fov is set
         * once the view size is known (lf_lightfield_folder_load) */
        f->focal_mm = focal, f->sensor_mm = sensor;
    }
    if (s_focus)
        L->convergence_m = focus, L->have |= LF_LIGHTFIELD_HAVE_CONVERGENCE;
    if (s_dmin)
        L->disp_min = dmin, L->disp_max = dmax, L->have |= LF_LIGHTFIELD_HAVE_DISP_RANGE;
    return LF_OK;
}

/* ---------- view names ---------- */

static int all_digits(const char *s, size_t n)
{
    if (!n || n > 6)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!isdigit((unsigned char)s[i]))
            return 0;
    return 1;
}

/* The last pair of '_'-separated all-digit fields of the name's stem:
 * row, column, and the prefix length (up to the '_' before the row). */
static int rowcol(const char *name, int *row, int *col, size_t *prefix)
{
    const char *dot = strrchr(name, '.');
    size_t stem = dot ? (size_t)(dot - name) : strlen(name);
    /* field boundaries: positions of '_' and the stem's end */
    size_t starts[64], lens[64];
    int nf = 0;
    size_t a = 0;
    for (size_t i = 0; i <= stem && nf < 64; i++)
        if (i == stem || name[i] == '_') {
            starts[nf] = a, lens[nf] = i - a, nf++;
            a = i + 1;
        }
    for (int k = nf - 2; k >= 1; k--)
        if (all_digits(name + starts[k], lens[k]) && all_digits(name + starts[k + 1], lens[k + 1])) {
            *row = atoi(name + starts[k]);
            *col = atoi(name + starts[k + 1]);
            *prefix = starts[k] - 1;
            return 1;
        }
    return 0;
}

static int hci_index(const char *name, int *idx)
{
    if (strncmp(name, "input_Cam", 9) || !is_image_name(name))
        return 0;
    const char *p = name + 9;
    size_t n = strspn(p, "0123456789");
    if (!n || n > 6 || p[n] != '.')
        return 0;
    *idx = atoi(p);
    return 1;
}

/* Appends names to a message, at most `limit` of them, "... and N more". */
static void list_append(char *msg, size_t cap, int *count, int limit, const char *name)
{
    size_t k = strlen(msg);
    if (*count < limit)
        snprintf(msg + k, cap - k, "%s%s", *count ? ", " : "", name);
    (*count)++;
}

static int scan_hci(const char *dir, const names *ls, lf_lightfield_folder *f, lf_error *err)
{
    f->kind = LF_LIGHTFIELD_FOLDER_HCI;
    int maxidx = -1, count = 0;
    const char *ext = NULL;
    for (size_t i = 0; i < ls->n; i++) {
        int idx;
        if (hci_index(ls->v[i], &idx)) {
            count++;
            if (idx > maxidx)
                maxidx = idx;
            if (!ext)
                ext = extension(ls->v[i]);
        }
    }
    if (!count)
        return lf_error_set(err, LF_ERR_PARSE, "%s: parameters.cfg but no views input_Cam000.png ...", dir);
    if (!f->nu) {
        int side = (int)floor(sqrt((double)(maxidx + 1)) + 0.5);
        if (side * side != maxidx + 1)
            return lf_error_set(err, LF_ERR_PARSE,
                                "%s: %d views (input_Cam000 .. input_Cam%03d) do not make a square grid and there is "
                                "no parameters.cfg with num_cams_x / num_cams_y; give --camsperdim NX NY",
                                dir, count, maxidx);
        f->nu = f->nv = side;
        f->layout.cams_x = f->layout.cams_y = side;
        f->layout.have |= LF_LIGHTFIELD_HAVE_CAMS;
    }
    int n = f->nu * f->nv;
    snprintf(f->pattern, sizeof f->pattern, "input_Cam%%03d.%s", ext);
    f->files = calloc((size_t)n, sizeof *f->files);
    if (!f->files)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    char extra[512] = "";
    int nextra = 0;
    for (size_t i = 0; i < ls->n; i++) {
        int idx;
        if (!hci_index(ls->v[i], &idx))
            continue;
        if (idx >= n) {
            list_append(extra, sizeof extra, &nextra, 6, ls->v[i]);
            continue;
        }
        if (f->files[idx]) {
            return lf_error_set(err, LF_ERR_PARSE, "%s: two files for view %d: %s and %s", dir, idx,
                                strrchr(f->files[idx], '/') + 1, ls->v[i]);
        }
        if (!(f->files[idx] = join(dir, ls->v[i])))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    if (nextra)
        return lf_error_set(err, LF_ERR_PARSE, "%s: the grid is %d x %d views (parameters.cfg) but there are more: %s%s",
                            dir, f->nu, f->nv, extra, nextra > 6 ? " ..." : "");
    char missing[640] = "";
    int nmiss = 0;
    for (int i = 0; i < n; i++)
        if (!f->files[i]) {
            char name[64];
            snprintf(name, sizeof name, f->pattern, i);
            list_append(missing, sizeof missing, &nmiss, 8, name);
        }
    if (nmiss)
        return lf_error_set(err, LF_ERR_PARSE, "%s: %d of %d views missing: %s%s (the grid is %d x %d)", dir, nmiss, n,
                            missing, nmiss > 8 ? " ..." : "", f->nu, f->nv);
    return LF_OK;
}

static int scan_rowcol(const char *dir, const names *ls, lf_lightfield_folder *f, lf_error *err)
{
    f->kind = LF_LIGHTFIELD_FOLDER_ROWCOL;
    int rmin = MAX_SIDE, cmin = MAX_SIDE, rmax = -1, cmax = -1, count = 0;
    const char *first = NULL;
    size_t first_prefix = 0;
    for (size_t i = 0; i < ls->n; i++) {
        int r, c;
        size_t pre;
        if (!is_image_name(ls->v[i]) || !rowcol(ls->v[i], &r, &c, &pre))
            continue;
        if (!first) {
            first = ls->v[i], first_prefix = pre;
        } else if (pre != first_prefix || strncmp(first, ls->v[i], pre)) {
            return lf_error_set(err, LF_ERR_PARSE,
                                "%s: views of two sets: %s and %s (one light field per folder, named PREFIX_RR_CC...)",
                                dir, first, ls->v[i]);
        }
        count++;
        rmin = r < rmin ? r : rmin, cmin = c < cmin ? c : cmin;
        rmax = r > rmax ? r : rmax, cmax = c > cmax ? c : cmax;
    }
    if (!count)
        return lf_error_set(err, LF_ERR_PARSE,
                            "%s: no light-field views: expected input_CamNNN.png with parameters.cfg (HCI) or images "
                            "named PREFIX_RR_CC[...].png|exr (row, column)",
                            dir);
    if (rmin != cmin || (rmin != 0 && rmin != 1))
        return lf_error_set(err, LF_ERR_PARSE,
                            "%s: view rows start at %d and columns at %d: expected both to start at 0 or both at 1", dir,
                            rmin, cmin);
    f->base = rmin;
    f->nv = rmax - rmin + 1, f->nu = cmax - cmin + 1;
    if (f->nu > MAX_SIDE || f->nv > MAX_SIDE)
        return lf_error_set(err, LF_ERR_PARSE, "%s: %d x %d views is too many", dir, f->nu, f->nv);
    f->layout.cams_x = f->nu, f->layout.cams_y = f->nv, f->layout.have |= LF_LIGHTFIELD_HAVE_CAMS;
    snprintf(f->pattern, sizeof f->pattern, "%.*s_RR_CC...%s (rows and columns from %d)", (int)first_prefix, first,
             strrchr(first, '.') ? strrchr(first, '.') : "", f->base);
    size_t n = (size_t)f->nu * f->nv;
    f->files = calloc(n, sizeof *f->files);
    if (!f->files)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < ls->n; i++) {
        int r, c;
        size_t pre;
        if (!is_image_name(ls->v[i]) || !rowcol(ls->v[i], &r, &c, &pre))
            continue;
        size_t k = (size_t)(r - f->base) * f->nu + (size_t)(c - f->base);
        if (f->files[k])
            return lf_error_set(err, LF_ERR_PARSE, "%s: two files for row %d column %d: %s and %s", dir, r, c,
                                strrchr(f->files[k], '/') + 1, ls->v[i]);
        if (!(f->files[k] = join(dir, ls->v[i])))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    char missing[640] = "";
    int nmiss = 0;
    for (int r = 0; r < f->nv; r++)
        for (int c = 0; c < f->nu; c++)
            if (!f->files[(size_t)r * f->nu + c]) {
                char name[64];
                snprintf(name, sizeof name, "row %d column %d", r + f->base, c + f->base);
                list_append(missing, sizeof missing, &nmiss, 8, name);
            }
    if (nmiss)
        return lf_error_set(err, LF_ERR_PARSE, "%s: %d of %zu views missing (%s): %s%s", dir, nmiss, n, f->pattern,
                            missing, nmiss > 8 ? " ..." : "");
    return LF_OK;
}

int lf_lightfield_folder_scan(const char *dir, lf_lightfield_folder *f, lf_error *err)
{
    memset(f, 0, sizeof *f);
    lf_lightfield_layout_init(&f->layout);
    f->layout.kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    f->layout.have |= LF_LIGHTFIELD_HAVE_KIND;
    if (!(f->dir = strdup(dir)))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    names ls;
    int rc = names_list(dir, &ls, err);
    if (rc) {
        lf_lightfield_folder_free(f);
        return rc;
    }
    int hci = 0, cfg = 0, gt = 0;
    for (size_t i = 0; i < ls.n; i++) {
        int idx;
        hci |= hci_index(ls.v[i], &idx);
        cfg |= !strcmp(ls.v[i], "parameters.cfg");
        gt |= !strcmp(ls.v[i], "gt_disp_lowres.pfm");
    }
    if (cfg) {
        char *p = join(dir, "parameters.cfg");
        rc = p ? read_cfg(p, f, err) : lf_error_set(err, LF_ERR_NOMEM, "out of memory");
        free(p);
    }
    if (!rc && gt && !(f->gt_disparity = join(dir, "gt_disp_lowres.pfm")))
        rc = lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    if (!rc)
        rc = hci || cfg ? scan_hci(dir, &ls, f, err) : scan_rowcol(dir, &ls, f, err);
    names_free(&ls);
    if (rc)
        lf_lightfield_folder_free(f);
    return rc;
}

/* ---------- loading ---------- */

/* What reading one view found. */
typedef struct view_load {
    int rc, w, h;
    size_t nonfinite; /* samples left as read (NaN/Inf) for mark_nonfinite */
    lf_error err;
} view_load;

typedef struct load_ctx {
    const lf_lightfield_folder *f;
    lf_lightfield *lf;
    lf_image *first; /* view 0, read already */
    int w, h;
    view_load *views;
} load_ctx;

/* Views [k0, k1): read, and copied into the light field when of the
 * first view's size. */
static void load_views(void *vctx, int k0, int k1, int tid)
{
    (void)tid;
    load_ctx *c = vctx;
    for (int k = k0; k < k1; k++) {
        view_load *vl = &c->views[k];
        lf_image img = {0};
        if (k == 0)
            img = *c->first;
        else if ((vl->rc = lf_image_read(c->f->files[k], &img, NULL, &vl->err)))
            continue;
        vl->w = img.width, vl->h = img.height;
        if (img.width == c->w && img.height == c->h) {
            float *dst = c->lf->data + (size_t)k * c->w * c->h * 3;
            for (size_t p = 0; p < (size_t)c->w * c->h; p++) {
                const float *s = img.data + p * (size_t)img.channels;
                float v[3];
                if (img.channels >= 3)
                    v[0] = s[0], v[1] = s[1], v[2] = s[2];
                else
                    v[0] = v[1] = v[2] = s[0];
                vl->nonfinite += !isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2]);
                memcpy(dst + p * 3, v, sizeof v);
            }
        }
        if (k > 0)
            lf_image_free(&img);
    }
}

/* View k's non-finite pixels become missing samples: 0 in the data, 0 in
 * the validity mask (allocated, all valid, at the first such view). */
static int mark_nonfinite(lf_lightfield *lf, int k, int n, lf_error *err)
{
    size_t npix = (size_t)lf->ns * lf->nt;
    if (!lf->valid) {
        size_t all = (size_t)n * npix;
        if (!(lf->valid = malloc(all * sizeof *lf->valid)))
            return lf_error_set(err, LF_ERR_NOMEM, "out of memory for the validity mask");
        for (size_t i = 0; i < all; i++)
            lf->valid[i] = 1.f;
    }
    float *d = lf->data + (size_t)k * npix * 3;
    for (size_t p = 0; p < npix; p++)
        if (!isfinite(d[3 * p]) || !isfinite(d[3 * p + 1]) || !isfinite(d[3 * p + 2])) {
            lf->valid[(size_t)k * npix + p] = 0.f;
            lf->nonfinite++, lf->missing++;
            d[3 * p] = d[3 * p + 1] = d[3 * p + 2] = 0.f;
        }
    return LF_OK;
}

int lf_lightfield_folder_load(const lf_lightfield_folder *f, const lf_lightfield_layout *flags, lf_lightfield *lf, lf_error *err)
{
    return lf_lightfield_folder_load_threads(f, flags, 0, lf, err);
}

int lf_lightfield_folder_load_threads(const lf_lightfield_folder *f, const lf_lightfield_layout *flags, int threads,
                                      lf_lightfield *lf, lf_error *err)
{
    memset(lf, 0, sizeof *lf);
    int n = f->nu * f->nv, rc = LF_OK;
    lf_image first = {0};
    if ((rc = lf_image_read(f->files[0], &first, NULL, err)))
        return rc;
    int w = first.width, h = first.height;
    if ((f->cfg_w && f->cfg_w != w) || (f->cfg_h && f->cfg_h != h)) {
        lf_image_free(&first);
        return lf_error_set(err, LF_ERR_PARSE, "%s is %d x %d but %s/parameters.cfg says %d x %d", f->files[0], w, h,
                            f->dir, f->cfg_w ? f->cfg_w : w, f->cfg_h ? f->cfg_h : h);
    }
    /* the folder's layout, completed with the view size, merged with the flags */
    lf_lightfield_layout file = f->layout, lay;
    file.tile_w = w, file.tile_h = h, file.have |= LF_LIGHTFIELD_HAVE_TILE;
    if (f->focal_mm > 0 && f->sensor_mm > 0) {
        double fpx = f->focal_mm / f->sensor_mm * (w > h ? w : h);
        file.fov_deg = 2 * atan(0.5 * (w < h ? w : h) / fpx) * 180 / M_PI;
        file.have |= LF_LIGHTFIELD_HAVE_FOV;
    }
    if ((flags && (flags->have & LF_LIGHTFIELD_HAVE_KIND) && flags->kind != LF_LIGHTFIELD_CAMERA_ARRAY)) {
        lf_image_free(&first);
        return lf_error_set(err, LF_ERR_PARAM, "%s: a folder of views is a camera array (--kind plenoptic given)",
                            f->dir);
    }
    if ((rc = lf_lightfield_layout_resolve(&file, flags, w * f->nu, h * f->nv, &lay, err))) {
        lf_image_free(&first);
        return rc;
    }
    if (lay.tile_w != w || lay.tile_h != h) {
        lf_image_free(&first);
        return lf_error_set(err, LF_ERR_PARAM, "%s: --tilesize %d %d contradicts the views' size %d x %d", f->dir,
                            lay.tile_w, lay.tile_h, w, h);
    }
    if ((rc = lf_lightfield_alloc(lf, f->nu, f->nv, w, h, err))) {
        lf_image_free(&first);
        return rc;
    }
    load_ctx lc = {.f = f, .lf = lf, .first = &first, .w = w, .h = h};
    lc.views = calloc((size_t)n, sizeof *lc.views);
    if (!lc.views) {
        lf_image_free(&first);
        lf_lightfield_free(lf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    /* the views decoded in parallel (PNG inflate and sRGB are most of the
     * time); what they found is gathered in file order, so the messages and
     * the mask are those of reading them one after the other */
    lf_parallel_for(n, threads, 1, load_views, &lc);
    char odd[768] = "";
    int nodd = 0;
    for (int k = 0; k < n && !rc; k++) {
        view_load *vl = &lc.views[k];
        if (vl->rc) {
            rc = lf_error_set(err, vl->rc, "%s", vl->err.msg);
        } else if (vl->w != w || vl->h != h) {
            char item[600];
            snprintf(item, sizeof item, "%s (%d x %d)", f->files[k], vl->w, vl->h);
            list_append(odd, sizeof odd, &nodd, 4, item);
        } else if (vl->nonfinite) {
            rc = mark_nonfinite(lf, k, n, err);
        }
    }
    free(lc.views);
    lf_image_free(&first);
    if (!rc && nodd)
        rc = lf_error_set(err, LF_ERR_PARSE, "%s: views differ in size: %s is %d x %d, but %s%s", f->dir, f->files[0],
                          w, h, odd, nodd > 4 ? " ..." : "");
    if (rc) {
        lf_lightfield_free(lf);
        return rc;
    }
    lf_lightfield_set_geometry(lf, &lay);
    return LF_OK;
}

/* ---------- writing the HCI layout ---------- */

static int write_hci_into(const char *dir, const lf_lightfield *lf, const lf_image *disparity, lf_error *err)
{
    char path[PATH_MAX + 64];
    int rc = LF_OK;
    for (int iv = 0; iv < lf->nv && !rc; iv++)
        for (int iu = 0; iu < lf->nu && !rc; iu++) {
            lf_image v = {lf->ns, lf->nt, 3, lf_lightfield_view(lf, iu, iv)};
            snprintf(path, sizeof path, "%s/input_Cam%03d.png", dir, iv * lf->nu + iu);
            rc = lf_image_write(path, &v, NULL, NULL, err);
        }
    if (!rc && disparity) {
        snprintf(path, sizeof path, "%s/gt_disp_lowres.pfm", dir);
        rc = lf_image_write(path, disparity, NULL, NULL, err);
    }
    if (rc)
        return rc;
    /* parameters.cfg, written beside and renamed into place */
    const lf_lightfield_layout *y = &lf->layout;
    char tmp[PATH_MAX + 96];
    snprintf(path, sizeof path, "%s/parameters.cfg", dir);
    snprintf(tmp, sizeof tmp, "%s/.parameters.cfg.tmp", dir);
    FILE *f = fopen(tmp, "w");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", tmp, strerror(errno));
    int wide = lf->ns > lf->nt ? lf->ns : lf->nt, narrow = lf->ns < lf->nt ? lf->ns : lf->nt;
    fprintf(f, "[intrinsics]\n");
    if (y->kind == LF_LIGHTFIELD_CAMERA_ARRAY && (y->have & LF_LIGHTFIELD_HAVE_FOV)) {
        /* HCI: focal length and the sensor size across the longer side, in mm;
         * a 35 mm sensor, the focal length giving the same focal length in pixels */
        double fpx = 0.5 * narrow / tan(y->fov_deg * M_PI / 360);
        fprintf(f, "focal_length_mm = %.9g\n", fpx * 35.0 / wide);
        fprintf(f, "sensor_size_mm = 35.0\n");
    }
    fprintf(f, "image_resolution_x_px = %d\nimage_resolution_y_px = %d\n", lf->ns, lf->nt);
    fprintf(f, "\n[extrinsics]\nnum_cams_x = %d\nnum_cams_y = %d\n", lf->nu, lf->nv);
    if (y->kind == LF_LIGHTFIELD_CAMERA_ARRAY && (y->have & LF_LIGHTFIELD_HAVE_BOUNDS) && lf->nu > 1)
        fprintf(f, "baseline_mm = %.7g\n", 1000 * (y->grid_bounds[1] - y->grid_bounds[0]) / (lf->nu - 1));
    if (y->kind == LF_LIGHTFIELD_CAMERA_ARRAY && (y->have & LF_LIGHTFIELD_HAVE_CONVERGENCE))
        fprintf(f, "focus_distance_m = %.9g\n", y->convergence_m);
    fprintf(f, "\n[meta]\nsource = lensfield (lftool decode --layout hci)\n");
    if (y->kind == LF_LIGHTFIELD_PLENOPTIC)
        fprintf(f, "# plenoptic capture: views are sub-aperture images; disparity 0 at the main lens's focus\n");
    double dmin = y->disp_min, dmax = y->disp_max;
    int have = (y->have & LF_LIGHTFIELD_HAVE_DISP_RANGE) != 0;
    if (disparity) {
        /* the range of the ground truth itself */
        dmin = INFINITY, dmax = -INFINITY;
        for (size_t i = 0; i < (size_t)disparity->width * disparity->height; i++) {
            float d = disparity->data[i * (size_t)disparity->channels];
            dmin = d < dmin ? d : dmin, dmax = d > dmax ? d : dmax;
        }
        have = dmin <= dmax;
    }
    if (have)
        fprintf(f, "disp_min = %.9g\ndisp_max = %.9g\n", dmin, dmax);
    int bad = ferror(f);
    if (fclose(f) || bad || rename(tmp, path)) {
        remove(tmp);
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
    }
    return LF_OK;
}

/* Written into a staging folder beside dir and moved into place
 * (base/lf_file_write.h), so a failure leaves no half-written folder. */
int lf_lightfield_write_hci(const char *dir, const lf_lightfield *lf, const lf_image *disparity, lf_error *err)
{
    char stage[PATH_MAX];
    int rc = lf_dir_stage_begin(dir, stage, sizeof stage, err);
    if (rc)
        return rc;
    rc = write_hci_into(stage, lf, disparity, err);
    if (rc) {
        lf_dir_stage_abort(stage);
        return rc;
    }
    return lf_dir_stage_commit(stage, dir, err);
}
