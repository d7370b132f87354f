// See VtkExport.h. Each grid is first planned (kind, region, cell count,
// bytes) so that every size limit is checked before anything is built; then
// built with OpenVDB's own iterators (leaf voxels, and tiles through a value
// iterator limited to the internal levels) and written atomically.
#include "vdb_bridge/VtkExport.h"

#include <array>
#include <limits>

#include <fmt/core.h>

#include <openvdb/tools/Dense.h>
#include <vtkCellData.h>
#include <vtkImageData.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkUnsignedCharArray.h>

#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/detail/GridSource.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VoxelCells.h"
#include "vdb_bridge/detail/VtkValueArrays.h"
#include "vdb_bridge/detail/VtkWriting.h"

namespace vdbdag::bridge {
namespace {

using detail::LoadedGrid;

std::string withCommas(uint64_t n) {
    std::string s = std::to_string(n), out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (i > 0 && (s.size() - i) % 3 == 0) out += ',';
        out += s[i];
    }
    return out;
}

template <typename GridT>
constexpr bool kHasValues = !std::is_same_v<typename GridT::TreeType::LeafNodeType::BuildType, openvdb::ValueMask>;

template <typename GridT>
uint64_t valueBytes() {
    if constexpr (!kHasValues<GridT>) return 0;
    else {
        using T = typename GridT::ValueType;
        using S = typename detail::VtkValueTraits<T>::Array::ValueType;
        return sizeof(S) * detail::VtkValueTraits<T>::comps;
    }
}

struct Plan {
    bool image = false;
    openvdb::CoordBBox region;  // image: the voxels written; unstructured: clip box (or infinite)
    bool clip = false;
    uint64_t cells = 0;
};

// Cells of an unstructured export: active voxels in leaves plus one per tile, clipped to the box.
template <typename TreeT>
uint64_t countCells(const TreeT& tree, const std::optional<openvdb::CoordBBox>& clip) {
    uint64_t cells = 0;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        if (!clip) { cells += leaf->onVoxelCount(); continue; }
        const openvdb::CoordBBox lb = leaf->getNodeBoundingBox();
        if (!lb.hasOverlap(*clip)) continue;
        if (clip->isInside(lb)) { cells += leaf->onVoxelCount(); continue; }
        for (auto v = leaf->cbeginValueOn(); v; ++v) cells += clip->isInside(v.getCoord()) ? 1 : 0;
    }
    typename TreeT::ValueOnCIter tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        if (!clip || tiles.getBoundingBox().hasOverlap(*clip)) ++cells;
    }
    return cells;
}

std::string limitAdvice() { return "export a region with --bbox X0,Y0,Z0,X1,Y1,Z1 (index space) or fewer grids with --grid NAME"; }

// A box's voxels along each axis and in all, without OpenVDB's int32
// arithmetic (CoordBBox::dim and ::volume wrap for boxes wider than 2^31 - 1,
// and a wrapped count passed every limit). Saturates at UINT64_MAX.
struct BoxSize {
    std::array<int64_t, 3> dim{0, 0, 0};
    uint64_t voxels = 0;
};
__extension__ typedef unsigned __int128 UInt128;  // GCC's and clang's 128-bit integer (not ISO C++: -Wpedantic)

BoxSize sizeOf(const openvdb::CoordBBox& box) {
    BoxSize s;
    if (box.empty()) return s;
    UInt128 n = 1;
    for (int a = 0; a < 3; ++a) {
        s.dim[size_t(a)] = int64_t(box.max()[a]) - int64_t(box.min()[a]) + 1;
        n *= uint64_t(s.dim[size_t(a)]);
        if (n > std::numeric_limits<uint64_t>::max()) n = std::numeric_limits<uint64_t>::max();
    }
    s.voxels = uint64_t(n);
    return s;
}

template <typename GridT>
Plan planGrid(const GridT& grid, const LoadedGrid& loaded, const std::string& input, const std::string& ext, const VtkExportOptions& options) {
    Plan plan;
    const openvdb::CoordBBox active = grid.evalActiveVoxelBoundingBox();
    const bool dense = !active.empty() && grid.activeVoxelCount() == sizeOf(active).voxels;
    plan.image = ext == ".vti" || (ext == ".vtm" && (options.bbox || dense));
    std::optional<openvdb::CoordBBox> box;
    if (options.bbox) {
        const auto& b = *options.bbox;
        box = openvdb::CoordBBox(openvdb::Coord(b[0], b[1], b[2]), openvdb::Coord(b[3], b[4], b[5]));
    }
    const std::string what = input + ": grid " + detail::gridLabel(loaded);
    if (plan.image) {
        if (!grid.transform().isLinear())
            throw Error(what + " has a non-linear (frustum) transform, which a .vti cannot hold: write a .vtu");
        plan.region = box ? *box : active;
        if (plan.region.empty()) throw Error(what + " has no active voxels: there is no region to write as an image (give --bbox)");
        const BoxSize size = sizeOf(plan.region);
        const uint64_t cells = size.voxels;
        const UInt128 wideBytes = (UInt128)cells * (valueBytes<GridT>() + 1);
        const uint64_t bytes = wideBytes > std::numeric_limits<uint64_t>::max() ? std::numeric_limits<uint64_t>::max() : uint64_t(wideBytes);
        bool tooWide = false;  // a vtkImageData counts points per axis in int
        for (int64_t d : size.dim) tooWide = tooWide || d >= int64_t(std::numeric_limits<int32_t>::max());
        if (tooWide || cells > uint64_t(std::numeric_limits<int32_t>::max()) || bytes > options.maxImageBytes)
            throw Error(fmt::format("{} as an image of {}x{}x{} voxels would take {} bytes, over the limit of {} (--max-bytes){}: {}, or write a .vtu of the active voxels",
                                    what, size.dim[0], size.dim[1], size.dim[2], withCommas(bytes),
                                    withCommas(options.maxImageBytes), dense ? "" : " although only " + withCommas(grid.activeVoxelCount()) + " voxels are active",
                                    limitAdvice()));
        plan.cells = cells;
    } else {
        plan.clip = bool(box);
        if (box) plan.region = *box;
        plan.cells = countCells(grid.tree(), box);
        if (plan.cells > options.maxCells)
            throw Error(fmt::format("{} has {} active cells{}, over the limit of {} (--max-cells): {}", what, withCommas(plan.cells),
                                    box ? " in the box" : "", withCommas(options.maxCells), limitAdvice()));
    }
    return plan;
}

std::string arrayName(const LoadedGrid& loaded) {
    return loaded.grid->getName().empty() ? "grid_" + std::to_string(loaded.fileIndex) : loaded.grid->getName();
}

template <typename GridT>
vtkSmartPointer<vtkDataObject> buildUnstructured(const GridT& grid, const LoadedGrid& loaded, const Plan& plan, Progress& progress,
                                                 VtkBlockReport& report) {
    using TreeT = typename GridT::TreeType;
    using ValueT = typename GridT::ValueType;
    const TreeT& tree = grid.tree();
    detail::VoxelCellBuilder cells(grid.transform());
    std::optional<detail::ValueColumn<ValueT>> values;
    if constexpr (kHasValues<GridT>)
        values.emplace(arrayName(loaded), detail::isColourGrid(grid), vtkIdType(plan.cells), detail::scanSampleVtkType(grid));
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        progress.advance();
        if (plan.clip && !leaf->getNodeBoundingBox().hasOverlap(plan.region)) continue;
        cells.beginLeaf(leaf->origin());
        for (auto v = leaf->cbeginValueOn(); v; ++v) {
            if (plan.clip && !plan.region.isInside(v.getCoord())) continue;
            cells.addVoxel(v.getCoord());
            if constexpr (kHasValues<GridT>) values->push(*v);
        }
    }
    typename TreeT::ValueOnCIter tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        openvdb::CoordBBox box = tiles.getBoundingBox();
        if (plan.clip) {
            if (!box.hasOverlap(plan.region)) continue;
            box.intersect(plan.region);
        }
        cells.addBox(box);
        ++report.tileCells;
        if constexpr (kHasValues<GridT>) values->push(*tiles);
    }
    report.cells = cells.cellCount();
    auto ugrid = cells.finish();
    if (values) ugrid->GetCellData()->AddArray(values->array());
    return ugrid;
}

template <typename GridT>
vtkSmartPointer<vtkDataObject> buildImage(const GridT& grid, const LoadedGrid& loaded, const Plan& plan, VtkBlockReport& report) {
    using TreeT = typename GridT::TreeType;
    using ValueT = typename GridT::ValueType;
    const openvdb::CoordBBox& region = plan.region;
    const openvdb::Coord dim = region.dim();
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(dim.x() + 1, dim.y() + 1, dim.z() + 1);  // points at voxel corners, a cell per voxel
    // world = [i j k 1] * M; the image's axes are M's rows, its origin the region's first corner.
    const openvdb::Mat4d m = grid.transform().baseMap()->getAffineMap()->getMat4();
    const openvdb::Vec3d origin = m.transform(openvdb::Vec3d(region.min().x() - 0.5, region.min().y() - 0.5, region.min().z() - 0.5));
    double spacing[3], direction[9];
    for (int c = 0; c < 3; ++c) {
        const openvdb::Vec3d axis(m(c, 0), m(c, 1), m(c, 2));
        spacing[c] = axis.length();
        for (int r = 0; r < 3; ++r) direction[3 * r + c] = axis[r] / spacing[c];
    }
    image->SetOrigin(origin.x(), origin.y(), origin.z());
    image->SetSpacing(spacing);
    image->SetDirectionMatrix(direction);
    const uint64_t cells = plan.cells;
    const auto cellIndex = [&](const openvdb::Coord& c) {
        return vtkIdType((c.x() - region.min().x()) + int64_t(dim.x()) * ((c.y() - region.min().y()) + int64_t(dim.y()) * (c.z() - region.min().z())));
    };
    if constexpr (kHasValues<GridT>) {
        openvdb::tools::Dense<ValueT, openvdb::tools::LayoutXYZ> dense(region);  // x fastest, as VTK's cells
        openvdb::tools::copyToDense(grid, dense);
        detail::ValueColumn<ValueT> values(arrayName(loaded), detail::isColourGrid(grid), vtkIdType(cells), detail::scanSampleVtkType(grid));
        const ValueT* data = dense.data();
        for (uint64_t i = 0; i < cells; ++i) values.push(data[i]);
        image->GetCellData()->AddArray(values.array());
    }
    vtkNew<vtkUnsignedCharArray> activeFlags;
    activeFlags->SetName("active");
    activeFlags->SetNumberOfValues(vtkIdType(cells));
    activeFlags->FillValue(0);
    const TreeT& tree = grid.tree();
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        if (!leaf->getNodeBoundingBox().hasOverlap(region)) continue;
        for (auto v = leaf->cbeginValueOn(); v; ++v)
            if (region.isInside(v.getCoord())) activeFlags->SetValue(cellIndex(v.getCoord()), 1);
    }
    typename TreeT::ValueOnCIter tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        openvdb::CoordBBox box = tiles.getBoundingBox();
        if (!box.hasOverlap(region)) continue;
        box.intersect(region);
        for (int z = box.min().z(); z <= box.max().z(); ++z)
            for (int y = box.min().y(); y <= box.max().y(); ++y)
                for (int x = box.min().x(); x <= box.max().x(); ++x) activeFlags->SetValue(cellIndex(openvdb::Coord(x, y, z)), 1);
    }
    image->GetCellData()->AddArray(activeFlags);
    report.cells = cells;
    report.region = {region.min().x(), region.min().y(), region.min().z(), region.max().x(), region.max().y(), region.max().z()};
    return image;
}

} // namespace

VtkExportReport exportVtk(const std::string& input, const std::string& output, const VtkExportOptions& options) {
    const std::string ext = detail::extensionOf(output);
    if (ext != ".vtu" && ext != ".vti" && ext != ".vtm") throw Error(output + ": unknown output type '" + ext + "' (use .vtu, .vti or .vtm)");
    const detail::Compressor compressor = detail::parseCompressor(options.compressor);
    if (options.bbox) {
        const auto& b = *options.bbox;
        if (b[0] > b[3] || b[1] > b[4] || b[2] > b[5]) throw Error("--bbox: each minimum must not exceed its maximum (X0,Y0,Z0,X1,Y1,Z1)");
    }
    const std::vector<LoadedGrid> grids = detail::loadGrids(input, options.grids, options.limits);
    if (grids.empty()) throw Error(input + ": holds no grids to export");
    if (ext != ".vtm" && grids.size() > 1)
        throw Error(fmt::format("{}: {} grids selected but a {} holds one: pick one with --grid NAME or write a .vtm", input, grids.size(), ext));

    // Plan everything (and check every limit) before building anything.
    std::vector<Plan> plans;
    uint64_t leaves = 0;
    for (const LoadedGrid& g : grids)
        detail::dispatchGridType(*g.grid, [&](const auto& grid, ValueType) {
            plans.push_back(planGrid(grid, g, input, ext, options));
            leaves += grid.tree().leafCount();
        });

    VtkExportReport report;
    vtkNew<vtkMultiBlockDataSet> blocks;
    vtkSmartPointer<vtkDataObject> single;
    Progress progress("export", leaves);
    for (size_t i = 0; i < grids.size(); ++i) {
        VtkBlockReport block;
        block.grid = grids[i].grid->getName();
        block.fileIndex = grids[i].fileIndex;
        block.valueType = grids[i].grid->valueType();
        block.kind = plans[i].image ? "image" : "unstructured";
        vtkSmartPointer<vtkDataObject> data;
        detail::dispatchGridType(*grids[i].grid, [&](const auto& grid, ValueType) {
            data = plans[i].image ? buildImage(grid, grids[i], plans[i], block) : buildUnstructured(grid, grids[i], plans[i], progress, block);
        });
        if (ext == ".vtm") detail::setBlock(blocks, unsigned(i), data, arrayName(grids[i]));
        else single = data;
        report.blocks.push_back(block);
    }
    progress.finish();
    detail::writeVtk(ext == ".vtm" ? static_cast<vtkDataObject*>(blocks.Get()) : single.Get(), output, compressor);
    report.bytes = detail::writtenBytes(output);
    return report;
}

} // namespace vdbdag::bridge
