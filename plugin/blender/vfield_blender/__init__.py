"""vfield for Blender: simulate a vfield scene and bring in its cloud, objects,
camera and sun, or import a simulation folder made before."""

bl_info = {
    "name": "vfield",
    "author": "vfield maintainers",
    "version": (0, 0, 0),  # vfield's, set by tools/make-blender-addon from CMakeLists.txt
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > vfield; File > Import > vfield simulation",
    "description": "Collision-free clouds and objects through vector fields: simulate with vfield, import the result",
    "category": "Import-Export",
}

import bpy
from bpy.props import PointerProperty, StringProperty

from . import operators


class VfieldPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    vfield_executable: StringProperty(
        name="vfield executable",
        description="The vfield command (a path, or a name found on PATH)",
        subtype="FILE_PATH",
        default="vfield",
    )

    def draw(self, context):
        self.layout.prop(self, "vfield_executable")


class VfieldSceneSettings(bpy.types.PropertyGroup):
    scene_file: StringProperty(name="Scene File", description="A vfield scene (.json)", subtype="FILE_PATH")
    output_dir: StringProperty(
        name="Output Folder", description="Where vfield simulates to [default: beside the scene file]", subtype="DIR_PATH"
    )


class VFIELD_PT_panel(bpy.types.Panel):
    bl_label = "vfield"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "vfield"

    def draw(self, context):
        settings = context.scene.vfield
        layout = self.layout
        layout.prop(settings, "scene_file")
        layout.prop(settings, "output_dir")
        layout.operator(operators.VFIELD_OT_simulate.bl_idname, icon="PLAY")
        layout.operator(operators.VFIELD_OT_import.bl_idname, text="Import Simulation Folder", icon="IMPORT")


classes = (VfieldPreferences, VfieldSceneSettings, operators.VFIELD_OT_simulate, operators.VFIELD_OT_import, VFIELD_PT_panel)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.vfield = PointerProperty(type=VfieldSceneSettings)
    bpy.types.TOPBAR_MT_file_import.append(operators.menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(operators.menu_import)
    del bpy.types.Scene.vfield
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
