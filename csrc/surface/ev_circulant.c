/* The limit eigenvectors of a rotationally symmetric 1-ring matrix (surface/ev_circulant.h).
 *
 * With equal spoke intervals the scheme's matrix M of an interior extraordinary vertex of
 * valence n commutes with the rotation F_j -> F_{j+1}, E_j -> E_{j+1}: it is block-circulant,
 * c_XY(d) = M[X_0, Y_d] (X, Y in {F, E}), and its eigenvectors are Fourier modes. For
 * z = exp(2 pi i p / n) a left eigenvector l[X_j] = u_X z^j, l[V] = 0 (p != 0) gives
 *   (l M)[Y_k] = z^k (u A_p)_Y,   A_p = sum_d c(d) z^-d   (2 x 2, complex),
 * and a right one r[Y_k] = v_Y z^-k gives (M r)[X_j] = z^-j (A_p v)_X; mode 0 adds V (3 x 3).
 * So the spectrum is that of n small blocks, O(n^2) to set up instead of dgeev's O(n^3) on
 * (2n+1)^2 (n = 300: 2.3 s -> milliseconds). Li, Finnigan, Sederberg 2016 section 5 state the
 * limit through M's dominant left eigenvector (eigenvalue 1) and the subdominant pair; for
 * Catmull-Clark-type rules that pair is mode 1 and its conjugate n-1, which is checked here
 * (every other mode strictly below), else the caller keeps dgeev. */
#include "surface/ev_circulant.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>

#define CIRC_TOL 1e-12   /* entries of M are O(1): rows sum to 1 */
#define CIRC_PI 3.14159265358979323846
#define GAP 1e-8         /* the subdominant pair must be this much (relative) above the rest */

static int is_circulant(const double *M, int32_t n) {
    int32_t sz = 2 * n + 1, V = 2 * n;
    for (int32_t X = 0; X < 2; X++)
        for (int32_t j = 1; j < n; j++) {
            const double *row = M + (size_t)(X * n + j) * sz, *row0 = M + (size_t)(X * n) * sz;
            for (int32_t Y = 0; Y < 2; Y++)
                for (int32_t k = 0; k < n; k++) {
                    int32_t d = k - j < 0 ? k - j + n : k - j;
                    if (!(fabs(row[Y * n + k] - row0[Y * n + d]) <= CIRC_TOL)) return 0;
                }
            if (!(fabs(row[V] - row0[V]) <= CIRC_TOL)) return 0;
        }
    const double *rv = M + (size_t)V * sz;
    for (int32_t Y = 0; Y < 2; Y++)
        for (int32_t k = 1; k < n; k++)
            if (!(fabs(rv[Y * n + k] - rv[Y * n]) <= CIRC_TOL)) return 0;
    return 1;
}

/* A_p = sum_d c(d) z^-d, z = exp(2 pi i p / n); cs/sn: cos, sin of 2 pi t / n, t = 0..n-1 */
static void block(const double *M, int32_t n, int32_t p, const double *cs, const double *sn,
                  double complex A[2][2]) {
    int32_t sz = 2 * n + 1;
    for (int X = 0; X < 2; X++)
        for (int Y = 0; Y < 2; Y++) {
            const double *c = M + (size_t)(X * n) * sz + (size_t)Y * n;
            double re = 0, im = 0;
            for (int32_t d = 0; d < n; d++) {
                int32_t t = (int32_t)(((int64_t)p * d) % n);
                re += c[d] * cs[t];
                im -= c[d] * sn[t];
            }
            A[X][Y] = re + im * I;
        }
}

static void eig2(double complex A[2][2], double complex *big, double complex *small) {
    double complex tr = A[0][0] + A[1][1], det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    double complex disc = csqrt(tr * tr - 4.0 * det);
    double complex a = 0.5 * (tr + disc), b = 0.5 * (tr - disc);
    if (cabs(a) >= cabs(b)) { *big = a; *small = b; }
    else { *big = b; *small = a; }
}

int ccn__ev_circulant_eigvecs(const double *M, int32_t n, double *l0, double *l1, double *l2,
                              double *r1, double *r2) {
    if (n < 3 || !is_circulant(M, n)) return 1;
    int32_t sz = 2 * n + 1, V = 2 * n;
    double *cs = malloc(sizeof(double) * 2 * (size_t)n);
    if (!cs) return -1;
    double *sn = cs + n;
    for (int32_t t = 0; t < n; t++) {
        double a = 2.0 * CIRC_PI * t / n;
        cs[t] = cos(a); sn[t] = sin(a);
    }
    /* mode 0 (left): B[X][Y] = sum_d c_XY(d), B[X][V] = n M[X_0,V], B[V][Y] = M[V,Y_0] */
    double B[3][3];
    for (int X = 0; X < 2; X++) {
        const double *row = M + (size_t)(X * n) * sz;
        for (int Y = 0; Y < 2; Y++) {
            double s = 0;
            for (int32_t d = 0; d < n; d++) s += row[Y * n + d];
            B[X][Y] = s;
        }
        B[X][2] = n * row[V];
    }
    for (int Y = 0; Y < 2; Y++) B[2][Y] = M[(size_t)V * sz + (size_t)Y * n];
    B[2][2] = M[(size_t)V * sz + V];
    /* its eigenvalues besides 1 (affine invariance: M 1 = 1): sum tr - 1, product det */
    double tr = B[0][0] + B[1][1] + B[2][2];
    double det = B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1])
               - B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0])
               + B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0]);
    double complex s0 = tr - 1.0, q0 = csqrt(s0 * s0 - 4.0 * det);
    double rest = fmax(cabs(0.5 * (s0 + q0)), cabs(0.5 * (s0 - q0)));
    /* modes 2 .. n-2 (n-1 is mode 1's conjugate) */
    double complex A[2][2], lam, other;
    for (int32_t p = 2; p <= n - 2; p++) {
        block(M, n, p, cs, sn, A);
        eig2(A, &lam, &other);
        rest = fmax(rest, cabs(lam));
    }
    block(M, n, 1, cs, sn, A);
    eig2(A, &lam, &other);
    rest = fmax(rest, cabs(other));
    if (!(cabs(lam) > (1.0 + GAP) * rest) || !(cabs(lam) < 1.0)) { free(cs); return 1; }

    /* l0: u (B - I) = 0, u orthogonal to two columns of B - I (the pair spanning best) */
    double C[3][3];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) C[a][b] = B[a][b] - (a == b);
    double u0[3] = {0, 0, 0}, best = -1;
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3;
        double x[3] = {C[1][a] * C[2][b] - C[2][a] * C[1][b], C[2][a] * C[0][b] - C[0][a] * C[2][b],
                       C[0][a] * C[1][b] - C[1][a] * C[0][b]};
        double nx = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        if (nx > best) { best = nx; u0[0] = x[0]; u0[1] = x[1]; u0[2] = x[2]; }
    }
    double sum = n * u0[0] + n * u0[1] + u0[2];
    if (!(fabs(sum) > 1e-300)) { free(cs); return 1; }
    for (int32_t j = 0; j < n; j++) { l0[j] = u0[0] / sum; l0[n + j] = u0[1] / sum; }
    l0[V] = u0[2] / sum;

    /* mode 1: left u A = lam u, right A v = lam v (the larger of the two formulas each) */
    double complex ua[2] = {A[1][0], lam - A[0][0]}, ub[2] = {lam - A[1][1], A[0][1]};
    double complex va[2] = {A[0][1], lam - A[0][0]}, vb[2] = {lam - A[1][1], A[1][0]};
    const double complex *u = cabs(ua[0]) + cabs(ua[1]) >= cabs(ub[0]) + cabs(ub[1]) ? ua : ub;
    const double complex *v = cabs(va[0]) + cabs(va[1]) >= cabs(vb[0]) + cabs(vb[1]) ? va : vb;
    double nu = sqrt(n * (creal(u[0] * conj(u[0])) + creal(u[1] * conj(u[1]))));
    if (!(nu > 1e-300)) { free(cs); return 1; }
    for (int32_t j = 0; j < n; j++) {
        double complex z = cs[j] + sn[j] * I; /* z^j; r uses z^-j */
        for (int X = 0; X < 2; X++) {
            double complex l = u[X] * z / nu, r = v[X] * conj(z);
            l1[X * n + j] = creal(l); l2[X * n + j] = cimag(l);
            r1[X * n + j] = creal(r); r2[X * n + j] = cimag(r);
        }
    }
    l1[V] = l2[V] = r1[V] = r2[V] = 0;
    free(cs);
    return 0;
}
