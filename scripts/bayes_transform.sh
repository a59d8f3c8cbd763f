#!/bin/bash
# The --bayes-transform table of the bayes note: input, dwt and swt (each with the
# defaults otherwise: split, --noise auto) on cornell and interior at 4/16/64 spp, 128x128,
# and for context the DWT with 2 x 2 cycle spinning (--spins 2).
# Renders the frames (--layers all) and references (--reference) into the current
# directory unless they are there. Prints relMSE / PSNR per cell.
T=${MCD_TOOL:-mcdenoise}
# Each cell: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
m() { sed -n 's/.*relMSE \([0-9.e+-]*\), PSNR \([0-9.inf]*\) dB, SSIM \([0-9.]*\), mean brightness \([0-9.a-z]*\) .*/\1 \/ \2 \/ \3 (\4)/p'; }
echo "| scene | spp | input | dwt | dwt --spins 2 | swt |"
echo "|---|---|---|---|---|---|"
for s in cornell interior; do
  [ -f ${s}_ref.exr ] || $T render --scene $s --size 128x128 --reference -o ${s}_ref.exr > /dev/null
  for n in 4 16 64; do
    f=${s}_$n.exr; r=${s}_ref.exr
    [ -f $f ] || $T render --scene $s --size 128x128 --spp $n --layers all -o $f > /dev/null
    row="| $s | $n | $($T compare $f $r | m)"
    for t in "dwt" "dwt --spins 2" "swt"; do
      $T denoise $f -o o.exr --method bayes --bayes-transform $t > /dev/null 2>&1
      row="$row | $($T compare o.exr $r | m)"
    done
    echo "$row |"
  done
done
