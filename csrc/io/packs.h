/* Face packs of the CAD export (internal; io/packs.c). */
#ifndef CCN_IO_PACKS_H
#define CCN_IO_PACKS_H

#include "io/export_model.h"

/* A rectangle of a x b faces of one mesh: cells[i + a*j] is the base half-edge of cell (i,j)
 * (its side 0 along the pack's u). */
typedef struct {
    int32_t a, b;
    int periodic[2];
    int32_t *cells;
} ccn__pack;

/* Face f of mesh m is a bicubic B-spline span of its net that may join a pack: a quad whose
 * 16 net vertices are regular (ccn__bicubic_net strict) and whose neighbours around its
 * corners are quads. */
int ccn__packable(const ccn_mesh *m, int32_t f, int pinned);
/* Maximal rectangles (greedy, face order) of the faces with ok[f] != 0; single: every face
 * its own 1x1 pack. *out: *n packs (free with ccn__packs_free). */
ccn_status ccn__packs_find(const ccn_mesh *m, const uint8_t *ok, int single, ccn__pack **out,
                           int32_t *n, ccn_error *err);
void ccn__packs_free(ccn__pack *p, int32_t n);
/* The pack's bicubic B-spline face in the caller's coordinates (centre + scale * m->pos):
 * poles = the cells' nets, knots = the ring intervals (times knot_scale), clamped at
 * non-periodic ends. place(ctx, face, out) gives the place of each cell's face. Returns
 * the face index or -1. */
typedef void (*ccn__xplace_fn)(void *ctx, int32_t face, ccn__xplace *out);
int32_t ccn__pack_face(ccn__xmodel *xm, const ccn_mesh *m, const ccn__pack *pk, int pinned,
                       const double centre[3], double scale, int32_t kind, ccn__xplace_fn place,
                       void *ctx);

#endif
