// Names of the value types, as OpenVDB spells them.
#include "src/volume/GridRecord.h"

namespace vdbdag {

const char* valueTypeName(ValueType type) {
    switch (type) {
        case ValueType::Float: return "float";
        case ValueType::Double: return "double";
        case ValueType::Int32: return "int32";
        case ValueType::Int64: return "int64";
        case ValueType::Bool: return "bool";
        case ValueType::Mask: return "mask";
        case ValueType::Vec3S: return "vec3s";
        case ValueType::Vec3D: return "vec3d";
        case ValueType::Vec3I: return "vec3i";
    }
    return "unknown";
}

} // namespace vdbdag
