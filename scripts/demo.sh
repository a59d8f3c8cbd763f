#!/usr/bin/env bash
# Build mcdenoise and run its main job on the built-in default input, writing images and a
# report to out/demo/. Until the renderer and the methods land, the main job is the
# wavelet foundation: a round trip of the built-in test image through the GPU DWT with
# every band dumped, and the wavelet benchmark at a size that finishes quickly.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
out=out/demo
mkdir -p "$out"
{
    echo "# mcdenoise demo, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    build/mcdenoise info
    build/mcdenoise wavelet builtin:rings -o "$out/roundtrip.png" --levels 5 --dump "$out/bands"
    build/mcdenoise bench wavelet --size 1024x1024 --repeat 3
} 2>&1 | tee "$out/report.txt"
echo "demo: images and report in $out/"
