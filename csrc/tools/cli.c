/* Shared helpers of the ccnurbs command-line tool. */
#include "cli.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

char *ccn_cli_read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "ccnurbs: cannot open %s: %s\n", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        char *nb = realloc(buf, 2 * cap + 1);
        if (!nb) { free(buf); buf = NULL; break; }
        buf = nb;
        cap *= 2;
    }
    int bad = ferror(f);
    fclose(f);
    if (!buf || bad) {
        fprintf(stderr, "ccnurbs: cannot read %s\n", path);
        free(buf);
        return NULL;
    }
    buf[n] = '\0';
    *len = n;
    return buf;
}

int ccn_cli_error(const char *what, const ccn_error *err) {
    fprintf(stderr, "ccnurbs: %s: %s: %s\n", what, ccn_status_name(err->status), err->message);
    return 2;
}

/* Parses an OBJ file; on success *obj holds the data viewed by *cage. */
static int load_cage(const char *path, ccn_obj **obj, ccn_cage *cage) {
    size_t len = 0;
    char *text = ccn_cli_read_file(path, &len);
    if (!text) return 2;
    ccn_error err;
    ccn_status st = ccn_obj_parse(text, len, obj, &err);
    free(text);
    if (st) return ccn_cli_error(path, &err);
    ccn_obj_get_cage(*obj, cage);
    for (int32_t i = 0; i < ccn_obj_get_num_warnings(*obj); i++)
        fprintf(stderr, "ccnurbs: %s: warning: %s\n", path, ccn_obj_get_warning(*obj, i));
    return 0;
}

/* Options left unset on the command line (-1) come from the file's tags, else the defaults. */
static void resolve_options(const ccn_obj *obj, ccn_options *o) {
    ccn_obj_tags t;
    ccn_obj_get_tags(obj, &t);
    if (o->boundary_corners < 0) o->boundary_corners = t.boundary_corners >= 0 ? t.boundary_corners : CCN_CORNERS_SMOOTH;
    if (o->crease_method < 0) o->crease_method = t.crease_method >= 0 ? t.crease_method : CCN_CREASE_UNIFORM;
}

int ccn_cli_load_uv(const char *path, ccn_options *o, int *fvar_linear, ccn_obj **obj,
                    ccn_cage *cage, ccn_fvar_channel *uv) {
    int rc = load_cage(path, obj, cage);
    if (rc) return rc;
    resolve_options(*obj, o);
    ccn_obj_get_fvar(*obj, uv);
    if (*fvar_linear < 0) *fvar_linear = uv->linear;
    uv->linear = *fvar_linear;
    return 0;
}

static const char *FVAR_NAMES[] = {"none", "corners-only", "corners-plus1", "corners-plus2",
                                   "boundaries", "all"};

int ccn_cli_fvar_linear(const char *s) {
    for (int m = 0; m < 6; m++)
        if (strcmp(s, FVAR_NAMES[m]) == 0) return m;
    return -1;
}

const char *ccn_cli_fvar_linear_name(int m) {
    return m >= 0 && m < 6 ? FVAR_NAMES[m] : "?";
}

int ccn_cli_load_plan(const char *path, ccn_options *o, ccn_plan **plan) {
    ccn_obj *obj = NULL;
    ccn_cage cage;
    int rc = load_cage(path, &obj, &cage);
    if (rc) return rc;
    resolve_options(obj, o);
    ccn_error err;
    ccn_status st = ccn_plan_create(&cage, o, plan, &err);
    ccn_obj_destroy(obj);
    return st ? ccn_cli_error(path, &err) : 0;
}

int ccn_cli_load_plan_caps(const char *path, ccn_options *o, ccn_plan **plan) {
    ccn_obj *obj = NULL;
    ccn_cage cage;
    int rc = load_cage(path, &obj, &cage);
    if (rc) return rc;
    resolve_options(obj, o);
    ccn_error err;
    ccn_status st = ccn_plan_create(&cage, o, plan, &err);
    ccn_plan_stats ps;
    while (!st && ccn_plan_get_stats(*plan, &ps) == CCN_OK && ps.num_caps_deferred > 0 && ps.levels < 10) {
        ccn_plan_destroy(*plan);
        *plan = NULL;
        o->levels = ps.levels + 1;
        st = ccn_plan_create(&cage, o, plan, &err);
    }
    ccn_obj_destroy(obj);
    return st ? ccn_cli_error(path, &err) : 0;
}

/* vt lines and the texture index of each face corner of a refined UV map. */
static int write_uv_values(FILE *f, const ccn_fvar *uv, int32_t **corner) {
    ccn_fvar_info fi;
    ccn_fvar_get_info(uv, &fi);
    double *val = malloc(sizeof(double) * (size_t)fi.width * (size_t)(fi.num_values ? fi.num_values : 1));
    *corner = malloc(sizeof(int32_t) * (size_t)(fi.num_face_verts ? fi.num_face_verts : 1));
    if (!val || !*corner) { free(val); return -1; }
    ccn_fvar_copy(uv, val, *corner);
    fprintf(f, "# ccnurbs uv: %d values, %d seam edges, %d sharp values\n", (int)fi.num_values,
            (int)fi.num_seam_edges, (int)fi.num_sharp_values);
    for (int32_t i = 0; i < fi.num_values; i++) {
        fputs("vt", f);
        for (int32_t k = 0; k < fi.width; k++) fprintf(f, " %.17g", val[(size_t)fi.width * i + k]);
        fputc('\n', f);
    }
    free(val);
    return 0;
}

static int write_body(FILE *f, const ccn_mesh *m, const ccn_fvar *uv, const char *header) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)(in.num_verts ? in.num_verts : 1));
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)(in.num_faces ? in.num_faces : 1));
    int32_t *fv = malloc(sizeof(int32_t) * (size_t)(in.num_face_verts ? in.num_face_verts : 1));
    int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)(in.num_edges ? in.num_edges : 1));
    double *ek = malloc(sizeof(double) * (size_t)(in.num_edges ? in.num_edges : 1));
    double *es = malloc(sizeof(double) * (size_t)(in.num_edges ? in.num_edges : 1));
    double *vs = malloc(sizeof(double) * (size_t)(in.num_verts ? in.num_verts : 1));
    int32_t *uvc = NULL;
    int rc = -1;
    if (!pos || !fs || !fv || !ev || !ek || !es || !vs) goto done;
    ccn_mesh_copy(m, pos, fs, fv, ev, ek);
    ccn_mesh_get_creases(m, es, vs);
    if (header) fprintf(f, "%s", header);
    fprintf(f, "# ccnurbs level %d: %d vertices, %d faces, %d edges, %d ring conflicts, "
               "%d EV fallbacks\n", (int)in.level, (int)in.num_verts, (int)in.num_faces,
            (int)in.num_edges, (int)in.num_ring_conflicts, (int)in.num_ev_fallbacks);
    for (int32_t v = 0; v < in.num_verts; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
    if (uv && write_uv_values(f, uv, &uvc)) goto done;
    for (int32_t i = 0, k = 0; i < in.num_faces; i++) {
        fputc('f', f);
        for (int32_t j = 0; j < fs[i]; j++, k++) {
            if (uvc) fprintf(f, " %d/%d", (int)fv[k] + 1, (int)uvc[k] + 1);
            else fprintf(f, " %d", (int)fv[k] + 1);
        }
        fputc('\n', f);
    }
    for (int32_t e = 0; e < in.num_edges; e++)
        fprintf(f, "# knot %d %d %.17g\n", (int)ev[2 * e] + 1, (int)ev[2 * e + 1] + 1, ek[e]);
    for (int32_t e = 0; e < in.num_edges; e++)
        if (es[e] > 0)
            fprintf(f, "# crease %d %d %.9g\n", (int)ev[2 * e] + 1, (int)ev[2 * e + 1] + 1, es[e]);
    for (int32_t v = 0; v < in.num_verts; v++)
        if (vs[v] > 0) fprintf(f, "# corner %d %.9g\n", (int)v + 1, vs[v]);
    rc = ferror(f) ? -1 : 0;
done:
    free(pos); free(fs); free(fv); free(ev); free(ek); free(es); free(vs); free(uvc);
    return rc;
}

int ccn_cli_write_mesh(const char *path, const ccn_mesh *m, const char *header) {
    return ccn_cli_write_mesh_uv(path, m, NULL, header);
}

int ccn_cli_write_mesh_uv(const char *path, const ccn_mesh *m, const ccn_fvar *uv, const char *header) {
    size_t n = strlen(path);
    char *tmp = malloc(n + 16);
    if (!tmp) return 2;
    snprintf(tmp, n + 16, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        fprintf(stderr, "ccnurbs: cannot write %s: %s\n", path, strerror(errno));
        free(tmp);
        return 2;
    }
    int rc = write_body(f, m, uv, header);
    if (fclose(f) != 0) rc = -1;
    if (rc == 0 && rename(tmp, path) != 0) rc = -1;
    if (rc != 0) {
        remove(tmp);
        fprintf(stderr, "ccnurbs: cannot write %s\n", path);
    }
    free(tmp);
    return rc ? 2 : 0;
}

int ccn_cli_scheme(const char *s, ccn_scheme *out) {
    if (strcmp(s, "eigen") == 0) *out = CCN_SCHEME_EIGEN;
    else if (strcmp(s, "nurss") == 0) *out = CCN_SCHEME_NURSS;
    else if (strcmp(s, "cc") == 0) *out = CCN_SCHEME_CATMULL_CLARK;
    else return -1;
    return 0;
}

const char *ccn_cli_scheme_name(ccn_scheme s) {
    return s == CCN_SCHEME_EIGEN ? "eigen" : s == CCN_SCHEME_NURSS ? "nurss" : "cc";
}

int ccn_cli_int(const char *s, int lo, int hi, int *out) {
    char *e;
    long x = strtol(s, &e, 10);
    if (e == s || *e || x < lo || x > hi) return -1;
    *out = (int)x;
    return 0;
}

/* Shared option parser of refine / limit / patches (see cli.h). */
int ccn_cli_parse(int argc, char **argv, unsigned allowed, int max_levels, ccn_options *o,
                  int *fvar_linear, const char **in, const char **out) {
    o->boundary_corners = -1; /* unset: the file's tags decide (resolve_options) */
    o->crease_method = -1;
    if (fvar_linear) *fvar_linear = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--scheme") == 0 && val) {
            if (ccn_cli_scheme(val, &o->scheme)) { fprintf(stderr, "ccnurbs: bad --scheme '%s'\n", val); return 2; }
            i++;
        } else if ((allowed & CCN_CLI_LEVELS) && strcmp(a, "--levels") == 0 && val) {
            if (ccn_cli_int(val, 0, max_levels, &o->levels)) {
                fprintf(stderr, "ccnurbs: --levels must be 0..%d\n", max_levels);
                return 2;
            }
            i++;
        } else if ((allowed & CCN_CLI_CAP) && strcmp(a, "--cap") == 0 && val) {
            if (strcmp(val, "bi5") == 0) o->cap = CCN_CAP_GUIDED_BI5;
            else if (strcmp(val, "refine") == 0) o->cap = CCN_CAP_REFINE;
            else if (strcmp(val, "fill") == 0) o->cap = CCN_CAP_G1_FILL;
            else { fprintf(stderr, "ccnurbs: bad --cap '%s'\n", val); return 2; }
            i++;
        } else if (strcmp(a, "--corners") == 0 && val) {
            if (strcmp(val, "smooth") == 0) o->boundary_corners = CCN_CORNERS_SMOOTH;
            else if (strcmp(val, "pinned") == 0) o->boundary_corners = CCN_CORNERS_PINNED;
            else { fprintf(stderr, "ccnurbs: bad --corners '%s'\n", val); return 2; }
            i++;
        } else if (strcmp(a, "--crease-method") == 0 && val) {
            if (strcmp(val, "uniform") == 0) o->crease_method = CCN_CREASE_UNIFORM;
            else if (strcmp(val, "chaikin") == 0) o->crease_method = CCN_CREASE_CHAIKIN;
            else { fprintf(stderr, "ccnurbs: bad --crease-method '%s'\n", val); return 2; }
            i++;
        } else if (strcmp(a, "--polyhedron") == 0 && val) {
            if (ccn_cli_int(val, CCN_POLY_SELECT, CCN_POLY_COUNT, &o->ev_polyhedron)) {
                fprintf(stderr, "ccnurbs: --polyhedron must be 0 (the per-vertex choice) .. %d\n", CCN_POLY_COUNT);
                return 2;
            }
            i++;
        } else if (fvar_linear && strcmp(a, "--fvar-linear") == 0 && val) {
            if ((*fvar_linear = ccn_cli_fvar_linear(val)) < 0) {
                fprintf(stderr, "ccnurbs: bad --fvar-linear '%s' (none, corners-only, corners-plus1, "
                                "corners-plus2, boundaries or all)\n", val);
                return 2;
            }
            i++;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "ccnurbs: unknown or incomplete option '%s'\n", a);
            return 2;
        } else if (!*in) *in = a;
        else if (!*out) *out = a;
        else { fprintf(stderr, "ccnurbs: too many arguments\n"); return 2; }
    }
    if (!*in || !*out) { fprintf(stderr, "ccnurbs %s: need an input and an output file\n", argv[0]); return 2; }
    return 0;
}
