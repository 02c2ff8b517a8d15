"""Builds a simulated vfield scene in Blender from its host scene.

Everything hangs under one root empty that turns vfield's y-up world into
Blender's z-up one (a rotation of +90 degrees about x: vfield (x, y, z) is
Blender (x, -z, y)); below it, meshes, tracks, the volume, the camera and the
sun keep vfield's coordinates and units (one world unit, one metre).
Importing the same simulation folder again replaces what it made."""

import math
import os

import bpy
from mathutils import Matrix, Quaternion, Vector

from .host_scene import HostScene, read_obj

TAG = "vfield_simulation"  # custom property: the simulation folder an ID was made from

# vfield's terrain colours (plugin/render/materials.cpp), linear RGB.
GRASS, DRY_GRASS = (0.11, 0.2, 0.05), (0.26, 0.24, 0.11)
ROCK, SNOW = (0.2, 0.17, 0.13), (0.85, 0.87, 0.9)


def root_matrix():
    """World from vfield: y up becomes z up."""
    return Matrix.Rotation(math.pi / 2, 4, "X")


def import_simulation(context, simulation_dir):
    """Imports (or re-imports) a simulation folder; returns the root object."""
    host = HostScene(simulation_dir)
    remove_import(host.simulation_dir)
    scene = context.scene

    scene.frame_start, scene.frame_end = host.frame_start, host.frame_end
    scene.render.fps = max(1, round(host.fps))
    scene.render.fps_base = scene.render.fps / host.fps
    scene.render.resolution_x, scene.render.resolution_y = host.camera["resolution"]
    scene.render.resolution_percentage = 100
    scene.render.engine = "CYCLES"
    scene.view_settings.view_transform = "Standard"  # vfield's frames are plain sRGB
    if not getattr(bpy.app.build_options, "openimagedenoise", False):
        scene.cycles.use_denoising = False
    scene.cycles.volume_bounces = 8  # light scatters many times in a cloud (Cycles' default: once)
    scene.frame_set(min(max(scene.frame_current, host.frame_start), host.frame_end))

    collection = _tag(bpy.data.collections.new(f"vfield {host.name}"), host)
    scene.collection.children.link(collection)
    root = _new_object(collection, host, f"vfield {host.name}", None)
    root.matrix_basis = root_matrix()
    root.empty_display_type = "ARROWS"

    for spec in host.objects:
        _add_mesh_object(collection, root, host, spec)
    _add_volume(collection, root, host)
    _add_camera(collection, root, host, scene)
    _add_sun(collection, root, host)
    scene.world = _make_world(host)

    scene.frame_set(scene.frame_current)  # poses the keyframed objects
    return root


def remove_import(simulation_dir):
    """Removes every object, datablock and collection an import of this folder made."""
    key = os.path.abspath(simulation_dir)
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.volumes, bpy.data.cameras, bpy.data.lights,
                       bpy.data.materials, bpy.data.worlds, bpy.data.collections):
        for block in [b for b in collection if b.get(TAG) == key]:
            collection.remove(block)


def _tag(block, host):
    block[TAG] = host.simulation_dir
    return block


def _new_object(collection, host, name, data, parent=None):
    obj = _tag(bpy.data.objects.new(name, data), host)
    collection.objects.link(obj)
    if parent is not None:
        obj.parent = parent
    return obj


def _add_mesh_object(collection, root, host, spec):
    vertices, triangles = read_obj(spec["mesh"])
    mesh = _tag(bpy.data.meshes.new(spec["name"]), host)
    mesh.from_pydata(vertices, [], triangles)
    mesh.validate()
    terrain = spec["material"]["kind"] == "terrain"
    mesh.polygons.foreach_set("use_smooth", [terrain] * len(mesh.polygons))
    heights = [v[1] for v in vertices] or [0.0]
    material = _terrain_material(host, spec["name"], min(heights), max(heights)) if terrain else \
        _painted_material(host, spec["name"], spec["material"]["color"])
    mesh.materials.append(material)
    obj = _new_object(collection, host, spec["name"], mesh, root)
    track = host.tracks.get(spec["name"]) if spec["space"] == "object" else None
    if track:
        _keyframe_track(obj, track)
    return obj


def _keyframe_track(obj, track):
    """One keyframe per simulated frame, linear between them (the simulation's
    own sampling), quaternions kept on one side so that nothing spins."""
    obj.rotation_mode = "QUATERNION"
    previous = None
    for frame, rows in track:
        location, rotation, scale = Matrix(rows).decompose()
        if previous is not None:
            rotation.make_compatible(previous)
        previous = rotation
        obj.location, obj.rotation_quaternion, obj.scale = location, rotation, scale
        for path in ("location", "rotation_quaternion", "scale"):
            obj.keyframe_insert(path, frame=frame)
    _make_linear(obj)


def _make_linear(animated):
    """Keys one a frame, straight between them: vfield's values at each
    frame, whatever interpolation made them."""
    for fcurve in animated.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"


def _add_volume(collection, root, host):
    first = host.density_file(host.frame_start)
    if not os.path.isfile(first):
        return None
    volume = _tag(bpy.data.volumes.new(f"{host.name} density"), host)
    volume.filepath = first
    # The grids' names, read from the first file before it becomes a sequence,
    # let the velocity grid be chosen.
    volume.grids.load()
    volume.velocity_grid = host.volume["velocityGrid"]
    volume.is_sequence = True
    volume.frame_start = host.frame_start
    volume.frame_duration = host.frame_end - host.frame_start + 1
    volume.frame_offset = host.frame_start - 1
    volume.sequence_mode = "CLIP"
    volume.velocity_unit = "SECOND"
    volume.velocity_scale = 1.0
    volume.materials.append(_cloud_material(host))
    return _new_object(collection, host, f"{host.name} cloud", volume, root)


def _cloud_material(host):
    """Principled Volume with vfield's medium: extinction per unit density as
    its density, albedo as its colour (absorption the rest), and the mean
    cosine of vfield's two Henyey-Greenstein lobes as its one lobe."""
    v = host.volume
    material = _tag(bpy.data.materials.new(f"{host.name} cloud"), host)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    shader = nodes.new("ShaderNodeVolumePrincipled")
    shader.inputs["Density"].default_value = v["extinction"]
    shader.inputs["Density Attribute"].default_value = v["densityGrid"]
    shader.inputs["Color"].default_value = (v["albedo"], v["albedo"], v["albedo"], 1.0)
    shader.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    weight = v["backWeight"]
    shader.inputs["Anisotropy"].default_value = (1 - weight) * v["anisotropy"] + weight * v["backAnisotropy"]
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(shader.outputs["Volume"], output.inputs["Volume"])
    return material


def _painted_material(host, name, color):
    material = _tag(bpy.data.materials.new(f"{name} paint"), host)
    material.use_nodes = True
    shader = material.node_tree.nodes["Principled BSDF"]
    shader.inputs["Base Color"].default_value = (*color, 1.0)
    shader.inputs["Roughness"].default_value = 0.6
    shader.inputs["Specular"].default_value = 0.2
    material.diffuse_color = (*color, 1.0)
    return material


def _terrain_material(host, name, low, high):
    """vfield's terrain: grass low and flat turning dry higher up, rock where
    steep, snow high and flat; world-space noise makes the borders wander."""
    material = _tag(bpy.data.materials.new(f"{name} terrain"), host)
    material.use_nodes = True
    tree = material.node_tree
    nodes, links = tree.nodes, tree.links
    shader = nodes["Principled BSDF"]
    shader.inputs["Roughness"].default_value = 0.95
    shader.inputs["Specular"].default_value = 0.05

    geometry = nodes.new("ShaderNodeNewGeometry")
    position = nodes.new("ShaderNodeSeparateXYZ")
    links.new(geometry.outputs["Position"], position.inputs["Vector"])
    normal = nodes.new("ShaderNodeSeparateXYZ")
    links.new(geometry.outputs["Normal"], normal.inputs["Vector"])
    noise = nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 0.02
    noise.inputs["Detail"].default_value = 6.0
    links.new(geometry.outputs["Position"], noise.inputs["Vector"])

    def add(a, b):
        node = nodes.new("ShaderNodeMath")
        node.operation = "MULTIPLY_ADD"
        links.new(a, node.inputs[0])
        node.inputs[1].default_value = 0.15
        links.new(b, node.inputs[2])
        return node.outputs[0]

    def smoothstep(value, edge0, edge1):
        node = nodes.new("ShaderNodeMapRange")
        node.interpolation_type = "SMOOTHSTEP"
        links.new(value, node.inputs["Value"])
        node.inputs["From Min"].default_value = edge0
        node.inputs["From Max"].default_value = edge1
        return node.outputs["Result"]

    def mix(factor, a, b):
        node = nodes.new("ShaderNodeMixRGB")
        links.new(factor, node.inputs["Fac"])
        for socket, colour in ((node.inputs["Color1"], a), (node.inputs["Color2"], b)):
            if isinstance(colour, tuple):
                socket.default_value = (*colour, 1.0)
            else:
                links.new(colour, socket)
        return node.outputs["Color"]

    wobble = nodes.new("ShaderNodeMath")
    wobble.operation = "SUBTRACT"
    links.new(noise.outputs["Fac"], wobble.inputs[0])
    wobble.inputs[1].default_value = 0.5
    height01 = smoothstep(position.outputs["Z"], low, high)
    height = add(wobble.outputs[0], height01)
    slope = add(wobble.outputs[0], normal.outputs["Z"])
    colour = mix(smoothstep(height, 0.25, 0.75), GRASS, DRY_GRASS)
    colour = mix(smoothstep(slope, 0.72, 0.55), colour, ROCK)
    snow = nodes.new("ShaderNodeMath")
    snow.operation = "MULTIPLY"
    links.new(smoothstep(height, 0.85, 0.95), snow.inputs[0])
    links.new(smoothstep(slope, 0.5, 0.75), snow.inputs[1])
    colour = mix(snow.outputs[0], colour, SNOW)
    links.new(colour, shader.inputs["Base Color"])
    return material


def _camera_matrix(pose):
    """Blender's camera looks down its -z with +y up."""
    position, look_at, up = (Vector(pose[k]) for k in ("position", "lookAt", "up"))
    forward = (look_at - position).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    rotation = Matrix((right, true_up, -forward)).transposed()
    return Matrix.Translation(position) @ rotation.to_4x4()


def _add_camera(collection, root, host, scene):
    data = _tag(bpy.data.cameras.new(f"{host.name} camera"), host)
    data.sensor_fit = "VERTICAL"
    data.clip_start, data.clip_end = 0.1, 1.0e5
    camera = _new_object(collection, host, f"{host.name} camera", data, root)
    poses = host.camera["poses"]
    data.angle_y = math.radians(poses[0]["fovDegrees"])
    camera.matrix_basis = _camera_matrix(poses[0])
    if len(poses) > 1:
        camera.rotation_mode = "QUATERNION"
        previous = None
        for pose in poses:
            location, rotation, _ = _camera_matrix(pose).decompose()
            if previous is not None:
                rotation.make_compatible(previous)
            previous = rotation
            camera.location, camera.rotation_quaternion = location, rotation
            camera.keyframe_insert("location", frame=pose["frame"])
            camera.keyframe_insert("rotation_quaternion", frame=pose["frame"])
            data.angle_y = math.radians(pose["fovDegrees"])
            data.keyframe_insert("lens", frame=pose["frame"])
        _make_linear(camera)
        _make_linear(data)
    scene.camera = camera
    return camera


def _add_sun(collection, root, host):
    """The sun's irradiance is vfield's intensity times its colour (surfaces
    reflect albedo / pi of it in both renderers)."""
    data = _tag(bpy.data.lights.new(f"{host.name} sun", "SUN"), host)
    data.angle = math.radians(0.53)
    light = _new_object(collection, host, f"{host.name} sun", data, root)
    light.rotation_mode = "QUATERNION"
    _set_sun(light, data, host.sun)
    if "frames" in host.sun:
        for sun in host.sun["frames"]:
            _set_sun(light, data, sun)
            light.keyframe_insert("rotation_quaternion", frame=sun["frame"])
            data.keyframe_insert("color", frame=sun["frame"])
            data.keyframe_insert("energy", frame=sun["frame"])
        _make_linear(light)
        _make_linear(data)
    return light


def _set_sun(light, data, sun):
    brightest = max(sun["color"]) or 1.0
    data.color = [c / brightest for c in sun["color"]]
    data.energy = sun["intensity"] * brightest
    # The light shines down its -z: +z points at the sun.
    light.rotation_quaternion = Vector(sun["direction"]).to_track_quat("Z", "Y")


def _make_world(host):
    """vfield's sky dome: horizon to zenith over the lower half of the sky."""
    sky = host.sky
    world = _tag(bpy.data.worlds.new(f"{host.name} sky"), host)
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    background.inputs["Strength"].default_value = sky["intensity"]
    coordinates = nodes.new("ShaderNodeTexCoord")
    direction = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coordinates.outputs["Generated"], direction.inputs["Vector"])
    height = nodes.new("ShaderNodeMapRange")
    height.interpolation_type = "SMOOTHSTEP"
    height.inputs["From Min"].default_value, height.inputs["From Max"].default_value = 0.0, 0.5
    links.new(direction.outputs["Z"], height.inputs["Value"])
    gradient = nodes.new("ShaderNodeMixRGB")
    gradient.inputs["Color1"].default_value = (*sky["horizonColor"], 1.0)
    gradient.inputs["Color2"].default_value = (*sky["zenithColor"], 1.0)
    links.new(height.outputs["Result"], gradient.inputs["Fac"])
    links.new(gradient.outputs["Color"], background.inputs["Color"])
    return world
