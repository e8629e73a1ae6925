/* NURSS rules (Sederberg, Zheng, Sewell, Sabin 1998) for what knot insertion cannot do:
 * faces with != 4 sides (level 0 only) and interior vertices of valence != 4.
 *
 * The 1998 text was not available to us; the rules below are the reading of its eqs. 11-18
 * that (a) reproduces tensor-product knot insertion on a regular grid with arbitrary
 * intervals (checked to 7e-16), (b) gives Catmull-Clark for equal intervals, and (c) is the
 * "nurss" vertex rule of SPEC §2.3 (f_i = d_{i-1} d_{i+2}, m_i = (d_{i-1}+d_{i+1})(d_{i-2}+d_{i+2})/2).
 * The interval beyond a vertex P along an edge is ccn__beyond() (p_i at an EV).
 */
#include "rules/nurss.h"

#include "base/vec3.h"
#include "rules/bspline.h"

#include <string.h>

/* Eq. 11: F = sum w_i P_i / sum w_i, w_i = A_i B_i, where A_i (B_i) averages the 1-D
 * insertion weights "own interval + 2 x interval beyond the far end" of P_i along edge i
 * and edge i-2 (edge i-1 and edge i+1). For a quad this is the tensor face point. */
void ccn__ngon_face_point(const ccn_mesh *m, int32_t f, double out[3]) {
    int32_t h0 = m->fstart[f], n = ccn__fsize(m, f);
    double sw = 0.0, acc[3] = {0, 0, 0};
    for (int32_t i = 0; i < n; i++) {
        int32_t hi = h0 + i, hm1 = h0 + (i + n - 1) % n, hm2 = h0 + (i + n - 2) % n,
                hp1 = h0 + (i + 1) % n;
        double a = m->eknot[m->hedge[hi]] + 2.0 * ccn__beyond(m, m->hvert[hp1], ccn__pos_at_end(m, hi), 0) +
                   m->eknot[m->hedge[hm2]] + 2.0 * ccn__beyond(m, m->hvert[hm2], m->hfanpos[hm2], 0);
        double b = m->eknot[m->hedge[hm1]] + 2.0 * ccn__beyond(m, m->hvert[hm1], m->hfanpos[hm1], 0) +
                   m->eknot[m->hedge[hp1]] +
                   2.0 * ccn__beyond(m, m->hvert[ccn__next(m, hp1)], ccn__pos_at_end(m, hp1), 0);
        double w = a * b;
        const double *p = m->pos + 3 * (size_t)m->hvert[hi];
        for (int k = 0; k < 3; k++) acc[k] += w * p[k];
        sw += w;
    }
    for (int k = 0; k < 3; k++) out[k] = acc[k] / sw;
}

/* Eqs. 16-18: V' = (n-3)/n V + (3/n) sum(m_i M_i + f_i F_i) / sum(m_i + f_i), M_i the curve
 * edge points of the spokes (H), F_i the new face points. n = 4 is Li 2016 eq. (7). */
void ccn__nurss_vertex_weights(const ccn_mesh *m, int32_t v, double *mf, double ab[2]) {
    int32_t n = ccn__valence(m, v), s0 = m->vfan_start[v];
    double sw = 0.0;
    const double *ek = m->eknot;
    for (int32_t i = 0; i < n; i++) {
        double dm1 = ek[m->hedge[m->vfan[s0 + (i + n - 1) % n]]];
        double dp1 = ek[m->hedge[m->vfan[s0 + (i + 1) % n]]];
        double dm2 = ek[m->hedge[m->vfan[s0 + (i + n - 2) % n]]];
        double dp2 = ek[m->hedge[m->vfan[s0 + (i + 2) % n]]];
        double mi = 0.5 * (dm1 + dp1) * (dm2 + dp2), fi = dm1 * dp2;
        mf[2 * i] = mi;
        mf[2 * i + 1] = fi;
        sw += mi + fi;
    }
    ab[0] = (double)(n - 3) / n;
    ab[1] = 3.0 / (n * sw);
}

void ccn__nurss_vertex_blend(const ccn_mesh *m, int32_t v, const double *mf, const double ab[2],
                             const double *H, const double *fp, double out[3]) {
    int32_t n = ccn__valence(m, v), s0 = m->vfan_start[v];
    const double *p = m->pos + 3 * (size_t)v;
#ifdef CCN_V2D /* x, y side by side: the same products and sums per lane (base/vec3.h) */
    ccn__v2d a01 = {0, 0};
    double a2 = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t hi = m->vfan[s0 + i];
        double mi = mf[2 * i], fi = mf[2 * i + 1];
        const double *hp = H + 3 * (size_t)m->hedge[hi], *fpp = fp + 3 * (size_t)m->hface[hi];
        ccn__v2d h01, f01, mv = {mi, mi}, fv = {fi, fi};
        memcpy(&h01, hp, sizeof h01);
        memcpy(&f01, fpp, sizeof f01);
        a01 += mv * h01 + fv * f01;
        a2 += mi * hp[2] + fi * fpp[2];
    }
    ccn__v2d p01, w0 = {ab[0], ab[0]}, w1 = {ab[1], ab[1]};
    memcpy(&p01, p, sizeof p01);
    ccn__v2d o01 = w0 * p01 + w1 * a01;
    out[0] = o01[0]; out[1] = o01[1]; out[2] = ab[0] * p[2] + ab[1] * a2;
#else
    double acc[3] = {0, 0, 0};
    for (int32_t i = 0; i < n; i++) {
        int32_t hi = m->vfan[s0 + i];
        double mi = mf[2 * i], fi = mf[2 * i + 1];
        const double *hp = H + 3 * (size_t)m->hedge[hi], *fpp = fp + 3 * (size_t)m->hface[hi];
        for (int k = 0; k < 3; k++) acc[k] += mi * hp[k] + fi * fpp[k];
    }
    for (int k = 0; k < 3; k++) out[k] = ab[0] * p[k] + ab[1] * acc[k];
#endif
}

/* The same arithmetic in one pass (no scratch for the fan's weights). */
void ccn__nurss_vertex_point(const ccn_mesh *m, int32_t v, const double *H, const double *fp,
                             double out[3]) {
    int32_t n = ccn__valence(m, v), s0 = m->vfan_start[v];
    double acc[3] = {0, 0, 0}, sw = 0.0;
    const double *ek = m->eknot;
    for (int32_t i = 0; i < n; i++) {
        int32_t hi = m->vfan[s0 + i];
        double dm1 = ek[m->hedge[m->vfan[s0 + (i + n - 1) % n]]];
        double dp1 = ek[m->hedge[m->vfan[s0 + (i + 1) % n]]];
        double dm2 = ek[m->hedge[m->vfan[s0 + (i + n - 2) % n]]];
        double dp2 = ek[m->hedge[m->vfan[s0 + (i + 2) % n]]];
        double mi = 0.5 * (dm1 + dp1) * (dm2 + dp2), fi = dm1 * dp2;
        const double *hp = H + 3 * (size_t)m->hedge[hi], *fpp = fp + 3 * (size_t)m->hface[hi];
        for (int k = 0; k < 3; k++) acc[k] += mi * hp[k] + fi * fpp[k];
        sw += mi + fi;
    }
    const double *p = m->pos + 3 * (size_t)v;
    double a = (double)(n - 3) / n, b = 3.0 / (n * sw);
    for (int k = 0; k < 3; k++) out[k] = a * p[k] + b * acc[k];
}
