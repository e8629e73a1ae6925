// Shared declarations of the osd_refine test oracle: osd_refine.cpp (main, refinement, exact
// limit), osd_obj.cpp (the OBJ reader with its sharpness and option tags) and osd_patch.cpp
// (--patch-limit: OpenSubdiv's adaptive patch table evaluated as Blender's Subdivision
// Surface does).
#ifndef CCNURBS_OSD_ORACLE_H
#define CCNURBS_OSD_ORACLE_H

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
};

// Parses an OBJ file (format: osd_obj.cpp); returns false with msg set on error.
bool readObj(const char *path, Mesh &m, std::string &msg);

// Message on stderr, exit 2 (osd_refine.cpp).
[[noreturn]] void die(const std::string &msg);

// Errors reported by OpenSubdiv's callback so far (osd_refine.cpp).
extern int g_osdErrors;

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
