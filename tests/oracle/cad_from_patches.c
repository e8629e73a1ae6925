/* Prototype of the unpacked export (test tool, not the product): every patch of
 * ccn_plan_patches (bicubic Bezier patches of the regular faces, the bi-5 rings and caps)
 * becomes one Bezier face of the CAD writers' neutral B-rep (csrc/io/cad.h). The topology is
 * recovered here from the geometry, which the library version will take from the plan's
 * meshes instead (tests/oracle/EXPORT_DESIGN.md): a patch corner lying inside another
 * patch's side splits that side (T-junctions: the cap rings, the level-K faces around a cap),
 * and two side segments with the same end points and mid point run in opposite directions
 * are one edge.
 *
 *   cad_from_patches [--packed] [--levels L] [--scheme eigen|nurss|cc] in.obj out.step out.igs
 *
 * --packed: maximal rectangles of strict-regular cage quads become one B-spline face each
 * with the ring intervals as knots (prototype in cad_pack.h); the patches of those cage
 * faces are dropped.
 *
 * Prints "key: value" lines: patches by degree, skipped faces, side breaks, shared and
 * boundary segments; the writers' status.
 */
#include "io/cad.h"
#include "cad_pack.h"

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

/* Point at running fraction w of side s of face f (sides 2, 3 run backwards). */
static void side_pt(const ccn__cad_surface *f, int s, double w, double x[3]) {
    double u0, u1, v0, v1;
    ccn__cad_domain(f, 0, &u0, &u1);
    ccn__cad_domain(f, 1, &v0, &v1);
    double u = s == 0 ? u0 + w * (u1 - u0) : s == 1 ? u1 : s == 2 ? u1 - w * (u1 - u0) : u0;
    double v = s == 0 ? v0 : s == 1 ? v0 + w * (v1 - v0) : s == 2 ? v1 : v1 - w * (v1 - v0);
    u = fmin(fmax(u, u0), u1);
    v = fmin(fmax(v, v0), v1);
    ccn__cad_eval(f, u, v, x);
}

static double dist(const double a[3], const double b[3]) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Running fraction of point q on side s of f, or -1 if it is not on it (samples + Newton
 * with a central-difference derivative: the residual check decides). */
static double project(const ccn__cad_surface *f, int s, const double q[3], double tol, int nsamp) {
    double best = 0, bd = INFINITY, x[3], xp[3], xm[3];
    for (int k = 0; k <= nsamp; k++) {
        side_pt(f, s, (double)k / nsamp, x);
        double e = dist(x, q);
        if (e < bd) { bd = e; best = (double)k / nsamp; }
    }
    double t = best, h = 1e-6;
    for (int it = 0; it < 40; it++) {
        side_pt(f, s, t, x);
        side_pt(f, s, fmin(t + h, 1), xp);
        side_pt(f, s, fmax(t - h, 0), xm);
        double dx[3], g = 0, hh = 0, dt = fmin(t + h, 1) - fmax(t - h, 0);
        for (int k = 0; k < 3; k++) { dx[k] = (xp[k] - xm[k]) / dt; g += (x[k] - q[k]) * dx[k]; hh += dx[k] * dx[k]; }
        if (hh <= 0) break;
        double step = g / hh;
        t = fmin(fmax(t - step, 0), 1);
        if (fabs(step) < 1e-15) break;
    }
    side_pt(f, s, t, x);
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
    fprintf(stderr, "usage: cad_from_patches [--packed] [--levels L] [--scheme eigen|nurss|cc] in.obj out.step out.igs\n");
    return 2;
}

int main(int argc, char **argv) {
    ccn_options opts = {0};
    const char *files[3];
    int nfiles = 0, packed = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--levels") && i + 1 < argc) opts.levels = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--packed")) packed = 1;
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
    /* Issue 14: a plan whose output level is not above the cap level K builds no caps (they
     * would not change the limit mesh), so the finite patch set with the bi-5 caps needs a
     * plan one level above K: raise the level until the caps (or their fallbacks) are there. */
    while (opts.cap == CCN_CAP_GUIDED_BI5 && sz.num_extraordinary > 0 && sz.num_caps + sz.num_cap_fallbacks == 0 &&
           opts.levels < 5) {
        ccn_plan_destroy(plan);
        opts.levels = (opts.levels > sz.levels ? opts.levels : sz.levels) + 1;
        if (ccn_plan_create(&cage, &opts, &plan, &err)) { fprintf(stderr, "cad_from_patches: %s\n", err.message); return 1; }
        ccn_plan_sizes(plan, &sz);
    }
    ccn_limit_mesh lm = {.positions = malloc(sizeof(double) * 3 * (size_t)sz.num_verts)};
    if (!lm.positions || ccn_plan_evaluate(plan, NULL, &lm, &err)) { fprintf(stderr, "evaluate: %s\n", err.message); return 1; }
    patch_list pl = {0};
    int32_t skipped = 0;
    ccn_plan_patches(plan, collect, &pl, &skipped);
    if (pl.oom || pl.n == 0) { fprintf(stderr, "cad_from_patches: no patches\n"); return 1; }
    /* faces: packs first (with --packed), then the patches of the other cage faces */
    cad_pack *packs = NULL;
    int32_t npacks = 0, *pack_of = NULL;
    ccn_mesh *mesh = NULL;
    if (packed) {
        pack_of = malloc(sizeof(int32_t) * (size_t)(cage.num_faces + 1));
        if (!pack_of || ccn_mesh_create(&cage, &mesh, &err)) { fprintf(stderr, "mesh: %s\n", err.message); return 1; }
        npacks = cad_make_packs(mesh, opts.boundary_corners == CCN_CORNERS_PINNED, &packs, pack_of);
        if (npacks < 0) return 1;
    }
    size_t np = 0, maxf = (size_t)npacks + pl.n;
    ccn__cad_surface *faces = calloc(maxf, sizeof *faces);
    static const double k01[2] = {0, 1};
    static const int32_t m4[2] = {4, 4}, m6[2] = {6, 6};
    int ndeg[6] = {0};
    for (int32_t k = 0; k < npacks; k++, np++) {
        ccn__cad_surface *F = &faces[np];
        for (int d = 0; d < 2; d++) {
            int32_t n = d ? packs[k].b : packs[k].a;
            F->degree[d] = 3;
            F->num_poles[d] = n + 3;
            F->num_knots[d] = n + 7;
            F->knots[d] = packs[k].knots[d];
            F->mults[d] = packs[k].mults[d];
            F->periodic[d] = packs[k].periodic[d];
        }
        F->poles = packs[k].poles;
    }
    for (size_t i = 0; i < pl.n; i++) {
        if (packed && pack_of[pl.p[i].face] >= 0) continue;
        int d = pl.p[i].deg;
        ndeg[d]++;
        for (int q = 0; q < 2; q++) {
            faces[np].degree[q] = d;
            faces[np].num_poles[q] = d + 1;
            faces[np].num_knots[q] = 2;
            faces[np].knots[q] = k01;
            faces[np].mults[q] = d == 3 ? m4 : m6;
        }
        faces[np++].poles = pl.p[i].pts;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    pt *corners = malloc(sizeof(pt) * 4 * np);
    int32_t maxc = 0;
    for (size_t i = 0; i < np; i++) {
        const ccn__cad_surface *F = &faces[i];
        for (int c = 0; c < 4; c++) side_pt(F, c, 0, corners[4 * i + c].x);
        for (size_t k = 0; k < 3 * (size_t)F->num_poles[0] * F->num_poles[1]; k++) {
            lo[k % 3] = fmin(lo[k % 3], F->poles[k]);
            hi[k % 3] = fmax(hi[k % 3], F->poles[k]);
        }
        maxc = ccn__cad_curve_capacity(F) > maxc ? ccn__cad_curve_capacity(F) : maxc;
    }
    double size = dist(lo, hi), tol = 1e-9 * size;
    double *sp = malloc(sizeof(double) * 3 * (size_t)maxc);
    qsort(corners, 4 * np, sizeof(pt), cmp_x);
    /* breaks: corners strictly inside each side, in running order */
    int32_t *bs = calloc(4 * np + 1, sizeof(int32_t));
    size_t bcap = 1024, nb = 0;
    double *br = malloc(sizeof(double) * bcap);
    for (size_t i = 0; i < np; i++)
        for (int s = 0; s < 4; s++) {
            const ccn__cad_surface *F = &faces[i];
            double blo[3], bhi[3], ts[512], a0[3], a1[3];
            int nt = 0, dir = s % 2, n = F->num_poles[dir];
            ccn__cad_side_curve(F, s, sp); /* its poles bound the side (convex hull) */
            for (int k = 0; k < 3; k++) { blo[k] = INFINITY; bhi[k] = -INFINITY; }
            for (int q = 0; q < n; q++)
                for (int k = 0; k < 3; k++) { blo[k] = fmin(blo[k], sp[3 * q + k] - tol); bhi[k] = fmax(bhi[k], sp[3 * q + k] + tol); }
            side_pt(F, s, 0, a0);
            side_pt(F, s, 1, a1);
            size_t a = 0, b = 4 * np; /* first corner with x >= blo[0] */
            while (a < b) { size_t mid = (a + b) / 2; if (corners[mid].x[0] < blo[0]) a = mid + 1; else b = mid; }
            for (size_t k = a; k < 4 * np && corners[k].x[0] <= bhi[0]; k++) {
                const double *q = corners[k].x;
                if (q[1] < blo[1] || q[1] > bhi[1] || q[2] < blo[2] || q[2] > bhi[2]) continue;
                if (dist(q, a0) <= tol || dist(q, a1) <= tol) continue;
                int dup = 0;
                for (int r = 0; r < nt && !dup; r++) { double x[3]; side_pt(F, s, ts[r], x); dup = dist(x, q) <= tol; }
                if (dup) continue;
                double t = project(F, s, q, tol, 16 * (n - F->degree[dir]));
                if (t <= 1e-12 || t >= 1 - 1e-12) continue;
                if (nt < 512) ts[nt++] = t;
            }
            qsort(ts, (size_t)nt, sizeof(double), cmp_dbl);
            if (nb + (size_t)nt > bcap) { bcap = 2 * (nb + (size_t)nt); br = realloc(br, sizeof(double) * bcap); }
            double plo, phi;
            ccn__cad_domain(F, dir, &plo, &phi);
            for (int r = 0; r < nt; r++) br[nb++] = s < 2 ? plo + ts[r] * (phi - plo) : phi - ts[r] * (phi - plo);
            bs[4 * i + s + 1] = (int32_t)nb;
        }
    /* segments and their matching */
    size_t ns = 4 * np + nb;
    segkey *sk = malloc(sizeof(segkey) * ns);
    int32_t *adj = malloc(sizeof(int32_t) * ns);
    size_t j = 0;
    for (size_t i = 0; i < np; i++)
        for (int s = 0; s < 4; s++) {
            const ccn__cad_surface *F = &faces[i];
            double plo, phi;
            ccn__cad_domain(F, s % 2, &plo, &phi);
            int32_t b0 = bs[4 * i + s], b1 = bs[4 * i + s + 1];
            double prev = 0;
            for (int32_t k = b0; k <= b1; k++, j++) {
                double next = k < b1 ? (s < 2 ? (br[k] - plo) : (phi - br[k])) / (phi - plo) : 1;
                side_pt(F, s, prev, sk[j].a);
                side_pt(F, s, next, sk[j].b);
                side_pt(F, s, 0.5 * (prev + next), sk[j].m);
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
    /* a seam: a face's side shared with the opposite side of the same face (periodic pack) */
    for (size_t a = 0; a < ns; a++) {
        const segkey *A = &sk[a];
        for (size_t b = a + 1; b < ns && adj[a] < 0; b++)
            if (adj[b] < 0 && dist(A->m, sk[b].m) <= tol && dist(A->a, sk[b].b) <= tol && dist(A->b, sk[b].a) <= tol) {
                adj[a] = (int32_t)b; adj[b] = (int32_t)a; shared += 2;
            }
        if (ns > 4096) break; /* quadratic: only for the few segments of small packed models */
    }
    /* connected components of faces through shared segments (a reader makes one shell each) */
    int32_t *comp = malloc(sizeof(int32_t) * np), ncomp = 0;
    for (size_t i = 0; i < np; i++) comp[i] = (int32_t)i;
    for (size_t q = 0; q < ns; q++) {
        if (adj[q] < 0) continue;
        size_t fa = 0, fb = 0, l2, h2; /* the face of a segment: segments of f start at 4f + bs[4f] */
        for (int w = 0; w < 2; w++) {
            size_t seg = w ? (size_t)adj[q] : q;
            l2 = 0; h2 = np;
            while (h2 - l2 > 1) { size_t mid = (l2 + h2) / 2; if (4 * mid + (size_t)bs[4 * mid] <= seg) l2 = mid; else h2 = mid; }
            if (w) fb = l2; else fa = l2;
        }
        int32_t a = (int32_t)fa, b = (int32_t)fb;
        while (comp[a] != a) a = comp[a];
        while (comp[b] != b) b = comp[b];
        if (a != b) comp[a < b ? b : a] = a < b ? a : b;
    }
    for (size_t i = 0; i < np; i++) ncomp += comp[i] == (int32_t)i;
    free(comp);
    ccn__cad_model m = {.num_faces = (int32_t)np, .faces = faces, .side_breaks_start = bs,
                        .side_breaks = br, .adjacency = adj, .name = "ccnurbs"};
    printf("packs: %d\nfaces: %zu\nbicubic: %d\nbi5: %d\nskipped_faces: %d\ncaps: %d\ncap_fallbacks: %d\n"
           "side_breaks: %zu\nsegments: %zu\nshared_segments: %zu\nboundary_segments: %zu\n"
           "components: %d\n", (int)npacks, np,
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
    for (int32_t k = 0; k < npacks; k++) /* packs: knots and periodic flags of the first */
        if (k < 4) {
            printf("pack %d: %d x %d cells, periodic %d %d, uknots", (int)k, (int)packs[k].a, (int)packs[k].b,
                   packs[k].periodic[0], packs[k].periodic[1]);
            for (int32_t q = 0; q < packs[k].a + 7; q++) printf(" %.17g", packs[k].knots[0][q]);
            printf(" vknots");
            for (int32_t q = 0; q < packs[k].b + 7; q++) printf(" %.17g", packs[k].knots[1][q]);
            printf("\n");
        }
    free(faces); free(sorted); free(sk); free(adj); free(bs); free(br); free(corners); free(pl.p); free(sp);
    cad_free_packs(packs, npacks);
    free(pack_of);
    ccn_mesh_destroy(mesh);
    free(lm.positions); free(text);
    ccn_plan_destroy(plan);
    ccn_obj_destroy(obj);
    return rc;
}
