/* The neutral B-rep of the CAD writers (cad.h): validation, vertices and shared edges, iso
 * curves of face sides, and the buffered number-exact output both writers use. */
#include "io/cad.h"

#include "base/error.h"
#include "base/vec3.h"
#include "rules/bspline.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- output ------------------------------------------------------------------------ */

void ccn__cad_out_init(ccn__cad_out *o, ccn__cad_write_fn fn, void *user) {
    o->fn = fn;
    o->user = user;
    o->len = 0;
    o->failed = 0;
}

static void out_drain(ccn__cad_out *o) {
    if (o->len && !o->failed && o->fn(o->user, o->buf, o->len) != 0) o->failed = 1;
    o->len = 0;
}

static void out_write(ccn__cad_out *o, const char *s, size_t n) {
    while (n && !o->failed) {
        size_t room = sizeof o->buf - o->len, k = n < room ? n : room;
        memcpy(o->buf + o->len, s, k);
        o->len += k;
        s += k;
        n -= k;
        if (o->len == sizeof o->buf) out_drain(o);
    }
}

void ccn__cad_write(ccn__cad_out *o, const char *s, size_t n) { out_write(o, s, n); }
void ccn__cad_puts(ccn__cad_out *o, const char *s) { out_write(o, s, strlen(s)); }

void ccn__cad_printf(ccn__cad_out *o, const char *fmt, ...) {
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof tmp) { o->failed = 1; return; } /* formats are short */
    out_write(o, tmp, (size_t)n);
}

int ccn__cad_flush(ccn__cad_out *o) {
    out_drain(o);
    return o->failed;
}

const char *ccn__cad_real(double x, char *buf) {
    char tmp[40];
    if (x == 0) x = 0; /* -0 -> 0: one spelling */
    /* The shortest of 15, 16 and 17 significant digits that reads back as x: every double is
     * written exactly (17 always suffice), and more than half of them need fewer. A decimal with fewer than 15 digits that reads back as a
     * normal x is what %.15g prints, its trailing zeros removed (a subnormal's spacing is
     * coarser: there every length is tried). */
    for (int digits = fabs(x) < DBL_MIN ? 1 : 15; digits <= 17; digits++) {
        snprintf(tmp, sizeof tmp, "%.*g", digits, x);
        if (digits == 17 || strtod(tmp, NULL) == x) break;
    }
    size_t j = 0;
    int dot = strchr(tmp, '.') != NULL;
    for (size_t i = 0; tmp[i]; i++) {
        if (tmp[i] == 'e') {
            if (!dot) { buf[j++] = '.'; dot = 1; }
            buf[j++] = 'E';
        } else {
            buf[j++] = tmp[i];
        }
    }
    if (!dot) buf[j++] = '.';
    buf[j] = '\0';
    return buf;
}

/* ---- B-spline helpers -------------------------------------------------------------- */

/* Flat knot i (0-based) of direction dir. */
static double flat_knot(const ccn__cad_surface *f, int dir, int32_t i) {
    for (int32_t k = 0; k < f->num_knots[dir]; k++) {
        if (i < f->mults[dir][k]) return f->knots[dir][k];
        i -= f->mults[dir][k];
    }
    return f->knots[dir][f->num_knots[dir] - 1];
}

void ccn__cad_segment_ends_uv(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j, int along,
                              double a[2], double b[2]) {
    const ccn__cad_surface *f = &m->faces[t->seg_face[j]];
    int s = t->seg_side[j], dir = s % 2 ? 1 : 0;
    double lo, hi;
    ccn__cad_domain(f, 1 - dir, &lo, &hi);
    double x0 = s < 2 ? t->seg_lo[j] : t->seg_hi[j], x1 = s < 2 ? t->seg_hi[j] : t->seg_lo[j]; /* loop order */
    if (along && !t->seg_sense[j]) { double x = x0; x0 = x1; x1 = x; }
    a[dir] = x0, b[dir] = x1;
    a[1 - dir] = b[1 - dir] = s == 1 || s == 2 ? hi : lo;
}

void ccn__cad_domain(const ccn__cad_surface *f, int dir, double *lo, double *hi) {
    *lo = flat_knot(f, dir, f->degree[dir]);
    *hi = flat_knot(f, dir, f->num_poles[dir]);
}

/* The span of t -- the largest flat index s in [p, n - 1] with t_s <= t, p when there is none
 * -- and its 2p flat knots t_{s-p+1} .. t_{s+p} into U, in two walks over the distinct knots
 * (flat_knot per index would cost the knot count each: packed faces have hundreds). */
static int32_t span_knots(const ccn__cad_surface *f, int dir, double t, double *U) {
    int32_t p = f->degree[dir], n = f->num_poles[dir], nk = f->num_knots[dir], last = -1;
    const double *kv = f->knots[dir];
    const int32_t *mu = f->mults[dir];
    for (int32_t k = 0; k < nk && kv[k] <= t; k++) last += mu[k];
    int32_t span = last < n - 1 ? last : n - 1;
    if (span < p) span = p;
    int32_t i = span - p + 1, k = 0, before = 0; /* flat index i lies in distinct knot k */
    while (k + 1 < nk && i >= before + mu[k]) before += mu[k++];
    for (int32_t q = 0; q < 2 * p; q++, i++) {
        while (k + 1 < nk && i >= before + mu[k]) before += mu[k++];
        U[q] = kv[k];
    }
    return span;
}

/* Nonzero basis functions N[span-p .. span] at t (span: t[span] <= t < t[span+1], the last
 * non-empty span inside the domain at its upper end). Returns span. */
static int32_t basis(const ccn__cad_surface *f, int dir, double t, double *N) {
    double U[2 * CCN_CAD_MAX_DEGREE];
    int32_t span = span_knots(f, dir, t, U);
    ccn__bspline_basis(f->degree[dir], U, t, N);
    return span;
}

void ccn__cad_eval(const ccn__cad_surface *f, double u, double v, double out[3]) {
    double Nu[CCN_CAD_MAX_DEGREE + 1], Nv[CCN_CAD_MAX_DEGREE + 1];
    int32_t su = basis(f, 0, u, Nu), sv = basis(f, 1, v, Nv), nv = f->num_poles[1];
    out[0] = out[1] = out[2] = 0;
    for (int32_t a = 0; a <= f->degree[0]; a++)
        for (int32_t b = 0; b <= f->degree[1]; b++) {
            const double *P = f->poles + 3 * ((size_t)(su - f->degree[0] + a) * nv + sv - f->degree[1] + b);
            for (int k = 0; k < 3; k++) out[k] += Nu[a] * Nv[b] * P[k];
        }
}

/* basis() with first derivatives dN (Piegl & Tiller A2.3, first order). */
static int32_t basis_d(const ccn__cad_surface *f, int dir, double t, double *N, double *dN) {
    int32_t p = f->degree[dir];
    double U[2 * CCN_CAD_MAX_DEGREE];
    int32_t span = span_knots(f, dir, t, U);
    double left[CCN_CAD_MAX_DEGREE + 1], right[CCN_CAD_MAX_DEGREE + 1];
    double ndu[CCN_CAD_MAX_DEGREE + 1][CCN_CAD_MAX_DEGREE + 1]; /* ndu[j][r]: basis, ndu[r][j]: knot differences */
    ndu[0][0] = 1;
    for (int32_t j = 1; j <= p; j++) {
        left[j] = t - U[p - j];      /* t_{span+1-j} */
        right[j] = U[p - 1 + j] - t; /* t_{span+j} */
        double saved = 0;
        for (int32_t r = 0; r < j; r++) {
            ndu[j][r] = right[r + 1] + left[j - r];
            double tmp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        ndu[j][j] = saved;
    }
    for (int32_t r = 0; r <= p; r++) {
        N[r] = ndu[r][p];
        double d = 0;
        if (p >= 1) {
            if (r >= 1) d += ndu[r - 1][p - 1] / ndu[p][r - 1];
            if (r <= p - 1) d -= ndu[r][p - 1] / ndu[p][r];
            d *= p;
        }
        dN[r] = d;
    }
    return span;
}

void ccn__cad_eval_d(const ccn__cad_surface *f, double u, double v, double pos[3], double du[3],
                     double dv[3]) {
    double Nu[CCN_CAD_MAX_DEGREE + 1], Nv[CCN_CAD_MAX_DEGREE + 1];
    double Du[CCN_CAD_MAX_DEGREE + 1], Dv[CCN_CAD_MAX_DEGREE + 1];
    int32_t su = basis_d(f, 0, u, Nu, Du), sv = basis_d(f, 1, v, Nv, Dv), nv = f->num_poles[1];
    for (int k = 0; k < 3; k++) pos[k] = du[k] = dv[k] = 0;
    for (int32_t a = 0; a <= f->degree[0]; a++)
        for (int32_t b = 0; b <= f->degree[1]; b++) {
            const double *P = f->poles + 3 * ((size_t)(su - f->degree[0] + a) * nv + sv - f->degree[1] + b);
            for (int k = 0; k < 3; k++) {
                pos[k] += Nu[a] * Nv[b] * P[k];
                du[k] += Du[a] * Nv[b] * P[k];
                dv[k] += Nu[a] * Dv[b] * P[k];
            }
        }
}

void ccn__cad_side_curve(const ccn__cad_surface *f, int s, double *out) {
    int dir = s % 2 == 0 ? 0 : 1, other = 1 - dir; /* the curve runs along dir */
    int at_hi = s == 1 || s == 2;                   /* side 1: u = u1, side 2: v = v1 */
    int32_t n = f->num_poles[dir], m = f->num_poles[other], p = f->degree[other];
    int32_t kend = at_hi ? f->num_knots[other] - 1 : 0;
    double N[CCN_CAD_MAX_DEGREE + 1];
    int32_t span = -1;
    int clamped = f->mults[other][kend] == p + 1;
    if (!clamped) {
        double lo, hi;
        ccn__cad_domain(f, other, &lo, &hi);
        span = basis(f, other, at_hi ? hi : lo, N);
    }
    for (int32_t i = 0; i < n; i++) {
        double *q = out + 3 * (size_t)i;
        if (clamped) { /* the boundary row itself: exact */
            int32_t j = at_hi ? m - 1 : 0;
            const double *P = f->poles + 3 * (dir == 0 ? (size_t)i * m + j : (size_t)j * n + i);
            memcpy(q, P, sizeof(double) * 3);
            continue;
        }
        q[0] = q[1] = q[2] = 0;
        for (int32_t b = 0; b <= p; b++) {
            int32_t j = span - p + b;
            const double *P = f->poles + 3 * (dir == 0 ? (size_t)i * m + j : (size_t)j * n + i);
            for (int k = 0; k < 3; k++) q[k] += N[b] * P[k];
        }
    }
}

/* ---- validation -------------------------------------------------------------------- */

static ccn_status check_direction(const ccn__cad_surface *f, int32_t fi, int dir, ccn_error *err) {
    const char *d = dir ? "v" : "u";
    int32_t p = f->degree[dir], n = f->num_poles[dir], nk = f->num_knots[dir];
    if (p < 1 || p > CCN_CAD_MAX_DEGREE)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                             "face %d: %s degree %d is not in [1, %d]", (int)fi, d, (int)p,
                             CCN_CAD_MAX_DEGREE);
    if (n < p + 1 || nk < 2 || !f->knots[dir] || !f->mults[dir])
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                             "face %d: %s needs >= %d poles and >= 2 knots (got %d, %d)",
                             (int)fi, d, (int)p + 1, (int)n, (int)nk);
    int64_t sum = 0;
    for (int32_t k = 0; k < nk; k++) {
        double t = f->knots[dir][k];
        int32_t mu = f->mults[dir][k];
        if (!isfinite(t) || (k && !(t > f->knots[dir][k - 1])))
            return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                 "face %d: %s knot %d (%g) is not finite and increasing",
                                 (int)fi, d, (int)k, t);
        int32_t maxm = k == 0 || k == nk - 1 ? p + 1 : p;
        if (mu < 1 || mu > maxm)
            return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                 "face %d: %s knot %d has multiplicity %d (allowed 1..%d)",
                                 (int)fi, d, (int)k, (int)mu, (int)maxm);
        sum += mu;
    }
    if (sum != (int64_t)n + p + 1)
        return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                             "face %d: %s multiplicities sum to %lld, expected %d poles + %d + 1",
                             (int)fi, d, (long long)sum, (int)n, (int)p);
    double lo, hi;
    ccn__cad_domain(f, dir, &lo, &hi);
    if (!(hi > lo))
        return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                             "face %d: empty %s domain [%g, %g]", (int)fi, d, lo, hi);
    if (f->periodic[dir]) { /* intervals repeat with the period; last p rows = first p */
        for (int32_t i = 0; i + 1 < 2 * p; i++) {
            double a = flat_knot(f, dir, i + 1) - flat_knot(f, dir, i);
            double b = flat_knot(f, dir, i + n - p + 1) - flat_knot(f, dir, i + n - p);
            if (fabs(a - b) > 1e-12 * (hi - lo))
                return ccn__fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                     "face %d: %s is marked periodic but its knot intervals "
                                     "do not repeat", (int)fi, d);
        }
        if (n < 2 * p)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                                 "face %d: periodic %s needs >= %d poles", (int)fi, d, (int)(2 * p));
    }
    return CCN_OK;
}

/* Point of side s at parameter t of the side's direction (u for sides 0, 2, v for 1, 3). */
static void side_point_at(const ccn__cad_surface *f, int s, double t, double out[3]) {
    double u0, u1, v0, v1;
    ccn__cad_domain(f, 0, &u0, &u1);
    ccn__cad_domain(f, 1, &v0, &v1);
    switch (s) {
    case 0: ccn__cad_eval(f, t, v0, out); break;
    case 1: ccn__cad_eval(f, u1, t, out); break;
    case 2: ccn__cad_eval(f, t, v1, out); break;
    default: ccn__cad_eval(f, u0, t, out); break;
    }
}

/* Point at fraction w of segment j in its loop running direction. */
static void seg_point(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j, double w,
                      double out[3]) {
    int s = t->seg_side[j];
    double lo = t->seg_lo[j], hi = t->seg_hi[j];
    side_point_at(&m->faces[t->seg_face[j]], s, s < 2 ? lo + w * (hi - lo) : hi - w * (hi - lo), out);
}

static int32_t uf_find(int32_t *parent, int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
}
static void uf_union(int32_t *parent, int32_t a, int32_t b) {
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a != b) { if (a < b) parent[b] = a; else parent[a] = b; } /* smallest root: stable */
}

void ccn__cad_topo_free(ccn__cad_topo *t) {
    free(t->face_seg); free(t->seg_face); free(t->seg_side); free(t->seg_lo); free(t->seg_hi);
    free(t->seg_vert); free(t->vert_pos); free(t->seg_edge); free(t->seg_sense);
    free(t->edge_seg); free(t->edge_vert); free(t->face_shell); free(t->shell_closed);
    free(t->shell_start); free(t->shell_face);
    memset(t, 0, sizeof *t);
}

static ccn_status check_faces(const ccn__cad_model *m, ccn__cad_topo *t, ccn_error *err) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t fi = 0; fi < m->num_faces; fi++) {
        const ccn__cad_surface *f = &m->faces[fi];
        for (int dir = 0; dir < 2; dir++) {
            ccn_status st = check_direction(f, fi, dir, err);
            if (st) return st;
        }
        if (!f->poles)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi, "face %d: poles is NULL", (int)fi);
        if ((int64_t)f->num_poles[0] * f->num_poles[1] > INT32_MAX / 3)
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_FACE, fi, "face %d: too many poles", (int)fi);
        size_t np = (size_t)f->num_poles[0] * (size_t)f->num_poles[1];
        for (size_t i = 0; i < 3 * np; i++) {
            double x = f->poles[i];
            if (!isfinite(x) || fabs(x) > 1e300)
                return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                                     "face %d: pole %zu has a non-finite or huge coordinate",
                                     (int)fi, i / 3);
            lo[i % 3] = x < lo[i % 3] ? x : lo[i % 3];
            hi[i % 3] = x > hi[i % 3] ? x : hi[i % 3];
        }
    }
    t->size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
    t->tolerance = m->tolerance > 0 ? m->tolerance : fmax(1e-7, 1e-10 * t->size);
    for (int32_t fi = 0; fi < m->num_faces; fi++) { /* periodic rows, after the size */
        const ccn__cad_surface *f = &m->faces[fi];
        int32_t nu = f->num_poles[0], nv = f->num_poles[1];
        for (int dir = 0; dir < 2; dir++) {
            if (!f->periodic[dir]) continue;
            int32_t n = f->num_poles[dir], p = f->degree[dir], other = f->num_poles[1 - dir];
            for (int32_t i = 0; i < p; i++)
                for (int32_t j = 0; j < other; j++) {
                    size_t a = dir == 0 ? (size_t)i * nv + j : (size_t)j * nv + i;
                    size_t b = dir == 0 ? (size_t)(i + n - p) * nv + j : (size_t)j * nv + i + n - p;
                    if (ccn__dist3(f->poles + 3 * a, f->poles + 3 * b) > t->tolerance)
                        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                                             "face %d: %s is marked periodic but pole row %d "
                                             "differs from row %d", (int)fi, dir ? "v" : "u",
                                             (int)(i + n - p), (int)i);
                }
        }
        (void)nu;
    }
    return CCN_OK;
}

/* Segments: where each side is split (validated) and its parameter range. */
static ccn_status build_segments(const ccn__cad_model *m, ccn__cad_topo *t, ccn_error *err) {
    int32_t nf = m->num_faces;
    const int32_t *bs = m->side_breaks_start;
    if ((bs == NULL) != (m->side_breaks == NULL))
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "side_breaks_start and side_breaks must both be given or both NULL");
    int64_t nb = bs ? bs[4 * nf] : 0;
    if (bs && bs[0] != 0)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "side_breaks_start[0] must be 0");
    for (int32_t a = 0; bs && a < 4 * nf; a++)
        if (bs[a + 1] < bs[a] || bs[a + 1] > INT32_MAX / 4 - 4 * (int64_t)nf)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, a / 4,
                                 "face %d side %d: side_breaks_start decreases or is too large",
                                 (int)(a / 4), (int)(a % 4));
    t->num_segs = (int32_t)(4 * (int64_t)nf + nb);
    size_t ns = (size_t)t->num_segs;
    t->face_seg = malloc(sizeof(int32_t) * ((size_t)nf + 1));
    t->seg_face = malloc(sizeof(int32_t) * ns);
    t->seg_side = malloc(ns);
    t->seg_lo = malloc(sizeof(double) * ns);
    t->seg_hi = malloc(sizeof(double) * ns);
    if (!t->face_seg || !t->seg_face || !t->seg_side || !t->seg_lo || !t->seg_hi)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    int32_t j = 0;
    for (int32_t f = 0; f < nf; f++) {
        t->face_seg[f] = j;
        for (int s = 0; s < 4; s++) {
            double lo, hi;
            ccn__cad_domain(&m->faces[f], s % 2, &lo, &hi);
            int32_t a = 4 * f + s, k0 = bs ? bs[a] : 0, k1 = bs ? bs[a + 1] : 0;
            /* running order: increasing parameter on sides 0, 1, decreasing on 2, 3 */
            double prev = s < 2 ? lo : hi;
            for (int32_t k = k0; k <= k1; k++, j++) {
                double next = k < k1 ? m->side_breaks[k] : (s < 2 ? hi : lo);
                int inside = s < 2 ? next > prev && next <= hi : next < prev && next >= lo;
                if (!isfinite(next) || !inside || (k < k1 && (next == lo || next == hi)))
                    return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, f,
                                         "face %d side %d: break %g is not strictly inside the side "
                                         "and after the previous one", (int)f, s, next);
                t->seg_face[j] = f;
                t->seg_side[j] = (uint8_t)s;
                t->seg_lo[j] = s < 2 ? prev : next;
                t->seg_hi[j] = s < 2 ? next : prev;
                prev = next;
            }
        }
    }
    t->face_seg[nf] = j;
    return CCN_OK;
}

/* Segments shared both ways, and the same curve (ends and three inner points agree). */
static ccn_status check_adjacency(const ccn__cad_model *m, const ccn__cad_topo *t, ccn_error *err) {
    for (int32_t a = 0; a < t->num_segs; a++) {
        int32_t b = m->adjacency[a], fa = t->seg_face[a], sa = t->seg_side[a];
        if (b < 0) continue;
        if (b >= t->num_segs || b == a || m->adjacency[b] != a)
            return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, fa,
                                 "face %d side %d: adjacency %d of segment %d is out of range, "
                                 "itself or not mutual", (int)fa, sa, (int)b, (int)a);
        if (b < a) continue;
        static const double w[5] = {0, 0.25, 0.5, 0.75, 1};
        for (int k = 0; k < 5; k++) {
            double pa[3], pb[3];
            seg_point(m, t, a, w[k], pa);
            seg_point(m, t, b, 1 - w[k], pb);
            double d = ccn__dist3(pa, pb);
            if (!(d <= t->tolerance))
                return ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, fa,
                                     "face %d side %d and face %d side %d are not the same "
                                     "curve run in opposite directions (%.3g apart at %g)",
                                     (int)fa, sa, (int)t->seg_face[b], (int)t->seg_side[b], d, w[k]);
        }
    }
    return CCN_OK;
}

/* The segment after j in its face's loop. */
static int32_t seg_next(const ccn__cad_topo *t, int32_t j) {
    int32_t f = t->seg_face[j];
    return j + 1 < t->face_seg[f + 1] ? j + 1 : t->face_seg[f];
}

/* Sets each vertex's position to the end pole of the first clamped edge curve ending there
 * (the vertices of periodic sides keep the point on the side). -1: out of memory. */
static int curve_end_vertices(const ccn__cad_model *m, ccn__cad_topo *t) {
    int32_t cap = 0;
    for (int32_t f = 0; f < m->num_faces; f++) {
        int32_t c = ccn__cad_curve_capacity(&m->faces[f]);
        cap = c > cap ? c : cap;
    }
    double *buf = malloc(sizeof(double) * (4 * (size_t)cap + CCN_CAD_MAX_DEGREE + 1));
    uint8_t *set = calloc((size_t)t->num_verts + 1, 1);
    if (!buf || !set) { free(buf); free(set); return -1; }
    ccn__cad_curve c = {0, 0, buf + 3 * (size_t)cap, buf, 0};
    for (int32_t e = 0; e < t->num_edges; e++) {
        int32_t v0 = t->edge_vert[2 * e], v1 = t->edge_vert[2 * e + 1];
        if (set[v0] && set[v1]) continue;
        ccn__cad_segment_curve(m, t, t->edge_seg[e], &c);
        int32_t p = c.degree, n = c.num_poles;
        if (c.periodic || c.knots[0] != c.knots[p] || c.knots[n] != c.knots[n + p]) continue; /* not clamped */
        if (!set[v0]) memcpy(t->vert_pos + 3 * (size_t)v0, c.poles, 3 * sizeof(double)), set[v0] = 1;
        if (!set[v1])
            memcpy(t->vert_pos + 3 * (size_t)v1, c.poles + 3 * (size_t)(c.num_poles - 1), 3 * sizeof(double)), set[v1] = 1;
    }
    free(buf);
    free(set);
    return 0;
}

int ccn__cad_whole_side(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j) {
    double lo, hi;
    ccn__cad_domain(&m->faces[t->seg_face[j]], t->seg_side[j] % 2, &lo, &hi);
    return t->seg_lo[j] == lo && t->seg_hi[j] == hi;
}

ccn_status ccn__cad_topo_build(const ccn__cad_model *m, ccn__cad_topo *t, ccn_error *err) {
    memset(t, 0, sizeof *t);
    if (err) { err->status = CCN_OK; err->element_kind = CCN_ELEM_NONE; err->element = -1; err->message[0] = 0; }
    if (!m || m->num_faces < 1 || !m->faces || !m->adjacency)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "the model is NULL or has no faces or no adjacency");
    if (m->num_faces > INT32_MAX / 8)
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "too many faces (%d)", (int)m->num_faces);
    const char *strs[2] = {m->name, m->timestamp};
    for (int k = 0; k < 2; k++)
        for (const char *c = strs[k]; c && *c; c++)
            if (*c < 32 || *c > 126 || *c == '\'' || *c == '\\' || c - strs[k] > 200)
                return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                                     "the %s must be printable ASCII (at most 200 characters) "
                                     "without quotes or backslashes", k ? "timestamp" : "name");
    ccn_status st = check_faces(m, t, err);
    if (!st) st = build_segments(m, t, err);
    if (!st) st = check_adjacency(m, t, err);
    if (st) { ccn__cad_topo_free(t); return st; }
    size_t ns = (size_t)t->num_segs;
    t->seg_vert = malloc(sizeof(int32_t) * ns);
    t->seg_edge = malloc(sizeof(int32_t) * ns);
    t->seg_sense = malloc(ns);
    t->edge_seg = malloc(sizeof(int32_t) * ns);
    t->edge_vert = malloc(sizeof(int32_t) * 2 * ns);
    t->vert_pos = malloc(sizeof(double) * 3 * ns);
    int32_t *parent = malloc(sizeof(int32_t) * ns);
    if (!t->seg_vert || !t->seg_edge || !t->seg_sense || !t->edge_seg || !t->edge_vert ||
        !t->vert_pos || !parent) {
        free(parent);
        ccn__cad_topo_free(t);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    /* vertices: segment starts joined through shared segments (start of a ~ end of b) */
    for (size_t i = 0; i < ns; i++) parent[i] = (int32_t)i;
    t->closed = 1;
    for (int32_t a = 0; a < t->num_segs; a++) {
        int32_t b = m->adjacency[a];
        if (b < 0) { t->closed = 0; continue; }
        uf_union(parent, a, seg_next(t, b));
        uf_union(parent, seg_next(t, a), b);
    }
    int32_t *vid = t->seg_edge; /* scratch: root -> vertex id */
    for (size_t i = 0; i < ns; i++) vid[i] = -1;
    for (int32_t i = 0; i < t->num_segs; i++) {
        int32_t r = uf_find(parent, i);
        if (vid[r] < 0) {
            vid[r] = t->num_verts;
            seg_point(m, t, r, 0, t->vert_pos + 3 * (size_t)t->num_verts);
            t->num_verts++;
        }
        t->seg_vert[i] = vid[r];
    }
    free(parent);
    /* edges: the curve is the iso curve of the first appearance (increasing parameter of that
     * side), or of its twin when only the twin is a whole side: then the curve's poles are that
     * face's own boundary poles, no knot insertion rounds them, and the file shares them */
    for (size_t i = 0; i < ns; i++) t->seg_edge[i] = -1;
    for (int32_t a0 = 0; a0 < t->num_segs; a0++) {
        if (t->seg_edge[a0] >= 0) continue;
        int32_t a = a0, b = m->adjacency[a0];
        if (b >= 0 && !ccn__cad_whole_side(m, t, a) && ccn__cad_whole_side(m, t, b)) a = b, b = a0;
        int32_t e = t->num_edges++;
        int fwd = t->seg_side[a] < 2; /* sides 0, 1 run in increasing parameter, 2, 3 decreasing */
        t->edge_seg[e] = a;
        t->seg_edge[a] = e;
        t->seg_sense[a] = (uint8_t)fwd;
        int32_t c0 = t->seg_vert[a], c1 = t->seg_vert[seg_next(t, a)];
        t->edge_vert[2 * e] = fwd ? c0 : c1;
        t->edge_vert[2 * e + 1] = fwd ? c1 : c0;
        if (b >= 0) {
            t->seg_edge[b] = e;
            t->seg_sense[b] = (uint8_t)!fwd;
        }
    }
    /* each vertex where the curve of its first edge starts or ends, bit for bit: the file
     * writes that point once for both */
    if (curve_end_vertices(m, t)) {
        ccn__cad_topo_free(t);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    /* shells: faces joined through shared segments, numbered in the order of their first face
     * (a cage of several parts is several shells, each a solid when closed) */
    int32_t nf = m->num_faces;
    t->face_shell = malloc(sizeof(int32_t) * (size_t)nf);
    int32_t *fp = malloc(sizeof(int32_t) * (size_t)nf);
    if (!t->face_shell || !fp) {
        free(fp);
        ccn__cad_topo_free(t);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    for (int32_t f = 0; f < nf; f++) fp[f] = f, t->face_shell[f] = -1;
    for (int32_t a = 0; a < t->num_segs; a++)
        if (m->adjacency[a] >= 0) uf_union(fp, t->seg_face[a], t->seg_face[m->adjacency[a]]);
    for (int32_t f = 0; f < nf; f++) {
        int32_t r = uf_find(fp, f);
        if (t->face_shell[r] < 0) t->face_shell[r] = t->num_shells++;
        t->face_shell[f] = t->face_shell[r];
    }
    free(fp);
    t->shell_closed = malloc((size_t)t->num_shells);
    t->shell_start = calloc((size_t)t->num_shells + 1, sizeof(int32_t));
    t->shell_face = malloc(sizeof(int32_t) * (size_t)nf);
    if (!t->shell_closed || !t->shell_start || !t->shell_face) {
        ccn__cad_topo_free(t);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    memset(t->shell_closed, 1, (size_t)t->num_shells);
    for (int32_t a = 0; a < t->num_segs; a++)
        if (m->adjacency[a] < 0) t->shell_closed[t->face_shell[t->seg_face[a]]] = 0;
    for (int32_t f = 0; f < nf; f++) t->shell_start[t->face_shell[f] + 1]++;
    for (int32_t sh = 0; sh < t->num_shells; sh++) t->shell_start[sh + 1] += t->shell_start[sh];
    for (int32_t f = 0; f < nf; f++) t->shell_face[t->shell_start[t->face_shell[f]]++] = f;
    for (int32_t sh = t->num_shells; sh > 0; sh--) t->shell_start[sh] = t->shell_start[sh - 1];
    t->shell_start[0] = 0;
    return CCN_OK;
}

/* ---- segment curves ------------------------------------------------------------------ */

int32_t ccn__cad_curve_capacity(const ccn__cad_surface *f) {
    int32_t a = f->num_poles[0] + 2 * f->degree[0], b = f->num_poles[1] + 2 * f->degree[1];
    return a > b ? a : b;
}

/* Inserts x into the curve until its multiplicity is degree (Boehm). */
static void insert_to_degree(ccn__cad_curve *c, double x) {
    int32_t p = c->degree;
    for (;;) {
        int32_t n = c->num_poles, k = p, mult = 0;
        while (k + 1 < n && c->knots[k + 1] <= x) k++; /* knots[k] <= x < knots[k+1] */
        for (int32_t i = k; i >= 0 && c->knots[i] == x; i--) mult++;
        if (mult >= p) return;
        for (int32_t i = n; i > k - mult; i--) memcpy(c->poles + 3 * (size_t)i, c->poles + 3 * ((size_t)i - 1), sizeof(double) * 3);
        /* new pole i (k-p+1 <= i <= k-mult) = a P_i + (1-a) P_{i-1}; poles[i] still holds P_i */
        double prev[3];
        memcpy(prev, c->poles + 3 * (size_t)(k - p), sizeof prev);
        for (int32_t i = k - p + 1; i <= k - mult; i++) {
            double a = (x - c->knots[i]) / (c->knots[i + p] - c->knots[i]), cur[3];
            double *q = c->poles + 3 * (size_t)i;
            memcpy(cur, q, sizeof cur);
            for (int d = 0; d < 3; d++) q[d] = a * cur[d] + (1 - a) * prev[d];
            memcpy(prev, cur, sizeof prev);
        }
        for (int32_t i = n + p; i > k; i--) c->knots[i + 1] = c->knots[i];
        c->knots[k + 1] = x;
        c->num_poles = n + 1;
    }
}

/* c's parameters mapped affinely onto [0, 1] (the shape is unchanged), so that the pcurves of
 * edges cut from faces with [0, 1]^2 domains repeat and are written once (io/step.c). */
static void unit_curve(ccn__cad_curve *c) {
    double lo = c->knots[c->degree], w = c->knots[c->num_poles] - lo;
    if (lo == 0 && w == 1) return;
    for (int32_t i = 0; i < c->num_poles + c->degree + 1; i++) c->knots[i] = (c->knots[i] - lo) / w;
}

void ccn__cad_segment_curve(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j,
                            ccn__cad_curve *c) {
    const ccn__cad_surface *f = &m->faces[t->seg_face[j]];
    int s = t->seg_side[j], d = s % 2 == 0 ? 0 : 1;
    double lo, hi;
    ccn__cad_domain(f, d, &lo, &hi);
    int32_t p = f->degree[d], n = f->num_poles[d], i = 0;
    c->degree = p;
    c->num_poles = n;
    for (int32_t k = 0; k < f->num_knots[d]; k++)
        for (int32_t r = 0; r < f->mults[d][k]; r++) c->knots[i++] = f->knots[d][k];
    ccn__cad_side_curve(f, s, c->poles);
    c->periodic = f->periodic[d];
    if (t->seg_lo[j] == lo && t->seg_hi[j] == hi) { unit_curve(c); return; }
    c->periodic = 0;
    double a = t->seg_lo[j], b = t->seg_hi[j];
    /* cut at b: keep poles 0 .. (first index of b) - 1 and knots up to b (p+1 times) */
    if (!(b == hi && c->knots[n + p] == hi && c->knots[n] == hi)) {
        insert_to_degree(c, b);
        int32_t i0 = 0;
        while (c->knots[i0] < b) i0++;
        c->num_poles = i0;
        c->knots[i0 + p] = b;
    }
    if (!(a == lo && c->knots[0] == lo && c->knots[p] == lo)) {
        insert_to_degree(c, a);
        int32_t i0 = 0;
        while (c->knots[i0] < a) i0++; /* knots[i0 .. i0+p-1] = a; pole i0-1 is on the curve */
        int32_t drop = i0 - 1, nk = c->num_poles + p + 1;
        memmove(c->poles, c->poles + 3 * (size_t)drop, sizeof(double) * 3 * (size_t)(c->num_poles - drop));
        memmove(c->knots + 1, c->knots + i0, sizeof(double) * (size_t)(nk - i0));
        c->knots[0] = a;
        c->num_poles -= drop;
    }
    unit_curve(c);
}
