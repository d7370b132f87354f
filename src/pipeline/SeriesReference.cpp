// See SeriesReference.h.
#include "src/pipeline/SeriesReference.h"

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "src/attributes/PredictedWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"

namespace vdbdag::pipeline {
namespace {

// Whether grid `g`'s active values may refer to grid `r`'s (and the
// windows' cuts agree: sameWindows). A grid whose inside is a signed fill
// is left alone (a reader that keeps windows rebuilds its layers).
bool mayRefer(const format::EncodedGrid& g, const format::EncodedGrid& r) {
    const format::EncodedLayer& a = g.active;
    const format::EncodedLayer& b = r.active;
    return g.record.valueType == r.record.valueType && valueSize(g.record.valueType) == 4 && !a.dag.empty() && a.valueWindows.predicted &&
           !g.inactiveSignedFill && !r.inactiveSignedFill &&
           b.valueWindows.predicted && !a.valueWindows.empty() && !b.valueWindows.empty() && a.valueWindows.referenceDistance == 0 &&
           g.lossy.tolerance.mode == attributes::ScalarTolerance::Mode::Exact && r.lossy.tolerance.mode == attributes::ScalarTolerance::Mode::Exact && a.dag == b.dag;
}

// Whether two payloads over the same layout cut it into the same windows: a
// float volume of integers has windows of 2^22 entries, one with any
// fraction 2^20 (PredictedWindows.h).
bool sameWindows(std::span<const uint8_t> a, std::span<const uint8_t> b, uint32_t vs, std::span<const uint64_t> layout) {
    return attributes::sameWindowCuts(attributes::readPredictedWindowDirectory(a, vs, layout, "a volume's predicted windows"),
                                      attributes::readPredictedWindowDirectory(b, vs, layout, "a volume's predicted windows"));
}

} // namespace

SeriesReferenceReport referenceSeries(format::SsvdagScene& scene, unsigned keyEvery, uint64_t keepBytes) {
    if (keyEvery == 0 || keyEvery > attributes::kMaxReferenceChain + 1)
        throw Error("--key-every " + std::to_string(keyEvery) + ": 1 to " + std::to_string(attributes::kMaxReferenceChain + 1) + " expected");
    SeriesReferenceReport report;
    const size_t n = scene.grids.size();
    // Which grids refer to the one before: each grid's windows as first
    // coded (needing no reference), their directories compared.
    std::vector<std::vector<uint8_t>> payload(n);
    std::vector<char> refers(n, 0);
    std::vector<uint64_t> bytes(n, 0);  // a grid's entries, decoded
    unsigned sinceKey = 0;              // grids since the run's last key grid
    for (size_t g = 0; g < n; ++g) {
        const format::EncodedGrid& grid = scene.grids[g];
        const attributes::ValueWindowsPayload& windows = grid.active.valueWindows;
        const uint32_t vs = valueSize(grid.record.valueType);
        if (windows.predicted && !windows.empty()) payload[g] = windows.load();
        bytes[g] = encoding::decodedSize(grid.active.dag).attributeEntries * vs;
        const bool inRun = g > 0 && mayRefer(grid, scene.grids[g - 1]) && sameWindows(payload[g], payload[g - 1], vs, encoding::attributeLayout(grid.active.dag));
        sinceKey = inRun ? sinceKey + 1 : 0;
        refers[g] = inRun && sinceKey % keyEvery != 0;
    }
    // In blocks of grids whose decoded entries (and those of the grid before
    // the block) take at most keepBytes (one grid at least): the grids a
    // block reads decoded, in parallel, then its referring grids coded
    // against the grid before, in parallel. Each grid is decoded once, the
    // same bytes for any block.
    for (size_t g0 = 0; g0 < n;) {
        size_t g1 = g0;
        uint64_t held = 0;
        std::vector<size_t> read;  // the grids the block decodes
        while (g1 < n) {
            uint64_t more = 0;
            if (refers[g1]) more = bytes[g1] + (read.empty() || read.back() != g1 - 1 ? bytes[g1 - 1] : 0);
            if (g1 > g0 && held + more > keepBytes) break;
            held += more;
            if (refers[g1]) {
                if (read.empty() || read.back() != g1 - 1) read.push_back(g1 - 1);
                read.push_back(g1);
            }
            ++g1;
        }
        std::vector<std::vector<uint8_t>> decoded(read.size());
        tbb::parallel_for(size_t(0), read.size(), [&](size_t i) {
            const format::EncodedGrid& grid = scene.grids[read[i]];
            const uint32_t vs = valueSize(grid.record.valueType);
            decoded[i] = attributes::decodePredictedWindows(payload[read[i]], vs, encoding::attributeLayout(grid.active.dag),
                                                            "grid '" + grid.record.name + "' predicted windows", encoding::attributePlaces(grid.active.dag, vs));
        });
        const auto decodedOf = [&](size_t g) -> const std::vector<uint8_t>& {
            return decoded[size_t(std::lower_bound(read.begin(), read.end(), g) - read.begin())];
        };
        std::vector<std::optional<std::vector<uint8_t>>> coded(g1 - g0);
        std::vector<uint64_t> referenced(g1 - g0, 0);
        tbb::parallel_for(g0, g1, [&](size_t g) {
            if (!refers[g]) return;
            const format::EncodedGrid& grid = scene.grids[g];
            const uint32_t vs = valueSize(grid.record.valueType);
            const std::vector<uint64_t> layout = encoding::attributeLayout(grid.active.dag);
            const std::vector<coding::BrickPlace> places = encoding::attributePlaces(grid.active.dag, vs);
            const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(payload[g], vs, layout, "grid '" + grid.record.name + "'");
            // Both grids' windows cut as `dir` (sameWindows).
            coded[g - g0] = attributes::referencePredictedWindows(payload[g], attributes::windowsOf(decodedOf(g), dir), attributes::windowsOf(decodedOf(g - 1), dir), vs, layout, places,
                                                                  "grid '" + grid.record.name + "' predicted windows", referenced[g - g0]);
        });
        for (size_t g = g0; g < g1; ++g) {
            if (!refers[g]) continue;
            format::EncodedGrid& grid = scene.grids[g];
            attributes::ValueWindowsPayload& windows = grid.active.valueWindows;
            report.bytesBefore += payload[g].size();
            report.bytesAfter += coded[g - g0] ? coded[g - g0]->size() : payload[g].size();
            if (!coded[g - g0]) continue;
            const uint32_t vs = valueSize(grid.record.valueType);
            windows.bytes = std::move(*coded[g - g0]);
            windows.file.reset();
            windows.referenceDistance = 1;
            // What a later reader of the scene decodes the windows with (the
            // grid before's payload as first coded: no longer read here).
            windows.reference = std::make_shared<const attributes::WindowReference>(std::move(payload[g - 1]), vs, encoding::attributeLayout(grid.active.dag),
                                                                                    nullptr, "grid '" + scene.grids[g - 1].record.name + "' predicted windows");
            ++report.referencedGrids;
            report.referencedWindows += referenced[g - g0];
        }
        g0 = g1;
    }
    return report;
}

} // namespace vdbdag::pipeline
