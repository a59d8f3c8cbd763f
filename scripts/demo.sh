#!/usr/bin/env bash
# Build mcdenoise and run its main job on the built-in default scene, writing images and a
# report to out/demo/: the cornell scene rendered with every layer group (the frame the
# methods will denoise), a reference (cached after the first run), previews, and the
# error of the noisy frame against the reference; then each of the five methods (awr,
# rhf, bayes, pivot, nfor) and auto (the default: them combined per pixel) with its plan,
# time and error against the reference;
# then the wavelet foundation on the frame (a GPU DWT round trip with every band dumped)
# and the wavelet benchmark at a size that finishes quickly.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
out=out/demo
mkdir -p "$out"
mcd=build/mcdenoise
{
    echo "# mcdenoise demo, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    $mcd info
    $mcd render --scene cornell --size 256x256 --spp 8 --seed 1 --layers all \
        -o "$out/cornell.exr" --preview "$out/cornell.png"
    $mcd render --scene cornell --size 256x256 --spp 256 --reference \
        -o "$out/cornell-reference.exr" --preview "$out/cornell-reference.png"
    $mcd info "$out/cornell.exr"
    $mcd compare "$out/cornell.exr" "$out/cornell-reference.exr"
    for method in awr rhf bayes pivot nfor auto; do
        $mcd denoise "$out/cornell.exr" --method $method --explain -o "$out/cornell-$method.exr" \
            --preview "$out/cornell-$method.png" --reference "$out/cornell-reference.exr"
    done
    $mcd wavelet "$out/cornell.exr" -o "$out/roundtrip.png" --levels 5 --dump "$out/bands"
    $mcd bench wavelet --size 1024x1024 --repeat 3
} 2>&1 | tee "$out/report.txt"
echo "demo: images and report in $out/"
