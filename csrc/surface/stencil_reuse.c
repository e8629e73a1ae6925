/* What a recreated plan keeps of the stencil table of the plan it replaces
 * (a plan made with options.previous; surface/stencil_reuse.h): which rows may have changed, the earlier rows,
 * the earlier table patched in place. Used by surface/tessellate.c. */
#include "surface/stencil_reuse.h"

#include "base/parallel.h"
#include "surface/limit.h"
#include "topology/knots.h"
#include "topology/mesh.h"

#include <string.h>

/* a plan made with options.previous: the intervals of level L are q's but near the edges whose interval
 * changed. A regular output vertex's stencil (surface/limit.c) reads the intervals of the
 * edges at its fan's vertices (its own and the ones beyond each neighbour), so it may change
 * where a vertex of one of its faces ends a changed edge: those vertices get 1 in the
 * returned mask (NULL: out of memory, or nothing to compare). Intervals are compared in the
 * caller's units (eknot * knot_scale, exact: the scales are powers of two), as the
 * normalisation may differ; a kept stencil is then the one this plan would make, its
 * derivative weights in q's interval unit (a power of two apart), which gives the same unit
 * normals. */
uint8_t *ccn__moved_vertices(const ccn_mesh *m, const ccn_mesh *q) {
    uint8_t *ends = ccn__changed_interval_ends(m, q), *moved = calloc((size_t)(m->nv ? m->nv : 1), 1);
    if (!ends || !moved) { free(ends); free(moved); return NULL; }
    for (int32_t v = 0; v < m->nv; v++)
        if (ends[v]) ccn__mesh_mark_face_ring(m, &v, 1, NULL, moved);
    free(ends);
    return moved;
}

/* The length of output o's row in the earlier plan q if it is a regular one (level-L indices
 * only, at most CCN_FAST_MAX entries), else -1. */
int32_t ccn__earlier_regular(const ccn_plan *q, int32_t o) {
    int32_t b = q->st_start[o], n = q->st_start[o + 1] - b, nvL = q->lev[q->L]->nv;
    if (n > CCN_FAST_MAX) return -1;
    for (int32_t k = 0; k < n; k++)
        if (q->st_v[b + k] >= nvL) return -1;
    return n;
}

/* Output o's row in the earlier plan q, if it is a regular one: 1 and s filled, else 0. */
int ccn__earlier_row(const ccn_plan *q, int32_t o, ccn__stencil *s) {
    int32_t b = q->st_start[o], n = ccn__earlier_regular(q, o);
    if (n < 0) return 0;
    const double *wp, *wu, *wv;
    ccn__plan_row_weights(q, o, &wp, &wu, &wv);
    memcpy(s->v, q->st_v + b, sizeof(int32_t) * (size_t)n);
    memcpy(s->wp, wp, sizeof(double) * (size_t)n);
    memcpy(s->wu, wu, sizeof(double) * (size_t)n);
    memcpy(s->wv, wv, sizeof(double) * (size_t)n);
    s->n = n;
    return 1;
}

/* ccn_plan_create with options.previous, the stencil table of the earlier plan q patched where intervals moved: the
 * regular rows near a changed interval are made again (in threads) into scratch, and when every
 * one of them and every irregular row (made by the caller into ib) has q's row length, q's
 * table is taken over and those rows are written in place (own weights: over the old ones; a
 * row that shared a weight set gets own weights, appended). The other rows are q's, which
 * are exactly this plan's (see ccn__moved_vertices). Not taken either when more than half
 * the regular rows would end up with their own weights (shared sets are re-found only by a new
 * table). */
typedef struct {
    const ccn_mesh *mL;
    int pinned;
    const int32_t *dl, *out_vL;
    int32_t *dv, *dn;   /* per dirty row: CCN_FAST_MAX indices, the length */
    double *dw;         /* per dirty row: 3 * CCN_FAST_MAX weights (wp, wu, wv) */
} patch_job;

static void patch_range(void *ctx, int32_t begin, int32_t end) {
    const patch_job *j = ctx;
    ccn__stencil *s = malloc(sizeof *s);
    for (int32_t i = begin; i < end; i++) {
        j->dn[i] = -1;
        if (!s) continue;
        ccn__limit_stencil(j->mL, j->out_vL[j->dl[i]], j->pinned, s);
        if (s->n > CCN_FAST_MAX) continue;
        j->dn[i] = s->n;
        memcpy(j->dv + CCN_FAST_MAX * (size_t)i, s->v, sizeof(int32_t) * (size_t)s->n);
        double *w = j->dw + 3 * CCN_FAST_MAX * (size_t)i;
        memcpy(w, s->wp, sizeof(double) * (size_t)s->n);
        memcpy(w + CCN_FAST_MAX, s->wu, sizeof(double) * (size_t)s->n);
        memcpy(w + 2 * CCN_FAST_MAX, s->wv, sizeof(double) * (size_t)s->n);
    }
    free(s);
}

int ccn__patch_stencils(ccn_plan *p, const ccn__reuse_rows *j, ccn__reuse_table *b) {
    ccn_plan *q = p->hint;
    const ccn_mesh *mL = p->lev[p->L];
    int32_t nout = p->nout_v, nd = 0, nfast = 0;
    if (!q->st_start || !q->st_v || !q->st_w) return 0;
    for (int32_t o = 0; o < nout; o++) {
        int32_t n = q->st_start[o + 1] - q->st_start[o];
        if (!j->fast[o]) { if (j->len[o] != n || q->st_w[o] < 0) return 0; continue; }
        nfast++;
        nd += j->moved[p->out_vL[o]];
    }
    int32_t *dl = malloc(sizeof(int32_t) * (size_t)(nd ? nd : 1));
    int32_t *dv = malloc(sizeof(int32_t) * CCN_FAST_MAX * (size_t)(nd ? nd : 1));
    int32_t *dn = malloc(sizeof(int32_t) * (size_t)(nd ? nd : 1));
    double *dw = malloc(sizeof(double) * 3 * CCN_FAST_MAX * (size_t)(nd ? nd : 1));
    int r = -1;
    if (!dl || !dv || !dn || !dw) goto out;
    nd = 0;
    int64_t add = 0, own_rows = 0;
    for (int32_t o = 0; o < nout; o++) {
        if (!j->fast[o]) continue;
        int dirty = j->moved[p->out_vL[o]];
        if (dirty) dl[nd++] = o;
        if (dirty && q->st_w[o] < 0) add += q->st_start[o + 1] - q->st_start[o];
        own_rows += dirty || q->st_w[o] >= 0;
    }
    r = 0;
    if (q->nws && 2 * own_rows > nfast) goto out; /* mostly own weights: let a new table share */
    patch_job pj = {mL, j->pinned, dl, p->out_vL, dv, dn, dw};
    ccn__parallel_for(p->threads, nd, patch_range, &pj);
    for (int32_t i = 0; i < nd; i++)
        if (dn[i] != q->st_start[dl[i] + 1] - q->st_start[dl[i]]) goto out; /* other length */
    r = -1;
    if (add) { /* room for the rows that leave their shared set */
        size_t cap = (size_t)q->st_nown + (size_t)add;
        double *a = realloc(q->st_wp, sizeof(double) * cap);
        if (a) q->st_wp = a;
        double *c = realloc(q->st_wu, sizeof(double) * cap);
        if (c) q->st_wu = c;
        double *d = realloc(q->st_wv, sizeof(double) * cap);
        if (d) q->st_wv = d;
        if (!a || !c || !d) goto out;
    }
    /* taken: q's table is this plan's from here on */
    free(p->st_start);
    free(p->st_w);
    p->st_start = q->st_start; p->st_w = q->st_w; p->ws = q->ws; p->nws = q->nws;
    b->v = q->st_v; b->wp = q->st_wp; b->wu = q->st_wu; b->wv = q->st_wv;
    p->st_nown = q->st_nown;
    q->st_start = q->st_w = q->st_v = NULL; q->ws = q->st_wp = q->st_wu = q->st_wv = NULL;
    q->nws = 0;
    b->n = p->st_start[nout];
    for (int32_t o = 0; o < nout; o++) { /* the irregular rows, made by the caller */
        if (j->fast[o]) continue;
        int32_t at = p->st_start[o], w = p->st_w[o], from = j->istart[o], n = j->len[o];
        memcpy(b->v + at, j->iv + from, sizeof(int32_t) * (size_t)n);
        memcpy(b->wp + w, j->iwp + from, sizeof(double) * (size_t)n);
        memcpy(b->wu + w, j->iwu + from, sizeof(double) * (size_t)n);
        memcpy(b->wv + w, j->iwv + from, sizeof(double) * (size_t)n);
    }
    for (int32_t i = 0; i < nd; i++) { /* the regular rows near a changed interval */
        int32_t o = dl[i], n = dn[i], at = p->st_start[o];
        if (p->st_w[o] < 0) { p->st_w[o] = p->st_nown; p->st_nown += n; }
        int32_t w = p->st_w[o];
        const double *src = dw + 3 * CCN_FAST_MAX * (size_t)i;
        memcpy(b->v + at, dv + CCN_FAST_MAX * (size_t)i, sizeof(int32_t) * (size_t)n);
        memcpy(b->wp + w, src, sizeof(double) * (size_t)n);
        memcpy(b->wu + w, src + CCN_FAST_MAX, sizeof(double) * (size_t)n);
        memcpy(b->wv + w, src + 2 * CCN_FAST_MAX, sizeof(double) * (size_t)n);
    }
    r = 1;
out:
    free(dl); free(dv); free(dn); free(dw);
    return r;
}

