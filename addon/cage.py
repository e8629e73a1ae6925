"""Reads a cage mesh into numpy arrays: positions, polygons, edges, knot intervals.

Object mode reads the Mesh with foreach_get. Edit mode reads through bmesh: the edit BMesh is
copied into a scratch Mesh (`BMesh.to_mesh`, one C call) and read the same way, so no Python
loop ever runs over vertices or edges.
"""
import hashlib

import bmesh
import bpy
import numpy as np

KNOT_ATTR = "knot_interval"
SCRATCH_NAME = ".ccnurbs_scratch"


class Cage:
    __slots__ = ("positions", "face_sizes", "face_verts", "loop_edges", "edge_verts", "knots",
                 "material_index", "edge_select", "num_materials")

    @property
    def num_verts(self):
        return len(self.positions)

    @property
    def num_edges(self):
        return len(self.edge_verts)

    def topology_key(self, *settings):
        """Hash of everything a plan (and the proxy's topology) depends on except positions:
        polygons, edges, intervals, material indices, settings."""
        h = hashlib.blake2b(digest_size=16)
        for a in (self.face_sizes, self.face_verts, self.edge_verts, self.material_index):
            h.update(np.ascontiguousarray(a).tobytes())
            h.update(b"|")
        h.update(b"K" + (self.knots.tobytes() if self.knots is not None else b"-"))
        h.update(repr((len(self.positions),) + settings).encode())
        return h.hexdigest()

    def position_key(self):
        return hashlib.blake2b(self.positions.tobytes(), digest_size=16).hexdigest()


_scratch = [SCRATCH_NAME]  # actual name (a library may already use SCRATCH_NAME)


def _scratch_mesh():
    me = bpy.data.meshes.get(_scratch[0])
    if me is None or me.library is not None:
        me = bpy.data.meshes.new(SCRATCH_NAME)
        _scratch[0] = me.name
    return me


def source_mesh(obj, editmesh=True):
    """The Mesh holding the cage's current state: the object's mesh, or (edit mode) a scratch
    copy of the edit BMesh. editmesh=False reads the Mesh even in edit mode (render threads:
    Blender flushes edit data before rendering; the scratch copy would write bpy.data)."""
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


def read_mesh(me, selection=False):
    c = Cage()
    nv, ne, nl, nf = len(me.vertices), len(me.edges), len(me.loops), len(me.polygons)
    co = np.empty(3 * nv, np.float32)
    me.vertices.foreach_get("co", co)
    c.positions = co.reshape(nv, 3).astype(np.float64)
    c.face_sizes = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_total", c.face_sizes)
    c.face_verts = np.empty(nl, np.int32)
    me.loops.foreach_get("vertex_index", c.face_verts)
    c.loop_edges = np.empty(nl, np.int32)
    me.loops.foreach_get("edge_index", c.loop_edges)
    starts = np.empty(nf, np.int32)
    me.polygons.foreach_get("loop_start", starts)
    packed = np.cumsum(c.face_sizes, dtype=np.int64) - c.face_sizes
    if not np.array_equal(starts, packed):  # corners not stored face by face: gather them
        idx = np.repeat(starts - packed, c.face_sizes) + np.arange(nl)
        c.face_verts, c.loop_edges = c.face_verts[idx], c.loop_edges[idx]
    ev = np.empty(2 * ne, np.int32)
    me.edges.foreach_get("vertices", ev)
    c.edge_verts = ev.reshape(ne, 2)
    a = knot_attribute(me)
    if a is not None:
        k = np.empty(ne, np.float32)
        a.data.foreach_get("value", k)
        c.knots = k.astype(np.float64)
    else:
        c.knots = None
    c.material_index = np.empty(nf, np.int32)
    me.polygons.foreach_get("material_index", c.material_index)
    c.num_materials = len(me.materials)
    if selection:
        s = np.empty(ne, bool)
        me.edges.foreach_get("select", s)
        c.edge_select = s
    else:
        c.edge_select = None
    return c


def read(obj, selection=False, editmesh=True):
    """The cage of a mesh object (edit mode included)."""
    return read_mesh(source_mesh(obj, editmesh), selection)
