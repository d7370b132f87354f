// See FileRoundTrip.h.
#include "src/selftest/FileRoundTrip.h"

#include <numeric>

#include "src/format/TraceableValues.h"

namespace vdbdag::selftest {

FileRoundTrip roundTripThroughFile(const GridRecord& grid, const pipeline::EncodeOptions& options) {
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(grid, options));
    const std::vector<uint8_t> bytes = format::writeScene(scene);
    FileRoundTrip out;
    out.fileBytes = bytes.size();
    format::SsvdagScene back = format::readScene(bytes, "selftest grid '" + grid.name + "' (in memory)");
    out.stored = std::move(back.grids.at(0));
    out.traceable = format::traceableValues(out.stored, false);
    out.decoded = pipeline::decodeGrid(out.stored);
    return out;
}

uint64_t storedNodeCount(const format::DagStats& stats) {
    return std::accumulate(stats.storedNodes.begin(), stats.storedNodes.end(), uint64_t(0));
}

uint64_t svoNodeCount(const format::DagStats& stats) {
    return std::accumulate(stats.svoNodes.begin(), stats.svoNodes.end(), uint64_t(0));
}

} // namespace vdbdag::selftest
