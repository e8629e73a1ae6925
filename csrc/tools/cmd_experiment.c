/* ccnurbs experiment: the numerical experiments of Li, Finnigan, Sederberg 2016, section 7.
 *
 *   maxima   the blending function of an extraordinary vertex (EV) with random spoke intervals
 *            has exactly one local maximum after L refinements (SPEC 3.2, DESIGN 4.3);
 *   charmap  the (12n+1) x (12n+1) three-ring refinement matrix has the spectrum
 *            1 > mu2 = mu3 > |mu4| and the characteristic map is regular and injective.
 *
 * The cage ("G-ring fan", G = 3 unless --rings): valence-n centre vertex V, n sectors, sector s
 * a G x G quad grid between spoke s (angle 2 pi s / n) and spoke s+1. Grid point (s, i, j),
 * 0 <= i, j <= G, sits at i u_s + j u_{s+1}; (s, 0, j) is (s+1, j, 0) and (s, 0, 0) is V.
 * Vertex numbering (fan_vid): V = 0, then per sector the points i = 1..G, j = 0..G, i.e.
 * 1 + s G (G+1) + (i-1)(G+1) + j; for G = 3 that is 12n+1 points, 9n faces, 21n edges. Every
 * edge parallel to spoke s carries d_s (SPEC 3.2), so opposite edges of every quad agree and
 * the interval beyond every spoke end is the spoke's own (e_s = d_s, also at level 0).
 *
 * Why three rings are exact (maxima): z = 1 at V, 0 elsewhere. The blending function's control
 * points at level k are non-zero only strictly inside fine ring 2 * 2^k (its support is the
 * coarse 2-ring). A point whose stencil differs from the infinite mesh's (boundary curve rules,
 * mirrored intervals) only reads points of fine rings >= 3 * 2^k - 2 >= 2 * 2^k (k >= 1; at
 * k = 0 it reads rings >= 1, all zero), and mirrored intervals equal the true ones here anyway.
 * So every refined z equals the infinite-mesh value. `--rings 4` checks this numerically (the
 * test script compares the two).
 *
 * Three-ring matrix (charmap): the cage is refined once (level 0 -> 1 uses NURSS rules at the EV
 * for every scheme, DESIGN 4.3), giving a level-1 mesh L1 whose intervals are again d_s (halved,
 * then normalised), so the matrix of L1 -> L2 is the stationary one. Its 3-ring is found through
 * topology (ring_grid): V1 = the vertex point of V (index nf + ne + 0 in L1, ccnurbs.h order)
 * and its spoke-0 neighbour = the edge point of the cage edge (V, (0,1,0)) (index nf + e); the
 * grid of each sector is then walked face by face through directed half-edges. The same walk
 * on L2 gives the fine 3-ring in the same order. Column c of the matrix is the refined 3-ring
 * when 3-ring point c of L1 is 1 and all else 0 (three columns per refine call, one per
 * coordinate). The characteristic net (x = eigenvector of mu2, y = of mu3, orthonormalised) is
 * placed on the 3-ring of L1 (everything else 0) and refined k levels; rings <= 2^(k+1) + 1 of
 * the result depend only on the 3-ring. The annulus of grid quads between rings R = 2^(k-1)
 * and 2R is checked: regular = every quad convex with one orientation (all four corner
 * triangles; positive Jacobian of its bilinear map); injective = in addition the ring-R and
 * ring-2R polygons are simple, do not cross each other, wind +-1 (the quad orientation) around
 * the EV's limit (the origin), and ring R lies inside ring 2R. For consistently oriented
 * triangles the number covering a point is winding(outer) - winding(inner) in {0, 1}.
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
#define EXP_PI 3.14159265358979323846

typedef enum { EXP_MAXIMA, EXP_CHARMAP } exp_kind;

typedef struct {
    exp_kind kind;
    ccn_scheme scheme;
    int levels, rings, threads, list, persist, charlevels, dist_log, start;
    long cases;
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
            "        [--threads T] [--rings G] [--list K] [--persist L2]\n"
            "  ccnurbs experiment charmap --cases N --seed S [--scheme eigen|nurss|cc] [--dist ...]\n"
            "        [--lo 1e-6] [--valences ...] [--knots ...] [--threads T] [--charlevels k] [--list K]\n");
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
    if (strcmp(opt, "--lo") == 0)
        return parse_double(val, &o->lo) || !(o->lo > 0 && o->lo <= 1) ? -1 : 0;
    struct { const char *name; long lo, hi; int *dst; } tab[] = {
        {"--levels", 0, 9, &o->levels},     {"--threads", 1, 256, &o->threads},
        {"--rings", 3, 8, &o->rings},       {"--list", 0, 1000000, &o->list},
        {"--persist", 0, 9, &o->persist},   {"--charlevels", 1, 7, &o->charlevels},
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

/* Valence and spoke intervals of case idx: a function of (seed, idx) only. */
static int case_setup(const exp_args *a, long idx, double *d) {
    if (a->nknots) {
        memcpy(d, a->knots, sizeof(double) * (size_t)a->nknots);
        return a->nknots;
    }
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
    int32_t support;  /* vertices with z > EXP_ZMIN */
    double zsum, zmax;
} max_result;

/* Counts vertices whose z exceeds that of every vertex sharing a face with them. */
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
    *r = (max_result){.fallbacks = in.num_ev_fallbacks};
    for (int32_t v = 0; v < in.num_verts; v++) {
        double z = pos[3 * v + 2];
        r->nonfinite += !isfinite(z);
        flag[v] = z > EXP_ZMIN;
        if (!flag[v]) continue;
        r->support++;
        r->zsum += z;
        if (z > r->zmax) r->zmax = z;
    }
    for (int32_t f = 0, k = 0; f < in.num_faces; k += fs[f], f++)
        for (int32_t a = 0; a < fs[f]; a++)
            for (int32_t b = 0; b < fs[f]; b++)
                if (a != b && !(pos[3 * fv[k + a] + 2] > pos[3 * fv[k + b] + 2])) flag[fv[k + a]] = 0;
    for (int32_t v = 0; v < in.num_verts; v++) r->maxima += flag[v];
    free(pos); free(fs); free(fv); free(flag);
    return CCN_OK;
}

/* start = 1: the blending function of the EV of the level-1 mesh (the cage refined once, then
 * z = 1 at the EV's vertex point and 0 elsewhere), so the EV rules of `scheme` act at every
 * level (SPEC 3's reference setup). Its intervals are again d_s per spoke direction. */
static ccn_status start_level1(const double *d, const fan_cage *c, ccn_mesh **out, ccn_error *err) {
    ccn_mesh *m0 = NULL;
    ccn_options o = {.scheme = CCN_SCHEME_NURSS};
    ccn_status st = fan_mesh(c, d, &m0, err);
    if (!st) st = ccn_refine(m0, 1, &o, out, err);
    ccn_mesh_destroy(m0);
    if (st) return st;
    ccn_mesh_info in;
    ccn_mesh_info_get(*out, &in);
    double *pos = calloc(3 * (size_t)in.num_verts, sizeof(double));
    if (!pos) return fail_memory(err);
    pos[3 * ((size_t)c->nf + (size_t)c->ne) + 2] = 1.0; /* vertex point of cage vertex 0 */
    st = ccn_mesh_set_positions(*out, pos, err);
    free(pos);
    return st;
}

/* Refines the fan with intervals d `levels` levels and counts maxima at the last level, or at
 * every level 1..levels into per_level[] when per_level is not NULL. */
static ccn_status maxima_case(const fan_cage *c, const double *d, ccn_scheme scheme, int levels,
                              int start, int *per_level, max_result *r, ccn_error *err) {
    ccn_mesh *cur = NULL, *next = NULL;
    ccn_options o = {.scheme = scheme};
    ccn_status st = start ? start_level1(d, c, &cur, err) : fan_mesh(c, d, &cur, err);
    if (st) {
        ccn_mesh_destroy(cur);
        return st;
    }
    int step = per_level ? 1 : levels;
    for (int l = 0; l < levels && !st; l += step) {
        st = ccn_refine(cur, step, &o, &next, err);
        ccn_mesh_destroy(cur);
        cur = next;
        next = NULL;
        if (!st && per_level) {
            st = count_maxima(cur, r, err);
            per_level[l] = r->maxima;
        }
    }
    if (!st && !per_level) st = count_maxima(cur, r, err);
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
} quad_mesh;

static void quad_free(quad_mesh *q) {
    free(q->pos); free(q->fv); free(q->everts); free(q->ostart); free(q->out);
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
    ccn_options o = {.scheme = scheme};
    ccn_status st = ccn_refine(m, 1, &o, out, err);
    if (st) return st;
    *ev = nf + ne + *ev;
    *s0 = nf + e;
    return CCN_OK;
}

/* ---- charmap: the three-ring matrix ------------------------------------------------------ */

typedef struct {
    int spectrum, regular, injective, matrix_ok;
    int fallbacks, orient, wind_in, wind_out, bad_quads, crossings, defective;
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
    int n, G;            /* valence, grid size per sector */
    const int32_t *idx;  /* fan_vid(n, G, ...) -> vertex */
    const double *pos;   /* 3 per vertex */
} char_grid;

static const double *gp(const char_grid *g, int s, int i, int j) {
    return g->pos + 3 * (size_t)g->idx[fan_vid(g->n, g->G, s, i, j)];
}

/* Quads of rings R..2R: every corner triangle must have the orientation of the first. */
static void annulus_quads(const char_grid *g, int R, cm_result *r) {
    r->orient = 0;
    r->bad_quads = 0;
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
                    if (!r->orient) r->orient = sg;
                    bad |= sg == 0 || sg != r->orient;
                }
                r->bad_quads += bad;
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

static int annulus_check(const char_grid *g, int R, cm_result *r) {
    annulus_quads(g, R, r);
    r->regular = r->bad_quads == 0 && r->orient != 0;
    int m1 = 2 * R * g->n, m2 = 4 * R * g->n;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    ring_polygon(g, R, pts);
    ring_polygon(g, 2 * R, pts + 2 * m1);
    const double origin[2] = {0, 0};
    r->wind_in = winding(pts, m1, origin);
    r->wind_out = winding(pts + 2 * m1, m2, origin);
    int nested = winding(pts + 2 * m1, m2, pts) == r->orient;
    r->crossings = polygon_crossings(pts, m1, m2);
    r->injective = r->regular && r->crossings == 0 && nested && r->wind_in == r->orient &&
                   r->wind_out == r->orient;
    free(pts);
    return 0;
}

/* Places the characteristic net (x, y, 0) on L1's 3-ring, refines k levels and checks the
 * annulus between rings R = 2^(k-1) and 2R. */
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
    for (int l = 0; l < k && !st; l++) {
        next = NULL;
        st = track_refine(l ? cur : c->L1, c->scheme, &ev, &s0, &next, err);
        ccn_mesh_destroy(cur);
        cur = next;
    }
    int R = 1 << (k - 1), G = 2 * R;
    quad_mesh q = {0};
    int32_t *idx = malloc(sizeof(int32_t) * (size_t)(1 + c->n * G * (G + 1)));
    if (!st && (!idx || quad_load(cur, &q))) st = fail_memory(err);
    if (!st && ring_grid(&q, ev, s0, c->n, G, idx)) {
        err->status = st = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "characteristic net is not a quad grid");
    }
    char_grid g = {c->n, G, idx, q.pos};
    if (!st && annulus_check(&g, R, r)) st = fail_memory(err);
    quad_free(&q);
    free(idx);
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
    if (a->kind == EXP_MAXIMA) st = maxima_case(c, d, a->scheme, a->levels, a->start, NULL, &run->mres[i], &err);
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
        printf(", seed %llu", (unsigned long long)a->seed);
    }
    printf(", threads %d\n", a->threads);
}

/* Per-level maxima of one failing case (--persist L2): "levels 1..L2: 1 1 2 ...". */
static void print_persist(const exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = case_setup(a, i, d), per[16];
    max_result r;
    ccn_error err;
    if (maxima_case(&run->cages[valence_slot(a, n)], d, a->scheme, a->persist, a->start, per, &r, &err)) {
        printf(" [levels: error]");
        return;
    }
    printf(" [levels 1..%d:", a->persist);
    for (int l = 0; l < a->persist; l++) printf(" %d", per[l]);
    printf("]");
}

static void print_error_case(const exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = case_setup(a, i, d);
    printf("error case %ld valence %d intervals ", i, n);
    print_intervals(d, n);
    printf(": %s\n", ccn_status_name((ccn_status)run->status[i]));
}

static long maxima_report(const exp_run *run) {
    const exp_args *a = run->a;
    long single = 0, fail = 0, errors = 0, fb_cases = 0, fb_total = 0, nonfin = 0, listed = 0;
    long vfail[EXP_MAX_VALS] = {0}, vcases[EXP_MAX_VALS] = {0};
    for (long i = 0; i < a->cases; i++) {
        const max_result *r = &run->mres[i];
        if (run->status[i]) { errors++; continue; }
        int slot = (int)(a->nknots ? 0 : i % a->nval);
        vcases[slot]++;
        fb_cases += r->fallbacks > 0;
        fb_total += r->fallbacks;
        nonfin += r->nonfinite > 0;
        if (r->maxima == 1 && !r->nonfinite) { single++; continue; }
        fail++;
        vfail[slot]++;
        if (listed++ >= a->list) continue;
        double d[EXP_MAX_N];
        int n = case_setup(a, i, d);
        printf("fail case %ld valence %d maxima %d intervals ", i, n, r->maxima);
        print_intervals(d, n);
        if (a->persist) print_persist(run, i);
        printf("\n");
    }
    if (listed > a->list) printf("(%ld more failures not listed)\n", listed - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
    printf("cases: %ld\n", a->cases);
    printf("single maximum: %ld (%.4f%%)\n", single, 100.0 * (double)single / (double)a->cases);
    printf("failures: %ld\n", fail);
    if (!a->nknots) {
        printf("failures by valence:");
        for (int v = 0; v < a->nval; v++) printf(" %d:%ld/%ld", a->val[v], vfail[v], vcases[v]);
        printf("\n");
    }
    printf("non-finite: %ld\n", nonfin);
    printf("fallbacks: %ld cases (%ld EV matrices)\n", fb_cases, fb_total);
    printf("errors: %ld\n", errors);
    return errors;
}

static void cm_fail_line(const exp_run *run, long i, const char *tag) {
    const cm_result *r = &run->cres[i];
    double d[EXP_MAX_N];
    int n = case_setup(run->a, i, d);
    printf("%s case %ld valence %d%s%s%s%s intervals ", tag, i, n, r->spectrum ? "" : " spectrum",
           r->regular ? "" : " regularity", r->injective ? "" : " injectivity",
           r->matrix_ok ? "" : " matrix");
    print_intervals(d, n);
    printf(" |mu|=%.6g,%.6g,%.6g,%.6g split %.2g im %.2g |mu4|/|mu2| %.6g bad_quads %d "
           "crossings %d winding %d,%d%s fallbacks %d\n", r->mod[0], r->mod[1], r->mod[2],
           r->mod[3], r->split, r->im2, r->ratio, r->bad_quads, r->crossings, r->wind_in,
           r->wind_out, r->defective ? " defective" : "", r->fallbacks);
}

typedef struct {
    long spectrum, regular, injective, matrix, all, fb_cases, errors;
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
        t->matrix += r->matrix_ok;
        t->all += r->spectrum && r->regular && r->injective && r->matrix_ok;
        t->fb_cases += r->fallbacks > 0;
        t->worst_ratio = fmax(t->worst_ratio, r->ratio);
        t->worst_split = fmax(t->worst_split, r->split);
        if (!r->fallbacks) t->worst_lam = fmax(t->worst_lam, r->lam_err);
        t->worst_rowsum = fmax(t->worst_rowsum, r->rowsum_err);
        t->worst_m = fmax(t->worst_m, r->m_err);
    }
}

static long charmap_report(const exp_run *run) {
    const exp_args *a = run->a;
    long listed = 0;
    for (long i = 0; i < a->cases; i++) {
        const cm_result *r = &run->cres[i];
        if (run->status[i] || (r->spectrum && r->regular && r->injective && r->matrix_ok)) continue;
        if (listed++ < a->list) cm_fail_line(run, i, "fail");
    }
    if (listed > a->list) printf("(%ld more failures not listed)\n", listed - a->list);
    for (long i = 0, shown = 0; i < a->cases && shown < a->list; i++)
        if (run->status[i]) { print_error_case(run, i); shown++; }
    if (a->nknots && !run->status[0]) cm_fail_line(run, 0, "details:");
    cm_totals t;
    cm_accumulate(run, &t);
    printf("cases: %ld\n", a->cases);
    printf("matrix ok: %ld (max |row sum - 1| %.3g, max 1-ring vs ccn_ev_matrix %.3g)\n",
           t.matrix, t.worst_rowsum, t.worst_m);
    printf("spectrum ok: %ld (max |mu2-mu3|/|mu2| %.3g, max |mu4|/|mu2| %.6g, "
           "max |mu2,3 - lambda_n| %.3g)\n", t.spectrum, t.worst_split, t.worst_ratio, t.worst_lam);
    printf("regular: %ld\n", t.regular);
    printf("injective: %ld\n", t.injective);
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
    max_result r;
    ccn_error err;
    if (maxima_case(&run->cages[0], a->knots, a->scheme, a->levels, a->start, per, &r, &err))
        return ccn_cli_error("experiment", &err);
    printf("maxima per level 1..%d:", a->levels);
    for (int l = 0; l < a->levels; l++) printf(" %d", per[l]);
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
