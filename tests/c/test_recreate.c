/* ccn_plan_create with options.previous (interval edits): a plan made from the previous plan of the same
 * cage topology equals a new plan of the edited cage (same cache), output vertex by
 * output vertex (positions, normals, corner normals; same sizes and output mesh), along a
 * chain of edits (each plan made from the one before):
 * one ring's interval changed, the largest interval raised (every normalised interval
 * changes), nothing changed, a tiny interval, a random one; and near-uniform spokes, so that
 * non-uniform guided caps (taus) are built and kept or made again. Byte-identical positions,
 * normals and corner normals (intervals are normalised by powers of two, so what is copied
 * is exactly what would be computed). The oracle is the plan made from scratch,
 * whose surface the other suites check against OpenSubdiv, B-spline oracles and the papers.
 * A previous plan of another topology, other creases or other options is ignored: the
 * result is then byte-identical to a new plan. */
#include "ccnurbs.h"
#include "testlib.h"
#include "plan_with.h"

#include <math.h>
#include <string.h>

typedef struct {
    ccn_obj *obj;
    ccn_cage cage;
    int32_t ne, *ev;
    double *knots, *creases;
} edit_cage;

/* Interval of a new edge: 1 (random_knots 0), random in [0.05, 20] (1), or in [1, 1.02] (2:
 * spoke ratios within the guided cap's range, so non-uniform caps with taus are built; 3: [1,
 * 1.045], so some caps are blended with the refined limit near the end of the range). */
static double new_knot(int random_knots) {
    if (random_knots >= 2) return 1.0 + (random_knots == 2 ? 0.02 : 0.045) * tl_rand01();
    return random_knots ? 0.05 + 19.95 * tl_rand01() * tl_rand01() : 1.0;
}

/* The cage of an OBJ file with every edge listed (intervals by new_knot). */
static int load(const char *path, int random_knots, int random_creases, edit_cage *c) {
    memset(c, 0, sizeof *c);
    size_t len = 0;
    char *text = tl_slurp(path, &len);
    ccn_error err;
    if (!text || ccn_obj_parse(text, len, &c->obj, &err) != CCN_OK) { free(text); return 0; }
    free(text);
    ccn_obj_get_cage(c->obj, &c->cage);
    int64_t nh = 0;
    for (int32_t f = 0; f < c->cage.num_faces; f++) nh += c->cage.face_sizes[f];
    c->ev = malloc(sizeof(int32_t) * 2 * (size_t)nh);
    c->knots = malloc(sizeof(double) * (size_t)nh);
    c->creases = malloc(sizeof(double) * (size_t)nh);
    int64_t at = 0;
    for (int32_t f = 0; f < c->cage.num_faces; f++) {
        int32_t n = c->cage.face_sizes[f];
        for (int32_t k = 0; k < n; k++) {
            int32_t a = c->cage.face_verts[at + k], b = c->cage.face_verts[at + (k + 1) % n];
            if (a > b) continue; /* each interior edge once (its other half runs b -> a) */
            c->ev[2 * c->ne] = a;
            c->ev[2 * c->ne + 1] = b;
            c->knots[c->ne] = new_knot(random_knots);
            c->creases[c->ne] = random_creases && tl_rand01() < 0.1 ? 3 * tl_rand01() : 0.0;
            c->ne++;
        }
        at += n;
    }
    /* boundary edges running b -> a with a > b were skipped: add them */
    at = 0;
    for (int32_t f = 0; f < c->cage.num_faces; f++) {
        int32_t n = c->cage.face_sizes[f];
        for (int32_t k = 0; k < n; k++) {
            int32_t a = c->cage.face_verts[at + k], b = c->cage.face_verts[at + (k + 1) % n], found = 0;
            if (a < b) continue;
            for (int32_t e = 0; e < c->ne && !found; e++) found = c->ev[2 * e] == b && c->ev[2 * e + 1] == a;
            if (found) continue;
            c->ev[2 * c->ne] = b;
            c->ev[2 * c->ne + 1] = a;
            c->knots[c->ne] = new_knot(random_knots);
            c->creases[c->ne] = 0.0;
            c->ne++;
        }
        at += n;
    }
    c->cage.num_edges = c->ne;
    c->cage.edge_verts = c->ev;
    c->cage.edge_knots = c->knots;
    c->cage.edge_creases = random_creases ? c->creases : NULL;
    return 1;
}

static void unload(edit_cage *c) {
    ccn_obj_destroy(c->obj);
    free(c->ev); free(c->knots); free(c->creases);
}

typedef struct { ccn_sizes s; double *x; int32_t *fv; } result;

/* r: p's output (positions: NULL for the cage's). from: NULL, or the earlier plan's last
 * output, whose buffers r takes over (from is left empty) and which ccn_plan_evaluate_changed
 * updates in place. */
static int evaluate_at(ccn_plan *p, const double *positions, result *from, result *r) {
    ccn_error err;
    ccn_plan_get_sizes(p, &r->s);
    size_t nv = (size_t)r->s.num_verts, nf = (size_t)r->s.num_faces;
    if (from) {
        r->x = from->x, r->fv = from->fv;
        from->x = NULL, from->fv = NULL;
    } else {
        r->x = malloc(sizeof(double) * (6 * nv + 12 * nf));
        r->fv = malloc(sizeof(int32_t) * 4 * nf);
    }
    if (!r->x || !r->fv) return 0;
    ccn_limit_mesh out = {.positions = r->x, .normals = r->x + 3 * nv,
                          .corner_normals = r->x + 6 * nv, .face_verts = r->fv};
    return (from ? ccn_plan_evaluate_changed(p, positions, &out, &err)
                 : ccn_plan_evaluate(p, positions, &out, &err)) == CCN_OK;
}

static int evaluate(ccn_plan *p, result *r) { return evaluate_at(p, NULL, NULL, r); }

/* Largest difference of a and b: positions relative to the cage's size (returned), normals
 * and corner normals (unit vectors, in *nrm); -1 when sizes or the output mesh differ. */
static double compare(const result *a, const result *b, double size, double *nrm) {
    *nrm = -1;
    if (memcmp(&a->s, &b->s, sizeof a->s)) return -1;
    size_t nv = (size_t)a->s.num_verts, nf = (size_t)a->s.num_faces;
    if (memcmp(a->fv, b->fv, sizeof(int32_t) * 4 * nf)) return -1;
    double wpos = 0, wn = 0;
    for (size_t i = 0; i < 6 * nv + 12 * nf; i++) {
        double d = fabs(a->x[i] - b->x[i]), *w = i < 3 * nv ? &wpos : &wn;
        if (i < 3 * nv) d /= size;
        if (!(d <= *w)) *w = isnan(d) ? INFINITY : d;
    }
    *nrm = wn;
    return wpos;
}

static double cage_size(const ccn_cage *c) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, s = 0;
    for (int32_t v = 0; v < c->num_verts; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], c->positions[3 * v + k]);
            hi[k] = fmax(hi[k], c->positions[3 * v + k]);
        }
    for (int k = 0; k < 3; k++) s = fmax(s, hi[k] - lo[k]);
    return s > 0 ? s : 1;
}

/* b (what) must equal the new plan's output a, byte for byte; worst: the largest differences. */
static void same(const result *a, const result *b, double size, const char *what, const char *name,
                 int levels, int step, double worst[2]) {
    double dn = -1, d = compare(a, b, size, &dn);
    CHECK(d == 0 && dn == 0, "%s L%d step %d: %s differs from a new plan by %g in positions, %g in normals%s",
          name, levels, step, what, d, dn, d < 0 ? " (sizes or output mesh)" : "");
    if (d > worst[0]) worst[0] = d;
    if (dn > worst[1]) worst[1] = dn;
}

/* One cage through a chain of edits at one level: each plan made from the one before. */
static void chain(const char *name, int random_knots, int random_creases, int levels, int *runs,
                  double worst_all[2]) {
    char path[256];
    snprintf(path, sizeof path, "tests/data/%s.obj", name);
    edit_cage c;
    if (!load(path, random_knots, random_creases, &c)) { CHECK(0, "cannot read %s", path); return; }
    ccn_cache *cache = NULL;
    ccn_error err;
    CHECK(ccn_cache_create(&cache, &err) == CCN_OK, "%s", err.message);
    ccn_options o = {0};
    o.levels = levels;
    ccn_plan *prev = NULL;
    CHECK(plan_cached(&c.cage, &o, cache, &prev, &err) == CCN_OK, "%s: %s", name, err.message);
    double size = cage_size(&c.cage), worst[2] = {0, 0};
    /* the cage's positions, and at step 5 moved (then ccn_plan_evaluate_changed has nothing
     * to keep and evaluates everything) */
    double *moved = malloc(sizeof(double) * 3 * (size_t)c.cage.num_verts);
    memcpy(moved, c.cage.positions, sizeof(double) * 3 * (size_t)c.cage.num_verts);
    moved[0] += 0.125 * size;
    result last = {0};
    CHECK(!prev || evaluate(prev, &last), "%s L%d: evaluate failed", name, levels);
    for (int step = 0; step < 6 && prev; step++) {
        int32_t e = (int32_t)(tl_rand01() * c.ne);
        double mx = 0;
        for (int32_t i = 0; i < c.ne; i++) mx = fmax(mx, c.knots[i]);
        if (random_knots >= 2) c.knots[e] = new_knot(random_knots); /* caps stay caps */
        else if (step == 0) c.knots[e] = 3.0 * mx;          /* a new largest interval */
        else if (step == 1) c.knots[e] = 0.05 + 5 * tl_rand01(); /* one ring */
        else if (step == 2) { /* nothing changed */ }
        else if (step == 3) c.knots[e] = 0.05;               /* a tiny interval */
        else c.knots[e] = 0.05 + 19.95 * tl_rand01();
        ccn_plan *fresh = NULL, *next = NULL;
        CHECK(plan_cached(&c.cage, &o, cache, &fresh, &err) == CCN_OK, "%s", err.message);
        CHECK(plan_recreate(prev, &c.cage, &o, cache, &next, &err) == CCN_OK, "%s", err.message);
        prev = next; /* the old plan was consumed (destroyed) by the call */
        if (!fresh || !next) { ccn_plan_destroy(fresh); break; }
        result a, b, k;
        memset(&a, 0, sizeof a); memset(&b, 0, sizeof b); memset(&k, 0, sizeof k);
        const double *at = step == 5 ? moved : NULL;
        /* the recreated plan's first evaluation keeps what the edit did not change of the
         * earlier plan's last output (ccn_plan_evaluate_changed); a second one computes all
         * (on odd steps the earlier plan's last output is its changed one: chains of them) */
        int full = step % 2 == 0 || step == 5;
        int ok = evaluate_at(fresh, at, NULL, &a) && evaluate_at(next, at, &last, &k);
        if (full) ok = ok && evaluate_at(next, at, NULL, &b);
        else b = k;
        CHECK(ok, "%s L%d step %d: evaluate failed", name, levels, step);
        if (ok) {
            same(&a, &b, size, "the recreated plan", name, levels, step, worst);
            same(&a, &k, size, "ccn_plan_evaluate_changed", name, levels, step, worst);
        }
        (*runs)++;
        free(a.x); free(a.fv); free(last.x); free(last.fv);
        if (full) { free(k.x); free(k.fv); }
        last = b;
        ccn_plan_destroy(fresh);
    }
    free(last.x); free(last.fv); free(moved);
    ccn_plan_destroy(prev);
    ccn_cache_destroy(cache);
    unload(&c);
    for (int k = 0; k < 2; k++) worst_all[k] = fmax(worst_all[k], worst[k]);
}

static void test_interval_edits(void) {
    static const char *cages[] = {"cube", "torus", "lshape", "mixed_boundary", "fan5", "fan8",
                                  "prism_pyramid", "suzanne", "jitter_sphere", "icosahedron",
                                  "grid4", "bfan5", "pole12"};
    int runs = 0;
    double worst[2] = {0, 0};
    for (size_t i = 0; i < sizeof cages / sizeof *cages; i++)
        for (int L = 1; L <= 3; L++) {
            chain(cages[i], 0, 0, L, &runs, worst);                  /* uniform, then edits */
            if (L <= 2) chain(cages[i], 1, i % 3 == 0, L, &runs, worst); /* random, creases */
        }
    /* guided caps with non-uniform spokes (taus), edits near and away from them */
    static const char *capped[] = {"fan5", "fan8", "fan3", "fan7", "pole12", "jitter_sphere"};
    for (size_t i = 0; i < sizeof capped / sizeof *capped; i++)
        for (int k = 0; k < 3; k++) chain(capped[i], 2, 0, 3, &runs, worst);
    /* spoke ratios up to 1.045: caps blended with the refined limit near the end of their range */
    for (size_t i = 0; i < sizeof capped / sizeof *capped; i++) chain(capped[i], 3, 0, 3, &runs, worst);
    printf("  %d recreated plans, largest difference from a new plan %.1e (positions, of the cage's size), "
           "%.1e (unit normals)\n", runs, worst[0], worst[1]);
    CHECK(runs >= 150, "only %d plans compared", runs);
}

/* ccn_plan_evaluate_changed into buffers other than those the earlier plan wrote (a fresh
 * array, or a copy of its output) evaluates everything: byte-identical to a new plan's output. */
static void test_foreign_buffer(void) {
    edit_cage c;
    if (!load("tests/data/suzanne.obj", 1, 0, &c)) return;
    ccn_options o = {0};
    o.scheme = CCN_SCHEME_EIGEN;
    o.levels = 2;
    ccn_error err;
    for (int copy = 0; copy < 2; copy++) {
        ccn_plan *prev = NULL, *next = NULL, *fresh = NULL;
        CHECK(ccn_plan_create(&c.cage, &o, &prev, &err) == CCN_OK, "%s", err.message);
        result last = {0}, a = {0}, k = {0};
        CHECK(prev && evaluate(prev, &last), "evaluate failed");
        c.knots[3] = 4.5; /* an interval edit */
        CHECK(ccn_plan_create(&c.cage, &o, &fresh, &err) == CCN_OK, "%s", err.message);
        CHECK(plan_recreate(prev, &c.cage, &o, NULL, &next, &err) == CCN_OK, "%s", err.message);
        CHECK(fresh && next && evaluate(fresh, &a), "evaluate failed");
        /* the foreign buffer: garbage, or a copy of the earlier plan's last output */
        size_t nv = (size_t)last.s.num_verts, nf = (size_t)last.s.num_faces;
        result other = last;
        other.x = malloc(sizeof(double) * (6 * nv + 12 * nf));
        other.fv = malloc(sizeof(int32_t) * 4 * nf);
        if (copy) memcpy(other.x, last.x, sizeof(double) * (6 * nv + 12 * nf));
        else memset(other.x, 0x7f, sizeof(double) * (6 * nv + 12 * nf));
        CHECK(evaluate_at(next, NULL, &other, &k), "evaluate_changed failed");
        double nrm, d = compare(&a, &k, cage_size(&c.cage), &nrm);
        CHECK(d == 0 && nrm == 0, "%s buffer: positions %.3g, normals %.3g from a new plan's",
              copy ? "a copied" : "a fresh", d, nrm);
        free(last.x); free(last.fv); free(a.x); free(a.fv); free(k.x); free(k.fv);
        ccn_plan_destroy(fresh);
        ccn_plan_destroy(next);
        c.knots[3] = 1.0;
    }
    unload(&c);
}

/* Another topology, other creases or other options: the previous plan is ignored (the result
 * is byte-identical to a new plan's). */
static void test_hint_ignored(void) {
    edit_cage a, b;
    if (!load("tests/data/torus.obj", 1, 0, &a) || !load("tests/data/cube.obj", 0, 0, &b)) {
        CHECK(0, "cannot read the cages");
        return;
    }
    ccn_error err;
    ccn_options o2 = {0}, o3 = {0};
    o2.levels = 2;
    o3.levels = 3;
    const char *what[3] = {"another topology", "other creases", "other options (levels)"};
    for (int i = 0; i < 3; i++) {
        ccn_plan *hint = NULL; /* consumed by ccn_plan_create with options.previous */
        a.cage.edge_creases = NULL;
        CHECK(ccn_plan_create(i == 0 ? &b.cage : &a.cage, &o2, &hint, &err) == CCN_OK, "%s", err.message);
        if (i == 1) for (int k = 0; k < a.ne; k++) a.creases[k] = k % 7 == 0 ? 1.5 : 0;
        a.cage.edge_creases = i == 1 ? a.creases : NULL;
        const ccn_options *o = i == 2 ? &o3 : &o2;
        ccn_plan *fresh = NULL, *next = NULL;
        CHECK(ccn_plan_create(&a.cage, o, &fresh, &err) == CCN_OK, "%s", err.message);
        CHECK(plan_recreate(hint, &a.cage, o, NULL, &next, &err) == CCN_OK, "%s", err.message);
        result x, y;
        if (fresh && next && evaluate(fresh, &x) && evaluate(next, &y)) {
            double dn, d = compare(&x, &y, 1, &dn);
            CHECK(d == 0 && dn == 0, "%s: the result differs from a new plan", what[i]);
            free(x.x); free(x.fv); free(y.x); free(y.fv);
        } else {
            CHECK(0, "%s: no plan", what[i]);
        }
        ccn_plan_destroy(fresh);
        ccn_plan_destroy(next);
    }
    ccn_plan *none = NULL, *bad = NULL, *victim = NULL;
    CHECK(plan_recreate(NULL, &b.cage, &o2, NULL, &none, &err) == CCN_OK, "prev NULL: %s", err.message);
    ccn_plan_destroy(none);
    /* a failing call consumes prev too (ASan: no leak, no use after free) */
    CHECK(ccn_plan_create(&b.cage, &o2, &victim, &err) == CCN_OK, "%s", err.message);
    ccn_cage broken = b.cage;
    broken.num_faces = 0;
    CHECK(plan_recreate(victim, &broken, &o2, NULL, &bad, &err) != CCN_OK && !bad,
          "a cage without faces must fail");
    unload(&a);
    unload(&b);
}

/* The earlier plan had a UV channel and was never evaluated (no rule tables to copy): the
 * recreated plan still equals a new one, holds no channel (ccn_plan_evaluate_fvar refuses
 * channel 0), takes a new one, and nothing leaks (ASan). */
static void test_channels_and_unevaluated(void) {
    edit_cage c;
    if (!load("tests/data/fvar_abab.obj", 1, 0, &c)) { CHECK(0, "cannot read fvar_abab.obj"); return; }
    ccn_fvar_channel uv;
    CHECK(ccn_obj_get_fvar(c.obj, &uv) == CCN_OK && uv.num_values > 0, "no UV map");
    ccn_error err;
    ccn_options o = {0};
    o.levels = 2;
    ccn_plan *prev = NULL, *next = NULL, *fresh = NULL;
    int32_t ch = -1;
    CHECK(ccn_plan_create(&c.cage, &o, &prev, &err) == CCN_OK, "%s", err.message);
    CHECK(prev && ccn_plan_add_fvar(prev, &uv, &ch, &err) == CCN_OK, "%s", err.message);
    c.knots[0] *= 2.5;
    CHECK(plan_recreate(prev, &c.cage, &o, NULL, &next, &err) == CCN_OK, "%s", err.message);
    CHECK(ccn_plan_create(&c.cage, &o, &fresh, &err) == CCN_OK, "%s", err.message);
    if (next && fresh) {
        result a = {0}, b = {0};
        double dn = -1, d = evaluate(fresh, &a) && evaluate(next, &b) ? compare(&a, &b, 1, &dn) : -1;
        CHECK(d == 0 && dn == 0, "unevaluated earlier plan: differs from a new plan (%g, %g)", d, dn);
        free(a.x); free(a.fv); free(b.x); free(b.fv);
        ccn_fvar_sizes fs;
        CHECK(ccn_plan_get_fvar_sizes(next, 0, &fs) != CCN_OK, "the earlier plan's channel was carried over");
        int32_t ch2 = -1;
        CHECK(ccn_plan_add_fvar(next, &uv, &ch2, &err) == CCN_OK && ch2 == 0, "%s", err.message);
    }
    ccn_plan_destroy(next);
    ccn_plan_destroy(fresh);
    unload(&c);
}

int main(void) {
    RUN(test_interval_edits);
    RUN(test_hint_ignored);
    RUN(test_foreign_buffer);
    RUN(test_channels_and_unevaluated);
    return TEST_SUMMARY();
}
