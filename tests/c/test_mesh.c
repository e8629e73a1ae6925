/* Cage validation and knot-ring resolution. */
#include "ccnurbs.h"
#include "testlib.h"

static double grid_pos[3 * 64];

/* Open (nx x ny)-quad grid; vertex (i,j) = j*(nx+1)+i. */
static int make_grid(int nx, int ny, int32_t *fs, int32_t *fv) {
    int f = 0;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++, f++) {
            int v = j * (nx + 1) + i;
            fs[f] = 4;
            fv[4 * f + 0] = v;
            fv[4 * f + 1] = v + 1;
            fv[4 * f + 2] = v + nx + 2;
            fv[4 * f + 3] = v + nx + 1;
        }
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            double *p = grid_pos + 3 * (j * (nx + 1) + i);
            p[0] = i; p[1] = j; p[2] = 0.1 * ((i * 7 + j * 3) % 5);
        }
    return f;
}

static ccn_status create(int nv, int nf, const int32_t *fs, const int32_t *fv, const double *pos,
                         ccn_error *err, ccn_mesh **out) {
    ccn_cage c = {0};
    c.num_verts = nv; c.num_faces = nf; c.positions = pos; c.face_sizes = fs; c.face_verts = fv;
    *out = NULL;
    return ccn_mesh_create(&c, out, err);
}

static const double P8[3 * 8] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0, 2, 1, 0, -1, 0, 0, 0, -1, 0};

/* Expect failure with status st, element (kind, index), and `needle` in the message. */
static void expect_err(int nv, int nf, const int32_t *fs, const int32_t *fv, const double *pos,
                       ccn_status st, int kind, int elem, const char *needle) {
    ccn_error err;
    ccn_mesh *m = (ccn_mesh *)1;
    ccn_status got = create(nv, nf, fs, fv, pos, &err, &m);
    CHECK(got == st, "status %d expected %d (%s)", got, st, err.message);
    CHECK(m == NULL, "no mesh on error");
    CHECK(err.status == st, "err.status %d", err.status);
    CHECK(err.element_kind == kind, "kind %d expected %d", err.element_kind, kind);
    if (elem >= 0) CHECK(err.element == elem, "element %d expected %d", err.element, elem);
    CHECK(strstr(err.message, needle) != NULL, "message '%s' lacks '%s'", err.message, needle);
    ccn_mesh_destroy(m);
}

/* A non-manifold cage is accepted as OpenSubdiv reads it: the mesh reports the cage's own
 * vertices and edges (the fans it is split into are welded back), every non-manifold edge is
 * infinitely sharp (sharpness 10) and its ends are corners. */
static void expect_nonmanifold(int nv, int nf, const int32_t *fs, const int32_t *fv,
                               int32_t ne, int32_t a, int32_t b, int32_t corner) {
    ccn_error err;
    ccn_mesh *m = NULL;
    ccn_status st = create(nv, nf, fs, fv, P8, &err, &m);
    CHECK(st == CCN_OK, "accepted: %s", err.message);
    if (!m) return;
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    CHECK(in.num_verts == nv && in.num_faces == nf && in.num_edges == ne,
          "counts %d %d %d, expected %d %d %d", in.num_verts, in.num_faces, in.num_edges, nv, nf, ne);
    int32_t ev[64];
    double es[32], vs[8];
    ccn_mesh_copy(m, NULL, NULL, NULL, ev, NULL);
    ccn_mesh_get_creases(m, es, vs);
    int found = a < 0;
    for (int32_t e = 0; e < in.num_edges && a >= 0; e++) {
        int hit = (ev[2 * e] == a && ev[2 * e + 1] == b) || (ev[2 * e] == b && ev[2 * e + 1] == a);
        if (hit) found = 1;
        CHECK(hit ? es[e] == 10.0 : es[e] == 0.0, "edge %d-%d sharpness %g", ev[2 * e], ev[2 * e + 1], es[e]);
    }
    CHECK(found, "edge %d-%d not listed once", a, b);
    for (int32_t v = 0; v < nv; v++) {
        int c = v == corner || (a >= 0 && (v == a || v == b));
        CHECK(c ? vs[v] == 10.0 : vs[v] == 0.0, "vertex %d sharpness %g", v, vs[v]);
    }
    /* refined once: V + E + F welded vertices; the corners stay where they are */
    ccn_mesh *r = NULL;
    CHECK(ccn_refine(m, 1, NULL, &r, &err) == CCN_OK, "refine: %s", err.message);
    if (r) {
        ccn_mesh_info ri;
        ccn_mesh_get_info(r, &ri);
        CHECK(ri.num_verts == nv + ne + nf, "level 1: %d vertices, expected %d", ri.num_verts, nv + ne + nf);
        double *p = malloc(sizeof(double) * 3 * (size_t)ri.num_verts);
        ccn_mesh_copy(r, p, NULL, NULL, NULL, NULL);
        for (int32_t v = 0; v < nv; v++) {
            int c = v == corner || (a >= 0 && (v == a || v == b));
            const double *q = p + 3 * (size_t)(nf + ne + v);
            if (c) CHECK(q[0] == P8[3 * v] && q[1] == P8[3 * v + 1] && q[2] == P8[3 * v + 2],
                         "corner %d moved to %g %g %g", v, q[0], q[1], q[2]);
        }
        free(p);
        ccn_mesh_destroy(r);
    }
    ccn_mesh_destroy(m);
}

/* Three triangles on edge 0-1. */
static void test_edge_three_faces(void) {
    int32_t fs[3] = {3, 3, 3}, fv[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    expect_nonmanifold(5, 3, fs, fv, 7, 0, 1, -1);
}

/* Two triangles meeting only at vertex 0 (a bowtie): vertex 0 is a corner. */
static void test_bowtie_vertex(void) {
    int32_t fs[2] = {3, 3}, fv[6] = {0, 1, 2, 0, 3, 4};
    expect_nonmanifold(5, 2, fs, fv, 6, -1, -1, 0);
}

static void test_two_gon(void) {
    int32_t fs[2] = {3, 2}, fv[5] = {0, 1, 2, 2, 3};
    expect_err(4, 2, fs, fv, P8, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 has 2 vertices");
}

static void test_repeated_vertex(void) {
    int32_t fs[2] = {3, 4}, fv[7] = {0, 1, 2, 1, 4, 5, 4};
    expect_err(6, 2, fs, fv, P8, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 1, "face 1 repeats vertex 4");
}

static void test_index_out_of_range(void) {
    int32_t fs[1] = {3}, fv[3] = {0, 1, 7};
    expect_err(3, 1, fs, fv, P8, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 0, "vertex index 7");
    int32_t fv2[3] = {0, -1, 2};
    expect_err(3, 1, fs, fv2, P8, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, 0, "vertex index -1");
}

/* Two quads using edge 0-1 in the same direction (one is flipped): edge 0-1 is non-manifold. */
static void test_orientation(void) {
    int32_t fs[2] = {4, 4}, fv[8] = {0, 1, 2, 3, 0, 1, 5, 4};
    expect_nonmanifold(6, 2, fs, fv, 7, 0, 1, -1);
}

static void test_nonfinite(void) {
    int32_t fs[1] = {4}, fv[4] = {0, 1, 2, 3};
    double p[12] = {0, 0, 0, 1, 0, 0, 1, 1, NAN, 0, 1, 0};
    expect_err(4, 1, fs, fv, p, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, 2, "vertex 2");
    p[8] = 0; p[10] = INFINITY;
    expect_err(4, 1, fs, fv, p, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, 3, "vertex 3");
}

static void test_arguments(void) {
    int32_t fs[1] = {4}, fv[4] = {0, 1, 2, 3};
    expect_err(-1, 1, fs, fv, P8, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "negative count");
    expect_err(4, -3, fs, fv, P8, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "negative count");
    expect_err(4, 0, fs, fv, P8, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "no faces");
    expect_err(4, 1, NULL, fv, P8, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "NULL");
    ccn_error err;
    ccn_mesh *m;
    CHECK(ccn_mesh_create(NULL, &m, &err) == CCN_ERR_ARGUMENT, "NULL cage");
    ccn_cage c = {0};
    c.num_verts = 4; c.num_faces = 1; c.positions = P8; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = 2; /* edge_verts missing */
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_ERR_ARGUMENT, "edge_verts NULL");
    CHECK(strstr(err.message, "edge_verts") != NULL, "%s", err.message);
}

static void test_isolated_and_loose(void) {
    int32_t fs[1] = {4}, fv[4] = {0, 1, 2, 3};
    int32_t ev[6] = {0, 2, 0, 1, 5, 6}; /* a diagonal (not an edge), a real edge, isolated pair */
    double kn[3] = {5.0, 2.0, 3.0};
    ccn_cage c = {0};
    c.num_verts = 8; c.num_faces = 1; c.positions = P8; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = 3; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = NULL;
    ccn_error err;
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_OK, "%s", err.message);
    if (!m) return;
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    CHECK(in.num_ignored_verts == 4, "ignored verts %d", in.num_ignored_verts);
    CHECK(in.num_ignored_edges == 2, "ignored edges %d", in.num_ignored_edges);
    CHECK(in.num_edges == 4 && in.num_boundary_edges == 4, "edges %d/%d", in.num_edges, in.num_boundary_edges);
    ccn_mesh_destroy(m);
}

/* Grid ring test: set one edge; its whole ring (computed here from grid geometry) takes
 * the value, every other edge stays 1. */
static void check_grid_rings(int nx, int ny, int32_t a, int32_t b, const double *vals, int nvals,
                             double expect, int expect_conflicts) {
    int32_t fs[64], fv[256], ev[8];
    double kn[4];
    int nf = make_grid(nx, ny, fs, fv);
    for (int i = 0; i < nvals; i++) {
        /* the i-th given edge: (a,b) shifted by i rows/columns along the ring */
        int horizontal = (b - a) == 1;
        int step = horizontal ? nx + 1 : 1;
        ev[2 * i] = a + i * step;
        ev[2 * i + 1] = b + i * step;
        kn[i] = vals[i];
    }
    ccn_cage c = {0};
    c.num_verts = (nx + 1) * (ny + 1); c.num_faces = nf; c.positions = grid_pos;
    c.face_sizes = fs; c.face_verts = fv; c.num_edges = nvals; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = NULL;
    ccn_error err;
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_OK, "%s", err.message);
    if (!m) return;
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    int32_t oev[512];
    double okn[256];
    ccn_mesh_copy(m, NULL, NULL, NULL, oev, okn);
    int in_ring = 0;
    int ax = a % (nx + 1), ay = a / (nx + 1), horizontal = (b - a) == 1;
    for (int e = 0; e < in.num_edges; e++) {
        int p = oev[2 * e], q = oev[2 * e + 1];
        int lo = p < q ? p : q, hi = p < q ? q : p;
        int lx = lo % (nx + 1);
        int ly = lo / (nx + 1);
        int ring = horizontal ? (hi - lo == 1 && lx == ax) : (hi - lo == nx + 1 && ly == ay);
        in_ring += ring;
        double want = ring ? expect : 1.0;
        CHECK(fabs(okn[e] - want) <= 1e-12 * want, "edge %d-%d: %g want %g", p, q, okn[e], want);
    }
    CHECK(in_ring == (horizontal ? ny + 1 : nx + 1), "ring size %d", in_ring);
    CHECK(in.num_ring_conflicts == expect_conflicts, "conflicts %d want %d", in.num_ring_conflicts,
          expect_conflicts);
    CHECK(in.num_rings == nx + ny, "rings %d", in.num_rings);
    ccn_mesh_destroy(m);
}

static void test_ring_single_edge(void) {
    double v1[1] = {3.5};
    check_grid_rings(4, 4, 6, 7, v1, 1, 3.5, 0);   /* horizontal edge (1,1)-(2,1) */
    check_grid_rings(4, 4, 7, 12, v1, 1, 3.5, 0);  /* vertical edge (2,1)-(2,2) */
    check_grid_rings(3, 5, 0, 1, v1, 1, 3.5, 0);   /* boundary edge */
}

static void test_ring_conflict_mean(void) {
    double v2[2] = {2.0, 4.0};
    check_grid_rings(4, 4, 6, 7, v2, 2, 3.0, 1);
    double v3[3] = {2.0, -1.0, NAN}; /* unset values do not vote */
    check_grid_rings(4, 4, 6, 7, v3, 3, 2.0, 0);
    double v4[2] = {5.0, 5.0}; /* agreeing values: no conflict */
    check_grid_rings(4, 4, 7, 12, v4, 2, 5.0, 0);
}

static void test_ring_cube(void) {
    static const double cp[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    int32_t fs[6] = {4, 4, 4, 4, 4, 4};
    int32_t fv[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    int32_t ev[2] = {0, 1};
    double kn[1] = {7.0};
    ccn_cage c = {0};
    c.num_verts = 8; c.num_faces = 6; c.positions = cp; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = 1; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = NULL;
    ccn_error err;
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_OK, "%s", err.message);
    if (!m) return;
    int32_t oev[24];
    double okn[12];
    ccn_mesh_copy(m, NULL, NULL, NULL, oev, okn);
    int n7 = 0;
    for (int e = 0; e < 12; e++) {
        const double *p = cp + 3 * oev[2 * e], *q = cp + 3 * oev[2 * e + 1];
        int along_x = p[0] != q[0];
        CHECK(fabs(okn[e] - (along_x ? 7.0 : 1.0)) < 1e-12, "cube edge %d: %g", e, okn[e]);
        n7 += along_x;
    }
    CHECK(n7 == 4, "ring of 4 x-edges, got %d", n7);
    ccn_mesh_destroy(m);
}

static void test_clamp_extreme_ratio(void) {
    int32_t fs[64], fv[256], ev[4] = {6, 7, 7, 12};
    double kn[2] = {1e-300, 1e300};
    int nf = make_grid(4, 4, fs, fv);
    ccn_cage c = {0};
    c.num_verts = 25; c.num_faces = nf; c.positions = grid_pos; c.face_sizes = fs; c.face_verts = fv;
    c.num_edges = 2; c.edge_verts = ev; c.edge_knots = kn;
    ccn_mesh *m = NULL, *r = NULL;
    ccn_error err;
    CHECK(ccn_mesh_create(&c, &m, &err) == CCN_OK, "%s", err.message);
    if (!m) return;
    double okn[64];
    ccn_mesh_copy(m, NULL, NULL, NULL, NULL, okn);
    double lo = INFINITY, hi = 0;
    for (int e = 0; e < 40; e++) { lo = okn[e] < lo ? okn[e] : lo; hi = okn[e] > hi ? okn[e] : hi; }
    CHECK(hi == 1e300, "largest kept: %g", hi);
    CHECK(lo >= 1e-6 * hi * (1 - 1e-12), "clamped to 1e-6 ratio: %g", lo / hi);
    ccn_options o = {0};
    CHECK(ccn_refine(m, 3, &o, &r, &err) == CCN_OK, "%s", err.message);
    if (r) {
        ccn_mesh_info in;
        ccn_mesh_get_info(r, &in);
        double *pos = malloc(sizeof(double) * 3 * in.num_verts);
        ccn_mesh_copy(r, pos, NULL, NULL, NULL, NULL);
        int finite = 1;
        for (int i = 0; i < 3 * in.num_verts; i++) finite &= isfinite(pos[i]);
        CHECK(finite, "refined positions finite");
        free(pos);
    }
    ccn_mesh_destroy(r);
    ccn_mesh_destroy(m);
}

static void test_refine_arguments(void) {
    int32_t fs[64], fv[256];
    int nf = make_grid(2, 2, fs, fv);
    ccn_mesh *m = NULL, *r = (ccn_mesh *)1;
    ccn_error err;
    CHECK(create(9, nf, fs, fv, grid_pos, &err, &m) == CCN_OK, "%s", err.message);
    CHECK(ccn_refine(m, -1, NULL, &r, &err) == CCN_ERR_ARGUMENT && r == NULL, "levels -1");
    CHECK(strstr(err.message, "levels") != NULL, "%s", err.message);
    ccn_options o = {0};
    o.scheme = (ccn_scheme)7;
    CHECK(ccn_refine(m, 1, &o, &r, &err) == CCN_ERR_ARGUMENT, "bad scheme");
    CHECK(ccn_refine(NULL, 1, NULL, &r, &err) == CCN_ERR_ARGUMENT, "NULL mesh");
    CHECK(ccn_refine(m, 15, NULL, &r, &err) == CCN_ERR_MEMORY, "size overflow is an error: %s", err.message);
    ccn_mesh_destroy(m);
}

int main(void) {
    RUN(test_edge_three_faces);
    RUN(test_bowtie_vertex);
    RUN(test_two_gon);
    RUN(test_repeated_vertex);
    RUN(test_index_out_of_range);
    RUN(test_orientation);
    RUN(test_nonfinite);
    RUN(test_arguments);
    RUN(test_isolated_and_loose);
    RUN(test_ring_single_edge);
    RUN(test_ring_conflict_mean);
    RUN(test_ring_cube);
    RUN(test_clamp_extreme_ratio);
    RUN(test_refine_arguments);
    return TEST_SUMMARY();
}
