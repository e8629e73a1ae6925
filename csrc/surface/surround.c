/* The exact bicubic surround of a guided cap, one level finer than the cap (bi5.h [R13]).
 *
 * The cap of EV V fills its n level-K faces; sector s is face s = (V, E_s, F_s, E_{s+1}) with
 * hole coordinates V = (0,0), E_s = (1,0), F_s = (1,1), E_{s+1} = (0,1) (u along spoke s in units
 * of its interval d_s, v along spoke s+1). With non-uniform intervals the level-K faces across
 * the hole's legs are not tensor patches (their nets contain V), but their level-(K+1)
 * children next to the hole are: each leg u = 1 (v = 1) meets two of them, at v in [0,1/2] and
 * [1/2,1] (u in [0,1/2] and [1/2,1]), each a square of side 1/2 in hole coordinates because
 * every interval halves per level and the spoke continues with its own interval (e_i = d_i).
 * Their bicubic patches (patches.c, strict: the subdivision limit) are re-expressed over the
 * hole [0,1]^2 by blossoming (exact: a polynomial under an affine change of parameter) and
 * raised to bi-5.
 *
 * Level-(K+1) numbering (refine/level.c): face point of level-K face f = f, edge point of edge e =
 * nf + e, vertex point of v = nf + ne + v; the child quad of face f at its corner h (a
 * half-edge) has index h and corners (VP(h's vertex), EP(h), FP(f), EP(prev h)).
 */
#include "surface/surround.h"

#include "surface/patches.h"

#include <string.h>

/* Blossom of the cubic Bézier c[0..3] (stride 3 doubles) at (3-k) x x0 and k x x1. */
static void blossom3(const double *c, size_t stride, double x0, double x1, int k, double out[3]) {
    double p[4][3];
    for (int i = 0; i < 4; i++) memcpy(p[i], c + (size_t)i * stride, sizeof p[i]);
    for (int lvl = 0; lvl < 3; lvl++) {
        double t = lvl < 3 - k ? x0 : x1;
        for (int i = 0; i < 3 - lvl; i++)
            for (int d = 0; d < 3; d++) p[i][d] = (1 - t) * p[i][d] + t * p[i + 1][d];
    }
    memcpy(out, p[0], sizeof p[0]);
}

/* Bicubic bez[a][b] on the face whose corners 0, 1, 3 sit at hole points c0, c1, c3 (a along
 * corner 0 -> 1, b along 0 -> 3, both axis-parallel): its Bézier form Q[i][j] over the hole
 * [0,1]^2 (i along u), raised to bi-5 into out (36 x 3). */
static void reparam_raise(const double bez[4][4][3], const double c0[2], const double c1[2],
                          const double c3[2], double *out) {
    static const double E[6][4] = {{1, 0, 0, 0}, {0.4, 0.6, 0, 0}, {0.1, 0.6, 0.3, 0},
                                   {0, 0.3, 0.6, 0.1}, {0, 0, 0.6, 0.4}, {0, 0, 0, 1}};
    int a_on_u = c1[0] != c0[0];
    int ax = a_on_u ? 0 : 1, bx = 1 - ax; /* hole axis of a and of b */
    double sa = c1[ax] - c0[ax], sb = c3[bx] - c0[bx];
    /* a(x) = (x - c0[ax]) / sa at hole values x = 0 and 1; same for b */
    double a0 = -c0[ax] / sa, a1 = (1 - c0[ax]) / sa, b0 = -c0[bx] / sb, b1 = (1 - c0[bx]) / sb;
    double T[4][4][3], Q[4][4][3];
    for (int ka = 0; ka < 4; ka++)      /* blossom along a: index ka = copies of hole value 1 */
        for (int jb = 0; jb < 4; jb++) blossom3(&bez[0][jb][0], 12, a0, a1, ka, T[ka][jb]);
    for (int ka = 0; ka < 4; ka++)
        for (int kb = 0; kb < 4; kb++) {
            double r[3];
            blossom3(&T[ka][0][0], 3, b0, b1, kb, r);
            int i = a_on_u ? ka : kb, j = a_on_u ? kb : ka; /* i along u, j along v */
            memcpy(Q[i][j], r, sizeof r);
        }
    memset(out, 0, sizeof(double) * 108);
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            for (int a = 0; a < 4; a++)
                for (int b = 0; b < 4; b++) {
                    double w = E[i][a] * E[j][b];
                    if (w == 0.0) continue;
                    for (int d = 0; d < 3; d++) out[(i * 6 + j) * 3 + d] += w * Q[a][b][d];
                }
}

typedef struct { int32_t id[12]; double uv[12][2]; int n; } pt_table;

static void put(pt_table *t, int32_t id, double u, double v) {
    t->id[t->n] = id;
    t->uv[t->n][0] = u;
    t->uv[t->n][1] = v;
    t->n++;
}

static const double *lookup(const pt_table *t, int32_t id) {
    for (int i = 0; i < t->n; i++)
        if (t->id[i] == id) return t->uv[i];
    return NULL;
}

int ccn__cap_surround(const ccn_mesh *mK, const ccn_mesh *mK1, int32_t ev, int pinned,
                      double *pieces) {
    int32_t n = ccn__valence(mK, ev), nf = mK->nf, ne = mK->ne;
    for (int32_t s = 0; s < n; s++) {
        int32_t h = mK->vfan[mK->vfan_start[ev] + s];
        if (ccn__fsize(mK, mK->hface[h]) != 4) return 0;
        int32_t g = ccn__next(mK, h), g2 = ccn__next(mK, g);
        int32_t t = mK->htwin[g], t2 = mK->htwin[g2];
        if (t < 0 || t2 < 0 || ccn__fsize(mK, mK->hface[t]) != 4 || ccn__fsize(mK, mK->hface[t2]) != 4)
            return 0;
        pt_table tb = {{0}, {{0}}, 0};
        int32_t vp = nf + ne;
        put(&tb, vp + mK->hvert[g], 1, 0);                     /* E_s */
        put(&tb, vp + mK->hvert[g2], 1, 1);                    /* F_s */
        put(&tb, vp + mK->hvert[ccn__next(mK, g2)], 0, 1);     /* E_{s+1} */
        put(&tb, nf + mK->hedge[g], 1, 0.5);
        put(&tb, nf + mK->hedge[g2], 0.5, 1);
        put(&tb, mK->hface[t], 1.5, 0.5);                      /* face across u = 1 */
        put(&tb, nf + mK->hedge[ccn__next(mK, t)], 1.5, 0);
        put(&tb, nf + mK->hedge[ccn__prev(mK, t)], 1.5, 1);
        put(&tb, mK->hface[t2], 0.5, 1.5);                     /* face across v = 1 */
        put(&tb, nf + mK->hedge[ccn__next(mK, t2)], 1, 1.5);
        put(&tb, nf + mK->hedge[ccn__prev(mK, t2)], 0, 1.5);
        const int32_t child[4] = {ccn__next(mK, t), t, t2, ccn__next(mK, t2)};
        for (int k = 0; k < 4; k++) {
            int32_t f1 = child[k], s0 = mK1->fstart[f1];
            if (ccn__fsize(mK1, f1) != 4) return 0;
            const double *c0 = lookup(&tb, mK1->hvert[s0]), *c1 = lookup(&tb, mK1->hvert[s0 + 1]);
            const double *c3 = lookup(&tb, mK1->hvert[s0 + 3]);
            if (!c0 || !c1 || !c3) return 0;
            if (!pieces) { /* topology only: positions are not computed yet */
                ccn__vpoint net[4][4];
                double Cu[4][4], Cv[4][4];
                if (!ccn__bicubic_net(mK1, f1, pinned, 1, net, Cu, Cv)) return 0;
                continue;
            }
            double bez[4][4][3];
            if (!ccn__bicubic_patch(mK1, f1, pinned, 1, bez)) return 0;
            reparam_raise((const double(*)[4][3])bez, c0, c1, c3, pieces + ((size_t)s * 4 + k) * 108);
        }
    }
    return 1;
}
