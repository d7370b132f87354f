// Reading a ValueReference section (docs/FORMAT.md 8.6): a grid whose
// active predicted windows take an earlier grid's same windows as their
// reference (a 4-D scan's volume before). The scene reader's half of the
// series reference; the writer's is pipeline/SeriesReference.h, the
// windows' attributes/PredictedWindows.h (WindowReference).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>

#include "src/attributes/PredictedWindows.h"
#include "src/format/ReadLimits.h"
#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"

namespace vdbdag::format {

// The payload, u32 distance d >= 1 (the reference is grid g - d); throws
// vdbdag::Error naming `sourceName` and the grid.
uint32_t parseValueReference(const Section& section, const std::string& sourceName);

// What a read shares between the grids that refer to one grid: that grid's
// windows once (one WindowReference), and what they add to the read's
// memory (`expanded`, checked against `limits`).
struct ReferenceReads {
    std::map<uint32_t, std::shared_ptr<const attributes::WindowReference>> byGrid;
    uint64_t* expanded = nullptr;
    const ReadLimits* limits = nullptr;
};

// Grid g's reference (`section`): checks that it names an earlier grid of
// this read (`scene`'s grids are grids first.., g's among them) with the
// same DAG, value type and window cuts as `layer` (whose windows are
// `payload`), sets the layer's referenceDistance and reference (and the
// earlier grid's referencedBy), and returns the reference's windows for a
// decode of `layer` now: sliced from the earlier grid's decoded entries
// when `decodedNow` and it has them, else through its WindowReference.
// Throws vdbdag::Error starting with `what` (the file and grid).
attributes::ReferenceWindow readValueReference(const Section& section, uint32_t g, uint32_t first, SsvdagScene& scene, EncodedLayer& layer,
                                               std::span<const uint8_t> payload, unsigned valueSize, bool decodedNow, ReferenceReads& reads,
                                               const std::string& what, const std::string& sourceName);

// The first grid of grid `grid`'s reference chain, from each grid's
// ValueReference section (`referenceOf(g)`, null: none): refused past grid
// 0 or beyond kMaxReferenceChain grids.
uint32_t referenceChainStart(uint32_t grid, const std::function<const Section*(uint32_t)>& referenceOf, const std::string& sourceName);

// The first grid of grid `grid`'s reference chain in the file at `path`
// (`grid` itself when it has no reference; at most kMaxReferenceChain
// grids back), from its ValueReference sections alone.
uint32_t referenceChainStart(const std::string& path, uint32_t grid, const ReadLimits& limits);

} // namespace vdbdag::format
