/* ccnurbs experiment: the numerical experiments of Li, Finnigan, Sederberg 2016, section 7.
 *
 *   maxima   the blending function of an extraordinary vertex (EV) with random spoke intervals
 *            has exactly one local maximum after L refinements (SPEC 3.2, DESIGN 4.3);
 *   charmap  the (12n+1) x (12n+1) three-ring refinement matrix has the spectrum
 *            1 > mu2 = mu3 > |mu4| and the characteristic map is regular and injective.
 * Results: tests/experiments/RESULTS.md; tests: tests/experiments/run_experiments.sh.
 *
 * The cage ("G-ring fan"): valence-n centre vertex V, n sectors, sector s a G x G quad grid
 * between spoke s (angle 2 pi s / n) and spoke s+1. Grid point (s, i, j), 0 <= i, j <= G, sits
 * at i u_s + j u_{s+1}; (s, 0, j) is (s+1, j, 0) and (s, 0, 0) is V. Numbering (fan_vid): V = 0,
 * then per sector i = 1..G, j = 0..G: 1 + s G (G+1) + (i-1)(G+1) + j; G = 3 gives 12n+1
 * points, 9n faces, 21n edges. Every edge parallel to spoke s carries d_s (SPEC 3.2), so
 * opposite edges of every quad agree and the interval beyond every spoke end is the spoke's own.
 *
 * Where the blending function starts (--start): `level1` (default) refines the cage once, then
 * sets z = 1 at the EV's vertex point and 0 elsewhere. The level-1 mesh is again a fan whose
 * rings parallel to spoke s carry d_s, and every following refinement uses the scheme's EV
 * rules (for eigen: M at every level) -- the paper's and SPEC 3's setup. `cage` sets z on the
 * level-0 cage and refines that, which is the library pipeline: level 0 -> 1 uses NURSS rules at
 * the EV for every scheme (DESIGN 4.3), so its figures mix the two rule sets.
 *
 * Why three rings are exact: the blending function's control points at level k are non-zero
 * only strictly inside fine ring 2 * 2^k (its support is the 2-ring). A point whose stencil
 * differs from the infinite mesh's (boundary curve rules, mirrored intervals) only reads points
 * of fine rings >= R 2^k - 2, R = rings of the starting mesh (3 for `cage`, 4 for `level1`,
 * built from a 2-ring cage), which is >= 2 * 2^k for k >= 1 (and reads only zeros at k = 0);
 * mirrored intervals equal the true ones here anyway. So every refined z equals the
 * infinite-mesh value; --rings 6 (level1) / 4 (cage) checks it (run_experiments.sh (b)).
 * Local maximum (SPEC A11): z > 1e-12 and z strictly above every vertex sharing a face.
 *
 * Three-ring matrix (charmap): the cage (G = 3) is refined once to L1 (whose intervals are
 * again d_s, halved and normalised), so the matrix of L1 -> L2 is the stationary one. Its
 * 3-ring is found through topology (ring_grid): V1 = the vertex point of V (index nf + ne + 0,
 * ccnurbs.h order) and its spoke-0 neighbour = the edge point of the cage edge (V, (0,1,0))
 * (index nf + e); each sector's grid is walked face by face through directed half-edges; the
 * same on L2 (track_refine follows V and its spoke-0 neighbour through every refinement).
 * Column c is the refined 3-ring when 3-ring point c of L1 is 1 and all else 0 (three columns
 * per refine call, one per coordinate). Checks: rows sum to 1, the 1-ring rows equal
 * ccn_ev_matrix, and LAPACKE_dgeev's spectrum. The characteristic net (x, y = an orthonormal
 * basis of the mu2, mu3 eigenvectors) is placed on L1's 3-ring (all else 0) and refined; after
 * l levels rings <= 2^(l+1) + 1 depend on the 3-ring only.
 *   regular, injective (the limit surface; the pass criterion): at level 2 every face of rings
 *     2..4 is a regular bicubic patch; its Bezier net comes from the knot-interval form
 *     (span_bezier, checked against the next level to 5e-17). det J is a bidegree-(5,5)
 *     polynomial; its Bernstein coefficients all of one sign prove regularity, a corner value of
 *     the other sign (or 0) disproves it, otherwise the patch is split (up to 6 times). Injective:
 *     in addition the limit curves of parameter rings 2 and 4 (8 samples per face side) are
 *     simple, do not meet, wind +-1 (the Jacobian's sign) around the EV's limit (the origin,
 *     since mu2, mu3 != 1), and ring 2 lies inside ring 4: with a consistently signed Jacobian
 *     the number of preimages of a point is winding(outer) - winding(inner), so it is <= 1.
 *   net regular, net injective (diagnostic): the same on the control net of level k
 *     (--charlevels): quads of rings 2^(k-1)..2^k convex with one orientation (all four corner
 *     triangles), and the ring polygons. Control nets converge slowly where intervals differ
 *     by 100x, so this test also fails on some regular maps.
 */
#include "cli.h"

#include <lapacke.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__GLIBC__)
#include <malloc.h> /* mallopt */
#endif

#define EXP_MAX_N 64       /* largest valence */
#define EXP_MAX_VALS 16    /* entries of --valences */
#define EXP_ZMIN 1e-12     /* z <= this: outside the support */
#define EXP_CHUNK 8        /* cases taken by a worker at a time */
#define EXP_MAX_LATER 8    /* levels followed beyond L by --persist */
#define EXP_PI 3.14159265358979323846

typedef enum { EXP_MAXIMA, EXP_CHARMAP } exp_kind;

typedef struct {
    exp_kind kind;
    ccn_scheme scheme;
    int levels, rings, threads, list, persist, charlevels, dist_log, start;
    long cases, offset;
    uint64_t seed;
    double lo;
    int nval, val[EXP_MAX_VALS];
    int nknots;
    double knots[EXP_MAX_N];
} exp_args;

/* ---- argument parsing ------------------------------------------------------------- */

static int exp_usage(void) {
    fprintf(stderr,
            "usage:\n"
            "  ccnurbs experiment maxima  --cases N --seed S [--scheme eigen|nurss|cc] [--levels L]\n"
            "        [--dist uniform|loguniform] [--lo 1e-6] [--valences 3,5,6,7,8] [--knots d0,d1,...]\n"
            "        [--threads T] [--rings G] [--list K] [--persist L2] [--start level1|cage] [--offset K]\n"
            "  ccnurbs experiment charmap --cases N --seed S [--scheme eigen|nurss|cc] [--dist ...]\n"
            "        [--lo 1e-6] [--valences ...] [--knots ...] [--threads T] [--charlevels k] [--list K]\n"
            "        [--offset K]\n"
            "  Case i (i = K .. K+N-1) has valence valences[i mod count] and intervals drawn from a\n"
            "  generator seeded by (S, i): results do not depend on --threads or on how a run is split.\n");
    return 2;
}

static int parse_double(const char *s, double *out) {
    char *e;
    double x = strtod(s, &e);
    if (e == s || *e || !isfinite(x)) return -1;
    *out = x;
    return 0;
}

static int parse_long(const char *s, long lo, long hi, long *out) {
    char *e;
    long x = strtol(s, &e, 10);
    if (e == s || *e || x < lo || x > hi) return -1;
    *out = x;
    return 0;
}

static int parse_u64(const char *s, uint64_t *out) {
    char *e;
    if (*s == '-') return -1;
    unsigned long long x = strtoull(s, &e, 10);
    if (e == s || *e) return -1;
    *out = (uint64_t)x;
    return 0;
}

/* Comma-separated list of ints in [lo, hi] (ints) or positive finite doubles (dbl). */
static int parse_list(const char *s, int cap, int *ints, double *dbl, int lo, int hi) {
    int n = 0;
    while (*s) {
        if (n == cap) return -1;
        char *e;
        if (ints) {
            long x = strtol(s, &e, 10);
            if (e == s || x < lo || x > hi) return -1;
            ints[n++] = (int)x;
        } else {
            double x = strtod(s, &e);
            if (e == s || !isfinite(x) || x <= 0) return -1;
            dbl[n++] = x;
        }
        if (*e == ',') e++;
        else if (*e) return -1;
        s = e;
    }
    return n;
}

static int parse_choice(const char *opt, const char *val, exp_args *o) {
    if (strcmp(opt, "--scheme") == 0) return ccn_cli_scheme(val, &o->scheme);
    if (strcmp(opt, "--start") == 0) {
        if (strcmp(val, "cage") == 0) o->start = 0;
        else if (strcmp(val, "level1") == 0) o->start = 1;
        else return -1;
        return 0;
    }
    if (strcmp(opt, "--dist") == 0) {
        if (strcmp(val, "uniform") == 0) o->dist_log = 0;
        else if (strcmp(val, "loguniform") == 0) o->dist_log = 1;
        else return -1;
        return 0;
    }
    return 1; /* not a choice option */
}

static int parse_number_opt(const char *opt, const char *val, exp_args *o) {
    long x;
    if (strcmp(opt, "--cases") == 0) return parse_long(val, 1, 100000000L, &o->cases);
    if (strcmp(opt, "--seed") == 0) return parse_u64(val, &o->seed);
    if (strcmp(opt, "--offset") == 0) return parse_long(val, 0, 1000000000L, &o->offset);
    if (strcmp(opt, "--lo") == 0)
        return parse_double(val, &o->lo) || !(o->lo > 0 && o->lo <= 1) ? -1 : 0;
    struct { const char *name; long lo, hi; int *dst; } tab[] = {
        {"--levels", 0, 9, &o->levels},     {"--threads", 1, 256, &o->threads},
        {"--rings", 3, 8, &o->rings},       {"--list", 0, 1000000, &o->list},
        {"--persist", 0, 12, &o->persist},   {"--charlevels", 2, 7, &o->charlevels},
    };
    for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++) {
        if (strcmp(opt, tab[i].name)) continue;
        if (parse_long(val, tab[i].lo, tab[i].hi, &x)) return -1;
        *tab[i].dst = (int)x;
        return 0;
    }
    return 1;
}

static int parse_option(const char *opt, const char *val, exp_args *o) {
    int r = parse_choice(opt, val, o);
    if (r <= 0) return r;
    r = parse_number_opt(opt, val, o);
    if (r <= 0) return r;
    if (strcmp(opt, "--valences") == 0) {
        o->nval = parse_list(val, EXP_MAX_VALS, o->val, NULL, 3, EXP_MAX_N);
        return o->nval > 0 ? 0 : -1;
    }
    if (strcmp(opt, "--knots") == 0) {
        o->nknots = parse_list(val, EXP_MAX_N, NULL, o->knots, 0, 0);
        return o->nknots >= 3 ? 0 : -1;
    }
    return 1;
}

static int parse_args(int argc, char **argv, exp_args *o) {
    *o = (exp_args){.scheme = CCN_SCHEME_EIGEN, .levels = 5, .rings = 3, .threads = 2,
                    .list = 50, .charlevels = 4, .start = 1, .cases = 1000, .seed = 1, .lo = 1e-6,
                    .nval = 5, .val = {3, 5, 6, 7, 8}};
    if (strcmp(argv[1], "maxima") == 0) o->kind = EXP_MAXIMA;
    else if (strcmp(argv[1], "charmap") == 0) o->kind = EXP_CHARMAP;
    else {
        fprintf(stderr, "ccnurbs experiment: unknown experiment '%s'\n", argv[1]);
        return -1;
    }
    for (int i = 2; i < argc; i += 2) {
        int r = i + 1 < argc ? parse_option(argv[i], argv[i + 1], o) : 1;
        if (r) {
            fprintf(stderr, "ccnurbs experiment: %s option '%s'%s%s\n", r < 0 ? "bad value for" :
                    "unknown or incomplete", argv[i], r < 0 ? ": " : "", r < 0 ? argv[i + 1] : "");
            return -1;
        }
    }
    if (o->nknots) o->cases = 1;
    return 0;
}

/* ---- random cases ------------------------------------------------------------------ */

static uint64_t mix64(uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Valence and spoke intervals of case offset + idx: a function of (seed, offset + idx) only. */
static int case_setup(const exp_args *a, long idx, double *d) {
    if (a->nknots) {
        memcpy(d, a->knots, sizeof(double) * (size_t)a->nknots);
        return a->nknots;
    }
    idx += a->offset;
    int n = a->val[idx % a->nval];
    uint64_t st = mix64(mix64(a->seed) ^ (uint64_t)idx);
    for (int s = 0; s < n; s++) {
        st = mix64(st);
        double u = (double)(st >> 11) * (1.0 / 9007199254740992.0);
        d[s] = a->dist_log ? exp(log(a->lo) * (1.0 - u)) : a->lo + (1.0 - a->lo) * u;
    }
    return n;
}

static int valence_slot(const exp_args *a, int n) {
    if (a->nknots) return 0;
    for (int i = 0; i < a->nval; i++)
        if (a->val[i] == n) return i;
    return -1;
}

/* ---- the G-ring fan cage ------------------------------------------------------------ */

typedef struct {
    int n, G;
    int32_t nv, nf, ne;
    double *pos;
    int32_t *fsize, *fverts, *everts;
    int32_t *edir; /* the spoke an edge is parallel to: its interval is d[edir] */
} fan_cage;

static int32_t fan_vid(int n, int G, int s, int i, int j) {
    s %= n;
    if (i == 0) return j == 0 ? 0 : fan_vid(n, G, s + 1, j, 0);
    return 1 + (int32_t)s * G * (G + 1) + (int32_t)(i - 1) * (G + 1) + j;
}

static void fan_free(fan_cage *c) {
    free(c->pos); free(c->fsize); free(c->fverts); free(c->everts); free(c->edir);
    memset(c, 0, sizeof *c);
}

static void fan_positions(fan_cage *c) {
    int n = c->n, G = c->G;
    memset(c->pos, 0, sizeof(double) * 3 * (size_t)c->nv);
    c->pos[2] = 1.0;
    for (int s = 0; s < n; s++) {
        double a0 = 2 * EXP_PI * s / n, a1 = 2 * EXP_PI * (s + 1) / n;
        for (int i = 1; i <= G; i++)
            for (int j = 0; j <= G; j++) {
                double *p = c->pos + 3 * (size_t)fan_vid(n, G, s, i, j);
                p[0] = i * cos(a0) + j * cos(a1);
                p[1] = i * sin(a0) + j * sin(a1);
            }
    }
}

static void fan_topology(fan_cage *c) {
    int n = c->n, G = c->G;
    int32_t f = 0, e = 0;
    for (int s = 0; s < n; s++) {
        for (int i = 0; i < G; i++)
            for (int j = 0; j < G; j++, f++) {
                int32_t *q = c->fverts + 4 * (size_t)f;
                c->fsize[f] = 4;
                q[0] = fan_vid(n, G, s, i, j);
                q[1] = fan_vid(n, G, s, i + 1, j);
                q[2] = fan_vid(n, G, s, i + 1, j + 1);
                q[3] = fan_vid(n, G, s, i, j + 1);
            }
        for (int j = 0; j <= G; j++) /* parallel to spoke s */
            for (int i = 0; i < G; i++, e++) {
                c->everts[2 * e] = fan_vid(n, G, s, i, j);
                c->everts[2 * e + 1] = fan_vid(n, G, s, i + 1, j);
                c->edir[e] = s;
            }
        for (int i = 1; i <= G; i++) /* parallel to spoke s+1 */
            for (int j = 0; j < G; j++, e++) {
                c->everts[2 * e] = fan_vid(n, G, s, i, j);
                c->everts[2 * e + 1] = fan_vid(n, G, s, i, j + 1);
                c->edir[e] = (s + 1) % n;
            }
    }
}

static int fan_build(fan_cage *c, int n, int G) {
    memset(c, 0, sizeof *c);
    c->n = n;
    c->G = G;
    c->nv = 1 + n * G * (G + 1);
    c->nf = n * G * G;
    c->ne = n * (2 * G * G + G);
    c->pos = malloc(sizeof(double) * 3 * (size_t)c->nv);
    c->fsize = malloc(sizeof(int32_t) * (size_t)c->nf);
    c->fverts = malloc(sizeof(int32_t) * 4 * (size_t)c->nf);
    c->everts = malloc(sizeof(int32_t) * 2 * (size_t)c->ne);
    c->edir = malloc(sizeof(int32_t) * (size_t)c->ne);
    if (!c->pos || !c->fsize || !c->fverts || !c->everts || !c->edir) {
        fan_free(c);
        return -1;
    }
    fan_positions(c);
    fan_topology(c);
    return 0;
}

/* The cage with spoke intervals d as a mesh. */
static ccn_status fan_mesh(const fan_cage *c, const double *d, ccn_mesh **out, ccn_error *err) {
    double *k = malloc(sizeof(double) * (size_t)c->ne);
    if (!k) {
        err->status = CCN_ERR_MEMORY;
        snprintf(err->message, sizeof err->message, "out of memory");
        return CCN_ERR_MEMORY;
    }
    for (int32_t e = 0; e < c->ne; e++) k[e] = d[c->edir[e]];
    ccn_cage cg = {.num_verts = c->nv, .num_faces = c->nf, .num_edges = c->ne,
                   .positions = c->pos, .face_sizes = c->fsize, .face_verts = c->fverts,
                   .edge_verts = c->everts, .edge_knots = k};
    ccn_status st = ccn_mesh_create(&cg, out, err);
    free(k);
    return st;
}

static ccn_status fail_memory(ccn_error *err) {
    err->status = CCN_ERR_MEMORY;
    err->element_kind = CCN_ELEM_NONE;
    err->element = -1;
    snprintf(err->message, sizeof err->message, "out of memory");
    return CCN_ERR_MEMORY;
}

/* ---- maxima ------------------------------------------------------------------------- */

typedef struct {
    int maxima;       /* face-local maxima at the last level counted */
    int fallbacks;    /* num_ev_fallbacks of the refined mesh */
    int nonfinite;    /* refined z that are NaN / Inf */
    int show;         /* input: print the maxima */
    int nlater;       /* counts at levels L+1 .. (--persist) of a failing case */
    signed char later[EXP_MAX_LATER];
    int32_t support;  /* vertices with z > EXP_ZMIN */
    double zsum, zmax;
} max_result;

/* Candidates (z > EXP_ZMIN) and the support statistics. */
static void support_stats(const double *pos, int32_t nv, unsigned char *flag, max_result *r) {
    for (int32_t v = 0; v < nv; v++) {
        double z = pos[3 * v + 2];
        r->nonfinite += !isfinite(z);
        flag[v] = z > EXP_ZMIN;
        if (!flag[v]) continue;
        r->support++;
        r->zsum += z;
        if (z > r->zmax) r->zmax = z;
    }
}

/* A face-local maximum is the unique argmax of every face around it: clears all other corners. */
static void clear_non_argmax(const double *pos, int32_t nf, const int32_t *fs, const int32_t *fv,
                             unsigned char *flag) {
    for (int32_t f = 0, k = 0; f < nf; k += fs[f], f++) {
        int32_t best = 0, tie = 0;
        for (int32_t a = 1; a < fs[f]; a++) {
            double za = pos[3 * fv[k + a] + 2], zb = pos[3 * fv[k + best] + 2];
            if (za > zb) { best = a; tie = 0; }
            else if (!(za < zb)) tie = 1; /* equal to the best so far (or NaN) */
        }
        for (int32_t a = 0; a < fs[f]; a++)
            if (a != best || tie) flag[fv[k + a]] = 0;
    }
}

/* Counts vertices whose z exceeds that of every vertex sharing a face with them (SPEC A11). */
static ccn_status count_maxima(const ccn_mesh *m, max_result *r, ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_info_get(m, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)in.num_faces);
    int32_t *fv = malloc(sizeof(int32_t) * (size_t)in.num_face_verts);
    unsigned char *flag = malloc((size_t)in.num_verts);
    if (!pos || !fs || !fv || !flag) {
        free(pos); free(fs); free(fv); free(flag);
        return fail_memory(err);
    }
    ccn_mesh_copy(m, pos, fs, fv, NULL, NULL);
    r->maxima = r->nonfinite = 0;
    r->support = 0;
    r->zsum = r->zmax = 0;
    r->fallbacks = in.num_ev_fallbacks;
    support_stats(pos, in.num_verts, flag, r);
    clear_non_argmax(pos, in.num_faces, fs, fv, flag);
    for (int32_t v = 0; v < in.num_verts; v++) {
        r->maxima += flag[v];
        if (flag[v] && r->show)
            printf("maximum: vertex %d x %.9g y %.9g z %.17g\n", (int)v, pos[3 * v],
                   pos[3 * v + 1], pos[3 * v + 2]);
    }
    free(pos); free(fs); free(fv); free(flag);
    return CCN_OK;
}

/* --start level1: the cage refined once (any scheme: NURSS), then z = 1 at the EV's vertex
 * point and 0 elsewhere (x, y kept); refining it applies the scheme's EV rules at every level. */
static ccn_status start_level1(const double *d, const fan_cage *c, ccn_mesh **out, ccn_error *err) {
    ccn_mesh *m0 = NULL;
    ccn_options o = {.scheme = CCN_SCHEME_NURSS, .threads = 1};
    ccn_status st = fan_mesh(c, d, &m0, err);
    if (!st) st = ccn_refine(m0, 1, &o, out, err);
    ccn_mesh_destroy(m0);
    if (st) return st;
    ccn_mesh_info in;
    ccn_mesh_info_get(*out, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    if (!pos) return fail_memory(err);
    ccn_mesh_copy(*out, pos, NULL, NULL, NULL, NULL);
    for (int32_t v = 0; v < in.num_verts; v++) pos[3 * v + 2] = 0.0;
    pos[3 * ((size_t)c->nf + (size_t)c->ne) + 2] = 1.0; /* vertex point of cage vertex 0 */
    st = ccn_mesh_set_positions(*out, pos, err);
    free(pos);
    return st;
}

static ccn_status refine_in_place(ccn_mesh **cur, int k, ccn_scheme scheme, ccn_error *err) {
    ccn_mesh *next = NULL;
    ccn_options o = {.scheme = scheme, .threads = 1}; /* cases run in parallel */
    ccn_status st = ccn_refine(*cur, k, &o, &next, err);
    ccn_mesh_destroy(*cur);
    *cur = next;
    return st;
}

/* Levels L+1 .. persist of a case with != 1 maximum at level L (cur is at level L). */
static ccn_status maxima_later(ccn_mesh **cur, const exp_args *a, max_result *r, ccn_error *err) {
    ccn_status st = CCN_OK;
    for (int l = a->levels; l < a->persist && !st && r->nlater < EXP_MAX_LATER; l++) {
        max_result t = {0};
        st = refine_in_place(cur, 1, a->scheme, err);
        if (!st) st = count_maxima(*cur, &t, err);
        if (!st) r->later[r->nlater++] = (signed char)(t.maxima > 127 ? 127 : t.maxima);
    }
    return st;
}

/* Refines the fan with intervals d a->levels levels and counts maxima at the last level, or at
 * every level 1..levels into per_level[] when per_level is not NULL; a case with != 1 maximum
 * is followed up to level a->persist. */
static ccn_status maxima_case(const fan_cage *c, const double *d, const exp_args *a,
                              int *per_level, max_result *r, ccn_error *err) {
    ccn_mesh *cur = NULL;
    ccn_status st = a->start ? start_level1(d, c, &cur, err) : fan_mesh(c, d, &cur, err);
    int step = per_level ? 1 : a->levels;
    for (int l = 0; l < a->levels && !st; l += step) {
        st = refine_in_place(&cur, step, a->scheme, err);
        if (!st && (per_level || l + step == a->levels)) st = count_maxima(cur, r, err);
        if (!st && per_level) per_level[l] = r->maxima;
    }
    if (!st && r->maxima != 1) st = maxima_later(&cur, a, r, err);
    ccn_mesh_destroy(cur);
    return st;
}

/* ---- charmap: topology helpers -------------------------------------------------------- */

typedef struct {
    int32_t nv, nf, ne;
    double *pos;
    int32_t *fv;       /* 4 * nf (all faces are quads after refinement) */
    int32_t *everts;   /* 2 * ne */
    int32_t *ostart;   /* nv + 1: outgoing half-edges (4 f + k) of each vertex */
    int32_t *out;
    double *eknot;     /* ne: ring intervals (quad_load_knots) */
    int32_t *vestart;  /* nv + 1: edges at each vertex (quad_load_knots) */
    int32_t *vedges;
} quad_mesh;

static void quad_free(quad_mesh *q) {
    free(q->pos); free(q->fv); free(q->everts); free(q->ostart); free(q->out);
    free(q->eknot); free(q->vestart); free(q->vedges);
    memset(q, 0, sizeof *q);
}

static int quad_index(quad_mesh *q) {
    q->ostart = calloc((size_t)q->nv + 1, sizeof(int32_t));
    q->out = malloc(sizeof(int32_t) * 4 * (size_t)q->nf);
    if (!q->ostart || !q->out) return -1;
    for (int32_t h = 0; h < 4 * q->nf; h++) q->ostart[q->fv[h] + 1]++;
    for (int32_t v = 0; v < q->nv; v++) q->ostart[v + 1] += q->ostart[v];
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)(q->nv ? q->nv : 1));
    if (!fill) return -1;
    memcpy(fill, q->ostart, sizeof(int32_t) * (size_t)q->nv);
    for (int32_t h = 0; h < 4 * q->nf; h++) q->out[fill[q->fv[h]]++] = h;
    free(fill);
    return 0;
}

/* Copies a mesh's positions, faces (must all be quads) and edges, and indexes half-edges. */
static int quad_load(const ccn_mesh *m, quad_mesh *q) {
    ccn_mesh_info in;
    ccn_mesh_info_get(m, &in);
    memset(q, 0, sizeof *q);
    if (in.num_face_verts != 4 * in.num_faces) return -1;
    q->nv = in.num_verts;
    q->nf = in.num_faces;
    q->ne = in.num_edges;
    q->pos = malloc(sizeof(double) * 3 * (size_t)q->nv);
    q->fv = malloc(sizeof(int32_t) * 4 * (size_t)q->nf);
    q->everts = malloc(sizeof(int32_t) * 2 * (size_t)q->ne);
    if (!q->pos || !q->fv || !q->everts) return -1;
    ccn_mesh_copy(m, q->pos, NULL, q->fv, q->everts, NULL);
    return quad_index(q);
}

/* quad_load plus the edge intervals and the edges at each vertex. */
static int quad_load_knots(const ccn_mesh *m, quad_mesh *q) {
    if (quad_load(m, q)) return -1;
    q->eknot = malloc(sizeof(double) * (size_t)(q->ne ? q->ne : 1));
    q->vestart = calloc((size_t)q->nv + 1, sizeof(int32_t));
    q->vedges = malloc(sizeof(int32_t) * 2 * (size_t)(q->ne ? q->ne : 1));
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)(q->nv ? q->nv : 1));
    if (!q->eknot || !q->vestart || !q->vedges || !fill) {
        free(fill);
        return -1;
    }
    ccn_mesh_copy(m, NULL, NULL, NULL, NULL, q->eknot);
    for (int32_t t = 0; t < 2 * q->ne; t++) q->vestart[q->everts[t] + 1]++;
    for (int32_t v = 0; v < q->nv; v++) q->vestart[v + 1] += q->vestart[v];
    memcpy(fill, q->vestart, sizeof(int32_t) * (size_t)q->nv);
    for (int32_t t = 0; t < 2 * q->ne; t++) q->vedges[fill[q->everts[t]]++] = t / 2;
    free(fill);
    return 0;
}

/* Interval of the edge a-b, or -1 if there is none. */
static double edge_knot(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t t = q->vestart[a]; t < q->vestart[a + 1]; t++) {
        int32_t e = q->vedges[t];
        if (q->everts[2 * e] + q->everts[2 * e + 1] - a == b) return q->eknot[e];
    }
    return -1;
}

/* Half-edge a -> b as 4 f + k (corner k of face f is a), or -1. */
static int32_t find_half(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t t = q->ostart[a]; t < q->ostart[a + 1]; t++) {
        int32_t h = q->out[t];
        if (q->fv[4 * (h / 4) + (h % 4 + 1) % 4] == b) return h;
    }
    return -1;
}

static int32_t corner(const quad_mesh *q, int32_t h, int k) {
    return q->fv[4 * (h / 4) + (h % 4 + k) % 4];
}

static int32_t find_edge(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t e = 0; e < q->ne; e++)
        if ((q->everts[2 * e] == a && q->everts[2 * e + 1] == b) ||
            (q->everts[2 * e] == b && q->everts[2 * e + 1] == a))
            return e;
    return -1;
}

/* Walks sector s's G x G grid from V = P[0][0] and P[1][0] = s0; P is (G+1)^2, P[i*(G+1)+j].
 * Column 0 through the faces' bottom edges P[0][j] -> P[1][j], columns i >= 1 through their
 * left edges P[i][j+1] -> P[i][j]. Returns 0, or -1 if the topology is not a quad grid. */
static int walk_sector(const quad_mesh *q, int32_t ev, int32_t s0, int G, int32_t *P) {
    int W = G + 1;
    for (int t = 0; t < W * W; t++) P[t] = -1;
    P[0] = ev;
    P[W] = s0;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            int32_t h = i == 0 ? find_half(q, P[j], P[W + j])
                               : find_half(q, P[i * W + j + 1], P[i * W + j]);
            if (h < 0) return -1;
            int32_t a = corner(q, h, 2), b = corner(q, h, 3);
            int32_t *pa = i == 0 ? &P[W + j + 1] : &P[(i + 1) * W + j];
            int32_t *pb = i == 0 ? &P[j + 1] : &P[(i + 1) * W + j + 1];
            if ((*pa >= 0 && *pa != a) || (*pb >= 0 && *pb != b)) return -1;
            *pa = a;
            *pb = b;
        }
    return 0;
}

/* The G-ring grid of valence-n EV `ev` whose spoke-0 neighbour is s0, in fan_vid order. */
static int ring_grid(const quad_mesh *q, int32_t ev, int32_t s0, int n, int G, int32_t *idx) {
    int W = G + 1;
    int32_t *P = malloc(sizeof(int32_t) * (size_t)(n + 1) * (size_t)(W * W));
    if (!P) return -1;
    int32_t spoke = s0, rc = 0;
    for (int s = 0; s <= n && !rc; s++) {
        int32_t *Ps = P + (size_t)s * W * W;
        rc = walk_sector(q, ev, spoke, s < n ? G : 1, Ps);
        if (rc || s == n) break;
        spoke = Ps[1];
        for (int i = 1; i <= G; i++)
            for (int j = 0; j <= G; j++) idx[fan_vid(n, G, s, i, j)] = Ps[i * W + j];
    }
    /* sector s's spoke s+1 must be sector s+1's spoke (so sector n is sector 0 again) */
    for (int s = 0; s < n && !rc; s++)
        for (int j = 1; j <= G; j++)
            if (P[(size_t)s * W * W + j] != idx[fan_vid(n, G, s + 1, j, 0)]) rc = -1;
    idx[0] = ev;
    free(P);
    return rc;
}

/* Refines m one level with `scheme`, following the EV and its spoke-0 neighbour: in the refined
 * mesh they are the vertex point of ev (nf + ne + ev) and the edge point of edge (ev, s0). */
static ccn_status track_refine(const ccn_mesh *m, ccn_scheme scheme, int32_t *ev, int32_t *s0,
                               ccn_mesh **out, ccn_error *err) {
    quad_mesh q;
    if (quad_load(m, &q)) {
        quad_free(&q);
        return fail_memory(err);
    }
    int32_t e = find_edge(&q, *ev, *s0);
    int32_t nf = q.nf, ne = q.ne;
    quad_free(&q);
    if (e < 0) {
        err->status = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "EV spoke edge not found");
        return CCN_ERR_INTERNAL;
    }
    ccn_options o = {.scheme = scheme, .threads = 1}; /* cases run in parallel */
    ccn_status st = ccn_refine(m, 1, &o, out, err);
    if (st) return st;
    *ev = nf + ne + *ev;
    *s0 = nf + e;
    return CCN_OK;
}

/* ---- charmap: the three-ring matrix ------------------------------------------------------ */

typedef struct {
    int spectrum, regular, injective, matrix_ok;  /* regular / injective: the limit surface */
    int net_regular, net_injective;               /* the same tests on control-net quads */
    int fallbacks, orient, wind_in, wind_out, bad_patches, undecided, crossings, defective;
    int net_orient, net_bad_quads;
    double mod[6];               /* |mu_1| .. |mu_6| */
    double mu2, mu3, im2;        /* real parts of mu2, mu3; |imag| of mu2 */
    double split, ratio, lam_err; /* |mu2-mu3|/|mu2|, |mu4|/|mu2|, max |mu2,3 - lambda_n| */
    double rowsum_err, m_err;    /* |row sum - 1|; 1-ring rows vs ccn_ev_matrix */
} cm_result;

typedef struct {
    int n, N;
    ccn_scheme scheme;
    ccn_mesh *L1;
    int32_t ev1, s01;
    int32_t *idx1, *idx2; /* 3-ring of L1 and of L1 refined once */
    int fallbacks;        /* num_ev_fallbacks of L1 refined once (the M of level 1) */
    double *A;            /* N x N row-major: fine 3-ring = A * coarse 3-ring */
} cm_ctx;

static void cm_free(cm_ctx *c) {
    ccn_mesh_destroy(c->L1);
    free(c->idx1); free(c->idx2); free(c->A);
}

static ccn_status ring_of(const ccn_mesh *m, int32_t ev, int32_t s0, int n, int32_t *idx,
                          ccn_error *err) {
    quad_mesh q;
    int rc = quad_load(m, &q) ? -2 : ring_grid(&q, ev, s0, n, 3, idx);
    quad_free(&q);
    if (rc == -2) return fail_memory(err);
    if (rc) {
        err->status = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "the EV's 3-ring is not a quad grid");
        return CCN_ERR_INTERNAL;
    }
    return CCN_OK;
}

/* Cage -> L1 and the 3-ring of L1. */
static ccn_status cm_setup(cm_ctx *c, const fan_cage *cage, const double *d, ccn_error *err) {
    ccn_mesh *m0 = NULL;
    c->N = 12 * c->n + 1;
    c->idx1 = malloc(sizeof(int32_t) * (size_t)c->N);
    c->idx2 = malloc(sizeof(int32_t) * (size_t)c->N);
    c->A = malloc(sizeof(double) * (size_t)c->N * (size_t)c->N);
    if (!c->idx1 || !c->idx2 || !c->A) return fail_memory(err);
    ccn_status st = fan_mesh(cage, d, &m0, err);
    c->ev1 = 0;
    c->s01 = fan_vid(c->n, 3, 0, 1, 0);
    if (!st) st = track_refine(m0, c->scheme, &c->ev1, &c->s01, &c->L1, err);
    ccn_mesh_destroy(m0);
    if (!st) st = ring_of(c->L1, c->ev1, c->s01, c->n, c->idx1, err);
    return st;
}

/* Columns c0 .. c0+2 of A: 3-ring point c0+k of L1 has coordinate k equal to 1. */
static ccn_status cm_columns(cm_ctx *c, int c0, double *pos, int32_t nv, ccn_error *err) {
    memset(pos, 0, sizeof(double) * 3 * (size_t)nv);
    for (int k = 0; k < 3 && c0 + k < c->N; k++) pos[3 * (size_t)c->idx1[c0 + k] + k] = 1.0;
    ccn_status st = ccn_mesh_set_positions(c->L1, pos, err);
    int32_t ev = c->ev1, s0 = c->s01;
    ccn_mesh *L2 = NULL;
    if (!st) st = track_refine(c->L1, c->scheme, &ev, &s0, &L2, err);
    if (!st && c0 == 0) st = ring_of(L2, ev, s0, c->n, c->idx2, err);
    if (!st) {
        ccn_mesh_info in;
        ccn_mesh_info_get(L2, &in);
        c->fallbacks = in.num_ev_fallbacks;
        double *p2 = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
        if (!p2) st = fail_memory(err);
        else {
            ccn_mesh_copy(L2, p2, NULL, NULL, NULL, NULL);
            for (int r = 0; r < c->N; r++)
                for (int k = 0; k < 3 && c0 + k < c->N; k++)
                    c->A[(size_t)r * c->N + c0 + k] = p2[3 * (size_t)c->idx2[r] + k];
            free(p2);
        }
    }
    ccn_mesh_destroy(L2);
    return st;
}

/* Row sums of A, and its 1-ring rows against ccn_ev_matrix (rows F_i, E_i, V of M are the
 * 3-ring points (i,1,1), (i,1,0), V; zero outside the 1-ring). */
static void cm_matrix_checks(const cm_ctx *c, const double *d, cm_result *r) {
    int n = c->n, N = c->N, sz = 2 * n + 1;
    r->rowsum_err = 0;
    for (int i = 0; i < N; i++) {
        double s = 0;
        for (int j = 0; j < N; j++) s += c->A[(size_t)i * N + j];
        r->rowsum_err = fmax(r->rowsum_err, fabs(s - 1.0));
    }
    double *M = malloc(sizeof(double) * (size_t)sz * (size_t)sz);
    int map[2 * EXP_MAX_N + 1];
    for (int i = 0; i < n; i++) {
        map[i] = fan_vid(n, 3, i, 1, 1);
        map[n + i] = fan_vid(n, 3, i, 1, 0);
    }
    map[2 * n] = 0;
    r->m_err = INFINITY;
    if (!M || ccn_ev_matrix(n, d, c->scheme, M, NULL, NULL)) {
        free(M);
        return;
    }
    r->m_err = 0;
    for (int i = 0; i < sz; i++) {
        double *row = c->A + (size_t)map[i] * N, e = 0, in1 = 0;
        for (int j = 0; j < sz; j++) {
            e = fmax(e, fabs(row[map[j]] - M[i * sz + j]));
            in1 += fabs(row[map[j]]);
        }
        double all = 0;
        for (int j = 0; j < N; j++) all += fabs(row[j]);
        r->m_err = fmax(r->m_err, fmax(e, all - in1));
    }
    free(M);
}

static ccn_status cm_matrix(cm_ctx *c, const double *d, cm_result *r, ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_info_get(c->L1, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    if (!pos) return fail_memory(err);
    ccn_status st = CCN_OK;
    for (int c0 = 0; c0 < c->N && !st; c0 += 3) st = cm_columns(c, c0, pos, in.num_verts, err);
    free(pos);
    if (st) return st;
    cm_matrix_checks(c, d, r);
    r->matrix_ok = r->rowsum_err <= 1e-12 && r->m_err <= 1e-12;
    return CCN_OK;
}

/* ---- charmap: spectrum ---------------------------------------------------------------- */

static double lambda_n(int n) {
    double cs = cos(2 * EXP_PI / n);
    return (5 + cs + sqrt((cs + 9) * (cs + 1))) / 16;
}

/* Indices of the eigenvalues by decreasing modulus (stable: conjugate pairs stay together). */
static void sort_by_modulus(const double *wr, const double *wi, int N, int *ord) {
    ord[0] = ord[1] = ord[2] = ord[3] = 0; /* N >= 6 */
    for (int i = 0; i < N; i++) ord[i] = i;
    for (int i = 1; i < N; i++) {
        int t = ord[i], j = i;
        double m = hypot(wr[t], wi[t]);
        while (j > 0 && hypot(wr[ord[j - 1]], wi[ord[j - 1]]) < m * (1 - 1e-13)) {
            ord[j] = ord[j - 1];
            j--;
        }
        ord[j] = t;
    }
}

/* x, y: an orthonormal basis of the (mu2, mu3) invariant subspace: the two eigenvectors, or
 * the real and imaginary parts of a complex pair's eigenvector. Returns -1 if degenerate. */
static int subdominant_plane(const double *vr, const double *wi, const int *ord, int N,
                             double *x, double *y) {
    int a = ord[1], b = ord[2];
    if (wi[a] != 0) { /* complex pair: columns a (real part) and a+1 (imaginary part) */
        a = wi[a] > 0 ? a : a - 1;
        b = a + 1;
    }
    for (int i = 0; i < N; i++) {
        x[i] = vr[(size_t)i * N + a];
        y[i] = vr[(size_t)i * N + b];
    }
    double xx = 0, xy = 0, yy = 0;
    for (int i = 0; i < N; i++) xx += x[i] * x[i];
    if (!(xx > 0)) return -1;
    for (int i = 0; i < N; i++) x[i] /= sqrt(xx);
    for (int i = 0; i < N; i++) xy += x[i] * y[i];
    for (int i = 0; i < N; i++) y[i] -= xy * x[i];
    for (int i = 0; i < N; i++) yy += y[i] * y[i];
    if (!(yy > 1e-12)) return -1; /* the eigenvectors are (numerically) parallel: defective */
    for (int i = 0; i < N; i++) y[i] /= sqrt(yy);
    return 0;
}

static void spectrum_verdict(const cm_ctx *c, const double *wr, const double *wi,
                             const int *ord, cm_result *r) {
    int N = c->N;
    for (int k = 0; k < 6; k++) r->mod[k] = k < N ? hypot(wr[ord[k]], wi[ord[k]]) : 0;
    r->mu2 = wr[ord[1]];
    r->mu3 = wr[ord[2]];
    r->im2 = fabs(wi[ord[1]]);
    r->split = hypot(wr[ord[1]] - wr[ord[2]], wi[ord[1]] - wi[ord[2]]) / r->mod[1];
    r->ratio = r->mod[3] / r->mod[1];
    double lam = lambda_n(c->n);
    r->lam_err = fmax(fabs(r->mu2 - lam), fabs(r->mu3 - lam));
    int one = fabs(wr[ord[0]] - 1) <= 1e-9 && wi[ord[0]] == 0 && r->mod[1] < 1 - 1e-9;
    int dbl = r->split <= 1e-7 && r->im2 <= 1e-7 * r->mod[1] && r->mu2 > 0;
    int sub = r->mod[3] < r->mod[1] * (1 - 1e-9);
    int lam_ok = c->scheme != CCN_SCHEME_EIGEN || r->fallbacks || r->lam_err <= 1e-9;
    r->spectrum = one && dbl && sub && lam_ok && !r->defective;
}

static ccn_status cm_spectrum(cm_ctx *c, cm_result *r, double *x, double *y, ccn_error *err) {
    int N = c->N;
    double *A = malloc(sizeof(double) * (size_t)N * N), *vr = malloc(sizeof(double) * (size_t)N * N);
    double *wr = malloc(sizeof(double) * (size_t)N), *wi = malloc(sizeof(double) * (size_t)N);
    int *ord = malloc(sizeof(int) * (size_t)N);
    ccn_status st = CCN_OK;
    if (!A || !vr || !wr || !wi || !ord || N < 6) st = fail_memory(err);
    else {
        memcpy(A, c->A, sizeof(double) * (size_t)N * N);
        lapack_int info = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'V', N, A, N, wr, wi, NULL, 1, vr, N);
        if (info != 0) {
            err->status = st = CCN_ERR_INTERNAL;
            snprintf(err->message, sizeof err->message, "dgeev failed (info %d)", (int)info);
        } else {
            sort_by_modulus(wr, wi, N, ord);
            r->defective = subdominant_plane(vr, wi, ord, N, x, y) != 0;
            spectrum_verdict(c, wr, wi, ord, r);
        }
    }
    free(A); free(vr); free(wr); free(wi); free(ord);
    return st;
}

/* ---- charmap: regularity and injectivity of the characteristic ring ------------------- */

static double orient2(const double *a, const double *b, const double *c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Closed segments ab and cd intersect (touching and collinear overlap count). */
static int seg_meet(const double *a, const double *b, const double *c, const double *d) {
    if (fmax(a[0], b[0]) < fmin(c[0], d[0]) || fmax(c[0], d[0]) < fmin(a[0], b[0]) ||
        fmax(a[1], b[1]) < fmin(c[1], d[1]) || fmax(c[1], d[1]) < fmin(a[1], b[1]))
        return 0;
    double o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a), o4 = orient2(c, d, b);
    return ((o1 <= 0 && o2 >= 0) || (o1 >= 0 && o2 <= 0)) &&
           ((o3 <= 0 && o4 >= 0) || (o3 >= 0 && o4 <= 0));
}

/* Winding number of the closed polygon pts[0..m-1] (xy pairs) around p; 99 if not integral. */
static int winding(const double *pts, int m, const double *p) {
    double sum = 0;
    for (int i = 0; i < m; i++) {
        const double *a = pts + 2 * i, *b = pts + 2 * ((i + 1) % m);
        double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
        sum += atan2(ax * by - ay * bx, ax * bx + ay * by);
    }
    double w = sum / (2 * EXP_PI);
    return fabs(w - round(w)) < 1e-6 ? (int)round(w) : 99;
}

typedef struct {
    int n, G;              /* valence, grid size per sector */
    const int32_t *idx;    /* fan_vid(n, G, ...) -> vertex */
    const quad_mesh *q;    /* positions, edges, intervals */
} char_grid;

/* Grid vertex (s, i, j); i < 0 or j < 0 reach into the neighbouring sectors:
 * (s, -i, j) = (s+1, j, i) and (s, i, -j) = (s-1, j, i). */
static int32_t grid_vertex(const char_grid *g, int s, int i, int j) {
    if (i < 0) return grid_vertex(g, s + 1, j, -i);
    if (j < 0) return grid_vertex(g, s + g->n - 1, -j, i);
    return g->idx[fan_vid(g->n, g->G, s, i, j)];
}

static const double *gp(const char_grid *g, int s, int i, int j) {
    return g->q->pos + 3 * (size_t)grid_vertex(g, s, i, j);
}

/* -- control-net test: quads of rings R..2R, every corner triangle with one orientation -- */

static void annulus_quads(const char_grid *g, int R, cm_result *r) {
    r->net_orient = 0;
    r->net_bad_quads = 0;
    for (int s = 0; s < g->n; s++)
        for (int i = 0; i < 2 * R; i++)
            for (int j = 0; j < 2 * R; j++) {
                if (i < R && j < R) continue;
                const double *q[4] = {gp(g, s, i, j), gp(g, s, i + 1, j), gp(g, s, i + 1, j + 1),
                                      gp(g, s, i, j + 1)};
                int bad = 0;
                for (int k = 0; k < 4; k++) {
                    double o = orient2(q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
                    int sg = o > 0 ? 1 : o < 0 ? -1 : 0;
                    if (!r->net_orient) r->net_orient = sg;
                    bad |= sg == 0 || sg != r->net_orient;
                }
                r->net_bad_quads += bad;
            }
}

/* The ring-r polygon (2 r n points): per sector (s,r,0..r) then (s,r-1..1,r). */
static void ring_polygon(const char_grid *g, int r, double *pts) {
    int m = 0;
    for (int s = 0; s < g->n; s++) {
        for (int j = 0; j <= r; j++, m++) memcpy(pts + 2 * m, gp(g, s, r, j), 2 * sizeof(double));
        for (int i = r - 1; i >= 1; i--, m++) memcpy(pts + 2 * m, gp(g, s, i, r), 2 * sizeof(double));
    }
}

/* Pairs of non-adjacent edges of the two closed polygons (m1 + m2 points) that meet. */
static int polygon_crossings(const double *pts, int m1, int m2) {
    int m = m1 + m2, count = 0;
    for (int e = 0; e < m; e++) {
        int pe = e < m1 ? 0 : 1, base_e = pe ? m1 : 0, len_e = pe ? m2 : m1;
        int e0 = e, e1 = base_e + (e - base_e + 1) % len_e;
        for (int f = e + 1; f < m; f++) {
            int pf = f < m1 ? 0 : 1, base_f = pf ? m1 : 0, len_f = pf ? m2 : m1;
            int f0 = f, f1 = base_f + (f - base_f + 1) % len_f;
            if (pe == pf && (e1 == f0 || f1 == e0)) continue; /* neighbours share a vertex */
            count += seg_meet(pts + 2 * e0, pts + 2 * e1, pts + 2 * f0, pts + 2 * f1);
        }
    }
    return count;
}

/* Inner polygon pts[0..m1), outer pts[m1..m1+m2): both simple, disjoint, winding `orient`
 * around the origin (the EV's limit), the inner one inside the outer one. */
static int rings_injective(const double *pts, int m1, int m2, int orient, int *wind_in,
                           int *wind_out, int *crossings) {
    const double origin[2] = {0, 0};
    *wind_in = winding(pts, m1, origin);
    *wind_out = winding(pts + 2 * m1, m2, origin);
    int nested = winding(pts + 2 * m1, m2, pts) == orient;
    *crossings = polygon_crossings(pts, m1, m2);
    return *crossings == 0 && nested && *wind_in == orient && *wind_out == orient;
}

static int net_check(const char_grid *g, int R, cm_result *r) {
    annulus_quads(g, R, r);
    r->net_regular = r->net_bad_quads == 0 && r->net_orient != 0;
    int m1 = 2 * R * g->n, m2 = 4 * R * g->n;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    ring_polygon(g, R, pts);
    ring_polygon(g, 2 * R, pts + 2 * m1);
    int wi, wo, cr;
    r->net_injective = r->net_regular && rings_injective(pts, m1, m2, r->net_orient, &wi, &wo, &cr);
    free(pts);
    return 0;
}

/* -- surface test: the limit patches of the annulus, exact Bezier form of det J ------------ */

/* Bezier points of the cubic span of edge P0 P1 of the control polygon P_{-1..2} (p[0..3])
 * with knot intervals d_{-2..2} (d[0..4]; d_j on edge P_j P_{j+1}): the inner points divide
 * P0 P1 in the ratio d_{-1} : d_0 : d_1, the ends divide the neighbouring thirds d_{-1} : d_0
 * and d_0 : d_1 (C2 knot-interval form, Sederberg et al. 1998). */
static void span_bezier(double p[4][2], const double d[5], double b[4][2]) {
    double s0 = d[0] + d[1] + d[2], s1 = d[1] + d[2] + d[3], s2 = d[2] + d[3] + d[4];
    for (int k = 0; k < 2; k++) {
        double rm = p[0][k] + (d[0] + d[1]) / s0 * (p[1][k] - p[0][k]);
        double l0 = p[1][k] + d[1] / s1 * (p[2][k] - p[1][k]);
        double r0 = p[1][k] + (d[1] + d[2]) / s1 * (p[2][k] - p[1][k]);
        double l1 = p[2][k] + d[2] / s2 * (p[3][k] - p[2][k]);
        b[0][k] = (d[2] * rm + d[1] * l0) / (d[1] + d[2]);
        b[1][k] = l0;
        b[2][k] = r0;
        b[3][k] = (d[3] * r0 + d[2] * l1) / (d[2] + d[3]);
    }
}

/* Bicubic Bezier net B[a][b] (a along i, b along j) of the limit patch of face (s, i, j). */
static int face_patch(const char_grid *g, int s, int i, int j, double B[4][4][2]) {
    double du[5], dv[5], P[4][2], T[4][4][2], b[4][2];
    for (int t = 0; t < 5; t++) {
        du[t] = edge_knot(g->q, grid_vertex(g, s, i - 2 + t, j), grid_vertex(g, s, i - 1 + t, j));
        dv[t] = edge_knot(g->q, grid_vertex(g, s, i, j - 2 + t), grid_vertex(g, s, i, j - 1 + t));
        if (!(du[t] > 0) || !(dv[t] > 0)) return -1;
    }
    for (int row = 0; row < 4; row++) { /* along i, rows j-1 .. j+2 */
        for (int a = 0; a < 4; a++) memcpy(P[a], gp(g, s, i - 1 + a, j - 1 + row), sizeof P[a]);
        span_bezier(P, du, b);
        for (int a = 0; a < 4; a++) memcpy(T[a][row], b[a], sizeof b[a]);
    }
    for (int a = 0; a < 4; a++) {
        span_bezier(T[a], dv, b);
        memcpy(B[a], b, sizeof b);
    }
    return 0;
}

/* Bernstein coefficients (bidegree 5, 5) of det J = x_u y_v - y_u x_v (up to a positive
 * factor): x_u has bidegree (2, 3), x_v (3, 2); B^m_i B^n_j = C(m,i) C(n,j) / C(m+n,i+j) B^{m+n}_{i+j}. */
static void jacobian_bezier(double B[4][4][2], double J[6][6]) {
    static const double C2[3] = {1, 2, 1}, C3[4] = {1, 3, 3, 1}, C5[6] = {1, 5, 10, 10, 5, 1};
    memset(J, 0, sizeof(double) * 36);
    for (int a1 = 0; a1 < 3; a1++)
        for (int b1 = 0; b1 < 4; b1++) {
            double ux = B[a1 + 1][b1][0] - B[a1][b1][0], uy = B[a1 + 1][b1][1] - B[a1][b1][1];
            for (int a2 = 0; a2 < 4; a2++)
                for (int b2 = 0; b2 < 3; b2++) {
                    double vx = B[a2][b2 + 1][0] - B[a2][b2][0], vy = B[a2][b2 + 1][1] - B[a2][b2][1];
                    double w = C2[a1] * C3[a2] / C5[a1 + a2] * C3[b1] * C2[b2] / C5[b1 + b2];
                    J[a1 + a2][b1 + b2] += w * (ux * vy - uy * vx);
                }
        }
}

/* Halves a bidegree-(5,5) Bernstein polynomial at u = 1/2 (dir 0) or v = 1/2 (dir 1). */
static void bern_split(double J[6][6], int dir, double lo[6][6], double hi[6][6]) {
    for (int l = 0; l < 6; l++) {
        double c[6];
        for (int t = 0; t < 6; t++) c[t] = dir ? J[l][t] : J[t][l];
        for (int r = 0; r < 6; r++) {
            double *L = dir ? &lo[l][r] : &lo[r][l], *H = dir ? &hi[l][5 - r] : &hi[5 - r][l];
            *L = c[0];
            *H = c[5 - r];
            for (int t = 0; t < 5 - r; t++) c[t] = 0.5 * (c[t] + c[t + 1]);
        }
    }
}

/* 1: every coefficient has sign sg (det J has sign sg on the whole patch); -1: a corner value
 * (an actual value of det J) has the wrong sign or is zero; 0: undecided after `depth` splits. */
static int jacobian_sign(double J[6][6], int sg, int depth) {
    const double corner[4] = {J[0][0], J[5][0], J[0][5], J[5][5]};
    for (int k = 0; k < 4; k++)
        if (!(sg * corner[k] > 0)) return -1;
    int all = 1;
    for (int a = 0; a < 6 && all; a++)
        for (int b = 0; b < 6 && all; b++) all = sg * J[a][b] > 0;
    if (all) return 1;
    if (depth == 0) return 0;
    double U0[6][6], U1[6][6], Q[4][6][6];
    bern_split(J, 0, U0, U1);
    bern_split(U0, 1, Q[0], Q[1]);
    bern_split(U1, 1, Q[2], Q[3]);
    int res = 1;
    for (int k = 0; k < 4 && res != -1; k++) {
        int t = jacobian_sign(Q[k], sg, depth - 1);
        res = t < res ? t : res;
    }
    return res;
}

/* Regularity of the limit patches of rings R..2R. */
static int surface_patches(const char_grid *g, int R, cm_result *r) {
    r->orient = 0;
    for (int s = 0; s < g->n; s++)
        for (int i = 0; i < 2 * R; i++)
            for (int j = 0; j < 2 * R; j++) {
                if (i < R && j < R) continue;
                double B[4][4][2], J[6][6];
                if (face_patch(g, s, i, j, B)) return -1;
                jacobian_bezier(B, J);
                if (!r->orient) r->orient = J[0][0] > 0 ? 1 : J[0][0] < 0 ? -1 : 0;
                int t = r->orient ? jacobian_sign(J, r->orient, 6) : -1;
                r->bad_patches += t < 0;
                r->undecided += t == 0;
            }
    return 0;
}

static void bezier3(double b[4][2], double t, double out[2]) {
    for (int k = 0; k < 2; k++) {
        double u = 1 - t, a = b[0][k] * u + b[1][k] * t, c = b[1][k] * u + b[2][k] * t,
               e = b[2][k] * u + b[3][k] * t;
        a = a * u + c * t;
        c = c * u + e * t;
        out[k] = a * u + c * t;
    }
}

/* The limit curve of parameter ring r, m samples per face side, in ring_polygon's order. */
static int ring_curve(const char_grid *g, int r, int m, double *pts) {
    int k = 0;
    for (int s = 0; s < g->n; s++) {
        double B[4][4][2], c[4][2];
        for (int j = 0; j < r; j++) { /* side i = r, from j to j+1: u = 0 of face (s, r, j) */
            if (face_patch(g, s, r, j, B)) return -1;
            for (int b = 0; b < 4; b++) memcpy(c[b], B[0][b], sizeof c[b]);
            for (int l = 0; l < m; l++, k++) bezier3(c, (double)l / m, pts + 2 * k);
        }
        for (int i = r - 1; i >= 0; i--) { /* side j = r, from i+1 to i: v = 0 of face (s, i, r) */
            if (face_patch(g, s, i, r, B)) return -1;
            for (int a = 0; a < 4; a++) memcpy(c[a], B[a][0], sizeof c[a]);
            for (int l = 0; l < m; l++, k++) bezier3(c, 1.0 - (double)l / m, pts + 2 * k);
        }
    }
    return 0;
}

#define EXP_CURVE_SAMPLES 8

static int surface_check(const char_grid *g, int R, cm_result *r) {
    if (surface_patches(g, R, r)) return -1;
    r->regular = r->bad_patches == 0 && r->undecided == 0 && r->orient != 0;
    int m1 = 2 * R * g->n * EXP_CURVE_SAMPLES, m2 = 2 * m1;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    int rc = ring_curve(g, R, EXP_CURVE_SAMPLES, pts) || ring_curve(g, 2 * R, EXP_CURVE_SAMPLES, pts + 2 * m1);
    if (!rc)
        r->injective = r->regular && rings_injective(pts, m1, m2, r->orient, &r->wind_in,
                                                     &r->wind_out, &r->crossings);
    free(pts);
    return rc ? -1 : 0;
}

/* The grid of G rings around the EV of mesh m, and `check` on it. */
static ccn_status grid_check(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                             int (*check)(const char_grid *, int, cm_result *), cm_result *r,
                             ccn_error *err) {
    quad_mesh q = {0};
    ccn_status st = CCN_OK;
    int32_t *idx = malloc(sizeof(int32_t) * (size_t)(1 + n * G * (G + 1)));
    if (!idx || quad_load_knots(m, &q)) st = fail_memory(err);
    if (!st && ring_grid(&q, ev, s0, n, G, idx)) {
        err->status = st = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "characteristic net is not a quad grid");
    }
    char_grid g = {n, G, idx, &q};
    if (!st && check(&g, R, r)) {
        err->status = st = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "characteristic ring check failed");
    }
    quad_free(&q);
    free(idx);
    return st;
}

#define EXP_SURFACE_LEVEL 2 /* the limit-surface test uses rings 2..4 of level 2 */

/* Places the characteristic net (x, y, 0) on L1's 3-ring and refines it k levels. After level l
 * rings <= 2^(l+1) + 1 depend on the 3-ring only. Level 2: the limit patches of rings R = 2 to
 * 2R (control points up to ring 2R + 2 = 6 <= 9); level k: the control-net quads of rings
 * R = 2^(k-1) to 2R. */
static ccn_status cm_charring(cm_ctx *c, int k, const double *x, const double *y, cm_result *r,
                              ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_info_get(c->L1, &in);
    double *pos = calloc(3 * (size_t)in.num_verts, sizeof(double));
    if (!pos) return fail_memory(err);
    for (int t = 0; t < c->N; t++) {
        pos[3 * (size_t)c->idx1[t]] = x[t];
        pos[3 * (size_t)c->idx1[t] + 1] = y[t];
    }
    ccn_status st = ccn_mesh_set_positions(c->L1, pos, err);
    free(pos);
    ccn_mesh *cur = NULL, *next = NULL;
    int32_t ev = c->ev1, s0 = c->s01;
    for (int l = 1; l <= k && !st; l++) {
        next = NULL;
        st = track_refine(l > 1 ? cur : c->L1, c->scheme, &ev, &s0, &next, err);
        ccn_mesh_destroy(cur);
        cur = next;
        if (!st && l == EXP_SURFACE_LEVEL)
            st = grid_check(cur, c->n, ev, s0, 7, 2, surface_check, r, err);
        if (!st && l == k)
            st = grid_check(cur, c->n, ev, s0, 1 << k, 1 << (k - 1), net_check, r, err);
    }
    ccn_mesh_destroy(cur);
    return st;
}

static ccn_status charmap_case(const fan_cage *cage, const double *d, ccn_scheme scheme, int k,
                               cm_result *r, ccn_error *err) {
    cm_ctx c = {.n = cage->n, .scheme = scheme};
    memset(r, 0, sizeof *r);
    double x[12 * EXP_MAX_N + 1], y[12 * EXP_MAX_N + 1];
    ccn_status st = cm_setup(&c, cage, d, err);
    if (!st) st = cm_matrix(&c, d, r, err);
    r->fallbacks = c.fallbacks;
    if (!st) st = cm_spectrum(&c, r, x, y, err);
    if (!st && !r->defective) st = cm_charring(&c, k, x, y, r, err);
    cm_free(&c);
    return st;
}

/* ---- running cases on threads ----------------------------------------------------------- */

typedef struct {
    const exp_args *a;
    const fan_cage *cages; /* one per valence slot */
    atomic_long next;
    max_result *mres;
    cm_result *cres;
    unsigned char *status; /* ccn_status per case */
} exp_run;

static void run_case(exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = case_setup(a, i, d);
    const fan_cage *c = &run->cages[valence_slot(a, n)];
    ccn_error err;
    ccn_status st;
    if (a->kind == EXP_MAXIMA) st = maxima_case(c, d, a, NULL, &run->mres[i], &err);
    else st = charmap_case(c, d, a->scheme, a->charlevels, &run->cres[i], &err);
    run->status[i] = (unsigned char)st;
}

static void *worker(void *p) {
    exp_run *run = p;
    for (;;) {
        long i0 = atomic_fetch_add(&run->next, EXP_CHUNK);
        if (i0 >= run->a->cases) break;
        for (long i = i0; i < i0 + EXP_CHUNK && i < run->a->cases; i++) run_case(run, i);
    }
    return NULL;
}

static int run_all(exp_run *run) {
    int T = run->a->threads;
    pthread_t *th = malloc(sizeof(pthread_t) * (size_t)T);
    if (!th) return -1;
    atomic_init(&run->next, 0);
    int started = 0;
    for (; started < T; started++)
        if (pthread_create(&th[started], NULL, worker, run)) break;
    if (started == 0) worker(run);
    for (int t = 0; t < started; t++) pthread_join(th[t], NULL);
    free(th);
    return 0;
}

/* ---- reports ------------------------------------------------------------------------------ */

static void print_intervals(const double *d, int n) {
    for (int s = 0; s < n; s++) printf("%s%.17g", s ? "," : "", d[s]);
}

static const char *scheme_name(ccn_scheme s) {
    return s == CCN_SCHEME_EIGEN ? "eigen" : s == CCN_SCHEME_NURSS ? "nurss" : "cc";
}

static void print_header(const exp_args *a, const char *what) {
    printf("ccnurbs experiment %s: scheme %s", what, scheme_name(a->scheme));
    if (a->kind == EXP_MAXIMA) printf(", levels %d, rings %d, start %s", a->levels, a->rings,
                                      a->start ? "level1" : "cage");
    else printf(", charlevels %d", a->charlevels);
    if (a->nknots) {
        printf(", knots ");
        print_intervals(a->knots, a->nknots);
    } else {
        printf(", dist %s [%g, 1], valences", a->dist_log ? "loguniform" : "uniform", a->lo);
        for (int i = 0; i < a->nval; i++) printf("%s%d", i ? "," : " ", a->val[i]);
        printf(", seed %llu, offset %ld", (unsigned long long)a->seed, a->offset);
    }
    printf(", threads %d\n", a->threads);
}

/* " [levels L+1..P: 1 1 2]" for a failing case followed by --persist. */
static void print_later(const exp_args *a, const max_result *r) {
    if (!r->nlater) return;
    printf(" [levels %d..%d:", a->levels + 1, a->levels + r->nlater);
    for (int l = 0; l < r->nlater; l++) printf(" %d", r->later[l]);
    printf("]");
}

static void print_error_case(const exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = case_setup(a, i, d);
    printf("error case %ld valence %d intervals ", a->offset + i, n);
    print_intervals(d, n);
    printf(": %s\n", ccn_status_name((ccn_status)run->status[i]));
}

typedef struct {
    long single, fail, persistent, errors, fb_cases, fb_total, nonfinite;
    long vfail[EXP_MAX_VALS], vcases[EXP_MAX_VALS];
} max_totals;

static void maxima_fail_line(const exp_run *run, long i) {
    const max_result *r = &run->mres[i];
    double d[EXP_MAX_N];
    int n = case_setup(run->a, i, d);
    printf("fail case %ld valence %d maxima %d intervals ", run->a->offset + i, n, r->maxima);
    print_intervals(d, n);
    print_later(run->a, r);
    printf("\n");
}

/* Tallies the cases and lists the first --list failures. */
static void maxima_tally(const exp_run *run, max_totals *t) {
    const exp_args *a = run->a;
    memset(t, 0, sizeof *t);
    for (long i = 0; i < a->cases; i++) {
        const max_result *r = &run->mres[i];
        if (run->status[i]) { t->errors++; continue; }
        int slot = (int)((a->offset + i) % a->nval);
        t->vcases[slot]++;
        t->fb_cases += r->fallbacks > 0;
        t->fb_total += r->fallbacks;
        t->nonfinite += r->nonfinite > 0;
        if (r->maxima == 1 && !r->nonfinite) { t->single++; continue; }
        t->vfail[slot]++;
        t->persistent += r->nonfinite || !r->nlater || r->later[r->nlater - 1] != 1;
        if (t->fail++ < a->list) maxima_fail_line(run, i);
    }
    if (t->fail > a->list) printf("(%ld more failures not listed)\n", t->fail - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
}

static long maxima_report(const exp_run *run) {
    const exp_args *a = run->a;
    max_totals t;
    maxima_tally(run, &t);
    double pc = 100.0 / (double)a->cases;
    printf("cases: %ld\n", a->cases);
    printf("single maximum: %ld (%.4f%%)\n", t.single, pc * (double)t.single);
    printf("failures: %ld\n", t.fail);
    printf("failures by valence:");
    for (int v = 0; v < a->nval; v++) printf(" %d:%ld/%ld", a->val[v], t.vfail[v], t.vcases[v]);
    printf("\n");
    if (a->persist > a->levels)
        printf("persistent (!= 1 maximum also at level %d): %ld; single maximum at level %d or "
               "by level %d: %ld (%.4f%%)\n", a->persist, t.persistent, a->levels, a->persist,
               a->cases - t.errors - t.persistent, pc * (double)(a->cases - t.errors - t.persistent));
    printf("non-finite: %ld\n", t.nonfinite);
    printf("fallbacks: %ld cases (%ld EV matrices)\n", t.fb_cases, t.fb_total);
    printf("errors: %ld\n", t.errors);
    return t.errors;
}

static int cm_pass(const cm_result *r) {
    return r->spectrum && r->regular && r->injective && r->matrix_ok;
}

static void cm_fail_line(const exp_run *run, long i, const char *tag) {
    const cm_result *r = &run->cres[i];
    double d[EXP_MAX_N];
    int n = case_setup(run->a, i, d);
    printf("%s case %ld valence %d%s%s%s%s%s intervals ", tag, run->a->offset + i, n,
           r->spectrum ? "" : " spectrum", r->regular ? "" : " regularity",
           r->injective ? "" : " injectivity", r->matrix_ok ? "" : " matrix",
           r->net_regular && r->net_injective ? "" : " (net)");
    print_intervals(d, n);
    printf(" |mu|=%.6g,%.6g,%.6g,%.6g split %.2g im %.2g |mu4|/|mu2| %.6g%s fallbacks %d;"
           " surface: bad patches %d undecided %d crossings %d winding %d,%d;"
           " net: bad quads %d%s\n", r->mod[0], r->mod[1], r->mod[2], r->mod[3], r->split,
           r->im2, r->ratio, r->defective ? " defective" : "", r->fallbacks, r->bad_patches,
           r->undecided, r->crossings, r->wind_in, r->wind_out, r->net_bad_quads,
           r->net_injective ? "" : " not injective");
}

typedef struct {
    long spectrum, regular, injective, net_regular, net_injective, matrix, all, fb_cases, errors;
    double worst_ratio, worst_split, worst_lam, worst_rowsum, worst_m;
} cm_totals;

static void cm_accumulate(const exp_run *run, cm_totals *t) {
    memset(t, 0, sizeof *t);
    for (long i = 0; i < run->a->cases; i++) {
        const cm_result *r = &run->cres[i];
        if (run->status[i]) { t->errors++; continue; }
        t->spectrum += r->spectrum;
        t->regular += r->regular;
        t->injective += r->injective;
        t->net_regular += r->net_regular;
        t->net_injective += r->net_injective;
        t->matrix += r->matrix_ok;
        t->all += cm_pass(r);
        t->fb_cases += r->fallbacks > 0;
        t->worst_ratio = fmax(t->worst_ratio, r->ratio);
        t->worst_split = fmax(t->worst_split, r->split);
        if (!r->fallbacks) t->worst_lam = fmax(t->worst_lam, r->lam_err);
        t->worst_rowsum = fmax(t->worst_rowsum, r->rowsum_err);
        t->worst_m = fmax(t->worst_m, r->m_err);
    }
}

static void cm_list(const exp_run *run) {
    const exp_args *a = run->a;
    long listed = 0;
    for (long i = 0; i < a->cases; i++)
        if (!run->status[i] && (!cm_pass(&run->cres[i]) || a->nknots))
            if (listed++ < a->list) cm_fail_line(run, i, cm_pass(&run->cres[i]) ? "pass" : "fail");
    if (listed > a->list) printf("(%ld more failures not listed)\n", listed - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
}

static long charmap_report(const exp_run *run) {
    const exp_args *a = run->a;
    cm_list(run);
    cm_totals t;
    cm_accumulate(run, &t);
    printf("cases: %ld\n", a->cases);
    printf("matrix ok: %ld (max |row sum - 1| %.3g, max 1-ring vs ccn_ev_matrix %.3g)\n",
           t.matrix, t.worst_rowsum, t.worst_m);
    printf("spectrum ok: %ld (max |mu2-mu3|/|mu2| %.3g, max |mu4|/|mu2| %.6g, "
           "max |mu2,3 - lambda_n| %.3g)\n", t.spectrum, t.worst_split, t.worst_ratio, t.worst_lam);
    printf("regular: %ld (limit surface: Bezier coefficients of det J, rings 2..4 of level 2)\n",
           t.regular);
    printf("injective: %ld\n", t.injective);
    printf("net regular: %ld (control-net quads, rings %d..%d of level %d)\n", t.net_regular,
           1 << (a->charlevels - 1), 1 << a->charlevels, a->charlevels);
    printf("net injective: %ld\n", t.net_injective);
    printf("all pass: %ld\n", t.all);
    printf("failures: %ld\n", a->cases - t.errors - t.all);
    printf("fallbacks: %ld cases\n", t.fb_cases);
    printf("errors: %ld\n", t.errors);
    return t.errors;
}

/* --knots for maxima: counts per level 1..L and the z statistics (rings-independence check). */
static int maxima_knots(const exp_run *run) {
    const exp_args *a = run->a;
    int per[16];
    max_result r = {.show = 1};
    ccn_error err;
    if (maxima_case(&run->cages[0], a->knots, a, per, &r, &err))
        return ccn_cli_error("experiment", &err);
    printf("maxima per level 1..%d:", a->levels);
    for (int l = 0; l < a->levels; l++) printf(" %d", per[l]);
    print_later(a, &r);
    printf("\nlevel %d: support %d vertices, sum z %.12g, max z %.15g, fallbacks %d\n", a->levels,
           (int)r.support, r.zsum, r.zmax, r.fallbacks);
    printf("cases: 1\nsingle maximum: %d\nfailures: %d\n", r.maxima == 1, r.maxima != 1);
    return 0;
}

/* ---- entry point ---------------------------------------------------------------------------- */

static int build_cages(const exp_args *a, fan_cage *cages) {
    int G = a->kind == EXP_MAXIMA ? (a->start ? (a->rings + 1) / 2 : a->rings) : 3;
    if (a->nknots) return fan_build(&cages[0], a->nknots, G);
    for (int i = 0; i < a->nval; i++)
        if (fan_build(&cages[i], a->val[i], G)) return -1;
    return 0;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int experiment(const exp_args *a) {
    fan_cage cages[EXP_MAX_VALS];
    memset(cages, 0, sizeof cages);
    exp_run run = {.a = a, .cages = cages};
    run.status = calloc((size_t)a->cases, 1);
    if (a->kind == EXP_MAXIMA) run.mres = calloc((size_t)a->cases, sizeof(max_result));
    else run.cres = calloc((size_t)a->cases, sizeof(cm_result));
    int rc = 2;
    double t0 = now_seconds();
    print_header(a, a->kind == EXP_MAXIMA ? "maxima" : "charmap");
    fflush(stdout);
    if (!run.status || !(run.mres || run.cres) || build_cages(a, cages)) {
        fprintf(stderr, "ccnurbs experiment: out of memory\n");
    } else if (a->kind == EXP_MAXIMA && a->nknots) {
        rc = maxima_knots(&run);
    } else if (run_all(&run) == 0) {
        long errors = a->kind == EXP_MAXIMA ? maxima_report(&run) : charmap_report(&run);
        rc = errors ? 1 : 0;
    }
    if (rc != 2) printf("time: %.3f s\n", now_seconds() - t0);
    for (int i = 0; i < EXP_MAX_VALS; i++) fan_free(&cages[i]);
    free(run.status); free(run.mres); free(run.cres);
    return rc;
}

/* Every case allocates and frees the same large blocks; by default glibc serves them with
 * mmap and unmaps them on free, and the page faults double the run time. */
static void keep_freed_memory(void) {
#if defined(M_MMAP_THRESHOLD) && defined(M_TRIM_THRESHOLD)
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

int ccn_cmd_experiment(int argc, char **argv) {
    exp_args a;
    keep_freed_memory();
    if (argc < 2) return exp_usage();
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        exp_usage();
        return 0;
    }
    if (parse_args(argc, argv, &a)) return exp_usage();
    if (a.kind == EXP_MAXIMA && a.levels < 1) {
        fprintf(stderr, "ccnurbs experiment: --levels must be >= 1\n");
        return 2;
    }
    return experiment(&a);
}
