#!/usr/bin/env bash
# scripts/gpu_bundle.py and `scripts/gpu_bench.sh --bundle` end to end on this machine's
# device: the bundle loads nothing from outside itself but the C and C++ runtimes, its
# stand-ins satisfy the loader, the tests run from it in shards, and the script prints a
# table row from it, also after a failing test (then exiting 1).
# Usage: gpu_bundle_test.sh BUILD_DIR
set -euo pipefail
build=$(realpath "$1")
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "gpu_bundle_test: $*" >&2; exit 1; }

python3 "$root/scripts/gpu_bundle.py" --build "$build" --out "$tmp/bundle" --archive
[[ -f $tmp/bundle.tar.xz ]] || fail "no archive"
lib=$tmp/bundle/lib
[[ -f $lib/libOpenImageIO.so.2.4 && -f $lib/libvulkan.so.1 ]] || fail "libraries missing"
[[ -f $tmp/bundle/layers/VkLayer_khronos_validation.json ]] || fail "validation layer missing"
# A stand-in is tiny: no code of the library it stands for.
[[ $(stat -c %s "$lib/libopenvdb.so.10.0") -lt 100000 ]] || fail "libopenvdb is not a stand-in"
[[ -f $tmp/bundle/build/libmcdenoise_oiio.so ]] || fail "the OpenImageIO module is missing"
# Every library the binaries load resolves inside the bundle, but the runtimes.
for bin in "$tmp/bundle/build/mcdenoise" "$tmp/bundle/build/tests/mcd_tests" \
    "$tmp/bundle/build/libmcdenoise_oiio.so"; do
    outside=$(LD_LIBRARY_PATH=$lib ldd "$bin" | awk '/=>/ { print $1, $3 }' |
        grep -v -E "^(libc|libm|libstdc\+\+|libgcc_s)\.so" | grep -v " $lib/" || true)
    [[ -z "$outside" ]] || fail "$bin loads from outside the bundle: $outside"
done
# The bundled tool reads and writes PNG through the bundled module, with nothing set.
env -u MCD_OIIO_MODULE_DIR LD_LIBRARY_PATH=$lib "$tmp/bundle/build/mcdenoise" render \
    --size 8x8 --spp 2 -o "$tmp/r.exr" --preview "$tmp/r.png" >"$tmp/log" 2>&1 &&
    env -u MCD_OIIO_MODULE_DIR LD_LIBRARY_PATH=$lib "$tmp/bundle/build/mcdenoise" info \
        "$tmp/r.png" >>"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; fail "the bundle's PNG failed"; }
# The bundle runs: a few tests in shards (all of them counted, the module's PNG ones among
# them, and one that hands OpenImageIO a file that is no image, which must not reach a
# stand-in), a frame, one method, the table; from the archive, unpacked by the script.
filter='VkKernelCache*:VkBuffer*:IoTestModule.PngIsReadAndWrittenThroughTheModule'
filter+=':IoTest.ErrorsNameTheFileAndTheLayer'
expected=$(LD_LIBRARY_PATH=$lib "$tmp/bundle/build/tests/mcd_tests" --gtest_list_tests \
    --gtest_filter="$filter" | grep -c '^  ')
bash "$root/scripts/gpu_bench.sh" --bundle "$tmp/bundle.tar.xz" --test-filter "$filter" \
    --sizes 40x30 --kernels-size none --methods bayes --out "$tmp/out" >"$tmp/log" 2>&1 ||
    { cat "$tmp/log" >&2; fail "gpu_bench.sh --bundle failed"; }
grep -q -E "tests: $expected passed" "$tmp/log" ||
    { cat "$tmp/log" >&2; fail "the tests did not run from the bundle"; }
grep -q -E '^[^,]+,bayes,40x30,[0-9.]+,[0-9.]+$' "$tmp/out/table.csv" ||
    { cat "$tmp/out/table.csv" "$tmp/log" >&2; fail "no timed row for bayes"; }
# A failing test is reported, the table still printed, and the script exits 1: a bundle
# whose test binary fails.
cp -r "$tmp/bundle" "$tmp/failing"
printf '#!/bin/sh\necho "[  FAILED  ] Planted.Failure (1 ms)"\nexit 1\n' \
    >"$tmp/failing/build/tests/mcd_tests"
if bash "$root/scripts/gpu_bench.sh" --bundle "$tmp/failing" --sizes 40x30 --kernels-size none \
    --methods bayes --out "$tmp/out2" >"$tmp/log2" 2>&1; then
    cat "$tmp/log2" >&2; fail "a failing test did not fail the script"
fi
grep -q 'tests FAILED' "$tmp/log2" && grep -q 'Planted.Failure' "$tmp/log2" ||
    { cat "$tmp/log2" >&2; fail "the failure was not reported"; }
grep -q -E '^[^,]+,bayes,40x30,[0-9.]+,[0-9.]+$' "$tmp/out2/table.csv" ||
    { cat "$tmp/log2" >&2; fail "no table after a failing test"; }
# A shard that crashes inside a test is reported with that test's name, the table printed.
printf '#!/bin/sh\necho "[ RUN      ] Planted.Crash"\nkill -SEGV $$\n' \
    >"$tmp/failing/build/tests/mcd_tests"
if bash "$root/scripts/gpu_bench.sh" --bundle "$tmp/failing" --sizes 40x30 --kernels-size none \
    --methods bayes --out "$tmp/out3" >"$tmp/log3" 2>&1; then
    cat "$tmp/log3" >&2; fail "a crashing test did not fail the script"
fi
grep -q -E 'Planted.Crash: shard [0-9]+ crashed \(exit 139\)' "$tmp/log3" ||
    { cat "$tmp/log3" >&2; fail "the crash was not reported with its test"; }
grep -q -E '^[^,]+,bayes,40x30,[0-9.]+,[0-9.]+$' "$tmp/out3/table.csv" ||
    { cat "$tmp/log3" >&2; fail "no table after a crashing test"; }
echo "gpu_bundle_test: ok"
