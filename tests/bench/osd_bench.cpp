// OpenSubdiv benchmark on an OBJ cage, min time over repeats.
//   osd_bench in.obj L [repeats]          uniform refinement: prints "osd <file> L<k>: topology T s,
//                                         points P s, limit Q s" (limit = PrimvarRefiner::Limit
//                                         with tangents at the last level).
//   osd_bench in.obj L repeats stencil    the limit-stencil pipeline (what ccn_plan_create /
//                                         ccn_plan_evaluate do): adaptive refiner (isolation 3,
//                                         Blender's default Quality) + LimitStencilTableFactory
//                                         at 2^L x 2^L samples per quad ptex face (2^(L-1) per
//                                         sub-face of an n-gon), then UpdateValues + UpdateDerivs.
//                                         Prints "osd-stencil <file> L<k>: N stencils; create C s,
//                                         update U s; table B bytes; peak RSS R kB".
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/resource.h>

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
    if (argc > 4 && std::string(argv[4]) == "stencil") {
        typedef Far::LimitStencilTableFactoryReal<double> LF;
        std::vector<double> us, vs;
        std::vector<std::pair<int, int>> ranges; // per ptex face: first sample, count
        double tc = 1e30, tu = 1e30;
        size_t nst = 0, bytes = 0;
        for (int r = 0; r < reps; r++) {
            double t0 = now();
            Far::TopologyRefiner *ref = Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
                desc, Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK, opt));
            ref->RefineAdaptive(Far::TopologyRefiner::AdaptiveOptions(3));
            if (us.empty()) { // the sample locations (not timed)
                Far::PtexIndices pt(*ref);
                for (int f = 0, p = 0; f < (int)sizes.size(); f++) {
                    int nsub = sizes[f] == 4 ? 1 : sizes[f], g = sizes[f] == 4 ? (1 << levels) : (1 << (levels > 0 ? levels - 1 : 0));
                    for (int k = 0; k < nsub; k++, p++) {
                        ranges.push_back(std::make_pair((int)us.size(), g * g));
                        for (int i = 0; i < g; i++)
                            for (int j = 0; j < g; j++) { us.push_back((double)i / g); vs.push_back((double)j / g); }
                    }
                    (void)pt;
                }
            }
            LF::LocationArrayVec locs(ranges.size());
            for (size_t k = 0; k < ranges.size(); k++) {
                locs[k].ptexIdx = (int)k;
                locs[k].numLocations = ranges[k].second;
                locs[k].s = us.data() + ranges[k].first;
                locs[k].t = vs.data() + ranges[k].first;
            }
            Far::LimitStencilTableReal<double> const *tab = LF::Create(*ref, locs);
            double t1 = now();
            nst = (size_t)tab->GetNumStencils();
            std::vector<Vtx> P(nst), Du(nst), Dv(nst);
            double tbest = 1e30;
            for (int q = 0; q < 3; q++) {
                verts[0].p[0] += 1e-3;
                double t2 = now();
                tab->UpdateValues(verts.data(), P.data());
                tab->UpdateDerivs(verts.data(), Du.data(), Dv.data());
                double t3 = now() - t2;
                if (t3 < tbest) tbest = t3;
            }
            bytes = tab->GetSizes().size() * sizeof(int) * 2 + tab->GetControlIndices().size() * sizeof(int) +
                    tab->GetWeights().size() * sizeof(double) * 3;
            if (t1 - t0 < tc) tc = t1 - t0;
            if (tbest < tu) tu = tbest;
            delete tab;
            delete ref;
        }
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        std::printf("osd-stencil %s L%d: %zu stencils; create %.4f s, update %.4f s; table %zu bytes; peak RSS %ld kB\n",
                    argv[1], levels, nst, tc, tu, bytes, ru.ru_maxrss);
        return 0;
    }
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
