# A procedural scene for Blender Cycles: fine texture detail a denoiser must keep. A wall
# with a fine checker and raised letters "ABC" in front of it, lit at a grazing angle by
# one area light and a dim fill, so the letters' facets and shadows carry the detail.
# Writes a multilayer EXR with the passes mcdenoise reads (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/textured_plane.py -- \
#       --spp 16 --seed 1 --size 128 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import AreaLight, Begin, Render, add, material  # noqa: E402

args, scene = Begin("render the textured plane with Cycles")

wall = material("wall", (0.7, 0.6, 0.45, 1.0), checker=True, index=1)
wall.node_tree.nodes["Checker Texture"].inputs["Scale"].default_value = 40.0
letters = material("letters", (0.8, 0.8, 0.8, 1.0), roughness=0.5, index=2)

bpy.ops.mesh.primitive_plane_add(size=4, location=(0, 0, 0), rotation=(1.5708, 0, 0))
add(bpy.context.object, wall, 1)

bpy.ops.object.text_add(location=(-1.1, -0.05, -0.35), rotation=(1.5708, 0, 0))
text = bpy.context.object
text.data.body = "ABC"
text.data.size = 1.0
text.data.extrude = 0.05
bpy.ops.object.convert(target="MESH")
add(bpy.context.object, letters, 2)

AreaLight((-2.5, -1.0, 0.5), 0.6, 300.0).rotation_euler = (0, -1.2, 0)
AreaLight((0, -3.0, 1.0), 3.0, 30.0).rotation_euler = (1.2, 0, 0)

bpy.ops.object.camera_add(location=(0, -3.0, 0), rotation=(1.5708, 0, 0))
scene.camera = bpy.context.object
scene.camera.data.lens = 40

Render(scene, args)
