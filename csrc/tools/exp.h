/* Shared types, constants and prototypes of `ccnurbs experiment` (the method: the header
 * comment of cmd_experiment.c). The pieces, each using only those listed below it:
 *   cmd_experiment.c    entry point and the threads runner
 *   exp_report.c        the header line, tallies and reports; maxima with --knots
 *   exp_args.c          argument parsing and usage
 *   exp_charmap.c       charmap: the three-ring matrix, its spectrum, the characteristic net
 *   exp_charmap_geom.c  charmap: regularity and injectivity of the characteristic map
 *   exp_maxima.c        maxima: refinement of the blending function and its local maxima
 *   exp_quad.c          quad-mesh half-edges, the EV's ring grid, refinement following the EV
 *   exp_fan.c           random cases and the G-ring fan cage
 * This header has no .c of its own: types, constants and prototypes only. */
#ifndef CCN_EXP_H
#define CCN_EXP_H
#include "ccnurbs.h"

#include <stdatomic.h>
#include <stdint.h>

#define EXP_MAX_N 64       /* largest valence */
#define EXP_MAX_VALS 16    /* entries of --valences */
#define EXP_MAX_LATER 8    /* levels followed beyond L by --persist */
#define EXP_PI 3.14159265358979323846

typedef enum { EXP_MAXIMA, EXP_CHARMAP } exp_kind;

typedef struct {
    exp_kind kind;
    ccn_scheme scheme;
    int levels, rings, threads, list, persist, charlevels, dist_log, start;
    int poly; /* --polyhedron: ccn_options.ev_polyhedron (0 = the per-vertex choice) */
    long cases, offset;
    uint64_t seed;
    double lo;
    int nval, val[EXP_MAX_VALS];
    int nknots;
    double knots[EXP_MAX_N];
} exp_args;

/* The G-ring fan cage (cmd_experiment.c's header comment). */
typedef struct {
    int n, G;
    int32_t nv, nf, ne;
    double *pos;
    int32_t *fsize, *fverts, *everts;
    int32_t *edir; /* the spoke an edge is parallel to: its interval is d[edir] */
} fan_cage;

/* One maxima case. */
typedef struct {
    int maxima;       /* face-local maxima at the last level counted */
    int fallbacks;    /* num_ev_fallbacks of the refined mesh */
    int nonfinite;    /* refined z that are NaN / Inf */
    int show;         /* input: print the maxima */
    int nlater;       /* counts at levels L+1 .. (--persist) of a failing case */
    signed char later[EXP_MAX_LATER];
    int32_t support;  /* vertices with z > EXP_ZMIN */
    double zsum, zmax;
} max_result;

/* A quad mesh with half-edges indexed (exp_quad.c). */
typedef struct {
    int32_t nv, nf, ne;
    double *pos;
    int32_t *fv;       /* 4 * nf (all faces are quads after refinement) */
    int32_t *everts;   /* 2 * ne */
    int32_t *ostart;   /* nv + 1: outgoing half-edges (4 f + k) of each vertex */
    int32_t *out;
    double *eknot;     /* ne: ring intervals (exp_quad_load_knots) */
    int32_t *vestart;  /* nv + 1: edges at each vertex (exp_quad_load_knots) */
    int32_t *vedges;
} quad_mesh;

/* One charmap case. */
typedef struct {
    int spectrum, regular, injective, matrix_ok;  /* regular / injective: the limit surface */
    int net_regular, net_injective;               /* the same tests on control-net quads */
    int fallbacks, orient, wind_in, wind_out, bad_patches, undecided, crossings, defective;
    int net_orient, net_bad_quads;
    double mod[6];               /* |mu_1| .. |mu_6| */
    double mu2, mu3, im2;        /* real parts of mu2, mu3; |imag| of mu2 */
    double split, ratio, lam_err; /* |mu2-mu3|/|mu2|, |mu4|/|mu2|, max |mu2,3 - lambda_n| */
    double rowsum_err, m_err;    /* |row sum - 1|; 1-ring rows vs ccn_ev_matrix */
} cm_result;

/* A run: the cases, their results, and the next case to take (cmd_experiment.c). */
typedef struct {
    const exp_args *a;
    const fan_cage *cages; /* one per valence slot */
    atomic_long next;
    max_result *mres;
    cm_result *cres;
    unsigned char *status; /* ccn_status per case */
} exp_run;

/* ---- exp_args.c ---- */
/* Prints the usage to stderr and returns 2. */
int exp_usage(void);
/* argv[1] is the experiment's name; prints the problem and returns -1 on error. */
int exp_parse_args(int argc, char **argv, exp_args *o);

/* ---- exp_fan.c ---- */
/* Valence and spoke intervals (into d) of case a->offset + idx: a function of (seed, index). */
int exp_case_setup(const exp_args *a, long idx, double *d);
/* Index of valence n in a->val (0 with --knots), -1 if absent. */
int exp_valence_slot(const exp_args *a, int n);
/* Vertex index of grid point (s, i, j) of the valence-n, G-ring fan. */
int32_t exp_fan_vid(int n, int G, int s, int i, int j);
int exp_fan_build(fan_cage *c, int n, int G);
void exp_fan_free(fan_cage *c);
/* The cage with spoke intervals d as a mesh. */
ccn_status exp_fan_mesh(const fan_cage *c, const double *d, ccn_mesh **out, ccn_error *err);
/* Fills err with CCN_ERR_MEMORY and returns it. */
ccn_status exp_fail_memory(ccn_error *err);

/* ---- exp_quad.c ---- */
void exp_quad_free(quad_mesh *q);
/* Copies a mesh's positions, faces (must all be quads) and edges, and indexes half-edges. */
int exp_quad_load(const ccn_mesh *m, quad_mesh *q);
/* exp_quad_load plus the edge intervals and the edges at each vertex. */
int exp_quad_load_knots(const ccn_mesh *m, quad_mesh *q);
/* Interval of the edge a-b, or -1 if there is none (needs exp_quad_load_knots). */
double exp_edge_knot(const quad_mesh *q, int32_t a, int32_t b);
/* The G-ring grid of valence-n EV `ev` whose spoke-0 neighbour is s0, in exp_fan_vid order. */
int exp_ring_grid(const quad_mesh *q, int32_t ev, int32_t s0, int n, int G, int32_t *idx);
/* Refines m one level, following the EV and its spoke-0 neighbour. */
ccn_status exp_track_refine(const ccn_mesh *m, ccn_scheme scheme, int poly, int32_t *ev, int32_t *s0,
                            ccn_mesh **out, ccn_error *err);

/* ---- exp_maxima.c ---- */
/* One maxima case (per_level: counts at every level 1..L, or NULL). */
ccn_status exp_maxima_case(const fan_cage *c, const double *d, const exp_args *a,
                           int *per_level, max_result *r, ccn_error *err);

/* ---- exp_charmap_geom.c ---- */
/* The grid of G rings around the EV of m; the limit-surface test (regular, injective) on
 * rings R..2R, or the control-net test (net regular, net injective) on rings R..2R. */
ccn_status exp_surface_test(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                            cm_result *r, ccn_error *err);
ccn_status exp_net_test(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                        cm_result *r, ccn_error *err);

/* ---- exp_charmap.c ---- */
/* One charmap case; k = --charlevels. */
ccn_status exp_charmap_case(const fan_cage *cage, const double *d, ccn_scheme scheme, int poly, int k,
                            cm_result *r, ccn_error *err);

/* ---- exp_report.c ---- */
void exp_print_header(const exp_args *a, const char *what);
/* The reports after a run; return the number of cases that ended in an error. */
long exp_maxima_report(const exp_run *run);
long exp_charmap_report(const exp_run *run);
/* maxima with --knots: counts per level and the z statistics; returns the exit code. */
int exp_maxima_knots(const exp_run *run);
#endif
