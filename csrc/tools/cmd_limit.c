/* ccnurbs limit: the limit mesh (positions + exact normals) as OBJ with vn lines; the UV map
 * (vt) as limit values per face corner (f v/vt/vn, --fvar-linear). An output named *.ply is
 * written as PLY (MeshLab, CloudCompare) with vertex properties x y z nx ny nz, and with
 * --curvature also k1 k2, the principal curvatures (k1 >= k2, positive where the surface bends
 * away from its normal; nan where unbounded or not computed, see ccn_limit_mesh). */
#include "cli.h"
#include "commands.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct { int32_t width, num_values; const double *values; const int32_t *face_values; } uv_out;

/* vn lines: one per vertex, or (corner normals) one per face corner, 4 per face in order. */
/* evs: the output's extraordinary points by ccn_ev_surface (capped, blended, refined, G1 fill). */
static int write_limit(FILE *f, const ccn_sizes *s, const ccn_plan_stats *ps, const ccn_limit_mesh *lm,
                       const uv_out *uv, const int32_t evs[4]) {
    fprintf(f, "# ccnurbs limit level %d: %d vertices, %d faces, %d caps, %d cap fallbacks, "
               "%d EV fallbacks, %d ring conflicts\n", (int)ps->levels, (int)s->num_verts,
            (int)s->num_faces, (int)ps->num_caps, (int)ps->num_cap_fallbacks,
            (int)ps->num_ev_fallbacks, (int)ps->num_ring_conflicts);
    if (evs[0] + evs[1] + evs[2] + evs[3])
        fprintf(f, "# extraordinary points: %d guided bi-5 cap, %d blended, %d G1 fill cap, %d refined limit\n",
                (int)evs[CCN_EV_CAPPED], (int)evs[CCN_EV_CAP_BLENDED], (int)evs[CCN_EV_FILLED],
                (int)evs[CCN_EV_REFINED]);
    for (int32_t v = 0; v < s->num_verts; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", lm->positions[3 * v], lm->positions[3 * v + 1],
                lm->positions[3 * v + 2]);
    const double *nrm = lm->corner_normals ? lm->corner_normals : lm->normals;
    int32_t nn = lm->corner_normals ? 4 * s->num_faces : s->num_verts;
    for (int32_t v = 0; v < nn; v++)
        fprintf(f, "vn %.17g %.17g %.17g\n", nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
    for (int32_t i = 0; uv && i < uv->num_values; i++) {
        fputs("vt", f);
        for (int32_t k = 0; k < uv->width; k++) fprintf(f, " %.17g", uv->values[(size_t)uv->width * i + k]);
        fputc('\n', f);
    }
    for (int32_t q = 0; q < s->num_faces; q++) {
        const int32_t *fv = lm->face_verts + 4 * q;
        fputc('f', f);
        for (int k = 0; k < 4; k++) {
            int32_t n = lm->corner_normals ? 4 * q + k : fv[k];
            if (uv) fprintf(f, " %d/%d/%d", fv[k] + 1, uv->face_values[4 * q + k] + 1, n + 1);
            else fprintf(f, " %d//%d", fv[k] + 1, n + 1);
        }
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

static int ends_with(const char *s, const char *tail) {
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && strcmp(s + n - m, tail) == 0;
}

/* ASCII PLY: per vertex x y z nx ny nz (k1 k2 with curvatures), quads as faces. */
static int write_ply(FILE *f, const ccn_sizes *s, const ccn_plan_stats *ps, const ccn_limit_mesh *lm) {
    fprintf(f, "ply\nformat ascii 1.0\ncomment ccnurbs limit level %d\n", (int)ps->levels);
    if (lm->curvatures)
        fputs("comment k1 >= k2: principal curvatures, positive where the surface bends away from "
              "its normal; nan where unbounded (an extraordinary vertex without a cap) or not "
              "computed (creases, corners, caps)\n", f);
    fprintf(f, "element vertex %d\n", (int)s->num_verts);
    const char *props[] = {"x", "y", "z", "nx", "ny", "nz", "k1", "k2"};
    for (int k = 0; k < (lm->curvatures ? 8 : 6); k++) fprintf(f, "property double %s\n", props[k]);
    fprintf(f, "element face %d\nproperty list uchar int vertex_indices\nend_header\n", (int)s->num_faces);
    for (int32_t v = 0; v < s->num_verts; v++) {
        const double *x = lm->positions + 3 * (size_t)v, *n = lm->normals + 3 * (size_t)v;
        fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g", x[0], x[1], x[2], n[0], n[1], n[2]);
        if (lm->curvatures) {
            for (int k = 0; k < 2; k++) {
                double c = lm->curvatures[2 * (size_t)v + k];
                if (c != c) fputs(" nan", f);
                else fprintf(f, " %.17g", c);
            }
        }
        fputc('\n', f);
    }
    for (int32_t q = 0; q < s->num_faces; q++) {
        const int32_t *fv = lm->face_verts + 4 * q;
        fprintf(f, "4 %d %d %d %d\n", (int)fv[0], (int)fv[1], (int)fv[2], (int)fv[3]);
    }
    return ferror(f) ? -1 : 0;
}

static int write_atomic(const char *path, const ccn_sizes *s, const ccn_plan_stats *ps, const ccn_limit_mesh *lm,
                        const uv_out *uv, const int32_t evs[4]) {
    size_t n = strlen(path);
    char *tmp = malloc(n + 32);
    if (!tmp) return 2;
    snprintf(tmp, n + 32, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int rc = !f ? -1 : ends_with(path, ".ply") ? write_ply(f, s, ps, lm) : write_limit(f, s, ps, lm, uv, evs);
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
    int curvature = 0;      /* --curvature: k1 k2 per vertex (PLY output) */
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--corner-normals") == 0 || strcmp(argv[i], "--curvature") == 0) {
            if (strcmp(argv[i], "--corner-normals") == 0) corner_normals = 1;
            else curvature = 1;
            for (int j = i; j + 1 < argc; j++) argv[j] = argv[j + 1];
            argc--;
            i--;
        }
    int fvar_linear = -1;
    int rc = ccn_cli_parse(argc, argv, CCN_CLI_LEVELS | CCN_CLI_CAP, 10, &o, &fvar_linear, &in, &out);
    if (rc) return rc;
    if (curvature && !ends_with(out, ".ply")) {
        fprintf(stderr, "ccnurbs limit: --curvature writes PLY: name the output *.ply\n");
        return 2;
    }
    ccn_obj *obj = NULL;
    ccn_cage cage;
    ccn_fvar_channel uvc;
    if ((rc = ccn_cli_load_uv(in, &o, &fvar_linear, &obj, &cage, &uvc))) return rc;
    ccn_plan *plan = NULL;
    ccn_error err;
    int32_t ch = -1;
    if (ccn_plan_create(&cage, &o, &plan, &err) || (uvc.num_values && ccn_plan_add_fvar(plan, &uvc, &ch, &err))) {
        ccn_plan_destroy(plan);
        ccn_obj_destroy(obj);
        return ccn_cli_error(in, &err);
    }
    ccn_obj_destroy(obj);
    ccn_sizes s;
    ccn_plan_get_sizes(plan, &s);
    ccn_plan_stats ps;
    ccn_plan_get_stats(plan, &ps);
    uv_out uv = {0, 0, NULL, NULL};
    double *uv_values = NULL;
    int32_t *uv_faces = NULL;
    if (ch >= 0) {
        ccn_fvar_sizes fs;
        ccn_plan_get_fvar_sizes(plan, ch, &fs);
        uv.width = fs.width;
        uv.num_values = fs.num_values;
        uv_values = malloc(sizeof(double) * (size_t)fs.width * (size_t)(fs.num_values ? fs.num_values : 1));
        uv_faces = malloc(sizeof(int32_t) * 4 * (size_t)(s.num_faces ? s.num_faces : 1));
        uv.values = uv_values;
        uv.face_values = uv_faces;
    }
    ccn_limit_mesh lm = {0};
    lm.positions = malloc(sizeof(double) * 3 * (size_t)(s.num_verts ? s.num_verts : 1));
    lm.normals = malloc(sizeof(double) * 3 * (size_t)(s.num_verts ? s.num_verts : 1));
    lm.face_verts = malloc(sizeof(int32_t) * 4 * (size_t)(s.num_faces ? s.num_faces : 1));
    if (corner_normals) lm.corner_normals = malloc(sizeof(double) * 12 * (size_t)(s.num_faces ? s.num_faces : 1));
    if (curvature) lm.curvatures = malloc(sizeof(double) * 2 * (size_t)(s.num_verts ? s.num_verts : 1));
    if (!lm.positions || !lm.normals || !lm.face_verts || (corner_normals && !lm.corner_normals) ||
        (curvature && !lm.curvatures) ||
        (ch >= 0 && (!uv_values || !uv_faces))) {
        fprintf(stderr, "ccnurbs: out of memory\n");
        rc = 2;
    } else if (ccn_plan_evaluate(plan, NULL, &lm, &err) ||
               (ch >= 0 && ccn_plan_evaluate_fvar(plan, ch, NULL, uv_values, uv_faces, &err))) {
        rc = ccn_cli_error(in, &err);
    } else {
        int32_t evs[4] = {0, 0, 0, 0}, nev = 0, *kind = NULL;
        if (ccn_plan_get_evs(plan, &nev, NULL, NULL) == CCN_OK && nev > 0 && (kind = malloc(sizeof(int32_t) * (size_t)nev)) &&
            ccn_plan_get_evs(plan, &nev, NULL, kind) == CCN_OK)
            for (int32_t i = 0; i < nev; i++)
                if (kind[i] >= 0 && kind[i] < 4) evs[kind[i]]++;
        free(kind);
        rc = write_atomic(out, &s, &ps, &lm, ch >= 0 ? &uv : NULL, evs);
    }
    free(lm.positions); free(lm.normals); free(lm.face_verts); free(lm.corner_normals);
    free(lm.curvatures);
    free(uv_values); free(uv_faces);
    ccn_plan_destroy(plan);
    return rc;
}
