// The traceable value channel of a layer (the palettes a tracer binds),
// built from what a scene holds: `values` when set (palette windows read
// from a file are decoded into it), else palettes compressed afresh from
// the predicted windows of an integer channel or from the raw attributes an
// encoder left. An encoder's and a tracer's part: it runs the palette
// compressor (the reader library, which looks values up directly, does
// not link it).
#pragma once
#include "src/format/SsvdagFile.h"

namespace vdbdag::format {

attributes::PaletteChannel traceableValues(const EncodedGrid& grid, bool inactive = false);

} // namespace vdbdag::format
