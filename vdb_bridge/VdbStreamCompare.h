// The comparison of VdbCompare.h between an original .vdb file and an
// .ssvdag scene, in bounded memory: neither side is ever a whole grid.
// The scene is read with format::ReadOptions::keepValueWindows and each
// layer decoded cube by cube (pipeline/LayerScatter.h); the original is
// read grid by grid through OpenVDB's delayed loading, and each cube's
// region of it is walked through OpenVDB's accessor, every leaf dropped as
// soon as the cubes covering it are done. Each layer is read from the file
// once. The checks are those of compareWithFile: headers, the active
// voxels (tiles counted as their voxels) with their values, and every
// stored inactive value, bit for bit.
#pragma once
#include <functional>
#include <string>

#include "src/format/SsvdagFile.h"
#include "vdb_bridge/VdbCompare.h"

namespace vdbdag::bridge {

// Called as each layer's cubes are compared: the step ("grid 'density':
// active voxels") and the cubes done of its total.
using CompareProgress = std::function<void(const std::string& step, uint64_t done, uint64_t total)>;

// Grids in the same order. With `values` false only headers and the active
// topology are compared (for --topology-only encodings).
CompareResult compareSceneWithFile(const std::string& originalPath, const format::SsvdagScene& scene, bool values = true,
                                   const CompareProgress& progress = {});

} // namespace vdbdag::bridge
