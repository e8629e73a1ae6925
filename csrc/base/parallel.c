/* Parallel-for with pthreads: contiguous ranges, joined before returning. */
#include "base/parallel.h"

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#define CCN_MAX_THREADS 16
#define CCN_MIN_PER_THREAD 4096

typedef struct { ccn__range_fn fn; void *ctx; int32_t begin, end; } job;

static void *run_job(void *arg) {
    job *j = arg;
    j->fn(j->ctx, j->begin, j->end);
    return NULL;
}

static void run(int threads, int32_t n, ccn__range_fn fn, void *ctx) {
    if (threads <= 1) {
        if (n > 0) fn(ctx, 0, n);
        return;
    }
    job jobs[CCN_MAX_THREADS];
    pthread_t tid[CCN_MAX_THREADS];
    int started[CCN_MAX_THREADS] = {0};
    for (int t = 0; t < threads; t++) {
        jobs[t].fn = fn;
        jobs[t].ctx = ctx;
        jobs[t].begin = (int32_t)((int64_t)n * t / threads);
        jobs[t].end = (int32_t)((int64_t)n * (t + 1) / threads);
        /* worker 0 runs on the calling thread; a failed create runs inline too */
        if (t > 0) started[t] = pthread_create(&tid[t], NULL, run_job, &jobs[t]) == 0;
    }
    run_job(&jobs[0]);
    for (int t = 1; t < threads; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else run_job(&jobs[t]);
    }
}

void ccn__parallel_for(int threads, int32_t n, ccn__range_fn fn, void *ctx) {
    if (threads > CCN_MAX_THREADS) threads = CCN_MAX_THREADS;
    if (threads > n / CCN_MIN_PER_THREAD) threads = n / CCN_MIN_PER_THREAD;
    run(threads, n, fn, ctx);
}

void ccn__parallel_tasks(int threads, int32_t n, ccn__range_fn fn, void *ctx) {
    if (threads > CCN_MAX_THREADS) threads = CCN_MAX_THREADS;
    if (threads > n) threads = n;
    run(threads, n, fn, ctx);
}

int ccn__thread_count(int32_t option) {
    if (option > 0) return option > CCN_MAX_THREADS ? CCN_MAX_THREADS : option;
    const char *e = getenv("CCN_THREADS");
    if (e) {
        int t = atoi(e);
        if (t > 0) return t > CCN_MAX_THREADS ? CCN_MAX_THREADS : t;
    }
    long c = sysconf(_SC_NPROCESSORS_ONLN);
    return c < 1 ? 1 : c > CCN_MAX_THREADS ? CCN_MAX_THREADS : (int)c;
}
