/* Knot removal for the CAD export's B-spline faces (internal; io/knot_removal.c). */
#ifndef CCN_IO_KNOT_REMOVAL_H
#define CCN_IO_KNOT_REMOVAL_H

#include "io/export_model.h"

/* Removes, from every face of xm and in both directions that are not periodic, each simple
 * interior knot the surface does not need: where it is C^3 across the knot's iso line (to the
 * rounding of its poles), the same surface has a representation without that knot (The NURBS
 * Book, 2nd ed., A5.8, applied to every pole row at once), in up to four rounds over the two
 * directions. A face moves by at most rel_tol times its own size per round (the diagonal of its
 * poles' bounding box: small faces keep their relative precision, and with it their normals),
 * or, where that is below the rounding of its coordinates, by 64 ulps of its largest coordinate
 * but no more than 1e-9 of its smallest pole spacing. Parameters, domains and cells are unchanged:
 * the face map and the topology read only those. A closed (periodic) direction stays periodic
 * where its knots allow. only_merged: only the faces merged since the last call (the others
 * have nothing left to remove); every face's `merged` is cleared. Returns the number of knots
 * removed, -1 when out of memory (xm->oom set; the faces stay valid). */
int64_t ccn__xm_remove_knots(ccn__xmodel *xm, double rel_tol, int only_merged);

/* Boehm's insertion of x into a B-spline curve of degree p with n poles of w doubles each
 * (P: n x w, flat knots t: n + p + 1 values; both with room for one more). */
void ccn__insert_knot(double *P, int32_t *n, int32_t w, double *t, int32_t p, double x);

/* Rows x n poles W (W[row][k], 3 each) along clamped flat knots U (n + p + 1): every interior
 * knot copy the rows do not need (of the value `only`, every value if it is NaN) removed, checked
 * as a whole within tol (model units). Returns the copies removed and updates U, W, *n; 0 when
 * none could be (U, W unchanged); -1 when out of memory. */
int32_t ccn__kr_reduce_rows(double *U, int32_t p, int32_t *n, int32_t rows, double *W, double tol,
                            double only);

/* A periodic direction's rows (rows x n poles W[row][k] along the flat knots U of the cad.h
 * form) unwrapped to the clamped form over the same domain (exact knot insertion): U becomes
 * n + p + 1 clamped knots, W rows x n. U: room for n + 3p + 1, W: rows x (n + 2p). 0, or -1
 * when out of memory. */
int ccn__kr_unwrap_periodic(double *U, int32_t p, int32_t n, int32_t rows, double *W);
/* The inverse: clamped rows (n poles, simple interior knots) back to the periodic form of the
 * same spline (least squares, kept only if it reproduces them within tol): 0 done (U, W in the
 * periodic form, n poles), 1 not (unchanged; too many spans, too few, or not periodic), -1 out
 * of memory. */
int ccn__kr_rewrap_periodic(double *U, int32_t p, int32_t n, int32_t rows, double *W, double tol);

#endif
