/* libFuzzer harness: bytes -> a cage -> ccn_mesh_create -> ccn_refine with every scheme and
 * corner rule (1 level; 2 levels for one of them, picked by the input), plus
 * ccn_mesh_set_positions and ccn_ev_matrix on values taken from the input.
 *
 * Input layout (every read past the end gives 0):
 *   byte 0: mode = b & 3 (0, 1: raw polygon soup; 2: quad grid; 3: quad fan around one
 *           vertex), b & 4: coordinates as raw 8-byte doubles (raw mode), b & 8: negative
 *           counts, b & 16: edge_verts NULL with num_edges > 0, b & 32: also call
 *           ccn_ev_matrix, b & 64: also ccn_mesh_set_positions with input values.
 *   raw soup: nv, nf, face sizes (0..9), indices (-1..nv), coordinates, edges, intervals.
 *   grid: nx, ny (1..6), a triangulation mask, a face-deletion mask, then per vertex one
 *         byte (a special value, NaN/Inf/1e300/..., for a few, else a small jitter).
 *   fan: valence k (3..66), closed/open, then per vertex one byte as for the grid.
 *   then: given edges (count, a face corner or a raw vertex pair each) and their intervals
 *         (special values: negative, 0, NaN, Inf, 1e-300, 1e300, ...; or ratios up to 1e9),
 *         [if edges: a byte, edge_knots NULL if even]; [b & 8: a byte of negative counts];
 *         a byte picking the (scheme, corners) refined 2 levels; [b & 64: new positions].
 * Sizes are bounded (<= 67 faces before refinement) so that one input runs in milliseconds.
 */
#include "fuzz_cage.h"

static void check_ev_matrix(rd *r) {
    int32_t n = (int32_t)(next(r) % 70) - 1;
    static double d[70], M[139 * 139];
    for (int i = 0; i < 70; i++) d[i] = next_knot(r);
    ccn_scheme sc = (ccn_scheme)(next(r) % 3);
    ccn_ev_info info;
    ccn_error e;
    fz_err_init(&e);
    ccn_status st = ccn_ev_matrix(n, d, sc, M, &info, &e);
    fz_check_status(st, &e, "ccn_ev_matrix");
    if (n < 3) FZ_CHECK(st == CCN_ERR_ARGUMENT, "valence %d accepted", n);
    if (st != CCN_OK) return;
    int32_t sz = 2 * n + 1;
    fz_check_finite(M, (size_t)sz * sz, "M");
    FZ_CHECK(isfinite(info.lambda) && info.lambda > 0 && info.lambda < 1, "lambda %g", info.lambda);
    for (int32_t i = 0; i < sz; i++) {
        double sum = 0;
        for (int32_t j = 0; j < sz; j++) sum += M[(size_t)i * sz + j];
        FZ_CHECK(fabs(sum - 1.0) < 1e-6, "row %d of M sums to %.17g", i, sum);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    rd r = {data, size, 0};
    static soup s;
    uint8_t flags = next(&r);
    fz_make_cage(&r, &s, flags);
    ccn_cage c = {0};
    c.num_verts = s.nv; c.num_faces = s.nf; c.num_edges = s.ne;
    c.positions = s.pos; c.face_sizes = s.fs; c.face_verts = s.fv;
    c.edge_verts = s.ne ? s.ev : NULL;
    c.edge_knots = s.ne && (next(&r) & 1) ? s.kn : NULL;
    uint8_t cb = next(&r);
    if ((cb & 1) && s.ne) c.edge_creases = s.cr;
    if (cb & 2) c.vertex_creases = s.vc;
    if (flags & 8) {
        uint8_t b = next(&r);
        if (b & 1) c.num_verts = -1 - b;
        if (b & 2) c.num_faces = -1;
        if (b & 4) c.num_edges = -2;
    }
    if ((flags & 16) && s.ne) c.edge_verts = NULL;

    int nonfinite = fz_nonfinite(&s);

    ccn_mesh *m = NULL;
    ccn_status st = fz_create_check(&c, &m);
    if (c.num_verts < 0 || c.num_faces < 0 || c.num_edges < 0 || c.num_faces == 0 ||
        (c.num_edges > 0 && !c.edge_verts))
        FZ_CHECK(st == CCN_ERR_ARGUMENT, "bad counts/arrays gave %d", (int)st);
    if (nonfinite && c.num_verts > 0) FZ_CHECK(st != CCN_OK, "non-finite coordinate accepted");
    if (st == CCN_OK) {
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        uint8_t sel = next(&r); /* which (scheme, corners) also gets 2 levels */
        for (int sc = 0; sc < 3; sc++)
            for (int corners = 0; corners < 2; corners++) {
                ccn_options o = {0};
                o.scheme = (ccn_scheme)sc;
                o.boundary_corners = corners;
                o.crease_method = (corners + sc) & 1;
                fz_refine_check(m, 1, &o);
                if (sc == sel % 3 && corners == ((sel >> 2) & 1)) fz_refine_check(m, 2, &o);
            }
        if (flags & 64) {
            static double p2[3 * MAXV];
            int bad = 0;
            for (int32_t k = 0; k < 3 * s.nv; k++) {
                p2[k] = fz_special(next(&r));
                bad |= !isfinite(p2[k]) || fabs(p2[k]) > FZ_HUGE;
            }
            ccn_error e;
            fz_err_init(&e);
            st = ccn_mesh_set_positions(m, p2, &e);
            fz_check_status(st, &e, "ccn_mesh_set_positions");
            FZ_CHECK(bad ? st == CCN_ERR_ARGUMENT : st == CCN_OK, "set_positions %d", (int)st);
            ccn_options o = {0};
            if (st == CCN_OK) fz_refine_check(m, 2, &o);
        }
        ccn_mesh_destroy(m);
    }
    if (flags & 32) check_ev_matrix(&r);
    return 0;
}
