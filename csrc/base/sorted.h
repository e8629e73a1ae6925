/* Search in a sorted array of doubles (internal). Used by the export's topology (a piece's
 * intervals on its line, io/export_topo.c) and face merging (knots and cells along a shared
 * side, io/face_merge.c), where sides hold thousands of values. */
#ifndef CCN_BASE_SORTED_H
#define CCN_BASE_SORTED_H

#include <stddef.h>

/* The first index of the non-decreasing xs[0 .. n) whose value is >= x (n if none). */
static inline size_t ccn__first_at_least(const double *xs, size_t n, double x) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (xs[mid] < x) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

#endif
