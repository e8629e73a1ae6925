"""CAD export: File > Export > "CCNURBS Surface (.step, .iges)" for the selected cages.

The exact limit surface of each cage with its modifier settings (scheme, cap, boundary), as
STEP AP214 or IGES 5.3 through the library's ccn_plan_export: B-spline faces packed over the
regular regions, the bi-5 caps at extraordinary points, one shell per cage (a solid when the
cage is closed). Several selected cages: one file each (the object's name appended).

Registered by __init__.py: `classes` and `register_menu()` (the File > Export menu entry),
`unregister()`; the CCNURBS modifier panel's "Export CAD" button calls the operator
`export_scene.ccnurbs_cad` for its object only (`active_only`). The cage is what the modifier
sees (the stack above it, read from its tap like the viewport; the object's own mesh when the
tap is not in the depsgraph), with the modifier's settings: scheme, cap, boundary, Use Creases
(edge and vertex creases as sharpness, as the modifier maps them). The ctypes binding of
ccn_plan_export is the block below (structures mirror csrc/include/ccnurbs.h field by field,
like native.py's); it loads the library through native.load().
"""
import ctypes
import os

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

import numpy as np

from . import native

# ---- ctypes binding of ccn_plan_export (csrc/include/ccnurbs.h, "CAD export") ------------

EXPORT_STEP, EXPORT_IGES = 0, 1
EXPORT_UNPACKED = 1
FACE_KINDS = ("pack", "bicubic", "bi5", "refined", "fill")

WRITE_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(ctypes.c_char),
                            ctypes.c_size_t)
PROGRESS_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_double)
FACE_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)  # ccn_export_face* (unused)


class ccn_export_options(ctypes.Structure):
    _fields_ = [("format", ctypes.c_int32),
                ("flags", ctypes.c_uint32),
                ("name", ctypes.c_char_p),
                ("timestamp", ctypes.c_char_p),
                ("tolerance", ctypes.c_double),
                ("fill_levels", ctypes.c_int32),
                ("face_fn", FACE_FN),
                ("face_user", ctypes.c_void_p),
                ("progress", PROGRESS_FN),
                ("progress_user", ctypes.c_void_p)]


class ccn_export_info(ctypes.Structure):
    _fields_ = [("num_faces", ctypes.c_int32),
                ("num_packs", ctypes.c_int32),
                ("num_bicubic", ctypes.c_int32),
                ("num_bi5", ctypes.c_int32),
                ("num_refined", ctypes.c_int32),
                ("num_fill_faces", ctypes.c_int32),
                ("num_packed_cage_faces", ctypes.c_int32),
                ("num_fills", ctypes.c_int32),
                ("fill_level", ctypes.c_int32),
                ("num_edges", ctypes.c_int32),
                ("num_vertices", ctypes.c_int32),
                ("num_shells", ctypes.c_int32),
                ("num_boundary_edges", ctypes.c_int32),
                ("closed", ctypes.c_int32),
                ("max_g1_deviation", ctypes.c_double),
                ("max_fill_g1_deviation", ctypes.c_double),
                ("size", ctypes.c_double),
                ("bytes", ctypes.c_int64),
                ("num_crease_edges", ctypes.c_int32),
                ("min_crease_angle", ctypes.c_double),
                ("max_crease_angle", ctypes.c_double)]


_bound = []


def _lib():
    lib = native.load()
    if not _bound:
        lib.ccn_plan_export.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double),
                                        ctypes.POINTER(ccn_export_options), WRITE_FN,
                                        ctypes.c_void_p, ctypes.POINTER(ccn_export_info),
                                        ctypes.POINTER(native.ccn_error)]
        lib.ccn_plan_export.restype = ctypes.c_int
        _bound.append(True)
    return lib


def plan_export(plan, stream, fmt=EXPORT_STEP, packed=True, name="ccnurbs", fill_levels=0,
                positions=None, progress=None):
    """Writes the surface of native.Plan `plan` (at `positions`, (V,3), or the cage's own) to
    the binary stream; progress(fraction) is called along. Returns the info as a dict; raises
    native.CCNError on failure (nothing useful is in the stream then)."""
    lib = _lib()
    failed = []

    def write(_user, data, n):
        try:
            stream.write(ctypes.string_at(data, n))
            return 0
        except Exception as e:  # stop the export: the library returns CCN_ERR_IO
            failed.append(e)
            return 1

    def prog(_user, x):
        if progress is not None:
            try:
                progress(x)
            except Exception:
                pass

    wfn, pfn = WRITE_FN(write), PROGRESS_FN(prog)
    safe = "".join(c for c in (name or "ccnurbs") if 32 <= ord(c) < 127 and c not in "'\\")[:200]
    opts = ccn_export_options(format=fmt, flags=0 if packed else EXPORT_UNPACKED,
                              name=(safe or "ccnurbs").encode("ascii"), timestamp=None,
                              tolerance=0.0, fill_levels=int(fill_levels), face_fn=FACE_FN(),
                              face_user=None, progress=pfn, progress_user=None)
    pos = None
    if positions is not None:
        pos = np.ascontiguousarray(positions, dtype=np.float64).reshape(-1)
    info, err = ccn_export_info(), native.ccn_error()
    st = lib.ccn_plan_export(plan._handle, pos.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
                             if pos is not None else None, ctypes.byref(opts), wfn, None,
                             ctypes.byref(info), ctypes.byref(err))
    if failed:
        raise native.CCNError("CCN_ERR_IO", "writing failed: %s" % failed[0])
    if st != 0:
        native._raise(st, err)
    return {k: getattr(info, k) for k, _ in ccn_export_info._fields_}


# ---- cages -----------------------------------------------------------------------------

def _settings(obj):
    s = getattr(obj, "ccnurbs", None)
    return (getattr(s, "scheme", "EIGEN"), getattr(s, "cap", "GUIDED_BI5"),
            getattr(s, "boundary_smooth", "ALL"), bool(getattr(s, "use_creases", False)))


def is_cage(obj):
    s = getattr(obj, "ccnurbs", None)
    return obj is not None and obj.type == 'MESH' and getattr(s, "role", 'NONE') == 'CAGE'


def read_cages(objects, depsgraph=None):
    """{name_full: Cage}: the cage each modifier sees (its tap in depsgraph: the stack above
    it), read in one walk of the depsgraph (Blender 3.x iterates its instances once), else the
    object's own mesh (edit mode too): positions (local), polygons, edges, intervals, creases."""
    from . import cage, tap
    found = {}
    if depsgraph is not None:
        try:
            found = tap.read(depsgraph, objects)
        except Exception:  # the tap is a matter of fidelity, never a reason to fail
            found = {}
    return {o.name_full: found.get(o.name_full) or cage.read(o) for o in objects}


def make_plan(pos, c, scheme, cap, boundary, creases):
    """A plan whose bi-5 caps exist: they are built only at output levels above the cap level
    (ccn_plan_stats.num_caps_deferred), so the level is raised from 0 until none is deferred."""
    sharp = cage_sharpness(c.edge_creases) if creases else None
    vsharp = cage_sharpness(c.vertex_creases) if creases else None
    levels = 0
    while True:
        plan = native.Plan(pos, c.face_sizes, c.face_verts, c.edge_verts, c.knots, scheme=scheme,
                           cap=cap, boundary=boundary, levels=levels, edge_sharpness=sharp,
                           vertex_sharpness=vsharp)
        if plan.sizes.get("num_caps_deferred", 0) == 0 or plan.sizes["levels"] >= 6:
            return plan
        levels = plan.sizes["levels"] + 1
        plan.close()


def cage_sharpness(creases):
    from . import cage
    return cage.sharpness(creases)


def export_object(obj, path, fmt, packed=True, fill_levels=0, world=True, scale=1.0,
                  progress=None, cage=None):
    """One cage to one file (written to a temporary name, then renamed). cage: its Cage
    (read_cages), None = the object's own mesh. Returns the info."""
    c = cage if cage is not None else read_cages([obj])[obj.name_full]
    pos = c.positions
    if world:
        M = np.array(obj.matrix_world, dtype=np.float64)
        pos = pos @ M[:3, :3].T + M[:3, 3]
    pos = pos * float(scale)
    scheme, cap, boundary, creases = _settings(obj)
    plan = make_plan(pos, c, scheme, cap, boundary, creases)
    tmp = path + ".tmp%d" % os.getpid()
    try:
        with open(tmp, "wb") as f:
            info = plan_export(plan, f, fmt, packed, obj.name, fill_levels, progress=progress)
        os.replace(tmp, path)
    finally:
        plan.close()
        if os.path.exists(tmp):
            os.remove(tmp)
    return info


def export_objects(objects, path, fmt=None, packed=True, fill_levels=0, world=True, scale=1.0,
                   wm=None, depsgraph=None):
    """Every cage of `objects`: one file at path (one cage) or path_<name> (several). fmt None:
    from the extension. Progress on wm (a WindowManager) when given. Returns [(path, info)]."""
    cages = [o for o in objects if is_cage(o)]
    if not cages:
        raise native.CCNError("CCN_ERR_ARGUMENT", "no CCNURBS cage selected")
    stem, ext = os.path.splitext(path)
    if fmt is None:
        fmt = EXPORT_IGES if ext.lower() in (".igs", ".iges") else EXPORT_STEP
    out = []
    read = read_cages(cages, depsgraph)
    if wm is not None:
        wm.progress_begin(0, 1000)
    try:
        for i, obj in enumerate(cages):
            p = path if len(cages) == 1 else "%s_%s%s" % (stem, bpy.path.clean_name(obj.name), ext)

            def prog(x, i=i):
                if wm is not None:
                    wm.progress_update(int(1000 * (i + x) / len(cages)))

            out.append((p, export_object(obj, p, fmt, packed, fill_levels, world, scale, prog,
                                         read[obj.name_full])))
    finally:
        if wm is not None:
            wm.progress_end()
    return out


def summary(info):
    return ("%d faces (%d packs, %d bicubic, %d bi-5, %d refined, %d fill), %s, %.1f MB, "
            "G1 %.1e rad%s" % (info["num_faces"], info["num_packs"], info["num_bicubic"],
                               info["num_bi5"], info["num_refined"], info["num_fill_faces"],
                               "closed solid" if info["closed"] else "open shell",
                               info["bytes"] / 1e6, info["max_g1_deviation"],
                               (", %d fills (G1 %.1e rad)" % (info["num_fills"],
                                                             info["max_fill_g1_deviation"])
                                if info["num_fills"] else "")
                               + (", %d crease edges (C0)" % info["num_crease_edges"]
                                  if info["num_crease_edges"] else "")))


# ---- operator and menu ---------------------------------------------------------------------

def _default_scale(context):
    u = context.scene.unit_settings
    return 1000.0 * u.scale_length if u.system != 'NONE' else 1.0


class EXPORT_SCENE_OT_ccnurbs_cad(bpy.types.Operator, ExportHelper):
    """Export the exact CCNURBS limit surface of the selected cages as STEP or IGES"""
    bl_idname = "export_scene.ccnurbs_cad"
    bl_label = "Export CCNURBS Surface"
    bl_options = {'PRESET'}

    filename_ext = ".step"
    filter_glob: StringProperty(default="*.step;*.stp;*.iges;*.igs", options={'HIDDEN'})
    file_format: EnumProperty(name="Format", items=(
        ('STEP', "STEP", "STEP AP214 (B-spline faces, a solid for closed cages)"),
        ('IGES', "IGES", "IGES 5.3 (entity 128 surfaces in a 514 shell)")), default='STEP')
    packed: BoolProperty(name="Packed", default=True, description="One B-spline face per "
                         "rectangle of regular faces (off: one face per cage face / patch)")
    fill_levels: IntProperty(name="Fill Levels", default=0, min=0, max=12, description="Levels "
                             "refined around points without a cap before they are closed (0: "
                             "the library's default)")
    use_selection: BoolProperty(name="Selected Only", default=True)
    apply_transform: BoolProperty(name="Apply Transform", default=True,
                                  description="World coordinates (object transform applied)")
    scale: FloatProperty(name="Scale", default=1000.0, min=1e-9, soft_max=1e6, description=""
                         "Millimetres per Blender unit (CAD files are in millimetres)")
    active_only: BoolProperty(name="Active Object Only", default=False, options={'HIDDEN'},
                              description="Export only the active object (the panel's button)")

    @classmethod
    def poll(cls, context):
        return any(is_cage(o) for o in context.scene.objects)

    def draw(self, context):
        layout = self.layout
        for name in ("file_format", "packed", "fill_levels", "apply_transform", "scale"):
            layout.prop(self, name)
        if not self.active_only:
            layout.prop(self, "use_selection")

    def invoke(self, context, event):
        self.scale = _default_scale(context)
        return ExportHelper.invoke(self, context, event)

    def check(self, context):
        """Keeps the file name's extension in line with the format."""
        want = ".igs" if self.file_format == 'IGES' else ".step"
        stem, ext = os.path.splitext(self.filepath)
        known = ext.lower() in (".step", ".stp", ".iges", ".igs")
        if known and (ext.lower() in (".igs", ".iges")) == (want == ".igs"):
            return False
        self.filepath = (stem if known else self.filepath) + want
        return True

    def execute(self, context):
        if self.active_only:
            objs = [context.object] if context.object is not None else []
        else:
            objs = context.selected_objects if self.use_selection else context.scene.objects
        ext = os.path.splitext(self.filepath)[1].lower()
        fmt = (EXPORT_IGES if ext in (".igs", ".iges") else EXPORT_STEP if ext in (".step", ".stp")
               else EXPORT_IGES if self.file_format == 'IGES' else EXPORT_STEP)
        try:
            done = export_objects(objs, self.filepath, fmt, self.packed, self.fill_levels,
                                  self.apply_transform, self.scale, context.window_manager,
                                  context.evaluated_depsgraph_get())
        except native.CCNError as e:
            self.report({'ERROR'}, "CCNURBS export: %s" % e)
            return {'CANCELLED'}
        except OSError as e:
            self.report({'ERROR'}, "CCNURBS export: %s" % e)
            return {'CANCELLED'}
        except Exception as e:  # never a silent failure: the report is the user's only view
            self.report({'ERROR'}, "CCNURBS export failed: %s: %s" % (type(e).__name__, e))
            return {'CANCELLED'}
        for p, info in done:
            self.report({'INFO'}, "%s: %s" % (os.path.basename(p), summary(info)))
        return {'FINISHED'}


def menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_ccnurbs_cad.bl_idname,
                         text="CCNURBS Surface (.step, .iges)")


classes = (EXPORT_SCENE_OT_ccnurbs_cad,)


def register_menu():
    bpy.types.TOPBAR_MT_file_export.append(menu_export)


def unregister_menu():
    bpy.types.TOPBAR_MT_file_export.remove(menu_export)


def register():
    """Stand-alone registration (the add-on registers `classes` and the menu itself)."""
    for cls in classes:
        bpy.utils.register_class(cls)
    register_menu()


def unregister():
    unregister_menu()
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
