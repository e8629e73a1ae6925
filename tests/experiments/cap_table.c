/* The table of the guided bi-5 cap on random stars (tests/experiments/cap_table.sh builds and
 * runs it): for valence n = 3, 5..12 and spoke max/min ratios R = 1 (equal), 2, 4, 10
 * (log-uniform in [1, R], one spoke at 1 and one at R), `cases` random general stars (3 x 3
 * quads per sector, jittered, random heights: not a symmetric dome), output level L: how many
 * extraordinary points get a cap, and for the capped ones the fairness measures of
 * tests/c/cap_fair.h against the refined limit (normal-turn excess, curvature sign changes,
 * max |K| over the refined limit's on the ring around the hole, K jump across the cap's joins,
 * G1 at the joins, folds). Built against the default library it measures what ships; against a
 * library compiled with -DCCN_CAP_KAPPA_RANGE=1e9 it measures today's non-uniform construction
 * wherever it can be built.
 *
 *   cap_table [cases] [level] [seed]     one line per (n, R), then the totals */
#include "../c/testlib.h"

#include "../c/cap_fair.h"

typedef struct { int L, evs, passed; fair all; } row;

static void measure_star(void *ctx, int k, fcage *c) {
    row *r = ctx;
    (void)k;
    ccn_cage g = fcage_view(c);
    fair F;
    fair_init(&F);
    ccn_options o = {0};
    if (fair_measure(&g, r->L, o, &F) != 0) return;
    r->evs++;
    r->passed += F.caps > 0 && F.turn <= 0.25 && !F.ksign && !F.hsign && F.kring <= 2 && F.kjump <= 0.15 && F.g1 <= 1e-9;
    fair *all = &r->all;
    all->caps += F.caps, all->fallbacks += F.fallbacks;
    if (F.caps) {
        all->turn = fmax(all->turn, F.turn), all->kring = fmax(all->kring, F.kring);
        all->kjump = fmax(all->kjump, F.kjump), all->g1 = fmax(all->g1, F.g1);
        all->jac = fmin(all->jac, F.jac);
        all->ksign += F.ksign, all->hsign += F.hsign;
    }
}

int main(int argc, char **argv) {
    int cases = argc > 1 ? atoi(argv[1]) : 4, L = argc > 2 ? atoi(argv[2]) : 5;
    tl_rng_state ^= (unsigned long long)(argc > 3 ? atoi(argv[3]) : 1) * 0x9E3779B97F4A7C15ull;
    const double Rs[] = {1, 2, 4, 10};
    printf("%-3s %-4s %5s %6s %6s %6s %5s %5s %7s %7s %8s %6s\n", "n", "R", "EVs", "capped", "turn", "turnOK", "Ksgn",
           "Hsgn", "K/ring", "Kjump", "G1", "jac");
    int tot = 0, totcap = 0, totpass = 0;
    for (int ri = 0; ri < 4; ri++)
        for (int n = 3; n <= 12; n++) {
            if (n == 4) continue;
            row r = {.L = L};
            fair_init(&r.all);
            star_row(n, Rs[ri], cases, measure_star, &r);
            fair all = r.all;
            int evs = r.evs, passed = r.passed;
            printf("%-3d %-4g %5d %6d %6.2f %6d %5d %5d %7.2f %7.3f %8.1e %6.3f\n", n, Rs[ri], evs, all.caps,
                   all.caps ? all.turn : 0.0, passed, all.ksign, all.hsign, all.caps ? all.kring : 0.0,
                   all.caps ? all.kjump : 0.0, all.caps ? all.g1 : 0.0, all.caps ? all.jac : 0.0);
            fflush(stdout);
            tot += evs, totcap += all.caps, totpass += passed;
        }
    printf("# %d EVs: %d capped (%.1f %%), %d capped and passing the harness (%.1f %%)\n", tot, totcap,
           100.0 * totcap / (tot ? tot : 1), totpass, 100.0 * totpass / (tot ? tot : 1));
    return 0;
}
