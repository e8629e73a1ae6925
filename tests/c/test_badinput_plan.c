/* The bad-input table through the plan API (ccn_plan_create / _sizes / _evaluate): the same
 * rows as test_badinput.c. Errors: exact status and message fragment, no plan. Accepted
 * inputs: a plan at level 2 for every scheme, cap and corner rule; every position and normal
 * finite, normals of unit length, indices in range, sizes as documented. */
#include "ccnurbs.h"
#include "testlib.h"
#include "badinput_cages.h"

#include <float.h>
#include <sys/resource.h>
#include <time.h>

static void expect_plan_err(const ccn_cage *c, const ccn_options *o, ccn_status st,
                            const char *needle) {
    ccn_error err;
    memset(&err, 0x5A, sizeof err);
    ccn_plan *p = (ccn_plan *)&err;
    ccn_status got = ccn_plan_create(c, o, &p, &err);
    CHECK(memchr(err.message, '\0', sizeof err.message) != NULL, "message not terminated");
    CHECK(got == st, "status %d (%s), expected %d: %s", got, ccn_status_name(got), st, err.message);
    CHECK(err.status == got, "err.status %d", err.status);
    CHECK(p == NULL, "no plan on error");
    CHECK(strstr(err.message, needle) != NULL, "message '%s' lacks '%s'", err.message, needle);
    if (got == CCN_OK) ccn_plan_destroy(p);
}

/* Evaluates a plan with every output; checks finiteness, unit normals, index ranges. */
static int eval_check(ccn_plan *p, const ccn_cage *c, const double *positions, const char *what) {
    ccn_sizes z;
    ccn_plan_get_sizes(p, &z);
    ccn_plan_stats z_st;
    ccn_plan_get_stats(p, &z_st);
    CHECK(z.num_cage_verts == c->num_verts, "%s: num_cage_verts %d", what, z.num_cage_verts);
    double *P = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
    double *N = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
    int32_t *fv = malloc(sizeof(int32_t) * 4 * (size_t)z.num_faces);
    int32_t *fo = malloc(sizeof(int32_t) * (size_t)z.num_faces);
    ccn_limit_mesh out = {.positions = P, .normals = N, .face_verts = fv, .face_origin = fo};
    ccn_error err;
    ccn_status st = ccn_plan_evaluate(p, positions, &out, &err);
    CHECK(st == CCN_OK, "%s: evaluate: %s", what, err.message);
    int ok = st == CCN_OK;
    if (ok) {
        int badp = 0, badn = 0, badi = 0;
        for (int64_t i = 0; i < 3 * (int64_t)z.num_verts; i++) badp += !isfinite(P[i]);
        for (int64_t v = 0; v < z.num_verts; v++) {
            const double *n = N + 3 * v;
            double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            badn += !(fabs(l - 1) < 1e-9);
        }
        for (int64_t i = 0; i < 4 * (int64_t)z.num_faces; i++)
            badi += fv[i] < 0 || fv[i] >= z.num_verts;
        for (int64_t f = 0; f < z.num_faces; f++) badi += fo[f] < 0 || fo[f] >= c->num_faces;
        CHECK(badp == 0 && badn == 0 && badi == 0,
              "%s: %d non-finite coordinates, %d bad normals, %d bad indices", what, badp, badn,
              badi);
        ok = badp == 0 && badn == 0 && badi == 0;
    }
    free(P); free(N); free(fv); free(fo);
    return ok;
}

/* A plan at `levels` for every scheme x cap x corner rule: created and evaluated cleanly. */
static void accept_plan(const ccn_cage *c, int32_t levels) {
    for (int sc = 0; sc < 3; sc++)
        for (int cap = 0; cap < 2; cap++)
            for (int corners = 0; corners < 2; corners++) {
                ccn_options o = {0};
                o.scheme = (ccn_scheme)sc;
                o.cap = (ccn_cap)cap;
                o.boundary_corners = corners;
                o.levels = levels;
                ccn_plan *p = NULL;
                ccn_error err;
                ccn_status st = ccn_plan_create(c, &o, &p, &err);
                CHECK(st == CCN_OK, "scheme %d cap %d corners %d: %s", sc, cap, corners,
                      err.message);
                if (!p) continue;
                char what[64];
                snprintf(what, sizeof what, "scheme %d cap %d corners %d", sc, cap, corners);
                eval_check(p, c, NULL, what);
                ccn_plan_destroy(p);
            }
}

/* ---- rows -------------------------------------------------------------------------- */

static void row_nan_inf_coordinate(void) {
    double p[12];
    memcpy(p, SQ, sizeof p);
    p[7] = NAN;
    ccn_cage c = cage_of(4, 1, p, SQ_FS, SQ_FV);
    expect_plan_err(&c, NULL, CCN_ERR_ARGUMENT, "vertex 2 has a non-finite coordinate");
    p[7] = 0;
    p[9] = INFINITY;
    expect_plan_err(&c, NULL, CCN_ERR_ARGUMENT, "vertex 3 has a non-finite coordinate");
    /* and at evaluation time: a good plan, bad positions */
    ccn_cage good = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    ccn_plan *pl = NULL;
    ccn_error err;
    ccn_options o = {0};
    o.levels = 2;
    CHECK(ccn_plan_create(&good, &o, &pl, &err) == CCN_OK, "%s", err.message);
    if (!pl) return;
    ccn_sizes z;
    ccn_plan_get_sizes(pl, &z);
    ccn_plan_stats z_st;
    ccn_plan_get_stats(pl, &z_st);
    double *P = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
    ccn_limit_mesh out = {.positions = P};
    CHECK(ccn_plan_evaluate(pl, p, &out, &err) == CCN_ERR_ARGUMENT, "evaluate with Inf");
    CHECK(strstr(err.message, "vertex 3 has a non-finite coordinate") != NULL, "%s", err.message);
    p[9] = NAN;
    CHECK(ccn_plan_evaluate(pl, p, &out, &err) == CCN_ERR_ARGUMENT, "evaluate with NaN");
    /* NULL output buffers */
    ccn_limit_mesh none = {0};
    CHECK(ccn_plan_evaluate(pl, NULL, &none, &err) == CCN_ERR_ARGUMENT, "NULL out->positions");
    CHECK(strstr(err.message, "NULL") != NULL, "%s", err.message);
    CHECK(ccn_plan_evaluate(pl, NULL, NULL, &err) == CCN_ERR_ARGUMENT, "NULL out");
    free(P);
    ccn_plan_destroy(pl);
}

static void row_bad_options(void) {
    ccn_cage c = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    ccn_options o = {0};
    o.scheme = (ccn_scheme)3;
    expect_plan_err(&c, &o, CCN_ERR_ARGUMENT, "unknown scheme 3");
    o.scheme = CCN_SCHEME_EIGEN;
    o.cap = (ccn_cap)-1;
    expect_plan_err(&c, &o, CCN_ERR_ARGUMENT, "unknown cap -1");
    o.cap = CCN_CAP_GUIDED_BI5;
    o.boundary_corners = 2;
    expect_plan_err(&c, &o, CCN_ERR_ARGUMENT, "unknown boundary_corners 2");
    o.boundary_corners = 0;
    o.levels = -1;
    expect_plan_err(&c, &o, CCN_ERR_ARGUMENT, "levels must be in [0, ");
    o.levels = 1000;
    expect_plan_err(&c, &o, CCN_ERR_ARGUMENT, "got 1000");
    ccn_plan *p = (ccn_plan *)1;
    ccn_error err;
    CHECK(ccn_plan_create(NULL, NULL, &p, &err) == CCN_ERR_ARGUMENT && p == NULL, "NULL cage");
    CHECK(ccn_plan_create(&c, NULL, NULL, &err) == CCN_ERR_ARGUMENT, "NULL out");
    ccn_sizes z;
    CHECK(ccn_plan_get_sizes(NULL, &z) == CCN_ERR_ARGUMENT, "sizes of NULL");
    ccn_plan_destroy(NULL);
}

static void interval_row(double value) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    int32_t ev[2] = {5, 6};
    double kn[1] = {value};
    c.num_edges = 1; c.edge_verts = ev; c.edge_knots = kn;
    accept_plan(&c, 2);
    soup_free(&s);
}

static void row_intervals(void) {
    interval_row(-2.0);
    interval_row(0.0);
    interval_row(NAN);
    interval_row(INFINITY);
    interval_row(1e-300);
    interval_row(1e300);
}

static void row_interval_ratio_1e9(void) {
    soup s = fan(5);
    ccn_cage c = soup_cage(&s);
    int32_t ev[4] = {0, 1, 0, 2};
    double kn[2] = {1e9, 1.0};
    c.num_edges = 2; c.edge_verts = ev; c.edge_knots = kn;
    accept_plan(&c, 2);
    soup_free(&s);
}

static void row_topology_errors(void) {
    static const double p[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    int32_t fs[3] = {3, 3, 3}, fv[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    ccn_cage c = cage_of(5, 3, p, fs, fv); /* non-manifold edge: accepted as OpenSubdiv */
    accept_plan(&c, 2);
    int32_t fvb[6] = {0, 1, 2, 0, 3, 4};
    ccn_cage b = cage_of(5, 2, p, fs, fvb); /* bowtie vertex: accepted */
    accept_plan(&b, 2);
    int32_t fsr[1] = {4}, fvr[4] = {0, 1, 2, 1};
    ccn_cage r = cage_of(4, 1, SQ, fsr, fvr);
    expect_plan_err(&r, NULL, CCN_ERR_TOPOLOGY, "face 0 repeats vertex 1");
    int32_t fs2[2] = {4, 2}, fv2[6] = {0, 1, 2, 3, 1, 0};
    ccn_cage g = cage_of(4, 2, SQ, fs2, fv2);
    expect_plan_err(&g, NULL, CCN_ERR_TOPOLOGY, "face 1 has 2 vertices");
    int32_t fsd[2] = {4, 4}, fvd[8] = {0, 1, 2, 3, 0, 1, 2, 3};
    ccn_cage d = cage_of(4, 2, SQ, fsd, fvd); /* a face twice, same orientation: accepted */
    accept_plan(&d, 2);
    ccn_cage e = cage_of(0, 0, SQ, SQ_FS, SQ_FV);
    expect_plan_err(&e, NULL, CCN_ERR_ARGUMENT, "cage has no faces");
}

static void row_valence_200(void) {
    soup s = fan(200);
    ccn_cage c = soup_cage(&s);
    accept_plan(&c, 2);
    ccn_options o = {0};
    o.levels = 3; /* above the cap level (K = 2) */
    ccn_plan *p = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&c, &o, &p, &err) == CCN_OK, "%s", err.message);
    if (p) {
        ccn_sizes z;
        ccn_plan_get_sizes(p, &z);
        ccn_plan_stats z_st;
        ccn_plan_get_stats(p, &z_st);
        CHECK(z_st.num_extraordinary == 1 && z_st.num_caps + z_st.num_cap_fallbacks == 1,
              "EVs %d, caps %d, cap fallbacks %d", z_st.num_extraordinary, z_st.num_caps,
              z_st.num_cap_fallbacks);
        ccn_plan_destroy(p);
    }
    soup_free(&s);
}

static void row_one_quad(void) {
    ccn_cage c = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    accept_plan(&c, 2);
    for (int32_t L = 0; L <= 3; L++) {
        ccn_options o = {0};
        o.levels = L;
        ccn_plan *p = NULL;
        ccn_error err;
        CHECK(ccn_plan_create(&c, &o, &p, &err) == CCN_OK, "%s", err.message);
        if (!p) continue;
        ccn_sizes z;
        ccn_plan_get_sizes(p, &z);
        ccn_plan_stats z_st;
        ccn_plan_get_stats(p, &z_st);
        int32_t side = (1 << L) + 1;
        CHECK(z.num_verts == side * side && z.num_faces == (1 << L) * (1 << L) && z_st.levels == L,
              "level %d: %d verts %d faces", L, z.num_verts, z.num_faces);
        ccn_plan_destroy(p);
    }
}

static void row_isolated_vertices(void) {
    double p[18];
    memcpy(p, SQ, sizeof SQ);
    p[12] = 5; p[13] = 6; p[14] = 7; p[15] = -5; p[16] = 1e30; p[17] = 0;
    ccn_cage c = cage_of(6, 1, p, SQ_FS, SQ_FV);
    accept_plan(&c, 2);
    ccn_options o = {0};
    o.levels = 1;
    ccn_plan *pl = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&c, &o, &pl, &err) == CCN_OK, "%s", err.message);
    if (!pl) return;
    ccn_sizes z;
    ccn_plan_get_sizes(pl, &z);
    ccn_plan_stats z_st;
    ccn_plan_get_stats(pl, &z_st);
    CHECK(z_st.num_ignored_verts == 2 && z.num_cage_verts == 6, "ignored %d, cage verts %d",
          z_st.num_ignored_verts, z.num_cage_verts);
    CHECK(z.num_verts == 9 && z.num_faces == 4, "isolated vertices left out: %d verts %d faces",
          z.num_verts, z.num_faces);
    ccn_plan_destroy(pl);
}

/* Coordinates of 1e30: finite, and 1e30 times the result for the cage scaled by 1e-30. */
static void row_coordinates_1e30(void) {
    soup s = fan(5);
    for (int32_t i = 0; i < 3 * s.nv; i++) s.pos[i] *= 1e30;
    ccn_cage c = soup_cage(&s);
    accept_plan(&c, 2);
    ccn_options o = {0};
    o.levels = 2;
    ccn_plan *pl = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&c, &o, &pl, &err) == CCN_OK, "%s", err.message);
    if (pl) {
        ccn_sizes z;
        ccn_plan_get_sizes(pl, &z);
        ccn_plan_stats z_st;
        ccn_plan_get_stats(pl, &z_st);
        double *a = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
        double *b = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
        double *u = malloc(sizeof(double) * 3 * (size_t)s.nv);
        for (int32_t i = 0; i < 3 * s.nv; i++) u[i] = s.pos[i] / 1e30;
        ccn_limit_mesh oa = {.positions = a}, ob = {.positions = b};
        CHECK(ccn_plan_evaluate(pl, s.pos, &oa, &err) == CCN_OK, "%s", err.message);
        CHECK(ccn_plan_evaluate(pl, u, &ob, &err) == CCN_OK, "%s", err.message);
        double d = 0;
        for (int32_t i = 0; i < 3 * z.num_verts; i++) d = fmax(d, fabs(a[i] / 1e30 - b[i]));
        CHECK(d < 1e-12, "1e30 result differs from the scaled unit result by %g", d);
        free(a); free(b); free(u);
        ccn_plan_destroy(pl);
    }
    soup_free(&s);
}

/* Finite coordinates near DBL_MAX (fixed): finite positions and unit normals, also when
 * given to ccn_plan_evaluate. */
static void row_coordinates_near_dbl_max(void) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    double *big = malloc(sizeof(double) * 3 * (size_t)s.nv);
    const double vals[4][2] = {{1e300, -1e300}, {1e300, 1e-300}, {1e308, 0}, {DBL_MAX, -DBL_MAX}};
    for (int t = 0; t < 4; t++) {
        int accepted = t < 2; /* |coordinate| <= 1e300 is accepted, beyond is an error */
        memcpy(big, s.pos, sizeof(double) * 3 * (size_t)s.nv);
        big[3 * 5 + 2] = vals[t][0];
        big[3 * 6 + 2] = vals[t][1];
        ccn_cage cb = c;
        cb.positions = big;
        ccn_options o = {0};
        o.levels = 2;
        ccn_plan *p = NULL;
        ccn_error err;
        if (accepted) accept_plan(&cb, 2);
        else {
            CHECK(ccn_plan_create(&cb, &o, &p, &err) == CCN_ERR_ARGUMENT && p == NULL, "create must refuse");
            CHECK(strstr(err.message, "vertex 5 has a coordinate beyond") != NULL, "%s", err.message);
        }
        CHECK(ccn_plan_create(&c, &o, &p, &err) == CCN_OK, "%s", err.message);
        if (p) {
            if (accepted) eval_check(p, &c, big, "evaluate(huge positions)");
            else {
                ccn_sizes z;
                ccn_plan_get_sizes(p, &z);
                ccn_plan_stats z_st;
                ccn_plan_get_stats(p, &z_st);
                double *out = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
                ccn_limit_mesh lm = {.positions = out};
                CHECK(ccn_plan_evaluate(p, big, &lm, &err) == CCN_ERR_ARGUMENT, "evaluate must refuse");
                free(out);
            }
            ccn_plan_destroy(p);
        }
    }
    free(big);
    soup_free(&s);
}

/* 2 million quads at level 0 (the output is the limit at the cage's own vertices, 2M
 * faces): planned and evaluated within memory, counts exact. */
static void row_two_million_faces(void) {
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    clock_t c0 = clock();
    soup s = grid(1000, 2000);
    ccn_cage c = soup_cage(&s);
    ccn_options o = {0};
    o.levels = 0;
    ccn_plan *p = NULL;
    ccn_error err;
    ccn_status st = ccn_plan_create(&c, &o, &p, &err);
    CHECK(st == CCN_OK || st == CCN_ERR_MEMORY, "plan: %s", err.message);
    if (p) {
        ccn_sizes z;
        ccn_plan_get_sizes(p, &z);
        ccn_plan_stats z_st;
        ccn_plan_get_stats(p, &z_st);
        CHECK(z.num_faces == 2000000 && z.num_verts == 1001 * 2001 && z_st.levels == 0,
              "sizes %d verts %d faces", z.num_verts, z.num_faces);
        double *P = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
        int32_t *fv = malloc(sizeof(int32_t) * 4 * (size_t)z.num_faces);
        if (P && fv) {
            ccn_limit_mesh out = {.positions = P, .face_verts = fv};
            CHECK(ccn_plan_evaluate(p, NULL, &out, &err) == CCN_OK, "%s", err.message);
            int bad = 0;
            for (int64_t i = 0; i < 3 * (int64_t)z.num_verts; i++) bad += !isfinite(P[i]);
            for (int64_t i = 0; i < 4 * (int64_t)z.num_faces; i++)
                bad += fv[i] < 0 || fv[i] >= z.num_verts;
            CHECK(bad == 0, "%d bad outputs", bad);
        }
        free(P);
        free(fv);
        ccn_plan_destroy(p);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("# 2M-face plan, level 0: %.2f s (cpu %.2f s), peak RSS %ld MB\n",
           (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec),
           (double)(clock() - c0) / CLOCKS_PER_SEC, ru.ru_maxrss / 1024);
    soup_free(&s);
}

int main(void) {
    RUN(row_nan_inf_coordinate);
    RUN(row_bad_options);
    RUN(row_intervals);
    RUN(row_interval_ratio_1e9);
    RUN(row_topology_errors);
    RUN(row_valence_200);
    RUN(row_one_quad);
    RUN(row_isolated_vertices);
    RUN(row_coordinates_1e30);
    RUN(row_coordinates_near_dbl_max);
    RUN(row_two_million_faces);
    return TEST_SUMMARY();
}
