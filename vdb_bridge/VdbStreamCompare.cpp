// See VdbStreamCompare.h. Per grid and layer, the scene's cubes come in
// attribute order, each one decoded into a small dense buffer (detail::DecodedCube);
// the original's voxels in the cube's box are then visited node by node
// through OpenVDB's accessor (walkRegion) and looked up in that buffer.
// What the original holds outside every cube is caught by counting: the
// layer's voxels in the original (its active voxel count, or its stored
// inactive values) must all have been met inside some cube.
//
// A leaf is dropped (replaced by a background tile) once the cubes that
// cover it are all done, so the original's loaded buffers are those of the
// leaves straddling the cubes in progress. The inactive layer reads the
// grid afresh, since the active pass drops the leaves whose inactive values
// it needs.
#include "vdb_bridge/VdbStreamCompare.h"

#include <bit>
#include <type_traits>
#include <unordered_map>

#include "src/pipeline/LayerScatter.h"
#include "src/util/Error.h"
#include "src/util/MappedPages.h"
#include "vdb_bridge/detail/DecodedCube.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/HeaderCompare.h"
#include "vdb_bridge/detail/LeafBricks.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {
namespace {

constexpr size_t kDropsPerRelease = 8192;  // leaves dropped between releases of the file's mapped pages
constexpr size_t kExamples = 8;

struct CoordHash {
    size_t operator()(const openvdb::Coord& c) const {
        return size_t(uint64_t(uint32_t(c.x())) * 0x9E3779B97F4A7C15ull ^ uint64_t(uint32_t(c.y())) * 0xC2B2AE3D27D4EB4Full ^ uint64_t(uint32_t(c.z())));
    }
};

// One layer of one grid: the scene's cubes against the original grid, read
// with delayed loading (and emptied as the cubes go).
template <typename GridT>
class LayerCheck {
    using TreeT = typename GridT::TreeType;
    using LeafT = typename TreeT::LeafNodeType;
    using ValueT = typename GridT::ValueType;
    using TopNodeT = typename TreeT::RootNodeType::ChildNodeType;

public:
    static constexpr bool kHasValues = !std::is_same_v<typename LeafT::BuildType, openvdb::ValueMask>;

    LayerCheck(const std::string& path, GridT& grid, bool inactive, bool values)
        : path_(path), tree_(grid.tree()), access_(tree_), background_(tree_.background()), inactive_(inactive), values_(values && kHasValues) {
        if (!inactive_) {
            expected_ = tree_.activeVoxelCount();
            return;
        }
        // The inactive tiles whose value is not the background; the leaves'
        // inactive values are counted as each leaf is first met.
        typename TreeT::ValueAllCIter it = tree_.cbeginValueAll();
        it.setMaxDepth(TreeT::ValueAllCIter::LEAF_DEPTH - 1);
        for (; it; ++it)
            if (it.isTileValue() && !it.isValueOn() && !detail::sameBits(ValueT(*it), background_)) expected_ += it.getBoundingBox().volume();
    }

    void check(const detail::DecodedCube& cube) {
        cube_ = &cube;
        matchedInCube_ = 0;
        if (!cube.uniform()) {
            metBits_.resize(std::max(metBits_.size(), cube.words()));
            std::fill(metBits_.begin(), metBits_.begin() + cube.words(), 0);
        }
        walkRegion<TopNodeT>(cube.box());
        if (cube.voxels() > matchedInCube_) {
            onlyInDecoded_ += cube.voxels() - matchedInCube_;
            exampleOnlyInDecoded(cube);
        }
        for (const openvdb::Coord& origin : drops_) drop(origin);
        drops_.clear();
        access_.clear();
    }

    // After the last cube: the layer's voxels of the original met in no cube.
    void finish() {
        if (inactive_) {  // the leaves no cube met: their stored inactive values
            std::vector<openvdb::Coord> rest;
            for (auto it = tree_.cbeginLeaf(); it; ++it) rest.push_back(it->origin());
            for (const openvdb::Coord& origin : rest) {
                if (!pending_.count(origin))
                    if (const LeafT* leaf = tree_.probeConstLeaf(origin)) expected_ += storedInactive(*leaf);
                drop(origin);
            }
            access_.clear();
        }
        pending_.clear();
        if (expected_ > met_) onlyInOriginal_ += expected_ - met_;
    }

    uint64_t onlyInOriginal() const { return onlyInOriginal_; }
    uint64_t onlyInDecoded() const { return onlyInDecoded_; }
    uint64_t valuesDiffering() const { return valuesDiffering_; }
    // Voxels in one side only, and values that differ.
    const std::vector<std::string>& placeExamples() const { return placeExamples_; }
    const std::vector<std::string>& valueExamples() const { return valueExamples_; }

private:
    // The original's nodes in `box`, from NodeT's level down: leaves, and
    // tiles (or the background) as boxes.
    template <typename NodeT>
    void walkRegion(const openvdb::CoordBBox& box) {
        constexpr int64_t dim = int64_t(NodeT::DIM);
        const auto floorTo = [](int32_t v) { return int64_t(v) & ~(dim - 1); };
        for (int64_t z = floorTo(box.min().z()); z <= box.max().z(); z += dim)
            for (int64_t y = floorTo(box.min().y()); y <= box.max().y(); y += dim)
                for (int64_t x = floorTo(box.min().x()); x <= box.max().x(); x += dim) {
                    const openvdb::Coord c{int32_t(x), int32_t(y), int32_t(z)};
                    openvdb::CoordBBox region(c, c.offsetBy(int32_t(dim - 1)));
                    region.intersect(box);
                    if (const NodeT* node = access_.template probeConstNode<NodeT>(c)) {
                        if constexpr (NodeT::LEVEL == 0) leaf(*node, region);
                        else walkRegion<typename NodeT::ChildNodeType>(region);
                    } else {
                        ValueT v;
                        const bool on = access_.probeValue(c, v);
                        tile(region, v, on);
                    }
                }
    }

    bool inLayer(bool on, const ValueT& v) const { return inactive_ ? !on && !detail::sameBits(v, background_) : on; }

    void leaf(const LeafT& node, const openvdb::CoordBBox& region) {
        const bool whole = region.volume() == LeafT::SIZE;
        if (inactive_) {
            auto found = pending_.find(node.origin());
            if (whole || found == pending_.end()) expected_ += storedInactive(node);  // first met
            for (openvdb::Index n = 0; n < LeafT::SIZE; ++n) {
                const ValueT& v = node.getValue(n);
                if (!inLayer(node.isValueOn(n), v)) continue;
                const openvdb::Coord c = node.offsetToGlobalCoord(n);
                if (whole || region.isInside(c)) meet(c, v);
            }
        } else {
            for (auto it = node.cbeginValueOn(); it; ++it) {
                const openvdb::Coord c = it.getCoord();
                if (!whole && !region.isInside(c)) continue;
                if constexpr (kHasValues) meet(c, values_ ? ValueT(*it) : ValueT());
                else meet(c, true);
            }
        }
        if (whole) {
            drops_.push_back(node.origin());
            return;
        }
        uint32_t& covered = pending_[node.origin()];
        covered += uint32_t(region.volume());
        if (covered >= LeafT::SIZE) {
            pending_.erase(node.origin());
            drops_.push_back(node.origin());
        }
    }

    void tile(const openvdb::CoordBBox& region, const ValueT& v, bool on) {
        if (!inLayer(on, v)) return;
        if (cube_->uniform()) {
            met_ += region.volume();
            matchedInCube_ += region.volume();
            if (values_ && !detail::sameBits(v, detail::valueFromBytes<ValueT>(cube_->value(0)))) differs(region.min(), v, cube_->value(0), region.volume());
            return;
        }
        for (int32_t z = region.min().z(); z <= region.max().z(); ++z)
            for (int32_t y = region.min().y(); y <= region.max().y(); ++y)
                for (int32_t x = region.min().x(); x <= region.max().x(); ++x) meet(openvdb::Coord(x, y, z), v);
    }

    // A voxel of the layer in the original, inside the cube.
    void meet(const openvdb::Coord& c, const ValueT& v) {
        ++met_;
        const size_t i = cube_->index(c);
        if (!cube_->has(i)) {
            ++onlyInOriginal_;
            example(placeExamples_, "voxel " + detail::showCoord(c) + (inactive_ ? " has a stored inactive value only in the original" : " active only in the original"));
            return;
        }
        ++matchedInCube_;
        if (!cube_->uniform()) metBits_[i >> 6] |= uint64_t(1) << (i & 63);
        if (values_ && !detail::sameBits(v, detail::valueFromBytes<ValueT>(cube_->value(i)))) differs(c, v, cube_->value(i), 1);
    }

    void differs(const openvdb::Coord& c, const ValueT& original, const uint8_t* decoded, uint64_t count) {
        valuesDiffering_ += count;
        example(valueExamples_, std::string(inactive_ ? "inactive" : "active") + " value at " + detail::showCoord(c) + ": " + detail::showValue(original) + " vs " +
                detail::showValue(detail::valueFromBytes<ValueT>(decoded)) + (count > 1 ? " (a tile of " + std::to_string(count) + " voxels)" : ""));
    }

    static void example(std::vector<std::string>& to, std::string line) {
        if (to.size() < kExamples) to.push_back(std::move(line));
    }

    // A voxel of the cube that the original's walk did not meet.
    void exampleOnlyInDecoded(const detail::DecodedCube& cube) {
        const std::string what = inactive_ ? " has a stored inactive value only in the decoded grid" : " active only in the decoded grid";
        if (cube.uniform()) {
            example(placeExamples_, "tile of " + std::to_string(cube.box().dim().x()) + "^3 at " + detail::showCoord(cube.box().min()) + what);
            return;
        }
        for (size_t w = 0; w < cube.words(); ++w)
            if (const uint64_t rest = cube.word(w) & ~metBits_[w]) {
                example(placeExamples_, "voxel " + detail::showCoord(cube.coordOf(w * 64 + size_t(std::countr_zero(rest)))) + what);
                return;
            }
    }

    uint64_t storedInactive(const LeafT& node) const {
        uint64_t n = 0;
        for (openvdb::Index i = 0; i < LeafT::SIZE; ++i)
            if (inLayer(node.isValueOn(i), node.getValue(i))) ++n;
        return n;
    }

    void drop(const openvdb::Coord& origin) {
        tree_.addTile(1, origin, background_, false);
        if (++dropped_ % kDropsPerRelease == 0) releaseMappedPages(path_);
    }

    const std::string& path_;
    TreeT& tree_;
    openvdb::tree::ValueAccessor<TreeT> access_;
    const ValueT background_;
    const bool inactive_, values_;
    const detail::DecodedCube* cube_ = nullptr;
    uint64_t expected_ = 0, met_ = 0, matchedInCube_ = 0;
    uint64_t onlyInOriginal_ = 0, onlyInDecoded_ = 0, valuesDiffering_ = 0;
    std::vector<std::string> placeExamples_, valueExamples_;
    std::unordered_map<openvdb::Coord, uint32_t, CoordHash> pending_;  // leaves partly covered: voxels covered so far
    std::vector<openvdb::Coord> drops_;
    std::vector<uint64_t> metBits_;  // the cube's voxels met in the original
    uint64_t dropped_ = 0;
};

// The cube size a layer is decoded at: its dense buffer stays under 16 MiB.
unsigned cutFor(unsigned valueSize) { return valueSize > 8 ? 6 : 7; }

} // namespace

CompareResult compareSceneWithFile(const std::string& originalPath, const format::SsvdagScene& scene, bool values, const CompareProgress& progress) {
    const detail::VdbFileIndex index = detail::indexVdbFile(originalPath);
    CompareResult result;
    if (index.uniqueNames.size() != scene.grids.size())
        result.headerDifferences.push_back("grid count differs (" + std::to_string(index.uniqueNames.size()) + " vs " + std::to_string(scene.grids.size()) + ")");
    detail::compareFileMetadata(*index.metadata, *detail::parseMetadata(scene.fileMetadata, originalPath + " (decoded)"), result.headerDifferences);
    for (size_t g = 0; g < std::min(index.uniqueNames.size(), scene.grids.size()); ++g) {
        const format::EncodedGrid& encoded = scene.grids[g];
        const std::string what = originalPath + " (decoded grid " + std::to_string(g) + ")";
        const openvdb::GridBase::Ptr header = detail::buildGrid(encoded.record, what);
        TopologyDifference topology;
        topology.gridIndex = g;
        ValueDifference valueDifference;
        valueDifference.gridIndex = g;
        for (const bool inactive : {false, true}) {
            if (inactive && !values) break;
            const openvdb::GridBase::Ptr original = detail::readGridDelayed(originalPath, index.uniqueNames[g]);
            topology.gridName = valueDifference.gridName = original->getName();
            if (!inactive) {
                detail::compareHeaders(g, *original, *header, result.headerDifferences);
                if (values && original->type() != header->type()) {
                    result.headerDifferences.push_back("grid " + std::to_string(g) + " '" + original->getName() + "': type differs (" + original->type() +
                                                       " vs " + header->type() + ")");
                    break;
                }
            }
            const bool supported = detail::dispatchMutableGridType(*original, [&](auto& typed) {
                using GridT = std::decay_t<decltype(typed)>;
                using Check = LayerCheck<GridT>;
                if (inactive && !Check::kHasValues) return;
                if (!inactive && values && Check::kHasValues && !detail::sameBits(typed.background(), static_cast<const GridT&>(*header).background()))
                    result.headerDifferences.push_back("grid " + std::to_string(g) + " '" + original->getName() + "': background differs");
                const unsigned vs = values ? valueSize(encoded.record.valueType) : 0;
                const unsigned cut = cutFor(vs);
                detail::DecodedCube cube(vs, cut);
                Check check(originalPath, typed, inactive, values);
                const std::string step = "grid '" + original->getName() + "': " + (inactive ? "inactive values" : "active voxels");
                pipeline::LayerCubes visit;
                visit.begin = [&](const encoding::SubtreeInstance& s) { cube.begin(s, what); };
                visit.voxels.brick = [&](int64_t x, int64_t y, int64_t z, uint64_t mask, const uint8_t* v) { cube.brick(x, y, z, mask, v); };
                visit.voxels.solid = [&](int64_t x, int64_t y, int64_t z, unsigned log2, const uint8_t* v) { cube.solid(x, y, z, log2, v); };
                visit.end = [&] { check.check(cube); };
                pipeline::scatterLayerByCubes(encoded, inactive, cut, visit, [&](uint64_t done, uint64_t total) {
                    if (progress) progress(step, done, total);
                });
                check.finish();
                if (inactive) {
                    valueDifference.inactiveValues += check.onlyInOriginal() + check.onlyInDecoded() + check.valuesDiffering();
                    for (const auto* list : {&check.placeExamples(), &check.valueExamples()})
                        valueDifference.examples.insert(valueDifference.examples.end(), list->begin(), list->end());
                } else {
                    topology.onlyInA += check.onlyInOriginal();
                    topology.onlyInB += check.onlyInDecoded();
                    valueDifference.activeValues += check.valuesDiffering();
                    topology.examples.insert(topology.examples.end(), check.placeExamples().begin(), check.placeExamples().end());
                    valueDifference.examples.insert(valueDifference.examples.end(), check.valueExamples().begin(), check.valueExamples().end());
                }
            });
            if (!supported) {
                result.headerDifferences.push_back("grid " + std::to_string(g) + " '" + original->getName() + "': unsupported type '" + original->type() + "'");
                break;
            }
        }
        if (topology.onlyInA || topology.onlyInB) {
            if (topology.examples.empty() && topology.onlyInA) topology.examples.push_back("active voxels of the original outside every decoded cube");
            result.topology.push_back(std::move(topology));
        }
        if (valueDifference.activeValues || valueDifference.inactiveValues) result.values.push_back(std::move(valueDifference));
    }
    result.identical = result.headerDifferences.empty() && result.topology.empty() && result.values.empty();
    return result;
}

} // namespace vdbdag::bridge
