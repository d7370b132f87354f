#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan, UBSan fatal) and runs
# each for N seconds (default 120), JOBS (default 2) at a time, from a generated seed corpus:
#   fuzz_ssvdag_reader    whole files: container (magic, table, bounds,
#                         checksums, zstd; also with checksums patched so
#                         mutations reach the structural checks), then the
#                         section parsers, DAG validation and a DAG walk
#   fuzz_ssvdag_sections  section payloads and DAG validation behind the checksums
#   fuzz_int_volume_coder the integer value coder: hostile streams, and
#                         encode/decode round trips of the fuzzer's samples
#   fuzz_scan_headers     NRRD, MetaImage, NIfTI (libnifti) and DICOM (GDCM)
#                         headers and raw file names, then their samples,
#                         seeded from ../shared/data
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
# With FUZZ_RUNS=N each target instead runs N inputs from a fixed random seed
# and a fresh seed corpus: the same inputs on every machine, so the short run
# that scripts/test.sh makes passes or fails alike here and in CI.
# Crash inputs are written to build-fuzz/artifacts/; the corpus grows in
# build-fuzz/corpus_*. Exit status is non-zero if any target found a bug.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_TO_RUN=${1:-120}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(fuzz_ssvdag_reader fuzz_ssvdag_sections fuzz_scan_headers fuzz_int_volume_coder)
JOBS=${JOBS:-2}

CXX=clang++ CC=clang cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVDBDAG_BUILD_FUZZERS=ON -DVDBDAG_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz -j"$JOBS" --target "${TARGETS[@]}" make_seed_corpus
[ -n "${FUZZ_RUNS:-}" ] && rm -rf build-fuzz/corpus_reader build-fuzz/corpus_sections build-fuzz/corpus_scan_headers build-fuzz/corpus_int_volume_coder
mkdir -p build-fuzz/corpus_reader build-fuzz/corpus_sections build-fuzz/corpus_scan_headers build-fuzz/artifacts
# Valid files, and the forged files of the tests (an expansion, a legacy
# Values section, voxels past INT32_MAX, DICOM headers claiming more pixels
# than they hold).
build-fuzz/make_seed_corpus build-fuzz/corpus_reader build-fuzz/corpus_sections build-fuzz/corpus_scan_headers
# Scan seeds: a format byte (0 NRRD, 1 MetaImage, 2 NIfTI, 3 gzip NIfTI, 4
# DICOM) and the first 64 KiB of a real file of that format.
seed() {  # KIND FILE
  [ -f "$2" ] || return 0
  { printf "\\$(printf '%03o' "$1")"; head -c 65000 "$2"; } > "build-fuzz/corpus_scan_headers/seed_$1_$(basename "$2")"
}
DATA=../shared/data
seed 0 "$DATA/dense/FLAIR.nrrd"; seed 0 "$DATA/dense/cthead_256x256x99_uint8.nhdr"; seed 1 "$DATA/dense/tooth_103x94x161_uint8.mhd"
for f in "$DATA"/medical/nifti/*.nii.gz; do
  seed 3 "$f"
  [ -f "$f" ] && { printf '\002'; zcat "$f" | head -c 65000 || true; } > "build-fuzz/corpus_scan_headers/seed_2_$(basename "$f" .gz)"
done
for f in $(ls "$DATA"/medical/dicom/rsna_2/PET 2>/dev/null | head -3); do seed 4 "$DATA/medical/dicom/rsna_2/PET/$f"; done
# The forged NRRD of the tests: a billion samples in a gzip stream it does not have.
printf '\000NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1000 1000 1000\nendian: little\nencoding: gzip\n\n' > build-fuzz/corpus_scan_headers/forged_gzip_sizes
# Raw: format byte 5, the file name (its layout), a NUL, the samples.
{ printf '\005vol_4x4x4_uint16le\000'; printf '%0128d' 7; } > build-fuzz/corpus_scan_headers/seed_5_raw_u16
{ printf '\005ct_8x2x2_float32\000'; printf '%0128d' 3; } > build-fuzz/corpus_scan_headers/seed_5_raw_f32
# Inputs a target once failed on (tests/fuzz/regressions/NAME, NAME as in
# corpus_NAME): replayed first by every run, CI's short one included.
for d in tests/fuzz/regressions/*/; do
  name=$(basename "$d")
  mkdir -p "build-fuzz/corpus_$name"
  cp "$d"* "build-fuzz/corpus_$name/"
done

# The targets run JOBS at a time (each fuzzer is one process on one core),
# each into its own log; the summaries print in the targets' order.
run_target() {  # TARGET: its exit status in build-fuzz/TARGET.status
  local target=$1 corpus=build-fuzz/corpus_${1#fuzz_ssvdag_} rc=0
  [ "$target" = fuzz_scan_headers ] && corpus=build-fuzz/corpus_scan_headers
  [ "$target" = fuzz_int_volume_coder ] && corpus=build-fuzz/corpus_int_volume_coder && mkdir -p "$corpus"
  local limit=(-max_total_time="$SECONDS_TO_RUN")
  [ -n "${FUZZ_RUNS:-}" ] && limit=(-runs="$FUZZ_RUNS" -seed=1)
  echo "== $target: ${limit[*]} from $(ls "$corpus" | wc -l) corpus files" > build-fuzz/"$target".head
  build-fuzz/"$target" "${limit[@]}" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
      -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/"$target"- "$corpus" > build-fuzz/"$target".log 2>&1 || rc=$?
  echo "$rc" > build-fuzz/"$target".status
}
for target in "${TARGETS[@]}"; do
  rm -f build-fuzz/"$target".status
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  run_target "$target" &
done
wait
status=0
for target in "${TARGETS[@]}"; do
  cat build-fuzz/"$target".head
  if [ "$(cat build-fuzz/"$target".status 2>/dev/null || echo 1)" != 0 ]; then
    status=1
    echo "!! $target found a problem; see build-fuzz/$target.log and build-fuzz/artifacts/"
  fi
  grep -E "^(stat::|Done|INFO: -max_total_time)|ERROR|SUMMARY" build-fuzz/"$target".log | tail -n 12
done
exit $status
