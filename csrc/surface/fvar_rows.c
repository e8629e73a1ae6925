/* The rows of a channel's composed stencils (surface/fvar_rows.h): where an output value lies
 * on the cage, and the rows made final over the caller's values. */
#include "surface/fvar_rows.h"

#include "base/error.h"
#include "base/parallel.h"
#include "surface/fvar_builder.h"

#include <math.h>
#include <string.h>

void ccn__fvar_builder_free(ccn__fvar_builder *c) {
    for (int32_t l = 0; c->lev && l <= c->L; l++) ccn__fvar_free(&c->lev[l]);
    for (int32_t l = 0; c->prep && l < c->L; l++) ccn__level_free(&c->prep[l]);
    if (c->has_sub) ccn__level_free(&c->sub);
    free(c->lev); free(c->prep); free(c->near); free(c->st_start); free(c->st_v); free(c->st_w);
    free(c->posS); free(c->value_of); free(c->fo); free(c->ab); free(c->direct); free(c->outs);
    free(c->hvL); free(c->firstL);
    ccn__fvar_direct_free(&c->dir1);
    free(c->d1); free(c->d1ab); free(c->d1verts); free(c->d1N); free(c->skip);
    ccn__fvar_direct_free(&c->dir);
    for (int32_t l = 0; c->pl && l < c->L; l++) { free(c->pl[l].f); free(c->pl[l].e); free(c->pl[l].v); }
    free(c->pl);
    memset(c, 0, sizeof *c);
}

void ccn__fvar_builder_destroy(ccn__fvar_builder *c) {
    ccn__fvar_builder_free(c);
    free(c);
}

void ccn__fvar_stencils_free(ccn__fvar_stencils *s) {
    if (!s) return;
    free(s->start); free(s->idx); free(s->w); free(s->face_values);
    free(s->dface); free(s->dab); free(s->dvals); free(s->dN);
    if (s->levels) ccn__fvar_builder_destroy(s->levels);
    memset(s, 0, sizeof *s);
}

/* The cage face a level-L value vertex lies on, through its corner h, and its grid point
 * there, a + (b << 16) in level-L face sizes, when that face is a quad: each level's face is
 * the child quad (V_j, E(h_j), F, E(h_j-1)) at corner j of its parent (refine/level.c), a
 * quarter of the parent's square. Integers: (x, y) in level-L face sizes within a face of side
 * z, so the parent's is (2 z c_0 + x (c_1 - c_0) + y (c_-1 - c_0)) with side 2 z. */
int32_t ccn__fvar_origin_at(const ccn_plan *p, int32_t h, int32_t stop, int32_t *ab) {
    static const int32_t C[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const ccn_mesh *mL = p->lev[p->L]; /* the value mesh's faces and corners are the vertices' */
    int32_t g = mL->hface[h], j = h - mL->fstart[g];
    int32_t x = C[j & 3][0], y = C[j & 3][1], z = 1;
    for (int32_t l = p->L; l > stop; l--) {
        const ccn_mesh *m = p->lev[l - 1];
        int32_t f = m->hface[g], k = g - m->fstart[f];
        if (ccn__fsize(m, f) == 4) {
            const int32_t *c0 = C[k], *c1 = C[(k + 1) & 3], *cm = C[(k + 3) & 3];
            int32_t nx = 2 * z * c0[0] + x * (c1[0] - c0[0]) + y * (cm[0] - c0[0]);
            int32_t ny = 2 * z * c0[1] + x * (c1[1] - c0[1]) + y * (cm[1] - c0[1]);
            x = nx; y = ny; z *= 2;
        }
        g = f;
    }
    int32_t sc = (1 << (p->L - stop)) / z;
    *ab = x * sc + ((y * sc) << 16);
    return g;
}

typedef struct { ccn__fvar_stencils *s; const int32_t *value_of; int32_t *len; double *sum; int unique; } merge_job;

/* Row o in place: zero weights dropped, value vertices -> the caller's values (summed where two
 * value vertices carry one value); len[o] its new length, -1 if the weights do not sum to 1. */
static void merge_range(void *ctx, int32_t b, int32_t end) {
    const merge_job *j = ctx;
    int32_t *idx = j->s->idx;
    double *w = j->s->w;
    for (int32_t o = b; o < end; o++) {
        int32_t first = j->s->start[o], n = first;
        double sum = 0.0;
        if (j->s->dface && j->s->dface[o] != -1) { /* a regular face's point, or by levels: no row */
            j->len[o] = 0;
            j->sum[o] = 1.0;
            continue;
        }
        for (int32_t e = first; e < j->s->start[o + 1]; e++) {
            double we = w[e];
            if (we == 0.0) continue;
            sum += we;
            int32_t val = j->value_of[idx[e]], q = j->unique ? n : first;
            while (q < n && idx[q] != val) q++;
            if (q < n) w[q] += we;
            else { idx[n] = val; w[n++] = we; }
        }
        j->len[o] = fabs(sum - 1.0) <= 1e-9 ? n - first : -1;
        j->sum[o] = sum;
    }
}

/* The rows in place: zero weights dropped, value vertices -> the caller's values (a value on two
 * value vertices once), and every stencil sums to 1; each row within its own entries (in
 * parallel), then the rows moved together. */
ccn_status ccn__fvar_finish_rows(int threads, const int32_t *value_of, int32_t nv0, ccn__fvar_stencils *s,
                                 ccn_error *err) {
    int32_t nout = s->nout;
    ccn_status st = CCN_OK;
    int32_t *len = malloc(sizeof(int32_t) * (size_t)(nout ? nout : 1));
    double *sums = malloc(sizeof(double) * (size_t)(nout ? nout : 1));
    if (!len || !sums) {
        free(len); free(sums);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying stencils)");
    }
    /* a row's candidates are distinct value vertices: they need merging only where two value
     * vertices carry one of the caller's values */
    int32_t maxval = 0;
    for (int32_t v = 0; v < nv0; v++) if (value_of[v] > maxval) maxval = value_of[v];
    uint8_t *used = calloc((size_t)maxval + 1, 1);
    int unique = used != NULL;
    for (int32_t v = 0; unique && v < nv0; v++) unique = !used[value_of[v]]++;
    free(used);
    merge_job mj = {s, value_of, len, sums, unique};
    ccn__parallel_for(threads, nout, merge_range, &mj);
    int32_t n = 0;
    for (int32_t o = 0; o < nout && !st; o++) {
        int32_t e0 = s->start[o], k = len[o];
        if (k < 0) { /* weight outside the neighbourhood: cannot happen */
            st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1,
                           "face-varying stencil of output value %d sums to %.17g", (int)o, sums[o]);
            break;
        }
        if (n != e0) {
            memmove(s->idx + n, s->idx + e0, sizeof(int32_t) * (size_t)k);
            memmove(s->w + n, s->w + e0, sizeof(double) * (size_t)k);
        }
        s->start[o] = n;
        n += k;
    }
    free(len); free(sums);
    s->start[nout] = n;
    if (!st) {
        int32_t *a = realloc(s->idx, sizeof(int32_t) * (size_t)(n ? n : 1));
        double *b = realloc(s->w, sizeof(double) * (size_t)(n ? n : 1));
        if (a) s->idx = a;
        if (b) s->w = b;
    }
    return st;
}
