/* Probing a face-varying channel's levels (internal; surface/fvar_probe.c). */
#ifndef CCN_SURFACE_FVAR_PROBE_H
#define CCN_SURFACE_FVAR_PROBE_H

#include "surface/fvar_builder.h"
#include "surface/plan_types.h"

typedef struct { int32_t *start, *list; } ccn__fvar_csr;

/* The candidates of the composed outputs: output o's row start[o] .. start[o+1] holds K(f),
 * f = c->fo[o], in K's order; per K row, its entries' offsets in the row sorted by colour
 * (perm) and those colours (col), so a pass finds its (at most three) colours at once. */
typedef struct { const int32_t *start, *kstart, *perm, *col; } ccn__fvar_cands;

/* K(f): the value vertices at the corners of the faces that share a value vertex with level-0
 * face f, each once; empty where skip[f] >= 0 (weights written down). -1 out of memory. */
int ccn__fvar_neighbourhoods(const ccn_mesh *m, const int32_t *skip, ccn__fvar_csr *K);
/* Colours of the value vertices, no two in one K(f) alike; the number of colours, -1 out of
 * memory. */
int32_t ccn__fvar_colour(const ccn_mesh *m, const ccn__fvar_csr *K, int32_t *col);
/* c->pl: the points each level must compute for the composed outputs c->outs (their limit
 * stencils c->st_* and the sub level around c->near). -1 out of memory. */
int ccn__fvar_probe_lists(ccn__fvar_builder *c);
/* npass passes (colours 3b .. 3b+2 set to 1, col per level-0 value vertex): each candidate e
 * of an output c->outs[i] (cd) gets its weight cw[e]. -1 out of memory. */
/* The outputs c->outs of a channel that kept its levels (ccn__fvar_stencils.levels): the
 * levels and limit stencils run on the caller's values (width per value, scaled by `down`,
 * the results by `up`), written to out (width per output value). Returns -1 out of memory. */
int ccn__fvar_levels_evaluate(const ccn_plan *p, ccn__fvar_builder *c, const double *vals, int32_t width,
                              double down, double up, double *out);
int ccn__fvar_probe_all(const ccn_plan *p, ccn__fvar_builder *c, int32_t npass, const int32_t *col,
                        const ccn__fvar_cands *cd, double *cw);

#endif
