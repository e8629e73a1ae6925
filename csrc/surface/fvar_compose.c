/* The composed limit stencils of a face-varying channel (surface/fvar_compose.h).
 *
 * The channel is the value mesh of refine/fvar.c refined through the plan's L levels in
 * lockstep with the vertex levels (their intervals and creases), with the exact limit stencil
 * of every level-L value vertex built as for positions (surface/limit.c on the value mesh:
 * tensor B-spline stencils where the 3x3 neighbourhood is regular, one level finer next to
 * irregular value vertices, the stationary 1-ring matrix on seams, corners and creases, the
 * left eigenvectors of M at EVs, taken over from the positions' stencil where the value vertex
 * matches the vertex). All of it is linear in the cage values, and an output value depends only
 * on the values at the corners of the faces that share a value vertex with its cage face (the
 * 4 x 4 of a regular patch). So its weights are read off by probing: the cage's value vertices
 * are coloured so that no two in such a neighbourhood share a colour, every colour is set to 1
 * in turn (three per pass, the rules' three components), the levels and limit stencils run, and
 * each output's result for a colour is the weight of the one value of that colour around it.
 * The weights are those evaluation would apply, summed in another order (a few ulps); each
 * stencil's weights must sum to 1 (affine invariance), which checks the neighbourhood bound.
 * Evaluation is then one sparse product per channel, and the levels are freed. Mode ALL
 * (bilinear) at level 0 composes the same way from its level-0 values.
 *
 * Outputs on a cage face whose value mesh is a regular grid around it get their weights
 * written down instead (the bicubic B-spline patch, surface/fvar_direct.c); the probes then
 * compute only the points the other outputs read and colour only the value vertices around
 * the other faces (surface/fvar_probe.c). When every face's are written down, levels 1..L are
 * only numbered (numbered()).
 *
 * Mode ALL from level 1 on is written down for every face (surface/fvar_bilinear.c); the rows'
 * last step, over the caller's values, is surface/fvar_rows.c's.
 *
 * Around a value vertex of high valence (a UV-mapped n-gon cap) every face's neighbourhood
 * holds the whole cap, so each of its values needs its own colour and probing would take n/3
 * passes over the region. Beyond CCN_FVAR_MAX_PASSES the probed outputs get no row: the
 * builder is kept in the stencils and they are evaluated through it, one pass per three
 * components of the caller's values (ccn__fvar_levels_evaluate, surface/fvar_probe.c).
 */
#include "surface/fvar_compose.h"

#include "base/error.h"
#include "base/parallel.h"
#include "refine/children.h"
#include "refine/fvar.h"
#include "rules/crease.h"
#include "surface/fvar_bilinear.h"
#include "surface/fvar_direct.h"
#include "surface/fvar_probe.h"
#include "surface/fvar_rows.h"
#include "surface/limit.h"

#include <math.h>
#include <string.h>

typedef ccn__fvar_builder builder;

#define CCN_FVAR_MAX_PASSES 16 /* probe passes (3 colours each) before a channel keeps its levels */

/* ---- the channel's levels and limit stencils -------------------------------------------- */

typedef struct { int32_t n, cap; int32_t *v; double *w; } wbuf;

static int push(wbuf *b, const ccn__stencil *s, int32_t off) {
    if (b->n + s->n > b->cap) {
        int64_t nc = 2 * (int64_t)b->cap + s->n + 1024;
        if (nc > INT32_MAX) return -1;
        int32_t *v = realloc(b->v, sizeof(int32_t) * (size_t)nc);
        if (v) b->v = v;
        double *w = realloc(b->w, sizeof(double) * (size_t)nc);
        if (w) b->w = w;
        if (!v || !w) return -1;
        b->cap = (int32_t)nc;
    }
    for (int i = 0; i < s->n; i++) {
        b->v[b->n] = s->v[i] + off;
        b->w[b->n++] = s->wp[i];
    }
    return 0;
}

/* A value vertex u at an interior EV of the value mesh has the vertex's fan, intervals and
 * scheme: its child stencil is the positions' stencil of vertex v, renumbered (level L+1 face
 * points keep their index, the edge points of v's spokes and v's vertex point map to u's). */
static int reuse_ev_stencil(const ccn_plan *p, const ccn_mesh *fm, int32_t u, int32_t v,
                            ccn__stencil *s) {
    const ccn_mesh *vm = p->lev[p->L];
    int32_t o = p->vmapL[v], nvL = vm->nv;
    if (o < 0) return 0;
    const double *wp, *wu, *wv;
    ccn__plan_row_weights(p, o, &wp, &wu, &wv);
    s->n = 0;
    for (int32_t k = p->st_start[o]; k < p->st_start[o + 1]; k++) {
        int32_t i = p->st_v[k] - nvL, j = -1;
        if (i < 0 || s->n >= CCN_STENCIL_MAX) return 0;
        if (i < vm->nf) j = i;
        else if (i >= vm->nf + vm->ne) j = i == vm->nf + vm->ne + v ? fm->nf + fm->ne + u : -1;
        else
            for (int32_t q = vm->vfan_start[v]; q < vm->vfan_start[v + 1] && j < 0; q++)
                if (vm->hedge[vm->vfan[q]] == i - vm->nf) j = fm->nf + fm->hedge[vm->vfan[q]];
        if (j < 0) return 0;
        s->v[s->n] = j; s->wp[s->n] = wp[k - p->st_start[o]]; s->wu[s->n] = s->wv[s->n] = 0.0;
        s->n++;
    }
    return 1;
}

/* A value whose rule follows its partner's sharpness (OpenSubdiv's dependent sharpness): does
 * the partner still have semi-sharp edges (then the value's limit is taken one level finer,
 * where the sub level applied the rule), and their sharpness one level finer, the largest, to
 * take as the value's own vertex sharpness there (the same corner-to-crease levels and
 * fractional weight when one edge is semi-sharp, as in the shapes that have it; 0: none). */
static int partner_semisharp(const ccn__fvar_level *fl, int32_t v, int method, float *child) {
    const ccn_mesh *m = fl->m;
    *child = 0.0f;
    if (!fl->partner || fl->partner[v] < 0 || !m->esharp) return 0;
    int32_t a = fl->partner[v], n = ccn__valence(m, a), semi = 0;
    for (int32_t k = 0; k < n; k++) {
        if (m->vboundary[a] && (k == 0 || k == n - 1)) continue;
        int32_t e = ccn__fan_edge(m, a, k);
        semi |= m->esharp[e] > 0.0f && m->esharp[e] < CCN_SHARPNESS_INFINITE;
        float cs = ccn__child_edge_sharpness(m, method, e, a);
        if (cs > 0.0f && cs < CCN_SHARPNESS_INFINITE && cs > *child) *child = cs;
    }
    return semi;
}

/* Regular value vertices away from irregular ones (the tensor B-spline 3 x 3 stencil, at
 * most FAST_MAX entries) are independent: their stencils are made in parallel into fixed
 * slots; the others one after the other (they share the ring scratch and the EV cache). */
#define FAST_MAX 9

typedef struct {
    const ccn__fvar_level *fl;
    int method;
    const uint8_t *skip; /* outputs with written-down weights: no limit stencil */
    uint8_t *irr;
    int32_t *cnt;     /* entries of a vertex's fast stencil; -1: made serially */
    int32_t *sv;      /* FAST_MAX slots per vertex */
    double *sw;
} fast_job;

static void irr_range(void *ctx, int32_t b, int32_t end) {
    const fast_job *j = ctx;
    const ccn_mesh *m = j->fl->m;
    float dep;
    for (int32_t v = b; v < end; v++) /* written-down outputs too: their neighbours' stencils */
        j->irr[v] = ccn__limit_kind(m, v, 0) != CCN_LIMIT_REGULAR || partner_semisharp(j->fl, v, j->method, &dep);
}

static void fast_range(void *ctx, int32_t b, int32_t end) {
    const fast_job *j = ctx;
    const ccn_mesh *m = j->fl->m;
    ccn__stencil *s = malloc(sizeof *s);
    for (int32_t v = b; v < end; v++) {
        j->cnt[v] = -1;
        if (j->skip[v]) { j->cnt[v] = 0; continue; }
        if (!s || ccn__near_irregular(m, v, j->irr)) continue;
        ccn__limit_stencil(m, v, 0, s);
        if (s->n > FAST_MAX) continue;
        for (int i = 0; i < s->n; i++) {
            j->sv[FAST_MAX * (size_t)v + i] = s->v[i];
            j->sw[FAST_MAX * (size_t)v + i] = s->wp[i];
        }
        j->cnt[v] = s->n;
    }
    free(s);
}

typedef struct { builder *c; const int32_t *cnt, *sv, *sstart, *bv; const double *sw, *bw; } gather_job;

static void gather_range(void *ctx, int32_t b, int32_t end) {
    const gather_job *j = ctx;
    builder *c = j->c;
    for (int32_t v = b; v < end; v++) {
        int32_t o = c->st_start[v], n = c->st_start[v + 1] - o;
        const int32_t *from_v = j->cnt[v] >= 0 ? j->sv + FAST_MAX * (size_t)v : j->bv + j->sstart[v];
        const double *from_w = j->cnt[v] >= 0 ? j->sw + FAST_MAX * (size_t)v : j->bw + j->sstart[v];
        memcpy(c->st_v + o, from_v, sizeof(int32_t) * (size_t)n);
        memcpy(c->st_w + o, from_w, sizeof(double) * (size_t)n);
    }
}

static ccn_status limit_stencils(const ccn_plan *p, builder *c, ccn_error *err) {
    const ccn__fvar_level *fl = &c->lev[c->L];
    const ccn_mesh *m = fl->m;
    size_t nv = (size_t)(m->nv ? m->nv : 1);
    ccn__stencil *s = malloc(sizeof *s);
    ccn__ring_limit *ring = malloc(sizeof *ring);
    ccn__ring_work *work = ccn__ring_work_create();
    wbuf b = {0, 0, NULL, NULL};
    fast_job fj = {fl, p->opts.crease_method, c->skip ? c->skip : c->direct, malloc(nv), malloc(sizeof(int32_t) * nv),
                   malloc(sizeof(int32_t) * FAST_MAX * nv), malloc(sizeof(double) * FAST_MAX * nv)};
    int32_t *sstart = malloc(sizeof(int32_t) * nv); /* a serial stencil's start in b */
    c->st_start = malloc(sizeof(int32_t) * ((size_t)m->nv + 1));
    c->near = malloc(sizeof(int32_t) * nv);
    ccn_status st = CCN_OK;
    if (!s || !ring || !work || !fj.irr || !fj.cnt || !fj.sv || !fj.sw || !sstart || !c->st_start || !c->near) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    ccn__ring_work_set_ev(work, p->opts.ev_polyhedron, p->ev_cache);
    ccn__parallel_for(p->threads, m->nv, irr_range, &fj);
    ccn__parallel_for(p->threads, m->nv, fast_range, &fj);
    float dep;
    for (int32_t v = 0; v < m->nv && !st; v++) {
        if (fj.cnt[v] >= 0) continue;
        int32_t off = 0;
        partner_semisharp(fl, v, p->opts.crease_method, &dep);
        if (!ccn__near_irregular(m, v, fj.irr)) {
            ccn__limit_stencil(m, v, 0, s);
        } else if (dep > 0.0f) { /* the partner's sharpness as its own */
            c->near[c->nnear++] = v;
            off = m->nv;
            st = ccn__ring_limit_eval_vs(m, v, p->opts.scheme, 0, p->opts.crease_method, dep, work, ring, err);
            s->n = 0;
            for (int32_t i = 0; !st && i < ring->npts; i++) {
                s->v[s->n] = ring->pts[i]; s->wp[s->n] = ring->wp[i]; s->wu[s->n] = s->wv[s->n] = 0.0;
                s->n++;
            }
        } else {
            c->near[c->nnear++] = v;
            off = m->nv;
            if (!(ccn__limit_kind(m, v, 0) == CCN_LIMIT_EV && reuse_ev_stencil(p, m, v, fl->vvert[v], s)))
                st = ccn__child_limit_stencil(m, v, 0, p->opts.scheme, p->opts.crease_method, work, s,
                                              ring, err);
        }
        sstart[v] = b.n;
        if (!st && push(&b, s, off))
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        fj.cnt[v] = -1 - (b.n - sstart[v]); /* -1 - entries */
    }
    if (st) goto done;
    /* the stencils in vertex order, sized exactly */
    c->st_start[0] = 0;
    for (int32_t v = 0; v < m->nv; v++) {
        int64_t n = fj.cnt[v] >= 0 ? fj.cnt[v] : -1 - fj.cnt[v];
        if (c->st_start[v] + n > INT32_MAX) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "face-varying stencils too large");
            goto done;
        }
        c->st_start[v + 1] = c->st_start[v] + (int32_t)n;
    }
    size_t total = (size_t)c->st_start[m->nv];
    c->st_v = malloc(sizeof(int32_t) * (total ? total : 1));
    c->st_w = malloc(sizeof(double) * (total ? total : 1));
    if (!c->st_v || !c->st_w) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    gather_job gj = {c, fj.cnt, fj.sv, sstart, b.v, fj.sw, b.w};
    ccn__parallel_for(p->threads, m->nv, gather_range, &gj);
done:
    if (c->near) {
        int32_t *nr = c->nnear ? realloc(c->near, sizeof(int32_t) * (size_t)c->nnear) : NULL;
        if (nr) c->near = nr;
    }
    free(b.v); free(b.w); free(sstart);
    free(fj.irr); free(fj.cnt); free(fj.sv); free(fj.sw);
    free(s); free(ring);
    ccn__ring_work_destroy(work);
    return st;
}

static int32_t origin(const ccn_plan *p, int32_t h, int32_t *ab) { return ccn__fvar_origin_at(p, h, 0, ab); }

typedef struct { const ccn_plan *p; builder *c; } origin_job;

static void origin1_range(void *ctx, int32_t b, int32_t end) {
    const origin_job *j = ctx;
    builder *c = j->c;
    const ccn_mesh *mL = c->lev[c->L].m;
    for (int32_t o = b; o < end; o++)
        c->d1[o] = c->direct[o] ? -1 : ccn__fvar_origin_at(j->p, mL->vfan[mL->vfan_start[o]], 1, &c->d1ab[o]);
}

/* The probed outputs that lie in a level-1 face whose block is regular at level 1 (the level-L
 * faces below a level-1 face are its quarters, as below level 0): their tables and grid points
 * (ccn__fvar_builder.d1). */
static ccn_status level1_blocks(const ccn_plan *p, builder *c, ccn_error *err) {
    const ccn_mesh *mL = c->lev[c->L].m, *m1 = c->lev[1].m;
    int32_t *tab = malloc(sizeof(int32_t) * (size_t)(m1->nf ? m1->nf : 1));
    c->d1 = malloc(sizeof(int32_t) * (size_t)(mL->nv ? mL->nv : 1));
    c->d1ab = malloc(sizeof(int32_t) * (size_t)(mL->nv ? mL->nv : 1));
    c->skip = malloc((size_t)(mL->nv ? mL->nv : 1));
    if (!tab || !c->d1 || !c->d1ab || !c->skip) {
        free(tab);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    }
    for (int32_t g = 0; g < m1->nf; g++) tab[g] = -1;
    origin_job oj = {p, c};
    ccn__parallel_for(p->threads, mL->nv, origin1_range, &oj); /* d1: the level-1 face */
    int32_t nlist = 0; /* only the level-1 faces of probed outputs are classified (tab: a list) */
    for (int32_t o = 0; o < mL->nv; o++) {
        int32_t g = c->d1[o];
        if (g >= 0 && tab[g] < 0) { tab[g] = 0; nlist++; }
    }
    int32_t *list = malloc(sizeof(int32_t) * (size_t)(nlist + 1));
    if (list) {
        nlist = 0;
        for (int32_t g = 0; g < m1->nf; g++)
            if (!tab[g]) { list[nlist++] = g; tab[g] = -1; }
    }
    if (!list || ccn__fvar_direct_build(&c->lev[1], p->threads, list, nlist, &c->dir1)) {
        free(tab); free(list);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    }
    free(list);
    c->nd1 = 0;
    for (int32_t o = 0; o < mL->nv; o++) {
        int32_t g = c->d1[o];
        if (g >= 0 && c->dir1.slot[g] >= 0) {
            if (tab[g] < 0) tab[g] = c->nd1++;
            c->d1[o] = tab[g];
        } else
            c->d1[o] = -1;
        c->skip[o] = (uint8_t)(c->direct[o] || c->d1[o] >= 0);
    }
    c->side1 = (1 << (c->L - 1)) + 1;
    c->d1verts = malloc(sizeof(int32_t) * 16 * (size_t)(c->nd1 ? c->nd1 : 1));
    c->d1N = malloc(sizeof(double) * 8 * (size_t)c->side1 * (size_t)(c->nd1 ? c->nd1 : 1));
    if (!c->d1verts || !c->d1N) {
        free(tab);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    }
    for (int32_t g = 0; g < m1->nf; g++) {
        int32_t t = tab[g];
        if (t < 0) continue;
        memcpy(c->d1verts + 16 * (size_t)t, c->dir1.verts + 16 * (size_t)c->dir1.slot[g], sizeof(int32_t) * 16);
        ccn__fvar_direct_table(&c->dir1, c->dir1.slot[g], c->side1, c->d1N + 8 * (size_t)c->side1 * t);
    }
    free(tab);
    return CCN_OK;
}

static void origin_range(void *ctx, int32_t b, int32_t end) {
    const origin_job *j = ctx;
    builder *c = j->c;
    const ccn_mesh *mL = c->numbered_only ? NULL : c->lev[c->L].m;
    for (int32_t o = b; o < end; o++) {
        c->fo[o] = origin(j->p, mL ? mL->vfan[mL->vfan_start[o]] : c->firstL[o], &c->ab[o]);
        c->direct[o] = c->dir.slot && c->dir.slot[c->fo[o]] >= 0;
    }
}

/* Every output written down: of levels 1..L only the numbering of the value vertices is needed
 * (refine/level.c's, through ccn__children_numbering from level 0's value vertices and
 * edges), each level-L value vertex's first fan corner as the value mesh would have it (its
 * outgoing boundary corner, else its first corner: topology/mesh.c) for origin(), and the
 * count of values kept sharp (vertex points keep their value's flag; under BOUNDARIES the
 * points of boundary edges are sharp too). */
static ccn_status numbered(const ccn_plan *p, builder *c, ccn_error *err) {
    const ccn_mesh *m0 = c->lev[0].m;
    int32_t nv = m0->nv, ne = m0->ne, *hv = NULL, *he = NULL, *ev = NULL, *cnt = NULL;
    int64_t nsharp = ccn__fvar_num_sharp(&c->lev[0]);
    int bnd = c->lev[0].linear == CCN_FVAR_LINEAR_BOUNDARIES;
    ccn_status st = CCN_OK;
    for (int32_t l = 0; l < c->L && !st; l++) {
        const ccn_mesh *vm = p->lev[l];
        const int32_t *hv0 = l ? hv : m0->hvert, *he0 = l ? he : m0->hedge, *ev0 = l ? ev : m0->everts;
        int64_t nh2 = 4 * (int64_t)vm->nh, ne2 = 2 * (int64_t)ne + vm->nh, nv2 = (int64_t)vm->nf + ne + nv;
        int32_t *hv2 = nh2 < INT32_MAX / 8 ? malloc(sizeof(int32_t) * (size_t)nh2) : NULL;
        int32_t *he2 = nh2 < INT32_MAX / 8 ? malloc(sizeof(int32_t) * (size_t)nh2) : NULL;
        int32_t *ev2 = ne2 < INT32_MAX / 8 ? malloc(sizeof(int32_t) * 2 * (size_t)ne2) : NULL;
        if (bnd) { /* boundary value edges: one corner each */
            cnt = calloc((size_t)(ne ? ne : 1), sizeof(int32_t));
            for (int32_t h = 0; cnt && h < vm->nh; h++) cnt[he0[h]]++;
            for (int32_t e = 0; cnt && e < ne; e++) nsharp += cnt[e] == 1;
        }
        if (!hv2 || !he2 || !ev2 || (bnd && !cnt))
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying levels)");
        else
            ccn__children_numbering(vm, ne, hv0, he0, ev0, hv2, he2, ev2, p->threads);
        free(cnt);
        cnt = NULL;
        if (l) { free(hv); free(he); free(ev); }
        hv = hv2; he = he2; ev = ev2; /* freed below on failure */
        nv = (int32_t)nv2; ne = (int32_t)ne2;
    }
    if (st) { free(hv); free(he); free(ev); return st; }
    int32_t nh = p->lev[c->L]->nh;
    if (!st && c->L == 0) { /* level 0 is the value mesh itself */
        hv = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
        he = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
        if (hv && he) { memcpy(hv, m0->hvert, sizeof(int32_t) * (size_t)nh); memcpy(he, m0->hedge, sizeof(int32_t) * (size_t)nh); }
        else st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying levels)");
    }
    if (!st) {
        c->firstL = malloc(sizeof(int32_t) * (size_t)(nv ? nv : 1));
        cnt = calloc((size_t)(ne ? ne : 1), sizeof(int32_t));
        if (!c->firstL || !cnt) st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying levels)");
    }
    if (!st) {
        for (int32_t h = 0; h < nh; h++) cnt[he[h]]++;
        for (int32_t v = 0; v < nv; v++) c->firstL[v] = -1;
        for (int32_t h = 0; h < nh; h++) {
            int32_t v = hv[h];
            if (c->firstL[v] < 0 || cnt[he[h]] == 1) c->firstL[v] = h;
        }
        for (int32_t v = 0; v < nv && !st; v++)
            if (c->firstL[v] < 0) st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "face-varying level %d: value %d has no face", (int)c->L, (int)v);
    }
    free(cnt); free(he); free(ev);
    c->hvL = hv;
    c->nvL = nv;
    if (c->bilinear) nsharp = nv; /* ALL: every point is kept sharp (refine/fvar.c) */
    c->nsharpL = nsharp > INT32_MAX ? INT32_MAX : (int32_t)nsharp;
    if (st) return st;
    c->fo = malloc(sizeof(int32_t) * (size_t)(nv ? nv : 1));
    c->ab = malloc(sizeof(int32_t) * (size_t)(nv ? nv : 1));
    c->direct = malloc((size_t)(nv ? nv : 1));
    c->outs = malloc(sizeof(int32_t));
    if (!c->fo || !c->ab || !c->direct || !c->outs)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    origin_job oj = {p, c};
    ccn__parallel_for(p->threads, nv, origin_range, &oj);
    return CCN_OK;
}

static ccn_status build(const ccn_plan *p, const ccn_fvar_channel *ch, builder *c, ccn_error *err) {
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    c->L = p->L;
    c->bilinear = ch->linear == CCN_FVAR_LINEAR_ALL;
    c->lev = calloc((size_t)c->L + 1, sizeof *c->lev);
    c->prep = calloc((size_t)(c->L ? c->L : 1), sizeof *c->prep);
    if (!c->lev || !c->prep)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    ccn_status st = ccn__fvar_build(p->lev[0], ch->indices, ch->linear, pinned, &c->lev[0], &c->value_of, err);
    if (st) return st;
    if (!c->bilinear && ccn__fvar_direct_build(&c->lev[0], p->threads, NULL, 0, &c->dir))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    if ((!c->bilinear && c->dir.count == c->lev[0].m->nf) || (c->bilinear && c->L >= 1)) {
        c->numbered_only = 1; /* nothing to probe */
        return numbered(p, c, err);
    }
    for (int32_t l = 0; l < c->L; l++) {
        if ((st = ccn__fvar_prepare(&c->prep[l], &c->lev[l], p->opts.scheme, p->opts.crease_method,
                                      p->opts.ev_polyhedron, p->ev_cache, err))) {
            memset(&c->prep[l], 0, sizeof c->prep[l]);
            return st;
        }
        c->prep[l].threads = p->threads;
        if ((st = ccn__fvar_child(&c->lev[l], &c->prep[l], p->lev[l], p->lev[l + 1], &c->lev[l + 1], err)))
            return st;
    }
    const ccn_mesh *mL = c->lev[c->L].m;
    c->fo = malloc(sizeof(int32_t) * (size_t)(mL->nv ? mL->nv : 1));
    c->ab = malloc(sizeof(int32_t) * (size_t)(mL->nv ? mL->nv : 1));
    c->direct = malloc((size_t)(mL->nv ? mL->nv : 1));
    if (!c->fo || !c->ab || !c->direct)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    origin_job oj = {p, c};
    ccn__parallel_for(p->threads, mL->nv, origin_range, &oj);
    for (int32_t o = 0; o < mL->nv; o++) c->nouts += !c->direct[o];
    if (!(c->outs = malloc(sizeof(int32_t) * (size_t)(c->nouts + 1))))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    c->nouts = 0;
    for (int32_t o = 0; o < mL->nv; o++)
        if (!c->direct[o]) c->outs[c->nouts++] = o;
    if (!c->bilinear && c->L >= 1 && (st = level1_blocks(p, c, err))) return st;
    if (!c->bilinear && (st = limit_stencils(p, c, err))) return st;
    if (c->nnear) {
        if ((st = ccn__fvar_prepare(&c->sub, &c->lev[c->L], p->opts.scheme, p->opts.crease_method,
                                      p->opts.ev_polyhedron, p->ev_cache, err)))
            return st;
        c->has_sub = 1;
        c->posS = malloc(sizeof(double) * 3 * ((size_t)mL->nf + mL->ne + mL->nv));
        if (!c->posS) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    return CCN_OK;
}

typedef struct {
    const builder *c;
    const ccn__fvar_csr *K; const int32_t *fo, *start, *compact;
    int32_t *idx;
    ccn__fvar_stencils *s;
    int by_levels;
} cand_job;

/* The candidates of each output: the value vertices of its cage face's neighbourhood; on a
 * regular face none, but the face and the grid point. */
static void cand_range(void *ctx, int32_t b, int32_t end) {
    const cand_job *j = ctx;
    for (int32_t o = b; o < end; o++) {
        int32_t n = j->start[o];
        if (j->c->direct[o]) {
            j->s->dface[o] = j->compact[j->fo[o]];
            continue;
        }
        if (j->by_levels) { j->s->dface[o] = CCN_FVAR_BY_LEVELS; continue; }
        if (j->s->dface) j->s->dface[o] = -1;
        for (int32_t k = j->K->start[j->fo[o]]; k < j->K->start[j->fo[o] + 1]; k++, n++) j->idx[n] = j->K->list[k];
    }
}

typedef struct { const builder *c; ccn__fvar_stencils *s; const int32_t *compact; int32_t *bad; } table_job;

static void table_range(void *ctx, int32_t b, int32_t e) {
    const table_job *j = ctx;
    const builder *c = j->c;
    ccn__fvar_stencils *s = j->s;
    int32_t side = s->side;
    for (int32_t f = b; f < e; f++) {
        int32_t k = j->compact[f];
        if (k < 0) continue;
        for (int i = 0; i < 16; i++) s->dvals[16 * (size_t)k + i] = c->value_of[c->dir.verts[16 * (size_t)c->dir.slot[f] + i]];
        double *N = s->dN + 8 * (size_t)side * k;
        ccn__fvar_direct_table(&c->dir, c->dir.slot[f], side, N);
        for (int32_t r = 0; r < 2 * side; r++)
            if (fabs(N[4 * r] + N[4 * r + 1] + N[4 * r + 2] + N[4 * r + 3] - 1.0) > 1e-9) j->bad[f] = 1;
    }
}

/* The regular faces' part of the stencils: per face its 16 caller values and basis tables,
 * compact[f] its index (nf, malloc'd). Each table row sums to 1 (affine invariance). */
static ccn_status direct_tables(const ccn_plan *p, builder *c, ccn__fvar_stencils *s, int32_t **compact,
                                ccn_error *err) {
    const ccn_mesh *m0 = c->lev[0].m;
    int32_t nd = c->dir.count, side = (1 << c->L) + 1, nout = s->nout;
    s->nd = nd;
    s->side = side;
    *compact = malloc(sizeof(int32_t) * (size_t)(m0->nf ? m0->nf : 1));
    int32_t *bad = calloc((size_t)(m0->nf ? m0->nf : 1), sizeof(int32_t));
    s->dface = malloc(sizeof(int32_t) * (size_t)(nout ? nout : 1));
    s->dab = c->ab; /* the outputs' grid points (origin_range) */
    c->ab = NULL;
    s->dvals = malloc(sizeof(int32_t) * 16 * (size_t)nd);
    s->dN = malloc(sizeof(double) * 8 * (size_t)side * (size_t)nd);
    if (!*compact || !bad || !s->dface || !s->dab || !s->dvals || !s->dN) {
        free(bad);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
    }
    for (int32_t f = 0, k = 0; f < m0->nf; f++) (*compact)[f] = c->dir.slot[f] < 0 ? -1 : k++;
    table_job j = {c, s, *compact, bad};
    ccn__parallel_for(p->threads, m0->nf, table_range, &j);
    ccn_status st = CCN_OK;
    for (int32_t f = 0; f < m0->nf && !st; f++)
        if (bad[f])
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, f, "face %d: its B-spline basis does not sum to 1", (int)f);
    free(bad);
    return st;
}

static ccn_status compose(const ccn_plan *p, builder *c, ccn__fvar_stencils *s, ccn_error *err) {
    const ccn_mesh *m0 = c->lev[0].m;
    int32_t nout = s->nout;
    ccn__fvar_csr K = {NULL, NULL};
    int32_t *col = malloc(sizeof(int32_t) * (size_t)m0->nv);
    const int32_t *fo = c->fo;
    int32_t ncol = -1, *kperm = NULL, *kcol = NULL;
    ccn_status st = CCN_OK;
    if (col && fo && !ccn__fvar_neighbourhoods(m0, c->dir.slot, &K)) ncol = c->nouts ? ccn__fvar_colour(m0, &K, col) : 0;
    /* a value vertex of high valence puts its whole neighbourhood into every face around it,
     * each value there needs a colour of its own and the passes grow with the valence (n^2 in
     * all): beyond CCN_FVAR_MAX_PASSES the probed outputs keep the levels instead and are
     * evaluated through them (ccn__fvar_levels_evaluate: one pass per evaluation) */
    int by_levels = c->nouts && ncol > 3 * CCN_FVAR_MAX_PASSES;
    s->start = malloc(sizeof(int32_t) * ((size_t)nout + 1));
    if (ncol < 0 || !s->start) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    /* the candidates: for each output, the value vertices of its cage face's neighbourhood */
    int64_t total = 0;
    for (int32_t o = 0; o < nout; o++) total += c->direct[o] || by_levels ? 0 : K.start[fo[o] + 1] - K.start[fo[o]];
    if (total > INT32_MAX) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "face-varying stencils too large"); goto done; }
    s->idx = malloc(sizeof(int32_t) * (size_t)(total ? total : 1));
    s->w = calloc((size_t)(total ? total : 1), sizeof(double));
    if (!s->idx || !s->w) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)"); goto done; }
    int32_t nk = K.start[m0->nf]; /* each K row's entries by colour (ccn__fvar_cands; probes only) */
    kperm = by_levels ? NULL : malloc(sizeof(int32_t) * (size_t)(nk ? nk : 1));
    kcol = by_levels ? NULL : malloc(sizeof(int32_t) * (size_t)(nk ? nk : 1));
    if (!by_levels && (!kperm || !kcol)) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)"); goto done; }
    for (int32_t f = 0; !by_levels && f < m0->nf; f++)
        for (int32_t a = K.start[f], i = a; i < K.start[f + 1]; i++) { /* insertion sort by colour */
            int32_t cv = col[K.list[i]], q = i;
            for (; q > a && kcol[q - 1] > cv; q--) { kcol[q] = kcol[q - 1]; kperm[q] = kperm[q - 1]; }
            kcol[q] = cv;
            kperm[q] = i - a;
        }
    s->start[0] = 0;
    for (int32_t o = 0; o < nout; o++)
        s->start[o + 1] = s->start[o] + (c->direct[o] || by_levels ? 0 : K.start[fo[o] + 1] - K.start[fo[o]]);
    int32_t *compact = NULL;
    if (c->dir.count > 0 && (st = direct_tables(p, c, s, &compact, err))) { free(compact); goto done; }
    if (by_levels && !s->dface && !(s->dface = malloc(sizeof(int32_t) * (size_t)(nout ? nout : 1)))) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    cand_job cj = {c, &K, fo, s->start, compact, s->idx, s, by_levels};
    ccn__parallel_for(p->threads, nout, cand_range, &cj);
    free(compact);
    if (c->dir.count > 0 && c->nouts) { /* probes of the other outputs: their points only, the rest zero */
        if (ccn__fvar_probe_lists(c)) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)"); goto done; }
        for (int32_t l = 1; l <= c->L; l++)
            memset(c->lev[l].m->pos, 0, sizeof(double) * 3 * (size_t)c->lev[l].m->nv);
    }
    if (by_levels) { /* the direct rows made final; the builder moves into s */
        st = ccn__fvar_finish_rows(p->threads, c->value_of, c->lev[0].m->nv, s, err);
        if (!st && !(s->levels = malloc(sizeof *s->levels)))
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
        if (!st) { *s->levels = *c; memset(c, 0, sizeof *c); }
        goto done;
    }
    ccn__fvar_cands cd = {s->start, K.start, kperm, kcol};
    if (ccn__fvar_probe_all(p, c, c->nouts ? (ncol + 2) / 3 : 0, col, &cd, s->w)) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying probes)");
        goto done;
    }
    free(kperm); free(kcol);
    kperm = kcol = NULL;
    st = ccn__fvar_finish_rows(p->threads, c->value_of, c->lev[0].m->nv, s, err);
done:
    free(K.start); free(K.list); free(col); free(kperm); free(kcol);
    return st;
}

ccn_status ccn__fvar_compose(const ccn_plan *p, const ccn_fvar_channel *ch, ccn__fvar_stencils *s,
                             ccn_error *err) {
    builder c;
    memset(&c, 0, sizeof c);
    memset(s, 0, sizeof *s);
    ccn_status st = build(p, ch, &c, err);
    if (!st && c.numbered_only) { /* level L's numbering is all that was made */
        s->nout = c.nvL;
        s->num_seams = c.lev[0].num_seams;
        s->num_sharp = c.nsharpL;
        s->face_values = c.hvL;
        c.hvL = NULL;
    } else if (!st) {
        const ccn_mesh *mL = c.lev[c.L].m;
        s->nout = mL->nv;
        s->num_seams = c.lev[0].num_seams;
        s->num_sharp = ccn__fvar_num_sharp(&c.lev[c.L]);
        s->face_values = malloc(sizeof(int32_t) * (size_t)mL->nh);
        if (!s->face_values) st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
        else memcpy(s->face_values, mL->hvert, sizeof(int32_t) * (size_t)mL->nh);
    }
    if (!st) st = c.numbered_only && c.bilinear ? ccn__fvar_bilinear_rows(p, &c, s, err) : compose(p, &c, s, err);
    ccn__fvar_builder_free(&c);
    if (st) ccn__fvar_stencils_free(s);
    return st;
}
