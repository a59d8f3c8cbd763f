#!/usr/bin/env bash
# Install the library from build/ into build/install, build examples/ against it as a
# program outside the tree would (find_package(mcdenoise)), and denoise a small rendered
# frame with every method through it. Part of scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=build/install
rm -rf "$prefix" build/example
cmake --install build --prefix "$prefix" >/dev/null
cmake -S examples -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$PWD/$prefix" >/dev/null
cmake --build build/example >/dev/null
frame=build/example/frame.exr
build/mcdenoise render --scene cornell --size 48x40 --spp 4 --layers all -o "$frame" >/dev/null
passed=0 failed=0
for method in awr bayes pivot rhf auto; do
    out=build/example/frame-$method.exr
    if build/example/denoise_frame "$frame" "$out" "$method" 2>&1 | tail -n 1 && [[ -s "$out" ]]; then
        passed=$((passed + 1))
    else
        echo "example: $method failed" >&2
        failed=$((failed + 1))
    fi
done
echo "example: $passed of $((passed + failed)) methods ran through the installed library"
((failed == 0))
