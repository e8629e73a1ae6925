/* One level of refinement: face, edge and vertex points, new topology, new intervals.
 *
 * Rules (DESIGN §4.2, §4.3, §6.1 of Li 2016):
 *  - quads away from extraordinary vertices: tensor-product knot insertion (bspline.c);
 *  - faces with != 4 sides (level 0 only) and interior EVs: NURSS (nurss.c);
 *  - scheme EIGEN: the 2n+1 "red" points of every interior EV (its vertex point, its spoke
 *    edge points, the face points of its faces) come from the matrix M of eigen.c applied to
 *    its 1-ring (§6.1); if M cannot be built the EV falls back to NURSS (counted). From level
 *    1 on this holds for every EV; at level 0 only for an EV that is already what the NURSS
 *    step would make it (quad 1-ring, no other EV on its faces, e_i = d_i); the others get
 *    the NURSS step first (DESIGN §4.3), and where only e_i = d_i is missing the two are
 *    blended by how far e_i is from d_i, so the surface does not jump there;
 *  - scheme CATMULL_CLARK: all intervals are 1, which makes every rule above Catmull-Clark.
 *  - boundaries: the boundary is a cubic B-spline curve of the boundary polygon; valence-2
 *    corners are smooth, or fixed with CCN_CORNERS_PINNED.
 *  - creases (rules/crease.h, OpenSubdiv's semantics with the knot-interval rules): an edge of
 *    sharpness s >= 1 gets the curve edge point H (knot insertion along the crease), 0 < s < 1
 *    the blend s H + (1-s) (smooth edge point); a vertex's point follows its rule: smooth and
 *    dart the smooth rule, crease the curve vertex rule along its two sharp edges (as on a
 *    boundary), corner the vertex itself, blended with OpenSubdiv's fractional weight where the
 *    rule changes to the next level's. The eigen matrices act only at EVs without sharp edges
 *    or vertex sharpness; valence-2 vertices always use NURSS / Catmull-Clark rules.
 *
 * New numbering (documented in ccnurbs.h): vertices = face points (face order), edge points
 * (edge order), vertex points (vertex order). Face f's corner j (half-edge h = fstart[f]+j)
 * becomes quad h = (V_j, E(h_j), F, E(h_{j-1})), so new face index = old half-edge index.
 * Edges: old edge e splits into 2e (at everts[2e]) and 2e+1 (at everts[2e+1]); the edge from
 * the face point of f to the edge point of h_j is 2*ne + fstart[f] + j.
 */
#include "refine/level.h"

#include "base/error.h"
#include "base/parallel.h"
#include "refine/children.h"
#include "rules/bspline.h"
#include "rules/crease.h"
#include "rules/nurss.h"
#include "topology/knots.h"
#include "topology/mesh.h"

#include <math.h>
#include <string.h>

/* ---- points ----------------------------------------------------------------------- */

typedef struct { const ccn__level *c; double *fp, *ep, *vp; } points_job;

static void one_face_point(const ccn__level *c, int32_t f, double *fp) {
    const ccn_mesh *m = c->m;
    if (ccn__fsize(m, f) == 4 && c->tf) ccn__quad_face_blend(m, f, c->tf + 2 * (size_t)f, fp + 3 * (size_t)f);
    else if (ccn__fsize(m, f) == 4) ccn__quad_face_point(m, f, c->pinned, fp + 3 * (size_t)f);
    else ccn__ngon_face_point(m, f, fp + 3 * (size_t)f);
}

static void face_range(void *ctx, int32_t b, int32_t e) {
    const points_job *j = ctx;
    for (int32_t f = b; f < e; f++) one_face_point(j->c, f, j->fp);
}

/* Edge point of a sharp interior edge e (OpenSubdiv's ComputeEdgeVertexMask with the
 * knot-interval crease point H and smooth point). */
static void creased_edge_point(const ccn__level *c, int32_t e, const double *fp, double out[3]) {
    const ccn_mesh *m = c->m;
    float s = m->esharp[e];
    const double *H = c->H + 3 * (size_t)e;
    int crease = s >= 1.0f;
    if (!crease && c->crease_method == CCN_CREASE_CHAIKIN)
        crease = ccn__child_edge_sharpness(m, c->crease_method, e, m->everts[2 * e]) > 0.0f &&
                 ccn__child_edge_sharpness(m, c->crease_method, e, m->everts[2 * e + 1]) > 0.0f;
    if (crease) {
        for (int k = 0; k < 3; k++) out[k] = H[k];
        return;
    }
    double sm[3], w = (double)s;
    ccn__edge_point(m, c->erep[e], c->H, fp, sm);
    for (int k = 0; k < 3; k++) out[k] = w * H[k] + (1.0 - w) * sm[k];
}

static void one_edge_point(const ccn__level *c, int32_t e, const double *fp, double *ep) {
    if (c->te) {
        const double *t = c->te + 3 * (size_t)e;
        ccn__curve_edge_blend(c->m, c->erep[e], t[0], c->H + 3 * (size_t)e);
        if (ccn__edge_sharp(c->m, e) && c->m->htwin[c->erep[e]] >= 0) creased_edge_point(c, e, fp, ep);
        else ccn__edge_blend(c->m, c->erep[e], t[1], t[2], c->H, fp, ep);
        return;
    }
    ccn__curve_edge_point(c->m, c->erep[e], c->pinned, c->H + 3 * (size_t)e);
    if (ccn__edge_sharp(c->m, e) && c->m->htwin[c->erep[e]] >= 0) creased_edge_point(c, e, fp, ep);
    else ccn__edge_point(c->m, c->erep[e], c->H, fp, ep);
}

static void edge_range(void *ctx, int32_t b, int32_t end) {
    const points_job *j = ctx;
    const ccn__level *c = j->c;
    for (int32_t e = b; e < end; e++) one_edge_point(c, e, j->fp, j->ep + 3 * (size_t)e);
}

#define CREASE_STACK 1024 /* fan sharpness on the stack up to this valence */

/* Curve vertex point along fan edges a and b (OpenSubdiv's crease mask 3/4, 1/8, 1/8 for equal
 * intervals; the boundary rule when a and b are the boundary edges). */
static void crease_point(const ccn_mesh *m, int32_t v, const double *H, int32_t a, int32_t b,
                         double out[3]) {
    int32_t ea = ccn__fan_edge(m, v, a), eb = ccn__fan_edge(m, v, b);
    double da = m->eknot[ea], db = m->eknot[eb], s = 1.0 / (2.0 * (da + db));
    const double *p = m->pos + 3 * (size_t)v, *ha = H + 3 * (size_t)ea, *hb = H + 3 * (size_t)eb;
    for (int k = 0; k < 3; k++) out[k] = 0.5 * p[k] + s * (db * ha[k] + da * hb[k]);
}

static void rule_point(const ccn__level *c, int32_t v, int rule, int32_t n, const float *s,
                       const double *fp, double out[3]) {
    const ccn_mesh *m = c->m;
    if (rule == CCN_RULE_CORNER) {
        for (int k = 0; k < 3; k++) out[k] = m->pos[3 * (size_t)v + k];
    } else if (rule == CCN_RULE_CREASE) {
        int32_t ends[2];
        ccn__sharp_crease_ends(n, s, ends);
        crease_point(m, v, c->H, ends[0], ends[1], out);
    } else {
        ccn__nurss_vertex_point(m, v, c->H, fp, out);
    }
}

/* Vertex point on a creased mesh (OpenSubdiv's ComputeVertexVertexMask). The rule comes from
 * the sharpness around r = v, or around c->partner[v] (face-varying dependent sharpness; the
 * crease then runs along v's own sharp edges, which are its two boundary edges). */
static void creased_vertex_point(const ccn__level *c, int32_t v, const double *fp, double out[3]) {
    const ccn_mesh *m = c->m;
    int32_t r = c->partner && c->partner[v] >= 0 ? c->partner[v] : v;
    int32_t n = ccn__valence(m, r), nv = ccn__valence(m, v), mx = n > nv ? n : nv;
    float sbuf[3 * CREASE_STACK], *ps = sbuf;
    if (mx > CREASE_STACK && !(ps = malloc(sizeof(float) * 3 * (size_t)mx))) {
        rule_point(c, v, CCN_RULE_CORNER, 0, NULL, fp, out); /* out of memory: keep the point */
        return;
    }
    float *cs = ps + mx, *own = r == v ? ps : cs + mx;
    ccn__fan_sharpness(m, r, ps);
    if (r != v) ccn__fan_sharpness(m, v, own);
    float pvs = ccn__vertex_sharpness(m, r, c->pinned);
    int prule = ccn__sharp_rule(pvs, n, ps);
    if (prule == CCN_RULE_SMOOTH || prule == CCN_RULE_DART) {
        ccn__nurss_vertex_point(m, v, c->H, fp, out);
    } else {
        rule_point(c, v, prule, nv, own, fp, out);
        float cvs = ccn__sharp_decrement(pvs);
        ccn__sharp_children(c->crease_method, n, ps, cs);
        int crule = ccn__sharp_rule(cvs, n, cs);
        if (crule != prule) {
            double ch[3], w = (double)ccn__sharp_fraction(c->crease_method, pvs, cvs, n, ps, cs);
            if (r == v) rule_point(c, v, crule, n, cs, fp, ch);
            else if (crule == CCN_RULE_SMOOTH || crule == CCN_RULE_DART) ccn__nurss_vertex_point(m, v, c->H, fp, ch);
            else rule_point(c, v, crule, nv, own, fp, ch);
            for (int k = 0; k < 3; k++) out[k] = w * out[k] + (1.0 - w) * ch[k];
        }
    }
    if (ps != sbuf) free(ps);
}

static void one_vertex_point(const ccn__level *c, int32_t v, const double *fp, double *vp) {
    const ccn_mesh *m = c->m;
    double *out = vp + 3 * (size_t)v;
    if (m->vfan_start[v + 1] == m->vfan_start[v]) { /* isolated: carried along */
        memcpy(out, m->pos + 3 * (size_t)v, sizeof(double) * 3);
    } else if (m->esharp) {
        if (c->tvs && c->tvs[v]) /* its creased rule is the smooth one, tabulated */
            ccn__nurss_vertex_blend(m, v, c->th + 2 * (size_t)m->vfan_start[v], c->tv + 2 * (size_t)v, c->H,
                                    fp, out);
        else
            creased_vertex_point(c, v, fp, out);
    } else if (m->vboundary[v]) {
        ccn__boundary_vertex_point(m, v, c->H, c->pinned, out);
    } else if (c->tv) {
        ccn__nurss_vertex_blend(m, v, c->th + 2 * (size_t)m->vfan_start[v], c->tv + 2 * (size_t)v, c->H,
                                fp, out);
    } else {
        ccn__nurss_vertex_point(m, v, c->H, fp, out);
    }
}

/* ---- the rules' weights, tabulated (ccn__level.tf ...) ------------------------------- */

/* One element's weights, each tabulated once (tmask). */
static void tab_face(ccn__level *c, int32_t f) {
    if (c->tmask[f]) return;
    c->tmask[f] = 1;
    if (ccn__fsize(c->m, f) == 4) ccn__quad_face_weights(c->m, f, c->pinned, c->tf + 2 * (size_t)f);
}

static void tab_edge(ccn__level *c, int32_t e) {
    const ccn_mesh *m = c->m;
    uint8_t *mask = c->tmask + m->nf;
    if (mask[e]) return;
    mask[e] = 1;
    int32_t h = c->erep[e], t = m->htwin[h];
    double *o = c->te + 3 * (size_t)e;
    o[0] = ccn__curve_edge_weight(m, h, c->pinned);
    o[1] = t < 0 ? 0.0 : ccn__transverse(m, h);
    o[2] = t < 0 ? 0.0 : ccn__transverse(m, t);
}

static void tab_vertex(ccn__level *c, int32_t v, float ps[CREASE_STACK]) {
    const ccn_mesh *m = c->m;
    uint8_t *mask = c->tmask + m->nf + m->ne;
    if (mask[v]) return;
    mask[v] = 1;
    if (m->vfan_start[v + 1] == m->vfan_start[v] || m->vboundary[v]) return;
    if (c->tvs) { /* creased mesh: where creased_vertex_point takes the smooth rule */
        int32_t n = ccn__valence(m, v);
        if ((c->partner && c->partner[v] >= 0) || n > CREASE_STACK) return;
        ccn__fan_sharpness(m, v, ps);
        int rule = ccn__sharp_rule(ccn__vertex_sharpness(m, v, c->pinned), n, ps);
        if (rule != CCN_RULE_SMOOTH && rule != CCN_RULE_DART) return;
        c->tvs[v] = 1;
    }
    ccn__nurss_vertex_weights(m, v, c->th + 2 * (size_t)m->vfan_start[v], c->tv + 2 * (size_t)v);
}

/* Over all elements (list NULL) or the listed ones. */
typedef struct { ccn__level *c; const int32_t *list; } tab_job;

static void tab_face_range(void *ctx, int32_t b, int32_t e) {
    const tab_job *j = ctx;
    for (int32_t i = b; i < e; i++) tab_face(j->c, j->list ? j->list[i] : i);
}

static void tab_edge_range(void *ctx, int32_t b, int32_t end) {
    const tab_job *j = ctx;
    for (int32_t i = b; i < end; i++) tab_edge(j->c, j->list ? j->list[i] : i);
}

static void tab_vertex_range(void *ctx, int32_t b, int32_t e) {
    const tab_job *j = ctx;
    float ps[CREASE_STACK];
    for (int32_t i = b; i < e; i++) tab_vertex(j->c, j->list ? j->list[i] : i, ps);
}

/* The tables, allocated once per level (0: out of memory, no tables: the rules run). The face
 * and edge weights come from the crease-aware look-ups, so they hold on creased meshes too (the
 * sharp edges' own rule still runs); the vertex weights are the smooth rule's, on a creased
 * mesh for the interior vertices whose sharpness gives the smooth (or dart) rule (tvs), the
 * same arithmetic as creased_vertex_point's. */
static int tab_alloc(ccn__level *c) {
    const ccn_mesh *m = c->m;
    if (c->tab_tried) return c->tf != NULL;
    c->tab_tried = 1;
    c->tf = malloc(sizeof(double) * 2 * (size_t)(m->nf ? m->nf : 1));
    c->te = malloc(sizeof(double) * 3 * (size_t)(m->ne ? m->ne : 1));
    c->tv = malloc(sizeof(double) * 2 * (size_t)(m->nv ? m->nv : 1));
    c->th = malloc(sizeof(double) * 2 * (size_t)(m->nh ? m->nh : 1));
    c->tmask = calloc((size_t)m->nf + m->ne + m->nv + 1, 1);
    if (m->esharp) c->tvs = calloc((size_t)(m->nv ? m->nv : 1), 1);
    if (!c->tf || !c->te || !c->tv || !c->th || !c->tmask || (m->esharp && !c->tvs)) {
        free(c->tf); free(c->te); free(c->tv); free(c->th); free(c->tvs); free(c->tmask);
        c->tf = c->te = c->tv = c->th = NULL;
        c->tvs = c->tmask = NULL;
        return 0;
    }
    return 1;
}

/* Every element's weights, once per level (the first ccn__level_points). */
static void tabulate(ccn__level *c) {
    const ccn_mesh *m = c->m;
    if (!tab_alloc(c) || c->tab_full) return;
    tab_job j = {c, NULL};
    ccn__parallel_for(c->threads, m->nf, tab_face_range, &j);
    ccn__parallel_for(c->threads, m->ne, tab_edge_range, &j);
    ccn__parallel_for(c->threads, m->nv, tab_vertex_range, &j);
    c->tab_full = 1;
}

/* a plan made with options.previous: the weights of q, a level of the same topology (an earlier plan's), for
 * every element whose weights read no interval that changed; the first ccn__level_points
 * tabulates the others. An element's rule reads intervals of edges at its vertices only (the
 * face's sides and the transverse ones beyond them, the edge's neighbours along its curve, the
 * vertex's fan: rules/bspline.c, rules/nurss.c), so it is kept where none of its vertices ends
 * a changed edge (compared in the caller's units, eknot * knot_scale). The normalisation may
 * differ (m's intervals are q's times r, a power of two: topology/knots.c): the weights that
 * are intervals (te's transverse ones) scale with r, the NURSS fan weights (products of two
 * sums of intervals) with r^2 and their normaliser with 1/r^2, exactly; the others are
 * ratios, the same to the bit. */
void ccn__level_tabulate_like(ccn__level *c, const ccn__level *q) {
    const ccn_mesh *m = c->m, *qm = q->m;
    if (!q->tab_full || !q->tf || c->tab_full || !qm || qm->nv != m->nv || qm->nf != m->nf ||
        qm->ne != m->ne || qm->nh != m->nh || !m->esharp != !qm->esharp || !q->tvs != !m->esharp)
        return;
    uint8_t *ends = ccn__changed_interval_ends(m, qm);
    if (!ends || !tab_alloc(c)) { free(ends); return; }
    double r = qm->knot_scale / m->knot_scale;
    uint8_t *fm = c->tmask, *em = fm + m->nf, *vm = em + m->ne;
    const uint8_t *qf = q->tmask, *qe = qf + m->nf, *qv = qe + m->ne;
    for (int32_t f = 0; f < m->nf; f++) {
        int keep = qf[f];
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1] && keep; h++) keep = !ends[m->hvert[h]];
        if (!keep) continue;
        c->tf[2 * (size_t)f] = q->tf[2 * (size_t)f];
        c->tf[2 * (size_t)f + 1] = q->tf[2 * (size_t)f + 1];
        fm[f] = 1;
    }
    for (int32_t e = 0; e < m->ne; e++) {
        if (!qe[e] || ends[m->everts[2 * e]] || ends[m->everts[2 * e + 1]]) continue;
        const double *a = q->te + 3 * (size_t)e;
        double *o = c->te + 3 * (size_t)e;
        o[0] = a[0]; o[1] = a[1] * r; o[2] = a[2] * r;
        em[e] = 1;
    }
    for (int32_t v = 0; v < m->nv; v++) {
        if (!qv[v] || ends[v]) continue;
        vm[v] = 1;
        if (m->vfan_start[v + 1] == m->vfan_start[v] || m->vboundary[v]) continue; /* no weights */
        if (c->tvs) {
            c->tvs[v] = q->tvs[v];
            if (!q->tvs[v]) continue;
        }
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
            c->th[2 * (size_t)k] = q->th[2 * (size_t)k] * r * r;
            c->th[2 * (size_t)k + 1] = q->th[2 * (size_t)k + 1] * r * r;
        }
        c->tv[2 * (size_t)v] = q->tv[2 * (size_t)v];
        c->tv[2 * (size_t)v + 1] = q->tv[2 * (size_t)v + 1] / (r * r);
    }
    free(ends);
}

/* Only the listed elements' weights (ccn__level_points_lists: the face-varying probes compute a
 * part of each level, the same part every pass). */
static void tabulate_lists(ccn__level *c, const int32_t *faces, int32_t nfaces, const int32_t *edges,
                           int32_t nedges, const int32_t *verts, int32_t nverts) {
    if (!tab_alloc(c) || c->tab_full) return;
    tab_job j = {c, faces};
    ccn__parallel_for(c->threads, nfaces, tab_face_range, &j);
    j.list = edges;
    ccn__parallel_for(c->threads, nedges, tab_edge_range, &j);
    j.list = verts;
    ccn__parallel_for(c->threads, nverts, tab_vertex_range, &j);
}

/* The weights of the points ccn__level_points_subset computes around the listed vertices,
 * once (the same list every call). */
void ccn__level_tabulate_subset(ccn__level *c, const int32_t *verts, int32_t nverts) {
    const ccn_mesh *m = c->m;
    if (c->tab_sub || !tab_alloc(c)) return;
    float ps[CREASE_STACK];
    for (int32_t i = 0; i < nverts; i++) {
        int32_t v = verts[i], n = ccn__valence(m, v);
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) tab_face(c, m->hface[m->vfan[k]]);
        for (int32_t k = 0; k < n; k++) tab_edge(c, ccn__fan_edge(m, v, k));
        tab_vertex(c, v, ps);
    }
    c->tab_sub = 1;
}

static void vertex_range(void *ctx, int32_t b, int32_t e) {
    const points_job *j = ctx;
    for (int32_t v = b; v < e; v++) one_vertex_point(j->c, v, j->fp, j->vp);
}

/* ---- red points: the eigen matrix M at each EV ------------------------------------ */

static ccn_status build_ev_matrices(ccn__level *c, ccn_error *err) {
    const ccn_mesh *m = c->m;
    size_t total = 0;
    int32_t maxn = 0;
    for (int32_t i = 0; i < c->nev; i++) {
        int32_t n = ccn__valence(m, c->ev_list[i]);
        c->Moff[i] = total;
        total += (size_t)(2 * n + 1) * (size_t)(2 * n + 1);
        if (n > maxn) maxn = n;
    }
    c->M = malloc(sizeof(double) * (total ? total : 1));
    double *d = malloc(sizeof(double) * (size_t)(maxn ? maxn : 1));
    if (!c->M || !d) {
        free(d);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (EV matrices)");
    }
    for (int32_t i = 0; i < c->nev; i++) {
        int32_t v = c->ev_list[i], n = ccn__valence(m, v);
        for (int32_t k = 0; k < n; k++) d[k] = m->eknot[ccn__fan_edge(m, v, k)];
        ccn_ev_info info;
        ccn_status st = ccn__ev_matrix_cached(n, d, CCN_SCHEME_EIGEN, c->ev_poly, c->ev_cache,
                                              c->M + c->Moff[i], &info, NULL);
        if (st) {
            free(d);
            return ccn__fail(err, st, CCN_ELEM_VERTEX, v,
                             "extraordinary vertex %d: refinement matrix failed", (int)v);
        }
        c->fallbacks += info.fallback != 0;
        c->ev_verified += info.verified > 0;
        c->ev_outside += info.outside_g1 != 0;
    }
    free(d);
    return CCN_OK;
}

/* Index of 1-ring point j (F_0..F_{n-1}, E_0..E_{n-1}, V) of EV v in the old mesh. */
static int32_t ring_point(const ccn_mesh *m, int32_t v, int32_t n, int32_t j) {
    if (j == 2 * n) return v;
    int32_t h = m->vfan[m->vfan_start[v] + (j % n)];
    int32_t nh = ccn__next(m, h);
    return j < n ? m->hvert[ccn__next(m, nh)] : m->hvert[nh];
}

/* The point the NURSS step gives red row r of EV v (kind which), table-free and from the
 * current face points: what a level-0 EV with ev_w < 1 blends M's point with. Computed here
 * rather than taken from the pass that ran before, because a partial pass (the lists of an
 * interval edit, the subset) need not have made it; the spokes' curve points are made in H
 * and H is restored, so the rest of the level reads what its own pass wrote. */
static void nurss_step_point(const ccn__level *c, int32_t v, int32_t n, int which, int32_t r,
                             const double *fp, double g[3]) {
    const ccn_mesh *m = c->m;
    int32_t h = m->vfan[m->vfan_start[v] + (r % n)];
    if (which == 0) {
        ccn__quad_face_point(m, m->hface[h], c->pinned, g);
        return;
    }
    double stack[3 * 64], *keep = n <= 64 ? stack : malloc(sizeof(double) * 3 * (size_t)n);
    int32_t saved = keep ? n : 0; /* (out of memory: H keeps the NURSS step's curve points) */
    for (int32_t k = 0; k < saved; k++) {
        int32_t e = ccn__fan_edge(m, v, k);
        memcpy(keep + 3 * k, c->H + 3 * (size_t)e, sizeof(double) * 3);
    }
    for (int32_t k = 0; k < n; k++) {
        int32_t e = ccn__fan_edge(m, v, k);
        ccn__curve_edge_point(m, c->erep[e], c->pinned, c->H + 3 * (size_t)e);
    }
    if (which == 1) {
        int32_t e = m->hedge[h];
        ccn__edge_point(m, c->erep[e], c->H, fp, g);
    } else {
        ccn__nurss_vertex_point(m, v, c->H, fp, g);
    }
    for (int32_t k = 0; k < saved; k++) {
        int32_t e = ccn__fan_edge(m, v, k);
        memcpy(c->H + 3 * (size_t)e, keep + 3 * k, sizeof(double) * 3);
    }
    if (keep != stack) free(keep);
}

/* Overwrites the red points of kind `which` (0 faces, 1 spokes, 2 vertex). */
static void apply_red(const ccn__level *c, int which, double *fp, double *ep, double *vp) {
    const ccn_mesh *m = c->m;
    for (int32_t i = 0; i < c->nev; i++) {
        int32_t v = c->ev_list[i], n = ccn__valence(m, v), sz = 2 * n + 1;
        const double *M = c->M + c->Moff[i];
        int32_t r0 = which == 0 ? 0 : which == 1 ? n : 2 * n, r1 = which == 2 ? sz : r0 + n;
        for (int32_t r = r0; r < r1; r++) {
            double acc[3] = {0, 0, 0};
            for (int32_t j = 0; j < sz; j++) {
                const double *p = m->pos + 3 * (size_t)ring_point(m, v, n, j);
                double w = M[(size_t)r * sz + j];
                acc[0] += w * p[0]; acc[1] += w * p[1]; acc[2] += w * p[2];
            }
            int32_t h = m->vfan[m->vfan_start[v] + (r % n)];
            double *out = which == 0 ? fp + 3 * (size_t)m->hface[h]
                        : which == 1 ? ep + 3 * (size_t)m->hedge[h]
                                     : vp + 3 * (size_t)v;
            double w = c->ev_w[i];
            if (w < 1) { /* blended with the NURSS step's point */
                double g[3];
                nurss_step_point(c, v, n, which, r, fp, g);
                for (int k = 0; k < 3; k++) acc[k] = w * acc[k] + (1 - w) * g[k];
            }
            memcpy(out, acc, sizeof acc);
        }
    }
}

/* ---- one level ---------------------------------------------------------------------- */

static int regular_interior(const ccn_mesh *m, int32_t v) {
    return !m->vboundary[v] && ccn__valence(m, v) == 4;
}

/* Level 0: may EV v take M already (Li 2016 §6.1), instead of the NURSS step that exists to
 * split non-quads, separate EVs and make e_i = d_i? Only when all of that already holds: every
 * face of v is a quad, every other corner of those faces is an interior valence-4 vertex (so no
 * other EV or n-gon shares a face with v), and each spoke continues beyond its end E_i with the
 * spoke's own interval (e_i = d_i, Fig. 3/5 — what M assumes). See README "Design notes".
 * Returns the weight of M against the NURSS step: 1 when e_i = d_i, falling smoothly to 0 as
 * max_i |log(e_i / d_i)| grows to CCN__LEVEL0_BAND (so the surface does not jump when an
 * interval beyond a spoke moves off the spoke's own), 0 when the topology is not ready. */
static double ev_ready_at_level0(const ccn_mesh *m, int32_t v) {
    double mismatch = 0;
    if (m->esharp) /* no crease anywhere on v's faces */
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
            int32_t f = m->hface[m->vfan[k]];
            for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++)
                if (ccn__sharp_count(m, m->hvert[h]) > 0 || m->vsharp[m->hvert[h]] > 0.0f) return 0;
        }
    for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
        int32_t h = m->vfan[k];
        if (ccn__fsize(m, m->hface[h]) != 4) return 0;
        int32_t h1 = ccn__next(m, h), h2 = ccn__next(m, h1), h3 = ccn__next(m, h2);
        if (!regular_interior(m, m->hvert[h1]) || !regular_interior(m, m->hvert[h2]) ||
            !regular_interior(m, m->hvert[h3]))
            return 0;
        int32_t t = m->htwin[h]; /* E_i -> v: the edge beyond E_i is opposite in E_i's fan */
        int32_t e = m->vfan_start[m->hvert[t]];
        int32_t beyond = m->hedge[m->vfan[e + (m->hfanpos[t] + 2) % 4]];
        mismatch = fmax(mismatch, fabs(log(m->eknot[m->hedge[h]] / m->eknot[beyond])));
    }
    double x = 1 - mismatch / CCN__LEVEL0_BAND;
    return x <= 0 ? 0 : x >= 1 ? 1 : x * x * (3 - 2 * x);
}

static ccn_status collect_evs(ccn__level *c, ccn_error *err) {
    const ccn_mesh *m = c->m;
    c->nev = 0;
    if (!c->red) return CCN_OK;
    for (int32_t v = 0; v < m->nv; v++) {
        if (!ccn__is_ev(m, v) || ccn__valence(m, v) < 3) continue; /* valence 2: NURSS / CC rules */
        if (m->esharp && (ccn__sharp_count(m, v) > 0 || m->vsharp[v] > 0.0f)) continue; /* creased */
        double w = m->info.level == 0 ? ev_ready_at_level0(m, v) : 1.0;
        if (!(w > 0)) continue; /* NURSS step */
        if (ccn__valence(m, v) > CCN_EV_MATRIX_MAX_VALENCE) { c->fallbacks++; c->nbig++; continue; }
        c->ev_w[c->nev] = w;
        c->ev_list[c->nev++] = v;
    }
    return build_ev_matrices(c, err);
}

void ccn__level_free(ccn__level *c) {
    if (!c) return;
    free(c->tf); free(c->te); free(c->tv); free(c->th); free(c->tvs); free(c->tmask);
    free(c->H); free(c->erep); free(c->ev_list); free(c->ev_w); free(c->Moff); free(c->M);
    memset(c, 0, sizeof *c);
}

ccn_status ccn__level_prepare(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                              int crease_method, ccn_error *err) {
    return ccn__level_prepare_ev(c, m, scheme, pinned, crease_method, CCN_POLY_SELECT, NULL, err);
}

ccn_status ccn__level_prepare_ev(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                                 int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                                 ccn_error *err) {
    return ccn__level_prepare_like(c, m, scheme, pinned, crease_method, ev_poly, cache, NULL, err);
}

ccn_status ccn__level_prepare_like(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                                   int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                                   ccn__level *like, ccn_error *err) {
    memset(c, 0, sizeof *c);
    c->ev_poly = ev_poly;
    c->ev_cache = cache;
    c->m = m;
    c->pinned = pinned;
    c->crease_method = crease_method;
    c->red = scheme == CCN_SCHEME_EIGEN;
    c->threads = 1;
    c->H = malloc(sizeof(double) * 3 * (size_t)(m->ne ? m->ne : 1));
    c->erep = malloc(sizeof(int32_t) * (size_t)(m->ne ? m->ne : 1));
    c->ev_list = malloc(sizeof(int32_t) * (size_t)(m->nv ? m->nv : 1));
    c->ev_w = malloc(sizeof(double) * (size_t)(m->nv ? m->nv : 1));
    c->Moff = malloc(sizeof(size_t) * (size_t)(m->nv ? m->nv : 1));
    if (!c->H || !c->erep || !c->ev_list || !c->ev_w || !c->Moff) {
        ccn__level_free(c);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (refinement)");
    }
    if (like && (!like->m || like->m->nv != m->nv || like->m->ne != m->ne || like->m->nh != m->nh ||
                 like->red != c->red || !like->erep))
        like = NULL;
    if (like) { /* the same topology: the same representatives */
        free(c->erep);
        c->erep = like->erep;
        like->erep = NULL;
    } else {
        for (int32_t e = 0; e < m->ne; e++) c->erep[e] = -1;
        for (int32_t h = m->nh - 1; h >= 0; h--) c->erep[m->hedge[h]] = h;
    }
    ccn_status st;
    if (like && c->red && m->info.level >= 1) { /* EVs from level 1 on: topology and sharpness */
        memcpy(c->ev_list, like->ev_list, sizeof(int32_t) * (size_t)like->nev);
        memcpy(c->ev_w, like->ev_w, sizeof(double) * (size_t)like->nev);
        c->nev = like->nev;
        c->fallbacks = c->nbig = like->nbig;
        st = build_ev_matrices(c, err);
    } else {
        st = collect_evs(c, err);
    }
    if (st) ccn__level_free(c);
    return st;
}

void ccn__level_points(ccn__level *c, double *out) {
    const ccn_mesh *m = c->m;
    tabulate(c);
    double *fp = out, *ep = out + 3 * (size_t)m->nf, *vp = out + 3 * ((size_t)m->nf + m->ne);
    points_job j = {c, fp, ep, vp};
    ccn__parallel_for(c->threads, m->nf, face_range, &j);
    apply_red(c, 0, fp, ep, vp);
    ccn__parallel_for(c->threads, m->ne, edge_range, &j);
    apply_red(c, 1, fp, ep, vp);
    ccn__parallel_for(c->threads, m->nv, vertex_range, &j);
    apply_red(c, 2, fp, ep, vp);
}

/* The listed points only (face-varying probes, surface/fvar_compose.c). */
typedef struct { const ccn__level *c; double *fp, *ep, *vp; const int32_t *list; } list_job;

static void face_list_range(void *ctx, int32_t b, int32_t e) {
    const list_job *j = ctx;
    for (int32_t i = b; i < e; i++) one_face_point(j->c, j->list[i], j->fp);
}

static void edge_list_range(void *ctx, int32_t b, int32_t e) {
    const list_job *j = ctx;
    for (int32_t i = b; i < e; i++) one_edge_point(j->c, j->list[i], j->fp, j->ep + 3 * (size_t)j->list[i]);
}

static void vertex_list_range(void *ctx, int32_t b, int32_t e) {
    const list_job *j = ctx;
    for (int32_t i = b; i < e; i++) one_vertex_point(j->c, j->list[i], j->fp, j->vp);
}

void ccn__level_points_lists(ccn__level *c, const int32_t *faces, int32_t nfaces,
                             const int32_t *edges, int32_t nedges, const int32_t *verts,
                             int32_t nverts, double *out) {
    const ccn_mesh *m = c->m;
    tabulate_lists(c, faces, nfaces, edges, nedges, verts, nverts);
    double *fp = out, *ep = out + 3 * (size_t)m->nf, *vp = out + 3 * ((size_t)m->nf + m->ne);
    list_job j = {c, fp, ep, vp, faces};
    ccn__parallel_for(c->threads, nfaces, face_list_range, &j);
    apply_red(c, 0, fp, ep, vp);
    j.list = edges;
    ccn__parallel_for(c->threads, nedges, edge_list_range, &j);
    apply_red(c, 1, fp, ep, vp);
    j.list = verts;
    ccn__parallel_for(c->threads, nverts, vertex_list_range, &j);
    apply_red(c, 2, fp, ep, vp);
}

/* Only the points around the listed vertices: their vertex points, the edge points of
 * their edges and the face points of their faces (plus every EV's red points). */
void ccn__level_points_subset(const ccn__level *c, const int32_t *verts, int32_t nverts,
                              double *out) {
    const ccn_mesh *m = c->m;
    double *fp = out, *ep = out + 3 * (size_t)m->nf, *vp = out + 3 * ((size_t)m->nf + m->ne);
    for (int32_t i = 0; i < nverts; i++) {
        int32_t v = verts[i];
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++)
            one_face_point(c, m->hface[m->vfan[k]], fp);
    }
    apply_red(c, 0, fp, ep, vp);
    for (int32_t i = 0; i < nverts; i++) {
        int32_t v = verts[i], n = ccn__valence(m, v);
        for (int32_t k = 0; k < n; k++) {
            int32_t e = ccn__fan_edge(m, v, k);
            one_edge_point(c, e, fp, ep + 3 * (size_t)e);
        }
    }
    apply_red(c, 1, fp, ep, vp);
    for (int32_t i = 0; i < nverts; i++) one_vertex_point(c, verts[i], fp, vp);
    apply_red(c, 2, fp, ep, vp);
}

/* Sharpness of the refined mesh: each half of an edge decays at its end vertex (uniform or
 * Chaikin), the edges inside faces are smooth, a vertex point's sharpness decays; dropped
 * again when nothing sharp is left. */
static ccn_status child_sharpness(const ccn__level *c, ccn_mesh *r, ccn_error *err) {
    const ccn_mesh *m = c->m;
    if (!m->esharp) return CCN_OK;
    if (ccn__mesh_alloc_sharpness(r))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (creases)");
    for (int32_t e = 0; e < m->ne; e++) {
        r->esharp[2 * e] = ccn__child_edge_sharpness(m, c->crease_method, e, m->everts[2 * e]);
        r->esharp[2 * e + 1] = ccn__child_edge_sharpness(m, c->crease_method, e, m->everts[2 * e + 1]);
    }
    for (int32_t v = 0; v < m->nv; v++) r->vsharp[m->nf + m->ne + v] = ccn__sharp_decrement(m->vsharp[v]);
    ccn__mesh_drop_smooth_sharpness(r);
    return CCN_OK;
}

ccn_status ccn__level_topology(const ccn__level *c, ccn_mesh **out, ccn_error *err) {
    return ccn__level_topology_like(c, NULL, out, err);
}

ccn_status ccn__level_topology_like(const ccn__level *c, ccn_mesh *like, ccn_mesh **out,
                                    ccn_error *err) {
    const ccn_mesh *m = c->m;
    int64_t nv2 = (int64_t)m->nf + m->ne + m->nv, nh2 = 4 * (int64_t)m->nh;
    int64_t ne2 = 2 * (int64_t)m->ne + m->nh;
    *out = NULL;
    if (like && (like->nv != nv2 || like->nf != m->nh || like->nh != nh2 || like->ne != ne2 ||
                 !like->fstart))
        like = NULL; /* not this level's child (or given up already): build it */
    if (nh2 > INT32_MAX / 8 || nv2 > INT32_MAX / 8 || ne2 > INT32_MAX / 8)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                         "refined mesh would have %lld face corners: too large", (long long)nh2);
    ccn_mesh *r = ccn__mesh_alloc((int32_t)nv2, m->nh, (int32_t)nh2, (int32_t)ne2);
    double *cand = malloc(sizeof(double) * (size_t)ne2);
    ccn_status st = CCN_OK;
    if (!r || !cand) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                       "out of memory for a refined mesh of %lld face corners", (long long)nh2);
        goto done;
    }
    if (like) { /* the same parent topology: the same child topology, moved over */
#define CCN_TAKE(f) do { free(r->f); r->f = like->f; like->f = NULL; } while (0)
        CCN_TAKE(fstart); CCN_TAKE(hvert); CCN_TAKE(htwin); CCN_TAKE(hedge); CCN_TAKE(hface);
        CCN_TAKE(everts); CCN_TAKE(vfan_start); CCN_TAKE(vfan); CCN_TAKE(hfanpos);
        CCN_TAKE(vlast_edge); CCN_TAKE(vboundary);
#undef CCN_TAKE
    } else {
        ccn__children_topology(m, r, c->threads);
        if (ccn__mesh_build_fans(r)) {
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "refined topology is invalid");
            goto done;
        }
    }
    if (ccn__mesh_weld_child(m, r)) { /* a split cage: its copies' children (topology/mesh.c) */
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (weld)");
        goto done;
    }
    ccn__children_candidates(m, cand);
    if ((st = ccn__children_intervals(m, r, cand, err))) goto done;
    if ((st = child_sharpness(c, r, err))) goto done;
    if (like) { /* the counts of the same topology and sharpness; the rings' are new */
        ccn_mesh_info in = like->info;
        in.num_rings = r->info.num_rings;
        r->info = in;
    } else {
        ccn__mesh_update_info(r);
    }
    r->info.num_ring_conflicts = m->info.num_ring_conflicts;
    r->info.num_ignored_edges = m->info.num_ignored_edges;
    r->info.num_ev_fallbacks = m->info.num_ev_fallbacks + c->fallbacks;
    r->info.level = m->info.level + 1;
    *out = r;
    r = NULL;
done:
    free(cand);
    ccn_mesh_destroy(r);
    return st;
}
