# A procedural product shot for Blender Cycles on transparent film (Film > Transparent): the
# background is alpha 0 for compositing, only the objects and their pedestal are opaque. A
# glossy ceramic head, a brushed-metal ring and a pedestal under a key light, a rim light and
# a studio sky that lights the scene but is not seen. Writes a multilayer EXR (common.py).
# Headless:
#   blender -b --factory-startup -P scripts/blender/product_transparent.py -- \
#       --spp 16 --seed 1 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import AreaLight, Begin, Camera, Principled, Render, World, add  # noqa: E402

args, scene = Begin("render the transparent-film product shot with Cycles", size=256)
World(scene, (0.7, 0.75, 0.8, 1.0), 0.5, horizon=(0.3, 0.3, 0.3, 1.0))
scene.render.film_transparent = True

ceramic = Principled("ceramic", 1, (0.1, 0.25, 0.6, 1.0), Roughness=0.15, Clearcoat=0.8)
metal = Principled("metal", 2, (0.9, 0.88, 0.85, 1.0), Metallic=1.0, Roughness=0.3)
stone = Principled("stone", 3, (0.55, 0.53, 0.5, 1.0), Roughness=0.7)

bpy.ops.mesh.primitive_cylinder_add(radius=0.9, depth=0.2, location=(0, 0, 0.1), vertices=96)
add(bpy.context.object, stone, 3)
bpy.ops.mesh.primitive_monkey_add(size=0.9, location=(-0.2, 0.1, 0.65), rotation=(-0.3, 0, 0.3))
head = bpy.context.object
head.modifiers.new("smooth", "SUBSURF").levels = 2
bpy.ops.object.shade_smooth()
add(head, ceramic, 1)
bpy.ops.mesh.primitive_torus_add(location=(0.5, -0.35, 0.33), major_radius=0.2,
                                 minor_radius=0.05, rotation=(1.1, 0, -0.4),
                                 major_segments=64, minor_segments=24)
bpy.ops.object.shade_smooth()
add(bpy.context.object, metal, 2)

AreaLight((-2.0, -1.5, 2.5), 1.2, 300.0).rotation_euler = (0.6, -0.6, 0)
AreaLight((1.5, 2.0, 1.8), 0.6, 200.0).rotation_euler = (-0.9, 0.6, 0)

Camera(scene, (0.2, -3.0, 1.4), (0.0, 0.0, 0.5), lens=45)

Render(scene, args)
