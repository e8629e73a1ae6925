"""Viewport overlay: edit-mode edges coloured by knot interval, with a legend (gpu + blf).

Colours are computed on a log scale: blue (short) ← grey (1) → red (long), the scale symmetric
around 1 and wide enough for the largest ratio present. Edge coordinates and colours are kept in
each object's state (`overlay`, state.py), refreshed by the depsgraph handler and the toggle; the
draw callbacks only read them (they never touch bpy.data). Draw handlers exist while the add-on
is enabled.
"""
import bpy
import numpy as np

from . import cage as cagemod
from . import compat, state

SHORT = np.array((0.10, 0.45, 1.00, 1.0), np.float32)
NEUTRAL = np.array((0.62, 0.62, 0.62, 0.55), np.float32)
LONG = np.array((1.00, 0.22, 0.08, 1.0), np.float32)
LINE_WIDTH = 3.0

_handles = []    # (space type, handle)
_failed = []     # a draw error is printed once, then the overlay stops drawing


def interval_colors(knots, num_edges):
    """(colors (E,4) float32, span L): interval d ↦ t = log2(d)/L ∈ [-1, 1]."""
    if knots is None:
        d = np.ones(num_edges)
    else:
        d = np.where(np.isfinite(knots) & (knots > 0), knots, 1.0)
    lg = np.log2(d)
    span = max(1.0, float(np.abs(lg).max())) if len(lg) else 1.0
    t = (lg / span)[:, None].astype(np.float32)
    col = np.where(t >= 0, NEUTRAL + (LONG - NEUTRAL) * t, NEUTRAL + (SHORT - NEUTRAL) * -t)
    return col.astype(np.float32), span


def legend_color(t):
    return tuple(NEUTRAL + (LONG - NEUTRAL) * t) if t >= 0 else tuple(
        NEUTRAL + (SHORT - NEUTRAL) * -t)


def refresh(obj, cage=None):
    """Recomputes the overlay data of one mesh object (edit mode: through bmesh)."""
    if cage is None:
        cage = cagemod.read(obj)
    colors, span = interval_colors(cage.knots, cage.num_edges)
    coords = cage.positions[cage.edge_verts.reshape(-1)].astype(np.float32)
    state.of(obj).overlay = {"coords": coords, "colors": np.repeat(colors, 2, axis=0),
                             "span": span, "batch": None, "knots": cage.knots}
    _tag_redraw()


def enabled(context=None):
    scene = (context or bpy.context).scene
    tools = getattr(scene, "ccnurbs_tools", None) if scene is not None else None
    return bool(tools and tools.show_overlay)


def on_objects_updated(objs):
    """Called by the depsgraph handler with the objects whose geometry changed."""
    if not any(st.overlay for _, st in state.items()) and not enabled():
        return
    for obj in objs:
        if obj.type == 'MESH' and obj.data.is_editmode and enabled():
            refresh(obj)
        else:
            st = state.peek(obj)
            if st is not None:
                st.overlay = None


def set_enabled(flag, context=None):
    state.clear_field("overlay")
    if flag:
        for obj in _edit_objects(context or bpy.context):
            refresh(obj)
    _tag_redraw()


def _tag_redraw():
    wm = getattr(bpy.context, "window_manager", None)
    for win in (wm.windows if wm else []):
        for area in win.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()


def _refresh_pending():
    objs = state.objects_where("overlay_pending")
    state.clear_field("overlay_pending", False)
    for obj in objs:
        if obj.type == 'MESH' and obj.data.is_editmode:
            try:
                refresh(obj)
            except Exception as e:  # shown as a missing overlay, never as a traceback
                print("CCNURBS overlay:", e)
    return None


def _edit_objects(context):
    objs = getattr(context, "objects_in_mode", None) or [getattr(context, "edit_object", None)]
    return [o for o in objs if o is not None and o.type == 'MESH' and o.data.is_editmode]


def _guard(fn):
    def draw():
        if _failed:
            return
        try:
            fn()
        except Exception as e:  # never a traceback per redraw
            _failed.append(e)
            print("CCNURBS overlay disabled after a drawing error: %s: %s"
                  % (type(e).__name__, e))
    draw.__name__ = fn.__name__
    return draw


@_guard
def draw_edges():
    context = bpy.context
    if not enabled(context):
        return
    import gpu
    from gpu_extras.batch import batch_for_shader
    shader = compat.builtin_shader("POLYLINE_SMOOTH_COLOR")
    region = context.region
    gpu.state.blend_set('ALPHA')
    gpu.state.depth_test_set('LESS_EQUAL')
    try:
        for obj in _edit_objects(context):
            st = state.peek(obj)
            entry = st.overlay if st is not None else None
            if entry is None:
                if st is None or not st.overlay_pending:
                    state.of(obj).overlay_pending = True
                    bpy.app.timers.register(_refresh_pending, first_interval=0.0)
                continue
            if entry["batch"] is None:
                entry["batch"] = batch_for_shader(shader, 'LINES', {"pos": entry["coords"],
                                                                    "color": entry["colors"]})
            with gpu.matrix.push_pop():
                gpu.matrix.multiply_matrix(obj.matrix_world)
                shader.bind()
                shader.uniform_float("viewportSize", (region.width, region.height))
                shader.uniform_float("lineWidth", LINE_WIDTH)
                entry["batch"].draw(shader)
    finally:
        gpu.state.depth_test_set('NONE')
        gpu.state.blend_set('NONE')


def legend_labels(span):
    lo, hi = 2.0 ** -span, 2.0 ** span
    return [("%.3g" % lo, -1.0), ("1", 0.0), ("%.3g" % hi, 1.0)]


@_guard
def draw_legend():
    context = bpy.context
    if not enabled(context):
        return
    entries = [st.overlay for st in map(state.peek, _edit_objects(context))
               if st is not None and st.overlay is not None]
    if not entries:
        return
    import blf
    import gpu
    from gpu_extras.batch import batch_for_shader
    span = max(e["span"] for e in entries)
    x0, y0, w, h, steps = 20, 40, 200, 12, 32
    verts, cols = [], []
    for i in range(steps):  # a few quads, not mesh data
        a, b = i / steps, (i + 1) / steps
        ca, cb = legend_color(2 * a - 1), legend_color(2 * b - 1)
        xa, xb = x0 + a * w, x0 + b * w
        verts += [(xa, y0), (xb, y0), (xb, y0 + h), (xa, y0), (xb, y0 + h), (xa, y0 + h)]
        cols += [ca, cb, cb, ca, cb, ca]
    shader = compat.builtin_shader("SMOOTH_COLOR_2D")
    batch = batch_for_shader(shader, 'TRIS', {"pos": verts, "color": cols})
    gpu.state.blend_set('ALPHA')
    shader.bind()
    batch.draw(shader)
    gpu.state.blend_set('NONE')
    font = 0
    compat.blf_size(font, 12)
    blf.color(font, 1, 1, 1, 1)
    blf.position(font, x0, y0 + h + 8, 0)
    blf.draw(font, "Knot interval")
    for text, t in legend_labels(span):
        tw = blf.dimensions(font, text)[0]
        blf.position(font, x0 + (t + 1) / 2 * w - tw / 2, y0 - 16, 0)
        blf.draw(font, text)


@_guard
def draw_ev_marks():
    """Analysis > Cap Status: a dot at each extraordinary point (sync.ev_marks), drawn over the
    surface."""
    context = bpy.context
    objs = [(o, st.ev_marks) for o in getattr(context, "visible_objects", ())
            for st in (state.peek(o),) if st is not None and st.ev_marks is not None
            and o.ccnurbs.cap_status and len(st.ev_marks["coords"])]
    if not objs:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader
    shader = compat.builtin_shader("FLAT_COLOR")
    gpu.state.point_size_set(9.0)
    gpu.state.depth_test_set('NONE')
    try:
        for obj, m in objs:
            if m["batch"] is None:
                m["batch"] = batch_for_shader(shader, 'POINTS', {"pos": m["coords"], "color": m["colors"]})
            with gpu.matrix.push_pop():
                gpu.matrix.multiply_matrix(obj.matrix_world)
                shader.bind()
                m["batch"].draw(shader)
    finally:
        gpu.state.point_size_set(1.0)


def register():
    unregister()
    _handles.append(bpy.types.SpaceView3D.draw_handler_add(draw_edges, (), 'WINDOW',
                                                           'POST_VIEW'))
    _handles.append(bpy.types.SpaceView3D.draw_handler_add(draw_legend, (), 'WINDOW',
                                                           'POST_PIXEL'))
    _handles.append(bpy.types.SpaceView3D.draw_handler_add(draw_ev_marks, (), 'WINDOW',
                                                           'POST_VIEW'))


def unregister():
    _failed.clear()
    while _handles:
        bpy.types.SpaceView3D.draw_handler_remove(_handles.pop(), 'WINDOW')
    state.clear_field("overlay")
    state.clear_field("overlay_pending", False)
    if bpy.app.timers.is_registered(_refresh_pending):
        bpy.app.timers.unregister(_refresh_pending)


def handle_count():
    return len(_handles)
