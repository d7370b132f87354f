// Volume -> .vdb: every grid rebuilt with its original type, header, values
// and stored inactive values; written atomically.
#include "vdb_bridge/VdbExport.h"

#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {

void exportVdb(const Volume& volume, const std::string& path, const std::function<void(size_t done, size_t total)>& onStep) {
    detail::initializeOpenVdb();
    const openvdb::MetaMap::Ptr metadata = detail::parseMetadata(volume.fileMetadata, path);
    openvdb::GridCPtrVec grids;
    const size_t steps = volume.grids.size() + 1;
    for (size_t g = 0; g < volume.grids.size(); ++g) {
        grids.push_back(detail::buildGrid(volume.grids[g], path + ": grid " + std::to_string(g)));
        if (onStep) onStep(g + 1, steps);
    }
    detail::writeVdbFile(path, grids, *metadata);
    if (onStep) onStep(steps, steps);
}

} // namespace vdbdag::bridge
