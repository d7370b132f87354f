#!/usr/bin/env bash
# Set up (install missing packages, build) and run the whole test suite
# (GoogleTest and the safety scripts under ctest), the core's unit tests
# under ASan + UBSan, then short fuzz runs.
# Tests that need ../shared/data skip cleanly when it is absent.
# Each stage prints how long it took (CI's budget is 45 minutes in all).
set -euo pipefail
cd "$(dirname "$0")/.."
started=$(date +%s); stage_start=$started
stage_done() {  # NAME: the time since the last stage, and in all
  local now; now=$(date +%s)
  echo "test.sh: $1 took $((now - stage_start)) s ($((now - started)) s in all)"
  stage_start=$now
}
# The compiler cache (CMakeLists.txt): its counts say how much was compiled.
cache_counts() { command -v ccache > /dev/null && ccache --print-stats 2> /dev/null |
    awk -F'\t' '$1 ~ /^(direct_cache_hit|preprocessed_cache_hit|cache_miss)$/ {n[$1] = $2}
        END {printf "test.sh: ccache: %d objects from the cache, %d compiled\n", n["direct_cache_hit"] + n["preprocessed_cache_hit"], n["cache_miss"]}'; }
command -v ccache > /dev/null && ccache --zero-stats > /dev/null
VDBDAG_WERROR=ON scripts/setup.sh  # warnings of our own code are errors here
cache_counts || true
stage_done "setup and build"
(cd build && ctest --output-on-failure --timeout 900 -j"$(nproc)")
stage_done "the suite (ctest)"
# The core library and its unit tests again under ASan + UBSan (build-asan).
scripts/sanitize.sh
stage_done "the core under ASan + UBSan (build and tests)"
# Short fuzz runs of every parser (libFuzzer, ASan + UBSan, a clang build in
# build-fuzz): a fixed seed and number of inputs, so they find here what
# they find in CI. Longer runs: scripts/fuzz.sh SECONDS.
FUZZ_RUNS=${FUZZ_RUNS:-50000} scripts/fuzz.sh
stage_done "short fuzz runs (build and runs)"
