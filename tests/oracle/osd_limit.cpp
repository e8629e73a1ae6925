// osd_limit: refiner construction and exact limits of the OpenSubdiv test oracle, shared by
// osd_refine (osd_refine.cpp) and fvar_oracle (fvar_oracle.cpp); declarations in osd_oracle.h.
// The exactness rules of PrimvarRefiner::Limit and the one-ring refinement that makes a limit
// exact where Limit is not are described in osd_refine.cpp's header; the face-varying
// counterparts (LimitFaceVarying, the one-ring refinement carrying the values) follow the same
// rules (limitFaceVaryingExact, localLimitFVar below).
#include "osd_oracle.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace osd_oracle {

int g_osdErrors = 0;

[[noreturn]] void die(const std::string &msg) {
    std::fprintf(stderr, "osd_refine: %s\n", msg.c_str());
    std::exit(2);
}

double g_settle = 1e-16;  // environment OSD_REFINE_SETTLE overrides (for experiments)
int g_maxLevels = 120;

void osdError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv error: %s\n", msg);
    g_osdErrors++;
}

void osdWarning(const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv warning: %s\n", msg);
}

namespace {

typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;

}  // namespace

Far::TopologyRefiner *createRefiner(Cage const &c, Sdc::Options const &opts) {
    Far::TopologyDescriptor desc;
    desc.numVertices = (int)c.pos.size();
    desc.numFaces = (int)c.faceSizes.size();
    desc.numVertsPerFace = c.faceSizes.data();
    desc.vertIndicesPerFace = c.faceVerts.data();
    desc.numCreases = (int)c.creaseWeights.size();
    desc.creaseVertexIndexPairs = c.creasePairs.empty() ? nullptr : c.creasePairs.data();
    desc.creaseWeights = c.creaseWeights.empty() ? nullptr : c.creaseWeights.data();
    desc.numCorners = (int)c.cornerWeights.size();
    desc.cornerVertexIndices = c.cornerVerts.empty() ? nullptr : c.cornerVerts.data();
    desc.cornerWeights = c.cornerWeights.empty() ? nullptr : c.cornerWeights.data();
    Far::TopologyDescriptor::FVarChannel ch;
    if (c.fvValues > 0) {
        ch.numValues = c.fvValues;
        ch.valueIndices = c.fvIndices.data();
        desc.numFVarChannels = 1;
        desc.fvarChannels = &ch;
    }
    return Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, opts));
}

namespace {

bool isSemiSharp(float s) { return s > 0.0f && s < Sdc::Crease::SHARPNESS_INFINITE; }

bool isSmoothRule(Sdc::Crease::Rule r) {
    return r == Sdc::Crease::RULE_SMOOTH || r == Sdc::Crease::RULE_DART;
}

// Interior vertex of two faces with the smooth or dart rule: Limit() uses the corner mask.
bool isInteriorValence2(Far::TopologyLevel const &lev, int v) {
    return !lev.IsVertexBoundary(v) && lev.GetVertexFaces(v).size() == 2 &&
           isSmoothRule(lev.GetVertexRule(v));
}

bool hasSemiSharp(Far::TopologyLevel const &lev, int v) {
    if (isSemiSharp(lev.GetVertexSharpness(v))) return true;
    Far::ConstIndexArray ve = lev.GetVertexEdges(v);
    for (int i = 0; i < ve.size(); i++)
        if (isSemiSharp(lev.GetEdgeSharpness(ve[i]))) return true;
    return false;
}

bool facesAllQuads(Far::TopologyLevel const &lev, int v) {
    Far::ConstIndexArray vf = lev.GetVertexFaces(v);
    for (int i = 0; i < vf.size(); i++)
        if (lev.GetFaceVertices(vf[i]).size() != 4) return false;
    return true;
}

// Limit() uses the smooth mask at a dart, but the dart's sharp edge refines with the crease
// rule, so the mask is not that of the vertex's refinement matrix; at an interior valence-2
// vertex Limit() uses the corner mask. Both need refining until the point settles.
bool needsSettling(Far::TopologyLevel const &lev, int v) {
    return isInteriorValence2(lev, v) || lev.GetVertexRule(v) == Sdc::Crease::RULE_DART;
}

}  // namespace

// Does Limit() at this level give the exact limit of vertex v? (see the header)
bool limitMaskExact(Far::TopologyLevel const &lev, int v) {
    return !hasSemiSharp(lev, v) && !needsSettling(lev, v) && facesAllQuads(lev, v);
}

// Whether Tan1 x Tan2 of Limit() is the surface normal at v (see the header); the rule is
// final there (limitMaskExact, or valence 2 refined to convergence).
bool normalDefined(Far::TopologyLevel const &lev, int v, Sdc::Options const &opts) {
    const bool boundary = lev.IsVertexBoundary(v);
    const int nf = lev.GetVertexFaces(v).size();
    if (boundary && opts.GetVtxBoundaryInterpolation() == Sdc::Options::VTX_BOUNDARY_NONE)
        return false;
    switch (lev.GetVertexRule(v)) {
    case Sdc::Crease::RULE_SMOOTH: return !boundary && nf >= 3;
    case Sdc::Crease::RULE_CREASE: return boundary && nf == 2;
    case Sdc::Crease::RULE_CORNER: return boundary && nf == 1;
    default: return false;
    }
}

namespace {

double diagonal(std::vector<Vertex3> const &p) {
    if (p.empty()) return 0.0;
    double mn[3], mx[3];
    for (int k = 0; k < 3; k++) mn[k] = mx[k] = p[0].p[k];
    for (auto const &q : p)
        for (int k = 0; k < 3; k++) {
            mn[k] = std::min(mn[k], q.p[k]);
            mx[k] = std::max(mx[k], q.p[k]);
        }
    return std::sqrt((mx[0] - mn[0]) * (mx[0] - mn[0]) + (mx[1] - mn[1]) * (mx[1] - mn[1]) +
                     (mx[2] - mn[2]) * (mx[2] - mn[2]));
}

// The faces around vertex v of level lev (positions P) with every sharpness they carry, as
// a Cage; returns v's index in it.
int extractRing(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P, int v, Cage &c) {
    c = Cage();
    std::map<int, int> local;
    std::vector<int> global;
    auto loc = [&](int g) {
        auto it = local.find(g);
        if (it != local.end()) return it->second;
        const int l = (int)c.pos.size();
        local[g] = l;
        global.push_back(g);
        c.pos.push_back(P[(size_t)g]);
        return l;
    };
    const int center = loc(v);
    std::set<int> seen;
    Far::ConstIndexArray vf = lev.GetVertexFaces(v);
    for (int i = 0; i < vf.size(); i++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(vf[i]);
        c.faceSizes.push_back(fv.size());
        for (int k = 0; k < fv.size(); k++) c.faceVerts.push_back(loc(fv[k]));
        Far::ConstIndexArray fe = lev.GetFaceEdges(vf[i]);
        for (int k = 0; k < fe.size(); k++) {
            if (!seen.insert(fe[k]).second) continue;
            const float s = lev.GetEdgeSharpness(fe[k]);
            if (s > 0.0f) {
                Far::ConstIndexArray ev = lev.GetEdgeVertices(fe[k]);
                c.creasePairs.push_back(loc(ev[0]));
                c.creasePairs.push_back(loc(ev[1]));
                c.creaseWeights.push_back(s);
            }
        }
    }
    for (size_t l = 0; l < global.size(); l++) {
        const float s = lev.GetVertexSharpness(global[l]);
        if (s > 0.0f) {
            c.cornerVerts.push_back((int)l);
            c.cornerWeights.push_back(s);
        }
    }
    return center;
}

}  // namespace

// Exact limit of vertex v of level lev by refining its one-ring (see the header).
LimitPoint localLimit(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P, int v,
                      Sdc::Options const &opts) {
    Cage c;
    int center = extractRing(lev, P, v, c);
    const double scale = diagonal(c.pos);
    bool settled = false;  // valence 2 or dart: the point no longer moves
    for (int it = 0;; it++) {
        Far::TopologyRefiner *ref = createRefiner(c, opts);
        if (!ref || g_osdErrors) die("OpenSubdiv rejected a vertex one-ring");
        Far::TopologyLevel const &l0 = ref->GetLevel(0);
        if (!hasSemiSharp(l0, center) && facesAllQuads(l0, center) &&
            (settled || !needsSettling(l0, center))) {
            std::vector<Vertex3> pos(c.pos.size()), t1(c.pos.size()), t2(c.pos.size());
            Far::PrimvarRefinerReal<double> pr(*ref);
            pr.Limit(c.pos, pos, t1, t2);
            LimitPoint r{pos[(size_t)center], t1[(size_t)center], t2[(size_t)center],
                         normalDefined(l0, center, opts)};
            delete ref;
            return r;
        }
        if (it >= g_maxLevels) die("a vertex limit did not settle in " + std::to_string(g_maxLevels) + " levels");
        Far::TopologyRefiner::UniformOptions uo(1);
        uo.fullTopologyInLastLevel = true;
        ref->RefineUniform(uo);
        if (g_osdErrors) die("OpenSubdiv refinement of a vertex one-ring failed");
        std::vector<Vertex3> next((size_t)ref->GetLevel(1).GetNumVertices());
        Far::PrimvarRefinerReal<double> pr(*ref);
        pr.Interpolate(1, c.pos, next);
        const int child = ref->GetLevel(0).GetVertexChildVertex(center);
        double d2 = 0.0, mag = 0.0;
        for (int k = 0; k < 3; k++) {
            const double d = next[(size_t)child].p[k] - c.pos[(size_t)center].p[k];
            d2 += d * d;
            mag = std::max(mag, std::fabs(next[(size_t)child].p[k]));
        }
        // the move cannot get below the rounding of the coordinates themselves
        settled = std::sqrt(d2) <= std::max(g_settle * scale, 4 * DBL_EPSILON * mag);
        Cage nc;
        center = extractRing(ref->GetLevel(1), next, child, nc);
        c.pos.swap(nc.pos);
        c.faceSizes.swap(nc.faceSizes);
        c.faceVerts.swap(nc.faceVerts);
        c.creasePairs.swap(nc.creasePairs);
        c.creaseWeights.swap(nc.creaseWeights);
        c.cornerVerts.swap(nc.cornerVerts);
        c.cornerWeights.swap(nc.cornerWeights);
        delete ref;
    }
}

// ---- face-varying channels -------------------------------------------------------------

namespace {

// The faces around vertex v of level lev as a Cage (extractRing) with their face-varying
// values (channel 0 of lev, values FV) as a local channel; fv receives the local values.
int extractRingFV(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P,
                  std::vector<Vertex3> const &FV, int v, Cage &c, std::vector<Vertex3> &fv) {
    const int center = extractRing(lev, P, v, c);
    std::map<int, int> local;
    fv.clear();
    c.fvIndices.clear();
    Far::ConstIndexArray vf = lev.GetVertexFaces(v);
    for (int i = 0; i < vf.size(); i++) {
        Far::ConstIndexArray vals = lev.GetFaceFVarValues(vf[i], 0);
        for (int k = 0; k < vals.size(); k++) {
            auto it = local.find(vals[k]);
            int l;
            if (it != local.end()) l = it->second;
            else {
                l = (int)fv.size();
                local[vals[k]] = l;
                fv.push_back(FV[(size_t)vals[k]]);
            }
            c.fvIndices.push_back(l);
        }
    }
    c.fvValues = (int)fv.size();
    return center;
}

}  // namespace

// Index of vertex v in face f of level lev.
int cornerOf(Far::TopologyLevel const &lev, int f, int v) {
    Far::ConstIndexArray fv = lev.GetFaceVertices(f);
    for (int k = 0; k < fv.size(); k++)
        if (fv[k] == v) return k;
    die("vertex not in face");
}

// PrimvarRefiner::LimitFaceVarying at the last level of r (which must be refined: at level 0
// OpenSubdiv reads the value tags with value indices as offsets, valid from level 1 on), with
// the crease values' weights 1/6, 2/3, 1/6 in double precision (OpenSubdiv's are float
// literals, off by 3e-8). A value that does not match the vertex topology is a corner (its
// limit is itself, weight exactly 1) or a crease along the two ends of its span of faces
// (FVarLevel::getVertexCreaseEndValues: the value after the vertex in the span's first face,
// the one before it in the last); the crease limit is recomputed and must agree with
// OpenSubdiv's to 1e-6.
void limitFaceVaryingExact(Far::TopologyRefiner const &r, std::vector<Vertex3> const &fv,
                           std::vector<Vertex3> &lim) {
    Far::TopologyLevel const &lev = r.GetLevel(r.GetMaxLevel());
    if (r.GetMaxLevel() < 1) die("face-varying limits need a refined level");
    lim.assign(fv.size(), Vertex3());
    Far::PrimvarRefinerReal<double> pr(r);
    pr.LimitFaceVarying(fv, lim, 0);
    for (int v = 0; v < lev.GetNumVertices(); v++) {
        if (lev.DoesVertexFVarTopologyMatch(v, 0)) continue;
        Far::ConstIndexArray vf = lev.GetVertexFaces(v);
        const int n = vf.size();
        if (n == 0) continue;
        const bool bnd = lev.IsVertexBoundary(v);
        std::vector<int> val((size_t)n);
        for (int i = 0; i < n; i++) val[(size_t)i] = lev.GetFaceFVarValues(vf[i], 0)[cornerOf(lev, vf[i], v)];
        Far::ConstIndexArray ve = lev.GetVertexEdges(v);
        for (int i = 0; i < n; i++) {
            const int u = val[(size_t)i];
            const int ip = (i + n - 1) % n;
            // i starts u's span: the first face (boundary), after another value, or after a
            // discontinuous edge (edge i leads face i)
            const bool start = bnd ? (i == 0 || val[(size_t)ip] != u)
                                   : (val[(size_t)ip] != u || !lev.DoesEdgeFVarTopologyMatch(ve[i], 0));
            if (!start) continue;
            const Vertex3 &x = fv[(size_t)u], &l = lim[(size_t)u];
            if (l.p[0] == x.p[0] && l.p[1] == x.p[1] && l.p[2] == x.p[2]) continue;  // a corner
            int e = i, cnt = 1;
            while (cnt < n && val[(size_t)((e + 1) % n)] == u && (bnd ? e + 1 < n : lev.DoesEdgeFVarTopologyMatch(ve[(e + 1) % n], 0))) {
                e = (e + 1) % n;
                cnt++;
            }
            Far::ConstIndexArray f0 = lev.GetFaceFVarValues(vf[i], 0), f1 = lev.GetFaceFVarValues(vf[e], 0);
            const int c0 = cornerOf(lev, vf[i], v), c1 = cornerOf(lev, vf[e], v);
            const Vertex3 &a = fv[(size_t)f0[(c0 + 1) % f0.size()]], &b = fv[(size_t)f1[(c1 + f1.size() - 1) % f1.size()]];
            Vertex3 ex;
            double diff = 0.0, mag = 1.0;
            for (int k = 0; k < 3; k++) {
                ex.p[k] = (a.p[k] + 4.0 * x.p[k] + b.p[k]) / 6.0;
                diff = std::max(diff, std::fabs(ex.p[k] - l.p[k]));
                mag = std::max(mag, std::fabs(a.p[k]) + std::fabs(b.p[k]) + std::fabs(x.p[k]));
            }
            if (diff > 1e-6 * mag) die("a face-varying crease value does not have the expected ends");
            lim[(size_t)u] = ex;
        }
    }
}

// Exact limit of the face-varying values at vertex v of level lev (positions P, values FV of
// channel 0), one per face of v in GetVertexFaces order (the value of v's corner in that
// face). As localLimit: the one-ring (positions, sharpness and values) is refined until no
// semi-sharp value is left around v (LimitFaceVarying is then exact: the vertex's limit mask
// for values that match the vertex topology, the crease curve's 1/6 2/3 1/6 or the value
// itself for the others), and at darts and interior valence-2 vertices until the point and
// its values move by <= the settle tolerance. The face-varying tags of the one-ring are those
// OpenSubdiv derives for it afresh, which are those its refinement propagates.
std::vector<Vertex3> localLimitFVar(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P,
                                    std::vector<Vertex3> const &FV, int v,
                                    Sdc::Options const &opts) {
    Cage c;
    std::vector<Vertex3> fv;
    int center = extractRingFV(lev, P, FV, v, c, fv);
    const int nfaces = lev.GetVertexFaces(v).size();
    std::vector<int> origin((size_t)nfaces);
    for (int i = 0; i < nfaces; i++) origin[(size_t)i] = i;
    const double scale = diagonal(c.pos), fscale = std::max(diagonal(fv), 1e-300);
    bool settled = false;
    for (int it = 0;; it++) {
        Far::TopologyRefiner *ref = createRefiner(c, opts);
        if (!ref || g_osdErrors) die("OpenSubdiv rejected a vertex one-ring");
        Far::TopologyLevel const &l0 = ref->GetLevel(0);
        const bool exact = !hasSemiSharp(l0, center) && facesAllQuads(l0, center) &&
                           (settled || !needsSettling(l0, center));
        if (it >= g_maxLevels) die("a face-varying limit did not settle in " + std::to_string(g_maxLevels) + " levels");
        Far::TopologyRefiner::UniformOptions uo(1);
        uo.fullTopologyInLastLevel = true;
        ref->RefineUniform(uo);
        if (g_osdErrors) die("OpenSubdiv refinement of a vertex one-ring failed");
        Far::TopologyLevel const &l1 = ref->GetLevel(1);
        std::vector<Vertex3> next((size_t)l1.GetNumVertices()), nfv((size_t)l1.GetNumFVarValues(0));
        Far::PrimvarRefinerReal<double> pr(*ref);
        pr.Interpolate(1, c.pos, next);
        pr.InterpolateFaceVarying(1, fv, nfv, 0);
        const int child = l0.GetVertexChildVertex(center);
        if (exact) { /* the limit of the vertex is that of its child one level finer (level >= 1) */
            std::vector<Vertex3> lim;
            limitFaceVaryingExact(*ref, nfv, lim);
            std::vector<Vertex3> out((size_t)nfaces);
            Far::ConstIndexArray cf = l1.GetVertexFaces(child);
            for (int i = 0; i < cf.size(); i++)
                out[(size_t)origin[(size_t)l1.GetFaceParentFace(cf[i])]] =
                    lim[(size_t)l1.GetFaceFVarValues(cf[i], 0)[cornerOf(l1, cf[i], child)]];
            delete ref;
            return out;
        }
        double d2 = 0.0, mag = 0.0, fmove = 0.0, fmag = 0.0;
        for (int k = 0; k < 3; k++) {
            const double d = next[(size_t)child].p[k] - c.pos[(size_t)center].p[k];
            d2 += d * d;
            mag = std::max(mag, std::fabs(next[(size_t)child].p[k]));
        }
        // the ring's faces one level finer, and the origin of each
        Far::ConstIndexArray cf = l1.GetVertexFaces(child);
        std::vector<int> norigin((size_t)cf.size());
        for (int i = 0; i < cf.size(); i++) { /* extractRingFV keeps this face order */
            const int parent = l1.GetFaceParentFace(cf[i]);
            norigin[(size_t)i] = origin[(size_t)parent];
            const Vertex3 &a = nfv[(size_t)l1.GetFaceFVarValues(cf[i], 0)[cornerOf(l1, cf[i], child)]];
            const Vertex3 &b = fv[(size_t)l0.GetFaceFVarValues(parent, 0)[cornerOf(l0, parent, center)]];
            for (int k = 0; k < 3; k++) {
                fmove = std::max(fmove, std::fabs(a.p[k] - b.p[k]));
                fmag = std::max(fmag, std::fabs(a.p[k]));
            }
        }
        settled = std::sqrt(d2) <= std::max(g_settle * scale, 4 * DBL_EPSILON * mag) &&
                  fmove <= std::max(g_settle * fscale, 4 * DBL_EPSILON * fmag);
        Cage nc;
        std::vector<Vertex3> nfvl;
        center = extractRingFV(l1, next, nfv, child, nc, nfvl);
        c = nc;
        fv.swap(nfvl);
        origin.swap(norigin);
        delete ref;
    }
}

}  // namespace osd_oracle
