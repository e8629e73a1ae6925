/* The refined mesh's topology and intervals (refine/children.h): the children of every face,
 * edge and vertex of a level, their twins, and the intervals the child edges get. */
#include "refine/children.h"

#include "base/parallel.h"
#include "topology/knots.h"
#include "topology/mesh.h"

#include <string.h>

/* Child edge of e at its end v: 2e from everts[2e], 2e + 1 from the other end. */
static int32_t child_edge(const int32_t *everts, int32_t e, int32_t v) {
    return everts[2 * e] == v ? 2 * e : 2 * e + 1;
}

typedef struct {
    const ccn_mesh *m; int32_t ne; const int32_t *hvert, *hedge, *everts;
    int32_t *chvert, *chedge, *ceverts;
} numbering_job;

static void numbering_edge_range(void *ctx, int32_t b, int32_t end) {
    const numbering_job *j = ctx;
    int32_t nf = j->m->nf, ne = j->ne;
    for (int32_t e = b; e < end; e++) {
        int32_t ep = nf + e;
        j->ceverts[4 * e + 0] = nf + ne + j->everts[2 * e];
        j->ceverts[4 * e + 1] = ep;
        j->ceverts[4 * e + 2] = ep;
        j->ceverts[4 * e + 3] = nf + ne + j->everts[2 * e + 1];
    }
}

static void numbering_face_range(void *ctx, int32_t b, int32_t end) {
    const numbering_job *j = ctx;
    const ccn_mesh *m = j->m;
    const int32_t *hvert = j->hvert, *hedge = j->hedge, *everts = j->everts;
    int32_t nf = m->nf, ne = j->ne, *chvert = j->chvert, *chedge = j->chedge, *ceverts = j->ceverts;
    for (int32_t f = b; f < end; f++) {
        int32_t s = m->fstart[f], n = ccn__fsize(m, f);
        for (int32_t k = 0; k < n; k++) {
            int32_t h = s + k, hp = s + (k + n - 1) % n;
            int32_t v = hvert[h], q = 4 * h, inner = 2 * ne + h;
            chvert[q + 0] = nf + ne + v;
            chvert[q + 1] = nf + hedge[h];
            chvert[q + 2] = f;
            chvert[q + 3] = nf + hedge[hp];
            chedge[q + 0] = child_edge(everts, hedge[h], v);
            chedge[q + 1] = inner;
            chedge[q + 2] = 2 * ne + hp;
            chedge[q + 3] = child_edge(everts, hedge[hp], v);
            ceverts[2 * inner] = f;
            ceverts[2 * inner + 1] = nf + hedge[h];
        }
    }
}

void ccn__children_numbering(const ccn_mesh *m, int32_t ne, const int32_t *hvert,
                                const int32_t *hedge, const int32_t *everts, int32_t *chvert,
                                int32_t *chedge, int32_t *ceverts, int threads) {
    numbering_job j = {m, ne, hvert, hedge, everts, chvert, chedge, ceverts};
    ccn__parallel_for(threads, ne, numbering_edge_range, &j);
    ccn__parallel_for(threads, m->nf, numbering_face_range, &j);
}

void ccn__children_topology(const ccn_mesh *m, ccn_mesh *r, int threads) {
    int32_t nf = m->nf, ne = m->ne;
    ccn__children_numbering(m, ne, m->hvert, m->hedge, m->everts, r->hvert, r->hedge, r->everts, threads);
    for (int32_t f = 0; f < nf; f++) {
        int32_t s = m->fstart[f], n = ccn__fsize(m, f);
        for (int32_t j = 0; j < n; j++) {
            int32_t h = s + j, hp = s + (j + n - 1) % n, hn = s + (j + 1) % n, q = 4 * h;
            int32_t t = m->htwin[h], tp = m->htwin[hp];
            r->htwin[q + 0] = t >= 0 ? 4 * ccn__next(m, t) + 3 : -1;
            r->htwin[q + 1] = 4 * hn + 2;
            r->htwin[q + 2] = 4 * hp + 1;
            r->htwin[q + 3] = tp >= 0 ? 4 * tp : -1;
            for (int k = 0; k < 4; k++) r->hface[q + k] = h;
        }
    }
    for (int32_t q = 0; q <= r->nf; q++) r->fstart[q] = 4 * q;
}

/* The child edges' candidate intervals: the two halves of each edge, and for the edge from
 * face point to edge point of half-edge h (NURSS Fig. 10) half the mean of the two sides
 * adjacent to edge h (for a quad with consistent rings: half the parallel ring's interval). */
void ccn__children_candidates(const ccn_mesh *m, double *cand) {
    int32_t ne = m->ne;
    for (int32_t e = 0; e < ne; e++) cand[2 * e] = cand[2 * e + 1] = 0.5 * m->eknot[e];
    for (int32_t f = 0; f < m->nf; f++) {
        int32_t s = m->fstart[f], n = ccn__fsize(m, f);
        for (int32_t j = 0; j < n; j++) {
            int32_t h = s + j, hp = s + (j + n - 1) % n, hn = s + (j + 1) % n;
            cand[2 * ne + h] = 0.25 * (m->eknot[m->hedge[hp]] + m->eknot[m->hedge[hn]]);
        }
    }
}

static int all_quads(const ccn_mesh *m) {
    for (int32_t f = 0; f < m->nf; f++)
        if (ccn__fsize(m, f) != 4) return 0;
    return 1;
}

ccn_status ccn__children_intervals(const ccn_mesh *m, ccn_mesh *r, double *cand, ccn_error *err) {
    if (all_quads(m)) { /* rings stay consistent: every interval halves */
        memcpy(r->eknot, cand, sizeof(double) * (size_t)r->ne);
        double mx = 0.0;
        for (int32_t e = 0; e < r->ne; e++) mx = r->eknot[e] > mx ? r->eknot[e] : mx;
        mx = ccn__pow2_at_least(mx > 0.0 ? mx : 1.0); /* exact, as at level 0 (topology/knots.c) */
        for (int32_t e = 0; e < r->ne; e++) r->eknot[e] /= mx;
        r->knot_scale = m->knot_scale * mx;
        r->info.num_rings = 2 * m->info.num_rings; /* each ring splits in two */
        return CCN_OK;
    }
    for (int32_t e = 0; e < r->ne; e++) cand[e] *= m->knot_scale;
    int32_t conflicts = m->info.num_ring_conflicts;
    ccn_status st = ccn__resolve_rings(r, cand, NULL, err);
    r->info.num_ring_conflicts = conflicts;
    return st;
}

