/* The per-vertex choice of the eigen polyhedron and the public ccn_ev_matrix entry points
 * (rules/eigen_select.h). */
#include "rules/eigen_select.h"

#include "rules/eigen.h"
#include "rules/eigen_fan.h"
#include "rules/eigen_shape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the cache: canonical interval tuple -> choice ---------------------------------------- */

typedef struct {
    int32_t n;
    size_t off;   /* into pool */
    ccn__ev_choice choice;
} cache_entry;

struct ccn__ev_cache {
    cache_entry *e;
    size_t count, cap;
    int64_t *table; /* open addressing: entry index or -1; tsize a power of two */
    size_t tsize;
    double *pool;
    size_t used, pool_cap;
};

ccn__ev_cache *ccn__ev_cache_create(void) { return calloc(1, sizeof(ccn__ev_cache)); }

size_t ccn__ev_cache_count(const ccn__ev_cache *c) { return c ? c->count : 0; }

void ccn__ev_cache_destroy(ccn__ev_cache *c) {
    if (!c) return;
    free(c->e); free(c->table); free(c->pool);
    free(c);
}

static uint64_t tuple_hash(int32_t n, const double *d) {
    uint64_t h = 1469598103934665603ull ^ (uint64_t)n;
    for (int32_t i = 0; i < n; i++) {
        uint64_t b;
        memcpy(&b, &d[i], sizeof b);
        h = (h ^ b) * 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

static int same_tuple(const ccn__ev_cache *c, const cache_entry *e, int32_t n, const double *d) {
    return e->n == n && memcmp(c->pool + e->off, d, sizeof(double) * (size_t)n) == 0;
}

static const ccn__ev_choice *cache_find(const ccn__ev_cache *c, int32_t n, const double *d) {
    if (!c || !c->tsize) return NULL;
    for (size_t k = tuple_hash(n, d) & (c->tsize - 1);; k = (k + 1) & (c->tsize - 1)) {
        int64_t i = c->table[k];
        if (i < 0) return NULL;
        if (same_tuple(c, &c->e[i], n, d)) return &c->e[i].choice;
    }
}

static int cache_rehash(ccn__ev_cache *c, size_t tsize) {
    int64_t *t = malloc(sizeof(int64_t) * tsize);
    if (!t) return -1;
    for (size_t k = 0; k < tsize; k++) t[k] = -1;
    for (size_t i = 0; i < c->count; i++) {
        size_t k = tuple_hash(c->e[i].n, c->pool + c->e[i].off) & (tsize - 1);
        while (t[k] >= 0) k = (k + 1) & (tsize - 1);
        t[k] = (int64_t)i;
    }
    free(c->table);
    c->table = t;
    c->tsize = tsize;
    return 0;
}

static int cache_add(ccn__ev_cache *c, int32_t n, const double *d, const ccn__ev_choice *ch) {
    if (c->count == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 16;
        cache_entry *e = realloc(c->e, sizeof *e * cap);
        if (!e) return -1;
        c->e = e, c->cap = cap;
    }
    if (c->used + (size_t)n > c->pool_cap) {
        size_t cap = 2 * (c->pool_cap + (size_t)n) + 64;
        double *p = realloc(c->pool, sizeof(double) * cap);
        if (!p) return -1;
        c->pool = p, c->pool_cap = cap;
    }
    memcpy(c->pool + c->used, d, sizeof(double) * (size_t)n);
    c->e[c->count] = (cache_entry){n, c->used, *ch};
    c->used += (size_t)n;
    c->count++;
    if (2 * c->count > c->tsize) return cache_rehash(c, c->tsize ? 2 * c->tsize : 64);
    size_t k = tuple_hash(n, d) & (c->tsize - 1);
    while (c->table[k] >= 0) k = (k + 1) & (c->tsize - 1);
    c->table[k] = (int64_t)(c->count - 1);
    return 0;
}

/* The lexicographically smallest rotation or reflection of d (the choice is invariant under
 * both: every candidate and both checks are). */
static void canonical(int32_t n, const double *d, double *out) {
    for (int32_t i = 0; i < n; i++) out[i] = d[i];
    for (int refl = 0; refl < 2; refl++)
        for (int32_t r = 0; r < n; r++) {
            int smaller = 0;
            for (int32_t i = 0; i < n; i++) {
                double x = d[refl ? (r - i + 2 * n) % n : (r + i) % n];
                if (x != out[i]) { smaller = x < out[i]; break; }
            }
            if (!smaller) continue;
            for (int32_t i = 0; i < n; i++) out[i] = d[refl ? (r - i + 2 * n) % n : (r + i) % n];
        }
}

/* ---- verification and choice --------------------------------------------------------------- */

static double smoothstep01(double x) {
    if (!(x > 0)) return 0.0;
    if (x >= 1) return 1.0;
    return x * x * (3 - 2 * x);
}

double ccn__ev_margin(int32_t n, const double *nd, int32_t poly, double *construction) {
    size_t sz = 2 * (size_t)n + 1;
    double *M = malloc(sizeof(double) * (sz * sz + 2 * sz));
    if (!M) return NAN;
    double *P = M + sz * sz, q;
    ccn_ev_info info;
    ccn__poly_blend one = {1, {poly}, {1.0}};
    if (ccn__ev_matrix_blend(n, nd, CCN_SCHEME_EIGEN, &one, M, &info, P, &q, NULL) != CCN_OK) q = -1;
    if (construction) *construction = q;
    if (q > 0) {
        double qm;
        int32_t maxima;
        if (ccn__fan_maxima_margin(n, nd, M, CCN__EV_SELECT_LEVELS, &qm, &maxima)) q = NAN;
        else q = fmin(q, qm / CCN__EV_MAXIMA_BAND);
    }
    if (q > 0) {
        ccn__charmap_margin cm;
        if (ccn__fan_charmap_margin(n, nd, M, P, info.T0, info.lambda, &cm)) q = NAN;
        else {
            q = fmin(q, fmin(cm.spectrum / CCN__EV_SPECTRUM_BAND, cm.regular / CCN__EV_REGULAR_BAND));
            if (!cm.injective) q = fmin(q, -1.0);
        }
    }
    free(M);
    return q;
}

int ccn__ev_verify(int32_t n, const double *nd, int32_t poly) {
    double q = ccn__ev_margin(n, nd, poly, NULL);
    return isnan(q) ? -1 : q > 0;
}

/* Weight of the paper's polyhedron accepted without checks: 1 up to a spoke ratio of
 * CCN__EV_TRUST_RATIO, 0 from CCN__EV_VERIFY_RATIO, smooth in log(ratio) between. */
static double trust_weight(double ratio) {
    return smoothstep01(log(CCN__EV_VERIFY_RATIO / ratio) / log(CCN__EV_VERIFY_RATIO / CCN__EV_TRUST_RATIO));
}

static void blend_add(ccn__poly_blend *b, int32_t poly, double w) {
    for (int32_t c = 0; c < b->count; c++)
        if (b->poly[c] == poly) { b->w[c] += w; return; }
    b->poly[b->count] = poly;
    b->w[b->count++] = w;
}

ccn_status ccn__ev_select(int32_t n, const double *nd, ccn__ev_cache *cache, ccn__ev_choice *out) {
    double mn = nd[0], mx = nd[0];
    for (int32_t i = 1; i < n; i++) mn = fmin(mn, nd[i]), mx = fmax(mx, nd[i]);
    memset(out, 0, sizeof *out);
    out->poly = CCN__POLY_PAPER;
    out->blend = (ccn__poly_blend){1, {CCN__POLY_PAPER}, {1.0}};
    double trust = trust_weight(mx / mn);
    if (n == 4 || n > CCN__EV_SELECT_MAX_VALENCE || trust >= 1) return CCN_OK;
    double key[CCN__EV_SELECT_MAX_VALENCE];
    canonical(n, nd, key);
    const ccn__ev_choice *hit = cache_find(cache, n, key);
    if (hit) {
        *out = *hit;
        out->cached = 1;
        return CCN_OK;
    }
    /* "The first candidate that passes", made continuous: candidate k takes the weight
     * s_k prod_{j<k} (1 - s_j), s = smoothstep of its margin (1 when it passes clearly, 0 when
     * it fails), the paper's s at least the trust weight. Every margin is continuous in the
     * intervals, so the weights are. */
    ccn__poly_blend b = {0, {0}, {0}};
    double rest = 1.0, built[CCN__POLY_COUNT + 1];
    for (int32_t poly = 1; poly <= CCN__POLY_COUNT && rest > 0; poly++) {
        double q = ccn__ev_margin(n, key, poly, &built[poly]);
        if (isnan(q)) return CCN_ERR_MEMORY;
        out->verified++;
        double sk = smoothstep01(q);
        if (poly == CCN__POLY_PAPER) sk = fmax(sk, trust);
        if (rest * sk > 0) blend_add(&b, poly, rest * sk);
        rest *= 1 - sk;
    }
    out->outside = rest >= 0.5;
    /* What no candidate takes goes down the same chain again by the constructions' margins
     * alone (s = smoothstep of the construction's margin: the candidates' eigen rules exist
     * there, unverified), and only what no construction takes to the paper's polyhedron, whose
     * failing construction falls back to the NURSS rules. The construction margin is continuous
     * where it is positive, and a margin is read only through smoothstep's positive part (a
     * failed check sets a margin to -1 at once: no weight may come from how badly a candidate
     * fails). At spoke ratios of several hundred the last verified candidate and the NURSS
     * rules are a fifth of the cage apart; the unverified eigen rules are close to the first
     * (tests/experiments/RESULTS.md, "What no candidate takes"). */
    for (int32_t poly = 1; poly <= CCN__POLY_COUNT && rest > 0; poly++) {
        double sk = smoothstep01(built[poly]);
        if (rest * sk > 0) blend_add(&b, poly, rest * sk);
        rest *= 1 - sk;
    }
    if (rest > 0) blend_add(&b, CCN__POLY_PAPER, rest);
    out->blend = b;
    int32_t best = 0;
    for (int32_t c = 1; c < b.count; c++)
        if (b.w[c] > b.w[best]) best = c;
    out->poly = b.poly[best];
    if (cache && cache_add(cache, n, key, out)) return CCN_ERR_MEMORY;
    return CCN_OK;
}

/* ---- entry points ---------------------------------------------------------------------------- */

ccn_status ccn__ev_matrix_cached(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                 int32_t polyhedron, ccn__ev_cache *cache, double *M,
                                 ccn_ev_info *info, ccn_error *err) {
    ccn_ev_info local;
    if (!info) info = &local;
    if (polyhedron < CCN_POLY_SELECT || polyhedron > CCN_POLY_COUNT) {
        memset(info, 0, sizeof *info);
        if (err) {
            err->status = CCN_ERR_ARGUMENT;
            err->element_kind = CCN_ELEM_NONE;
            err->element = -1;
            snprintf(err->message, sizeof err->message, "ev matrix: polyhedron %d outside [0, %d]",
                     (int)polyhedron, CCN_POLY_COUNT);
        }
        return CCN_ERR_ARGUMENT;
    }
    ccn__ev_choice ch;
    memset(&ch, 0, sizeof ch);
    ch.poly = polyhedron ? polyhedron : CCN__POLY_PAPER;
    ch.blend = (ccn__poly_blend){1, {ch.poly}, {1.0}};
    if (scheme == CCN_SCHEME_EIGEN && polyhedron == CCN_POLY_SELECT &&
        ccn__ev_validate(n, spoke_knots, scheme, M, err) == CCN_OK && n <= CCN__EV_SELECT_MAX_VALENCE) {
        double nd[CCN__EV_SELECT_MAX_VALENCE];
        ccn__ev_normalise(n, spoke_knots, nd);
        if (ccn__ev_select(n, nd, cache, &ch)) {
            memset(info, 0, sizeof *info);
            if (err) {
                err->status = CCN_ERR_MEMORY;
                err->element_kind = CCN_ELEM_NONE;
                err->element = -1;
                snprintf(err->message, sizeof err->message, "ev matrix: out of memory (verification)");
            }
            return CCN_ERR_MEMORY;
        }
    }
    ccn_status st = ccn__ev_matrix_blend(n, spoke_knots, scheme, &ch.blend, M, info, NULL, NULL, err);
    if (st == CCN_OK && scheme == CCN_SCHEME_EIGEN) {
        info->verified = ch.verified;
        info->outside_g1 = ch.outside;
    }
    return st;
}

ccn_status ccn_ev_matrix_polyhedron(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                    int32_t polyhedron, double *M, ccn_ev_info *info,
                                    ccn_error *err) {
    return ccn__ev_matrix_cached(n, spoke_knots, scheme, polyhedron, NULL, M, info, err);
}

ccn_status ccn_ev_matrix(int32_t n, const double *spoke_knots, ccn_scheme scheme, double *M,
                         ccn_ev_info *info, ccn_error *err) {
    return ccn__ev_matrix_cached(n, spoke_knots, scheme, CCN_POLY_SELECT, NULL, M, info, err);
}
