/* The guided bi-5 caps of a plan (K&P 2018, bi5/bi5.h): the cap level K (EVs isolated by three
 * regular rings), each EV's c-net, 1-ring and limit weights, the shared operator per valence,
 * the exact level-(K+1) surround for arbitrary non-uniform intervals (surface/surround.c), the
 * fallbacks, and their evaluation (caps and the bicubic ring faces around them). */
#include "surface/caps.h"
#include "surface/fill_cap.h"

#include "base/error.h"
#include "base/parallel.h"
#include "base/vec3.h"
#include "bi5/bi5.h"
#include "rules/bspline.h"
#include "rules/crease.h"
#include "surface/limit.h"
#include "surface/op_cache.h"
#include "surface/patches.h"
#include "surface/plan_levels.h"
#include "surface/surround.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Non-uniform spoke intervals get a cap only while every kappa_s = d_{s+1}/d_{s-1} is within
 * this factor of 1 (beyond it the measured curvature of the cap fails the acceptance
 * figures -- README "The guided bi-5 cap"); the others use the exact refined limit (counted as
 * cap fallbacks). kappa = 1 for every spoke (equal or alternating intervals) always qualifies. */
#ifndef CCN_CAP_KAPPA_RANGE /* a research build may widen it (tests/experiments/cap_table.sh) */
#define CCN_CAP_KAPPA_RANGE 1.05
#endif
/* ... and the cap is blended with the refined limit in its hole (weight w, ccn__cap.w) as the
 * largest |log kappa_s| goes from log(CCN_CAP_KAPPA_FULL) to log(CCN_CAP_KAPPA_RANGE), so the
 * surface does not jump where an EV's spokes leave the range. */
#define CCN_CAP_KAPPA_FULL 1.04
/* With options.cap = G1_FILL the bi-5 cap is blended with the G1 fill cap instead, over a wider
 * band (the two differ more than the bi-5 cap and the refined limit do: over 1.04 .. 1.05 a
 * sweep of one interval moved the surface 20x faster in the band than outside it, over
 * 1.01 .. 1.05 within 10x, tests/c/test_fill_cap.c). */
#ifndef CCN_FILL_CAP_KAPPA_FULL
#define CCN_FILL_CAP_KAPPA_FULL 1.01
#endif
/* Equal spoke intervals take the uniform operator on the level-K net; a research build may take
 * the exact surround there too (tests/experiments/RESULTS.md: the same fairness, at 2 - 3.6x the
 * evaluation time where caps are built). The two constructions differ (the exact surround's
 * first ring has speed 1/2): by 1.2e-4 - 4.7e-4 of a star's size at level 4, valence 3 - 10,
 * when one interval leaves equality by 1e-9. So while the intervals' spread log(max d / min d)
 * is below CCN_CAP_UNIFORM_BAND the uniform operator's cap and its bicubic ring faces are
 * blended with the exact-surround cap and the exact limit there (the uniform twin's weight
 * falling smoothly from 1 at equality to 0 at the band's end), and the surface moves
 * continuously as an interval leaves equality; within the band the ring faces are the exact
 * limit only up to that blend, which fades out across them (twin_ring_weight). */
#define CCN_CAP_UNIFORM_BAND 0.01
#ifndef CCN_CAP_EXACT_SURROUND_ALWAYS
#define CCN_CAP_EXACT_SURROUND_ALWAYS 0
#endif

/* Sharp edges or vertex sharpness at v (boundary edges not counted)? */
static int creased(const ccn_mesh *m, int32_t v) {
    return m->esharp && (ccn__sharp_count(m, v) > (m->vboundary[v] ? 2 : 0) || m->vsharp[v] > 0.0f);
}

/* An EV the cap is for: interior, smooth (no crease at it), valence >= 3 (valence 2 is refined
 * to the limit: surface/ring_limit.c). */
static int cap_ev(const ccn_mesh *m, int32_t v) {
    return ccn__is_ev(m, v) && ccn__valence(m, v) >= 3 && !creased(m, v);
}

void ccn__cap_free(ccn__cap *c) {
    ccn__fill_cap_destroy(c->fill);
    free(c->upatches);
    free(c->cnet); free(c->ring); free(c->l0); free(c->knots); free(c->patches); free(c->pieces);
    free(c->taus);
    memset(c, 0, sizeof *c);
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
                    if (m->vboundary[w] || ccn__valence(m, w) != 4 || creased(m, w)) return 0;
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
    for (int32_t v = 0; v < m->nv; v++) n += cap_ev(m, v);
    return n;
}

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

/* The operator for valence n: the paper's ring speeds, or (exact_surround) a first ring of
 * speed 1/2 in front of them (bi5.h [R13]). Shared by the caps of the plan, or by every plan
 * of the caller's ccn_cache. */
static const struct ccn__bi5 *cap_op(ccn_plan *p, int32_t n, int exact_surround, ccn_error *err) {
    int32_t key = exact_surround ? -n : n;
    for (int32_t i = 0; i < p->nops; i++)
        if (p->op_n[i] == key) return p->ops[i];
    static const double s5[3] = {0.75, 0.875, 0.875}, s3[1] = {15.0 / 16.0};
    static const double h5[4] = {0.5, 0.75, 0.875, 0.875}, h3[2] = {0.5, 15.0 / 16.0};
    const double *sig = exact_surround ? (n == 3 ? h3 : h5) : (n == 3 ? s3 : s5);
    int32_t nsig = (n == 3 ? 1 : 3) + (exact_surround ? 1 : 0);
    if (p->op_cache) return ccn__cache_op(p->op_cache, key, n, sig, nsig, err); /* shared */
    struct ccn__bi5 **ops = realloc(p->ops, sizeof(*ops) * ((size_t)p->nops + 1));
    if (ops) p->ops = ops;
    int32_t *op_n = realloc(p->op_n, sizeof(int32_t) * ((size_t)p->nops + 1));
    if (op_n) p->op_n = op_n;
    if (!ops || !op_n) return NULL;
    if (ccn__bi5_create(n, sig, nsig, &p->ops[p->nops], err)) return NULL;
    p->op_n[p->nops] = key;
    return p->ops[p->nops++];
}

/* Arbitrary NU intervals: switch cap c to the exact level-(K+1) surround (bi5.h [R13]) and
 * check that it exists and that the construction runs; 1 on success. */
static int cap_use_surround(ccn_plan *p, ccn__cap *c, int32_t ev, const double *zero, ccn_error *e2) {
    if (p->R < p->K + 1 && ccn__plan_build_levels(p, p->K + 1, e2)) return 0;
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
           ccn__bi5_apply_pieces(op, zero, c->pieces, c->knots, 0, c->taus, zero, NULL, c->patches, e2) == CCN_OK;
}

/* a plan made with options.previous: the earlier plan's cap at EV ev of level K, if it has taus and the same
 * spoke intervals (in the caller's units; the taus depend on their ratios only, bi5.h [R11],
 * which the power-of-two normalisation keeps to the bit), else NULL. hint_caps: the earlier
 * cap per level-K vertex, or -1. */
static const ccn__cap *same_spokes_cap(const ccn_plan *p, const int32_t *hint_caps, int32_t ev,
                                       const ccn__cap *c) {
    if (!hint_caps || hint_caps[ev] < 0) return NULL;
    const ccn__cap *h = &p->hint->caps[hint_caps[ev]];
    if (h->n != c->n || !h->taus) return NULL;
    double s = p->lev[p->K]->knot_scale, hs = p->hint->lev[p->K]->knot_scale;
    for (int32_t k = 0; k < c->n; k++) {
        double a = c->knots[k] * s, b = h->knots[k] * hs;
        if (a != b) return NULL;
    }
    return h;
}

/* A cap being set up (ccn__caps_setup's three passes): its slot in p->caps, what is left. */
typedef struct {
    int32_t ev;
    int ok, uni;       /* ok: so far; uni: equal spoke intervals */
    int need_taus;     /* non-uniform spokes whose taus are still to be solved (pass 2) */
    int need_fill;     /* a G1 fill cap whose operator is still to be solved (pass 2) */
} cap_todo;

/* Pass 1 (serial): the cap of EV ev at level K in slot c: its net, ring, spoke intervals,
 * limit weights, the kappa range, and its taus when the earlier plan has them. */
static void cap_begin(ccn_plan *p, int32_t ev, const int32_t *hint_caps, ccn__cap *c, cap_todo *t) {
    const ccn_mesh *m = p->lev[p->K];
    int32_t n = ccn__valence(m, ev);
    memset(c, 0, sizeof *c);
    memset(t, 0, sizeof *t);
    t->ev = ev;
    if (n > CCN_CAP_MAX_VALENCE) return;
    ccn_error e2;
    const struct ccn__bi5 *op = cap_op(p, n, 0, &e2);
    if (!op) return;
    c->n = n;
    c->op = op;
    c->cnet = malloc(sizeof(int32_t) * (6 * (size_t)n + 1));
    c->ring = malloc(sizeof(int32_t) * (2 * (size_t)n + 1));
    c->l0 = malloc(sizeof(double) * 3 * (2 * (size_t)n + 1)); /* limit point, then tangents */
    c->knots = malloc(sizeof(double) * (size_t)n);
    c->patches = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(op));
    ccn__stencil *s = malloc(sizeof *s);
    int ok = c->cnet && c->ring && c->l0 && c->knots && c->patches && s;
    if (ok) {
        cap_cnet(m, ev, n, c->cnet);
        ccn__ev_ring(m, ev, c->ring);
        for (int32_t k = 0; k < n; k++) c->knots[k] = m->eknot[ccn__fan_edge(m, ev, k)];
        ok = ccn__ev_limit(m, ev, p->opts.scheme, p->opts.ev_polyhedron, p->ev_cache, s, &e2) == CCN_OK;
        for (int32_t j = 0; ok && j < 2 * n + 1; j++)
            c->l0[j] = s->wp[j], c->l0[2 * n + 1 + j] = s->wu[j], c->l0[4 * n + 2 + j] = s->wv[j];
        int nu = 0, uni = 1; /* some kappa_s = d_{s+1}/d_{s-1} != 1: taus, once (no positions) */
        double dmin = c->knots[0], dmax = c->knots[0];
        const double krange = CCN_CAP_KAPPA_RANGE;
        double lk = 0;
        for (int32_t k = 0; k < n; k++) {
            double kap = c->knots[(k + 1) % n] / c->knots[(k + n - 1) % n];
            nu |= fabs(kap - 1.0) > 1e-12;
            uni &= fabs(c->knots[k] / c->knots[0] - 1.0) <= 1e-12;
            dmin = fmin(dmin, c->knots[k]), dmax = fmax(dmax, c->knots[k]);
            lk = fmax(lk, fabs(log(kap)));
            if (kap > krange * (1 + 1e-12) || kap * krange < 1 - 1e-12) ok = 0; /* measured range */
        }
        double kfull = p->opts.cap == CCN_CAP_G1_FILL ? CCN_FILL_CAP_KAPPA_FULL : CCN_CAP_KAPPA_FULL;
        double x = (log(krange) - lk) / (log(krange) - log(kfull));
        c->w = x >= 1 ? 1.0 : x <= 0 ? 0.0 : x * x * (3 - 2 * x);
        if (!(c->w > 0)) ok = 0; /* at the range's end the refined limit alone */
        t->uni = uni;
        double spread = log(dmax / dmin) / CCN_CAP_UNIFORM_BAND; /* the uniform twin's weight */
        c->wu = uni || !(spread < 1) || CCN_CAP_EXACT_SURROUND_ALWAYS ? 0.0 : 1 - spread * spread * (3 - 2 * spread);
        /* beyond the bi-5 cap's whole range: the G1 fill cap (its operator in pass 2), blended
         * with the bi-5 cap while that has weight */
        if (p->opts.cap == CCN_CAP_G1_FILL && c->w < 1 && n >= CCN_FILL_CAP_MIN_VALENCE &&
            (p->R >= p->K + 1 || ccn__plan_build_levels(p, p->K + 1, &e2) == CCN_OK)) {
            int r = ccn__fill_cap_create(p, ev, n, c->knots, &c->fill);
            t->need_fill = r > 0;
        }
        if (ok && nu) {
            c->taus = malloc(sizeof(double complex) * 36 * (size_t)n);
            const ccn__cap *h = c->taus ? same_spokes_cap(p, hint_caps, ev, c) : NULL;
            if (h) memcpy(c->taus, h->taus, sizeof(double complex) * 36 * (size_t)n); /* the same taus */
            else if (c->taus) t->need_taus = 1;
            else ok = 0;
        }
    }
    free(s);
    t->ok = ok;
}

/* Pass 2 (the plan's threads): the taus of the caps that need them (bi5.h [R11]); each solve
 * reads its cap and the shared operator only. */
typedef struct { ccn__cap *caps; cap_todo *todo; const int32_t *list; } taus_job;

static void taus_range(void *ctx, int32_t begin, int32_t end) {
    const taus_job *j = ctx;
    for (int32_t k = begin; k < end; k++) {
        int32_t i = j->list[k];
        cap_todo *t = &j->todo[i];
        ccn__cap *c = &j->caps[i];
        ccn_error e2;
        if (t->ok && t->need_taus) t->ok = ccn__bi5_nu_taus(c->op, c->knots, 0, c->taus, &e2) == CCN_OK;
        if (t->need_fill && ccn__fill_cap_solve(c->fill) <= 0) {
            ccn__fill_cap_destroy(c->fill);
            c->fill = NULL;
        }
    }
}

/* Pass 3 (serial, in EV order): the patches of the cap in slot c (its taus known); 1 if it is
 * kept, 0 for a fallback (the slot freed). */
static int cap_finish(ccn_plan *p, ccn__cap *c, const cap_todo *t) {
    int ok = t->ok;
    if (ok) {
        ccn_error e2;
        double *zero = calloc(3 * (6 * (size_t)c->n + 1), sizeof(double));
        ok = zero != NULL;
        /* Equal spoke intervals: the uniform operator on the level-K net, whose bicubic surround
         * is the limit itself. Any other intervals (kappa = 1 alternating and period 4 too, whose
         * level-K surround is not the limit: measured 5e-5 .. 6e-3 off): the exact
         * level-(K+1) surround and the exact centre normal (bi5.h [R13], [R14]). */
        if (ok && t->uni && !CCN_CAP_EXACT_SURROUND_ALWAYS)
            ok = ccn__bi5_apply_cached(c->op, zero, c->knots, c->taus, zero, c->patches, &e2) == CCN_OK;
        else if (ok && c->wu > 0) { /* the uniform twin: the operator the cap has so far */
            c->uop = c->op;
            c->upatches = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(c->uop));
            ok = c->upatches && cap_use_surround(p, c, t->ev, zero, &e2);
        } else if (ok) ok = cap_use_surround(p, c, t->ev, zero, &e2);
        free(zero);
    }
    if (!ok && c->fill) { /* the fill alone */
        free(c->taus); free(c->pieces); free(c->patches); free(c->upatches);
        c->taus = NULL, c->pieces = NULL, c->patches = NULL, c->upatches = NULL;
        c->w = 0, c->wu = 0;
        c->exact_surround = 1; /* its surround is the limit itself */
        return 1;
    }
    if (!ok) ccn__cap_free(c);
    return ok;
}

/* Chooses K, builds the caps. A cap at level K >= L (the output level) changes nothing: every
 * output sample of its hole is the EV itself (the exact limit point; [R14] its exact normal) or
 * lies on the hole's border (the exact limit), so no cap is built then (measured equal to
 * 4e-16 in position and 4e-12 rad in normal on the shipped cages). */
ccn_status ccn__caps_setup(ccn_plan *p, ccn_error *err) {
    p->K = -1;
    if (p->opts.cap != CCN_CAP_GUIDED_BI5 && p->opts.cap != CCN_CAP_G1_FILL) return CCN_OK;
    ccn_status st0 = ccn__plan_build_levels(p, 1, err);
    if (st0) return st0;
    if (count_evs(p->lev[1]) == 0) return CCN_OK;
    int32_t K = 2;
    for (; K <= 4; K++) {
        if (K >= p->L) { /* no cap level below the output level: nothing to do */
            p->caps_deferred = count_evs(p->lev[1]);
            return CCN_OK;
        }
        ccn_status st = ccn__plan_build_levels(p, K, err);
        if (st) return st;
        const ccn_mesh *m = p->lev[K];
        int32_t *stamp = malloc(sizeof(int32_t) * (size_t)m->nv), *q = malloc(sizeof(int32_t) * (size_t)m->nv);
        if (!stamp || !q) { free(stamp); free(q); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
        for (int32_t v = 0; v < m->nv; v++) stamp[v] = -1;
        int all = 1;
        for (int32_t v = 0; v < m->nv && all; v++)
            if (cap_ev(m, v) && !cap_isolated(m, v, stamp, q)) all = 0;
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
    int32_t *hint_caps = NULL; /* a plan made with options.previous: the earlier plan's caps by EV */
    if (p->hint && p->hint->K == K && p->hint->ncap && p->hint->lev[K]->nv == m->nv &&
        (hint_caps = malloc(sizeof(int32_t) * (size_t)m->nv))) {
        for (int32_t v = 0; v < m->nv; v++) hint_caps[v] = -1;
        for (int32_t c = 0; c < p->hint->ncap; c++) hint_caps[p->hint->caps[c].cnet[0]] = c;
    }
    cap_todo *todo = malloc(sizeof(cap_todo) * (size_t)(nev ? nev : 1));
    if (!todo) { free(hint_caps); free(stamp); free(q); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
    int32_t ncand = 0; /* pass 1: every cap EV in order, a slot each */
    for (int32_t v = 0; v < m->nv; v++) {
        if (!cap_ev(m, v)) continue;
        if (!cap_isolated(m, v, stamp, q)) { p->stats.num_cap_fallbacks++; continue; }
        cap_begin(p, v, hint_caps, &p->caps[ncand], &todo[ncand]);
        ncand++;
    }
    int32_t nsolve = 0; /* pass 2: the tau solves (each a few ms), spread over the threads */
    int32_t *solve = malloc(sizeof(int32_t) * (size_t)(ncand ? ncand : 1));
    for (int32_t i = 0; solve && i < ncand; i++)
        if ((todo[i].ok && todo[i].need_taus) || todo[i].need_fill) solve[nsolve++] = i;
    if (!solve) /* out of memory: those caps fall back */
        for (int32_t i = 0; i < ncand; i++) {
            todo[i].ok &= !todo[i].need_taus;
            if (todo[i].need_fill) ccn__fill_cap_destroy(p->caps[i].fill), p->caps[i].fill = NULL;
        }
    taus_job tj = {p->caps, todo, solve};
    ccn__parallel_for(p->threads, nsolve, taus_range, &tj);
    free(solve);
    for (int32_t i = 0; i < ncand; i++) { /* pass 3: in EV order; the kept caps packed */
        ccn__cap c = p->caps[i];
        if (cap_finish(p, &c, &todo[i])) p->caps[p->ncap++] = c;
        else p->stats.num_cap_fallbacks++;
    }
    free(todo);
    free(hint_caps);
    free(stamp); free(q);
    p->stats.num_caps = p->ncap;
    int32_t maxn = 0;
    for (int32_t c = 0; c < p->ncap; c++) maxn = p->caps[c].n > maxn ? p->caps[c].n : maxn;
    p->cap_net = malloc(sizeof(double) * 3 * (6 * (size_t)maxn + 1));
    if (!p->cap_net) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    return CCN_OK;
}

/* ---- caps from meshes alone (the CAD export's holes) --------------------------------------- */

/* The EV's limit point ctr and unit normal nrm from its 1-ring (ring, 2n+1 points of P) and the
 * limit weights wp, wu, wv over it. */
static void ring_frame(const double *P, const int32_t *ring, int32_t n, const double *wp,
                       const double *wu, const double *wv, double ctr[3], double nrm[3]) {
    double tu[3] = {0, 0, 0}, tv[3] = {0, 0, 0};
    ctr[0] = ctr[1] = ctr[2] = 0;
    for (int32_t j = 0; j < 2 * n + 1; j++)
        for (int i = 0; i < 3; i++) {
            double x = P[3 * (size_t)ring[j] + i];
            ctr[i] += wp[j] * x;
            tu[i] += wu[j] * x;
            tv[i] += wv[j] * x;
        }
    ccn__unit_normal(tu, tv, nrm);
}

/* Adds sign * org to np points. A cap is built with its EV's limit point as origin (the
 * construction is affine invariant): a cap is small against its coordinates, its inner rings
 * far smaller, and their joins keep G1 to the rounding of the cap's own size, not of its place
 * (the unit cube's exported caps met within 1.1e-11 rad in absolute coordinates, 3.4e-13 so;
 * the cube moved to (1000, 1000, 1000): 1.2e-7 against 7.6e-10; caps of holes 7 levels down
 * 1e-7 against 4.5e-12). */
static void translate(double *pts, size_t np, const double org[3], double sign) {
    for (size_t j = 0; j < np; j++)
        for (int i = 0; i < 3; i++) pts[3 * j + i] += sign * org[i];
}


void ccn__cap_ops_free(struct ccn__bi5 **ops) {
    for (int32_t n = 0; n < CCN_CAP_OPS; n++) {
        ccn__bi5_destroy(ops[n]);
        ops[n] = NULL;
    }
}

int ccn__cap_exact(const ccn_mesh *mK, const ccn_mesh *mK1, int32_t ev, int scheme,
                   int32_t ev_poly, ccn__ev_cache *cache, int pinned, int any_kappa, double border_exp,
                   int rings, struct ccn__bi5 **ops, const struct ccn__bi5 **op, double **patches) {
    *patches = NULL;
    if (ev < 0 || ev >= mK->nv || !cap_ev(mK, ev)) return 0;
    int32_t n = ccn__valence(mK, ev);
    if (n > CCN_CAP_MAX_VALENCE) return 0;
    double *knots = malloc(sizeof(double) * (size_t)n);
    if (!knots) return -1;
    int nu = 0, beyond = 0; /* the spoke ratios first: outside the range nothing else is needed */
    for (int32_t k = 0; k < n; k++) knots[k] = mK->eknot[ccn__fan_edge(mK, ev, k)];
    for (int32_t k = 0; k < n; k++) { /* within the range where the plan's caps are whole */
        double kap = knots[(k + 1) % n] / knots[(k + n - 1) % n];
        nu |= fabs(kap - 1.0) > 1e-12;
        beyond |= fabs(log(kap)) > log(CCN_CAP_KAPPA_FULL);
    }
    if (beyond && !any_kappa) {
        free(knots);
        return 0;
    }
    if (!beyond) border_exp = 0; /* within the range: the plan's construction */
    ccn_error e2;
    /* Two operators. ops[n]: the first ring (speed 1/2, which takes the exact surround) and the
     * G1 cap right after it, the holes' default. The plan's further rings (3/4, 7/8, 7/8;
     * valence 3: 15/16) leave a cap 1/512 (1/16) of the hole's size; several levels below the
     * cage its poles near the EV lie so close together that their rounding to doubles at their
     * absolute coordinates turns the normals across its spokes (catmark_bishop 4e-8 rad at
     * valence 3; cube_semi moved by 1000: 4.5e-9), and the rings cost faces. Without them: G1
     * to 1e-13 instead of 1e-12 (fans of valence 5-8 with semi-sharp spokes), bishop 3.2e-9 rad
     * as OpenCASCADE reads it, catmark_car 29.8 MB instead of 35.9, and the curvature is the
     * surround's either way (the cap's largest |K| over that of the exact pieces around it:
     * cube_semi 1.70-2.00 against 1.75-2.07, the fans 1.89-4.64 against 1.92-4.95, the car's
     * 30 hole caps of valence 5+ median 1.58 against 1.59, the smallest K unchanged; reflection
     * lines alike). ops[CCN_CAP_OPS / 2 + n] (rings = 1, n >= 5): the plan's rings after the
     * first, which the export keeps beyond the kappa range (io/fill.c), where the cap right
     * after the first ring dips into a saddle (star5_nu) or kinks the reflection lines
     * (star7_nu). The plan's own caps are what the modifier shows and keep the paper's speeds. */
    int32_t slot = rings && n != 3 ? CCN_CAP_OPS / 2 + n : n;
    if (!ops[slot]) {
        static const double h5[4] = {0.5, 0.75, 0.875, 0.875};
        ccn_status st = ccn__bi5_create(n, h5, slot == n ? 1 : 4, &ops[slot], &e2);
        if (st) {
            free(knots);
            return st == CCN_ERR_MEMORY ? -1 : 0;
        }
    }
    *op = ops[slot];
    int32_t *stamp = malloc(sizeof(int32_t) * ((size_t)mK->nv + 1));
    int32_t *queue = malloc(sizeof(int32_t) * ((size_t)mK->nv + 1));
    int32_t *cnet = malloc(sizeof(int32_t) * (6 * (size_t)n + 1));
    int32_t *ring = malloc(sizeof(int32_t) * (2 * (size_t)n + 1));
    double *net = malloc(sizeof(double) * 3 * (6 * (size_t)n + 1));
    double *pieces = malloc(sizeof(double) * 432 * (size_t)n);
    double *out = malloc(sizeof(double) * 108 * (size_t)ccn__bi5_num_patches(*op));
    double complex *taus = NULL;
    ccn__stencil *s = malloc(sizeof *s);
    int r = -1;
    if (!stamp || !queue || !cnet || !ring || !net || !pieces || !out || !s) goto done;
    r = 0;
    for (int32_t v = 0; v < mK->nv; v++) stamp[v] = -1;
    if (!cap_isolated(mK, ev, stamp, queue)) goto done;
    if (!ccn__cap_surround(mK, mK1, ev, pinned, pieces)) goto done;
    if (nu) {
        taus = malloc(sizeof(double complex) * 36 * (size_t)n);
        if (!taus) { r = -1; goto done; }
        if (ccn__bi5_nu_taus(*op, knots, border_exp, taus, &e2)) goto done;
    }
    if (ccn__ev_limit(mK, ev, scheme, ev_poly, cache, s, &e2)) goto done;
    ccn__ev_ring(mK, ev, ring);
    double org[3], nrm[3];
    const double zero[3] = {0, 0, 0};
    ring_frame(mK->pos, ring, n, s->wp, s->wu, s->wv, org, nrm);
    cap_cnet(mK, ev, n, cnet);
    for (int32_t j = 0; j < 6 * n + 1; j++) memcpy(net + 3 * j, mK->pos + 3 * (size_t)cnet[j], sizeof(double) * 3);
    translate(net, 6 * (size_t)n + 1, org, -1);
    translate(pieces, 144 * (size_t)n, org, -1);
    if (ccn__bi5_apply_pieces(*op, net, pieces, knots, border_exp, taus, zero, isfinite(nrm[0]) ? nrm : NULL, out, &e2))
        goto done;
    translate(out, 36 * (size_t)ccn__bi5_num_patches(*op), org, 1);
    *patches = out;
    out = NULL;
    r = 1;
done:
    free(stamp); free(queue); free(cnet); free(ring); free(knots); free(net); free(pieces);
    free(out); free(taus); free(s);
    return r;
}

/* a = the unit normal of w b + (1 - w) a (a, b unit). */
static void blend_normal(double a[3], const double b[3], double w) {
    double m[3];
    for (int k = 0; k < 3; k++) m[k] = w * b[k] + (1 - w) * a[k];
    double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    for (int k = 0; k < 3; k++) a[k] = m[k] / l;
}

/* The weight of a uniform twin's ring face rf at its (u, v) (face frame, corner j at UNIT[j]):
 * wu at the corners on the cap's 1-ring (the hole's border, p->rf_on), 0 at the others, in
 * between the tensor product of smoothsteps, so that the weight and its slope across the face's
 * edges are continuous and vanish on the ring's outer edge: there the surface is the exact
 * limit, C1. */
static double twin_ring_weight(const ccn_plan *p, const ccn__cap *cp, int32_t rf, double u, double v) {
    double su = u * u * (3 - 2 * u), sv = v * v * (3 - 2 * v), t = 0;
    const double h[4] = {(1 - su) * (1 - sv), su * (1 - sv), su * sv, (1 - su) * sv};
    for (int j = 0; j < 4; j++) t += p->rf_on[rf] >> j & 1 ? h[j] : 0;
    return cp->wu * t;
}

/* The faces around each hole: bicubic patches of the level-K net (see surface/plan_types.h);
 * around a cap with a uniform twin (wu > 0) blended with the exact limit already there
 * (twin_ring_weight). */
static void eval_ring_faces(ccn_plan *p, ccn_limit_mesh *out, uint8_t *written) {
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
        if (written) written[o] = 1;
        const ccn__cap *cp = &p->caps[p->rf_cap[p->bv_rf[i]]];
        double wr = cp->exact_surround ? twin_ring_weight(p, cp, p->bv_rf[i], p->bv_uv[2 * i], p->bv_uv[2 * i + 1]) : 1;
        double *po = out->positions + 3 * (size_t)o;
        double *no = out->normals ? out->normals + 3 * (size_t)o : NULL, nn[3];
        if (wr < 1)
            for (int k = 0; k < 3; k++) po[k] = wr * x[k] + (1 - wr) * po[k];
        else
            memcpy(po, x, sizeof x);
        if (!no) continue;
        ccn__unit_normal(du, dv, nn);
        if (wr < 1) blend_normal(no, nn, wr);
        else memcpy(no, nn, sizeof nn);
    }
}

ccn_status ccn__caps_evaluate(ccn_plan *p, ccn_limit_mesh *out, uint8_t *written, ccn_error *err) {
    if (p->ncap == 0) return CCN_OK;
    const double *P = p->lev[p->K]->pos;
    for (int32_t c = 0; c < p->ncap; c++) {
        ccn__cap *cp = &p->caps[c];
        if (cp->fill && !ccn__fill_cap_update(p, cp->fill))
            return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, cp->cnet[0], "fill cap border lost");
        if (!(cp->w > 0)) continue; /* the fill alone */
        int32_t n = cp->n, nc = 6 * n + 1;
        double *net = p->cap_net, ctr[3] = {0, 0, 0}, org[3], nrm[3]; /* ctr: at the origin */
        for (int32_t j = 0; j < nc; j++) memcpy(net + 3 * j, P + 3 * (size_t)cp->cnet[j], sizeof(double) * 3);
        ring_frame(P, cp->ring, n, cp->l0, cp->l0 + 2 * n + 1, cp->l0 + 4 * n + 2, org, nrm);
        translate(net, (size_t)nc, org, -1); /* built around the EV (translate) */
        ccn_status st;
        if (cp->exact_surround) {
            int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
            if (!ccn__cap_surround(p->lev[p->K], p->lev[p->K + 1], cp->cnet[0], pinned, cp->pieces))
                return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_VERTEX, cp->cnet[0], "cap surround lost");
            translate(cp->pieces, 144 * (size_t)n, org, -1);
            st = ccn__bi5_apply_pieces(cp->op, net, cp->pieces, cp->knots, 0, cp->taus, ctr,
                                       isfinite(nrm[0]) ? nrm : NULL, cp->patches, err);
        } else if (isfinite(nrm[0])) {
            st = ccn__bi5_apply_normal(cp->op, net, cp->knots, cp->taus, ctr, nrm, cp->patches, err);
        } else {
            st = ccn__bi5_apply_cached(cp->op, net, cp->knots, cp->taus, ctr, cp->patches, err);
        }
        if (!st && cp->wu > 0) /* the uniform twin on the level-K net */
            st = isfinite(nrm[0]) ? ccn__bi5_apply_normal(cp->uop, net, NULL, NULL, ctr, nrm, cp->upatches, err)
                                  : ccn__bi5_apply_cached(cp->uop, net, NULL, NULL, ctr, cp->upatches, err);
        if (st) return st;
        translate(cp->patches, 36 * (size_t)ccn__bi5_num_patches(cp->op), org, 1);
        if (cp->wu > 0) translate(cp->upatches, 36 * (size_t)ccn__bi5_num_patches(cp->uop), org, 1);
    }
    for (int32_t i = 0; i < p->nhv; i++) {
        const ccn__cap *cp = &p->caps[p->hv_cap[i]];
        double x[3], du[3], dv[3], w = cp->w, u = p->hv_uv[2 * i], v = p->hv_uv[2 * i + 1];
        int32_t o = p->hv_out[i], k = p->hv_sector[i];
        if (written) written[o] = 1;
        double *po = out->positions + 3 * (size_t)o, *no = out->normals ? out->normals + 3 * (size_t)o : NULL;
        if (cp->fill) { /* the G1 fill cap: alone, or what the bi-5 cap is blended with */
            ccn__fill_cap_eval(cp->fill, k, u, v, po, du, dv, NULL);
            if (no) ccn__unit_normal(du, dv, no);
            if (!(w > 0)) continue;
        }
        double nn[3];
        ccn__bi5_eval(cp->op, cp->patches, k, u, v, x, du, dv);
        ccn__unit_normal(du, dv, nn);
        if (cp->wu > 0) { /* near-equal intervals: with the uniform operator's cap */
            double xu[3], duu[3], dvu[3], n2[3];
            ccn__bi5_eval(cp->uop, cp->upatches, k, u, v, xu, duu, dvu);
            ccn__unit_normal(duu, dvu, n2);
            for (int q = 0; q < 3; q++) x[q] = cp->wu * xu[q] + (1 - cp->wu) * x[q];
            blend_normal(nn, n2, cp->wu);
        }
        if (w < 1) { /* near the end of the cap's range: blended with the fill cap, or with the
                      * refined limit (there) */
            for (int q = 0; q < 3; q++) po[q] = w * x[q] + (1 - w) * po[q];
            if (no) {
                if (nn[0] * no[0] + nn[1] * no[1] + nn[2] * no[2] < 0)
                    for (int q = 0; q < 3; q++) nn[q] = -nn[q];
                blend_normal(no, nn, w);
            }
            continue;
        }
        memcpy(po, x, sizeof x);
        if (no) memcpy(no, nn, sizeof nn);
    }
    eval_ring_faces(p, out, written);
    return CCN_OK;
}

/* ---- the output's extraordinary points and their caps (ccn_plan_get_evs) ----------------- */

ccn_status ccn_plan_get_evs(const ccn_plan *p, int32_t *num, int32_t *out_vertex, int32_t *surface) {
    if (!p || !num) return CCN_ERR_ARGUMENT;
    const ccn_mesh *mL = p->lev[p->L];
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    /* each cap's EV: its level-K vertex carried to level L (vertex point v -> nf + ne + v) */
    uint8_t *capped = p->ncap ? calloc((size_t)mL->nv, 1) : NULL;
    if (p->ncap && !capped) return CCN_ERR_MEMORY;
    for (int32_t c = 0; c < p->ncap; c++) {
        int32_t v = p->caps[c].cnet[0];
        for (int32_t l = p->K; l < p->L; l++) v += p->lev[l]->nf + p->lev[l]->ne;
        capped[v] = p->caps[c].w >= 1 ? 1 : p->caps[c].w > 0 ? 2 : 3;
    }
    int32_t n = 0;
    for (int32_t o = 0; o < p->nout_v; o++) {
        int32_t v = p->out_vL[o];
        if (ccn__limit_kind(mL, v, pinned) != CCN_LIMIT_EV) continue;
        if (out_vertex) out_vertex[n] = o;
        if (surface)
            surface[n] = !capped || !capped[v] ? CCN_EV_REFINED
                         : capped[v] == 1 ? CCN_EV_CAPPED : capped[v] == 2 ? CCN_EV_CAP_BLENDED : CCN_EV_FILLED;
        n++;
    }
    free(capped);
    *num = n;
    return CCN_OK;
}
