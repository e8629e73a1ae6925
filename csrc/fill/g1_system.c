/* The G1 fill's linear system, dense parts (fill/g1_system.h; what it solves and why:
 * fill/g1_fill.c). */
#include "fill/g1_system.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double KQ[NQ + PQ + 1] = CCN_FILL_G1_KNOTS;
static const double KC[9] = {0, 0, 0, 0, 1, 2, 2, 2, 2};

/* All n basis functions of degree p (>= 2) over flat knots t at u (the span with
 * t[s] <= u < t[s+1], the last one at the domain's end) and their first and second
 * derivatives (d2N may be NULL): N^(k)_{i,p} = p (N^(k-1)_{i,p-1} / (t_{i+p} - t_i)
 * - N^(k-1)_{i+1,p-1} / (t_{i+p+1} - t_{i+1})), 0/0 = 0. */
static double ratio(double a, double l) { return l > 0 ? a / l : 0; }
void ccn__g1_basis(const double *t, int p, int n, double u, double *N, double *dN, double *d2N) {
    double a[NQ + PQ + 1], b[NQ + PQ + 1], lo[NQ + PQ + 1], d1[NQ + PQ + 1];
    int s = p;
    for (int i = n - 1; i >= p; i--)
        if (t[i] <= u && t[i] < t[i + 1]) { s = i; break; }
    int m = n + p; /* degree-0 functions 0 .. m - 1 */
    for (int i = 0; i < m; i++) a[i] = i == s;
    for (int d = 1; d <= p; d++) {
        if (d == p - 1) memcpy(lo, a, sizeof(double) * (size_t)(m - d + 1)); /* degree p - 2 */
        if (d == p) /* a: degree p - 1 */
            for (int i = 0; i < n; i++) dN[i] = p * (ratio(a[i], t[i + p] - t[i]) - ratio(a[i + 1], t[i + p + 1] - t[i + 1]));
        for (int i = 0; i < m - d; i++)
            b[i] = ratio((u - t[i]) * a[i], t[i + d] - t[i]) + ratio((t[i + d + 1] - u) * a[i + 1], t[i + d + 1] - t[i + 1]);
        memcpy(a, b, sizeof(double) * (size_t)(m - d));
    }
    memcpy(N, a, sizeof(double) * (size_t)n);
    if (!d2N) return;
    for (int i = 0; i < n + 1; i++) /* first derivatives of the degree p - 1 functions */
        d1[i] = (p - 1) * (ratio(lo[i], t[i + p - 1] - t[i]) - ratio(lo[i + 1], t[i + p] - t[i + 1]));
    for (int i = 0; i < n; i++) d2N[i] = p * (ratio(d1[i], t[i + p] - t[i]) - ratio(d1[i + 1], t[i + p + 1] - t[i + 1]));
}

/* A[k] = the Gram matrices of the quintic basis' k-th derivatives over [0, 2] (Gauss-Legendre,
 * 6 points per span: exact for the degree-10 products). */
void ccn__g1_gram(double A[3][NQ][NQ]) {
    static const double X[6] = {-0.9324695142031521, -0.6612093864662645, -0.2386191860831969,
                                0.2386191860831969,  0.6612093864662645,  0.9324695142031521};
    static const double Wt[6] = {0.1713244923791704, 0.3607615730481386, 0.4679139345726910,
                                 0.4679139345726910, 0.3607615730481386, 0.1713244923791704};
    memset(A, 0, sizeof(double) * 3 * NQ * NQ);
    for (int span = 0; span < 2; span++)
        for (int g = 0; g < 6; g++) {
            double u = span + 0.5 * (X[g] + 1), w = 0.5 * Wt[g], B[3][NQ];
            ccn__g1_basis(KQ, PQ, NQ, u, B[0], B[1], B[2]);
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < NQ; i++)
                    for (int j = 0; j < NQ; j++) A[k][i][j] += w * B[k][i] * B[k][j];
        }
}

/* E (9 x 5): the quintic poles of each cubic B-spline (degree raising, exact: the cubic with
 * a simple knot at 1 is C2 there, the quintic with a triple one too), by collocation at the
 * quintic's Greville abscissae; the end rows exactly the unit ones so that spokes stay
 * bit-identical. */
int ccn__g1_raise_matrix(double E[NQ][5]) {
    double A[NQ * NQ], B[NQ * 5], dN[NQ], Nc[5], dNc[5];
    lapack_int ipiv[NQ];
    for (int r = 0; r < NQ; r++) {
        double g = 0;
        for (int k = 1; k <= PQ; k++) g += KQ[r + k];
        g /= PQ;
        ccn__g1_basis(KQ, PQ, NQ, g, A + NQ * r, dN, NULL);
        ccn__g1_basis(KC, 3, 5, g, Nc, dNc, NULL);
        memcpy(B + 5 * r, Nc, sizeof Nc);
    }
    if (LAPACKE_dgesv(LAPACK_ROW_MAJOR, NQ, 5, A, NQ, ipiv, B, 5) != 0) return -1;
    for (int i = 0; i < NQ; i++)
        for (int k = 0; k < 5; k++) {
            double e = B[5 * i + k];
            E[i][k] = fabs(e) < 1e-13 ? 0 : e;
        }
    for (int k = 0; k < 5; k++) E[0][k] = k == 0, E[NQ - 1][k] = k == 4;
    return 0;
}

/* The weights (beta, gamma) with Da + beta Db ~ gamma T in least squares; 0 when the three do
 * not lie in one plane with Da and Db on opposite sides of T (within 1e-7). */
int ccn__g1_weights_of(const double *Da, const double *Db, const double *T, double *beta, double *gamma) {
    double bb = 0, bt = 0, tt = 0, ab = 0, at = 0, aa = 0;
    for (int d = 0; d < 3; d++) {
        bb += Db[d] * Db[d], bt += Db[d] * T[d], tt += T[d] * T[d];
        ab += Da[d] * Db[d], at += Da[d] * T[d], aa += Da[d] * Da[d];
    }
    double det = bb * tt - bt * bt;
    if (!(det > 1e-12 * bb * tt) || !(aa > 0)) return 0;
    double be = (-ab * tt + at * bt) / det, ga = (at * bb - ab * bt) / det, res = 0;
    for (int d = 0; d < 3; d++) {
        double x = Da[d] + be * Db[d] - ga * T[d];
        res += x * x;
    }
    if (!(res <= 1e-14 * aa) || !(be > 0)) return 0;
    *beta = be, *gamma = ga;
    return 1;
}

/* Is a on the line of t (within 1e-7 rad)? */
static int along(const double *a, const double *t) {
    double c[3] = {a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0]};
    double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2], aa = 0, tt = 0;
    for (int d = 0; d < 3; d++) aa += a[d] * a[d], tt += t[d] * t[d];
    return aa > 0 && tt > 0 && cc <= 1e-14 * aa * tt;
}

/* out (n x nr) = V1 S1^-1 U1^T rhs (m x nr): the least-norm solution of C x = rhs on C's first
 * `rank` singular triplets (C = U S V^T, row-major U m x m, VT n x n). */
static void particular(const double *U, const double *VT, const double *sv, int32_t rank, int32_t m, int32_t n,
                       const double *rhs, double *out, int32_t nr, double *ur) {
    memset(out, 0, sizeof(double) * (size_t)nr * n);
    for (int32_t r = 0; r < rank; r++) {
        for (int32_t d = 0; d < nr; d++) ur[d] = 0;
        for (int32_t q = 0; q < m; q++) {
            double u = U[(size_t)q * m + r];
            if (u != 0)
                for (int32_t d = 0; d < nr; d++) ur[d] += u * rhs[(size_t)nr * q + d];
        }
        for (int32_t i = 0; i < n; i++)
            for (int32_t d = 0; d < nr; d++) out[(size_t)nr * i + d] += VT[(size_t)r * n + i] * ur[d] / sv[r];
    }
}

/* x = E c E^T per filled sector: the bicubic fills degree-raised, rows first (spokes stay
 * bit-identical: E's first row is the unit one). */
void ccn__g1_raise(double E[NQ][5], const double (*cs)[5][5][3], const uint8_t *filled, int32_t nfan,
                   double (*x)[NQ][NQ][3]) {
    for (int32_t k = 0; k < nfan; k++) {
        if (!filled[k]) { memset(x[k], 0, sizeof x[k]); continue; }
        double t[NQ][5][3];
        for (int i = 0; i < NQ; i++)
            for (int b = 0; b < 5; b++)
                for (int d = 0; d < 3; d++) {
                    double s = 0;
                    for (int a = 0; a < 5; a++) s += E[i][a] * cs[k][a][b][d];
                    t[i][b][d] = s;
                }
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++)
                for (int d = 0; d < 3; d++) {
                    double s = 0;
                    for (int b = 0; b < 5; b++) s += t[i][b][d] * E[j][b];
                    x[k][i][j][d] = s;
                }
    }
}

/* The unknowns: per smooth spoke (smooth[k] set here) its poles 2..6, per filled sector with a
 * smooth spoke its inner poles 1..6 x 1..6 except the cross-derivative row along a sharp spoke
 * (its crease keeps the normals it was built with); a sector between two sharp spokes stays.
 * idx[k][i][j] = the unknown of sector k's pole (i, j), -1 if fixed. Returns their number
 * (*nsm: the smooth spokes), -1 out of memory. */
int32_t ccn__g1_unknowns(int32_t nfan, int32_t nsp, const uint8_t *sharp, const uint8_t *filled, uint8_t *smooth,
                         int32_t (*idx)[NQ][NQ], int32_t *nsm) {
    int32_t nvar = 0, *spk = malloc(sizeof(int32_t) * (size_t)(nsp + 1));
    if (!spk) return -1;
    *nsm = 0;
    for (int32_t k = 0; k < nsp; k++) {
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan;
        smooth[k] = !sharp[k] && k < nfan && filled[a] && filled[b] && (nsp == nfan || k > 0);
        spk[k] = smooth[k] ? nvar : -1;
        if (smooth[k]) nvar += 5, (*nsm)++;
    }
    for (int32_t k = 0, blk = 0; k < nfan; k++) {
        int32_t k1 = (k + 1) % nsp;
        int own = filled[k] && (spk[k] >= 0 || spk[k1] >= 0);
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = -1;
                if (!own) {
                } else if (j == 0) {
                    if (i >= 2 && i <= 6 && spk[k] >= 0) v = spk[k] + i - 2;
                } else if (i == 0) {
                    if (j >= 2 && j <= 6 && spk[k1] >= 0) v = spk[k1] + j - 2;
                } else if (i <= 6 && j <= 6 && !(j == 1 && i >= 2 && spk[k] < 0) && !(i == 1 && j >= 2 && spk[k1] < 0)) {
                    v = 5 * *nsm + 36 * blk + 6 * (i - 1) + (j - 1);
                }
                idx[k][i][j] = v;
            }
        if (own) blk++, nvar += 36;
    }
    free(spk);
    return nvar;
}

/* The weights the data implies at both ends of every smooth spoke (fill/g1_fill.h): at u = 0
 * the three vectors lie in the limit tangent plane (spokes k+1, k-1, k), at u = 2 the exact
 * pieces beyond meet C1 (beta = the parameter scale across, gamma ~ 0), each solved in least
 * squares and checked (coplanar, beta > 0: no fold). */
int ccn__g1_data_weights(double (*x)[NQ][NQ][3], int32_t nfan, int32_t nsp, const uint8_t *smooth,
                         ccn__g1_weights *wt) {
    for (int32_t k = 0; k < nsp; k++) {
        if (!smooth[k]) continue;
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan;
        double Da0[3], Db0[3], T0[3], Da2[3], Db2[3], T2[3], be0, ga0, be2, ga2;
        for (int d = 0; d < 3; d++) {
            Da0[d] = x[a][0][1][d] - x[a][0][0][d], Db0[d] = x[b][1][0][d] - x[b][0][0][d];
            T0[d] = x[a][1][0][d] - x[a][0][0][d];
            Da2[d] = x[a][8][1][d] - x[a][8][0][d], Db2[d] = x[b][1][8][d] - x[b][0][8][d];
            T2[d] = x[a][8][0][d] - x[a][7][0][d];
        }
        if (!ccn__g1_weights_of(Da2, Db2, T2, &be2, &ga2)) return 0;
        if (!ccn__g1_weights_of(Da0, Db0, T0, &be0, &ga0)) { /* a valence-2 vertex: the three on one line */
            if (!along(Da0, T0) || !along(Db0, T0)) return 0;
            double dt = 0, tt = 0;
            be0 = be2; /* any beta holds there: the far end's */
            for (int d = 0; d < 3; d++) dt += (Da0[d] + be0 * Db0[d]) * T0[d], tt += T0[d] * T0[d];
            ga0 = dt / tt;
        }
        wt[k][0] = be0, wt[k][1] = ga0, wt[k][2] = be2, wt[k][3] = ga2;
    }
    return 1;
}

void ccn__g1_rows(double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], int32_t nfan, int32_t nsp, const uint8_t *smooth,
                  const ccn__g1_weights *wt, ccn__g1_row *C, double *R) {
    static const double GL[NCOL] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
    int32_t row = 0;
    size_t ncol = (size_t)NQ * NQ * nfan;
    for (int32_t k = 0; k < nsp; k++) {
        if (!smooth[k]) continue;
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan;
        double be0 = wt[k][0], ga0 = wt[k][1], be2 = wt[k][2], ga2 = wt[k][3];
        for (int span = 0; span < 2; span++)
            for (int c = 0; c < NCOL; c++, row++) {
                double u = span + 0.5 * (GL[c] + 1), N[NQ], dN[NQ];
                ccn__g1_basis(KQ, PQ, NQ, u, N, dN, NULL);
                /* true derivatives: d/dv at v = 0 is 5 (x_i1 - x_i0) (first knot span 1), the
                 * spoke's d/du sum dN_i x_i0; the end values above have the same factors */
                double f = (1 - u / 2) * (1 - u / 2), be = be2 + (be0 - be2) * f, ga = (ga2 + (ga0 - ga2) * f) / 5;
                for (int i = 0; i < NQ; i++) {
                    /* D_k: x_a[i][1] - x_a[i][0]; D_{k-1}: x_b[1][i] - x_b[0][i], where x_b[0][i]
                     * is the spoke's x_a[i][0] (one unknown) */
                    struct { int32_t s, ii, jj; double c; } term[3] = {
                        {a, i, 1, N[i]}, {a, i, 0, -N[i] - be * N[i] - ga * dN[i]}, {b, 1, i, be * N[i]}};
                    for (int t = 0; t < 3; t++) {
                        int32_t v = idx[term[t].s][term[t].ii][term[t].jj];
                        if (v >= 0) C[row].v[C[row].n] = v, C[row].c[C[row].n++] = term[t].c;
                        if (!x) {
                            R[row * ncol + ((size_t)term[t].s * NQ + term[t].ii) * NQ + term[t].jj] -= term[t].c;
                            continue;
                        }
                        const double *val = x[term[t].s][term[t].ii][term[t].jj];
                        for (int d = 0; d < 3; d++) R[3 * (size_t)row + d] -= term[t].c * val[d];
                    }
                }
            }
    }
}

/* The thin-plate functional's entry for poles (i, j) and (i2, j2) of one sector (A: gram). */
double ccn__g1_plate(double A[3][NQ][NQ], int i, int j, int i2, int j2) {
    return A[2][i][i2] * A[0][j][j2] + 2 * A[1][i][i2] * A[1][j][j2] + A[0][i][i2] * A[2][j][j2];
}

/* The energy of x + delta (delta on the unknowns): the thin-plate functional over every filled
 * sector, sum over (i,j), (i',j') of x_ij x_i'j' (A2 A0 + 2 A1 A1 + A0 A2) = delta^T W delta +
 * 2 H^T delta + const, W += 1e-9 of its mean diagonal (definite). W dense (n x n) or, when NULL,
 * into the band b. */
void ccn__g1_thin_plate(double A[3][NQ][NQ], double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], const uint8_t *filled,
                        int32_t nfan, int32_t n, double *W, ccn__g1_band *b, double *H) {
    size_t ncol = (size_t)NQ * NQ * nfan;
    for (int32_t k = 0; k < nfan; k++) {
        if (!filled[k]) continue;
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = idx[k][i][j];
                if (v < 0) continue; /* also every pole of a sector without unknowns */
                for (int i2 = 0; i2 < NQ; i2++)
                    for (int j2 = 0; j2 < NQ; j2++) {
                        double e = ccn__g1_plate(A, i, j, i2, j2);
                        int32_t v2 = idx[k][i2][j2];
                        if (v2 >= 0) {
                            if (W) W[(size_t)v * n + v2] += e;
                            else ccn__g1_band_add(b, v, v2, e);
                        }
                        if (x)
                            for (int d = 0; d < 3; d++) H[3 * (size_t)v + d] += e * x[k][i2][j2][d];
                        else
                            H[v * ncol + ((size_t)k * NQ + i2) * NQ + j2] += e;
                    }
            }
    }
    double tr = 0;
    if (W) {
        for (int32_t i = 0; i < n; i++) tr += W[(size_t)i * n + i];
        for (int32_t i = 0; i < n; i++) W[(size_t)i * n + i] += 1e-9 * tr / n;
        return;
    }
    for (int32_t i = 0; i < b->nb; i++) tr += b->ab[(size_t)i * b->ld];
    for (int32_t i = 0; i < b->nd; i++) tr += b->D[(size_t)i * b->nd + i];
    for (int32_t i = 0; i < b->nb; i++) b->ab[(size_t)i * b->ld] += 1e-9 * tr / n;
    for (int32_t i = 0; i < b->nd; i++) b->D[(size_t)i * b->nd + i] += 1e-9 * tr / n;
}

/* The least-energy delta (n x nr) with C delta = R (m x nr): only the unknowns next to the smooth spokes
 * appear in C (the columns c); the others (f) are free. The SVD of C's columns c, C_c = U S V^T,
 * gives a particular solution dp = V1 S1^-1 U1^T R and the null space Z = V2 (singular values
 * below 1e-11 of the largest: the dependent rows); with delta_c = dp + Z^T y the energy's normal
 * equations in (y, delta_f), M = B^T W B with B = diag(Z^T, I), are solved by Cholesky, so the
 * SVD and the products stay the size of the spokes' neighbourhood. 1, 0 (no factorisation), -1
 * out of memory. */
int ccn__g1_least_energy(int32_t m, int32_t n, const double *C, const double *R, const double *W, const double *H,
                         double *del, int32_t nr) {
    int rc = -1;
    int32_t nc = 0, nf = 0, *col = malloc(sizeof(int32_t) * (size_t)n);
    double *Y = malloc(sizeof(double) * (size_t)n * n), *G = malloc(sizeof(double) * (size_t)n * n);
    double *U = malloc(sizeof(double) * (size_t)m * m), *VT = malloc(sizeof(double) * (size_t)n * n);
    double *sv = malloc(sizeof(double) * (size_t)(m + n)), *sup = malloc(sizeof(double) * (size_t)(m + n));
    double *dp = malloc(sizeof(double) * (size_t)nr * n), *g = malloc(sizeof(double) * (size_t)nr * n);
    double *ur = malloc(sizeof(double) * (size_t)nr);
    if (!col || !Y || !G || !U || !VT || !sv || !sup || !dp || !g || !ur) goto done;
    rc = 0;
    for (int32_t i = 0; i < n; i++) { /* c first, then f */
        int used = 0;
        for (int32_t r = 0; r < m && !used; r++) used = C[(size_t)r * n + i] != 0;
        if (used) col[nc++] = i;
    }
    for (int32_t i = 0, k = 0; i < n; i++) {
        if (k < nc && col[k] == i) { k++; continue; }
        col[nc + nf++] = i;
    }
    for (int32_t r = 0; r < m; r++) /* C_c */
        for (int32_t j = 0; j < nc; j++) Y[(size_t)r * nc + j] = C[(size_t)r * n + col[j]];
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', m, nc, Y, nc, sv, U, m, VT, nc, sup) != 0) goto done;
    int32_t rank = 0, mn = m < nc ? m : nc;
    while (rank < mn && sv[rank] > 1e-11 * sv[0]) rank++;
    int32_t nz = nc - rank, N = nz + nf;
    particular(U, VT, sv, rank, m, nc, R, dp, nr, ur);
    /* G (n x N) = W B, column by column (B's column z < nz: Z's row z on c; else the unit f) */
    for (int32_t i = 0; i < n; i++)
        for (int32_t z = 0; z < N; z++) {
            double acc = 0;
            if (z < nz)
                for (int32_t j = 0; j < nc; j++) acc += W[(size_t)i * n + col[j]] * VT[(size_t)(rank + z) * nc + j];
            else
                acc = W[(size_t)i * n + col[nc + z - nz]];
            G[(size_t)i * N + z] = acc;
        }
    /* M = B^T (W B) into Y (N x N), g = -B^T (W dp + H) */
    for (int32_t z = 0; z < N; z++) {
        for (int32_t z2 = 0; z2 < N; z2++) {
            double acc = 0;
            if (z < nz)
                for (int32_t j = 0; j < nc; j++) acc += VT[(size_t)(rank + z) * nc + j] * G[(size_t)col[j] * N + z2];
            else
                acc = G[(size_t)col[nc + z - nz] * N + z2];
            Y[(size_t)z * N + z2] = acc;
        }
        for (int32_t d = 0; d < nr; d++) {
            double acc = 0;
            for (int32_t j = 0; j < nc; j++) acc += G[(size_t)col[j] * N + z] * dp[(size_t)nr * j + d];
            if (z < nz)
                for (int32_t j = 0; j < nc; j++) acc += VT[(size_t)(rank + z) * nc + j] * H[(size_t)nr * col[j] + d];
            else
                acc += H[(size_t)nr * col[nc + z - nz] + d];
            g[(size_t)nr * z + d] = -acc;
        }
    }
    if (N > 0 && LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', N, nr, Y, N, g, nr) != 0) goto done;
    for (int32_t j = 0; j < nc; j++) /* delta on c: dp + Z^T y; on f: its own */
        for (int32_t d = 0; d < nr; d++) {
            double acc = dp[(size_t)nr * j + d];
            for (int32_t z = 0; z < nz; z++) acc += VT[(size_t)(rank + z) * nc + j] * g[(size_t)nr * z + d];
            del[(size_t)nr * col[j] + d] = acc;
        }
    for (int32_t j = 0; j < nf; j++)
        for (int32_t d = 0; d < nr; d++) del[(size_t)nr * col[nc + j] + d] = g[(size_t)nr * (nz + j) + d];
    rc = 1;
done:
    free(col); free(Y); free(G); free(U); free(VT); free(sv); free(sup); free(dp); free(g); free(ur);
    return rc;
}

