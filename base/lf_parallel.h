/* lf_parallel.h - a parallel for over [0, n) on system threads
 * (pthreads), items handed out in chunks from an atomic counter so uneven
 * items balance.  fn(ctx, i0, i1, tid) runs items [i0, i1) on thread tid
 * (0 <= tid < threads).  The calling thread takes part; when a thread
 * cannot be created its share runs on the others. */
#ifndef LF_PARALLEL_H
#define LF_PARALLEL_H

#define LF_PARALLEL_MAX_THREADS 1024 /* tid < this; size per-thread scratch with lf_parallel_threads() */

typedef void (*lf_parallel_fn)(void *ctx, int i0, int i1, int tid);

/* threads <= 0: the online cores; at most LF_PARALLEL_MAX_THREADS.
 * chunk <= 0: 1.  Returns the thread count used (>= 1).  Which thread runs
 * an item never changes what the item computes, so results that are a
 * function of the item alone are the same for any thread count. */
int lf_parallel_for(int n, int threads, int chunk, lf_parallel_fn fn, void *ctx);
/* The thread count lf_parallel_for(n, threads, ...) uses (tid < it). */
int lf_parallel_threads(int threads);

/* The same loop in the background, for a caller that watches while it runs
 * (the renderer's checkpoints): `threads` new threads (tid 0 .. threads-1)
 * take the items and lf_parallel_start returns at once; the caller does not
 * take part.  When no thread can be created the loop runs on the calling
 * thread before lf_parallel_start returns.  lf_parallel_join waits for
 * every item and frees the job (NULL is fine). */
typedef struct lf_parallel_job lf_parallel_job;
lf_parallel_job *lf_parallel_start(int n, int threads, int chunk, lf_parallel_fn fn, void *ctx);
void lf_parallel_join(lf_parallel_job *job);

#endif
