/* NURSS rules (Sederberg et al. 1998) for what knot insertion cannot do (internal;
 * rules/nurss.c). */
#ifndef CCN_RULES_NURSS_H
#define CCN_RULES_NURSS_H

#include "topology/halfedge.h"

/* NURSS face point of a face with != 4 sides (Sederberg et al. 1998). */
void ccn__ngon_face_point(const ccn_mesh *m, int32_t f, double out[3]);
/* NURSS vertex point of an interior vertex of any valence (valence 4: tensor rule (7)). */
void ccn__nurss_vertex_point(const ccn_mesh *m, int32_t v, const double *H, const double *fp,
                             double out[3]);

#endif
