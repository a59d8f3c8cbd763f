#!/bin/bash
# The quality table of issue #5 (AWR's headline: full AWR at 32 spp on average against
# uniform Monte Carlo at 256): relMSE against the 4096-spp reference on dof-arealight for
# uniform MC, MC + AWR reconstruction, adaptive sampling only, and full AWR (adaptive +
# reconstruction) at 8/16/32/64 spp, and full AWR with 2 x 2 cycle spinning (--awr-spins 2,
# beyond the paper), then uniform MC at 128 and 256 spp. Usage:
#   awr_quality.sh [WxH [SPP_REF]] [extra render options for the adaptive runs, e.g.
#   --contrast-floor 0]
# SPP_REF is the reference's spp (4096 by default; at 1024x1024, 2048 takes 14 min here).
# Renders into the current directory (the reference is cached by `render --reference`).
T=${MCD_TOOL:-mcdenoise}
size=${1:-256x256}
refSpp=${2:-4096}
shift $(($# < 2 ? $# : 2))
scene=dof-arealight
# Each cell: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
m() { sed -n 's/.*relMSE \([0-9.e+-]*\), PSNR \([0-9.inf]*\) dB, SSIM \([0-9.]*\), mean brightness \([0-9.a-z]*\) .*/\1 \/ \2 \/ \3 (\4)/p'; }
r=ref_${size}_$refSpp.exr
[ -f $r ] || $T render --scene $scene --size $size --reference --spp $refSpp -o $r \
  > /dev/null || exit 1
echo "$scene $size, against a $refSpp-spp reference; adaptive options: ${*:-defaults}"
echo "| avg spp | uniform MC | MC + AWR reconstruction | adaptive only | full AWR | full AWR, --awr-spins 2 |"
echo "|---|---|---|---|---|---|"
for n in 8 16 32 64; do
  $T render --scene $scene --size $size --spp $n -o mc.exr > /dev/null || exit 1
  $T denoise mc.exr --method awr -o mc_awr.exr > /dev/null || exit 1
  $T render --scene $scene --size $size --spp $n --adaptive awr "$@" --denoised full.exr \
    -o adaptive.exr > /dev/null || exit 1
  $T denoise adaptive.exr --method awr --awr-spins 2 -o spun.exr > /dev/null || exit 1
  echo "| $n | $($T compare mc.exr $r | m) | $($T compare mc_awr.exr $r | m) |" \
    "$($T compare adaptive.exr $r | m) | $($T compare full.exr $r | m) |" \
    "$($T compare spun.exr $r | m) |"
done
for n in 128 256; do
  $T render --scene $scene --size $size --spp $n -o mc.exr > /dev/null || exit 1
  echo "uniform MC at $n spp: $($T compare mc.exr $r | m)"
done
