#!/usr/bin/env bash
# A change against the build before it, as the closing notes quote it:
# another checkout's build folder (BASE, e.g. a `git worktree` of the
# commit before, built with scripts/setup.sh) beside this one (build/).
#
#   scripts/compare_builds.sh BASE bytes
#       every shared input (../shared/data: level sets, .vdb files, dense
#       scans, NIfTI, the PET and adi_brain series 1) and a few option sets
#       (--memory-limit 256M, --abs-error) encoded by both: the files must
#       be the same bytes (or both refused). Exit 1 when any differ.
#   scripts/compare_builds.sh BASE time N encode|decode INPUT [OPTIONS...]
#       N rounds of the command by each build, the order flipped every
#       round (the second of a pair ran about 2 % faster on this machine
#       in an A/A run, which a fixed order would count for the change);
#       medians and their ratio. decode takes an .ssvdag and writes a .vdb.
# --json (last argument): one JSON object instead of the text line.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n '2,16s/^# \{0,1\}//p' "$0" >&2; exit 2; }
BASE=$1 MODE=$2
shift 2
JSON=0
if [ $# -gt 0 ] && [ "${!#}" = "--json" ]; then JSON=1; set -- "${@:1:$#-1}"; fi
OLD=$BASE/vdbdag NEW=build/vdbdag
for b in "$OLD" "$NEW"; do [ -x "$b" ] || { echo "compare_builds: $b is not built" >&2; exit 2; }; done
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
DATA=${VDBDAG_SHARED_DATA:-../shared/data}

if [ "$MODE" = bytes ]; then
  runs=0 differ=0 names=()
  one() {  # label, encode arguments
    local label=$1; shift
    local r1=0 r2=0
    "$OLD" encode "$@" -o "$TMP/a.ssvdag" --force -q >/dev/null 2>&1 || r1=$?
    "$NEW" encode "$@" -o "$TMP/b.ssvdag" --force -q >/dev/null 2>&1 || r2=$?
    runs=$((runs + 1))
    if [ $r1 -ne $r2 ] || { [ $r1 -eq 0 ] && ! cmp -s "$TMP/a.ssvdag" "$TMP/b.ssvdag"; }; then
      differ=$((differ + 1)); names+=("$label")
      [ $JSON = 1 ] || echo "differ: $label (exit $r1 / $r2)"
    fi
    rm -f "$TMP/a.ssvdag" "$TMP/b.ssvdag"
  }
  shopt -s nullglob
  for f in "$DATA"/levelsets/*.vdb "$DATA"/vdb/*.vdb "$DATA"/dense/*.nhdr "$DATA"/dense/*.mhd "$DATA"/dense/*.nrrd "$DATA"/medical/nifti/*.nii.gz; do
    one "$(basename "$f")" "$f"
  done
  [ -e "$DATA/medical/dicom/rsna_2/PET" ] && one PET "$DATA/medical/dicom/rsna_2/PET"
  [ -e "$DATA/medical/dicom/adi_brain" ] && one "adi_brain series 1" "$DATA/medical/dicom/adi_brain" --series 1
  [ -e "$DATA/levelsets/bunny_d512_ls.vdb" ] && one "bunny --memory-limit 256M" "$DATA/levelsets/bunny_d512_ls.vdb" --memory-limit 256M
  [ -e "$DATA/dense/cthead_256x256x99_uint8.nhdr" ] && one "cthead --abs-error 2" "$DATA/dense/cthead_256x256x99_uint8.nhdr" --abs-error 2
  [ -e "$DATA/vdb/smoke1.vdb" ] && one "smoke1 --abs-error 0.001" "$DATA/vdb/smoke1.vdb" --abs-error 0.001
  [ $runs -gt 0 ] || { echo "compare_builds: no input in $DATA" >&2; exit 2; }
  if [ $JSON = 1 ]; then
    /usr/bin/python3 -c 'import json,sys; print(json.dumps({"runs": int(sys.argv[1]), "differ": sys.argv[2:]}))' "$runs" "${names[@]+"${names[@]}"}"
  else
    echo "$runs runs, $differ differ"
  fi
  [ $differ -eq 0 ]
  exit
fi

[ "$MODE" = time ] && [ $# -ge 3 ] || { sed -n '2,16s/^# \{0,1\}//p' "$0" >&2; exit 2; }
N=$1 CMD=$2 INPUT=$3
shift 3
case "$CMD" in encode) OUT=$TMP/out.ssvdag ;; decode) OUT=$TMP/out.vdb ;; *) echo "compare_builds: time encode or decode, not $CMD" >&2; exit 2 ;; esac
one() {  # label, binary, options
  local label=$1 bin=$2 s e
  shift 2
  s=$(date +%s%N)
  "$bin" "$CMD" "$INPUT" "$@" -o "$OUT" --force -q >/dev/null 2>&1 || { echo "compare_builds: $bin $CMD $INPUT failed" >&2; exit 1; }
  e=$(date +%s%N)
  echo "$label $(( (e - s) / 1000000 ))"
}
for i in $(seq "$N"); do
  if [ $((i % 2)) = 1 ]; then one base "$OLD" "$@"; one new "$NEW" "$@"; else one new "$NEW" "$@"; one base "$OLD" "$@"; fi
done > "$TMP/times"
/usr/bin/python3 - "$TMP/times" "$JSON" "$CMD" "$INPUT" <<'PY'
import json, statistics, sys
times = {}
for line in open(sys.argv[1]):
    k, v = line.split()
    times.setdefault(k, []).append(int(v))
base, new = statistics.median(times["base"]), statistics.median(times["new"])
r = {"command": sys.argv[3], "input": sys.argv[4], "rounds": len(times["new"]), "base_ms": base, "new_ms": new, "ratio": round(new / base, 3),
     "base_runs_ms": times["base"], "new_runs_ms": times["new"]}
print(json.dumps(r) if sys.argv[2] == "1" else "%s %s: base %g ms, new %g ms (medians of %d), ratio %.3f" % (r["command"], r["input"], base, new, r["rounds"], r["ratio"]))
PY
