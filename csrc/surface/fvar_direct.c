/* Face-varying limit weights of regular faces, written down (surface/fvar_direct.h).
 *
 * A level-0 face f of a channel's value mesh is written down when it is a quad and the value
 * vertices of the faces around its corners (its 4 x 4 block) are distinct and lie on a grid of
 * quads: interior valence-4 value vertices, with no sharp edge, no vertex sharpness, no corner
 * kept by the mode and no dependent sharpness, except along straight boundary lines of the
 * value mesh (UV seams and the mesh boundary), whose vertices are smooth valence-3 boundary
 * vertices and, where two lines meet, pinned valence-2 corners. Then every rule that reaches
 * the limit over f is the tensor product of the knot-insertion curve rules (rules/bspline.c,
 * DESIGN §4.2, Li 2016 eqs (5)-(7)) with the ring intervals: each level inserts the midpoint
 * knot of every interval, and the limit of a level-L vertex is the surface at its knot. At a
 * boundary line the crease rules are those of the grid point-reflected across it
 * (P_-k = 2 P_0 - P_k, intervals mirrored; the boundary curve is the cubic B-spline of its
 * polygon, DESIGN §4.2), which the refinement keeps. So the limit over f is the bicubic
 * B-spline patch of the (reflected) block, with the knot vectors of the five rings that cross
 * it in each direction (the block's three and the one beyond on either side; the ring
 * interval beyond an interior valence-4 vertex is that of the opposite spoke, as the rules
 * look it up, along a boundary the next boundary edge's, and mirrored at a line), and the
 * weights of an output value at (u, v) in f are N_i(u) N_j(v) (de Boor's basis functions,
 * Piegl & Tiller A2.2), with a reflected point's weight folded onto the two it is made of,
 * computed once instead of probing the refinement.
 * The probed weights are the same numbers summed in another order (a few ulps).
 */
#include "surface/fvar_direct.h"

#include "rules/bspline.h"
#include "rules/crease.h"
#include "base/parallel.h"

#include <stdlib.h>
#include <string.h>

void ccn__fvar_direct_free(ccn__fvar_direct *d) {
    if (!d) return;
    free(d->slot); free(d->verts); free(d->knots); free(d->fold);
    memset(d, 0, sizeof *d);
}

/* What a value vertex may be inside a written-down block: an interior valence-4 vertex, a
 * smooth boundary vertex of valence 3 (two quads; seams and the mesh boundary alike: the
 * crease rules of its boundary curve), or a pinned corner of valence 2 (one quad, infinitely
 * sharp vertex); every face around it a quad, no sharp interior edge, no vertex sharpness
 * (but a corner's), no corner kept by the mode but a valence-2 one, no dependent sharpness. */
enum { K_NONE, K_INTERIOR, K_BOUNDARY, K_CORNER };

static int value_kind(const ccn__fvar_level *fl, int32_t v) {
    const ccn_mesh *m = fl->m;
    int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v];
    if (fl->partner && fl->partner[v] >= 0) return K_NONE;
    int kept = fl->corner && fl->corner[v];
    float vs = m->vsharp ? m->vsharp[v] : 0.0f;
    for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
        int32_t h = m->vfan[k];
        if (ccn__fsize(m, m->hface[h]) != 4) return K_NONE;
        if (m->htwin[h] >= 0 && ccn__edge_sharp(m, m->hedge[h])) return K_NONE;
    }
    if (!m->vboundary[v]) return nfan == 4 && !kept && !(vs > 0.0f) ? K_INTERIOR : K_NONE;
    if (nfan == 2) return !kept && !(vs > 0.0f) ? K_BOUNDARY : K_NONE;
    if (nfan == 1) return vs >= CCN_SHARP_INF ? K_CORNER : K_NONE;
    return K_NONE;
}

static int put(int32_t P[16], int32_t v, int i, int j) {
    if (i < 0 || i > 3 || j < 0 || j > 3) return -1;
    int32_t *c = &P[i + 4 * j];
    if (*c == v) return 0;
    if (*c >= 0) return -1;
    for (int k = 0; k < 16; k++) /* distinct vertices only (no wrap-around) */
        if (P[k] == v) return -1;
    *c = v;
    return 0;
}

/* The fan position of w's edge towards a (0 .. valence - 1), -1 if none. */
static int spoke_of(const ccn_mesh *m, int32_t w, int32_t a) {
    for (int32_t k = 0, n = ccn__valence(m, w); k < n; k++) {
        int32_t e = ccn__fan_edge(m, w, k);
        if (m->everts[2 * e] + m->everts[2 * e + 1] - w == a) return (int)k;
    }
    return -1;
}

static double spoke(const ccn_mesh *m, int32_t w, int32_t a) {
    int k = spoke_of(m, w, a);
    return k < 0 ? -1.0 : m->eknot[ccn__fan_edge(m, w, k)];
}

/* The interval of w's spoke opposite to its spoke towards a, as the rules look it up: across an
 * interior valence-4 vertex, and along the boundary curve at a valence-3 boundary vertex. */
static double beyond(const ccn_mesh *m, int32_t w, int32_t a) {
    int k = spoke_of(m, w, a), n = ccn__valence(m, w);
    if (k < 0) return -1.0;
    if (!m->vboundary[w] && n == 4) return m->eknot[ccn__fan_edge(m, w, (k + 2) % 4)];
    if (m->vboundary[w] && n == 3 && k != 1) return m->eknot[ccn__fan_edge(m, w, 2 - k)];
    return -1.0;
}

/* Block, knot vectors and folds of face f, 0 if it is written down. The faces around f's
 * corners are laid on the integer grid from f (corners (1,1), (2,1), (2,2), (1,2)), each by its
 * place in the corner's fan (quarter turns about it). A boundary edge of a
 * laid face is a boundary line (u_lo: column 0 or 1, the faces to its right; u_hi: 2 or 3;
 * v_lo / v_hi: rows): on a line at column 1 (2), column 0 (3) is missing and is the point
 * reflection 2 P_1j - P_2j (2 P_2j - P_1j) with the mirrored intervals (DESIGN §4.2's boundary
 * curve with point-reflected ends, as tests/c/bspline_oracle.h has it); on a line at column 0 (3)
 * the interval beyond it is mirrored. A vertex on no line must be interior, on one a
 * boundary vertex, on two a pinned corner. */
static int block(const ccn__fvar_level *fl, const uint8_t *kind, int32_t f, int32_t P[16],
                 double kn[12], uint8_t *fold) {
    const ccn_mesh *m = fl->m;
    if (ccn__fsize(m, f) != 4) return -1;
    int32_t h0 = m->fstart[f], faces[13];
    int8_t gi[13][4], gj[13][4]; /* each laid face's corners on the grid, in its own order */
    int nfaces = 1;
    static const int ci[4] = {1, 2, 2, 1}, cj[4] = {1, 1, 2, 2};
    for (int k = 0; k < 16; k++) P[k] = -1;
    faces[0] = f;
    for (int k = 0; k < 4; k++) {
        int32_t c = m->hvert[h0 + k];
        if (kind[c] == K_NONE || put(P, c, ci[k], cj[k])) return -1;
        gi[0][k] = (int8_t)ci[k];
        gj[0][k] = (int8_t)cj[k];
    }
    /* the faces around corner c_k, counter-clockwise from f in c_k's fan (the next one is
     * across f's edge to c_k-1): the t-th lies on the grid square spanned by R^t a, R^t+1 a
     * from c_k, a the direction of f's edge to c_k+1, R the quarter turn (x, y) -> (-y, x) */
    for (int k = 0; k < 4; k++) {
        int32_t c = m->hvert[h0 + k], s = m->vfan_start[c], nfan = m->vfan_start[c + 1] - s;
        int32_t pf = m->hfanpos[h0 + k];
        for (int32_t p = 0; p < nfan; p++) {
            if (p == pf) continue;
            int t = (int)(((p - pf) % 4 + 4) % 4), x = ci[(k + 1) & 3] - ci[k], y = cj[(k + 1) & 3] - cj[k];
            for (int r = 0; r < t; r++) { int z = x; x = -y; y = z; }
            int x2 = -y, y2 = x; /* R^t+1 a */
            int32_t hg = m->vfan[s + p], g = m->hface[hg], q = hg - m->fstart[g];
            int32_t hn = ccn__next(m, hg), ho = ccn__next(m, hn), hp = ccn__prev(m, hg);
            if (put(P, m->hvert[hn], ci[k] + x, cj[k] + y) || put(P, m->hvert[ho], ci[k] + x + x2, cj[k] + y + y2) ||
                put(P, m->hvert[hp], ci[k] + x2, cj[k] + y2))
                return -1;
            int known = 0;
            for (int u = 1; u < nfaces && !known; u++) known = faces[u] == g;
            if (known) continue;
            if (nfaces == 13) return -1;
            faces[nfaces] = g;
            gi[nfaces][q] = (int8_t)ci[k];             gj[nfaces][q] = (int8_t)cj[k];
            gi[nfaces][(q + 1) & 3] = (int8_t)(ci[k] + x); gj[nfaces][(q + 1) & 3] = (int8_t)(cj[k] + y);
            gi[nfaces][(q + 2) & 3] = (int8_t)(ci[k] + x + x2); gj[nfaces][(q + 2) & 3] = (int8_t)(cj[k] + y + y2);
            gi[nfaces][(q + 3) & 3] = (int8_t)(ci[k] + x2); gj[nfaces][(q + 3) & 3] = (int8_t)(cj[k] + y2);
            nfaces++;
        }
    }
    /* the boundary lines */
    int ul = -9, uh = -9, vl = -9, vh = -9;
    for (int t = 0; t < nfaces; t++) {
        int32_t s = m->fstart[faces[t]];
        for (int k = 0; k < 4; k++) {
            if (m->htwin[s + k] >= 0) continue;
            int pi = gi[t][k], pj = gj[t][k], qi = gi[t][(k + 1) & 3], qj = gj[t][(k + 1) & 3];
            int *line = qj < pj ? &ul : qj > pj ? &uh : qi > pi ? &vl : &vh;
            int at = pi == qi ? pi : pj;
            if (*line != -9 && *line != at) return -1;
            *line = at;
        }
    }
    if ((ul != -9 && ul > 1) || (uh != -9 && uh < 2) || (vl != -9 && vl > 1) || (vh != -9 && vh < 2) ||
        (ul == 1 && uh == 2) || (vl == 1 && vh == 2))
        return -1;
    for (int t = 0; t < nfaces; t++) { /* a line's edges are all boundary edges */
        int32_t s = m->fstart[faces[t]];
        for (int k = 0; k < 4; k++) {
            int pi = gi[t][k], pj = gj[t][k], qi = gi[t][(k + 1) & 3], qj = gj[t][(k + 1) & 3];
            int on = (pi == qi && (pi == ul || pi == uh)) || (pj == qj && (pj == vl || pj == vh));
            if (on && m->htwin[s + k] >= 0) return -1;
        }
    }
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int gone = (ul == 1 && i == 0) || (uh == 2 && i == 3) || (vl == 1 && j == 0) || (vh == 2 && j == 3);
            int32_t v = P[i + 4 * j];
            if (gone != (v < 0)) return -1;
            if (gone) continue;
            int nl = (i == ul) + (i == uh) + (j == vl) + (j == vh);
            if (kind[v] != (nl == 0 ? K_INTERIOR : nl == 1 ? K_BOUNDARY : nl == 2 ? K_CORNER : K_NONE))
                return -1;
        }
    /* intervals D_-2 .. D_2 across the columns (u, along row 1) and E across the rows (v,
     * along column 1); a missing column's are mirrored */
    double D[5], E[5];
    D[2] = m->eknot[m->hedge[h0]];
    D[1] = ul == 1 ? D[2] : spoke(m, P[1 + 4], P[0 + 4]);
    D[3] = uh == 2 ? D[2] : spoke(m, P[2 + 4], P[3 + 4]);
    D[0] = ul == 1 ? D[3] : ul == 0 ? D[1] : beyond(m, P[0 + 4], P[1 + 4]);
    D[4] = uh == 2 ? D[1] : uh == 3 ? D[3] : beyond(m, P[3 + 4], P[2 + 4]);
    E[2] = m->eknot[m->hedge[h0 + 3]];
    E[1] = vl == 1 ? E[2] : spoke(m, P[1 + 4], P[1]);
    E[3] = vh == 2 ? E[2] : spoke(m, P[1 + 8], P[1 + 12]);
    E[0] = vl == 1 ? E[3] : vl == 0 ? E[1] : beyond(m, P[1], P[1 + 4]);
    E[4] = vh == 2 ? E[1] : vh == 3 ? E[3] : beyond(m, P[1 + 12], P[1 + 8]);
    for (int k = 0; k < 5; k++)
        if (!(D[k] > 0.0) || !(E[k] > 0.0)) return -1;
    double *U = kn, *V = kn + 6;
    U[2] = 0.0; U[1] = -D[1]; U[0] = U[1] - D[0]; U[3] = D[2]; U[4] = U[3] + D[3]; U[5] = U[4] + D[4];
    V[2] = 0.0; V[1] = -E[1]; V[0] = V[1] - E[0]; V[3] = E[2]; V[4] = V[3] + E[3]; V[5] = V[4] + E[4];
    /* a missing point's slot holds a real value (weight 0 after the fold) */
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            if (P[i + 4 * j] < 0) {
                int a = i < 1 ? 1 : i > 2 ? 2 : i, b = j < 1 ? 1 : j > 2 ? 2 : j;
                int ii = (ul == 1 && i == 0) || (uh == 2 && i == 3) ? a : i;
                int jj = (vl == 1 && j == 0) || (vh == 2 && j == 3) ? b : j;
                P[i + 4 * j] = P[ii + 4 * jj];
            }
    *fold = (uint8_t)((ul == 1) | (uh == 2) << 1 | (vl == 1) << 2 | (vh == 2) << 3);
    return 0;
}

typedef struct {
    const ccn__fvar_level *f0; uint8_t *kind; ccn__fvar_direct *d; const int32_t *list;
} direct_job;

static void kind_range(void *ctx, int32_t b, int32_t e) {
    const direct_job *j = ctx;
    for (int32_t i = b; i < e; i++) {
        int32_t v = j->list ? j->list[i] : i;
        j->kind[v] = (uint8_t)value_kind(j->f0, v);
    }
}

static void block_range(void *ctx, int32_t b, int32_t e) {
    const direct_job *j = ctx;
    ccn__fvar_direct *d = j->d;
    for (int32_t i = b; i < e; i++) {
        int32_t f = j->list ? j->list[i] : i;
        d->slot[f] = block(j->f0, j->kind, f, d->verts + 16 * (size_t)f, d->knots + 12 * (size_t)f, d->fold + f) ? -1 : f;
    }
}

/* The value vertices a listed face's block can reach: the corners of the faces around its
 * corners (block() reads no other kind). Returns their list (malloc'd), NULL out of memory. */
static int32_t *block_vertices(const ccn_mesh *m, const int32_t *faces, int32_t nfaces, int32_t *count) {
    uint8_t *mark = calloc((size_t)m->nv + 1, 1);
    int32_t n = 0, *list = NULL;
    if (!mark) return NULL;
    for (int32_t i = 0; i < nfaces; i++) {
        int32_t f = faces[i];
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
            int32_t c = m->hvert[h];
            for (int32_t q = m->vfan_start[c]; q < m->vfan_start[c + 1]; q++) {
                int32_t g = m->hface[m->vfan[q]];
                for (int32_t k = m->fstart[g]; k < m->fstart[g + 1]; k++) {
                    int32_t w = m->hvert[k];
                    n += !mark[w];
                    mark[w] = 1;
                }
            }
        }
    }
    if ((list = malloc(sizeof(int32_t) * (size_t)(n + 1)))) {
        n = 0;
        for (int32_t v = 0; v < m->nv; v++)
            if (mark[v]) list[n++] = v;
        *count = n;
    }
    free(mark);
    return list;
}

int ccn__fvar_direct_build(const ccn__fvar_level *f0, int threads, const int32_t *faces, int32_t nfaces,
                           ccn__fvar_direct *d) {
    const ccn_mesh *m = f0->m;
    memset(d, 0, sizeof *d);
    uint8_t *kind = malloc((size_t)(m->nv ? m->nv : 1));
    d->slot = malloc(sizeof(int32_t) * (size_t)(m->nf ? m->nf : 1));
    d->verts = malloc(sizeof(int32_t) * 16 * (size_t)(m->nf ? m->nf : 1)); /* slot = face */
    d->knots = malloc(sizeof(double) * 12 * (size_t)(m->nf ? m->nf : 1));
    d->fold = malloc((size_t)(m->nf ? m->nf : 1));
    int32_t nverts = m->nv, *verts = faces ? block_vertices(m, faces, nfaces, &nverts) : NULL;
    if (!kind || !d->slot || !d->verts || !d->knots || !d->fold || (faces && !verts)) {
        free(kind); free(verts); ccn__fvar_direct_free(d);
        return -1;
    }
    direct_job j = {f0, kind, d, verts};
    ccn__parallel_for(threads, nverts, kind_range, &j);
    if (faces)
        for (int32_t f = 0; f < m->nf; f++) d->slot[f] = -1;
    j.list = faces;
    ccn__parallel_for(threads, faces ? nfaces : m->nf, block_range, &j);
    for (int32_t f = 0; f < m->nf; f++) d->count += d->slot[f] >= 0;
    free(kind); free(verts);
    return 0;
}

/* The four cubic B-spline basis functions of span [U2, U3] at x. */
static void basis(const double U[6], double x, double N[4]) {
    ccn__bspline_basis(3, U, x, N);
}

/* A missing end point's weight folded onto the two it reflects: P_0 = 2 P_1 - P_2 (lo) or
 * P_3 = 2 P_2 - P_1 (hi); the sum stays 1. */
static void fold_basis(double N[4], int lo, int hi) {
    if (lo) { N[1] += 2.0 * N[0]; N[2] -= N[0]; N[0] = 0.0; }
    if (hi) { N[2] += 2.0 * N[3]; N[1] -= N[3]; N[3] = 0.0; }
}

void ccn__fvar_direct_table(const ccn__fvar_direct *d, int32_t s, int32_t side, double *N) {
    const double *U = d->knots + 12 * (size_t)s, *V = U + 6;
    double step = 1.0 / (double)(side > 1 ? side - 1 : 1);
    int fl = d->fold[s];
    for (int32_t a = 0; a < side; a++) {
        basis(U, (double)a * step * U[3], N + 4 * (size_t)a);
        basis(V, (double)a * step * V[3], N + 4 * ((size_t)side + a));
        fold_basis(N + 4 * (size_t)a, fl & 1, fl & 2);
        fold_basis(N + 4 * ((size_t)side + a), fl & 4, fl & 8);
    }
}
