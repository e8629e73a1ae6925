/* Principal curvatures of the limit surface (ccn_limit_mesh.curvatures) against an independent
 * tensor-product B-spline written here.
 *
 * A torus of nu x nv quads (every vertex regular) whose edge rings carry random intervals is,
 * in the limit, the periodic bicubic B-spline with those knot intervals and the cage vertices as
 * control points (vertex (i, j) at knots (t_i, s_j); its blossom labels (t_i-1, t_i, t_i+1)).
 * Level L inserts 2^L - 1 equally spaced knots into every interval, so the output vertices lie
 * at those parameters. Here the spline is evaluated by the blossoming (de Boor) recursion, its
 * derivatives from the blossom's multi-affinity (f' = 3 f(t, t, d), f'' = 6 f(t, d, d)), and
 * the principal curvatures from the eigenvalues of the shape operator I^-1 II (a 2 x 2
 * eigenproblem, not the library's H +- sqrt(H^2 - K)). Each output vertex is matched to its
 * parameter by position. Checked: k1, k2 within 1e-8 of the largest |k|, the k1 direction
 * parallel where the two differ, the sign (positive at the point farthest from the axis, where
 * the surface bends away from its outward normal), and that without the option nothing is
 * written. Open grids (corners pinned) likewise, against the B-spline of the net extended by
 * mirror ghosts. Plus flags: a star's EV gives NaN. */
#include "ccnurbs.h"
#include "testlib.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

typedef struct {
    int nu, nv;
    double *P;        /* 3 * nu * nv, vertex (i, j) at 3 * (j * nu + i) */
    double *du, *dv;  /* intervals: du[i] between columns i and i+1, dv[j] rows j, j+1 */
} torus;

/* Knot k of a periodic sequence of intervals d[0..n-1] (t_0 = 0, any integer k). */
static double knot(const double *d, int n, int k) {
    double T = 0, t = 0;
    for (int i = 0; i < n; i++) T += d[i];
    int q = (int)floor((double)k / n), r = k - q * n;
    for (int i = 0; i < r; i++) t += d[i];
    return t + q * T;
}

/* The blossom f(x1, x2, x3) of the cubic on [t_i, t_i+1] of a periodic B-spline curve with
 * control points C[m] (each dim values, m mod n) at knots t (intervals d). */
static void blossom(const double *C, int dim, const double *d, int n, int i, const double x[3],
                    double *out) {
    double P[4][12], t[8]; /* dim <= 12 */
    for (int a = 0; a < 8; a++) t[a] = knot(d, n, i - 3 + a); /* t[a] = t_{i-3+a} */
    for (int a = 0; a < 4; a++) {
        int m = ((i - 1 + a) % n + n) % n;
        for (int c = 0; c < dim; c++) P[a][c] = C[dim * m + c];
    }
    /* P[a] = f(t_{i-2+a}, t_{i-1+a}, t_{i+a}) = labels (t[a+1], t[a+2], t[a+3]) */
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3 - r; a++) {
            /* combine P[a] and P[a+1]: their differing labels are t[a+1+r] and t[a+4] */
            double lo = t[a + 1 + r], hi = t[a + 4], w = (x[r] - lo) / (hi - lo);
            for (int c = 0; c < dim; c++) P[a][c] = (1 - w) * P[a][c] + w * P[a + 1][c];
        }
    for (int c = 0; c < dim; c++) out[c] = P[0][c];
}

/* Value and derivatives of a periodic curve at t in segment i: f, f', f'' (dim each). */
static void curve_derivs(const double *C, int dim, const double *d, int n, int i, double t,
                         double *f, double *f1, double *f2) {
    double a[12], b[12], c[12], e[12];
    double x0[3] = {t, t, t}, x1[3] = {t, t, t + 1}, x2[3] = {t, t + 1, t + 1}, x3[3] = {t, t + 1, t};
    blossom(C, dim, d, n, i, x0, a);
    blossom(C, dim, d, n, i, x1, b);
    blossom(C, dim, d, n, i, x2, c);
    blossom(C, dim, d, n, i, x3, e);
    for (int k = 0; k < dim; k++) {
        f[k] = a[k];
        f1[k] = 3 * (b[k] - a[k]);
        f2[k] = 6 * (c[k] - b[k] - e[k] + a[k]);
    }
}

/* S, S_u, S_v, S_uu, S_uv, S_vv of the torus spline at (u in segment i, v in segment j). */
static void surface_derivs(const torus *T, int i, double u, int j, double v, double D[6][3]) {
    /* along u, every row m of control points: its value and u-derivatives, as curves in v */
    int n = T->nu, m = T->nv;
    double *R = malloc(sizeof(double) * 9 * (size_t)m);
    for (int r = 0; r < m; r++) {
        double f[3], f1[3], f2[3];
        curve_derivs(T->P + 3 * (size_t)r * n, 3, T->du, n, i, u, f, f1, f2);
        memcpy(R + 9 * r, f, sizeof f);
        memcpy(R + 9 * r + 3, f1, sizeof f1);
        memcpy(R + 9 * r + 6, f2, sizeof f2);
    }
    double f[9], f1[9], f2[9];
    curve_derivs(R, 9, T->dv, m, j, v, f, f1, f2);
    for (int c = 0; c < 3; c++) {
        D[0][c] = f[c];          /* S */
        D[1][c] = f[3 + c];      /* S_u */
        D[2][c] = f1[c];         /* S_v */
        D[3][c] = f[6 + c];      /* S_uu */
        D[4][c] = f1[3 + c];     /* S_uv */
        D[5][c] = f2[c];         /* S_vv */
    }
    free(R);
}

/* Principal curvatures (k1 >= k2, positive bending away from n = S_u x S_v) and the unit
 * direction of k1, from the shape operator's 2 x 2 eigenproblem. */
static void oracle_curvature(double D[6][3], double *k1, double *k2, double dir[3]) {
    double *su = D[1], *sv = D[2], n[3] = {su[1] * sv[2] - su[2] * sv[1],
                                           su[2] * sv[0] - su[0] * sv[2],
                                           su[0] * sv[1] - su[1] * sv[0]};
    double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 3; c++) n[c] /= ln;
    double I[2][2] = {{0}}, II[2][2] = {{0}};
    double *t[2] = {su, sv}, *s2[2][2] = {{D[3], D[4]}, {D[4], D[5]}};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int c = 0; c < 3; c++) {
                I[a][b] += t[a][c] * t[b][c];
                II[a][b] -= s2[a][b][c] * n[c];
            }
    double det = I[0][0] * I[1][1] - I[0][1] * I[1][0];
    double Ii[2][2] = {{I[1][1] / det, -I[0][1] / det}, {-I[1][0] / det, I[0][0] / det}};
    double W[2][2];
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) W[a][b] = Ii[a][0] * II[0][b] + Ii[a][1] * II[1][b];
    double tr = W[0][0] + W[1][1], dt = W[0][0] * W[1][1] - W[0][1] * W[1][0];
    double disc = sqrt(fmax(tr * tr / 4 - dt, 0));
    *k1 = tr / 2 + disc;
    *k2 = tr / 2 - disc;
    /* eigenvector of W for k1 */
    double x, y;
    if (fabs(W[0][1]) + fabs(*k1 - W[0][0]) > fabs(W[1][0]) + fabs(*k1 - W[1][1])) x = W[0][1], y = *k1 - W[0][0];
    else x = *k1 - W[1][1], y = W[1][0];
    double l = 0;
    for (int c = 0; c < 3; c++) dir[c] = x * su[c] + y * sv[c], l += dir[c] * dir[c];
    l = sqrt(l);
    for (int c = 0; c < 3; c++) dir[c] /= l;
}

static void torus_make(torus *T, int nu, int nv, double spread) {
    T->nu = nu, T->nv = nv;
    T->P = malloc(sizeof(double) * 3 * (size_t)nu * nv);
    T->du = malloc(sizeof(double) * (size_t)nu);
    T->dv = malloc(sizeof(double) * (size_t)nv);
    for (int i = 0; i < nu; i++) T->du[i] = exp(spread * (2 * tl_rand01() - 1));
    for (int j = 0; j < nv; j++) T->dv[j] = exp(spread * (2 * tl_rand01() - 1));
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            double a = 2 * PI * (i + 0.3 * (tl_rand01() - 0.5)) / nu;
            double b = 2 * PI * (j + 0.3 * (tl_rand01() - 0.5)) / nv;
            double r = 1.0 + 0.1 * (tl_rand01() - 0.5), R = 3.0;
            double *p = T->P + 3 * ((size_t)j * nu + i);
            p[0] = (R + r * cos(b)) * cos(a);
            p[1] = (R + r * cos(b)) * sin(a);
            p[2] = r * sin(b) + 0.2 * (tl_rand01() - 0.5);
        }
}

static void torus_free(torus *T) { free(T->P); free(T->du); free(T->dv); }

/* The row of ref (n rows of `stride` doubles, a position first) nearest to x; *dist its
 * distance. */
static int nearest(const double *ref, int stride, int n, const double *x, double *dist) {
    int best = 0;
    double bd = INFINITY;
    for (int r = 0; r < n; r++) {
        const double *q = ref + (size_t)stride * r;
        double dx = x[0] - q[0], dy = x[1] - q[1], dz = x[2] - q[2], dd = dx * dx + dy * dy + dz * dz;
        if (dd < bd) bd = dd, best = r;
    }
    *dist = sqrt(bd);
    return best;
}

/* A plan of cage at `levels` with `cap` (NULL, after a CHECK, when it cannot be made) and its
 * sizes. */
static int plan_corners = CCN_CORNERS_SMOOTH; /* boundary_corners of make_plan's plans */

static ccn_plan *make_plan(const ccn_cage *cage, int levels, ccn_cap cap, ccn_sizes *sz) {
    ccn_options o;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.cap = cap;
    o.boundary_corners = plan_corners;
    ccn_plan *p = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(cage, &o, &p, &err) == CCN_OK, "plan: %s", err.message);
    if (p) ccn_plan_get_sizes(p, sz);
    return p;
}

/* The cage: quads (i, j) (i+1, j) (i+1, j+1) (i, j+1); u edges carry du[i], v edges dv[j]. */
static ccn_cage torus_cage(const torus *T, int32_t *fsz, int32_t *fv, int32_t *ev, double *kn) {
    int n = T->nu, m = T->nv, ne = 0;
#define VID(i, j) ((((j) % m + m) % m) * n + (((i) % n + n) % n))
    for (int j = 0; j < m; j++)
        for (int i = 0; i < n; i++) {
            int f = j * n + i;
            fsz[f] = 4;
            fv[4 * f] = VID(i, j), fv[4 * f + 1] = VID(i + 1, j);
            fv[4 * f + 2] = VID(i + 1, j + 1), fv[4 * f + 3] = VID(i, j + 1);
            ev[2 * ne] = VID(i, j), ev[2 * ne + 1] = VID(i + 1, j), kn[ne++] = T->du[i];
            ev[2 * ne] = VID(i, j), ev[2 * ne + 1] = VID(i, j + 1), kn[ne++] = T->dv[j];
        }
#undef VID
    return (ccn_cage){n * m, n * m, ne, T->P, fsz, fv, ev, kn, NULL, NULL};
}

static void check_torus(int nu, int nv, double spread, int levels, double *worst_k,
                        double *worst_dir) {
    torus T;
    torus_make(&T, nu, nv, spread);
    int32_t *fsz = malloc(sizeof(int32_t) * (size_t)nu * nv), *fv = malloc(sizeof(int32_t) * 4 * (size_t)nu * nv);
    int32_t *ev = malloc(sizeof(int32_t) * 4 * (size_t)nu * nv);
    double *kn = malloc(sizeof(double) * 2 * (size_t)nu * nv);
    ccn_cage cage = torus_cage(&T, fsz, fv, ev, kn);
    ccn_sizes sz;
    ccn_error err;
    ccn_plan *p = make_plan(&cage, levels, CCN_CAP_GUIDED_BI5, &sz);
    if (!p) return;
    int32_t N = sz.num_verts;
    double *X = malloc(sizeof(double) * 3 * (size_t)N), *K = malloc(sizeof(double) * 2 * (size_t)N);
    double *Dd = malloc(sizeof(double) * 3 * (size_t)N);
    ccn_limit_mesh out;
    memset(&out, 0, sizeof out);
    out.positions = X;
    out.curvatures = K;
    out.curvature_dirs = Dd;
    CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK, "evaluate: %s", err.message);
    int S = 1 << levels, nu2 = nu * S, nv2 = nv * S;
    CHECK(N == nu2 * nv2, "output vertices %d, expected %d", (int)N, nu2 * nv2);
    /* the oracle at every output parameter, and each output vertex matched by position */
    double (*ref)[9] = malloc(sizeof(double[9]) * (size_t)nu2 * nv2);
    double kmax = 0, pos_err = 0;
    for (int b = 0; b < nv2; b++)
        for (int a = 0; a < nu2; a++) {
            int i = a / S, j = b / S;
            double u = knot(T.du, nu, i) + (a % S) * T.du[i] / S;
            double v = knot(T.dv, nv, j) + (b % S) * T.dv[j] / S;
            double D[6][3], k1, k2, dir[3];
            surface_derivs(&T, i, u, j, v, D);
            oracle_curvature(D, &k1, &k2, dir);
            double *r = ref[b * nu2 + a];
            memcpy(r, D[0], sizeof(double) * 3);
            r[3] = k1, r[4] = k2;
            memcpy(r + 5, dir, sizeof dir);
            kmax = fmax(kmax, fmax(fabs(k1), fabs(k2)));
        }
    double wk = 0, wd = 0, far = -1, k_far = 0;
    for (int32_t q = 0; q < N; q++) {
        double dist;
        double *r = ref[nearest(&ref[0][0], 9, nu2 * nv2, X + 3 * q, &dist)];
        pos_err = fmax(pos_err, dist);
        wk = fmax(wk, fmax(fabs(K[2 * q] - r[3]), fabs(K[2 * q + 1] - r[4])) / kmax);
        if (r[3] - r[4] > 1e-3 * kmax) {
            double c = fabs(Dd[3 * q] * r[5] + Dd[3 * q + 1] * r[6] + Dd[3 * q + 2] * r[7]);
            wd = fmax(wd, sqrt(fmax(0, 1 - c * c)));
        }
        double rad = hypot(X[3 * q], X[3 * q + 1]);
        if (rad > far) far = rad, k_far = K[2 * q + 1];
    }
    CHECK(pos_err < 1e-9, "positions off the oracle by %.3g: the parameters are not matched", pos_err);
    CHECK(wk <= 1e-8, "torus %dx%d spread %g level %d: curvature off by %.3g of max |k| %.3g",
          nu, nv, spread, levels, wk, kmax);
    CHECK(wd <= 1e-6, "torus %dx%d level %d: k1 direction off by sin %.3g", nu, nv, levels, wd);
    /* the vertex farthest from the axis: the surface lies inside the cylinder through it, so
     * every normal curvature there is at least the cylinder's (> 0, bending away from the
     * outward normal) */
    CHECK(k_far > 0, "k2 = %.3g at the vertex farthest from the axis: the sign is not "
          "'bending away from the normal'", k_far);
    *worst_k = fmax(*worst_k, wk);
    *worst_dir = fmax(*worst_dir, wd);
    /* without the option nothing is computed or written */
    double guard = 12345.0;
    out.curvatures = NULL;
    out.curvature_dirs = NULL;
    K[0] = guard;
    CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK && K[0] == guard, "written without the option");
    free(ref); free(X); free(K); free(Dd);
    ccn_plan_destroy(p);
    free(fsz); free(fv); free(ev); free(kn);
    torus_free(&T);
}

static void test_torus_equals_bspline(void) {
    double wk = 0, wd = 0;
    int cases = 0;
    for (int rep = 0; rep < 3; rep++)
        for (int levels = 1; levels <= 3; levels++) {
            check_torus(5 + rep, 6 + 2 * rep, rep == 0 ? 0.0 : 1.2, levels, &wk, &wd);
            cases++;
        }
    printf("# %d random tori (intervals up to e^2.4 : 1), levels 1-3: principal curvatures within "
           "%.3g of max |k| of the tensor B-spline, k1 directions within sin %.3g\n", cases, wk, wd);
}

/* Limit positions and curvatures of cage at `levels` (refined limit, no cap); malloc'ed. */
static int32_t star_eval(const ccn_cage *cage, int levels, double **X, double **K) {
    ccn_sizes sz;
    ccn_error err;
    ccn_plan *p = make_plan(cage, levels, CCN_CAP_REFINE, &sz);
    if (!p) return 0;
    *X = malloc(sizeof(double) * 3 * (size_t)sz.num_verts);
    *K = malloc(sizeof(double) * 2 * (size_t)sz.num_verts);
    ccn_limit_mesh out;
    memset(&out, 0, sizeof out);
    out.positions = *X;
    out.curvatures = *K;
    ccn_status st = ccn_plan_evaluate(p, NULL, &out, &err);
    ccn_plan_destroy(p);
    return st == CCN_OK ? sz.num_verts : 0;
}

/* A valence-5 star (an EV in the middle of a fan) with non-uniform intervals: NaN at the EV,
 * numbers elsewhere; the vertices next to the EV, whose limit comes from the grid one level
 * finer, agree with the same surface points of the next output level (there farther from the
 * EV, on their own level's grid); curvature_dirs without curvatures is refused. */
static void test_flags(void) {
    /* fan of 5 quads around vertex 0 */
    double P[3 * 11];
    int32_t fsz[5], fv[20];
    P[0] = P[1] = 0, P[2] = 0.3;
    for (int k = 0; k < 5; k++) {
        double a = 2 * PI * k / 5, b = a + PI / 5;
        P[3 * (1 + k)] = cos(a), P[3 * (1 + k) + 1] = sin(a), P[3 * (1 + k) + 2] = 0;
        P[3 * (6 + k)] = 1.4 * cos(b), P[3 * (6 + k) + 1] = 1.4 * sin(b), P[3 * (6 + k) + 2] = -0.2;
    }
    for (int k = 0; k < 5; k++) {
        fsz[k] = 4;
        fv[4 * k] = 0, fv[4 * k + 1] = 1 + k, fv[4 * k + 2] = 6 + k, fv[4 * k + 3] = 1 + (k + 1) % 5;
    }
    int32_t ev[2 * 20];
    double kn[20];
    int ne = 0;
    for (int k = 0; k < 5; k++) { /* spokes and the outer edges parallel to them */
        double d = 0.5 + 0.4 * k;
        ev[2 * ne] = 0, ev[2 * ne + 1] = 1 + k, kn[ne++] = d;
        ev[2 * ne] = 1 + (k + 4) % 5, ev[2 * ne + 1] = 6 + (k + 4) % 5, kn[ne++] = d;
    }
    ccn_cage cage = {11, 5, ne, P, fsz, fv, ev, kn, NULL, NULL};
    ccn_sizes sz;
    ccn_error err;
    ccn_plan *p = make_plan(&cage, 3, CCN_CAP_REFINE, &sz);
    if (!p) return;
    double *X = malloc(sizeof(double) * 3 * (size_t)sz.num_verts), *K = malloc(sizeof(double) * 2 * (size_t)sz.num_verts);
    double D[3];
    ccn_limit_mesh out;
    memset(&out, 0, sizeof out);
    out.positions = X;
    out.curvature_dirs = D;
    CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_ERR_ARGUMENT, "curvature_dirs alone accepted");
    out.curvature_dirs = NULL;
    out.curvatures = K;
    CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK, "evaluate: %s", err.message);
    int numbers = 0;
    int32_t evq = -1, *F = malloc(sizeof(int32_t) * 4 * (size_t)sz.num_faces);
    int32_t *nfaces = calloc((size_t)sz.num_verts, sizeof(int32_t));
    out.face_verts = F;
    CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK, "evaluate: %s", err.message);
    for (int32_t c = 0; c < 4 * sz.num_faces; c++) nfaces[F[c]]++;
    for (int32_t q = 0; q < sz.num_verts; q++) { /* the EV: the one vertex in 5 faces */
        if (nfaces[q] == 5) evq = q;
        if (nfaces[q] == 4) numbers += isfinite(K[2 * q]) && isfinite(K[2 * q + 1]);
    }
    free(F);
    free(nfaces);
    CHECK(evq >= 0, "no vertex of valence 5 in the output");
    if (evq < 0) evq = 0;
    CHECK(isnan(K[2 * evq]) && isnan(K[2 * evq + 1]), "the EV's curvature is not flagged NaN");
    CHECK(numbers > 0, "no curvature at the regular vertices around the EV");
    free(X); free(K);
    ccn_plan_destroy(p);
    /* levels 3 and 4 at their shared points */
    double *X3, *K3, *X4, *K4, worst = 0, kmax = 0;
    int32_t n3 = star_eval(&cage, 3, &X3, &K3), n4 = star_eval(&cage, 4, &X4, &K4), shared = 0;
    CHECK(n3 > 0 && n4 > 0, "plans of levels 3 and 4");
    for (int32_t a = 0; a < n3; a++) {
        if (!isfinite(K3[2 * a])) continue;
        kmax = fmax(kmax, fmax(fabs(K3[2 * a]), fabs(K3[2 * a + 1])));
        for (int32_t b = 0; b < n4; b++) {
            double dx = X3[3 * a] - X4[3 * b], dy = X3[3 * a + 1] - X4[3 * b + 1], dz = X3[3 * a + 2] - X4[3 * b + 2];
            if (dx * dx + dy * dy + dz * dz > 1e-24) continue;
            CHECK(isfinite(K4[2 * b]), "a point with curvature at level 3 has none at level 4");
            worst = fmax(worst, fmax(fabs(K3[2 * a] - K4[2 * b]), fabs(K3[2 * a + 1] - K4[2 * b + 1])));
            shared++;
        }
    }
    CHECK(shared > 100 && worst <= 1e-9 * kmax, "levels 3 and 4: %d shared points, curvature "
          "differs by %.3g (max |k| %.3g)", (int)shared, worst, kmax);
    printf("# valence-5 star, non-uniform: the EV flagged; %d points shared by levels 3 and 4 "
           "(next to the EV: the finer grid's stencils) agree to %.3g of max |k|\n", (int)shared,
           worst / kmax);
    free(X3); free(K3); free(X4); free(K4);
}

/* ccn_plan_get_evs: a cube's 8 corners are capped with the default cap (their curvature a
 * number), refined with cap = REFINE (their curvature NaN); a valence-5 fan with spoke ratio 4.2
 * gets no cap. */
static int32_t ev_statuses(const ccn_cage *cage, ccn_cap cap, int levels, int32_t *st, int32_t *finite) {
    ccn_sizes sz;
    ccn_error err;
    ccn_plan *p = make_plan(cage, levels, cap, &sz);
    if (!p) return -1;
    int32_t n = 0, vs[64];
    ccn_plan_get_evs(p, &n, NULL, NULL);
    if (n > 64) { ccn_plan_destroy(p); return -1; }
    ccn_plan_get_evs(p, &n, vs, st);
    double *X = malloc(sizeof(double) * 3 * (size_t)sz.num_verts), *K = malloc(sizeof(double) * 2 * (size_t)sz.num_verts);
    ccn_limit_mesh out;
    memset(&out, 0, sizeof out);
    out.positions = X;
    out.curvatures = K;
    ccn_plan_evaluate(p, NULL, &out, &err);
    for (int32_t i = 0; i < n; i++) finite[i] = isfinite(K[2 * vs[i]]);
    free(X); free(K);
    ccn_plan_destroy(p);
    return n;
}

static void test_ev_status(void) {
    double P[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
    int32_t fsz[6] = {4, 4, 4, 4, 4, 4};
    int32_t fv[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    ccn_cage cube = {8, 6, 0, P, fsz, fv, NULL, NULL, NULL, NULL};
    int32_t st[64], fin[64];
    int32_t n = ev_statuses(&cube, CCN_CAP_GUIDED_BI5, 3, st, fin);
    CHECK(n == 8, "cube: %d EVs, expected 8", (int)n);
    for (int32_t i = 0; i < n; i++)
        CHECK(st[i] == CCN_EV_CAPPED && fin[i], "cube EV %d: status %d, curvature %s", (int)i,
              (int)st[i], fin[i] ? "a number" : "NaN");
    n = ev_statuses(&cube, CCN_CAP_REFINE, 3, st, fin);
    CHECK(n == 8, "cube, refine: %d EVs", (int)n);
    for (int32_t i = 0; i < n; i++)
        CHECK(st[i] == CCN_EV_REFINED && !fin[i], "cube (refine) EV %d: status %d", (int)i, (int)st[i]);
    CHECK(ccn_plan_get_evs(NULL, &n, NULL, NULL) == CCN_ERR_ARGUMENT, "NULL plan accepted");
}

/* ---- an open grid: the B-spline of the mirror extension ------------------------------------ */

/* The blossom f(x1, x2, x3) of segment [t_i, t_i+1] of an open curve whose control points C[m]
 * (dim each) are given for m = -1 .. n (ghosts at both ends) and whose knots t[k + 2] = t_k,
 * k = -2 .. n + 1. */
static void open_blossom(const double *C, int dim, const double *t, int i, const double x[3],
                         double *out) {
    double P[4][12], T[8] = {0};
    for (int a = 1; a < 7; a++) T[a] = t[i - 3 + a + 2]; /* t_{i-2} .. t_{i+3}: the ones used */
    for (int a = 0; a < 4; a++)
        for (int c = 0; c < dim; c++) P[a][c] = C[dim * (i - 1 + a + 1) + c];
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3 - r; a++) {
            double lo = T[a + 1 + r], hi = T[a + 4], w = (x[r] - lo) / (hi - lo);
            for (int c = 0; c < dim; c++) P[a][c] = (1 - w) * P[a][c] + w * P[a + 1][c];
        }
    for (int c = 0; c < dim; c++) out[c] = P[0][c];
}

static void open_derivs(const double *C, int dim, const double *t, int i, double u, double *f,
                        double *f1, double *f2) {
    double a[12], b[12], c[12], e[12];
    double x0[3] = {u, u, u}, x1[3] = {u, u, u + 1}, x2[3] = {u, u + 1, u + 1}, x3[3] = {u, u + 1, u};
    open_blossom(C, dim, t, i, x0, a);
    open_blossom(C, dim, t, i, x1, b);
    open_blossom(C, dim, t, i, x2, c);
    open_blossom(C, dim, t, i, x3, e);
    for (int k = 0; k < dim; k++) {
        f[k] = a[k];
        f1[k] = 3 * (b[k] - a[k]);
        f2[k] = 6 * (c[k] - b[k] - e[k] + a[k]);
    }
}

/* Knots of an open sequence of intervals d[0..n-2] between n points, extended by the mirror:
 * t[k + 2] = t_k for k = -2 .. n + 1, the intervals beyond each end those inside it in mirror
 * order (D_-1 = D_0, D_-2 = D_1; likewise at the far end), as the boundary's ghost points have. */
static void open_knots(const double *d, int n, double *t) {
    t[2] = 0;
    for (int k = 1; k < n; k++) t[k + 2] = t[k + 1] + d[k - 1];
    t[1] = t[2] - d[0];
    t[0] = t[1] - d[n > 2 ? 1 : 0];
    t[n + 2] = t[n + 1] + d[n - 2];
    t[n + 3] = t[n + 2] + d[n > 2 ? n - 3 : 0];
}

/* An nu x nv grid of control points (random heights, random intervals on its rings), corners
 * pinned (Blender's Keep Corners): its limit is the tensor B-spline of the net extended by
 * mirror ghosts (P_-1 = 2 P_0 - P_1 on each side, corners mirrored twice); the curvature at
 * every output vertex, boundaries included, against it. */
static void check_open_grid(int nu, int nv, int levels, double *worst) {
    double *du = malloc(sizeof(double) * (size_t)nu), *dv = malloc(sizeof(double) * (size_t)nv);
    for (int i = 0; i + 1 < nu; i++) du[i] = exp(1.2 * (2 * tl_rand01() - 1));
    for (int j = 0; j + 1 < nv; j++) dv[j] = exp(1.2 * (2 * tl_rand01() - 1));
    int NU = nu + 2, NV = nv + 2; /* with ghosts: index (i + 1, j + 1) */
    double *G = malloc(sizeof(double) * 3 * (size_t)NU * NV), *P = malloc(sizeof(double) * 3 * (size_t)nu * nv);
#define GP(i, j) (G + 3 * ((size_t)((j) + 1) * NU + (size_t)((i) + 1)))
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            double *q = GP(i, j), *r = P + 3 * ((size_t)j * nu + i);
            q[0] = i + 0.2 * (tl_rand01() - 0.5);
            q[1] = j + 0.2 * (tl_rand01() - 0.5);
            q[2] = 0.8 * (tl_rand01() - 0.5);
            memcpy(r, q, sizeof(double) * 3);
        }
    for (int j = 0; j < nv; j++)
        for (int c = 0; c < 3; c++) {
            GP(-1, j)[c] = 2 * GP(0, j)[c] - GP(1, j)[c];
            GP(nu, j)[c] = 2 * GP(nu - 1, j)[c] - GP(nu - 2, j)[c];
        }
    for (int i = -1; i <= nu; i++)
        for (int c = 0; c < 3; c++) {
            GP(i, -1)[c] = 2 * GP(i, 0)[c] - GP(i, 1)[c];
            GP(i, nv)[c] = 2 * GP(i, nv - 1)[c] - GP(i, nv - 2)[c];
        }
    double *tu = malloc(sizeof(double) * (size_t)(nu + 4)), *tv = malloc(sizeof(double) * (size_t)(nv + 4));
    open_knots(du, nu, tu);
    open_knots(dv, nv, tv);
    /* the cage */
    int nf = (nu - 1) * (nv - 1), ne = 0;
    int32_t *fsz = malloc(sizeof(int32_t) * (size_t)nf), *fv = malloc(sizeof(int32_t) * 4 * (size_t)nf);
    int32_t *ev = malloc(sizeof(int32_t) * 4 * (size_t)nu * nv);
    double *kn = malloc(sizeof(double) * 2 * (size_t)nu * nv);
    for (int j = 0; j + 1 < nv; j++)
        for (int i = 0; i + 1 < nu; i++) {
            int f = j * (nu - 1) + i;
            fsz[f] = 4;
            fv[4 * f] = j * nu + i, fv[4 * f + 1] = j * nu + i + 1;
            fv[4 * f + 2] = (j + 1) * nu + i + 1, fv[4 * f + 3] = (j + 1) * nu + i;
        }
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            if (i + 1 < nu) ev[2 * ne] = j * nu + i, ev[2 * ne + 1] = j * nu + i + 1, kn[ne++] = du[i];
            if (j + 1 < nv) ev[2 * ne] = j * nu + i, ev[2 * ne + 1] = (j + 1) * nu + i, kn[ne++] = dv[j];
        }
    ccn_cage cage = {nu * nv, nf, ne, P, fsz, fv, ev, kn, NULL, NULL};
    ccn_sizes sz;
    ccn_error err;
    plan_corners = CCN_CORNERS_PINNED; /* corners pinned: the mirror extension everywhere */
    ccn_plan *p = make_plan(&cage, levels, CCN_CAP_GUIDED_BI5, &sz);
    plan_corners = CCN_CORNERS_SMOOTH;
    double *X = malloc(sizeof(double) * 3 * (size_t)sz.num_verts), *K = malloc(sizeof(double) * 2 * (size_t)sz.num_verts);
    ccn_limit_mesh out;
    memset(&out, 0, sizeof out);
    out.positions = X;
    out.curvatures = K;
    CHECK(p && ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK, "evaluate");
    /* the oracle on the output's parameter grid, each output vertex matched by position */
    int S = 1 << levels, nu2 = (nu - 1) * S + 1, nv2 = (nv - 1) * S + 1;
    double (*ref)[5] = malloc(sizeof(double[5]) * (size_t)nu2 * nv2), kmax = 0, pos_err = 0;
    double *R = malloc(sizeof(double) * 9 * (size_t)NV);
    for (int a = 0; a < nu2; a++) {
        int i = a / S < nu - 1 ? a / S : nu - 2;
        double u = tu[i + 2] + (a - i * S) * (tu[i + 3] - tu[i + 2]) / S;
        for (int r = -1; r <= nv; r++) { /* each row of the extended net as a curve in u */
            double f[3], f1[3], f2[3], row[3 * 64];
            for (int m = -1; m <= nu; m++) memcpy(row + 3 * (m + 1), GP(m, r), sizeof(double) * 3);
            open_derivs(row, 3, tu, i, u, f, f1, f2);
            memcpy(R + 9 * (r + 1), f, sizeof f);
            memcpy(R + 9 * (r + 1) + 3, f1, sizeof f1);
            memcpy(R + 9 * (r + 1) + 6, f2, sizeof f2);
        }
        for (int b = 0; b < nv2; b++) {
            int j = b / S < nv - 1 ? b / S : nv - 2;
            double v = tv[j + 2] + (b - j * S) * (tv[j + 3] - tv[j + 2]) / S;
            double f[9], f1[9], f2[9], D[6][3], k1, k2, dir[3];
            open_derivs(R, 9, tv, j, v, f, f1, f2);
            for (int c = 0; c < 3; c++) {
                D[0][c] = f[c], D[1][c] = f[3 + c], D[2][c] = f1[c];
                D[3][c] = f[6 + c], D[4][c] = f1[3 + c], D[5][c] = f2[c];
            }
            oracle_curvature(D, &k1, &k2, dir);
            double *q = ref[b * nu2 + a];
            memcpy(q, D[0], sizeof(double) * 3);
            q[3] = k1, q[4] = k2;
            kmax = fmax(kmax, fmax(fabs(k1), fabs(k2)));
        }
    }
    int compared = 0, flagged = 0;
    double wk = 0;
    for (int32_t o = 0; p && o < sz.num_verts; o++) {
        double dist;
        int best = nearest(&ref[0][0], 5, nu2 * nv2, X + 3 * o, &dist);
        pos_err = fmax(pos_err, dist);
        if (!isfinite(K[2 * o])) { flagged++; continue; }
        wk = fmax(wk, fmax(fabs(K[2 * o] - ref[best][3]), fabs(K[2 * o + 1] - ref[best][4])) / kmax);
        compared++;
    }
    CHECK(pos_err < 1e-9, "open grid: positions off the mirror-extended B-spline by %.3g", pos_err);
    CHECK(wk <= 1e-8, "open grid %dx%d level %d: curvature off by %.3g of max |k|", nu, nv, levels, wk);
    CHECK(flagged <= 4 && compared + flagged == sz.num_verts, "open grid: %d flagged (the 4 "
          "corners at most), %d compared", flagged, compared);
    *worst = fmax(*worst, wk);
#undef GP
    free(ref); free(R); free(X); free(K); free(G); free(P); free(du); free(dv); free(tu); free(tv);
    free(fsz); free(fv); free(ev); free(kn);
    if (p) ccn_plan_destroy(p);
}

static void test_open_grid_equals_bspline(void) {
    double worst = 0;
    for (int rep = 0; rep < 3; rep++)
        for (int levels = 1; levels <= 3; levels++) check_open_grid(5 + rep, 4 + 2 * rep, levels, &worst);
    printf("# 9 random open grids (boundaries, intervals up to e^2.4 : 1), levels 1-3: principal "
           "curvatures within %.3g of max |k| of the mirror-extended tensor B-spline\n", worst);
}

/* Asking for curvatures computes them in the same pass as the positions (the rows' second
 * derivative weights beside their first): positions, normals and corner normals must be those
 * of an evaluation without them, to the bit, and every evaluation the same numbers; a
 * changed-only evaluation after an interval edit (which evaluates in full when curvatures are
 * asked) equals a new plan's. A cube (its corners capped or refined) with non-uniform rings
 * and a creased edge. */
static void test_curvature_leaves_the_surface_alone(void) {
    static const double P[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                 -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
    static const int32_t fsz[6] = {4, 4, 4, 4, 4, 4};
    static const int32_t fv[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4,
                                   1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    static const int32_t ev[8] = {0, 1, 1, 2, 4, 5, 0, 4};
    double kn[4] = {2.5, 1, 1.75, 1}, cr[4] = {0, 0, 0, 2.5};
    for (int variant = 0; variant < 4; variant++) {
        ccn_cage cage = {8, 6, 4, P, fsz, fv, ev, kn, variant & 1 ? cr : NULL, NULL};
        ccn_cap cap = variant & 2 ? CCN_CAP_REFINE : CCN_CAP_GUIDED_BI5;
        ccn_sizes sz;
        ccn_error err;
        ccn_plan *p = make_plan(&cage, 3, cap, &sz);
        if (!p) return;
        size_t n = (size_t)sz.num_verts, nc = 4 * (size_t)sz.num_faces;
        double *X0 = malloc(sizeof(double) * 3 * n), *N0 = malloc(sizeof(double) * 3 * n);
        double *C0 = malloc(sizeof(double) * 3 * nc), *X1 = malloc(sizeof(double) * 3 * n);
        double *N1 = malloc(sizeof(double) * 3 * n), *C1 = malloc(sizeof(double) * 3 * nc);
        double *K1 = malloc(sizeof(double) * 2 * n), *K2 = malloc(sizeof(double) * 2 * n);
        double *D1 = malloc(sizeof(double) * 3 * n);
        ccn_limit_mesh plain = {.positions = X0, .normals = N0, .corner_normals = C0};
        ccn_limit_mesh curv = {.positions = X1, .normals = N1, .corner_normals = C1,
                               .curvatures = K1, .curvature_dirs = D1};
        CHECK(ccn_plan_evaluate(p, NULL, &curv, &err) == CCN_OK, "evaluate: %s", err.message);
        CHECK(ccn_plan_evaluate(p, NULL, &plain, &err) == CCN_OK, "evaluate: %s", err.message);
        CHECK(!memcmp(X0, X1, sizeof(double) * 3 * n) && !memcmp(N0, N1, sizeof(double) * 3 * n) &&
              !memcmp(C0, C1, sizeof(double) * 3 * nc),
              "variant %d: positions or normals change when curvatures are asked", variant);
        curv.curvatures = K2;
        CHECK(ccn_plan_evaluate(p, NULL, &curv, &err) == CCN_OK, "evaluate: %s", err.message);
        int32_t finite = 0;
        for (size_t i = 0; i < 2 * n; i++) {
            finite += isfinite(K1[i]) != 0;
            CHECK(K1[i] == K2[i] || (isnan(K1[i]) && isnan(K2[i])), "variant %d: curvature %d differs "
                  "between evaluations", variant, (int)(i / 2));
        }
        CHECK(finite > (int32_t)n, "variant %d: %d of %d curvatures are numbers", variant, (int)finite,
              (int)(2 * n));
        /* an interval edit: the plan made with options.previous, evaluated changed-only with
         * curvatures, against a new plan's full evaluation */
        kn[0] = 1.25;
        ccn_options o = {0};
        o.levels = 3, o.cap = cap, o.previous = p;
        ccn_plan *q = NULL, *r = make_plan(&cage, 3, cap, &sz);
        CHECK(ccn_plan_create(&cage, &o, &q, &err) == CCN_OK, "previous: %s", err.message);
        p = NULL; /* destroyed by the call */
        if (q && r) {
            double *K3 = malloc(sizeof(double) * 2 * n);
            curv.curvatures = K3;
            CHECK(ccn_plan_evaluate(r, NULL, &curv, &err) == CCN_OK, "evaluate: %s", err.message);
            curv.curvatures = K2;
            CHECK(ccn_plan_evaluate_changed(q, NULL, &curv, &err) == CCN_OK, "changed: %s", err.message);
            for (size_t i = 0; i < 2 * n; i++)
                CHECK(K3[i] == K2[i] || (isnan(K3[i]) && isnan(K2[i])), "variant %d: curvature %d of "
                      "the changed-only evaluation differs from a new plan's", variant, (int)(i / 2));
            free(K3);
        }
        kn[0] = 2.5;
        ccn_plan_destroy(q);
        ccn_plan_destroy(r);
        ccn_plan_destroy(p);
        free(X0); free(N0); free(C0); free(X1); free(N1); free(C1); free(K1); free(K2); free(D1);
    }
}

int main(void) {
    RUN(test_torus_equals_bspline);
    RUN(test_open_grid_equals_bspline);
    RUN(test_flags);
    RUN(test_ev_status);
    RUN(test_curvature_leaves_the_surface_alone);
    return TEST_SUMMARY();
}
