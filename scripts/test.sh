#!/usr/bin/env bash
# Set up (install missing packages, build) and run the whole test suite
# (GoogleTest and the safety scripts under ctest), the core's unit tests
# under ASan + UBSan, then short fuzz runs.
# Tests that need ../shared/data skip cleanly when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
VDBDAG_WERROR=ON scripts/setup.sh  # warnings of our own code are errors here
(cd build && ctest --output-on-failure --timeout 900 -j"$(nproc)")
# The core library and its unit tests again under ASan + UBSan (build-asan).
scripts/sanitize.sh
# Short fuzz runs of every parser (libFuzzer, ASan + UBSan, a clang build in
# build-fuzz): a fixed seed and number of inputs, so they find here what
# they find in CI. Longer runs: scripts/fuzz.sh SECONDS.
FUZZ_RUNS=${FUZZ_RUNS:-50000} scripts/fuzz.sh
