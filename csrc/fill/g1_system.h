/* The G1 fill's linear system (internal to fill/: fill/g1_system.c, the dense parts, and
 * fill/g1_band.c, the banded solve for many spokes): the quintic basis, the unknowns, the G1
 * rows, the thin-plate energy and its constrained minimiser. */
#ifndef CCN_FILL_G1_SYSTEM_H
#define CCN_FILL_G1_SYSTEM_H

#include "fill/g1_band.h"
#include "fill/g1_types.h"

#include <stdint.h>

#define NQ CCN_FILL_G1_POLES
#define PQ 5    /* degree */
#define NCOL 8  /* collocation points per span */

/* All n basis functions of degree p over flat knots t at u, their first and (d2N not NULL)
 * second derivatives. */
void ccn__g1_basis(const double *t, int p, int n, double u, double *N, double *dN, double *d2N);
/* A[k] = the Gram matrices of the quintic basis' k-th derivatives over [0, 2]. */
void ccn__g1_gram(double A[3][NQ][NQ]);
/* E (9 x 5): the quintic poles of each cubic B-spline of the 2-span cubic (degree raising). */
int ccn__g1_raise_matrix(double E[NQ][5]);
/* x = E c E^T per filled sector. */
void ccn__g1_raise(double E[NQ][5], const double (*cs)[5][5][3], const uint8_t *filled, int32_t nfan,
                   double (*x)[NQ][NQ][3]);
/* The weights (beta, gamma) with Da + beta Db ~ gamma T in least squares; 0 when the three do
 * not lie in one plane with Da and Db on opposite sides of T. */
int ccn__g1_weights_of(const double *Da, const double *Db, const double *T, double *beta, double *gamma);
/* The unknowns and their numbers idx[k][i][j] (-1 fixed); returns their count, -1 out of
 * memory. */
int32_t ccn__g1_unknowns(int32_t nfan, int32_t nsp, const uint8_t *sharp, const uint8_t *filled, uint8_t *smooth,
                         int32_t (*idx)[NQ][NQ], int32_t *nsm);
/* The data's weights per smooth spoke (wt[k]); 0 when a spoke's end data admits none. */
int ccn__g1_data_weights(double (*x)[NQ][NQ][3], int32_t nfan, int32_t nsp, const uint8_t *smooth,
                         ccn__g1_weights *wt);
/* The G1 rows C delta = R at x with weights wt (2 NCOL per smooth spoke). x NULL: R is m x
 * (81 nfan), the rows' coefficients on every pole of x (flat index (k NQ + i) NQ + j) -- the
 * operator's right-hand sides; else m x 3. */
void ccn__g1_rows(double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], int32_t nfan, int32_t nsp, const uint8_t *smooth,
                  const ccn__g1_weights *wt, ccn__g1_row *C, double *R);
/* The thin-plate functional's entry for poles (i, j) and (i2, j2) of one sector. */
double ccn__g1_plate(double A[3][NQ][NQ], int i, int j, int i2, int j2);
/* The energy of x + delta: delta^T W delta + 2 H^T delta + const (W dense n x n, or into the
 * band b when NULL). x NULL: H is n x (81 nfan), H's coefficients on every pole of x. */
void ccn__g1_thin_plate(double A[3][NQ][NQ], double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], const uint8_t *filled,
                        int32_t nfan, int32_t n, double *W, ccn__g1_band *b, double *H);
/* The least-energy delta (n x nr) with C delta = R (m x nr, C dense m x n). 1, 0, -1 oom. */
int ccn__g1_least_energy(int32_t m, int32_t n, const double *C, const double *R, const double *W, const double *H,
                         double *del, int32_t nr);

#endif
