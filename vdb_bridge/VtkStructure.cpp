// See VtkStructure.h. The walking is pure core (src/encoding/DagStructure);
// this file only turns levels into VTK blocks.
#include "vdb_bridge/VtkStructure.h"

#include <algorithm>

#include <fmt/core.h>

#include <openvdb/openvdb.h>
#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkInformation.h>
#include <vtkIntArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnsignedCharArray.h>

#include "src/encoding/DagStructure.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/VdbImport.h"
#include "vdb_bridge/detail/GridSource.h"
#include "vdb_bridge/detail/VoxelCells.h"
#include "vdb_bridge/detail/VtkWriting.h"

namespace vdbdag::bridge {
namespace {

// One level's cells and fields.
struct LevelBlock {
    explicit LevelBlock(const std::array<double, 16>& indexToWorld) : cells(indexToWorld) {
        level->SetName("level");
        nodeId->SetName("node_id");
        refcount->SetName("refcount");
        instances->SetName("instances");
        mirror->SetName("mirror");
        solid->SetName("solid");
    }
    void add(unsigned levelIndex, unsigned log2Size, const std::array<int64_t, 3>& corner, uint32_t id, const encoding::StructureLevel& info, unsigned m) {
        const int64_t size = int64_t(1) << log2Size;
        auto clampCoord = [](int64_t v) { return int(std::clamp<int64_t>(v, std::numeric_limits<int>::min(), std::numeric_limits<int>::max())); };
        cells.addBox(openvdb::CoordBBox(openvdb::Coord(clampCoord(corner[0]), clampCoord(corner[1]), clampCoord(corner[2])),
                                        openvdb::Coord(clampCoord(corner[0] + size - 1), clampCoord(corner[1] + size - 1), clampCoord(corner[2] + size - 1))));
        level->InsertNextValue(int(levelIndex));
        nodeId->InsertNextValue(int(id));
        refcount->InsertNextValue(vtkTypeInt64(std::min<uint64_t>(info.refcount[id], uint64_t(INT64_MAX))));
        instances->InsertNextValue(vtkTypeInt64(std::min<uint64_t>(info.instances[id], uint64_t(INT64_MAX))));
        mirror->InsertNextValue(static_cast<unsigned char>(m));
        solid->InsertNextValue(info.solid[id] ? 1 : 0);
    }
    vtkSmartPointer<vtkUnstructuredGrid> finish() {
        auto grid = cells.finish();
        for (vtkDataArray* a : std::initializer_list<vtkDataArray*>{level, nodeId, refcount, instances, mirror, solid}) grid->GetCellData()->AddArray(a);
        grid->GetCellData()->SetActiveScalars("refcount");
        return grid;
    }
    detail::VoxelCellBuilder cells;
    vtkNew<vtkIntArray> level, nodeId;
    vtkNew<vtkTypeInt64Array> refcount, instances;
    vtkNew<vtkUnsignedCharArray> mirror, solid;
};

vtkSmartPointer<vtkMultiBlockDataSet> gridBlocks(const format::EncodedGrid& grid, const StructureExportOptions& options, StructureGridReport& report) {
    auto blocks = vtkSmartPointer<vtkMultiBlockDataSet>::New();
    const std::vector<encoding::StructureLevel> levels = encoding::analyzeStructure(grid.active.dag);
    uint64_t total = 0;
    for (const auto& l : levels) total = total > UINT64_MAX - l.totalInstances ? UINT64_MAX : total + l.totalInstances;
    report.perInstance = !options.uniqueNodes && total <= options.maxInstances;
    std::vector<std::unique_ptr<LevelBlock>> out;
    for (size_t i = 0; i < levels.size(); ++i) out.push_back(std::make_unique<LevelBlock>(grid.record.indexToWorld));
    if (report.perInstance) {
        encoding::visitNodeInstances(grid.active.dag, [&](const encoding::NodeInstance& n) {
            out[n.levelIndex]->add(n.levelIndex, n.log2Size, {n.x, n.y, n.z}, n.nodeId, levels[n.levelIndex], n.mirror);
        });
    } else {
        for (size_t i = 0; i < levels.size(); ++i)
            for (uint32_t id = 0; id < levels[i].nodeCount(); ++id)
                out[i]->add(unsigned(i), levels[i].log2Size, levels[i].firstCorner[id], id, levels[i], levels[i].firstMirror[id]);
    }
    for (size_t i = 0; i < levels.size(); ++i) {
        StructureLevelReport lr;
        lr.nodeSize = uint64_t(1) << levels[i].log2Size;
        lr.uniqueNodes = levels[i].nodeCount();
        lr.instances = levels[i].totalInstances;
        lr.cells = out[i]->cells.cellCount();
        report.levels.push_back(lr);
        detail::setBlock(blocks, unsigned(i), out[i]->finish(),
                         fmt::format("level {} ({}^3 nodes: {} unique, {} instances)", i, lr.nodeSize, lr.uniqueNodes, lr.instances));
    }
    return blocks;
}

} // namespace

StructureExportReport exportStructure(const std::string& input, const std::string& output, const StructureExportOptions& options) {
    if (detail::extensionOf(output) != ".vtm") throw Error(output + ": the structure is written as a multiblock .vtm (one block per level)");
    const detail::Compressor compressor = detail::parseCompressor(options.compressor);
    format::SsvdagScene scene;
    if (detail::isSsvdagPath(input)) {
        format::ReadOptions readOptions;
        readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
        readOptions.limits = options.limits;
        scene = format::readSceneFile(input, readOptions);
    } else {
        ImportOptions importOptions;
        importOptions.onlyGrids = options.grids;
        importOptions.topologyOnly = true;
        scene = pipeline::encodeVolume(importVdb(input, importOptions).volume);
    }
    std::vector<size_t> chosen;
    for (size_t i = 0; i < scene.grids.size(); ++i)
        if (options.grids.empty() || std::find(options.grids.begin(), options.grids.end(), scene.grids[i].record.name) != options.grids.end())
            chosen.push_back(i);
    for (const std::string& wanted : options.grids)
        if (std::none_of(scene.grids.begin(), scene.grids.end(), [&](const auto& g) { return g.record.name == wanted; }))
            throw Error(input + ": no grid named '" + wanted + "'");
    if (chosen.empty()) throw Error(input + ": holds no grids");

    StructureExportReport report;
    vtkNew<vtkMultiBlockDataSet> top;
    for (size_t c = 0; c < chosen.size(); ++c) {
        const format::EncodedGrid& grid = scene.grids[chosen[c]];
        StructureGridReport gr;
        gr.grid = grid.record.name;
        gr.fileIndex = detail::isSsvdagPath(input) ? chosen[c] : c;
        auto blocks = gridBlocks(grid, options, gr);
        if (chosen.size() == 1) {
            for (unsigned b = 0; b < blocks->GetNumberOfBlocks(); ++b)
                detail::setBlock(top, b, blocks->GetBlock(b), blocks->GetMetaData(b)->Get(vtkCompositeDataSet::NAME()));
        } else {
            detail::setBlock(top, unsigned(c), blocks, grid.record.name.empty() ? "grid_" + std::to_string(c) : grid.record.name);
        }
        report.grids.push_back(std::move(gr));
    }
    detail::writeVtk(top, output, compressor);
    report.bytes = detail::writtenBytes(output);
    return report;
}

} // namespace vdbdag::bridge
