// encodeNormals (NormalChannel.h): exact normals to k-bit octahedral codes,
// palette-compressed. An encoder's part; reading a channel: NormalChannel.cpp.
#include "src/attributes/NormalChannel.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <tbb/parallel_for.h>

#include "src/attributes/OctahedralNormal.h"
#include "src/attributes/PaletteCompressor.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

// A quantised entry: its code (u32), then its angular error (double, >= 0;
// -1: no direction), in the 12 bytes of its exact normal.
constexpr size_t kEntry = sizeof(std::array<float, 3>);
static_assert(kEntry == sizeof(uint32_t) + sizeof(double));

NormalQuantizer::NormalQuantizer(unsigned bits) : bits_(bits) {
    if (bits < 4 || bits > 32 || bits % 2) throw Error("internal error: ONV bits must be even, 4..32");
}

void NormalQuantizer::quantise(std::span<uint8_t> piece) const {
    if (piece.size() % kEntry) throw Error("internal error: normals are 12 bytes each");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, piece.size() / kEntry, 4096), [&](const auto& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            uint8_t* entry = piece.data() + i * kEntry;
            std::array<float, 3> normal;
            std::memcpy(normal.data(), entry, kEntry);
            bool zero = false;
            const OctahedralCode c = encodeOctahedral(normal, bits_, &zero);
            const double angle = zero ? -1.0 : angleDegrees(decodeOctahedral(c, bits_), normal);
            std::memcpy(entry, &c.bits, sizeof(uint32_t));
            std::memcpy(entry + sizeof(uint32_t), &angle, sizeof(double));
        }
    });
}

void NormalQuantizer::add(std::span<const uint8_t> quantised) {
    for (size_t at = 0; at + kEntry <= quantised.size(); at += kEntry) {
        codes_.insert(codes_.end(), quantised.begin() + long(at), quantised.begin() + long(at + sizeof(uint32_t)));
        ++entries_;
        double angle;
        std::memcpy(&angle, &quantised[at + sizeof(uint32_t)], sizeof(double));
        if (angle == -1.0) {
            ++zeroLength_;
            continue;
        }
        sumAngle_ += angle;
        maxAngle_ = std::max(maxAngle_, angle);
    }
}

NormalChannel NormalQuantizer::finish(NormalReport::Source source, uint64_t oneSided) {
    NormalChannel channel;
    channel.bits = bits_;
    channel.report.source = source;
    channel.report.entries = entries_;
    channel.report.oneSided = oneSided;
    channel.report.zeroLength = zeroLength_;
    channel.report.maxAngleDegrees = maxAngle_;
    const uint64_t measured = entries_ - zeroLength_;
    channel.report.meanAngleDegrees = measured ? sumAngle_ / double(measured) : 0.0;
    channel.codes = compressPalette(codes_, 4);
    codes_ = {};
    return channel;
}

NormalChannel encodeNormals(std::span<const std::array<float, 3>> normals, unsigned bits, NormalReport::Source source, uint64_t oneSided) {
    NormalQuantizer quantizer(bits);
    std::vector<uint8_t> piece(normals.size() * kEntry);
    if (!piece.empty()) std::memcpy(piece.data(), normals.data(), piece.size());
    quantizer.quantise(piece);
    quantizer.add(piece);
    return quantizer.finish(source, oneSided);
}

} // namespace vdbdag::attributes
