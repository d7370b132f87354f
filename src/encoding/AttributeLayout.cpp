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

} // namespace vdbdag::encoding
