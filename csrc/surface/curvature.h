/* Principal curvatures of the limit surface at the output vertices (internal;
 * surface/curvature.c). */
#ifndef CCN_SURFACE_CURVATURE_H
#define CCN_SURFACE_CURVATURE_H

#include "surface/plan_types.h"

/* k1 >= k2 and the unit direction of k1 (dir may be NULL) from S_u, S_v, S_uu, S_uv, S_vv
 * (d[0..4]); NaN when the tangents are degenerate. Positive where the surface bends away from
 * its normal S_u x S_v. */
void ccn__principal_curvatures(const double d[5][3], double *k1, double *k2, double dir[3]);
/* out->curvatures (and out->curvature_dirs if given) of every output vertex, after the levels'
 * points are evaluated; NaN where the value is unbounded or not computed (curvature.c). The
 * first call makes the plan's shared second-derivative weights (p->curv_ws). */
ccn_status ccn__curvature_evaluate(ccn_plan *p, ccn_limit_mesh *out, ccn_error *err);

#endif
