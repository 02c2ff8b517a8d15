"""The add-on's operators: simulate a scene and import it, import a folder."""

import os

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from .build import import_simulation
from .host_scene import HostSceneError
from .simulation import Simulation, SimulationError, find_vfield


def _preferences(context):
    return context.preferences.addons[__package__].preferences


def _import(operator, context, simulation_dir):
    try:
        import_simulation(context, simulation_dir)
    except HostSceneError as e:
        operator.report({"ERROR"}, str(e))
        return {"CANCELLED"}
    operator.report({"INFO"}, f"vfield: imported {simulation_dir}")
    return {"FINISHED"}


class VFIELD_OT_simulate(bpy.types.Operator):
    """Simulate the scene file with vfield and import the result (Esc cancels)"""

    bl_idname = "vfield.simulate"
    bl_label = "Simulate and Import"

    scene_file: StringProperty(name="Scene File", subtype="FILE_PATH")
    output_dir: StringProperty(name="Output Folder", subtype="DIR_PATH")

    def _paths(self, context):
        settings = context.scene.vfield
        scene_file = bpy.path.abspath(self.scene_file or settings.scene_file)
        output_dir = bpy.path.abspath(self.output_dir or settings.output_dir)
        if not os.path.isfile(scene_file):
            raise SimulationError(f"{scene_file or '(no scene file)'}: not a file")
        if not output_dir:
            output_dir = os.path.splitext(scene_file)[0] + "_sim"
        return scene_file, output_dir

    def _start(self, context):
        scene_file, self._output_dir = self._paths(context)
        return Simulation(find_vfield(_preferences(context).vfield_executable), scene_file, self._output_dir)

    def execute(self, context):
        """Blocking, for scripts and the command line."""
        try:
            self._simulation = self._start(context)
            self._simulation.wait()
        except SimulationError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return _import(self, context, self._output_dir)

    def invoke(self, context, event):
        """Runs in the background; progress in the status bar."""
        try:
            self._simulation = self._start(context)
        except SimulationError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.progress_begin(0, 1)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _finish(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == "ESC":
            self._simulation.cancel()
            self._finish(context)
            self.report({"WARNING"}, "vfield: simulation cancelled; simulating again resumes it")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        finished = self._simulation.poll()
        if self._simulation.total:
            context.window_manager.progress_update(self._simulation.done / self._simulation.total)
        if self._simulation.status:
            context.workspace.status_text_set(self._simulation.status + "   (Esc cancels)")
        if not finished:
            return {"RUNNING_MODAL"}
        self._finish(context)
        try:
            self._simulation.check()
        except SimulationError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return _import(self, context, self._output_dir)


class VFIELD_OT_import(bpy.types.Operator, ImportHelper):
    """Import a vfield simulation folder: its cloud, objects, camera and sun"""

    bl_idname = "import_scene.vfield_simulation"
    bl_label = "Import vfield Simulation"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ""
    use_filter_folder = True
    directory: StringProperty(name="Simulation Folder", subtype="DIR_PATH")

    def execute(self, context):
        return _import(self, context, bpy.path.abspath(self.directory))


def menu_import(self, context):
    self.layout.operator(VFIELD_OT_import.bl_idname, text="vfield simulation")
