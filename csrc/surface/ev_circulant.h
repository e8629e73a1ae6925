/* The limit eigenvectors of a rotationally symmetric 1-ring matrix from its discrete Fourier
 * blocks (ev_circulant.c). Internal. */
#ifndef CCN_SURFACE_EV_CIRCULANT_H
#define CCN_SURFACE_EV_CIRCULANT_H

#include <stdint.h>

/* From this valence on, ccn__ev_limit tries the Fourier path before LAPACK's dgeev (below it
 * dgeev costs well under a millisecond and its results stay as they were). */
#define CCN_EV_CIRCULANT_MIN_VALENCE 16

/* M: (2n+1)^2, row-major, ring order F_0..F_{n-1}, E_0..E_{n-1}, V (surface/limit.h). When M
 * is block-circulant (M[X_{j+1}, Y_{k+1}] = M[X_j, Y_k], M[X_j, V] and M[V, Y_k] independent
 * of j, k, within 1e-12: equal spoke intervals) and its subdominant eigenvalue is the Fourier
 * mode 1 / n-1 pair, strictly above every other mode's eigenvalues, writes (2n+1 each):
 *   l0: the left eigenvector of eigenvalue 1, summing to 1;
 *   l1, l2: a real basis of the subdominant left invariant subspace (unit complex norm);
 *   r1, r2: a real basis of the matching right invariant subspace (for the orientation);
 * and returns 0. Returns 1 (nothing written) otherwise, -1 when out of memory. O(n^2). */
int ccn__ev_circulant_eigvecs(const double *M, int32_t n, double *l0, double *l1, double *l2,
                              double *r1, double *r2);

#endif
