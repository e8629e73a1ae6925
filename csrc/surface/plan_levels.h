/* The refinement levels of a plan (internal; surface/plan_levels.c). */
#ifndef CCN_SURFACE_PLAN_LEVELS_H
#define CCN_SURFACE_PLAN_LEVELS_H

#include "surface/plan_types.h"

/* Builds levels p->R+1 .. R (topology and prepared rules); lev[0..p->R] exist. */
ccn_status ccn__plan_build_levels(ccn_plan *p, int32_t R, ccn_error *err);

#endif
