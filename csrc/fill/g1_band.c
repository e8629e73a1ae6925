/* The G1 fill's banded solve for many spokes (fill/g1_system.h), where the dense SVD's cost
 * (the cube of the unknowns) is out of reach. */
#include "fill/g1_band.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NQ CCN_FILL_G1_POLES

/* Adds e at (v, v2) of the symmetric matrix (called for both halves: keeps the lower one). */
void ccn__g1_band_add(ccn__g1_band *b, int32_t v, int32_t v2, double e) {
    int32_t i = b->perm[v], j = b->perm[v2];
    if (i < b->nb && j < b->nb) {
        if (i >= j) b->ab[(size_t)(i - j) + (size_t)j * b->ld] += e;
    } else if (i >= b->nb && j >= b->nb) {
        b->D[(size_t)(i - b->nb) * b->nd + (j - b->nb)] += e;
    } else if (j >= b->nb) {
        b->E[(size_t)(j - b->nb) * b->nb + i] += e;
    }
}


/* The band's order: sector 1, spoke 2, sector 2, ..., spoke N-1, sector N-1 (spoke k between
 * the sectors k-1 and k its rows couple), then as the border the poles that close the cycle:
 * sector 0's inner ones and spokes 0 and 1 (sector 0's energy couples them to each other); kd
 * the widest coupling (a sector with its spokes' poles, a G1 row's terms). 1, -1 out of
 * memory. */
int ccn__g1_band_setup(ccn__g1_band *b, int32_t (*idx)[NQ][NQ], int32_t nfan, int32_t n, const ccn__g1_row *C,
                       int32_t m) {
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

void ccn__g1_band_free(ccn__g1_band *b) {
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
int ccn__g1_least_energy_banded(int32_t m, int32_t n, const ccn__g1_row *C, const double *R, ccn__g1_band *b,
                                const double *H, double *del) {
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
            for (int32_t t2 = 0; t2 < C[r].n; t2++) ccn__g1_band_add(b, C[r].v[t], C[r].v[t2], rho * C[r].c[t] * C[r].c[t2]);
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

