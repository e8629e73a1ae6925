/* The planar reparameterisation tau of the bi-5 cap (internal; bi5/tau.c). */
#ifndef CCN_BI5_TAU_H
#define CCN_BI5_TAU_H

#include "bi5/bi5_types.h"

/* raise(chi~) (bi-3 -> bi-5) as a complex 6x6 patch. */
void ccn__bi5_raise_chi(const double complex chi[16], double complex G[36]);
/* Symmetric tau (SPEC §6.2, [R4]) for valence n from chi~_{sigma_l}. */
ccn_status ccn__bi5_tau(int32_t n, const double complex chi[16], double complex tau[36],
                        ccn_error *err);
/* [R15] Each sector s of the planar border G (n x 36) mapped so that spoke s has length
 * d_s^e (d over its geometric mean). */
void ccn__bi5_spoke_scale(int32_t n, const double *d, double e, double complex *G);
/* Non-uniform taus (one per sector, [R9]); kap[s] = kappa of spoke e_s; e > 0 with the spoke
 * intervals d: their green layers from the spoke-scaled border ([R15]; e = 0, d may be NULL). */
ccn_status ccn__bi5_tau_nu(int32_t n, const double complex chi[16], const double *kap, const double *d,
                           double e, double complex *tau /* n x 36 */, ccn_error *err);
/* BB coefficients (degree 7, complex) of the G1 residual across the separator between the
 * bi-5 patches fs and fs1 ([R10]; c = cos(2 pi / n), k = kappa of the separator). */
void ccn__bi5_g1_res(const double complex *fs, const double complex *fs1, double c, double k,
                     double complex R[8]);

#endif
