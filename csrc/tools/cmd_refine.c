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
    o.levels = 1;
    const char *in = NULL, *out = NULL;
    int rc0 = ccn_cli_parse(argc, argv, CCN_CLI_LEVELS, 16, &o, &in, &out);
    if (rc0) return rc0;
    ccn_mesh *cage = NULL, *ref = NULL;
    int rc = ccn_cli_load_mesh(in, &cage);
    if (rc) return rc;
    ccn_error err;
    if (ccn_refine(cage, o.levels, &o, &ref, &err)) rc = ccn_cli_error(in, &err);
    else rc = ccn_cli_write_mesh(out, ref, NULL);
    ccn_mesh_destroy(cage);
    ccn_mesh_destroy(ref);
    return rc;
}
