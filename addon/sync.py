"""Keeps the proxies in step with their cages: plan cache, status, one cage at a time.

One direction only: the modifier's input tap (the cage after the stack above; tap.py) +
settings → library plan → proxy mesh → the Geometry Nodes modifier shows the proxy. Nothing here
reads what it wrote:

* a content key per proxy (topology+intervals+settings hash : position hash) is stored on the
  proxy mesh; an update whose key equals the stored one does nothing (this also ends the update
  our own write causes, and survives undo, which restores proxy and key together);
* same topology key → the cached plan is evaluated with new positions and only positions and
  normals are rewritten; otherwise a new plan is made, and the proxy is rebuilt only if its
  faces change (an interval edit keeps them: positions and normals are rewritten in place);
* any failure is recorded as the cage's status (shown in the panel) and nothing is raised; the
  proxy keeps the previous limit, except for a cage without faces, which shows itself.

Each change costs two evaluations of the cage object (the one that produced the tap, and the one
Blender runs at once after our write, reading the new proxy): Python cannot run inside an
evaluation (measured in README "Design notes").
"""
import time
import traceback

import bpy
import numpy as np

from . import analysis, attrs, loose, memory, modifier, native, proxies, state
from . import cage as cagemod

# Creases: edge and vertex sharpness 10 c^2 (Blender's Subdivision Surface mapping) go to
# ccn_cage.edge_creases / vertex_creases when the cage's Use Creases is on (the default).

stats = {"handler_calls": 0, "syncs": 0, "rebuilds": 0, "position_updates": 0, "skipped": 0, "errors": 0,
         "internal_errors": 0, "render_frames": 0, "changed_only": 0}
# changed_only: interval edits whose plan wrote only the outputs the edit changed
# Per cage and kind ('VIEW', 'RENDER'), in its state (state.py): plans (topology key, native.Plan),
# status (Status), key_memo (the last topology keys, their inputs (cage.py), and "loose": the
# loose counts of that topology).
# What an edit's update leaves for when editing pauses, with this key suffix on the proxy and
# its state marked `pending_normals` (handlers.py writes the rest once editing pauses):
# * exact normals on Blender < 4.5 (defer_normals: encoded custom normals, whose write and every
#   evaluation of the cage afterwards cost 5x the rest of an update; meanwhile Blender's own);
# * the analysis attributes (defer_analysis: the curvatures double the library's evaluation, so
#   while a vertex is dragged the update costs what it costs without analysis, and the colours
#   follow once the drag pauses; meanwhile they show the last computed curvature).
PENDING = "|normals pending"


class Status:
    __slots__ = ("error", "num_verts", "num_faces", "sizes", "seconds", "kind", "levels",
                 "showing", "loose", "element", "key", "reason", "element_verts")

    def __init__(self, kind, levels=0, error=None):
        self.kind, self.levels, self.error = kind, levels, error
        self.num_verts = self.num_faces = 0
        self.sizes = {}
        self.seconds = 0.0
        self.showing = "limit"   # limit | last valid limit | cage | stored (a linked cage)
        self.loose = (0, 0)      # (vertices, edges) in no face, counted by the add-on
        self.element = None      # (ccn_element_kind, index) an error names (errors.py)
        self.reason = None       # the error's reason (native.REASONS; errors.advice keys on it)
        self.element_verts = None  # an edge element's two vertices
        self.key = None          # the proxy key it describes (sync_object)


def status(obj, kind='VIEW'):
    st = state.peek(obj)
    return st.status.get(kind) if st is not None else None


def pending_normals():
    """The cages whose viewport proxy waits for its exact normals."""
    return state.objects_where("pending_normals")


def free_render_plans():
    for _, st in state.items():
        st.close_plans(['RENDER'])


def _plan_for(ost, kind, topo, cage, s, levels, uv_chans):
    cached = ost.plans.get(kind)
    if cached is not None and cached[0] == topo:
        return cached[1]
    old = None
    if cached is not None:
        old = cached[1]
        del ost.plans[kind]
    try:
        why = memory.refusal(cage.face_sizes, levels,
                             "Levels Viewport" if kind == 'VIEW' else "Render levels")
        if why:  # before anything is allocated (memory.py)
            raise native.CCNError("CCN_ERR_MEMORY", why, reason="levels_refused")
        sharp = cagemod.sharpness(cage.edge_creases) if s.use_creases else None
        vsharp = cagemod.sharpness(cage.vertex_creases) if s.use_creases else None
        ends = cage.loose_edge_ends()
        if ends.any():  # corners, as Subdivision Surface makes them
            vsharp = np.zeros(cage.num_verts) if vsharp is None else np.array(vsharp, np.float64)
            vsharp[ends] = 10.0
        # the old plan gives its topology and unchanged stencils to an interval edit's plan
        # (ccn_plan_create with options.previous, which consumes it; only freed when topology, creases or options
        # differ)
        plan = native.Plan(cage.positions, cage.face_sizes, cage.face_verts, cage.edge_verts,
                           cage.knots, scheme=s.scheme, cap=s.cap, boundary=s.boundary_smooth,
                           levels=levels, edge_sharpness=sharp, vertex_sharpness=vsharp,
                           previous=loose.unwrap(old))
    finally:
        if old is not None:
            old.close()
    part = loose.Loose(cage, levels)
    if not part.empty:  # loose vertices and edges, carried as Subdivision Surface carries them
        plan = loose.WithLoose(plan, cage, part)
    plan.uv_channels = attrs.add_channels(plan, uv_chans, s.uv_smooth)
    plan.corner_channels = attrs.add_corner_channels(plan, cage.extras)
    plan.face_origin = plan.corner_edge_origin = None
    ost.plans[kind] = (topo, plan)
    return plan


def _write_extras(me, plan, cage, uv_chans, ekey, rebuilt):
    """UV maps and attributes (attrs.py), when they or the topology changed."""
    if not rebuilt and me.get(attrs.KEY_PROP) == ekey:
        return
    x = cage.extras
    if (plan.face_origin is None and x is not None and x.face) or (
            plan.corner_edge_origin is None and attrs.needs_edge_origin(x)):
        res = plan.evaluate(cage.positions, topology=True)
        plan.face_origin, plan.corner_edge_origin = res["face_origin"], res["corner_edge_origin"]
    edge_from = (attrs.edge_origin(me, plan.corner_edge_origin, cage.loop_edges)
                 if attrs.needs_edge_origin(x) else None)
    attrs.write(me, x, plan, uv_chans, plan.uv_channels, plan.face_origin,
                plan.corner_channels, edge_from)
    me[attrs.KEY_PROP] = ekey


def sync_object(obj, kind, cage, force=False, defer_normals=False, defer_analysis=False):
    """Brings the cage's viewport ('VIEW') or render ('RENDER') proxy up to date with `cage`
    (the tap's arrays). defer_normals, defer_analysis: exact normals, the analysis attributes
    are left for later (see PENDING). Returns the Status; never raises."""
    s = obj.ccnurbs
    levels = s.levels if kind == 'VIEW' else s.render_levels
    ost = state.of(obj)
    if kind == 'VIEW' and s.cap_status and ost.ev_marks is None:
        force = True  # e.g. a file just loaded: its proxy is right, the marks are not made yet
    elif kind == 'VIEW' and not s.cap_status:
        ost.ev_marks = None
    st = Status(kind, levels)
    t0 = time.perf_counter()
    p = None
    try:
        uv_chans, uv_topo = attrs.uv_channels(ost, cage.extras, cage.face_verts)
        uv_topo += attrs.corner_layout(cage.extras)
        memo = ost.key_memo.setdefault(kind, {})
        topo, faces = (k + uv_topo for k in
                       cage.topology_keys(levels, *s.option_tuple(), creases=s.use_creases,
                                          memo=memo))
        if "loose" not in memo:  # a new topology (the memo starts afresh): count once
            memo["loose"] = cage.loose_counts()
        st.loose = memo["loose"]
        old = ost.status.get(kind)
        p = modifier.proxy(obj, kind)
        if p is None:
            raise native.CCNError("CCN_ERR_ARGUMENT", "the modifier has no proxy (re-add it)")
        if levels == 0:  # as Subdivision Surface at Levels 0: the cage itself, no limit
            if proxies.show_cage(p):
                stats["syncs"] += 1
            ost.close_plans([kind])
            st.num_verts, st.num_faces = len(cage.positions), len(cage.face_sizes)
            st.sizes = {}
            st.showing = "cage"
            st.key = proxies.CAGE_KEY
            st.seconds = time.perf_counter() - t0
            ost.status[kind] = st
            return st
        ekey = attrs.data_key(cage.extras, s.uv_smooth)
        curv = s.curvature  # analysis: in the viewport and in renders (Workbench pictures)
        key = topo + ":" + cage.position_key() + ":" + ekey + ":" + curv
        proxies.sync_materials(obj.data, p)
        me = p.data
        stored = me.get(proxies.KEY_PROP)
        curv_later = curv != 'NONE' and defer_analysis
        if stored == key + PENDING and (defer_normals or curv_later):
            ost.pending_normals = True  # e.g. after undo: still waiting
        if not force and (stored == key or stored == key + PENDING and (defer_normals or curv_later)):
            stats["skipped"] += 1
            if old is None or old.error or old.key != key:  # file just loaded, or undo restored
                old = Status(kind, levels)                  # another proxy: describe this one
                old.num_verts, old.num_faces = len(me.vertices), len(me.polygons)
                old.loose = st.loose
                old.key = key
                cached = ost.plans.get(kind)
                if cached is not None and cached[0] == topo:
                    old.sizes = dict(cached[1].sizes)
                ost.status[kind] = old
            return old
        stats["syncs"] += 1
        plan = _plan_for(ost, kind, topo, cage, s, levels, uv_chans)
        me = proxies.own_mesh(p)
        # an interval edit changes the plan, not the output faces: positions (and normals)
        # are rewritten in place, the proxy keeps its topology
        same_topology = (me.get(proxies.TOPO_PROP) == faces
                         and len(me.vertices) == plan.sizes["num_verts"]
                         and len(me.polygons) == plan.sizes["num_faces"])
        exact = s.normals == 'EXACT'
        deferred = exact and defer_normals or curv_later
        exact = exact and not defer_normals
        curv_now = curv != 'NONE' and not curv_later  # (the attributes stay as they are)
        if same_topology and me.get(proxies.KEY_PROP) == key:
            pass  # forced: the proxy is already right
        elif same_topology:
            res = plan.evaluate(cage.positions, topology=False, curvature=curv_now)
            proxies.write_positions(me, res, exact)
            if not curv_later:
                analysis.write(me, res.get("curvatures"), curv)
            stats["changed_only"] += plan.changed_only
            # a new plan (an interval edit) changes the limit UVs and attributes too
            _write_extras(me, plan, cage, uv_chans, ekey, me.get(proxies.PLAN_PROP) != topo)
            stats["position_updates"] += 1
        else:
            res = plan.evaluate(cage.positions, topology=True, curvature=curv_now)
            plan.face_origin, plan.corner_edge_origin = res["face_origin"], res["corner_edge_origin"]
            proxies.write_topology(me, res, cage, exact)
            if not curv_later:  # (a new topology: the old attributes went with it)
                analysis.write(me, res.get("curvatures"), curv)
            _write_extras(me, plan, cage, uv_chans, ekey, True)
            # the carried vertex groups' names live on the mesh, which the rebuild cleared
            modifier.ensure_proxy_groups(p, modifier.carried_groups(obj))
            stats["rebuilds"] += 1
        if kind == 'VIEW':
            ost.ev_marks = ev_marks(plan, me) if s.cap_status else None
        me[proxies.KEY_PROP] = key + PENDING if deferred else key
        if deferred:
            ost.pending_normals = True
        me[proxies.TOPO_PROP] = faces
        me[proxies.PLAN_PROP] = topo
        st.num_verts, st.num_faces = len(me.vertices), len(me.polygons)
        st.sizes = dict(plan.sizes)
        st.key = key
    except native.CCNError as e:
        st.error = str(e)
        st.element = (e.element_kind, e.element) if e.element >= 0 else None
        st.reason, st.element_verts = e.reason, e.element_verts
        stats["errors"] += 1
        if not len(cage.face_sizes) and p is not None:  # nothing to show but the cage itself
            proxies.clear(p)
            state.forget(obj, [kind])
    except Exception as e:  # never let a handler raise: report it in the panel instead
        st.error = "internal error: %s: %s" % (type(e).__name__, e)
        stats["errors"] += 1
        stats["internal_errors"] += 1
        traceback.print_exc()
    st.seconds = time.perf_counter() - t0
    if st.error:
        shown = p.data if p is not None and p.data is not None else None
        if shown is not None and len(shown.vertices):
            st.showing = "last valid limit"
            st.num_verts, st.num_faces = len(shown.vertices), len(shown.polygons)
        else:
            st.showing = "cage"
    ost.status[kind] = st
    return st


EV_COLORS = np.array([(0.1, 0.85, 0.2, 1.0), (1.0, 0.85, 0.1, 1.0), (1.0, 0.1, 0.1, 1.0),
                      (0.1, 0.7, 1.0, 1.0)],
                     np.float32)  # capped, cap blended, refined, G1 fill (native.Plan.EV_SURFACES)


def ev_marks(plan, me):
    """Analysis > Cap Status: positions (the proxy's, local) and colours of the extraordinary
    points, and how many are capped, blended, refined, filled."""
    idx, kind = plan.evs()
    co = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", co)
    return {"coords": co.reshape(-1, 3)[idx], "colors": EV_COLORS[kind],
            "counts": tuple(int((kind == k).sum()) for k in range(len(EV_COLORS))), "batch": None}


def missing_tap(obj, kind):
    """The modifier is on but its input tap is not in the evaluated result."""
    st = Status(kind, error="CCNURBS cannot read its input: a modifier below it realizes or "
                "removes instances. Move CCNURBS below it, or turn that modifier off.")
    p = modifier.proxy(obj, kind)
    st.showing = "last valid limit" if p is not None and p.data and len(p.data.vertices) \
        else "cage"
    state.of(obj).status[kind] = st
    return st


def linked_cage(obj, kind):
    """A cage linked from a library file: its proxies are that file's, read-only here (writing
    into linked meshes through the API crashes some of Blender's mesh functions), so the add-on
    cannot write its limit. It shows the render mesh the library stored (Store Render Mesh in
    File: in the viewport too, the viewport proxy being saved empty), else its cage; said in
    the panel either way."""
    lib = bpy.path.basename(obj.library.filepath) if obj.library is not None else ""
    p = modifier.proxy(obj, 'RENDER')
    me = p.data if p is not None else None
    if me is not None and (len(me.polygons) or me.get(proxies.KEY_PROP) == proxies.CAGE_KEY):
        st = Status(kind, obj.ccnurbs.render_levels)
        st.num_verts, st.num_faces = len(me.vertices), len(me.polygons)
        st.showing = "stored"
        st.reason = "linked_stored"
    else:
        st = Status(kind, error="linked from %s, which stores no render mesh: the add-on cannot "
                    "write the limit surface into linked data, so the cage is shown"
                    % (lib or "a library"))
        st.reason = "linked_data"
        st.showing = "cage"
    state.of(obj).status[kind] = st
    return st


def render_bytes(obj):
    p = modifier.proxy(obj, 'RENDER')
    return proxies.size_bytes(p.data if p is not None else None)
