#!/usr/bin/env bash
# Install the libraries from build/ into build/install and use them as programs outside
# the tree would: check that the core library links no image-file library, build
# examples/ against the installed CMake package as C++17 (find_package(mcdenoise)),
# denoise a small rendered frame with every method (denoise_frame, files), denoise
# buffers in memory from C++ and from C (denoise_buffers, denoise_buffers_c), and run the
# installed Python module. Part of scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=build/install
rm -rf "$prefix" build/example
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Quiet when it works, the whole log when a step fails.
step() { "$@" >"$log" 2>&1 || { cat "$log" >&2; echo "example: failed: $*" >&2; exit 1; }; }
fail() { echo "example: $*" >&2; exit 1; }
step cmake --install build --prefix "$prefix"

core=$(find "$prefix" -name 'libmcdenoise.so' | head -n 1)
[[ -n "$core" ]] || fail "no libmcdenoise.so under $prefix"
libs=$(ldd "$core")
if grep -qiE 'OpenImageIO|OpenEXR|libdeflate' <<<"$libs"; then
    echo "$libs" >&2
    fail "$core links an image-file library"
fi
echo "example: $(basename "$core") needs $(wc -l <<<"$libs") shared libraries, no image-file library"

step cmake -S examples -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$PWD/$prefix" \
    -DCMAKE_CXX_STANDARD=17 -DCMAKE_CXX_STANDARD_REQUIRED=ON
# Whole output first: grep -q would close the pipe early, and pipefail reads ninja's SIGPIPE
# as a failure.
commands=$(ninja -C build/example -t commands denoise_buffers)
grep -q -- '-std=[a-z]*++17' <<<"$commands" || fail "the examples did not build as C++17"
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

# Buffers in memory, no files: the C++ example (each fails unless the error falls).
for method in auto bayes awr; do
    build/example/denoise_buffers "$method" || fail "denoise_buffers $method failed"
done
build/example/denoise_buffers_c || fail "denoise_buffers_c failed"

# The Python module, installed beside the libraries: the issue's check.
python=$(command -v /usr/bin/python3 || command -v python3)
site=$(find "$prefix" -type d -name dist-packages | head -n 1)
[[ -n "$site" && -f "$site/mcdenoise/__init__.py" ]] || fail "no Python module under $prefix"
shape=$(PYTHONPATH="$PWD/$site" "$python" -c \
    "import mcdenoise, numpy as np; print(mcdenoise.denoise(np.random.rand(64, 64, 3).astype(np.float32)).shape)")
[[ "$shape" == "(64, 64, 3)" ]] || fail "the Python check printed '$shape', not (64, 64, 3)"
echo "example: python: mcdenoise.denoise(64x64x3) -> $shape (module in $site)"
