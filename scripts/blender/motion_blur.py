# A procedural scene for Blender Cycles with motion blur: a ball thrown across the view, a
# spinning fan and a swinging pendulum, over a tiled floor before a striped wall; the
# shutter is open for half a frame. Writes a multilayer EXR (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/motion_blur.py -- \
#       --spp 16 --seed 1 --out frame.exr
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import (AreaLight, Begin, Camera, Keyframes, Principled, Render, Texture,  # noqa: E402
                    World, add)

args, scene = Begin("render the motion blur scene with Cycles", size=256)
World(scene, (0.5, 0.55, 0.6, 1.0), 0.3)

floor = Principled("floor", 1, (0.5, 0.5, 0.5, 1.0), Roughness=0.4)
Texture(floor, "Checker", Scale=24.0, Color1=(0.6, 0.58, 0.55, 1.0),
        Color2=(0.2, 0.2, 0.22, 1.0))
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 2, 0))
add(bpy.context.object, floor, 1)
wall = Principled("wall", 2, (0.5, 0.5, 0.5, 1.0))
Texture(wall, "Wave", Scale=3.0, Distortion=0.0)
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 3.5, 2), rotation=(1.5708, 0, 0))
add(bpy.context.object, wall, 2)

# The frame rendered is frame 1; objects are keyed at frames 0, 1 and 2.
scene.frame_set(1)
scene.render.use_motion_blur = True
scene.render.motion_blur_shutter = 0.5

ball = Principled("ball", 3, (0.85, 0.1, 0.08, 1.0), Roughness=0.3)
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.18, segments=48, ring_count=24)
bpy.ops.object.shade_smooth()
add(bpy.context.object, ball, 3)
Keyframes(bpy.context.object, "location", [(-1.6, 1.2, 1.0), (-0.2, 1.2, 1.2), (1.2, 1.2, 1.0)])

# A fan: four blades on a hub, turning a quarter turn per frame about the y axis.
blade = Principled("blade", 4, (0.9, 0.85, 0.3, 1.0), Roughness=0.5)
bpy.ops.object.empty_add(location=(0.7, 2.2, 1.6))
hub = bpy.context.object
for k in range(4):
    angle = k * math.pi / 2
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0.7 + 0.3 * math.cos(angle), 2.2,
                                                      1.6 + 0.3 * math.sin(angle)),
                                    rotation=(0, -angle, 0))
    piece = bpy.context.object
    piece.scale = (0.5, 0.02, 0.1)
    add(piece, blade, 4)
    piece.parent = hub
    piece.matrix_parent_inverse = hub.matrix_world.inverted()
Keyframes(hub, "rotation_euler", [(0, 0, 0), (0, math.pi / 2, 0), (0, math.pi, 0)])
# Rotation is blurred along an arc only with more than two transform steps.
hub.cycles.motion_steps = 4
for piece in hub.children:
    piece.cycles.motion_steps = 4

# A pendulum: a metal bob on a thin rod, swinging through the bottom of its arc.
metal = Principled("metal", 5, (0.8, 0.8, 0.85, 1.0), Metallic=1.0, Roughness=0.2)
bpy.ops.object.empty_add(location=(-0.9, 2.0, 2.4))
pivot = bpy.context.object
bpy.ops.mesh.primitive_cylinder_add(radius=0.01, depth=1.5, location=(-0.9, 2.0, 1.65))
rod = bpy.context.object
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.15, location=(-0.9, 2.0, 0.85))
bpy.ops.object.shade_smooth()
bob = bpy.context.object
for part in (rod, bob):
    add(part, metal, 5)
    part.parent = pivot
    part.matrix_parent_inverse = pivot.matrix_world.inverted()
Keyframes(pivot, "rotation_euler", [(0, -0.25, 0), (0, 0, 0), (0, 0.25, 0)])

AreaLight((-1.5, -0.5, 3.0), 1.5, 300.0).rotation_euler = (0.3, -0.4, 0)
Camera(scene, (0.0, -2.4, 1.3), (0.0, 1.5, 1.1), lens=32)

Render(scene, args)
