/* Guided rapidly-contracting bi-5 rings and G1 cap for one extraordinary vertex (EV)
 * (Karciauskas & Peters 2018, "Rapidly contracting subdivision yields finite, effectively C2
 * surfaces"; called "the paper" below). Specification: reference/bi5/SPEC.md (section numbers
 * "SPEC §x" below). Internal header, not installed.
 *
 * Files (csrc/bi5/; each uses only the ones above it in this list):
 *        bi5_types.h  the operator struct, constants, inline helpers (no code of its own);
 *        bernstein.c  1-D/2-D Bernstein-Bezier helpers: split, prolongation, Taylor jets,
 *                     patch evaluation (SPEC §2.2, §2.3, §2.5);
 *        charmap.c    chi~_sigma, the characteristic tensor-border of adjustable-speed
 *                     subdivision (SPEC §3), blossoms, c-net neighbour rules (SPEC §1);
 *        guide.c      the guide g: explicit BB parametrisation (SPEC §4.2), composite jets /
 *                     sampling matrices (SPEC §2.3), least-squares fit (SPEC §4.4);
 *        rings.c      t_CC, C2-rule, the ring patches of one sector (SPEC §2, §5), ring-0
 *                     borders from an exact surround ([R13]);
 *        tau.c        the planar cap reparameterisation tau (SPEC §6.2, [R4], [R11]);
 *        cap.c        the G1 cap assembly (SPEC §6.3, [R10]-[R12]);
 *        bi5.c        the operator, the entry point (this header): create / apply / eval, the
 *                     whole construction and its global stencil (SPEC §5-§7).
 *
 * Reconstruction choices ([R] = not determined by the paper; SPEC tags in brackets):
 *  [R1] c-net labels c_1..c_4 = grid nodes (2,0),(2,1),(2,2),(1,2) (SPEC §1.2 [R]); c_5 = (1,1),
 *       c_6 = (1,0), c_7 = EV are forced by eq. (7) [I].
 *  [R2] chi~_sigma is the frequency-1 eigenvector of the reconstructed adjustable-speed scheme
 *       (exact cubic knot insertion on knots (-1/s~,-1,0,1,1/s~,(1+s)/s~), SPEC §3.1), its
 *       bicubic tensor-border normalised so that chi~[3][0] = 1 (corner on spoke e_0).
 *  [R3] Guide fit: unweighted least squares over all 27 tensor-border coefficients of every
 *       sector (spoke coefficients counted twice), target = raise(t_CC) without C2-rule,
 *       sampling map chi~_{1/2}; b_600 fixed to eq. (7)/(8) or to the caller's centre
 *       (SPEC §4.4). Solved by Householder QR (LAPACK dgeqrf/dormqr/dtrtrs).
 *  [R4] tau: the green coefficients max(i,j) >= 4 and tau_33 come from raise(chi~_{sigma_l})
 *       (7 free parameters, the paper's count); F_5 energy by 6x6 Gauss-Legendre (SPEC §6.2).
 *  [R5] Cap: the two free coefficients per separator (the differences a_k - b_k, k = 2,3) are
 *       taken from the jet map a (least squares, SPEC §6.3 step 4).
 *  [R6] The contraction of the guide g^r(x) = g(Lambda_r x), Lambda_r = lambda_1 ... lambda_r,
 *       is folded into the sampling map (sampling g with Lambda_r chi~): identical to the
 *       Appendix's de Casteljau restriction, with one sampling matrix per ring.
 *  [R7] The guide is stored in BB form per sector (28 coefficients on the triangle
 *       O, V_s, V_{s+1}); then the sampling matrix [g^s o omega^s phi] is the same for all s.
 *  [R8] Non-uniform spoke intervals d_0..d_{n-1} (SPEC §9, DESIGN §4.4), t_CC: every interval
 *       along the line of spoke e_k near the EV is taken equal to d_k (true once the EV is two
 *       NU refinement levels deep, intervals halving); sector s uses the knots of its own
 *       virtual regular grid: u-intervals (d_{s+2}, d_{s+2} | d_s, d_s, d_s), v-intervals
 *       (d_{s-1}, d_{s-1} | d_{s+1}, d_{s+1}, d_{s+1}) ("|" = the EV; these are the real ring
 *       intervals of the nodes the stencils use), normalised to the hole [0,1]^2; BB weights by
 *       blossoming (SPEC §9.1, ccn__bi5_bb_weights).
 *       * kappa_s = d_{s+1}/d_{s-1} = 1 for all s (all equal; alternating for even n): the knots
 *         are uniform in each sector's own scale, so the operator IS the uniform one (BB form is
 *         invariant under per-patch affine reparameterisation): stencil path.
 *       * d_{s+2} = d_{s-2} for all s (kappa may be != 1 only for n = 0 mod 4, period-4
 *         intervals): the sectors' grids agree, t_CC is C0 and C2 with ratio kappa_s across
 *         spoke e_s, and it is the prolongation of the exact NU bi-3 ring (patches.c's
 *         "beyond V" interval (d_{s-2}+d_{s+2})/2 equals d_{s+2} here): NU construction.
 *       * otherwise sector s continues spoke e_s through the EV along e_{s+2}, sector s-1 along
 *         e_{s-2}: the two bicubic hole patches (and the bi-3 patches on either side of the
 *         spoke line) disagree along the spoke; no tensor-border joins such a ring C2:
 *         ccn__bi5_apply returns CCN_ERR_KNOTS. ccn__bi5_apply_border accepts any intervals
 *         when the caller supplies a consistent tensor-border of its own surrounding ring, and
 *         ccn__bi5_apply_pieces takes the exact surround one level finer ([R13]; the plan's
 *         path).
 *  [R9] NU rings: the NU C2-rule with r = kappa_s at every level >= 1 (SPEC §9.3); the level-0
 *       border must already satisfy it (checked in apply_border; exact for the cases above).
 *  [R10] NU cap G1 form, per separator (spoke e_{s+1} between sectors s and s+1, k = kappa_{s+1}):
 *       alpha(t) d_u f^s(0,t) + d_v f^{s+1}(t,0) = gamma(t) d_t f^{s+1}(t,0),
 *       alpha = 1 + (k-1)(2t - t^2) (BB (1,k,k)), gamma = 2c (1-t)^2: symmetric at the centre
 *       (alpha(0) = 1: the centre relation E_s + E_{s+2} = 2c E_{s+1} of SPEC §6.1), NU-C1 with
 *       ratio k at t = 1 (alpha(1) = k, alpha'(1) = 0, gamma(1) = gamma'(1) = 0), so the
 *       degree-7 BB equations 0,1 hold by the red (centre) data and 6,7 by the green (ring)
 *       data; k = 1 is SPEC §6.1 (degree-raised). Chosen a priori, and tau is built to satisfy
 *       it, rather than reading alpha, beta, gamma off an unconstrained tau: those are 2x2
 *       determinants of tau's derivatives of degree 9, giving 15 equations per separator for
 *       the cap's 5 free coefficients.
 *  [R11] NU tau: one planar tau^s per sector, green layers (max(i,j) >= 4) = the NU C2-rule
 *       applied to raise(omega^s chi~_{sigma_l}), tau^s_33 = raise(...)_33; constraints
 *       tau^s_00 = 0, C0 and [R10] (as a polynomial identity) with tau^{s+1}; minimum of
 *       sum_s F_5(tau^s). kappa = 1 reproduces the symmetric tau (test: 3e-14).
 *  [R12] NU cap black squares e_3, a_2, a_3, b_2, b_3 of each separator: the solution of the 4
 *       middle equations (2..5) of [R10] closest (Euclidean) to the jet map a (e_3's reference
 *       = mean of the two sectors' jet values); kappa = 1 gives SPEC §6.3's closed form.
 *  [R13] Arbitrary NU spoke intervals (the third case of [R8]): the level-K faces next to the
 *       hole are not tensor patches (their 4x4 nets contain V and the interval "beyond V" differs
 *       row by row: d_{s-2} on one side, d_{s+2} on the other), but the level-(K+1) faces next
 *       to the level-K hole are: their nets stop one level-(K+1) ring short of V, every interval
 *       they need is a mesh edge, and the scheme refines them by knot insertion forever, so
 *       their bicubic patches ARE the limit surface. Each leg of the hole meets two of them
 *       (knot at 1/2). The cap takes those pieces as its border with a first ring of speed
 *       sigma = 1/2 so that each ring-0 patch meets exactly one piece (the corner patch two,
 *       which agree on its corner block because the surround is C2 there), followed by the
 *       usual rings (3/4, 7/8, 7/8; n = 3: 15/16). Ring 0 joins the surround C2 by
 *       construction; the pieces are C2 with ratio kappa_s across each spoke (one tensor
 *       spline), as the NU C2-rule [R9] needs. The guide's least-squares target is t_CC with
 *       the [R8] knots, which is only an approximation of the border here (it shapes the
 *       guide, not the joins).
 *  [R14] With a prescribed centre normal (ccn__bi5_apply_pieces), the guide's first-order
 *       coefficients b_510, b_501 at the centre are projected onto the plane through the centre
 *       point with that normal and the remaining parameters refitted with them fixed. The cap's
 *       centre jet is the guide's, so the cap's tangent plane at the EV is the exact limit's
 *       (the plain fit left it 0.002-0.04 rad off for non-uniform intervals).
 *  [R15] Spoke-scaled guide domain (border_exp e > 0, ccn__bi5_apply_pieces and
 *       ccn__bi5_nu_taus): the planar border omega^s raise(chi~) of each sector is first mapped
 *       linearly so that spoke s has length d_s^e (over the intervals' geometric mean), then
 *       C2-ruled; the guide is fitted through it (per-sector sampling, its own design matrix),
 *       the rings sample the guide through it and tau's green layers come from it. With e = 1/2
 *       the caps of holes several levels below an EV whose spoke ratios leave the plan's kappa
 *       range fold less and bend less than with e = 0 (tests/experiments/RESULTS.md); the
 *       plan's own caps use e = 0.
 *  Numerics: tau's equality-constrained minimum by the SVD null space of the constraints
 *  (they are redundant) and Cholesky on the reduced normal equations of F_5.
 */
#ifndef CCN_BI5_H
#define CCN_BI5_H

#include "bi5/bi5_types.h"

/* n >= 3, n != 4; sigmas: the ring speeds in (0,1) (paper's default (3/4,7/8,7/8); n = 3:
 * (15/16)); 1 <= nsig <= 16. */
ccn_status ccn__bi5_create(int32_t n, const double *sigmas, int32_t nsig, ccn__bi5 **out,
                           ccn_error *err);
void ccn__bi5_destroy(ccn__bi5 *b);
int32_t ccn__bi5_num_rings(const ccn__bi5 *b);
int32_t ccn__bi5_num_patches(const ccn__bi5 *b); /* (3*nsig+1)*n */
/* cnet: (6n+1) x 3 points in SPEC §1.2 order (X[0] = EV, X[1+6k+m-1] = c_m^k: grid nodes
 * (2,0),(2,1),(2,2),(1,2),(1,1),(1,0) of sector k, u along spoke k, v along spoke k+1).
 * spoke_knots: the n spoke intervals d_k (NULL = uniform). center: the surface point for the EV
 * (NULL = eq (7)/(8)). Output: patches[(r*3 + {A,B,C}) * n + s][6][6][3] for rings r < nsig,
 * then the cap patches[(3*nsig)*n + s][6][6][3]; (3*nsig+1)*n bi-5 patches in all.
 * Knots [R8]: kappa_s = 1 for all s -> the uniform operator (one stencil product per
 * coordinate). kappa != 1 and d_{s+2} = d_{s-2} for all s (n = 0 mod 4) -> the non-uniform
 * construction [R8]-[R12], recomputed per call (tau^s, guide fit; ~1-30 ms). Any other
 * intervals: CCN_ERR_KNOTS (caller uses ccn__bi5_apply_pieces or ccn__bi5_apply_border).
 * Non-uniform tau that folds (Jacobian <= 0 somewhere, extreme kappa): CCN_ERR_KNOTS. */
ccn_status ccn__bi5_apply(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                          const double *center, double *patches, ccn_error *err);
/* Any intervals, given the caller's own surrounding ring: border[s][6][6][3] is the bi-5
 * tensor-border t~^0 of sector s (SPEC §1.3; only the 27 entries with i >= 3 or j >= 3 are
 * read): rows i = 3..5 = the C2 prolongation into the hole of the bi-3 patch across u = 1
 * (raised to degree 5), columns j = 3..5 = that of the patch across v = 1, in the hole's
 * [0,1]^2 parameters. For uniform knots this is raise(t_CC), SPEC §2.1. It must be C0 and C2
 * with ratio kappa_s = d_{s+1}/d_{s-1} across every spoke e_s (checked, relative tolerance 1e-9,
 * else CCN_ERR_KNOTS naming the spoke). center (required): the EV's surface point. The guide
 * is fitted to this border; the rings use the NU C2-rule [R9], the cap [R10]-[R12]. */
ccn_status ccn__bi5_apply_border(const ccn__bi5 *b, const double *border, const double *spoke_knots,
                                 const double *center, double *patches, ccn_error *err);
/* Any intervals, given the exact bicubic surround one level finer (bi5.h [R13]): b's first
 * ring must have sigma = 1/2. pieces[(s*4 + k)*36*3]: sector s's four surround pieces as full
 * bi-5 polynomials over the hole [0,1]^2 (k = 0: across u = 1, v in [0,1/2]; 1: across u = 1,
 * v in [1/2,1]; 2: across v = 1, u in [0,1/2]; 3: across v = 1, u in [1/2,1]). The guide is
 * fitted to the pieces (their least-squares tensor-border); ring 0 takes its outer layers from
 * the pieces, the other rings and the cap are [R9]-[R12]. normal (may be NULL): the unit
 * normal of the surface at the centre; the guide's tangent plane there is set to it ([R14]).
 * border_exp: the guide's domain ([R15]; 0 = the symmetric characteristic border); taus, when
 * given, must come from ccn__bi5_nu_taus with the same border_exp. */
ccn_status ccn__bi5_apply_pieces(const ccn__bi5 *b, const double *cnet, const double *pieces,
                                 const double *spoke_knots, double border_exp, const double complex *taus,
                                 const double *center, const double *normal, double *patches,
                                 ccn_error *err);
/* The per-sector taus of non-uniform spoke intervals ([R11]; n x 36, CCN_ERR_KNOTS if tau folds):
 * they depend on the intervals only, so a caller that evaluates repeatedly computes them once
 * and passes them to ccn__bi5_apply_cached / ccn__bi5_apply_pieces (NULL there: computed per
 * call, the ~35 ms that dominate a non-uniform cap's construction); border_exp as in
 * ccn__bi5_apply_pieces. */
ccn_status ccn__bi5_nu_taus(const ccn__bi5 *b, const double *spoke_knots, double border_exp, double complex *taus,
                            ccn_error *err);
/* ccn__bi5_apply with precomputed taus (NULL: as ccn__bi5_apply). */
ccn_status ccn__bi5_apply_cached(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                                 const double complex *taus, const double *center, double *patches,
                                 ccn_error *err);
/* ccn__bi5_apply_cached with the surface's centre point and unit normal at the EV: the cap's
 * tangent plane there is set to that normal's ([R14]; the uniform operator: precomputed
 * stencils, no allocation). */
ccn_status ccn__bi5_apply_normal(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                                 const double complex *taus, const double *center, const double *normal,
                                 double *patches, ccn_error *err);
/* Surface at sector s, hole coordinates (u,v) in [0,1]^2 ((0,0) = EV, u along spoke s, v along
 * spoke s+1): finds the ring / patch (SPEC §1.4, rho_r = 1 - sigma_r) and returns the position
 * and the derivatives with respect to u and v. */
void ccn__bi5_eval(const ccn__bi5 *b, const double *patches, int32_t s, double u, double v,
                   double pos[3], double du[3], double dv[3]);
/* The bi-5 patch (36 points, 3 doubles each) holding hole point (u, v) of sector s, the point's
 * coordinates (pu, pv) in it and the hole's units per patch unit along each (su, sv). */
const double *ccn__bi5_locate(const ccn__bi5 *b, const double *patches, int32_t s, double u,
                              double v, double *pu, double *pv, double *su, double *sv);

#endif
