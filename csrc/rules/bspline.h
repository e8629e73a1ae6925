/* Non-uniform cubic B-spline knot insertion in knot-interval form (DESIGN §4.2) and its
 * tensor-product use on a quad mesh with ring intervals. Internal. */
#ifndef CCN_RULES_BSPLINE_H
#define CCN_RULES_BSPLINE_H

#include "topology/halfedge.h"

/* Curve edge point E_j = (1-w) P_j + w P_{j+1} for the midpoint of the span with interval d,
 * dp the interval before P_j and dn the one after P_{j+1} (DESIGN §4.2, Li 2016 eq (5)). */
static inline double ccn__edge_weight(double dp, double d, double dn) {
    return (2.0 * dp + d) / (2.0 * (dp + d + dn));
}

/* Interval beyond vertex v along the k-th edge of its fan (straight through v). */
double ccn__beyond(const ccn_mesh *m, int32_t v, int32_t k, int pinned);
/* Interval of the quad f on the far side of edge(h) (h in f), measured transversally. */
double ccn__side(const ccn_mesh *m, int32_t h, int pinned);
/* Interval of face(h) transverse to edge(h). */
double ccn__transverse(const ccn_mesh *m, int32_t h);
/* Position of edge(h) in the fan of h's end vertex. */
int32_t ccn__pos_at_end(const ccn_mesh *m, int32_t h);
/* Is v an interior vertex of valence != 4? */
static inline int ccn__is_ev(const ccn_mesh *m, int32_t v) {
    return !m->vboundary[v] && m->vfan_start[v + 1] > m->vfan_start[v] && ccn__valence(m, v) != 4;
}

/* The p + 1 nonzero B-spline basis functions of degree p at x in a span [U[p-1], U[p]] of the
 * 2p knots U around it (Piegl & Tiller A2.2): N[i] for the control point of knots U[i] .. */
void ccn__bspline_basis(int p, const double *U, double x, double *N);

/* 1-D limit value (w) and derivative (dw) weights on (P_-1, P_0, P_1) at knot t_0 of a cubic
 * B-spline with intervals D_-2, D_-1, D_0, D_1 around it. */
void ccn__curve_limit_weights(double dm2, double dm1, double d0, double d1, double w[3],
                              double dw[3]);
/* The same and the second derivative weights ddw. */
void ccn__curve_limit_weights2(double dm2, double dm1, double d0, double d1, double w[3],
                               double dw[3], double ddw[3]);
/* Curve edge point of edge(h) (knot insertion along the edge): its weight w (topology and
 * intervals only) and the blend (1-w) P_a + w P_b of the current positions. */
void ccn__curve_edge_point(const ccn_mesh *m, int32_t h, int pinned, double out[3]);
double ccn__curve_edge_weight(const ccn_mesh *m, int32_t h, int pinned);
void ccn__curve_edge_blend(const ccn_mesh *m, int32_t h, double w, double out[3]);
/* Tensor-product face point of quad face f (knot insertion in both directions): its weights
 * (s, t) along f's first and second edge, and their bilinear blend of f's corners. */
void ccn__quad_face_point(const ccn_mesh *m, int32_t f, int pinned, double out[3]);
void ccn__quad_face_weights(const ccn_mesh *m, int32_t f, int pinned, double st[2]);
void ccn__quad_face_blend(const ccn_mesh *m, int32_t f, const double st[2], double out[3]);
/* Edge point of an interior edge: H/2 + transverse blend of the two new face points (bl, br:
 * the transverse intervals of the faces of h and of its twin; H itself on the boundary). */
void ccn__edge_point(const ccn_mesh *m, int32_t h, const double *H, const double *fp,
                     double out[3]);
void ccn__edge_blend(const ccn_mesh *m, int32_t h, double bl, double br, const double *H,
                     const double *fp, double out[3]);
/* Boundary vertex: the curve vertex rule along the boundary (or pinned corner). */
void ccn__boundary_vertex_point(const ccn_mesh *m, int32_t v, const double *H, int pinned,
                                double out[3]);

#endif
