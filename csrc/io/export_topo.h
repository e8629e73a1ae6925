/* Topology of the CAD export's faces from their places on the cage (internal;
 * io/export_topo.c). */
#ifndef CCN_IO_EXPORT_TOPO_H
#define CCN_IO_EXPORT_TOPO_H

#include "io/export_model.h"

/* Side breaks and adjacency of the faces (cad.h's model) from their places on the cage;
 * crease[seg] = 1 where the segment lies on an infinitely sharp cage edge (a C0 edge). */
ccn_status ccn__xtopo_build(const ccn__xmodel *xm, const ccn_mesh *cage, int32_t **breaks_start,
                            double **breaks, int32_t **adjacency, uint8_t **crease, ccn_error *err);

#endif
