#include "lf_error.h"

#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

int lf_error_set(lf_error *err, int code, const char *fmt, ...)
{
    if (!err || err->code != LF_OK)
        return code;
    err->code = code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return code;
}

void lf_error_clear(lf_error *err)
{
    if (!err)
        return;
    err->code = LF_OK;
    err->msg[0] = '\0';
}

int lf_loc_format(char *buf, size_t n, const lf_loc *loc)
{
    const char *file = loc && loc->file ? loc->file : "<unknown>";
    if (!loc || loc->line <= 0)
        return snprintf(buf, n, "%s", file);
    if (loc->col <= 0)
        return snprintf(buf, n, "%s:%lld", file, loc->line);
    return snprintf(buf, n, "%s:%lld:%lld", file, loc->line, loc->col);
}

int lf_error_at(lf_error *err, int code, const lf_loc *loc, const char *fmt, ...)
{
    if (!err || err->code != LF_OK)
        return code;
    char where[512] = "";
    size_t used = 0;
    if (loc) {
        lf_loc_format(where, sizeof where, loc);
        used = strlen(where);
    }
    err->code = code;
    if (used)
        snprintf(err->msg, sizeof err->msg, "%s: ", where);
    else
        err->msg[0] = '\0';
    size_t off = strlen(err->msg);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg + off, sizeof err->msg - off, fmt, ap);
    va_end(ap);
    return code;
}

static void warn_append(lf_warnings *w, const char *s, size_t len)
{
    if (w->len + len + 2 > w->cap) {
        size_t cap = w->cap ? w->cap : 256;
        while (cap < w->len + len + 2)
            cap *= 2;
        char *t = realloc(w->text, cap);
        if (!t) {
            w->lost++;
            return;
        }
        w->text = t;
        w->cap = cap;
    }
    memcpy(w->text + w->len, s, len);
    w->len += len;
    if (len == 0 || s[len - 1] != '\n')
        w->text[w->len++] = '\n';
    w->text[w->len] = '\0';
    w->count++;
}

void lf_warn_at(lf_warnings *w, const lf_loc *loc, const char *fmt, ...)
{
    if (!w)
        return;
    char line[1536];
    size_t off = 0;
    if (loc) {
        lf_loc_format(line, 512, loc);
        off = strlen(line);
        off += (size_t)snprintf(line + off, sizeof line - off, ": ");
    }
    snprintf(line + off, sizeof line - off, "warning: ");
    off = strlen(line);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line + off, sizeof line - off, fmt, ap);
    va_end(ap);
    warn_append(w, line, strlen(line));
}

void lf_warn_text(lf_warnings *w, const char *text)
{
    if (!w || !text)
        return;
    while (*text) {
        const char *nl = strchr(text, '\n');
        size_t len = nl ? (size_t)(nl - text) + 1 : strlen(text);
        warn_append(w, text, len);
        text += len;
    }
}

const char *lf_warnings_text(const lf_warnings *w) { return w && w->len ? w->text : NULL; }

void lf_warnings_free(lf_warnings *w)
{
    if (!w)
        return;
    free(w->text);
    w->text = NULL;
    w->len = w->cap = 0;
    w->count = w->lost = 0;
}
