/* Fairness of a cap against the refined limit measured on the output meshes only (so that caps
 * without a patch form can be compared with those with one): for valence n = 3, 5..12 and spoke
 * max/min ratios R = 1, 2, 4, 10 (log-uniform in [1, R], one spoke at 1 and one at R), `cases`
 * random general stars as tests/experiments/cap_table.c makes them, output level L:
 *   turn   max over output edges of the cap plan's normal-turn rate minus the refined limit's,
 *          over the refined limit's largest rate;
 *   Ksgn, Hsgn  holes where the refined limit's K (H) keeps one sign and the cap's takes the other;
 *   K/ring max |K| of the cap in the hole over the refined limit's on the ring around it;
 *   outside max distance between the plans outside the holes, over the size;
 *   pass   caps passing turn <= 0.25, no sign change, K/ring <= 2.
 * K and H from the exact positions and normals (least-squares shape operator, cap_fair.h).
 *
 *   self   the refined limit's own max |K| in the hole away from the EV (max(u, v) >= 1/4) over
 *          that on the ring: where it is above 2 the surface's curvature itself grows towards
 *          the EV, and rpass counts caps passing with K/ring <= max(2, 1.25 self) instead.
 *
 *   cap_mesh_table bi5|blend [cases] [level] [seed]   (tests/experiments/cap_mesh_table.sh
 *   builds it against the library as it ships, or for "blend" against the research build)
 * CMT_DETAIL=1 prints, per cap, max |K| of the cap and of the refined limit in 8 distance bins
 * from the EV; CMT_DUMP=n,R,k writes that star (valence n, ratio R, case k) to cage.obj. */
#include "../c/testlib.h"

#include "../c/cap_fair.h"

typedef struct { double turn, kring, kself, outside; int ksign, hsign, caps, pass, rpass; } mfair;

static int measure(const ccn_cage *cage, int L, ccn_cap cap, mfair *F) {
    fplan pb, pr;
    ccn_options ob = {0}, orf = {0};
    ob.levels = orf.levels = L;
    ob.cap = cap;
    orf.cap = CCN_CAP_REFINE;
    if (fplan_run(cage, ob, &pb) || fplan_run(cage, orf, &pr)) { fplan_free(&pb); fplan_free(&pr); return -1; }
    double size = bbox_diag(pr.x, pr.nv);
    uint8_t *hole = calloc((size_t)pr.nv, 1), *outer = calloc((size_t)pr.nv, 1);
    for (int32_t i = 0; i < pb.p->nhv; i++) {
        double u = pb.p->hv_uv[2 * i], v = pb.p->hv_uv[2 * i + 1];
        outer[pb.p->hv_out[i]] = fmax(u, v) >= 0.25;
        if (u < 1 - 1e-12 && v < 1 - 1e-12) hole[pb.p->hv_out[i]] = (uint8_t)(pb.p->hv_cap[i] + 1);
    }
    mfair G = {0};
    for (int32_t v = 0; v < pr.nv; v++)
        if (!hole[v]) {
            double d[3] = {pb.x[3 * v] - pr.x[3 * v], pb.x[3 * v + 1] - pr.x[3 * v + 1], pb.x[3 * v + 2] - pr.x[3 * v + 2]};
            G.outside = fmax(G.outside, norm3(d) / size);
        }
    double rmax, excess = turn_excess(&pr, &pb, &rmax);
    G.turn = excess / rmax;
    int32_t *nbs, *nb;
    neighbours(&pr, &nbs, &nb);
    for (int32_t c = 0; c < pb.p->ncap; c++) {
        double kmin = 1e300, kmax = -1e300, hmin = 1e300, hmax = -1e300;
        double cmin = 1e300, cmax = -1e300, chmin = 1e300, chmax = -1e300, kc = 0, kout = 0, kself = 0;
        for (int32_t v = 0; v < pr.nv; v++) {
            double K, H;
            if (hole[v] == c + 1) {
                ring_curvature(pr.x, pr.n, nbs, nb, v, &K, &H);
                kmin = fmin(kmin, K), kmax = fmax(kmax, K), hmin = fmin(hmin, H), hmax = fmax(hmax, H);
                if (outer[v]) kself = fmax(kself, fabs(K));
                ring_curvature(pb.x, pb.n, nbs, nb, v, &K, &H);
                kc = fmax(kc, fabs(K));
                cmin = fmin(cmin, K), cmax = fmax(cmax, K), chmin = fmin(chmin, H), chmax = fmax(chmax, H);
            } else if (!hole[v]) {
                int next = 0;
                for (int32_t q = nbs[v]; q < nbs[v + 1] && !next; q++) next = hole[nb[q]] == c + 1;
                if (!next) continue;
                ring_curvature(pr.x, pr.n, nbs, nb, v, &K, &H);
                kout = fmax(kout, fabs(K));
            }
        }
        if (getenv("CMT_DETAIL")) { /* max |K| by distance from the EV (cap, refined), 8 bins over the hole */
            int32_t ev = -1;
            for (int32_t i = 0; i < pb.p->nhv; i++)
                if (pb.p->hv_cap[i] == c && pb.p->hv_uv[2 * i] == 0 && pb.p->hv_uv[2 * i + 1] == 0) ev = pb.p->hv_out[i];
            double rmaxh = 0, bc[10] = {0}, br[10] = {0};
            for (int32_t v = 0; v < pr.nv; v++)
                if (hole[v] == c + 1) {
                    double d[3] = {pr.x[3 * v] - pr.x[3 * ev], pr.x[3 * v + 1] - pr.x[3 * ev + 1], pr.x[3 * v + 2] - pr.x[3 * ev + 2]};
                    rmaxh = fmax(rmaxh, norm3(d));
                }
            for (int32_t v = 0; v < pr.nv; v++)
                if (hole[v] == c + 1) {
                    double d[3] = {pr.x[3 * v] - pr.x[3 * ev], pr.x[3 * v + 1] - pr.x[3 * ev + 1], pr.x[3 * v + 2] - pr.x[3 * ev + 2]};
                    int b = (int)(8 * norm3(d) / rmaxh);
                    if (b > 7) b = 7;
                    double K, H;
                    ring_curvature(pb.x, pb.n, nbs, nb, v, &K, &H); bc[b] = fmax(bc[b], fabs(K));
                    ring_curvature(pr.x, pr.n, nbs, nb, v, &K, &H); br[b] = fmax(br[b], fabs(K));
                }
            printf("   kout %.3g  cap:", kout);
            for (int b = 0; b < 8; b++) printf(" %.3g", bc[b]);
            printf("  refined:");
            for (int b = 0; b < 8; b++) printf(" %.3g", br[b]);
            printf("\n");
        }
        int ks = (kmin > 0 && cmin <= 0) || (kmax < 0 && cmax >= 0);
        int hs = (hmin > 0 && chmin <= 0) || (hmax < 0 && chmax >= 0);
        double kr = kout > 0 ? kc / kout : 0, ksr = kout > 0 ? kself / kout : 0;
        G.ksign += ks, G.hsign += hs, G.kring = fmax(G.kring, kr), G.kself = fmax(G.kself, ksr), G.caps++;
        G.pass += !ks && !hs && kr <= 2 && G.turn <= 0.25;
        G.rpass += !ks && !hs && kr <= fmax(2, 1.25 * ksr) && G.turn <= 0.25;
    }
    free(nbs); free(nb); free(hole); free(outer);
    fplan_free(&pb);
    fplan_free(&pr);
    *F = G;
    return 0;
}

typedef struct { ccn_cap cap; int L, n; double R; int evs; mfair all; } row;

static void measure_star(void *ctx, int k, fcage *c) {
    row *r = ctx;
    char have[64];
    snprintf(have, sizeof have, "%d,%g,%d", r->n, r->R, k);
    if (getenv("CMT_DUMP") && strcmp(getenv("CMT_DUMP"), have) == 0) fcage_write_obj(c, "cage.obj");
    ccn_cage g = fcage_view(c);
    mfair F;
    if (measure(&g, r->L, r->cap, &F) != 0) return;
    r->evs++;
    mfair *all = &r->all;
    all->caps += F.caps, all->pass += F.pass, all->rpass += F.rpass, all->ksign += F.ksign, all->hsign += F.hsign;
    if (F.caps) all->turn = fmax(all->turn, F.turn), all->kring = fmax(all->kring, F.kring), all->kself = fmax(all->kself, F.kself);
    all->outside = fmax(all->outside, F.outside);
}

int main(int argc, char **argv) {
    /* "blend": the research cap of tests/experiments/cap_blend.patch (the enum value after REFINE) */
    ccn_cap cap = argc > 1 && strcmp(argv[1], "blend") == 0 ? (ccn_cap)(CCN_CAP_REFINE + 1) : CCN_CAP_GUIDED_BI5;
    int cases = argc > 2 ? atoi(argv[2]) : 4, L = argc > 3 ? atoi(argv[3]) : 5;
    tl_rng_state ^= (unsigned long long)(argc > 4 ? atoi(argv[4]) : 1) * 0x9E3779B97F4A7C15ull;
    const double Rs[] = {1, 2, 4, 10};
    printf("%-3s %-4s %5s %6s %6s %6s %6s %5s %5s %7s %7s %8s\n", "n", "R", "EVs", "capped", "pass", "rpass", "turn", "Ksgn", "Hsgn",
           "K/ring", "self", "outside");
    int tot = 0, totcap = 0, totpass = 0, totr = 0;
    for (int ri = 0; ri < 4; ri++)
        for (int n = 3; n <= 12; n++) {
            if (n == 4) continue;
            row r = {.cap = cap, .L = L, .n = n, .R = Rs[ri]};
            star_row(n, Rs[ri], cases, measure_star, &r);
            mfair all = r.all;
            int evs = r.evs;
            printf("%-3d %-4g %5d %6d %6d %6d %6.2f %5d %5d %7.2f %7.2f %8.1e\n", n, Rs[ri], evs, all.caps, all.pass, all.rpass, all.turn,
                   all.ksign, all.hsign, all.kring, all.kself, all.outside);
            fflush(stdout);
            tot += evs, totcap += all.caps, totpass += all.pass, totr += all.rpass;
        }
    printf("# %d EVs: %d capped (%.1f %%), %d capped and passing (%.1f %%), %d passing relative to the surface's own K/ring (%.1f %%)\n", tot, totcap, 100.0 * totcap / (tot ? tot : 1),
           totpass, 100.0 * totpass / (tot ? tot : 1), totr, 100.0 * totr / (tot ? tot : 1));
    return 0;
}
