/* The parallel for (base/parallel.c): every item runs exactly once on a
 * thread id below the thread count, for any item count, thread count and
 * chunk; the background form runs them all by the time it is joined. */
#include <stdatomic.h>
#include <stdlib.h>

#include "base/lf_parallel.h"
#include "lf_test.h"

typedef struct {
    atomic_int *hits;
    atomic_int bad_tid, calls;
    int nth;
} count_ctx;

static void count(void *arg, int i0, int i1, int tid)
{
    count_ctx *c = arg;
    atomic_fetch_add(&c->calls, 1);
    if (tid < 0 || tid >= c->nth)
        atomic_fetch_add(&c->bad_tid, 1);
    for (int i = i0; i < i1; i++)
        atomic_fetch_add(&c->hits[i], 1);
}

static int run(int n, int threads, int chunk, int background)
{
    count_ctx c;
    c.hits = calloc((size_t)(n > 0 ? n : 1), sizeof *c.hits);
    atomic_init(&c.bad_tid, 0);
    atomic_init(&c.calls, 0);
    c.nth = lf_parallel_threads(threads);
    if (background)
        lf_parallel_join(lf_parallel_start(n, threads, chunk, count, &c));
    else
        CHECK(lf_parallel_for(n, threads, chunk, count, &c) == c.nth);
    int wrong = atomic_load(&c.bad_tid);
    for (int i = 0; i < n; i++)
        wrong += atomic_load(&c.hits[i]) != 1;
    int k = chunk > 0 ? chunk : 1;
    CHECK_MSG(atomic_load(&c.calls) == (n + k - 1) / k, "n %d chunk %d: %d calls", n, chunk, atomic_load(&c.calls));
    free(c.hits);
    return wrong;
}

int main(void)
{
    CHECK(lf_parallel_threads(0) >= 1 && lf_parallel_threads(-3) == lf_parallel_threads(0));
    CHECK(lf_parallel_threads(5) == 5 && lf_parallel_threads(1 << 20) == LF_PARALLEL_MAX_THREADS);
    const int ns[] = {0, 1, 7, 1000}, ths[] = {0, 1, 2, 3, 17}, chunks[] = {0, 1, 3, 64};
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 5; b++)
            for (int k = 0; k < 4; k++)
                for (int bg = 0; bg < 2; bg++) {
                    int wrong = run(ns[a], ths[b], chunks[k], bg);
                    CHECK_MSG(wrong == 0, "n %d threads %d chunk %d %s: %d items wrong", ns[a], ths[b], chunks[k],
                              bg ? "start/join" : "for", wrong);
                }
    lf_parallel_join(NULL);
    return lf_test_end();
}
