// What `vdb_print -l` tells of a grid, taken from an encoded grid without
// decoding it: the active voxels' index bounding box from the DAG (bottom-up,
// one visit per stored node, reflections applied), and the active values'
// range from the value windows one window at a time (never the whole
// channel, never the palette compressor). vdb_bridge/VdbSummary.h computes
// the same from a .vdb with OpenVDB, so the two can be compared.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/encoding/CompactDag.h"
#include "src/format/DagBounds.h"
#include "src/format/SsvdagFile.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::format {


// Minimum and maximum of raw values as OpenVDB's tools::minMax finds them,
// by the value type's `<` made total (attributes/ValueRange.h).
using ValueRange = attributes::ValueRange;

struct GridSummary {
    uint64_t activeVoxels = 0;
    uint64_t solidNodes = 0;          // DAG nodes that are whole active cubes (a .vdb's active tiles)
    std::optional<IndexBox> indexBox;  // active voxels
    ValueRange activeRange;            // active values (tiles once each)
};
// `grid` as read with ReadOptions::keepValueWindows (or fully): from its
// Summary section when the file has one, else from its DAG and values.
GridSummary summarizeGrid(const EncodedGrid& grid);
// What an encoder stores in `grid`'s Summary section, once the grid is
// whole: the one read, or the grid's summary (its value range the value
// writer's where it kept one: no value is decoded).
StoredSummary summaryToStore(const EncodedGrid& grid);
// The same from the grid's DAG and values, whatever its Summary says (the
// check of `info --values`).
StoredSummary recomputedSummary(const EncodedGrid& grid);

// A value as OpenVDB's operator<< prints it (6 significant digits, vectors
// as "[x, y, z]"), and as JSON-ready doubles (one, or three for vectors).
std::string formatValue(ValueType type, std::span<const uint8_t> value);
std::vector<double> valueNumbers(ValueType type, std::span<const uint8_t> value);

} // namespace vdbdag::format
