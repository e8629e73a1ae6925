/* Probing a face-varying channel's levels (surface/fvar_probe.h): the colouring of the cage's
 * value vertices, the points each level must compute, and the passes that read the composed
 * outputs' weights off the levels (surface/fvar_compose.c says why probing gives them). */
#include "surface/fvar_probe.h"

#include "base/parallel.h"

#include <string.h>

typedef ccn__fvar_builder builder;
typedef ccn__fvar_probe_list probe_list;

/* One probe pass's limit values, read off as they are made: output o's limit of the level-L
 * values (3 components: colours 3b .. 3b+2 set to 1) is the weight of each of o's candidates
 * (row start[o] .. start[o+1]) with one of those colours. */
typedef struct {
    const builder *c; const double *PL, *PS, *P1; const ccn__fvar_cands *cd; const int32_t *outs; double *cw; int32_t b;
} limit_job;

/* Output o's limit of the level-L values PL (its level-(L+1) points PS, level 1's P1). */
static inline void limit_point(const builder *c, int32_t o, const double *PL, const double *PS,
                               const double *P1, int32_t nvL, double x[3]) {
    if (c->bilinear) memcpy(x, PL + 3 * (size_t)o, sizeof(double) * 3);
    else if (c->d1 && c->d1[o] >= 0) { /* the level-1 block's patch (ccn__fvar_builder.d1) */
        int32_t t = c->d1[o], a1 = c->d1ab[o] & 0xffff, b1 = c->d1ab[o] >> 16;
        const double *Nu = c->d1N + 8 * (size_t)c->side1 * t + 4 * (size_t)a1;
        const double *Nv = c->d1N + 8 * (size_t)c->side1 * t + 4 * ((size_t)c->side1 + b1);
        const int32_t *P = c->d1verts + 16 * (size_t)t;
        double x0 = 0, x1 = 0, x2 = 0;
        for (int jj = 0; jj < 4; jj++) {
            double r0 = 0, r1 = 0, r2 = 0;
            for (int ii = 0; ii < 4; ii++) {
                const double *q = P1 + 3 * (size_t)P[ii + 4 * jj];
                r0 += Nu[ii] * q[0]; r1 += Nu[ii] * q[1]; r2 += Nu[ii] * q[2];
            }
            x0 += Nv[jj] * r0; x1 += Nv[jj] * r1; x2 += Nv[jj] * r2;
        }
        x[0] = x0; x[1] = x1; x[2] = x2;
    } else {
        double x0 = 0, x1 = 0, x2 = 0;
        for (int32_t k = c->st_start[o]; k < c->st_start[o + 1]; k++) {
            int32_t i = c->st_v[k];
            const double *q = i < nvL ? PL + 3 * (size_t)i : PS + 3 * ((size_t)i - nvL);
            double w = c->st_w[k];
            x0 += w * q[0]; x1 += w * q[1]; x2 += w * q[2];
        }
        x[0] = x0; x[1] = x1; x[2] = x2;
    }
}

static void limit_range(void *ctx, int32_t b, int32_t end) {
    const limit_job *j = ctx;
    const builder *c = j->c;
    const ccn_mesh *mL = c->lev[c->L].m;
    const int32_t *start = j->cd->start, *kst = j->cd->kstart, *kp = j->cd->perm, *kc = j->cd->col, c0 = 3 * j->b;
    int32_t nvL = mL->nv;
    for (int32_t i = b; i < end; i++) {
        int32_t o = j->outs ? j->outs[i] : i;
        double x[3];
        limit_point(c, o, j->PL, j->PS, j->P1, nvL, x);
        int32_t a = kst[c->fo[o]], n = kst[c->fo[o] + 1] - a, lo = 0, hi = n;
        while (lo < hi) { /* the first of o's candidates with colour >= c0 */
            int32_t mid = (lo + hi) / 2;
            if (kc[a + mid] < c0) lo = mid + 1;
            else hi = mid;
        }
        for (int32_t q = lo; q < n && kc[a + q] < c0 + 3; q++) j->cw[start[o] + kp[a + q]] = x[kc[a + q] - c0];
    }
}


/* K(f): the value vertices at the corners of the faces that share a value vertex with face f
 * (level 0), each once; empty for a regular face (skip[f] >= 0: its weights are written down). */
int ccn__fvar_neighbourhoods(const ccn_mesh *m, const int32_t *skip, ccn__fvar_csr *K) {
    int32_t cap = 64, n = 0;
    K->start = malloc(sizeof(int32_t) * ((size_t)m->nf + 1));
    K->list = malloc(sizeof(int32_t) * (size_t)cap);
    int32_t *seen = malloc(sizeof(int32_t) * (size_t)m->nv);
    if (!K->start || !K->list || !seen) { free(seen); return -1; }
    for (int32_t v = 0; v < m->nv; v++) seen[v] = -1;
    K->start[0] = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1] && !(skip && skip[f] >= 0); h++) {
            int32_t u = m->hvert[h];
            for (int32_t q = m->vfan_start[u]; q < m->vfan_start[u + 1]; q++) {
                int32_t g = m->hface[m->vfan[q]];
                for (int32_t k = m->fstart[g]; k < m->fstart[g + 1]; k++) {
                    int32_t w = m->hvert[k];
                    if (seen[w] == f) continue;
                    seen[w] = f;
                    if (n == cap) {
                        int32_t *l = cap < INT32_MAX / 2 ? realloc(K->list, sizeof(int32_t) * 2 * (size_t)cap) : NULL;
                        if (!l) { free(seen); return -1; }
                        K->list = l;
                        cap *= 2;
                    }
                    K->list[n++] = w;
                }
            }
        }
        K->start[f + 1] = n;
    }
    free(seen);
    return 0;
}

/* Colours of the value vertices: no two in one K(f) alike (greedy, smallest free colour).
 * Returns the number of colours, -1 on failure. */
int32_t ccn__fvar_colour(const ccn_mesh *m, const ccn__fvar_csr *K, int32_t *col) {
    int32_t nv = m->nv, ncol = 0;
    ccn__fvar_csr I = {calloc((size_t)nv + 1, sizeof(int32_t)), malloc(sizeof(int32_t) * (size_t)(K->start[m->nf] + 1))};
    int32_t *mark = malloc(sizeof(int32_t) * ((size_t)nv + 1));
    if (!I.start || !I.list || !mark) { free(I.start); free(I.list); free(mark); return -1; }
    for (int32_t i = 0; i < K->start[m->nf]; i++) I.start[K->list[i] + 1]++;
    for (int32_t v = 0; v < nv; v++) I.start[v + 1] += I.start[v];
    for (int32_t f = 0; f < m->nf; f++) /* I(v): the faces f with v in K(f) */
        for (int32_t i = K->start[f]; i < K->start[f + 1]; i++) I.list[I.start[K->list[i]]++] = f;
    for (int32_t v = nv; v > 0; v--) I.start[v] = I.start[v - 1];
    I.start[0] = 0;
    for (int32_t c = 0; c <= nv; c++) mark[c] = -1;
    for (int32_t v = 0; v < nv; v++) col[v] = -1;
    /* breadth-first order over the value mesh's edges: fronts colour like a tiling */
    int32_t *order = malloc(sizeof(int32_t) * (size_t)(nv ? nv : 1)), head = 0, tail = 0;
    uint8_t *queued = calloc((size_t)(nv ? nv : 1), 1);
    if (!order || !queued) { free(order); free(queued); free(I.start); free(I.list); free(mark); return -1; }
    for (int32_t s0 = 0; s0 < nv; s0++) {
        if (queued[s0]) continue;
        queued[s0] = 1;
        order[tail++] = s0;
        while (head < tail) {
            int32_t u = order[head++];
            for (int32_t q = m->vfan_start[u]; q < m->vfan_start[u + 1]; q++) {
                int32_t h = m->vfan[q], a = m->hvert[ccn__next(m, h)], z = m->hvert[ccn__prev(m, h)];
                if (!queued[a]) { queued[a] = 1; order[tail++] = a; }
                if (!queued[z]) { queued[z] = 1; order[tail++] = z; }
            }
        }
    }
    for (int32_t t = 0; t < nv; t++) {
        int32_t v = order[t];
        for (int32_t i = I.start[v]; i < I.start[v + 1]; i++) {
            int32_t f = I.list[i];
            for (int32_t k = K->start[f]; k < K->start[f + 1]; k++)
                if (col[K->list[k]] >= 0) mark[col[K->list[k]]] = v;
        }
        int32_t c = 0;
        while (mark[c] == v) c++;
        col[v] = c;
        if (c + 1 > ncol) ncol = c + 1;
    }
    free(order); free(queued);
    free(I.start); free(I.list); free(mark);
    return ncol;
}

/* The points the probes need, level by level, when some outputs have written-down weights:
 * found backwards from what the composed outputs' limit stencils read. Level L: the points
 * of their stencils, and around each vertex the sub level refines (near[]) the corners of its
 * faces. Level l computes the next level's points that are needed, closed under what the
 * rules read of the same pass (refine/level.c: an edge point reads the face points of its
 * faces, a vertex point those of its faces and the curve points H of its edges); the points
 * of level l then needed are the corners of every listed face and the ends of every listed
 * edge, and an EV's whole ring where one of its red points (the eigen rows overwriting the
 * face points of its faces, the points of its spokes and its own) is listed or read. Every
 * point a needed point's rule reads is thus right, and the others stay 0 unread. */
static void mark_faces_around(const ccn_mesh *m, int32_t v, uint8_t *need) {
    for (int32_t q = m->vfan_start[v]; q < m->vfan_start[v + 1]; q++) {
        int32_t g = m->hface[m->vfan[q]];
        for (int32_t h = m->fstart[g]; h < m->fstart[g + 1]; h++) need[m->hvert[h]] = 1;
    }
    need[v] = 1;
}

/* The level-1 block points of the outputs read off level 1 (ccn__fvar_builder.d1). */
static void mark_level1_blocks(const builder *c, uint8_t *need1) {
    for (int32_t i = 0; c->d1 && i < c->nouts; i++) {
        int32_t t = c->d1[c->outs[i]];
        for (int k = 0; t >= 0 && k < 16; k++) need1[c->d1verts[16 * (size_t)t + k]] = 1;
    }
}

static int list_of(const uint8_t *mark, int32_t n, int32_t **out, int32_t *count) {
    int32_t k = 0;
    for (int32_t i = 0; i < n; i++) k += mark[i] != 0;
    *out = malloc(sizeof(int32_t) * (size_t)(k + 1));
    if (!*out) return -1;
    *count = 0;
    for (int32_t i = 0; i < n; i++)
        if (mark[i]) (*out)[(*count)++] = i;
    return 0;
}

int ccn__fvar_probe_lists(builder *c) {
    int32_t L = c->L;
    const ccn_mesh *mL = c->lev[L].m;
    uint8_t *need = calloc((size_t)mL->nv + 1, 1);
    c->pl = calloc((size_t)(L ? L : 1), sizeof *c->pl);
    if (!need || !c->pl) { free(need); return -1; }
    for (int32_t i = 0; i < c->nouts; i++) {
        int32_t o = c->outs[i];
        for (int32_t k = c->st_start[o]; k < c->st_start[o + 1]; k++)
            if (c->st_v[k] < mL->nv) need[c->st_v[k]] = 1;
    }
    if (c->has_sub) { /* the sub level's points around near[]: their faces' corners, EV rings */
        uint8_t *isev = calloc((size_t)mL->nv + 1, 1);
        if (!isev) { free(need); return -1; }
        for (int32_t i = 0; i < c->sub.nev; i++) isev[c->sub.ev_list[i]] = 1;
        for (int32_t i = 0; i < c->nnear; i++) {
            int32_t v = c->near[i];
            for (int32_t q = mL->vfan_start[v]; q < mL->vfan_start[v + 1]; q++) {
                int32_t g = mL->hface[mL->vfan[q]];
                for (int32_t h = mL->fstart[g]; h < mL->fstart[g + 1]; h++) {
                    int32_t u = mL->hvert[h];
                    need[u] = 1;
                    if (isev[u]) mark_faces_around(mL, u, need);
                }
            }
        }
        free(isev);
    }
    if (L == 1) mark_level1_blocks(c, need);
    int ok = 1;
    for (int32_t l = L - 1; ok && l >= 0; l--) {
        const ccn_mesh *m = c->lev[l].m;
        if (l == 0 && L > 1) mark_level1_blocks(c, need); /* need: level 1's points here */
        const ccn__level *pr = &c->prep[l];
        probe_list *q = &c->pl[l];
        uint8_t *fm = calloc((size_t)m->nf + 1, 1), *em = calloc((size_t)m->ne + 1, 1);
        uint8_t *vm = calloc((size_t)m->nv + 1, 1), *prev = calloc((size_t)m->nv + 1, 1);
        if (!fm || !em || !vm || !prev) { free(fm); free(em); free(vm); free(prev); ok = 0; break; }
        for (int32_t x = 0; x < m->nf; x++) fm[x] = need[x];
        for (int32_t x = 0; x < m->ne; x++) em[x] = need[m->nf + x];
        for (int32_t x = 0; x < m->nv; x++) vm[x] = need[m->nf + m->ne + x];
        for (int32_t v = 0; v < m->nv; v++) { /* a vertex point: its faces' points, its H */
            if (!vm[v]) continue;
            for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) fm[m->hface[m->vfan[k]]] = 1;
            for (int32_t k = 0, n = ccn__valence(m, v); k < n; k++) em[ccn__fan_edge(m, v, k)] = 1;
        }
        for (int32_t e = 0; e < m->ne; e++) { /* an edge point: its faces' points */
            if (!em[e]) continue;
            int32_t h = pr->erep[e], t = m->htwin[h];
            fm[m->hface[h]] = 1;
            if (t >= 0) fm[m->hface[t]] = 1;
        }
        for (int32_t f = 0; f < m->nf; f++)
            if (fm[f])
                for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) prev[m->hvert[h]] = 1;
        for (int32_t e = 0; e < m->ne; e++)
            if (em[e]) prev[m->everts[2 * e]] = prev[m->everts[2 * e + 1]] = 1;
        for (int32_t v = 0; v < m->nv; v++) prev[v] |= vm[v];
        for (int32_t i = 0; i < pr->nev; i++) { /* red points listed or read: the EV's ring */
            int32_t w = pr->ev_list[i], hit = vm[w];
            for (int32_t k = m->vfan_start[w]; k < m->vfan_start[w + 1] && !hit; k++)
                hit = fm[m->hface[m->vfan[k]]] || em[m->hedge[m->vfan[k]]];
            for (int32_t k = 0, n = ccn__valence(m, w); k < n && !hit; k++) hit = em[ccn__fan_edge(m, w, k)];
            if (hit) mark_faces_around(m, w, prev);
        }
        ok = !list_of(fm, m->nf, &q->f, &q->nf) && !list_of(em, m->ne, &q->e, &q->ne) &&
             !list_of(vm, m->nv, &q->v, &q->nv);
        free(fm); free(em); free(vm);
        free(need);
        need = prev;
    }
    free(need);
    return ok ? 0 : -1;
}

/* What one probe pass writes: the levels' points (pos[l], the value mesh of level l's) and the
 * rules' scratch (levels prep[0..L-1], sub). The builder's own, or a worker's copies sharing
 * their topology, rules and tables (struct copies with their own points and scratch H; every
 * table is made by the first pass, before the workers start). */
typedef struct {
    double **pos, *posS;
    ccn__level *prep, *sub;
    ccn_mesh *mcopy;          /* a worker's: the meshes its levels read their points from */
    ccn__level subcopy;
} probe_set;

/* Levels 1..L from level 0's points (w->pos[0]), only the points the probed outputs read
 * (c->pl), and the level-(L+1) points around near[]. */
static void run_levels(const builder *c, const probe_set *w) {
    for (int32_t l = 0; l < c->L; l++) {
        const probe_list *q = c->pl ? &c->pl[l] : NULL;
        if (q) ccn__level_points_lists(&w->prep[l], q->f, q->nf, q->e, q->ne, q->v, q->nv, w->pos[l + 1]);
        else ccn__level_points(&w->prep[l], w->pos[l + 1]);
    }
    if (c->has_sub) {
        ccn__level_tabulate_subset(w->sub, c->near, c->nnear); /* the first pass, before the copies */
        ccn__level_points_subset(w->sub, c->near, c->nnear, w->posS);
    }
}

/* One probe pass: colours 3b .. 3b+2 set to 1 (components 0..2), every level and limit
 * stencil run; each candidate weight of those colours is read off (limit_range). */
static void probe(const builder *c, const probe_set *w, int threads, const int32_t *col, int32_t b,
                  const ccn__fvar_cands *cd, double *cw) {
    double *P0 = w->pos[0];
    for (int32_t v = 0; v < c->lev[0].m->nv; v++)
        for (int k = 0; k < 3; k++) P0[3 * (size_t)v + k] = col[v] == 3 * b + k ? 1.0 : 0.0;
    run_levels(c, w);
    limit_job j = {c, w->pos[c->L], w->posS, c->L >= 1 ? w->pos[1] : NULL, cd, c->outs, cw, b};
    ccn__parallel_for(threads, c->nouts, limit_range, &j);
}

static void probe_set_free(probe_set *w, int32_t L) {
    for (int32_t l = 0; w->mcopy && l <= L; l++) free(w->mcopy[l].pos);
    for (int32_t l = 0; w->prep && l < L; l++) free(w->prep[l].H);
    free(w->subcopy.H); free(w->posS); free(w->mcopy); free(w->prep); free(w->pos);
    memset(w, 0, sizeof *w);
}

/* A worker's copy of the builder's levels, its points zero (the probes leave the points they
 * do not need at zero). Returns -1 out of memory. */
static int probe_set_copy(const builder *c, probe_set *w) {
    memset(w, 0, sizeof *w);
    int32_t L = c->L;
    w->mcopy = calloc((size_t)L + 1, sizeof *w->mcopy);
    w->pos = calloc((size_t)L + 1, sizeof *w->pos);
    w->prep = calloc((size_t)(L ? L : 1), sizeof *w->prep);
    if (!w->mcopy || !w->pos || !w->prep) return -1;
    for (int32_t l = 0; l <= L; l++) {
        w->mcopy[l] = *c->lev[l].m;
        w->mcopy[l].pos = w->pos[l] = calloc(3 * (size_t)(c->lev[l].m->nv ? c->lev[l].m->nv : 1), sizeof(double));
        if (!w->pos[l]) return -1;
    }
    for (int32_t l = 0; l < L; l++) {
        w->prep[l] = c->prep[l];
        w->prep[l].m = &w->mcopy[l];
        w->prep[l].threads = 1;
        w->prep[l].H = calloc(3 * (size_t)(w->mcopy[l].ne ? w->mcopy[l].ne : 1), sizeof(double));
        if (!w->prep[l].H) return -1;
    }
    if (c->has_sub) {
        const ccn_mesh *mL = &w->mcopy[L];
        w->subcopy = c->sub;
        w->subcopy.m = mL;
        w->subcopy.threads = 1;
        w->subcopy.H = calloc(3 * (size_t)(mL->ne ? mL->ne : 1), sizeof(double));
        w->posS = calloc(3 * ((size_t)mL->nf + mL->ne + mL->nv), sizeof(double));
        w->sub = &w->subcopy;
        if (!w->subcopy.H || !w->posS) return -1;
    }
    return 0;
}

typedef struct {
    const builder *c; const probe_set *sets; int32_t nsets, npass;
    const int32_t *col; const ccn__fvar_cands *cd; double *cw;
} pool_job;

/* Worker t (one task each) runs passes t + 1, t + 1 + nsets, ... on its own set. */
static void pool_range(void *ctx, int32_t b, int32_t end) {
    const pool_job *j = ctx;
    for (int32_t t = b; t < end; t++)
        for (int32_t pass = 1 + t; pass < j->npass; pass += j->nsets)
            probe(j->c, &j->sets[t], 1, j->col, pass, j->cd, j->cw);
}

/* Every pass: the first on the builder's own set (threaded inside; it makes the levels'
 * tables), the others spread over the threads, each on its own set: the passes write disjoint
 * weights and compute the same numbers wherever they run. Without memory for the copies they
 * run one after the other on the builder's set. */
int ccn__fvar_probe_all(const ccn_plan *p, builder *c, int32_t npass, const int32_t *col,
                     const ccn__fvar_cands *cd, double *cw) {
    if (npass <= 0) return 0;
    double **ownpos = malloc(sizeof(double *) * ((size_t)c->L + 1));
    if (!ownpos) return -1;
    for (int32_t l = 0; l <= c->L; l++) ownpos[l] = c->lev[l].m->pos;
    probe_set own = {ownpos, c->posS, c->prep, &c->sub, NULL, {0}};
    int32_t nsets = p->threads - 1 < npass - 1 ? p->threads - 1 : npass - 1, made = 0;
    probe_set *sets = nsets > 0 ? calloc((size_t)nsets + 1, sizeof *sets) : NULL;
    probe(c, &own, p->threads, col, 0, cd, cw);
    if (sets) { /* the builder's set is worker 0's too */
        sets[0] = own;
        for (made = 1; made <= nsets && !probe_set_copy(c, &sets[made]); made++) {}
        if (made <= nsets) probe_set_free(&sets[made], c->L);
    }
    if (made >= 2) {
        pool_job j = {c, sets, made, npass, col, cd, cw};
        for (int32_t l = 0; l < c->L; l++) c->prep[l].threads = 1; /* one thread per worker */
        ccn__parallel_tasks(made, made, pool_range, &j);
        for (int32_t l = 0; l < c->L; l++) c->prep[l].threads = p->threads;
    } else
        for (int32_t pass = 1; pass < npass; pass++) probe(c, &own, p->threads, col, pass, cd, cw);
    for (int32_t t = 1; t < made; t++) probe_set_free(&sets[t], c->L);
    free(sets);
    free(ownpos);
    return 0;
}

typedef struct { const builder *c; const double *PL, *PS, *P1; double *out; int32_t width, c0; double up; } levels_job;

static void levels_range(void *ctx, int32_t b, int32_t end) {
    const levels_job *j = ctx;
    const builder *c = j->c;
    int32_t nvL = c->lev[c->L].m->nv;
    for (int32_t i = b; i < end; i++) {
        int32_t o = c->outs[i];
        double x[3];
        limit_point(c, o, j->PL, j->PS, j->P1, nvL, x);
        for (int k = 0; k < 3 && j->c0 + k < j->width; k++) j->out[(size_t)j->width * o + j->c0 + k] = j->up * x[k];
    }
}

int ccn__fvar_levels_evaluate(const ccn_plan *p, builder *c, const double *vals, int32_t width,
                              double down, double up, double *out) {
    double **ownpos = malloc(sizeof(double *) * ((size_t)c->L + 1));
    if (!ownpos) return -1;
    for (int32_t l = 0; l <= c->L; l++) ownpos[l] = c->lev[l].m->pos;
    probe_set own = {ownpos, c->posS, c->prep, &c->sub, NULL, {0}};
    for (int32_t c0 = 0; c0 < width; c0 += 3) { /* the probe pass, on the caller's values */
        for (int32_t v = 0; v < c->lev[0].m->nv; v++)
            for (int k = 0; k < 3; k++)
                ownpos[0][3 * (size_t)v + k] = c0 + k < width ? down * vals[(size_t)width * c->value_of[v] + c0 + k] : 0.0;
        run_levels(c, &own);
        levels_job j = {c, ownpos[c->L], c->posS, c->L >= 1 ? ownpos[1] : NULL, out, width, c0, up};
        ccn__parallel_for(p->threads, c->nouts, levels_range, &j);
    }
    free(ownpos);
    return 0;
}
