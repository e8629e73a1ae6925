/* The half-edge mesh every layer above works on (internal): struct ccn_mesh and its inline
 * accessors. Built and validated by topology/mesh.c; ring intervals by topology/knots.c. */
#ifndef CCN_TOPOLOGY_HALFEDGE_H
#define CCN_TOPOLOGY_HALFEDGE_H

#include "ccnurbs.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* Half-edge mesh. Face f owns the half-edges fstart[f] .. fstart[f+1]-1 in boundary order
 * (counter-clockwise seen from outside); half-edge h runs from hvert[h] to hvert[next(h)].
 * Edges are numbered in order of first appearance when walking faces and their half-edges
 * (level 0) or by the refinement rule documented in refine/level.c (levels >= 1). */
struct ccn_mesh {
    int32_t nv, nf, ne, nh;
    double *pos;     /* 3 * nv */
    int32_t *fstart; /* nf + 1 */
    int32_t *hvert;  /* nh: origin vertex */
    int32_t *htwin;  /* nh: opposite half-edge, -1 on the boundary */
    int32_t *hedge;  /* nh: edge index */
    int32_t *hface;  /* nh: face index */
    int32_t *everts; /* 2 * ne */
    double *eknot;   /* ne: ring interval, normalised by a power of two: the largest in (1/2, 1] */
    double knot_scale; /* eknot * knot_scale = interval in the caller's units */
    /* Vertex fans: the outgoing half-edges of vertex v in counter-clockwise order are
     * vfan[vfan_start[v] .. vfan_start[v+1]-1]. A boundary vertex's fan starts with the
     * outgoing boundary half-edge; its last edge (incoming boundary) is vlast_edge[v]. */
    int32_t *vfan_start; /* nv + 1 */
    int32_t *vfan;       /* nh */
    int32_t *hfanpos;    /* nh: position of h in its origin vertex's fan */
    int32_t *vlast_edge; /* nv: incoming boundary edge of a boundary vertex, else -1 */
    uint8_t *vboundary;  /* nv */
    /* Sharpness (OpenSubdiv semantics: > 0 sharp, >= 10 infinite), kept in single precision
     * as OpenSubdiv keeps it so that fractional blends match it bit for bit. Both NULL when
     * every edge and vertex is smooth (then every rule is the crease-free one). Boundary
     * edges are infinitely sharp whatever esharp says. */
    float *esharp;       /* ne */
    float *vsharp;       /* nv */
    /* A non-manifold cage split into a manifold one (topology/split.c): the copies of a
     * vertex (or of the edges between copies) have the same points at every level, and the
     * mesh's public view welds them: vrep[v] is v's representative (the smallest vertex of its
     * group), vweld[v] its welded index (at level 0 the cage's vertex), erep / eweld the same
     * for edges; nvw / new the welded counts. All NULL (0) for a manifold cage. */
    int32_t *vrep, *vweld, *erep, *eweld;
    int32_t nvw, new_;
    ccn_mesh_info info;
};

static inline int32_t ccn__next(const ccn_mesh *m, int32_t h) {
    int32_t f = m->hface[h];
    return h + 1 < m->fstart[f + 1] ? h + 1 : m->fstart[f];
}
static inline int32_t ccn__prev(const ccn_mesh *m, int32_t h) {
    int32_t f = m->hface[h];
    return h > m->fstart[f] ? h - 1 : m->fstart[f + 1] - 1;
}
static inline int32_t ccn__fsize(const ccn_mesh *m, int32_t f) {
    return m->fstart[f + 1] - m->fstart[f];
}
static inline int32_t ccn__valence(const ccn_mesh *m, int32_t v) {
    return m->vfan_start[v + 1] - m->vfan_start[v] + (m->vboundary[v] ? 1 : 0);
}
/* Edge k (0 <= k < valence) of v's fan, counter-clockwise. */
static inline int32_t ccn__fan_edge(const ccn_mesh *m, int32_t v, int32_t k) {
    int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v];
    return k < nfan ? m->hedge[m->vfan[m->vfan_start[v] + k]] : m->vlast_edge[v];
}

/* Is edge e sharp (> 0) at this level (for the vertex rules)? Boundary edges are
 * (infinitely) sharp whatever this says. */
static inline int ccn__edge_sharp(const ccn_mesh *m, int32_t e) {
    return m->esharp && m->esharp[e] > 0.0f;
}
/* Does edge e split the knot-interval look-ups like a boundary at this level (sharpness >= 1:
 * its full crease rule applies)? Below 1 its points blend the crease and the smooth rule, and
 * the look-ups are the smooth ones, so the smooth part is exactly the smooth rule. */
static inline int ccn__edge_splits(const ccn_mesh *m, int32_t e) {
    return m->esharp && m->esharp[e] >= 1.0f;
}

#define CCN_KNOT_MIN_RATIO 1e-6

/* The smallest power of two >= x (x > 0, finite): the interval normalisation (topology/knots.c),
 * by which dividing is exact. */
static inline double ccn__pow2_at_least(double x) {
    int e;
    double f = frexp(x, &e); /* x = f 2^e, f in [1/2, 1) */
    return ldexp(1.0, f == 0.5 ? e - 1 : e);
}
#define CCN_COORD_MAX 1e300 /* larger |coordinates| are rejected: results must stay finite */

#endif
