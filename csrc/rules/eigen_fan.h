/* The verification of one eigen matrix M on the infinite regular fan around its EV (internal;
 * rules/eigen_fan.c): the two experiments of Li, Finnigan, Sederberg 2016 section 7 as the
 * library's own code, for the per-vertex choice of the eigen polyhedron (rules/eigen_select.c).
 *
 * The fan: valence n, sector s (between spokes s and s+1) a regular quad grid, every edge
 * parallel to spoke s carrying d_s (the situation of every EV from level 1 on, intervals
 * normalised). It is refined by exactly the engine's rules (refine/level.c: NURSS-form knot
 * insertion, the interval p_s = (d_{s-2} + d_{s+2})/2 beyond the EV, M for the 2n+1 red
 * points, in the engine's order), on a structured grid instead of a mesh; a test checks it
 * against ccn_refine on fan cages. */
#ifndef CCN_RULES_EIGEN_FAN_H
#define CCN_RULES_EIGEN_FAN_H

#include <stdint.h>

/* Face-local maxima (z > 1e-12 and above every vertex sharing a face) of the blending function
 * of the EV after `levels` refinements of z = 1 at the EV, 0 elsewhere (the experiment's
 * --start level1). M: (2n+1)^2, ring order F_0..F_{n-1}, E_0..E_{n-1}, V. Returns the count,
 * or -1 when out of memory. */
int32_t ccn__fan_maxima(int32_t n, const double *d, const double *M, int levels);
/* The same with the sum and the maximum of z over the level (for the test against the engine). */
int ccn__fan_blend_stats(int32_t n, const double *d, const double *M, int levels, double *zsum,
                         double *zmax, int32_t *maxima);

typedef struct {
    int spectrum;   /* M: 1 simple, lambda double and subdominant (LAPACK), and the outer rings
                       of the 3-ring eigenvector converged (their eigenvalues are below lambda) */
    int regular;    /* det J of every limit patch of rings 2..4 at level 2 keeps one sign */
    int injective;  /* the limit ring curves 2 and 4 are simple, nested, wind once */
    int bad_patches, undecided;
} ccn__charmap_result;

/* The characteristic map of M (the experiment `charmap`'s pass criterion, without its
 * diagnostics): P = the eigen polyhedron M was built from (2 (2n+1) doubles, ring order,
 * V = 0), T0 = (M P)_V, lambda its eigenvalue. Returns 0, or -1 when out of memory. */
int ccn__fan_charmap(int32_t n, const double *d, const double *M, const double *P,
                     const double T0[2], double lambda, ccn__charmap_result *r);

/* The same tests as continuous margins (the per-vertex choice blends candidates by them, so
 * the surface moves continuously with the intervals; rules/eigen_select.c):
 *   maxima: ccn__fan_maxima_margin's q in [-1, 1], negative when a second face-local maximum
 *           stands clear of the top (see eigen_fan.c); maxima = the count as ccn__fan_maxima.
 *   spectrum: 1 - FAN_SPECTRUM_MIN - |mu4| / lambda, |mu4| the largest eigenvalue modulus
 *           of M besides 1 and the double lambda; <= 0 fails (lambda not subdominant by that
 *           gap: the power iteration of the characteristic net would need too many steps);
 *   regular: min over the patches of rings 2..4 of the smallest Bernstein coefficient of
 *           det J after three uniform splits over the patch's largest, times the orientation:
 *           > 0 proves regularity; -1 when not computed;
 *   injective: the discrete test of ccn__fan_charmap, made only when regular > 0 (with a
 *           regular map it can change only where a ring curve passes the centre). */
typedef struct {
    double spectrum, regular;
    int injective;
} ccn__charmap_margin;

#define FAN_SPECTRUM_MIN 0.01

int ccn__fan_maxima_margin(int32_t n, const double *d, const double *M, int levels, double *q,
                           int32_t *maxima);
int ccn__fan_charmap_margin(int32_t n, const double *d, const double *M, const double *P,
                            const double T0[2], double lambda, ccn__charmap_margin *r);

#endif
