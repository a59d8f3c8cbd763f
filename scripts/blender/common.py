# What the Blender scene scripts share: arguments, materials, and the Cycles settings and
# passes mcdenoise reads (README, "Frames from other renderers"): Combined, the light
# passes, Denoising Albedo/Normal/Depth, IndexOB, IndexMA, Debug Sample Count. A scene
# script builds its objects between Begin() and Render().
import argparse
import math
import random
import sys

import bpy
import mathutils


def Begin(description, size=64):
    """Parse the arguments after "--" and start from an empty scene."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--size", type=int, default=size)
    parser.add_argument("--out", required=True)
    parser.add_argument("--jitter", action="store_true",
                        help="shift the camera by a sub-pixel offset drawn from the pixel filter "
                        "(seeded by --seed); use it for independent 1-spp frames, see Render()")
    parser.add_argument("--count", type=int, default=1,
                        help="render this many frames, seeds --seed, --seed + 1, ..., in one "
                        "Blender process (saves its start per frame); --out then holds {seed}")
    parser.add_argument("--passes", choices=("all", "default"), default="all",
                        help="all: every pass mcdenoise reads; default: what a user has, "
                        "Blender's default passes (Combined, Z) plus the Denoising Data passes")
    args = parser.parse_args(argv)
    if args.count > 1 and "{seed}" not in args.out:
        parser.error("--count needs {seed} in --out")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return args, bpy.context.scene


def material(name, color, roughness=1.0, metallic=0.0, checker=False, index=0):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.pass_index = index
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    if checker:
        tex = mat.node_tree.nodes.new("ShaderNodeTexChecker")
        tex.inputs["Scale"].default_value = 8.0
        tex.inputs["Color1"].default_value = color
        tex.inputs["Color2"].default_value = (0.1, 0.1, 0.1, 1.0)
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def add(obj, mat, index):
    obj.data.materials.append(mat)
    obj.pass_index = index
    return obj


def Box(scene, floor, white, red, green):
    """A Cornell box 2 units wide, open to the camera, and the camera looking in."""
    walls = [((0, 0, -1), (0, 0, 0), floor, 1), ((0, 0, 1), (3.14159, 0, 0), white, 2),
             ((0, 1, 0), (1.5708, 0, 0), white, 3), ((-1, 0, 0), (0, 1.5708, 0), red, 4),
             ((1, 0, 0), (0, -1.5708, 0), green, 5)]
    for location, rotation, mat, index in walls:
        bpy.ops.mesh.primitive_plane_add(size=2, location=location, rotation=rotation)
        add(bpy.context.object, mat, index)
    bpy.ops.object.camera_add(location=(0, -3.4, 0), rotation=(1.5708, 0, 0))
    scene.camera = bpy.context.object
    scene.camera.data.lens = 35


def AreaLight(location, size, energy):
    bpy.ops.object.light_add(type="AREA", location=location)
    light = bpy.context.object
    light.data.size = size
    light.data.energy = energy
    return light


def Principled(name, index, color, **inputs):
    """A Principled BSDF material; `inputs` sets its sockets by name with spaces as
    underscores (Roughness=0.2, Transmission=1.0, Emission_Strength=50.0, ...)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.pass_index = index
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = color
    for key, value in inputs.items():
        bsdf.inputs[key.replace("_", " ")].default_value = value
    return mat


def Texture(mat, kind, socket="Base Color", **inputs):
    """Add a texture node of this kind ("Checker", "Brick", "Noise", "Wave", ...) and link its
    Color output into the material's Principled BSDF socket; returns the node."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    tex = nodes.new(f"ShaderNodeTex{kind}")
    for key, value in inputs.items():
        tex.inputs[key.replace("_", " ")].default_value = value
    links.new(tex.outputs["Color"], nodes["Principled BSDF"].inputs[socket])
    return tex


def World(scene, color, strength, horizon=None):
    """A world of one colour, or a vertical gradient from `horizon` to `color` at the zenith."""
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    scene.world = world
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    background.inputs["Strength"].default_value = strength
    if horizon is None:
        background.inputs["Color"].default_value = color
        return world
    coords = nodes.new("ShaderNodeTexCoord")
    split = nodes.new("ShaderNodeSeparateXYZ")
    ramp = nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = horizon
    ramp.color_ramp.elements[1].color = color
    links.new(coords.outputs["Generated"], split.inputs["Vector"])
    links.new(split.outputs["Z"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], background.inputs["Color"])
    return world


def Camera(scene, location, target, lens=35.0):
    """Add the scene camera at `location` looking at `target`."""
    bpy.ops.object.camera_add(location=location)
    camera = bpy.context.object
    direction = mathutils.Vector(target) - mathutils.Vector(location)
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    camera.data.lens = lens
    scene.camera = camera
    return camera


def Keyframes(obj, path, values):
    """Key `obj.<path>` to values[i] at frame i with linear interpolation (motion blur)."""
    for frame, value in enumerate(values):
        setattr(obj, path, value)
        obj.keyframe_insert(data_path=path, frame=frame)
    for curve in obj.animation_data.action.fcurves:
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"


def BlackmanHarrisOffset(rng, width):
    """One offset in pixels drawn from Cycles' 1D Blackman-Harris pixel filter of this width."""
    while True:
        x = rng.uniform(-0.5 * width, 0.5 * width)
        t = 2 * math.pi * (x / width + 0.5)
        f = 0.35875 - 0.48829 * math.cos(t) + 0.14128 * math.cos(2 * t) - 0.01168 * math.cos(3 * t)
        if rng.uniform(0, 1) <= f:
            return x


def JitterCamera(scene, seed):
    """Cycles traces a pixel's sample 0 through the pixel's centre whatever the seed: N 1-spp
    frames with different seeds then share every camera ray, and their mean converges to the
    point-sampled (aliased) image, not to the filtered pixels of a many-spp reference (their
    albedo, normal and depth are identical at every pixel). Shifting the whole camera by an
    offset drawn from the pixel filter makes each frame's sample an independent draw of the
    filter, so the mean converges to the reference. Cycles samples its filter per axis, and
    its Blackman-Harris spans twice the filter width the user sets."""
    rng = random.Random(seed)
    width = 2 * scene.cycles.filter_width
    size = max(scene.render.resolution_x, scene.render.resolution_y)
    camera = scene.camera.data
    # A shift of 1 moves the image by its larger dimension.
    camera.shift_x += BlackmanHarrisOffset(rng, width) / size
    camera.shift_y += BlackmanHarrisOffset(rng, width) / size


def DefaultPasses(layer):
    """What a user has: a new view layer's passes (Combined with alpha, Z) and the Denoising
    Data passes (Denoising Normal, Albedo, Depth) that Blender's denoisers read."""
    layer.use_pass_combined = True
    layer.use_pass_z = True
    layer.cycles.denoising_store_passes = True


def AllPasses(layer):
    """Every pass mcdenoise reads."""
    layer.use_pass_combined = True
    layer.use_pass_z = True
    layer.use_pass_normal = True
    layer.use_pass_object_index = True
    layer.use_pass_material_index = True
    for kind in ("diffuse", "glossy", "transmission"):
        for part in ("direct", "indirect", "color"):
            setattr(layer, f"use_pass_{kind}_{part}", True)
    layer.use_pass_emit = True
    layer.use_pass_environment = True
    layer.cycles.denoising_store_passes = True
    # The pixel's share of the samples; mcdenoise makes it spp with cycles.<layer>.samples.
    if hasattr(layer.cycles, "pass_debug_sample_count"):
        layer.cycles.pass_debug_sample_count = True
    if hasattr(layer.cycles, "use_pass_volume_direct"):
        layer.cycles.use_pass_volume_direct = True
        layer.cycles.use_pass_volume_indirect = True


def Render(scene, args):
    """Render with the passes --passes names and write the multilayer EXR, or --count of them
    with consecutive seeds (each jittered anew with --jitter)."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    # No clamping: a clamped frame is biased against its reference.
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "AUTO"

    layer = scene.view_layers[0]
    if args.passes == "default":
        DefaultPasses(layer)
    else:
        AllPasses(layer)

    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.use_file_extension = False
    camera = scene.camera.data
    shift = camera.shift_x, camera.shift_y
    for seed in range(args.seed, args.seed + args.count):
        scene.cycles.seed = seed
        camera.shift_x, camera.shift_y = shift
        if args.jitter:
            JitterCamera(scene, seed)
        scene.render.filepath = args.out.replace("{seed}", str(seed))
        bpy.ops.render.render(write_still=True)


def CornellBox(scene):
    """The classic diffuse Cornell box: white, red and green walls (ids 1-3), a tall and a
    short white block (6, 7) and a ceiling light a quarter of the ceiling's width (soft
    shadows, few fireflies)."""
    white = material("white", (0.73, 0.73, 0.73, 1.0), index=1)
    red = material("red", (0.65, 0.05, 0.05, 1.0), index=2)
    green = material("green", (0.12, 0.45, 0.15, 1.0), index=3)
    Box(scene, white, white, red, green)
    bpy.ops.mesh.primitive_cube_add(size=1, location=(-0.35, 0.3, -0.4), rotation=(0, 0, 0.3))
    tall = bpy.context.object
    tall.scale = (0.55, 0.55, 1.2)
    add(tall, white, 6)
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0.4, -0.2, -0.7), rotation=(0, 0, -0.3))
    short = bpy.context.object
    short.scale = (0.55, 0.55, 0.6)
    add(short, white, 7)
    AreaLight((0, 0, 0.98), 0.5, 40.0)
