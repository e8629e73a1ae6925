/* Regression tests for library bugs found by the fuzzers and the bad-input table,
 * all fixed: KB1 interior valence-2 vertices are a topology error; KB2b coordinates beyond
 * +-1e300 are an argument error; KB3 evaluate(NULL) uses the cage given to create; KB4 the
 * unit box is an exact power-of-two scaling after an exact centre shift that no part of the cage
 * pays for, ignoring isolated vertices. Inputs also in tests/fuzz/regressions/. */
#include "ccnurbs.h"
#include "testlib.h"

#include <float.h>

static int enabled(void) { return 1; }

/* Either a clear error at creation, or: refine 2 levels with every scheme and both corner
 * rules succeeds and every refined coordinate is finite. */
static void accepted_means_finite(const ccn_cage *c, ccn_status allowed_err) {
    ccn_mesh *m = NULL;
    ccn_error err;
    ccn_status st = ccn_mesh_create(c, &m, &err);
    if (st != CCN_OK) {
        CHECK(st == allowed_err, "create: status %d: %s", st, err.message);
        return;
    }
    for (int sc = 0; sc < 3; sc++)
        for (int corners = 0; corners < 2; corners++) {
            ccn_options o = {0};
            o.scheme = (ccn_scheme)sc;
            o.boundary_corners = corners;
            ccn_mesh *r = NULL;
            st = ccn_refine(m, 2, &o, &r, &err);
            CHECK(st == CCN_OK, "scheme %d corners %d: status %d (%s): %s", sc, corners, st,
                  ccn_status_name(st), err.message);
            if (!r) continue;
            ccn_mesh_info in;
            ccn_mesh_get_info(r, &in);
            double *p = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
            ccn_mesh_copy(r, p, NULL, NULL, NULL, NULL);
            int bad = 0;
            for (int32_t i = 0; i < 3 * in.num_verts; i++) bad += !isfinite(p[i]);
            CHECK(bad == 0, "scheme %d corners %d: %d non-finite coordinates", sc, corners, bad);
            free(p);
            ccn_mesh_destroy(r);
        }
    ccn_mesh_destroy(m);
}

/* The plan at level 2 with every scheme and cap: either the error `allowed_err` at creation,
 * or created and evaluated with finite positions and normals. */
static void plan_accepted_means_finite(const ccn_cage *c, ccn_status allowed_err) {
    for (int sc = 0; sc < 3; sc++)
        for (int cap = 0; cap < 2; cap++) {
            ccn_options o = {0};
            o.scheme = (ccn_scheme)sc;
            o.cap = (ccn_cap)cap;
            o.levels = 2;
            ccn_plan *p = NULL;
            ccn_error err;
            ccn_status st = ccn_plan_create(c, &o, &p, &err);
            if (st != CCN_OK) {
                CHECK(st == allowed_err, "plan scheme %d cap %d: status %d (%s): %s", sc, cap,
                      st, ccn_status_name(st), err.message);
                continue;
            }
            ccn_sizes z;
            ccn_plan_get_sizes(p, &z);
            double *P = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
            double *N = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
            ccn_limit_mesh out = {.positions = P, .normals = N};
            st = ccn_plan_evaluate(p, NULL, &out, &err);
            CHECK(st == CCN_OK, "plan scheme %d cap %d: evaluate %s", sc, cap, err.message);
            int bad = 0;
            for (int32_t i = 0; st == CCN_OK && i < 3 * z.num_verts; i++)
                bad += !isfinite(P[i]) || !isfinite(N[i]);
            CHECK(bad == 0, "plan scheme %d cap %d: %d non-finite outputs", sc, cap, bad);
            free(P);
            free(N);
            ccn_plan_destroy(p);
        }
}

/* KB1 (fuzz_obj, regressions/obj/kb1_interior_valence2_pillow.obj): a closed two-triangle
 * "pillow" (the same triangle twice, opposite orientations) has three interior vertices of
 * valence 2. It made ccn_refine with the eigen scheme fail with CCN_ERR_ARGUMENT
 * "extraordinary vertex 7: refinement matrix failed" (ccn_ev_matrix refuses n = 2; the message
 * named a level-1 vertex) and ccn_plan_create fail for every scheme. Interior valence 2 is
 * now supported (Catmull-Clark / NURSS rules there, no eigen matrix, the limit from
 * the 1-ring's stationary matrix), so the pillows must be accepted with finite output. */
static void kb1_interior_valence2(void) {
    if (!enabled()) return;
    static const double p[12] = {0, 0, 0, 1, 2, 2, 1, 3, 0, 0, 0, 1};
    int32_t fs[2] = {3, 3}, fv[6] = {0, 1, 2, 0, 2, 1};
    ccn_cage c = {0};
    c.num_verts = 3; c.num_faces = 2; c.positions = p; c.face_sizes = fs; c.face_verts = fv;
    accepted_means_finite(&c, CCN_OK);
    plan_accepted_means_finite(&c, CCN_OK);
    int32_t fs4[2] = {4, 4}, fv4[8] = {0, 1, 2, 3, 3, 2, 1, 0}; /* quad pillow */
    static const double q[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.5};
    c.num_verts = 4; c.positions = q; c.face_sizes = fs4; c.face_verts = fv4;
    accepted_means_finite(&c, CCN_OK);
    plan_accepted_means_finite(&c, CCN_OK);
}

/* KB2b (fuzz_mesh, regressions/mesh/kb2b_dblmax_overshoot), left after the unit-box fix of
 * KB2 (f719cec): when the cage's bounding box reaches DBL_MAX, points mapped back from the
 * unit box overflow if they lie even slightly outside it (rounding; eigen weights are not
 * all positive). A 4x1 quad grid (last quad split into two triangles) with four vertices at
 * y = DBL_MAX, intervals DBL_MAX and 128.6: ccn_refine eigen, 2 levels, gives an Inf
 * coordinate (nurss, cc: finite); ccn_plan_evaluate at level 2 gives Inf for every scheme.
 * Expected: CCN_ERR_ARGUMENT for coordinates above a documented bound (e.g. 1e300), or
 * finite output. */
static void kb2b_dbl_max_overshoot(void) {
    if (!enabled()) return;
    const double M = DBL_MAX;
    double p[30] = {0, 0, 0.44921875, 1, 0, -0.1953125, 2, M, 0, 3, M, 0, 4, M, 0,
                    0, 1, 0.26171875, 1, 1, 0.26171875, 2, 1, 0.26171875, 3, 1, 0.26171875,
                    4, M, 0};
    int32_t fs[5] = {4, 4, 4, 3, 3};
    int32_t fv[18] = {0, 1, 6, 5, 1, 2, 7, 6, 2, 3, 8, 7, 3, 4, 9, 3, 9, 8};
    int32_t ev[4] = {6, 1, 4, 9};
    double kn[2] = {DBL_MAX, 128.63969449369745};
    ccn_cage c = {0};
    c.num_verts = 10; c.num_faces = 5; c.positions = p; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = 2; c.edge_verts = ev; c.edge_knots = kn;
    accepted_means_finite(&c, CCN_ERR_ARGUMENT);
    plan_accepted_means_finite(&c, CCN_ERR_ARGUMENT);
}

/* KB3 (fuzz_plan, regressions/plan/kb3_*): ccn_plan_evaluate(plan, NULL, ...) is documented
 * as "the cage's own positions", but after a call with explicit positions it reuses those
 * (plan.c keeps them in lev[0]). Either the header should say "the positions of the last
 * call (initially the cage's)", or NULL should restore the cage's. */
static void kb3_plan_null_positions(void) {
    if (!enabled()) return;
    static const double p[27] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 1,
                                 2, 1, 0, 0, 2, 0, 1, 2, 0, 2, 2, 0};
    double p2[27];
    for (int i = 0; i < 27; i++) p2[i] = 2 * p[i];
    int32_t fs[4] = {4, 4, 4, 4}, fv[16] = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7};
    ccn_cage c = {0};
    c.num_verts = 9; c.num_faces = 4; c.positions = p; c.face_sizes = fs; c.face_verts = fv;
    ccn_options o = {0};
    o.levels = 2;
    ccn_plan *pl = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&c, &o, &pl, &err) == CCN_OK, "%s", err.message);
    if (!pl) return;
    ccn_sizes z;
    ccn_plan_get_sizes(pl, &z);
    double *a = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
    double *b = malloc(sizeof(double) * 3 * (size_t)z.num_verts);
    ccn_limit_mesh oa = {.positions = a}, ob = {.positions = b};
    ccn_plan_evaluate(pl, NULL, &oa, &err);
    ccn_plan_evaluate(pl, p2, &ob, &err);
    ccn_plan_evaluate(pl, NULL, &ob, &err);
    double d = 0;
    for (int32_t i = 0; i < 3 * z.num_verts; i++) d = fmax(d, fabs(a[i] - b[i]));
    CHECK(d == 0, "evaluate(NULL) after evaluate(2P) differs from the first evaluate(NULL) by %g",
          d);
    free(a);
    free(b);
    ccn_plan_destroy(pl);
}

/* KB4 (test_badinput.c row_isolated_vertices): an isolated vertex far away must not cost the
 * cage any precision. Mapping positions to the bounding box of *all* cage vertices,
 * (p - centre) / scale, did: a unit quad plus an isolated (ignored) vertex at y = 1e12 refined 2
 * levels 6e-5 away from the quad alone, at y = 1e20 about 1 away; the plan's limit positions
 * were 1.6e-4 / 8e3 / 1.4e14 off for 1e12 / 1e20 / 1e30, and the isolated vertex came back
 * moved. The unit box is the box of the vertices in faces, its shift exact and kept only where no
 * connected part reaches farther from it than from the origin (test_locality.c: far parts). */
static void kb4_far_vertex_precision(void) {
    if (!enabled()) return;
    const double far[3] = {1e12, 1e20, 1e30};
    for (int t = 0; t < 3; t++) {
        double p[15] = {0, 0, 0, 1, 0, 0, 1, 1, 0.2, 0, 1, 0, 5, far[t], 7};
        int32_t fs[1] = {4}, fv[4] = {0, 1, 2, 3};
        ccn_cage c = {0};
        c.num_verts = 5; c.num_faces = 1; c.positions = p; c.face_sizes = fs; c.face_verts = fv;
        ccn_cage c4 = c;
        c4.num_verts = 4;
        ccn_mesh *m = NULL, *m4 = NULL, *r = NULL, *r4 = NULL;
        ccn_error err;
        ccn_mesh_create(&c, &m, &err);
        ccn_mesh_create(&c4, &m4, &err);
        if (m && m4 && ccn_refine(m, 2, NULL, &r, &err) == CCN_OK &&
            ccn_refine(m4, 2, NULL, &r4, &err) == CCN_OK) {
            double a[3 * 26], b[3 * 25];
            ccn_mesh_copy(r, a, NULL, NULL, NULL, NULL);
            ccn_mesh_copy(r4, b, NULL, NULL, NULL, NULL);
            double d = 0;
            for (int i = 0; i < 3 * 25; i++) d = fmax(d, fabs(a[i] - b[i]));
            CHECK(d < 1e-12, "isolated vertex at %g: refined quad off by %g", far[t], d);
            CHECK(a[75] == 5 && a[76] == far[t] && a[77] == 7,
                  "isolated vertex at %g came back as %.17g %.17g %.17g", far[t], a[75], a[76],
                  a[77]);
        }
        ccn_mesh_destroy(m); ccn_mesh_destroy(m4); ccn_mesh_destroy(r); ccn_mesh_destroy(r4);
        ccn_options o = {0};
        o.levels = 2;
        ccn_plan *pl = NULL, *pl4 = NULL;
        if (ccn_plan_create(&c, &o, &pl, &err) == CCN_OK &&
            ccn_plan_create(&c4, &o, &pl4, &err) == CCN_OK) {
            double P[3 * 25], P4[3 * 25];
            ccn_limit_mesh lm = {.positions = P}, lm4 = {.positions = P4};
            ccn_plan_evaluate(pl, NULL, &lm, &err);
            ccn_plan_evaluate(pl4, NULL, &lm4, &err);
            double d = 0;
            for (int i = 0; i < 3 * 25; i++) d = fmax(d, fabs(P[i] - P4[i]));
            CHECK(d < 1e-12, "isolated vertex at %g: limit of the quad off by %g", far[t], d);
        }
        ccn_plan_destroy(pl);
        ccn_plan_destroy(pl4);
    }
}

/* KB5 (fuzz_mesh, regressions/mesh/subnormal_coordinate): a triangle whose only non-zero
 * coordinate is subnormal (5e-320) refined to NaN: the power-of-two scale's reciprocal
 * overflowed. The exponent is now clamped. */
static void kb5_subnormal_coordinates(void) {
    static const double p[9] = {5.0710897889145545e-320, 0, 0, 0, 0, 0, 0, 0, 0};
    int32_t fs[1] = {3}, fv[3] = {0, 1, 2};
    ccn_cage c = {0};
    c.num_verts = 3; c.num_faces = 1; c.positions = p; c.face_sizes = fs; c.face_verts = fv;
    accepted_means_finite(&c, CCN_OK);
    plan_accepted_means_finite(&c, CCN_OK);
}

int main(void) {
    RUN(kb5_subnormal_coordinates);
    RUN(kb1_interior_valence2);
    RUN(kb2b_dbl_max_overshoot);
    RUN(kb3_plan_null_positions);
    RUN(kb4_far_vertex_precision);
    return TEST_SUMMARY();
}
