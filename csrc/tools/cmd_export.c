/* ccnurbs export: the exact limit surface as STEP or IGES (ccn_plan_export), with the face
 * counts and continuity figures on stdout as "key: value" lines.
 *
 *   ccnurbs export --format step|iges [--unpacked] [--fill-levels N] [--name NAME]
 *                  [--face-map FILE] [--scheme ...] [--cap ...] [--corners ...] [--levels L]
 *                  in.obj out.step
 *
 * --face-map FILE: per face "F index kind patch cells", then per cell "C cage_face sub u0 u1
 * v0 v1 s0 t0 s1 t1 s2 t2" (ccn_export_cell): where every face lies on the cage, for tests.
 * --levels L: the plan's output level; raised until the plan builds its bi-5 caps (they exist
 * only above the cap level; ccn_plan_stats.num_caps_deferred).
 * Output files are written to a temporary name and renamed: nothing is left on failure. */
#include "cli.h"
#include "commands.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int write_file(void *user, const char *data, size_t len) {
    return fwrite(data, 1, len, (FILE *)user) != len;
}

static void face_line(void *user, const ccn_export_face *f) {
    FILE *o = user;
    fprintf(o, "F %d %d %d %d\n", (int)f->index, (int)f->kind, (int)f->patch, (int)f->num_cells);
    for (int32_t i = 0; i < f->num_cells; i++) {
        const ccn_export_cell *c = &f->cells[i];
        fprintf(o, "C %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                (int)c->cage_face, (int)c->sub, c->uv[0], c->uv[1], c->uv[2], c->uv[3],
                c->st[0][0], c->st[0][1], c->st[1][0], c->st[1][1], c->st[2][0], c->st[2][1]);
    }
}

static char *tmp_name(const char *path) {
    size_t n = strlen(path) + 32;
    char *t = malloc(n);
    if (t) snprintf(t, n, "%s.tmp%ld", path, (long)getpid());
    return t;
}

static const char *KIND[5] = {"packs", "bicubic", "bi5", "refined", "fill_faces"};

int ccn_cmd_export(int argc, char **argv) {
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    const char *map = NULL;
    int have_format = 0;
    char **rest = malloc(sizeof(char *) * (size_t)(argc + 1));
    int nrest = 0;
    if (!rest) { fprintf(stderr, "ccnurbs: out of memory\n"); return 2; }
    rest[nrest++] = argv[0];
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--format") == 0 && val) {
            if (strcmp(val, "step") == 0) eo.format = CCN_EXPORT_STEP;
            else if (strcmp(val, "iges") == 0) eo.format = CCN_EXPORT_IGES;
            else { fprintf(stderr, "ccnurbs: bad --format '%s' (step or iges)\n", val); free(rest); return 2; }
            have_format = 1;
            i++;
        } else if (strcmp(a, "--unpacked") == 0) {
            eo.flags |= CCN_EXPORT_UNPACKED;
        } else if (strcmp(a, "--fill-levels") == 0 && val) {
            int n;
            if (ccn_cli_int(val, 1, 12, &n)) { fprintf(stderr, "ccnurbs: --fill-levels must be 1..12\n"); free(rest); return 2; }
            eo.fill_levels = n;
            i++;
        } else if (strcmp(a, "--name") == 0 && val) {
            eo.name = val;
            i++;
        } else if (strcmp(a, "--face-map") == 0 && val) {
            map = val;
            i++;
        } else {
            rest[nrest++] = argv[i];
        }
    }
    ccn_options o = {0};
    const char *in = NULL, *out = NULL;
    int rc = ccn_cli_parse(nrest, rest, CCN_CLI_LEVELS | CCN_CLI_CAP, 10, &o, NULL, &in, &out);
    free(rest);
    if (rc) return rc;
    if (!have_format) { /* from the extension, else STEP */
        size_t n = strlen(out);
        if ((n > 4 && strcmp(out + n - 4, ".igs") == 0) || (n > 5 && strcmp(out + n - 5, ".iges") == 0))
            eo.format = CCN_EXPORT_IGES;
    }
    ccn_plan *plan = NULL;
    if ((rc = ccn_cli_load_plan_caps(in, &o, &plan))) return rc;
    char *tmp = tmp_name(out), *tmap = map ? tmp_name(map) : NULL;
    FILE *f = tmp ? fopen(tmp, "wb") : NULL, *fm = NULL;
    if (!f) { fprintf(stderr, "ccnurbs: cannot write %s\n", out); rc = 2; goto done; }
    if (map && (!tmap || !(fm = fopen(tmap, "wb")))) { fprintf(stderr, "ccnurbs: cannot write %s\n", map); rc = 2; goto done; }
    if (fm) { eo.face_fn = face_line; eo.face_user = fm; }
    ccn_export_info info;
    ccn_error err;
    ccn_status st = ccn_plan_export(plan, NULL, &eo, write_file, f, &info, &err);
    int wbad = fclose(f) != 0;
    f = NULL;
    if (fm) { wbad |= fclose(fm) != 0; fm = NULL; }
    if (st) { rc = ccn_cli_error(in, &err); goto done; }
    if (wbad || rename(tmp, out) != 0 || (map && rename(tmap, map) != 0)) {
        fprintf(stderr, "ccnurbs: cannot write %s\n", out);
        rc = 2;
        goto done;
    }
    printf("format: %s\nfaces: %d\n", eo.format == CCN_EXPORT_IGES ? "iges" : "step", (int)info.num_faces);
    int32_t by[5] = {info.num_packs, info.num_bicubic, info.num_bi5, info.num_refined, info.num_fill_faces};
    for (int k = 0; k < 5; k++) printf("%s: %d\n", KIND[k], (int)by[k]);
    printf("packed_cage_faces: %d\nfills: %d\nfill_level: %d\nedges: %d\nvertices: %d\nshells: %d\n"
           "boundary_edges: %d\nclosed: %d\nmax_g1_deviation: %.3e\nmax_fill_g1_deviation: %.3e\n"
           "size: %.17g\nbytes: %lld\ncrease_edges: %d\nmin_crease_angle: %.3e\nmax_crease_angle: %.3e\n",
           (int)info.num_packed_cage_faces, (int)info.num_fills, (int)info.fill_level,
           (int)info.num_edges, (int)info.num_vertices, (int)info.num_shells,
           (int)info.num_boundary_edges, (int)info.closed, info.max_g1_deviation,
           info.max_fill_g1_deviation, info.size, (long long)info.bytes, (int)info.num_crease_edges,
           info.min_crease_angle, info.max_crease_angle);
done:
    if (f) fclose(f);
    if (fm) fclose(fm);
    if (rc && tmp) remove(tmp);
    if (rc && tmap) remove(tmap);
    free(tmp);
    free(tmap);
    ccn_plan_destroy(plan);
    return rc;
}
