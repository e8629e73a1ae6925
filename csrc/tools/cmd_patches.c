/* ccnurbs patches: the finite patch set in BezierView format (type 4 = tensor patch of
 * degree d: a line "4", a line "d", then (d+1)^2 points), for public viewers. The output
 * level is raised until the bi-5 caps exist (none at levels not above the cap level). */
#include "cli.h"
#include "commands.h"

#include <stdlib.h>
#include <string.h>

typedef struct { FILE *f; int32_t n3, n5; } bv_out;

static void put_patch(void *user, int32_t degree, const double *pts, int32_t cage_face) {
    bv_out *o = user;
    (void)cage_face;
    fprintf(o->f, "4\n%d\n", (int)degree);
    for (int32_t i = 0; i < (degree + 1) * (degree + 1); i++)
        fprintf(o->f, "%.17g %.17g %.17g\n", pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    if (degree == 3) o->n3++; else o->n5++;
}

int ccn_cmd_patches(int argc, char **argv) {
    ccn_options o = {0};
    const char *in = NULL, *out = NULL;
    int rc0 = ccn_cli_parse(argc, argv, CCN_CLI_CAP, 0, &o, NULL, &in, &out);
    if (rc0) return rc0;
    ccn_plan *plan = NULL;
    int rc = ccn_cli_load_plan_caps(in, &o, &plan);
    if (rc) return rc;
    ccn_sizes s;
    ccn_plan_get_sizes(plan, &s);
    ccn_limit_mesh lm = {0};
    lm.positions = malloc(sizeof(double) * 3 * (size_t)(s.num_verts ? s.num_verts : 1));
    ccn_error err;
    size_t n = strlen(out);
    char *tmp = malloc(n + 8);
    FILE *f = NULL;
    if (!lm.positions || !tmp) { rc = 2; fprintf(stderr, "ccnurbs: out of memory\n"); goto done; }
    if (ccn_plan_evaluate(plan, NULL, &lm, &err)) { rc = ccn_cli_error(in, &err); goto done; }
    snprintf(tmp, n + 8, "%s.tmp", out);
    if (!(f = fopen(tmp, "wb"))) { rc = 2; fprintf(stderr, "ccnurbs: cannot write %s\n", out); goto done; }
    bv_out bo = {f, 0, 0};
    int32_t skipped = 0;
    ccn_plan_patches(plan, put_patch, &bo, &skipped);
    if (fclose(f) != 0 || rename(tmp, out) != 0) { remove(tmp); rc = 2; fprintf(stderr, "ccnurbs: cannot write %s\n", out); goto done; }
    fprintf(stderr, "ccnurbs: %d bicubic and %d bi-5 patches written to %s (%d irregular faces "
                    "not representable as patches)\n", (int)bo.n3, (int)bo.n5, out, (int)skipped);
done:
    free(tmp);
    free(lm.positions);
    ccn_plan_destroy(plan);
    return rc;
}
