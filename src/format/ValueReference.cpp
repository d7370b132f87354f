// See ValueReference.h.
#include "src/format/ValueReference.h"

#include <vector>

#include "src/encoding/AttributeLayout.h"
#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::format {

uint32_t parseValueReference(const Section& section, const std::string& sourceName) {
    ByteReader r(section.data, sourceName + ": grid " + std::to_string(section.grid) + " ValueReference");
    const uint32_t distance = r.get<uint32_t>();
    r.expectEnd();
    if (distance == 0) r.fail("names the grid itself");
    return distance;
}

attributes::ReferenceWindow readValueReference(const Section& section, uint32_t g, uint32_t first, SsvdagScene& scene, EncodedLayer& layer,
                                               std::span<const uint8_t> payload, unsigned vs, bool decodedNow, ReferenceReads& reads,
                                               const std::string& what, const std::string& sourceName) {
    ByteReader r(section.data, what + " ValueReference");
    const uint32_t distance = parseValueReference(section, sourceName);
    if (distance > g - first) r.fail("names grid " + std::to_string(int64_t(g) - distance) + ", not an earlier grid of this read");
    EncodedGrid& earlier = scene.grids[g - first - distance];
    EncodedLayer& other = earlier.active;
    const ValueType type = scene.grids[g - first].record.valueType;
    if (earlier.record.valueType != type || !other.valueWindows.predicted || other.valueWindows.empty() || other.dag != layer.dag)
        r.fail("names grid " + std::to_string(g - distance) + ", whose active voxels or values are not this grid's kind (the same DAG, type and predicted windows)");
    attributes::ValueWindowsPayload& windows = layer.valueWindows;
    windows.referenceDistance = distance;
    const std::vector<uint64_t> layout = encoding::attributeLayout(layer.dag);
    std::shared_ptr<const attributes::WindowReference>& node = reads.byGrid[g - distance];
    if (!node) {  // its payload once more: counted as what the read takes
        *reads.expanded = saturatingAdd(*reads.expanded, other.valueWindows.size());
        checkMemory(*reads.limits, *reads.expanded, what, "its sections and decoded values");
        node = std::make_shared<const attributes::WindowReference>(other.valueWindows.load(), vs, layout, other.valueWindows.reference,
                                                                   sourceName + ": grid " + std::to_string(g - distance) + " active predicted windows (a reference)");
    }
    windows.reference = node;
    if (!other.valueWindows.referencedBy) other.valueWindows.referencedBy = node;
    // The same windows (a float volume with fractions is cut in smaller ones than one of integers).
    if (!attributes::sameWindowCuts(attributes::readPredictedWindowDirectory(payload, vs, layout, what + " active predicted windows"), node->directory))
        r.fail("names grid " + std::to_string(g - distance) + ", whose values are cut into other windows");
    if (other.attributes.empty() || !decodedNow) return {};
    return attributes::windowsOf(other.attributes, node->directory);  // decoded already (used only during the decode that follows)
}

uint32_t referenceChainStart(uint32_t grid, const std::function<const Section*(uint32_t)>& referenceOf, const std::string& sourceName) {
    uint32_t first = grid;
    unsigned hops = 0;
    while (const Section* ref = referenceOf(first)) {
        const uint32_t distance = parseValueReference(*ref, sourceName);
        if (distance > first) throw Error(sourceName + ": grid " + std::to_string(first) + " ValueReference: names a grid before the first");
        if (++hops > attributes::kMaxReferenceChain)
            throw Error(sourceName + ": grid " + std::to_string(grid) + " takes its values' reference through more than " +
                        std::to_string(attributes::kMaxReferenceChain) + " grids");
        first -= distance;
    }
    return first;
}

uint32_t referenceChainStart(const std::string& path, uint32_t grid, const ReadLimits& limits) {
    std::map<uint32_t, Section> byGrid;
    for (Section& s : readContainerFile(path, false, limits, [&](SectionKind kind, uint32_t g) { return kind == SectionKind::ValueReference && g <= grid; }))
        byGrid[s.grid] = std::move(s);
    return referenceChainStart(grid, [&](uint32_t g) -> const Section* {
        const auto it = byGrid.find(g);
        return it == byGrid.end() ? nullptr : &it->second;
    }, path);
}

} // namespace vdbdag::format
