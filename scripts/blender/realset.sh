#!/bin/bash
# Render the real-scene benchmark set (`mcdenoise bench real` reads it): per scene
#   plain.exr        one 16-spp frame with what a user has: Blender's default passes
#                    (Combined with alpha, Depth) plus the Denoising Data passes;
#   frames/NN.exr    16 independent 1-spp frames with every pass mcdenoise reads, the camera
#                    jittered by the pixel filter (common.py, JitterCamera);
#   acc.exr          those frames through `mcdenoise accumulate` (mean and statistics);
#   ref/chunkNN.exr  the reference in chunks of 1024 spp, each its own seed;
#   plain-SEED.exr   with --plain-seeds: more plain frames like plain.exr, one per seed, held
#                    out of the tuning (bench real reads plain.exr alone);
#   acc-SEED.exr     with --acc-seeds: more accumulated frames like acc.exr, of the 1-spp
#                    frames frames-SEED/NN.exr of seeds SEED..SEED+N-1, held out alike;
#   ref.exr          the chunks through `mcdenoise accumulate`: color is their mean, and
#                    half0.color / half1.color the means of the odd and even chunks (two
#                    halves of different seeds, whose difference estimates the reference's
#                    own noise; the bench reports it).
# Everything is cached: a file that exists is not rendered again, so a stopped run resumes
# and a larger --ref-spp only adds chunks. The frames first, then the reference chunks round
# by round over the scenes, so a stopped run has chunks of every scene.
#
# Usage: realset.sh [--out DIR] [--scenes a,b,...] [--ref-spp N] [--size N] [--frames N]
#                   [--tool PATH] [--plain-seeds S,S,...] [--acc-seeds S,S,...]
#   --out      cache directory (default ~/.cache/mcdenoise/realset); one folder per scene
#   --scenes   scenes to render (default all: scripts/blender/<scene>.py)
#   --ref-spp  reference samples per pixel for every scene, a multiple of 2048 (default
#              per scene: 4096; sunlit_room 12288, glossy_lights 16384, which converge
#              slowly)
#   --size     image side in pixels (default 256)
#   --frames   1-spp frames to accumulate and spp of the plain frame (default 16)
#   --tool     the mcdenoise binary (default: build/mcdenoise, else mcdenoise on the PATH)
#   --plain-seeds  comma-separated seeds of extra plain frames (e.g. 2001,3001,4001,5001)
#   --acc-seeds    comma-separated first seeds of extra accumulated frames (e.g. 101,201;
#              the set's acc.exr is seeds 1..N)
# Renders run one at a time under `nice -n 10`; DIR/realset.log has each render's time.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${HOME}/.cache/mcdenoise/realset
scenes=still_life,sunlit_room,glossy_lights,fence_grass,motion_blur,product_transparent
refSpp=
size=256
frames=16
tool=
plainSeeds=
accSeeds=
while [ $# -gt 0 ]; do
    case $1 in
        --out) out=$2; shift 2 ;;
        --scenes) scenes=$2; shift 2 ;;
        --ref-spp) refSpp=$2; shift 2 ;;
        --size) size=$2; shift 2 ;;
        --frames) frames=$2; shift 2 ;;
        --tool) tool=$2; shift 2 ;;
        --plain-seeds) plainSeeds=$2; shift 2 ;;
        --acc-seeds) accSeeds=$2; shift 2 ;;
        -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        *) echo "realset.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$tool" ]; then
    if [ -x "$root/build/mcdenoise" ]; then tool=$root/build/mcdenoise; else tool=mcdenoise; fi
fi
command -v blender > /dev/null || { echo "realset.sh: blender is not installed" >&2; exit 1; }
command -v "$tool" > /dev/null || { echo "realset.sh: no mcdenoise binary '$tool'" >&2; exit 1; }
if [ -n "$refSpp" ] && { [ "$refSpp" -lt 2048 ] || [ $((refSpp % 2048)) -ne 0 ]; }; then
    echo "realset.sh: --ref-spp $refSpp is not a positive multiple of 2048" >&2
    exit 2
fi
chunkSpp=1024
IFS=, read -r -a seeds <<< "$plainSeeds"
for seed in "${seeds[@]}"; do
    [[ $seed =~ ^[0-9]+$ ]] || { echo "realset.sh: --plain-seeds: '$seed' is no seed" >&2; exit 2; }
done
IFS=, read -r -a accFirst <<< "$accSeeds"
for seed in "${accFirst[@]}"; do
    [[ $seed =~ ^[0-9]+$ ]] || { echo "realset.sh: --acc-seeds: '$seed' is no seed" >&2; exit 2; }
done
IFS=, read -r -a list <<< "$scenes"
for scene in "${list[@]}"; do
    [ -f "$here/$scene.py" ] || { echo "realset.sh: no scene script $here/$scene.py" >&2; exit 2; }
done
mkdir -p "$out"
log=$out/realset.log

# The reference spp of a scene: --ref-spp, else 4096, more where the reference's own noise
# (what bench real reports) is far above 1e-4 at 4096 spp.
SceneRefSpp() {
    if [ -n "$refSpp" ]; then echo "$refSpp"; return; fi
    case $1 in
        sunlit_room) echo 12288 ;;
        glossy_lights) echo 16384 ;;
        *) echo 4096 ;;
    esac
}

# Refuse a cache made by other scene scripts or settings: its frames would not match.
CheckStamp() {
    local scene=$1 dir=$out/$1 stamp
    stamp="$(cat "$here/$scene.py" "$here/common.py" | md5sum | cut -c1-32) size=$size frames=$frames"
    if [ -f "$dir/stamp" ] && [ "$(cat "$dir/stamp")" != "$stamp" ]; then
        echo "realset.sh: $dir was rendered from another version of $scene.py/common.py or" \
            "other --size/--frames; move it away to render it again" >&2
        exit 1
    fi
    mkdir -p "$dir/frames" "$dir/ref"
    echo "$stamp" > "$dir/stamp"
}

# Run Blender on a scene: log label, then the script's arguments; its output goes to
# LOGFILE ($blenderLog) and the time to realset.log.
blenderLog=
Blender() {
    local label=$1 start=$SECONDS
    shift
    if ! nice -n 10 blender -b --factory-startup -P "$here/$scene.py" -- --size "$size" "$@" \
        > "$blenderLog" 2>&1; then
        echo "realset.sh: blender failed on $label (see $blenderLog)" | tee -a "$log" >&2
        exit 1
    fi
    echo "$(date -Is) $scene $label: $((SECONDS - start)) s" | tee -a "$log"
}

# Render one file unless it exists: output, spp, seed, then extra script arguments. Blender
# writes to a temporary name that is renamed when it succeeds.
Render() {
    local file=$1 spp=$2 seed=$3
    shift 3
    [ -f "$file" ] && return 0
    blenderLog=$file.blender.log
    Blender "$(basename "$(dirname "$file")")/$(basename "$file") $spp spp seed $seed" \
        --spp "$spp" --seed "$seed" --out "$file.partial.exr" "$@"
    [ -f "$file.partial.exr" ] || { echo "realset.sh: blender wrote no $file" >&2; exit 1; }
    mv "$file.partial.exr" "$file"
    rm -f "$blenderLog"
}

# The jittered 1-spp frames NN.exr (NN from 01), seeds first..first+N-1, in one Blender
# process unless all exist. Usage: RenderFrames DIR [FIRST (default 1)].
RenderFrames() {
    local dir=$1 first=${2:-1} s missing=0
    local last=$((first + frames - 1))
    for s in $(seq 1 "$frames"); do [ -f "$(printf '%s/%02d.exr' "$dir" "$s")" ] || missing=1; done
    [ $missing = 1 ] || return 0
    rm -rf "$dir/partial"
    mkdir -p "$dir/partial"
    blenderLog=$dir/partial/blender.log
    Blender "frames: $frames x 1 spp, seeds $first-$last" --spp 1 --seed "$first" \
        --count "$frames" --jitter --passes all --out "$dir/partial/{seed}.exr"
    for s in $(seq "$first" "$last"); do
        [ -f "$dir/partial/$s.exr" ] || { echo "realset.sh: blender wrote no frame $s" >&2; exit 1; }
    done
    for s in $(seq "$first" "$last"); do
        mv "$dir/partial/$s.exr" "$(printf '%s/%02d.exr' "$dir" $((s - first + 1)))"
    done
    rm -rf "$dir/partial"
}

# Accumulate inputs into output when it is missing, older than an input or made from
# other inputs or flags (OUTPUT.inputs lists them, after the layout's tag: a file made
# before accumulate wrote half0's own layers is made again). Usage: Accumulate OUTPUT
# FLAGS INPUTS..., FLAGS one word of accumulate's options ("-" for none).
Accumulate() {
    local output=$1 flags=$2
    shift 2
    local stale=0 f record="half0-layers $flags $*" extra=()
    [ "$flags" = - ] || extra=("$flags")
    [ -f "$output" ] && [ "$(cat "$output.inputs" 2> /dev/null)" = "$record" ] || stale=1
    for f in "$@"; do [ "$f" -nt "$output" ] && stale=1; done
    [ $stale = 1 ] || return 0
    "$tool" accumulate "${extra[@]}" "$@" -o "$output.partial.exr" > "$output.log" 2>&1 ||
        { echo "realset.sh: accumulate failed for $output (see $output.log)" >&2; exit 1; }
    mv "$output.partial.exr" "$output"
    echo "$record" > "$output.inputs"
}

echo "$(date -Is) realset.sh: scenes $scenes, ${size}x$size, out $out" >> "$log"
for scene in "${list[@]}"; do
    CheckStamp "$scene"
    dir=$out/$scene
    Render "$dir/plain.exr" "$frames" 1001 --passes default
    for seed in "${seeds[@]}"; do
        Render "$dir/plain-$seed.exr" "$frames" "$seed" --passes default
    done
    RenderFrames "$dir/frames"
    inputs=()
    for s in $(seq 1 "$frames"); do inputs+=("$(printf '%s/frames/%02d.exr' "$dir" "$s")"); done
    Accumulate "$dir/acc.exr" - "${inputs[@]}"
    for seed in "${accFirst[@]}"; do
        RenderFrames "$dir/frames-$seed" "$seed"
        inputs=()
        for s in $(seq 1 "$frames"); do
            inputs+=("$(printf '%s/frames-%s/%02d.exr' "$dir" "$seed" "$s")")
        done
        Accumulate "$dir/acc-$seed.exr" - "${inputs[@]}"
    done
done

# Reference chunks round by round: chunk k of every scene before chunk k + 1 of any.
most=0
for scene in "${list[@]}"; do
    n=$(($(SceneRefSpp "$scene") / chunkSpp))
    [ $n -gt $most ] && most=$n
done
for k in $(seq 1 $most); do
    for scene in "${list[@]}"; do
        [ "$k" -le $(($(SceneRefSpp "$scene") / chunkSpp)) ] || continue
        Render "$(printf '%s/%s/ref/chunk%02d.exr' "$out" "$scene" "$k")" $chunkSpp \
            $((100000 + k)) --passes default
    done
done
for scene in "${list[@]}"; do
    n=$(($(SceneRefSpp "$scene") / chunkSpp))
    chunks=()
    for k in $(seq 1 "$n"); do chunks+=("$(printf '%s/%s/ref/chunk%02d.exr' "$out" "$scene" "$k")"); done
    # The reference's halves estimate its noise; half0's own layers serve no one there.
    Accumulate "$out/$scene/ref.exr" --no-half0-layers "${chunks[@]}"
done
echo "$(date -Is) realset.sh: done" | tee -a "$log"
echo "measure it: $tool bench real $out"
