// The optional normal channel of a grid (`encode --normals K`, Dado et al.
// §4.3): one k-bit octahedral normal vector (ONV, OctahedralNormal.h) per
// attribute entry of the grid's active layer, in the same attribute order
// and count as its values, stored as uint32 codes in a palette channel
// (PaletteChannel.h) like any other attribute.
//
// For tracers: entry i's normal is `channel.decode(i)` (a unit vector, in
// world space when computed from a level set's gradient, else as the normal
// grid stores it); the entry index is the same one the value channel uses
// (child-pointer offsets + popcount rank, DESIGN.md invariant 2). Entries
// are per voxel instance, not per shared node, so a mirrored instance reads
// its own voxel's normal: no flip is needed.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/attributes/PaletteChannel.h"

namespace vdbdag::attributes {

// Where exact normals came from and what quantising them cost.
struct NormalReport {
    enum class Source : uint8_t { Gradient = 0, NormalGrid = 1 };
    Source source = Source::Gradient;
    uint64_t entries = 0;
    uint64_t zeroLength = 0;  // no direction (flat region, zero vector): stored as +z, not in the angle statistics
    uint64_t oneSided = 0;    // gradient: entries where a band edge forced a one-sided difference
    double meanAngleDegrees = 0, maxAngleDegrees = 0;  // decoded vs exact (unquantised) normal
};

struct NormalChannel {
    unsigned bits = 0;      // k in {10, 12, 16, 24, 32} (any even 4..32 reads back)
    PaletteChannel codes;   // valueSize 4: OctahedralCode::bits, little-endian
    NormalReport report;

    uint64_t entryCount() const { return codes.entryCount; }
    uint32_t code(uint64_t entry) const;
    std::array<float, 3> decode(uint64_t entry) const;  // unit vector
};

// The ONV sizes `--normals` accepts.
bool isSupportedNormalBits(unsigned bits);

// Quantises exact normals (attribute order; a zero or non-finite vector
// means "no direction") to `bits`-bit ONVs and measures the angular error
// of every entry. `oneSided` and `source` are copied into the report.
NormalChannel encodeNormals(std::span<const std::array<float, 3>> normals, unsigned bits, NormalReport::Source source, uint64_t oneSided);

// The same a piece at a time, so that a channel is never held as exact
// normals: quantise() turns a piece of exact normals (3 x float each) into
// its codes and angular errors in place (12 bytes each still; any thread,
// any order), add() takes the pieces in attribute order. finish() gives
// encodeNormals' channel, bit for bit (the errors are summed in the same
// order).
class NormalQuantizer {
public:
    explicit NormalQuantizer(unsigned bits);
    void quantise(std::span<uint8_t> piece) const;
    void add(std::span<const uint8_t> quantised);
    NormalChannel finish(NormalReport::Source source, uint64_t oneSided);

private:
    unsigned bits_;
    std::vector<uint8_t> codes_;
    uint64_t entries_ = 0, zeroLength_ = 0;
    double sumAngle_ = 0, maxAngle_ = 0;
};

// Serialisation of the Normals section (see SsvdagFile.cpp); the reader
// checks the bit count, the entry count against `expectedEntries` and that
// every stored code fits in `bits` bits. Throws Error("<what>: ...").
std::vector<uint8_t> serializeNormals(const NormalChannel& channel);
NormalChannel deserializeNormals(std::span<const uint8_t> bytes, uint64_t expectedEntries, const std::string& what);

} // namespace vdbdag::attributes
