#!/bin/bash
# What runs on the GPU machine (scripts/gpu_bundle.sh packs it into .gpu/):
# the project's Vulkan tracer, its walk in floats and in doubles, the CPU
# tracer on that machine's cores, and NanoVDB's HDDA in CUDA, on the same
# camera rays of the bunny level set at 1024x768, 1920x1080 and 3840x2160.
# Results go to $OUT (or .gpu/gpu_out). `--here`: a check of the bundle on
# this machine (lavapipe, no CUDA, 1024x768 only), nothing installed.
cd "$(dirname "$0")"  # the bundle folder
OUT=${OUT:-$PWD/gpu_out}; mkdir -p "$OUT"
export LD_LIBRARY_PATH=$PWD/lib
if [ "${1:-}" = --here ]; then
  ./bin/vdbdag_gpu_trace_bench data/bunny.ssvdag 2 cpu --small 2>&1 | tee "$OUT/gpu_trace_bench.txt"
  exit "${PIPESTATUS[0]}"
fi
for f in deb/*.deb; do dpkg -x "$f" /; done; ldconfig
nvidia-smi -L; nproc
ls /usr/share/vulkan/icd.d /etc/vulkan/icd.d /usr/local/nvidia/share/vulkan/icd.d 2>&1 | head
if ! ls /usr/share/vulkan/icd.d/*nvidia* /etc/vulkan/icd.d/*nvidia* >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
python3 -c "import lzma,shutil; shutil.copyfileobj(lzma.open('data/bunny.nvdb.xz'), open('data/bunny.nvdb','wb'))"
(nvcc -O3 -std=c++17 -arch=sm_90 -Iinclude nvdb_trace.cu -o nvdb_trace > "$OUT/nvcc.txt" 2>&1; echo "nvcc rc $?" >> "$OUT/nvcc.txt") &
timeout 300 ./bin/vdbdag_gpu_trace_bench data/bunny.ssvdag 30 cpu 2>&1 | tee "$OUT/gpu_trace_bench.txt"
wait
tail -30 "$OUT/nvcc.txt"
grep ^camera "$OUT/gpu_trace_bench.txt" | while read -r _ w h _ fov _ ex ey ez _ tx ty tz _ ux uy uz; do
  timeout 60 ./nvdb_trace data/bunny.nvdb 30 "$w" "$h" "$fov" "$ex" "$ey" "$ez" "$tx" "$ty" "$tz" "$ux" "$uy" "$uz"
done 2>&1 | tee "$OUT/nvdb.txt"
