/* Inverse of the bilinear map of Li 2016 eq (30), closed form of Floater 2015 (eqs (31)-(32))
 * with the orientation sign of SPEC 2.4 and a safeguarded Newton polish (rules/bilinear.h). */
#include "rules/bilinear.h"

#include <math.h>

static double cross2(const double u[2], const double v[2]) { return u[0] * v[1] - u[1] * v[0]; }

/* ---- inverse bilinear map (eqs (30)-(32), Floater 2015) ------------------------------- */

typedef struct {
    double p[4][2]; /* corners in cyclic order: B(0,0), B(1,0), B(1,1), B(0,1) */
} quad;

/* B(a1, a2) of eq (30) with corners q->p[0..3] = (V, E_i, F_i, E_{i+1}). */
static void bl_eval(const quad *q, double a1, double a2, double out[2]) {
    int k;
    for (k = 0; k < 2; k++)
        out[k] = (1 - a1) * (1 - a2) * q->p[0][k] + a1 * (1 - a2) * q->p[1][k] + a1 * a2 * q->p[2][k] +
                 (1 - a1) * a2 * q->p[3][k];
}

static double bl_residual(const quad *q, const double x[2], double a1, double a2) {
    double b[2];
    bl_eval(q, a1, a2, b);
    return fmax(fabs(b[0] - x[0]), fabs(b[1] - x[1]));
}

/* L1 distance of (a1, a2) from the unit square (0 inside). */
static double square_dist(double a1, double a2) {
    return fmax(0.0, fmax(-a1, a1 - 1.0)) + fmax(0.0, fmax(-a2, a2 - 1.0));
}

/* Floater's closed form (31)-(32) for one branch br = +-1 of sqrt(D). With v_k = x - p_k,
 * S_k = v_k x v_{k+1} / 2, T_k = v_{k-1} x v_{k+1} / 2 (1-based, cyclic),
 * D = T1^2 + T2^2 + 2 S1 S3 + 2 S2 S4,
 * a1 = 2 S4 / (2 S4 - T1 + T2 + s sqrt D), a2 = 2 S1 / (2 S1 - T1 - T2 + s sqrt D),
 * s = br * orientation sign of the quad (SPEC 2.4: the printed form is the CCW case).
 * Returns 0, or 1 if D < 0 (no real root). */
static int floater_branch(const quad *q, const double x[2], double br, double *a1,
                          double *a2, double *dratio) {
    double v[4][2], S[4], T[4], D, Dscale, orient, r, e13[2], e24[2];
    int k;
    for (k = 0; k < 4; k++) {
        v[k][0] = x[0] - q->p[k][0];
        v[k][1] = x[1] - q->p[k][1];
    }
    for (k = 0; k < 4; k++) {
        S[k] = 0.5 * cross2(v[k], v[(k + 1) % 4]);
        T[k] = 0.5 * cross2(v[(k + 3) % 4], v[(k + 1) % 4]);
    }
    D = T[0] * T[0] + T[1] * T[1] + 2 * S[0] * S[2] + 2 * S[1] * S[3];
    Dscale = T[0] * T[0] + T[1] * T[1] + 2 * fabs(S[0] * S[2]) + 2 * fabs(S[1] * S[3]);
    *dratio = Dscale > 0 ? D / Dscale : 0.0;
    if (D < 0) {
        if (D < -1e-12 * Dscale) return 1;
        D = 0; /* a double root perturbed by rounding */
    }
    e13[0] = q->p[2][0] - q->p[0][0];
    e13[1] = q->p[2][1] - q->p[0][1];
    e24[0] = q->p[3][0] - q->p[1][0];
    e24[1] = q->p[3][1] - q->p[1][1];
    orient = cross2(e13, e24) >= 0 ? 1.0 : -1.0;
    r = br * orient * sqrt(D);
    *a1 = 2 * S[3] / (2 * S[3] - T[0] + T[1] + r);
    *a2 = 2 * S[0] / (2 * S[0] - T[0] - T[1] + r);
    return 0;
}

/* One safeguarded Newton run from (*a1, *a2): full step, halved until |B - x| decreases.
 * Leaves the best point found in (*a1, *a2) and returns its residual. */
static double newton_run(const quad *q, const double x[2], double *a1, double *a2,
                         double tol) {
    double u = *a1, w = *a2, res = bl_residual(q, x, u, w);
    int it, k;
    for (it = 0; it < 60 && res > tol; it++) {
        double b[2], J[2][2], det, du, dw, t = 1.0, h[2];
        int improved = 0;
        bl_eval(q, u, w, b);
        for (k = 0; k < 2; k++) {
            h[k] = q->p[0][k] - q->p[1][k] + q->p[2][k] - q->p[3][k];
            J[k][0] = q->p[1][k] - q->p[0][k] + w * h[k]; /* dB/da1 */
            J[k][1] = q->p[3][k] - q->p[0][k] + u * h[k]; /* dB/da2 */
        }
        det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
        if (!(fabs(det) > 0) || !isfinite(det)) break;
        du = ((x[0] - b[0]) * J[1][1] - (x[1] - b[1]) * J[0][1]) / det;
        dw = ((x[1] - b[1]) * J[0][0] - (x[0] - b[0]) * J[1][0]) / det;
        for (k = 0; k < 40; k++, t *= 0.5) {
            double r2 = bl_residual(q, x, u + t * du, w + t * dw);
            if (r2 < res) {
                u += t * du;
                w += t * dw;
                res = r2;
                improved = 1;
                break;
            }
        }
        if (!improved) break;
    }
    *a1 = u;
    *a2 = w;
    return res;
}

/* Keeps (a1, a2) as the best candidate if it solves the system and is nearer the unit square
 * (ties: smaller residual). */
static void consider(double a1, double a2, double res, double tol, double *b1, double *b2,
                     double *bdist, double *bres) {
    double dist;
    if (!isfinite(a1) || !isfinite(a2) || !(res <= tol)) return;
    dist = square_dist(a1, a2);
    if (dist < *bdist - 1e-12 || (dist <= *bdist + 1e-12 && res < *bres)) {
        *b1 = a1;
        *b2 = a2;
        *bdist = dist;
        *bres = res;
    }
}

int ccn__bilinear_inverse(const double corners[8], const double x[2], double *a1, double *a2) {
    double dratio;
    return ccn__bilinear_inverse_d(corners, x, a1, a2, &dratio);
}

int ccn__bilinear_inverse_d(const double corners[8], const double x[2], double *a1, double *a2,
                            double *dratio) {
    static const double starts[5][2] = {{0.5, 0.5}, {0.25, 0.25}, {0.75, 0.75},
                                        {0.25, 0.75}, {0.75, 0.25}};
    quad Q;
    double size = 0, tol, polish, b1 = NAN, b2 = NAN, bdist = INFINITY,
                    bres = INFINITY;
    int k, br;
    *a1 = *a2 = NAN;
    *dratio = -1;
    if (!isfinite(x[0]) || !isfinite(x[1])) return 2;
    for (k = 0; k < 4; k++) {
        Q.p[k][0] = corners[2 * k];
        Q.p[k][1] = corners[2 * k + 1];
    }
    for (k = 0; k < 4; k++) {
        if (!isfinite(Q.p[k][0]) || !isfinite(Q.p[k][1])) return 2;
        size = fmax(size, fmax(fabs(Q.p[k][0] - Q.p[0][0]), fabs(Q.p[k][1] - Q.p[0][1])));
    }
    if (!(size > 0)) return 2;
    tol = 1e-10 * size;
    polish = 4e-16 * size;
    /* Closed form, both branches of sqrt(D), each polished by a few Newton steps. */
    for (br = 1; br >= -1; br -= 2) {
        double u, w, res;
        if (floater_branch(&Q, x, (double)br, &u, &w, dratio)) continue;
        if (!isfinite(u) || !isfinite(w)) continue;
        res = bl_residual(&Q, x, u, w);
        if (res > polish) res = newton_run(&Q, x, &u, &w, polish);
        consider(u, w, res, tol, &b1, &b2, &bdist, &bres);
    }
    /* Ill-conditioned closed form (or D < 0 by rounding): Newton from several starts. */
    if (!isfinite(b1)) {
        for (k = 0; k < 5; k++) {
            double u = starts[k][0], w = starts[k][1];
            double res = newton_run(&Q, x, &u, &w, polish);
            consider(u, w, res, tol, &b1, &b2, &bdist, &bres);
        }
    }
    if (!isfinite(b1)) return 1;
    *a1 = b1;
    *a2 = b2;
    return 0;
}
