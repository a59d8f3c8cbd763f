#!/usr/bin/env bash
# Build mcdenoise and run its test suite (everything but the `slow` label) on the default
# Vulkan device: lavapipe on a machine without a GPU. MCD_DEVICE picks another one. Then
# the installed library, through the program in examples/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
(
    cd build
    ctest -LE slow --output-on-failure -V -j "$(nproc)" 2>&1 |
        grep -vE '^[0-9]+: (Test command|Working Directory|Environment variables|Test timeout)'
    exit "${PIPESTATUS[0]}"
)
# The installed library, used by a program outside the tree (examples/).
scripts/example.sh
