// Independent comparison of two .vdb files (or a file and a Volume) with
// OpenVDB's own tree operations and accessors: same grids in the same order,
// same name, type, class, transform, background and metadata, same active
// voxels (tiles counted as their voxels), every active value and every
// stored inactive value bit-identical. Reports the first differences.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge {

struct TopologyDifference {
    size_t gridIndex = 0;
    std::string gridName;
    uint64_t onlyInA = 0;  // active voxels in A but not B
    uint64_t onlyInB = 0;
    std::vector<std::string> examples;  // e.g. "voxel (1,2,3) active only in A"
};

struct ValueDifference {
    size_t gridIndex = 0;
    std::string gridName;
    uint64_t activeValues = 0;    // voxels active in either grid whose values differ bitwise
    uint64_t inactiveValues = 0;  // inactive in both, stored value differs bitwise
    std::vector<std::string> examples;
};

struct CompareResult {
    bool identical = true;
    std::vector<std::string> headerDifferences;  // name / class / transform / metadata / grid count
    std::vector<TopologyDifference> topology;    // one per grid that differs
    std::vector<ValueDifference> values;         // one per grid whose values differ
};

// Compares every grid of the original .vdb file at `originalPath` with
// `decoded` (grids in the same order).
// With `values` false only headers and topology are compared (for
// --topology-only encodings, which decode to MaskGrids).
CompareResult compareWithFile(const std::string& originalPath, const Volume& decoded, bool values = true);

// Same, between two .vdb files.
CompareResult compareFiles(const std::string& pathA, const std::string& pathB, bool values = true);

} // namespace vdbdag::bridge
