/* ccnurbs refine: K levels of control-mesh refinement, OBJ in and out; the UV map (vt) is
 * refined with it as a face-varying channel (--fvar-linear). */
#include "cli.h"
#include "commands.h"

#include <stdio.h>

int ccn_cmd_refine(int argc, char **argv) {
    ccn_options o = {0};
    o.levels = 1;
    int fvar_linear = -1;
    const char *in = NULL, *out = NULL;
    int rc0 = ccn_cli_parse(argc, argv, CCN_CLI_LEVELS, 16, &o, &fvar_linear, &in, &out);
    if (rc0) return rc0;
    ccn_obj *obj = NULL;
    ccn_cage cage;
    ccn_fvar_channel uv;
    int rc = ccn_cli_load_uv(in, &o, &fvar_linear, &obj, &cage, &uv);
    if (rc) return rc;
    ccn_mesh *cm = NULL, *ref = NULL;
    ccn_fvar *fv = NULL;
    ccn_error err;
    char header[160] = "";
    if (ccn_mesh_create(&cage, &cm, &err) || ccn_refine(cm, o.levels, &o, &ref, &err) ||
        (uv.num_values && ccn_fvar_refine(cm, &uv, o.levels, &o, &fv, &err))) {
        rc = ccn_cli_error(in, &err);
    } else {
        if (fv) snprintf(header, sizeof header, "# ccnurbs uv: --fvar-linear %s\n", ccn_cli_fvar_linear_name(fvar_linear));
        rc = ccn_cli_write_mesh_uv(out, ref, fv, header);
    }
    ccn_fvar_destroy(fv);
    ccn_mesh_destroy(cm);
    ccn_mesh_destroy(ref);
    ccn_obj_destroy(obj);
    return rc;
}
