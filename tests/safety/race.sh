#!/usr/bin/env bash
# Racing writers: a command creating a new output (no --force) while another
# program creates the same file must not replace it. For each writing
# command, the output appears (written by this script) once the command's
# temporary exists: the command must exit non-zero with one line naming the
# output, the other program's file must be byte-identical, and no temporary
# may be left. A command that finished before its temporary was seen, or
# renamed its output before the other file appeared, is tried again, and
# skipped, not failed, the third time (the race was not staged).
#
#   bash tests/safety/race.sh BUILD_DIR
#
# Inputs are made here (vdb_tool); ../shared/data is not needed.
set -u
source "$(dirname "$0")/common.sh"
safety_init "${1:-}" race

if ! command -v vdb_tool > /dev/null; then
    echo "SKIP: vdb_tool not installed"
    exit 77
fi
IN=$WORK/in
OUT=$WORK/out
mkdir -p "$IN" "$OUT"
vdb_tool -quiet -sphere d=400 r=1.0 w=3 -write "$IN/big.vdb" > /dev/null 2>&1
"$VDBDAG" encode "$IN/big.vdb" -o "$IN/big.ssvdag" -q > /dev/null 2>&1
if [ ! -s "$IN/big.ssvdag" ]; then
    echo "FAIL: could not make the inputs"
    exit 1
fi

# command | input | output extension | options
CASES=(
    "encode|big.vdb|ssvdag|"
    "decode|big.ssvdag|vdb|"
    "export|big.ssvdag|vtu|"
    "render|big.ssvdag|png|--width 1200 --height 1200 -q"
)
for c in "${CASES[@]}"; do
    IFS='|' read -r cmd input ext options <<< "$c"
    name="race: $cmd -> new .$ext"
    out=$OUT/new.$ext
    for attempt in 1 2 3; do  # a race not staged (see below) is tried again
        rm -rf "${OUT:?}"/*
        # shellcheck disable=SC2086  # options split into words on purpose
        "$VDBDAG" "$cmd" "$IN/$input" -o "$out" $options > /dev/null 2> "$WORK/err" &
        pid=$!
        # Stage the race where it hurts: once the command's temporary exists
        # (after its checks, before its rename), the other file appears.
        staged=0
        for _ in $(seq 1 5000); do
            if ls -A "$OUT" | grep -q "^\.new\.$ext\.tmp"; then staged=1; break; fi
            kill -0 "$pid" 2> /dev/null || break
            sleep 0.002
        done
        # The other program creates its file at once, complete, and without
        # replacing one (a link fails where the name exists): where the command
        # renamed its output first, it won the race fairly and exit 0 is right.
        echo "the other program's file" > "$WORK/other"
        ln "$WORK/other" "$out" 2> /dev/null
        appeared=$?
        theirs=$(sha "$WORK/other")
        wait "$pid"
        rc=$?
        unstaged=0
        [ "$rc" -eq 0 ] && { [ "$staged" -eq 0 ] || [ "$appeared" -ne 0 ]; } && unstaged=1
        [ "$unstaged" -eq 0 ] && break
    done
    if [ "$unstaged" -eq 1 ]; then
        skip_case "$name" "three times the command finished before the other file could appear"
        continue
    fi
    why=""
    [ "$rc" -eq 0 ] && why="exit 0"
    [ "$(sha "$out")" != "$theirs" ] && why="$why; the other program's file was replaced"
    [ "$(names "$OUT")" != "new.$ext" ] && why="$why; the folder holds $(names "$OUT" | tr '\n' ' ')"
    if [ "$rc" -ne 0 ] && { ! one_error_line "$WORK/err" || ! grep -q -- "$out" "$WORK/err"; }; then
        why="$why; stderr is not one 'vdbdag: ' line naming the output: $(flat "$WORK/err")"
    fi
    if [ -z "$why" ]; then
        pass "$name (exit $rc: $(flat "$WORK/err"))"
    else
        fail "$name" "${why#; }"
    fi
done

summary
