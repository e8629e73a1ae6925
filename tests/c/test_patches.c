/* Bicubic patches of regular faces vs de Boor evaluation of the tensor-product B-spline,
 * written here independently (<= 1e-12 relative at random parameters). */
#include "ccnurbs.h"
#include "surface/patches.h"
#include "testlib.h"

/* Periodic knot vector from intervals d[0..n-1]: t[k] for k in [-8, n+8]. */
static double knot(const double *d, int n, int k) {
    double t = 0;
    if (k >= 0) for (int i = 0; i < k; i++) t += d[i % n];
    else for (int i = -1; i >= k; i--) t -= d[((i % n) + n) % n];
    return t;
}

/* de Boor: curve value at t in span [t_j, t_{j+1}] from control points P_{j-1}..P_{j+2}
 * (P_i has blossom (t_{i-1}, t_i, t_{i+1})). coef[4] = weights on P_{j-1}..P_{j+2}. */
static void deboor_weights(const double *d, int n, int j, double t, double coef[4]) {
    /* work on unit vectors: 4 control points, 3 levels of affine combinations */
    double w[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    for (int r = 1; r <= 3; r++)
        for (int i = 3; i >= r; i--) {
            /* point i (control index j-1+i) at level r: interpolate between i-1 and i */
            int ci = j - 1 + i;
            double lo = knot(d, n, ci - 2), hi = knot(d, n, ci + 2 - r);
            double a = (t - lo) / (hi - lo);
            for (int k = 0; k < 4; k++) w[i][k] = (1 - a) * w[i - 1][k] + a * w[i][k];
        }
    for (int k = 0; k < 4; k++) coef[k] = w[3][k];
}

#define NU 6
#define NV 5
static double du_[NU], dv_[NV], P_[NU][NV][3];
static double odu_[NU], odv_[NV]; /* the oracle's own copy of the knots */

static void tensor_eval(double s, double t, double out[3]) {
    /* locate spans */
    int i = 0, j = 0;
    while (knot(odu_, NU, i + 1) <= s && i < NU - 1) i++;
    while (knot(odv_, NV, j + 1) <= t && j < NV - 1) j++;
    double cu[4], cv[4];
    deboor_weights(odu_, NU, i, s, cu);
    deboor_weights(odv_, NV, j, t, cv);
    out[0] = out[1] = out[2] = 0;
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) {
            const double *p = P_[((i - 1 + a) % NU + NU) % NU][((j - 1 + b) % NV + NV) % NV];
            for (int k = 0; k < 3; k++) out[k] += cu[a] * cv[b] * p[k];
        }
}

/* Maps (u,v) of level-l descendant face to level-0 parameters: walk the corner chain. */
typedef struct { double c[4][2]; } quad_param;

static void child_param(const quad_param *q, int j, quad_param *out) {
    const double *a = q->c[j], *b = q->c[(j + 1) % 4], *cc = q->c[(j + 2) % 4], *p = q->c[(j + 3) % 4];
    double ctr[2] = {(a[0] + b[0] + cc[0] + p[0]) / 4, (a[1] + b[1] + cc[1] + p[1]) / 4};
    double mb[2] = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2}, mp[2] = {(a[0] + p[0]) / 2, (a[1] + p[1]) / 2};
    memcpy(out->c[0], a, sizeof(double) * 2);
    memcpy(out->c[1], mb, sizeof mb);
    memcpy(out->c[2], ctr, sizeof ctr);
    memcpy(out->c[3], mp, sizeof mp);
}

static void check_level(int levels, double *maxerr) {
    int nv = NU * NV;
    double pos[3 * NU * NV];
    int32_t fs[NU * NV], fv[4 * NU * NV], ev[2 * 2 * NU * NV];
    double kn[2 * NU * NV];
    int ne = 0;
    for (int i = 0; i < NU; i++)
        for (int j = 0; j < NV; j++) {
            int v = i * NV + j;
            memcpy(pos + 3 * v, P_[i][j], sizeof(double) * 3);
            int f = v;
            fs[f] = 4;
            fv[4 * f + 0] = v;
            fv[4 * f + 1] = ((i + 1) % NU) * NV + j;
            fv[4 * f + 2] = ((i + 1) % NU) * NV + (j + 1) % NV;
            fv[4 * f + 3] = i * NV + (j + 1) % NV;
            ev[2 * ne] = v; ev[2 * ne + 1] = fv[4 * f + 1]; kn[ne++] = du_[i];
            ev[2 * ne] = v; ev[2 * ne + 1] = fv[4 * f + 3]; kn[ne++] = dv_[j];
        }
    ccn_cage c = {0};
    c.num_verts = nv; c.num_faces = nv; c.positions = pos; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = ne; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_OK, "%s", err.message);
    ccn_options o = {0};
    CHECK(ccn_refine(m, levels, &o, &r, &err) == CCN_OK, "%s", err.message);
    if (!m || !r) { ccn_mesh_destroy(m); ccn_mesh_destroy(r); return; }
    ccn_mesh_info in;
    ccn_mesh_get_info(r, &in);
    double size = 0;
    for (int k = 0; k < 3 * nv; k++) size = fabs(pos[k]) > size ? fabs(pos[k]) : size;
    int nfaces = in.num_faces, checked = 0;
    for (int f = 0; f < nfaces; f++) {
        /* level-0 face and corner chain of f: face index at level l+1 = half-edge at level l */
        int chain[8], g = f;
        for (int l = levels; l > 0; l--) { chain[l - 1] = g % 4; g /= 4; }
        quad_param q = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}}, q2;
        for (int l = 0; l < levels; l++) { child_param(&q, chain[l], &q2); q = q2; }
        int i0 = g / NV, j0 = g % NV;
        double bez[4][4][3];
        CHECK(ccn__bicubic_patch(r, f, 0, 1, bez) == 1, "face %d regular", f);
        for (int s = 0; s < 3; s++) {
            double u = tl_rand01(), v = tl_rand01(), x[3], dx[3], dy[3], y[3];
            ccn__bezier_eval(&bez[0][0][0], 3, u, v, x, dx, dy);
            /* bilinear map of the descendant quad into the level-0 face's unit square */
            double a = (1 - u) * (1 - v) * q.c[0][0] + u * (1 - v) * q.c[1][0] + u * v * q.c[2][0] + (1 - u) * v * q.c[3][0];
            double b = (1 - u) * (1 - v) * q.c[0][1] + u * (1 - v) * q.c[1][1] + u * v * q.c[2][1] + (1 - u) * v * q.c[3][1];
            double sp = knot(odu_, NU, i0) + a * odu_[i0], tp = knot(odv_, NV, j0) + b * odv_[j0];
            tensor_eval(sp, tp, y);
            for (int k = 0; k < 3; k++) {
                double e = fabs(x[k] - y[k]) / size;
                if (!(e <= *maxerr)) *maxerr = e; /* NaN propagates as a failure */
            }
            checked++;
        }
    }
    CHECK(checked == 3 * nfaces, "all faces checked");
    ccn_mesh_destroy(m);
    ccn_mesh_destroy(r);
}

static void test_torus_patches_vs_deboor(void) {
    double worst = 0;
    for (int seed = 0; seed < 4; seed++) {
        for (int i = 0; i < NU; i++) du_[i] = 0.05 + 19.95 * tl_rand01();
        for (int j = 0; j < NV; j++) dv_[j] = 0.05 + 19.95 * tl_rand01();
        for (int i = 0; i < NU; i++)
            for (int j = 0; j < NV; j++)
                for (int k = 0; k < 3; k++) P_[i][j][k] = 10 * tl_rand01() - 5;
        memcpy(odu_, du_, sizeof du_);
        memcpy(odv_, dv_, sizeof dv_);
        for (int levels = 0; levels <= 2; levels++) {
            double e = 0;
            check_level(levels, &e);
            worst = e > worst ? e : worst;
            CHECK(e <= 1e-12, "seed %d level %d: max rel error %g", seed, levels, e);
        }
    }
    printf("  torus bicubic patches vs de Boor: max rel error %.3g\n", worst);
}

/* The comparison must be able to fail: an oracle with one different knot disagrees. */
static void test_oracle_detects_wrong_knots(void) {
    for (int i = 0; i < NU; i++) du_[i] = 0.5 + tl_rand01();
    for (int j = 0; j < NV; j++) dv_[j] = 0.5 + tl_rand01();
    for (int i = 0; i < NU; i++)
        for (int j = 0; j < NV; j++)
            for (int k = 0; k < 3; k++) P_[i][j][k] = 10 * tl_rand01() - 5;
    memcpy(odu_, du_, sizeof du_);
    memcpy(odv_, dv_, sizeof dv_);
    odu_[2] *= 1.5;
    double e = 0;
    check_level(1, &e);
    CHECK(e > 1e-4, "a wrong knot must show: error only %g", e);
}

int main(void) {
    RUN(test_torus_patches_vs_deboor);
    RUN(test_oracle_detects_wrong_knots);
    return TEST_SUMMARY();
}
