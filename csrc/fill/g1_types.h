/* The G1 fill's constants and weight type (types only; fill/g1_fill.h). */
#ifndef CCN_FILL_G1_TYPES_H
#define CCN_FILL_G1_TYPES_H

#include <stdint.h>

#define CCN_FILL_G1_POLES 9
#define CCN_FILL_G1_KNOTS {0, 0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2, 2, 2}
/* Up to this many spokes the solve is dense (its cost grows with the cube of the spokes, 2 s
 * at 32), beyond it banded (linear in them). */
#define CCN_FILL_G1_DENSE_SPOKES 32

/* The weights of spoke k's relation at its ends, wt[k] = {beta(0), gamma(0), beta(2),
 * gamma(2)}, with the relation's pole differences as D and T (D_k: x_k[i][1] - x_k[i][0],
 * D_{k-1}: x_{k-1}[1][i] - x_{k-1}[0][i], T: x_k[1][0] - x_k[0][0] at u = 0 and
 * x_k[8][0] - x_k[7][0] at u = 2). In between quadratic, flat at u = 2 (fill/g1_fill.c). */
typedef double ccn__g1_weights[4];
/* One G1 row over the unknowns: sum_t c[t] delta[v[t]]. */
typedef struct { int32_t n, v[3 * CCN_FILL_G1_POLES]; double c[3 * CCN_FILL_G1_POLES]; } ccn__g1_row;

#endif
