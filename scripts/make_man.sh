#!/usr/bin/env bash
# Writes the vdbdag(1) man page from the built command's own --help texts
# (help2man; called by the build's `man` target): the top-level help, then a
# COMMANDS section with each command's `vdbdag help COMMAND`.
# Usage: scripts/make_man.sh BUILD/vdbdag OUT.1
set -euo pipefail
V=$1
OUT=$2
INCLUDE=$(mktemp)
trap 'rm -f "$INCLUDE"' EXIT
{
  echo "[COMMANDS]"
  for c in encode decode info verify render devices export diff import bench selftest; do
    echo ".SS $c"
    echo ".nf"
    "$V" help "$c" | sed -e 's/\\/\\\\/g' -e 's/^\./\\\&./'
    echo ".fi"
  done
  echo "[EXIT STATUS]"
  echo "0: done (diff and verify: the volumes are identical). 1: failed, with one line on stderr naming the file and the problem (verify: the round trip differs; diff: they differ; selftest: a case failed). 2: a mistake in the command line (diff: any error)."
  echo "[SEE ALSO]"
  echo "vdb_print(1), nanovdb_print(1). The file format: docs/FORMAT.md in the source tree."
} > "$INCLUDE"
help2man --no-info --no-discard-stderr --name "compress OpenVDB volumes and dense scans into symmetry-aware sparse voxel DAGs (.ssvdag) and back" \
  --include "$INCLUDE" --output "$OUT" "$V"
