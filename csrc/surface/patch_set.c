/* ccn_plan_patches (public) and ccn__plan_patches_placed (internal, for the CAD export): the
 * finite patch set of a plan, and where each patch lies in the plan's meshes. */
#include "surface/patch_set.h"

#include "surface/plan_types.h"

#include "bi5/bi5.h"
#include "surface/fill_cap.h"
#include "surface/patches.h"

#include <math.h>
#include <string.h>

static const double UNIT[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

typedef struct {
    const ccn_plan *p;
    ccn__place_fn fn;
    void *user;
    int32_t index;  /* next patch index */
    double buf[108];
} walk;

/* Emits one patch (points in the plan's unit box, mapped back to the caller's coordinates
 * like ccn_plan_evaluate) or a hole (pts NULL). rect NULL: the whole face. */
static void emit(walk *w, int32_t kind, int32_t deg, const double *pts, int32_t level, int32_t face,
                 const double rect[3][2], int32_t cap, int32_t sector, int32_t ring, int32_t part) {
    const ccn_plan *p = w->p;
    ccn__patch_place pl;
    pl.kind = kind;
    pl.degree = pts ? deg : 0;
    pl.level = level;
    pl.face = face;
    for (int k = 0; k < 3; k++) {
        pl.rect[k][0] = rect ? rect[k][0] : UNIT[k == 2 ? 3 : k][0];
        pl.rect[k][1] = rect ? rect[k][1] : UNIT[k == 2 ? 3 : k][1];
    }
    pl.cap = cap;
    pl.sector = sector;
    pl.ring = ring;
    pl.part = part;
    pl.points = NULL;
    pl.index = -1;
    if (pts) {
        int32_t n = (deg + 1) * (deg + 1);
        for (int32_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) w->buf[3 * i + k] = p->centre[k] + p->scale * pts[3 * i + k];
        pl.points = w->buf;
        pl.index = w->index++;
    }
    w->fn(w->user, &pl);
}

static int export_bicubic(walk *w, int32_t lvl) {
    const ccn_plan *p = w->p;
    const ccn_mesh *m = p->lev[lvl];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    uint8_t *kind = calloc((size_t)(m->nf ? m->nf : 1), 1); /* 1 hole, 2 ring face */
    if (!kind) return -1;
    for (int32_t c = 0; c < p->ncap; c++)
        for (int32_t k = p->lev[p->K]->vfan_start[p->caps[c].cnet[0]];
             k < p->lev[p->K]->vfan_start[p->caps[c].cnet[0] + 1]; k++)
            kind[p->lev[p->K]->hface[p->lev[p->K]->vfan[k]]] = 1;
    for (int32_t i = 0; i < p->nrf; i++) /* ring faces (of an exact-surround cap: its uniform twin's) */
        if (!p->caps[p->rf_cap[i]].exact_surround) kind[p->rf_face[i]] = 2;
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
                int ok = ccn__bicubic_patch(p->lev[lvl + 1], h, pinned, 1, bez);
                emit(w, ok ? CCN__PATCH_SURROUND : CCN__PATCH_HOLE, 3, ok ? &bez[0][0][0] : NULL,
                     lvl + 1, h, NULL, -1, -1, -1, -1);
            }
            continue;
        }
        int ok = ccn__bicubic_patch(m, f, pinned, kind[f] != 2, bez);
        int32_t kd = !ok ? CCN__PATCH_HOLE : kind[f] == 2 ? CCN__PATCH_RING : CCN__PATCH_STRICT;
        emit(w, kd, 3, ok ? &bez[0][0][0] : NULL, lvl, f, NULL, -1, -1, -1, -1);
    }
    free(kind);
    return 0;
}

void ccn__cap_patch_rect(const struct ccn__bi5 *op, int32_t n, int32_t i, int32_t j0, double rect[3][2]) {
    int32_t r = i / (3 * n), part = (i / n) % 3, nsig = op->nsig;
    double R = 1, hole[3][2]; /* hole coordinates of the patch's (0,0), (1,0), (0,1) */
    for (int32_t q = 0; q < r && q < nsig; q++) R *= 1.0 - op->sig[q];
    if (r >= nsig) {
        double z[3][2] = {{0, 0}, {R, 0}, {0, R}};
        memcpy(hole, z, sizeof hole);
    } else {
        double Rn = R * (1.0 - op->sig[r]);
        double a[3][3][2] = {{{Rn, 0}, {R, 0}, {Rn, Rn}},      /* A: u in [Rn,R], v in [0,Rn] */
                             {{Rn, Rn}, {R, Rn}, {Rn, R}},     /* B */
                             {{0, Rn}, {Rn, Rn}, {0, R}}};     /* C: u in [0,Rn], v in [Rn,R] */
        for (int k = 0; k < 3; k++) { hole[k][0] = a[part][k][0]; hole[k][1] = a[part][k][1]; }
    }
    const double *o = UNIT[j0], *eu = UNIT[(j0 + 1) % 4], *ev = UNIT[(j0 + 3) % 4];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++)
            rect[k][d] = o[d] + hole[k][0] * (eu[d] - o[d]) + hole[k][1] * (ev[d] - o[d]);
}

/* The G1 fill cap of cap c: per sector four quintic Bezier patches, each a quarter of the
 * sector's level-K face. */
static void export_fill(walk *w, int32_t c) {
    const ccn_plan *p = w->p;
    const ccn__cap *cp = &p->caps[c];
    const ccn_mesh *mK = p->lev[p->K];
    for (int32_t s = 0; s < cp->n; s++) {
        int32_t h = mK->vfan[mK->vfan_start[cp->cnet[0]] + s], f = mK->hface[h], j0 = h - mK->fstart[f];
        double b[4][6][6][3];
        ccn__fill_cap_bezier(cp->fill, s, b);
        const double *o = UNIT[j0], *eu = UNIT[(j0 + 1) % 4], *ev = UNIT[(j0 + 3) % 4];
        for (int q = 0; q < 4; q++) {
            double a = 0.5 * (q / 2), cc = 0.5 * (q % 2), hole[3][2] = {{a, cc}, {a + 0.5, cc}, {a, cc + 0.5}}, rect[3][2];
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 2; d++)
                    rect[k][d] = o[d] + hole[k][0] * (eu[d] - o[d]) + hole[k][1] * (ev[d] - o[d]);
            emit(w, CCN__PATCH_CAP, 5, &b[q][0][0][0], p->K, f, (const double(*)[2])rect, c, s, -1, -1);
        }
    }
}

/* The bi-5 patches of cap c, each placed in its sector's level-K face (ccn__cap_patch_rect). */
static void export_cap(walk *w, int32_t c) {
    const ccn_plan *p = w->p;
    const ccn__cap *cp = &p->caps[c];
    if (!(cp->w > 0)) {
        export_fill(w, c);
        return;
    }
    const ccn_mesh *mK = p->lev[p->K];
    int32_t n = cp->n, nsig = cp->op->nsig, np = ccn__bi5_num_patches(cp->op);
    for (int32_t i = 0; i < np; i++) {
        int32_t s = i % n, r = i / (3 * n), part = (i / n) % 3;
        int32_t h = mK->vfan[mK->vfan_start[cp->cnet[0]] + s], f = mK->hface[h];
        double rect[3][2];
        ccn__cap_patch_rect(cp->op, n, i, h - mK->fstart[f], rect);
        emit(w, r >= nsig ? CCN__PATCH_CAP : CCN__PATCH_CAP_RING, 5, cp->patches + 108 * (size_t)i,
             p->K, f, (const double(*)[2])rect, c, s, r, r >= nsig ? -1 : part);
    }
}

ccn_status ccn__plan_patches_placed(const ccn_plan *p, ccn__place_fn fn, void *user) {
    if (!p || !fn) return CCN_ERR_ARGUMENT;
    walk w;
    w.p = p;
    w.fn = fn;
    w.user = user;
    w.index = 0;
    if (export_bicubic(&w, p->K >= 0 ? p->K : p->R)) return CCN_ERR_MEMORY;
    for (int32_t c = 0; c < p->ncap; c++) export_cap(&w, c);
    return CCN_OK;
}

void ccn__plan_view_get(const ccn_plan *p, ccn__plan_view *v) {
    v->num_levels = p->R + 1;
    v->lev = (const ccn_mesh *const *)p->lev;
    v->patch_level = p->K >= 0 ? p->K : p->R;
    v->cap_level = p->K;
    v->scheme = (int32_t)p->opts.scheme;
    v->pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    memcpy(v->centre, p->centre, sizeof v->centre);
    v->scale = p->scale;
    v->crease_method = p->opts.crease_method;
    v->ev_polyhedron = p->opts.ev_polyhedron;
    v->ev_cache = p->ev_cache;
    v->guided_caps = p->opts.cap != CCN_CAP_REFINE;
    v->output_level = p->L;
}

/* ---- ccn_plan_patches ------------------------------------------------------------ */

typedef struct { ccn_patch_fn fn; void *user; int32_t skipped; } public_walk;

static int32_t cage_face_of(const ccn_plan *p, int32_t l, int32_t f) {
    for (; l > 0; l--) f = p->lev[l - 1]->hface[f];
    return f;
}

typedef struct { const ccn_plan *p; public_walk *pw; } public_ctx;

static void public_emit(void *user, const ccn__patch_place *pl) {
    public_ctx *c = user;
    if (!pl->points) { c->pw->skipped++; return; }
    c->pw->fn(c->pw->user, pl->degree, pl->points, cage_face_of(c->p, pl->level, pl->face));
}

ccn_status ccn_plan_patches(const ccn_plan *p, ccn_patch_fn fn, void *user, int32_t *skipped) {
    if (!p || !fn) return CCN_ERR_ARGUMENT;
    public_walk pw = {fn, user, 0};
    public_ctx c = {p, &pw};
    ccn_status st = ccn__plan_patches_placed(p, public_emit, &c);
    if (skipped) *skipped = st ? 0 : pw.skipped;
    return st;
}
