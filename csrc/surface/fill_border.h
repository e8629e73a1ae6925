/* The border data of the fill faces around one vertex w (internal; surface/fill_border.c, used
 * by io/fill_faces.c, the CAD export's fills, and surface/fill_cap.c, the plan's caps beyond
 * the bi-5 range): per fan face k of w at the fill level, the 2 x 2 faces [0,2]^2 of its sector
 * (u along spoke k, v along spoke k + 1) and the exact bicubic pieces across its far sides,
 * whose sides and C1 continuations become the outer two layers of the sector's clamped 2-span
 * bicubic (knots 0000 1 2222 in units of the level's faces). */
#ifndef CCN_SURFACE_FILL_BORDER_H
#define CCN_SURFACE_FILL_BORDER_H

#include "topology/halfedge.h"

/* One sector's block around w: the aligned cells (a base half-edge b of face hface[b] runs
 * along +u; -1 past a crease or the boundary) of the 2x2 faces [0,2]^2 (g at w, A, B, D) and
 * of the faces along its far sides: N1, N2 across u = 2 (v in [0,1], [1,2]), M1, M2 across
 * v = 2. h: w's fan half-edge of the sector. */
typedef struct { int32_t g, A, B, D, N1, N2, M1, M2; } ccn__fill_block;
void ccn__fill_sector_block(const ccn_mesh *m, int32_t h, ccn__fill_block *k);

/* The bicubic patch of the aligned cell b (strict or not) in the cell's frame; 0 if none. */
int ccn__fill_cell_patch(const ccn_mesh *m, int32_t b, int pinned, double out[4][4][3]);

/* The 2-span poles of the side (layer 0) or of its C1 continuation (layer 1) of the cells
 * P (first span) and Q (second span) across their u = 0 side (v = 0 side if along_u). */
void ccn__fill_side_poles(const double P[4][4][3], const double Q[4][4][3], int along_u, int layer,
                          double out[5][3]);

/* The sector's bicubic poles c (zeroed by the caller) from the patches nb = N1, N2, M1, M2: the
 * outer two layers (the far corner the mean of both sides'), the inner ones their linear
 * continuations; the spokes (c[i][0], c[0][j]) are the caller's. */
void ccn__fill_sector_border(const double nb[4][4][4][3], double c[5][5][3]);

#endif
