/* Shared checks for the libFuzzer harnesses in tests/fuzz/ (and tests that replay them).
 * A failed check prints what failed and aborts, which libFuzzer reports as a crash and
 * saves the input under build/fuzz/. */
#ifndef CCN_FUZZ_COMMON_H
#define CCN_FUZZ_COMMON_H
#include "ccnurbs.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FZ_CHECK(cond, ...)                                                             \
    do {                                                                                \
        if (!(cond)) {                                                                  \
            fprintf(stderr, "FUZZ CHECK FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                               \
            fputc('\n', stderr);                                                        \
            abort();                                                                    \
        }                                                                               \
    } while (0)

/* Library bugs found earlier (tests/c/test_fixed_bugs.c), all fixed; the checks are strict:
 *   KB1: an interior vertex of valence 2 (e.g. a two-face "pillow") is accepted by
 *        ccn_mesh_create, but ccn_refine with the eigen scheme fails at level >= 2 with
 *        CCN_ERR_ARGUMENT "extraordinary vertex N: refinement matrix failed";
 *        ccn_plan_create fails for every scheme (nurss, cc: "ev matrix: valence 2 outside
 *        [3, 65536]").
 *   KB2b: finite coordinates near DBL_MAX (the bounding box reaching it) can still give
 *        Inf after the unit-box fix of KB2 (points mapped back from slightly outside the
 *        box overflow). Tolerated only for |coordinate| > FZ_HUGE = 1e300.
 *   KB3: ccn_plan_evaluate(plan, NULL, ...) after a call with explicit positions reuses
 *        those positions, not "the cage's own positions" (ccnurbs.h). */
#define FZ_HUGE 1e300

static inline int fz_known_bugs(void) { return 1; } /* KB1, KB2b, KB3 are fixed: strict */
/* Largest |coordinate| of a mesh (KB2b) and whether it has an interior vertex of valence 2
 * (KB1). */
static inline void fz_mesh_facts(const ccn_mesh *m, double *maxabs, int *interior_v2) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    double *p = malloc(sizeof(double) * 3 * (size_t)(in.num_verts + 1));
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)(in.num_faces + 1));
    int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)(in.num_edges + 1));
    int32_t *cnt = calloc(2 * (size_t)(in.num_verts + 1), sizeof(int32_t));
    int32_t *fv = malloc(sizeof(int32_t) * (size_t)(in.num_face_verts + 1));
    if (!p || !fs || !ev || !cnt || !fv) abort();
    ccn_mesh_copy(m, p, fs, fv, ev, NULL);
    *maxabs = 0;
    for (int32_t i = 0; i < 3 * in.num_verts; i++) *maxabs = fmax(*maxabs, fabs(p[i]));
    for (int32_t i = 0; i < 2 * in.num_edges; i++) cnt[2 * ev[i]]++;      /* edges at v */
    for (int32_t i = 0; i < in.num_face_verts; i++) cnt[2 * fv[i] + 1]++; /* faces at v */
    *interior_v2 = 0;
    for (int32_t v = 0; v < in.num_verts; v++)
        if (cnt[2 * v] == 2 && cnt[2 * v + 1] == 2) *interior_v2 = 1;
    free(p); free(fs); free(ev); free(cnt); free(fv);
}

/* An error struct filled with garbage, so that an unterminated message is noticed. */
static inline void fz_err_init(ccn_error *e) {
    memset(e, 0x5A, sizeof *e);
}

/* Every returned status is a known one, matches err.status, and the message is
 * NUL-terminated (and non-empty on error). */
static inline void fz_check_status(ccn_status st, const ccn_error *e, const char *call) {
    FZ_CHECK((int)st >= (int)CCN_OK && (int)st <= (int)CCN_ERR_IO, "%s: status %d", call, (int)st);
    FZ_CHECK(memchr(e->message, '\0', sizeof e->message) != NULL,
             "%s: err.message not NUL-terminated", call);
    FZ_CHECK(e->status == st, "%s: err.status %d != returned %d (%s)", call, (int)e->status,
             (int)st, e->message);
    if (st != CCN_OK) {
        FZ_CHECK(e->message[0] != '\0', "%s: error %d with an empty message", call, (int)st);
        FZ_CHECK(e->element_kind >= CCN_ELEM_NONE && e->element_kind <= CCN_ELEM_VALUE,
                 "%s: element_kind %d", call, (int)e->element_kind);
        FZ_CHECK(e->element >= -1, "%s: element %d", call, (int)e->element);
    }
}

static inline void fz_check_finite(const double *p, size_t n, const char *what) {
    for (size_t i = 0; i < n; i++)
        FZ_CHECK(isfinite(p[i]), "%s[%zu] = %g is not finite", what, i, p[i]);
}

/* Refines `m` by `levels` with the given options and checks the result: counts follow the
 * refinement rule (V' = F + E + V, F' = sum of face sizes, all quads), indices are in range,
 * every position and interval is finite. Returns the status of ccn_refine. */
static inline ccn_status fz_refine_check(const ccn_mesh *m, int levels, const ccn_options *o) {
    ccn_error e;
    fz_err_init(&e);
    ccn_mesh *r = (ccn_mesh *)&e; /* must be overwritten */
    ccn_status st = ccn_refine(m, levels, o, &r, &e);
    fz_check_status(st, &e, "ccn_refine");
    double maxabs;
    int interior_v2;
    fz_mesh_facts(m, &maxabs, &interior_v2);
    if (st != CCN_OK) {
        FZ_CHECK(r == NULL, "ccn_refine failed but returned a mesh");
        if (!fz_known_bugs() && interior_v2 && st == CCN_ERR_ARGUMENT &&
            strstr(e.message, "refinement matrix failed"))
            return st; /* KB1 */
        FZ_CHECK(st == CCN_ERR_MEMORY, "ccn_refine of a valid mesh failed: %d %s", (int)st,
                 e.message);
        return st;
    }
    FZ_CHECK(r != NULL, "ccn_refine OK without a mesh");
    ccn_mesh_info in0, in;
    FZ_CHECK(ccn_mesh_get_info(m, &in0) == CCN_OK, "info");
    FZ_CHECK(ccn_mesh_get_info(r, &in) == CCN_OK, "info");
    FZ_CHECK(in.level == in0.level + levels, "level %d after %d levels from %d", in.level,
             levels, in0.level);
    if (levels == 1) {
        int64_t nv = (int64_t)in0.num_faces + in0.num_edges + in0.num_verts;
        FZ_CHECK(in.num_verts == nv, "refined verts %d, expected %lld", in.num_verts,
                 (long long)nv);
        FZ_CHECK(in.num_faces == in0.num_face_verts, "refined faces %d, expected %d",
                 in.num_faces, in0.num_face_verts);
        FZ_CHECK(in.num_edges == 2 * in0.num_edges + in0.num_face_verts, "refined edges %d",
                 in.num_edges);
    }
    if (levels >= 1) FZ_CHECK(in.num_face_verts == 4 * in.num_faces, "not all quads");
    FZ_CHECK(in.num_ev_fallbacks >= 0 && in.num_ring_conflicts >= 0, "counts");
    double *pos = malloc(sizeof(double) * 3 * (size_t)(in.num_verts + 1));
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)(in.num_faces + 1));
    int32_t *fv = malloc(sizeof(int32_t) * (size_t)(in.num_face_verts + 1));
    int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)(in.num_edges + 1));
    double *kn = malloc(sizeof(double) * (size_t)(in.num_edges + 1));
    FZ_CHECK(pos && fs && fv && ev && kn, "harness out of memory");
    FZ_CHECK(ccn_mesh_copy(r, pos, fs, fv, ev, kn) == CCN_OK, "copy");
    if (fz_known_bugs() || maxabs <= FZ_HUGE) /* KB2b */
        fz_check_finite(pos, 3 * (size_t)in.num_verts, "refined position");
    for (int32_t i = 0; i < in.num_faces; i++) FZ_CHECK(fs[i] >= 3, "face %d size %d", i, fs[i]);
    for (int32_t i = 0; i < in.num_face_verts; i++)
        FZ_CHECK(fv[i] >= 0 && fv[i] < in.num_verts, "face vertex %d out of range", fv[i]);
    for (int32_t i = 0; i < 2 * in.num_edges; i++)
        FZ_CHECK(ev[i] >= 0 && ev[i] < in.num_verts, "edge vertex %d out of range", ev[i]);
    for (int32_t i = 0; i < in.num_edges; i++)
        FZ_CHECK(isfinite(kn[i]) && kn[i] > 0, "refined interval %d = %g", i, kn[i]);
    free(pos); free(fs); free(fv); free(ev); free(kn);
    ccn_mesh_destroy(r);
    return st;
}

/* Creates a mesh from `c` and checks the status; on success checks the info counts. */
static inline ccn_status fz_create_check(const ccn_cage *c, ccn_mesh **out) {
    ccn_error e;
    fz_err_init(&e);
    *out = (ccn_mesh *)&e;
    ccn_status st = ccn_mesh_create(c, out, &e);
    fz_check_status(st, &e, "ccn_mesh_create");
    if (st != CCN_OK) {
        FZ_CHECK(*out == NULL, "ccn_mesh_create failed but returned a mesh");
        return st;
    }
    FZ_CHECK(*out != NULL, "ccn_mesh_create OK without a mesh");
    ccn_mesh_info in;
    FZ_CHECK(ccn_mesh_get_info(*out, &in) == CCN_OK, "info");
    FZ_CHECK(in.num_verts == c->num_verts && in.num_faces == c->num_faces, "counts %d %d",
             in.num_verts, in.num_faces);
    FZ_CHECK(in.num_ignored_verts >= 0 && in.num_ignored_verts <= in.num_verts, "ignored");
    FZ_CHECK(in.num_ignored_edges >= 0 && in.num_ignored_edges <= c->num_edges, "ignored e");
    FZ_CHECK(in.level == 0, "level %d", in.level);
    return st;
}

/* A double from one byte: special values for small bytes, else a small coordinate. */
static inline double fz_special(uint8_t b) {
    static const double sp[24] = {
        0.0, 1.0, -1.0, 0.5, NAN, INFINITY, -INFINITY, 1e300, -1e300, 1e-300,
        1.7976931348623157e308,
        2.2250738585072014e-308, 4.9e-324, 1e30, -1e30, 1e-30, 1e9, 1e-9, 1e15, -0.0,
        3.0, 1e6, 1e-6, 2.5};
    if (b < 24) return sp[b];
    return ((double)b - 140.0) / 16.0;
}

#endif
