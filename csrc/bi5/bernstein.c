/* Bernstein-Bezier helpers of the bi-5 construction (SPEC §2.2, §2.3, §2.5): binomials,
 * Bernstein polynomials, splitting and prolongation of degree-5 pieces, truncated Taylor
 * coefficients, corner-jet weights and bi-5 patch evaluation. */
#include "bi5/bernstein.h"

#include <string.h>

/* ---- Bernstein-Bezier helpers (SPEC §2.2, §2.5) --------------------------------------- */

double ccn__bi5_binom(int32_t d, int32_t k) {
    if (k < 0 || k > d) return 0.0;
    double r = 1.0;
    for (int32_t q = 1; q <= k; q++) r = r * (double)(d - k + q) / (double)q;
    return r;
}

double ccn__bi5_bern(int32_t d, int32_t k, double t) {
    if (k < 0 || k > d) return 0.0;
    return ccn__bi5_binom(d, k) * pow(1.0 - t, d - k) * pow(t, k);
}

void ccn__bi5_split(double rho, double SR[36], double SL[36]) {
    /* Right piece [rho,1]: SR_kl = B^{5-k}_{l-k}(rho); left piece [0,rho]: SL_kl = B^k_l(rho). */
    for (int32_t k = 0; k < 6; k++)
        for (int32_t l = 0; l < 6; l++) {
            SR[k * 6 + l] = l >= k ? ccn__bi5_bern(5 - k, l - k, rho) : 0.0;
            SL[k * 6 + l] = l <= k ? ccn__bi5_bern(k, l, rho) : 0.0;
        }
}

void ccn__bi5_prolong(double tau, double PR[9]) {
    /* q_k = sum_m C(k,m) (1-tau)^m tau^(k-m) p_{5-m}; PR acts on (p_3, p_4, p_5). */
    memset(PR, 0, sizeof(double) * 9);
    for (int32_t k = 0; k < 3; k++)
        for (int32_t mm = 0; mm <= k; mm++)
            PR[k * 3 + 2 - mm] += ccn__bi5_binom(k, mm) * pow(1.0 - tau, mm) * pow(tau, k - mm);
}

/* Taylor weights Wt[a][idx] (a <= 2) of a degree-d Bernstein polynomial at t = corner. */
static void taylor_weights_1d(int32_t d, int32_t corner, double Wt[3][6]) {
    memset(Wt, 0, sizeof(double) * 18);
    for (int32_t a = 0; a < 3; a++)
        for (int32_t k = 0; k <= a; k++) {
            double w = ccn__bi5_binom(d, a) * ccn__bi5_binom(a, k) * (((a - k) & 1) ? -1.0 : 1.0);
            Wt[a][corner ? d - a + k : k] += w;
        }
}

void ccn__bi5_taylor(const double complex *P, int32_t d, int32_t cu, int32_t cv,
                     double complex T[9]) {
    double Wu[3][6], Wv[3][6];
    taylor_weights_1d(d, cu, Wu);
    taylor_weights_1d(d, cv, Wv);
    for (int32_t a = 0; a < 3; a++)
        for (int32_t b = 0; b < 3; b++) {
            double complex acc = 0;
            for (int32_t k = 0; k <= d; k++)
                for (int32_t l = 0; l <= d; l++)
                    if (Wu[a][k] != 0.0 && Wv[b][l] != 0.0) acc += Wu[a][k] * Wv[b][l] * P[k * (d + 1) + l];
            T[a * 3 + b] = acc;
        }
}

void ccn__bi5_jet_weights(int32_t corner1, double Wj[9]) {
    /* SPEC §2.3: layer k from orders a <= k: C(k,a)/C(5,a), times (-1)^a at corner 1. */
    memset(Wj, 0, sizeof(double) * 9);
    for (int32_t k = 0; k < 3; k++)
        for (int32_t a = 0; a <= k; a++)
            Wj[k * 3 + a] = ccn__bi5_binom(k, a) / ccn__bi5_binom(5, a) * ((corner1 && (a & 1)) ? -1.0 : 1.0);
}

void ccn__bi5_bern5_with_deriv(double t, double B[6], double D[6]) {
    for (int32_t k = 0; k < 6; k++) {
        B[k] = ccn__bi5_bern(5, k, t);
        D[k] = 5.0 * (ccn__bi5_bern(4, k - 1, t) - ccn__bi5_bern(4, k, t));
    }
}

void ccn__bi5_patch_eval(const double *P, int32_t m, double u, double v, double *pos,
                         double *du, double *dv) {
    double Bu[6], Du[6], Bv[6], Dv[6];
    ccn__bi5_bern5_with_deriv(u, Bu, Du);
    ccn__bi5_bern5_with_deriv(v, Bv, Dv);
    ccn__bi5_patch_eval_tab(P, m, Bu, Du, Bv, Dv, pos, du, dv);
}

void ccn__bi5_patch_eval_tab(const double *P, int32_t m, const double Bu[6], const double Du[6],
                             const double Bv[6], const double Dv[6], double *pos, double *du,
                             double *dv) {
    for (int32_t c = 0; c < m; c++) {
        double p = 0, pu = 0, pv = 0;
        for (int32_t i = 0; i < 6; i++)
            for (int32_t j = 0; j < 6; j++) {
                double x = P[(i * 6 + j) * m + c];
                p += Bu[i] * Bv[j] * x;
                pu += Du[i] * Bv[j] * x;
                pv += Bu[i] * Dv[j] * x;
            }
        if (pos) pos[c] = p;
        if (du) du[c] = pu;
        if (dv) dv[c] = pv;
    }
}
