"""The add-on's session state of each object, in one place.

Everything the add-on remembers about an object between updates lives in one `ObjectState`,
found by the object's stable id (`key`), not by its name: a rename changes nothing here, a copy
(Shift+D, Copy to Selected, append) is another object with a state of its own, and `forget` is
the one path that drops an object's state (closing its plans). `sweep` drops the states of
objects that no longer exist.

What a state holds (each module reads and writes its own fields):
* sync.py: `plans` {kind: (topology key, plan)}, `status` {kind: Status}, `key_memo` {kind:
  {...}} (the last topology keys and their inputs), `pending_normals` (the viewport proxy waits
  for its exact normals);
* attrs.py: `uv` (data hash, UV channels) of the last cage read;
* tap.py: `object_mode` (the last Object Mode cage's edges, intervals, creases, materials and
  extras, for Edit Mode reads) and `edit_note`;
* hygiene.py: `removed_note` (a second CCNURBS modifier went);
* overlay.py: `overlay` (the interval overlay's arrays and batch) and `overlay_pending`;
  `ev_marks` (Analysis > Cap Status: the extraordinary points' positions and colours, written
  by sync.py);
* handlers.py: `render_dirty` (its stored render mesh is due) and `echo` (its next update is
  the save's own).

The id: `ID.session_uid` (Blender 4.2+: unique in the session, kept by renames and undo). Blender
3.4 does not expose it; there the id is the object's address (`as_pointer()`, kept by renames;
undo and file loads forget every state, handlers.py), and `sweep` drops a deleted object's state
before the address can be reused.

Nothing here is saved in files.
"""
import bpy

HAS_SESSION_UID = hasattr(bpy.types.ID, "session_uid")


class ObjectState:
    __slots__ = ("plans", "status", "key_memo", "pending_normals", "uv", "object_mode",
                 "edit_note", "removed_note", "overlay", "overlay_pending", "render_dirty",
                 "echo", "ev_marks")

    def __init__(self):
        self.plans, self.status, self.key_memo = {}, {}, {}
        self.pending_normals = self.overlay_pending = self.render_dirty = self.echo = False
        self.uv = self.object_mode = self.edit_note = self.removed_note = self.overlay = None
        self.ev_marks = None

    def close_plans(self, kinds=None):
        for kind in list(self.plans) if kinds is None else kinds:
            entry = self.plans.pop(kind, None)
            if entry is not None:
                entry[1].close()


_states = {}  # key(obj) -> ObjectState


def key(obj):
    return obj.session_uid if HAS_SESSION_UID else obj.as_pointer()


def of(obj):
    """The object's state, made if it has none."""
    k = key(obj)
    st = _states.get(k)
    if st is None:
        st = _states[k] = ObjectState()
    return st


def peek(obj):
    """The object's state, or None."""
    return _states.get(key(obj))


def items():
    """(key, state) of every object with a state."""
    return list(_states.items())


def any_flag(flag):
    return any(getattr(st, flag) for st in _states.values())


def objects_where(flag):
    """The live objects whose state has `flag` set."""
    keys = {k for k, st in _states.items() if getattr(st, flag)}
    return [o for o in bpy.data.objects if key(o) in keys] if keys else []


def forget(obj, kinds=None):
    """Drops the object's plans of `kinds` (all: its whole state)."""
    st = peek(obj)
    if st is None:
        return
    if kinds is None:
        st.close_plans()
        del _states[key(obj)]
        return
    st.close_plans(kinds)
    for kind in kinds:
        st.status.pop(kind, None)
        st.key_memo.pop(kind, None)


def forget_all():
    for st in _states.values():
        st.close_plans()
    _states.clear()


def sweep():
    """Drops the states of objects that no longer exist."""
    if not _states:
        return
    live = {key(o) for o in bpy.data.objects}
    for k in [k for k in _states if k not in live]:
        _states.pop(k).close_plans()


def clear_field(name, value=None):
    """Resets one field in every state (e.g. the overlay when it is turned off)."""
    for st in _states.values():
        setattr(st, name, value)
