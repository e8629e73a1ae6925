/* Holes of the plan's patch set, closed watertight (io/fill.h; EXPORT_DESIGN.md section 7).
 *
 * A hole is a face the plan has no patch for: its net contains an irregular vertex whose
 * limit is no polynomial (a cap fallback EV, a smooth valence-2 corner, a boundary EV).
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
 * After the last level, what is left are the 2x2 faces per sector around each irregular
 * vertex w (the faces whose nets contain w; with non-uniform intervals their own patches
 * disagree, [R13] of bi5.h). Each sector becomes one fill face: a bicubic B-spline with 2 x 2
 * uniform spans (knots 0 0 0 0 1 2 2 2 2 in units of the last level's faces), poles c[i][j]
 * (i along spoke k, j along spoke k+1):
 *   - outer two layers (i >= 3 or j >= 3): the strict faces across the far sides and their C1
 *     continuations, as 2-span curves (the two faces along each far side join C2 with equal
 *     intervals): the fill joins them exactly C1 (position and derivative);
 *   - spokes (c[i][0], c[0][j]), shared bit-identically by the two sectors: c00 = the exact
 *     limit point of w, c20 = 2 c30 - c40, c10 in w's limit tangent plane (five candidates:
 *     2 c20 - c30 or P + b (c20 - P), b = 0.3 .. 0.9, projected; the one whose fills deviate
 *     least across the spokes is kept); a boundary spoke is the exact boundary curve (cubic
 *     B-spline of the boundary polygon);
 *   - the inner poles: linear continuations of the outer layers (c2j = 2 c3j - c4j, ...), then
 *     along every inner spoke the cross-derivative poles of both sectors are moved into planes
 *     whose normals run from w's limit normal to the exact normal at the spoke's far end.
 * So the fill is C1 across its far sides and G1 at w; across the spokes it is G1 only
 * approximately, a deviation the export measures and reports (it shrinks with the levels).
 */
#include "io/fill.h"

#include "io/packs.h"

#include "base/error.h"
#include "refine/level.h"
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

/* ---- faces -------------------------------------------------------------------------- */

static void to_caller(const ccn__plan_view *v, double *p, int32_t n) {
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) p[3 * i + k] = v->centre[k] + v->scale * p[3 * i + k];
}

/* The Bezier grid b (4x4x3, b[i][j] i along the face's first half-edge) re-framed to start at
 * corner r (r quarter turns: (u,v) -> (1 - v', u') each). */
static void rotate(double b[4][4][3], int32_t r) {
    double t[4][4][3];
    for (; r > 0; r--) {
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) memcpy(t[i][j], b[3 - j][i], sizeof t[i][j]);
        memcpy(b, t, sizeof t);
    }
}

typedef struct { const ccn__xplace *pl; } tplace;

static void place_tab(void *ctx, int32_t face, ccn__xplace *out) {
    *out = ((const tplace *)ctx)->pl[face];
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Limit point and unit normal of irregular vertex w of m. */
static ccn_status vertex_limit(const ccn_mesh *m, int32_t w, int scheme, int pinned, double P[3],
                               double N[3], ccn_error *err) {
    ccn__stencil *s = malloc(sizeof *s);
    if (!s) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
    ccn_status st = CCN_OK;
    if (ccn__limit_kind(m, w, pinned) == CCN_LIMIT_EV) st = ccn__ev_limit(m, w, scheme, s, err);
    else ccn__limit_stencil(m, w, pinned, s);
    double tu[3] = {0, 0, 0}, tv[3] = {0, 0, 0};
    P[0] = P[1] = P[2] = 0;
    for (int i = 0; !st && i < s->n; i++)
        for (int k = 0; k < 3; k++) {
            double x = m->pos[3 * (size_t)s->v[i] + k];
            P[k] += s->wp[i] * x;
            tu[k] += s->wu[i] * x;
            tv[k] += s->wv[i] * x;
        }
    free(s);
    N[0] = tu[1] * tv[2] - tu[2] * tv[1];
    N[1] = tu[2] * tv[0] - tu[0] * tv[2];
    N[2] = tu[0] * tv[1] - tu[1] * tv[0];
    double l = sqrt(dot3(N, N));
    if (!st && !(l > 0))
        st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_VERTEX, w, "no limit tangent plane at a hole's vertex");
    for (int k = 0; k < 3; k++) N[k] /= l;
    return st;
}

/* End vertex of fan edge k of w (k may be a boundary vertex's last edge). */
static int32_t fan_end(const ccn_mesh *m, int32_t w, int32_t k) {
    int32_t e = ccn__fan_edge(m, w, k);
    return m->everts[2 * e] == w ? m->everts[2 * e + 1] : m->everts[2 * e];
}

/* Aligned cells (packs.c's convention): a base half-edge b of face hface[b] runs along +u. */
static int32_t step_u(const ccn_mesh *m, int32_t b) {
    if (b < 0) return -1;
    int32_t t = m->htwin[ccn__next(m, b)];
    return t < 0 ? -1 : ccn__next(m, t);
}
static int32_t step_v(const ccn_mesh *m, int32_t b) {
    return b < 0 ? -1 : m->htwin[ccn__next(m, ccn__next(m, b))];
}

/* The bicubic patch of the aligned cell b (strict or not) in the cell's frame; 0 if none. */
static int cell_patch(const ccn_mesh *m, int32_t b, int pinned, double out[4][4][3]) {
    if (b < 0) return 0;
    int32_t f = m->hface[b];
    if (!ccn__bicubic_patch(m, f, pinned, 0, out)) return 0;
    rotate(out, b - m->fstart[f]);
    return 1;
}

/* Poles Q0..Q4 of the 2-span uniform clamped cubic (knots 0000 1 2222) equal to the C2 pair of
 * Bezier pieces a0..a3, a3..a6 (a[k] at stride 3 doubles). */
static void two_span(const double a[7][3], double Q[5][3]) {
    for (int d = 0; d < 3; d++) {
        Q[0][d] = a[0][d];
        Q[1][d] = a[1][d];
        Q[2][d] = 0.5 * ((2 * a[2][d] - a[1][d]) + (2 * a[4][d] - a[5][d]));
        Q[3][d] = a[5][d];
        Q[4][d] = a[6][d];
    }
}

/* One sector's block around w: the aligned cells of the 2x2 faces [0,2]^2 and of the strict
 * faces along its far sides: N1, N2 across u = 2 (v in [0,1], [1,2]), M1, M2 across v = 2. */
typedef struct { int32_t g, A, B, D, N1, N2, M1, M2; } block;

static void sector_block(const ccn_mesh *m, int32_t h, block *k) {
    k->g = h;
    k->A = step_u(m, h);
    k->B = step_v(m, h);
    k->D = step_v(m, k->A);
    k->N1 = step_u(m, k->A);
    k->N2 = step_u(m, k->D);
    k->M1 = step_v(m, k->B);
    k->M2 = step_v(m, k->D);
}

/* The 2-span poles of the side (layer 0) or of its C1 continuation (layer 1) of the cells
 * P (first span) and Q (second span) across their u = 0 side (v = 0 side if along_u). */
static void side_poles(const double P[4][4][3], const double Q[4][4][3], int along_u, int layer,
                       double out[5][3]) {
    double a[7][3];
    for (int k = 0; k < 7; k++) {
        const double (*c)[4][3] = k < 3 ? P : Q;
        int q = k < 3 ? k : k - 3;
        const double *s = along_u ? c[q][0] : c[0][q], *t = along_u ? c[q][1] : c[1][q];
        for (int d = 0; d < 3; d++) a[k][d] = layer ? 2 * s[d] - t[d] : s[d];
    }
    two_span((const double(*)[3])a, out);
}

static void unit3(double *a) {
    double l = sqrt(dot3(a, a));
    if (l > 0) for (int d = 0; d < 3; d++) a[d] /= l;
}
static void cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* x moved least so that (x - p).n = 0 (n unit). */
static void onto_plane(double *x, const double *p, const double *n) {
    double t = (x[0] - p[0]) * n[0] + (x[1] - p[1]) * n[1] + (x[2] - p[2]) * n[2];
    for (int d = 0; d < 3; d++) x[d] -= t * n[d];
}
/* x moved least so that (x - p).n1 = 0 and (x - q).n2 = 0 (n1, n2 unit; nearly parallel: their
 * mean alone). */
static void onto_two(double *x, const double *p, const double *n1, const double *q, const double *n2) {
    double a = dot3(n1, n2), r1 = 0, r2 = 0, det = 1 - a * a;
    for (int d = 0; d < 3; d++) { r1 += (x[d] - p[d]) * n1[d]; r2 += (x[d] - q[d]) * n2[d]; }
    if (det < 1e-6) {
        double n[3] = {n1[0] + n2[0], n1[1] + n2[1], n1[2] + n2[2]}, m[3];
        unit3(n);
        for (int d = 0; d < 3; d++) m[d] = 0.5 * (p[d] + q[d]);
        onto_plane(x, m, n);
        return;
    }
    double al = (r1 - a * r2) / det, be = (r2 - a * r1) / det;
    for (int d = 0; d < 3; d++) x[d] -= al * n1[d] + be * n2[d];
}

/* Approximate G1 across the fills' spokes: along spoke k the normal is interpolated between
 * w's limit normal N and the exact normal at the spoke's far end (Greville abscissae 1/6, 1/2
 * of poles 1, 2), and both sectors' cross-derivative poles there are moved into that plane:
 * c_k[2][1], c_{k-1}[1][2] by one constraint, the twists c_k[1][1] by the constraints of both
 * of their spokes. Boundary spokes keep their exact boundary curve and constrain nothing. */
static void spoke_planes(const ccn_mesh *m, int32_t w, double (*nb)[6][4][4][3], double (*cs)[5][5][3],
                         int32_t nfan, int32_t nsp, int bnd, double N[3]) {
    (void)m; (void)w;
    double ring[3] = {0, 0, 0};
    for (int32_t k = 0; k < nfan; k++) { /* orient N like the sectors */
        double a[3], b[3], c[3];
        for (int d = 0; d < 3; d++) { a[d] = cs[k][4][0][d] - cs[k][0][0][d]; b[d] = cs[k][0][4][d] - cs[k][0][0][d]; }
        cross(a, b, c);
        for (int d = 0; d < 3; d++) ring[d] += c[d];
    }
    if (dot3(ring, N) < 0) for (int d = 0; d < 3; d++) N[d] = -N[d];
    double (*np)[2][3] = malloc(sizeof *np * (size_t)(nsp + 1)); /* per spoke: normals at poles 1, 2 */
    if (!np) return; /* the fill stays as built (a larger deviation, still reported) */
    for (int32_t k = 0; k < nsp; k++) {
        double du[3], dv[3], n4[3];
        if (k < nfan) { /* sector k's N1 at its corner (2h,0): exact */
            const double (*c)[4][3] = (const double(*)[4][3])nb[k][0];
            for (int d = 0; d < 3; d++) { du[d] = c[1][0][d] - c[0][0][d]; dv[d] = c[0][1][d] - c[0][0][d]; }
        } else {
            const double (*c)[4][3] = (const double(*)[4][3])nb[k - 1][2];
            for (int d = 0; d < 3; d++) { du[d] = c[1][0][d] - c[0][0][d]; dv[d] = c[0][1][d] - c[0][0][d]; }
        }
        cross(du, dv, n4);
        unit3(n4);
        static const double g[2] = {1.0 / 6.0, 0.5};
        for (int i = 0; i < 2; i++) {
            for (int d = 0; d < 3; d++) np[k][i][d] = (1 - g[i]) * N[d] + g[i] * n4[d];
            unit3(np[k][i]);
        }
    }
    for (int32_t k = 0; k < nfan; k++) {
        int32_t k1 = (k + 1) % nsp;
        int inner0 = !bnd || k > 0, inner1 = !bnd || k1 < nsp - 1; /* spokes k, k+1 inner? */
        double (*c)[5][3] = cs[k];
        if (inner0) onto_plane(c[2][1], c[2][0], np[k][1]);
        if (inner1) onto_plane(c[1][2], c[0][2], np[k1][1]);
        if (inner0 && inner1) onto_two(c[1][1], c[1][0], np[k][0], c[0][1], np[k1][0]);
        else if (inner0) onto_plane(c[1][1], c[1][0], np[k][0]);
        else if (inner1) onto_plane(c[1][1], c[0][1], np[k1][0]);
    }
    free(np);
}

/* Largest normal angle across the inner spokes of the fills cs (8 points per spoke). */
static double spoke_deviation(double (*cs)[5][5][3], int32_t nfan, int32_t nsp, int bnd) {
    static const double kn[3] = {0, 1, 2};
    static const int32_t mu[3] = {4, 1, 4};
    double worst = 0;
    for (int32_t k = 0; k < nsp; k++) {
        if (bnd && (k == 0 || k == nsp - 1)) continue;
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan; /* spoke k: u-axis of a, v-axis of b */
        ccn__cad_surface A = {{3, 3}, {5, 5}, {3, 3}, {kn, kn}, {mu, mu}, &cs[a][0][0][0], {0, 0}};
        ccn__cad_surface B = A;
        B.poles = &cs[b][0][0][0];
        for (int i = 0; i < 8; i++) {
            double t = 2.0 * (i + 0.5) / 8, p[3], du[3], dv[3], na[3], nb[3], c[3];
            ccn__cad_eval_d(&A, t, 0, p, du, dv);
            cross(du, dv, na);
            ccn__cad_eval_d(&B, 0, t, p, du, dv);
            cross(du, dv, nb);
            cross(na, nb, c);
            double ang = atan2(sqrt(dot3(c, c)), dot3(na, nb));
            if (!(ang <= worst)) worst = ang;
        }
    }
    return worst;
}

/* Fill faces around irregular vertex w of m (the last level): per fan face (sector) one
 * bicubic B-spline face with 2 x 2 spans over the sector's 2x2 faces, which it replaces. */
static ccn_status fill_vertex(ccn__xmodel *xm, const ccn__plan_view *v, const ccn_mesh *m,
                              int32_t w, const ccn__xplace *fpl, int32_t fill_id, uint8_t *covered,
                              ccn_error *err) {
    int32_t nfan = m->vfan_start[w + 1] - m->vfan_start[w], nsp = ccn__valence(m, w);
    int bnd = m->vboundary[w];
    double P[3], N[3];
    ccn_status st = vertex_limit(m, w, v->scheme, v->pinned, P, N, err);
    if (st) return st;
    double (*sp)[5][3] = malloc(sizeof *sp * (size_t)(nsp + 1)); /* spoke curves from w */
    double (*nb)[6][4][4][3] = malloc(sizeof *nb * (size_t)(nfan ? nfan : 1)); /* N1 N2 M1 M2 A B */
    block *bk = malloc(sizeof *bk * (size_t)(nfan ? nfan : 1));
    double (*cs)[5][5][3] = NULL; /* the fills' poles, per sector */
    if (!sp || !nb || !bk) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); goto done; }
    for (int32_t k = 0; k < nfan; k++) {
        sector_block(m, m->vfan[m->vfan_start[w] + k], &bk[k]);
        const int32_t cells[6] = {bk[k].N1, bk[k].N2, bk[k].M1, bk[k].M2, bk[k].A, bk[k].B};
        int ok = ccn__fsize(m, m->hface[bk[k].g]) == 4 && bk[k].D >= 0;
        for (int q = 0; q < 6 && ok; q++) ok = cell_patch(m, cells[q], v->pinned, nb[k][q]);
        if (!ok) {
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_VERTEX, w,
                           "the faces around a hole's vertex are not regular enough to fill");
            goto done;
        }
    }
    cs = malloc(sizeof *cs * 2 * (size_t)(nfan ? nfan : 1));
    if (!cs) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); goto done; }
    /* the spokes' inner poles (c10 = P + b (c20 - P) or 2 c20 - c30, in the tangent plane):
     * the candidate with the smallest measured normal deviation across the spokes */
    static const double BETA[5] = {-1, 0.3, 0.5, 0.7, 0.9};
    double best = INFINITY, (*cbest)[5][5][3] = cs + nfan;
    for (int cand = 0; cand < 5; cand++) {
        double beta = BETA[cand];
        for (int32_t k = 0; k < nsp; k++) { /* spoke k: sector k's u-axis, sector k-1's v-axis */
            double (*c)[3] = sp[k], L[5][3], S[5][3];
            if (k < nfan) { /* from sector k's cells N1 (and N2) across u = 2 */
                side_poles((const double(*)[4][3])nb[k][0], (const double(*)[4][3])nb[k][1], 0, 0, S);
                side_poles((const double(*)[4][3])nb[k][0], (const double(*)[4][3])nb[k][1], 0, 1, L);
            } else { /* a boundary vertex's last spoke: sector k-1's cells M1, M2 across v = 2 */
                side_poles((const double(*)[4][3])nb[k - 1][2], (const double(*)[4][3])nb[k - 1][3], 1, 0, S);
                side_poles((const double(*)[4][3])nb[k - 1][2], (const double(*)[4][3])nb[k - 1][3], 1, 1, L);
            }
            memcpy(c[4], S[0], sizeof c[4]);
            memcpy(c[3], L[0], sizeof c[3]);
            memcpy(c[0], P, sizeof P);
            if (bnd && (k == 0 || k == nsp - 1)) { /* the boundary curve: exact */
                /* second span = the boundary row of cell A (sector 0) / column of cell B (last) */
                const double (*E)[4][3] = (const double(*)[4][3])(k == 0 ? nb[0][4] : nb[nfan - 1][5]);
                double e2[4][3];
                for (int q = 0; q < 4; q++) memcpy(e2[q], k == 0 ? E[q][0] : E[0][q], sizeof e2[q]);
                int32_t e = ccn__fan_edge(m, w, k), eo = ccn__fan_edge(m, w, k == 0 ? nsp - 1 : 0);
                int32_t end = fan_end(m, w, k);
                double D0 = m->eknot[e], Dm = m->eknot[eo], b1[3], b2[3];
                double al = Dm / (Dm + 2 * D0), ga = (Dm + D0) / (Dm + 2 * D0); /* D_1 = D_0 */
                for (int d = 0; d < 3; d++) {
                    b1[d] = (1 - al) * m->pos[3 * (size_t)w + d] + al * m->pos[3 * (size_t)end + d];
                    b2[d] = (1 - ga) * m->pos[3 * (size_t)w + d] + ga * m->pos[3 * (size_t)end + d];
                    c[1][d] = b1[d];
                    c[2][d] = 0.5 * ((2 * b2[d] - b1[d]) + (2 * e2[1][d] - e2[2][d]));
                    c[3][d] = e2[2][d];
                    c[4][d] = e2[3][d];
                }
            } else {
                double X[3];
                for (int d = 0; d < 3; d++) c[2][d] = 2 * c[3][d] - c[4][d];
                for (int d = 0; d < 3; d++) X[d] = beta < 0 ? 2 * c[2][d] - c[3][d] - P[d] : beta * (c[2][d] - P[d]);
                double t = dot3(X, N);
                for (int d = 0; d < 3; d++) c[1][d] = P[d] + X[d] - t * N[d];
            }
        }
        for (int32_t k = 0; k < nfan; k++) {
            double (*c)[5][3] = cs[k], S[5][3], L[5][3];
            memset(c, 0, sizeof cs[k]);
            int cnt[5][5];
            memset(cnt, 0, sizeof cnt);
            for (int pass = 0; pass < 2; pass++) { /* u-side from N1, N2; v-side from M1, M2 */
                const double (*a)[4][3] = (const double(*)[4][3])nb[k][pass ? 2 : 0];
                const double (*b)[4][3] = (const double(*)[4][3])nb[k][pass ? 3 : 1];
                side_poles(a, b, pass, 0, S);
                side_poles(a, b, pass, 1, L);
                for (int q = 0; q < 5; q++)
                    for (int lay = 0; lay < 2; lay++) {
                        int i = pass ? q : 4 - lay, j = pass ? 4 - lay : q;
                        for (int d = 0; d < 3; d++) c[i][j][d] += lay ? L[q][d] : S[q][d];
                        cnt[i][j]++;
                    }
            }
            for (int i = 0; i < 5; i++) /* the far corner comes from both sides: their mean */
                for (int j = 0; j < 5; j++)
                    for (int d = 0; d < 3 && cnt[i][j] > 1; d++) c[i][j][d] /= cnt[i][j];
            for (int j = 1; j < 3; j++) /* inner layers: linear continuations of the outer two */
                for (int d = 0; d < 3; d++) {
                    c[2][j][d] = 2 * c[3][j][d] - c[4][j][d];
                    c[j][2][d] = 2 * c[j][3][d] - c[j][4][d];
                }
            for (int d = 0; d < 3; d++) {
                c[2][2][d] = 0.5 * ((2 * c[3][2][d] - c[4][2][d]) + (2 * c[2][3][d] - c[2][4][d]));
                c[1][1][d] = 0.5 * ((2 * c[2][1][d] - c[3][1][d]) + (2 * c[1][2][d] - c[1][3][d]));
            }
            for (int q = 0; q < 5; q++) { /* spokes exactly (shared with the next sector) */
                memcpy(c[q][0], sp[k][q], sizeof c[q][0]);
                memcpy(c[0][q], sp[(k + 1) % nsp][q], sizeof c[0][q]);
            }
        }
        spoke_planes(m, w, nb, cs, nfan, nsp, bnd, N);
        double dev = spoke_deviation(cs, nfan, nsp, bnd);
        if (dev < best || cand == 0) {
            best = dev;
            memcpy(cbest, cs, sizeof *cs * (size_t)nfan);
        }
    }
    memcpy(cs, cbest, sizeof *cs * (size_t)nfan);
    static const double K[9] = {0, 0, 0, 0, 1, 2, 2, 2, 2};
    for (int32_t k = 0; k < nfan && !st; k++) {
        double (*c)[5][3] = cs[k];
        int32_t g = m->hface[bk[k].g], r = bk[k].g - m->fstart[g];
        ccn__xplace q1, q2;
        ccn__xplace_rotate(&fpl[g], r, &q1); /* the sector's [0,1]^2: its face at w */
        double twice[3][2] = {{0, 0}, {2, 0}, {0, 2}};
        ccn__xplace_sub(&q1, (const double(*)[2])twice, &q2);
        to_caller(v, &c[0][0][0], 25);
        int32_t f = ccn__xm_add_face(xm, CCN_EXPORT_FACE_FILL, 3, 3, 5, 5, 1, 1);
        if (f < 0 || ccn__xm_set_flat(xm, f, 0, K) || ccn__xm_set_flat(xm, f, 1, K)) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
            break;
        }
        memcpy((void *)xm->faces[f].s.poles, c, sizeof cs[k]);
        xm->faces[f].fill = fill_id;
        ccn__xcell *cl = &xm->cells[xm->faces[f].cell0];
        cl->uv[0] = 0; cl->uv[1] = 2; cl->uv[2] = 0; cl->uv[3] = 2;
        cl->pl = q2;
        const int32_t blk[4] = {bk[k].g, bk[k].A, bk[k].B, bk[k].D};
        for (int q = 0; q < 4; q++) covered[m->hface[blk[q]]] = 1;
    }
done:
    free(sp);
    free(nb);
    free(bk);
    free(cs);
    return st;
}

#define CCN_FILL_MAX_LEVEL 16 /* deepest level a fill goes to when its vertices are close */

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
    ccn_status st = CCN_OK;
    if (!reg || !regpl) goto oom;
    memcpy(reg, faces, sizeof(int32_t) * (size_t)n);
    for (int32_t i = 0; i < n; i++) ccn__xplace_of(v->lev, level, faces[i], &regpl[i]);
    for (int32_t j = 0; nreg > 0; j++) {
        int last = j + 1 >= o->levels;
        sel = calloc((size_t)cm->nf, 1);
        vmark = malloc((size_t)cm->nv + 1);
        inv = malloc(sizeof(int32_t) * (size_t)cm->nf);
        if (!sel || !vmark || !inv) goto oom;
        for (int32_t i = 0; i < nreg; i++) sel[reg[i]] = 1;
        grow(cm, sel, 3, vmark);
        if ((st = cut(cm, sel, level + j, &S, &fmap, err))) goto done;
        for (int32_t f = 0; f < cm->nf; f++) inv[f] = -1;
        for (int32_t f = 0; f < S->nf; f++) inv[fmap[f]] = f;
        ccn__level lv;
        if ((st = ccn__level_prepare(&lv, S, v->scheme, v->pinned, v->crease_method, err))) goto done;
        st = ccn__level_topology(&lv, &T, err);
        if (!st) ccn__level_points(&lv, T->pos);
        ccn__level_free(&lv);
        if (st) goto done;
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
        if (last) { /* the fill faces around each irregular vertex cover what is left */
            uint8_t *done_v = calloc((size_t)T->nv, 1), *cov = calloc((size_t)T->nf, 1);
            if (!done_v || !cov) { free(done_v); free(cov); goto oom; }
            int32_t nf0 = xm->num_faces, nc0 = xm->num_cells, nfill0 = o->num_fills;
            for (int32_t i = 0; i < nreg && !st; i++)
                for (int32_t h = T->fstart[reg[i]]; h < T->fstart[reg[i] + 1] && !st; h++) {
                    int32_t w = T->hvert[h];
                    if (done_v[w] || ccn__limit_kind(T, w, v->pinned) == CCN_LIMIT_REGULAR) continue;
                    done_v[w] = 1;
                    st = fill_vertex(xm, v, T, w, tpl, o->num_fills++, cov, err);
                }
            for (int32_t i = 0; i < nreg && !st; i++)
                if (!cov[reg[i]])
                    st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, tpl[reg[i]].cage_face,
                                   "a hole near cage face %d is not around one irregular vertex",
                                   (int)tpl[reg[i]].cage_face);
            free(done_v);
            free(cov);
            if (st == CCN_ERR_INTERNAL && level + j + 1 < CCN_FILL_MAX_LEVEL) {
                /* irregular vertices still too close for the fill's blocks: one level more */
                for (int32_t f = nf0; f < xm->num_faces; f++) {
                    ccn__cad_surface *sf = &xm->faces[f].s;
                    free((void *)sf->poles);
                    for (int d = 0; d < 2; d++) { free((void *)sf->knots[d]); free((void *)sf->mults[d]); }
                }
                xm->num_faces = nf0;
                xm->num_cells = nc0;
                o->num_fills = nfill0;
                st = CCN_OK;
                ccn__ok(err);
                last = 0;
            } else if (st) {
                goto done;
            } else {
                o->fill_level = level + j + 1;
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
    return st;
}
