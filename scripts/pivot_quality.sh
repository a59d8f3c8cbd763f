#!/bin/bash
# The quality table of the pivot note (issue #7), in the current directory: renders
# cornell, relief-abc, double-textured and glossy-cornell at 128x128 with every layer at
# 4, 16 and 64 spp, runs planefit (k 0.3, the default, and k 0), and bilateral, and prints
# relMSE / PSNR / SSIM (mean brightness over the reference's) for input and outputs; then the
# texture letters' crops and brightness of relief-abc (scripts/pivot_letters.py, which
# needs python3-openimageio).
T=${MCD_TOOL:-mcdenoise}
here=$(dirname "$0")
# Each cell: relMSE / PSNR dB / SSIM (mean brightness over the reference's).
m() { sed -n 's/.*relMSE \([0-9.e+-]*\), PSNR \([0-9.inf]*\) dB, SSIM \([0-9.]*\), mean brightness \([0-9.a-z]*\) .*/\1 \/ \2 \/ \3 (\4)/p'; }
echo "| scene | spp | input | planefit k 0.3 | planefit k 0 | bilateral |"
echo "|---|---|---|---|---|---|"
for s in cornell relief-abc double-textured glossy-cornell; do
  $T render --scene $s --size 128x128 --reference -o ref_$s.exr > /dev/null || exit 1
  for n in 4 16 64; do
    f=${s}_$n.exr
    $T render --scene $s --size 128x128 --spp $n --layers all -o $f > /dev/null || exit 1
    row="| $s | $n | $($T compare $f ref_$s.exr | m)"
    for v in "k03:--robust-k 0.3" "k0:--robust-k 0" "bl:--filter bilateral"; do
      out=${s}_${n}_${v%%:*}.exr
      $T denoise $f -o $out --method pivot ${v#*:} > /dev/null || exit 1
      row="$row | $($T compare $out ref_$s.exr | m)"
    done
    echo "$row |"
  done
done
for n in 4 16 64; do
  /usr/bin/python3 "$here/pivot_letters.py" letters_$n.png ref_relief-abc.exr relief-abc_$n.exr \
    relief-abc_${n}_k03.exr relief-abc_${n}_k0.exr relief-abc_${n}_bl.exr
done
