/* Merging the CAD export's faces across whole shared sides (internal; io/face_merge.c). */
#ifndef CCN_IO_FACE_MERGE_H
#define CCN_IO_FACE_MERGE_H

#include "io/export_model.h"

/* Merges, in rounds until none is left, pairs of faces of one kind (packs, bicubic, bi-5,
 * refined; never fills) that share a whole side (no crease) and whose union is one spline at
 * least C^1 across the join, checked within rel_tol times the larger face's size plus the
 * rounding of its coordinates. unify: also sides whose knots or cells differ (both made the
 * union's first) and degree-3 faces of different kinds, where the union has no more poles than
 * the two (face_merge.c). The merged face replaces the first, the second is removed
 * (xm->num_faces shrinks). *merged: the number of merges. Returns CCN_OK or the failure (err
 * set; xm stays valid). cage: the plan's level 0. */
ccn_status ccn__xm_merge_faces(ccn__xmodel *xm, const ccn_mesh *cage, double rel_tol, int unify,
                               int64_t *merged, ccn_error *err);

#endif
