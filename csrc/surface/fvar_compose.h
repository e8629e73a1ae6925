/* The composed limit stencils of a face-varying channel (internal; surface/fvar_compose.c). */
#ifndef CCN_SURFACE_FVAR_COMPOSE_H
#define CCN_SURFACE_FVAR_COMPOSE_H

#include "surface/plan_types.h"

/* Each output value (a level-L value vertex) as weights over the channel's cage values. */
typedef struct {
    int32_t nout;           /* output values */
    int32_t *start, *idx;   /* CSR, nout + 1 offsets; idx: the caller's value indices */
    double *w;
    int32_t *face_values;   /* 4 * num_faces: the output value of each output face corner */
    int32_t num_seams, num_sharp;
} ccn__fvar_stencils;

/* Builds the channel's value levels and limit stencils (refine/fvar.c, surface/limit.c), composes
 * them into stencils over the cage values, and frees the levels. */
ccn_status ccn__fvar_compose(const ccn_plan *p, const ccn_fvar_channel *ch, ccn__fvar_stencils *out,
                             ccn_error *err);
void ccn__fvar_stencils_free(ccn__fvar_stencils *s);

#endif
