/* The guide of the bi-5 construction (internal; bi5/guide.c). */
#ifndef CCN_BI5_GUIDE_H
#define CCN_BI5_GUIDE_H

#include "bi5/bi5_types.h"

/* Index of the triangle coefficient b_{ijk} (i+j+k = 6; i <-> O, j <-> V_s, k <-> V_{s+1}). */
static inline int32_t ccn__bi5_tri(int32_t i, int32_t j, int32_t k) {
    (void)j;
    return (6 - i) * (7 - i) / 2 + k;
}
/* Guide parameters -> BB coefficients, m columns: par (npar x m) -> bb (28n x m), row-major. */
void ccn__bi5_guide_bb(int32_t n, const double *par, int32_t m, double *bb);
/* Sampling matrix S (36 x 28): bi-5 coefficients of the corner jets [g o (mu phi)] for the
 * sector-0 triangle piece g, phi a planar bi-d patch ((d+1)^2 complex, [i*(d+1)+j]); corners:
 * bit 0 = (0,0), 1 = (1,0), 2 = (0,1), 3 = (1,1). Other rows are zero. */
void ccn__bi5_sample(int32_t n, const double complex *phi, int32_t d, double mu,
                     unsigned corners, double S[36 * 28]);
/* Design matrix and its QR factorisation (SPEC §4.4). */
ccn_status ccn__bi5_guide_setup(ccn__bi5 *b, ccn_error *err);
/* The fit's design matrices for per-sector sampling maps (samp0s: n x 36 x 28): a copy of b
 * owning new qr, qtau, s0, qr1, qtau1, s12 (freed by ccn__bi5_guide_nu_free). */
ccn_status ccn__bi5_guide_setup_nu(const ccn__bi5 *b, const double *samp0s, ccn__bi5 *out, ccn_error *err);
void ccn__bi5_guide_nu_free(ccn__bi5 *c);
/* Least-squares guide fit: tcc (n x 36 x m, raised t_CC), b600 (m) -> gbb (n x 28 x m). */
ccn_status ccn__bi5_guide_fit(const ccn__bi5 *b, const double *tcc, const double *b600,
                              int32_t m, double *gbb, ccn_error *err);
/* The same for m = 3 (x, y, z) with the guide's tangent plane at the centre prescribed: the
 * first-order coefficients b_510, b_501 of the plain fit are projected onto the plane through
 * b600 with unit normal `normal`, and the other parameters refitted with them fixed. */
ccn_status ccn__bi5_guide_fit_plane(const ccn__bi5 *b, const double *tcc, const double *b600,
                                    const double *normal, double *gbb, ccn_error *err);
/* The fit with b_510, b_501 given: p12 = 2 x m (p1 columns, then p2 columns). */
ccn_status ccn__bi5_guide_fit_fixed(const ccn__bi5 *b, const double *tcc, const double *b600,
                                    const double *p12, int32_t m, double *gbb, ccn_error *err);
/* p12 = (b_510, b_501) as two 3-vectors, projected onto the plane through b600 with that
 * unit normal. */
void ccn__bi5_project_p12(const double *b600, const double *normal, double p12[6]);

#endif
