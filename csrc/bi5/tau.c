/* The planar reparameterisation tau of the central G1 cap (paper Sec. 6; SPEC §6.2, [R4]):
 * minimum F_5 energy under the G1 constraints, symmetric or (non-uniform, [R11]) one tau per
 * sector; and the G1 residual form shared with the cap assembly (bi5/cap.c). */
#include "bi5/tau.h"

#include "base/error.h"
#include "bi5/bernstein.h"
#include "bi5/rings.h"

#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

/* ---- G1 form ------------------------------------------------------------------------- */

/* BB coefficients (degree 7) of  alpha(t) d_u f^s(0,t) + d_v f^{s+1}(t,0) - gamma(t) d_t f^{s+1}(t,0)
 * with alpha = (1, k, k), beta = (1,1,1), gamma = (2c, 0, 0) in degree-2 BB form ([R9]; k = 1 is
 * eq. (9) corrected, SPEC §6.1, degree-raised by one). fs, fs1: bi-5 patches [i*6+j]. */
void ccn__bi5_g1_res(const double complex *fs, const double complex *fs1, double c, double k,
                     double complex R[8]) {
    double complex U[6], V[6], D[5], Q[7];
    const double al[3] = {1.0, k, k}, ga[3] = {2.0 * c, 0.0, 0.0};
    for (int32_t q = 0; q < 6; q++) {
        U[q] = 5.0 * (fs[6 + q] - fs[q]);
        V[q] = 5.0 * (fs1[q * 6 + 1] - fs1[q * 6]);
        if (q < 5) D[q] = 5.0 * (fs1[(q + 1) * 6] - fs1[q * 6]);
    }
    for (int32_t q = 0; q <= 6; q++) { /* gamma * D, degree 6 */
        Q[q] = 0;
        for (int32_t i = 0; i <= 2; i++)
            if (q - i >= 0 && q - i <= 4)
                Q[q] += ccn__bi5_binom(2, i) * ccn__bi5_binom(4, q - i) / ccn__bi5_binom(6, q) * ga[i] * D[q - i];
    }
    for (int32_t q = 0; q <= 7; q++) {
        double complex acc = 0;
        for (int32_t i = 0; i <= 2; i++)
            if (q - i >= 0 && q - i <= 5)
                acc += ccn__bi5_binom(2, i) * ccn__bi5_binom(5, q - i) / ccn__bi5_binom(7, q)
                       * (al[i] * U[q - i] + V[q - i]);
        acc -= (q >= 1 ? q / 7.0 * Q[q - 1] : 0.0) + (q <= 6 ? (7 - q) / 7.0 * Q[q] : 0.0);
        R[q] = acc;
    }
}

/* ---- F_5 energy (SPEC §6.2) ------------------------------------------------------------ */

static double bern_deriv(int32_t d, int32_t k, double t, int32_t order) {
    double f = 1.0, acc = 0.0;
    for (int32_t q = 0; q < order; q++) f *= (double)(d - q);
    for (int32_t q = 0; q <= order; q++)
        acc += (((order - q) & 1) ? -1.0 : 1.0) * ccn__bi5_binom(order, q) * ccn__bi5_bern(d - order, k - q, t);
    return f * acc;
}

#define F5_ROWS (6 * 36 * 2)

/* The 6x6 Gauss-Legendre rule on [0,1]^2 of f5_vec, tabulated once per tau solve (f5_vec runs
 * 30 + ns times on the same nodes): D[a][p][k] = d^a/dx^a B^5_k at node p, and the row weights
 * sqrt(C(5,i) w_pa w_pb). Computed by the same expressions as before tabulation, so F_5 is
 * bit-identical (the pow calls were 76 % of a non-uniform plan). */
typedef struct {
    double D[6][6][6];
    double sw[6][6][6];
} f5_table;

static void f5_table_init(f5_table *T) {
    static const double gx[6] = {-0.9324695142031521, -0.6612093864662645, -0.2386191860831969,
                                 0.2386191860831969, 0.6612093864662645, 0.9324695142031521};
    static const double gw[6] = {0.1713244923791704, 0.3607615730481386, 0.4679139345726910,
                                 0.4679139345726910, 0.3607615730481386, 0.1713244923791704};
    for (int32_t a = 0; a <= 5; a++)
        for (int32_t p = 0; p < 6; p++)
            for (int32_t k = 0; k < 6; k++) T->D[a][p][k] = bern_deriv(5, k, 0.5 * (gx[p] + 1), a);
    for (int32_t i = 0; i <= 5; i++)
        for (int32_t pa = 0; pa < 6; pa++)
            for (int32_t pb = 0; pb < 6; pb++)
                T->sw[i][pa][pb] = sqrt(ccn__bi5_binom(5, i) * (0.25 * gw[pa] * gw[pb]));
}

/* Weighted samples whose squared sum is F_5(tau) = int sum_{i+j=5} C(5,i) |d_u^i d_v^j tau|^2
 * (6x6 Gauss-Legendre, exact for these degrees). */
static void f5_vec(const f5_table *T, const double complex *t, double out[F5_ROWS]) {
    int32_t r = 0;
    for (int32_t i = 0; i <= 5; i++)
        for (int32_t pa = 0; pa < 6; pa++)
            for (int32_t pb = 0; pb < 6; pb++) {
                const double *bu = T->D[i][pa], *bv = T->D[5 - i][pb];
                double complex acc = 0;
                for (int32_t k = 0; k < 6; k++)
                    for (int32_t l = 0; l < 6; l++) acc += bu[k] * bv[l] * t[k * 6 + l];
                acc *= T->sw[i][pa][pb];
                out[r++] = creal(acc);
                out[r++] = cimag(acc);
            }
}

/* ---- constrained least squares --------------------------------------------------------- */

/* Null space and particular solution of A y = b (A: na x ny column-major, redundant rows
 * allowed) by pivoted QR of A^T = Q R P^T: rank r from |R_ii|; y = Q_r R_r^-T (P^T b)_r,
 * null space = Q[:, r:] (Q returned in Q, ny x ny column-major). */
static ccn_status null_space(int32_t na, int32_t ny, const double *A, const double *b, double *Q,
                             double *y, int32_t *rank_out, ccn_error *err) {
    int32_t k = na < ny ? na : ny, rank = 0;
    lapack_int *jpvt = calloc((size_t)na, sizeof(lapack_int));
    double *At = malloc(sizeof(double) * (size_t)ny * (size_t)(na > ny ? na : ny)), *tq = malloc(sizeof(double) * (size_t)ny);
    double *z = malloc(sizeof(double) * (size_t)ny);
    ccn_status st = CCN_OK;
    if (!jpvt || !At || !tq || !z) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (tau)");
        goto done;
    }
    for (int32_t i = 0; i < na; i++)
        for (int32_t q = 0; q < ny; q++) At[(size_t)i * ny + q] = A[(size_t)q * na + i];
    lapack_int info = LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ny, na, At, ny, jpvt, tq);
    while (!info && rank < k && fabs(At[(size_t)rank * ny + rank]) > 1e-10 * fabs(At[0])) rank++;
    for (int32_t i = 0; !info && i < rank; i++) { /* R_r^T z = (P^T b)_r, forward */
        double acc = b[jpvt[i] - 1];
        for (int32_t j = 0; j < i; j++) acc -= At[(size_t)i * ny + j] * z[j];
        z[i] = acc / At[(size_t)i * ny + i];
    }
    for (int32_t i = 0; !info && i < k; i++) /* reflectors into Q (ny x ny) */
        memcpy(Q + (size_t)i * ny, At + (size_t)i * ny, sizeof(double) * (size_t)ny);
    if (!info) info = LAPACKE_dorgqr(LAPACK_COL_MAJOR, ny, ny, k, Q, ny, tq);
    if (info) {
        st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "bi5: tau constraint QR failed (%d)", (int)info);
        goto done;
    }
    for (int32_t q = 0; q < ny; q++) {
        double acc = 0;
        for (int32_t i = 0; i < rank; i++) acc += Q[(size_t)i * ny + q] * z[i];
        y[q] = acc;
    }
    *rank_out = rank;
done:
    free(jpvt); free(At); free(tq); free(z);
    return st;
}

/* H0 = F0^T F0 (30 x 30) and g_s = F0^T f0_s: the normal equations of sum_s |F0 y_s + f0_s|^2. */
static void energy_normal(int32_t ns, const double *F0, const double *f0, double H0[900], double *g) {
    for (int32_t p = 0; p < 30; p++)
        for (int32_t q = 0; q < 30; q++) {
            double acc = 0;
            for (int32_t r = 0; r < F5_ROWS; r++) acc += F0[p * F5_ROWS + r] * F0[q * F5_ROWS + r];
            H0[p * 30 + q] = acc;
        }
    for (int32_t s = 0; s < ns; s++)
        for (int32_t p = 0; p < 30; p++) {
            double acc = 0;
            for (int32_t r = 0; r < F5_ROWS; r++) acc += F0[p * F5_ROWS + r] * f0[(size_t)s * F5_ROWS + r];
            g[s * 30 + p] = acc;
        }
}

/* min sum_s |F0 y_s + f0_s|^2 over y = (y_0..y_{ns-1}) (30 parameters per sector, the same F0
 * for every sector) subject to A y = b: y = y_p + N z, and the reduced normal equations
 * N^T H N z = -N^T (H y_p + g) with the block-diagonal H = F0^T F0, g_s = F0^T f0_s. */
static ccn_status constrained_min(int32_t ns, int32_t na, const double *A, const double *b,
                                  const double *F0, const double *f0, double *y, ccn_error *err) {
    int32_t ny = 30 * ns, rank = 0;
    double *Q = malloc(sizeof(double) * (size_t)ny * ny), *HN = malloc(sizeof(double) * (size_t)ny * ny);
    double *M = malloc(sizeof(double) * (size_t)ny * ny), *rhs = malloc(sizeof(double) * (size_t)ny);
    double *g = malloc(sizeof(double) * (size_t)ny), H0[900];
    ccn_status st = CCN_OK;
    if (!Q || !HN || !M || !rhs || !g) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (tau)");
        goto done;
    }
    energy_normal(ns, F0, f0, H0, g);
    if ((st = null_space(na, ny, A, b, Q, y, &rank, err))) goto done;
    int32_t nn = ny - rank;
    const double *N = Q + (size_t)rank * ny; /* column j: N[j*ny + q] */
    for (int32_t q = 0; q < ny; q++) { /* HN = H N, g <- H y_p + g */
        int32_t s = q / 30, p = q % 30;
        for (int32_t j = 0; j < nn; j++) {
            double acc = 0;
            for (int32_t t = 0; t < 30; t++) acc += H0[p * 30 + t] * N[(size_t)j * ny + s * 30 + t];
            HN[(size_t)j * ny + q] = acc;
        }
        double acc = g[q];
        for (int32_t t = 0; t < 30; t++) acc += H0[p * 30 + t] * y[s * 30 + t];
        g[q] = acc;
    }
    for (int32_t i = 0; i < nn; i++) {
        for (int32_t j = 0; j < nn; j++) {
            double acc = 0;
            for (int32_t q = 0; q < ny; q++) acc += N[(size_t)i * ny + q] * HN[(size_t)j * ny + q];
            M[(size_t)j * nn + i] = acc;
        }
        double acc = 0;
        for (int32_t q = 0; q < ny; q++) acc += N[(size_t)i * ny + q] * g[q];
        rhs[i] = -acc;
    }
    if (nn > 0) {
        lapack_int info = LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', nn, 1, M, nn, rhs, nn);
        if (info) { st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "bi5: tau energy is degenerate (%d)", (int)info); goto done; }
        for (int32_t j = 0; j < nn; j++)
            for (int32_t q = 0; q < ny; q++) y[q] += N[(size_t)j * ny + q] * rhs[j];
    }
done:
    free(Q); free(HN); free(M); free(rhs); free(g);
    return st;
}

/* ---- tau ------------------------------------------------------------------------------- */

/* Free coefficients of tau: max(i,j) <= 3 except (3,3) ([R4]); 15 complex per sector. */
static const int32_t *free_list(void) {
    static const int32_t fl[15] = {0, 1, 2, 3, 6, 7, 8, 9, 12, 13, 14, 15, 18, 19, 20};
    return fl;
}

static int is_fixed(int32_t e) { return e / 6 >= 4 || e % 6 >= 4 || e == 21; }

void ccn__bi5_raise_chi(const double complex chi[16], double complex G[36]) {
    static const double E[6][4] = {{1, 0, 0, 0}, {0.4, 0.6, 0, 0}, {0.1, 0.6, 0.3, 0},
                                   {0, 0.3, 0.6, 0.1}, {0, 0, 0.6, 0.4}, {0, 0, 0, 1}};
    for (int32_t i = 0; i < 6; i++)
        for (int32_t j = 0; j < 6; j++) {
            double complex acc = 0;
            for (int32_t a = 0; a < 4; a++)
                for (int32_t b = 0; b < 4; b++) acc += E[i][a] * E[j][b] * chi[a * 4 + b];
            G[i * 6 + j] = acc;
        }
}

/* Fills ns patches from the fixed parts green (ns x 36) and the 30 ns real parameters y. */
static void tau_make(int32_t ns, const double complex *green, const double *y, double complex *t) {
    const int32_t *fl = free_list();
    for (int32_t s = 0; s < ns; s++) {
        for (int32_t e = 0; e < 36; e++) t[s * 36 + e] = is_fixed(e) ? green[s * 36 + e] : 0;
        for (int32_t q = 0; q < 15; q++)
            t[s * 36 + fl[q]] = y[s * 30 + 2 * q] + y[s * 30 + 2 * q + 1] * CCN_BI5_I;
    }
}

typedef struct {
    int32_t n, ns;            /* valence, number of independent sectors (1: symmetric) */
    const double *kap;        /* NULL: symmetric */
    const double complex *green;
} tau_problem;

static int32_t tau_ncons(const tau_problem *P) {
    return P->kap ? P->n * (2 + 12 + 16) : 2 + 42 + 12 + 16;
}

/* Constraint residuals (real) of the patches t. */
static void tau_cons(const tau_problem *P, const double complex *t, double *r) {
    int32_t q = 0, n = P->n;
    double c = cos(2.0 * CCN_BI5_PI / n);
    double complex om = ccn__bi5_omega(n, 1), R[8], z[36];
#define PUSH(x) do { double complex x_ = (x); r[q++] = creal(x_); r[q++] = cimag(x_); } while (0)
    if (!P->kap) { /* symmetric (SPEC §6.2): tau_00 = 0, diagonal symmetry, C0 and (9) with omega tau */
        PUSH(t[0]);
        for (int32_t i = 0; i < 6; i++)
            for (int32_t j = i; j < 6; j++) PUSH(t[j * 6 + i] - om * conj(t[i * 6 + j]));
        for (int32_t i = 0; i < 6; i++) PUSH(t[i] - om * t[i * 6]);
        for (int32_t e = 0; e < 36; e++) z[e] = om * t[e];
        ccn__bi5_g1_res(t, z, c, 1.0, R);
        for (int32_t i = 0; i < 8; i++) PUSH(R[i]);
        return;
    }
    for (int32_t s = 0; s < n; s++) { /* [R9]: per sector; edge s|s+1 is spoke e_{s+1} */
        const double complex *fs = t + s * 36, *fs1 = t + ((s + 1) % n) * 36;
        PUSH(fs[0]);
        for (int32_t i = 0; i < 6; i++) PUSH(fs[i] - fs1[i * 6]);
        ccn__bi5_g1_res(fs, fs1, c, P->kap[(s + 1) % n], R);
        for (int32_t i = 0; i < 8; i++) PUSH(R[i]);
    }
#undef PUSH
}

/* Builds and solves the tau problem; t receives ns patches. */
static ccn_status tau_solve(const tau_problem *P, double complex *t, ccn_error *err) {
    int32_t ny = 30 * P->ns, na = tau_ncons(P);
    double *A = malloc(sizeof(double) * (size_t)na * ny), *b = malloc(sizeof(double) * (size_t)na);
    double *F0 = malloc(sizeof(double) * 30 * F5_ROWS), *f0 = malloc(sizeof(double) * (size_t)F5_ROWS * P->ns);
    double *y = calloc((size_t)ny, sizeof(double)), *r = malloc(sizeof(double) * (size_t)na);
    ccn_status st = CCN_OK;
    if (!A || !b || !F0 || !f0 || !y || !r) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (tau)");
        goto done;
    }
    f5_table T5;
    f5_table_init(&T5);
    tau_make(P->ns, P->green, y, t); /* affine maps: value at 0, then unit columns */
    tau_cons(P, t, b);
    for (int32_t s = 0; s < P->ns; s++) f5_vec(&T5, t + s * 36, f0 + (size_t)s * F5_ROWS);
    for (int32_t q = 0; q < ny; q++) {
        y[q] = 1.0;
        tau_make(P->ns, P->green, y, t);
        tau_cons(P, t, r);
        for (int32_t k = 0; k < na; k++) A[(size_t)q * na + k] = r[k] - b[k];
        if (q < 30) { /* the energy's linear part is the same for every sector */
            f5_vec(&T5, t, F0 + (size_t)q * F5_ROWS);
            for (int32_t k = 0; k < F5_ROWS; k++) F0[(size_t)q * F5_ROWS + k] -= f0[k];
        }
        y[q] = 0.0;
    }
    for (int32_t k = 0; k < na; k++) b[k] = -b[k];
    st = constrained_min(P->ns, na, A, b, F0, f0, y, err);
    double resid = 0, scale = 1;
    for (int32_t k = 0; !st && k < na; k++) {
        double acc = -b[k];
        for (int32_t q = 0; q < ny; q++) acc += A[(size_t)q * na + k] * y[q];
        resid = fmax(resid, fabs(acc));
        scale = fmax(scale, fabs(b[k]));
    }
    if (!st && !(resid <= 1e-9 * scale))
        st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1,
                       "bi5: the G1 constraints on tau are inconsistent (residual %g)", resid);
    if (!st) tau_make(P->ns, P->green, y, t);
done:
    free(A); free(b); free(F0); free(f0); free(y); free(r);
    return st;
}

ccn_status ccn__bi5_tau(int32_t n, const double complex chi[16], double complex tau[36],
                        ccn_error *err) {
    double complex G[36];
    ccn__bi5_raise_chi(chi, G);
    tau_problem P = {n, 1, NULL, G};
    return tau_solve(&P, tau, err);
}

/* Smallest Jacobian Im(conj(tau_u) tau_v) of the planar bi-5 map tau on a 21 x 21 grid; B, D:
 * the Bernstein values and derivatives at the grid's 21 parameters (ccn__bi5_bern5_with_deriv
 * at k / 20), the same for every sector. */
static double tau_min_jacobian(const double complex tau[36], double B[21][6], double D[21][6]) {
    double P[72], du[2], dv[2], jmin = INFINITY;
    for (int32_t k = 0; k < 36; k++) P[2 * k] = creal(tau[k]), P[2 * k + 1] = cimag(tau[k]);
    for (int32_t a = 0; a <= 20; a++)
        for (int32_t c = 0; c <= 20; c++) {
            ccn__bi5_patch_eval_tab(P, 2, B[a], D[a], B[c], D[c], NULL, du, dv);
            jmin = fmin(jmin, du[0] * dv[1] - du[1] * dv[0]);
        }
    return jmin;
}

/* [R15] Sector s of the planar border G (n x 36, omega^s raise(chi~) per sector) mapped by the
 * real-linear map that takes omega^s to d_s^e omega^s and omega^{s+1} to d_{s+1}^e omega^{s+1}
 * (d normalised by its geometric mean): the spokes of the guide's domain get lengths from
 * their intervals, so that the cross-spoke ratios come out as (d_{s+1}/d_{s-1})^e before the
 * C2-rule makes them kappa_s. */
void ccn__bi5_spoke_scale(int32_t n, const double *d, double e, double complex *G) {
    double gm = 0;
    for (int32_t s = 0; s < n; s++) gm += log(d[s]) / n;
    for (int32_t s = 0; s < n; s++) {
        double complex w0 = ccn__bi5_omega(n, s), w1 = ccn__bi5_omega(n, s + 1);
        double l0 = exp(e * (log(d[s]) - gm)), l1 = exp(e * (log(d[(s + 1) % n]) - gm));
        double det = creal(w0) * cimag(w1) - cimag(w0) * creal(w1);
        for (int32_t k = 0; k < 36; k++) {
            double complex z = G[s * 36 + k];
            double a = (creal(z) * cimag(w1) - cimag(z) * creal(w1)) / det;
            double b = (creal(w0) * cimag(z) - cimag(w0) * creal(z)) / det;
            G[s * 36 + k] = a * l0 * w0 + b * l1 * w1;
        }
    }
}

ccn_status ccn__bi5_tau_nu(int32_t n, const double complex chi[16], const double *kap, const double *d, double e,
                           double complex *tau, ccn_error *err) {
    double complex *G = malloc(sizeof(double complex) * 36 * (size_t)n);
    if (!G) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (tau)");
    double complex G0[36];
    ccn__bi5_raise_chi(chi, G0);
    for (int32_t s = 0; s < n; s++)
        for (int32_t e = 0; e < 36; e++) G[s * 36 + e] = ccn__bi5_omega(n, s) * G0[e];
    if (d && e > 0) ccn__bi5_spoke_scale(n, d, e, G);
    ccn__bi5_c2_rule(n, kap, 2, (double *)G); /* green layers carry the NU C1 ratio */
    tau_problem P = {n, n, kap, G};
    ccn_status st = tau_solve(&P, tau, err);
    free(G);
    /* Extreme spoke ratios (e.g. kappa = 10 next to kappa = 0.1) fold the minimum-energy
     * tau, and the cap with it (a reversed normal at the centre): refuse, the caller falls
     * back to the exact refined limit. kappa <= 3 keeps J >= 0.33 (measured). */
    double B[21][6], D[21][6];
    for (int32_t a = 0; a <= 20; a++) ccn__bi5_bern5_with_deriv(a / 20.0, B[a], D[a]);
    for (int32_t s = 0; !st && s < n; s++)
        if (!(tau_min_jacobian(tau + 36 * (size_t)s, B, D) > 0))
            st = ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_EDGE, s,
                           "bi5: the cap parameterization folds in sector %d for these spoke ratios "
                           "(kappa %g)", (int)s, kap[s]);
    return st;
}
