/* The least-energy G1 quintic fill (fill/g1_fill.h).
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
 * energy is minimised over Z and the other unknowns by a Cholesky solve (fill/g1_system.c). Beyond
 * CCN_FILL_G1_DENSE_SPOKES spokes, where that costs the cube of the unknowns, the same minimiser
 * comes from the augmented Lagrangian on a banded factorisation (fill/g1_band.c; the
 * valence-64 fan 0.2 s, OpenSubdiv's pole360 within its export's 4.4 s). Measured (tests/c/test_export.c, the OpenSubdiv shapes): normals across the spokes
 * within 1e-12 to 4e-10 rad (what is left is the data's own consistency: the three tangent
 * vectors at the vertex and the C1 data at the far end are coplanar to 1e-9 of their size); the
 * fills' largest |K| below the bicubic ones' on boundary EVs
 * (mixed_boundary 6.96 -> 4.86, the corner fan there 9e5 -> 1.4e4), up to 1.9x above at
 * interior EVs with spoke ratios 8 to 22 where the bicubic fill was 6e-2 rad off G1.
 *
 * As an operator (ccn__g1_operator_*): with the weights fixed in advance the relations are
 * linear in the poles and so is the minimiser: delta = L x for every pole x of the raised data,
 * composed with the degree raising into L cs. The plan's caps beyond the bi-5 range take their
 * weights from the knot intervals alone (surface/fill_cap.c), so one operator serves every
 * evaluation and every vertex with the same spoke ratios. */
#include "fill/g1_fill.h"
#include "fill/g1_system.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double KQ[NQ + PQ + 1] = CCN_FILL_G1_KNOTS;

int ccn__fill_g1_solve(const double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                       const uint8_t *filled, const ccn__g1_weights *wt_in, double (*q)[NQ][NQ][3],
                       uint8_t *smooth, double *energy) {
    if (nfan < 1) return 0;
    double E[NQ][5], A[3][NQ][NQ];
    if (ccn__g1_raise_matrix(E)) return 0;
    ccn__g1_gram(A);
    int rc = -1;
    double (*x)[NQ][NQ][3] = malloc(sizeof *x * (size_t)nfan); /* raised, then the fairest G1 */
    int32_t (*idx)[NQ][NQ] = malloc(sizeof *idx * (size_t)nfan), nsm = 0;
    ccn__g1_weights *wt = malloc(sizeof *wt * (size_t)(nsp + 1));
    double *W = NULL, *Cd = NULL, *R = NULL, *H = NULL, *del = NULL;
    ccn__g1_row *C = NULL;
    ccn__g1_band bd = {0};
    memset(smooth, 0, (size_t)nsp + 1);
    if (!x || !idx || !wt) goto done;
    ccn__g1_raise(E, cs, filled, nfan, x);
    int32_t n = ccn__g1_unknowns(nfan, nsp, sharp, filled, smooth, idx, &nsm), m = 2 * NCOL * nsm;
    if (n < 0) goto done;
    rc = 0;
    if (!nsm) goto done;
    if (wt_in) memcpy(wt, wt_in, sizeof *wt * (size_t)nsp);
    else if (!ccn__g1_data_weights(x, nfan, nsp, smooth, wt)) goto done;
    rc = -1;
    C = calloc((size_t)m, sizeof *C);
    R = calloc((size_t)m * 3, sizeof(double));
    H = calloc((size_t)n * 3, sizeof(double));
    del = calloc((size_t)n * 3, sizeof(double));
    if (!C || !R || !H || !del) goto done;
    ccn__g1_rows(x, idx, nfan, nsp, smooth, (const ccn__g1_weights *)wt, C, R);
    if (nsp <= CCN_FILL_G1_DENSE_SPOKES) { /* dense: the SVD's exact null space */
        W = calloc((size_t)n * n, sizeof(double));
        Cd = calloc((size_t)m * n, sizeof(double));
        if (!W || !Cd) goto done;
        for (int32_t r = 0; r < m; r++)
            for (int32_t t = 0; t < C[r].n; t++) Cd[(size_t)r * n + C[r].v[t]] += C[r].c[t];
        ccn__g1_thin_plate(A, x, idx, filled, nfan, n, W, NULL, H);
        rc = ccn__g1_least_energy(m, n, Cd, R, W, H, del, 3);
    } else {
        rc = ccn__g1_band_setup(&bd, idx, nfan, n, C, m);
        if (rc < 0) goto done;
        ccn__g1_thin_plate(A, x, idx, filled, nfan, n, NULL, &bd, H);
        rc = ccn__g1_least_energy_banded(m, n, C, R, &bd, H, del);
    }
    if (rc <= 0) goto done;
    for (int32_t k = 0; k < nfan; k++) /* a shared spoke pole is one unknown: both sectors get it */
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = idx[k][i][j];
                if (v < 0) continue;
                for (int d = 0; d < 3; d++) x[k][i][j][d] += del[3 * (size_t)v + d];
            }
    double en = 0;
    for (int32_t k = 0; k < nfan; k++) /* the thin-plate energy of the result */
        for (int i = 0; i < NQ && filled[k]; i++)
            for (int j = 0; j < NQ; j++)
                for (int i2 = 0; i2 < NQ; i2++)
                    for (int j2 = 0; j2 < NQ; j2++) {
                        double e = ccn__g1_plate(A, i, j, i2, j2);
                        for (int d = 0; d < 3; d++) en += e * x[k][i][j][d] * x[k][i2][j2][d];
                    }
    *energy = en;
    memcpy(q, x, sizeof *x * (size_t)nfan);
done:
    ccn__g1_band_free(&bd);
    free(x);
    free(idx);
    free(wt);
    free(W);
    free(Cd);
    free(C);
    free(R);
    free(H);
    free(del);
    return rc;
}

int ccn__fill_g1_vertex_weights(const double a[3], const double b[3], const double t[3], double *beta,
                                double *gamma) {
    return ccn__g1_weights_of(a, b, t, beta, gamma);
}

/* ---- the operator ------------------------------------------------------------------- */

struct ccn__g1_operator {
    int32_t n, nvar;
    int32_t (*idx)[NQ][NQ]; /* the unknowns (ccn__g1_unknowns) */
    double *L;              /* nvar x 25 n: delta on the unknowns from cs[k][a][b] */
    double E[NQ][5];
};

void ccn__g1_operator_destroy(ccn__g1_operator *op) {
    if (!op) return;
    free(op->idx);
    free(op->L);
    free(op);
}

int ccn__g1_operator_create(int32_t n, const ccn__g1_weights *wt, ccn__g1_operator **out) {
    *out = NULL;
    if (n < 2 || n > CCN_FILL_G1_DENSE_SPOKES) return 0;
    ccn__g1_operator *op = calloc(1, sizeof *op);
    uint8_t *sharp = calloc((size_t)n + 1, 1), *filled = malloc((size_t)n + 1), *smooth = calloc((size_t)n + 1, 1);
    double A[3][NQ][NQ], *W = NULL, *Cd = NULL, *R = NULL, *H = NULL, *del = NULL;
    ccn__g1_row *C = NULL;
    int rc = -1;
    if (!op || !sharp || !filled || !smooth || !(op->idx = malloc(sizeof *op->idx * (size_t)n))) goto done;
    memset(filled, 1, (size_t)n + 1);
    op->n = n;
    rc = 0;
    if (ccn__g1_raise_matrix(op->E)) goto done;
    ccn__g1_gram(A);
    rc = -1;
    int32_t nsm = 0, nv = ccn__g1_unknowns(n, n, sharp, filled, smooth, op->idx, &nsm), m = 2 * NCOL * nsm;
    size_t ncol = (size_t)NQ * NQ * n;
    if (nv <= 0) goto done;
    op->nvar = nv;
    C = calloc((size_t)m, sizeof *C);
    R = calloc((size_t)m * ncol, sizeof(double));
    H = calloc((size_t)nv * ncol, sizeof(double));
    del = calloc((size_t)nv * ncol, sizeof(double));
    W = calloc((size_t)nv * nv, sizeof(double));
    Cd = calloc((size_t)m * nv, sizeof(double));
    op->L = calloc((size_t)nv * 25 * n, sizeof(double));
    if (!C || !R || !H || !del || !W || !Cd || !op->L) goto done;
    ccn__g1_rows(NULL, op->idx, n, n, smooth, wt, C, R);
    for (int32_t r = 0; r < m; r++)
        for (int32_t t = 0; t < C[r].n; t++) Cd[(size_t)r * nv + C[r].v[t]] += C[r].c[t];
    ccn__g1_thin_plate(A, NULL, op->idx, filled, n, nv, W, NULL, H);
    rc = ccn__g1_least_energy(m, nv, Cd, R, W, H, del, (int32_t)ncol);
    if (rc <= 0) goto done;
    /* L = del (E x E) per sector: the raising folded in */
    for (int32_t v = 0; v < nv; v++)
        for (int32_t k = 0; k < n; k++) {
            const double *dk = del + (size_t)v * ncol + (size_t)k * NQ * NQ;
            double *lk = op->L + (size_t)v * 25 * n + 25 * (size_t)k, t[NQ][5];
            for (int i = 0; i < NQ; i++)
                for (int b = 0; b < 5; b++) {
                    double s = 0;
                    for (int j = 0; j < NQ; j++) s += dk[NQ * i + j] * op->E[j][b];
                    t[i][b] = s;
                }
            for (int a = 0; a < 5; a++)
                for (int b = 0; b < 5; b++) {
                    double s = 0;
                    for (int i = 0; i < NQ; i++) s += op->E[i][a] * t[i][b];
                    lk[5 * a + b] = s;
                }
        }
done:
    free(sharp); free(filled); free(smooth); free(W); free(Cd); free(C); free(R); free(H); free(del);
    if (rc > 0) *out = op;
    else ccn__g1_operator_destroy(op);
    return rc;
}

void ccn__g1_operator_apply(const ccn__g1_operator *op, const double (*cs)[5][5][3], double (*q)[NQ][NQ][3]) {
    int32_t n = op->n;
    uint8_t filled[CCN_FILL_G1_DENSE_SPOKES + 1];
    memset(filled, 1, sizeof filled);
    double E[NQ][5];
    memcpy(E, op->E, sizeof E);
    ccn__g1_raise(E, cs, filled, n, q);
    const double *c = &cs[0][0][0][0];
    for (int32_t k = 0; k < n; k++)
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++) {
                int32_t v = op->idx[k][i][j];
                if (v < 0) continue;
                const double *l = op->L + (size_t)v * 25 * n;
                double s[3] = {0, 0, 0};
                for (int32_t e = 0; e < 25 * n; e++)
                    for (int d = 0; d < 3; d++) s[d] += l[e] * c[3 * (size_t)e + d];
                for (int d = 0; d < 3; d++) q[k][i][j][d] += s[d];
            }
}

/* ---- evaluation ------------------------------------------------------------------- */

void ccn__fill_g1_eval(const double q[NQ][NQ][3], double u, double v, double x[3], double du[3], double dv[3],
                       double (*d2)[3]) {
    double Nu[NQ], dNu[NQ], d2Nu[NQ], Nv[NQ], dNv[NQ], d2Nv[NQ];
    ccn__g1_basis(KQ, PQ, NQ, u, Nu, dNu, d2Nu);
    ccn__g1_basis(KQ, PQ, NQ, v, Nv, dNv, d2Nv);
    double r[6][3];
    memset(r, 0, sizeof r);
    for (int i = 0; i < NQ; i++)
        for (int j = 0; j < NQ; j++) {
            const double w[6] = {Nu[i] * Nv[j], dNu[i] * Nv[j], Nu[i] * dNv[j],
                                 d2Nu[i] * Nv[j], dNu[i] * dNv[j], Nu[i] * d2Nv[j]};
            for (int t = 0; t < 6; t++)
                for (int d = 0; d < 3; d++) r[t][d] += w[t] * q[i][j][d];
        }
    memcpy(x, r[0], sizeof r[0]);
    memcpy(du, r[1], sizeof r[1]);
    memcpy(dv, r[2], sizeof r[2]);
    if (d2) memcpy(d2, r[3], sizeof r[0] * 3);
}

/* Z[s] (6 x 9): the Bezier poles of span s of a curve from its 9 poles (collocation at 6
 * points of the span: the Bernstein system solved for the B-spline values). */
static int bezier_matrix(double Z[2][6][NQ]) {
    for (int s = 0; s < 2; s++) {
        double B[36], Nm[6 * NQ], dN[NQ];
        lapack_int ipiv[6];
        for (int r = 0; r < 6; r++) {
            double t = r / 5.0, bin[6] = {1, 5, 10, 10, 5, 1};
            for (int i = 0; i < 6; i++) B[6 * r + i] = bin[i] * pow(t, i) * pow(1 - t, 5 - i);
            ccn__g1_basis(KQ, PQ, NQ, s + t, Nm + NQ * r, dN, NULL);
        }
        if (LAPACKE_dgesv(LAPACK_ROW_MAJOR, 6, NQ, B, 6, ipiv, Nm, NQ) != 0) return -1;
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < NQ; j++) Z[s][i][j] = fabs(Nm[NQ * i + j]) < 1e-14 ? 0 : Nm[NQ * i + j];
    }
    return 0;
}

void ccn__fill_g1_bezier(const double q[NQ][NQ][3], double b[4][6][6][3]) {
    double Z[2][6][NQ], t[6][NQ][3];
    if (bezier_matrix(Z)) { memset(b, 0, sizeof(double) * 4 * 6 * 6 * 3); return; }
    for (int a = 0; a < 2; a++) {
        for (int i = 0; i < 6; i++) /* rows: span a along u */
            for (int j = 0; j < NQ; j++)
                for (int d = 0; d < 3; d++) {
                    double s = 0;
                    for (int p = 0; p < NQ; p++) s += Z[a][i][p] * q[p][j][d];
                    t[i][j][d] = s;
                }
        for (int c = 0; c < 2; c++)
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++)
                    for (int d = 0; d < 3; d++) {
                        double s = 0;
                        for (int p = 0; p < NQ; p++) s += Z[c][j][p] * t[i][p][d];
                        b[2 * a + c][i][j][d] = s;
                    }
    }
}
