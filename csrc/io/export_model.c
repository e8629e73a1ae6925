/* The CAD export's model under construction (io/export.h): faces with owned B-spline data,
 * their cells, and the places of mesh faces on the cage. */
#include "io/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double UNIT[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

/* ---- places ------------------------------------------------------------------------ */

static void at(const ccn__xplace *q, double x, double y, double out[2]) {
    for (int d = 0; d < 2; d++)
        out[d] = q->p[0][d] + x * (q->p[1][d] - q->p[0][d]) + y * (q->p[2][d] - q->p[0][d]);
}

void ccn__xplace_sub(const ccn__xplace *q, const double r[3][2], ccn__xplace *out) {
    ccn__xplace o;
    o.cage_face = q->cage_face;
    o.sub = q->sub;
    for (int k = 0; k < 3; k++) at(q, r[k][0], r[k][1], o.p[k]);
    *out = o;
}

void ccn__xplace_child(const ccn__xplace *q, int32_t j, ccn__xplace *out) {
    const double *a = UNIT[j & 3], *b = UNIT[(j + 1) & 3], *c = UNIT[(j + 3) & 3];
    double r[3][2] = {{a[0], a[1]}, {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2},
                      {(a[0] + c[0]) / 2, (a[1] + c[1]) / 2}};
    ccn__xplace_sub(q, (const double(*)[2])r, out);
}

void ccn__xplace_rotate(const ccn__xplace *q, int32_t r, ccn__xplace *out) {
    const double *a = UNIT[r & 3], *b = UNIT[(r + 1) & 3], *c = UNIT[(r + 3) & 3];
    double rr[3][2] = {{a[0], a[1]}, {b[0], b[1]}, {c[0], c[1]}};
    ccn__xplace_sub(q, (const double(*)[2])rr, out);
}

void ccn__xplace_of(const ccn_mesh *const *lev, int32_t level, int32_t f, ccn__xplace *out) {
    int32_t corner[64];
    int32_t l = level;
    for (; l > 0; l--) { /* face f of level l is half-edge f of level l-1: corner f - fstart */
        const ccn_mesh *up = lev[l - 1];
        int32_t g = up->hface[f];
        corner[l] = f - up->fstart[g];
        f = g;
    }
    ccn__xplace q = {f, -1, {{0, 0}, {1, 0}, {0, 1}}};
    int32_t from = 1;
    if (ccn__fsize(lev[0], f) != 4 && level >= 1) { /* n-gon: its level-1 quad has its own frame */
        q.sub = corner[1];
        from = 2;
    }
    for (int32_t k = from; k <= level; k++) ccn__xplace_child(&q, corner[k], &q);
    *out = q;
}

/* ---- faces ------------------------------------------------------------------------- */

void ccn__xm_free_surface(ccn__cad_surface *s) {
    free((void *)s->poles);
    for (int d = 0; d < 2; d++) { free((void *)s->knots[d]); free((void *)s->mults[d]); }
    memset(s, 0, sizeof *s);
}

void ccn__xm_free(ccn__xmodel *xm) {
    for (int32_t f = 0; f < xm->num_faces; f++) ccn__xm_free_surface(&xm->faces[f].s);
    free(xm->faces);
    free(xm->cells);
    memset(xm, 0, sizeof *xm);
}

int32_t ccn__xm_add_face(ccn__xmodel *xm, int32_t kind, int32_t du, int32_t dv, int32_t nu,
                         int32_t nv, int32_t cells_u, int32_t cells_v) {
    if (xm->oom) return -1;
    if (xm->num_faces == xm->cap_faces) {
        int32_t c = xm->cap_faces ? 2 * xm->cap_faces : 256;
        ccn__xface *p = realloc(xm->faces, sizeof *p * (size_t)c);
        if (!p) { xm->oom = 1; return -1; }
        xm->faces = p;
        xm->cap_faces = c;
    }
    int32_t nc = cells_u * cells_v;
    if (xm->num_cells + nc > xm->cap_cells) {
        int32_t c = 2 * (xm->num_cells + nc) + 256;
        ccn__xcell *p = realloc(xm->cells, sizeof *p * (size_t)c);
        if (!p) { xm->oom = 1; return -1; }
        xm->cells = p;
        xm->cap_cells = c;
    }
    ccn__xface *F = &xm->faces[xm->num_faces];
    memset(F, 0, sizeof *F);
    F->kind = kind;
    F->patch = -1;
    F->fill = -1;
    F->cells_u = cells_u;
    F->cells_v = cells_v;
    F->cell0 = xm->num_cells;
    F->s.degree[0] = du;
    F->s.degree[1] = dv;
    F->s.num_poles[0] = nu;
    F->s.num_poles[1] = nv;
    double *poles = malloc(sizeof(double) * 3 * (size_t)nu * (size_t)nv);
    if (!poles) { xm->oom = 1; return -1; }
    F->s.poles = poles;
    xm->num_cells += nc;
    return xm->num_faces++;
}

int ccn__xm_set_flat(ccn__xmodel *xm, int32_t f, int dir, const double *t) {
    ccn__cad_surface *s = &xm->faces[f].s;
    int32_t m = s->num_poles[dir] + s->degree[dir] + 1, nk = 0;
    double *k = malloc(sizeof(double) * (size_t)m);
    int32_t *mu = malloc(sizeof(int32_t) * (size_t)m);
    if (!k || !mu) { free(k); free(mu); xm->oom = 1; return -1; }
    for (int32_t i = 0; i < m; i++) {
        if (nk && t[i] == k[nk - 1]) { mu[nk - 1]++; continue; }
        k[nk] = t[i];
        mu[nk++] = 1;
    }
    free((void *)s->knots[dir]);
    free((void *)s->mults[dir]);
    s->knots[dir] = k;
    s->mults[dir] = mu;
    s->num_knots[dir] = nk;
    return 0;
}

void ccn__cad_flat_knots(const ccn__cad_surface *s, int dir, double *t) {
    for (int32_t k = 0, i = 0; k < s->num_knots[dir]; k++)
        for (int32_t c = 0; c < s->mults[dir][k]; c++) t[i++] = s->knots[dir][k];
}

double ccn__cad_surface_size(const ccn__cad_surface *s, double *reach) {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, d2 = 0, big = 0;
    for (int64_t i = 0; i < (int64_t)s->num_poles[0] * s->num_poles[1]; i++)
        for (int c = 0; c < 3; c++) {
            double x = s->poles[3 * i + c];
            lo[c] = fmin(lo[c], x), hi[c] = fmax(hi[c], x), big = fmax(big, fabs(x));
        }
    for (int c = 0; c < 3; c++) d2 += hi[c] > lo[c] ? (hi[c] - lo[c]) * (hi[c] - lo[c]) : 0;
    if (reach) *reach = big;
    return sqrt(d2);
}

int32_t ccn__xm_add_bezier(ccn__xmodel *xm, int32_t kind, int32_t deg, const double *pts,
                           const ccn__xplace *pl) {
    int32_t f = ccn__xm_add_face(xm, kind, deg, deg, deg + 1, deg + 1, 1, 1);
    if (f < 0) return -1;
    double t[12];
    for (int32_t i = 0; i < 2 * (deg + 1); i++) t[i] = i <= deg ? 0 : 1;
    if (ccn__xm_set_flat(xm, f, 0, t) || ccn__xm_set_flat(xm, f, 1, t)) return -1;
    memcpy((void *)xm->faces[f].s.poles, pts, sizeof(double) * 3 * (size_t)((deg + 1) * (deg + 1)));
    ccn__xcell *c = &xm->cells[xm->faces[f].cell0];
    c->uv[0] = 0; c->uv[1] = 1; c->uv[2] = 0; c->uv[3] = 1;
    c->pl = *pl;
    return f;
}

void ccn__xm_unit_domains(ccn__xmodel *xm) {
    for (int32_t f = 0; f < xm->num_faces; f++) {
        ccn__xface *X = &xm->faces[f];
        if (X->kind == CCN_EXPORT_FACE_PACK || X->kind == CCN_EXPORT_FACE_REFINED) continue;
        for (int dir = 0; dir < 2; dir++) {
            double lo, hi;
            ccn__cad_domain(&X->s, dir, &lo, &hi);
            if (lo == 0 && hi == 1) continue;
            double w = hi - lo, *k = (double *)X->s.knots[dir];
            int ok = w > 0 && isfinite(w);
            for (int32_t i = 1; i < X->s.num_knots[dir] && ok; i++) /* still distinct */
                ok = (k[i] - lo) / w > (k[i - 1] - lo) / w;
            if (!ok) continue;
            /* the same map on every value, so knots and cell bounds that were equal stay equal,
             * and lo, hi land on 0 and 1 exactly */
            for (int32_t i = 0; i < X->s.num_knots[dir]; i++) k[i] = (k[i] - lo) / w;
            for (int32_t c = 0; c < X->cells_u * X->cells_v; c++) {
                double *uv = xm->cells[X->cell0 + c].uv + 2 * dir;
                uv[0] = (uv[0] - lo) / w;
                uv[1] = (uv[1] - lo) / w;
            }
        }
    }
}
