/* Knot intervals of edge rings (internal). */
#ifndef CCN_TOPOLOGY_KNOTS_H
#define CCN_TOPOLOGY_KNOTS_H

#include "topology/halfedge.h"

/* Resolves ring intervals from per-edge candidate values (<= 0 / non-finite = unset) and
 * normalises them (by a power of two: largest in (1/2, 1]; clamped to >= 1e-6 of the largest). Writes m->eknot, m->knot_scale and the
 * ring counts in m->info. `source` (may be NULL) tags each edge's value with the identity of
 * where it came from; a ring's value is the mean over distinct sources (NULL: over edges). */
ccn_status ccn__resolve_rings(ccn_mesh *m, const double *edge_values, const int32_t *source,
                              ccn_error *err);
/* Per vertex of m, 1 where it ends an edge whose interval in the caller's units (eknot *
 * knot_scale: exact, the scales are powers of two) differs from q's, a mesh of the same
 * topology (an earlier plan's level); NULL when out of memory or the sizes differ. */
uint8_t *ccn__changed_interval_ends(const ccn_mesh *m, const ccn_mesh *q);

#endif
