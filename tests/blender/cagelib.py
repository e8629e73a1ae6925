"""Helpers shared by the headless Blender tests and the demo (run inside Blender's Python).

Independent of the add-on: OBJ cages with `# knot i j d` lines in and out, mesh objects with
the `knot_interval` EDGE attribute, the CLI as reference.
"""
import os
import subprocess
import tempfile

import bpy
import numpy as np

CLI_SCHEME = {"EIGEN": "eigen", "NURSS": "nurss", "CATMULL_CLARK": "cc"}
CLI_CAP = {"GUIDED_BI5": "bi5", "REFINE": "refine", "G1_FILL": "fill"}
CLI_CORNERS = {"ALL": "smooth", "PRESERVE_CORNERS": "pinned"}


def read_obj(path):
    """(V (n,3), faces [list], knots {(i,j): d}) with 0-based indices."""
    V, F, K = [], [], {}
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                V.append([float(x) for x in t[1:4]])
            elif t[0] == "f":
                F.append([int(x.split("/")[0]) - 1 for x in t[1:]])
            elif t[0] == "#" and len(t) >= 5 and t[1] == "knot":
                a, b = int(t[2]) - 1, int(t[3]) - 1
                K[(min(a, b), max(a, b))] = float(t[4])
    return np.array(V, np.float64), F, K


def make_object(name, V, F, knots=None, link=True):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(v) for v in V], [], [tuple(f) for f in F])
    me.update()
    if knots:
        set_knots(me, knots)
    ob = bpy.data.objects.new(name, me)
    if link:
        bpy.context.scene.collection.objects.link(ob)
    return ob


def edge_keys(me):
    ev = np.empty(2 * len(me.edges), np.int32)
    me.edges.foreach_get("vertices", ev)
    ev = ev.reshape(-1, 2)
    return [(int(min(a, b)), int(max(a, b))) for a, b in ev]


def set_knots(me, knots):
    a = me.attributes.get("knot_interval") or me.attributes.new("knot_interval", 'FLOAT', 'EDGE')
    vals = np.array([knots.get(k, 0.0) for k in edge_keys(me)], np.float32)
    a.data.foreach_set("value", vals)
    me.update()


def get_knots(me):
    a = me.attributes.get("knot_interval")
    if a is None:
        return None
    v = np.empty(len(me.edges), np.float32)
    a.data.foreach_get("value", v)
    return v


def mesh_positions(me):
    co = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def edge_vertex_creases(me):
    """(edge creases (E,), vertex creases (V,)) in [0, 1]: the `crease_edge` / `crease_vert`
    attributes (4.0+), MeshEdge.crease and the vertex crease layer (3.x); zeros when unset."""
    ec, vc = np.zeros(len(me.edges), np.float32), np.zeros(len(me.vertices), np.float32)
    if bpy.app.version >= (4, 0, 0):
        for name, out in (("crease_edge", ec), ("crease_vert", vc)):
            a = me.attributes.get(name)
            if a is not None:
                a.data.foreach_get("value", out)
    else:
        me.edges.foreach_get("crease", ec)
        layers = getattr(me, "vertex_creases", None)
        if layers:
            layers[0].data.foreach_get("value", vc)
    return ec, vc


def write_cage_obj(me, path, creases=False):
    """Writes the mesh (object mode data) as an OBJ cage with its knot intervals (and its
    creases as OpenSubdiv sharpness 10 c^2, Blender's mapping, if creases)."""
    P = mesh_positions(me)
    sizes = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_total", sizes)
    starts = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_start", starts)
    lv = np.empty(len(me.loops), np.int32)
    me.loops.foreach_get("vertex_index", lv)
    k = get_knots(me)
    with open(path, "w") as fh:
        for p in P:
            fh.write("v %.9g %.9g %.9g\n" % tuple(p))
        for s, n in zip(starts, sizes):
            fh.write("f " + " ".join(str(int(i) + 1) for i in lv[s:s + n]) + "\n")
        if k is not None:
            for (a, b), d in zip(edge_keys(me), k):
                if d > 0:
                    fh.write("# knot %d %d %.9g\n" % (a + 1, b + 1, d))
        if creases:
            ec, vc = edge_vertex_creases(me)
            for (a, b), c in zip(edge_keys(me), ec):
                if c > 0:
                    fh.write("# crease %d %d %.17g\n" % (a + 1, b + 1, 10 * float(c) ** 2))
            for i, c in enumerate(vc):
                if c > 0:
                    fh.write("# corner %d %.17g\n" % (i + 1, 10 * float(c) ** 2))
        # Subdivision Surface's rule, which the add-on follows: the ends of an edge in no face
        # are infinitely sharp (corners), with or without creases
        le = np.empty(len(me.loops), np.int32)
        me.loops.foreach_get("edge_index", le)
        loose = np.ones(len(me.edges), bool)
        loose[le] = False
        for i in np.unique(np.array(edge_keys(me), np.int64).reshape(-1, 2)[loose].ravel()):
            fh.write("# corner %d 10\n" % (int(i) + 1))


def read_limit_obj(path):
    V, N = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                V.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("vn "):
                N.append([float(x) for x in line.split()[1:4]])
    return np.array(V, np.float64).reshape(-1, 3), np.array(N, np.float64).reshape(-1, 3)


def cli_curvature(cli, me, levels, scheme="EIGEN", cap="GUIDED_BI5", boundary="ALL"):
    """Runs `ccnurbs limit --curvature` (PLY) on the mesh; returns (positions, (N, 2) k1 k2)."""
    with tempfile.TemporaryDirectory() as d:
        src, dst = os.path.join(d, "cage.obj"), os.path.join(d, "limit.ply")
        write_cage_obj(me, src)
        cmd = [cli, "limit", "--levels", str(levels), "--scheme", CLI_SCHEME[scheme],
               "--cap", CLI_CAP[cap], "--corners", CLI_CORNERS[boundary], "--curvature", src, dst]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), r.returncode, r.stderr))
        with open(dst) as fh:
            lines = fh.read().split("\n")
        nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
        start = lines.index("end_header") + 1
        A = np.array([[float(x) for x in l.split()] for l in lines[start:start + nv]])
        return A[:, :3], A[:, 6:8]


def cli_limit(cli, me, levels, scheme="EIGEN", cap="GUIDED_BI5", boundary="ALL", creases=False):
    """Runs `ccnurbs limit` on the mesh; returns (positions, normals)."""
    with tempfile.TemporaryDirectory() as d:
        src, dst = os.path.join(d, "cage.obj"), os.path.join(d, "limit.obj")
        write_cage_obj(me, src, creases)
        cmd = [cli, "limit", "--levels", str(levels), "--scheme", CLI_SCHEME[scheme],
               "--cap", CLI_CAP[cap], "--corners", CLI_CORNERS[boundary], src, dst]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), r.returncode, r.stderr))
        return read_limit_obj(dst)
