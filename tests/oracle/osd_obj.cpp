// osd_obj: the OBJ reader of the osd_refine test oracle (osd_oracle.h).
//
// Input. `v x y z` and `f a b c ...` lines (1-based, negative = relative, `a/b/c` tolerated),
// plus sharpness and options in either of two forms:
//   OpenSubdiv shape tags (regression/common/shape_utils.cpp Shape::tag::parseTag, applied as
//   in regression/common/far_utils.h GetSdcOptions / assignComponentTags):
//     t NAME nints/nfloats/nstrings int... float... string...
//     t crease 2k/1/0 a0 b0 ... a(k-1) b(k-1) s       k edges (0-based vertex pairs), one
//     t crease 2k/k/0 a0 b0 ... s0 ... s(k-1)          sharpness for all or one per edge
//     t corner k/1/0 v0 ... s  |  t corner k/k/0 v0 ... s0 ...   vertex sharpness
//     t interpolateboundary 1/0/0 m      m = 0 VTX_BOUNDARY_NONE, 1 EDGE_AND_CORNER,
//                                        2 EDGE_ONLY (far_utils.h; RenderMan's numbering)
//     t creasemethod 0/0/1 normal|chaikin   CREASE_UNIFORM | CREASE_CHAIKIN ("uniform" is
//                                        accepted as a synonym of "normal")
//     t facevaryinginterpolateboundary 1/0/0 m   m = 0..5: FVAR_LINEAR_NONE, CORNERS_ONLY,
//                                        CORNERS_PLUS1, CORNERS_PLUS2, BOUNDARIES, ALL; stored
//                                        in Sdc::Options (no effect on vertex data)
//     t smoothtriangles 0/0/1 catmark|smooth   TRI_SUB_CATMARK | TRI_SUB_SMOOTH
//   Other tags (hole, vertexedit, ...) are ignored with a warning on stderr. Sharpness is
//   clamped to >= 0 as OpenSubdiv does (std::max(0.0f, s)); a malformed tag is an error.
//   Differences from far_utils.h: with several sharpness values far_utils.h reads
//   floatargs[j] for the pair starting at int j (0, 2, 4, ...), which runs past the array;
//   here value k goes with pair k. No OpenSubdiv shape has more than one value per tag.
//   (RenderMan's crease tag lists a chain of vertices; OpenSubdiv's shapes use pairs.)
//   CCNURBS comments (1-based vertex indices, OpenSubdiv sharpness):
//     # crease i j s      edge i-j has sharpness s
//     # corner i s        vertex i has sharpness s
//   A comment whose word after crease/corner is not an integer is prose (OpenSubdiv's shapes
//   have "#  crease tags for perimeter:") and is ignored.
//   A later value for the same edge or vertex replaces an earlier one (as in OpenSubdiv).
//   A crease on a pair of vertices that is not an edge of a face is an error.
#include "osd_oracle.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace osd_oracle {

namespace {

bool parseLong(const std::string &tok, long &out) {
    char *end = nullptr;
    errno = 0;
    long x = std::strtol(tok.c_str(), &end, 10);
    if (end == tok.c_str() || *end != '\0' || errno) return false;
    out = x;
    return true;
}

bool parseDouble(const std::string &tok, double &out) {
    char *end = nullptr;
    errno = 0;
    double x = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0') return false;
    out = x;
    return true;
}

// OpenSubdiv clamps sharpness with std::max(0.0f, s), which also turns NaN into 0.
float clampSharpness(double s) {
    float f = (float)s;
    return std::max(0.0f, f);
}

// Parses a `t` line (tokens after "t"). Returns false with msg on a malformed tag.
bool parseTag(std::istringstream &ss, Mesh &m, const std::string &where, std::string &msg) {
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
bool parseComment(std::istringstream &ss, Mesh &m, const std::string &where, std::string &msg) {
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

}  // namespace

// Parses an OBJ file; returns false with msg set on error.
bool readObj(const char *path, Mesh &m, std::string &msg) {
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

}  // namespace osd_oracle
