/* Fill faces made exactly G1 across their smooth spokes (internal; io/fill_g1.c, used by
 * io/fill_faces.c). */
#ifndef CCN_IO_FILL_G1_H
#define CCN_IO_FILL_G1_H

#include "fill/g1_fill.h"

#include <stdint.h>

/* Bicubic fills that deviate less than this (rad) across their spokes are kept as they are
 * (smooth valence-2 corners: 1e-21). */
#define CCN_FILL_G1_EXACT 1e-10
/* Quintic fills within this (rad) are G1 as CAD readers take it (their spokes' data is
 * consistent to about 1e-9 of its size, io/fill_g1.c): among them the fairest is kept. */
#define CCN_FILL_G1_TARGET 1e-8
/* The largest normal angle across the smooth spokes (smooth[k]) of per-sector fill faces over
 * [0, 2]^2 with knots 0, 1, 2 of multiplicities mu (degree deg; poles sector after sector, each
 * square, i along its spoke k), at `samples` points of each spoke. */
double ccn__fill_spoke_angle(const double *poles, int32_t deg, const int32_t mu[3], int32_t nfan, int32_t nsp,
                             const uint8_t *smooth, int samples);

/* From the bicubic fills cs (per fan face k: 5 x 5 poles of the clamped 2-span cubic, knots
 * 0000 1 2222; spoke k = sector k's u-axis and sector k-1's v-axis, shared bit for bit; the
 * spoke's inner pole in the limit tangent plane; the outer two layers the exact C1 data), the
 * quintic fills q that are exactly G1 across every smooth spoke (sharp[k] = 0, both sectors
 * filled): of all quintic fills with the G1 relations
 *     D_k(u) + beta(u) D_{k-1}(u) = gamma(u) T(u),  u in [0, 2]
 * (D the two sectors' cross-boundary derivatives, T the spoke's tangent, the weights fixed by
 * the data at both ends) the one of least thin-plate energy. The limit point, the spokes' first
 * poles (the tangent plane), the sharp spokes and the outer two layers (the C1 join) are the
 * bicubic fill's, degree-raised. bnd: w on the boundary (nsp = nfan + 1 spokes, else nsp =
 * nfan). Returns 1 with q, *dev (the largest normal angle across the smooth spokes, 16
 * points each) and *energy (q's thin-plate energy, to compare fills of different spoke data),
 * 0 when the relations have no solution (no common tangent plane or a folded corner; q
 * untouched), -1 out of memory (fill/g1_fill.h: ccn__fill_g1_solve with the data's weights). */
int ccn__fill_g1(const double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                 const uint8_t *filled, double (*q)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3], double *dev,
                 double *energy);

#endif
