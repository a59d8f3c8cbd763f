#!/bin/bash
# Measure every method and auto on a Blender Cycles scene (README, "Frames from other
# renderers"): N independent 1-spp renders accumulated into one frame with statistics, and
# one plain N-spp render with the ordinary passes only, each against a high-spp reference.
# Usage: measure.sh SCENE [SIZE [N [REF_SPP]]]   (defaults 128, 16, 2048)
#   SCENE: glossy_box, cornell_box or textured_plane (scripts/blender/SCENE.py).
# Renders into the current directory; the reference and the renders are kept and reused.
# MCD_TOOL picks the mcdenoise binary (default: mcdenoise on the PATH).
set -euo pipefail
scene=$1
size=${2:-128}
n=${3:-16}
refSpp=${4:-2048}
T=${MCD_TOOL:-mcdenoise}
here=$(cd "$(dirname "$0")" && pwd)
render() {  # spp seed out [--jitter]
    [ -f "$3" ] || blender -b --factory-startup -P "$here/$scene.py" -- --spp "$1" --seed "$2" \
        --size "$size" --out "$PWD/$3" ${4:-} > /dev/null 2>&1 || { echo "blender failed on $3" >&2; exit 1; }
}
render "$refSpp" 99999 "${scene}_ref.exr"
# --jitter: Cycles puts sample 0 at the pixel centre whatever the seed (common.py).
for s in $(seq 1 "$n"); do render 1 "$s" "${scene}_1spp_$s.exr" --jitter; done
render "$n" 1001 "${scene}_${n}spp.exr"
$T accumulate $(for s in $(seq 1 "$n"); do echo "${scene}_1spp_$s.exr"; done) \
    -o "${scene}_acc.exr" > /dev/null
# Input and output: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
err() {
    sed -n 's/.*relMSE \([0-9.e+-]*\) -> \([0-9.e+-]*\), PSNR \([0-9.inf]*\) -> \([0-9.inf]*\) dB, SSIM \([0-9.]*\) -> \([0-9.]*\), mean brightness \([0-9.a-z]*\) -> \([0-9.a-z]*\) .*/\1_\/_\3_\/_\5_(\7) \2_\/_\4_\/_\6_(\8)/p'
}
echo "| $scene ${size}x$size | frame | method | input | output |"
echo "|---|---|---|---|---|"
for frame in acc "${n}spp"; do
    for method in auto awr bayes pivot rhf; do
        out=$($T denoise "${scene}_$frame.exr" --method $method -o "${scene}_${frame}_$method.exr" \
            --reference "${scene}_ref.exr" 2>&1 || true)
        figures=$(echo "$out" | err)
        if [ -n "$figures" ]; then
            figures=${figures// / | }
            figures=${figures//_/ }
        else
            figures="- | refused: $(echo "$out" | tail -1 | cut -c1-60)"
        fi
        echo "| | $frame | $method | $figures |"
    done
done
