# A procedural scene for Blender Cycles rendered with Film > Transparent: a diffuse sphere
# and a glossy cube on a small floor tile, lit by a sun and a coloured world, against a
# background that is left transparent (Combined.A = 0 there; the Env pass still holds the
# world the camera sees). Writes a multilayer EXR with the passes mcdenoise reads
# (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/transparent_film.py -- \
#       --spp 16 --seed 1 --size 24 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import Begin, Render, add, material  # noqa: E402

args, scene = Begin("render objects on transparent film with Cycles")

red = material("red", (0.7, 0.1, 0.08, 1.0), index=1)
glossy = material("glossy", (0.9, 0.85, 0.6, 1.0), roughness=0.2, metallic=1.0, index=2)
tile = material("tile", (0.6, 0.6, 0.6, 1.0), checker=True, index=3)

bpy.ops.mesh.primitive_plane_add(size=1.6, location=(0, 0.2, -0.5))
add(bpy.context.object, tile, 1)
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.35, location=(-0.35, 0.2, -0.15), segments=32,
                                     ring_count=16)
bpy.ops.object.shade_smooth()
add(bpy.context.object, red, 2)
bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.4, 0.35, -0.25), rotation=(0, 0, 0.5))
add(bpy.context.object, glossy, 3)

bpy.ops.object.camera_add(location=(0, -3.0, 0.6), rotation=(1.35, 0, 0))
scene.camera = bpy.context.object
scene.camera.data.lens = 40
bpy.ops.object.light_add(type="SUN", location=(2, -2, 3), rotation=(0.6, 0.3, 0.4))
bpy.context.object.data.energy = 3.0

# A world that lights the objects (diffuse and glossy indirect from it) and that the camera
# sees around them: the Env pass is not zero where the film is transparent.
world = bpy.data.worlds.new("sky")
world.use_nodes = True
background = world.node_tree.nodes["Background"]
background.inputs["Color"].default_value = (0.35, 0.5, 0.8, 1.0)
background.inputs["Strength"].default_value = 1.0
scene.world = world

scene.render.film_transparent = True
Render(scene, args)
