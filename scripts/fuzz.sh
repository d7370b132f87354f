#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan, UBSan fatal) and runs
# each for N seconds (default 120) from a generated seed corpus:
#   fuzz_ssvdag_reader    whole files: container (magic, table, bounds,
#                         checksums, zstd; also with checksums patched so
#                         mutations reach the structural checks), then the
#                         section parsers, DAG validation and a DAG walk
#   fuzz_ssvdag_sections  section payloads and DAG validation behind the checksums
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
# Crash inputs are written to build-fuzz/artifacts/; the corpus grows in
# build-fuzz/corpus_*. Exit status is non-zero if any target found a bug.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_TO_RUN=${1:-120}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(fuzz_ssvdag_reader fuzz_ssvdag_sections)
JOBS=${JOBS:-2}

CXX=clang++ CC=clang cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVDBDAG_BUILD_FUZZERS=ON -DVDBDAG_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz -j"$JOBS" --target "${TARGETS[@]}" make_seed_corpus
mkdir -p build-fuzz/corpus_reader build-fuzz/corpus_sections build-fuzz/artifacts
build-fuzz/make_seed_corpus build-fuzz/corpus_reader build-fuzz/corpus_sections

status=0
for target in "${TARGETS[@]}"; do
  corpus=build-fuzz/corpus_${target#fuzz_ssvdag_}
  echo "== $target: ${SECONDS_TO_RUN}s from $(ls "$corpus" | wc -l) corpus files"
  if ! build-fuzz/"$target" -max_total_time="$SECONDS_TO_RUN" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
        -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/"$target"- "$corpus" > build-fuzz/"$target".log 2>&1; then
    status=1
    echo "!! $target found a problem; see build-fuzz/$target.log and build-fuzz/artifacts/"
  fi
  grep -E "^(stat::|Done|INFO: -max_total_time)|ERROR|SUMMARY" build-fuzz/"$target".log | tail -n 12
done
exit $status
