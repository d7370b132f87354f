// libFuzzer target for what lies behind the container's checksums: section
// payload parsing, DAG validation and decoding. The input is a list of
// sections in a checksum-free framing (u8 count, then per section u8 kind,
// u8 grid, u16 length, payload), so mutations reach the parsers instead of
// failing the checksum. Run: scripts/fuzz.sh [SECONDS]
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "src/encoding/CompactDag.h"
#include "src/format/SsvdagFile.h"
#include "src/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace vdbdag;
    if (size < 1) return 0;
    std::vector<format::Section> sections;
    size_t pos = 1;
    for (unsigned i = 0; i < data[0] && pos + 4 <= size; ++i) {
        const uint8_t kind = data[pos], grid = data[pos + 1];
        uint16_t length;
        std::memcpy(&length, data + pos + 2, 2);
        pos += 4;
        if (length > size - pos) length = uint16_t(size - pos);
        sections.push_back({format::SectionKind(kind), grid, std::vector<uint8_t>(data + pos, data + pos + length)});
        pos += length;
    }
    try {
        const format::SsvdagScene scene = format::sectionsToScene(std::move(sections), "fuzz");
        for (const auto& grid : scene.grids) {
            uint64_t visited = 0;
            encoding::visitInstances(
                grid.active.dag, [&](int64_t, int64_t, int64_t, uint64_t) { ++visited; }, [&](int64_t, int64_t, int64_t, unsigned) { ++visited; });
        }
    } catch (const Error&) {
    }
    return 0;
}
