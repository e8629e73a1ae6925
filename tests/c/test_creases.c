/* Creases with knot intervals, against an oracle written here from first
 * principles (cubic B-splines on explicit knots, de Boor evaluation, Boehm insertion, point
 * reflection at boundaries); no code or formula is shared with csrc/.
 *
 *  1. Open grids and tori with random ring intervals in [0.05, 20] and an infinitely sharp
 *     crease line across: every limit position equals one of the two tensor-product B-spline
 *     surfaces that the crease bounds (each side's control grid, point-reflected at the crease
 *     and at the grid's boundary, pinned corners), <= 1e-12 of the bounding box; every face
 *     corner's normal equals its side's surface normal (<= 1e-10 rad), so the two sides of the
 *     crease get their own exact normals.
 *  2. The refined crease polygon equals 1-D Boehm insertion (every span halved per level) of
 *     the crease polygon with its intervals, point-reflected at the ends.
 *  3. Semi-sharp: sharpness k behaves as infinitely sharp for k levels and as smooth after:
 *     refine(s = k, k levels) = refine(s = 10, k levels), refine(s = k, k + 2) = 2 smooth
 *     levels of refine(s = 10, k); a fractional s = k + 1/2 gives, at level k + 1, the mean of
 *     the crease and the smooth points on the crease and the smooth points elsewhere.
 *  4. Random sharpness in [0, 12] (edges and vertices) and random intervals on a torus: the
 *     limit is finite and exact (every output vertex of level L is, to 1e-12, an output
 *     vertex of level L + 1), normals are unit.
 *  5. Extraordinary vertices on and next to creases (a cube with a creased edge chain: crease,
 *     corner and dart EVs; a valence-5 and a valence-3 vertex on a crease): finite output,
 *     caps at the smooth EVs, several normals at crease vertices; every face corner's normal
 *     matches the normal of the finer limit mesh's face at that corner (finite differences,
 *     converging with the level), also at the sharp corners; a semi-sharp variant is exact
 *     (level 2's limit points are level 3's).
 */
#include "ccnurbs.h"
#include "testlib.h"

#include <stdint.h>

#define TOL_POS 1e-12
#define TOL_ANGLE 1e-10

#include "bspline_oracle.h" /* the oracle: cubic B-spline curves, de Boor evaluation */

/* A tensor surface over a (nu+1) x (nv+1) grid G[i][j] (3 doubles), intervals DU, DV.
 * Value and both derivatives at grid-parameter (u, v) given as (span, fraction). */
typedef struct { int nu, nv, pu, pv; const double *G; const double *DU, *DV; } osurf;

static void os_eval(const osurf *s, int ku, double fu, int kv, double fv, double X[3], double Su[3],
                    double Sv[3]) {
    int nrow = s->pu ? s->nu : s->nu + 1, ncol = s->pv ? s->nv : s->nv + 1;
    double *C = NEW(double, (size_t)nrow * 6); /* per row: value(3), d/dv(3) along v */
    double *row = NEW(double, (size_t)ncol * 3);
    for (int i = 0; i < nrow; i++) {
        for (int j = 0; j < ncol; j++) memcpy(row + 3 * j, s->G + 3 * ((size_t)i * ncol + j), sizeof(double) * 3);
        ocurve cv = oc_make(row, s->nv, 3, s->DV, s->pv);
        double x = cv.t[2 + kv] + fv * (cv.t[2 + kv + 1] - cv.t[2 + kv]);
        oc_eval(&cv, x, kv, C + 6 * i, C + 6 * i + 3);
        oc_free(&cv);
    }
    ocurve cu = oc_make(C, s->nu, 6, s->DU, s->pu);
    double x = cu.t[2 + ku] + fu * (cu.t[2 + ku + 1] - cu.t[2 + ku]), val[6], der[6];
    oc_eval(&cu, x, ku, val, der);
    oc_free(&cu);
    for (int q = 0; q < 3; q++) { X[q] = val[q]; Sv[q] = val[3 + q]; Su[q] = der[q]; }
    free(C);
    free(row);
}

/* Boehm: insert the midpoint of every span of the curve L times; returns the refined polygon
 * (between the original end points), 2^L n + 1 points (closed: 2^L n). */
static double *oc_boehm(const double *Q, int n, const double *I, int periodic, int L, int *nout) {
    /* knot-interval form of one insertion pass (from blossoms): for a cubic B-spline with
     * points P_i and intervals D_i, inserting the midpoint of span i gives the edge point
     * f(t_i, t_i + D_i/2, t_{i+1}) and vertex point f(t_i - D_{i-1}/2, t_i, t_i + D_i/2),
     * evaluated by blossoming on the local knots */
    int m = n;
    double *P = NEW(double, (size_t)(n + 1) * 3), *D = NEW(double, n);
    memcpy(P, Q, sizeof(double) * 3 * (size_t)(periodic ? n : n + 1)); /* closed: n points */
    memcpy(D, I, sizeof(double) * (size_t)n);
    for (int l = 0; l < L; l++) {
        ocurve c = oc_make(P, m, 3, D, periodic);
        int m2 = 2 * m;
        double *P2 = NEW(double, (size_t)(m2 + 1) * 3), *D2 = NEW(double, m2);
        const double *t = c.t + 2;
        for (int i = 0; i <= m; i++) {
            for (int e = 0; e < 2; e++) {
                if (e == 1 && i == m) break;
                /* new point's blossom arguments */
                double a, b, cc;
                if (e == 0) { a = t[i] - (t[i] - t[i - 1]) / 2; b = t[i]; cc = t[i] + (t[i + 1] - t[i]) / 2; }
                else { a = t[i]; b = t[i] + (t[i + 1] - t[i]) / 2; cc = t[i + 1]; }
                /* blossom f(a, b, cc) of the span containing b: span i (b in [t_i, t_{i+1}]) */
                int k = i < m ? i : m - 1;
                double d[4][3];
                for (int q = 0; q < 4; q++) memcpy(d[q], c.Q + (size_t)(k - 1 + q + 2) * 3, sizeof(double) * 3);
                double args[3] = {a, b, cc};
                for (int r = 1; r <= 3; r++)
                    for (int q = 3; q >= r; q--) {
                        double lo = t[k - 3 + q], hi = t[k + 1 + q - r];
                        double al = (args[r - 1] - lo) / (hi - lo);
                        for (int z = 0; z < 3; z++) d[q][z] = (1 - al) * d[q - 1][z] + al * d[q][z];
                    }
                memcpy(P2 + 3 * (size_t)(2 * i + e), d[3], sizeof(double) * 3);
            }
        }
        for (int i = 0; i < m; i++) D2[2 * i] = D2[2 * i + 1] = D[i] / 2;
        oc_free(&c);
        free(P); free(D);
        P = P2; D = D2; m = m2;
    }
    free(D);
    *nout = periodic ? m : m + 1;
    return P;
}

/* ==== library side ====================================================================== */

typedef struct {
    int M, N, torus;        /* M x N quads; torus: periodic both ways */
    double *P;              /* vertices (i, j): open (M+1)(N+1), torus M N */
    double *du, *dv;        /* ring intervals along i (M) and j (N) */
    int nv, nf, ne;
    int32_t *fs, *fv, *ev;
    double *kn, *cr;        /* per listed edge */
} grid;

static int gv(const grid *g, int i, int j) {
    if (g->torus) return ((i % g->M + g->M) % g->M) * g->N + ((j % g->N + g->N) % g->N);
    return i * (g->N + 1) + j;
}

/* crease_i: the grid line i = crease_i carries sharpness s (edges along j). */
static grid grid_make(int M, int N, int torus, int crease_i, double s) {
    grid g;
    memset(&g, 0, sizeof g);
    g.M = M; g.N = N; g.torus = torus;
    int ni = torus ? M : M + 1, nj = torus ? N : N + 1;
    g.nv = ni * nj;
    g.nf = M * N;
    g.P = NEW(double, 3 * g.nv);
    g.du = NEW(double, M);
    g.dv = NEW(double, N);
    for (int i = 0; i < M; i++) g.du[i] = 0.05 + 19.95 * tl_rand01();
    for (int j = 0; j < N; j++) g.dv[j] = 0.05 + 19.95 * tl_rand01();
    for (int i = 0; i < ni; i++)
        for (int j = 0; j < nj; j++) {
            double *p = g.P + 3 * gv(&g, i, j);
            if (torus) {
                double a = 2 * 3.141592653589793 * i / M, b = 2 * 3.141592653589793 * j / N;
                double r = 3 + (1 + 0.2 * tl_rand01()) * cos(b);
                p[0] = r * cos(a); p[1] = r * sin(a); p[2] = (1 + 0.2 * tl_rand01()) * sin(b);
            } else {
                p[0] = i + 0.3 * (tl_rand01() - 0.5);
                p[1] = j + 0.3 * (tl_rand01() - 0.5);
                p[2] = 0.6 * sin(0.9 * i) * cos(0.7 * j) + 0.4 * tl_rand01();
            }
        }
    g.fs = NEW(int32_t, g.nf);
    g.fv = NEW(int32_t, 4 * g.nf);
    for (int i = 0, f = 0; i < M; i++)
        for (int j = 0; j < N; j++, f++) {
            g.fs[f] = 4;
            g.fv[4 * f] = gv(&g, i, j); g.fv[4 * f + 1] = gv(&g, i + 1, j);
            g.fv[4 * f + 2] = gv(&g, i + 1, j + 1); g.fv[4 * f + 3] = gv(&g, i, j + 1);
        }
    /* every edge listed: knots, and the crease line */
    int maxe = 2 * (M + 1) * (N + 1);
    g.ev = NEW(int32_t, 2 * maxe);
    g.kn = NEW(double, maxe);
    g.cr = NEW(double, maxe);
    for (int i = 0; i < ni; i++)
        for (int j = 0; j < nj; j++) {
            if (torus || i < M) { /* (i,j)-(i+1,j) */
                g.ev[2 * g.ne] = gv(&g, i, j); g.ev[2 * g.ne + 1] = gv(&g, i + 1, j);
                g.kn[g.ne] = g.du[i % M]; g.cr[g.ne] = 0; g.ne++;
            }
            if (torus || j < N) { /* (i,j)-(i,j+1) */
                g.ev[2 * g.ne] = gv(&g, i, j); g.ev[2 * g.ne + 1] = gv(&g, i, j + 1);
                g.kn[g.ne] = g.dv[j % N]; g.cr[g.ne] = i == crease_i ? s : 0; g.ne++;
            }
        }
    return g;
}

static void grid_free(grid *g) {
    free(g->P); free(g->du); free(g->dv); free(g->fs); free(g->fv); free(g->ev); free(g->kn); free(g->cr);
}

static ccn_cage grid_cage(const grid *g) {
    ccn_cage c = {g->nv, g->nf, g->ne, g->P, g->fs, g->fv, g->ev, g->kn, g->cr, NULL};
    return c;
}

typedef struct { int32_t nv, nf; double *pos, *nrm, *cn; int32_t *fv, *eo; ccn_sizes s; ccn_plan_stats st; } lmesh;

static int limit(const ccn_cage *c, const ccn_options *o, lmesh *lm) {
    ccn_plan *p = NULL;
    ccn_error err;
    memset(lm, 0, sizeof *lm);
    if (ccn_plan_create(c, o, &p, &err)) { fprintf(stderr, "plan: %s\n", err.message); return -1; }
    ccn_plan_get_sizes(p, &lm->s);
    ccn_plan_get_stats(p, &lm->st);
    lm->nv = lm->s.num_verts; lm->nf = lm->s.num_faces;
    lm->pos = NEW(double, 3 * lm->nv);
    lm->nrm = NEW(double, 3 * lm->nv);
    lm->cn = NEW(double, 12 * lm->nf);
    lm->fv = NEW(int32_t, 4 * lm->nf);
    lm->eo = NEW(int32_t, 4 * lm->nf);
    ccn_limit_mesh out = {.positions = lm->pos, .normals = lm->nrm, .face_verts = lm->fv, .corner_normals = lm->cn,
                          .corner_edge_origin = lm->eo};
    int rc = ccn_plan_evaluate(p, NULL, &out, &err) ? -1 : 0;
    if (rc) fprintf(stderr, "evaluate: %s\n", err.message);
    ccn_plan_destroy(p);
    return rc;
}
static void lm_free(lmesh *l) { free(l->pos); free(l->nrm); free(l->cn); free(l->fv); free(l->eo); }

static double bbox(const double *p, int n) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) { lo[k] = fmin(lo[k], p[3 * i + k]); hi[k] = fmax(hi[k], p[3 * i + k]); }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}
static double dist(const double *a, const double *b) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
static void unit(double *n) {
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0) for (int k = 0; k < 3; k++) n[k] /= l;
}
static double angle(const double *a, const double *b) {
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    double s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return atan2(s, d);
}

/* ==== 1. the two sides of a crease =========================================================== */

typedef struct { double X[3], n[3]; int side, row; } opoint; /* row: refined u index */

/* Oracle points of one side: rows r0..r0+rows of the grid (wrapping on the torus). */
static void side_points(const grid *g, int r0, int rows, int L, int side, opoint *out, int *nout) {
    int nj = g->torus ? g->N : g->N + 1;
    double *G = NEW(double, 3 * (size_t)(rows + 1) * nj), *DU = NEW(double, rows);
    for (int i = 0; i <= rows; i++)
        for (int j = 0; j < nj; j++)
            memcpy(G + 3 * ((size_t)i * nj + j), g->P + 3 * gv(g, r0 + i, j), sizeof(double) * 3);
    for (int i = 0; i < rows; i++) DU[i] = g->du[(r0 + i) % g->M];
    osurf s = {rows, g->N, 0, g->torus, G, DU, g->dv};
    int S = 1 << L;
    for (int ku = 0; ku < rows; ku++)
        for (int a = 0; a <= S; a++) {
            if (a == S && ku + 1 < rows) continue; /* the next span's a = 0 */
            for (int kv = 0; kv < g->N; kv++)
                for (int b = 0; b <= S; b++) {
                    if (b == S && (g->torus || kv + 1 < g->N)) continue;
                    opoint *o = &out[(*nout)++];
                    double Su[3], Sv[3];
                    os_eval(&s, ku, (double)a / S, kv, (double)b / S, o->X, Su, Sv);
                    o->row = ku * S + a;
                    o->n[0] = Su[1] * Sv[2] - Su[2] * Sv[1];
                    o->n[1] = Su[2] * Sv[0] - Su[0] * Sv[2];
                    o->n[2] = Su[0] * Sv[1] - Su[1] * Sv[0];
                    unit(o->n);
                    o->side = side;
                }
        }
    free(G); free(DU);
}

static void check_two_sides(int M, int N, int torus, int c, int L, ccn_scheme scheme) {
    grid g = grid_make(M, N, torus, c, 10.0);
    ccn_cage cage = grid_cage(&g);
    ccn_options o = {scheme, CCN_CAP_REFINE, L, CCN_CORNERS_PINNED, 1, CCN_CREASE_UNIFORM, CCN_POLY_SELECT, NULL, NULL};
    lmesh lm;
    int ok = limit(&cage, &o, &lm) == 0;
    CHECK(ok, "plan");
    if (!ok) { grid_free(&g); return; }
    opoint *orc = NEW(opoint, 2 * (size_t)lm.nv + 64);
    int no = 0;
    if (torus) side_points(&g, c, M, L, 0, orc, &no);
    else { side_points(&g, 0, c, L, 0, orc, &no); side_points(&g, c, M - c, L, 1, orc, &no); }
    double size = bbox(lm.pos, lm.nv), worst = 0, worst_n = 0;
    int *mt = NEW(int, 2 * lm.nv), unmatched = 0; /* up to two oracle points per vertex */
    for (int v = 0; v < lm.nv; v++) {
        mt[2 * v] = mt[2 * v + 1] = -1;
        double best = 1e300;
        for (int k = 0; k < no; k++) {
            double d = dist(lm.pos + 3 * v, orc[k].X);
            if (d < best) best = d;
            if (d <= 1e-9 * size) mt[2 * v + (mt[2 * v] >= 0)] = k;
        }
        if (best > worst) worst = best;
        if (mt[2 * v] < 0) unmatched++;
    }
    CHECK(worst <= TOL_POS * size && unmatched == 0, "%s %dx%d crease %d L%d: position error %.3g of %.3g, %d unmatched",
          torus ? "torus" : "grid", M, N, c, L, worst, size, unmatched);
    /* corner normals: a vertex on the crease matches two oracle points (one per side, or
     * both ends of the torus' cylinder); the face's corner takes the one whose side and row
     * are those of the face's other vertices */
    for (int f = 0; f < lm.nf; f++) {
        double rowsum = 0;
        int cnt = 0, side = 0;
        for (int k = 0; k < 4; k++) {
            int v = lm.fv[4 * f + k];
            if (mt[2 * v] >= 0 && mt[2 * v + 1] < 0) { rowsum += orc[mt[2 * v]].row; cnt++; side = orc[mt[2 * v]].side; }
        }
        double rowmean = cnt ? rowsum / cnt : 0;
        for (int k = 0; k < 4; k++) {
            int v = lm.fv[4 * f + k], m = mt[2 * v];
            if (m < 0) continue;
            if (mt[2 * v + 1] >= 0) {
                int m2 = mt[2 * v + 1];
                double c1 = (orc[m].side != side) * 1e9 + fabs(orc[m].row - rowmean);
                double c2 = (orc[m2].side != side) * 1e9 + fabs(orc[m2].row - rowmean);
                if (c2 < c1) m = m2;
            }
            double a = angle(lm.cn + 12 * f + 3 * k, orc[m].n);
            if (a > worst_n) worst_n = a;
        }
    }
    CHECK(worst_n <= TOL_ANGLE, "%s crease corner normals: worst angle %.3g rad", torus ? "torus" : "grid", worst_n);
    CHECK(lm.st.num_sharp_corners > 0, "crease vertices with two normals: %d", lm.st.num_sharp_corners);
    /* corner_edge_origin: the output edges on the crease line are exactly the corners whose
     * cage corner starts a crease edge (2 faces x N 2^L edges, one loop on the torus too) */
    int on_crease = 0, bad_origin = 0;
    for (int f = 0; f < lm.nf; f++)
        for (int k = 0; k < 4; k++) {
            int j = lm.eo[4 * f + k], a = lm.fv[4 * f + k], b = lm.fv[4 * f + (k + 1) % 4];
            int both = mt[2 * a + 1] >= 0 && mt[2 * b + 1] >= 0; /* both vertices on the crease */
            if (j >= 0) {
                int va = g.fv[j], vb = g.fv[(j % 4 == 3) ? j - 3 : j + 1];
                int ia = torus ? va / g.N : va / (g.N + 1), ib = torus ? vb / g.N : vb / (g.N + 1);
                if (ia == c && ib == c) on_crease++;
                else if (both) bad_origin++;
            } else if (both) bad_origin++;
        }
    CHECK(on_crease == 2 * (g.N << L) && bad_origin == 0, "edge origins: %d corners on the crease (expected %d), %d wrong",
          on_crease, 2 * (g.N << L), bad_origin);
    printf("#   %s %dx%d crease at %d, level %d, %s: positions %.2e of size, corner normals %.2e rad, %d two-sided vertices\n",
           torus ? "torus" : "grid ", M, N, c, L, scheme == CCN_SCHEME_EIGEN ? "eigen" : "nurss", worst / size, worst_n,
           lm.st.num_sharp_corners);
    free(orc); free(mt);
    lm_free(&lm);
    grid_free(&g);
}

static void test_crease_two_sides(void) {
    for (int rep = 0; rep < 3; rep++) {
        check_two_sides(7, 6, 0, 3, 2, CCN_SCHEME_EIGEN);
        check_two_sides(6, 5, 0, 2, 3, CCN_SCHEME_NURSS);
        check_two_sides(8, 7, 1, 3, 2, CCN_SCHEME_EIGEN);
    }
}

/* ==== 2. the refined crease polygon ========================================================== */

static void check_crease_curve(int torus, int L) {
    int M = 6, N = torus ? 7 : 6, c = 3;
    grid g = grid_make(M, N, torus, c, 10.0);
    ccn_cage cage = grid_cage(&g);
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    ccn_options o = {CCN_SCHEME_EIGEN, CCN_CAP_REFINE, L, CCN_CORNERS_PINNED, 1, CCN_CREASE_UNIFORM, CCN_POLY_SELECT, NULL, NULL};
    CHECK(ccn_mesh_create(&cage, &m, &err) == CCN_OK, "mesh: %s", err.message);
    CHECK(m && ccn_refine(m, L, &o, &r, &err) == CCN_OK, "refine: %s", err.message);
    if (!r) { ccn_mesh_destroy(m); grid_free(&g); return; }
    int nj = torus ? N : N + 1, n = 0;
    double *Q = NEW(double, 3 * nj);
    for (int j = 0; j < nj; j++) memcpy(Q + 3 * j, g.P + 3 * gv(&g, c, j), sizeof(double) * 3);
    double *B = oc_boehm(Q, N, g.dv, torus, L, &n);
    ccn_mesh_info in;
    ccn_mesh_get_info(r, &in);
    double *pos = NEW(double, 3 * in.num_verts), *es = NEW(double, in.num_edges);
    int32_t *ev = NEW(int32_t, 2 * in.num_edges);
    ccn_mesh_copy(r, pos, NULL, NULL, ev, NULL);
    ccn_mesh_get_creases(r, es, NULL);
    /* every vertex of a sharp refined edge is a point of the refined crease polygon */
    double size = bbox(pos, in.num_verts), worst = 0;
    int nsharp = 0;
    for (int e = 0; e < in.num_edges; e++) {
        if (es[e] < 10) continue;
        nsharp++;
        for (int k = 0; k < 2; k++) {
            double best = 1e300;
            for (int q = 0; q < n; q++) best = fmin(best, dist(pos + 3 * ev[2 * e + k], B + 3 * q));
            worst = fmax(worst, best);
        }
    }
    CHECK(nsharp == (N << L), "%d sharp refined edges, expected %d", nsharp, N << L);
    CHECK(worst <= TOL_POS * size, "%s crease polygon at level %d: %.3g of %.3g", torus ? "closed" : "open", L, worst, size);
    printf("#   %s crease polygon, level %d: Boehm insertion %.2e of size\n", torus ? "closed" : "open  ", L, worst / size);
    free(Q); free(B); free(pos); free(es); free(ev);
    ccn_mesh_destroy(m); ccn_mesh_destroy(r);
    grid_free(&g);
}

static void test_crease_curve_boehm(void) {
    for (int L = 1; L <= 3; L++) { check_crease_curve(0, L); check_crease_curve(1, L); }
}

/* ==== 3. semi-sharp ========================================================================== */

typedef struct { int nv, nf, ne, nfv; double *pos, *kn, *es; int32_t *fs, *fv, *ev; } mdata;

static mdata mesh_data(const ccn_mesh *m) {
    mdata d;
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    d.nv = in.num_verts; d.nf = in.num_faces; d.ne = in.num_edges; d.nfv = in.num_face_verts;
    d.pos = NEW(double, 3 * d.nv); d.kn = NEW(double, d.ne); d.es = NEW(double, d.ne);
    d.fs = NEW(int32_t, d.nf); d.fv = NEW(int32_t, d.nfv); d.ev = NEW(int32_t, 2 * d.ne);
    ccn_mesh_copy(m, d.pos, d.fs, d.fv, d.ev, d.kn);
    ccn_mesh_get_creases(m, d.es, NULL);
    return d;
}
static void md_free(mdata *d) { free(d->pos); free(d->kn); free(d->es); free(d->fs); free(d->fv); free(d->ev); }

static ccn_mesh *refine_grid(const grid *g, double s, int levels, int method) {
    grid h = *g;
    double *cr = NEW(double, g->ne);
    for (int e = 0; e < g->ne; e++) cr[e] = g->cr[e] > 0 ? s : 0;
    h.cr = cr;
    ccn_cage c = grid_cage(&h);
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    ccn_options o = {CCN_SCHEME_EIGEN, CCN_CAP_REFINE, levels, CCN_CORNERS_PINNED, 1, method, CCN_POLY_SELECT, NULL, NULL};
    if (ccn_mesh_create(&c, &m, &err) == CCN_OK) ccn_refine(m, levels, &o, &r, &err);
    ccn_mesh_destroy(m);
    free(cr);
    return r;
}

/* refine `levels` more levels of mesh d with every crease replaced by sharpness s */
static ccn_mesh *refine_data(const mdata *d, double s, int levels) {
    double *cr = NEW(double, d->ne);
    for (int e = 0; e < d->ne; e++) cr[e] = d->es[e] > 0 ? s : 0;
    ccn_cage c = {d->nv, d->nf, d->ne, d->pos, d->fs, d->fv, d->ev, d->kn, cr, NULL};
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    ccn_options o = {CCN_SCHEME_EIGEN, CCN_CAP_REFINE, levels, CCN_CORNERS_PINNED, 1, CCN_CREASE_UNIFORM, CCN_POLY_SELECT, NULL, NULL};
    if (ccn_mesh_create(&c, &m, &err) == CCN_OK) ccn_refine(m, levels, &o, &r, &err);
    else fprintf(stderr, "refine_data: %s\n", err.message);
    ccn_mesh_destroy(m);
    free(cr);
    return r;
}

/* Largest distance from a point of one set to the other set, both ways: the nearest point is
 * found exactly by a sweep over the other set sorted by x, stopped once |dx| exceeds the best. */
static const double *sd_keys;
static int sd_cmp(const void *a, const void *b) {
    double x = sd_keys[3 * *(const int *)a], y = sd_keys[3 * *(const int *)b];
    return (x > y) - (x < y);
}
static double set_diff(const double *A, int na, const double *B, int nb) {
    double w = na == nb ? 0 : 1e300;
    for (int pass = 0; pass < 2; pass++) {
        const double *X = pass ? B : A, *Y = pass ? A : B;
        int nx = pass ? nb : na, ny = pass ? na : nb;
        int *ord = NEW(int, ny > 0 ? ny : 1);
        for (int j = 0; j < ny; j++) ord[j] = j;
        sd_keys = Y;
        qsort(ord, (size_t)ny, sizeof *ord, sd_cmp);
        for (int i = 0; i < nx; i++) {
            const double *p = X + 3 * i;
            int lo = 0, hi = ny; /* first index whose x >= p's x */
            while (lo < hi) { int m = (lo + hi) / 2; if (Y[3 * ord[m]] < p[0]) lo = m + 1; else hi = m; }
            double best = 1e300;
            for (int j = lo; j < ny && Y[3 * ord[j]] - p[0] <= best; j++) best = fmin(best, dist(p, Y + 3 * ord[j]));
            for (int j = lo - 1; j >= 0 && p[0] - Y[3 * ord[j]] <= best; j--) best = fmin(best, dist(p, Y + 3 * ord[j]));
            w = fmax(w, best);
        }
        free(ord);
    }
    return w;
}

/* Same vertex numbering (both refined from the same cage): index by index; else as sets. */
static double max_diff(const ccn_mesh *a, const ccn_mesh *b, int same_numbering, double *size) {
    mdata x = mesh_data(a), y = mesh_data(b);
    double w = x.nv == y.nv ? 0 : 1e300;
    if (same_numbering)
        for (int i = 0; x.nv == y.nv && i < x.nv; i++) w = fmax(w, dist(x.pos + 3 * i, y.pos + 3 * i));
    else
        w = set_diff(x.pos, x.nv, y.pos, y.nv);
    *size = bbox(x.pos, x.nv);
    md_free(&x); md_free(&y);
    return w;
}

static void test_semisharp_levels(void) {
    for (int rep = 0; rep < 3; rep++)
        for (int k = 1; k <= 3; k++) {
            grid g = grid_make(6, 5, rep == 1, 3, 10.0);
            double size = 1.0;
            ccn_mesh *a = refine_grid(&g, k, k, CCN_CREASE_UNIFORM), *b = refine_grid(&g, 10, k, CCN_CREASE_UNIFORM);
            double e1 = a && b ? max_diff(a, b, 1, &size) : 1e300;
            CHECK(e1 <= 1e-15 * size, "s = %d: %d levels differ from the sharp crease by %.3g", k, k, e1);
            /* then smooth: two more levels = two smooth levels of the sharp level-k mesh */
            ccn_mesh *c = refine_grid(&g, k, k + 2, CCN_CREASE_UNIFORM);
            mdata bd = mesh_data(b);
            ccn_mesh *d = refine_data(&bd, 0, 2);
            double e2 = c && d ? max_diff(c, d, 0, &size) : 1e300;
            CHECK(e2 <= 1e-14 * size, "s = %d: levels %d..%d differ from smooth refinement by %.3g", k, k + 1, k + 2, e2);
            /* fractional s = k + 1/2: level k + 1 = mean of crease and smooth on the crease */
            ccn_mesh *f = refine_grid(&g, k + 0.5, k + 1, CCN_CREASE_UNIFORM);
            ccn_mesh *fs = refine_data(&bd, 10, 1), *fw = refine_data(&bd, 0, 1);
            mdata F = mesh_data(f), S = mesh_data(fs), W = mesh_data(fw);
            double *want = NEW(double, 3 * S.nv);
            char *on = calloc((size_t)S.nv, 1); /* on the refined crease: an endpoint of a sharp edge of fs */
            for (int e = 0; e < S.ne; e++)
                if (S.es[e] > 0) on[S.ev[2 * e]] = on[S.ev[2 * e + 1]] = 1;
            for (int v = 0; v < S.nv; v++) /* fs and fw share their numbering */
                for (int q = 0; q < 3; q++)
                    want[3 * v + q] = on[v] ? 0.5 * (S.pos[3 * v + q] + W.pos[3 * v + q]) : W.pos[3 * v + q];
            double e3 = set_diff(F.pos, F.nv, want, S.nv);
            free(want); free(on);
            CHECK(e3 <= 1e-14 * bbox(F.pos, F.nv), "s = %d.5: level %d is not the blend (%.3g)", k, k + 1, e3);
            md_free(&F); md_free(&S); md_free(&W); md_free(&bd);
            ccn_mesh_destroy(a); ccn_mesh_destroy(b); ccn_mesh_destroy(c); ccn_mesh_destroy(d);
            ccn_mesh_destroy(f); ccn_mesh_destroy(fs); ccn_mesh_destroy(fw);
            grid_free(&g);
        }
}

/* ==== 4. random sharpness ==================================================================== */

static void test_random_sharpness(void) {
    double worst = 0;
    for (int rep = 0; rep < 8; rep++) {
        grid g = grid_make(6, 7, 1, 0, 0.0);
        double *vc = NEW(double, g.nv);
        for (int e = 0; e < g.ne; e++) g.cr[e] = tl_rand01() < 0.3 ? 12 * tl_rand01() : 0;
        for (int v = 0; v < g.nv; v++) vc[v] = tl_rand01() < 0.1 ? 12 * tl_rand01() : 0;
        ccn_cage c = grid_cage(&g);
        c.vertex_creases = vc;
        for (int method = 0; method < 2; method++)
            for (int L = 1; L <= 2; L++) {
                ccn_options o = {rep & 1 ? CCN_SCHEME_NURSS : CCN_SCHEME_EIGEN, CCN_CAP_REFINE, L,
                                 CCN_CORNERS_SMOOTH, 1, method, CCN_POLY_SELECT, NULL, NULL};
                lmesh a, b;
                o.levels = L;
                int ok = limit(&c, &o, &a) == 0;
                o.levels = L + 1;
                ok = ok && limit(&c, &o, &b) == 0;
                CHECK(ok, "plan rep %d L%d", rep, L);
                if (!ok) continue;
                int finite = 1, unitn = 1;
                for (int i = 0; i < 3 * a.nv; i++) finite &= isfinite(a.pos[i]) && isfinite(a.nrm[i]);
                for (int i = 0; i < 12 * a.nf; i += 3) unitn &= fabs(sqrt(a.cn[i] * a.cn[i] + a.cn[i + 1] * a.cn[i + 1] + a.cn[i + 2] * a.cn[i + 2]) - 1) < 1e-12;
                CHECK(finite && unitn, "finite %d, unit corner normals %d", finite, unitn);
                double size = bbox(b.pos, b.nv), e = 0;
                for (int v = 0; v < a.nv; v++) { /* level L's vertices are level L+1's */
                    double best = 1e300;
                    for (int w = 0; w < b.nv; w++) best = fmin(best, dist(a.pos + 3 * v, b.pos + 3 * w));
                    e = fmax(e, best);
                }
                worst = fmax(worst, e / size);
                CHECK(e <= TOL_POS * size, "rep %d method %d L%d: a level-L limit point is %.3g from level L+1's", rep, method, L, e);
                lm_free(&a); lm_free(&b);
            }
        free(vc);
        grid_free(&g);
    }
    printf("#   random sharpness in [0,12]: level-L limit points on level L+1's within %.2e of size\n", worst);
}

/* ==== 5. extraordinary vertices on and next to creases ====================================== */

#include "test_creases_ev.h"

int main(void) {
    RUN(test_crease_two_sides);
    RUN(test_crease_curve_boehm);
    RUN(test_semisharp_levels);
    RUN(test_random_sharpness);
    RUN(test_crease_evs);
    return TEST_SUMMARY();
}
