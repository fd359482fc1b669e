/* A parallel for on pthreads (lf_parallel.h). */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
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

int lf_parallel_threads(int threads)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int nth = threads > 0 ? threads : (cores > 0 ? (int)cores : 1);
    return nth > MAX_THREADS ? MAX_THREADS : nth;
}

/* A loop's shared counter and its threads (tid 0 may be the caller). */
struct lf_parallel_job {
    par_shared s;
    int nth;
    par_job jobs[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    int created[MAX_THREADS];
};

static void job_init(lf_parallel_job *j, int n, int nth, int chunk, lf_parallel_fn fn, void *ctx)
{
    atomic_init(&j->s.next, 0);
    j->s.n = n, j->s.chunk = chunk > 0 ? chunk : 1, j->s.fn = fn, j->s.ctx = ctx;
    j->nth = nth;
    for (int t = 0; t < nth; t++) {
        j->jobs[t] = (par_job){&j->s, t};
        j->created[t] = 0;
    }
}

/* Threads first..nth-1; returns how many were created. */
static int job_spawn(lf_parallel_job *j, int first)
{
    int started = 0;
    for (int t = first; t < j->nth; t++)
        started += j->created[t] = pthread_create(&j->tid[t], NULL, par_worker, &j->jobs[t]) == 0;
    return started;
}

static void job_wait(lf_parallel_job *j)
{
    for (int t = 0; t < j->nth; t++)
        if (j->created[t])
            pthread_join(j->tid[t], NULL);
}

int lf_parallel_for(int n, int threads, int chunk, lf_parallel_fn fn, void *ctx)
{
    int nth = lf_parallel_threads(threads);
    if (n <= 0)
        return nth;
    lf_parallel_job j;
    job_init(&j, n, nth, chunk, fn, ctx);
    job_spawn(&j, 1);
    par_worker(&j.jobs[0]); /* takes items until none is left, also those of threads not created */
    job_wait(&j);
    return nth;
}

lf_parallel_job *lf_parallel_start(int n, int threads, int chunk, lf_parallel_fn fn, void *ctx)
{
    int nth = lf_parallel_threads(threads);
    lf_parallel_job *j = malloc(sizeof *j);
    if (!j) { /* no memory for the job: run the loop here */
        lf_parallel_for(n, 1, chunk, fn, ctx);
        return NULL;
    }
    job_init(j, n > 0 ? n : 0, nth, chunk, fn, ctx);
    if (n > 0 && !job_spawn(j, 0))
        par_worker(&j->jobs[0]);
    return j;
}

void lf_parallel_join(lf_parallel_job *job)
{
    if (!job)
        return;
    job_wait(job);
    free(job);
}
