// The DAG's structure for ParaView (`vdbdag export IN --structure -o OUT.vtm`):
// one block per level (root first), a world-space cube per node instance
// with the fields `level` (0 = root), `node_id` (the node's ordinal in its
// level as stored, most referenced first), `refcount` (parent pointers to
// the node; the root's is 1), `instances` (how often the node occurs in the
// expanded octree), `mirror` (the 3-bit reflection under which this instance
// uses the shared node: bit 0 x, bit 1 y, bit 2 z; SSVDAG paper §3) and
// `solid` (an active tile). Past `maxInstances` (or with `uniqueNodes`) a
// cell per unique node, placed at its first instance. A .vdb input is encoded
// in memory first (topology only, default settings); several grids nest.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "src/format/ReadLimits.h"

namespace vdbdag::bridge {

struct StructureExportOptions {
    std::vector<std::string> grids;
    uint64_t maxInstances = 4'000'000;  // per grid, all levels together
    bool uniqueNodes = false;
    std::string compressor = "zlib";
    format::ReadLimits limits;  // for an .ssvdag input
};

struct StructureLevelReport {
    uint64_t nodeSize = 0;  // voxels per edge
    uint64_t uniqueNodes = 0, instances = 0, cells = 0;
};

struct StructureGridReport {
    std::string grid;
    size_t fileIndex = 0;
    bool perInstance = true;
    std::vector<StructureLevelReport> levels;  // root first
};

struct StructureExportReport {
    std::vector<StructureGridReport> grids;
    uint64_t bytes = 0;
};

// `output` must be a .vtm. Throws vdbdag::Error.
StructureExportReport exportStructure(const std::string& input, const std::string& output, const StructureExportOptions& options);

} // namespace vdbdag::bridge
