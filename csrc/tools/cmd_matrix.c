/* `ccnurbs matrix --valence N [--knots d0,d1,...] [--scheme eigen|nurss|cc]`
 *
 * Prints the extraordinary-vertex refinement matrix M of ccn_ev_matrix (Li, Finnigan,
 * Sederberg 2016): header lines starting with '#' (scheme, valence, knots, lambda, T0,
 * fallback, residual, and a note if the eigen rules fell back to NURSS), then the 2n+1 rows
 * of M (ordering F_0..F_{n-1}, E_0..E_{n-1}, V, paper eq (1)), one per line, %.17g.
 * --knots may be omitted (all intervals 1) or list exactly N values. Errors: message on
 * stderr, exit status 2. Options may also be written --name=value.
 */
#include "cli.h"
#include "commands.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MATRIX_MAX_VALENCE 65536

static void matrix_usage(FILE *f) {
    fprintf(f, "usage: ccnurbs matrix --valence N [--knots d0,d1,...] [--scheme eigen|nurss|cc]\n"
               "  prints the (2N+1)x(2N+1) extraordinary-vertex matrix M (rows F_0..F_{N-1},\n"
               "  E_0..E_{N-1}, V) after '#' lines with lambda, T0, fallback and residual.\n"
               "  --knots: N spoke intervals (> 0), comma separated; default all 1.\n");
}

/* Parses "--name value" or "--name=value"; returns the value or NULL (not this option).
 * *i is advanced past a separate value; *missing set if the value is absent. */
static const char *matrix_opt(int argc, char **argv, int *i, const char *name, int *missing) {
    size_t len = strlen(name);
    const char *a = argv[*i];
    if (strncmp(a, name, len) != 0) return NULL;
    if (a[len] == '=') return a + len + 1;
    if (a[len] != 0) return NULL;
    if (*i + 1 >= argc) {
        *missing = 1;
        return NULL;
    }
    return argv[++*i];
}

static int matrix_parse_valence(const char *s, long *n) {
    char *end;
    errno = 0;
    *n = strtol(s, &end, 10);
    if (errno || end == s || *end != 0 || *n < 3 || *n > MATRIX_MAX_VALENCE) {
        fprintf(stderr, "ccnurbs matrix: --valence '%s' must be an integer in [3, %d]\n", s,
                MATRIX_MAX_VALENCE);
        return 1;
    }
    return 0;
}

/* Comma (or space) separated list of exactly n numbers into d. */
static int matrix_parse_knots(const char *s, long n, double *d) {
    long count = 0;
    const char *p = s;
    while (*p) {
        char *end;
        double v;
        while (*p == ' ' || *p == '\t') p++;
        errno = 0;
        v = strtod(p, &end);
        if (end == p || errno == ERANGE) {
            fprintf(stderr, "ccnurbs matrix: --knots: cannot read value %ld at '%.20s'\n",
                    count, p);
            return 1;
        }
        if (count < n) d[count] = v;
        count++;
        p = end;
        while (*p == ' ' || *p == '\t') p++;
        if (*p == ',') {
            p++;
            if (!*p) break;
        } else if (*p) {
            fprintf(stderr, "ccnurbs matrix: --knots: unexpected '%c' after value %ld\n", *p,
                    count - 1);
            return 1;
        }
    }
    if (count != n) {
        fprintf(stderr, "ccnurbs matrix: --knots has %ld values, --valence is %ld\n", count, n);
        return 1;
    }
    return 0;
}

static int matrix_parse_scheme(const char *s, ccn_scheme *scheme) {
    if (!strcmp(s, "eigen")) *scheme = CCN_SCHEME_EIGEN;
    else if (!strcmp(s, "nurss")) *scheme = CCN_SCHEME_NURSS;
    else if (!strcmp(s, "cc") || !strcmp(s, "catmull-clark")) *scheme = CCN_SCHEME_CATMULL_CLARK;
    else {
        fprintf(stderr, "ccnurbs matrix: unknown --scheme '%s' (eigen, nurss, cc)\n", s);
        return 1;
    }
    return 0;
}

static void matrix_print(long n, const double *d, ccn_scheme scheme, const double *M,
                         const ccn_ev_info *info, const ccn_error *err) {
    long r, c, N = 2 * n + 1;
    printf("# scheme %s\n# valence %ld\n# knots", ccn_cli_scheme_name(scheme), n);
    for (r = 0; r < n; r++) printf("%s%.17g", r ? "," : " ", d[r]);
    printf("\n# lambda %.17g\n# T0 %.17g %.17g\n# fallback %d\n# residual %.3g\n",
           info->lambda, info->T0[0], info->T0[1], (int)info->fallback, info->residual);
    if (err->message[0]) printf("# note %s\n", err->message);
    printf("# polyhedron %d\n# verified %d\n# outside_g1 %d\n", (int)info->polyhedron,
           (int)info->verified, (int)info->outside_g1);
    for (r = 0; r < N; r++) {
        for (c = 0; c < N; c++) printf(c ? " %.17g" : "%.17g", M[r * N + c]);
        putchar('\n');
    }
}

int ccn_cmd_matrix(int argc, char **argv) {
    const char *valence = NULL, *knots = NULL, *scheme_s = "eigen", *v;
    ccn_scheme scheme = CCN_SCHEME_EIGEN;
    ccn_ev_info info;
    ccn_error err;
    double *d = NULL, *M = NULL;
    long n, k;
    int i, rc = 2;
    for (i = 1; i < argc; i++) {
        int missing = 0;
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            matrix_usage(stdout);
            return 0;
        }
        if ((v = matrix_opt(argc, argv, &i, "--valence", &missing))) valence = v;
        else if ((v = matrix_opt(argc, argv, &i, "--knots", &missing))) knots = v;
        else if ((v = matrix_opt(argc, argv, &i, "--scheme", &missing))) scheme_s = v;
        else {
            fprintf(stderr, "ccnurbs matrix: %s '%s'\n",
                    missing ? "missing value for" : "unknown argument", argv[i]);
            matrix_usage(stderr);
            return 2;
        }
    }
    if (!valence) {
        fprintf(stderr, "ccnurbs matrix: --valence is required\n");
        matrix_usage(stderr);
        return 2;
    }
    if (matrix_parse_valence(valence, &n) || matrix_parse_scheme(scheme_s, &scheme)) return 2;
    d = malloc(sizeof(double) * (size_t)n);
    M = malloc(sizeof(double) * (size_t)(2 * n + 1) * (size_t)(2 * n + 1));
    if (!d || !M) {
        fprintf(stderr, "ccnurbs matrix: out of memory for valence %ld\n", n);
        goto done;
    }
    for (k = 0; k < n; k++) d[k] = 1.0;
    if (knots && matrix_parse_knots(knots, n, d)) goto done;
    if (ccn_ev_matrix((int32_t)n, d, scheme, M, &info, &err) != CCN_OK) {
        fprintf(stderr, "ccnurbs matrix: %s\n", err.message);
        goto done;
    }
    matrix_print(n, d, scheme, M, &info, &err);
    rc = fflush(stdout) == 0 ? 0 : 2;
done:
    free(d);
    free(M);
    return rc;
}
