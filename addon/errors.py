"""Cage errors an artist can act on: what to do about each kind, and a Select button that selects
the offending vertex, edge or face in Edit Mode.

The library names the element by its index in the cage it was given: the mesh after the modifiers
above CCNURBS. Without such modifiers (or with deform-only ones) that is the object's own mesh, and
the element is selected there; otherwise the panel says to apply or disable them first.
"""
import bmesh
import bpy

from . import modifier, sync

ELEM_VERTEX, ELEM_EDGE, ELEM_FACE = 1, 2, 3

# what to do, by the failure's reason (native.REASONS: the library's ccn_reason; the add-on's own)
_ADVICE = {
    "face_repeats_vertex": "Merge by Distance or Mesh > Clean Up > Degenerate Dissolve.",
    "face_too_few_vertices": "Delete this face (it has fewer than 3 corners).",
    "index_out_of_range": "The mesh is inconsistent: Mesh > Clean Up, or re-import it.",
    "nonfinite_coordinate": "Move this vertex to a finite position or delete it.",
    "coordinate_range": "Scale the mesh down: coordinates must stay below 1e300.",
    "nan_sharpness": "Set this element's crease to a number (Shift+E).",
    "valence_limit": "Split this vertex's fan (dissolve some of its edges): at most 1024 edges "
                     "can meet at a vertex.",
    "face_size_limit": "Split this face (Knife, or Poke Faces).",
    "no_faces": "Add faces: only faces are subdivided.",
    "linked_data": "Make a library override (Object > Library Override > Make), append the "
                   "object instead of linking it (File > Append), or make it local "
                   "(Object > Relations > Make Local). Or, in the library file, turn on Store "
                   "Render Mesh in File and save it: the files that link it show that surface.",
    "levels_refused": "Each level needs four times the memory of the one below: lower the "
                      "levels, or close programs that hold memory.",
    "out_of_memory": "Lower the levels: the limit mesh did not fit in memory.",
}


def advice(st):
    """What to do about the status' failure ("" if there is nothing to advise)."""
    return _ADVICE.get(getattr(st, "reason", None) or "", "") if st is not None else ""


def selectable(st):
    """(kind, index, vertex pair or None) of the status' element, or None."""
    if st is None or not st.error or not getattr(st, "element", None):
        return None
    kind, index = st.element
    pair = None
    if kind == ELEM_EDGE:  # an edge is selected by its two vertices
        pair = getattr(st, "element_verts", None)
        if not pair:
            return None
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
        self.report({'INFO'}, "Selected %s: %s" % (what, advice(sync.status(obj, 'VIEW'))
                                                   or "see the panel"))
        return {'FINISHED'}


classes = (OBJECT_OT_ccnurbs_select_error,)
