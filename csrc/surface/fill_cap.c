/* The G1 fill cap of a plan (surface/fill_cap.h).
 *
 * Why: where an EV's spoke ratios leave the guided bi-5 cap's range its hole showed the refined
 * limit, whose curvature at the EV is unbounded (it doubles per level at valence 8, spoke ratio
 * 2) and whose normals converge slowly. The fill cap closes the hole -- the EV's level-K fan
 * faces, 2 x 2 level-(K+1) faces per sector -- with one quintic B-spline per sector
 * (fill/g1_fill.h: 2 x 2 spans, 9 x 9 poles), exactly G1 across the spokes, C1 to the exact
 * limit around it (its outer two layers are the exact pieces across the hole's far sides and
 * their C1 continuations, surface/fill_border.h), through the exact limit point with the exact
 * tangent plane.
 *
 * Linear, so that an evaluation costs a matrix product: every input is a fixed linear map of
 * the level-(K+1) points, and the G1 relations' weights come from the knot intervals alone.
 *   - Spoke k's first pole: P + s D_k, D_k = row E_k of the subdominant spectral projector
 *     R (L R)^-1 L of the EV's matrix M applied to its 1-ring (the characteristic map's spoke
 *     vector in the limit tangent plane; L, R the left and right eigenvectors of the two
 *     subdominant eigenvalues), s = CCN__FILL_CAP_TANGENT (tests/experiments/RESULTS.md: at
 *     the export's fill level 0.33 kept the fill's largest |K| within twice the exact pieces'
 *     around it on 34 of 36 random stars of valence 5-12; in the plan's harness 0.4-0.5 lower
 *     it somewhat, 0.2 and 0.7 raise it: shorter tangents pinch, longer ones bulge).
 *   - At u = 0 the relation D_{k+1} + beta D_{k-1} = gamma D_k holds among the characteristic
 *     map's planar spoke vectors c(k) = R_{E_k} (L R)^-1, so beta(0), gamma(0) solve it in the
 *     plane, for every position of the ring.
 *   - At u = 2 the fill meets the exact spline, in which the cross derivatives of the two
 *     sectors along the spoke's far end are one derivative scaled by the intervals of the faces
 *     on either side: D_k = (d_{k+1} / 2) S_s, D_{k-1} = -(d_{k-1} / 2) S_s in level-K spoke
 *     intervals d (the far sides are halves of the level-K edges opposite spokes k+1 and k-1),
 *     so beta(2) = d_{k+1} / d_{k-1}, gamma(2) = 0.
 * The operator depends on the weights only (fill/g1_fill.c); the fill is built around the EV's
 * limit point (translated there and back) so that its rounding is that of the hole's size.
 * Measured not fair enough to be the default cap (docs/caps.md): exactly G1 and finite, but its
 * curvature jumps across the spokes and peaks at the vertex. */
#include "surface/fill_cap.h"

#include "base/error.h"
#include "fill/g1_fill.h"
#include "surface/fill_border.h"
#include "surface/limit.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NQ CCN_FILL_G1_POLES
#define CCN__FILL_CAP_TANGENT 0.33

struct ccn__fill_cap {
    int32_t n, w1, rot;      /* valence; the EV at level K+1; its fan face k + rot is sector k */
    int32_t *ring;           /* 2n+1 level-(K+1) 1-ring (M's order) */
    double *wp, *wd;         /* limit weights (2n+1); spoke k's tangent pole offset, n x (2n+1) */
    ccn__fill_block *blk;    /* per sector, at level K+1 */
    ccn__g1_weights *wt;     /* per spoke */
    ccn__g1_operator *op;
    double (*q)[NQ][NQ][3];  /* the fill's poles, per sector */
    double (*cs)[5][5][3];   /* the bicubic data (update's scratch) */
};

void ccn__fill_cap_destroy(ccn__fill_cap *f) {
    if (!f) return;
    free(f->ring); free(f->wp); free(f->wd); free(f->blk); free(f->wt); free(f->q); free(f->cs);
    ccn__g1_operator_destroy(f->op);
    free(f);
}

/* The subdominant spectral projector's spoke rows: wd[k] (over the ring) and the planar
 * characteristic-map vectors c[k]. 1, 0 (no subdominant pair), -1 out of memory. */
static int spoke_tangents(int32_t n, const double *M, double *wd, double (*c)[2]) {
    int32_t sz = 2 * n + 1;
    double *A = malloc(sizeof(double) * (3 * (size_t)sz * sz + 2 * (size_t)sz));
    if (!A) return -1;
    double *VL = A + (size_t)sz * sz, *VR = VL + (size_t)sz * sz, *wr = VR + (size_t)sz * sz, *wi = wr + sz;
    memcpy(A, M, sizeof(double) * (size_t)sz * sz);
    int r = 0;
    if (LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'V', 'V', sz, A, sz, wr, wi, VL, sz, VR, sz)) goto done;
    int32_t i0 = 0, i1 = -1, i2 = -1; /* the dominant eigenvalue 1, then the two largest moduli */
    for (int32_t i = 1; i < sz; i++)
        if (fabs(wr[i] - 1) + fabs(wi[i]) < fabs(wr[i0] - 1) + fabs(wi[i0])) i0 = i;
    for (int32_t i = 0; i < sz; i++) {
        if (i == i0) continue;
        double mod = hypot(wr[i], wi[i]);
        if (i1 < 0 || mod > hypot(wr[i1], wi[i1])) i2 = i1, i1 = i;
        else if (i2 < 0 || mod > hypot(wr[i2], wi[i2])) i2 = i;
    }
    if (i1 < 0 || i2 < 0) goto done;
    if (wi[i1] != 0.0) { /* a complex pair: its real and imaginary parts, in columns i, i + 1 */
        if (wi[i1] < 0) i1--;
        i2 = i1 + 1;
    }
    double G[2][2] = {{0, 0}, {0, 0}};
    for (int32_t q = 0; q < sz; q++) {
        G[0][0] += VL[(size_t)q * sz + i1] * VR[(size_t)q * sz + i1], G[0][1] += VL[(size_t)q * sz + i1] * VR[(size_t)q * sz + i2];
        G[1][0] += VL[(size_t)q * sz + i2] * VR[(size_t)q * sz + i1], G[1][1] += VL[(size_t)q * sz + i2] * VR[(size_t)q * sz + i2];
    }
    double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
    if (!(fabs(det) > 1e-14 * (fabs(G[0][0] * G[1][1]) + fabs(G[0][1] * G[1][0])))) goto done;
    double Gi[2][2] = {{G[1][1] / det, -G[0][1] / det}, {-G[1][0] / det, G[0][0] / det}};
    for (int32_t k = 0; k < n; k++) { /* E_k is ring entry n + k */
        double rk[2] = {VR[(size_t)(n + k) * sz + i1], VR[(size_t)(n + k) * sz + i2]};
        c[k][0] = rk[0] * Gi[0][0] + rk[1] * Gi[1][0];
        c[k][1] = rk[0] * Gi[0][1] + rk[1] * Gi[1][1];
        for (int32_t q = 0; q < sz; q++)
            wd[(size_t)k * sz + q] = CCN__FILL_CAP_TANGENT * (c[k][0] * VL[(size_t)q * sz + i1] + c[k][1] * VL[(size_t)q * sz + i2]);
    }
    r = 1;
done:
    free(A);
    return r;
}

int ccn__fill_cap_create(const ccn_plan *p, int32_t ev, int32_t n, const double *knots, ccn__fill_cap **out) {
    *out = NULL;
    if (n < CCN_FILL_CAP_MIN_VALENCE || n > CCN_FILL_G1_DENSE_SPOKES || p->K < 0 || p->R < p->K + 1) return 0;
    const ccn_mesh *mK = p->lev[p->K], *m = p->lev[p->K + 1];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    int32_t w1 = mK->nf + mK->ne + ev, sz = 2 * n + 1;
    if (ccn__valence(m, w1) != n || ccn__limit_kind(m, w1, pinned) != CCN_LIMIT_EV) return 0;
    ccn__fill_cap *f = calloc(1, sizeof *f);
    ccn__stencil *s = malloc(sizeof *s);
    double *M = malloc(sizeof(double) * (size_t)sz * sz), (*c)[2] = malloc(sizeof *c * (size_t)n);
    double *d = malloc(sizeof(double) * (size_t)n);
    int r = -1;
    if (!f || !s || !M || !c || !d) goto done;
    f->n = n;
    f->w1 = w1;
    f->ring = malloc(sizeof(int32_t) * (size_t)sz);
    f->wp = malloc(sizeof(double) * (size_t)sz);
    f->wd = malloc(sizeof(double) * (size_t)sz * n);
    f->blk = malloc(sizeof *f->blk * (size_t)n);
    f->wt = malloc(sizeof *f->wt * (size_t)n);
    f->q = malloc(sizeof *f->q * (size_t)n);
    f->cs = malloc(sizeof *f->cs * (size_t)n);
    if (!f->ring || !f->wp || !f->wd || !f->blk || !f->wt || !f->q || !f->cs) goto done;
    r = 0;
    /* sector k = level-K fan face k: its child at the EV is the level-K fan half-edge's number */
    int32_t h0 = mK->vfan[mK->vfan_start[ev]];
    f->rot = -1;
    for (int32_t j = 0; j < n; j++)
        if (m->hface[m->vfan[m->vfan_start[w1] + j]] == h0) f->rot = j;
    if (f->rot < 0) goto done;
    for (int32_t k = 0; k < n; k++) {
        int32_t h = m->vfan[m->vfan_start[w1] + (k + f->rot) % n];
        if (m->hface[h] != mK->vfan[mK->vfan_start[ev] + k]) goto done;
        ccn__fill_sector_block(m, h, &f->blk[k]);
        const ccn__fill_block *b = &f->blk[k];
        if (b->N1 < 0 || b->N2 < 0 || b->M1 < 0 || b->M2 < 0) goto done;
    }
    ccn_error e2;
    ccn__ev_ring(m, w1, f->ring);
    if (ccn__ev_limit(m, w1, p->opts.scheme, p->opts.ev_polyhedron, p->ev_cache, s, &e2)) goto done;
    memcpy(f->wp, s->wp, sizeof(double) * (size_t)sz);
    for (int32_t k = 0; k < n; k++) d[k] = m->eknot[ccn__fan_edge(m, w1, k)];
    if (ccn__ev_matrix_cached(n, d, (ccn_scheme)p->opts.scheme, p->opts.ev_polyhedron, p->ev_cache, M, NULL, &e2))
        goto done;
    int t = spoke_tangents(n, M, f->wd, c);
    if (t <= 0) { r = t; goto done; }
    /* the weights in the fill's sector order (ring spoke k of level K+1 is fan edge k there) */
    for (int32_t k = 0; k < n; k++) {
        int32_t j = (k + f->rot) % n, jp = (j + 1) % n, jm = (j + n - 1) % n;
        double Da[3] = {c[jp][0], c[jp][1], 0}, Db[3] = {c[jm][0], c[jm][1], 0}, T[3] = {c[j][0], c[j][1], 0};
        if (!ccn__fill_g1_vertex_weights(Da, Db, T, &f->wt[k][0], &f->wt[k][1])) goto done;
        f->wt[k][2] = knots[(k + 1) % n] / knots[(k + n - 1) % n];
        f->wt[k][3] = 0;
    }
    r = 1;
done:
    free(s); free(M); free(c); free(d);
    if (r > 0) *out = f;
    else ccn__fill_cap_destroy(f);
    return r;
}

int ccn__fill_cap_solve(ccn__fill_cap *f) {
    return ccn__g1_operator_create(f->n, (const ccn__g1_weights *)f->wt, &f->op);
}

int ccn__fill_cap_update(const ccn_plan *p, ccn__fill_cap *f) {
    const ccn_mesh *m = p->lev[p->K + 1];
    const double *pos = m->pos;
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    int32_t n = f->n, sz = 2 * n + 1;
    double P[3] = {0, 0, 0}, nb[4][4][4][3], sp[CCN_FILL_G1_DENSE_SPOKES][5][3];
    for (int32_t q = 0; q < sz; q++)
        for (int d = 0; d < 3; d++) P[d] += f->wp[q] * pos[3 * (size_t)f->ring[q] + d];
    for (int32_t k = 0; k < n; k++) { /* spoke k: P, its tangent pole, then from sector k's N1, N2 */
        const ccn__fill_block *b = &f->blk[k];
        const int32_t cells[4] = {b->N1, b->N2, b->M1, b->M2};
        for (int i = 0; i < 4; i++)
            if (!ccn__fill_cell_patch(m, cells[i], pinned, nb[i])) return 0;
        double (*c)[5][3] = f->cs[k], S[5][3], L[5][3];
        memset(c, 0, sizeof f->cs[k]);
        ccn__fill_sector_border((const double(*)[4][4][3])nb, c);
        ccn__fill_side_poles((const double(*)[4][3])nb[0], (const double(*)[4][3])nb[1], 0, 0, S);
        ccn__fill_side_poles((const double(*)[4][3])nb[0], (const double(*)[4][3])nb[1], 0, 1, L);
        const double *wd = f->wd + (size_t)((k + f->rot) % n) * sz;
        for (int d = 0; d < 3; d++) {
            double t = 0;
            for (int32_t q = 0; q < sz; q++) t += wd[q] * pos[3 * (size_t)f->ring[q] + d];
            sp[k][0][d] = 0;
            sp[k][1][d] = t;
            sp[k][3][d] = L[0][d] - P[d];
            sp[k][4][d] = S[0][d] - P[d];
            sp[k][2][d] = 2 * sp[k][3][d] - sp[k][4][d];
        }
        for (int i = 0; i < 5; i++) /* around the limit point (translated back below) */
            for (int j = 0; j < 5; j++)
                for (int d = 0; d < 3; d++) c[i][j][d] -= P[d];
    }
    for (int32_t k = 0; k < n; k++)
        for (int i = 0; i < 5; i++) {
            memcpy(f->cs[k][i][0], sp[k][i], sizeof sp[k][i]);
            memcpy(f->cs[k][0][i], sp[(k + 1) % n][i], sizeof sp[k][i]);
        }
    ccn__g1_operator_apply(f->op, (const double(*)[5][5][3])f->cs, f->q);
    for (int32_t k = 0; k < n; k++)
        for (int i = 0; i < NQ; i++)
            for (int j = 0; j < NQ; j++)
                for (int d = 0; d < 3; d++) f->q[k][i][j][d] += P[d];
    return 1;
}

void ccn__fill_cap_eval(const ccn__fill_cap *f, int32_t k, double u, double v, double x[3], double du[3],
                        double dv[3], double (*d2)[3]) {
    ccn__fill_g1_eval((const double(*)[NQ][3])f->q[k], 2 * u, 2 * v, x, du, dv, d2);
    for (int d = 0; d < 3; d++) { /* d/du of the face = 2 d/du of the fill */
        du[d] *= 2, dv[d] *= 2;
        if (d2) d2[0][d] *= 4, d2[1][d] *= 4, d2[2][d] *= 4;
    }
}

void ccn__fill_cap_bezier(const ccn__fill_cap *f, int32_t k, double b[4][6][6][3]) {
    ccn__fill_g1_bezier((const double(*)[NQ][3])f->q[k], b);
}
