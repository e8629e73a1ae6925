/* The output mesh of a plan (internal; surface/tessellate.c). */
#ifndef CCN_SURFACE_TESSELLATE_H
#define CCN_SURFACE_TESSELLATE_H

#include "surface/plan_types.h"

/* Output topology, face origins and the limit stencil of every output vertex. */
ccn_status ccn__tess_output(ccn_plan *p, ccn_error *err);
/* The output vertices inside each cap hole and on the ring faces around it (after caps). */
ccn_status ccn__tess_holes(ccn_plan *p, ccn_error *err);

#endif
