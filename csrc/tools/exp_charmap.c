/* ccnurbs experiment charmap: the three-ring refinement matrix, its spectrum, and the
 * characteristic net refined for the regularity / injectivity tests (exp_charmap_geom.c). */
#include "exp.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- charmap: the three-ring matrix ------------------------------------------------------ */

typedef struct {
    int n, N;
    ccn_scheme scheme;
    int poly;
    ccn_mesh *L1;
    int32_t ev1, s01;
    int32_t *idx1, *idx2; /* 3-ring of L1 and of L1 refined once */
    int fallbacks;        /* num_ev_fallbacks of L1 refined once (the M of level 1) */
    double *A;            /* N x N row-major: fine 3-ring = A * coarse 3-ring */
} cm_ctx;

static void cm_free(cm_ctx *c) {
    ccn_mesh_destroy(c->L1);
    free(c->idx1); free(c->idx2); free(c->A);
}

static ccn_status ring_of(const ccn_mesh *m, int32_t ev, int32_t s0, int n, int32_t *idx,
                          ccn_error *err) {
    quad_mesh q;
    int rc = exp_quad_load(m, &q) ? -2 : exp_ring_grid(&q, ev, s0, n, 3, idx);
    exp_quad_free(&q);
    if (rc == -2) return exp_fail_memory(err);
    if (rc) {
        err->status = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "the EV's 3-ring is not a quad grid");
        return CCN_ERR_INTERNAL;
    }
    return CCN_OK;
}

/* Cage -> L1 and the 3-ring of L1. */
static ccn_status cm_setup(cm_ctx *c, const fan_cage *cage, const double *d, ccn_error *err) {
    ccn_mesh *m0 = NULL;
    c->N = 12 * c->n + 1;
    c->idx1 = malloc(sizeof(int32_t) * (size_t)c->N);
    c->idx2 = malloc(sizeof(int32_t) * (size_t)c->N);
    c->A = malloc(sizeof(double) * (size_t)c->N * (size_t)c->N);
    if (!c->idx1 || !c->idx2 || !c->A) return exp_fail_memory(err);
    ccn_status st = exp_fan_mesh(cage, d, &m0, err);
    c->ev1 = 0;
    c->s01 = exp_fan_vid(c->n, 3, 0, 1, 0);
    if (!st) st = exp_track_refine(m0, c->scheme, c->poly, &c->ev1, &c->s01, &c->L1, err);
    ccn_mesh_destroy(m0);
    if (!st) st = ring_of(c->L1, c->ev1, c->s01, c->n, c->idx1, err);
    return st;
}

/* Columns c0 .. c0+2 of A: 3-ring point c0+k of L1 has coordinate k equal to 1. */
static ccn_status cm_columns(cm_ctx *c, int c0, double *pos, int32_t nv, ccn_error *err) {
    memset(pos, 0, sizeof(double) * 3 * (size_t)nv);
    for (int k = 0; k < 3 && c0 + k < c->N; k++) pos[3 * (size_t)c->idx1[c0 + k] + k] = 1.0;
    ccn_status st = ccn_mesh_set_positions(c->L1, pos, err);
    int32_t ev = c->ev1, s0 = c->s01;
    ccn_mesh *L2 = NULL;
    if (!st) st = exp_track_refine(c->L1, c->scheme, c->poly, &ev, &s0, &L2, err);
    if (!st && c0 == 0) st = ring_of(L2, ev, s0, c->n, c->idx2, err);
    if (!st) {
        ccn_mesh_info in;
        ccn_mesh_get_info(L2, &in);
        c->fallbacks = in.num_ev_fallbacks;
        double *p2 = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
        if (!p2) st = exp_fail_memory(err);
        else {
            ccn_mesh_copy(L2, p2, NULL, NULL, NULL, NULL);
            for (int r = 0; r < c->N; r++)
                for (int k = 0; k < 3 && c0 + k < c->N; k++)
                    c->A[(size_t)r * c->N + c0 + k] = p2[3 * (size_t)c->idx2[r] + k];
            free(p2);
        }
    }
    ccn_mesh_destroy(L2);
    return st;
}

/* Row sums of A, and its 1-ring rows against ccn_ev_matrix (rows F_i, E_i, V of M are the
 * 3-ring points (i,1,1), (i,1,0), V; zero outside the 1-ring). */
static void cm_matrix_checks(const cm_ctx *c, const double *d, cm_result *r) {
    int n = c->n, N = c->N, sz = 2 * n + 1;
    r->rowsum_err = 0;
    for (int i = 0; i < N; i++) {
        double s = 0;
        for (int j = 0; j < N; j++) s += c->A[(size_t)i * N + j];
        r->rowsum_err = fmax(r->rowsum_err, fabs(s - 1.0));
    }
    double *M = malloc(sizeof(double) * (size_t)sz * (size_t)sz);
    int map[2 * EXP_MAX_N + 1];
    for (int i = 0; i < n; i++) {
        map[i] = exp_fan_vid(n, 3, i, 1, 1);
        map[n + i] = exp_fan_vid(n, 3, i, 1, 0);
    }
    map[2 * n] = 0;
    r->m_err = INFINITY;
    if (!M || ccn_ev_matrix_polyhedron(n, d, c->scheme, c->poly, M, NULL, NULL)) {
        free(M);
        return;
    }
    r->m_err = 0;
    for (int i = 0; i < sz; i++) {
        double *row = c->A + (size_t)map[i] * N, e = 0, in1 = 0;
        for (int j = 0; j < sz; j++) {
            e = fmax(e, fabs(row[map[j]] - M[i * sz + j]));
            in1 += fabs(row[map[j]]);
        }
        double all = 0;
        for (int j = 0; j < N; j++) all += fabs(row[j]);
        r->m_err = fmax(r->m_err, fmax(e, all - in1));
    }
    free(M);
}

static ccn_status cm_matrix(cm_ctx *c, const double *d, cm_result *r, ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_get_info(c->L1, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    if (!pos) return exp_fail_memory(err);
    ccn_status st = CCN_OK;
    for (int c0 = 0; c0 < c->N && !st; c0 += 3) st = cm_columns(c, c0, pos, in.num_verts, err);
    free(pos);
    if (st) return st;
    cm_matrix_checks(c, d, r);
    r->matrix_ok = r->rowsum_err <= 1e-12 && r->m_err <= 1e-12;
    return CCN_OK;
}

/* ---- charmap: spectrum ---------------------------------------------------------------- */

static double lambda_n(int n) {
    double cs = cos(2 * EXP_PI / n);
    return (5 + cs + sqrt((cs + 9) * (cs + 1))) / 16;
}

/* Indices of the eigenvalues by decreasing modulus (stable: conjugate pairs stay together). */
static void sort_by_modulus(const double *wr, const double *wi, int N, int *ord) {
    ord[0] = ord[1] = ord[2] = ord[3] = 0; /* N >= 6 */
    for (int i = 0; i < N; i++) ord[i] = i;
    for (int i = 1; i < N; i++) {
        int t = ord[i], j = i;
        double m = hypot(wr[t], wi[t]);
        while (j > 0 && hypot(wr[ord[j - 1]], wi[ord[j - 1]]) < m * (1 - 1e-13)) {
            ord[j] = ord[j - 1];
            j--;
        }
        ord[j] = t;
    }
}

/* x, y: an orthonormal basis of the (mu2, mu3) invariant subspace: the two eigenvectors, or
 * the real and imaginary parts of a complex pair's eigenvector. Returns -1 if degenerate. */
static int subdominant_plane(const double *vr, const double *wi, const int *ord, int N,
                             double *x, double *y) {
    int a = ord[1], b = ord[2];
    if (wi[a] != 0) { /* complex pair: columns a (real part) and a+1 (imaginary part) */
        a = wi[a] > 0 ? a : a - 1;
        b = a + 1;
    }
    for (int i = 0; i < N; i++) {
        x[i] = vr[(size_t)i * N + a];
        y[i] = vr[(size_t)i * N + b];
    }
    double xx = 0, xy = 0, yy = 0;
    for (int i = 0; i < N; i++) xx += x[i] * x[i];
    if (!(xx > 0)) return -1;
    for (int i = 0; i < N; i++) x[i] /= sqrt(xx);
    for (int i = 0; i < N; i++) xy += x[i] * y[i];
    for (int i = 0; i < N; i++) y[i] -= xy * x[i];
    for (int i = 0; i < N; i++) yy += y[i] * y[i];
    if (!(yy > 1e-12)) return -1; /* the eigenvectors are (numerically) parallel: defective */
    for (int i = 0; i < N; i++) y[i] /= sqrt(yy);
    return 0;
}

static void spectrum_verdict(const cm_ctx *c, const double *wr, const double *wi,
                             const int *ord, cm_result *r) {
    int N = c->N;
    for (int k = 0; k < 6; k++) r->mod[k] = k < N ? hypot(wr[ord[k]], wi[ord[k]]) : 0;
    r->mu2 = wr[ord[1]];
    r->mu3 = wr[ord[2]];
    r->im2 = fabs(wi[ord[1]]);
    r->split = hypot(wr[ord[1]] - wr[ord[2]], wi[ord[1]] - wi[ord[2]]) / r->mod[1];
    r->ratio = r->mod[3] / r->mod[1];
    double lam = lambda_n(c->n);
    r->lam_err = fmax(fabs(r->mu2 - lam), fabs(r->mu3 - lam));
    int one = fabs(wr[ord[0]] - 1) <= 1e-9 && wi[ord[0]] == 0 && r->mod[1] < 1 - 1e-9;
    int dbl = r->split <= 1e-7 && r->im2 <= 1e-7 * r->mod[1] && r->mu2 > 0;
    int sub = r->mod[3] < r->mod[1] * (1 - 1e-9);
    int lam_ok = c->scheme != CCN_SCHEME_EIGEN || r->fallbacks || r->lam_err <= 1e-9;
    r->spectrum = one && dbl && sub && lam_ok && !r->defective;
}

static ccn_status cm_spectrum(cm_ctx *c, cm_result *r, double *x, double *y, ccn_error *err) {
    int N = c->N;
    double *A = malloc(sizeof(double) * (size_t)N * N), *vr = malloc(sizeof(double) * (size_t)N * N);
    double *wr = malloc(sizeof(double) * (size_t)N), *wi = malloc(sizeof(double) * (size_t)N);
    int *ord = malloc(sizeof(int) * (size_t)N);
    ccn_status st = CCN_OK;
    if (!A || !vr || !wr || !wi || !ord || N < 6) st = exp_fail_memory(err);
    else {
        memcpy(A, c->A, sizeof(double) * (size_t)N * N);
        lapack_int info = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'V', N, A, N, wr, wi, NULL, 1, vr, N);
        if (info != 0) {
            err->status = st = CCN_ERR_INTERNAL;
            snprintf(err->message, sizeof err->message, "dgeev failed (info %d)", (int)info);
        } else {
            sort_by_modulus(wr, wi, N, ord);
            r->defective = subdominant_plane(vr, wi, ord, N, x, y) != 0;
            spectrum_verdict(c, wr, wi, ord, r);
        }
    }
    free(A); free(vr); free(wr); free(wi); free(ord);
    return st;
}

/* ---- charmap: the characteristic net ------------------------------------------------------ */

#define EXP_SURFACE_LEVEL 2 /* the limit-surface test uses rings 2..4 of level 2 */

/* Places the characteristic net (x, y, 0) on L1's 3-ring and refines it k levels. After level l
 * rings <= 2^(l+1) + 1 depend on the 3-ring only. Level 2: the limit patches of rings R = 2 to
 * 2R (control points up to ring 2R + 2 = 6 <= 9); level k: the control-net quads of rings
 * R = 2^(k-1) to 2R. */
static ccn_status cm_charring(cm_ctx *c, int k, const double *x, const double *y, cm_result *r,
                              ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_get_info(c->L1, &in);
    double *pos = calloc(3 * (size_t)in.num_verts, sizeof(double));
    if (!pos) return exp_fail_memory(err);
    for (int t = 0; t < c->N; t++) {
        pos[3 * (size_t)c->idx1[t]] = x[t];
        pos[3 * (size_t)c->idx1[t] + 1] = y[t];
    }
    ccn_status st = ccn_mesh_set_positions(c->L1, pos, err);
    free(pos);
    ccn_mesh *cur = NULL, *next = NULL;
    int32_t ev = c->ev1, s0 = c->s01;
    for (int l = 1; l <= k && !st; l++) {
        next = NULL;
        st = exp_track_refine(l > 1 ? cur : c->L1, c->scheme, c->poly, &ev, &s0, &next, err);
        ccn_mesh_destroy(cur);
        cur = next;
        if (!st && l == EXP_SURFACE_LEVEL)
            st = exp_surface_test(cur, c->n, ev, s0, 7, 2, r, err);
        if (!st && l == k)
            st = exp_net_test(cur, c->n, ev, s0, 1 << k, 1 << (k - 1), r, err);
    }
    ccn_mesh_destroy(cur);
    return st;
}

ccn_status exp_charmap_case(const fan_cage *cage, const double *d, ccn_scheme scheme, int poly, int k,
                            cm_result *r, ccn_error *err) {
    cm_ctx c = {.n = cage->n, .scheme = scheme, .poly = poly};
    memset(r, 0, sizeof *r);
    if (scheme == CCN_SCHEME_EIGEN && poly == CCN_POLY_SELECT) {
        /* the library's choice for these intervals, once: the matrix is built column by column
         * (one ccn_refine per three columns), each call would repeat the verification */
        double *M1 = malloc(sizeof(double) * (2 * (size_t)cage->n + 1) * (2 * (size_t)cage->n + 1));
        ccn_ev_info info;
        if (!M1) return exp_fail_memory(err);
        if (ccn_ev_matrix(cage->n, d, scheme, M1, &info, NULL) == CCN_OK && info.polyhedron)
            c.poly = info.polyhedron;
        else c.poly = CCN_POLY_PAPER;
        free(M1);
    }
    double x[12 * EXP_MAX_N + 1], y[12 * EXP_MAX_N + 1];
    ccn_status st = cm_setup(&c, cage, d, err);
    if (!st) st = cm_matrix(&c, d, r, err);
    r->fallbacks = c.fallbacks;
    if (!st) st = cm_spectrum(&c, r, x, y, err);
    if (!st && !r->defective) st = cm_charring(&c, k, x, y, r, err);
    cm_free(&c);
    return st;
}
