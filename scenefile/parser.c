/* parser.c - the pbrt-v4 scene-file reader (see lf_scene_desc.h).
 *
 * A hand-written tokenizer feeds a table of directive handlers that keep
 * pbrt-v4's graphics state (BasicSceneBuilder in pbrt-v4's scene.cpp): two
 * CTMs, attribute stack, named coordinate systems, materials, textures and
 * object instances.  Every error names file:line:col.  Errors are collected:
 * after one, the parser skips to the next directive name and goes on, up to
 * max_errors; if there was any, everything built is freed at the end.
 *
 * Files are read as streams (lf_file_stream: gzip detected by its magic
 * bytes) through a window of 64 KiB, so memory follows the tokens kept,
 * not the file's size: pbrt-v4 maps plain files and inflates .gz files
 * whole, where one 3 GB comment line costs 3 GB.  Tokens are bounded
 * instead (LX_MAX_STRING, LX_MAX_BARE).  Include and Import push the file
 * onto the lexer's stack of frames, so the token stream continues into the
 * included file and back out of it, as pbrt-v4's tokenizer does: a
 * parameter list may span the end of an included file.
 *
 * Where lensfield deliberately differs from pbrt-v4 (all documented at the
 * handler): Include paths are relative to the including file; TransformBegin
 * saves only the CTMs (pbrt-v3 semantics, which is what files that still use
 * it expect); WorldEnd, ColorSpace and Option are accepted with a warning;
 * an unclosed AttributeBegin is a warning.  Shapes, lights, materials and
 * media lensfield cannot render are errors ("not supported") unless
 * lf_parse_opts.allow_unsupported, which turns them into warnings
 * (docs/scene-format.md).
 */
#include "lf_scene_desc.h"
#include "base/lf_color.h"
#include "base/lf_file.h"
#include "base/lf_suggest.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define MAX_INCLUDE_DEPTH 64
/* AttributeBegin/ObjectBegin/TransformBegin nesting: each level keeps a
 * copy of the graphics state (about 6 KB), so 1M levels in a 15 KB .pbrt.gz
 * took 6 GB.  Real scenes nest a few levels (exporters: tens); 10,000 keeps
 * the stack under 60 MB. */
#define MAX_BLOCK_DEPTH 10000
/* Values in one parameter: 2^28 numbers are 2 GiB as doubles and at least
 * 512 MB of text (89 million triangles' indices); the file is read as a
 * stream, so this is what bounds memory for a run of numbers (a 14 MB
 * .pbrt.gz can hold 3 GB of "0 ", 12 GB as doubles).  Meshes that large
 * belong in PLY files, whose counts are checked against the file. */
#define MAX_PARAM_VALUES ((size_t)1 << 28)

/* ------------------------------------------------------------------------ */
/* Small utilities                                                          */

static char *dup_range(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static char *dup_cstr(const char *s) { return dup_range(s, strlen(s)); }

/* Grows *arr so that it holds at least count + 1 elements. */
static int grow(void **arr, size_t *cap, size_t count, size_t elem)
{
    if (count < *cap)
        return 0;
    size_t ncap = *cap ? *cap * 2 : 8;
    void *p = realloc(*arr, ncap * elem);
    if (!p)
        return -1;
    *arr = p;
    *cap = ncap;
    return 0;
}

/* String -> int map with borrowed keys (the names live in the description
 * or in the parser), open addressing; for named materials, textures,
 * objects and coordinate systems, which large scenes have thousands of. */
typedef struct strmap {
    const char **keys;
    int *vals;
    size_t cap, count;
} strmap;

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ull;
    return h;
}

static int strmap_get(const strmap *m, const char *key)
{
    if (!m->cap)
        return -1;
    for (size_t i = hash_str(key) & (m->cap - 1);; i = (i + 1) & (m->cap - 1)) {
        if (!m->keys[i])
            return -1;
        if (strcmp(m->keys[i], key) == 0)
            return m->vals[i];
    }
}

static int strmap_put(strmap *m, const char *key, int val);

static int strmap_rehash(strmap *m, size_t ncap)
{
    strmap n = {calloc(ncap, sizeof *n.keys), calloc(ncap, sizeof *n.vals), ncap, 0};
    if (!n.keys || !n.vals) {
        free(n.keys);
        free(n.vals);
        return -1;
    }
    for (size_t i = 0; i < m->cap; i++)
        if (m->keys[i])
            strmap_put(&n, m->keys[i], m->vals[i]);
    free(m->keys);
    free(m->vals);
    *m = n;
    return 0;
}

/* Inserts or replaces. */
static int strmap_put(strmap *m, const char *key, int val)
{
    if (2 * (m->count + 1) > m->cap && strmap_rehash(m, m->cap ? 2 * m->cap : 16))
        return -1;
    size_t i = hash_str(key) & (m->cap - 1);
    while (m->keys[i] && strcmp(m->keys[i], key) != 0)
        i = (i + 1) & (m->cap - 1);
    if (!m->keys[i])
        m->count++;
    m->keys[i] = key;
    m->vals[i] = val;
    return 0;
}

static void strmap_free(strmap *m)
{
    free(m->keys);
    free(m->vals);
    memset(m, 0, sizeof *m);
}

/* ------------------------------------------------------------------------ */
/* Tokenizer                                                                */

typedef enum tok_kind { TK_EOF, TK_STRING, TK_NUMBER, TK_WORD, TK_LBRACK, TK_RBRACK } tok_kind;

typedef struct token {
    tok_kind kind;
    const char *s; /* text (in the lexer's token store); for strings, between the quotes, escapes undecoded */
    size_t n;
    double num;    /* TK_NUMBER */
    int escaped;   /* TK_STRING contains a backslash */
    lf_loc loc;
    const char *dir; /* directory of the file it was read from (Include, plymesh paths) */
} token;

/* Files are read as streams through a window (LX_WINDOW bytes a frame),
 * and each token's text is copied out of it into the token store, so memory
 * follows the tokens kept, not the file: a 3 GB comment or run of blanks
 * costs nothing, and a value list (a mesh of millions of numbers) keeps only
 * its parsed numbers.  A token is bounded instead: */
#ifndef LF_LEX_WINDOW
#define LF_LEX_WINDOW 65536 /* the fuzz build makes it tiny (CMakeLists.txt) */
#endif
#define LX_WINDOW ((size_t)LF_LEX_WINDOW)
/* a quoted string: file names, types and names are far shorter, and a
 * string array is a list of such strings */
#define LX_MAX_STRING 65536
/* a number or a bare word (directive names, true/false): numbers were
 * already refused from 128 characters (17 significant digits and an
 * exponent need 25) and the longest directive name has 22 */
#define LX_MAX_BARE 128
/* The token store: blocks that never move (tokens point into them); a token
 * starts a new block when the longest string might not fit.  Text is
 * released at each directive, after each parameter and after each value of
 * a list (lx_mark/lx_release), so a few tokens live at a time. */
#define LX_BLOCK ((size_t)1 << 20)

/* One file being read.  Include pushes a frame and the lexer pops it at its
 * end, so the token stream runs on into the including file as in pbrt-v4:
 * a parameter list may start in one file and continue in the other. */
typedef struct lx_frame {
    lf_file_stream *in; /* the file; NULL for a text given whole (lf_scene_parse_string) */
    const char *text;   /* ... which goes through the window too, so both read alike */
    size_t text_left;
    char *window;       /* LX_WINDOW bytes */
    const char *p, *end; /* what is left to read of the window (or the text) */
    int at_end;         /* nothing follows end */
    lf_error read_error; /* a stream that failed: reported once, at its end */
    long long line, col; /* 64-bit: a line over 2 GiB was undefined behaviour in an int */
    const char *file;   /* kept in the description's strings */
    const char *dir;    /* directory of file */
    lf_loc from;        /* the Include that opened it (line 0 for the top-level file) */
    int included;       /* read by Include/Import: refused whole if it does not start as a scene */
    int directives;     /* directives read from it so far */
} lx_frame;

typedef struct lexer {
    lx_frame *fr;
    int n_fr, cap_fr;
    char **blocks;      /* the token store */
    size_t n_blocks, cur_block, used; /* text is appended at blocks[cur_block] + used */
    token peeked;
    int has_peek;
} lexer;

typedef struct parser parser;
static int nomem(parser *P);
static int perr(parser *P, int code, const lf_loc *loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Refills an empty window from the stream.  0 at the end (or when reading
 * failed: the error is kept for lex_scan to report). */
static int lx_fill(lx_frame *L)
{
    if (L->at_end)
        return 0;
    size_t got = 0;
    if (!L->in) {
        got = L->text_left < LX_WINDOW ? L->text_left : LX_WINDOW;
        memcpy(L->window, L->text, got);
        L->text += got;
        L->text_left -= got;
    } else if (lf_file_stream_read(L->in, L->window, LX_WINDOW, &got, &L->read_error)) {
        got = 0;
    }
    if (got == 0) {
        L->at_end = 1;
        return 0;
    }
    L->p = L->window;
    L->end = L->window + got;
    return 1;
}

static inline int lx_peekc(lx_frame *L)
{
    if (L->p == L->end && !lx_fill(L))
        return EOF;
    return (unsigned char)*L->p;
}

static inline int lx_getc(lx_frame *L)
{
    if (L->p == L->end && !lx_fill(L))
        return EOF;
    int c = (unsigned char)*L->p++;
    if (c == '\n') {
        L->line++;
        L->col = 1;
    } else {
        L->col++;
    }
    return c;
}

/* Skips to the end of the line (a comment), a window at a time. */
static void lx_skip_line(lx_frame *L)
{
    for (;;) {
        if (L->p == L->end && !lx_fill(L))
            return;
        const char *q = L->p;
        while (q < L->end && *q != '\n' && *q != '\r')
            q++;
        L->col += q - L->p;
        L->p = q;
        if (q < L->end)
            return;
    }
}

/* Where the token store will write next, to give back with lx_release. */
static size_t lx_mark(const lexer *X) { return X->cur_block * LX_BLOCK + X->used; }

static int lx_text_begin(lexer *X, char **start);

/* Where p is in the store (as lx_mark counts), or SIZE_MAX outside it. */
static size_t lx_pos(const lexer *X, const char *p)
{
    for (size_t b = 0; p && b < X->n_blocks; b++)
        if (p >= X->blocks[b] && p < X->blocks[b] + LX_BLOCK)
            return b * LX_BLOCK + (size_t)(p - X->blocks[b]);
    return SIZE_MAX;
}

/* Gives back the text of the tokens read since mark, which must no longer
 * be needed; a peeked token read since then is kept (moved down to mark). */
static void lx_release(lexer *X, size_t mark)
{
    if (mark >= lx_mark(X))
        return;
    size_t at = X->has_peek ? lx_pos(X, X->peeked.s) : SIZE_MAX;
    size_t cur = X->cur_block, used = X->used;
    X->cur_block = mark / LX_BLOCK;
    X->used = mark % LX_BLOCK;
    if (at == SIZE_MAX || at < mark)
        return;
    char *start;
    if (lx_text_begin(X, &start)) { /* no memory for a block: keep everything */
        X->cur_block = cur, X->used = used;
        return;
    }
    memmove(start, X->peeked.s, X->peeked.n + 1);
    X->peeked.s = start;
    X->used += X->peeked.n + 1;
}

/* Starts a token's text in the store: *start receives where it begins (a
 * token is kept whole in one block).  -1: no memory. */
static int lx_text_begin(lexer *X, char **start)
{
    if (X->n_blocks == 0 || X->used + LX_MAX_STRING + 2 > LX_BLOCK) {
        if (X->n_blocks && X->cur_block + 1 < X->n_blocks) {
            X->cur_block++;
        } else {
            char **nb = realloc(X->blocks, (X->n_blocks + 1) * sizeof *nb);
            if (!nb)
                return -1;
            X->blocks = nb;
            if (!(nb[X->n_blocks] = malloc(LX_BLOCK)))
                return -1;
            X->cur_block = X->n_blocks++;
        }
        X->used = 0;
    }
    *start = X->blocks[X->cur_block] + X->used;
    return 0;
}

/* Ends a token of n bytes begun at start (NUL-terminated, not counted). */
static void lx_text_end(lexer *X, char *start, size_t n)
{
    start[n] = '\0';
    X->used += n + 1;
}

static int lx_push(lexer *X, lf_file_stream *in, const char *text, size_t len, const char *file, const char *dir,
                   const lf_loc *from)
{
    if (X->n_fr == X->cap_fr) {
        int nc = X->cap_fr ? 2 * X->cap_fr : 8;
        lx_frame *n = realloc(X->fr, (size_t)nc * sizeof *n);
        if (!n)
            return -1;
        X->fr = n;
        X->cap_fr = nc;
    }
    lx_frame *L = &X->fr[X->n_fr];
    memset(L, 0, sizeof *L);
    if (!(L->window = malloc(LX_WINDOW)))
        return -1;
    L->in = in;
    L->text = text;
    L->text_left = len;
    L->p = L->end = L->window;
    L->line = L->col = 1;
    L->file = file;
    L->dir = dir;
    L->from = from ? *from : (lf_loc){0};
    L->included = X->n_fr > 0;
    X->n_fr++;
    return 0;
}

/* Ends the innermost file.  Token text lives in the store, so the stream
 * and its window go at once. */
static void lx_pop(lexer *X)
{
    lx_frame *F = &X->fr[--X->n_fr];
    lf_file_stream_close(F->in);
    free(F->window);
}

static void lx_free(lexer *X)
{
    while (X->n_fr)
        lx_pop(X);
    for (size_t b = 0; b < X->n_blocks; b++)
        free(X->blocks[b]);
    free(X->blocks);
    free(X->fr);
    memset(X, 0, sizeof *X);
}

static int is_space(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

static int is_bare_end(int c) { return is_space(c) || c == '"' || c == '[' || c == ']' || c == '#'; }

static int is_escape_char(int c) { return c && strchr("bfnrt\\'\"", c) != NULL; }

/* A stream that failed (corrupt gzip data half-way, a read error): named as
 * push_file names a file it cannot read. */
static int lx_report_read_error(parser *P, lx_frame *L)
{
    const char *what = L->read_error.msg;
    size_t pl = strlen(L->file);
    if (strncmp(what, L->file, pl) == 0 && what[pl] == ':' && what[pl + 1] == ' ')
        what += pl + 2;
    int code = L->read_error.code;
    lf_error_clear(&L->read_error);
    if (L->from.line)
        return perr(P, code, &L->from, "cannot read included file \"%s\": %s", L->file, what);
    return perr(P, code, NULL, "cannot read scene file \"%s\": %s", L->file, what);
}

/* Skips blanks and comments, leaving included files at their end.  0 with
 * *L the frame of the next token (or of the end of everything); an error
 * when a file could not be read to its end. */
static int lex_skip(parser *P, lexer *X, lx_frame **out)
{
    lx_frame *L = &X->fr[X->n_fr - 1];
    for (;;) {
        int c = lx_peekc(L);
        if (c == EOF) {
            if (L->read_error.code)
                return lx_report_read_error(P, L);
            if (X->n_fr == 1)
                break;
            lx_pop(X); /* end of an included file: continue in the includer */
            L = &X->fr[X->n_fr - 1];
        } else if (is_space(c)) {
            const char *q = L->p, *newline = NULL; /* the blanks in the window at once */
            for (; q < L->end; q++) {
                char b = *q;
                if (b == ' ' || b == '\t')
                    continue;
                if (b == '\n') {
                    L->line++;
                    newline = q;
                } else if (!is_space((unsigned char)b)) {
                    break;
                }
            }
            L->col = newline ? q - newline : L->col + (q - L->p);
            L->p = q;
        } else if (c == '#') {
            lx_skip_line(L);
        } else {
            break;
        }
    }
    *out = L;
    return LF_OK;
}

/* Past the rest of a string too long to keep: to its closing quote, the
 * end of the line or of the file, as its scan would have stopped. */
static void lx_skip_string(lx_frame *L)
{
    int c;
    while ((c = lx_getc(L)) != EOF && c != '"' && c != '\n')
        if (c == '\\' && lx_getc(L) == EOF)
            return;
}

static int lex_string(parser *P, lexer *X, lx_frame *L, token *t, char *text)
{
    size_t n = 0;
    t->kind = TK_STRING;
    for (;;) {
        int c = lx_getc(L);
        if (c == EOF)
            return perr(P, LF_ERR_PARSE, &t->loc, "unterminated string: end of file before the closing '\"'");
        if (c == '\n')
            return perr(P, LF_ERR_PARSE, &t->loc, "unterminated string: newline before the closing '\"'");
        if (c == '"')
            break;
        if (n >= LX_MAX_STRING) {
            lx_skip_string(L);
            return perr(P, LF_ERR_PARSE, &t->loc,
                        "string longer than %d bytes: expected its closing '\"' within that (file names, types and "
                        "names are far shorter)",
                        LX_MAX_STRING);
        }
        text[n++] = (char)c;
        if (c == '\\') {
            int e = lx_getc(L);
            if (!is_escape_char(e))
                return perr(P, LF_ERR_PARSE, &t->loc,
                            e == EOF ? "unterminated string: end of file after '\\'"
                                     : "unknown escape sequence in string");
            text[n++] = (char)e; /* the store has room for one more than LX_MAX_STRING */
            t->escaped = 1;
        }
    }
    lx_text_end(X, text, n);
    t->s = text;
    t->n = n;
    return LF_OK;
}

/* A bare token: a directive, a number, or true/false.  text[0] holds its
 * first character. */
static int lex_bare(parser *P, lexer *X, lx_frame *L, token *t, char *text)
{
    long long n = 1;
    for (;;) { /* a window at a time; a bare token never holds a newline */
        if (L->p == L->end && !lx_fill(L))
            break;
        const char *q = L->p;
        for (; q < L->end && !is_bare_end((unsigned char)*q); q++, n++)
            if (n < LX_MAX_BARE)
                text[n] = *q;
        L->col += q - L->p;
        L->p = q;
        if (q < L->end)
            break;
    }
    char first = text[0];
    int numeric = isdigit((unsigned char)first) || first == '-' || first == '+' || first == '.';
    if (n >= LX_MAX_BARE) {
        if (numeric) {
            text[40] = '\0';
            return perr(P, LF_ERR_PARSE, &t->loc, "invalid number \"%s...\"", text);
        }
        /* not echoed: it may be the first token of a file that is no scene */
        return perr(P, LF_ERR_PARSE, &t->loc,
                    "a word of %lld characters: expected a directive, a number, true or false (at most %d "
                    "characters)",
                    n, LX_MAX_BARE - 1);
    }
    lx_text_end(X, text, (size_t)n);
    t->s = text;
    t->n = (size_t)n;
    if (!numeric) {
        t->kind = TK_WORD;
        return LF_OK;
    }
    char *end;
    double v = strtod(text, &end);
    if (end != text + n)
        return perr(P, LF_ERR_PARSE, &t->loc, "invalid number \"%s\"", text);
    if (!isfinite(v))
        return perr(P, LF_ERR_NUMERIC, &t->loc, "non-finite number \"%s\"", text);
    t->kind = TK_NUMBER;
    t->num = v;
    return LF_OK;
}

static int lex_scan(parser *P, lexer *X, token *t)
{
    memset(t, 0, sizeof *t);
    lx_frame *L = NULL;
    int rc = lex_skip(P, X, &L);
    if (rc)
        return rc;
    t->loc = (lf_loc){L->file, L->line, L->col};
    t->dir = L->dir;
    int c = lx_getc(L);
    if (c == EOF) {
        t->kind = TK_EOF;
        return LF_OK;
    }
    if (c == '[' || c == ']') {
        t->kind = c == '[' ? TK_LBRACK : TK_RBRACK;
        t->s = c == '[' ? "[" : "]";
        t->n = 1;
        return LF_OK;
    }
    char *text;
    if (lx_text_begin(X, &text))
        return nomem(P);
    if (c == '"')
        return lex_string(P, X, L, t, text);
    text[0] = (char)c;
    return lex_bare(P, X, L, t, text);
}

static int lex_next(parser *P, lexer *L, token *t)
{
    if (L->has_peek) {
        *t = L->peeked;
        L->has_peek = 0;
        return LF_OK;
    }
    return lex_scan(P, L, t);
}

static int lex_peek(parser *P, lexer *L, token *t)
{
    if (!L->has_peek) {
        int rc = lex_scan(P, L, &L->peeked);
        if (rc)
            return rc;
        L->has_peek = 1;
    }
    *t = L->peeked;
    return LF_OK;
}

/* The decoded contents of a string token (malloc'ed), or NULL (no memory). */
static char *tok_string(const token *t)
{
    char *d = malloc(t->n + 1);
    if (!d)
        return NULL;
    size_t j = 0;
    for (size_t i = 0; i < t->n; i++) {
        char c = t->s[i];
        if (c == '\\' && i + 1 < t->n) {
            c = t->s[++i];
            switch (c) {
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'n': c = '\n'; break;
            case 'r': c = '\r'; break;
            case 't': c = '\t'; break;
            default: break; /* \\ \' \" stand for themselves */
            }
        }
        d[j++] = c;
    }
    d[j] = '\0';
    return d;
}

static int tok_is(const token *t, const char *word)
{
    size_t n = strlen(word);
    return t->n == n && memcmp(t->s, word, n) == 0;
}

/* What a token is, for messages: `string "abc"`, `number 3`, `"Shape"`. */
static const char *describe(const token *t, char *buf, size_t size)
{
    /* Up to 40 characters; bytes that are not printable ASCII (binary or
     * compressed data read as text) are shown as \xNN. */
    char text[4 * 40 + 1];
    size_t k = 0, lim = t->n > 40 ? 40 : t->n;
    for (size_t i = 0; i < lim; i++) {
        unsigned char c = (unsigned char)t->s[i];
        if (c >= 0x20 && c < 0x7f)
            text[k++] = (char)c;
        else
            k += (size_t)snprintf(text + k, sizeof text - k, "\\x%02x", c);
    }
    text[k] = '\0';
    int n = (int)k;
    const char *more = t->n > 40 ? "..." : "";
    switch (t->kind) {
    case TK_EOF: snprintf(buf, size, "end of file"); break;
    case TK_STRING: snprintf(buf, size, "string \"%.*s%s\"", n, text, more); break;
    case TK_NUMBER: snprintf(buf, size, "number %.*s%s", n, text, more); break;
    case TK_WORD: snprintf(buf, size, "\"%.*s%s\"", n, text, more); break;
    case TK_LBRACK: snprintf(buf, size, "'['"); break;
    case TK_RBRACK: snprintf(buf, size, "']'"); break;
    }
    return buf;
}

/* ------------------------------------------------------------------------ */
/* Parser state                                                             */

enum { ATTR_SHAPE, ATTR_LIGHT, ATTR_MATERIAL, ATTR_MEDIUM, ATTR_TEXTURE, ATTR_COUNT };
static const char *const attr_targets[ATTR_COUNT] = {"shape", "light", "material", "medium", "texture"};

/* pbrt-v4's GraphicsState, less what lensfield ignores (media, colour space). */
typedef struct gstate {
    lf_transform ctm[2];
    int active[2];
    int material;   /* >= 0: index; -1: none; <= -2: NamedMaterial reference -2 - material */
    int area_light; /* index into area_lights, or -1 */
    int reverse_orientation;
    const char *medium_inside, *medium_outside; /* MediumInterface names (kept strings), NULL: none given */
    lf_paramset attrs[ATTR_COUNT];
} gstate;

typedef struct pushed {
    char kind; /* 'a' AttributeBegin, 'o' ObjectBegin, 't' TransformBegin */
    lf_loc loc;
    gstate saved; /* for 't' only ctm and active are meaningful, attrs empty */
} pushed;

typedef struct named_ref { /* a name resolved after the whole scene is read */
    char *name;
    lf_loc loc;
} named_ref;

typedef struct coord_sys {
    char *name;
    lf_transform xf[2];
} coord_sys;

struct parser {
    lf_scene_desc *d;
    lf_error *err;
    gstate gs;
    pushed *stack;
    size_t n_stack, cap_stack;
    int world;          /* inside the world block */
    int current_object; /* ObjectBegin being defined, or -1 */

    coord_sys *coordsys;
    size_t n_coordsys, cap_coordsys;
    strmap coordsys_map, material_map, float_tex_map, spectrum_tex_map, object_map;

    named_ref *material_refs; /* NamedMaterial uses */
    size_t n_material_refs, cap_material_refs;
    named_ref *instance_refs; /* parallel to d->instances */
    size_t cap_instance_refs;

    size_t cap_strings, cap_textures, cap_materials, cap_lights, cap_area_lights, cap_shapes, cap_objects,
        cap_instances, cap_media;
    lf_warnings warnings; /* its text is d->warnings */
    int warned_transform_begin;
    /* Errors are collected: the parse goes on at the next directive, and
     * every message (up to max_errors) is kept here, one per line. */
    char *errors;
    size_t errors_len, errors_cap;
    int n_errors, max_errors, first_code;
    int allow_unsupported;
    const char *main_dir; /* directory of the top-level file */
};

static int perr(parser *P, int code, const lf_loc *loc, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    lf_error one = {0};
    lf_error_at(&one, code, loc, "%s", msg);
    const char *line = one.msg;
    if (P->n_errors++ == 0)
        P->first_code = code;
    lf_error_set(P->err, code, "%s", line);
    size_t len = strlen(line);
    if (P->errors_len + len + 2 > P->errors_cap) {
        size_t cap = P->errors_cap ? P->errors_cap : 1024;
        while (cap < P->errors_len + len + 2)
            cap *= 2;
        char *e = realloc(P->errors, cap);
        if (!e)
            return code; /* the first message is in P->err regardless */
        P->errors = e;
        P->errors_cap = cap;
    }
    memcpy(P->errors + P->errors_len, line, len);
    P->errors[P->errors_len + len] = '\n';
    P->errors[P->errors_len + len + 1] = '\0';
    P->errors_len += len + 1;
    return code;
}

static int nomem(parser *P) { return lf_error_set(P->err, LF_ERR_NOMEM, "out of memory while parsing the scene"); }

static void pwarn(parser *P, const lf_loc *loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static void pwarn(parser *P, const lf_loc *loc, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    lf_warn_at(&P->warnings, loc, "%s", msg);
    P->d->warnings = P->warnings.text; /* the description owns the text */
}

/* Keeps a copy of s alive as long as the description (file names for
 * lf_loc, base directories). */
static const char *keep_string(parser *P, const char *s)
{
    lf_scene_desc *d = P->d;
    if (grow((void **)&d->strings, &P->cap_strings, d->n_strings, sizeof *d->strings))
        return NULL;
    char *c = dup_cstr(s);
    if (!c)
        return NULL;
    d->strings[d->n_strings++] = c;
    return c;
}

static void gstate_free(gstate *g)
{
    for (int i = 0; i < ATTR_COUNT; i++)
        lf_params_free(&g->attrs[i]);
}

static int gstate_copy(gstate *dst, const gstate *src)
{
    *dst = *src;
    for (int i = 0; i < ATTR_COUNT; i++)
        memset(&dst->attrs[i], 0, sizeof dst->attrs[i]);
    for (int i = 0; i < ATTR_COUNT; i++)
        if (lf_params_copy(&dst->attrs[i], &src->attrs[i])) {
            gstate_free(dst);
            return -1;
        }
    return 0;
}

static lf_anim_xform current_xform(const parser *P)
{
    lf_anim_xform a;
    a.xf[0] = P->gs.ctm[0];
    a.xf[1] = P->gs.ctm[1];
    a.time[0] = P->d->transform_start_time;
    a.time[1] = P->d->transform_end_time;
    a.animated = memcmp(a.xf[0].m, a.xf[1].m, sizeof a.xf[0].m) != 0;
    return a;
}

/* CTM = CTM * t for each active CTM (pbrt's ForActiveTransforms). */
static void apply_transform(parser *P, const lf_transform *t)
{
    for (int i = 0; i < 2; i++)
        if (P->gs.active[i])
            P->gs.ctm[i] = lf_transform_compose(&P->gs.ctm[i], t);
}

static void set_transform(parser *P, const lf_transform *t)
{
    for (int i = 0; i < 2; i++)
        if (P->gs.active[i])
            P->gs.ctm[i] = *t;
}

static int set_coordsys(parser *P, const char *name, const lf_transform xf[2])
{
    int idx = strmap_get(&P->coordsys_map, name);
    if (idx >= 0) {
        P->coordsys[idx].xf[0] = xf[0];
        P->coordsys[idx].xf[1] = xf[1];
        return LF_OK;
    }
    if (grow((void **)&P->coordsys, &P->cap_coordsys, P->n_coordsys, sizeof *P->coordsys))
        return nomem(P);
    coord_sys *c = &P->coordsys[P->n_coordsys];
    if (!(c->name = dup_cstr(name)))
        return nomem(P);
    c->xf[0] = xf[0];
    c->xf[1] = xf[1];
    if (strmap_put(&P->coordsys_map, c->name, (int)P->n_coordsys)) {
        free(c->name);
        return nomem(P);
    }
    P->n_coordsys++;
    return LF_OK;
}

/* ------------------------------------------------------------------------ */
/* Arguments and parameter lists                                            */

static int is_nonfinite_word(const token *t);
static int join_path(const char *dir, const char *rel, char **out);
static int resolve_path(parser *P, const char *dir, const char *rel, char **out);

static int expect_numbers(parser *P, lexer *L, const token *dir, int n, double *out)
{
    for (int i = 0; i < n; i++) {
        token t;
        int rc = lex_next(P, L, &t);
        if (rc)
            return rc;
        char b[200];
        if (t.kind == TK_WORD && is_nonfinite_word(&t))
            return perr(P, LF_ERR_NUMERIC, &t.loc, "non-finite number %s in %.*s", describe(&t, b, sizeof b),
                        (int)dir->n, dir->s);
        if (t.kind != TK_NUMBER)
            return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects %d numbers, got %s after %d", (int)dir->n, dir->s, n,
                        describe(&t, b, sizeof b), i);
        out[i] = t.num;
    }
    return LF_OK;
}

/* Reads one quoted string argument of directive `dir` into *out (malloc'ed). */
static int expect_string(parser *P, lexer *L, const token *dir, const char *what, char **out, lf_loc *loc)
{
    token t;
    int rc = lex_next(P, L, &t);
    if (rc)
        return rc;
    if (t.kind != TK_STRING) {
        char b[200];
        return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects a quoted string (%s), got %s", (int)dir->n, dir->s, what,
                    describe(&t, b, sizeof b));
    }
    if (!(*out = tok_string(&t)))
        return nomem(P);
    if (loc)
        *loc = t.loc;
    return LF_OK;
}

/* What kind of value each parameter type takes. */
typedef enum value_class { VC_NUMBER, VC_STRING, VC_BOOL, VC_SPECTRUM } value_class;

static value_class class_of(lf_param_type t)
{
    switch (t) {
    case LF_PT_STRING:
    case LF_PT_TEXTURE: return VC_STRING;
    case LF_PT_BOOL: return VC_BOOL;
    case LF_PT_SPECTRUM: return VC_SPECTRUM;
    default: return VC_NUMBER;
    }
}

typedef struct value_acc {
    double *nums;
    size_t n_nums, cap_nums;
    char **strs;
    size_t n_strs, cap_strs;
    unsigned char *bools;
    size_t n_bools, cap_bools;
} value_acc;

static void acc_free(value_acc *a)
{
    free(a->nums);
    for (size_t i = 0; i < a->n_strs; i++)
        free(a->strs[i]);
    free(a->strs);
    free(a->bools);
    memset(a, 0, sizeof *a);
}

static int is_nonfinite_word(const token *t)
{
    static const char *const words[] = {"nan", "inf", "infinity"};
    for (size_t i = 0; i < 3; i++)
        if (t->n == strlen(words[i]) && strncasecmp(t->s, words[i], t->n) == 0)
            return 1;
    return 0;
}

/* Adds one value token to the parameter being read, checking it against the
 * declared type. */
static int add_value(parser *P, const token *t, lf_param_type type, const char *decl, value_acc *a)
{
    char b[200];
    value_class vc = class_of(type);
    if (a->n_nums + a->n_strs + a->n_bools >= MAX_PARAM_VALUES)
        return perr(P, LF_ERR_PARSE, &t->loc,
                    "parameter \"%s\" has more than %zu values: expected ']' (a mesh this large belongs in a PLY "
                    "file)",
                    decl, MAX_PARAM_VALUES);
    if (t->kind == TK_WORD && is_nonfinite_word(t))
        return perr(P, LF_ERR_NUMERIC, &t->loc, "non-finite number \"%.*s\" in parameter \"%s\"", (int)t->n, t->s,
                    decl);
    int is_bool_word = t->kind == TK_WORD && (tok_is(t, "true") || tok_is(t, "false"));
    if (t->kind == TK_NUMBER) {
        if (vc != VC_NUMBER && vc != VC_SPECTRUM)
            return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" expects %s, got %s", decl,
                        vc == VC_BOOL ? "true or false" : "a quoted string", describe(t, b, sizeof b));
        if (vc == VC_SPECTRUM && a->n_strs)
            return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" mixes a spectrum name and numbers", decl);
        if (type == LF_PT_INTEGER && (t->num != floor(t->num) || fabs(t->num) > 2147483647.0))
            return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" expects integers, got %s", decl,
                        describe(t, b, sizeof b));
        if (grow((void **)&a->nums, &a->cap_nums, a->n_nums, sizeof *a->nums))
            return nomem(P);
        a->nums[a->n_nums++] = t->num;
        return LF_OK;
    }
    if (t->kind == TK_STRING) {
        char *s = tok_string(t);
        if (!s)
            return nomem(P);
        if (vc == VC_BOOL) { /* pbrt-v4 also accepts "true" and "false" quoted */
            int v = strcmp(s, "true") == 0 ? 1 : strcmp(s, "false") == 0 ? 0 : -1;
            free(s);
            if (v < 0)
                return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" expects true or false, got %s", decl,
                            describe(t, b, sizeof b));
            if (grow((void **)&a->bools, &a->cap_bools, a->n_bools, 1))
                return nomem(P);
            a->bools[a->n_bools++] = (unsigned char)v;
            return LF_OK;
        }
        if (vc == VC_NUMBER || (vc == VC_SPECTRUM && (a->n_nums || a->n_strs))) {
            free(s);
            if (vc == VC_SPECTRUM)
                return perr(P, LF_ERR_PARSE, &t->loc,
                            "parameter \"%s\" expects (wavelength, value) pairs or one spectrum name, got %s", decl,
                            describe(t, b, sizeof b));
            return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" expects numbers, got %s", decl,
                        describe(t, b, sizeof b));
        }
        if (grow((void **)&a->strs, &a->cap_strs, a->n_strs, sizeof *a->strs)) {
            free(s);
            return nomem(P);
        }
        a->strs[a->n_strs++] = s;
        return LF_OK;
    }
    if (is_bool_word) {
        if (vc != VC_BOOL)
            return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\" expects %s, got %s", decl,
                        vc == VC_STRING ? "a quoted string" : "numbers", describe(t, b, sizeof b));
        if (grow((void **)&a->bools, &a->cap_bools, a->n_bools, 1))
            return nomem(P);
        a->bools[a->n_bools++] = tok_is(t, "true");
        return LF_OK;
    }
    return perr(P, LF_ERR_PARSE, &t->loc, "parameter \"%s\": expected a value, got %s", decl, describe(t, b, sizeof b));
}

/* Value-count rules pbrt-v4 enforces when it builds a ParameterDictionary. */
static int check_count(parser *P, const lf_loc *loc, lf_param_type type, const char *decl, const value_acc *a)
{
    size_t n = a->n_nums;
    switch (type) {
    case LF_PT_POINT2:
    case LF_PT_VECTOR2:
        if (n % 2)
            return perr(P, LF_ERR_PARSE, loc, "parameter \"%s\" has %zu values, not a multiple of 2", decl, n);
        break;
    case LF_PT_POINT3:
    case LF_PT_VECTOR3:
    case LF_PT_NORMAL3:
        if (n % 3)
            return perr(P, LF_ERR_PARSE, loc, "parameter \"%s\" has %zu values, not a multiple of 3", decl, n);
        break;
    case LF_PT_RGB:
        /* several triples only for per-voxel grids (MakeNamedMedium "rgbgrid");
         * a single colour read from more is an error at its lookup */
        if (n == 0 || n % 3)
            return perr(P, LF_ERR_PARSE, loc, "parameter \"%s\" needs 3 values, got %zu (or 3 per sample of a grid)",
                        decl, n);
        break;
    case LF_PT_BLACKBODY:
        if (n != 1)
            return perr(P, LF_ERR_PARSE, loc,
                        "parameter \"%s\" needs 1 value (temperature in kelvin; pbrt-v3's scale is gone), got %zu",
                        decl, n);
        break;
    case LF_PT_SPECTRUM:
        if (a->n_strs == 0 && (n < 2 || n % 2))
            return perr(P, LF_ERR_PARSE, loc,
                        "parameter \"%s\" needs (wavelength, value) pairs or one spectrum name, got %zu numbers", decl,
                        n);
        break;
    case LF_PT_TEXTURE:
        if (a->n_strs != 1)
            return perr(P, LF_ERR_PARSE, loc, "parameter \"%s\" needs 1 texture name, got %zu", decl, a->n_strs);
        break;
    default: break;
    }
    return LF_OK;
}

/* A "spectrum" parameter naming neither a built-in spectrum nor numbers
 * names a spectrum file (pbrt-v4): it is read here, relative to the
 * directory of the file the parameter was written in, and becomes the same
 * (wavelength, value) pairs as if they had been written inline. */
static int load_spectrum_file(parser *P, const token *t, lf_param_type type, const char *decl, value_acc *a)
{
    lf_vec3 dummy;
    if (type != LF_PT_SPECTRUM || a->n_strs != 1 || a->n_nums || lf_named_spectrum_rgb(a->strs[0], &dummy) == 0)
        return LF_OK;
    char *path;
    if (resolve_path(P, t->dir, a->strs[0], &path))
        return nomem(P);
    double *v;
    size_t n;
    lf_error fe = {0};
    int rc = lf_spectrum_file_read(path, &v, &n, &fe);
    free(path);
    if (rc == LF_ERR_NOMEM)
        return nomem(P);
    if (rc)
        return perr(P, rc, &t->loc,
                    "parameter \"%s\": \"%s\" is not a named spectrum (see docs/scene-format.md), and as a spectrum "
                    "file: %s",
                    decl, a->strs[0], fe.msg);
    free(a->strs[0]);
    free(a->strs);
    a->strs = NULL;
    a->n_strs = a->cap_strs = 0;
    free(a->nums);
    a->nums = v;
    a->n_nums = a->cap_nums = 2 * n;
    return LF_OK;
}

/* Splits a "type name" declaration. */
static int split_decl(parser *P, const token *t, const char *decl, lf_param_type *type, char **name)
{
    const char *p = decl;
    while (*p == ' ' || *p == '\t')
        p++;
    const char *type_b = p;
    while (*p && *p != ' ' && *p != '\t')
        p++;
    const char *type_e = p;
    while (*p == ' ' || *p == '\t')
        p++;
    const char *name_b = p;
    while (*p && *p != ' ' && *p != '\t')
        p++;
    const char *name_e = p;
    while (*p == ' ' || *p == '\t')
        p++;
    if (type_b == type_e || name_b == name_e || *p)
        return perr(P, LF_ERR_PARSE, &t->loc, "malformed parameter declaration \"%s\": expected \"type name\"", decl);
    char word[64];
    size_t tn = (size_t)(type_e - type_b);
    if (tn >= sizeof word)
        tn = sizeof word - 1;
    memcpy(word, type_b, tn);
    word[tn] = '\0';
    if (lf_param_type_from_name(word, type))
        return perr(P, LF_ERR_PARSE, &t->loc, "unknown parameter type \"%s\" in \"%s\"", word, decl);
    if (!(*name = dup_range(name_b, (size_t)(name_e - name_b))))
        return nomem(P);
    return LF_OK;
}

typedef int (*directive_fn)(parser *P, lexer *L, const token *dir);
static directive_fn find_directive(const token *t);

/* Puts back a directive name that ended a malformed construct, so that the
 * parse resumes at it after the error (only right after lex_next). */
static int is_directive_like(const token *t);
static void unget_directive(lexer *L, const token *t)
{
    if (!L->has_peek && is_directive_like(t)) {
        L->peeked = *t;
        L->has_peek = 1;
    }
}

/* pbrt-v4's ParameterDictionary looks parameters up from the last one
 * given, and its unused-parameter check lets an earlier parameter of the
 * same type and name pass as shadowed: so a parameter given twice in one
 * statement takes its last value, silently.  The earlier one is replaced
 * here (1), which is that rule.  The same name with another type stays a
 * separate parameter: pbrt reads only the type it asks for and reports
 * the other as unused, and so does lensfield. */
static int replace_duplicate(lf_paramset *out, lf_param *p)
{
    for (size_t i = 0; i < out->count; i++) {
        lf_param *q = &out->items[i];
        if (q->type != p->type || strcmp(q->name, p->name) != 0)
            continue;
        free(q->name);
        free(q->nums);
        for (size_t k = 0; k < q->n_strs; k++)
            free(q->strs[k]);
        free(q->strs);
        free(q->bools);
        *q = *p;
        return 1;
    }
    return 0;
}

/* Reads the parameter list that follows a directive's fixed arguments:
 * pairs of "type name" and a value or [ values ], up to the next token that
 * is not a quoted string. */
static int parse_params(parser *P, lexer *L, lf_paramset *out)
{
    for (;;) {
        token t;
        size_t param_mark = lx_mark(L); /* a parameter's own copies are kept, not its tokens */
        int rc = lex_peek(P, L, &t);
        if (rc)
            return rc;
        if (t.kind != TK_STRING)
            return LF_OK;
        lex_next(P, L, &t);
        char *decl = tok_string(&t);
        if (!decl)
            return nomem(P);
        lf_param_type type;
        char *name = NULL;
        if ((rc = split_decl(P, &t, decl, &type, &name))) {
            free(decl);
            return rc;
        }
        value_acc a = {0};
        token v;
        if ((rc = lex_next(P, L, &v)))
            goto fail;
        if (v.kind == TK_LBRACK) {
            token open = v;
            for (;;) {
                size_t value_mark = lx_mark(L); /* each value is kept parsed, its text released */
                if ((rc = lex_next(P, L, &v)))
                    goto fail;
                if (v.kind == TK_RBRACK)
                    break;
                if (v.kind == TK_EOF) {
                    rc = perr(P, LF_ERR_PARSE, &open.loc, "unclosed '[' in parameter \"%s\": end of file before ']'",
                              decl);
                    goto fail;
                }
                if (v.kind == TK_LBRACK || (v.kind == TK_WORD && !tok_is(&v, "true") && !tok_is(&v, "false") &&
                                            !is_nonfinite_word(&v))) {
                    unget_directive(L, &v); /* the parse goes on there */
                    char b[200];
                    rc = perr(P, LF_ERR_PARSE, &v.loc, "expected a value or ']' to close the '[' at %lld:%lld, got %s",
                              open.loc.line, open.loc.col, describe(&v, b, sizeof b));
                    goto fail;
                }
                if ((rc = add_value(P, &v, type, decl, &a)))
                    goto fail;
                lx_release(L, value_mark);
            }
        } else if (v.kind == TK_NUMBER || v.kind == TK_STRING ||
                   (v.kind == TK_WORD && (tok_is(&v, "true") || tok_is(&v, "false") || is_nonfinite_word(&v)))) {
            if ((rc = add_value(P, &v, type, decl, &a)))
                goto fail;
        } else {
            unget_directive(L, &v);
            char b[200];
            rc = perr(P, LF_ERR_PARSE, &v.loc, "parameter \"%s\" has no value: expected a value or '[', got %s", decl,
                      describe(&v, b, sizeof b));
            goto fail;
        }
        if ((rc = check_count(P, &t.loc, type, decl, &a)))
            goto fail;
        if ((rc = load_spectrum_file(P, &t, type, decl, &a)))
            goto fail;
        lf_param p = {0};
        p.type = type;
        p.name = name;
        p.nums = a.nums;
        p.n_nums = a.n_nums;
        p.strs = a.strs;
        p.n_strs = a.n_strs;
        p.bools = a.bools;
        p.n_bools = a.n_bools;
        p.loc = t.loc;
        if (!replace_duplicate(out, &p) && lf_params_add(out, &p)) {
            rc = nomem(P);
            goto fail;
        }
        free(decl);
        lx_release(L, param_mark);
        continue;
    fail:
        acc_free(&a);
        free(name);
        free(decl);
        return rc;
    }
}

/* "type" params: the common shape of Shape, Camera, Material, ... */
static int parse_entity(parser *P, lexer *L, const token *dir, const char *what, lf_entity *e)
{
    memset(e, 0, sizeof *e);
    e->loc = dir->loc;
    int rc = expect_string(P, L, dir, what, &e->type, NULL);
    if (!rc)
        rc = parse_params(P, L, &e->params);
    return rc;
}

/* Frees what one parameter owns (lf_params_free does this for whole sets). */
static void param_release(lf_param *p)
{
    free(p->name);
    free(p->nums);
    for (size_t k = 0; k < p->n_strs; k++)
        free(p->strs[k]);
    free(p->strs);
    free(p->bools);
    memset(p, 0, sizeof *p);
}

static void entity_free(lf_entity *e)
{
    free(e->type);
    lf_params_free(&e->params);
    memset(e, 0, sizeof *e);
}

/* pbrt-v4's VERIFY_OPTIONS / VERIFY_WORLD. */
static int require_options(parser *P, const token *dir)
{
    if (P->world)
        return perr(P, LF_ERR_PARSE, &dir->loc, "%.*s not allowed inside world block (after WorldBegin)",
                    (int)dir->n, dir->s);
    return LF_OK;
}

static int require_world(parser *P, const token *dir)
{
    if (!P->world)
        return perr(P, LF_ERR_PARSE, &dir->loc,
                    "%.*s not allowed before WorldBegin (scene description must be inside the world block)",
                    (int)dir->n, dir->s);
    return LF_OK;
}

/* ------------------------------------------------------------------------ */
/* Directive handlers                                                       */

static int d_identity(parser *P, lexer *L, const token *dir)
{
    (void)L;
    (void)dir;
    lf_transform id = lf_transform_identity();
    set_transform(P, &id);
    return LF_OK;
}

static int d_translate(parser *P, lexer *L, const token *dir)
{
    double v[3];
    int rc = expect_numbers(P, L, dir, 3, v);
    if (rc)
        return rc;
    lf_transform t = lf_transform_translate(v[0], v[1], v[2]);
    apply_transform(P, &t);
    return LF_OK;
}

static int d_scale(parser *P, lexer *L, const token *dir)
{
    double v[3];
    int rc = expect_numbers(P, L, dir, 3, v);
    if (rc)
        return rc;
    lf_transform t = lf_transform_scale(v[0], v[1], v[2]);
    apply_transform(P, &t);
    return LF_OK;
}

static int d_rotate(parser *P, lexer *L, const token *dir)
{
    double v[4];
    int rc = expect_numbers(P, L, dir, 4, v);
    if (rc)
        return rc;
    lf_transform t = lf_transform_rotate(v[0], v[1], v[2], v[3]);
    apply_transform(P, &t);
    return LF_OK;
}

static int d_lookat(parser *P, lexer *L, const token *dir)
{
    double v[9];
    int rc = expect_numbers(P, L, dir, 9, v);
    if (rc)
        return rc;
    lf_transform t;
    if (lf_transform_look_at(v, v + 3, v + 6, &t)) {
        /* Distinct but huge numbers cancel (1e19 + 1 == 1e19) or overflow
         * when squared: say so rather than that eye equals look. */
        double big = 0;
        for (int i = 0; i < 9; i++)
            big = fmax(big, fabs(v[i]));
        if (big > 1e15 && (v[0] != v[3] || v[1] != v[4] || v[2] != v[5]))
            return perr(P, LF_ERR_PARSE, &dir->loc,
                        "LookAt: the numbers are too large (up to %g): at that magnitude eye, look and up cannot be "
                        "told apart in double precision; keep |coordinate| <= 1e15 scene units",
                        big);
        return perr(P, LF_ERR_PARSE, &dir->loc,
                    "LookAt: eye equals look, or the up vector is parallel to the viewing direction");
    }
    apply_transform(P, &t);
    return LF_OK;
}

/* Transform / ConcatTransform: 16 numbers listed column-major (pbrt
 * transposes them), normally inside [ ]; the brackets are optional here. */
static int read_matrix(parser *P, lexer *L, const token *dir, lf_transform *out)
{
    token t;
    int rc = lex_peek(P, L, &t);
    if (rc)
        return rc;
    int bracketed = t.kind == TK_LBRACK;
    if (bracketed)
        lex_next(P, L, &t);
    double v[16];
    char b[200];
    for (int i = 0; i < 16; i++) {
        if ((rc = lex_next(P, L, &t)))
            return rc;
        if (t.kind == TK_WORD && is_nonfinite_word(&t))
            return perr(P, LF_ERR_NUMERIC, &t.loc, "non-finite number %s in %.*s", describe(&t, b, sizeof b),
                        (int)dir->n, dir->s);
        if (t.kind != TK_NUMBER) {
            if (bracketed && t.kind == TK_RBRACK)
                return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects 16 numbers, got %d", (int)dir->n, dir->s, i);
            return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects 16 numbers, got %s after %d", (int)dir->n, dir->s,
                        describe(&t, b, sizeof b), i);
        }
        v[i] = t.num;
    }
    if (bracketed) {
        if ((rc = lex_next(P, L, &t)))
            return rc;
        if (t.kind != TK_RBRACK)
            return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects 16 numbers: expected ']' after them, got %s",
                        (int)dir->n, dir->s, describe(&t, b, sizeof b));
    }
    double m[4][4];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            m[r][c] = v[c * 4 + r];
    if (lf_transform_from_matrix(m, out)) {
        /* pbrt-v4 keeps a singular matrix and fills its inverse with NaN. */
        memcpy(out->m, m, sizeof m);
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 4; c++)
                out->inv[r][c] = NAN;
        pwarn(P, &dir->loc, "%.*s: the matrix is singular", (int)dir->n, dir->s);
    }
    return LF_OK;
}

static int d_transform(parser *P, lexer *L, const token *dir)
{
    lf_transform t;
    int rc = read_matrix(P, L, dir, &t);
    if (!rc)
        set_transform(P, &t);
    return rc;
}

static int d_concat_transform(parser *P, lexer *L, const token *dir)
{
    lf_transform t;
    int rc = read_matrix(P, L, dir, &t);
    if (!rc)
        apply_transform(P, &t);
    return rc;
}

static int d_coordinate_system(parser *P, lexer *L, const token *dir)
{
    char *name;
    int rc = expect_string(P, L, dir, "a coordinate system name", &name, NULL);
    if (rc)
        return rc;
    rc = set_coordsys(P, name, P->gs.ctm);
    free(name);
    return rc;
}

static int d_coordsys_transform(parser *P, lexer *L, const token *dir)
{
    char *name;
    lf_loc loc;
    int rc = expect_string(P, L, dir, "a coordinate system name", &name, &loc);
    if (rc)
        return rc;
    int idx = strmap_get(&P->coordsys_map, name);
    if (idx >= 0) {
        /* Both CTMs, whatever ActiveTransform says (pbrt-v4). */
        P->gs.ctm[0] = P->coordsys[idx].xf[0];
        P->gs.ctm[1] = P->coordsys[idx].xf[1];
    } else {
        pwarn(P, &loc, "couldn't find named coordinate system \"%s\"", name);
    }
    free(name);
    return LF_OK;
}

static int d_transform_times(parser *P, lexer *L, const token *dir)
{
    int rc = require_options(P, dir);
    double v[2];
    if (!rc)
        rc = expect_numbers(P, L, dir, 2, v);
    if (rc)
        return rc;
    P->d->transform_start_time = v[0];
    P->d->transform_end_time = v[1];
    return LF_OK;
}

static int d_active_transform(parser *P, lexer *L, const token *dir)
{
    token t;
    int rc = lex_next(P, L, &t);
    if (rc)
        return rc;
    if (t.kind == TK_WORD && tok_is(&t, "All")) {
        P->gs.active[0] = P->gs.active[1] = 1;
    } else if (t.kind == TK_WORD && tok_is(&t, "StartTime")) {
        P->gs.active[0] = 1;
        P->gs.active[1] = 0;
    } else if (t.kind == TK_WORD && tok_is(&t, "EndTime")) {
        P->gs.active[0] = 0;
        P->gs.active[1] = 1;
    } else {
        char b[200];
        return perr(P, LF_ERR_PARSE, &t.loc, "%.*s expects StartTime, EndTime or All, got %s", (int)dir->n, dir->s,
                    describe(&t, b, sizeof b));
    }
    return LF_OK;
}

static int d_reverse_orientation(parser *P, lexer *L, const token *dir)
{
    (void)L;
    int rc = require_world(P, dir);
    if (!rc)
        P->gs.reverse_orientation = !P->gs.reverse_orientation;
    return rc;
}

static int push_state(parser *P, char kind, const lf_loc *loc)
{
    if (P->n_stack >= MAX_BLOCK_DEPTH)
        return perr(P, LF_ERR_PARSE, loc,
                    "blocks (AttributeBegin, ObjectBegin, TransformBegin) nested more than %d deep: each level keeps "
                    "a copy of the graphics state, and no scene needs that many (is an End missing?)",
                    MAX_BLOCK_DEPTH);
    if (grow((void **)&P->stack, &P->cap_stack, P->n_stack, sizeof *P->stack))
        return nomem(P);
    pushed *e = &P->stack[P->n_stack];
    e->kind = kind;
    e->loc = *loc;
    if (kind == 't') {
        memset(&e->saved, 0, sizeof e->saved);
        e->saved.ctm[0] = P->gs.ctm[0];
        e->saved.ctm[1] = P->gs.ctm[1];
        e->saved.active[0] = P->gs.active[0];
        e->saved.active[1] = P->gs.active[1];
    } else if (gstate_copy(&e->saved, &P->gs)) {
        return nomem(P);
    }
    P->n_stack++;
    return LF_OK;
}

static const char *block_name(char kind)
{
    return kind == 'a' ? "AttributeBegin" : kind == 'o' ? "ObjectBegin" : "TransformBegin";
}

/* Pops the innermost block, which must have been opened by `kind`. */
static int pop_state(parser *P, char kind, const token *dir)
{
    if (P->n_stack == 0)
        return perr(P, LF_ERR_PARSE, &dir->loc, "%.*s without a matching %s", (int)dir->n, dir->s, block_name(kind));
    pushed *e = &P->stack[P->n_stack - 1];
    if (e->kind != kind) {
        char opened[512];
        lf_loc_format(opened, sizeof opened, &e->loc);
        return perr(P, LF_ERR_PARSE, &dir->loc, "mismatched nesting: %.*s closes the %s at %s", (int)dir->n, dir->s,
                    block_name(e->kind), opened);
    }
    if (kind == 't') {
        P->gs.ctm[0] = e->saved.ctm[0];
        P->gs.ctm[1] = e->saved.ctm[1];
        P->gs.active[0] = e->saved.active[0];
        P->gs.active[1] = e->saved.active[1];
    } else {
        gstate_free(&P->gs);
        P->gs = e->saved;
    }
    P->n_stack--;
    return LF_OK;
}

static int d_attribute_begin(parser *P, lexer *L, const token *dir)
{
    (void)L;
    int rc = require_world(P, dir);
    return rc ? rc : push_state(P, 'a', &dir->loc);
}

static int d_attribute_end(parser *P, lexer *L, const token *dir)
{
    (void)L;
    int rc = require_world(P, dir);
    return rc ? rc : pop_state(P, 'a', dir);
}

/* Deprecated since pbrt-v4.  lensfield keeps pbrt-v3's meaning: only the
 * CTMs (and which of them are active) are saved and restored. */
static int d_transform_begin(parser *P, lexer *L, const token *dir)
{
    (void)L;
    if (!P->warned_transform_begin) {
        pwarn(P, &dir->loc, "TransformBegin/End are deprecated; use AttributeBegin/End");
        P->warned_transform_begin = 1;
    }
    return push_state(P, 't', &dir->loc);
}

static int d_transform_end(parser *P, lexer *L, const token *dir)
{
    (void)L;
    return pop_state(P, 't', dir);
}

static int d_attribute(parser *P, lexer *L, const token *dir)
{
    char *target;
    lf_loc loc;
    int rc = expect_string(P, L, dir, "shape, light, material, medium or texture", &target, &loc);
    if (rc)
        return rc;
    int which = -1;
    for (int i = 0; i < ATTR_COUNT; i++)
        if (strcmp(target, attr_targets[i]) == 0)
            which = i;
    if (which < 0) {
        rc = perr(P, LF_ERR_PARSE, &loc,
                  "unknown attribute target \"%s\": must be \"shape\", \"light\", \"material\", \"medium\" or "
                  "\"texture\"",
                  target);
        free(target);
        return rc;
    }
    free(target);
    lf_paramset ps = {0};
    if ((rc = parse_params(P, L, &ps))) {
        lf_params_free(&ps);
        return rc;
    }
    /* A later Attribute overrides an earlier one of the same name.  Items
     * move from ps to attrs one at a time; ps keeps what has not moved. */
    lf_paramset *attrs = &P->gs.attrs[which];
    for (size_t i = 0; i < ps.count; i++) {
        lf_param *p = &ps.items[i];
        size_t j;
        for (j = 0; j < attrs->count; j++)
            if (strcmp(attrs->items[j].name, p->name) == 0)
                break;
        if (j < attrs->count) {
            param_release(&attrs->items[j]);
            attrs->items[j] = *p;
        } else if (lf_params_add(attrs, p)) {
            lf_params_free(&ps);
            return nomem(P);
        }
        memset(p, 0, sizeof *p);
        p->name = NULL;
    }
    lf_params_free(&ps);
    return LF_OK;
}

static int d_world_begin(parser *P, lexer *L, const token *dir)
{
    (void)L;
    int rc = require_options(P, dir);
    if (rc)
        return rc;
    P->world = 1;
    P->gs.ctm[0] = P->gs.ctm[1] = lf_transform_identity();
    P->gs.active[0] = P->gs.active[1] = 1;
    return set_coordsys(P, "world", P->gs.ctm);
}

static int d_world_end(parser *P, lexer *L, const token *dir)
{
    (void)L;
    pwarn(P, &dir->loc, "WorldEnd is pbrt-v3 syntax and is ignored");
    return LF_OK;
}

static int join_path(const char *dir, const char *rel, char **out)
{
    if (rel[0] == '/' || !dir || !dir[0] || strcmp(dir, ".") == 0) {
        *out = dup_cstr(rel);
    } else {
        size_t n = strlen(dir) + strlen(rel) + 2;
        *out = malloc(n);
        if (*out)
            snprintf(*out, n, "%s/%s", dir, rel);
    }
    return *out ? 0 : -1;
}

/* A file named in a scene: relative to the directory of the file that names
 * it (`dir`); if nothing is there, relative to the top-level file's
 * directory, which is where pbrt-v4 looks (its scenes name nested files
 * that way).  The first candidate is returned when neither exists, so the
 * message names the path lensfield tried first. */
static int resolve_path(parser *P, const char *dir, const char *rel, char **out)
{
    if (join_path(dir, rel, out))
        return -1;
    if (rel[0] == '/' || !P->main_dir || (dir && strcmp(dir, P->main_dir) == 0) || access(*out, F_OK) == 0)
        return 0;
    char *alt;
    if (join_path(P->main_dir, rel, &alt))
        return -1;
    if (access(alt, F_OK) == 0) {
        free(*out);
        *out = alt;
    } else {
        free(alt);
    }
    return 0;
}

/* The directory part of path: "a/b/c.pbrt" -> "a/b", "c.pbrt" -> ".". */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return dup_cstr(".");
    if (slash == path)
        return dup_cstr("/");
    return dup_range(path, (size_t)(slash - path));
}

/* Pushes the file at `path` onto the lexer: its tokens come next, then the
 * rest of the including file (pbrt-v4 includes tokens, not statements).
 * The file may be gzipped.  `from` is where the Include was written (NULL
 * for the top-level file). */
static int push_file(parser *P, lexer *X, const char *path, const lf_loc *from)
{
    lf_file_stream *in;
    lf_error fe = {0};
    if (lf_file_stream_open(path, &in, &fe)) {
        if (fe.code == LF_ERR_NOMEM)
            return nomem(P);
        /* fe.msg is "path: what"; say which kind of file it was. */
        const char *what = fe.msg;
        size_t pl = strlen(path);
        if (strncmp(what, path, pl) == 0 && what[pl] == ':' && what[pl + 1] == ' ')
            what += pl + 2;
        int open_failed = strncmp(what, "cannot open: ", 13) == 0;
        if (open_failed)
            what += 13;
        if (from)
            return perr(P, fe.code, from, "%s included file \"%s\": %s", open_failed ? "cannot open" : "cannot read",
                        path, what);
        return perr(P, fe.code, NULL, "%s scene file \"%s\": %s", open_failed ? "cannot open" : "cannot read", path,
                    what);
    }
    char *dir = dir_of(path);
    const char *kept_file = keep_string(P, path);
    const char *kept_dir = dir ? keep_string(P, dir) : NULL;
    free(dir);
    if (!kept_file || !kept_dir || lx_push(X, in, "", 0, kept_file, kept_dir, from)) {
        lf_file_stream_close(in);
        return nomem(P);
    }
    return LF_OK;
}

/* Include and Import: pbrt-v4 resolves the name against the directory of the
 * main scene file; lensfield tries the directory of the including file
 * first, then the main file's (resolve_path), so both layouts work.  Import is read like Include (pbrt-v4 parses it in
 * parallel; the result is the same). */
static int d_include(parser *P, lexer *L, const token *dir)
{
    char *name;
    int rc = expect_string(P, L, dir, "a file name", &name, NULL);
    if (rc)
        return rc;
    if (tok_is(dir, "Import") && !P->world) {
        free(name);
        return perr(P, LF_ERR_PARSE, &dir->loc, "Import is only allowed inside the world block");
    }
    if (L->n_fr > MAX_INCLUDE_DEPTH) {
        free(name);
        return perr(P, LF_ERR_PARSE, &dir->loc, "%.*s nested more than %d deep (does a file include itself?)",
                    (int)dir->n, dir->s, MAX_INCLUDE_DEPTH);
    }
    char *path;
    if (resolve_path(P, dir->dir, name, &path)) {
        free(name);
        return nomem(P);
    }
    free(name);
    rc = push_file(P, L, path, &dir->loc);
    free(path);
    return rc;
}

/* Camera, Film, Sampler, Integrator, PixelFilter, Accelerator. */
static int d_option_entity(parser *P, lexer *L, const token *dir)
{
    int rc = require_options(P, dir);
    if (rc)
        return rc;
    lf_entity e;
    if ((rc = parse_entity(P, L, dir, "a type name", &e))) {
        entity_free(&e);
        return rc;
    }
    lf_scene_desc *d = P->d;
    lf_entity *slot = tok_is(dir, "Film")          ? &d->film
                      : tok_is(dir, "Sampler")     ? &d->sampler
                      : tok_is(dir, "Integrator")  ? &d->integrator
                      : tok_is(dir, "PixelFilter") ? &d->filter
                      : tok_is(dir, "Accelerator") ? &d->accelerator
                                                   : &d->camera.e;
    entity_free(slot);
    *slot = e;
    if (slot == &d->camera.e) {
        d->camera.world_to_camera = current_xform(P);
        d->camera.medium = P->gs.medium_outside;
        /* pbrt-v4 names the camera-to-world transform "camera". */
        lf_transform inv[2] = {lf_transform_inverse(&P->gs.ctm[0]), lf_transform_inverse(&P->gs.ctm[1])};
        return set_coordsys(P, "camera", inv);
    }
    return LF_OK;
}

/* lensfield renders in linear sRGB and has no global options: both are read
 * and ignored (pbrt-v4 allows them anywhere, so no world-block check). */
static int d_color_space(parser *P, lexer *L, const token *dir)
{
    char *name;
    int rc = expect_string(P, L, dir, "a colour space name", &name, NULL);
    if (rc)
        return rc;
    pwarn(P, &dir->loc, "ColorSpace \"%s\" ignored: lensfield renders in linear sRGB", name);
    free(name);
    return LF_OK;
}

static int d_option(parser *P, lexer *L, const token *dir)
{
    lf_paramset ps = {0};
    int rc = parse_params(P, L, &ps);
    if (!rc && ps.count == 0) {
        token t;
        char b[200];
        lex_peek(P, L, &t);
        rc = perr(P, LF_ERR_PARSE, &t.loc, "Option expects a \"type name\" value pair, got %s",
                  describe(&t, b, sizeof b));
    }
    if (!rc)
        pwarn(P, &dir->loc, "Option \"%s\" ignored", ps.items[0].name);
    lf_params_free(&ps);
    return rc;
}

/* pbrt-v4's shape, light, material and texture types, and those of them lensfield
 * cannot render (docs/scene-format.md has the whole table).  Leaving one out
 * changes what the image shows, so it is an error unless the user asked for
 * --allow-unsupported (lf_parse_opts.allow_unsupported). */
static const char *const pbrt_shapes[] = {"bilinearmesh", "curve",  "cylinder", "disk", "loopsubdiv",
                                          "plymesh",      "sphere", "trianglemesh", NULL};
static const char *const refused_shapes[] = {NULL};
static const char *const pbrt_lights[] = {"distant", "goniometric", "infinite", "point", "projection", "spot", NULL};
static const char *const refused_lights[] = {"goniometric", "projection", NULL};
static const char *const pbrt_materials[] = {"coatedconductor", "coateddiffuse", "conductor",   "dielectric", "diffuse",
                                             "diffusetransmission", "hair", "interface", "measured", "mix",
                                             "subsurface",      "thindielectric", "none", "", NULL};
static const char *const refused_materials[] = {NULL};
static const char *const pbrt_textures[] = {"bilerp", "checkerboard", "constant", "directionmix", "dots", "fbm",
                                            "imagemap", "marble", "mix", "ptex", "scale", "windy", "wrinkled",
                                            NULL};
static const char *const refused_textures[] = {"ptex", NULL};

static int in_list(const char *const *list, const char *s)
{
    for (; *list; list++)
        if (strcmp(*list, s) == 0)
            return 1;
    return 0;
}

/* 0: supported; 1: not supported but allowed (a warning was written, the
 * caller leaves it out or substitutes `instead`); otherwise an error code. */
static int check_supported(parser *P, const token *dir, const char *type, const char *const *known,
                           const char *const *refused, const char *instead)
{
    if (in_list(known, type) && !in_list(refused, type))
        return 0;
    /* pbrt-v4 calls it unknown when it is not one of its own types. */
    const char *what = known == pbrt_shapes      ? "shape"
                       : known == pbrt_lights    ? "light"
                       : known == pbrt_textures  ? "texture"
                                                 : "material";
    int is_known = in_list(known, type);
    const char *guess = is_known ? NULL : lf_suggest_among(type, known);
    if (guess) /* a misspelt type: unknown, whatever --allow-unsupported says */
        return perr(P, LF_ERR_PARSE, &dir->loc, "%.*s: unknown %s \"%s\" (did you mean \"%s\"?)", (int)dir->n,
                    dir->s, what, type, guess);
    if (P->allow_unsupported) {
        if (is_known)
            pwarn(P, &dir->loc, "%.*s \"%s\" is not supported; %s (--allow-unsupported)", (int)dir->n, dir->s,
                  type, instead);
        else
            pwarn(P, &dir->loc, "%.*s: unknown %s \"%s\" is not supported; %s (--allow-unsupported)", (int)dir->n,
                  dir->s, what, type, instead);
        return 1;
    }
    if (!is_known)
        return perr(P, LF_ERR_UNSUPPORTED, &dir->loc,
                    "%.*s: unknown %s \"%s\" is not supported (--allow-unsupported renders the scene without it)",
                    (int)dir->n, dir->s, what, type);
    return perr(P, LF_ERR_UNSUPPORTED, &dir->loc,
                "%.*s \"%s\" is not supported (--allow-unsupported renders the scene without it)", (int)dir->n,
                dir->s, type);
}

/* An allowed unsupported material is rendered as pbrt's default material. */
static void make_default_material(lf_entity *e)
{
    free(e->type);
    e->type = dup_cstr("diffuse");
    lf_params_free(&e->params);
}

static int merge_attrs(parser *P, lf_paramset *ps, int which)
{
    return lf_params_merge_defaults(ps, &P->gs.attrs[which]) ? nomem(P) : LF_OK;
}

/* The start of a world-block directive that adds an element to one of the
 * scene's arrays: checks the block and makes room for one more element of
 * elem_size bytes, zeroed, at *elem (the count is not advanced). */
static int world_slot(parser *P, const token *dir, void **array, size_t *cap, size_t count, size_t elem_size,
                      void **elem)
{
    int rc = require_world(P, dir);
    if (rc)
        return rc;
    if (grow(array, cap, count, elem_size))
        return nomem(P);
    *elem = (char *)*array + count * elem_size;
    memset(*elem, 0, elem_size);
    return LF_OK;
}

/* world_slot, then the directive's type and parameters into the entity at
 * entity_offset of the new element, with the graphics state's attributes of
 * kind `attrs` merged in.  On failure the entity is freed. */
static int world_entity(parser *P, lexer *L, const token *dir, void **array, size_t *cap, size_t count,
                        size_t elem_size, size_t entity_offset, const char *what, int attrs, void **elem)
{
    int rc = world_slot(P, dir, array, cap, count, elem_size, elem);
    if (rc)
        return rc;
    lf_entity *e = (lf_entity *)((char *)*elem + entity_offset);
    rc = parse_entity(P, L, dir, what, e);
    if (!rc)
        rc = merge_attrs(P, &e->params, attrs);
    if (rc)
        entity_free(e);
    return rc;
}

static int d_material(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_material_desc *m;
    int rc = world_entity(P, L, dir, (void **)&d->materials, &P->cap_materials, d->n_materials, sizeof *m,
                          offsetof(lf_material_desc, e), "a material type", ATTR_MATERIAL, (void **)&m);
    if (rc)
        return rc;
    rc = check_supported(P, dir, m->e.type, pbrt_materials, refused_materials, "rendered as \"diffuse\" 0.5");
    if (rc == 1) {
        make_default_material(&m->e);
        rc = m->e.type ? LF_OK : nomem(P);
    }
    if (rc) {
        entity_free(&m->e);
        return rc;
    }
    P->gs.material = (int)d->n_materials++;
    return LF_OK;
}

static int d_make_named_material(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_material_desc *m;
    int rc = world_slot(P, dir, (void **)&d->materials, &P->cap_materials, d->n_materials, sizeof *m, (void **)&m);
    if (rc)
        return rc;
    m->e.loc = dir->loc;
    lf_loc name_loc;
    rc = expect_string(P, L, dir, "a material name", &m->name, &name_loc);
    if (!rc)
        rc = parse_params(P, L, &m->e.params);
    if (!rc)
        rc = merge_attrs(P, &m->e.params, ATTR_MATERIAL);
    if (!rc) {
        int prev = strmap_get(&P->material_map, m->name);
        if (prev >= 0) {
            const lf_loc *pl = &d->materials[prev].e.loc;
            char first[512];
            lf_loc_format(first, sizeof first, pl);
            rc = perr(P, LF_ERR_PARSE, &name_loc, "named material \"%s\" redefined (first defined at %s)", m->name,
                      first);
        }
    }
    if (!rc) {
        /* The type travels as a "string type" parameter; move it to e.type so
         * named and anonymous materials look alike to the scene builder. */
        size_t i;
        for (i = 0; i < m->e.params.count; i++)
            if (strcmp(m->e.params.items[i].name, "type") == 0)
                break;
        lf_param *tp = i < m->e.params.count ? &m->e.params.items[i] : NULL;
        if (!tp || tp->type != LF_PT_STRING || tp->n_strs != 1) {
            rc = perr(P, LF_ERR_PARSE, tp ? &tp->loc : &name_loc,
                      "MakeNamedMaterial \"%s\": needs a \"string type\" parameter with one value", m->name);
        } else {
            m->e.type = tp->strs[0];
            tp->strs[0] = NULL;
            param_release(tp);
            memmove(tp, tp + 1, (m->e.params.count - i - 1) * sizeof *tp);
            m->e.params.count--;
            rc = check_supported(P, dir, m->e.type, pbrt_materials, refused_materials,
                                 "rendered as \"diffuse\" 0.5");
            if (rc == 1) {
                make_default_material(&m->e);
                rc = m->e.type ? LF_OK : nomem(P);
            }
        }
    }
    if (!rc && strmap_put(&P->material_map, m->name, (int)d->n_materials))
        rc = nomem(P);
    if (rc) {
        entity_free(&m->e);
        free(m->name);
        return rc;
    }
    d->n_materials++;
    return LF_OK;
}

static int d_named_material(parser *P, lexer *L, const token *dir)
{
    int rc = require_world(P, dir);
    if (rc)
        return rc;
    if (grow((void **)&P->material_refs, &P->cap_material_refs, P->n_material_refs, sizeof *P->material_refs))
        return nomem(P);
    named_ref *r = &P->material_refs[P->n_material_refs];
    if ((rc = expect_string(P, L, dir, "a material name", &r->name, &r->loc)))
        return rc;
    /* Resolved at the end: pbrt-v4 allows MakeNamedMaterial after its use. */
    P->gs.material = -2 - (int)P->n_material_refs++;
    return LF_OK;
}

static int d_texture(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_texture_desc *t;
    int rc = world_slot(P, dir, (void **)&d->textures, &P->cap_textures, d->n_textures, sizeof *t, (void **)&t);
    if (rc)
        return rc;
    t->e.loc = dir->loc;
    char *kind = NULL;
    lf_loc name_loc, kind_loc;
    rc = expect_string(P, L, dir, "a texture name", &t->name, &name_loc);
    if (!rc)
        rc = expect_string(P, L, dir, "\"float\" or \"spectrum\"", &kind, &kind_loc);
    if (!rc && strcmp(kind, "float") != 0 && strcmp(kind, "spectrum") != 0)
        rc = perr(P, LF_ERR_PARSE, &kind_loc, "texture type \"%s\" unknown: must be \"float\" or \"spectrum\"", kind);
    if (!rc)
        t->is_float = strcmp(kind, "float") == 0;
    if (!rc)
        rc = expect_string(P, L, dir, "a texture class", &t->e.type, NULL);
    if (!rc)
        rc = parse_params(P, L, &t->e.params);
    if (!rc)
        rc = merge_attrs(P, &t->e.params, ATTR_TEXTURE);
    if (!rc) {
        rc = check_supported(P, dir, t->e.type, pbrt_textures, refused_textures, "rendered as \"constant\" 1");
        if (rc == 1) { /* pbrt's constant texture, value 1 */
            free(t->e.type);
            t->e.type = dup_cstr("constant");
            lf_params_free(&t->e.params);
            rc = t->e.type ? LF_OK : nomem(P);
        }
    }
    strmap *names = t->is_float ? &P->float_tex_map : &P->spectrum_tex_map;
    if (!rc) {
        int prev = strmap_get(names, t->name);
        if (prev >= 0) {
            const lf_loc *pl = &d->textures[prev].e.loc;
            char first[512];
            lf_loc_format(first, sizeof first, pl);
            rc = perr(P, LF_ERR_PARSE, &name_loc, "%s texture \"%s\" redefined (first defined at %s)", kind, t->name,
                      first);
        }
    }
    if (!rc && strmap_put(names, t->name, (int)d->n_textures))
        rc = nomem(P);
    free(kind);
    if (rc) {
        entity_free(&t->e);
        free(t->name);
        return rc;
    }
    t->object_to_world = P->gs.ctm[0];
    d->n_textures++;
    return LF_OK;
}

static int d_light_source(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_light_desc *l;
    int rc = world_entity(P, L, dir, (void **)&d->lights, &P->cap_lights, d->n_lights, sizeof *l,
                          offsetof(lf_light_desc, e), "a light type", ATTR_LIGHT, (void **)&l);
    if (rc)
        return rc;
    rc = check_supported(P, dir, l->e.type, pbrt_lights, refused_lights, "it is left out");
    if (rc) {
        entity_free(&l->e);
        return rc == 1 ? LF_OK : rc;
    }
    l->light_to_world = current_xform(P);
    l->reverse_orientation = P->gs.reverse_orientation;
    d->n_lights++;
    return LF_OK;
}

static int d_area_light_source(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_entity *e;
    int rc = world_entity(P, L, dir, (void **)&d->area_lights, &P->cap_area_lights, d->n_area_lights, sizeof *e, 0,
                          "an area light type", ATTR_LIGHT, (void **)&e);
    if (rc)
        return rc;
    P->gs.area_light = (int)d->n_area_lights++;
    return LF_OK;
}

static int d_shape(parser *P, lexer *L, const token *dir)
{
    lf_scene_desc *d = P->d;
    lf_shape_desc *s;
    int rc = world_entity(P, L, dir, (void **)&d->shapes, &P->cap_shapes, d->n_shapes, sizeof *s,
                          offsetof(lf_shape_desc, e), "a shape type", ATTR_SHAPE, (void **)&s);
    if (rc)
        return rc;
    rc = check_supported(P, dir, s->e.type, pbrt_shapes, refused_shapes, "it is left out");
    if (rc) {
        entity_free(&s->e);
        return rc == 1 ? LF_OK : rc;
    }
    s->object_to_world = current_xform(P);
    s->material = P->gs.material;
    s->area_light = P->gs.area_light;
    s->reverse_orientation = P->gs.reverse_orientation;
    s->object = P->current_object;
    s->base_dir = dir->dir;
    s->medium_inside = P->gs.medium_inside;
    s->medium_outside = P->gs.medium_outside;
    if (s->object >= 0 && s->area_light >= 0)
        pwarn(P, &dir->loc, "area lights are not supported with object instancing");
    d->n_shapes++;
    return LF_OK;
}

static int d_object_begin(parser *P, lexer *L, const token *dir)
{
    int rc = require_world(P, dir);
    if (rc)
        return rc;
    char *name;
    lf_loc loc;
    if ((rc = expect_string(P, L, dir, "an object name", &name, &loc)))
        return rc;
    if (P->current_object >= 0)
        rc = perr(P, LF_ERR_PARSE, &dir->loc, "ObjectBegin \"%s\" inside the definition of object \"%s\"", name,
                  P->d->objects[P->current_object].name);
    else if (strmap_get(&P->object_map, name) >= 0)
        rc = perr(P, LF_ERR_PARSE, &loc, "object \"%s\" redefined", name);
    lf_scene_desc *d = P->d;
    if (!rc && grow((void **)&d->objects, &P->cap_objects, d->n_objects, sizeof *d->objects))
        rc = nomem(P);
    /* ObjectBegin also opens an attribute block (pbrt-v4). */
    if (!rc)
        rc = push_state(P, 'o', &dir->loc);
    if (rc) {
        free(name);
        return rc;
    }
    lf_object_desc *o = &d->objects[d->n_objects];
    o->name = name;
    o->object_to_world = current_xform(P);
    P->current_object = (int)d->n_objects++;
    if (strmap_put(&P->object_map, o->name, P->current_object))
        return nomem(P);
    return LF_OK;
}

static int d_object_end(parser *P, lexer *L, const token *dir)
{
    (void)L;
    int rc = require_world(P, dir);
    if (rc)
        return rc;
    if (P->current_object < 0)
        return perr(P, LF_ERR_PARSE, &dir->loc, "ObjectEnd outside of an object definition");
    if ((rc = pop_state(P, 'o', dir)))
        return rc;
    P->current_object = -1;
    return LF_OK;
}

static int d_object_instance(parser *P, lexer *L, const token *dir)
{
    int rc = require_world(P, dir);
    if (rc)
        return rc;
    lf_scene_desc *d = P->d;
    size_t cap = P->cap_instances;
    if (grow((void **)&d->instances, &P->cap_instances, d->n_instances, sizeof *d->instances))
        return nomem(P);
    if (P->cap_instances != cap) {
        named_ref *r = realloc(P->instance_refs, P->cap_instances * sizeof *r);
        if (!r)
            return nomem(P);
        P->instance_refs = r;
        P->cap_instance_refs = P->cap_instances;
    }
    named_ref *ref = &P->instance_refs[d->n_instances];
    if ((rc = expect_string(P, L, dir, "an object name", &ref->name, &ref->loc)))
        return rc;
    if (P->current_object >= 0) {
        rc = perr(P, LF_ERR_PARSE, &dir->loc, "ObjectInstance \"%s\" inside the definition of object \"%s\"",
                  ref->name, d->objects[P->current_object].name);
        free(ref->name);
        return rc;
    }
    lf_instance_desc *inst = &d->instances[d->n_instances++];
    inst->object = -1; /* resolved at the end: pbrt-v4 allows use before definition */
    inst->instance_to_world = current_xform(P);
    inst->loc = dir->loc;
    return LF_OK;
}

/* MakeNamedMedium "name" params: kept with the CTM; the scene builder reads
 * the "string type" and the rest (homogeneous media are rendered, grid
 * media refused there with this location).  Allowed before WorldBegin too
 * (a camera may sit in a medium). */
static int d_make_named_medium(parser *P, lexer *L, const token *dir)
{
    char *name;
    int rc = expect_string(P, L, dir, "a medium name", &name, NULL);
    if (rc)
        return rc;
    lf_scene_desc *d = P->d;
    if (grow((void **)&d->media, &P->cap_media, d->n_media, sizeof *d->media)) {
        free(name);
        return nomem(P);
    }
    lf_medium_desc *m = &d->media[d->n_media];
    memset(m, 0, sizeof *m);
    rc = parse_params(P, L, &m->e.params);
    if (!rc)
        rc = merge_attrs(P, &m->e.params, ATTR_MEDIUM); /* Attribute "medium" defaults */
    if (rc) {
        lf_params_free(&m->e.params);
        free(name);
        return rc;
    }
    for (size_t i = 0; i < d->n_media; i++)
        if (!strcmp(d->media[i].name, name)) {
            rc = perr(P, LF_ERR_PARSE, &dir->loc, "medium \"%s\" redefined", name);
            lf_params_free(&m->e.params);
            free(name);
            return rc;
        }
    m->name = name;
    m->e.loc = dir->loc;
    m->medium_to_world = P->gs.ctm[0];
    d->n_media++;
    return LF_OK;
}

/* MediumInterface "inside" ["outside"]: one name sets both (pbrt-v4). The
 * names are resolved by the scene builder ("" is vacuum). */
static int d_medium_interface(parser *P, lexer *L, const token *dir)
{
    char *inside;
    int rc = expect_string(P, L, dir, "an interior medium name", &inside, NULL);
    if (rc)
        return rc;
    token t;
    if ((rc = lex_peek(P, L, &t))) {
        free(inside);
        return rc;
    }
    const char *in = keep_string(P, inside), *out = in;
    free(inside);
    if (!in)
        return nomem(P);
    if (t.kind == TK_STRING) { /* the exterior name is optional */
        char *outside;
        if ((rc = expect_string(P, L, dir, "an exterior medium name", &outside, NULL)))
            return rc;
        out = keep_string(P, outside);
        free(outside);
        if (!out)
            return nomem(P);
    }
    P->gs.medium_inside = in;
    P->gs.medium_outside = out;
    return LF_OK;
}

static const struct directive {
    const char *name;
    directive_fn fn;
} directives[] = {
    {"Accelerator", d_option_entity},
    {"ActiveTransform", d_active_transform},
    {"AreaLightSource", d_area_light_source},
    {"Attribute", d_attribute},
    {"AttributeBegin", d_attribute_begin},
    {"AttributeEnd", d_attribute_end},
    {"Camera", d_option_entity},
    {"ColorSpace", d_color_space},
    {"ConcatTransform", d_concat_transform},
    {"CoordSysTransform", d_coordsys_transform},
    {"CoordinateSystem", d_coordinate_system},
    {"Film", d_option_entity},
    {"Identity", d_identity},
    {"Import", d_include},
    {"Include", d_include},
    {"Integrator", d_option_entity},
    {"LightSource", d_light_source},
    {"LookAt", d_lookat},
    {"MakeNamedMaterial", d_make_named_material},
    {"MakeNamedMedium", d_make_named_medium},
    {"Material", d_material},
    {"MediumInterface", d_medium_interface},
    {"NamedMaterial", d_named_material},
    {"ObjectBegin", d_object_begin},
    {"ObjectEnd", d_object_end},
    {"ObjectInstance", d_object_instance},
    {"Option", d_option},
    {"PixelFilter", d_option_entity},
    {"ReverseOrientation", d_reverse_orientation},
    {"Rotate", d_rotate},
    {"Sampler", d_option_entity},
    {"Scale", d_scale},
    {"Shape", d_shape},
    {"Texture", d_texture},
    {"Transform", d_transform},
    {"TransformBegin", d_transform_begin},
    {"TransformEnd", d_transform_end},
    {"TransformTimes", d_transform_times},
    {"Translate", d_translate},
    {"WorldBegin", d_world_begin},
    {"WorldEnd", d_world_end},
};

static directive_fn find_directive(const token *t)
{
    if (t->kind != TK_WORD)
        return NULL;
    for (size_t i = 0; i < sizeof directives / sizeof directives[0]; i++)
        if (tok_is(t, directives[i].name))
            return directives[i].fn;
    return NULL;
}

/* Reports an unknown directive with the nearest known one.  Returns 1 when
 * that is a block keyword (WorldBegin, AttributeBegin/End, ObjectBegin/End,
 * TransformBegin/End): the parse stops there, since every later line would
 * be judged inside the wrong block (a misspelt WorldBegin would otherwise
 * make each following world directive an error of its own). */
static int unknown_directive(parser *P, const token *t)
{
    char b[200], word[64];
    snprintf(word, sizeof word, "%.*s", (int)(t->n < 63 ? t->n : 63), t->s);
    lf_suggest s = lf_suggest_begin(word);
    for (size_t i = 0; i < sizeof directives / sizeof directives[0]; i++)
        lf_suggest_consider(&s, directives[i].name);
    const char *best = lf_suggest_best(&s);
    int block = best && (strstr(best, "Begin") || strstr(best, "End"));
    perr(P, LF_ERR_PARSE, &t->loc, "unknown directive %s%s%s%s%s", describe(t, b, sizeof b),
         best ? " (did you mean " : "", best ? best : "", best ? "?)" : "",
         block ? "; stopped reading: what follows depends on that block" : "");
    return block;
}

/* A bare word that is not a value: a directive, or a misspelt one (which
 * then gets its own "unknown directive" error). */
static int is_directive_like(const token *t)
{
    return t->kind == TK_WORD && !tok_is(t, "true") && !tok_is(t, "false") && !is_nonfinite_word(t) &&
           !tok_is(t, "StartTime") && !tok_is(t, "EndTime") && !tok_is(t, "All");
}

/* After an error: skips tokens up to the next directive name (or the end),
 * so one run reports every problem of a scene. */
static void recover(parser *P, lexer *L)
{
    for (;;) {
        token t;
        size_t mark = lx_mark(L); /* skipped tokens keep no text */
        int rc = lex_peek(P, L, &t);
        if (rc == LF_ERR_NOMEM || P->n_errors >= P->max_errors)
            return;
        if (rc) /* a malformed token: the lexer has moved past it */
            continue;
        if (t.kind == TK_EOF || is_directive_like(&t))
            return;
        lex_next(P, L, &t);
        lx_release(L, mark);
    }
}

/* Reads directives until the end of the top-level file; *eof receives
 * where it ended. */
static int parse_run(parser *P, lexer *L, lf_loc *eof)
{
    for (;;) {
        lx_release(L, 0); /* the tokens of the directive before */
        if (P->n_errors >= P->max_errors) {
            char line[64];
            snprintf(line, sizeof line, "(stopped after %d errors)\n", P->n_errors);
            size_t n = strlen(line);
            char *e = realloc(P->errors, P->errors_len + n + 1);
            if (e) {
                memcpy(e + P->errors_len, line, n + 1);
                P->errors = e;
                P->errors_len += n;
                P->errors_cap = P->errors_len + 1;
            }
            return P->first_code;
        }
        token t;
        int rc = lex_next(P, L, &t);
        if (rc == LF_ERR_NOMEM)
            return rc;
        if (rc) {
            recover(P, L);
            continue;
        }
        if (t.kind == TK_EOF) {
            *eof = t.loc;
            return P->n_errors ? P->first_code : LF_OK;
        }
        char b[200];
        directive_fn fn = find_directive(&t);
        lx_frame *top = &L->fr[L->n_fr - 1];
        int from_top = t.loc.file == top->file;
        if (!fn && from_top && top->included && top->directives == 0) {
            /* An included file that does not begin with a directive is not a
             * scene (Include "/etc/shadow"): refused whole, its content never
             * echoed in messages. */
            perr(P, LF_ERR_PARSE, &t.loc, "\"%s\" is not a scene file (it does not begin with a directive): not "
                 "read further", top->file);
            top->p = top->end; /* its end: the lexer returns to the including file */
            top->at_end = 1;
            continue;
        }
        if (fn && from_top)
            top->directives++;
        if (!fn) {
            if (t.kind != TK_WORD)
                perr(P, LF_ERR_PARSE, &t.loc, "expected a directive, got %s", describe(&t, b, sizeof b));
            else if (unknown_directive(P, &t)) /* a misspelt block keyword: stop here */
                return P->first_code;
            recover(P, L);
            continue;
        }
        rc = fn(P, L, &t);
        if (rc == LF_ERR_NOMEM)
            return rc;
        if (rc)
            recover(P, L);
    }
}

/* ------------------------------------------------------------------------ */
/* Set-up, end of input, clean-up                                           */

static void parser_free(parser *P)
{
    gstate_free(&P->gs);
    for (size_t i = 0; i < P->n_stack; i++)
        gstate_free(&P->stack[i].saved);
    free(P->stack);
    for (size_t i = 0; i < P->n_coordsys; i++)
        free(P->coordsys[i].name);
    free(P->coordsys);
    strmap_free(&P->coordsys_map);
    strmap_free(&P->material_map);
    strmap_free(&P->float_tex_map);
    strmap_free(&P->spectrum_tex_map);
    strmap_free(&P->object_map);
    for (size_t i = 0; i < P->n_material_refs; i++)
        free(P->material_refs[i].name);
    free(P->material_refs);
    if (P->instance_refs)
        for (size_t i = 0; i < P->d->n_instances; i++)
            free(P->instance_refs[i].name);
    free(P->instance_refs);
}

/* What pbrt-v4 checks once all files are read. */
static int finish(parser *P, const lf_loc *eof)
{
    lf_scene_desc *d = P->d;
    if (!P->world)
        return perr(P, LF_ERR_PARSE, eof, "end of file before WorldBegin");
    while (P->n_stack) {
        pushed *e = &P->stack[P->n_stack - 1];
        if (e->kind == 'o')
            pwarn(P, &e->loc, "ObjectBegin without ObjectEnd at end of file");
        else
            pwarn(P, &e->loc, "%s without %s at end of file", block_name(e->kind),
                  e->kind == 'a' ? "AttributeEnd" : "TransformEnd");
        gstate_free(&e->saved);
        P->n_stack--;
    }
    /* Resolve NamedMaterial references; every one must name a material. */
    int *resolved = NULL;
    if (P->n_material_refs) {
        resolved = malloc(P->n_material_refs * sizeof *resolved);
        if (!resolved)
            return nomem(P);
    }
    int rc = LF_OK;
    for (size_t i = 0; i < P->n_material_refs; i++) {
        resolved[i] = strmap_get(&P->material_map, P->material_refs[i].name);
        if (resolved[i] < 0 && P->n_errors < P->max_errors)
            rc = perr(P, LF_ERR_PARSE, &P->material_refs[i].loc, "NamedMaterial \"%s\" is not defined",
                      P->material_refs[i].name);
    }
    if (rc) {
        free(resolved);
        return P->first_code;
    }
    for (size_t i = 0; i < d->n_shapes; i++)
        if (d->shapes[i].material <= -2)
            d->shapes[i].material = resolved[-2 - d->shapes[i].material];
    free(resolved);
    for (size_t i = 0; i < d->n_instances; i++) {
        int o = strmap_get(&P->object_map, P->instance_refs[i].name);
        if (o < 0 && P->n_errors < P->max_errors)
            rc = perr(P, LF_ERR_PARSE, &P->instance_refs[i].loc, "ObjectInstance \"%s\": no such object",
                      P->instance_refs[i].name);
        d->instances[i].object = o;
    }
    return rc ? P->first_code : LF_OK;
}

static int parse_begin(parser *P, const lf_parse_opts *o, lf_scene_desc *out, lf_error *err)
{
    memset(out, 0, sizeof *out);
    memset(P, 0, sizeof *P);
    P->d = out;
    P->err = err;
    P->max_errors = o && o->max_errors > 0 ? o->max_errors : LF_PARSE_MAX_ERRORS;
    P->allow_unsupported = o ? o->allow_unsupported : 0;
    out->allow_unsupported = P->allow_unsupported;
    out->transform_start_time = 0.0;
    out->transform_end_time = 1.0;
    P->gs.ctm[0] = P->gs.ctm[1] = lf_transform_identity();
    /* a scene without a Camera directive: pbrt-v4's default camera at the
     * origin (a zero matrix here made NaN rays and Embree aborted) */
    out->camera.world_to_camera.xf[0] = out->camera.world_to_camera.xf[1] = P->gs.ctm[0];
    P->gs.active[0] = P->gs.active[1] = 1;
    P->gs.material = -1;
    P->gs.area_light = -1;
    P->current_object = -1;
    return set_coordsys(P, "world", P->gs.ctm);
}

static int parse_end(parser *P, lexer *L, int rc, const lf_loc *eof, char **errors)
{
    if (!rc)
        rc = finish(P, eof);
    lx_free(L);
    parser_free(P);
    if (rc) {
        /* Make sure the caller sees a message even for a bare status. */
        if (P->err && P->err->code == LF_OK)
            lf_error_set(P->err, rc, "scene parse failed");
        lf_scene_desc_free(P->d);
    }
    if (errors) {
        *errors = rc ? P->errors : NULL;
        if (rc && !P->errors && P->err)
            *errors = dup_cstr(P->err->msg);
        if (!rc)
            free(P->errors);
    } else {
        free(P->errors);
    }
    return rc;
}

int lf_scene_parse_file_ex(const char *path, const lf_parse_opts *opts, lf_scene_desc *out, lf_error *err,
                           char **errors)
{
    parser P;
    lexer L = {0};
    lf_loc eof = {path, 1, 1};
    int rc = parse_begin(&P, opts, out, err);
    if (!rc)
        rc = push_file(&P, &L, path, NULL);
    if (!rc)
        P.main_dir = out->scene_dir = L.fr[0].dir;
    if (!rc)
        rc = parse_run(&P, &L, &eof);
    return parse_end(&P, &L, rc, &eof, errors);
}

int lf_scene_parse_file(const char *path, lf_scene_desc *out, lf_error *err)
{
    return lf_scene_parse_file_ex(path, NULL, out, err, NULL);
}

int lf_scene_parse_string_ex(const char *text, const char *name, const lf_parse_opts *opts, lf_scene_desc *out,
                             lf_error *err, char **errors)
{
    parser P;
    lexer L = {0};
    if (!name)
        name = "<string>";
    int rc = parse_begin(&P, opts, out, err);
    const char *file = NULL, *dir = NULL;
    if (!rc) {
        char *dname = dir_of(name);
        file = keep_string(&P, name);
        dir = dname ? keep_string(&P, dname) : NULL;
        free(dname);
        if (!file || !dir)
            rc = nomem(&P);
    }
    lf_loc eof = {name, 1, 1};
    if (!rc && lx_push(&L, NULL, text ? text : "", text ? strlen(text) : 0, file, dir, NULL))
        rc = nomem(&P);
    if (!rc)
        P.main_dir = out->scene_dir = dir;
    if (!rc)
        rc = parse_run(&P, &L, &eof);
    return parse_end(&P, &L, rc, &eof, errors);
}

int lf_scene_parse_string(const char *text, const char *name, lf_scene_desc *out, lf_error *err)
{
    return lf_scene_parse_string_ex(text, name, NULL, out, err, NULL);
}

void lf_scene_desc_free(lf_scene_desc *d)
{
    if (!d)
        return;
    entity_free(&d->camera.e);
    entity_free(&d->film);
    entity_free(&d->sampler);
    entity_free(&d->integrator);
    entity_free(&d->filter);
    entity_free(&d->accelerator);
    for (size_t i = 0; i < d->n_textures; i++) {
        entity_free(&d->textures[i].e);
        free(d->textures[i].name);
    }
    free(d->textures);
    for (size_t i = 0; i < d->n_materials; i++) {
        entity_free(&d->materials[i].e);
        free(d->materials[i].name);
    }
    free(d->materials);
    for (size_t i = 0; i < d->n_lights; i++)
        entity_free(&d->lights[i].e);
    free(d->lights);
    for (size_t i = 0; i < d->n_area_lights; i++)
        entity_free(&d->area_lights[i]);
    free(d->area_lights);
    for (size_t i = 0; i < d->n_shapes; i++)
        entity_free(&d->shapes[i].e);
    free(d->shapes);
    for (size_t i = 0; i < d->n_objects; i++)
        free(d->objects[i].name);
    free(d->objects);
    free(d->instances);
    for (size_t i = 0; i < d->n_media; i++) {
        entity_free(&d->media[i].e);
        free(d->media[i].name);
    }
    free(d->media);
    free(d->warnings);
    for (size_t i = 0; i < d->n_strings; i++)
        free(d->strings[i]);
    free(d->strings);
    memset(d, 0, sizeof *d);
}
