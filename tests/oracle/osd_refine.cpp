// osd_refine: reference Catmull-Clark refinement with OpenSubdiv (test oracle).
//
//   osd_refine [--levels K] [--corners smooth|pinned] [--limit | --limit-normals | --limit-osd |
//              --patch-limit [--isolation N] [--inf-sharp-patch 0|1] [--single-crease-patch 0|1]
//              [--endcap gregory|bspline]] [--fvar-linear M] in.obj out.obj
//
// Input: OBJ with OpenSubdiv shape tags or CCNURBS sharpness comments and UV maps (osd_obj.cpp).
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
//   --fvar-linear M (0..5 or none, corners-only, corners-plus1, corners-plus2, boundaries,
//     all): the face-varying interpolation (wins over the file's facevaryinginterpolateboundary
//     tag; neither: OpenSubdiv's default, all).
// UV maps. When every face corner has a texture index (`f v/vt`), the `vt` values are a
// face-varying channel and the output has the level-K values as `vt` lines and faces as
// `f v/vt` (`f v/vt/vn` with --limit-normals), in OpenSubdiv's order: InterpolateFaceVarying
// level by level; with --limit (levels >= 1), the exact limit of each value: LimitFaceVarying
// at level K where it is exact, with its crease weights in double precision, and where Limit is
// not (see above) the one-ring refinement, carrying the values (osd_limit.cpp, localLimitFVar,
// limitFaceVaryingExact). --patch-limit writes no UV map (positions only).
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

namespace {

void usage() {
    die("usage: osd_refine [--levels K] [--corners smooth|pinned] "
        "[--limit | --limit-normals | --limit-osd | --patch-limit [--isolation N] "
        "[--inf-sharp-patch 0|1] [--single-crease-patch 0|1] [--endcap gregory|bspline]] "
        "[--fvar-linear M] in.obj out.obj");
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
    int fvarLinear = -1;
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
        } else if (a == "--fvar-linear" && i + 1 < argc) {
            static const char *names[6] = {"none", "corners-only", "corners-plus1", "corners-plus2",
                                           "boundaries", "all"};
            const std::string m = argv[++i];
            for (int k = 0; k < 6; k++)
                if (m == names[k] || m == std::to_string(k)) fvarLinear = k;
            if (fvarLinear < 0) die("--fvar-linear must be 0..5 or an OpenSubdiv name");
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
    if (fvarLinear >= 0) m.fvarInterpolateBoundary = fvarLinear;
    const bool uv = m.hasUV() && !patch;

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
    if (uv) {
        base.fvValues = (int)m.uvs.size();
        base.fvIndices = m.faceUVs;
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
    std::vector<Vertex3> cur = m.verts, next, curfv = m.uvs, nextfv;
    for (int l = 1; l <= levels; l++) {
        next.assign((size_t)refiner->GetLevel(l).GetNumVertices(), Vertex3());
        primvar.Interpolate(l, cur, next);
        cur.swap(next);
        if (uv) {
            nextfv.assign((size_t)refiner->GetLevel(l).GetNumFVarValues(0), Vertex3());
            primvar.InterpolateFaceVarying(l, curfv, nextfv, 0);
            curfv.swap(nextfv);
        }
    }
    Far::TopologyLevel const &lev = refiner->GetLevel(levels);
    std::vector<Vertex3> nrm;
    int nLocal = 0, nNoNormal = 0;
    if (limit && uv) {
        if (levels < 1) die("face-varying limits need --levels >= 1");
        std::vector<Vertex3> lim;
        limitFaceVaryingExact(*refiner, curfv, lim);
        for (int v = 0; !limitOsd && v < (int)cur.size(); v++) {
            if (limitMaskExact(lev, v)) continue;
            std::vector<Vertex3> per = localLimitFVar(lev, cur, curfv, v, sdcOpts);
            Far::ConstIndexArray vf = lev.GetVertexFaces(v);
            for (int i = 0; i < vf.size(); i++)
                lim[(size_t)lev.GetFaceFVarValues(vf[i], 0)[cornerOf(lev, vf[i], v)]] = per[(size_t)i];
        }
        curfv.swap(lim);
    }
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
    for (size_t i = 0; uv && i < curfv.size(); i++) {
        std::fprintf(out, "vt");
        for (int k = 0; k < m.uvWidth; k++) std::fprintf(out, " %.17g", curfv[i].p[k]);
        std::fputc('\n', out);
    }
    for (int f = 0; f < lev.GetNumFaces(); f++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(f);
        std::fputc('f', out);
        for (int i = 0; i < fv.size(); i++) {
            std::fprintf(out, " %d", fv[i] + 1);
            if (uv) std::fprintf(out, "/%d", lev.GetFaceFVarValues(f, 0)[i] + 1);
            if (normals) std::fprintf(out, "%s/%d", uv ? "" : "/", fv[i] + 1);
        }
        std::fputc('\n', out);
    }
    if (std::fclose(out) != 0) die(std::string("write error on ") + outPath);
    delete refiner;
    return 0;
}
