#!/usr/bin/env bash
# Every method and auto on a GPU (issue #32), from a fresh clone: install what is missing,
# build, run the kernel-vs-reference tests on the device, then denoise a frame of the
# built-in renderer (every layer) at each size with each method and print one table: the
# GPU time (the sum of the dispatches' timestamps) and the whole process's wall time, beside
# a previous run's figures on another device (--beside: lavapipe's CSV from this script);
# then `mcdenoise bench kernels` at one size: each method's main kernels against the
# device's streaming and FMA rates measured in the same run (docs/performance.md).
#
# Sized for a 15-minute slot on an NVIDIA H100/H200 with 16 cores (the defaults). On
# lavapipe shrink it, e.g. --sizes 128x96 --kernels-size 64x64 --methods awr,auto.
#
# Usage: scripts/gpu_bench.sh [options]
#   --sizes LIST     frame sizes, comma-separated (default 1920x1080,3840x2160)
#   --methods LIST   methods, comma-separated (default: every method the CLI lists, and auto)
#   --device NAME    the Vulkan device (a name or index as `mcdenoise info` lists; default
#                    the first NVIDIA device, else mcdenoise's own choice)
#   --spp N          samples per pixel of the rendered frames (default 8)
#   --kernels-size S the frame size of `bench kernels` (default 1920x1080; none: skip it)
#   --run-timeout N  seconds one denoise (or the kernels bench) may take (default 300)
#   --beside CSV     a previous run's table.csv, printed beside this run's figures
#   --out DIR        where frames, outputs and the table go (default gpu_bench.out)
#   --debs DIR       a machine without network: install the .deb files in DIR instead of
#                    apt-get (scripts/packages.txt and their dependencies, downloaded with
#                    `apt-get download` on a machine of the same release)
#   --bundle DIR     a machine that cannot build (no network, another distribution): run the
#                    binaries and libraries packed by scripts/gpu_bundle.py into DIR instead
#                    of installing and building (implies --no-install --no-build); or the
#                    DIR.tar.xz that `gpu_bundle.py --archive` writes, unpacked into --out
#   --test-filter P  the tests run on the device (default '*Kernel*': every kernel-vs-reference
#                    suite), in one process per core (at most 16), as gtest shards
#   --test-timeout N seconds one shard may take (default 600); a shard that runs past it or
#                    crashes is reported with the test it was in, and the others' logs kept
#   --no-install, --no-build, --no-tests   skip a step
# Writes DIR/table.csv (device,method,size,gpu_ms,wall_s, one row per run), DIR/kernels.csv
# (bench kernels' figures per kernel), DIR/table.md (both tables) and DIR/tests.log. A failed
# test does not stop the runs: the script prints the table and then exits 1.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

sizes=1920x1080,3840x2160
methods=""
device=""
spp=8
kernelsSize=1920x1080
runTimeout=300
beside=""
out=gpu_bench.out
debs=""
bundle=""
testFilter='*Kernel*'
testTimeout=600
install=1 build=1 tests=1
while (($#)); do
    case $1 in
    --sizes) sizes=$2; shift ;;
    --methods) methods=$2; shift ;;
    --device) device=$2; shift ;;
    --spp) spp=$2; shift ;;
    --kernels-size) kernelsSize=$2; shift ;;
    --run-timeout) runTimeout=$2; shift ;;
    --beside) beside=$(realpath "$2"); shift ;;
    --out) out=$2; shift ;;
    --debs) debs=$(realpath "$2"); shift ;;
    --bundle) bundle=$(realpath "$2"); install=0 build=0; shift ;;
    --test-filter) testFilter=$2; shift ;;
    --test-timeout) testTimeout=$2; shift ;;
    --no-install) install=0 ;;
    --no-build) build=0 ;;
    --no-tests) tests=0 ;;
    -h | --help) sed -n '2,37p' "$0"; exit 0 ;;
    *) echo "gpu_bench: unknown argument $1 (--help lists them)" >&2; exit 2 ;;
    esac
    shift
done
mkdir -p "$out"
out=$(realpath "$out")
say() { echo "gpu_bench: $*" >&2; }

# 1. Packages: scripts/packages.txt, from apt or from --debs.
install_packages() {
    local missing=()
    while read -r package; do
        [[ -z "$package" || "$package" == \#* ]] && continue
        dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
            missing+=("$package")
    done <scripts/packages.txt
    ((${#missing[@]})) || return 0
    if [[ -n "$debs" ]]; then
        say "installing the .deb files of $debs"
        dpkg -i "$debs"/*.deb >"$out/install.log" 2>&1 || {
            say "dpkg -i failed; see $out/install.log"; exit 1; }
    elif [[ $(id -u) -eq 0 ]]; then
        say "installing ${missing[*]}"
        export DEBIAN_FRONTEND=noninteractive
        { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}"; } \
            >"$out/install.log" 2>&1 || {
            say "apt-get failed (no network? then --debs); see $out/install.log"; exit 1; }
    else
        say "missing packages: ${missing[*]} (run as root, or pass --debs)"; exit 1
    fi
}
((install)) && install_packages

# 2. Build (Release) into build/: the tool and the fast tests only (ccache where installed).
if ((build)); then
    say "building"
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    [[ -f build/build.ninja ]] || cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
        "${launcher[@]}" >"$out/build.log" 2>&1 || {
        say "cmake failed; see $out/build.log"; exit 1; }
    cmake --build build --parallel "$(nproc)" --target mcdenoise mcd_tests >>"$out/build.log" \
        2>&1 || { say "the build failed; see $out/build.log"; exit 1; }
fi
bin=$root/build
if [[ -f "$bundle" ]]; then
    say "unpacking $bundle"
    rm -rf "$out/bundle" && mkdir -p "$out/bundle"
    tar -xJf "$bundle" -C "$out/bundle" --strip-components=1 || {
        say "cannot unpack $bundle"; exit 1; }
    bundle=$out/bundle
fi
if [[ -n "$bundle" ]]; then
    bin=$bundle/build
    export LD_LIBRARY_PATH=$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    export VK_LAYER_PATH=$bundle/layers
    # OpenImageIO tries every reader on a file its extension's reader cannot open, and the
    # bundle's stand-ins would run: let it try that one reader alone.
    export OPENIMAGEIO_OPTIONS=${OPENIMAGEIO_OPTIONS:+$OPENIMAGEIO_OPTIONS,}try_all_readers=0
fi
tool=$bin/mcdenoise
[[ -x "$tool" ]] || { say "no $tool (build first)"; exit 1; }

# The device: the one named, else the first NVIDIA device. NVIDIA's driver sometimes ships
# its ICD outside the loader's search path.
if ! "$tool" info 2>/dev/null | grep -qi nvidia; then
    for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json \
        /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json; do
        [[ -f "$icd" ]] && export VK_DRIVER_FILES=$icd && break
    done
fi
if [[ -z "$device" ]]; then
    device=$("$tool" info 2>/dev/null | sed -n 's/^[* ] \([0-9]*\): .*NVIDIA.*/\1/p' | head -1)
fi
[[ -n "$device" ]] && export MCD_DEVICE=$device
name=$("$tool" info 2>/dev/null | sed -n 's/^\* [0-9]*: \(.*\) (.*), Vulkan.*/\1/p' | head -1)
[[ -n "$name" ]] || { say "no Vulkan device (mcdenoise info):"; "$tool" info >&2; exit 1; }
say "device: $name"
csvName=${name//,/;}  # the CSV's device column

# 3. The kernel-vs-reference tests on that device: gtest shards side by side, one process
# (one Vulkan device) each, since the CPU references are most of their time.
testsFailed=0
if ((tests)); then
    shards=$(nproc)
    ((shards > 16)) && shards=16
    say "tests $testFilter on $name, $shards processes"
    pids=()
    for ((i = 0; i < shards; ++i)); do
        GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i timeout "$testTimeout" \
            "$bin/tests/mcd_tests" --gtest_filter="$testFilter" >"$out/tests_$i.log" 2>&1 &
        pids+=($!)
    done
    for ((i = 0; i < shards; ++i)); do
        rc=0
        wait "${pids[$i]}" || rc=$?
        ((rc)) && testsFailed=1
        # A shard that ended without gtest's summary: name the test it was in.
        if ((rc == 124 || rc > 128)); then
            last=$(sed -n 's/^\[ RUN      \] //p' "$out/tests_$i.log" | tail -1)
            how="crashed (exit $rc)"
            ((rc == 124)) && how="ran past $testTimeout s"
            echo "[  FAILED  ] ${last:-(before its first test)}: shard $i $how" >>"$out/tests_$i.log"
        fi
    done
    cat "$out"/tests_*.log >"$out/tests.log"
    rm -f "$out"/tests_*.log
    passed=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) tests\{0,1\}\..*/\1/p' "$out/tests.log" |
        awk '{ n += $1 } END { print n + 0 }')
    if ((testsFailed)); then
        say "tests FAILED on $name ($passed passed); see $out/tests.log"
        grep -E '^\[  FAILED  \] .*( \([0-9]+ ms\)|: shard [0-9]+ .*)$' "$out/tests.log" >&2 || true
    else
        say "tests: $passed passed on $name"
    fi
fi

# 4. Each method at each size: one rendered frame per size, one process per run.
# The methods the CLI lists under "Methods (--method):", one "  name: summary" a line.
if [[ -z "$methods" ]]; then
    methods=$("$tool" denoise --help | sed -n '/^Methods/,/^Usage/p' |
        sed -n 's/^  \([a-z0-9]*\): .*/\1/p' | paste -sd,),auto
fi
say "methods: $methods"
csv=$out/table.csv
echo "device,method,size,gpu_ms,wall_s" >"$csv"
for size in ${sizes//,/ }; do
    frame=$out/frame_$size.exr
    if [[ ! -f "$frame" ]]; then
        say "rendering $size, $spp spp, every layer"
        "$tool" render --size "$size" --spp "$spp" --layers all -o "$frame" >/dev/null
    fi
    for method in ${methods//,/ }; do
        start=$(date +%s%N)
        if line=$(timeout "$runTimeout" "$tool" denoise "$frame" --method "$method" \
            -o "$out/${method}_$size.exr" 2>&1 | grep -E ": $method in [0-9.]+ ms"); then
            wall=$(awk -v ns=$(($(date +%s%N) - start)) 'BEGIN { printf "%.2f", ns / 1e9 }')
            gpu=$(echo "$line" | sed -n 's/.* in [0-9.]* ms (\([0-9.]*\) ms GPU.*/\1/p')
            printf '%s,%s,%s,%s,%s\n' "$csvName" "$method" "$size" "$gpu" "$wall" >>"$csv"
            say "$method at $size: $gpu ms GPU, $wall s wall"
        else
            say "$method at $size failed (or ran past $runTimeout s)"
            printf '%s,%s,%s,failed,failed\n' "$csvName" "$method" "$size" >>"$csv"
        fi
    done
done

# 5. Each method's main kernels against the device's limits, measured in one process.
kernelsCsv=$out/kernels.csv
rm -f "$kernelsCsv"
if [[ "$kernelsSize" != none ]]; then
    say "bench kernels at $kernelsSize"
    timeout "$runTimeout" "$tool" bench kernels --size "$kernelsSize" --spp "$spp" \
        --methods "$methods" --csv "$kernelsCsv" >"$out/kernels.txt" 2>&1 ||
        say "bench kernels failed (or ran past $runTimeout s); see $out/kernels.txt"
fi

# The table, with the --beside run's figures for the same method and size.
other=""
[[ -n "$beside" ]] && other=$(sed -n '2p' "$beside" | cut -d, -f1)
{
    if [[ -n "$other" ]]; then
        echo "| method | size | $name GPU ms | wall s | $other GPU ms | wall s |"
        echo "|---|---|---|---|---|---|"
    else
        echo "| method | size | $name GPU ms | wall s |"
        echo "|---|---|---|---|"
    fi
    tail -n +2 "$csv" | while IFS=, read -r _ method size gpu wall; do
        row="| $method | $size | $gpu | $wall |"
        if [[ -n "$other" ]]; then
            theirs=$(awk -F, -v m="$method" -v s="$size" '$2 == m && $3 == s { print $4 " | " $5 }' \
                "$beside" | head -1)
            row="$row ${theirs:-- | -} |"
        fi
        echo "$row"
    done
    # The kernels of at least 5% of their method's GPU time, from bench kernels; a kernel
    # without an operation formula has its bytes' bound only, a lower bound of the fraction;
    # '<=' marks a count that takes no data-dependent shortcut (flops_bound at_most).
    if [[ -s "$kernelsCsv" ]]; then
        echo
        sed -n '1s/^# /bench kernels: /p' "$kernelsCsv"
        echo
        echo "| method | kernel | calls | bytes/px | flop/px | GPU ms | GB/s | GFLOP/s | of roofline |"
        echo "|---|---|---|---|---|---|---|---|---|"
        awk -F, 'NR > 2 { total[$1] += $6; row[NR] = $0 }
            END { for (i = 3; i <= NR; ++i) { split(row[i], f, ",");
                if (f[6] >= 0.05 * total[f[1]])
                    printf "| %s | %s | %s | %s | %s | %.2f | %s | %s | %s%.1f%% |\n", f[1],
                        f[2], f[3], f[4], f[5] == "" ? "-" : (f[10] == "at_most" ? "<=" : "") f[5],
                        f[6], f[7], f[8] == "" ? "-" : (f[10] == "at_most" ? "<=" : "") f[8],
                        f[5] == "" ? ">=" : "", 100 * f[9] } }' \
            "$kernelsCsv"
    fi
} | tee "$out/table.md"
exit $testsFailed
