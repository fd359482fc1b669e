/* grade.c - grading one submission against a rubric.
 *
 * For each check: find the submitted file (safeio.c), render what the
 * assignment asks for with the reference implementation (two seeds, cached
 * on disk by a hash of the edited scene text and settings), compare
 * (metrics.c), and when the image is wrong, name the known mistake
 * (a rubric "variant") whose reference it matches. */
#define _GNU_SOURCE
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "base/lf_file_write.h"
#include "lightfield/lf_lightfield.h"
#include "render/lf_render.h"
#include "grade_internal.h"

int lf_grade_report_student(const char *report_dir, const char *title, const lf_grade_result *r, lf_error *err);

typedef struct cached_ref {
    uint64_t key;
    lf_image img;
    lf_attrs meta;
} cached_ref;

struct lf_grade_ctx {
    lf_grade_rubric rubric;
    char dir[1024], cache[1024], report[1024];
    int threads;
    cached_ref *refs;
    int nrefs;
    char **students; /* report folder names given so far: each submission gets its own */
    int nstudents;
};

lf_grade_opts lf_grade_opts_default(void)
{
    lf_grade_opts o = {0};
    return o;
}

static int mkdirs(const char *path)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", path);
    for (char *s = p + 1; *s; s++)
        if (*s == '/') {
            *s = 0;
            if (mkdir(p, 0755) && errno != EEXIST)
                return -1;
            *s = '/';
        }
    return mkdir(p, 0755) && errno != EEXIST ? -1 : 0;
}

int lf_grade_ctx_new(const char *assignment_dir, const lf_grade_opts *o, lf_grade_ctx **out, lf_error *err)
{
    *out = NULL;
    lf_grade_ctx *g = calloc(1, sizeof *g);
    if (!g)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    snprintf(g->dir, sizeof g->dir, "%s", assignment_dir);
    char path[1200];
    snprintf(path, sizeof path, "%s/rubric.txt", assignment_dir);
    if (lf_grade_rubric_parse(path, &g->rubric, err)) {
        free(g);
        return err->code;
    }
    if (o && o->cache_dir)
        snprintf(g->cache, sizeof g->cache, "%s", o->cache_dir);
    else if (getenv("XDG_CACHE_HOME") && getenv("XDG_CACHE_HOME")[0])
        snprintf(g->cache, sizeof g->cache, "%s/lensfield", getenv("XDG_CACHE_HOME"));
    else
        snprintf(g->cache, sizeof g->cache, "%s/.cache/lensfield", getenv("HOME") ? getenv("HOME") : "/tmp");
    if (o && o->report_dir)
        snprintf(g->report, sizeof g->report, "%s", o->report_dir);
    g->threads = o ? o->threads : 0;
    *out = g;
    return 0;
}

void lf_grade_ctx_release(lf_grade_ctx *g)
{
    if (!g)
        return;
    for (int i = 0; i < g->nrefs; i++)
        lf_image_free(&g->refs[i].img), lf_attrs_free(&g->refs[i].meta);
    free(g->refs);
    for (int i = 0; i < g->nstudents; i++)
        free(g->students[i]);
    free(g->students);
    lf_grade_rubric_free(&g->rubric);
    free(g);
}

const char *lf_grade_title(const lf_grade_ctx *g) { return g->rubric.title; }

int lf_grade_max_points(const lf_grade_ctx *g)
{
    int m = 0;
    for (int i = 0; i < g->rubric.nchecks; i++)
        m += g->rubric.checks[i].points;
    return m;
}

void lf_grade_result_free(lf_grade_result *r)
{
    free(r->checks);
    memset(r, 0, sizeof *r);
}

/* ---------- reference renders ---------- */

static char *read_text(const char *path, lf_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        lf_error_set(err, LF_ERR_IO, "%s: cannot open", path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (!s || fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        fclose(f);
        lf_error_set(err, LF_ERR_IO, "%s: cannot read", path);
        return NULL;
    }
    s[n] = 0;
    fclose(f);
    return s;
}

static char *edit_text(const char *scene_path, const lf_grade_edit *edits, int nedits, lf_error *err)
{
    char *text = read_text(scene_path, err);
    for (int i = 0; text && i < nedits; i++) {
        char *at = strstr(text, edits[i].find);
        if (!at) {
            lf_error_set(err, LF_ERR_PARAM, "%s: variant edit: text '%s' not found", scene_path, edits[i].find);
            free(text);
            return NULL;
        }
        size_t lf = strlen(edits[i].find), lr = strlen(edits[i].replace), lt = strlen(text);
        char *nt = malloc(lt - lf + lr + 1);
        if (!nt) {
            free(text);
            lf_error_set(err, LF_ERR_NOMEM, "out of memory");
            return NULL;
        }
        size_t pre = (size_t)(at - text);
        memcpy(nt, text, pre);
        memcpy(nt + pre, edits[i].replace, lr);
        memcpy(nt + pre + lr, at + lf, lt - pre - lf + 1);
        free(text);
        text = nt;
    }
    return text;
}

static int render_text(const char *text, const char *scene_path, int spp, uint32_t seed, int threads, lf_image *out,
                       lf_attrs *meta, lf_error *err)
{
    lf_scene_desc d;
    if (lf_scene_parse_string(text, scene_path, &d, err))
        return err->code;
    lf_render_opts o = lf_render_opts_default();
    o.spp = spp;
    o.seed = seed;
    o.has_seed = 1;
    o.threads = threads;
    o.scene_path = scene_path;
    lf_renderer *r;
    int rc = lf_renderer_create(&d, &o, &r, err);
    if (!rc) {
        lf_attrs m = {0};
        rc = lf_renderer_render(r, out, &m, err);
        if (meta)
            *meta = m;
        else
            lf_attrs_free(&m);
        lf_renderer_free(r);
    }
    lf_scene_desc_free(&d);
    return rc;
}

int lf_grade_render(const char *scene_path, const lf_grade_edit *edits, int nedits, int spp, uint32_t seed,
                    int threads, lf_image *out, lf_attrs *meta, lf_error *err)
{
    char *text = edit_text(scene_path, edits, nedits, err);
    if (!text)
        return err->code;
    int rc = render_text(text, scene_path, spp, seed, threads, out, meta, err);
    free(text);
    return rc;
}

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *s = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ s[i]) * 1099511628211ull;
    return h;
}

static int copy_image(const lf_image *src, lf_image *dst)
{
    lf_error e = {0};
    if (lf_image_alloc(dst, src->width, src->height, src->channels, &e))
        return -1;
    memcpy(dst->data, src->data, sizeof(float) * (size_t)src->width * src->height * src->channels);
    return 0;
}

/* The reference for a scene (+ variant) at spp and seed; the image is owned
 * by the context. */
static int reference(lf_grade_ctx *g, const char *scene_rel, const lf_grade_variant *v, int spp, uint32_t seed,
                     const lf_image **img, const lf_attrs **meta, lf_error *err)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", g->dir, scene_rel);
    lf_grade_edit edits[LF_GRADE_MAX_EDITS] = {{0}};
    int ne = v ? v->nedits : 0;
    for (int i = 0; i < ne; i++)
        edits[i].find = v->find[i], edits[i].replace = v->replace[i];
    char *text = edit_text(path, edits, ne, err);
    if (!text)
        return err->code;
    char settings[256];
    snprintf(settings, sizeof settings, "lfgrade-ref-1|%d|%u|%s", spp, seed, v ? v->post : "");
    uint64_t key = fnv(fnv(1469598103934665603ull, text, strlen(text)), settings, strlen(settings));
    for (int i = 0; i < g->nrefs; i++)
        if (g->refs[i].key == key) {
            free(text);
            *img = &g->refs[i].img, *meta = &g->refs[i].meta;
            return 0;
        }
    cached_ref *nr = realloc(g->refs, sizeof *nr * (size_t)(g->nrefs + 1));
    if (!nr) {
        free(text);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    g->refs = nr;
    cached_ref *c = &g->refs[g->nrefs];
    memset(c, 0, sizeof *c);
    c->key = key;
    char file[1400];
    snprintf(file, sizeof file, "%s/ref-%016llx.exr", g->cache, (unsigned long long)key);
    lf_error cerr = {0};
    int rc = 0;
    if (lf_image_read(file, &c->img, &c->meta, &cerr)) {
        rc = render_text(text, path, spp, seed, g->threads, &c->img, &c->meta, err);
        if (!rc && v && v->post[0])
            rc = lf_grade_post(v->post, &c->img, err);
        if (!rc) {
            if (mkdirs(g->cache))
                rc = lf_error_set(err, LF_ERR_IO, "%s: cannot create the cache directory: %s", g->cache,
                                  strerror(errno));
            else
                rc = lf_image_write(file, &c->img, &c->meta, NULL, err);
        }
    }
    free(text);
    if (rc) {
        lf_image_free(&c->img), lf_attrs_free(&c->meta);
        return rc;
    }
    g->nrefs++;
    *img = &c->img, *meta = &c->meta;
    return 0;
}

/* ---------- a submission ---------- */

typedef struct sub_image {
    char base[64];
    char file[96];
    int state; /* 0 not looked at, 1 header ok, 2 decoded, -1 problem */
    char why[512];
    const char *format;
    int w, h;
    unsigned char *bytes;
    size_t nbytes;
    lf_image img;
} sub_image;

typedef struct submission {
    const char *dir;
    char *md;
    char md_why[512];
    int md_state; /* 0 not read, 1 ok, -1 problem */
    sub_image imgs[16];
    int nimgs;
} submission;

static void set_why(sub_image *im, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_why(sub_image *im, const char *fmt, ...)
{
    char msg[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    size_t l = strlen(msg);
    if (l >= sizeof im->why)
        l = sizeof im->why - 1;
    memcpy(im->why, msg, l);
    im->why[l] = 0;
}

static sub_image *find_image(submission *s, const char *base)
{
    for (int i = 0; i < s->nimgs; i++)
        if (!strcmp(s->imgs[i].base, base))
            return &s->imgs[i];
    if (s->nimgs == 16)
        return NULL;
    sub_image *im = &s->imgs[s->nimgs++];
    memset(im, 0, sizeof *im);
    snprintf(im->base, sizeof im->base, "%s", base);
    /* EXR preferred when both exist (lossless) */
    static const char *exts[] = {"exr", "png"};
    for (int k = 0; k < 2; k++) {
        snprintf(im->file, sizeof im->file, "%s.%s", base, exts[k]);
        char why[512];
        int rc = lf_grade_read_inside(s->dir, im->file, LF_GRADE_MAX_FILE, &im->bytes, &im->nbytes, why, sizeof why);
        if (rc == 1)
            continue;
        if (rc < 0) {
            im->state = -1;
            set_why(im, "%s", why);
            return im;
        }
        if (lf_grade_image_header(im->bytes, im->nbytes, &im->format, &im->w, &im->h, why, sizeof why)) {
            im->state = -1;
            set_why(im, "%s: %s", im->file, why);
            return im;
        }
        if ((!strcmp(im->format, "png")) != (k == 1)) {
            im->state = -1;
            set_why(im, "%s: the file is a %s image (name and contents disagree)", im->file, im->format);
            return im;
        }
        im->state = 1;
        return im;
    }
    im->state = -1;
    snprintf(im->file, sizeof im->file, "%s.png", base);
    set_why(im, "missing: neither %s.png nor %s.exr in the submission", base, base);
    return im;
}

/* The decoded image if it has the expected size; else NULL and a reason. */
static sub_image *get_image(submission *s, const char *base, int w, int h, char *why, size_t wn)
{
    sub_image *im = find_image(s, base);
    if (!im) {
        snprintf(why, wn, "too many images");
        return NULL;
    }
    if (im->state < 0) {
        snprintf(why, wn, "%s", im->why);
        return NULL;
    }
    if (im->w != w || im->h != h) {
        snprintf(why, wn, "%s: wrong size: %dx%d, expected %dx%d (not compared)", im->file, im->w, im->h, w, h);
        return NULL;
    }
    if (im->state == 1) {
        char msg[400];
        if (lf_grade_image_decode(im->bytes, im->nbytes, im->format, &im->img, msg, sizeof msg)) {
            im->state = -1;
            set_why(im, "%s: %s", im->file, msg);
            snprintf(why, wn, "%s", im->why);
            return NULL;
        }
        if (im->img.width != w || im->img.height != h) {
            im->state = -1;
            set_why(im, "%s: decodes to %dx%d, expected %dx%d", im->file, im->img.width, im->img.height, w, h);
            snprintf(why, wn, "%s", im->why);
            return NULL;
        }
        size_t bad = lf_image_count_nonfinite(&im->img);
        if (bad) {
            im->state = -1;
            set_why(im, "%s: %zu NaN/Inf pixel values (not compared)", im->file, bad);
            snprintf(why, wn, "%s", im->why);
            return NULL;
        }
        im->state = 2;
    }
    return im;
}

static const char *get_md(submission *s)
{
    if (s->md_state == 0) {
        unsigned char *d;
        size_t n;
        int rc = lf_grade_read_inside(s->dir, "Submission.md", LF_GRADE_MAX_MD, &d, &n, s->md_why, sizeof s->md_why);
        if (rc == 1)
            snprintf(s->md_why, sizeof s->md_why, "Submission.md: missing");
        if (rc) {
            s->md_state = -1;
        } else {
            for (size_t i = 0; i < n; i++)
                if (d[i] == 0)
                    d[i] = ' ';
            s->md = (char *)d;
            s->md_state = 1;
        }
    }
    return s->md_state > 0 ? s->md : NULL;
}

static void free_submission(submission *s)
{
    free(s->md);
    for (int i = 0; i < s->nimgs; i++)
        free(s->imgs[i].bytes), lf_image_free(&s->imgs[i].img);
}

/* Section headings (# ...) whose text starts with name, case-insensitively;
 * returns the body length (non-blank characters) or -1 when absent. */
static int section_body(const char *md, const char *name, const char **body_start, const char **body_end)
{
    const char *p = md;
    while (*p) {
        const char *eol = strchr(p, '\n');
        if (!eol)
            eol = p + strlen(p);
        if (*p == '#') {
            const char *t = p;
            while (*t == '#')
                t++;
            while (*t == ' ' || *t == '\t')
                t++;
            if (!strncasecmp(t, name, strlen(name))) {
                const char *b = *eol ? eol + 1 : eol, *e = b;
                int nonblank = 0;
                while (*e) {
                    if ((e == md || e[-1] == '\n') && *e == '#')
                        break;
                    if (!isspace((unsigned char)*e))
                        nonblank++;
                    e++;
                }
                if (body_start)
                    *body_start = b, *body_end = e;
                return nonblank;
            }
        }
        p = *eol ? eol + 1 : eol;
    }
    return -1;
}

/* The first line mentioning "lftool WORD" (the Commands section first),
 * copied without markdown decoration. */
static int find_command(const char *md, const char *word, char *line, size_t n)
{
    char pat[64];
    snprintf(pat, sizeof pat, "lftool %s", word);
    const char *at = strstr(md, pat);
    if (!at)
        return -1;
    const char *eol = strchr(at, '\n');
    size_t len = eol ? (size_t)(eol - at) : strlen(at);
    if (len >= n)
        len = n - 1;
    memcpy(line, at, len);
    line[len] = 0;
    /* drop inline-code backticks and a trailing carriage return */
    char *bt = strchr(line, '`');
    if (bt && !strpbrk(bt + 1, ";|&$<>\\(){}")) {
        char *q = bt;
        while (*q == '`' || *q == ' ' || *q == '\r')
            q++;
        if (!*q)
            *bt = 0;
    }
    size_t l = strlen(line);
    while (l && (line[l - 1] == '\r' || line[l - 1] == ' '))
        line[--l] = 0;
    return 0;
}

static int parse_num(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return end != s && !*end && !errno && isfinite(*v) ? 0 : -1;
}

/* What a student's `lftool synth|refocus ...` asked for, re-implemented. */
typedef struct declared {
    int ok;
    char why[512];
    lf_lightfield_synth_opts synth;
    int have_outfov, have_outdim, have_pos, have_focal;
    char flags_seen[512]; /* " lensradius focaldistance ..." */
    double values[32];
    char names[32][24];
    int nvalues;
    /* refocus */
    int focus_kind; /* 0 none, 1 depth, 2 disparity, 3 alpha */
    double focus, aperture;
    int have_aperture;
} declared;

static void remember(declared *d, const char *name, double v)
{
    if (d->nvalues < 32) {
        snprintf(d->names[d->nvalues], sizeof d->names[0], "%s", name);
        d->values[d->nvalues++] = v;
    }
}

static int declared_value(const declared *d, const char *name, double *v)
{
    for (int i = d->nvalues - 1; i >= 0; i--)
        if (!strcmp(d->names[i], name)) {
            *v = d->values[i];
            return 1;
        }
    return 0;
}

static void parse_declared(const char *md, const char *word, declared *d)
{
    memset(d, 0, sizeof *d);
    d->synth = lf_lightfield_synth_defaults();
    char line[2048];
    if (!md) {
        snprintf(d->why, sizeof d->why, "no Submission.md to read the lftool %s command from", word);
        return;
    }
    if (find_command(md, word, line, sizeof line)) {
        snprintf(d->why, sizeof d->why, "Submission.md: no `lftool %s ...` command found", word);
        return;
    }
    char **v;
    int n;
    lf_error why = {0};
    if (lf_grade_tokenize(line, &v, &n, &why)) {
        snprintf(d->why, sizeof d->why, "Submission.md: the lftool %s command %.400s", word, why.msg);
        return;
    }
    static const struct {
        const char *flag;
        int n;
    } flags[] = {{"--samplesperpixel", 1}, {"--focaldistance", 1}, {"--camerapos", 3}, {"--camerarot", 3},
                 {"--inputfov", 1},        {"--outputfov", 1},     {"--lensradius", 1}, {"--griddim", 4},
                 {"--camsperdim", 2},      {"--outputdim", 2},     {"--seed", 1},       {"--threads", 1},
                 {"--depth", 1},           {"--disparity", 1},     {"--alpha", 1},      {"--aperture", 1}};
    int positional = 0;
    d->ok = 1;
    for (int i = 2; i < n && d->ok; i++) {
        const char *a = v[i];
        if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--coverage") || !strcmp(a, "--method")) {
            i++;
            continue;
        }
        if (a[0] != '-') {
            positional++;
            continue;
        }
        int k = -1;
        for (size_t f = 0; f < sizeof flags / sizeof *flags; f++)
            if (!strcmp(a, flags[f].flag))
                k = (int)f;
        if (k < 0) {
            d->ok = 0;
            snprintf(d->why, sizeof d->why, "Submission.md: lftool %s: unknown flag %.60s", word, a);
            break;
        }
        double x[4];
        for (int j = 0; j < flags[k].n; j++) {
            if (i + 1 + j >= n || parse_num(v[i + 1 + j], &x[j])) {
                d->ok = 0;
                snprintf(d->why, sizeof d->why, "Submission.md: lftool %s: %s needs %d finite number(s)", word, a,
                         flags[k].n);
                break;
            }
        }
        if (!d->ok)
            break;
        i += flags[k].n;
        const char *name = a + 2;
        remember(d, name, x[0]);
        if (!strcmp(name, "samplesperpixel")) {
            if (x[0] < 1 || x[0] > 1024) /* checked before the conversion: 1e308 has no int */
                d->ok = 0, snprintf(d->why, sizeof d->why, "--samplesperpixel %g outside 1..1024", x[0]);
            else
                d->synth.spp = (int)x[0];
        } else if (!strcmp(name, "focaldistance"))
            d->synth.focal_distance = x[0], d->have_focal = 1;
        else if (!strcmp(name, "camerapos"))
            memcpy(d->synth.pos, x, sizeof d->synth.pos), d->have_pos = 1;
        else if (!strcmp(name, "camerarot"))
            memcpy(d->synth.rot_deg, x, sizeof d->synth.rot_deg);
        else if (!strcmp(name, "outputfov"))
            d->synth.fov_deg = x[0], d->have_outfov = 1;
        else if (!strcmp(name, "lensradius"))
            d->synth.lens_radius = x[0];
        else if (!strcmp(name, "outputdim")) {
            if (x[0] < 1 || x[1] < 1 || x[0] > 2048 || x[1] > 2048)
                d->ok = 0, snprintf(d->why, sizeof d->why, "--outputdim %g %g outside 1..2048", x[0], x[1]);
            else
                d->synth.width = (int)x[0], d->synth.height = (int)x[1], d->have_outdim = 1;
        } else if (!strcmp(name, "seed")) {
            if (!(fabs(x[0]) <= 4294967295.0))
                d->ok = 0, snprintf(d->why, sizeof d->why, "--seed %g outside 0..4294967295", x[0]);
            else
                d->synth.seed = (uint32_t)fabs(x[0]);
        }
        else if (!strcmp(name, "depth"))
            d->focus_kind = 1, d->focus = x[0];
        else if (!strcmp(name, "disparity"))
            d->focus_kind = 2, d->focus = x[0];
        else if (!strcmp(name, "alpha"))
            d->focus_kind = 3, d->focus = x[0];
        else if (!strcmp(name, "aperture"))
            d->aperture = x[0], d->have_aperture = 1;
    }
    if (d->ok && positional < 1) {
        d->ok = 0;
        snprintf(d->why, sizeof d->why, "Submission.md: lftool %s: no input file", word);
    }
    lf_grade_free_argv(v, n);
}

/* Applies "key:value,key:value" overrides (variants) to a declaration. */
static void apply_set(declared *d, const char *set)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", set);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        char *colon = strchr(tok, ':');
        if (!colon)
            continue;
        *colon = 0;
        double x = atof(colon + 1);
        if (!strcmp(tok, "lensradius"))
            d->synth.lens_radius = x;
        else if (!strcmp(tok, "focaldistance"))
            d->synth.focal_distance = x, d->have_focal = 1;
        else if (!strcmp(tok, "outputfov"))
            d->synth.fov_deg = x, d->have_outfov = 1;
        else if (!strcmp(tok, "depth"))
            d->focus_kind = 1, d->focus = x;
        else if (!strcmp(tok, "disparity"))
            d->focus_kind = 2, d->focus = x;
    }
}

/* Light-field pipelines on a reference raw: synth (CS348B Part 2) or refocus. */
static int lightfield_product(const lf_image *raw, const lf_attrs *meta, const declared *d, int refocus, int threads,
                              lf_image *out, char *why, size_t wn)
{
    lf_error err = {0};
    lf_lightfield_layout file, flags, lay;
    lf_lightfield_layout_init(&flags);
    lf_lightfield lf;
    memset(&lf, 0, sizeof lf);
    if (lf_lightfield_layout_from_attrs(meta, &file, &err) ||
        lf_lightfield_layout_resolve(&file, &flags, raw->width, raw->height, &lay, &err) ||
        lf_lightfield_decode(raw, &lay, NULL, &lf, &err)) {
        snprintf(why, wn, "grader: reference light field: %s", err.msg);
        lf_lightfield_free(&lf);
        return -1;
    }
    int rc;
    if (!refocus) {
        lf_lightfield_synth_opts s = d->synth;
        s.threads = threads > 0 ? threads : 2;
        if (!d->have_outfov)
            s.fov_deg = lay.fov_deg;
        if (!d->have_outdim)
            s.width = lf.ns, s.height = lf.nt;
        if (!d->have_pos) {
            s.pos[0] = 0.5 * (lay.grid_bounds[0] + lay.grid_bounds[1]);
            s.pos[1] = 0.5 * (lay.grid_bounds[2] + lay.grid_bounds[3]);
            s.pos[2] = 0;
        }
        if (!d->have_focal && (lay.have & LF_LIGHTFIELD_HAVE_CAM_LENS) && lay.focal_distance > 0)
            s.focal_distance = lay.focal_distance;
        rc = lf_lightfield_synth(&lf, &s, out, NULL, NULL, &err);
    } else {
        lf_lightfield_refocus_opts ro = lf_lightfield_refocus_defaults();
        if (d->have_aperture)
            ro.aperture_radius = d->aperture;
        double disp = 0;
        rc = 0;
        if (d->focus_kind == 1)
            rc = lf_lightfield_depth_to_disparity(&lf, d->focus, &disp, &err);
        else if (d->focus_kind == 3)
            rc = lf_lightfield_alpha_to_disparity(&lf, d->focus, &disp, &err);
        else if (d->focus_kind == 2)
            disp = d->focus;
        ro.disparity_px = disp;
        if (!rc)
            rc = lf_lightfield_refocus(&lf, &ro, out, &err);
    }
    lf_lightfield_free(&lf);
    if (rc)
        snprintf(why, wn, "the declared command cannot be reproduced: %s", err.msg);
    return rc ? -1 : 0;
}

/* ---------- comparing ---------- */

typedef struct compare_job {
    lf_grade_ctx *g;
    const lf_grade_check *c;
    lf_grade_check_result *res;
    const char *student_dir; /* report folder, or NULL */
    /* reference producer: seed 0 = A, 1 = B; variant may be NULL */
    int (*make)(struct compare_job *j, const lf_grade_variant *v, int which, lf_image *out, char *why, size_t wn);
    declared decl;
    int spp;
    uint32_t seed;
} compare_job;

static int make_render(compare_job *j, const lf_grade_variant *v, int which, lf_image *out, char *why, size_t wn)
{
    const lf_image *img;
    const lf_attrs *meta;
    lf_error err = {0};
    if (reference(j->g, lf_grade_check_get(j->c, "scene", ""), v, j->spp, j->seed + (uint32_t)which, &img, &meta,
                  &err)) {
        snprintf(why, wn, "grader: reference %s: %s", v ? v->name : "render", err.msg);
        return -2;
    }
    return copy_image(img, out);
}

static int make_lightfield(compare_job *j, const lf_grade_variant *v, int which, lf_image *out, char *why, size_t wn,
                           int refocus)
{
    const lf_image *img;
    const lf_attrs *meta;
    lf_error err = {0};
    if (reference(j->g, lf_grade_check_get(j->c, "scene", ""), NULL, j->spp, j->seed + (uint32_t)which, &img, &meta,
                  &err)) {
        snprintf(why, wn, "grader: reference light field: %s", err.msg);
        return -2;
    }
    declared d = j->decl;
    if (v && v->set[0])
        apply_set(&d, v->set);
    d.synth.seed = 7 + (uint32_t)which;
    return lightfield_product(img, meta, &d, refocus, j->g->threads, out, why, wn);
}
static int make_synth(compare_job *j, const lf_grade_variant *v, int which, lf_image *out, char *why, size_t wn)
{
    return make_lightfield(j, v, which, out, why, wn, 0);
}
static int make_refocus(compare_job *j, const lf_grade_variant *v, int which, lf_image *out, char *why, size_t wn)
{
    return make_lightfield(j, v, which, out, why, wn, 1);
}

static void fail(lf_grade_check_result *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void fail(lf_grade_check_result *r, const char *fmt, ...)
{
    r->status = LF_GRADE_FAIL;
    r->earned = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->reason, sizeof r->reason, fmt, ap);
    va_end(ap);
}

static void write_png(const char *dir, const char *id, const char *what, const lf_image *img)
{
    if (!dir)
        return;
    char path[1400];
    snprintf(path, sizeof path, "%s/%s-%s.png", dir, id, what);
    lf_error e = {0};
    lf_image_write(path, img, NULL, NULL, &e);
}

/* A search variant at one value: its with= texts with {v} / {v*K} replaced. */
static int instantiate(const lf_grade_variant *v, double value, lf_grade_variant *out)
{
    *out = *v;
    out->search = 0;
    for (int e = 0; e < v->nedits; e++) {
        const char *t = v->replace[e];
        size_t cap = strlen(t) + 256, n = 0;
        char *o = malloc(cap);
        if (!o) {
            for (int q = 0; q < e; q++)
                free(out->replace[q]);
            return -1;
        }
        while (*t && n + 64 < cap) {
            if (t[0] == '{' && t[1] == 'v') {
                const char *end = strchr(t, '}');
                double k = 1;
                if (end && t[2] == '*')
                    k = atof(t + 3);
                if (end) {
                    n += (size_t)snprintf(o + n, cap - n, "%.6g", value * k);
                    t = end + 1;
                    continue;
                }
            }
            o[n++] = *t++;
        }
        o[n] = 0;
        out->replace[e] = o;
    }
    return 0;
}

static void free_instance(lf_grade_variant *v)
{
    for (int e = 0; e < v->nedits; e++)
        free(v->replace[e]);
}

/* {pct} {value} {base} {K/value} {value*K} in a search variant's texts */
static void search_text(const lf_grade_variant *v, const char *text, double factor, char *out, size_t n)
{
    size_t k = 0;
    double value = v->base * factor;
    for (const char *t = text; *t && k + 40 < n;) {
        const char *end = t[0] == '{' ? strchr(t, '}') : NULL;
        double K;
        if (!end) {
            out[k++] = *t++;
            continue;
        }
        if (!strncmp(t, "{pct}", 5))
            k += (size_t)snprintf(out + k, n - k, "%+.0f%%", 100 * (factor - 1));
        else if (!strncmp(t, "{value}", 7))
            k += (size_t)snprintf(out + k, n - k, "%.4g", value);
        else if (!strncmp(t, "{base}", 6))
            k += (size_t)snprintf(out + k, n - k, "%.4g", v->base);
        else if (!strncmp(t, "{value*", 7))
            k += (size_t)snprintf(out + k, n - k, "%.3g", value * atof(t + 7));
        else if (sscanf(t + 1, "%lf/value}", &K) == 1 && strstr(t, "/value}") == strchr(t, '/'))
            k += (size_t)snprintf(out + k, n - k, "%.3g", K / value);
        else if (sscanf(t + 1, "%lf/base}", &K) == 1 && strstr(t, "/base}") == strchr(t, '/'))
            k += (size_t)snprintf(out + k, n - k, "%.3g", K / v->base);
        else {
            out[k++] = *t++;
            continue;
        }
        t = end + 1;
    }
    out[k < n ? k : n - 1] = 0;
}

/* The gain k of x ~ k v, least squares over the values x does not clip
 * (an 8-bit image saturates: its clipped part says only "at least"). */
static double fit_gain(const lf_image *x, const lf_image *v, int eight_bit)
{
    double sxv = 0, svv = 0;
    size_t n = (size_t)x->width * x->height * (size_t)x->channels;
    for (size_t i = 0; i < n; i++) {
        if (eight_bit && x->data[i] >= 0.98f)
            continue;
        sxv += (double)x->data[i] * v->data[i], svv += (double)v->data[i] * v->data[i];
    }
    return svv > 0 && sxv > 0 ? sxv / svv : NAN;
}

static void scale_image(lf_image *im, double k)
{
    size_t n = (size_t)im->width * im->height * (size_t)im->channels;
    for (size_t i = 0; i < n; i++)
        im->data[i] = (float)(im->data[i] * k);
}

/* ratio of the submission against variant v (two seeds; NULL: the correct
 * reference); < 0 grader error.  With gain non-NULL, also the ratio once v
 * is scaled by the gain fitted to x (*gain, *gain_ratio): the same mistake
 * at another exposure. */
static double variant_ratio(compare_job *j, const lf_grade_variant *v, const lf_image *x, int eight_bit,
                            const lf_image *a, char *why, size_t wn, int *grader_err, double *gain,
                            double *gain_ratio)
{
    lf_image va = {0}, vb = {0};
    int rc = j->make(j, v, 0, &va, why, wn);
    if (!rc)
        rc = j->make(j, v, 1, &vb, why, wn);
    double r = INFINITY;
    if (gain)
        *gain = NAN, *gain_ratio = INFINITY;
    if (rc == -2)
        *grader_err = 1;
    else if (!rc && va.width == a->width && va.height == a->height && vb.width == a->width && vb.height == a->height) {
        double k = gain ? fit_gain(x, &va, eight_bit) : NAN;
        if (isfinite(k)) {
            lf_image ga = {0}, gb = {0};
            if (!copy_image(&va, &ga) && !copy_image(&vb, &gb)) {
                scale_image(&ga, k), scale_image(&gb, k);
                if (eight_bit)
                    lf_grade_quantize8(&ga), lf_grade_quantize8(&gb);
                *gain = k, *gain_ratio = lf_grade_noise_ratio(x, &ga, &ga, &gb);
            }
            lf_image_free(&ga), lf_image_free(&gb);
        }
        if (eight_bit)
            lf_grade_quantize8(&va), lf_grade_quantize8(&vb);
        r = lf_grade_noise_ratio(x, &va, &va, &vb);
    }
    lf_image_free(&va), lf_image_free(&vb);
    return r;
}

/* Physical measurements of x against the correct reference a: brightness,
 * field of view, blur (docs/grading.md, "Measurements"). */
static void appendf(char *out, size_t n, size_t *k, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void appendf(char *out, size_t n, size_t *k, const char *fmt, ...)
{
    if (*k + 1 >= n)
        return;
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(out + *k, n - *k, fmt, ap);
    va_end(ap);
    if (w > 0)
        *k = *k + (size_t)w < n ? *k + (size_t)w : n - 1;
}

static void measure(const compare_job *j, const lf_image *x, const lf_image *a, char *out, size_t n)
{
    const lf_grade_check *c = j->c;
    size_t k = 0;
    double bright = lf_grade_mean(x) / fmax(lf_grade_mean(a), 1e-12);
    appendf(out, n, &k, "brightness %.2fx the reference", bright);
    double m = lf_grade_fit_scale(x, a);
    double hfov = atof(lf_grade_check_get(c, "hfov", "0"));
    if (!strcmp(lf_grade_check_get(c, "fov_fit", "1"), "0"))
        ; /* tiled light fields: no single image centre */
    else if (fabs(m - 1) < 0.01)
        appendf(out, n, &k, "; field of view as expected (no change of magnification explains the difference)");
    else if (hfov > 0)
        appendf(out, n, &k, "; field of view %.1f deg across, expected %.1f (content %.3fx the size)",
                              2 * atan(m * tan(hfov * M_PI / 360)) * 180 / M_PI, hfov, 1 / m);
    else
        appendf(out, n, &k, "; field of view %+.1f%% (tan of the half angle; content %.3fx the size)",
                              100 * (m - 1), 1 / m);
    const char *hl = lf_grade_check_get(c, "highlights", NULL);
    int x0, y0, x1, y1, cnt;
    if (hl && sscanf(hl, "%d,%d,%d,%d:%d", &x0, &y0, &x1, &y1, &cnt) == 5) {
        double ds = lf_grade_highlight_diameter(x, x0, y0, x1, y1, cnt), da = lf_grade_highlight_diameter(a, x0, y0, x1, y1, cnt);
        const char *expect = lf_grade_check_get(c, "blur_px", NULL);
        appendf(out, n, &k, "; blur circle of the highlights %.1f px across, expected %.1f (reference %.1f)", ds,
                              expect ? atof(expect) : da, da);
    } else if (strcmp(lf_grade_check_get(c, "blur", "1"), "0")) {
        double b = lf_grade_fit_blur(x, a);
        if (b > 0)
            appendf(out, n, &k, "; blurrier: like the reference through a %.1f px blur disc", b);
        else if (b < 0)
            appendf(out, n, &k, "; sharper: the reference looks like it through a %.1f px blur disc", -b);
    }
    (void)k;
}

/* What a variant is compared against: the submission x (8-bit or not) and
 * the correct reference a; why and gerr carry a grader-side failure. */
typedef struct subject {
    const lf_image *x, *a;
    int eight_bit;
    int gerr;
    char why[700];
} subject;

/* The ratio of search variant v at the factor exp(l) into *r; -1 (r
 * untouched) when the variant cannot be instantiated. */
static int ratio_at(compare_job *j, const lf_grade_variant *v, double l, subject *t, double *r)
{
    lf_grade_variant inst;
    if (instantiate(v, v->base * exp(l), &inst))
        return -1;
    *r = variant_ratio(j, &inst, t->x, t->eight_bit, t->a, t->why, sizeof t->why, &t->gerr, NULL, NULL);
    free_instance(&inst);
    return 0;
}

enum { MAX_SEARCH_STEPS = 25 };

/* A search's first stage: the ratio on a grid of log factors ll over
 * [lo, hi], at 1/8 of the sample count (the bias dominates away from the
 * best value).  Returns the best grid index, or -1. */
static int search_grid(compare_job *j, const lf_grade_variant *v, subject *t, double *ll, double *rr, int *ns_out)
{
    double lf0 = log(v->lo), lf1 = log(v->hi);
    int ns = (int)ceil((lf1 - lf0) / 0.04) + 1;
    ns = ns > MAX_SEARCH_STEPS ? MAX_SEARCH_STEPS : ns < 3 ? 3 : ns;
    double bestr = INFINITY;
    int bi = -1, full_spp = j->spp;
    j->spp = getenv("LF_GRADE_FULLSEARCH") ? full_spp : full_spp / 8 > 4 ? full_spp / 8 : 4 < full_spp ? 4 : full_spp;
    for (int q = 0; q < ns && !t->gerr; q++) {
        ll[q] = lf0 + (lf1 - lf0) * q / (ns - 1);
        rr[q] = INFINITY;
        if (fabs(ll[q]) >= 0.005)
            ratio_at(j, v, ll[q], t, &rr[q]);
        if (rr[q] < bestr)
            bestr = rr[q], bi = q;
    }
    j->spp = full_spp;
    *ns_out = ns;
    return bi;
}

/* The vertex of the parabola through the best grid point and its
 * neighbours (the grid point itself when that is not a minimum). */
static double grid_vertex(const double *ll, const double *rr, int bi, int ns)
{
    double lbest = ll[bi];
    if (bi > 0 && bi < ns - 1 && isfinite(rr[bi - 1]) && isfinite(rr[bi + 1])) {
        double den = rr[bi - 1] - 2 * rr[bi] + rr[bi + 1];
        if (den > 0) {
            double t = 0.5 * (rr[bi - 1] - rr[bi + 1]) / den;
            if (t > -1 && t < 1)
                lbest += t * (ll[1] - ll[0]);
        }
    }
    return fabs(lbest) < 0.005 ? ll[bi] : lbest;
}

/* A search's second stage, at the full sample count: lbest and half a grid
 * step h either side, then the parabola's vertex (kept unless clearly
 * worse).  Returns the best log factor, its ratio in *rfull. */
static double refine_full_count(compare_job *j, const lf_grade_variant *v, subject *t, double lbest, double h,
                                double *rfull)
{
    double rl[3];
    for (int q = 0; q < 3 && !t->gerr; q++) {
        rl[q] = INFINITY;
        if (fabs(lbest + (q - 1) * h) >= 0.005)
            ratio_at(j, v, lbest + (q - 1) * h, t, &rl[q]);
    }
    double lfine = lbest;
    *rfull = rl[1];
    if (rl[0] < *rfull)
        *rfull = rl[0], lfine = lbest - h;
    if (rl[2] < *rfull)
        *rfull = rl[2], lfine = lbest + h;
    double den = rl[0] - 2 * rl[1] + rl[2];
    if (isfinite(den) && den > 0) {
        double s = 0.5 * (rl[0] - rl[2]) / den, r2;
        if (s > -1 && s < 1 && fabs(lbest + s * h) >= 0.005 && !t->gerr && !ratio_at(j, v, lbest + s * h, t, &r2) &&
            r2 <= *rfull * 1.1)
            *rfull = fmin(r2, *rfull), lfine = lbest + s * h;
    }
    return lfine;
}

/* The fraction of an 8-bit image clipped at white in every colour channel. */
static double clipped_fraction(const lf_image *x)
{
    size_t np = (size_t)x->width * x->height, nc = 0;
    for (size_t i = 0; i < np; i++) {
        const float *px = x->data + i * (size_t)x->channels;
        int all = 1;
        for (int ch = 0; ch < x->channels && ch < 3; ch++)
            all &= px[ch] >= 0.999f;
        nc += (size_t)all;
    }
    return np ? (double)nc / (double)np : 0;
}

/* The verdict on a failed comparison: the known mistake that matches best,
 * what the searches measured.  The diagnosis comes first in the reason and
 * only what supports it follows; fits against the correct reference are
 * listed only when nothing accounts for the image (they would contradict a
 * right diagnosis: a pinhole's image fits no focus distance). */
typedef struct diagnosis {
    const lf_grade_variant *best;
    char best_reason[600], best_measure[420], found[900];
    size_t nfound;
    double clipped;
    /* the best fixed variant at a fitted exposure: gain_variant x gain
     * matches at gain_ratio (gain against the variant's own exposure) */
    const lf_grade_variant *gain_variant;
    double gain, gain_ratio;
    /* the correct reference at a fitted exposure: a uniform brightness error */
    double uniform_gain, uniform_ratio;
    /* the exposure of the named mistake over the correct one (1: as the reason says) */
    double exposure;
} diagnosis;

/* Fixed variants, each with its own two seeds (its noise can differ: a
 * pinhole is noisier), as given and at the exposure fitted to the image.
 * Returns the lowest ratio as given. */
static double match_fixed_variants(compare_job *j, subject *t, diagnosis *d)
{
    lf_grade_check_result *r = j->res;
    double fixed_ratio = INFINITY;
    d->gain_ratio = d->uniform_ratio = INFINITY;
    d->gain = d->uniform_gain = NAN;
    variant_ratio(j, NULL, t->x, t->eight_bit, t->a, t->why, sizeof t->why, &t->gerr, &d->uniform_gain,
                  &d->uniform_ratio);
    for (int k = 0; k < j->c->nvariants && !t->gerr; k++) {
        const lf_grade_variant *v = &j->c->variants[k];
        if (!v->search) {
            double g, rg;
            double rv = variant_ratio(j, v, t->x, t->eight_bit, t->a, t->why, sizeof t->why, &t->gerr, &g, &rg);
            if (rv < r->variant_ratio) {
                r->variant_ratio = rv, d->best = v, snprintf(d->best_reason, sizeof d->best_reason, "%s", v->reason);
                /* measured: the variant's exposure times the gain fitted against it */
                d->exposure = (v->brightness > 0 ? v->brightness : 1) * (isfinite(g) ? g : 1);
            }
            if (rg < d->gain_ratio)
                d->gain_ratio = rg, d->gain = g, d->gain_variant = v;
            fixed_ratio = fmin(fixed_ratio, rv);
        }
    }
    return fixed_ratio;
}

/* What a search's ratio at its best value means. */
static const char *search_meaning(double ratio, double max_ratio)
{
    return ratio <= max_ratio ? "accounts for the image" : "does not account for the image";
}

/* Searches (a scene value scaled over a range: any focus error, aperture,
 * sensor size or shutter): each located on a grid, refined, and named
 * unless a fixed variant already explains the image or it is clipped. */
static void search_variants(compare_job *j, subject *t, diagnosis *d, int named_ok, double max_ratio)
{
    lf_grade_check_result *r = j->res;
    for (int k = 0; k < j->c->nvariants && !t->gerr && j->make == make_render; k++) {
        const lf_grade_variant *v = &j->c->variants[k];
        if (!v->search)
            continue;
        double rr[MAX_SEARCH_STEPS], ll[MAX_SEARCH_STEPS], rfull;
        int ns, bi = search_grid(j, v, t, ll, rr, &ns);
        if (bi < 0 || t->gerr)
            continue;
        double lbest = refine_full_count(j, v, t, grid_vertex(ll, rr, bi, ns), 0.5 * (ll[1] - ll[0]), &rfull);
        char m[400] = "";
        if (v->measure[0] && d->nfound + 8 < sizeof d->found) {
            search_text(v, v->measure, exp(lbest), m, sizeof m);
            d->nfound += (size_t)snprintf(d->found + d->nfound, sizeof d->found - d->nfound,
                                          "; %s (there: %.1fx the Monte Carlo noise level, %s)", m, rfull,
                                          search_meaning(rfull, max_ratio));
            if (d->nfound >= sizeof d->found)
                d->nfound = sizeof d->found - 1;
        }
        if (named_ok && rfull < r->variant_ratio) {
            r->variant_ratio = rfull, d->best = v, d->exposure = 1;
            search_text(v, v->reason, exp(lbest), d->best_reason, sizeof d->best_reason);
            snprintf(d->best_measure, sizeof d->best_measure, "%s", m);
        }
    }
}

/* The fraction of clipped pixels above which an 8-bit image is only "too bright". */
#define SATURATED 0.95

/* A lower bound of the exposure factor of an image clipped at white: every
 * clipped value k a >= 1, so k >= 1 / a (a the reference, values a visible
 * pixel would hold). */
static double saturation_bound(const lf_image *x, const lf_image *a)
{
    double amin = INFINITY;
    size_t n = (size_t)x->width * x->height * (size_t)x->channels;
    for (size_t i = 0; i < n; i++)
        if (x->data[i] >= 0.999f && a->data[i] > 1.0f / 255)
            amin = fmin(amin, a->data[i]);
    return isfinite(amin) && amin > 0 ? 1 / amin : 1;
}

/* "14.1x too bright" / "2.0x too dark" / "4% too bright" (near 1) */
static void brightness_words(double k, char *out, size_t n)
{
    if (k > 0.75 && k < 1.5)
        snprintf(out, n, "%.0f%% too %s", 100 * fabs(k - 1), k >= 1 ? "bright" : "dark");
    else if (k >= 1)
        snprintf(out, n, "%.1fx too bright", k);
    else
        snprintf(out, n, "%.1fx too dark", 1 / k);
}

/* What the noise ratio of the image against the correct reference means. */
static void noise_words(double ratio, double max_ratio, int spp, char *out, size_t n)
{
    snprintf(out, n, "%.1fx the Monte Carlo noise level of the reference at %d spp: %s; pass <= %.1fx", ratio, spp,
             ratio <= max_ratio ? "within the noise" : "a real difference, not noise", max_ratio);
}

/* The failure's reason: the diagnosis first (a known mistake, a uniform
 * exposure error, a known mistake at another exposure), then what supports
 * it; or, when nothing accounts for the image, every measurement. */
static void report_failure(compare_job *j, const sub_image *im, const lf_image *a, diagnosis *d, double max_ratio)
{
    lf_grade_check_result *r = j->res;
    char noise[200], bw[64], clip[200] = "";
    noise_words(r->noise_ratio, max_ratio, j->spp, noise, sizeof noise);
    if (d->clipped > 0.2)
        snprintf(clip, sizeof clip,
                 "; %.0f%% of the pixels clipped at white (over-exposed: the mean brightness there is only a lower "
                 "bound)",
                 100 * d->clipped);
    if (d->clipped >= SATURATED) {
        double bright = lf_grade_mean(&im->img) / fmax(lf_grade_mean(a), 1e-12);
        snprintf(r->measurements, sizeof r->measurements, "mean brightness %.2fx the reference%s", bright, clip);
        snprintf(r->best_variant, sizeof r->best_variant, "over-exposed");
        brightness_words(saturation_bound(&im->img, a), bw, sizeof bw);
        fail(r, "%s: over-exposed: %.0f%% of the pixels clipped at white, at least %s: check the ray weight and the "
                "exposure (a white image shows nothing else; against the correct reference: %s); measured: %s",
             im->file, 100 * d->clipped, bw, noise, r->measurements);
        return;
    }
    int named = d->best && r->variant_ratio <= max_ratio && r->variant_ratio < r->noise_ratio;
    int uniform = !named && d->uniform_ratio <= max_ratio && isfinite(d->uniform_gain);
    int gained = !named && !uniform && d->gain_variant && d->gain_ratio <= max_ratio;
    if (named || uniform || gained) {
        size_t k = 0;
        double bright = lf_grade_mean(&im->img) / fmax(lf_grade_mean(a), 1e-12);
        appendf(r->measurements, sizeof r->measurements, &k, "mean brightness %.2fx the reference%s", bright, clip);
        if (named && d->best_measure[0])
            appendf(r->measurements, sizeof r->measurements, &k, "; %s", d->best_measure);
    } else {
        measure(j, &im->img, a, r->measurements, sizeof r->measurements);
        size_t l = strlen(r->measurements);
        snprintf(r->measurements + l, sizeof r->measurements - l, "%s%s", clip, d->found);
    }
    if (named) {
        snprintf(r->best_variant, sizeof r->best_variant, "%s", d->best->name);
        char extra[160] = "";
        if (fabs(log(d->exposure)) > log(1.1)) {
            brightness_words(d->exposure, bw, sizeof bw);
            snprintf(extra, sizeof extra, "; %s: check the ray weight and the exposure", bw);
        }
        fail(r, "%s: %s%s (the image matches the reference for that mistake at %.2fx the Monte Carlo noise level; "
                "against the correct reference: %s); measured: %s",
             im->file, d->best_reason, extra, r->variant_ratio, noise, r->measurements);
    } else if (uniform) {
        snprintf(r->best_variant, sizeof r->best_variant, "exposure");
        r->variant_ratio = d->uniform_ratio;
        brightness_words(d->uniform_gain, bw, sizeof bw);
        fail(r, "%s: uniformly %s: check the ray weight and the exposure (scaled by %.3g, the image matches the "
                "reference at %.2fx the Monte Carlo noise level; as it is: %s); measured: %s",
             im->file, bw, 1 / d->uniform_gain, d->uniform_ratio, noise, r->measurements);
    } else if (gained) {
        const lf_grade_variant *v = d->gain_variant;
        snprintf(r->best_variant, sizeof r->best_variant, "%s", v->name);
        r->variant_ratio = d->gain_ratio;
        brightness_words(d->gain * (v->brightness > 0 ? v->brightness : 1), bw, sizeof bw);
        fail(r, "%s: %s; and %s: check the ray weight and the exposure (at that exposure the image matches the "
                "reference for that mistake at %.2fx the Monte Carlo noise level; against the correct reference: "
                "%s); measured: %s",
             im->file, v->reason, bw, d->gain_ratio, noise, r->measurements);
    } else
        fail(r, "%s differs from the reference: %s; unrecognised mistake, measured: %s%s", im->file, noise,
             r->measurements, d->best ? " (no known mistake accounts for it)" : "");
}

/* The scores of x against the correct reference a (b: its second seed),
 * and the report's pictures. */
static void score(compare_job *j, const lf_image *x, const lf_image *a, const lf_image *b)
{
    lf_grade_check_result *r = j->res;
    r->noise_ratio = lf_grade_noise_ratio(x, a, a, b);
    r->ssim = lf_grade_ssim(x, a);
    r->ssim_noise = lf_grade_ssim(b, a);
    lf_image_psnr(x, a, &r->psnr_db, NULL);
    if (j->student_dir) {
        lf_image heat;
        write_png(j->student_dir, j->c->id, "submission", x);
        write_png(j->student_dir, j->c->id, "reference", a);
        if (!lf_grade_heatmap(x, a, b, &heat)) {
            write_png(j->student_dir, j->c->id, "diff", &heat);
            lf_image_free(&heat);
        }
    }
}

/* Returns 0, or -2 on a grader-side failure (err filled).  A submission
 * beyond the noise level goes on to the diagnosis: which known mistake
 * accounts for it? */
static int compare(compare_job *j, submission *s, lf_error *err)
{
    lf_grade_check_result *r = j->res;
    subject t = {0};
    lf_image a = {0}, b = {0};
    /* the submission's image first: a missing or unreadable one costs no
     * reference (issue 32: references were rendered before looking) */
    sub_image *early = find_image(s, lf_grade_check_get(j->c, "image", j->c->id));
    if (!early || early->state < 0) {
        fail(r, "%s", early ? early->why : "too many images");
        return 0;
    }
    int rc = j->make(j, NULL, 0, &a, t.why, sizeof t.why);
    if (!rc)
        rc = j->make(j, NULL, 1, &b, t.why, sizeof t.why);
    if (rc) {
        lf_image_free(&a), lf_image_free(&b);
        if (rc == -2)
            return lf_error_set(err, LF_ERR_INTERNAL, "check %s: %s", j->c->id, t.why);
        fail(r, "%s", t.why);
        return 0;
    }
    sub_image *im = get_image(s, lf_grade_check_get(j->c, "image", j->c->id), a.width, a.height, t.why, sizeof t.why);
    if (!im) {
        fail(r, "%s", t.why);
        lf_image_free(&a), lf_image_free(&b);
        return 0;
    }
    t.x = &im->img, t.a = &a, t.eight_bit = !strcmp(im->format, "png");
    if (t.eight_bit)
        lf_grade_quantize8(&a), lf_grade_quantize8(&b);
    double max_ratio = atof(lf_grade_check_get(j->c, "max_ratio", "3"));
    score(j, &im->img, &a, &b);
    if (r->noise_ratio > max_ratio) {
        diagnosis d = {0};
        r->variant_ratio = INFINITY;
        d.gain_ratio = d.uniform_ratio = INFINITY;
        /* an 8-bit image clipped at white over much of its area: any larger
         * exposure explains the clipped part, so no search is named; one
         * white almost everywhere says nothing but "too bright" */
        d.clipped = t.eight_bit ? clipped_fraction(&im->img) : 0;
        if (d.clipped < SATURATED) {
            double fixed_ratio = match_fixed_variants(j, &t, &d);
            int fixed_ok = fixed_ratio <= max_ratio && fixed_ratio < r->noise_ratio;
            int gain_ok = d.gain_ratio <= max_ratio && !(d.uniform_ratio <= max_ratio);
            /* a fixed mistake that accounts for the image (at some exposure)
             * ends the diagnosis: searches would only add contradicting fits */
            if (!fixed_ok && !gain_ok)
                search_variants(j, &t, &d, d.clipped <= 0.2, max_ratio);
        }
        if (t.gerr)
            rc = lf_error_set(err, LF_ERR_INTERNAL, "check %s: %s", j->c->id, t.why);
        else
            report_failure(j, im, &a, &d, max_ratio);
    }
    lf_image_free(&a), lf_image_free(&b);
    return rc;
}

/* ---------- focus of a refocused plenoptic image, region by region ---------- */

typedef struct focus_subject {
    char name[64];
    double depth;
    int x0, y0, x1, y1;
} focus_subject;

/* subjects='near card@0.3:7,27,28,57;...' (view pixels, x1 y1 exclusive) */
static int parse_subjects(const char *spec, focus_subject *sj, int max, char *why, size_t wn)
{
    int n = 0;
    const char *p = spec;
    while (*p && n < max) {
        const char *end = strchr(p, ';');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char item[200];
        if (len >= sizeof item) {
            snprintf(why, wn, "grader: subject too long in '%s'", spec);
            return -1;
        }
        memcpy(item, p, len), item[len] = 0;
        char *at = strchr(item, '@');
        focus_subject *f = &sj[n];
        if (!at || sscanf(at + 1, "%lf:%d,%d,%d,%d", &f->depth, &f->x0, &f->y0, &f->x1, &f->y1) != 5 ||
            !(f->depth > 0) || f->x1 <= f->x0 + 2 || f->y1 <= f->y0 + 2) {
            snprintf(why, wn, "grader: subject '%s': expected NAME@DEPTH:X0,Y0,X1,Y1", item);
            return -1;
        }
        *at = 0;
        snprintf(f->name, sizeof f->name, "%.63s", item);
        n++;
        p += len;
        if (*p == ';')
            p++;
    }
    if (n == 0)
        snprintf(why, wn, "grader: no subjects in '%s'", spec);
    return n ? n : -1;
}

static double depth_of_disparity(const lf_lightfield *lf, double d)
{
    double den = d - lf->disp_at_inf;
    return lf->disp_per_inv_m != 0 && den * lf->disp_per_inv_m > 0 ? lf->disp_per_inv_m / den : INFINITY;
}

/* A focus check's state: its subjects, the depth asked and the reference
 * capture; from the sweep, where the submission looks focused. */
typedef struct focus_check {
    focus_subject sj[8];
    int ns, target;           /* target: the subject nearest the asked depth */
    double want, d_want;      /* the asked depth (m) and its disparity (px/view) */
    lf_lightfield lf;         /* the reference capture, decoded */
    const sub_image *im;
    int eight_bit;
    double best_d;            /* the sweep's best match (px/view) */
    double best_sweep[8];     /* its sharpness, subject by subject */
} focus_check;

/* The reference plenoptic capture (raw and its attributes), decoded into lf. */
static int decode_reference(const lf_grade_check *c, const lf_image *raw, const lf_attrs *meta, lf_lightfield *lf,
                            lf_error *err)
{
    lf_lightfield_layout file, flags, lay;
    lf_lightfield_layout_init(&flags);
    lf_error e = {0};
    if (lf_lightfield_layout_from_attrs(meta, &file, &e) ||
        lf_lightfield_layout_resolve(&file, &flags, raw->width, raw->height, &lay, &e) ||
        lf_lightfield_decode(raw, &lay, NULL, lf, &e)) {
        lf_lightfield_free(lf);
        return lf_error_set(err, LF_ERR_INTERNAL, "check %s: reference light field: %s", c->id, e.msg);
    }
    return 0;
}

/* The reference refocused as asked (ref), and a sweep over the subjects'
 * disparities: the step whose per-region sharpness matches the submission
 * best, refined between steps by a parabola, goes in f->best_d. */
static int focus_sweep(focus_check *f, int threads, lf_image *ref, lf_error *e)
{
    const focus_subject *sj = f->sj;
    double dmin = f->d_want, dmax = f->d_want;
    for (int k = 0; k < f->ns; k++) {
        double d;
        if (!lf_lightfield_depth_to_disparity(&f->lf, sj[k].depth, &d, e))
            dmin = fmin(dmin, d), dmax = fmax(dmax, d);
    }
    dmin -= 0.5, dmax += 0.5;
    enum { NSWEEP = 41 };
    double best_err = INFINITY, errs[NSWEEP + 1];
    int best_q = -1;
    lf_lightfield_refocus_opts ro = lf_lightfield_refocus_defaults();
    ro.threads = threads > 0 ? threads : 2;
    ro.disparity_px = f->d_want;
    f->best_d = 0;
    int rc = lf_lightfield_refocus(&f->lf, &ro, ref, e);
    for (int q = 0; !rc && q <= NSWEEP; q++) {
        lf_image sw = {0};
        /* the sweep, plus exactly zero (the unrefocused image) as the last step */
        ro.disparity_px = q < NSWEEP ? dmin + (dmax - dmin) * q / (NSWEEP - 1) : 0.0;
        if ((rc = lf_lightfield_refocus(&f->lf, &ro, &sw, e)))
            break;
        if (f->eight_bit)
            lf_grade_quantize8(&sw);
        double sum = 0, v[8];
        for (int k = 0; k < f->ns; k++) {
            v[k] = lf_grade_sharpness(&sw, sj[k].x0, sj[k].y0, sj[k].x1, sj[k].y1);
            double a = lf_grade_sharpness(&f->im->img, sj[k].x0, sj[k].y0, sj[k].x1, sj[k].y1);
            double l = log((a + 1e-9) / (v[k] + 1e-9));
            sum += l * l;
        }
        errs[q] = sum;
        if (sum < best_err - 1e-12)
            best_err = sum, f->best_d = ro.disparity_px, best_q = q, memcpy(f->best_sweep, v, sizeof v);
        lf_image_free(&sw);
    }
    if (rc)
        return rc;
    /* between sweep steps: the vertex of the parabola through the best and its neighbours */
    if (best_q > 0 && best_q < NSWEEP - 1 && fabs(f->best_d) > 1e-12) {
        double em = errs[best_q - 1], e0 = errs[best_q], ep = errs[best_q + 1], den = em - 2 * e0 + ep;
        if (den > 0) {
            double t = 0.5 * (em - ep) / den;
            if (t > -1 && t < 1)
                f->best_d += t * (dmax - dmin) / (NSWEEP - 1);
        }
    }
    return 0;
}

/* The verdict against the reference refocused as asked (ref): sharpness
 * region by region, the depth the image looks focused at, brightness. */
static void focus_verdict(const focus_check *f, const lf_grade_check *c, lf_image *ref, lf_grade_check_result *r)
{
    double min_sharp = atof(lf_grade_check_get(c, "min_sharpness", "0.6"));
    double max_sharp = atof(lf_grade_check_get(c, "max_sharpness", "1.8"));
    double max_bright = atof(lf_grade_check_get(c, "max_brightness", "1.2"));
    double focus_tol = atof(lf_grade_check_get(c, "focus_tol", "0.1")); /* px/view */
    const focus_subject *sj = f->sj;
    const lf_image *x = &f->im->img;
    double ref_sharp[8], sub_sharp[8], best_d = f->best_d, want = f->want, d_want = f->d_want;
    if (f->eight_bit)
        lf_grade_quantize8(ref);
    for (int k = 0; k < f->ns; k++) {
        ref_sharp[k] = lf_grade_sharpness(ref, sj[k].x0, sj[k].y0, sj[k].x1, sj[k].y1);
        sub_sharp[k] = lf_grade_sharpness(x, sj[k].x0, sj[k].y0, sj[k].x1, sj[k].y1);
    }
    lf_image_psnr(x, ref, &r->psnr_db, NULL);
    r->ssim = lf_grade_ssim(x, ref);
    double bright = lf_grade_mean(x) / fmax(lf_grade_mean(ref), 1e-12);
    double z_est = depth_of_disparity(&f->lf, best_d);
    char looks[300], ztxt[48];
    if (isinf(z_est))
        snprintf(ztxt, sizeof ztxt, "beyond infinity");
    else
        snprintf(ztxt, sizeof ztxt, "%.3g m", z_est);
    snprintf(looks, sizeof looks, "the image looks focused at %s (disparity %.2f px/view%s; asked: %g m, %.2f px/view)",
             ztxt, best_d, fabs(best_d) < 1e-9 ? ": not refocused, the plain average of the views" : "", want, d_want);
    /* the measurements, for the report */
    char meas[600];
    int n = snprintf(meas, sizeof meas, "sharpness against the reference:");
    for (int k = 0; k < f->ns && n < (int)sizeof meas; k++)
        n += snprintf(meas + n, sizeof meas - (size_t)n, "%s %s %.2fx", k ? "," : "", sj[k].name,
                      sub_sharp[k] / fmax(ref_sharp[k], 1e-12));
    if (n < (int)sizeof meas)
        snprintf(meas + n, sizeof meas - (size_t)n, "; brightness %.2fx", bright);
    int target = f->target;
    r->noise_ratio = NAN;
    r->variant_ratio = sub_sharp[target] / fmax(ref_sharp[target], 1e-12);
    snprintf(r->best_variant, sizeof r->best_variant, "focus %.3g m", z_est);
    double ratio_t = r->variant_ratio;
    /* how far the best full-aperture refocus is from the submission, region by region */
    int worst = 0;
    double worst_ratio = 1;
    for (int k = 0; k < f->ns; k++) {
        double q = (sub_sharp[k] + 1e-9) / (f->best_sweep[k] + 1e-9);
        if (q > worst_ratio)
            worst_ratio = q, worst = k;
    }
    const char *file = f->im->file;
    if (worst_ratio > max_sharp) {
        fail(r, "%s: the %s at %g m is %.2fx sharper than any full-aperture refocus leaves it (the closest, focused at "
                "%s, pass <= %.2fx): more depth of field than asked (a smaller --aperture or a single view?); %s",
             file, sj[worst].name, sj[worst].depth, worst_ratio, ztxt, max_sharp, meas);
    } else if (ratio_t < min_sharp) {
        fail(r, "%s: the %s at %g m is not in focus: sharpness %.2fx the reference (pass >= %.2fx); %s; %s", file,
             sj[target].name, sj[target].depth, ratio_t, min_sharp, looks, meas);
    } else if (fabs(best_d - d_want) > focus_tol) {
        fail(r, "%s: focused near but not at the %s: %s; the focus is off by %+.2f px/view (pass within %.2f), %+.0f%% "
                "in depth; %s",
             file, sj[target].name, looks, best_d - d_want, focus_tol, 100.0 * (z_est / want - 1.0), meas);
    } else if (!(bright <= max_bright && bright >= 1 / max_bright)) {
        fail(r, "%s: brightness %.2fx the reference (pass within %.2fx); %s", file, bright, max_bright, meas);
    }
    snprintf(r->measurements, sizeof r->measurements, "%s; %s", meas, looks);
}

/* kind focus (docs/grading.md): the submitted image must be the reference
 * plenoptic capture refocused at `depth`: the subject at that depth as sharp
 * as in the reference refocused there (>= min_sharpness of it), the others
 * no sharper than max_sharpness of theirs (a full aperture), the brightness
 * within max_brightness.  Failing, the reason gives the measurements and the
 * depth the image looks focused at (the refocus sweep of the reference whose
 * per-region sharpness matches best). */
static int run_focus(lf_grade_ctx *g, const lf_grade_check *c, submission *s, lf_grade_check_result *r, lf_error *err)
{
    focus_check f;
    memset(&f, 0, sizeof f);
    char why[700];
    f.ns = parse_subjects(lf_grade_check_get(c, "subjects", ""), f.sj, 8, why, sizeof why);
    if (f.ns < 0)
        return lf_error_set(err, LF_ERR_PARSE, "check %s: %s", c->id, why);
    f.want = atof(lf_grade_check_get(c, "depth", "0"));
    int spp = atoi(lf_grade_check_get(c, "spp", "8")), rc;
    uint32_t seed = (uint32_t)strtoul(lf_grade_check_get(c, "seed", "1000"), NULL, 10);
    sub_image *early = find_image(s, lf_grade_check_get(c, "image", c->id));
    if (!early || early->state < 0) { /* no image, no reference to compute */
        fail(r, "%s", early ? early->why : "too many images");
        return 0;
    }
    const lf_image *raw;
    const lf_attrs *meta;
    if (reference(g, lf_grade_check_get(c, "scene", ""), NULL, spp, seed, &raw, &meta, err))
        return lf_error_set(err, err->code, "check %s: reference light field: %s", c->id, err->msg);
    if ((rc = decode_reference(c, raw, meta, &f.lf, err)))
        return rc;
    lf_error e = {0};
    if (lf_lightfield_depth_to_disparity(&f.lf, f.want, &f.d_want, &e)) {
        lf_lightfield_free(&f.lf);
        return lf_error_set(err, LF_ERR_INTERNAL, "check %s: depth=%g: %s", c->id, f.want, e.msg);
    }
    for (int k = 1; k < f.ns; k++)
        if (fabs(f.sj[k].depth - f.want) < fabs(f.sj[f.target].depth - f.want))
            f.target = k;
    sub_image *im = get_image(s, lf_grade_check_get(c, "image", c->id), f.lf.ns, f.lf.nt, why, sizeof why);
    if (!im) {
        fail(r, "%s", why);
        lf_lightfield_free(&f.lf);
        return 0;
    }
    f.im = im, f.eight_bit = !strcmp(im->format, "png");
    lf_image ref = {0};
    if (focus_sweep(&f, g->threads, &ref, &e)) {
        lf_image_free(&ref), lf_lightfield_free(&f.lf);
        return lf_error_set(err, LF_ERR_INTERNAL, "check %s: refocusing the reference: %s", c->id, e.msg);
    }
    focus_verdict(&f, c, &ref, r);
    lf_image_free(&ref), lf_lightfield_free(&f.lf);
    return 0;
}

/* ---------- checks ---------- */

/* One check being run: the rubric's check c on submission s (md: its
 * Submission.md, or NULL), the result r. */
typedef struct check_run {
    lf_grade_ctx *g;
    const lf_grade_check *c;
    submission *s;
    const char *md, *student_dir;
    lf_grade_check_result *r;
    lf_error *err;
} check_run;

/* kind files: the listed images readable, Submission.md present */
static int check_files(const check_run *k)
{
    char list[256], missing[900] = "";
    snprintf(list, sizeof list, "%s", lf_grade_check_get(k->c, "images", ""));
    if (!k->md)
        snprintf(missing, sizeof missing, "%s", k->s->md_why);
    for (char *t = strtok(list, ","); t; t = strtok(NULL, ",")) {
        sub_image *im = find_image(k->s, t);
        if (im && im->state < 0) {
            size_t l = strlen(missing);
            snprintf(missing + l, sizeof missing - l, "%s%s", l ? "; " : "", im->why);
        }
    }
    if (missing[0])
        fail(k->r, "%s", missing);
    return 0;
}

/* kind sections: Submission.md has the required "## " sections, not empty */
static int check_sections(const check_run *k)
{
    if (!k->md) {
        fail(k->r, "%s", k->s->md_why);
        return 0;
    }
    char list[256], bad[600] = "";
    snprintf(list, sizeof list, "%s", lf_grade_check_get(k->c, "require", ""));
    for (char *t = strtok(list, ","); t; t = strtok(NULL, ",")) {
        int body = section_body(k->md, t, NULL, NULL);
        if (body <= 0) {
            size_t l = strlen(bad);
            snprintf(bad + l, sizeof bad - l, "%s\"## %s\" %s", l ? "; " : "", t, body < 0 ? "missing" : "empty");
        }
    }
    if (bad[0])
        fail(k->r, "Submission.md: required sections: %s", bad);
    return 0;
}

/* kind size: an image of the given width and height */
static int check_size(const check_run *k)
{
    const lf_grade_check *c = k->c;
    int w = atoi(lf_grade_check_get(c, "width", "0")), h = atoi(lf_grade_check_get(c, "height", "0"));
    sub_image *im = find_image(k->s, lf_grade_check_get(c, "image", c->id));
    if (!im)
        fail(k->r, "too many images");
    else if (im->state < 0)
        fail(k->r, "%s", im->why);
    else if (im->w != w || im->h != h)
        fail(k->r, "%s: wrong size: %dx%d, expected %dx%d", im->file, im->w, im->h, w, h);
    return 0;
}

/* kind answer: "KEY = VALUE" in Submission.md, within tol of the value */
static int check_answer(const check_run *k)
{
    const lf_grade_check *c = k->c;
    lf_grade_check_result *r = k->r;
    const char *key = lf_grade_check_get(c, "key", "");
    double want = atof(lf_grade_check_get(c, "value", "0")), tol = atof(lf_grade_check_get(c, "tol", "0"));
    const char *at = k->md ? strstr(k->md, key) : NULL;
    if (!k->md) {
        fail(r, "%s", k->s->md_why);
        return 0;
    }
    if (!at || !key[0]) {
        fail(r, "Submission.md: no \"%s = VALUE\" answer", key);
        return 0;
    }
    at += strlen(key);
    while (*at == ' ' || *at == '=' || *at == ':' || *at == '*' || *at == '`')
        at++;
    char *end;
    double got = strtod(at, &end);
    if (end == at || !isfinite(got))
        fail(r, "Submission.md: %s has no number", key);
    else if (fabs(got - want) > tol)
        fail(r, "Submission.md: %s = %g, expected %g +- %g", key, got, want, tol);
    return 0;
}

/* kind constraint: a flag of the declared lftool command within bounds */
static int check_constraint(const check_run *k)
{
    const lf_grade_check *c = k->c;
    const char *cmd = lf_grade_check_get(c, "command", "synth"), *flag = lf_grade_check_get(c, "flag", "");
    declared decl;
    parse_declared(k->md, cmd, &decl);
    if (!decl.ok) {
        fail(k->r, "%s", decl.why);
        return 0;
    }
    double v = atof(lf_grade_check_get(c, "default", "0"));
    int have = declared_value(&decl, flag, &v);
    const char *gt = lf_grade_check_get(c, "gt", NULL), *lt = lf_grade_check_get(c, "lt", NULL);
    if ((gt && !(v > atof(gt))) || (lt && !(v < atof(lt))))
        fail(k->r, "%s (--%s is %g%s; required %s %s)", lf_grade_check_get(c, "reason", "constraint violated"), flag,
             v, have ? "" : ", the default", gt ? ">" : "<", gt ? gt : lt);
    return 0;
}

static int check_focus(const check_run *k)
{
    return run_focus(k->g, k->c, k->s, k->r, k->err);
}

/* The comparison of a check's image against its references. */
static void job_init(const check_run *k, compare_job *j)
{
    memset(j, 0, sizeof *j);
    j->g = k->g, j->c = k->c, j->res = k->r, j->student_dir = k->student_dir;
    j->spp = atoi(lf_grade_check_get(k->c, "spp", "16"));
    j->seed = (uint32_t)strtoul(lf_grade_check_get(k->c, "seed", "1000"), NULL, 10);
}

/* kind render: the image against reference renders of the scene */
static int check_render(const check_run *k)
{
    compare_job j;
    job_init(k, &j);
    j.make = make_render;
    return compare(&j, k->s, k->err);
}

/* Grading costs what the assignment's own settings cost (issue 32): the
 * declared synth's samples (width x height x spp) are held to the check's
 * max_work (default 2^20, a little over twice the handout's 96 x 72 x 64).
 * More samples per pixel than that allows are re-run with fewer: a student's
 * image with less noise than the reference still matches it.  An output size
 * other than the image's, or one with more pixels than max_work, fails here
 * before any reference is computed.  1 when the check failed. */
static int declared_over_budget(const lf_grade_check *c, submission *s, declared *d, lf_grade_check_result *r)
{
    double max_work = atof(lf_grade_check_get(c, "max_work", "1048576"));
    sub_image *im = find_image(s, lf_grade_check_get(c, "image", c->id));
    if (!im || im->state < 0) {
        fail(r, "%s", im ? im->why : "too many images");
        return 1;
    }
    if (!d->have_outdim)
        return 0;
    if (im->state > 0 && (im->w != d->synth.width || im->h != d->synth.height)) {
        fail(r, "%s: wrong size: %dx%d, but the declared --outputdim is %d %d (not compared)", im->file, im->w,
             im->h, d->synth.width, d->synth.height);
        return 1;
    }
    double pixels = (double)d->synth.width * d->synth.height;
    if (pixels > max_work) {
        fail(r, "the declared --outputdim %d %d is more than this check grades (%.0f pixels x samples at most); "
                "use the handout's settings", d->synth.width, d->synth.height, max_work);
        return 1;
    }
    if (pixels * d->synth.spp > max_work)
        d->synth.spp = (int)(max_work / pixels);
    return 0;
}

/* kinds synth and refocus: the image against the declared lftool command
 * re-run on the reference light field */
static int check_lightfield(const check_run *k)
{
    const lf_grade_check *c = k->c;
    int refocus = !strcmp(c->kind, "refocus");
    if (lf_grade_check_get(c, "optional", NULL)) {
        sub_image *im = find_image(k->s, lf_grade_check_get(c, "image", c->id));
        if (im && im->state < 0 && strstr(im->why, "missing:")) {
            fail(k->r, "optional part not submitted");
            return 0;
        }
    }
    compare_job j;
    job_init(k, &j);
    parse_declared(k->md, refocus ? "refocus" : "synth", &j.decl);
    if (!j.decl.ok) {
        fail(k->r, "%s", j.decl.why);
        return 0;
    }
    if (!refocus && declared_over_budget(c, k->s, &j.decl, k->r))
        return 0;
    j.make = refocus ? make_refocus : make_synth;
    return compare(&j, k->s, k->err);
}

static const struct {
    const char *kind;
    int (*run)(const check_run *k);
} check_kinds[] = {
    {"files", check_files},   {"sections", check_sections}, {"size", check_size},
    {"answer", check_answer}, {"constraint", check_constraint}, {"focus", check_focus},
    {"render", check_render}, {"synth", check_lightfield}, {"refocus", check_lightfield},
};

static int run_check(lf_grade_ctx *g, const lf_grade_check *c, submission *s, lf_grade_check_result *r,
                     const char *student_dir, lf_error *err)
{
    memset(r, 0, sizeof *r);
    snprintf(r->id, sizeof r->id, "%s", c->id);
    snprintf(r->kind, sizeof r->kind, "%s", c->kind);
    r->points = r->earned = c->points;
    r->status = LF_GRADE_PASS;
    r->noise_ratio = r->ssim = r->ssim_noise = r->psnr_db = r->variant_ratio = NAN;
    check_run k = {g, c, s, get_md(s), student_dir, r, err};
    for (size_t i = 0; i < sizeof check_kinds / sizeof check_kinds[0]; i++)
        if (!strcmp(c->kind, check_kinds[i].kind))
            return check_kinds[i].run(&k);
    return lf_error_set(err, LF_ERR_INTERNAL, "check %s: kind %s not implemented", c->id, c->kind);
}

static void student_name(const char *dir, char *out, size_t n)
{
    char tmp[1024];
    snprintf(tmp, sizeof tmp, "%s", dir);
    size_t l = strlen(tmp);
    while (l > 1 && tmp[l - 1] == '/')
        tmp[--l] = 0;
    const char *b = strrchr(tmp, '/');
    b = b ? b + 1 : tmp;
    size_t k = 0;
    for (; *b && k + 1 < n; b++)
        out[k++] = (isalnum((unsigned char)*b) || *b == '-' || *b == '_' || *b == '.') ? *b : '_';
    out[k] = 0;
    if (!k || out[0] == '.')
        snprintf(out, n, "submission");
}

/* The student's name made unique within the run (a/alice and b/alice are
 * alice and alice-2) and never the grade book's own files, so no report
 * overwrites another nor the grade book.  0, or -1 out of memory. */
static int unique_student(lf_grade_ctx *g, char *name, size_t n)
{
    char base[sizeof ((lf_grade_result *)0)->student];
    snprintf(base, sizeof base, "%s", name);
    for (int k = 1;; k++) {
        if (k > 1)
            snprintf(name, n, "%.*s-%d", (int)(n - 12), base, k);
        int taken = !strcasecmp(name, "gradebook.csv") || !strcasecmp(name, "gradebook.json");
        for (int i = 0; i < g->nstudents && !taken; i++)
            taken = !strcmp(g->students[i], name);
        if (!taken)
            break;
    }
    char **grown = realloc(g->students, (size_t)(g->nstudents + 1) * sizeof *grown);
    if (!grown)
        return -1;
    g->students = grown;
    if (!(g->students[g->nstudents] = strdup(name)))
        return -1;
    g->nstudents++;
    return 0;
}

int lf_grade_submission(lf_grade_ctx *g, const char *submission_dir, lf_grade_result *res, lf_error *err)
{
    memset(res, 0, sizeof *res);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    student_name(submission_dir, res->student, sizeof res->student);
    if (unique_student(g, res->student, sizeof res->student))
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    snprintf(res->path, sizeof res->path, "%s", submission_dir);
    res->checks = calloc((size_t)g->rubric.nchecks, sizeof *res->checks);
    if (!res->checks)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    res->nchecks = g->rubric.nchecks;
    /* the student's report is built beside its folder and moved into place
     * (base/lf_file_write.h): a full disk leaves no half-written report */
    char sdir[1400], stage[PATH_MAX], *student_dir = NULL;
    if (g->report[0]) {
        snprintf(sdir, sizeof sdir, "%s/%s", g->report, res->student);
        if (mkdirs(g->report))
            return lf_error_set(err, LF_ERR_IO, "%s: cannot create: %s", g->report, strerror(errno));
        if (lf_dir_stage_begin(sdir, stage, sizeof stage, err))
            return err->code;
        student_dir = stage;
    }
    submission s;
    memset(&s, 0, sizeof s);
    s.dir = submission_dir;
    struct stat st;
    int rc = 0;
    int no_dir = stat(submission_dir, &st) || !S_ISDIR(st.st_mode);
    for (int i = 0; i < g->rubric.nchecks && !rc; i++) {
        lf_grade_check_result *r = &res->checks[i];
        if (no_dir) {
            memset(r, 0, sizeof *r);
            snprintf(r->id, sizeof r->id, "%s", g->rubric.checks[i].id);
            snprintf(r->kind, sizeof r->kind, "%s", g->rubric.checks[i].kind);
            r->points = g->rubric.checks[i].points;
            r->noise_ratio = r->ssim = r->ssim_noise = r->psnr_db = r->variant_ratio = NAN;
            fail(r, "%s: not a folder", submission_dir);
        } else {
            rc = run_check(g, &g->rubric.checks[i], &s, r, student_dir, err);
        }
        res->max += r->points;
        res->score += r->earned;
    }
    free_submission(&s);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    res->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (!rc && student_dir)
        rc = lf_grade_report_student(student_dir, g->rubric.title, res, err);
    if (student_dir && rc)
        lf_dir_stage_abort(stage);
    else if (student_dir)
        rc = lf_dir_stage_commit(stage, sdir, err);
    return rc;
}
