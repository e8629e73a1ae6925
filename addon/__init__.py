# SPDX-License-Identifier: GPL-3.0-or-later
"""CCNURBS: non-uniform Catmull-Clark limit surfaces with knot intervals.

Legacy add-on (`bl_info`, Blender 3.x) and extension (`blender_manifest.toml`, Blender 4.2+).
Only relative imports: as an extension the package is `bl_ext.<repo>.ccnurbs`.
"""

bl_info = {
    "name": "CCNURBS",
    "author": "CCNURBS authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Modifiers > CCNURBS; 3D View > Sidebar > CCNURBS (Edit Mode)",
    "description": "Non-uniform Catmull-Clark subdivision with knot intervals and smooth "
                   "extraordinary points",
    "category": "Mesh",
    "doc_url": "",
}

_SUBMODULES = ("compat", "native", "cage", "props", "values", "knots", "modifier", "tap",
               "proxies", "sync", "hygiene", "overlay", "handlers", "objio", "operators", "errors",
               "ui")
if "bpy" in locals():  # Reload Scripts: reload the submodules in dependency order
    import importlib
    for _name in _SUBMODULES:
        if _name in globals():
            importlib.reload(globals()[_name])

import bpy  # noqa: E402

from . import (compat, native, cage, props, values, knots, modifier, tap, proxies,  # noqa: E402
               sync, hygiene, overlay, handlers, objio, operators, errors, ui)

_classes = (props.classes + knots.classes + objio.classes + operators.classes + errors.classes
            + ui.classes)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    props.register()
    overlay.register()
    ui.register()
    objio.register()
    handlers.register()


def unregister():
    handlers.unregister()
    objio.unregister()
    ui.unregister()
    overlay.unregister()
    props.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
