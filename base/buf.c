/* Growable arrays and the string buffer (lf_buf.h). */
#include "lf_buf.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int lf_array_reserve(void **data, size_t *cap, size_t need, size_t elem_size)
{
    if (need <= *cap)
        return 0;
    if (elem_size == 0)
        return -1;
    size_t c = *cap ? *cap : 8;
    while (c < need) {
        if (c > SIZE_MAX / 2)
            return -1;
        c *= 2;
    }
    if (c > SIZE_MAX / elem_size)
        return -1;
    void *p = realloc(*data, c * elem_size);
    if (!p)
        return -1;
    *data = p;
    *cap = c;
    return 0;
}

int lf_strbuf_append(lf_strbuf *b, const char *text, size_t n)
{
    if (b->failed)
        return -1;
    if (n > SIZE_MAX - b->len - 1 || lf_array_reserve((void **)&b->s, &b->cap, b->len + n + 1, 1)) {
        b->failed = 1;
        return -1;
    }
    memcpy(b->s + b->len, text, n);
    b->len += n;
    b->s[b->len] = '\0';
    return 0;
}

int lf_strbuf_puts(lf_strbuf *b, const char *text)
{
    return lf_strbuf_append(b, text, strlen(text));
}

int lf_strbuf_vprintf(lf_strbuf *b, const char *fmt, va_list ap)
{
    if (b->failed)
        return -1;
    va_list again;
    va_copy(again, ap);
    char small[256];
    int n = vsnprintf(small, sizeof small, fmt, ap);
    if (n < 0) {
        va_end(again);
        b->failed = 1;
        return -1;
    }
    int rc;
    if ((size_t)n < sizeof small) {
        rc = lf_strbuf_append(b, small, (size_t)n);
    } else if (lf_array_reserve((void **)&b->s, &b->cap, b->len + (size_t)n + 1, 1)) {
        b->failed = 1;
        rc = -1;
    } else {
        vsnprintf(b->s + b->len, (size_t)n + 1, fmt, again);
        b->len += (size_t)n;
        rc = 0;
    }
    va_end(again);
    return rc;
}

int lf_strbuf_printf(lf_strbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = lf_strbuf_vprintf(b, fmt, ap);
    va_end(ap);
    return rc;
}

char *lf_strbuf_take(lf_strbuf *b)
{
    char *s = b->s;
    if (!s && !b->failed)
        s = calloc(1, 1);
    b->s = NULL;
    b->len = b->cap = 0;
    b->failed = 0;
    return s;
}

void lf_strbuf_free(lf_strbuf *b)
{
    free(b->s);
    b->s = NULL;
    b->len = b->cap = 0;
    b->failed = 0;
}
