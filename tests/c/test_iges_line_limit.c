/* An IGES section longer than its 7-digit sequence numbers allow is refused with a message,
 * not written past its line buffer. The limit (9,999,999 lines) is reached only by exports of
 * about a million control points (OpenSubdiv's catmark_car unpacked: 276,210 faces); so this
 * test compiles its own copy of the IGES writer with a limit of 60 lines (the library's copy is
 * then not linked: the archive member is pulled only for an undefined symbol) and exports a
 * torus through the public ccn_plan_export: IGES is refused naming the limit and the way out,
 * nothing is written, STEP of the same plan is written. */
#define CCN_IGES_MAX_LINES 60
#include "io/iges.c"

#include "testlib.h"

typedef struct { size_t n; } counter;

static int count_fn(void *user, const char *data, size_t len) {
    (void)data;
    ((counter *)user)->n += len;
    return 0;
}

static ccn_plan *torus(ccn_obj **obj, int flags_levels) {
    size_t len;
    char *text = tl_slurp("tests/data/torus.obj", &len);
    ccn_cage cage;
    ccn_error err;
    ccn_plan *p = NULL;
    ccn_options o = {0};
    o.levels = flags_levels;
    if (!text || ccn_obj_parse(text, len, obj, &err) || ccn_obj_get_cage(*obj, &cage) ||
        ccn_plan_create(&cage, &o, &p, &err))
        p = NULL;
    free(text);
    return p;
}

static void iges_over_the_line_limit_is_refused(void) {
    ccn_obj *obj = NULL;
    ccn_plan *p = torus(&obj, 2);
    CHECK(p != NULL, "plan of tests/data/torus.obj");
    if (!p) return;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    eo.flags = CCN_EXPORT_UNPACKED; /* 48 faces: far more than 60 parameter lines */
    eo.format = CCN_EXPORT_IGES;
    counter c = {0};
    ccn_error err;
    ccn_status st = ccn_plan_export(p, NULL, &eo, count_fn, &c, NULL, &err);
    CHECK(st == CCN_ERR_ARGUMENT, "IGES over the limit: status %d", (int)st);
    CHECK(strstr(err.message, "more than 60 lines") != NULL && strstr(err.message, "export STEP") != NULL,
          "message: %s", err.message);
    CHECK(c.n == 0, "%zu bytes written before the refusal", c.n);
    eo.format = CCN_EXPORT_STEP;
    c.n = 0;
    st = ccn_plan_export(p, NULL, &eo, count_fn, &c, NULL, &err);
    CHECK(st == CCN_OK && c.n > 0, "STEP of the same plan: status %d, %zu bytes", (int)st, c.n);
    /* packed, the torus is one face: written if its IGES fits in 60 lines, else refused the same way */
    eo.format = CCN_EXPORT_IGES;
    eo.flags = 0;
    c.n = 0;
    st = ccn_plan_export(p, NULL, &eo, count_fn, &c, NULL, &err);
    CHECK((st == CCN_OK && c.n > 0) || (st == CCN_ERR_ARGUMENT && c.n == 0), "packed IGES: status %d", (int)st);
    printf("  unpacked IGES refused (%s); packed IGES: %s\n", err.message, st == CCN_OK ? "written" : "refused");
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

int main(void) {
    RUN(iges_over_the_line_limit_is_refused);
    return TEST_SUMMARY();
}
