// libFuzzer target for the .ssvdag reader: container, sections and DAG
// validation, then a decode of whatever validated. Any input must end in
// success or vdbdag::Error; anything else (crash, sanitizer report, other
// exception, timeout) is a bug. Run: scripts/fuzz.sh [SECONDS]
#include <cstddef>
#include <cstdint>
#include <span>

#include "src/encoding/CompactDag.h"
#include "src/format/SsvdagFile.h"
#include "src/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        const vdbdag::format::SsvdagScene scene = vdbdag::format::readScene(std::span<const uint8_t>(data, size), "fuzz");
        for (const auto& grid : scene.grids) {
            uint64_t visited = 0;
            vdbdag::encoding::visitInstances(
                grid.dag, [&](int64_t, int64_t, int64_t, uint64_t) { ++visited; }, [&](int64_t, int64_t, int64_t, unsigned) { ++visited; });
        }
    } catch (const vdbdag::Error&) {
    }
    return 0;
}
