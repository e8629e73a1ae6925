/* Holes of the plan's patch set, closed watertight (io/fill.h; EXPORT_DESIGN.md section 7).
 *
 * A hole is a face the plan has no patch for: its net contains an irregular vertex whose
 * limit is no polynomial (a cap fallback EV, a smooth valence-2 corner, a boundary EV; on
 * creased cages a dart, a crease or corner vertex whose sector is not the boundary-like one,
 * a cone point, a vertex with semi-sharp values still decaying).
 * Around the holes the mesh is refined level by level, locally: each level, the faces still
 * to refine plus three rings of margin are cut out of the current mesh (ccn_mesh_create, the
 * level number set so the same rules apply), refined once (refine/level.h), and of the
 * children of the faces being refined the strict ones (16 regular net vertices: the
 * subdivision limit itself, forever) are exported as exact bicubic pieces (packed: one
 * B-spline face per 2x2 block and so on), the others are refined further. The cut mesh's
 * own boundary is wrong after refinement, but only within one ring of it, which the
 * three-ring margin keeps away (the wrong band grows by one ring of each finer level, less
 * than one ring of the first level in all).
 *
 * Creases: the cut meshes carry the level's edge and vertex sharpness, the refinement the
 * plan's crease method. Strictness is the crease-aware one (surface/patches.c: a face beside an
 * infinitely sharp crease is strict when the crease is a B-spline boundary of its side), so
 * exact pieces reach the crease curves and packs stop there. While a semi-sharp value is left
 * its vertices are irregular: the fills come o->levels levels below the level where the last
 * one decayed (at most ceil(s) levels below the cage).
 *
 * After the last level, what is left are the 2x2 faces per fan face around each irregular
 * vertex, closed by fill faces (io/fill_faces.c); irregular vertices still too close for the
 * fills' blocks go one level deeper.
 */
#include "io/fill.h"

#include "io/fill_faces.h"
#include "io/fill_g1.h"
#include "io/packs.h"

#include "base/error.h"
#include "refine/level.h"
#include "rules/crease.h"
#include "bi5/bi5.h"
#include "surface/caps.h"
#include "surface/curvature.h"
#include "surface/limit.h"
#include "surface/patches.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


/* ---- cutting a local mesh ------------------------------------------------------------ */

/* Marks the faces within `rings` vertex-rings of the marked ones, then closes the selection so
 * that every vertex's selected faces form one fan (no non-manifold vertex in the cut). */
static void grow(const ccn_mesh *m, uint8_t *sel, int rings, uint8_t *vmark) {
    for (int r = 0; r < rings; r++) {
        memset(vmark, 0, (size_t)m->nv);
        for (int32_t f = 0; f < m->nf; f++)
            if (sel[f])
                for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) vmark[m->hvert[h]] = 1;
        for (int32_t v = 0; v < m->nv; v++)
            if (vmark[v])
                for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) sel[m->hface[m->vfan[k]]] = 1;
    }
    for (int changed = 1; changed;) {
        changed = 0;
        for (int32_t v = 0; v < m->nv; v++) {
            int32_t k0 = m->vfan_start[v], k1 = m->vfan_start[v + 1], runs = 0, any = 0;
            for (int32_t k = k0; k < k1; k++) {
                int s = sel[m->hface[m->vfan[k]]];
                int prev = k > k0 ? sel[m->hface[m->vfan[k - 1]]] : (m->vboundary[v] ? 0 : sel[m->hface[m->vfan[k1 - 1]]]);
                any |= s;
                runs += s && !prev;
            }
            if (any && (runs > 1 || (runs == 0 && any))) {
                for (int32_t k = k0; k < k1; k++)
                    if (!sel[m->hface[m->vfan[k]]]) { sel[m->hface[m->vfan[k]]] = 1; changed = 1; }
            }
        }
    }
}

/* The selected faces of m as a mesh of their own (faces in m's order, same corner order);
 * face_map[f] = its face in m. */
static ccn_status cut(const ccn_mesh *m, const uint8_t *sel, int32_t level, ccn_mesh **out,
                      int32_t **face_map, ccn_error *err) {
    int32_t nf = 0, nc = 0, nv = 0;
    int32_t *vmap = malloc(sizeof(int32_t) * (size_t)m->nv);
    int32_t *emark = malloc(sizeof(int32_t) * (size_t)m->ne);
    if (!vmap || !emark) { free(vmap); free(emark); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); }
    for (int32_t v = 0; v < m->nv; v++) vmap[v] = -1;
    for (int32_t e = 0; e < m->ne; e++) emark[e] = 0;
    int32_t ne = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        if (!sel[f]) continue;
        nf++;
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
            nc++;
            if (vmap[m->hvert[h]] < 0) vmap[m->hvert[h]] = nv++;
            if (!emark[m->hedge[h]]) { emark[m->hedge[h]] = 1; ne++; }
        }
    }
    double *pos = malloc(sizeof(double) * 3 * (size_t)(nv ? nv : 1));
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)(nf ? nf : 1)), *fv = malloc(sizeof(int32_t) * (size_t)(nc ? nc : 1));
    int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)(ne ? ne : 1));
    double *ek = malloc(sizeof(double) * (size_t)(ne ? ne : 1));
    double *es = m->esharp ? malloc(sizeof(double) * (size_t)(ne ? ne : 1)) : NULL;
    double *vs = m->vsharp ? malloc(sizeof(double) * (size_t)(nv ? nv : 1)) : NULL;
    int32_t *fm = malloc(sizeof(int32_t) * (size_t)(nf ? nf : 1));
    ccn_status st = CCN_OK;
    if (!pos || !fs || !fv || !ev || !ek || !fm || (m->esharp && !es) || (m->vsharp && !vs)) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
        goto done;
    }
    for (int32_t v = 0; v < m->nv; v++)
        if (vmap[v] >= 0) {
            memcpy(pos + 3 * (size_t)vmap[v], m->pos + 3 * (size_t)v, sizeof(double) * 3);
            if (vs) vs[vmap[v]] = m->vsharp[v];
        }
    int32_t fi = 0, ci = 0, ei = 0;
    for (int32_t e = 0; e < m->ne; e++) emark[e] = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        if (!sel[f]) continue;
        fm[fi] = f;
        fs[fi++] = ccn__fsize(m, f);
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
            fv[ci++] = vmap[m->hvert[h]];
            int32_t e = m->hedge[h];
            if (emark[e]) continue;
            emark[e] = 1;
            ev[2 * ei] = vmap[m->everts[2 * e]];
            ev[2 * ei + 1] = vmap[m->everts[2 * e + 1]];
            if (es) es[ei] = m->esharp[e];
            ek[ei++] = m->eknot[e];
        }
    }
    /* the creases of this level (already decayed; float -> double -> float is exact) */
    ccn_cage c = {nv, nf, ne, pos, fs, fv, ev, ek, es, vs};
    ccn_mesh *sm = NULL;
    if ((st = ccn_mesh_create(&c, &sm, err))) goto done;
    sm->info.level = level; /* the rules of that level (level 0 differs at EVs) */
    *out = sm;
    *face_map = fm;
    fm = NULL;
done:
    free(vmap); free(emark); free(pos); free(fs); free(fv); free(ev); free(ek); free(es); free(vs); free(fm);
    return st;
}

/* A smooth valence-2 vertex (two edges: an interior one between two faces, or an open corner
 * of one face), none of its edges or itself sharp. Its two sectors open to a half-plane in the
 * limit, so the exact pieces next to it grow skewed with every level and their normals (and the
 * fills' near their degenerate corners) magnify the rounding of their poles about fourfold per
 * level: its fills come CCN_FILL_LEVELS_V2 levels earlier (fill.h). */
static int smooth_valence2(const ccn_mesh *m, int32_t w) {
    if (ccn__valence(m, w) != 2 || (m->vsharp && m->vsharp[w] > 0)) return 0;
    for (int32_t k = 0; k < 2; k++) {
        int32_t e = ccn__fan_edge(m, w, k);
        if (e < 0 || ccn__edge_sharp(m, e)) return 0;
    }
    return 1;
}

/* ---- faces -------------------------------------------------------------------------- */

static void to_caller(const ccn__plan_view *v, double *p, int32_t n) {
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) p[3 * i + k] = v->centre[k] + v->scale * p[3 * i + k];
}

typedef struct { const ccn__xplace *pl; } tplace;

static void place_tab(void *ctx, int32_t face, ccn__xplace *out) {
    *out = ((const tplace *)ctx)->pl[face];
}

/* Is a semi-sharp value (still decaying) left on m? Then no fill yet: the vertices along it
 * are irregular, and they become smooth within ceil(s) levels. */
static int semi_sharp(const ccn_mesh *m) {
    for (int32_t e = 0; m->esharp && e < m->ne; e++)
        if (m->esharp[e] > 0.0f && m->esharp[e] < CCN_SHARP_INF) return 1;
    for (int32_t v = 0; m->vsharp && v < m->nv; v++)
        if (m->vsharp[v] > 0.0f && m->vsharp[v] < CCN_SHARP_INF) return 1;
    return 0;
}

#define CCN_FILL_MAX_LEVEL 16 /* deepest level a fill goes to when its vertices are close */

/* ---- caps ---------------------------------------------------------------------------- */

/* The coarsest level of a cap over a hole (cap_vertex): the export equals the limit of every
 * plan of this output level or below (Levels 4 shows the same surface; deeper Levels show the
 * refined limit inside the cap's faces, where it pinches at the EV). */
#define CCN_FILL_CAP_LEVEL 4
/* At the last level a smooth interior EV whose spokes leave the cap's kappa range gets the
 * non-uniform cap unless the fill faces over the same hole are fairer (both G1 exact: their
 * largest |K| below CCN_FILL_CAP_PREFER times the cap's, so that near ties decide alike on
 * every platform), or unless the cap's largest |K| exceeds this many times theirs where the
 * fill is G1 only approximately (io/fill_g1.c found no exact form: G1 exactness is worth that
 * much curvature). */
#define CCN_FILL_CAP_K_RATIO 2.0

/* The irregular vertex w of T (the refinement of the cut S) as a vertex of S: T numbers face
 * points, edge points, then vertex points (refine/level.h); -1 if w is not a vertex point. */
static int32_t parent_vertex(const ccn_mesh *S, int32_t w) {
    int32_t v = w - S->nf - S->ne;
    return v >= 0 && v < S->nv ? v : -1;
}

/* The largest |Gaussian curvature| of faces [f0, f1) of xm, sampled on a 17 x 17 grid of each
 * to 0.005 of its sides (exact first derivatives, second ones by their central differences over
 * 1e-4 of the span; the principal curvatures of surface/curvature.h). Caps and fills put their
 * largest |K| next to a side (a saddle spot by the cap's centre, the fill's vertex): a 9 x 9
 * grid to 0.01 of the sides chose the less fair closure on 2 of 42 random stars. */
static double faces_max_k(const ccn__xmodel *xm, int32_t f0, int32_t f1) {
    double kmax = 0;
    for (int32_t f = f0; f < f1; f++) {
        const ccn__cad_surface *s = &xm->faces[f].s;
        double u0, u1, v0, v1;
        ccn__cad_domain(s, 0, &u0, &u1);
        ccn__cad_domain(s, 1, &v0, &v1);
        double hu = 1e-4 * (u1 - u0), hv = 1e-4 * (v1 - v0);
        for (int a = 0; a <= 16; a++)
            for (int b = 0; b <= 16; b++) {
                double u = u0 + (u1 - u0) * (0.005 + 0.99 * a / 16), v = v0 + (v1 - v0) * (0.005 + 0.99 * b / 16);
                /* d: S_u, S_v, S_uu, S_uv, S_vv; first derivatives at (u +- hu, v), (u, v +- hv) */
                double d[5][3], p[3], au[3], av[3], bu[3], bv[3], cu[3], cv[3], eu[3], ev[3], k1, k2;
                ccn__cad_eval_d(s, u, v, p, d[0], d[1]);
                ccn__cad_eval_d(s, u + hu, v, p, au, av);
                ccn__cad_eval_d(s, u - hu, v, p, bu, bv);
                ccn__cad_eval_d(s, u, v + hv, p, cu, cv);
                ccn__cad_eval_d(s, u, v - hv, p, eu, ev);
                for (int c = 0; c < 3; c++) {
                    d[2][c] = (au[c] - bu[c]) / (2 * hu);
                    d[3][c] = (cu[c] - eu[c]) / (2 * hv);
                    d[4][c] = (cv[c] - ev[c]) / (2 * hv);
                }
                ccn__principal_curvatures((const double(*)[3])d, &k1, &k2, NULL);
                double K = fabs(k1 * k2);
                if (isfinite(K) && K > kmax) kmax = K;
            }
    }
    return kmax;
}

/* Drops the faces and cells added after (nf0, nc0). */
static void xm_rollback(ccn__xmodel *xm, int32_t nf0, int32_t nc0) {
    for (int32_t f = nf0; f < xm->num_faces; f++) ccn__xm_free_surface(&xm->faces[f].s);
    xm->num_faces = nf0;
    xm->num_cells = nc0;
}

/* The faces, cells and fill count before a level's fills, to undo them (fill_undo). */
typedef struct {
    int32_t nf, nc, nfill;
} fill_mark;

static fill_mark fill_mark_of(const ccn__xmodel *xm, const ccn__fill_opts *o) {
    fill_mark k = {xm->num_faces, xm->num_cells, o->num_fills};
    return k;
}

static void fill_undo(ccn__xmodel *xm, ccn__fill_opts *o, fill_mark k) {
    xm_rollback(xm, k.nf, k.nc);
    o->num_fills = k.nfill;
}

/* Fill faces around each irregular vertex of T's faces reg[0..nreg-1] (only the smooth
 * valence-2 ones if only_v2), marking the faces they cover in cov; *any = 1 (any may be NULL)
 * if one was filled. CCN_ERR_INTERNAL: a vertex's fill cannot be placed at this level (the caller
 * undoes the level's fills and refines further). */
static ccn_status fill_vertices(ccn__xmodel *xm, const ccn__plan_view *v, const ccn_mesh *T,
                                const int32_t *reg, int32_t nreg, const ccn__xplace *tpl,
                                int only_v2, uint8_t *cov, int *any, ccn__fill_opts *o,
                                ccn_error *err) {
    uint8_t *done_v = calloc((size_t)T->nv, 1);
    if (!done_v) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
    ccn__fill_level *fl = NULL;
    ccn_status st = CCN_OK;
    for (int32_t i = 0; i < nreg && !st; i++)
        for (int32_t h = T->fstart[reg[i]]; h < T->fstart[reg[i] + 1] && !st; h++) {
            int32_t w = T->hvert[h];
            if (done_v[w] || (only_v2 && !smooth_valence2(T, w)) ||
                ccn__fill_vertex_regular(T, w, v->pinned)) continue;
            done_v[w] = 1;
            if (!fl && (st = ccn__fill_level_create(v, T, &fl, err))) break;
            st = ccn__fill_vertex(xm, fl, w, tpl, o->num_fills++, cov, NULL, err);
            if (any) *any = 1;
        }
    ccn__fill_level_destroy(fl);
    free(done_v);
    return st;
}

/* Adds the cap patches pt (around vertex u of S, operator op) to xm, placed as the plan's caps
 * (surface/patch_set.h). 1, or -1 out of memory. */
static int add_cap(ccn__xmodel *xm, const ccn__plan_view *v, const ccn_mesh *S, int32_t u,
                   const ccn__xplace *pl, const struct ccn__bi5 *op, const double *pt) {
    int32_t n = ccn__valence(S, u), np = ccn__bi5_num_patches(op);
    double b[108];
    for (int32_t i = 0; i < np; i++) {
        int32_t h = S->vfan[S->vfan_start[u] + i % n], f = S->hface[h];
        double rect[3][2];
        ccn__cap_patch_rect(op, n, i, h - S->fstart[f], rect);
        ccn__xplace sub;
        ccn__xplace_sub(&pl[f], (const double(*)[2])rect, &sub);
        memcpy(b, pt + 108 * (size_t)i, sizeof b);
        to_caller(v, b, 36);
        if (ccn__xm_add_bezier(xm, CCN_EXPORT_FACE_BI5, 5, b, &sub) < 0) return -1;
    }
    return 1;
}

/* The guide's domains tried for a cap beyond the plan's kappa range (bi5.h [R15]): the
 * symmetric one and spokes d_s^(1/2); each is the fairer on some stars (measured,
 * tests/experiments/RESULTS.md). The second replaces the first only when its largest |K| is
 * below CCN_FILL_CAP_PREFER times the first's, so that near ties (where rounding could
 * decide) keep the plan's domain on every platform. */
static const double beyond_exps[2] = {0.0, 0.5};
#define CCN_FILL_CAP_PREFER 0.9

/* A guided bi-5 cap (surface/caps.h, ccn__cap_exact) over the faces of S around vertex u,
 * instead of refining further and filling: the faces T has not exported there are exactly the
 * children of u's faces (their nets hold u's vertex point), and the cap joins the exported ones
 * C1 (its ring 0 is the exact level-(K+1) surround). pl: the places of S's faces. Marks the
 * covered faces of T in cov. fl (the last level only): spokes beyond the cap's kappa range are
 * capped too, with the fairest of the caps of beyond_exps and the fill faces of w (T's vertex
 * of u, places tpl) that would close the hole instead: both are built and sampled, and the
 * fairer stays (CCN_FILL_CAP_K_RATIO above). 1 capped, 0 not capped, -1 out of memory. */
static int cap_vertex(ccn__xmodel *xm, const ccn__plan_view *v, const ccn_mesh *S, const ccn_mesh *T,
                      int32_t u, const ccn__xplace *pl, struct ccn__bi5 **ops, uint8_t *cov,
                      ccn__fill_level *fl, const ccn__xplace *tpl, int32_t w) {
    for (int32_t k = S->vfan_start[u]; k < S->vfan_start[u + 1]; k++)
        if (pl[S->hface[S->vfan[k]]].cage_face < 0) return 0; /* a face around u is not in the hole */
    const struct ccn__bi5 *op = NULL;
    double *pt = NULL;
    /* within the range the cap right after the first ring; beyond it the plan's rings too
     * (surface/caps.c: without them star7_nu's cap is flatter, but its reflection lines kink) */
    int r = ccn__cap_exact(S, T, u, v->scheme, v->ev_polyhedron, v->ev_cache, v->pinned, 0, 0, 0, ops, &op, &pt);
    if (r == 0 && fl) { /* beyond the range: the fairest cap, against the fill */
        double kbest = INFINITY;
        for (int q = 0; q < 2 && r >= 0; q++) {
            const struct ccn__bi5 *oq;
            double *pq;
            int rq = ccn__cap_exact(S, T, u, v->scheme, v->ev_polyhedron, v->ev_cache, v->pinned, 1,
                                    beyond_exps[q], 1, ops, &oq, &pq);
            if (rq < 0) r = -1;
            if (rq <= 0) continue;
            int32_t nf0 = xm->num_faces, nc0 = xm->num_cells;
            double k = add_cap(xm, v, S, u, pl, oq, pq) > 0 ? faces_max_k(xm, nf0, xm->num_faces) : NAN;
            xm_rollback(xm, nf0, nc0);
            if (isnan(k) || xm->oom) { free(pq); r = -1; continue; }
            if (k < CCN_FILL_CAP_PREFER * kbest) { free(pt); pt = pq; op = oq; kbest = k; }
            else free(pq);
        }
        if (r >= 0 && pt) {
            int32_t nf1 = xm->num_faces, nc1 = xm->num_cells;
            uint8_t *tmp = calloc((size_t)T->nf, 1);
            ccn_error e2;
            double fdev = INFINITY;
            ccn_status st = tmp ? ccn__fill_vertex(xm, fl, w, tpl, 0, tmp, &fdev, &e2) : CCN_ERR_MEMORY;
            free(tmp);
            double kf = st == CCN_OK ? faces_max_k(xm, nf1, xm->num_faces) : INFINITY;
            xm_rollback(xm, nf1, nc1);
            if (st == CCN_ERR_MEMORY || xm->oom) r = -1;
            else if (fdev <= CCN_FILL_G1_EXACT) r = !(kf < CCN_FILL_CAP_PREFER * kbest);
            else r = kbest <= CCN_FILL_CAP_K_RATIO * kf;
        }
    }
    if (r > 0) r = add_cap(xm, v, S, u, pl, op, pt);
    free(pt);
    if (r > 0)
        for (int32_t k = S->vfan_start[u]; k < S->vfan_start[u + 1]; k++) {
            int32_t f = S->hface[S->vfan[k]];
            for (int32_t c = S->fstart[f]; c < S->fstart[f + 1]; c++) cov[c] = 1;
        }
    return r;
}

/* ---- the levels ---------------------------------------------------------------------- */

ccn_status ccn__fill_holes(ccn__xmodel *xm, const ccn__plan_view *v, int32_t level,
                           const int32_t *faces, int32_t n, ccn__fill_opts *o, ccn_error *err) {
    const ccn_mesh *cm = v->lev[level];
    ccn_mesh *owned = NULL, *S = NULL, *T = NULL;
    int32_t *reg = malloc(sizeof(int32_t) * (size_t)(n ? n : 1)), nreg = n, *fmap = NULL;
    ccn__xplace *regpl = malloc(sizeof(ccn__xplace) * (size_t)(n ? n : 1));
    uint8_t *sel = NULL, *vmark = NULL, *mask = NULL;
    int32_t *inv = NULL;
    ccn__xplace *tpl = NULL;
    ccn__pack *pk = NULL;
    int32_t npk = 0;
    ccn__xplace *spl = NULL;          /* places of the cut's faces (caps) */
    struct ccn__bi5 *ops[CCN_CAP_OPS] = {0};
    ccn_status st = CCN_OK;
    if (!reg || !regpl) goto oom;
    memcpy(reg, faces, sizeof(int32_t) * (size_t)n);
    int32_t smooth_level = semi_sharp(cm) ? -1 : level;
    for (int32_t i = 0; i < n; i++) ccn__xplace_of(v->lev, level, faces[i], &regpl[i]);
    for (int32_t j = 0; nreg > 0; j++) {
        sel = calloc((size_t)cm->nf, 1);
        vmark = malloc((size_t)cm->nv + 1);
        inv = malloc(sizeof(int32_t) * (size_t)cm->nf);
        if (!sel || !vmark || !inv) goto oom;
        for (int32_t i = 0; i < nreg; i++) sel[reg[i]] = 1;
        grow(cm, sel, 3, vmark);
        if ((st = cut(cm, sel, level + j, &S, &fmap, err))) goto done;
        for (int32_t f = 0; f < cm->nf; f++) inv[f] = -1;
        for (int32_t f = 0; f < S->nf; f++) inv[fmap[f]] = f;
        /* a cap where the vertex left is a smooth EV the cap can take (semi-sharp creases
         * decayed around it): its faces are done; the other holes go on. Never at a level
         * coarser than CCN_FILL_CAP_LEVEL or the plan's output level: the samples of a plan of
         * that level or below in such a hole are its EV (the cap's centre, the exact limit
         * point) and its border (the exact surround), so the export still shows what such a
         * plan shows; a coarser cap would differ from the refined limit the plan samples
         * inside it. */
        int capping = v->guided_caps && level + j >= v->output_level && level + j >= CCN_FILL_CAP_LEVEL;
        if (capping) { /* the places of S's faces being refined, for caps over them */
            free(spl);
            spl = malloc(sizeof(ccn__xplace) * (size_t)(S->nf ? S->nf : 1));
            if (!spl) goto oom;
            for (int32_t f = 0; f < S->nf; f++) spl[f].cage_face = -1; /* not being refined */
            for (int32_t i = 0; i < nreg; i++) spl[inv[reg[i]]] = regpl[i];
        }
        ccn__level lv;
        if ((st = ccn__level_prepare_ev(&lv, S, v->scheme, v->pinned, v->crease_method, v->ev_polyhedron,
                                         v->ev_cache, err))) goto done;
        st = ccn__level_topology(&lv, &T, err);
        if (!st) ccn__level_points(&lv, T->pos);
        ccn__level_free(&lv);
        if (st) goto done;
        /* fills o->levels levels below the hole level, or below the level where the last
         * semi-sharp value decayed (at most ceil(s) levels: until then the vertices along it
         * are irregular, and the surface there needs the levels to flatten like elsewhere) */
        if (smooth_level < 0 && !semi_sharp(T)) smooth_level = level + j + 1;
        int last = (smooth_level >= 0 && level + j + 1 - smooth_level >= o->levels) ||
                   level + j + 1 >= CCN_FILL_MAX_LEVEL;
        /* children of the faces being refined: strict -> exact pieces, else refined further */
        tpl = malloc(sizeof(ccn__xplace) * (size_t)T->nf);
        mask = calloc((size_t)T->nf, 1);
        int32_t *nreg2 = malloc(sizeof(int32_t) * 4 * (size_t)nreg);
        ccn__xplace *npl = malloc(sizeof(ccn__xplace) * 4 * (size_t)nreg);
        if (!tpl || !mask || !nreg2 || !npl) { free(nreg2); free(npl); goto oom; }
        int32_t nn = 0;
        for (int32_t i = 0; i < nreg; i++) {
            int32_t sf = inv[reg[i]];
            for (int32_t k = 0; k < 4; k++) {
                int32_t c = S->fstart[sf] + k;
                ccn__xplace_child(&regpl[i], k, &tpl[c]);
                ccn__vpoint net[4][4];
                double Cu[4][4], Cv[4][4];
                if (ccn__bicubic_net(T, c, v->pinned, 1, net, Cu, Cv)) mask[c] = 1;
                else { nreg2[nn] = c; npl[nn++] = tpl[c]; }
            }
        }
        free(reg); free(regpl);
        reg = nreg2; regpl = npl; nreg = nn;
        tplace tp = {tpl};
        if ((st = ccn__packs_find(T, mask, !o->packed, &pk, &npk, err))) goto done;
        for (int32_t k = 0; k < npk; k++) {
            if (pk[k].a * pk[k].b > 1 || o->packed) {
                if (ccn__pack_face(xm, T, &pk[k], v->pinned, v->centre, v->scale, CCN_EXPORT_FACE_REFINED,
                                   place_tab, &tp) < 0) goto oom;
            } else {
                double b[4][4][3];
                int32_t c = T->hface[pk[k].cells[0]];
                ccn__bicubic_patch(T, c, v->pinned, 1, b);
                to_caller(v, &b[0][0][0], 16);
                if (ccn__xm_add_bezier(xm, CCN_EXPORT_FACE_REFINED, 3, &b[0][0][0], &tpl[c]) < 0) goto oom;
            }
        }
        ccn__packs_free(pk, npk);
        pk = NULL;
        npk = 0;
        if (capping && nreg) { /* the caps (above) */
            uint8_t *tried = calloc((size_t)T->nv, 1), *capcov = calloc((size_t)T->nf, 1);
            int r = tried && capcov ? 0 : -1;
            ccn__fill_level *cfl = NULL; /* last level: caps beyond the range against fills */
            if (last && r == 0 && (st = ccn__fill_level_create(v, T, &cfl, err))) {
                free(tried); free(capcov);
                goto done;
            }
            for (int32_t i = 0; i < nreg && r >= 0; i++)
                for (int32_t h = T->fstart[reg[i]]; h < T->fstart[reg[i] + 1] && r >= 0; h++) {
                    int32_t w = T->hvert[h];
                    if (tried[w] || capcov[reg[i]] || ccn__fill_vertex_regular(T, w, v->pinned)) continue;
                    tried[w] = 1;
                    int32_t u = parent_vertex(S, w);
                    if (u >= 0) r = cap_vertex(xm, v, S, T, u, spl, ops, capcov, cfl, tpl, w);
                }
            ccn__fill_level_destroy(cfl);
            int32_t kept = 0;
            for (int32_t i = 0; i < nreg && r >= 0; i++)
                if (!capcov[reg[i]]) { reg[kept] = reg[i]; regpl[kept++] = regpl[i]; }
            free(tried);
            free(capcov);
            if (r < 0) goto oom;
            /* holes closed at the last level by caps instead of fills: that level is the fills' */
            if (last && kept < nreg && o->fill_level < level + j + 1) o->fill_level = level + j + 1;
            nreg = kept;
        }
        int depth = smooth_level >= 0 ? level + j + 1 - smooth_level : -1;
        if (!last && nreg && depth >= 1 && depth >= o->levels - CCN_FILL_LEVELS_V2) {
            /* smooth valence-2 vertices: their fills at this level, fewer levels down (smooth_valence2);
             * where one cannot be placed yet, all of this level's wait for the next level */
            uint8_t *cov = calloc((size_t)T->nf, 1);
            if (!cov) goto oom;
            int any = 0;
            fill_mark mark = fill_mark_of(xm, o);
            st = fill_vertices(xm, v, T, reg, nreg, tpl, 1, cov, &any, o, err);
            if (st == CCN_ERR_INTERNAL) { /* not yet: undo this level's valence-2 fills */
                fill_undo(xm, o, mark);
                memset(cov, 0, (size_t)T->nf);
                st = CCN_OK;
                ccn__ok(err);
                any = 0;
            }
            if (st) { free(cov); goto done; }
            int32_t kept = 0;
            for (int32_t i = 0; i < nreg; i++)
                if (!cov[reg[i]]) { reg[kept] = reg[i]; regpl[kept++] = regpl[i]; }
            free(cov);
            nreg = kept;
            if (any && level + j + 1 > o->fill_level) o->fill_level = level + j + 1;
        }
        if (last && nreg) { /* the fill faces around each irregular vertex cover what is left */
            uint8_t *cov = calloc((size_t)T->nf, 1);
            if (!cov) goto oom;
            fill_mark mark = fill_mark_of(xm, o);
            st = fill_vertices(xm, v, T, reg, nreg, tpl, 0, cov, NULL, o, err);
            for (int32_t i = 0; i < nreg && !st; i++)
                if (!cov[reg[i]])
                    st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, tpl[reg[i]].cage_face,
                                   "a hole near cage face %d is not around one irregular vertex",
                                   (int)tpl[reg[i]].cage_face);
            free(cov);
            if (st == CCN_ERR_INTERNAL && level + j + 1 < CCN_FILL_MAX_LEVEL) {
                /* irregular vertices still too close for the fill's blocks: one level more */
                fill_undo(xm, o, mark);
                st = CCN_OK;
                ccn__ok(err);
                last = 0;
            } else if (st) {
                goto done;
            } else {
                o->fill_level = level + j + 1; /* the deepest fills' level */
                nreg = 0; /* done */
            }
        }
        free(sel); free(vmark); free(inv); free(fmap); free(mask);
        sel = vmark = mask = NULL;
        inv = fmap = NULL;
        free(tpl);
        tpl = NULL;
        ccn_mesh_destroy(S);
        S = NULL;
        ccn_mesh_destroy(owned);
        owned = T;
        cm = T;
        T = NULL;
    }
    if (xm->oom) goto oom;
    goto done;
oom:
    st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
done:
    ccn__packs_free(pk, npk);
    ccn_mesh_destroy(S);
    ccn_mesh_destroy(T);
    ccn_mesh_destroy(owned);
    free(reg); free(regpl); free(sel); free(vmark); free(inv); free(fmap); free(mask); free(tpl);
    free(spl);
    ccn__cap_ops_free(ops);
    return st;
}
