/* Face-varying mode ALL written down (surface/fvar_bilinear.h).
 *
 * Mode ALL (every value linear: OpenSubdiv's FVAR_LINEAR_ALL) refines bilinearly (face points
 * the average, edge points the midpoint), and a bilinear limit is the level-L value itself: the
 * output at (u, v) of the level-1 quad (V_k, E(h_k), F, E(h_k-1)) of cage face f is the bilinear
 * interpolation of c_k, (c_k + c_k+1)/2, the average of f's n corners and (c_k-1 + c_k)/2, so its
 * weights are written down for every face (from level 1 on; the probed weights are the same
 * numbers summed in another order, a few ulps).
 */
#include "surface/fvar_bilinear.h"

#include "base/error.h"
#include "base/parallel.h"
#include "surface/fvar_rows.h"

#include <stdlib.h>

/* Mode ALL from level 1 on (the file comment): output o's row is the bilinear weights of its
 * cage face's corners at its grid point (u, v) in its level-1 quad k, over the value vertices
 * of those corners (finish_rows maps them to the caller's values). */
typedef struct { const ccn_plan *p; const ccn__fvar_builder *c; ccn__fvar_stencils *s; int32_t *g, *ab; } bilinear_job;

static void bilinear_origin_range(void *ctx, int32_t b, int32_t end) {
    const bilinear_job *j = ctx;
    for (int32_t o = b; o < end; o++) j->g[o] = ccn__fvar_origin_at(j->p, j->c->firstL[o], 1, &j->ab[o]);
}

static void bilinear_range(void *ctx, int32_t b, int32_t end) {
    const bilinear_job *j = ctx;
    const ccn_mesh *m0 = j->c->lev[0].m; /* the value mesh: the cage's faces and corners */
    double side = (double)(1 << (j->c->L - 1));
    for (int32_t o = b; o < end; o++) {
        int32_t g = j->g[o], f = m0->hface[g], f0 = m0->fstart[f], n = m0->fstart[f + 1] - f0;
        int32_t k = g - f0, next = (k + 1) % n, prev = (k + n - 1) % n, e = j->s->start[o];
        double u = (j->ab[o] & 0xffff) / side, v = (j->ab[o] >> 16) / side;
        double a00 = (1.0 - u) * (1.0 - v), a10 = u * (1.0 - v), a11 = u * v, a01 = (1.0 - u) * v;
        for (int32_t i = 0; i < n; i++) { /* V_k, E(h_k), F, E(h_k-1) at (0,0), (1,0), (1,1), (0,1) */
            double w = a11 / n;
            if (i == k) w += a00 + 0.5 * a10 + 0.5 * a01;
            if (i == next) w += 0.5 * a10;
            if (i == prev) w += 0.5 * a01;
            j->s->idx[e + i] = m0->hvert[f0 + i];
            j->s->w[e + i] = w;
        }
    }
}

ccn_status ccn__fvar_bilinear_rows(const ccn_plan *p, const ccn__fvar_builder *c, ccn__fvar_stencils *s,
                                   ccn_error *err) {
    const ccn_mesh *m0 = c->lev[0].m;
    int32_t nout = s->nout;
    bilinear_job j = {p, c, s, malloc(sizeof(int32_t) * (size_t)(nout ? nout : 1)),
                      malloc(sizeof(int32_t) * (size_t)(nout ? nout : 1))};
    s->start = malloc(sizeof(int32_t) * ((size_t)nout + 1));
    ccn_status st = CCN_OK;
    if (!j.g || !j.ab || !s->start) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    ccn__parallel_for(p->threads, nout, bilinear_origin_range, &j);
    int64_t total = 0;
    s->start[0] = 0;
    for (int32_t o = 0; o < nout; o++) {
        total += ccn__fsize(m0, m0->hface[j.g[o]]);
        if (total > INT32_MAX) {
            st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "face-varying stencils too large");
            goto done;
        }
        s->start[o + 1] = (int32_t)total;
    }
    s->idx = malloc(sizeof(int32_t) * (size_t)(total ? total : 1));
    s->w = malloc(sizeof(double) * (size_t)(total ? total : 1));
    if (!s->idx || !s->w) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
        goto done;
    }
    ccn__parallel_for(p->threads, nout, bilinear_range, &j);
    st = ccn__fvar_finish_rows(p->threads, c->value_of, m0->nv, s, err);
done:
    free(j.g); free(j.ab);
    return st;
}
