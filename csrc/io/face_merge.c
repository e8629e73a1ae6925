/* Merging the CAD export's faces (io/face_merge.h).
 *
 * Why: the export builds its faces piece by piece (the bi-5 cap's rings, one L of three
 * patches per sector and ring, the bands of a refined hole, the packer's rectangles), and each
 * face costs the file its boundary: four edge curves, their vertices and the loop. Where two
 * faces of one kind and degree share a whole side and their union is one C^1 (or smoother)
 * spline in a common parametrisation, one face is the same surface with fewer entities.
 *
 * A pair (face A, side s; face B, side t) is merged when, after turning both domains by
 * quarter turns so that the shared side is A's u = max and B's u = min:
 *   - both are clamped across the join (along it clamped, or both periodic), of equal degrees,
 *     with the same number of cell rows;
 *   - their v knot vectors agree up to an affine map (B's v is re-parametrised onto A's);
 *   - the shared pole column agrees within tol (face_tolerance);
 *   - B's u is scaled so that the two cross-boundary derivatives agree (ratio of their lengths
 *     on the row where A's is largest, or the small fraction within 1e-9 of it if the union is
 *     C^1 with that: snap_ratio), the union written with the join knot of multiplicity p
 *     (C0: exact), and the join knot's copies the union does not need removed (the checked
 *     removal of io/knot_removal.c, the join's knot only): the merge is kept only if the join
 *     is left with at most p - 1 copies (C^1 or smoother). Anything else leaves both faces as
 *     they were.
 * Rounds of merges (each face at most once per round, the topology rebuilt between rounds)
 * run until none is possible, so nested pieces (a cap's rings around its centre) grow into one
 * or two faces per sector; across spokes a cap's rings join G1 only (the C2-rule's centre
 * relation), so sectors stay apart. The merged face has patch -1 and the cells of both, B's
 * re-parametrised.
 *
 * With `unify` the shared side's knots and cells may differ: both faces first take the union
 * of the two (Boehm's knot insertion along the side, cells cut; the surfaces unchanged), and
 * faces of the degree-3 kinds (packs, bicubic patches, refined pieces: all exact pieces of the
 * limit) merge across kinds. Around a semi-sharp crease the refined pieces of each level form a
 * band of that level's cells and knots beside the coarser level's: their unions are C2 (the
 * limit surface there is), so the bands of all levels and the packs beside them become one
 * face. A merge is kept only if the union has no more poles than the two faces had: the
 * inserted knots must be ones the join's knot removal gives back. Run after a pass without it
 * and the knot removal (io/knot_removal.h), so that the knots a band does not need are gone
 * before they would spread into its neighbours. Closed bands (periodic along the shared side,
 * as around a lathe shape's rings) merge only then (merged before the removal, a knot one band
 * needs would stay in the other); where their knots around differ, the union is inserted in the
 * periodic form (tface_insert_v_periodic), and where they start around at different points one
 * seam is moved to the other's first (align_seams). */
#include "io/face_merge.h"

#include "base/error.h"
#include "base/sorted.h"
#include "base/vec3.h"
#include "io/export_topo.h"
#include "io/knot_removal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A face's data in flat form, owned. */
typedef struct {
    int32_t deg[2], n[2], per[2]; /* per: periodic (the cad.h form) in that direction */
    double *t[2]; /* flat knots: n + deg + 1 */
    double *P;    /* pole (i, j) at 3 (i n[1] + j), i along u */
    int32_t cu, cv;
    ccn__xcell *cells; /* (i, j) at i + cu j */
} tface;

static void tface_free(tface *f) {
    free(f->t[0]); free(f->t[1]); free(f->P); free(f->cells);
    memset(f, 0, sizeof *f);
}

static int tface_of(const ccn__xmodel *xm, int32_t fi, tface *f) {
    const ccn__xface *X = &xm->faces[fi];
    const ccn__cad_surface *s = &X->s;
    memset(f, 0, sizeof *f);
    size_t np = (size_t)s->num_poles[0] * s->num_poles[1];
    f->P = malloc(sizeof(double) * 3 * np);
    f->cells = malloc(sizeof(ccn__xcell) * (size_t)X->cells_u * X->cells_v);
    for (int d = 0; d < 2; d++) {
        f->deg[d] = s->degree[d];
        f->n[d] = s->num_poles[d];
        f->per[d] = s->periodic[d];
        f->t[d] = malloc(sizeof(double) * (size_t)(s->num_poles[d] + s->degree[d] + 1));
    }
    if (!f->P || !f->cells || !f->t[0] || !f->t[1]) { tface_free(f); return -1; }
    memcpy(f->P, s->poles, sizeof(double) * 3 * np);
    for (int d = 0; d < 2; d++) ccn__cad_flat_knots(s, d, f->t[d]);
    f->cu = X->cells_u;
    f->cv = X->cells_v;
    memcpy(f->cells, xm->cells + X->cell0, sizeof(ccn__xcell) * (size_t)f->cu * f->cv);
    return 0;
}

/* A quarter turn of the domain: (u, v) -> (v, -u), side k becomes side k - 1 (orientation, and
 * so the normal, kept). */
static int tface_turn(tface *f) {
    int32_t nu = f->n[0], nv = f->n[1], mu = nu + f->deg[0] + 1;
    double *P = malloc(sizeof(double) * 3 * (size_t)nu * nv), *tv = malloc(sizeof(double) * (size_t)mu);
    ccn__xcell *C = malloc(sizeof(ccn__xcell) * (size_t)f->cu * f->cv);
    if (!P || !tv || !C) { free(P); free(tv); free(C); return -1; }
    for (int32_t i2 = 0; i2 < nv; i2++) /* new (i2, j2) = old (nu - 1 - j2, i2) */
        for (int32_t j2 = 0; j2 < nu; j2++)
            memcpy(P + 3 * ((size_t)i2 * nu + j2), f->P + 3 * ((size_t)(nu - 1 - j2) * nv + i2), sizeof(double) * 3);
    for (int32_t i = 0; i < mu; i++) tv[i] = -f->t[0][mu - 1 - i];
    for (int32_t ci = 0; ci < f->cu; ci++)
        for (int32_t cj = 0; cj < f->cv; cj++) {
            const ccn__xcell *a = &f->cells[ci + f->cu * cj];
            ccn__xcell *b = &C[cj + f->cv * (f->cu - 1 - ci)];
            b->uv[0] = a->uv[2], b->uv[1] = a->uv[3], b->uv[2] = -a->uv[1], b->uv[3] = -a->uv[0];
            ccn__xplace_rotate(&a->pl, 1, &b->pl);
        }
    free(f->P); free(f->cells); free(f->t[0]);
    f->P = P, f->cells = C;
    f->t[0] = f->t[1], f->t[1] = tv;
    int32_t d = f->deg[0]; f->deg[0] = f->deg[1], f->deg[1] = d;
    d = f->per[0]; f->per[0] = f->per[1], f->per[1] = d;
    f->n[0] = nv, f->n[1] = nu;
    int32_t c = f->cu; f->cu = f->cv, f->cv = c;
    return 0;
}

static int clamped(const double *t, int32_t n, int32_t p) {
    for (int32_t i = 1; i <= p; i++)
        if (t[i] != t[0] || t[n + p - i] != t[n + p]) return 0;
    return t[p + 1] > t[p] && t[n] > t[n - 1];
}

/* ---- closed bands: the seam moved ---------------------------------------------------------- */

/* f's seam in its periodic direction d moved to the knot r of its domain: the same surface, its
 * knots and pole rows shifted by k spans (a periodic spline's basis functions are translates,
 * so pole i and the knots from i on describe the same piece after a relabelling), the domain
 * [r, r + T], the cells before r moved up by the period T and placed after the others. Closed
 * bands around one ring start at different points of it (one band of a crease's level runs
 * around the other way); the topology then breaks their common side at both seams and they
 * would never be compared. 0: done, 1: r is not an interior knot and cell boundary (f unchanged),
 * -1: out of memory. */
static int tface_move_seam(tface *f, int d, double r) {
    int32_t p = f->deg[d], n = f->n[d], m = n - p, o = f->n[1 - d];
    const double *U = f->t[d];
    double T = U[n] - U[p];
    int32_t k = 0;
    for (int32_t i = 1; i < m && !k; i++)
        if (U[p + i] == r) k = i;
    int32_t cn = d ? f->cv : f->cu, co = d ? f->cu : f->cv, c0 = -1;
    for (int32_t c = 1; c < cn && c0 < 0; c++) { /* the first cell row at r */
        const ccn__xcell *x = &f->cells[d ? f->cu * c : c];
        if (x->uv[2 * d] == r) c0 = c;
    }
    if (!k || c0 < 0 || !f->per[d]) return 1;
    double *t = malloc(sizeof(double) * (size_t)(n + p + 1)), *P = malloc(sizeof(double) * 3 * (size_t)n * o);
    ccn__xcell *C = malloc(sizeof(ccn__xcell) * (size_t)cn * co);
    if (!t || !P || !C) { free(t); free(P); free(C); return -1; }
    for (int32_t i = 0; i <= n + p; i++) t[i] = i + k <= n + p ? U[i + k] : U[i + k - m] + T;
    for (int32_t i = 0; i < n; i++) /* pole row i along d: the old row (i + k) mod m */
        for (int32_t j = 0; j < o; j++) {
            int32_t src = (i + k) % m;
            size_t a = d ? (size_t)j * n + i : (size_t)i * o + j, b = d ? (size_t)j * n + src : (size_t)src * o + j;
            memcpy(P + 3 * a, f->P + 3 * b, sizeof(double) * 3);
        }
    for (int32_t c = 0; c < cn; c++)
        for (int32_t e = 0; e < co; e++) {
            int32_t c2 = (c - c0 + cn) % cn;
            ccn__xcell x = f->cells[d ? e + f->cu * c : c + f->cu * e];
            if (c < c0) x.uv[2 * d] += T, x.uv[2 * d + 1] += T;
            C[d ? e + f->cu * c2 : c2 + f->cu * e] = x;
        }
    free(f->t[d]); free(f->P); free(f->cells);
    f->t[d] = t, f->P = P, f->cells = C;
    return 0;
}

/* ---- sides of different knots and cells: both made the union's ------------------------ */

/* x snapped to the nearest of the n non-decreasing values a within tol (else x); a binary
 * search (a merged band's side holds a thousand knots and as many cells). */
static double snap_to(double x, const double *a, int32_t n, double tol) {
    int32_t lo = (int32_t)ccn__first_at_least(a, (size_t)n, x);
    double r = x, best = tol;
    if (lo > 0 && fabs(a[lo - 1] - x) <= best) best = fabs(a[lo - 1] - x), r = a[lo - 1];
    if (lo < n && fabs(a[lo] - x) <= best) r = a[lo];
    return r;
}

/* f's v knots made U (m values, a superset of f's with f's ends): each missing copy inserted into
 * every u row (Boehm; the surface unchanged). 1: U is not a superset (f unchanged), -1: out of
 * memory. */
static int tface_insert_v(tface *f, const double *U, int32_t m) {
    int32_t nu = f->n[0], nv = f->n[1], q = f->deg[1], N = m - q - 1, w = 3 * nu;
    double *Q = malloc(sizeof(double) * (size_t)w * N), *t = malloc(sizeof(double) * (size_t)m);
    if (!Q || !t) { free(Q); free(t); return -1; }
    for (int32_t j = 0; j < nv; j++) /* v-major: pole j holds the whole u row */
        for (int32_t i = 0; i < nu; i++) memcpy(Q + (size_t)j * w + 3 * i, f->P + 3 * ((size_t)i * nv + j), sizeof(double) * 3);
    memcpy(t, f->t[1], sizeof(double) * (size_t)(nv + q + 1));
    int32_t n = nv;
    for (int32_t i = 0, j = 0; i < m; i++) { /* U's values missing from t, in increasing order */
        if (j < n + q + 1 && t[j] == U[i]) { j++; continue; }
        if (n == N) { n = -1; break; } /* more missing than U has room for: not a superset */
        ccn__insert_knot(Q, &n, w, t, q, U[i]);
        j++;
    }
    if (n != N) { free(Q); free(t); return 1; }
    double *P = malloc(sizeof(double) * 3 * (size_t)nu * N);
    if (!P) { free(Q); free(t); return -1; }
    for (int32_t j = 0; j < N; j++)
        for (int32_t i = 0; i < nu; i++) memcpy(P + 3 * ((size_t)i * N + j), Q + (size_t)j * w + 3 * i, sizeof(double) * 3);
    free(Q); free(f->P); free(f->t[1]);
    f->P = P, f->t[1] = t, f->n[1] = N;
    return 0;
}

/* The same for f periodic along v: its knots within the period made D (nd values from its
 * domain's start to its end, f's among them). Unwrapped to the clamped form (exact), the
 * missing knots inserted, wrapped again (kept only if the periodic form reproduces the clamped
 * one within tol). 1: not a superset, or not periodic again (f unchanged); -1: out of memory. */
static int tface_insert_v_periodic(tface *f, const double *D, int32_t nd, double tol) {
    int32_t q = f->deg[1], n = f->n[1], rows = f->n[0], n1 = nd - 1 + q;
    if (n1 <= n) return 1;
    double *U = malloc(sizeof(double) * (size_t)(n + 3 * q + 1));
    double *W = malloc(sizeof(double) * 3 * (size_t)rows * (n + 2 * q));
    double *W1 = malloc(sizeof(double) * 3 * (size_t)rows * n1);
    double *t = malloc(sizeof(double) * (size_t)(n1 + 3 * q + 1));
    int r = 0;
    if (!U || !W || !W1 || !t) { r = -1; goto out; }
    memcpy(U, f->t[1], sizeof(double) * (size_t)(n + q + 1));
    memcpy(W, f->P, sizeof(double) * 3 * (size_t)rows * n); /* row i (along u) runs along v */
    if (ccn__kr_unwrap_periodic(U, q, n, rows, W)) { r = -1; goto out; }
    for (int32_t row = 0; row < rows && !r; row++) {
        double *P = W1 + 3 * (size_t)row * n1;
        memcpy(P, W + 3 * (size_t)row * n, sizeof(double) * 3 * (size_t)n);
        memcpy(t, U, sizeof(double) * (size_t)(n + q + 1));
        int32_t N = n, j = q + 1;
        for (int32_t i = 1; i + 1 < nd; i++) { /* D's interior values missing from t */
            if (j < N && t[j] == D[i]) { j++; continue; }
            if (N == n1) { r = 1; break; }
            ccn__insert_knot(P, &N, 3, t, q, D[i]);
            j++;
        }
        if (!r && (N != n1 || t[q] != D[0] || t[n1] != D[nd - 1])) r = 1;
    }
    if (!r) r = ccn__kr_rewrap_periodic(t, q, n1, rows, W1, tol);
    if (!r) {
        free(f->P); free(f->t[1]);
        f->P = W1, f->t[1] = t, f->n[1] = n1;
        W1 = t = NULL;
    }
out:
    free(U); free(W); free(W1); free(t);
    return r;
}

/* y as k / 2^d (d <= 30) when it is one to 1e-9, else NaN: cells are dyadic rectangles of their
 * cage face, and places are compared exactly (export_model.h). */
static double dyadic(double y) {
    double s = 1073741824.0, k = nearbyint(y * s);
    return fabs(y - k / s) <= 1e-9 ? k / s : NAN;
}

/* f's cells cut along v at the values c (nc, increasing, f's own boundaries among them): each
 * part's place the matching sub-rectangle of its cell's. 1: a cut not at a dyadic fraction of
 * its cell (f unchanged), -1: out of memory. */
static int tface_cut_v(tface *f, const double *c, int32_t nc) {
    int32_t cv = nc - 1;
    ccn__xcell *C = malloc(sizeof(ccn__xcell) * (size_t)f->cu * cv);
    if (!C) return -1;
    for (int32_t ci = 0; ci < f->cu; ci++)
        for (int32_t cj = 0, k = 0; cj < f->cv; cj++) {
            const ccn__xcell *a = &f->cells[ci + f->cu * cj];
            double v0 = a->uv[2], v1 = a->uv[3];
            for (; k < cv && c[k] < v1; k++) {
                ccn__xcell *b = &C[ci + f->cu * k];
                double y0 = dyadic((c[k] - v0) / (v1 - v0)), y1 = dyadic((c[k + 1] - v0) / (v1 - v0));
                if (!(y0 >= 0 && y1 <= 1)) { free(C); return 1; }
                double r[3][2] = {{0, y0}, {1, y0}, {0, y1}};
                *b = *a;
                b->uv[2] = c[k], b->uv[3] = c[k + 1];
                ccn__xplace_sub(&a->pl, (const double(*)[2])r, &b->pl);
            }
        }
    free(f->cells);
    f->cells = C;
    f->cv = cv;
    return 0;
}

/* A pair's tolerance: rel_tol times the face's size (its poles' bounding-box diagonal) plus the
 * rounding of its coordinates (16 units in the last place of the largest). Measured on the
 * test cages, OpenSubdiv's car and the 2.5k cage: unions that are C1 miss it by at most 3e-12 of
 * the largest coordinate (the bi-5 patches' own construction; degree-3 pieces 1e-14), unions
 * that are not by 1e-6 or more, and the shared columns of faces that meet differ by at most
 * 3e-12; so rel_tol = 1e-10 decides far from both (the same faces on every platform's build),
 * while the surface moves only by the union's actual defect. */
static double face_tolerance(const ccn__cad_surface *s, double rel_tol) {
    double big, size = ccn__cad_surface_size(s, &big);
    return rel_tol * size + 16 * DBL_EPSILON * big;
}

/* B's v (along the shared side) made A's parameter, and both faces' v knots and cells the
 * union of the two: a side of a coarser level's piece against a finer one's, or of pieces
 * whose knots were thinned differently. The surfaces are unchanged (knot insertion, cells cut);
 * whether the two sides are the same curve is merge_pair's shared-column check. tol_a, tol_b:
 * each face's own rounding, within which a closed face's union must reproduce it
 * (tface_insert_v_periodic). 0: done (or nothing to do), 1: not comparable, -1: out of memory. */
static int unify_v(tface *A, tface *B, double tol_a, double tol_b) {
    int32_t q = A->deg[1], ma = A->n[1] + q + 1, mb = B->n[1] + q + 1;
    if (B->deg[1] != q || A->per[1] != B->per[1]) return 1;
    int per = A->per[1]; /* closed sides: the knots within the period, wrapped again */
    double *ta = A->t[1], *tb = B->t[1];
    /* the domains' ends (a clamped face's end knots, a periodic one's period) */
    double a0 = ta[q], a1 = ta[A->n[1]], b0 = tb[q], b1 = tb[B->n[1]], sv = (a1 - a0) / (b1 - b0);
    double tol = 1e-12 * (a1 - a0);
    if (!(sv > 0) || !isfinite(sv)) return 1;
    /* A's cell boundaries */
    int32_t ca = A->cv + 1, cb = B->cv + 1;
    double *U = malloc(sizeof(double) * (size_t)(ma + mb)), *bc = malloc(sizeof(double) * (size_t)cb),
           *ac = malloc(sizeof(double) * (size_t)ca), *C = malloc(sizeof(double) * (size_t)(ca + cb));
    if (!U || !bc || !ac || !C) { free(U); free(bc); free(ac); free(C); return -1; }
    for (int32_t j = 0; j < A->cv; j++) ac[j] = A->cells[A->cu * j].uv[2];
    ac[A->cv] = A->cells[A->cu * (A->cv - 1)].uv[3];
    /* B mapped: knots and cells onto A's values where they meet them */
    for (int32_t i = 0; i < mb; i++) {
        double x = a0 + (tb[i] - b0) * sv;
        x = snap_to(x, ta, ma, tol);
        tb[i] = snap_to(x, ac, ca, tol);
    }
    for (int32_t k = 0; k < B->cu * B->cv; k++)
        for (int e = 2; e < 4; e++) {
            double x = a0 + (B->cells[k].uv[e] - b0) * sv;
            x = snap_to(x, ac, ca, tol);
            B->cells[k].uv[e] = snap_to(x, ta, ma, tol);
        }
    for (int32_t j = 0; j < B->cv; j++) bc[j] = B->cells[B->cu * j].uv[2];
    bc[B->cv] = B->cells[B->cu * (B->cv - 1)].uv[3];
    /* the unions (sorted merges: equal values once, knots with the larger multiplicity; of a
     * periodic face the knots of its domain) */
    int32_t m = 0, nc = 0, r = 0;
    const double *xa = per ? ta + q : ta, *xb = per ? tb + q : tb;
    int32_t la = per ? A->n[1] - q + 1 : ma, lb = per ? B->n[1] - q + 1 : mb;
    for (int32_t i = 0, j = 0; i < la || j < lb;) {
        if (j >= lb || (i < la && xa[i] < xb[j])) U[m++] = xa[i++];
        else if (i >= la || xb[j] < xa[i]) U[m++] = xb[j++];
        else U[m++] = xa[i++], j++;
    }
    for (int32_t i = 0, j = 0; i < ca || j < cb;) {
        if (j >= cb || (i < ca && ac[i] < bc[j])) C[nc++] = ac[i++];
        else if (i >= ca || bc[j] < ac[i]) C[nc++] = bc[j++];
        else C[nc++] = ac[i++], j++;
    }
    for (int32_t i = 1; i + q < m - 1 && !r; i++) /* an interior knot of more than q copies */
        if (U[i] > U[0] && U[i + q] == U[i] && U[i] < U[m - 1]) r = 1;
    if (per) {
        if (!r && m != la) r = tface_insert_v_periodic(A, U, m, tol_a);
        if (!r && m != lb) r = tface_insert_v_periodic(B, U, m, tol_b);
    } else {
        if (!r && m != ma) r = tface_insert_v(A, U, m);
        if (!r && m != mb) r = tface_insert_v(B, U, m);
    }
    if (!r && nc != ca) r = tface_cut_v(A, C, nc);
    if (!r && nc != cb) r = tface_cut_v(B, C, nc);
    free(U); free(bc); free(ac); free(C);
    return r;
}

/* B's v parameter x on A's: A's knot where x is B's corresponding knot (exactly: the cells'
 * ends must be the face's own values, or a sample on the border would fall outside the domain),
 * else the affine map. */
static double map_v(const double *ta, const double *tb, int32_t mv, double sv, double x) {
    int32_t lo = (int32_t)ccn__first_at_least(tb, (size_t)mv, x); /* tb non-decreasing */
    if (lo < mv && tb[lo] == x) return ta[lo];
    return ta[0] + (x - tb[0]) * sv;
}

/* c, or the fraction a / b (b <= 4096) within 1e-9 of it: the pieces' parameter lengths are
 * ratios of small integers (ring speeds, cell counts), measured here to about 1e-12 from the
 * poles. The exact ratio makes the join C^1 to rounding rather than to the measurement, and the
 * merged faces' knots exact, so that equal domains repeat bit for bit (their pcurves are
 * written once, io/step.c). The knot removal below checks the union either way. */
static double snap_ratio(double c) {
    double x = c, h0 = 1, h1 = 0, k0 = 0, k1 = 1; /* convergents h/k of c's continued fraction */
    for (int i = 0; i < 40; i++) {
        double a = floor(x), h = a * h0 + h1, k = a * k0 + k1;
        if (k > 4096) break;
        if (fabs(h / k - c) <= 1e-9 * c) return h / k;
        h1 = h0, h0 = h, k1 = k0, k0 = k;
        if (x - a < 1e-15) break;
        x = 1 / (x - a);
    }
    return c;
}

/* The union of A and B with B's u scaled by c and its v mapped onto A's by sv (merge_pair),
 * or 0 when it is not C^1. -1: out of memory. */
static int merge_scaled(const tface *A, const tface *B, double tol, double c, double sv, tface *M) {
    int32_t p = A->deg[0], q = A->deg[1], nA = A->n[0], nB = B->n[0], nv = A->n[1], mv = nv + q + 1;
    const double *ta = A->t[1], *tb = B->t[1];
    memset(M, 0, sizeof *M);
    /* the union: u knots A's (without its end copies), the join p times, B's scaled */
    int32_t n = nA + nB - 1, m = n + p + 1;
    double *U = malloc(sizeof(double) * (size_t)m), *W = malloc(sizeof(double) * 3 * (size_t)n * nv);
    if (!U || !W) { free(U); free(W); return -1; }
    double uj = A->t[0][nA + p], ub = B->t[0][0];
    for (int32_t i = 0; i < nA; i++) U[i] = A->t[0][i];
    for (int32_t i = 0; i < p; i++) U[nA + i] = uj;
    for (int32_t i = p + 1; i <= nB + p; i++) U[nA + p + (i - p - 1)] = uj + c * (B->t[0][i] - ub);
    /* rows along u: W[row j][k] */
    for (int32_t j = 0; j < nv; j++)
        for (int32_t k = 0; k < n; k++) {
            const double *src = k < nA ? A->P + 3 * ((size_t)k * nv + j) : B->P + 3 * ((size_t)(k - nA + 1) * nv + j);
            memcpy(W + 3 * ((size_t)j * n + k), src, sizeof(double) * 3);
        }
    int32_t n1 = n, got = ccn__kr_reduce_rows(U, p, &n1, nv, W, tol, uj);
    if (got < 0) { free(U); free(W); return -1; }
    int32_t mult = 0;
    for (int32_t i = 0; i < n1 + p + 1; i++) mult += U[i] == uj;
    if (got == 0 || mult > p - 1) { free(U); free(W); return 0; }
    M->deg[0] = p, M->deg[1] = q;
    M->n[0] = n1, M->n[1] = nv;
    M->per[0] = 0, M->per[1] = A->per[1];
    M->t[0] = U;
    M->t[1] = malloc(sizeof(double) * (size_t)mv);
    M->P = malloc(sizeof(double) * 3 * (size_t)n1 * nv);
    M->cu = A->cu + B->cu, M->cv = A->cv;
    M->cells = malloc(sizeof(ccn__xcell) * (size_t)M->cu * M->cv);
    if (!M->t[1] || !M->P || !M->cells) { free(W); tface_free(M); return -1; }
    memcpy(M->t[1], ta, sizeof(double) * (size_t)mv);
    for (int32_t i = 0; i < n1; i++)
        for (int32_t j = 0; j < nv; j++) memcpy(M->P + 3 * ((size_t)i * nv + j), W + 3 * ((size_t)j * n1 + i), sizeof(double) * 3);
    free(W);
    for (int32_t cj = 0; cj < M->cv; cj++) {
        for (int32_t ci = 0; ci < A->cu; ci++) M->cells[ci + M->cu * cj] = A->cells[ci + A->cu * cj];
        for (int32_t ci = 0; ci < B->cu; ci++) {
            ccn__xcell x = B->cells[ci + B->cu * cj];
            x.uv[0] = uj + c * (x.uv[0] - ub), x.uv[1] = uj + c * (x.uv[1] - ub);
            x.uv[2] = map_v(ta, tb, mv, sv, x.uv[2]), x.uv[3] = map_v(ta, tb, mv, sv, x.uv[3]);
            M->cells[A->cu + ci + M->cu * cj] = x;
        }
    }
    return 1;
}

/* The union of A (its u = max side) and B (its u = min side), or 0 when it is not C^1; M gets
 * the merged face. -1: out of memory. */
static int merge_pair(const tface *A, const tface *B, double tol, tface *M) {
    int32_t p = A->deg[0], q = A->deg[1], nA = A->n[0], nB = B->n[0], nv = A->n[1];
    memset(M, 0, sizeof *M);
    if (B->deg[0] != p || B->deg[1] != q || B->n[1] != nv || B->cv != A->cv) return 0;
    /* across the join clamped; along it clamped, or both periodic (closed bands stacked) */
    if (A->per[0] || B->per[0] || A->per[1] != B->per[1] || !clamped(A->t[0], nA, p) || !clamped(B->t[0], nB, p) ||
        (!A->per[1] && (!clamped(A->t[1], nv, q) || !clamped(B->t[1], nv, q))))
        return 0;
    /* v: B's knots an affine image of A's */
    const double *ta = A->t[1], *tb = B->t[1];
    int32_t mv = nv + q + 1;
    double a0 = ta[0], a1 = ta[mv - 1], b0 = tb[0], b1 = tb[mv - 1], sv = (a1 - a0) / (b1 - b0);
    for (int32_t i = 0; i < mv; i++)
        if (fabs(a0 + (tb[i] - b0) * sv - ta[i]) > 1e-12 * (a1 - a0)) return 0;
    /* the shared column */
    for (int32_t j = 0; j < nv; j++)
        if (!(ccn__dist3(A->P + 3 * ((size_t)(nA - 1) * nv + j), B->P + 3 * (size_t)j) <= tol)) return 0;
    /* B's u scale: the cross-boundary derivatives' ratio on A's largest */
    double best = -1, c = 1;
    double ha = A->t[0][nA + p] - A->t[0][nA - 1], hb = B->t[0][p + 1] - B->t[0][0];
    for (int32_t j = 0; j < nv; j++) {
        double da[3], db[3];
        for (int k = 0; k < 3; k++) {
            da[k] = (A->P[3 * ((size_t)(nA - 1) * nv + j) + k] - A->P[3 * ((size_t)(nA - 2) * nv + j) + k]) / ha;
            db[k] = (B->P[3 * ((size_t)nv + j) + k] - B->P[3 * (size_t)j + k]) / hb;
        }
        double la = sqrt(da[0] * da[0] + da[1] * da[1] + da[2] * da[2]);
        double lb = sqrt(db[0] * db[0] + db[1] * db[1] + db[2] * db[2]);
        if (la > best && lb > 0) best = la, c = lb / la;
    }
    if (!(best > 0) || !(c > 0) || !isfinite(c)) return 0;
    double cs = snap_ratio(c);
    if (cs != c) { /* the exact ratio first; the measured one if the union is not C^1 with it */
        int r = merge_scaled(A, B, tol, cs, sv, M);
        if (r) return r;
    }
    return merge_scaled(A, B, tol, c, sv, M);
}


/* Face fi of xm becomes M (its arrays taken over; cells appended to xm->cells). */
static int replace_face(ccn__xmodel *xm, int32_t fi, tface *M) {
    ccn__xface *X = &xm->faces[fi];
    int32_t nc = M->cu * M->cv;
    if (xm->num_cells + nc > xm->cap_cells) {
        int32_t cap = 2 * (xm->num_cells + nc) + 256;
        ccn__xcell *p = realloc(xm->cells, sizeof *p * (size_t)cap);
        if (!p) return -1;
        xm->cells = p;
        xm->cap_cells = cap;
    }
    memcpy(xm->cells + xm->num_cells, M->cells, sizeof(ccn__xcell) * (size_t)nc);
    X->cell0 = xm->num_cells;
    xm->num_cells += nc;
    X->cells_u = M->cu, X->cells_v = M->cv;
    X->patch = -1;
    X->merged = 1;
    ccn__cad_surface *s = &X->s;
    free((void *)s->poles);
    s->poles = M->P;
    M->P = NULL;
    for (int d = 0; d < 2; d++) {
        s->degree[d] = M->deg[d];
        s->num_poles[d] = M->n[d];
        s->periodic[d] = M->per[d];
        if (ccn__xm_set_flat(xm, fi, d, M->t[d])) return -1;
    }
    return 0;
}

static void drop_face(ccn__xmodel *xm, int32_t fi) {
    ccn__xm_free_surface(&xm->faces[fi].s);
    xm->faces[fi].kind = -1;
}

/* The kind of a union of faces of kinds a and b (degree-3 kinds when they differ). */
static int32_t union_kind(int32_t a, int32_t b) {
    if (a == b) return a;
    return a == CCN_EXPORT_FACE_REFINED || b == CCN_EXPORT_FACE_REFINED ? CCN_EXPORT_FACE_REFINED : CCN_EXPORT_FACE_PACK;
}

static int cubic_kind(int32_t kind) {
    return kind == CCN_EXPORT_FACE_PACK || kind == CCN_EXPORT_FACE_BICUBIC || kind == CCN_EXPORT_FACE_REFINED;
}

static int mergeable_kind(int32_t kind) {
    return kind == CCN_EXPORT_FACE_PACK || kind == CCN_EXPORT_FACE_BICUBIC || kind == CCN_EXPORT_FACE_BI5 ||
           kind == CCN_EXPORT_FACE_REFINED;
}

/* Where two closed bands share a side that the topology breaks only at their two seams (one
 * break on each side, both pieces of each side against the other face), one band's seam is
 * moved to the other's (tface_move_seam), so that the next topology sees one whole side and the
 * pair is tried. The band moved is one whose opposite side is not already whole against a
 * neighbour (so a move never undoes a match, and the moves end). Both faces of a pair are marked
 * in done (this round's topology no longer describes the moved one). Returns the number of
 * seams moved, -1 on out of memory. */
static int64_t align_seams(ccn__xmodel *xm, const int32_t *bs, const double *br, const int32_t *adj,
                           const int32_t *segface, const uint8_t *segside, uint8_t *done) {
    int32_t nf = xm->num_faces;
    int64_t moved = 0;
    for (int32_t f = 0; f < nf; f++)
        for (int s = 0; s < 4 && !done[f]; s++) {
            int d = s % 2 == 0 ? 0 : 1; /* sides 0, 2 run along u */
            if (!mergeable_kind(xm->faces[f].kind) || !xm->faces[f].s.periodic[d] ||
                bs[4 * f + s + 1] - bs[4 * f + s] != 1)
                continue;
            int32_t j0 = 4 * f + s + bs[4 * f + s], a0 = adj[j0], a1 = adj[j0 + 1];
            if (a0 < 0 || a1 < 0) continue;
            int32_t g = segface[a0], t = segside[a0];
            int dg = t % 2 == 0 ? 0 : 1; /* g's direction along the shared side */
            if (g == f || segface[a1] != g || segside[a1] != t || done[g] || !xm->faces[g].s.periodic[dg] ||
                !mergeable_kind(xm->faces[g].kind) || bs[4 * g + t + 1] - bs[4 * g + t] != 1)
                continue;
            /* the one to move: its opposite side not whole against a neighbour */
            int32_t h = -1;
            int dh = 0;
            double r = 0;
            int ot = (t + 2) % 4, os = (s + 2) % 4;
            if (!(bs[4 * g + ot + 1] == bs[4 * g + ot] && adj[4 * g + ot + bs[4 * g + ot]] >= 0))
                h = g, dh = dg, r = br[bs[4 * g + t]];
            else if (!(bs[4 * f + os + 1] == bs[4 * f + os] && adj[4 * f + os + bs[4 * f + os]] >= 0))
                h = f, dh = d, r = br[bs[4 * f + s]];
            if (h < 0) continue;
            tface A;
            if (tface_of(xm, h, &A)) return -1;
            int rc = tface_move_seam(&A, dh, r);
            if (rc == 0) {
                ccn__xface keep = xm->faces[h];
                if (replace_face(xm, h, &A)) rc = -1;
                xm->faces[h].patch = keep.patch, xm->faces[h].merged = keep.merged;
            }
            tface_free(&A);
            if (rc < 0) return -1;
            if (rc == 0) done[f] = done[g] = 1, moved++;
        }
    return moved;
}

ccn_status ccn__xm_merge_faces(ccn__xmodel *xm, const ccn_mesh *cage, double rel_tol, int unify,
                                int64_t *merged, ccn_error *err) {
    *merged = 0;
    int seam_rounds = 0;
    for (;;) {
        int32_t *bs = NULL, *adj = NULL;
        double *br = NULL;
        uint8_t *crease = NULL;
        ccn_status st = ccn__xtopo_build(xm, cage, &bs, &br, &adj, &crease, err);
        if (st) return st;
        int32_t nf = xm->num_faces, nseg = 4 * nf + bs[4 * nf];
        int32_t *segface = malloc(sizeof(int32_t) * (size_t)nseg);
        uint8_t *segside = malloc((size_t)nseg), *used = calloc((size_t)nf, 1);
        if (!segface || !segside || !used) {
            free(segface); free(segside); free(used); free(bs); free(br); free(adj); free(crease);
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face merging)");
        }
        for (int32_t f = 0; f < nf; f++)
            for (int s = 0; s < 4; s++)
                for (int32_t k = 0; k <= bs[4 * f + s + 1] - bs[4 * f + s]; k++) {
                    int32_t j = 4 * f + s + bs[4 * f + s] + k;
                    segface[j] = f, segside[j] = (uint8_t)s;
                }
        int64_t round = 0;
        int oom = 0;
        int64_t moved = 0; /* closed bands' seams first: a pair aligned is tried in the next round */
        if (unify && seam_rounds < 16 && (moved = align_seams(xm, bs, br, adj, segface, segside, used)) != 0)
            oom = moved < 0, seam_rounds++;
        for (int32_t f = 0; f < nf && !oom; f++) {
            if (used[f] || !mergeable_kind(xm->faces[f].kind)) continue;
            for (int s = 0; s < 4 && !used[f] && !oom; s++) {
                if (bs[4 * f + s + 1] != bs[4 * f + s]) continue; /* split side */
                int32_t j = 4 * f + s + bs[4 * f + s], o = adj[j];
                if (o < 0 || crease[j]) continue;
                int32_t g = segface[o], t = segside[o];
                int32_t kf = xm->faces[f].kind, kg = xm->faces[g].kind;
                if (g == f || used[g] || (kg != kf && !(unify && cubic_kind(kf) && cubic_kind(kg)))) continue;
                if (bs[4 * g + t + 1] != bs[4 * g + t]) continue;
                const ccn__cad_surface *sf = &xm->faces[f].s, *sg = &xm->faces[g].s;
                if ((sf->periodic[0] || sf->periodic[1] || sg->periodic[0] || sg->periodic[1]) &&
                    (!unify || (sf->periodic[0] && sf->periodic[1]) || (sg->periodic[0] && sg->periodic[1])))
                    continue; /* closed bands only once their knots are removed (the poles rule) */
                tface A, B, M;
                if (tface_of(xm, f, &A)) { oom = 1; break; }
                if (tface_of(xm, g, &B)) { tface_free(&A); oom = 1; break; }
                int r = 0;
                for (int k = 0; k < (s + 3) % 4 && !r; k++) r = tface_turn(&A); /* side s -> 1 */
                for (int k = 0; k < (t + 1) % 4 && !r; k++) r = tface_turn(&B); /* side t -> 3 */
                int64_t poles = (int64_t)A.n[0] * A.n[1] + (int64_t)B.n[0] * B.n[1];
                if (!r && unify && (r = unify_v(&A, &B, face_tolerance(sf, 1e-12), face_tolerance(sg, 1e-12))) > 0) { /* sides not comparable */
                    tface_free(&A);
                    tface_free(&B);
                    continue;
                }
                double tol = fmax(face_tolerance(sf, rel_tol), face_tolerance(sg, rel_tol));
                int ok = r ? -1 : merge_pair(&A, &B, tol, &M);
                if (ok > 0 && (int64_t)M.n[0] * M.n[1] > poles) { /* inserted knots kept: not smaller */
                    tface_free(&M);
                    ok = 0;
                }
                tface_free(&A);
                tface_free(&B);
                if (ok < 0) { oom = 1; break; }
                if (!ok) continue;
                if (replace_face(xm, f, &M)) { tface_free(&M); oom = 1; break; }
                tface_free(&M);
                xm->faces[f].kind = union_kind(kf, kg);
                drop_face(xm, g);
                used[f] = used[g] = 1;
                round++;
            }
        }
        free(segface); free(segside); free(used); free(bs); free(br); free(adj); free(crease);
        if (oom) {
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face merging)");
        }
        /* the dropped faces out (their cells stay unused in xm->cells) */
        int32_t w = 0;
        for (int32_t f = 0; f < xm->num_faces; f++)
            if (xm->faces[f].kind >= 0) xm->faces[w++] = xm->faces[f];
        xm->num_faces = w;
        *merged += round;
        if (!round && moved <= 0) break;
    }
    return CCN_OK;
}
