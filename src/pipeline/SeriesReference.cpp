// See SeriesReference.h.
#include "src/pipeline/SeriesReference.h"

#include <string>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"

namespace vdbdag::pipeline {
namespace {

bool sameDag(const encoding::CompactDag& a, const encoding::CompactDag& b) {
    return a.origin == b.origin && a.log2Size == b.log2Size && a.rootReflection == b.rootReflection && a.levelStart == b.levelStart &&
           a.offsetWords == b.offsetWords && a.inner == b.inner && a.leaves == b.leaves;
}

// Whether grid `g`'s active values may refer to grid `r`'s (and the
// windows' cuts agree: sameWindows). A grid whose inside is a signed fill
// is left alone (a reader that keeps windows rebuilds its layers).
bool mayRefer(const format::EncodedGrid& g, const format::EncodedGrid& r) {
    const format::EncodedLayer& a = g.active;
    const format::EncodedLayer& b = r.active;
    return g.record.valueType == r.record.valueType && valueSize(g.record.valueType) == 4 && !a.dag.empty() && a.valueWindows.predicted &&
           !g.inactiveSignedFill && !r.inactiveSignedFill &&
           b.valueWindows.predicted && !a.valueWindows.empty() && !b.valueWindows.empty() && a.valueWindows.referenceDistance == 0 &&
           g.lossy.tolerance.mode == attributes::ScalarTolerance::Mode::Exact && r.lossy.tolerance.mode == attributes::ScalarTolerance::Mode::Exact && sameDag(a.dag, b.dag);
}

// Whether two payloads over the same layout cut it into the same windows: a
// float volume of integers has windows of 2^22 entries, one with any
// fraction 2^20 (PredictedWindows.h).
bool sameWindows(std::span<const uint8_t> a, std::span<const uint8_t> b, uint32_t vs, std::span<const uint64_t> layout) {
    const attributes::WindowDirectory da = attributes::readPredictedWindowDirectory(a, vs, layout, "a volume's predicted windows");
    const attributes::WindowDirectory db = attributes::readPredictedWindowDirectory(b, vs, layout, "a volume's predicted windows");
    if (da.windows.size() != db.windows.size()) return false;
    for (size_t k = 0; k < da.windows.size(); ++k)
        if (da.windows[k].entries != db.windows[k].entries) return false;
    return true;
}

} // namespace

SeriesReferenceReport referenceSeries(format::SsvdagScene& scene, unsigned keyEvery, uint64_t keepBytes) {
    if (keyEvery == 0 || keyEvery > attributes::kMaxReferenceChain + 1)
        throw Error("--key-every " + std::to_string(keyEvery) + ": 1 to " + std::to_string(attributes::kMaxReferenceChain + 1) + " expected");
    SeriesReferenceReport report;
    // Grid g - 1's windows as first coded (needing no reference), and its
    // entries window by window when the pass decoded them (up to
    // keepBytes; beyond, each is decoded again from the payload).
    std::vector<uint8_t> previous;
    std::vector<std::vector<uint8_t>> previousWindows;
    unsigned sinceKey = 0;  // grids since the run's last key grid
    for (size_t g = 0; g < scene.grids.size(); ++g) {
        format::EncodedGrid& grid = scene.grids[g];
        attributes::ValueWindowsPayload& windows = grid.active.valueWindows;
        std::vector<uint8_t> own = windows.predicted && !windows.empty() ? windows.load() : std::vector<uint8_t>{};
        const uint32_t vs = valueSize(grid.record.valueType);
        const bool inRun = g > 0 && mayRefer(grid, scene.grids[g - 1]) && sameWindows(own, previous, vs, encoding::attributeLayout(grid.active.dag));
        sinceKey = inRun ? sinceKey + 1 : 0;
        const bool keep = g + 1 < scene.grids.size() && mayRefer(scene.grids[g + 1], grid) &&
                          encoding::decodedSize(grid.active.dag).attributeEntries * vs <= keepBytes;
        std::vector<std::vector<uint8_t>> decoded;
        if (inRun && sinceKey % keyEvery != 0) {
            const std::vector<uint64_t> layout = encoding::attributeLayout(grid.active.dag);
            const std::vector<coding::BrickPlace> places = encoding::attributePlaces(grid.active.dag, vs);
            const std::string previousName = "grid '" + scene.grids[g - 1].record.name + "' predicted windows";
            // The reference's windows: as the pass decoded them, else from its payload.
            std::shared_ptr<const attributes::WindowReference> reference =
                std::make_shared<const attributes::WindowReference>(std::move(previous), vs, layout, nullptr, previousName);
            const attributes::ReferenceWindow window = [&](size_t k) {
                return k < previousWindows.size() && !previousWindows[k].empty() ? previousWindows[k] : reference->window(k, layout, places);
            };
            uint64_t referenced = 0;
            std::optional<std::vector<uint8_t>> coded = attributes::referencePredictedWindows(
                own, window, vs, layout, places, "grid '" + grid.record.name + "' predicted windows", referenced, keep ? &decoded : nullptr);
            report.bytesBefore += own.size();
            report.bytesAfter += coded ? coded->size() : own.size();
            if (coded) {
                windows.bytes = std::move(*coded);
                windows.file.reset();
                windows.referenceDistance = 1;
                windows.reference = std::move(reference);
                ++report.referencedGrids;
                report.referencedWindows += referenced;
            }
        }
        previous = std::move(own);
        previousWindows = std::move(decoded);
    }
    return report;
}

} // namespace vdbdag::pipeline
