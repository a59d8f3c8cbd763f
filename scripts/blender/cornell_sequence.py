# Frames of an animation of the Cornell box (cornell_box.py's scene) for Blender Cycles,
# for the temporal mode (docs/sequences.md): a static camera, or a camera that trucks
# sideways and pans a little, 0.1 units a frame (about 6 pixels at 256x256), so that the
# blocks uncover the walls behind them. Writes one multilayer EXR per frame with the passes
# mcdenoise reads, including Vector (the motion vectors towards the previous and the next
# frame). Headless:
#   blender -b --factory-startup -P scripts/blender/cornell_sequence.py -- \
#       --move camera --frames 1-8 --spp 16 --seed 1 --size 256 --out 'seq/frame.{frame:04d}.exr'
# Frame f is rendered with seed --seed + f - 1 (independent noise per frame, as a renderer's
# animated seed gives).
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402

from common import AllPasses, CornellBox  # noqa: E402


def Arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(description="render frames of the Cornell box animation")
    parser.add_argument("--move", choices=("none", "camera"), default="none")
    parser.add_argument("--frames", default="1-8", help="FIRST-LAST or one frame")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--out", required=True, help="a path with {frame} (str.format)")
    args = parser.parse_args(argv)
    first, _, last = args.frames.partition("-")
    args.first, args.last = int(first), int(last or first)
    if "{frame" not in args.out:
        parser.error("--out needs {frame}")
    return args


def Build(scene):
    CornellBox(scene)


def AnimateCamera(scene, first, last):
    """Truck the camera along x, 0.1 a frame, centred between frames 4 and 5 whatever frames
    are rendered, and pan it by half the angle that would keep the box's centre in view.
    Linear keys on every frame from first - 1 to last + 1: the Vector pass reads the poses
    one frame either side."""
    camera = scene.camera
    for frame in range(min(first, 1) - 1, max(last, 8) + 2):
        x = 0.1 * (frame - 4.5)
        camera.location = (x, -3.4, 0)
        camera.rotation_euler = (math.pi / 2, 0, -0.5 * math.atan2(x, 4.4))
        camera.keyframe_insert("location", frame=frame)
        camera.keyframe_insert("rotation_euler", frame=frame)
    for fcurve in camera.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"


def Settings(scene, args):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    # The Vector pass needs motion blur off.
    scene.render.use_motion_blur = False
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "AUTO"
    layer = scene.view_layers[0]
    AllPasses(layer)
    layer.use_pass_vector = True
    image = scene.render.image_settings
    image.file_format = "OPEN_EXR_MULTILAYER"
    image.color_depth = "32"
    image.exr_codec = "ZIP"
    scene.render.use_file_extension = False


args = Arguments()
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
Build(scene)
if args.move == "camera":
    AnimateCamera(scene, args.first, args.last)
Settings(scene, args)
for frame in range(args.first, args.last + 1):
    path = args.out.format(frame=frame)
    if os.path.exists(path):
        continue
    scene.frame_set(frame)
    scene.cycles.seed = args.seed + frame - 1
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
