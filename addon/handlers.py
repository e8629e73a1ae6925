"""Persistent app handlers: when to read the taps, sync, clean up. Handlers never raise.

* depsgraph_update_post: the cages whose geometry changed → their taps in this depsgraph →
  viewport proxies (Blender re-evaluates at once after our write, before drawing). Also the cheap
  hygiene triggers (hygiene.suspicious, object/group counts).
  Blender < 4.5, interactive: the viewport proxies get Blender's own normals while the cage keeps
  changing and a timer writes the exact ones NORMALS_DELAY after the last change (encoded custom
  normals cost 5x the rest of an update; sync.PENDING). With Analysis > Curvature on
  (interactive), the analysis attributes likewise: the curvatures double the evaluation, so a
  drag costs what it costs without analysis and the colours follow NORMALS_DELAY after it.
* frame_change_post: frame_set, playback and every frame of a render. Viewport depsgraph: the
  viewport proxies of the cages whose input changed (with their analysis, not deferred: a viewport
  render of an animation shows each frame's), then `depsgraph.update()` so the frame shows them. Render depsgraph: the render proxies at Render levels from the render-evaluated taps,
  then `depsgraph.update()` so the engine renders them (headless included); Render levels
  refused for memory are an error of the render (_render_error).
* render_init: Cycles' Persistent Data off for the render (it would keep the first frame's
  surface; _before_render).
* render_complete / render_cancel: render proxies emptied and render plans freed (unless the
  cage stores its render mesh in the file); Persistent Data restored; the render's errors in a
  popup (UI sessions).
* save_pre / save_post: hygiene.collect(); viewport proxies swapped out of the write
  (proxies.py): nothing is rebuilt; the proxies are evaluated again at the next redraw.
* load_post, undo_post, redo_post: hygiene, then every cage re-read.
"""
import traceback

import bpy
from bpy.app.handlers import persistent

from . import compat, hygiene, modifier, overlay, proxies, state, sync, tap

_busy = [False]
_counts = [None]
_saving = [False]  # between save_pre and save_post: the proxies are swapped out, read nothing
_refresh = [False]  # enabled while bpy.data was restricted: refresh at the first chance


def _guarded(fn, *args):
    if _busy[0]:
        return None
    _busy[0] = True
    try:
        return fn(*args)
    except Exception:
        sync.stats["internal_errors"] += 1
        traceback.print_exc()
    finally:
        _busy[0] = False
    return None


def run_collect():
    _, fresh, _ = hygiene.collect()  # a rename needs nothing here: states follow the object
    state.sweep()  # deleted objects' states
    _counts[0] = hygiene.counts()
    return fresh


def _shown(obj, depsgraph):
    mod = modifier.get_modifier(obj)
    if mod is None:
        return False
    if depsgraph.mode == 'RENDER':
        return mod.show_render
    if obj.mode == 'EDIT' and not mod.show_in_editmode:
        return False
    return mod.show_viewport


NORMALS_DELAY = 0.3  # seconds of quiet before deferred normals and analysis are written (UI only)
# Deferred exact normals (sync.PENDING): Blender < 4.5 in an interactive session; deferred
# analysis attributes: every Blender, interactive; [0] = True makes scripts and headless tests
# defer too (they then call write_pending_normals()).
DEFER_IN_BACKGROUND = [False]


def defer_normals():
    return not compat.FREE_NORMALS and (not bpy.app.background or DEFER_IN_BACKGROUND[0])


def defer_analysis():
    """The analysis attributes of an edit's update, once editing pauses (sync.PENDING): in an
    interactive session (and in scripts that ask for it), not in background renders."""
    return not bpy.app.background or DEFER_IN_BACKGROUND[0]


def sync_cages(depsgraph, objs, kind='VIEW', force=False, defer=None, analysis_now=False):
    """Reads the taps of `objs` from `depsgraph` and syncs their `kind` proxies (viewport
    proxies with deferred exact normals where defer_normals() and deferred analysis attributes
    where defer_analysis(), unless defer=False; analysis_now: the analysis is not deferred).
    Returns the number of proxies written."""
    defer_a = kind == 'VIEW' and defer is not False and not analysis_now and defer_analysis()
    defer = kind == 'VIEW' and (defer_normals() if defer is None else defer)
    for o in objs:
        if o.library is not None and modifier.is_cage(o) and sync.status(o, kind) is None:
            sync.linked_cage(o, kind)
    objs = [o for o in objs if modifier.is_cage(o) and o.library is None and _shown(o, depsgraph)]
    if any([modifier.carry_vertex_groups(o) for o in objs]):  # each object's, then one update
        depsgraph.update()  # the taps with the vertex groups the chains now carry
    taps = tap.read(depsgraph, objs)
    written = 0
    for obj in objs:
        cage = taps.get(obj.name_full)
        if cage is None:
            sync.missing_tap(obj, kind)
            continue
        before = sync.stats["syncs"]
        sync.sync_object(obj, kind, cage, force=force, defer_normals=defer,
                         defer_analysis=defer_a)
        written += sync.stats["syncs"] - before
        if kind == 'VIEW' and obj.ccnurbs.store_render_mesh and bpy.app.background:
            sync.sync_object(obj, 'RENDER', cage)  # farm files from scripts: no idle timer here
        elif kind == 'VIEW' and obj.ccnurbs.store_render_mesh:
            state.of(obj).render_dirty = True
    if not bpy.app.background and state.any_flag("render_dirty"):
        if bpy.app.timers.is_registered(_render_timer):
            bpy.app.timers.unregister(_render_timer)
        bpy.app.timers.register(_render_timer, first_interval=RENDER_DELAY)
    # each update: the delay again
    if (defer or defer_a) and not bpy.app.background and state.any_flag("pending_normals"):
        if bpy.app.timers.is_registered(_normals_timer):
            bpy.app.timers.unregister(_normals_timer)
        bpy.app.timers.register(_normals_timer, first_interval=NORMALS_DELAY)
    return written


def write_pending_normals():
    """The exact normals and analysis attributes of every viewport proxy that waits for them
    (sync.PENDING)."""
    objs = sync.pending_normals()
    state.clear_field("pending_normals", False)
    if objs:
        sync_cages(bpy.context.evaluated_depsgraph_get(), objs, 'VIEW', defer=False)


def _normals_timer():
    if _busy[0]:
        return 0.1
    _guarded(write_pending_normals)
    return None


RENDER_DELAY = 1.0  # seconds of quiet before stored render meshes are refreshed (UI only)


def _render_timer():
    if _busy[0]:
        return 0.2
    objs = state.objects_where("render_dirty")
    state.clear_field("render_dirty", False)

    def run():
        dg = bpy.context.evaluated_depsgraph_get()
        sync_cages(dg, [o for o in objs if o.ccnurbs.store_render_mesh], 'RENDER')
    _guarded(run)
    return None


def sync_all(depsgraph=None, force=False):
    dg = depsgraph or bpy.context.evaluated_depsgraph_get()
    return sync_cages(dg, modifier.cages(), 'VIEW', force)


def _updated(depsgraph):
    objs, meshes, geometry = set(), set(), set()
    for u in depsgraph.updates:
        idd = u.id.original if u.id.original is not None else u.id
        if isinstance(idd, bpy.types.Object):
            objs.add(idd)
            if u.is_updated_geometry:
                geometry.add(idd)
        elif isinstance(idd, bpy.types.Mesh) and u.is_updated_geometry:
            meshes.add(idd)
    if meshes:
        extra = {o for o in bpy.data.objects if o.data in meshes}
        objs |= extra
        geometry |= extra
    return objs, geometry


def _is_echo(objs, geometry, depsgraph):
    """The update only re-evaluated cages because the save swapped their proxies back."""
    if not state.any_flag("echo"):
        return False
    cages = {o for o in objs if state.peek(o) is not None and state.peek(o).echo}
    others = {o for o in objs if o not in cages and o.ccnurbs.role
              not in hygiene.PROXY_ROLES}
    meshes = [u for u in depsgraph.updates if isinstance(u.id, bpy.types.Mesh)
              and not u.id.name.startswith(".CCNURBS")]
    state.clear_field("echo", False)
    return not others and not meshes


def _on_update(depsgraph):
    if _refresh[0]:
        _refresh[0] = False
        run_collect()
        sync_all(depsgraph)
    objs, geometry = _updated(depsgraph)
    if _is_echo(objs, geometry, depsgraph):
        return
    fresh = []
    if _counts[0] != hygiene.counts() or any(hygiene.suspicious(o) for o in objs):
        fresh = run_collect()
    sync_cages(depsgraph, [o for o in geometry if o.type == 'MESH' and o not in fresh], 'VIEW')
    if fresh:  # new groups (copies): evaluate them now, then read their taps
        depsgraph.update()
        sync_cages(depsgraph, fresh, 'VIEW')
    overlay.on_objects_updated(geometry)


@persistent
def on_depsgraph_update_post(scene, depsgraph=None):
    sync.stats["handler_calls"] += 1
    if _saving[0]:
        return
    _guarded(_on_update, depsgraph or bpy.context.evaluated_depsgraph_get())


def cages_in(depsgraph):
    """The cages this depsgraph evaluates: those of its scene and those its collection
    instances draw (assets, characters: in no scene themselves)."""
    evaluated = {i.original for i in depsgraph.ids if isinstance(i, bpy.types.Object)}
    return [o for o in modifier.cages() if o in evaluated]


def _on_frame(depsgraph):
    if depsgraph is None:
        return
    if depsgraph.mode == 'RENDER':
        cages = cages_in(depsgraph)
        if sync_cages(depsgraph, cages, 'RENDER'):
            sync.stats["render_frames"] += 1
            depsgraph.update()
        for o in cages:  # a render at other levels than asked for is an error, not silent
            st = sync.status(o, 'RENDER')
            if st is not None and st.error:
                _render_error("%s: Render levels %d not rendered (%s); rendering %s"
                              % (o.name, o.ccnurbs.render_levels, st.error,
                                 "the viewport limit" if modifier.proxy(o, 'VIEW') is not None
                                 and len(modifier.proxy(o, 'VIEW').data.vertices)
                                 else "the cage"))
        return
    # a frame's analysis at once: a viewport render of an animation shows each frame's
    if sync_cages(depsgraph, cages_in(depsgraph), 'VIEW', analysis_now=True):
        depsgraph.update()


@persistent
def on_frame_change_post(scene, depsgraph=None):
    _guarded(_on_frame, depsgraph)


_persistent_off = []  # scenes whose Persistent Data this render turned off (restored after it)
_render_errors = []   # this render's errors, shown in a popup when it ends (UI sessions)


def _render_error(msg):
    """An error of this render: printed at once as Blender prints its errors (what a headless
    render or a farm log shows) and, in the UI, shown in a popup when the render ends (an add-on
    cannot write into the render's own report)."""
    print("Error: CCNURBS: " + msg)
    if msg not in _render_errors:
        _render_errors.append(msg)


def _show_render_errors():
    msgs = list(_render_errors)
    _render_errors.clear()
    wm = bpy.context.window_manager
    if not msgs or bpy.app.background or wm is None or not wm.windows:
        return None  # headless: no popup (bpy as a module has a window it cannot draw in)

    def draw(menu, _context):
        for m in msgs:
            menu.layout.label(text=m, icon='ERROR')
    try:
        with bpy.context.temp_override(window=wm.windows[0]):
            wm.popup_menu(draw, title="CCNURBS: render", icon='ERROR')
    except Exception:  # a timer must not raise; the errors were printed
        sync.stats["internal_errors"] += 1
        traceback.print_exc()
    return None


def _before_render(scene):
    """Cycles with Persistent Data syncs again only what a frame's evaluation reports as updated,
    and the render proxies are written after that evaluation (frame_change_post, then
    `depsgraph.update()`, which clears those reports): every frame would show the surface of the
    first one it synced. So a Cycles render of a file with a cage runs without Persistent Data,
    which is restored when the render ends, and the console says so."""
    r = scene.render if scene is not None else None
    if r is None or not r.use_persistent_data or r.engine != 'CYCLES' or not modifier.cages():
        return
    r.use_persistent_data = False
    _persistent_off.append(scene.name_full)
    print("CCNURBS: %s: Persistent Data is off during this render (each frame's limit surface "
          "must be synced again); it is turned back on when the render ends" % scene.name_full)


@persistent
def on_render_init(scene=None, *args):
    _guarded(_before_render, scene)


def _after_render():
    while _persistent_off:
        scene = bpy.data.scenes.get(_persistent_off.pop())
        if scene is not None:
            scene.render.use_persistent_data = True
    for obj in modifier.cages():
        if not obj.ccnurbs.store_render_mesh and obj.library is None:
            proxies.clear(modifier.proxy(obj, 'RENDER'))
    sync.free_render_plans()
    if _render_errors and not bpy.app.background:  # render handlers may run off the main thread
        bpy.app.timers.register(_show_render_errors, first_interval=0.0)
    elif bpy.app.background:
        _render_errors.clear()


@persistent
def on_render_done(*args):
    _guarded(_after_render)


def _before_save():
    run_collect()
    proxies.detach_for_save([modifier.proxy(o, 'VIEW') for o in modifier.cages()])
    _saving[0] = True


def _after_save():
    _saving[0] = False
    if proxies.reattach_after_save():  # the cages' next update is our own echo
        for o in modifier.cages():
            state.of(o).echo = True


@persistent
def on_save_pre(*args):
    _guarded(_before_save)


@persistent
def on_save_post(*args):
    _guarded(_after_save)


def _reload(forget):
    _saving[0] = False  # a save that failed between save_pre and save_post ends here
    if forget:
        state.forget_all()
    run_collect()
    sync_all()


@persistent
def on_load_post(*args):
    _guarded(_reload, True)


@persistent
def on_undo_redo(*args):
    _guarded(_reload, False)


HANDLERS = (("depsgraph_update_post", on_depsgraph_update_post),
            ("frame_change_post", on_frame_change_post), ("load_post", on_load_post),
            ("undo_post", on_undo_redo), ("redo_post", on_undo_redo),
            ("render_init", on_render_init),
            ("render_complete", on_render_done), ("render_cancel", on_render_done),
            ("save_pre", on_save_pre), ("save_post", on_save_post)) + \
    ((("save_post_fail", on_save_post),) if hasattr(bpy.app.handlers, "save_post_fail") else ())


def _is_ours(fn, name):
    """A handler of this module, also one left by an earlier load of it (same module name)."""
    return getattr(fn, "__name__", None) == name and getattr(fn, "__module__", None) == __name__


def refresh_after_enable():
    """Every surface re-read after the add-on is enabled (a timer: add-ons register while
    bpy.data is restricted; headless, where no timer fires, the first update does it)."""
    if _refresh[0]:
        _refresh[0] = False
        _guarded(_reload, False)
    return None


def register():
    for event, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, event)
        for h in [h for h in lst if _is_ours(h, fn.__name__)]:
            lst.remove(h)
        lst.append(fn)
    _refresh[0] = True
    if isinstance(bpy.data, bpy.types.BlendData):  # enabled from a script or the preferences:
        refresh_after_enable()                       # the data is open, refresh now
    else:  # at start-up bpy.data is restricted while add-ons register: at the first chance
        bpy.app.timers.register(refresh_after_enable, first_interval=0.0)


def unregister():
    for event, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, event)
        for h in [h for h in lst if h is fn or _is_ours(h, fn.__name__)]:
            lst.remove(h)
    for t in (_render_timer, refresh_after_enable, _show_render_errors):
        if bpy.app.timers.is_registered(t):
            bpy.app.timers.unregister(t)
    state.forget_all()
