// See NanoVdb.h.
#include "vdb_bridge/NanoVdb.h"

#include <algorithm>
#include <filesystem>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/NanoToOpenVDB.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "src/util/OutputPath.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/ImportGrids.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {

using detail::oneLine;

bool isNanoVdbPath(const std::string& path) { return lowerExtension(path) == ".nvdb"; }

ImportResult importNanoVdb(const std::string& path, const ImportOptions& options) {
    checkInputFile(path, "a NanoVDB file");
    detail::initializeOpenVdb();
    const uint64_t fileBytes = std::filesystem::file_size(path);
    // The grids' declared sizes first: NanoVDB allocates what a header
    // claims, so a claim the file cannot hold is refused before that.
    std::vector<nanovdb::io::GridMetaData> metas;
    try {
        metas = nanovdb::io::readGridMetaData(path);
    } catch (const std::exception& e) {
        throw Error(path + ": not a NanoVDB file, or a damaged one (" + oneLine(e.what()) + ")");
    }
    for (size_t i = 0; i < metas.size(); ++i) {
        const auto& m = metas[i];
        const bool raw = m.codec == nanovdb::io::Codec::NONE;
        if (m.fileSize > fileBytes || (raw && m.gridSize != m.fileSize) || m.gridSize / 64 > std::max<uint64_t>(m.fileSize, 1))
            throw Error(path + ": grid " + std::to_string(i) + " declares " + std::to_string(m.gridSize) + " bytes in " + std::to_string(m.fileSize) +
                        " stored (the file holds " + std::to_string(fileBytes) + "): the file is damaged");
    }
    openvdb::GridPtrVec grids;
    try {
        const auto handles = nanovdb::io::readGrids(path);
        for (size_t i = 0; i < handles.size(); ++i) {
            const nanovdb::GridMetaData* meta = handles[i].gridMetaData();
            try {
                grids.push_back(nanovdb::nanoToOpenVDB(handles[i]));
            } catch (const std::exception&) {
                const std::string name = meta ? meta->shortGridName() : "";
                const std::string type = meta ? nanovdb::toStr(meta->gridType()) : "unknown";
                const std::string message = "grid " + std::to_string(i) + " '" + name + "' has NanoVDB type '" + type + "', which vdbdag does not convert";
                if (!options.skipUnsupported) throw Error(path + ": " + message + " (use --skip-unsupported to convert the other grids)");
            }
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path + ": NanoVDB could not read the file (" + oneLine(e.what()) + ")");
    }
    ImportResult result = detail::importGrids(grids, openvdb::MetaMap(), path, options);
    if (grids.size() < metas.size())
        result.warnings.push_back(path + ": skipped " + std::to_string(metas.size() - grids.size()) + " grid(s) of a NanoVDB type vdbdag does not convert");
    return result;
}

void exportNanoVdb(const Volume& volume, const std::string& path, const std::function<void(size_t done, size_t total)>& onStep) {
    detail::initializeOpenVdb();
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    const size_t steps = volume.grids.size() + 1;
    for (size_t g = 0; g < volume.grids.size(); ++g) {
        const GridRecord& record = volume.grids[g];
        const std::string what = path + ": grid " + std::to_string(g) + " '" + record.name + "'";
        if (record.valueType == ValueType::Vec3I) throw Error(what + ": NanoVDB has no vec3i grids (write a .vdb instead)");
        const openvdb::GridBase::Ptr grid = detail::buildGrid(record, what);
        try {
            handles.push_back(nanovdb::openToNanoVDB(grid));
        } catch (const std::exception& e) {
            throw Error(what + ": NanoVDB could not convert it (" + oneLine(e.what()) + ")");
        }
        if (onStep) onStep(g + 1, steps);
    }
    writeStreamAtomically(path, [&](std::ostream& out) {
        try {
            nanovdb::io::writeGrids(out, handles);
        } catch (const std::exception& e) {
            throw Error(path + ": NanoVDB could not write the file (" + oneLine(e.what()) + ")");
        }
    });
    if (onStep) onStep(steps, steps);
}

} // namespace vdbdag::bridge
