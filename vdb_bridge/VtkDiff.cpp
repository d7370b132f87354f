// See VtkDiff.h. The union of the two active topologies comes from
// OpenVDB's own topologyUnion on MaskTree copies; values come through
// OpenVDB accessors, so this is independent of the DAG code.
#include "vdb_bridge/VtkDiff.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/core.h>

#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkUnsignedCharArray.h>

#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/detail/GridSource.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VoxelCells.h"
#include "vdb_bridge/detail/VtkWriting.h"

namespace vdbdag::bridge {
namespace {

using detail::LoadedGrid;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

template <typename T>
constexpr int componentsOf() {
    if constexpr (openvdb::VecTraits<T>::IsVec) return 3;
    else return 1;
}

template <typename T>
void toDoubles(const T& v, double* out) {
    if constexpr (openvdb::VecTraits<T>::IsVec) {
        for (int c = 0; c < 3; ++c) out[c] = double(v[c]);
    } else {
        out[0] = double(v);
    }
}

// Tile width of the node at tree depth d (ValueAccessor::getValueDepth: 0 root tile, -1 background).
template <typename TreeT>
int64_t widthAtDepth(int d) {
    using RootChild = typename TreeT::RootNodeType::ChildNodeType;
    using MidChild = typename RootChild::ChildNodeType;
    switch (d) {
        case -1: return std::numeric_limits<int64_t>::max();
        case 0: return RootChild::DIM;
        case 1: return MidChild::DIM;
        case 2: return TreeT::LeafNodeType::DIM;
        default: return 1;
    }
}

// Accumulates statistics and (optionally) cells.
template <typename GridT>
class DiffBuilder {
public:
    using ValueT = typename GridT::ValueType;
    static constexpr bool kHasValues = !std::is_same_v<typename GridT::TreeType::LeafNodeType::BuildType, openvdb::ValueMask>;
    static constexpr int kComps = componentsOf<ValueT>();

    DiffBuilder(const GridT& a, bool buildCells, const DiffOptions& options, const std::string& what)
        : buildCells_(buildCells), options_(options), what_(what), cells_(a.transform()) {
        if (kHasValues) {
            for (auto* arr : {aValues_.Get(), bValues_.Get()}) arr->SetNumberOfComponents(kComps);
            aValues_->SetName("a");
            bValues_->SetName("b");
        }
        absError_->SetName("abs_error");
        relError_->SetName("rel_error");
        status_->SetName("status");
    }

    void beginLeaf(const openvdb::Coord& origin) { cells_.beginLeaf(origin); }

    // One voxel (box == nullptr) or one uniform box of `weight` voxels.
    void add(const openvdb::Coord& ijk, const openvdb::CoordBBox* box, uint64_t weight, bool aOn, bool bOn, const ValueT& va, const ValueT& vb) {
        unsigned status;
        double da[3] = {kNaN, kNaN, kNaN}, db[3] = {kNaN, kNaN, kNaN};
        double absErr = kNaN, relErr = kNaN;
        if (kHasValues) {
            if (aOn) toDoubles(va, da);
            if (bOn) toDoubles(vb, db);
        }
        if (aOn && bOn) {
            status = sameBits(va, vb) ? 0 : 1;
            double sq = 0, na = 0, nb = 0;
            for (int c = 0; c < kComps; ++c) {
                sq += (da[c] - db[c]) * (da[c] - db[c]);
                na += da[c] * da[c];
                nb += db[c] * db[c];
            }
            absErr = status == 0 || !kHasValues ? 0.0 : std::sqrt(sq);
            const double scale = std::max(std::sqrt(na), std::sqrt(nb));
            relErr = absErr == 0 ? 0.0 : absErr / scale;
            if (std::isfinite(absErr)) {
                maxAbs_ = std::max(maxAbs_, absErr);
                if (std::isfinite(relErr)) maxRel_ = std::max(maxRel_, relErr);
                sum_ += absErr * double(weight);
                sumSq_ += absErr * absErr * double(weight);
                compared_ += weight;
            } else {
                nonFinite_ += weight;
            }
        } else {
            status = aOn ? 2 : 3;
            if (aOn && kHasValues) {  // against what B stores there (its background or inactive value)
                double dbInactive[3] = {kNaN, kNaN, kNaN}, sq = 0;
                toDoubles(vb, dbInactive);
                for (int c = 0; c < kComps; ++c) sq += (da[c] - dbInactive[c]) * (da[c] - dbInactive[c]);
                const double e = std::sqrt(sq);
                if (std::isfinite(e)) {
                    maxOnlyA_ = std::max(maxOnlyA_, e);
                    sumOnlyA_ += e * double(weight);
                    sumSqOnlyA_ += e * e * double(weight);
                    onlyA_ += weight;
                }
            }
        }
        if (aOn && kHasValues) {
            double mag = 0;
            if (kComps == 1) mag = da[0];
            else for (int c = 0; c < kComps; ++c) mag += da[c] * da[c];
            if (kComps == 3) mag = std::sqrt(mag);
            if (std::isfinite(mag)) { minA_ = std::min(minA_, mag); maxA_ = std::max(maxA_, mag); }
        }
        voxels_[status] += weight;
        if (!buildCells_ || (options_.onlyDifferences && status == 0)) return;
        if (cells_.cellCount() >= options_.maxCells)
            throw Error(fmt::format("{}: the diff has more than {} cells (--max-cells): compare fewer grids with --grid NAME, or use --only-differences",
                                    what_, options_.maxCells));
        if (box) cells_.addBox(*box);
        else cells_.addVoxel(ijk);
        if (kHasValues) {
            aValues_->InsertNextTuple(da);
            bValues_->InsertNextTuple(db);
        }
        absError_->InsertNextValue(absErr);
        relError_->InsertNextValue(relErr);
        status_->InsertNextValue(static_cast<unsigned char>(status));
    }

    void finish(GridDiff& d) {
        d.voxels = voxels_;
        d.nonFiniteErrors = nonFinite_;
        d.maxAbsError = maxAbs_;
        d.maxRelError = maxRel_;
        d.meanAbsError = compared_ ? sum_ / double(compared_) : 0.0;
        d.rmsError = compared_ ? std::sqrt(sumSq_ / double(compared_)) : 0.0;
        d.peak = maxA_ >= minA_ ? maxA_ - minA_ : 0.0;
        d.psnr = d.rmsError == 0 ? std::numeric_limits<double>::infinity() : d.peak > 0 ? 20.0 * std::log10(d.peak / d.rmsError) : kNaN;
        // Over every voxel of A, B's inactive value standing where B has no
        // active one: what a threshold (encode --background-below) costs.
        const uint64_t all = compared_ + onlyA_;
        d.ofA.voxels = all;
        d.ofA.maxAbsError = std::max(maxAbs_, maxOnlyA_);
        d.ofA.meanAbsError = all ? (sum_ + sumOnlyA_) / double(all) : 0.0;
        d.ofA.rmsError = all ? std::sqrt((sumSq_ + sumSqOnlyA_) / double(all)) : 0.0;
        d.ofA.psnr = d.ofA.rmsError == 0 ? std::numeric_limits<double>::infinity() : d.peak > 0 ? 20.0 * std::log10(d.peak / d.ofA.rmsError) : kNaN;
        d.cells = cells_.cellCount();
    }

    vtkSmartPointer<vtkUnstructuredGrid> grid() {
        auto g = cells_.finish();
        if (kHasValues) {
            g->GetCellData()->AddArray(aValues_);
            g->GetCellData()->AddArray(bValues_);
        }
        g->GetCellData()->AddArray(absError_);
        g->GetCellData()->AddArray(relError_);
        g->GetCellData()->AddArray(status_);
        g->GetCellData()->SetActiveScalars("status");
        return g;
    }

private:
    bool buildCells_;
    const DiffOptions& options_;
    std::string what_;
    detail::VoxelCellBuilder cells_;
    vtkNew<vtkDoubleArray> aValues_, bValues_, absError_, relError_;
    vtkNew<vtkUnsignedCharArray> status_;
    std::array<uint64_t, 4> voxels_{};
    uint64_t compared_ = 0, nonFinite_ = 0;
    double maxAbs_ = 0, maxRel_ = 0, sum_ = 0, sumSq_ = 0;
    uint64_t onlyA_ = 0;
    double maxOnlyA_ = 0, sumOnlyA_ = 0, sumSqOnlyA_ = 0;
    double minA_ = std::numeric_limits<double>::infinity(), maxA_ = -std::numeric_limits<double>::infinity();
};

template <typename GridT>
vtkSmartPointer<vtkUnstructuredGrid> diffGrids(const GridT& a, const GridT& b, bool buildCells, const DiffOptions& options, const std::string& what,
                                               Progress& progress, GridDiff& report) {
    using TreeT = typename GridT::TreeType;
    openvdb::MaskTree unionTree(a.tree(), false, openvdb::TopologyCopy());
    unionTree.topologyUnion(b.tree());
    auto accA = a.getConstAccessor();
    auto accB = b.getConstAccessor();
    DiffBuilder<GridT> builder(a, buildCells, options, what);
    for (auto leaf = unionTree.cbeginLeaf(); leaf; ++leaf) {
        progress.advance();
        builder.beginLeaf(leaf->origin());
        for (auto v = leaf->cbeginValueOn(); v; ++v) {
            const openvdb::Coord c = v.getCoord();
            builder.add(c, nullptr, 1, accA.isValueOn(c), accB.isValueOn(c), accA.getValue(c), accB.getValue(c));
        }
    }
    openvdb::MaskTree::ValueOnCIter tiles = unionTree.cbeginValueOn();
    tiles.setMaxDepth(openvdb::MaskTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        const openvdb::CoordBBox box = tiles.getBoundingBox();
        const int64_t width = box.dim().x();
        const openvdb::Coord c = box.min();
        if (widthAtDepth<TreeT>(accA.getValueDepth(c)) >= width && widthAtDepth<TreeT>(accB.getValueDepth(c)) >= width) {
            builder.add(c, &box, box.volume(), accA.isValueOn(c), accB.isValueOn(c), accA.getValue(c), accB.getValue(c));
            continue;
        }
        // One side is not uniform over the tile: walk its voxels, a leaf-sized block at a time.
        for (int z0 = box.min().z(); z0 <= box.max().z(); z0 += 8)
            for (int y0 = box.min().y(); y0 <= box.max().y(); y0 += 8)
                for (int x0 = box.min().x(); x0 <= box.max().x(); x0 += 8) {
                    builder.beginLeaf(openvdb::Coord(x0, y0, z0));
                    for (int z = z0; z < z0 + 8; ++z)
                        for (int y = y0; y < y0 + 8; ++y)
                            for (int x = x0; x < x0 + 8; ++x) {
                                const openvdb::Coord v(x, y, z);
                                builder.add(v, nullptr, 1, accA.isValueOn(v), accB.isValueOn(v), accA.getValue(v), accB.getValue(v));
                            }
                }
    }
    builder.finish(report);
    return buildCells ? builder.grid() : nullptr;
}

// Which grid of B each grid of A is compared with (DiffOptions::pairing);
// what is left unpaired is a header difference.
std::vector<std::pair<size_t, size_t>> pairGrids(const std::vector<LoadedGrid>& gridsA, const std::vector<LoadedGrid>& gridsB, const std::string& pathA,
                                                 const std::string& pathB, DiffPairing how, DiffReport& report) {
    std::vector<std::pair<size_t, size_t>> pairing;
    if (how == DiffPairing::Auto && gridsA.size() == 1 && gridsB.size() == 1) how = DiffPairing::Order;  // one grid each: whatever their names
    if (how == DiffPairing::Order) {
        const size_t n = std::min(gridsA.size(), gridsB.size());
        for (size_t i = 0; i < n; ++i) {
            pairing.emplace_back(i, i);
            if (gridsA[i].grid->getName() != gridsB[i].grid->getName())
                report.notes.push_back(fmt::format("grid {} of {} is compared with grid {} of {}", detail::gridLabel(gridsA[i]), pathA,
                                                   detail::gridLabel(gridsB[i]), pathB));
        }
        for (size_t i = n; i < gridsA.size(); ++i)
            report.headerDifferences.push_back(fmt::format("grid {} of {} has no counterpart in {}", detail::gridLabel(gridsA[i]), pathA, pathB));
        for (size_t j = n; j < gridsB.size(); ++j)
            report.headerDifferences.push_back(fmt::format("grid {} of {} has no counterpart in {}", detail::gridLabel(gridsB[j]), pathB, pathA));
        return pairing;
    }
    // By name, and among grids of the same name by their rank (the second
    // 'density' of A with the second 'density' of B).
    std::vector<bool> usedB(gridsB.size(), false);
    for (size_t i = 0; i < gridsA.size(); ++i) {
        const std::string& name = gridsA[i].grid->getName();
        size_t rank = 0;
        for (size_t k = 0; k < i; ++k) rank += gridsA[k].grid->getName() == name;
        size_t seen = 0, match = gridsB.size();
        for (size_t j = 0; j < gridsB.size() && match == gridsB.size(); ++j)
            if (gridsB[j].grid->getName() == name && seen++ == rank) match = j;
        if (match == gridsB.size()) {
            report.headerDifferences.push_back(fmt::format("grid {} of {} has no namesake in {}", detail::gridLabel(gridsA[i]), pathA, pathB));
            continue;
        }
        usedB[match] = true;
        pairing.emplace_back(i, match);
    }
    for (size_t j = 0; j < gridsB.size(); ++j)
        if (!usedB[j]) report.headerDifferences.push_back(fmt::format("grid {} of {} has no namesake in {}", detail::gridLabel(gridsB[j]), pathB, pathA));
    return pairing;
}

// Transforms that differ by at most 1e-6 of the voxel size (a NIfTI file's
// float32 affine against a NRRD's decimal one) are equal, with a note;
// anything else is a header difference.
void compareTransforms(const openvdb::GridBase& a, const openvdb::GridBase& b, const std::string& label, DiffReport& report) {
    if (a.transform() == b.transform()) return;
    const auto mapA = a.transform().baseMap()->getAffineMap(), mapB = b.transform().baseMap()->getAffineMap();
    const openvdb::Mat4d ma = mapA->getMat4(), mb = mapB->getMat4();
    const openvdb::Vec3d voxel = a.voxelSize();
    const double tolerance = kTransformTolerance * std::min({voxel[0], voxel[1], voxel[2]});
    double largest = 0;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) largest = std::max(largest, std::abs(ma(r, c) - mb(r, c)));
    const bool linear = a.transform().isLinear() && b.transform().isLinear();
    if (linear && largest <= tolerance) {
        report.notes.push_back(fmt::format("grid {}: the transforms are equal to 1e-6 of the voxel size (largest difference {:.3g})", label, largest));
        return;
    }
    report.headerDifferences.push_back(fmt::format("grid {}: the transforms differ (largest difference {:.6g}, more than 1e-6 of the voxel size); cells are placed with A's", label, largest));
}

} // namespace

DiffReport diffVolumes(const std::string& pathA, const std::string& pathB, const std::string& output, const DiffOptions& options) {
    std::string ext;
    if (!output.empty()) {
        ext = detail::extensionOf(output);
        if (ext != ".vtu" && ext != ".vtm") throw Error(output + ": a diff is written as .vtu (one grid) or .vtm (several grids)");
    }
    const detail::Compressor compressor = detail::parseCompressor(options.compressor);
    const std::vector<LoadedGrid> gridsA = detail::loadGrids(pathA, options.grids, options.limits);
    const std::vector<LoadedGrid> gridsB = detail::loadGrids(pathB, options.grids, options.limits);
    DiffReport report;
    const std::vector<std::pair<size_t, size_t>> pairing = pairGrids(gridsA, gridsB, pathA, pathB, options.pairing, report);
    const size_t pairs = pairing.size();
    if (ext == ".vtu" && pairs > 1)
        throw Error(fmt::format("{}: {} grid pairs to compare but a .vtu holds one: pick one with --grid NAME or write a .vtm", output, pairs));
    uint64_t leaves = 0;
    for (const auto& [ia, ib] : pairing) {
        const auto& a = *gridsA[ia].grid;
        const auto& b = *gridsB[ib].grid;
        if (a.type() != b.type())
            throw Error(fmt::format("grid {} of {} is {} but grid {} of {} is {}: only grids of the same type are compared", detail::gridLabel(gridsA[ia]),
                                    pathA, a.valueType(), detail::gridLabel(gridsB[ib]), pathB, b.valueType()));
        compareTransforms(a, b, detail::gridLabel(gridsA[ia]), report);
        leaves += a.baseTree().leafCount();
    }
    vtkNew<vtkMultiBlockDataSet> blocks;
    vtkSmartPointer<vtkDataObject> single;
    Progress progress("diff", leaves);
    for (size_t p = 0; p < pairs; ++p) {
        const size_t i = pairing[p].first, ib = pairing[p].second;
        GridDiff d;
        d.name = gridsA[i].grid->getName();
        d.indexA = gridsA[i].fileIndex;
        d.indexB = gridsB[ib].fileIndex;
        d.valueType = gridsA[i].grid->valueType();
        vtkSmartPointer<vtkUnstructuredGrid> cells;
        detail::dispatchGridType(*gridsA[i].grid, [&](const auto& a, ValueType) {
            using GridT = std::decay_t<decltype(a)>;
            const auto& b = static_cast<const GridT&>(*gridsB[ib].grid);
            cells = diffGrids(a, b, !output.empty(), options, pathA + " vs " + pathB + ": grid " + detail::gridLabel(gridsA[i]), progress, d);
        });
        if (ext == ".vtm") detail::setBlock(blocks, unsigned(p), cells, d.name.empty() ? "grid_" + std::to_string(d.indexA) : d.name);
        else single = cells;
        if (d.differs()) report.identical = false;
        report.grids.push_back(d);
    }
    progress.finish();
    if (!report.headerDifferences.empty()) report.identical = false;
    if (!output.empty()) {
        if (ext == ".vtu" && !single) {  // nothing to compare: an empty mesh
            detail::VoxelCellBuilder empty(*openvdb::math::Transform::createLinearTransform());
            single = empty.finish();
        }
        detail::writeVtk(ext == ".vtm" ? static_cast<vtkDataObject*>(blocks.Get()) : single.Get(), output, compressor);
        report.bytes = detail::writtenBytes(output);
    }
    return report;
}

} // namespace vdbdag::bridge
