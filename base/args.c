/* Table-driven command lines (lf_args.h). */
#include "lf_args.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lf_buf.h"
#include "lf_suggest.h"

static lf_args_status fail(lf_error *err, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static lf_args_status fail(lf_error *err, const char *fmt, ...)
{
    if (err && !err->code) { /* the first message stays, as lf_error_set */
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->code = LF_ERR_PARAM;
    }
    return LF_ARGS_ERROR;
}

const lf_command *lf_args_find(const lf_tool *tool, const char *name)
{
    for (int i = 0; i < tool->n_commands; i++) {
        const char *n = tool->commands[i].name;
        if ((!n && !name) || (n && name && !strcmp(n, name)))
            return &tool->commands[i];
    }
    return NULL;
}

static unsigned range_flags(const lf_arg *a)
{
    unsigned f = a->flags;
    if (f & LF_ARG_MIN_OPEN)
        f |= LF_ARG_HAS_MIN;
    if (f & LF_ARG_MAX_OPEN)
        f |= LF_ARG_HAS_MAX;
    return f;
}

/* "a number > 0", "an integer from 1 to 64", ... */
static void describe_range(const lf_arg *a, char *out, size_t n)
{
    unsigned f = range_flags(a);
    const char *what = a->type == LF_ARG_INT || a->type == LF_ARG_LONG ? "an integer" : "a number";
    if ((f & LF_ARG_HAS_MIN) && (f & LF_ARG_HAS_MAX) && !(f & (LF_ARG_MIN_OPEN | LF_ARG_MAX_OPEN)))
        snprintf(out, n, "%s from %.10g to %.10g", what, a->min, a->max);
    else if ((f & LF_ARG_HAS_MIN) && (f & LF_ARG_HAS_MAX))
        snprintf(out, n, "%s %s %.10g and %s %.10g", what, (f & LF_ARG_MIN_OPEN) ? ">" : ">=", a->min,
                 (f & LF_ARG_MAX_OPEN) ? "<" : "<=", a->max);
    else if (f & LF_ARG_HAS_MIN)
        snprintf(out, n, "%s %s %.10g", what, (f & LF_ARG_MIN_OPEN) ? ">" : ">=", a->min);
    else if (f & LF_ARG_HAS_MAX)
        snprintf(out, n, "%s %s %.10g", what, (f & LF_ARG_MAX_OPEN) ? "<" : "<=", a->max);
    else
        snprintf(out, n, "%s", what);
    if (a->type == LF_ARG_DOUBLE && (a->flags & LF_ARG_INF_OK))
        snprintf(out + strlen(out), n - strlen(out), " (or inf)");
}

static int in_range(const lf_arg *a, double v)
{
    unsigned f = range_flags(a);
    if (isinf(v) && v > 0 && a->type == LF_ARG_DOUBLE && (a->flags & LF_ARG_INF_OK))
        return 1;
    if ((f & LF_ARG_HAS_MIN) && ((f & LF_ARG_MIN_OPEN) ? !(v > a->min) : !(v >= a->min)))
        return 0;
    if ((f & LF_ARG_HAS_MAX) && ((f & LF_ARG_MAX_OPEN) ? !(v < a->max) : !(v <= a->max)))
        return 0;
    return 1;
}

static int choice_ok(const char *choices, const char *v)
{
    size_t n = strlen(v);
    for (const char *p = choices; p && *p;) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && !strncmp(p, v, n))
            return 1;
        p = bar ? bar + 1 : NULL;
    }
    return 0;
}

/* One value of flag a into slot k. */
static lf_args_status store(const lf_arg *a, int k, const char *text, lf_error *err)
{
    char range[160];
    switch (a->type) {
    case LF_ARG_INT: {
        char *end;
        errno = 0;
        long v = strtol(text, &end, 10);
        if (end == text || *end || errno == ERANGE || v < INT_MIN || v > INT_MAX || !in_range(a, (double)v)) {
            describe_range(a, range, sizeof range);
            return fail(err, "%s wants %s, got \"%s\"", a->name, range, text);
        }
        ((int *)a->value)[k] = (int)v;
        return LF_ARGS_OK;
    }
    case LF_ARG_LONG: {
        char *end;
        errno = 0;
        long long v = strtoll(text, &end, 10);
        if (end == text || *end || errno == ERANGE || !in_range(a, (double)v)) {
            describe_range(a, range, sizeof range);
            return fail(err, "%s wants %s, got \"%s\"", a->name, range, text);
        }
        ((long long *)a->value)[k] = v;
        return LF_ARGS_OK;
    }
    case LF_ARG_DOUBLE: {
        char *end;
        errno = 0;
        double v = strtod(text, &end);
        int inf_ok = (a->flags & LF_ARG_INF_OK) && isinf(v) && v > 0;
        if (end == text || *end || isnan(v) || (isinf(v) && !inf_ok) || (errno == ERANGE && !isinf(v) && v != 0) ||
            !in_range(a, v)) {
            describe_range(a, range, sizeof range);
            return fail(err, "%s wants %s, got \"%s\"", a->name, range, text);
        }
        ((double *)a->value)[k] = v;
        return LF_ARGS_OK;
    }
    case LF_ARG_CHOICE:
        if (!choice_ok(a->choices, text))
            return fail(err, "%s wants one of %s, got \"%s\"", a->name, a->choices, text);
        *(const char **)a->value = text;
        return LF_ARGS_OK;
    case LF_ARG_STRING:
        *(const char **)a->value = text;
        return LF_ARGS_OK;
    case LF_ARG_LIST: {
        int cap = a->count > 0 ? a->count : 1;
        if (*a->count_out >= cap)
            return fail(err, "%s is given more than %d times", a->name, cap);
        ((const char **)a->value)[(*a->count_out)++] = text;
        return LF_ARGS_OK;
    }
    case LF_ARG_FLAG:
        break;
    }
    return fail(err, "%s takes no value", a->name);
}

static const lf_arg *find_arg(const lf_command *cmd, const char *name, size_t len)
{
    for (int i = 0; i < cmd->n_args; i++) {
        const lf_arg *a = &cmd->args[i];
        if ((strlen(a->name) == len && !strncmp(a->name, name, len)) ||
            (a->short_name && strlen(a->short_name) == len && !strncmp(a->short_name, name, len)))
            return a;
    }
    return NULL;
}

/* A word that starts with '-' but is a number ("-1.5") or "-" is positional. */
static int looks_like_flag(const char *s)
{
    if (s[0] != '-' || s[1] == '\0')
        return 0;
    if ((s[1] >= '0' && s[1] <= '9') || s[1] == '.')
        return 0;
    return 1;
}

static lf_args_status unknown(const lf_tool *tool, const lf_command *cmd, const char *flag, size_t len,
                              lf_error *err)
{
    for (int i = 0; tool && i < tool->n_commands; i++) {
        const lf_command *o = &tool->commands[i];
        if (o != cmd && o->name && find_arg(o, flag, len))
            return fail(err, "%.*s is a flag of `%s %s`, not of `%s%s%s`", (int)len, flag, tool->name,
                        o->name, tool->name, cmd->name ? " " : "", cmd->name ? cmd->name : "");
    }
    char typed[64];
    snprintf(typed, sizeof typed, "%.*s", (int)len, flag);
    lf_suggest s = lf_suggest_begin(typed);
    for (int i = 0; i < cmd->n_args; i++)
        if (!(cmd->args[i].flags & LF_ARG_HIDDEN))
            lf_suggest_consider(&s, cmd->args[i].name);
    lf_suggest_consider(&s, "--help");
    if (lf_suggest_best(&s))
        return fail(err, "unknown flag %.*s (did you mean %s?)", (int)len, flag, lf_suggest_best(&s));
    return fail(err, "unknown flag %.*s", (int)len, flag);
}

const char *lf_args_unknown_command(const lf_tool *tool, const char *word, lf_error *err)
{
    lf_suggest s = lf_suggest_begin(word);
    for (int i = 0; i < tool->n_commands; i++)
        lf_suggest_consider(&s, tool->commands[i].name);
    if (lf_suggest_best(&s))
        lf_error_set(err, LF_ERR_PARAM, "unknown command \"%s\" (did you mean %s?)", word, lf_suggest_best(&s));
    else
        lf_error_set(err, LF_ERR_PARAM, "unknown command \"%s\"", word);
    return err->msg;
}

lf_args_status lf_args_parse(const lf_tool *tool, const lf_command *cmd, int argc, char **argv, int first,
                             char **positional, int *n_positional, lf_error *err)
{
    lf_error_clear(err);
    *n_positional = 0;
    unsigned char seen[256] = {0};
    if (cmd->n_args > (int)sizeof seen)
        return fail(err, "internal: more than %d flags in one command", (int)sizeof seen);
    for (int i = 0; i < cmd->n_args; i++) {
        if (cmd->args[i].given)
            *cmd->args[i].given = 0;
        if (cmd->args[i].type == LF_ARG_LIST && cmd->args[i].count_out)
            *cmd->args[i].count_out = 0;
    }
    int flags_done = 0;
    for (int i = first; i < argc; i++) {
        const char *w = argv[i];
        if (flags_done || !looks_like_flag(w)) {
            positional[(*n_positional)++] = argv[i];
            continue;
        }
        if (!strcmp(w, "--")) {
            flags_done = 1;
            continue;
        }
        if (!strcmp(w, "--help") || !strcmp(w, "-h"))
            return LF_ARGS_HELP;
        if (!strcmp(w, "--version"))
            return LF_ARGS_VERSION;
        if (!strcmp(w, "--man"))
            return LF_ARGS_MAN;
        const char *eq = strncmp(w, "--", 2) == 0 ? strchr(w, '=') : NULL;
        size_t len = eq ? (size_t)(eq - w) : strlen(w);
        const lf_arg *a = find_arg(cmd, w, len);
        if (!a)
            return unknown(tool, cmd, w, len, err);
        seen[a - cmd->args] = 1;
        if (a->given)
            *a->given = 1;
        if (a->type == LF_ARG_FLAG) {
            if (eq)
                return fail(err, "%s takes no value", a->name);
            *(int *)a->value = 1;
            continue;
        }
        int nval = (a->type == LF_ARG_INT || a->type == LF_ARG_DOUBLE) && a->count > 1 ? a->count : 1;
        if (eq && nval != 1)
            return fail(err, "%s takes %d values (%s %s ...)", a->name, nval, a->name,
                        a->metavar ? a->metavar : "V");
        for (int k = 0; k < nval; k++) {
            const char *text;
            if (eq) {
                text = eq + 1;
            } else {
                if (i + 1 >= argc) {
                    if (nval > 1)
                        return fail(err, "%s takes %d values, got %d", a->name, nval, k);
                    return fail(err, "%s needs a value (%s)", a->name, a->metavar ? a->metavar : "value");
                }
                text = argv[++i];
            }
            lf_args_status st = store(a, k, text, err);
            if (st != LF_ARGS_OK)
                return st;
        }
    }
    for (int i = 0; i < cmd->n_args; i++) {
        const lf_arg *a = &cmd->args[i];
        if ((a->flags & LF_ARG_REQUIRED) && !seen[i])
            return fail(err, "%s is required", a->name);
    }
    if (*n_positional < cmd->min_positional)
        return fail(err, "missing argument%s (usage: %s%s%s %s)", cmd->min_positional > 1 ? "s" : "",
                    tool ? tool->name : "",
                    cmd->name ? " " : "", cmd->name ? cmd->name : "", cmd->synopsis ? cmd->synopsis : "");
    if (cmd->max_positional >= 0 && *n_positional > cmd->max_positional)
        return fail(err, "unexpected argument \"%s\"", positional[cmd->max_positional]);
    return LF_ARGS_OK;
}

/* "-o, --output OUT" */
static void flag_label(const lf_arg *a, lf_strbuf *b)
{
    if (a->short_name)
        lf_strbuf_printf(b, "%s, ", a->short_name);
    lf_strbuf_puts(b, a->name);
    int nval = (a->type == LF_ARG_INT || a->type == LF_ARG_DOUBLE) && a->count > 1 ? a->count : 1;
    if (a->type == LF_ARG_CHOICE && !a->metavar)
        lf_strbuf_printf(b, " %s", a->choices);
    else if (a->type != LF_ARG_FLAG && a->metavar && strchr(a->metavar, ' '))
        lf_strbuf_printf(b, " %s", a->metavar); /* "X0 X1 Y0 Y1": one name per value, given whole */
    else if (a->type != LF_ARG_FLAG)
        for (int k = 0; k < nval; k++)
            lf_strbuf_printf(b, " %s", a->metavar ? a->metavar : "V");
}

/* "an integer from 1 to 64; required" appended to the help sentence. */
static void flag_notes(const lf_arg *a, lf_strbuf *b)
{
    unsigned f = range_flags(a);
    char range[160];
    int any = 0;
    if ((a->type == LF_ARG_INT || a->type == LF_ARG_LONG || a->type == LF_ARG_DOUBLE) &&
        (f & (LF_ARG_HAS_MIN | LF_ARG_HAS_MAX))) {
        describe_range(a, range, sizeof range);
        lf_strbuf_printf(b, " [%s", range);
        any = 1;
    }
    if (a->type == LF_ARG_CHOICE && a->metavar && strchr(a->choices, '|')) {
        lf_strbuf_printf(b, "%sone of %s", any ? "; " : " [", a->choices);
        any = 1;
    }
    if (a->flags & LF_ARG_REQUIRED) {
        lf_strbuf_printf(b, "%srequired", any ? "; " : " [");
        any = 1;
    }
    if (any)
        lf_strbuf_puts(b, "]");
}

/* Appends text word-wrapped to `width` columns; the cursor starts at column
 * `col` and continuation lines are indented by `indent`. */
static void wrap(lf_strbuf *b, const char *text, int col, int indent, int width)
{
    const char *p = text;
    while (*p) {
        while (*p == ' ')
            p++;
        size_t len = strcspn(p, " ");
        if (!len)
            break;
        if (col > indent && col + 1 + (int)len > width) {
            lf_strbuf_printf(b, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            lf_strbuf_puts(b, " ");
            col++;
        }
        lf_strbuf_append(b, p, len);
        col += (int)len;
        p += len;
    }
}

static void command_usage(const lf_tool *tool, const lf_command *c, lf_strbuf *b)
{
    lf_strbuf_printf(b, "usage: %s%s%s %s\n", tool->name, c->name ? " " : "", c->name ? c->name : "",
                     c->synopsis ? c->synopsis : "");
    if (c->summary)
        lf_strbuf_printf(b, "  %s\n", c->summary);
    if (c->description) {
        lf_strbuf_puts(b, "\n");
        wrap(b, c->description, 0, 0, 79);
        lf_strbuf_puts(b, "\n");
    }
    lf_strbuf_puts(b, "\noptions:\n");
    for (int i = 0; i < c->n_args; i++) {
        const lf_arg *a = &c->args[i];
        if (a->flags & LF_ARG_HIDDEN)
            continue;
        lf_strbuf lab = {0};
        flag_label(a, &lab);
        size_t width = lab.len;
        lf_strbuf_printf(b, "  %s", lab.s ? lab.s : "");
        lf_strbuf_free(&lab);
        if (width < 26)
            lf_strbuf_printf(b, "%*s", (int)(26 - width), "");
        else
            lf_strbuf_puts(b, "\n                            ");
        lf_strbuf help = {0};
        lf_strbuf_puts(&help, a->help ? a->help : "");
        flag_notes(a, &help);
        wrap(b, help.s ? help.s : "", 28, 28, 79);
        lf_strbuf_free(&help);
        lf_strbuf_puts(b, "\n");
    }
    lf_strbuf_puts(b, "  -h, --help                this help\n  --man                     the manual page (through "
                      "man(1) on a terminal)\n  --version                 print the version\n");
}

char *lf_args_usage(const lf_tool *tool, const lf_command *cmd)
{
    lf_strbuf b = {0};
    const lf_command *fallback = lf_args_find(tool, NULL);
    if (cmd || fallback) {
        command_usage(tool, cmd ? cmd : fallback, &b);
        if (!cmd && tool->n_commands > 1) { /* the other commands of a tool that runs one without a name */
            lf_strbuf_puts(&b, "\nother commands:\n");
            for (int i = 0; i < tool->n_commands; i++)
                if (tool->commands[i].name)
                    lf_strbuf_printf(&b, "  %s %-10s %s\n", tool->name, tool->commands[i].name,
                                     tool->commands[i].summary ? tool->commands[i].summary : "");
        }
    } else {
        lf_strbuf_printf(&b, "usage: %s COMMAND [options]\n  %s\n\ncommands:\n", tool->name,
                         tool->summary ? tool->summary : "");
        for (int i = 0; i < tool->n_commands; i++) {
            const lf_command *c = &tool->commands[i];
            if (c->name)
                lf_strbuf_printf(&b, "  %-14s %s\n", c->name, c->summary ? c->summary : "");
        }
        char run[256];
        snprintf(run, sizeof run, "Run `%s COMMAND --help` for a command's flags, `%s --man` for the manual page; "
                 "`%s --version` prints the version.", tool->name, tool->name, tool->name);
        lf_strbuf_puts(&b, "\n");
        wrap(&b, run, 0, 0, 79);
        lf_strbuf_puts(&b, "\n");
    }
    if (tool->description && !cmd) {
        lf_strbuf_puts(&b, "\n");
        wrap(&b, tool->description, 0, 0, 79);
        lf_strbuf_puts(&b, "\n");
    }
    if (b.failed) {
        lf_strbuf_free(&b);
        return NULL;
    }
    return lf_strbuf_take(&b);
}

/* roff text: backslashes doubled, '-' as \-, a leading '.' or '\'' escaped. */
static void roff(lf_strbuf *b, const char *s)
{
    if (!s)
        return;
    if (s[0] == '.' || s[0] == '\'')
        lf_strbuf_puts(b, "\\&");
    for (; *s; s++) {
        if (*s == '\\')
            lf_strbuf_puts(b, "\\e");
        else if (*s == '-')
            lf_strbuf_puts(b, "\\-");
        else if (*s == '\n' && (s[1] == '.' || s[1] == '\''))
            lf_strbuf_puts(b, "\n\\&");
        else
            lf_strbuf_append(b, s, 1);
    }
}

char *lf_args_man(const lf_tool *tool, const char *date)
{
    lf_strbuf b = {0};
    lf_strbuf_printf(&b, ".TH %s 1 \"%s\" \"lensfield %s\" \"lensfield manual\"\n.SH NAME\n", tool->name,
                     date ? date : "", tool->version ? tool->version : "");
    roff(&b, tool->name);
    lf_strbuf_puts(&b, " \\- ");
    roff(&b, tool->summary);
    lf_strbuf_puts(&b, "\n.SH SYNOPSIS\n");
    for (int i = 0; i < tool->n_commands; i++) {
        const lf_command *c = &tool->commands[i];
        lf_strbuf_printf(&b, ".B %s%s%s\n", tool->name, c->name ? " " : "", c->name ? c->name : "");
        roff(&b, c->synopsis);
        lf_strbuf_puts(&b, "\n.br\n");
    }
    if (tool->description) {
        lf_strbuf_puts(&b, ".SH DESCRIPTION\n");
        roff(&b, tool->description);
        lf_strbuf_puts(&b, "\n");
    }
    lf_strbuf_puts(&b, tool->n_commands > 1 ? ".SH COMMANDS\n" : ".SH OPTIONS\n");
    for (int i = 0; i < tool->n_commands; i++) {
        const lf_command *c = &tool->commands[i];
        if (c->name) {
            lf_strbuf_puts(&b, ".SS ");
            roff(&b, c->name);
            lf_strbuf_puts(&b, "\n");
        }
        roff(&b, c->summary);
        lf_strbuf_puts(&b, "\n");
        if (c->description) {
            lf_strbuf_puts(&b, ".PP\n");
            roff(&b, c->description);
            lf_strbuf_puts(&b, "\n");
        }
        for (int k = 0; k < c->n_args; k++) {
            const lf_arg *a = &c->args[k];
            if (a->flags & LF_ARG_HIDDEN)
                continue;
            lf_strbuf lab = {0}, help = {0};
            flag_label(a, &lab);
            lf_strbuf_puts(&help, a->help ? a->help : "");
            flag_notes(a, &help);
            lf_strbuf_puts(&b, ".TP\n.B ");
            roff(&b, lab.s);
            lf_strbuf_puts(&b, "\n");
            roff(&b, help.s);
            lf_strbuf_puts(&b, "\n");
            lf_strbuf_free(&lab);
            lf_strbuf_free(&help);
        }
    }
    lf_strbuf_puts(&b, ".SH EXIT STATUS\n0 success; 1 bad input or a failed operation (the message names the file); "
                       "2 a bad command line.\n");
    if (b.failed) {
        lf_strbuf_free(&b);
        return NULL;
    }
    return lf_strbuf_take(&b);
}
