/* parallel_internal.h - a parallel for over [0, n) on system threads
 * (pthreads), items handed out in chunks from an atomic counter so uneven
 * items balance.  fn(ctx, i0, i1, tid) runs items [i0, i1) on thread tid
 * (0 <= tid < threads).  The calling thread takes part; when a thread
 * cannot be created its share runs on the others. */
#ifndef LF_LF_PARALLEL_INTERNAL_H
#define LF_LF_PARALLEL_INTERNAL_H

typedef void (*lf_lf_par_fn)(void *ctx, int i0, int i1, int tid);

/* threads <= 0: 2.  chunk <= 0: 1.  Returns the thread count used (>= 1). */
int lf_lf_parallel_for(int n, int threads, int chunk, lf_lf_par_fn fn, void *ctx);

#endif
