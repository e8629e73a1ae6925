/* Union-find over int32 indices (internal): parent[x] == x for a root; ccn__uf_union keeps the
 * smaller index as the root, so the classes' roots do not depend on the order of unions. Used
 * for the knot rings (topology/knots.c) and the fans of non-manifold vertices
 * (topology/split.c). */
#ifndef CCN_BASE_UNION_FIND_H
#define CCN_BASE_UNION_FIND_H

#include <stdint.h>

static inline int32_t ccn__uf_find(int32_t *parent, int32_t x) {
    while (parent[x] != x) { /* path halving */
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static inline void ccn__uf_union(int32_t *parent, int32_t a, int32_t b) {
    a = ccn__uf_find(parent, a);
    b = ccn__uf_find(parent, b);
    if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

#endif
