"""Keeps the proxies in step with their cages: persistent handlers, plan cache, proxy writes.

One direction only: cage (mesh or edit BMesh) + settings → library plan → proxy mesh → the
Geometry Nodes modifier shows the proxy. The handler never reads what it wrote:

* a content key per proxy (topology+intervals+settings hash : position hash) is stored on the
  proxy mesh; an update whose key equals the stored one does nothing (this also ends the update
  our own write causes, and survives undo, which restores proxy and key together);
* a re-entrancy flag stops nested calls;
* same topology key → the cached plan is evaluated with new positions and only positions and
  normals are rewritten; otherwise a new plan is made and the proxy rebuilt;
* any failure is recorded as the cage's status (shown in the panel); the proxy keeps the previous
  limit; nothing is raised.
"""
import threading
import time
import traceback

import bpy
import numpy as np
from bpy.app.handlers import persistent

from . import cage as cagemod
from . import compat, modifier, native

KEY_PROP = "ccnurbs_key"
TOPO_PROP = "ccnurbs_topology"
RENDER_DELAY = 1.0  # seconds of quiet before render proxies are refreshed

stats = {"handler_calls": 0, "syncs": 0, "rebuilds": 0, "position_updates": 0, "skipped": 0,
         "errors": 0, "internal_errors": 0}
_busy = False
_plans = {}      # (object name, kind) -> (topology key, native.Plan)
_status = {}     # (object name, kind) -> Status
_render_dirty = set()


class Status:
    __slots__ = ("error", "num_verts", "num_faces", "sizes", "seconds", "kind", "levels")

    def __init__(self, kind, levels=0, error=None):
        self.kind, self.levels, self.error = kind, levels, error
        self.num_verts = self.num_faces = 0
        self.sizes = {}
        self.seconds = 0.0


def status(obj, kind='VIEW'):
    return _status.get((obj.name_full, kind))


# ---- writing a proxy ---------------------------------------------------------------------------

def _write_normals(me, res, exact):
    if exact:
        compat.set_vertex_normals(me, res["normals"].astype(np.float32))
    else:
        compat.use_plain_normals(me)


def _write_topology(me, res, cage, exact=True):
    pos = res["positions"].astype(np.float32).ravel()
    fv = res["face_verts"].ravel()
    nv, nf = len(res["positions"]), len(res["face_verts"])
    me.clear_geometry()
    me.vertices.add(nv)
    me.loops.add(4 * nf)
    me.polygons.add(nf)
    me.vertices.foreach_set("co", pos)
    me.loops.foreach_set("vertex_index", fv)
    compat.set_face_loops(me, np.arange(0, 4 * nf, 4, dtype=np.int32), np.full(nf, 4, np.int32))
    me.polygons.foreach_set("use_smooth", np.ones(nf, bool))
    if cage.material_index is not None and len(cage.material_index):
        origin = np.clip(res["face_origin"], 0, len(cage.material_index) - 1)
        me.polygons.foreach_set("material_index", cage.material_index[origin])
    me.update(calc_edges=True)
    _write_normals(me, res, exact)


def _write_positions(me, res, exact=True):
    me.vertices.foreach_set("co", res["positions"].astype(np.float32).ravel())
    me.update()
    _write_normals(me, res, exact)


def _sync_materials(obj, proxy):
    src, dst = obj.data.materials, proxy.data.materials
    if [m for m in src] != [m for m in dst]:
        dst.clear()
        for m in src:
            dst.append(m)


# ---- one cage ----------------------------------------------------------------------------------

def sync_object(obj, kind='VIEW', force=False, cage=None):
    """Brings the cage's viewport ('VIEW') or render ('RENDER') proxy up to date. Returns the
    Status; never raises."""
    s = obj.ccnurbs
    levels = s.levels if kind == 'VIEW' else s.render_levels
    key_name = (obj.name_full, kind)
    st = Status(kind, levels)
    t0 = time.perf_counter()
    try:
        if obj.library is not None:
            return _status.setdefault(key_name, st)
        if modifier.needs_repair(obj):
            modifier.ensure(obj)
        proxy = s.proxy if kind == 'VIEW' else s.render_proxy
        me = proxy.data
        if cage is None:
            main = threading.current_thread() is threading.main_thread()
            cage = cagemod.read(obj, editmesh=main)
        topo = cage.topology_key(levels, *s.option_tuple())
        key = topo + ":" + cage.position_key()
        _sync_materials(obj, proxy)
        old = _status.get(key_name)
        if not force and me.get(KEY_PROP) == key:
            stats["skipped"] += 1
            if old is None or old.error:  # unknown (file just loaded) or fixed by undo
                old = Status(kind, levels)
                old.num_verts, old.num_faces = len(me.vertices), len(me.polygons)
                _status[key_name] = old
            return old
        stats["syncs"] += 1
        cached = _plans.get(key_name)
        if cached is not None and cached[0] == topo:
            plan = cached[1]
        else:
            if cached is not None:
                cached[1].close()
                del _plans[key_name]
            plan = native.Plan(cage.positions, cage.face_sizes, cage.face_verts,
                               cage.edge_verts, cage.knots, scheme=s.scheme, cap=s.cap,
                               boundary=s.boundary_smooth, levels=levels)
            _plans[key_name] = (topo, plan)
        same_topology = (me.get(TOPO_PROP) == topo
                         and len(me.vertices) == plan.sizes["num_verts"]
                         and len(me.polygons) == plan.sizes["num_faces"])
        if same_topology and me.get(KEY_PROP) == key:
            pass  # forced: the proxy is already right
        elif same_topology:
            res = plan.evaluate(cage.positions, topology=False)
            _write_positions(me, res, s.normals == 'EXACT')
            stats["position_updates"] += 1
        else:
            _write_topology(me, plan.evaluate(cage.positions, topology=True), cage,
                            s.normals == 'EXACT')
            stats["rebuilds"] += 1
        me[KEY_PROP] = key
        me[TOPO_PROP] = topo
        st.num_verts, st.num_faces = len(me.vertices), len(me.polygons)
        st.sizes = dict(plan.sizes)
    except native.CCNError as e:
        st.error = str(e)
        stats["errors"] += 1
    except Exception as e:  # never let a handler raise: report it in the panel instead
        st.error = "internal error: %s: %s" % (type(e).__name__, e)
        stats["errors"] += 1
        stats["internal_errors"] += 1
        traceback.print_exc()
    st.seconds = time.perf_counter() - t0
    if st.error and proxy_is_valid(obj, kind):
        p = (s.proxy if kind == 'VIEW' else s.render_proxy).data
        st.num_verts, st.num_faces = len(p.vertices), len(p.polygons)
    _status[key_name] = st
    return st


def proxy_is_valid(obj, kind):
    p = obj.ccnurbs.proxy if kind == 'VIEW' else obj.ccnurbs.render_proxy
    return p is not None and p.data is not None


def sync_render(objects=None):
    """Render proxies of every cage (or of `objects`) at render_levels."""
    for obj in modifier.cages(objects):
        mod = modifier.get_modifier(obj)
        if mod.show_render:
            sync_object(obj, 'RENDER')
    _render_dirty.clear()


def sync_all():
    for obj in modifier.cages():
        sync_object(obj, 'VIEW')


# ---- handlers ----------------------------------------------------------------------------------

def _updated_cages(depsgraph):
    objs, meshes = set(), set()
    for u in depsgraph.updates:
        if not u.is_updated_geometry:
            continue
        idd = u.id.original if u.id.original is not None else u.id
        if isinstance(idd, bpy.types.Object):
            objs.add(idd)
        elif isinstance(idd, bpy.types.Mesh):
            meshes.add(idd)
    if meshes:
        objs.update(o for o in bpy.data.objects if o.data in meshes)
    return [o for o in objs if o.type == 'MESH' and o.ccnurbs.role == 'CAGE'
            and modifier.get_modifier(o) is not None], objs


@persistent
def on_depsgraph_update_post(scene, depsgraph=None):
    global _busy
    if _busy:
        return
    _busy = True
    stats["handler_calls"] += 1
    try:
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        cages, objs = _updated_cages(depsgraph)
        for obj in cages:
            mod = modifier.get_modifier(obj)
            if not mod.show_viewport:
                continue
            st = sync_object(obj, 'VIEW')
            if not st.error:
                _render_dirty.add(obj.name_full)
        from . import overlay
        overlay.on_objects_updated(objs)
        if _render_dirty and not bpy.app.background:
            if bpy.app.timers.is_registered(_render_timer):
                bpy.app.timers.unregister(_render_timer)
            bpy.app.timers.register(_render_timer, first_interval=RENDER_DELAY)
    except Exception:
        stats["internal_errors"] += 1
        traceback.print_exc()
    finally:
        _busy = False


def _render_timer():
    global _busy
    if _busy:
        return 0.2
    _busy = True
    try:
        names = set(_render_dirty)
        sync_render([o for o in bpy.data.objects if o.name_full in names])
    except Exception:
        traceback.print_exc()
    finally:
        _busy = False
    return None


def _guarded(fn):
    global _busy
    if _busy:
        return
    _busy = True
    try:
        fn()
    except Exception:
        stats["internal_errors"] += 1
        traceback.print_exc()
    finally:
        _busy = False


@persistent
def on_load_post(*args):
    for _, plan in _plans.values():
        plan.close()
    _plans.clear()
    _status.clear()
    _render_dirty.clear()
    _guarded(sync_all)


@persistent
def on_undo_redo(*args):
    _guarded(sync_all)


@persistent
def on_render_init(*args):
    _guarded(sync_render)


@persistent
def on_save_pre(*args):
    _guarded(lambda: (sync_all(), sync_render()))


HANDLERS = (("depsgraph_update_post", on_depsgraph_update_post), ("load_post", on_load_post),
            ("undo_post", on_undo_redo), ("redo_post", on_undo_redo),
            ("render_init", on_render_init), ("save_pre", on_save_pre))


def _is_ours(fn, name):
    """A handler of this module, also one left by an earlier load of it (same module name)."""
    return getattr(fn, "__name__", None) == name and getattr(fn, "__module__", None) == __name__


def register():
    for event, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, event)
        for h in [h for h in lst if _is_ours(h, fn.__name__)]:
            lst.remove(h)
        lst.append(fn)


def unregister():
    for event, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, event)
        for h in [h for h in lst if h is fn or _is_ours(h, fn.__name__)]:
            lst.remove(h)
    if bpy.app.timers.is_registered(_render_timer):
        bpy.app.timers.unregister(_render_timer)
    for _, plan in _plans.values():
        plan.close()
    _plans.clear()
    _status.clear()
    _render_dirty.clear()
