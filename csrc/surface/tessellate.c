/* The output mesh: the level-L refinement of the cage (a (2^L+1)^2 grid per cage quad,
 * shared samples along edges), its per-face origin, the limit stencil of every output
 * vertex, and the vertices that lie in a guided-cap hole with their hole coordinates. */
#include "surface/tessellate.h"

#include "base/error.h"
#include "base/parallel.h"
#include "surface/edit_region.h"
#include "surface/limit.h"
#include "surface/stencil_reuse.h"
#include "topology/mesh.h"

#include <math.h>
#include <string.h>

/* The earlier plan's output mesh (a plan made with options.previous: the same level-L topology), moved over. */
static ccn_status output_topology_like(ccn_plan *p, ccn_plan *q) {
    p->nout_v = q->nout_v;
    p->nout_f = q->nout_f;
    p->nout_e = q->nout_e;
#define CCN_TAKE(f) do { p->f = q->f; q->f = NULL; } while (0)
    CCN_TAKE(vmapL); CCN_TAKE(out_fv); CCN_TAKE(out_origin); CCN_TAKE(out_ce); CCN_TAKE(out_ev);
    CCN_TAKE(out_vL); CCN_TAKE(out_eorigin);
#undef CCN_TAKE
    return CCN_OK;
}

static ccn_status output_topology(ccn_plan *p, ccn_error *err) {
    const ccn_mesh *mL = p->lev[p->L];
    if (p->hint && p->hint->L == p->L && p->hint->lev[p->L]->nv == mL->nv &&
        p->hint->lev[p->L]->nh == mL->nh && p->hint->vmapL)
        return output_topology_like(p, p->hint);
    p->vmapL = malloc(sizeof(int32_t) * (size_t)mL->nv);
    p->out_fv = malloc(sizeof(int32_t) * (size_t)mL->nh);
    p->out_origin = malloc(sizeof(int32_t) * (size_t)(mL->nf ? mL->nf : 1));
    if (!p->vmapL || !p->out_fv || !p->out_origin)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (output mesh)");
    /* output vertices are numbered in the order the output faces first use them (the faces
     * are in the refinement's quadtree order), so neighbours on the surface get near numbers:
     * the index arrays of a saved mesh compress like Subdivision Surface's; loose cage vertices
     * (no face) get none */
    int32_t no = 0;
    for (int32_t v = 0; v < mL->nv; v++) p->vmapL[v] = -1;
    for (int32_t h = 0; h < mL->nh; h++) {
        int32_t v = mL->hvert[h], r = mL->vrep ? mL->vrep[v] : v; /* a split cage: welded */
        if (p->vmapL[r] < 0) p->vmapL[r] = no++;
        p->out_fv[h] = p->vmapL[v] = p->vmapL[r];
    }
    p->nout_v = no;
    p->nout_f = mL->nf;
    /* the output edges, numbered like the vertices: in the order the faces first use them */
    int32_t *emap = malloc(sizeof(int32_t) * (size_t)(mL->ne ? mL->ne : 1)), ne = 0;
    p->out_ce = malloc(sizeof(int32_t) * (size_t)(mL->nh ? mL->nh : 1));
    p->out_ev = malloc(sizeof(int32_t) * 2 * (size_t)(mL->ne ? mL->ne : 1));
    if (!emap || !p->out_ce || !p->out_ev) {
        free(emap);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (output mesh)");
    }
    for (int32_t e = 0; e < mL->ne; e++) emap[e] = -1;
    for (int32_t h = 0; h < mL->nh; h++) {
        int32_t e = mL->erep ? mL->erep[mL->hedge[h]] : mL->hedge[h];
        if (emap[e] < 0) {
            emap[e] = ne;
            p->out_ev[2 * (size_t)ne] = p->vmapL[mL->everts[2 * (size_t)e]];
            p->out_ev[2 * (size_t)ne + 1] = p->vmapL[mL->everts[2 * (size_t)e + 1]];
            ne++;
        }
        p->out_ce[h] = emap[e];
    }
    p->nout_e = ne;
    free(emap);
    p->out_vL = malloc(sizeof(int32_t) * (size_t)(no ? no : 1));
    if (!p->out_vL) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (output mesh)");
    for (int32_t v = 0; v < mL->nv; v++) /* a welded vertex reads its representative */
        if (p->vmapL[v] >= 0 && (!mL->vrep || mL->vrep[v] == v)) p->out_vL[p->vmapL[v]] = v;
    for (int32_t f = 0; f < mL->nf; f++) {
        int32_t g = f;
        for (int32_t l = p->L; l > 0; l--) g = p->lev[l - 1]->hface[g];
        p->out_origin[f] = g;
    }
    /* the child quad q of level l+1 at corner j of a level-l face is that corner's half-edge
     * (refine/level.c): its corner 0 -> 1 lies on the parent half-edge q, its corner 3 -> 0 on the
     * parent's previous half-edge, its corners 1 -> 2 and 2 -> 3 inside the parent face */
    p->out_eorigin = malloc(sizeof(int32_t) * (size_t)(mL->nh ? mL->nh : 1));
    if (!p->out_eorigin) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (output mesh)");
    for (int32_t h = 0; h < mL->nh; h++) {
        int32_t g = h;
        for (int32_t l = p->L; l > 0 && g >= 0; l--) {
            const ccn_mesh *m = p->lev[l], *up = p->lev[l - 1];
            int32_t q = m->hface[g], k = g - m->fstart[q];
            g = k == 0 ? q : k == 3 ? ccn__prev(up, q) : -1;
        }
        p->out_eorigin[h] = g;
    }
    return CCN_OK;
}

typedef struct { int32_t n, cap; int32_t *v; double *wp, *wu, *wv; } csr_buf;

static int csr_reserve(csr_buf *b, int64_t nc) {
    if (nc > INT32_MAX) return -1;
    int32_t *v = realloc(b->v, sizeof(int32_t) * (size_t)nc);
    if (v) b->v = v;
    double *a = realloc(b->wp, sizeof(double) * (size_t)nc);
    if (a) b->wp = a;
    double *c = realloc(b->wu, sizeof(double) * (size_t)nc);
    if (c) b->wu = c;
    double *d = realloc(b->wv, sizeof(double) * (size_t)nc);
    if (d) b->wv = d;
    if (!v || !a || !c || !d) return -1;
    b->cap = (int32_t)nc;
    return 0;
}

static int csr_push(csr_buf *b, const ccn__stencil *s) {
    if (b->n + s->n > b->cap && csr_reserve(b, 2 * (int64_t)b->cap + s->n + 1024)) return -1;
    memcpy(b->v + b->n, s->v, sizeof(int32_t) * (size_t)s->n);
    memcpy(b->wp + b->n, s->wp, sizeof(double) * (size_t)s->n);
    memcpy(b->wu + b->n, s->wu, sizeof(double) * (size_t)s->n);
    memcpy(b->wv + b->n, s->wv, sizeof(double) * (size_t)s->n);
    b->n += s->n;
    return 0;
}

static void offset_stencil(ccn__stencil *s, int32_t off) {
    for (int i = 0; i < s->n; i++) s->v[i] += off;
}

/* Appends the sectors of ring (several tangent planes at output vertex o, level-L vertex v):
 * their stencils (offset into the level-(L+1) indices) and the sector of each face corner. */
static int push_sectors(ccn_plan *p, const ccn_mesh *mL, int32_t v, int32_t o,
                        const ccn__ring_limit *ring, csr_buf *sb, int32_t *cap_sv, int32_t *cap_sec) {
    if (p->nsv + 1 >= *cap_sv) {
        int32_t nc = 2 * *cap_sv + 64;
        int32_t *a = realloc(p->sv_out, sizeof(int32_t) * (size_t)nc);
        if (a) p->sv_out = a;
        int32_t *b = realloc(p->sv_sec, sizeof(int32_t) * ((size_t)nc + 1));
        if (b) p->sv_sec = b;
        if (!a || !b) return -1;
        *cap_sv = nc;
    }
    if (!p->corner_sec) {
        p->corner_sec = malloc(sizeof(int32_t) * 4 * (size_t)(p->nout_f ? p->nout_f : 1));
        if (!p->corner_sec) return -1;
        for (int32_t i = 0; i < 4 * p->nout_f; i++) p->corner_sec[i] = -1;
        p->sv_sec[0] = 0;
    }
    if (p->nsec + ring->nsec + 1 >= *cap_sec) {
        int32_t nc = 2 * *cap_sec + ring->nsec + 64;
        int32_t *a = realloc(p->sec_start, sizeof(int32_t) * ((size_t)nc + 1));
        if (!a) return -1;
        p->sec_start = a;
        if (p->nsec == 0) p->sec_start[0] = 0;
        *cap_sec = nc;
    }
    ccn__stencil *t = malloc(sizeof *t);
    if (!t) return -1;
    for (int32_t s = 0; s < ring->nsec; s++) {
        t->n = 0;
        for (int32_t i = 0; i < ring->npts; i++) {
            double wu = ring->wu[(size_t)s * ring->npts + i], wv = ring->wv[(size_t)s * ring->npts + i];
            if (wu == 0.0 && wv == 0.0) continue;
            t->v[t->n] = ring->pts[i] + mL->nv; t->wp[t->n] = 0; t->wu[t->n] = wu; t->wv[t->n] = wv;
            t->n++;
        }
        if (csr_push(sb, t)) { free(t); return -1; }
        int32_t sec = p->nsec++;
        p->sec_start[sec + 1] = sb->n;
        for (int32_t j = 0; j < ring->sec_nface[s]; j++) { /* the fan faces of the sector */
            int32_t k = (ring->sec_face0[s] + j) % ccn__valence(mL, v);
            int32_t h = mL->vfan[mL->vfan_start[v] + k], f = mL->hface[h];
            p->corner_sec[4 * f + (h - mL->fstart[f])] = sec;
        }
    }
    free(t);
    p->sv_out[p->nsv] = o;
    p->sv_sec[p->nsv + 1] = p->nsec;
    p->nsv++;
    return 0;
}

/* The regular output vertices away from irregular ones (the tensor B-spline 3 x 3 stencil of
 * surface/limit.c, at most FAST_MAX entries) are independent of each other: they are made in
 * the plan's threads, each into FAST_MAX slots of the table; the others (near irregular
 * vertices) one after the other, in output order, as they share the ring scratch, the EV choice
 * cache and the sector arrays. The table is then packed in place (entries only move down). */
#define FAST_MAX CCN_FAST_MAX

typedef struct {
    const ccn_plan *p;
    const ccn_mesh *mL;
    int pinned;
    uint8_t *irr;          /* per level-L vertex */
    uint8_t *fast;         /* per output vertex */
    const int32_t *slot;   /* per output vertex: its first entry in the unpacked table */
    int32_t *len;          /* per output vertex: its entries */
    const csr_buf *ib;     /* the irregular stencils, in output order */
    const int32_t *istart; /* per output vertex: its first entry in ib (irregular ones) */
    csr_buf *b;            /* the table */
    uint64_t *hash;        /* per regular output vertex: a hash of its weights (ref < 0) */
    int32_t *ref;          /* per regular output vertex: an earlier one with the same weights,
                              or -1 (its weights are in the table), -2 (the same, not hashed),
                              or -3 - k: the earlier plan's weight set k (ccn_plan_create with options.previous) */
    const uint8_t *moved;  /* a plan made with options.previous: per level-L vertex, 1 where an interval its
                              regular stencil reads may have changed; else NULL */
} stencil_job;

/* FNV-1a over the bits of the position weights and the first derivative weights (and their
 * count), finalised; equal weights are then told by comparing them all. */
static uint64_t weights_hash(int32_t n, const double *wp, const double *wu, const double *wv) {
    uint64_t h = 1469598103934665603ull ^ (uint64_t)n, x;
    for (int32_t k = 0; k < n; k++) {
        memcpy(&x, &wp[k], sizeof x);
        h = (h ^ x) * 1099511628211ull;
    }
    memcpy(&x, &wu[0], sizeof x);
    h = (h ^ x) * 1099511628211ull;
    memcpy(&x, &wv[0], sizeof x);
    h = (h ^ x) * 1099511628211ull;
    h ^= h >> 33; /* the low bits, which index the table, from all of them (splitmix64) */
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    return h;
}

static void irr_range(void *ctx, int32_t begin, int32_t end) {
    stencil_job *j = ctx;
    for (int32_t v = begin; v < end; v++)
        j->irr[v] = ccn__limit_kind(j->mL, v, j->pinned) != CCN_LIMIT_REGULAR;
}

/* j->irr widened to ccn__near_irregular's test: the corners of every face around an irregular
 * vertex (few of them) join it, in place; near: scratch, nv bytes. */
static void widen_irregular(stencil_job *j, uint8_t *near) {
    const ccn_mesh *m = j->mL;
    memcpy(near, j->irr, (size_t)m->nv);
    for (int32_t v = 0; v < m->nv; v++)
        if (j->irr[v]) ccn__mesh_mark_face_ring(m, &v, 1, NULL, near);
    memcpy(j->irr, near, (size_t)m->nv);
}

static void fast_range(void *ctx, int32_t begin, int32_t end) { /* after widen_irregular */
    stencil_job *j = ctx;
    for (int32_t o = begin; o < end; o++) j->fast[o] = !j->irr[j->p->out_vL[o]];
}

/* The last distinct weights a range made (most regular outputs repeat one of them). */
#define RECENT 8
typedef struct { int32_t o, n; uint64_t h; double w[3 * FAST_MAX]; } recent_weights;

static int same_weights(const recent_weights *r, const ccn__stencil *s) {
    size_t z = sizeof(double) * (size_t)s->n;
    return r->n == s->n && !memcmp(r->w, s->wp, z) && !memcmp(r->w + FAST_MAX, s->wu, z) &&
           !memcmp(r->w + 2 * FAST_MAX, s->wv, z);
}

static void fill_range(void *ctx, int32_t begin, int32_t end) {
    stencil_job *j = ctx;
    ccn__stencil *s = malloc(sizeof *s);
    recent_weights *rc = malloc(sizeof *rc * RECENT);
    int nrc = 0, last = 0, put = 0;
    int32_t tried = 0, made = 0; /* a range whose weights are mostly new stops looking */
    csr_buf *b = j->b;
    for (int32_t o = begin; o < end; o++) {
        int32_t at = j->slot[o];
        if (!j->fast[o]) { /* made serially: copied into place */
            int32_t from = j->istart[o], n = j->len[o];
            memcpy(b->v + at, j->ib->v + from, sizeof(int32_t) * (size_t)n);
            memcpy(b->wp + at, j->ib->wp + from, sizeof(double) * (size_t)n);
            memcpy(b->wu + at, j->ib->wu + from, sizeof(double) * (size_t)n);
            memcpy(b->wv + at, j->ib->wv + from, sizeof(double) * (size_t)n);
            continue;
        }
        j->len[o] = -1; /* failed: no scratch, or more than FAST_MAX entries */
        if (!s || !rc) continue;
        const ccn_plan *q = j->p->hint;
        int keep = j->moved && !j->moved[j->p->out_vL[o]];
        if (keep && q->st_w[o] < 0) { /* the earlier plan's shared set: named only */
            int32_t n = ccn__earlier_regular(q, o);
            if (n >= 0) {
                memcpy(b->v + at, q->st_v + q->st_start[o], sizeof(int32_t) * (size_t)n);
                j->len[o] = n;
                j->ref[o] = -3 - (-1 - q->st_w[o]);
                continue;
            }
        }
        if (!keep || !ccn__earlier_row(q, o, s)) ccn__limit_stencil(j->mL, j->p->out_vL[o], j->pinned, s);
        if (s->n > FAST_MAX) continue;
        memcpy(b->v + at, s->v, sizeof(int32_t) * (size_t)s->n);
        j->len[o] = s->n;
        j->ref[o] = -1;
        if (tried >= 512 && 2 * made > tried) { /* non-uniform intervals: each its own */
            memcpy(b->wp + at, s->wp, sizeof(double) * (size_t)s->n);
            memcpy(b->wu + at, s->wu, sizeof(double) * (size_t)s->n);
            memcpy(b->wv + at, s->wv, sizeof(double) * (size_t)s->n);
            j->ref[o] = -2; /* no hash */
            continue;
        }
        tried++;
        if (nrc && same_weights(&rc[last], s)) { j->ref[o] = rc[last].o; continue; }
        uint64_t h = weights_hash(s->n, s->wp, s->wu, s->wv);
        for (int i = 0; i < nrc && j->ref[o] < 0; i++)
            if (rc[i].h == h && same_weights(&rc[i], s)) { j->ref[o] = rc[i].o; last = i; }
        if (j->ref[o] >= 0) continue;
        made++;
        memcpy(b->wp + at, s->wp, sizeof(double) * (size_t)s->n); /* new here: into the table */
        memcpy(b->wu + at, s->wu, sizeof(double) * (size_t)s->n);
        memcpy(b->wv + at, s->wv, sizeof(double) * (size_t)s->n);
        j->hash[o] = h;
        recent_weights *r = &rc[put];
        r->o = o; r->n = s->n; r->h = h;
        memcpy(r->w, s->wp, sizeof(double) * (size_t)s->n);
        memcpy(r->w + FAST_MAX, s->wu, sizeof(double) * (size_t)s->n);
        memcpy(r->w + 2 * FAST_MAX, s->wv, sizeof(double) * (size_t)s->n);
        last = put;
        put = (put + 1) % RECENT;
        if (nrc < RECENT) nrc++;
    }
    free(s);
    free(rc);
}

/* The regular outputs' weight sets (ccn_plan.st_w, ws): each distinct (n, wp, wu, wv) once.
 * An output whose range had made its weights already takes that one's set; the others are
 * found through an open-addressing table on the hashes fill_range made. */
static ccn_status weight_sets(ccn_plan *p, const stencil_job *j, int32_t nout, ccn_error *err) {
    csr_buf *b = j->b;
    const ccn_plan *q = p->hint;
    int64_t nfast = 0, heads = 0;
    for (int32_t o = 0; o < nout; o++) {
        nfast += j->fast[o];
        heads += j->fast[o] && j->ref[o] < 0 && j->ref[o] > -3;
    }
    if (2 * heads > nfast) { /* mostly distinct (non-uniform intervals): every row its own */
        for (int32_t o = 0; o < nout; o++) {
            if (!j->fast[o] || (j->ref[o] < 0 && j->ref[o] > -3)) continue;
            int32_t at = j->slot[o], n = j->len[o];
            const double *w = j->ref[o] <= -3 ? q->ws + 27 * (size_t)(-3 - j->ref[o]) : NULL;
            const double *fp = w ? w : b->wp + j->slot[j->ref[o]], *fu = w ? w + 9 : b->wu + j->slot[j->ref[o]];
            const double *fv = w ? w + 18 : b->wv + j->slot[j->ref[o]];
            memcpy(b->wp + at, fp, sizeof(double) * (size_t)n);
            memcpy(b->wu + at, fu, sizeof(double) * (size_t)n);
            memcpy(b->wv + at, fv, sizeof(double) * (size_t)n);
        }
        p->nws = 0;
        return CCN_OK;
    }
    size_t size = 16;
    while (size < 2 * (size_t)nfast) size *= 2;
    int32_t *table = malloc(sizeof(int32_t) * size), cap = 16;
    uint64_t *sh = malloc(sizeof(uint64_t) * (size_t)cap);
    int32_t *sn = malloc(sizeof(int32_t) * (size_t)cap);
    int32_t *qmap = q && q->nws ? malloc(sizeof(int32_t) * (size_t)q->nws) : NULL; /* q's set -> ours */
    p->ws = malloc(sizeof(double) * 27 * (size_t)cap);
    p->nws = 0;
    ccn_status st = CCN_OK;
    if (!table || !sh || !sn || !p->ws || (q && q->nws && !qmap)) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
        goto done;
    }
    for (size_t i = 0; i < size; i++) table[i] = -1;
    for (int32_t k = 0; qmap && k < q->nws; k++) qmap[k] = -1;
    for (int32_t o = 0; o < nout; o++) {
        if (!j->fast[o]) continue;
        if (j->ref[o] >= 0) { p->st_w[o] = p->st_w[j->ref[o]]; continue; } /* an earlier one's */
        int32_t at = j->slot[o], n = j->len[o], set = -1, qk = j->ref[o] <= -3 ? -3 - j->ref[o] : -1;
        if (qk >= 0 && qmap[qk] >= 0) { p->st_w[o] = -1 - qmap[qk]; continue; }
        const double *wp = b->wp + at, *wu = b->wu + at, *wv = b->wv + at;
        if (qk >= 0) { wp = q->ws + 27 * (size_t)qk; wu = wp + 9; wv = wp + 18; }
        uint64_t h = j->ref[o] == -2 || qk >= 0 ? weights_hash(n, wp, wu, wv) : j->hash[o];
        size_t i = (size_t)h & (size - 1);
        for (; table[i] >= 0; i = (i + 1) & (size - 1)) {
            int32_t t = table[i];
            const double *w = p->ws + 27 * (size_t)t;
            if (sh[t] == h && sn[t] == n && !memcmp(w, wp, sizeof(double) * (size_t)n) &&
                !memcmp(w + 9, wu, sizeof(double) * (size_t)n) && !memcmp(w + 18, wv, sizeof(double) * (size_t)n)) {
                set = t;
                break;
            }
        }
        if (set < 0) {
            if (p->nws == cap) {
                cap *= 2;
                uint64_t *a = realloc(sh, sizeof(uint64_t) * (size_t)cap);
                if (a) sh = a;
                int32_t *c = realloc(sn, sizeof(int32_t) * (size_t)cap);
                if (c) sn = c;
                double *d = realloc(p->ws, sizeof(double) * 27 * (size_t)cap);
                if (d) p->ws = d;
                if (!a || !c || !d) {
                    st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
                    goto done;
                }
            }
            set = p->nws++;
            double *w = p->ws + 27 * (size_t)set;
            memset(w, 0, sizeof(double) * 27);
            memcpy(w, wp, sizeof(double) * (size_t)n);
            memcpy(w + 9, wu, sizeof(double) * (size_t)n);
            memcpy(w + 18, wv, sizeof(double) * (size_t)n);
            sh[set] = h;
            sn[set] = n;
            table[i] = set;
        }
        if (qk >= 0) qmap[qk] = set;
        p->st_w[o] = -1 - set;
    }
done:
    free(table); free(sh); free(sn); free(qmap);
    return st;
}

static ccn_status output_stencils(ccn_plan *p, ccn_error *err) {
    const ccn_mesh *mL = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    int32_t nout = p->nout_v;
    size_t nslot = (size_t)(nout ? nout : 1);
    ccn__stencil *s = malloc(sizeof *s);
    ccn__ring_limit *ring = malloc(sizeof *ring);
    ccn__ring_work *work = ccn__ring_work_create();
    if (work) ccn__ring_work_set_ev(work, p->opts.ev_polyhedron, p->ev_cache);
    csr_buf b = {0, 0, NULL, NULL, NULL, NULL}, sb = {0, 0, NULL, NULL, NULL, NULL};
    csr_buf ib = {0, 0, NULL, NULL, NULL, NULL};
    int32_t cap_sv = 0, cap_sec = 0;
    int32_t *slot = malloc(sizeof(int32_t) * (nslot + 1)), *len = malloc(sizeof(int32_t) * nslot);
    int32_t *istart = malloc(sizeof(int32_t) * nslot);
    stencil_job j = {p, mL, pinned, malloc((size_t)(mL->nv ? mL->nv : 1)), malloc(nslot), slot,
                     len, &ib, istart, &b, malloc(sizeof(uint64_t) * nslot), malloc(sizeof(int32_t) * nslot),
                     NULL};
    uint8_t *moved = NULL; /* a plan made with options.previous: the earlier plan's rows where nothing moved */
    if (p->hint && p->hint->L == p->L && p->hint->nout_v == nout && p->hint->st_start)
        j.moved = moved = ccn__moved_vertices(mL, p->hint->lev[p->L]);
    p->st_start = malloc(sizeof(int32_t) * ((size_t)nout + 1));
    p->st_w = malloc(sizeof(int32_t) * nslot);
    p->near = malloc(sizeof(int32_t) * (size_t)(mL->nv ? mL->nv : 1));
    ccn_status st = CCN_OK;
    if (!s || !ring || !work || !p->st_start || !p->near || !slot || !len || !istart || !j.irr ||
        !j.fast || !j.hash || !j.ref || !p->st_w) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
        goto done;
    }
    p->nnear = 0;
    if (moved) { /* the same topology and creases: the same regular outputs (not in near) */
        memset(j.fast, 1, nslot);
        for (int32_t i = 0; i < p->hint->nnear; i++) j.fast[p->vmapL[p->hint->near[i]]] = 0;
    } else {
        ccn__parallel_for(p->threads, mL->nv, irr_range, &j);
        uint8_t *near = malloc((size_t)(mL->nv ? mL->nv : 1));
        if (!near) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
            goto done;
        }
        widen_irregular(&j, near);
        free(near);
        ccn__parallel_for(p->threads, nout, fast_range, &j);
    }
    /* the irregular ones, in output order */
    for (int32_t o = 0; o < nout; o++) {
        if (j.fast[o]) continue;
        int32_t v = p->out_vL[o];
        p->near[p->nnear++] = v;
        st = ccn__child_limit_stencil(mL, v, pinned, p->opts.scheme, p->opts.crease_method, work,
                                      s, ring, err);
        if (st) goto done;
        offset_stencil(s, mL->nv);
        if (ring->nsec > 1 && push_sectors(p, mL, v, o, ring, &sb, &cap_sv, &cap_sec)) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
            goto done;
        }
        istart[o] = ib.n;
        len[o] = s->n;
        if (csr_push(&ib, s)) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
            goto done;
        }
    }
    if (moved && p->region && (p->region->redo = malloc(nslot))) /* the rows made again */
        for (int32_t o = 0; o < nout; o++) p->region->redo[o] = !j.fast[o] || moved[p->out_vL[o]];
    if (moved) { /* a plan made with options.previous: the earlier table patched in place, where it fits */
        ccn__reuse_rows in = {j.fast, moved, len, istart, ib.v, ib.wp, ib.wu, ib.wv, pinned};
        ccn__reuse_table t = {NULL, NULL, NULL, NULL, 0};
        int r = ccn__patch_stencils(p, &in, &t);
        if (r > 0) { b.v = t.v; b.wp = t.wp; b.wu = t.wu; b.wv = t.wv; b.n = t.n; }
        if (r < 0) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
            goto done;
        }
        if (r) goto sectors;
    }
    /* FAST_MAX slots per regular one, the irregular ones' own size; made, then packed */
    slot[0] = 0;
    for (int32_t o = 0; o < nout; o++) {
        int64_t next = (int64_t)slot[o] + (j.fast[o] ? FAST_MAX : len[o]);
        if (next > INT32_MAX) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "stencil table too large");
            goto done;
        }
        slot[o + 1] = (int32_t)next;
    }
    if (csr_reserve(&b, (int64_t)slot[nout] + 1)) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
        goto done;
    }
    ccn__parallel_for(p->threads, nout, fill_range, &j);
    for (int32_t o = 0; o < nout; o++)
        if (len[o] < 0) {
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_VERTEX, o,
                           "output vertex %d: out of memory, or a regular stencil above %d entries",
                           (int)o, FAST_MAX);
            goto done;
        }
    if ((st = weight_sets(p, &j, nout, err))) goto done;
    /* packed: every row's indices; the weights of the irregular rows only (the regular ones'
     * are in their sets). Entries move down only: slot[o] >= st_start[o] >= own */
    p->st_start[0] = 0;
    int32_t own = 0;
    for (int32_t o = 0; o < nout; o++) {
        int32_t to = p->st_start[o], from = slot[o], n = len[o];
        if (to != from) memmove(b.v + to, b.v + from, sizeof(int32_t) * (size_t)n);
        if (!j.fast[o] || !p->nws) {
            if (own != from) {
                memmove(b.wp + own, b.wp + from, sizeof(double) * (size_t)n);
                memmove(b.wu + own, b.wu + from, sizeof(double) * (size_t)n);
                memmove(b.wv + own, b.wv + from, sizeof(double) * (size_t)n);
            }
            p->st_w[o] = own;
            own += n;
        }
        p->st_start[o + 1] = to + n;
    }
    b.n = p->st_start[nout];
    { /* the tables to their size */
        int32_t *v = realloc(b.v, sizeof(int32_t) * (size_t)(b.n ? b.n : 1));
        double *a = realloc(b.wp, sizeof(double) * (size_t)(own ? own : 1));
        double *c = realloc(b.wu, sizeof(double) * (size_t)(own ? own : 1));
        double *d = realloc(b.wv, sizeof(double) * (size_t)(own ? own : 1));
        if (v) b.v = v;
        if (a) b.wp = a;
        if (c) b.wu = c;
        if (d) b.wv = d;
    }
    p->st_nown = own;
sectors:
    if (p->nsec) {
        p->sec_nrm = malloc(sizeof(double) * 3 * (size_t)p->nsec);
        if (!p->sec_nrm) st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (stencils)");
    }
done:
    p->st_v = b.v; p->st_wp = b.wp; p->st_wu = b.wu; p->st_wv = b.wv;
    p->sec_v = sb.v; p->sec_wu = sb.wu; p->sec_wv = sb.wv;
    free(sb.wp);
    free(ib.v); free(ib.wp); free(ib.wu); free(ib.wv);
    free(slot); free(len); free(istart); free(j.irr); free(j.fast); free(j.hash); free(j.ref);
    free(moved);
    free(s);
    free(ring);
    ccn__ring_work_destroy(work);
    return st;
}

ccn_status ccn__tess_output(ccn_plan *p, ccn_error *err) {
    ccn_status st = output_topology(p, err);
    if (!st) st = output_stencils(p, err);
    return st;
}

/* ---- cap holes ---------------------------------------------------------------------- */

typedef struct {
    ccn_plan *p;
    int mode;              /* 0: cap hole vertex, 1: vertex on a ring face */
    int32_t cap, sector;   /* mode 0 */
    int32_t rf;            /* mode 1 */
    uint8_t *seen;         /* per level-L vertex */
    int32_t n[2], capacity[2];
} hole_walk;

static int grow_i32(int32_t **a, int32_t nc) {
    int32_t *b = realloc(*a, sizeof(int32_t) * (size_t)nc);
    if (b) *a = b;
    return b ? 0 : -1;
}
static int grow_f64(double **a, int32_t nc) {
    double *b = realloc(*a, sizeof(double) * (size_t)nc);
    if (b) *a = b;
    return b ? 0 : -1;
}

static int record(hole_walk *w, int32_t vL, const double uv[2]) {
    ccn_plan *p = w->p;
    int md = w->mode;
    if (w->seen[vL] || p->vmapL[vL] < 0) return 0;
    w->seen[vL] = 1;
    if (w->n[md] >= w->capacity[md]) {
        int32_t nc = 2 * w->capacity[md] + 64;
        int bad = md == 0 ? grow_i32(&p->hv_out, nc) | grow_i32(&p->hv_cap, nc) |
                                grow_i32(&p->hv_sector, nc) | grow_f64(&p->hv_uv, 2 * nc)
                          : grow_i32(&p->bv_out, nc) | grow_i32(&p->bv_rf, nc) |
                                grow_f64(&p->bv_uv, 2 * nc);
        if (bad) return -1;
        w->capacity[md] = nc;
    }
    int32_t i = w->n[md]++;
    if (md == 0) {
        p->hv_out[i] = p->vmapL[vL];
        p->hv_cap[i] = w->cap;
        p->hv_sector[i] = w->sector;
        p->hv_uv[2 * i] = uv[0];
        p->hv_uv[2 * i + 1] = uv[1];
    } else {
        p->bv_out[i] = p->vmapL[vL];
        p->bv_rf[i] = w->rf;
        p->bv_uv[2 * i] = uv[0];
        p->bv_uv[2 * i + 1] = uv[1];
    }
    return 0;
}

/* Level-L vertex whose vertex-point chain is level-K vertex v, or -1. */
static int32_t ancestor_at_L(const ccn_plan *p, int32_t v) {
    for (int32_t l = p->K; l > p->L; l--) {
        v -= p->lev[l - 1]->nf + p->lev[l - 1]->ne;
        if (v < 0) return -1;
    }
    return v;
}

/* Face f of level l with corner coordinates c[k] (in f's half-edge order). */
static int walk_face(hole_walk *w, int32_t l, int32_t f, double c[][2]) {
    const ccn_mesh *m = w->p->lev[l];
    int32_t s0 = m->fstart[f], n = ccn__fsize(m, f);
    if (l == w->p->L || w->p->L < w->p->K) { /* record what exists at the output level */
        for (int32_t j = 0; j < n; j++) {
            int32_t v = l == w->p->L ? m->hvert[s0 + j] : ancestor_at_L(w->p, m->hvert[s0 + j]);
            if (v >= 0 && record(w, v, c[j])) return -1;
        }
        return 0;
    }
    double ctr[2] = {0, 0};
    for (int32_t j = 0; j < n; j++) { ctr[0] += c[j][0] / n; ctr[1] += c[j][1] / n; }
    for (int32_t j = 0; j < n; j++) {
        int32_t jn = (j + 1) % n, jp = (j + n - 1) % n;
        double cc[4][2] = {{c[j][0], c[j][1]},
                           {(c[j][0] + c[jn][0]) / 2, (c[j][1] + c[jn][1]) / 2},
                           {ctr[0], ctr[1]},
                           {(c[j][0] + c[jp][0]) / 2, (c[j][1] + c[jp][1]) / 2}};
        if (walk_face(w, l + 1, s0 + j, cc)) return -1;
    }
    return 0;
}

static const double UNIT[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

static int walk_cap(hole_walk *w, int32_t c) {
    const ccn_mesh *mK = w->p->lev[w->p->K];
    int32_t ev = w->p->caps[c].cnet[0], n = w->p->caps[c].n;
    w->mode = 0;
    w->cap = c;
    for (int32_t k = 0; k < n; k++) {
        int32_t h = mK->vfan[mK->vfan_start[ev] + k], f = mK->hface[h];
        int32_t j0 = h - mK->fstart[f];
        double cc[4][2];
        for (int j = 0; j < 4; j++) {
            cc[(j0 + j) % 4][0] = UNIT[j][0];
            cc[(j0 + j) % 4][1] = UNIT[j][1];
        }
        w->sector = k;
        if (walk_face(w, w->p->K, f, cc)) return -1;
    }
    return 0;
}

/* Faces touching the cap's 1-ring vertices but not the EV (the ring around the hole). */
static int walk_ring_faces(hole_walk *w, int32_t c, uint8_t *face_done) {
    ccn_plan *p = w->p;
    const ccn_mesh *mK = p->lev[p->K];
    const ccn__cap *cp = &p->caps[c];
    if (cp->exact_surround && !(cp->wu > 0)) return 0; /* its surround is the limit itself (bi5.h [R13]) */
    w->mode = 1;
    for (int32_t j = 0; j < 2 * cp->n; j++) {
        int32_t v = cp->ring[j];
        for (int32_t k = mK->vfan_start[v]; k < mK->vfan_start[v + 1]; k++) {
            int32_t f = mK->hface[mK->vfan[k]], touches = 0;
            for (int32_t h = mK->fstart[f]; h < mK->fstart[f + 1]; h++) touches |= mK->hvert[h] == cp->cnet[0];
            if (touches || face_done[f]) continue;
            face_done[f] = 1;
            if (grow_i32(&p->rf_face, p->nrf + 1) || grow_i32(&p->rf_cap, p->nrf + 1)) return -1;
            uint8_t *on = realloc(p->rf_on, (size_t)p->nrf + 1);
            if (!on) return -1;
            p->rf_on = on;
            p->rf_face[p->nrf] = f;
            p->rf_cap[p->nrf] = c;
            p->rf_on[p->nrf] = 0; /* its corners on the 1-ring (the hole's border) */
            for (int32_t h = mK->fstart[f]; h < mK->fstart[f + 1] && h - mK->fstart[f] < 8; h++)
                for (int32_t r = 0; r < 2 * cp->n; r++)
                    if (cp->ring[r] == mK->hvert[h]) p->rf_on[p->nrf] |= (uint8_t)(1u << (h - mK->fstart[f]));
            w->rf = p->nrf++;
            double cc[4][2];
            memcpy(cc, UNIT, sizeof cc);
            if (walk_face(w, p->K, f, cc)) return -1;
        }
    }
    return 0;
}

ccn_status ccn__tess_holes(ccn_plan *p, ccn_error *err) {
    const ccn_mesh *mL = p->lev[p->L], *mK = p->lev[p->K];
    hole_walk w;
    memset(&w, 0, sizeof w);
    w.p = p;
    w.seen = calloc((size_t)mL->nv, 1);
    uint8_t *face_done = calloc((size_t)mK->nf, 1);
    int bad = !w.seen || !face_done;
    for (int32_t c = 0; !bad && c < p->ncap; c++) bad = walk_cap(&w, c) != 0;
    for (int32_t c = 0; !bad && c < p->ncap; c++) bad = walk_ring_faces(&w, c, face_done) != 0;
    if (!bad) p->rf_bez = malloc(sizeof(double) * 48 * (size_t)(p->nrf ? p->nrf : 1));
    bad = bad || !p->rf_bez;
    p->nhv = w.n[0];
    p->nbv = w.n[1];
    free(w.seen);
    free(face_done);
    if (bad) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (holes)");
    return CCN_OK;
}
