# Shared helpers of the safety scripts (sourced, not run).
#   safety_init BUILD_DIR NAME   sets VDBDAG, PROBE, PHANTOM, SHARED, WORK (a fresh mktemp -d)
#   pass NAME / fail NAME WHY / skip_case NAME WHY, summary (exits 1 on any failure)
#   listing DIR                  every entry: name, type, size, inode, mode, link target, sha256
#   one_error_line FILE          exactly one line, starting "vdbdag: "
#   force_flag CMD               "--force" if `vdbdag CMD --help` offers it, else ""
#   valid_output FILE            the output is what its extension says (independent checks)
# shellcheck shell=bash

SAFETY_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
SAFETY_ROOT=$(cd "$SAFETY_DIR/../.." && pwd)
PASSED=0
FAILED=0
SKIPPED=0
FAILURES=()
SAFETY_MOUNTS=()

safety_cleanup() {
    local m
    for m in "${SAFETY_MOUNTS[@]}"; do
        mountpoint -q "$m" 2>/dev/null && umount "$m" 2>/dev/null
    done
    [ -n "${WORK:-}" ] && [ -d "$WORK" ] && chmod -R u+w "$WORK" 2>/dev/null
    [ -n "${WORK:-}" ] && [ -d "$WORK" ] && rm -rf "$WORK"
}

safety_init() {
    local build=${1:-}
    SAFETY_NAME=$2
    if [ -z "$build" ] || [ ! -d "$build" ]; then
        echo "usage: $0 BUILD_DIR" >&2
        exit 2
    fi
    BUILD=$(cd "$build" && pwd)
    VDBDAG=$BUILD/vdbdag
    PROBE=$BUILD/vdbdag_vdb_probe
    PHANTOM=$BUILD/vdbdag_make_ct_phantom
    local b
    for b in "$VDBDAG" "$PROBE"; do
        if [ ! -x "$b" ]; then
            echo "FAIL: $b not built (cmake --build $BUILD --target vdbdag vdbdag_vdb_probe)"
            exit 1
        fi
    done
    SHARED=${VDBDAG_SHARED_DATA:-$SAFETY_ROOT/../shared/data}
    WORK=$(mktemp -d "${TMPDIR:-/tmp}/vdbdag_${SAFETY_NAME}_XXXXXX")
    trap safety_cleanup EXIT
    # Private copies: a rebuild during the run must not swap the binaries.
    mkdir -p "$WORK/bin"
    cp "$VDBDAG" "$PROBE" "$WORK/bin/"
    # The image writers live beside the binary (vdb_bridge/image_module), loaded by render.
    [ -f "$BUILD/libvdbdag_images.so" ] && cp "$BUILD/libvdbdag_images.so" "$WORK/bin/"
    # ... and so does vdbdag-full, which vdbdag runs for VTK output and DICOM input (src/util/FullCommand.h).
    [ -f "$(dirname "$VDBDAG")/vdbdag-full" ] && cp "$(dirname "$VDBDAG")/vdbdag-full" "$WORK/bin/"
    VDBDAG=$WORK/bin/vdbdag
    PROBE=$WORK/bin/vdbdag_vdb_probe
    if [ -x "$PHANTOM" ]; then
        cp "$PHANTOM" "$WORK/bin/"
        PHANTOM=$WORK/bin/vdbdag_make_ct_phantom
    fi
    trap 'exit 130' INT TERM HUP
    SAFETY_START=$SECONDS
}

pass() {
    PASSED=$((PASSED + 1))
    echo "PASS: $1"
}

fail() {
    FAILED=$((FAILED + 1))
    FAILURES+=("$1: $2")
    echo "FAIL: $1: $2"
}

skip_case() {
    SKIPPED=$((SKIPPED + 1))
    echo "SKIP: $1: $2"
}

summary() {
    echo "---- $SAFETY_NAME: $PASSED passed, $FAILED failed, $SKIPPED skipped in $((SECONDS - SAFETY_START)) s"
    if [ "$FAILED" -gt 0 ]; then
        echo "---- failures:"
        local f
        for f in "${FAILURES[@]}"; do echo "  $f"; done
        exit 1
    fi
    exit 0
}

# One line per entry (hidden ones too): name|type|size|inode|mode|link|sha256.
listing() {
    local dir=$1 line name
    (cd "$dir" && find . -mindepth 1 -printf '%P|%y|%s|%i|%m|%l\n' | LC_ALL=C sort) | while IFS= read -r line; do
        name=${line%%|*}
        if [ -f "$dir/$name" ] && [ ! -L "$dir/$name" ]; then
            echo "$line|$(sha256sum < "$dir/$name" | cut -c1-64)"
        else
            echo "$line|-"
        fi
    done
}

# Names only (for "no temporary left").
names() { (cd "$1" && find . -mindepth 1 -printf '%P\n' | LC_ALL=C sort); }

sha() { sha256sum < "$1" | cut -c1-64; }

one_error_line() {
    local f=$1
    [ "$(wc -l < "$f")" -eq 1 ] && [ "$(head -c 8 "$f")" = "vdbdag: " ]
}

# Shows stderr on one line for a FAIL message.
flat() { tr '\n' ' ' < "$1" | cut -c1-300; }

force_flag() {
    if "$VDBDAG" "$1" --help 2>&1 | grep -q -- '--force'; then echo "--force"; else echo ""; fi
}

# Independent validity checks of a finished output, by extension.
valid_output() {
    local f=$1
    [ -f "$f" ] && [ ! -L "$f" ] || return 1
    case "$f" in
        *.vdb) "$PROBE" read "$f" > /dev/null 2>&1 ;;
        *.ssvdag) "$VDBDAG" info "$f" > /dev/null 2>&1 ;;
        *.vtu | *.vti | *.vtm) head -c 4096 "$f" | grep -q '<VTKFile' && tail -c 64 "$f" | grep -q '</VTKFile>' ;;
        *.png) [ "$(head -c 8 "$f" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ;;
        *) return 1 ;;
    esac
}
