/* The guide g (paper Sec. 3, 4.2; SPEC §4): piecewise total degree 6 on the n triangles
 * (O, V_s, V_{s+1}), C1 across the rays, one cubic expansion at O. Explicit BB
 * parametrisation (SPEC §4.2), composite jets [g o phi] (SPEC §2.3) and the least-squares fit
 * to the c-net's tensor-border (SPEC §4.4, [R3]). */
#include "bi5/guide.h"

#include "base/error.h"
#include "bi5/bernstein.h"

#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

/* ---- explicit BB parametrisation (SPEC §4.2) ------------------------------------------- */

#define GROW(s, i, j, k) (bb + ((size_t)(s) * CCN_BI5_NTRI + (size_t)ccn__bi5_tri(i, j, k)) * (size_t)m)

static void vset(double *d, const double *a, int32_t m) { memcpy(d, a, sizeof(double) * (size_t)m); }
static void vaxpy(double *d, double w, const double *a, int32_t m) {
    for (int32_t c = 0; c < m; c++) d[c] += w * a[c];
}

/* Cubic part (b_{ijk}, i >= 3) of sector s+1 from sector s: (2) i<=3, (3) i<=3, (4) i=2,3,
 * (5) i=3 all at once as the blossom identity V_{s+2} = w2 O + w0 V_s + w1 V_{s+1}:
 * b^{s+1}_{a,b,c} = sum_{al+be+ga=c} c!/(al! be! ga!) w0^al w1^be w2^ga b^s_{a+ga, al, b+be}. */
static void propagate_cubic(double *bb, int32_t m, int32_t s, double c) {
    const double w[3] = {-1.0, 2.0 * c, 2.0 * (1.0 - c)};
    static const double fact[4] = {1, 1, 2, 6};
    for (int32_t a = 3; a <= 6; a++)
        for (int32_t cc = 0; cc <= 6 - a; cc++) {
            int32_t bq = 6 - a - cc;
            double *dst = GROW(s + 1, a, bq, cc);
            memset(dst, 0, sizeof(double) * (size_t)m);
            for (int32_t al = 0; al <= cc; al++)
                for (int32_t be = 0; be <= cc - al; be++) {
                    int32_t ga = cc - al - be;
                    double wt = fact[cc] / (fact[al] * fact[be] * fact[ga])
                                * pow(w[0], al) * pow(w[1], be) * pow(w[2], ga);
                    vaxpy(dst, wt, GROW(s, a + ga, al, bq + be), m);
                }
        }
}

void ccn__bi5_guide_bb(int32_t n, const double *par, int32_t m, double *bb) {
    static const int32_t black_s[3][3] = {{2, 1, 3}, {1, 1, 4}, {0, 1, 5}};
    static const int32_t black_s1[3][3] = {{2, 3, 1}, {1, 4, 1}, {0, 5, 1}};
    static const int32_t gold[6][3] = {{2, 2, 2}, {1, 3, 2}, {1, 2, 3}, {0, 4, 2}, {0, 3, 3}, {0, 2, 4}};
    double c = cos(2.0 * CCN_BI5_PI / n);
    memset(bb, 0, sizeof(double) * (size_t)n * CCN_BI5_NTRI * (size_t)m);
    int32_t q = 0; /* 1. cub[10]: b^0_{6-mm, a, mm-a} */
    for (int32_t mm = 0; mm <= 3; mm++)
        for (int32_t a = mm; a >= 0; a--) vset(GROW(0, 6 - mm, a, mm - a), par + (size_t)(q++) * m, m);
    for (int32_t s = 0; s + 1 < n; s++) propagate_cubic(bb, m, s, c);
    for (int32_t s = 0; s < n; s++) { /* 2. black, 3. gold */
        int32_t s1 = (s + 1) % n;
        const double *pb = par + (size_t)(10 + 6 * s) * m, *pg = par + (size_t)(10 + 6 * n + 6 * s) * m;
        for (int32_t k = 0; k < 3; k++) {
            vset(GROW(s, black_s[k][0], black_s[k][1], black_s[k][2]), pb + (size_t)k * m, m);
            vset(GROW(s1, black_s1[k][0], black_s1[k][1], black_s1[k][2]), pb + (size_t)(3 + k) * m, m);
        }
        for (int32_t k = 0; k < 6; k++)
            vset(GROW(s, gold[k][0], gold[k][1], gold[k][2]), pg + (size_t)k * m, m);
    }
    for (int32_t i = 4; i <= 6; i++) /* 4. (3') then (2) */
        for (int32_t s = 0; s < n; s++) {
            int32_t s1 = (s + 1) % n;
            double *dst = GROW(s, 6 - i, 0, i);
            memset(dst, 0, sizeof(double) * (size_t)m);
            vaxpy(dst, 0.5 / c, GROW(s, 6 - i, 1, i - 1), m);
            vaxpy(dst, 0.5 / c, GROW(s1, 6 - i, i - 1, 1), m);
            vaxpy(dst, 1.0 - 1.0 / c, GROW(s, 7 - i, 0, i - 1), m);
            vset(GROW(s1, 6 - i, i, 0), dst, m);
        }
}

/* ---- composite jets (SPEC §2.3) -------------------------------------------------------- */

/* Truncated product of bivariate series (exponents <= 2 in each variable). */
static void series_mul(const double A[9], const double B[9], double C[9]) {
    double out[9] = {0};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            for (int c = 0; c < 3 - a; c++)
                for (int e = 0; e < 3 - b; e++) out[(a + c) * 3 + b + e] += A[a * 3 + b] * B[c * 3 + e];
    memcpy(C, out, sizeof out);
}

/* Series of the 28 Bernstein polynomials B_ijk(l0,l1,l2) of the sector-0 triangle composed
 * with a planar series z = X + iY: l2 = Y / sin(theta), l1 = X - l2 cos(theta), l0 = 1-l1-l2. */
static void bernstein_series(int32_t n, const double complex T[9], double Bs[28][9]) {
    double th = 2.0 * CCN_BI5_PI / n, l[3][9], pw[3][7][9];
    for (int k = 0; k < 9; k++) {
        l[2][k] = cimag(T[k]) / sin(th);
        l[1][k] = creal(T[k]) - l[2][k] * cos(th);
        l[0][k] = (k == 0 ? 1.0 : 0.0) - l[1][k] - l[2][k];
    }
    for (int v = 0; v < 3; v++) {
        memset(pw[v][0], 0, sizeof pw[v][0]);
        pw[v][0][0] = 1.0;
        for (int p = 1; p <= 6; p++) series_mul(pw[v][p - 1], l[v], pw[v][p]);
    }
    static const double fact[7] = {1, 1, 2, 6, 24, 120, 720};
    for (int32_t i = 0; i <= 6; i++)
        for (int32_t k = 0; k <= 6 - i; k++) {
            int32_t j = 6 - i - k, t = ccn__bi5_tri(i, j, k);
            double tmp[9];
            series_mul(pw[0][i], pw[1][j], tmp);
            series_mul(tmp, pw[2][k], Bs[t]);
            for (int e = 0; e < 9; e++) Bs[t][e] *= fact[6] / (fact[i] * fact[j] * fact[k]);
        }
}

void ccn__bi5_sample(int32_t n, const double complex *phi, int32_t d, double mu,
                     unsigned corners, double S[36 * 28]) {
    memset(S, 0, sizeof(double) * 36 * 28);
    for (int32_t cn = 0; cn < 4; cn++) {
        if (!(corners & (1u << cn))) continue;
        int32_t cu = cn & 1, cv = cn >> 1;
        double complex T[9];
        double Bs[28][9], Wu[9], Wv[9];
        ccn__bi5_taylor(phi, d, cu, cv, T);
        for (int k = 0; k < 9; k++) T[k] *= mu;
        bernstein_series(n, T, Bs);
        ccn__bi5_jet_weights(cu, Wu);
        ccn__bi5_jet_weights(cv, Wv);
        for (int32_t k = 0; k < 3; k++)
            for (int32_t l = 0; l < 3; l++) {
                int32_t ii = cu ? 5 - k : k, jj = cv ? 5 - l : l;
                for (int32_t t = 0; t < 28; t++) {
                    double acc = 0;
                    for (int32_t a = 0; a <= k; a++)
                        for (int32_t b = 0; b <= l; b++) acc += Wu[k * 3 + a] * Wv[l * 3 + b] * Bs[t][a * 3 + b];
                    S[(ii * 6 + jj) * 28 + t] = acc;
                }
            }
    }
}

/* ---- least-squares fit (SPEC §4.4) ----------------------------------------------------- */

static int32_t mask_list(int32_t idx[27]) {
    int32_t q = 0;
    for (int32_t i = 0; i < 6; i++)
        for (int32_t j = 0; j < 6; j++)
            if (ccn__bi5_in_mask(i, j)) idx[q++] = i * 6 + j;
    return q;
}

/* The fit's design matrix J (27n x (npar-1): the sampled tensor-borders of parameters 1.. of
 * every sector, sector s sampled by samp + s * sstride, 36 x 28) and its QR factorisations:
 * s0 = parameter 0's border, s12 = parameters 1 and 2's, qr/qtau = QR of J, qr1/qtau1 = QR of
 * J without parameters 1, 2 (b_510, b_501). */
static ccn_status fit_design(const ccn__bi5 *b, const double *samp, size_t sstride, double *s0, double *s12,
                             double *qr, double *qtau, double *qr1, double *qtau1, ccn_error *err) {
    int32_t n = b->n, P = b->npar, rows = 27 * n, idx[27];
    mask_list(idx);
    double *J = qr;
    for (int32_t s = 0; s < n; s++)
        for (int32_t e = 0; e < 27; e++)
            for (int32_t p = 0; p < P; p++) {
                double acc = 0;
                for (int32_t t = 0; t < 28; t++)
                    acc += samp[(size_t)s * sstride + idx[e] * 28 + t] * b->gpar[((size_t)s * 28 + t) * P + p];
                if (p == 0) s0[s * 27 + e] = acc;
                else J[(size_t)(p - 1) * rows + s * 27 + e] = acc;
            }
    /* parameters 1, 2 (b_510, b_501) apart, and the QR of the other columns */
    memcpy(s12, J, sizeof(double) * 2 * (size_t)rows);
    memcpy(qr1, J + 2 * (size_t)rows, sizeof(double) * (size_t)rows * (size_t)(P - 3));
    lapack_int info1 = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, rows, P - 3, qr1, rows, qtau1);
    lapack_int info = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, rows, P - 1, J, rows, qtau);
    if (info1 != 0) info = info1;
    double rmin = INFINITY, rmax = 0;
    for (int32_t p = 0; p < P - 1; p++) {
        double r = fabs(J[(size_t)p * rows + p]);
        rmin = r < rmin ? r : rmin;
        rmax = r > rmax ? r : rmax;
    }
    if (info != 0 || !(rmin > 1e-12 * rmax))
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1,
                         "bi5: guide least-squares matrix (27n x 12n+9, n = %d) is rank deficient "
                         "(|R| min/max = %g)", (int)n, rmax > 0 ? rmin / rmax : 0.0);
    return CCN_OK;
}

ccn_status ccn__bi5_guide_setup(ccn__bi5 *b, ccn_error *err) {
    int32_t n = b->n, P = b->npar, rows = 27 * n;
    ccn__bi5_sample(n, b->chi_half, 3, 1.0, 0xEu, b->samp0); /* corners (1,0),(1,1),(0,1) */
    double *eye = calloc((size_t)P * (size_t)P, sizeof(double));
    b->qr1 = malloc(sizeof(double) * (size_t)rows * (size_t)(P - 3));
    b->qtau1 = malloc(sizeof(double) * (size_t)P);
    b->s12 = malloc(sizeof(double) * 2 * (size_t)rows);
    if (!eye || !b->gpar || !b->qr || !b->qtau || !b->s0 || !b->qr1 || !b->qtau1 || !b->s12) {
        free(eye);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (guide, n = %d)", (int)n);
    }
    for (int32_t p = 0; p < P; p++) eye[(size_t)p * P + p] = 1.0;
    ccn__bi5_guide_bb(n, eye, P, b->gpar);
    free(eye);
    return fit_design(b, b->samp0, 0, b->s0, b->s12, b->qr, b->qtau, b->qr1, b->qtau1, err);
}

/* The design matrices of a fit whose sampling differs per sector (samp0s: n x 36 x 28, the
 * corner jets of [. o phi_s] at (1,0), (1,1), (0,1)): a copy of b with its own qr, qtau, s0,
 * qr1, qtau1, s12 (ccn__bi5_guide_nu_free releases them). */
ccn_status ccn__bi5_guide_setup_nu(const ccn__bi5 *b, const double *samp0s, ccn__bi5 *out, ccn_error *err) {
    int32_t n = b->n, P = b->npar, rows = 27 * n;
    *out = *b;
    out->qr = malloc(sizeof(double) * (size_t)rows * (size_t)(P - 1));
    out->qtau = malloc(sizeof(double) * (size_t)P);
    out->s0 = malloc(sizeof(double) * (size_t)rows);
    out->qr1 = malloc(sizeof(double) * (size_t)rows * (size_t)(P - 3));
    out->qtau1 = malloc(sizeof(double) * (size_t)P);
    out->s12 = malloc(sizeof(double) * 2 * (size_t)rows);
    ccn_status st = !out->qr || !out->qtau || !out->s0 || !out->qr1 || !out->qtau1 || !out->s12
                        ? ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (guide, n = %d)", (int)n)
                        : fit_design(b, samp0s, 36 * 28, out->s0, out->s12, out->qr, out->qtau, out->qr1, out->qtau1, err);
    if (st) ccn__bi5_guide_nu_free(out);
    return st;
}

void ccn__bi5_guide_nu_free(ccn__bi5 *c) {
    free(c->qr); free(c->qtau); free(c->s0); free(c->qr1); free(c->qtau1); free(c->s12);
    c->qr = c->qtau = c->s0 = c->qr1 = c->qtau1 = c->s12 = NULL;
}

/* The guide's Bezier coefficients from its parameters: gbb = gpar * par (m columns). */
static void guide_from_params(const ccn__bi5 *b, const double *par, int32_t m, double *gbb) {
    int32_t n = b->n, P = b->npar;
    for (int32_t r = 0; r < 28 * n; r++) {
        double *o = gbb + (size_t)r * m;
        memset(o, 0, sizeof(double) * (size_t)m);
        for (int32_t p = 0; p < P; p++) {
            double w = b->gpar[(size_t)r * P + p];
            if (w != 0.0) vaxpy(o, w, par + (size_t)p * m, m);
        }
    }
}

ccn_status ccn__bi5_guide_fit(const ccn__bi5 *b, const double *tcc, const double *b600,
                              int32_t m, double *gbb, ccn_error *err) {
    int32_t n = b->n, P = b->npar, rows = 27 * n, idx[27];
    mask_list(idx);
    double *tgt = malloc(sizeof(double) * (size_t)rows * (size_t)m);
    double *par = malloc(sizeof(double) * (size_t)P * (size_t)m);
    if (!tgt || !par) {
        free(tgt); free(par);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (guide fit)");
    }
    for (int32_t s = 0; s < n; s++)
        for (int32_t e = 0; e < 27; e++)
            for (int32_t c = 0; c < m; c++)
                tgt[(size_t)c * rows + s * 27 + e] =
                    tcc[((size_t)s * 36 + idx[e]) * m + c] - b->s0[s * 27 + e] * b600[c];
    lapack_int info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', rows, m, P - 1, b->qr, rows,
                                     b->qtau, tgt, rows);
    if (info == 0)
        info = LAPACKE_dtrtrs(LAPACK_COL_MAJOR, 'U', 'N', 'N', P - 1, m, b->qr, rows, tgt, rows);
    if (info != 0) {
        free(tgt); free(par);
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "bi5: guide QR solve failed (%d)", (int)info);
    }
    for (int32_t c = 0; c < m; c++) {
        par[c] = b600[c];
        for (int32_t p = 1; p < P; p++) par[(size_t)p * m + c] = tgt[(size_t)c * rows + p - 1];
    }
    guide_from_params(b, par, m, gbb);
    free(tgt); free(par);
    return CCN_OK;
}

ccn_status ccn__bi5_guide_fit_fixed(const ccn__bi5 *b, const double *tcc, const double *b600,
                                    const double *p12, int32_t m, double *gbb, ccn_error *err) {
    int32_t n = b->n, P = b->npar, rows = 27 * n, idx[27];
    mask_list(idx);
    double *tgt = malloc(sizeof(double) * (size_t)rows * (size_t)m), *par = malloc(sizeof(double) * (size_t)P * (size_t)m);
    if (!tgt || !par) {
        free(tgt); free(par);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (guide fit)");
    }
    for (int32_t s = 0; s < n; s++)
        for (int32_t e = 0; e < 27; e++)
            for (int32_t c = 0; c < m; c++) {
                int32_t r = s * 27 + e;
                tgt[(size_t)c * rows + r] = tcc[((size_t)s * 36 + idx[e]) * m + c] - b->s0[r] * b600[c] -
                                            b->s12[r] * p12[c] - b->s12[rows + r] * p12[m + c];
            }
    lapack_int info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', rows, m, P - 3, b->qr1, rows,
                                     b->qtau1, tgt, rows);
    if (info == 0)
        info = LAPACKE_dtrtrs(LAPACK_COL_MAJOR, 'U', 'N', 'N', P - 3, m, b->qr1, rows, tgt, rows);
    if (info != 0) {
        free(tgt); free(par);
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "bi5: guide QR solve failed (%d)", (int)info);
    }
    for (int32_t c = 0; c < m; c++) {
        par[c] = b600[c];
        par[m + c] = p12[c];
        par[2 * m + c] = p12[m + c];
        for (int32_t q = 3; q < P; q++) par[(size_t)q * m + c] = tgt[(size_t)c * rows + q - 3];
    }
    guide_from_params(b, par, m, gbb);
    free(tgt); free(par);
    return CCN_OK;
}

void ccn__bi5_project_p12(const double *b600, const double *normal, double p12[6]) {
    for (int q = 0; q < 2; q++) {
        double h = 0;
        for (int c = 0; c < 3; c++) h += (p12[3 * q + c] - b600[c]) * normal[c];
        for (int c = 0; c < 3; c++) p12[3 * q + c] -= h * normal[c];
    }
}

ccn_status ccn__bi5_guide_fit_plane(const ccn__bi5 *b, const double *tcc, const double *b600,
                                    const double *normal, double *gbb, ccn_error *err) {
    ccn_status st = ccn__bi5_guide_fit(b, tcc, b600, 3, gbb, err); /* for b_510, b_501 */
    if (st) return st;
    const int32_t t1 = ccn__bi5_tri(5, 1, 0), t2 = ccn__bi5_tri(5, 0, 1);
    double p[6], p12[6];
    for (int c = 0; c < 3; c++) p[c] = gbb[(size_t)t1 * 3 + c], p[3 + c] = gbb[(size_t)t2 * 3 + c];
    ccn__bi5_project_p12(b600, normal, p);
    for (int c = 0; c < 3; c++) p12[c] = p[c], p12[3 + c] = p[3 + c]; /* rows p1, p2 of m = 3 */
    return ccn__bi5_guide_fit_fixed(b, tcc, b600, p12, 3, gbb, err);
}
