"""Blender's compositor takes vfield's EXR frames apart: the frame (the main
job's first, 160x90, its terrain and cloud) loads as a multilayer image whose
Image node offers every pass, and the cloud laid over the surfaces with
Blender's Alpha Over (premultiplied) gives back the beauty.

blender -b --factory-startup --python-exit-code 1 --python test_passes.py --
    --vfield VFIELD --scene scenes/cloud_bank.json --work DIR"""

import argparse
import os
import shutil
import subprocess
import sys

import bpy

PASSES = ("cloud", "surfaces", "shadow", "normal", "objectIndex", "vector")
WIDTH, HEIGHT = 160, 90
SMALL = ["--set", f"/render/resolution=[{WIDTH},{HEIGHT}]", "--set", "/render/samplesPerPixel=2"]
TOLERANCE = 1e-4  # the largest difference in any pixel and channel, 32-bit frames


def arguments():
    parser = argparse.ArgumentParser()
    for name in ("--vfield", "--scene", "--work"):
        parser.add_argument(name, required=True)
    return parser.parse_args(sys.argv[sys.argv.index("--") + 1 :])


def vfield_frame(args):
    """Simulates and renders the scene's first frame as a 32-bit EXR; returns its path."""
    sim, out = os.path.join(args.work, "sim"), os.path.join(args.work, "frames")
    subprocess.run([args.vfield, "--quiet", "simulate", args.scene, "-o", sim, "--frames", "1", *SMALL], check=True)
    subprocess.run([args.vfield, "--quiet", "render", args.scene, "--sim", sim, "-o", out, "--frames", "1",
                    "--format", "exr", "--set", "/render/exrDepth=\"float\"", *SMALL], check=True)
    return os.path.join(out, "frame.0001.exr")


def largest_difference(frame, work):
    """Renders Blender's compositor's |beauty - cloud over surfaces| (and, to
    show the check can fail, |beauty - surfaces|) to EXRs; returns the largest
    value of each, and asserts the Image node offers every pass."""
    image = bpy.data.images.load(frame)
    tuple(image.size)  # reading its size loads the file; its type is known from then on
    assert image.type == "MULTILAYER", f"Blender reads the frame as {image.type}, not as a multilayer EXR"
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"  # renders nothing: no objects; the compositor does the work
    scene.cycles.samples = 1
    scene.cycles.device = "CPU"
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.use_compositing = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.use_nodes = True
    nodes, links = scene.node_tree.nodes, scene.node_tree.links
    nodes.clear()
    frame_node = nodes.new("CompositorNodeImage")
    frame_node.image = image
    offered = {socket.name for socket in frame_node.outputs if socket.enabled}
    missing = [name for name in PASSES if name not in offered]
    assert not missing, f"the Image node offers {sorted(offered)}; missing {missing}"

    over = nodes.new("CompositorNodeAlphaOver")
    over.use_premultiply = False  # vfield's layers are premultiplied already
    links.new(frame_node.outputs["surfaces"], over.inputs[1])
    links.new(frame_node.outputs["cloud"], over.inputs[2])
    difference = nodes.new("CompositorNodeMixRGB")
    difference.blend_type = "DIFFERENCE"
    links.new(frame_node.outputs["Combined"], difference.inputs[1])
    composite = nodes.new("CompositorNodeComposite")
    composite.use_alpha = False
    links.new(difference.outputs["Image"], composite.inputs["Image"])

    largest = {}
    for name, socket in (("over", over.outputs["Image"]), ("surfaces", frame_node.outputs["surfaces"])):
        links.new(socket, difference.inputs[2])
        scene.render.filepath = os.path.join(work, f"difference_{name}.exr")
        bpy.ops.render.render(write_still=True)
        result = bpy.data.images.load(scene.render.filepath)
        pixels = result.pixels[:]
        bpy.data.images.remove(result)
        assert len(pixels) == 4 * WIDTH * HEIGHT, f"the compositor made {len(pixels) // 4} pixels, not {WIDTH * HEIGHT}"
        largest[name] = max(max(pixels[i : i + 3]) for i in range(0, len(pixels), 4))
    return largest


def main():
    args = arguments()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    for obj in list(bpy.data.objects):  # --factory-startup's cube, lamp and camera
        bpy.data.objects.remove(obj)
    largest = largest_difference(vfield_frame(args), args.work)
    print(f"beauty against Blender's cloud over surfaces: largest difference {largest['over']:.2e} "
          f"(allowed {TOLERANCE:g}); against the surfaces alone {largest['surfaces']:.3f}")
    assert largest["surfaces"] > 0.01, "the frame's cloud does not show: the check could not fail"
    assert largest["over"] <= TOLERANCE, f"the beauty is not the cloud over the surfaces in Blender: {largest['over']:.2e}"

main()
