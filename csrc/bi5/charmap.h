/* Characteristic maps of adjustable-speed subdivision, blossoms, c-net nodes (internal;
 * bi5/charmap.c). */
#ifndef CCN_BI5_CHARMAP_H
#define CCN_BI5_CHARMAP_H

#include "bi5/bi5_types.h"

/* lambda_sigma (paper Sec. 4.1). */
double ccn__bi5_lambda(int32_t n, double sigma);
/* Neighbour rules (SPEC §1.1): c-net index (0 = EV) of node (i,j) of sector s, -1 <= i,j <= 2,
 * and the sector offset *ds (node lies in sector s + *ds, for Fourier phases); -1 if the node
 * is not in the 6n+1 net. */
int32_t ccn__bi5_node(int32_t n, int32_t s, int32_t i, int32_t j, int32_t *ds);
/* Cubic B-spline with control point c_m at knot t_m and blossom label (t_{m-1},t_m,t_{m+1});
 * t[0..5] = t_{-2..3}. Weights w[0..2] on c_{k-1}, c_k, c_{k+1} (k = 0 or 1) of the blossom
 * b(t_k, x, y). Returns 0, or -1 if the knots are degenerate. */
int ccn__bi5_blossom(const double t[6], int32_t k, double x, double y, double w[3]);
/* BB coefficients of the cubic piece on [t_0,t_1] = [0,1]: W[a][q] = weight of node
 * first[a] + q (first = -1,-1,-1,0). */
int ccn__bi5_bb_weights(const double t[6], double W[4][3]);
/* chi~_sigma (SPEC §3.1, [R2]) and the dominant frequency-1 eigenvalue of the scheme. */
ccn_status ccn__bi5_charmap(int32_t n, double sigma, double complex chi[16], double *lambda,
                            ccn_error *err);

#endif
