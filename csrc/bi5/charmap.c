/* Characteristic tensor-borders chi~_sigma of adjustable-speed subdivision (SPEC §3, [R2]),
 * cubic blossoms and the c-net neighbour rules (SPEC §1.1, §1.2). */
#include "bi5/charmap.h"

#include "base/error.h"
#include "bi5/bernstein.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

double ccn__bi5_lambda(int32_t n, double sigma) {
    /* Paper Sec. 4.1: lambda = s~/2 ((1+c)s^2 + 2 s~ + s sqrt((1+c)((1+c)s^2 + 4 s~))). */
    double c = cos(2.0 * CCN_BI5_PI / n), st = 1.0 - sigma;
    return 0.5 * st * ((1 + c) * sigma * sigma + 2 * st
                       + sigma * sqrt((1 + c) * ((1 + c) * sigma * sigma + 4 * st)));
}

/* Own nodes of a sector in c-net order c_1..c_6 ([R1]). */
static const int32_t own_i[6] = {2, 2, 2, 1, 1, 1}, own_j[6] = {0, 1, 2, 2, 1, 0};

static int32_t own_index(int32_t i, int32_t j) {
    for (int32_t m = 0; m < 6; m++)
        if (own_i[m] == i && own_j[m] == j) return m;
    return -1;
}

int32_t ccn__bi5_node(int32_t n, int32_t s, int32_t i, int32_t j, int32_t *ds) {
    int32_t off = 0;
    for (int32_t guard = 0; guard < 4; guard++) {
        if (i == 0 && j == 0) { *ds = 0; return 0; }
        if (i >= 1 && j >= 0) {
            int32_t m = own_index(i, j);
            if (m < 0) return -1;
            *ds = off;
            return 1 + 6 * (((s + off) % n + n) % n) + m;
        }
        if (i == 0 && j >= 1) { i = j; j = 0; off++; continue; }        /* (0,j)_s = (j,0)_{s+1} */
        if (j == -1 && i >= 0) { j = i; i = 1; off--; continue; }       /* (i,-1)_s = (1,i)_{s-1} */
        if (i == -1 && j >= 0) { i = j; j = 1; off++; continue; }       /* (-1,j)_s = (j,1)_{s+1} */
        return -1;                                                       /* (-1,-1) */
    }
    return -1;
}

int ccn__bi5_blossom(const double t[6], int32_t k, double x, double y, double w[3]) {
    /* Pairs of the labels without t_k: c_{k-1}: (t_{k-2},t_{k-1}), c_k: (t_{k-1},t_{k+1}),
     * c_{k+1}: (t_{k+1},t_{k+2}); solve sum w (1, p+q, pq) = (1, x+y, xy) (Cramer). */
    const double *T = t + 2; /* T[m] = t_m */
    double p[3] = {T[k - 2], T[k - 1], T[k + 1]}, q[3] = {T[k - 1], T[k + 1], T[k + 2]};
    double A[3][3], r[3] = {1.0, x + y, x * y};
    for (int c = 0; c < 3; c++) {
        A[0][c] = 1.0;
        A[1][c] = p[c] + q[c];
        A[2][c] = p[c] * q[c];
    }
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1])
               - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
               + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(fabs(det) > 1e-300)) return -1;
    for (int c = 0; c < 3; c++) {
        double B[3][3];
        memcpy(B, A, sizeof B);
        for (int rr = 0; rr < 3; rr++) B[rr][c] = r[rr];
        w[c] = (B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1])
              - B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0])
              + B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0])) / det;
    }
    return 0;
}

int ccn__bi5_bb_weights(const double t[6], double W[4][3]) {
    /* SPEC §3.1 / §2.1: W_0 = b(0,0,0), W_1 = b(0,0,1), W_2 = b(0,1,1) on c_{-1..1};
     * W_3 = b(1,1,1) on c_{0..2}. */
    int e = 0;
    e |= ccn__bi5_blossom(t, 0, 0.0, 0.0, W[0]);
    e |= ccn__bi5_blossom(t, 0, 0.0, 1.0, W[1]);
    e |= ccn__bi5_blossom(t, 0, 1.0, 1.0, W[2]);
    e |= ccn__bi5_blossom(t, 1, 1.0, 1.0, W[3]);
    return e;
}

/* Knots of the reconstructed scheme, level units, hole boundary at 1 (SPEC §3.1). */
static void sigma_knots(double sigma, double t[6]) {
    double st = 1.0 - sigma;
    t[0] = -1.0 / st; t[1] = -1.0; t[2] = 0.0; t[3] = 1.0; t[4] = 1.0 / st;
    t[5] = (1.0 + sigma) / st;
}

/* 1-D refinement rules R_0, R_1, R_2 (SPEC §3.1 table) as weights on nodes first[I] + q. */
static int refine_rules(double sigma, double R[3][3], int32_t first[3]) {
    double t[6], st = 1.0 - sigma;
    sigma_knots(sigma, t);
    first[0] = -1; first[1] = -1; first[2] = 0;
    int e = ccn__bi5_blossom(t, 0, -st, st, R[0]);       /* b(-s~, 0, s~) */
    e |= ccn__bi5_blossom(t, 0, st, 1.0, R[1]);          /* b(0, s~, 1)   */
    e |= ccn__bi5_blossom(t, 1, st, 1.0 + sigma, R[2]);  /* b(s~, 1, 1+s) */
    return e;
}

/* Frequency-1 matrix M (6x6 complex, column-major) of the 2-D rules on sector 0 (SPEC §3.1). */
static void freq1_matrix(int32_t n, double sigma, double complex M[36]) {
    double R[3][3];
    int32_t first[3];
    refine_rules(sigma, R, first);
        memset(M, 0, sizeof(double complex) * 36);
    for (int32_t r = 0; r < 6; r++) {
        int32_t Ii = own_i[r], Jj = own_j[r];
        for (int32_t a = 0; a < 3; a++)
            for (int32_t bq = 0; bq < 3; bq++) {
                int32_t ds, node = ccn__bi5_node(n, 0, first[Ii] + a, first[Jj] + bq, &ds);
                double w = R[Ii][a] * R[Jj][bq];
                if (node <= 0 || w == 0.0) continue; /* EV: no frequency-1 part */
                M[r + 6 * ((node - 1) % 6)] += w * ccn__bi5_omega(n, ds);
            }
    }
}

/* Null vector of M - lambda Id by complex SVD (SPEC §3.1). */
static ccn_status null_vector(double complex M[36], double lambda, double complex x[6],
                              ccn_error *err) {
    double complex A[36], U[36], VT[36];
    double sv[6], super[5];
    memcpy(A, M, sizeof A);
    for (int k = 0; k < 6; k++) A[k + 6 * k] -= lambda;
    lapack_int info = LAPACKE_zgesvd(LAPACK_COL_MAJOR, 'N', 'A', 6, 6, A, 6, sv, U, 6, VT, 6, super);
    if (info != 0 || !(sv[5] <= 1e-9 * (1.0 + sv[0])))
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1,
                         "bi5: characteristic map: lambda_sigma is not an eigenvalue of the "
                         "frequency-1 matrix (info %d, smallest singular value %g)", (int)info, sv[5]);
    for (int k = 0; k < 6; k++) x[k] = conj(VT[5 + 6 * k]);
    return CCN_OK;
}

/* Bicubic tensor-border of the frequency-1 net x (sector 0) with the BB weights W. */
static void eigen_border(int32_t n, const double complex x[6], double W[4][3],
                         double complex chi[16]) {
    static const int32_t first[4] = {-1, -1, -1, 0};
        for (int32_t a = 0; a < 4; a++)
        for (int32_t bq = 0; bq < 4; bq++) {
            double complex acc = 0;
            for (int32_t p = 0; p < 3 && (a || bq); p++)
                for (int32_t q = 0; q < 3; q++) {
                    int32_t ds, node = ccn__bi5_node(n, 0, first[a] + p, first[bq] + q, &ds);
                    if (node > 0) acc += W[a][p] * W[bq][q] * ccn__bi5_omega(n, ds) * x[(node - 1) % 6];
                }
            chi[a * 4 + bq] = acc;
        }
}

ccn_status ccn__bi5_charmap(int32_t n, double sigma, double complex chi[16], double *lambda,
                            ccn_error *err) {
    if (!(sigma > 0.0 && sigma < 1.0))
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "bi5: ring speed sigma = %g is not in (0,1)", sigma);
    double complex M[36], x[6];
    double lam = ccn__bi5_lambda(n, sigma), t[6], W[4][3];
    freq1_matrix(n, sigma, M);
    ccn_status st = null_vector(M, lam, x, err);
    if (st) return st;
    sigma_knots(sigma, t);
    ccn__bi5_bb_weights(t, W);
    eigen_border(n, x, W, chi);
    double complex scale = chi[3 * 4 + 0]; /* [R2]: chi~[3][0] = 1 */
    if (!(cabs(scale) > 1e-12))
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1,
                         "bi5: characteristic map has a zero corner on spoke e_0");
    for (int k = 0; k < 16; k++) chi[k] /= scale;
    chi[0] = 0;
    if (lambda) *lambda = lam;
    return CCN_OK;
}
