"""Panels: knot tools in the edit-mode sidebar, modifier settings in the Modifier tab."""
import bmesh
import bpy

from . import cage as cagemod
from . import analysis, errors, modifier, native, proxies, state, sync, values


def active_edge_interval(obj):
    """Interval of the active (last selected) edge in edit mode, or None."""
    bm = bmesh.from_edit_mesh(obj.data)
    act = bm.select_history.active
    if not isinstance(act, bmesh.types.BMEdge):
        return None
    layer = bm.edges.layers.float.get(cagemod.KNOT_ATTR)
    v = act[layer] if layer is not None else 0.0
    return float(values.effective(v))


class VIEW3D_PT_ccnurbs_knots(bpy.types.Panel):
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "CCNURBS"
    bl_label = "Knot Intervals"
    bl_context = "mesh_edit"

    def draw(self, context):
        layout = self.layout
        tools = context.scene.ccnurbs_tools
        col = layout.column(align=True)
        col.prop(tools, "knot_value")
        op = col.operator("mesh.ccnurbs_set_knot_interval", text="Set on Rings", icon='CHECKMARK')
        op.value = tools.knot_value
        row = layout.row(align=True)
        row.operator("mesh.ccnurbs_select_ring", text="Select Rings", icon='EDGESEL')
        row = layout.row(align=True)
        row.operator("mesh.ccnurbs_clear_knot_interval", text="Clear Rings").scope = 'SELECTED'
        row.operator("mesh.ccnurbs_clear_knot_interval", text="Clear All").scope = 'ALL'
        layout.prop(tools, "show_overlay", icon='OVERLAY')
        obj = context.edit_object
        if obj is not None and obj.type == 'MESH':
            v = active_edge_interval(obj)
            if v is not None:
                layout.label(text="Active edge: %g" % v)
            if modifier.is_cage(obj):
                _draw_status(layout, obj)


def _draw_status(layout, obj):
    st = sync.status(obj, 'VIEW')
    if st is None:
        return
    box = layout.box()
    if st.error:
        col = box.column()
        col.alert = True
        col.label(text=error_heading(st), icon='ERROR')
        for line in _wrap(st.error, 48):
            col.label(text=line)
        what = errors.advice(st)
        if what:
            col = box.column()
            for i, line in enumerate(_wrap(what, 48)):
                col.label(text=line, icon='QUESTION' if i == 0 else 'BLANK1')
        if errors.selectable(st):
            box.operator("object.ccnurbs_select_error", text="Select", icon='RESTRICT_SELECT_OFF')
        return
    if st.showing == "stored":
        lib = bpy.path.basename(obj.library.filepath) if obj.library is not None else ""
        return ["Linked: the surface %s stored, %d vertices, %d faces" % (
            lib or "its library", st.num_verts, st.num_faces),
            "(Render Levels %d; a library override makes it live)" % st.levels]
    if st.key == proxies.CAGE_KEY:  # Levels 0
        box.label(text="Levels 0: the cage, %d vertices, %d faces" % (st.num_verts, st.num_faces),
                  icon='MESH_DATA')
        return
    box.label(text="Limit: %d vertices, %d faces" % (st.num_verts, st.num_faces), icon='MESH_DATA')
    z = dict(st.sizes)
    z["num_ignored_verts"], z["num_ignored_edges"] = st.loose
    if z:
        box.label(text="Extraordinary: %d, caps: %d" % (z.get("num_extraordinary", 0),
                                                      z.get("num_caps", 0)))
        notes = []
        if z.get("num_sharp_edges") or z.get("num_sharp_vertices"):
            notes.append("creases: %d sharp edges, %d sharp vertices; %d limit vertices with "
                         "one normal per side" % (z.get("num_sharp_edges", 0),
                                                  z.get("num_sharp_vertices", 0),
                                                  z.get("num_sharp_corners", 0)))
        if z.get("num_ring_conflicts"):
            notes.append("%d ring conflicts (mean used)" % z["num_ring_conflicts"])
        if z.get("num_ev_fallbacks"):
            notes.append("%d eigen→NURSS fallbacks" % z["num_ev_fallbacks"])
        if z.get("num_ev_outside_g1"):
            notes.append("%d extraordinary points outside the verified G1 range (spoke"
                         " interval ratios too extreme for every eigen polyhedron tried)"
                         % z["num_ev_outside_g1"])
        if z.get("num_cap_fallbacks"):
            notes.append("%d cap fallbacks (exact limit there: too close to another"
                         " extraordinary point or a boundary, valence > 32, or spoke"
                         " interval ratios beyond about 1:5)" % z["num_cap_fallbacks"])
        for name in modifier.subdivisions_above(obj):
            notes.append(modifier.SUBDIVIDED_NOTE % name)
        for name in modifier.vertex_groups_below(obj):
            notes.append(modifier.VGROUP_NOTE % name)
        if z.get("num_ignored_verts") or z.get("num_ignored_edges"):
            notes.append("loose: %d vertices, %d edges (carried as Subdivision Surface carries "
                         "them)" % (z.get("num_ignored_verts", 0), z.get("num_ignored_edges", 0)))
        for n in notes:
            lines = _wrap(n, 48)
            box.label(text=lines[0], icon='INFO')
            for line in lines[1:]:
                box.label(text=line, icon='BLANK1')
        ost = state.peek(obj)
        for note in ((ost.edit_note, ost.removed_note) if ost is not None else ()):
            if note:
                for i, line in enumerate(_wrap(note, 48)):
                    box.label(text=line, icon='INFO' if i == 0 else 'BLANK1')
        box.label(text="Updated in %.1f ms" % (1000 * st.seconds))


def _wrap(text, width):
    words, lines, cur = text.split(), [], ""
    for w in words:
        if cur and len(cur) + 1 + len(w) > width:
            lines.append(cur)
            cur = w
        else:
            cur = (cur + " " + w) if cur else w
    if cur:
        lines.append(cur)
    return lines


def error_heading(st):
    return {"limit": "Cage error:", "last valid limit": "Cage error — showing the last valid "
            "limit:", "cage": "Cage error — showing the cage (no valid limit yet):"}[st.showing]


def status_lines(obj):
    """The text the modifier panel shows for a cage (also used by tests)."""
    st = sync.status(obj, 'VIEW')
    if st is None:
        return []
    if st.error:
        return [error_heading(st), st.error]
    if st.showing == "stored":
        lib = bpy.path.basename(obj.library.filepath) if obj.library is not None else ""
        return ["Linked: the surface %s stored, %d vertices, %d faces" % (
            lib or "its library", st.num_verts, st.num_faces),
            "(Render Levels %d; a library override makes it live)" % st.levels]
    if st.key == proxies.CAGE_KEY:
        return ["Levels 0: the cage, %d vertices, %d faces" % (st.num_verts, st.num_faces)]
    return ["Limit: %d vertices, %d faces" % (st.num_verts, st.num_faces)]


def render_mesh_line(obj):
    """What the file holds for rendering (the Store Render Mesh in File line)."""
    if not obj.ccnurbs.store_render_mesh:
        return "Render mesh: computed per frame when rendering, not saved"
    p = modifier.proxy(obj, 'RENDER')
    me = p.data if p is not None else None
    if me is None or not len(me.vertices):
        return "Render mesh in file: not computed yet"
    if me.get(proxies.KEY_PROP) == proxies.CAGE_KEY:
        return "Render levels 0: renders the cage"
    return "Render mesh in file: %d vertices, %.1f MB" % (len(me.vertices),
                                                          sync.render_bytes(obj) / 1e6)


class DATA_PT_ccnurbs_modifier(bpy.types.Panel):
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "modifier"
    bl_label = "CCNURBS"

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and ob.type == 'MESH' and ob.ccnurbs.role != 'VIEW_PROXY'

    def draw(self, context):
        layout = self.layout
        obj = context.object
        if not native.available():
            col = layout.column()
            col.alert = True
            col.label(text="Library not loaded:", icon='ERROR')
            for line in _wrap(native.load_error() or "", 48):
                col.label(text=line)
        if not modifier.is_cage(obj):
            layout.operator("object.ccnurbs_add", icon='MOD_SUBSURF')
            return
        s = obj.ccnurbs
        layout.use_property_split = True
        col = layout.column(align=True)
        col.prop(s, "levels", text="Levels Viewport")
        col.prop(s, "render_levels", text="Render")
        layout.prop(s, "scheme")
        layout.prop(s, "cap")
        layout.prop(s, "boundary_smooth")
        layout.prop(s, "uv_smooth")
        layout.prop(s, "use_creases")
        layout.prop(s, "normals")
        layout.prop(s, "store_render_mesh")
        layout.label(text=render_mesh_line(obj), icon='FILE_BLEND')
        box = layout.box()
        box.label(text="Analysis", icon='VIEWZOOM')
        box.prop(s, "curvature")
        line = curvature_legend(obj)
        if line:
            box.label(text=line, icon='COLOR')
        box.prop(s, "cap_status")
        line = cap_status_line(obj)
        if line:
            box.label(text=line, icon='PMARKER_ACT')
        row = box.row(align=True)
        row.operator("view3d.ccnurbs_highlight_lines", text="Highlight Lines", icon='SHADING_SOLID').show = True
        row.operator("view3d.ccnurbs_highlight_lines", text="Off").show = False
        _draw_status(layout, obj)
        rst = sync.status(obj, 'RENDER')
        if rst is not None and rst.error:
            col = layout.column()
            col.alert = True
            col.label(text="Render levels: " + rst.error, icon='ERROR')
        op = layout.operator("export_scene.ccnurbs_cad", text="Export CAD", icon='EXPORT')
        op.active_only = True
        layout.operator("object.ccnurbs_remove", icon='X')


def curvature_legend(obj):
    """The colour scale of the curvature analysis, or None."""
    s = obj.ccnurbs
    p = modifier.proxy(obj, 'VIEW')
    if s.curvature == 'NONE' or p is None or p.data is None:
        return None
    r = p.data.get(analysis.RANGE_PROP)
    if r is None:
        return None
    name = {"GAUSSIAN": "Gaussian", "MEAN": "mean", "MAX": "max |k|"}[s.curvature]
    return "%s: blue -%.3g, white 0, red +%.3g; magenta: undefined (Solid > Attribute)" % (
        name, r, r)


def cap_status_line(obj):
    """How the extraordinary points are made, or None (Cap Status off or not yet computed)."""
    st = state.peek(obj)
    if not obj.ccnurbs.cap_status or st is None or st.ev_marks is None:
        return None
    c, b, r, f = st.ev_marks["counts"]
    line = "Extraordinary points: %d capped (green), %d blended (yellow), %d refined (red: " \
           "unbounded curvature)" % (c, b, r)
    return line + (", %d G1 fill (blue)" % f if f else "")


def edge_menu(self, context):
    """Entries in Edit Mode > Edge."""
    layout = self.layout
    layout.separator()
    layout.operator("mesh.ccnurbs_set_knot_interval", text="Set Knot Interval (Rings)")
    layout.operator("mesh.ccnurbs_select_ring", text="Select Knot Rings")
    layout.operator("mesh.ccnurbs_clear_knot_interval", text="Clear Knot Intervals").scope = \
        'SELECTED'


classes = (VIEW3D_PT_ccnurbs_knots, DATA_PT_ccnurbs_modifier)


def register():
    bpy.types.VIEW3D_MT_edit_mesh_edges.append(edge_menu)


def unregister():
    bpy.types.VIEW3D_MT_edit_mesh_edges.remove(edge_menu)
