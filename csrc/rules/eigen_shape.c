/* Candidate eigen polyhedra (see rules/eigen_shape.h for the list and the reasons). */
#include "rules/eigen_shape.h"

#include <math.h>
#include <stdlib.h>

#define SHAPE_PI 3.14159265358979323846

static const ccn__poly_design DESIGNS[CCN__POLY_COUNT] = {
    {CCN__LEN_PAPER, 0, 0, 0},
    {CCN__LEN_EXPONENT, 0.1, 0, 0},  {CCN__LEN_EXPONENT, 0.2, 0, 0},   {CCN__LEN_EXPONENT, -0.1, 0, 0},
    {CCN__LEN_EXPONENT, 0.05, 0, 0}, {CCN__LEN_EXPONENT, -0.05, 0, 0}, {CCN__LEN_EXPONENT, 0.15, 0, 0},
    {CCN__LEN_EXPONENT, -0.2, 0, 0}, {CCN__LEN_EXPONENT, 0.3, 0, 0},   {CCN__LEN_EXPONENT, -0.3, 0, 0},
    {CCN__LEN_EXPONENT, 0.4, 0, 0},
    {CCN__LEN_GREVILLE, 0, 0, 0},
    {CCN__LEN_GREVILLE, 0, -0.08, 0}, {CCN__LEN_GREVILLE, 0, -0.12, 0}, {CCN__LEN_PAPER, 0, -0.08, 0},
    {CCN__LEN_GREVILLE, 0, -0.05, 0}, {CCN__LEN_EXPONENT, 0.1, -0.12, 0}, {CCN__LEN_GREVILLE, 0, -0.2, 0},
    {CCN__LEN_PAPER, 0, -0.12, 0},    {CCN__LEN_GREVILLE, 0, -0.03, 0}, {CCN__LEN_EXPONENT, 0.1, -0.08, 0},
    {CCN__LEN_GREVILLE, 0, -0.15, 0},
    {CCN__LEN_GREVILLE, -0.1, -0.1, 3}, {CCN__LEN_GREVILLE, 0.1, -0.06, 0}, {CCN__LEN_GREVILLE, 0.1, -0.2, 0},
    {CCN__LEN_GREVILLE, 0.1, -0.03, 0}, {CCN__LEN_GREVILLE, -0.1, -0.06, 0}, {CCN__LEN_PAPER, 0, -0.15, 1},
};

const ccn__poly_design *ccn__poly_design_of(int32_t poly) {
    return poly >= 1 && poly <= CCN__POLY_COUNT ? &DESIGNS[poly - 1] : NULL;
}

static int32_t md(int64_t i, int32_t n) {
    int64_t r = i % n;
    return (int32_t)(r < 0 ? r + n : r);
}

/* Greville candidate. In x = log l the equations are (D x)_s = x_{s+1} - x_{s-1} = b_s,
 * b_s = log((2 d_{s+1} + d_{s-1}) / (2 d_{s-1} + d_{s+1})). D is circulant with eigenvalues
 * 2i sin(2 pi k / n) (zero for k = 0 and, n even, k = n/2), so the least-squares solution
 * closest to the paper's x_p is x_p + D^+ (b - D x_p), D^+ applied by a discrete Fourier
 * transform (O(n^2); the selection runs for moderate n only). */
static int greville_lengths(int32_t n, const double *d, double *l) {
    double *buf = malloc(sizeof(double) * 5 * (size_t)n);
    if (!buf) return -1;
    double *x = buf, *r = x + n, *zr = r + n, *zi = zr + n, *z = zi + n;
    for (int32_t s = 0; s < n; s++) x[s] = log(l[s]);
    for (int32_t s = 0; s < n; s++) {
        double dp = d[md(s + 1, n)], dm = d[md(s - 1, n)];
        r[s] = log((2 * dp + dm) / (2 * dm + dp)) - (x[md(s + 1, n)] - x[md(s - 1, n)]);
    }
    for (int32_t k = 0; k < n; k++) { /* R_k = sum_j r_j w^{-jk}, Z_k = R_k / (2i sin) */
        double sk = sin(2 * SHAPE_PI * k / n), re = 0, im = 0;
        for (int32_t j = 0; j < n; j++) {
            double a = 2 * SHAPE_PI * (double)md((int64_t)j * k, n) / n;
            re += r[j] * cos(a);
            im -= r[j] * sin(a);
        }
        if (fabs(sk) < 1e-9) { zr[k] = zi[k] = 0; continue; }
        zr[k] = im / (2 * sk); /* (re + i im) / (2 i sk) */
        zi[k] = -re / (2 * sk);
    }
    for (int32_t j = 0; j < n; j++) {
        double acc = 0;
        for (int32_t k = 0; k < n; k++) {
            double a = 2 * SHAPE_PI * (double)md((int64_t)j * k, n) / n;
            acc += zr[k] * cos(a) - zi[k] * sin(a);
        }
        z[j] = acc / n;
    }
    for (int32_t s = 0; s < n; s++) l[s] = exp(x[s] + z[s]);
    free(buf);
    return 0;
}

static double sector_weight(const ccn__poly_design *des, double a, double b) {
    double x = des->angle_fn == 1 ? a + b : des->angle_fn == 2 ? fmin(a, b) : des->angle_fn == 3 ? fmax(a, b) : a * b;
    return pow(x, des->a);
}

int ccn__poly_apply(const ccn__poly_design *des, int32_t n, const double *d, double *l,
                    double *c, double *s) {
    if (des->lengths == CCN__LEN_EXPONENT)
        for (int32_t i = 0; i < n; i++) l[i] = pow(l[i], 1.0 - des->e) * pow(d[i], des->e);
    if (des->lengths == CCN__LEN_GREVILLE) {
        if (greville_lengths(n, d, l)) return -1;
        if (des->e != 0)
            for (int32_t i = 0; i < n; i++) l[i] = pow(l[i], 1.0 - des->e) * pow(d[i], des->e);
    }
    if (des->a != 0) {
        double sum = 0, phi = 0;
        for (int32_t i = 0; i < n; i++) sum += sector_weight(des, d[i], d[md(i + 1, n)]);
        for (int32_t i = 0; i < n; i++) {
            c[i] = cos(phi);
            s[i] = sin(phi);
            phi += 2 * SHAPE_PI * sector_weight(des, d[i], d[md(i + 1, n)]) / sum;
        }
    }
    return 0;
}
