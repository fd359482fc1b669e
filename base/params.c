#include "lf_params.h"
#include "lf_suggest.h"

#include <stdlib.h>
#include <string.h>

#include "lf_color.h"

static const char *const type_names[] = {
    [LF_PT_FLOAT] = "float",     [LF_PT_INTEGER] = "integer", [LF_PT_BOOL] = "bool",
    [LF_PT_STRING] = "string",   [LF_PT_POINT2] = "point2",   [LF_PT_VECTOR2] = "vector2",
    [LF_PT_POINT3] = "point3",   [LF_PT_VECTOR3] = "vector3", [LF_PT_NORMAL3] = "normal3",
    [LF_PT_RGB] = "rgb",         [LF_PT_SPECTRUM] = "spectrum", [LF_PT_BLACKBODY] = "blackbody",
    [LF_PT_TEXTURE] = "texture",
};

const char *lf_param_type_name(lf_param_type t)
{
    if ((unsigned)t < sizeof type_names / sizeof type_names[0] && type_names[t])
        return type_names[t];
    return "?";
}

int lf_param_type_from_name(const char *word, lf_param_type *out)
{
    static const struct {
        const char *word;
        lf_param_type type;
    } aliases[] = {
        /* pbrt-v3 spellings that pbrt-v4 still reads. */
        {"point", LF_PT_POINT3}, {"vector", LF_PT_VECTOR3}, {"normal", LF_PT_NORMAL3}, {"color", LF_PT_RGB},
    };
    if (!word)
        return -1;
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++)
        if (type_names[i] && strcmp(type_names[i], word) == 0) {
            *out = (lf_param_type)i;
            return 0;
        }
    for (size_t i = 0; i < sizeof aliases / sizeof aliases[0]; i++)
        if (strcmp(aliases[i].word, word) == 0) {
            *out = aliases[i].type;
            return 0;
        }
    return -1;
}

static void param_free(lf_param *p)
{
    free(p->name);
    free(p->nums);
    for (size_t i = 0; i < p->n_strs; i++)
        free(p->strs[i]);
    free(p->strs);
    free(p->bools);
    memset(p, 0, sizeof *p);
}

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* Deep copy of one parameter; 0 or -1 on allocation failure (dst freed). */
static int param_copy(lf_param *dst, const lf_param *src)
{
    memset(dst, 0, sizeof *dst);
    dst->type = src->type;
    dst->loc = src->loc;
    dst->name = dup_str(src->name ? src->name : "");
    if (!dst->name)
        goto fail;
    if (src->n_nums) {
        dst->nums = malloc(src->n_nums * sizeof *dst->nums);
        if (!dst->nums)
            goto fail;
        memcpy(dst->nums, src->nums, src->n_nums * sizeof *dst->nums);
        dst->n_nums = src->n_nums;
    }
    if (src->n_bools) {
        dst->bools = malloc(src->n_bools);
        if (!dst->bools)
            goto fail;
        memcpy(dst->bools, src->bools, src->n_bools);
        dst->n_bools = src->n_bools;
    }
    if (src->n_strs) {
        dst->strs = calloc(src->n_strs, sizeof *dst->strs);
        if (!dst->strs)
            goto fail;
        dst->n_strs = src->n_strs;
        for (size_t i = 0; i < src->n_strs; i++)
            if (!(dst->strs[i] = dup_str(src->strs[i])))
                goto fail;
    }
    return 0;
fail:
    param_free(dst);
    return -1;
}

int lf_params_add(lf_paramset *ps, const lf_param *p)
{
    if (ps->count == ps->cap) {
        size_t cap = ps->cap ? 2 * ps->cap : 8;
        lf_param *items = realloc(ps->items, cap * sizeof *items);
        if (!items)
            return LF_ERR_NOMEM;
        ps->items = items;
        ps->cap = cap;
    }
    ps->items[ps->count++] = *p;
    return LF_OK;
}

static int add_copy(lf_paramset *dst, const lf_param *src, int used)
{
    lf_param c;
    if (param_copy(&c, src))
        return LF_ERR_NOMEM;
    c.used = used;
    if (lf_params_add(dst, &c)) {
        param_free(&c);
        return LF_ERR_NOMEM;
    }
    return LF_OK;
}

int lf_params_copy(lf_paramset *dst, const lf_paramset *src)
{
    memset(dst, 0, sizeof *dst);
    for (size_t i = 0; i < src->count; i++)
        if (add_copy(dst, &src->items[i], 0)) {
            lf_params_free(dst);
            return LF_ERR_NOMEM;
        }
    dst->error = src->error;
    return LF_OK;
}

int lf_params_merge_defaults(lf_paramset *ps, const lf_paramset *defaults)
{
    for (size_t i = 0; i < defaults->count; i++) {
        if (lf_params_peek(ps, defaults->items[i].name))
            continue;
        /* Added already marked used: an Attribute default applies to every
         * following shape (or light ...), and a shape that has no use for it
         * is not a typo (pbrt-v4's mayBeUnused). */
        if (add_copy(ps, &defaults->items[i], 1))
            return LF_ERR_NOMEM;
    }
    return LF_OK;
}

void lf_params_free(lf_paramset *ps)
{
    if (!ps)
        return;
    for (size_t i = 0; i < ps->count; i++)
        param_free(&ps->items[i]);
    free(ps->items);
    free(ps->absent);
    memset(ps, 0, sizeof *ps);
}

const lf_param *lf_params_peek(const lf_paramset *ps, const char *name)
{
    for (size_t i = 0; i < ps->count; i++)
        if (strcmp(ps->items[i].name, name) == 0)
            return &ps->items[i];
    return NULL;
}

/* Remembers a name looked up and not found (lf_paramset.absent). */
static void note_absent(lf_paramset *ps, const char *name, int type)
{
    /* An empty set has nothing unused to suggest a name for; and callers keep
     * stack-local empty sets for directives the scene left out, which they
     * never free. */
    if (ps->count == 0)
        return;
    for (size_t i = 0; i < ps->absent_len; i += strlen(ps->absent + i + 1) + 2)
        if (!strcmp(ps->absent + i + 1, name))
            return;
    size_t n = strlen(name) + 2;
    if (ps->absent_len + n > ps->absent_cap) {
        size_t cap = 2 * (ps->absent_len + n) + 64;
        char *a = realloc(ps->absent, cap);
        if (!a)
            return;
        ps->absent = a, ps->absent_cap = cap;
    }
    ps->absent[ps->absent_len] = (char)(type + 1);
    memcpy(ps->absent + ps->absent_len + 1, name, n - 1);
    ps->absent_len += n;
}

static lf_param *find_marked(lf_paramset *ps, const char *name, int type)
{
    lf_param *p = (lf_param *)lf_params_peek(ps, name);
    if (p)
        p->used = 1;
    else
        note_absent(ps, name, type);
    return p;
}

lf_param *lf_params_find(lf_paramset *ps, const char *name) { return find_marked(ps, name, -1); }

static void type_error(lf_paramset *ps, const lf_param *p, const char *expected)
{
    lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc, "parameter \"%s\" is declared %s, expected %s", p->name,
                lf_param_type_name(p->type), expected);
}

static void count_error(lf_paramset *ps, const lf_param *p, size_t expected, size_t got)
{
    lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc, "parameter \"%s %s\" expects %zu value%s, got %zu",
                lf_param_type_name(p->type), p->name, expected, expected == 1 ? "" : "s", got);
}

/* Finds `name`, marks it used and checks its type and value count; NULL if
 * absent or wrong (the error is recorded in ps). */
static lf_param *lookup(lf_paramset *ps, const char *name, lf_param_type type, size_t count)
{
    lf_param *p = find_marked(ps, name, (int)type);
    if (!p)
        return NULL;
    if (p->type != type) {
        type_error(ps, p, lf_param_type_name(type));
        return NULL;
    }
    size_t n = type == LF_PT_BOOL ? p->n_bools
               : (type == LF_PT_STRING || type == LF_PT_TEXTURE) ? p->n_strs
                                                                 : p->n_nums;
    if (count && n != count) {
        count_error(ps, p, count, n);
        return NULL;
    }
    return p;
}

double lf_params_float(lf_paramset *ps, const char *name, double def)
{
    lf_param *p = lookup(ps, name, LF_PT_FLOAT, 1);
    return p ? p->nums[0] : def;
}

int lf_params_int(lf_paramset *ps, const char *name, int def)
{
    lf_param *p = lookup(ps, name, LF_PT_INTEGER, 1);
    return p ? (int)p->nums[0] : def;
}

int lf_params_bool(lf_paramset *ps, const char *name, int def)
{
    lf_param *p = lookup(ps, name, LF_PT_BOOL, 1);
    return p ? (p->bools[0] != 0) : def;
}

const char *lf_params_string(lf_paramset *ps, const char *name, const char *def)
{
    lf_param *p = lookup(ps, name, LF_PT_STRING, 1);
    return p ? p->strs[0] : def;
}

static int fixed(lf_paramset *ps, const char *name, lf_param_type type, size_t n, double *out)
{
    lf_param *p = lookup(ps, name, type, n);
    if (!p)
        return 0;
    memcpy(out, p->nums, n * sizeof *out);
    return 1;
}

int lf_params_point2(lf_paramset *ps, const char *name, double out[2])
{
    return fixed(ps, name, LF_PT_POINT2, 2, out);
}

int lf_params_point3(lf_paramset *ps, const char *name, double out[3])
{
    return fixed(ps, name, LF_PT_POINT3, 3, out);
}

int lf_params_vector3(lf_paramset *ps, const char *name, double out[3])
{
    return fixed(ps, name, LF_PT_VECTOR3, 3, out);
}

const double *lf_params_nums(lf_paramset *ps, const char *name, lf_param_type type, size_t *count)
{
    *count = 0;
    lf_param *p = lookup(ps, name, type, 0); /* any count */
    if (!p)
        return NULL;
    *count = p->n_nums;
    return p->nums;
}

const char *const *lf_params_strings(lf_paramset *ps, const char *name, size_t *count)
{
    *count = 0;
    lf_param *p = lookup(ps, name, LF_PT_STRING, 0);
    if (!p)
        return NULL;
    *count = p->n_strs;
    return (const char *const *)p->strs;
}

int lf_params_rgb(lf_paramset *ps, const char *name, lf_spectrum_kind kind, lf_vec3 def, lf_vec3 *out)
{
    *out = def;
    lf_param *p = lf_params_find(ps, name);
    if (!p)
        return 0;
    lf_vec3 c;
    switch (p->type) {
    case LF_PT_RGB:
        if (p->n_nums != 3) {
            count_error(ps, p, 3, p->n_nums);
            return 1;
        }
        c = lf_v3((float)p->nums[0], (float)p->nums[1], (float)p->nums[2]);
        /* pbrt-v4 rejects these rather than guessing what was meant. */
        if (c.x < 0.f || c.y < 0.f || c.z < 0.f) {
            lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc, "rgb parameter \"%s\" has a negative component", p->name);
            return 1;
        }
        if (kind == LF_SPECTRUM_ALBEDO && lf_maxc(c) > 1.f) {
            lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc,
                        "rgb albedo parameter \"%s\" (%g %g %g) has a component greater than 1", p->name, p->nums[0],
                        p->nums[1], p->nums[2]);
            return 1;
        }
        break;
    case LF_PT_BLACKBODY:
        if (p->n_nums != 1) {
            count_error(ps, p, 1, p->n_nums);
            return 1;
        }
        if (!(p->nums[0] > 0.0)) {
            lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc,
                        "blackbody parameter \"%s\": temperature %g K is not positive", p->name, p->nums[0]);
            return 1;
        }
        c = lf_blackbody_rgb(p->nums[0]);
        if (kind == LF_SPECTRUM_ALBEDO)
            c = lf_v3(lf_clampf(c.x, 0.f, 1.f), lf_clampf(c.y, 0.f, 1.f), lf_clampf(c.z, 0.f, 1.f));
        break;
    case LF_PT_SPECTRUM:
        if (p->n_strs == 1 && p->n_nums == 0) {
            if (lf_named_spectrum_rgb(p->strs[0], &c)) {
                lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc,
                            "spectrum parameter \"%s\": unknown named spectrum \"%s\" "
                            "(the scene parser reads spectrum files)",
                            p->name, p->strs[0]);
                return 1;
            }
            break;
        }
        if (p->n_strs || p->n_nums < 2 || p->n_nums % 2) {
            lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc,
                        "spectrum parameter \"%s\" needs (wavelength, value) pairs or one name", p->name);
            return 1;
        } else {
            size_t n = p->n_nums / 2;
            double *l = malloc(2 * n * sizeof *l);
            if (!l) {
                lf_error_set(&ps->error, LF_ERR_NOMEM, "out of memory");
                return 1;
            }
            double *v = l + n;
            for (size_t i = 0; i < n; i++) {
                l[i] = p->nums[2 * i];
                v[i] = p->nums[2 * i + 1];
                if (i > 0 && !(l[i] > l[i - 1])) {
                    free(l);
                    lf_error_at(&ps->error, LF_ERR_PARAM, &p->loc,
                                "spectrum parameter \"%s\": wavelengths must increase (%g after %g)", p->name,
                                p->nums[2 * i], p->nums[2 * i - 2]);
                    return 1;
                }
            }
            c = lf_spectrum_pairs_rgb(l, v, n, kind);
            free(l);
        }
        break;
    case LF_PT_FLOAT:
        if (p->n_nums != 1) {
            count_error(ps, p, 1, p->n_nums);
            return 1;
        }
        c = lf_v3((float)p->nums[0], (float)p->nums[0], (float)p->nums[0]);
        break;
    default:
        type_error(ps, p, "rgb, blackbody, spectrum or float");
        return 1;
    }
    /* Out-of-gamut spectra (a 1900 K blackbody has negative blue in sRGB)
     * would emit or reflect negative light: clip to the gamut. */
    *out = lf_v3(c.x > 0.f ? c.x : 0.f, c.y > 0.f ? c.y : 0.f, c.z > 0.f ? c.z : 0.f);
    return 1;
}

const lf_error *lf_params_error(const lf_paramset *ps) { return &ps->error; }

/* Parameters that pbrt-v4 once read and has since dropped: today's pbrt-v4
 * refuses them as unused too (ParameterDictionary::ReportUnused), and some
 * of pbrt-v4-scenes' files still carry them; the message says so. */
static const char *dropped_note(const char *context, const char *name)
{
    static const struct {
        const char *context, *name, *note;
    } dropped[] = {
        {"Film", "scale",
         "early pbrt-v4's film scale factor; pbrt-v4 no longer reads it and refuses it as well: delete it, or "
         "use \"float iso\""},
        {"Integrator", "rrthreshold",
         "pbrt-v3's and early pbrt-v4's Russian-roulette threshold; pbrt-v4 no longer reads it and refuses it as "
         "well: delete it"},
    };
    for (size_t i = 0; context && i < sizeof dropped / sizeof dropped[0]; i++)
        if (!strncmp(context, dropped[i].context, strlen(dropped[i].context)) && !strcmp(name, dropped[i].name))
            return dropped[i].note;
    return NULL;
}

int lf_params_finish(const lf_paramset *ps, const char *context, lf_error *err)
{
    const lf_error *parked = lf_params_error(ps);
    if (parked->code != LF_OK)
        return lf_error_set(err, parked->code, "%s", parked->msg);
    for (size_t i = 0; i < ps->count; i++) {
        const lf_param *p = &ps->items[i];
        if (p->used)
            continue;
        lf_suggest s = lf_suggest_begin(p->name);
        for (size_t k = 0; k < ps->absent_len; k += strlen(ps->absent + k + 1) + 2)
            lf_suggest_consider(&s, ps->absent + k + 1);
        const char *best = lf_suggest_best(&s);
        int type = best && best[-1] ? best[-1] - 1 : (int)p->type; /* the type byte before the name; 0: as written */
        const char *note = best ? NULL : dropped_note(context, p->name);
        if (note)
            return lf_error_at(err, LF_ERR_PARAM, &p->loc, "unused parameter \"%s %s\" in %s (%s)",
                               lf_param_type_name(p->type), p->name, context, note);
        return lf_error_at(err, LF_ERR_PARAM, &p->loc, "unused parameter \"%s %s\" in %s%s%s%s%s%s",
                           lf_param_type_name(p->type), p->name, context ? context : "directive",
                           best ? " (did you mean \"" : "", best ? lf_param_type_name((lf_param_type)type) : "",
                           best ? " " : "", best ? best : "", best ? "\"?)" : "");
    }
    return LF_OK;
}
