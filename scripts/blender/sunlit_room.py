# A procedural interior for Blender Cycles lit mostly indirectly: the sun falls through one
# window onto the floor, and the rest of the room sees only the light that patch sends back
# and the sky through the window (sampled through a portal). A dark table on a dark rug and a
# dark cabinet (dark objects of low contrast) stand out of the sun. Writes a multilayer EXR
# (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/sunlit_room.py -- \
#       --spp 16 --seed 1 --out frame.exr
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import Begin, Camera, Principled, Render, World, add  # noqa: E402

args, scene = Begin("render the sunlit room with Cycles", size=256)
World(scene, (0.35, 0.5, 0.9, 1.0), 3.0, horizon=(0.8, 0.85, 0.9, 1.0))

walls = Principled("walls", 1, (0.75, 0.72, 0.66, 1.0))
floor = Principled("floor", 2, (0.35, 0.24, 0.14, 1.0), Roughness=0.6)
rug = Principled("rug", 3, (0.05, 0.045, 0.04, 1.0))
wood = Principled("dark wood", 4, (0.045, 0.03, 0.022, 1.0), Roughness=0.5)
cabinet = Principled("cabinet", 5, (0.06, 0.06, 0.065, 1.0), Roughness=0.8)


def Block(name, mat, index, lo, hi):
    """An axis-aligned box from corner `lo` to corner `hi`."""
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    bpy.ops.mesh.primitive_cube_add(size=1, location=centre)
    obj = bpy.context.object
    obj.name = name
    obj.scale = [b - a for a, b in zip(lo, hi)]
    return add(obj, mat, index)


# A closed room 3.6 x 3.4 x 2.6 m with walls 0.1 m thick; the window (2.2 x 1.6 m) is in
# the wall at x = 1.8.
t, X, Y, Z = 0.1, 1.8, 1.7, 2.6
Block("floor", floor, 1, (-X - t, -Y - t, -t), (X + t, Y + t, 0))
Block("ceiling", walls, 2, (-X - t, -Y - t, Z), (X + t, Y + t, Z + t))
Block("back wall", walls, 3, (-X - t, Y, 0), (X + t, Y + t, Z))
Block("front wall", walls, 4, (-X - t, -Y - t, 0), (X + t, -Y, Z))
Block("left wall", walls, 5, (-X - t, -Y, 0), (-X, Y, Z))
wy0, wy1, wz0, wz1 = -1.1, 1.1, 0.7, 2.3
Block("window sill", walls, 6, (X, -Y, 0), (X + t, Y, wz0))
Block("window lintel", walls, 6, (X, -Y, wz1), (X + t, Y, Z))
Block("window left", walls, 6, (X, -Y, wz0), (X + t, wy0, wz1))
Block("window right", walls, 6, (X, wy1, wz0), (X + t, Y, wz1))

# A dark rug, and on it the dark table, in the back half of the room out of the sun; a dark
# cabinet by the back wall.
Block("rug", rug, 7, (-1.5, 0.2, 0), (0.3, 1.5, 0.01))
Block("table top", wood, 8, (-1.2, 0.5, 0.72), (0.0, 1.2, 0.76))
for x, y in ((-1.1, 0.6), (-0.1, 0.6), (-1.1, 1.1), (-0.1, 1.1)):
    Block("table leg", wood, 8, (x - 0.03, y - 0.03, 0.01), (x + 0.03, y + 0.03, 0.72))
Block("cabinet", cabinet, 9, (-1.8, -0.4, 0), (-1.35, 0.4, 1.1))
# A pale vase on the table: one bright object to anchor the tone.
vase = Principled("vase", 10, (0.7, 0.7, 0.68, 1.0), Roughness=0.3)
bpy.ops.mesh.primitive_cylinder_add(radius=0.07, depth=0.25, location=(-0.5, 0.85, 0.885))
add(bpy.context.object, vase, 10)

# A low sun through the window onto the front half of the floor and the foot of the left
# wall; the table and the cabinet stay out of it.
bpy.ops.object.light_add(type="SUN")
sun = bpy.context.object
sun.data.energy = 8.0
sun.data.angle = math.radians(0.6)
sun.rotation_euler = (0, math.radians(66), math.radians(15))
# A portal in the window: Cycles samples the sky through it (what interior renders use).
bpy.ops.object.light_add(type="AREA", location=(X + t / 2, (wy0 + wy1) / 2, (wz0 + wz1) / 2),
                         rotation=(0, math.radians(-90), 0))
portal = bpy.context.object
portal.data.shape = "RECTANGLE"
portal.data.size, portal.data.size_y = wz1 - wz0, wy1 - wy0
portal.data.cycles.is_portal = True

Camera(scene, (1.3, -1.4, 1.6), (-1.0, 0.5, 0.7), lens=18)

Render(scene, args)
