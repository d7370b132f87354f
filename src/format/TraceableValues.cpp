// See TraceableValues.h.
#include "src/format/TraceableValues.h"

#include "src/attributes/PaletteCompressor.h"
#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/encoding/AttributeLayout.h"

namespace vdbdag::format {

attributes::PaletteChannel traceableValues(const EncodedGrid& grid, bool inactive) {
    const EncodedLayer& layer = grid.layer(inactive);
    const attributes::PaletteChannel& values = layer.values;
    const attributes::ValueWindowsPayload& windows = layer.valueWindows;
    const std::vector<uint8_t>& attributes = layer.attributes;
    if (values.entryCount || values.valueSize) return values;
    if (!windows.empty() && windows.predicted && !attributes.empty()) return attributes::compressPalette(attributes, valueSize(grid.record.valueType));
    if (!windows.empty() && windows.predicted) {
        const encoding::CompactDag& dag = layer.dag;
        const uint32_t vs = valueSize(grid.record.valueType);
        const std::vector<uint64_t> layout = encoding::attributeLayout(dag);
        const std::vector<coding::BrickPlace> places = encoding::attributePlaces(dag, vs);
        return attributes::compressPalette(attributes::decodePredictedWindows(windows.load(), vs, layout, "grid '" + grid.record.name + "' predicted windows",
                                                                              places, {}, attributes::referenceWindows(windows.reference, layout, places),
                                                                              windows.referencedBy.get()),
                                           vs);
    }
    if (!windows.empty()) return attributes::decodeValueWindows(windows.load(), "grid '" + grid.record.name + "' value windows");
    return attributes::compressPalette(attributes, valueSize(grid.record.valueType));
}

} // namespace vdbdag::format
