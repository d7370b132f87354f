// Volume -> .vdb: every grid rebuilt with its original type, header, values
// and stored inactive values; written atomically.
#include "vdb_bridge/VdbExport.h"

#include "src/util/AtomicFile.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {

void exportVdb(const Volume& volume, const std::string& path) {
    detail::initializeOpenVdb();
    openvdb::GridPtrVec grids;
    for (size_t g = 0; g < volume.grids.size(); ++g)
        grids.push_back(detail::buildGrid(volume.grids[g], path + ": grid " + std::to_string(g)));
    writeViaTemporary(path, [&](const std::string& temporary) {
        try {
            openvdb::io::File file(temporary);
            file.write(grids);
            file.close();
        } catch (const openvdb::Exception& e) {
            throw Error(path + ": OpenVDB could not write the file (" + detail::oneLine(e.what()) + ")");
        }
    });
}

} // namespace vdbdag::bridge
