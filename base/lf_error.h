/* lf_error.h - error reporting for every lensfield library.
 *
 * Libraries never print or exit: a function that can fail takes an
 * `lf_error *` (which may be NULL), returns a status (0 = ok, non-zero = an
 * LF_ERR_* code) and keeps the FIRST message set on the error, so the
 * root cause is what the caller sees.  Only tools/ print and exit.
 *
 *   lf_error err = {0};
 *   if (lf_something(..., &err)) { fprintf(stderr, "%s\n", err.msg); return 1; }
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

#ifdef __cplusplus
}
#endif
#endif
