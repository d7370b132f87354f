#!/usr/bin/env bash
# Packs the GPU measurement of issue 42 for a lent GPU machine into the
# ignored folder .gpu/ (about 30 MB, the one folder that travels): the
# project's vdbdag_gpu_trace_bench (the Vulkan tracer, its walk in floats and
# in doubles, and the CPU tracer) with its shared libraries, Debian's Vulkan
# loader, NanoVDB's headers and tests/tools/gpu/nvdb_trace.cu (NanoVDB's HDDA
# in CUDA, compiled there with nvcc), and the bunny level set as .ssvdag and
# as .nvdb. Run from the project's root after a build; on the GPU machine:
#   bash .gpu/run.sh      (results in $OUT, or .gpu/gpu_out)
# Check it here first: bash .gpu/run.sh --here (lavapipe, no CUDA: 1024x768 only).
set -euo pipefail
cd "$(dirname "$0")/.."
P=$PWD; D=$P/.gpu; B=$P/build
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo /.gpu/ >> .git/info/exclude
ninja -C "$B" vdbdag vdbdag_gpu_trace_bench > /dev/null
rm -rf "$D"; mkdir -p "$D/bin" "$D/lib" "$D/deb" "$D/data" "$D/include"
(cd "$D/deb" && apt-get download libvulkan1 > /dev/null)
cp "$B/vdbdag_gpu_trace_bench" "$D/bin/"
# Every shared library it needs but the C and C++ runtimes and the Vulkan loader (from the .deb).
ldd "$B/vdbdag_gpu_trace_bench" | awk '/=> \// {print $3}' | grep -v -E '/(libc|libm|libgcc_s|libstdc\+\+|libvulkan|ld-linux)[.-]' |
  while read -r l; do cp -L "$l" "$D/lib/"; done
cp -r /usr/include/nanovdb "$D/include/"
cp tests/tools/gpu/nvdb_trace.cu tests/tools/gpu/run.sh "$D/"
BUNNY=../shared/data/levelsets/bunny_d512_ls.vdb
[ -f "$BUNNY" ] || { echo "gpu_bundle.sh: no $BUNNY" >&2; exit 1; }
"$B/vdbdag" encode "$BUNNY" -o "$D/data/bunny.ssvdag" --force > /dev/null
nanovdb_convert -f "$BUNNY" "$D/data/bunny.nvdb" > /dev/null && xz -9 -f "$D/data/bunny.nvdb"
du -sh "$D"
