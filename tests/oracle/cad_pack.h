/* Prototype of face packing for cad_from_patches (test tool; the library version is
 * designed in EXPORT_DESIGN.md section 5): maximal rectangles of strict-regular cage quads
 * become one bicubic B-spline face each, poles = the rectangle's control net (mirror ghosts
 * on the boundary), knots = the ring intervals in the cage's units, unclamped (periodic
 * where the rectangle closes on itself). Uses the library's internal headers (read only). */
#ifndef CAD_PACK_H
#define CAD_PACK_H

#include "surface/limit.h"
#include "surface/patches.h"
#include "topology/halfedge.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
    int32_t a, b;          /* cells along u, v */
    int periodic[2];
    double *poles;         /* (nu x nv) x 3, nu = a + 3, nv = b + 3 */
    double *knots[2];      /* flat, nu + 4 / nv + 4 values, all multiplicity 1 */
    int32_t *mults[2];
} cad_pack;

static int32_t pk_step_u(const ccn_mesh *m, int32_t b) {
    int32_t t = m->htwin[ccn__next(m, b)];
    return t < 0 ? -1 : ccn__next(m, t);
}
static int32_t pk_step_v(const ccn_mesh *m, int32_t b) {
    return m->htwin[ccn__next(m, ccn__next(m, b))];
}

static void pk_vpos(const ccn_mesh *m, const ccn__vpoint *p, double out[3]) {
    out[0] = out[1] = out[2] = 0;
    for (int k = 0; k < p->n; k++)
        for (int i = 0; i < 3; i++) out[i] += p->w[k] * m->pos[3 * (size_t)p->v[k] + i];
}

/* Intervals D_-2 .. D_{n+1} of one direction of a pack (scaled to the cage's units). */
static void pk_intervals(const ccn_mesh *m, const int32_t *base, int32_t n, int dir, int pinned,
                         int periodic, double *D /* n + 4, D[k+2] = D_k */) {
    for (int32_t i = 0; i < n; i++) {
        int32_t h = dir == 0 ? base[i] : ccn__prev(m, base[i]); /* side 0 / side 3 edge */
        D[i + 2] = m->eknot[m->hedge[h]] * m->knot_scale;
    }
    if (periodic) {
        D[0] = D[n]; D[1] = D[n + 1]; D[n + 2] = D[2]; D[n + 3] = D[3];
        return;
    }
    ccn__vgrid g0, g1, g2;
    ccn__vertex_grid(m, m->hvert[base[0]], m->hfanpos[base[0]], pinned, &g0);
    int32_t last = base[n - 1], c2 = ccn__next(m, ccn__next(m, last));
    ccn__vertex_grid(m, m->hvert[last], m->hfanpos[last], pinned, &g1);
    ccn__vertex_grid(m, m->hvert[c2], m->hfanpos[c2], pinned, &g2);
    const double *d0 = dir ? g0.dv : g0.du, *d1 = dir ? g1.dv : g1.du, *d2 = dir ? g2.dv : g2.du;
    D[0] = d0[0] * m->knot_scale; D[1] = d0[1] * m->knot_scale;
    D[n + 2] = d1[3] * m->knot_scale; D[n + 3] = d2[0] * m->knot_scale;
}

/* D_k for k in [-3, n+2]: periodic = cyclic; else the outermost given one repeats (the
 * knots t_{-3} and t_{n+3} do not touch the domain). */
static double pk_D(const double *D, int32_t n, int periodic, int32_t k) {
    if (periodic) return D[((k % n) + n) % n + 2];
    return D[(k < -2 ? -2 : k > n + 1 ? n + 1 : k) + 2];
}

static void pk_flat(const double *D, int32_t n, int periodic, double *t, int32_t *mult) {
    /* flat t_{-3} .. t_{n+3} (n + 7 values), t_0 = 0, t_{k+1} - t_k = D_k */
    t[3] = 0;
    for (int32_t k = 0; k <= n + 2; k++) t[k + 4] = t[k + 3] + pk_D(D, n, periodic, k);
    for (int32_t k = -1; k >= -3; k--) t[k + 3] = t[k + 4] - pk_D(D, n, periodic, k);
    for (int32_t k = 0; k < n + 7; k++) mult[k] = 1;
}

/* Builds every pack; pack_of[f] = pack index or -1. Returns the number of packs (-1: OOM). */
static int32_t cad_make_packs(const ccn_mesh *m, int pinned, cad_pack **out, int32_t *pack_of) {
    int32_t nf = m->nf, np = 0, cap = 16;
    uint8_t *ok = calloc((size_t)nf, 1);
    int32_t *cells = malloc(sizeof(int32_t) * (size_t)(nf + 1));
    int32_t *nextrow = malloc(sizeof(int32_t) * (size_t)(nf + 1));
    cad_pack *packs = malloc(sizeof(cad_pack) * (size_t)cap);
    if (!ok || !cells || !nextrow || !packs) { free(ok); free(cells); free(nextrow); free(packs); return -1; }
    for (int32_t f = 0; f < nf; f++) {
        ccn__vpoint net[4][4];
        double Cu[4][4], Cv[4][4];
        ok[f] = (uint8_t)ccn__bicubic_net(m, f, pinned, 1, net, Cu, Cv);
        pack_of[f] = -1;
    }
    for (int32_t f = 0; f < nf; f++) {
        if (!ok[f] || pack_of[f] >= 0) continue;
        int32_t b0 = m->fstart[f], a = 1, rows = 1, per[2] = {0, 0};
        cells[0] = b0;
        pack_of[f] = np;
        for (;;) { /* grow along +u */
            int32_t nb = pk_step_u(m, cells[a - 1]);
            if (nb < 0) break;
            if (nb == b0) { per[0] = 1; break; }
            int32_t g = m->hface[nb];
            if (!ok[g] || pack_of[g] >= 0) break;
            cells[a++] = nb;
            pack_of[g] = np;
        }
        for (;;) { /* add rows along +v */
            int32_t *row = cells + (size_t)(rows - 1) * a, *next = nextrow;
            int good = 1, wrap = 1;
            for (int32_t i = 0; i < a && good; i++) {
                int32_t nb = pk_step_v(m, row[i]);
                if (nb < 0) { good = 0; break; }
                next[i] = nb;
                wrap &= nb == cells[i];
                if (i > 0 && pk_step_u(m, next[i - 1]) != nb) good = 0;
            }
            if (good && per[0] && pk_step_u(m, next[a - 1]) != next[0]) good = 0;
            if (good && wrap) { per[1] = 1; break; }
            for (int32_t i = 0; i < a && good; i++) {
                int32_t g = m->hface[next[i]];
                if (!ok[g] || pack_of[g] >= 0) good = 0;
                for (int32_t k = 0; k < i && good; k++) good = m->hface[next[k]] != g;
            }
            if (!good || (int64_t)(rows + 1) * a > nf) break;
            for (int32_t i = 0; i < a; i++) pack_of[m->hface[next[i]]] = np;
            memcpy(cells + (size_t)rows * a, next, sizeof(int32_t) * (size_t)a);
            rows++;
        }
        if (np == cap) {
            cad_pack *p2 = realloc(packs, sizeof(cad_pack) * (size_t)(cap *= 2));
            if (!p2) { free(ok); free(cells); free(nextrow); free(packs); return -1; }
            packs = p2;
        }
        cad_pack *P = &packs[np];
        P->a = a; P->b = rows; P->periodic[0] = per[0]; P->periodic[1] = per[1];
        int32_t nu = a + 3, nv = rows + 3;
        P->poles = calloc(3 * (size_t)nu * nv, sizeof(double));
        for (int d = 0; d < 2; d++) {
            int32_t n = d ? rows : a;
            P->knots[d] = malloc(sizeof(double) * (size_t)(n + 7));
            P->mults[d] = malloc(sizeof(int32_t) * (size_t)(n + 7));
            double *D = malloc(sizeof(double) * (size_t)(n + 4));
            int32_t *base = malloc(sizeof(int32_t) * (size_t)n);
            for (int32_t i = 0; i < n; i++) base[i] = d ? cells[(size_t)i * a] : cells[i];
            pk_intervals(m, base, n, d, pinned, per[d], D);
            pk_flat(D, n, per[d], P->knots[d], P->mults[d]);
            free(D); free(base);
        }
        for (int32_t j = 0; j < rows; j++)
            for (int32_t i = 0; i < a; i++) { /* each cell's net, rotated into the pack frame */
                int32_t bh = cells[(size_t)j * a + i], g = m->hface[bh], r = bh - m->fstart[g];
                ccn__vpoint net[4][4], rot[4][4];
                double Cu[4][4], Cv[4][4];
                ccn__bicubic_net(m, g, pinned, 1, net, Cu, Cv);
                for (; r > 0; r--) {
                    for (int I = 0; I < 4; I++)
                        for (int J = 0; J < 4; J++) rot[I][J] = net[3 - J][I];
                    memcpy(net, rot, sizeof net);
                }
                for (int I = 0; I < 4; I++)
                    for (int J = 0; J < 4; J++) pk_vpos(m, &net[I][J], P->poles + 3 * ((size_t)(i + I) * nv + j + J));
            }
        np++;
    }
    free(ok);
    free(cells);
    free(nextrow);
    *out = packs;
    return np;
}

static void cad_free_packs(cad_pack *p, int32_t n) {
    for (int32_t i = 0; i < n; i++) {
        free(p[i].poles);
        for (int d = 0; d < 2; d++) { free(p[i].knots[d]); free(p[i].mults[d]); }
    }
    free(p);
}
#endif
