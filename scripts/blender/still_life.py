# A procedural still life for Blender Cycles: a table with a fine checkered cloth (texture at
# pixel scale, finer than a pixel towards the back), a glass sphere and a glass tumbler, a
# striped cup and fruit, a brick backdrop; the camera focuses on the glass sphere at f/1.4, so
# the cloth in front and the bricks behind are out of focus (depth of field). Lit by one
# soft key light and a dim sky. Writes a multilayer EXR (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/still_life.py -- \
#       --spp 16 --seed 1 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import (AreaLight, Begin, Camera, Principled, Render, Texture, World,  # noqa: E402
                    add)

args, scene = Begin("render the still life with Cycles", size=256)
World(scene, (0.55, 0.65, 0.8, 1.0), 0.25)

cloth = Principled("cloth", 1, (0.8, 0.8, 0.8, 1.0), Roughness=0.8)
Texture(cloth, "Checker", Scale=160.0, Color1=(0.75, 0.72, 0.65, 1.0),
        Color2=(0.15, 0.2, 0.45, 1.0))
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 2.0, 0))
add(bpy.context.object, cloth, 1)

bricks = Principled("bricks", 2, (0.6, 0.3, 0.2, 1.0))
Texture(bricks, "Brick", Scale=12.0, Color1=(0.55, 0.22, 0.12, 1.0),
        Color2=(0.4, 0.18, 0.1, 1.0), Mortar=(0.7, 0.68, 0.6, 1.0), Mortar_Size=0.03)
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 4.0, 2.0), rotation=(1.5708, 0, 0))
add(bpy.context.object, bricks, 2)

glass = Principled("glass", 3, (1.0, 1.0, 1.0, 1.0), Roughness=0.0, Transmission=1.0, IOR=1.5)
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.22, location=(0.05, 0.3, 0.22), segments=64,
                                     ring_count=32)
bpy.ops.object.shade_smooth()
add(bpy.context.object, glass, 3)
# A solid glass tumbler with a rounded rim: light refracts through it and its caustic falls
# on the cloth.
bpy.ops.mesh.primitive_cylinder_add(radius=0.14, depth=0.4, location=(-0.45, 0.75, 0.2),
                                    vertices=64)
bpy.ops.object.shade_smooth()
tumbler = bpy.context.object
tumbler.modifiers.new("rim", "BEVEL").width = 0.03
tumbler.modifiers["rim"].segments = 4
tumbler.data.use_auto_smooth = True
add(tumbler, glass, 4)

cup = Principled("cup", 5, (0.9, 0.9, 0.85, 1.0), Roughness=0.25)
Texture(cup, "Wave", Scale=6.0, Distortion=0.0).wave_type = "RINGS"
bpy.ops.mesh.primitive_cylinder_add(radius=0.16, depth=0.3, location=(0.5, 0.9, 0.15),
                                    vertices=48)
bpy.ops.object.shade_smooth()
add(bpy.context.object, cup, 5)

fruit = Principled("fruit", 6, (0.9, 0.45, 0.05, 1.0), Roughness=0.45)
# Orange peel: fine noise through a bump node, detail at pixel scale.
noise = fruit.node_tree.nodes.new("ShaderNodeTexNoise")
noise.inputs["Scale"].default_value = 80.0
noise.inputs["Detail"].default_value = 4.0
bump = fruit.node_tree.nodes.new("ShaderNodeBump")
bump.inputs["Strength"].default_value = 0.4
fruit.node_tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
fruit.node_tree.links.new(bump.outputs["Normal"],
                          fruit.node_tree.nodes["Principled BSDF"].inputs["Normal"])
for x, y, r in ((0.42, 0.25, 0.11), (0.62, 0.38, 0.1), (-0.3, 0.1, 0.09)):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=r, location=(x, y, r), segments=32,
                                         ring_count=16)
    bpy.ops.object.shade_smooth()
    add(bpy.context.object, fruit, 6)

AreaLight((-1.5, -0.8, 2.0), 1.0, 120.0).rotation_euler = (0.5, -0.6, 0)

camera = Camera(scene, (0.15, -1.6, 0.75), (0.0, 0.5, 0.2), lens=50)
camera.data.dof.use_dof = True
camera.data.dof.focus_distance = 1.95
camera.data.dof.aperture_fstop = 1.4

Render(scene, args)
