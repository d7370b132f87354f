// Reading .vdb files into vdbdag's Volume (topology + descriptors), with no
// OpenVDB types in the interface. Handles every file format OpenVDB reads
// (222-224, half floats, blosc, zip).
#pragma once
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge {

struct ImportOptions {
    std::vector<std::string> onlyGrids;  // empty: all grids; else only grids with these names
    // A grid of an unsupported type (PointDataGrid, string grids, ...) stops
    // the import with an error naming the grid and its type, unless this is
    // set; then the grid is skipped and a warning is added to `warnings`.
    bool skipUnsupported = false;
    // Geometry only: keep each grid's header but import it as a mask (active
    // topology, no values, no inactive layer); it decodes as a MaskGrid.
    bool topologyOnly = false;
    // Exact shading normals (GridRecord::normals) for `--normals`: by
    // default the gradient of every float/double grid; with `normalGrid`,
    // the normalised values of that vec3 grid, on that grid only.
    bool normals = false;
    std::string normalGrid;
};

struct ImportResult {
    Volume volume;
    std::vector<std::string> warnings;
};

// Throws vdbdag::Error ("PATH: ...") if the file is missing, not a .vdb, or
// holds an unsupported grid (see ImportOptions).
ImportResult importVdb(const std::string& path, const ImportOptions& options = {});

} // namespace vdbdag::bridge
