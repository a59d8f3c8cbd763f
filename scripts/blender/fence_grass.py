# A procedural outdoor scene for Blender Cycles made of thin geometry: a chain-link fence of
# wires under a pixel wide, grass blades a few pixels tall, and two power lines across a sky;
# lit by a low sun and the sky. Writes a multilayer EXR (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/fence_grass.py -- \
#       --spp 16 --seed 1 --out frame.exr
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import Begin, Camera, Principled, Render, World, add  # noqa: E402

args, scene = Begin("render the fence and grass scene with Cycles", size=256)
World(scene, (0.15, 0.3, 0.8, 1.0), 0.8, horizon=(0.6, 0.65, 0.7, 1.0))


def Wires(name, polylines, radius, mat, index):
    """One curve object with a round wire of this radius along each polyline."""
    curve = bpy.data.curves.new(name, "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = radius
    curve.bevel_resolution = 2
    for points in polylines:
        spline = curve.splines.new("POLY")
        spline.points.add(len(points) - 1)
        for point, (x, y, z) in zip(spline.points, points):
            point.co = (x, y, z, 1.0)
    obj = bpy.data.objects.new(name, curve)
    bpy.context.collection.objects.link(obj)
    return add(obj, mat, index)


ground = Principled("ground", 1, (0.3, 0.25, 0.15, 1.0), Roughness=1.0, Specular=0.2)
# Soil and dry grass mottled by fine noise.
noise = ground.node_tree.nodes.new("ShaderNodeTexNoise")
noise.inputs["Scale"].default_value = 40.0
noise.inputs["Detail"].default_value = 6.0
ramp = ground.node_tree.nodes.new("ShaderNodeValToRGB")
ramp.color_ramp.elements[0].position = 0.35
ramp.color_ramp.elements[0].color = (0.12, 0.09, 0.05, 1.0)
ramp.color_ramp.elements[1].position = 0.65
ramp.color_ramp.elements[1].color = (0.35, 0.33, 0.15, 1.0)
ground.node_tree.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
ground.node_tree.links.new(ramp.outputs["Color"],
                           ground.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
bpy.ops.mesh.primitive_plane_add(size=400, location=(0, 0, 0))
add(bpy.context.object, ground, 1)

# A chain-link fence 2 m high along y = 3: diagonal wires 8 cm apart, 3 mm thick.
steel = Principled("steel", 2, (0.6, 0.62, 0.65, 1.0), Metallic=1.0, Roughness=0.4)
x0, x1, height, step = -6.0, 6.0, 2.0, 0.08
diagonals = []
for k in range(int((x1 - x0 + height) / step) + 1):
    start = x0 - height + k * step
    diagonals.append([(start + t * height / 8, 3.0, t * height / 8) for t in range(9)])
    diagonals.append([(start + height - t * height / 8, 3.0, t * height / 8) for t in range(9)])
clipped = [[p for p in line if x0 <= p[0] <= x1] for line in diagonals]
Wires("fence", [line for line in clipped if len(line) >= 2], 0.0015, steel, 2)
posts = [[(x, 3.0, 0.0), (x, 3.0, height + 0.05)] for x in range(-6, 7, 2)]
Wires("posts", posts, 0.03, steel, 3)
Wires("rail", [[(x0, 3.0, height), (x1, 3.0, height)]], 0.015, steel, 3)

# Two sagging power lines high across the view.
cable = Principled("cable", 4, (0.02, 0.02, 0.02, 1.0), Roughness=0.5)
lines = [[(x, 12.0 + 0.5 * j, 7.0 + j - 1.5 * math.cosh(x / 12.0) + 1.5) for x in range(-30, 31)]
         for j in range(2)]
Wires("power lines", lines, 0.01, cable, 4)

# Grass: thin tapered blades scattered in front of the fence, from a fixed seed so every
# render has the same blades.
rng = random.Random(7)
grass = Principled("grass", 5, (0.12, 0.35, 0.05, 1.0), Roughness=0.6, Subsurface=0.0)
verts, faces = [], []
for _ in range(12000):
    x, y = rng.uniform(-4.0, 4.0), rng.uniform(-0.5, 3.2)
    h, w, a = rng.uniform(0.1, 0.35), rng.uniform(0.004, 0.008), rng.uniform(0, math.pi)
    lean_x, lean_y = rng.gauss(0, 0.05), rng.gauss(0, 0.05)
    dx, dy = w * math.cos(a), w * math.sin(a)
    n = len(verts)
    verts += [(x - dx, y - dy, 0), (x + dx, y + dy, 0), (x + lean_x, y + lean_y, h)]
    faces.append((n, n + 1, n + 2))
mesh = bpy.data.meshes.new("grass")
mesh.from_pydata(verts, [], faces)
blades = bpy.data.objects.new("grass", mesh)
bpy.context.collection.objects.link(blades)
add(blades, grass, 5)

bpy.ops.object.light_add(type="SUN")
sun = bpy.context.object
sun.data.energy = 4.0
sun.data.angle = math.radians(1.0)
sun.rotation_euler = (math.radians(55), 0, math.radians(120))

Camera(scene, (0.3, -2.2, 0.9), (0.0, 3.0, 1.2), lens=32)

Render(scene, args)
