/* lf_buf.h - growable arrays and a string buffer, the two containers every
 * module needs.
 *
 *   lf_vec3 *pts = NULL; size_t n = 0, cap = 0;
 *   if (lf_array_reserve((void **)&pts, &cap, n + 1, sizeof *pts)) return LF_ERR_NOMEM;
 *   pts[n++] = p;
 *
 *   lf_strbuf b = {0};
 *   lf_strbuf_printf(&b, "%d views\n", n);
 *   if (b.failed) ...;            // out of memory at some point: b.s is still valid text
 *   puts(b.s ? b.s : "");
 *   lf_strbuf_free(&b);
 *
 * Growth doubles the capacity (amortised O(1) appends); sizes that would
 * overflow size_t fail like an allocation failure, never wrap.
 */
#ifndef LF_BUF_H
#define LF_BUF_H

#include <stdarg.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Makes *data hold at least `need` elements of elem_size bytes, doubling
 * *cap as needed.  Returns 0, or -1 (data and cap unchanged) when memory
 * runs out or the size overflows. */
int lf_array_reserve(void **data, size_t *cap, size_t need, size_t elem_size);

typedef struct lf_strbuf {
    char *s;    /* NUL-terminated text, or NULL while empty */
    size_t len; /* bytes before the NUL */
    size_t cap;
    int failed; /* set when an append ran out of memory (the text is cut there) */
} lf_strbuf;

/* Appends n bytes / a string / formatted text.  Return 0, or -1 after
 * setting b->failed. */
int lf_strbuf_append(lf_strbuf *b, const char *text, size_t n);
int lf_strbuf_puts(lf_strbuf *b, const char *text);
int lf_strbuf_printf(lf_strbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
int lf_strbuf_vprintf(lf_strbuf *b, const char *fmt, va_list ap);
/* Hands the text to the caller (free() it) and empties the buffer.  Never
 * NULL unless memory ran out: an empty buffer gives "". */
char *lf_strbuf_take(lf_strbuf *b);
void lf_strbuf_free(lf_strbuf *b);

#ifdef __cplusplus
}
#endif
#endif
