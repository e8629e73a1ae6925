/* The least-energy G1 quintic fill of a vertex's sectors from their border data (internal;
 * fill/g1_fill.c): as one solve for given data (the CAD export's fills, io/fill_faces.c) and as
 * a linear operator for given weights (the plan's caps beyond the bi-5 range,
 * surface/fill_cap.c). Knows no mesh.
 *
 * A fill sector is a degree-5 B-spline with 2 x 2 spans, knots CCN_FILL_G1_KNOTS in units of
 * the fill level's faces, 9 x 9 poles, pole (i, j) i along the sector's spoke k (its u-axis), j
 * along spoke k + 1. Its data is the bicubic fill cs (per fan face k: 5 x 5 poles of the
 * clamped 2-span cubic, knots 0000 1 2222; spoke k = sector k's u-axis and sector k-1's v-axis,
 * shared bit for bit; the spoke's inner pole in the limit tangent plane; the outer two layers
 * the exact C1 data), raised to degree 5. Kept: the limit point, the spokes' first poles (the
 * tangent plane), the sharp spokes and the cross-derivative row along them, the outer two
 * layers (the C1 join). Free: the rest, chosen so that along every smooth spoke
 *     D_k(u) + beta(u) D_{k-1}(u) = gamma(u) T(u),  u in [0, 2]
 * (D the two sectors' cross-boundary derivatives, T the spoke's tangent) with the least
 * thin-plate energy. */
#ifndef CCN_FILL_G1_FILL_H
#define CCN_FILL_G1_FILL_H

#include "fill/g1_types.h"

#include <stdint.h>

/* The fill q of data cs (bnd: w on the boundary, nsp = nfan + 1 spokes, else nsp = nfan; sharp
 * spokes C0; unfilled sectors absent). wt: the weights, or NULL for the ones the data implies
 * (solved at both ends in least squares and checked: no common tangent plane or a folded
 * corner gives 0). smooth[k] (nsp + 1 bytes) is set to 1 for the spokes made G1. Returns 1
 * with q and *energy (q's thin-plate energy, to compare fills of different spoke data), 0 when
 * the relations have no solution (q untouched), -1 out of memory. */
int ccn__fill_g1_solve(const double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                       const uint8_t *filled, const ccn__g1_weights *wt, double (*q)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3],
                       uint8_t *smooth, double *energy);

/* The weights at the vertex where the spoke vectors are known in a plane (a characteristic
 * map's): a + beta b = gamma t with a, b the neighbouring spokes' vectors, t spoke k's; 0 when
 * b and t are parallel or a and b lie on one side of t (a folded map). */
int ccn__fill_g1_vertex_weights(const double a[3], const double b[3], const double t[3], double *beta,
                                double *gamma);

/* The same fill as a linear map, for an interior vertex of n smooth spokes with every sector
 * filled and fixed weights wt (n entries): q = raise(cs) + L cs on the free poles, the same
 * result as ccn__fill_g1_solve(cs, n, n, no sharp spoke, all filled, wt) to rounding. Made
 * once per weight set (a dense solve with the data's 25 n coordinates as right-hand sides);
 * applying it costs 41 n x 25 n multiply-adds per coordinate. 1 with *out, 0 no solution, -1
 * out of memory. */
typedef struct ccn__g1_operator ccn__g1_operator;
int ccn__g1_operator_create(int32_t n, const ccn__g1_weights *wt, ccn__g1_operator **out);
void ccn__g1_operator_apply(const ccn__g1_operator *op, const double (*cs)[5][5][3],
                            double (*q)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3]);
void ccn__g1_operator_destroy(ccn__g1_operator *op);

/* A fill sector q at (u, v) in [0, 2]^2: the point x, its first derivatives du, dv and (d2 not
 * NULL) its second ones d2[0] = uu, d2[1] = uv, d2[2] = vv. */
void ccn__fill_g1_eval(const double q[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3], double u, double v, double x[3],
                       double du[3], double dv[3], double (*d2)[3]);
/* The four quintic Bezier patches of sector q (6 x 6 x 3 each, first index along u), b[2a + c]
 * over [a, a + 1] x [c, c + 1]. */
void ccn__fill_g1_bezier(const double q[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3], double b[4][6][6][3]);

#endif
