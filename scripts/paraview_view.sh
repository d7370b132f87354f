#!/usr/bin/env bash
# Renders an .ssvdag or .vdb file in ParaView through the plugin built in
# ./build (scripts/paraview_view.py: a contour or a volume rendering), to
# look at. Needs the plugin (scripts/setup.sh) and xvfb (installed if missing).
#   scripts/paraview_view.sh FILE OUT.png [contour VALUE | volume] [LEVEL]
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: $0 FILE OUT.png [contour VALUE | volume] [LEVEL]" >&2; exit 2; }
plugin=$(find build/paraview/lib -name VdbdagReader.so 2>/dev/null | head -1)
[ -n "$plugin" ] || { echo "$0: no plugin in build/paraview (is paraview-dev installed? scripts/setup.sh)" >&2; exit 1; }
sdk=$(scripts/paraview_sdk.sh)
prefix=$(cd "$sdk/../../../.." && pwd)
if ! command -v xvfb-run >/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends xvfb >/dev/null
fi
input=$(realpath "$1"); output=$(realpath -m "$2"); shift 2
xvfb-run -a -s "-screen 0 1024x768x24" "$prefix/bin/pvpython" --force-offscreen-rendering scripts/paraview_view.py \
  "$prefix/lib/python3/dist-packages" "$(realpath "$plugin")" "$input" "$output" "$@" 2>&1 | grep -v "^$" || true
[ -f "$output" ] || { echo "$0: no image written" >&2; exit 1; }
