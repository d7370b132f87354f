#!/usr/bin/env bash
# Full disk: `decode`, `import`, `encode`, `export` (.vtu) and `render` (.png,
# whose OpenImageIO writer does not report a failed write) writing onto a
# small tmpfs that fills up must fail non-zero, keep the previous output
# byte-identical (same inode: not replaced) and leave no temporary behind
# (the folder's listing is exactly what it was).
#
#   bash tests/safety/full_disk.sh BUILD_DIR
#
# Needs root (mount -t tmpfs); exits 77 (skipped) otherwise. Inputs are made
# here (vdb_tool, vdbdag_make_ct_phantom); ../shared/data is not needed.
set -u
source "$(dirname "$0")/common.sh"
safety_init "${1:-}" full_disk

if [ "$(id -u)" -ne 0 ]; then
    echo "SKIP: full_disk needs root for mount -t tmpfs"
    exit 77
fi
MNT=$WORK/mnt
mkdir -p "$MNT"
if ! mount -t tmpfs -o size=1m tmpfs "$MNT" 2> "$WORK/mount.err"; then
    echo "SKIP: cannot mount a tmpfs: $(flat "$WORK/mount.err")"
    exit 77
fi
umount "$MNT"
SAFETY_MOUNTS+=("$MNT")
for tool in vdb_tool fallocate; do
    if ! command -v "$tool" > /dev/null; then
        echo "SKIP: $tool not installed"
        exit 77
    fi
done
if [ ! -x "$PHANTOM" ]; then
    echo "FAIL: $PHANTOM not built"
    exit 1
fi

IN=$WORK/in
REF=$WORK/ref
mkdir -p "$IN" "$REF"
vdb_tool -quiet -sphere d=48 r=1.0 w=3 -write "$IN/small.vdb" > /dev/null 2>&1
vdb_tool -quiet -sphere d=320 r=1.0 w=3 -write "$IN/big.vdb" > /dev/null 2>&1
"$PHANTOM" "$IN/small" --dims 16 16 16 > /dev/null
"$PHANTOM" "$IN/big" --dims 160 160 160 > /dev/null
"$VDBDAG" encode "$IN/small.vdb" -o "$IN/small.ssvdag" > /dev/null 2>&1
"$VDBDAG" encode "$IN/big.vdb" -o "$IN/big.ssvdag" > /dev/null 2>&1
for f in small.vdb big.vdb small.nhdr big.nhdr small.ssvdag big.ssvdag; do
    if [ ! -s "$IN/$f" ]; then
        echo "FAIL: could not make the input $f"
        exit 1
    fi
done

# command | output extension | small input | big input [| options]
# (encode --memory-limit also writes its scratch file beside the output)
CASES=(
    "decode|vdb|small.ssvdag|big.ssvdag"
    "import|vdb|small.nhdr|big.nhdr"
    "encode|ssvdag|small.vdb|big.vdb"
    "encode|ssvdag|small.vdb|big.vdb|--memory-limit 1M"
    "export|vtu|small.vdb|big.vdb"
    "render|png|small.ssvdag|big.ssvdag|--width 1600 --height 1600 -q"
)

for c in "${CASES[@]}"; do
    IFS='|' read -r cmd ext small big options <<< "$c"
    name="full disk: $cmd${options:+ $options} -> .$ext"
    force=$(force_flag "$cmd")
    rm -rf "${REF:?}"/*
    # Undisturbed runs elsewhere: the sizes of the previous and the new output.
    # shellcheck disable=SC2086  # options split into words on purpose
    if ! "$VDBDAG" "$cmd" "$IN/$small" -o "$REF/prev.$ext" $options > /dev/null 2> "$WORK/err" ||
        ! "$VDBDAG" "$cmd" "$IN/$big" -o "$REF/new.$ext" $options > /dev/null 2> "$WORK/err"; then
        fail "$name" "an undisturbed run failed: $(flat "$WORK/err")"
        continue
    fi
    prevSize=$(stat -c %s "$REF/prev.$ext")
    newSize=$(stat -c %s "$REF/new.$ext")
    if [ "$newSize" -lt 65536 ]; then
        fail "$name" "setup: the new output is only $newSize bytes"
        continue
    fi
    # A tmpfs that holds the previous output plus half of the new one.
    sizeKb=$(((prevSize + newSize) / 1024 + 2048))
    if ! mount -t tmpfs -o "size=${sizeKb}k" tmpfs "$MNT"; then
        fail "$name" "mount failed"
        continue
    fi
    cp "$REF/prev.$ext" "$MNT/out.$ext"
    avail=$(df -B1 --output=avail "$MNT" | tail -1 | tr -d ' ')
    filler=$(((avail - newSize / 2) / 4096 * 4096))
    if [ "$filler" -gt 0 ]; then
        fallocate -l "$filler" "$MNT/filler" 2> /dev/null || head -c "$filler" /dev/zero > "$MNT/filler"
    fi
    avail=$(df -B1 --output=avail "$MNT" | tail -1 | tr -d ' ')
    if [ "$avail" -ge "$newSize" ]; then
        fail "$name" "setup: $avail bytes free, the new output ($newSize bytes) would fit"
        umount "$MNT"
        continue
    fi
    before=$(listing "$MNT")
    prevSha=$(sha "$MNT/out.$ext")
    # shellcheck disable=SC2086
    timeout -k 5 300 "$VDBDAG" "$cmd" "$IN/$big" -o "$MNT/out.$ext" $force $options > "$WORK/out" 2> "$WORK/err"
    rc=$?
    after=$(listing "$MNT")
    why=""
    if [ "$rc" -eq 0 ]; then
        why="exit 0 on a full disk ($avail bytes free for $newSize)"
    elif [ "$rc" -eq 124 ] || [ "$rc" -ge 128 ]; then
        why="exit $rc (timeout or signal)"
    fi
    if [ ! -f "$MNT/out.$ext" ]; then
        why="$why; the previous output is gone"
    elif [ "$(sha "$MNT/out.$ext")" != "$prevSha" ]; then
        why="$why; the previous output changed ($(stat -c %s "$MNT/out.$ext") bytes now, $prevSize before)"
    fi
    if [ "$before" != "$after" ]; then
        why="$why; the folder changed: $(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | tr '\n' ' ' | cut -c1-400)"
    fi
    if [ "$rc" -ne 0 ] && ! one_error_line "$WORK/err"; then
        why="$why; stderr is not one 'vdbdag: ' line: $(flat "$WORK/err")"
    elif [ "$rc" -ne 0 ] && ! grep -q -- "$MNT/" "$WORK/err"; then
        why="$why; the error names no file in $MNT: $(flat "$WORK/err")"
    fi
    if [ -z "$why" ]; then
        pass "$name (exit $rc: $(flat "$WORK/err"))"
    else
        fail "$name" "${why#; }"
    fi
    umount "$MNT"
done

summary
