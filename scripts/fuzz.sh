#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan+UBSan) and runs each for N
# seconds (default 120) from a generated seed corpus:
#   fuzz_ssvdag_reader    whole files (container, checksums, sections, DAG)
#   fuzz_ssvdag_sections  section payloads and DAG validation behind the checksums
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_TO_RUN=${1:-120}
CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVDBDAG_BUILD_FUZZERS=ON -DVDBDAG_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz --target fuzz_ssvdag_reader fuzz_ssvdag_sections make_seed_corpus
mkdir -p build-fuzz/corpus_reader build-fuzz/corpus_sections
build-fuzz/make_seed_corpus build-fuzz/corpus_reader build-fuzz/corpus_sections
for target in fuzz_ssvdag_reader fuzz_ssvdag_sections; do
  corpus=build-fuzz/corpus_${target#fuzz_ssvdag_}
  build-fuzz/$target -max_total_time="$SECONDS_TO_RUN" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 "$corpus" 2>&1 | tail -n 12
done
