/* Rapidly contracting bi-5 rings (paper Sec. 4.3, SPEC §2, §5): the tensor-border t_CC of the
 * level-K net, raising to degree 5, the (NU) C2-rule across spokes, sampling the guide into
 * a border, the ring patches A, B, C of one sector, and ring 0 from an exact surround ([R13]). */
#include "bi5/rings.h"

#include "bi5/bernstein.h"
#include "bi5/charmap.h"

#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

/* ---- t_CC (SPEC §2.1, §9.1, [R8]) ------------------------------------------------------ */

/* Knot vector t_{-2..3} of a direction with interval dn on the negative side and dp on the
 * positive side, normalised so that the hole interval is [0,1]. */
static void dir_knots(double dn, double dp, double t[6]) {
    double r = dn / dp;
    t[0] = -2 * r; t[1] = -r; t[2] = 0; t[3] = 1; t[4] = 2; t[5] = 3;
}

static void bb_weights_exact(const double t[6], double W[4][3]) {
    ccn__bi5_bb_weights(t, W);
    W[1][0] = 0.0; /* b(t0,t0,t1) and b(t0,t1,t1) do not involve c_{-1} (exactly) */
    W[2][0] = 0.0;
}

/* Raises bicubic tensor-borders p (n x 16 x m, [a*4+b], p_00 unused) to bi-5 on the mask:
 * T (n x 36 x m), zero elsewhere (SPEC §2.2). */
void ccn__bi5_raise_border(int32_t n, const double *p, int32_t m, double *T) {
    static const double E[6][4] = {{1, 0, 0, 0}, {0.4, 0.6, 0, 0}, {0.1, 0.6, 0.3, 0},
                                   {0, 0.3, 0.6, 0.1}, {0, 0, 0.6, 0.4}, {0, 0, 0, 1}};
    memset(T, 0, sizeof(double) * (size_t)n * 36 * (size_t)m);
    for (int32_t s = 0; s < n; s++)
        for (int32_t i = 0; i < 6; i++)
            for (int32_t j = 0; j < 6; j++) {
                if (!ccn__bi5_in_mask(i, j)) continue;
                for (int32_t a = 0; a < 4; a++)
                    for (int32_t bq = 0; bq < 4; bq++)
                        if (E[i][a] * E[j][bq] != 0.0 && (a || bq))
                            ccn__bi5_axpy(T + ((size_t)s * 36 + i * 6 + j) * m, E[i][a] * E[j][bq],
                                          p + ((size_t)s * 16 + a * 4 + bq) * m, m);
            }
}

/* t_CC of every sector (SPEC §2.1; knots [R8]), bicubic: p (n x 16 x m). */
void ccn__bi5_tcc(int32_t n, const double *X, const double *d, int32_t m, double *p) {
    static const int32_t first[4] = {-1, -1, -1, 0};
    memset(p, 0, sizeof(double) * (size_t)n * 16 * (size_t)m);
    for (int32_t s = 0; s < n; s++) {
        double tu[6], tv[6], Wu[4][3], Wv[4][3];
        dir_knots(d ? d[(s + 2) % n] : 1, d ? d[s] : 1, tu);
        dir_knots(d ? d[(s + n - 1) % n] : 1, d ? d[(s + 1) % n] : 1, tv);
        bb_weights_exact(tu, Wu);
        bb_weights_exact(tv, Wv);
        for (int32_t a = 0; a < 4; a++)
            for (int32_t bq = 0; bq < 4; bq++) {
                if (a == 0 && bq == 0) continue; /* p_00 is never used (SPEC §2.2) */
                for (int32_t i = 0; i < 3; i++)
                    for (int32_t j = 0; j < 3; j++) {
                        double w = Wu[a][i] * Wv[bq][j];
                        int32_t ds, node = ccn__bi5_node(n, s, first[a] + i, first[bq] + j, &ds);
                        if (w == 0.0 || node < 0) continue;
                        ccn__bi5_axpy(p + ((size_t)s * 16 + a * 4 + bq) * m, w, X + (size_t)node * m, m);
                    }
            }
    }
}

/* ---- C2-rule (SPEC §2.4, §9.3) --------------------------------------------------------- */

/* Across every spoke e_s, for along-spoke index i = 3..5: P_-2, P_-1 = T^{s-1}_{2,i},
 * T^{s-1}_{1,i}; P_0 = T^s_{i,0}; P_1, P_2 = T^s_{i,1}, T^s_{i,2}. Ratio r = kap[s] (NULL: 1):
 * P_-1 = ((1+r)^2 P_0 + r^2 P_-2 - P_2) / (2r(1+r)), P_1 = P_0 + r (P_0 - P_-1). */
void ccn__bi5_c2_rule(int32_t n, const double *kap, int32_t m, double *T) {
    for (int32_t s = 0; s < n; s++) {
        int32_t p = (s + n - 1) % n;
        double r = kap ? kap[s] : 1.0;
        for (int32_t i = 3; i < 6; i++) {
            double *Pm2 = T + ((size_t)p * 36 + 2 * 6 + i) * m, *Pm1 = T + ((size_t)p * 36 + 1 * 6 + i) * m;
            double *P0 = T + ((size_t)s * 36 + i * 6 + 0) * m, *P1 = T + ((size_t)s * 36 + i * 6 + 1) * m;
            double *P2 = T + ((size_t)s * 36 + i * 6 + 2) * m;
            for (int32_t c = 0; c < m; c++) {
                double pm1 = ((1 + r) * (1 + r) * P0[c] + r * r * Pm2[c] - P2[c]) / (2 * r * (1 + r));
                Pm1[c] = pm1;
                P1[c] = P0[c] + r * (P0[c] - pm1);
            }
        }
    }
}

/* ---- rings (SPEC §5 step 4) ------------------------------------------------------------ */

/* out[i][j] = sum_{k in [k0,6), l in [l0,6)} L[i][k] Tm[k][l] R[j][l] for i in [i0,i1),
 * j in [j0,j1) (m columns). */
static void tmul(const double L[36], const double *Tm, const double R[36], int32_t i0, int32_t i1,
                 int32_t j0, int32_t j1, int32_t k0, int32_t l0, int32_t m, double *out) {
    for (int32_t i = i0; i < i1; i++)
        for (int32_t j = j0; j < j1; j++) {
            double *o = out + (size_t)(i * 6 + j) * m;
            memset(o, 0, sizeof(double) * (size_t)m);
            for (int32_t k = k0; k < 6; k++)
                for (int32_t l = l0; l < 6; l++) {
                    double w = L[i * 6 + k] * R[j * 6 + l];
                    if (w != 0.0) ccn__bi5_axpy(o, w, Tm + (size_t)(k * 6 + l) * m, m);
                }
        }
}

/* Patches A, B, C of one sector from the outer border To (level r-1) and the inner border Ti
 * (level r): split sigma : 1-sigma, inner part prolonged with tau = 1/rho (SPEC §2.5). */
void ccn__bi5_ring_sector(const double *To, const double *Ti, double sigma, int32_t m,
                        double *A, double *B, double *C) {
    double rho = 1.0 - sigma, SR[36], SL[36], PR[9], P6[36] = {0}, Id[36] = {0};
    ccn__bi5_split(rho, SR, SL);
    ccn__bi5_prolong(1.0 / rho, PR);
    for (int32_t k = 0; k < 3; k++)
        for (int32_t l = 0; l < 3; l++) P6[k * 6 + 3 + l] = PR[k * 3 + l];
    for (int32_t k = 0; k < 6; k++) Id[k * 6 + k] = 1.0;
    tmul(SR, To, SL, 3, 6, 0, 6, 3, 0, m, A);   /* A[3..5][.] = SR To[3..5][.] SL^T */
    tmul(P6, Ti, Id, 0, 3, 0, 6, 3, 0, m, A);   /* A[0..2][.] = PR Ti[3..5][.]      */
    tmul(SL, To, SR, 0, 6, 3, 6, 0, 3, m, C);   /* C[.][3..5] = SL To[.][3..5] SR^T */
    tmul(Id, Ti, P6, 0, 6, 0, 3, 0, 3, m, C);   /* C[.][0..2] = Ti[.][3..5] PR^T    */
    tmul(SR, To, SR, 3, 6, 0, 6, 3, 0, m, B);   /* B[3..5][.]                        */
    tmul(SR, To, SR, 0, 3, 3, 6, 0, 3, m, B);   /* B[0..2][3..5]                     */
    tmul(P6, Ti, P6, 0, 3, 0, 3, 3, 3, m, B);   /* B[0..2][0..2] = PR Ti PR^T        */
}

/* Ring 0 of a sector with sigma = 1/2 from the exact surround pieces (bi5.h [R13]): P holds
 * 4 full bi-5 polynomials (36 x m each) over the hole: 0 across u = 1 for v in [0,1/2], 1 across
 * u = 1 for v in [1/2,1], 2 across v = 1 for u in [0,1/2], 3 across v = 1 for u in [1/2,1].
 * Each patch takes its outer layers from the piece it borders (the split at 1/2 is the pieces'
 * knot), its inner layers from Ti as in ring_sector. */
void ccn__bi5_ring_sector_pieces(const double *P, const double *Ti, int32_t m, double *A, double *B,
                               double *C) {
    double SR[36], SL[36], PR[9], P6[36] = {0}, Id[36] = {0};
    size_t ps = 36 * (size_t)m;
    ccn__bi5_split(0.5, SR, SL);
    ccn__bi5_prolong(2.0, PR);
    for (int32_t k = 0; k < 3; k++)
        for (int32_t l = 0; l < 3; l++) P6[k * 6 + 3 + l] = PR[k * 3 + l];
    for (int32_t k = 0; k < 6; k++) Id[k * 6 + k] = 1.0;
    tmul(SR, P + 0 * ps, SL, 3, 6, 0, 6, 3, 0, m, A); /* A[3..5][.]: piece u, v <= 1/2 */
    tmul(P6, Ti, Id, 0, 3, 0, 6, 3, 0, m, A);
    tmul(SL, P + 2 * ps, SR, 0, 6, 3, 6, 0, 3, m, C); /* C[.][3..5]: piece v, u <= 1/2 */
    tmul(Id, Ti, P6, 0, 6, 0, 3, 0, 3, m, C);
    tmul(SR, P + 1 * ps, SR, 3, 6, 0, 6, 3, 0, m, B); /* B[3..5][.]: piece u, v >= 1/2 */
    tmul(SR, P + 3 * ps, SR, 0, 3, 3, 6, 0, 3, m, B); /* B[0..2][3..5]: piece v, u >= 1/2 */
    tmul(P6, Ti, P6, 0, 3, 0, 3, 3, 3, m, B);
}

/* T (n x 36 x m) = the sampling matrix of sector s, samp + s * sstride (36 x 28; sstride 0: one
 * for every sector), applied to the guide gbb (n x 28 x m). */
void ccn__bi5_sample_border(int32_t n, const double *samp, size_t sstride, const double *gbb, int32_t m,
                            double *T) {
    memset(T, 0, sizeof(double) * (size_t)n * 36 * (size_t)m);
    for (int32_t s = 0; s < n; s++)
        for (int32_t e = 0; e < 36; e++)
            for (int32_t t = 0; t < 28; t++) {
                double w = samp[(size_t)s * sstride + e * 28 + t];
                if (w != 0.0)
                    ccn__bi5_axpy(T + ((size_t)s * 36 + e) * m, w, gbb + ((size_t)s * 28 + t) * m, m);
            }
}

/* Least-squares degree-5 BB coefficients c[6][m] of the piecewise function that is lo(t) on
 * [0,1/2] and hi(t) on [1/2,1] (each given by 6 BB coefficients of stride `st` doubles):
 * 8 Gauss-Legendre-like nodes per half, normal equations solved by LAPACK (dposv). */
static int fit_piecewise(const double *lo, const double *hi, size_t st, int32_t m, double *c) {
    static const double g[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281,
                                0.9305681557970263}; /* 4-point Gauss nodes on [0,1] */
    double N[36] = {0}, R[6 * 3] = {0};
    for (int half = 0; half < 2; half++)
        for (int q = 0; q < 4; q++) {
            double t = 0.5 * (half + g[q]), B[6], y[3] = {0, 0, 0};
            for (int j = 0; j < 6; j++) B[j] = ccn__bi5_bern(5, j, t);
            const double *P = half ? hi : lo;
            for (int j = 0; j < 6; j++)
                for (int k = 0; k < m; k++) y[k] += B[j] * P[(size_t)j * st + k];
            for (int a = 0; a < 6; a++) {
                for (int b2 = 0; b2 < 6; b2++) N[a * 6 + b2] += B[a] * B[b2];
                for (int k = 0; k < m; k++) R[a * 3 + k] += B[a] * y[k];
            }
        }
    if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', 6, m, N, 6, R, 3) != 0) return -1;
    for (int a = 0; a < 6; a++)
        for (int k = 0; k < m; k++) c[(size_t)a * m + k] = R[a * 3 + k];
    return 0;
}

/* The guide's least-squares target from the pieces (bi5.h [R13]): per sector, rows 3..5 =
 * the best single quintic in v of the two u-leg pieces' rows, columns 3..5 the same for the
 * v-leg pieces in u, the corner block (both >= 3) the mean of the two. T: n x 36 x 3. */
int ccn__bi5_pieces_target(int32_t n, const double *pieces, double *T) {
    memset(T, 0, sizeof(double) * (size_t)n * 108);
    for (int32_t s = 0; s < n; s++) {
        const double *P = pieces + (size_t)s * 432;
        double *Ts = T + (size_t)s * 108, c[18];
        for (int i = 3; i < 6; i++) { /* row i (u-jet), function of v: entries (i, j), stride 3 */
            if (fit_piecewise(P + i * 18, P + 108 + i * 18, 3, 3, c)) return -1;
            for (int j = 0; j < 6; j++)
                for (int k = 0; k < 3; k++) Ts[(i * 6 + j) * 3 + k] = c[j * 3 + k];
        }
        for (int j = 3; j < 6; j++) { /* column j (v-jet), function of u: entries (i, j), stride 18 */
            if (fit_piecewise(P + 216 + j * 3, P + 324 + j * 3, 18, 3, c)) return -1;
            for (int i = 0; i < 6; i++)
                for (int k = 0; k < 3; k++) {
                    double *t = Ts + (i * 6 + j) * 3 + k;
                    *t = i >= 3 ? 0.5 * (*t + c[i * 3 + k]) : c[i * 3 + k];
                }
        }
    }
    return 0;
}
