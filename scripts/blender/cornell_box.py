# A procedural scene for Blender Cycles: the classic diffuse Cornell box, a tall and a short
# block under a square ceiling light, all indirect light diffuse. Writes a multilayer EXR
# with the passes mcdenoise reads (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/cornell_box.py -- \
#       --spp 16 --seed 1 --size 128 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import AreaLight, Begin, Box, Render, add, material  # noqa: E402

args, scene = Begin("render the Cornell box with Cycles")

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

# A ceiling light a quarter of the ceiling's width: soft shadows, few fireflies.
AreaLight((0, 0, 0.98), 0.5, 40.0)

Render(scene, args)
