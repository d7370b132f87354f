"""Renders an .ssvdag or .vdb file in ParaView through the VdbdagReader plugin,
to look at: a contour (level sets: the zero surface) or a volume rendering
(fogs and scans), at the reader's automatic level of detail.
  pvpython scripts/paraview_view.py PV_SITE_PACKAGES PLUGIN.so FILE OUT.png [contour VALUE | volume] [LEVEL]
scripts/paraview_check.sh FILE.ssvdag|vdb OUT.png ... runs it; it is not part of the test suite."""
import sys
import time

sys.path.insert(0, sys.argv[1])  # ParaView's modules before python3-vtk9's
from paraview.simple import (LoadPlugin, OpenDataFile, Contour, Show, CreateView, SetActiveView, ColorBy,  # noqa: E402
                             GetColorTransferFunction, GetOpacityTransferFunction, SaveScreenshot, ResetCamera)

plugin, path, out = sys.argv[2:5]
mode = sys.argv[5] if len(sys.argv) > 5 else "volume"
LoadPlugin(plugin, remote=False, ns=globals())
reader = OpenDataFile(path)
if len(sys.argv) > 7:
    reader.LevelOfDetail = int(sys.argv[7])
start = time.time()
reader.UpdatePipeline()
reader.UpdatePropertyInformation()
info = reader.GetDataInformation()
array = reader.PointData.keys()[0]
lo, hi = reader.PointData[array].GetRange()
print("paraview_view: %s: level %d, %d points, '%s' in [%g, %g], read in %.2f s"
      % (path, reader.GetProperty("ChosenLevel").GetData(), info.GetNumberOfPoints(), array, lo, hi, time.time() - start))
view = CreateView("RenderView")
view.ViewSize = [800, 800]
view.Background = [1, 1, 1]
if hasattr(view, "UseColorPaletteForBackground"):
    view.UseColorPaletteForBackground = 0
view.OrientationAxesVisibility = 0
SetActiveView(view)
if mode == "contour":
    value = float(sys.argv[6]) if len(sys.argv) > 6 else 0.0
    surface = Contour(Input=reader, ContourBy=["POINTS", array], Isosurfaces=[value], ComputeScalars=0)
    display = Show(surface, view)
    display.DiffuseColor = [0.85, 0.7, 0.5]
    display.AmbientColor = [0.85, 0.7, 0.5]
else:
    display = Show(reader, view)
    display.SetRepresentationType("Volume")
    ColorBy(display, ("POINTS", array))
    colours = GetColorTransferFunction(array)
    colours.ApplyPreset("Grayscale", True)
    opacity = GetOpacityTransferFunction(array)
    # Transparent below a fifth of the range (air, empty space), rising to 0.6.
    opacity.Points = [lo, 0, 0.5, 0, lo + 0.2 * (hi - lo), 0, 0.5, 0, hi, 0.6, 0.5, 0]
    colours.RescaleTransferFunction(lo, hi)
# Y up (OpenVDB's and the scanned models' convention), from the front, a
# little from above and the side.
view.CameraPosition = [0.8, 0.6, 1.6]
view.CameraFocalPoint = [0, 0, 0]
view.CameraViewUp = [0, 1, 0]
ResetCamera(view)
SaveScreenshot(out, view, ImageResolution=[800, 800])
print("paraview_view: wrote " + out)
