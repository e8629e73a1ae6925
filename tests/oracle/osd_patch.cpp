// osd_patch: `osd_refine --patch-limit`, the limit as Blender's Subdivision Surface computes it
// with Use Limit Surface (test oracle; osd_oracle.h).
//
// Blender (intern/opensubdiv/internal/evaluator/evaluator_impl.cc, formerly
// opensubdiv_evaluator_internal.cc; the same settings in 3.4, 4.5 and 5.0) refines the cage
// with TopologyRefiner::RefineAdaptive(AdaptiveOptions(Quality), useInfSharpPatch = true),
// builds a Far::PatchTable with PatchTableFactory::Options(Quality), ENDCAP_GREGORY_BASIS and
// useInfSharpPatch = true (all else default: no single-crease patches, legacy sharp-corner
// patches), and places each vertex of its level-L mesh at a point of the uniform grid of a
// ptex face (source/blender/blenkernel/intern/subdiv_foreach.cc, subdiv_mesh.cc): a quad is
// one ptex face with (2^L + 1)^2 samples, an n-gon n ptex faces (one per corner) with
// (2^(L-1) + 1)^2 each; the point is found with a patch map and evaluated with the patch's
// basis, in float. Here the same is done in double precision for the vertices of the
// uniformly refined level-L mesh, which are exactly those grid points: each level-L face
// corner gets the (ptex face, u, v) of its parent's corners, edge midpoints and centre, and a
// vertex is evaluated at the coordinates of its first face corner (a point on a ptex edge is
// on two patches, which agree there).
// Options: --isolation N (1..10: Quality), --inf-sharp-patch 0|1, --single-crease-patch
// 0|1, --endcap gregory|bspline. Regular (B-spline) patches are exact, and at the level-L
// vertices so is an end cap's corner where its vertex's limit mask is (at an extraordinary
// vertex with no semi-sharp value left). Not at a dart (an infinitely sharp crease ending at
// a vertex): the corner there is PrimvarRefiner::Limit's smooth mask after N levels (equal to
// 1e-16 of the size on tests/oracle/run_patch_limit.sh's creased cube), which approaches the
// dart's limit by about 2.2x per level (2.3e-5 of the size at N = 10 there). Nor at a smooth
// boundary corner, where the legacy sharp-corner patch is off by about 4e-8 at N = 10.
// Not reproduced, as no test cage needs it: Blender also isolates face-varying (UV) features
// (considerFVarChannels when the mesh has a UV map; no effect on the positions measured: the
// creased cube with and without its UV map), and adds to the sharpness of a vertex with two
// edges the smaller of their sharpness (intern/opensubdiv/internal/topology/
// topology_refiner_factory.cc; those edges are uncreased in the test cages).
#include "osd_oracle.h"

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>

#include <memory>

using namespace OpenSubdiv;

namespace osd_oracle {

namespace {

struct PtexPoint {
    int face = -1;  // ptex face index, -1: not set
    double u = 0.0, v = 0.0;
};

PtexPoint mid(PtexPoint a, PtexPoint const &b) {
    a.u = 0.5 * (a.u + b.u);
    a.v = 0.5 * (a.v + b.v);
    return a;
}

// (ptex face, u, v) of each corner of each face of `level` (level >= 0), flattened like
// the faces' vertices.
std::vector<PtexPoint> cornerCoords(Far::TopologyRefiner const &ref, int level) {
    Far::PtexIndices ptex(ref);
    Far::TopologyLevel const &l0 = ref.GetLevel(0);
    std::vector<PtexPoint> cur;
    static const double quadUV[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int f = 0; f < l0.GetNumFaces(); f++) {
        const int n = l0.GetFaceVertices(f).size();
        for (int k = 0; k < n; k++) {
            PtexPoint p;
            p.face = ptex.GetFaceId(f) + (n == 4 ? 0 : k);
            if (n == 4) {
                p.u = quadUV[k][0];
                p.v = quadUV[k][1];
            }
            cur.push_back(p);  // an n-gon's corner k: origin of its ptex face k
        }
    }
    for (int l = 0; l < level; l++) {
        Far::TopologyLevel const &pl = ref.GetLevel(l), &cl = ref.GetLevel(l + 1);
        std::vector<int> offset(1, 0);
        for (int f = 0; f < cl.GetNumFaces(); f++)
            offset.push_back(offset.back() + cl.GetFaceVertices(f).size());
        std::vector<PtexPoint> next((size_t)offset.back());
        int poff = 0;
        for (int f = 0; f < pl.GetNumFaces(); f++) {
            Far::ConstIndexArray pv = pl.GetFaceVertices(f), pe = pl.GetFaceEdges(f);
            Far::ConstIndexArray kids = pl.GetFaceChildFaces(f);
            const int n = pv.size();
            const PtexPoint *pc = &cur[(size_t)poff];
            PtexPoint centre = pc[0];
            if (n == 4) {
                centre.u = 0.25 * (pc[0].u + pc[1].u + pc[2].u + pc[3].u);
                centre.v = 0.25 * (pc[0].v + pc[1].v + pc[2].v + pc[3].v);
            }
            for (int c = 0; c < kids.size(); c++) {
                Far::ConstIndexArray cv = cl.GetFaceVertices(kids[c]);
                // the parent corner this child face holds (an n-gon's ptex face)
                int corner = -1;
                for (int k = 0; k < n && corner < 0; k++)
                    for (int j = 0; j < cv.size(); j++)
                        if (cv[j] == pl.GetVertexChildVertex(pv[k])) corner = k;
                if (corner < 0) die("--patch-limit: a child face holds no parent corner");
                for (int j = 0; j < cv.size(); j++) {
                    PtexPoint q;
                    const int w = cv[j];
                    if (n == 4) {
                        if (w == pl.GetFaceChildVertex(f)) q = centre;
                        for (int k = 0; k < 4; k++) {
                            if (w == pl.GetVertexChildVertex(pv[k])) q = pc[k];
                            if (w == pl.GetEdgeChildVertex(pe[k])) q = mid(pc[k], pc[(k + 1) % 4]);
                        }
                    } else {  // child face `corner` of an n-gon is its ptex face `corner`:
                        // the corner at (0,0), edge `corner` (to the next vertex) at (1,0),
                        // the centre at (1,1), the edge before at (0,1)
                        q.face = pc[corner].face;
                        const int prev = (corner + n - 1) % n;
                        if (w == pl.GetVertexChildVertex(pv[corner])) q.u = q.v = 0.0;
                        else if (w == pl.GetEdgeChildVertex(pe[corner])) q.u = 1.0, q.v = 0.0;
                        else if (w == pl.GetFaceChildVertex(f)) q.u = q.v = 1.0;
                        else if (w == pl.GetEdgeChildVertex(pe[prev])) q.u = 0.0, q.v = 1.0;
                        else q.face = -1;
                    }
                    if (q.face < 0)
                        die("--patch-limit: a child vertex is no parent corner, edge or face");
                    next[(size_t)offset[(size_t)kids[c]] + (size_t)j] = q;
                }
            }
            poff += n;
        }
        cur.swap(next);
    }
    return cur;
}

}  // namespace

std::vector<Vertex3> patchLimit(Far::TopologyRefiner const &uniform, int levels,
                                Far::TopologyRefiner &adaptive,
                                std::vector<Vertex3> const &basePos, PatchOptions const &opts,
                                PatchStats &stats) {
    Far::PatchTableFactory::Options po((unsigned)opts.isolation);
    po.SetEndCapType(opts.bsplineEndCaps ? Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS
                                         : Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    po.useInfSharpPatch = opts.infSharpPatch;
    po.useSingleCreasePatch = opts.singleCreasePatch;
    po.SetPatchPrecision<double>();
    adaptive.RefineAdaptive(po.GetRefineAdaptiveOptions());
    if (g_osdErrors) die("OpenSubdiv adaptive refinement failed");
    std::unique_ptr<Far::PatchTable> table(Far::PatchTableFactory::Create(adaptive, po));
    if (!table || g_osdErrors) die("OpenSubdiv PatchTableFactory failed");

    // every level's vertices, then the end caps' local points
    const int nRef = adaptive.GetNumVerticesTotal();
    stats.maxLevel = adaptive.GetMaxLevel();
    stats.localPoints = table->GetNumLocalPoints();
    std::vector<Vertex3> X((size_t)(nRef + stats.localPoints));
    std::copy(basePos.begin(), basePos.end(), X.begin());
    Far::PrimvarRefinerReal<double> pr(adaptive);
    Vertex3 *src = X.data();
    for (int l = 1; l <= adaptive.GetMaxLevel(); l++) {
        Vertex3 *dst = src + adaptive.GetLevel(l - 1).GetNumVertices();
        pr.Interpolate(l, src, dst);
        src = dst;
    }
    if (stats.localPoints > 0)
        table->GetLocalPointStencilTable<double>()->UpdateValues(X.data(), X.data() + nRef);
    for (int a = 0; a < table->GetNumPatchArrays(); a++) {
        const Far::PatchDescriptor::Type t = table->GetPatchArrayDescriptor(a).GetType();
        int &count = t == Far::PatchDescriptor::REGULAR         ? stats.regular
                     : t == Far::PatchDescriptor::GREGORY_BASIS ? stats.gregoryBasis
                                                                : stats.other;
        count += table->GetNumPatches(a);
    }

    Far::TopologyLevel const &lev = uniform.GetLevel(levels);
    std::vector<PtexPoint> corners = cornerCoords(uniform, levels);
    std::vector<PtexPoint> at((size_t)lev.GetNumVertices());
    for (int f = 0, off = 0; f < lev.GetNumFaces(); f++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(f);
        for (int k = 0; k < fv.size(); k++, off++)
            if (at[(size_t)fv[k]].face < 0) at[(size_t)fv[k]] = corners[(size_t)off];
    }
    Far::PatchMap map(*table);
    std::vector<Vertex3> out(at.size());
    double w[20];
    for (size_t i = 0; i < at.size(); i++) {
        if (at[i].face < 0)
            die("--patch-limit: vertex " + std::to_string(i + 1) + " is on no face");
        Far::PatchTable::PatchHandle const *h = map.FindPatch(at[i].face, at[i].u, at[i].v);
        if (!h) die("--patch-limit: no patch at ptex face " + std::to_string(at[i].face));
        table->EvaluateBasis(*h, at[i].u, at[i].v, w);
        Far::ConstIndexArray cv = table->GetPatchVertices(*h);
        out[i].Clear();
        for (int k = 0; k < cv.size(); k++) out[i].AddWithWeight(X[(size_t)cv[k]], w[k]);
    }
    return out;
}

}  // namespace osd_oracle
