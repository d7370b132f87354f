// Everything about one grid except its voxels: what the user sees in
// `vdb_print` (name, class, value type) plus what a decoder needs to rebuild
// the grid bit-exactly. OpenVDB's own serialisation of an empty copy of the
// grid (`vdbDescriptor`: metadata, transform, background, class, half-float
// flag) is kept as an opaque blob, written and read only by vdb_bridge.
#pragma once
#include <array>
#include <cstdint>
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

struct GridRecord {
    std::string name;        // may be empty; names may repeat within a file
    std::string gridClass;   // "level set", "fog volume", "staggered", "unknown"
    ValueType valueType = ValueType::Mask;
    // Index-space -> world-space affine map (row-major 4x4, OpenVDB's Mat4d
    // convention: world = [i j k 1] * M). For renderers; the exact transform,
    // linear or not, lives in vdbDescriptor.
    std::array<double, 16> indexToWorld{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    std::vector<uint8_t> vdbDescriptor;  // opaque, see above
    GridTopology topology;
};

// A whole .vdb file, in file order.
struct Volume {
    std::vector<GridRecord> grids;
};

} // namespace vdbdag
