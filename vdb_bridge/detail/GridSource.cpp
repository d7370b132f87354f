// See GridSource.h.
#include "vdb_bridge/detail/GridSource.h"

#include "vdb_bridge/DenseImport.h"

#include <algorithm>
#include <filesystem>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/InputScene.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge::detail {

bool isSsvdagPath(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".ssvdag";
}

namespace {

void checkNames(const std::string& path, const std::vector<std::string>& names, const std::vector<std::string>& wanted) {
    for (const std::string& w : wanted)
        if (std::find(names.begin(), names.end(), w) == names.end()) {
            std::string list;
            for (const auto& n : names) list += (list.empty() ? "'" : ", '") + n + "'";
            throw Error(path + ": no grid named '" + w + "' (the file has " + (list.empty() ? "no grids" : list) + ")");
        }
}

bool selected(const std::vector<std::string>& wanted, const std::string& name) {
    return wanted.empty() || std::find(wanted.begin(), wanted.end(), name) != wanted.end();
}

} // namespace

std::vector<LoadedGrid> loadGrids(const std::string& path, const std::vector<std::string>& onlyGrids, const format::ReadLimits& limits) {
    initializeOpenVdb();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    std::vector<LoadedGrid> out;
    if (denseFormatOf(path) != DenseFormat::None && !isSsvdagPath(path)) {  // a scan, read as `import` reads it (no thresholds)
        DenseImportOptions options;
        options.showProgress = false;
        DenseImportResult imported = importDense(path, options);
        checkNames(path, {imported.volume.grids.front().name}, onlyGrids);
        if (selected(onlyGrids, imported.volume.grids.front().name))
            out.push_back({0, buildGrid(imported.volume.grids.front(), path + ": grid 0")});
        return out;
    }
    if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a directory, not a .vdb or .ssvdag file");
    if (inputKindOf(path) == InputKind::NanoVdb) {  // NanoVDB: through NanoVDB's converter, as `encode` reads it
        ImportResult imported = importNanoVdb(path);
        std::vector<std::string> names;
        for (const auto& g : imported.volume.grids) names.push_back(g.name);
        checkNames(path, names, onlyGrids);
        for (size_t i = 0; i < imported.volume.grids.size(); ++i)
            if (selected(onlyGrids, imported.volume.grids[i].name))
                out.push_back({i, buildGrid(imported.volume.grids[i], path + ": grid " + std::to_string(i))});
        return out;
    }
    if (isSsvdagPath(path)) {
        format::ReadOptions readOptions;
        readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
        readOptions.limits = limits;
        format::SsvdagScene scene = format::readSceneFile(path, readOptions);
        std::vector<std::string> names;
        for (const auto& g : scene.grids) names.push_back(g.record.name);
        checkNames(path, names, onlyGrids);
        for (size_t i = 0; i < scene.grids.size(); ++i) {
            if (!selected(onlyGrids, scene.grids[i].record.name)) continue;
            const GridRecord record = pipeline::decodeGrid(scene.grids[i]);
            out.push_back({i, buildGrid(record, path + ": grid " + std::to_string(i))});
        }
        return out;
    }
    const VdbFileContents contents = readVdbFile(path);
    const openvdb::GridPtrVec* grids = &contents.grids;
    std::vector<std::string> names;
    for (const auto& g : *grids) names.push_back(g->getName());
    checkNames(path, names, onlyGrids);
    for (size_t i = 0; i < grids->size(); ++i) {
        const auto& g = (*grids)[i];
        if (!selected(onlyGrids, g->getName())) continue;
        if (!dispatchGridType(*g, [](const auto&, ValueType) {}))
            throw Error(path + ": grid " + std::to_string(i) + " '" + g->getName() + "' has type '" + g->type() + "'" + typeHint(*g) +
                        ", which vdbdag does not convert (pick other grids with --grid NAME)");
        out.push_back({i, g});
    }
    return out;
}

std::string gridLabel(const LoadedGrid& grid) {
    return grid.grid->getName().empty() ? "#" + std::to_string(grid.fileIndex) : "'" + grid.grid->getName() + "'";
}

} // namespace vdbdag::bridge::detail
