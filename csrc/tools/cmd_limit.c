/* ccnurbs limit: the limit mesh (positions + exact normals) as OBJ with vn lines. */
#include "cli.h"
#include "commands.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* vn lines: one per vertex, or (corner normals) one per face corner, 4 per face in order. */
static int write_limit(FILE *f, const ccn_sizes *s, const ccn_limit_mesh *lm) {
    fprintf(f, "# ccnurbs limit level %d: %d vertices, %d faces, %d caps, %d cap fallbacks, "
               "%d EV fallbacks, %d ring conflicts\n", (int)s->levels, (int)s->num_verts,
            (int)s->num_faces, (int)s->num_caps, (int)s->num_cap_fallbacks,
            (int)s->num_ev_fallbacks, (int)s->num_ring_conflicts);
    for (int32_t v = 0; v < s->num_verts; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", lm->positions[3 * v], lm->positions[3 * v + 1],
                lm->positions[3 * v + 2]);
    const double *nrm = lm->corner_normals ? lm->corner_normals : lm->normals;
    int32_t nn = lm->corner_normals ? 4 * s->num_faces : s->num_verts;
    for (int32_t v = 0; v < nn; v++)
        fprintf(f, "vn %.17g %.17g %.17g\n", nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
    for (int32_t q = 0; q < s->num_faces; q++) {
        const int32_t *fv = lm->face_verts + 4 * q;
        int32_t n0 = lm->corner_normals ? 4 * q : fv[0], n1 = lm->corner_normals ? 4 * q + 1 : fv[1];
        int32_t n2 = lm->corner_normals ? 4 * q + 2 : fv[2], n3 = lm->corner_normals ? 4 * q + 3 : fv[3];
        fprintf(f, "f %d//%d %d//%d %d//%d %d//%d\n", fv[0] + 1, n0 + 1, fv[1] + 1, n1 + 1,
                fv[2] + 1, n2 + 1, fv[3] + 1, n3 + 1);
    }
    return ferror(f) ? -1 : 0;
}

static int write_atomic(const char *path, const ccn_sizes *s, const ccn_limit_mesh *lm) {
    size_t n = strlen(path);
    char *tmp = malloc(n + 32);
    if (!tmp) return 2;
    snprintf(tmp, n + 32, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int rc = f ? write_limit(f, s, lm) : -1;
    if (f && fclose(f) != 0) rc = -1;
    if (rc == 0 && rename(tmp, path) != 0) rc = -1;
    if (rc) { remove(tmp); fprintf(stderr, "ccnurbs: cannot write %s\n", path); }
    free(tmp);
    return rc ? 2 : 0;
}

int ccn_cmd_limit(int argc, char **argv) {
    ccn_options o = {0};
    const char *in = NULL, *out = NULL;
    o.levels = 2;
    int corner_normals = 0; /* --corner-normals: one vn per face corner (creased surfaces) */
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--corner-normals") == 0) {
            corner_normals = 1;
            for (int j = i; j + 1 < argc; j++) argv[j] = argv[j + 1];
            argc--;
            i--;
        }
    int rc = ccn_cli_parse(argc, argv, CCN_CLI_LEVELS | CCN_CLI_CAP, 10, &o, &in, &out);
    if (rc) return rc;
    ccn_plan *plan = NULL;
    if ((rc = ccn_cli_load_plan(in, &o, &plan))) return rc;
    ccn_sizes s;
    ccn_plan_sizes(plan, &s);
    ccn_limit_mesh lm = {0};
    lm.positions = malloc(sizeof(double) * 3 * (size_t)(s.num_verts ? s.num_verts : 1));
    lm.normals = malloc(sizeof(double) * 3 * (size_t)(s.num_verts ? s.num_verts : 1));
    lm.face_verts = malloc(sizeof(int32_t) * 4 * (size_t)(s.num_faces ? s.num_faces : 1));
    if (corner_normals) lm.corner_normals = malloc(sizeof(double) * 12 * (size_t)(s.num_faces ? s.num_faces : 1));
    ccn_error err;
    if (!lm.positions || !lm.normals || !lm.face_verts || (corner_normals && !lm.corner_normals)) {
        fprintf(stderr, "ccnurbs: out of memory\n");
        rc = 2;
    } else if (ccn_plan_evaluate(plan, NULL, &lm, &err)) {
        rc = ccn_cli_error(in, &err);
    } else {
        rc = write_atomic(out, &s, &lm);
    }
    free(lm.positions); free(lm.normals); free(lm.face_verts); free(lm.corner_normals);
    ccn_plan_destroy(plan);
    return rc;
}
