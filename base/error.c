#include "lf_error.h"

#include <stdarg.h>
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
