/* Principal curvatures of the limit surface at the output vertices (internal;
 * surface/curvature.c). */
#ifndef CCN_SURFACE_CURVATURE_H
#define CCN_SURFACE_CURVATURE_H

#include "surface/plan_types.h"

#include <math.h>

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
/* k1 >= k2, times s (the unit box's 1/scale), from the first fundamental form (E, F, G,
 * det = EG - F^2 > 0) and the second (L, M, N, against the unit normal). With the shape operator
 * W = I^-1 II, H = tr W / 2 = (EN - 2FM + GL) / (2 det) and
 *   H^2 - K = ((W11 - W22) / 2)^2 + W12 W21 = ((GL - EN)^2 / 4 + (GM - FN)(EM - FL)) / det^2,
 * which has no cancellation of H^2 against K: at an umbilic (a sphere) both terms vanish with
 * the differences of the forms, so k1 - k2 is the rounding of those differences (~1e-16
 * relative), not the square root of H^2 - K's rounding (~1e-8). One division, no branch: the
 * stencil pass runs this at every output vertex. */
static inline void ccn__forms_to_k(double E, double F, double G, double det, double L, double M,
                                   double N, double s, double *k1, double *k2) {
    double r = s / det;
    double a = G * L - E * N, b = G * M - F * N, c = E * M - F * L;
    double H = (E * N - 2 * F * M + G * L) * (0.5 * r);
    double disc = sqrt(fmax(0.25 * a * a + b * c, 0.0)) * r;
    *k1 = H + disc;
    *k2 = H - disc;
}

/* Output o's curvatures from its derivatives d (S_u, S_v, S_uu, S_uv, S_vv in the unit box of
 * evaluate) and the unit normal nh of S_u x S_v (ccn__unit_normal of d[0], d[1]), inv_scale =
 * 1 / the box's scale: the stencil pass's path (no direction). NaN for degenerate tangents. */
static inline void ccn__curvature_at_unit(const double d[5][3], const double nh[3],
                                          double inv_scale, double k[2]) {
    const double *su = d[0], *sv = d[1];
    double E = su[0] * su[0] + su[1] * su[1] + su[2] * su[2];
    double F = su[0] * sv[0] + su[1] * sv[1] + su[2] * sv[2];
    double G = sv[0] * sv[0] + sv[1] * sv[1] + sv[2] * sv[2], det = E * G - F * F;
    if (!(det > 1e-300 * (E * G + 1e-300))) { /* (and the fallback normal of degenerate tangents) */
        k[0] = k[1] = NAN;
        return;
    }
    double L = -(d[2][0] * nh[0] + d[2][1] * nh[1] + d[2][2] * nh[2]);
    double M = -(d[3][0] * nh[0] + d[3][1] * nh[1] + d[3][2] * nh[2]);
    double N = -(d[4][0] * nh[0] + d[4][1] * nh[1] + d[4][2] * nh[2]);
    ccn__forms_to_k(E, F, G, det, L, M, N, inv_scale, &k[0], &k[1]);
}
/* Output o: NaN, the flag (no bounded single value, or its cap's patch gives it later). */
void ccn__curvature_flag(ccn_limit_mesh *out, int32_t o);
/* After the stencil pass (which computed the CCN__CURV_ROW outputs and flagged the others) and
 * the caps: the outputs with stencils of their own, and the caps' and their rings' patches. */
void ccn__curvature_evaluate(ccn_plan *p, ccn_limit_mesh *out);

#endif
