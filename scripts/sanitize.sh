#!/usr/bin/env bash
# The core library and its unit tests under AddressSanitizer and
# UndefinedBehaviorSanitizer (CMake option VDBDAG_SANITIZE, build-asan):
# the container, DAG, value coders, reader and CPU tracer with every
# out-of-bounds access, use after free, leak and undefined operation caught.
# Run by scripts/test.sh beside the Release suite.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DVDBDAG_SANITIZE=ON -DVDBDAG_BUILD_TESTS=OFF >/dev/null
cmake --build build-asan -j"$JOBS" --target vdbdag_core_tests
(cd build-asan && ctest --output-on-failure --timeout 900 -j"$JOBS" -R '^[A-Za-z]')
