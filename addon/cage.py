"""Reads a cage mesh into numpy arrays: positions, polygons, edges, knot intervals, creases.

Two sources: the evaluated input tap of the modifier (tap.py: the mesh after the modifiers above
CCNURBS, true positions in the point attribute "ccn_co"), which the modifier computes from; and
the object's own mesh (object mode: the Mesh; edit mode: the edit BMesh copied into a scratch
Mesh with one C call), which the knot operators act on. Every array is read with foreach_get;
no Python loop runs over elements.

Values, one meaning everywhere: a knot interval <= 0, NaN or Inf is unset (= 1); the library
reads it the same way. Creases are Blender's [0, 1] values; `sharpness()` maps them as Blender's
Subdivision Surface does (10 c^2, OpenSubdiv sharpness).
"""
import hashlib

import bmesh
import bpy
import numpy as np

from . import attrs, compat

KNOT_ATTR = "knot_interval"
SCRATCH_NAME = ".ccnurbs_scratch"


class Cage:
    __slots__ = ("positions", "face_sizes", "face_verts", "loop_edges", "edge_verts", "knots",
                 "material_index", "edge_select", "num_materials", "edge_creases",
                 "vertex_creases", "extras")

    @property
    def num_verts(self):
        return len(self.positions)

    @property
    def num_edges(self):
        return len(self.edge_verts)

    def loose_counts(self):
        """(vertices in no face, edges in no face): computed here, whatever the library says."""
        used_v = np.zeros(self.num_verts, bool)
        used_v[self.face_verts] = True
        used_e = np.zeros(self.num_edges, bool)
        used_e[self.loop_edges] = True
        return int((~used_v).sum()), int((~used_e).sum())

    def loose_edge_ends(self):
        """Face vertices at an end of an edge in no face: Subdivision Surface makes them infinitely
        sharp (Blender's subdiv_converter_mesh.cc, infinite_sharp_vertices_map), whatever Use
        Creases says, so a face vertex with a loose edge is a corner of the surface."""
        used_e = np.zeros(self.num_edges, bool)
        used_e[self.loop_edges] = True
        ends = np.zeros(self.num_verts, bool)
        ends[self.edge_verts[~used_e].ravel()] = True
        on_face = np.zeros(self.num_verts, bool)
        on_face[self.face_verts] = True
        return ends & on_face  # (the others are loose.py's: no surface there to sharpen)

    def topology_keys(self, *settings, creases=False, memo=None):
        """(plan key, faces key): hashes of everything a plan depends on except positions
        (polygons, edges, intervals, material indices, settings and, with Use Creases,
        creases), and the same without the intervals: the key of the proxy's topology
        (intervals change the plan but not the limit mesh's faces). One pass over the arrays.
        memo (a dict kept by the caller per cage): when every hashed input equals the last
        call's, its keys are returned without hashing (a position update); otherwise it starts
        afresh, so what the caller keeps in it belongs to this topology."""
        inputs = (self.face_sizes, self.face_verts, self.edge_verts, self.material_index,
                  self.knots) + ((self.edge_creases, self.vertex_creases) if creases else ())
        sig = (len(self.positions), settings, creases)
        if memo is not None and memo.get("sig") == sig and _same(memo["inputs"], inputs):
            return memo["keys"]
        keys = self._hash_topology(settings, creases)
        if memo is not None:
            memo.clear()
            memo.update(sig=sig, keys=keys,
                        inputs=tuple(None if a is None else np.array(a) for a in inputs))
        return keys

    def _hash_topology(self, settings, creases):
        base = hashlib.blake2b(digest_size=16)
        for a in (self.face_sizes, self.face_verts, self.edge_verts, self.material_index):
            base.update(np.ascontiguousarray(a).tobytes())
            base.update(b"|")
        tail = b""
        if creases:
            for a in (self.edge_creases, self.vertex_creases):
                tail += b"C" + (a.tobytes() if a is not None else b"-")
        tail += repr((len(self.positions),) + settings).encode()
        keys = []
        for knots in (True, False):
            h = base.copy()
            if knots:
                h.update(b"K" + (self.knots.tobytes() if self.knots is not None else b"-"))
            h.update(tail)
            keys.append(h.hexdigest())
        return tuple(keys)

    def position_key(self):
        return hashlib.blake2b(self.positions.tobytes(), digest_size=16).hexdigest()


def _same(old, new):
    """Equal arrays (or both None), input by input."""
    if len(old) != len(new):
        return False
    for a, b in zip(old, new):
        if a is None or b is None:
            if a is not b:
                return False
            continue
        b = np.asarray(b)
        if a.shape != b.shape or a.dtype != b.dtype or not np.array_equal(a, b):
            return False
    return True


def sharpness(creases):
    """Blender crease c in [0, 1] -> OpenSubdiv sharpness 10 c^2 (Blender's Subdivision Surface
    mapping, `BKE_subdiv_crease_to_sharpness_f`); None stays None."""
    if creases is None:
        return None
    c = np.clip(np.nan_to_num(creases, nan=0.0), 0.0, 1.0)
    return 10.0 * c * c


_scratch = [SCRATCH_NAME]  # actual name (a library may already use SCRATCH_NAME)


def _scratch_mesh():
    me = bpy.data.meshes.get(_scratch[0])
    if me is None or me.library is not None:
        me = bpy.data.meshes.new(SCRATCH_NAME)
        _scratch[0] = me.name
    return me


def source_mesh(obj, editmesh=True):
    """The Mesh holding the object's own current state: its mesh, or (edit mode) a scratch copy
    of the edit BMesh."""
    me = obj.data
    if me.is_editmode and editmesh:
        bm = bmesh.from_edit_mesh(me)
        scratch = _scratch_mesh()
        bm.to_mesh(scratch)
        return scratch
    return me


def knot_attribute(me):
    a = me.attributes.get(KNOT_ATTR)
    if a is not None and a.domain == 'EDGE' and a.data_type == 'FLOAT':
        return a
    return None


def positions(me, position_attr=None):
    nv = len(me.vertices)
    co = np.empty(3 * nv, np.float32)
    a = me.attributes.get(position_attr) if position_attr else None
    if a is not None and a.domain == 'POINT' and a.data_type == 'FLOAT_VECTOR':
        a.data.foreach_get("vector", co)
    else:
        compat.get_array(me, "positions", co)
    return co.reshape(nv, 3).astype(np.float64)


def read_mesh(me, selection=False, position_attr=None, attributes=True, extras=False):
    """attributes=False: positions and topology only (knots, creases None; material 0).
    extras: also the UV maps and point / face attributes the limit mesh carries (attrs.py)."""
    c = Cage()
    ne, nl, nf = len(me.edges), len(me.loops), len(me.polygons)
    c.positions = positions(me, position_attr)
    c.face_sizes = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_total", c.face_sizes)
    c.face_verts = np.empty(nl, np.int32)
    compat.get_array(me, "corner_verts", c.face_verts)
    c.loop_edges = np.empty(nl, np.int32)
    compat.get_array(me, "corner_edges", c.loop_edges)
    starts = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_start", starts)
    packed = np.cumsum(c.face_sizes, dtype=np.int64) - c.face_sizes
    idx = None
    if not np.array_equal(starts, packed):  # corners not stored face by face: gather them
        idx = np.repeat(starts - packed, c.face_sizes) + np.arange(nl)
        c.face_verts, c.loop_edges = c.face_verts[idx], c.loop_edges[idx]
    c.extras = attrs.read(me, idx) if extras and attributes else None
    ev = np.empty(2 * ne, np.int32)
    compat.get_array(me, "edge_verts", ev)
    c.edge_verts = ev.reshape(ne, 2)
    a = knot_attribute(me) if attributes else None
    if a is not None and len(a.data) == ne:
        k = np.empty(ne, np.float32)
        a.data.foreach_get("value", k)
        c.knots = k.astype(np.float64)
    else:
        c.knots = None
    c.edge_creases = compat.edge_creases(me) if attributes else None
    c.vertex_creases = compat.vertex_creases(me) if attributes else None
    c.material_index = np.zeros(nf, np.int32)
    if attributes or compat.VERSION < (4, 0, 0):
        compat.get_array(me, "material_index", c.material_index)
    c.num_materials = len(me.materials)
    if selection:
        s = np.empty(ne, bool)
        compat.get_array(me, "edge_select", s)
        c.edge_select = s
    else:
        c.edge_select = None
    return c


def read(obj, selection=False, editmesh=True):
    """The object's own mesh as a cage (edit mode included): what the knot operators edit."""
    return read_mesh(source_mesh(obj, editmesh), selection)
