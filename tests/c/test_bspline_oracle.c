/* Independent knot-insertion oracle for regular regions of the refinement.
 *
 * Everything below the "oracle" banner is written from first principles and shares no
 * code (and no formulas) with the library: a cubic B-spline on an explicit knot vector,
 * Boehm single-knot insertion, de Boor evaluation, periodic / point-reflected extension,
 * and the tensor product (one direction, then the other).  The knot-interval edge/vertex
 * formulas of SPEC 1.1 appear only in the oracle self-test, as a cross-check of the
 * oracle's own index bookkeeping.
 *
 * Library cases (public API only: ccn_mesh_create / ccn_refine / ccn_mesh_copy /
 * ccn_mesh_get_info):
 *   1. torus grids (all valence 4): EIGEN and NURSS after 1-3 levels == periodic tensor
 *      Boehm; refined edge intervals == ring interval / 2^L; refined faces == grid cells.
 *   2. open grids, pinned corners: == tensor Boehm of the doubly point-reflected grid
 *      (SPEC [1d]), compared on the refined points of the original domain.
 *   3. boundary loops: pinned == 1D Boehm of each reflected side (SPEC [1c]); smooth ==
 *      periodic 1D Boehm of the whole boundary polygon (SPEC [1f]).
 *   +  the header's vertex-order contract, level by level (ccn_refine(.., 1) iterated),
 *      which names the failing point (face / edge / vertex point of which element).
 *   4. oracle self-checks (curve and surface preserved under insertion, uniform masks,
 *      SPEC 1.1 formulas, a negative control).
 *
 * Build with -DORACLE_SELFTEST to run only the oracle parts (no library needed).
 */
#ifndef ORACLE_SELFTEST
#include "ccnurbs.h"
#endif
#include "testlib.h"

#include <stdint.h>

#define O_PI 3.14159265358979323846
#define O_EXT 3     /* extension points per side (periodic copies or reflections) */
#define REL_TOL 1e-12

static void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) { fprintf(stderr, "out of memory\n"); exit(2); }
    return p;
}
#define NEW(T, n) ((T *)xmalloc(sizeof(T) * (size_t)(n)))

static int imod(int a, int m) { int r = a % m; return r < 0 ? r + m : r; }
static int iclamp(int a, int lo, int hi) { return a < lo ? lo : a > hi ? hi : a; }
static double rnd_interval(void) { return 0.05 + 19.95 * tl_rand01(); }

/* =====================================================================================
 * oracle: cubic B-spline "curve" whose control points have `dim` doubles each.
 * N control points P_0..P_{N-1}, knots t_0..t_{N+3}; P_i is supported on [t_i, t_{i+4}]
 * (blossom P_i = f(t_{i+1}, t_{i+2}, t_{i+3})), so the control-polygon edge P_i P_{i+1}
 * carries the knot interval t_{i+3} - t_{i+2}.  Domain [t_3, t_N].
 * ===================================================================================*/
typedef struct { int N, dim; double *P, *t; } oc;

static oc oc_alloc(int N, int dim) {
    oc c;
    c.N = N; c.dim = dim;
    c.P = NEW(double, (size_t)N * (size_t)dim);
    c.t = NEW(double, N + 4);
    return c;
}
static void oc_free(oc *c) { free(c->P); free(c->t); c->P = c->t = NULL; }

/* Boehm: insert the knot x (t_3 <= x < t_N) once.  Returns 0 if x is outside. */
static int oc_insert(oc *c, double x) {
    const int N = c->N, d = c->dim;
    int s = -1;
    for (int k = 3; k <= N - 1; k++)
        if (c->t[k] <= x && x < c->t[k + 1]) { s = k; break; }
    if (s < 0) return 0;
    oc q = oc_alloc(N + 1, d);
    for (int i = 0; i <= N; i++) {
        double *Q = q.P + (size_t)i * d;
        if (i <= s - 3) {
            memcpy(Q, c->P + (size_t)i * d, sizeof(double) * (size_t)d);
        } else if (i <= s) {
            const double a = (x - c->t[i]) / (c->t[i + 3] - c->t[i]);
            const double *A = c->P + (size_t)(i - 1) * d, *B = c->P + (size_t)i * d;
            for (int e = 0; e < d; e++) Q[e] = (1.0 - a) * A[e] + a * B[e];
        } else {
            memcpy(Q, c->P + (size_t)(i - 1) * d, sizeof(double) * (size_t)d);
        }
    }
    for (int k = 0; k <= s; k++) q.t[k] = c->t[k];
    q.t[s + 1] = x;
    for (int k = s + 1; k <= N + 3; k++) q.t[k + 1] = c->t[k];
    oc_free(c);
    *c = q;
    return 1;
}

/* Inserts the midpoint of every domain span [t_s, t_{s+1}], s = 3..N-1, highest first
 * so that lower indices stay valid.  Afterwards old knot k >= 3 sits at index 2k-3 and the
 * point with blossom centre t_{a+2} (old P_a, a >= 1) becomes the vertex point Q_{2a-1},
 * followed by the edge point Q_{2a}.  Returns 0 on a zero-length span. */
static int oc_refine(oc *c) {
    for (int s = c->N - 1; s >= 3; s--) {
        if (!(c->t[s] < c->t[s + 1])) return 0;
        if (!oc_insert(c, 0.5 * (c->t[s] + c->t[s + 1]))) return 0;
    }
    return 1;
}

/* de Boor evaluation at x in [t_3, t_N]. */
static void oc_eval(const oc *c, double x, double *out) {
    const int d = c->dim;
    int s = 3;
    while (s < c->N - 1 && c->t[s + 1] <= x) s++;
    double *D = NEW(double, 4 * (size_t)d);
    for (int j = 0; j < 4; j++) memcpy(D + (size_t)j * d, c->P + (size_t)(s - 3 + j) * d, sizeof(double) * (size_t)d);
    for (int r = 1; r <= 3; r++)
        for (int j = 3; j >= r; j--) {
            const int i = s - 3 + j;
            const double a = (x - c->t[i]) / (c->t[i + 4 - r] - c->t[i]);
            for (int e = 0; e < d; e++) D[(size_t)j * d + e] = (1.0 - a) * D[(size_t)(j - 1) * d + e] + a * D[(size_t)j * d + e];
        }
    memcpy(out, D + 3 * (size_t)d, sizeof(double) * (size_t)d);
    free(D);
}

/* Periodic extension: m points (dim d), D[i] = interval between P_i and P_{i+1 mod m}.
 * Local point a is P_{(a-R) mod m}; the original P_0 is local point R. */
static oc oc_ext_periodic(const double *P, int m, const double *D, int d, int R) {
    oc c = oc_alloc(m + 2 * R, d);
    for (int a = 0; a < c.N; a++) memcpy(c.P + (size_t)a * d, P + (size_t)imod(a - R, m) * d, sizeof(double) * (size_t)d);
    /* t_{k+1} - t_k is the interval between local points k-2 and k-1 */
    c.t[0] = 0.0;
    for (int k = 0; k <= c.N + 2; k++) c.t[k + 1] = c.t[k] + D[imod(k - 2 - R, m)];
    return c;
}

/* Point-reflected extension of an open polygon of m+1 points and m intervals:
 * P_{-r} = 2 P_0 - P_r, d_{-r} = d_{r-1} (same at the other end).  Needs R <= m.
 * Intervals further out (only in the outermost knots) are clamped; they influence only
 * refined points far outside the original domain. */
static double refl_interval(const double *D, int m, int r) {
    int idx = r < 0 ? -r - 1 : (r >= m ? 2 * m - r - 1 : r);
    return D[iclamp(idx, 0, m - 1)];
}
static oc oc_ext_reflect(const double *P, int m, const double *D, int d, int R) {
    oc c = oc_alloc(m + 1 + 2 * R, d);
    for (int a = 0; a < c.N; a++) {
        const int r = a - R;
        double *Q = c.P + (size_t)a * d;
        if (r < 0) {
            for (int e = 0; e < d; e++) Q[e] = 2.0 * P[e] - P[(size_t)(-r) * d + e];
        } else if (r > m) {
            for (int e = 0; e < d; e++) Q[e] = 2.0 * P[(size_t)m * d + e] - P[(size_t)(2 * m - r) * d + e];
        } else {
            memcpy(Q, P + (size_t)r * d, sizeof(double) * (size_t)d);
        }
    }
    c.t[0] = 0.0;
    for (int k = 0; k <= c.N + 2; k++) c.t[k + 1] = c.t[k] + refl_interval(D, m, k - 2 - R);
    return c;
}

static oc oc_ext(const double *P, int m, const double *D, int d, int periodic) {
    return periodic ? oc_ext_periodic(P, m, D, d, O_EXT) : oc_ext_reflect(P, m, D, d, O_EXT);
}

/* A[(i*nv + j)*k + c] -> B[(j*nu + i)*k + c] */
static double *transpose(const double *A, int nu, int nv, int k) {
    double *B = NEW(double, (size_t)nu * nv * k);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++)
            memcpy(B + ((size_t)j * nu + i) * k, A + ((size_t)i * nv + j) * k, sizeof(double) * (size_t)k);
    return B;
}

/* 1D oracle: L levels of midpoint insertion on a closed (periodic: m points, m intervals)
 * or open (m+1 points, m intervals, reflected ends) polygon of 3D points.  Output: the
 * refined points of the original range, 2^L m (+1 if open); fine_d (may be NULL) gets the
 * 2^L m refined intervals.  Returns the number of points, 0 on failure. */
static int oracle_curve(const double *P, int m, const double *D, int periodic, int L, double **out, double *fine_d) {
    oc c = oc_ext(P, m, D, 3, periodic);
    int o = O_EXT;
    for (int l = 0; l < L; l++) {
        if (!oc_refine(&c)) { oc_free(&c); return 0; }
        o = 2 * o - 1;
    }
    const int K = (m << L) + (periodic ? 0 : 1);
    *out = NEW(double, 3 * (size_t)K);
    memcpy(*out, c.P + (size_t)o * 3, sizeof(double) * 3 * (size_t)K);
    if (fine_d)
        for (int I = 0; I < (m << L); I++) fine_d[I] = c.t[o + I + 3] - c.t[o + I + 2];
    oc_free(&c);
    return K;
}

/* Tensor oracle: grid of nu x nv points (nu = m or m+1, nv = n or n+1), point (i,j) at
 * Pc[(i*nv + j)*3], intervals Du[m] along i, Dv[n] along j.  Extends (periodically or by
 * point reflection) in i, then in j, refines L levels in j, then L levels in i (insertion in
 * distinct directions commutes), returns the Mf x Nf refined points of the original domain,
 * Mf = 2^L m (+1 if open).  fine_du / fine_dv (may be NULL) get the refined intervals. */
static double *oracle_grid(const double *Pc, int m, int n, const double *Du, const double *Dv, int periodic,
                           int L, int *Mf, int *Nf, double *fine_du, double *fine_dv) {
    const int nv = periodic ? n : n + 1;
    oc cu = oc_ext(Pc, m, Du, 3 * nv, periodic); /* points = rows i, dim 3*nv */
    double *T = transpose(cu.P, cu.N, nv, 3);     /* nv x Nu */
    oc cv = oc_ext(T, n, Dv, 3 * cu.N, periodic); /* points = columns j, dim 3*Nu */
    free(T);
    int ou = O_EXT, ov = O_EXT, ok = 1;
    for (int l = 0; l < L; l++) { ok &= oc_refine(&cv); ov = 2 * ov - 1; }
    free(cu.P);
    cu.P = transpose(cv.P, cv.N, cu.N, 3); /* Nu x Nv' */
    cu.dim = 3 * cv.N;
    for (int l = 0; l < L; l++) { ok &= oc_refine(&cu); ou = 2 * ou - 1; }
    *Mf = (m << L) + (periodic ? 0 : 1);
    *Nf = (n << L) + (periodic ? 0 : 1);
    double *F = NULL;
    if (ok) {
        F = NEW(double, 3 * (size_t)*Mf * *Nf);
        for (int I = 0; I < *Mf; I++)
            memcpy(F + (size_t)I * *Nf * 3, cu.P + ((size_t)(ou + I) * cv.N + ov) * 3, sizeof(double) * 3 * (size_t)*Nf);
        if (fine_du) for (int I = 0; I < (m << L); I++) fine_du[I] = cu.t[ou + I + 3] - cu.t[ou + I + 2];
        if (fine_dv) for (int J = 0; J < (n << L); J++) fine_dv[J] = cv.t[ov + J + 3] - cv.t[ov + J + 2];
    }
    oc_free(&cu);
    oc_free(&cv);
    return F;
}

/* -------------------------------------------------------------------------------------
 * small geometry helpers
 * -----------------------------------------------------------------------------------*/
static double dist3(const double *a, const double *b) {
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

/* Cage test data: an m x n quad grid, periodic in both directions (torus) or open. */
typedef struct {
    int m, n, periodic, nu, nv; /* nu x nv vertices, vertex (i,j) has index i*nv + j */
    int nverts, nfaces, nedges;
    double *pos, *Du, *Dv, *ek;
    int32_t *fs, *fv, *ev;
} gcage;

static int gid(const gcage *g, int i, int j) { return imod(i, g->nu) * g->nv + imod(j, g->nv); }

/* uniform: all intervals 1.  flip: random edge directions in edge_verts. */
static gcage gcage_make(int m, int n, int periodic, int uniform) {
    gcage g;
    memset(&g, 0, sizeof g);
    g.m = m; g.n = n; g.periodic = periodic;
    g.nu = periodic ? m : m + 1;
    g.nv = periodic ? n : n + 1;
    g.nverts = g.nu * g.nv;
    g.nfaces = m * n;
    g.nedges = m * g.nv + g.nu * n;
    g.Du = NEW(double, m);
    g.Dv = NEW(double, n);
    for (int i = 0; i < m; i++) g.Du[i] = uniform ? 1.0 : rnd_interval();
    for (int j = 0; j < n; j++) g.Dv[j] = uniform ? 1.0 : rnd_interval();
    g.pos = NEW(double, 3 * (size_t)g.nverts);
    for (int i = 0; i < g.nu; i++)
        for (int j = 0; j < g.nv; j++) {
            double *p = g.pos + 3 * (size_t)gid(&g, i, j);
            if (periodic) { /* jittered torus */
                const double a = 2.0 * O_PI * (i + 0.35 * (tl_rand01() - 0.5)) / m;
                const double b = 2.0 * O_PI * (j + 0.35 * (tl_rand01() - 0.5)) / n;
                const double R = 3.0, r = 1.0 + 0.3 * (tl_rand01() - 0.5);
                p[0] = (R + r * cos(b)) * cos(a) + 0.2 * (tl_rand01() - 0.5);
                p[1] = (R + r * cos(b)) * sin(a) + 0.2 * (tl_rand01() - 0.5);
                p[2] = r * sin(b) + 0.2 * (tl_rand01() - 0.5);
            } else { /* jittered height field */
                p[0] = i + 0.4 * (tl_rand01() - 0.5);
                p[1] = j + 0.4 * (tl_rand01() - 0.5);
                p[2] = 2.0 * tl_rand01() - 1.0;
            }
        }
    g.fs = NEW(int32_t, g.nfaces);
    g.fv = NEW(int32_t, 4 * (size_t)g.nfaces);
    for (int i = 0, f = 0; i < m; i++)
        for (int j = 0; j < n; j++, f++) {
            g.fs[f] = 4;
            g.fv[4 * f + 0] = gid(&g, i, j);
            g.fv[4 * f + 1] = gid(&g, i + 1, j);
            g.fv[4 * f + 2] = gid(&g, i + 1, j + 1);
            g.fv[4 * f + 3] = gid(&g, i, j + 1);
        }
    g.ev = NEW(int32_t, 2 * (size_t)g.nedges);
    g.ek = NEW(double, g.nedges);
    int e = 0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < g.nv; j++, e++) {
            const int a = gid(&g, i, j), b = gid(&g, i + 1, j), fl = tl_rand01() < 0.5;
            g.ev[2 * e] = fl ? b : a; g.ev[2 * e + 1] = fl ? a : b; g.ek[e] = g.Du[i];
        }
    for (int i = 0; i < g.nu; i++)
        for (int j = 0; j < n; j++, e++) {
            const int a = gid(&g, i, j), b = gid(&g, i, j + 1), fl = tl_rand01() < 0.5;
            g.ev[2 * e] = fl ? b : a; g.ev[2 * e + 1] = fl ? a : b; g.ek[e] = g.Dv[j];
        }
    return g;
}
static void gcage_free(gcage *g) {
    free(g->pos); free(g->Du); free(g->Dv); free(g->ek); free(g->fs); free(g->fv); free(g->ev);
}
static double *gcage_oracle(const gcage *g, int L, int *Mf, int *Nf, double *fdu, double *fdv) {
    return oracle_grid(g->pos, g->m, g->n, g->Du, g->Dv, g->periodic, L, Mf, Nf, fdu, fdv);
}


/* Nearest-neighbour search over oracle points (uniform grid hash). */
typedef struct { const double *P; int n, g; double lo[3], h; int *start, *idx; } nnhash;

static void nn_cell(const nnhash *H, const double *p, int c[3]) {
    for (int k = 0; k < 3; k++) c[k] = iclamp((int)floor((p[k] - H->lo[k]) / H->h), 0, H->g - 1);
}
static void nn_build(nnhash *H, const double *P, int n) {
    double hi[3] = {-INFINITY, -INFINITY, -INFINITY}, ext = 0.0;
    H->P = P; H->n = n;
    for (int k = 0; k < 3; k++) H->lo[k] = INFINITY;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (P[3 * i + k] < H->lo[k]) H->lo[k] = P[3 * i + k];
            if (P[3 * i + k] > hi[k]) hi[k] = P[3 * i + k];
        }
    for (int k = 0; k < 3; k++) if (hi[k] - H->lo[k] > ext) ext = hi[k] - H->lo[k];
    H->g = (int)cbrt((double)n) + 1;
    H->h = ext > 0 ? ext / H->g * (1 + 1e-9) : 1.0;
    const int nc = H->g * H->g * H->g;
    H->start = NEW(int, nc + 1);
    H->idx = NEW(int, n);
    memset(H->start, 0, sizeof(int) * (size_t)(nc + 1));
    int *cid = NEW(int, n);
    for (int i = 0; i < n; i++) {
        int c[3];
        nn_cell(H, P + 3 * i, c);
        cid[i] = (c[0] * H->g + c[1]) * H->g + c[2];
        H->start[cid[i] + 1]++;
    }
    for (int c = 0; c < nc; c++) H->start[c + 1] += H->start[c];
    int *fill = NEW(int, nc);
    memcpy(fill, H->start, sizeof(int) * (size_t)nc);
    for (int i = 0; i < n; i++) H->idx[fill[cid[i]]++] = i;
    free(fill); free(cid);
}
static void nn_free(nnhash *H) { free(H->start); free(H->idx); }
static int nn_query(const nnhash *H, const double *q, double *dist) {
    int c[3], best = -1;
    double bd = INFINITY;
    nn_cell(H, q, c);
    for (int r = 0; r <= H->g; r++) {
        for (int x = c[0] - r; x <= c[0] + r; x++) {
            if (x < 0 || x >= H->g) continue;
            for (int y = c[1] - r; y <= c[1] + r; y++) {
                if (y < 0 || y >= H->g) continue;
                for (int z = c[2] - r; z <= c[2] + r; z++) {
                    if (z < 0 || z >= H->g) continue;
                    if (abs(x - c[0]) != r && abs(y - c[1]) != r && abs(z - c[2]) != r) continue;
                    const int cc = (x * H->g + y) * H->g + z;
                    for (int k = H->start[cc]; k < H->start[cc + 1]; k++) {
                        const double d = dist3(q, H->P + 3 * H->idx[k]);
                        if (d < bd) { bd = d; best = H->idx[k]; }
                    }
                }
            }
        }
        if (best >= 0 && bd <= r * H->h) break;
    }
    *dist = bd;
    return best;
}

/* The nearest-neighbour hash against brute force (also for queries outside the bbox). */
static void test_nn_hash(void) {
    tl_rng_state = 4242;
    const int n = 3000;
    double *P = NEW(double, 3 * n);
    for (int i = 0; i < 3 * n; i++) P[i] = tl_rand01() * (i % 3 == 2 ? 0.1 : 5.0); /* flat cloud */
    nnhash H;
    nn_build(&H, P, n);
    int bad = 0;
    for (int k = 0; k < 2000; k++) {
        double q[3];
        for (int c = 0; c < 3; c++) q[c] = (k < 1000 ? P[3 * (k % n) + c] : 0.0) + (tl_rand01() - 0.5) * (k < 1000 ? 1e-3 : 12.0);
        double d;
        const int a = nn_query(&H, q, &d);
        int b = -1;
        double bd = INFINITY;
        for (int i = 0; i < n; i++) if (dist3(q, P + 3 * i) < bd) { bd = dist3(q, P + 3 * i); b = i; }
        bad += a != b && d != bd;
    }
    CHECK(bad == 0, "%d nearest-neighbour queries wrong", bad);
    nn_free(&H);
    free(P);
}

/* =====================================================================================
 * 4. oracle self-tests (no library)
 * ===================================================================================*/
static void random_curve(oc *c, int N, int dim) {
    *c = oc_alloc(N, dim);
    for (int i = 0; i < N * dim; i++) c->P[i] = 4.0 * tl_rand01() - 2.0;
    c->t[0] = 0.0;
    for (int k = 0; k < N + 3; k++) c->t[k + 1] = c->t[k] + rnd_interval();
}

static double curve_eval_diff(const oc *a, const oc *b, int samples) {
    const double lo = a->t[3], hi = a->t[a->N];
    double e = 0.0, s = 0.0;
    double *pa = NEW(double, a->dim), *pb = NEW(double, a->dim);
    for (int k = 0; k <= samples; k++) {
        const double x = k == samples ? hi : lo + (hi - lo) * tl_rand01();
        oc_eval(a, x, pa);
        oc_eval(b, x, pb);
        for (int i = 0; i < a->dim; i++) {
            if (fabs(pa[i] - pb[i]) > e) e = fabs(pa[i] - pb[i]);
            if (fabs(pa[i]) > s) s = fabs(pa[i]);
        }
    }
    free(pa); free(pb);
    return e / (s > 0 ? s : 1.0);
}

/* Curve preserved by midpoint insertion (1, 2, 3 levels), evaluated by de Boor; a wrong
 * knot must be detected (negative control). */
static void test_oracle_curve_preserved(void) {
    double worst = 0.0;
    for (int seed = 1; seed <= 8; seed++) {
        tl_rng_state = 0x1234ull * (unsigned long long)seed;
        oc c0;
        random_curve(&c0, 6 + seed, 3);
        oc c = oc_alloc(c0.N, 3);
        memcpy(c.P, c0.P, sizeof(double) * 3 * (size_t)c0.N);
        memcpy(c.t, c0.t, sizeof(double) * (size_t)(c0.N + 4));
        for (int l = 1; l <= 3; l++) {
            const int N0 = c.N;
            CHECK(oc_refine(&c), "refine failed");
            CHECK(c.N == 2 * N0 - 3, "count %d vs %d", c.N, 2 * N0 - 3);
            const double e = curve_eval_diff(&c0, &c, 200);
            if (e > worst) worst = e;
            CHECK(e <= 1e-12, "seed %d level %d: curve moved by %g", seed, l, e);
        }
        /* negative control: a knot 1% off inside one span must change the curve */
        oc bad = oc_alloc(c0.N, 3);
        memcpy(bad.P, c0.P, sizeof(double) * 3 * (size_t)c0.N);
        memcpy(bad.t, c0.t, sizeof(double) * (size_t)(c0.N + 4));
        const int s = 4;
        CHECK(oc_insert(&bad, 0.5 * (c0.t[s] + c0.t[s + 1])), "insert");
        bad.t[s + 1] += 0.01 * (c0.t[s + 1] - c0.t[s]); /* knot vector no longer matches points */
        const double eb = curve_eval_diff(&c0, &bad, 200);
        CHECK(eb > 1e-6, "negative control not detected (%g)", eb);
        oc_free(&bad);
        oc_free(&c);
        oc_free(&c0);
    }
    printf("  curve preservation: max rel error %.3g\n", worst);
}

/* Tensor surface preserved: evaluate (u then v by de Boor) before/after a grid refinement
 * done the way oracle_grid does it. */
static void test_oracle_surface_preserved(void) {
    double worst = 0.0;
    for (int seed = 1; seed <= 4; seed++) {
        tl_rng_state = 0x777ull * (unsigned long long)seed;
        const int Nu = 7 + seed, Nv = 6 + 2 * seed;
        oc cu;
        random_curve(&cu, Nu, 3 * Nv); /* rows, each a row of Nv points */
        oc cv0;
        random_curve(&cv0, Nv, 3); /* only for the v knots */
        double *tv = NEW(double, Nv + 4);
        memcpy(tv, cv0.t, sizeof(double) * (size_t)(Nv + 4));
        oc_free(&cv0);
        /* refined copy */
        double *T = transpose(cu.P, Nu, Nv, 3);
        oc cv = oc_alloc(Nv, 3 * Nu);
        memcpy(cv.P, T, sizeof(double) * 3 * (size_t)Nu * Nv);
        memcpy(cv.t, tv, sizeof(double) * (size_t)(Nv + 4));
        free(T);
        for (int l = 0; l < 2; l++) CHECK(oc_refine(&cv), "refine v");
        oc cr = oc_alloc(Nu, 3 * cv.N);
        free(cr.P);
        cr.P = transpose(cv.P, cv.N, Nu, 3);
        memcpy(cr.t, cu.t, sizeof(double) * (size_t)(Nu + 4));
        for (int l = 0; l < 2; l++) CHECK(oc_refine(&cr), "refine u");
        double *row0 = NEW(double, 3 * (size_t)Nv), *row1 = NEW(double, 3 * (size_t)cv.N);
        for (int k = 0; k < 100; k++) {
            const double x = cu.t[3] + (cu.t[Nu] - cu.t[3]) * tl_rand01();
            const double y = tv[3] + (tv[Nv] - tv[3]) * tl_rand01();
            oc_eval(&cu, x, row0);
            oc_eval(&cr, x, row1);
            oc a = {Nv, 3, row0, tv}, b = {cv.N, 3, row1, cv.t};
            double pa[3], pb[3];
            oc_eval(&a, y, pa);
            oc_eval(&b, y, pb);
            const double e = dist3(pa, pb);
            if (e > worst) worst = e;
        }
        CHECK(worst <= 1e-12, "seed %d: surface moved by %g", seed, worst);
        free(row0); free(row1); free(tv);
        oc_free(&cu); oc_free(&cv); oc_free(&cr);
    }
    printf("  surface preservation: max error %.3g\n", worst);
}

/* The oracle's index bookkeeping against the knot-interval formulas of SPEC 1.1
 * (periodic and reflected-open curves, random intervals), and the refined intervals. */
static void test_oracle_vs_interval_formulas(void) {
    double worst = 0.0;
    for (int seed = 1; seed <= 6; seed++) {
        tl_rng_state = 0xABCull * (unsigned long long)seed;
        const int m = 4 + seed;
        double *P = NEW(double, 3 * (size_t)(m + 1)), *D = NEW(double, m), *fd = NEW(double, 2 * (size_t)m);
        for (int i = 0; i < 3 * (m + 1); i++) P[i] = 4.0 * tl_rand01() - 2.0;
        for (int i = 0; i < m; i++) D[i] = rnd_interval();
        for (int periodic = 0; periodic <= 1; periodic++) {
            double *R = NULL;
            const int K = oracle_curve(P, m, D, periodic, 1, &R, fd);
            CHECK(K == 2 * m + !periodic, "K %d", K);
            const int np = periodic ? m : m + 1;
#define PP(j) (P + 3 * (periodic ? imod(j, m) : (j)))
#define DD(j) (periodic ? D[imod(j, m)] : refl_interval(D, m, j))
            /* edge points */
            double *E = NEW(double, 3 * (size_t)(m + 2));
            for (int j = -1; j <= m; j++) {
                const double dp = DD(j - 1), d = DD(j), dn = DD(j + 1);
                const double w = (2 * dp + d) / (2 * (dp + d + dn));
                double a[3], b[3];
                for (int c = 0; c < 3; c++) {
                    /* reflected points outside 0..m for the open case */
                    a[c] = (periodic || (j >= 0 && j <= m)) ? PP(j)[c] : 2 * P[(j < 0 ? 0 : m) * 3 + c] - P[(j < 0 ? -j : 2 * m - j) * 3 + c];
                    b[c] = (periodic || (j + 1 >= 0 && j + 1 <= m)) ? PP(j + 1)[c] : 2 * P[(j + 1 < 0 ? 0 : m) * 3 + c] - P[(j + 1 < 0 ? -(j + 1) : 2 * m - (j + 1)) * 3 + c];
                    E[3 * (j + 1) + c] = (1 - w) * a[c] + w * b[c];
                }
            }
            for (int j = 0; j < np; j++) {
                const double dp = DD(j - 1), d = DD(j);
                double V[3];
                for (int c = 0; c < 3; c++) V[c] = 0.5 * PP(j)[c] + (d * E[3 * j + c] + dp * E[3 * (j + 1) + c]) / (2 * (dp + d));
                const double ev = dist3(V, R + 3 * (2 * j));
                if (ev > worst) worst = ev;
                CHECK(ev <= 1e-13, "vertex point %d (periodic %d): %g", j, periodic, ev);
                if (j < m) {
                    const double ee = dist3(E + 3 * (j + 1), R + 3 * (2 * j + 1));
                    if (ee > worst) worst = ee;
                    CHECK(ee <= 1e-13, "edge point %d (periodic %d): %g", j, periodic, ee);
                    /* knot differences carry rounding of the cumulative knots (<= 20 * m) */
                    CHECK(fabs(fd[2 * j] - 0.5 * D[j]) <= 1e-13 * 20 * m && fabs(fd[2 * j + 1] - 0.5 * D[j]) <= 1e-13 * 20 * m,
                          "fine interval %d: %.17g %.17g vs %.17g", j, fd[2 * j], fd[2 * j + 1], 0.5 * D[j]);
                }
            }
#undef PP
#undef DD
            free(E);
            free(R);
        }
        free(P); free(D); free(fd);
    }
    printf("  vs SPEC 1.1 interval formulas: max error %.3g\n", worst);
}

/* Uniform intervals: the tensor oracle gives Catmull-Clark's regular masks (torus), and the
 * OpenSubdiv EDGE_AND_CORNER boundary masks (open grid): boundary vertex (1,6,1)/8, boundary
 * edge midpoint, corner pinned.  Also checks the refined intervals. */
static void test_oracle_uniform_masks(void) {
    double worst = 0.0;
    for (int periodic = 1; periodic >= 0; periodic--) {
        tl_rng_state = 99 + (unsigned long long)periodic;
        gcage g = gcage_make(periodic ? 6 : 5, periodic ? 5 : 4, periodic, 1);
        int Mf, Nf;
        double *fdu = NEW(double, 2 * g.m), *fdv = NEW(double, 2 * g.n);
        double *F = gcage_oracle(&g, 1, &Mf, &Nf, fdu, fdv);
        CHECK(F != NULL, "oracle failed");
        if (!F) { gcage_free(&g); free(fdu); free(fdv); continue; }
        for (int i = 0; i < 2 * g.m; i++) CHECK(fdu[i] == 0.5, "fine du %d = %g", i, fdu[i]);
        for (int j = 0; j < 2 * g.n; j++) CHECK(fdv[j] == 0.5, "fine dv %d = %g", j, fdv[j]);
        for (int I = 0; I < Mf; I++)
            for (int J = 0; J < Nf; J++) {
                double X[3] = {0, 0, 0};
                const int i = I / 2, j = J / 2, bi = !periodic && (I == 0 || I == Mf - 1), bj = !periodic && (J == 0 || J == Nf - 1);
                /* 1D masks: odd index = midpoint of (k, k+1); even = (1,6,1)/8 around k, or
                 * pinned (weight 1) on an open boundary */
                int ku[3], kv[3];
                double wu[3], wv[3];
                int nu_ = 0, nv_ = 0;
                if (I & 1) { ku[0] = i; ku[1] = i + 1; wu[0] = wu[1] = 0.5; nu_ = 2; }
                else if (bi) { ku[0] = i; wu[0] = 1; nu_ = 1; }
                else { ku[0] = i - 1; ku[1] = i; ku[2] = i + 1; wu[0] = wu[2] = 0.125; wu[1] = 0.75; nu_ = 3; }
                if (J & 1) { kv[0] = j; kv[1] = j + 1; wv[0] = wv[1] = 0.5; nv_ = 2; }
                else if (bj) { kv[0] = j; wv[0] = 1; nv_ = 1; }
                else { kv[0] = j - 1; kv[1] = j; kv[2] = j + 1; wv[0] = wv[2] = 0.125; wv[1] = 0.75; nv_ = 3; }
                for (int a = 0; a < nu_; a++)
                    for (int b = 0; b < nv_; b++)
                        for (int c = 0; c < 3; c++) X[c] += wu[a] * wv[b] * g.pos[3 * gid(&g, ku[a], kv[b]) + c];
                const double e = dist3(X, F + 3 * ((size_t)I * Nf + J));
                if (e > worst) worst = e;
                CHECK(e <= 1e-14, "uniform mask (%d,%d) periodic %d: %g", I, J, periodic, e);
            }
        free(F); free(fdu); free(fdv);
        gcage_free(&g);
    }
    printf("  uniform Catmull-Clark / boundary masks: max error %.3g\n", worst);
}

/* [1e]: refining the reflected extension twice == reflecting the once-refined polygon and
 * refining again (the oracle carries the extension through all levels; this confirms the
 * boundary reading that the library implements level by level). */
static void test_oracle_reflection_stable(void) {
    double worst = 0.0;
    for (int seed = 1; seed <= 5; seed++) {
        tl_rng_state = 0x5151ull * (unsigned long long)seed;
        const int m = 3 + seed;
        double *P = NEW(double, 3 * (size_t)(m + 1)), *D = NEW(double, m), *fd = NEW(double, 2 * (size_t)m);
        for (int i = 0; i < 3 * (m + 1); i++) P[i] = 4.0 * tl_rand01() - 2.0;
        for (int i = 0; i < m; i++) D[i] = rnd_interval();
        double *R1 = NULL, *R2 = NULL, *R11 = NULL;
        oracle_curve(P, m, D, 0, 1, &R1, fd);
        oracle_curve(P, m, D, 0, 2, &R2, NULL);
        oracle_curve(R1, 2 * m, fd, 0, 1, &R11, NULL);
        for (int k = 0; k <= 4 * m; k++) {
            const double e = dist3(R2 + 3 * k, R11 + 3 * k);
            if (e > worst) worst = e;
        }
        CHECK(worst <= 1e-13, "seed %d: %g", seed, worst);
        free(P); free(D); free(fd); free(R1); free(R2); free(R11);
    }
    printf("  reflection stable under refinement: max error %.3g\n", worst);
}

/* =====================================================================================
 * library cases
 * ===================================================================================*/
#ifndef ORACLE_SELFTEST

/* Boundary polygon of an open grid as one closed loop: (0,0)->(m,0)->(m,n)->(0,n)->(0,0).
 * Returns 2(m+n) points; D gets the 2(m+n) boundary intervals. */
static double *boundary_loop(const gcage *g, double *D) {
    const int K = 2 * (g->m + g->n);
    double *P = NEW(double, 3 * (size_t)K);
    int k = 0;
    for (int i = 0; i < g->m; i++, k++) { memcpy(P + 3 * k, g->pos + 3 * gid(g, i, 0), 3 * sizeof(double)); D[k] = g->Du[i]; }
    for (int j = 0; j < g->n; j++, k++) { memcpy(P + 3 * k, g->pos + 3 * gid(g, g->m, j), 3 * sizeof(double)); D[k] = g->Dv[j]; }
    for (int i = g->m; i > 0; i--, k++) { memcpy(P + 3 * k, g->pos + 3 * gid(g, i, g->n), 3 * sizeof(double)); D[k] = g->Du[i - 1]; }
    for (int j = g->n; j > 0; j--, k++) { memcpy(P + 3 * k, g->pos + 3 * gid(g, 0, j), 3 * sizeof(double)); D[k] = g->Dv[j - 1]; }
    return P;
}

/* Pinned oracle loop: each side refined on its own reflected curve, concatenated
 * (corners once).  Returns 2^L * 2(m+n) points. */
static double *oracle_loop_pinned(const gcage *g, int L, int *K) {
    /* side s starts at (si, sj), steps (di, dj), has len steps; u-side if dj == 0 */
    const int si[4] = {0, g->m, g->m, 0}, sj[4] = {0, 0, g->n, g->n};
    const int di[4] = {1, 0, -1, 0}, dj[4] = {0, 1, 0, -1};
    const int len[4] = {g->m, g->n, g->m, g->n};
    *K = (2 * (g->m + g->n)) << L;
    double *out = NEW(double, 3 * (size_t)*K);
    int k = 0;
    for (int s = 0; s < 4; s++) {
        const int ln = len[s];
        double *P = NEW(double, 3 * (size_t)(ln + 1)), *D = NEW(double, ln);
        for (int q = 0; q <= ln; q++) {
            const int i = si[s] + q * di[s], j = sj[s] + q * dj[s];
            memcpy(P + 3 * q, g->pos + 3 * gid(g, i, j), 3 * sizeof(double));
            if (q < ln) D[q] = dj[s] == 0 ? g->Du[di[s] > 0 ? i : i - 1] : g->Dv[dj[s] > 0 ? j : j - 1];
        }
        double *R = NULL;
        const int n = oracle_curve(P, ln, D, 0, L, &R, NULL);
        if (n > 0) memcpy(out + 3 * k, R, sizeof(double) * 3 * (size_t)(n - 1)); /* drop the end corner */
        k += (ln << L);
        free(R); free(P); free(D);
    }
    return out;
}

/* Cyclic comparison of two closed polygons of K points (either direction, any start). */
static double loop_distance(const double *A, const double *B, int K) {
    int s = 0;
    double bd = INFINITY;
    for (int k = 0; k < K; k++) { const double d = dist3(A + 3 * k, B); if (d < bd) { bd = d; s = k; } }
    double best = INFINITY;
    for (int dir = -1; dir <= 1; dir += 2) {
        double e = 0.0;
        for (int k = 0; k < K; k++) {
            const double d = dist3(A + 3 * imod(s + dir * k, K), B + 3 * k);
            if (d > e) e = d;
        }
        if (e < best) best = e;
    }
    return best;
}


static double bbox_diag(const double *P, int n) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            if (P[3 * i + c] < lo[c]) lo[c] = P[3 * i + c];
            if (P[3 * i + c] > hi[c]) hi[c] = P[3 * i + c];
        }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

static const char *point_kind(int I, int J) {
    return (I & 1) && (J & 1) ? "face point" : ((I & 1) || (J & 1)) ? "edge point" : "vertex point";
}

/* A refined library mesh, copied out. */
typedef struct {
    ccn_mesh_info info;
    double *pos, *ek;
    int32_t *fs, *fv, *ev;
} lmesh;

static int lmesh_get(const ccn_mesh *m, lmesh *o) {
    memset(o, 0, sizeof *o);
    if (ccn_mesh_get_info(m, &o->info) != CCN_OK) return 0;
    o->pos = NEW(double, 3 * (size_t)o->info.num_verts);
    o->fs = NEW(int32_t, o->info.num_faces);
    o->fv = NEW(int32_t, o->info.num_face_verts);
    o->ev = NEW(int32_t, 2 * (size_t)o->info.num_edges);
    o->ek = NEW(double, o->info.num_edges);
    return ccn_mesh_copy(m, o->pos, o->fs, o->fv, o->ev, o->ek) == CCN_OK;
}
static void lmesh_free(lmesh *o) { free(o->pos); free(o->ek); free(o->fs); free(o->fv); free(o->ev); }

static ccn_mesh *make_mesh(const gcage *g, int with_knots) {
    ccn_cage cage;
    memset(&cage, 0, sizeof cage);
    cage.num_verts = g->nverts;
    cage.num_faces = g->nfaces;
    cage.positions = g->pos;
    cage.face_sizes = g->fs;
    cage.face_verts = g->fv;
    if (with_knots) {
        cage.num_edges = g->nedges;
        cage.edge_verts = g->ev;
        cage.edge_knots = g->ek;
    }
    ccn_mesh *mesh = NULL;
    ccn_error err;
    memset(&err, 0, sizeof err);
    const ccn_status st = ccn_mesh_create(&cage, &mesh, &err);
    CHECK(st == CCN_OK && mesh, "ccn_mesh_create: %d %s", (int)st, err.message);
    if (st != CCN_OK) { ccn_mesh_destroy(mesh); return NULL; }
    ccn_mesh_info info;
    if (ccn_mesh_get_info(mesh, &info) == CCN_OK) {
        CHECK(info.num_verts == g->nverts && info.num_faces == g->nfaces && info.num_edges == g->nedges,
              "cage counts %d/%d/%d", info.num_verts, info.num_faces, info.num_edges);
        CHECK(info.num_rings == g->m + g->n, "num_rings %d, expected %d", info.num_rings, g->m + g->n);
        CHECK(info.num_ring_conflicts == 0, "num_ring_conflicts %d", info.num_ring_conflicts);
        CHECK(info.num_extraordinary == 0, "num_extraordinary %d", info.num_extraordinary);
    }
    return mesh;
}

static const char *scheme_name(ccn_scheme s) {
    return s == CCN_SCHEME_EIGEN ? "eigen" : s == CCN_SCHEME_NURSS ? "nurss" : "cc";
}

static double g_max_err[8]; /* per case, relative to the bbox diagonal */

/* Compares a library mesh after L levels with the oracle grid: nearest-neighbour bijection,
 * faces == grid cells (consistent orientation, every cell once), edge intervals ==
 * ring interval / 2^L.  Returns the max relative position error. */
static double compare_refined(const gcage *g, const lmesh *lm, int L, const char *tag) {
    int Mf, Nf;
    double *fdu = NEW(double, (size_t)g->m << L), *fdv = NEW(double, (size_t)g->n << L);
    double *F = gcage_oracle(g, L, &Mf, &Nf, fdu, fdv);
    const int no = Mf * Nf;
    double maxe = INFINITY;
    CHECK(F != NULL, "%s: oracle failed", tag);
    if (!F) goto done;
    const int Mc = g->m << L, Nc = g->n << L; /* cells */
    CHECK(lm->info.num_verts == no, "%s: num_verts %d, expected %d", tag, lm->info.num_verts, no);
    CHECK(lm->info.num_faces == Mc * Nc, "%s: num_faces %d, expected %d", tag, lm->info.num_faces, Mc * Nc);
    CHECK(lm->info.num_edges == Mc * Nf + Mf * Nc, "%s: num_edges %d, expected %d", tag, lm->info.num_edges, Mc * Nf + Mf * Nc);
    CHECK(lm->info.level == L, "%s: level %d", tag, lm->info.level);
    CHECK(lm->info.num_extraordinary == 0 && lm->info.num_ev_fallbacks == 0, "%s: EVs %d fallbacks %d", tag,
          lm->info.num_extraordinary, lm->info.num_ev_fallbacks);
    CHECK(lm->info.num_boundary_edges == (g->periodic ? 0 : 2 * (Mc + Nc)), "%s: num_boundary_edges %d", tag,
          lm->info.num_boundary_edges);
    if (lm->info.num_verts != no) goto done;
    {
        const double scale = bbox_diag(F, no);
        nnhash H;
        nn_build(&H, F, no);
        int *map = NEW(int, no), *hits = NEW(int, no);
        memset(hits, 0, sizeof(int) * (size_t)no);
        memset(map, 0, sizeof(int) * (size_t)no);
        double e = 0.0;
        int worst = 0;
        for (int v = 0; v < no; v++) {
            double d;
            map[v] = nn_query(&H, lm->pos + 3 * v, &d);
            if (!(d <= e)) { e = d; worst = v; } /* NaN-safe */
            hits[map[v]]++;
        }
        int dup = 0;
        for (int k = 0; k < no; k++) dup += hits[k] != 1;
        maxe = e / scale;
        {
            const int I = map[worst] / Nf, J = map[worst] % Nf;
            CHECK(maxe <= REL_TOL, "%s: max error %.3g (rel. to bbox %.3g) at library vertex %d ~ oracle (%d,%d) = %s%s",
                  tag, maxe, scale, worst, I, J, point_kind(I, J),
                  (!g->periodic && (I == 0 || J == 0 || I == Mf - 1 || J == Nf - 1)) ? " on the boundary" : "");
        }
        CHECK(dup == 0, "%s: nearest-neighbour map is not a bijection (%d oracle points not hit once)", tag, dup);
        /* faces */
        if (maxe <= REL_TOL && dup == 0) {
            char *cell = NEW(char, (size_t)Mc * Nc);
            memset(cell, 0, (size_t)Mc * Nc);
            int badf = 0;
            for (int f = 0, o = 0; f < lm->info.num_faces; o += lm->fs[f], f++) {
                if (lm->fs[f] != 4) { badf++; continue; }
                int I[4], J[4], turn = 0, ok = 1;
                for (int k = 0; k < 4; k++) { I[k] = map[lm->fv[o + k]] / Nf; J[k] = map[lm->fv[o + k]] % Nf; }
                int du[4], dv[4];
                for (int k = 0; k < 4 && ok; k++) {
                    du[k] = I[(k + 1) % 4] - I[k];
                    dv[k] = J[(k + 1) % 4] - J[k];
                    if (g->periodic) {
                        if (du[k] == Mc - 1) du[k] = -1; else if (du[k] == 1 - Mc) du[k] = 1;
                        if (dv[k] == Nc - 1) dv[k] = -1; else if (dv[k] == 1 - Nc) dv[k] = 1;
                    }
                    ok = abs(du[k]) + abs(dv[k]) == 1;
                }
                for (int k = 0; k < 4 && ok; k++) turn += du[k] * dv[(k + 1) % 4] - dv[k] * du[(k + 1) % 4];
                if (!ok || turn != 4) { badf++; continue; }
                int i0 = I[0], j0 = J[0];
                for (int k = 1; k < 4; k++) {
                    if (g->periodic ? (I[k] + 1) % Mc == i0 : I[k] + 1 == i0) i0 = I[k];
                    if (g->periodic ? (J[k] + 1) % Nc == j0 : J[k] + 1 == j0) j0 = J[k];
                }
                if (i0 >= Mc || j0 >= Nc || cell[(size_t)i0 * Nc + j0]++) badf++;
            }
            CHECK(badf == 0, "%s: %d refined faces are not grid cells with the cage's orientation", tag, badf);
            free(cell);
            /* edge intervals */
            int bade = 0;
            double worst_k = 0.0;
            for (int k = 0; k < lm->info.num_edges; k++) {
                const int a = map[lm->ev[2 * k]], b = map[lm->ev[2 * k + 1]];
                int Ia = a / Nf, Ja = a % Nf, Ib = b / Nf, Jb = b % Nf;
                double want = -1.0;
                if (Ja == Jb) {
                    int lo = (g->periodic ? (Ia + 1) % Mf == Ib : Ia + 1 == Ib) ? Ia : (g->periodic ? (Ib + 1) % Mf == Ia : Ib + 1 == Ia) ? Ib : -1;
                    if (lo >= 0) want = g->Du[lo >> L] / (double)(1 << L);
                } else if (Ia == Ib) {
                    int lo = (g->periodic ? (Ja + 1) % Nf == Jb : Ja + 1 == Jb) ? Ja : (g->periodic ? (Jb + 1) % Nf == Ja : Jb + 1 == Ja) ? Jb : -1;
                    if (lo >= 0) want = g->Dv[lo >> L] / (double)(1 << L);
                }
                if (want < 0) { bade++; continue; }
                const double r = fabs(lm->ek[k] - want) / want;
                if (!(r <= worst_k)) worst_k = r;
                if (!(r <= 1e-12)) {
                    if (bade < 3)
                        fprintf(stderr, "  %s: edge %d (%d,%d)-(%d,%d): interval %.17g, expected %.17g\n", tag, k, Ia, Ja, Ib, Jb,
                                lm->ek[k], want);
                    bade++;
                }
            }
            CHECK(bade == 0, "%s: %d refined edges with a wrong interval (or not grid edges), max rel %.3g", tag, bade, worst_k);
        }
        free(map); free(hits);
        nn_free(&H);
    }
done:
    free(F); free(fdu); free(fdv);
    return maxe;
}

/* refine the cage L levels in one call and compare */
static double run_direct(const gcage *g, int L, const ccn_options *opt, int with_knots, const char *tag) {
    double e = INFINITY;
    ccn_mesh *mesh = make_mesh(g, with_knots);
    if (!mesh) return e;
    ccn_mesh *out = NULL;
    ccn_error err;
    memset(&err, 0, sizeof err);
    const ccn_status st = ccn_refine(mesh, L, opt, &out, &err);
    CHECK(st == CCN_OK && out, "%s: ccn_refine: %s (%s)", tag, ccn_status_name(st), err.message);
    if (st == CCN_OK && out) {
        lmesh lm;
        if (lmesh_get(out, &lm)) e = compare_refined(g, &lm, L, tag);
        else CHECK(0, "%s: ccn_mesh_get_info/ccn_mesh_copy failed", tag);
        lmesh_free(&lm);
    }
    ccn_mesh_destroy(out);
    ccn_mesh_destroy(mesh);
    return e;
}

/* The header's vertex order, level by level (ccn_refine(.., 1) on the previous output):
 * face points (face order), edge points (edge order), vertex points (vertex order).
 * Tracks every vertex's fine-grid coordinate through that contract and compares with the
 * oracle by index: a failure names the exact point.  Returns max relative error. */
static double run_ordered(const gcage *g, int L, const ccn_options *opt, const char *tag) {
    double maxe = 0.0;
    ccn_mesh *cur = make_mesh(g, 1);
    if (!cur) return INFINITY;
    int nv = g->nverts, Mk = g->periodic ? g->m : g->m + 1, Nk = g->periodic ? g->n : g->n + 1;
    int *cI = NEW(int, nv), *cJ = NEW(int, nv);
    for (int i = 0; i < g->nu; i++)
        for (int j = 0; j < g->nv; j++) { cI[gid(g, i, j)] = i; cJ[gid(g, i, j)] = j; }
    for (int k = 1; k <= L && cur; k++) {
        lmesh lc;
        char t2[160];
        snprintf(t2, sizeof t2, "%s level %d", tag, k);
        if (!lmesh_get(cur, &lc)) { CHECK(0, "%s: copy failed", t2); lmesh_free(&lc); maxe = INFINITY; break; }
        ccn_mesh *next = NULL;
        ccn_error err;
        memset(&err, 0, sizeof err);
        const ccn_status st = ccn_refine(cur, 1, opt, &next, &err);
        CHECK(st == CCN_OK && next, "%s: ccn_refine: %s (%s)", t2, ccn_status_name(st), err.message);
        lmesh ln;
        memset(&ln, 0, sizeof ln);
        if (st != CCN_OK || !next || !lmesh_get(next, &ln)) { lmesh_free(&lc); lmesh_free(&ln); maxe = INFINITY; ccn_mesh_destroy(next); break; }
        /* coordinates on the cell lattice of level k-1: Mk x Nk vertices, wrap if periodic */
        const int Mc = g->periodic ? Mk : Mk - 1, Nc = g->periodic ? Nk : Nk - 1;
        const int nn = lc.info.num_faces + lc.info.num_edges + lc.info.num_verts;
        CHECK(ln.info.num_verts == nn, "%s: %d vertices, expected F+E+V = %d", t2, ln.info.num_verts, nn);
        int *nI = NEW(int, nn), *nJ = NEW(int, nn), bad = 0;
#define LOWER(a, b, M) (g->periodic ? (((a) + 1) % (M) == (b) ? (a) : ((b) + 1) % (M) == (a) ? (b) : -1) \
                                    : ((a) + 1 == (b) ? (a) : (b) + 1 == (a) ? (b) : -1))
        for (int f = 0, o = 0; f < lc.info.num_faces; o += lc.fs[f], f++) {
            int iv[2] = {cI[lc.fv[o]], -1}, jv[2] = {cJ[lc.fv[o]], -1};
            for (int q = 1; q < lc.fs[f]; q++) {
                const int a = cI[lc.fv[o + q]], b = cJ[lc.fv[o + q]];
                if (a != iv[0]) iv[1] = a;
                if (b != jv[0]) jv[1] = b;
            }
            const int li = iv[1] < 0 ? -1 : LOWER(iv[0], iv[1], Mc), lj = jv[1] < 0 ? -1 : LOWER(jv[0], jv[1], Nc);
            if (lc.fs[f] != 4 || li < 0 || lj < 0) { bad++; nI[f] = nJ[f] = 0; continue; }
            nI[f] = 2 * li + 1; nJ[f] = 2 * lj + 1;
        }
        for (int e = 0; e < lc.info.num_edges; e++) {
            const int p = lc.info.num_faces + e, a = lc.ev[2 * e], b = lc.ev[2 * e + 1];
            if (cJ[a] == cJ[b]) {
                const int l = LOWER(cI[a], cI[b], Mc);
                nI[p] = 2 * l + 1; nJ[p] = 2 * cJ[a];
                if (l < 0) bad++;
            } else {
                const int l = LOWER(cJ[a], cJ[b], Nc);
                nI[p] = 2 * cI[a]; nJ[p] = 2 * l + 1;
                if (l < 0 || cI[a] != cI[b]) bad++;
            }
        }
#undef LOWER
        for (int v = 0; v < lc.info.num_verts; v++) {
            const int p = lc.info.num_faces + lc.info.num_edges + v;
            nI[p] = 2 * cI[v]; nJ[p] = 2 * cJ[v];
        }
        CHECK(bad == 0, "%s: %d faces/edges of the previous level are not grid cells/edges", t2, bad);
        int Mf, Nf;
        double *F = gcage_oracle(g, k, &Mf, &Nf, NULL, NULL);
        if (F && ln.info.num_verts == nn && bad == 0) {
            const double scale = bbox_diag(F, Mf * Nf);
            double e = 0.0;
            int worst = 0, nbad = 0;
            for (int p = 0; p < nn; p++) {
                const double d = dist3(ln.pos + 3 * p, F + 3 * ((size_t)nI[p] * Nf + nJ[p])) / scale;
                if (!(d <= e)) { e = d; worst = p; }
                if (!(d <= REL_TOL)) {
                    if (nbad < 4) {
                        const int nf = lc.info.num_faces, ne = lc.info.num_edges;
                        const int I = nI[p], J = nJ[p];
                        fprintf(stderr, "  %s: vertex %d = %s of %s %d, fine (%d,%d)%s: error %.3g\n", t2, p,
                                p < nf ? "face point" : p < nf + ne ? "edge point" : "vertex point",
                                p < nf ? "face" : p < nf + ne ? "edge" : "vertex", p < nf ? p : p < nf + ne ? p - nf : p - nf - ne, I, J,
                                (!g->periodic && (I == 0 || J == 0 || I == Mf - 1 || J == Nf - 1)) ? " boundary" : "", d);
                    }
                    nbad++;
                }
            }
            CHECK(e <= REL_TOL, "%s: %d points off, max rel error %.3g at vertex %d (fine %d,%d)", t2, nbad, e, worst, nI[worst],
                  nJ[worst]);
            if (!(e <= maxe)) maxe = e;
        }
        free(F);
        free(cI); free(cJ);
        cI = nI; cJ = nJ;
        Mk = 2 * Mk - (g->periodic ? 0 : 1);
        Nk = 2 * Nk - (g->periodic ? 0 : 1);
        lmesh_free(&lc); lmesh_free(&ln);
        ccn_mesh_destroy(cur);
        cur = next;
    }
    free(cI); free(cJ);
    ccn_mesh_destroy(cur);
    return maxe;
}

static void note(int c, double e) { if (!(e <= g_max_err[c])) g_max_err[c] = e; }

/* 1. torus grids */
static void test_torus_vs_periodic_boehm(void) {
    const int sizes[2][2] = {{7, 6}, {5, 9}};
    const ccn_scheme schemes[2] = {CCN_SCHEME_EIGEN, CCN_SCHEME_NURSS};
    for (int seed = 1; seed <= 3; seed++)
        for (int s = 0; s < 2; s++) {
            tl_rng_state = 0x70D05ull * (unsigned long long)seed + (unsigned long long)s;
            gcage g = gcage_make(sizes[s][0], sizes[s][1], 1, 0);
            for (int sc = 0; sc < 2; sc++) {
                ccn_options opt;
                memset(&opt, 0, sizeof opt);
                opt.scheme = schemes[sc];
                for (int L = 1; L <= 3; L++) {
                    char tag[128];
                    snprintf(tag, sizeof tag, "torus %dx%d seed %d %s L=%d", g.m, g.n, seed, scheme_name(opt.scheme), L);
                    opt.levels = L;
                    note(1, run_direct(&g, L, &opt, 1, tag));
                }
                char tag[128];
                snprintf(tag, sizeof tag, "torus %dx%d seed %d %s (order)", g.m, g.n, seed, scheme_name(opt.scheme));
                note(5, run_ordered(&g, 3, &opt, tag));
            }
            gcage_free(&g);
        }
}

/* 2. open grids, pinned corners */
static void test_open_pinned_vs_reflected_boehm(void) {
    const int sizes[2][2] = {{6, 5}, {4, 7}};
    const ccn_scheme schemes[2] = {CCN_SCHEME_EIGEN, CCN_SCHEME_NURSS};
    for (int seed = 1; seed <= 3; seed++)
        for (int s = 0; s < 2; s++) {
            tl_rng_state = 0x0BE7ull * (unsigned long long)seed + (unsigned long long)s;
            gcage g = gcage_make(sizes[s][0], sizes[s][1], 0, 0);
            for (int sc = 0; sc < 2; sc++) {
                ccn_options opt;
                memset(&opt, 0, sizeof opt);
                opt.scheme = schemes[sc];
                opt.boundary_corners = CCN_CORNERS_PINNED;
                for (int L = 1; L <= 3; L++) {
                    char tag[128];
                    snprintf(tag, sizeof tag, "open %dx%d pinned seed %d %s L=%d", g.m, g.n, seed, scheme_name(opt.scheme), L);
                    opt.levels = L;
                    note(2, run_direct(&g, L, &opt, 1, tag));
                }
                char tag[128];
                snprintf(tag, sizeof tag, "open %dx%d pinned seed %d %s (order)", g.m, g.n, seed, scheme_name(opt.scheme));
                note(5, run_ordered(&g, 3, &opt, tag));
            }
            gcage_free(&g);
        }
}

/* Boundary loop of a mesh: the directed boundary edges (whose reverse is in no face),
 * chained.  Returns the vertex sequence length, 0 if not a single simple loop. */
static int cmp_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}
static int mesh_boundary_loop(const lmesh *lm, int **loop) {
    const int nv = lm->info.num_verts, nh = lm->info.num_face_verts;
    uint64_t *he = NEW(uint64_t, nh);
    for (int f = 0, o = 0; f < lm->info.num_faces; o += lm->fs[f], f++)
        for (int k = 0; k < lm->fs[f]; k++)
            he[o + k] = (uint64_t)lm->fv[o + k] * (uint64_t)nv + (uint64_t)lm->fv[o + (k + 1) % lm->fs[f]];
    qsort(he, (size_t)nh, sizeof *he, cmp_u64);
    int *next = NEW(int, nv), nb = 0, first = -1;
    for (int v = 0; v < nv; v++) next[v] = -1;
    for (int h = 0; h < nh; h++) {
        const uint64_t a = he[h] / (uint64_t)nv, b = he[h] % (uint64_t)nv, rev = b * (uint64_t)nv + a;
        if (bsearch(&rev, he, (size_t)nh, sizeof *he, cmp_u64)) continue;
        /* boundary edge a->b; the loop runs the other way round for the outside, either is fine */
        if (next[a] >= 0) { nb = -1000000; break; }
        next[a] = (int)b;
        first = (int)a;
        nb++;
    }
    int K = 0;
    *loop = NULL;
    if (nb > 0) {
        *loop = NEW(int, nb);
        int v = first;
        do { (*loop)[K++] = v; v = next[v]; } while (v >= 0 && v != first && K < nb);
        if (v != first || K != nb) K = 0;
    }
    free(he); free(next);
    return K;
}

/* 3. boundary polygon: pinned (per side, reflected) and smooth (one periodic curve) */
static void test_boundary_polygon(void) {
    const int sizes[2][2] = {{6, 5}, {4, 7}};
    for (int seed = 1; seed <= 3; seed++)
        for (int s = 0; s < 2; s++)
            for (int pinned = 0; pinned <= 1; pinned++)
                for (int sc = 0; sc < 2; sc++) {
                    tl_rng_state = 0xB0DAull * (unsigned long long)seed + (unsigned long long)s;
                    gcage g = gcage_make(sizes[s][0], sizes[s][1], 0, 0);
                    ccn_mesh *mesh = make_mesh(&g, 1);
                    for (int L = 1; L <= 3 && mesh; L++) {
                        char tag[128];
                        ccn_options opt;
                        memset(&opt, 0, sizeof opt);
                        opt.scheme = sc ? CCN_SCHEME_NURSS : CCN_SCHEME_EIGEN;
                        opt.levels = L;
                        opt.boundary_corners = pinned ? CCN_CORNERS_PINNED : CCN_CORNERS_SMOOTH;
                        snprintf(tag, sizeof tag, "boundary %dx%d %s seed %d %s L=%d", g.m, g.n, pinned ? "pinned" : "smooth", seed,
                                 scheme_name(opt.scheme), L);
                        int K = 0;
                        double *O = NULL;
                        if (pinned) {
                            O = oracle_loop_pinned(&g, L, &K);
                        } else {
                            double *D = NEW(double, 2 * (g.m + g.n));
                            double *B = boundary_loop(&g, D);
                            K = oracle_curve(B, 2 * (g.m + g.n), D, 1, L, &O, NULL);
                            free(B); free(D);
                        }
                        ccn_mesh *out = NULL;
                        ccn_error err;
                        memset(&err, 0, sizeof err);
                        const ccn_status st = ccn_refine(mesh, L, &opt, &out, &err);
                        CHECK(st == CCN_OK && out, "%s: ccn_refine: %s (%s)", tag, ccn_status_name(st), err.message);
                        lmesh lm;
                        memset(&lm, 0, sizeof lm);
                        if (st == CCN_OK && out && lmesh_get(out, &lm)) {
                            int *loop = NULL;
                            const int nl = mesh_boundary_loop(&lm, &loop);
                            CHECK(nl == K, "%s: boundary loop has %d vertices, expected %d", tag, nl, K);
                            if (nl == K && K > 0) {
                                double *A = NEW(double, 3 * (size_t)K);
                                for (int k = 0; k < K; k++) memcpy(A + 3 * k, lm.pos + 3 * loop[k], 3 * sizeof(double));
                                const double e = loop_distance(A, O, K) / bbox_diag(O, K);
                                CHECK(e <= REL_TOL, "%s: boundary loop error %.3g (rel.)", tag, e);
                                if (e > REL_TOL) { /* name the worst point */
                                    int sidx = 0;
                                    double bd = INFINITY;
                                    for (int k = 0; k < K; k++) if (dist3(A + 3 * k, O) < bd) { bd = dist3(A + 3 * k, O); sidx = k; }
                                    for (int dir = -1; dir <= 1; dir += 2) {
                                        int wk = 0;
                                        double we = 0;
                                        for (int k = 0; k < K; k++) {
                                            const double d = dist3(A + 3 * imod(sidx + dir * k, K), O + 3 * k);
                                            if (d > we) { we = d; wk = k; }
                                        }
                                        fprintf(stderr, "  %s: direction %+d: worst oracle loop index %d of %d (corner every %d/%d), err %.3g\n",
                                                tag, dir, wk, K, g.m << L, g.n << L, we);
                                    }
                                }
                                note(3, e);
                                free(A);
                            }
                            free(loop);
                        }
                        lmesh_free(&lm);
                        ccn_mesh_destroy(out);
                        free(O);
                    }
                    ccn_mesh_destroy(mesh);
                    gcage_free(&g);
                }
}

/* Uniform intervals: edge_knots NULL (= all 1) with every scheme, including plain
 * Catmull-Clark, on a torus and a pinned open grid. */
static void test_uniform_all_schemes(void) {
    const ccn_scheme schemes[3] = {CCN_SCHEME_EIGEN, CCN_SCHEME_NURSS, CCN_SCHEME_CATMULL_CLARK};
    for (int periodic = 0; periodic <= 1; periodic++) {
        tl_rng_state = 0x5EEDull + (unsigned long long)periodic;
        gcage g = gcage_make(periodic ? 6 : 5, periodic ? 5 : 6, periodic, 1);
        for (int sc = 0; sc < 3; sc++)
            for (int L = 1; L <= 2; L++) {
                ccn_options opt;
                memset(&opt, 0, sizeof opt);
                opt.scheme = schemes[sc];
                opt.levels = L;
                opt.boundary_corners = CCN_CORNERS_PINNED;
                char tag[128];
                snprintf(tag, sizeof tag, "uniform %s %s L=%d", periodic ? "torus" : "open pinned", scheme_name(opt.scheme), L);
                note(4, run_direct(&g, L, &opt, 0, tag));
            }
        gcage_free(&g);
    }
}

/* The counters of ccn_mesh_info on refined meshes (kept apart from the geometric cases:
 * a wrong counter should not hide whether the geometry is right). */
static void test_refined_info_counts(void) {
    for (int periodic = 0; periodic <= 1; periodic++) {
        tl_rng_state = 0x1F0ull + (unsigned long long)periodic;
        gcage g = gcage_make(5, 4, periodic, 0);
        ccn_mesh *mesh = make_mesh(&g, 1);
        for (int L = 1; L <= 2 && mesh; L++) {
            ccn_options opt;
            memset(&opt, 0, sizeof opt);
            opt.boundary_corners = CCN_CORNERS_PINNED;
            ccn_mesh *out = NULL;
            ccn_mesh_info info;
            if (ccn_refine(mesh, L, &opt, &out, NULL) == CCN_OK && ccn_mesh_get_info(out, &info) == CCN_OK) {
                const int Mc = g.m << L, Nc = g.n << L;
                CHECK(info.num_rings == Mc + Nc, "%s L=%d: num_rings %d, expected %d (2^L x the cage's %d)",
                      periodic ? "torus" : "open", L, info.num_rings, Mc + Nc, g.m + g.n);
                CHECK(info.num_ring_conflicts == 0, "num_ring_conflicts %d", info.num_ring_conflicts);
                CHECK(info.num_face_verts == 4 * Mc * Nc, "num_face_verts %d", info.num_face_verts);
                CHECK(info.max_valence == 4, "max_valence %d", info.max_valence);
                CHECK(info.num_ignored_verts == 0 && info.num_ignored_edges == 0, "ignored %d %d", info.num_ignored_verts,
                      info.num_ignored_edges);
            } else {
                CHECK(0, "refine failed");
            }
            ccn_mesh_destroy(out);
        }
        ccn_mesh_destroy(mesh);
        gcage_free(&g);
    }
}

static void test_report(void) {
    printf("  max rel errors: torus %.3g, open pinned %.3g, boundary loops %.3g, uniform/NULL knots %.3g, ordered %.3g\n",
           g_max_err[1], g_max_err[2], g_max_err[3], g_max_err[4], g_max_err[5]);
}
#endif /* !ORACLE_SELFTEST */

int main(void) {
    RUN(test_oracle_curve_preserved);
    RUN(test_oracle_surface_preserved);
    RUN(test_oracle_vs_interval_formulas);
    RUN(test_oracle_uniform_masks);
    RUN(test_oracle_reflection_stable);
    RUN(test_nn_hash);
#ifndef ORACLE_SELFTEST
    RUN(test_torus_vs_periodic_boehm);
    RUN(test_open_pinned_vs_reflected_boehm);
    RUN(test_boundary_polygon);
    RUN(test_uniform_all_schemes);
    RUN(test_refined_info_counts);
    test_report();
#endif
    return TEST_SUMMARY();
}
