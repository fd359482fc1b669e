/* Wall-clock time and progress-bar text (lf_progress.h). */
#include "lf_progress.h"

#include <stdio.h>
#include <time.h>

double lf_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void lf_progress_start(lf_progress *p)
{
    p->t0 = lf_seconds();
    p->last = 0;
}

int lf_progress_line(lf_progress *p, long done, long total, char *buf, size_t n)
{
    double t = lf_seconds();
    if (t - p->last < 0.2 && done < total)
        return 0;
    p->last = t;
    double frac = total > 0 ? (double)done / total : 1, el = t - p->t0;
    double eta = frac > 0 ? el * (1 - frac) / frac : 0;
    enum { WIDTH = 40 };
    int fill = (int)(frac * WIDTH);
    char bar[WIDTH + 1];
    for (int i = 0; i < WIDTH; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[WIDTH] = '\0';
    snprintf(buf, n, "\r[%s] %5.1f%%  %6.1fs elapsed  ETA %6.1fs %s", bar, 100 * frac, el, eta,
             done >= total ? "\n" : "");
    return 1;
}
