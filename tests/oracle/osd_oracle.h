// Shared declarations of the osd_refine test oracle: osd_refine.cpp (main, refinement, exact
// limit) and osd_obj.cpp (the OBJ reader with its sharpness and option tags).
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

}  // namespace osd_oracle

#endif
