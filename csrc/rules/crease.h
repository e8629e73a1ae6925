/* Creases: OpenSubdiv's sharpness semantics (Sdc::Crease), internal; rules/crease.c.
 *
 * Sharpness is a float as in OpenSubdiv: <= 0 smooth, >= 10 infinite, in between semi-sharp.
 * A vertex's rule comes from its sharpness and the number of sharp edges around it (boundary
 * edges count as infinitely sharp): smooth (none), dart (one), crease (two), corner (three
 * or more, or vertex sharpness > 0). Each level every semi-sharp value decays (uniform: minus
 * one; Chaikin: 3/4 of itself plus 1/4 of the mean of the other semi-sharp edges at the end
 * vertex, minus one); where a vertex's rule changes from one level to the next its point is
 * the blend of the two rules' points with OpenSubdiv's fractional weight. */
#ifndef CCN_RULES_CREASE_H
#define CCN_RULES_CREASE_H

#include "topology/halfedge.h"

enum { CCN_RULE_SMOOTH = 1, CCN_RULE_DART = 2, CCN_RULE_CREASE = 4, CCN_RULE_CORNER = 8 };

#define CCN_SHARP_INF 10.0f

/* Sharpness one level finer of a vertex or (uniform) an edge. */
float ccn__sharp_decrement(float s);
/* Sharpness one level finer of each of n edges around a vertex (sharpness s, fan order): their
 * halves at that vertex (Sdc::Crease::SubdivideEdgeSharpnessesAroundVertex). */
void ccn__sharp_children(int method, int32_t n, const float *s, float *cs);
/* The rule of a vertex of sharpness vs with n edges of sharpness s. */
int ccn__sharp_rule(float vs, int32_t n, const float *s);
/* The two crease edges: the first and last sharp edge in fan order. */
void ccn__sharp_crease_ends(int32_t n, const float *s, int32_t ends[2]);
/* OpenSubdiv's weight of the parent rule's point where the rule changes (in [0,1]). */
float ccn__sharp_fraction(int method, float pvs, float cvs, int32_t n, const float *ps, const float *cs);

/* Sharpness of v's fan edges at this level (boundary edges: 10) into s; returns the count. */
int32_t ccn__fan_sharpness(const ccn_mesh *m, int32_t v, float *s);
/* Sharpness of v itself (pinned valence-2 boundary corners: infinite, as OpenSubdiv's
 * EDGE_AND_CORNER makes them). */
float ccn__vertex_sharpness(const ccn_mesh *m, int32_t v, int pinned);
/* Number of sharp fan edges of v (boundary edges count); 0 on a crease-free mesh's interior. */
int32_t ccn__sharp_count(const ccn_mesh *m, int32_t v);
/* Sharpness one level finer of the half of edge e at its endpoint v. */
float ccn__child_edge_sharpness(const ccn_mesh *m, int method, int32_t e, int32_t v);

#endif
