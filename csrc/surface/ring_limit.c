/* Exact limits from the stationary 1-ring subdivision matrix (surface/ring_limit.h).
 *
 * The 1-ring of a vertex V one level finer (its vertex point, the edge points of its spokes,
 * the face points of its faces) refines into the 1-ring of V's next vertex point, and nothing
 * else enters: face points read their face, a spoke's edge point its two ends and the two face
 * points beside it, V's point its fan. From level l+1 on, every interval along a spoke is the
 * spoke's own (the knot is inserted in the middle of each span), so the 1-ring's matrix S is
 * the same at every further level once the spokes' and V's sharpness no longer change (0 or
 * infinite). S is computed here by running the refinement itself (refine/level.c) on a
 * synthetic mesh made of the 1-ring only, with the unit vectors as positions: the synthetic
 * mesh's outer vertices are boundary vertices, whose look-ups mirror, which is exactly what
 * the real mesh's look-ups give there from level l+1 on (the interval beyond an edge point
 * along its spoke is the spoke's other half). Semi-sharp values still left at level l+1 are
 * refined away first: the matrices of those levels, with the decayed sharpness, are multiplied
 * in front.
 *
 * From the stationary S (sectors of the fan between consecutive infinitely sharp spokes refine
 * independently, so each sector's rows form a closed block):
 *   position: the crease curve's limit along V's two sharp spokes (1-D B-spline limit, the
 *     intervals along each spoke being the spoke's), V itself at a corner, else the left
 *     eigenvector of S for the eigenvalue 1 (darts, interior valence 2, ...);
 *   tangents, per sector: the left eigenvectors of the sector block for its two largest
 *     eigenvalues of modulus < 1 (a complex pair: real and imaginary parts). Their orientation
 *     comes from the right eigenvectors, i.e. the characteristic map: the sector's ring polygon
 *     (V, E_a, F_a, E_a+1, ..., E_b) must run counter-clockwise in it, as the faces do; so the
 *     normal's sign never depends on how the control net is folded.
 * Results are cached per 1-ring configuration (valence, boundary, intervals, sharpness). */
#include "surface/ring_limit.h"

#include "base/error.h"
#include "refine/level.h"
#include "rules/bspline.h"
#include "rules/crease.h"
#include "topology/mesh.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAXV CCN_RING_MAX_VALENCE
#define MAXP CCN_RING_MAX_PTS
#define MAX_DECAY 16 /* levels a semi-sharp value (< 10) needs at most to decay */

typedef struct {
    int32_t n, boundary, pinned, scheme, method;
    double d[MAXV]; /* spoke intervals, largest = 1 */
    float c[MAXV];  /* spoke sharpness at the 1-ring's level (boundary spokes: 0) */
    float vs;       /* V's sharpness */
} ring_cfg;

typedef struct {
    uint64_t hash;
    ring_cfg cfg;
    int32_t nsec, npts;
    int32_t sec_face0[MAXV], sec_nface[MAXV];
    double *wp, *wu, *wv; /* npts, nsec x npts, nsec x npts */
} cache_entry;

struct ccn__ring_work {
    double *S, *T, *U;          /* MAXP^2 each */
    double *A, *VL, *VR, *wr, *wi;
    double *wu, *wv;            /* the last result's tangents (nsec x npts) */
    cache_entry *cache;
    int32_t ncache, capcache;
    int32_t *slot;              /* open-addressing index into cache, nslot entries, -1 = free */
    int32_t nslot;
    int32_t ev_poly;            /* eigen polyhedron option and the owner's choice cache, for */
    ccn__ev_cache *ev_cache;    /* the EV limits computed with this work (surface/limit.c) */
};

void ccn__ring_work_set_ev(ccn__ring_work *w, int32_t ev_poly, ccn__ev_cache *cache) {
    w->ev_poly = ev_poly;
    w->ev_cache = cache;
}

void ccn__ring_work_ev(const ccn__ring_work *w, int32_t *ev_poly, ccn__ev_cache **cache) {
    *ev_poly = w ? w->ev_poly : CCN_POLY_SELECT;
    *cache = w ? w->ev_cache : NULL;
}

ccn__ring_work *ccn__ring_work_create(void) {
    ccn__ring_work *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    size_t p2 = (size_t)MAXP * MAXP;
    w->S = malloc(sizeof(double) * p2);
    w->T = malloc(sizeof(double) * p2);
    w->U = malloc(sizeof(double) * p2);
    w->A = malloc(sizeof(double) * p2);
    w->VL = malloc(sizeof(double) * p2);
    w->VR = malloc(sizeof(double) * p2);
    w->wr = malloc(sizeof(double) * MAXP);
    w->wi = malloc(sizeof(double) * MAXP);
    if (!w->S || !w->T || !w->U || !w->A || !w->VL || !w->VR || !w->wr || !w->wi) {
        ccn__ring_work_destroy(w);
        return NULL;
    }
    return w;
}

void ccn__ring_work_destroy(ccn__ring_work *w) {
    if (!w) return;
    for (int32_t i = 0; i < w->ncache; i++) {
        free(w->cache[i].wp); free(w->cache[i].wu); free(w->cache[i].wv);
    }
    free(w->cache);
    free(w->slot);
    free(w->S); free(w->T); free(w->U); free(w->A); free(w->VL); free(w->VR); free(w->wr);
    free(w->wi); free(w->wu); free(w->wv);
    free(w);
}

static int32_t nfaces(const ring_cfg *g) { return g->boundary ? g->n - 1 : g->n; }

/* ---- the synthetic 1-ring mesh and its matrix ------------------------------------------ */

/* Vertices V = 0, E_k = 1 + k, F_k = 1 + n + k; face k = (V, E_k, F_k, E_k+1). The edge
 * E_k-F_k is parallel to spoke k+1, F_k-E_k+1 to spoke k (intervals of the child 1-ring). */
static ccn_status synthetic_mesh(const ring_cfg *g, ccn_mesh **out, ccn_error *err) {
    int32_t n = g->n, nf = nfaces(g), nv = 1 + n + nf, ne = n + 2 * nf;
    int32_t fsz[MAXV], fv[4 * MAXV], ev[2 * 3 * MAXV];
    double pos[3 * MAXP], kn[3 * MAXV], cr[3 * MAXV], vc[MAXP];
    memset(pos, 0, sizeof(double) * 3 * (size_t)nv);
    memset(vc, 0, sizeof(double) * (size_t)nv);
    vc[0] = g->vs;
    for (int32_t k = 0; k < nf; k++) {
        int32_t k1 = (k + 1) % n;
        fsz[k] = 4;
        fv[4 * k] = 0; fv[4 * k + 1] = 1 + k; fv[4 * k + 2] = 1 + n + k; fv[4 * k + 3] = 1 + k1;
        ev[2 * (n + 2 * k)] = 1 + k;          ev[2 * (n + 2 * k) + 1] = 1 + n + k;
        kn[n + 2 * k] = g->d[k1];             cr[n + 2 * k] = 0;
        ev[2 * (n + 2 * k + 1)] = 1 + n + k;  ev[2 * (n + 2 * k + 1) + 1] = 1 + k1;
        kn[n + 2 * k + 1] = g->d[k];          cr[n + 2 * k + 1] = 0;
    }
    for (int32_t k = 0; k < n; k++) {
        ev[2 * k] = 0; ev[2 * k + 1] = 1 + k;
        kn[k] = g->d[k]; cr[k] = g->c[k];
    }
    ccn_cage c = {nv, nf, ne, pos, fsz, fv, ev, kn, cr, vc};
    return ccn_mesh_create(&c, out, err);
}

/* S (npts x npts, row-major): child 1-ring = S * 1-ring, both in the order V, E_k, F_k. */
static ccn_status ring_matrix(const ring_cfg *g, double *S, ccn_error *err) {
    ccn_mesh *m = NULL;
    ccn_status st = synthetic_mesh(g, &m, err);
    if (st) return st;
    int32_t n = g->n, nf = nfaces(g), np = 1 + n + nf;
    int32_t row[MAXP];
    row[0] = m->nf + m->ne + 0;
    for (int32_t k = 0; k < n; k++) {
        int32_t e = ccn__fan_edge(m, 0, k);
        int32_t other = m->everts[2 * e] == 0 ? m->everts[2 * e + 1] : m->everts[2 * e];
        if (other != 1 + k) { ccn_mesh_destroy(m); return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "ring limit: fan order"); }
        row[1 + k] = m->nf + e;
    }
    for (int32_t k = 0; k < nf; k++) row[1 + n + k] = k;
    ccn__level lev;
    st = ccn__level_prepare(&lev, m, g->scheme, g->pinned, g->method, err);
    double *out = st ? NULL : malloc(sizeof(double) * 3 * ((size_t)m->nf + m->ne + m->nv));
    if (!st && !out) st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (ring limit)");
    for (int32_t b = 0; !st && 3 * b < np; b++) {
        memset(m->pos, 0, sizeof(double) * 3 * (size_t)m->nv);
        for (int c = 0; c < 3 && 3 * b + c < np; c++) m->pos[3 * (3 * b + c) + c] = 1.0;
        ccn__level_points(&lev, out);
        for (int32_t r = 0; r < np; r++)
            for (int c = 0; c < 3 && 3 * b + c < np; c++) S[(size_t)r * np + 3 * b + c] = out[3 * (size_t)row[r] + c];
    }
    if (lev.m) ccn__level_free(&lev);
    free(out);
    ccn_mesh_destroy(m);
    return st;
}

static int stationary(const ring_cfg *g) {
    if (g->vs > 0.0f && g->vs < CCN_SHARP_INF) return 0;
    for (int32_t k = 0; k < g->n; k++)
        if (g->c[k] > 0.0f && g->c[k] < CCN_SHARP_INF) return 0;
    return 1;
}

/* The 1-ring's sharpness one level finer (the halves of the spokes at V). */
static void decay(ring_cfg *g) {
    float s[MAXV], cs[MAXV];
    for (int32_t k = 0; k < g->n; k++)
        s[k] = g->boundary && (k == 0 || k == g->n - 1) ? CCN_SHARP_INF : g->c[k];
    ccn__sharp_children(g->method, g->n, s, cs);
    for (int32_t k = 0; k < g->n; k++)
        if (!(g->boundary && (k == 0 || k == g->n - 1))) g->c[k] = cs[k];
    g->vs = ccn__sharp_decrement(g->vs);
}

/* ---- eigenvectors -------------------------------------------------------------------- */

/* Left (VL) and right (VR) eigenvectors of the block B (m x m) of S on rows/columns idx.
 * Returns 0 on success. Eigenvector j is column j of VL / VR (LAPACK's pairs for complex). */
static int block_eig(ccn__ring_work *w, const double *S, int32_t np, const int32_t *idx, int32_t m) {
    for (int32_t a = 0; a < m; a++)
        for (int32_t b = 0; b < m; b++) w->A[(size_t)a * m + b] = S[(size_t)idx[a] * np + idx[b]];
    return LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'V', 'V', m, w->A, m, w->wr, w->wi, w->VL, m, w->VR, m) != 0;
}

/* The eigenvalue closest to 1 (its left eigenvector, summing to 1) into l0; -1 on failure. */
static int dominant(ccn__ring_work *w, int32_t m, double *l0) {
    int32_t i0 = 0;
    for (int32_t i = 1; i < m; i++)
        if (fabs(w->wr[i] - 1) + fabs(w->wi[i]) < fabs(w->wr[i0] - 1) + fabs(w->wi[i0])) i0 = i;
    double sum = 0;
    for (int32_t r = 0; r < m; r++) sum += w->VL[(size_t)r * m + i0];
    if (!(fabs(sum) > 1e-300) || fabs(w->wr[i0] - 1) > 1e-6) return -1;
    for (int32_t r = 0; r < m; r++) l0[r] = w->VL[(size_t)r * m + i0] / sum;
    return 0;
}

/* The two tangent eigenvectors (largest |lambda| < 1) of the block: left ones into t1, t2,
 * right ones into r1, r2. Returns -1 if there are not two. */
static int tangents(ccn__ring_work *w, int32_t m, double *t1, double *t2, double *r1, double *r2) {
    int32_t i1 = -1, i2 = -1;
    for (int32_t i = 0; i < m; i++) {
        double mod = hypot(w->wr[i], w->wi[i]);
        if (mod > 1.0 - 1e-9) continue; /* the eigenvalue(s) 1 */
        if (i1 < 0 || mod > hypot(w->wr[i1], w->wi[i1]) + 1e-12) { i2 = i1; i1 = i; }
        else if (i2 < 0 || mod > hypot(w->wr[i2], w->wi[i2]) + 1e-12) i2 = i;
    }
    if (i1 < 0) return -1;
    int cplx = w->wi[i1] != 0.0;
    if (cplx) {
        if (w->wi[i1] < 0) i1--; /* the pair is stored as (re, im) in columns i, i+1 */
        i2 = i1 + 1;
    } else if (i2 < 0 || w->wi[i2] != 0.0) {
        /* the second largest is a complex pair while the largest is real: take its real part */
        if (i2 < 0) return -1;
        if (w->wi[i2] < 0) i2--;
    }
    for (int32_t r = 0; r < m; r++) {
        t1[r] = w->VL[(size_t)r * m + i1]; t2[r] = w->VL[(size_t)r * m + i2];
        r1[r] = w->VR[(size_t)r * m + i1]; r2[r] = w->VR[(size_t)r * m + i2];
    }
    return 0;
}

/* ---- one vertex ---------------------------------------------------------------------- */

static uint64_t cfg_hash(const ring_cfg *g) {
    const unsigned char *p = (const unsigned char *)g;
    size_t len = offsetof(ring_cfg, d);
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < len; i++) h = (h ^ p[i]) * 1099511628211ull;
    for (int32_t k = 0; k < g->n; k++) {
        const unsigned char *q = (const unsigned char *)&g->d[k], *r = (const unsigned char *)&g->c[k];
        for (size_t i = 0; i < sizeof(double); i++) h = (h ^ q[i]) * 1099511628211ull;
        for (size_t i = 0; i < sizeof(float); i++) h = (h ^ r[i]) * 1099511628211ull;
    }
    const unsigned char *q = (const unsigned char *)&g->vs;
    for (size_t i = 0; i < sizeof(float); i++) h = (h ^ q[i]) * 1099511628211ull;
    return h;
}

static int cfg_equal(const ring_cfg *a, const ring_cfg *b) {
    if (a->n != b->n || a->boundary != b->boundary || a->pinned != b->pinned || a->scheme != b->scheme ||
        a->method != b->method || a->vs != b->vs)
        return 0;
    for (int32_t k = 0; k < a->n; k++)
        if (a->d[k] != b->d[k] || a->c[k] != b->c[k]) return 0;
    return 1;
}

/* Sectors of the stationary 1-ring (sharp: boundary spokes and infinitely sharp spokes). */
static void sectors(const ring_cfg *g, ccn__ring_limit *o) {
    int32_t n = g->n, sharp[MAXV], ns = 0;
    for (int32_t k = 0; k < n; k++)
        if ((g->boundary && (k == 0 || k == n - 1)) || g->c[k] >= CCN_SHARP_INF) sharp[ns++] = k;
    o->nsec = 0;
    if (g->boundary) { /* sharp[0] = 0 ... sharp[ns-1] = n-1 */
        for (int32_t i = 0; i + 1 < ns; i++) {
            o->sec_face0[o->nsec] = sharp[i];
            o->sec_nface[o->nsec++] = sharp[i + 1] - sharp[i];
        }
    } else if (ns < 2) {
        o->sec_face0[0] = ns ? sharp[0] : 0;
        o->sec_nface[0] = n;
        o->nsec = 1;
    } else {
        for (int32_t i = 0; i < ns; i++) {
            int32_t a = sharp[i], b = sharp[(i + 1) % ns];
            o->sec_face0[o->nsec] = a;
            o->sec_nface[o->nsec++] = ((b - a) % n + n) % n;
        }
    }
}

/* Position and per-sector tangents over the stationary 1-ring (ring order), into o->wp and
 * w->wu / w->wv. */
static ccn_status solve_stationary(ccn__ring_work *w, const ring_cfg *g, const double *S,
                                   ccn__ring_limit *o, ccn_error *err) {
    int32_t n = g->n, nf = nfaces(g), np = 1 + n + nf;
    sectors(g, o);
    int32_t nsharp = 0, ends[2] = {-1, -1};
    for (int32_t k = 0; k < n; k++)
        if ((g->boundary && (k == 0 || k == n - 1)) || g->c[k] > 0.0f) {
            if (nsharp < 2) ends[nsharp] = k;
            nsharp++;
        }
    int corner = g->vs > 0.0f || nsharp > 2 || (g->pinned && g->boundary && n == 2);
    memset(o->wp, 0, sizeof(double) * (size_t)np);
    if (corner) {
        o->wp[0] = 1.0;
    } else if (nsharp == 2) { /* the crease curve's limit: 1-D, intervals d_a | d_b */
        double wl[3], dw[3], da = g->d[ends[0]], db = g->d[ends[1]];
        ccn__curve_limit_weights(da, da, db, db, wl, dw);
        o->wp[1 + ends[0]] = wl[0]; o->wp[0] = wl[1]; o->wp[1 + ends[1]] = wl[2];
    } else {
        int32_t idx[MAXP];
        for (int32_t i = 0; i < np; i++) idx[i] = i;
        if (block_eig(w, S, np, idx, np) || dominant(w, np, o->wp))
            return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "ring limit: no eigenvalue 1");
    }
    free(w->wu); free(w->wv);
    w->wu = calloc((size_t)o->nsec * np, sizeof(double));
    w->wv = calloc((size_t)o->nsec * np, sizeof(double));
    if (!w->wu || !w->wv) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (ring limit)");
    for (int32_t s = 0; s < o->nsec; s++) {
        /* the sector's points in ring order of its polygon: V, E_a, F_a, E_a+1, ..., E_b */
        int32_t idx[MAXP], m = 0, a = o->sec_face0[s], nfs = o->sec_nface[s];
        int full = nfs == n && !g->boundary;
        idx[m++] = 0;
        for (int32_t j = 0; j < nfs; j++) {
            idx[m++] = 1 + (a + j) % n;
            idx[m++] = 1 + n + (a + j) % n;
        }
        if (!full) idx[m++] = 1 + (a + nfs) % n;
        double t1[MAXP], t2[MAXP], r1[MAXP], r2[MAXP];
        if (block_eig(w, S, np, idx, m) || tangents(w, m, t1, t2, r1, r2))
            return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "ring limit: no tangent plane");
        /* orientation: the sector polygon (points 1..m-1 and V for a partial sector) must be
         * counter-clockwise in the characteristic map (r1, r2) */
        double area = 0;
        int32_t first = full ? 1 : 0;
        for (int32_t i = first; i < m; i++) {
            int32_t j = i + 1 < m ? i + 1 : first;
            area += r1[i] * r2[j] - r1[j] * r2[i];
        }
        /* and the duality of the left to the right eigenvectors: with P ~ V + r1 A + r2 B
         * near V, (t1.P, t2.P) = G (A, B), G = [t_i . r_j]; complex pairs have det G > 0 */
        double g11 = 0, g12 = 0, g21 = 0, g22 = 0;
        for (int32_t i = 0; i < m; i++) {
            g11 += t1[i] * r1[i]; g12 += t1[i] * r2[i]; g21 += t2[i] * r1[i]; g22 += t2[i] * r2[i];
        }
        double nt1 = 0, nt2 = 0, nr1 = 0, nr2 = 0;
        for (int32_t i = 0; i < m; i++) {
            nt1 += t1[i] * t1[i]; nt2 += t2[i] * t2[i]; nr1 += r1[i] * r1[i]; nr2 += r2[i] * r2[i];
        }
        double det = g11 * g22 - g12 * g21, scale = sqrt(nt1 * nt2 * nr1 * nr2);
        double sg = (area < 0) != (det < 0) ? -1.0 : 1.0;
        if (!(fabs(det) > 1e-6 * scale) || !(fabs(area) > 1e-9 * sqrt(nr1 * nr2))) {
            /* a defective eigenvalue (e.g. the one-face crease sector, where the face's 1/4
             * meets the crease curve's 1/4: the tangent is the curve's second difference, as
             * in OpenSubdiv, and has no dual right eigenvector): orient on a canonical planar
             * sector instead, V at 0 and the spokes ccw, pi/2 per face up to two faces, pi/k
             * for k > 2 (a half plane), 2 pi / n around a full ring */
            double step = full ? 2 * 3.141592653589793 / n : nfs <= 2 ? 3.141592653589793 / 2 : 3.141592653589793 / nfs;
            double a1[2] = {0, 0}, a2[2] = {0, 0};
            for (int32_t i = 1; i < m; i++) {
                int32_t j = (i - 1) / 2;             /* E_a+j (odd i) or F_a+j (even i) */
                double ang = (i & 1) ? j * step : (j + 0.5) * step, rad = (i & 1) ? 1.0 : 1.5;
                double x = rad * cos(ang), y = rad * sin(ang);
                a1[0] += t1[i] * x; a1[1] += t1[i] * y;
                a2[0] += t2[i] * x; a2[1] += t2[i] * y;
            }
            sg = a1[0] * a2[1] - a1[1] * a2[0] < 0 ? -1.0 : 1.0;
        }
        for (int32_t i = 0; i < m; i++) {
            w->wu[(size_t)s * np + idx[i]] = t1[i];
            w->wv[(size_t)s * np + idx[i]] = sg * t2[i];
        }
    }
    return CCN_OK;
}

static ccn_status solve(ccn__ring_work *w, ring_cfg g, ccn__ring_limit *o, ccn_error *err) {
    int32_t n = g.n, np = 1 + n + nfaces(&g);
    size_t p2 = (size_t)np * np;
    int composed = 0;
    ccn_status st;
    for (int lvl = 0; lvl < MAX_DECAY && !stationary(&g); lvl++) { /* T = S_d ... S_1 */
        if ((st = ring_matrix(&g, w->S, err))) return st;
        if (!composed) memcpy(w->T, w->S, sizeof(double) * p2);
        else {
            for (int32_t i = 0; i < np; i++)
                for (int32_t j = 0; j < np; j++) {
                    double acc = 0;
                    for (int32_t k = 0; k < np; k++) acc += w->S[(size_t)i * np + k] * w->T[(size_t)k * np + j];
                    w->U[(size_t)i * np + j] = acc;
                }
            memcpy(w->T, w->U, sizeof(double) * p2);
        }
        composed = 1;
        decay(&g);
    }
    if ((st = ring_matrix(&g, w->S, err))) return st;
    if ((st = solve_stationary(w, &g, w->S, o, err))) return st;
    if (composed) { /* stencils over the later 1-ring -> over this one */
        double tmp[MAXP];
        for (int32_t s = -1; s < o->nsec; s++)
            for (int q = 0; q < (s < 0 ? 1 : 2); q++) {
                double *x = s < 0 ? o->wp : (q ? w->wv : w->wu) + (size_t)s * np;
                for (int32_t j = 0; j < np; j++) {
                    double acc = 0;
                    for (int32_t k = 0; k < np; k++) acc += x[k] * w->T[(size_t)k * np + j];
                    tmp[j] = acc;
                }
                memcpy(x, tmp, sizeof(double) * (size_t)np);
            }
    }
    return CCN_OK;
}

static int32_t *slot_of(ccn__ring_work *w, uint64_t h, const ring_cfg *g) {
    for (int32_t i = (int32_t)(h & (uint64_t)(w->nslot - 1));; i = (i + 1) & (w->nslot - 1)) {
        int32_t c = w->slot[i];
        if (c < 0 || (w->cache[c].hash == h && cfg_equal(&w->cache[c].cfg, g))) return &w->slot[i];
    }
}

static int rehash(ccn__ring_work *w) {
    int32_t ns = w->nslot ? 2 * w->nslot : 64;
    int32_t *sl = malloc(sizeof(int32_t) * (size_t)ns);
    if (!sl) return -1;
    free(w->slot);
    w->slot = sl;
    w->nslot = ns;
    for (int32_t i = 0; i < ns; i++) sl[i] = -1;
    for (int32_t c = 0; c < w->ncache; c++) *slot_of(w, w->cache[c].hash, &w->cache[c].cfg) = c;
    return 0;
}

static ccn_status cache_put(ccn__ring_work *w, const ring_cfg *g, uint64_t h, const ccn__ring_limit *o) {
    if (2 * (w->ncache + 1) > w->nslot && rehash(w)) return CCN_ERR_MEMORY;
    if (w->ncache == w->capcache) {
        int32_t nc = w->capcache ? 2 * w->capcache : 16;
        cache_entry *c = realloc(w->cache, sizeof *c * (size_t)nc);
        if (!c) return CCN_ERR_MEMORY;
        w->cache = c;
        w->capcache = nc;
    }
    cache_entry *e = &w->cache[w->ncache];
    size_t np = (size_t)o->npts, ns = (size_t)o->nsec;
    e->wp = malloc(sizeof(double) * np);
    e->wu = malloc(sizeof(double) * np * ns);
    e->wv = malloc(sizeof(double) * np * ns);
    if (!e->wp || !e->wu || !e->wv) { free(e->wp); free(e->wu); free(e->wv); return CCN_ERR_MEMORY; }
    e->hash = h; e->cfg = *g; e->nsec = o->nsec; e->npts = o->npts;
    memcpy(e->sec_face0, o->sec_face0, sizeof(int32_t) * ns);
    memcpy(e->sec_nface, o->sec_nface, sizeof(int32_t) * ns);
    memcpy(e->wp, o->wp, sizeof(double) * np);
    memcpy(e->wu, w->wu, sizeof(double) * np * ns);
    memcpy(e->wv, w->wv, sizeof(double) * np * ns);
    *slot_of(w, h, g) = w->ncache;
    w->ncache++;
    return CCN_OK;
}

ccn_status ccn__ring_limit_eval(const ccn_mesh *m, int32_t v, int scheme, int pinned,
                                int crease_method, ccn__ring_work *w, ccn__ring_limit *out,
                                ccn_error *err) {
    return ccn__ring_limit_eval_vs(m, v, scheme, pinned, crease_method, -1.0f, w, out, err);
}

ccn_status ccn__ring_limit_eval_vs(const ccn_mesh *m, int32_t v, int scheme, int pinned,
                                   int crease_method, float child_vs, ccn__ring_work *w,
                                   ccn__ring_limit *out, ccn_error *err) {
    int32_t n = ccn__valence(m, v);
    if (n > MAXV || n < 2 || m->vfan_start[v + 1] == m->vfan_start[v])
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VERTEX, v,
                         "vertex %d has valence %d; the ring limit supports 2..%d", (int)v, (int)n, MAXV);
    ring_cfg g;
    memset(&g, 0, sizeof g);
    g.n = n; g.boundary = m->vboundary[v]; g.pinned = pinned; g.scheme = scheme; g.method = crease_method;
    double dmax = 0;
    for (int32_t k = 0; k < n; k++) {
        int32_t e = ccn__fan_edge(m, v, k);
        g.d[k] = m->eknot[e];
        dmax = fmax(dmax, g.d[k]);
        int bnd = g.boundary && (k == 0 || k == n - 1);
        g.c[k] = bnd ? 0.0f : ccn__child_edge_sharpness(m, crease_method, e, v);
    }
    for (int32_t k = 0; k < n; k++) g.d[k] /= dmax;
    g.vs = child_vs >= 0.0f ? child_vs : ccn__sharp_decrement(m->vsharp ? m->vsharp[v] : 0.0f);
    /* the child 1-ring in level-(l+1) numbering */
    int32_t nf = g.boundary ? n - 1 : n;
    out->npts = 1 + n + nf;
    out->pts[0] = m->nf + m->ne + v;
    for (int32_t k = 0; k < n; k++) out->pts[1 + k] = m->nf + ccn__fan_edge(m, v, k);
    for (int32_t k = 0; k < nf; k++) out->pts[1 + n + k] = m->hface[m->vfan[m->vfan_start[v] + k]];
    uint64_t h = cfg_hash(&g);
    int32_t hit = w->nslot ? *slot_of(w, h, &g) : -1;
    if (hit >= 0) {
        const cache_entry *e = &w->cache[hit];
        size_t np = (size_t)e->npts, ns = (size_t)e->nsec;
        out->nsec = e->nsec;
        memcpy(out->sec_face0, e->sec_face0, sizeof(int32_t) * ns);
        memcpy(out->sec_nface, e->sec_nface, sizeof(int32_t) * ns);
        memcpy(out->wp, e->wp, sizeof(double) * np);
        out->wu = e->wu;
        out->wv = e->wv;
        return CCN_OK;
    }
    ccn_status st = solve(w, g, out, err);
    if (st) return st;
    if (cache_put(w, &g, h, out) == CCN_OK) {
        out->wu = w->cache[w->ncache - 1].wu;
        out->wv = w->cache[w->ncache - 1].wv;
    } else {
        out->wu = w->wu;
        out->wv = w->wv;
    }
    return CCN_OK;
}
