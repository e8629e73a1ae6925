/* Face-varying limit weights written down directly where the value mesh is a regular grid
 * (internal; surface/fvar_direct.c). */
#ifndef CCN_SURFACE_FVAR_DIRECT_H
#define CCN_SURFACE_FVAR_DIRECT_H

#include "refine/fvar.h"

/* The level-0 faces of a channel whose limit is a bicubic tensor-product B-spline patch. */
typedef struct {
    int32_t *slot;  /* nf: the face's slot below (the face itself), -1: composed by probing */
    int32_t *verts; /* 16 per slot: value vertex P_ij at i + 4 j (corner 0 of the face is P_11) */
    double *knots;  /* 12 per slot: the knot vectors U[0..5], V[0..5] (span [U2, U3] x [V2, V3]) */
    uint8_t *fold;  /* per slot: missing end points, point-reflected (1: P_0j, 2: P_3j, 4: P_i0,
                     * 8: P_i3; their slots hold a real value with weight 0) */
    int32_t count;
} ccn__fvar_direct;

/* Classifies the faces of a level (see surface/fvar_direct.c) on up to `threads`: every face,
 * or only the nfaces listed (distinct; the others get slot -1). Returns 0, or -1 out of
 * memory. */
int ccn__fvar_direct_build(const ccn__fvar_level *f0, int threads, const int32_t *faces, int32_t nfaces,
                           ccn__fvar_direct *d);
void ccn__fvar_direct_free(ccn__fvar_direct *d);

/* The basis functions of slot s's face at the grid points a / (side - 1), a = 0 .. side - 1, of
 * u (along its first half-edge) and v (along the reversed last one): N[4 a + i] = N_i(u_a),
 * then N[4 side + 4 b + j] = N_j(v_b); the weight of verts[16 s + i + 4 j] is their product. */
void ccn__fvar_direct_table(const ccn__fvar_direct *d, int32_t s, int32_t side, double *N);

#endif
