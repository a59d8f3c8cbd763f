# What the Blender scene scripts share: arguments, materials, and the Cycles settings and
# passes mcdenoise reads (README, "Frames from other renderers"): Combined, the light
# passes, Denoising Albedo/Normal/Depth, IndexOB, IndexMA, Debug Sample Count. A scene
# script builds its objects between Begin() and Render().
import argparse
import math
import random
import sys

import bpy


def Begin(description):
    """Parse the arguments after "--" and start from an empty scene."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--out", required=True)
    parser.add_argument("--jitter", action="store_true",
                        help="shift the camera by a sub-pixel offset drawn from the pixel filter "
                        "(seeded by --seed); use it for independent 1-spp frames, see Render()")
    args = parser.parse_args(argv)
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
    filter, so the mean converges to the reference. Cycles samples its filter per axis."""
    rng = random.Random(seed)
    width = scene.cycles.filter_width
    size = max(scene.render.resolution_x, scene.render.resolution_y)
    camera = scene.camera.data
    # A shift of 1 moves the image by its larger dimension.
    camera.shift_x += BlackmanHarrisOffset(rng, width) / size
    camera.shift_y += BlackmanHarrisOffset(rng, width) / size


def Render(scene, args):
    """Render with every pass mcdenoise reads and write the multilayer EXR."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.seed = args.seed
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    # No clamping: a clamped frame is biased against its reference.
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "AUTO"
    if args.jitter:
        JitterCamera(scene, args.seed)

    layer = scene.view_layers[0]
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

    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.filepath = args.out
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
