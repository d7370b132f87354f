#!/usr/bin/env bash
# Opens a file in ParaView 5.11 (pvpython under xvfb) and saves a
# screenshot, to check by eye that the object shows.
#
#   scripts/paraview_check.sh FILE.vtu|vti|vtm FIELD OUT.png [THRESHOLD_FIELD MIN MAX]
#   scripts/paraview_check.sh FILE.ssvdag|vdb OUT.png [contour VALUE | volume] [LEVEL]
#
# A VTK export is coloured by a cell field; the optional threshold keeps
# cells with MIN <= THRESHOLD_FIELD <= MAX (e.g. `level 5 5` for one level of
# a --structure export, `status 1 3` for the differing cells of a diff). An
# .ssvdag or .vdb file is opened directly through the VdbdagReader plugin of
# ./build (scripts/paraview_view.py): its zero surface (contour, the default
# VALUE 0) or a volume rendering, at the reader's automatic level of detail
# or LEVEL. Installs `paraview xvfb` if missing, and unpacks pvpython without
# installing it (python3-paraview would remove libvtk9-dev,
# ../shared/TOOLCHAIN.md) into ${VDBDAG_PV_DIR:-$HOME/.cache/vdbdag/pvpython}.
# Not part of the test suite.
set -euo pipefail
case "${1:-}" in
  *.ssvdag|*.vdb) PLUGIN_MODE=1 ;;
  *) PLUGIN_MODE=0 ;;
esac
if [ "$PLUGIN_MODE" = 1 ]; then
  if [ $# -lt 2 ] || [ $# -gt 5 ]; then
    echo "usage: $0 FILE.ssvdag|vdb OUT.png [contour VALUE | volume] [LEVEL]" >&2
    exit 2
  fi
  INPUT=$(realpath "$1"); OUTPUT=$(realpath -m "$2")
elif [ $# -ne 3 ] && [ $# -ne 6 ]; then
  echo "usage: $0 FILE.vtu|vti|vtm FIELD OUT.png [THRESHOLD_FIELD MIN MAX]" >&2
  echo "       $0 FILE.ssvdag|vdb OUT.png [contour VALUE | volume] [LEVEL]" >&2
  exit 2
else
  INPUT=$(realpath "$1"); FIELD=$2; OUTPUT=$(realpath -m "$3")
fi
[ -f "$INPUT" ] || { echo "$0: $1: no such file" >&2; exit 1; }

SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
if ! command -v paraview >/dev/null || ! command -v xvfb-run >/dev/null; then
  echo "paraview_check: installing paraview xvfb" >&2
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends paraview xvfb >/dev/null
fi
PV_DIR=${VDBDAG_PV_DIR:-$HOME/.cache/vdbdag/pvpython}
if [ ! -x "$PV_DIR/usr/bin/pvpython" ]; then
  echo "paraview_check: unpacking pvpython into $PV_DIR" >&2
  mkdir -p "$PV_DIR"
  tmp=$(mktemp -d)
  chmod 755 "$tmp"  # apt downloads as _apt
  (cd "$tmp" && apt-get download -qq python3-paraview >/dev/null && dpkg-deb -x python3-paraview_*.deb "$PV_DIR")
  rm -rf "$tmp"
fi

# pvpython under xvfb now and then aborts at start-up ("bad X server
# connection": xvfb-run -a races other users of display :99). Start from a
# random display number and retry a crash (exit >= 128), never an ordinary failure.
run_pvpython() {
  local attempt status=0
  for attempt in 1 2 3; do
    status=0
    xvfb-run -a -n $((100 + RANDOM % 800)) -s "-screen 0 1024x768x24" "$@" || status=$?
    [ "$status" -lt 128 ] && return "$status"
    echo "paraview_check: pvpython crashed (exit $status), attempt $attempt of 3" >&2
  done
  return "$status"
}

if [ "$PLUGIN_MODE" = 1 ]; then
  ROOT=$(cd "$(dirname "$0")/.." && pwd)
  plugin=$(find "$ROOT/build/paraview/lib" -name VdbdagReader.so 2>/dev/null | head -1)
  [ -n "$plugin" ] || { echo "$0: no plugin in build/paraview (paraview-dev missing? scripts/setup.sh installs it)" >&2; exit 1; }
  shift 2
  run_pvpython "$PV_DIR/usr/bin/pvpython" --force-offscreen-rendering "$ROOT/scripts/paraview_view.py" \
    "$PV_DIR/usr/lib/python3/dist-packages" "$plugin" "$INPUT" "$OUTPUT" "$@"
  exit $?
fi

script=$(mktemp --suffix=.py)
trap 'rm -f "$script"' EXIT
cat > "$script" <<PY
import sys
# pvpython puts python3-vtk9's modules first; ParaView's own must win.
sys.path.insert(0, "$PV_DIR/usr/lib/python3/dist-packages")
from paraview.simple import *
source = OpenDataFile("$INPUT")
if source is None:
    sys.exit("paraview_check: ParaView cannot open $INPUT")
args = sys.argv[1:]
if args:
    source = Threshold(Input=source, Scalars=["CELLS", args[0]], LowerThreshold=float(args[1]), UpperThreshold=float(args[2]),
                       ThresholdMethod="Between")
source.UpdatePipeline()
info = source.GetDataInformation()
cells = info.GetNumberOfCells()
print("paraview_check: %d cells, %d points, bounds %s" % (cells, info.GetNumberOfPoints(), info.GetBounds()))
if cells == 0:
    sys.exit("paraview_check: nothing to show")
view = CreateView("RenderView")
view.ViewSize = [1024, 768]
view.Background = [1, 1, 1]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
view.OrientationAxesVisibility = 0
display = Show(source, view)
display.Representation = "Surface"
ColorBy(display, ("CELLS", "$FIELD"))
display.RescaleTransferFunctionToDataRange(True, False)
display.SetScalarBarVisibility(view, True)
bar = GetScalarBar(GetColorTransferFunction("$FIELD"), view)
bar.Title = "$FIELD"
bar.ComponentTitle = ""
bar.TitleColor = [0, 0, 0]
bar.LabelColor = [0, 0, 0]
# Y up (the scanned models' convention), seen from the front, a little from above and the side.
view.CameraPosition = [0.8, 0.6, 1.6]
view.CameraFocalPoint = [0, 0, 0]
view.CameraViewUp = [0, 1, 0]
view.ResetCamera()
Render(view)
SaveScreenshot("$OUTPUT", view, ImageResolution=[1024, 768])
print("paraview_check: wrote $OUTPUT")
PY
shift 3
run_pvpython "$PV_DIR/usr/bin/pvpython" --force-offscreen-rendering "$script" "$@"
