/* ccn_plan_patches (public): the finite patch set of a plan, for export and inspection. */
#include "surface/plan_types.h"

#include "bi5/bi5.h"
#include "surface/patches.h"

#include <math.h>
#include <string.h>

static int32_t cage_face_of(const ccn_plan *p, int32_t l, int32_t f) {
    for (; l > 0; l--) f = p->lev[l - 1]->hface[f];
    return f;
}

/* Control points back in the caller's coordinates (evaluate works in a unit box). */
static void emit(const ccn_plan *p, ccn_patch_fn fn, void *user, int32_t deg, const double *pts,
                 int32_t face) {
    double buf[108];
    int32_t n = (deg + 1) * (deg + 1);
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) buf[3 * i + k] = p->centre[k] + p->scale * pts[3 * i + k];
    fn(user, deg, buf, face);
}

static void export_bicubic(const ccn_plan *p, int32_t lvl, ccn_patch_fn fn, void *user,
                           int32_t *skipped) {
    const ccn_mesh *m = p->lev[lvl];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    uint8_t *kind = calloc((size_t)(m->nf ? m->nf : 1), 1); /* 1 hole, 2 ring face */
    if (!kind) { *skipped = m->nf; return; }
    for (int32_t c = 0; c < p->ncap; c++)
        for (int32_t k = p->lev[p->K]->vfan_start[p->caps[c].cnet[0]];
             k < p->lev[p->K]->vfan_start[p->caps[c].cnet[0] + 1]; k++)
            kind[p->lev[p->K]->hface[p->lev[p->K]->vfan[k]]] = 1;
    for (int32_t i = 0; i < p->nrf; i++) kind[p->rf_face[i]] = 2;
    for (int32_t c = 0; c < p->ncap; c++) { /* exact surround: faces around the hole, 3 */
        const ccn__cap *cp = &p->caps[c];
        if (!cp->exact_surround || lvl != p->K) continue;
        for (int32_t j = 0; j < 2 * cp->n; j++)
            for (int32_t k = m->vfan_start[cp->ring[j]]; k < m->vfan_start[cp->ring[j] + 1]; k++)
                if (kind[m->hface[m->vfan[k]]] == 0) kind[m->hface[m->vfan[k]]] = 3;
    }
    double bez[4][4][3];
    for (int32_t f = 0; f < m->nf; f++) {
        if (kind[f] == 1) continue;
        if (kind[f] == 3) { /* not a tensor patch at level K: its level-(K+1) children are */
            for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
                if (ccn__bicubic_patch(p->lev[lvl + 1], h, pinned, 1, bez))
                    emit(p, fn, user, 3, &bez[0][0][0], cage_face_of(p, lvl + 1, h));
                else
                    (*skipped)++;
            }
            continue;
        }
        if (ccn__bicubic_patch(m, f, pinned, kind[f] != 2, bez))
            emit(p, fn, user, 3, &bez[0][0][0], cage_face_of(p, lvl, f));
        else
            (*skipped)++;
    }
    free(kind);
}

ccn_status ccn_plan_patches(const ccn_plan *p, ccn_patch_fn fn, void *user, int32_t *skipped) {
    if (!p || !fn) return CCN_ERR_ARGUMENT;
    int32_t sk = 0, lvl = p->K >= 0 ? p->K : p->R;
    export_bicubic(p, lvl, fn, user, &sk);
    for (int32_t c = 0; c < p->ncap; c++) {
        const ccn__cap *cp = &p->caps[c];
        const ccn_mesh *mK = p->lev[p->K];
        int32_t np = ccn__bi5_num_patches(cp->op);
        for (int32_t i = 0; i < np; i++) {
            int32_t s = i % cp->n, h = mK->vfan[mK->vfan_start[cp->cnet[0]] + s];
            emit(p, fn, user, 5, cp->patches + 108 * (size_t)i, cage_face_of(p, p->K, mK->hface[h]));
        }
    }
    if (skipped) *skipped = sk;
    return CCN_OK;
}
