// One grid through the whole core path the CLI takes, in memory: encodeGrid
// -> the .ssvdag container bytes (writeScene) -> readScene (which validates
// every section and the DAG) -> decodeGrid. The selftest cases then compare
// `decoded` with the input through the brute-force reference
// (SyntheticGrid.h) and read sizes off `stored`.
#pragma once
#include <cstdint>
#include <string>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::selftest {

struct FileRoundTrip {
    uint64_t fileBytes = 0;       // the whole .ssvdag file
    format::EncodedGrid stored;   // the grid as read back from the file (DAG, value windows, stats, lossy report)
    attributes::PaletteChannel traceable;  // its active values as the reader lays them out for tracing (format::traceableValues)
    GridRecord decoded;
    uint64_t channelBytes() const { return traceable.byteSize(); }  // traceable value channel
    uint64_t dagBytes() const { return stored.active.dag.byteSize(); }
};

FileRoundTrip roundTripThroughFile(const GridRecord& grid, const pipeline::EncodeOptions& options = {});

// Total stored (SSVDAG) and SVO node counts over all levels.
uint64_t storedNodeCount(const format::DagStats& stats);
uint64_t svoNodeCount(const format::DagStats& stats);

} // namespace vdbdag::selftest
