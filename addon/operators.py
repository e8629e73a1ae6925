"""Operators that add and remove the CCNURBS modifier (they use modifier.py, handlers.py and
sync.py; none of those imports this module)."""
import bpy

from . import handlers, modifier, state, sync


class OBJECT_OT_ccnurbs_add(bpy.types.Operator):
    """Add the CCNURBS limit-surface modifier to the selected mesh objects"""
    bl_idname = "object.ccnurbs_add"
    bl_label = "Add CCNURBS"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == 'MESH'

    def execute(self, context):
        objs = [o for o in context.selected_objects if o.type == 'MESH']
        if context.active_object not in objs:
            objs.append(context.active_object)
        msgs, level = [], 'INFO'
        existed = {o.name_full: modifier.is_cage(o) for o in objs}
        for obj in objs:
            modifier.ensure(obj)
        handlers.sync_cages(context.evaluated_depsgraph_get(), objs, 'VIEW')  # no-op if done
        for obj in objs:
            st = sync.status(obj, 'VIEW') or sync.Status('VIEW', error="no input evaluated")
            if st.error:
                level = 'WARNING'
                msgs.append("%s: %s" % (obj.name, st.error))
            else:
                msgs.append("%s: %s limit mesh, %d vertices, %d faces (levels %d)"
                            % (obj.name, "updated" if existed[obj.name_full] else "added",
                               st.num_verts,
                               st.num_faces, obj.ccnurbs.levels))
            for name in modifier.subdivisions_above(obj):
                level = 'WARNING'
                msgs.append("%s: %s" % (obj.name, modifier.SUBDIVIDED_NOTE % name))
        self.report({level}, "CCNURBS " + "; ".join(msgs))
        return {'FINISHED'}


class OBJECT_OT_ccnurbs_remove(bpy.types.Operator):
    """Remove the CCNURBS modifier and its proxy meshes (knot intervals are kept)"""
    bl_idname = "object.ccnurbs_remove"
    bl_label = "Remove CCNURBS"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return modifier.is_cage(context.active_object)

    def execute(self, context):
        obj = context.active_object
        modifier.remove(obj)
        state.forget(obj)
        self.report({'INFO'}, "CCNURBS removed from %s (knot intervals kept)" % obj.name)
        return {'FINISHED'}


class VIEW3D_OT_ccnurbs_highlight_lines(bpy.types.Operator):
    """Show highlight lines (a stripe matcap in Solid shading) in the 3D views and Workbench
    renders, or turn them off"""
    bl_idname = "view3d.ccnurbs_highlight_lines"
    bl_label = "Highlight Lines"
    bl_options = {'REGISTER'}

    show: bpy.props.BoolProperty(name="Show", default=True)
    direction: bpy.props.EnumProperty(
        name="Direction", default='RINGS',
        items=(('RINGS', "Rings", "Stripes by the angle to the view direction: closed rings "
                "around every point facing the viewer"),
               ('HORIZONTAL', "Horizontal", "Zebra stripes of a horizontally striped wall"),
               ('VERTICAL', "Vertical", "Zebra stripes of a vertically striped wall")))
    stripes: bpy.props.IntProperty(name="Density", default=15, min=3, max=60,
                                   description="Light-dark stripe pairs across the view")

    def execute(self, context):
        from . import analysis
        name = analysis.show_highlight_lines(context, self.show, self.direction, self.stripes)
        if self.show and not name:
            self.report({'WARNING'}, "CCNURBS: the highlight-line matcap could not be loaded")
            return {'CANCELLED'}
        return {'FINISHED'}


classes = (OBJECT_OT_ccnurbs_add, OBJECT_OT_ccnurbs_remove, VIEW3D_OT_ccnurbs_highlight_lines)
