"""vfield's reference path tracer against Blender Cycles on the main job's
cloud alone (scenes/cloud_bank.json at its first frame, terrain removed,
160x90, seen from 2.6 times its largest radius, black sky, one
Henyey-Greenstein lobe of g 0.75, albedo 0.97), front-, side- and back-lit
(the sun 140, 90 and 30 degrees from the view), single and multiple
scattering: the light the cloud sends to the camera (the image's mean
radiance, the sky transparent) agrees within 1% beyond Cycles' noise.

The frame is simulated and imported once (the sun changes nothing in the
simulation) and lit three ways. Cycles renders the folder as the add-on
imports it (plugin/blender), the sun turned as the add-on turns it, with
the settings that match vfield's reference (matching_cycles below): no
clamping, no denoising, a box pixel filter, a point-like sun, volume steps
of a quarter voxel, 256 volume bounces (0 for single scattering, as vfield's
maxBounces 1). One render gives both: its combined image is the multiple
scattering, its Volume Direct pass (the sun's light at the first scattering
event) the single. Its noise is measured: it renders each lighting SEEDS
times with other seeds, and the standard error of their mean widens the
tolerance. Cycles' time is its samples' (a ray-marching step of a quarter
voxel through the detailed cloud, at every bounce), and the check's power
its noise: SEEDS x CYCLES_SAMPLES sets both. vfield's reference at
VFIELD_SAMPLES is as noisy as Cycles' mean or less (0.3% between seeds on
the side-lit multiple scattering).

blender -b --factory-startup --python-exit-code 1 --python test_cycles_light.py --
    --vfield VFIELD --scene scenes/cloud_bank.json --work DIR"""

import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugin", "blender"))
from vfield_blender.build import import_simulation, remove_import  # noqa: E402

# The sun 140, 90 and 30 degrees from the camera's view (vfield's y-up world).
LIGHTINGS = {"front": (0.534, 0.673, 0.512), "side": (-0.305, 0.764, 0.569), "back": (-0.977, 0.176, 0.12)}
# vfield's maxBounces for each, and the Cycles image that holds it.
SCATTERING = {"single": (1, "volume_direct"), "multiple": (1000, "combined")}
LONE_CLOUD = [
    "--set", "/objects=[]",
    "--set", "/sky/intensity=0",
    "--set", "/sky/hazeDistance=0",
    "--set", "/render/backWeight=0",
    "--set", "/render/transparentSky=true",
    "--set", "/camera/position=[140.28,77.82,39.3]",
    "--set", "/camera/lookAt=[-50.2,30.2,1.2]",
    "--set", "/render/resolution=[160,90]",
]
VFIELD_SAMPLES = 256
CYCLES_SAMPLES = 32  # a render, SEEDS renders a case
SEEDS = 4
TOLERANCE = 0.01


def arguments():
    parser = argparse.ArgumentParser()
    for name in ("--vfield", "--scene", "--work"):
        parser.add_argument(name, required=True)
    return parser.parse_args(sys.argv[sys.argv.index("--") + 1 :])


def mean_radiance(path):
    """The mean of r, g and b over the image (premultiplied: a transparent sky adds nothing)."""
    image = bpy.data.images.load(path)
    pixels = image.pixels[:]
    bpy.data.images.remove(image)
    count = len(pixels) // 4
    return sum(sum(pixels[channel::4]) for channel in range(3)) / (3 * count)


def matching_cycles(scene, seed):
    """What makes Cycles compute what vfield's reference does."""
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = CYCLES_SAMPLES
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = seed
    cycles.volume_bounces = 256
    cycles.max_bounces = 256
    cycles.volume_step_rate = 0.25
    cycles.volume_max_steps = 100000
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    for light in bpy.data.lights:
        if light.type == "SUN":
            light.angle = 0.0  # vfield's sun is a direction
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"


def write_passes(scene, work, seed):
    """The compositor writes the combined image and the Volume Direct pass to
    their own OpenEXR files; returns their paths by SCATTERING's names."""
    scene.view_layers[0].cycles.use_pass_volume_direct = True
    scene.use_nodes = True
    nodes = scene.node_tree.nodes
    nodes.clear()
    layers = nodes.new("CompositorNodeRLayers")
    output = nodes.new("CompositorNodeOutputFile")
    output.base_path = work
    output.format.file_format = "OPEN_EXR"
    output.format.color_depth = "32"
    output.file_slots.clear()
    paths = {}
    for image, socket in (("combined", "Image"), ("volume_direct", "VolumeDir")):
        name = f"cycles_{image}_{seed}_"
        output.file_slots.new(name)
        scene.node_tree.links.new(layers.outputs[socket], output.inputs[name])
        paths[image] = os.path.join(work, f"{name}{scene.frame_current:04d}.exr")
    return paths


def cycles_means(work):
    """Cycles' mean radiance of the imported frame, combined and single
    scattering, once per seed."""
    scene = bpy.context.scene
    means = {"combined": [], "volume_direct": []}
    for seed in range(1, SEEDS + 1):
        matching_cycles(scene, seed)
        paths = write_passes(scene, work, seed)
        scene.render.filepath = os.path.join(work, f"cycles_{seed}.exr")
        bpy.ops.render.render(write_still=False)
        for image, path in paths.items():
            means[image].append(mean_radiance(path))
    return means


def vfield_mean(args, sim, lighting, max_bounces, work):
    """The mean radiance of vfield's reference render of the frame."""
    out = os.path.join(work, f"vfield_{max_bounces}")
    subprocess.run([args.vfield, "--quiet", "render", args.scene, "--sim", sim, "-o", out, "--frames", "1",
                    "--integrator", "reference", "--spp", str(VFIELD_SAMPLES), "--format", "exr",
                    "--set", f"/render/maxBounces={max_bounces}", "--set", "/render/passes=false", *lighting], check=True)
    return mean_radiance(os.path.join(out, "frame.0001.exr"))


def main():
    args = arguments()
    shutil.rmtree(args.work, ignore_errors=True)
    # --factory-startup's cube, lamp and camera are no part of the scene.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    # The cloud is the same whatever the sun: simulated and imported once
    # (the frame's density, camera and sun), then lit three ways.
    sim = os.path.join(args.work, "sim")
    subprocess.run([args.vfield, "--quiet", "simulate", args.scene, "-o", sim, "--frames", "1", *LONE_CLOUD], check=True)
    import_simulation(bpy.context, sim)
    bpy.context.scene.frame_set(1)
    sun = next(obj for obj in bpy.data.objects if obj.type == "LIGHT" and obj.data.type == "SUN")
    failures = []
    for name, direction in LIGHTINGS.items():
        work = os.path.join(args.work, name)
        # As the add-on places vfield's sun: its +z, under the import's root, points at it.
        sun.rotation_quaternion = Vector(direction).to_track_quat("Z", "Y")
        cycles_images = cycles_means(work)
        lighting = [*LONE_CLOUD, "--set", "/sun/direction=[%g,%g,%g]" % direction]
        for scattering, (max_bounces, image) in SCATTERING.items():
            ours = vfield_mean(args, sim, lighting, max_bounces, work)
            cycles = cycles_images[image]
            ratio = statistics.mean(cycles) / ours
            # The standard error of Cycles' mean over its seeds; vfield's, at
            # more samples of a path tracer with less variance, is smaller.
            error = statistics.stdev(cycles) / math.sqrt(SEEDS) / ours if SEEDS > 1 else 0.0
            allowed = TOLERANCE + 3.0 * error
            verdict = "ok" if abs(ratio - 1.0) <= allowed else "FAILS"
            print(f"{name}-lit, {scattering} scattering: Cycles {ratio:.4f} of vfield's reference "
                  f"(Cycles' standard error {error:.4f}; allowed {allowed:.4f}) {verdict}")
            if verdict != "ok":
                failures.append(f"{name} {scattering}: {ratio:.4f}")
    remove_import(sim)
    assert not failures, f"Cycles and vfield's reference disagree: {failures}"


main()
