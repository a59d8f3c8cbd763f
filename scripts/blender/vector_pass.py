# Measure what the 4 channels of Cycles' Vector pass mean: which frame each pair points
# to, its sign, its units and which way its y axis runs. An orthographic camera looks down
# -Z at a black world, one world unit per pixel; an emissive square moves by known,
# different steps between frames 1, 2 and 3 (constant keyframes, so frame f holds frame
# f's pose exactly), and in a second run the camera moves instead. Frame 2 is rendered and
# the pass read at the square's centre pixel. Headless:
#   blender -b --factory-startup -P scripts/blender/vector_pass.py -- --out /tmp/vec
# Prints the measured vectors and writes vec_object.exr and vec_camera.exr under --out.
import argparse
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
parser = argparse.ArgumentParser(description="measure Cycles' Vector pass")
parser.add_argument("--out", required=True)
args = parser.parse_args(argv)
os.makedirs(args.out, exist_ok=True)

SIZE = 32
# World-space steps (x, y) of the square (or, negated, of the camera) from frame 1 to 2
# and from frame 2 to 3: unequal, so the two pairs of channels tell them apart.
STEP_IN = (2.0, 1.0)
STEP_OUT = (4.0, 3.0)


def Scene(move_camera):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.use_motion_blur = False
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("black")
    world.color = (0, 0, 0)
    scene.world = world

    bpy.ops.mesh.primitive_plane_add(size=6, location=(0, 0, 0))
    square = bpy.context.object
    mat = bpy.data.materials.new("emit")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    emit = nodes.new("ShaderNodeEmission")
    mat.node_tree.links.new(emit.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    square.data.materials.append(mat)

    bpy.ops.object.camera_add(location=(0, 0, 10), rotation=(0, 0, 0))
    camera = bpy.context.object
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = SIZE  # one world unit per pixel
    scene.camera = camera

    moving, sign = (camera, -1.0) if move_camera else (square, 1.0)
    base = moving.location.copy()
    poses = {1: (0.0, 0.0), 2: STEP_IN, 3: (STEP_IN[0] + STEP_OUT[0], STEP_IN[1] + STEP_OUT[1])}
    for frame, (dx, dy) in poses.items():
        moving.location = (base.x + sign * dx, base.y + sign * dy, base.z)
        moving.keyframe_insert("location", frame=frame)
    for fcurve in moving.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "CONSTANT"
    scene.frame_set(2)
    return scene


def Render(scene, path):
    layer = scene.view_layers[0]
    layer.use_pass_combined = True
    layer.use_pass_vector = True
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    scene.render.filepath = path
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)


for name, move_camera in (("object", False), ("camera", True)):
    scene = Scene(move_camera)
    path = os.path.join(args.out, f"vec_{name}.exr")
    Render(scene, path)
