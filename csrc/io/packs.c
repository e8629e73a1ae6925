/* Face packs (io/export.h): maximal rectangles of regular faces of one mesh level, each
 * exported as one bicubic B-spline face whose poles are the rectangle's control net and whose
 * knots are the ring intervals (EXPORT_DESIGN.md section 5, items 1-2).
 *
 * A cell is a face with a frame: its base half-edge b runs along the pack's +u. Moving +u from
 * b: t = twin(next(b)), new base next(t); moving +v: new base twin(next(next(b))). Greedy in
 * face order: grow along +u from the first free packable face (meeting the start again:
 * periodic in u), then add rows along +v while every cell of the next row is packable, free,
 * distinct and consistent (reaching the first row again: periodic in v). A regular torus is
 * one pack, periodic both ways. Packs end at sharp edges (creases are C0 edges between faces).
 *
 * Knots: D_k = the ring interval of column k (side 0 of its cells; rows: side 3), the two
 * beyond each end from the corner vertex grids (mirrored at a boundary), cumulated from 0:
 * flat t_-3 .. t_{n+3}, domain [t_0, t_n]. Non-periodic ends are clamped by inserting the end
 * knot to multiplicity 3 (Boehm) and dropping what lies outside: exact, the interior knots stay
 * the ring intervals. Periodic directions keep the unclamped periodic form (cad.h), which
 * needs >= 3 cells (else the closed rectangle is clamped like an open one).
 */
#include "io/packs.h"

#include "io/knot_removal.h"

#include "base/error.h"
#include "surface/limit.h"
#include "surface/patches.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Steps never cross a sharp edge: a crease is a C0 edge between two packs (each side's
 * nets are mirrored across it, so no net spans it). */
static int32_t step_u(const ccn_mesh *m, int32_t b) {
    int32_t x = ccn__next(m, b), t = m->htwin[x];
    return t < 0 || ccn__edge_sharp(m, m->hedge[x]) ? -1 : ccn__next(m, t);
}
static int32_t step_v(const ccn_mesh *m, int32_t b) {
    int32_t x = ccn__next(m, ccn__next(m, b));
    return ccn__edge_sharp(m, m->hedge[x]) ? -1 : m->htwin[x];
}

int ccn__packable(const ccn_mesh *m, int32_t f, int pinned) {
    ccn__vpoint net[4][4];
    double Cu[4][4], Cv[4][4];
    if (!ccn__bicubic_net(m, f, pinned, 1, net, Cu, Cv)) return 0;
    for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) { /* the 3x3 block: quads */
        int32_t v = m->hvert[h];
        for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++)
            if (ccn__fsize(m, m->hface[m->vfan[k]]) != 4) return 0;
    }
    return 1;
}

void ccn__packs_free(ccn__pack *p, int32_t n) {
    for (int32_t i = 0; p && i < n; i++) free(p[i].cells);
    free(p);
}

ccn_status ccn__packs_find(const ccn_mesh *m, const uint8_t *ok, int single, ccn__pack **out,
                           int32_t *n, ccn_error *err) {
    int32_t nf = m->nf, np = 0, cap = 16;
    int32_t *pack_of = malloc(sizeof(int32_t) * (size_t)(nf + 1));
    int32_t *cells = malloc(sizeof(int32_t) * (size_t)(nf + 1));
    int32_t *next = malloc(sizeof(int32_t) * (size_t)(nf + 1));
    ccn__pack *packs = malloc(sizeof(ccn__pack) * (size_t)cap);
    *out = NULL;
    *n = 0;
    if (!pack_of || !cells || !next || !packs) goto oom;
    for (int32_t f = 0; f < nf; f++) pack_of[f] = -1;
    for (int32_t f = 0; f < nf; f++) {
        if (!ok[f] || pack_of[f] >= 0) continue;
        int32_t b0 = m->fstart[f], a = 1, rows = 1;
        int per[2] = {0, 0};
        cells[0] = b0;
        pack_of[f] = np;
        while (!single) { /* grow along +u */
            int32_t nb = step_u(m, cells[a - 1]);
            if (nb < 0) break;
            if (nb == b0) { per[0] = 1; break; }
            int32_t g = m->hface[nb];
            if (!ok[g] || pack_of[g] >= 0) break;
            cells[a++] = nb;
            pack_of[g] = np;
        }
        while (!single) { /* add rows along +v */
            const int32_t *row = cells + (size_t)(rows - 1) * a;
            int good = 1, wrap = 1;
            for (int32_t i = 0; i < a && good; i++) {
                int32_t nb = step_v(m, row[i]);
                if (nb < 0) { good = 0; break; }
                next[i] = nb;
                wrap &= nb == cells[i];
                if (i > 0 && step_u(m, next[i - 1]) != nb) good = 0;
            }
            if (good && per[0] && step_u(m, next[a - 1]) != next[0]) good = 0;
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
            ccn__pack *p2 = realloc(packs, sizeof(ccn__pack) * (size_t)(cap *= 2));
            if (!p2) goto oom;
            packs = p2;
        }
        ccn__pack *P = &packs[np];
        P->a = a;
        P->b = rows;
        P->periodic[0] = per[0];
        P->periodic[1] = per[1];
        P->cells = malloc(sizeof(int32_t) * (size_t)a * (size_t)rows);
        if (!P->cells) goto oom;
        memcpy(P->cells, cells, sizeof(int32_t) * (size_t)a * (size_t)rows);
        np++;
    }
    free(pack_of);
    free(cells);
    free(next);
    *out = packs;
    *n = np;
    return CCN_OK;
oom:
    free(pack_of);
    free(cells);
    free(next);
    ccn__packs_free(packs, np);
    return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (packs)");
}

/* Intervals D_-2 .. D_{n+1} of one direction (D[k+2] = D_k), in the caller's units. */
static void intervals(const ccn_mesh *m, const int32_t *base, int32_t n, int dir, int pinned,
                      int periodic, double *D) {
    double ks = m->knot_scale;
    for (int32_t i = 0; i < n; i++) {
        int32_t h = dir == 0 ? base[i] : ccn__prev(m, base[i]); /* side 0 / side 3 edge */
        D[i + 2] = m->eknot[m->hedge[h]] * ks;
    }
    if (periodic) {
        for (int k = 0; k < 2; k++) {
            D[k] = D[(n - 2 + k) % n + 2];
            D[n + 2 + k] = D[k % n + 2];
        }
        return;
    }
    ccn__vgrid g0, g1, g2;
    ccn__vertex_grid(m, m->hvert[base[0]], m->hfanpos[base[0]], pinned, &g0);
    int32_t last = base[n - 1], c2 = ccn__next(m, ccn__next(m, last));
    ccn__vertex_grid(m, m->hvert[last], m->hfanpos[last], pinned, &g1);
    ccn__vertex_grid(m, m->hvert[c2], m->hfanpos[c2], pinned, &g2);
    const double *d0 = dir ? g0.dv : g0.du, *d1 = dir ? g1.dv : g1.du, *d2 = dir ? g2.dv : g2.du;
    D[0] = d0[0] * ks;
    D[1] = d0[1] * ks;
    D[n + 2] = d1[3] * ks;
    D[n + 3] = d2[0] * ks;
}

/* Flat knots t_-3 .. t_{n+3} (n + 7 values, t_0 = 0) from D (periodic: cyclic beyond). */
static void flat_knots(const double *D, int32_t n, int periodic, double *t) {
#define DK(k) (periodic ? D[(((k) % n) + n) % n + 2] : D[((k) < -2 ? -2 : (k) > n + 1 ? n + 1 : (k)) + 2])
    t[3] = 0;
    for (int32_t k = 0; k <= n + 2; k++) t[k + 4] = t[k + 3] + DK(k);
    for (int32_t k = -1; k >= -3; k--) t[k + 3] = t[k + 4] - DK(k);
#undef DK
}

/* Clamps both ends of a cubic curve of n poles (P: capacity n + 2 rows, t: n + 6 values):
 * afterwards n is unchanged, t = (t_0 x 4, interior knots, t_n x 4). */
static void clamp_curve(double *P, int32_t n, int32_t w, double *t) {
    int32_t N = n;
    double lo = t[3], hi = t[n];
    ccn__insert_knot(P, &N, w, t, 3, lo);
    ccn__insert_knot(P, &N, w, t, 3, lo);
    /* triple lo at flat 3..5: pole 2 is the start; drop poles 0, 1 and knots t_-3, t_-2 */
    memmove(P, P + 2 * (size_t)w, sizeof(double) * (size_t)(N - 2) * w);
    memmove(t, t + 2, sizeof(double) * (size_t)(N + 4 - 2));
    N -= 2;
    t[0] = lo;
    ccn__insert_knot(P, &N, w, t, 3, hi);
    ccn__insert_knot(P, &N, w, t, 3, hi);
    /* triple hi at flat N-2..N: pole N-3 is the end; keep poles 0..N-3, knots 0..N, + hi */
    N -= 2;
    t[N + 3] = hi;
}

/* Clamps direction dir of the nu x nv net P (3 doubles per pole) in place. */
static int clamp_dir(double *P, int32_t nu, int32_t nv, int dir, double *t) {
    int32_t n = dir == 0 ? nu : nv, w = 3 * (dir == 0 ? nv : nu);
    double *Q = malloc(sizeof(double) * (size_t)(n + 4) * (size_t)w);
    if (!Q) return -1;
    for (int32_t i = 0; i < nu; i++) /* Q: rows along dir */
        for (int32_t j = 0; j < nv; j++)
            memcpy(Q + (dir == 0 ? (size_t)i * w + 3 * (size_t)j : (size_t)j * w + 3 * (size_t)i),
                   P + 3 * ((size_t)i * nv + j), sizeof(double) * 3);
    clamp_curve(Q, n, w, t);
    for (int32_t i = 0; i < nu; i++)
        for (int32_t j = 0; j < nv; j++)
            memcpy(P + 3 * ((size_t)i * nv + j),
                   Q + (dir == 0 ? (size_t)i * w + 3 * (size_t)j : (size_t)j * w + 3 * (size_t)i),
                   sizeof(double) * 3);
    free(Q);
    return 0;
}

static void vpos(const ccn_mesh *m, const ccn__vpoint *p, const double centre[3], double scale,
                 double out[3]) {
    double x[3] = {0, 0, 0};
    for (int k = 0; k < p->n; k++)
        for (int i = 0; i < 3; i++) x[i] += p->w[k] * m->pos[3 * (size_t)p->v[k] + i];
    for (int i = 0; i < 3; i++) out[i] = centre[i] + scale * x[i];
}

int32_t ccn__pack_face(ccn__xmodel *xm, const ccn_mesh *m, const ccn__pack *pk, int pinned,
                       const double centre[3], double scale, int32_t kind, ccn__xplace_fn place,
                       void *ctx) {
    int32_t a = pk->a, b = pk->b, nu = a + 3, nv = b + 3;
    int per[2] = {pk->periodic[0] && a >= 3, pk->periodic[1] && b >= 3};
    int32_t f = ccn__xm_add_face(xm, kind, 3, 3, nu, nv, a, b);
    if (f < 0) return -1;
    double *t[2] = {malloc(sizeof(double) * (size_t)(a + 10)), malloc(sizeof(double) * (size_t)(b + 10))};
    double *D = malloc(sizeof(double) * (size_t)((a > b ? a : b) + 4));
    int32_t *base = malloc(sizeof(int32_t) * (size_t)(a > b ? a : b));
    double *P = (double *)xm->faces[f].s.poles;
    int bad = !t[0] || !t[1] || !D || !base;
    for (int d = 0; d < 2 && !bad; d++) {
        int32_t n = d ? b : a;
        for (int32_t i = 0; i < n; i++) base[i] = d ? pk->cells[(size_t)i * a] : pk->cells[i];
        intervals(m, base, n, d, pinned, pk->periodic[d], D);
        flat_knots(D, n, pk->periodic[d], t[d]);
    }
    for (int32_t j = 0; j < b && !bad; j++)
        for (int32_t i = 0; i < a; i++) { /* each cell's net, rotated into the pack frame */
            int32_t bh = pk->cells[(size_t)j * a + i], g = m->hface[bh], r = bh - m->fstart[g];
            ccn__vpoint net[4][4], rot[4][4];
            double Cu[4][4], Cv[4][4];
            ccn__bicubic_net(m, g, pinned, 0, net, Cu, Cv);
            for (; r > 0; r--) {
                for (int I = 0; I < 4; I++)
                    for (int J = 0; J < 4; J++) rot[I][J] = net[3 - J][I];
                memcpy(net, rot, sizeof net);
            }
            for (int I = 0; I < 4; I++)
                for (int J = 0; J < 4; J++)
                    vpos(m, &net[I][J], centre, scale, P + 3 * ((size_t)(i + I) * nv + j + J));
            ccn__xcell *c = &xm->cells[xm->faces[f].cell0 + i + (size_t)a * j];
            c->uv[0] = t[0][i + 3];
            c->uv[1] = t[0][i + 4];
            c->uv[2] = t[1][j + 3];
            c->uv[3] = t[1][j + 4];
            ccn__xplace q;
            place(ctx, g, &q);
            ccn__xplace_rotate(&q, bh - m->fstart[g], &c->pl);
        }
    for (int d = 0; d < 2 && !bad; d++)
        if (!per[d] && clamp_dir(P, nu, nv, d, t[d])) bad = 1;
    for (int d = 0; d < 2 && !bad; d++) {
        xm->faces[f].s.periodic[d] = per[d];
        if (ccn__xm_set_flat(xm, f, d, t[d])) bad = 1;
    }
    free(t[0]);
    free(t[1]);
    free(D);
    free(base);
    if (bad) { xm->oom = 1; return -1; }
    return f;
}
