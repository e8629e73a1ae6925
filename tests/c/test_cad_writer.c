/* The CAD writers (csrc/io/cad.h) on hand-built models: a pillow cube of 6 bicubic Bézier
 * faces (closed), an open 2x3 grid of Bézier patches cut from one bicubic B-spline (C2
 * across the shared sides), and one torus face periodic in both directions with
 * non-uniform knots. Checks here: the writers accept the models, write the same bytes
 * twice, and reject broken models with a status naming the face; a failing sink gives
 * CCN_ERR_IO.
 *
 * With an output directory argument (tests/oracle/run_cad.sh passes one) it also writes
 * NAME.step, NAME.igs and NAME.ref for each model: the reference grid "f i j u v x y z" of
 * every face evaluated here by an independent Cox-de Boor recursion (not cad.c's de Boor),
 * 7 x 7 samples over the face's domain, and torus_build.txt, the torus in OpenCASCADE's
 * periodic form for `occt_read --build`.
 */
#include "io/cad.h"
#include "testlib.h"

#define GRID 7
#define PI 3.14159265358979323846

/* ---- an independent evaluator: Cox-de Boor recursion on the flat knot vector ---------- */

typedef struct {
    ccn__cad_surface s;
    double knots[2][64];
    int32_t mults[2][64];
    double poles[3 * 64 * 64];
} tsurf;

static int flat(const ccn__cad_surface *s, int d, double *t) {
    int n = 0;
    for (int k = 0; k < s->num_knots[d]; k++)
        for (int m = 0; m < s->mults[d][k]; m++) t[n++] = s->knots[d][k];
    return n;
}

/* N_{i,p}(x) by recursion; spans half-open [t_i, t_i+1) except at the domain end. */
static double cdb(const double *t, int i, int p, double x, double end) {
    if (p == 0) {
        if (x == end) return t[i] < x && x == t[i + 1]; /* the last span is closed */
        return t[i] <= x && x < t[i + 1];
    }
    double a = 0, b = 0;
    if (t[i + p] > t[i]) a = (x - t[i]) / (t[i + p] - t[i]) * cdb(t, i, p - 1, x, end);
    if (t[i + p + 1] > t[i + 1]) b = (t[i + p + 1] - x) / (t[i + p + 1] - t[i + 1]) * cdb(t, i + 1, p - 1, x, end);
    return a + b;
}

static void ref_domain(const ccn__cad_surface *s, int d, double *lo, double *hi) {
    double t[200] = {0};
    flat(s, d, t);
    *lo = t[s->degree[d]];
    *hi = t[s->num_poles[d]];
}

static void ref_eval(const ccn__cad_surface *s, double u, double v, double out[3]) {
    double tu[200] = {0}, tv[200] = {0}, u0, u1, v0, v1;
    flat(s, 0, tu);
    flat(s, 1, tv);
    ref_domain(s, 0, &u0, &u1);
    ref_domain(s, 1, &v0, &v1);
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < s->num_poles[0]; i++) {
        double a = cdb(tu, i, s->degree[0], u, u1);
        if (a == 0) continue;
        for (int j = 0; j < s->num_poles[1]; j++) {
            double w = a * cdb(tv, j, s->degree[1], v, v1);
            const double *P = s->poles + 3 * (i * s->num_poles[1] + j);
            for (int k = 0; k < 3; k++) out[k] += w * P[k];
        }
    }
}

/* ---- models ------------------------------------------------------------------------- */

static void bezier_setup(tsurf *f, int deg, double lo, double hi) {
    memset(f, 0, sizeof *f);
    for (int d = 0; d < 2; d++) {
        f->s.degree[d] = deg;
        f->s.num_poles[d] = deg + 1;
        f->s.num_knots[d] = 2;
        f->knots[d][0] = lo;
        f->knots[d][1] = hi;
        f->mults[d][0] = f->mults[d][1] = deg + 1;
        f->s.knots[d] = f->knots[d];
        f->s.mults[d] = f->mults[d];
    }
    f->s.poles = f->poles;
}

/* Segments of the model (as cad.h numbers them) and adjacency by geometry: two segments
 * are shared when they are the same curve run in opposite directions (5 fractions). */
typedef struct { int face, side; double lo, hi; } tseg;

static int segments(const tsurf *f, int n, const int32_t *bs, const double *br, tseg *out) {
    int j = 0;
    for (int k = 0; k < n; k++)
        for (int s = 0; s < 4; s++) {
            double lo, hi;
            ref_domain(&f[k].s, s % 2, &lo, &hi);
            int a = 4 * k + s, b0 = bs ? bs[a] : 0, b1 = bs ? bs[a + 1] : 0;
            double prev = s < 2 ? lo : hi;
            for (int b = b0; b <= b1; b++, j++) {
                double next = b < b1 ? br[b] : (s < 2 ? hi : lo);
                out[j].face = k;
                out[j].side = s;
                out[j].lo = s < 2 ? prev : next;
                out[j].hi = s < 2 ? next : prev;
                prev = next;
            }
        }
    return j;
}

static void seg_pt(const tsurf *f, const tseg *g, double w, double out[3]) {
    double u0, u1, v0, v1;
    const ccn__cad_surface *s = &f[g->face].s;
    ref_domain(s, 0, &u0, &u1);
    ref_domain(s, 1, &v0, &v1);
    double t = g->side < 2 ? g->lo + w * (g->hi - g->lo) : g->hi - w * (g->hi - g->lo);
    double u = g->side == 0 || g->side == 2 ? t : g->side == 1 ? u1 : u0;
    double v = g->side == 1 || g->side == 3 ? t : g->side == 0 ? v0 : v1;
    ref_eval(s, u, v, out);
}

static int find_adjacency(const tsurf *f, int n, const int32_t *bs, const double *br, int32_t *adj) {
    tseg g[128];
    int ns = segments(f, n, bs, br, g);
    for (int a = 0; a < ns; a++) adj[a] = -1;
    for (int a = 0; a < ns; a++)
        for (int b = 0; b < ns && adj[a] < 0; b++) {
            if (b == a || adj[b] >= 0) continue;
            int same = 1;
            for (int k = 0; k <= 4 && same; k++) {
                double p[3], q[3];
                seg_pt(f, &g[a], k / 4.0, p);
                seg_pt(f, &g[b], 1 - k / 4.0, q);
                same = fabs(p[0] - q[0]) + fabs(p[1] - q[1]) + fabs(p[2] - q[2]) < 1e-12;
            }
            if (same) { adj[a] = b; adj[b] = a; }
        }
    return ns;
}

/* Unit cube, each face a bicubic Bézier patch with its inner poles pushed out by 0.15:
 * straight shared edges, outward Su x Sv. Half the faces use the domain [-1, 2.5]. */
static int make_cube(tsurf *f) {
    static const double O[6][3] = {{0, 0, 0}, {0, 0, 1}, {0, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}};
    static const double A[6][3] = {{0, 1, 0}, {1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}};
    static const double B[6][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int k = 0; k < 6; k++) {
        bezier_setup(&f[k], 3, k % 2 ? -1 : 0, k % 2 ? 2.5 : 1);
        double nrm[3] = {A[k][1] * B[k][2] - A[k][2] * B[k][1], A[k][2] * B[k][0] - A[k][0] * B[k][2],
                         A[k][0] * B[k][1] - A[k][1] * B[k][0]};
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) {
                int inner = i > 0 && i < 3 && j > 0 && j < 3;
                for (int c = 0; c < 3; c++)
                    f[k].poles[3 * (4 * i + j) + c] = O[k][c] + i / 3.0 * A[k][c] + j / 3.0 * B[k][c] +
                                                      (inner ? 0.15 * nrm[c] : 0);
            }
    }
    return 6;
}

/* Open 2 x 3 grid: the Bézier patches of a uniform bicubic B-spline height field with a
 * 5 x 6 control net (so C2 across every shared side). */
static int make_grid(tsurf *f) {
    static const double M[4][4] = {{1, 4, 1, 0}, {0, 4, 2, 0}, {0, 2, 4, 0}, {0, 1, 4, 1}};
    double P[5][6][3];
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 6; j++) {
            P[i][j][0] = i;
            P[i][j][1] = j * 0.9;
            P[i][j][2] = 0.4 * sin(1.3 * i) * cos(0.8 * j) + 0.1 * i * j / 6.0;
        }
    int n = 0;
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 3; b++, n++) {
            bezier_setup(&f[n], 3, 0, 1);
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++)
                    for (int c = 0; c < 3; c++) {
                        double x = 0;
                        for (int r = 0; r < 4; r++)
                            for (int q = 0; q < 4; q++) x += M[i][r] * M[j][q] * P[a + r][b + q][c];
                        f[n].poles[3 * (4 * i + j) + c] = x / 36.0;
                    }
        }
    return n;
}

/* Degree elevation of a Bézier face in both directions (exact: same surface, degree + 1). */
static void bezier_elevate(tsurf *f) {
    int p = f->s.degree[0], n = p + 1;
    double Q[3 * 36], T[3 * 36];
    for (int i = 0; i <= n; i++) /* along u: T[i][j] from P[i-1][j], P[i][j] */
        for (int j = 0; j < n; j++)
            for (int k = 0; k < 3; k++) {
                double a = (double)i / n;
                double lo = i > 0 ? f->poles[3 * ((i - 1) * n + j) + k] : 0, hi = i < n ? f->poles[3 * (i * n + j) + k] : 0;
                T[3 * (i * n + j) + k] = a * lo + (1 - a) * hi;
            }
    for (int i = 0; i <= n; i++) /* along v */
        for (int j = 0; j <= n; j++)
            for (int k = 0; k < 3; k++) {
                double a = (double)j / n;
                double lo = j > 0 ? T[3 * (i * n + j - 1) + k] : 0, hi = j < n ? T[3 * (i * n + j) + k] : 0;
                Q[3 * (i * (n + 1) + j) + k] = a * lo + (1 - a) * hi;
            }
    bezier_setup(f, p + 1, f->knots[0][0], f->knots[0][1]);
    memcpy(f->poles, Q, sizeof(double) * 3 * (size_t)((n + 1) * (n + 1)));
}

/* T-junctions: the left column of the grid's B-spline as one packed face (unclamped uniform
 * knots, 4 x 6 poles, three spans along v) next to the right column's three Bézier patches,
 * the middle one elevated to bi-5 (a degree-3 pack meeting a degree-5 face, as at a cap);
 * the pack's side 1 is split at its knots v = 4, 5. */
static int32_t tee_bs[4 * 4 + 1];
static double tee_br[2] = {4, 5};
static int make_tee(tsurf *f) {
    tsurf g[6];
    make_grid(g);
    f[1] = g[3]; f[2] = g[4]; f[3] = g[5];
    for (int k = 1; k < 4; k++) f[k].s.knots[0] = f[k].knots[0], f[k].s.knots[1] = f[k].knots[1],
                                f[k].s.mults[0] = f[k].mults[0], f[k].s.mults[1] = f[k].mults[1],
                                f[k].s.poles = f[k].poles;
    bezier_elevate(&f[2]);
    bezier_elevate(&f[2]);
    memset(&f[0], 0, sizeof f[0]);
    const int np[2] = {4, 6};
    for (int d = 0; d < 2; d++) {
        f[0].s.degree[d] = 3;
        f[0].s.num_poles[d] = np[d];
        f[0].s.num_knots[d] = np[d] + 4;
        for (int i = 0; i < np[d] + 4; i++) { f[0].knots[d][i] = i; f[0].mults[d][i] = 1; }
        f[0].s.knots[d] = f[0].knots[d];
        f[0].s.mults[d] = f[0].mults[d];
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 6; j++) {
            double *P = f[0].poles + 3 * (6 * i + j);
            P[0] = i;
            P[1] = j * 0.9;
            P[2] = 0.4 * sin(1.3 * i) * cos(0.8 * j) + 0.1 * i * j / 6.0;
        }
    f[0].s.poles = f[0].poles;
    for (int a = 0; a <= 16; a++) tee_bs[a] = a <= 1 ? 0 : 2; /* face 0 side 1: two breaks */
    return 4;
}

/* Torus: a periodic bicubic B-spline in both directions, NU x NV distinct poles, knot
 * intervals du, dv (non-uniform), in the standard unclamped form (poles wrap by 3). */
#define TNU 8
#define TNV 6
static const double tdu[TNU] = {1.0, 0.7, 1.3, 0.9, 1.1, 0.6, 1.4, 1.0};
static const double tdv[TNV] = {0.8, 1.2, 1.0, 0.5, 1.5, 1.0};

static void torus_pole(int i, int j, double out[3]) {
    double phi = 2 * PI * (i % TNU) / TNU, th = 2 * PI * (j % TNV) / TNV + 0.3;
    double R = 3.0 + 0.2 * cos(3 * phi), r = 1.0 + 0.1 * sin(2 * th);
    out[0] = (R + r * cos(th)) * cos(phi);
    out[1] = (R + r * cos(th)) * sin(phi);
    out[2] = r * sin(th);
}

static int make_torus(tsurf *f) {
    memset(f, 0, sizeof *f);
    const int p = 3, n[2] = {TNU, TNV};
    const double *d[2] = {tdu, tdv};
    for (int k = 0; k < 2; k++) {
        f->s.degree[k] = p;
        f->s.num_poles[k] = n[k] + p;
        f->s.num_knots[k] = n[k] + 2 * p + 1;
        f->s.periodic[k] = 1;
        double t = -2.0;
        for (int i = 0; i < n[k] + 2 * p + 1; i++) {
            f->knots[k][i] = t;
            f->mults[k][i] = 1;
            t += d[k][(i + n[k] - p) % n[k]]; /* interval i is d[i - p]: t[p] .. t[p+1] is d[0] */
        }
        f->s.knots[k] = f->knots[k];
        f->s.mults[k] = f->mults[k];
    }
    for (int i = 0; i < TNU + p; i++)
        for (int j = 0; j < TNV + p; j++) torus_pole(i, j, f->poles + 3 * (i * (TNV + p) + j));
    f->s.poles = f->poles;
    return 1;
}

/* ---- output ------------------------------------------------------------------------- */

typedef struct { char *buf; size_t len, cap; int fail_after; } sink;

static int sink_fn(void *user, const char *data, size_t len) {
    sink *s = user;
    if (s->fail_after >= 0 && s->len + len > (size_t)s->fail_after) return 1;
    if (s->len + len > s->cap) {
        size_t cap = 2 * (s->len + len);
        char *b = realloc(s->buf, cap);
        if (!b) return 1;
        s->buf = b;
        s->cap = cap;
    }
    memcpy(s->buf + s->len, data, len);
    s->len += len;
    return 0;
}

typedef ccn_status (*writer_fn)(const ccn__cad_model *, ccn__cad_write_fn, void *, ccn_error *);

static const char *outdir;

static void write_file(const char *name, const char *ext, const char *data, size_t len) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s.%s", outdir, name, ext);
    FILE *fp = fopen(path, "wb");
    CHECK(fp != NULL, "cannot open %s", path);
    if (!fp) return;
    CHECK(fwrite(data, 1, len, fp) == len, "short write %s", path);
    CHECK(fclose(fp) == 0, "close %s", path);
}

static void write_ref(const char *name, const tsurf *f, int n) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s.ref", outdir, name);
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL, "cannot open %s", path);
    if (!fp) return;
    int ok = 1;
    for (int k = 0; k < n; k++) {
        double u0, u1, v0, v1, x[3];
        ref_domain(&f[k].s, 0, &u0, &u1);
        ref_domain(&f[k].s, 1, &v0, &v1);
        for (int i = 0; i < GRID; i++)
            for (int j = 0; j < GRID; j++) {
                double u = u0 + (u1 - u0) * i / (GRID - 1), v = v0 + (v1 - v0) * j / (GRID - 1);
                ref_eval(&f[k].s, u, v, x);
                ok &= fprintf(fp, "%d %d %d %.17g %.17g %.17g %.17g %.17g\n", k, i, j, u, v, x[0], x[1], x[2]) > 0;
            }
    }
    CHECK(ok, "writing %s", path);
    CHECK(fclose(fp) == 0, "close %s", path);
}

/* Writes the model with both writers: status, determinism, files for the oracle. */
static void export_model(const char *name, tsurf *f, int n, const int32_t *bs, const double *br,
                         int expect_closed) {
    ccn__cad_surface faces[8];
    int32_t adj[128];
    for (int k = 0; k < n; k++) faces[k] = f[k].s;
    int ns = find_adjacency(f, n, bs, br, adj), shared = 0;
    for (int a = 0; a < ns; a++) shared += adj[a] >= 0;
    CHECK((shared == ns) == expect_closed, "%s: %d of %d segments shared", name, shared, ns);
    ccn__cad_model m = {.num_faces = n, .faces = faces, .side_breaks_start = bs, .side_breaks = br,
                        .adjacency = adj, .name = name};
    static const char *ext[2] = {"step", "igs"};
    writer_fn w[2] = {ccn__step_write, ccn__iges_write};
    for (int k = 0; k < 2; k++) {
        sink a = {NULL, 0, 0, -1}, b = {NULL, 0, 0, -1};
        ccn_error e;
        ccn_status st = w[k](&m, sink_fn, &a, &e);
        CHECK(st == CCN_OK, "%s.%s: %s", name, ext[k], e.message);
        st = w[k](&m, sink_fn, &b, &e);
        CHECK(st == CCN_OK && a.len == b.len && a.len > 0 && memcmp(a.buf, b.buf, a.len) == 0,
              "%s.%s: two writes differ", name, ext[k]);
        if (st == CCN_OK && outdir) write_file(name, ext[k], a.buf, a.len);
        sink c = {NULL, 0, 0, (int)(a.len / 2)}; /* a sink that fails half-way */
        st = w[k](&m, sink_fn, &c, &e);
        CHECK(st == CCN_ERR_IO, "%s.%s: failing sink gave %d", name, ext[k], (int)st);
        free(a.buf); free(b.buf); free(c.buf);
    }
    if (outdir) write_ref(name, f, n);
}

static tsurf models[8];

static void test_cube(void) { export_model("cube", models, make_cube(models), NULL, NULL, 1); }
static void test_grid(void) { export_model("grid", models, make_grid(models), NULL, NULL, 0); }
static void test_tee(void) { export_model("tee", models, make_tee(models), tee_bs, tee_br, 0); }
static void test_torus(void) {
    export_model("torus", models, make_torus(models), NULL, NULL, 1);
    if (!outdir) return;
    char path[512];
    snprintf(path, sizeof path, "%s/torus_build.txt", outdir);
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL, "cannot open %s", path);
    if (!fp) return;
    int ok = fprintf(fp, "degree 3 3\npoles %d %d\nperiodic 1 1\n", TNU, TNV) > 0;
    const int n[2] = {TNU, TNV};
    for (int k = 0; k < 2; k++) { /* the period t[p] .. t[p+n] and mults 1 */
        ok &= fprintf(fp, "%cknots %d", k ? 'v' : 'u', n[k] + 1) > 0;
        for (int i = 0; i <= n[k]; i++) ok &= fprintf(fp, " %.17g", models[0].knots[k][3 + i]) > 0;
        ok &= fprintf(fp, "\n%cmults %d", k ? 'v' : 'u', n[k] + 1) > 0;
        for (int i = 0; i <= n[k]; i++) ok &= fprintf(fp, " 1") > 0;
        ok &= fprintf(fp, "\n") > 0;
    }
    for (int i = 0; i < TNU; i++)
        for (int j = 0; j < TNV; j++) {
            double x[3];
            torus_pole(i, j, x);
            ok &= fprintf(fp, "%.17g %.17g %.17g\n", x[0], x[1], x[2]) > 0;
        }
    CHECK(ok, "writing %s", path);
    CHECK(fclose(fp) == 0, "close %s", path);
}

/* The writers' own evaluation agrees with the recursion (the writers place vertices with it). */
static void test_eval(void) {
    int n = make_torus(models);
    (void)n;
    double u0, u1, v0, v1, a[3], b[3], worst = 0;
    ccn__cad_domain(&models[0].s, 0, &u0, &u1);
    ccn__cad_domain(&models[0].s, 1, &v0, &v1);
    for (int i = 0; i <= 10; i++)
        for (int j = 0; j <= 10; j++) {
            double u = u0 + (u1 - u0) * i / 10, v = v0 + (v1 - v0) * j / 10;
            ccn__cad_eval(&models[0].s, u, v, a);
            ref_eval(&models[0].s, u, v, b);
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(a[k] - b[k]));
        }
    CHECK(worst <= 1e-13, "de Boor vs recursion %g", worst);
}

/* Each segment curve (knot insertion cut, parameters mapped onto [0, 1]) evaluated by the
 * recursion equals the surface side at the corresponding parameter: a split unclamped
 * (periodic) side and the tee's split pack side. */
static double curve_eval_ref(const ccn__cad_curve *c, double t, int k) {
    double x = 0, end = c->knots[c->num_poles];
    for (int i = 0; i < c->num_poles; i++) x += cdb(c->knots, i, c->degree, t, end) * c->poles[3 * i + k];
    return x;
}

static void check_segments(const ccn__cad_model *m, const tsurf *f) {
    ccn__cad_topo t;
    ccn_error e;
    CHECK(ccn__cad_topo_build(m, &t, &e) == CCN_OK, "topo: %s", e.message);
    double knots[200], poles[600], worst = 0;
    int cut = 0;
    for (int32_t j = 0; j < t.num_segs; j++) {
        ccn__cad_curve c = {0, 0, knots, poles, 0};
        CHECK(ccn__cad_curve_capacity(&m->faces[t.seg_face[j]]) <= 190, "capacity");
        ccn__cad_segment_curve(m, &t, j, &c);
        CHECK(c.knots[c.degree] == 0 && c.knots[c.num_poles] == 1, "segment %d: curve domain [%g, %g], not [0, 1]",
              (int)j, c.knots[c.degree], c.knots[c.num_poles]);
        cut += c.num_poles != m->faces[t.seg_face[j]].num_poles[t.seg_side[j] % 2];
        for (int q = 0; q <= 8; q++) {
            double w = t.seg_lo[j] + (t.seg_hi[j] - t.seg_lo[j]) * q / 8, x[3], u0, u1, v0, v1;
            const ccn__cad_surface *s = &f[t.seg_face[j]].s;
            ref_domain(s, 0, &u0, &u1);
            ref_domain(s, 1, &v0, &v1);
            int sd = t.seg_side[j];
            ref_eval(s, sd % 2 ? (sd == 1 ? u1 : u0) : w, sd % 2 ? w : (sd == 0 ? v0 : v1), x);
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(curve_eval_ref(&c, q / 8.0, k) - x[k]));
        }
    }
    CHECK(worst <= 1e-13, "segment curves differ from the surface by %g", worst);
    CHECK(cut > 0, "no segment was cut");
    ccn__cad_topo_free(&t);
}

static void test_segments(void) {
    int n = make_tee(models);
    ccn__cad_surface faces[4];
    int32_t adj[128];
    for (int k = 0; k < n; k++) faces[k] = models[k].s;
    find_adjacency(models, n, tee_bs, tee_br, adj);
    ccn__cad_model m = {.num_faces = n, .faces = faces, .side_breaks_start = tee_bs,
                        .side_breaks = tee_br, .adjacency = adj};
    check_segments(&m, models);
    /* the torus with its u seam split at two knots and its v seam at one non-knot */
    make_torus(models);
    /* side 0 split at u = 2.7, 6 (knots), side 1 at v = 3.5 (no knot); sides 2, 3 are the
     * same seam edges, split at the same points in their own running order */
    int32_t bs2[5] = {0, 2, 3, 5, 6};
    double br2[6] = {2.7, 6.0, 3.5, 6.0, 2.7, 3.5};
    ccn__cad_surface tf = models[0].s;
    int32_t tadj[16];
    int ns = find_adjacency(models, 1, bs2, br2, tadj), shared = 0;
    for (int a = 0; a < ns; a++) shared += tadj[a] >= 0;
    CHECK(shared == ns, "split torus: %d of %d segments shared", shared, ns);
    ccn__cad_model tm = {.num_faces = 1, .faces = &tf, .side_breaks_start = bs2, .side_breaks = br2,
                         .adjacency = tadj};
    check_segments(&tm, models);
    writer_fn w[2] = {ccn__step_write, ccn__iges_write};
    static const char *ext[2] = {"step", "igs"};
    for (int k = 0; k < 2; k++) {
        sink a = {NULL, 0, 0, -1};
        ccn_error e;
        CHECK(w[k](&tm, sink_fn, &a, &e) == CCN_OK, "split torus: %s", e.message);
        if (outdir) write_file("torus_split", ext[k], a.buf, a.len);
        free(a.buf);
    }
    if (outdir) write_ref("torus_split", models, 1);
}

static void expect_error(const char *what, ccn__cad_model *m, ccn_status want, int32_t face) {
    writer_fn w[2] = {ccn__step_write, ccn__iges_write};
    for (int k = 0; k < 2; k++) {
        sink s = {NULL, 0, 0, -1};
        ccn_error e;
        memset(&e, 0, sizeof e);
        ccn_status st = w[k](m, sink_fn, &s, &e);
        CHECK(st == want, "%s: status %d, want %d (%s)", what, (int)st, (int)want, e.message);
        CHECK(face < 0 || (e.element_kind == CCN_ELEM_FACE && e.element == face &&
                           strstr(e.message, "face") != NULL),
              "%s: error names element %d kind %d: %s", what, (int)e.element, (int)e.element_kind, e.message);
        CHECK(s.len == 0, "%s: wrote %zu bytes before failing", what, s.len);
        free(s.buf);
    }
}

static void test_bad_models(void) {
    int n = make_cube(models);
    ccn__cad_surface faces[6];
    int32_t adj[24];
    for (int k = 0; k < n; k++) faces[k] = models[k].s;
    find_adjacency(models, n, NULL, NULL, adj);
    ccn__cad_model m = {.num_faces = n, .faces = faces, .adjacency = adj, .name = "bad"};
    int32_t keep = adj[5];
    adj[5] = 4 * 3 + 2; /* not mutual */
    expect_error("non-mutual side", &m, CCN_ERR_TOPOLOGY, 1);
    adj[5] = keep;
    int32_t b = adj[0]; /* swap two partners: mutual but a different curve */
    int32_t c = adj[1];
    adj[0] = c; adj[c] = 0; adj[1] = b; adj[b] = 1;
    expect_error("mismatched sides", &m, CCN_ERR_TOPOLOGY, 0);
    find_adjacency(models, n, NULL, NULL, adj);
    models[2].poles[7] = NAN;
    expect_error("NaN pole", &m, CCN_ERR_ARGUMENT, 2);
    models[2].poles[7] = 0;
    n = make_cube(models);
    models[3].mults[0][0] = 3; /* sum no longer poles + degree + 1 */
    expect_error("knot sum", &m, CCN_ERR_KNOTS, 3);
    models[3].mults[0][0] = 4;
    models[4].knots[1][1] = models[4].knots[1][0];
    expect_error("knots not increasing", &m, CCN_ERR_KNOTS, 4);
    models[4].knots[1][1] = 1;
    faces[5].degree[0] = 0;
    expect_error("degree 0", &m, CCN_ERR_ARGUMENT, 5);
    faces[5].degree[0] = 3;
    m.name = "it's";
    expect_error("quote in name", &m, CCN_ERR_ARGUMENT, -1);
    m.name = NULL;
    m.num_faces = 0;
    expect_error("no faces", &m, CCN_ERR_ARGUMENT, -1);
    /* periodic flag on a face whose rows do not repeat */
    make_torus(models);
    models[0].poles[0] += 0.5;
    ccn__cad_surface tf = models[0].s;
    int32_t tadj[4] = {2, 3, 0, 1};
    ccn__cad_model tm = {.num_faces = 1, .faces = &tf, .adjacency = tadj};
    expect_error("periodic rows differ", &tm, CCN_ERR_ARGUMENT, 0);
    /* a break outside its side, and breaks out of order */
    int nt = make_tee(models);
    ccn__cad_surface tee[4];
    for (int k = 0; k < nt; k++) tee[k] = models[k].s;
    int32_t tadj2[128];
    find_adjacency(models, nt, tee_bs, tee_br, tadj2);
    ccn__cad_model mt = {.num_faces = nt, .faces = tee, .side_breaks_start = tee_bs,
                         .side_breaks = tee_br, .adjacency = tadj2};
    tee_br[1] = 6; /* = the side's end */
    expect_error("break at the side's end", &mt, CCN_ERR_ARGUMENT, 0);
    tee_br[0] = 5; tee_br[1] = 4;
    expect_error("breaks out of order", &mt, CCN_ERR_ARGUMENT, 0);
    tee_br[0] = 4; tee_br[1] = 5;
    mt.side_breaks = NULL;
    expect_error("breaks without their starts", &mt, CCN_ERR_ARGUMENT, -1);
}

int main(int argc, char **argv) {
    outdir = argc > 1 ? argv[1] : NULL;
    RUN(test_eval);
    RUN(test_cube);
    RUN(test_grid);
    RUN(test_tee);
    RUN(test_segments);
    RUN(test_torus);
    RUN(test_bad_models);
    return TEST_SUMMARY();
}
