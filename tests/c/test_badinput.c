/* The bad-input table (README "Bad input"): one RUN per row. Errors: the exact
 * status, element and a message fragment. Accepted inputs: ccn_refine by 2 levels with every
 * scheme and both corner rules gives finite positions and intervals and the documented
 * counts. Fixed bugs keep their own regression tests in test_fixed_bugs.c.
 * The plan API (ccn_plan_evaluate) rows are in test_badinput_plan.c. */
#include "ccnurbs.h"
#include "testlib.h"
#include "badinput_cages.h"

#include <float.h>
#include <stdint.h>
#include <sys/resource.h>
#include <time.h>

/* ---- helpers --------------------------------------------------------------------- */

static void expect_err(const ccn_cage *c, ccn_status st, int kind, int elem, const char *needle) {
    ccn_error err;
    memset(&err, 0x5A, sizeof err);
    ccn_mesh *m = (ccn_mesh *)&err;
    ccn_status got = ccn_mesh_create(c, &m, &err);
    CHECK(memchr(err.message, '\0', sizeof err.message) != NULL, "message not terminated");
    CHECK(got == st, "status %d (%s), expected %d (%s): %s", got, ccn_status_name(got), st,
          ccn_status_name(st), err.message);
    CHECK(err.status == got, "err.status %d", err.status);
    CHECK(m == NULL, "no mesh on error");
    CHECK(err.element_kind == kind, "element kind %d, expected %d", err.element_kind, kind);
    if (elem >= 0) CHECK(err.element == elem, "element %d, expected %d", err.element, elem);
    CHECK(strstr(err.message, needle) != NULL, "message '%s' lacks '%s'", err.message, needle);
    if (got == CCN_OK) ccn_mesh_destroy(m);
}

static void expect_obj_err(const char *text, ccn_status st, int line, const char *needle) {
    ccn_error err;
    memset(&err, 0x5A, sizeof err);
    ccn_obj *o = (ccn_obj *)&err;
    size_t len = strlen(text);
    char *copy = malloc(len ? len : 1); /* not NUL-terminated: the reader must honour len */
    memcpy(copy, text, len);
    ccn_status got = ccn_obj_parse(copy, len, &o, &err);
    free(copy);
    CHECK(memchr(err.message, '\0', sizeof err.message) != NULL, "message not terminated");
    CHECK(got == st, "status %d, expected %d: %s", got, st, err.message);
    CHECK(o == NULL, "no object on error");
    CHECK(err.element_kind == CCN_ELEM_LINE && err.element == line, "element %d/%d, line %d",
          err.element_kind, err.element, line);
    CHECK(strstr(err.message, needle) != NULL, "message '%s' lacks '%s'", err.message, needle);
    if (got == CCN_OK) ccn_obj_destroy(o);
}

/* Checks a mesh's outputs: finite positions and positive finite intervals. */
static void check_mesh_finite(const ccn_mesh *m, const char *what) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    double *p = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    double *k = malloc(sizeof(double) * (size_t)in.num_edges);
    ccn_mesh_copy(m, p, NULL, NULL, NULL, k);
    int bad = -1, badk = -1;
    for (int32_t i = 0; i < 3 * in.num_verts && bad < 0; i++) if (!isfinite(p[i])) bad = i;
    for (int32_t e = 0; e < in.num_edges && badk < 0; e++)
        if (!(isfinite(k[e]) && k[e] > 0)) badk = e;
    CHECK(bad < 0, "%s: position[%d] = %g", what, bad, bad >= 0 ? p[bad] : 0.0);
    CHECK(badk < 0, "%s: interval[%d] = %g", what, badk, badk >= 0 ? k[badk] : 0.0);
    free(p);
    free(k);
}

/* Creates the mesh (must succeed), refines it 2 levels with every scheme and both corner
 * rules, checks counts and finiteness; returns the created mesh (caller destroys) or NULL. */
static ccn_mesh *accept_and_refine(const ccn_cage *c) {
    ccn_error err;
    ccn_mesh *m = NULL;
    ccn_status st = ccn_mesh_create(c, &m, &err);
    CHECK(st == CCN_OK, "create: %s", err.message);
    if (st != CCN_OK) return NULL;
    check_mesh_finite(m, "cage");
    ccn_mesh_info in0;
    ccn_mesh_get_info(m, &in0);
    for (int sc = 0; sc < 3; sc++)
        for (int corners = 0; corners < 2; corners++) {
            ccn_options o = {0};
            o.scheme = (ccn_scheme)sc;
            o.boundary_corners = corners;
            ccn_mesh *r = NULL;
            st = ccn_refine(m, 2, &o, &r, &err);
            CHECK(st == CCN_OK, "refine scheme %d corners %d: %s", sc, corners, err.message);
            if (!r) continue;
            char what[64];
            snprintf(what, sizeof what, "scheme %d corners %d level 2", sc, corners);
            check_mesh_finite(r, what);
            ccn_mesh_info in;
            ccn_mesh_get_info(r, &in);
            CHECK(in.level == 2 && in.num_faces == 4 * in0.num_face_verts,
                  "level %d, %d faces (cage corners %d)", in.level, in.num_faces,
                  in0.num_face_verts);
            ccn_mesh_destroy(r);
        }
    return m;
}

/* Resolved interval of cage edge (a, b); NaN if not an edge. */
static double interval_of(const ccn_mesh *m, int32_t a, int32_t b) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)in.num_edges);
    double *k = malloc(sizeof(double) * (size_t)in.num_edges), x = NAN;
    ccn_mesh_copy(m, NULL, NULL, NULL, ev, k);
    for (int32_t e = 0; e < in.num_edges; e++)
        if ((ev[2 * e] == a && ev[2 * e + 1] == b) || (ev[2 * e] == b && ev[2 * e + 1] == a))
            x = k[e];
    free(ev);
    free(k);
    return x;
}

/* ---- rows -------------------------------------------------------------------------- */

static void row_nan_coordinate(void) {
    double p[12];
    memcpy(p, SQ, sizeof p);
    p[7] = NAN;
    ccn_cage c = cage_of(4, 1, p, SQ_FS, SQ_FV);
    expect_err(&c, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, 2,
               "vertex 2 has a non-finite coordinate (NaN or Inf)");
}

static void row_inf_coordinate(void) {
    double p[12];
    memcpy(p, SQ, sizeof p);
    p[9] = -INFINITY;
    ccn_cage c = cage_of(4, 1, p, SQ_FS, SQ_FV);
    expect_err(&c, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, 3,
               "vertex 3 has a non-finite coordinate (NaN or Inf)");
}

/* One edge of a 3x3 grid gets `value`; its ring's resolved interval is `want` relative to
 * the others' 1 (ratio compared, as intervals are scale-free). */
static void interval_row(double value, double want_ratio) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    int32_t ev[2] = {5, 6}; /* interior edge (1,1)-(2,1) */
    double kn[1] = {value};
    c.num_edges = 1; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = accept_and_refine(&c);
    if (m) {
        double r = interval_of(m, 5, 6) / interval_of(m, 0, 4); /* ring vs. a vertical edge */
        CHECK(fabs(r / want_ratio - 1) < 1e-9, "interval ratio %.17g, expected %.17g", r,
              want_ratio);
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        CHECK(in.num_ignored_edges == 0 && in.num_ring_conflicts == 0, "ignored %d conflicts %d",
              in.num_ignored_edges, in.num_ring_conflicts);
        ccn_mesh_destroy(m);
    }
    soup_free(&s);
}

/* One interior edge of a 3x3 grid gets sharpness `value`: accepted (refined finite), the
 * stored sharpness is `want` (<= 0 smooth, >= 10 and +Inf infinitely sharp: 10). */
static void crease_row(double value, double want) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    int32_t ev[2] = {5, 6};
    double cr[1] = {value};
    c.num_edges = 1; c.edge_verts = ev; c.edge_creases = cr;
    ccn_mesh *m = accept_and_refine(&c);
    if (m) {
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        int32_t *e2 = malloc(sizeof(int32_t) * 2 * (size_t)in.num_edges);
        double *sh = malloc(sizeof(double) * (size_t)in.num_edges), got = -1;
        ccn_mesh_copy(m, NULL, NULL, NULL, e2, NULL);
        ccn_mesh_get_creases(m, sh, NULL);
        for (int32_t e = 0; e < in.num_edges; e++)
            if ((e2[2 * e] == 5 && e2[2 * e + 1] == 6) || (e2[2 * e] == 6 && e2[2 * e + 1] == 5)) got = sh[e];
        CHECK(got == want, "sharpness %g stored as %g, expected %g", value, got, want);
        CHECK(in.num_sharp_edges == (want > 0), "sharp edges %d", in.num_sharp_edges);
        free(e2); free(sh);
        ccn_mesh_destroy(m);
    }
    soup_free(&s);
}

static void row_crease_negative(void) { crease_row(-3.0, 0.0); } /* smooth, as OpenSubdiv */
static void row_crease_fraction(void) { crease_row(0.25, 0.25); }
static void row_crease_inf(void) { crease_row(INFINITY, 10.0); }
static void row_crease_huge(void) { crease_row(1e300, 10.0); }

static void row_crease_nan(void) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    int32_t ev[4] = {1, 2, 5, 6};
    double cr[2] = {1.0, NAN};
    c.num_edges = 2; c.edge_verts = ev; c.edge_creases = cr;
    expect_err(&c, CCN_ERR_ARGUMENT, CCN_ELEM_EDGE, 1, "edge 1 (vertices 5-6) has a NaN crease sharpness");
    double vc[16] = {0};
    vc[9] = NAN;
    c.num_edges = 0; c.edge_creases = NULL; c.vertex_creases = vc;
    expect_err(&c, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, 9, "vertex 9 has a NaN crease sharpness");
    soup_free(&s);
}

/* Interior valence 2 (two quads sharing two consecutive edges, inside a grid): accepted. */
static void row_interior_valence2(void) {
    /* a quad pillow: the same quad twice, reversed: four interior vertices of valence 2 */
    int32_t fs[2] = {4, 4}, fv[8] = {0, 1, 2, 3, 3, 2, 1, 0};
    static const double q[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0.2, 0, 1, 0.5};
    ccn_cage c = cage_of(4, 2, q, fs, fv);
    ccn_mesh *m = accept_and_refine(&c);
    ccn_mesh_destroy(m);
}

static void row_interval_negative(void) { interval_row(-2.0, 1.0); } /* unset -> 1 */
static void row_interval_zero(void) { interval_row(0.0, 1.0); }
static void row_interval_nan(void) { interval_row(NAN, 1.0); }
static void row_interval_inf(void) { interval_row(INFINITY, 1.0); }
static void row_interval_1e_300(void) { interval_row(1e-300, 1e-6); } /* clamped */
static void row_interval_1e300(void) { interval_row(1e300, 1e6); }    /* others clamped */

/* Spokes of a valence-5 EV with intervals 1e9 and 1 alternating (ratio 1e9 between
 * neighbouring rings): clamped to 1e6, finite with every scheme. */
static void row_interval_ratio_1e9(void) {
    soup s = fan(5);
    ccn_cage c = soup_cage(&s);
    int32_t ev[4] = {0, 1, 0, 2};
    double kn[2] = {1e9, 1.0};
    c.num_edges = 2; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = accept_and_refine(&c);
    if (m) {
        double r = interval_of(m, 0, 1) / interval_of(m, 0, 2);
        CHECK(fabs(r / 1e6 - 1) < 1e-9, "clamped ratio %.17g", r);
        ccn_mesh_destroy(m);
    }
    soup_free(&s);
}

/* Non-manifold topology is read as OpenSubdiv reads it (tests/c/test_mesh.c checks the
 * sharpening; tests/oracle/run_osd_shapes.sh the surfaces): accepted and refined finite. */
static void row_nonmanifold_edge(void) {
    static const double p[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    int32_t fs[3] = {3, 3, 3}, fv[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    ccn_cage c = cage_of(5, 3, p, fs, fv);
    ccn_mesh_destroy(accept_and_refine(&c));
}

static void row_bowtie_vertex(void) {
    static const double p[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0};
    int32_t fs[2] = {3, 3}, fv[6] = {0, 1, 2, 0, 3, 4};
    ccn_cage c = cage_of(5, 2, p, fs, fv);
    ccn_mesh_destroy(accept_and_refine(&c));
}

static void row_repeated_vertex(void) {
    int32_t fs[1] = {4}, fv[4] = {0, 1, 2, 1};
    ccn_cage c = cage_of(4, 1, SQ, fs, fv);
    expect_err(&c, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 0, "face 0 repeats vertex 1");
}

static void row_two_gon(void) {
    int32_t fs[2] = {4, 2}, fv[6] = {0, 1, 2, 3, 1, 0};
    ccn_cage c = cage_of(4, 2, SQ, fs, fv);
    expect_err(&c, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 has 2 vertices (at least 3 needed)");
    int32_t fs1[2] = {4, 1}, fs0[2] = {4, 0}, fsn[2] = {4, -3};
    ccn_cage c1 = cage_of(4, 2, SQ, fs1, fv), c0 = cage_of(4, 2, SQ, fs0, fv);
    ccn_cage cn = cage_of(4, 2, SQ, fsn, fv);
    expect_err(&c1, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 has 1 vertices");
    expect_err(&c0, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 has 0 vertices");
    expect_err(&cn, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 has -3 vertices");
}

/* Each failure an application acts on has its reason code (ccn_error.reason), so advice never
 * reads the message; an edge names its two vertices (element_verts). */
static ccn_reason reason_of(const ccn_cage *c, ccn_error *err) {
    ccn_mesh *m = NULL;
    memset(err, 0x5A, sizeof *err);
    ccn_status st = ccn_mesh_create(c, &m, err);
    ccn_mesh_destroy(m);
    return st == CCN_OK ? CCN_REASON_NONE : (ccn_reason)err->reason;
}

static void row_reason_codes(void) {
    ccn_error err;
    ccn_cage ok = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    CHECK(reason_of(&ok, &err) == CCN_REASON_NONE && err.reason == CCN_REASON_NONE, "ok: %d", err.reason);
    double p[12];
    memcpy(p, SQ, sizeof p);
    p[4] = NAN;
    ccn_cage nan = cage_of(4, 1, p, SQ_FS, SQ_FV);
    CHECK(reason_of(&nan, &err) == CCN_REASON_NONFINITE_COORDINATE, "NaN: %d", err.reason);
    p[4] = 1e305;
    CHECK(reason_of(&nan, &err) == CCN_REASON_COORDINATE_RANGE, "range: %d", err.reason);
    int32_t ev[2] = {1, 2};
    double cr[1] = {NAN};
    ccn_cage nc = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    nc.num_edges = 1, nc.edge_verts = ev, nc.edge_creases = cr;
    CHECK(reason_of(&nc, &err) == CCN_REASON_NAN_SHARPNESS, "NaN crease: %d", err.reason);
    CHECK(err.element_kind == CCN_ELEM_EDGE && err.element_verts[0] == 1 && err.element_verts[1] == 2,
          "edge vertices %d-%d", err.element_verts[0], err.element_verts[1]);
    int32_t fs2[2] = {4, 2}, fv2[6] = {0, 1, 2, 3, 1, 0};
    ccn_cage two = cage_of(4, 2, SQ, fs2, fv2);
    CHECK(reason_of(&two, &err) == CCN_REASON_FACE_TOO_FEW_VERTICES, "2-gon: %d", err.reason);
    CHECK(err.element_verts[0] == -1, "no edge: %d", err.element_verts[0]);
    int32_t fvr[4] = {0, 1, 2, 1};
    ccn_cage rep = cage_of(4, 1, SQ, SQ_FS, fvr);
    CHECK(reason_of(&rep, &err) == CCN_REASON_FACE_REPEATS_VERTEX, "repeat: %d", err.reason);
    int32_t fvo[4] = {0, 1, 2, 9};
    ccn_cage out = cage_of(4, 1, SQ, SQ_FS, fvo);
    CHECK(reason_of(&out, &err) == CCN_REASON_INDEX_OUT_OF_RANGE, "range: %d", err.reason);
    ccn_cage none = cage_of(4, 0, SQ, SQ_FS, SQ_FV);
    CHECK(reason_of(&none, &err) == CCN_REASON_NO_FACES, "no faces: %d", err.reason);
    /* the plan's limits */
    soup s = fan(1100);
    ccn_cage big = soup_cage(&s);
    ccn_plan *pl = NULL;
    ccn_options o = {0};
    o.levels = 1;
    CHECK(ccn_plan_create(&big, &o, &pl, &err) != CCN_OK && err.reason == CCN_REASON_VALENCE_LIMIT,
          "valence: %d (%s)", err.reason, err.message);
    ccn_plan_destroy(pl);
    soup_free(&s);
}

/* The same face twice (same orientation: its edges are used twice in one direction) and three
 * times (edges shared by three faces): non-manifold, accepted. A reversed duplicate is a closed
 * two-face "pillow" of interior valence-2 vertices (row_interior_valence2, test_fixed_bugs.c). */
static void row_duplicate_faces(void) {
    int32_t fs[2] = {4, 4}, fv[8] = {0, 1, 2, 3, 0, 1, 2, 3};
    ccn_cage c = cage_of(4, 2, SQ, fs, fv);
    ccn_mesh_destroy(accept_and_refine(&c));
    int32_t fs3[3] = {4, 4, 4}, fv3[12] = {0, 1, 2, 3, 3, 2, 1, 0, 0, 1, 2, 3};
    ccn_cage c3 = cage_of(4, 3, SQ, fs3, fv3);
    ccn_mesh_destroy(accept_and_refine(&c3));
}

/* An interior vertex of valence 200 (closed fan of 200 quads): accepted, finite. */
static void row_valence_200(void) {
    soup s = fan(200);
    ccn_cage c = soup_cage(&s);
    ccn_mesh *m = accept_and_refine(&c);
    if (m) {
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        CHECK(in.max_valence == 200 && in.num_extraordinary == 1, "max valence %d, EVs %d",
              in.max_valence, in.num_extraordinary);
        ccn_mesh_destroy(m);
    }
    soup_free(&s);
}

static void row_empty_mesh(void) {
    ccn_cage c = cage_of(0, 0, SQ, SQ_FS, SQ_FV);
    expect_err(&c, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "cage has no faces");
    ccn_cage c2 = cage_of(4, 0, SQ, SQ_FS, SQ_FV); /* vertices only */
    expect_err(&c2, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "cage has no faces");
    ccn_cage c3 = {0}; /* all NULL */
    expect_err(&c3, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "cage has no faces");
}

/* One quad: 4 boundary valence-2 corners; 2 levels give 25 vertices, 16 quads. */
static void row_one_quad(void) {
    ccn_cage c = cage_of(4, 1, SQ, SQ_FS, SQ_FV);
    ccn_mesh *m = accept_and_refine(&c);
    if (!m) return;
    ccn_mesh *r = NULL;
    ccn_error err;
    CHECK(ccn_refine(m, 2, NULL, &r, &err) == CCN_OK, "%s", err.message);
    if (r) {
        ccn_mesh_info in;
        ccn_mesh_get_info(r, &in);
        CHECK(in.num_verts == 25 && in.num_faces == 16, "%d verts %d faces", in.num_verts,
              in.num_faces);
        ccn_mesh_destroy(r);
    }
    ccn_mesh_destroy(m);
}

/* Isolated vertices keep their slot (carried along unchanged, to rounding) and are counted. */
static void row_isolated_vertices(void) {
    double p[18];
    memcpy(p, SQ, sizeof SQ);
    p[12] = 5; p[13] = 6; p[14] = 7; p[15] = -5; p[16] = 3; p[17] = 0;
    /* (an isolated vertex far away, e.g. at 1e30, is test_fixed_bugs.c KB4) */
    ccn_cage c = cage_of(6, 1, p, SQ_FS, SQ_FV);
    ccn_mesh *m = accept_and_refine(&c);
    if (!m) return;
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    CHECK(in.num_ignored_verts == 2, "ignored %d", in.num_ignored_verts);
    ccn_mesh *r = NULL;
    ccn_error err;
    CHECK(ccn_refine(m, 1, NULL, &r, &err) == CCN_OK, "%s", err.message);
    if (r) {
        ccn_mesh_info ri;
        ccn_mesh_get_info(r, &ri);
        double *q = malloc(sizeof(double) * 3 * (size_t)ri.num_verts);
        ccn_mesh_copy(r, q, NULL, NULL, NULL, NULL);
        /* vertex points come last, in vertex order: isolated vertex 4 is carried along */
        const double *v4 = q + 3 * (ri.num_verts - 2);
        CHECK(fabs(v4[0] - 5) < 1e-14 && fabs(v4[1] - 6) < 1e-14 && fabs(v4[2] - 7) < 1e-14,
              "isolated vertex moved: %.17g %.17g %.17g", v4[0], v4[1], v4[2]);
        CHECK(ri.num_ignored_verts == 2, "ignored after refine %d", ri.num_ignored_verts);
        free(q);
        ccn_mesh_destroy(r);
    }
    ccn_mesh_destroy(m);
}

/* Coordinates of 1e30 (a fan with an EV and a grid): finite, and scale-equivariant — the
 * result equals 1e30 times the result for the cage divided by 1e30. */
static void row_coordinates_1e30(void) {
    soup s = fan(5);
    for (int32_t i = 0; i < 3 * s.nv; i++) s.pos[i] *= 1e30;
    ccn_cage c = soup_cage(&s);
    ccn_mesh *m = accept_and_refine(&c);
    if (m) {
        for (int32_t i = 0; i < 3 * s.nv; i++) s.pos[i] /= 1e30;
        ccn_mesh *u = NULL, *r = NULL, *ru = NULL;
        ccn_error err;
        ccn_mesh_create(&c, &u, &err);
        ccn_refine(m, 2, NULL, &r, &err);
        ccn_refine(u, 2, NULL, &ru, &err);
        if (r && ru) {
            ccn_mesh_info in;
            ccn_mesh_get_info(r, &in);
            double *a = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
            double *b = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
            ccn_mesh_copy(r, a, NULL, NULL, NULL, NULL);
            ccn_mesh_copy(ru, b, NULL, NULL, NULL, NULL);
            double dmax = 0;
            for (int32_t i = 0; i < 3 * in.num_verts; i++)
                dmax = fmax(dmax, fabs(a[i] / 1e30 - b[i]));
            CHECK(dmax < 1e-12, "1e30 result differs from the scaled unit result by %g", dmax);
            free(a);
            free(b);
        }
        ccn_mesh_destroy(u); ccn_mesh_destroy(r); ccn_mesh_destroy(ru);
        ccn_mesh_destroy(m);
    }
    soup_free(&s);
}

/* Finite coordinates near DBL_MAX (found by fuzz_mesh, fixed: the library refines in a unit
 * box): accepted, finite output; also through ccn_mesh_set_positions. */
static void row_coordinates_near_dbl_max(void) {
    soup s = grid(3, 3);
    ccn_cage c = soup_cage(&s);
    /* up to +-1e300: accepted, finite (work in an exactly scaled box) */
    const double ok_vals[2][2] = {{1e300, -1e300}, {1e300, 1e-300}};
    for (int t = 0; t < 2; t++) {
        s.pos[3 * 5 + 2] = ok_vals[t][0];
        s.pos[3 * 6 + 2] = ok_vals[t][1];
        ccn_mesh *m = accept_and_refine(&c);
        ccn_mesh_destroy(m);
    }
    /* beyond: a clear error naming the vertex, from create and from set_positions */
    const double bad_vals[3][2] = {{1e308, 0}, {1e301, -1e308}, {DBL_MAX, -DBL_MAX}};
    for (int t = 0; t < 3; t++) {
        s.pos[3 * 5 + 2] = bad_vals[t][0];
        s.pos[3 * 6 + 2] = bad_vals[t][1];
        ccn_mesh *m = (ccn_mesh *)1;
        ccn_error err;
        CHECK(ccn_mesh_create(&c, &m, &err) == CCN_ERR_ARGUMENT && m == NULL, "create must refuse");
        CHECK(err.element_kind == CCN_ELEM_VERTEX && err.element == 5, "names vertex 5: %s", err.message);
        CHECK(strstr(err.message, "vertex 5 has a coordinate beyond") != NULL, "%s", err.message);
        double *small = malloc(sizeof(double) * 3 * (size_t)s.nv);
        memcpy(small, s.pos, sizeof(double) * 3 * (size_t)s.nv);
        small[3 * 5 + 2] = small[3 * 6 + 2] = 0;
        ccn_cage cs = soup_cage(&s);
        cs.positions = small;
        ccn_mesh *m2 = NULL;
        CHECK(ccn_mesh_create(&cs, &m2, &err) == CCN_OK, "%s", err.message);
        if (m2) {
            CHECK(ccn_mesh_set_positions(m2, s.pos, &err) == CCN_ERR_ARGUMENT, "set_positions must refuse");
            CHECK(strstr(err.message, "coordinate beyond") != NULL, "%s", err.message);
            ccn_mesh_destroy(m2);
        }
        free(small);
    }
    soup_free(&s);
}

/* A 2-million-quad cage (1000 x 2000 grid): created, refined one level within memory, with
 * the exact counts (no int32 overflow); 3 levels (512 M corners) are refused up front with
 * CCN_ERR_MEMORY naming the sizes. A cage over the corner limit (INT32_MAX / 8 corners) is
 * CCN_ERR_MEMORY naming the limit. */
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void row_two_million_faces(void) {
    double t0 = now();
    clock_t c0 = clock();
    soup s = grid(1000, 2000);
    ccn_cage c = soup_cage(&s);
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    ccn_status st = ccn_mesh_create(&c, &m, &err);
    double t1 = now(), c1 = (double)(clock() - c0) / CLOCKS_PER_SEC;
    CHECK(st == CCN_OK || (st == CCN_ERR_MEMORY && strstr(err.message, "corners")),
          "create: %s", err.message);
    if (m) {
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        CHECK(in.num_faces == 2000000 && in.num_verts == 1001 * 2001 &&
                  in.num_edges == 1000 * 2001 + 2000 * 1001 && in.num_face_verts == 8000000,
              "cage counts %d %d %d %d", in.num_faces, in.num_verts, in.num_edges,
              in.num_face_verts);
        ccn_options o = {0};
        o.scheme = CCN_SCHEME_NURSS;
        st = ccn_refine(m, 1, &o, &r, &err);
        CHECK(st == CCN_OK || (st == CCN_ERR_MEMORY && strstr(err.message, "memory")),
              "refine: %s", err.message);
        if (r) {
            ccn_mesh_info ri;
            ccn_mesh_get_info(r, &ri);
            int64_t nv = (int64_t)in.num_faces + in.num_edges + in.num_verts;
            int64_t ne = 2 * (int64_t)in.num_edges + in.num_face_verts;
            CHECK(ri.num_verts == nv && ri.num_faces == 8000000 && ri.num_edges == ne &&
                      ri.num_face_verts == 32000000,
                  "refined counts %d %d %d %d", ri.num_verts, ri.num_faces, ri.num_edges,
                  ri.num_face_verts);
            /* spot-check: positions finite, the last vertex point is the grid corner's */
            double *p = malloc(sizeof(double) * 3 * (size_t)ri.num_verts);
            if (p) {
                ccn_mesh_copy(r, p, NULL, NULL, NULL, NULL);
                int bad = 0;
                for (int64_t i = 0; i < 3 * (int64_t)ri.num_verts; i++) bad += !isfinite(p[i]);
                CHECK(bad == 0, "%d non-finite refined coordinates", bad);
                free(p);
            }
            ccn_mesh_destroy(r);
        }
        /* 3 levels would pass the corner limit: refused before any work */
        r = NULL;
        double tr = now();
        st = ccn_refine(m, 3, &o, &r, &err);
        CHECK(st == CCN_ERR_MEMORY && r == NULL, "3 levels: status %d", st);
        CHECK(strstr(err.message, "3 levels of a 8000000-corner cage would exceed 268435455 "
                                  "face corners") != NULL, "%s", err.message);
        CHECK(now() - tr < 1.0, "refusing 3 levels took %.2f s", now() - tr);
        ccn_mesh_destroy(m);
    }
    /* the corner limit (INT32_MAX / 8), checked in 64-bit before anything is read or
     * allocated: one face of 268435456 corners, or two of INT32_MAX (sum > INT32_MAX) */
    int32_t big[2] = {268435456, 3}, huge[2] = {INT32_MAX, INT32_MAX};
    ccn_cage cb = cage_of(4, 2, SQ, big, SQ_FV);
    expect_err(&cb, CCN_ERR_MEMORY, CCN_ELEM_FACE, 0,
               "cage too large: more than 268435455 face corners");
    ccn_cage ch = cage_of(4, 2, SQ, huge, SQ_FV);
    expect_err(&ch, CCN_ERR_MEMORY, CCN_ELEM_FACE, 0, "cage too large");
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("# 2M-face cage: create %.2f s (cpu %.2f s), create + refine 1 level %.2f s "
           "(cpu %.2f s), peak RSS %ld MB\n", t1 - t0, c1, now() - t0,
           (double)(clock() - c0) / CLOCKS_PER_SEC, ru.ru_maxrss / 1024);
    soup_free(&s);
}

/* The parsed text (which must parse) and its cage view; NULL if it did not parse. */
static ccn_obj *parsed_cage(const char *text, ccn_cage *c) {
    ccn_obj *o = NULL;
    ccn_error err;
    CHECK(ccn_obj_parse(text, strlen(text), &o, &err) == CCN_OK, "%s", err.message);
    if (o) ccn_obj_get_cage(o, c);
    return o;
}

static void row_truncated_obj(void) {
    expect_obj_err("v 0 0 0\nv 1 0", CCN_ERR_IO, 2, "OBJ line 2: vertex needs three numbers");
    expect_obj_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 /", CCN_ERR_IO, 5,
                   "OBJ line 5: bad face index");
    expect_obj_err("v 0 0 0\n# knot 1 2", CCN_ERR_IO, 2, "expected '# knot i j d'");
    /* a file cut after a complete line parses; then the cage is judged (a 2-gon here) */
    ccn_cage c;
    ccn_obj *o = parsed_cage("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2", &c);
    if (o) expect_err(&c, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 0, "face 0 has 2 vertices");
    ccn_obj_destroy(o);
}

static void row_garbage_obj(void) {
    expect_obj_err("\001\002garbage\377\nf x y z\n", CCN_ERR_IO, 2, "OBJ line 2: bad face index");
    expect_obj_err("v 1 2 three\n", CCN_ERR_IO, 1, "OBJ line 1: vertex needs three numbers");
    expect_obj_err("v 0 0 0\nf 1 0 1\n", CCN_ERR_IO, 2, "bad face index");            /* 0 */
    expect_obj_err("v 0 0 0\nf 1 -7 1\n", CCN_ERR_IO, 2, "face index out of range");   /* rel */
    expect_obj_err("f 99999999999999999999 1 2\n", CCN_ERR_IO, 1, "bad face index");  /* huge */
    char longtok[200];
    memset(longtok, '1', sizeof longtok - 1);
    longtok[0] = 'v'; longtok[1] = ' '; longtok[sizeof longtok - 1] = '\0';
    expect_obj_err(longtok, CCN_ERR_IO, 1, "vertex needs three numbers");
    /* binary noise: no crash, a status in range, a terminated message */
    unsigned char noise[4096];
    for (size_t i = 0; i < sizeof noise; i++) noise[i] = (unsigned char)(tl_rand01() * 256);
    ccn_obj *o = NULL;
    ccn_error err;
    memset(&err, 0x5A, sizeof err);
    ccn_status st = ccn_obj_parse((const char *)noise, sizeof noise, &o, &err);
    CHECK(st == CCN_OK || st == CCN_ERR_IO, "noise: %d", st);
    CHECK(memchr(err.message, '\0', sizeof err.message) != NULL, "message not terminated");
    ccn_obj_destroy(o);
}

/* The OBJ format's line continuation: a backslash ending a line (LF or CRLF) joins the next,
 * also between a number and the backslash; errors after it count the physical lines. */
static void row_obj_continuation(void) {
    ccn_cage c;
    ccn_obj *o = parsed_cage("v 0 0 0\nv 1 0 \\\n0\nv 1 1 0\r\nv 0 1 0\nf 1 2\\\r\n 3 \\\n4\n", &c);
    if (o) {
        CHECK(c.num_verts == 4 && c.num_faces == 1 && c.face_sizes[0] == 4,
              "continued lines: %d verts, %d faces", (int)c.num_verts, (int)c.num_faces);
        CHECK(c.num_faces == 1 && c.face_verts[3] == 3 && c.positions[3] == 1.0 && c.positions[5] == 0.0,
              "continued values misread");
    }
    ccn_obj_destroy(o);
    expect_obj_err("v 0 0 \\\n0\n\nv 1 x 0\n", CCN_ERR_IO, 4, "OBJ line 4: vertex needs three numbers");
    expect_obj_err("v 0 0 0\nf 1 \\\n x\n", CCN_ERR_IO, 2, "OBJ line 2: bad face index");
}

/* Out-of-range indices and inconsistent orientation, for completeness of the table. */
static void row_index_out_of_range(void) {
    int32_t fv[4] = {0, 1, 2, 9};
    ccn_cage c = cage_of(4, 1, SQ, SQ_FS, fv);
    expect_err(&c, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 0,
               "face 0 uses vertex index 9, out of range [0, 4)");
}

int main(void) {
    RUN(row_nan_coordinate);
    RUN(row_obj_continuation);
    RUN(row_inf_coordinate);
    RUN(row_interval_negative);
    RUN(row_interval_zero);
    RUN(row_interval_nan);
    RUN(row_crease_negative);
    RUN(row_crease_fraction);
    RUN(row_crease_inf);
    RUN(row_crease_huge);
    RUN(row_crease_nan);
    RUN(row_interior_valence2);
    RUN(row_interval_inf);
    RUN(row_interval_1e_300);
    RUN(row_interval_1e300);
    RUN(row_interval_ratio_1e9);
    RUN(row_nonmanifold_edge);
    RUN(row_bowtie_vertex);
    RUN(row_repeated_vertex);
    RUN(row_two_gon);
    RUN(row_reason_codes);
    RUN(row_duplicate_faces);
    RUN(row_valence_200);
    RUN(row_empty_mesh);
    RUN(row_one_quad);
    RUN(row_isolated_vertices);
    RUN(row_coordinates_1e30);
    RUN(row_coordinates_near_dbl_max);
    RUN(row_two_million_faces);
    RUN(row_truncated_obj);
    RUN(row_garbage_obj);
    RUN(row_index_out_of_range);
    return TEST_SUMMARY();
}
