# A procedural scene for Blender Cycles: a closed box with a checker-textured floor, a
# glossy sphere, a diffuse cube and a small bright light (fireflies through the glossy
# paths). Writes a multilayer EXR with the passes mcdenoise reads (README, "Frames from
# other renderers"): Combined, the light passes, Denoising Albedo/Normal/Depth, IndexOB,
# IndexMA. Headless:
#   blender -b --factory-startup -P scripts/blender/glossy_box.py -- \
#       --spp 16 --seed 1 --size 64 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import AreaLight, Begin, Box, Render, add, material  # noqa: E402

args, scene = Begin("render the glossy box with Cycles")

white = material("white", (0.8, 0.8, 0.8, 1.0), index=1)
red = material("red", (0.8, 0.1, 0.1, 1.0), index=2)
green = material("green", (0.1, 0.7, 0.1, 1.0), index=3)
floor = material("floor", (0.8, 0.7, 0.5, 1.0), checker=True, index=4)
glossy = material("glossy", (0.9, 0.9, 0.9, 1.0), roughness=0.15, metallic=1.0, index=5)

Box(scene, floor, white, red, green)

bpy.ops.mesh.primitive_uv_sphere_add(radius=0.4, location=(0.35, 0.2, -0.6), segments=48,
                                     ring_count=24)
bpy.ops.object.shade_smooth()
add(bpy.context.object, glossy, 6)
bpy.ops.mesh.primitive_cube_add(size=0.6, location=(-0.4, 0.3, -0.7), rotation=(0, 0, 0.4))
add(bpy.context.object, white, 7)

# A small, bright light near the ceiling: most paths miss it, the ones that hit make
# fireflies.
AreaLight((0, 0, 0.98), 0.15, 60.0)

Render(scene, args)
