/* Property measurements of a bi-5 ring/cap patch set (Karciauskas & Peters 2018), shared by
 * test_bi5.c (c-nets) and test_cap.c (whole pipeline). Written for the tests, independently of
 * the library: power-form evaluation with exact derivatives; each measure returns the largest
 * absolute defect. Patch layout: (3*nsig+1)*n patches of 6x6x3, ring r kind A/B/C, then the cap. */
#ifndef CCN_TEST_BI5_PROPS_H
#define CCN_TEST_BI5_PROPS_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

static inline double binom(int d, int k) {
    double r = 1;
    for (int q = 1; q <= k; q++) r = r * (d - k + q) / q;
    return r;
}

/* Power-form coefficients M[a][b] (u^a v^b) of a bi-d patch P[i][j][3] (d <= 5). */
static inline void power_form(int d, const double *P, double M[6][6][3]) {
    double C[6][6] = {{0}}; /* u^a coefficient of B^d_i */
    for (int i = 0; i <= d; i++)
        for (int a = i; a <= d; a++) C[a][i] = binom(d, i) * binom(d - i, a - i) * (((a - i) & 1) ? -1 : 1);
    memset(M, 0, sizeof(double) * 108);
    for (int a = 0; a <= d; a++)
        for (int b = 0; b <= d; b++)
            for (int i = 0; i <= d; i++)
                for (int j = 0; j <= d; j++)
                    for (int c = 0; c < 3; c++) M[a][b][c] += C[a][i] * C[b][j] * P[(i * (d + 1) + j) * 3 + c];
}

static inline void pf_eval(double M[6][6][3], double u, double v, int du, int dv, double out[3]) {
    out[0] = out[1] = out[2] = 0;
    for (int a = du; a < 6; a++)
        for (int b = dv; b < 6; b++) {
            double fa = 1, fb = 1;
            for (int q = 0; q < du; q++) fa *= a - q;
            for (int q = 0; q < dv; q++) fb *= b - q;
            double w = fa * fb * pow(u, a - du) * pow(v, b - dv);
            for (int c = 0; c < 3; c++) out[c] += w * M[a][b][c];
        }
}

typedef struct {
    int n, nsig;
    const double *sig;
    const double *P;     /* patches */
    double (*M)[6][6][3]; /* their power forms */
} surf_t;

static inline void surf_init(surf_t *S, int n, int nsig, const double *sig, const double *P) {
    S->n = n; S->nsig = nsig; S->sig = sig; S->P = P;
    int np = (3 * nsig + 1) * n;
    S->M = malloc(sizeof(*S->M) * (size_t)np);
    for (int k = 0; S->M && k < np; k++) power_form(5, P + (size_t)k * 108, S->M[k]);
}

static inline int patch_idx(const surf_t *S, int r, int kind, int s) {
    return r < S->nsig ? (3 * r + kind) * S->n + s : 3 * S->nsig * S->n + s;
}

/* Ring r (0-based, sigma_{r+1}) patch kind (0 A, 1 B, 2 C) in level-r units; r = nsig: cap. */
static inline void ring_eval(const surf_t *S, int r, int kind, int s, double u, double v, int du, int dv,
                      double out[3]) {
    double u0 = 0, lu = 1, v0 = 0, lv = 1;
    if (r < S->nsig) {
        double sg = S->sig[r], rho = 1 - sg;
        u0 = kind == 2 ? 0 : rho; lu = kind == 2 ? rho : sg;
        v0 = kind == 0 ? 0 : rho; lv = kind == 0 ? rho : sg;
    }
    pf_eval(S->M[patch_idx(S, r, kind, s)], (u - u0) / lu, (v - v0) / lv, du, dv, out);
    double f = pow(lu, -du) * pow(lv, -dv);
    for (int c = 0; c < 3; c++) out[c] *= f;
}

static inline double vdiff(const double a[3], const double b[3]) {
    return fmax(fabs(a[0] - b[0]), fmax(fabs(a[1] - b[1]), fabs(a[2] - b[2])));
}

static inline void cross(const double a[3], const double b[3], double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double angle(const double a[3], const double b[3]) {
    double c[3];
    cross(a, b, c);
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

/* A|B across v = rho and B|C across u = rho, all derivatives of total order <= 2. */
static inline double ring_internal(const surf_t *S) {
    double e = 0, a[3], b[3];
    for (int r = 0; r < S->nsig; r++) {
        double sg = S->sig[r], rho = 1 - sg;
        for (int s = 0; s < S->n; s++)
            for (int q = 0; q <= 6; q++) {
                double t = rho + sg * q / 6.0;
                for (int k = 0; k <= 2; k++)
                    for (int l = 0; k + l <= 2; l++) {
                        ring_eval(S, r, 0, s, t, rho, l, k, a);
                        ring_eval(S, r, 1, s, t, rho, l, k, b);
                        e = fmax(e, vdiff(a, b));
                        ring_eval(S, r, 1, s, rho, t, k, l, a);
                        ring_eval(S, r, 2, s, rho, t, k, l, b);
                        e = fmax(e, vdiff(a, b));
                    }
            }
    }
    return e;
}

/* Across spoke e_s: A^s(u,0) vs C^{s-1}(0,u) (rotation (u,v) -> (-v,u)); transversal
 * derivatives in knot units (interval d_{s+1} in sector s, d_{s-1} in sector s-1). */
static inline double ring_spokes(const surf_t *S, const double *d) {
    double e = 0, a[3], b[3];
    int n = S->n;
    for (int r = 0; r < S->nsig; r++) {
        double sg = S->sig[r], rho = 1 - sg;
        for (int s = 0; s < n; s++) {
            int p = (s + n - 1) % n;
            double hs = d ? d[(s + 1) % n] : 1, hp = d ? d[p] : 1;
            for (int q = 0; q <= 6; q++) {
                double t = rho + sg * q / 6.0;
                for (int k = 0; k <= 2; k++)
                    for (int l = 0; k + l <= 2; l++) {
                        ring_eval(S, r, 0, s, t, 0, l, k, a);
                        ring_eval(S, r, 2, p, 0, t, k, l, b);
                        double f = ((k & 1) ? -1 : 1) * pow(hs / hp, k);
                        for (int c = 0; c < 3; c++) b[c] *= f;
                        e = fmax(e, vdiff(a, b));
                    }
            }
        }
    }
    return e;
}

/* Ring r inner boundary vs ring r+1 outer boundary (C2), and cap vs last ring (C1). */
static inline double ring_to_ring(const surf_t *S, int order) {
    double e = 0, a[3], b[3];
    for (int r = 0; r < S->nsig; r++) {
        double rho = 1 - S->sig[r];
        int last = r + 1 == S->nsig;
        if (last != (order == 1)) continue;
        for (int s = 0; s < S->n; s++)
            for (int q = 0; q <= 8; q++) {
                double t = q / 8.0; /* along the boundary, level-(r+1) units */
                for (int k = 0; k <= order; k++)
                    for (int l = 0; k + l <= order; l++) {
                        /* edge u = rho (level r) = u = 1 (level r+1) */
                        ring_eval(S, r, 0, s, rho, rho * t, k, l, a);
                        int kind = last ? 0 : (t <= 1 - S->sig[r + 1] ? 0 : 1);
                        ring_eval(S, r + 1, kind, s, 1.0, t, k, l, b);
                        double f = pow(rho, -(k + l));
                        for (int c = 0; c < 3; c++) b[c] *= f;
                        e = fmax(e, vdiff(a, b));
                        /* edge v = rho = v = 1 */
                        ring_eval(S, r, 2, s, rho * t, rho, l, k, a);
                        kind = last ? 0 : (t <= 1 - S->sig[r + 1] ? 2 : 1);
                        ring_eval(S, r + 1, kind, s, t, 1.0, l, k, b);
                        for (int c = 0; c < 3; c++) b[c] *= f;
                        e = fmax(e, vdiff(a, b));
                    }
            }
    }
    return e;
}

/* Cap: C0 and angle between normals along every separator, and of all sector normals at the
 * centre. Returns the C0 defect, *ang the largest angle (rad). */
static inline double cap_g1(const surf_t *S, double *ang) {
    double e = 0, worst = 0, n0[3] = {0, 0, 0};
    int n = S->n, L = S->nsig;
    for (int s = 0; s < n; s++) {
        int s1 = (s + 1) % n;
        for (int q = 0; q <= 40; q++) {
            double t = q / 40.0, p1[3], p2[3], u1[3], v1[3], u2[3], v2[3], m1[3], m2[3];
            ring_eval(S, L, 0, s, 0, t, 0, 0, p1);
            ring_eval(S, L, 0, s1, t, 0, 0, 0, p2);
            e = fmax(e, vdiff(p1, p2));
            ring_eval(S, L, 0, s, 0, t, 1, 0, u1);
            ring_eval(S, L, 0, s, 0, t, 0, 1, v1);
            ring_eval(S, L, 0, s1, t, 0, 1, 0, u2);
            ring_eval(S, L, 0, s1, t, 0, 0, 1, v2);
            cross(u1, v1, m1);
            cross(u2, v2, m2);
            worst = fmax(worst, angle(m1, m2));
            if (q == 0 && s == 0) memcpy(n0, m1, sizeof n0);
            if (q == 0) worst = fmax(worst, angle(n0, m1));
        }
    }
    *ang = worst;
    return e;
}

/* Mean and Gauss curvature at the centre from each cap sector: largest spread over the
 * sectors relative to 1 + max |H|, |K|. */
static inline double centre_curvature(const surf_t *S) {
    double Hmin = INFINITY, Hmax = -INFINITY, Kmin = INFINITY, Kmax = -INFINITY;
    for (int s = 0; s < S->n; s++) {
        double fu[3], fv[3], fuu[3], fuv[3], fvv[3], N[3];
        ring_eval(S, S->nsig, 0, s, 0, 0, 1, 0, fu);
        ring_eval(S, S->nsig, 0, s, 0, 0, 0, 1, fv);
        ring_eval(S, S->nsig, 0, s, 0, 0, 2, 0, fuu);
        ring_eval(S, S->nsig, 0, s, 0, 0, 1, 1, fuv);
        ring_eval(S, S->nsig, 0, s, 0, 0, 0, 2, fvv);
        cross(fu, fv, N);
        double nn = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        double E = 0, F = 0, G = 0, L = 0, M = 0, NN = 0;
        for (int c = 0; c < 3; c++) {
            E += fu[c] * fu[c]; F += fu[c] * fv[c]; G += fv[c] * fv[c];
            L += fuu[c] * N[c] / nn; M += fuv[c] * N[c] / nn; NN += fvv[c] * N[c] / nn;
        }
        double det = E * G - F * F, H = (E * NN - 2 * F * M + G * L) / (2 * det), K = (L * NN - M * M) / det;
        Hmin = fmin(Hmin, H); Hmax = fmax(Hmax, H); Kmin = fmin(Kmin, K); Kmax = fmax(Kmax, K);
    }
    double big = 1 + fmax(fmax(fabs(Hmin), fabs(Hmax)), fmax(fabs(Kmin), fabs(Kmax)));
    return fmax(Hmax - Hmin, Kmax - Kmin) / big;
}


#endif
