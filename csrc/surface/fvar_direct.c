/* Face-varying limit weights of regular faces, written down (surface/fvar_direct.h).
 *
 * A level-0 face f of a channel's value mesh is regular when it is a quad and all 16 value
 * vertices of the faces around its corners (its 4 x 4 block) are distinct interior valence-4
 * value vertices whose faces are all quads, with no sharp edge, no vertex sharpness, no corner
 * kept by the mode and no dependent sharpness. Then every rule that reaches the limit over f
 * is the tensor product of the knot-insertion curve rules (rules/bspline.c, DESIGN §4.2,
 * Li 2016 eqs (5)-(7)) with the ring intervals: each level inserts the midpoint knot of every
 * interval, and the limit of a level-L vertex is the surface at its knot. So the limit over f
 * is the bicubic B-spline patch of the block, with the knot vectors of the five rings that
 * cross it in each direction (the block's three and the one beyond on either side; the ring
 * interval beyond an interior valence-4 vertex is that of the opposite spoke, as the rules
 * look it up), and the weights of an output value at (u, v) in f are N_i(u) N_j(v) (de Boor's
 * basis functions, Piegl & Tiller A2.2), computed once instead of probing the refinement.
 * The probed weights are the same numbers summed in another order (a few ulps).
 */
#include "surface/fvar_direct.h"

#include "rules/bspline.h"

#include <stdlib.h>
#include <string.h>

void ccn__fvar_direct_free(ccn__fvar_direct *d) {
    if (!d) return;
    free(d->slot); free(d->verts); free(d->knots);
    memset(d, 0, sizeof *d);
}

static int regular_value(const ccn__fvar_level *fl, int32_t v) {
    const ccn_mesh *m = fl->m;
    if (m->vboundary[v] || m->vfan_start[v + 1] - m->vfan_start[v] != 4) return 0;
    if ((fl->corner && fl->corner[v]) || (fl->partner && fl->partner[v] >= 0)) return 0;
    if (m->vsharp && m->vsharp[v] > 0.0f) return 0;
    for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
        int32_t h = m->vfan[k];
        if (ccn__fsize(m, m->hface[h]) != 4 || ccn__edge_sharp(m, m->hedge[h])) return 0;
    }
    return 1;
}

/* The block's grid, filled as the faces around f's corners give it. */
typedef struct { int32_t P[16]; int n; } grid;

static int put(grid *g, int32_t v, int i, int j) {
    if (i < 0 || i > 3 || j < 0 || j > 3) return -1;
    int32_t *c = &g->P[i + 4 * j];
    if (*c == v) return 0;
    if (*c >= 0) return -1;
    for (int k = 0; k < 16; k++) /* distinct vertices only (no wrap-around) */
        if (g->P[k] == v) return -1;
    *c = v;
    g->n++;
    return 0;
}

static int find(const grid *g, int32_t v, int *i, int *j) {
    for (int k = 0; k < 16; k++)
        if (g->P[k] == v) { *i = k & 3; *j = k >> 2; return 0; }
    return -1;
}

/* The interval of the spoke of interior valence-4 vertex w opposite to its spoke towards a. */
static double beyond(const ccn_mesh *m, int32_t w, int32_t a) {
    int32_t s = m->vfan_start[w];
    for (int q = 0; q < 4; q++)
        if (m->hvert[ccn__next(m, m->vfan[s + q])] == a) return m->eknot[m->hedge[m->vfan[s + (q + 2) % 4]]];
    return -1.0;
}

static double spoke(const ccn_mesh *m, int32_t w, int32_t a) {
    for (int32_t k = m->vfan_start[w]; k < m->vfan_start[w + 1]; k++)
        if (m->hvert[ccn__next(m, m->vfan[k])] == a) return m->eknot[m->hedge[m->vfan[k]]];
    return -1.0;
}

/* Block and knot vectors of face f, 0 if it is regular. */
static int block(const ccn__fvar_level *fl, const uint8_t *reg, int32_t f, int32_t P[16], double kn[12]) {
    const ccn_mesh *m = fl->m;
    if (ccn__fsize(m, f) != 4) return -1;
    int32_t h0 = m->fstart[f], c[4];
    static const int ci[4] = {1, 2, 2, 1}, cj[4] = {1, 1, 2, 2};
    grid g;
    for (int k = 0; k < 16; k++) g.P[k] = -1;
    g.n = 0;
    for (int k = 0; k < 4; k++) {
        c[k] = m->hvert[h0 + k];
        if (!reg[c[k]] || put(&g, c[k], ci[k], cj[k])) return -1;
    }
    for (int k = 0; k < 4; k++) { /* the spokes: f's two at c_k give the other two (opposite) */
        int32_t s = m->vfan_start[c[k]], w[4];
        int di[4], dj[4], known[4] = {0, 0, 0, 0};
        for (int q = 0; q < 4; q++) {
            w[q] = m->hvert[ccn__next(m, m->vfan[s + q])];
            for (int t = 1; t <= 3; t += 2) {
                int kk = (k + t) & 3;
                if (w[q] == c[kk]) { di[q] = ci[kk] - ci[k]; dj[q] = cj[kk] - cj[k]; known[q] = 1; }
            }
        }
        for (int q = 0; q < 4; q++)
            if (!known[q] && known[(q + 2) & 3]) { di[q] = -di[(q + 2) & 3]; dj[q] = -dj[(q + 2) & 3]; known[q] = 1; }
        for (int q = 0; q < 4; q++)
            if (!known[q] || put(&g, w[q], ci[k] + di[q], cj[k] + dj[q])) return -1;
    }
    for (int k = 0; k < 4; k++) /* the diagonals: the opposite corner of each face at c_k */
        for (int32_t q = m->vfan_start[c[k]]; q < m->vfan_start[c[k] + 1]; q++) {
            int32_t h = m->vfan[q], a = m->hvert[ccn__next(m, h)], b = m->hvert[ccn__prev(m, h)];
            int32_t o = m->hvert[ccn__next(m, ccn__next(m, h))];
            int ai, aj, bi, bj;
            if (find(&g, a, &ai, &aj) || find(&g, b, &bi, &bj) ||
                put(&g, o, ai + bi - ci[k], aj + bj - cj[k]))
                return -1;
        }
    if (g.n != 16) return -1;
    for (int k = 0; k < 16; k++)
        if (!reg[g.P[k]]) return -1;
    /* intervals D_-2 .. D_2 across the columns (u) and rows (v) */
    double D[5], E[5];
    D[1] = spoke(m, g.P[1 + 4], g.P[0 + 4]);
    D[2] = m->eknot[m->hedge[h0]];
    D[3] = spoke(m, g.P[2 + 4], g.P[3 + 4]);
    D[0] = beyond(m, g.P[0 + 4], g.P[1 + 4]);
    D[4] = beyond(m, g.P[3 + 4], g.P[2 + 4]);
    E[1] = spoke(m, g.P[1 + 4], g.P[1]);
    E[2] = m->eknot[m->hedge[h0 + 3]];
    E[3] = spoke(m, g.P[1 + 8], g.P[1 + 12]);
    E[0] = beyond(m, g.P[1], g.P[1 + 4]);
    E[4] = beyond(m, g.P[1 + 12], g.P[1 + 8]);
    for (int k = 0; k < 5; k++)
        if (!(D[k] > 0.0) || !(E[k] > 0.0)) return -1;
    double *U = kn, *V = kn + 6;
    U[2] = 0.0; U[1] = -D[1]; U[0] = U[1] - D[0]; U[3] = D[2]; U[4] = U[3] + D[3]; U[5] = U[4] + D[4];
    V[2] = 0.0; V[1] = -E[1]; V[0] = V[1] - E[0]; V[3] = E[2]; V[4] = V[3] + E[3]; V[5] = V[4] + E[4];
    memcpy(P, g.P, sizeof g.P);
    return 0;
}

int ccn__fvar_direct_build(const ccn__fvar_level *f0, ccn__fvar_direct *d) {
    const ccn_mesh *m = f0->m;
    memset(d, 0, sizeof *d);
    uint8_t *reg = malloc((size_t)(m->nv ? m->nv : 1));
    d->slot = malloc(sizeof(int32_t) * (size_t)(m->nf ? m->nf : 1));
    if (!reg || !d->slot) { free(reg); ccn__fvar_direct_free(d); return -1; }
    for (int32_t v = 0; v < m->nv; v++) reg[v] = (uint8_t)regular_value(f0, v);
    d->verts = malloc(sizeof(int32_t) * 16 * (size_t)(m->nf ? m->nf : 1)); /* slot = face */
    d->knots = malloc(sizeof(double) * 12 * (size_t)(m->nf ? m->nf : 1));
    if (!d->verts || !d->knots) { free(reg); ccn__fvar_direct_free(d); return -1; }
    for (int32_t f = 0; f < m->nf; f++) {
        d->slot[f] = block(f0, reg, f, d->verts + 16 * (size_t)f, d->knots + 12 * (size_t)f) ? -1 : f;
        d->count += d->slot[f] >= 0;
    }
    free(reg);
    return 0;
}

/* The four cubic B-spline basis functions of span [U2, U3] at x. */
static void basis(const double U[6], double x, double N[4]) {
    ccn__bspline_basis(3, U, x, N);
}

void ccn__fvar_direct_table(const ccn__fvar_direct *d, int32_t s, int32_t side, double *N) {
    const double *U = d->knots + 12 * (size_t)s, *V = U + 6;
    double step = 1.0 / (double)(side > 1 ? side - 1 : 1);
    for (int32_t a = 0; a < side; a++) {
        basis(U, (double)a * step * U[3], N + 4 * (size_t)a);
        basis(V, (double)a * step * V[3], N + 4 * ((size_t)side + a));
    }
}
