// See AttributeLayout.h.
#include "src/encoding/AttributeLayout.h"

#include <bit>

#include "src/util/Error.h"

namespace vdbdag::encoding {

std::vector<uint64_t> attributeLayout(const CompactDag& dag) {
    std::vector<uint64_t> layout;
    if (dag.empty()) return layout;
    const uint64_t emitted = decodedSize(dag).emittedBricks;
    // The walk stops at 2^31 bricks too; checked here so the reserve never asks for more.
    if (emitted > (uint64_t(1) << 31))
        throw Error("the DAG emits " + std::to_string(emitted) + " bricks, more than the 2^31 a predicted-value layout holds");
    layout.reserve(size_t(emitted));
    uint64_t next = 0;
    visitInAttributeOrder(
        dag,
        [&](const BrickInstance& b) {
            if (b.firstEntry != next) throw Error("internal error: attribute order is not sequential");
            layout.push_back(b.storedMask);
            next += uint64_t(std::popcount(b.storedMask));
        },
        [&](int64_t, int64_t, int64_t, unsigned, uint64_t entry) {
            if (entry != next) throw Error("internal error: attribute order is not sequential");
            layout.push_back(0);
            ++next;
        });
    return layout;
}

std::vector<coding::BrickPlace> attributePlaces(const CompactDag& dag, uint32_t valueSize) {
    std::vector<coding::BrickPlace> places;
    if (dag.empty() || (valueSize != 4 && valueSize != 12)) return places;  // int32, float32, vec3s
    const uint64_t emitted = decodedSize(dag).emittedBricks;
    if (emitted > (uint64_t(1) << 31))
        throw Error("the DAG emits " + std::to_string(emitted) + " bricks, more than the 2^31 a predicted-value layout holds");
    places.reserve(size_t(emitted));
    visitInAttributeOrder(
        dag, [&](const BrickInstance& b) { places.push_back({int32_t(b.x), int32_t(b.y), int32_t(b.z), b.mirror}); },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t) { places.push_back(coding::tilePlace(x, y, z, log2Size)); });
    return places;
}

} // namespace vdbdag::encoding
