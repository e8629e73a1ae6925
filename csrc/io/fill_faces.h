/* The fill faces that close the last hole around one irregular vertex (internal;
 * io/fill_faces.c, used by io/fill.c). */
#ifndef CCN_IO_FILL_FACES_H
#define CCN_IO_FILL_FACES_H

#include "io/export_model.h"

/* One mesh level of the local refinement prepared for fills: its next level's points around
 * the vertices (the exact limit stencils of surface/ring_limit.c are over them). */
typedef struct ccn__fill_level ccn__fill_level;
ccn_status ccn__fill_level_create(const ccn__plan_view *v, const ccn_mesh *m, ccn__fill_level **out,
                                  ccn_error *err);
void ccn__fill_level_destroy(ccn__fill_level *fl);

/* Is w regular in every sector of its fan (surface/limit.h ccn__sector_regular): no fill? */
int ccn__fill_vertex_regular(const ccn_mesh *m, int32_t w, int pinned);

/* The fill faces around irregular vertex w of the level (one B-spline face per fan face over
 * the 2x2 faces there, which it marks in covered[]): bicubic, or quintic where the bicubic
 * ones deviate from G1 across their smooth spokes and io/fill_g1.c makes them exact; fpl: the
 * places of the level's faces. spoke_dev (optional): the largest normal angle across the
 * smooth spokes of the faces made. CCN_ERR_INTERNAL when the faces around w are not regular
 * enough (the caller goes one level deeper). */
ccn_status ccn__fill_vertex(ccn__xmodel *xm, ccn__fill_level *fl, int32_t w, const ccn__xplace *fpl,
                            int32_t fill_id, uint8_t *covered, double *spoke_dev, ccn_error *err);

#endif
