/* Fairness of the guided bi-5 cap, measured by tests/c/cap_fair.h
 * (independent Bernstein-Bezier evaluation with second derivatives; the refined limit's
 * curvature from its exact normals): the tear box, star cages n = 3..12 with intervals in
 * [0.2, 2], the Fig. 16 / 18 patterns up to the fold limit (r = 1.5 .. 5), and, so that caps are
 * built and measured, the same cages with intervals inside the cap's kappa range (1 +- 0.02)
 * and with kappa = 1 (alternating intervals 1, r). Levels 4-6. For every cap that is built:
 * normal-turn excess <= 0.25 of the refined limit's largest rate, no curvature sign change
 * where the refined limit keeps its sign, max |K| <= 3x the refined limit's, K jump across
 * cap-ring and cap-cap joins <= 10 % of max |K|, cap-centre normal = exact limit normal to
 * 1e-9 rad, outside the holes = exact limit to 1e-12, G1 at every join to 1e-9 rad (spoke
 * intervals within 1 % of equal: the hole border and ring faces, where the uniform operator's
 * cap is blended in, within 1e-4 of the size and 1e-4 rad of the exact limit). Vertices
 * whose spoke ratios kappa_s = d_{s+1}/d_{s-1} leave [1/1.05, 1.05] (or whose cap folds) fall
 * back and are counted; the count is checked against that rule. */
#include "testlib.h"

#include "cap_fair.h"

typedef struct { fair all; int cases, want_fb, got_fb; } tally;

static int in_range(int n, const double *d) {
    for (int s = 0; s < n; s++) {
        double k = d[(s + 1) % n] / d[(s + n - 1) % n];
        if (k > 1.05 || k < 1 / 1.05) return 0;
    }
    return 1;
}

static void check_case(const char *what, fcage *c, int L, int expect_caps, int expect_fb, tally *t) {
    fair F;
    fair_init(&F);
    ccn_cage g = fcage_view(c);
    ccn_options o = {0};
    char name[96];
    snprintf(name, sizeof name, "%s L%d", what, L);
    CHECK(fair_measure(&g, L, o, &F) == 0, "%s: plans", name);
    if (getenv("FAIR_VERBOSE")) fair_print(name, &F);
    CHECK(F.turn <= 0.25, "%s: normal-turn excess %.3f of the refined limit's max", name, F.turn);
    CHECK(F.ksign == 0 && F.hsign == 0, "%s: curvature sign changes K %d H %d", name, F.ksign, F.hsign);
    CHECK(F.kratio <= 3, "%s: max |K| ratio %.2f", name, F.kratio);
    CHECK(F.kjump <= 0.10, "%s: K jump %.3f of max |K|", name, F.kjump);
    CHECK(F.centre <= 1e-9, "%s: centre normal %.2g rad", name, F.centre);
    CHECK(F.outside <= 1e-12, "%s: outside the holes %.2g", name, F.outside);
    CHECK(F.g1 <= 1e-9, "%s: G1 %.2g rad", name, F.g1);
    /* intervals within 1 % of equal: the uniform operator's cap and its ring faces blended in */
    CHECK(F.twin_out <= 1e-4 && F.twin_g1 <= 1e-4, "%s: uniform twin's border and ring faces %.2g of the size, "
          "%.2g rad from the exact limit", name, F.twin_out, F.twin_g1);
    if (expect_caps >= 0) CHECK(F.caps == expect_caps, "%s: %d caps, want %d", name, F.caps, expect_caps);
    if (expect_fb >= 0) CHECK(F.fallbacks == expect_fb, "%s: %d fallbacks, want %d", name, F.fallbacks, expect_fb);
    fair *a = &t->all;
    a->turn = fmax(a->turn, F.turn), a->kratio = fmax(a->kratio, F.kratio), a->kjump = fmax(a->kjump, F.kjump);
    a->centre = fmax(a->centre, F.centre), a->outside = fmax(a->outside, F.outside), a->g1 = fmax(a->g1, F.g1);
    a->twin_out = fmax(a->twin_out, F.twin_out), a->twin_g1 = fmax(a->twin_g1, F.twin_g1), a->twins += F.twins;
    a->jac = fmin(a->jac, F.jac);
    a->ksign += F.ksign, a->hsign += F.hsign, a->caps += F.caps, a->fallbacks += F.fallbacks;
    t->cases++;
}

static void star_case(const char *what, int n, const double *d, int L, int fold_ok, tally *t) {
    fcage c;
    star_cage(n, 3, d, &c);
    int ok = in_range(n, d);
    /* in range: a cap (fold_ok: unless tau folds, counted either way) */
    check_case(what, &c, L, ok && !fold_ok ? 1 : -1, ok ? (fold_ok ? -1 : 0) : 1, t);
    fcage_free(&c);
}

static void test_acceptance(void) {
    tally t;
    memset(&t, 0, sizeof t);
    fair_init(&t.all);
    int small = getenv("CCN_TEST_SMALL") != NULL; /* the sanitizer run: level 4, a few cases */
    for (int L = 4; L <= (small ? 4 : 6); L++) {
        fcage c;
        tear_box(&c);
        check_case("tear box", &c, L, 4, 4, &t); /* the -x corners (equal spokes) get caps */
        fcage_free(&c);
        for (int n = 3; n <= 12; n++) {
            if (n == 4 || (small && n > 6)) continue;
            double d[12];
            char what[64];
            for (int s = 0; s < n; s++) d[s] = 0.2 + 1.8 * tl_rand01();
            snprintf(what, sizeof what, "star n %d, [0.2, 2]", n);
            if (L == 4) star_case(what, n, d, L, 1, &t); /* they fall back: the level does not matter */
            for (int s = 0; s < n; s++) d[s] = 1 + 0.04 * (tl_rand01() - 0.5);
            snprintf(what, sizeof what, "star n %d, 1 +- 0.02", n);
            star_case(what, n, d, L, 0, &t);
            if (n % 2 == 0) {
                double r = 0.2 + 1.8 * tl_rand01();
                for (int s = 0; s < n; s++) d[s] = s & 1 ? r : 1;
                snprintf(what, sizeof what, "star n %d, 1, %.2f alternating", n, r);
                star_case(what, n, d, L, 0, &t);
            }
        }
        const double rs[] = {1.03, 1.5, 3, 5};
        for (int k = 0; k < 4; k++) {
            double r = rs[k], d16[6] = {1, r, r, 1, 1, r}, d18[8] = {1, r, r, 1, 1, 1, r, 1};
            char what[64];
            if (k > 0 && L > 4) continue; /* out of range: fallbacks, checked at level 4 */
            snprintf(what, sizeof what, "fig16 r %.2f", r);
            star_case(what, 6, d16, L, 0, &t);
            snprintf(what, sizeof what, "fig18 r %.2f", r);
            star_case(what, 8, d18, L, 0, &t);
        }
    }
    fair_print("all cases", &t.all);
    printf("# %d cases (levels 4-6): %d caps measured, %d fell back; %d caps with a uniform twin (intervals within 1 %% "
           "of equal): border and ring faces %.2g of the size, %.2g rad from the exact limit\n", t.cases, t.all.caps,
           t.all.fallbacks, t.all.twins, t.all.twin_out, t.all.twin_g1);
    CHECK(t.all.caps >= (small ? 5 : 50), "caps measured: %d", t.all.caps);
}

/* At output levels L <= K the default cap costs nothing and changes nothing --
 * no cap is built, the output is the refine plan's bit for bit -- and from L = K + 1 on the caps
 * are there (the cube: eight valence-3 EVs, K = 2). */
static void test_no_cap_work_at_low_levels(void) {
    fcage c;
    tear_box(&c);
    ccn_cage g = fcage_view(&c);
    for (int L = 1; L <= 3; L++) {
        fplan pb, pr;
        ccn_options o = {0};
        o.levels = L;
        CHECK(fplan_run(&g, o, &pb) == 0, "plan");
        o.cap = CCN_CAP_REFINE;
        CHECK(fplan_run(&g, o, &pr) == 0, "plan");
        ccn_sizes sz;
        ccn_plan_get_sizes(pb.p, &sz);
        ccn_plan_stats sz_st;
        ccn_plan_get_stats(pb.p, &sz_st);
        int same = memcmp(pb.x, pr.x, sizeof(double) * 3 * pr.nv) == 0 && memcmp(pb.n, pr.n, sizeof(double) * 3 * pr.nv) == 0;
        if (L <= 2) CHECK(sz_st.num_caps == 0 && sz_st.num_cap_fallbacks == 0 && same, "L%d: %d caps, identical %d", L, sz_st.num_caps, same);
        else CHECK(sz_st.num_caps == 4 && sz_st.num_cap_fallbacks == 4 && !same, "L%d: %d caps, %d fallbacks", L, sz_st.num_caps, sz_st.num_cap_fallbacks);
        fplan_free(&pb);
        fplan_free(&pr);
    }
    fcage_free(&c);
}

int main(void) {
    RUN(test_no_cap_work_at_low_levels);
    RUN(test_acceptance);
    return TEST_SUMMARY();
}
