/* The Suzanne-like cage (tests/data/suzanne.obj: Blender 3.4's
 * primitive_monkey_add, its valence-2 vertex dissolved) with five edge rings through the
 * forehead set to 3 (the five longest rings with an edge in the forehead box x in (-0.45, 0.45),
 * y < -0.55, z in (0.45, 0.95): 41, 41, 36, 36 and 27 edges). At levels 3, 4, 5 the normal jump
 * across every output edge (angle between its end normals) is measured, over the whole surface
 * and over the forehead, with the exact normals and with "fast" normals (the sum of the faces'
 * normals, what the add-on's Fast mode shows): it shrinks level by level (ratio <= 0.7 each
 * step), i.e. the surface is crease-free there; the saw-tooth highlight boundary the issue saw
 * is a wave of the limit surface at the scale of the cage faces (README "Design notes"). */
#include "testlib.h"

#include "ccnurbs.h"

static int32_t find(int32_t *p, int32_t x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
}

typedef struct { int32_t ne; int32_t *ev; double *kn; } knots_t;

/* Unique edges, rings (opposite quad edges), the five forehead rings at 3. */
static void forehead_rings(const ccn_cage *cg, knots_t *k, int sizes[5]) {
    int32_t nf = cg->num_faces, nc = 0;
    for (int32_t f = 0; f < nf; f++) nc += cg->face_sizes[f];
    int32_t *fe = malloc(sizeof(int32_t) * nc);
    k->ev = malloc(sizeof(int32_t) * 2 * nc);
    k->ne = 0;
    for (int32_t f = 0, c = 0; f < nf; c += cg->face_sizes[f], f++)
        for (int j = 0; j < cg->face_sizes[f]; j++) {
            int32_t a = cg->face_verts[c + j], b = cg->face_verts[c + (j + 1) % cg->face_sizes[f]], e = -1;
            for (int32_t x = 0; x < k->ne && e < 0; x++)
                if ((k->ev[2 * x] == a && k->ev[2 * x + 1] == b) || (k->ev[2 * x] == b && k->ev[2 * x + 1] == a)) e = x;
            if (e < 0) { e = k->ne++; k->ev[2 * e] = a; k->ev[2 * e + 1] = b; }
            fe[c + j] = e;
        }
    int32_t ne = k->ne, *par = malloc(sizeof(int32_t) * ne), *sz = calloc(ne, sizeof(int32_t));
    int *fore = calloc(ne, sizeof(int));
    for (int32_t e = 0; e < ne; e++) par[e] = e;
    for (int32_t f = 0, c = 0; f < nf; c += cg->face_sizes[f], f++)
        if (cg->face_sizes[f] == 4)
            for (int j = 0; j < 2; j++) par[find(par, fe[c + j])] = find(par, fe[c + j + 2]);
    for (int32_t e = 0; e < ne; e++) {
        const double *a = cg->positions + 3 * k->ev[2 * e], *b = cg->positions + 3 * k->ev[2 * e + 1];
        double m[3] = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
        sz[find(par, e)]++;
        if (m[1] < -0.55 && m[2] > 0.45 && m[2] < 0.95 && fabs(m[0]) < 0.45) fore[find(par, e)] = 1;
    }
    int32_t pick[5];
    for (int q = 0; q < 5; q++) {
        int32_t best = -1;
        for (int32_t r = 0; r < ne; r++) {
            int used = 0;
            for (int i = 0; i < q; i++) used |= pick[i] == r;
            if (par[r] == r && fore[r] && !used && (best < 0 || sz[r] > sz[best])) best = r;
        }
        pick[q] = best;
        sizes[q] = best >= 0 ? sz[best] : 0;
    }
    k->kn = malloc(sizeof(double) * ne);
    for (int32_t e = 0; e < ne; e++) {
        k->kn[e] = 1;
        for (int i = 0; i < 5; i++)
            if (find(par, e) == pick[i]) k->kn[e] = 3;
    }
    free(fe); free(par); free(sz); free(fore);
}

/* Largest end-normal angle over the output edges (forehead: edge midpoint in the box). */
static void jumps(const double *x, const double *n, const int32_t *q, int32_t nf, double *all, double *fore) {
    *all = *fore = 0;
    for (int32_t f = 0; f < nf; f++)
        for (int j = 0; j < 4; j++) {
            int32_t a = q[4 * f + j], b = q[4 * f + (j + 1) % 4];
            double c = n[3 * a] * n[3 * b] + n[3 * a + 1] * n[3 * b + 1] + n[3 * a + 2] * n[3 * b + 2];
            double an = acos(c > 1 ? 1 : c < -1 ? -1 : c);
            double mx = (x[3 * a] + x[3 * b]) / 2, my = (x[3 * a + 1] + x[3 * b + 1]) / 2, mz = (x[3 * a + 2] + x[3 * b + 2]) / 2;
            *all = fmax(*all, an);
            if (fabs(mx) < 0.5 && my < -0.45 && mz > 0.5 && mz < 1.0) *fore = fmax(*fore, an);
        }
}

static void fast_normals(const double *x, const int32_t *q, int32_t nv, int32_t nf, double *n) {
    memset(n, 0, sizeof(double) * 3 * nv);
    for (int32_t f = 0; f < nf; f++) {
        const double *A = x + 3 * q[4 * f], *B = x + 3 * q[4 * f + 1], *C = x + 3 * q[4 * f + 2], *D = x + 3 * q[4 * f + 3];
        double e1[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]}, e2[3] = {D[0] - B[0], D[1] - B[1], D[2] - B[2]};
        double o[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 3; k++) n[3 * q[4 * f + j] + k] += o[k];
    }
    for (int32_t v = 0; v < nv; v++) {
        double l = sqrt(n[3 * v] * n[3 * v] + n[3 * v + 1] * n[3 * v + 1] + n[3 * v + 2] * n[3 * v + 2]);
        for (int k = 0; k < 3; k++) n[3 * v + k] /= l;
    }
}

static void test_forehead(void) {
    size_t len;
    char *t = tl_slurp("tests/data/suzanne.obj", &len);
    CHECK(t != NULL, "tests/data/suzanne.obj");
    if (!t) return;
    ccn_obj *obj = NULL;
    ccn_error err;
    CHECK(ccn_obj_parse(t, len, &obj, &err) == CCN_OK, "%s", err.message);
    free(t);
    if (!obj) return;
    ccn_cage cg;
    ccn_obj_get_cage(obj, &cg);
    knots_t k;
    int sizes[5];
    forehead_rings(&cg, &k, sizes);
    CHECK(sizes[0] == 41 && sizes[1] == 41 && sizes[2] == 36 && sizes[3] == 36 && sizes[4] == 27,
          "forehead rings %d %d %d %d %d", sizes[0], sizes[1], sizes[2], sizes[3], sizes[4]);
    cg.num_edges = k.ne, cg.edge_verts = k.ev, cg.edge_knots = k.kn;
    const char *sn[3] = {"eigen", "nurss", "cc"};
    int small = getenv("CCN_TEST_SMALL") != NULL; /* the sanitizer run: eigen only */
    for (int sc = 0; sc < (small ? 1 : 3); sc++) {
        double J[3][2][2]; /* level, exact/fast, all/forehead */
        for (int L = 3; L <= 5; L++) {
            ccn_options o = {.scheme = sc, .levels = L, .threads = 2};
            ccn_plan *p = NULL;
            CHECK(ccn_plan_create(&cg, &o, &p, &err) == CCN_OK, "%s", err.message);
            if (!p) return;
            ccn_sizes s;
            ccn_plan_get_sizes(p, &s);
            double *x = malloc(sizeof(double) * 3 * s.num_verts), *n = malloc(sizeof(double) * 3 * s.num_verts);
            int32_t *q = malloc(sizeof(int32_t) * 4 * s.num_faces);
            ccn_limit_mesh lm = {.positions = x, .normals = n, .face_verts = q};
            CHECK(ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK, "%s", err.message);
            jumps(x, n, q, s.num_faces, &J[L - 3][0][0], &J[L - 3][0][1]);
            fast_normals(x, q, s.num_verts, s.num_faces, n);
            jumps(x, n, q, s.num_faces, &J[L - 3][1][0], &J[L - 3][1][1]);
            free(x); free(n); free(q);
            ccn_plan_destroy(p);
        }
        for (int m = 0; m < 2; m++) {
            printf("# %s, %s normals: max jump over all edges %.3f %.3f %.3f, forehead %.3f %.3f %.3f rad (levels 3, 4, 5)\n",
                   sn[sc], m ? "fast" : "exact", J[0][m][0], J[1][m][0], J[2][m][0], J[0][m][1], J[1][m][1], J[2][m][1]);
            for (int L = 0; L < 2; L++)
                for (int r = 0; r < 2; r++)
                    CHECK(J[L + 1][m][r] <= 0.7 * J[L][m][r], "%s %s %s: jump %.3f at level %d -> %.3f", sn[sc],
                          m ? "fast" : "exact", r ? "forehead" : "all", J[L][m][r], L + 3, J[L + 1][m][r]);
        }
    }
    free(k.ev); free(k.kn);
    ccn_obj_destroy(obj);
}

int main(void) {
    RUN(test_forehead);
    return TEST_SUMMARY();
}
