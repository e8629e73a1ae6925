/* The neutral B-rep of the CAD writers (cad.h): validation, vertices and shared edges, iso
 * curves of face sides, and the buffered number-exact output both writers use. */
#include "cad.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ccn_status ccn__cad_fail(ccn_error *err, ccn_status st, int32_t kind, int32_t element,
                         const char *fmt, ...) {
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = st;
        err->element_kind = kind;
        err->element = element;
    }
    return st;
}

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
    snprintf(tmp, sizeof tmp, "%.17g", x);
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

void ccn__cad_domain(const ccn__cad_surface *f, int dir, double *lo, double *hi) {
    *lo = flat_knot(f, dir, f->degree[dir]);
    *hi = flat_knot(f, dir, f->num_poles[dir]);
}

/* Nonzero basis functions N[span-p .. span] at t (span: t[span] <= t < t[span+1], the last
 * non-empty span inside the domain at its upper end). Returns span. */
static int32_t basis(const ccn__cad_surface *f, int dir, double t, double *N) {
    int32_t p = f->degree[dir], n = f->num_poles[dir], span = p;
    while (span + 1 < n && flat_knot(f, dir, span + 1) <= t) span++;
    double left[CCN_CAD_MAX_DEGREE + 1], right[CCN_CAD_MAX_DEGREE + 1];
    N[0] = 1;
    for (int32_t j = 1; j <= p; j++) {
        left[j] = t - flat_knot(f, dir, span + 1 - j);
        right[j] = flat_knot(f, dir, span + j) - t;
        double saved = 0;
        for (int32_t r = 0; r < j; r++) {
            double tmp = N[r] / (right[r + 1] + left[j - r]);
            N[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        N[j] = saved;
    }
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
        return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                             "face %d: %s degree %d is not in [1, %d]", (int)fi, d, (int)p,
                             CCN_CAD_MAX_DEGREE);
    if (n < p + 1 || nk < 2 || !f->knots[dir] || !f->mults[dir])
        return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                             "face %d: %s needs >= %d poles and >= 2 knots (got %d, %d)",
                             (int)fi, d, (int)p + 1, (int)n, (int)nk);
    int64_t sum = 0;
    for (int32_t k = 0; k < nk; k++) {
        double t = f->knots[dir][k];
        int32_t mu = f->mults[dir][k];
        if (!isfinite(t) || (k && !(t > f->knots[dir][k - 1])))
            return ccn__cad_fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                 "face %d: %s knot %d (%g) is not finite and increasing",
                                 (int)fi, d, (int)k, t);
        int32_t maxm = k == 0 || k == nk - 1 ? p + 1 : p;
        if (mu < 1 || mu > maxm)
            return ccn__cad_fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                 "face %d: %s knot %d has multiplicity %d (allowed 1..%d)",
                                 (int)fi, d, (int)k, (int)mu, (int)maxm);
        sum += mu;
    }
    if (sum != (int64_t)n + p + 1)
        return ccn__cad_fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                             "face %d: %s multiplicities sum to %lld, expected %d poles + %d + 1",
                             (int)fi, d, (long long)sum, (int)n, (int)p);
    double lo, hi;
    ccn__cad_domain(f, dir, &lo, &hi);
    if (!(hi > lo))
        return ccn__cad_fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                             "face %d: empty %s domain [%g, %g]", (int)fi, d, lo, hi);
    if (f->periodic[dir]) { /* intervals repeat with the period; last p rows = first p */
        for (int32_t i = 0; i + 1 < 2 * p; i++) {
            double a = flat_knot(f, dir, i + 1) - flat_knot(f, dir, i);
            double b = flat_knot(f, dir, i + n - p + 1) - flat_knot(f, dir, i + n - p);
            if (fabs(a - b) > 1e-12 * (hi - lo))
                return ccn__cad_fail(err, CCN_ERR_KNOTS, CCN_ELEM_FACE, fi,
                                     "face %d: %s is marked periodic but its knot intervals "
                                     "do not repeat", (int)fi, d);
        }
        if (n < 2 * p)
            return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                                 "face %d: periodic %s needs >= %d poles", (int)fi, d, (int)(2 * p));
    }
    return CCN_OK;
}

static void corner_point(const ccn__cad_surface *f, int c, double out[3]) {
    double u0, u1, v0, v1;
    ccn__cad_domain(f, 0, &u0, &u1);
    ccn__cad_domain(f, 1, &v0, &v1);
    ccn__cad_eval(f, c == 1 || c == 2 ? u1 : u0, c >= 2 ? v1 : v0, out);
}

/* Point at fraction w of side s in the side's own running direction. */
static void side_point(const ccn__cad_surface *f, int s, double w, double out[3]) {
    double u0, u1, v0, v1;
    ccn__cad_domain(f, 0, &u0, &u1);
    ccn__cad_domain(f, 1, &v0, &v1);
    double a = u0 + w * (u1 - u0), b = v0 + w * (v1 - v0);
    double ra = u1 - w * (u1 - u0), rb = v1 - w * (v1 - v0);
    switch (s) {
    case 0: ccn__cad_eval(f, a, v0, out); break;
    case 1: ccn__cad_eval(f, u1, b, out); break;
    case 2: ccn__cad_eval(f, ra, v1, out); break;
    default: ccn__cad_eval(f, u0, rb, out); break;
    }
}

static double dist3(const double a[3], const double b[3]) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
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
    free(t->corner_vert); free(t->vert_pos); free(t->side_edge); free(t->side_sense);
    free(t->edge_side); free(t->edge_vert);
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
            return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi, "face %d: poles is NULL", (int)fi);
        if ((int64_t)f->num_poles[0] * f->num_poles[1] > INT32_MAX / 3)
            return ccn__cad_fail(err, CCN_ERR_MEMORY, CCN_ELEM_FACE, fi, "face %d: too many poles", (int)fi);
        size_t np = (size_t)f->num_poles[0] * (size_t)f->num_poles[1];
        for (size_t i = 0; i < 3 * np; i++) {
            double x = f->poles[i];
            if (!isfinite(x) || fabs(x) > 1e300)
                return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
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
                    if (dist3(f->poles + 3 * a, f->poles + 3 * b) > t->tolerance)
                        return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, fi,
                                             "face %d: %s is marked periodic but pole row %d "
                                             "differs from row %d", (int)fi, dir ? "v" : "u",
                                             (int)(i + n - p), (int)i);
                }
        }
        (void)nu;
    }
    return CCN_OK;
}

/* Sides shared both ways, and the same curve (corners and three inner points agree). */
static ccn_status check_adjacency(const ccn__cad_model *m, const ccn__cad_topo *t, ccn_error *err) {
    int32_t ns = 4 * m->num_faces;
    for (int32_t a = 0; a < ns; a++) {
        int32_t b = m->adjacency[a];
        if (b < 0) continue;
        if (b >= ns || b == a || m->adjacency[b] != a)
            return ccn__cad_fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, a / 4,
                                 "face %d side %d: adjacency %d is out of range, itself or not "
                                 "mutual", (int)(a / 4), (int)(a % 4), (int)b);
        if (b < a) continue;
        static const double w[5] = {0, 0.25, 0.5, 0.75, 1};
        for (int k = 0; k < 5; k++) {
            double pa[3], pb[3];
            side_point(&m->faces[a / 4], a % 4, w[k], pa);
            side_point(&m->faces[b / 4], b % 4, 1 - w[k], pb);
            double d = dist3(pa, pb);
            if (!(d <= t->tolerance))
                return ccn__cad_fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_FACE, a / 4,
                                     "face %d side %d and face %d side %d are not the same "
                                     "curve run in opposite directions (%.3g apart at %g)",
                                     (int)(a / 4), (int)(a % 4), (int)(b / 4), (int)(b % 4), d, w[k]);
        }
    }
    return CCN_OK;
}

ccn_status ccn__cad_topo_build(const ccn__cad_model *m, ccn__cad_topo *t, ccn_error *err) {
    memset(t, 0, sizeof *t);
    if (err) { err->status = CCN_OK; err->element_kind = CCN_ELEM_NONE; err->element = -1; err->message[0] = 0; }
    if (!m || m->num_faces < 1 || !m->faces || !m->adjacency)
        return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "the model is NULL or has no faces or no adjacency");
    if (m->num_faces > INT32_MAX / 8)
        return ccn__cad_fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "too many faces (%d)", (int)m->num_faces);
    const char *strs[2] = {m->name, m->timestamp};
    for (int k = 0; k < 2; k++)
        for (const char *c = strs[k]; c && *c; c++)
            if (*c < 32 || *c > 126 || *c == '\'' || *c == '\\' || c - strs[k] > 200)
                return ccn__cad_fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                                     "the %s must be printable ASCII (at most 200 characters) "
                                     "without quotes or backslashes", k ? "timestamp" : "name");
    ccn_status st = check_faces(m, t, err);
    if (st) return st;
    if ((st = check_adjacency(m, t, err))) return st;
    int32_t nf = m->num_faces, ns = 4 * nf;
    t->corner_vert = malloc(sizeof(int32_t) * (size_t)ns);
    t->side_edge = malloc(sizeof(int32_t) * (size_t)ns);
    t->side_sense = malloc((size_t)ns);
    t->edge_side = malloc(sizeof(int32_t) * (size_t)ns);
    t->edge_vert = malloc(sizeof(int32_t) * 2 * (size_t)ns);
    t->vert_pos = malloc(sizeof(double) * 3 * (size_t)ns);
    int32_t *parent = malloc(sizeof(int32_t) * (size_t)ns);
    if (!t->corner_vert || !t->side_edge || !t->side_sense || !t->edge_side || !t->edge_vert ||
        !t->vert_pos || !parent) {
        free(parent);
        ccn__cad_topo_free(t);
        return ccn__cad_fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    }
    /* vertices: corners joined through shared sides (corner s of f ~ corner t+1 of g) */
    for (int32_t i = 0; i < ns; i++) parent[i] = i;
    t->closed = 1;
    for (int32_t a = 0; a < ns; a++) {
        int32_t b = m->adjacency[a];
        if (b < 0) { t->closed = 0; continue; }
        int32_t fa = a / 4, sa = a % 4, fb = b / 4, sb = b % 4;
        uf_union(parent, 4 * fa + sa, 4 * fb + (sb + 1) % 4);
        uf_union(parent, 4 * fa + (sa + 1) % 4, 4 * fb + sb);
    }
    int32_t *vid = t->side_edge; /* scratch: root -> vertex id */
    for (int32_t i = 0; i < ns; i++) vid[i] = -1;
    for (int32_t i = 0; i < ns; i++) {
        int32_t r = uf_find(parent, i);
        if (vid[r] < 0) {
            vid[r] = t->num_verts;
            corner_point(&m->faces[r / 4], r % 4, t->vert_pos + 3 * (size_t)t->num_verts);
            t->num_verts++;
        }
        t->corner_vert[i] = vid[r];
    }
    free(parent);
    /* edges: first appearance defines the curve (increasing parameter of that side) */
    for (int32_t i = 0; i < ns; i++) t->side_edge[i] = -1;
    for (int32_t a = 0; a < ns; a++) {
        if (t->side_edge[a] >= 0) continue;
        int32_t e = t->num_edges++, f = a / 4, s = a % 4;
        int fwd = s < 2; /* sides 0, 1 run in increasing parameter, 2, 3 decreasing */
        t->edge_side[e] = a;
        t->side_edge[a] = e;
        t->side_sense[a] = (uint8_t)fwd;
        int32_t c0 = t->corner_vert[4 * f + s], c1 = t->corner_vert[4 * f + (s + 1) % 4];
        t->edge_vert[2 * e] = fwd ? c0 : c1;
        t->edge_vert[2 * e + 1] = fwd ? c1 : c0;
        int32_t b = m->adjacency[a];
        if (b >= 0) {
            t->side_edge[b] = e;
            t->side_sense[b] = (uint8_t)!fwd;
        }
    }
    return CCN_OK;
}
