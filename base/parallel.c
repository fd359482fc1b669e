/* A parallel for on pthreads (lf_parallel.h). */
#include <pthread.h>
#include <stdatomic.h>
#include <unistd.h>

#include "lf_parallel.h"

enum { MAX_THREADS = LF_PARALLEL_MAX_THREADS };

typedef struct par_shared {
    atomic_int next;
    int n, chunk;
    lf_parallel_fn fn;
    void *ctx;
} par_shared;

typedef struct par_job {
    par_shared *s;
    int tid;
} par_job;

static void *par_worker(void *arg)
{
    par_job *j = arg;
    par_shared *s = j->s;
    for (;;) {
        int i0 = atomic_fetch_add(&s->next, s->chunk);
        if (i0 >= s->n)
            break;
        int i1 = i0 + s->chunk < s->n ? i0 + s->chunk : s->n;
        s->fn(s->ctx, i0, i1, j->tid);
    }
    return NULL;
}

int lf_parallel_for(int n, int threads, int chunk, lf_parallel_fn fn, void *ctx)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int nth = threads > 0 ? threads : (cores > 0 ? (int)cores : 1);
    if (nth > MAX_THREADS)
        nth = MAX_THREADS;
    if (chunk <= 0)
        chunk = 1;
    if (n <= 0)
        return nth;
    par_shared s;
    atomic_init(&s.next, 0);
    s.n = n, s.chunk = chunk, s.fn = fn, s.ctx = ctx;
    par_job jobs[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    int created[MAX_THREADS] = {0};
    for (int t = 0; t < nth; t++)
        jobs[t] = (par_job){&s, t};
    for (int t = 1; t < nth; t++)
        created[t] = pthread_create(&tid[t], NULL, par_worker, &jobs[t]) == 0;
    par_worker(&jobs[0]);
    for (int t = 1; t < nth; t++)
        if (created[t])
            pthread_join(tid[t], NULL);
    return nth;
}
