/* Probing a face-varying channel's levels (internal; surface/fvar_probe.c). */
#ifndef CCN_SURFACE_FVAR_PROBE_H
#define CCN_SURFACE_FVAR_PROBE_H

#include "surface/fvar_builder.h"
#include "surface/plan_types.h"

typedef struct { int32_t *start, *list; } ccn__fvar_csr;

/* K(f): the value vertices at the corners of the faces that share a value vertex with level-0
 * face f, each once; empty where skip[f] >= 0 (weights written down). -1 out of memory. */
int ccn__fvar_neighbourhoods(const ccn_mesh *m, const int32_t *skip, ccn__fvar_csr *K);
/* Colours of the value vertices, no two in one K(f) alike; the number of colours, -1 out of
 * memory. */
int32_t ccn__fvar_colour(const ccn_mesh *m, const ccn__fvar_csr *K, int32_t *col);
/* c->pl: the points each level must compute for the composed outputs c->outs (their limit
 * stencils c->st_* and the sub level around c->near). -1 out of memory. */
int ccn__fvar_probe_lists(ccn__fvar_builder *c);
/* npass passes (colours 3b .. 3b+2 set to 1): each candidate e of output c->outs[i] (row
 * start[o] .. start[o+1], colour ccol[e]) gets its weight cw[e]. -1 out of memory. */
int ccn__fvar_probe_all(const ccn_plan *p, ccn__fvar_builder *c, int32_t npass, const int32_t *col,
                        const int32_t *start, const int32_t *ccol, double *cw);

#endif
