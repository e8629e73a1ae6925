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
/* Its weights (topology and intervals only): m_i, f_i per fan edge i (mf[2i], mf[2i+1]) and
 * ab = ((n-3)/n, 3/(n sum(m_i + f_i))); and their blend of the current points. */
void ccn__nurss_vertex_weights(const ccn_mesh *m, int32_t v, double *mf, double ab[2]);
void ccn__nurss_vertex_blend(const ccn_mesh *m, int32_t v, const double *mf, const double ab[2],
                             const double *H, const double *fp, double out[3]);

#endif
