/* The rows of a channel's composed stencils (internal; surface/fvar_rows.c): where an output
 * value lies on the cage, and the rows made final over the caller's values. */
#ifndef CCN_SURFACE_FVAR_ROWS_H
#define CCN_SURFACE_FVAR_ROWS_H

#include "surface/plan_types.h"

/* Each output value (a level-L value vertex) as weights over the channel's cage values: a CSR
 * row, or on a regular cage face (surface/fvar_direct.c) the face's bicubic patch at a grid
 * point, N_i(u_a) N_j(v_b) over its 16 values with the basis functions tabulated per face. */
typedef struct {
    int32_t nout;           /* output values */
    int32_t *start, *idx;   /* CSR, nout + 1 offsets; idx: the caller's value indices */
    double *w;
    int32_t *dface;         /* nout or NULL: the output's regular face (below), -1: its CSR row */
    int32_t *dab;           /* nout: grid point a + (b << 16) on that face, a, b in 0..side-1 */
    int32_t nd, side;       /* regular faces; grid points per side (2^L + 1) */
    int32_t *dvals;         /* 16 per regular face: the caller's value at P_ij, i + 4 j */
    double *dN;             /* 8 * side per regular face: N_0..3(u_a), then N_0..3(v_b) */
    int32_t *face_values;   /* 4 * num_faces: the output value of each output face corner */
    int32_t num_seams, num_sharp;
    /* not NULL: the outputs whose dface is CCN_FVAR_BY_LEVELS have no row; they are evaluated
     * through these kept value levels, one pass per 3 components (surface/fvar_compose.c says
     * when: a neighbourhood too large to probe, as around a high-valence n-gon) */
    struct ccn__fvar_builder *levels;
} ccn__fvar_stencils;
#define CCN_FVAR_BY_LEVELS (-2)
void ccn__fvar_stencils_free(ccn__fvar_stencils *s);
/* Frees what a builder (surface/fvar_builder.h) holds; _destroy also the struct itself. */
void ccn__fvar_builder_free(struct ccn__fvar_builder *c);
void ccn__fvar_builder_destroy(struct ccn__fvar_builder *c);

/* The face of level `stop` that level-L corner h lies in, and its grid point there, a + (b << 16)
 * in level-L face sizes (quad faces; see the definition). */
int32_t ccn__fvar_origin_at(const ccn_plan *p, int32_t h, int32_t stop, int32_t *ab);
/* s->start/idx/w over level-0 value vertices (nv0 of them, value_of: their caller values) ->
 * over the caller's values, zero weights dropped, each row checked to sum to 1. */
ccn_status ccn__fvar_finish_rows(int threads, const int32_t *value_of, int32_t nv0,
                                 ccn__fvar_stencils *s, ccn_error *err);

#endif
