// Everything about one grid except its voxels: what the user sees in
// `vdb_print` (name, class, value type) plus what a decoder needs to rebuild
// the grid bit-exactly. OpenVDB's own serialisation of an empty copy of the
// grid (`vdbDescriptor`: metadata, transform, background, class, half-float
// flag) is kept as an opaque blob, written and read only by vdb_bridge.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/volume/GridTopology.h"

namespace vdbdag {

// The value types vdbdag converts (OpenVDB type names in comments).
enum class ValueType : uint8_t {
    Float = 0,   // "float"
    Double = 1,  // "double"
    Int32 = 2,   // "int32"
    Int64 = 3,   // "int64"
    Bool = 4,    // "bool"
    Mask = 5,    // "mask"
    Vec3S = 6,   // "vec3s"
    Vec3D = 7,   // "vec3d"
    Vec3I = 8,   // "vec3i"
};
const char* valueTypeName(ValueType type);
// Bytes per value (bool: 1 byte; mask: 0, no values).
unsigned valueSize(ValueType type);

// Values of one topology, in input order: for brick i (topology order) the
// values of its set bits in increasing bit order, then one value per tile.
// Values are kept as raw bytes so the round trip is bit-exact (NaN payloads,
// -0.0, denormals).
struct LayerValues {
    std::vector<uint8_t> bricks;
    std::vector<uint8_t> tiles;
};

// Exact normals for shading (`encode --normals K`), computed by vdb_bridge:
// one unit vector (3 x float) per active value, in the same input order as
// GridRecord::values; a zero vector means "no direction". (A namespace-level
// type, not nested: clang cannot default-construct a nested class with member
// initialisers inside std::optional of its still incomplete enclosing class.)
struct GridNormals {
    LayerValues vectors;
    bool fromNormalGrid = false;  // false: the level set's gradient
    uint64_t oneSided = 0;        // gradient entries where a band edge forced a one-sided difference
};

// Float values on a lattice: each is float(round_to_double(k * slope) +
// intercept) for an integer k, as a rescaled scan's are (value = sample x
// slope + intercept, vdb_bridge's DenseImport). A hint to the value coder,
// which codes the k instead (attributes/RescaledFloats.h) where every value
// of a window checks out; never trusted beyond that.
struct ValueRescale {
    double slope = 1, intercept = 0;
    bool operator==(const ValueRescale&) const = default;
};

struct GridRecord {
    std::string name;        // may be empty; names may repeat within a file
    std::string gridClass;   // "level set", "fog volume", "staggered", "unknown"
    ValueType valueType = ValueType::Mask;
    // Index-space -> world-space affine map (row-major 4x4, OpenVDB's Mat4d
    // convention: world = [i j k 1] * M). For renderers; the exact transform,
    // linear or not, lives in vdbDescriptor.
    std::array<double, 16> indexToWorld{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    std::vector<uint8_t> vdbDescriptor;  // opaque, see above
    std::vector<uint8_t> background;     // raw background value (valueSize bytes)
    GridTopology topology;               // active voxels and tiles
    LayerValues values;                  // their values (empty for mask grids)
    // Inactive voxels and tiles whose stored value differs (bitwise) from the
    // background, e.g. a level set's inside; cost grows with what differs.
    GridTopology inactiveTopology;
    LayerValues inactiveValues;
    // Optional exact normals for shading (`encode --normals K`).
    using Normals = GridNormals;
    std::optional<Normals> normals;
    // Float grids only: the lattice the values are believed to lie on.
    std::optional<ValueRescale> rescale;
};

// Everything but the voxels (topologies, values, normals): what
// CubeSource::header() holds, copied without the voxels.
GridRecord headerOf(const GridRecord& grid);

// A whole .vdb file: its grids in file order and its file-level metadata
// (OpenVDB's own MetaMap serialisation, opaque like vdbDescriptor; empty
// when the file has none).
struct Volume {
    std::vector<GridRecord> grids;
    std::vector<uint8_t> fileMetadata;
};

} // namespace vdbdag
