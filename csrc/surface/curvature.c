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
 * A row's curvature stencil reads the points its position row reads, and the row's own
 * first-derivative weights are S_u and S_v. So the first evaluation asking for curvatures keeps
 * each row's S_uu, S_uv, S_vv weights beside its position weights (ccn__curvature_prepare: once
 * per shared weight set, else per row), and the stencil pass (surface/plan.c) computes
 * positions, normals and curvatures from one load of the points: a curvature costs nine more
 * products per entry and the forms. Rows whose curvature stencil reads other points (none in
 * the cages measured) keep the per-vertex path.
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
#include "surface/fill_cap.h"
#include "surface/limit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    ccn_plan *p;
    ccn_limit_mesh *out;
    const uint8_t *near; /* per level-L vertex: its limit is taken one level finer */
    const uint8_t *flag; /* per output vertex: not the refined limit's tensor spline */
} curv_job;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void ccn__principal_curvatures(const double d[5][3], double *k1, double *k2, double dir[3]) {
    const double *su = d[0], *sv = d[1];
    /* det from the cross product (|S_u x S_v|^2 = EG - F^2, without the cancellation) */
    double n[3] = {su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2],
                   su[0] * sv[1] - su[1] * sv[0]};
    double E = dot3(su, su), F = dot3(su, sv), G = dot3(sv, sv), det = dot3(n, n);
    if (!(det > 1e-300 * (E * G + 1e-300))) {
        *k1 = *k2 = NAN;
        if (dir) dir[0] = dir[1] = dir[2] = NAN;
        return;
    }
    double ln = sqrt(det);
    for (int i = 0; i < 3; i++) n[i] /= ln;
    double L = -dot3(d[2], n), M = -dot3(d[3], n), N = -dot3(d[4], n);
    ccn__forms_to_k(E, F, G, det, L, M, N, 1.0, k1, k2);
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

void ccn__curvature_at(const ccn_plan *p, const double d[5][3], ccn_limit_mesh *out, int32_t o) {
    double *k = out->curvatures + 2 * (size_t)o;
    ccn__principal_curvatures(d, &k[0], &k[1],
                              out->curvature_dirs ? out->curvature_dirs + 3 * (size_t)o : NULL);
    /* the levels' points are in the unit box of evaluate: lengths scale by p->scale */
    k[0] /= p->scale;
    k[1] /= p->scale;
}

void ccn__curvature_flag(ccn_limit_mesh *out, int32_t o) {
    out->curvatures[2 * (size_t)o] = out->curvatures[2 * (size_t)o + 1] = NAN;
    if (out->curvature_dirs)
        for (int k = 0; k < 3; k++) out->curvature_dirs[3 * (size_t)o + k] = NAN;
}

/* The curvature stencil s of output o (level-L vertex v; child: the grid one level finer,
 * its points after the level's in the stencil rows' numbering) aligned with o's stencil row:
 * the second-derivative weights in the row's order into wuu, wuv, wvv. 0 when s has other
 * points than the row, or first-derivative weights other than the row's (then o keeps its own
 * stencil). */
static int align_row(const ccn_plan *p, int32_t o, int child, const ccn__stencil2 *s,
                     double *wuu, double *wuv, double *wvv) {
    int32_t n = p->st_start[o + 1] - p->st_start[o], nvL = p->lev[p->L]->nv;
    const int32_t *idx = p->st_v + p->st_start[o];
    const double *wp, *wu, *wv;
    if (s->n != n) return 0;
    ccn__plan_row_weights(p, o, &wp, &wu, &wv);
    double scale = 0;
    for (int32_t k = 0; k < n; k++) scale += fabs(wu[k]) + fabs(wv[k]);
    for (int32_t k = 0; k < n; k++) {
        int e = 0;
        while (e < s->n && (child ? s->v[e] + nvL : s->v[e]) != idx[k]) e++;
        if (e == s->n || fabs(s->w[0][e] - wu[k]) > 1e-12 * scale ||
            fabs(s->w[1][e] - wv[k]) > 1e-12 * scale)
            return 0;
        wuu[k] = s->w[2][e];
        wuv[k] = s->w[3][e];
        wvv[k] = s->w[4][e];
    }
    return 1;
}

/* curv_mode and the own rows' aligned weights, per output (rows are independent). A shared
 * set's rows take the set's weights (made before from its first row) where their own stencil
 * has the same ones: equal first-derivative weights need not mean equal second-derivative ones
 * where a boundary's mirrored points merged into others (fewer than nine entries). */
static void mode_range(void *ctx, int32_t begin, int32_t end) {
    curv_job *j = ctx;
    ccn_plan *p = j->p;
    const ccn_mesh *mL = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn__stencil2 s;
    double e[3][CCN_STENCIL2_MAX];
    for (int32_t o = begin; o < end; o++) {
        int32_t v = p->out_vL[o], w = p->st_w[o], n = p->st_start[o + 1] - p->st_start[o];
        int child = j->near[v];
        uint8_t *mode = &p->curv_mode[o];
        if (!j->flag[o] && w < 0 && p->curv_set[-1 - w] == 1 && n == 9 && !child) {
            /* nine distinct points: the tensor's 1-D point and first-derivative weights fix
             * each direction's knot intervals (w_-1 / w'_-1 = -D_0 / 3, rules/bspline.c), so the
             * set's second-derivative weights are this row's */
            *mode = CCN__CURV_ROW;
            continue;
        }
        if (j->flag[o] || !ccn__curvature_stencil(mL, v, pinned, child, &s)) {
            *mode = CCN__CURV_FLAG;
            continue;
        }
        *mode = child ? CCN__CURV_OWN_CHILD : CCN__CURV_OWN;
        if (w >= 0) {
            if (align_row(p, o, child, &s, p->curv_wuu + w, p->curv_wuv + w, p->curv_wvv + w))
                *mode = CCN__CURV_ROW;
        } else if (p->curv_set[-1 - w] == 1 && n <= 9 &&
                   align_row(p, o, child, &s, e[0], e[1], e[2])) {
            const double *cw = p->curv_ws + 27 * (size_t)(-1 - w);
            if (!memcmp(e[0], cw, sizeof(double) * (size_t)n) &&
                !memcmp(e[1], cw + 9, sizeof(double) * (size_t)n) &&
                !memcmp(e[2], cw + 18, sizeof(double) * (size_t)n))
                *mode = CCN__CURV_ROW;
        }
    }
}

/* The tables of ccn__curvature_prepare dropped (out of memory: the next evaluation tries again). */
static ccn_status curv_fail(ccn_plan *p, ccn_error *err) {
    free(p->curv_mode); free(p->curv_set); free(p->curv_ws);
    free(p->curv_wuu); free(p->curv_wuv); free(p->curv_wvv); free(p->curv_other);
    p->curv_mode = p->curv_set = NULL;
    p->curv_ws = p->curv_wuu = p->curv_wuv = p->curv_wvv = NULL;
    p->curv_other = NULL;
    return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (curvature)");
}

ccn_status ccn__curvature_prepare(ccn_plan *p, ccn_error *err) {
    if (p->curv_mode) return CCN_OK;
    const ccn_mesh *mL = p->lev[p->L];
    int32_t nout = p->nout_v;
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    size_t nown = (size_t)(p->st_nown ? p->st_nown : 1), nset = (size_t)(p->nws ? p->nws : 1);
    uint8_t *near = calloc((size_t)mL->nv + (size_t)nout + 1, 1);
    p->curv_mode = malloc((size_t)(nout ? nout : 1));
    p->curv_set = calloc(nset, 1);
    p->curv_ws = malloc(sizeof(double) * 27 * nset);
    p->curv_wuu = malloc(sizeof(double) * nown);
    p->curv_wuv = malloc(sizeof(double) * nown);
    p->curv_wvv = malloc(sizeof(double) * nown);
    if (!near || !p->curv_mode || !p->curv_set || !p->curv_ws || !p->curv_wuu || !p->curv_wuv ||
        !p->curv_wvv) {
        free(near);
        return curv_fail(p, err);
    }
    uint8_t *flag = near + mL->nv;
    for (int32_t i = 0; i < p->nnear; i++) near[p->near[i]] = 1;
    for (int32_t i = 0; i < p->nsv; i++) flag[p->sv_out[i]] = 1; /* creases, corners */
    for (int32_t i = 0; i < p->nhv; i++) flag[p->hv_out[i]] = 1; /* caps: their patches */
    /* a shared weight set: the second-derivative weights of its first row (mode_range checks
     * the others against them) */
    ccn__stencil2 s;
    for (int32_t o = 0; o < nout && p->nws; o++) {
        int32_t w = p->st_w[o];
        if (w >= 0 || flag[o] || p->curv_set[-1 - w]) continue;
        int32_t set = -1 - w, child = near[p->out_vL[o]];
        double *cw = p->curv_ws + 27 * (size_t)set;
        p->curv_set[set] = 2;
        if (p->st_start[o + 1] - p->st_start[o] <= 9 &&
            ccn__curvature_stencil(mL, p->out_vL[o], pinned, child, &s) &&
            align_row(p, o, child, &s, cw, cw + 9, cw + 18))
            p->curv_set[set] = 1;
    }
    curv_job j = {p, NULL, near, flag};
    ccn__parallel_for(p->threads, nout, mode_range, &j);
    free(near);
    int32_t n = 0;
    for (int32_t o = 0; o < nout; o++) n += p->curv_mode[o] >= CCN__CURV_OWN;
    p->curv_other = malloc(sizeof(int32_t) * (size_t)(n ? n : 1));
    if (!p->curv_other) return curv_fail(p, err);
    p->ncurv_other = 0;
    for (int32_t o = 0; o < nout; o++)
        if (p->curv_mode[o] >= CCN__CURV_OWN) p->curv_other[p->ncurv_other++] = o;
    return CCN_OK;
}

/* The outputs whose curvature stencil is not their row's points: made and applied here. */
static void other_range(void *ctx, int32_t begin, int32_t end) {
    const curv_job *j = ctx;
    const ccn_plan *p = j->p;
    const ccn_mesh *mL = p->lev[p->L];
    const double *PL = mL->pos, *PS = p->posS;
    int32_t nvL = mL->nv;
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn__stencil2 s;
    for (int32_t i = begin; i < end; i++) {
        int32_t o = p->curv_other[i];
        int child = p->curv_mode[o] == CCN__CURV_OWN_CHILD;
        double d[5][3] = {{0}};
        if (!ccn__curvature_stencil(mL, p->out_vL[o], pinned, child, &s)) {
            ccn__curvature_flag(j->out, o);
            continue;
        }
        for (int e = 0; e < s.n; e++) {
            int32_t v = child ? s.v[e] + nvL : s.v[e];
            const double *q = SPOINT(v);
            for (int c = 0; c < 5; c++)
                for (int x = 0; x < 3; x++) d[c][x] += s.w[c][e] * q[x];
        }
        ccn__curvature_at(p, (const double(*)[3])d, j->out, o);
    }
}

void ccn__curvature_evaluate(ccn_plan *p, ccn_limit_mesh *out) {
    curv_job j = {p, out, NULL, NULL};
    ccn__parallel_for(p->threads, p->ncurv_other, other_range, &j);
    /* the patches: after ccn__caps_evaluate, which filled them */
    for (int32_t i = 0; i < p->nhv + p->nbv; i++) {
        int32_t o;
        double d[5][3];
        if (i < p->nhv) {
            const ccn__cap *cp = &p->caps[p->hv_cap[i]];
            o = p->hv_out[i];
            if (cp->fill && !(cp->w > 0)) { /* the G1 fill cap alone */
                double x[3]; /* d: S_u, S_v, S_uu, S_uv, S_vv (bezier_d2's) */
                ccn__fill_cap_eval(cp->fill, p->hv_sector[i], p->hv_uv[2 * i], p->hv_uv[2 * i + 1], x, d[0], d[1],
                                   (double(*)[3])d[2]);
                ccn__curvature_at(p, (const double(*)[3])d, out, o);
                continue;
            }
            if (cp->w < 1 || cp->wu > 0) { /* blended: not computed */
                ccn__curvature_flag(out, o);
                continue;
            }
            double pu, pv, su, sv;
            const double *P = ccn__bi5_locate(cp->op, cp->patches, p->hv_sector[i], p->hv_uv[2 * i],
                                              p->hv_uv[2 * i + 1], &pu, &pv, &su, &sv);
            bezier_d2(P, 5, pu, pv, d);
        } else { /* the bicubic faces around a cap: their patch where it has one */
            int32_t b = i - p->nhv;
            const double *B = p->rf_bez + 48 * (size_t)p->bv_rf[b];
            if (isnan(B[0])) continue;
            o = p->bv_out[b];
            if (p->caps[p->rf_cap[p->bv_rf[b]]].exact_surround) { /* blended with the limit */
                ccn__curvature_flag(out, o);
                continue;
            }
            bezier_d2(B, 3, p->bv_uv[2 * b], p->bv_uv[2 * b + 1], d);
        }
        ccn__curvature_at(p, (const double(*)[3])d, out, o);
    }
}
