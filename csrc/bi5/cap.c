/* Central G1 cap assembly (paper Sec. 6; SPEC §6.3): the cap patches from the guide and the
 * last ring, closed-form black squares ([R5]) or, with non-uniform intervals, the per-sector
 * least-squares black squares ([R9], [R12]). */
#include "bi5/cap.h"

#include "base/error.h"
#include "bi5/bernstein.h"
#include "bi5/guide.h"
#include "bi5/tau.h"

#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

/* ---- cap assembly (SPEC §6.3) ---------------------------------------------------------- */

/* Closed form of SPEC §6.3 step 3-4 for the separator s|s1, column col. */
static void black_closed(double *fs, double *fs1, const double *as, const double *as1,
                         int32_t m, double c) {
#define F(P, i, j) (P)[((i) * 6 + (j)) * m]
    double e2 = F(fs1, 2, 0), e4 = F(fs1, 4, 0), e5 = F(fs1, 5, 0);
    double d1 = 10 * (0.5 * (F(fs1, 1, 1) + F(fs, 1, 1)) - F(fs1, 1, 0));
    double d4 = 10 * (0.5 * (F(fs1, 4, 1) + F(fs, 1, 4)) - e4);
    double d3 = c * (e5 - e4) - d4 / 2;
    double e3 = (d1 + 8 * c * e4 - 2 * d3 + 12 * c * e2) / (20 * c);
    double d2 = 4 * c * (e4 - e3) - d3;
    double m2 = e2 + d2 / 10, m3 = e3 + d3 / 10;
    double h2 = 0.5 * (F(as1, 2, 1) - F(as, 1, 2)), h3 = 0.5 * (F(as1, 3, 1) - F(as, 1, 3));
    F(fs1, 3, 0) = e3; F(fs, 0, 3) = e3;
    F(fs1, 2, 1) = m2 + h2; F(fs, 1, 2) = m2 - h2;
    F(fs1, 3, 1) = m3 + h3; F(fs, 1, 3) = m3 - h3;
#undef F
}

/* [R9]: black squares e3, a2, a3, b2, b3 closest to the jet map subject to the middle G1
 * equations 2..5 (equations 0,1 hold by the red data, 6,7 by the green data). */
static const int32_t bl_s1[3] = {18, 13, 19}, bl_s[2] = {8, 9}; /* (3,0),(2,1),(3,1); (1,2),(1,3) */

static void black_ls(double *fs, double *fs1, const double *as, const double *as1, int32_t m,
                     double c, double k) {
    double complex zs[36], zs1[36], R[8];
    double M[4][5], x[5], xa[5];
    for (int32_t u = 0; u < 5; u++) { /* columns of the 4x5 system */
        memset(zs, 0, sizeof zs);
        memset(zs1, 0, sizeof zs1);
        if (u == 0) { zs1[bl_s1[0]] = 1; zs[3] = 1; }
        else if (u < 3) zs1[bl_s1[u]] = 1;
        else zs[bl_s[u - 3]] = 1;
        ccn__bi5_g1_res(zs, zs1, c, k, R);
        for (int32_t i = 0; i < 4; i++) M[i][u] = creal(R[i + 2]);
    }
    double MMt[16], Mc[16];
    for (int32_t i = 0; i < 4; i++)
        for (int32_t j = 0; j < 4; j++) {
            MMt[i * 4 + j] = 0;
            for (int32_t u = 0; u < 5; u++) MMt[i * 4 + j] += M[i][u] * M[j][u];
        }
    for (int32_t col = 0; col < m; col++) {
        for (int32_t e = 0; e < 36; e++) { zs[e] = fs[e * m + col]; zs1[e] = fs1[e * m + col]; }
        zs1[bl_s1[0]] = zs[3] = 0;
        for (int32_t q = 1; q < 3; q++) zs1[bl_s1[q]] = 0;
        for (int32_t q = 0; q < 2; q++) zs[bl_s[q]] = 0;
        ccn__bi5_g1_res(zs, zs1, c, k, R);
        xa[0] = 0.5 * (as1[bl_s1[0] * m + col] + as[3 * m + col]);
        for (int32_t q = 1; q < 3; q++) xa[q] = as1[bl_s1[q] * m + col];
        for (int32_t q = 0; q < 2; q++) xa[3 + q] = as[bl_s[q] * m + col];
        double rhs[4];
        for (int32_t i = 0; i < 4; i++) { /* rhs - M xa */
            rhs[i] = -creal(R[i + 2]);
            for (int32_t u = 0; u < 5; u++) rhs[i] -= M[i][u] * xa[u];
        }
        memcpy(Mc, MMt, sizeof Mc);
        lapack_int ipiv[4];
        LAPACKE_dgesv(LAPACK_ROW_MAJOR, 4, 1, Mc, 4, ipiv, rhs, 1);
        for (int32_t u = 0; u < 5; u++) {
            x[u] = xa[u];
            for (int32_t i = 0; i < 4; i++) x[u] += M[i][u] * rhs[i];
        }
        fs1[bl_s1[0] * m + col] = fs[3 * m + col] = x[0];
        for (int32_t q = 1; q < 3; q++) fs1[bl_s1[q] * m + col] = x[q];
        for (int32_t q = 0; q < 2; q++) fs[bl_s[q] * m + col] = x[3 + q];
    }
}

ccn_status ccn__bi5_cap(const ccn__bi5 *b, const double *gbb, const double *T, int32_t m,
                        const double *kap, const double complex *taus, double *cap,
                        ccn_error *err) {
    int32_t n = b->n;
    size_t psz = 36 * (size_t)m;
    double *a = malloc(sizeof(double) * (size_t)n * psz), S[36 * 28];
    if (!a) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "bi5: out of memory (cap)");
    memset(a, 0, sizeof(double) * (size_t)n * psz);
    for (int32_t s = 0; s < n; s++) { /* a^s = corner jets [g^l_s o omega^s tau] */
        const double *Sm = b->scap;
        if (kap) {
            double complex t0[36];
            for (int32_t e = 0; e < 36; e++) t0[e] = taus[s * 36 + e] * ccn__bi5_omega(n, -s);
            ccn__bi5_sample(n, t0, 5, b->Lam[b->nsig - 1], 0xFu, S);
            Sm = S;
        }
        for (int32_t e = 0; e < 36; e++)
            for (int32_t t = 0; t < 28; t++)
                if (Sm[e * 28 + t] != 0.0)
                    ccn__bi5_axpy(a + s * psz + (size_t)e * m, Sm[e * 28 + t], gbb + ((size_t)s * 28 + t) * m, m);
    }
    for (int32_t s = 0; s < n; s++) /* green: C1 with the last ring */
        for (int32_t e = 0; e < 36; e++) {
            const double *src = (e / 6 >= 4 || e % 6 >= 4) ? T + s * psz : a + s * psz;
            memcpy(cap + s * psz + (size_t)e * m, src + (size_t)e * m, sizeof(double) * (size_t)m);
        }
    for (int32_t s = 0; s < n; s++) {
        int32_t s1 = (s + 1) % n;
        double *fs = cap + s * psz, *fs1 = cap + s1 * psz;
        if (!kap)
            for (int32_t col = 0; col < m; col++)
                black_closed(fs + col, fs1 + col, a + s * psz + col, a + s1 * psz + col, m, b->c);
        else black_ls(fs, fs1, a + s * psz, a + s1 * psz, m, b->c, kap[s1]);
    }
    free(a);
    return CCN_OK;
}
