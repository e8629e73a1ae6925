/* The exact bicubic surround of a guided cap one level finer (internal; surface/surround.c). */
#ifndef CCN_SURFACE_SURROUND_H
#define CCN_SURFACE_SURROUND_H

#include "topology/halfedge.h"

/* The exact level-(K+1) bicubic surround of the cap of EV ev (level K), as 4 bi-5 pieces per
 * sector over the hole (layout of ccn__bi5_apply_pieces); 0 if it is not there.
 * pieces = NULL: check the topology only (reads no positions). */
int ccn__cap_surround(const ccn_mesh *mK, const ccn_mesh *mK1, int32_t ev, int pinned,
                      double *pieces);

#endif
