/* What a recreated plan keeps of the earlier plan's stencil table (internal;
 * surface/stencil_reuse.c, for surface/tessellate.c). */
#ifndef CCN_SURFACE_STENCIL_REUSE_H
#define CCN_SURFACE_STENCIL_REUSE_H

#include "surface/limit.h"
#include "surface/plan_types.h"

#define CCN_FAST_MAX 9 /* entries of a regular output vertex's stencil (3 x 3) */

/* Per level-L vertex of m, 1 where a regular stencil may read an interval that differs from
 * q's (q: the same level of the earlier plan); NULL when out of memory or not comparable. */
uint8_t *ccn__moved_vertices(const ccn_mesh *m, const ccn_mesh *q);
/* The length of output o's row in the earlier plan q if it is a regular one, else -1. */
int32_t ccn__earlier_regular(const ccn_plan *q, int32_t o);
/* Output o's regular row in the earlier plan q into s: 1, or 0 if it is not a regular row. */
int ccn__earlier_row(const ccn_plan *q, int32_t o, ccn__stencil *s);

typedef struct {
    const uint8_t *fast, *moved;  /* per output vertex: regular; per level-L vertex: moved */
    const int32_t *len, *istart;  /* per output vertex: the irregular rows' length, first entry */
    const int32_t *iv;            /* the irregular rows' entries (made by the caller) */
    const double *iwp, *iwu, *iwv;
    int pinned;
} ccn__reuse_rows;
typedef struct { int32_t *v; double *wp, *wu, *wv; int32_t n; } ccn__reuse_table;
/* p->hint's table made p's, the changed rows rewritten: 1 (p->st_start, st_w, ws, nws,
 * st_nown set; the entries and own weights in t), 0 when it does not fit (nothing changed),
 * -1 when out of memory. */
int ccn__patch_stencils(ccn_plan *p, const ccn__reuse_rows *j, ccn__reuse_table *t);

#endif
