/* Knot intervals belong to edge rings (DESIGN §4.1, Li 2016 §2: opposite edges of every
 * quad carry the same interval). A ring is a class of edges linked through opposite edges
 * of quads; non-quad faces do not link their edges.
 *
 * Resolution: the ring's interval is the mean of the positive finite values given on its
 * edges (1 if none); a ring whose given values differ is counted as a conflict. Intervals
 * are then normalised by the smallest power of two at least the largest (so the largest is in
 * (1/2, 1]; the scale is kept in knot_scale) and clamped to >= CCN_KNOT_MIN_RATIO times the
 * largest (DESIGN §4.5), so every rule's denominators stay positive. A power of two because
 * dividing by it is exact: every rule is homogeneous in the intervals (ratios; an interval
 * weight scales with them), so two cages whose intervals differ by a factor give the same
 * weights to the bit, and a plan made after an edit that moves the largest interval can keep
 * the earlier plan's weights, rescaled exactly (ccn_plan_create with options.previous).
 */
#include "topology/knots.h"

#include "base/error.h"
#include "base/union_find.h"

#include <math.h>
#include <string.h>

static void link_quads(const ccn_mesh *m, int32_t *parent) {
    for (int32_t e = 0; e < m->ne; e++) parent[e] = e;
    for (int32_t f = 0; f < m->nf; f++) {
        if (ccn__fsize(m, f) != 4) continue;
        const int32_t *he = m->hedge + m->fstart[f];
        ccn__uf_union(parent, he[0], he[2]);
        ccn__uf_union(parent, he[1], he[3]);
    }
}

static int is_set(double x) { return isfinite(x) && x > 0.0; }

typedef struct { int32_t ring, source; double value; } tagged;

static int cmp_tagged(const void *x, const void *y) {
    const tagged *p = x, *q = y;
    if (p->ring != q->ring) return p->ring < q->ring ? -1 : 1;
    return (p->source > q->source) - (p->source < q->source);
}

/* Mean over distinct (ring, source) pairs; conflicts counted per ring. */
static void ring_means(const ccn_mesh *m, const int32_t *parent, const double *val,
                       const int32_t *source, double *sum, int32_t *cnt, double *lo, double *hi,
                       tagged *tags) {
    int32_t nt = 0;
    for (int32_t e = 0; e < m->ne; e++) {
        if (!is_set(val[e])) continue;
        tags[nt].ring = parent[e];
        tags[nt].source = source ? source[e] : e;
        tags[nt].value = val[e];
        nt++;
    }
    if (source) qsort(tags, (size_t)nt, sizeof *tags, cmp_tagged);
    for (int32_t i = 0; i < nt; i++) {
        if (source && i > 0 && tags[i].ring == tags[i - 1].ring &&
            tags[i].source == tags[i - 1].source)
            continue;
        int32_t r = tags[i].ring;
        double x = tags[i].value;
        sum[r] += x;
        cnt[r]++;
        if (x < lo[r]) lo[r] = x;
        if (x > hi[r]) hi[r] = x;
    }
}

uint8_t *ccn__changed_interval_ends(const ccn_mesh *m, const ccn_mesh *q) {
    if (!q || q->ne != m->ne || q->nv != m->nv) return NULL;
    uint8_t *ends = calloc((size_t)(m->nv ? m->nv : 1), 1);
    for (int32_t e = 0; ends && e < m->ne; e++)
        if (m->eknot[e] * m->knot_scale != q->eknot[e] * q->knot_scale)
            ends[m->everts[2 * e]] = ends[m->everts[2 * e + 1]] = 1;
    return ends;
}

ccn_status ccn__resolve_rings(ccn_mesh *m, const double *val, const int32_t *source,
                              ccn_error *err) {
    size_t ne = (size_t)(m->ne ? m->ne : 1);
    int32_t *parent = malloc(sizeof(int32_t) * ne);
    int32_t *cnt = calloc(ne, sizeof(int32_t));
    double *sum = calloc(ne, sizeof(double));
    double *lo = malloc(sizeof(double) * ne), *hi = malloc(sizeof(double) * ne);
    tagged *tags = malloc(sizeof(tagged) * ne);
    ccn_status st = CCN_OK;
    if (!parent || !cnt || !sum || !lo || !hi || !tags) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (knot rings)");
        goto done;
    }
    link_quads(m, parent);
    for (int32_t e = 0; e < m->ne; e++) {
        parent[e] = ccn__uf_find(parent, e);
        lo[e] = INFINITY;
        hi[e] = -INFINITY;
    }
    ring_means(m, parent, val, source, sum, cnt, lo, hi, tags);
    int32_t rings = 0, conflicts = 0;
    double vmax = 0.0;
    for (int32_t e = 0; e < m->ne; e++) {
        if (parent[e] != e) continue;
        rings++;
        if (cnt[e] > 1 && hi[e] - lo[e] > 1e-12 * hi[e]) conflicts++;
        sum[e] = cnt[e] ? sum[e] / cnt[e] : 1.0;
        if (!(sum[e] <= 1e300)) sum[e] = 1e300; /* overflow of the mean */
        if (sum[e] > vmax) vmax = sum[e];
    }
    m->knot_scale = ccn__pow2_at_least(vmax > 0.0 ? vmax : 1.0);
    double lo_knot = CCN_KNOT_MIN_RATIO * ((vmax > 0.0 ? vmax : 1.0) / m->knot_scale);
    for (int32_t e = 0; e < m->ne; e++) {
        double x = sum[parent[e]] / m->knot_scale;
        m->eknot[e] = x < lo_knot ? lo_knot : x;
    }
    m->info.num_rings = rings;
    m->info.num_ring_conflicts = conflicts;
done:
    free(parent); free(cnt); free(sum); free(lo); free(hi); free(tags);
    return st;
}
