/* Fill faces made exactly G1 across their smooth spokes (io/fill_g1.h).
 *
 * Why: a bicubic fill face has four free poles per sector once its outer two layers (the C1
 * join to the exact pieces), its spokes and the tangent plane at the vertex are fixed; the G1
 * relations along a spoke are more equations than that, so io/fill_faces.c meets them only
 * approximately (measured: up to 6e-2 rad at interior EVs with spoke ratios near 10, 4e-2 at
 * boundary EVs). Raised to degree 5 with a C2 knot in the middle (9 x 9 poles, the same
 * surface), a sector has 36 free inner poles and each smooth spoke 5, enough for the relations
 * of every spoke exactly.
 *
 * The relations (the classical linear G1 form of the vertex-enclosure analyses, Peters): along
 * spoke k, with D_k the cross-boundary derivative of sector k (its d/dv at v = 0), D_{k-1}
 * that of sector k-1 (its d/du at u = 0) and T the spoke's tangent,
 *     D_k(u) + beta(u) D_{k-1}(u) - gamma(u) T(u) = 0   for u in [0, 2].
 * The weights' end values come from the data: at u = 0 the three vectors lie in the limit
 * tangent plane (spokes k+1, k-1, k), at u = 2 the exact pieces beyond meet C1 (beta = the
 * parameter scale across, gamma ~ 0), each solved in least squares and checked (coplanar,
 * beta > 0: no fold). In between they are quadratic with zero slope at u = 2,
 * w(u) = w(2) + (w(0) - w(2)) (1 - u/2)^2: the u-derivative of the relation at u = 2 holds by
 * the exact C2 data only if the weights are flat there, and a kink anywhere (at the C2 knot 1)
 * would ask the cross derivative for a jump it cannot make; linear weights or ones bent at 1
 * leave 1e-6 to 3e-5 rad. The residual is then a degree-7 polynomial on each span, so it
 * vanishes identically when it vanishes at the 8 Gauss points of each span: those rows, linear
 * in the poles and the same for x, y and z, are the constraints C x = r.
 *
 * Among the solutions, the fairest: the least thin-plate energy sum over the sectors of
 * integral |S_uu|^2 + 2 |S_uv|^2 + |S_vv|^2 (exact Gram matrices of the basis' derivatives;
 * + 1e-9 of its trace, so that it is definite). The SVD of C's columns (the unknowns next to
 * the spokes) gives a particular solution and the null space Z (singular values below 1e-11 of
 * the largest: the rows are dependent, the relations hold at the span ends by the data and
 * around an interior vertex of even valence the twists' enclosure condition repeats); the
 * energy is minimised over Z and the other unknowns by a Cholesky solve (least_energy). Beyond
 * CCN_FILL_G1_DENSE_SPOKES spokes, where that costs the cube of the unknowns, the same minimiser
 * comes from the augmented Lagrangian on a banded factorisation (least_energy_banded; the
 * valence-64 fan 0.2 s, OpenSubdiv's pole360 within its export's 4.4 s). Measured (tests/c/test_export.c, the OpenSubdiv shapes): normals across the spokes
 * within 1e-12 to 4e-10 rad (what is left is the data's own consistency: the three tangent
 * vectors at the vertex and the C1 data at the far end are coplanar to 1e-9 of their size); the
 * fills' largest |K| below the bicubic ones' on boundary EVs
 * (mixed_boundary 6.96 -> 4.86, the corner fan there 9e5 -> 1.4e4), up to 1.9x above at
 * interior EVs with spoke ratios 8 to 22 where the bicubic fill was 6e-2 rad off G1. */
#include "io/fill_g1.h"

#include "io/cad.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NQ CCN_FILL_G1_POLES
#define PQ 5 /* degree */
#define NCOL 8 /* collocation points per span */

static const double KQ[NQ + PQ + 1] = CCN_FILL_G1_KNOTS;
static const double KC[9] = {0, 0, 0, 0, 1, 2, 2, 2, 2};

/* All n basis functions of degree p (>= 2) over flat knots t at u (the span with
 * t[s] <= u < t[s+1], the last one at the domain's end) and their first and second
 * derivatives (d2N may be NULL): N^(k)_{i,p} = p (N^(k-1)_{i,p-1} / (t_{i+p} - t_i)
 * - N^(k-1)_{i+1,p-1} / (t_{i+p+1} - t_{i+1})), 0/0 = 0. */
static double ratio(double a, double l) { return l > 0 ? a / l : 0; }
static void basis(const double *t, int p, int n, double u, double *N, double *dN, double *d2N) {
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
static void gram(double A[3][NQ][NQ]) {
    static const double X[6] = {-0.9324695142031521, -0.6612093864662645, -0.2386191860831969,
                                0.2386191860831969,  0.6612093864662645,  0.9324695142031521};
    static const double Wt[6] = {0.1713244923791704, 0.3607615730481386, 0.4679139345726910,
                                 0.4679139345726910, 0.3607615730481386, 0.1713244923791704};
    memset(A, 0, sizeof(double) * 3 * NQ * NQ);
    for (int span = 0; span < 2; span++)
        for (int g = 0; g < 6; g++) {
            double u = span + 0.5 * (X[g] + 1), w = 0.5 * Wt[g], B[3][NQ];
            basis(KQ, PQ, NQ, u, B[0], B[1], B[2]);
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < NQ; i++)
                    for (int j = 0; j < NQ; j++) A[k][i][j] += w * B[k][i] * B[k][j];
        }
}

/* E (9 x 5): the quintic poles of each cubic B-spline (degree raising, exact: the cubic with
 * a simple knot at 1 is C2 there, the quintic with a triple one too), by collocation at the
 * quintic's Greville abscissae; the end rows exactly the unit ones so that spokes stay
 * bit-identical. */
static int raise_matrix(double E[NQ][5]) {
    double A[NQ * NQ], B[NQ * 5], dN[NQ], Nc[5], dNc[5];
    lapack_int ipiv[NQ];
    for (int r = 0; r < NQ; r++) {
        double g = 0;
        for (int k = 1; k <= PQ; k++) g += KQ[r + k];
        g /= PQ;
        basis(KQ, PQ, NQ, g, A + NQ * r, dN, NULL);
        basis(KC, 3, 5, g, Nc, dNc, NULL);
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
static int weights(const double *Da, const double *Db, const double *T, double *beta, double *gamma) {
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

static double angle_between(const double *a, const double *b) {
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

double ccn__fill_spoke_angle(const double *poles, int32_t deg, const int32_t mu[3], int32_t nfan, int32_t nsp,
                             const uint8_t *smooth, int samples) {
    static const double kn[3] = {0, 1, 2};
    int32_t np = mu[0] + mu[1] + mu[2] - deg - 1; /* poles per direction */
    double worst = 0;
    for (int32_t k = 0; k < nsp; k++) {
        if (!smooth[k]) continue;
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan; /* spoke k: u-axis of a, v-axis of b */
        ccn__cad_surface A = {{deg, deg}, {np, np}, {3, 3}, {kn, kn}, {mu, mu}, poles + 3 * (size_t)np * np * a, {0, 0}};
        ccn__cad_surface B = A;
        B.poles = poles + 3 * (size_t)np * np * b;
        for (int i = 0; i < samples; i++) {
            double t = 2.0 * (i + 0.5) / samples, p[3], du[3], dv[3], na[3], nb[3];
            ccn__cad_eval_d(&A, t, 0, p, du, dv);
            na[0] = du[1] * dv[2] - du[2] * dv[1], na[1] = du[2] * dv[0] - du[0] * dv[2], na[2] = du[0] * dv[1] - du[1] * dv[0];
            ccn__cad_eval_d(&B, 0, t, p, du, dv);
            nb[0] = du[1] * dv[2] - du[2] * dv[1], nb[1] = du[2] * dv[0] - du[0] * dv[2], nb[2] = du[0] * dv[1] - du[1] * dv[0];
            double ang = angle_between(na, nb);
            if (!(ang <= worst)) worst = ang;
        }
    }
    return worst;
}

/* out (n x 3) = V1 S1^-1 U1^T rhs (m x 3): the least-norm solution of C x = rhs on C's first
 * `rank` singular triplets (C = U S V^T, row-major U m x m, VT n x n). */
static void particular(const double *U, const double *VT, const double *sv, int32_t rank, int32_t m, int32_t n,
                       const double *rhs, double *out) {
    memset(out, 0, sizeof(double) * 3 * (size_t)n);
    for (int32_t r = 0; r < rank; r++) {
        double ur[3] = {0, 0, 0};
        for (int32_t q = 0; q < m; q++)
            for (int d = 0; d < 3; d++) ur[d] += U[(size_t)q * m + r] * rhs[3 * (size_t)q + d];
        for (int32_t i = 0; i < n; i++)
            for (int d = 0; d < 3; d++) out[3 * (size_t)i + d] += VT[(size_t)r * n + i] * ur[d] / sv[r];
    }
}

/* x = E c E^T per filled sector: the bicubic fills degree-raised, rows first (spokes stay
 * bit-identical: E's first row is the unit one). */
static void raise_fills(double E[NQ][5], const double (*cs)[5][5][3], const uint8_t *filled, int32_t nfan,
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
static int32_t number_unknowns(int32_t nfan, int32_t nsp, const uint8_t *sharp, const uint8_t *filled,
                               uint8_t *smooth, int32_t (*idx)[NQ][NQ], int32_t *nsm) {
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

/* The G1 rows C delta = R (2 NCOL rows per smooth spoke, each with at most 3 NQ terms) at x; 0
 * when a spoke's end data admits no weights. Sector a = k (spoke k is its u-axis), b = k - 1
 * (its v-axis). */
typedef struct { int32_t n, v[3 * NQ]; double c[3 * NQ]; } g1_row; /* sum_t c[t] delta[v[t]] */

static int g1_rows(double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], int32_t nfan, int32_t nsp, const uint8_t *smooth,
                   g1_row *C, double *R) {
    static const double GL[NCOL] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
    int32_t row = 0;
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
        if (!weights(Da2, Db2, T2, &be2, &ga2)) return 0;
        if (!weights(Da0, Db0, T0, &be0, &ga0)) { /* a valence-2 vertex: the three on one line */
            if (!along(Da0, T0) || !along(Db0, T0)) return 0;
            double dt = 0, tt = 0;
            be0 = be2; /* any beta holds there: the far end's */
            for (int d = 0; d < 3; d++) dt += (Da0[d] + be0 * Db0[d]) * T0[d], tt += T0[d] * T0[d];
            ga0 = dt / tt;
        }
        for (int span = 0; span < 2; span++)
            for (int c = 0; c < NCOL; c++, row++) {
                double u = span + 0.5 * (GL[c] + 1), N[NQ], dN[NQ];
                basis(KQ, PQ, NQ, u, N, dN, NULL);
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
                        const double *val = x[term[t].s][term[t].ii][term[t].jj];
                        if (v >= 0) C[row].v[C[row].n] = v, C[row].c[C[row].n++] = term[t].c;
                        for (int d = 0; d < 3; d++) R[3 * (size_t)row + d] -= term[t].c * val[d];
                    }
                }
            }
    }
    return 1;
}

/* The thin-plate functional's entry for poles (i, j) and (i2, j2) of one sector (A: gram). */
static double plate(double A[3][NQ][NQ], int i, int j, int i2, int j2) {
    return A[2][i][i2] * A[0][j][j2] + 2 * A[1][i][i2] * A[1][j][j2] + A[0][i][i2] * A[2][j][j2];
}

/* The system of the banded solve (many spokes): the unknowns permuted (perm) along the fan, so
 * that all but the border -- the poles that close the cycle -- lie in a band of half-width kd (lower band storage, column-major, for dpbtrf); E (nb x nd, column-major) the
 * band's coupling to the border, D (nd x nd) the border's own block. */
typedef struct {
    int32_t n, nb, nd, kd, ld;
    int32_t *perm;
    double *ab, *E, *D;
} band;

/* Adds e at (v, v2) of the symmetric matrix (called for both halves: keeps the lower one). */
static void band_add(band *b, int32_t v, int32_t v2, double e) {
    int32_t i = b->perm[v], j = b->perm[v2];
    if (i < b->nb && j < b->nb) {
        if (i >= j) b->ab[(size_t)(i - j) + (size_t)j * b->ld] += e;
    } else if (i >= b->nb && j >= b->nb) {
        b->D[(size_t)(i - b->nb) * b->nd + (j - b->nb)] += e;
    } else if (j >= b->nb) {
        b->E[(size_t)(j - b->nb) * b->nb + i] += e;
    }
}

/* The energy of x + delta (delta on the unknowns): the thin-plate functional over every filled
 * sector, sum over (i,j), (i',j') of x_ij x_i'j' (A2 A0 + 2 A1 A1 + A0 A2) = delta^T W delta +
 * 2 H^T delta + const, W += 1e-9 of its mean diagonal (definite). W dense (n x n) or, when NULL,
 * into the band b. */
static void thin_plate(double A[3][NQ][NQ], double (*x)[NQ][NQ][3], int32_t (*idx)[NQ][NQ], const uint8_t *filled,
                       int32_t nfan, int32_t n, double *W, band *b, double *H) {
    for (int32_t k = 0; k < nfan; k++) {
        if (!filled[k]) continue;
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = idx[k][i][j];
                if (v < 0) continue; /* also every pole of a sector without unknowns */
                for (int i2 = 0; i2 < NQ; i2++)
                    for (int j2 = 0; j2 < NQ; j2++) {
                        double e = plate(A, i, j, i2, j2);
                        int32_t v2 = idx[k][i2][j2];
                        if (v2 >= 0) {
                            if (W) W[(size_t)v * n + v2] += e;
                            else band_add(b, v, v2, e);
                        }
                        for (int d = 0; d < 3; d++) H[3 * (size_t)v + d] += e * x[k][i2][j2][d];
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

/* The least-energy delta (n x 3) with C delta = R: only the unknowns next to the smooth spokes
 * appear in C (the columns c); the others (f) are free. The SVD of C's columns c, C_c = U S V^T,
 * gives a particular solution dp = V1 S1^-1 U1^T R and the null space Z = V2 (singular values
 * below 1e-11 of the largest: the dependent rows); with delta_c = dp + Z^T y the energy's normal
 * equations in (y, delta_f), M = B^T W B with B = diag(Z^T, I), are solved by Cholesky, so the
 * SVD and the products stay the size of the spokes' neighbourhood. 1, 0 (no factorisation), -1
 * out of memory. */
static int least_energy(int32_t m, int32_t n, const double *C, const double *R, const double *W, const double *H,
                        double *del) {
    int rc = -1;
    int32_t nc = 0, nf = 0, *col = malloc(sizeof(int32_t) * (size_t)n);
    double *Y = malloc(sizeof(double) * (size_t)n * n), *G = malloc(sizeof(double) * (size_t)n * n);
    double *U = malloc(sizeof(double) * (size_t)m * m), *VT = malloc(sizeof(double) * (size_t)n * n);
    double *sv = malloc(sizeof(double) * (size_t)(m + n)), *sup = malloc(sizeof(double) * (size_t)(m + n));
    double *dp = malloc(sizeof(double) * 3 * (size_t)n), *g = malloc(sizeof(double) * 3 * (size_t)n);
    if (!col || !Y || !G || !U || !VT || !sv || !sup || !dp || !g) goto done;
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
    particular(U, VT, sv, rank, m, nc, R, dp);
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
        for (int d = 0; d < 3; d++) {
            double acc = 0;
            for (int32_t j = 0; j < nc; j++) acc += G[(size_t)col[j] * N + z] * dp[3 * (size_t)j + d];
            if (z < nz)
                for (int32_t j = 0; j < nc; j++) acc += VT[(size_t)(rank + z) * nc + j] * H[3 * (size_t)col[j] + d];
            else
                acc += H[3 * (size_t)col[nc + z - nz] + d];
            g[3 * (size_t)z + d] = -acc;
        }
    }
    if (N > 0 && LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', N, 3, Y, N, g, 3) != 0) goto done;
    for (int32_t j = 0; j < nc; j++) /* delta on c: dp + Z^T y; on f: its own */
        for (int d = 0; d < 3; d++) {
            double acc = dp[3 * (size_t)j + d];
            for (int32_t z = 0; z < nz; z++) acc += VT[(size_t)(rank + z) * nc + j] * g[3 * (size_t)z + d];
            del[3 * (size_t)col[j] + d] = acc;
        }
    for (int32_t j = 0; j < nf; j++)
        for (int d = 0; d < 3; d++) del[3 * (size_t)col[nc + j] + d] = g[3 * (size_t)(nz + j) + d];
    rc = 1;
done:
    free(col); free(Y); free(G); free(U); free(VT); free(sv); free(sup); free(dp); free(g);
    return rc;
}

/* ---- many spokes: the banded solve ------------------------------------------------------ */

/* The band's order: sector 1, spoke 2, sector 2, ..., spoke N-1, sector N-1 (spoke k between
 * the sectors k-1 and k its rows couple), then as the border the poles that close the cycle:
 * sector 0's inner ones and spokes 0 and 1 (sector 0's energy couples them to each other); kd
 * the widest coupling (a sector with its spokes' poles, a G1 row's terms). 1, -1 out of
 * memory. */
static int band_setup(band *b, int32_t (*idx)[NQ][NQ], int32_t nfan, int32_t n, const g1_row *C, int32_t m) {
    int32_t *key = malloc(sizeof(int32_t) * (size_t)n), *cnt = calloc(2 * (size_t)nfan + 3, sizeof(int32_t));
    b->perm = malloc(sizeof(int32_t) * (size_t)n);
    if (!key || !cnt || !b->perm) { free(key); free(cnt); return -1; }
    const int32_t border = 2 * nfan + 1; /* keys: spoke k 2k, sector k 2k + 1, then the border */
    for (int32_t v = 0; v < n; v++) key[v] = -1;
    for (int32_t k = 0; k < nfan; k++)
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = idx[k][i][j], sk = j == 0 ? k : i == 0 ? (k + 1) % nfan : -1; /* spoke or -1 */
                if (v < 0) continue;
                key[v] = sk >= 2 ? 2 * sk : sk >= 0 || k == 0 ? border : 2 * k + 1;
            }
    /* numbers no pole takes (a sector's cross-derivative row along a sharp spoke stays fixed,
     * number_unknowns skips it): next to the following number */
    for (int32_t v = n - 1; v >= 0; v--)
        if (key[v] < 0) key[v] = v + 1 < n && key[v + 1] >= 0 ? key[v + 1] : border;
    for (int32_t v = 0; v < n; v++) cnt[key[v] + 1]++;
    for (int32_t q = 1; q < border + 2; q++) cnt[q] += cnt[q - 1];
    b->n = n, b->nb = cnt[border], b->nd = n - b->nb;
    for (int32_t v = 0; v < n; v++) b->perm[v] = cnt[key[v]]++;
    int32_t kd = 0;
    for (int32_t k = 0; k < nfan; k++) {
        int32_t lo = n, hi = -1;
        for (int p = 0; p < NQ * NQ; p++) {
            int32_t v = idx[k][p / NQ][p % NQ], q = v >= 0 ? b->perm[v] : -1;
            if (q >= 0 && q < b->nb) lo = q < lo ? q : lo, hi = q > hi ? q : hi;
        }
        if (hi - lo > kd) kd = hi - lo;
    }
    for (int32_t r = 0; r < m; r++) {
        int32_t lo = n, hi = -1;
        for (int32_t t = 0; t < C[r].n; t++) {
            int32_t q = b->perm[C[r].v[t]];
            if (q < b->nb) lo = q < lo ? q : lo, hi = q > hi ? q : hi;
        }
        if (hi - lo > kd) kd = hi - lo;
    }
    b->kd = kd, b->ld = kd + 1;
    b->ab = calloc((size_t)b->ld * (b->nb ? b->nb : 1), sizeof(double));
    b->E = calloc((size_t)b->nb * b->nd + 1, sizeof(double));
    b->D = calloc((size_t)b->nd * b->nd + 1, sizeof(double));
    free(key);
    free(cnt);
    return b->ab && b->E && b->D ? 1 : -1;
}

static void band_free(band *b) {
    free(b->perm);
    free(b->ab);
    free(b->E);
    free(b->D);
}

/* The least-energy delta with C delta = R for many spokes, where the dense SVD's cost (the cube
 * of the unknowns) is out of reach: the augmented Lagrangian (the method of multipliers),
 *     (W + rho C^T C) delta_t = -H + C^T (rho R - mu_t),   mu_{t+1} = mu_t + rho (C delta_t - R),
 * whose iterates tend to the constrained minimiser whatever rho and whether or not C's rows are
 * dependent (a dependent row's multiplier drifts along C's left null space, which C^T maps to
 * 0). The matrix is factored once: banded Cholesky (dpbtrf) of the band and the border's Schur
 * complement S = D - E^T B^-1 E (dpotrf), so a pass costs the band's back substitution.
 * rho = CCN__G1_RHO x W's mean diagonal over C^T C's: a row direction of singular value s
 * converges by the factor 1 / (1 + rho s^2 / lambda) per pass, so rho must be large where rows
 * are nearly dependent (measured with every fill solved this way: rho 1e6 leaves 1e-6 rad on the
 * Fig. 16-18 fills, 1e9 up to 2e-7, 1e11 and 1e12 1e-12 to 1e-9 in 3-12 passes; the poles then
 * differ from the dense solve's by up to 1e-5 of the model along directions the energy hardly
 * sees). The passes stop when the largest row residual has not fallen for three of them.
 * 1, 0 (no factorisation), -1 out of memory. */
#define CCN__G1_RHO 1e11
#define CCN__G1_PASSES 200
static int least_energy_banded(int32_t m, int32_t n, const g1_row *C, const double *R, band *b, const double *H,
                               double *del) {
    int32_t nb = b->nb, nd = b->nd, ld = b->ld, kd = b->kd;
    double wd = 0, cd = 0;
    for (int32_t i = 0; i < nb; i++) wd += b->ab[(size_t)i * ld];
    for (int32_t i = 0; i < nd; i++) wd += b->D[(size_t)i * nd + i];
    for (int32_t r = 0; r < m; r++)
        for (int32_t t = 0; t < C[r].n; t++) cd += C[r].c[t] * C[r].c[t];
    if (!(wd > 0) || !(cd > 0)) return 0;
    double rho = CCN__G1_RHO * wd / cd;
    for (int32_t r = 0; r < m; r++)
        for (int32_t t = 0; t < C[r].n; t++)
            for (int32_t t2 = 0; t2 < C[r].n; t2++) band_add(b, C[r].v[t], C[r].v[t2], rho * C[r].c[t] * C[r].c[t2]);
    int rc = -1;
    double *Y = malloc(sizeof(double) * ((size_t)nb * nd + 1)), *S = malloc(sizeof(double) * ((size_t)nd * nd + 1));
    double *mu = calloc(3 * (size_t)m, sizeof(double)), *rhs = malloc(sizeof(double) * 3 * (size_t)n);
    double *buf = malloc(sizeof(double) * 3 * (size_t)n), *res = malloc(sizeof(double) * 3 * (size_t)m);
    if (!Y || !S || !mu || !rhs || !buf || !res) goto done;
    rc = 0;
    if (nb && LAPACKE_dpbtrf(LAPACK_COL_MAJOR, 'L', nb, kd, b->ab, ld) != 0) goto done;
    if (nd) {
        memcpy(Y, b->E, sizeof(double) * (size_t)nb * nd);
        if (nb && LAPACKE_dpbtrs(LAPACK_COL_MAJOR, 'L', nb, kd, nd, b->ab, ld, Y, nb) != 0) goto done;
        for (int32_t i = 0; i < nd; i++)
            for (int32_t j = 0; j < nd; j++) {
                double acc = b->D[(size_t)i * nd + j];
                for (int32_t l = 0; l < nb; l++) acc -= b->E[(size_t)i * nb + l] * Y[(size_t)j * nb + l];
                S[(size_t)j * nd + i] = acc;
            }
        if (LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', nd, S, nd) != 0) goto done;
    }
    double best = INFINITY;
    for (int pass = 0, stall = 0; pass < CCN__G1_PASSES && stall < 3; pass++) {
        for (int32_t v = 0; v < n; v++)
            for (int d = 0; d < 3; d++) rhs[3 * (size_t)v + d] = -H[3 * (size_t)v + d];
        for (int32_t r = 0; r < m; r++)
            for (int32_t t = 0; t < C[r].n; t++)
                for (int d = 0; d < 3; d++)
                    rhs[3 * (size_t)C[r].v[t] + d] += C[r].c[t] * (rho * R[3 * (size_t)r + d] - mu[3 * (size_t)r + d]);
        for (int32_t v = 0; v < n; v++)
            for (int d = 0; d < 3; d++) buf[(size_t)d * n + b->perm[v]] = rhs[3 * (size_t)v + d];
        if (nb && LAPACKE_dpbtrs(LAPACK_COL_MAJOR, 'L', nb, kd, 3, b->ab, ld, buf, n) != 0) break;
        if (nd) { /* the border: z = S^-1 (g - E^T y), then y -= Y z */
            for (int d = 0; d < 3; d++)
                for (int32_t i = 0; i < nd; i++) {
                    double acc = buf[(size_t)d * n + nb + i];
                    for (int32_t l = 0; l < nb; l++) acc -= b->E[(size_t)i * nb + l] * buf[(size_t)d * n + l];
                    buf[(size_t)d * n + nb + i] = acc;
                }
            if (LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', nd, 3, S, nd, buf + nb, n) != 0) break;
            for (int d = 0; d < 3; d++)
                for (int32_t l = 0; l < nb; l++) {
                    double acc = 0;
                    for (int32_t i = 0; i < nd; i++) acc += Y[(size_t)i * nb + l] * buf[(size_t)d * n + nb + i];
                    buf[(size_t)d * n + l] -= acc;
                }
        }
        double worst = 0;
        for (int32_t r = 0; r < m; r++)
            for (int d = 0; d < 3; d++) {
                double acc = -R[3 * (size_t)r + d];
                for (int32_t t = 0; t < C[r].n; t++) acc += C[r].c[t] * buf[(size_t)d * n + b->perm[C[r].v[t]]];
                res[3 * (size_t)r + d] = acc;
                if (!(fabs(acc) <= worst)) worst = fabs(acc);
            }
        if (worst < best) {
            stall = worst < 0.9 * best ? 0 : stall + 1;
            best = worst;
            for (int32_t v = 0; v < n; v++)
                for (int d = 0; d < 3; d++) del[3 * (size_t)v + d] = buf[(size_t)d * n + b->perm[v]];
            rc = 1;
        } else {
            stall++;
        }
        for (int32_t q = 0; q < 3 * m; q++) mu[q] += rho * res[q];
    }
done:
    free(Y); free(S); free(mu); free(rhs); free(buf); free(res);
    return rc;
}

int ccn__fill_g1(const double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                 const uint8_t *filled, double (*q)[NQ][NQ][3], double *dev, double *energy) {
    if (nfan < 1) return 0;
    double E[NQ][5], A[3][NQ][NQ];
    if (raise_matrix(E)) return 0;
    gram(A);
    int rc = -1;
    double (*x)[NQ][NQ][3] = malloc(sizeof *x * (size_t)nfan); /* raised, then the fairest G1 */
    int32_t (*idx)[NQ][NQ] = malloc(sizeof *idx * (size_t)nfan), nsm = 0;
    uint8_t *smooth = calloc((size_t)nsp + 1, 1);
    double *W = NULL, *Cd = NULL, *R = NULL, *H = NULL, *del = NULL;
    g1_row *C = NULL;
    band bd = {0};
    if (!x || !idx || !smooth) goto done;
    raise_fills(E, cs, filled, nfan, x);
    int32_t n = number_unknowns(nfan, nsp, sharp, filled, smooth, idx, &nsm), m = 2 * NCOL * nsm;
    if (n < 0) goto done;
    rc = 0;
    if (!nsm) goto done;
    rc = -1;
    C = calloc((size_t)m, sizeof *C);
    R = calloc((size_t)m * 3, sizeof(double));
    H = calloc((size_t)n * 3, sizeof(double));
    del = calloc((size_t)n * 3, sizeof(double));
    if (!C || !R || !H || !del) goto done;
    rc = 0;
    if (!g1_rows(x, idx, nfan, nsp, smooth, C, R)) goto done;
    if (nsp <= CCN_FILL_G1_DENSE_SPOKES) { /* dense: the SVD's exact null space */
        rc = -1;
        W = calloc((size_t)n * n, sizeof(double));
        Cd = calloc((size_t)m * n, sizeof(double));
        if (!W || !Cd) goto done;
        for (int32_t r = 0; r < m; r++)
            for (int32_t t = 0; t < C[r].n; t++) Cd[(size_t)r * n + C[r].v[t]] += C[r].c[t];
        thin_plate(A, x, idx, filled, nfan, n, W, NULL, H);
        rc = least_energy(m, n, Cd, R, W, H, del);
    } else {
        rc = band_setup(&bd, idx, nfan, n, C, m);
        if (rc < 0) goto done;
        thin_plate(A, x, idx, filled, nfan, n, NULL, &bd, H);
        rc = least_energy_banded(m, n, C, R, &bd, H, del);
    }
    if (rc <= 0) goto done;
    for (int32_t k = 0; k < nfan; k++) /* a shared spoke pole is one unknown: both sectors get it */
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = idx[k][i][j];
                if (v < 0) continue;
                for (int d = 0; d < 3; d++) x[k][i][j][d] += del[3 * (size_t)v + d];
            }
    static const int32_t MU[3] = {6, 3, 6};
    *dev = ccn__fill_spoke_angle(&x[0][0][0][0], PQ, MU, nfan, nsp, smooth, 16);
    double en = 0;
    for (int32_t k = 0; k < nfan; k++) /* the thin-plate energy of the result */
        for (int i = 0; i < NQ && filled[k]; i++)
            for (int j = 0; j < NQ; j++)
                for (int i2 = 0; i2 < NQ; i2++)
                    for (int j2 = 0; j2 < NQ; j2++) {
                        double e = plate(A, i, j, i2, j2);
                        for (int d = 0; d < 3; d++) en += e * x[k][i][j][d] * x[k][i2][j2][d];
                    }
    *energy = en;
    memcpy(q, x, sizeof *x * (size_t)nfan);
done:
    band_free(&bd);
    free(x);
    free(idx);
    free(smooth);
    free(W);
    free(Cd);
    free(C);
    free(R);
    free(H);
    free(del);
    return rc;
}
