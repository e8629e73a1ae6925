/* Principal curvatures of the limit surface at the output vertices (internal;
 * surface/curvature.c). */
#ifndef CCN_SURFACE_CURVATURE_H
#define CCN_SURFACE_CURVATURE_H

#include "surface/plan_types.h"

/* k1 >= k2 and the unit direction of k1 (dir may be NULL) from S_u, S_v, S_uu, S_uv, S_vv
 * (d[0..4]); NaN when the tangents are degenerate. Positive where the surface bends away from
 * its normal S_u x S_v. */
void ccn__principal_curvatures(const double d[5][3], double *k1, double *k2, double dir[3]);
/* The plan's curvature tables (plan_types.h: curv_mode and the second-derivative weights
 * aligned with the stencil rows), once per plan, before the first stencil pass that computes
 * curvatures. */
ccn_status ccn__curvature_prepare(ccn_plan *p, ccn_error *err);
/* Output o's curvatures (and direction) from its derivatives in the unit box of evaluate. */
void ccn__curvature_at(const ccn_plan *p, const double d[5][3], ccn_limit_mesh *out, int32_t o);
/* The same from the unit normal of S_u x S_v (ccn__unit_normal of d[0], d[1]): one square
 * root and one division fewer; no direction. */
void ccn__curvature_at_unit(const ccn_plan *p, const double d[5][3], const double nh[3],
                            ccn_limit_mesh *out, int32_t o);
/* Output o: NaN, the flag (no bounded single value, or its cap's patch gives it later). */
void ccn__curvature_flag(ccn_limit_mesh *out, int32_t o);
/* After the stencil pass (which computed the CCN__CURV_ROW outputs and flagged the others) and
 * the caps: the outputs with stencils of their own, and the caps' and their rings' patches. */
void ccn__curvature_evaluate(ccn_plan *p, ccn_limit_mesh *out);

#endif
