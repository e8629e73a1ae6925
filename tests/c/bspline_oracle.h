/* Cubic B-spline curves on explicit knots, written from first principles for the tests
 * (test_creases.c, test_fvar.c): no code or formula is shared with csrc/. */
#ifndef CCN_TESTS_BSPLINE_ORACLE_H
#define CCN_TESTS_BSPLINE_ORACLE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static inline void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) { fprintf(stderr, "out of memory\n"); exit(2); }
    return p;
}
#define NEW(T, n) ((T *)xmalloc(sizeof(T) * (size_t)(n)))

/* ==== oracle ============================================================================
 * A cubic B-spline curve with control points Q_0..Q_{n} (dim doubles each) and intervals
 * I_0..I_{n-1} (I_i between Q_i and Q_{i+1}) has knots t_0 = 0, t_{i+1} = t_i + I_i; Q_i is
 * the blossom f(t_{i-1}, t_i, t_{i+1}) and its limit point is f(t_i, t_i, t_i). Ends are
 * point-reflected: Q_{-k} = 2 Q_0 - Q_k with I_{-k} = I_{k-1}; closed curves wrap. */
typedef struct { int n, dim; double *Q, *t; } ocurve; /* extended: points -2..n+2 */

static inline ocurve oc_make(const double *Q, int n, int dim, const double *I, int periodic) {
    ocurve c;
    c.n = n; c.dim = dim;
    c.Q = NEW(double, (size_t)(n + 5) * dim);
    c.t = NEW(double, n + 5);
    for (int j = -2; j <= n + 2; j++) {
        double *dst = c.Q + (size_t)(j + 2) * dim;
        if (periodic) {
            int m = ((j % n) + n) % n; /* n points on a closed curve: Q_n = Q_0 */
            memcpy(dst, Q + (size_t)m * dim, sizeof(double) * dim);
        } else if (j < 0) {
            for (int k = 0; k < dim; k++) dst[k] = 2 * Q[k] - Q[(size_t)(-j) * dim + k];
        } else if (j > n) {
            for (int k = 0; k < dim; k++) dst[k] = 2 * Q[(size_t)n * dim + k] - Q[(size_t)(2 * n - j) * dim + k];
        } else {
            memcpy(dst, Q + (size_t)j * dim, sizeof(double) * dim);
        }
    }
    /* knots t_{-2}..t_{n+2} */
    double *t = c.t + 2;
    t[0] = 0;
    for (int i = 0; i < n + 2; i++) {
        double Ii = periodic ? I[i % n] : (i < n ? I[i] : I[2 * n - 1 - i]);
        t[i + 1] = t[i] + Ii;
    }
    for (int i = -1; i >= -2; i--) {
        double Ii = periodic ? I[((i % n) + n) % n] : I[-i - 1];
        t[i] = t[i + 1] - Ii;
    }
    return c;
}
static inline void oc_free(ocurve *c) { free(c->Q); free(c->t); }

/* Value and derivative at x in [t_k, t_{k+1}] (k clamped to [0, n-1]) by de Boor. */
static inline void oc_eval(const ocurve *c, double x, int k, double *val, double *der) {
    const double *t = c->t + 2;
    int dim = c->dim;
    double d[4][16];
    for (int a = 0; a < 4; a++) /* P_{k-1} .. P_{k+2} */
        memcpy(d[a], c->Q + (size_t)(k - 1 + a + 2) * dim, sizeof(double) * dim);
    /* control a = P_{k-1+a} has blossom (t_{k-2+a}, t_{k-1+a}, t_{k+a}) */
    for (int r = 1; r <= 3; r++) {
        if (r == 3)
            for (int q = 0; q < dim; q++) der[q] = 3 * (d[3][q] - d[2][q]) / (t[k + 1] - t[k]);
        for (int a = 3; a >= r; a--) { /* de Boor: alpha = (x - tau_j)/(tau_{j+4-r} - tau_j) */
            double lo = t[k - 3 + a], hi = t[k + 1 + a - r];
            double al = (x - lo) / (hi - lo);
            for (int q = 0; q < dim; q++) d[a][q] = (1 - al) * d[a - 1][q] + al * d[a][q];
        }
    }
    memcpy(val, d[3], sizeof(double) * dim);
}

#endif
