/* Face-varying channels and per-vertex data on a plan's output (surface/plan_fvar.h).
 *
 * A channel is the value mesh of refine/fvar.c refined through the plan's L levels in
 * lockstep with the vertex levels (their intervals and creases), plus the exact limit stencil
 * of every level-L value vertex built as for positions (surface/limit.c on the value mesh:
 * tensor B-spline stencils where the 3x3 neighbourhood is regular, one level finer next to
 * irregular value vertices, the stationary 1-ring matrix on seams, corners and creases, the
 * left eigenvectors of M at EVs, taken over from the positions' stencil where the value
 * vertex matches the vertex). Evaluation re-runs only the arithmetic: values through the
 * levels (3 components at a time), then the stencils. Mode ALL is bilinear: the level-L values
 * are the limit. Per-vertex data runs through the plan's own levels and stencils, on scratch
 * positions, so the plan's geometry stays that of the last ccn_plan_evaluate.
 */
#include "surface/plan_fvar.h"

#include "base/error.h"
#include "base/parallel.h"
#include "refine/fvar.h"
#include "surface/limit.h"

#include <math.h>
#include <string.h>

struct ccn__fvchan {
    int32_t width, ncage;
    double *cage_values;      /* width * ncage: the values given to ccn_plan_add_fvar */
    int32_t *value_of;        /* level-0 value vertex -> cage value */
    int32_t L;
    ccn__fvar_level *lev;     /* L + 1 levels */
    ccn__level *prep;         /* L prepared levels */
    ccn__level sub;           /* level L -> L+1 around near[] (has_sub) */
    int has_sub;
    double *posS;             /* level-(L+1) points, 3 * (nf + ne + nv) of level L */
    int32_t nnear, *near;
    int32_t *st_start, *st_v; /* CSR per level-L value vertex; index >= nvL: an (L+1) point */
    double *st_w;
    int bilinear;
    int32_t num_seams, num_sharp;
};

void ccn__fvchan_free(struct ccn__fvchan *c) {
    if (!c) return;
    for (int32_t l = 0; c->lev && l <= c->L; l++) ccn__fvar_free(&c->lev[l]);
    for (int32_t l = 0; c->prep && l < c->L; l++) ccn__level_free(&c->prep[l]);
    if (c->has_sub) ccn__level_free(&c->sub);
    free(c->lev); free(c->prep); free(c->posS); free(c->near); free(c->cage_values);
    free(c->value_of); free(c->st_start); free(c->st_v); free(c->st_w);
    free(c);
}

/* ---- building a channel --------------------------------------------------------------- */

typedef struct { int32_t n, cap; int32_t *v; double *w; } wbuf;

static int push(wbuf *b, const ccn__stencil *s, int32_t off) {
    if (b->n + s->n > b->cap) {
        int64_t nc = 2 * (int64_t)b->cap + s->n + 1024;
        if (nc > INT32_MAX) return -1;
        int32_t *v = realloc(b->v, sizeof(int32_t) * (size_t)nc);
        if (v) b->v = v;
        double *w = realloc(b->w, sizeof(double) * (size_t)nc);
        if (w) b->w = w;
        if (!v || !w) return -1;
        b->cap = (int32_t)nc;
    }
    for (int i = 0; i < s->n; i++) {
        b->v[b->n] = s->v[i] + off;
        b->w[b->n++] = s->wp[i];
    }
    return 0;
}

static int near_irregular(const ccn_mesh *m, int32_t v, const uint8_t *irr) {
    if (irr[v]) return 1;
    for (int32_t k = m->vfan_start[v]; k < m->vfan_start[v + 1]; k++) {
        int32_t f = m->hface[m->vfan[k]];
        for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++)
            if (irr[m->hvert[h]]) return 1;
    }
    return 0;
}

/* A value vertex u at an interior EV of the value mesh has the vertex's fan, intervals and
 * scheme: its child stencil is the positions' stencil of vertex v, renumbered (level L+1 face
 * points keep their index, the edge points of v's spokes and v's vertex point map to u's). */
static int reuse_ev_stencil(const ccn_plan *p, const ccn_mesh *fm, int32_t u, int32_t v,
                            ccn__stencil *s) {
    const ccn_mesh *vm = p->lev[p->L];
    int32_t o = p->vmapL[v], nvL = vm->nv;
    if (o < 0) return 0;
    s->n = 0;
    for (int32_t k = p->st_start[o]; k < p->st_start[o + 1]; k++) {
        int32_t i = p->st_v[k] - nvL, j = -1;
        if (i < 0 || s->n >= CCN_STENCIL_MAX) return 0;
        if (i < vm->nf) j = i;
        else if (i >= vm->nf + vm->ne) j = i == vm->nf + vm->ne + v ? fm->nf + fm->ne + u : -1;
        else
            for (int32_t q = vm->vfan_start[v]; q < vm->vfan_start[v + 1] && j < 0; q++)
                if (vm->hedge[vm->vfan[q]] == i - vm->nf) j = fm->nf + fm->hedge[vm->vfan[q]];
        if (j < 0) return 0;
        s->v[s->n] = j; s->wp[s->n] = p->st_wp[k]; s->wu[s->n] = s->wv[s->n] = 0.0;
        s->n++;
    }
    return 1;
}

static ccn_status channel_stencils(const ccn_plan *p, struct ccn__fvchan *c, ccn_error *err) {
    const ccn__fvar_level *fl = &c->lev[c->L];
    const ccn_mesh *m = fl->m;
    ccn__stencil *s = malloc(sizeof *s);
    ccn__ring_limit *ring = malloc(sizeof *ring);
    ccn__ring_work *work = ccn__ring_work_create();
    uint8_t *irr = malloc((size_t)m->nv);
    wbuf b = {0, 0, NULL, NULL};
    c->st_start = malloc(sizeof(int32_t) * ((size_t)m->nv + 1));
    c->near = malloc(sizeof(int32_t) * (size_t)m->nv);
    ccn_status st = CCN_OK;
    if (!s || !ring || !work || !irr || !c->st_start || !c->near) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    c->st_start[0] = 0;
    for (int32_t v = 0; v < m->nv; v++) irr[v] = ccn__limit_kind(m, v, 0) != CCN_LIMIT_REGULAR;
    for (int32_t v = 0; v < m->nv && !st; v++) {
        int32_t off = 0;
        if (!near_irregular(m, v, irr)) {
            ccn__limit_stencil(m, v, 0, s);
        } else {
            c->near[c->nnear++] = v;
            off = m->nv;
            if (!(ccn__limit_kind(m, v, 0) == CCN_LIMIT_EV && reuse_ev_stencil(p, m, v, fl->vvert[v], s)))
                st = ccn__child_limit_stencil(m, v, 0, p->opts.scheme, p->opts.crease_method, work, s,
                                              ring, err);
        }
        if (!st && push(&b, s, off))
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        c->st_start[v + 1] = b.n;
    }
done:
    c->st_v = b.v;
    c->st_w = b.w;
    free(s); free(ring); free(irr);
    ccn__ring_work_destroy(work);
    return st;
}

static ccn_status build_channel(ccn_plan *p, const ccn_fvar_channel *ch, struct ccn__fvchan *c,
                                ccn_error *err) {
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    c->width = ch->width;
    c->ncage = ch->num_values;
    c->L = p->L;
    c->bilinear = ch->linear == CCN_FVAR_LINEAR_ALL;
    size_t nval = (size_t)ch->width * (size_t)ch->num_values;
    c->cage_values = malloc(sizeof(double) * nval);
    c->lev = calloc((size_t)c->L + 1, sizeof *c->lev);
    c->prep = calloc((size_t)(c->L ? c->L : 1), sizeof *c->prep);
    if (!c->cage_values || !c->lev || !c->prep)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    memcpy(c->cage_values, ch->values, sizeof(double) * nval);
    ccn_status st = ccn__fvar_build(p->lev[0], ch->indices, ch->linear, pinned, &c->lev[0], &c->value_of, err);
    if (st) return st;
    c->num_seams = c->lev[0].num_seams;
    for (int32_t l = 0; l < c->L; l++) {
        if ((st = ccn__fvar_prepare(&c->prep[l], &c->lev[l], p->opts.scheme, p->opts.crease_method, err))) {
            memset(&c->prep[l], 0, sizeof c->prep[l]);
            return st;
        }
        c->prep[l].threads = p->threads;
        if ((st = ccn__fvar_child(&c->lev[l], &c->prep[l], p->lev[l], p->lev[l + 1], &c->lev[l + 1], err)))
            return st;
    }
    const ccn_mesh *mL = c->lev[c->L].m;
    c->num_sharp = ccn__fvar_num_sharp(&c->lev[c->L]);
    if (c->bilinear) return CCN_OK;
    if ((st = channel_stencils(p, c, err))) return st;
    if (c->nnear) {
        if ((st = ccn__fvar_prepare(&c->sub, &c->lev[c->L], p->opts.scheme, p->opts.crease_method, err)))
            return st;
        c->has_sub = 1;
        c->posS = malloc(sizeof(double) * 3 * ((size_t)mL->nf + mL->ne + mL->nv));
        if (!c->posS) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    return CCN_OK;
}

ccn_status ccn_plan_add_fvar(ccn_plan *p, const ccn_fvar_channel *ch, int32_t *channel,
                             ccn_error *err) {
    ccn__ok(err);
    if (!p) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "plan is NULL");
    ccn_status st = ccn__fvar_check(p->lev[0], ch, err);
    if (st) return st;
    struct ccn__fvchan **fv = realloc(p->fv, sizeof *fv * ((size_t)p->nfv + 1));
    struct ccn__fvchan *c = calloc(1, sizeof *c);
    if (fv) p->fv = fv;
    if (!fv || !c) {
        free(c);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    }
    if ((st = build_channel(p, ch, c, err))) {
        ccn__fvchan_free(c);
        return st;
    }
    p->fv[p->nfv] = c;
    if (channel) *channel = p->nfv;
    p->nfv++;
    return CCN_OK;
}

ccn_status ccn_plan_fvar_sizes(const ccn_plan *p, int32_t channel, ccn_fvar_sizes *s) {
    if (!p || !s || channel < 0 || channel >= p->nfv) return CCN_ERR_ARGUMENT;
    const struct ccn__fvchan *c = p->fv[channel];
    s->width = c->width;
    s->num_values = c->lev[c->L].m->nv;
    s->num_cage_values = c->ncage;
    s->num_seam_edges = c->num_seams;
    s->num_sharp_values = c->num_sharp;
    return CCN_OK;
}

/* ---- evaluation ------------------------------------------------------------------------ */

/* Exponent of a power-of-two scale that keeps every value below 1 (exact scaling). */
static int value_exponent(const double *v, size_t n) {
    double big = 0.0;
    for (size_t i = 0; i < n; i++) big = fmax(big, fabs(v[i]));
    int e = big > 0 ? ilogb(big) + 1 : 0;
    return e < -1000 ? -1000 : e > 1000 ? 1000 : e;
}

static ccn_status check_values(const double *v, int32_t w, int32_t n, ccn_error *err) {
    for (int64_t i = 0; i < (int64_t)w * n; i++)
        if (!isfinite(v[i]) || fabs(v[i]) > CCN_COORD_MAX)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VALUE, (int32_t)(i / w),
                             "value %d has a non-finite component or one beyond +-%g",
                             (int)(i / w), CCN_COORD_MAX);
    return CCN_OK;
}

typedef struct {
    const int32_t *start, *idx; const double *w;
    const double *PL, *PS; int32_t nvL;
    double *out; int32_t width, c0, e;
} apply_job;

static void apply_range(void *ctx, int32_t b, int32_t end) {
    const apply_job *j = ctx;
    int nk = j->width - j->c0 < 3 ? j->width - j->c0 : 3;
    for (int32_t o = b; o < end; o++) {
        double x[3] = {0, 0, 0};
        for (int32_t k = j->start[o]; k < j->start[o + 1]; k++) {
            int32_t i = j->idx[k];
            const double *q = i < j->nvL ? j->PL + 3 * (size_t)i : j->PS + 3 * ((size_t)i - j->nvL);
            for (int c = 0; c < 3; c++) x[c] += j->w[k] * q[c];
        }
        for (int c = 0; c < nk; c++) j->out[(size_t)j->width * o + j->c0 + c] = ldexp(x[c], j->e);
    }
}

ccn_status ccn_plan_evaluate_fvar(ccn_plan *p, int32_t channel, const double *values,
                                  double *out_values, int32_t *face_values, ccn_error *err) {
    ccn__ok(err);
    if (!p || !out_values || channel < 0 || channel >= (p ? p->nfv : 0))
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "plan or out_values is NULL, or no channel %d", (int)channel);
    struct ccn__fvchan *c = p->fv[channel];
    const double *vals = values ? values : c->cage_values;
    ccn_status st = check_values(vals, c->width, c->ncage, err);
    if (st) return st;
    int32_t w = c->width, e = value_exponent(vals, (size_t)w * (size_t)c->ncage);
    ccn_mesh *m0 = c->lev[0].m, *mL = c->lev[c->L].m;
    for (int32_t c0 = 0; c0 < w; c0 += 3) {
        for (int32_t v = 0; v < m0->nv; v++)
            for (int k = 0; k < 3; k++)
                m0->pos[3 * (size_t)v + k] = c0 + k < w ? ldexp(vals[(size_t)w * c->value_of[v] + c0 + k], -e) : 0.0;
        for (int32_t l = 0; l < c->L; l++) ccn__level_points(&c->prep[l], c->lev[l + 1].m->pos);
        if (c->bilinear) {
            int nk = w - c0 < 3 ? w - c0 : 3;
            for (int32_t v = 0; v < mL->nv; v++)
                for (int k = 0; k < nk; k++) out_values[(size_t)w * v + c0 + k] = ldexp(mL->pos[3 * (size_t)v + k], e);
            continue;
        }
        if (c->has_sub) ccn__level_points_subset(&c->sub, c->near, c->nnear, c->posS);
        apply_job j = {c->st_start, c->st_v, c->st_w, mL->pos, c->posS, mL->nv, out_values, w, c0, e};
        ccn__parallel_for(p->threads, mL->nv, apply_range, &j);
    }
    if (face_values) memcpy(face_values, mL->hvert, sizeof(int32_t) * (size_t)mL->nh);
    return CCN_OK;
}

/* ---- per-vertex data ------------------------------------------------------------------- */

#define VD_MAX_LEVELS 16 /* the plan has at most 10 output levels (+1) */

ccn_status ccn_plan_evaluate_vertex_data(ccn_plan *p, int32_t width, const double *data,
                                         double *out, ccn_error *err) {
    ccn__ok(err);
    if (!p || !data || !out)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "plan, data or out is NULL");
    if (width < 1 || width > CCN_FVAR_MAX_WIDTH)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "vertex data width must be 1..%d, got %d",
                         CCN_FVAR_MAX_WIDTH, (int)width);
    ccn_status st = check_values(data, width, p->ncage, err);
    if (st) return st;
    int32_t top = p->R > p->L ? p->L + 1 : p->L; /* levels the stencils read */
    if (top >= VD_MAX_LEVELS) return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "too many levels");
    size_t total = 0;
    for (int32_t l = 0; l <= top; l++) total += 3 * (size_t)p->lev[l]->nv;
    const ccn_mesh *mL = p->lev[p->L];
    size_t nS = p->has_sub ? 3 * ((size_t)mL->nf + mL->ne + mL->nv) : 0;
    if (!p->vd_buf && !(p->vd_buf = malloc(sizeof(double) * (total + nS + 1))))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (vertex data)");
    double *saved[VD_MAX_LEVELS], *buf = p->vd_buf;
    for (int32_t l = 0; l <= top; l++) {
        saved[l] = p->lev[l]->pos;
        p->lev[l]->pos = buf;
        buf += 3 * (size_t)p->lev[l]->nv;
    }
    double *PS = p->has_sub ? buf : p->R > p->L ? p->lev[p->L + 1]->pos : NULL;
    int e = value_exponent(data, (size_t)width * (size_t)p->ncage);
    ccn_mesh *m0 = p->lev[0];
    for (int32_t c0 = 0; c0 < width; c0 += 3) {
        for (int32_t v = 0; v < m0->nv; v++)
            for (int k = 0; k < 3; k++)
                m0->pos[3 * (size_t)v + k] = c0 + k < width ? ldexp(data[(size_t)width * v + c0 + k], -e) : 0.0;
        for (int32_t l = 0; l < top; l++) ccn__level_points(&p->prep[l], p->lev[l + 1]->pos);
        if (p->has_sub) ccn__level_points_subset(&p->sub, p->near, p->nnear, PS);
        apply_job j = {p->st_start, p->st_v, p->st_wp, mL->pos, PS, mL->nv, out, width, c0, e};
        ccn__parallel_for(p->threads, p->nout_v, apply_range, &j);
    }
    for (int32_t l = 0; l <= top; l++) p->lev[l]->pos = saved[l];
    return CCN_OK;
}
