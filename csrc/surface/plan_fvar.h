/* Face-varying channels and per-vertex data on a plan's output (internal; surface/plan_fvar.c,
 * public ccn_plan_add_fvar / ccn_plan_get_fvar_sizes / ccn_plan_evaluate_fvar /
 * ccn_plan_evaluate_vertex_data). */
#ifndef CCN_SURFACE_PLAN_FVAR_H
#define CCN_SURFACE_PLAN_FVAR_H

#include "surface/plan_types.h"

/* Frees channel c of the plan (ccn_plan_destroy). */
void ccn__fvchan_free(struct ccn__fvchan *c);

#endif
