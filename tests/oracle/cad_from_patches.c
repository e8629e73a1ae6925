/* Prototype of the unpacked export (test tool, not the product): every patch of
 * ccn_plan_patches (bicubic Bezier patches of the regular faces, the bi-5 rings and caps)
 * becomes one Bezier face of the CAD writers' neutral B-rep (csrc/io/cad.h). The topology is
 * recovered here from the geometry, which the library version will take from the plan's
 * meshes instead (tests/oracle/EXPORT_DESIGN.md): a patch corner lying inside another
 * patch's side splits that side (T-junctions: the cap rings, the level-K faces around a cap),
 * and two side segments with the same end points and mid point run in opposite directions
 * are one edge.
 *
 *   cad_from_patches [--levels L] [--scheme eigen|nurss|cc] in.obj out.step out.igs
 *
 * Prints "key: value" lines: patches by degree, skipped faces, side breaks, shared and
 * boundary segments; the writers' status.
 */
#include "io/cad.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { int deg; double pts[108]; int32_t face; } patch;
typedef struct { patch *p; size_t n, cap; int oom; } patch_list;

static void collect(void *user, int32_t degree, const double *points, int32_t cage_face) {
    patch_list *l = user;
    if (l->oom) return;
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 1024;
        patch *p = realloc(l->p, cap * sizeof *p);
        if (!p) { l->oom = 1; return; }
        l->p = p;
        l->cap = cap;
    }
    patch *q = &l->p[l->n++];
    q->deg = degree;
    q->face = cage_face;
    memcpy(q->pts, points, sizeof(double) * 3 * (size_t)((degree + 1) * (degree + 1)));
}

/* Side s of patch p as a Bezier curve in running direction: ctrl[0..deg]. */
static void side_ctrl(const patch *p, int s, double ctrl[6][3]) {
    int d = p->deg, n = d + 1;
    for (int k = 0; k <= d; k++) {
        int i, j;
        switch (s) {
        case 0: i = k; j = 0; break;          /* v = 0, u increasing */
        case 1: i = d; j = k; break;          /* u = 1, v increasing */
        case 2: i = d - k; j = d; break;      /* v = 1, u decreasing */
        default: i = 0; j = d - k; break;     /* u = 0, v decreasing */
        }
        memcpy(ctrl[k], p->pts + 3 * (i * n + j), sizeof(double) * 3);
    }
}

static void bez_curve(double c[6][3], int d, double t, double x[3], double dx[3]) {
    double b[6][3];
    memcpy(b, c, sizeof b);
    for (int r = 1; r < d; r++)
        for (int i = 0; i <= d - r; i++)
            for (int k = 0; k < 3; k++) b[i][k] = (1 - t) * b[i][k] + t * b[i + 1][k];
    for (int k = 0; k < 3; k++) {
        dx[k] = d * (b[1][k] - b[0][k]);
        x[k] = (1 - t) * b[0][k] + t * b[1][k];
    }
}

static double dist(const double a[3], const double b[3]) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Parameter of point q on the curve (running direction), or -1 if it is not on it. */
static double project(double c[6][3], int d, const double q[3], double tol) {
    double best = 0, bd = INFINITY, x[3], dx[3];
    for (int k = 0; k <= 16; k++) {
        bez_curve(c, d, k / 16.0, x, dx);
        double e = dist(x, q);
        if (e < bd) { bd = e; best = k / 16.0; }
    }
    double t = best;
    for (int it = 0; it < 30; it++) {
        bez_curve(c, d, t, x, dx);
        double g = (x[0] - q[0]) * dx[0] + (x[1] - q[1]) * dx[1] + (x[2] - q[2]) * dx[2];
        double h = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
        if (h <= 0) break;
        t -= g / h;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
    }
    bez_curve(c, d, t, x, dx);
    return dist(x, q) <= tol ? t : -1;
}

typedef struct { double x[3]; } pt;
static int cmp_x(const void *a, const void *b) {
    double d = ((const pt *)a)->x[0] - ((const pt *)b)->x[0];
    return d < 0 ? -1 : d > 0;
}
static int cmp_dbl(const void *a, const void *b) {
    double d = *(const double *)a - *(const double *)b;
    return d < 0 ? -1 : d > 0;
}

typedef struct { double a[3], b[3], m[3]; int32_t id; } segkey;
static int cmp_seg(const void *a, const void *b) {
    double d = ((const segkey *)a)->m[0] - ((const segkey *)b)->m[0];
    return d < 0 ? -1 : d > 0;
}

static int write_fn(void *user, const char *data, size_t len) {
    return fwrite(data, 1, len, (FILE *)user) != len;
}

static int usage(void) {
    fprintf(stderr, "usage: cad_from_patches [--levels L] [--scheme eigen|nurss|cc] in.obj out.step out.igs\n");
    return 2;
}

int main(int argc, char **argv) {
    ccn_options opts = {0};
    const char *files[3];
    int nfiles = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--levels") && i + 1 < argc) opts.levels = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--scheme") && i + 1 < argc) {
            const char *s = argv[++i];
            opts.scheme = !strcmp(s, "nurss") ? CCN_SCHEME_NURSS : !strcmp(s, "cc") ? CCN_SCHEME_CATMULL_CLARK : CCN_SCHEME_EIGEN;
        } else if (nfiles < 3) files[nfiles++] = argv[i];
        else return usage();
    }
    if (nfiles != 3) return usage();
    FILE *fp = fopen(files[0], "rb");
    if (!fp) { perror(files[0]); return 1; }
    fseek(fp, 0, SEEK_END);
    long len = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    char *text = malloc((size_t)len + 1);
    if (!text || fread(text, 1, (size_t)len, fp) != (size_t)len) { fclose(fp); return 1; }
    fclose(fp);
    ccn_error err;
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *plan;
    if (ccn_obj_parse(text, (size_t)len, &obj, &err) || ccn_obj_cage(obj, &cage) ||
        ccn_plan_create(&cage, &opts, &plan, &err)) {
        fprintf(stderr, "cad_from_patches: %s\n", err.message);
        return 1;
    }
    ccn_sizes sz;
    ccn_plan_sizes(plan, &sz);
    ccn_limit_mesh lm = {malloc(sizeof(double) * 3 * (size_t)sz.num_verts), NULL, NULL, NULL};
    if (!lm.positions || ccn_plan_evaluate(plan, NULL, &lm, &err)) { fprintf(stderr, "evaluate: %s\n", err.message); return 1; }
    patch_list pl = {0};
    int32_t skipped = 0;
    ccn_plan_patches(plan, collect, &pl, &skipped);
    if (pl.oom || pl.n == 0) { fprintf(stderr, "cad_from_patches: no patches\n"); return 1; }
    size_t np = pl.n;
    int ndeg[6] = {0};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    pt *corners = malloc(sizeof(pt) * 4 * np);
    for (size_t i = 0; i < np; i++) {
        const patch *p = &pl.p[i];
        int d = p->deg, n = d + 1;
        ndeg[d]++;
        const int ci[4][2] = {{0, 0}, {d, 0}, {d, d}, {0, d}};
        for (int c = 0; c < 4; c++) memcpy(corners[4 * i + c].x, p->pts + 3 * (ci[c][0] * n + ci[c][1]), sizeof(double) * 3);
        for (int k = 0; k < 3 * n * n; k++) {
            lo[k % 3] = fmin(lo[k % 3], p->pts[k]);
            hi[k % 3] = fmax(hi[k % 3], p->pts[k]);
        }
    }
    double size = dist(lo, hi), tol = 1e-9 * size;
    qsort(corners, 4 * np, sizeof(pt), cmp_x);
    /* breaks: corners strictly inside each side, in running order */
    int32_t *bs = calloc(4 * np + 1, sizeof(int32_t));
    size_t bcap = 1024, nb = 0;
    double *br = malloc(sizeof(double) * bcap);
    for (size_t i = 0; i < np; i++)
        for (int s = 0; s < 4; s++) {
            double c[6][3], blo[3], bhi[3], ts[64];
            int nt = 0, d = pl.p[i].deg;
            side_ctrl(&pl.p[i], s, c);
            for (int k = 0; k < 3; k++) { blo[k] = INFINITY; bhi[k] = -INFINITY; }
            for (int q = 0; q <= d; q++)
                for (int k = 0; k < 3; k++) { blo[k] = fmin(blo[k], c[q][k] - tol); bhi[k] = fmax(bhi[k], c[q][k] + tol); }
            size_t a = 0, b = 4 * np; /* first corner with x >= blo[0] */
            while (a < b) { size_t m = (a + b) / 2; if (corners[m].x[0] < blo[0]) a = m + 1; else b = m; }
            for (size_t k = a; k < 4 * np && corners[k].x[0] <= bhi[0]; k++) {
                const double *q = corners[k].x;
                if (q[1] < blo[1] || q[1] > bhi[1] || q[2] < blo[2] || q[2] > bhi[2]) continue;
                if (dist(q, c[0]) <= tol || dist(q, c[d]) <= tol) continue;
                double t = project(c, d, q, tol);
                if (t <= 1e-9 || t >= 1 - 1e-9) continue;
                int dup = 0;
                for (int r = 0; r < nt; r++) dup |= fabs(ts[r] - t) < 1e-9;
                if (!dup && nt < 64) ts[nt++] = t;
            }
            qsort(ts, (size_t)nt, sizeof(double), cmp_dbl);
            if (nb + (size_t)nt > bcap) { bcap = 2 * (nb + (size_t)nt); br = realloc(br, sizeof(double) * bcap); }
            for (int r = 0; r < nt; r++) br[nb++] = s < 2 ? ts[r] : 1 - ts[r]; /* the side's own parameter */
            bs[4 * i + s + 1] = (int32_t)nb;
        }
    /* segments and their matching */
    size_t ns = 4 * np + nb;
    segkey *sk = malloc(sizeof(segkey) * ns);
    int32_t *adj = malloc(sizeof(int32_t) * ns);
    size_t j = 0;
    for (size_t i = 0; i < np; i++)
        for (int s = 0; s < 4; s++) {
            double c[6][3], dx[3];
            int d = pl.p[i].deg;
            side_ctrl(&pl.p[i], s, c);
            int32_t b0 = bs[4 * i + s], b1 = bs[4 * i + s + 1];
            double prev = 0;
            for (int32_t k = b0; k <= b1; k++, j++) {
                double next = k < b1 ? (s < 2 ? br[k] : 1 - br[k]) : 1; /* running fraction */
                bez_curve(c, d, prev, sk[j].a, dx);
                bez_curve(c, d, next, sk[j].b, dx);
                bez_curve(c, d, 0.5 * (prev + next), sk[j].m, dx);
                sk[j].id = (int32_t)j;
                adj[j] = -1;
                prev = next;
            }
        }
    segkey *sorted = malloc(sizeof(segkey) * ns);
    memcpy(sorted, sk, sizeof(segkey) * ns);
    qsort(sorted, ns, sizeof(segkey), cmp_seg);
    size_t shared = 0;
    for (size_t a = 0; a < ns; a++) {
        const segkey *A = &sorted[a];
        if (adj[A->id] >= 0) continue;
        for (size_t b = a + 1; b < ns && sorted[b].m[0] <= A->m[0] + tol; b++) {
            const segkey *B = &sorted[b];
            if (adj[B->id] >= 0 || dist(A->m, B->m) > tol || dist(A->a, B->b) > tol || dist(A->b, B->a) > tol) continue;
            adj[A->id] = B->id;
            adj[B->id] = A->id;
            shared += 2;
            break;
        }
    }
    /* connected components of faces through shared segments (a reader makes one shell each) */
    int32_t *comp = malloc(sizeof(int32_t) * np), ncomp = 0;
    for (size_t i = 0; i < np; i++) comp[i] = (int32_t)i;
    for (size_t i = 0, q = 0; i < np; i++)
        for (int s = 0; s < 4; s++)
            for (int32_t k = bs[4 * i + s]; k <= bs[4 * i + s + 1]; k++, q++) {
                if (adj[q] < 0) continue;
                size_t other = 0; /* the face of segment adj[q]: segments of face f start at 4f + bs[4f] */
                size_t lo2 = 0, hi2 = np;
                while (hi2 - lo2 > 1) { size_t mid = (lo2 + hi2) / 2; if (4 * mid + (size_t)bs[4 * mid] <= (size_t)adj[q]) lo2 = mid; else hi2 = mid; }
                other = lo2;
                int32_t a = (int32_t)i, b = (int32_t)other;
                while (comp[a] != a) a = comp[a];
                while (comp[b] != b) b = comp[b];
                if (a != b) comp[a < b ? b : a] = a < b ? a : b;
            }
    for (size_t i = 0; i < np; i++) ncomp += comp[i] == (int32_t)i;
    free(comp);
    /* the neutral model: Bezier faces on [0,1]^2 */
    ccn__cad_surface *faces = calloc(np, sizeof *faces);
    static const double k01[2] = {0, 1};
    static const int32_t m4[2] = {4, 4}, m6[2] = {6, 6};
    for (size_t i = 0; i < np; i++) {
        int d = pl.p[i].deg;
        for (int q = 0; q < 2; q++) {
            faces[i].degree[q] = d;
            faces[i].num_poles[q] = d + 1;
            faces[i].num_knots[q] = 2;
            faces[i].knots[q] = k01;
            faces[i].mults[q] = d == 3 ? m4 : m6;
        }
        faces[i].poles = pl.p[i].pts;
    }
    ccn__cad_model m = {.num_faces = (int32_t)np, .faces = faces, .side_breaks_start = bs,
                        .side_breaks = br, .adjacency = adj, .name = "ccnurbs"};
    printf("patches: %zu\nbicubic: %d\nbi5: %d\nskipped_faces: %d\ncaps: %d\ncap_fallbacks: %d\n"
           "side_breaks: %zu\nsegments: %zu\nshared_segments: %zu\nboundary_segments: %zu\n"
           "components: %d\n", np,
           ndeg[3], ndeg[5], (int)skipped, (int)sz.num_caps, (int)sz.num_cap_fallbacks, nb, ns,
           shared, ns - shared, (int)ncomp);
    int rc = 0;
    ccn__cad_write_fn fn = write_fn;
    ccn_status (*w[2])(const ccn__cad_model *, ccn__cad_write_fn, void *, ccn_error *) = {ccn__step_write, ccn__iges_write};
    for (int k = 0; k < 2; k++) {
        FILE *out = fopen(files[1 + k], "wb");
        if (!out) { perror(files[1 + k]); return 1; }
        ccn_status st = w[k](&m, fn, out, &err);
        int cl = fclose(out);
        printf("%s: %s%s%s\n", k ? "iges" : "step", st ? ccn_status_name(st) : "ok", st ? ": " : "", st ? err.message : "");
        rc |= st != CCN_OK || cl != 0;
    }
    free(faces); free(sorted); free(sk); free(adj); free(bs); free(br); free(corners); free(pl.p);
    free(lm.positions); free(text);
    ccn_plan_destroy(plan);
    ccn_obj_destroy(obj);
    return rc;
}
