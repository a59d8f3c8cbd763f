#!/bin/bash
# The quality table of the bayes note: run in a directory holding S_N.exr frames
# (mcdenoise render --scene S --size 128x128 --spp N --layers split) and S_ref.exr
# references; needs scripts/bayes_skimage.py beside this file.
T=${MCD_TOOL:-mcdenoise}
# Each cell: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
m() { sed -n 's/.*relMSE \([0-9.e+-]*\), PSNR \([0-9.inf]*\) dB, SSIM \([0-9.]*\), mean brightness \([0-9.a-z]*\) .*/\1 \/ \2 \/ \3 (\4)/p'; }
for s in cornell interior; do for n in 4 16 64; do
  f=${s}_$n.exr; r=${s}_ref.exr
  row="| $s | $n | $($T compare $f $r | m)"
  for opts in "" "--no-split" "--noise auto" "--noise auto --no-split" "--noise auto --hp-factor 1"; do
    $T denoise $f -o o.exr --method bayes $opts > /dev/null 2>&1
    row="$row | $($T compare o.exr $r | m)"
  done
  for v in "split rgb" "whole rgb" "whole ycbcr"; do
    /usr/bin/python3 "$(dirname "$0")/bayes_skimage.py" $f sk.exr $v > /dev/null
    row="$row | $($T compare sk.exr $r | m)"
  done
  echo "$row |"
done; done
