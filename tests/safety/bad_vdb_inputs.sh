#!/usr/bin/env bash
# Bad .vdb input: fog_torus.vdb truncated at every length 0..200 and at N
# random lengths, and N single-bit flips of it (fixed seed), each given to
# `vdbdag encode F -o out.ssvdag` under a 4 GB address-space cap and a time
# limit. Each run must end either
#   * non-zero, with exactly one stderr line starting "vdbdag: " (never a
#     signal, exit 134/139, "terminate called" or a timeout) and no output
#     or temporary left, or
#   * exit 0 with an .ssvdag whose decode is what OpenVDB itself reads from
#     F (vdbdag_vdb_probe same); if OpenVDB's own read of F fails or crashes
#     (vdbdag_vdb_probe read, in a child), the tool must have failed.
# A truncated file is never accepted as an empty volume ("0 grid(s)"). And
# `encode points.vdb --skip-unsupported` (no convertible grid) fails and
# writes nothing.
#
#   bash tests/safety/bad_vdb_inputs.sh BUILD_DIR
#   VDBDAG_FUZZ_CASES=N         random truncations and bit flips, N each (default 1000)
#   VDBDAG_FUZZ_TRUNCATIONS=N / VDBDAG_FUZZ_FLIPS=N   set them apart
#   VDBDAG_FUZZ_SEED=S          (default 20240611)   VDBDAG_FUZZ_JOBS=J (default 2)
#   VDBDAG_FUZZ_TIMEOUT=S       per run (default 60)
#   VDBDAG_FUZZ_ENCODE_OPTIONS="..."  extra encode options, e.g. "--memory-limit 1M"
#                               (the region-by-region reader)
set -u
source "$(dirname "$0")/common.sh"
safety_init "${1:-}" bad_vdb_inputs

SRC=$SHARED/vdb/fog_torus.vdb
POINTS=$SHARED/vdb/points.vdb
if [ ! -f "$SRC" ]; then
    echo "SKIP: $SRC not present (../shared/data absent)"
    exit 77
fi
N=${VDBDAG_FUZZ_CASES:-1000}
TRUNCS=${VDBDAG_FUZZ_TRUNCATIONS:-$N}
FLIPS=${VDBDAG_FUZZ_FLIPS:-$N}
SEED=${VDBDAG_FUZZ_SEED:-20240611}
JOBS=${VDBDAG_FUZZ_JOBS:-2}
LIMIT_S=${VDBDAG_FUZZ_TIMEOUT:-60}
MEM_KB=4194304
# OpenVDB's own read (the reference) gets 1 GB: a valid 30 KB file never needs
# it, while a truncated header can make OpenVDB zero 3 GB before it fails,
# seconds of page faults per case. Past the cap its read fails, so the tool
# must have refused that file too.
REF_MEM_KB=1048576
SIZE=$(stat -c %s "$SRC")
RES=$WORK/results
mkdir -p "$RES"

# The case list, drawn up front from one seeded generator (bash's RANDOM).
CASES=$WORK/cases
RANDOM=$SEED
{
    for ((l = 0; l <= 200 && l < SIZE; ++l)); do echo "trunc $l"; done
    for ((i = 0; i < TRUNCS; ++i)); do echo "trunc $(((RANDOM * 32768 + RANDOM) % SIZE))"; done
    for ((i = 0; i < FLIPS; ++i)); do echo "flip $(((RANDOM * 32768 + RANDOM) % SIZE)) $((RANDOM % 8))"; done
} > "$CASES"
TOTAL=$(wc -l < "$CASES")
echo "---- $TOTAL cases on $SRC ($SIZE bytes): lengths 0..200, $TRUNCS random truncations, $FLIPS bit flips; seed $SEED, $JOBS jobs, ${LIMIT_S} s and ${MEM_KB} KB per run${VDBDAG_FUZZ_ENCODE_OPTIONS:+; encode $VDBDAG_FUZZ_ENCODE_OPTIONS}"

capped() {  # capped OUT ERR CMD...: runs CMD under the memory cap (MEM_KB, or CAP_KB) and time limit
    local out=$1 err=$2
    shift 2
    (ulimit -v "${CAP_KB:-$MEM_KB}" && exec timeout -k 5 "$LIMIT_S" "$@") > "$out" 2> "$err"
}

# One case; writes "PASS|desc|" or "FAIL|desc|why|category" to $RES/ID.
run_case() {
    local id=$1 kind=$2 a=$3 b=${4:-}
    local d=$WORK/c$id desc why="" cat="" rc refrc
    mkdir -p "$d/out"
    local f=$d/in.vdb
    if [ "$kind" = trunc ]; then
        desc="truncated at $a of $SIZE"
        head -c "$a" "$SRC" > "$f"
    else
        desc="bit $b of byte $a flipped"
        cp "$SRC" "$f"
        local byte
        byte=$(od -An -tu1 -j "$a" -N1 "$f" | tr -d ' ')
        printf "\\$(printf %03o $((byte ^ (1 << b))))" | dd of="$f" bs=1 seek="$a" conv=notrunc status=none
    fi
    CAP_KB=$REF_MEM_KB capped "$d/ref.out" "$d/ref.err" "$PROBE" read "$f"
    refrc=$?
    # shellcheck disable=SC2086  # the options split into words on purpose
    capped "$d/tool.out" "$d/tool.err" "$VDBDAG" encode "$f" -o "$d/out/out.ssvdag" ${VDBDAG_FUZZ_ENCODE_OPTIONS:-}
    rc=$?
    if [ "$rc" -eq 124 ] || [ "$rc" -eq 137 ]; then
        why="timed out after $LIMIT_S s (exit $rc)"; cat="timeout"
    elif [ "$rc" -ge 128 ]; then
        why="killed by signal $((rc - 128)) (exit $rc): $(flat "$d/tool.err")"; cat="signal $((rc - 128))"
    elif grep -q "terminate called" "$d/tool.err"; then
        why="terminate called: $(flat "$d/tool.err")"; cat="terminate called"
    elif [ "$rc" -ne 0 ]; then
        if ! one_error_line "$d/tool.err"; then
            why="exit $rc, stderr is not one 'vdbdag: ' line: $(flat "$d/tool.err")"; cat="error message not one line"
        elif [ -n "$(names "$d/out")" ]; then
            why="exit $rc but left: $(names "$d/out" | tr '\n' ' ')"; cat="output left after failure"
        fi
    else
        if [ "$kind" = trunc ] && grep -q ' 0 grid(s)' "$d/tool.out"; then
            why="a truncated file accepted as an empty volume: $(flat "$d/tool.out")"; cat="truncated accepted as 0 grids"
        elif [ "$refrc" -ne 0 ]; then
            why="accepted a file OpenVDB cannot read (probe exit $refrc: $(flat "$d/ref.out") $(flat "$d/ref.err"))"; cat="accepted unreadable file"
        elif [ "$(names "$d/out")" != "out.ssvdag" ]; then
            why="exit 0, output folder holds: $(names "$d/out" | tr '\n' ' ')"; cat="bad output folder"
        else
            capped "$d/dec.out" "$d/dec.err" "$VDBDAG" decode "$d/out/out.ssvdag" -o "$d/dec.vdb"
            local drc=$?
            if [ "$drc" -ne 0 ]; then
                why="exit 0 but its output does not decode (exit $drc: $(flat "$d/dec.err"))"; cat="output does not decode"
            else
                capped "$d/same.out" "$d/same.err" "$PROBE" same "$f" "$d/dec.vdb"
                if [ $? -ne 0 ]; then
                    why="exit 0 but the decode differs from what OpenVDB reads: $(grep -v '^note:' "$d/same.out" | head -3 | tr '\n' ' ' | cut -c1-300)"
                    cat="decode differs from OpenVDB's read"
                fi
            fi
        fi
    fi
    if [ -z "$why" ]; then
        echo "PASS|$desc (encode exit $rc, OpenVDB read exit $refrc)|" > "$RES/$id"
    else
        echo "FAIL|$desc|$why|$cat" > "$RES/$id"
    fi
    rm -rf "$d"
}

id=0
running=0
while read -r kind a b; do
    id=$((id + 1))
    run_case "$(printf %05d $id)" "$kind" "$a" "$b" &
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait -n
        running=$((running - 1))
    fi
done < "$CASES"
wait

declare -A CATS=()
for r in "$RES"/*; do
    IFS='|' read -r status desc why cat < "$r"
    if [ "$status" = PASS ]; then
        pass "$desc"
    else
        fail "$desc" "$why"
        CATS[$cat]=$((${CATS[$cat]:-0} + 1))
    fi
done

# No convertible grid: fail, write nothing.
if [ -f "$POINTS" ]; then
    d=$WORK/points
    mkdir -p "$d/out"
    capped "$d/tool.out" "$d/tool.err" "$VDBDAG" encode "$POINTS" --skip-unsupported -o "$d/out/out.ssvdag"
    rc=$?
    if [ "$rc" -eq 0 ] || [ "$rc" -ge 124 ]; then
        fail "points.vdb --skip-unsupported (no convertible grid)" "exit $rc: $(flat "$d/tool.out") $(flat "$d/tool.err"); folder: $(names "$d/out" | tr '\n' ' ')"
        CATS["no convertible grid accepted"]=1
    elif [ -n "$(names "$d/out")" ]; then
        fail "points.vdb --skip-unsupported (no convertible grid)" "exit $rc but the folder holds: $(names "$d/out" | tr '\n' ' ')"
    elif ! tail -n 1 "$d/tool.err" | grep -q '^vdbdag: '; then
        fail "points.vdb --skip-unsupported (no convertible grid)" "exit $rc, the last stderr line is not a 'vdbdag: ' error: $(flat "$d/tool.err")"
    else
        pass "points.vdb --skip-unsupported (no convertible grid): exit $rc, $(flat "$d/tool.err")"
    fi
else
    skip_case "points.vdb --skip-unsupported" "$POINTS not present"
fi

echo "---- $TOTAL fuzz cases run"
for k in "${!CATS[@]}"; do echo "---- failures: ${CATS[$k]} x $k"; done
summary
