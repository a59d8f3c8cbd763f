#!/bin/bash
# Throughput of a sequence (issue #19): N frames denoised by one `mcdenoise denoise` call
# against N separate calls, each way timed REPEATS times in turn; prints wall and CPU
# (user + sys) seconds per way, the medians and their ratio. Frames are rendered once into
# DIR (kept between runs). Extra arguments go to every denoise call (e.g. --method bayes).
#   scripts/bench_sequence.sh [DIR] [-- denoise options]
# Environment: MCD_TOOL (default mcdenoise), FRAMES (8), SIZE (512x512), SPP (8),
# LAYERS (render --layers, default none), REPEATS (3).
set -euo pipefail
T=${MCD_TOOL:-mcdenoise}
N=${FRAMES:-8}
SIZE=${SIZE:-512x512}
SPP=${SPP:-8}
REPEATS=${REPEATS:-3}
DIR=/tmp/mcd_bench_sequence
if [[ $# -gt 0 && $1 != -- ]]; then DIR=$1; shift; fi
[[ ${1:-} == -- ]] && shift
mkdir -p "$DIR"
cd "$DIR"
for ((i = 1; i <= N; ++i)); do
  f=$(printf 'in.%04d.exr' "$i")
  [[ -f $f ]] || "$T" render --size "$SIZE" --spp "$SPP" --seed "$i" \
    ${LAYERS:+--layers "$LAYERS"} -o "$f" > /dev/null
done

# Seconds of wall, user and sys of a command, as "wall cpu".
timed() {
  local t
  t=$( { TIMEFORMAT='%R %U %S'; time "$@" > /dev/null 2>&1; } 2>&1 )
  awk '{ printf "%.2f %.2f\n", $1, $2 + $3 }' <<< "$t"
}
separate() {
  for ((i = 1; i <= N; ++i)); do
    "$T" denoise "$(printf 'in.%04d.exr' "$i")" -o "$(printf 'sep.%04d.exr' "$i")" "$@" || return 1
  done
}
one() { "$T" denoise "in.####.exr" --frames "1-$N" -o "seq.####.exr" "$@"; }
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# One untimed call first: the driver's own shader cache is then warm for both ways.
"$T" denoise in.0001.exr -o warm.exr "$@" > /dev/null 2>&1
echo "$N frames of $SIZE at $SPP spp, denoise $*, device: $("$T" info 2>/dev/null | sed -n 's/^\* [0-9]*: //p')"
sepWall=() sepCpu=() oneWall=() oneCpu=()
for ((r = 1; r <= REPEATS; ++r)); do
  read -r w c < <(timed separate "$@"); sepWall+=("$w"); sepCpu+=("$c")
  read -r w c < <(timed one "$@"); oneWall+=("$w"); oneCpu+=("$c")
  echo "run $r: $N separate calls ${sepWall[-1]} s wall (${sepCpu[-1]} s CPU), one call ${oneWall[-1]} s wall (${oneCpu[-1]} s CPU)"
done
sw=$(printf '%s\n' "${sepWall[@]}" | median) ow=$(printf '%s\n' "${oneWall[@]}" | median)
sc=$(printf '%s\n' "${sepCpu[@]}" | median) oc=$(printf '%s\n' "${oneCpu[@]}" | median)
awk -v sw="$sw" -v ow="$ow" -v sc="$sc" -v oc="$oc" -v n="$N" 'BEGIN {
  printf "median: separate %.2f s (%.2f frames/s), one call %.2f s (%.2f frames/s): %.2fx throughput; CPU %.2f s vs %.2f s: %.2fx\n",
    sw, n / sw, ow, n / ow, sw / ow, sc, oc, sc / oc }'
