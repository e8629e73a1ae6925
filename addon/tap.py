"""Reads the modifier's input tap from an evaluated depsgraph (see modifier.py).

The CCNURBS group hands its input (the cage after every modifier above it, attributes
propagated) to Python as one collapsed instance carrying the point attribute "ccn_co". After an
evaluation it is read:

* 5.0+: `Object.evaluated_geometry().instance_references()` of each cage (per object; on
  4.3-4.5 each call leaks a block, compat.has_evaluated_geometry);
* before: `depsgraph.object_instances`, the one walk Blender offers, always to its end (a walk
  left early leaks its dupli list); instances of other objects are skipped unread. A cage
  drawn by a collection instance is the instance object of its tap's instance there.

The temporary objects of `object_instances` are only valid during their iteration step, so the
cage arrays are read there and then.

Edit mode on 4.x/5.x: every mesh Blender evaluates from an edit mesh keeps a link to the edit
BMesh, and Python's attribute API then reads the BMesh's layers instead of the mesh's own
(measured: no attribute is listed on the tap). Positions and topology are arrays and read
correctly. Intervals and creases then come from the edit mesh itself when the stack above keeps
its edges (no stack, or deform-only: Armature, shape keys, Lattice, Displace), else from the last
Object Mode tap while the edge topology is unchanged (moving vertices), else they are dropped
until Object Mode; both last cases put a note in the panel (`edit_note`).
"""
import numpy as np

from . import cage as cagemod
from . import compat, modifier, state
from .modifier import TAP_ATTR

# In each cage's state (state.py): object_mode, the last Object Mode read (edge_verts bytes,
# knots, edge creases, vertex creases, material indices, face_verts bytes, UV maps and
# attributes), and edit_note, the note shown in the panel.


def _is_tap(me):
    if me is None or not hasattr(me, "attributes"):
        return False
    return me.attributes.get(TAP_ATTR) is not None or bool(getattr(me, "is_editmode", False))


def _read(obj, me):
    ost = state.of(obj)
    ost.edit_note = None
    if not getattr(me, "is_editmode", False):
        c = cagemod.read_mesh(me, extras=True)
        ost.object_mode = (c.edge_verts.tobytes(), c.knots, c.edge_creases, c.vertex_creases,
                           c.material_index, c.face_verts.tobytes(), c.extras)
        return c
    own = cagemod.read_mesh(cagemod.source_mesh(obj), extras=True)  # the edit mesh itself:
    # right when the stack keeps its edges (UVs and attributes: its corners)
    if (modifier.stack_keeps_topology(obj) and len(me.vertices) == len(own.positions)
            and len(me.loops) == len(own.face_verts) and len(me.edges) == len(own.edge_verts)):
        # deform-only stack: the elements are the edit mesh's, in its order; the tap's element
        # arrays would be read one element at a time (edit-mode meshes, see above)
        own.positions = cagemod.positions(me)
        return own
    c = cagemod.read_mesh(me, attributes=False, extras=True)
    if np.array_equal(own.face_verts, c.face_verts):
        c.extras = own.extras
    if len(own.edge_verts) == len(c.edge_verts) and np.array_equal(own.edge_verts, c.edge_verts):
        c.knots, c.edge_creases, c.vertex_creases = own.knots, own.edge_creases, \
            own.vertex_creases
        if len(own.material_index) == len(c.material_index):
            c.material_index = own.material_index
        return c
    cached = ost.object_mode
    if cached is not None and cached[5] == c.face_verts.tobytes() and c.extras is None:
        c.extras = cached[6]
    if cached is not None and cached[0] == c.edge_verts.tobytes():
        c.knots, c.edge_creases, c.vertex_creases = cached[1:4]
        if len(cached[4]) == len(c.material_index):
            c.material_index = cached[4]
    else:
        c.knots = c.edge_creases = c.vertex_creases = None
    ost.edit_note = ("Edit Mode: interval and crease edits through the modifiers above "
                       "show in Object Mode (Blender %d.x Python limit)" % compat.VERSION[0])
    return c


def read(depsgraph, objects):
    """{object.name_full: Cage} for the given cage objects whose tap is in `depsgraph` (an object
    whose modifier is off, or whose tap a modifier below realized, is missing)."""
    objects = [o for o in objects]
    found = {}
    if not objects:
        return found
    if compat.has_evaluated_geometry():
        for obj in objects:
            ev = obj.evaluated_get(depsgraph)
            try:
                refs = ev.evaluated_geometry().instance_references()
            except (RuntimeError, ReferenceError, TypeError):  # not evaluated in this graph
                continue
            for ref in refs:
                me = getattr(ref, "mesh", None)
                if _is_tap(me):
                    found[obj.name_full] = _read(obj, me)
                    break
        return found
    wanted = {o.name_full: o for o in objects}
    for inst in depsgraph.object_instances:
        if not inst.is_instance:
            continue
        # the tap's instancer: the cage itself (parent), or, where a collection instance draws
        # the cage, the cage as the instance object under that instancer
        parent, io = inst.parent, inst.instance_object
        name = parent.original.name_full if parent is not None else None
        if name not in wanted and io is not None:
            name = io.original.name_full
        if name not in wanted or name in found:
            continue
        me = inst.object.data
        if _is_tap(me):
            found[name] = _read(wanted[name], me)
    # no early break: a loop left before its end leaks the depsgraph's dupli list (measured on
    # 3.4 and 4.5: "Not freed memory blocks", duplilist and dupli object, at exit)
    return found
