/* The G1 fill cap of a plan (internal; surface/fill_cap.c): the finite, exactly G1 closure of
 * a smooth interior EV's hole where the guided bi-5 cap is not whole (spoke ratios beyond its
 * range), as a linear map of the level-(K+1) points. */
#ifndef CCN_SURFACE_FILL_CAP_H
#define CCN_SURFACE_FILL_CAP_H

#include "surface/plan_types.h"

/* The fill cap is built at every cap EV of valence >= this whose bi-5 cap is not whole
 * (measured on random stars: valence 3 has no fair G1 fill of this form, tests/experiments/
 * RESULTS.md; its hole keeps the refined limit). */
#define CCN_FILL_CAP_MIN_VALENCE 5

typedef struct ccn__fill_cap ccn__fill_cap;

/* The fill cap of level-K EV ev (valence n, spoke intervals knots) on the plan's level-(K+1)
 * mesh (built): its border cells, the limit and spoke-tangent weights over the EV's level-(K+1)
 * ring and the G1 operator of its weights. 1 with *out, 0 when the EV does not qualify or the
 * relations have no solution (a folded characteristic map), -1 out of memory. Reads the plan's
 * meshes and the EV cache only, so caps may be made in parallel. */
int ccn__fill_cap_create(const ccn_plan *p, int32_t ev, int32_t n, const double *knots, ccn__fill_cap **out);
void ccn__fill_cap_destroy(ccn__fill_cap *f);
/* Its G1 operator (the costly part, ~10 ms at valence 8; safe in parallel): 1, 0 no solution,
 * -1 out of memory. */
int ccn__fill_cap_solve(ccn__fill_cap *f);

/* The fill's poles from the plan's current level-(K+1) points. 0 when a border cell has no
 * bicubic patch (cannot happen on an isolated cap EV; the caller reports it). */
int ccn__fill_cap_update(const ccn_plan *p, ccn__fill_cap *f);

/* The fill at (u, v) in [0,1]^2 of sector k's level-K face (u along spoke k, v along spoke
 * k + 1, as the bi-5 cap's hole coordinates): point, first derivatives and (d2 not NULL) the
 * second ones uu, uv, vv, all in the face's coordinates. */
void ccn__fill_cap_eval(const ccn__fill_cap *f, int32_t k, double u, double v, double x[3], double du[3],
                        double dv[3], double (*d2)[3]);

/* The four quintic Bezier patches of sector k (b[2a + c] over the face's [a/2, (a+1)/2] x
 * [c/2, (c+1)/2]), in the plan's coordinates. */
void ccn__fill_cap_bezier(const ccn__fill_cap *f, int32_t k, double b[4][6][6][3]);

#endif
