// libFuzzer target for src/coding/IntVolumeCoder and BrickValueCoder: the
// first 8 bytes choose a small shape (up to 16^3; for the brick coder, byte
// 7 odd, a layout of up to 16 bricks whose masks come from the data, tiles
// among them; byte 7 & 2, the bricks placed side by side with mirrors; & 4
// as well, lossless, coded as labels (byte 4 & 8: label model generation 2,
// else 1); & 8, the bricks visited in the
// layout's order rather than spatially, & 16 in raster blocks; with places and byte 5 & 0x40, the
// entries are float32 bits for coding/FloatValueCoder, & 0x20 too vec3s,
// any bits allowed and every bit kept), the sample range, near and the
// model generation (byte 7 & 32: a reference volume from the data for the
// raster coder, or for the placed walk of generation 3 or 4, not labels;
// byte 7 & 64, generation 4 placed in spatial order: tiles as
// neighbours); the rest is (a) a stream to
// decode, which must throw vdbdag::Error or give samples inside the range,
// never crash or read out of bounds, and (b) the samples of a volume to
// encode, whose decode must give every sample back (within near).
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "src/coding/BrickValueCoder.h"
#include "src/coding/FloatValueCoder.h"
#include "src/coding/IntVolumeCoder.h"
#include "src/coding/LabelCoder.h"
#include "src/util/Error.h"

using namespace vdbdag::coding;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 8) return 0;
    IntVolumeShape shape{1 + data[0] % 16, 1 + data[1] % 16, 1 + data[2] % 16};
    IntCoderOptions o;
    const unsigned bits = 1 + data[3] % 32;
    o.minValue = data[4] & 1 ? -(int64_t(1) << (bits - 1)) : 0;
    o.maxValue = std::min<int64_t>(INT32_MAX, o.minValue + (int64_t(1) << bits) - 1);
    o.near = data[5] % 4 == 0 ? data[6] % 5 : 0;
    o.model = ((data[5] >> 7) & 1) + ((data[6] >> 7) & 1) + ((data[4] >> 1) & 1) + ((data[4] >> 2) & 1);  // bytes 5's and 6's top bits, byte 4's bits 1-2: the model generation, 0-4
    const std::span<const uint8_t> rest(data + 8, size - 8);
    const bool bricks = data[7] & 1;
    std::vector<uint64_t> layout;
    if (bricks) {
        for (unsigned b = 0; b < 1u + data[0] % 16; ++b) {
            uint64_t mask = 0;
            const size_t at = (b * 8) % std::max<size_t>(1, rest.size());
            if (!rest.empty()) std::memcpy(&mask, rest.data() + at, std::min<size_t>(8, rest.size() - at));
            layout.push_back(b % 5 == 4 ? 0 : mask);
        }
    }
    // Byte 7 & 2: the bricks placed (distinct places in a 4x4 grid of bricks, mirrors from the data).
    std::vector<BrickPlace> places;
    if (bricks && (data[7] & 2))
        for (unsigned b = 0; b < layout.size(); ++b) places.push_back({int32_t(4 * (b % 4)), int32_t(4 * (b / 4)), 0, uint32_t(data[(b % 6) + 1] % 8)});
    if (!places.empty() && (data[5] & 0x40)) {  // float32 bits (byte 5 & 0x20: vec3s): any decode refused or in bounds, every encode exact
        const bool vectors = data[5] & 0x20;
        const uint64_t n = layoutEntryCount(layout) * (vectors ? 3 : 1);
        std::vector<uint32_t> out(n), bits(n);
        try {
            if (vectors) decodePlacedFloatVectors(rest, layout, places, out, "fuzz");
            else decodePlacedFloats(rest, layout, places, out, "fuzz");
        } catch (const vdbdag::Error&) {
        }
        for (size_t i = 0; i < n; ++i)
            if (!rest.empty()) std::memcpy(&bits[i], rest.data() + (i * 4) % rest.size(), std::min<size_t>(4, rest.size() - (i * 4) % rest.size()));
        if (vectors) decodePlacedFloatVectors(encodePlacedFloatVectors(bits, layout, places), layout, places, out, "fuzz");
        else decodePlacedFloats(encodePlacedFloats(bits, layout, places), layout, places, out, "fuzz");
        if (out != bits) std::abort();
        return 0;
    }
    const bool labels = !places.empty() && (data[7] & 4) && o.near == 0;  // byte 7 & 4: coded as labels (LabelCoder)
    const int labelModel = data[4] & 8 ? 2 : 1;
    // byte 7 & 8: the layout's brick order; & 16, raster blocks
    const BrickOrder order = data[7] & 8 ? BrickOrder::Attribute : data[7] & 16 ? BrickOrder::Raster : BrickOrder::Spatial;
    o.tileNeighbours = !places.empty() && !labels && o.model == 4 && (data[7] & 64) && order != BrickOrder::Attribute;
    if (o.tileNeighbours)  // tiles as a DAG lays them out: aligned to their size (8, 16 or 32), apart from the bricks and each other
        for (unsigned b = 0; b < layout.size(); ++b)
            if (layout[b] == 0) places[b] = {int32_t(32 * (b + 1)), 0, 0, 3 + uint32_t(data[(b % 6) + 1] % 3)};
    const auto decode = [&](std::span<const uint8_t> stream, std::vector<int32_t>& out) {
        if (labels) decodePlacedLabels(stream, layout, places, order, int32_t(o.minValue), int32_t(o.maxValue), out, "fuzz", labelModel);
        else if (!places.empty()) decodePlacedBrickValues(stream, layout, places, order, o, out, "fuzz");
        else if (bricks) decodeBrickValues(stream, layout, o, out, "fuzz");
        else decodeIntVolume(stream, shape, o, out);
    };
    const auto encode = [&](const std::vector<int32_t>& samples) {
        if (labels) return encodePlacedLabels(samples, layout, places, order, int32_t(o.minValue), int32_t(o.maxValue), labelModel);
        if (!places.empty()) return encodePlacedBrickValues(samples, layout, places, order, o);
        return bricks ? encodeBrickValues(samples, layout, o) : encodeIntVolume(samples, shape, o);
    };
    const uint64_t count = bricks ? layoutEntryCount(layout) : shape.count();
    // Byte 7 & 32: a reference volume (IntCoderOptions::reference) of
    // samples from the data, in the range or not (a reference is any int32),
    // for the raster coder or the placed walk of generation 3 or 4.
    std::vector<int32_t> reference;
    if ((data[7] & 32) && (!bricks || (!places.empty() && !labels && o.model >= 3))) {
        reference.resize(count);
        for (size_t i = 0; i < reference.size(); ++i)
            if (!rest.empty()) std::memcpy(&reference[i], rest.data() + (i * 3) % rest.size(), std::min<size_t>(4, rest.size() - (i * 3) % rest.size()));
        o.reference = reference;
    }
    std::vector<int32_t> out(count);
    try {
        decode(rest, out);
        for (int32_t x : out)
            if (x < o.minValue || x > o.maxValue) std::abort();
    } catch (const vdbdag::Error&) {
    }
    std::vector<int32_t> samples(count);
    for (size_t i = 0; i < samples.size(); ++i) {
        uint32_t raw = 0;
        if (!rest.empty()) std::memcpy(&raw, rest.data() + (i * 4) % rest.size(), std::min<size_t>(4, rest.size() - (i * 4) % rest.size()));
        samples[i] = int32_t(o.minValue + int64_t(raw % uint64_t(o.maxValue - o.minValue + 1)));
    }
    const std::vector<uint8_t> bytes = encode(samples);
    decode(bytes, out);
    for (size_t i = 0; i < samples.size(); ++i)
        if (std::abs(int64_t(out[i]) - samples[i]) > o.near) std::abort();
    return 0;
}
