#!/usr/bin/env bash
# Makes the ParaView SDK that the plugin (paraview/) is built against and
# prints its ParaView_DIR; prints nothing and exits 1 without paraview-dev.
#
# Debian's paraview-dev CMake package names files that only python3-paraview
# holds (pvpython's modules, ParaView's wrapping hierarchy), and
# python3-paraview cannot be installed beside python3-vtk9, which
# libvtk9-dev needs (../shared/TOOLCHAIN.md). So python3-paraview is
# unpacked, not installed, into ${VDBDAG_PV_DIR:-~/.cache/vdbdag/pvpython}
# (as scripts/paraview_check.sh does), and PV_DIR/prefix is made a view of
# /usr: links to /usr's folders, except lib/python3 and the hierarchy files,
# which come from the unpacked package, and the CMake package itself, which
# is copied (CMake resolves a linked package back to /usr and would look for
# the files there). Safe to run repeatedly; nothing under /usr changes.
set -euo pipefail
config=$(dpkg -L paraview-dev 2>/dev/null | grep '/cmake/paraview-[0-9.]*/paraview-config.cmake$' | head -1) || true
[ -n "$config" ] || exit 1
package=$(dirname "$config")              # /usr/lib/MULTIARCH/cmake/paraview-5.11
libdir=$(dirname "$(dirname "$package")")  # /usr/lib/MULTIARCH
multiarch=$(basename "$libdir")
PV_DIR=${VDBDAG_PV_DIR:-$HOME/.cache/vdbdag/pvpython}
prefix=$PV_DIR/prefix
if [ ! -x "$PV_DIR/usr/bin/pvpython" ]; then
  echo "paraview_sdk: unpacking python3-paraview into $PV_DIR" >&2
  mkdir -p "$PV_DIR"
  tmp=$(mktemp -d)
  chmod 755 "$tmp"  # apt downloads as _apt
  (cd "$tmp" && apt-get download -qq python3-paraview >/dev/null 2>&1 && dpkg-deb -x python3-paraview_*.deb "$PV_DIR")
  rm -rf "$tmp"
fi
if [ ! -f "$prefix/lib/$multiarch/cmake/$(basename "$package")/paraview-config.cmake" ] || [ "$config" -nt "$prefix/.made" ]; then
  rm -rf "$prefix"
  mkdir -p "$prefix/lib/$multiarch/cmake" "$prefix/lib/$multiarch/vtk/hierarchy" "$prefix/bin"
  ln -s /usr/include "$prefix/include"
  ln -s /usr/share "$prefix/share"
  ln -s "$PV_DIR/usr/lib/python3" "$prefix/lib/python3"
  for e in "$libdir"/*; do
    case "$(basename "$e")" in cmake|vtk) ;; *) ln -s "$e" "$prefix/lib/$multiarch/" ;; esac
  done
  for e in "$libdir"/cmake/*; do
    [ "$e" = "$package" ] || ln -s "$e" "$prefix/lib/$multiarch/cmake/"
  done
  cp -r "$package" "$prefix/lib/$multiarch/cmake/"
  for h in "$libdir"/vtk/hierarchy/* "$PV_DIR/usr/lib/$multiarch"/vtk/hierarchy/*; do
    [ -e "$h" ] && ln -s "$h" "$prefix/lib/$multiarch/vtk/hierarchy/"
  done
  for f in /usr/bin/paraview /usr/bin/pv* /usr/bin/*-pv[0-9]*; do
    [ -e "$f" ] && ln -sf "$f" "$prefix/bin/"
  done
  ln -sf "$PV_DIR/usr/bin/pvpython" "$prefix/bin/pvpython"
  touch "$prefix/.made"
fi
echo "$prefix/lib/$multiarch/cmake/$(basename "$package")"
