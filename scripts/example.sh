#!/usr/bin/env bash
# Install the library from build/ into build/install, build examples/ against it as a
# program outside the tree would (find_package(mcdenoise)), and denoise a small rendered
# frame with every method through it. Part of scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=build/install
rm -rf "$prefix" build/example
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Quiet when it works, the whole log when a step fails.
step() { "$@" >"$log" 2>&1 || { cat "$log" >&2; echo "example: failed: $*" >&2; exit 1; }; }
step cmake --install build --prefix "$prefix"
step cmake -S examples -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$PWD/$prefix"
step cmake --build build/example
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
