#!/usr/bin/env bash
# Size report, all measured in one run. Geometry (`--topology-only`): the
# .ssvdag (symmetry), the --no-symmetry .ssvdag (same compact encoding, plain
# SVDAG), and the same topology written by OpenVDB as a blosc MaskGrid .vdb
# (what `vdbdag decode` of a topology-only file writes). Then the lossless
# encoding with values against the input .vdb (blosc) and NanoVDB's float
# grid (nanovdb_convert), file and traceable in-memory sizes.
# Usage: scripts/size_report.sh [OUTDIR]   (needs a built tree: scripts/setup.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-build/size_report}
mkdir -p "$OUT"
inputs=()
[ -f "$OUT/sphere_d1024.vdb" ] || vdb_tool -sphere d=1024 r=1.0 w=3 -write "$OUT/sphere_d1024.vdb" >/dev/null
inputs+=("$OUT/sphere_d1024.vdb")
[ -f ../shared/data/levelsets/bunny_d512_ls.vdb ] && inputs+=(../shared/data/levelsets/bunny_d512_ls.vdb)
[ -f ../shared/data/levelsets/armadillo_d512_ls.vdb ] && inputs+=(../shared/data/levelsets/armadillo_d512_ls.vdb)
printf "| input | active voxels | SSVDAG bytes | SVDAG bytes | SSVDAG/SVDAG | MaskGrid blosc .vdb | SSVDAG/MaskGrid | bits/voxel | encode s |\n"
printf "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n"
for f in "${inputs[@]}"; do
  name=$(basename "$f" .vdb)
  start=$(date +%s.%N)
  build/vdbdag encode "$f" -o "$OUT/$name.ssvdag" -f --topology-only --json > "$OUT/$name.json"
  end=$(date +%s.%N)
  build/vdbdag encode "$f" -o "$OUT/$name.svdag.ssvdag" -f --no-symmetry --topology-only >/dev/null
  build/vdbdag decode "$OUT/$name.ssvdag" -o "$OUT/${name}_mask.vdb" -f
  voxels=$(python3 -c "import json;print(json.load(open('$OUT/$name.json'))['active_voxels'])")
  s=$(stat -c %s "$OUT/$name.ssvdag"); p=$(stat -c %s "$OUT/$name.svdag.ssvdag"); m=$(stat -c %s "$OUT/${name}_mask.vdb")
  python3 -c "print(f'| $name | {$voxels:,} | {$s:,} | {$p:,} | {$s/$p:.3f} | {$m:,} | {$s/$m:.4f} (1/{$m/$s:.1f}) | {8*$s/$voxels:.3f} | {$end-$start:.2f} |')"
done

printf "\n| input | blosc .vdb bytes | NanoVDB float bytes | lossless .ssvdag bytes | .ssvdag / .vdb | traceable bytes | traceable / NanoVDB | encode s |\n"
printf "|---|---:|---:|---:|---:|---:|---:|---:|\n"
for f in "${inputs[@]}"; do
  name=$(basename "$f" .vdb)
  nanovdb_convert -f "$f" "$OUT/$name.nvdb" >/dev/null
  start=$(date +%s.%N)
  build/vdbdag encode "$f" -o "$OUT/$name.values.ssvdag" -f >/dev/null
  end=$(date +%s.%N)
  build/vdbdag info "$OUT/$name.values.ssvdag" --values --json > "$OUT/$name.values.json"
  v=$(stat -c %s "$f"); n=$(stat -c %s "$OUT/$name.nvdb"); s=$(stat -c %s "$OUT/$name.values.ssvdag")
  t=$(python3 -c "import json;print(sum(g['traceable_bytes'] for g in json.load(open('$OUT/$name.values.json'))['grids']))")
  python3 -c "print(f'| $name | {$v:,} | {$n:,} | {$s:,} | {$s/$v:.3f} | {$t:,} | {$t/$n:.3f} | {$end-$start:.2f} |')"
done
