// osd_refine: reference Catmull-Clark refinement with OpenSubdiv (test oracle).
//
//   osd_refine [--levels K] [--corners smooth|pinned] [--limit] in.obj out.obj
//
// Reads `v x y z` and `f a b c ...` lines (1-based, negative = relative, `a/b/c` tolerated,
// every other line ignored), refines uniformly K levels (default 1) with SCHEME_CATMARK,
// Sdc boundary interpolation EDGE_ONLY (smooth) or EDGE_AND_CORNER (pinned), default
// creasing, and writes the level-K mesh (`v` with %.17g, `f` 1-based). With --limit the `v`
// lines hold the limit positions of the level-K vertices instead. Positions are refined in
// double precision (PrimvarRefinerReal<double>, double mask weights).
// Level-K vertex order: OpenSubdiv "orderVerticesFromFacesFirst" (at each level face
// points, then edge points, then vertex points). Errors: message on stderr, exit 2.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
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
};

int g_osdErrors = 0;

void osdError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv error: %s\n", msg);
    g_osdErrors++;
}

void osdWarning(const char *msg) {
    std::fprintf(stderr, "osd_refine: OpenSubdiv warning: %s\n", msg);
}

[[noreturn]] void die(const std::string &msg) {
    std::fprintf(stderr, "osd_refine: %s\n", msg.c_str());
    std::exit(2);
}

void usage() {
    die("usage: osd_refine [--levels K] [--corners smooth|pinned] [--limit] in.obj out.obj");
}

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
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag)) continue;
        std::ostringstream where;
        where << path << ":" << lineNo << ": ";
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
                n++;
            }
            if (n < 3) {
                msg = where.str() + "face with fewer than 3 vertices";
                return false;
            }
            m.faceSizes.push_back(n);
        }
    }
    if (in.bad()) {
        msg = std::string("read error on ") + path;
        return false;
    }
    const int nv = (int)m.verts.size();
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
        }
        off += (size_t)n;
    }
    if (m.faceSizes.empty()) {
        msg = std::string(path) + ": no faces";
        return false;
    }
    return true;
}

}  // namespace

int main(int argc, char **argv) {
    int levels = 1;
    bool pinned = false, limit = false;
    const char *inPath = nullptr, *outPath = nullptr;
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--levels" && i + 1 < argc) {
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

    Far::SetErrorCallback(osdError);
    Far::SetWarningCallback(osdWarning);

    Mesh m;
    std::string msg;
    if (!readObj(inPath, m, msg)) die(msg);

    Sdc::Options sdcOpts;
    sdcOpts.SetVtxBoundaryInterpolation(pinned ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                               : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);

    Far::TopologyDescriptor desc;
    desc.numVertices = (int)m.verts.size();
    desc.numFaces = (int)m.faceSizes.size();
    desc.numVertsPerFace = m.faceSizes.data();
    desc.vertIndicesPerFace = m.faceVerts.data();

    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdcOpts));
    if (!refiner || g_osdErrors) die("OpenSubdiv rejected the topology");

    if (limit && levels == 0) {
        for (int s : m.faceSizes)
            if (s != 4) die("--limit with --levels 0 needs an all-quad mesh");
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
        Vertex3 const *src = cur.data();
        Vertex3 *dst = next.data();
        primvar.Interpolate(l, src, dst);
        cur.swap(next);
    }
    if (limit) {
        next.assign(cur.size(), Vertex3());
        Vertex3 const *src = cur.data();
        Vertex3 *dst = next.data();
        primvar.Limit(src, dst);
        cur.swap(next);
    }
    if (g_osdErrors) die("OpenSubdiv interpolation failed");

    Far::TopologyLevel const &lev = refiner->GetLevel(levels);
    FILE *out = std::fopen(outPath, "w");
    if (!out) die(std::string("cannot write ") + outPath + ": " + std::strerror(errno));
    std::fprintf(out, "# osd_refine: catmark, %d level(s), corners %s%s\n", levels,
                 pinned ? "pinned" : "smooth", limit ? ", limit positions" : "");
    for (size_t i = 0; i < cur.size(); i++)
        std::fprintf(out, "v %.17g %.17g %.17g\n", cur[i].p[0], cur[i].p[1], cur[i].p[2]);
    for (int f = 0; f < lev.GetNumFaces(); f++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(f);
        std::fputc('f', out);
        for (int i = 0; i < fv.size(); i++) std::fprintf(out, " %d", fv[i] + 1);
        std::fputc('\n', out);
    }
    if (std::fclose(out) != 0) die(std::string("write error on ") + outPath);
    delete refiner;
    return 0;
}
