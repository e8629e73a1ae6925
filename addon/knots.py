"""Knot intervals: edge rings and the edit-mode operators that set, select and clear them.

An interval belongs to an edge ring (opposite edges of every quad carry the same value), so the
operators always act on whole rings. Values live in the EDGE float attribute `knot_interval`
(absent, <= 0, NaN or Inf = unset = 1; values.py). Ring labels are computed with numpy from the
cage arrays; the values are written through the edit BMesh layer, only on the edges that change.
"""
import bmesh
import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty

from . import cage as cagemod
from . import values

KNOT_ATTR = cagemod.KNOT_ATTR


def quad_opposite_pairs(face_sizes, loop_edges):
    """(k, 2) edge index pairs opposite in a quad (the links of edge rings)."""
    starts = np.cumsum(face_sizes, dtype=np.int64) - face_sizes
    q = starts[face_sizes == 4]
    if not len(q):
        return np.empty((0, 2), np.int64)
    e = loop_edges[q[:, None] + np.arange(4)]
    return np.concatenate([e[:, [0, 2]], e[:, [1, 3]]]).astype(np.int64)


def ring_labels(num_edges, pairs):
    """Connected components of the 'opposite in a quad' relation: label[e] = smallest edge
    index of e's ring (Shiloach-Vishkin style hooking + pointer jumping, all numpy)."""
    lab = np.arange(num_edges, dtype=np.int64)
    if not len(pairs):
        return lab
    a, b = pairs[:, 0], pairs[:, 1]
    while True:
        la, lb = lab[a], lab[b]
        m = np.minimum(la, lb)
        new = lab.copy()
        np.minimum.at(new, la, m)
        np.minimum.at(new, lb, m)
        while True:
            nxt = new[new]
            if np.array_equal(nxt, new):
                break
            new = nxt
        if np.array_equal(new, lab):
            return lab
        lab = new


def rings_of(cage, edges):
    """Sorted edge indices of every ring containing one of `edges` (bool mask or indices)."""
    labels = ring_labels(cage.num_edges, quad_opposite_pairs(cage.face_sizes, cage.loop_edges))
    sel = np.asarray(edges)
    if sel.dtype == bool:
        sel = np.flatnonzero(sel)
    if not len(sel):
        return np.empty(0, np.int64), 0
    wanted = np.unique(labels[sel])
    return np.flatnonzero(np.isin(labels, wanted)), len(wanted)


def _edit_objects(context):
    objs = getattr(context, "objects_in_mode_unique_data", None) or [context.edit_object]
    return [o for o in objs if o is not None and o.type == 'MESH' and o.data.is_editmode]


def _selected_rings(obj):
    """(bm, ring edge indices, number of rings, number of selected edges) of an edit object."""
    cage = cagemod.read(obj, selection=True)
    idx, nrings = rings_of(cage, cage.edge_select)
    bm = bmesh.from_edit_mesh(obj.data)
    bm.edges.ensure_lookup_table()
    if len(bm.edges) != cage.num_edges:  # cannot happen: the scratch copy is the BMesh
        raise RuntimeError("edge count mismatch between BMesh and its copy")
    return bm, idx, nrings, int(cage.edge_select.sum())


def _fmt(v):
    return ("%g" % v)


class _EditMeshOp:
    @classmethod
    def poll(cls, context):
        return context.mode == 'EDIT_MESH' and context.edit_object is not None


class MESH_OT_ccnurbs_set_knot_interval(_EditMeshOp, bpy.types.Operator):
    """Set the knot interval of the selected edges and of their whole edge rings"""
    bl_idname = "mesh.ccnurbs_set_knot_interval"
    bl_label = "Set Knot Interval"
    bl_options = {'REGISTER', 'UNDO'}

    value: FloatProperty(name="Interval", description="Knot interval of the rings: a positive "
                         "finite number (only ratios matter; 1 = uniform). Other values are "
                         "refused with a message; Clear resets to 1", default=1.0,
                         soft_min=0.01, soft_max=100.0, precision=3)

    def invoke(self, context, event):
        if not self.properties.is_property_set("value"):
            self.value = context.scene.ccnurbs_tools.knot_value
        return self.execute(context)

    def execute(self, context):
        refused = values.check_storable(self.value)
        if refused:
            self.report({'ERROR'}, refused)
            return {'CANCELLED'}
        total_edges = total_rings = changed = 0
        for obj in _edit_objects(context):
            bm, idx, nrings, nsel = _selected_rings(obj)
            if not len(idx):
                continue
            layer = bm.edges.layers.float.get(KNOT_ATTR) or bm.edges.layers.float.new(KNOT_ATTR)
            edges = bm.edges
            v = float(self.value)
            for i in idx.tolist():  # only the edges that change; BMesh has no bulk setter
                edges[i][layer] = v
            bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)
            total_edges += len(idx)
            total_rings += nrings
            changed += 1
        if not total_edges:
            self.report({'WARNING'}, "Select at least one edge")
            return {'CANCELLED'}
        self.report({'INFO'}, "Knot interval %s set on %d edges in %d ring%s%s"
                    % (_fmt(self.value), total_edges, total_rings, "s" * (total_rings != 1),
                       (" (%d objects)" % changed) if changed > 1 else ""))
        return {'FINISHED'}


class MESH_OT_ccnurbs_select_ring(_EditMeshOp, bpy.types.Operator):
    """Extend the selection to the whole edge rings of the selected edges"""
    bl_idname = "mesh.ccnurbs_select_ring"
    bl_label = "Select Knot Ring"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        total = rings = 0
        switched = False
        ts = context.tool_settings
        if not ts.mesh_select_mode[1]:
            ts.mesh_select_mode = (False, True, False)
            switched = True
        for obj in _edit_objects(context):
            bm, idx, nrings, nsel = _selected_rings(obj)
            if not len(idx):
                continue
            if switched:
                bm.select_mode = {'EDGE'}
            edges = bm.edges
            for i in idx.tolist():
                edges[i].select_set(True)
            bm.select_flush_mode()
            bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)
            total += len(idx) - nsel
            rings += nrings
        if not rings:
            self.report({'WARNING'}, "Select at least one edge")
            return {'CANCELLED'}
        self.report({'INFO'}, "Selected %d ring%s (%d more edges)%s"
                    % (rings, "s" * (rings != 1), total,
                       ", switched to edge select mode" if switched else ""))
        return {'FINISHED'}


class MESH_OT_ccnurbs_clear_knot_interval(_EditMeshOp, bpy.types.Operator):
    """Reset knot intervals to 1 (unset): on the rings of the selected edges, or everywhere"""
    bl_idname = "mesh.ccnurbs_clear_knot_interval"
    bl_label = "Clear Knot Interval"
    bl_options = {'REGISTER', 'UNDO'}

    scope: EnumProperty(name="Scope", items=(
        ('SELECTED', "Selected Rings", "Clear the rings of the selected edges"),
        ('ALL', "All", "Remove the knot_interval attribute: every interval becomes 1")),
        default='SELECTED')

    def execute(self, context):
        total = rings = objects = 0
        for obj in _edit_objects(context):
            bm = bmesh.from_edit_mesh(obj.data)
            layer = bm.edges.layers.float.get(KNOT_ATTR)
            if layer is None:
                continue
            if self.scope == 'ALL':
                total += len(bm.edges)
                bm.edges.layers.float.remove(layer)
                objects += 1
            else:
                bm, idx, nrings, nsel = _selected_rings(obj)
                layer = bm.edges.layers.float.get(KNOT_ATTR)
                edges = bm.edges
                for i in idx.tolist():
                    edges[i][layer] = 0.0
                total += len(idx)
                rings += nrings
                objects += bool(len(idx))
            bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)
        if not objects:
            self.report({'WARNING'}, "No knot intervals to clear" if self.scope == 'ALL'
                        else "No knot intervals set / no edge selected")
            return {'CANCELLED'}
        if self.scope == 'ALL':
            self.report({'INFO'}, "Removed knot intervals of %d edges (all intervals are 1)"
                        % total)
        else:
            self.report({'INFO'}, "Cleared knot intervals of %d edges in %d ring%s"
                        % (total, rings, "s" * (rings != 1)))
        return {'FINISHED'}


classes = (MESH_OT_ccnurbs_set_knot_interval, MESH_OT_ccnurbs_select_ring,
           MESH_OT_ccnurbs_clear_knot_interval)
