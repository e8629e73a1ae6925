/* Cage topology: half-edge mesh from a polygon soup, with validation.
 *
 * Rejected (CCN_ERR_TOPOLOGY, the message names the element): a face with < 3 vertices or a
 * repeated vertex, an index out of range. Rejected (CCN_ERR_ARGUMENT): negative counts,
 * NULL arrays, NaN/Inf coordinates or beyond +-CCN_COORD_MAX, no faces, NaN sharpness.
 * Non-manifold cages (an edge shared by more than two faces, two faces using an edge in the
 * same direction, a vertex whose faces form more than one fan) are read as OpenSubdiv reads
 * them: split into a manifold cage (topology/split.c) whose outputs are welded back through the
 * representatives below. Ignored and counted: isolated vertices, knot or crease values given
 * for vertex pairs that are not edges of any face (loose edges). Sharpness <= 0 is smooth,
 * >= 10 (and +Inf) is stored as 10 (infinitely sharp), as OpenSubdiv does. Interior vertices
 * of valence 2 are accepted (Catmull-Clark / NURSS rules at n = 2, no eigen rules or cap).
 */
#include "topology/mesh.h"

#include "base/error.h"
#include "base/union_find.h"
#include "topology/knots.h"
#include "topology/split.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

ccn_mesh *ccn__mesh_alloc(int32_t nv, int32_t nf, int32_t nh, int32_t ne) {
    ccn_mesh *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->nv = nv; m->nf = nf; m->nh = nh; m->ne = ne;
    m->knot_scale = 1.0;
    m->pos = malloc(sizeof(double) * 3 * (size_t)(nv ? nv : 1));
    m->fstart = malloc(sizeof(int32_t) * ((size_t)nf + 1));
    m->hvert = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->htwin = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->hedge = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->hface = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->everts = malloc(sizeof(int32_t) * 2 * (size_t)(ne ? ne : 1));
    m->eknot = malloc(sizeof(double) * (size_t)(ne ? ne : 1));
    m->vfan_start = malloc(sizeof(int32_t) * ((size_t)nv + 1));
    m->vfan = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->hfanpos = malloc(sizeof(int32_t) * (size_t)(nh ? nh : 1));
    m->vlast_edge = malloc(sizeof(int32_t) * (size_t)(nv ? nv : 1));
    m->vboundary = malloc((size_t)(nv ? nv : 1));
    if (!m->pos || !m->fstart || !m->hvert || !m->htwin || !m->hedge || !m->hface ||
        !m->everts || !m->eknot || !m->vfan_start || !m->vfan || !m->hfanpos ||
        !m->vlast_edge || !m->vboundary) {
        ccn_mesh_destroy(m);
        return NULL;
    }
    return m;
}

void ccn_mesh_destroy(ccn_mesh *m) {
    if (!m) return;
    free(m->pos); free(m->fstart); free(m->hvert); free(m->htwin); free(m->hedge);
    free(m->hface); free(m->everts); free(m->eknot); free(m->vfan_start); free(m->vfan);
    free(m->hfanpos); free(m->vlast_edge); free(m->vboundary); free(m->esharp); free(m->vsharp);
    free(m->vrep); free(m->vweld); free(m->erep); free(m->eweld);
    free(m);
}

int ccn__mesh_alloc_sharpness(ccn_mesh *m) {
    free(m->esharp);
    free(m->vsharp);
    m->esharp = calloc((size_t)(m->ne ? m->ne : 1), sizeof(float));
    m->vsharp = calloc((size_t)(m->nv ? m->nv : 1), sizeof(float));
    if (m->esharp && m->vsharp) return 0;
    free(m->esharp); free(m->vsharp);
    m->esharp = NULL; m->vsharp = NULL;
    return -1;
}

void ccn__mesh_drop_smooth_sharpness(ccn_mesh *m) {
    if (!m->esharp) return;
    for (int32_t e = 0; e < m->ne; e++)
        if (m->esharp[e] > 0.0f) return;
    for (int32_t v = 0; v < m->nv; v++)
        if (m->vsharp[v] > 0.0f) return;
    free(m->esharp); free(m->vsharp);
    m->esharp = NULL; m->vsharp = NULL;
}

/* ---- fans ----------------------------------------------------------------------- */

/* Walks v's fan from `start` by h -> twin(prev(h)) (counter-clockwise); returns the count
 * of outgoing half-edges visited and writes them to out (if not NULL). */
static int32_t walk_fan(const ccn_mesh *m, int32_t start, int32_t *out, int32_t cap,
                        int32_t *last) {
    int32_t h = start, k = 0;
    for (;;) {
        if (out && k < cap) out[k] = h;
        k++;
        int32_t p = ccn__prev(m, h);
        int32_t t = m->htwin[p];
        if (t < 0) { *last = m->hedge[p]; return k; }
        if (t == start || k > cap) { *last = -1; return k; }
        h = t;
    }
}

int32_t ccn__mesh_build_fans(ccn_mesh *m) {
    int32_t nv = m->nv, nh = m->nh;
    int32_t *start = m->vlast_edge; /* scratch: a starting half-edge per vertex */
    memset(m->vfan_start, 0, sizeof(int32_t) * ((size_t)nv + 1));
    for (int32_t v = 0; v < nv; v++) start[v] = -1;
    for (int32_t h = 0; h < nh; h++) {
        int32_t v = m->hvert[h];
        m->vfan_start[v + 1]++;
        if (start[v] < 0 || m->htwin[h] < 0) {
            if (start[v] >= 0 && m->htwin[start[v]] < 0 && m->htwin[h] < 0) return v + 1;
            start[v] = h;
        }
    }
    for (int32_t v = 0; v < nv; v++) m->vfan_start[v + 1] += m->vfan_start[v];
    for (int32_t v = 0; v < nv; v++) {
        int32_t s = start[v], cnt = m->vfan_start[v + 1] - m->vfan_start[v], last = -1;
        m->vboundary[v] = 0;
        if (cnt == 0) { m->vlast_edge[v] = -1; continue; }
        int32_t got = walk_fan(m, s, m->vfan + m->vfan_start[v], cnt, &last);
        if (got != cnt) return v + 1;
        m->vboundary[v] = (uint8_t)(m->htwin[s] < 0);
        m->vlast_edge[v] = m->vboundary[v] ? last : -1;
        for (int32_t k = 0; k < cnt; k++) m->hfanpos[m->vfan[m->vfan_start[v] + k]] = k;
    }
    return 0;
}

void ccn__mesh_mark_face_ring(const ccn_mesh *m, const int32_t *list, int32_t n, uint8_t *fm,
                              uint8_t *y) {
    for (int32_t i = 0; i < n; i++) {
        int32_t v = list[i];
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
            int32_t f = m->hface[m->vfan[k]];
            if (fm && fm[f]) continue;
            if (fm) fm[f] = 1;
            for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) y[m->hvert[h]] = 1;
        }
    }
}

void ccn__mesh_update_info(ccn_mesh *m) {
    ccn_mesh_info *in = &m->info;
    in->num_verts = m->vweld ? m->nvw : m->nv; in->num_faces = m->nf;
    in->num_edges = m->eweld ? m->new_ : m->ne;
    in->num_face_verts = m->nh;
    in->num_boundary_edges = 0;
    for (int32_t h = 0; h < m->nh; h++) in->num_boundary_edges += m->htwin[h] < 0;
    in->num_extraordinary = 0; in->max_valence = 0; in->num_ignored_verts = 0;
    in->num_sharp_edges = 0; in->num_sharp_vertices = 0;
    for (int32_t e = 0; m->esharp && e < m->ne; e++) in->num_sharp_edges += m->esharp[e] > 0.0f;
    for (int32_t v = 0; m->vsharp && v < m->nv; v++) in->num_sharp_vertices += m->vsharp[v] > 0.0f;
    for (int32_t v = 0; v < m->nv; v++) {
        int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v];
        if (nfan == 0) { in->num_ignored_verts++; continue; }
        int32_t val = ccn__valence(m, v);
        if (val > in->max_valence) in->max_valence = val;
        if (!m->vboundary[v] && val != 4) in->num_extraordinary++;
    }
}

/* ---- welded view of a split cage ------------------------------------------------- */

typedef struct { int32_t a, b, e; } wkey;

static int wkey_cmp(const void *x, const void *y) {
    const wkey *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return (p->e > q->e) - (p->e < q->e);
}

int ccn__mesh_weld(ccn_mesh *m) {
    if (!m->vrep) return 0;
    free(m->vweld); free(m->erep); free(m->eweld);
    m->vweld = malloc(sizeof(int32_t) * (size_t)(m->nv ? m->nv : 1));
    m->erep = malloc(sizeof(int32_t) * (size_t)(m->ne ? m->ne : 1));
    m->eweld = malloc(sizeof(int32_t) * (size_t)(m->ne ? m->ne : 1));
    wkey *k = malloc(sizeof(wkey) * (size_t)(m->ne ? m->ne : 1));
    if (!m->vweld || !m->erep || !m->eweld || !k) { free(k); return -1; }
    int32_t n = 0;
    for (int32_t v = 0; v < m->nv; v++)
        if (m->vrep[v] == v) m->vweld[v] = n++;
    for (int32_t v = 0; v < m->nv; v++) m->vweld[v] = m->vweld[m->vrep[v]];
    m->nvw = n;
    for (int32_t e = 0; e < m->ne; e++) {
        int32_t a = m->vrep[m->everts[2 * e]], b = m->vrep[m->everts[2 * e + 1]];
        k[e] = (wkey){a < b ? a : b, a < b ? b : a, e};
    }
    qsort(k, (size_t)m->ne, sizeof *k, wkey_cmp);
    for (int32_t i = 0; i < m->ne;) { /* the smallest edge of each group represents it */
        int32_t j = i + 1;
        while (j < m->ne && k[j].a == k[i].a && k[j].b == k[i].b) j++;
        for (int32_t q = i; q < j; q++) m->erep[k[q].e] = k[i].e;
        i = j;
    }
    free(k);
    n = 0;
    for (int32_t e = 0; e < m->ne; e++)
        if (m->erep[e] == e) m->eweld[e] = n++;
    for (int32_t e = 0; e < m->ne; e++) m->eweld[e] = m->eweld[m->erep[e]];
    m->new_ = n;
    return 0;
}

int ccn__mesh_weld_child(const ccn_mesh *m, ccn_mesh *r) {
    if (!m->vrep) return 0;
    free(r->vrep);
    r->vrep = malloc(sizeof(int32_t) * (size_t)(r->nv ? r->nv : 1));
    if (!r->vrep) return -1;
    for (int32_t f = 0; f < m->nf; f++) r->vrep[f] = f;
    for (int32_t e = 0; e < m->ne; e++) r->vrep[m->nf + e] = m->nf + m->erep[e];
    for (int32_t v = 0; v < m->nv; v++) r->vrep[m->nf + m->ne + v] = m->nf + m->ne + m->vrep[v];
    return ccn__mesh_weld(r);
}

/* ---- building from a polygon soup ----------------------------------------------- */

typedef struct { int32_t a, b, h; } hkey;

/* The half-edges' keys (min end, max end, half-edge) of m (faces filled), sorted by (a, b, h):
 * counted into one bucket per a (made in increasing h, so each bucket is in h order), then
 * each bucket -- a vertex's few edges -- by b, stably (insertion sort). The order qsort with
 * the (a, b, h) comparison gives, in O(nh) and without a call per comparison. -1: no memory. */
static int sorted_keys(const ccn_mesh *m, hkey *keys) {
    int32_t nh = m->nh, nv = m->nv;
    int32_t *start = calloc((size_t)nv + 1, sizeof(int32_t));
    if (!start) return -1;
    for (int32_t h = 0; h < nh; h++) {
        int32_t a = m->hvert[h], b = m->hvert[ccn__next(m, h)];
        start[(a < b ? a : b) + 1]++;
    }
    for (int32_t v = 0; v < nv; v++) start[v + 1] += start[v];
    for (int32_t h = 0; h < nh; h++) {
        int32_t a = m->hvert[h], b = m->hvert[ccn__next(m, h)], lo = a < b ? a : b;
        hkey k = {lo, a < b ? b : a, h};
        keys[start[lo]++] = k;
    }
    /* start[v] is now the end of bucket v (the start of v + 1) */
    for (int32_t v = 0, b0 = 0; v < nv; b0 = start[v], v++)
        for (int32_t i = b0 + 1; i < start[v]; i++) {
            hkey k = keys[i];
            int32_t j = i;
            for (; j > b0 && keys[j - 1].b > k.b; j--) keys[j] = keys[j - 1];
            keys[j] = k;
        }
    free(start);
    return 0;
}

static ccn_status check_args(const ccn_cage *c, int64_t *nh_out, ccn_error *err) {
    if (!c) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "cage is NULL");
    if (c->num_verts < 0 || c->num_faces < 0 || c->num_edges < 0)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "negative count (verts %d, faces %d, edges %d)", (int)c->num_verts,
                         (int)c->num_faces, (int)c->num_edges);
    if (c->num_faces == 0)
        return ccn__because(err, CCN_REASON_NO_FACES,
                            ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "cage has no faces"));
    if (!c->positions || !c->face_sizes || !c->face_verts)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "cage positions, face_sizes or face_verts is NULL");
    if (c->num_edges > 0 && !c->edge_verts)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "num_edges is %d but edge_verts is NULL", (int)c->num_edges);
    for (int32_t v = 0; v < c->num_verts; v++)
        for (int k = 0; k < 3; k++) {
            double x = c->positions[3 * (size_t)v + k];
            if (!isfinite(x))
                return ccn__because(err, CCN_REASON_NONFINITE_COORDINATE,
                                    ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, v,
                                              "vertex %d has a non-finite coordinate (NaN or Inf)", (int)v));
            if (fabs(x) > CCN_COORD_MAX)
                return ccn__because(err, CCN_REASON_COORDINATE_RANGE,
                                    ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, v,
                                              "vertex %d has a coordinate beyond +-%g", (int)v, CCN_COORD_MAX));
        }
    for (int32_t i = 0; c->edge_creases && i < c->num_edges; i++)
        if (isnan(c->edge_creases[i])) {
            ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_EDGE, i,
                      "edge %d (vertices %d-%d) has a NaN crease sharpness", (int)i,
                      (int)c->edge_verts[2 * i], (int)c->edge_verts[2 * i + 1]);
            if (err) err->element_verts[0] = c->edge_verts[2 * i], err->element_verts[1] = c->edge_verts[2 * i + 1];
            return ccn__because(err, CCN_REASON_NAN_SHARPNESS, CCN_ERR_ARGUMENT);
        }
    for (int32_t v = 0; c->vertex_creases && v < c->num_verts; v++)
        if (isnan(c->vertex_creases[v]))
            return ccn__because(err, CCN_REASON_NAN_SHARPNESS,
                                ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, v,
                                          "vertex %d has a NaN crease sharpness", (int)v));
    int64_t nh = 0;
    for (int32_t f = 0; f < c->num_faces; f++) {
        int32_t s = c->face_sizes[f];
        if (s < 3)
            return ccn__because(err, CCN_REASON_FACE_TOO_FEW_VERTICES,
                                ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, f,
                                          "face %d has %d vertices (at least 3 needed)", (int)f, (int)s));
        nh += s;
        if (nh > INT32_MAX / 8)
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_FACE, f,
                             "cage too large: more than %d face corners", INT32_MAX / 8);
    }
    *nh_out = nh;
    return CCN_OK;
}

static ccn_status fill_faces(ccn_mesh *m, const ccn_cage *c, ccn_error *err) {
    int32_t h = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        int32_t s = c->face_sizes[f];
        m->fstart[f] = h;
        for (int32_t k = 0; k < s; k++, h++) {
            int32_t v = c->face_verts[h];
            if (v < 0 || v >= m->nv)
                return ccn__because(err, CCN_REASON_INDEX_OUT_OF_RANGE,
                                    ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, f,
                                              "face %d uses vertex index %d, out of range [0, %d)",
                                              (int)f, (int)v, (int)m->nv));
            for (int32_t j = 0; j < k; j++)
                if (c->face_verts[m->fstart[f] + j] == v)
                    return ccn__because(err, CCN_REASON_FACE_REPEATS_VERTEX,
                                        ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, f,
                                                  "face %d repeats vertex %d", (int)f, (int)v));
            m->hvert[h] = v;
            m->hface[h] = f;
        }
    }
    m->fstart[m->nf] = h;
    return CCN_OK;
}

/* Pairs half-edges into edges (sorted keys, left sorted for find_edge), numbering edges by
 * first appearance; grp and gmap: nh ints of scratch each. */
static ccn_status pair_edges(ccn_mesh *m, hkey *keys, int32_t *grp, int32_t *gmap, int *nonmanifold,
                             ccn_error *err) {
    int32_t nh = m->nh;
    if (sorted_keys(m, keys))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory for %d corners", (int)nh);
    int32_t ng = 0;
    for (int32_t i = 0; i < nh;) {
        int32_t j = i + 1;
        while (j < nh && keys[j].a == keys[i].a && keys[j].b == keys[i].b) j++;
        for (int32_t k = i; k < j; k++) grp[keys[k].h] = ng;
        m->htwin[keys[i].h] = -1;
        if (j - i == 2) {
            int32_t h0 = keys[i].h, h1 = keys[i + 1].h;
            if (m->hvert[h0] == m->hvert[h1]) {
                *nonmanifold = 1;
                return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, m->hface[h1],
                                 "edge %d-%d is used in the same direction by faces %d and %d "
                                 "(inconsistent orientation)", (int)keys[i].a, (int)keys[i].b,
                                 (int)m->hface[h0], (int)m->hface[h1]);
            }
            m->htwin[h0] = h1;
            m->htwin[h1] = h0;
        } else if (j - i > 2) {
            *nonmanifold = 1;
            return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_EDGE, ng,
                             "edge %d-%d is shared by %d faces (faces %d, %d, %d): non-manifold",
                             (int)keys[i].a, (int)keys[i].b, (int)(j - i),
                             (int)m->hface[keys[i].h], (int)m->hface[keys[i + 1].h],
                             (int)m->hface[keys[i + 2].h]);
        }
        ng++;
        i = j;
    }
    /* grp ids -> edge ids by first appearance */
    for (int32_t g = 0; g < ng; g++) gmap[g] = -1;
    int32_t ne = 0;
    for (int32_t h = 0; h < nh; h++) {
        int32_t g = grp[h];
        if (gmap[g] < 0) {
            gmap[g] = ne;
            m->everts[2 * ne] = m->hvert[h];
            m->everts[2 * ne + 1] = m->hvert[ccn__next(m, h)];
            ne++;
        }
        m->hedge[h] = gmap[g];
    }
    m->ne = ne;
    return CCN_OK;
}

/* Finds edge (a,b) by binary search in keys sorted by (min,max); -1 if absent. */
static int32_t find_edge(const ccn_mesh *m, const hkey *sorted, int32_t a, int32_t b) {
    hkey k = {a < b ? a : b, a < b ? b : a, -1};
    size_t lo = 0, hi = (size_t)m->nh;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        const hkey *s = &sorted[mid];
        if (s->a < k.a || (s->a == k.a && s->b < k.b)) lo = mid + 1; else hi = mid;
    }
    if (lo < (size_t)m->nh && sorted[lo].a == k.a && sorted[lo].b == k.b)
        return m->hedge[sorted[lo].h];
    return -1;
}

static ccn_status apply_knots(ccn_mesh *m, const ccn_cage *c, const hkey *keys, ccn_error *err) {
    double *val = malloc(sizeof(double) * (size_t)(m->ne ? m->ne : 1));
    if (!val) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    for (int32_t e = 0; e < m->ne; e++) val[e] = 0.0;
    m->info.num_ignored_edges = 0;
    if ((c->edge_knots || c->edge_creases) && c->edge_verts) {
        for (int32_t i = 0; i < c->num_edges; i++) {
            int32_t a = c->edge_verts[2 * i], b = c->edge_verts[2 * i + 1];
            int32_t e = (a >= 0 && b >= 0 && a < m->nv && b < m->nv) ? find_edge(m, keys, a, b)
                                                                      : -1;
            if (e < 0) { m->info.num_ignored_edges++; continue; }
            if (!c->edge_knots) continue;
            double x = c->edge_knots[i];
            if (isfinite(x) && x > 0.0) val[e] = x; /* an unset value does not replace a set one */
        }
    }
    ccn_status st = ccn__resolve_rings(m, val, NULL, err);
    free(val);
    return st;
}

/* Sharpness as OpenSubdiv stores it: float, clamped to [0, 10]. */
static float sharpness_value(double s) {
    if (!(s > 0.0)) return 0.0f;
    if (s >= CCN_SHARPNESS_INFINITE) return (float)CCN_SHARPNESS_INFINITE;
    return (float)s;
}

/* Edge sharpness from edge_creases (keys sorted by pair_edges), vertex sharpness. */
static ccn_status apply_creases(ccn_mesh *m, const ccn_cage *c, const hkey *keys, ccn_error *err) {
    int any = 0;
    for (int32_t i = 0; c->edge_creases && c->edge_verts && i < c->num_edges && !any; i++)
        any = c->edge_creases[i] > 0.0;
    for (int32_t v = 0; c->vertex_creases && v < c->num_verts && !any; v++)
        any = c->vertex_creases[v] > 0.0;
    if (!any) return CCN_OK;
    if (ccn__mesh_alloc_sharpness(m))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (creases)");
    for (int32_t i = 0; c->edge_creases && c->edge_verts && i < c->num_edges; i++) {
        int32_t a = c->edge_verts[2 * i], b = c->edge_verts[2 * i + 1];
        int32_t e = (a >= 0 && b >= 0 && a < m->nv && b < m->nv) ? find_edge(m, keys, a, b) : -1;
        if (e < 0) continue; /* counted in apply_knots */
        float s = sharpness_value(c->edge_creases[i]);
        if (s > 0.0f) m->esharp[e] = s; /* a smooth value does not replace a sharp one */
    }
    for (int32_t v = 0; c->vertex_creases && v < c->num_verts; v++)
        m->vsharp[v] = sharpness_value(c->vertex_creases[v]);
    return CCN_OK;
}

static ccn_status mesh_create(const ccn_cage *cage, int64_t nh, ccn_mesh **out, int *nonmanifold,
                              ccn_error *err);

ccn_status ccn_mesh_create(const ccn_cage *cage, ccn_mesh **out, ccn_error *err) {
    ccn__ok(err);
    if (!out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "out is NULL");
    *out = NULL;
    int64_t nh = 0;
    ccn_status st = check_args(cage, &nh, err);
    if (st) return st;
    /* a manifold cage is built directly; one that is not (an edge with more than two faces or
     * used twice in one direction, a vertex with several fans) is split into a manifold cage
     * (topology/split.c) and built from that, at no cost to manifold cages */
    int nonmanifold = 0;
    st = mesh_create(cage, nh, out, &nonmanifold, err);
    if (!st || !nonmanifold) return st;
    ccn__ok(err);
    ccn__split sp;
    if ((st = ccn__split_cage(cage, (int32_t)nh, &sp, err))) return st;
    if (!sp.split) /* cannot happen: mesh_create found what the split finds */
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "non-manifold cage not split");
    ccn_cage c2 = *cage;
    c2.num_verts = sp.num_verts, c2.positions = sp.positions, c2.face_verts = sp.face_verts;
    c2.num_edges = sp.num_edges, c2.edge_verts = sp.edge_verts, c2.edge_knots = sp.edge_knots;
    c2.edge_creases = sp.edge_creases, c2.vertex_creases = sp.vertex_creases;
    nonmanifold = 0;
    st = mesh_create(&c2, nh, out, &nonmanifold, err);
    if (!st) {
        ccn_mesh *m = *out;
        m->vrep = sp.vorig; /* at level 0 the cage vertex is the representative */
        sp.vorig = NULL;
        if (ccn__mesh_weld(m)) {
            ccn_mesh_destroy(m);
            *out = NULL;
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (weld)");
        } else {
            ccn__mesh_update_info(m);
            m->info.num_ignored_edges = sp.ignored_edges;
            m->info.level = 0;
        }
    }
    ccn__split_free(&sp);
    return st;
}

static ccn_status mesh_create(const ccn_cage *cage, int64_t nh, ccn_mesh **out, int *nonmanifold,
                              ccn_error *err) {
    ccn_status st = CCN_OK;
    ccn_mesh *m = ccn__mesh_alloc(cage->num_verts, cage->num_faces, (int32_t)nh, (int32_t)nh);
    hkey *keys = malloc(sizeof(hkey) * (size_t)nh);
    int32_t *grp = malloc(sizeof(int32_t) * 2 * (size_t)nh);
    if (!m || !keys || !grp) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory for %lld corners",
                       (long long)nh);
        goto done;
    }
    memcpy(m->pos, cage->positions, sizeof(double) * 3 * (size_t)m->nv);
    if ((st = fill_faces(m, cage, err))) goto done;
    if ((st = pair_edges(m, keys, grp, grp + nh, nonmanifold, err))) goto done;
    int32_t bad = ccn__mesh_build_fans(m);
    if (bad) {
        *nonmanifold = 1;
        st = ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, bad - 1,
                       "vertex %d is non-manifold: its faces form more than one fan",
                       (int)(bad - 1));
        goto done;
    }
    if ((st = apply_knots(m, cage, keys, err))) goto done;
    if ((st = apply_creases(m, cage, keys, err))) goto done;
    ccn__mesh_update_info(m);
    m->info.level = 0;
    *out = m;
    m = NULL;
done:
    free(keys);
    free(grp);
    ccn_mesh_destroy(m);
    return st;
}

ccn_status ccn_mesh_get_info(const ccn_mesh *m, ccn_mesh_info *info) {
    if (!m || !info) return CCN_ERR_ARGUMENT;
    *info = m->info;
    return CCN_OK;
}

ccn_status ccn_mesh_copy(const ccn_mesh *m, double *positions, int32_t *face_sizes,
                         int32_t *face_verts, int32_t *edge_verts, double *edge_knots) {
    if (!m) return CCN_ERR_ARGUMENT;
    if (m->vweld) { /* a split cage's mesh: its welded view */
        for (int32_t v = 0; positions && v < m->nv; v++)
            if (m->vrep[v] == v) memcpy(positions + 3 * (size_t)m->vweld[v], m->pos + 3 * (size_t)v, sizeof(double) * 3);
        for (int32_t f = 0; face_sizes && f < m->nf; f++) face_sizes[f] = ccn__fsize(m, f);
        for (int32_t h = 0; face_verts && h < m->nh; h++) face_verts[h] = m->vweld[m->hvert[h]];
        for (int32_t e = 0; e < m->ne; e++) {
            if (m->erep[e] != e) continue;
            int32_t w = m->eweld[e];
            if (edge_verts) edge_verts[2 * w] = m->vweld[m->everts[2 * e]], edge_verts[2 * w + 1] = m->vweld[m->everts[2 * e + 1]];
            if (edge_knots) edge_knots[w] = m->eknot[e] * m->knot_scale;
        }
        return CCN_OK;
    }
    if (positions) memcpy(positions, m->pos, sizeof(double) * 3 * (size_t)m->nv);
    if (face_sizes)
        for (int32_t f = 0; f < m->nf; f++) face_sizes[f] = ccn__fsize(m, f);
    if (face_verts) memcpy(face_verts, m->hvert, sizeof(int32_t) * (size_t)m->nh);
    if (edge_verts) memcpy(edge_verts, m->everts, sizeof(int32_t) * 2 * (size_t)m->ne);
    if (edge_knots)
        for (int32_t e = 0; e < m->ne; e++) edge_knots[e] = m->eknot[e] * m->knot_scale;
    return CCN_OK;
}

ccn_status ccn_mesh_get_creases(const ccn_mesh *m, double *edge_sharpness, double *vertex_sharpness) {
    if (!m) return CCN_ERR_ARGUMENT;
    if (m->vweld) { /* welded view: the representatives' */
        for (int32_t e = 0; edge_sharpness && e < m->ne; e++)
            if (m->erep[e] == e) edge_sharpness[m->eweld[e]] = m->esharp ? m->esharp[e] : 0.0;
        for (int32_t v = 0; vertex_sharpness && v < m->nv; v++)
            if (m->vrep[v] == v) vertex_sharpness[m->vweld[v]] = m->vsharp ? m->vsharp[v] : 0.0;
        return CCN_OK;
    }
    for (int32_t e = 0; edge_sharpness && e < m->ne; e++)
        edge_sharpness[e] = m->esharp ? m->esharp[e] : 0.0;
    for (int32_t v = 0; vertex_sharpness && v < m->nv; v++)
        vertex_sharpness[v] = m->vsharp ? m->vsharp[v] : 0.0;
    return CCN_OK;
}

ccn_status ccn_mesh_set_positions(ccn_mesh *m, const double *positions, ccn_error *err) {
    ccn__ok(err);
    if (!m || !positions)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "mesh or positions is NULL");
    int32_t nv = m->vweld ? m->nvw : m->nv; /* a split cage: one position per welded vertex */
    for (int32_t i = 0; i < 3 * nv; i++) {
        if (!isfinite(positions[i]))
            return ccn__because(err, CCN_REASON_NONFINITE_COORDINATE,
                                ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, i / 3,
                                          "vertex %d has a non-finite coordinate (NaN or Inf)", (int)(i / 3)));
        if (fabs(positions[i]) > CCN_COORD_MAX)
            return ccn__because(err, CCN_REASON_COORDINATE_RANGE,
                                ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, i / 3,
                                          "vertex %d has a coordinate beyond +-%g", (int)(i / 3), CCN_COORD_MAX));
    }
    if (m->vweld)
        for (int32_t v = 0; v < m->nv; v++)
            memcpy(m->pos + 3 * (size_t)v, positions + 3 * (size_t)m->vweld[v], sizeof(double) * 3);
    else
        memcpy(m->pos, positions, sizeof(double) * 3 * (size_t)m->nv);
    return CCN_OK;
}

/* Positions relative to a centre, scaled by a power of two so that the largest coordinate of
 * the vertices in faces is below 1 (isolated vertices do not count). The centre is the middle
 * of the bounding box rounded to a multiple of a power of two q at least 1/8 of its extent and
 * at least the coordinates' last place, so the shift is exact (p - c is a multiple of ulp(p)
 * below |p| + |c|) and moving a vertex rarely moves it; computed on the mesh, a model 1000
 * times its size away then keeps the precision it has at the origin (the output adds the centre
 * back, one rounding). The centre is kept only if no connected part reaches farther from it
 * than from the origin: a part at the origin beside one far away keeps its own precision (and
 * a part's surface does not depend on where the others are). A box around the origin is not
 * shifted (at most a factor 2 to gain; and no pass over the parts on every evaluation of the
 * usual model around its object's origin). */
void ccn__normalize(ccn_mesh *m, double centre[3], double *scale) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, big = 0;
    for (int32_t v = 0; v < m->nv; v++) {
        if (m->vfan_start[v + 1] == m->vfan_start[v]) continue;
        for (int k = 0; k < 3; k++) {
            double x = m->pos[3 * (size_t)v + k];
            lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x), big = fmax(big, fabs(x));
        }
    }
    centre[0] = centre[1] = centre[2] = 0;
    double extent = 0;
    for (int k = 0; k < 3; k++) extent = fmax(extent, hi[k] - lo[k]);
    int inside = 1; /* the origin in the box: every part already lies within the box's extent */
    for (int k = 0; k < 3; k++) inside &= lo[k] <= 0 && hi[k] >= 0;
    if (!inside && big > 0 && isfinite(big) && extent > 0 && isfinite(extent)) {
        int eq = ilogb(extent) - 3, eb = ilogb(big) - 52;
        double q = ldexp(1.0, eq > eb ? eq : eb), c[3];
        for (int k = 0; k < 3; k++) c[k] = q * nearbyint(0.5 * (lo[k] + hi[k]) / q);
        /* the parts (union-find over the faces' corners) and how far each reaches from c and
         * from the origin; without memory, no shift */
        int32_t *root = malloc(sizeof(int32_t) * (size_t)(m->nv ? m->nv : 1));
        double *reach = malloc(sizeof(double) * 2 * (size_t)(m->nv ? m->nv : 1));
        int shift = root && reach;
        if (shift) {
            for (int32_t v = 0; v < m->nv; v++) root[v] = v, reach[2 * (size_t)v] = reach[2 * (size_t)v + 1] = 0;
            for (int32_t f = 0; f < m->nf; f++)
                for (int32_t h = m->fstart[f] + 1; h < m->fstart[f + 1]; h++)
                    ccn__uf_union(root, m->hvert[m->fstart[f]], m->hvert[h]);
            for (int32_t v = 0; v < m->nv; v++) {
                if (m->vfan_start[v + 1] == m->vfan_start[v]) continue;
                size_t r = (size_t)ccn__uf_find(root, v);
                for (int k = 0; k < 3; k++) {
                    double x = m->pos[3 * (size_t)v + k];
                    reach[2 * r] = fmax(reach[2 * r], fabs(x - c[k]));
                    reach[2 * r + 1] = fmax(reach[2 * r + 1], fabs(x));
                }
            }
            for (int32_t v = 0; v < m->nv && shift; v++) shift = reach[2 * (size_t)v] <= reach[2 * (size_t)v + 1];
        }
        free(root);
        free(reach);
        if (shift) {
            big = 0;
            for (int k = 0; k < 3; k++) {
                centre[k] = c[k];
                big = fmax(big, fmax(fabs(lo[k] - c[k]), fabs(hi[k] - c[k])));
            }
        }
    }
    int e = big > 0 && isfinite(big) ? ilogb(big) + 1 : 0;
    if (e < -1000) e = -1000; /* subnormal input: 2^-e must stay finite */
    if (e > 1000) e = 1000;
    *scale = ldexp(1.0, e);
    double inv = ldexp(1.0, -e); /* powers of two: exact */
    for (int32_t v = 0; v < m->nv; v++)
        for (int k = 0; k < 3; k++) m->pos[3 * (size_t)v + k] = (m->pos[3 * (size_t)v + k] - centre[k]) * inv;
}

void ccn__denormalize(ccn_mesh *m, const double centre[3], double scale) {
    for (int32_t v = 0; v < m->nv; v++)
        for (int k = 0; k < 3; k++)
            m->pos[3 * (size_t)v + k] = centre[k] + scale * m->pos[3 * (size_t)v + k];
}
