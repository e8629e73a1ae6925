// OpenSubdiv uniform refinement benchmark: topology refinement and primvar interpolation
// of the same OBJ cage, min time over repeats. Prints "osd <file> L<k>: topology T s,
// points P s, limit Q s" (limit = PrimvarRefiner::Limit with tangents at the last level).
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;

struct Vtx {
    double p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(const Vtx &s, double w) { for (int k = 0; k < 3; k++) p[k] += w * s.p[k]; }
};

static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int main(int argc, char **argv) {
    if (argc < 3) { std::fprintf(stderr, "usage: osd_bench in.obj levels [repeats]\n"); return 2; }
    int levels = std::atoi(argv[2]), reps = argc > 3 ? std::atoi(argv[3]) : 5;
    std::ifstream in(argv[1]);
    std::vector<Vtx> verts;
    std::vector<int> sizes, idx;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string t;
        ss >> t;
        if (t == "v") { Vtx v; ss >> v.p[0] >> v.p[1] >> v.p[2]; verts.push_back(v); }
        else if (t == "f") {
            int n = 0; std::string w;
            while (ss >> w) { idx.push_back(std::atoi(w.c_str()) - 1); n++; }
            sizes.push_back(n);
        }
    }
    Sdc::Options opt;
    opt.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    Far::TopologyDescriptor desc;
    desc.numVertices = (int)verts.size();
    desc.numFaces = (int)sizes.size();
    desc.numVertsPerFace = sizes.data();
    desc.vertIndicesPerFace = idx.data();
    double ttopo = 1e30, tpts = 1e30, tlim = 1e30;
    size_t nout = 0;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        Far::TopologyRefiner *ref = Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
            desc, Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK, opt));
        Far::TopologyRefiner::UniformOptions uo(levels);
        uo.fullTopologyInLastLevel = true;
        ref->RefineUniform(uo);
        double t1 = now();
        std::vector<Vtx> buf(ref->GetNumVerticesTotal());
        std::copy(verts.begin(), verts.end(), buf.begin());
        Far::PrimvarRefinerReal<double> pr(*ref);
        Vtx *src = buf.data();
        for (int l = 1; l <= levels; l++) {
            Vtx *dst = src + ref->GetLevel(l - 1).GetNumVertices();
            pr.Interpolate(l, src, dst);
            src = dst;
        }
        double t2 = now();
        size_t nl = ref->GetLevel(levels).GetNumVertices();
        std::vector<Vtx> lim(nl), du(nl), dv(nl);
        Vtx *lp = lim.data(), *dup = du.data(), *dvp = dv.data();
        pr.Limit(src, lp, dup, dvp); /* positions and tangents, as we compute normals */
        double t3 = now();
        nout = lim.size();
        if (t1 - t0 < ttopo) ttopo = t1 - t0;
        if (t2 - t1 < tpts) tpts = t2 - t1;
        if (t3 - t2 < tlim) tlim = t3 - t2;
        delete ref;
    }
    std::printf("osd %s L%d: %zu verts; topology %.4f s, points %.4f s, limit %.4f s\n", argv[1], levels,
                nout, ttopo, tpts, tlim);
    return 0;
}
