// fvar_oracle: face-varying channels of ccnurbs against OpenSubdiv, in one process (test oracle).
//
//   fvar_oracle [--levels "1 2 3"] [--schemes cc,eigen] [--tol T] shape.obj ...
//
// For every shape with a UV map (`vt`, every corner `f v/vt`), every level K and each of the six
// FVarLinearInterpolation modes: OpenSubdiv's values at level K (InterpolateFaceVarying) and
// their exact limits (osd_limit.cpp: limitFaceVaryingExact at level K, localLimitFVar where the
// limit masks are not exact), per face corner, against ccnurbs' ccn_fvar_refine (refined) and
// ccn_plan_evaluate_fvar on a plan with --cap refine (limit), for each scheme (cc; eigen, with
// the shapes' equal intervals). ccnurbs reads the file with its own OBJ reader (ccn_obj_parse,
// ccn_obj_get_fvar); options as the CLI resolves them (interpolateboundary 1 pins corners,
// creasemethod). Corners are matched through OpenSubdiv's topology (ccnurbsFaceOrder below),
// and the corner positions (refined, limit) must agree too (<= T of the bounding box), so a
// wrong match cannot pass. Error: the largest component difference over the diagonal of the
// cage's UV bounding box. One line per shape, level and scheme (all modes, refined and limit),
// then "N passed, N failed"; exit 1 on any failure.
#include "osd_oracle.h"

#include <opensubdiv/far/primvarRefiner.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

extern "C" {
#include "ccnurbs.h"
}

using namespace OpenSubdiv;
using namespace osd_oracle;

namespace {

// OpenSubdiv's level-K faces in ccnurbs' order (ccnurbs.h: "faces: each old face's sub-quads
// in corner order", the sub-quad of corner j starting at the vertex's child): ours[f] is the
// ccnurbs index of OpenSubdiv face f, rot[f] the OpenSubdiv corner of ccnurbs corner 0
// (OpenSubdiv corner k = ccnurbs corner (k - rot) mod n). From the topology only.
void ccnurbsFaceOrder(Far::TopologyRefiner const &r, int K, std::vector<int> &ours,
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


struct Result {
    double fv = 0.0, pos = 0.0;  // worst relative errors
    int mode = -1;
    const char *kind = "";
};

double bboxDiag(const double *p, size_t n, int w) {
    if (n == 0) return 1.0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int k = 0; k < w; k++) lo[k] = hi[k] = p[k];
    for (size_t i = 1; i < n; i++)
        for (int k = 0; k < w; k++) {
            lo[k] = std::min(lo[k], p[w * i + k]);
            hi[k] = std::max(hi[k], p[w * i + k]);
        }
    double d = 0;
    for (int k = 0; k < w; k++) d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return d > 0 ? std::sqrt(d) : 1.0;
}

// OpenSubdiv per face corner in ccnurbs' order: positions (3) and values (w) at level K.
struct OsdCorners {
    std::vector<double> pos, val, lpos, lval;
};

OsdCorners osdLevel(Mesh const &m, Cage const &base, Sdc::Options opts, int K) {
    Far::TopologyRefiner *r = createRefiner(base, opts);
    if (!r || g_osdErrors) die("OpenSubdiv rejected the topology");
    Far::TopologyRefiner::UniformOptions uo(K);
    uo.orderVerticesFromFacesFirst = true;
    uo.fullTopologyInLastLevel = true;
    r->RefineUniform(uo);
    Far::PrimvarRefinerReal<double> pr(*r);
    std::vector<Vertex3> P = m.verts, F = m.uvs, nP, nF;
    for (int l = 1; l <= K; l++) {
        nP.assign((size_t)r->GetLevel(l).GetNumVertices(), Vertex3());
        nF.assign((size_t)r->GetLevel(l).GetNumFVarValues(0), Vertex3());
        pr.Interpolate(l, P, nP);
        pr.InterpolateFaceVarying(l, F, nF, 0);
        P.swap(nP);
        F.swap(nF);
    }
    Far::TopologyLevel const &lev = r->GetLevel(K);
    std::vector<Vertex3> LP(P.size()), t1(P.size()), t2(P.size()), LF;
    pr.Limit(P, LP, t1, t2);
    limitFaceVaryingExact(*r, F, LF);
    for (int v = 0; v < lev.GetNumVertices(); v++) {
        if (limitMaskExact(lev, v)) continue;
        LP[(size_t)v] = localLimit(lev, P, v, opts).pos;
        std::vector<Vertex3> per = localLimitFVar(lev, P, F, v, opts);
        Far::ConstIndexArray vf = lev.GetVertexFaces(v);
        for (int i = 0; i < vf.size(); i++)
            LF[(size_t)lev.GetFaceFVarValues(vf[i], 0)[cornerOf(lev, vf[i], v)]] = per[(size_t)i];
    }
    if (g_osdErrors) die("OpenSubdiv failed");
    std::vector<int> ours, rot;
    ccnurbsFaceOrder(*r, K, ours, rot);
    OsdCorners c;
    size_t nc = 4 * (size_t)lev.GetNumFaces();
    c.pos.assign(3 * nc, 0.0);
    c.lpos.assign(3 * nc, 0.0);
    c.val.assign(3 * nc, 0.0);
    c.lval.assign(3 * nc, 0.0);
    for (int f = 0; f < lev.GetNumFaces(); f++) {
        Far::ConstIndexArray fv = lev.GetFaceVertices(f), fval = lev.GetFaceFVarValues(f, 0);
        if (fv.size() != 4) die("a refined face is not a quad");
        for (int k = 0; k < 4; k++) {
            size_t q = 4 * (size_t)ours[(size_t)f] + (size_t)((k - rot[(size_t)f] + 4) % 4);
            for (int j = 0; j < 3; j++) {
                c.pos[3 * q + j] = P[(size_t)fv[k]].p[j];
                c.lpos[3 * q + j] = LP[(size_t)fv[k]].p[j];
                c.val[3 * q + j] = F[(size_t)fval[k]].p[j];
                c.lval[3 * q + j] = LF[(size_t)fval[k]].p[j];
            }
        }
    }
    delete r;
    return c;
}

void worse(Result &r, double fv, double pos, int mode, const char *kind) {
    if (fv > r.fv || pos > r.pos || r.mode < 0) {
        if (fv >= r.fv) { r.mode = mode; r.kind = kind; }
        r.fv = std::max(r.fv, fv);
        r.pos = std::max(r.pos, pos);
    }
}

[[noreturn]] void ccnDie(const char *what, ccn_error const &e) {
    die(std::string(what) + ": " + e.message);
}

}  // namespace

int main(int argc, char **argv) {
    std::vector<int> levels = {1, 2, 3};
    std::vector<ccn_scheme> schemes = {CCN_SCHEME_CATMULL_CLARK, CCN_SCHEME_EIGEN};
    double tol = 1e-9;
    std::vector<const char *> files;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--levels" && i + 1 < argc) {
            levels.clear();
            std::istringstream ss(argv[++i]);
            int k;
            while (ss >> k) levels.push_back(k);
        } else if (a == "--schemes" && i + 1 < argc) {
            schemes.clear();
            std::string s = argv[++i], t;
            std::istringstream ss(s);
            while (std::getline(ss, t, ','))
                schemes.push_back(t == "eigen" ? CCN_SCHEME_EIGEN : t == "nurss" ? CCN_SCHEME_NURSS : CCN_SCHEME_CATMULL_CLARK);
        } else if (a == "--tol" && i + 1 < argc) {
            tol = std::atof(argv[++i]);
        } else {
            files.push_back(argv[i]);
        }
    }
    Far::SetErrorCallback(osdError);
    Far::SetWarningCallback(osdWarning);
    int pass = 0, fail = 0;
    for (const char *path : files) {
        const char *slash = std::strrchr(path, '/');
        std::string name = slash ? slash + 1 : path;
        if (name.size() > 4 && name.substr(name.size() - 4) == ".obj") name.resize(name.size() - 4);
        Mesh m;
        std::string msg;
        if (!readObj(path, m, msg)) die(msg);
        if (!m.hasUV()) {
            std::printf("skip %-28s no UV map\n", name.c_str());
            continue;
        }
        Sdc::Options opts;
        opts.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
        if (m.interpolateBoundary >= 0) {
            static const Sdc::Options::VtxBoundaryInterpolation ib[3] = {
                Sdc::Options::VTX_BOUNDARY_NONE, Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER,
                Sdc::Options::VTX_BOUNDARY_EDGE_ONLY};
            opts.SetVtxBoundaryInterpolation(ib[m.interpolateBoundary]);
        }
        opts.SetCreasingMethod(m.creaseMethod == 1 ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
        Cage base;
        base.pos = m.verts;
        base.faceSizes = m.faceSizes;
        base.faceVerts = m.faceVerts;
        for (auto const &c : m.creases)
            if (c.second > 0.0f) {
                base.creasePairs.push_back(c.first.first);
                base.creasePairs.push_back(c.first.second);
                base.creaseWeights.push_back(c.second);
            }
        for (auto const &c : m.corners)
            if (c.second > 0.0f) {
                base.cornerVerts.push_back(c.first);
                base.cornerWeights.push_back(c.second);
            }
        base.fvValues = (int)m.uvs.size();
        base.fvIndices = m.faceUVs;

        // ccnurbs: its own reader
        std::ifstream in(path, std::ios::binary);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ccn_obj *obj = nullptr;
        ccn_error err;
        if (ccn_obj_parse(text.data(), text.size(), &obj, &err)) ccnDie("ccn_obj_parse", err);
        ccn_cage cage;
        ccn_fvar_channel ch;
        ccn_obj_tags tags;
        ccn_obj_get_cage(obj, &cage);
        ccn_obj_get_fvar(obj, &ch);
        ccn_obj_get_tags(obj, &tags);
        if (ch.num_values != (int)m.uvs.size()) die("ccnurbs reads another UV map");
        const double uvdiag = bboxDiag(ch.values, (size_t)ch.num_values, ch.width);
        const double diag = bboxDiag(cage.positions, (size_t)cage.num_verts, 3);
        ccn_mesh *cm = nullptr;
        if (ccn_mesh_create(&cage, &cm, &err)) ccnDie("ccn_mesh_create", err);

        for (int K : levels) {
            OsdCorners osd[6];
            for (int mode = 0; mode < 6; mode++) {
                Sdc::Options o = opts;
                o.SetFVarLinearInterpolation((Sdc::Options::FVarLinearInterpolation)mode);
                osd[mode] = osdLevel(m, base, o, K);
            }
            for (ccn_scheme sc : schemes) {
                ccn_options co = {};
                co.scheme = sc;
                co.cap = CCN_CAP_REFINE;
                co.levels = K;
                co.boundary_corners = tags.boundary_corners >= 0 ? tags.boundary_corners : CCN_CORNERS_SMOOTH;
                co.crease_method = tags.crease_method >= 0 ? tags.crease_method : CCN_CREASE_UNIFORM;
                Result res;
                // refined values and corner positions
                ccn_mesh *ref = nullptr;
                if (ccn_refine(cm, K, &co, &ref, &err)) ccnDie("ccn_refine", err);
                ccn_mesh_info ri;
                ccn_mesh_get_info(ref, &ri);
                std::vector<double> rpos(3 * (size_t)ri.num_verts);
                std::vector<int32_t> rfv((size_t)ri.num_face_verts);
                ccn_mesh_copy(ref, rpos.data(), nullptr, rfv.data(), nullptr, nullptr);
                ccn_mesh_destroy(ref);
                // limit: one plan, six channels
                ccn_plan *plan = nullptr;
                if (ccn_plan_create(&cage, &co, &plan, &err)) ccnDie("ccn_plan_create", err);
                ccn_sizes sz;
                ccn_plan_get_sizes(plan, &sz);
                std::vector<double> lp(3 * (size_t)sz.num_verts);
                std::vector<int32_t> lfv(4 * (size_t)sz.num_faces);
                ccn_limit_mesh lm = {lp.data(), nullptr, lfv.data(), nullptr, nullptr, nullptr, nullptr, nullptr,
                                      nullptr, nullptr};
                if (ccn_plan_evaluate(plan, nullptr, &lm, &err)) ccnDie("ccn_plan_evaluate", err);
                if ((size_t)ri.num_face_verts != osd[0].val.size() / 3 || 4 * (size_t)sz.num_faces != osd[0].val.size() / 3)
                    die("face corner counts differ from OpenSubdiv's");
                for (int mode = 0; mode < 6; mode++) {
                    ccn_fvar_channel c = ch;
                    c.linear = mode;
                    ccn_fvar *fv = nullptr;
                    if (ccn_fvar_refine(cm, &c, K, &co, &fv, &err)) ccnDie("ccn_fvar_refine", err);
                    ccn_fvar_info fi;
                    ccn_fvar_get_info(fv, &fi);
                    std::vector<double> vals((size_t)fi.width * (size_t)fi.num_values);
                    std::vector<int32_t> fvi((size_t)fi.num_face_verts);
                    ccn_fvar_copy(fv, vals.data(), fvi.data());
                    ccn_fvar_destroy(fv);
                    int32_t idx;
                    if (ccn_plan_add_fvar(plan, &c, &idx, &err)) ccnDie("ccn_plan_add_fvar", err);
                    ccn_fvar_sizes fs;
                    ccn_plan_get_fvar_sizes(plan, idx, &fs);
                    std::vector<double> lv((size_t)fs.width * (size_t)fs.num_values);
                    std::vector<int32_t> lfi(4 * (size_t)sz.num_faces);
                    if (ccn_plan_evaluate_fvar(plan, idx, nullptr, lv.data(), lfi.data(), &err))
                        ccnDie("ccn_plan_evaluate_fvar", err);
                    double er = 0, el = 0, pr = 0, pl = 0;
                    const OsdCorners &o = osd[mode];
                    for (size_t q = 0; q < fvi.size(); q++) {
                        for (int k = 0; k < fi.width; k++) {
                            er = std::max(er, std::fabs(vals[(size_t)fi.width * fvi[q] + k] - o.val[3 * q + k]));
                            el = std::max(el, std::fabs(lv[(size_t)fs.width * lfi[q] + k] - o.lval[3 * q + k]));
                        }
                        for (int k = 0; k < 3; k++) {
                            pr = std::max(pr, std::fabs(rpos[3 * (size_t)rfv[q] + k] - o.pos[3 * q + k]));
                            pl = std::max(pl, std::fabs(lp[3 * (size_t)lfv[q] + k] - o.lpos[3 * q + k]));
                        }
                    }
                    if (!(er == er) || !(el == el)) er = el = INFINITY;
                    worse(res, er / uvdiag, pr / diag, mode, "refined");
                    worse(res, el / uvdiag, pl / diag, mode, "limit");
                }
                ccn_plan_destroy(plan);
                static const char *names[6] = {"none", "corners-only", "corners-plus1", "corners-plus2", "boundaries", "all"};
                const bool ok = res.fv <= tol && res.pos <= tol;
                std::printf("%-4s %-28s L%d %-5s 6 modes, refined+limit: uv max_rel %.3g (%s %s), corner positions max_rel %.3g\n",
                            ok ? "ok" : "FAIL", name.c_str(), K, sc == CCN_SCHEME_EIGEN ? "eigen" : sc == CCN_SCHEME_NURSS ? "nurss" : "cc",
                            res.fv, names[res.mode], res.kind, res.pos);
                std::fflush(stdout);
                if (ok) pass++;
                else fail++;
            }
        }
        ccn_mesh_destroy(cm);
        ccn_obj_destroy(obj);
    }
    std::printf("%d passed, %d failed\n", pass, fail);
    return fail ? 1 : 0;
}
