#!/usr/bin/env bash
# Set up, then run the main job on a bundled sample: generate the samples,
# encode to .ssvdag, verify the lossless round trip, decode back to .vdb,
# write the VTK diff of the decode against the sample (torus_diff.vtu, for
# ParaView), render the .ssvdag (torus.png) and print a summary. Outputs go to demo_output/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
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
echo "== render (Vulkan when a device exists, else the CPU tracer)"
build/vdbdag render "$OUT/torus.ssvdag" -o "$OUT/torus.png" -f --shadows
echo "== summary"
build/vdbdag info "$OUT/torus.ssvdag"
ls -l "$SAMPLE" "$OUT/torus.ssvdag" "$OUT/torus_decoded.vdb" "$OUT/torus_diff.vtu" "$OUT/torus.png"
