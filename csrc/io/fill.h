/* Holes of the plan's patch set closed for the CAD export (internal; io/fill.c). */
#ifndef CCN_IO_FILL_H
#define CCN_IO_FILL_H

#include "io/export_model.h"

/* Smooth valence-2 vertices get their fills this many levels before the others (at least one
 * level below the hole): measured on catmark_car and catmark_val2_interior, the pieces next to
 * such a vertex and its fills lose about a factor 4 of their G1 to rounding per level, and at 6
 * levels they leave 3.9e-8 rad (OpenCASCADE's reading: 7e-8, fills 1.7e-7); 3 levels keep them
 * below 1e-8. */
#define CCN_FILL_LEVELS_V2 3

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
 * sectors of every irregular vertex, over the 2x2 faces there (CCN_EXPORT_FACE_FILL); smooth
 * valence-2 vertices CCN_FILL_LEVELS_V2 levels earlier (at least one level down). */
ccn_status ccn__fill_holes(ccn__xmodel *xm, const ccn__plan_view *v, int32_t level,
                           const int32_t *faces, int32_t n, ccn__fill_opts *o, ccn_error *err);

#endif
