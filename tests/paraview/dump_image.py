# Run by pvpython (ParaView's own Python): loads the VdbdagReader plugin,
# opens each case's file (or list of files: a series) with ParaView's reader
# factory (as File > Open does), applies the case's reader properties,
# updates it (at the case's time, if any) and saves
# what ParaView holds (geometry, chosen level, every point array) as .npz
# for check_plugin.py to compare with independent readers.
#   pvpython dump_image.py PV_SITE_PACKAGES PLUGIN.so CASES.json
import json
import sys

sys.path.insert(0, sys.argv[1])  # ParaView's modules before python3-vtk9's
from paraview.simple import Contour, LoadPlugin, OpenDataFile  # noqa: E402
import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

LoadPlugin(sys.argv[2], remote=False, ns=globals())
for case in json.load(open(sys.argv[3])):
    reader = OpenDataFile(case["file"])
    if reader is None or reader.GetXMLName() != "VdbdagReader":
        sys.exit("dump_image: ParaView opened %s with %s, not the plugin's reader"
                 % (case["file"], None if reader is None else reader.GetXMLName()))
    for name, value in case.get("properties", {}).items():
        setattr(reader, name, value)
    if "time" in case:
        reader.UpdatePipeline(case["time"])
    else:
        reader.UpdatePipeline()
    reader.UpdatePropertyInformation()  # ChosenLevel of this update
    image = reader.GetClientSideObject().GetOutputDataObject(0)  # the builtin session's data of this update
    if image.IsA("vtkMultiBlockDataSet"):  # Output Type "Active Voxels": per block, each cell's corners 0 and 6, and values
        out = {"class": np.array(image.GetClassName()), "blocks": np.array(
            [image.GetMetaData(b).Get(image.NAME()) for b in range(image.GetNumberOfBlocks())])}
        for b in range(image.GetNumberOfBlocks()):
            cells = image.GetBlock(b)
            corners = vtk_to_numpy(cells.GetPoints().GetData()).reshape(-1, 8, 3)
            out["lo_%d" % b], out["hi_%d" % b] = corners[:, 0, :], corners[:, 6, :]
            out["values_%d" % b] = vtk_to_numpy(cells.GetCellData().GetArray(0))
        np.savez(case["out"], **out)
        print("dump_image: %s -> cells of %s" % (case["file"], list(out["blocks"])))
        continue
    out = {
        "class": np.array(image.GetClassName()),
        "dims": np.array(image.GetDimensions()),
        "origin": np.array(image.GetOrigin()),
        "spacing": np.array(image.GetSpacing()),
        "direction": np.array([image.GetDirectionMatrix().GetElement(r, c) for r in range(3) for c in range(3)]),
        "level": np.array(reader.GetProperty("ChosenLevel").GetData()),
        "times": np.array(list(reader.TimestepValues) if reader.TimestepValues else []),
        "grids": np.array(list(reader.GetProperty("GridInfo").GetData() or [])[0::2]),
        "arrays": np.array([image.GetPointData().GetArrayName(i) for i in range(image.GetPointData().GetNumberOfArrays())]),
    }
    if "contour" in case:  # the surface at that value of the first array
        surface = Contour(Input=reader, ContourBy=["POINTS", out["arrays"][0]], Isosurfaces=[case["contour"]])
        surface.UpdatePipeline()
        out["contour_points"] = np.array(surface.GetDataInformation().GetNumberOfPoints())
    for i in range(image.GetPointData().GetNumberOfArrays()):
        out["array_%d" % i] = vtk_to_numpy(image.GetPointData().GetArray(i))
    np.savez(case["out"], **out)
    print("dump_image: %s -> %s %s" % (case["file"], out["dims"], list(out["arrays"])))
