/* Face-varying channels and per-vertex data on a plan's output (surface/plan_fvar.h).
 *
 * A channel is its composed limit stencils (surface/fvar_compose.c): each output value as
 * weights over the caller's values, so evaluating new values is one sparse product; where the
 * neighbourhoods are too large to compose (high-valence n-gons), the outputs without a row run
 * through the channel's kept levels (surface/fvar_probe.c, one pass per 3 components). Per-vertex
 * data runs through the plan's own levels and stencils, on scratch positions, so the plan's
 * geometry stays that of the last ccn_plan_evaluate.
 */
#include "surface/plan_fvar.h"

#include "base/error.h"
#include "base/parallel.h"
#include "base/vec3.h"
#include "refine/fvar.h"
#include "surface/fvar_compose.h"
#include "surface/fvar_probe.h"

#include <math.h>
#include <string.h>

struct ccn__fvchan {
    int32_t width, ncage;
    double *cage_values;      /* width * ncage: the values given to ccn_plan_add_fvar */
    ccn__fvar_stencils s;
};

void ccn__fvchan_free(struct ccn__fvchan *c) {
    if (!c) return;
    ccn__fvar_stencils_free(&c->s);
    free(c->cage_values);
    free(c);
}

static ccn_status build_channel(ccn_plan *p, const ccn_fvar_channel *ch, struct ccn__fvchan *c,
                                ccn_error *err) {
    c->width = ch->width;
    c->ncage = ch->num_values;
    size_t nval = (size_t)ch->width * (size_t)ch->num_values;
    c->cage_values = malloc(sizeof(double) * nval);
    if (!c->cage_values)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    memcpy(c->cage_values, ch->values, sizeof(double) * nval);
    return ccn__fvar_compose(p, ch, &c->s, err);
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

ccn_status ccn_plan_get_fvar_sizes(const ccn_plan *p, int32_t channel, ccn_fvar_sizes *s) {
    if (!p || !s || channel < 0 || channel >= p->nfv) return CCN_ERR_ARGUMENT;
    const struct ccn__fvchan *c = p->fv[channel];
    s->width = c->width;
    s->num_values = c->s.nout;
    s->num_cage_values = c->ncage;
    s->num_seam_edges = c->s.num_seams;
    s->num_sharp_values = c->s.num_sharp;
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
    const ccn_plan *p;
    const double *PL, *PS; int32_t nvL;
    double *out; int32_t width, c0;
    double up; /* the power-of-two scale back */
} apply_job;

/* Level-L points and level-(L+1) points (index >= nvL) through stencils (vertex data). */
static void apply_range(void *ctx, int32_t b, int32_t end) {
    const apply_job *j = ctx;
    const int32_t *start = j->p->st_start, nvL = j->nvL, width = j->width, c0 = j->c0;
    const double *PL = j->PL, *PS = j->PS, up = j->up;
    double *out = j->out;
    int nk = width - c0 < 3 ? width - c0 : 3;
    for (int32_t o = b; o < end; o++) {
        double x0 = 0, x1 = 0, x2 = 0;
        const double *w, *wu, *wv;
        ccn__plan_row_weights(j->p, o, &w, &wu, &wv);
        const int32_t *idx = j->p->st_v + start[o];
        for (int32_t k = 0, n = start[o + 1] - start[o]; k < n; k++) {
            int32_t i = idx[k];
            const double *q = i < nvL ? PL + 3 * (size_t)i : PS + 3 * ((size_t)i - nvL);
            double wk = w[k];
            x0 += wk * q[0]; x1 += wk * q[1]; x2 += wk * q[2];
        }
        double *dst = out + (size_t)width * o + c0;
        dst[0] = up * x0;
        if (nk > 1) dst[1] = up * x1;
        if (nk > 2) dst[2] = up * x2;
    }
}

typedef struct { const ccn__fvar_stencils *s; const double *vals; double *out; int32_t width; } spmv_job;

/* Output o on a regular face: sum_j N_j(v_b) sum_i N_i(u_a) value(P_ij) (surface/fvar_compose.h). */
static void direct_value(const ccn__fvar_stencils *s, int32_t o, const double *vals, int32_t w,
                         double *dst) {
    int32_t f = s->dface[o], a = s->dab[o] & 0xffff, bb = s->dab[o] >> 16;
    const double *Nu = s->dN + 8 * (size_t)s->side * f + 4 * (size_t)a;
    const double *Nv = s->dN + 8 * (size_t)s->side * f + 4 * ((size_t)s->side + bb);
    const int32_t *P = s->dvals + 16 * (size_t)f;
    if (w == 2) {
#ifdef CCN_V2D /* u and v side by side: the same products and sums per lane (base/vec3.h) */
        ccn__v2d xy = {0, 0};
        for (int jj = 0; jj < 4; jj++) {
            ccn__v2d r = {0, 0};
            for (int i = 0; i < 4; i++) {
                ccn__v2d v, n = {Nu[i], Nu[i]};
                memcpy(&v, vals + 2 * (size_t)P[i + 4 * jj], sizeof v);
                r += n * v;
            }
            ccn__v2d n = {Nv[jj], Nv[jj]};
            xy += n * r;
        }
        dst[0] = xy[0];
        dst[1] = xy[1];
#else
        double x = 0, y = 0;
        for (int jj = 0; jj < 4; jj++) {
            double rx = 0, ry = 0;
            for (int i = 0; i < 4; i++) {
                const double *v = vals + 2 * (size_t)P[i + 4 * jj];
                rx += Nu[i] * v[0];
                ry += Nu[i] * v[1];
            }
            x += Nv[jj] * rx;
            y += Nv[jj] * ry;
        }
        dst[0] = x;
        dst[1] = y;
#endif
        return;
    }
    for (int32_t c = 0; c < w; c++) dst[c] = 0.0;
    for (int jj = 0; jj < 4; jj++)
        for (int i = 0; i < 4; i++) {
            double wt = Nu[i] * Nv[jj];
            const double *v = vals + (size_t)w * P[i + 4 * jj];
            for (int32_t c = 0; c < w; c++) dst[c] += wt * v[c];
        }
}

static void spmv_range(void *ctx, int32_t b, int32_t end) {
    const spmv_job *j = ctx;
    const int32_t *start = j->s->start, *idx = j->s->idx, w = j->width, *dface = j->s->dface;
    const double *wt = j->s->w, *vals = j->vals;
    double *out = j->out;
    if (w == 2) { /* UV maps */
        for (int32_t o = b; o < end; o++) {
            if (dface && dface[o] >= 0) { direct_value(j->s, o, vals, w, out + 2 * (size_t)o); continue; }
#ifdef CCN_V2D
            ccn__v2d xy = {0, 0};
            for (int32_t k = start[o]; k < start[o + 1]; k++) {
                ccn__v2d v, n = {wt[k], wt[k]};
                memcpy(&v, vals + 2 * (size_t)idx[k], sizeof v);
                xy += n * v;
            }
            memcpy(out + 2 * (size_t)o, &xy, sizeof xy);
#else
            double x = 0, y = 0;
            for (int32_t k = start[o]; k < start[o + 1]; k++) {
                const double *v = vals + 2 * (size_t)idx[k];
                x += wt[k] * v[0];
                y += wt[k] * v[1];
            }
            out[2 * (size_t)o] = x;
            out[2 * (size_t)o + 1] = y;
#endif
        }
        return;
    }
    for (int32_t o = b; o < end; o++) {
        double *dst = out + (size_t)w * o;
        if (dface && dface[o] >= 0) { direct_value(j->s, o, vals, w, dst); continue; }
        for (int32_t c = 0; c < w; c++) dst[c] = 0.0;
        for (int32_t k = start[o]; k < start[o + 1]; k++) {
            const double *v = vals + (size_t)w * idx[k];
            for (int32_t c = 0; c < w; c++) dst[c] += wt[k] * v[c];
        }
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
    spmv_job j = {&c->s, vals, out_values, c->width};
    ccn__parallel_for(p->threads, c->s.nout, spmv_range, &j);
    if (c->s.levels) { /* the outputs without a row: through the channel's levels, in a unit scale */
        int e = value_exponent(vals, (size_t)c->width * (size_t)c->ncage);
        if (ccn__fvar_levels_evaluate(p, c->s.levels, vals, c->width, ldexp(1.0, -e), ldexp(1.0, e), out_values))
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
    }
    if (face_values) memcpy(face_values, c->s.face_values, sizeof(int32_t) * 4 * (size_t)p->nout_f);
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
    double down = ldexp(1.0, -e), up = ldexp(1.0, e);
    ccn_mesh *m0 = p->lev[0];
    for (int32_t c0 = 0; c0 < width; c0 += 3) {
        for (int32_t v = 0; v < m0->nv; v++) {
            size_t d = (size_t)width * (size_t)(m0->vrep ? m0->vrep[v] : v); /* copies: the cage vertex's */
            for (int k = 0; k < 3; k++)
                m0->pos[3 * (size_t)v + k] = c0 + k < width ? down * data[d + c0 + k] : 0.0;
        }
        for (int32_t l = 0; l < top; l++) ccn__level_points(&p->prep[l], p->lev[l + 1]->pos);
        if (p->has_sub) {
            ccn__level_tabulate_subset(&p->sub, p->near, p->nnear);
            ccn__level_points_subset(&p->sub, p->near, p->nnear, PS);
        }
        apply_job j = {p, mL->pos, PS, mL->nv, out, width, c0, up};
        ccn__parallel_for(p->threads, p->nout_v, apply_range, &j);
    }
    for (int32_t l = 0; l <= top; l++) p->lev[l]->pos = saved[l];
    return CCN_OK;
}
