/* Bernstein-Bezier helpers of the bi-5 construction (internal; bi5/bernstein.c). */
#ifndef CCN_BI5_BERNSTEIN_H
#define CCN_BI5_BERNSTEIN_H

#include "bi5/bi5_types.h"

/* Binomial coefficient and Bernstein polynomial B^d_k(t). */
double ccn__bi5_binom(int32_t d, int32_t k);
double ccn__bi5_bern(int32_t d, int32_t k, double t);
/* 1-D Bernstein-Bezier helpers (degree 5 unless noted). */
void ccn__bi5_split(double rho, double SR[36], double SL[36]);
void ccn__bi5_prolong(double tau, double PR[9]);
/* Truncated Taylor coefficients T[a*3+b] = d_u^a d_v^b P / (a! b!) (a,b <= 2) at corner
 * (cu,cv) of a complex bi-d patch. */
void ccn__bi5_taylor(const double complex *P, int32_t d, int32_t cu, int32_t cv,
                     double complex T[9]);
/* Corner jet constructor [f] (SPEC §2.3): weights Wj[k*3+a] for layer k from order a. */
void ccn__bi5_jet_weights(int32_t corner1, double Wj[9]);
/* Evaluates a bi-5 patch with m-column coefficients (36 x m) and its first derivatives. */
void ccn__bi5_patch_eval(const double *P, int32_t m, double u, double v, double *pos,
                         double *du, double *dv);
/* The degree-5 Bernstein values B and derivatives D at t (ccn__bi5_patch_eval's), and
 * ccn__bi5_patch_eval from such tables at u (Bu, Du) and v (Bv, Dv): the same numbers. */
void ccn__bi5_bern5_with_deriv(double t, double B[6], double D[6]);
void ccn__bi5_patch_eval_tab(const double *P, int32_t m, const double Bu[6], const double Du[6],
                             const double Bv[6], const double Dv[6], double *pos, double *du,
                             double *dv);

#endif
