/* Knot-insertion stencils on a quad mesh with ring intervals (DESIGN §4.2).
 *
 * Every rule is the tensor product of the curve rules
 *   edge point   E_j = ((D_j + 2D_{j+1}) P_j + (D_j + 2D_{j-1}) P_{j+1}) / (2(D_{j-1}+D_j+D_{j+1}))
 *   vertex point V_j = (D_j E_{j-1} + D_{j-1} E_j) / (2(D_{j-1}+D_j)) + P_j/2
 * (Li 2016 eqs (5)-(7) are the case "e = d"). The intervals a stencil needs beyond the
 * points it touches come from rings; where no ring exists they are defined by:
 *  - straight through an interior valence-4 vertex: the opposite edge of the fan;
 *  - straight through an interior EV: p_i = (d_{i-2} + d_{i+2}) / 2 (NURSS, SPEC A9);
 *  - a boundary vertex, edge transverse to the boundary: the edge's own interval (mirror);
 *  - a boundary vertex, edge along the boundary: the other boundary edge (the boundary is a
 *    cubic B-spline curve), or the edge's own interval at a pinned valence-2 corner.
 * Stencils read old control points only.
 *
 * Creases (rules/crease.h) split the surface into sectors that refine independently, like
 * boundaries: the non-uniform spline on each side of an (at this level) sharp edge is the one
 * that edge's curve bounds. So every look-up treats sharp edges (sharpness >= 1 at this level,
 * ccn__edge_splits; a fractional edge blends rules that use the smooth look-ups) as boundary
 * edges: at a vertex
 * with two sharp edges (a crease) the interval beyond along a smooth edge is that edge's own
 * (mirror), along a sharp edge the other sharp edge's (the crease curve continues); at a
 * corner (three or more sharp edges, or vertex sharpness) every edge mirrors; at a dart (one
 * sharp edge) the look-ups are the smooth ones. The quad face point's interval across a sharp
 * edge is its own (mirror), as across a boundary.
 */
#include "rules/bspline.h"

#include "rules/crease.h"

/* Fan edges of v that split the look-ups (boundary edges count): the outgoing half-edges of
 * v's fan but a boundary vertex's first (its outgoing boundary edge; the incoming one is not
 * in the fan). */
static int32_t split_count(const ccn_mesh *m, int32_t v) {
    int32_t b = m->vboundary[v], k = b ? 2 : 0;
    for (int32_t i = m->vfan_start[v] + b; i < m->vfan_start[v + 1]; i++)
        k += m->esharp[m->hedge[m->vfan[i]]] >= 1.0f;
    return k;
}

/* Crease-aware interval beyond v along fan edge k (see the file comment). */
static double beyond_creased(const ccn_mesh *m, int32_t v, int32_t k, int pinned) {
    int32_t n = ccn__valence(m, v), e = ccn__fan_edge(m, v, k);
    int32_t nsharp = split_count(m, v);
    int bnd_edge = m->vboundary[v] && (k == 0 || k == n - 1);
    int sharp = bnd_edge || ccn__edge_splits(m, e);
    int corner = nsharp >= 3 || ccn__vertex_sharpness(m, v, pinned) >= 1.0f;
    if (sharp) {
        if (nsharp == 2 && !corner) { /* along the crease: the other sharp edge */
            for (int32_t j = 0; j < n; j++) {
                if (j == k) continue;
                int bj = m->vboundary[v] && (j == 0 || j == n - 1);
                int32_t ej = ccn__fan_edge(m, v, j);
                if (bj || ccn__edge_splits(m, ej)) return m->eknot[ej];
            }
        }
        if (corner) return m->eknot[e];
        /* a dart's sharp edge: the smooth look-up below */
    } else if (nsharp >= 2 || corner) {
        return m->eknot[e];
    }
    if (m->vboundary[v]) return m->eknot[e];
    if (n == 4) return m->eknot[ccn__fan_edge(m, v, (k + 2) & 3)];
    if (n == 2) return m->eknot[ccn__fan_edge(m, v, 1 - k)];
    return 0.5 * (m->eknot[ccn__fan_edge(m, v, (k + n - 2) % n)] +
                  m->eknot[ccn__fan_edge(m, v, (k + 2) % n)]);
}

double ccn__beyond(const ccn_mesh *m, int32_t v, int32_t k, int pinned) {
    if (m->esharp) return beyond_creased(m, v, k, pinned);
    int32_t n = ccn__valence(m, v);
    if (m->vboundary[v]) {
        int32_t e = ccn__fan_edge(m, v, k);
        if (k != 0 && k != n - 1) return m->eknot[e];
        if (pinned && n == 2) return m->eknot[e];
        return m->eknot[ccn__fan_edge(m, v, k == 0 ? n - 1 : 0)];
    }
    if (n == 4) return m->eknot[ccn__fan_edge(m, v, (k + 2) & 3)];
    if (n == 2) return m->eknot[ccn__fan_edge(m, v, 1 - k)]; /* valence 2: the other edge */
    return 0.5 * (m->eknot[ccn__fan_edge(m, v, (k + n - 2) % n)] +
                  m->eknot[ccn__fan_edge(m, v, (k + 2) % n)]);
}

int32_t ccn__pos_at_end(const ccn_mesh *m, int32_t h) {
    int32_t t = m->htwin[h];
    if (t >= 0) return m->hfanpos[t];
    return ccn__valence(m, m->hvert[ccn__next(m, h)]) - 1; /* incoming boundary edge */
}

double ccn__transverse(const ccn_mesh *m, int32_t h) {
    if (ccn__fsize(m, m->hface[h]) == 4) return m->eknot[m->hedge[ccn__next(m, h)]];
    return 0.5 * (m->eknot[m->hedge[ccn__next(m, h)]] + m->eknot[m->hedge[ccn__prev(m, h)]]);
}

double ccn__side(const ccn_mesh *m, int32_t h, int pinned) {
    if (ccn__edge_splits(m, m->hedge[h])) return m->eknot[m->hedge[ccn__next(m, h)]]; /* mirror */
    int32_t v0 = m->hvert[h], v1 = m->hvert[ccn__next(m, h)];
    int ev0 = ccn__is_ev(m, v0), ev1 = ccn__is_ev(m, v1);
    if (ev0 || ev1) {
        /* NURSS: the interval straight through the EV along f's other edge at it */
        double s = 0.0;
        if (ev0) s += ccn__beyond(m, v0, m->hfanpos[m->htwin[ccn__prev(m, h)]], pinned);
        if (ev1) s += ccn__beyond(m, v1, m->hfanpos[ccn__next(m, h)], pinned);
        return ev0 && ev1 ? 0.5 * s : s;
    }
    int32_t t = m->htwin[h];
    if (t >= 0) return ccn__transverse(m, t);
    return m->eknot[m->hedge[ccn__next(m, h)]]; /* mirror across the boundary */
}

static void lerp3(const double *a, const double *b, double w, double out[3]) {
    for (int k = 0; k < 3; k++) out[k] = (1.0 - w) * a[k] + w * b[k];
}

double ccn__curve_edge_weight(const ccn_mesh *m, int32_t h, int pinned) {
    int32_t a = m->hvert[h], b = m->hvert[ccn__next(m, h)];
    double dp = ccn__beyond(m, a, m->hfanpos[h], pinned);
    double dn = ccn__beyond(m, b, ccn__pos_at_end(m, h), pinned);
    return ccn__edge_weight(dp, m->eknot[m->hedge[h]], dn);
}

void ccn__curve_edge_blend(const ccn_mesh *m, int32_t h, double w, double out[3]) {
    lerp3(m->pos + 3 * (size_t)m->hvert[h], m->pos + 3 * (size_t)m->hvert[ccn__next(m, h)], w, out);
}

void ccn__curve_edge_point(const ccn_mesh *m, int32_t h, int pinned, double out[3]) {
    ccn__curve_edge_blend(m, h, ccn__curve_edge_weight(m, h, pinned), out);
}

void ccn__quad_face_weights(const ccn_mesh *m, int32_t f, int pinned, double st[2]) {
    int32_t h0 = m->fstart[f];
    double a = m->eknot[m->hedge[h0]], b = m->eknot[m->hedge[h0 + 1]];
    st[0] = ccn__edge_weight(ccn__side(m, h0 + 3, pinned), a, ccn__side(m, h0 + 1, pinned));
    st[1] = ccn__edge_weight(ccn__side(m, h0, pinned), b, ccn__side(m, h0 + 2, pinned));
}

void ccn__quad_face_blend(const ccn_mesh *m, int32_t f, const double st[2], double out[3]) {
    int32_t h0 = m->fstart[f];
    const double *p0 = m->pos + 3 * (size_t)m->hvert[h0], *p1 = m->pos + 3 * (size_t)m->hvert[h0 + 1],
                 *p2 = m->pos + 3 * (size_t)m->hvert[h0 + 2], *p3 = m->pos + 3 * (size_t)m->hvert[h0 + 3];
    double s = st[0], t = st[1];
    double w0 = (1 - s) * (1 - t), w1 = s * (1 - t), w2 = s * t, w3 = (1 - s) * t;
    for (int k = 0; k < 3; k++) out[k] = w0 * p0[k] + w1 * p1[k] + w2 * p2[k] + w3 * p3[k];
}

void ccn__quad_face_point(const ccn_mesh *m, int32_t f, int pinned, double out[3]) {
    double st[2];
    ccn__quad_face_weights(m, f, pinned, st);
    ccn__quad_face_blend(m, f, st, out);
}

void ccn__edge_blend(const ccn_mesh *m, int32_t h, double bl, double br, const double *H,
                     const double *fp, double out[3]) {
    int32_t t = m->htwin[h], e = m->hedge[h];
    const double *he = H + 3 * (size_t)e;
    if (t < 0) {
        for (int k = 0; k < 3; k++) out[k] = he[k];
        return;
    }
    const double *fl = fp + 3 * (size_t)m->hface[h], *fr = fp + 3 * (size_t)m->hface[t];
    double s = 1.0 / (2.0 * (bl + br));
    for (int k = 0; k < 3; k++) out[k] = 0.5 * he[k] + s * (br * fl[k] + bl * fr[k]);
}

void ccn__edge_point(const ccn_mesh *m, int32_t h, const double *H, const double *fp,
                     double out[3]) {
    int32_t t = m->htwin[h];
    double bl = t < 0 ? 0.0 : ccn__transverse(m, h), br = t < 0 ? 0.0 : ccn__transverse(m, t);
    ccn__edge_blend(m, h, bl, br, H, fp, out);
}

void ccn__boundary_vertex_point(const ccn_mesh *m, int32_t v, const double *H, int pinned,
                                double out[3]) {
    const double *p = m->pos + 3 * (size_t)v;
    if (pinned && ccn__valence(m, v) == 2) {
        for (int k = 0; k < 3; k++) out[k] = p[k];
        return;
    }
    int32_t eo = ccn__fan_edge(m, v, 0), ei = m->vlast_edge[v];
    double dout = m->eknot[eo], din = m->eknot[ei];
    const double *hi = H + 3 * (size_t)ei, *ho = H + 3 * (size_t)eo;
    double s = 1.0 / (2.0 * (din + dout));
    for (int k = 0; k < 3; k++) out[k] = 0.5 * p[k] + s * (dout * hi[k] + din * ho[k]);
}

void ccn__bspline_basis(int p, const double *U, double x, double *N) {
    double left[64], right[64]; /* p <= 63 (OpenCASCADE's limit is 25) */
    N[0] = 1.0;
    for (int j = 1; j <= p && j < 64; j++) {
        left[j] = x - U[p - j];
        right[j] = U[p - 1 + j] - x;
        double saved = 0.0;
        for (int r = 0; r < j; r++) {
            double t = N[r] / (right[r + 1] + left[j - r]);
            N[r] = saved + right[r + 1] * t;
            saved = left[j - r] * t;
        }
        N[j] = saved;
    }
}

/* 1-D limit at knot t_0 of a cubic B-spline with control points P_-1, P_0, P_1 (blossoms
 * f(t_-2,t_-1,t_0), f(t_-1,t_0,t_1), f(t_0,t_1,t_2)) and intervals D_-2, D_-1, D_0, D_1:
 *   A = f(t_-1,t_0,t_0) = P_-1 + a (P_0 - P_-1),  a = (D_-2 + D_-1)/(D_-2 + D_-1 + D_0)
 *   B = f(t_0,t_0,t_1)  = P_0 + b (P_1 - P_0),    b = D_-1/(D_-1 + D_0 + D_1)
 *   f(t_0) = A + g (B - A), g = D_-1/(D_-1 + D_0);  f'(t_0) = 3 (B - A)/(D_-1 + D_0). */
/* The second derivative at t_0 (blossoms: f''(t_0) = 6 f(t_0, d, d), the derivative curve's
 * control points Q = 3 (P_0 - P_-1) / (D_-2 + D_-1 + D_0) and 3 (P_1 - P_0) / (D_-1 + D_0 + D_1),
 * f''(t_0) = 2 (Q_1 - Q_0) / (D_-1 + D_0)); uniform intervals give (1, -2, 1). */
void ccn__curve_limit_weights2(double dm2, double dm1, double d0, double d1, double w[3],
                               double dw[3], double ddw[3]) {
    ccn__curve_limit_weights(dm2, dm1, d0, d1, w, dw);
    double s = 6.0 / (dm1 + d0), a = 1.0 / (dm2 + dm1 + d0), b = 1.0 / (dm1 + d0 + d1);
    ddw[0] = s * a;
    ddw[1] = -s * (a + b);
    ddw[2] = s * b;
}

void ccn__curve_limit_weights(double dm2, double dm1, double d0, double d1, double w[3],
                                double dw[3]) {
    double a = (dm2 + dm1) / (dm2 + dm1 + d0), b = dm1 / (dm1 + d0 + d1);
    double g = dm1 / (dm1 + d0), s = 3.0 / (dm1 + d0);
    double A[3] = {1 - a, a, 0}, B[3] = {0, 1 - b, b};
    for (int i = 0; i < 3; i++) {
        w[i] = A[i] + g * (B[i] - A[i]);
        dw[i] = s * (B[i] - A[i]);
    }
}

