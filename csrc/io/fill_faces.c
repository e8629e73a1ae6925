/* The fill faces around one irregular vertex w at the last level of a hole's local
 * refinement (io/fill_faces.h; EXPORT_DESIGN.md section 7; io/fill.c refines the levels).
 *
 * What is left around w are the 2x2 faces per fan face (the faces whose nets contain w; with
 * non-uniform intervals their own patches disagree, [R13] of bi5.h). Each fan face (a fill
 * sector) becomes one fill face: a bicubic B-spline with 2 x 2 uniform spans (knots
 * 0 0 0 0 1 2 2 2 2 in units of the last level's faces), poles c[i][j] (i along spoke k, j
 * along spoke k+1):
 *   - outer two layers (i >= 3 or j >= 3): the strict faces across the far sides and their C1
 *     continuations, as 2-span curves (the two faces along each far side join C2 with equal
 *     intervals): the fill joins them exactly C1 (position and derivative);
 *   - spokes (c[i][0], c[0][j]), shared bit-identically by the two sectors: c00 = the exact
 *     limit point of w, c20 = 2 c30 - c40, c10 in the limit tangent plane of the spoke's
 *     sector (five candidates: 2 c20 - c30 or P + b (c20 - P), b = 0.3 .. 0.9, projected; the
 *     one whose fills deviate least across the spokes is kept); a boundary spoke, and a sharp
 *     spoke at a crease or corner vertex, is the exact boundary / crease curve: the cubic
 *     B-spline of its polygon (second span: the side of the strict cell beyond; first span
 *     from w and the spoke's end with the interval beyond w that the crease look-ups give,
 *     rules/bspline.c: the other crease edge's on a crease, the spoke's own at a corner);
 *   - the inner poles: linear continuations of the outer layers (c2j = 2 c3j - c4j, ...), then
 *     along every smooth spoke the cross-derivative poles of both sectors are moved into planes
 *     whose normals run from the limit normal at w to the exact normal at the spoke's far end.
 * So the fill is C1 across its far sides and G1 at w; across the smooth spokes it is G1 only
 * approximately, a deviation the export measures and reports (it shrinks with the levels).
 *
 * Creases: the fan is split into sectors by its sharp spokes (no semi-sharp value is left at
 * the fill level, io/fill.c). w's limit point and one exact tangent plane per sector come from
 * the library's stencils (surface/ring_limit.c over w's child 1-ring; a smooth interior EV:
 * the eigenvectors of M). Sharp spokes are C0 edges between the fills of the two sides, which
 * share the spoke curve bit for bit and are not constrained across it; on a crease or corner
 * vertex the spoke is the exact crease curve. At a corner, the smooth spokes of a sector between
 * two crease curves leave w in the plane of those curves' tangents (corner_planes). A dart's
 * sharp spoke (its crease ends at w, whose rule is the smooth one, so the curve is no B-spline
 * of its polygon there) is built like a smooth spoke: C0, close to the crease, its distance to
 * the limit measured like the rest. */
#include "io/fill_faces.h"
#include "io/fill_g1.h"

#include "base/error.h"
#include "refine/level.h"
#include "rules/bspline.h"
#include "surface/fill_border.h"
#include "surface/limit.h"
#include "surface/patches.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ccn__fill_level {
    const ccn__plan_view *v;
    const ccn_mesh *m;
    ccn__level lv;           /* m's next level (prepared once) */
    int prepared;
    double *child;           /* its points around the vertex being filled */
    ccn__ring_work *rw;
    ccn__ring_limit ring;
    ccn__stencil s;
};

ccn_status ccn__fill_level_create(const ccn__plan_view *v, const ccn_mesh *m, ccn__fill_level **out,
                                  ccn_error *err) {
    *out = NULL;
    ccn__fill_level *fl = calloc(1, sizeof *fl);
    if (!fl) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
    fl->v = v;
    fl->m = m;
    fl->child = malloc(sizeof(double) * 3 * ((size_t)m->nf + m->ne + m->nv + 1));
    fl->rw = ccn__ring_work_create();
    ccn_status st = !fl->child || !fl->rw ? ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)")
                                          : ccn__level_prepare_ev(&fl->lv, m, v->scheme, v->pinned, v->crease_method,
                                                                   v->ev_polyhedron, v->ev_cache, err);
    if (st) {
        ccn__fill_level_destroy(fl);
        return st;
    }
    ccn__ring_work_set_ev(fl->rw, v->ev_polyhedron, v->ev_cache);
    fl->prepared = 1;
    *out = fl;
    return CCN_OK;
}

void ccn__fill_level_destroy(ccn__fill_level *fl) {
    if (!fl) return;
    if (fl->prepared) ccn__level_free(&fl->lv);
    ccn__ring_work_destroy(fl->rw);
    free(fl->child);
    free(fl);
}

int ccn__fill_vertex_regular(const ccn_mesh *m, int32_t w, int pinned) {
    for (int32_t k = 0; k < m->vfan_start[w + 1] - m->vfan_start[w]; k++)
        if (!ccn__sector_regular(m, w, k, pinned)) return 0;
    return 1;
}

/* ---- faces -------------------------------------------------------------------------- */

static void to_caller(const ccn__plan_view *v, double *p, int32_t n) {
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) p[3 * i + k] = v->centre[k] + v->scale * p[3 * i + k];
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int32_t fan_end(const ccn_mesh *m, int32_t w, int32_t k) {
    int32_t e = ccn__fan_edge(m, w, k);
    return m->everts[2 * e] == w ? m->everts[2 * e + 1] : m->everts[2 * e];
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

/* w's limit point P and, per fan face k, the unit normal N[k] of its sector. */
static ccn_status vertex_limit(ccn__fill_level *fl, int32_t w, double P[3], double (*N)[3],
                               ccn_error *err) {
    const ccn_mesh *m = fl->m;
    const ccn__plan_view *v = fl->v;
    int32_t nfan = m->vfan_start[w + 1] - m->vfan_start[w];
    ccn__stencil *s = &fl->s;
    const double *pos = m->pos;
    ccn_status st;
    fl->ring.nsec = 0;
    if (ccn__limit_kind(m, w, v->pinned) == CCN_LIMIT_EV) {
        st = ccn__ev_limit(m, w, v->scheme, v->ev_polyhedron, v->ev_cache, s, err);
    } else { /* stencils over w's child 1-ring */
        ccn__level_points_subset(&fl->lv, &w, 1, fl->child);
        st = ccn__child_limit_stencil(m, w, v->pinned, v->scheme, v->crease_method, fl->rw, s, &fl->ring, err);
        pos = fl->child;
    }
    if (st) return st;
    double tu0[3] = {0, 0, 0}, tv0[3] = {0, 0, 0};
    P[0] = P[1] = P[2] = 0;
    for (int i = 0; i < s->n; i++)
        for (int d = 0; d < 3; d++) {
            double x = pos[3 * (size_t)s->v[i] + d];
            P[d] += s->wp[i] * x;
            tu0[d] += s->wu[i] * x;
            tv0[d] += s->wv[i] * x;
        }
    const ccn__ring_limit *r = &fl->ring;
    for (int32_t k = 0; k < nfan; k++) {
        double tu[3], tv[3];
        memcpy(tu, tu0, sizeof tu);
        memcpy(tv, tv0, sizeof tv);
        for (int32_t i = 0; i < r->nsec; i++) {
            if (((k - r->sec_face0[i]) % nfan + nfan) % nfan >= r->sec_nface[i]) continue;
            const double *wu = r->wu + (size_t)i * r->npts, *wv = r->wv + (size_t)i * r->npts;
            memset(tu, 0, sizeof tu);
            memset(tv, 0, sizeof tv);
            for (int32_t j = 0; j < r->npts; j++)
                for (int d = 0; d < 3; d++) {
                    tu[d] += wu[j] * pos[3 * (size_t)r->pts[j] + d];
                    tv[d] += wv[j] * pos[3 * (size_t)r->pts[j] + d];
                }
            break;
        }
        cross(tu, tv, N[k]);
        double l = sqrt(dot3(N[k], N[k]));
        if (!(l > 0))
            return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_VERTEX, w, "no limit tangent plane at a hole's vertex");
        for (int d = 0; d < 3; d++) N[k][d] /= l;
    }
    return CCN_OK;
}

/* Approximate G1 across the fills' smooth spokes: along spoke k the normal is interpolated
 * between the limit normal Ns[k] of its sector at w and the exact normal at the spoke's far end
 * (Greville abscissae 1/6, 1/2 of poles 1, 2), and both sectors' cross-derivative poles there
 * are moved into that plane: c_k[2][1], c_{k-1}[1][2] by one constraint, the twists c_k[1][1]
 * by the constraints of both of their spokes. Sharp spokes (boundary, creases) constrain
 * nothing. */
static void spoke_planes(double (*nb)[6][4][4][3], double (*cs)[5][5][3], int32_t nfan, int32_t nsp,
                         const uint8_t *sharp, const uint8_t *filled, double (*Ns)[3]) {
    double (*np)[2][3] = malloc(sizeof *np * (size_t)(nsp + 1)); /* per spoke: normals at poles 1, 2 */
    if (!np) return; /* the fill stays as built (a larger deviation, still reported) */
    for (int32_t k = 0; k < nsp; k++) { /* a smooth spoke's two sectors are both filled or not */
        if (sharp[k] || !filled[k < nfan ? k : k - 1]) continue;
        double du[3], dv[3], n4[3], n0[3];
        const double (*c)[4][3] = (const double(*)[4][3])(k < nfan ? nb[k][0] : nb[k - 1][2]);
        for (int d = 0; d < 3; d++) { du[d] = c[1][0][d] - c[0][0][d]; dv[d] = c[0][1][d] - c[0][0][d]; }
        cross(du, dv, n4); /* sector k's N1 at its corner (2h,0) (the last spoke: M1 at (0,2h)) */
        unit3(n4);
        double sg = dot3(Ns[k], n4) < 0 ? -1 : 1; /* the limit normal oriented like the faces */
        for (int d = 0; d < 3; d++) n0[d] = sg * Ns[k][d];
        static const double g[2] = {1.0 / 6.0, 0.5};
        for (int i = 0; i < 2; i++) {
            for (int d = 0; d < 3; d++) np[k][i][d] = (1 - g[i]) * n0[d] + g[i] * n4[d];
            unit3(np[k][i]);
        }
    }
    for (int32_t k = 0; k < nfan; k++) {
        if (!filled[k]) continue;
        int32_t k1 = (k + 1) % nsp;
        int inner0 = !sharp[k], inner1 = !sharp[k1]; /* spokes k, k+1 constrained? */
        double (*c)[5][3] = cs[k];
        if (inner0) onto_plane(c[2][1], c[2][0], np[k][1]);
        if (inner1) onto_plane(c[1][2], c[0][2], np[k1][1]);
        if (inner0 && inner1) onto_two(c[1][1], c[1][0], np[k][0], c[0][1], np[k1][0]);
        else if (inner0) onto_plane(c[1][1], c[1][0], np[k][0]);
        else if (inner1) onto_plane(c[1][1], c[0][1], np[k1][0]);
    }
    free(np);
}

/* Largest normal angle across the smooth spokes of the bicubic fills cs (8 points per spoke). */
static double spoke_deviation(double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                              const uint8_t *filled, uint8_t *smooth) {
    static const int32_t mu[3] = {4, 1, 4};
    for (int32_t k = 0; k < nsp; k++) /* spoke k: u-axis of sector k, v-axis of sector k-1 */
        smooth[k] = !sharp[k] && filled[k % nfan] && filled[(k + nfan - 1) % nfan];
    return ccn__fill_spoke_angle(&cs[0][0][0][0], 3, mu, nfan, nsp, smooth, 8);
}

/* The first two inner poles b1, b2 of the exact crease or boundary curve along sharp spoke k
 * from w: the cubic B-spline of its polygon, the interval beyond w from the crease look-ups
 * (rules/bspline.c: the other crease edge's on a crease, the spoke's own at a corner). */
static void crease_poles(const ccn_mesh *m, int32_t w, int32_t k, int pinned, double b1[3], double b2[3]) {
    int32_t e = ccn__fan_edge(m, w, k), end = fan_end(m, w, k);
    double D0 = m->eknot[e], Dm = ccn__beyond(m, w, k, pinned);
    double al = Dm / (Dm + 2 * D0), ga = (Dm + D0) / (Dm + 2 * D0); /* D_1 = D_0 */
    for (int d = 0; d < 3; d++) {
        b1[d] = (1 - al) * m->pos[3 * (size_t)w + d] + al * m->pos[3 * (size_t)end + d];
        b2[d] = (1 - ga) * m->pos[3 * (size_t)w + d] + ga * m->pos[3 * (size_t)end + d];
    }
}

/* The tangent plane at a corner for the smooth spokes of each sector between two exact sharp
 * spokes: the plane of the two crease curves' tangents. A surface through both curves that has
 * a tangent plane at w has that one; the refined limit in a sector of two or more faces at a
 * corner need not (its smooth spokes leave w out of that plane, a cone inside the sector), and
 * fills that follow its tangents cannot be G1 across those spokes (catmark_inf_crease1: 0.46
 * rad). Where the two tangents are parallel (a crease through w, a smooth boundary) the limit's
 * plane stays. Ns[k] (per spoke) is replaced, oriented as before. */
static void corner_planes(const ccn_mesh *m, int32_t w, const double P[3], int32_t nfan, int32_t nsp,
                          int bnd, const uint8_t *sharp, int pinned, double (*Ns)[3]) {
    for (int32_t k0 = 0; k0 < nsp; k0++) {
        if (!sharp[k0] || (bnd && k0 == nsp - 1)) continue;
        int32_t k1 = k0 + 1, n = 0; /* the next sharp spoke (cyclic inside) */
        while (n < nfan && !sharp[k1 % nsp]) k1++, n++;
        if (n == 0 || n >= nfan || (bnd && k1 >= nsp)) continue; /* no smooth spoke, or one sector */
        double a[3], b[3], c[3], unused[3];
        crease_poles(m, w, k0, pinned, a, unused);
        crease_poles(m, w, k1 % nsp, pinned, b, unused);
        for (int d = 0; d < 3; d++) a[d] -= P[d], b[d] -= P[d]; /* the curves' tangents at w */
        cross(a, b, c);
        double lc = sqrt(dot3(c, c)), la = sqrt(dot3(a, a)), lb = sqrt(dot3(b, b));
        if (!(lc > 1e-6 * la * lb)) continue;
        for (int32_t k = k0 + 1; k < k1; k++) {
            double *N = Ns[k % nsp], sg = dot3(N, c) < 0 ? -1 : 1;
            for (int d = 0; d < 3; d++) N[d] = sg * c[d] / lc;
        }
    }
}

ccn_status ccn__fill_vertex(ccn__xmodel *xm, ccn__fill_level *fl, int32_t w, const ccn__xplace *fpl,
                            int32_t fill_id, uint8_t *covered, double *spoke_dev, ccn_error *err) {
    const ccn_mesh *m = fl->m;
    const ccn__plan_view *v = fl->v;
    int32_t nfan = m->vfan_start[w + 1] - m->vfan_start[w], nsp = ccn__valence(m, w), nsharp = 0;
    int bnd = m->vboundary[w];
    double P[3];
    ccn_status st = CCN_OK;
    double (*sp)[5][3] = malloc(sizeof *sp * (size_t)(nsp + 1)); /* spoke curves from w */
    double (*nb)[6][4][4][3] = malloc(sizeof *nb * (size_t)(nfan ? nfan : 1)); /* N1 N2 M1 M2 A B */
    ccn__fill_block *bk = malloc(sizeof *bk * (size_t)(nfan ? nfan : 1));
    double (*N)[3] = malloc(sizeof *N * (size_t)(nfan ? nfan : 1)); /* per fan face: its sector's */
    double (*Ns)[3] = malloc(sizeof *Ns * (size_t)(nsp + 1));      /* per spoke */
    uint8_t *sharp = malloc((size_t)nsp + 1);                         /* C0 spokes */
    uint8_t *filled = malloc((size_t)nfan + 1); /* fan faces in irregular sectors: filled */
    uint8_t *smooth = malloc((size_t)nsp + 1);  /* spokes measured for G1 */
    double (*cs)[5][5][3] = NULL; /* the fills' poles, per sector */
    double (*q)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3] = NULL, (*qc)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3] = NULL; /* their exactly G1 form, a candidate */
    if (!sp || !nb || !bk || !N || !Ns || !sharp || !filled || !smooth) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); goto done; }
    if ((st = vertex_limit(fl, w, P, N, err))) goto done;
    for (int32_t k = 0; k < nsp; k++) {
        sharp[k] = (bnd && (k == 0 || k == nsp - 1)) || ccn__edge_splits(m, ccn__fan_edge(m, w, k));
        nsharp += sharp[k];
        memcpy(Ns[k], N[k < nfan ? k : nfan - 1], sizeof Ns[k]); /* a smooth spoke's faces share a sector */
    }
    int dart = !bnd && nsharp == 1; /* its sharp spoke: C0, but no B-spline curve at w */
    if (!dart && nsharp >= 2) corner_planes(m, w, P, nfan, nsp, bnd, sharp, v->pinned, Ns);
    /* a regular sector of w (a crease's two-face side, a corner's one-face side) has its exact
     * pieces already: only the fan faces of irregular sectors are filled */
    for (int32_t k = 0; k < nfan; k++) filled[k] = !ccn__sector_regular(m, w, k, v->pinned);
    for (int32_t k = 0; k < nfan; k++) {
        if (!filled[k]) continue;
        ccn__fill_sector_block(m, m->vfan[m->vfan_start[w] + k], &bk[k]);
        const int32_t cells[6] = {bk[k].N1, bk[k].N2, bk[k].M1, bk[k].M2, bk[k].A, bk[k].B};
        int ok = ccn__fsize(m, m->hface[bk[k].g]) == 4 && bk[k].D >= 0;
        for (int q = 0; q < 6 && ok; q++) ok = ccn__fill_cell_patch(m, cells[q], v->pinned, nb[k][q]);
        if (!ok) {
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_VERTEX, w,
                           "the faces around a hole's vertex are not regular enough to fill");
            goto done;
        }
    }
    cs = malloc(sizeof *cs * 2 * (size_t)(nfan ? nfan : 1));
    if (!cs) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); goto done; }
    /* the spokes' inner poles (c10 = P + b (c20 - P) or 2 c20 - c30, in the tangent plane):
     * for the bicubic fill the first five candidates, the one with the smallest measured normal
     * deviation across the spokes; for the exactly G1 fill (io/fill_g1.c) every candidate, the
     * one of least thin-plate energy (the tangents' length sets the curvature near the vertex:
     * measured on random stars with spoke ratios up to 10, the fill's largest |K| varies 10- to
     * 100-fold over b = 0.05 .. 0.9, lowest near 0.2 - 0.3 where the energy is least too). Above
     * 16 spokes (a solve costs 0.1 s and grows with their cube) b = 0.3 only. */
    static const double BETA[9] = {-1, 0.3, 0.5, 0.7, 0.9, 0.15, 0.2, 0.25, 0.4};
    double best = INFINITY, (*cbest)[5][5][3] = cs + nfan, qbest = INFINITY, qdev = INFINITY;
    for (int cand = 0; cand < 9; cand++) {
        double beta = BETA[cand];
        for (int32_t k = 0; k < nsp; k++) { /* spoke k: sector k's u-axis, sector k-1's v-axis */
            double (*c)[3] = sp[k], L[5][3], S[5][3];
            int32_t km = bnd ? k - 1 : (k + nfan - 1) % nfan;
            int own = k < nfan && filled[k]; /* else from sector k-1's v-side */
            if (!own && (km < 0 || !filled[km])) continue; /* no fill on either side */
            if (own) { /* from sector k's cells N1 (and N2) across u = 2 */
                ccn__fill_side_poles((const double(*)[4][3])nb[k][0], (const double(*)[4][3])nb[k][1], 0, 0, S);
                ccn__fill_side_poles((const double(*)[4][3])nb[k][0], (const double(*)[4][3])nb[k][1], 0, 1, L);
            } else { /* sector k-1's cells M1, M2 across v = 2 */
                ccn__fill_side_poles((const double(*)[4][3])nb[km][2], (const double(*)[4][3])nb[km][3], 1, 0, S);
                ccn__fill_side_poles((const double(*)[4][3])nb[km][2], (const double(*)[4][3])nb[km][3], 1, 1, L);
            }
            memcpy(c[4], S[0], sizeof c[4]);
            memcpy(c[3], L[0], sizeof c[3]);
            memcpy(c[0], P, sizeof P);
            if (sharp[k] && !dart) { /* the boundary or crease curve: exact */
                /* second span = the row of cell A of sector k along it / the column of cell B
                 * of sector k-1 */
                const double (*E)[4][3] = (const double(*)[4][3])(own ? nb[k][4] : nb[km][5]);
                double e2[4][3];
                for (int q = 0; q < 4; q++) memcpy(e2[q], own ? E[q][0] : E[0][q], sizeof e2[q]);
                double b1[3], b2[3];
                crease_poles(m, w, k, v->pinned, b1, b2);
                for (int d = 0; d < 3; d++) {
                    c[1][d] = b1[d];
                    c[2][d] = 0.5 * ((2 * b2[d] - b1[d]) + (2 * e2[1][d] - e2[2][d]));
                    c[3][d] = e2[2][d];
                    c[4][d] = e2[3][d];
                }
            } else {
                double X[3];
                for (int d = 0; d < 3; d++) c[2][d] = 2 * c[3][d] - c[4][d];
                for (int d = 0; d < 3; d++) X[d] = beta < 0 ? 2 * c[2][d] - c[3][d] - P[d] : beta * (c[2][d] - P[d]);
                double t = dot3(X, Ns[k]);
                for (int d = 0; d < 3; d++) c[1][d] = P[d] + X[d] - t * Ns[k][d];
            }
        }
        if (!bnd && nsharp == 0 && m->vsharp && m->vsharp[w] > 0) {
            /* a cone point (the vertex pinned, no sharp edge): the limit has no tangent plane
             * there, so no two ordinary patch corners meeting at it are G1 across their spoke
             * (their corner normals would have to agree). The corners are degenerate instead:
             * every spoke leaves the apex with zero first derivative, so near it a sector is
             * P + u^2 A + 2uv B + v^2 C, a quadratic cone whose normal along a spoke comes from
             * second-order poles, which the spoke planes below make agree (measured: 0.35-0.75
             * rad across the spokes with the spokes' tangents, 5e-12 - 1e-10 rad so) */
            for (int32_t k = 0; k < nsp; k++) memcpy(sp[k][1], P, sizeof P);
        }
        if (nsp == 2 && nfan == 2 && !bnd && !sharp[0] && !sharp[1] && filled[0] && filled[1]) {
            /* an interior valence-2 vertex: its sectors are half-planes, so its two spokes must
             * leave it along one line (a patch's corner cannot open wider than pi: with the
             * limit's tangents, 170-190 degrees apart, one sector folds over the other, and no
             * G1 relation with beta > 0 holds at the vertex); the line bisects them, in the
             * tangent plane */
            double t0[3], t1[3], e[3], l0, l1, le;
            for (int d = 0; d < 3; d++) t0[d] = sp[0][1][d] - P[d], t1[d] = sp[1][1][d] - P[d];
            l0 = sqrt(dot3(t0, t0)), l1 = sqrt(dot3(t1, t1));
            for (int d = 0; d < 3; d++) e[d] = t0[d] / l0 - t1[d] / l1;
            le = sqrt(dot3(e, e));
            if (l0 > 0 && l1 > 0 && le > 0)
                for (int d = 0; d < 3; d++) sp[0][1][d] = P[d] + l0 * e[d] / le, sp[1][1][d] = P[d] - l1 * e[d] / le;
        }
        for (int32_t k = 0; k < nfan; k++) {
            double (*c)[5][3] = cs[k];
            memset(c, 0, sizeof cs[k]);
            if (!filled[k]) continue;
            ccn__fill_sector_border((const double(*)[4][4][3])nb[k], c);
            for (int q = 0; q < 5; q++) { /* spokes exactly (shared with the next sector) */
                memcpy(c[q][0], sp[k][q], sizeof c[q][0]);
                memcpy(c[0][q], sp[(k + 1) % nsp][q], sizeof c[0][q]);
            }
        }
        spoke_planes(nb, cs, nfan, nsp, sharp, filled, Ns);
        double dev = spoke_deviation(cs, nfan, nsp, sharp, filled, smooth);
        if (cand < 5 && (dev < best || cand == 0)) {
            best = dev;
            memcpy(cbest, cs, sizeof *cs * (size_t)nfan);
        }
        if (!(dev > CCN_FILL_G1_EXACT) || (nsp > 16 && cand != 1)) continue;
        if (!qc) qc = malloc(sizeof *qc * (size_t)nfan);
        if (!q) q = malloc(sizeof *q * (size_t)nfan);
        double dq, en;
        int r = q && qc ? ccn__fill_g1((const double(*)[5][5][3])cs, nfan, nsp, sharp, filled, qc, &dq, &en) : -1;
        if (r < 0) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)"); goto done; }
        /* exact ones by energy; while none is, the least deviation */
        int exact = dq <= CCN_FILL_G1_TARGET, have = qdev <= CCN_FILL_G1_TARGET;
        if (r && (exact ? !have || en < qbest : !have && dq < qdev)) {
            double (*t)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3] = q;
            q = qc, qc = t;
            qdev = dq, qbest = en;
        }
    }
    memcpy(cs, cbest, sizeof *cs * (size_t)nfan);
    /* exactly G1 across the smooth spokes where the bicubic fill is not: kept when it deviates
     * less */
    if (q && qdev < best) {
        best = qdev;
    } else {
        free(q);
        q = NULL;
    }
    if (spoke_dev) *spoke_dev = best;
    static const double K[9] = {0, 0, 0, 0, 1, 2, 2, 2, 2}, KQ[15] = CCN_FILL_G1_KNOTS;
    for (int32_t k = 0; k < nfan && !st; k++) {
        if (!filled[k]) continue;
        double (*c)[5][3] = cs[k];
        int32_t g = m->hface[bk[k].g], r = bk[k].g - m->fstart[g];
        ccn__xplace q1, q2;
        ccn__xplace_rotate(&fpl[g], r, &q1); /* the sector's [0,1]^2: its face at w */
        double twice[3][2] = {{0, 0}, {2, 0}, {0, 2}};
        ccn__xplace_sub(&q1, (const double(*)[2])twice, &q2);
        int deg = q ? 5 : 3, np = q ? CCN_FILL_G1_POLES : 5;
        double *poles = q ? &q[k][0][0][0] : &c[0][0][0];
        to_caller(v, poles, np * np);
        int32_t f = ccn__xm_add_face(xm, CCN_EXPORT_FACE_FILL, deg, deg, np, np, 1, 1);
        if (f < 0 || ccn__xm_set_flat(xm, f, 0, q ? KQ : K) || ccn__xm_set_flat(xm, f, 1, q ? KQ : K)) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (fill)");
            break;
        }
        memcpy((void *)xm->faces[f].s.poles, poles, sizeof(double) * 3 * (size_t)(np * np));
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
    free(N);
    free(Ns);
    free(sharp);
    free(filled);
    free(smooth);
    free(cs);
    free(q);
    free(qc);
    return st;
}

