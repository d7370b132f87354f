// Independent comparison of two .vdb files (or a file and a Volume) with
// OpenVDB's own tree operations: same grids in the same order, same name,
// class, transform and metadata, same active voxels (tiles counted as their
// voxels). Reports the first differences with coordinates.
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

struct CompareResult {
    bool identical = true;
    std::vector<std::string> headerDifferences;  // name / class / transform / metadata / grid count
    std::vector<TopologyDifference> topology;    // one per grid that differs
};

// Compares the topology (and grid headers) of every grid of the original
// .vdb file at `originalPath` with `decoded` (grids in the same order).
CompareResult compareTopology(const std::string& originalPath, const Volume& decoded);

// Same, between two .vdb files.
CompareResult compareTopologyFiles(const std::string& pathA, const std::string& pathB);

} // namespace vdbdag::bridge
