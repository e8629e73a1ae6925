/* ccnurbs experiment: argument parsing and usage. */
#include "cli.h"
#include "exp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int exp_usage(void) {
    fprintf(stderr,
            "usage:\n"
            "  ccnurbs experiment maxima  --cases N --seed S [--scheme eigen|nurss|cc] [--levels L]\n"
            "        [--dist uniform|loguniform] [--lo 1e-6] [--valences 3,5,6,7,8] [--knots d0,d1,...]\n"
            "        [--threads T] [--rings G] [--list K] [--persist L2] [--start level1|cage] [--offset K]\n"
            "  ccnurbs experiment charmap --cases N --seed S [--scheme eigen|nurss|cc] [--dist ...]\n"
            "        [--lo 1e-6] [--valences ...] [--knots ...] [--threads T] [--charlevels k] [--list K]\n"
            "        [--offset K]\n"
            "  Both: [--polyhedron P] the eigen polyhedron (0: the per-vertex choice, default;\n"
            "        1: the paper's spoke lengths; 2..%d: one fixed candidate, ccnurbs.h CCN_POLY_*)\n"
            "  Case i (i = K .. K+N-1) has valence valences[i mod count] and intervals drawn from a\n"
            "  generator seeded by (S, i): results do not depend on --threads or on how a run is split.\n",
            CCN_POLY_COUNT);
    return 2;
}

static int parse_double(const char *s, double *out) {
    char *e;
    double x = strtod(s, &e);
    if (e == s || *e || !isfinite(x)) return -1;
    *out = x;
    return 0;
}

static int parse_long(const char *s, long lo, long hi, long *out) {
    char *e;
    long x = strtol(s, &e, 10);
    if (e == s || *e || x < lo || x > hi) return -1;
    *out = x;
    return 0;
}

static int parse_u64(const char *s, uint64_t *out) {
    char *e;
    if (*s == '-') return -1;
    unsigned long long x = strtoull(s, &e, 10);
    if (e == s || *e) return -1;
    *out = (uint64_t)x;
    return 0;
}

/* Comma-separated list of ints in [lo, hi] (ints) or positive finite doubles (dbl). */
static int parse_list(const char *s, int cap, int *ints, double *dbl, int lo, int hi) {
    int n = 0;
    while (*s) {
        if (n == cap) return -1;
        char *e;
        if (ints) {
            long x = strtol(s, &e, 10);
            if (e == s || x < lo || x > hi) return -1;
            ints[n++] = (int)x;
        } else {
            double x = strtod(s, &e);
            if (e == s || !isfinite(x) || x <= 0) return -1;
            dbl[n++] = x;
        }
        if (*e == ',') e++;
        else if (*e) return -1;
        s = e;
    }
    return n;
}

static int parse_choice(const char *opt, const char *val, exp_args *o) {
    if (strcmp(opt, "--scheme") == 0) return ccn_cli_scheme(val, &o->scheme);
    if (strcmp(opt, "--start") == 0) {
        if (strcmp(val, "cage") == 0) o->start = 0;
        else if (strcmp(val, "level1") == 0) o->start = 1;
        else return -1;
        return 0;
    }
    if (strcmp(opt, "--dist") == 0) {
        if (strcmp(val, "uniform") == 0) o->dist_log = 0;
        else if (strcmp(val, "loguniform") == 0) o->dist_log = 1;
        else return -1;
        return 0;
    }
    return 1; /* not a choice option */
}

static int parse_number_opt(const char *opt, const char *val, exp_args *o) {
    long x;
    if (strcmp(opt, "--cases") == 0) return parse_long(val, 1, 100000000L, &o->cases);
    if (strcmp(opt, "--seed") == 0) return parse_u64(val, &o->seed);
    if (strcmp(opt, "--offset") == 0) return parse_long(val, 0, 1000000000L, &o->offset);
    if (strcmp(opt, "--lo") == 0)
        return parse_double(val, &o->lo) || !(o->lo > 0 && o->lo <= 1) ? -1 : 0;
    struct { const char *name; long lo, hi; int *dst; } tab[] = {
        {"--levels", 0, 9, &o->levels},     {"--threads", 1, 256, &o->threads},
        {"--rings", 3, 8, &o->rings},       {"--list", 0, 1000000, &o->list},
        {"--persist", 0, 12, &o->persist},   {"--charlevels", 2, 7, &o->charlevels},
        {"--polyhedron", 0, CCN_POLY_COUNT, &o->poly},
    };
    for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++) {
        if (strcmp(opt, tab[i].name)) continue;
        if (parse_long(val, tab[i].lo, tab[i].hi, &x)) return -1;
        *tab[i].dst = (int)x;
        return 0;
    }
    return 1;
}

static int parse_option(const char *opt, const char *val, exp_args *o) {
    int r = parse_choice(opt, val, o);
    if (r <= 0) return r;
    r = parse_number_opt(opt, val, o);
    if (r <= 0) return r;
    if (strcmp(opt, "--valences") == 0) {
        o->nval = parse_list(val, EXP_MAX_VALS, o->val, NULL, 3, EXP_MAX_N);
        return o->nval > 0 ? 0 : -1;
    }
    if (strcmp(opt, "--knots") == 0) {
        o->nknots = parse_list(val, EXP_MAX_N, NULL, o->knots, 0, 0);
        return o->nknots >= 3 ? 0 : -1;
    }
    return 1;
}

int exp_parse_args(int argc, char **argv, exp_args *o) {
    *o = (exp_args){.scheme = CCN_SCHEME_EIGEN, .levels = 5, .rings = 3, .threads = 2,
                    .list = 50, .charlevels = 4, .start = 1, .cases = 1000, .seed = 1, .lo = 1e-6,
                    .nval = 5, .val = {3, 5, 6, 7, 8}};
    if (strcmp(argv[1], "maxima") == 0) o->kind = EXP_MAXIMA;
    else if (strcmp(argv[1], "charmap") == 0) o->kind = EXP_CHARMAP;
    else {
        fprintf(stderr, "ccnurbs experiment: unknown experiment '%s'\n", argv[1]);
        return -1;
    }
    for (int i = 2; i < argc; i += 2) {
        int r = i + 1 < argc ? parse_option(argv[i], argv[i + 1], o) : 1;
        if (r) {
            fprintf(stderr, "ccnurbs experiment: %s option '%s'%s%s\n", r < 0 ? "bad value for" :
                    "unknown or incomplete", argv[i], r < 0 ? ": " : "", r < 0 ? argv[i + 1] : "");
            return -1;
        }
    }
    if (o->nknots) o->cases = 1;
    return 0;
}
