"""Operators that add and remove the CCNURBS modifier (they use modifier.py and sync.py;
neither imports this module)."""
import bpy

from . import modifier, sync


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
        for obj in objs:
            existed = modifier.is_cage(obj)
            modifier.ensure(obj, context)
            st = sync.sync_object(obj, 'VIEW', force=True)
            if st.error:
                level = 'WARNING'
                msgs.append("%s: %s" % (obj.name, st.error))
            else:
                msgs.append("%s: %s limit mesh, %d vertices, %d faces (levels %d)"
                            % (obj.name, "updated" if existed else "added", st.num_verts,
                               st.num_faces, obj.ccnurbs.levels))
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
        self.report({'INFO'}, "CCNURBS removed from %s (knot intervals kept)" % obj.name)
        return {'FINISHED'}


classes = (OBJECT_OT_ccnurbs_add, OBJECT_OT_ccnurbs_remove)
