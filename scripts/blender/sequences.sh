#!/bin/bash
# Render the Blender Cycles sequences of the flicker benchmark (`mcdenoise bench flicker`,
# docs/sequences.md) with cornell_sequence.py:
#   cornell_static/frame.NNNN.exr  8 frames of the static Cornell box, 256x256, 16 spp,
#                                  seeds 1-8;
#   cornell_static/ref.exr         one reference for all of them (4096 spp);
#   cornell_camera/frame.NNNN.exr  8 frames of the camera move, 128x128, 16 spp, seeds 1-8,
#                                  with the Vector pass;
#   cornell_camera/ref.NNNN.exr    a reference per frame (2048 spp).
# Everything is cached: a file that exists is not rendered again, so a stopped run resumes.
# Renders run one at a time under `nice -n 10`; DIR/sequences.log has each render's time.
# Usage: sequences.sh [--out DIR] [--size N] [--frames N] [--ref-spp-static N]
#                     [--ref-spp-camera N]
#   --out     cache directory (default ~/.cache/mcdenoise/sequences)
#   --size    both sequences' width and height in pixels (default: 256 static, 128 camera)
#   --frames  frames 1 to N of each (default 8)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${HOME}/.cache/mcdenoise/sequences
refStatic=4096
refCamera=2048
sizeStatic=256
sizeCamera=128
frames=8
while [ $# -gt 0 ]; do
    case $1 in
        --out) out=$2; shift 2 ;;
        --ref-spp-static) refStatic=$2; shift 2 ;;
        --ref-spp-camera) refCamera=$2; shift 2 ;;
        --size) sizeStatic=$2; sizeCamera=$2; shift 2 ;;
        --frames) frames=$2; shift 2 ;;
        *) echo "sequences.sh: unknown argument $1" >&2; exit 2 ;;
    esac
done
mkdir -p "$out/cornell_static" "$out/cornell_camera"
log=$out/sequences.log

render() {  # what; then cornell_sequence.py's arguments
    local what=$1
    shift
    local start=$SECONDS
    nice -n 10 blender -b --factory-startup -P "$here/cornell_sequence.py" -- "$@" \
        > "$out/blender.log" 2>&1 || { echo "blender failed on $what (see $out/blender.log)" >&2; exit 1; }
    echo "$(date +%F\ %T) $what: $((SECONDS - start)) s" >> "$log"
}

# The noisy frames first, so the benchmark can start before the references are done.
render "cornell_static frames" --move none --frames 1-$frames --spp 16 --seed 1 --size $sizeStatic \
    --out "$out/cornell_static/frame.{frame:04d}.exr"
render "cornell_camera frames" --move camera --frames 1-$frames --spp 16 --seed 1 --size $sizeCamera \
    --out "$out/cornell_camera/frame.{frame:04d}.exr"
for f in $(seq 1 "$frames"); do
    render "cornell_camera reference $f" --move camera --frames $f --spp "$refCamera" \
        --seed $((100000 + f - 1)) --size $sizeCamera --out "$out/cornell_camera/ref.{frame:04d}.exr"
done
# The static view's reference: frame 1's pose (every frame's), one render.
[ -f "$out/cornell_static/ref.exr" ] ||
    render "cornell_static reference" --move none --frames 1 --spp "$refStatic" --seed 99999 \
        --size $sizeStatic --out "$out/cornell_static/ref.{frame:04d}.exr"
[ -f "$out/cornell_static/ref.0001.exr" ] && mv "$out/cornell_static/ref.0001.exr" "$out/cornell_static/ref.exr"
echo "done: $out"
