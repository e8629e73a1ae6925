/* Internal helpers of the extraordinary-vertex matrix (rules/eigen.c).
 *
 * Li, Finnigan, Sederberg 2016, "G1 non-uniform Catmull-Clark surfaces", sections 4-6, with
 * the readings of shared/reference/eigen/SPEC.md section 2 (cited below as SPEC 2.x).
 * Not part of the public API; every symbol is ccn__ prefixed.
 */
#ifndef CCN_RULES_EIGEN_H
#define CCN_RULES_EIGEN_H

#include "ccnurbs.h"
#include "rules/eigen_shape.h"

/* Largest valence ccn_ev_matrix accepts. The eigen polyhedron costs O(n^2) and M itself has
 * (2n+1)^2 entries (n = 65536 would already be a 34 GB matrix). */
#define CCN__EV_MAX_VALENCE 65536

/* Up to this valence ccn_ev_matrix uses stack scratch; above it one malloc. */
#define CCN__EV_STACK_VALENCE 64

/* Spoke intervals are divided by their maximum and clamped to at least this (DESIGN 4.5). */
#define CCN__EV_MIN_INTERVAL 1e-6

/* Eigen-rule sanity limits; outside them ccn_ev_matrix falls back to the NURSS rules. */
#define CCN__EV_PARAM_LO (-0.5)
#define CCN__EV_PARAM_HI 1.5
#define CCN__EV_MAX_RESIDUAL 1e-8
/* Bands over which M is blended from the eigen rules to the NURSS rules as the construction
 * nears those limits (parameter slack; discriminant D / Dscale): M stays continuous. */
#define CCN__EV_PARAM_BAND 0.25
#define CCN__EV_D_BAND 0.02

/* cos(2 pi k / n) and sin(2 pi k / n), with exact 0, +-1 at the quarter points (so n = 4
 * reproduces the tensor rules exactly) and symmetric rounding elsewhere. n >= 1. */
void ccn__cos_sin_2pi(int64_t k, int64_t n, double *c, double *s);

/* Catmull-Clark's subdominant eigenvalue, eq (15): lambda = (5 + c + sqrt((c+9)(c+1)))/16,
 * c = cos(2 pi / n); and gamma of eq (14) (F_i = gamma (E_i + E_{i+1}), eq (13)). n >= 3. */
double ccn__ev_lambda(int32_t n);
double ccn__ev_gamma(int32_t n);

/* d / max(d), clamped to >= CCN__EV_MIN_INTERVAL (every rule set is invariant under a common
 * scale of the intervals). Returns max(d). */
double ccn__ev_normalise(int32_t n, const double *d, double *out);

/* The argument checks of ccn_ev_matrix (valence, NULL pointers, scheme, intervals > 0). */
ccn_status ccn__ev_validate(int32_t n, const double *d, ccn_scheme scheme, const double *M,
                            ccn_error *err);

/* ccn_ev_matrix with a given eigen polyhedron poly (1..CCN__POLY_COUNT, rules/eigen_shape.h;
 * ignored by the NURSS and Catmull-Clark schemes), no selection. P (may be NULL): the
 * polyhedron of the normalised intervals, 2 (2n+1) doubles in M's ring order (F_i, E_i, V = 0);
 * written only when M is the eigen M (no fallback). info->polyhedron = poly then, else 0. */
ccn_status ccn__ev_matrix_poly(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                               int32_t poly, double *M, ccn_ev_info *info, double *P,
                               ccn_error *err);
/* The same for a blend of candidates (rules/eigen_shape.h); info->polyhedron = the candidate
 * of the largest weight. margin NULL: the library's M (near the construction's limits blended
 * with the NURSS M, see eigen.c run_scheme). margin given: the pure eigen M (or the NURSS M when
 * the construction fails, margin -1) and the construction's margin (>= 1 clear, <= 0 fails),
 * for the verification (rules/eigen_select.c). */
ccn_status ccn__ev_matrix_blend(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                const ccn__poly_blend *blend, double *M, ccn_ev_info *info,
                                double *P, double *margin, ccn_error *err);

#endif
