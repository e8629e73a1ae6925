// Shared declarations of the OpenSubdiv test oracles: osd_refine.cpp (osd_refine's main and
// refinement), osd_limit.cpp (refiner construction and the exact limits of vertices and of
// face-varying values), osd_obj.cpp (the OBJ reader with its sharpness and option tags and
// UV maps) and osd_patch.cpp (--patch-limit: OpenSubdiv's adaptive patch table evaluated as
// Blender's Subdivision Surface does). fvar_oracle.cpp (ccnurbs' face-varying channels against
// OpenSubdiv in one process) links osd_limit.cpp and osd_obj.cpp.
#ifndef CCNURBS_OSD_ORACLE_H
#define CCNURBS_OSD_ORACLE_H

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace osd_oracle {

struct Vertex3 {
    double p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Vertex3 const &s, double w) {
        p[0] += w * s.p[0];
        p[1] += w * s.p[1];
        p[2] += w * s.p[2];
    }
};

// The input file: positions, faces, sharpness and option tags (osd_obj.cpp).
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

// Parses an OBJ file (format: osd_obj.cpp); returns false with msg set on error.
bool readObj(const char *path, Mesh &m, std::string &msg);

// Message on stderr, exit 2 (osd_limit.cpp, as the rest of this block).
[[noreturn]] void die(const std::string &msg);

// Errors reported by OpenSubdiv's callback so far (osdError counts them).
extern int g_osdErrors;
void osdError(OpenSubdiv::Far::ErrorType, const char *msg);
void osdWarning(const char *msg);

// The settle tolerance of the one-ring refinement (osd_refine.cpp's header; default 1e-16).
extern double g_settle;

// A mesh with its sharpness and at most one face-varying channel, ready for a
// TopologyDescriptor.
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

OpenSubdiv::Far::TopologyRefiner *createRefiner(Cage const &c, OpenSubdiv::Sdc::Options const &opts);

// Does PrimvarRefiner::Limit at this level give the exact limit of vertex v? (osd_refine.cpp's
// header: not with semi-sharp values around v, at darts, interior valence-2 vertices and
// vertices of non-quads)
bool limitMaskExact(OpenSubdiv::Far::TopologyLevel const &lev, int v);
// Whether Tan1 x Tan2 of Limit() is the surface normal at v (osd_refine.cpp's header).
bool normalDefined(OpenSubdiv::Far::TopologyLevel const &lev, int v,
                   OpenSubdiv::Sdc::Options const &opts);

struct LimitPoint {
    Vertex3 pos, tan1, tan2;
    bool normalOk;
};

// Exact limit of vertex v of level lev (positions P) by refining its one-ring.
LimitPoint localLimit(OpenSubdiv::Far::TopologyLevel const &lev, std::vector<Vertex3> const &P,
                      int v, OpenSubdiv::Sdc::Options const &opts);

// Index of vertex v in face f of level lev.
int cornerOf(OpenSubdiv::Far::TopologyLevel const &lev, int f, int v);

// Exact limits of the face-varying values fv (channel 0) at the last level of r, which must be
// refined (PrimvarRefiner::LimitFaceVarying with the crease weights in double precision;
// exact where limitMaskExact holds).
void limitFaceVaryingExact(OpenSubdiv::Far::TopologyRefiner const &r,
                           std::vector<Vertex3> const &fv, std::vector<Vertex3> &lim);

// Exact limit of the face-varying values at vertex v of level lev (positions P, values FV of
// channel 0), one per face of v in GetVertexFaces order, by refining its one-ring.
std::vector<Vertex3> localLimitFVar(OpenSubdiv::Far::TopologyLevel const &lev,
                                    std::vector<Vertex3> const &P, std::vector<Vertex3> const &FV,
                                    int v, OpenSubdiv::Sdc::Options const &opts);

// --patch-limit settings (osd_patch.cpp). Defaults are Blender's.
struct PatchOptions {
    int isolation = 10;         // Subdivision Surface's Quality
    bool infSharpPatch = true;  // Blender: always
    bool singleCreasePatch = false;
    bool bsplineEndCaps = false;  // false: ENDCAP_GREGORY_BASIS (Blender), true: BSPLINE_BASIS
};

// What the patch table held, for the output's comment line.
struct PatchStats {
    int maxLevel = 0;
    int regular = 0, gregoryBasis = 0, other = 0;
    int localPoints = 0;
};

// Positions of the vertices of level `levels` of `uniform` (uniformly refined to that level,
// any vertex order) evaluated on the patch table of `adaptive` (an unrefined refiner of the
// same cage) at their ptex coordinates; basePos are the cage positions.
std::vector<Vertex3> patchLimit(OpenSubdiv::Far::TopologyRefiner const &uniform, int levels,
                                OpenSubdiv::Far::TopologyRefiner &adaptive,
                                std::vector<Vertex3> const &basePos, PatchOptions const &opts,
                                PatchStats &stats);

}  // namespace osd_oracle

#endif
