"""The Blender add-on, headless: installed from its zip, it simulates a small
cloud-and-airplane scene with vfield, imports it (frame range, grids,
material, keyframes against tracks.json, the keyed camera and sun), imports
again without duplicates,
a Cycles render of a frame shows the cloud and the airplane where vfield's
own render of that frame does, and a running simulation can be cancelled.

blender -b --factory-startup --python-exit-code 1 --python test_addon.py --
    --zip ADDON.zip --vfield VFIELD --scene SCENE.json --work DIR"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

import addon_utils
import bpy
from mathutils import Matrix, Vector

FRAMES = (1, 40)
RESOLUTION = (192, 108)
CHECKED_FRAME = 18  # the airplane just before the cloud
MIN_IOU = 0.9
MIN_AIRPLANE_IOU = 0.8  # a smaller shape: its edge pixels weigh more
# Keyed camera and sun; at the checked frame the camera stands where the silhouettes are framed.
CAMERA_KEYS = [[1, [-10, 7, 46]], [CHECKED_FRAME, [-4, 5, 42]], [40, [0, 5, 40]]]
FOV_KEYS = [[1, 55], [CHECKED_FRAME, 50], [40, 45]]
SUN_INTENSITY_KEYS = [[1, 4.0], [40, 1.5]]
SUN_DIRECTION_KEYS = [[1, [0.6, 0.8, 0.0]], [40, [0.0, 0.6, 0.8]]]


def arguments():
    parser = argparse.ArgumentParser()
    for name in ("--zip", "--vfield", "--scene", "--work"):
        parser.add_argument(name, required=True)
    return parser.parse_args(sys.argv[sys.argv.index("--") + 1 :])


def small_scene(source, work):
    """The plane through the cloud without its hills (the silhouettes are the
    cloud's and the airplane's), the cloud half as wide with 20,000 particles
    (as dense), the airplane nearer to it and the camera closer, 40 frames."""
    with open(source, encoding="utf-8") as f:
        scene = json.load(f)
    here = os.path.dirname(os.path.abspath(source))
    scene["objects"] = [o for o in scene["objects"] if o.get("motion") == "dynamic"]
    for o in scene["objects"]:
        if "file" in o["mesh"]:
            o["mesh"]["file"] = os.path.join(here, o["mesh"]["file"])
    cloud = scene["clouds"][0]
    cloud["count"] = 20000
    cloud["radii"] = [r / 2 for r in cloud["radii"]]
    scene["objects"][0]["transform"]["translate"] = [-45, 0, 0]
    scene["camera"] = {"position": {"keys": CAMERA_KEYS, "interpolation": "smooth"}, "lookAt": [-6, 0, 0],
                       "fovDegrees": {"keys": FOV_KEYS}}
    scene.setdefault("sun", {})["intensity"] = {"keys": SUN_INTENSITY_KEYS}
    scene["sun"]["direction"] = {"keys": SUN_DIRECTION_KEYS}
    scene["frames"]["start"], scene["frames"]["end"] = FRAMES
    scene["render"]["resolution"] = list(RESOLUTION)
    path = os.path.join(work, "cloud_and_airplane.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)
    return path


def install(zip_path, vfield):
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    addon_utils.enable("vfield_blender", default_set=True, handle_error=None)
    assert addon_utils.check("vfield_blender")[1], "the add-on did not enable"
    bpy.context.preferences.addons["vfield_blender"].preferences.vfield_executable = vfield


def vfield_objects(sim):
    return sorted(o.name for o in bpy.data.objects if o.get("vfield_simulation") == os.path.abspath(sim))


def check_import(sim, tracks_path, extinction):
    scene = bpy.context.scene
    assert (scene.frame_start, scene.frame_end) == FRAMES, (scene.frame_start, scene.frame_end)
    cloud = bpy.data.objects["cloud_and_airplane cloud"]
    volume = cloud.data
    scene.frame_set(CHECKED_FRAME)
    volume.grids.load()
    assert volume.grids.frame_filepath.endswith(f"density.{CHECKED_FRAME:04d}.vdb"), volume.grids.frame_filepath
    grids = {g.name: g.data_type for g in volume.grids}
    assert grids.get("density") == "FLOAT" and grids.get("vel") == "VECTOR_FLOAT", grids
    assert volume.velocity_grid == "vel"
    shader = volume.materials[0].node_tree.nodes["Principled Volume"]
    assert math.isclose(shader.inputs["Density"].default_value, extinction, rel_tol=1e-6)

    airplane = bpy.data.objects["airplane"]
    root = airplane.parent
    with open(tracks_path, encoding="utf-8") as f:
        track = {e["frame"]: e["matrix"] for e in json.load(f)["objects"]["airplane"]}
    for frame in (FRAMES[0], CHECKED_FRAME, FRAMES[1]):
        scene.frame_set(frame)
        expected = Matrix.Rotation(math.pi / 2, 4, "X") @ Matrix([track[frame][r * 4 : r * 4 + 4] for r in range(4)])
        got = airplane.matrix_world
        error = max(abs(got[r][c] - expected[r][c]) for r in range(4) for c in range(4))
        assert error < 1e-4, f"frame {frame}: the airplane is off its track by {error}"
        assert all(abs(x - y) < 1e-6 for r, s in zip(root.matrix_world, Matrix.Rotation(math.pi / 2, 4, "X")) for x, y in zip(r, s))
    print(f"import: frames {FRAMES}, grids {grids}, the airplane on its track at 3 frames")


def check_keys(sim):
    """The keyed camera and sun come in as Blender keyframes: at the keys they
    hold the keys' values, between them vfield's value at each frame."""
    scene = bpy.context.scene
    with open(os.path.join(sim, "host", "host.json"), encoding="utf-8") as f:
        host = json.load(f)
    poses = {p["frame"]: p for p in host["camera"]["poses"]}
    suns = {s["frame"]: s for s in host["sun"]["frames"]}
    assert sorted(poses) == list(range(FRAMES[0], FRAMES[1] + 1)), sorted(poses)
    up = Matrix.Rotation(math.pi / 2, 4, "X")  # vfield's y up is Blender's z up
    camera, sun = bpy.data.objects["cloud_and_airplane camera"], bpy.data.objects["cloud_and_airplane sun"]
    keyed = dict(CAMERA_KEYS)
    for frame in (1, 7, CHECKED_FRAME, 29, 40):
        scene.frame_set(frame)
        position = keyed.get(frame, poses[frame]["position"])
        error = (camera.matrix_world.translation - up @ Vector(position)).length
        assert error < 1e-4, f"frame {frame}: the camera is {error} off {position}"
        fov = dict(FOV_KEYS).get(frame, poses[frame]["fovDegrees"])
        assert math.isclose(math.degrees(camera.data.angle_y), fov, rel_tol=1e-4), (frame, math.degrees(camera.data.angle_y))
        # The light shines down its -z.
        toward = (sun.matrix_world.to_3x3() @ Vector((0, 0, 1))).normalized()
        assert (toward - up.to_3x3() @ Vector(suns[frame]["direction"])).length < 1e-4, (frame, toward)
        brightest = max(suns[frame]["color"])
        assert math.isclose(sun.data.energy, suns[frame]["intensity"] * brightest, rel_tol=1e-5), (frame, sun.data.energy)
    assert math.isclose(suns[1]["intensity"], 4.0) and math.isclose(suns[40]["intensity"], 1.5), suns
    print(f"keys: camera and sun keyframed at {len(poses)} frames, on their keys at frames 1, {CHECKED_FRAME} and 40")


def masks(path):
    """What covers each pixel (alpha over one half), and the airplane among
    it: its red paint, or shade darker than any of the white cloud."""
    image = bpy.data.images.load(path)
    pixels = list(image.pixels)
    bpy.data.images.remove(image)
    rgba = [pixels[i : i + 4] for i in range(0, len(pixels), 4)]
    covered = [p[3] > 0.5 for p in rgba]
    red = [p[3] > 0.5 and (p[0] > 1.5 * p[2] or max(p[:3]) < 0.25 * p[3]) for p in rgba]
    return covered, red


def iou(a, b):
    either = sum(x or y for x, y in zip(a, b))
    return sum(x and y for x, y in zip(a, b)) / either if either else 0.0


def silhouettes_agree(scene_path, sim, work, vfield):
    """IoU of the pixels covered (alpha over one half) in vfield's render and
    in Cycles' render of the imported frame."""
    scene = bpy.context.scene
    scene.frame_set(CHECKED_FRAME)
    scene.render.film_transparent = True
    scene.cycles.samples = 32
    scene.cycles.device = "CPU"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_mode = "RGBA"
    cycles_frame = os.path.join(work, "cycles.exr")
    scene.render.filepath = cycles_frame
    bpy.ops.render.render(write_still=True)
    ours = os.path.join(work, "vfield")
    subprocess.run([vfield, "--quiet", "render", scene_path, "--sim", sim, "-o", ours, "--frames", str(CHECKED_FRAME),
                    "--format", "exr", "--transparent-sky", "--set", "/render/passes=false"], check=True)
    cycles_covered, cycles_red = masks(cycles_frame)
    vfield_covered, vfield_red = masks(os.path.join(ours, f"frame.{CHECKED_FRAME:04d}.exr"))
    everything, airplane = iou(cycles_covered, vfield_covered), iou(cycles_red, vfield_red)
    print(f"silhouettes: Cycles {sum(cycles_covered)} px, vfield {sum(vfield_covered)} px, IoU {everything:.3f}; "
          f"the airplane: {sum(cycles_red)} px and {sum(vfield_red)} px, IoU {airplane:.3f}")
    assert sum(vfield_covered) > 2000 and sum(vfield_red) > 100, "vfield's frame shows too little to compare"
    assert everything >= MIN_IOU, f"IoU {everything:.3f} below {MIN_IOU}"
    assert airplane >= MIN_AIRPLANE_IOU, f"the airplane's IoU {airplane:.3f} below {MIN_AIRPLANE_IOU}"

def cancel_stops_the_simulation(vfield, scene_path, work):
    """What Esc does in Blender: the add-on reads vfield's progress and stops it
    part-way (a 400-frame run of the scene, stopped after its second frame)."""
    from vfield_blender.simulation import Simulation

    with open(scene_path, encoding="utf-8") as f:
        scene = json.load(f)
    scene["frames"]["end"] = 400
    long_scene = os.path.join(work, "long.json")
    with open(long_scene, "w", encoding="utf-8") as f:
        json.dump(scene, f)
    simulation = Simulation(vfield, long_scene, os.path.join(work, "cancelled"))
    while not simulation.poll() and simulation.done < 2:
        time.sleep(0.02)
    simulation.cancel()
    assert simulation.process.returncode != 0, "vfield finished before it was cancelled"
    assert simulation.total == 400 and 2 <= simulation.done < 400, (simulation.done, simulation.total)
    # The status bar has news before the first frame too (building the fields), and an ETA after.
    first_frame = next(i for i, line in enumerate(simulation.log) if line.startswith("frame 1/"))
    assert any(line.startswith("preparing: ") for line in simulation.log[:first_frame]), simulation.log[:first_frame]
    assert "ETA" in simulation.log[first_frame], simulation.log[first_frame]
    print(f"cancel: vfield stopped after frame {simulation.done} of {simulation.total}")


def main():
    args = arguments()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    # --factory-startup's cube, lamp and camera are no part of the scene.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    install(args.zip, args.vfield)
    scene_path = small_scene(args.scene, args.work)
    sim = os.path.join(args.work, "sim")

    assert bpy.ops.vfield.simulate(scene_file=scene_path, output_dir=sim) == {"FINISHED"}
    with open(scene_path, encoding="utf-8") as f:
        extinction = json.load(f)["render"].get("extinction", 1.0)
    check_import(sim, os.path.join(sim, "tracks.json"), extinction)
    check_keys(sim)

    before = vfield_objects(sim)
    assert bpy.ops.import_scene.vfield_simulation(directory=sim) == {"FINISHED"}
    after = vfield_objects(sim)
    assert before == after, f"importing again changed the objects: {before} -> {after}"
    assert len(bpy.data.volumes) == 1 and len([w for w in bpy.data.worlds if w.get("vfield_simulation")]) == 1
    print(f"import again: the same {len(after)} objects, nothing duplicated")

    silhouettes_agree(scene_path, sim, args.work, args.vfield)
    cancel_stops_the_simulation(args.vfield, scene_path, args.work)


main()
