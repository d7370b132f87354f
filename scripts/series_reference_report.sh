#!/usr/bin/env bash
# A 4-D scan's volumes coded against the volume before (issue 43 item 2,
# docs/FORMAT.md 8.6) in one run: each series encoded with every volume
# alone (--key-every 1, the baseline) and with the default key volumes
# (--key-every 8), and with one key volume (--key-every 256); sizes, and
# encode and decode times as medians of 5 runs, the two commands
# alternated. Every decode is checked sample for sample against the source
# by nibabel (bit for bit, floats by their bits).
# Inputs: ../shared/data/medical/nifti/mpld_asl.nii.gz when present, and a
# synthetic fMRI-like series made here with numpy (64x64x32 int16, 60
# volumes: a smooth head, per-voxel noise, a slow drift and a block
# activation), labelled as synthetic.
# Writes docs/series_reference.md and docs/bench/series_reference.jsonl.
#   scripts/series_reference_report.sh
set -euo pipefail
cd "$(dirname "$0")/.."
VDBDAG=build/vdbdag
PY=/usr/bin/python3
OUT=docs/series_reference.md
JSONL=docs/bench/series_reference.jsonl
mkdir -p docs/bench
: > "$JSONL"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
INPUTS=()
ASL=../shared/data/medical/nifti/mpld_asl.nii.gz
[ -f "$ASL" ] && INPUTS+=("$ASL")
"$PY" - "$TMP/synthetic_fmri.nii.gz" <<'EOF'
import sys
import numpy as np
import nibabel as nib
rng = np.random.default_rng(5)
x, y, z = np.meshgrid(np.arange(64), np.arange(64), np.arange(32), indexing="ij")
r = np.sqrt(((x - 32) / 28.0) ** 2 + ((y - 32) / 30.0) ** 2 + ((z - 16) / 15.0) ** 2)
head = np.where(r < 1, 800 + 300 * np.cos(3 * r) + 40 * np.sin(x / 3.0) * np.cos(y / 4.0), 20)
region = ((x - 40) ** 2 + (y - 26) ** 2 + (z - 18) ** 2) < 36
vols = []
for t in range(60):
    v = head * (1 + 0.0004 * t) + rng.normal(0, 12, head.shape) + (25 * region if (t // 10) % 2 else 0)
    vols.append(np.clip(np.rint(v), 0, 32767).astype(np.int16))
img = nib.Nifti1Image(np.stack(vols, axis=-1), np.diag([3.0, 3.0, 3.5, 1.0]))
img.header.set_xyzt_units("mm", "sec")
nib.save(img, sys.argv[1])
EOF
INPUTS+=("$TMP/synthetic_fmri.nii.gz")
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
seconds() { local s e; s=$(date +%s.%N); "$@" > /dev/null; e=$(date +%s.%N); echo "$e - $s" | bc; }
{
  echo "# A 4-D scan's volumes coded against the volume before"
  echo
  echo "Made by \`scripts/series_reference_report.sh\` on $(date -u +%Y-%m-%d), vdbdag $(git describe --always --dirty 2>/dev/null || echo unknown),"
  echo "$(nproc) cores. Each series encoded with every volume alone (\`--key-every 1\`, the baseline),"
  echo "with a key volume every 8 (the default) and with one key volume (\`--key-every 256\`)."
  echo "Times: medians of 5 runs, the commands alternated; decode to .nii.gz. Every decode checked"
  echo "bit for bit against the source by nibabel."
  echo
  echo "| series | volumes | alone (bytes) | key every 8 | ratio | one key | ratio | encode alone / key 8 (s) | decode alone / key 8 (s) | bit-exact |"
  echo "|---|---:|---:|---:|---:|---:|---:|---|---|---|"
} > "$OUT"
for in in "${INPUTS[@]}"; do
  name=$(basename "$in")
  volumes=$("$PY" -c "import nibabel as n,sys; s=n.load(sys.argv[1]).shape; print(s[3] if len(s)>3 else 1)" "$in")
  declare -A enc=() dec=()
  for run in 1 2 3 4 5; do
    for k in 1 8; do
      enc[$k]+="$(seconds "$VDBDAG" encode "$in" -o "$TMP/k$k.ssvdag" --key-every $k --force) "
      dec[$k]+="$(seconds "$VDBDAG" decode "$TMP/k$k.ssvdag" -o "$TMP/k$k.nii.gz" --force) "
    done
  done
  "$VDBDAG" encode "$in" -o "$TMP/k256.ssvdag" --key-every 256 --force > /dev/null
  "$VDBDAG" decode "$TMP/k256.ssvdag" -o "$TMP/k256.nii.gz" --force > /dev/null
  exact=$("$PY" - "$in" "$TMP/k1.nii.gz" "$TMP/k8.nii.gz" "$TMP/k256.nii.gz" <<'EOF'
import sys
import numpy as np
import nibabel as nib
src = np.asarray(nib.load(sys.argv[1]).dataobj)
ok = True
for p in sys.argv[2:]:
    got = np.asarray(nib.load(p).dataobj)
    ok &= got.dtype == src.dtype and got.shape == src.shape and np.ascontiguousarray(got).tobytes() == np.ascontiguousarray(src).tobytes()
print("true" if ok else "false")
EOF
)
  b1=$(stat -c %s "$TMP/k1.ssvdag"); b8=$(stat -c %s "$TMP/k8.ssvdag"); b256=$(stat -c %s "$TMP/k256.ssvdag")
  e1=$(tr ' ' '\n' <<< "${enc[1]}" | grep . | median); e8=$(tr ' ' '\n' <<< "${enc[8]}" | grep . | median)
  d1=$(tr ' ' '\n' <<< "${dec[1]}" | grep . | median); d8=$(tr ' ' '\n' <<< "${dec[8]}" | grep . | median)
  r8=$(echo "scale=3; $b8 / $b1" | bc); r256=$(echo "scale=3; $b256 / $b1" | bc)
  label=$name
  [[ "$in" == "$TMP"/* ]] && label="$name (synthetic, made by this script)"
  printf '| %s | %s | %s | %s | 0%s | %s | 0%s | %.2f / %.2f | %.2f / %.2f | %s |\n' "$label" "$volumes" "$b1" "$b8" "$r8" "$b256" "$r256" "$e1" "$e8" "$d1" "$d8" "$exact" >> "$OUT"
  printf '{"series":"%s","volumes":%s,"bytes_alone":%s,"bytes_key8":%s,"bytes_one_key":%s,"encode_s_alone":%s,"encode_s_key8":%s,"decode_s_alone":%s,"decode_s_key8":%s,"bit_exact":%s}\n' \
    "$name" "$volumes" "$b1" "$b8" "$b256" "$e1" "$e8" "$d1" "$d8" "$exact" >> "$JSONL"
  unset enc dec
done
echo "wrote $OUT" >&2
