/* ccnurbs refine: K levels of control-mesh refinement, OBJ in and out. */
#include "cli.h"

#include <string.h>

int ccn_cli_scheme(const char *s, ccn_scheme *out) {
    if (strcmp(s, "eigen") == 0) *out = CCN_SCHEME_EIGEN;
    else if (strcmp(s, "nurss") == 0) *out = CCN_SCHEME_NURSS;
    else if (strcmp(s, "cc") == 0) *out = CCN_SCHEME_CATMULL_CLARK;
    else return -1;
    return 0;
}

int ccn_cmd_refine(int argc, char **argv) {
    ccn_options o = {0};
    int levels = 1;
    const char *in = NULL, *out = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--scheme") == 0 && val) {
            if (ccn_cli_scheme(val, &o.scheme)) { fprintf(stderr, "ccnurbs: bad --scheme '%s'\n", val); return 2; }
            i++;
        } else if (strcmp(a, "--levels") == 0 && val) {
            if (ccn_cli_int(val, 0, 16, &levels)) { fprintf(stderr, "ccnurbs: --levels must be 0..16\n"); return 2; }
            i++;
        } else if (strcmp(a, "--corners") == 0 && val) {
            if (strcmp(val, "smooth") == 0) o.boundary_corners = CCN_CORNERS_SMOOTH;
            else if (strcmp(val, "pinned") == 0) o.boundary_corners = CCN_CORNERS_PINNED;
            else { fprintf(stderr, "ccnurbs: bad --corners '%s'\n", val); return 2; }
            i++;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "ccnurbs: unknown or incomplete option '%s'\n", a);
            return 2;
        } else if (!in) in = a;
        else if (!out) out = a;
        else { fprintf(stderr, "ccnurbs: too many arguments\n"); return 2; }
    }
    if (!in || !out) { fprintf(stderr, "ccnurbs refine: need in.obj and out.obj\n"); return 2; }
    ccn_mesh *cage = NULL, *ref = NULL;
    int rc = ccn_cli_load_mesh(in, &cage);
    if (rc) return rc;
    ccn_error err;
    if (ccn_refine(cage, levels, &o, &ref, &err)) rc = ccn_cli_error(in, &err);
    else rc = ccn_cli_write_mesh(out, ref, NULL);
    ccn_mesh_destroy(cage);
    ccn_mesh_destroy(ref);
    return rc;
}
