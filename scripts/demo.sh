#!/usr/bin/env bash
# Set up, then run the main job on a bundled sample: generate the samples,
# encode to .ssvdag, verify the lossless round trip, decode back to .vdb,
# write the VTK diff of the decode against the sample (torus_diff.vtu, for
# ParaView), render the .ssvdag (torus.png) and print a summary. Outputs go to demo_output/.
#
# Only what the demo needs is built first (the vdbdag command, the sample
# generator and libvdbdag_images.so, which writes the PNG), so the result
# shows before the rest (tests, benchmarks, vdbdag-mpi) is built at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
# Install the missing packages, configure, and build the demo's targets only.
VDBDAG_BUILD_TARGETS="vdbdag vdbdag_images vdbdag_make_samples" scripts/setup.sh
OUT=demo_output
mkdir -p "$OUT"
build/vdbdag_make_samples samples/generated >/dev/null
SAMPLE=samples/generated/torus_ls.vdb
echo "== encode $SAMPLE"
build/vdbdag encode "$SAMPLE" -o "$OUT/torus.ssvdag" -f
echo "== verify (encode + decode in memory, compared with OpenVDB)"
build/vdbdag verify "$SAMPLE"
echo "== decode"
build/vdbdag decode "$OUT/torus.ssvdag" -o "$OUT/torus_decoded.vdb" -f
echo "== VTK diff of the lossless decode (for ParaView; exits non-zero if anything differs)"
build/vdbdag diff "$SAMPLE" "$OUT/torus_decoded.vdb" -o "$OUT/torus_diff.vtu" -f
echo "== render (a Vulkan GPU when there is one, else the CPU tracer)"
build/vdbdag render "$OUT/torus.ssvdag" -o "$OUT/torus.png" -f --shadows
echo "== summary"
build/vdbdag info "$OUT/torus.ssvdag"
ls -l "$SAMPLE" "$OUT/torus.ssvdag" "$OUT/torus_decoded.vdb" "$OUT/torus_diff.vtu" "$OUT/torus.png"
echo "== demo done: its outputs are in $OUT/"
echo "== now building the remaining targets (tests, benchmarks, vdbdag-mpi): cmake --build build"
cmake --build build -j"$(nproc)"
echo "== build complete: scripts/test.sh runs the test suite"
