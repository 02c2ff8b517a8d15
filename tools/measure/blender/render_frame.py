"""Imports a vfield simulation folder with the add-on (from this checkout, not
installed) and renders one frame with Cycles:

blender -b --factory-startup --python tools/measure/blender/render_frame.py --
    SIM FRAME OUT.png [--samples N] [--resolution W H]"""

import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugin", "blender"))
from vfield_blender.build import import_simulation  # noqa: E402


def main():
    parser = argparse.ArgumentParser(prog="render_frame.py")
    parser.add_argument("sim")
    parser.add_argument("frame", type=int)
    parser.add_argument("output")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", type=int, nargs=2)
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1 :])

    # --factory-startup's cube, lamp and camera are no part of the scene (the
    # lamp lit a patch of the canyon's wall).
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    import_simulation(bpy.context, args.sim)
    scene = bpy.context.scene
    scene.frame_set(args.frame)
    scene.cycles.samples = args.samples
    if args.resolution:
        scene.render.resolution_x, scene.render.resolution_y = args.resolution
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = os.path.abspath(args.output)
    bpy.ops.render.render(write_still=True)


main()
