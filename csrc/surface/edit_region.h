/* What an interval edit changes of the earlier plan's last evaluation (internal;
 * surface/edit_region.c, for surface/plan.c and surface/tessellate.c). */
#ifndef CCN_SURFACE_EDIT_REGION_H
#define CCN_SURFACE_EDIT_REGION_H

#include "surface/plan_types.h"

typedef struct { int32_t nf, ne, nv; int32_t *f, *e, *v; } ccn__edit_lists;

struct ccn__edit_region {
    double *pos0;           /* the earlier plan's normalised cage positions of its last evaluate */
    double centre[3], scale;
    int32_t R;
    ccn__edit_lists *lists; /* per level l < R: the elements whose level-(l+1) points may change */
    uint8_t *dirtyL;        /* per level-L vertex: its point may change */
    uint8_t *redo;          /* per output vertex: its stencil row was made again (tessellate.c) */
    int32_t nrows, *rows;   /* the output rows to apply again */
    uint8_t *written;       /* evaluate's scratch: per output vertex, written by this call */
    const double *out[3];   /* the arrays the earlier plan's last evaluation wrote (its last_out) */
};

/* During ccn_plan_create with options.previous, after the levels are built (before setup_level_s): when the earlier
 * plan p->hint was evaluated, its levels' points become p's (moved) and p->region records
 * which of them the edit changes; else p->region stays NULL. 0, or -1 when out of memory. */
int ccn__edit_region_begin(ccn_plan *p);
/* After the stencil table is made: the rows to apply again; the region is dropped when the
 * table did not record which rows it made again. 0, or -1 when out of memory. */
int ccn__edit_region_rows(ccn_plan *p);
void ccn__edit_region_free(struct ccn__edit_region *r);

#endif
