/* A minimal parallel-for over index ranges with pthreads (internal). Each worker gets a
 * contiguous range; results are deterministic because ranges write disjoint outputs. */
#ifndef CCN_BASE_PARALLEL_H
#define CCN_BASE_PARALLEL_H
#include <stdint.h>

typedef void (*ccn__range_fn)(void *ctx, int32_t begin, int32_t end);
/* Runs fn over [0, n) on up to `threads` threads (1 = inline); small n runs inline. */
void ccn__parallel_for(int threads, int32_t n, ccn__range_fn fn, void *ctx);
/* The same for n large tasks: up to min(threads, n) threads whatever n is. */
void ccn__parallel_tasks(int threads, int32_t n, ccn__range_fn fn, void *ctx);
/* Thread count from the option (> 0), else CCN_THREADS, else the online CPUs (max 16). */
int ccn__thread_count(int32_t option);
#endif
