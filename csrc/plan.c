/* Public limit-surface API: ccn_plan_create / sizes / evaluate / destroy.
 *
 * create: validate the cage, choose the output level L (>= 1 if the cage has non-quads),
 * the cap level K (EVs isolated by three regular rings, K >= 2) and the refinement depth
 * R = max(L+1, K); build every level's topology and rules once; build the limit stencil of
 * every output vertex (limit.c) and, for cap = GUIDED_BI5, the c-net of every EV and the
 * output vertices inside its hole (tessellate.c).
 * evaluate: refine positions through the stored levels (no topology work), apply the
 * stencils, and evaluate the bi-5 caps for the hole vertices.
 */
#include "plan.h"

#include "bspline.h"
#include "patches.h"
#include "parallel.h"

#include <math.h>
#include <string.h>

#include "bi5.h"
#define CCN_HAVE_BI5 1

#define CCN_MAX_LEVELS 10
#define CCN_CAP_MAX_VALENCE 32

static void cap_free(ccn__cap *c) {
    free(c->cnet); free(c->ring); free(c->l0); free(c->knots); free(c->patches); free(c->pieces);
    free(c->taus);
    memset(c, 0, sizeof *c);
}

void ccn_plan_destroy(ccn_plan *p) {
    if (!p) return;
    for (int32_t l = 0; l < p->R; l++) ccn__level_free(&p->prep[l]);
    if (p->has_sub) { ccn__level_free(&p->sub); free(p->posS); }
    free(p->near);
    free(p->cage_pos);
    free(p->cap_net);
    for (int32_t l = 0; p->lev && l <= p->R; l++) ccn_mesh_destroy(p->lev[l]);
    for (int32_t c = 0; c < p->ncap; c++) cap_free(&p->caps[c]);
#if CCN_HAVE_BI5
    for (int32_t i = 0; i < p->nops; i++) ccn__bi5_destroy(p->ops[i]);
#endif
    free(p->ops); free(p->op_n); free(p->caps); free(p->prep); free(p->lev);
    free(p->vmapL); free(p->out_fv); free(p->out_origin);
    free(p->st_start); free(p->st_v); free(p->st_wp); free(p->st_wu); free(p->st_wv);
    free(p->orient); free(p->hv_out); free(p->hv_cap); free(p->hv_sector); free(p->hv_uv);
    free(p->rf_face); free(p->rf_bez); free(p->bv_out); free(p->bv_rf); free(p->bv_uv);
    free(p);
}

static ccn_status check_options(const ccn_options *o, ccn_error *err) {
    if (o->scheme < CCN_SCHEME_EIGEN || o->scheme > CCN_SCHEME_CATMULL_CLARK)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown scheme %d", (int)o->scheme);
    if (o->cap < CCN_CAP_GUIDED_BI5 || o->cap > CCN_CAP_REFINE)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown cap %d", (int)o->cap);
    if (o->boundary_corners < CCN_CORNERS_SMOOTH || o->boundary_corners > CCN_CORNERS_PINNED)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown boundary_corners %d",
                         (int)o->boundary_corners);
    if (o->levels < 0 || o->levels > CCN_MAX_LEVELS)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "levels must be in [0, %d], got %d",
                         CCN_MAX_LEVELS, (int)o->levels);
    return CCN_OK;
}

/* Builds levels 1..R (topology and prepared rules); lev[0] exists. */
static ccn_status build_levels(ccn_plan *p, int32_t R, ccn_error *err) {
    ccn_mesh **lev = realloc(p->lev, sizeof(ccn_mesh *) * ((size_t)R + 1));
    if (lev) p->lev = lev;
    ccn__level *prep = realloc(p->prep, sizeof(ccn__level) * (size_t)(R ? R : 1));
    if (prep) p->prep = prep;
    if (!lev || !prep) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    for (int32_t l = p->R; l < R; l++) {
        ccn_status st = ccn__level_prepare(&p->prep[l], p->lev[l], p->opts.scheme, pinned, err);
        if (st) return st;
        p->prep[l].threads = p->threads;
        p->lev[l + 1] = NULL;
        p->R = l + 1; /* prep[l] is owned from here on */
        st = ccn__level_topology(&p->prep[l], &p->lev[l + 1], err);
        if (st) { p->R = l; ccn__level_free(&p->prep[l]); return st; }
    }
    return CCN_OK;
}

/* ---- caps ------------------------------------------------------------------------- */

/* Is every vertex within three face rings of ev (except ev) interior and of valence 4? */
static int cap_isolated(const ccn_mesh *m, int32_t ev, int32_t *stamp, int32_t *queue) {
    int32_t qn = 0, qh = 0;
    stamp[ev] = ev;
    queue[qn++] = ev;
    for (int ring = 0; ring < 3; ring++) {
        int32_t end = qn;
        for (; qh < end; qh++) {
            int32_t v = queue[qh];
            for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
                int32_t f = m->hface[m->vfan[k]];
                for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
                    int32_t w = m->hvert[h];
                    if (stamp[w] == ev) continue;
                    stamp[w] = ev;
                    if (m->vboundary[w] || ccn__valence(m, w) != 4) return 0;
                    queue[qn++] = w;
                }
            }
            if (m->vboundary[v] && v != ev) return 0;
        }
    }
    return 1;
}

static int32_t count_evs(const ccn_mesh *m) {
    int32_t n = 0;
    for (int32_t v = 0; v < m->nv; v++) n += ccn__is_ev(m, v);
    return n;
}

#if CCN_HAVE_BI5
/* The c-net (SPEC §1.2): per sector k, grid nodes (2,0),(2,1),(2,2),(1,2),(1,1),(1,0). */
static void cap_cnet(const ccn_mesh *m, int32_t ev, int32_t n, int32_t *cnet) {
    cnet[0] = ev;
    for (int32_t k = 0; k < n; k++) {
        int32_t h = m->vfan[m->vfan_start[ev] + k];
        int32_t g = ccn__next(m, h);        /* E_k -> F_k in face k */
        int32_t t = m->htwin[g];            /* F_k -> E_k: face (1,1),(1,0),(2,0),(2,1) */
        int32_t y = ccn__next(m, ccn__next(m, t));
        int32_t t2 = m->htwin[ccn__prev(m, t)]; /* F_k -> (2,1): face (1,1),(2,1),(2,2),(1,2) */
        int32_t *c = cnet + 1 + 6 * k;
        c[0] = m->hvert[y];                            /* (2,0) */
        c[1] = m->hvert[ccn__next(m, t2)];             /* (2,1) */
        c[2] = m->hvert[ccn__next(m, ccn__next(m, t2))]; /* (2,2) */
        c[3] = m->hvert[ccn__prev(m, t2)];             /* (1,2) */
        c[4] = m->hvert[ccn__next(m, g)];              /* (1,1) = F_k */
        c[5] = m->hvert[g];                            /* (1,0) = E_k */
    }
}
#endif

#if CCN_HAVE_BI5
/* The operator for valence n: the paper's ring speeds, or (exact_surround) a first ring of
 * speed 1/2 in front of them (bi5.h [R13]). Shared by the caps of the plan. */
static const struct ccn__bi5 *cap_op(ccn_plan *p, int32_t n, int exact_surround, ccn_error *err) {
    int32_t key = exact_surround ? -n : n;
    for (int32_t i = 0; i < p->nops; i++)
        if (p->op_n[i] == key) return p->ops[i];
    static const double s5[3] = {0.75, 0.875, 0.875}, s3[1] = {15.0 / 16.0};
    static const double h5[4] = {0.5, 0.75, 0.875, 0.875}, h3[2] = {0.5, 15.0 / 16.0};
    const double *sig = exact_surround ? (n == 3 ? h3 : h5) : (n == 3 ? s3 : s5);
    int32_t nsig = (n == 3 ? 1 : 3) + (exact_surround ? 1 : 0);
    struct ccn__bi5 **ops = realloc(p->ops, sizeof(*ops) * ((size_t)p->nops + 1));
    if (ops) p->ops = ops;
    int32_t *op_n = realloc(p->op_n, sizeof(int32_t) * ((size_t)p->nops + 1));
    if (op_n) p->op_n = op_n;
    if (!ops || !op_n) return NULL;
    if (ccn__bi5_create(n, sig, nsig, &p->ops[p->nops], err)) return NULL;
    p->op_n[p->nops] = key;
    return p->ops[p->nops++];
}
#endif

#if CCN_HAVE_BI5
/* Arbitrary NU intervals: switch cap c to the exact level-(K+1) surround (bi5.h [R13]) and
 * check that it exists and that the construction runs; 1 on success. */
static int cap_use_surround(ccn_plan *p, ccn__cap *c, int32_t ev, const double *zero, ccn_error *e2) {
    if (p->R < p->K + 1 && build_levels(p, p->K + 1, e2)) return 0;
    const struct ccn__bi5 *op = cap_op(p, c->n, 1, e2);
    if (!op) return 0;
    /* the taus depend on the last ring's speed only, which both operators share */
    if (op->sig[op->nsig - 1] != c->op->sig[c->op->nsig - 1]) return 0;
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    free(c->patches);
    c->op = op;
    c->exact_surround = 1;
    c->patches = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(op));
    c->pieces = calloc(432 * (size_t)c->n, sizeof(double));
    return c->patches && c->pieces &&
           ccn__cap_surround(p->lev[p->K], p->lev[p->K + 1], ev, pinned, NULL) &&
           ccn__bi5_apply_pieces(op, zero, c->pieces, c->knots, c->taus, zero, c->patches, e2) == CCN_OK;
}
#endif

/* Sets up the cap of EV ev at level K; returns 1 if it was added, 0 for a fallback. */
static int cap_add(ccn_plan *p, int32_t ev, ccn_error *err) {
#if CCN_HAVE_BI5
    const ccn_mesh *m = p->lev[p->K];
    int32_t n = ccn__valence(m, ev);
    if (n > CCN_CAP_MAX_VALENCE) return 0;
    ccn_error e2;
    const struct ccn__bi5 *op = cap_op(p, n, 0, &e2);
    if (!op) return 0;
    ccn__cap *c = &p->caps[p->ncap];
    memset(c, 0, sizeof *c);
    c->n = n;
    c->op = op;
    c->cnet = malloc(sizeof(int32_t) * (6 * (size_t)n + 1));
    c->ring = malloc(sizeof(int32_t) * (2 * (size_t)n + 1));
    c->l0 = malloc(sizeof(double) * (2 * (size_t)n + 1));
    c->knots = malloc(sizeof(double) * (size_t)n);
    c->patches = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(op));
    double *zero = calloc(3 * (6 * (size_t)n + 1), sizeof(double));
    ccn__stencil *s = malloc(sizeof *s);
    int ok = c->cnet && c->ring && c->l0 && c->knots && c->patches && zero && s;
    if (ok) {
        cap_cnet(m, ev, n, c->cnet);
        ccn__ev_ring(m, ev, c->ring);
        for (int32_t k = 0; k < n; k++) c->knots[k] = m->eknot[ccn__fan_edge(m, ev, k)];
        ok = ccn__ev_limit(m, ev, p->opts.scheme, s, &e2) == CCN_OK;
        for (int32_t j = 0; ok && j < 2 * n + 1; j++) c->l0[j] = s->wp[j];
        int nu = 0; /* some kappa_s = d_{s+1}/d_{s-1} != 1: taus, once (they need no positions) */
        for (int32_t k = 0; k < n; k++)
            nu |= fabs(c->knots[(k + 1) % n] / c->knots[(k + n - 1) % n] - 1.0) > 1e-12;
        if (ok && nu) {
            c->taus = malloc(sizeof(double complex) * 36 * (size_t)n);
            ok = c->taus && ccn__bi5_nu_taus(op, c->knots, c->taus, &e2) == CCN_OK;
        }
        ccn_status st = ok ? ccn__bi5_apply_cached(op, zero, c->knots, c->taus, zero, c->patches, &e2)
                           : CCN_ERR_ARGUMENT;
        if (st == CCN_ERR_KNOTS) ok = cap_use_surround(p, c, ev, zero, &e2);
        else ok = ok && st == CCN_OK;
    }
    free(zero);
    free(s);
    if (!ok) {
        cap_free(c);
        return 0;
    }
    p->ncap++;
    (void)err;
    return 1;
#else
    (void)p; (void)ev; (void)err;
    return 0;
#endif
}

/* Chooses K, builds the caps. */
static ccn_status setup_caps(ccn_plan *p, ccn_error *err) {
    p->K = -1;
    if (p->opts.cap != CCN_CAP_GUIDED_BI5) return CCN_OK;
    ccn_status st0 = build_levels(p, 1, err);
    if (st0) return st0;
    if (count_evs(p->lev[1]) == 0) return CCN_OK;
    int32_t K = 2;
    for (; K <= 4; K++) {
        ccn_status st = build_levels(p, K, err);
        if (st) return st;
        const ccn_mesh *m = p->lev[K];
        int32_t *stamp = malloc(sizeof(int32_t) * (size_t)m->nv), *q = malloc(sizeof(int32_t) * (size_t)m->nv);
        if (!stamp || !q) { free(stamp); free(q); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
        for (int32_t v = 0; v < m->nv; v++) stamp[v] = -1;
        int all = 1;
        for (int32_t v = 0; v < m->nv && all; v++)
            if (ccn__is_ev(m, v) && !cap_isolated(m, v, stamp, q)) all = 0;
        free(stamp); free(q);
        if (all || K == 4) break;
    }
    p->K = K;
    const ccn_mesh *m = p->lev[K];
    int32_t nev = count_evs(m);
    p->caps = calloc((size_t)(nev ? nev : 1), sizeof(ccn__cap));
    int32_t *stamp = malloc(sizeof(int32_t) * (size_t)m->nv), *q = malloc(sizeof(int32_t) * (size_t)m->nv);
    if (!p->caps || !stamp || !q) { free(stamp); free(q); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
    for (int32_t v = 0; v < m->nv; v++) stamp[v] = -1;
    for (int32_t v = 0; v < m->nv; v++) {
        if (!ccn__is_ev(m, v)) continue;
        if (!cap_isolated(m, v, stamp, q) || !cap_add(p, v, err)) p->sizes.num_cap_fallbacks++;
    }
    free(stamp); free(q);
    p->sizes.num_caps = p->ncap;
    int32_t maxn = 0;
    for (int32_t c = 0; c < p->ncap; c++) maxn = p->caps[c].n > maxn ? p->caps[c].n : maxn;
    p->cap_net = malloc(sizeof(double) * 3 * (6 * (size_t)maxn + 1));
    if (!p->cap_net) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    return CCN_OK;
}

/* ---- create ----------------------------------------------------------------------- */

/* Level L+1: the built lev[L+1] when caps needed it, else computed around irregular
 * vertices only (evaluate) from a prepared level L. */
static ccn_status setup_level_s(ccn_plan *p, ccn_error *err) {
    if (p->R > p->L) { p->posS = p->lev[p->L + 1]->pos; return CCN_OK; }
    const ccn_mesh *m = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn_status st = ccn__level_prepare(&p->sub, m, p->opts.scheme, pinned, err);
    if (st) return st;
    p->has_sub = 1;
    p->sub.threads = 1; /* a few points only */
    p->posS = malloc(sizeof(double) * 3 * ((size_t)m->nf + m->ne + m->nv));
    if (!p->posS) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    return CCN_OK;
}

static int has_non_quads(const ccn_mesh *m) {
    for (int32_t f = 0; f < m->nf; f++)
        if (ccn__fsize(m, f) != 4) return 1;
    return 0;
}

static void fill_sizes(ccn_plan *p) {
    ccn_sizes *s = &p->sizes;
    const ccn_mesh_info *c = &p->lev[0]->info, *r = &p->lev[p->R]->info;
    s->num_verts = p->nout_v;
    s->num_faces = p->nout_f;
    s->num_cage_verts = p->ncage;
    s->levels = p->L;
    s->refine_levels = p->R;
    s->num_extraordinary = p->R >= 1 ? p->lev[1]->info.num_extraordinary : c->num_extraordinary;
    s->num_ev_fallbacks = r->num_ev_fallbacks;
    s->num_ring_conflicts = c->num_ring_conflicts;
    s->num_ignored_verts = c->num_ignored_verts;
    s->num_ignored_edges = c->num_ignored_edges;
}

ccn_status ccn_plan_create(const ccn_cage *cage, const ccn_options *opts, ccn_plan **out,
                           ccn_error *err) {
    ccn__ok(err);
    if (!out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "out is NULL");
    *out = NULL;
    ccn_options o = {0};
    if (opts) o = *opts;
    ccn_status st = check_options(&o, err);
    if (st) return st;
    ccn_plan *p = calloc(1, sizeof *p);
    if (!p) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    p->opts = o;
    p->threads = ccn__thread_count(o.threads);
    p->lev = calloc(1, sizeof(ccn_mesh *));
    if (!p->lev) { free(p); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
    ccn_mesh *cage_mesh = NULL;
    if ((st = ccn_mesh_create(cage, &cage_mesh, err))) { ccn_plan_destroy(p); return st; }
    if (o.scheme == CCN_SCHEME_CATMULL_CLARK) {
        for (int32_t e = 0; e < cage_mesh->ne; e++) cage_mesh->eknot[e] = 1.0;
        cage_mesh->knot_scale = 1.0;
    }
    p->lev[0] = cage_mesh;
    p->ncage = cage->num_verts;
    p->scale = 1.0;
    p->cage_pos = malloc(sizeof(double) * 3 * (size_t)(p->ncage ? p->ncage : 1));
    if (!p->cage_pos) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto fail; }
    memcpy(p->cage_pos, cage_mesh->pos, sizeof(double) * 3 * (size_t)p->ncage);
    for (int32_t v = 0; v < cage_mesh->nv && !st; v++)
        if (cage_mesh->vfan_start[v + 1] > cage_mesh->vfan_start[v] &&
            ccn__valence(cage_mesh, v) > CCN_EV_MATRIX_MAX_VALENCE)
            st = ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, v,
                           "vertex %d has valence %d; the limit surface supports at most %d",
                           (int)v, (int)ccn__valence(cage_mesh, v), CCN_EV_MATRIX_MAX_VALENCE);
    for (int32_t f = 0; f < cage_mesh->nf && !st; f++)
        if (ccn__fsize(cage_mesh, f) > CCN_EV_MATRIX_MAX_VALENCE)
            st = ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, f,
                           "face %d has %d sides; the limit surface supports at most %d",
                           (int)f, (int)ccn__fsize(cage_mesh, f), CCN_EV_MATRIX_MAX_VALENCE);
    if (st) goto fail;
    p->L = o.levels < 1 && has_non_quads(cage_mesh) ? 1 : o.levels;
    int64_t corners = cage_mesh->nh; /* fail before any work if the output cannot be indexed */
    for (int32_t l = 0; l < p->L + 1 && !st; l++)
        if ((corners *= 4) > INT32_MAX / 8)
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                           "%d levels of a %d-corner cage would exceed %d face corners",
                           (int)p->L, (int)cage_mesh->nh, INT32_MAX / 8);
    if (st) goto fail;
    if ((st = setup_caps(p, err))) goto fail;
    if ((st = build_levels(p, p->R > p->L ? p->R : p->L, err))) goto fail;
    if ((st = setup_level_s(p, err))) goto fail;
    if ((st = ccn__tess_output(p, err))) goto fail;
    if (p->ncap && (st = ccn__tess_holes(p, err))) goto fail;
    fill_sizes(p);
    *out = p;
    return CCN_OK;
fail:
    ccn_plan_destroy(p);
    return st;
}

ccn_status ccn_plan_sizes(const ccn_plan *p, ccn_sizes *s) {
    if (!p || !s) return CCN_ERR_ARGUMENT;
    *s = p->sizes;
    return CCN_OK;
}

/* ---- evaluate --------------------------------------------------------------------- */

static void cross(const double a[3], const double b[3], double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static void unit_normal(const double du[3], const double dv[3], double n[3]) {
    cross(du, dv, n);
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0 && isfinite(l)) { n[0] /= l; n[1] /= l; n[2] /= l; }
    else { n[0] = 0; n[1] = 0; n[2] = 1; } /* degenerate cage geometry: documented fallback */
}

#define SPOINT(i) ((i) < nvL ? PL + 3 * (size_t)(i) : PS + 3 * ((size_t)(i) - nvL))

typedef struct { const ccn_plan *p; ccn_limit_mesh *out; } stencil_job;

static void stencil_range(void *ctx, int32_t begin, int32_t end) {
    const stencil_job *j = ctx;
    const ccn_plan *p = j->p;
    ccn_limit_mesh *out = j->out;
    const double *PL = p->lev[p->L]->pos, *PS = p->posS;
    int32_t nvL = p->lev[p->L]->nv;
    for (int32_t o = begin; o < end; o++) {
        double x[3] = {0, 0, 0}, du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
        for (int32_t k = p->st_start[o]; k < p->st_start[o + 1]; k++) {
            const double *q = SPOINT(p->st_v[k]);
            for (int i = 0; i < 3; i++) {
                x[i] += p->st_wp[k] * q[i];
                du[i] += p->st_wu[k] * q[i];
                dv[i] += p->st_wv[k] * q[i];
            }
        }
        memcpy(out->positions + 3 * (size_t)o, x, sizeof x);
        if (!out->normals) continue;
        double *n = out->normals + 3 * (size_t)o;
        unit_normal(du, dv, n);
        const int32_t *r = p->orient + 3 * (size_t)o;
        if (r[0] >= 0) { /* EV: agree with the first face of the 1-ring */
            double a[3], b[3], c[3];
            const double *r0 = SPOINT(r[0]), *r1 = SPOINT(r[1]), *r2 = SPOINT(r[2]);
            for (int i = 0; i < 3; i++) {
                a[i] = r1[i] - r0[i];
                b[i] = r2[i] - r0[i];
            }
            cross(a, b, c);
            if (c[0] * n[0] + c[1] * n[1] + c[2] * n[2] < 0) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
        }
    }
}

static void eval_stencils(const ccn_plan *p, ccn_limit_mesh *out) {
    stencil_job j = {p, out};
    ccn__parallel_for(p->threads, p->nout_v, stencil_range, &j);
}

#if CCN_HAVE_BI5
/* The faces around each hole: bicubic patches of the level-K net (see plan.h). */
static void eval_ring_faces(ccn_plan *p, ccn_limit_mesh *out) {
    const ccn_mesh *mK = p->lev[p->K];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    for (int32_t i = 0; i < p->nrf; i++)
        if (!ccn__bicubic_patch(mK, p->rf_face[i], pinned, 0, (double(*)[4][3])(p->rf_bez + 48 * (size_t)i)))
            p->rf_bez[48 * (size_t)i] = NAN; /* not a patch: keep the limit stencil */
    for (int32_t i = 0; i < p->nbv; i++) {
        const double *b = p->rf_bez + 48 * (size_t)p->bv_rf[i];
        if (isnan(b[0])) continue;
        double x[3], du[3], dv[3];
        ccn__bezier_eval(b, 3, p->bv_uv[2 * i], p->bv_uv[2 * i + 1], x, du, dv);
        int32_t o = p->bv_out[i];
        memcpy(out->positions + 3 * (size_t)o, x, sizeof x);
        if (out->normals) unit_normal(du, dv, out->normals + 3 * (size_t)o);
    }
}
#endif

static ccn_status eval_caps(ccn_plan *p, ccn_limit_mesh *out, ccn_error *err) {
#if CCN_HAVE_BI5
    if (p->ncap == 0) return CCN_OK;
    const double *P = p->lev[p->K]->pos;
    for (int32_t c = 0; c < p->ncap; c++) {
        ccn__cap *cp = &p->caps[c];
        int32_t n = cp->n, nc = 6 * n + 1;
        double *net = p->cap_net, ctr[3] = {0, 0, 0}; /* sized for the largest cap at create */
        for (int32_t j = 0; j < nc; j++) memcpy(net + 3 * j, P + 3 * (size_t)cp->cnet[j], sizeof(double) * 3);
        for (int32_t j = 0; j < 2 * n + 1; j++)
            for (int i = 0; i < 3; i++) ctr[i] += cp->l0[j] * P[3 * (size_t)cp->ring[j] + i];
        ccn_status st;
        if (cp->exact_surround) {
            int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
            if (!ccn__cap_surround(p->lev[p->K], p->lev[p->K + 1], cp->cnet[0], pinned, cp->pieces))
                return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, cp->cnet[0], "cap surround lost");
            st = ccn__bi5_apply_pieces(cp->op, net, cp->pieces, cp->knots, cp->taus, ctr, cp->patches, err);
        } else {
            st = ccn__bi5_apply_cached(cp->op, net, cp->knots, cp->taus, ctr, cp->patches, err);
        }
        if (st) return st;
    }
    for (int32_t i = 0; i < p->nhv; i++) {
        const ccn__cap *cp = &p->caps[p->hv_cap[i]];
        double x[3], du[3], dv[3];
        ccn__bi5_eval(cp->op, cp->patches, p->hv_sector[i], p->hv_uv[2 * i], p->hv_uv[2 * i + 1], x, du, dv);
        int32_t o = p->hv_out[i];
        memcpy(out->positions + 3 * (size_t)o, x, sizeof x);
        if (out->normals) unit_normal(du, dv, out->normals + 3 * (size_t)o);
    }
    eval_ring_faces(p, out);
#else
    (void)p; (void)out; (void)err;
#endif
    return CCN_OK;
}

ccn_status ccn_plan_evaluate(ccn_plan *p, const double *positions, ccn_limit_mesh *out,
                             ccn_error *err) {
    ccn__ok(err);
    if (!p || !out || !out->positions)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "plan, out or out->positions is NULL");
    if (positions) {
        ccn_status st = ccn_mesh_set_positions(p->lev[0], positions, err);
        if (st) return st;
    } else { /* the cage's own positions, as given to ccn_plan_create */
        memcpy(p->lev[0]->pos, p->cage_pos, sizeof(double) * 3 * (size_t)p->ncage);
    }
    /* every rule is affine-invariant: work in a unit box so that huge coordinates (1e300)
     * cannot overflow, and map back at the end */
    double *centre = p->centre, scale;
    ccn__normalize(p->lev[0], centre, &scale);
    p->scale = scale;
    for (int32_t l = 0; l < p->R; l++) ccn__level_points(&p->prep[l], p->lev[l + 1]->pos);
    if (p->has_sub) ccn__level_points_subset(&p->sub, p->near, p->nnear, p->posS);
    eval_stencils(p, out);
    ccn_status st = eval_caps(p, out, err);
    if (st) return st;
    for (int32_t o = 0; o < p->nout_v; o++)
        for (int k = 0; k < 3; k++) out->positions[3 * (size_t)o + k] = centre[k] + scale * out->positions[3 * (size_t)o + k];
    if (out->face_verts) memcpy(out->face_verts, p->out_fv, sizeof(int32_t) * 4 * (size_t)p->nout_f);
    if (out->face_origin) memcpy(out->face_origin, p->out_origin, sizeof(int32_t) * (size_t)p->nout_f);
    return CCN_OK;
}

/* ---- patch export --------------------------------------------------------------- */

static int32_t cage_face_of(const ccn_plan *p, int32_t l, int32_t f) {
    for (; l > 0; l--) f = p->lev[l - 1]->hface[f];
    return f;
}

/* Control points back in the caller's coordinates (evaluate works in a unit box). */
static void emit(const ccn_plan *p, ccn_patch_fn fn, void *user, int32_t deg, const double *pts,
                 int32_t face) {
    double buf[108];
    int32_t n = (deg + 1) * (deg + 1);
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) buf[3 * i + k] = p->centre[k] + p->scale * pts[3 * i + k];
    fn(user, deg, buf, face);
}

static void export_bicubic(const ccn_plan *p, int32_t lvl, ccn_patch_fn fn, void *user,
                           int32_t *skipped) {
    const ccn_mesh *m = p->lev[lvl];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    uint8_t *kind = calloc((size_t)(m->nf ? m->nf : 1), 1); /* 1 hole, 2 ring face */
    if (!kind) { *skipped = m->nf; return; }
    for (int32_t c = 0; c < p->ncap; c++)
        for (int32_t k = p->lev[p->K]->vfan_start[p->caps[c].cnet[0]];
             k < p->lev[p->K]->vfan_start[p->caps[c].cnet[0] + 1]; k++)
            kind[p->lev[p->K]->hface[p->lev[p->K]->vfan[k]]] = 1;
    for (int32_t i = 0; i < p->nrf; i++) kind[p->rf_face[i]] = 2;
    for (int32_t c = 0; c < p->ncap; c++) { /* exact surround: faces around the hole, 3 */
        const ccn__cap *cp = &p->caps[c];
        if (!cp->exact_surround || lvl != p->K) continue;
        for (int32_t j = 0; j < 2 * cp->n; j++)
            for (int32_t k = m->vfan_start[cp->ring[j]]; k < m->vfan_start[cp->ring[j] + 1]; k++)
                if (kind[m->hface[m->vfan[k]]] == 0) kind[m->hface[m->vfan[k]]] = 3;
    }
    double bez[4][4][3];
    for (int32_t f = 0; f < m->nf; f++) {
        if (kind[f] == 1) continue;
        if (kind[f] == 3) { /* not a tensor patch at level K: its level-(K+1) children are */
            for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
                if (ccn__bicubic_patch(p->lev[lvl + 1], h, pinned, 1, bez))
                    emit(p, fn, user, 3, &bez[0][0][0], cage_face_of(p, lvl + 1, h));
                else
                    (*skipped)++;
            }
            continue;
        }
        if (ccn__bicubic_patch(m, f, pinned, kind[f] != 2, bez))
            emit(p, fn, user, 3, &bez[0][0][0], cage_face_of(p, lvl, f));
        else
            (*skipped)++;
    }
    free(kind);
}

ccn_status ccn_plan_patches(const ccn_plan *p, ccn_patch_fn fn, void *user, int32_t *skipped) {
    if (!p || !fn) return CCN_ERR_ARGUMENT;
    int32_t sk = 0, lvl = p->K >= 0 ? p->K : p->R;
    export_bicubic(p, lvl, fn, user, &sk);
#if CCN_HAVE_BI5
    for (int32_t c = 0; c < p->ncap; c++) {
        const ccn__cap *cp = &p->caps[c];
        const ccn_mesh *mK = p->lev[p->K];
        int32_t np = ccn__bi5_num_patches(cp->op);
        for (int32_t i = 0; i < np; i++) {
            int32_t s = i % cp->n, h = mK->vfan[mK->vfan_start[cp->cnet[0]] + s];
            emit(p, fn, user, 5, cp->patches + 108 * (size_t)i, cage_face_of(p, p->K, mK->hface[h]));
        }
    }
#endif
    if (skipped) *skipped = sk;
    return CCN_OK;
}
