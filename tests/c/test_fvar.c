/* Face-varying channels (UV maps) and per-vertex data, against an oracle written
 * here from first principles (tests/c/bspline_oracle.h: cubic B-splines on explicit knots,
 * de Boor evaluation, point reflection at the ends); no code or formula is shared with csrc/.
 *
 *  1. Open grids and tori with random ring intervals in [0.05, 20] and a UV map without
 *     seams: every limit UV (each output face corner's value) is the tensor-product B-spline of
 *     the UV values at the corner's parameter (point-reflected at the grid's boundary: pinned
 *     corners), <= 1e-12 of the UV box, for every mode that keeps UVs smooth there (grid: NONE
 *     with pinned geometric corners, CORNERS_ONLY / PLUS1 / PLUS2; torus: all but ALL), schemes
 *     eigen and nurss; CORNERS_ONLY pins the UV corners also where the geometry's are smooth.
 *     The parameter of an output vertex is found from its position (the positions' oracle).
 *  2. A seam across the grid (and around the torus): the faces on each side use their own
 *     values on the seam line; each side's limit UVs are the tensor B-spline of that side's
 *     values alone, point-reflected at the seam as at a boundary (the modes' smooth boundary
 *     rule; on the grid the seam's ends are UV corners, pinned by CORNERS_*; the torus' closed
 *     seam has no ends, so NONE too), with the seam edges' intervals; BOUNDARIES: on the seam and
 *     the boundary the limit is the piecewise-linear interpolation of the side's values; ALL:
 *     bilinear interpolation of each face's corner values everywhere.
 *  3. The plan: new values need no rebuild (an affine map of the values maps the result),
 *     several channels and widths, per-vertex data interpolated like the positions (the limit
 *     of the positions themselves is the limit surface) without disturbing the plan's geometry,
 *     ccn_fvar_refine, the OBJ reader's UV map, and every refusal naming its element.
 *  4. A UV map equal to the positions (one value per vertex, mode NONE: no seam, nothing
 *     sharpened) refines and has its limit exactly as the positions do, here for each fixed
 *     eigen polyhedron (ccn_options.ev_polyhedron) on a cage with non-uniform intervals at its
 *     extraordinary vertices, where the polyhedron changes the surface.
 */
#include "ccnurbs.h"
#include "testlib.h"

#include <stdint.h>

#include "bspline_oracle.h"

#define TOL 1e-12

/* ==== oracle: a tensor-product B-spline of dim-valued control points ==================== */

typedef struct { int nu, nv, pu, pv, dim; const double *G; const double *DU, *DV; } vsurf;

/* Value at grid parameter (span ku, fraction fu; span kv, fraction fv). */
static void vs_eval(const vsurf *s, int ku, double fu, int kv, double fv, double *X) {
    int nrow = s->pu ? s->nu : s->nu + 1, ncol = s->pv ? s->nv : s->nv + 1, d = s->dim;
    double *C = NEW(double, (size_t)nrow * d), *der = NEW(double, d);
    for (int i = 0; i < nrow; i++) {
        ocurve cv = oc_make(s->G + (size_t)i * ncol * d, s->nv, d, s->DV, s->pv);
        double x = cv.t[2 + kv] + fv * (cv.t[2 + kv + 1] - cv.t[2 + kv]);
        oc_eval(&cv, x, kv, C + (size_t)i * d, der);
        oc_free(&cv);
    }
    ocurve cu = oc_make(C, s->nu, d, s->DU, s->pu);
    double x = cu.t[2 + ku] + fu * (cu.t[2 + ku + 1] - cu.t[2 + ku]);
    oc_eval(&cu, x, ku, X, der);
    oc_free(&cu);
    free(C);
    free(der);
}

/* ==== the cage: an M x N grid or torus with a UV map ===================================== */

typedef struct {
    int M, N, torus, seam;    /* seam: row of vertices i = seam carries two sets of values, -1 none */
    int W;                    /* channel width */
    double *P, *du, *dv;
    int nv, nf, ne;
    int32_t *fs, *fv, *ev;
    double *kn;
    double *val;              /* values: base (one per vertex), then the seam copies */
    int nval;
    int32_t *idx;             /* per face corner */
} grid;

static int gv(const grid *g, int i, int j) {
    if (g->torus) return ((i % g->M + g->M) % g->M) * g->N + ((j % g->N + g->N) % g->N);
    return i * (g->N + 1) + j;
}
static int ni(const grid *g) { return g->torus ? g->M : g->M + 1; }
static int nj(const grid *g) { return g->torus ? g->N : g->N + 1; }
/* Is face row fi the one that uses the seam copies at the seam row? (the side before it) */
static int uses_copy(const grid *g, int fi) {
    return g->seam >= 0 && (g->torus ? fi == (g->seam - 1 + g->M) % g->M : fi < g->seam);
}
static int value_index(const grid *g, int i, int j, int fi) {
    int ii = g->torus ? ((i % g->M) + g->M) % g->M : i;
    if (g->seam >= 0 && ii == g->seam && uses_copy(g, fi)) return g->nv + ((j % nj(g)) + nj(g)) % nj(g);
    return gv(g, i, j);
}

static grid grid_make(int M, int N, int torus, int seam, int W) {
    grid g;
    memset(&g, 0, sizeof g);
    g.M = M; g.N = N; g.torus = torus; g.seam = seam; g.W = W;
    g.nv = ni(&g) * nj(&g);
    g.nf = M * N;
    g.P = NEW(double, 3 * g.nv);
    g.du = NEW(double, M);
    g.dv = NEW(double, N);
    for (int i = 0; i < M; i++) g.du[i] = 0.05 + 19.95 * tl_rand01();
    for (int j = 0; j < N; j++) g.dv[j] = 0.05 + 19.95 * tl_rand01();
    for (int i = 0; i < ni(&g); i++)
        for (int j = 0; j < nj(&g); j++) {
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
    g.idx = NEW(int32_t, 4 * g.nf);
    for (int i = 0, f = 0; i < M; i++)
        for (int j = 0; j < N; j++, f++) {
            int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
            g.fs[f] = 4;
            for (int k = 0; k < 4; k++) {
                g.fv[4 * f + k] = gv(&g, ci[k], cj[k]);
                g.idx[4 * f + k] = value_index(&g, ci[k], cj[k], i);
            }
        }
    g.ev = NEW(int32_t, 4 * (size_t)(M + 1) * (N + 1));
    g.kn = NEW(double, 2 * (size_t)(M + 1) * (N + 1));
    for (int i = 0; i < ni(&g); i++)
        for (int j = 0; j < nj(&g); j++) {
            if (torus || i < M) {
                g.ev[2 * g.ne] = gv(&g, i, j); g.ev[2 * g.ne + 1] = gv(&g, i + 1, j);
                g.kn[g.ne++] = g.du[i % M];
            }
            if (torus || j < N) {
                g.ev[2 * g.ne] = gv(&g, i, j); g.ev[2 * g.ne + 1] = gv(&g, i, j + 1);
                g.kn[g.ne++] = g.dv[j % N];
            }
        }
    g.nval = g.nv + (seam >= 0 ? nj(&g) : 0);
    g.val = NEW(double, (size_t)W * g.nval);
    for (int k = 0; k < W * g.nval; k++) g.val[k] = tl_rand01();
    return g;
}
static void grid_free(grid *g) {
    free(g->P); free(g->du); free(g->dv); free(g->fs); free(g->fv); free(g->ev); free(g->kn);
    free(g->val); free(g->idx);
}
static ccn_cage grid_cage(const grid *g) {
    ccn_cage c = {g->nv, g->nf, g->ne, g->P, g->fs, g->fv, g->ev, g->kn, NULL, NULL};
    return c;
}
static ccn_fvar_channel grid_channel(const grid *g, int linear) {
    ccn_fvar_channel ch = {g->W, g->nval, g->val, g->idx, linear};
    return ch;
}

/* ==== the library's limit UVs per face corner, with each corner's parameter ============= */

typedef struct {
    int nf, W;
    double *uv;      /* W per face corner */
    int *row, *col;  /* refined parameter index (units of 1/2^L of a cage span) per corner */
    int *frow, *fcol; /* cage face row and column of each output face */
    double pos_err;  /* positions vs the positions' oracle, relative */
} result;

static void result_free(result *r) { free(r->uv); free(r->row); free(r->col); free(r->frow); free(r->fcol); }

static double dist3(const double *a, const double *b) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static int run(const grid *g, int linear, ccn_scheme scheme, int L, int corners, result *r) {
    ccn_cage cage = grid_cage(g);
    ccn_options o = {.scheme = scheme, .cap = CCN_CAP_REFINE, .levels = L, .boundary_corners = corners,
                     .threads = 1, .crease_method = CCN_CREASE_UNIFORM};
    ccn_fvar_channel ch = grid_channel(g, linear);
    ccn_plan *p = NULL;
    ccn_error err;
    int32_t c = -1;
    memset(r, 0, sizeof *r);
    if (ccn_plan_create(&cage, &o, &p, &err) || ccn_plan_add_fvar(p, &ch, &c, &err)) {
        fprintf(stderr, "plan: %s\n", err.message);
        ccn_plan_destroy(p);
        return -1;
    }
    ccn_sizes s;
    ccn_fvar_sizes fs;
    ccn_plan_get_sizes(p, &s);
    ccn_plan_get_fvar_sizes(p, c, &fs);
    double *pos = NEW(double, 3 * s.num_verts), *vals = NEW(double, (size_t)g->W * fs.num_values);
    int32_t *fv = NEW(int32_t, 4 * s.num_faces), *fo = NEW(int32_t, s.num_faces), *fvv = NEW(int32_t, 4 * s.num_faces);
    ccn_limit_mesh lm = {.positions = pos, .face_verts = fv, .face_origin = fo};
    int rc = ccn_plan_evaluate(p, NULL, &lm, &err) || ccn_plan_evaluate_fvar(p, c, NULL, vals, fvv, &err) ? -1 : 0;
    if (rc) fprintf(stderr, "evaluate: %s\n", err.message);
    /* the positions' oracle (pinned corners): every refined parameter's point */
    int S = 1 << L, R = g->M * S + (g->torus ? 0 : 1), C = g->N * S + (g->torus ? 0 : 1);
    double *G = NEW(double, 3 * (size_t)ni(g) * nj(g)), *X = NEW(double, 3 * (size_t)R * C);
    for (int i = 0; i < ni(g); i++)
        for (int j = 0; j < nj(g); j++) memcpy(G + 3 * ((size_t)i * nj(g) + j), g->P + 3 * gv(g, i, j), sizeof(double) * 3);
    vsurf ps = {g->M, g->N, g->torus, g->torus, 3, G, g->du, g->dv};
    for (int a = 0; a < R; a++)
        for (int b = 0; b < C; b++) {
            int ku = a / S < g->M ? a / S : g->M - 1, kv = b / S < g->N ? b / S : g->N - 1;
            vs_eval(&ps, ku, (double)(a - ku * S) / S, kv, (double)(b - kv * S) / S, X + 3 * ((size_t)a * C + b));
        }
    int *vrow = NEW(int, s.num_verts), *vcol = NEW(int, s.num_verts);
    double worst = 0, size = 0;
    for (int k = 0; k < R * C; k++) size = fmax(size, dist3(X + 3 * k, X));
    for (int v = 0; v < s.num_verts; v++) {
        double best = 1e300;
        for (int k = 0; k < R * C; k++) {
            double d = dist3(pos + 3 * v, X + 3 * k);
            if (d < best) { best = d; vrow[v] = k / C; vcol[v] = k % C; }
        }
        worst = fmax(worst, best);
    }
    r->pos_err = worst / size;
    r->nf = s.num_faces;
    r->W = g->W;
    r->uv = NEW(double, (size_t)g->W * 4 * s.num_faces);
    r->row = NEW(int, 4 * s.num_faces);
    r->col = NEW(int, 4 * s.num_faces);
    r->frow = NEW(int, s.num_faces);
    r->fcol = NEW(int, s.num_faces);
    for (int f = 0; f < s.num_faces; f++) {
        r->frow[f] = fo[f] / g->N;
        r->fcol[f] = fo[f] % g->N;
        for (int k = 0; k < 4; k++) {
            int q = 4 * f + k;
            memcpy(r->uv + (size_t)g->W * q, vals + (size_t)g->W * fvv[q], sizeof(double) * g->W);
            r->row[q] = vrow[fv[q]];
            r->col[q] = vcol[fv[q]];
        }
    }
    free(pos); free(vals); free(fv); free(fo); free(fvv); free(G); free(X); free(vrow); free(vcol);
    ccn_plan_destroy(p);
    return rc;
}

static double uv_box(const grid *g) {
    double d = 0;
    for (int k = 0; k < g->W; k++) {
        double lo = 1e300, hi = -1e300;
        for (int v = 0; v < g->nval; v++) { lo = fmin(lo, g->val[(size_t)g->W * v + k]); hi = fmax(hi, g->val[(size_t)g->W * v + k]); }
        d += (hi - lo) * (hi - lo);
    }
    return sqrt(d);
}

/* The side of face row fi and the rows of its control grid: side 0 starts at row 0 (grid) or
 * at the seam (torus, one side); side 1 (grid) at the seam. */
static void side_of(const grid *g, int fi, int *r0, int *rows) {
    if (g->seam < 0) { *r0 = 0; *rows = g->M; return; }
    if (g->torus) { *r0 = g->seam; *rows = g->M; return; }
    if (fi < g->seam) { *r0 = 0; *rows = g->seam; }
    else { *r0 = g->seam; *rows = g->M - g->seam; }
}

/* The oracle value of a face corner: its side's tensor B-spline at its parameter. */
static void oracle_uv(const grid *g, int L, int frow, int row, int col, double *out) {
    int S = 1 << L, r0, rows;
    side_of(g, frow, &r0, &rows);
    int rel = row - r0 * S, nc = nj(g);
    if (g->torus) {
        rel = ((rel % (g->M * S)) + g->M * S) % (g->M * S);
        if (rel == 0 && g->seam >= 0 && frow == (g->seam - 1 + g->M) % g->M) rel = g->M * S;
    }
    int nr = rows + 1 - (g->torus && g->seam < 0); /* a torus without seam wraps in u */
    double *G = NEW(double, (size_t)g->W * nr * nc);
    for (int i = 0; i < nr; i++)
        for (int j = 0; j < nc; j++) {
            int ii = r0 + i, fi = i < rows ? (r0 + i) % g->M : (r0 + i - 1) % g->M; /* a face row using row ii */
            int vi = value_index(g, ii, j, fi);
            memcpy(G + (size_t)g->W * (i * nc + j), g->val + (size_t)g->W * vi, sizeof(double) * g->W);
        }
    double *DU = NEW(double, rows);
    for (int i = 0; i < rows; i++) DU[i] = g->du[(r0 + i) % g->M];
    vsurf s = {rows, g->N, g->torus && g->seam < 0, g->torus, g->W, G, DU, g->dv};
    int ku = rel / S < rows ? rel / S : rows - 1;
    int cc = g->torus ? ((col % (g->N * S)) + g->N * S) % (g->N * S) : col;
    int kv = cc / S < g->N ? cc / S : g->N - 1;
    vs_eval(&s, ku, (double)(rel - ku * S) / S, kv, (double)(cc - kv * S) / S, out);
    free(G);
    free(DU);
}

static double compare_bspline(const grid *g, int L, const result *r) {
    double worst = 0, *want = NEW(double, g->W);
    for (int q = 0; q < 4 * r->nf; q++) {
        oracle_uv(g, L, r->frow[q / 4], r->row[q], r->col[q], want);
        for (int k = 0; k < g->W; k++) worst = fmax(worst, fabs(want[k] - r->uv[(size_t)g->W * q + k]));
    }
    free(want);
    return worst / uv_box(g);
}

/* ==== 1 and 2: B-spline sides ============================================================== */

static const char *MODE[6] = {"none", "corners-only", "corners-plus1", "corners-plus2", "boundaries", "all"};

static void check_bspline(int M, int N, int torus, int seam, int W, int mode, ccn_scheme sc, int L) {
    grid g = grid_make(M, N, torus, seam, W);
    result r;
    int ok = run(&g, mode, sc, L, CCN_CORNERS_PINNED, &r) == 0;
    CHECK(ok, "plan");
    if (ok) {
        double e = compare_bspline(&g, L, &r);
        CHECK(r.pos_err <= TOL, "positions: %.3g", r.pos_err);
        CHECK(e <= TOL, "%s %dx%d seam %d %s L%d: limit UVs differ from the tensor B-spline by %.3g of the UV box",
              torus ? "torus" : "grid", M, N, seam, MODE[mode], L, e);
        printf("#   %-5s %dx%d %s, width %d, %-13s %-5s L%d: limit values vs tensor B-spline %.2e\n", torus ? "torus" : "grid", M, N,
               seam < 0 ? "no seam " : "seam    ", W, MODE[mode], sc == CCN_SCHEME_EIGEN ? "eigen" : "nurss", L, e);
        result_free(&r);
    }
    grid_free(&g);
}

static void test_uv_bspline_no_seam(void) {
    for (int m = CCN_FVAR_LINEAR_NONE; m <= CCN_FVAR_LINEAR_CORNERS_PLUS2; m++) check_bspline(7, 6, 0, -1, 2, m, m % 2 ? CCN_SCHEME_NURSS : CCN_SCHEME_EIGEN, 2);
    for (int m = CCN_FVAR_LINEAR_NONE; m <= CCN_FVAR_LINEAR_BOUNDARIES; m++) check_bspline(8, 7, 1, -1, 4, m, CCN_SCHEME_EIGEN, 2);
    check_bspline(6, 5, 0, -1, 2, CCN_FVAR_LINEAR_CORNERS_ONLY, CCN_SCHEME_EIGEN, 3);
}

static void test_uv_bspline_seam(void) {
    for (int m = CCN_FVAR_LINEAR_CORNERS_ONLY; m <= CCN_FVAR_LINEAR_CORNERS_PLUS2; m++) check_bspline(7, 6, 0, 3, 2, m, CCN_SCHEME_EIGEN, 2);
    check_bspline(6, 6, 0, 2, 3, CCN_FVAR_LINEAR_CORNERS_ONLY, CCN_SCHEME_NURSS, 3);
    for (int m = CCN_FVAR_LINEAR_NONE; m <= CCN_FVAR_LINEAR_CORNERS_PLUS2; m++) check_bspline(8, 7, 1, 3, 2, m, CCN_SCHEME_EIGEN, 2);
}

/* Geometry with smooth corners: CORNERS_ONLY still pins the UV corners (the same UVs as with
 * pinned geometric corners), NONE smooths them (different UVs at the corners only). */
static void test_uv_corners_follow_mode(void) {
    grid g = grid_make(6, 5, 0, -1, 2);
    ccn_cage cage = grid_cage(&g);
    double *uv[4];
    int nf = 0;
    for (int t = 0; t < 4; t++) {
        ccn_options o = {.scheme = CCN_SCHEME_EIGEN, .cap = CCN_CAP_REFINE, .levels = 2,
                         .boundary_corners = t % 2 ? CCN_CORNERS_SMOOTH : CCN_CORNERS_PINNED, .threads = 1};
        ccn_fvar_channel ch = grid_channel(&g, t < 2 ? CCN_FVAR_LINEAR_CORNERS_ONLY : CCN_FVAR_LINEAR_NONE);
        ccn_plan *p = NULL;
        ccn_error err;
        int32_t c = -1;
        CHECK(ccn_plan_create(&cage, &o, &p, &err) == CCN_OK && ccn_plan_add_fvar(p, &ch, &c, &err) == CCN_OK, "%s", err.message);
        ccn_sizes s;
        ccn_fvar_sizes fs;
        ccn_plan_get_sizes(p, &s);
        ccn_plan_get_fvar_sizes(p, c, &fs);
        double *vals = NEW(double, 2 * fs.num_values);
        int32_t *fvv = NEW(int32_t, 4 * s.num_faces);
        CHECK(ccn_plan_evaluate_fvar(p, c, NULL, vals, fvv, &err) == CCN_OK, "%s", err.message);
        nf = s.num_faces;
        uv[t] = NEW(double, 8 * nf);
        for (int q = 0; q < 4 * nf; q++) memcpy(uv[t] + 2 * q, vals + 2 * fvv[q], sizeof(double) * 2);
        free(vals); free(fvv);
        ccn_plan_destroy(p);
    }
    double same = 0, differ = 0;
    for (int q = 0; q < 8 * nf; q++) { same = fmax(same, fabs(uv[0][q] - uv[1][q])); differ = fmax(differ, fabs(uv[2][q] - uv[3][q])); }
    CHECK(same == 0.0, "CORNERS_ONLY: UVs depend on the geometry's corner rule (%.3g)", same);
    CHECK(differ > 1e-3, "NONE: UV corners do not follow the geometry's corner rule (%.3g)", differ);
    for (int t = 0; t < 4; t++) free(uv[t]);
    grid_free(&g);
}

/* BOUNDARIES: on the seam and the grid's boundary, the piecewise-linear interpolation of the
 * side's values; ALL: every face bilinear. */
static void test_uv_linear_modes(void) {
    for (int mode = CCN_FVAR_LINEAR_BOUNDARIES; mode <= CCN_FVAR_LINEAR_ALL; mode++) {
        grid g = grid_make(6, 5, 0, 3, 2);
        int L = 2, S = 1 << L, checked = 0;
        result r;
        CHECK(run(&g, mode, CCN_SCHEME_EIGEN, L, CCN_CORNERS_PINNED, &r) == 0, "plan"); /* pinned: parameters from positions */
        double worst = 0;
        for (int q = 0; q < 4 * r.nf; q++) {
            int f = q / 4, fi = r.frow[f], fj = r.fcol[f], row = r.row[q], col = r.col[q];
            int on_row = row % S == 0 && (row == 0 || row == g.M * S || row == g.seam * S);
            int on_col = col == 0 || col == g.N * S;
            if (mode == CCN_FVAR_LINEAR_BOUNDARIES && !on_row && !on_col) continue;
            /* bilinear over the cage face (fi, fj) the corner's output face lies on */
            double a = (double)(row - fi * S) / S, b = (double)(col - fj * S) / S;
            int v00 = value_index(&g, fi, fj, fi), v10 = value_index(&g, fi + 1, fj, fi);
            int v11 = value_index(&g, fi + 1, fj + 1, fi), v01 = value_index(&g, fi, fj + 1, fi);
            for (int k = 0; k < 2; k++) {
                double want = (1 - a) * (1 - b) * g.val[2 * v00 + k] + a * (1 - b) * g.val[2 * v10 + k] +
                              a * b * g.val[2 * v11 + k] + (1 - a) * b * g.val[2 * v01 + k];
                worst = fmax(worst, fabs(want - r.uv[2 * q + k]));
            }
            checked++;
        }
        worst /= uv_box(&g);
        CHECK(checked > 0 && worst <= TOL, "%s: %d corners, linear interpolation off by %.3g", MODE[mode], checked, worst);
        printf("#   grid 6x5 seam, %-10s L%d: %d corners %s, linear interpolation %.2e\n", MODE[mode], L, checked,
               mode == CCN_FVAR_LINEAR_ALL ? "(all)" : "on seam and boundary", worst);
        result_free(&r);
        grid_free(&g);
    }
}

/* ==== 3. the plan ========================================================================= */

static void test_plan_reuse_and_vertex_data(void) {
    grid g = grid_make(6, 6, 1, 2, 5);
    ccn_cage cage = grid_cage(&g);
    ccn_options o = {.scheme = CCN_SCHEME_EIGEN, .cap = CCN_CAP_REFINE, .levels = 2,
                     .boundary_corners = CCN_CORNERS_SMOOTH, .threads = 2};
    ccn_plan *p = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&cage, &o, &p, &err) == CCN_OK, "%s", err.message);
    if (!p) { grid_free(&g); return; }
    int32_t c0, c1;
    ccn_fvar_channel ch = grid_channel(&g, CCN_FVAR_LINEAR_CORNERS_ONLY);
    CHECK(ccn_plan_add_fvar(p, &ch, &c0, &err) == CCN_OK && c0 == 0, "%s", err.message);
    ch.linear = CCN_FVAR_LINEAR_ALL;
    CHECK(ccn_plan_add_fvar(p, &ch, &c1, &err) == CCN_OK && c1 == 1, "%s", err.message);
    ccn_sizes s;
    ccn_fvar_sizes fs;
    ccn_plan_get_sizes(p, &s);
    ccn_plan_get_fvar_sizes(p, c0, &fs);
    CHECK(fs.width == 5 && fs.num_cage_values == g.nval && fs.num_seam_edges == g.N, "sizes: width %d, %d cage values, %d seams",
          (int)fs.width, (int)fs.num_cage_values, (int)fs.num_seam_edges);
    size_t nout = (size_t)5 * fs.num_values;
    double *a = NEW(double, nout), *b = NEW(double, nout), *vals = NEW(double, 5 * (size_t)g.nval);
    CHECK(ccn_plan_evaluate_fvar(p, c0, NULL, a, NULL, &err) == CCN_OK, "%s", err.message);
    for (int k = 0; k < 5 * g.nval; k++) vals[k] = 3.0 * g.val[k] - 1.0 + k % 5; /* affine, per component */
    CHECK(ccn_plan_evaluate_fvar(p, c0, vals, b, NULL, &err) == CCN_OK, "%s", err.message);
    double e = 0;
    for (size_t k = 0; k < nout; k++) e = fmax(e, fabs(b[k] - (3.0 * a[k] - 1.0 + (double)(k % 5))));
    CHECK(e <= 1e-13, "new values without a rebuild: the affine map of the values misses by %.3g", e);
    CHECK(ccn_plan_evaluate_fvar(p, c0, NULL, b, NULL, &err) == CCN_OK && !memcmp(a, b, sizeof(double) * nout),
          "NULL values: not the values given");
    ccn_fvar_sizes fs1;
    ccn_plan_get_fvar_sizes(p, c1, &fs1);
    double *lin = NEW(double, 5 * (size_t)fs1.num_values);
    CHECK(ccn_plan_evaluate_fvar(p, c1, vals, lin, NULL, &err) == CCN_OK, "bilinear channel: %s", err.message);
    free(lin);
    printf("#   plan reuse: affine map of new values %.2e\n", e);
    /* per-vertex data: the positions themselves give the limit surface; data with 5
     * components (an affine map of x, y, z) gives the map of it; the plan's geometry stays */
    double *pos = NEW(double, 3 * s.num_verts), *pos2 = NEW(double, 3 * s.num_verts), *vd = NEW(double, 5 * s.num_verts);
    ccn_limit_mesh lm = {.positions = pos};
    CHECK(ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK, "%s", err.message);
    double *data = NEW(double, 5 * g.nv);
    for (int v = 0; v < g.nv; v++) {
        const double *x = g.P + 3 * v;
        double d[5] = {x[0], x[1], x[2], x[0] - 2 * x[1] + 0.5, 1e3 * x[2] - 7};
        memcpy(data + 5 * v, d, sizeof d);
    }
    CHECK(ccn_plan_evaluate_vertex_data(p, 5, data, vd, &err) == CCN_OK, "%s", err.message);
    double ev = 0;
    for (int v = 0; v < s.num_verts; v++) {
        const double *x = pos + 3 * v, *d = vd + 5 * v;
        double want[5] = {x[0], x[1], x[2], x[0] - 2 * x[1] + 0.5, 1e3 * x[2] - 7};
        for (int k = 0; k < 5; k++) ev = fmax(ev, fabs(d[k] - want[k]) / (k == 4 ? 1e3 : 1.0));
    }
    CHECK(ev <= 1e-13 * 4, "vertex data: %.3g from the positions' limit", ev);
    /* the plan's geometry is untouched: patches unchanged */
    ccn_limit_mesh lm2 = {.positions = pos2};
    CHECK(ccn_plan_evaluate_vertex_data(p, 1, data, vd, &err) == CCN_OK, "%s", err.message);
    CHECK(ccn_plan_evaluate(p, NULL, &lm2, &err) == CCN_OK && !memcmp(pos, pos2, sizeof(double) * 3 * s.num_verts),
          "positions changed after vertex data");
    printf("#   vertex data (5 components, affine in the positions): %.2e\n", ev);
    /* refusals name the element */
    double nanv = g.val[7];
    g.val[7] = NAN;
    ch.linear = CCN_FVAR_LINEAR_NONE;
    CHECK(ccn_plan_add_fvar(p, &ch, &c1, &err) == CCN_ERR_ARGUMENT && err.element_kind == CCN_ELEM_VALUE && err.element == 1 &&
          strstr(err.message, "value 1"), "NaN value: %s", err.message);
    g.val[7] = nanv;
    for (int k = 0; k < 5 * g.nval; k++) vals[k] = g.val[k];
    vals[5 * 3 + 2] = INFINITY;
    CHECK(ccn_plan_evaluate_fvar(p, c0, vals, b, NULL, &err) == CCN_ERR_ARGUMENT && err.element_kind == CCN_ELEM_VALUE &&
          err.element == 3, "Inf value at evaluate: %s", err.message);
    int32_t keep = g.idx[4 * 2 + 1];
    g.idx[4 * 2 + 1] = g.nval + 5;
    CHECK(ccn_plan_add_fvar(p, &ch, &c1, &err) == CCN_ERR_ARGUMENT && err.element_kind == CCN_ELEM_FACE && err.element == 2 &&
          strstr(err.message, "face 2 corner 1"), "bad index: %s", err.message);
    g.idx[4 * 2 + 1] = keep;
    ch.width = 0;
    CHECK(ccn_plan_add_fvar(p, &ch, &c1, &err) == CCN_ERR_ARGUMENT && strstr(err.message, "width"), "width 0: %s", err.message);
    ch.width = 5;
    ch.linear = 9;
    CHECK(ccn_plan_add_fvar(p, &ch, &c1, &err) == CCN_ERR_ARGUMENT && strstr(err.message, "mode 9"), "mode 9: %s", err.message);
    CHECK(ccn_plan_evaluate_fvar(p, 7, NULL, b, NULL, &err) == CCN_ERR_ARGUMENT && strstr(err.message, "channel 7"),
          "channel 7: %s", err.message);
    CHECK(ccn_plan_evaluate_vertex_data(p, 0, data, vd, &err) == CCN_ERR_ARGUMENT, "width 0 vertex data accepted");
    data[5 * 4 + 1] = NAN;
    CHECK(ccn_plan_evaluate_vertex_data(p, 5, data, vd, &err) == CCN_ERR_ARGUMENT && err.element_kind == CCN_ELEM_VALUE &&
          err.element == 4, "NaN vertex data: %s", err.message);
    free(a); free(b); free(vals); free(pos); free(pos2); free(vd); free(data);
    ccn_plan_destroy(p);
    grid_free(&g);
}

/* ccn_fvar_refine with ALL is bilinear refinement: face points the mean of the face's values,
 * edge points the mean of the edge's two; the OBJ reader's UV map and its refusals. */
static void test_refine_and_obj(void) {
    const char *text =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.2 0.1\nvt 0.7 0.4\nvt 0.6 0.9\nvt 0.1 0.8\n"
        "f 1/1 2/2 3/3 4/4\nf 2/5 5/6 6/7 3/8\nt facevaryinginterpolateboundary 1/0/0 5\n";
    ccn_obj *obj = NULL;
    ccn_error err;
    CHECK(ccn_obj_parse(text, strlen(text), &obj, &err) == CCN_OK, "%s", err.message);
    if (!obj) return;
    ccn_cage cage;
    ccn_fvar_channel ch;
    ccn_obj_get_cage(obj, &cage);
    ccn_obj_get_fvar(obj, &ch);
    CHECK(ch.width == 2 && ch.num_values == 8 && ch.linear == CCN_FVAR_LINEAR_ALL && ch.indices[5] == 5,
          "UV map: width %d, %d values, mode %d", (int)ch.width, (int)ch.num_values, (int)ch.linear);
    ccn_mesh *m = NULL;
    ccn_fvar *fv = NULL;
    ccn_options o = {.scheme = CCN_SCHEME_EIGEN, .cap = CCN_CAP_REFINE, .levels = 1, .threads = 1};
    CHECK(ccn_mesh_create(&cage, &m, &err) == CCN_OK && ccn_fvar_refine(m, &ch, 1, &o, &fv, &err) == CCN_OK, "%s", err.message);
    if (fv) {
        ccn_fvar_info in;
        ccn_fvar_get_info(fv, &in);
        CHECK(in.num_face_verts == 32 && in.num_seam_edges == 1 && in.level == 1, "info: %d corners, %d seams",
              (int)in.num_face_verts, (int)in.num_seam_edges);
        double *v = NEW(double, 2 * in.num_values);
        int32_t *fi = NEW(int32_t, in.num_face_verts);
        ccn_fvar_copy(fv, v, fi);
        /* sub-quad 0 of face 1: (V = vt 5, E, F = centre, E) */
        const double *cen = v + 2 * fi[4 * 4 + 2], *e0 = v + 2 * fi[4 * 4 + 1];
        CHECK(fabs(cen[0] - 0.4) < 1e-15 && fabs(cen[1] - 0.55) < 1e-15, "face point %g %g", cen[0], cen[1]);
        CHECK(fabs(e0[0] - 0.45) < 1e-15 && fabs(e0[1] - 0.25) < 1e-15, "edge point %g %g", e0[0], e0[1]);
        free(v); free(fi);
    }
    ccn_fvar_destroy(fv);
    ccn_mesh_destroy(m);
    ccn_obj_destroy(obj);
    /* a partial map is ignored with a warning; an index beyond the vt lines names its line */
    const char *partial = "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3\n";
    CHECK(ccn_obj_parse(partial, strlen(partial), &obj, &err) == CCN_OK, "%s", err.message);
    ccn_obj_get_fvar(obj, &ch);
    CHECK(ch.num_values == 0 && ccn_obj_get_num_warnings(obj) == 1 && strstr(ccn_obj_get_warning(obj, 0), "UV map ignored"),
          "partial UV map: %d values, %d warnings", (int)ch.num_values, (int)ccn_obj_get_num_warnings(obj));
    ccn_obj_destroy(obj);
    const char *beyond = "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/4\n";
    CHECK(ccn_obj_parse(beyond, strlen(beyond), &obj, &err) == CCN_ERR_IO && err.element_kind == CCN_ELEM_LINE &&
          err.element == 5 && strstr(err.message, "texture index 4"), "beyond: %s", err.message);
    const char *badvt = "v 0 0 0\nvt x 0\n";
    CHECK(ccn_obj_parse(badvt, strlen(badvt), &obj, &err) == CCN_ERR_IO && err.element == 2, "bad vt: %s", err.message);
}

/* ==== 4. a UV map that is the positions follows the positions' rules ====================== */

static void test_uv_follows_polyhedron(void) {
    size_t len = 0;
    char *t = tl_slurp("tests/data/fig17_v7.obj", &len);
    CHECK(t != NULL, "tests/data/fig17_v7.obj");
    if (!t) return;
    ccn_obj *obj = NULL;
    ccn_error err;
    CHECK(ccn_obj_parse(t, len, &obj, &err) == CCN_OK, "%s", err.message);
    free(t);
    if (!obj) return;
    ccn_cage cage;
    ccn_obj_get_cage(obj, &cage);
    ccn_fvar_channel ch = {.width = 3, .num_values = cage.num_verts, .values = cage.positions,
                           .indices = cage.face_verts, .linear = CCN_FVAR_LINEAR_NONE};
    ccn_mesh *m = NULL;
    CHECK(ccn_mesh_create(&cage, &m, &err) == CCN_OK, "%s", err.message);
    for (int32_t poly = CCN_POLY_SELECT; m && poly <= 3; poly++) {
        ccn_options o = {.scheme = CCN_SCHEME_EIGEN, .cap = CCN_CAP_REFINE, .levels = 2, .threads = 1,
                         .ev_polyhedron = poly};
        /* refined: each face corner's value is its vertex's refined position */
        ccn_mesh *r = NULL;
        ccn_fvar *fv = NULL;
        double rerr = INFINITY, lerr = INFINITY;
        if (ccn_refine(m, 2, &o, &r, &err) == CCN_OK && ccn_fvar_refine(m, &ch, 2, &o, &fv, &err) == CCN_OK) {
            ccn_mesh_info mi;
            ccn_fvar_info fi;
            ccn_mesh_get_info(r, &mi);
            ccn_fvar_get_info(fv, &fi);
            double *P = NEW(double, 3 * mi.num_verts), *V = NEW(double, 3 * fi.num_values);
            int32_t *pf = NEW(int32_t, mi.num_face_verts), *vf = NEW(int32_t, fi.num_face_verts);
            ccn_mesh_copy(r, P, NULL, pf, NULL, NULL);
            ccn_fvar_copy(fv, V, vf);
            rerr = fi.num_face_verts == mi.num_face_verts ? 0.0 : INFINITY;
            for (int32_t q = 0; q < mi.num_face_verts && rerr == 0.0; q++)
                for (int k = 0; k < 3; k++) rerr = fmax(rerr, fabs(P[3 * pf[q] + k] - V[3 * vf[q] + k]));
            free(P); free(V); free(pf); free(vf);
        }
        ccn_fvar_destroy(fv);
        ccn_mesh_destroy(r);
        /* limit: each output face corner's value is its vertex's limit position */
        ccn_plan *p = NULL;
        int32_t idx = -1;
        if (ccn_plan_create(&cage, &o, &p, &err) == CCN_OK && ccn_plan_add_fvar(p, &ch, &idx, &err) == CCN_OK) {
            ccn_sizes sz;
            ccn_fvar_sizes fs;
            ccn_plan_get_sizes(p, &sz);
            ccn_plan_get_fvar_sizes(p, idx, &fs);
            double *X = NEW(double, 3 * sz.num_verts), *U = NEW(double, 3 * fs.num_values);
            int32_t *q4 = NEW(int32_t, 4 * sz.num_faces), *u4 = NEW(int32_t, 4 * sz.num_faces);
            ccn_limit_mesh lm = {.positions = X, .face_verts = q4};
            if (ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK &&
                ccn_plan_evaluate_fvar(p, idx, NULL, U, u4, &err) == CCN_OK) {
                lerr = 0.0;
                for (int32_t q = 0; q < 4 * sz.num_faces; q++)
                    for (int k = 0; k < 3; k++) lerr = fmax(lerr, fabs(X[3 * q4[q] + k] - U[3 * u4[q] + k]));
            }
            free(X); free(U); free(q4); free(u4);
        }
        ccn_plan_destroy(p);
        CHECK(rerr <= TOL && lerr <= TOL, "polyhedron %d: UVs = positions off by %.3g refined, %.3g limit (%s)",
              (int)poly, rerr, lerr, err.message);
        printf("#   fig17_v7 L2 ev_polyhedron %d: UV map = positions, refined %.2e, limit %.2e\n", (int)poly, rerr, lerr);
    }
    ccn_mesh_destroy(m);
    ccn_obj_destroy(obj);
}

/* A channel evaluated through its levels (tests/data/fvar_cylinder64.obj: a 64-gon cap disk
 * needs more probe colours than surface/fvar_compose.c composes): new values without a new
 * plan, in every mode and width 1-5, equal a new plan's (bitwise), the evaluation is linear
 * (a blend of two value sets gives the blend of the outputs, 1e-13), repeatable, and a plan
 * and a width the levels evaluate in several passes (width 5: 3 + 2 components) agree with
 * their components evaluated one by one. OpenSubdiv checks the values themselves
 * (tests/oracle/run_fvar_shapes.sh). */
static void test_levels_channel(void) {
    size_t len = 0;
    char *t = tl_slurp("tests/data/fvar_cylinder64.obj", &len);
    ccn_obj *obj = NULL;
    ccn_error err;
    if (!t || ccn_obj_parse(t, len, &obj, &err)) { CHECK(0, "load fvar_cylinder64.obj"); free(t); return; }
    free(t);
    ccn_cage cage;
    ccn_fvar_channel uv;
    ccn_obj_get_cage(obj, &cage);
    ccn_obj_get_fvar(obj, &uv);
    int nv = uv.num_values;
    for (int mode = 0; mode < 6; mode++)
        for (int W = 1; W <= 5; W += 2) {
            double *A = malloc(sizeof(double) * W * nv), *B = malloc(sizeof(double) * W * nv), *C = malloc(sizeof(double) * W * nv);
            for (int i = 0; i < W * nv; i++) { A[i] = tl_rand01(); B[i] = 3 * tl_rand01() - 1; C[i] = 0.25 * A[i] + 0.75 * B[i]; }
            ccn_fvar_channel ch = {W, nv, A, uv.indices, mode}, chB = ch;
            chB.values = B;
            ccn_options o = {0};
            o.levels = 2;
            ccn_plan *p = NULL, *q = NULL;
            int32_t c = -1, cq = -1;
            if (ccn_plan_create(&cage, &o, &p, &err) || ccn_plan_add_fvar(p, &ch, &c, &err) ||
                ccn_plan_create(&cage, &o, &q, &err) || ccn_plan_add_fvar(q, &chB, &cq, &err)) {
                CHECK(0, "mode %d width %d: %s", mode, W, err.message);
            } else {
                ccn_fvar_sizes fs;
                ccn_plan_get_fvar_sizes(p, c, &fs);
                size_t n = (size_t)W * fs.num_values;
                double *a = malloc(sizeof(double) * n), *b = malloc(sizeof(double) * n), *bq = malloc(sizeof(double) * n);
                double *cc = malloc(sizeof(double) * n), *a2 = malloc(sizeof(double) * n);
                ccn_plan_evaluate_fvar(p, c, NULL, a, NULL, &err);
                ccn_plan_evaluate_fvar(p, c, B, b, NULL, &err);
                ccn_plan_evaluate_fvar(q, cq, NULL, bq, NULL, &err);
                ccn_plan_evaluate_fvar(p, c, C, cc, NULL, &err);
                ccn_plan_evaluate_fvar(p, c, A, a2, NULL, &err);
                double lin = 0;
                for (size_t i = 0; i < n; i++) lin = fmax(lin, fabs(cc[i] - (0.25 * a[i] + 0.75 * b[i])));
                CHECK(memcmp(b, bq, sizeof(double) * n) == 0, "mode %d width %d: new values != a new plan's", mode, W);
                CHECK(memcmp(a, a2, sizeof(double) * n) == 0, "mode %d width %d: not repeatable", mode, W);
                CHECK(lin <= 1e-13, "mode %d width %d: not linear (%.3g)", mode, W, lin);
                int finite = 1;
                for (size_t i = 0; i < n; i++) finite &= isfinite(a[i]);
                CHECK(finite, "mode %d width %d: non-finite output", mode, W);
                if (W == 5) { /* component 4 (the second pass) alone, as a width-1 channel */
                    double *A4 = malloc(sizeof(double) * nv), *o4 = malloc(sizeof(double) * fs.num_values);
                    for (int i = 0; i < nv; i++) A4[i] = A[5 * i + 4];
                    ccn_fvar_channel c1 = {1, nv, A4, uv.indices, mode};
                    int32_t k = -1;
                    double e = 1e300;
                    if (!ccn_plan_add_fvar(q, &c1, &k, &err) && !ccn_plan_evaluate_fvar(q, k, NULL, o4, NULL, &err)) {
                        e = 0;
                        for (int i = 0; i < fs.num_values; i++) e = fmax(e, fabs(o4[i] - a[5 * (size_t)i + 4]));
                    }
                    CHECK(e <= 1e-14, "mode %d: component 4 of width 5 vs alone %.3g", mode, e);
                    free(A4); free(o4);
                }
                free(a); free(b); free(bq); free(cc); free(a2);
            }
            ccn_plan_destroy(p); ccn_plan_destroy(q);
            free(A); free(B); free(C);
        }
    ccn_obj_destroy(obj);
}

int main(void) {
    RUN(test_uv_bspline_no_seam);
    RUN(test_uv_bspline_seam);
    RUN(test_uv_corners_follow_mode);
    RUN(test_uv_linear_modes);
    RUN(test_plan_reuse_and_vertex_data);
    RUN(test_refine_and_obj);
    RUN(test_uv_follows_polyhedron);
    RUN(test_levels_channel);
    return TEST_SUMMARY();
}
