/* The composed limit stencils of a face-varying channel (internal; surface/fvar_compose.c). */
#ifndef CCN_SURFACE_FVAR_COMPOSE_H
#define CCN_SURFACE_FVAR_COMPOSE_H

#include "surface/fvar_rows.h"
#include "surface/plan_types.h"


/* Builds the channel's value levels and limit stencils (refine/fvar.c, surface/limit.c), composes
 * them into stencils over the cage values, and frees the levels. */
ccn_status ccn__fvar_compose(const ccn_plan *p, const ccn_fvar_channel *ch, ccn__fvar_stencils *out,
                             ccn_error *err);

#endif
