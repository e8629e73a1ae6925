/* Exact limit position and tangents of a refined vertex, as a stencil over its neighbours.
 *
 * Used on the last refinement level R = L+1 (or deeper), where every output vertex except
 * an irregular vertex itself is at least two rings away from any irregular vertex, so its
 * 1-ring refines by tensor knot insertion forever and its limit is the B-spline value at
 * its knot (and the derivatives there):
 *  - interior valence 4: tensor product of the 1-D limit stencils below;
 *  - boundary valence 3 and pinned corners: the same with mirrored ghost points
 *    P(i,-1) = 2P(i,0) - P(i,1) (the boundary is the B-spline of the mirror extension,
 *    SPEC [1d]);
 *  - other boundary vertices (smooth corners, boundary EVs), crease, corner and dart
 *    vertices, interior valence 2, and vertices whose edges still carry semi-sharp values:
 *    the stationary 1-ring matrix of surface/ring_limit.c (exact position and one exact
 *    tangent plane per sector between sharp edges); for valences above
 *    CCN_RING_MAX_VALENCE at a boundary, the boundary curve's limit with the cross-boundary
 *    tangent approximated by the direction to the interior neighbours;
 *  - smooth interior EVs: left eigenvectors of the refinement matrix M of the 1-ring
 *    (stationary from level 1): eigenvalue 1 gives the limit point, the subdominant pair the
 *    tangents, oriented by the characteristic map (right eigenvectors).
 *
 * 1-D limit at knot t_0 of a cubic B-spline with control points P_-1, P_0, P_1 (blossoms
 * f(t_-2,t_-1,t_0), f(t_-1,t_0,t_1), f(t_0,t_1,t_2)) and intervals D_-2, D_-1, D_0, D_1:
 *   A = f(t_-1,t_0,t_0) = P_-1 + a (P_0 - P_-1),  a = (D_-2 + D_-1)/(D_-2 + D_-1 + D_0)
 *   B = f(t_0,t_0,t_1)  = P_0 + b (P_1 - P_0),    b = D_-1/(D_-1 + D_0 + D_1)
 *   f(t_0) = A + g (B - A), g = D_-1/(D_-1 + D_0);  f'(t_0) = 3 (B - A)/(D_-1 + D_0).
 */
#include "surface/limit.h"

#include "base/error.h"
#include "rules/bspline.h"
#include "rules/crease.h"
#include "surface/ev_circulant.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

static ccn__vpoint vp1(int32_t v) {
    ccn__vpoint p = {{v, 0, 0, 0}, {1, 0, 0, 0}, 1};
    return p;
}

/* 2a - b */
static ccn__vpoint mirror(ccn__vpoint a, ccn__vpoint b) {
    ccn__vpoint p = a;
    for (int i = 0; i < p.n; i++) p.w[i] *= 2;
    for (int i = 0; i < b.n; i++) { p.v[p.n] = b.v[i]; p.w[p.n] = -b.w[i]; p.n++; }
    return p;
}

static void stencil_add(ccn__stencil *s, int32_t v, double wp, double wu, double wv) {
    for (int i = 0; i < s->n; i++)
        if (s->v[i] == v) { s->wp[i] += wp; s->wu[i] += wu; s->wv[i] += wv; return; }
    if (s->n >= CCN_STENCIL_MAX) return; /* cannot happen for the shapes built here */
    s->v[s->n] = v; s->wp[s->n] = wp; s->wu[s->n] = wu; s->wv[s->n] = wv; s->n++;
}

/* End vertex of the k-th fan edge of v (k may be the boundary's last edge). */
static int32_t fan_end(const ccn_mesh *m, int32_t v, int32_t k) {
    int32_t e = ccn__fan_edge(m, v, k);
    return m->everts[2 * e] == v ? m->everts[2 * e + 1] : m->everts[2 * e];
}
/* Diagonal vertex of fan face k. */
static int32_t fan_diag(const ccn_mesh *m, int32_t v, int32_t k) {
    int32_t h = m->vfan[m->vfan_start[v] + k];
    return m->hvert[ccn__next(m, ccn__next(m, h))];
}
/* Interval straight beyond the end of fan edge k (away from v): the far end and the edge's
 * place in its fan through the twin where there is one. */
static double beyond_end(const ccn_mesh *m, int32_t v, int32_t k, int pinned) {
    int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v];
    if (k < nfan) {
        int32_t h = m->vfan[m->vfan_start[v] + k], t = m->htwin[h];
        if (t >= 0) return ccn__beyond(m, m->hvert[t], m->hfanpos[t], pinned);
        return ccn__beyond(m, fan_end(m, v, k), ccn__pos_at_end(m, h), pinned);
    }
    /* the incoming boundary edge is its origin's outgoing boundary edge */
    return ccn__beyond(m, fan_end(m, v, k), 0, pinned);
}

/* Tensor stencil over a 3x3 grid of virtual points g[i+1][j+1], i along u, j along v. */
static void tensor_stencil(ccn__vpoint g[3][3], const double wu[3], const double dwu[3],
                           const double wv[3], const double dwv[3], ccn__stencil *s) {
    s->n = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < g[i][j].n; k++) {
                double c = g[i][j].w[k];
                stencil_add(s, g[i][j].v[k], c * wu[i] * wv[j], c * dwu[i] * wv[j],
                            c * wu[i] * dwv[j]);
            }
}

/* Fan edge of slot s (0: +u, 1: +v, 2: -u, 3: -v) for a grid whose +u is fan edge k0; -1
 * when the slot does not exist (boundary: mirrored). */
static int32_t slot_edge(const ccn_mesh *m, int32_t v, int32_t k0, int s) {
    int32_t n = ccn__valence(m, v), k = s == 3 ? k0 - 1 : k0 + s;
    if (!m->vboundary[v]) return (k % n + n) % n;
    return k >= 0 && k < n ? k : -1;
}

/* Does fan edge k of v bound a sector (a boundary edge, or sharp enough to split the look-ups,
 * rules/bspline.c)? */
static int sector_edge(const ccn_mesh *m, int32_t v, int32_t k) {
    int32_t n = ccn__valence(m, v);
    if (m->vboundary[v] && (k == 0 || k == n - 1)) return 1;
    return ccn__edge_splits(m, ccn__fan_edge(m, v, k));
}

void ccn__fan_sector(const ccn_mesh *m, int32_t v, int32_t k, int32_t *first, int32_t *count) {
    int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v], n = ccn__valence(m, v), splits = 0;
    for (int32_t j = 0; m->esharp && j < n; j++) splits += sector_edge(m, v, j);
    if (m->vboundary[v] ? splits <= 2 : splits < 2) { /* the whole fan */
        *first = 0;
        *count = nfan;
        return;
    }
    int32_t a = k, b = k + 1; /* fan faces a .. b-1; walk to the bounding edges a and b */
    while (!sector_edge(m, v, (a % n + n) % n)) a--;
    while (!sector_edge(m, v, b % n)) b++;
    *first = (a % n + n) % n;
    *count = b - a;
}

int ccn__sector_regular(const ccn_mesh *m, int32_t v, int32_t k, int pinned) {
    int kind = ccn__limit_kind(m, v, pinned);
    if (kind == CCN_LIMIT_REGULAR) return 1;
    if (kind != CCN_LIMIT_RING || !m->esharp) return 0;
    int32_t n = ccn__valence(m, v), ns = 0;
    float vs = ccn__vertex_sharpness(m, v, pinned);
    if (vs > 0.0f && vs < CCN_SHARP_INF) return 0; /* semi-sharp: its rule still changes */
    for (int32_t j = 0; j < n; j++) {
        int bnd = m->vboundary[v] && (j == 0 || j == n - 1);
        float s = bnd ? CCN_SHARP_INF : m->esharp[ccn__fan_edge(m, v, j)];
        if (s > 0.0f && s < CCN_SHARP_INF) return 0;
        ns += s >= CCN_SHARP_INF;
    }
    if (ns < 2) return 0; /* a dart, or a cone (vertex sharpness only) */
    int32_t first, count;
    ccn__fan_sector(m, v, k, &first, &count);
    /* a corner's one-face sector is a pinned corner, a crease's two-face sector a boundary
     * vertex of valence 3: both refine by knot insertion with mirrored ghosts */
    return ns >= 3 || vs >= CCN_SHARP_INF ? count == 1 : count == 2;
}

void ccn__vertex_grid(const ccn_mesh *m, int32_t v, int32_t k0, int pinned, ccn__vgrid *g) {
    int32_t sl[4];
    for (int s = 0; s < 4; s++) sl[s] = slot_edge(m, v, k0, s);
    int32_t first = 0, count = 0;
    if (m->esharp) ccn__fan_sector(m, v, k0, &first, &count);
    if (m->esharp && count < m->vfan_start[v + 1] - m->vfan_start[v]) {
        /* the sector of fan face k0 between sharp edges, as if those edges were the boundary:
         * its edges first .. first+count are the fan of a boundary vertex */
        int32_t n = ccn__valence(m, v), rel = ((k0 - first) % n + n) % n;
        for (int s = 0; s < 4; s++) {
            int32_t k = s == 3 ? rel - 1 : rel + s;
            sl[s] = k >= 0 && k <= count ? (first + k) % n : -1;
        }
    }
    /* fan face k lies between fan edges k and k+1: quadrant (+u,+v) is face sl[0],
     * (-u,+v) face sl[1], (-u,-v) face sl[2], (+u,-v) face sl[3] */
    ccn__vpoint (*p)[3] = g->p;
    int has2 = sl[2] >= 0, has3 = sl[3] >= 0;
    p[1][1] = vp1(v);
    p[2][1] = vp1(fan_end(m, v, sl[0]));
    p[1][2] = vp1(fan_end(m, v, sl[1]));
    p[2][2] = vp1(fan_diag(m, v, sl[0]));
    if (has2) {
        p[0][1] = vp1(fan_end(m, v, sl[2]));
        p[0][2] = vp1(fan_diag(m, v, sl[1]));
    } else {
        p[0][1] = mirror(p[1][1], p[2][1]);
        p[0][2] = mirror(p[1][2], p[2][2]);
    }
    if (has3) {
        p[1][0] = vp1(fan_end(m, v, sl[3]));
        p[2][0] = vp1(fan_diag(m, v, sl[3]));
        p[0][0] = has2 ? vp1(fan_diag(m, v, sl[2])) : mirror(p[1][0], p[2][0]);
    } else {
        for (int i = 0; i < 3; i++) p[i][0] = mirror(p[i][1], p[i][2]);
    }
    double d0 = m->eknot[ccn__fan_edge(m, v, sl[0])], e0 = m->eknot[ccn__fan_edge(m, v, sl[1])];
    double d1 = beyond_end(m, v, sl[0], pinned), e1 = beyond_end(m, v, sl[1], pinned);
    g->du[2] = d0; g->du[3] = d1;
    g->du[1] = sl[2] >= 0 ? m->eknot[ccn__fan_edge(m, v, sl[2])] : d0;
    g->du[0] = sl[2] >= 0 ? beyond_end(m, v, sl[2], pinned) : d1;
    g->dv[2] = e0; g->dv[3] = e1;
    g->dv[1] = sl[3] >= 0 ? m->eknot[ccn__fan_edge(m, v, sl[3])] : e0;
    g->dv[0] = sl[3] >= 0 ? beyond_end(m, v, sl[3], pinned) : e1;
}

/* An interior valence-4 vertex (most outputs): the grid of ccn__vertex_grid with +u along fan
 * edge 0 (no ghosts, no sectors: its edges are smooth), its weights in tensor_stencil's order
 * and arithmetic (the same numbers); 0 when two grid points are one vertex (a tiny closed
 * mesh), which the general path merges. */
/* The 3 x 3 grid g of an interior valence-4 vertex with +u along fan edge 0 and its intervals
 * (D_-2 .. D_1) along u and v; 0 when two grid points are one vertex. */
static inline int interior_grid(const ccn_mesh *m, int32_t v, int pinned, int32_t g[3][3],
                                double du[4], double dv[4]) {
    int32_t q[3][3] = {{fan_diag(m, v, 2), fan_end(m, v, 2), fan_diag(m, v, 1)},
                       {fan_end(m, v, 3), v, fan_end(m, v, 1)},
                       {fan_diag(m, v, 3), fan_end(m, v, 0), fan_diag(m, v, 0)}};
    const int32_t *gv = &q[0][0];
    int dup = 0; /* without branches: the compiler compares in vectors */
    for (int a = 1; a < 9; a++)
        for (int b = 0; b < a; b++) dup |= gv[a] == gv[b];
    if (dup) return 0;
    memcpy(g, q, sizeof q);
    du[0] = beyond_end(m, v, 2, pinned), du[1] = m->eknot[ccn__fan_edge(m, v, 2)];
    du[2] = m->eknot[ccn__fan_edge(m, v, 0)], du[3] = beyond_end(m, v, 0, pinned);
    dv[0] = beyond_end(m, v, 3, pinned), dv[1] = m->eknot[ccn__fan_edge(m, v, 3)];
    dv[2] = m->eknot[ccn__fan_edge(m, v, 1)], dv[3] = beyond_end(m, v, 1, pinned);
    return 1;
}

static int interior_stencil(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil *s) {
    int32_t g[3][3];
    double du[4], dv[4];
    if (!interior_grid(m, v, pinned, g, du, dv)) return 0;
    double wu[3], dwu[3], wv[3], dwv[3];
    ccn__curve_limit_weights(du[0], du[1], du[2], du[3], wu, dwu);
    ccn__curve_limit_weights(dv[0], dv[1], dv[2], dv[3], wv, dwv);
    s->n = 9;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int k = 3 * i + j;
            s->v[k] = g[i][j];
            s->wp[k] = wu[i] * wv[j];
            s->wu[k] = dwu[i] * wv[j];
            s->wv[k] = wu[i] * dwv[j];
        }
    return 1;
}

/* Interior valence 4, boundary valence 3 or pinned corner. */
static void regular_stencil(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil *s) {
    if (!m->vboundary[v] && interior_stencil(m, v, pinned, s)) return;
    ccn__vgrid g;
    ccn__vertex_grid(m, v, 0, pinned, &g);
    double wu[3], dwu[3], wv[3], dwv[3];
    ccn__curve_limit_weights(g.du[0], g.du[1], g.du[2], g.du[3], wu, dwu);
    ccn__curve_limit_weights(g.dv[0], g.dv[1], g.dv[2], g.dv[3], wv, dwv);
    tensor_stencil(g.p, wu, dwu, wv, dwv, s);
}

/* Smooth corners and boundary EVs: boundary curve limit, interior direction. */
static void boundary_curve_stencil(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil *s) {
    int32_t n = ccn__valence(m, v);
    int32_t next = fan_end(m, v, 0), prev = fan_end(m, v, n - 1);
    double d0 = m->eknot[ccn__fan_edge(m, v, 0)], dm1 = m->eknot[ccn__fan_edge(m, v, n - 1)];
    double d1 = beyond_end(m, v, 0, pinned), dm2 = beyond_end(m, v, n - 1, pinned);
    double w[3], dw[3];
    ccn__curve_limit_weights(dm2, dm1, d0, d1, w, dw);
    s->n = 0;
    int32_t pts[3] = {prev, v, next};
    for (int i = 0; i < 3; i++) stencil_add(s, pts[i], w[i], dw[i], -w[i]);
    /* cross-boundary direction: mean of the interior neighbours (and diagonals) minus the
     * limit point; approximate, see the file comment */
    int32_t cnt = 0, tmp[2 * CCN_STENCIL_MAX];
    for (int32_t k = 1; k < n - 1 && cnt < CCN_STENCIL_MAX; k++) tmp[cnt++] = fan_end(m, v, k);
    for (int32_t k = 0; k < n - 1 && cnt < CCN_STENCIL_MAX; k++) tmp[cnt++] = fan_diag(m, v, k);
    for (int32_t i = 0; i < cnt; i++) stencil_add(s, tmp[i], 0, 0, 1.0 / cnt);
}

int ccn__limit_kind(const ccn_mesh *m, int32_t v, int pinned) {
    if (m->vfan_start[v + 1] == m->vfan_start[v]) return CCN_LIMIT_ISOLATED;
    int32_t n = ccn__valence(m, v);
    if (m->esharp && (ccn__sharp_count(m, v) > (m->vboundary[v] ? 2 : 0) || m->vsharp[v] > 0.0f))
        return CCN_LIMIT_RING;
    if (!m->vboundary[v]) return n == 4 ? CCN_LIMIT_REGULAR : n == 2 ? CCN_LIMIT_RING : CCN_LIMIT_EV;
    if (n == 3 || (n == 2 && pinned)) return CCN_LIMIT_REGULAR;
    return CCN_LIMIT_BOUNDARY_CURVE;
}

int ccn__near_irregular(const ccn_mesh *m, int32_t v, const uint8_t *irregular) {
    if (irregular[v]) return 1;
    for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
        int32_t f = m->hface[m->vfan[k]];
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++)
            if (irregular[m->hvert[h]]) return 1;
    }
    return 0;
}

int ccn__limit_stencil(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil *s) {
    int kind = ccn__limit_kind(m, v, pinned);
    s->n = 0;
    if (kind == CCN_LIMIT_REGULAR) regular_stencil(m, v, pinned, s);
    else if (kind == CCN_LIMIT_BOUNDARY_CURVE) boundary_curve_stencil(m, v, pinned, s);
    else if (kind == CCN_LIMIT_ISOLATED) stencil_add(s, v, 1, 0, 0);
    return kind;
}

/* ---- extraordinary vertices: eigenvectors of M ------------------------------------ */

int32_t ccn__ev_ring(const ccn_mesh *m, int32_t v, int32_t *ring) {
    int32_t n = ccn__valence(m, v);
    for (int32_t k = 0; k < n; k++) {
        int32_t h = m->vfan[m->vfan_start[v] + k], nh = ccn__next(m, h);
        ring[k] = m->hvert[ccn__next(m, nh)];
        ring[n + k] = m->hvert[nh];
    }
    ring[2 * n] = v;
    return 2 * n + 1;
}

/* G = [l_i . r_j] and the ring polygon's area in the characteristic map (r1, r2; stride rs):
 * l2 is negated when their signs disagree (the orientation rule of left_eigvecs) */
static void orient(double *l1, double *l2, const double *r1, const double *r2, size_t rs, int32_t sz) {
    int32_t n = (sz - 1) / 2;
    double area = 0, g11 = 0, g12 = 0, g21 = 0, g22 = 0;
    for (int32_t r = 0; r < sz; r++) {
        g11 += l1[r] * r1[(size_t)r * rs]; g12 += l1[r] * r2[(size_t)r * rs];
        g21 += l2[r] * r1[(size_t)r * rs]; g22 += l2[r] * r2[(size_t)r * rs];
    }
    for (int32_t k = 0; k < 2 * n; k++) { /* polygon E_0, F_0, E_1, F_1, ... */
        int32_t a = k & 1 ? k / 2 : n + k / 2, kb = (k + 1) % (2 * n), b = kb & 1 ? kb / 2 : n + kb / 2;
        area += r1[(size_t)a * rs] * r2[(size_t)b * rs] - r1[(size_t)b * rs] * r2[(size_t)a * rs];
    }
    if ((area < 0) != (g11 * g22 - g12 * g21 < 0))
        for (int32_t r = 0; r < sz; r++) l2[r] = -l2[r];
}

/* Left eigenvectors of M (sz x sz, row-major; ring order F_0..F_{n-1}, E_0..E_{n-1}, V): l0
 * for eigenvalue 1 (sum 1), l1/l2 spanning the subdominant pair (real pair or real/imaginary
 * parts of a complex pair), l2's sign chosen so that (l1.P) x (l2.P) is the outward normal:
 * the ring polygon E_0, F_0, E_1, ... runs counter-clockwise in the characteristic map (the
 * right eigenvectors r1, r2) and G = [l_i . r_j] has positive determinant (see
 * surface/ring_limit.c), whatever the geometry of the net. From valence
 * CCN_EV_CIRCULANT_MIN_VALENCE on, a block-circulant M (equal spokes) takes the Fourier path
 * (surface/ev_circulant.c) instead of dgeev. */
static ccn_status left_eigvecs(const double *M, int32_t sz, double *l0, double *l1, double *l2,
                               ccn_error *err) {
    size_t s2 = (size_t)sz * sz;
    if ((sz - 1) / 2 >= CCN_EV_CIRCULANT_MIN_VALENCE) { /* equal spokes: Fourier blocks, O(n^2) */
        double *r = malloc(sizeof(double) * 2 * (size_t)sz);
        int got = r ? ccn__ev_circulant_eigvecs(M, (sz - 1) / 2, l0, l1, l2, r, r + sz) : -1;
        if (got == 0) orient(l1, l2, r, r + sz, 1, sz);
        free(r);
        if (got < 0) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (EV limit)");
        if (got == 0) return CCN_OK;
    }
    double *A = malloc(sizeof(double) * (3 * s2 + 2 * (size_t)sz));
    if (!A) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (EV limit)");
    double *VL = A + s2, *VR = VL + s2, *wr = VR + s2, *wi = wr + sz;
    memcpy(A, M, sizeof(double) * s2);
    lapack_int info = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'V', 'V', sz, A, sz, wr, wi, VL, sz,
                                    VR, sz);
    if (info != 0) {
        free(A);
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "eigen decomposition failed");
    }
    int32_t i0 = 0;
    for (int32_t i = 1; i < sz; i++)
        if (fabs(wr[i] - 1) + fabs(wi[i]) < fabs(wr[i0] - 1) + fabs(wi[i0])) i0 = i;
    int32_t i1 = -1, i2 = -1;
    for (int32_t i = 0; i < sz; i++) {
        if (i == i0) continue;
        double mod = hypot(wr[i], wi[i]);
        if (i1 < 0 || mod > hypot(wr[i1], wi[i1])) { i2 = i1; i1 = i; }
        else if (i2 < 0 || mod > hypot(wr[i2], wi[i2])) i2 = i;
    }
    double sum = 0;
    for (int32_t r = 0; r < sz; r++) sum += VL[(size_t)r * sz + i0];
    int cplx = wi[i1] != 0.0;
    if (cplx && wi[i1] < 0) i1 = i1 - 1; /* LAPACK stores a pair as (re, im) columns i, i+1 */
    int32_t j2 = cplx ? i1 + 1 : i2;
    for (int32_t r = 0; r < sz; r++) {
        l0[r] = VL[(size_t)r * sz + i0] / sum;
        l1[r] = VL[(size_t)r * sz + i1];
        l2[r] = VL[(size_t)r * sz + j2];
    }
    orient(l1, l2, VR + i1, VR + j2, (size_t)sz, sz);
    free(A);
    if (!(fabs(sum) > 1e-300))
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "no eigenvalue 1 in M");
    return CCN_OK;
}

static ccn_status ev_limit_ring(const ccn_mesh *m, int32_t v, int scheme, int child,
                               int32_t ev_poly, ccn__ev_cache *cache, ccn__stencil *s,
                               ccn_error *err);

ccn_status ccn__ev_limit(const ccn_mesh *m, int32_t v, int scheme, int32_t ev_poly,
                         ccn__ev_cache *cache, ccn__stencil *s, ccn_error *err) {
    return ev_limit_ring(m, v, scheme, 0, ev_poly, cache, s, err);
}

/* child: the ring is that of v's vertex point one level finer (same spoke ratios). M is the
 * refinement's own (the same polyhedron choice, from the owner's cache). */
static ccn_status ev_limit_ring(const ccn_mesh *m, int32_t v, int scheme, int child,
                               int32_t ev_poly, ccn__ev_cache *cache, ccn__stencil *s,
                               ccn_error *err) {
    int32_t n = ccn__valence(m, v), sz = 2 * n + 1;
    if (sz > CCN_STENCIL_MAX)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, v,
                         "vertex %d has valence %d; at most %d is supported for limits", (int)v,
                         (int)n, (CCN_STENCIL_MAX - 1) / 2);
    double *buf = malloc(sizeof(double) * ((size_t)sz * sz + 4 * (size_t)sz));
    int32_t ring[CCN_STENCIL_MAX];
    if (!buf) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (EV limit)");
    double *M = buf, *d = M + (size_t)sz * sz, *l0 = d + sz, *l1 = l0 + sz, *l2 = l1 + sz;
    for (int32_t k = 0; k < n; k++) d[k] = m->eknot[ccn__fan_edge(m, v, k)];
    ccn_status st = ccn__ev_matrix_cached(n, d, (ccn_scheme)scheme, ev_poly, cache, M, NULL, err);
    if (!st) st = left_eigvecs(M, sz, l0, l1, l2, err);
    if (!st) {
        ccn__ev_ring(m, v, ring);
        if (child) {
            for (int32_t k = 0; k < n; k++) {
                int32_t h = m->vfan[m->vfan_start[v] + k];
                ring[k] = m->hface[h];           /* face point */
                ring[n + k] = m->nf + m->hedge[h]; /* edge point */
            }
            ring[2 * n] = m->nf + m->ne + v;
        }
        s->n = 0;
        for (int32_t j = 0; j < sz; j++) stencil_add(s, ring[j], l0[j], l1[j], l2[j]);
    }
    free(buf);
    return st;
}

/* ---- stencils one level finer, from this level's topology ------------------------ */
/* Level l+1 numbering: face point f -> f, edge point e -> nf + e, vertex point v -> nf+ne+v.
 * Around the vertex point of v every interval along a spoke is the spoke's (halved: only
 * ratios matter), so no level-(l+1) topology is needed. */

/* The 3 x 3 grid around the vertex point of v one level finer (level-(l+1) numbering) and
 * its intervals along u and v (D_-2, D_-1, D_0, D_1), as child_regular uses them. */
static void child_grid(const ccn_mesh *m, int32_t v, ccn__vpoint p[3][3], double du[4],
                       double dv[4]) {
    int32_t sl[4];
    for (int k = 0; k < 4; k++) sl[k] = slot_edge(m, v, 0, k);
    int has2 = sl[2] >= 0, has3 = sl[3] >= 0;
    int32_t nf = m->nf, ne = m->ne;
#define CE(k) vp1(nf + ccn__fan_edge(m, v, k))
#define CF(k) vp1(m->hface[m->vfan[m->vfan_start[v] + (k)]])
    p[1][1] = vp1(nf + ne + v);
    p[2][1] = CE(sl[0]);
    p[1][2] = CE(sl[1]);
    p[2][2] = CF(sl[0]);
    if (has2) { p[0][1] = CE(sl[2]); p[0][2] = CF(sl[1]); }
    else { p[0][1] = mirror(p[1][1], p[2][1]); p[0][2] = mirror(p[1][2], p[2][2]); }
    if (has3) {
        p[1][0] = CE(sl[3]);
        p[2][0] = CF(sl[3]);
        p[0][0] = has2 ? CF(sl[2]) : mirror(p[1][0], p[2][0]);
    } else {
        for (int i = 0; i < 3; i++) p[i][0] = mirror(p[i][1], p[i][2]);
    }
#undef CE
#undef CF
    double d0 = m->eknot[ccn__fan_edge(m, v, sl[0])], d1 = m->eknot[ccn__fan_edge(m, v, sl[1])];
    double d2 = has2 ? m->eknot[ccn__fan_edge(m, v, sl[2])] : d0;
    double d3 = has3 ? m->eknot[ccn__fan_edge(m, v, sl[3])] : d1;
    du[0] = du[1] = d2; du[2] = du[3] = d0;
    dv[0] = dv[1] = d3; dv[2] = dv[3] = d1;
}

static void child_regular(const ccn_mesh *m, int32_t v, ccn__stencil *s) {
    ccn__vpoint p[3][3];
    double du[4], dv[4], wu[3], dwu[3], wv[3], dwv[3];
    child_grid(m, v, p, du, dv);
    ccn__curve_limit_weights(du[0], du[1], du[2], du[3], wu, dwu);
    ccn__curve_limit_weights(dv[0], dv[1], dv[2], dv[3], wv, dwv);
    tensor_stencil(p, wu, dwu, wv, dwv, s);
}

/* ---- second derivatives (curvature) ------------------------------------------------- */

static void stencil2_add(ccn__stencil2 *s, int32_t v, const double w[5]) {
    int k = 0;
    while (k < s->n && s->v[k] != v) k++;
    if (k == s->n) {
        if (s->n == CCN_STENCIL2_MAX) return; /* cannot happen: 9 grid points of <= 4 vertices */
        s->v[s->n++] = v;
        for (int c = 0; c < 5; c++) s->w[c][k] = 0.0;
    }
    for (int c = 0; c < 5; c++) s->w[c][k] += w[c];
}

/* Tensor product of the 1-D weights of ccn__curve_limit_weights2 over the grid g: S_u, S_v,
 * S_uu, S_uv, S_vv at the grid's centre. */
static void tensor_stencil2(ccn__vpoint g[3][3], const double du[4], const double dv[4],
                            ccn__stencil2 *s) {
    double wu[3], dwu[3], ddwu[3], wv[3], dwv[3], ddwv[3];
    ccn__curve_limit_weights2(du[0], du[1], du[2], du[3], wu, dwu, ddwu);
    ccn__curve_limit_weights2(dv[0], dv[1], dv[2], dv[3], wv, dwv, ddwv);
    s->n = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < g[i][j].n; k++) {
                double c = g[i][j].w[k];
                double w[5] = {c * dwu[i] * wv[j], c * wu[i] * dwv[j], c * ddwu[i] * wv[j],
                               c * dwu[i] * dwv[j], c * wu[i] * ddwv[j]};
                stencil2_add(s, g[i][j].v[k], w);
            }
}

/* An interior valence-4 vertex without sharp edges: interior_stencil's grid, 9 distinct points
 * (0 when two are one vertex: the general path merges them). */
static int interior_stencil2(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil2 *s) {
    int32_t g[3][3];
    double du[4], dv[4], wu[3], dwu[3], ddwu[3], wv[3], dwv[3], ddwv[3];
    if (!interior_grid(m, v, pinned, g, du, dv)) return 0;
    ccn__curve_limit_weights2(du[0], du[1], du[2], du[3], wu, dwu, ddwu);
    ccn__curve_limit_weights2(dv[0], dv[1], dv[2], dv[3], wv, dwv, ddwv);
    s->n = 9;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int k = 3 * i + j;
            s->v[k] = g[i][j];
            s->w[0][k] = dwu[i] * wv[j];
            s->w[1][k] = wu[i] * dwv[j];
            s->w[2][k] = ddwu[i] * wv[j];
            s->w[3][k] = dwu[i] * dwv[j];
            s->w[4][k] = wu[i] * ddwv[j];
        }
    return 1;
}

int ccn__curvature_stencil(const ccn_mesh *m, int32_t v, int pinned, int child,
                           ccn__stencil2 *s) {
    s->n = 0;
    if (ccn__limit_kind(m, v, pinned) != CCN_LIMIT_REGULAR) return 0;
    if (!child && !m->vboundary[v] && !m->esharp && interior_stencil2(m, v, pinned, s)) return 1;
    ccn__vpoint p[3][3];
    if (child) {
        double du[4], dv[4];
        child_grid(m, v, p, du, dv);
        tensor_stencil2(p, du, dv, s);
    } else {
        ccn__vgrid g;
        ccn__vertex_grid(m, v, 0, pinned, &g);
        tensor_stencil2(g.p, g.du, g.dv, s);
    }
    return 1;
}

static void child_boundary_curve(const ccn_mesh *m, int32_t v, ccn__stencil *s) {
    int32_t n = ccn__valence(m, v), nf = m->nf, nfan = m->vfan_start[v + 1] - m->vfan_start[v];
    double d0 = m->eknot[ccn__fan_edge(m, v, 0)], dm = m->eknot[ccn__fan_edge(m, v, n - 1)];
    double w[3], dw[3];
    ccn__curve_limit_weights(dm, dm, d0, d0, w, dw);
    s->n = 0;
    int32_t pts[3] = {nf + ccn__fan_edge(m, v, n - 1), nf + m->ne + v, nf + ccn__fan_edge(m, v, 0)};
    for (int i = 0; i < 3; i++) stencil_add(s, pts[i], w[i], dw[i], -w[i]);
    int32_t cnt = (n - 2) + nfan;
    for (int32_t k = 1; k < n - 1; k++) stencil_add(s, nf + ccn__fan_edge(m, v, k), 0, 0, 1.0 / cnt);
    for (int32_t k = 0; k < nfan; k++) stencil_add(s, m->hface[m->vfan[m->vfan_start[v] + k]], 0, 0, 1.0 / cnt);
}

ccn_status ccn__child_limit_stencil(const ccn_mesh *m, int32_t v, int pinned, int scheme,
                                    int crease_method, ccn__ring_work *w, ccn__stencil *s,
                                    ccn__ring_limit *ring, ccn_error *err) {
    int kind = ccn__limit_kind(m, v, pinned);
    s->n = 0;
    if (ring) ring->nsec = 0;
    if (kind == CCN_LIMIT_REGULAR) child_regular(m, v, s);
    else if (kind == CCN_LIMIT_ISOLATED) stencil_add(s, m->nf + m->ne + v, 1, 0, 0);
    else if (kind == CCN_LIMIT_EV) {
        int32_t ev_poly;
        ccn__ev_cache *cache;
        ccn__ring_work_ev(w, &ev_poly, &cache);
        return ev_limit_ring(m, v, scheme, 1, ev_poly, cache, s, err);
    }
    else if (ccn__valence(m, v) > CCN_RING_MAX_VALENCE || !w || !ring) {
        if (kind == CCN_LIMIT_BOUNDARY_CURVE) child_boundary_curve(m, v, s);
        else stencil_add(s, m->nf + m->ne + v, 1, 0, 0); /* huge creased valence: the point */
    } else {
        ccn_status st = ccn__ring_limit_eval(m, v, scheme, pinned, crease_method, w, ring, err);
        if (st) return st;
        for (int32_t i = 0; i < ring->npts; i++) /* sector 0's tangents for the stencil */
            stencil_add(s, ring->pts[i], ring->wp[i], ring->wu[i], ring->wv[i]);
    }
    return CCN_OK;
}
