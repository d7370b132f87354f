#!/usr/bin/env bash
# The reader library as a user gets it: `cmake --install` into a temporary
# prefix, then a separate project (examples/) configured against it with
# CMAKE_PREFIX_PATH and built, and the same example built a second time from
# pkg-config's flags alone. The installed libvdbdag.so may depend on the C++
# runtime, zstd and xxHash only. Then the consumer's point lookups are
# compared, line for line, with OpenVDB's accessor (vdbdag_vdb_probe values)
# on random active voxels and random points around them: the generated
# samples (level sets, a fog with tiles, vec3s and bool grids) and, when
# ../shared/data is present, the bunny level set (10^5 coordinates).
#   usage: check_install.sh BUILD_DIR
set -euo pipefail
BUILD=$(cd "$1" && pwd)
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$BUILD" --prefix "$WORK/prefix" > "$WORK/install.log" || { cat "$WORK/install.log"; fail "cmake --install"; }
LIBDIR=$(dirname "$(find "$WORK/prefix" -name 'libvdbdag.so' | head -1)")
[ -f "$WORK/prefix/include/vdbdag/vdbdag.h" ] || fail "no include/vdbdag/vdbdag.h in the prefix"
[ -n "$LIBDIR" ] || fail "no libvdbdag.so in the prefix"

# Dependencies of the installed library: nothing but libc, libm, the C++
# runtime, zstd and xxHash.
deps=$(readelf -d "$LIBDIR/libvdbdag.so" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | sort)
for d in $deps; do
    case "$d" in
        libc.so.*|libm.so.*|libstdc++.so.*|libgcc_s.so.*|ld-linux*|libzstd.so.*|libxxhash.so.*) ;;
        *) fail "libvdbdag.so needs $d (only the C++ runtime, zstd and xxHash are allowed)";;
    esac
done
echo "libvdbdag.so needs: $(echo $deps)"

# The ParaView plugin, when this build made one: under ParaView's plugin
# layout, finding the prefix's libvdbdag.so (not the build tree's).
if [ -n "$(find "$BUILD/paraview/lib" -name VdbdagReader.so 2>/dev/null | head -1)" ]; then
    plugin=$(find "$WORK/prefix" -path '*/paraview-*/plugins/VdbdagReader/VdbdagReader.so' | head -1)
    [ -n "$plugin" ] || fail "the ParaView plugin is not installed under LIBDIR/paraview-X.Y/plugins/VdbdagReader/"
    found=$(ldd "$plugin" | sed -n 's/.*libvdbdag\.so[^ ]* => \([^ ]*\).*/\1/p')
    [ "$(realpath "$found")" = "$(realpath "$LIBDIR/libvdbdag.so")" ] || fail "the installed plugin finds libvdbdag at '$found', not in the prefix"
    echo "ParaView plugin installed: ${plugin#$WORK/prefix/}"
fi

# 1. CMake: find_package(vdbdag CONFIG) with CMAKE_PREFIX_PATH.
cmake -S "$ROOT/examples" -B "$WORK/cmake-build" -G Ninja -DCMAKE_PREFIX_PATH="$WORK/prefix" -DCMAKE_BUILD_TYPE=Release > "$WORK/configure.log" 2>&1 ||
    { cat "$WORK/configure.log"; fail "configuring examples/ against the installed package"; }
cmake --build "$WORK/cmake-build" > "$WORK/build.log" 2>&1 || { cat "$WORK/build.log"; fail "building examples/"; }
LOOKUP="$WORK/cmake-build/vdbdag_lookup"
# 2. pkg-config, with a plain compiler call.
PKG_CONFIG_PATH="$LIBDIR/pkgconfig" pkg-config --exists vdbdag || fail "pkg-config does not find vdbdag.pc"
# shellcheck disable=SC2046
g++ -std=c++17 -O2 "$ROOT/examples/lookup.cpp" -o "$WORK/lookup-pc" $(PKG_CONFIG_PATH="$LIBDIR/pkgconfig" pkg-config --cflags --libs vdbdag) \
    -Wl,-rpath,"$LIBDIR" || fail "building examples/lookup.cpp with pkg-config's flags"

init=$(find "$WORK/prefix" -path '*dist-packages/vdbdag/__init__.py' | head -1)
PYDIR=""
[ -n "$init" ] && PYDIR=$(dirname "$(dirname "$init")")
if [ -z "$PYDIR" ]; then echo "note: no Python module in the prefix (pybind11 not found at configure time)"; fi
# The interpreter the module was built for (cmake/PythonModule.cmake).
PYTHON=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$BUILD/CMakeCache.txt" | head -1)
PYTHON=${PYTHON:-python3}
VDBDAG="$BUILD/vdbdag"
PROBE="$BUILD/vdbdag_vdb_probe"
"$BUILD/vdbdag_make_samples" "$WORK/samples" > /dev/null

compare() {  # FILE.vdb GRID N
    local vdb=$1 grid=$2 n=$3 name
    name=$(basename "$vdb" .vdb)
    [ -f "$WORK/$name.ssvdag" ] || "$VDBDAG" encode "$vdb" -o "$WORK/$name.ssvdag" -q > /dev/null
    "$PROBE" sample "$vdb" "$grid" "$n" 7 > "$WORK/coords"
    "$PROBE" values "$vdb" "$grid" < "$WORK/coords" > "$WORK/want"
    "$LOOKUP" "$WORK/$name.ssvdag" "$grid" < "$WORK/coords" > "$WORK/got"
    "$WORK/lookup-pc" "$WORK/$name.ssvdag" "$grid" < "$WORK/coords" > "$WORK/got-pc"
    [ "$(wc -l < "$WORK/want")" -eq "$n" ] || fail "$name/$grid: the probe answered $(wc -l < "$WORK/want") of $n lookups"
    local active
    active=$(grep -c '^1' "$WORK/want" || true)
    [ "$active" -ge $((n * 4 / 10)) ] || fail "$name/$grid: only $active of $n sampled voxels are active"
    if ! cmp -s "$WORK/want" "$WORK/got"; then
        paste -d'|' "$WORK/coords" "$WORK/want" "$WORK/got" | awk -F'|' '$2 != $3' | head -5
        fail "$name/$grid: vdbdag::Accessor differs from OpenVDB's accessor"
    fi
    cmp -s "$WORK/got" "$WORK/got-pc" || fail "$name/$grid: the pkg-config build answers differently"
    if [ -n "$PYDIR" ]; then  # the installed Python module, same coordinates, same format
        PYTHONPATH="$PYDIR" "$PYTHON" - "$WORK/$name.ssvdag" "$grid" "$WORK/coords" > "$WORK/got-py" <<'PY' || fail "$name/$grid: the installed Python module failed"
import sys, numpy as np, vdbdag
g = vdbdag.open(sys.argv[1]).grid(sys.argv[2])
ijk = np.loadtxt(sys.argv[3], dtype=np.int32, ndmin=2)
active = g.is_active(ijk)
values = None if g.value_type == "mask" else np.ascontiguousarray(g.values(ijk))
row = 0 if values is None else values.nbytes // len(ijk)
raw = b"" if values is None else values.tobytes()
out = []
for n, on in enumerate(active):
    out.append(("1 " if on else "0 ") + ("-" if values is None else raw[n * row:(n + 1) * row].hex()))
sys.stdout.write("\n".join(out) + "\n")
PY
        cmp -s "$WORK/want" "$WORK/got-py" || fail "$name/$grid: the installed Python module differs from OpenVDB's accessor"
    fi
    echo "ok $name/$grid: $n lookups ($active active) equal OpenVDB's, bit for bit (C++ via CMake and pkg-config${PYDIR:+, Python})"
}

compare "$WORK/samples/sphere_ls.vdb" sphere 20000
compare "$WORK/samples/fog_tiles.vdb" density 20000
compare "$WORK/samples/multi_grid.vdb" Cd 20000
compare "$WORK/samples/multi_grid.vdb" surface 20000
compare "$WORK/samples/far_apart.vdb" far_apart 20000
SHARED="$ROOT/../shared/data"
if [ -f "$SHARED/levelsets/bunny_d512_ls.vdb" ]; then
    grid=$("$PROBE" meta "$SHARED/levelsets/bunny_d512_ls.vdb" | "$PYTHON" -c 'import json,sys; print(json.load(sys.stdin)["grids"][0]["name"])')
    compare "$SHARED/levelsets/bunny_d512_ls.vdb" "$grid" 100000
else
    echo "skip: ../shared/data absent, the bunny check did not run"
fi
"$LOOKUP" "$WORK/multi_grid.ssvdag" > "$WORK/list"
grep -q "'Cd' vec3s" "$WORK/list" || { cat "$WORK/list"; fail "the grid listing lacks 'Cd' vec3s"; }
if "$LOOKUP" "$WORK/missing.ssvdag" > /dev/null 2> "$WORK/err"; then fail "a missing file was opened"; fi
grep -q "missing.ssvdag" "$WORK/err" || fail "the error does not name the file: $(cat "$WORK/err")"
echo "install check passed"
