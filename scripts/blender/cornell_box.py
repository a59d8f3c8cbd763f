# A procedural scene for Blender Cycles: the classic diffuse Cornell box, a tall and a short
# block under a square ceiling light, all indirect light diffuse. Writes a multilayer EXR
# with the passes mcdenoise reads (common.py). Headless:
#   blender -b --factory-startup -P scripts/blender/cornell_box.py -- \
#       --spp 16 --seed 1 --size 128 --out frame.exr
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import Begin, CornellBox, Render  # noqa: E402

args, scene = Begin("render the Cornell box with Cycles")

CornellBox(scene)

Render(scene, args)
