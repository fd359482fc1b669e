/* lf_progress.h - wall-clock time and the text of a progress bar, for tools
 * that report long work (the library never prints: the tool prints the line).
 *
 *   lf_progress p; lf_progress_start(&p);
 *   char line[128];
 *   if (lf_progress_line(&p, done, total, line, sizeof line)) fputs(line, stderr);
 */
#ifndef LF_PROGRESS_H
#define LF_PROGRESS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds on the monotonic clock (for intervals). */
double lf_seconds(void);

typedef struct lf_progress {
    double t0, last; /* start, and when the last line was made (lf_seconds) */
} lf_progress;

void lf_progress_start(lf_progress *p);
/* The line for `done` of `total`: "\r[####....]  42.0%   12.3s elapsed  ETA
 * 17.0s " (40-character bar; ETA from the rate so far), ending in a newline
 * when done == total.  Returns 0 (buf untouched) when the previous line is
 * less than 0.2 s old and the work is not finished, else 1. */
int lf_progress_line(lf_progress *p, long done, long total, char *buf, size_t n);

#ifdef __cplusplus
}
#endif
#endif
