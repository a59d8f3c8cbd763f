#!/bin/bash
# The --noise table of the bayes note: fixed (s_n 0.19, finest 2 s_n) vs mad (the finest
# HH bands' median |y|) vs variance (per band from the variance layer), with the split
# (default) and without. Run in a directory holding S_N.exr frames (mcdenoise render
# --scene S --size 128x128 --spp N --layers split, which includes `variance`) and S_ref.exr.
T=${MCD_TOOL:-mcdenoise}
# Each cell: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
m() { sed -n 's/.*relMSE \([0-9.e+-]*\), PSNR \([0-9.inf]*\) dB, SSIM \([0-9.]*\), mean brightness \([0-9.a-z]*\) .*/\1 \/ \2 \/ \3 (\4)/p'; }
for s in cornell interior; do for n in 4 16 64; do
  f=${s}_$n.exr; r=${s}_ref.exr
  row="| $s | $n | $($T compare $f $r | m)"
  for split in "" "--no-split"; do for noise in fixed mad variance; do
    $T denoise $f -o o.exr --method bayes --noise $noise $split > /dev/null 2>&1
    row="$row | $($T compare o.exr $r | m)"
  done; done
  echo "$row |"
done; done
