/* Exact limit stencils at refined vertices (limit.c). Internal. */
#ifndef CCN_SURFACE_LIMIT_H
#define CCN_SURFACE_LIMIT_H

#include "surface/ring_limit.h"
#include "topology/halfedge.h"

#define CCN_STENCIL_MAX 2049 /* 2n+1 for valence n <= 1024 */

/* Weights over vertices of one mesh level: position (wp) and two tangents (wu, wv) whose
 * cross product wu x wv points along the outward normal (except for EVs: see ev_limit). */
typedef struct {
    int n;
    int32_t v[CCN_STENCIL_MAX];
    double wp[CCN_STENCIL_MAX], wu[CCN_STENCIL_MAX], wv[CCN_STENCIL_MAX];
} ccn__stencil;

enum {
    CCN_LIMIT_REGULAR = 0,     /* tensor B-spline limit (mirror ghosts on the boundary) */
    CCN_LIMIT_BOUNDARY_CURVE,  /* smooth corner or boundary EV */
    CCN_LIMIT_EV,              /* smooth interior extraordinary vertex: use ccn__ev_limit */
    CCN_LIMIT_ISOLATED,
    CCN_LIMIT_RING             /* sharp spokes or vertex sharpness, interior valence 2:
                                  surface/ring_limit.c, from the child 1-ring */
};

/* A virtual grid point: up to 4 real vertices with weights (mirror ghosts). */
typedef struct { int32_t v[4]; double w[4]; int n; } ccn__vpoint;
/* The 3x3 grid around a regular vertex v (interior valence 4, boundary valence 3 or pinned
 * corner) with +u along fan edge k0 and +v along fan edge k0+1: p[i+1][j+1] is grid point
 * (i,j); missing points across the boundary are mirror ghosts. du[0..3] = intervals
 * D_-2, D_-1, D_0, D_1 along u (D_0 between (0,0) and (1,0)); dv likewise. */
typedef struct { ccn__vpoint p[3][3]; double du[4], dv[4]; } ccn__vgrid;
void ccn__vertex_grid(const ccn_mesh *m, int32_t v, int32_t k0, int pinned, ccn__vgrid *g);
/* Creases: the fan faces first .. first+count-1 (mod the fan size) of v's sector that holds
 * fan face k, between the edges that split the look-ups (sharpness >= 1) or the boundary; the
 * whole fan when v has fewer than two such edges. ccn__vertex_grid builds the grid of fan face
 * k0's sector, mirrored across its sharp edges as across a boundary. */
void ccn__fan_sector(const ccn_mesh *m, int32_t v, int32_t k, int32_t *first, int32_t *count);
/* Is the limit of v's sector holding fan face k the tensor spline of that sector's grid, as at
 * a regular vertex? REGULAR vertices, and on creased meshes (no semi-sharp value at v) a
 * crease vertex's two-face sector (a boundary vertex of valence 3: the crease curve is the
 * B-spline boundary on each side) and a corner's one-face sector (a pinned corner). */
int ccn__sector_regular(const ccn_mesh *m, int32_t v, int32_t k, int pinned);

int ccn__limit_kind(const ccn_mesh *m, int32_t v, int pinned);
/* Is v, or a vertex of one of its faces, flagged in `irregular` (then its level-L box does not
 * refine by knot insertion and its limit needs level L+1)? */
int ccn__near_irregular(const ccn_mesh *m, int32_t v, const uint8_t *irregular);
/* Fills s for REGULAR / BOUNDARY_CURVE / ISOLATED vertices; returns the kind (for EV the
 * stencil is left empty). */
int ccn__limit_stencil(const ccn_mesh *m, int32_t v, int pinned, ccn__stencil *s);
/* 1-ring of an interior vertex in M's order (F_0..F_{n-1}, E_0..E_{n-1}, V); returns 2n+1. */
int32_t ccn__ev_ring(const ccn_mesh *m, int32_t v, int32_t *ring);
/* Limit point and tangent directions of an interior EV from the left eigenvectors of M
 * (scheme's matrix); wu x wv is the outward normal (oriented by the characteristic map). */
ccn_status ccn__ev_limit(const ccn_mesh *m, int32_t v, int scheme, int32_t ev_poly,
                         ccn__ev_cache *cache, ccn__stencil *s, ccn_error *err);
/* Limit stencil of the vertex point of v one level finer, in level-(l+1) numbering (face
 * point f -> f, edge point e -> nf+e, vertex point v -> nf+ne+v), built from this level's
 * topology; wu x wv is the outward normal. For BOUNDARY_CURVE and RING vertices (w and ring
 * given) ring receives every sector's tangent pair (s holds sector 0's). */
ccn_status ccn__child_limit_stencil(const ccn_mesh *m, int32_t v, int pinned, int scheme,
                                    int crease_method, ccn__ring_work *w, ccn__stencil *s,
                                    ccn__ring_limit *ring, ccn_error *err);
/* Weights of the first and second derivatives at a REGULAR vertex (the tensor B-spline of its
 * 3 x 3 grid, ghosts included): w[0..4] = S_u, S_v, S_uu, S_uv, S_vv, with S_u x S_v along the
 * outward normal as in ccn__limit_stencil. */
#define CCN_STENCIL2_MAX 36
typedef struct {
    int n;
    int32_t v[CCN_STENCIL2_MAX];
    double w[5][CCN_STENCIL2_MAX];
} ccn__stencil2;
/* Fills s for a REGULAR vertex v of m (child = 0: over m's vertices, as ccn__limit_stencil;
 * child = 1: over the level-(l+1) points around v's vertex point, as
 * ccn__child_limit_stencil); returns 0 (s empty) for any other kind. */
int ccn__curvature_stencil(const ccn_mesh *m, int32_t v, int pinned, int child,
                           ccn__stencil2 *s);
#endif
