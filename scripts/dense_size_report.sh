#!/usr/bin/env bash
# Dense-scan size report (issue 5), every figure measured in this one run:
# for each scan, the raw samples, `zstd -19` and `xz -9e` of the raw file,
# OpenVDB's blosc .vdb of the same dense grid (`vdbdag import`, rewritten by
# `vdb_tool ... codec=blosc`), the lossless .ssvdag (`vdbdag encode`, brick
# predictor when it is smaller) and the palette-only .ssvdag (`--no-predict`);
# then the lossy variant with the air made background (`--background-below`),
# its size and the error it costs (from `encode --json`).
# Usage: scripts/dense_size_report.sh [OUTDIR] [PHANTOM_PREFIX]
#   PHANTOM_PREFIX: also report PREFIX.nhdr/.raw (vdbdag_make_ct_phantom).
# Needs a built tree (scripts/setup.sh) and ../shared/data/dense.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-build/dense_size_report}
PHANTOM=${2:-}
mkdir -p "$OUT"
D=../shared/data/dense
# header|raw|threshold for --background-below
inputs=("$D/cranium_256x256x108_int16le.nhdr|$D/cranium_256x256x108_int16le.raw|-500"
        "$D/cthead_256x256x99_uint8.nhdr|$D/cthead_256x256x99_uint8.raw|30")
[ -n "$PHANTOM" ] && inputs+=("$PHANTOM.nhdr|$PHANTOM.raw|400")

printf "| scan | raw bytes | zstd -19 | xz -9e | blosc .vdb | .ssvdag lossless | palettes only | .ssvdag/raw | .ssvdag/zstd | .ssvdag/xz | .ssvdag/blosc | encode s |\n"
printf "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
for entry in "${inputs[@]}"; do
  IFS='|' read -r header raw threshold <<< "$entry"
  name=$(basename "$header" .nhdr)
  r=$(stat -c %s "$raw")
  z=$(zstd -19 -T2 -q -c "$raw" | wc -c)
  x=$(xz -9e -T2 -c "$raw" | wc -c)
  build/vdbdag import "$header" -o "$OUT/$name.import.vdb" -f > /dev/null
  vdb_tool -read "$OUT/$name.import.vdb" -write codec=blosc "$OUT/$name.blosc.vdb" > /dev/null 2>&1
  b=$(stat -c %s "$OUT/$name.blosc.vdb")
  start=$(date +%s.%N)
  build/vdbdag encode "$header" -o "$OUT/$name.ssvdag" -f > /dev/null
  end=$(date +%s.%N)
  s=$(stat -c %s "$OUT/$name.ssvdag")
  build/vdbdag encode "$header" --no-predict -o "$OUT/$name.palette.ssvdag" -f > /dev/null
  p=$(stat -c %s "$OUT/$name.palette.ssvdag")
  python3 -c "print(f'| $name | {$r:,} | {$z:,} ({$z/$r:.3f}x) | {$x:,} ({$x/$r:.3f}x) | {$b:,} ({$b/$r:.3f}x) | {$s:,} | {$p:,} ({$p/$r:.3f}x) | {$s/$r:.3f} | {$s/$z:.3f} | {$s/$x:.3f} | {$s/$b:.3f} | {$end-$start:.2f} |')"
done

printf "\n| scan | --background-below | .ssvdag bytes | .ssvdag/raw | inactive samples | changed | max abs change | mean abs change | RMS | PSNR dB |\n"
printf "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
for entry in "${inputs[@]}"; do
  IFS='|' read -r header raw threshold <<< "$entry"
  name=$(basename "$header" .nhdr)
  r=$(stat -c %s "$raw")
  build/vdbdag encode "$header" --background-below "$threshold" --json -o "$OUT/$name.air.ssvdag" -f > "$OUT/$name.air.json"
  python3 - "$OUT/$name.air.json" "$r" "$name" "$threshold" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); raw = int(sys.argv[2]); t = j["threshold"]
psnr = "inf" if t["psnr_db"] is None else f"{t['psnr_db']:.2f}"
print(f"| {sys.argv[3]} | {sys.argv[4]} (background {t['background_value']:g}) | {j['bytes']:,} | {j['bytes']/raw:.3f} | {t['inactive_samples']:,} of {t['samples']:,} | {t['changed_samples']:,} | {t['max_abs_change']:g} | {t['mean_abs_change']:.3f} | {t['rms_change']:.3f} | {psnr} |")
PY
done
