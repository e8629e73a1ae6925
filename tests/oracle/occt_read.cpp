// Independent oracle for the CAD writers (test-only): reads a STEP or IGES file with
// OpenCASCADE and reports what a CAD system would see, as "key: value" lines on stdout.
//
//   occt_read [--no-heal] [--grid N --points FILE [--curvature]] [--samples K] [--eval REQ --out RES]
//             [--fallback FACES] [--edges FILE] model.step|model.igs
//   occt_read --build SURF.txt --grid N --points FILE
//
// Report: reader status, counts of solids/shells/faces/wires/edges/vertices, whether
// BRepCheck_Analyzer finds the shape valid, free edges (ShapeAnalysis_FreeBounds), whether
// each shell is closed (BRep_Tool::IsClosed) and how many edges have exactly two face uses
// (TopExp::MapShapesAndAncestors; a seam counts its two uses in one face), the largest edge
// and vertex tolerance, one "face I:" line per face (surface type, degrees, poles, knots,
// multiplicities, periodic/closed flags, parameter bounds, orientation) and the normal angle
// across every edge with two face uses: K samples along the edge, the uv of each side from
// its pcurve, the oriented face normals from BRepLProp_SLProps, angle = atan2(|n1 x n2|,
// n1.n2) (accurate near 0). With --points, every face is evaluated on an N x N grid of its
// surface's parameter bounds: lines "face i j u v x y z nx ny nz" (normal of the oriented
// face), in face order (TopExp_Explorer over the file's shape); with --curvature each line ends
// with the principal curvatures "k1 k2" (k1 >= k2, positive where the face bends away from its
// oriented normal; nan where undefined).
//
// --eval REQ --out RES: REQ has lines "face u v" (face index in TopExp order, parameters of
// its surface); RES gets "face u v x y z nx ny nz" (the oriented normal, 0 0 0 if undefined).
// --fallback FACES: face indices (whitespace separated) whose edges are reported apart:
// normal_angle_max covers the edges with no such face, normal_angle_fallback_max the others.
// --edges FILE: one line per edge with two face uses, "fa fb ua va ub vb max min": the two
// faces (TopExp order), the uv on each (from the pcurves) of the edge's point at 0.4142 of its
// range (irrational: never at a vertex of the cage's hierarchy) and the largest
// and smallest normal angle of its samples; for a caller that knows where the edges lie (e.g.
// which are creases, whose angles are not G1 deviations).
//
// --no-heal: no shape healing after the translation (the reader's ShapeFix sequence is
// replaced by an undefined one), so a wrongly oriented edge use or a gap the writer left
// shows as an invalid shape instead of being repaired silently.
//
// --build reads a B-spline description (below) and builds the Geom_BSplineSurface itself
// (OpenCASCADE's periodic form when a direction is periodic), then writes the same grid:
// the independent surface a writer's output is compared with.
//   degree DU DV / poles NU NV / periodic PU PV / uknots K t1..tK / umults K m1..mK /
//   vknots ... / vmults ... / then NU*NV lines "x y z", u outer (OpenCASCADE's conventions:
//   a periodic direction lists its distinct poles and K = period knots + 1).
#include <BRepAdaptor_Surface.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESSolid_EdgeList.hxx>
#include <IGESSolid_Loop.hxx>
#include <IGESSolid_VertexList.hxx>
#include <StepData_StepModel.hxx>
#include <StepShape_Edge.hxx>
#include <StepShape_EdgeLoop.hxx>
#include <StepShape_OrientedEdge.hxx>
#include <StepShape_Vertex.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomLProp_SLProps.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_Static.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeAnalysis_FreeBounds.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListIteratorOfListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Shell.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <map>
#include <utility>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

static int usage() {
    std::fprintf(stderr, "usage: occt_read [--no-heal] [--grid N --points FILE [--curvature]] [--samples K] [--eval REQ --out RES]\n"
                         "                 [--fallback FACES] [--edges FILE] FILE.step|FILE.igs\n"
                         "       occt_read --build SURF.txt --grid N --points FILE\n");
    return 2;
}

static bool ends_with(const std::string &s, const char *suf) {
    std::string t(suf);
    if (s.size() < t.size()) return false;
    std::string e = s.substr(s.size() - t.size());
    std::transform(e.begin(), e.end(), e.begin(), ::tolower);
    return e == t;
}

// Warnings and fails of a check list: counted on stdout, the messages on stderr.
static void count_checks(const char *what, const Interface_CheckIterator &chl) {
    int nw = 0, nf = 0;
    for (chl.Start(); chl.More(); chl.Next()) {
        const Handle(Interface_Check) &c = chl.Value();
        for (int i = 1; i <= c->NbWarnings(); i++) std::fprintf(stderr, "%s warning: %s\n", what, c->CWarning(i));
        for (int i = 1; i <= c->NbFails(); i++) std::fprintf(stderr, "%s fail: %s\n", what, c->CFail(i));
        nw += c->NbWarnings();
        nf += c->NbFails();
    }
    std::printf("%s_warnings: %d\n%s_fails: %d\n", what, nw, what, nf);
}

static void reader_checks(XSControl_Reader &r) {
    count_checks("load", r.WS()->ModelCheckList());
    count_checks("transfer", r.WS()->TransferReader()->TransientProcess()->CheckList(Standard_False));
}

// The loops as written in the file, read through OpenCASCADE's entity model (before any
// translation or healing): every loop closed head to tail (the end vertex of each edge use is
// the start of the next) and every edge used at most once in each direction (a consistently
// oriented shell uses a shared edge once forward and once reversed).
struct use_count { int fwd = 0, rev = 0; };
typedef std::map<std::pair<const void *, int>, use_count> use_map; // edge -> uses
static void report_file_loops(int loops, int broken, const use_map &uses) {
    int opposite = 0, single = 0, bad = 0;
    for (auto &u : uses) {
        if (u.second.fwd == 1 && u.second.rev == 1) opposite++;
        else if (u.second.fwd + u.second.rev == 1) single++;
        else bad++;
    }
    std::printf("file_loops: %d\nfile_loops_broken: %d\nfile_edges_used_both_ways: %d\n"
                "file_edges_used_once: %d\nfile_edges_misused: %d\n", loops, broken, opposite, single, bad);
}

static void step_file_loops(const Handle(StepData_StepModel) &model) {
    int loops = 0, broken = 0;
    use_map uses;
    for (int i = 1; i <= model->NbEntities(); i++) {
        Handle(StepShape_EdgeLoop) loop = Handle(StepShape_EdgeLoop)::DownCast(model->Value(i));
        if (loop.IsNull()) continue;
        loops++;
        int n = loop->NbEdgeList();
        bool ok = n > 0;
        for (int k = 1; k <= n && ok; k++) {
            Handle(StepShape_OrientedEdge) a = loop->EdgeListValue(k), b = loop->EdgeListValue(k % n + 1);
            Handle(StepShape_Edge) ea = a->EdgeElement(), eb = b->EdgeElement();
            if (ea.IsNull() || eb.IsNull()) { ok = false; break; }
            const void *end = (a->Orientation() ? ea->EdgeEnd() : ea->EdgeStart()).get();
            const void *start = (b->Orientation() ? eb->EdgeStart() : eb->EdgeEnd()).get();
            ok = end != nullptr && end == start;
            use_count &u = uses[std::make_pair((const void *)ea.get(), 0)];
            (a->Orientation() ? u.fwd : u.rev)++;
        }
        broken += !ok;
    }
    report_file_loops(loops, broken, uses);
}

static void iges_file_loops(const Handle(IGESData_IGESModel) &model) {
    int loops = 0, broken = 0;
    use_map uses;
    for (int i = 1; i <= model->NbEntities(); i++) {
        Handle(IGESSolid_Loop) loop = Handle(IGESSolid_Loop)::DownCast(model->Value(i));
        if (loop.IsNull()) continue;
        loops++;
        int n = loop->NbEdges();
        bool ok = n > 0;
        auto ends = [&](int k, std::pair<const void *, int> &s, std::pair<const void *, int> &e) {
            Handle(IGESSolid_EdgeList) el = Handle(IGESSolid_EdgeList)::DownCast(loop->Edge(k));
            if (loop->EdgeType(k) != 0 || el.IsNull()) return false;
            int x = loop->ListIndex(k);
            if (x < 1 || x > el->NbEdges()) return false;
            std::pair<const void *, int> a(el->StartVertexList(x).get(), el->StartVertexIndex(x));
            std::pair<const void *, int> b(el->EndVertexList(x).get(), el->EndVertexIndex(x));
            s = loop->Orientation(k) ? a : b;
            e = loop->Orientation(k) ? b : a;
            return true;
        };
        for (int k = 1; k <= n && ok; k++) {
            std::pair<const void *, int> sa, ea, sb, eb;
            ok = ends(k, sa, ea) && ends(k % n + 1, sb, eb) && ea == sb;
            if (!ok) break;
            use_count &u = uses[std::make_pair((const void *)loop->Edge(k).get(), loop->ListIndex(k))];
            (loop->Orientation(k) ? u.fwd : u.rev)++;
        }
        broken += !ok;
    }
    report_file_loops(loops, broken, uses);
}

// Oriented unit normal of face F at (u, v); false where the normal is undefined.
static bool face_normal(const TopoDS_Face &F, const BRepAdaptor_Surface &S, double u, double v,
                        gp_Pnt &P, gp_Dir &N) {
    BRepLProp_SLProps props(S, u, v, 1, 1e-12);
    P = props.Value();
    if (!props.IsNormalDefined()) return false;
    N = props.Normal();
    if (F.Orientation() == TopAbs_REVERSED) N.Reverse();
    return true;
}

static void print_surface(int i, const TopoDS_Face &F) {
    Handle(Geom_Surface) s = BRep_Tool::Surface(F);
    Handle(Geom_RectangularTrimmedSurface) tr = Handle(Geom_RectangularTrimmedSurface)::DownCast(s);
    if (!tr.IsNull()) s = tr->BasisSurface();
    double u0, u1, v0, v1;
    s->Bounds(u0, u1, v0, v1);
    std::printf("face %d: type %s orientation %s bounds %.17g %.17g %.17g %.17g", i,
                s->DynamicType()->Name(), F.Orientation() == TopAbs_REVERSED ? "reversed" : "forward",
                u0, u1, v0, v1);
    Handle(Geom_BSplineSurface) b = Handle(Geom_BSplineSurface)::DownCast(s);
    if (!b.IsNull()) {
        std::printf(" udeg %d vdeg %d upoles %d vpoles %d uperiodic %d vperiodic %d uclosed %d "
                    "vclosed %d rational %d", b->UDegree(), b->VDegree(), b->NbUPoles(), b->NbVPoles(),
                    (int)b->IsUPeriodic(), (int)b->IsVPeriodic(), (int)b->IsUClosed(),
                    (int)b->IsVClosed(), (int)(b->IsURational() || b->IsVRational()));
        for (int d = 0; d < 2; d++) {
            int n = d ? b->NbVKnots() : b->NbUKnots();
            std::printf(" %cknots %d", d ? 'v' : 'u', n);
            for (int k = 1; k <= n; k++) std::printf(" %.17g", d ? b->VKnot(k) : b->UKnot(k));
            std::printf(" %cmults", d ? 'v' : 'u');
            for (int k = 1; k <= n; k++) std::printf(" %d", d ? b->VMultiplicity(k) : b->UMultiplicity(k));
        }
    }
    std::printf("\n");
}

static int with_curvature; // --curvature: --points lines end with "k1 k2"

// Principal curvatures at (u, v), positive where the face bends away from its oriented normal
// (OpenCASCADE's are signed along the surface's D1U x D1V: positive bending towards it); NaN
// where OpenCASCADE has none.
static void face_curvature(const TopoDS_Face &F, const BRepAdaptor_Surface &S, double u, double v,
                           double &k1, double &k2) {
    BRepLProp_SLProps props(S, u, v, 2, 1e-12);
    k1 = k2 = NAN;
    if (!props.IsNormalDefined() || !props.IsCurvatureDefined()) return;
    double s = F.Orientation() == TopAbs_REVERSED ? 1.0 : -1.0;
    double a = s * props.MaxCurvature(), b = s * props.MinCurvature();
    k1 = a > b ? a : b;
    k2 = a > b ? b : a;
}

// N x N grid of the surface's parameter bounds of face F (index fi) into out.
static void write_grid(FILE *out, int fi, const TopoDS_Face &F, int N) {
    BRepAdaptor_Surface S(F, Standard_False); // untrimmed surface parametrisation
    double u0 = S.FirstUParameter(), u1 = S.LastUParameter();
    double v0 = S.FirstVParameter(), v1 = S.LastVParameter();
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            double u = u0 + (u1 - u0) * i / (N - 1), v = v0 + (v1 - v0) * j / (N - 1);
            gp_Pnt P;
            gp_Dir D(0, 0, 1);
            bool ok = face_normal(F, S, u, v, P, D);
            std::fprintf(out, "%d %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g", fi, i, j,
                         u, v, P.X(), P.Y(), P.Z(), ok ? D.X() : 0.0, ok ? D.Y() : 0.0,
                         ok ? D.Z() : 0.0);
            if (with_curvature) {
                double k1, k2;
                face_curvature(F, S, u, v, k1, k2);
                std::fprintf(out, " %.17g %.17g", k1, k2);
            }
            std::fprintf(out, "\n");
        }
}

// --eval: the faces at the requested parameters.
static bool eval_requests(const TopoDS_Shape &shape, const char *req, const char *res) {
    TopTools_IndexedMapOfShape fmap;
    TopExp::MapShapes(shape, TopAbs_FACE, fmap);
    std::vector<BRepAdaptor_Surface *> ad(fmap.Extent() + 1, nullptr);
    std::ifstream in(req);
    FILE *out = std::fopen(res, "w");
    if (!in || !out) { if (out) std::fclose(out); return false; }
    int fi;
    double u, v;
    bool ok = true;
    while (in >> fi >> u >> v) {
        if (fi < 0 || fi >= fmap.Extent()) { ok = false; break; }
        if (!ad[fi]) ad[fi] = new BRepAdaptor_Surface(TopoDS::Face(fmap(fi + 1)), Standard_False);
        gp_Pnt P;
        gp_Dir D(0, 0, 1);
        bool nd = face_normal(TopoDS::Face(fmap(fi + 1)), *ad[fi], u, v, P, D);
        std::fprintf(out, "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", fi, u, v, P.X(), P.Y(), P.Z(),
                     nd ? D.X() : 0.0, nd ? D.Y() : 0.0, nd ? D.Z() : 0.0);
    }
    for (auto *a : ad) delete a;
    return std::fclose(out) == 0 && ok;
}

// Normal angles across edges used twice (two faces, or a seam of one face).
static FILE *edges_out; // --edges

static void edge_angles(const TopoDS_Shape &shape, int K, const std::vector<char> &fallback) {
    TopTools_IndexedDataMapOfShapeListOfShape ef;
    TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, ef);
    TopTools_IndexedMapOfShape fmap;
    TopExp::MapShapes(shape, TopAbs_FACE, fmap);
    double fbmax = 0;
    long fbpairs = 0;
    double amax = 0, asum = 0;
    long count = 0, undefined = 0, pairs = 0;
    int worst = -1;
    for (int e = 1; e <= ef.Extent(); e++) {
        const TopoDS_Edge &E = TopoDS::Edge(ef.FindKey(e));
        const TopTools_ListOfShape &faces = ef.FindFromIndex(e);
        std::vector<TopoDS_Face> fs;
        for (TopTools_ListIteratorOfListOfShape it(faces); it.More(); it.Next())
            fs.push_back(TopoDS::Face(it.Value()));
        // a seam appears once per use with the same face; pair the two uses
        TopoDS_Face fa, fb;
        TopoDS_Edge ea = E, eb = E;
        if (fs.size() == 2 && !fs[0].IsSame(fs[1])) {
            fa = fs[0];
            fb = fs[1];
        } else if ((fs.size() == 1 || fs.size() == 2) && BRep_Tool::IsClosed(E, fs[0])) {
            fa = fb = fs[0];
            ea = TopoDS::Edge(E.Oriented(TopAbs_FORWARD));
            eb = TopoDS::Edge(E.Oriented(TopAbs_REVERSED));
        } else {
            continue;
        }
        int ia = fmap.FindIndex(fa) - 1, ib = fmap.FindIndex(fb) - 1;
        bool fb_edge = (ia >= 0 && ia < (int)fallback.size() && fallback[ia]) ||
                       (ib >= 0 && ib < (int)fallback.size() && fallback[ib]);
        if (fb_edge) fbpairs++;
        else pairs++;
        double f0, l0;
        BRep_Tool::Range(E, f0, l0);
        BRepAdaptor_Surface Sa(fa), Sb(fb);
        double fa0, la0, fb0, lb0;
        Handle(Geom2d_Curve) ca = BRep_Tool::CurveOnSurface(ea, fa, fa0, la0);
        Handle(Geom2d_Curve) cb = BRep_Tool::CurveOnSurface(eb, fb, fb0, lb0);
        if (ca.IsNull() || cb.IsNull()) { undefined++; continue; }
        double emax = 0, emin = HUGE_VAL;
        for (int k = 0; k < K; k++) {
            double t = f0 + (l0 - f0) * (k + 0.5) / K; // inner samples: corners may be EVs
            gp_Pnt2d pa = ca->Value(t), pb = cb->Value(t);
            gp_Pnt Pa, Pb;
            gp_Dir Na, Nb;
            if (!face_normal(fa, Sa, pa.X(), pa.Y(), Pa, Na) || !face_normal(fb, Sb, pb.X(), pb.Y(), Pb, Nb)) {
                undefined++;
                continue;
            }
            gp_Vec a(Na), b(Nb);
            double ang = std::atan2(a.Crossed(b).Magnitude(), a.Dot(b));
            emax = std::max(emax, ang);
            emin = std::min(emin, ang);
            if (fb_edge) { fbmax = std::max(fbmax, ang); continue; }
            if (ang > amax) { amax = ang; worst = e; }
            asum += ang;
            count++;
        }
        if (edges_out) { // a point at an irrational fraction: never at a vertex of the cage
            double t = f0 + (l0 - f0) * 0.41421356237309515;
            gp_Pnt2d pa = ca->Value(t), pb = cb->Value(t);
            std::fprintf(edges_out, "%d %d %.17g %.17g %.17g %.17g %.6e %.6e\n", ia, ib, pa.X(), pa.Y(), pb.X(),
                         pb.Y(), emax, emin);
        }
    }
    std::printf("edge_pairs: %ld\nnormal_samples: %ld\nnormal_undefined: %ld\n", pairs, count, undefined);
    std::printf("normal_angle_max: %.6e\nnormal_angle_mean: %.6e\nnormal_angle_worst_edge: %d\n", amax,
                count ? asum / count : 0.0, worst);
    std::printf("fallback_edge_pairs: %ld\nnormal_angle_fallback_max: %.6e\n", fbpairs, fbmax);
}

static void report(const TopoDS_Shape &shape, int K, const std::vector<char> &fallback) {
    TopTools_IndexedMapOfShape m;
    static const struct { TopAbs_ShapeEnum t; const char *name; } kinds[] = {
        {TopAbs_SOLID, "solids"}, {TopAbs_SHELL, "shells"}, {TopAbs_FACE, "faces"},
        {TopAbs_WIRE, "wires"}, {TopAbs_EDGE, "edges"}, {TopAbs_VERTEX, "vertices"}};
    for (auto &k : kinds) {
        m.Clear();
        TopExp::MapShapes(shape, k.t, m);
        std::printf("%s: %d\n", k.name, m.Extent());
    }
    BRepCheck_Analyzer ana(shape);
    std::printf("valid: %d\n", (int)ana.IsValid());
    int closed_shells = 0;
    for (TopExp_Explorer ex(shape, TopAbs_SHELL); ex.More(); ex.Next())
        closed_shells += BRep_Tool::IsClosed(ex.Current()) ? 1 : 0;
    std::printf("closed_shells: %d\n", closed_shells);
    if (closed_shells) { // a closed shell bounds positive volume when its faces point out
        GProp_GProps g;
        BRepGProp::VolumeProperties(shape, g, 1e-10); // adaptive, relative error 1e-10
        std::printf("volume: %.17g\n", g.Mass());
    }
    ShapeAnalysis_FreeBounds fb(shape, Standard_False, Standard_False); // no sewing: as read
    TopTools_IndexedMapOfShape fe;
    TopExp::MapShapes(fb.GetClosedWires(), TopAbs_EDGE, fe);
    TopExp::MapShapes(fb.GetOpenWires(), TopAbs_EDGE, fe);
    std::printf("free_edges: %d\n", fe.Extent());
    TopTools_IndexedDataMapOfShapeListOfShape ef;
    TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, ef);
    int uses[4] = {0, 0, 0, 0}; // edges used by 1, 2 (two faces), 2 (seam), other
    double etol = 0, vtol = 0;
    for (int e = 1; e <= ef.Extent(); e++) {
        const TopoDS_Edge &E = TopoDS::Edge(ef.FindKey(e));
        etol = std::max(etol, BRep_Tool::Tolerance(E));
        int n = ef.FindFromIndex(e).Extent();
        const TopoDS_Face &F0 = TopoDS::Face(ef.FindFromIndex(e).First());
        if (BRep_Tool::IsClosed(E, F0) && (n == 1 || (n == 2 && ef.FindFromIndex(e).Last().IsSame(F0))))
            uses[2]++;
        else if (n == 1) uses[0]++;
        else if (n == 2) uses[1]++;
        else uses[3]++;
    }
    m.Clear();
    TopExp::MapShapes(shape, TopAbs_VERTEX, m);
    for (int v = 1; v <= m.Extent(); v++) vtol = std::max(vtol, BRep_Tool::Tolerance(TopoDS::Vertex(m(v))));
    std::printf("edges_one_face: %d\nedges_two_faces: %d\nedges_seam: %d\nedges_other: %d\n", uses[0],
                uses[1], uses[2], uses[3]);
    std::printf("max_edge_tolerance: %.6e\nmax_vertex_tolerance: %.6e\n", etol, vtol);
    int i = 0;
    for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) print_surface(i++, TopoDS::Face(ex.Current()));
    edge_angles(shape, K, fallback);
}

// ---- --build ---------------------------------------------------------------------------

static bool expect(std::ifstream &in, const char *word) {
    std::string w;
    return (in >> w) && w == word;
}

static Handle(Geom_BSplineSurface) build_surface(const char *path) {
    std::ifstream in(path);
    int du, dv, nu, nv, pu, pv;
    if (!expect(in, "degree") || !(in >> du >> dv) || !expect(in, "poles") || !(in >> nu >> nv) ||
        !expect(in, "periodic") || !(in >> pu >> pv))
        return nullptr;
    std::vector<double> kn[2];
    std::vector<int> mu[2];
    static const char *names[4] = {"uknots", "umults", "vknots", "vmults"};
    for (int d = 0; d < 2; d++) {
        int k;
        if (!expect(in, names[2 * d]) || !(in >> k) || k < 2) return nullptr;
        kn[d].resize(k);
        for (auto &x : kn[d]) if (!(in >> x)) return nullptr;
        int k2;
        if (!expect(in, names[2 * d + 1]) || !(in >> k2) || k2 != k) return nullptr;
        mu[d].resize(k);
        for (auto &x : mu[d]) if (!(in >> x)) return nullptr;
    }
    TColgp_Array2OfPnt P(1, nu, 1, nv);
    for (int i = 1; i <= nu; i++)
        for (int j = 1; j <= nv; j++) {
            double x, y, z;
            if (!(in >> x >> y >> z)) return nullptr;
            P(i, j) = gp_Pnt(x, y, z);
        }
    TColStd_Array1OfReal UK(1, (int)kn[0].size()), VK(1, (int)kn[1].size());
    TColStd_Array1OfInteger UM(1, (int)kn[0].size()), VM(1, (int)kn[1].size());
    for (int k = 0; k < (int)kn[0].size(); k++) { UK(k + 1) = kn[0][k]; UM(k + 1) = mu[0][k]; }
    for (int k = 0; k < (int)kn[1].size(); k++) { VK(k + 1) = kn[1][k]; VM(k + 1) = mu[1][k]; }
    try {
        return new Geom_BSplineSurface(P, UK, VK, UM, VM, du, dv, pu != 0, pv != 0);
    } catch (const Standard_Failure &e) {
        std::fprintf(stderr, "occt_read: Geom_BSplineSurface: %s\n", e.GetMessageString());
        return nullptr;
    }
}

int main(int argc, char **argv) {
    int N = 0, K = 8, heal = 1;
    const char *points = nullptr, *build = nullptr, *file = nullptr, *req = nullptr, *res = nullptr;
    const char *edges = nullptr;
    std::vector<char> fallback;
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "--grid") && i + 1 < argc) N = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--points") && i + 1 < argc) points = argv[++i];
        else if (!std::strcmp(argv[i], "--samples") && i + 1 < argc) K = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--build") && i + 1 < argc) build = argv[++i];
        else if (!std::strcmp(argv[i], "--no-heal")) heal = 0;
        else if (!std::strcmp(argv[i], "--curvature")) with_curvature = 1;
        else if (!std::strcmp(argv[i], "--eval") && i + 1 < argc) req = argv[++i];
        else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) res = argv[++i];
        else if (!std::strcmp(argv[i], "--edges") && i + 1 < argc) edges = argv[++i];
        else if (!std::strcmp(argv[i], "--fallback") && i + 1 < argc) {
            std::ifstream fin(argv[++i]);
            int x;
            while (fin >> x) {
                if (x < 0) return usage();
                if ((size_t)x >= fallback.size()) fallback.resize(x + 1, 0);
                fallback[x] = 1;
            }
        }
        else if (argv[i][0] == '-') return usage();
        else file = argv[i];
    }
    if ((points && N < 2) || K < 1 || (!file && !build) || (build && (file || !points)) || (!req != !res))
        return usage();
    // the readers' progress and warning messages go to stderr, not into the report
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_Printer));
    if (build) {
        Handle(Geom_BSplineSurface) s = build_surface(build);
        if (s.IsNull()) { std::fprintf(stderr, "occt_read: cannot build %s\n", build); return 1; }
        FILE *out = std::fopen(points, "w");
        if (!out) { std::perror(points); return 1; }
        double u0, u1, v0, v1;
        s->Bounds(u0, u1, v0, v1);
        for (int i = 0; i < N; i++)
            for (int j = 0; j < N; j++) {
                double u = u0 + (u1 - u0) * i / (N - 1), v = v0 + (v1 - v0) * j / (N - 1);
                GeomLProp_SLProps props(s, u, v, 1, 1e-12);
                gp_Pnt P = props.Value();
                gp_Dir D = props.IsNormalDefined() ? props.Normal() : gp_Dir(0, 0, 1);
                std::fprintf(out, "0 %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", i, j, u, v,
                             P.X(), P.Y(), P.Z(), D.X(), D.Y(), D.Z());
            }
        std::printf("built: %s\nuperiodic: %d\nvperiodic: %d\n", build, (int)s->IsUPeriodic(),
                    (int)s->IsVPeriodic());
        return std::fclose(out) == 0 ? 0 : 1;
    }
    std::string f(file);
    bool iges = ends_with(f, ".igs") || ends_with(f, ".iges");
    TopoDS_Shape shape;
    IFSelect_ReturnStatus st;
    int roots = 0;
    std::printf("file: %s\nformat: %s\n", file, iges ? "iges" : "step");
    IGESControl_Reader ri;
    STEPControl_Reader rs;
    XSControl_Reader &r = iges ? (XSControl_Reader &)ri : (XSControl_Reader &)rs;
    if (!heal) { // the translation as written: no ShapeFix sequence after it
        Interface_Static::SetCVal("read.step.sequence", "CcnNoHealing");
        Interface_Static::SetCVal("read.iges.sequence", "CcnNoHealing");
    }
    std::printf("healing: %d\n", heal);
    st = r.ReadFile(file);
    if (st == IFSelect_RetDone) {
        if (iges) iges_file_loops(ri.IGESModel());
        else step_file_loops(rs.StepModel());
        roots = r.TransferRoots();
        shape = r.OneShape();
        reader_checks(r);
    }
    std::printf("reader_status: %s\ntransferred_roots: %d\n", st == IFSelect_RetDone ? "done" : "failed", roots);
    if (st != IFSelect_RetDone || shape.IsNull()) {
        std::printf("shape: null\n");
        return 1;
    }
    std::printf("shape_type: %s\n", TopAbs::ShapeTypeToString(shape.ShapeType()));
    if (edges && !(edges_out = std::fopen(edges, "w"))) { std::perror(edges); return 1; }
    report(shape, K, fallback);
    if (edges_out && std::fclose(edges_out) != 0) { std::perror(edges); return 1; }
    if (req && !eval_requests(shape, req, res)) { std::fprintf(stderr, "occt_read: --eval failed\n"); return 1; }
    if (points) {
        FILE *out = std::fopen(points, "w");
        if (!out) { std::perror(points); return 1; }
        int i = 0;
        for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) write_grid(out, i++, TopoDS::Face(ex.Current()), N);
        if (std::fclose(out) != 0) return 1;
    }
    return 0;
}
