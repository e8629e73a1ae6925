/* The refined mesh's topology and intervals (internal; refine/children.c): the next level of a
 * mesh has one vertex per face, edge and vertex (faces first, then edges, then vertices), one
 * quad per face corner, two child edges per edge and one per corner. */
#ifndef CCN_REFINE_CHILDREN_H
#define CCN_REFINE_CHILDREN_H

#include "topology/halfedge.h"

/* The next level's numbering for any numbering of m's corners by vertices hvert and edges
 * hedge (m->nh each; everts: their ne edges' ends), such as a face-varying channel's values:
 * child corner 4h + k's vertex and edge (4 * m->nh each) and the 2 ne + nh child edges' ends.
 * The child faces and corners are m's child's. On up to `threads`. */
void ccn__children_numbering(const ccn_mesh *m, int32_t ne, const int32_t *hvert,
                             const int32_t *hedge, const int32_t *everts, int32_t *chvert,
                             int32_t *chedge, int32_t *ceverts, int threads);
/* The child mesh r's corners, twins, faces (r allocated for m's child). */
void ccn__children_topology(const ccn_mesh *m, ccn_mesh *r, int threads);
/* The child edges' candidate intervals (2 ne + nh): the two halves of each edge, and for the
 * edge from face point to edge point of half-edge h (NURSS Fig. 10) half the mean of the two
 * sides adjacent to edge h. */
void ccn__children_candidates(const ccn_mesh *m, double *cand);
/* r's intervals from the candidates: halves where every face is a quad (normalised by a power
 * of two), else the rings resolved again (topology/knots.c). */
ccn_status ccn__children_intervals(const ccn_mesh *m, ccn_mesh *r, double *cand, ccn_error *err);

#endif
