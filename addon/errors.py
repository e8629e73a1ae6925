"""Cage errors an artist can act on: what to do about each kind, and a Select button that selects
the offending vertex, edge or face in Edit Mode.

The library names the element by its index in the cage it was given: the mesh after the modifiers
above CCNURBS. Without such modifiers (or with deform-only ones) that is the object's own mesh, and
the element is selected there; otherwise the panel says to apply or disable them first.
"""
import re

import bmesh
import bpy

from . import modifier, sync

ELEM_VERTEX, ELEM_EDGE, ELEM_FACE = 1, 2, 3

# (pattern in the library's message, what to do)
_ADVICE = (
    ("repeats vertex", "Merge by Distance or Mesh > Clean Up > Degenerate Dissolve."),
    ("vertices (at least 3 needed)", "Delete this face (it has fewer than 3 corners)."),
    ("non-finite coordinate", "Move this vertex to a finite position or delete it."),
    ("coordinate beyond", "Scale the mesh down: coordinates must stay below 1e300."),
    ("NaN crease", "Set this element's crease to a number (Shift+E)."),
    ("valence", "Split this vertex's fan (dissolve some of its edges): at most 1024 edges "
                "can meet at a vertex."),
    ("sides; the limit surface", "Split this face (Knife, or Poke Faces)."),
    ("cage has no faces", "Add faces: only faces are subdivided."),
    ("the add-on cannot write the limit surface into linked data",
     "Append the object instead of linking it (File > Append), or make it local (Object > "
     "Relations > Make Local)."),
    ("of memory is free", "Each level needs four times the memory of the one below: lower the "
                          "levels, or close programs that hold memory."),
    ("out of memory", "Lower the levels: the limit mesh did not fit in memory."),
)


def advice(message):
    for pat, what in _ADVICE:
        if pat in message:
            return what
    return ""


def selectable(st):
    """(kind, index, vertex pair or None) of the status' element, or None."""
    if st is None or not st.error or not getattr(st, "element", None):
        return None
    kind, index = st.element
    pair = None
    if kind == ELEM_EDGE:  # edges are named by their vertices: "edge 7-8 ..."
        m = re.search(r"edge (\d+)-(\d+)", st.error) or re.search(r"vertices (\d+)-(\d+)", st.error)
        if not m:
            return None
        pair = (int(m.group(1)), int(m.group(2)))
    elif kind not in (ELEM_VERTEX, ELEM_FACE) or index < 0:
        return None
    return kind, index, pair


class OBJECT_OT_ccnurbs_select_error(bpy.types.Operator):
    """Select the vertex, edge or face the cage error names (Edit Mode)"""
    bl_idname = "object.ccnurbs_select_error"
    bl_label = "Select"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == 'MESH' and selectable(sync.status(ob, 'VIEW'))

    def execute(self, context):
        obj = context.active_object
        kind, index, pair = selectable(sync.status(obj, 'VIEW'))
        if not modifier.stack_keeps_topology(obj):
            self.report({'WARNING'}, "The error is in the mesh after the modifiers above CCNURBS; "
                        "apply or disable them to find the element in the mesh itself")
            return {'CANCELLED'}
        if obj.mode != 'EDIT':
            bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(obj.data)
        for seq in (bm.verts, bm.edges, bm.faces):
            for x in seq:
                x.select = False
        bm.verts.ensure_lookup_table()
        bm.faces.ensure_lookup_table()
        what = None
        if kind == ELEM_VERTEX and index < len(bm.verts):
            bm.verts[index].select = True
            bm.select_mode = {'VERT'}
            what = "vertex %d" % index
        elif kind == ELEM_FACE and index < len(bm.faces):
            bm.faces[index].select = True
            bm.select_mode = {'FACE'}
            what = "face %d" % index
        elif kind == ELEM_EDGE and pair and max(pair) < len(bm.verts):
            a, b = bm.verts[pair[0]], bm.verts[pair[1]]
            for e in a.link_edges:
                if e.other_vert(a) is b:
                    e.select = True
                    what = "edge %d-%d" % pair
            a.select = b.select = True
            bm.select_mode = {'EDGE'}
        bm.select_flush_mode()
        bmesh.update_edit_mesh(obj.data)
        if what is None:
            self.report({'WARNING'}, "The element the error names is not in this mesh")
            return {'CANCELLED'}
        self.report({'INFO'}, "Selected %s: %s" % (what, advice(sync.status(obj, 'VIEW').error)
                                                   or "see the panel"))
        return {'FINISHED'}


classes = (OBJECT_OT_ccnurbs_select_error,)
