/* libFuzzer harness: bytes -> a cage (fuzz_cage.h) and options (including out-of-range
 * scheme, cap, levels and corners) -> ccn_plan_create + ccn_plan_get_sizes / _get_stats + ccn_plan_evaluate
 * (cage positions, then positions from the input, then with optional outputs left NULL).
 * Checks: statuses in range, messages NUL-terminated, invalid options and cages rejected,
 * sizes consistent, every position and normal finite (normals of unit length), indices in
 * range, topology outputs identical between calls; ccn_plan_patches: degree 3 or 5, finite
 * control points, cage face in range; a face-varying channel and per-vertex data from the
 * input (fvar_stage); an interval edit through ccn_plan_create with options.previous and ccn_plan_evaluate_changed,
 * byte-identical to a new plan (edit_stage). Output buffers are allocated at exactly
 * the sizes ccn_plan_get_sizes gives, so ASan catches any write past them.
 * Input: byte 0 flags (as fuzz_mesh.c), the cage, then scheme, cap, levels, corners,
 * threads bytes, then positions for the second evaluation. Built only once the library
 * defines ccn_plan_evaluate (tests/fuzz/fuzz.mk). */
#include "fuzz_cage.h"
#include "../c/plan_with.h"

static void check_outputs(const ccn_sizes *z, const ccn_limit_mesh *out, int32_t cage_faces) {
    fz_check_finite(out->positions, 3 * (size_t)z->num_verts, "limit position");
    if (out->normals) {
        fz_check_finite(out->normals, 3 * (size_t)z->num_verts, "limit normal");
        for (int32_t v = 0; v < z->num_verts; v++) {
            const double *n = out->normals + 3 * (size_t)v;
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            FZ_CHECK(fabs(len - 1.0) <= 1e-6, "normal %d has length %.17g", v, len);
        }
    }
    if (out->face_verts)
        for (int64_t i = 0; i < 4 * (int64_t)z->num_faces; i++)
            FZ_CHECK(out->face_verts[i] >= 0 && out->face_verts[i] < z->num_verts,
                     "face vertex %d out of [0, %d)", out->face_verts[i], z->num_verts);
    if (out->face_origin)
        for (int32_t f = 0; f < z->num_faces; f++)
            FZ_CHECK(out->face_origin[f] >= 0 && out->face_origin[f] < cage_faces,
                     "face origin %d out of [0, %d)", out->face_origin[f], cage_faces);
}

typedef struct { int32_t cage_faces, count, strict; } patch_ctx;

static void on_patch(void *user, int32_t degree, const double *points, int32_t cage_face) {
    patch_ctx *c = user;
    FZ_CHECK(degree == 3 || degree == 5, "patch degree %d", degree);
    FZ_CHECK(cage_face >= 0 && cage_face < c->cage_faces, "patch cage face %d of %d", cage_face,
             c->cage_faces);
    if (c->strict) /* KB2b */
        fz_check_finite(points, 3 * (size_t)(degree + 1) * (size_t)(degree + 1), "patch point");
    c->count++;
}

/* 4: a face-varying channel from the input (value indices per cage corner, some out of range;
 * values, some non-finite; width 1..3; a mode, 6 invalid) and per-vertex data. A bad channel
 * must be refused with CCN_ERR_ARGUMENT; a good one gives exactly sized outputs: finite values,
 * face values in range, the same face values for new values, and vertex data finite. */
static void fvar_stage(ccn_plan *plan, const ccn_cage *c, const ccn_sizes *z, rd *r) {
    int32_t nc = 0;
    for (int32_t f = 0; f < c->num_faces; f++) nc += c->face_sizes[f];
    uint8_t hb = next(r);
    int32_t width = 1 + hb % 3, nvals = 1 + next(r) % 32, mode = next(r) % 7;
    int32_t *idx = malloc(sizeof(int32_t) * (size_t)(nc + 1));
    double *vals = malloc(sizeof(double) * (size_t)width * (size_t)nvals);
    FZ_CHECK(idx && vals, "harness out of memory");
    int bad = mode > CCN_FVAR_LINEAR_ALL;
    for (int32_t i = 0; i < nc; i++) {
        uint8_t b = next(r);
        idx[i] = b == 255 ? nvals : b == 254 ? -1 : (hb & 8) ? i % nvals : b % nvals;
        bad |= idx[i] < 0 || idx[i] >= nvals;
    }
    for (int32_t k = 0; k < width * nvals; k++) {
        uint8_t b = next(r);
        vals[k] = b < 8 ? fz_special(b) : ((double)b - 128.0) / 32.0;
        bad |= !isfinite(vals[k]) || fabs(vals[k]) > FZ_HUGE;
    }
    ccn_fvar_channel ch = {width, nvals, vals, idx, mode};
    ccn_error e;
    fz_err_init(&e);
    int32_t id = -1;
    ccn_status st = ccn_plan_add_fvar(plan, &ch, &id, &e);
    fz_check_status(st, &e, "ccn_plan_add_fvar");
    if (bad) FZ_CHECK(st == CCN_ERR_ARGUMENT, "a bad channel gave %d", (int)st);
    else FZ_CHECK(st == CCN_OK || st == CCN_ERR_MEMORY, "add_fvar: %d %s", (int)st, e.message);
    if (st == CCN_OK) {
        ccn_fvar_sizes fs;
        FZ_CHECK(ccn_plan_get_fvar_sizes(plan, id, &fs) == CCN_OK, "ccn_plan_get_fvar_sizes");
        FZ_CHECK(fs.width == width && fs.num_cage_values == nvals && fs.num_values > 0 &&
                     fs.num_values <= 4 * (int64_t)z->num_faces,
                 "fvar sizes: width %d, %d cage values, %d values", fs.width, fs.num_cage_values,
                 fs.num_values);
        size_t nf4 = 4 * (size_t)z->num_faces;
        double *out = malloc(sizeof(double) * (size_t)width * (size_t)fs.num_values);
        int32_t *fvv = malloc(sizeof(int32_t) * nf4), *fvv2 = malloc(sizeof(int32_t) * nf4);
        FZ_CHECK(out && fvv && fvv2, "harness out of memory");
        fz_err_init(&e);
        st = ccn_plan_evaluate_fvar(plan, id, NULL, out, fvv, &e);
        fz_check_status(st, &e, "ccn_plan_evaluate_fvar");
        FZ_CHECK(st == CCN_OK, "evaluate_fvar: %d %s", (int)st, e.message);
        fz_check_finite(out, (size_t)width * (size_t)fs.num_values, "limit value");
        for (size_t i = 0; i < nf4; i++)
            FZ_CHECK(fvv[i] >= 0 && fvv[i] < fs.num_values, "face value %d of %d", fvv[i], fs.num_values);
        for (int32_t k = 0; k < width * nvals; k++) vals[k] = 0.5 * vals[k] + 1.0;
        fz_err_init(&e);
        st = ccn_plan_evaluate_fvar(plan, id, vals, out, fvv2, &e);
        fz_check_status(st, &e, "ccn_plan_evaluate_fvar(values)");
        FZ_CHECK(st == CCN_OK, "evaluate_fvar(values): %d %s", (int)st, e.message);
        fz_check_finite(out, (size_t)width * (size_t)fs.num_values, "limit value");
        FZ_CHECK(memcmp(fvv, fvv2, sizeof(int32_t) * nf4) == 0, "face values changed");
        free(out); free(fvv); free(fvv2);
    }
    /* per-vertex data: the cage's x coordinate and a constant (affine: stays within range) */
    double *vd = malloc(sizeof(double) * 2 * (size_t)(c->num_verts + 1));
    double *vo = malloc(sizeof(double) * 2 * (size_t)(z->num_verts + 1));
    FZ_CHECK(vd && vo, "harness out of memory");
    int vbad = 0;
    for (int32_t v = 0; v < c->num_verts; v++) {
        vd[2 * v] = c->positions[3 * (size_t)v];
        vd[2 * v + 1] = 1.0;
        vbad |= !isfinite(vd[2 * v]) || fabs(vd[2 * v]) > FZ_HUGE;
    }
    fz_err_init(&e);
    st = ccn_plan_evaluate_vertex_data(plan, 2, vd, vo, &e);
    fz_check_status(st, &e, "ccn_plan_evaluate_vertex_data");
    if (!vbad) {
        FZ_CHECK(st == CCN_OK || st == CCN_ERR_MEMORY, "vertex data: %d %s", (int)st, e.message);
        if (st == CCN_OK) {
            fz_check_finite(vo, 2 * (size_t)z->num_verts, "vertex data");
            for (int32_t v = 0; v < z->num_verts; v++)
                FZ_CHECK(fabs(vo[2 * v + 1] - 1.0) <= 1e-9, "a constant gave %.17g", vo[2 * v + 1]);
        }
    }
    free(vd); free(vo); free(idx); free(vals);
}

/* 5: an interval edit (one edge's interval from the input): the plan recreated from this one
 * (ccn_plan_create with options.previous) and evaluated by ccn_plan_evaluate_changed into this plan's last output
 * gives the same status as a new plan of the edited cage and, when both succeed, the same
 * bytes (positions, normals). *plan is consumed; the recreated plan (or NULL) replaces it. */
static void edit_stage(ccn_plan **plan, const ccn_cage *c, const ccn_options *o, const ccn_sizes *z,
                       const ccn_plan_stats *zs, int strict, rd *r) {
    /* two more plans: only for cages up to valence and face size 12 whose plan verified no
     * eigen polyhedron (ccn_plan_stats.num_ev_verified: that verification, made again by the new
     * plan, takes some inputs past the fuzzer's 10 s; test_recreate covers such cages) */
    if (c->num_edges <= 0 || !c->edge_verts || zs->num_ev_verified > 0) return;
    int32_t *deg = calloc((size_t)c->num_verts + 1, sizeof(int32_t));
    FZ_CHECK(deg != NULL, "harness out of memory");
    int big = 0;
    for (int32_t f = 0, at = 0; f < c->num_faces; at += c->face_sizes[f++]) {
        big |= c->face_sizes[f] > 12;
        for (int32_t k = 0; k < c->face_sizes[f]; k++)
            if (c->face_verts[at + k] >= 0 && c->face_verts[at + k] < c->num_verts) big |= ++deg[c->face_verts[at + k]] > 12;
    }
    free(deg);
    if (big) return;
    size_t nv3 = 3 * (size_t)z->num_verts;
    double *a = malloc(sizeof(double) * 2 * nv3), *b = malloc(sizeof(double) * 2 * nv3);
    double *kn = malloc(sizeof(double) * (size_t)c->num_edges);
    FZ_CHECK(a && b && kn, "harness out of memory");
    ccn_limit_mesh la = {.positions = a, .normals = a + nv3}, lb = {.positions = b, .normals = b + nv3};
    ccn_error e;
    fz_err_init(&e);
    ccn_status s0 = ccn_plan_evaluate(*plan, NULL, &la, &e); /* the last output before the edit */
    for (int32_t i = 0; i < c->num_edges; i++) kn[i] = c->edge_knots ? c->edge_knots[i] : 1.0;
    uint8_t eb = next(r), vb = next(r);
    kn[eb % c->num_edges] = vb < 8 ? fz_special(vb) : (double)vb / 16.0;
    ccn_cage c2 = *c;
    c2.edge_knots = kn;
    ccn_plan *fresh = NULL, *next_plan = NULL;
    fz_err_init(&e);
    ccn_status sf = ccn_plan_create(&c2, o, &fresh, &e);
    fz_check_status(sf, &e, "ccn_plan_create(edited)");
    fz_err_init(&e);
    ccn_status sr = plan_recreate(*plan, &c2, o, NULL, &next_plan, &e);
    *plan = next_plan;
    fz_check_status(sr, &e, "ccn_plan_create with options.previous");
    FZ_CHECK(sr == sf || sr == CCN_ERR_MEMORY || sf == CCN_ERR_MEMORY,
             "recreate gave %d, a new plan %d", (int)sr, (int)sf);
    FZ_CHECK((sr == CCN_OK) == (next_plan != NULL), "recreate %d with plan %p", (int)sr, (void *)next_plan);
    if (sr == CCN_OK && sf == CCN_OK && s0 == CCN_OK) {
        ccn_sizes z2;
        FZ_CHECK(ccn_plan_get_sizes(next_plan, &z2) == CCN_OK && z2.num_verts == z->num_verts, "sizes changed");
        fz_err_init(&e);
        ccn_status e1 = ccn_plan_evaluate(fresh, NULL, &lb, &e);
        fz_err_init(&e);
        ccn_status e2 = ccn_plan_evaluate_changed(next_plan, NULL, &la, &e);
        fz_check_status(e2, &e, "ccn_plan_evaluate_changed");
        FZ_CHECK(e1 == e2 || e1 == CCN_ERR_MEMORY || e2 == CCN_ERR_MEMORY, "evaluate %d, changed %d", (int)e1, (int)e2);
        if (e1 == CCN_OK && e2 == CCN_OK && strict)
            FZ_CHECK(memcmp(a, b, sizeof(double) * 2 * nv3) == 0,
                     "ccn_plan_evaluate_changed differs from a new plan's evaluation");
    }
    ccn_plan_destroy(fresh);
    free(a); free(b); free(kn);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    rd r = {data, size, 0};
    static soup s;
    uint8_t flags = next(&r);
    fz_fan_max = 40; /* valence 3..40: both sides of the cap's valence limit, fast enough */
    fz_make_cage(&r, &s, flags);
    ccn_cage c = {0};
    c.num_verts = s.nv; c.num_faces = s.nf; c.num_edges = s.ne;
    c.positions = s.pos; c.face_sizes = s.fs; c.face_verts = s.fv;
    c.edge_verts = s.ne ? s.ev : NULL;
    c.edge_knots = s.ne ? s.kn : NULL;
    uint8_t cb = next(&r);
    if ((cb & 1) && s.ne) c.edge_creases = s.cr;
    if (cb & 2) c.vertex_creases = s.vc;
    if ((flags & 16) && s.ne) c.edge_verts = NULL;

    ccn_options o = {0};
    o.scheme = (ccn_scheme)(next(&r) % 4);     /* 3: invalid */
    o.cap = (ccn_cap)(next(&r) % 4);           /* 3: invalid */
    uint8_t lb = next(&r);
    o.levels = lb == 255 ? 1000 : lb == 254 ? INT32_MIN : (int32_t)(lb % 5) - 1; /* -1..3 */
    o.boundary_corners = next(&r) % 3;         /* 2: invalid */
    o.threads = next(&r) % 3;
    o.crease_method = next(&r) % 2;
    int opts_bad = o.scheme > CCN_SCHEME_CATMULL_CLARK || o.cap > CCN_CAP_G1_FILL ||
                   o.levels < 0 || o.boundary_corners > CCN_CORNERS_PINNED;
    int levels_huge = o.levels == 1000; /* must be refused: CCN_ERR_ARGUMENT or _MEMORY */

    /* Is the cage itself valid? (the plan must accept exactly the cages ccn_mesh_create does) */
    ccn_mesh *m = NULL;
    ccn_status mst = fz_create_check(&c, &m);
    double maxabs = 0;
    int interior_v2 = 0;
    if (mst == CCN_OK) fz_mesh_facts(m, &maxabs, &interior_v2);
    int strict = fz_known_bugs() || maxabs <= FZ_HUGE; /* KB2b */
    ccn_mesh_destroy(m);

    ccn_error e;
    fz_err_init(&e);
    ccn_plan *plan = (ccn_plan *)&e;
    ccn_status st = ccn_plan_create(&c, &o, &plan, &e);
    fz_check_status(st, &e, "ccn_plan_create");
    if (st != CCN_OK) {
        FZ_CHECK(plan == NULL, "plan_create failed but returned a plan");
        int kb1 = !fz_known_bugs() && interior_v2 && st == CCN_ERR_ARGUMENT &&
                  (strstr(e.message, "refinement matrix failed") ||
                   strstr(e.message, "valence 2 outside"));
        FZ_CHECK(opts_bad || levels_huge || mst != CCN_OK || st == CCN_ERR_MEMORY || kb1,
                 "valid cage and options rejected: %d %s", (int)st, e.message);
        return 0;
    }
    FZ_CHECK(plan != NULL, "plan_create OK without a plan");
    FZ_CHECK(!opts_bad && !levels_huge, "invalid options accepted (scheme %d cap %d levels %d corners %d)",
             (int)o.scheme, (int)o.cap, (int)o.levels, (int)o.boundary_corners);
    FZ_CHECK(mst == CCN_OK, "a cage ccn_mesh_create rejects (%d) gave a plan", (int)mst);

    ccn_sizes z;
    memset(&z, 0x5A, sizeof z);
    FZ_CHECK(ccn_plan_get_sizes(plan, &z) == CCN_OK, "ccn_plan_get_sizes");
    FZ_CHECK(z.num_cage_verts == c.num_verts, "num_cage_verts %d, cage %d", z.num_cage_verts,
             c.num_verts);
    FZ_CHECK(z.num_verts > 0 && z.num_faces > 0, "sizes %d %d", z.num_verts, z.num_faces);
    ccn_plan_stats zs;
    memset(&zs, 0x5A, sizeof zs);
    FZ_CHECK(ccn_plan_get_stats(plan, &zs) == CCN_OK, "ccn_plan_get_stats");
    FZ_CHECK(zs.levels == o.levels || (o.levels == 0 && zs.levels == 1), "levels %d for %d",
             zs.levels, o.levels);
    FZ_CHECK(zs.refine_levels >= 0 && zs.num_extraordinary >= 0 && zs.num_caps >= 0 &&
                 zs.num_cap_fallbacks >= 0 && zs.num_ev_fallbacks >= 0 &&
                 zs.num_ring_conflicts >= 0 && zs.num_ignored_verts >= 0 &&
                 zs.num_ignored_edges >= 0,
             "negative counts in ccn_plan_stats");
    if (z.num_verts > 2000000 || z.num_faces > 2000000) { ccn_plan_destroy(plan); return 0; }

    size_t nv3 = 3 * (size_t)z.num_verts, nf4 = 4 * (size_t)z.num_faces;
    double *pos = malloc(sizeof(double) * nv3), *nrm = malloc(sizeof(double) * nv3);
    int32_t *fv = malloc(sizeof(int32_t) * nf4), *fo = malloc(sizeof(int32_t) * z.num_faces);
    int32_t *fv2 = malloc(sizeof(int32_t) * nf4), *fo2 = malloc(sizeof(int32_t) * z.num_faces);
    FZ_CHECK(pos && nrm && fv && fo && fv2 && fo2, "harness out of memory");

    /* 1: the cage's own positions, every output */
    ccn_limit_mesh out = {.positions = pos, .normals = nrm, .face_verts = fv, .face_origin = fo};
    fz_err_init(&e);
    st = ccn_plan_evaluate(plan, NULL, &out, &e);
    fz_check_status(st, &e, "ccn_plan_evaluate");
    FZ_CHECK(st == CCN_OK || st == CCN_ERR_MEMORY, "evaluate failed: %d %s", (int)st, e.message);
    if (st == CCN_OK && strict) check_outputs(&z, &out, c.num_faces);
    double *pos1 = malloc(sizeof(double) * nv3);
    FZ_CHECK(pos1 != NULL, "harness out of memory");
    memcpy(pos1, pos, sizeof(double) * nv3);
    if (st == CCN_OK) {
        patch_ctx pc = {c.num_faces, 0, strict};
        int32_t skipped = -1;
        ccn_status pst = ccn_plan_patches(plan, on_patch, &pc, &skipped);
        FZ_CHECK(pst == CCN_OK, "ccn_plan_patches: %d", (int)pst);
        FZ_CHECK(skipped >= 0, "skipped %d", skipped);
    }

    /* 2: positions from the input (non-finite ones must be rejected), normals left NULL */
    double *p2 = malloc(sizeof(double) * 3 * (size_t)(c.num_verts + 1));
    FZ_CHECK(p2 != NULL, "harness out of memory");
    int bad = 0;
    for (int32_t k = 0; k < 3 * c.num_verts; k++) {
        uint8_t b = next(&r);
        p2[k] = b < 24 ? fz_special(b) : c.positions[k] + ((double)b - 140.0) / 64.0;
        bad |= !isfinite(p2[k]) || fabs(p2[k]) > FZ_HUGE; /* rejected beyond 1e300 */
    }
    double maxabs2 = 0;
    for (int32_t k = 0; k < 3 * c.num_verts; k++) maxabs2 = fmax(maxabs2, fabs(p2[k]));
    int strict2 = fz_known_bugs() || maxabs2 <= FZ_HUGE; /* KB2b */
    ccn_limit_mesh out2 = {.positions = pos, .face_verts = fv2, .face_origin = fo2};
    fz_err_init(&e);
    ccn_status st2 = ccn_plan_evaluate(plan, p2, &out2, &e);
    fz_check_status(st2, &e, "ccn_plan_evaluate(positions)");
    if (bad) FZ_CHECK(st2 == CCN_ERR_ARGUMENT, "non-finite positions gave %d", (int)st2);
    else FZ_CHECK(st2 == CCN_OK || st2 == CCN_ERR_MEMORY, "evaluate(positions): %d %s",
                  (int)st2, e.message);
    if (st2 == CCN_OK) {
        if (strict2) check_outputs(&z, &out2, c.num_faces);
        if (st == CCN_OK) {
            FZ_CHECK(memcmp(fv, fv2, sizeof(int32_t) * nf4) == 0, "face_verts changed");
            FZ_CHECK(memcmp(fo, fo2, sizeof(int32_t) * z.num_faces) == 0, "face_origin changed");
        }
    }

    /* 3: NULL positions again ("the cage's own positions"), positions output only; then a
     * NULL positions buffer must be an argument error. KB3: the library reuses the positions
     * of the previous call instead (KB3, fixed: strict). */
    double *pos3 = malloc(sizeof(double) * nv3);
    FZ_CHECK(pos3 != NULL, "harness out of memory");
    ccn_limit_mesh out3 = {.positions = pos3};
    fz_err_init(&e);
    ccn_status st3 = ccn_plan_evaluate(plan, NULL, &out3, &e);
    fz_check_status(st3, &e, "ccn_plan_evaluate(positions only)");
    int strict3 = fz_known_bugs() || st2 != CCN_OK ? strict : strict2; /* KB3 */
    if (st3 == CCN_OK && strict3) check_outputs(&z, &out3, c.num_faces);
    if (st3 == CCN_OK && st == CCN_OK && fz_known_bugs() && strict)
        FZ_CHECK(memcmp(pos1, pos3, sizeof(double) * nv3) == 0,
                 "KB3: evaluate(NULL) after evaluate(positions) does not use the cage's own");
    free(pos3);
    ccn_limit_mesh out4 = {.normals = nrm};
    fz_err_init(&e);
    st = ccn_plan_evaluate(plan, NULL, &out4, &e);
    fz_check_status(st, &e, "ccn_plan_evaluate(NULL positions)");
    FZ_CHECK(st == CCN_ERR_ARGUMENT, "NULL out->positions gave %d", (int)st);
    fz_err_init(&e);
    st = ccn_plan_evaluate(plan, NULL, NULL, &e);
    fz_check_status(st, &e, "ccn_plan_evaluate(NULL out)");
    FZ_CHECK(st == CCN_ERR_ARGUMENT, "NULL out gave %d", (int)st);

    fvar_stage(plan, &c, &z, &r);
    edit_stage(&plan, &c, &o, &z, &zs, strict, &r);
    free(p2); free(pos1); free(pos); free(nrm); free(fv); free(fo); free(fv2); free(fo2);
    ccn_plan_destroy(plan);
    return 0;
}
