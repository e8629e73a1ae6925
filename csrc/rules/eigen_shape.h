/* Candidate eigen polyhedra (internal; rules/eigen_shape.c).
 *
 * Li, Finnigan, Sederberg 2016 section 5 fixes one planar polyhedron per spoke-interval tuple
 * (equal angles 2 pi/n, spoke lengths l_i). The rules (27)-(38) turn any planar polyhedron
 * with V^0 = 0, spokes E_i^0 and face points F_i^0 = gamma (E_i^0 + E_{i+1}^0) into an M with
 * M P^0 = lambda P^0 + 1 T^0. The per-vertex choice tries, for a vertex whose
 * paper polyhedron fails the verification (rules/eigen_select.c), other polyhedra in a fixed
 * order; this file defines them (public numbering: ccnurbs.h CCN_POLY_*):
 *   1        the paper's lengths l_i;
 *   2..11    l_i^(1-e) d_i^e, e = 0.1, 0.2, -0.1, 0.05, -0.05, 0.15, -0.2, 0.3, -0.3, 0.4
 *            (d normalised to max 1; tests/experiments/RESULTS.md finding 3);
 *   12       "Greville": the lengths closest to the paper's (least squares in log l) for which
 *            the two face points beside each spoke s lie at transverse distances in the ratio
 *            of the transverse Greville abscissae, l_{s+1} / l_{s-1} = (2 d_{s+1} + d_{s-1}) /
 *            (2 d_{s-1} + d_{s+1}) (least squares where the n equations have no exact
 *            solution). At n = 4 the paper's lengths solve them, so it is the paper's there;
 *   13..28   interval-dependent sector angles (the idea of the "modified eigen-polyhedron",
 *            Visual Computing for Industry, Biomedicine and Art 5:18, 2022, whose formulas we
 *            could not read): sector s (between spokes s and s+1) gets the angle
 *            2 pi w_s / sum w with w_s = (d_s d_{s+1})^a (or (d_s + d_{s+1})^a, max(d_s,
 *            d_{s+1})^a), on the paper's, Greville or Greville^(1-e) d^e lengths; the 16
 *            (lengths, e, a, w) of DESIGNS in eigen_shape.c were chosen by a greedy set cover
 *            of the cases no earlier candidate passes (log-uniform [1e-3, 1] and [1e-6, 1],
 *            seed 1, cases 0-1499; measured on cases 4000-5999, README "Eigen rules").
 *            Negative a (wider sectors between short spokes) is what helps.
 * Every candidate is equivariant under rotation and reflection of the spoke order and equals
 * the paper's polyhedron for equal intervals (all l_i equal, equal angles). */
#ifndef CCN_RULES_EIGEN_SHAPE_H
#define CCN_RULES_EIGEN_SHAPE_H

#include <stdint.h>

#define CCN__POLY_PAPER 1
#define CCN__POLY_COUNT 28 /* candidates 1..CCN__POLY_COUNT */

typedef enum { CCN__LEN_PAPER = 0, CCN__LEN_EXPONENT, CCN__LEN_GREVILLE } ccn__len_rule;

/* A polyhedron design: the spoke lengths (the paper's, l^(1-e) d^e, or Greville) and the
 * angle exponent a of the sector angles 2 pi w_s / sum w, w_s = (d_s d_{s+1})^a (a = 0: the
 * paper's equal angles). */
typedef struct {
    ccn__len_rule lengths;
    double e, a;
    int angle_fn; /* research: 0 w_s = (d_s d_{s+1})^a, 1 (d_s + d_{s+1})^a, 2 min^a, 3 max^a */
} ccn__poly_design;

/* A weighted blend of candidates (the per-vertex choice, rules/eigen_select.c): the spoke
 * lengths are the weighted geometric mean of the candidates' lengths, the spoke angles the
 * weighted mean of theirs (each candidate's angles increase from 0 at spoke 0). Weights > 0,
 * summing to 1; count 1 is that candidate exactly. */
typedef struct {
    int32_t count;
    int32_t poly[CCN__POLY_COUNT];
    double w[CCN__POLY_COUNT];
} ccn__poly_blend;

/* The design of candidate poly (1..CCN__POLY_COUNT), NULL for any other number. */
const ccn__poly_design *ccn__poly_design_of(int32_t poly);

/* Applies a design to the paper's polyhedron: l[0..n-1] holds the paper's lengths (eigen.c,
 * from the normalised intervals d) and c, s the equal-angle spoke directions; both are
 * replaced by the design's. Returns 0, or -1 when out of memory. */
int ccn__poly_apply(const ccn__poly_design *des, int32_t n, const double *d, double *l,
                    double *c, double *s);

#endif
