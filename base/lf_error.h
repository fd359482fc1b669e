/* lf_error.h - error reporting for every lensfield library.
 *
 * Libraries never print or exit: a function that can fail takes an
 * `lf_error *` (which may be NULL), returns a status (0 = ok, non-zero = an
 * LF_ERR_* code) and keeps the FIRST message set on the error, so the
 * root cause is what the caller sees.  Only tools/ print and exit.
 *
 *   lf_error err = {0};
 *   if (lf_something(..., &err)) { fprintf(stderr, "%s\n", err.msg); return 1; }
 *
 * Errors about something written in a file carry its place: lf_error_at
 * formats the lf_loc once ("file:line:col: message"), as pbrt-v4's
 * Error(const FileLoc *, ...) does; nothing else spells "%s:%d:%d".
 * Warnings go to one channel, an lf_warnings list the caller prints:
 *
 *   lf_warn_at(&w, &entity->loc, "\"%s\" is ignored", name);
 *   // w.text: "scene.pbrt:3:1: warning: \"x\" is ignored\n"
 *
 * The plugin ABI (camera/lf_camera.h) is the one place that reports errors
 * into a char buffer instead, so plugins need no lensfield library.
 */
#ifndef LF_ERROR_H
#define LF_ERROR_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    LF_OK = 0,
    LF_ERR_IO = 1,        /* file missing, unreadable, unwritable */
    LF_ERR_PARSE = 2,     /* malformed input; message names file:line:col */
    LF_ERR_PARAM = 3,     /* bad, unknown or unused parameter value */
    LF_ERR_UNSUPPORTED = 4,
    LF_ERR_NOMEM = 5,
    LF_ERR_NUMERIC = 6,   /* NaN/Inf or out-of-range numbers */
    LF_ERR_INTERNAL = 7,
    LF_ERR_INTERRUPTED = 8 /* stopped on request (SIGINT/SIGTERM); state was saved */
};

typedef struct lf_error {
    int code;
    char msg[1024];
} lf_error;

/* Sets code and message unless an error is already recorded.  Returns code,
 * so `return lf_error_set(err, LF_ERR_IO, "...", ...);` reads naturally.
 * err may be NULL. */
int lf_error_set(lf_error *err, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Clears a recorded error. */
void lf_error_clear(lf_error *err);

/* Where something was written in a file.  `file` points into storage owned
 * by whoever read the file (a scene description, or a string literal); it
 * stays valid as long as the owner does.  line 0: the file as a whole; col 0:
 * the line as a whole.  64-bit: a 3 GB line is read (as a stream) and its
 * columns must be told exactly. */
typedef struct lf_loc {
    const char *file;
    long long line, col;
} lf_loc;

/* The one location formatter: "file:line:col", "file:line" (col 0), "file"
 * (line 0); a NULL file is "<unknown>".  Writes at most n bytes (NUL
 * included) and returns what snprintf returns. */
int lf_loc_format(char *buf, size_t n, const lf_loc *loc);

/* lf_error_set with the location in front: "file:line:col: message".  A NULL
 * loc sets the message alone.  Returns code. */
int lf_error_at(lf_error *err, int code, const lf_loc *loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* The one warning channel: lines of text, each ending in '\n', for the tool
 * to print.  Zero-initialise; free with lf_warnings_free.  Appending never
 * fails the caller: a warning lost to an allocation failure is counted in
 * `lost`. */
typedef struct lf_warnings {
    char *text; /* NULL while empty */
    size_t len, cap;
    int count, lost;
} lf_warnings;

/* Appends "LOC: warning: message\n" (a NULL loc: "warning: message\n"). */
void lf_warn_at(lf_warnings *w, const lf_loc *loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Appends a line as it is (a newline is added when missing); several lines
 * at once count as one warning each.  For warnings that already carry their
 * place, e.g. those of a scene description passed on by the renderer. */
void lf_warn_text(lf_warnings *w, const char *text);

/* The text gathered so far, or NULL when there is none. */
const char *lf_warnings_text(const lf_warnings *w);

void lf_warnings_free(lf_warnings *w);

#ifdef __cplusplus
}
#endif
#endif
