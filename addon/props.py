"""Settings: `Object.ccnurbs` (per cage / proxy) and `Scene.ccnurbs_tools` (knot editing).

The cage holds no pointer to its proxies (the modifier's node group names them), so nothing but
the group keeps a proxy alive."""
import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty,
                       StringProperty)

SCHEME_ITEMS = (
    ('EIGEN', "Eigen", "Li, Finnigan & Sederberg 2016: eigen-polyhedron rules at extraordinary "
     "points (single smooth bump, G1)"),
    ('NURSS', "NURSS", "Sederberg et al. 1998 non-uniform rules everywhere (may show twin "
     "peaks at extraordinary points)"),
    ('CATMULL_CLARK', "Catmull-Clark", "Uniform Catmull-Clark: knot intervals are ignored"),
)
CAP_ITEMS = (
    ('GUIDED_BI5', "Guided Bi-5", "Fill extraordinary points with guided bi-5 rings and a G1 "
     "cap (Karciauskas & Peters 2018): a finite, smooth surface"),
    ('REFINE', "Refine", "Evaluate the limit of refinement at extraordinary points"),
    ('G1_FILL', "G1 Fill", "Guided bi-5 caps where the knot intervals allow them, elsewhere a "
     "G1 fill: a finite surface, exactly G1 at every extraordinary point of valence 5 or more, "
     "as the CAD export writes it; less fair than the other modes at uneven intervals"),
)
BOUNDARY_ITEMS = (
    ('ALL', "All", "Smooth the boundary and its corners (like Subdivision Surface 'All')"),
    ('PRESERVE_CORNERS', "Keep Corners", "Pin valence-2 boundary corners (like Subdivision "
     "Surface 'Keep Corners')"),
)
# Subdivision Surface's UV Smooth, same identifiers, names, descriptions and default (what a new
# Subdivision Surface modifier gets in 3.4, 4.5 and 5.0: Keep Boundaries; tests/blender/case_uv.py)
UV_SMOOTH_ITEMS = (
    ('NONE', "None", "UVs are not smoothed, boundaries are kept sharp"),
    ('PRESERVE_CORNERS', "Keep Corners", "UVs are smoothed, corners on discontinuous boundary "
     "are kept sharp"),
    ('PRESERVE_CORNERS_AND_JUNCTIONS', "Keep Corners, Junctions", "UVs are smoothed, corners "
     "on discontinuous boundary and junctions of 3 or more regions are kept sharp"),
    ('PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE', "Keep Corners, Junctions, Concave", "UVs are "
     "smoothed, corners on discontinuous boundary, junctions of 3 or more regions and darts "
     "and concave corners are kept sharp"),
    ('PRESERVE_BOUNDARIES', "Keep Boundaries", "UVs are smoothed, boundaries are kept sharp"),
    ('SMOOTH_ALL', "All", "UVs and boundaries are smoothed"),
)
CURVATURE_ITEMS = (
    ('NONE', "Off", "No curvature analysis (costs nothing)"),
    ('GAUSSIAN', "Gaussian", "Colour by the Gaussian curvature k1 k2"),
    ('MEAN', "Mean", "Colour by the mean curvature (k1 + k2) / 2"),
    ('MAX', "Max |k|", "Colour by the largest principal curvature magnitude"),
)
NORMALS_ITEMS = (
    ('EXACT', "Exact", "Exact surface normals from the derivatives, as custom split normals "
     "(in Blender 3.x custom normals make each update several times slower)"),
    ('FAST', "Fast", "Blender's smooth vertex normals of the exact limit positions: faster "
     "updates while editing heavy meshes"),
)
ROLE_ITEMS = (('NONE', "None", ""), ('CAGE', "Cage", ""), ('VIEW_PROXY', "Viewport Proxy", ""),
              ('RENDER_PROXY', "Render Proxy", ""))


def _store_changed(self, context):
    """Store Render Mesh off: the stored mesh goes now (it is computed again per render)."""
    from . import modifier, proxies  # neither imports props: no cycle
    obj = self.id_data
    if not self.store_render_mesh and isinstance(obj, bpy.types.Object) and obj.library is None:
        proxies.clear(modifier.proxy(obj, 'RENDER'))
    _tag(self, context)


def _tag(self, context):
    """A setting changed: tag the cage so the depsgraph handler re-evaluates it."""
    obj = self.id_data
    if isinstance(obj, bpy.types.Object) and self.role == 'CAGE':
        obj.update_tag(refresh={'DATA'})


class CCNURBS_ObjectSettings(bpy.types.PropertyGroup):
    role: EnumProperty(items=ROLE_ITEMS, default='NONE', options={'HIDDEN'})
    levels: IntProperty(name="Levels Viewport", description="Samples per cage-face side are "
                        "2^levels (viewport)", default=2, min=0, max=10, soft_max=6, update=_tag)
    render_levels: IntProperty(name="Render", description="Samples per cage-face side are "
                               "2^levels (final render)", default=3, min=0, max=10, soft_max=6,
                               update=_tag)
    scheme: EnumProperty(name="Scheme", items=SCHEME_ITEMS, default='EIGEN', update=_tag)
    cap: EnumProperty(name="Cap", items=CAP_ITEMS, default='GUIDED_BI5', update=_tag)
    boundary_smooth: EnumProperty(name="Boundary Smooth", items=BOUNDARY_ITEMS, default='ALL',
                                  update=_tag)
    uv_smooth: EnumProperty(name="UV Smooth", items=UV_SMOOTH_ITEMS, default='PRESERVE_BOUNDARIES',
                            description="Controls how smoothing is applied to UVs (as in "
                            "Subdivision Surface)", update=_tag)
    normals: EnumProperty(name="Normals", items=NORMALS_ITEMS, default='EXACT', update=_tag)
    curvature: EnumProperty(
        name="Curvature", items=CURVATURE_ITEMS, default='NONE', update=_tag,
        description="Analysis: the exact principal curvatures of the limit surface as point "
        "attributes curvature_gaussian and curvature_mean, and the chosen one as the colour "
        "attribute curvature_color (Solid shading > Attribute); magenta where the curvature is "
        "unbounded or not computed")
    cap_status: BoolProperty(
        name="Cap Status", default=False, update=_tag,
        description="Analysis: mark each extraordinary point of the limit surface in the 3D "
        "view: green, capped (G1, bounded curvature); yellow, a cap blended with the refined "
        "limit; red, the refined limit (no cap: its curvature is unbounded there)")
    use_creases: BoolProperty(
        name="Use Creases", default=True, update=_tag,
        description="Use the mesh's edge and vertex creases (Shift+E) as sharpness, mapped as the "
                    "Subdivision Surface modifier does (sharpness 10 c²: crease 1 is infinitely "
                    "sharp)")
    store_render_mesh: BoolProperty(
        name="Store Render Mesh in File", default=False, update=_store_changed,
        description="Keep the Render-levels limit mesh computed (refreshed a second after "
        "edits stop) and saved in the .blend, so the file renders at Render levels where the "
        "add-on is not installed (render farms). Off: render meshes are computed per frame "
        "while rendering and never saved; a file without the add-on shows and renders the cage")
    owner_name: StringProperty(options={'HIDDEN'})  # on proxies: the cage's name (no user)

    def option_tuple(self):
        return (self.scheme, self.cap, self.boundary_smooth, self.normals, self.uv_smooth,
                self.use_creases)


def _overlay_toggled(self, context):
    from . import overlay
    overlay.set_enabled(self.show_overlay, context)


class CCNURBS_SceneTools(bpy.types.PropertyGroup):
    knot_value: FloatProperty(name="Interval", description="Knot interval used by Set: a positive "
                              "finite number (only ratios matter; Clear resets to 1)",
                              default=2.0, soft_min=0.01, soft_max=100.0, precision=3)
    show_overlay: BoolProperty(name="Knot Overlay", description="Colour edges by knot interval "
                               "in edit mode", default=False, update=_overlay_toggled)


classes = (CCNURBS_ObjectSettings, CCNURBS_SceneTools)


def register():
    bpy.types.Object.ccnurbs = PointerProperty(type=CCNURBS_ObjectSettings)
    bpy.types.Scene.ccnurbs_tools = PointerProperty(type=CCNURBS_SceneTools)


def unregister():
    del bpy.types.Scene.ccnurbs_tools
    del bpy.types.Object.ccnurbs
