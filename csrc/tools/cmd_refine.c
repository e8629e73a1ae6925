/* ccnurbs refine: K levels of control-mesh refinement, OBJ in and out. */
#include "cli.h"
#include "commands.h"

int ccn_cmd_refine(int argc, char **argv) {
    ccn_options o = {0};
    o.levels = 1;
    const char *in = NULL, *out = NULL;
    int rc0 = ccn_cli_parse(argc, argv, CCN_CLI_LEVELS, 16, &o, &in, &out);
    if (rc0) return rc0;
    ccn_mesh *cage = NULL, *ref = NULL;
    int rc = ccn_cli_load_mesh(in, &o, &cage);
    if (rc) return rc;
    ccn_error err;
    if (ccn_refine(cage, o.levels, &o, &ref, &err)) rc = ccn_cli_error(in, &err);
    else rc = ccn_cli_write_mesh(out, ref, NULL);
    ccn_mesh_destroy(cage);
    ccn_mesh_destroy(ref);
    return rc;
}
