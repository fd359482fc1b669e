/* bench_util.h - what every benchmark times with: wall-clock seconds
 * (lf_seconds, base/lf_progress.h), the process's CPU seconds, and the
 * median of repeated runs (docs/performance.md quotes medians). */
#ifndef LF_BENCH_UTIL_H
#define LF_BENCH_UTIL_H

#include <stdlib.h>
#include <time.h>

#include "base/lf_progress.h"

static inline double bench_cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

/* qsort comparison of doubles, ascending. */
static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v and returns its median. */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

#endif
