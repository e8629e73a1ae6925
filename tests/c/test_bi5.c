/* Tests of the guided rapidly-contracting bi-5 rings and G1 cap (csrc/bi5/: charmap.c,
 * guide.c, rings.c, cap.c; Karciauskas & Peters 2018, reference/bi5/SPEC.md).
 *
 * Oracles written here, independently of the library:
 *   - the numpy prototype's numbers (tests/bi5/test_vectors.txt = reference/bi5/dump_vectors.py
 *     output): lambda_sigma, chi~_sigma, tau, an end-to-end n = 5 example;
 *   - the surrounding bicubic ring: tensor B-spline evaluated with Cox-de Boor recursion on an
 *     extended net (uniform or non-uniform knots);
 *   - eigen nets: the Catmull-Clark matrix of the 6n+1 net (rules composed literally) and
 *     LAPACKE_dgeev;
 *   - patch evaluation in power form and by de Casteljau.
 * Tolerances are relative to the size of the net (largest |coordinate|). Derivatives are
 * compared in one parameter scale (hole units, chain rule through the ring levels; knot units
 * for non-uniform intervals). Set BI5_CAP_SIZE_MD=path to write the cap-size table. */
#include "testlib.h"

#include "ccnurbs.h"
#include "bi5/bi5.h"
#include "bi5/charmap.h"
#include "bi5/tau.h"
#include "bi5_props.h"

#include <lapacke.h>

#define TWO_PI 6.283185307179586476925
#define TOL 1e-9
#define VECTORS "tests/bi5/test_vectors.txt"

static const double E35[6][4] = {{1, 0, 0, 0}, {0.4, 0.6, 0, 0}, {0.1, 0.6, 0.3, 0},
                                 {0, 0.3, 0.6, 0.1}, {0, 0, 0.6, 0.4}, {0, 0, 0, 1}}; /* degree 3 -> 5 */
static const double SIG5[3] = {0.75, 0.875, 0.875}, SIG3[1] = {15.0 / 16.0};

/* ---------------------------------------------------------------------------------------- */
/* reference numbers                                                                         */

static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)len + 1);
    if (buf && fread(buf, 1, (size_t)len, f) != (size_t)len) { free(buf); buf = NULL; }
    if (buf) buf[len] = '\0';
    fclose(f);
    return buf;
}

/* Reads count numbers following the line that starts with title ("(re,im)" gives 2 numbers). */
static int read_block(const char *text, const char *title, int count, double *out) {
    const char *p = text;
    size_t tl = strlen(title);
    while (p && strncmp(p, title, tl) != 0) {
        p = strchr(p, '\n');
        if (p) p++;
    }
    if (!p || !(p = strchr(p, '\n'))) return 0;
    for (int k = 0; k < count; k++) {
        while (*p && strchr(" \t\n(),", *p)) p++;
        char *end;
        out[k] = strtod(p, &end);
        if (end == p) return 0;
        p = end;
    }
    return 1;
}

static double paper_lambda(int n, double s) { /* paper Sec. 4.1 */
    double c = cos(TWO_PI / n), st = 1 - s;
    return st / 2 * ((1 + c) * s * s + 2 * st + s * sqrt((1 + c) * ((1 + c) * s * s + 4 * st)));
}

/* ---------------------------------------------------------------------------------------- */
/* nets: extended net, own nodes 1 <= i <= 3, 0 <= j <= 3 of each sector (12), index 0 = EV   */

static int node3(int n, int s, int i, int j) {
    for (int g = 0; g < 4; g++) {
        s = ((s % n) + n) % n;
        if (i == 0 && j == 0) return 0;
        if (i >= 1 && j >= 0) return (i <= 3 && j <= 3) ? 1 + 12 * s + (i - 1) * 4 + j : -1;
        if (i == 0 && j >= 1) { i = j; j = 0; s++; continue; }   /* (0,j)_s = (j,0)_{s+1} */
        if (j == -1 && i >= 0) { j = i; i = 1; s--; continue; }  /* (i,-1)_s = (1,i)_{s-1} */
        if (i == -1 && j >= 0) { i = j; j = 1; s++; continue; }  /* (-1,j)_s = (j,1)_{s+1} */
        return -1;
    }
    return -1;
}

static const int LBL_I[6] = {2, 2, 2, 1, 1, 1}, LBL_J[6] = {0, 1, 2, 2, 1, 0};

/* c-net index of node (i,j) of sector s (i,j <= 2), SPEC §1.2 order. */
static int cnode(int n, int s, int i, int j) {
    int e = node3(n, s, i, j);
    if (e <= 0) return e;
    int ss = (e - 1) / 12, q = (e - 1) % 12, ii = q / 4 + 1, jj = q % 4;
    for (int m = 0; m < 6; m++)
        if (LBL_I[m] == ii && LBL_J[m] == jj) return 1 + 6 * ss + m;
    return -1;
}

static void extract_cnet(int n, const double *X3, double *X) {
    memcpy(X, X3, sizeof(double) * 3);
    for (int k = 0; k < n; k++)
        for (int m = 0; m < 6; m++)
            memcpy(X + 3 * (1 + 6 * k + m), X3 + 3 * node3(n, k, LBL_I[m], LBL_J[m]), sizeof(double) * 3);
}

static double rnd(void) { return 2 * tl_rand01() - 1; }

/* Jittered polar layout with a bumpy height (prototype's make_net, different random numbers). */
static void make_net(int n, double *X3) {
    for (int e = 0; e < 1 + 12 * n; e++) {
        double x = 0, y = 0;
        if (e > 0) {
            int s = (e - 1) / 12, q = (e - 1) % 12, i = q / 4 + 1, j = q % 4;
            double a0 = TWO_PI * s / n, a1 = TWO_PI * (s + 1) / n;
            x = i * cos(a0) + j * cos(a1);
            y = i * sin(a0) + j * sin(a1);
        }
        X3[3 * e + 2] = 0.25 * x * x - 0.15 * x * y + 0.1 * y * y * y + 0.15 * rnd();
        X3[3 * e] = x + 0.05 * rnd();
        X3[3 * e + 1] = y + 0.05 * rnd();
    }
}

static double net_size(const double *X, int npts) {
    double m = 0;
    for (int k = 0; k < 3 * npts; k++) m = fmax(m, fabs(X[k]));
    return m;
}

/* ---------------------------------------------------------------------------------------- */
/* patch evaluation: power form, de Casteljau                                                */

static void decasteljau(const double *P, double u, double v, double out[3]) {
    double row[6][3], w[6][3];
    for (int i = 0; i < 6; i++) {
        for (int j = 0; j < 6; j++) memcpy(w[j], P + (i * 6 + j) * 3, sizeof(double) * 3);
        for (int r = 5; r > 0; r--)
            for (int j = 0; j < r; j++)
                for (int c = 0; c < 3; c++) w[j][c] = (1 - v) * w[j][c] + v * w[j + 1][c];
        memcpy(row[i], w[0], sizeof(double) * 3);
    }
    for (int r = 5; r > 0; r--)
        for (int i = 0; i < r; i++)
            for (int c = 0; c < 3; c++) row[i][c] = (1 - u) * row[i][c] + u * row[i + 1][c];
    memcpy(out, row[0], sizeof(double) * 3);
}

/* ---------------------------------------------------------------------------------------- */
/* surrounding bicubic ring: Cox-de Boor                                                     */

#define KOFF 8
/* Knots of a direction: t_k = k dp (k >= 0), k dn (k < 0); array index k + KOFF. */
static void dir_knots(double dn, double dp, double T[20]) {
    for (int k = -KOFF; k < 20 - KOFF; k++) T[k + KOFF] = k >= 0 ? k * dp : k * dn;
}

static double cdb(const double *T, int j, int k, double x, int der) {
    const double *t = T + KOFF;
    if (der > 0) {
        double a = t[j + k - 1] - t[j], b = t[j + k] - t[j + 1], r = 0;
        if (a > 0) r += cdb(T, j, k - 1, x, der - 1) / a;
        if (b > 0) r -= cdb(T, j + 1, k - 1, x, der - 1) / b;
        return (k - 1) * r;
    }
    if (k == 1) return (t[j] <= x && x < t[j + 1]) ? 1.0 : 0.0;
    double r = 0, a = t[j + k - 1] - t[j], b = t[j + k] - t[j + 1];
    if (a > 0) r += (x - t[j]) / a * cdb(T, j, k - 1, x, 0);
    if (b > 0) r += (t[j + k] - x) / b * cdb(T, j + 1, k - 1, x, 0);
    return r;
}

/* Tensor cubic B-spline of sector s's virtual grid (control point (i,j) at knots (t_i, t_j),
 * label (t_{i-1}, t_i, t_{i+1})): derivative (du,dv) at knot coordinates (x, y), summing
 * control points i in [i0,i0+4), j in [j0,j0+4). d: spoke intervals or NULL. */
static void surround(int n, const double *X3, const double *d, int s, int i0, int j0, double x,
                     double y, int du, int dv, double out[3]) {
    const int missing_zero = i0 == -1 && j0 == -1; /* hole patch: (-1,-1) cancels */
    double Tu[20], Tv[20];
    dir_knots(d ? d[(s + 2) % n] : 1, d ? d[s] : 1, Tu);
    dir_knots(d ? d[(s + n - 1) % n] : 1, d ? d[(s + 1) % n] : 1, Tv);
    out[0] = out[1] = out[2] = 0;
    for (int i = i0; i < i0 + 4; i++)
        for (int j = j0; j < j0 + 4; j++) {
            double w = cdb(Tu, i - 2, 4, x, du) * cdb(Tv, j - 2, 4, y, dv);
            int e = node3(n, s, i, j);
            if (w == 0) continue;
            if (e < 0 && missing_zero) continue;
            if (e < 0) { out[0] = NAN; return; }
            for (int c = 0; c < 3; c++) out[c] += w * X3[3 * e + c];
        }
}

/* ---------------------------------------------------------------------------------------- */
/* property measurements (each returns the largest defect, absolute)                        */

/* Ring x^0 vs the surrounding bicubic ring across u = 1 and v = 1, derivatives of total
 * order <= 2 (hole units -> knot units: factor d_s^k d_{s+1}^l). */
static double ring_surround(const surf_t *S, const double *X3, const double *d) {
    double e = 0, a[3], b[3];
    int n = S->n;
    double rho = 1 - S->sig[0];
    for (int s = 0; s < n; s++) {
        double hu = d ? d[s] : 1, hv = d ? d[(s + 1) % n] : 1;
        for (int q = 0; q <= 8; q++) {
            double t = 0.99 * q / 8.0;
            for (int k = 0; k <= 2; k++)
                for (int l = 0; k + l <= 2; l++) {
                    ring_eval(S, 0, t <= rho ? 0 : 1, s, 1.0, t, k, l, a);
                    surround(n, X3, d, s, 0, -1, hu, t * hv, k, l, b);
                    double f = pow(hu, k) * pow(hv, l);
                    for (int c = 0; c < 3; c++) b[c] *= f;
                    e = fmax(e, isnan(b[0]) ? INFINITY : vdiff(a, b));
                    ring_eval(S, 0, t <= rho ? 2 : 1, s, t, 1.0, l, k, a);
                    surround(n, X3, d, s, -1, 0, t * hu, hv, l, k, b);
                    f = pow(hu, l) * pow(hv, k);
                    for (int c = 0; c < 3; c++) b[c] *= f;
                    e = fmax(e, isnan(b[0]) ? INFINITY : vdiff(a, b));
                }
        }
    }
    return e;
}

typedef struct {
    double internal, spokes, r2r, cap_ring, surround, cap_c0, cap_angle, curv;
} defects;

static void measure(const surf_t *S, const double *X3, const double *d, defects *D) {
    D->internal = fmax(D->internal, ring_internal(S));
    D->spokes = fmax(D->spokes, ring_spokes(S, d));
    D->r2r = fmax(D->r2r, ring_to_ring(S, 2));
    D->cap_ring = fmax(D->cap_ring, ring_to_ring(S, 1));
    if (X3) D->surround = fmax(D->surround, ring_surround(S, X3, d));
    double a;
    D->cap_c0 = fmax(D->cap_c0, cap_g1(S, &a));
    D->cap_angle = fmax(D->cap_angle, a);
    D->curv = fmax(D->curv, centre_curvature(S));
}

static void relative(defects *D, double size) {
    D->internal /= size; D->spokes /= size; D->r2r /= size; D->cap_ring /= size;
    D->surround /= size; D->cap_c0 /= size;
}

static void report(const char *what, const defects *D) {
    printf("  %-24s C2 in ring %.1e, across spokes %.1e, ring-ring %.1e, x0-bi3 %.1e, "
           "cap-ring C1 %.1e, cap C0 %.1e, normal angle %.1e rad, centre (H,K) spread %.1e\n",
           what, D->internal, D->spokes, D->r2r, D->surround, D->cap_ring, D->cap_c0, D->cap_angle,
           D->curv);
    CHECK(D->internal <= TOL, "%s: ring-internal C2 defect %g", what, D->internal);
    CHECK(D->spokes <= TOL, "%s: across-spoke C2 defect %g", what, D->spokes);
    CHECK(D->r2r <= TOL, "%s: ring-to-ring C2 defect %g", what, D->r2r);
    CHECK(D->surround <= TOL, "%s: ring x^0 / bicubic ring C2 defect %g", what, D->surround);
    CHECK(D->cap_ring <= TOL, "%s: cap / last ring C1 defect %g", what, D->cap_ring);
    CHECK(D->cap_c0 <= TOL, "%s: cap C0 defect %g", what, D->cap_c0);
    CHECK(D->cap_angle <= TOL, "%s: cap normal angle %g rad", what, D->cap_angle);
    CHECK(D->curv <= 1e-8, "%s: centre curvature differs between sectors by %g", what, D->curv);
}

static ccn__bi5 *make_op(int n) {
    ccn__bi5 *b = NULL;
    ccn_error err;
    ccn_status st = ccn__bi5_create(n, n == 3 ? SIG3 : SIG5, n == 3 ? 1 : 3, &b, &err);
    CHECK(st == CCN_OK, "create n=%d: %s", n, err.message);
    return st == CCN_OK ? b : NULL;
}

static double *run_apply(const ccn__bi5 *b, const double *X, const double *d, ccn_status *st) {
    ccn_error err;
    double *P = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(b));
    *st = ccn__bi5_apply(b, X, d, NULL, P, &err);
    if (*st) fprintf(stderr, "  apply: %s\n", err.message);
    return P;
}

/* ---------------------------------------------------------------------------------------- */
/* 1. reference numbers of the prototype                                                     */

static void test_vectors_lambda(void) {
    char *txt = read_file(VECTORS);
    CHECK(txt != NULL, "cannot read %s (run from the repository root)", VECTORS);
    if (!txt) return;
    static const int ns[5] = {3, 5, 6, 7, 8};
    static const double sg[4] = {0.5, 0.75, 0.875, 0.9375};
    double worst = 0;
    for (int q = 0; q < 5; q++) {
        char key[32];
        snprintf(key, sizeof key, "n=%d ", ns[q]);
        const char *p = strstr(txt, key);
        CHECK(p != NULL, "no lambda line for n=%d", ns[q]);
        for (int k = 0; p && k < 4; k++) {
            char sk[32];
            snprintf(sk, sizeof sk, "sigma=%g:", sg[k]);
            const char *v = strstr(p, sk);
            double ref = v ? strtod(v + strlen(sk), NULL) : NAN;
            double mine = ccn__bi5_lambda(ns[q], sg[k]);
            worst = fmax(worst, fabs(mine - ref));
            worst = fmax(worst, fabs(paper_lambda(ns[q], sg[k]) - ref));
        }
    }
    printf("  lambda_sigma vs prototype: %.1e\n", worst);
    CHECK(worst <= 1e-15, "lambda_sigma differs from the prototype by %g", worst);
    free(txt);
}

static void test_vectors_chi(void) {
    char *txt = read_file(VECTORS);
    if (!txt) { CHECK(0, "cannot read %s", VECTORS); return; }
    static const int ns[4] = {3, 5, 6, 8};
    static const double sg[4] = {0.5, 0.75, 0.875, 0.9375};
    double worst = 0, ref[32];
    for (int q = 0; q < 4; q++)
        for (int k = 0; k < 4; k++) {
            char title[64];
            snprintf(title, sizeof title, "chi n=%d sigma=%g ", ns[q], sg[k]);
            CHECK(read_block(txt, title, 32, ref), "no block '%s'", title);
            double complex chi[16];
            double lam;
            ccn_error err;
            CHECK(ccn__bi5_charmap(ns[q], sg[k], chi, &lam, &err) == CCN_OK, "%s", err.message);
            for (int e = 1; e < 16; e++) worst = fmax(worst, cabs(chi[e] - (ref[2 * e] + CCN_BI5_I * ref[2 * e + 1])));
        }
    printf("  chi~_sigma (n = 3,5,6,8; 4 speeds) vs prototype: %.1e\n", worst);
    CHECK(worst <= 1e-12, "chi~ differs from the prototype by %g", worst);
    free(txt);
}

static void test_vectors_tau(void) {
    char *txt = read_file(VECTORS);
    if (!txt) { CHECK(0, "cannot read %s", VECTORS); return; }
    static const int ns[3] = {5, 3, 7};
    static const double sg[3] = {0.875, 0.9375, 0.875};
    double worst = 0, ref[72];
    for (int q = 0; q < 3; q++) {
        char title[64];
        snprintf(title, sizeof title, "tau n=%d sigma=%g ", ns[q], sg[q]);
        CHECK(read_block(txt, title, 72, ref), "no block '%s'", title);
        double complex chi[16], tau[36];
        ccn_error err;
        CHECK(ccn__bi5_charmap(ns[q], sg[q], chi, NULL, &err) == CCN_OK, "%s", err.message);
        CHECK(ccn__bi5_tau(ns[q], chi, tau, &err) == CCN_OK, "%s", err.message);
        for (int e = 0; e < 36; e++) worst = fmax(worst, cabs(tau[e] - (ref[2 * e] + CCN_BI5_I * ref[2 * e + 1])));
    }
    printf("  tau (n = 5, 3, 7) vs prototype: %.1e\n", worst);
    CHECK(worst <= 1e-12, "tau differs from the prototype by %g", worst);
    free(txt);
}

/* Rows 3..5 of t~^{r-1} and t~^r of sector 0 recovered from ring x^{r-1}'s patch A:
 * A[3..5] = SR[3..5][3..5] To[3..5] SL^T, A[0..2] = PR Ti[3..5] (SPEC §5), solved here. */
static void borders_from_A(const double *A, double sigma, double To[3][6][3], double Ti[3][6][3]) {
    double rho = 1 - sigma, t = 1 / rho, SR[6][6] = {{0}}, SL[6][6] = {{0}}, Y[6][6][3];
    for (int k = 0; k < 6; k++)
        for (int l = 0; l < 6; l++) {
            if (l >= k) SR[k][l] = binom(5 - k, l - k) * pow(1 - rho, 5 - l) * pow(rho, l - k);
            if (l <= k) SL[k][l] = binom(k, l) * pow(1 - rho, k - l) * pow(rho, l);
        }
    for (int j = 0; j < 6; j++)
        for (int c = 0; c < 3; c++) {
            for (int i = 5; i >= 3; i--) { /* back substitution, SR upper triangular */
                double acc = A[(i * 6 + j) * 3 + c];
                for (int k = i + 1; k <= 5; k++) acc -= SR[i][k] * Y[k][j][c];
                Y[i][j][c] = acc / SR[i][i];
            }
            double q0 = A[(0 * 6 + j) * 3 + c], q1 = A[(1 * 6 + j) * 3 + c], q2 = A[(2 * 6 + j) * 3 + c];
            double p5 = q0, p4 = (q1 - t * p5) / (1 - t);
            double p3 = (q2 - t * t * p5 - 2 * (1 - t) * t * p4) / ((1 - t) * (1 - t));
            Ti[2][j][c] = p5; Ti[1][j][c] = p4; Ti[0][j][c] = p3;
        }
    for (int i = 3; i <= 5; i++)
        for (int c = 0; c < 3; c++)
            for (int j = 0; j < 6; j++) { /* forward substitution, SL lower triangular */
                double acc = Y[i][j][c];
                for (int l = 0; l < j; l++) acc -= SL[j][l] * To[i - 3][l][c];
                To[i - 3][j][c] = acc / SL[j][j];
            }
}

static void test_vectors_example(void) {
    char *txt = read_file(VECTORS);
    if (!txt) { CHECK(0, "cannot read %s", VECTORS); return; }
    double X[93], ref[108], refT[108];
    CHECK(read_block(txt, "cnet n=5 ", 93, X), "no c-net block");
    ccn__bi5 *b = make_op(5);
    if (!b) { free(txt); return; }
    ccn_status st;
    double *P = run_apply(b, X, NULL, &st);
    CHECK(st == CCN_OK, "apply failed");
    static const char *titles[4] = {"ring x^0 patch A sector 0", "ring x^0 patch B sector 0",
                                    "ring x^0 patch C sector 0", "cap patch sector 0"};
    int idx[4] = {0, 5, 10, 45};
    double worst = 0;
    for (int q = 0; q < 4; q++) {
        CHECK(read_block(txt, titles[q], 108, ref), "no block '%s'", titles[q]);
        double e = 0;
        for (int k = 0; k < 108; k++) e = fmax(e, fabs(P[(size_t)idx[q] * 108 + k] - ref[k]));
        printf("  n = 5 example, %-26s max |C - prototype| = %.1e\n", titles[q], e);
        worst = fmax(worst, e);
    }
    double To[3][6][3], Ti[3][6][3];
    borders_from_A(P, SIG5[0], To, Ti);
    CHECK(read_block(txt, "t~^0 (t_CC raised) sector 0", 108, ref), "no t~^0 block");
    CHECK(read_block(txt, "t~^1 sector 0", 108, refT), "no t~^1 block");
    double et = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 6; j++)
            for (int c = 0; c < 3; c++) {
                et = fmax(et, fabs(To[i][j][c] - ref[((i + 3) * 6 + j) * 3 + c]));
                et = fmax(et, fabs(Ti[i][j][c] - refT[((i + 3) * 6 + j) * 3 + c]));
            }
    printf("  n = 5 example, t~^0 and t~^1 rows 3..5 (from patch A) vs prototype: %.1e\n", et);
    CHECK(worst <= 1e-11, "end-to-end example differs from the prototype by %g", worst);
    CHECK(et <= 1e-10, "tensor-borders differ from the prototype by %g", et);
    free(P);
    ccn__bi5_destroy(b);
    free(txt);
}

/* ---------------------------------------------------------------------------------------- */
/* 2. continuity on random nets                                                              */

static const int NS[7] = {3, 5, 6, 7, 8, 10, 16}, NNETS[7] = {40, 40, 30, 30, 25, 25, 15};

static void test_random_nets(void) {
    int total = 0;
    for (int q = 0; q < 7; q++) {
        int n = NS[q];
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        defects D = {0};
        double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * (6 * (size_t)n + 1));
        for (int k = 0; k < NNETS[q]; k++, total++) {
            make_net(n, X3);
            extract_cnet(n, X3, X);
            ccn_status st;
            double *P = run_apply(b, X, NULL, &st);
            CHECK(st == CCN_OK, "apply n=%d", n);
            surf_t S;
            surf_init(&S, n, b->nsig, b->sig, P);
            defects d1 = {0};
            measure(&S, X3, NULL, &d1);
            relative(&d1, net_size(X3, 1 + 12 * n));
            D.internal = fmax(D.internal, d1.internal); D.spokes = fmax(D.spokes, d1.spokes);
            D.r2r = fmax(D.r2r, d1.r2r); D.cap_ring = fmax(D.cap_ring, d1.cap_ring);
            D.surround = fmax(D.surround, d1.surround); D.cap_c0 = fmax(D.cap_c0, d1.cap_c0);
            D.cap_angle = fmax(D.cap_angle, d1.cap_angle);
            D.curv = fmax(D.curv, d1.curv);
            free(S.M);
            free(P);
        }
        char what[64];
        snprintf(what, sizeof what, "n=%d (%d nets)", n, NNETS[q]);
        report(what, &D);
        free(X3); free(X);
        ccn__bi5_destroy(b);
    }
    CHECK(total >= 200, "only %d random nets", total);
}

/* ---------------------------------------------------------------------------------------- */
/* 3. eigen nets, precision, degree, evaluation, invariance                                  */

/* Catmull-Clark subdivision matrix of the 6n+1 net (rows composed from face, edge, vertex
 * rules with the sector-local grid), row-major (6n+1)^2. */
static void cc_face(int n, int s, int a, int b, double *row, double w) {
    int c[4][2] = {{a, b}, {a + 1, b}, {a + 1, b + 1}, {a, b + 1}};
    for (int k = 0; k < 4; k++) row[cnode(n, s, c[k][0], c[k][1])] += w / 4;
}
static void cc_edge(int n, int s, int p0, int p1, int q0, int q1, int f1a, int f1b, int f2a, int f2b, double *row) {
    row[cnode(n, s, p0, p1)] += 0.25;
    row[cnode(n, s, q0, q1)] += 0.25;
    cc_face(n, s, f1a, f1b, row, 0.25);
    cc_face(n, s, f2a, f2b, row, 0.25);
}
static void cc_vertex(int n, int s, int i, int j, double *row) {
    cc_face(n, s, i - 1, j - 1, row, 1.0 / 16);
    cc_face(n, s, i, j - 1, row, 1.0 / 16);
    cc_face(n, s, i, j, row, 1.0 / 16);
    cc_face(n, s, i - 1, j, row, 1.0 / 16);
    int nb[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
    for (int k = 0; k < 4; k++) {
        row[cnode(n, s, i, j)] += 2.0 / 4 * 0.5 / 4;
        row[cnode(n, s, nb[k][0], nb[k][1])] += 2.0 / 4 * 0.5 / 4;
    }
    row[cnode(n, s, i, j)] += 0.25;
}
static void cc_matrix(int n, double *S) {
    int N = 6 * n + 1;
    memset(S, 0, sizeof(double) * (size_t)N * N);
    for (int s = 0; s < n; s++) {
        cc_edge(n, s, 0, 0, 1, 0, 0, -1, 0, 0, S + (size_t)cnode(n, s, 1, 0) * N);
        cc_face(n, s, 0, 0, S + (size_t)cnode(n, s, 1, 1) * N, 1.0);
        cc_vertex(n, s, 1, 0, S + (size_t)cnode(n, s, 2, 0) * N);
        cc_edge(n, s, 1, 0, 1, 1, 0, 0, 1, 0, S + (size_t)cnode(n, s, 2, 1) * N);
        cc_vertex(n, s, 1, 1, S + (size_t)cnode(n, s, 2, 2) * N);
        cc_edge(n, s, 0, 1, 1, 1, 0, 0, 0, 1, S + (size_t)cnode(n, s, 1, 2) * N);
    }
    double *v = S; /* EV: (Q + 2R + (n-3)V)/n */
    for (int s = 0; s < n; s++) {
        cc_face(n, s, 0, 0, v, 1.0 / (n * n));
        v[0] += 2.0 / (n * n) * 0.5;
        v[cnode(n, s, 1, 0)] += 2.0 / (n * n) * 0.5;
    }
    v[0] += (n - 3.0) / n;
}

/* A planar eigen net: the two subdominant eigenvectors of the CC matrix as (x, y), z linear. */
static int eigen_net(int n, double *X, double *lam) {
    int N = 6 * n + 1;
    double *S = malloc(sizeof(double) * (size_t)N * N), *wr = malloc(sizeof(double) * N);
    double *wi = malloc(sizeof(double) * N), *V = malloc(sizeof(double) * (size_t)N * N);
    cc_matrix(n, S);
    lapack_int info = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'V', N, S, N, wr, wi, NULL, N, V, N);
    int ok = info == 0, k1 = -1, k2 = -1;
    double top = -1;
    for (int k = 0; k < N; k++) top = fmax(top, fabs(wr[k]));
    for (int k = 0; ok && k < N; k++) { /* the two largest below the eigenvalue 1 */
        if (fabs(wr[k] - 1) < 1e-9) continue;
        if (k1 < 0 || wr[k] > wr[k1]) { k2 = k1; k1 = k; }
        else if (k2 < 0 || wr[k] > wr[k2]) k2 = k;
    }
    ok = ok && k1 >= 0 && k2 >= 0 && fabs(wr[k1] - wr[k2]) < 1e-9 && fabs(wi[k1]) < 1e-12;
    for (int r = 0; ok && r < N; r++) {
        double x = V[(size_t)r * N + k1], y = V[(size_t)r * N + k2];
        X[3 * r] = x;
        X[3 * r + 1] = y;
        X[3 * r + 2] = 0.3 * x - 0.7 * y + 0.2;
    }
    *lam = ok ? wr[k1] : 0;
    free(S); free(wr); free(wi); free(V);
    return ok;
}

static void test_eigen_contraction(void) {
    double worst = 0, worst_plane = 0, worst_cc = 0;
    /* the paper's speeds, and the plan's exact-surround speeds (a ring of 1/2 first, bi5.h [R13]) */
    static const double H5[4] = {0.5, 0.75, 0.875, 0.875}, H3[2] = {0.5, 15.0 / 16.0};
    for (int q = 0; q < 14; q++) {
        int n = NS[q % 7];
        ccn__bi5 *b = NULL;
        if (q < 7) b = make_op(n);
        else {
            ccn_error e;
            CHECK(ccn__bi5_create(n, n == 3 ? H3 : H5, n == 3 ? 2 : 4, &b, &e) == CCN_OK, "%s", e.message);
        }
        if (!b) continue;
        double *X = malloc(sizeof(double) * 3 * (6 * (size_t)n + 1)), lcc;
        CHECK(eigen_net(n, X, &lcc), "n=%d: no Catmull-Clark eigen net", n);
        worst_cc = fmax(worst_cc, fabs(lcc - paper_lambda(n, 0.5)));
        ccn_status st;
        double *P = run_apply(b, X, NULL, &st);
        const double *ctr = P + ((size_t)3 * b->nsig * n) * 108; /* cap (0,0) */
        for (int s = 0; s < n; s++) {
            /* corner on spoke e_s of t~^r: ring 0's A[5][0], then ring (r-1)'s A[0][0] */
            double prev = 0;
            for (int r = 0; r <= b->nsig; r++) {
                const double *A = P + ((size_t)(3 * (r ? r - 1 : 0)) * n + s) * 108;
                const double *K = A + (r ? 0 : 5 * 6 * 3);
                double dist = sqrt(pow(K[0] - ctr[0], 2) + pow(K[1] - ctr[1], 2) + pow(K[2] - ctr[2], 2));
                if (r) worst = fmax(worst, fabs(dist / prev - paper_lambda(n, b->sig[r - 1])));
                prev = dist;
            }
        }
        double size = net_size(X, 6 * n + 1);
        for (int k = 0; k < ccn__bi5_num_patches(b) * 36; k++) {
            const double *p = P + 3 * (size_t)k;
            worst_plane = fmax(worst_plane, fabs(p[2] - (0.3 * p[0] - 0.7 * p[1] + 0.2)) / size);
        }
        free(P); free(X);
        ccn__bi5_destroy(b);
    }
    printf("  CC eigenvalue vs paper's lambda_1/2: %.1e; eigen-net contraction per ring vs "
           "lambda_sigma (both speed sets): %.1e; off-plane: %.1e\n", worst_cc, worst, worst_plane);
    CHECK(worst_cc <= 1e-12, "CC eigenvalue %g", worst_cc);
    CHECK(worst <= 1e-9, "ring contraction differs from lambda_sigma by %g", worst);
    CHECK(worst_plane <= 1e-10, "eigen net output leaves the plane by %g", worst_plane);
}

static void test_linear_precision(void) {
    double worst = 0;
    for (int q = 0; q < 7; q++) {
        int n = NS[q];
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        int N = 6 * n + 1;
        double *X = malloc(sizeof(double) * 3 * (size_t)N);
        for (int rep = 0; rep < 3; rep++) {
            double nx = rnd(), ny = rnd(), nz = 1 + tl_rand01(), h = rnd(); /* plane n.x = h */
            for (int k = 0; k < N; k++) {
                X[3 * k] = 3 * rnd();
                X[3 * k + 1] = 3 * rnd();
                X[3 * k + 2] = (h - nx * X[3 * k] - ny * X[3 * k + 1]) / nz;
            }
            ccn_status st;
            double *P = run_apply(b, X, NULL, &st);
            double nn = sqrt(nx * nx + ny * ny + nz * nz);
            for (int k = 0; k < ccn__bi5_num_patches(b) * 36; k++) {
                const double *p = P + 3 * (size_t)k;
                worst = fmax(worst, fabs(nx * p[0] + ny * p[1] + nz * p[2] - h) / nn / net_size(X, N));
            }
            free(P);
        }
        free(X);
        ccn__bi5_destroy(b);
    }
    printf("  planar nets: largest distance of a BB coefficient from the plane: %.1e (relative)\n", worst);
    CHECK(worst <= 1e-10, "planar net gives non-planar output (%g)", worst);
}

/* Shape of the output, de Casteljau vs power form, and ccn__bi5_eval vs the patches. */
static void test_degree_and_eval(void) {
    double e_dc = 0, e_ev = 0, e_cont = 0;
    for (int q = 0; q < 7; q++) {
        int n = NS[q];
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        CHECK(ccn__bi5_num_rings(b) == (n == 3 ? 1 : 3), "num_rings");
        CHECK(ccn__bi5_num_patches(b) == (3 * ccn__bi5_num_rings(b) + 1) * n, "num_patches");
        double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * (6 * (size_t)n + 1));
        make_net(n, X3);
        extract_cnet(n, X3, X);
        ccn_status st;
        double *P = run_apply(b, X, NULL, &st);
        surf_t S;
        surf_init(&S, n, b->nsig, b->sig, P);
        for (int k = 0; k < ccn__bi5_num_patches(b); k++)
            for (int rep = 0; rep < 4; rep++) {
                double u = tl_rand01(), v = tl_rand01(), a[3], c[3];
                decasteljau(P + (size_t)k * 108, u, v, a);
                pf_eval(S.M[k], u, v, 0, 0, c);
                e_dc = fmax(e_dc, vdiff(a, c));
            }
        for (int rep = 0; rep < 400; rep++) { /* eval: locate the patch, chain rule */
            int s = rep % n;
            double u = pow(tl_rand01(), 1 + rep % 7), v = pow(tl_rand01(), 1 + rep % 5);
            double p[3], du[3], dv[3], ref[3], rdu[3], rdv[3], scale = 1, uu = u, vv = v;
            ccn__bi5_eval(b, P, s, u, v, p, du, dv);
            int r = 0, kind = 0;
            for (; r < b->nsig; r++) {
                double rho = 1 - b->sig[r];
                if (uu >= rho || vv >= rho) { kind = uu >= rho ? (vv <= rho ? 0 : 1) : 2; break; }
                uu /= rho; vv /= rho; scale /= rho;
            }
            ring_eval(&S, r, kind, s, uu, vv, 0, 0, ref);
            ring_eval(&S, r, kind, s, uu, vv, 1, 0, rdu);
            ring_eval(&S, r, kind, s, uu, vv, 0, 1, rdv);
            for (int c = 0; c < 3; c++) { rdu[c] *= scale; rdv[c] *= scale; }
            e_ev = fmax(e_ev, fmax(vdiff(p, ref), fmax(vdiff(du, rdu), vdiff(dv, rdv)) / scale));
            /* continuity of eval across the ring boundary u = rho_1 */
            double pa[3], pb[3], t1[3], t2[3];
            ccn__bi5_eval(b, P, s, 1 - b->sig[0], v, pa, t1, t2);
            ccn__bi5_eval(b, P, s, 1 - b->sig[0] - 1e-13, v, pb, t1, t2);
            e_cont = fmax(e_cont, vdiff(pa, pb));
        }
        free(S.M); free(P); free(X3); free(X);
        ccn__bi5_destroy(b);
    }
    printf("  de Casteljau vs power form %.1e; eval vs patches (value, derivatives) %.1e; "
           "eval across ring boundary %.1e\n", e_dc, e_ev, e_cont);
    CHECK(e_dc <= 1e-12, "de Casteljau vs power form %g", e_dc);
    CHECK(e_ev <= 1e-11, "ccn__bi5_eval vs the patches %g", e_ev);
    CHECK(e_cont <= 1e-11, "ccn__bi5_eval jumps at a ring boundary %g", e_cont);
}

/* Translating the net translates the output (rows sum to 1); relabelling the sectors
 * relabels the output (rotational equivariance of the stencil). */
static void test_invariance(void) {
    double e_tr = 0, e_rot = 0;
    for (int q = 0; q < 7; q++) {
        int n = NS[q], N = 6 * n + 1;
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * N);
        double *Y = malloc(sizeof(double) * 3 * N), t[3] = {10 * rnd(), 10 * rnd(), 10 * rnd()};
        make_net(n, X3);
        extract_cnet(n, X3, X);
        ccn_status st;
        double *P = run_apply(b, X, NULL, &st);
        for (int k = 0; k < N; k++)
            for (int c = 0; c < 3; c++) Y[3 * k + c] = X[3 * k + c] + t[c];
        double *Q = run_apply(b, Y, NULL, &st);
        int np = ccn__bi5_num_patches(b);
        double size = net_size(X, N) + fmax(fabs(t[0]), fmax(fabs(t[1]), fabs(t[2])));
        for (int k = 0; k < np * 36; k++)
            for (int c = 0; c < 3; c++) e_tr = fmax(e_tr, fabs(Q[3 * k + c] - P[3 * k + c] - t[c]) / size);
        free(Q);
        int sh = 1 + (int)(tl_rand01() * (n - 1)); /* new sector k = old sector k + sh */
        memcpy(Y, X, sizeof(double) * 3);
        for (int k = 0; k < n; k++)
            memcpy(Y + 3 * (1 + 6 * k), X + 3 * (1 + 6 * ((k + sh) % n)), sizeof(double) * 18);
        Q = run_apply(b, Y, NULL, &st);
        for (int p = 0; p < np; p++) {
            int type = p / n, s = p % n, p2 = type * n + (s + sh) % n;
            for (int k = 0; k < 108; k++) e_rot = fmax(e_rot, fabs(Q[(size_t)p * 108 + k] - P[(size_t)p2 * 108 + k]));
        }
        free(Q); free(P); free(X3); free(X); free(Y);
        ccn__bi5_destroy(b);
    }
    printf("  translation (relative) %.1e, sector relabelling %.1e\n", e_tr, e_rot);
    CHECK(e_tr <= 1e-10, "translation invariance %g (relative)", e_tr);
    CHECK(e_rot <= 1e-12, "rotational equivariance %g", e_rot);
}

/* ---------------------------------------------------------------------------------------- */
/* 4. non-uniform intervals                                                                  */

static void merge(defects *D, defects *d1, double size) {
    relative(d1, size);
    D->internal = fmax(D->internal, d1->internal); D->spokes = fmax(D->spokes, d1->spokes);
    D->r2r = fmax(D->r2r, d1->r2r); D->cap_ring = fmax(D->cap_ring, d1->cap_ring);
    D->surround = fmax(D->surround, d1->surround); D->cap_c0 = fmax(D->cap_c0, d1->cap_c0);
    D->cap_angle = fmax(D->cap_angle, d1->cap_angle);
    D->curv = fmax(D->curv, d1->curv);
}

/* kappa = 1 (alternating intervals, even n) is the uniform operator; unsupported intervals are
 * refused with CCN_ERR_KNOTS; the symmetric tau is the kappa = 1 case of the NU tau. */
static void test_nu_classes(void) {
    ccn__bi5 *b = make_op(6);
    if (!b) return;
    int n = 6, N = 6 * n + 1;
    double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * N);
    make_net(n, X3);
    extract_cnet(n, X3, X);
    double d[6] = {0.3, 1.7, 0.3, 1.7, 0.3, 1.7}, e = 0;
    ccn_status st, st2;
    double *P = run_apply(b, X, NULL, &st), *Q = run_apply(b, X, d, &st2);
    CHECK(st == CCN_OK && st2 == CCN_OK, "apply");
    for (int k = 0; k < ccn__bi5_num_patches(b) * 108; k++) e = fmax(e, fabs(P[k] - Q[k]));
    printf("  n=6, intervals (0.3,1.7,...) (kappa = 1) vs uniform: %.1e\n", e);
    CHECK(e == 0.0, "kappa = 1 must give the uniform operator (%g)", e);
    free(P); free(Q); free(X3); free(X);
    ccn__bi5_destroy(b);

    b = make_op(5);
    if (!b) return;
    double d5[5] = {1, 1.3, 0.8, 1.1, 0.9}, X5[93] = {0};
    double *P5 = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(b));
    ccn_error err;
    st = ccn__bi5_apply(b, X5, d5, NULL, P5, &err);
    printf("  n=5, intervals (1,1.3,0.8,1.1,0.9): status %s: %s\n", ccn_status_name(st), err.message);
    CHECK(st == CCN_ERR_KNOTS, "unsupported intervals must give CCN_ERR_KNOTS");
    double bad[5] = {1, 1, -1, 1, 1};
    CHECK(ccn__bi5_apply(b, X5, bad, NULL, P5, &err) == CCN_ERR_KNOTS, "negative interval accepted");
    free(P5);
    double kap1[16], et = 0;
    for (int k = 0; k < 16; k++) kap1[k] = 1.0;
    for (int q = 1; q < 7; q++) {
        int nn = NS[q];
        double complex chi[16], tau[36], *taus = malloc(sizeof(double complex) * 36 * (size_t)nn);
        ccn__bi5_charmap(nn, 0.875, chi, NULL, &err);
        CHECK(ccn__bi5_tau(nn, chi, tau, &err) == CCN_OK, "tau");
        CHECK(ccn__bi5_tau_nu(nn, chi, kap1, NULL, 0, taus, &err) == CCN_OK, "tau_nu: %s", err.message);
        for (int s = 0; s < nn; s++)
            for (int k = 0; k < 36; k++) et = fmax(et, cabs(taus[s * 36 + k] - cexp(CCN_BI5_I * TWO_PI * s / nn) * tau[k]));
        free(taus);
    }
    printf("  NU tau with kappa = 1 vs symmetric tau (n = 5..16): %.1e\n", et);
    CHECK(et <= 1e-11, "NU tau (kappa = 1) differs from the symmetric tau by %g", et);
    ccn__bi5_destroy(b);
}

/* n = 0 mod 4 with period-4 intervals: kappa != 1 but d_{s+2} = d_{s-2}, so the sectors'
 * bicubic grids agree: exact non-uniform construction, checked in knot units. */
static void test_nu_period4(void) {
    static const int ns[3] = {8, 12, 16}, cnt[3] = {12, 8, 6};
    for (int q = 0; q < 3; q++) {
        int n = ns[q], N = 6 * n + 1;
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        defects D = {0};
        double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * N);
        double d[16], kmin = 1e9, kmax = 0;
        for (int k = 0; k < cnt[q]; k++) {
            for (int s = 0; s < 4; s++) d[s] = 0.4 + 2 * tl_rand01();
            for (int s = 4; s < n; s++) d[s] = d[s - 4];
            for (int s = 0; s < n; s++) {
                double kp = d[(s + 1) % n] / d[(s + n - 1) % n];
                kmin = fmin(kmin, kp); kmax = fmax(kmax, kp);
            }
            make_net(n, X3);
            extract_cnet(n, X3, X);
            ccn_status st;
            double *P = run_apply(b, X, d, &st);
            CHECK(st == CCN_OK, "NU apply n=%d", n);
            surf_t S;
            surf_init(&S, n, b->nsig, b->sig, P);
            defects d1 = {0};
            measure(&S, X3, d, &d1);
            merge(&D, &d1, net_size(X3, 1 + 12 * n));
            free(S.M); free(P);
        }
        char what[80];
        snprintf(what, sizeof what, "NU n=%d (%d, k %.2f..%.2f)", n, cnt[q], kmin, kmax);
        report(what, &D);
        free(X3); free(X);
        ccn__bi5_destroy(b);
    }
}

/* Bicubic hole patch of sector s's virtual NU grid (SPEC §9.1) by Cox-de Boor derivatives at
 * the corner (0,0) converted to BB form: border[a*4+b][3]. */
static void nu_hole_border(int n, const double *X3, const double *d, int s, double *p) {
    double T[4][4][3];
    for (int a = 0; a < 4; a++)
        for (int c = 0; c < 4; c++) {
            double out[3], f = 1;
            surround(n, X3, d, s, -1, -1, 0, 0, a, c, out);
            for (int q = 2; q <= a; q++) f *= q;
            for (int q = 2; q <= c; q++) f *= q;
            for (int k = 0; k < 3; k++) /* Taylor in hole units */
                T[a][c][k] = out[k] / f * pow(d[s], a) * pow(d[(s + 1) % n], c);
        }
    for (int a = 0; a < 4; a++)
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 3; k++) {
                double acc = 0;
                for (int a2 = 0; a2 <= a; a2++)
                    for (int c2 = 0; c2 <= c; c2++)
                        acc += binom(a, a2) / binom(3, a2) * binom(c, c2) / binom(3, c2) * T[a2][c2][k];
                p[(a * 4 + c) * 3 + k] = (a || c) ? acc : 0;
            }
}

/* Arbitrary intervals through ccn__bi5_apply_border: the caller's border (here: each sector's
 * NU hole patch, made C0 + C2 across the spokes) -> rings C2 in knot units, ring x^0 joins
 * the border C2, cap G1 and C1 with the last ring. */
static void test_nu_border(void) {
    static const int ns[4] = {3, 5, 7, 10};
    for (int q = 0; q < 4; q++) {
        int n = ns[q], N = 1 + 12 * n;
        ccn__bi5 *b = make_op(n);
        if (!b) continue;
        defects D = {0};
        double *X3 = malloc(sizeof(double) * 3 * (size_t)N), *B = malloc(sizeof(double) * 108 * (size_t)n);
        double d[16], e_join = 0, ctr[3];
        for (int rep = 0; rep < 6; rep++) {
            for (int s = 0; s < n; s++) d[s] = 0.3 + 2 * tl_rand01();
            make_net(n, X3);
            for (int s = 0; s < n; s++) { /* raise each sector's NU hole patch to bi-5 */
                double p3[48];
                nu_hole_border(n, X3, d, s, p3);
                for (int i = 0; i < 6; i++)
                    for (int j = 0; j < 6; j++)
                        for (int k = 0; k < 3; k++) {
                            double acc = 0;
                            for (int a = 0; a < 4; a++)
                                for (int c = 0; c < 4; c++)
                                    acc += E35[i][a] * E35[j][c] * p3[(a * 4 + c) * 3 + k];
                            B[(size_t)s * 108 + (i * 6 + j) * 3 + k] = acc;
                        }
            }
            for (int s = 0; s < n; s++) { /* make it C0 + NU C2 across spoke e_s */
                int p = (s + n - 1) % n;
                double r = d[(s + 1) % n] / d[p];
                for (int i = 3; i < 6; i++)
                    for (int k = 0; k < 3; k++) {
                        double *P0 = B + (size_t)s * 108 + (i * 6) * 3 + k, *Q0 = B + (size_t)p * 108 + i * 3 + k;
                        double P2 = B[(size_t)s * 108 + (i * 6 + 2) * 3 + k], Pm2 = B[(size_t)p * 108 + (2 * 6 + i) * 3 + k];
                        double p0 = 0.5 * (*P0 + *Q0), pm1 = ((1 + r) * (1 + r) * p0 + r * r * Pm2 - P2) / (2 * r * (1 + r));
                        *P0 = *Q0 = p0;
                        B[(size_t)p * 108 + (1 * 6 + i) * 3 + k] = pm1;
                        B[(size_t)s * 108 + (i * 6 + 1) * 3 + k] = p0 + r * (p0 - pm1);
                    }
            }
            memcpy(ctr, X3, sizeof ctr);
            double *P = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(b));
            ccn_error err;
            ccn_status st = ccn__bi5_apply_border(b, B, d, ctr, P, &err);
            CHECK(st == CCN_OK, "apply_border n=%d: %s", n, err.message);
            surf_t S;
            surf_init(&S, n, b->nsig, b->sig, P);
            defects d1 = {0};
            measure(&S, NULL, d, &d1);
            double size = net_size(X3, N);
            merge(&D, &d1, size);
            for (int s = 0; s < n; s++) { /* x^0 vs the border (rows 3..5 / columns 3..5) */
                double M[6][6][3], a[3], c[3], rho = 1 - b->sig[0];
                power_form(5, B + (size_t)s * 108, M);
                for (int qq = 0; qq <= 8; qq++) {
                    double t = qq / 8.0;
                    for (int k = 0; k <= 2; k++)
                        for (int l = 0; k + l <= 2; l++) {
                            ring_eval(&S, 0, t <= rho ? 0 : 1, s, 1, t, k, l, a);
                            pf_eval(M, 1, t, k, l, c);
                            e_join = fmax(e_join, vdiff(a, c) / size);
                            ring_eval(&S, 0, t <= rho ? 2 : 1, s, t, 1, l, k, a);
                            pf_eval(M, t, 1, l, k, c);
                            e_join = fmax(e_join, vdiff(a, c) / size);
                        }
                }
            }
            free(S.M); free(P);
        }
        D.surround = e_join;
        char what[64];
        snprintf(what, sizeof what, "NU border n=%d (6 nets)", n);
        report(what, &D);
        free(X3); free(B);
        ccn__bi5_destroy(b);
    }
}

/* ---------------------------------------------------------------------------------------- */
/* 5. cap size vs 8 Catmull-Clark steps (K&P Sec. 7; SPEC §8.8)                               */

/* Diameter of the region bounded by the given boundary samples (max pairwise distance). */
static double diameter(const double *pts, int m) {
    double dmax = 0;
    for (int a = 0; a < m; a++)
        for (int c = a + 1; c < m; c++)
            dmax = fmax(dmax, sqrt(pow(pts[3 * a] - pts[3 * c], 2) + pow(pts[3 * a + 1] - pts[3 * c + 1], 2)
                                   + pow(pts[3 * a + 2] - pts[3 * c + 2], 2)));
    return dmax;
}

static void cap_size_row(int n, const double *sig, int nsig, double *ratio_lam, double *ratio_geo) {
    ccn__bi5 *b = NULL;
    ccn_error err;
    *ratio_lam = *ratio_geo = NAN;
    if (ccn__bi5_create(n, sig, nsig, &b, &err)) return;
    double *X = malloc(sizeof(double) * 3 * (6 * (size_t)n + 1)), lcc;
    if (eigen_net(n, X, &lcc)) {
        ccn_status st;
        double *P = run_apply(b, X, NULL, &st);
        surf_t S;
        surf_init(&S, n, nsig, b->sig, P);
        int m = 2 * 16 * n;
        double *hole = malloc(sizeof(double) * 3 * (size_t)m), *cap = malloc(sizeof(double) * 3 * (size_t)m);
        for (int s = 0, k = 0; s < n; s++)
            for (int q = 0; q < 16; q++, k += 2) {
                double t = q / 16.0;
                ring_eval(&S, 0, t <= 1 - sig[0] ? 0 : 1, s, 1, t, 0, 0, hole + 3 * k);     /* level-0 hole */
                ring_eval(&S, 0, t <= 1 - sig[0] ? 2 : 1, s, t, 1, 0, 0, hole + 3 * k + 3);
                ring_eval(&S, nsig, 0, s, 1, t, 0, 0, cap + 3 * k);                           /* cap boundary */
                ring_eval(&S, nsig, 0, s, t, 1, 0, 0, cap + 3 * k + 3);
            }
        double Lam = 1;
        for (int r = 0; r < nsig; r++) Lam *= paper_lambda(n, sig[r]);
        *ratio_lam = Lam / pow(paper_lambda(n, 0.5), 8);
        *ratio_geo = diameter(cap, m) / (pow(lcc, 8) * diameter(hole, m));
        free(hole); free(cap); free(S.M); free(P);
    }
    free(X);
    ccn__bi5_destroy(b);
}

static void test_cap_size(void) {
    const char *path = getenv("BI5_CAP_SIZE_MD");
    FILE *md = path ? fopen(path, "w") : NULL;
    if (md)
        fprintf(md, "# Cap size vs 8 Catmull-Clark steps\n\n"
                    "Written by `BI5_CAP_SIZE_MD=tests/bi5/CAP_SIZE.md build/tests/test_bi5` "
                    "(tests/c/test_bi5.c, test_cap_size).\n\n"
                    "Net: the Catmull-Clark eigen net (characteristic map) of valence n. "
                    "`lambda ratio` = prod lambda_sigma_r / lambda_1/2^8 (paper Sec. 4.1); "
                    "`measured` = diameter of the cap / diameter of the level-0 hole shrunk by "
                    "lambda_1/2^8 (the hole that remains after 8 Catmull-Clark steps); "
                    "`CC steps` = log(prod lambda_sigma_r) / log(lambda_1/2). "
                    "Below 1 = the cap is smaller than after 8 CC steps (K&P Sec. 7).\n\n"
                    "| n | speeds | lambda ratio | measured | CC steps |\n|---|---|---|---|---|\n");
    printf("   n  speeds           lambda-ratio  measured  CC-steps\n");
    for (int n = 3; n <= 10; n++) {
        if (n == 4) continue;
        for (int v = 0; v < (n == 3 ? 2 : 1); v++) {
            const double *sig = v ? SIG3 : SIG5;
            int nsig = v ? 1 : 3;
            double rl, rg, Lam = 1;
            cap_size_row(n, sig, nsig, &rl, &rg);
            for (int r = 0; r < nsig; r++) Lam *= paper_lambda(n, sig[r]);
            double steps = log(Lam) / log(paper_lambda(n, 0.5));
            const char *sp = v ? "(15/16)" : "(3/4,7/8,7/8)";
            printf("  %2d  %-15s  %10.3f  %8.3f  %8.2f\n", n, sp, rl, rg, steps);
            if (md) fprintf(md, "| %d | %s | %.3f | %.3f | %.2f |\n", n, sp, rl, rg, steps);
            CHECK(isfinite(rl) && isfinite(rg), "cap size n=%d", n);
            if (n > 4 && !v) CHECK(rl < 1 && rg < 1, "n=%d: cap not smaller than 8 CC steps", n);
        }
    }
    if (md) fclose(md);
}

/* ---------------------------------------------------------------------------------------- */
/* 6. arguments, large valence                                                               */

static void test_errors(void) {
    ccn__bi5 *b = NULL;
    ccn_error err;
    double bad[2] = {0.5, 1.0};
    CHECK(ccn__bi5_create(4, SIG5, 3, &b, &err) == CCN_ERR_ARGUMENT, "n = 4 accepted");
    CHECK(ccn__bi5_create(2, SIG5, 3, &b, &err) == CCN_ERR_ARGUMENT, "n = 2 accepted");
    CHECK(ccn__bi5_create(5, bad, 2, &b, &err) == CCN_ERR_ARGUMENT, "sigma = 1 accepted");
    CHECK(ccn__bi5_create(5, SIG5, 0, &b, &err) == CCN_ERR_ARGUMENT, "no rings accepted");
    CHECK(strstr(err.message, "rings") != NULL, "message '%s'", err.message);
    b = make_op(5);
    if (!b) return;
    double X[93] = {0}, *P = malloc(sizeof(double) * 108 * 50);
    X[40] = NAN;
    CHECK(ccn__bi5_apply(b, X, NULL, NULL, P, &err) == CCN_ERR_ARGUMENT, "NaN accepted");
    CHECK(ccn__bi5_apply(b, NULL, NULL, NULL, P, &err) == CCN_ERR_ARGUMENT, "NULL accepted");
    free(P);
    ccn__bi5_destroy(b);
}

static void test_valence_32(void) {
    int n = 32, N = 6 * n + 1;
    ccn__bi5 *b = make_op(n);
    if (!b) return;
    double *X3 = malloc(sizeof(double) * 3 * (1 + 12 * (size_t)n)), *X = malloc(sizeof(double) * 3 * N);
    make_net(n, X3);
    extract_cnet(n, X3, X);
    ccn_status st;
    double *P = run_apply(b, X, NULL, &st);
    surf_t S;
    surf_init(&S, n, b->nsig, b->sig, P);
    defects D = {0};
    measure(&S, X3, NULL, &D);
    relative(&D, net_size(X3, 1 + 12 * n));
    report("n=32 (1 net)", &D);
    free(S.M); free(P); free(X3); free(X);
    ccn__bi5_destroy(b);
}

int main(void) {
    RUN(test_vectors_lambda);
    RUN(test_vectors_chi);
    RUN(test_vectors_tau);
    RUN(test_vectors_example);
    RUN(test_random_nets);
    RUN(test_eigen_contraction);
    RUN(test_linear_precision);
    RUN(test_degree_and_eval);
    RUN(test_invariance);
    RUN(test_nu_classes);
    RUN(test_nu_period4);
    RUN(test_nu_border);
    RUN(test_cap_size);
    RUN(test_errors);
    RUN(test_valence_32);
    return TEST_SUMMARY();
}
