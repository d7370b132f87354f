#!/usr/bin/env bash
# Signals: SIGINT, SIGTERM and SIGHUP sent at 10%, 50% and 90% of an
# undisturbed run of `encode`, `decode`, `import`, `export` and `render`
# must leave no temporary in the output folder and the previous output
# byte-identical (same bytes, same inode), or, when the command finished
# anyway (exit 0), a valid new output. After a SIGKILL during the write, the
# next run of the same command to the same output must leave no temporary
# behind (the dead process's leftover is removed).
#
#   bash tests/safety/signals.sh BUILD_DIR
#   VDBDAG_SIGNAL_SCALE=2 ...   bigger inputs (longer runs)
#
# Inputs are made here (vdb_tool, vdbdag_make_ct_phantom).
set -u
source "$(dirname "$0")/common.sh"
safety_init "${1:-}" signals

if ! command -v vdb_tool > /dev/null; then
    echo "SKIP: vdb_tool not installed"
    exit 77
fi
if [ ! -x "$PHANTOM" ]; then
    echo "FAIL: $PHANTOM not built"
    exit 1
fi
# Background jobs of a non-interactive shell ignore SIGINT: env resets it.
RUN=(env --default-signal=INT,TERM,HUP)
if ! "${RUN[@]}" true 2> /dev/null; then
    echo "SKIP: env --default-signal (coreutils >= 8.31) is needed"
    exit 77
fi

SCALE=${VDBDAG_SIGNAL_SCALE:-1}
IN=$WORK/in
mkdir -p "$IN"
vdb_tool -quiet -sphere d=$((576 * SCALE)) r=1.0 w=3 -write "$IN/ball.vdb" > /dev/null 2>&1
vdb_tool -quiet -sphere d=$((256 * SCALE)) r=1.0 w=3 -write "$IN/ball_export.vdb" > /dev/null 2>&1
"$PHANTOM" "$IN/scan" --dims $((256 * SCALE)) $((256 * SCALE)) $((320 * SCALE)) > /dev/null
"$VDBDAG" encode "$IN/ball.vdb" -o "$IN/ball.ssvdag" > /dev/null 2> "$WORK/err"
for f in ball.vdb ball_export.vdb scan.nhdr ball.ssvdag; do
    if [ ! -s "$IN/$f" ]; then
        echo "FAIL: could not make the input $f: $(flat "$WORK/err")"
        exit 1
    fi
done

# name | output extension | arguments before -o
CASES=(
    "encode|ssvdag|encode $IN/ball.vdb"
    "decode|vdb|decode $IN/ball.ssvdag"
    "import|vdb|import $IN/scan.nhdr"
    "export|vtu|export $IN/ball_export.vdb"
    "render|png|render $IN/ball.ssvdag --backend cpu --width 1600 --height 1200 --shadows"
)
SENTINEL="previous output: must survive"
printf '%s\n' "$SENTINEL" > "$WORK/sentinel"
is_sentinel() { cmp -s "$1" "$WORK/sentinel"; }
WATCHDOG_S=300

now() { echo "${EPOCHREALTIME/,/.}"; }

# Starts the command in the background: sets PID.
start() {
    local out=$1
    shift
    # shellcheck disable=SC2086
    "${RUN[@]}" "$VDBDAG" "$@" -o "$out" $FORCE > "$WORK/out" 2> "$WORK/err" &
    PID=$!
    (sleep "$WATCHDOG_S" && kill -KILL "$PID" 2> /dev/null) > /dev/null 2>&1 &
    WATCH=$!
}

finish() {
    { wait "$PID"; } 2> /dev/null
    RC=$?
    kill "$WATCH" 2> /dev/null
    wait "$WATCH" 2> /dev/null
}

for c in "${CASES[@]}"; do
    IFS='|' read -r cmd ext args <<< "$c"
    read -r -a argv <<< "$args"
    FORCE=$(force_flag "$cmd")
    OUT=$WORK/out_$cmd
    mkdir -p "$OUT"

    # Two undisturbed runs: the shorter duration, and that it works at all.
    T=""
    for attempt in 1 2; do
        rm -f "$OUT/out.$ext"
        t0=$(now)
        start "$OUT/out.$ext" "${argv[@]}"
        finish
        t1=$(now)
        [ "$RC" -ne 0 ] && break
        T=$(awk -v a="$t0" -v b="$t1" -v t="$T" 'BEGIN { d = b - a; if (t != "" && t < d) d = t; printf "%.3f", d }')
    done
    if [ "$RC" -ne 0 ] || ! valid_output "$OUT/out.$ext"; then
        fail "$cmd: undisturbed run" "exit $RC, $(flat "$WORK/err")"
        continue
    fi
    echo "---- $cmd: an undisturbed run takes $T s ($(stat -c %s "$OUT/out.$ext") bytes)"
    if awk -v t="$T" 'BEGIN { exit !(t < 1.0) }'; then
        echo "note: $cmd runs under 1 s; signals land in start-up (use VDBDAG_SIGNAL_SCALE=2)"
    fi

    for sig in INT TERM HUP; do
        for frac in 0.1 0.5 0.9; do
            name="$cmd: SIG$sig at $(awk -v f="$frac" 'BEGIN { printf "%d", f * 100 }')%"
            rm -rf "${OUT:?}"/* "$OUT"/.[!.]* 2> /dev/null
            cp "$WORK/sentinel" "$OUT/out.$ext"
            before=$(listing "$OUT")
            delay=$(awk -v t="$T" -v f="$frac" 'BEGIN { printf "%.3f", t * f }')
            start "$OUT/out.$ext" "${argv[@]}"
            sleep "$delay"
            sent=yes
            kill -s "$sig" "$PID" 2> /dev/null || sent="no (already finished)"
            finish
            after=$(listing "$OUT")
            why=""
            if [ "$(names "$OUT")" != "out.$ext" ]; then
                why="; the folder holds: $(names "$OUT" | tr '\n' ' ')"
            fi
            if [ "$RC" -eq 0 ]; then
                if ! valid_output "$OUT/out.$ext"; then
                    why="$why; exit 0 but out.$ext is not a valid .$ext"
                elif is_sentinel "$OUT/out.$ext"; then
                    why="$why; exit 0 but out.$ext still holds the previous output"
                fi
            elif [ "$before" != "$after" ]; then
                # Replaced whole by a valid new output: the signal came after the commit (rename).
                if ! valid_output "$OUT/out.$ext" || is_sentinel "$OUT/out.$ext"; then
                    why="$why; exit $RC and the previous output changed: $(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | tr '\n' ' ' | cut -c1-300)"
                fi
            fi
            [ "$RC" -eq 137 ] && why="$why; killed by the watchdog after $WATCHDOG_S s"
            if [ -z "$why" ]; then
                pass "$name (signal sent: $sent, exit $RC)"
            else
                fail "$name" "${why#; } (signal sent: $sent; stderr: $(flat "$WORK/err"))"
            fi
        done
    done

    # SIGKILL during the write, then the same command again.
    name="$cmd: rerun after SIGKILL during the write"
    rm -rf "${OUT:?}"/* "$OUT"/.[!.]* 2> /dev/null
    cp "$WORK/sentinel" "$OUT/out.$ext"
    start "$OUT/out.$ext" "${argv[@]}"
    deadPid=$PID
    shopt -s dotglob nullglob
    how="simulated"
    while kill -0 "$PID" 2> /dev/null; do
        entries=("$OUT"/*)
        if [ "${#entries[@]}" -gt 1 ]; then
            kill -KILL "$PID" 2> /dev/null && how="real"
            break
        fi
        sleep 0.005
    done
    finish
    entries=("$OUT"/*)
    shopt -u dotglob nullglob
    if [ "${#entries[@]}" -le 1 ]; then
        # No temporary was caught: leave one as a dead process would.
        how="simulated"
        deadPid=$(sh -c 'echo $$')
        head -c 100000 /dev/urandom > "$OUT/.out.$ext.tmp.$deadPid.123456789"
    fi
    leftover=$(names "$OUT" | grep -v "^out.$ext\$" | tr '\n' ' ')
    start "$OUT/out.$ext" "${argv[@]}"
    finish
    if [ "$RC" -ne 0 ]; then
        fail "$name" "the rerun failed: exit $RC, $(flat "$WORK/err")"
    elif [ "$(names "$OUT")" != "out.$ext" ]; then
        fail "$name" "($how leftover of PID $deadPid: $leftover) after the rerun the folder holds: $(names "$OUT" | tr '\n' ' ')"
    elif ! valid_output "$OUT/out.$ext"; then
        fail "$name" "the rerun's output is not a valid .$ext"
    else
        pass "$name ($how leftover of PID $deadPid: $leftover removed)"
    fi
    rm -rf "$OUT"
done

summary
