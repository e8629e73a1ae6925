/* The half-edge mesh every layer above works on (internal): struct ccn_mesh and its inline
 * accessors. Built and validated by topology/mesh.c; ring intervals by topology/knots.c. */
#ifndef CCN_TOPOLOGY_HALFEDGE_H
#define CCN_TOPOLOGY_HALFEDGE_H

#include "ccnurbs.h"

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
    double *eknot;   /* ne: ring interval, normalised so the largest is 1 */
    double knot_scale; /* eknot * knot_scale = interval in the caller's units */
    /* Vertex fans: the outgoing half-edges of vertex v in counter-clockwise order are
     * vfan[vfan_start[v] .. vfan_start[v+1]-1]. A boundary vertex's fan starts with the
     * outgoing boundary half-edge; its last edge (incoming boundary) is vlast_edge[v]. */
    int32_t *vfan_start; /* nv + 1 */
    int32_t *vfan;       /* nh */
    int32_t *hfanpos;    /* nh: position of h in its origin vertex's fan */
    int32_t *vlast_edge; /* nv: incoming boundary edge of a boundary vertex, else -1 */
    uint8_t *vboundary;  /* nv */
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

#define CCN_KNOT_MIN_RATIO 1e-6
#define CCN_COORD_MAX 1e300 /* larger |coordinates| are rejected: results must stay finite */

#endif
