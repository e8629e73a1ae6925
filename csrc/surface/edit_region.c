/* What an interval edit changes of the earlier plan's last evaluation (a plan made with options.previous and
 * ccn_plan_evaluate_changed; surface/edit_region.h).
 *
 * After an interval edit the cage positions are usually those of the earlier plan's last
 * evaluation, and a level point can then change only where its rule's weights or its inputs
 * changed. At level l, let X be the vertices whose point changed and the ends of the edges
 * whose interval changed (every rule reads the intervals of edges at its element's vertices
 * only: refine/level.c, ccn__level_tabulate_like), and Z the vertices within two face rings of
 * X. A level-(l+1) point reads level-l points within two face rings of its element's vertices:
 * a vertex point its faces' corners and the curve points H of its fan edges (one vertex
 * beyond each neighbour), an edge point its two faces and its curve, a face point its corners,
 * an EV's red points its 1-ring (Li 2016 §6.1). So only the children of the faces, edges and
 * vertices touching Z can change; the others keep the earlier plan's points, moved over, which
 * are this plan's to the bit (the same arithmetic on the same numbers: intervals are
 * normalised by powers of two, topology/knots.c). At level L a stencil row is applied again
 * when it reads a changed point or a level-(L+1) point (made again by every evaluation), or
 * when it was made again itself (surface/tessellate.c sets redo). ccn_plan_evaluate_changed
 * checks that the positions are the same and else evaluates everything.
 */
#include "surface/edit_region.h"

#include "topology/knots.h"
#include "topology/mesh.h"

#include <string.h>

void ccn__edit_region_free(struct ccn__edit_region *r) {
    if (!r) return;
    for (int32_t l = 0; r->lists && l < r->R; l++) {
        free(r->lists[l].f); free(r->lists[l].e); free(r->lists[l].v);
    }
    free(r->lists); free(r->pos0); free(r->dirtyL); free(r->redo); free(r->rows); free(r->written);
    free(r);
}

/* The set entries of mask (n) into list (n entries room): their count. */
static int32_t listed(const uint8_t *mask, int32_t n, int32_t *list) {
    int32_t c = 0;
    for (int32_t i = 0; i < n; i++)
        if (mask[i]) list[c++] = i;
    return c;
}

static int32_t *alloc_list(int32_t n) { return malloc(sizeof(int32_t) * (size_t)(n ? n : 1)); }

/* Level l = m (q: the earlier plan's, for its intervals), D: its changed points (NULL: none).
 * Fills the lists of elements to compute and *child, the changed points of level l+1. The
 * work is the changed region's, but for the passes over the edges' intervals and the masks. */
static int level_lists(const ccn_mesh *m, const ccn_mesh *q, const uint8_t *D, ccn__edit_lists *L,
                       uint8_t **child) {
    uint8_t *x = ccn__changed_interval_ends(m, q);
    int64_t nc = (int64_t)m->nf + m->ne + m->nv;
    uint8_t *c = calloc((size_t)nc + 1, 1), *fm = calloc((size_t)m->nf + 1, 1);
    int32_t *list = alloc_list(m->nv);
    int ok = x && c && fm && list;
    if (ok) {
        if (D) for (int32_t v = 0; v < m->nv; v++) x[v] |= D[v];
        uint8_t *z = c + m->nf + m->ne; /* Z: X and two face rings around it */
        memcpy(z, x, (size_t)m->nv);
        int32_t n = listed(x, m->nv, list);
        ccn__mesh_mark_face_ring(m, list, n, fm, z);  /* one ring */
        n = listed(z, m->nv, list);
        ccn__mesh_mark_face_ring(m, list, n, c, z);   /* two (c: the faces around the first ring) */
        n = listed(z, m->nv, list);
        for (int32_t i = 0; i < n; i++) { /* the faces and edges touching Z */
            int32_t v = list[i];
            for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) c[m->hface[m->vfan[k]]] = 1;
            for (int32_t k = 0, nk = ccn__valence(m, v); k < nk; k++) c[m->nf + ccn__fan_edge(m, v, k)] = 1;
        }
        L->v = list;
        list = NULL;
        L->nv = n;
        L->f = alloc_list(m->nf);
        L->e = alloc_list(m->ne);
        ok = L->f && L->e;
        if (ok) {
            L->nf = listed(c, m->nf, L->f);
            L->ne = listed(c + m->nf, m->ne, L->e);
        }
    }
    free(x);
    free(fm);
    free(list);
    if (!ok) { free(c); c = NULL; }
    *child = c;
    return ok ? 0 : -1;
}

int ccn__edit_region_begin(ccn_plan *p) {
    ccn_plan *q = p->hint;
    p->region = NULL;
    if (!q || !q->evaluated || q->R != p->R || q->L != p->L) return 0;
    for (int32_t l = 0; l <= p->R; l++)
        if (!q->lev[l] || !q->lev[l]->pos || q->lev[l]->nv != p->lev[l]->nv) return 0;
    struct ccn__edit_region *r = calloc(1, sizeof *r);
    if (!r) return -1;
    r->R = p->R;
    r->lists = calloc((size_t)(p->R ? p->R : 1), sizeof *r->lists);
    size_t n0 = sizeof(double) * 3 * (size_t)p->lev[0]->nv;
    r->pos0 = malloc(n0 ? n0 : 1);
    if (!r->lists || !r->pos0) { ccn__edit_region_free(r); return -1; }
    memcpy(r->pos0, q->lev[0]->pos, n0);
    memcpy(r->centre, q->centre, sizeof r->centre);
    r->scale = q->scale;
    memcpy(r->out, q->last_out, sizeof r->out);
    uint8_t *D = NULL, *DL = NULL; /* level l's changed points; level L's */
    for (int32_t l = 0; l < p->R; l++) {
        uint8_t *child = NULL;
        int bad = level_lists(p->lev[l], q->lev[l], D, &r->lists[l], &child);
        if (D != DL) free(D);
        D = child;
        if (l + 1 == p->L) DL = D;
        if (bad) {
            if (D != DL) free(D);
            free(DL);
            ccn__edit_region_free(r);
            return -1;
        }
    }
    if (D != DL) free(D);
    if (!DL && !(DL = calloc((size_t)p->lev[p->L]->nv + 1, 1))) { ccn__edit_region_free(r); return -1; }
    r->dirtyL = DL;
    for (int32_t l = 1; l <= p->R; l++) { /* the earlier plan's points become this plan's */
        double *t = p->lev[l]->pos;
        p->lev[l]->pos = q->lev[l]->pos;
        q->lev[l]->pos = t;
    }
    p->region = r;
    return 0;
}

int ccn__edit_region_rows(ccn_plan *p) {
    struct ccn__edit_region *r = p->region;
    if (!r) return 0;
    if (!r->redo) { ccn__edit_region_free(r); p->region = NULL; return 0; }
    const ccn_mesh *mL = p->lev[p->L];
    int32_t nout = p->nout_v, nvL = mL->nv, n = 0;
    r->rows = alloc_list(nout);
    r->written = calloc((size_t)(nout ? nout : 1), 1);
    int32_t *list = alloc_list(nvL);
    uint8_t *near = calloc((size_t)nvL + 1, 1), *fm = calloc((size_t)mL->nf + 1, 1);
    if (!r->rows || !r->written || !list || !near || !fm) {
        free(list); free(near); free(fm);
        ccn__edit_region_free(r);
        p->region = NULL;
        return -1;
    }
    /* a regular row (not redo) reads its vertex's 1-ring at level L only: it reads a changed
     * point when a changed point lies on a face around its vertex */
    ccn__mesh_mark_face_ring(mL, list, listed(r->dirtyL, nvL, list), fm, near);
    for (int32_t o = 0; o < nout; o++)
        if (r->redo[o] || near[p->out_vL[o]]) r->rows[n++] = o;
    free(list); free(near); free(fm);
    r->nrows = n;
    return 0;
}
