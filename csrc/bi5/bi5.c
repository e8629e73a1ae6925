/* The guided bi-5 operator (paper Sec. 4-6; SPEC §5-§7), the construction's entry point: create /
 * apply / eval. It runs the rings (bi5/rings.c), the guide (bi5/guide.c) and the cap
 * (bi5/tau.c, bi5/cap.c); none of them calls back. The construction is linear in the c-net and the centre point, so create runs
 * it once on unit nets and keeps sector 0's global stencil (SPEC §7); apply is one stencil
 * product per coordinate (the other sectors by cyclic relabelling of the net). */
#include "bi5/bi5.h"

#include "base/error.h"
#include "base/vec3.h"
#include "bi5/bernstein.h"
#include "bi5/cap.h"
#include "bi5/charmap.h"
#include "bi5/guide.h"
#include "bi5/rings.h"
#include "bi5/tau.h"

#include <stdlib.h>
#include <string.h>

/* ---- the whole construction on m columns (SPEC §5, §6) --------------------------------- */

/* [R15] Per-sector sampling matrices through the spoke-scaled characteristic border: the
 * planar tensor-border omega^s raise(chi) of every sector, spoke s scaled to d_s^e, made C2
 * with ratio kappa_s across each spoke (the C2-rule, as tau's green layers [R11]), rotated back
 * to sector 0's frame and sampled (corners `corners`, scale mu): S (n x 36 x 28). */
static int nu_samples(const ccn__bi5 *b, const double complex chi[16], double mu, unsigned corners,
                      const double *kap, const double *d, double e, double *S) {
    int32_t n = b->n;
    double complex *G = malloc(sizeof(double complex) * 36 * (size_t)n), G0[36], t0[36];
    if (!G) return -1;
    ccn__bi5_raise_chi(chi, G0);
    for (int32_t s = 0; s < n; s++)
        for (int32_t k = 0; k < 36; k++) G[s * 36 + k] = ccn__bi5_omega(n, s) * G0[k];
    ccn__bi5_spoke_scale(n, d, e, G);
    ccn__bi5_c2_rule(n, kap, 2, (double *)G);
    for (int32_t s = 0; s < n; s++) {
        for (int32_t k = 0; k < 36; k++) t0[k] = G[s * 36 + k] * ccn__bi5_omega(n, -s);
        ccn__bi5_sample(n, t0, 5, mu, corners, S + (size_t)s * 36 * 28);
    }
    free(G);
    return 0;
}

/* X: (6n+1) x m c-net or T0: the raised tensor-border t~^0 (n x 36 x m), b600: m centre values, d: spoke intervals (NULL: uniform), kap: C2-rule
 * ratios (NULL: 1), taus: per-sector cap taus (NULL: symmetric), e: the guide's domain ([R15];
 * 0: the symmetric characteristic border, else spokes d_s^e, with kap and d). out: patches x 36 x m. */
static ccn_status construct(const ccn__bi5 *b, const double *X, const double *T0,
                            const double *b600, int32_t m, const double *d, const double *kap,
                            const double complex *taus, const double *pieces, const double *normal,
                            const double *p12, double e, double *out, ccn_error *err) {
    int32_t n = b->n;
    size_t tsz = (size_t)n * 36 * (size_t)m, psz = 36 * (size_t)m;
    double *To = malloc(sizeof(double) * tsz), *Ti = malloc(sizeof(double) * tsz);
    double *gbb = malloc(sizeof(double) * (size_t)n * 28 * (size_t)m), *Ss = NULL;
    ccn_status st = CCN_OK;
    if (!To || !Ti || !gbb) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (construction)");
        goto done;
    }
    if (T0) memcpy(To, T0, sizeof(double) * tsz);
    else {                                                /* t~^0 = raise(t_CC) */
        ccn__bi5_tcc(n, X, d, m, Ti);
        ccn__bi5_raise_border(n, Ti, m, To);
    }
    int scaled = kap && d && e > 0; /* [R15]: the fit and the rings through the scaled border */
    ccn__bi5 bf = *b;
    const ccn__bi5 *fb = b;
    if (scaled) {
        Ss = malloc(sizeof(double) * (size_t)n * 36 * 28);
        if (!Ss || nu_samples(b, b->chi_half, 1.0, 0xEu, kap, d, e, Ss)) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (construction)");
            goto done;
        }
        if ((st = ccn__bi5_guide_setup_nu(b, Ss, &bf, err))) goto done;
        fb = &bf;
    }
    st = p12 ? ccn__bi5_guide_fit_fixed(fb, To, b600, p12, m, gbb, err)
         : normal && m == 3 ? ccn__bi5_guide_fit_plane(fb, To, b600, normal, gbb, err)
                            : ccn__bi5_guide_fit(fb, To, b600, m, gbb, err);
    if (scaled) ccn__bi5_guide_nu_free(&bf);
    if (st) goto done;
    for (int32_t r = 0; r < b->nsig; r++) {
        if (scaled) {                                               /* t^{r+1} = [g^{r+1} o chi~^d] */
            if (nu_samples(b, b->chi[r], b->Lam[r], 0xEu, kap, d, e, Ss)) {
                st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (construction)");
                goto done;
            }
            ccn__bi5_sample_border(n, Ss, 36 * 28, gbb, m, Ti);
        } else ccn__bi5_sample_border(n, b->samp[r], 0, gbb, m, Ti); /* t^{r+1} = [g^{r+1} o chi~] */
        ccn__bi5_c2_rule(n, kap, m, Ti);                           /* t~^{r+1} */
        for (int32_t s = 0; s < n; s++) {
            double *A = out + ((size_t)(3 * r + 0) * n + s) * psz;
            double *B = out + ((size_t)(3 * r + 1) * n + s) * psz;
            double *C = out + ((size_t)(3 * r + 2) * n + s) * psz;
            if (r == 0 && pieces) ccn__bi5_ring_sector_pieces(pieces + (size_t)s * 4 * psz, Ti + (size_t)s * psz, m, A, B, C);
            else ccn__bi5_ring_sector(To + (size_t)s * psz, Ti + (size_t)s * psz, b->sig[r], m, A, B, C);
        }
        double *tmp = To; To = Ti; Ti = tmp;
    }
    st = ccn__bi5_cap(b, gbb, To, m, kap, taus, out + (size_t)3 * b->nsig * n * psz, err);
done:
    free(Ss);
    free(To); free(Ti); free(gbb);
    return st;
}

/* ---- operator ------------------------------------------------------------------------- */

void ccn__bi5_destroy(ccn__bi5 *b) {
    if (!b) return;
    free(b->gpar); free(b->qr); free(b->qtau); free(b->s0); free(b->stencil);
    free(b->qr1); free(b->qtau1); free(b->s12); free(b->stencilF); free(b->w12);
    free(b);
}

int32_t ccn__bi5_num_rings(const ccn__bi5 *b) { return b->nsig; }
int32_t ccn__bi5_num_patches(const ccn__bi5 *b) { return (3 * b->nsig + 1) * b->n; }

static ccn_status check_create_args(int32_t n, const double *sigmas, int32_t nsig, ccn__bi5 **out,
                                    ccn_error *err) {
    if (!out || !sigmas)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL argument to create");
    if (n < 3 || n == 4 || n > 1000)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, -1,
                         "bi5: valence %d not supported (need n >= 3, n != 4)", (int)n);
    if (nsig < 1 || nsig > CCN_BI5_MAXSIG)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "bi5: number of rings %d not in [1, %d]", (int)nsig, CCN_BI5_MAXSIG);
    for (int32_t r = 0; r < nsig; r++)
        if (!(sigmas[r] > 0.0 && sigmas[r] < 1.0))
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "bi5: ring speed sigma_%d = %g is not in (0,1)", (int)r + 1, sigmas[r]);
    return CCN_OK;
}

/* Characteristic maps, sampling matrices, tau (everything that depends on n, sigmas). */
static ccn_status precompute(ccn__bi5 *b, ccn_error *err) {
    ccn_status st = ccn__bi5_charmap(b->n, 0.5, b->chi_half, NULL, err);
    double Lam = 1.0;
    for (int32_t r = 0; !st && r < b->nsig; r++) {
        st = ccn__bi5_charmap(b->n, b->sig[r], b->chi[r], &b->lam[r], err);
        Lam *= b->lam[r];
        b->Lam[r] = Lam;
        if (!st) ccn__bi5_sample(b->n, b->chi[r], 3, Lam, 0xEu, b->samp[r]);
    }
    if (!st) st = ccn__bi5_guide_setup(b, err);
    if (!st) st = ccn__bi5_tau(b->n, b->chi[b->nsig - 1], b->tau, err);
    if (!st) ccn__bi5_sample(b->n, b->tau, 5, Lam, 0xFu, b->scap);
    return st;
}

/* [R14] for the stencil path: the plain fit's b_510, b_501 (sector 0) as functionals of net and
 * centre (w12), and the construction with them given (stencilF, two more input columns). */
static ccn_status build_stencil_fixed(ccn__bi5 *b, ccn_error *err) {
    int32_t n = b->n, nc = 6 * n + 1, m = nc + 1, mf = nc + 3, np = ccn__bi5_num_patches(b), nt = 3 * b->nsig + 1;
    double *X = calloc((size_t)nc * (size_t)mf, sizeof(double)), *c0 = calloc((size_t)mf, sizeof(double));
    double *p12 = calloc(2 * (size_t)mf, sizeof(double)), *out = malloc(sizeof(double) * (size_t)np * 36 * (size_t)mf);
    double *Ti = malloc(sizeof(double) * (size_t)n * 36 * (size_t)m), *To = malloc(sizeof(double) * (size_t)n * 36 * (size_t)m);
    double *gbb = malloc(sizeof(double) * (size_t)n * 28 * (size_t)m), *Xm = calloc((size_t)nc * (size_t)m, sizeof(double));
    b->stencilF = malloc(sizeof(double) * (size_t)nt * 36 * (size_t)mf);
    b->w12 = malloc(sizeof(double) * 2 * (size_t)m);
    ccn_status st = CCN_OK;
    if (!X || !c0 || !p12 || !out || !Ti || !To || !gbb || !Xm || !b->stencilF || !b->w12)
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (stencil, n = %d)", (int)n);
    if (!st) { /* w12: the plain fit on the unit nets (columns 0..nc-1) and the unit centre (nc) */
        double *cm = calloc((size_t)m, sizeof(double));
        for (int32_t k = 0; k < nc; k++) Xm[(size_t)k * m + k] = 1.0;
        if (cm) cm[nc] = 1.0;
        ccn__bi5_tcc(n, Xm, NULL, m, Ti);
        ccn__bi5_raise_border(n, Ti, m, To);
        st = cm ? ccn__bi5_guide_fit(b, To, cm, m, gbb, err)
                : ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory");
        const int32_t t1 = ccn__bi5_tri(5, 1, 0), t2 = ccn__bi5_tri(5, 0, 1);
        for (int32_t k = 0; !st && k < m; k++) {
            b->w12[k] = gbb[(size_t)t1 * m + k];
            b->w12[m + k] = gbb[(size_t)t2 * m + k];
        }
        free(cm);
    }
    if (!st) {
        for (int32_t k = 0; k < nc; k++) X[(size_t)k * mf + k] = 1.0;
        c0[nc] = 1.0;
        p12[nc + 1] = 1.0;          /* p1 column */
        p12[mf + nc + 2] = 1.0;     /* p2 column */
        st = construct(b, X, NULL, c0, mf, NULL, NULL, NULL, NULL, NULL, p12, 0, out, err);
    }
    for (int32_t t = 0; !st && t < nt; t++)
        memcpy(b->stencilF + (size_t)t * 36 * mf, out + (size_t)t * n * 36 * mf, sizeof(double) * 36 * (size_t)mf);
    free(X); free(c0); free(p12); free(out); free(Ti); free(To); free(gbb); free(Xm);
    return st;
}

/* Global stencil of sector 0: run the construction on the unit nets and the unit centre. */
static ccn_status build_stencil(ccn__bi5 *b, ccn_error *err) {
    int32_t n = b->n, nc = 6 * n + 1, m = nc + 1, np = ccn__bi5_num_patches(b), nt = 3 * b->nsig + 1;
    double *X = calloc((size_t)nc * (size_t)m, sizeof(double)), *c0 = calloc((size_t)m, sizeof(double));
    double *out = malloc(sizeof(double) * (size_t)np * 36 * (size_t)m);
    b->stencil = malloc(sizeof(double) * (size_t)nt * 36 * (size_t)m);
    ccn_status st = CCN_OK;
    if (!X || !c0 || !out || !b->stencil)
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (stencil, n = %d)", (int)n);
    if (!st) {
        for (int32_t k = 0; k < nc; k++) X[(size_t)k * m + k] = 1.0;
        c0[nc] = 1.0;
        st = construct(b, X, NULL, c0, m, NULL, NULL, NULL, NULL, NULL, NULL, 0, out, err);
    }
    for (int32_t t = 0; !st && t < nt; t++) /* sector 0 patch of type t = patch index t*n */
        memcpy(b->stencil + (size_t)t * 36 * m, out + (size_t)t * n * 36 * m, sizeof(double) * 36 * (size_t)m);
    free(X); free(c0); free(out);
    if (!st) st = build_stencil_fixed(b, err);
    return st;
}

ccn_status ccn__bi5_create(int32_t n, const double *sigmas, int32_t nsig, ccn__bi5 **out,
                           ccn_error *err) {
    ccn_status st = check_create_args(n, sigmas, nsig, out, err);
    if (st) return st;
    *out = NULL;
    ccn__bi5 *b = calloc(1, sizeof *b);
    if (!b) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (create)");
    b->n = n;
    b->nsig = nsig;
    b->npar = 12 * n + 10;
    b->theta = 2.0 * CCN_BI5_PI / n;
    b->c = cos(b->theta);
    memcpy(b->sig, sigmas, sizeof(double) * (size_t)nsig);
    b->gpar = malloc(sizeof(double) * 28 * (size_t)n * (size_t)b->npar);
    b->qr = malloc(sizeof(double) * 27 * (size_t)n * (size_t)(b->npar - 1));
    b->qtau = malloc(sizeof(double) * (size_t)b->npar);
    b->s0 = malloc(sizeof(double) * 27 * (size_t)n);
    st = precompute(b, err);
    if (!st) st = build_stencil(b, err);
    if (st) {
        ccn__bi5_destroy(b);
        return st;
    }
    *out = b;
    ccn__ok(err);
    return CCN_OK;
}

/* Centre point, eq. (7) (n > 4) or eq. (8) (n = 3), from c_5 = (1,1) and c_6 = (1,0). */
static void centre_point(int32_t n, const double *X, double ctr[3]) {
    double g5 = n == 3 ? 5.0 / 96.0 : 1.0 / (n * (n + 5.0)), g6 = n == 3 ? 1.0 / 6.0 : 4.0 * g5;
    double g7 = 1.0 - n * (g5 + g6);
    for (int c = 0; c < 3; c++) {
        double acc = g7 * X[c];
        for (int32_t k = 0; k < n; k++) acc += g5 * X[3 * (1 + 6 * k + 4) + c] + g6 * X[3 * (1 + 6 * k + 5) + c];
        ctr[c] = acc;
    }
}

/* One stencil row on the net relabelled so that sector s becomes 0: the centre weight row[0]
 * and the 6 weights per sector of its n sectors (the centre-point and normal terms are the
 * caller's). */
static inline void stencil_row(const double *row, const double *X, int32_t n, int32_t s, double acc[3]) {
#ifdef CCN_V2D /* x, y side by side: the same products and sums per lane (base/vec3.h) */
    ccn__v2d x01, w0 = {row[0], row[0]};
    memcpy(&x01, X, sizeof x01);
    ccn__v2d a01 = w0 * x01;
    double a2 = row[0] * X[2];
    for (int32_t k = 0, ks = s; k < n; k++, ks = ks + 1 == n ? 0 : ks + 1) {
        const double *w = row + 1 + 6 * k, *x = X + 3 * (1 + 6 * ks);
        for (int32_t q = 0; q < 6; q++) {
            double wq = w[q];
            ccn__v2d wv = {wq, wq}, xq;
            memcpy(&xq, x + 3 * q, sizeof xq);
            a01 += wv * xq;
            a2 += wq * x[3 * q + 2];
        }
    }
    acc[0] = a01[0]; acc[1] = a01[1]; acc[2] = a2;
#else
    double a0 = row[0] * X[0], a1 = row[0] * X[1], a2 = row[0] * X[2]; /* in registers */
    for (int32_t k = 0, ks = s; k < n; k++, ks = ks + 1 == n ? 0 : ks + 1) {
        const double *w = row + 1 + 6 * k, *x = X + 3 * (1 + 6 * ks);
        for (int32_t q = 0; q < 6; q++) {
            double wq = w[q];
            a0 += wq * x[3 * q];
            a1 += wq * x[3 * q + 1];
            a2 += wq * x[3 * q + 2];
        }
    }
    acc[0] = a0; acc[1] = a1; acc[2] = a2;
#endif
}

/* Uniform operator: sector s = stencil applied to the net relabelled so that s becomes 0. */
static void apply_stencil(const ccn__bi5 *b, const double *X, const double ctr[3], double *patches) {
    int32_t n = b->n, nc = 6 * n + 1, m = nc + 1, nt = 3 * b->nsig + 1;
    for (int32_t s = 0; s < n; s++)
        for (int32_t t = 0; t < nt; t++)
            for (int32_t e = 0; e < 36; e++) {
                const double *row = b->stencil + ((size_t)t * 36 + e) * m;
                double acc[3];
                stencil_row(row, X, n, s, acc);
                double *o = patches + (((size_t)t * n + s) * 36 + e) * 3;
                for (int c = 0; c < 3; c++) o[c] = acc[c] + row[nc] * ctr[c];
            }
}

/* The uniform operator with the centre normal prescribed ([R14]): per sector, the plain fit's
 * b_510, b_501 of the relabelled net, projected, then the fixed-parameter stencil. */
static void apply_stencil_normal(const ccn__bi5 *b, const double *X, const double ctr[3],
                                 const double N[3], double *patches) {
    int32_t n = b->n, nc = 6 * n + 1, m = nc + 1, mf = nc + 3, nt = 3 * b->nsig + 1;
    for (int32_t s = 0; s < n; s++) {
        double p[6];
        for (int q = 0; q < 2; q++) {
            const double *w = b->w12 + (size_t)q * m;
            for (int c = 0; c < 3; c++) {
                double acc = w[0] * X[c] + w[nc] * ctr[c];
                for (int32_t k = 0; k < n; k++)
                    for (int32_t e = 0; e < 6; e++) acc += w[1 + 6 * k + e] * X[3 * (1 + 6 * ((k + s) % n) + e) + c];
                p[3 * q + c] = acc;
            }
        }
        ccn__bi5_project_p12(ctr, N, p);
        for (int32_t t = 0; t < nt; t++)
            for (int32_t e = 0; e < 36; e++) {
                const double *row = b->stencilF + ((size_t)t * 36 + e) * mf;
                double acc[3];
                stencil_row(row, X, n, s, acc);
                double *o = patches + (((size_t)t * n + s) * 36 + e) * 3;
                for (int c = 0; c < 3; c++) o[c] = acc[c] + row[nc] * ctr[c] + row[nc + 1] * p[c] + row[nc + 2] * p[3 + c];
            }
    }
}

/* kappa_s = d_{s+1} / d_{s-1} for every spoke (d = NULL: all 1); 1 if some kappa != 1. */
static int spoke_kappas(int32_t n, const double *d, double *kap) {
    int nu = 0;
    for (int32_t s = 0; s < n; s++) {
        kap[s] = d ? d[(s + 1) % n] / d[(s + n - 1) % n] : 1.0;
        if (fabs(kap[s] - 1.0) > 1e-12) nu = 1;
    }
    return nu;
}

/* Knot classification (see bi5.h): 0 uniform-equivalent, 1 supported NU, -1 unsupported. */
static int classify_knots(int32_t n, const double *d, double *kap, int32_t *bad) {
    if (!spoke_kappas(n, d, kap)) return 0;
    for (int32_t s = 0; s < n; s++)
        if (fabs(d[(s + 2) % n] - d[(s + n - 2) % n]) > 1e-12 * (d[(s + 2) % n] + d[(s + n - 2) % n])) {
            *bad = s;
            return -1;
        }
    return 1;
}

static ccn_status check_apply_args(const ccn__bi5 *b, const double *cnet, int32_t npts,
                                   const double *d, const double *center, double *patches,
                                   ccn_error *err) {
    if (!b || !cnet || !patches)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL argument to apply");
    for (int32_t k = 0; k < 3 * npts; k++)
        if (!isfinite(cnet[k]))
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, k / 3,
                             "bi5: input point %d is not finite", (int)(k / 3));
    for (int c = 0; center && c < 3; c++)
        if (!isfinite(center[c]))
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: centre point is not finite");
    for (int32_t s = 0; d && s < b->n; s++)
        if (!(d[s] > 0.0 && isfinite(d[s])))
            return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_EDGE, s,
                             "bi5: spoke %d has knot interval %g (need finite > 0)", (int)s, d[s]);
    return CCN_OK;
}

static ccn_status apply_impl(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                             const double complex *taus_in, const double *center, const double *normal,
                             double *patches, ccn_error *err) {
    ccn_status st = check_apply_args(b, cnet, b ? 6 * b->n + 1 : 0, spoke_knots, center, patches, err);
    if (st) return st;
    int32_t n = b->n, bad = -1;
    double ctr[3];
    if (center) memcpy(ctr, center, sizeof ctr);
    else centre_point(n, cnet, ctr);
    double kap_small[64]; /* no allocation on the uniform path for the valences the plan caps */
    double *kap = n <= 64 ? kap_small : malloc(sizeof(double) * (size_t)n);
    if (!kap) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (apply)");
    int kind = spoke_knots ? classify_knots(n, spoke_knots, kap, &bad) : 0;
    if (kind == 0 && normal) apply_stencil_normal(b, cnet, ctr, normal, patches);
    else if (kind == 0) apply_stencil(b, cnet, ctr, patches);
    else if (kind < 0)
        st = ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_EDGE, bad,
                       "bi5: spoke intervals with kappa != 1 and d_%d != d_%d around spoke %d: the "
                       "sectors' bicubic tensor-borders disagree along the spoke (SPEC §9, bi5.h [R8])",
                       (int)((bad + 2) % n), (int)((bad + n - 2) % n), (int)bad);
    else {
        double complex *taus = taus_in ? NULL : malloc(sizeof(double complex) * 36 * (size_t)n);
        if (!taus_in)
            st = taus ? ccn__bi5_tau_nu(n, b->chi[b->nsig - 1], kap, NULL, 0, taus, err)
                      : ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (apply)");
        if (!st) st = construct(b, cnet, NULL, ctr, 3, spoke_knots, kap, taus_in ? taus_in : taus, NULL, normal, NULL, 0, patches, err);
        free(taus);
    }
    if (kap != kap_small) free(kap);
    if (!st) ccn__ok(err);
    return st;
}

ccn_status ccn__bi5_apply(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                          const double *center, double *patches, ccn_error *err) {
    return apply_impl(b, cnet, spoke_knots, NULL, center, NULL, patches, err);
}

ccn_status ccn__bi5_apply_cached(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                                 const double complex *taus, const double *center, double *patches,
                                 ccn_error *err) {
    return apply_impl(b, cnet, spoke_knots, taus, center, NULL, patches, err);
}

ccn_status ccn__bi5_apply_normal(const ccn__bi5 *b, const double *cnet, const double *spoke_knots,
                                 const double complex *taus, const double *center, const double *normal,
                                 double *patches, ccn_error *err) {
    if (!center || !normal)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL centre or normal");
    return apply_impl(b, cnet, spoke_knots, taus, center, normal, patches, err);
}

ccn_status ccn__bi5_nu_taus(const ccn__bi5 *b, const double *spoke_knots, double border_exp, double complex *taus,
                            ccn_error *err) {
    if (!b || !spoke_knots || !taus)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL argument to nu_taus");
    int32_t n = b->n;
    double *kap = malloc(sizeof(double) * (size_t)n);
    if (!kap) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (nu_taus)");
    ccn_status st = CCN_OK;
    for (int32_t s = 0; s < n && !st; s++)
        if (!(spoke_knots[s] > 0.0 && isfinite(spoke_knots[s])))
            st = ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_EDGE, s, "bi5: spoke %d has knot interval %g",
                           (int)s, spoke_knots[s]);
    if (!st) spoke_kappas(n, spoke_knots, kap);
    if (!st) st = ccn__bi5_tau_nu(n, b->chi[b->nsig - 1], kap, spoke_knots, border_exp, taus, err);
    free(kap);
    return st;
}

/* Largest C0 / NU-C2 defect of the raised borders T (n x 36 x 3) across the spokes, relative to
 * the border's size; *spoke receives the worst spoke. */
static double border_defect(int32_t n, const double *T, const double *kap, int32_t *spoke) {
    double worst = 0, size = 1e-300;
    for (int32_t k = 0; k < n * 108; k++) size = fmax(size, fabs(T[k]));
    for (int32_t s = 0; s < n; s++) {
        int32_t p = (s + n - 1) % n;
        double r = kap ? kap[s] : 1.0;
        for (int32_t i = 3; i < 6; i++)
            for (int c = 0; c < 3; c++) {
                double Pm2 = T[(p * 36 + 12 + i) * 3 + c], Pm1 = T[(p * 36 + 6 + i) * 3 + c];
                double P0 = T[(s * 36 + i * 6) * 3 + c], P0b = T[(p * 36 + i) * 3 + c];
                double P1 = T[(s * 36 + i * 6 + 1) * 3 + c], P2 = T[(s * 36 + i * 6 + 2) * 3 + c];
                double e = fmax(fabs(P0 - P0b), fabs(P1 - P0 - r * (P0 - Pm1)));
                e = fmax(e, fabs((P2 - 2 * P1 + P0) - r * r * (P0 - 2 * Pm1 + Pm2)));
                if (e > worst) { worst = e; *spoke = s; }
            }
    }
    return worst / size;
}

ccn_status ccn__bi5_apply_border(const ccn__bi5 *b, const double *border, const double *spoke_knots,
                                 const double *center, double *patches, ccn_error *err) {
    if (!border || !center)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL border or centre");
    ccn_status st = check_apply_args(b, center, 1, spoke_knots, center, patches, err);
    if (st) return st;
    int32_t n = b->n, spoke = -1, nu = 0;
    for (int32_t k = 0; k < n * 108; k++)
        if (ccn__bi5_in_mask(k / 3 % 36 / 6, k / 3 % 6) && !isfinite(border[k]))
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "bi5: tensor-border of sector %d is not finite", (int)(k / 108));
    double *T = malloc(sizeof(double) * (size_t)n * 108), *kap = malloc(sizeof(double) * (size_t)n);
    double complex *taus = malloc(sizeof(double complex) * 36 * (size_t)n);
    if (!T || !kap || !taus) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (apply_border)");
        goto done;
    }
    nu = spoke_kappas(n, spoke_knots, kap);
    for (int32_t k = 0; k < n * 108; k++) /* the mask only */
        T[k] = ccn__bi5_in_mask(k / 3 % 36 / 6, k / 3 % 6) ? border[k] : 0.0;
    double def = border_defect(n, T, kap, &spoke);
    if (def > 1e-9) {
        st = ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_EDGE, spoke,
                       "bi5: tensor-border is not C0 / C2 (ratio kappa = %g) across spoke %d "
                       "(relative defect %g)", kap[spoke], (int)spoke, def);
        goto done;
    }
    if (nu) st = ccn__bi5_tau_nu(n, b->chi[b->nsig - 1], kap, NULL, 0, taus, err);
    if (!st) st = construct(b, NULL, T, center, 3, NULL, nu ? kap : NULL, nu ? taus : NULL, NULL, NULL, NULL, 0, patches, err);
    if (!st) ccn__ok(err);
done:
    free(T); free(kap); free(taus);
    return st;
}

ccn_status ccn__bi5_apply_pieces(const ccn__bi5 *b, const double *cnet, const double *pieces,
                                 const double *spoke_knots, double border_exp, const double complex *taus_in,
                                 const double *center, const double *normal, double *patches,
                                 ccn_error *err) {
    ccn_status st = check_apply_args(b, cnet, b ? 6 * b->n + 1 : 0, spoke_knots, center, patches, err);
    if (st) return st;
    if (!pieces || !center || !spoke_knots)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "bi5: NULL pieces, knots or centre");
    if (b->sig[0] != 0.5)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "bi5: the pieces need a first ring with sigma = 1/2 (got %g)", b->sig[0]);
    int32_t n = b->n;
    for (int32_t k = 0; k < n * 4 * 108; k++)
        if (!isfinite(pieces[k]))
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "bi5: surround piece of sector %d is not finite", (int)(k / 432));
    double *kap = malloc(sizeof(double) * (size_t)n);
    double complex *taus = taus_in ? NULL : malloc(sizeof(double complex) * 36 * (size_t)n);
    int nu = 0;
    if (!kap || (!taus_in && !taus))
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (apply_pieces)");
    if (!st) nu = spoke_kappas(n, spoke_knots, kap);
    double *T = st ? NULL : malloc(sizeof(double) * (size_t)n * 108);
    if (!st && !T) st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (apply_pieces)");
    if (!st && ccn__bi5_pieces_target(n, pieces, T))
        st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "bi5: border fit failed");
    if (!st && nu && !taus_in) st = ccn__bi5_tau_nu(n, b->chi[b->nsig - 1], kap, spoke_knots, border_exp, taus, err);
    const double complex *tu = taus_in ? taus_in : taus;
    if (!st) st = construct(b, NULL, T, center, 3, spoke_knots, nu ? kap : NULL, nu ? tu : NULL,
                            pieces, normal, NULL, border_exp, patches, err);
    free(kap); free(taus); free(T);
    if (!st) ccn__ok(err);
    return st;
}

/* ---- evaluation (SPEC §1.4) ------------------------------------------------------------ */

const double *ccn__bi5_locate(const ccn__bi5 *b, const double *patches, int32_t s, double u,
                              double v, double *pu, double *pv, double *su, double *sv) {
    int32_t n = b->n;
    s = ((s % n) + n) % n;
    double scale = 1.0; /* level-r units per hole unit */
    u = u < 0 ? 0 : (u > 1 ? 1 : u);
    v = v < 0 ? 0 : (v > 1 ? 1 : v);
    for (int32_t r = 0; r < b->nsig; r++) {
        double rho = 1.0 - b->sig[r], sg = b->sig[r];
        if (u >= rho || v >= rho) {
            int32_t kind = u >= rho ? (v <= rho ? 0 : 1) : 2; /* A, B, C */
            double u0 = kind == 2 ? 0.0 : rho, lu = kind == 2 ? rho : sg;
            double v0 = kind == 0 ? 0.0 : rho, lv = kind == 0 ? rho : sg;
            *pu = (u - u0) / lu, *pv = (v - v0) / lv;
            *su = scale / lu, *sv = scale / lv;
            return patches + (((size_t)(3 * r + kind) * n + s) * 36) * 3;
        }
        u /= rho; v /= rho; scale /= rho;
    }
    *pu = u, *pv = v, *su = *sv = scale;
    return patches + (((size_t)3 * b->nsig * n + s) * 36) * 3;
}

void ccn__bi5_eval(const ccn__bi5 *b, const double *patches, int32_t s, double u, double v,
                   double pos[3], double du[3], double dv[3]) {
    double pu, pv, su, sv;
    const double *P = ccn__bi5_locate(b, patches, s, u, v, &pu, &pv, &su, &sv);
    ccn__bi5_patch_eval(P, 3, pu, pv, pos, du, dv);
    for (int c = 0; c < 3; c++) { du[c] *= su; dv[c] *= sv; }
}
