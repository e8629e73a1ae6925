/* Cage topology (internal): allocation, vertex fans, info, unit-box normalisation of a
 * ccn_mesh (topology/halfedge.h). ccn_mesh_create and friends are public (ccnurbs.h). */
#ifndef CCN_TOPOLOGY_MESH_H
#define CCN_TOPOLOGY_MESH_H

#include "topology/halfedge.h"

ccn_mesh *ccn__mesh_alloc(int32_t nv, int32_t nf, int32_t nh, int32_t ne);
/* Builds vfan / hfanpos / vboundary / valence info from hvert/htwin/fstart. Returns 0 on
 * success, or the index + 1 of a vertex whose faces form more than one fan (non-manifold). */
int32_t ccn__mesh_build_fans(ccn_mesh *m);
void ccn__mesh_update_info(ccn_mesh *m);
/* The welded view of a split cage's mesh (halfedge.h: vweld, erep, eweld from vrep); a no-op
 * for a manifold one. -1 when out of memory. */
int ccn__mesh_weld(ccn_mesh *m);
/* r, the child of m: its representatives from m's (faces are never split), then welded. */
int ccn__mesh_weld_child(const ccn_mesh *m, ccn_mesh *r);
/* y[u] = 1 for every corner u of the faces around the n listed vertices; fm (may be NULL):
 * faces already visited, skipped and set (each face once). */
void ccn__mesh_mark_face_ring(const ccn_mesh *m, const int32_t *list, int32_t n, uint8_t *fm,
                              uint8_t *y);
/* Allocates esharp and vsharp (all 0); 0 on success. */
int ccn__mesh_alloc_sharpness(ccn_mesh *m);
/* Frees esharp and vsharp if every value is 0 (the crease-free rules then apply). */
void ccn__mesh_drop_smooth_sharpness(ccn_mesh *m);
/* Affine normalisation of positions to a unit box (the rules are affine-invariant). */
void ccn__normalize(ccn_mesh *m, double centre[3], double *scale);
void ccn__denormalize(ccn_mesh *m, const double centre[3], double scale);

#endif
