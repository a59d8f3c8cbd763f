# A procedural night scene for Blender Cycles: small, very bright lights (glowing bulbs a few
# pixels wide) above polished metal objects on a glossy dark floor, so most of what the
# camera sees is glossy reflection of small lights, with caustics (fireflies) on the walls.
# Writes a multilayer EXR (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/glossy_lights.py -- \
#       --spp 16 --seed 1 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import Begin, Camera, Principled, Render, World, add  # noqa: E402

args, scene = Begin("render the glossy lights scene with Cycles", size=256)
World(scene, (0.02, 0.025, 0.04, 1.0), 1.0)

floor = Principled("floor", 1, (0.05, 0.05, 0.06, 1.0), Roughness=0.12, Specular=0.6)
wall = Principled("wall", 2, (0.35, 0.33, 0.3, 1.0), Roughness=0.9)
chrome = Principled("chrome", 3, (0.95, 0.95, 0.95, 1.0), Metallic=1.0, Roughness=0.03)
gold = Principled("gold", 4, (1.0, 0.72, 0.3, 1.0), Metallic=1.0, Roughness=0.2)
copper = Principled("copper", 5, (0.95, 0.55, 0.4, 1.0), Metallic=1.0, Roughness=0.35)

bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 2, 0))
add(bpy.context.object, floor, 1)
bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 3.0, 3), rotation=(1.5708, 0, 0))
add(bpy.context.object, wall, 2)

bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(-0.7, 0.8, 0.45), segments=64,
                                     ring_count=32)
bpy.ops.object.shade_smooth()
add(bpy.context.object, chrome, 3)
bpy.ops.mesh.primitive_torus_add(location=(0.55, 0.5, 0.3), major_radius=0.4,
                                 minor_radius=0.12, rotation=(1.2, 0, 0.5),
                                 major_segments=64, minor_segments=24)
bpy.ops.object.shade_smooth()
add(bpy.context.object, gold, 4)
bpy.ops.mesh.primitive_monkey_add(size=0.6, location=(1.05, 1.9, 0.35), rotation=(0, 0, 0.4))
monkey = bpy.context.object
monkey.modifiers.new("smooth", "SUBSURF").levels = 2
bpy.ops.object.shade_smooth()
add(monkey, copper, 5)

# Bulbs: small emitting spheres, bright enough to light the scene from a few pixels.
bulbs = [((-1.4, 1.2, 1.6), (1.0, 0.8, 0.55)), ((0.1, 0.2, 1.4), (1.0, 0.9, 0.8)),
         ((1.3, 1.8, 1.9), (0.6, 0.75, 1.0)), ((-0.3, 2.4, 0.9), (1.0, 0.5, 0.3)),
         ((1.6, 0.6, 0.5), (0.8, 1.0, 0.8))]
for i, (location, color) in enumerate(bulbs):
    bulb = Principled(f"bulb{i}", 6 + i, (0, 0, 0, 1), Emission=color + (1.0,),
                      Emission_Strength=400.0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03, location=location, segments=16,
                                         ring_count=8)
    add(bpy.context.object, bulb, 6 + i)

Camera(scene, (0.0, -2.6, 1.1), (0.0, 1.0, 0.45), lens=35)

Render(scene, args)
