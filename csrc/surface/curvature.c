/* Principal curvatures of the limit surface at the output vertices (surface/curvature.h).
 *
 * Where the limit at an output vertex is the tensor B-spline of a 3 x 3 grid (a REGULAR vertex
 * of level L away from irregular ones, or, next to them, the grid around its vertex point one
 * level finer: the same grids the position stencils use, surface/tessellate.c), the surface is
 * C2 there and its first and second derivatives are exact stencils on those points
 * (ccn__curvature_stencil: the cubic's f''(t_0) from its knot intervals, rules/bspline.c). The
 * fundamental forms then give the principal curvatures:
 *   E = S_u.S_u, F = S_u.S_v, G = S_v.S_v,  n = S_u x S_v / |S_u x S_v| (the output normal),
 *   L = -S_uu.n, M = -S_uv.n, N = -S_vv.n   (curvature positive where the surface bends away
 *                                            from its normal: a sphere with outward normals
 *                                            has k1 = k2 = 1/r),
 *   K = (LN - M^2)/(EG - F^2), H = (EN - 2FM + GL) / (2 (EG - F^2)), k1,2 = H +- sqrt(H^2 - K),
 * and the direction of k1 is (du, dv) in the kernel of II - k1 I, mapped by (S_u, S_v).
 *
 * On a cap (the bi-5 patches, K&P 2018) and the bicubic faces around it the surface is those
 * polynomial patches, and the same forms come from the patch's own derivatives (a patch's
 * parametrisation: the curvatures do not depend on it).
 *
 * Everywhere else the value is NaN, a flag rather than a number: at an extraordinary vertex of
 * the refined limit the curvature is unbounded (or depends on the direction of approach); at
 * creases and corners each side has its own; on boundary curves of smooth corners and boundary
 * EVs, and where a cap is blended with the refined limit (the end of its range), it is not
 * computed. */
#include "surface/curvature.h"

#include "base/error.h"
#include "bi5/bi5.h"
#include "base/parallel.h"
#include "surface/limit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const ccn_plan *p;
    ccn_limit_mesh *out;
    const uint8_t *near; /* per level-L vertex: its limit is taken one level finer */
    const uint8_t *skip; /* per output vertex: not the refined limit's tensor spline */
} curv_job;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void ccn__principal_curvatures(const double d[5][3], double *k1, double *k2, double dir[3]) {
    const double *su = d[0], *sv = d[1];
    double n[3] = {su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2],
                   su[0] * sv[1] - su[1] * sv[0]};
    double ln = sqrt(dot3(n, n));
    double E = dot3(su, su), F = dot3(su, sv), G = dot3(sv, sv), det = E * G - F * F;
    if (!(ln > 0) || !(det > 1e-300 * (E * G + 1e-300))) {
        *k1 = *k2 = NAN;
        if (dir) dir[0] = dir[1] = dir[2] = NAN;
        return;
    }
    for (int i = 0; i < 3; i++) n[i] /= ln;
    double L = -dot3(d[2], n), M = -dot3(d[3], n), N = -dot3(d[4], n);
    double K = (L * N - M * M) / det, H = (E * N - 2 * F * M + G * L) / (2 * det);
    double disc = sqrt(fmax(H * H - K, 0.0));
    *k1 = H + disc;
    *k2 = H - disc;
    if (!dir) return;
    /* (II - k1 I)(du, dv) = 0: the row of larger norm gives the kernel */
    double a = L - *k1 * E, b = M - *k1 * F, c = N - *k1 * G;
    double du, dv;
    if (a * a + b * b >= b * b + c * c) du = b, dv = -a;
    else du = c, dv = -b;
    double t[3];
    for (int i = 0; i < 3; i++) t[i] = du * su[i] + dv * sv[i];
    double lt = sqrt(dot3(t, t));
    if (!(lt > 1e-12 * sqrt(E + G) * (fabs(du) + fabs(dv) + 1e-300))) { /* umbilic: any */
        for (int i = 0; i < 3; i++) t[i] = su[i];
        lt = sqrt(E);
    }
    for (int i = 0; i < 3; i++) dir[i] = t[i] / lt;
}

/* Bernstein values, first and second derivatives of degree deg (<= 5) at t. */
static void bern2(int deg, double t, double B[6], double D[6], double DD[6]) {
    double b[3][7]; /* degrees deg-2, deg-1, deg (index +1: b[.][0] = 0) */
    for (int d = 0; d < 3; d++) {
        int m = deg - 2 + d;
        for (int i = 0; i < 7; i++) b[d][i] = 0;
        if (m < 0) continue;
        b[d][1] = 1;
        for (int q = 1; q <= m; q++)
            for (int i = q + 1; i >= 1; i--) b[d][i] = (1 - t) * b[d][i] + t * b[d][i - 1];
    }
    for (int i = 0; i <= deg; i++) {
        B[i] = b[2][i + 1];
        D[i] = deg * (b[1][i] - b[1][i + 1]);
        DD[i] = deg * (deg - 1) * ((i >= 1 ? b[0][i - 1] : 0) - 2 * b[0][i] + b[0][i + 1]);
    }
}

/* S_u, S_v, S_uu, S_uv, S_vv of a tensor Bezier patch P[(i (deg+1) + j) 3 + c], i along u. */
static void bezier_d2(const double *P, int deg, double u, double v, double d[5][3]) {
    double Bu[6], Du[6], DDu[6], Bv[6], Dv[6], DDv[6];
    bern2(deg, u, Bu, Du, DDu);
    bern2(deg, v, Bv, Dv, DDv);
    memset(d, 0, sizeof(double) * 15);
    for (int i = 0; i <= deg; i++)
        for (int j = 0; j <= deg; j++) {
            const double *x = P + 3 * (size_t)(i * (deg + 1) + j);
            double w[5] = {Du[i] * Bv[j], Bu[i] * Dv[j], DDu[i] * Bv[j], Du[i] * Dv[j], Bu[i] * DDv[j]};
            for (int c = 0; c < 5; c++)
                for (int k = 0; k < 3; k++) d[c][k] += w[c] * x[k];
        }
}

#define SPOINT(i) ((i) < nvL ? PL + 3 * (size_t)(i) : PS + 3 * ((size_t)(i) - nvL))

static void curv_range(void *ctx, int32_t begin, int32_t end) {
    const curv_job *j = ctx;
    const ccn_plan *p = j->p;
    const ccn_mesh *mL = p->lev[p->L];
    const double *PL = mL->pos, *PS = p->posS;
    int32_t nvL = mL->nv;
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn__stencil2 s;
    for (int32_t o = begin; o < end; o++) {
        double *k = j->out->curvatures + 2 * (size_t)o;
        double *dir = j->out->curvature_dirs ? j->out->curvature_dirs + 3 * (size_t)o : NULL;
        int32_t v = p->out_vL[o], set = p->st_w[o] < 0 ? -1 - p->st_w[o] : -1;
        int child = j->near[v];
        double d[5][3] = {{0}};
        if (j->skip[o]) {
            k[0] = k[1] = NAN;
            if (dir) dir[0] = dir[1] = dir[2] = NAN;
            continue;
        }
        if (set >= 0 && p->curv_set[set] == 1 && !child && p->st_start[o + 1] - p->st_start[o] == 9) {
            /* a regular row of a shared weight set: its indices, the set's weights */
            const int32_t *idx = p->st_v + p->st_start[o];
            const double *w = p->curv_ws + 45 * (size_t)set;
            for (int e = 0; e < 9; e++) {
                const double *q = SPOINT(idx[e]);
                for (int c = 0; c < 5; c++)
                    for (int x = 0; x < 3; x++) d[c][x] += w[9 * c + e] * q[x];
            }
        } else {
            if (!ccn__curvature_stencil(mL, v, pinned, child, &s)) {
                k[0] = k[1] = NAN;
                if (dir) dir[0] = dir[1] = dir[2] = NAN;
                continue;
            }
            for (int e = 0; e < s.n; e++) {
                int32_t i = child ? s.v[e] + nvL : s.v[e];
                const double *q = SPOINT(i);
                for (int c = 0; c < 5; c++)
                    for (int x = 0; x < 3; x++) d[c][x] += s.w[c][e] * q[x];
            }
        }
        ccn__principal_curvatures((const double(*)[3])d, &k[0], &k[1], dir);
        /* the levels' points are in the unit box of evaluate: lengths scale by p->scale */
        k[0] /= p->scale;
        k[1] /= p->scale;
    }
}

/* The second-derivative weights of every shared weight set (p->curv_ws), once per plan: the
 * stencil of the first regular row using the set (identical first-derivative weights of a 3 x 3
 * tensor row determine its knot intervals, so the set's rows share these too); a set whose
 * first row's stencil is not in its row's order is left to the per-vertex path. */
static int shared_sets(ccn_plan *p, const uint8_t *near) {
    if (p->curv_set || p->nws == 0) return 0;
    p->curv_ws = malloc(sizeof(double) * 45 * (size_t)p->nws);
    p->curv_set = calloc((size_t)p->nws, 1);
    if (!p->curv_ws || !p->curv_set) {
        free(p->curv_ws); free(p->curv_set);
        p->curv_ws = NULL, p->curv_set = NULL;
        return -1;
    }
    const ccn_mesh *mL = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn__stencil2 s;
    for (int32_t o = 0; o < p->nout_v; o++) {
        if (p->st_w[o] >= 0 || near[p->out_vL[o]]) continue;
        int32_t set = -1 - p->st_w[o];
        if (p->curv_set[set]) continue;
        p->curv_set[set] = 2;
        const int32_t *idx = p->st_v + p->st_start[o];
        if (p->st_start[o + 1] - p->st_start[o] != 9 ||
            !ccn__curvature_stencil(mL, p->out_vL[o], pinned, 0, &s) || s.n != 9)
            continue;
        int same = 1;
        for (int e = 0; e < 9; e++) same &= s.v[e] == idx[e];
        if (!same) continue;
        for (int c = 0; c < 5; c++)
            for (int e = 0; e < 9; e++) p->curv_ws[45 * (size_t)set + 9 * c + e] = s.w[c][e];
        p->curv_set[set] = 1;
    }
    return 0;
}

ccn_status ccn__curvature_evaluate(ccn_plan *p, ccn_limit_mesh *out, ccn_error *err) {
    const ccn_mesh *mL = p->lev[p->L];
    uint8_t *near = calloc((size_t)mL->nv + (size_t)p->nout_v + 1, 1);
    if (!near) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (curvature)");
    uint8_t *skip = near + mL->nv;
    for (int32_t i = 0; i < p->nnear; i++) near[p->near[i]] = 1;
    if (shared_sets(p, near)) {
        free(near);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (curvature)");
    }
    for (int32_t i = 0; i < p->nsv; i++) skip[p->sv_out[i]] = 1; /* creases, corners */
    for (int32_t i = 0; i < p->nhv; i++) skip[p->hv_out[i]] = 1; /* caps */
    for (int32_t i = 0; i < p->nbv; i++) /* bicubic faces around caps (not a patch: the limit) */
        if (!isnan(p->rf_bez[48 * (size_t)p->bv_rf[i]])) skip[p->bv_out[i]] = 1;
    curv_job j = {p, out, near, skip};
    ccn__parallel_for(p->threads, p->nout_v, curv_range, &j);
    /* the patches: after ccn__caps_evaluate, which filled them */
    for (int32_t i = 0; i < p->nhv + p->nbv; i++) {
        int32_t o;
        double d[5][3];
        if (i < p->nhv) {
            const ccn__cap *cp = &p->caps[p->hv_cap[i]];
            o = p->hv_out[i];
            if (cp->w < 1) { /* blended with the refined limit: not computed */
                out->curvatures[2 * (size_t)o] = out->curvatures[2 * (size_t)o + 1] = NAN;
                if (out->curvature_dirs)
                    for (int k = 0; k < 3; k++) out->curvature_dirs[3 * (size_t)o + k] = NAN;
                continue;
            }
            double pu, pv, su, sv;
            const double *P = ccn__bi5_locate(cp->op, cp->patches, p->hv_sector[i], p->hv_uv[2 * i],
                                              p->hv_uv[2 * i + 1], &pu, &pv, &su, &sv);
            bezier_d2(P, 5, pu, pv, d);
        } else {
            int32_t b = i - p->nhv;
            const double *B = p->rf_bez + 48 * (size_t)p->bv_rf[b];
            if (isnan(B[0])) continue;
            o = p->bv_out[b];
            bezier_d2(B, 3, p->bv_uv[2 * b], p->bv_uv[2 * b + 1], d);
        }
        double *k = out->curvatures + 2 * (size_t)o;
        ccn__principal_curvatures((const double(*)[3])d, &k[0], &k[1],
                                  out->curvature_dirs ? out->curvature_dirs + 3 * (size_t)o : NULL);
        k[0] /= p->scale;
        k[1] /= p->scale;
    }
    free(near);
    return CCN_OK;
}
