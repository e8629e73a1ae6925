// osd_refine: reference Catmull-Clark refinement with OpenSubdiv (test oracle).
//
//   osd_refine [--levels K] [--corners smooth|pinned] [--limit | --limit-normals | --limit-osd |
//              --patch-limit [--isolation N] [--inf-sharp-patch 0|1] [--single-crease-patch 0|1]
//              [--endcap gregory|bspline]] in.obj out.obj
//
// Input: OBJ with OpenSubdiv shape tags or CCNURBS sharpness comments (osd_obj.cpp).
// Options. Boundary interpolation is EDGE_ONLY (--corners smooth, the default) or
// EDGE_AND_CORNER (--corners pinned) unless the file has an interpolateboundary tag, which
// then wins over --corners. Creasing is CREASE_UNIFORM unless creasemethod says chaikin.
// Output. The level-K mesh (`v` with %.17g, `f` 1-based), K = --levels (default 1), refined
// uniformly with SCHEME_CATMARK in double precision (PrimvarRefinerReal<double>).
//   --limit: the `v` lines hold the exact limit positions of the level-K vertices.
//     PrimvarRefiner::Limit applies the limit mask of each vertex's rule at the level it is
//     called on, which is exact only where that mask belongs to the vertex's refinement
//     matrix for all later levels. It is not where an edge or vertex with sharpness
//     0 < s < 10 is left at level K (the mask treats it as infinitely sharp), at a dart (the
//     smooth mask, but the dart's sharp edge refines with the crease rule) and at an
//     interior valence-2 vertex (the corner mask: the point itself). For such a vertex this
//     tool takes the vertex's one-ring of faces (positions, edge and vertex sharpness),
//     refines it one level with the same options, takes the child vertex's one-ring, and so
//     on: until no semi-sharp value is left around it (the mask is then exact), and at a dart
//     or valence-2 vertex until the point moves by <= 1e-16 of the level-K one-ring's size
//     or 4 ulps of its coordinates (the environment variable OSD_REFINE_SETTLE changes
//     1e-16; at most 120 levels). A
//     vertex's next one-ring depends only on its one-ring and the sharpness of its edges,
//     so nothing else is needed. Checked: equal (<= 2e-16 of the bounding box) to
//     PrimvarRefiner::Limit after refining the whole mesh past every semi-sharp value.
//     A vertex of a non-quad face (--levels 0) is refined the same way, so --limit works at
//     level 0 on any mesh.
//   --limit-normals: --limit plus `vn` lines (one per `v`, unit length): the normalised
//     cross product Tan1 x Tan2 of PrimvarRefiner::Limit, only where those tangents span the
//     exact tangent plane: interior smooth vertices of valence >= 3 (eigenvector masks),
//     regular boundary vertices (2 faces: the B-spline cross tangent) and sharp corners of one
//     face (the two boundary curves' end tangents). Everywhere else the line is `vn 0 0 0`
//     (undefined): interior crease vertices and corners of several faces (two or more
//     tangent planes; Tan2 is one side's), darts (smooth masks, not the dart's), interior
//     valence-2 vertices (chords of the two edges), smooth corners (average of the two
//     boundary chords), boundary vertices of 3 or more faces (Biermann et al.'s masks, not
//     those of these rules: they differ from deep refinement by up to 1e-2), and boundary
//     vertices under interpolateboundary 0.
//   --limit-osd: plain PrimvarRefiner::Limit at level K (OpenSubdiv's own approximation
//     described above), for comparison.
//   --patch-limit: the level-K vertices evaluated on OpenSubdiv's adaptive patch table
//     (Far::PatchTableFactory, Far::PatchMap, PatchTable::EvaluateBasis at each vertex's
//     ptex face (u, v)) as Blender's Subdivision Surface does with Use Limit Surface; the
//     defaults are Blender's (isolation 10 = Quality 10, infinitely sharp patches, no
//     single-crease patches, Gregory basis end caps). Not the exact limit near irregular
//     features: see osd_patch.cpp.
// Level-K vertex order: OpenSubdiv "orderVerticesFromFacesFirst" (at each level face
// points, then edge points, then vertex points). Errors: message on stderr, exit 2.
#include "osd_oracle.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace OpenSubdiv;
using namespace osd_oracle;

namespace osd_oracle {

int g_osdErrors = 0;

[[noreturn]] void die(const std::string &msg) {
    std::fprintf(stderr, "osd_refine: %s\n", msg.c_str());
    std::exit(2);
}

}  // namespace osd_oracle

namespace {

double g_settle = 1e-16;  // environment OSD_REFINE_SETTLE overrides (for experiments)
int g_maxLevels = 120;

void osdError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv error: %s\n", msg);
    g_osdErrors++;
}

void osdWarning(const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv warning: %s\n", msg);
}

void usage() {
    die("usage: osd_refine [--levels K] [--corners smooth|pinned] "
        "[--limit | --limit-normals | --limit-osd | --patch-limit [--isolation N] "
        "[--inf-sharp-patch 0|1] [--single-crease-patch 0|1] [--endcap gregory|bspline]] "
        "in.obj out.obj");
}

typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;

// A mesh with its sharpness, ready for a TopologyDescriptor.
struct Cage {
    std::vector<Vertex3> pos;
    std::vector<int> faceSizes, faceVerts;
    std::vector<int> creasePairs;
    std::vector<float> creaseWeights;
    std::vector<int> cornerVerts;
    std::vector<float> cornerWeights;
};

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
    return Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, opts));
}

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

struct LimitPoint {
    Vertex3 pos, tan1, tan2;
    bool normalOk;
};

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

Vertex3 unitNormal(Vertex3 const &a, Vertex3 const &b) {
    Vertex3 n;
    n.p[0] = a.p[1] * b.p[2] - a.p[2] * b.p[1];
    n.p[1] = a.p[2] * b.p[0] - a.p[0] * b.p[2];
    n.p[2] = a.p[0] * b.p[1] - a.p[1] * b.p[0];
    const double len = std::sqrt(n.p[0] * n.p[0] + n.p[1] * n.p[1] + n.p[2] * n.p[2]);
    if (!(len > 0.0) || !std::isfinite(len)) {
        n.Clear();
        return n;
    }
    for (int k = 0; k < 3; k++) n.p[k] /= len;
    return n;
}

const char *boundaryName(Sdc::Options::VtxBoundaryInterpolation b) {
    switch (b) {
    case Sdc::Options::VTX_BOUNDARY_NONE: return "none";
    case Sdc::Options::VTX_BOUNDARY_EDGE_ONLY: return "edge-only";
    case Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER: return "edge-and-corner";
    }
    return "?";
}

}  // namespace

int main(int argc, char **argv) {
    int levels = 1;
    bool pinned = false, limit = false, normals = false, limitOsd = false, patch = false;
    bool patchOpt = false;  // a --patch-limit setting was given
    PatchOptions po;
    const char *inPath = nullptr, *outPath = nullptr;
    auto flag = [&](const char *name, const char *v) {
        const std::string s = v;
        if (s != "0" && s != "1") die(std::string(name) + " must be 0 or 1");
        patchOpt = true;
        return s == "1";
    };
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--isolation" && i + 1 < argc) {
            char *end = nullptr;
            long k = std::strtol(argv[++i], &end, 10);
            if (*argv[i] == '\0' || *end != '\0' || k < 1 || k > 10)
                die("--isolation must be 1..10");
            po.isolation = (int)k;
            patchOpt = true;
        } else if (a == "--inf-sharp-patch" && i + 1 < argc) {
            po.infSharpPatch = flag("--inf-sharp-patch", argv[++i]);
        } else if (a == "--single-crease-patch" && i + 1 < argc) {
            po.singleCreasePatch = flag("--single-crease-patch", argv[++i]);
        } else if (a == "--endcap" && i + 1 < argc) {
            const std::string c = argv[++i];
            if (c != "gregory" && c != "bspline") die("--endcap must be gregory or bspline");
            po.bsplineEndCaps = c == "bspline";
            patchOpt = true;
        } else if (a == "--patch-limit") {
            patch = true;
        } else if (a == "--levels" && i + 1 < argc) {
            char *end = nullptr;
            long k = std::strtol(argv[++i], &end, 10);
            if (*argv[i] == '\0' || *end != '\0' || k < 0 || k > 10) die("--levels must be 0..10");
            levels = (int)k;
        } else if (a == "--corners" && i + 1 < argc) {
            const std::string c = argv[++i];
            if (c == "smooth") pinned = false;
            else if (c == "pinned") pinned = true;
            else die("--corners must be smooth or pinned");
        } else if (a == "--limit") {
            limit = true;
        } else if (a == "--limit-normals") {
            limit = normals = true;
        } else if (a == "--limit-osd") {
            limit = limitOsd = true;
        } else if (a.size() > 1 && a[0] == '-') {
            usage();
        } else if (!inPath) {
            inPath = argv[i];
        } else if (!outPath) {
            outPath = argv[i];
        } else {
            usage();
        }
    }
    if (!inPath || !outPath) usage();
    if (limitOsd && normals) die("--limit-osd and --limit-normals exclude each other");
    if (patch && limit) die("--patch-limit excludes --limit, --limit-normals and --limit-osd");
    if (patchOpt && !patch) die("--isolation, --inf-sharp-patch, --single-crease-patch and "
                                "--endcap need --patch-limit");

    if (const char *e = std::getenv("OSD_REFINE_SETTLE")) g_settle = std::atof(e);
    Far::SetErrorCallback(osdError);
    Far::SetWarningCallback(osdWarning);

    Mesh m;
    std::string msg;
    if (!readObj(inPath, m, msg)) die(msg);

    Sdc::Options sdcOpts;
    sdcOpts.SetVtxBoundaryInterpolation(pinned ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                               : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    if (m.interpolateBoundary >= 0) {
        static const Sdc::Options::VtxBoundaryInterpolation ib[3] = {
            Sdc::Options::VTX_BOUNDARY_NONE, Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER,
            Sdc::Options::VTX_BOUNDARY_EDGE_ONLY};
        sdcOpts.SetVtxBoundaryInterpolation(ib[m.interpolateBoundary]);
    }
    if (m.fvarInterpolateBoundary >= 0) {
        static const Sdc::Options::FVarLinearInterpolation fv[6] = {
            Sdc::Options::FVAR_LINEAR_NONE,          Sdc::Options::FVAR_LINEAR_CORNERS_ONLY,
            Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1, Sdc::Options::FVAR_LINEAR_CORNERS_PLUS2,
            Sdc::Options::FVAR_LINEAR_BOUNDARIES,    Sdc::Options::FVAR_LINEAR_ALL};
        sdcOpts.SetFVarLinearInterpolation(fv[m.fvarInterpolateBoundary]);
    }
    sdcOpts.SetCreasingMethod(m.creaseMethod == 1 ? Sdc::Options::CREASE_CHAIKIN
                                                  : Sdc::Options::CREASE_UNIFORM);
    sdcOpts.SetTriangleSubdivision(m.smoothTriangles == 1 ? Sdc::Options::TRI_SUB_SMOOTH
                                                          : Sdc::Options::TRI_SUB_CATMARK);

    Cage base;
    base.pos = m.verts;
    base.faceSizes = m.faceSizes;
    base.faceVerts = m.faceVerts;
    for (auto const &c : m.creases) {
        if (!(c.second > 0.0f)) continue;
        base.creasePairs.push_back(c.first.first);
        base.creasePairs.push_back(c.first.second);
        base.creaseWeights.push_back(c.second);
    }
    for (auto const &c : m.corners) {
        if (!(c.second > 0.0f)) continue;
        base.cornerVerts.push_back(c.first);
        base.cornerWeights.push_back(c.second);
    }
    Far::TopologyRefiner *refiner = createRefiner(base, sdcOpts);
    if (!refiner || g_osdErrors) die("OpenSubdiv rejected the topology");

    if (limitOsd && levels == 0) {
        for (int s : m.faceSizes)
            if (s != 4) die("--limit-osd with --levels 0 needs an all-quad mesh");
    }
    if (levels > 0) {
        Far::TopologyRefiner::UniformOptions uo(levels);
        uo.orderVerticesFromFacesFirst = true;
        uo.fullTopologyInLastLevel = true;
        refiner->RefineUniform(uo);
        if (g_osdErrors) die("OpenSubdiv refinement failed");
    }

    Far::PrimvarRefinerReal<double> primvar(*refiner);
    std::vector<Vertex3> cur = m.verts, next;
    for (int l = 1; l <= levels; l++) {
        next.assign((size_t)refiner->GetLevel(l).GetNumVertices(), Vertex3());
        primvar.Interpolate(l, cur, next);
        cur.swap(next);
    }
    Far::TopologyLevel const &lev = refiner->GetLevel(levels);
    std::vector<Vertex3> nrm;
    int nLocal = 0, nNoNormal = 0;
    if (limit) {
        std::vector<Vertex3> pos(cur.size()), t1(cur.size()), t2(cur.size());
        primvar.Limit(cur, pos, t1, t2);
        if (g_osdErrors) die("OpenSubdiv Limit failed");
        if (normals) nrm.assign(cur.size(), Vertex3());
        for (int v = 0; v < (int)cur.size(); v++) {
            bool ok;
            if (limitOsd || limitMaskExact(lev, v)) {
                ok = normalDefined(lev, v, sdcOpts);
            } else {
                LimitPoint lp = localLimit(lev, cur, v, sdcOpts);
                pos[(size_t)v] = lp.pos;
                t1[(size_t)v] = lp.tan1;
                t2[(size_t)v] = lp.tan2;
                ok = lp.normalOk;
                nLocal++;
            }
            if (normals) {
                if (ok) nrm[(size_t)v] = unitNormal(t1[(size_t)v], t2[(size_t)v]);
                else nrm[(size_t)v].Clear();
                const Vertex3 &n = nrm[(size_t)v];
                if (n.p[0] == 0.0 && n.p[1] == 0.0 && n.p[2] == 0.0) nNoNormal++;
            }
        }
        cur.swap(pos);
    }
    PatchStats ps;
    if (patch) {
        std::unique_ptr<Far::TopologyRefiner> adaptive(createRefiner(base, sdcOpts));
        if (!adaptive || g_osdErrors) die("OpenSubdiv rejected the topology");
        cur = patchLimit(*refiner, levels, *adaptive, m.verts, po, ps);
    }
    if (g_osdErrors) die("OpenSubdiv interpolation failed");

    FILE *out = std::fopen(outPath, "w");
    if (!out) die(std::string("cannot write ") + outPath + ": " + std::strerror(errno));
    std::fprintf(out,
                 "# osd_refine: catmark, %d level(s), boundary %s%s, creasing %s, %d crease(s), "
                 "%d corner(s)%s",
                 levels, boundaryName(sdcOpts.GetVtxBoundaryInterpolation()),
                 m.interpolateBoundary >= 0 ? " (file tag)" : "",
                 m.creaseMethod == 1 ? "chaikin" : "uniform", (int)base.creaseWeights.size(),
                 (int)base.cornerWeights.size(), m.smoothTriangles == 1 ? ", smooth triangles" : "");
    if (m.fvarInterpolateBoundary >= 0)
        std::fprintf(out, ", fvar boundary %d", m.fvarInterpolateBoundary);
    if (limitOsd) std::fprintf(out, ", PrimvarRefiner::Limit positions");
    else if (limit) std::fprintf(out, ", limit positions (%d by one-ring refinement)", nLocal);
    if (normals) std::fprintf(out, ", normals (%d undefined: 0 0 0)", nNoNormal);
    if (patch)
        std::fprintf(out,
                     ", patch-table limit (isolation %d, inf-sharp patches %s, single-crease "
                     "patches %s, %s end caps; %d levels, %d regular, %d Gregory basis, %d other "
                     "patches, %d local points)",
                     po.isolation, po.infSharpPatch ? "on" : "off",
                     po.singleCreasePatch ? "on" : "off",
                     po.bsplineEndCaps ? "B-spline basis" : "Gregory basis", ps.maxLevel,
                     ps.regular, ps.gregoryBasis, ps.other, ps.localPoints);
    std::fputc('\n', out);
    for (size_t i = 0; i < cur.size(); i++)
        std::fprintf(out, "v %.17g %.17g %.17g\n", cur[i].p[0], cur[i].p[1], cur[i].p[2]);
    for (size_t i = 0; i < nrm.size(); i++)
        std::fprintf(out, "vn %.17g %.17g %.17g\n", nrm[i].p[0], nrm[i].p[1], nrm[i].p[2]);
    for (int f = 0; f < lev.GetNumFaces(); f++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(f);
        std::fputc('f', out);
        for (int i = 0; i < fv.size(); i++) {
            if (normals) std::fprintf(out, " %d//%d", fv[i] + 1, fv[i] + 1);
            else std::fprintf(out, " %d", fv[i] + 1);
        }
        std::fputc('\n', out);
    }
    if (std::fclose(out) != 0) die(std::string("write error on ") + outPath);
    delete refiner;
    return 0;
}
