/* Non-manifold cages made manifold (internal; topology/split.c): non-manifold edges and
 * vertices, as OpenSubdiv reads them, become boundaries and copies of vertices on a manifold
 * cage, sharpened as OpenSubdiv sharpens them. */
#ifndef CCN_TOPOLOGY_SPLIT_H
#define CCN_TOPOLOGY_SPLIT_H

#include "ccnurbs.h"


typedef struct {
    int split;                /* 0: the cage is manifold (nothing below is set) */
    int32_t num_verts;        /* the cage's vertices, then the copies */
    double *positions;        /* 3 * num_verts */
    int32_t *face_verts;      /* the cage's corners on the copies (faces unchanged) */
    int32_t *vorig;           /* num_verts: the cage vertex of each (vertex v < the cage's: v) */
    int32_t num_edges;        /* one per face corner: its edge's listed interval and crease */
    int32_t *edge_verts;
    double *edge_knots, *edge_creases;
    double *vertex_creases;   /* num_verts; non-manifold vertices infinitely sharp */
    int32_t ignored_edges;    /* listed edges of the cage that no face uses */
} ccn__split;

/* Splits the cage (basic checks passed: nh corners, indices in range) if it is not manifold;
 * s->split = 0 and nothing allocated if it is. CCN_OK or CCN_ERR_MEMORY. */
ccn_status ccn__split_cage(const ccn_cage *c, int32_t nh, ccn__split *s, ccn_error *err);
void ccn__split_free(ccn__split *s);

#endif
