#!/usr/bin/env bash
# scripts/gpu_bundle.py and `scripts/gpu_bench.sh --bundle` end to end on this machine's
# device: the bundle loads nothing from outside itself but the C and C++ runtimes, its
# stand-ins satisfy the loader, and the script prints a table row from it.
# Usage: gpu_bundle_test.sh BUILD_DIR
set -euo pipefail
build=$(realpath "$1")
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "gpu_bundle_test: $*" >&2; exit 1; }

python3 "$root/scripts/gpu_bundle.py" --build "$build" --out "$tmp/bundle"
lib=$tmp/bundle/lib
[[ -f $lib/libOpenImageIO.so.2.4 && -f $lib/libvulkan.so.1 ]] || fail "libraries missing"
[[ -f $tmp/bundle/layers/VkLayer_khronos_validation.json ]] || fail "validation layer missing"
# A stand-in is tiny: no code of the library it stands for.
[[ $(stat -c %s "$lib/libopenvdb.so.10.0") -lt 100000 ]] || fail "libopenvdb is not a stand-in"
# Every library the binaries load resolves inside the bundle, but the runtimes.
for bin in "$tmp/bundle/build/mcdenoise" "$tmp/bundle/build/tests/mcd_tests"; do
    outside=$(LD_LIBRARY_PATH=$lib ldd "$bin" | awk '/=>/ { print $1, $3 }' |
        grep -v -E "^(libc|libm|libstdc\+\+|libgcc_s)\.so" | grep -v " $lib/" || true)
    [[ -z "$outside" ]] || fail "$bin loads from outside the bundle: $outside"
done
# The bundle runs: a frame, one method, the table.
bash "$root/scripts/gpu_bench.sh" --bundle "$tmp/bundle" --no-tests --sizes 40x30 \
    --kernels-size none --methods bayes --out "$tmp/out" >"$tmp/log" 2>&1 ||
    { cat "$tmp/log" >&2; fail "gpu_bench.sh --bundle failed"; }
grep -q -E '^[^,]+,bayes,40x30,[0-9.]+,[0-9.]+$' "$tmp/out/table.csv" ||
    { cat "$tmp/out/table.csv" "$tmp/log" >&2; fail "no timed row for bayes"; }
echo "gpu_bundle_test: ok"
