/* ccnurbs experiment: the numerical experiments of Li, Finnigan, Sederberg 2016, section 7.
 *
 *   maxima   the blending function of an extraordinary vertex (EV) with random spoke intervals
 *            has exactly one local maximum after L refinements (SPEC 3.2, DESIGN 4.3);
 *   charmap  the (12n+1) x (12n+1) three-ring refinement matrix has the spectrum
 *            1 > mu2 = mu3 > |mu4| and the characteristic map is regular and injective.
 * Results: tests/experiments/RESULTS.md; tests: tests/experiments/run_experiments.sh.
 * Code: this file (entry point, threads runner) and the exp_*.c files listed in exp.h.
 *
 * The cage ("G-ring fan"): valence-n centre vertex V, n sectors, sector s a G x G quad grid
 * between spoke s (angle 2 pi s / n) and spoke s+1. Grid point (s, i, j), 0 <= i, j <= G, sits
 * at i u_s + j u_{s+1}; (s, 0, j) is (s+1, j, 0) and (s, 0, 0) is V. Numbering (exp_fan_vid):
 * V = 0, then per sector i = 1..G, j = 0..G: 1 + s G (G+1) + (i-1)(G+1) + j; G = 3 gives
 * 12n+1 points, 9n faces, 21n edges. Every edge parallel to spoke s carries d_s (SPEC 3.2), so
 * opposite edges of every quad agree and the interval beyond every spoke end is the spoke's own.
 *
 * Where the blending function starts (--start): `level1` (default) refines the cage once, then
 * sets z = 1 at the EV's vertex point and 0 elsewhere. The level-1 mesh is again a fan whose
 * rings parallel to spoke s carry d_s, and every following refinement uses the scheme's EV
 * rules (for eigen: M at every level) -- the paper's and SPEC 3's setup. `cage` sets z on the
 * level-0 cage and refines that, which is the library pipeline: level 0 -> 1 uses NURSS rules at
 * the EV for every scheme (DESIGN 4.3), so its figures mix the two rule sets.
 *
 * Why three rings are exact: the blending function's control points at level k are non-zero
 * only strictly inside fine ring 2 * 2^k (its support is the 2-ring). A point whose stencil
 * differs from the infinite mesh's (boundary curve rules, mirrored intervals) only reads points
 * of fine rings >= R 2^k - 2, R = rings of the starting mesh (3 for `cage`, 4 for `level1`,
 * built from a 2-ring cage), which is >= 2 * 2^k for k >= 1 (and reads only zeros at k = 0);
 * mirrored intervals equal the true ones here anyway. So every refined z equals the
 * infinite-mesh value; --rings 6 (level1) / 4 (cage) checks it (run_experiments.sh (b)).
 * Local maximum (SPEC A11): z > 1e-12 and z strictly above every vertex sharing a face.
 *
 * Three-ring matrix (charmap): the cage (G = 3) is refined once to L1 (whose intervals are
 * again d_s, halved and normalised), so the matrix of L1 -> L2 is the stationary one. Its
 * 3-ring is found through topology (exp_ring_grid): V1 = the vertex point of V (index nf + ne + 0,
 * ccnurbs.h order) and its spoke-0 neighbour = the edge point of the cage edge (V, (0,1,0))
 * (index nf + e); each sector's grid is walked face by face through directed half-edges; the
 * same on L2 (exp_track_refine follows V and its spoke-0 neighbour through every refinement).
 * Column c is the refined 3-ring when 3-ring point c of L1 is 1 and all else 0 (three columns
 * per refine call, one per coordinate). Checks: rows sum to 1, the 1-ring rows equal
 * ccn_ev_matrix, and LAPACKE_dgeev's spectrum. The characteristic net (x, y = an orthonormal
 * basis of the mu2, mu3 eigenvectors) is placed on L1's 3-ring (all else 0) and refined; after
 * l levels rings <= 2^(l+1) + 1 depend on the 3-ring only.
 *   regular, injective (the limit surface; the pass criterion): at level 2 every face of rings
 *     2..4 is a regular bicubic patch; its Bezier net comes from the knot-interval form
 *     (span_bezier, checked against the next level to 5e-17). det J is a bidegree-(5,5)
 *     polynomial; its Bernstein coefficients all of one sign prove regularity, a corner value of
 *     the other sign (or 0) disproves it, otherwise the patch is split (up to 6 times). Injective:
 *     in addition the limit curves of parameter rings 2 and 4 (8 samples per face side) are
 *     simple, do not meet, wind +-1 (the Jacobian's sign) around the EV's limit (the origin,
 *     since mu2, mu3 != 1), and ring 2 lies inside ring 4: with a consistently signed Jacobian
 *     the number of preimages of a point is winding(outer) - winding(inner), so it is <= 1.
 *   net regular, net injective (diagnostic): the same on the control net of level k
 *     (--charlevels): quads of rings 2^(k-1)..2^k convex with one orientation (all four corner
 *     triangles), and the ring polygons. Control nets converge slowly where intervals differ
 *     by 100x, so this test also fails on some regular maps.
 */
#include "commands.h"
#include "exp.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__GLIBC__)
#include <malloc.h> /* mallopt */
#endif

#define EXP_CHUNK 8        /* cases taken by a worker at a time */

/* ---- running cases on threads ----------------------------------------------------------- */

static void run_case(exp_run *run, long i) {
    const exp_args *a = run->a;
    double d[EXP_MAX_N];
    int n = exp_case_setup(a, i, d);
    const fan_cage *c = &run->cages[exp_valence_slot(a, n)];
    ccn_error err;
    ccn_status st;
    if (a->kind == EXP_MAXIMA) st = exp_maxima_case(c, d, a, NULL, &run->mres[i], &err);
    else st = exp_charmap_case(c, d, a->scheme, a->poly, a->charlevels, &run->cres[i], &err);
    run->status[i] = (unsigned char)st;
}

static void *worker(void *p) {
    exp_run *run = p;
    for (;;) {
        long i0 = atomic_fetch_add(&run->next, EXP_CHUNK);
        if (i0 >= run->a->cases) break;
        for (long i = i0; i < i0 + EXP_CHUNK && i < run->a->cases; i++) run_case(run, i);
    }
    return NULL;
}

static int run_all(exp_run *run) {
    int T = run->a->threads;
    pthread_t *th = malloc(sizeof(pthread_t) * (size_t)T);
    if (!th) return -1;
    atomic_init(&run->next, 0);
    int started = 0;
    for (; started < T; started++)
        if (pthread_create(&th[started], NULL, worker, run)) break;
    if (started == 0) worker(run);
    for (int t = 0; t < started; t++) pthread_join(th[t], NULL);
    free(th);
    return 0;
}

/* ---- entry point ---------------------------------------------------------------------------- */

static int build_cages(const exp_args *a, fan_cage *cages) {
    int G = a->kind == EXP_MAXIMA ? (a->start ? (a->rings + 1) / 2 : a->rings) : 3;
    if (a->nknots) return exp_fan_build(&cages[0], a->nknots, G);
    for (int i = 0; i < a->nval; i++)
        if (exp_fan_build(&cages[i], a->val[i], G)) return -1;
    return 0;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int experiment(const exp_args *a) {
    fan_cage cages[EXP_MAX_VALS];
    memset(cages, 0, sizeof cages);
    exp_run run = {.a = a, .cages = cages};
    run.status = calloc((size_t)a->cases, 1);
    if (a->kind == EXP_MAXIMA) run.mres = calloc((size_t)a->cases, sizeof(max_result));
    else run.cres = calloc((size_t)a->cases, sizeof(cm_result));
    int rc = 2;
    double t0 = now_seconds();
    exp_print_header(a, a->kind == EXP_MAXIMA ? "maxima" : "charmap");
    fflush(stdout);
    if (!run.status || !(run.mres || run.cres) || build_cages(a, cages)) {
        fprintf(stderr, "ccnurbs experiment: out of memory\n");
    } else if (a->kind == EXP_MAXIMA && a->nknots) {
        rc = exp_maxima_knots(&run);
    } else if (run_all(&run) == 0) {
        long errors = a->kind == EXP_MAXIMA ? exp_maxima_report(&run) : exp_charmap_report(&run);
        rc = errors ? 1 : 0;
    }
    if (rc != 2) printf("time: %.3f s\n", now_seconds() - t0);
    for (int i = 0; i < EXP_MAX_VALS; i++) exp_fan_free(&cages[i]);
    free(run.status); free(run.mres); free(run.cres);
    return rc;
}

/* Every case allocates and frees the same large blocks; by default glibc serves them with
 * mmap and unmaps them on free, and the page faults double the run time. */
static void keep_freed_memory(void) {
#if defined(M_MMAP_THRESHOLD) && defined(M_TRIM_THRESHOLD)
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

int ccn_cmd_experiment(int argc, char **argv) {
    exp_args a;
    keep_freed_memory();
    if (argc < 2) return exp_usage();
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        exp_usage();
        return 0;
    }
    if (exp_parse_args(argc, argv, &a)) return exp_usage();
    if (a.kind == EXP_MAXIMA && a.levels < 1) {
        fprintf(stderr, "ccnurbs experiment: --levels must be >= 1\n");
        return 2;
    }
    return experiment(&a);
}
