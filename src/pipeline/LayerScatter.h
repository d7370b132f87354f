// A layer of a grid read from a file (format::ReadOptions::keepValueWindows)
// decoded cube by cube: its subtrees of 2^cutLog2 voxels in attribute order,
// each one's values taken from the value windows one window at a time
// (attributes/WindowCursor.h). So a reader that writes the voxels out as
// they come (a dense decode) holds the DAG, one window and one cube, never
// the layer's values or an OpenVDB grid.
#pragma once
#include <cstdint>
#include <functional>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/AttributeOrder.h"

namespace vdbdag::pipeline {

struct LayerCubes {
    std::function<void(const encoding::SubtreeInstance&)> begin;  // before a subtree's voxels
    SubtreeVoxels voxels;
    std::function<void()> end;  // after them
};

// `inactive`: the inactive layer. Works on a scene read either way (the
// values as an attribute array or kept in windows).
void scatterLayerByCubes(const format::EncodedGrid& grid, bool inactive, unsigned cutLog2, const LayerCubes& visit,
                         const std::function<void(uint64_t done, uint64_t total)>& progress = {});

} // namespace vdbdag::pipeline
