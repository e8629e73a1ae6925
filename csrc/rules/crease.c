/* Creases (rules/crease.h): OpenSubdiv 3.5's Sdc::Crease, in single precision as there
 * (sdc/crease.cpp: DetermineVertexVertexRule, ComputeFractionalWeightAtVertex,
 * SubdivideEdgeSharpnessAtVertex / ...AroundVertex; sdc/crease.h: decrementSharpness,
 * GetSharpEdgePairOfCrease). */
#include "rules/crease.h"

#include "topology/halfedge.h"

static int smooth(float s) { return s <= 0.0f; }
static int sharp(float s) { return s > 0.0f; }
static int infinite(float s) { return s >= CCN_SHARP_INF; }
static int semisharp(float s) { return s > 0.0f && s < CCN_SHARP_INF; }

float ccn__sharp_decrement(float s) {
    if (smooth(s)) return 0.0f;
    if (infinite(s)) return CCN_SHARP_INF;
    if (s > 1.0f) return s - 1.0f;
    return 0.0f;
}

void ccn__sharp_children(int method, int32_t n, const float *s, float *cs) {
    if (method != CCN_CREASE_CHAIKIN || n < 2) {
        for (int32_t i = 0; i < n; i++) cs[i] = ccn__sharp_decrement(s[i]);
        return;
    }
    float sum = 0.0f;
    int32_t cnt = 0;
    for (int32_t i = 0; i < n; i++)
        if (semisharp(s[i])) { cnt++; sum += s[i]; }
    for (int32_t i = 0; i < n; i++) {
        if (cnt == 0) cs[i] = s[i]; /* OpenSubdiv's smooth shortcut: values kept */
        else if (smooth(s[i])) cs[i] = 0.0f;
        else if (infinite(s[i])) cs[i] = CCN_SHARP_INF;
        else if (cnt == 1) cs[i] = ccn__sharp_decrement(s[i]);
        else {
            float other = (sum - s[i]) / (float)(cnt - 1);
            float c = (0.75f * s[i] + 0.25f * other) - 1.0f;
            cs[i] = smooth(c) ? 0.0f : c;
        }
    }
}

int ccn__sharp_rule(float vs, int32_t n, const float *s) {
    if (sharp(vs)) return CCN_RULE_CORNER;
    int32_t k = 0;
    for (int32_t i = 0; i < n; i++) k += sharp(s[i]);
    return k > 2 ? CCN_RULE_CORNER : 1 << k;
}

void ccn__sharp_crease_ends(int32_t n, const float *s, int32_t ends[2]) {
    ends[0] = 0;
    while (ends[0] < n - 1 && smooth(s[ends[0]])) ends[0]++;
    ends[1] = n - 1;
    while (ends[1] > 0 && smooth(s[ends[1]])) ends[1]--;
}

float ccn__sharp_fraction(int method, float pvs, float cvs, int32_t n, const float *ps, const float *cs) {
    int32_t cnt = 0;
    float sum = 0.0f;
    if (sharp(pvs) && smooth(cvs)) { cnt = 1; sum = pvs; }
    for (int32_t i = 0; i < n; i++) {
        int t = method != CCN_CREASE_CHAIKIN ? sharp(ps[i]) && ps[i] <= 1.0f
                                             : sharp(ps[i]) && smooth(cs[i]);
        if (t) { sum += ps[i]; cnt++; }
    }
    if (cnt == 0) return 0.0f;
    float w = sum / (float)cnt;
    return w > 1.0f ? 1.0f : w;
}

int32_t ccn__fan_sharpness(const ccn_mesh *m, int32_t v, float *s) {
    int32_t n = ccn__valence(m, v);
    for (int32_t k = 0; k < n; k++) {
        int32_t e = ccn__fan_edge(m, v, k);
        int bnd = m->vboundary[v] && (k == 0 || k == n - 1);
        s[k] = bnd ? CCN_SHARP_INF : m->esharp ? m->esharp[e] : 0.0f;
    }
    return n;
}

float ccn__vertex_sharpness(const ccn_mesh *m, int32_t v, int pinned) {
    if (pinned && m->vboundary[v] && ccn__valence(m, v) == 2) return CCN_SHARP_INF;
    return m->vsharp ? m->vsharp[v] : 0.0f;
}

int32_t ccn__sharp_count(const ccn_mesh *m, int32_t v) {
    int32_t n = ccn__valence(m, v), k = m->vboundary[v] ? 2 : 0;
    if (!m->esharp) return k;
    for (int32_t i = m->vboundary[v] ? 1 : 0; i < (m->vboundary[v] ? n - 1 : n); i++)
        k += m->esharp[ccn__fan_edge(m, v, i)] > 0.0f;
    return k;
}

float ccn__child_edge_sharpness(const ccn_mesh *m, int method, int32_t e, int32_t v) {
    float s = m->esharp ? m->esharp[e] : 0.0f;
    if (method != CCN_CREASE_CHAIKIN || smooth(s) || infinite(s)) return ccn__sharp_decrement(s);
    int32_t n = ccn__valence(m, v);
    if (n < 2) return ccn__sharp_decrement(s);
    float sum = 0.0f;
    int32_t cnt = 0;
    for (int32_t k = 0; k < n; k++) {
        int32_t f = ccn__fan_edge(m, v, k);
        int bnd = m->vboundary[v] && (k == 0 || k == n - 1);
        float x = bnd ? CCN_SHARP_INF : m->esharp[f];
        if (semisharp(x)) { cnt++; sum += x; }
    }
    if (cnt > 1) {
        float other = (sum - s) / (float)(cnt - 1);
        s = 0.75f * s + 0.25f * other;
    }
    s -= 1.0f;
    return sharp(s) ? s : 0.0f;
}
