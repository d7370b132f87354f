// Volume -> .vdb: every grid rebuilt with its original type, header, values
// and stored inactive values; written atomically.
#include "vdb_bridge/VdbExport.h"

#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {

void exportVdb(const Volume& volume, const std::string& path) {
    detail::initializeOpenVdb();
    const openvdb::MetaMap::Ptr metadata = detail::parseMetadata(volume.fileMetadata, path);
    openvdb::GridCPtrVec grids;
    for (size_t g = 0; g < volume.grids.size(); ++g)
        grids.push_back(detail::buildGrid(volume.grids[g], path + ": grid " + std::to_string(g)));
    detail::writeVdbFile(path, grids, *metadata);
}

} // namespace vdbdag::bridge
