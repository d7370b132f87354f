// encodeNormals (NormalChannel.h): exact normals to k-bit octahedral codes,
// palette-compressed. An encoder's part; reading a channel: NormalChannel.cpp.
#include "src/attributes/NormalChannel.h"

#include <cmath>
#include <cstring>

#include "src/attributes/OctahedralNormal.h"
#include "src/attributes/PaletteCompressor.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

NormalChannel encodeNormals(std::span<const std::array<float, 3>> normals, unsigned bits, NormalReport::Source source, uint64_t oneSided) {
    if (bits < 4 || bits > 32 || bits % 2) throw Error("internal error: ONV bits must be even, 4..32");
    NormalChannel channel;
    channel.bits = bits;
    channel.report.source = source;
    channel.report.entries = normals.size();
    channel.report.oneSided = oneSided;
    std::vector<uint8_t> codes(normals.size() * 4);
    double sumAngle = 0;
    for (size_t i = 0; i < normals.size(); ++i) {
        bool zero = false;
        const OctahedralCode c = encodeOctahedral(normals[i], bits, &zero);
        std::memcpy(&codes[i * 4], &c.bits, 4);
        if (zero) {
            ++channel.report.zeroLength;
            continue;
        }
        const double angle = angleDegrees(decodeOctahedral(c, bits), normals[i]);
        sumAngle += angle;
        channel.report.maxAngleDegrees = std::max(channel.report.maxAngleDegrees, angle);
    }
    const uint64_t measured = channel.report.entries - channel.report.zeroLength;
    channel.report.meanAngleDegrees = measured ? sumAngle / double(measured) : 0.0;
    channel.codes = compressPalette(codes, 4);
    return channel;
}

} // namespace vdbdag::attributes
