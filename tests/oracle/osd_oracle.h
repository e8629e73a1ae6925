// Shared OpenSubdiv oracle code (test oracle): the OBJ reader with OpenSubdiv's shape tags and
// UV maps, refiner construction (with a face-varying channel), the exactness rules of
// PrimvarRefiner::Limit / LimitFaceVarying and the one-ring refinement that makes limits exact
// where they are not. Used by osd_refine.cpp (the command-line oracle) and fvar_oracle.cpp
// (face-varying channels of every regression shape in one process). See osd_refine.cpp for
// the input format and the exactness rules.
#ifndef CCN_TESTS_OSD_ORACLE_H
#define CCN_TESTS_OSD_ORACLE_H
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
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct Vertex3 {
    double p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Vertex3 const &s, double w) {
        p[0] += w * s.p[0];
        p[1] += w * s.p[1];
        p[2] += w * s.p[2];
    }
};

struct Mesh {
    std::vector<Vertex3> verts;
    std::vector<int> faceSizes;
    std::vector<int> faceVerts;
    // sharpness, 0-based; later entries replace earlier ones
    std::map<std::pair<int, int>, float> creases;  // key: (min, max) vertex
    std::map<int, float> corners;
    // options from tags (-1 = not given)
    int interpolateBoundary = -1;
    int fvarInterpolateBoundary = -1;
    int creaseMethod = -1;  // 0 normal, 1 chaikin
    int smoothTriangles = -1;
    // UV map: `vt` lines (up to 3 components, padded with 0) and each face corner's texture
    // index (0-based; -1 when the token has none)
    std::vector<Vertex3> uvs;
    int uvWidth = 0;
    std::vector<int> faceUVs;
    bool hasUV() const {
        if (uvs.empty() || faceUVs.empty()) return false;
        for (int t : faceUVs)
            if (t < 0) return false;
        return true;
    }
};

int g_osdErrors = 0;
double g_settle = 1e-16;  // environment OSD_REFINE_SETTLE overrides (for experiments)
int g_maxLevels = 120;

inline void osdError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv error: %s\n", msg);
    g_osdErrors++;
}

inline void osdWarning(const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv warning: %s\n", msg);
}

[[noreturn]] inline void die(const std::string &msg) {
    std::fprintf(stderr, "osd_refine: %s\n", msg.c_str());
    std::exit(2);
}

inline void usage() {
    die("usage: osd_refine [--levels K] [--corners smooth|pinned] "
        "[--limit | --limit-normals | --limit-osd] in.obj out.obj");
}

inline bool parseLong(const std::string &tok, long &out) {
    char *end = nullptr;
    errno = 0;
    long x = std::strtol(tok.c_str(), &end, 10);
    if (end == tok.c_str() || *end != '\0' || errno) return false;
    out = x;
    return true;
}

inline bool parseDouble(const std::string &tok, double &out) {
    char *end = nullptr;
    errno = 0;
    double x = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0') return false;
    out = x;
    return true;
}

// OpenSubdiv clamps sharpness with std::max(0.0f, s), which also turns NaN into 0.
inline float clampSharpness(double s) {
    float f = (float)s;
    return std::max(0.0f, f);
}

// Parses a `t` line (tokens after "t"). Returns false with msg on a malformed tag.
inline bool parseTag(std::istringstream &ss, Mesh &m, const std::string &where, std::string &msg) {
    std::string name, counts;
    if (!(ss >> name >> counts)) {
        msg = where + "tag needs a name and nints/nfloats/nstrings";
        return false;
    }
    long n[3] = {0, 0, 0};
    {
        std::vector<std::string> parts;
        std::string part;
        std::istringstream cs(counts);
        while (std::getline(cs, part, '/')) parts.push_back(part);
        if (parts.size() != 3) {
            msg = where + "tag counts must be nints/nfloats/nstrings, got '" + counts + "'";
            return false;
        }
        for (int k = 0; k < 3; k++)
            if (!parseLong(parts[k], n[k]) || n[k] < 0 || n[k] > 100000000L) {
                msg = where + "bad tag count '" + counts + "'";
                return false;
            }
    }
    std::vector<long> ints;
    std::vector<double> floats;
    std::vector<std::string> strings;
    std::string tok;
    for (long k = 0; k < n[0]; k++) {
        long x;
        if (!(ss >> tok) || !parseLong(tok, x)) {
            msg = where + "tag '" + name + "' needs " + std::to_string(n[0]) + " integers";
            return false;
        }
        ints.push_back(x);
    }
    for (long k = 0; k < n[1]; k++) {
        double x;
        if (!(ss >> tok) || !parseDouble(tok, x)) {
            msg = where + "tag '" + name + "' needs " + std::to_string(n[1]) + " numbers";
            return false;
        }
        floats.push_back(x);
    }
    for (long k = 0; k < n[2]; k++) {
        if (!(ss >> tok)) {
            msg = where + "tag '" + name + "' needs " + std::to_string(n[2]) + " strings";
            return false;
        }
        strings.push_back(tok);
    }
    if (ss >> tok) {
        msg = where + "tag '" + name + "' has extra value '" + tok + "'";
        return false;
    }
    auto oneInt = [&](long lo, long hi, int &dst) {
        if (ints.size() != 1 || ints[0] < lo || ints[0] > hi) {
            msg = where + "tag '" + name + "' needs one integer in " + std::to_string(lo) +
                  ".." + std::to_string(hi);
            return false;
        }
        dst = (int)ints[0];
        return true;
    };
    if (name == "crease") {
        const size_t pairs = ints.size() / 2;
        if (ints.size() < 2 || ints.size() % 2 || !(floats.size() == 1 || floats.size() == pairs)) {
            msg = where + "crease tag needs vertex pairs and one sharpness or one per pair";
            return false;
        }
        for (size_t k = 0; k < pairs; k++) {
            long a = ints[2 * k], b = ints[2 * k + 1];
            if (a < 0 || b < 0 || a > 2000000000L || b > 2000000000L || a == b) {
                msg = where + "bad crease edge " + std::to_string(a) + " " + std::to_string(b);
                return false;
            }
            m.creases[{(int)std::min(a, b), (int)std::max(a, b)}] =
                clampSharpness(floats.size() == 1 ? floats[0] : floats[k]);
        }
    } else if (name == "corner") {
        if (ints.empty() || !(floats.size() == 1 || floats.size() == ints.size())) {
            msg = where + "corner tag needs vertices and one sharpness or one per vertex";
            return false;
        }
        for (size_t k = 0; k < ints.size(); k++) {
            if (ints[k] < 0 || ints[k] > 2000000000L) {
                msg = where + "bad corner vertex " + std::to_string(ints[k]);
                return false;
            }
            m.corners[(int)ints[k]] = clampSharpness(floats.size() == 1 ? floats[0] : floats[k]);
        }
    } else if (name == "interpolateboundary") {
        return oneInt(0, 2, m.interpolateBoundary);
    } else if (name == "facevaryinginterpolateboundary") {
        return oneInt(0, 5, m.fvarInterpolateBoundary);
    } else if (name == "creasemethod") {
        if (strings.size() != 1 ||
            !(strings[0] == "normal" || strings[0] == "uniform" || strings[0] == "chaikin")) {
            msg = where + "creasemethod tag needs one string: normal (or uniform) or chaikin";
            return false;
        }
        m.creaseMethod = strings[0] == "chaikin" ? 1 : 0;
    } else if (name == "smoothtriangles") {
        if (strings.size() != 1 || !(strings[0] == "catmark" || strings[0] == "smooth")) {
            msg = where + "smoothtriangles tag needs one string: catmark or smooth";
            return false;
        }
        m.smoothTriangles = strings[0] == "smooth" ? 1 : 0;
    } else {
        std::fprintf(stderr, "osd_refine: warning: %signoring unsupported tag '%s'\n",
                     where.c_str(), name.c_str());
    }
    return true;
}

// "# crease i j s" / "# corner i s" (1-based). Other comments are ignored.
inline bool parseComment(std::istringstream &ss, Mesh &m, const std::string &where, std::string &msg) {
    std::string kw;
    if (!(ss >> kw)) return true;
    if (kw != "crease" && kw != "corner") return true;
    const int nInts = kw == "crease" ? 2 : 1;
    long idx[2] = {0, 0};
    double s = 0;
    std::string tok;
    // "# crease tags for perimeter:" (OpenSubdiv's shapes) is prose, not a statement
    if (!(ss >> tok) || !parseLong(tok, idx[0])) return true;
    for (int k = 0; k < nInts; k++) {
        if ((k > 0 && !(ss >> tok)) || !parseLong(tok, idx[k]) || idx[k] < 1 ||
            idx[k] > 2000000000L) {
            msg = where + "expected '# " + kw + (nInts == 2 ? " i j s" : " i s") +
                  "' with 1-based vertex indices";
            return false;
        }
    }
    if (!(ss >> tok) || !parseDouble(tok, s)) {
        msg = where + "expected a sharpness after '# " + kw + "'";
        return false;
    }
    if (nInts == 2) {
        if (idx[0] == idx[1]) {
            msg = where + "crease edge needs two different vertices";
            return false;
        }
        m.creases[{(int)std::min(idx[0], idx[1]) - 1, (int)std::max(idx[0], idx[1]) - 1}] =
            clampSharpness(s);
    } else {
        m.corners[(int)idx[0] - 1] = clampSharpness(s);
    }
    return true;
}

// Parses an OBJ file; returns false with msg set on error.
inline bool readObj(const char *path, Mesh &m, std::string &msg) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        msg = std::string("cannot open ") + path + ": " + std::strerror(errno);
        return false;
    }
    std::string line;
    long lineNo = 0;
    while (std::getline(in, line)) {
        lineNo++;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::ostringstream where;
        where << path << ":" << lineNo << ": ";
        size_t first = line.find_first_not_of(" \t");
        if (first != std::string::npos && line[first] == '#') {
            std::istringstream cs(line.substr(first + 1));
            if (!parseComment(cs, m, where.str(), msg)) return false;
            continue;
        }
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag)) continue;
        if (tag == "v") {
            Vertex3 v;
            for (int k = 0; k < 3; k++) {
                std::string tok;
                if (!(ss >> tok)) {
                    msg = where.str() + "vertex needs 3 coordinates";
                    return false;
                }
                char *end = nullptr;
                errno = 0;
                v.p[k] = std::strtod(tok.c_str(), &end);
                if (end == tok.c_str() || *end != '\0' || !std::isfinite(v.p[k])) {
                    msg = where.str() + "bad coordinate '" + tok + "'";
                    return false;
                }
            }
            m.verts.push_back(v);
        } else if (tag == "vt") {
            Vertex3 t;
            t.Clear();
            int k = 0;
            std::string tok;
            for (; k < 3 && (ss >> tok); k++) {
                char *end = nullptr;
                t.p[k] = std::strtod(tok.c_str(), &end);
                if (end == tok.c_str() || *end != '\0' || !std::isfinite(t.p[k])) {
                    msg = where.str() + "bad texture coordinate '" + tok + "'";
                    return false;
                }
            }
            if (k == 0) {
                msg = where.str() + "texture coordinate needs a number";
                return false;
            }
            m.uvWidth = std::max(m.uvWidth, k);
            m.uvs.push_back(t);
        } else if (tag == "f") {
            std::string tok;
            int n = 0;
            while (ss >> tok) {
                char *end = nullptr;
                errno = 0;
                long idx = std::strtol(tok.c_str(), &end, 10);
                if (end == tok.c_str() || (*end != '\0' && *end != '/') || errno) {
                    msg = where.str() + "bad face index '" + tok + "'";
                    return false;
                }
                long nv = (long)m.verts.size();
                if (idx < 0) idx = nv + idx + 1;  // relative index
                if (idx < 1 || idx > 2000000000L) {
                    msg = where.str() + "face index out of range '" + tok + "'";
                    return false;
                }
                m.faceVerts.push_back((int)(idx - 1));
                long uv = 0;  // texture index: the field after the first '/'
                if (*end == '/' && end[1] != '/' && end[1] != '\0') {
                    char *e2 = nullptr;
                    uv = std::strtol(end + 1, &e2, 10);
                    if (e2 == end + 1 || (*e2 != '\0' && *e2 != '/') || uv == 0) {
                        msg = where.str() + "bad texture index '" + tok + "'";
                        return false;
                    }
                    if (uv < 0) uv = (long)m.uvs.size() + uv + 1;
                }
                m.faceUVs.push_back((int)uv - 1);
                n++;
            }
            if (n < 3) {
                msg = where.str() + "face with fewer than 3 vertices";
                return false;
            }
            m.faceSizes.push_back(n);
        } else if (tag == "t") {
            if (!parseTag(ss, m, where.str(), msg)) return false;
        }
    }
    if (in.bad()) {
        msg = std::string("read error on ") + path;
        return false;
    }
    const int nv = (int)m.verts.size();
    std::set<std::pair<int, int>> edges;
    size_t off = 0;
    for (size_t f = 0; f < m.faceSizes.size(); f++) {
        const int n = m.faceSizes[f];
        for (int i = 0; i < n; i++) {
            const int a = m.faceVerts[off + i];
            if (a >= nv) {
                msg = std::string(path) + ": face " + std::to_string(f + 1) +
                      " references vertex " + std::to_string(a + 1) + " of " +
                      std::to_string(nv);
                return false;
            }
            for (int j = i + 1; j < n; j++) {
                if (m.faceVerts[off + j] == a) {
                    msg = std::string(path) + ": face " + std::to_string(f + 1) +
                          " repeats vertex " + std::to_string(a + 1);
                    return false;
                }
            }
            const int b = m.faceVerts[off + (i + 1) % n];
            edges.insert({std::min(a, b), std::max(a, b)});
        }
        off += (size_t)n;
    }
    if (m.faceSizes.empty()) {
        msg = std::string(path) + ": no faces";
        return false;
    }
    for (int t : m.faceUVs)
        if (t >= (int)m.uvs.size() && !m.uvs.empty()) {
            msg = std::string(path) + ": texture index " + std::to_string(t + 1) + " of " +
                  std::to_string(m.uvs.size()) + " vt lines";
            return false;
        }
    for (auto const &c : m.creases) {
        if (!edges.count(c.first)) {
            msg = std::string(path) + ": crease on vertices " + std::to_string(c.first.first) +
                  " " + std::to_string(c.first.second) +
                  " (0-based) which are not joined by an edge";
            return false;
        }
    }
    for (auto const &c : m.corners) {
        if (c.first >= nv) {
            msg = std::string(path) + ": corner on vertex " + std::to_string(c.first) +
                  " (0-based) of " + std::to_string(nv);
            return false;
        }
    }
    return true;
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
    // face-varying channel (one value index per face corner; none when fvValues is 0)
    int fvValues = 0;
    std::vector<int> fvIndices;
};

inline Far::TopologyRefiner *createRefiner(Cage const &c, Sdc::Options const &opts) {
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

inline bool isSemiSharp(float s) { return s > 0.0f && s < Sdc::Crease::SHARPNESS_INFINITE; }

inline bool isSmoothRule(Sdc::Crease::Rule r) {
    return r == Sdc::Crease::RULE_SMOOTH || r == Sdc::Crease::RULE_DART;
}

// Interior vertex of two faces with the smooth or dart rule: Limit() uses the corner mask.
inline bool isInteriorValence2(Far::TopologyLevel const &lev, int v) {
    return !lev.IsVertexBoundary(v) && lev.GetVertexFaces(v).size() == 2 &&
           isSmoothRule(lev.GetVertexRule(v));
}

inline bool hasSemiSharp(Far::TopologyLevel const &lev, int v) {
    if (isSemiSharp(lev.GetVertexSharpness(v))) return true;
    Far::ConstIndexArray ve = lev.GetVertexEdges(v);
    for (int i = 0; i < ve.size(); i++)
        if (isSemiSharp(lev.GetEdgeSharpness(ve[i]))) return true;
    return false;
}

inline bool facesAllQuads(Far::TopologyLevel const &lev, int v) {
    Far::ConstIndexArray vf = lev.GetVertexFaces(v);
    for (int i = 0; i < vf.size(); i++)
        if (lev.GetFaceVertices(vf[i]).size() != 4) return false;
    return true;
}

// Limit() uses the smooth mask at a dart, but the dart's sharp edge refines with the crease
// rule, so the mask is not that of the vertex's refinement matrix; at an interior valence-2
// vertex Limit() uses the corner mask. Both need refining until the point settles.
inline bool needsSettling(Far::TopologyLevel const &lev, int v) {
    return isInteriorValence2(lev, v) || lev.GetVertexRule(v) == Sdc::Crease::RULE_DART;
}

// Does Limit() at this level give the exact limit of vertex v? (see the header)
inline bool limitMaskExact(Far::TopologyLevel const &lev, int v) {
    return !hasSemiSharp(lev, v) && !needsSettling(lev, v) && facesAllQuads(lev, v);
}

// Whether Tan1 x Tan2 of Limit() is the surface normal at v (see the header); the rule is
// final there (limitMaskExact, or valence 2 refined to convergence).
inline bool normalDefined(Far::TopologyLevel const &lev, int v, Sdc::Options const &opts) {
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

inline double diagonal(std::vector<Vertex3> const &p) {
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
inline int extractRing(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P, int v, Cage &c) {
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
inline LimitPoint localLimit(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P, int v,
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

inline Vertex3 unitNormal(Vertex3 const &a, Vertex3 const &b) {
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

inline const char *boundaryName(Sdc::Options::VtxBoundaryInterpolation b) {
    switch (b) {
    case Sdc::Options::VTX_BOUNDARY_NONE: return "none";
    case Sdc::Options::VTX_BOUNDARY_EDGE_ONLY: return "edge-only";
    case Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER: return "edge-and-corner";
    }
    return "?";
}

// ---- face-varying channels -------------------------------------------------------------

// The faces around vertex v of level lev as a Cage (extractRing) with their face-varying
// values (channel 0 of lev, values FV) as a local channel; fv receives the local values.
inline int extractRingFV(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P,
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

// Index of vertex v in face f of level lev.
inline int cornerOf(Far::TopologyLevel const &lev, int f, int v) {
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
inline void limitFaceVaryingExact(Far::TopologyRefiner const &r, std::vector<Vertex3> const &fv,
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
inline std::vector<Vertex3> localLimitFVar(Far::TopologyLevel const &lev, std::vector<Vertex3> const &P,
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

// OpenSubdiv's level-K faces in ccnurbs' order (ccnurbs.h: "faces: each old face's sub-quads
// in corner order", the sub-quad of corner j starting at the vertex's child): ours[f] is the
// ccnurbs index of OpenSubdiv face f, rot[f] the OpenSubdiv corner of ccnurbs corner 0
// (OpenSubdiv corner k = ccnurbs corner (k - rot) mod n). From the topology only.
inline void ccnurbsFaceOrder(Far::TopologyRefiner const &r, int K, std::vector<int> &ours,
                             std::vector<int> &rot) {
    Far::TopologyLevel const &b = r.GetLevel(0);
    ours.resize((size_t)b.GetNumFaces());
    rot.assign((size_t)b.GetNumFaces(), 0);
    std::vector<int> start((size_t)b.GetNumFaces());
    int acc = 0;
    for (int f = 0; f < b.GetNumFaces(); f++) {
        ours[(size_t)f] = f;
        start[(size_t)f] = acc;
        acc += b.GetFaceVertices(f).size();
    }
    for (int l = 0; l < K; l++) {
        Far::TopologyLevel const &p = r.GetLevel(l), &c = r.GetLevel(l + 1);
        std::vector<int> nours((size_t)c.GetNumFaces(), -1), nrot((size_t)c.GetNumFaces(), 0);
        for (int f = 0; f < p.GetNumFaces(); f++) {
            Far::ConstIndexArray kids = p.GetFaceChildFaces(f);
            Far::ConstIndexArray pv = p.GetFaceVertices(f);
            const int n = pv.size();
            for (int i = 0; i < kids.size(); i++) {
                const int vc = p.GetVertexChildVertex(pv[i]);
                Far::ConstIndexArray cv = c.GetFaceVertices(kids[i]);
                int a = 0;
                while (a < cv.size() && cv[a] != vc) a++;
                if (a == cv.size()) die("child face i does not hold the child of corner i");
                const int j = ((i - rot[(size_t)f]) % n + n) % n;
                nours[(size_t)kids[i]] = (l == 0 ? start[(size_t)ours[(size_t)f]] : 4 * ours[(size_t)f]) + j;
                nrot[(size_t)kids[i]] = a;
            }
        }
        ours.swap(nours);
        rot.swap(nrot);
    }
}

}  // namespace

#endif
