"""File > Import / Export > "OBJ with knot intervals and creases" (.obj).

The format of the `ccnurbs` CLI (README "File format"): `v`, `vt`, `f v/vt` (negative indices
accepted), and comment statements other readers skip, 1-based vertex indices:

    # knot i j d     edge (i, j) has knot interval d  (<= 0 / NaN / Inf: unset, not stored)
    # crease i j s   edge (i, j) has OpenSubdiv sharpness s  (Blender crease c = sqrt(s / 10))
    # corner i s     vertex i has sharpness s                 (Blender vertex crease, same map)

The sharpness map is Blender's Subdivision Surface one (sharpness = 10 c^2). Export writes the
object's own mesh (edit-mode changes included): positions and UVs as float32 exactly (%.9g),
intervals as float32 exactly, sharpness as float64 (%.17g), so import -> export -> import keeps
every value bit for bit. Parsing is a loop over lines (text has no bulk reader); mesh data goes
in and out with foreach_get / foreach_set.
"""

import os

import bpy
import numpy as np
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import cage as cagemod
from . import compat, values

class ObjData:
    def __init__(self):
        self.v, self.vt, self.face_sizes, self.fv, self.fvt = [], [], [], [], []
        self.knots, self.creases, self.corners = [], [], []
        self.warnings = []

def _index(tok, n, line_no):
    i = int(tok)
    i = i - 1 if i > 0 else n + i
    if not 0 <= i < n:
        raise ValueError("line %d: index %s out of range" % (line_no, tok))
    return i

def parse(text):
    d = ObjData()
    for no, line in enumerate(text.splitlines(), 1):
        t = line.split()
        if not t:
            continue
        head = t[0]
        if head == "v":
            d.v.append(tuple(float(x) for x in t[1:4]))
        elif head == "vt":
            d.vt.append((float(t[1]), float(t[2]) if len(t) > 2 else 0.0))
        elif head == "f":
            vs, ts = [], []
            for c in t[1:]:
                parts = c.split("/")
                vs.append(_index(parts[0], len(d.v), no))
                if len(parts) > 1 and parts[1]:
                    ts.append(_index(parts[1], len(d.vt), no))
            if len(vs) < 3:
                raise ValueError("line %d: a face needs at least 3 vertices" % no)
            d.face_sizes.append(len(vs))
            d.fv += vs
            d.fvt.append(ts if len(ts) == len(vs) else None)
        elif head == "#" and len(t) >= 4 and t[1] in ("knot", "crease", "corner"):
            try:
                if t[1] == "corner":
                    d.corners.append((_index(t[2], len(d.v), no), float(t[3])))
                elif len(t) >= 5:
                    a, b = _index(t[2], len(d.v), no), _index(t[3], len(d.v), no)
                    (d.knots if t[1] == "knot" else d.creases).append((a, b, float(t[4])))
            except ValueError as e:
                d.warnings.append(str(e))
    return d

def crease_from_sharpness(s):
    """OpenSubdiv sharpness -> Blender crease: c = sqrt(s / 10) in [0, 1]; s <= 0 / NaN -> 0."""
    s = np.asarray(s, np.float64)
    with np.errstate(invalid="ignore"):
        c = np.sqrt(np.clip(np.nan_to_num(s, nan=0.0, posinf=10.0), 0.0, 10.0) / 10.0)
    return c.astype(np.float32)

def _edge_lookup(me):
    ev = np.empty(2 * len(me.edges), np.int32)
    me.edges.foreach_get("vertices", ev)
    ev = ev.reshape(-1, 2).astype(np.int64)
    nv = max(len(me.vertices), 1)
    keys = np.minimum(ev[:, 0], ev[:, 1]) * nv + np.maximum(ev[:, 0], ev[:, 1])
    order = np.argsort(keys)
    return keys[order], order, nv

def _edge_values(me, triples, lookup):
    """Edge indices and values of (i, j, value) triples; pairs that are not edges dropped."""
    keys, order, nv = lookup
    if not triples:
        return np.empty(0, np.int64), np.empty(0), 0
    a = np.array(triples, np.float64)
    i, j = a[:, 0].astype(np.int64), a[:, 1].astype(np.int64)
    k = np.minimum(i, j) * nv + np.maximum(i, j)
    pos = np.clip(np.searchsorted(keys, k), 0, max(len(keys) - 1, 0))
    ok = keys[pos] == k if len(keys) else np.zeros(len(k), bool)
    return order[pos[ok]], a[ok, 2], int((~ok).sum())

def build_mesh(d, name):
    me = bpy.data.meshes.new(name)
    nv, nf, nl = len(d.v), len(d.face_sizes), len(d.fv)
    me.vertices.add(nv)
    me.loops.add(nl)
    me.polygons.add(nf)
    me.vertices.foreach_set("co", np.array(d.v, np.float32).ravel())
    me.loops.foreach_set("vertex_index", np.array(d.fv, np.int32))
    sizes = np.array(d.face_sizes, np.int32)
    compat.set_face_loops(me, (np.cumsum(sizes) - sizes).astype(np.int32), sizes)
    me.update(calc_edges=True)
    if d.vt and all(t is not None for t in d.fvt):
        uv = me.uv_layers.new(name="UVMap")
        idx = np.concatenate([np.array(t, np.int64) for t in d.fvt]) if nf else np.empty(0, int)
        uv.data.foreach_set("uv", np.array(d.vt, np.float32)[idx].ravel())
    elif d.vt:
        d.warnings.append("some faces have no vt indices: UVs not imported")
    lookup = _edge_lookup(me)
    report = {"knots": 0, "unset": 0, "creases": 0, "corners": 0, "not_edges": 0}
    if d.knots:
        e, val, bad = _edge_values(me, d.knots, lookup)
        ok = values.is_set(val)
        k = np.zeros(len(me.edges), np.float32)
        k[e[ok]] = val[ok]
        a = me.attributes.new(cagemod.KNOT_ATTR, 'FLOAT', 'EDGE')
        a.data.foreach_set("value", k)
        report["knots"], report["unset"] = int(ok.sum()), int((~ok).sum())
        report["not_edges"] += bad
    if d.creases:
        e, val, bad = _edge_values(me, d.creases, lookup)
        c = np.zeros(len(me.edges), np.float32)
        c[e] = crease_from_sharpness(val)
        compat.set_edge_creases(me, c)
        report["creases"], report["not_edges"] = len(e), report["not_edges"] + bad
    if d.corners:
        a = np.array(d.corners, np.float64)
        c = np.zeros(nv, np.float32)
        c[a[:, 0].astype(np.int64)] = crease_from_sharpness(a[:, 1])
        compat.set_vertex_creases(me, c)
        report["corners"] = len(a)
    me.update()
    return me, report

def _fmt_rows(fmt, arr):
    return "".join(fmt % tuple(r) for r in arr.tolist())

def export_text(me):
    """The OBJ text of a mesh (object-mode data)."""
    c = cagemod.read_mesh(me)
    out = ["# CCNURBS cage: %d vertices, %d faces\n" % (c.num_verts, len(c.face_sizes))]
    co = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", co)
    out.append(_fmt_rows("v %.9g %.9g %.9g\n", co.reshape(-1, 3).astype(np.float64)))
    uv_layer = me.uv_layers.active
    nl = len(c.face_verts)
    if uv_layer is not None and nl:
        uv = np.empty(2 * len(me.loops), np.float32)
        uv_layer.data.foreach_get("uv", uv)
        uv = uv.reshape(-1, 2)
        starts = np.empty(len(me.polygons), np.int32)
        me.polygons.foreach_get("loop_start", starts)
        idx = np.repeat(starts, c.face_sizes) + (np.arange(nl) - np.repeat(
            np.cumsum(c.face_sizes) - c.face_sizes, c.face_sizes))
        uniq, inv = np.unique(uv[idx].view(np.uint64).ravel(), return_inverse=True)
        out.append(_fmt_rows("vt %.9g %.9g\n", uniq.view(np.float32).reshape(-1, 2)
                             .astype(np.float64)))
        corner = np.char.add(np.char.add((c.face_verts + 1).astype(str), "/"),
                             (inv + 1).astype(str))
    else:
        corner = (c.face_verts + 1).astype(str)
    ends = np.cumsum(c.face_sizes)
    for s, e in zip((ends - c.face_sizes).tolist(), ends.tolist()):
        out.append("f " + " ".join(corner[s:e].tolist()) + "\n")
    ev = c.edge_verts.astype(np.int64) + 1
    if c.knots is not None:
        m = values.is_set(c.knots)
        out.append(_fmt_rows("# knot %d %d %.9g\n", np.column_stack(
            [ev[m], c.knots[m].astype(np.float32).astype(np.float64)]).astype(object)))
    if c.edge_creases is not None:
        m = c.edge_creases > 0
        out.append(_fmt_rows("# crease %d %d %.17g\n", np.column_stack(
            [ev[m], cagemod.sharpness(c.edge_creases[m])]).astype(object)))
    if c.vertex_creases is not None:
        m = np.flatnonzero(c.vertex_creases > 0)
        out.append(_fmt_rows("# corner %d %.17g\n", np.column_stack(
            [m + 1, cagemod.sharpness(c.vertex_creases[m])]).astype(object)))
    return "".join(out)

class IMPORT_OT_ccnurbs_obj(bpy.types.Operator, ImportHelper):
    """Import an OBJ cage with its knot intervals, creases, corners and UVs"""
    bl_idname = "import_scene.ccnurbs_obj"
    bl_label = "Import OBJ with Knot Intervals"
    bl_options = {'REGISTER', 'UNDO'}
    filename_ext = ".obj"
    filter_glob: StringProperty(default="*.obj", options={'HIDDEN'})

    def execute(self, context):
        try:
            with open(self.filepath, encoding="utf-8", errors="replace") as fh:
                d = parse(fh.read())
        except (OSError, ValueError) as e:
            self.report({'ERROR'}, "Cannot import %s: %s" % (self.filepath, e))
            return {'CANCELLED'}
        name = os.path.splitext(os.path.basename(self.filepath))[0] or "cage"
        me, rep = build_mesh(d, name)
        ob = bpy.data.objects.new(name, me)
        context.collection.objects.link(ob)
        for o in context.selected_objects:
            o.select_set(False)
        ob.select_set(True)
        context.view_layer.objects.active = ob
        msg = ("Imported %s: %d vertices, %d faces, %d intervals, %d creases, %d corners"
               % (ob.name, len(me.vertices), len(me.polygons), rep["knots"], rep["creases"],
                  rep["corners"]))
        extra = []
        if rep["unset"]:
            extra.append("%d intervals <= 0 / NaN / Inf left unset (= 1)" % rep["unset"])
        if rep["not_edges"]:
            extra.append("%d knot/crease lines name no edge of a face (ignored)"
                         % rep["not_edges"])
        extra += d.warnings[:3]
        self.report({'WARNING'} if extra else {'INFO'}, msg + ("; " + "; ".join(extra)
                                                             if extra else ""))
        return {'FINISHED'}

class EXPORT_OT_ccnurbs_obj(bpy.types.Operator, ExportHelper):
    """Export the active mesh as an OBJ cage with knot intervals, creases, corners and UVs"""
    bl_idname = "export_scene.ccnurbs_obj"
    bl_label = "Export OBJ with Knot Intervals"
    filename_ext = ".obj"
    filter_glob: StringProperty(default="*.obj", options={'HIDDEN'})

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == 'MESH'

    def execute(self, context):
        ob = context.active_object
        if ob.mode == 'EDIT':
            ob.update_from_editmode()
        try:
            text = export_text(ob.data)
            with open(self.filepath, "w", encoding="utf-8") as fh:
                fh.write(text)
        except OSError as e:
            self.report({'ERROR'}, "Cannot write %s: %s" % (self.filepath, e))
            return {'CANCELLED'}
        self.report({'INFO'}, "Exported %s to %s" % (ob.name, self.filepath))
        return {'FINISHED'}

def _menu_import(self, context):
    self.layout.operator(IMPORT_OT_ccnurbs_obj.bl_idname,
                         text="OBJ with knot intervals and creases (.obj)")

def _menu_export(self, context):
    self.layout.operator(EXPORT_OT_ccnurbs_obj.bl_idname,
                         text="OBJ with knot intervals and creases (.obj)")

classes = (IMPORT_OT_ccnurbs_obj, EXPORT_OT_ccnurbs_obj)

def register():
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)

def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)

