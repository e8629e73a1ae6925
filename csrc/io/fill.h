/* Holes of the plan's patch set closed for the CAD export (internal; io/fill.c). */
#ifndef CCN_IO_FILL_H
#define CCN_IO_FILL_H

#include "io/export_model.h"

typedef struct {
    int32_t levels;          /* refinement levels below the holes' level (>= 1) */
    int packed;              /* pack the exact pieces of each level */
    int32_t num_fills;       /* out: irregular vertices closed by fill faces */
    int32_t fill_level;      /* out: level of the fill faces */
} ccn__fill_opts;

/* The holes faces[0..n-1] of plan level `level` (the plan has no patch there): refined
 * o->levels levels deeper around them (below the level where the last semi-sharp value
 * decayed, if any), the exact bicubic pieces of every level (strict faces:
 * CCN_EXPORT_FACE_REFINED), then at the last level one fill face per fan face in the irregular
 * sectors of every irregular vertex, over the 2x2 faces there (CCN_EXPORT_FACE_FILL). */
ccn_status ccn__fill_holes(ccn__xmodel *xm, const ccn__plan_view *v, int32_t level,
                           const int32_t *faces, int32_t n, ccn__fill_opts *o, ccn_error *err);

#endif
