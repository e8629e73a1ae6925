/* ccnurbs experiment: the header line, the tallies and reports of a run, and maxima with
 * --knots (one case, counts per level). */
#include "cli.h"
#include "exp.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void print_intervals(const double *d, int n) {
    for (int s = 0; s < n; s++) printf("%s%.17g", s ? "," : "", d[s]);
}

void exp_print_header(const exp_args *a, const char *what) {
    printf("ccnurbs experiment %s: scheme %s", what, ccn_cli_scheme_name(a->scheme));
    if (a->kind == EXP_MAXIMA) printf(", levels %d, rings %d, start %s", a->levels, a->rings,
                                      a->start ? "level1" : "cage");
    else printf(", charlevels %d", a->charlevels);
    if (a->nknots) {
        printf(", knots ");
        print_intervals(a->knots, a->nknots);
    } else {
        printf(", dist %s [%g, 1], valences", a->dist_log ? "loguniform" : "uniform", a->lo);
        for (int i = 0; i < a->nval; i++) printf("%s%d", i ? "," : " ", a->val[i]);
        printf(", seed %llu, offset %ld", (unsigned long long)a->seed, a->offset);
    }
    printf(", polyhedron %d%s, threads %d\n", a->poly, a->poly ? "" : " (per-vertex choice)", a->threads);
}

/* " [levels L+1..P: 1 1 2]" for a failing case followed by --persist. */
static void print_later(const exp_args *a, const max_result *r) {
    if (!r->nlater) return;
    printf(" [levels %d..%d:", a->levels + 1, a->levels + r->nlater);
    for (int l = 0; l < r->nlater; l++) printf(" %d", r->later[l]);
    printf("]");
}

static void print_error_case(const exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = exp_case_setup(a, i, d);
    printf("error case %ld valence %d intervals ", a->offset + i, n);
    print_intervals(d, n);
    printf(": %s\n", ccn_status_name((ccn_status)run->status[i]));
}

typedef struct {
    long single, fail, persistent, errors, fb_cases, fb_total, nonfinite;
    long vfail[EXP_MAX_VALS], vcases[EXP_MAX_VALS];
} max_totals;

static void maxima_fail_line(const exp_run *run, long i) {
    const max_result *r = &run->mres[i];
    double d[EXP_MAX_N];
    int n = exp_case_setup(run->a, i, d);
    printf("fail case %ld valence %d maxima %d intervals ", run->a->offset + i, n, r->maxima);
    print_intervals(d, n);
    print_later(run->a, r);
    printf("\n");
}

/* Tallies the cases and lists the first --list failures. */
static void maxima_tally(const exp_run *run, max_totals *t) {
    const exp_args *a = run->a;
    memset(t, 0, sizeof *t);
    for (long i = 0; i < a->cases; i++) {
        const max_result *r = &run->mres[i];
        if (run->status[i]) { t->errors++; continue; }
        int slot = (int)((a->offset + i) % a->nval);
        t->vcases[slot]++;
        t->fb_cases += r->fallbacks > 0;
        t->fb_total += r->fallbacks;
        t->nonfinite += r->nonfinite > 0;
        if (r->maxima == 1 && !r->nonfinite) { t->single++; continue; }
        t->vfail[slot]++;
        t->persistent += r->nonfinite || !r->nlater || r->later[r->nlater - 1] != 1;
        if (t->fail++ < a->list) maxima_fail_line(run, i);
    }
    if (t->fail > a->list) printf("(%ld more failures not listed)\n", t->fail - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
}

long exp_maxima_report(const exp_run *run) {
    const exp_args *a = run->a;
    max_totals t;
    maxima_tally(run, &t);
    double pc = 100.0 / (double)a->cases;
    printf("cases: %ld\n", a->cases);
    printf("single maximum: %ld (%.4f%%)\n", t.single, pc * (double)t.single);
    printf("failures: %ld\n", t.fail);
    printf("failures by valence:");
    for (int v = 0; v < a->nval; v++) printf(" %d:%ld/%ld", a->val[v], t.vfail[v], t.vcases[v]);
    printf("\n");
    if (a->persist > a->levels)
        printf("persistent (!= 1 maximum also at level %d): %ld; single maximum at level %d or "
               "by level %d: %ld (%.4f%%)\n", a->persist, t.persistent, a->levels, a->persist,
               a->cases - t.errors - t.persistent, pc * (double)(a->cases - t.errors - t.persistent));
    printf("non-finite: %ld\n", t.nonfinite);
    printf("fallbacks: %ld cases (%ld EV matrices)\n", t.fb_cases, t.fb_total);
    printf("errors: %ld\n", t.errors);
    return t.errors;
}

static int cm_pass(const cm_result *r) {
    return r->spectrum && r->regular && r->injective && r->matrix_ok;
}

static void cm_fail_line(const exp_run *run, long i, const char *tag) {
    const cm_result *r = &run->cres[i];
    double d[EXP_MAX_N];
    int n = exp_case_setup(run->a, i, d);
    printf("%s case %ld valence %d%s%s%s%s%s intervals ", tag, run->a->offset + i, n,
           r->spectrum ? "" : " spectrum", r->regular ? "" : " regularity",
           r->injective ? "" : " injectivity", r->matrix_ok ? "" : " matrix",
           r->net_regular && r->net_injective ? "" : " (net)");
    print_intervals(d, n);
    printf(" |mu|=%.6g,%.6g,%.6g,%.6g split %.2g im %.2g |mu4|/|mu2| %.6g%s fallbacks %d;"
           " surface: bad patches %d undecided %d crossings %d winding %d,%d;"
           " net: bad quads %d%s\n", r->mod[0], r->mod[1], r->mod[2], r->mod[3], r->split,
           r->im2, r->ratio, r->defective ? " defective" : "", r->fallbacks, r->bad_patches,
           r->undecided, r->crossings, r->wind_in, r->wind_out, r->net_bad_quads,
           r->net_injective ? "" : " not injective");
}

typedef struct {
    long spectrum, regular, injective, net_regular, net_injective, matrix, all, fb_cases, errors;
    double worst_ratio, worst_split, worst_lam, worst_rowsum, worst_m;
} cm_totals;

static void cm_accumulate(const exp_run *run, cm_totals *t) {
    memset(t, 0, sizeof *t);
    for (long i = 0; i < run->a->cases; i++) {
        const cm_result *r = &run->cres[i];
        if (run->status[i]) { t->errors++; continue; }
        t->spectrum += r->spectrum;
        t->regular += r->regular;
        t->injective += r->injective;
        t->net_regular += r->net_regular;
        t->net_injective += r->net_injective;
        t->matrix += r->matrix_ok;
        t->all += cm_pass(r);
        t->fb_cases += r->fallbacks > 0;
        t->worst_ratio = fmax(t->worst_ratio, r->ratio);
        t->worst_split = fmax(t->worst_split, r->split);
        if (!r->fallbacks) t->worst_lam = fmax(t->worst_lam, r->lam_err);
        t->worst_rowsum = fmax(t->worst_rowsum, r->rowsum_err);
        t->worst_m = fmax(t->worst_m, r->m_err);
    }
}

static void cm_list(const exp_run *run) {
    const exp_args *a = run->a;
    long listed = 0;
    for (long i = 0; i < a->cases; i++)
        if (!run->status[i] && (!cm_pass(&run->cres[i]) || a->nknots))
            if (listed++ < a->list) cm_fail_line(run, i, cm_pass(&run->cres[i]) ? "pass" : "fail");
    if (listed > a->list) printf("(%ld more failures not listed)\n", listed - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
}

long exp_charmap_report(const exp_run *run) {
    const exp_args *a = run->a;
    cm_list(run);
    cm_totals t;
    cm_accumulate(run, &t);
    printf("cases: %ld\n", a->cases);
    printf("matrix ok: %ld (max |row sum - 1| %.3g, max 1-ring vs ccn_ev_matrix %.3g)\n",
           t.matrix, t.worst_rowsum, t.worst_m);
    printf("spectrum ok: %ld (max |mu2-mu3|/|mu2| %.3g, max |mu4|/|mu2| %.6g, "
           "max |mu2,3 - lambda_n| %.3g)\n", t.spectrum, t.worst_split, t.worst_ratio, t.worst_lam);
    printf("regular: %ld (limit surface: Bezier coefficients of det J, rings 2..4 of level 2)\n",
           t.regular);
    printf("injective: %ld\n", t.injective);
    printf("net regular: %ld (control-net quads, rings %d..%d of level %d)\n", t.net_regular,
           1 << (a->charlevels - 1), 1 << a->charlevels, a->charlevels);
    printf("net injective: %ld\n", t.net_injective);
    printf("all pass: %ld\n", t.all);
    printf("failures: %ld\n", a->cases - t.errors - t.all);
    printf("fallbacks: %ld cases\n", t.fb_cases);
    printf("errors: %ld\n", t.errors);
    return t.errors;
}

/* --knots for maxima: counts per level 1..L and the z statistics (rings-independence check). */
int exp_maxima_knots(const exp_run *run) {
    const exp_args *a = run->a;
    int per[16];
    max_result r = {.show = 1};
    ccn_error err;
    if (exp_maxima_case(&run->cages[0], a->knots, a, per, &r, &err))
        return ccn_cli_error("experiment", &err);
    printf("maxima per level 1..%d:", a->levels);
    for (int l = 0; l < a->levels; l++) printf(" %d", per[l]);
    print_later(a, &r);
    printf("\nlevel %d: support %d vertices, sum z %.12g, max z %.15g, fallbacks %d\n", a->levels,
           (int)r.support, r.zsum, r.zmax, r.fallbacks);
    printf("cases: 1\nsingle maximum: %d\nfailures: %d\n", r.maxima == 1, r.maxima != 1);
    return 0;
}
