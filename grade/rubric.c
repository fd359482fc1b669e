/* rubric.c - assignments/<name>/rubric.txt, one directive per line:
 *
 *   assignment NAME
 *   title TEXT
 *   check ID POINTS KIND key=value ...
 *   variant CHECK_ID NAME reason='...' [replace='...' with='...']... [post=OP] [set=key:value,...]
 *
 * Values may be quoted with '...' or "..." (no escapes).  Kinds and keys:
 * docs/grading.md. */
#include <ctype.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "grade_internal.h"

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

int lf_grade_find_assignment(const char *a, char *out, size_t n, lf_error *err)
{
    char rubric[PATH_MAX + 16];
    snprintf(rubric, sizeof rubric, "%s/rubric.txt", a);
    if (is_dir(a) && access(rubric, R_OK) == 0 && snprintf(out, n, "%s", a) < (int)n)
        return LF_OK;
    if (snprintf(out, n, "assignments/%s", a) < (int)n && is_dir(out))
        return LF_OK;
    char exe[PATH_MAX];
    ssize_t l = readlink("/proc/self/exe", exe, sizeof exe - 1);
    char *slash = NULL;
    if (l > 0) {
        exe[l] = 0;
        slash = strrchr(exe, '/');
    }
    if (slash) {
        *slash = 0;
        /* the source tree (build/bin/../../assignments), then an install
         * (PREFIX/bin/../share/lensfield/assignments, CMakeLists.txt) */
        if (snprintf(out, n, "%s/../../assignments/%s", exe, a) < (int)n && is_dir(out))
            return LF_OK;
        if (snprintf(out, n, "%s/../share/lensfield/assignments/%s", exe, a) < (int)n && is_dir(out))
            return LF_OK;
    }
    return lf_error_set(err, LF_ERR_PARAM,
                        "%s: no such assignment (a folder with rubric.txt, or a name under assignments/ here, in the "
                        "source tree or in the installed share/lensfield/assignments/)",
                        a);
}

static int tokenize(const char *line, int strict, char ***argv_out, int *argc_out, lf_error *err)
{
    if (strict) {
        const char *bad = strpbrk(line, ";|&$`<>\\(){}\n\r");
        if (bad) {
            return lf_error_set(err, LF_ERR_PARSE,
                                "contains shell syntax '%c': commands are read as data and never run, so this line is "
                                "not accepted",
                                *bad == '\n' || *bad == '\r' ? ' ' : *bad);
        }
    }
    int cap = 16, n = 0;
    char **v = malloc(sizeof *v * (size_t)cap);
    size_t len = strlen(line);
    char *buf = malloc(len + 1);
    if (!v || !buf) {
        free(v), free(buf);
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    }
    const char *p = line;
    for (;;) {
        while (*p && isspace((unsigned char)*p))
            p++;
        if (!*p || (*p == '#' && !strict))
            break;
        size_t k = 0;
        while (*p && !isspace((unsigned char)*p)) {
            if (*p == '\'' || *p == '"') {
                char q = *p++;
                const char *e = strchr(p, q);
                if (!e) {
                    lf_grade_free_argv(v, n);
                    free(buf);
                    return lf_error_set(err, LF_ERR_PARSE, "unterminated %c quote", q);
                }
                memcpy(buf + k, p, (size_t)(e - p));
                k += (size_t)(e - p);
                p = e + 1;
            } else {
                buf[k++] = *p++;
            }
        }
        buf[k] = 0;
        if (n == cap) {
            char **nv = realloc(v, sizeof *v * (size_t)cap * 2);
            if (!nv)
                goto oom;
            v = nv, cap *= 2;
        }
        if (!(v[n] = strdup(buf)))
            goto oom;
        n++;
    }
    free(buf);
    *argv_out = v;
    *argc_out = n;
    return 0;
oom:
    lf_grade_free_argv(v, n);
    free(buf);
    return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
}

int lf_grade_tokenize(const char *line, char ***argv, int *argc, lf_error *err)
{
    return tokenize(line, 1, argv, argc, err);
}

void lf_grade_free_argv(char **argv, int argc)
{
    for (int i = 0; i < argc; i++)
        free(argv[i]);
    free(argv);
}

static const char *kinds[] = {"files", "sections", "size", "render", "synth", "refocus", "constraint", "answer", "focus"};

const char *lf_grade_check_get(const lf_grade_check *c, const char *key, const char *def)
{
    for (int i = 0; i < c->nkv; i++)
        if (!strcmp(c->key[i], key))
            return c->val[i];
    return def;
}

void lf_grade_rubric_free(lf_grade_rubric *r)
{
    for (int i = 0; i < r->nchecks; i++) {
        lf_grade_check *c = &r->checks[i];
        for (int k = 0; k < c->nkv; k++)
            free(c->key[k]), free(c->val[k]);
        for (int v = 0; v < c->nvariants; v++)
            for (int e = 0; e < c->variants[v].nedits; e++)
                free(c->variants[v].find[e]), free(c->variants[v].replace[e]);
    }
    free(r->checks);
    memset(r, 0, sizeof *r);
}

static int parse_assignment(lf_grade_rubric *r, char **v, int n, const lf_loc *at, lf_error *err)
{
    (void)n, (void)at, (void)err;
    snprintf(r->assignment, sizeof r->assignment, "%s", v[1]);
    return 0;
}

static int parse_title(lf_grade_rubric *r, char **v, int n, const lf_loc *at, lf_error *err)
{
    (void)at, (void)err;
    r->title[0] = 0;
    for (int i = 1; i < n; i++) {
        size_t l = strlen(r->title);
        snprintf(r->title + l, sizeof r->title - l, "%s%s", i > 1 ? " " : "", v[i]);
    }
    return 0;
}

/* check ID POINTS KIND key=value ... */
static int parse_check(lf_grade_rubric *r, char **v, int n, const lf_loc *at, lf_error *err)
{
    lf_grade_check *nc = realloc(r->checks, sizeof *nc * (size_t)(r->nchecks + 1));
    if (!nc)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    r->checks = nc;
    lf_grade_check *c = &r->checks[r->nchecks++];
    memset(c, 0, sizeof *c);
    c->line = at->line;
    snprintf(c->id, sizeof c->id, "%s", v[1]);
    char *end;
    long pts = strtol(v[2], &end, 10);
    int rc = 0;
    if (*end || pts < 0 || pts > 1000)
        rc = lf_error_at(err, LF_ERR_PARSE, at, "points '%s' is not an integer in 0..1000", v[2]);
    c->points = (int)pts;
    snprintf(c->kind, sizeof c->kind, "%s", v[3]);
    int known = 0;
    for (size_t k = 0; k < sizeof kinds / sizeof *kinds; k++)
        known |= !strcmp(kinds[k], v[3]);
    if (!known && !rc)
        rc = lf_error_at(err, LF_ERR_PARSE, at, "unknown check kind '%s'", v[3]);
    for (int i = 4; i < n && !rc; i++) {
        char *eq = strchr(v[i], '=');
        if (!eq || c->nkv == 24)
            return lf_error_at(err, LF_ERR_PARSE, at, "expected key=value, got '%s'", v[i]);
        *eq = 0;
        c->key[c->nkv] = strdup(v[i]);
        c->val[c->nkv++] = strdup(eq + 1);
    }
    return rc;
}

/* One key=value of a variant line. */
static int parse_variant_field(lf_grade_variant *va, char *kv, const lf_loc *at, lf_error *err)
{
    char *eq = strchr(kv, '=');
    if (!eq)
        return lf_error_at(err, LF_ERR_PARSE, at, "expected key=value, got '%s'", kv);
    *eq = 0;
    const char *val = eq + 1;
    if (!strcmp(kv, "reason"))
        snprintf(va->reason, sizeof va->reason, "%s", val);
    else if (!strcmp(kv, "post"))
        snprintf(va->post, sizeof va->post, "%s", val);
    else if (!strcmp(kv, "set"))
        snprintf(va->set, sizeof va->set, "%s", val);
    else if (!strcmp(kv, "measure"))
        snprintf(va->measure, sizeof va->measure, "%s", val);
    else if (!strcmp(kv, "base"))
        va->base = atof(val);
    else if (!strcmp(kv, "brightness")) {
        va->brightness = atof(val);
        if (!(va->brightness > 0))
            return lf_error_at(err, LF_ERR_PARSE, at, "brightness= wants a factor > 0");
    }
    else if (!strcmp(kv, "range")) {
        if (sscanf(val, "%lf:%lf", &va->lo, &va->hi) != 2 || !(va->lo > 0) || !(va->hi > va->lo))
            return lf_error_at(err, LF_ERR_PARSE, at, "range= wants LO:HI factors, 0 < LO < HI");
    } else if (!strcmp(kv, "replace") && va->nedits < LF_GRADE_MAX_EDITS)
        va->find[va->nedits] = strdup(val), va->replace[va->nedits] = NULL;
    else if (!strcmp(kv, "with") && va->find[va->nedits] && !va->replace[va->nedits])
        va->replace[va->nedits++] = strdup(val);
    else
        return lf_error_at(err, LF_ERR_PARSE, at, "unexpected '%s' in a variant", kv);
    return 0;
}

/* variant CHECK_ID NAME key=value ... (of a check above) */
static int parse_variant(lf_grade_rubric *r, char **v, int n, const lf_loc *at, lf_error *err)
{
    lf_grade_check *c = NULL;
    for (int i = 0; i < r->nchecks; i++)
        if (!strcmp(r->checks[i].id, v[1]))
            c = &r->checks[i];
    if (!c || c->nvariants == LF_GRADE_MAX_VARIANTS)
        return lf_error_at(err, LF_ERR_PARSE, at, "variant of %s: %s", v[1],
                           c ? "too many variants" : "no such check above");
    lf_grade_variant *va = &c->variants[c->nvariants++];
    memset(va, 0, sizeof *va);
    snprintf(va->name, sizeof va->name, "%s", v[2]);
    int rc = 0;
    for (int i = 3; i < n && !rc; i++)
        rc = parse_variant_field(va, v[i], at, err);
    if (!rc && va->nedits < LF_GRADE_MAX_EDITS && va->find[va->nedits])
        rc = lf_error_at(err, LF_ERR_PARSE, at, "replace= without with=");
    for (int e = 0; !rc && e < va->nedits; e++)
        if (strstr(va->replace[e], "{v"))
            va->search = 1;
    if (!rc && va->search && (!(va->base != 0) || !(va->hi > 0)))
        rc = lf_error_at(err, LF_ERR_PARSE, at, "a search variant ({v} in with=) needs base= and range=");
    if (!rc && !va->reason[0])
        rc = lf_error_at(err, LF_ERR_PARSE, at, "a variant needs reason=");
    return rc;
}

/* The directives: name, fields (with the name) at least and at most (-1: any). */
static const struct {
    const char *name;
    int min_fields, max_fields;
    int (*parse)(lf_grade_rubric *r, char **v, int n, const lf_loc *at, lf_error *err);
} directives[] = {
    {"assignment", 2, 2, parse_assignment},
    {"title", 2, -1, parse_title},
    {"check", 4, -1, parse_check},
    {"variant", 4, -1, parse_variant},
};

int lf_grade_rubric_parse(const char *path, lf_grade_rubric *r, lf_error *err)
{
    memset(r, 0, sizeof *r);
    lf_loc at = {path, 0, 0}; /* line 0: the file as a whole */
    FILE *f = fopen(path, "r");
    if (!f)
        return lf_error_at(err, LF_ERR_IO, &at, "cannot open the rubric");
    char line[4096];
    int rc = 0;
    while (!rc && fgets(line, sizeof line, f)) {
        at.line++;
        char **v;
        int n;
        lf_error why = {0};
        if (tokenize(line, 0, &v, &n, &why)) {
            rc = lf_error_at(err, why.code, &at, "%s", why.msg);
            break;
        }
        size_t d = 0;
        while (n > 0 && d < sizeof directives / sizeof *directives &&
               (strcmp(v[0], directives[d].name) || n < directives[d].min_fields ||
                (directives[d].max_fields >= 0 && n > directives[d].max_fields)))
            d++;
        if (n > 0 && d < sizeof directives / sizeof *directives)
            rc = directives[d].parse(r, v, n, &at, err);
        else if (n > 0)
            rc = lf_error_at(err, LF_ERR_PARSE, &at, "unknown directive '%s' (or missing fields)", v[0]);
        lf_grade_free_argv(v, n);
    }
    fclose(f);
    at.line = 0;
    if (!rc && !r->nchecks)
        rc = lf_error_at(err, LF_ERR_PARSE, &at, "no checks");
    if (rc)
        lf_grade_rubric_free(r);
    return rc;
}
