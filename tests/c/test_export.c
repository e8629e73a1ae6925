/* ccn_plan_export: the exported faces, evaluated here by an independent Cox-de Boor
 * recursion on the surfaces the face callback reports, against
 *   - the plan's own limit samples (ccn_plan_evaluate, level 3): every sample lies in some
 *     face (located by the cells' places, decoded here from the documented order of the
 *     output faces) and equals it <= 1e-12 x size, fills apart;
 *   - a global refinement (ccn_refine) for the exact pieces around holes: every
 *     CCN_EXPORT_FACE_REFINED face equals the strict bicubic patch of its face in the
 *     globally refined mesh (the export refines locally);
 * and the cells tile every cage face (areas sum to 1 per quad), the packed regular torus is
 * one periodic face whose knots are the ring intervals, bad input is rejected with a status
 * and a message naming the problem, a failing sink gives CCN_ERR_IO, output is deterministic.
 */
#include "ccnurbs.h"
#include "io/cad.h"
#include "io/fill.h"
#include "io/knot_removal.h"
#include "surface/patches.h"
#include "testlib.h"

#define MAXF 20000

/* ---- captured faces --------------------------------------------------------------- */

typedef struct {
    int kind, patch, ncells;
    ccn_export_cell *cells;
    int deg[2], np[2], per[2];
    double *t[2]; /* flat knots */
    int nt[2];
    double *P;
} face;

typedef struct { face *f; int n; } faces;

static void capture(void *user, const ccn_export_face *e) {
    faces *F = user;
    if (F->n >= MAXF) return;
    face *f = &F->f[F->n++];
    f->kind = e->kind;
    f->patch = e->patch;
    f->ncells = e->num_cells;
    f->cells = malloc(sizeof(ccn_export_cell) * (size_t)e->num_cells);
    memcpy(f->cells, e->cells, sizeof(ccn_export_cell) * (size_t)e->num_cells);
    for (int d = 0; d < 2; d++) {
        f->deg[d] = e->degree[d];
        f->np[d] = e->num_poles[d];
        f->per[d] = e->periodic[d];
        int n = 0;
        for (int k = 0; k < e->num_knots[d]; k++) n += e->mults[d][k];
        f->t[d] = malloc(sizeof(double) * (size_t)n);
        f->nt[d] = n;
        n = 0;
        for (int k = 0; k < e->num_knots[d]; k++)
            for (int m = 0; m < e->mults[d][k]; m++) f->t[d][n++] = e->knots[d][k];
    }
    size_t np = 3 * (size_t)e->num_poles[0] * (size_t)e->num_poles[1];
    f->P = malloc(sizeof(double) * np);
    memcpy(f->P, e->poles, sizeof(double) * np);
}

static void faces_free(faces *F) {
    for (int i = 0; i < F->n; i++) {
        free(F->f[i].cells); free(F->f[i].t[0]); free(F->f[i].t[1]); free(F->f[i].P);
    }
    free(F->f);
}

/* N_{i,p}(x), Cox-de Boor; half-open spans except the domain's last. */
static double cdb(const double *t, int i, int p, double x, double end) {
    if (p == 0) {
        if (x == end) return t[i] < x && x == t[i + 1];
        return t[i] <= x && x < t[i + 1];
    }
    double a = 0, b = 0;
    if (t[i + p] > t[i]) a = (x - t[i]) / (t[i + p] - t[i]) * cdb(t, i, p - 1, x, end);
    if (t[i + p + 1] > t[i + 1]) b = (t[i + p + 1] - x) / (t[i + p + 1] - t[i + 1]) * cdb(t, i + 1, p - 1, x, end);
    return a + b;
}

static void feval(const face *f, double u, double v, double out[3]) {
    double u1 = f->t[0][f->np[0]], v1 = f->t[1][f->np[1]];
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < f->np[0]; i++) {
        double a = cdb(f->t[0], i, f->deg[0], u, u1);
        if (a == 0) continue;
        for (int j = 0; j < f->np[1]; j++) {
            double w = a * cdb(f->t[1], j, f->deg[1], v, v1);
            for (int k = 0; k < 3; k++) out[k] += w * f->P[3 * (i * f->np[1] + j) + k];
        }
    }
}

/* Point and exact first derivatives: N'_{i,p} = p N_{i,p-1} / (t_{i+p} - t_i)
 * - p N_{i+1,p-1} / (t_{i+p+1} - t_{i+1}). */
static double cdb_d(const double *t, int i, int p, double x, double end) {
    double a = 0, b = 0;
    if (t[i + p] > t[i]) a = p / (t[i + p] - t[i]) * cdb(t, i, p - 1, x, end);
    if (t[i + p + 1] > t[i + 1]) b = p / (t[i + p + 1] - t[i + 1]) * cdb(t, i + 1, p - 1, x, end);
    return a - b;
}

static void feval_d(const face *f, double u, double v, double P[3], double Su[3], double Sv[3]) {
    double u1 = f->t[0][f->np[0]], v1 = f->t[1][f->np[1]];
    for (int k = 0; k < 3; k++) P[k] = Su[k] = Sv[k] = 0;
    for (int i = 0; i < f->np[0]; i++) {
        double a = cdb(f->t[0], i, f->deg[0], u, u1), da = cdb_d(f->t[0], i, f->deg[0], u, u1);
        for (int j = 0; j < f->np[1]; j++) {
            double b = cdb(f->t[1], j, f->deg[1], v, v1), db = cdb_d(f->t[1], j, f->deg[1], v, v1);
            for (int k = 0; k < 3; k++) {
                double x = f->P[3 * (i * f->np[1] + j) + k];
                P[k] += a * b * x, Su[k] += da * b * x, Sv[k] += a * db * x;
            }
        }
    }
}

/* ---- helpers ------------------------------------------------------------------------ */

typedef struct { char *d; size_t n, cap; int fail_after; } sink;

static int sink_fn(void *user, const char *data, size_t len) {
    sink *s = user;
    if (s->fail_after >= 0 && s->n + len > (size_t)s->fail_after) return 1;
    if (s->n + len > s->cap) {
        s->cap = 2 * (s->n + len) + 4096;
        s->d = realloc(s->d, s->cap);
    }
    memcpy(s->d + s->n, data, len);
    s->n += len;
    return 0;
}

/* name: a cage of tests/data, or an OBJ text when it starts with "v ". */
static ccn_plan *load(const char *name, ccn_obj **obj, ccn_cage *cage, const ccn_options *o) {
    char path[256];
    snprintf(path, sizeof path, "tests/data/%s.obj", name);
    size_t len = strlen(name);
    char *text = strncmp(name, "v ", 2) ? tl_slurp(path, &len) : strdup(name);
    if (!text) return NULL;
    ccn_error err;
    ccn_plan *p = NULL;
    if (ccn_obj_parse(text, len, obj, &err) || ccn_obj_get_cage(*obj, cage) || ccn_plan_create(cage, o, &p, &err))
        p = NULL;
    free(text);
    ccn_plan_stats ps; /* the bi-5 caps exist only above the cap level; raise the level */
    while (p && ccn_plan_get_stats(p, &ps) == CCN_OK && ps.num_caps_deferred > 0) {
        ccn_options o2 = {0};
        if (o) o2 = *o;
        o2.levels = ps.levels + 1;
        ccn_plan_destroy(p);
        if (ccn_plan_create(cage, &o2, &p, &err)) p = NULL;
    }
    return p;
}

/* tests/data/<name>.obj's plan at output level `levels` (raised until its caps exist). */
static ccn_plan *load_at(const char *name, int levels, ccn_obj **obj, ccn_cage *cage) {
    ccn_options o = {0};
    o.levels = levels;
    return load(name, obj, cage, &o);
}

static ccn_status run(ccn_plan *p, ccn_export_options *eo, faces *F, sink *s, ccn_export_info *info,
                      ccn_error *err) {
    if (F) {
        F->f = calloc(MAXF, sizeof(face));
        F->n = 0;
        eo->face_fn = capture;
        eo->face_user = F;
    }
    return ccn_plan_export(p, NULL, eo, sink_fn, s, info, err);
}

static int contains(const char *d, size_t n, const char *w) {
    size_t k = strlen(w);
    for (size_t i = 0; i + k <= n; i++)
        if (!memcmp(d + i, w, k)) return 1;
    return 0;
}

static const double UNIT[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

/* Place (3 corners) of face q of the level-L output: the documented order (see file comment). */
static void place_of(const ccn_cage *cage, int L, int q, int *c, int *sub, double p[3][2]) {
    int chain[32], n = 0, f = q;
    for (int l = L; l > 1; l--) { chain[n++] = f % 4; f /= 4; }
    int start = 0, cf = 0;
    while (start + cage->face_sizes[cf] <= f) start += cage->face_sizes[cf++];
    int j1 = f - start;
    double P[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    *c = cf;
    *sub = -1;
    if (cage->face_sizes[cf] == 4) chain[n++] = j1;
    else *sub = j1;
    for (int k = n - 1; k >= 0; k--) {
        int j = chain[k];
        double a[2], b[2], d[2], Q[3][2];
        for (int e = 0; e < 2; e++) {
            a[e] = UNIT[j][e];
            b[e] = (UNIT[j][e] + UNIT[(j + 1) % 4][e]) / 2;
            d[e] = (UNIT[j][e] + UNIT[(j + 3) % 4][e]) / 2;
        }
        const double *pts[3] = {a, b, d};
        for (int r = 0; r < 3; r++)
            for (int e = 0; e < 2; e++)
                Q[r][e] = P[0][e] + pts[r][0] * (P[1][e] - P[0][e]) + pts[r][1] * (P[2][e] - P[0][e]);
        memcpy(P, Q, sizeof P);
    }
    memcpy(p, P, sizeof P);
}

/* (u,v) of local point st in cell c, or 0 if outside. */
static int cell_uv(const ccn_export_cell *c, const double st[2], double *u, double *v) {
    double e1[2] = {c->st[1][0] - c->st[0][0], c->st[1][1] - c->st[0][1]};
    double e2[2] = {c->st[2][0] - c->st[0][0], c->st[2][1] - c->st[0][1]};
    double det = e1[0] * e2[1] - e1[1] * e2[0], r[2] = {st[0] - c->st[0][0], st[1] - c->st[0][1]};
    double x = (r[0] * e2[1] - r[1] * e2[0]) / det, y = (e1[0] * r[1] - e1[1] * r[0]) / det;
    if (x < -1e-12 || x > 1 + 1e-12 || y < -1e-12 || y > 1 + 1e-12) return 0;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    y = y < 0 ? 0 : y > 1 ? 1 : y;
    *u = c->uv[0] + x * (c->uv[1] - c->uv[0]);
    *v = c->uv[2] + y * (c->uv[3] - c->uv[2]);
    return 1;
}

/* Every level-3 limit sample against the faces containing it; returns the number of faces
 * touched; *worst = max distance / size (fills apart), *unmatched samples. */
static int against_limit(ccn_plan *p, const ccn_cage *cage, const faces *F, double *worst,
                         double *fill_worst, int *unmatched) {
    ccn_sizes sz;
    ccn_plan_get_sizes(p, &sz);
    ccn_plan_stats ps;
    ccn_plan_get_stats(p, &ps);
    int L = ps.levels;
    double *pos = malloc(sizeof(double) * 3 * (size_t)sz.num_verts);
    int32_t *fv = malloc(sizeof(int32_t) * 4 * (size_t)sz.num_faces);
    ccn_limit_mesh lm = {.positions = pos, .face_verts = fv};
    ccn_error err;
    int touched = 0;
    *worst = *fill_worst = 0;
    *unmatched = 0;
    if (ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK) {
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int i = 0; i < sz.num_verts; i++)
            for (int k = 0; k < 3; k++) { lo[k] = fmin(lo[k], pos[3 * i + k]); hi[k] = fmax(hi[k], pos[3 * i + k]); }
        double size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
        char *hit = calloc((size_t)F->n, 1);
        for (int q = 0; q < sz.num_faces; q++) {
            int c, sub;
            double P[3][2];
            place_of(cage, L, q, &c, &sub, P);
            for (int k = 0; k < 4; k++) {
                double st[2];
                for (int e = 0; e < 2; e++)
                    st[e] = k == 0 ? P[0][e] : k == 1 ? P[1][e] : k == 2 ? P[1][e] + P[2][e] - P[0][e] : P[2][e];
                const double *x = pos + 3 * fv[4 * q + k];
                int found = 0;
                for (int i = 0; i < F->n; i++)
                    for (int j = 0; j < F->f[i].ncells; j++) {
                        const ccn_export_cell *cl = &F->f[i].cells[j];
                        double u, v, y[3];
                        if (cl->cage_face != c || cl->sub != sub || !cell_uv(cl, st, &u, &v)) continue;
                        feval(&F->f[i], u, v, y);
                        double d = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2])) / size;
                        double *w = F->f[i].kind == CCN_EXPORT_FACE_FILL ? fill_worst : worst;
                        if (d > *w) *w = d;
                        found = 1;
                        hit[i] = 1;
                    }
                *unmatched += !found;
            }
        }
        for (int i = 0; i < F->n; i++) touched += hit[i];
        free(hit);
    }
    free(pos);
    free(fv);
    return touched;
}

/* ---- tests ---------------------------------------------------------------------------- */

static void check_cage(const char *name, int closed, int fills) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load_at(name, 3, &obj, &cage);
    CHECK(p != NULL, "%s: plan", name);
    if (!p) return;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    faces F;
    sink s = {NULL, 0, 0, -1};
    ccn_export_info info;
    ccn_error err;
    ccn_status st = run(p, &eo, &F, &s, &info, &err);
    CHECK(st == CCN_OK, "%s: export: %s", name, err.message);
    CHECK(info.num_faces == F.n, "%s: %d faces reported, %d called back", name, (int)info.num_faces, F.n);
    CHECK(info.num_packs + info.num_bicubic + info.num_bi5 + info.num_refined + info.num_fill_faces == info.num_faces,
          "%s: counts by kind", name);
    CHECK(info.closed == closed && (closed ? info.num_boundary_edges == 0 : info.num_boundary_edges > 0),
          "%s: closed %d, %d boundary edges", name, (int)info.closed, (int)info.num_boundary_edges);
    CHECK(info.num_shells == 1, "%s: %d shells", name, (int)info.num_shells);
    CHECK(info.num_fills == fills, "%s: %d fills, expected %d", name, (int)info.num_fills, fills);
    CHECK(info.max_g1_deviation <= 1e-8, "%s: G1 deviation %g", name, info.max_g1_deviation);
    CHECK(info.bytes == (int64_t)s.n && s.n > 0, "%s: bytes", name);
    /* cells tile every cage face (quad) or level-1 quad of an n-gon: areas sum to 1 */
    int nsub = 0;
    for (int c = 0; c < cage.num_faces; c++) nsub += cage.face_sizes[c] == 4 ? 1 : cage.face_sizes[c];
    double *area = calloc((size_t)nsub, sizeof(double));
    int *first = malloc(sizeof(int) * (size_t)cage.num_faces), acc = 0;
    for (int c = 0; c < cage.num_faces; c++) { first[c] = acc; acc += cage.face_sizes[c] == 4 ? 1 : cage.face_sizes[c]; }
    for (int i = 0; i < F.n; i++)
        for (int j = 0; j < F.f[i].ncells; j++) {
            const ccn_export_cell *c = &F.f[i].cells[j];
            double a = fabs((c->st[1][0] - c->st[0][0]) * (c->st[2][1] - c->st[0][1]) -
                            (c->st[1][1] - c->st[0][1]) * (c->st[2][0] - c->st[0][0]));
            area[first[c->cage_face] + (c->sub < 0 ? 0 : c->sub)] += a;
        }
    double amax = 0;
    for (int i = 0; i < nsub; i++) amax = fmax(amax, fabs(area[i] - 1));
    CHECK(amax <= 1e-12, "%s: the cells do not tile the cage (area error %g)", name, amax);
    free(area);
    free(first);
    double worst, fill_worst;
    int unmatched, touched = against_limit(p, &cage, &F, &worst, &fill_worst, &unmatched);
    CHECK(unmatched == 0, "%s: %d limit samples in no face", name, unmatched);
    CHECK(worst <= 1e-12, "%s: faces vs limit samples %g x size", name, worst);
    printf("  %s: %d faces (%d packs, %d bicubic, %d bi-5, %d refined, %d fill), %d touched by "
           "level-3 samples, max distance %.2e x size (fills %.2e), G1 %.2e (fills %.2e), %lld bytes\n",
           name, F.n, (int)info.num_packs, (int)info.num_bicubic, (int)info.num_bi5, (int)info.num_refined,
           (int)info.num_fill_faces, touched, worst, fill_worst, info.max_g1_deviation,
           info.max_fill_g1_deviation, (long long)info.bytes);
    /* STEP and IGES: deterministic */
    sink s2 = {NULL, 0, 0, -1};
    eo.face_fn = NULL;
    ccn_export_info i2;
    CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s2, &i2, &err) == CCN_OK && s2.n == s.n &&
          memcmp(s.d, s2.d, s.n) == 0, "%s: STEP output differs between two runs", name);
    eo.format = CCN_EXPORT_IGES;
    sink s3 = {NULL, 0, 0, -1};
    CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s3, &i2, &err) == CCN_OK && i2.num_faces == info.num_faces &&
          i2.num_edges == info.num_edges && i2.max_g1_deviation == info.max_g1_deviation,
          "%s: IGES figures differ", name);
    free(s.d); free(s2.d); free(s3.d);
    faces_free(&F);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

static void test_cages(void) {
    check_cage("torus", 1, 0);
    check_cage("cube", 1, 0);
    check_cage("cube_tri", 1, 0);
    check_cage("ngon_prism", 1, 0);
    check_cage("lshape", 0, 6);
    check_cage("pole12", 0, 0);
    check_cage("flip35", 0, 4);
    check_cage("fig18_v8", 0, 9); /* 8 boundary corners; the centre (spoke ratio 5): its G1 fill is fairer than the cap */
    check_cage("fig16_v6", 0, 7);
    check_cage("mixed_boundary", 0, 11);
    check_cage("torus_semi", 1, 0);
    check_cage("cube_semi", 1, 0); /* its corners capped once the creases decayed, no fills */
    check_cage("crease_band", 0, 4); /* the four corners filled */
    check_cage("crease_tube", 0, 0);
}

/* tests/data/<name>.obj (or an OBJ text) at output level `levels` (raised until its caps exist)
 * exported with the defaults but cap and fill_levels: its faces into F; the file's text into
 * *text (NUL-terminated, the caller frees it) when text is not NULL. CCN_OK or the failure (F
 * then empty). */
static ccn_status export_text(const char *name, int levels, ccn_cap cap, int fill_levels, faces *F,
                              ccn_export_info *info, char **text) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_options o = {0};
    o.levels = levels;
    o.cap = cap;
    ccn_plan *p = load(name, &obj, &cage, &o);
    memset(F, 0, sizeof *F);
    if (!p) return CCN_ERR_ARGUMENT;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    eo.fill_levels = fill_levels;
    sink s = {NULL, 0, 0, -1};
    ccn_error err;
    ccn_status st = run(p, &eo, F, &s, info, &err);
    if (st != CCN_OK) {
        faces_free(F);
        memset(F, 0, sizeof *F);
    }
    if (text && st == CCN_OK) {
        sink_fn(&s, "", 1);
        *text = s.d;
    } else {
        free(s.d);
    }
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
    return st;
}

static ccn_status export_cap_at(const char *name, ccn_cap cap, int fill_levels, faces *F, ccn_export_info *info) {
    return export_text(name, 3, cap, fill_levels, F, info, NULL);
}

static ccn_status export_cap(const char *name, ccn_cap cap, faces *F, ccn_export_info *info) {
    return export_cap_at(name, cap, 0, F, info);
}

static ccn_status export_of(const char *name, faces *F, ccn_export_info *info) {
    return export_cap(name, CCN_CAP_GUIDED_BI5, F, info);
}

/* Largest number of distinct interior knots of an exported face in one direction. */
static int max_interior_knots(const char *name) {
    faces F;
    ccn_export_info info;
    if (export_of(name, &F, &info) != CCN_OK) return -1;
    int most = 0;
    for (int i = 0; i < F.n; i++)
        for (int d = 0; d < 2; d++) {
            int distinct = 0;
            for (int k = 1; k < F.f[i].nt[d]; k++) distinct += F.f[i].t[d][k] != F.f[i].t[d][k - 1];
            if (distinct - 1 > most) most = distinct - 1;
        }
    faces_free(&F);
    return most;
}

/* Along a ring of semi-sharp edges of constant sharpness the limit is the cage's own B-spline
 * (the crease rules are the cubic's along it), and across it only the knots at 2^-j of a cage
 * interval (j <= ceil(sharpness)) are new: the refined bands around the crease rings of
 * torus_semi (8 x 6 cage edges, sharpness 2 and 2.5) need at most 8 + 2 x 2 x 3 = 20 interior
 * knots in a direction, where the level-3 pieces carry 8 x 8 = 64 along a ring. */
static void test_semi_sharp_knots(void) {
    int most = max_interior_knots("torus_semi");
    CHECK(most >= 0 && most <= 20, "torus_semi: a face with %d interior knots in one direction", most);
    printf("# torus_semi: at most %d interior knots per face and direction\n", most);
}

/* Beside a straight row of semi-sharp edges (crease_band: sharpness 2.5 across an 8 x 8 grid)
 * the export refines level by level: a band of pieces per level, each with its level's cells and
 * knots along the crease. The limit is C2 across the bands (it is the refinement's limit there,
 * no crease rule reaches it), so the bands and the packs beside them are one face: every cell of
 * the cage faces beside the crease, away from the ends' holes (rows 3 and 4, columns 2..5),
 * lies in one face, and its knots are at most double (C1 or smoother inside). Level 1, so that
 * the bands of levels 2 and 3 are the export's; test_cages checks the faces against the limit. */
static void test_crease_band(void) {
    faces F;
    ccn_export_info info;
    CHECK(export_text("crease_band", 1, CCN_CAP_GUIDED_BI5, 0, &F, &info, NULL) == CCN_OK, "crease_band: export");
    int owner = -1, split = 0, maxmult = 0;
    for (int i = 0; i < F.n; i++)
        for (int j = 0; j < F.f[i].ncells; j++) {
            int cf = F.f[i].cells[j].cage_face, row = cf / 8, col = cf % 8;
            if (row < 3 || row > 4 || col < 2 || col > 5) continue;
            if (owner < 0) owner = i;
            split += owner != i;
        }
    CHECK(owner >= 0 && split == 0, "crease_band: the cells beside the crease in %d other faces", split);
    if (owner >= 0)
        for (int d = 0; d < 2; d++)
            for (int k = F.f[owner].deg[d] + 1, m = 1; k < F.f[owner].nt[d] - F.f[owner].deg[d] - 1; k++) {
                m = F.f[owner].t[d][k] == F.f[owner].t[d][k - 1] ? m + 1 : 1;
                if (m > maxmult) maxmult = m;
            }
    CHECK(maxmult <= 2, "crease_band: an interior knot of the band's face %d times", maxmult);
    printf("# crease_band: %d faces; the band beside the crease one face of %d x %d poles\n", F.n,
           owner >= 0 ? F.f[owner].np[0] : 0, owner >= 0 ? F.f[owner].np[1] : 0);
    faces_free(&F);
}

/* Faces that share a whole side and join C1 or better are one face: the cube's 8 caps (24
 * sectors, 4 bi-5 patches each: the centre and a ring's three) give at most 2 faces per sector,
 * and the 72 bicubic patches around them (C2 to each other) at most 12 faces; test_cages
 * checks the merged faces against the limit. */
static void test_merged_faces(void) {
    faces F;
    ccn_export_info info;
    CHECK(export_of("cube", &F, &info) == CCN_OK, "cube: export");
    CHECK(info.num_bi5 <= 48 && info.num_bicubic <= 12, "cube: %d bi-5 faces (<= 48), %d bicubic (<= 12)",
          (int)info.num_bi5, (int)info.num_bicubic);
    printf("# cube: %d faces (%d bi-5, %d bicubic) from 96 bi-5 and 72 bicubic patches\n", (int)info.num_faces,
           (int)info.num_bi5, (int)info.num_bicubic);
    faces_free(&F);
}

/* Corners whose semi-sharp edges decay (cube_semi: sharpness 1.5) have no cap at the plan's cap
 * level; the export caps them where they are smooth and isolated, at level 4 (the coarsest a
 * hole's cap is made at): bi-5 faces instead of fills, G1 inside, and equal to the limit
 * samples of the plans of levels 3 and 4 (the level-4 plan's samples in each cap are its EV
 * and its border). */
static void test_caps_in_holes(void) {
    faces F;
    ccn_export_info info;
    CHECK(export_of("cube_semi", &F, &info) == CCN_OK, "cube_semi: export");
    CHECK(info.num_fills == 0 && info.num_fill_faces == 0 && info.num_bi5 >= 8 * 3,
          "cube_semi: %d fills, %d bi-5 faces (a cap at each corner)", (int)info.num_fills, (int)info.num_bi5);
    CHECK(info.max_g1_deviation <= 1e-9, "cube_semi: G1 %g", info.max_g1_deviation);
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load_at("cube_semi", 4, &obj, &cage);
    CHECK(p != NULL, "cube_semi: level-4 plan");
    if (p) {
        double worst, fill_worst;
        int unmatched, touched = against_limit(p, &cage, &F, &worst, &fill_worst, &unmatched);
        CHECK(unmatched == 0 && worst <= 1e-12, "cube_semi: %d level-4 samples in no face, faces vs "
              "them %g x size", unmatched, worst);
        printf("# cube_semi: %d faces (%d bi-5, %d refined), G1 %.2e, %d faces touched by level-4 "
               "samples, within %.2e x size\n", (int)info.num_faces, (int)info.num_bi5,
               (int)info.num_refined, info.max_g1_deviation, touched, worst);
        ccn_plan_destroy(p);
        ccn_obj_destroy(obj);
    }
    faces_free(&F);
}

/* Largest |Gaussian curvature| (and the smallest K into *kmin) of face f over a 25 x 25 grid
 * inside it (to 0.005 of its sides), from this file's own Cox-de Boor evaluation (poles taken
 * relative to c, so that tiny faces far from the origin keep their digits; second derivatives
 * by central differences over 1e-4 of the span). Sample
 * points within [rmin, rmax) of c only (rmax <= 0: all). */
static double face_max_k(const face *f, const double c[3], double rmin, double rmax, double *dmax, double *kmin) {
    face g = *f;
    size_t np = (size_t)f->np[0] * (size_t)f->np[1];
    g.P = malloc(sizeof(double) * 3 * np);
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < 3; k++) g.P[3 * i + k] = f->P[3 * i + k] - c[k];
    double u0 = f->t[0][f->deg[0]], u1 = f->t[0][f->np[0]], v0 = f->t[1][f->deg[1]], v1 = f->t[1][f->np[1]];
    double hu = 1e-4 * (u1 - u0), hv = 1e-4 * (v1 - v0), kmax = 0;
    for (int a = 0; a <= 24; a++)
        for (int b = 0; b <= 24; b++) {
            double u = u0 + (u1 - u0) * (0.005 + 0.99 * a / 24), v = v0 + (v1 - v0) * (0.005 + 0.99 * b / 24);
            double P[3][3][3], xu[3], xv[3], xuu[3], xuv[3], xvv[3], n[3];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) feval(&g, u + (i - 1) * hu, v + (j - 1) * hv, P[i][j]);
            double d = sqrt(P[1][1][0] * P[1][1][0] + P[1][1][1] * P[1][1][1] + P[1][1][2] * P[1][1][2]);
            if (dmax) *dmax = fmax(*dmax, d);
            if (d < rmin || (rmax > 0 && d >= rmax)) continue;
            for (int k = 0; k < 3; k++) {
                xu[k] = (P[2][1][k] - P[0][1][k]) / (2 * hu);
                xv[k] = (P[1][2][k] - P[1][0][k]) / (2 * hv);
                xuu[k] = (P[2][1][k] - 2 * P[1][1][k] + P[0][1][k]) / (hu * hu);
                xvv[k] = (P[1][2][k] - 2 * P[1][1][k] + P[1][0][k]) / (hv * hv);
                xuv[k] = (P[2][2][k] - P[2][0][k] - P[0][2][k] + P[0][0][k]) / (4 * hu * hv);
            }
            n[0] = xu[1] * xv[2] - xu[2] * xv[1], n[1] = xu[2] * xv[0] - xu[0] * xv[2], n[2] = xu[0] * xv[1] - xu[1] * xv[0];
            double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            double E = xu[0] * xu[0] + xu[1] * xu[1] + xu[2] * xu[2], G = xv[0] * xv[0] + xv[1] * xv[1] + xv[2] * xv[2];
            double F = xu[0] * xv[0] + xu[1] * xv[1] + xu[2] * xv[2], W = E * G - F * F;
            if (!(nl > 0) || !(W > 0)) continue;
            double L = 0, M = 0, N = 0;
            for (int k = 0; k < 3; k++) L += xuu[k] * n[k] / nl, M += xuv[k] * n[k] / nl, N += xvv[k] * n[k] / nl;
            kmax = fmax(kmax, fabs(L * N - M * M) / W);
            if (kmin) *kmin = fmin(*kmin, (L * N - M * M) / W);
        }
    free(g.P);
    return kmax;
}

/* A cap's curvature against its surround: the cap is the faces mine marks (NULL: every bi-5
 * face), its centre c the mean of their poles and its reach r0 their farthest pole from c; kc,
 * kcmin its largest |K| and smallest K; kr, krmin the same over the faces of kind `around` (-1:
 * every face but the bi-5 ones) at distances in [r0, 2 r0) from c. 0: no face in the cap. */
typedef struct { double c[3], r0, kc, kcmin, kr, krmin; } cap_k;

static int cap_against_surround(const faces *F, const uint8_t *mine, int around, cap_k *o) {
    double cnt = 0;
    *o = (cap_k){{0, 0, 0}, 0, 0, INFINITY, 0, INFINITY};
    for (int i = 0; i < F->n; i++)
        if (mine ? mine[i] : F->f[i].kind == CCN_EXPORT_FACE_BI5)
            for (int q = 0; q < F->f[i].np[0] * F->f[i].np[1]; q++, cnt++)
                for (int k = 0; k < 3; k++) o->c[k] += F->f[i].P[3 * q + k];
    if (cnt == 0) return 0;
    for (int k = 0; k < 3; k++) o->c[k] /= cnt;
    for (int i = 0; i < F->n; i++)
        if (mine ? mine[i] : F->f[i].kind == CCN_EXPORT_FACE_BI5)
            o->kc = fmax(o->kc, face_max_k(&F->f[i], o->c, 0, 0, &o->r0, &o->kcmin));
    for (int i = 0; i < F->n; i++)
        if (around < 0 ? F->f[i].kind != CCN_EXPORT_FACE_BI5 : F->f[i].kind == around)
            o->kr = fmax(o->kr, face_max_k(&F->f[i], o->c, o->r0, 2 * o->r0, NULL, &o->krmin));
    return 1;
}

/* The hole caps' curvature is the surround's: at each of cube_semi's corners (valence 3; faces
 * grouped by the octant of their poles' mean, the cube spans [0, 1]^3) the cap's Gaussian
 * curvature stays positive like that of the exact pieces around it (within twice its reach)
 * and its largest |K| within 2.5x theirs (measured 1.7-2.0x; the refined limit's own curvature
 * rises towards a valence-3 corner). */
static void test_caps_in_holes_fair(void) {
    faces F;
    ccn_export_info info;
    CHECK(export_of("cube_semi", &F, &info) == CCN_OK, "cube_semi: export");
    double worst = 0;
    int corners = 0;
    for (int oct = 0; oct < 8; oct++) {
        uint8_t *mine = calloc((size_t)F.n + 1, 1);
        for (int i = 0; i < F.n; i++) {
            if (F.f[i].kind != CCN_EXPORT_FACE_BI5) continue;
            int np = F.f[i].np[0] * F.f[i].np[1];
            double m[3] = {0, 0, 0};
            for (int q = 0; q < np; q++)
                for (int k = 0; k < 3; k++) m[k] += F.f[i].P[3 * q + k] / np;
            mine[i] = ((m[0] > 0.5) | (m[1] > 0.5) << 1 | (m[2] > 0.5) << 2) == oct;
        }
        cap_k K;
        if (cap_against_surround(&F, mine, -1, &K)) {
            CHECK(K.krmin > 0 && K.kcmin > 0 && K.kc <= 2.5 * K.kr, "cube_semi corner %d: the cap's K in [%g, %g], "
                  "the exact pieces' around it in [%g, %g]", oct, K.kcmin, K.kc, K.krmin, K.kr);
            worst = fmax(worst, K.kc / K.kr);
            corners++;
        }
        free(mine);
    }
    CHECK(corners == 8, "cube_semi: caps at %d corners, want 8", corners);
    printf("# cube_semi: the caps' largest |K| <= %.2f x the exact pieces' around them\n", worst);
    faces_free(&F);
    /* fans of valence 5-8 (tests/data/fanN.obj, heights jittered) with spokes of sharpness 1.5:
     * one cap each, in a hole at level 4; measured 1.89-4.64x the exact pieces' largest |K|
     * (1.92-4.95 with the plan's rings after the first; the refined limit's curvature grows
     * towards the EV with the valence), K as positive as theirs */
    for (int n = 5; n <= 8; n++) {
        char path[64], *text, *out;
        size_t len;
        snprintf(path, sizeof path, "tests/data/fan%d.obj", n);
        text = tl_slurp(path, &len);
        CHECK(text != NULL, "%s", path);
        if (!text) continue;
        out = malloc(3 * len + 64 * (size_t)n + 64);
        size_t o = 0;
        int vi = 0;
        for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
            double x, y, z;
            if (sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3)
                o += (size_t)sprintf(out + o, "v %.6f %.6f %.6f\n", x, y, z + 0.15 * sin(7.3 * ++vi));
            else if (line[0] == 'f')
                o += (size_t)sprintf(out + o, "%s\n", line);
        }
        for (int k = 1; k <= n; k++) o += (size_t)sprintf(out + o, "# crease 1 %d 1.5\n", 2 * k);
        faces G;
        ccn_export_info gi;
        CHECK(export_of(out, &G, &gi) == CCN_OK && gi.num_bi5 > 0,
              "fan%d with semi-sharp spokes: export, its EV capped", n);
        cap_k K;
        cap_against_surround(&G, NULL, -1, &K);
        CHECK(K.kr > 0 && K.kc <= 5 * K.kr && (K.krmin <= 0 || K.kcmin > 0) && gi.max_g1_deviation <= 1e-10,
              "fan%d with semi-sharp spokes: the cap's K in [%g, %g], the exact pieces' around it in [%g, %g], "
              "G1 %g", n, K.kcmin, K.kc, K.krmin, K.kr, gi.max_g1_deviation);
        printf("# fan%d with semi-sharp spokes: %d faces (%d bi-5), the cap's largest |K| %.2f x the exact "
               "pieces' around it, G1 %.1e\n", n, (int)gi.num_faces, (int)gi.num_bi5, K.kc / K.kr, gi.max_g1_deviation);
        faces_free(&G);
        free(out);
        free(text);
    }
}

/* An interior EV whose spoke ratios leave the cap's range: the export caps its hole at the
 * last level (G1 to rounding) and keeps the cap because it is fairer than the fill faces (G1
 * too, io/fill_g1.c) would be. Measured here, on the exported faces, against the fill faces
 * that close the same hole at the same level with --cap refine: the cap's largest |K| is not
 * above theirs and within 5x the largest of the exact pieces around it (its
 * curvature rises towards the EV), and where it dips into a saddle (a spot next to the centre;
 * the surface around is elliptic) its |K| stays below theirs. star7_nu (valence 7, ratios 1.2-2);
 * star5_nu (valence 5, ratios up to 4: the cap with the symmetric guide domain folds, the one
 * with spokes d^(1/2), bi5.h [R15], is kept). */
static void cap_beyond_range(const char *name, int corners) {
    faces F;
    ccn_export_info info;
    CHECK(export_of(name, &F, &info) == CCN_OK, "%s: export", name);
    CHECK(info.num_fill_faces == corners && info.num_bi5 > 0, "%s: %d fill faces (the %d corners), %d bi-5",
          name, (int)info.num_fill_faces, corners, (int)info.num_bi5);
    CHECK(info.max_g1_deviation <= 1e-9 && info.max_fill_g1_deviation <= 1e-12,
          "%s: G1 %g, fills %g", name, info.max_g1_deviation, info.max_fill_g1_deviation);
    /* the cap (every bi-5 face) against the exact pieces around it */
    cap_k K;
    cap_against_surround(&F, NULL, CCN_EXPORT_FACE_REFINED, &K);
    const double *c = K.c, r0 = K.r0, kc = K.kc, kcmin = K.kcmin, kr = K.kr, krmin = K.krmin;
    /* what closes the same hole without caps: --cap refine's fill faces there */
    faces R;
    ccn_export_info ri;
    double kf = 0, kfmin = INFINITY;
    CHECK(export_cap(name, CCN_CAP_REFINE, &R, &ri) == CCN_OK, "%s: export with --cap refine", name);
    int fl = 6 + info.fill_level - ri.fill_level; /* fill_levels count from the patch level */
    faces_free(&R);
    CHECK(export_cap_at(name, CCN_CAP_REFINE, fl, &R, &ri) == CCN_OK && ri.fill_level == info.fill_level,
          "%s: export with --cap refine, fills at level %d (%d)", name, (int)info.fill_level, (int)ri.fill_level);
    for (int i = 0; i < R.n; i++) {
        double dmin = INFINITY;
        if (R.f[i].kind != CCN_EXPORT_FACE_FILL) continue;
        for (int q = 0; q < R.f[i].np[0] * R.f[i].np[1]; q++) {
            const double *P = R.f[i].P + 3 * q;
            dmin = fmin(dmin, sqrt((P[0] - c[0]) * (P[0] - c[0]) + (P[1] - c[1]) * (P[1] - c[1]) + (P[2] - c[2]) * (P[2] - c[2])));
        }
        if (dmin < r0) kf = fmax(kf, face_max_k(&R.f[i], c, 0, 0, NULL, &kfmin));
    }
    CHECK(krmin > 0 && kcmin >= -kr, "%s: K from %g in the cap (fills: from %g; the exact pieces around it "
          "from %g to %g)", name, kcmin, kfmin, krmin, kr);
    CHECK(kr > 0 && kc <= 5 * kr && kc <= kf, "%s: the cap's max |K| %g, the fills' %g, the exact pieces' around it %g",
          name, kc, kf, kr);
    CHECK(ri.max_fill_g1_deviation <= 1e-9, "%s: the fills are %g rad off G1", name, ri.max_fill_g1_deviation);
    printf("# %s: %d faces (%d bi-5, %d fill), G1 %.2e; the cap's K in [%.3g, %.3g], %.2f x the largest of the "
           "exact pieces within 2x its reach (K >= %.3g there); fills instead: K in [%.3g, %.3g], G1 %.2e\n",
           name, (int)info.num_faces, (int)info.num_bi5, (int)info.num_fill_faces, info.max_g1_deviation, kcmin,
           kc, kr > 0 ? kc / kr : 0.0, krmin, kfmin, kf, ri.max_fill_g1_deviation);
    faces_free(&R);
    faces_free(&F);
}

static void test_caps_beyond_range(void) {
    cap_beyond_range("star7_nu", 7);
    cap_beyond_range("star5_nu", 5);
}

/* Cages far from the origin (moved by 1000 along each axis): caps still meet G1 to the rounding
 * of their own size (they are built around their EVs), not of their place. The cube's caps are
 * the plan's; cube_semi's are the export's, in holes a level below the plan where its creases
 * have decayed, and their poles near the EV must not lie so close together that rounding them
 * at their absolute coordinates turns the normals (with the paper's ring of speed 15/16 at
 * valence 3, whose cap is a sixteenth of the hole: 4.5e-9 rad here). */
static void far_export(const char *name, int level, double bound) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load_at(name, level, &obj, &cage);
    CHECK(p != NULL, "%s: plan", name);
    if (!p) return;
    double *far = malloc(sizeof(double) * 3 * (size_t)cage.num_verts);
    for (int32_t i = 0; i < 3 * cage.num_verts; i++) far[i] = cage.positions[i] + 1000.0;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    sink s = {NULL, 0, 0, -1};
    ccn_export_info info;
    ccn_error err;
    CHECK(ccn_plan_export(p, far, &eo, sink_fn, &s, &info, &err) == CCN_OK, "far %s: export: %s", name, err.message);
    CHECK(info.num_bi5 > 0 && info.max_g1_deviation <= bound, "far %s: %d bi-5 faces, G1 %g (bound %g)", name,
          (int)info.num_bi5, info.max_g1_deviation, bound);
    printf("# %s moved by 1000: G1 %.2e (bound %.0e)\n", name, info.max_g1_deviation, bound);
    free(s.d);
    free(far);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

static void test_far_from_origin(void) {
    far_export("cube", 3, 1e-8);
    far_export("cube_semi", 3, 1e-9);
}

/* ---- knot removal (io/knot_removal.c), against a refinement made here ----------------------- */

/* Boehm: u inserted into flat knots t (n + p + 1) of a row of n poles (3 each; room for n + 1). */
static void boehm(double *t, int p, int *n, double *P, double u) {
    int k = p;
    while (k + 1 < *n && t[k + 1] <= u) k++;
    for (int i = *n; i > k; i--) memcpy(P + 3 * i, P + 3 * (i - 1), sizeof(double) * 3);
    for (int i = k; i >= k - p + 1; i--) {
        double a = (u - t[i]) / (t[i + p] - t[i]);
        for (int c = 0; c < 3; c++) P[3 * i + c] = a * P[3 * i + c] + (1 - a) * P[3 * (i - 1) + c];
    }
    memmove(t + k + 2, t + k + 1, sizeof(double) * (size_t)(*n + p - k));
    t[k + 1] = u;
    (*n)++;
}

/* A model of one face of degree p x p with nu x nv poles P on flat knots tu, tv (periodic along
 * u if per_u): face 0 of xm, or -1. */
static int32_t one_face(ccn__xmodel *xm, int32_t kind, int p, int nu, int nv, const double *tu, const double *tv,
                        const double *P, int per_u) {
    memset(xm, 0, sizeof *xm);
    int32_t f = ccn__xm_add_face(xm, kind, p, p, nu, nv, 1, 1);
    CHECK(f == 0 && ccn__xm_set_flat(xm, f, 0, tu) == 0 && ccn__xm_set_flat(xm, f, 1, tv) == 0, "model");
    if (f != 0) return -1;
    xm->faces[0].s.periodic[0] = per_u;
    memcpy((void *)xm->faces[0].s.poles, P, sizeof(double) * 3 * (size_t)nu * nv);
    return 0;
}

/* The largest distance between the face of degree p x p with nu x nv poles P on flat knots tu,
 * tv and the removal's result S (same v knots), at `samples` random (u, v), u in [u0, u1]
 * (this file's Cox-de Boor). */
static double moved(int p, int nu, int nv, const double *tu, const double *tv, const double *P,
                    const ccn__cad_surface *S, double u0, double u1, int samples) {
    double *tr = malloc(sizeof(double) * (size_t)(S->num_poles[0] + p + 1));
    ccn__cad_flat_knots(S, 0, tr);
    face a = {0}, b = {0};
    a.deg[0] = a.deg[1] = b.deg[0] = b.deg[1] = p;
    a.np[0] = nu, a.np[1] = nv, a.t[0] = (double *)tu, a.t[1] = (double *)tv, a.P = (double *)P;
    b.np[0] = S->num_poles[0], b.np[1] = nv, b.t[0] = tr, b.t[1] = (double *)tv, b.P = (double *)S->poles;
    double worst = 0;
    for (int k = 0; k < samples; k++) {
        double u = u0 + (u1 - u0) * tl_rand01(), v = tv[nv] * tl_rand01(), x[3], y[3];
        feval(&a, u, v, x);
        feval(&b, u, v, y);
        for (int c = 0; c < 3; c++) worst = fmax(worst, fabs(x[c] - y[c]));
    }
    free(tr);
    return worst;
}

/* A random bicubic surface on clamped knots with random intervals, refined here by inserting
 * random knots along u (one row at a time: the tensor product), handed to the removal: it must
 * give back exactly the coarse knots (the random poles make the surface only C2 at those) and
 * the same surface (evaluated by this file's Cox-de Boor) within its tolerance. */
static void test_knot_removal(void) {
    for (int trial = 0; trial < 20; trial++) {
        int p = 3, n0 = 4 + trial % 5, nv = 4 + trial % 3, extra = 1 + 7 * (trial % 4);
        double t0[64], tv[16];
        for (int i = 0; i <= p; i++) t0[i] = 0;
        for (int i = p + 1; i <= n0 + p; i++) t0[i] = i <= n0 ? t0[i - 1] + 0.2 + tl_rand01() : t0[n0];
        for (int i = 0; i < nv + p + 1; i++) tv[i] = i <= p ? 0 : i >= nv ? nv - p : i - p;
        double *P0 = malloc(sizeof(double) * 3 * (size_t)n0 * nv);
        for (int i = 0; i < 3 * n0 * nv; i++) P0[i] = tl_rand01();
        /* refine: the same insertions in every v column (pole (i, j) at 3 (i nv + j)) */
        double ins[40];
        for (int e = 0; e < extra; e++) ins[e] = t0[p] + (t0[n0] - t0[p]) * (0.02 + 0.96 * tl_rand01());
        int nf = n0 + extra;
        double *Pf = malloc(sizeof(double) * 3 * (size_t)nf * nv), tf[64];
        for (int j = 0; j < nv; j++) {
            double row[3 * 64], t[64];
            int n = n0;
            memcpy(t, t0, sizeof(double) * (size_t)(n0 + p + 1));
            for (int i = 0; i < n0; i++) memcpy(row + 3 * i, P0 + 3 * (i * nv + j), sizeof(double) * 3);
            for (int e = 0; e < extra; e++) boehm(t, p, &n, row, ins[e]);
            for (int i = 0; i < nf; i++) memcpy(Pf + 3 * (i * nv + j), row + 3 * i, sizeof(double) * 3);
            memcpy(tf, t, sizeof(double) * (size_t)(nf + p + 1));
        }
        ccn__xmodel xm;
        if (one_face(&xm, CCN_EXPORT_FACE_PACK, p, nf, nv, tf, tv, Pf, 0)) return;
        int64_t got = ccn__xm_remove_knots(&xm, 1e-12, 0);
        const ccn__cad_surface *S = &xm.faces[0].s;
        int same = S->num_poles[0] == n0 && S->num_poles[1] == nv && got == extra;
        for (int k = 0; same && k < S->num_knots[0]; k++) same = S->knots[0][k] == t0[k == 0 ? 0 : k + p];
        CHECK(same, "trial %d: %lld of %d inserted knots removed, %d poles along u for %d", trial,
              (long long)got, extra, (int)S->num_poles[0], n0);
        double worst = moved(p, nf, nv, tf, tv, Pf, S, t0[p], t0[n0], 200);
        CHECK(worst <= 1e-12, "trial %d: the surface moved %g", trial, worst);
        ccn__xm_free(&xm);
        free(P0);
        free(Pf);
    }
    /* closed: a periodic cubic (integer knots, m spans, random poles) refined by the curve's
     * own midpoint rules (vertex (1,6,1)/8, edge (1,1)/2: half the knot spacing) along u; the
     * removal gives back the periodic face of m spans and the same surface */
    for (int trial = 0; trial < 6; trial++) {
        int p = 3, m = 4 + trial, nv = 4, n0 = m + p, nf = 2 * m + p;
        double t0[64], tf[64], tv[16];
        for (int k = 0; k <= n0 + p; k++) t0[k] = k - p;
        for (int k = 0; k <= nf + p; k++) tf[k] = 0.5 * (k - p);
        for (int i = 0; i < nv + p + 1; i++) tv[i] = i <= p ? 0 : i >= nv ? nv - p : i - p;
        double P0[3 * 16 * 4], Pf[3 * 32 * 4];
        for (int i = 0; i < m; i++)
            for (int j = 0; j < nv; j++)
                for (int c = 0; c < 3; c++) P0[3 * (i * nv + j) + c] = tl_rand01();
        for (int i = m; i < n0; i++) memcpy(P0 + 3 * i * nv, P0 + 3 * (i - m) * nv, sizeof(double) * 3 * nv);
        for (int jj = 0; jj < 2 * m; jj++)
            for (int j = 0; j < nv; j++)
                for (int c = 0; c < 3; c++) {
                    int i = (jj + 1) / 2;
#define CP(k) P0[3 * ((((k) % m + m) % m) * nv + j) + c]
                    Pf[3 * (jj * nv + j) + c] = jj % 2 ? (CP(i - 1) + 6 * CP(i) + CP(i + 1)) / 8 : (CP(i) + CP(i + 1)) / 2;
#undef CP
                }
        for (int i = 2 * m; i < nf; i++) memcpy(Pf + 3 * i * nv, Pf + 3 * (i - 2 * m) * nv, sizeof(double) * 3 * nv);
        ccn__xmodel xm;
        if (one_face(&xm, CCN_EXPORT_FACE_PACK, p, nf, nv, tf, tv, Pf, 1)) return;
        int64_t got = ccn__xm_remove_knots(&xm, 1e-12, 0);
        const ccn__cad_surface *S = &xm.faces[0].s;
        int same = S->periodic[0] && S->num_poles[0] == n0 && got == m && S->num_knots[0] == n0 + p + 1;
        for (int k = 0; same && k < S->num_knots[0]; k++) same = S->knots[0][k] == t0[k];
        CHECK(same, "closed trial %d: %lld knots removed, periodic %d, %d poles along u for %d", trial,
              (long long)got, (int)S->periodic[0], (int)S->num_poles[0], n0);
        double worst = same ? moved(p, n0, nv, t0, tv, P0, S, 0, m, 200) : 0;
        CHECK(worst <= 1e-12, "closed trial %d: the surface moved %g", trial, worst);
        ccn__xm_free(&xm);
    }
}

/* The same around a tube (crease_tube: a closed ring of sharpness 2.5 around an open tube of
 * 8 x 6 quads): every band is closed, periodic around the tube, and the bands of different
 * levels (the packs of the cage rows away from the crease, the refined bands nearer it) differ
 * in their knots around it. They merge when both take the union of those knots (inserted in the
 * periodic form): the cells of cage rows 0 and 1 lie in one face, those of rows 4 and 5 in one.
 * The bands on either side of the crease start around it at different points (one runs the
 * other way); with one band's seam moved to the other's they merge too, and the whole tube, C2
 * around and along, is one face. */
static void test_crease_tube(void) {
    faces F;
    ccn_export_info info;
    CHECK(export_text("crease_tube", 1, CCN_CAP_GUIDED_BI5, 0, &F, &info, NULL) == CCN_OK, "crease_tube: export");
    for (int side = 0; side < 2; side++) {
        int owner = -1, split = 0;
        for (int i = 0; i < F.n; i++)
            for (int j = 0; j < F.f[i].ncells; j++) {
                int row = F.f[i].cells[j].cage_face / 8;
                if (side ? row < 4 : row > 1) continue;
                if (owner < 0) owner = i;
                split += owner != i;
            }
        CHECK(owner >= 0 && split == 0, "crease_tube: the cells of rows %s in %d other faces", side ? "4, 5" : "0, 1",
              split);
    }
    CHECK(F.n == 1, "crease_tube: %d faces, not one", F.n);
    printf("# crease_tube: %d faces\n", F.n);
    faces_free(&F);
}

/* A strip beside a semi-sharp crease as the export packs it: a bicubic face one span across and
 * a few cage spans along, refined here eight levels along u (every dyadic knot down to 1/256 of
 * a span, inserted level by level as refinement leaves them: each pole carries the rounding of
 * a few ulps), placed as a small face far from the origin (size 0.1 at 2). The removal at the
 * export's tolerance must give back the cage spans but for a few knots (at least 98 % of the
 * inserted ones removed: the last, coarsest removals meet the rounding of all the finer ones)
 * and the same surface to the rounding of its coordinates. */
static void test_knot_removal_long_run(void) {
    for (int trial = 0; trial < 4; trial++) {
        int p = 3, spans = 2 + trial, n0 = spans + p, nv = 4, levels = 8;
        int extra = spans * ((1 << levels) - 1), nf = n0 + extra;
        double *t0 = malloc(sizeof(double) * (size_t)(n0 + p + 1)), tv[8] = {0, 0, 0, 0, 1, 1, 1, 1};
        double *tf = malloc(sizeof(double) * (size_t)(nf + p + 1));
        double *P0 = malloc(sizeof(double) * 3 * (size_t)n0 * nv), *Pf = malloc(sizeof(double) * 3 * (size_t)nf * nv);
        double *row = malloc(sizeof(double) * 3 * (size_t)(nf + 1));
        for (int i = 0; i <= n0 + p; i++) t0[i] = i <= p ? 0 : i >= n0 ? spans : i - p;
        const double at[3] = {1.9, -0.7, 0.4};
        for (int i = 0; i < n0 * nv; i++)
            for (int c = 0; c < 3; c++) P0[3 * i + c] = at[c] + 0.04 * tl_rand01();
        for (int j = 0; j < nv; j++) {
            int n = n0;
            memcpy(tf, t0, sizeof(double) * (size_t)(n0 + p + 1));
            for (int i = 0; i < n0; i++) memcpy(row + 3 * i, P0 + 3 * (i * nv + j), sizeof(double) * 3);
            for (int l = 1; l <= levels; l++) /* level by level, as refinement halves the spans */
                for (int k = 0; k < spans << (l - 1); k++) boehm(tf, p, &n, row, (2 * k + 1) / (double)(1 << l));
            for (int i = 0; i < nf; i++) memcpy(Pf + 3 * (i * nv + j), row + 3 * i, sizeof(double) * 3);
        }
        ccn__xmodel xm;
        if (one_face(&xm, CCN_EXPORT_FACE_REFINED, p, nf, nv, tf, tv, Pf, 0)) return;
        int64_t got = ccn__xm_remove_knots(&xm, 1e-13, 0);
        const ccn__cad_surface *S = &xm.faces[0].s;
        CHECK(got >= 0.98 * extra, "trial %d: %lld of %d inserted knots removed, %d poles along u for "
              "the cage's %d", trial, (long long)got, extra, (int)S->num_poles[0], n0);
        double worst = moved(p, n0, nv, t0, tv, P0, S, 0, spans, 400);
        CHECK(worst <= 1e-13, "trial %d: the surface moved %g", trial, worst);
        printf("# a strip of %d cage spans refined 8 levels, at 2 from the origin: %lld of %d knots removed, "
               "%d poles along u for the cage's %d, the surface moved %.2g\n", spans, (long long)got, extra,
               (int)S->num_poles[0], n0, worst);
        ccn__xm_free(&xm);
        free(t0); free(tf); free(P0); free(Pf); free(row);
    }
}

/* The exact pieces around holes equal the strict patches of a global refinement. */
static void check_refined(const char *name, int fill_levels, int depth) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_options o = {0};
    o.levels = 1;
    ccn_plan *p = load(name, &obj, &cage, &o);
    CHECK(p != NULL, "plan");
    if (!p) return;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    eo.fill_levels = fill_levels;
    eo.flags = CCN_EXPORT_UNPACKED; /* one face per refined face: each is one mesh face */
    faces F;
    sink s = {NULL, 0, 0, -1};
    ccn_export_info info;
    ccn_error err;
    CHECK(run(p, &eo, &F, &s, &info, &err) == CCN_OK, "export: %s", err.message);
    ccn_sizes sz;
    ccn_plan_get_sizes(p, &sz);
    ccn_plan_stats ps;
    ccn_plan_get_stats(p, &ps);
    int top = info.fill_level;
    int plevel = top - depth; /* the patch level: the cap level K (fallbacks) or the deepest */
    CHECK(ps.num_caps == 0 && plevel >= 1 && plevel <= ps.refine_levels, "%s: fill level %d, patch level %d + %d",
          name, top, (int)ps.refine_levels, depth);
    ccn_mesh *cm = NULL, *ref[8] = {NULL};
    CHECK(ccn_mesh_create(&cage, &cm, &err) == CCN_OK, "mesh");
    for (int l = 1; l <= top && l < 8; l++) CHECK(ccn_refine(cm, l, &o, &ref[l], &err) == CCN_OK, "refine %d", l);
    int checked = 0;
    double worst = 0;
    for (int i = 0; i < F.n; i++) {
        const face *f = &F.f[i];
        if (f->kind != CCN_EXPORT_FACE_REFINED) continue;
        const ccn_export_cell *c = &f->cells[0];
        double side = fabs(c->st[1][0] - c->st[0][0]) + fabs(c->st[1][1] - c->st[0][1]);
        int l = (int)lround(-log2(side));
        CHECK(l >= 1 && l <= top && l < 8, "refined face %d has level %d", i, l);
        if (l < 1 || l > top || l >= 8) continue;
        ccn_mesh_info mi;
        ccn_mesh_get_info(ref[l], &mi);
        int found = -1;
        double Q[3][2];
        for (int q = 0; q < mi.num_faces && found < 0; q++) { /* the level-l face at this place */
            int cf, sub;
            place_of(&cage, l, q, &cf, &sub, Q);
            double ca[2] = {Q[1][0] + Q[2][0] - Q[0][0], Q[1][1] + Q[2][1] - Q[0][1]};
            double cb[2] = {c->st[1][0] + c->st[2][0] - c->st[0][0], c->st[1][1] + c->st[2][1] - c->st[0][1]};
            double mida[2] = {(Q[0][0] + ca[0]) / 2, (Q[0][1] + ca[1]) / 2}, midb[2] = {(c->st[0][0] + cb[0]) / 2, (c->st[0][1] + cb[1]) / 2};
            if (cf == c->cage_face && fabs(mida[0] - midb[0]) + fabs(mida[1] - midb[1]) < 1e-12) found = q;
        }
        CHECK(found >= 0, "refined face %d: no level-%d face there", i, l);
        if (found < 0) continue;
        double bez[4][4][3];
        CHECK(ccn__bicubic_patch(ref[l], found, 0, 1, bez), "refined face %d: level-%d face %d is not strict", i, l, found);
        for (int a = 0; a <= 4; a++)
            for (int b = 0; b <= 4; b++) { /* the same point: via the cell and via the face */
                double x = a / 4.0, y = b / 4.0, st[2], u, v, X[3], Y[3] = {0, 0, 0};
                for (int e = 0; e < 2; e++)
                    st[e] = c->st[0][e] + x * (c->st[1][e] - c->st[0][e]) + y * (c->st[2][e] - c->st[0][e]);
                cell_uv(c, st, &u, &v);
                feval(f, u, v, X);
                /* st in the level-l face's own frame */
                double e1[2] = {Q[1][0] - Q[0][0], Q[1][1] - Q[0][1]}, e2[2] = {Q[2][0] - Q[0][0], Q[2][1] - Q[0][1]};
                double det = e1[0] * e2[1] - e1[1] * e2[0], r[2] = {st[0] - Q[0][0], st[1] - Q[0][1]};
                double fu = (r[0] * e2[1] - r[1] * e2[0]) / det, fw = (e1[0] * r[1] - e1[1] * r[0]) / det;
                for (int I = 0; I < 4; I++)
                    for (int J = 0; J < 4; J++) {
                        double bi = (I == 0 ? 1 : I == 3 ? 1 : 3) * pow(fu, I) * pow(1 - fu, 3 - I);
                        double bj = (J == 0 ? 1 : J == 3 ? 1 : 3) * pow(fw, J) * pow(1 - fw, 3 - J);
                        for (int k = 0; k < 3; k++) Y[k] += bi * bj * bez[I][J][k];
                    }
                double d = sqrt((X[0] - Y[0]) * (X[0] - Y[0]) + (X[1] - Y[1]) * (X[1] - Y[1]) + (X[2] - Y[2]) * (X[2] - Y[2]));
                worst = fmax(worst, d);
            }
        checked++;
    }
    CHECK(checked == info.num_refined && checked > 0, "%s: %d of %d refined faces checked", name, checked, (int)info.num_refined);
    CHECK(worst <= 1e-12 * info.size, "%s: refined faces vs the global refinement: %g", name, worst);
    printf("  %s: %d refined faces (levels %d..%d) = the global refinement's patches, max %.2e\n",
           name, checked, plevel + 1, top, worst);
    for (int l = 1; l < 8; l++) ccn_mesh_destroy(ref[l]);
    ccn_mesh_destroy(cm);
    free(s.d);
    faces_free(&F);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

static void test_refined(void) {
    /* smooth valence-2 corners: their fills CCN_FILL_LEVELS_V2 levels earlier, at least 1 down */
    check_refined("grid4", 3, 3 - CCN_FILL_LEVELS_V2 > 1 ? 3 - CCN_FILL_LEVELS_V2 : 1);
    check_refined("fig16_v6", 3, 3); /* an interior EV whose cap folds (1:10), non-uniform */
    check_refined("bfan5", 3, 3);    /* a boundary EV */
}

/* A regular torus: one periodic face, knots = the ring intervals. */
static void test_torus_pack(void) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load("torus", &obj, &cage, NULL);
    CHECK(p != NULL, "plan");
    if (!p) return;
    ccn_export_options eo;
    memset(&eo, 0, sizeof eo);
    faces F;
    sink s = {NULL, 0, 0, -1};
    ccn_export_info info;
    ccn_error err;
    CHECK(run(p, &eo, &F, &s, &info, &err) == CCN_OK, "export: %s", err.message);
    CHECK(F.n == 1 && info.num_packs == 1 && info.num_edges == 2 && info.num_vertices == 1 && info.closed,
          "%d faces, %d edges, %d vertices", F.n, (int)info.num_edges, (int)info.num_vertices);
    if (F.n == 1) {
        const face *f = &F.f[0];
        CHECK(f->per[0] && f->per[1] && f->deg[0] == 3 && f->np[0] == 8 + 3 && f->np[1] == 6 + 3,
              "periodic %d %d, %d x %d poles", f->per[0], f->per[1], f->np[0], f->np[1]);
        for (int k = 0; k + 1 < f->nt[0]; k++) CHECK(fabs(f->t[0][k + 1] - f->t[0][k] - 1) < 1e-15, "u knot %d", k);
    }
    /* unpacked: one face per cage quad */
    eo.flags = CCN_EXPORT_UNPACKED;
    sink s2 = {NULL, 0, 0, -1};
    eo.face_fn = NULL;
    CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s2, &info, &err) == CCN_OK && info.num_faces == 48 &&
          info.num_packed_cage_faces == 48 && info.closed, "unpacked: %d faces", (int)info.num_faces);
    free(s.d); free(s2.d);
    faces_free(&F);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

static void progress_fn(void *user, double x) {
    double *last = user;
    CHECK(x >= last[0] && x <= 1, "progress %g after %g", x, last[0]);
    last[0] = x;
}

static void test_bad_input(void) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load("cube", &obj, &cage, NULL);
    CHECK(p != NULL, "plan");
    if (!p) return;
    ccn_export_options eo;
    ccn_error err;
    sink s = {NULL, 0, 0, -1};
#define BAD(expr, want, what)                                                                  \
    do {                                                                                       \
        s.n = 0;                                                                               \
        ccn_status st_ = (expr);                                                               \
        CHECK(st_ == (want) && err.message[0] && s.n == 0, "%s: status %d (%s), %zu bytes", what, \
              (int)st_, err.message, s.n);                                                     \
    } while (0)
    memset(&eo, 0, sizeof eo);
    BAD(ccn_plan_export(NULL, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "NULL plan");
    ccn_plan *p0 = NULL; /* output level 0: no caps are built, none to export */
    CHECK(ccn_plan_create(&cage, NULL, &p0, &err) == CCN_OK, "plan at level 0");
    if (p0) {
        BAD(ccn_plan_export(p0, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "caps deferred");
        CHECK(strstr(err.message, "more levels") != NULL, "message: %s", err.message);
        ccn_plan_destroy(p0);
    }
    BAD(ccn_plan_export(p, NULL, &eo, NULL, &s, NULL, &err), CCN_ERR_ARGUMENT, "NULL callback");
    eo.format = 7;
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "format 7");
    CHECK(strstr(err.message, "format") != NULL, "message: %s", err.message);
    eo.format = 0;
    eo.flags = 0x10;
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "flags");
    eo.flags = 0;
    eo.fill_levels = 13;
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "fill_levels 13");
    eo.fill_levels = 0;
    eo.name = "it's";
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "quote in name");
    eo.name = NULL;
    eo.timestamp = "yesterday";
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "timestamp");
    eo.timestamp = NULL;
    eo.tolerance = NAN;
    BAD(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "NaN tolerance");
    eo.tolerance = 0;
    double bad[24];
    for (int i = 0; i < 24; i++) bad[i] = cage.positions[i];
    bad[3 * 5 + 1] = NAN;
    BAD(ccn_plan_export(p, bad, &eo, sink_fn, &s, NULL, &err), CCN_ERR_ARGUMENT, "NaN position");
    CHECK(err.element_kind == CCN_ELEM_VERTEX && err.element == 5, "names vertex 5: %d %d (%s)",
          (int)err.element_kind, (int)err.element, err.message);
    s.fail_after = 1000;
    s.n = 0;
    CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err) == CCN_ERR_IO, "failing sink: %s", err.message);
    s.fail_after = -1;
    double last = 0;
    eo.progress = progress_fn;
    eo.progress_user = &last;
    eo.name = "cube part";
    eo.timestamp = "2024-05-06T07:08:09";
    s.n = 0;
    CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s, NULL, &err) == CCN_OK && last == 1.0, "progress ends at %g", last);
    CHECK(s.n > 0 && contains(s.d, s.n, "cube part") && contains(s.d, s.n, "2024-05-06T07:08:09"),
          "name and timestamp in the file");
    free(s.d);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

/* The fill faces' normals across the spokes they share, from this file's own evaluation (exact
 * first derivatives): the fills are G1 there (io/fill_g1.c) where the bicubic fills deviated
 * by up to 6e-2 rad (Fig. 17), 3.6e-2 (mixed_boundary's boundary EVs), 4.7e-3 (bfan5), 8e-4
 * (continuity_cube's valence-3 points, intervals 1 : 22.4); now within the CAD target 1e-8 (to
 * the consistency of the data the relations start from: the tangent vectors at the vertex and
 * the C1 data at the far end agree to 1e-9 of their size, and that is what is left, 4e-10 on
 * mixed_boundary here, 1.8e-9 with another LAPACK). Two fill faces share a spoke when
 * 7 points along a side of each coincide (either direction); the angle between their normals is
 * taken as it is (a fold would show as pi). */
/* Distance of x from the line through a and b. */
static double line_dist(const double x[3], const double a[3], const double b[3]) {
    double d[3], e[3], c[3];
    for (int k = 0; k < 3; k++) d[k] = b[k] - a[k], e[k] = x[k] - a[k];
    c[0] = d[1] * e[2] - d[2] * e[1], c[1] = d[2] * e[0] - d[0] * e[2], c[2] = d[0] * e[1] - d[1] * e[0];
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* The largest normal angle across the fill faces' shared sides (7 points each), except sides
 * on one of the nskip lines skip[i][0..1] (straight crease spokes: C0 by design); *pairs counts
 * the sides. name: a cage of tests/data, or an OBJ text when it starts with "v ". */
static double fill_spoke_angle_skip(const char *name, int *pairs, const double (*skip)[2][3], int nskip) {
    faces F;
    ccn_export_info info;
    *pairs = 0;
    if (export_of(name, &F, &info) != CCN_OK) return INFINITY;
    double worst = 0, (*mid)[4][3] = malloc(sizeof *mid * (size_t)(F.n ? F.n : 1));
    for (int a = 0; a < F.n; a++) /* each side's midpoint: only sides meeting there are compared */
        for (int sa = 0; sa < 4 && F.f[a].kind == CCN_EXPORT_FACE_FILL; sa++) {
            const face *A = &F.f[a];
            double ua[2] = {A->t[0][A->deg[0]], A->t[0][A->np[0]]}, va[2] = {A->t[1][A->deg[1]], A->t[1][A->np[1]]};
            double u = sa < 2 ? 0.5 * (ua[0] + ua[1]) : ua[sa - 2], v = sa < 2 ? va[sa] : 0.5 * (va[0] + va[1]), Su[3], Sv[3];
            feval_d(A, u, v, mid[a][sa], Su, Sv);
        }
    for (int a = 0; a < F.n; a++)
        for (int b = a + 1; b < F.n; b++) {
            const face *A = &F.f[a], *B = &F.f[b];
            if (A->kind != CCN_EXPORT_FACE_FILL || B->kind != CCN_EXPORT_FACE_FILL) continue;
            double ua[2] = {A->t[0][A->deg[0]], A->t[0][A->np[0]]}, va[2] = {A->t[1][A->deg[1]], A->t[1][A->np[1]]};
            double ub[2] = {B->t[0][B->deg[0]], B->t[0][B->np[0]]}, vb[2] = {B->t[1][B->deg[1]], B->t[1][B->np[1]]};
            for (int sa = 0; sa < 4; sa++)
                for (int sb = 0; sb < 4; sb++)
                    for (int rev = 0; rev < 2; rev++) {
                        double gap = 0;
                        for (int k = 0; k < 3; k++) gap = fmax(gap, fabs(mid[a][sa][k] - mid[b][sb][k]));
                        if (!(gap <= 1e-6)) continue;
                        double pa[7][3], pb[7][3], na[7][3], nb[7][3], d = 0, size = 0;
                        for (int q = 0; q < 7; q++) {
                            double x = (q + 1) / 8.0, y = rev ? 1 - x : x, P[3], Su[3], Sv[3];
                            double u = sa < 2 ? ua[0] + x * (ua[1] - ua[0]) : ua[sa - 2];
                            double v = sa < 2 ? va[sa] : va[0] + x * (va[1] - va[0]);
                            feval_d(A, u, v, pa[q], Su, Sv);
                            na[q][0] = Su[1] * Sv[2] - Su[2] * Sv[1], na[q][1] = Su[2] * Sv[0] - Su[0] * Sv[2],
                            na[q][2] = Su[0] * Sv[1] - Su[1] * Sv[0];
                            u = sb < 2 ? ub[0] + y * (ub[1] - ub[0]) : ub[sb - 2];
                            v = sb < 2 ? vb[sb] : vb[0] + y * (vb[1] - vb[0]);
                            feval_d(B, u, v, P, Su, Sv);
                            memcpy(pb[q], P, sizeof P);
                            nb[q][0] = Su[1] * Sv[2] - Su[2] * Sv[1], nb[q][1] = Su[2] * Sv[0] - Su[0] * Sv[2],
                            nb[q][2] = Su[0] * Sv[1] - Su[1] * Sv[0];
                            for (int k = 0; k < 3; k++) d = fmax(d, fabs(pa[q][k] - pb[q][k]));
                        }
                        for (int k = 0; k < 3; k++) size = fmax(size, fabs(pa[6][k] - pa[0][k]));
                        if (!(d <= 1e-9 * size)) continue;
                        int on = 0;
                        for (int i = 0; i < nskip && !on; i++)
                            on = line_dist(pa[0], skip[i][0], skip[i][1]) <= 1e-9 * size &&
                                 line_dist(pa[6], skip[i][0], skip[i][1]) <= 1e-9 * size;
                        if (on) continue;
                        (*pairs)++;
                        for (int q = 0; q < 7; q++) {
                            double c[3] = {na[q][1] * nb[q][2] - na[q][2] * nb[q][1], na[q][2] * nb[q][0] - na[q][0] * nb[q][2],
                                           na[q][0] * nb[q][1] - na[q][1] * nb[q][0]};
                            double ang = atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                                               na[q][0] * nb[q][0] + na[q][1] * nb[q][1] + na[q][2] * nb[q][2]);
                            if (!(ang <= worst)) worst = ang;
                        }
                    }
        }
    free(mid);
    faces_free(&F);
    return worst;
}

static double fill_spoke_angle(const char *name, int *pairs) { return fill_spoke_angle_skip(name, pairs, NULL, 0); }

static void test_fills_g1(void) {
    static const char *cages[] = {"lshape",   "bfan5",           "mixed_boundary", "fig16_v6",
                                  "fig17_v7", "continuity_cube", "fan64",          "fvar_cylinder64"};
    for (int i = 0; i < (int)(sizeof cages / sizeof *cages); i++) {
        int pairs;
        double ang = fill_spoke_angle(cages[i], &pairs);
        CHECK(pairs > 0 && ang <= 1e-8, "%s: %d fill spokes, normals across them up to %g rad", cages[i], pairs, ang);
        printf("# %s: %d fill spokes, normals across them <= %.2e rad\n", cages[i], pairs, ang);
    }
    /* an interior valence-2 vertex: two quads sharing two edges, spokes 180 degrees apart and
     * the vertex lifted; its half-plane sectors must not fold over each other (pi rad) */
    static const char val2[] = "v 0 0 0.3\nv 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nf 1 2 4 3\nf 1 3 5 2\n";
    int pairs;
    double ang = fill_spoke_angle(val2, &pairs);
    CHECK(pairs == 2 && ang <= 1e-8, "valence 2: %d fill spokes, normals across them up to %g rad", pairs, ang);
    printf("# interior valence 2: %d fill spokes, normals across them <= %.2e rad\n", pairs, ang);
    /* a corner of three creases (OpenSubdiv's catmark_inf_crease1, one of its fans): sectors of
     * one, two and three faces, the last two with smooth spokes inside; the refined limit has no
     * tangent plane in the three-face sector, the fills take the plane of its creases' tangents */
    static const char corner3[] =
        "v -0.55 -0.375 -0.55\nv -0.05 0 -0.55\nv -0.3 0 -0.115\nv -0.8 0 -0.115\nv -1.05 0 -0.55\n"
        "v -0.8 0 -0.985\nv -0.3 0 -0.985\nv -0.175 0 -0.3\nv -0.55 0 -0.05\nv -0.925 0 -0.3\n"
        "v -0.925 0 -0.8\nv -0.55 0 -1.05\nv -0.175 0 -0.8\n"
        "f 1 2 8 3\nf 1 3 9 4\nf 1 4 10 5\nf 1 5 11 6\nf 1 6 12 7\nf 1 7 13 2\n"
        "t interpolateboundary 1/0/0 1\nt crease 2/1/0 0 2 10.0\nt crease 2/1/0 0 3 10.0\n"
        "t crease 2/1/0 0 5 10.0\n";
    static const double creases[3][2][3] = {{{-0.55, -0.375, -0.55}, {-0.3, 0, -0.115}},
                                            {{-0.55, -0.375, -0.55}, {-0.8, 0, -0.115}},
                                            {{-0.55, -0.375, -0.55}, {-0.8, 0, -0.985}}};
    ang = fill_spoke_angle_skip(corner3, &pairs, creases, 3);
    CHECK(pairs >= 2 && ang <= 1e-8, "corner of three creases: %d fill spokes, normals across them up to %g rad", pairs, ang);
    printf("# corner of three creases: %d fill spokes, normals across them <= %.2e rad\n", pairs, ang);
    /* a boundary vertex of 40 faces (beyond the dense solve's 32 spokes: the banded one, with
     * its two sharp spokes), lifted and the rim waved */
    char bfan[8192];
    size_t at = (size_t)snprintf(bfan, sizeof bfan, "v 0 0 0.3\n");
    for (int k = 0; k <= 80; k++) { /* even k: spoke ends, odd k: the quads' far corners */
        double a = 3.14159265358979 * k / 80, r = k % 2 ? 1.3 : 1.0;
        at += (size_t)snprintf(bfan + at, sizeof bfan - at, "v %.6f %.6f %.6f\n", r * cos(a), r * sin(a), 0.1 * sin(3 * a));
    }
    for (int k = 0; k < 40; k++)
        at += (size_t)snprintf(bfan + at, sizeof bfan - at, "f 1 %d %d %d\n", 2 + 2 * k, 3 + 2 * k, 4 + 2 * k);
    ang = fill_spoke_angle(bfan, &pairs);
    CHECK(pairs >= 39 && ang <= 1e-8, "boundary valence 41: %d fill spokes, normals across them up to %g rad", pairs, ang);
    printf("# boundary vertex of 40 faces: %d fill spokes, normals across them <= %.2e rad\n", pairs, ang);
}

/* A cage of two parts (two cubes, their faces interleaved in the file): one shell per part,
 * each a solid (STEP: CLOSED_SHELL in its MANIFOLD_SOLID_BREP; IGES: a 514 shell and an
 * independent 186 solid each), and the faces reach the file -- and the face callback -- part
 * by part, the order in which a reader meets them. */
static void test_parts(void) {
    static const int Q[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5}, {3, 4, 8, 7}, {1, 5, 8, 4}, {2, 3, 7, 6}};
    char text[2048];
    size_t at = 0;
    for (int part = 0; part < 2; part++)
        for (int k = 0; k < 8; k++)
            at += (size_t)snprintf(text + at, sizeof text - at, "v %d %d %d\n", ((k & 1) ^ ((k >> 1) & 1)) + 3 * part,
                                   (k >> 1) & 1, (k >> 2) & 1);
    for (int f = 0; f < 6; f++) /* face f of the first cube, then face f of the second */
        for (int part = 0; part < 2; part++)
            at += (size_t)snprintf(text + at, sizeof text - at, "f %d %d %d %d\n", Q[f][0] + 8 * part,
                                   Q[f][1] + 8 * part, Q[f][2] + 8 * part, Q[f][3] + 8 * part);
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load(text, &obj, &cage, NULL);
    CHECK(p != NULL, "plan of two cubes");
    if (!p) return;
    for (int fmt = 0; fmt < 2; fmt++) {
        ccn_export_options eo;
        memset(&eo, 0, sizeof eo);
        eo.format = fmt ? CCN_EXPORT_IGES : CCN_EXPORT_STEP;
        faces F;
        sink s = {NULL, 0, 0, -1};
        ccn_export_info info;
        ccn_error err;
        CHECK(run(p, &eo, &F, &s, &info, &err) == CCN_OK, "export: %s", err.message);
        sink_fn(&s, "", 1); /* a C string */
        CHECK(info.num_shells == 2 && info.closed == 1, "%d shells, closed %d", (int)info.num_shells, (int)info.closed);
        int part = 0, order_ok = F.n > 0, seen[2] = {0, 0};
        for (int i = 0; i < F.n; i++) {
            int c = F.f[i].cells[0].cage_face % 2; /* odd cage faces: the second cube */
            for (int j = 1; j < F.f[i].ncells; j++) order_ok &= F.f[i].cells[j].cage_face % 2 == c;
            order_ok &= c >= part;
            part = c;
            seen[c] = 1;
        }
        CHECK(order_ok && seen[0] && seen[1], "%s: faces part by part", fmt ? "IGES" : "STEP");
        if (!fmt) {
            int shells = 0, solids = 0;
            for (const char *q = s.d; (q = strstr(q, "CLOSED_SHELL(")) && q < s.d + s.n; q++) shells++;
            for (const char *q = s.d; (q = strstr(q, "MANIFOLD_SOLID_BREP(")) && q < s.d + s.n; q++) solids++;
            CHECK(shells == 2 && solids == 2 && !strstr(s.d, "OPEN_SHELL"), "STEP: %d closed shells, %d solids",
                  shells, solids);
        } else {
            int shells = 0, solids = 0, roots = 0;
            for (const char *q = s.d, *e; q && *q; q = (e = strchr(q, '\n')) ? e + 1 : NULL) { /* directory lines */
                if (strlen(q) < 74 || q[72] != 'D') continue;
                if (!strncmp(q, "     514", 8)) shells++;
                if (!strncmp(q, "     186", 8)) solids++, roots += !strncmp(q + 64, "00000000", 8);
            }
            CHECK(shells == 4 && solids == 4 && roots == 2, "IGES: %d shells, %d solids (%d independent)", shells / 2,
                  solids / 2, roots);
        }
        faces_free(&F);
        free(s.d);
    }
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

static int count_of(const char *d, const char *w) {
    int n = 0;
    for (const char *q = d; (q = strstr(q, w)); q++) n++;
    return n;
}

/* Every edge use carries a pcurve: STEP a PCURVE per face an edge bounds inside one
 * SURFACE_CURVE (SEAM_CURVE where a periodic face meets itself) per edge, IGES a planar 126
 * (form 1) per loop entry, each loop entry naming one. Whether the pcurves are exact is what
 * OpenCASCADE checks (tests/oracle/run_export.sh: normals across edges as it reads them). */
static void test_pcurves(void) {
    static const char *cages[2] = {"lshape", "torus"}; /* boundary edges; a periodic face */
    for (int k = 0; k < 2; k++) {
        ccn_obj *obj;
        ccn_cage cage;
        ccn_plan *p = load_at(cages[k], 3, &obj, &cage);
        CHECK(p != NULL, "%s: plan", cages[k]);
        if (!p) continue;
        for (int fmt = 0; fmt < 2; fmt++) {
            ccn_export_options eo;
            memset(&eo, 0, sizeof eo);
            eo.format = fmt ? CCN_EXPORT_IGES : CCN_EXPORT_STEP;
            sink s = {NULL, 0, 0, -1};
            ccn_export_info info;
            ccn_error err;
            CHECK(ccn_plan_export(p, NULL, &eo, sink_fn, &s, &info, &err) == CCN_OK, "%s: %s", cages[k], err.message);
            sink_fn(&s, "", 1);
            int uses = 2 * info.num_edges - info.num_boundary_edges;
            if (!fmt) {
                int sc = count_of(s.d, "=SURFACE_CURVE("), seam = count_of(s.d, "=SEAM_CURVE(");
                int pc = count_of(s.d, "=PCURVE("), ec = count_of(s.d, "=EDGE_CURVE(");
                CHECK(sc + seam == info.num_edges && ec == info.num_edges && pc == uses && (k == 0 ? seam == 0 : seam > 0),
                      "%s STEP: %d surface curves + %d seams, %d edge curves, %d pcurves for %d edges (%d uses)",
                      cages[k], sc, seam, ec, pc, (int)info.num_edges, uses);
            } else {
                int pc = 0, loops = 0;
                for (const char *q = s.d, *e; q && *q; q = (e = strchr(q, '\n')) ? e + 1 : NULL) {
                    if (strlen(q) < 74 || q[72] != 'D' || (atoi(q + 73) & 1) == 0) continue; /* first DE lines */
                    const char *q2 = strchr(q, '\n');
                    if (!strncmp(q, "     126", 8) && q2 && atoi(q2 + 1 + 32) == 1) pc++;
                    if (!strncmp(q, "     508", 8)) loops++;
                }
                CHECK(pc == uses && loops == info.num_faces, "%s IGES: %d pcurves for %d edge uses, %d loops",
                      cages[k], pc, uses, loops);
            }
            free(s.d);
        }
        ccn_plan_destroy(p);
        ccn_obj_destroy(obj);
    }
}

typedef struct { const char *p; size_t n; } body;

static int body_cmp(const void *a, const void *b) {
    const body *x = a, *y = b;
    if (x->n != y->n) return x->n < y->n ? -1 : 1;
    return memcmp(x->p, y->p, x->n);
}

static int int_cmp(const void *a, const void *b) {
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The text after "=" of entity line q, up to its end ("...;"), as a string of length *len. */
static const char *entity_body(const char *q, size_t *len) {
    const char *b = strchr(q, '='), *e = strstr(q, ");\n");
    if (!b || !e || e < b) { *len = 0; return q; }
    *len = (size_t)(e - b);
    return b;
}

/* Each thing the STEP file says once: no two CARTESIAN_POINTs and no two pcurve lines (the
 * degree-1 B_SPLINE_CURVE_WITH_KNOTS of the DEFINITIONAL_REPRESENTATIONs) with the same text, so
 * the patch faces' pcurves that repeat are shared (fewer representations than PCURVEs); every
 * VERTEX_POINT's point a pole of an edge curve (the vertex is the curve's end, bit for bit);
 * every patch face (bicubic, bi-5, fill) on [0, 1]^2, the joins of merged ones at exact
 * fractions (so that equal domains repeat bit for bit). The cube at level 3: bi-5 caps, bicubic
 * rings, no periodic face. */
static void test_written_once(void) {
    faces F;
    ccn_export_info info;
    char *text = NULL;
    CHECK(export_text("cube", 3, CCN_CAP_GUIDED_BI5, 0, &F, &info, &text) == CCN_OK, "cube: export");
    if (!text) return;
    /* entity lines: "#id=" at a line start (an entity continues on the next lines where a
     * list is wrapped after a comma; entity_body reads on to its end) */
    int nl = 0, cap = 1024;
    const char **line = malloc(sizeof(char *) * (size_t)cap);
    for (const char *q = text; q && *q; q = strchr(q, '\n') ? strchr(q, '\n') + 1 : NULL)
        if (*q == '#' && q[1 + strspn(q + 1, "0123456789")] == '=') { /* not a wrapped list's "#12," */
            if (nl == cap) line = realloc(line, sizeof(char *) * (size_t)(cap *= 2));
            line[nl++] = q;
        }
    /* repeated texts: the point and pcurve-line bodies sorted, neighbours compared */
    body *bodies = malloc(sizeof(body) * (size_t)(nl ? nl : 1));
    int nb = 0, dup_pt = 0, dup_line = 0, lines = 0, vp = 0, vp_bad = 0;
    for (int i = 0; i < nl; i++) {
        body b;
        b.p = entity_body(line[i], &b.n);
        int pt = !strncmp(b.p, "=CARTESIAN_POINT(", 17), pl = !strncmp(b.p, "=B_SPLINE_CURVE_WITH_KNOTS('',1,", 32);
        lines += pl;
        if (pt || pl) bodies[nb++] = b;
    }
    qsort(bodies, (size_t)nb, sizeof(body), body_cmp);
    for (int i = 1; i < nb; i++)
        if (!body_cmp(&bodies[i - 1], &bodies[i])) *(bodies[i].p[1] == 'C' ? &dup_pt : &dup_line) += 1;
    /* VERTEX_POINT('',#k): #k among the poles of the 3D curves (degree > 1 or not a pcurve) */
    int *poles = malloc(sizeof(int) * strlen(text) / 2 + 1), np = 0;
    for (int i = 0; i < nl; i++) {
        size_t li;
        const char *b = entity_body(line[i], &li);
        if (strncmp(b, "=B_SPLINE_CURVE_WITH_KNOTS(''", 29) || !strncmp(b, "=B_SPLINE_CURVE_WITH_KNOTS('',1,", 32)) continue;
        for (const char *r = b; (r = strchr(r, '#')) && r < b + li; r++) poles[np++] = atoi(r + 1);
    }
    qsort(poles, (size_t)np, sizeof(int), int_cmp);
    for (int i = 0; i < nl; i++) {
        size_t li;
        const char *b = entity_body(line[i], &li);
        if (strncmp(b, "=VERTEX_POINT(''", 16)) continue;
        int k = atoi(b + 18);
        vp++;
        vp_bad += !bsearch(&k, poles, (size_t)np, sizeof(int), int_cmp);
    }
    free(poles);
    free(bodies);
    int pc = count_of(text, "=PCURVE("), reps = count_of(text, "=DEFINITIONAL_REPRESENTATION(");
    CHECK(dup_pt == 0 && dup_line == 0 && lines == reps && reps < pc && vp == info.num_vertices && vp_bad == 0,
          "cube STEP: %d repeated points, %d repeated pcurve lines, %d lines for %d representations and %d "
          "pcurves, %d of %d vertices not an edge curve's pole",
          dup_pt, dup_line, lines, reps, pc, vp_bad, vp);
    int patches = 0, off_unit = 0, inner = 0, inexact = 0;
    for (int i = 0; i < F.n; i++) {
        const face *f = &F.f[i];
        if (f->kind != CCN_EXPORT_FACE_BICUBIC && f->kind != CCN_EXPORT_FACE_BI5 && f->kind != CCN_EXPORT_FACE_FILL)
            continue;
        patches++;
        for (int d = 0; d < 2; d++) {
            off_unit += f->t[d][f->deg[d]] != 0 || f->t[d][f->np[d]] != 1;
            for (int k = f->deg[d] + 1; k < f->np[d]; k++) { /* a merged face's joins */
                double t = f->t[d][k];
                int exact = 0;
                for (int q = 1; q <= 4096 && !exact; q++) exact = (double)round(t * q) / q == t;
                inner++;
                inexact += !exact;
            }
        }
    }
    CHECK(patches > 0 && off_unit == 0, "cube: %d of %d patch faces' directions not on [0, 1]", off_unit, patches);
    /* the pieces' lengths are ratios of small integers: merged faces' joins at exact fractions */
    CHECK(inner > 0 && inexact == 0, "cube: %d of %d joins of merged patch faces not at a fraction a / b, b <= 4096",
          inexact, inner);
    free(line);
    faces_free(&F);
    free(text);
}

/* The reals of STEP and IGES: every double written reads back as itself, always with a decimal
 * point and an upper-case exponent, in the fewest digits that do (a shorter decimal that reads
 * back as x would be found by trying 1..17 digits here). Doubles of every size, random bits. */
static void test_reals(void) {
    uint64_t state = 12345;
    int bad_read = 0, bad_form = 0, longer = 0, n = 0;
    char buf[40], tmp[40];
    const double fixed[] = {0, -0.0, 1, -1, 0.5, 0.1, 2.5e-7, 1e22, 1e-300, 123456789012345678.0, 4.9e-324,
                            1.7976931348623157e308, 0.30000000000000004, 1.0 / 3};
    for (int i = 0; i < 20000 + (int)(sizeof fixed / sizeof *fixed); i++) {
        double x;
        if (i < (int)(sizeof fixed / sizeof *fixed)) x = fixed[i];
        else {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            uint64_t bits = state;
            if (i % 2) bits = (bits & 0x800FFFFFFFFFFFFFull) | ((uint64_t)(1023 - 40 + (state >> 58)) << 52);
            memcpy(&x, &bits, sizeof x);
            if (!isfinite(x)) continue;
        }
        n++;
        const char *r = ccn__cad_real(x, buf);
        bad_read += strtod(r, NULL) != x;
        bad_form += !strchr(r, '.') || strchr(r, 'e') != NULL || (strchr(r, 'E') && strchr(r, 'E') < strchr(r, '.'));
        for (int digits = 1; digits <= 17; digits++) {
            snprintf(tmp, sizeof tmp, "%.*g", digits, x);
            if (strtod(tmp, NULL) != x) continue;
            size_t want = strlen(tmp) + (strchr(tmp, '.') ? 0 : 1); /* + the decimal point added */
            longer += strlen(r) > want;
            break;
        }
    }
    CHECK(bad_read == 0 && bad_form == 0 && longer == 0,
          "reals: of %d, %d read back otherwise, %d without a point or with a lower-case exponent, %d longer "
          "than the shortest that reads back", n, bad_read, bad_form, longer);
}

/* A sheet folded onto itself (a quad and its reverse, back to back: every vertex an interior
 * valence-2 vertex) has no B-rep: the export refuses with a topology error naming a cage face. */
static void test_folded(void) {
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *p = load("v 0.1 0 0.1\nv 0.9 0 0.1\nv 0.9 0 0.9\nv 0.1 0 0.9\nf 1 2 3 4\nf 4 3 2 1\n", &obj, &cage, NULL);
    CHECK(p != NULL, "plan of the folded sheet");
    if (!p) return;
    sink s = {NULL, 0, 0, -1};
    ccn_error err;
    ccn_status st = ccn_plan_export(p, NULL, NULL, sink_fn, &s, NULL, &err); /* default options */
    CHECK(st == CCN_ERR_TOPOLOGY && err.element_kind == CCN_ELEM_FACE && err.element >= 0 &&
              err.element < cage.num_faces && strstr(err.message, "cage face") && s.n == 0,
          "status %d, element %d/%d: %s (%zu bytes)", (int)st, (int)err.element_kind, (int)err.element,
          err.message, s.n);
    free(s.d);
    ccn_plan_destroy(p);
    ccn_obj_destroy(obj);
}

int main(void) {
    RUN(test_bad_input);
    RUN(test_torus_pack);
    RUN(test_refined);
    RUN(test_cages);
    RUN(test_semi_sharp_knots);
    RUN(test_crease_band);
    RUN(test_crease_tube);
    RUN(test_merged_faces);
    RUN(test_caps_in_holes);
    RUN(test_caps_in_holes_fair);
    RUN(test_caps_beyond_range);
    RUN(test_fills_g1);
    RUN(test_far_from_origin);
    RUN(test_knot_removal);
    RUN(test_knot_removal_long_run);
    RUN(test_parts);
    RUN(test_pcurves);
    RUN(test_written_once);
    RUN(test_folded);
    RUN(test_reals);
    return TEST_SUMMARY();
}
