// NanoVDB files (.nvdb) in and out, through NanoVDB's own converters
// (libnanovdb-dev): a NanoVDB grid becomes the OpenVDB grid nanoToOpenVDB
// makes of it and is then imported like a .vdb grid; a Volume is built as
// OpenVDB grids (as exportVdb builds them) and openToNanoVDB makes each a
// NanoVDB grid. Lossless where the NanoVDB grid is: float, double, int32,
// int64, bool, mask, vec3s and vec3d grids come back bit for bit (active and
// inactive values, tiles, background, transform); Fp4/Fp8/Fp16/FpN grids
// are read as the floats they decode to. NanoVDB keeps no metadata, so a
// .nvdb has none to give and a written .nvdb loses a Volume's. NanoVDB has
// no vec3i grids: writing one is refused.
#pragma once
#include <functional>
#include <string>

#include "src/volume/GridRecord.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::bridge {

// By extension: ".nvdb", any case.
bool isNanoVdbPath(const std::string& path);

// Throws vdbdag::Error ("PATH: ...") for a missing, damaged or unreadable
// file, or a grid type vdbdag does not convert (see ImportOptions).
ImportResult importNanoVdb(const std::string& path, const ImportOptions& options = {});

// Writes every grid of `volume` to `path` atomically (uncompressed, with
// NanoVDB's default statistics and checksums).
void exportNanoVdb(const Volume& volume, const std::string& path, const std::function<void(size_t done, size_t total)>& onStep = {});

} // namespace vdbdag::bridge
