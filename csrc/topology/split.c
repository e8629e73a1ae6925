/* Non-manifold cages made manifold (topology/split.h), as OpenSubdiv reads them
 * (far/topologyRefinerFactory.cpp): an edge used by more than two faces, or by two faces in the
 * same direction (inconsistent winding), is non-manifold and infinitely sharp; its ends, and a
 * vertex whose faces form more than one fan, are non-manifold vertices and infinitely sharp
 * (corners) -- except a vertex inside a non-manifold crease (two non-manifold edges, no
 * boundary edge, more faces than edges), which keeps the crease rule along them.
 *
 * The half-edge mesh the rules work on must be manifold, so the cage is split: the corners of
 * each vertex are grouped into fans joined across manifold edges, and each fan beyond the first
 * gets a copy of the vertex. Every use of a non-manifold edge then lies on a boundary (or on an
 * edge the copies share, marked sharp), and every copy of a sharpened vertex is a corner or a
 * crease vertex whose rule reads the same points: the copies' points coincide at every level,
 * and the outputs weld them back (the mesh's vertex representatives, topology/mesh.c). */
#include "topology/split.h"

#include "base/error.h"
#include "base/union_find.h"

#include <stdlib.h>
#include <string.h>

typedef struct { int32_t a, b, h; } ekey;

static int ekey_cmp(const void *x, const void *y) {
    const ekey *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return (p->h > q->h) - (p->h < q->h);
}

void ccn__split_free(ccn__split *s) {
    free(s->positions); free(s->face_verts); free(s->edge_verts); free(s->edge_knots);
    free(s->edge_creases); free(s->vertex_creases); free(s->vorig);
    memset(s, 0, sizeof *s);
}

ccn_status ccn__split_cage(const ccn_cage *c, int32_t nh, ccn__split *s, ccn_error *err) {
    memset(s, 0, sizeof *s);
    int32_t nv = c->num_verts, nf = c->num_faces;
    int32_t *fstart = malloc(sizeof(int32_t) * ((size_t)nf + 1));
    int32_t *next = malloc(sizeof(int32_t) * (size_t)nh), *twin = malloc(sizeof(int32_t) * (size_t)nh);
    int32_t *par = malloc(sizeof(int32_t) * (size_t)nh), *copy = malloc(sizeof(int32_t) * (size_t)nh);
    uint8_t *nme = calloc((size_t)nh, 1), *nmv = calloc((size_t)(nv ? nv : 1), 1);
    ekey *keys = malloc(sizeof(ekey) * (size_t)nh);
    int32_t *cnt = calloc(4 * (size_t)(nv ? nv : 1), sizeof(int32_t)); /* edges, faces, nm, boundary */
    ccn_status st = CCN_OK;
    if (!fstart || !next || !twin || !par || !copy || !nme || !nmv || !keys || !cnt) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (non-manifold split)");
        goto done;
    }
    fstart[0] = 0;
    for (int32_t f = 0; f < nf; f++) {
        fstart[f + 1] = fstart[f] + c->face_sizes[f];
        for (int32_t h = fstart[f]; h < fstart[f + 1]; h++) next[h] = h + 1 < fstart[f + 1] ? h + 1 : fstart[f];
    }
    for (int32_t h = 0; h < nh; h++) {
        int32_t a = c->face_verts[h], b = c->face_verts[next[h]];
        keys[h] = (ekey){a < b ? a : b, a < b ? b : a, h};
        twin[h] = -1;
        par[h] = h;
        copy[h] = -1;
    }
    qsort(keys, (size_t)nh, sizeof *keys, ekey_cmp);
    int any = 0;
    for (int32_t i = 0; i < nh;) {
        int32_t j = i + 1;
        while (j < nh && keys[j].a == keys[i].a && keys[j].b == keys[i].b) j++;
        int32_t h0 = keys[i].h;
        int manifold = j - i == 2 && c->face_verts[h0] != c->face_verts[keys[i + 1].h];
        if (manifold) twin[h0] = keys[i + 1].h, twin[keys[i + 1].h] = h0;
        int nm = j - i > 2 || (j - i == 2 && !manifold);
        for (int32_t k = i; k < j; k++) nme[keys[k].h] = (uint8_t)nm;
        int32_t ends[2] = {keys[i].a, keys[i].b};
        for (int e = 0; e < 2; e++) {
            cnt[4 * ends[e]]++;                       /* distinct edges at the vertex */
            cnt[4 * ends[e] + 2] += nm;               /* non-manifold ones */
            cnt[4 * ends[e] + 3] += j - i == 1;       /* boundary ones */
            if (nm) nmv[ends[e]] = 1;
        }
        any |= nm;
        i = j;
    }
    /* corners of a vertex joined across manifold edges: h (a -> b) and its twin t (b -> a)
     * join corner h with next(t) at a, and next(h) with t at b */
    for (int32_t h = 0; h < nh; h++) {
        cnt[4 * c->face_verts[h] + 1]++;
        if (twin[h] >= 0) {
            ccn__uf_union(par, h, next[twin[h]]);
            ccn__uf_union(par, next[h], twin[h]);
        }
    }
    /* fans: the first keeps the vertex's index, the others get copies after the cage's */
    uint8_t *used = calloc((size_t)(nv ? nv : 1), 1);
    if (!used) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto done; }
    int32_t nv2 = nv;
    for (int32_t h = 0; h < nh; h++) {
        int32_t r = ccn__uf_find(par, h), v = c->face_verts[h];
        if (copy[r] >= 0) continue;
        if (!used[v]) copy[r] = v, used[v] = 1;
        else copy[r] = nv2++, nmv[v] = 1, any = 1;
    }
    free(used);
    if (!any) goto done; /* manifold: the cage is used as it is */
    s->split = 1;
    s->num_verts = nv2;
    s->positions = malloc(sizeof(double) * 3 * (size_t)nv2);
    s->vorig = malloc(sizeof(int32_t) * (size_t)nv2);
    s->face_verts = malloc(sizeof(int32_t) * (size_t)nh);
    s->vertex_creases = malloc(sizeof(double) * (size_t)nv2);
    int32_t ne2 = c->num_edges + nh; /* the cage's list, then every corner's edge when non-manifold */
    s->edge_verts = malloc(sizeof(int32_t) * 2 * (size_t)ne2);
    s->edge_knots = malloc(sizeof(double) * (size_t)ne2);
    s->edge_creases = malloc(sizeof(double) * (size_t)ne2);
    if (!s->positions || !s->vorig || !s->face_verts || !s->vertex_creases || !s->edge_verts ||
        !s->edge_knots || !s->edge_creases) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (non-manifold split)");
        goto done;
    }
    for (int32_t v = 0; v < nv; v++) s->vorig[v] = v;
    for (int32_t h = 0; h < nh; h++) {
        int32_t v2 = copy[ccn__uf_find(par, h)];
        s->face_verts[h] = v2;
        s->vorig[v2] = c->face_verts[h];
    }
    for (int32_t v = 0; v < nv2; v++) {
        int32_t o = s->vorig[v];
        memcpy(s->positions + 3 * (size_t)v, c->positions + 3 * (size_t)o, sizeof(double) * 3);
        double vc = c->vertex_creases ? c->vertex_creases[o] : 0.0;
        /* OpenSubdiv: a non-manifold vertex is a corner, but inside a non-manifold crease */
        const int32_t *k = cnt + 4 * o;
        int crease = k[2] == 2 && k[3] == 0 && k[1] > k[0];
        s->vertex_creases[v] = nmv[o] && !crease ? CCN_SHARPNESS_INFINITE : vc;
    }
    /* the cage's edges, on every split edge between copies of their ends (each face edge listed;
     * a later unset value does not replace a set one), then the non-manifold edges' sharpness */
    ekey *listed = malloc(sizeof(ekey) * (size_t)(c->num_edges ? c->num_edges : 1));
    if (!listed) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto done; }
    for (int32_t i = 0; i < c->num_edges; i++) {
        int32_t x = c->edge_verts[2 * i], y = c->edge_verts[2 * i + 1];
        listed[i] = (ekey){x < y ? x : y, x < y ? y : x, i};
    }
    qsort(listed, (size_t)c->num_edges, sizeof *listed, ekey_cmp); /* in list order per pair */
    uint8_t *seen = calloc((size_t)(c->num_edges ? c->num_edges : 1), 1);
    if (!seen) { free(listed); st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto done; }
    int32_t e2 = 0;
    for (int32_t h = 0; h < nh; h++) {
        int32_t a = s->face_verts[h], b = s->face_verts[next[h]];
        int32_t oa = c->face_verts[h], ob = c->face_verts[next[h]];
        double kn = 0, cr = nme[h] ? CCN_SHARPNESS_INFINITE : 0.0;
        ekey k = {oa < ob ? oa : ob, oa < ob ? ob : oa, -1};
        size_t lo = 0, hi = (size_t)c->num_edges;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (listed[mid].a < k.a || (listed[mid].a == k.a && listed[mid].b < k.b)) lo = mid + 1;
            else hi = mid;
        }
        for (size_t q = lo; q < (size_t)c->num_edges && listed[q].a == k.a && listed[q].b == k.b; q++) {
            int32_t i = listed[q].h;
            seen[i] = 1;
            if (c->edge_knots && c->edge_knots[i] > 0) kn = c->edge_knots[i];
            if (c->edge_creases && c->edge_creases[i] > cr) cr = c->edge_creases[i];
        }
        s->edge_verts[2 * e2] = a, s->edge_verts[2 * e2 + 1] = b;
        s->edge_knots[e2] = kn, s->edge_creases[e2] = cr;
        e2++;
    }
    s->num_edges = e2;
    for (int32_t i = 0; i < c->num_edges; i++) s->ignored_edges += !seen[i]; /* in no face */
    free(seen);
    free(listed);
done:
    free(fstart); free(next); free(twin); free(par); free(copy); free(nme); free(nmv); free(keys);
    free(cnt);
    if (st) ccn__split_free(s);
    return st;
}
