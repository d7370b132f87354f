// See NormalChannel.h. Section payload (little-endian):
//   u8 bits, u8 source, u64 entries, u64 zero-length, u64 one-sided,
//   f64 mean angle, f64 max angle (degrees), then the palette channel of the
//   uint32 codes (serializePalette) to the end of the section.
#include "src/attributes/NormalChannel.h"

#include <cmath>
#include <cstring>

#include "src/attributes/OctahedralNormal.h"
#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

uint32_t NormalChannel::code(uint64_t entry) const {
    uint32_t c = 0;
    codes.lookup(entry, reinterpret_cast<uint8_t*>(&c));
    return c;
}

std::array<float, 3> NormalChannel::decode(uint64_t entry) const { return decodeOctahedral({code(entry)}, bits); }

bool isSupportedNormalBits(unsigned bits) { return bits == 10 || bits == 12 || bits == 16 || bits == 24 || bits == 32; }

std::vector<uint8_t> serializeNormals(const NormalChannel& c) {
    format::ByteWriter w;
    w.put<uint8_t>(uint8_t(c.bits));
    w.put<uint8_t>(uint8_t(c.report.source));
    for (uint64_t v : {c.report.entries, c.report.zeroLength, c.report.oneSided}) w.put<uint64_t>(v);
    w.put<double>(c.report.meanAngleDegrees);
    w.put<double>(c.report.maxAngleDegrees);
    w.putBytes(serializePalette(c.codes));
    return w.take();
}

NormalChannel deserializeNormals(std::span<const uint8_t> bytes, uint64_t expectedEntries, const std::string& what) {
    format::ByteReader r(bytes, what);
    NormalChannel c;
    c.bits = r.get<uint8_t>();
    if (c.bits < 4 || c.bits > 32 || c.bits % 2) r.fail("normal codes of " + std::to_string(c.bits) + " bits (must be even, 4..32)");
    const uint8_t source = r.get<uint8_t>();
    if (source > 1) r.fail("unknown normal source " + std::to_string(source));
    c.report.source = NormalReport::Source(source);
    c.report.entries = r.get<uint64_t>();
    c.report.zeroLength = r.get<uint64_t>();
    c.report.oneSided = r.get<uint64_t>();
    c.report.meanAngleDegrees = r.get<double>();
    c.report.maxAngleDegrees = r.get<double>();
    if (c.report.zeroLength > c.report.entries || c.report.oneSided > c.report.entries) r.fail("counts exceed the entries");
    if (!std::isfinite(c.report.meanAngleDegrees) || !std::isfinite(c.report.maxAngleDegrees) || c.report.maxAngleDegrees < 0 ||
        c.report.maxAngleDegrees > 180)
        r.fail("implausible angular error");
    c.codes = deserializePalette(bytes.subspan(r.position()), what + " codes");
    if (c.codes.valueSize != 4) r.fail("codes of " + std::to_string(c.codes.valueSize) + " bytes, expected 4");
    if (c.codes.entryCount != expectedEntries || c.report.entries != expectedEntries)
        r.fail("holds " + std::to_string(c.codes.entryCount) + " normals, the DAG has " + std::to_string(expectedEntries) + " entries");
    // Every stored code (materials and directly stored blocks) must fit k bits.
    const uint64_t limit = uint64_t(1) << c.bits;
    for (const std::vector<uint8_t>* raw : {&c.codes.materials, &c.codes.direct})
        for (size_t i = 0; i + 4 <= raw->size(); i += 4) {
            uint32_t v;
            std::memcpy(&v, raw->data() + i, 4);
            if (uint64_t(v) >= limit) r.fail("normal code " + std::to_string(v) + " does not fit " + std::to_string(c.bits) + " bits");
        }
    return c;
}

} // namespace vdbdag::attributes
