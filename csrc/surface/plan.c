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
#include "surface/plan_types.h"

#include "base/error.h"
#include "base/parallel.h"
#include "base/vec3.h"
#include "bi5/bi5.h"
#include "surface/caps.h"
#include "surface/curvature.h"
#include "surface/edit_region.h"
#include "surface/plan_fvar.h"
#include "surface/plan_levels.h"
#include "surface/tessellate.h"
#include "topology/mesh.h"

#include <math.h>
#include <string.h>

#define CCN_MAX_LEVELS 10
#define CCN_EV_CACHE_CARRY 65536 /* a recreated plan keeps the earlier one's EV choices up to this many */

void ccn_plan_destroy(ccn_plan *p) {
    if (!p) return;
    for (int32_t l = 0; l < p->R; l++) ccn__level_free(&p->prep[l]);
    if (p->has_sub) { ccn__level_free(&p->sub); free(p->posS); }
    free(p->near);
    free(p->cage_pos);
    free(p->cap_net);
    for (int32_t l = 0; p->lev && l <= p->R; l++) ccn_mesh_destroy(p->lev[l]);
    for (int32_t c = 0; c < p->ncap; c++) ccn__cap_free(&p->caps[c]);
    for (int32_t i = 0; i < p->nops; i++) ccn__bi5_destroy(p->ops[i]);
    free(p->ops); free(p->op_n); free(p->caps); free(p->prep); free(p->lev);
    free(p->vmapL); free(p->out_vL); free(p->out_fv); free(p->out_origin); free(p->out_eorigin);
    free(p->out_ev); free(p->out_ce);
    free(p->st_start); free(p->st_v); free(p->st_wp); free(p->st_wu); free(p->st_wv);
    free(p->st_w); free(p->ws);
    free(p->curv_ws); free(p->curv_set); free(p->curv_mode);
    free(p->curv_wuu); free(p->curv_wuv); free(p->curv_wvv); free(p->curv_other);
    free(p->sv_out); free(p->sv_sec); free(p->sec_start); free(p->sec_v); free(p->sec_wu);
    free(p->sec_wv); free(p->corner_sec); free(p->sec_nrm); free(p->hv_out); free(p->hv_cap); free(p->hv_sector); free(p->hv_uv);
    free(p->rf_face); free(p->rf_cap); free(p->rf_on); free(p->rf_bez); free(p->bv_out); free(p->bv_rf); free(p->bv_uv);
    for (int32_t c = 0; c < p->nfv; c++) ccn__fvchan_free(p->fv[c]);
    free(p->fv); free(p->vd_buf);
    ccn__ev_cache_destroy(p->ev_cache);
    ccn__edit_region_free(p->region);
    free(p);
}

static ccn_status check_options(const ccn_options *o, ccn_error *err) {
    if (o->scheme < CCN_SCHEME_EIGEN || o->scheme > CCN_SCHEME_CATMULL_CLARK)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown scheme %d", (int)o->scheme);
    if (o->cap < CCN_CAP_GUIDED_BI5 || o->cap > CCN_CAP_G1_FILL)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown cap %d", (int)o->cap);
    if (o->boundary_corners < CCN_CORNERS_SMOOTH || o->boundary_corners > CCN_CORNERS_PINNED)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown boundary_corners %d",
                         (int)o->boundary_corners);
    if (o->crease_method < CCN_CREASE_UNIFORM || o->crease_method > CCN_CREASE_CHAIKIN)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown crease_method %d",
                         (int)o->crease_method);
    if (o->ev_polyhedron < CCN_POLY_SELECT || o->ev_polyhedron > CCN_POLY_COUNT)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "ev_polyhedron %d outside [0, %d]",
                         (int)o->ev_polyhedron, CCN_POLY_COUNT);
    if (o->levels < 0 || o->levels > CCN_MAX_LEVELS)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "levels must be in [0, %d], got %d",
                         CCN_MAX_LEVELS, (int)o->levels);
    return CCN_OK;
}

/* ---- create ----------------------------------------------------------------------- */

/* Level L+1: the built lev[L+1] when caps needed it, else computed around irregular
 * vertices only (evaluate) from a prepared level L. */
static ccn_status setup_level_s(ccn_plan *p, ccn_error *err) {
    if (p->R > p->L) { p->posS = p->lev[p->L + 1]->pos; return CCN_OK; }
    const ccn_mesh *m = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    ccn__level *same = p->hint && p->hint->has_sub ? &p->hint->sub : NULL; /* its topology */
    ccn_status st = ccn__level_prepare_like(&p->sub, m, p->opts.scheme, pinned, p->opts.crease_method,
                                            p->opts.ev_polyhedron, p->ev_cache, same, err);
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
    ccn_sizes *z = &p->sizes;
    ccn_plan_stats *s = &p->stats;
    const ccn_mesh_info *c = &p->lev[0]->info, *r = &p->lev[p->R]->info;
    z->num_verts = p->nout_v;
    z->num_faces = p->nout_f;
    z->num_cage_verts = p->ncage;
    z->num_edges = p->nout_e;
    s->levels = p->L;
    s->refine_levels = p->R;
    s->num_caps_deferred = p->caps_deferred;
    s->num_extraordinary = p->R >= 1 ? p->lev[1]->info.num_extraordinary : c->num_extraordinary;
    s->num_ev_fallbacks = r->num_ev_fallbacks;
    s->num_ring_conflicts = c->num_ring_conflicts;
    s->num_ignored_verts = c->num_ignored_verts;
    s->num_ignored_edges = c->num_ignored_edges;
    s->num_sharp_edges = c->num_sharp_edges;
    s->num_sharp_vertices = c->num_sharp_vertices;
    s->num_sharp_corners = p->nsv;
    for (int32_t l = 0; l < p->R; l++) { /* every EV gets M once per level from level 1 on */
        if (p->prep[l].ev_verified > s->num_ev_verified) s->num_ev_verified = p->prep[l].ev_verified;
        if (p->prep[l].ev_outside > s->num_ev_outside_g1) s->num_ev_outside_g1 = p->prep[l].ev_outside;
    }
}

static ccn_status create(const ccn_cage *cage, const ccn_options *opts, ccn_cache *cache,
                         ccn_plan *prev, ccn_plan **out, ccn_error *err);

ccn_status ccn_plan_create(const ccn_cage *cage, const ccn_options *opts, ccn_plan **out,
                           ccn_error *err) {
    ccn_plan *prev = opts ? opts->previous : NULL;
    ccn_status st = create(cage, opts, opts ? opts->cache : NULL, prev, out, err);
    ccn_plan_destroy(prev); /* consumed: what the new plan took is NULL in it */
    return st;
}

/* Does the earlier plan q have cage mesh m's topology and sharpness, and options o (but for
 * the thread count, which changes no number)? Then every level's topology and the output mesh
 * are q's. */
static int same_plan_topology(const ccn_plan *q, const ccn_options *o, const ccn_mesh *m) {
    const ccn_options *a = &q->opts;
    if (a->scheme != o->scheme || a->cap != o->cap || a->levels != o->levels ||
        a->boundary_corners != o->boundary_corners || a->crease_method != o->crease_method ||
        a->ev_polyhedron != o->ev_polyhedron)
        return 0;
    const ccn_mesh *c = q->lev[0];
    if (c->nv != m->nv || c->nf != m->nf || c->ne != m->ne || c->nh != m->nh) return 0;
    if (!c->esharp != !m->esharp || !c->vsharp != !m->vsharp) return 0;
    size_t nh = sizeof(int32_t) * (size_t)m->nh;
    return !memcmp(c->fstart, m->fstart, sizeof(int32_t) * ((size_t)m->nf + 1)) &&
           !memcmp(c->hvert, m->hvert, nh) && !memcmp(c->htwin, m->htwin, nh) &&
           !memcmp(c->hedge, m->hedge, nh) &&
           !memcmp(c->everts, m->everts, sizeof(int32_t) * 2 * (size_t)m->ne) &&
           (!m->esharp || !memcmp(c->esharp, m->esharp, sizeof(float) * (size_t)m->ne)) &&
           (!m->vsharp || !memcmp(c->vsharp, m->vsharp, sizeof(float) * (size_t)m->nv));
}

static ccn_status create(const ccn_cage *cage, const ccn_options *opts, ccn_cache *cache,
                         ccn_plan *prev, ccn_plan **out, ccn_error *err) {
    ccn__ok(err);
    if (!out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "out is NULL");
    *out = NULL;
    ccn_options o = {0};
    if (opts) o = *opts;
    o.cache = NULL, o.previous = NULL; /* passed apart: the plan keeps no pointer to previous */
    ccn_status st = check_options(&o, err);
    if (st) return st;
    ccn_plan *p = calloc(1, sizeof *p);
    if (!p) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    p->opts = o;
    p->op_cache = cache;
    p->threads = ccn__thread_count(o.threads);
    p->lev = calloc(1, sizeof(ccn_mesh *));
    p->ev_cache = ccn__ev_cache_create();
    if (!p->lev || !p->ev_cache) { free(p->lev); ccn__ev_cache_destroy(p->ev_cache); free(p); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
    ccn_mesh *cage_mesh = NULL;
    if ((st = ccn_mesh_create(cage, &cage_mesh, err))) { ccn_plan_destroy(p); return st; }
    if (o.scheme == CCN_SCHEME_CATMULL_CLARK) {
        for (int32_t e = 0; e < cage_mesh->ne; e++) cage_mesh->eknot[e] = 1.0;
        cage_mesh->knot_scale = 1.0;
    }
    p->lev[0] = cage_mesh;
    p->ncage = cage->num_verts;
    p->scale = 1.0;
    /* level 0's points (a split non-manifold cage has copies of some vertices after the
     * cage's, topology/split.c) */
    p->cage_pos = malloc(sizeof(double) * 3 * (size_t)(cage_mesh->nv ? cage_mesh->nv : 1));
    if (!p->cage_pos) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto fail; }
    memcpy(p->cage_pos, cage_mesh->pos, sizeof(double) * 3 * (size_t)cage_mesh->nv);
    for (int32_t v = 0; v < cage_mesh->nv && !st; v++)
        if (cage_mesh->vfan_start[v + 1] > cage_mesh->vfan_start[v] &&
            ccn__valence(cage_mesh, v) > CCN_EV_MATRIX_MAX_VALENCE)
            st = ccn__because(err, CCN_REASON_VALENCE_LIMIT,
                              ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, cage_mesh->vrep ? cage_mesh->vrep[v] : v,
                                        "vertex %d has valence %d; the limit surface supports at most %d",
                                        (int)(cage_mesh->vrep ? cage_mesh->vrep[v] : v),
                                        (int)ccn__valence(cage_mesh, v), CCN_EV_MATRIX_MAX_VALENCE));
    for (int32_t f = 0; f < cage_mesh->nf && !st; f++)
        if (ccn__fsize(cage_mesh, f) > CCN_EV_MATRIX_MAX_VALENCE)
            st = ccn__because(err, CCN_REASON_FACE_SIZE_LIMIT,
                              ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, f,
                                        "face %d has %d sides; the limit surface supports at most %d",
                                        (int)f, (int)ccn__fsize(cage_mesh, f), CCN_EV_MATRIX_MAX_VALENCE));
    if (st) goto fail;
    if (prev && prev->R >= 1 && same_plan_topology(prev, &o, cage_mesh)) p->hint = prev;
    if (prev && prev->ev_cache && ccn__ev_cache_count(prev->ev_cache) <= CCN_EV_CACHE_CARRY) {
        /* the eigen polyhedron choices it verified: a function of the spoke intervals only
         * (rules/eigen_select.c), so the EVs the edit left alone are not verified again */
        ccn__ev_cache *t = p->ev_cache;
        p->ev_cache = prev->ev_cache;
        prev->ev_cache = t;
    }
    p->L = o.levels < 1 && has_non_quads(cage_mesh) ? 1 : o.levels;
    int64_t corners = cage_mesh->nh; /* fail before any work if the output cannot be indexed */
    for (int32_t l = 0; l < p->L + 1 && !st; l++)
        if ((corners *= 4) > INT32_MAX / 8)
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                           "%d levels of a %d-corner cage would exceed %d face corners",
                           (int)p->L, (int)cage_mesh->nh, INT32_MAX / 8);
    if (st) goto fail;
    if ((st = ccn__caps_setup(p, err))) goto fail;
    if ((st = ccn__plan_build_levels(p, p->R > p->L ? p->R : p->L, err))) goto fail;
    if (p->hint) ccn__edit_region_begin(p); /* none when out of memory: evaluate all */
    if ((st = setup_level_s(p, err))) goto fail;
    if ((st = ccn__tess_output(p, err))) goto fail;
    if (p->ncap && (st = ccn__tess_holes(p, err))) goto fail;
    ccn__edit_region_rows(p);
    fill_sizes(p);
    p->hint = NULL;
    *out = p;
    return CCN_OK;
fail:
    p->hint = NULL;
    ccn_plan_destroy(p);
    return st;
}

ccn_status ccn_plan_get_sizes(const ccn_plan *p, ccn_sizes *s) {
    if (!p || !s) return CCN_ERR_ARGUMENT;
    *s = p->sizes;
    return CCN_OK;
}

ccn_status ccn_plan_get_stats(const ccn_plan *p, ccn_plan_stats *s) {
    if (!p || !s) return CCN_ERR_ARGUMENT;
    *s = p->stats;
    return CCN_OK;
}

/* ---- evaluate --------------------------------------------------------------------- */

#define SPOINT(i) ((i) < nvL ? PL + 3 * (size_t)(i) : PS + 3 * ((size_t)(i) - nvL))

typedef struct { const ccn_plan *p; ccn_limit_mesh *out; const int32_t *rows; } stencil_job; /* rows: NULL = all */

/* Three weighted sums of row o's points: s[t] = sum_k w[t][k] P(st_v[st_start[o] + k]) (the
 * position and tangents with the row's weights; its second derivatives with the curvature
 * weights, a second pass over the same points, in cache: twelve accumulators in one pass would
 * not fit the sixteen vector registers). */
static inline void row_sums(const ccn_plan *p, int32_t o, const double *const w[3], double s[3][3]) {
    const double *PL = p->lev[p->L]->pos, *PS = p->posS;
    int32_t nvL = p->lev[p->L]->nv;
    const int32_t *idx = p->st_v + p->st_start[o];
    int32_t n = p->st_start[o + 1] - p->st_start[o];
#ifdef CCN_V2D
    /* x and y in one register pair, z alone: each lane the same products and sums as the
     * scalar loop, so the result is bit-identical */
    ccn__v2d axy = {0, 0}, bxy = {0, 0}, cxy = {0, 0};
    double a2 = 0, b2 = 0, c2 = 0;
    for (int32_t k = 0; k < n; k++) {
        const double *q = SPOINT(idx[k]);
        ccn__v2d qxy;
        memcpy(&qxy, q, sizeof qxy);
        double a = w[0][k], b = w[1][k], c = w[2][k];
        ccn__v2d av = {a, a}, bv = {b, b}, cv = {c, c};
        axy += av * qxy; a2 += a * q[2];
        bxy += bv * qxy; b2 += b * q[2];
        cxy += cv * qxy; c2 += c * q[2];
    }
    s[0][0] = axy[0], s[0][1] = axy[1], s[0][2] = a2;
    s[1][0] = bxy[0], s[1][1] = bxy[1], s[1][2] = b2;
    s[2][0] = cxy[0], s[2][1] = cxy[1], s[2][2] = c2;
#else
    double a0 = 0, a1 = 0, a2 = 0, b0 = 0, b1 = 0, b2 = 0, c0 = 0, c1 = 0, c2 = 0;
    for (int32_t k = 0; k < n; k++) {
        const double *q = SPOINT(idx[k]);
        double a = w[0][k], b = w[1][k], c = w[2][k];
        a0 += a * q[0]; a1 += a * q[1]; a2 += a * q[2];
        b0 += b * q[0]; b1 += b * q[1]; b2 += b * q[2];
        c0 += c * q[0]; c1 += c * q[1]; c2 += c * q[2];
    }
    s[0][0] = a0, s[0][1] = a1, s[0][2] = a2;
    s[1][0] = b0, s[1][1] = b1, s[1][2] = b2;
    s[2][0] = c0, s[2][1] = c1, s[2][2] = c2;
#endif
}

/* In blocks of STENCIL_BLOCK rows: the sums of every row of the block first, then the normals
 * and curvatures (square roots and divisions on the sums' results), so that the processor
 * overlaps the rows' long dependency chains instead of waiting on each. */
#define STENCIL_BLOCK 16
static void stencil_range(void *ctx, int32_t begin, int32_t end) {
    const stencil_job *j = ctx;
    const ccn_plan *p = j->p;
    ccn_limit_mesh *out = j->out;
    double inv_scale = 1.0 / p->scale;
    /* s: x, S_u, S_v; with curvatures S_uu, S_uv, S_vv from the same points, where the row's
     * curvature stencil is its own points (curvature.c), else flagged or made later; s + 1
     * holds the five derivatives in the order of the curvature functions */
    double s[STENCIL_BLOCK][6][3];
    for (int32_t i0 = begin; i0 < end; i0 += STENCIL_BLOCK) {
        int32_t nb = end - i0 < STENCIL_BLOCK ? end - i0 : STENCIL_BLOCK;
        for (int32_t b = 0; b < nb; b++) {
            int32_t o = j->rows ? j->rows[i0 + b] : i0 + b;
            const double *w[3];
            ccn__plan_row_weights(p, o, &w[0], &w[1], &w[2]);
            row_sums(p, o, w, s[b]);
            if (out->curvatures && p->curv_mode[o] == CCN__CURV_ROW) {
                ccn__plan_row_curv_weights(p, o, &w[0], &w[1], &w[2]);
                row_sums(p, o, w, s[b] + 3);
            }
        }
        for (int32_t b = 0; b < nb; b++) {
            int32_t o = j->rows ? j->rows[i0 + b] : i0 + b;
            int curv = out->curvatures && p->curv_mode[o] == CCN__CURV_ROW;
            const double(*d)[3] = (const double(*)[3])(s[b] + 1);
            memcpy(out->positions + 3 * (size_t)o, s[b][0], sizeof s[b][0]);
            if (out->normals) ccn__unit_normal(s[b][1], s[b][2], out->normals + 3 * (size_t)o);
            if (curv && out->normals && !out->curvature_dirs) /* the unit normal made just now */
                ccn__curvature_at_unit(d, out->normals + 3 * (size_t)o, inv_scale,
                                       out->curvatures + 2 * (size_t)o);
            else if (curv)
                ccn__curvature_at(p, d, out, o);
            else if (out->curvatures && p->curv_mode[o] == CCN__CURV_FLAG)
                ccn__curvature_flag(out, o);
        }
    }
}

static void eval_stencils(const ccn_plan *p, ccn_limit_mesh *out, const int32_t *rows, int32_t nrows) {
    stencil_job j = {p, out, rows};
    ccn__parallel_for(p->threads, rows ? nrows : p->nout_v, stencil_range, &j);
}

/* Sharp features: each sector's normal, the vertex normal = their normalised sum. */
static void eval_sectors(ccn_plan *p, ccn_limit_mesh *out) {
    const double *PL = p->lev[p->L]->pos, *PS = p->posS;
    int32_t nvL = p->lev[p->L]->nv;
    for (int32_t sc = 0; sc < p->nsec; sc++) {
        double du[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
        for (int32_t k = p->sec_start[sc]; k < p->sec_start[sc + 1]; k++) {
            const double *q = SPOINT(p->sec_v[k]);
            for (int i = 0; i < 3; i++) { du[i] += p->sec_wu[k] * q[i]; dv[i] += p->sec_wv[k] * q[i]; }
        }
        ccn__unit_normal(du, dv, p->sec_nrm + 3 * (size_t)sc);
    }
    for (int32_t i = 0; i < p->nsv; i++) {
        double sum[3] = {0, 0, 0}, *n = out->normals + 3 * (size_t)p->sv_out[i];
        for (int32_t sc = p->sv_sec[i]; sc < p->sv_sec[i + 1]; sc++)
            for (int k = 0; k < 3; k++) sum[k] += p->sec_nrm[3 * (size_t)sc + k];
        double l = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
        if (l > 1e-12) for (int k = 0; k < 3; k++) n[k] = sum[k] / l;
        else memcpy(n, p->sec_nrm + 3 * (size_t)p->sv_sec[i], sizeof(double) * 3); /* a fold */
    }
}

static void eval_corner_normals(const ccn_plan *p, ccn_limit_mesh *out) {
    for (int32_t f = 0; f < p->nout_f; f++)
        for (int k = 0; k < 4; k++) {
            int32_t sc = p->corner_sec ? p->corner_sec[4 * f + k] : -1;
            const double *src = sc >= 0 ? p->sec_nrm + 3 * (size_t)sc
                                        : out->normals + 3 * (size_t)p->out_fv[4 * f + k];
            memcpy(out->corner_normals + 3 * (4 * (size_t)f + k), src, sizeof(double) * 3);
        }
}

/* Both evaluations; changed: out holds the last evaluation of the plan p was recreated from
 * (ccn_plan_evaluate_changed). */
static ccn_status evaluate(ccn_plan *p, const double *positions, ccn_limit_mesh *out, int changed,
                           ccn_error *err) {
    ccn__ok(err);
    if (!p || !out || !out->positions)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "plan, out or out->positions is NULL");
    if (out->corner_normals && !out->normals)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "corner_normals needs normals too");
    if (out->curvature_dirs && !out->curvatures)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "curvature_dirs needs curvatures too");
    struct ccn__edit_region *r = changed ? p->region : NULL;
    if (!changed && p->region) { /* the earlier plan's points are this plan's now: evaluate all */
        ccn__edit_region_free(p->region);
        p->region = NULL;
    }
    p->evaluated = 0;
    if (positions) {
        ccn_status st = ccn_mesh_set_positions(p->lev[0], positions, err);
        if (st) return st;
    } else { /* the cage's own positions, as given to ccn_plan_create */
        memcpy(p->lev[0]->pos, p->cage_pos, sizeof(double) * 3 * (size_t)p->lev[0]->nv);
    }
    /* every rule is affine-invariant: work in a unit box so that huge coordinates (1e300)
     * cannot overflow, and map back at the end */
    double *centre = p->centre, scale;
    ccn__normalize(p->lev[0], centre, &scale);
    p->scale = scale;
    p->region = NULL; /* used once, by this call */
    if (r && (memcmp(r->pos0, p->lev[0]->pos, sizeof(double) * 3 * (size_t)p->lev[0]->nv) ||
              memcmp(r->centre, centre, sizeof r->centre) || r->scale != scale)) {
        ccn__edit_region_free(r); /* the cage moved too: everything changes */
        r = NULL;
    }
    /* only the arrays the earlier plan wrote last hold what the edit did not change: any other
     * buffer (or one it did not write) is evaluated in full */
    const double *given[3] = {out->positions, out->normals, out->corner_normals};
    for (int k = 0; r && k < 3; k++)
        if (given[k] && given[k] != r->out[k]) {
            ccn__edit_region_free(r);
            r = NULL;
        }
    /* curvatures are not kept between evaluations: every row's are made again */
    if (r && out->curvatures) {
        ccn__edit_region_free(r);
        r = NULL;
    }
    if (out->curvatures) {
        ccn_status st = ccn__curvature_prepare(p, err);
        if (st) { ccn__edit_region_free(r); return st; }
    }
    for (int32_t l = 0; l < p->R; l++) {
        if (r)
            ccn__level_points_lists(&p->prep[l], r->lists[l].f, r->lists[l].nf, r->lists[l].e,
                                    r->lists[l].ne, r->lists[l].v, r->lists[l].nv, p->lev[l + 1]->pos);
        else
            ccn__level_points(&p->prep[l], p->lev[l + 1]->pos);
    }
    if (p->has_sub) {
        ccn__level_tabulate_subset(&p->sub, p->near, p->nnear);
        ccn__level_points_subset(&p->sub, p->near, p->nnear, p->posS);
    }
    uint8_t *written = NULL;
    if (r) {
        written = r->written;
        memset(written, 0, (size_t)p->nout_v);
        for (int32_t i = 0; i < r->nrows; i++) written[r->rows[i]] = 1;
        eval_stencils(p, out, r->rows, r->nrows);
        /* a cap blended with the refined limit (caps.c) reads the limit in its whole hole (not
         * one with a fill cap: that is what it is blended with), the ring faces of a cap with a
         * uniform twin read it on them */
        int32_t nb = 0, *blend = NULL;
        for (int32_t i = 0; i < p->nhv + p->nbv; i++) {
            const ccn__cap *cp = &p->caps[i < p->nhv ? p->hv_cap[i] : p->rf_cap[p->bv_rf[i - p->nhv]]];
            int32_t o = i < p->nhv ? p->hv_out[i] : p->bv_out[i - p->nhv];
            if ((i < p->nhv ? cp->w < 1 && !cp->fill : cp->exact_surround) && !written[o]) {
                if (!blend && !(blend = malloc(sizeof(int32_t) * (size_t)(p->nhv + p->nbv)))) {
                    ccn__edit_region_free(r);
                    return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
                }
                written[o] = 1;
                blend[nb++] = o;
            }
        }
        if (nb) eval_stencils(p, out, blend, nb);
        free(blend);
    } else {
        eval_stencils(p, out, NULL, 0);
    }
    if (out->normals && p->nsec) eval_sectors(p, out);
    ccn_status st = ccn__caps_evaluate(p, out, written, err);
    if (st) { ccn__edit_region_free(r); return st; }
    if (out->corner_normals) eval_corner_normals(p, out);
    if (out->curvatures) ccn__curvature_evaluate(p, out);
    for (int32_t o = 0; o < p->nout_v; o++)
        if (!written || written[o])
            for (int k = 0; k < 3; k++) out->positions[3 * (size_t)o + k] = centre[k] + scale * out->positions[3 * (size_t)o + k];
    ccn__edit_region_free(r);
    if (out->face_verts) memcpy(out->face_verts, p->out_fv, sizeof(int32_t) * 4 * (size_t)p->nout_f);
    if (out->face_origin) memcpy(out->face_origin, p->out_origin, sizeof(int32_t) * (size_t)p->nout_f);
    if (out->corner_edge_origin)
        memcpy(out->corner_edge_origin, p->out_eorigin, sizeof(int32_t) * 4 * (size_t)p->nout_f);
    if (out->edge_verts) memcpy(out->edge_verts, p->out_ev, sizeof(int32_t) * 2 * (size_t)p->nout_e);
    if (out->corner_edges) memcpy(out->corner_edges, p->out_ce, sizeof(int32_t) * 4 * (size_t)p->nout_f);
    p->last_out[0] = out->positions, p->last_out[1] = out->normals;
    p->last_out[2] = out->corner_normals;
    p->evaluated = 1;
    return CCN_OK;
}

ccn_status ccn_plan_evaluate(ccn_plan *p, const double *positions, ccn_limit_mesh *out,
                             ccn_error *err) {
    return evaluate(p, positions, out, 0, err);
}

ccn_status ccn_plan_evaluate_changed(ccn_plan *p, const double *positions, ccn_limit_mesh *out,
                                     ccn_error *err) {
    return evaluate(p, positions, out, 1, err);
}
