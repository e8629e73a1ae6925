/* The G1 fill cap (options.cap = G1_FILL, surface/fill_cap.h), measured by tests/c/cap_fair.h
 * (independent Bernstein-Bezier evaluation of the cap's patches, the refined limit's exact
 * positions, normals and curvatures):
 *   - random general stars of valence 5-12 with spoke max/min ratios 2, 4 and 10 (log-uniform,
 *     one spoke at each end): every EV gets a cap, G1 across its spokes and along its border
 *     (against the exact limit's normals) within 1e-9 rad, its centre normal the exact limit
 *     normal within 1e-9 rad, outside the holes the exact limit to 1e-12, no fold;
 *   - valence 3 keeps the refined limit (a fallback, counted);
 *   - within the bi-5 cap's range nothing changes (the default cap's output bit for bit);
 *   - across the end of the bi-5 range (the blend of the two caps) and along a sweep of one
 *     spoke interval the surface moves continuously: no step of the sweep more than 10x its
 *     median step;
 *   - its patches (ccn_plan_patches) are the surface the plan shows: every output vertex in a
 *     hole lies on them within 1e-12 of the size.
 * The fairness measures (normal-turn excess, max |K| over the ring's, K jump) are printed, not
 * held: this construction does not meet the harness (docs/caps.md). */
#include "testlib.h"

#include "cap_fair.h"

static void fill_star(int n, double R, int k, fcage *c) {
    double d[12];
    tl_rng_state = 0x243F6A8885A308D3ull ^ (unsigned long long)(1000 * n + 10 * R + k);
    random_spokes(n, R, d);
    general_star(n, d, c);
}

static void test_stars(void) {
    static const int ns[] = {5, 6, 7, 8, 10, 12};
    static const double Rs[] = {2, 4, 10};
    fair all;
    fair_init(&all);
    for (int ri = 0; ri < 3; ri++)
        for (int ni = 0; ni < 6; ni++) {
            fcage c;
            fill_star(ns[ni], Rs[ri], 0, &c);
            ccn_cage g = fcage_view(&c);
            ccn_options o = {0};
            o.cap = CCN_CAP_G1_FILL;
            fair F;
            fair_init(&F);
            char name[64];
            snprintf(name, sizeof name, "n %d R %g", ns[ni], Rs[ri]);
            CHECK(fair_measure(&g, 4, o, &F) == 0, "%s: plans", name);
            if (getenv("FAIR_VERBOSE")) fair_print(name, &F);
            CHECK(F.caps == 1 && F.fallbacks == 0 && F.holes_checked == 1, "%s: %d caps, %d fallbacks", name, F.caps,
                  F.fallbacks);
            CHECK(F.g1 <= 1e-9, "%s: G1 %.2g rad", name, F.g1);
            CHECK(F.centre <= 1e-9, "%s: centre normal %.2g rad", name, F.centre);
            CHECK(F.outside <= 1e-12, "%s: outside the hole %.2g", name, F.outside);
            CHECK(F.jac > 0.01, "%s: min |Xu x Xv| %.3g of its max", name, F.jac);
            all.turn = fmax(all.turn, F.turn), all.kring = fmax(all.kring, F.kring), all.kjump = fmax(all.kjump, F.kjump);
            all.g1 = fmax(all.g1, F.g1), all.centre = fmax(all.centre, F.centre), all.jac = fmin(all.jac, F.jac);
            all.ksign += F.ksign, all.hsign += F.hsign, all.caps += F.caps;
            fcage_free(&c);
        }
    printf("# 18 stars (valence 5-12, ratios 2/4/10, level 4): caps %d; G1 %.2g rad, centre %.2g rad; not held: "
           "turn excess %.2f, max |K| / ring %.1f, K jump %.2f, K sign %d, H sign %d\n", all.caps, all.g1, all.centre,
           all.turn, all.kring, all.kjump, all.ksign, all.hsign);
}

static void test_valence3_and_in_range(void) {
    fcage c;
    double d3[3] = {1, 2, 1.5};
    star_cage(3, 3, d3, &c);
    ccn_cage g = fcage_view(&c);
    ccn_options o = {0};
    o.cap = CCN_CAP_G1_FILL;
    fair F;
    fair_init(&F);
    CHECK(fair_measure(&g, 4, o, &F) == 0 && F.caps == 0 && F.fallbacks == 1, "valence 3: %d caps %d fallbacks",
          F.caps, F.fallbacks);
    fcage_free(&c);
    double d[7] = {1, 1.002, 1.004, 1.0, 0.998, 1.0, 1.003}; /* the bi-5 cap whole (kappa <= 1.01) */
    star_cage(7, 3, d, &c);
    g = fcage_view(&c);
    fplan pa, pb;
    ccn_options oa = {0}, ob = {0};
    oa.levels = ob.levels = 4;
    ob.cap = CCN_CAP_G1_FILL;
    CHECK(fplan_run(&g, oa, &pa) == 0 && fplan_run(&g, ob, &pb) == 0, "plans");
    CHECK(pa.nv == pb.nv && memcmp(pa.x, pb.x, sizeof(double) * 3 * (size_t)pa.nv) == 0 &&
              memcmp(pa.n, pb.n, sizeof(double) * 3 * (size_t)pa.nv) == 0,
          "in range: the default cap's output");
    fplan_free(&pa);
    fplan_free(&pb);
    fcage_free(&c);
}

/* Largest step over the median step of the output positions along a sweep of spoke interval
 * d[0] over [a, b] (geometric, m steps). */
static double sweep_ratio(int n, double *d, double a, double b, int m, ccn_cap cap) {
    double *prev = NULL, *steps = malloc(sizeof(double) * (size_t)m), worst = 0;
    int32_t nv = 0;
    for (int i = 0; i <= m; i++) {
        d[0] = a * pow(b / a, (double)i / m);
        fcage c;
        star_cage(n, 3, d, &c);
        ccn_cage g = fcage_view(&c);
        fplan p;
        ccn_options o = {0};
        o.levels = 4;
        o.cap = cap;
        if (fplan_run(&g, o, &p)) { fcage_free(&c); break; }
        if (prev) {
            double s = 0;
            for (int32_t v = 0; v < 3 * nv; v++) s = fmax(s, fabs(p.x[v] - prev[v]));
            steps[i - 1] = s;
        }
        nv = p.nv;
        free(prev);
        prev = malloc(sizeof(double) * 3 * (size_t)nv);
        memcpy(prev, p.x, sizeof(double) * 3 * (size_t)nv);
        fplan_free(&p);
        fcage_free(&c);
    }
    double *sorted = malloc(sizeof(double) * (size_t)m);
    memcpy(sorted, steps, sizeof(double) * (size_t)m);
    for (int i = 1; i < m; i++) /* insertion sort: m is small */
        for (int j = i; j > 0 && sorted[j] < sorted[j - 1]; j--) {
            double t = sorted[j];
            sorted[j] = sorted[j - 1], sorted[j - 1] = t;
        }
    double med = sorted[m / 2];
    for (int i = 0; i < m; i++) worst = fmax(worst, steps[i] / med);
    if (getenv("FILL_SWEEP"))
        for (int i = 0; i < m; i++) printf("#   step %d (d0 %.5f): %.3g x median\n", i, a * pow(b / a, (i + 1.0) / m), steps[i] / med);
    free(prev); free(steps); free(sorted);
    return worst;
}

static void test_continuity(void) {
    /* kappa of spokes 1 and 6 = d[0]: through the blend band 1.01 .. 1.05 (from just above 1: at
     * exactly equal intervals the bi-5 cap takes another construction) */
    double d[7] = {1, 1, 1, 1, 1, 1, 1};
    double r1 = sweep_ratio(7, d, 1.002, 1.08, 80, CCN_CAP_G1_FILL);
    printf("# across the bi-5 range's end (d0 1.002 .. 1.08, 80 steps): largest step %.2f x the median\n", r1);
    CHECK(r1 <= 10, "bi-5 / fill blend: step %.2f x median", r1);
    double e[8] = {1, 2, 1.5, 1, 3, 1, 1.2, 2.5};
    double r2 = sweep_ratio(8, e, 1.5, 6, 40, CCN_CAP_G1_FILL);
    printf("# spoke interval 1.5 .. 6 (40 steps): largest step %.2f x the median\n", r2);
    CHECK(r2 <= 10, "sweep: step %.2f x median", r2);
}

static void test_patches_are_the_surface(void) {
    fcage c;
    fill_star(8, 4, 1, &c);
    ccn_cage g = fcage_view(&c);
    fplan p;
    ccn_options o = {0};
    o.levels = 4;
    o.cap = CCN_CAP_G1_FILL;
    CHECK(fplan_run(&g, o, &p) == 0, "plan");
    const ccn__cap *cp = &p.p->caps[0];
    CHECK(p.p->ncap == 1 && cp->fill && !(cp->w > 0), "a fill cap");
    double worst = 0, size = bbox_diag(p.x, p.nv);
    for (int32_t i = 0; i < p.p->nhv; i++) { /* each hole sample on its sector's Bezier patches */
        double b[4][6][6][3], u = p.p->hv_uv[2 * i], v = p.p->hv_uv[2 * i + 1], jet[6][3];
        ccn__fill_cap_bezier(cp->fill, p.p->hv_sector[i], b);
        int a = u < 0.5 ? 0 : 1, q = v < 0.5 ? 0 : 1;
        bez5_jet((const double(*)[6][3])b[2 * a + q], 2 * u - a, 2 * v - q, jet);
        const double *x = p.x + 3 * (size_t)p.p->hv_out[i];
        for (int k = 0; k < 3; k++)
            worst = fmax(worst, fabs(p.p->centre[k] + p.p->scale * jet[0][k] - x[k]) / size);
    }
    CHECK(worst <= 1e-12, "hole samples off the patches by %.2g of the size", worst);
    fplan_free(&p);
    fcage_free(&c);
}

int main(void) {
    RUN(test_stars);
    RUN(test_valence3_and_in_range);
    RUN(test_continuity);
    RUN(test_patches_are_the_surface);
    return TEST_SUMMARY();
}
