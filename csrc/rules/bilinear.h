/* Inverse bilinear map (internal; rules/bilinear.c), used by the eigen rules' face and edge
 * points (Li 2016 eqs (30)-(32)). */
#ifndef CCN_RULES_BILINEAR_H
#define CCN_RULES_BILINEAR_H

/* Inverse of the bilinear map
 *     B(a1, a2) = (1-a1)(1-a2) p0 + a1(1-a2) p1 + a1 a2 p2 + (1-a1) a2 p3,
 * corners pk = (corners[2k], corners[2k+1]) in cyclic order, either orientation: finds
 * (a1, a2) with B(a1, a2) = x.
 * Floater 2015's closed form (paper eqs (31)-(32)) with the orientation sign of SPEC 2.4;
 * of the (up to two) roots the one inside / nearest the unit square is returned. If the
 * closed form is ill-conditioned (substitution residual too large) a safeguarded Newton
 * iteration from several starts is used instead.
 * Returns 0 on success (|B(a1,a2) - x| <= 1e-10 * quad size), 1 if no real solution was
 * found (D < 0, non-convex quad), 2 on degenerate or non-finite input. On failure *a1, *a2
 * are set to NaN. */
int ccn__bilinear_inverse(const double corners[8], const double x[2], double *a1, double *a2);

/* The same, also giving D / Dscale of Floater's discriminant (in [-1, 1]; the two roots meet
 * at 0 and leave the real plane below it), a continuous measure of how far the solve is from
 * having no real root. */
int ccn__bilinear_inverse_d(const double corners[8], const double x[2], double *a1, double *a2,
                            double *dratio);

#endif
