/* Topology of the exported faces from their places on the cage (io/export.h), no geometry:
 * every face side is a chain of pieces, one per cell along it, and each piece lies on a line
 * of the cage's hierarchy with an exact (dyadic) parameter interval:
 *   - a cage edge e: parameter 0 at everts[2e], 1 at everts[2e+1];
 *   - the split edge j of an n-gon cage face (the midpoint of the edge of its half-edge j to
 *     the face point): 0 at the midpoint, 1 at the face point;
 *   - an iso line inside a cage quad (or a level-1 quad of an n-gon): s = const or t = const.
 * Per line, the ends of all its pieces are the breaks; each elementary interval between
 * breaks is covered by one face side (boundary) or by two running in opposite directions
 * (an edge; anything else is an internal error). Consecutive elementary segments of a side
 * whose partners are consecutive on one other side (or which are both boundary) are merged,
 * so an edge runs as far as the same two faces meet (a torus pack: two seam edges), and not
 * from an infinitely sharp cage edge (a crease: C0) onto a smooth line or back. */
#include "io/export_topo.h"

#include "base/error.h"
#include "base/sorted.h"
#include "rules/crease.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
    int32_t type, a, b, c; /* 0: cage edge a; 1: split edge b of face a; 2: face a, sub b, axis c */
    double val;            /* type 2: the fixed coordinate */
} line_key;

typedef struct {
    line_key k;
    double x0, x1;  /* line parameter at the piece's start and end (running order) */
    double r0, r1;  /* the face side's parameter there */
    int32_t face, side, order; /* order: running index of the piece on its side */
    int crease;     /* on an infinitely sharp cage edge */
} piece;

static int key_cmp(const line_key *a, const line_key *b) {
    if (a->type != b->type) return a->type < b->type ? -1 : 1;
    if (a->a != b->a) return a->a < b->a ? -1 : 1;
    if (a->b != b->b) return a->b < b->b ? -1 : 1;
    if (a->c != b->c) return a->c < b->c ? -1 : 1;
    return a->val < b->val ? -1 : a->val > b->val;
}

static int piece_cmp(const void *pa, const void *pb) {
    const piece *a = pa, *b = pb;
    int c = key_cmp(&a->k, &b->k);
    if (c) return c;
    double la = a->x0 < a->x1 ? a->x0 : a->x1, lb = b->x0 < b->x1 ? b->x0 : b->x1;
    if (la != lb) return la < lb ? -1 : 1;
    if (a->face != b->face) return a->face < b->face ? -1 : 1;
    return a->side - b->side;
}

/* An elementary segment's place on its face's boundary: side, the piece's order along it, k
 * within the piece. */
typedef struct { int32_t face, side, order, k; int32_t seg; } ref;

static int ref_cmp(const void *pa, const void *pb) {
    const ref *a = pa, *b = pb;
    if (a->face != b->face) return a->face < b->face ? -1 : 1;
    if (a->side != b->side) return a->side < b->side ? -1 : 1;
    if (a->order != b->order) return a->order < b->order ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

static int dbl_cmp(const void *pa, const void *pb) {
    double a = *(const double *)pa, b = *(const double *)pb;
    return a < b ? -1 : a > b;
}

/* The line of the segment P -> Q at place (c, sub): key and line parameters; 0 if it is not
 * axis-parallel (an internal error). */
static int classify(const ccn_mesh *cage, int32_t c, int32_t sub, const double P[2],
                    const double Q[2], line_key *k, double *x0, double *x1) {
    int axis = P[0] == Q[0] ? 0 : P[1] == Q[1] ? 1 : -1;
    if (axis < 0) return 0;
    double val = axis == 0 ? P[0] : P[1], a0 = axis == 0 ? P[1] : P[0], a1 = axis == 0 ? Q[1] : Q[0];
    memset(k, 0, sizeof *k);
    int32_t n = ccn__fsize(cage, c), h = -1;
    double p0 = 0, p1 = 0; /* parameter along half-edge h */
    if (val != 0 && val != 1) { /* an iso line inside the quad */
        k->type = 2; k->a = c; k->b = sub; k->c = axis; k->val = val;
        *x0 = a0; *x1 = a1;
        return 1;
    }
    if (sub < 0) { /* cage quad: s=0 side 3, s=1 side 1, t=0 side 0, t=1 side 2 */
        int side = axis == 0 ? (val == 0 ? 3 : 1) : (val == 0 ? 0 : 2);
        h = cage->fstart[c] + side;
        int rev = side >= 2;
        p0 = rev ? 1 - a0 : a0;
        p1 = rev ? 1 - a1 : a1;
    } else if ((axis == 0 && val == 1) || (axis == 1 && val == 1)) { /* a split edge */
        int32_t j = axis == 0 ? sub : (sub + n - 1) % n;
        k->type = 1; k->a = c; k->b = j;
        *x0 = a0; *x1 = a1;
        return 1;
    } else if (axis == 1) { /* t = 0: first half of half-edge sub */
        h = cage->fstart[c] + sub;
        p0 = a0 / 2; p1 = a1 / 2;
    } else { /* s = 0: second half of half-edge sub-1, backwards */
        h = cage->fstart[c] + (sub + n - 1) % n;
        p0 = 1 - a0 / 2; p1 = 1 - a1 / 2;
    }
    int32_t e = cage->hedge[h];
    int fwd = cage->hvert[h] == cage->everts[2 * e];
    k->type = 0; k->a = e;
    *x0 = fwd ? p0 : 1 - p0;
    *x1 = fwd ? p1 : 1 - p1;
    return 1;
}

static const double CX[4][2][2] = { /* cell side s: local (x,y) from, to */
    {{0, 0}, {1, 0}}, {{1, 0}, {1, 1}}, {{1, 1}, {0, 1}}, {{0, 1}, {0, 0}}};

static void at(const ccn__xplace *q, const double xy[2], double out[2]) {
    for (int d = 0; d < 2; d++)
        out[d] = q->p[0][d] + xy[0] * (q->p[1][d] - q->p[0][d]) + xy[1] * (q->p[2][d] - q->p[0][d]);
}

typedef struct {
    int32_t face, side;
    double r0, r1;       /* side parameter at start, end */
    int32_t partner;     /* elementary segment index, -1 */
    int32_t pos;         /* running index on its side */
    int dir;             /* 1: along the line's parameter */
    int crease;
} eseg;

ccn_status ccn__xtopo_build(const ccn__xmodel *xm, const ccn_mesh *cage, int32_t **breaks_start,
                            double **breaks, int32_t **adjacency, uint8_t **crease, ccn_error *err) {
    ccn_status st = CCN_OK;
    int32_t F = xm->num_faces;
    size_t np = 0;
    for (int32_t f = 0; f < F; f++) np += 2 * ((size_t)xm->faces[f].cells_u + xm->faces[f].cells_v);
    piece *pc = malloc(sizeof(piece) * (np ? np : 1));
    double *xs = malloc(sizeof(double) * 2 * (np ? np : 1));
    int32_t *side_first = malloc(sizeof(int32_t) * (4 * (size_t)F + 1)); /* first eseg of each side */
    eseg *es = NULL;
    int32_t *group = NULL, *bstart = NULL, *adj = NULL;
    double *br = NULL;
    uint8_t *cr = NULL;
    *breaks_start = NULL; *breaks = NULL; *adjacency = NULL; *crease = NULL;
    if (!pc || !xs || !side_first) goto oom;
    size_t n = 0;
    for (int32_t f = 0; f < F; f++) {
        const ccn__xface *X = &xm->faces[f];
        int32_t a = X->cells_u, b = X->cells_v;
        for (int s = 0; s < 4; s++) {
            int32_t cnt = s % 2 == 0 ? a : b;
            for (int32_t q = 0; q < cnt; q++) {
                int32_t i = s == 0 ? q : s == 1 ? a - 1 : s == 2 ? a - 1 - q : 0;
                int32_t j = s == 0 ? 0 : s == 1 ? q : s == 2 ? b - 1 : b - 1 - q;
                const ccn__xcell *c = &xm->cells[X->cell0 + i + (size_t)a * j];
                piece *p = &pc[n++];
                double P[2], Q[2];
                at(&c->pl, CX[s][0], P);
                at(&c->pl, CX[s][1], Q);
                if (!classify(cage, c->pl.cage_face, c->pl.sub, P, Q, &p->k, &p->x0, &p->x1)) {
                    st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, c->pl.cage_face,
                                   "export face %d side %d is not an iso line of cage face %d",
                                   (int)f, s, (int)c->pl.cage_face);
                    goto done;
                }
                int lo_u = s % 2 == 0; /* sides 0, 2 run along u: uv[0..1]; 1, 3 along v */
                double A = lo_u ? c->uv[0] : c->uv[2], B = lo_u ? c->uv[1] : c->uv[3];
                p->r0 = s < 2 ? A : B;
                p->r1 = s < 2 ? B : A;
                p->face = f;
                p->side = s;
                p->order = q;
                p->crease = p->k.type == 0 && cage->esharp && cage->esharp[p->k.a] >= CCN_SHARP_INF;
            }
        }
    }
    qsort(pc, n, sizeof *pc, piece_cmp);
    /* elementary segments: count first */
    size_t ne = 0, nint = 0, g0 = 0;
    for (size_t g = 0; g <= n; g++) {
        if (g < n && (g == g0 || !key_cmp(&pc[g].k, &pc[g0].k))) continue;
        size_t nx = 0; /* group [g0, g): distinct ends */
        for (size_t i = g0; i < g; i++) { xs[nx++] = pc[i].x0; xs[nx++] = pc[i].x1; }
        qsort(xs, nx, sizeof(double), dbl_cmp);
        size_t u = 0;
        for (size_t i = 0; i < nx; i++) if (!u || xs[i] != xs[u - 1]) xs[u++] = xs[i];
        nint += u ? u - 1 : 0; /* a line's intervals: a gap between its pieces is one too */
        for (size_t i = g0; i < g; i++) {
            double lo = pc[i].x0 < pc[i].x1 ? pc[i].x0 : pc[i].x1, hi = pc[i].x0 + pc[i].x1 - lo;
            size_t k0 = ccn__first_at_least(xs, u, lo), k1 = ccn__first_at_least(xs, u, hi);
            ne += k1 > k0 ? k1 - k0 : 0;
        }
        g0 = g;
    }
    es = malloc(sizeof(eseg) * (ne ? ne : 1));
    int32_t *cover = malloc(sizeof(int32_t) * 2 * (nint ? nint : 1)); /* per elementary interval */
    if (!es || !cover) { free(cover); goto oom; }
    /* per piece its elementary segments in running order; collect per side afterwards */
    ref *rf = malloc(sizeof(ref) * (ne ? ne : 1));
    if (!rf) { free(cover); goto oom; }
    size_t m = 0, ni = 0;
    g0 = 0;
    for (size_t g = 0; g <= n && !st; g++) {
        if (g < n && (g == g0 || !key_cmp(&pc[g].k, &pc[g0].k))) continue;
        size_t nx = 0;
        for (size_t i = g0; i < g; i++) { xs[nx++] = pc[i].x0; xs[nx++] = pc[i].x1; }
        qsort(xs, nx, sizeof(double), dbl_cmp);
        size_t u = 0;
        for (size_t i = 0; i < nx; i++) if (!u || xs[i] != xs[u - 1]) xs[u++] = xs[i];
        size_t base = ni; /* elementary intervals of this line: ni .. ni + u - 2 */
        for (size_t k = 0; k + 1 < u; k++) cover[2 * (ni + k)] = cover[2 * (ni + k) + 1] = -1;
        ni += u ? u - 1 : 0;
        for (size_t i = g0; i < g && !st; i++) {
            const piece *p = &pc[i];
            int fwd = p->x1 > p->x0;
            double lo = fwd ? p->x0 : p->x1, hi = fwd ? p->x1 : p->x0;
            int32_t cnt = 0;
            /* its elementary intervals: [xs[k], xs[k + 1]] for k0 <= k < k1 (its ends are in xs) */
            size_t k0 = ccn__first_at_least(xs, u, lo), k1 = ccn__first_at_least(xs, u, hi);
            for (size_t k = k0; k < k1; k++) {
                size_t kk = fwd ? k : k0 + k1 - 1 - k;
                double xa = fwd ? xs[kk] : xs[kk + 1], xb = fwd ? xs[kk + 1] : xs[kk];
                eseg *e = &es[m];
                e->face = p->face;
                e->side = p->side;
                e->r0 = xa == p->x0 ? p->r0 : p->r0 + (xa - p->x0) / (p->x1 - p->x0) * (p->r1 - p->r0);
                e->r1 = xb == p->x1 ? p->r1 : p->r0 + (xb - p->x0) / (p->x1 - p->x0) * (p->r1 - p->r0);
                e->partner = -1;
                e->dir = fwd;
                e->crease = p->crease;
                int32_t *cv = &cover[2 * (base + kk)];
                if (cv[0] < 0) cv[0] = (int32_t)m;
                else if (cv[1] < 0) cv[1] = (int32_t)m;
                else
                    st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, p->face,
                                   "export faces %d, %d and %d meet on one edge",
                                   (int)es[cv[0]].face, (int)es[cv[1]].face, (int)p->face);
                rf[m].face = p->face; rf[m].side = p->side; rf[m].order = p->order;
                rf[m].k = cnt++;
                rf[m].seg = (int32_t)m;
                m++;
            }
        }
        /* pairs must run in opposite directions: a consistently oriented shell */
        for (size_t k = base; k < ni && !st; k++) {
            int32_t A = cover[2 * k], B = cover[2 * k + 1];
            if (B < 0) continue;
            if (es[A].dir == es[B].dir) {
                st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, es[A].face,
                               "export faces %d and %d run their common edge the same way",
                               (int)es[A].face, (int)es[B].face);
                break;
            }
            es[A].partner = B;
            es[B].partner = A;
        }
        g0 = g;
    }
    free(cover);
    if (st) { free(rf); goto done; }
    /* order the elementary segments by (face, side, piece order, k) */
    int32_t *perm = malloc(sizeof(int32_t) * (m ? m : 1)), *inv = malloc(sizeof(int32_t) * (m ? m : 1));
    if (!perm || !inv) { free(perm); free(inv); free(rf); goto oom; }
    {
        /* where each side starts (counts), then one sort by (face, side, piece order, k): a
         * merged face's side can hold thousands of segments */
        memset(side_first, 0, sizeof(int32_t) * (4 * (size_t)F + 1));
        for (size_t i = 0; i < m; i++) side_first[4 * rf[i].face + rf[i].side + 1]++;
        for (int32_t i = 0; i < 4 * F; i++) side_first[i + 1] += side_first[i];
        qsort(rf, m, sizeof *rf, ref_cmp);
        for (size_t i = 0; i < m; i++) perm[i] = rf[i].seg;
    }
    free(rf);
    for (size_t i = 0; i < m; i++) inv[perm[i]] = (int32_t)i;
    for (size_t i = 0; i < m; i++) es[perm[i]].pos = (int32_t)i; /* global running index */
    /* merge: group[i] (in sorted order) = final segment index */
    group = malloc(sizeof(int32_t) * (m ? m : 1));
    bstart = calloc(4 * (size_t)F + 1, sizeof(int32_t));
    br = malloc(sizeof(double) * (m ? m : 1));
    if (!group || !bstart || !br) { free(perm); free(inv); goto oom; }
    int32_t ng = 0, nb = 0;
    for (int32_t sd = 0; sd < 4 * F; sd++) {
        int32_t s0 = side_first[sd], s1 = side_first[sd + 1];
        if (s0 == s1) { /* cannot happen: every side has a cell */
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_FACE, sd / 4, "export face %d side %d is empty",
                           (int)(sd / 4), (int)(sd % 4));
            break;
        }
        for (int32_t i = s0; i < s1; i++) {
            int merge = 0;
            if (i > s0) {
                const eseg *A = &es[perm[i - 1]], *B = &es[perm[i]];
                if (A->crease != B->crease) merge = 0;
                else if (A->partner < 0 && B->partner < 0) merge = 1;
                else if (A->partner >= 0 && B->partner >= 0) {
                    int32_t pa = inv[A->partner], pb = inv[B->partner];
                    merge = pb + 1 == pa && es[A->partner].face == es[B->partner].face &&
                            es[A->partner].side == es[B->partner].side;
                }
            }
            if (!merge) {
                if (i > s0) br[nb++] = es[perm[i]].r0;
                ng++;
            }
            group[i] = ng - 1;
        }
        bstart[sd + 1] = nb;
    }
    if (st) { free(perm); free(inv); goto done; }
    adj = malloc(sizeof(int32_t) * (ng ? ng : 1));
    cr = malloc((size_t)(ng ? ng : 1));
    if (!adj || !cr) { free(perm); free(inv); goto oom; }
    for (int32_t i = 0; i < ng; i++) adj[i] = -1;
    for (size_t i = 0; i < m; i++) {
        const eseg *e = &es[perm[i]];
        if (e->partner >= 0) adj[group[i]] = group[inv[e->partner]];
        cr[group[i]] = (uint8_t)e->crease;
    }
    free(perm);
    free(inv);
    *breaks_start = bstart; bstart = NULL;
    *breaks = br; br = NULL;
    *adjacency = adj; adj = NULL;
    *crease = cr; cr = NULL;
    goto done;
oom:
    st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export topology)");
done:
    free(pc); free(xs); free(side_first); free(es); free(group); free(bstart); free(br); free(adj); free(cr);
    return st;
}
