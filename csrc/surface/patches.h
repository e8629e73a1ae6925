/* Bicubic Bézier patches of regular faces (patches.c). Internal. */
#ifndef CCN_SURFACE_PATCHES_H
#define CCN_SURFACE_PATCHES_H

#include "surface/limit.h"

/* The 4x4 net of quad f (net[i+1][j+1] = point (i,j), i along its first half-edge) and the
 * B-spline -> Bézier matrices of both directions; 0 if a corner is not regular, or (strict)
 * if some net vertex is not regular, i.e. the patch would not be the subdivision limit. */
int ccn__bicubic_net(const ccn_mesh *m, int32_t f, int pinned, int strict, ccn__vpoint net[4][4],
                     double Cu[4][4], double Cv[4][4]);
/* Bézier control points bez[i][j] (i along u = first half-edge) from m->pos; 0 if the face
 * is not a regular patch. */
int ccn__bicubic_patch(const ccn_mesh *m, int32_t f, int pinned, int strict, double bez[4][4][3]);
/* Tensor Bézier patch of degree deg (<= 5), control points b[(i*(deg+1)+j)*3], i along u:
 * position and first derivatives at (u, v). */
void ccn__bezier_eval(const double *b, int deg, double u, double v, double pos[3],
                      double du[3], double dv[3]);
#endif
