// Names of the value types, as OpenVDB spells them; a grid's header.
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

unsigned valueSize(ValueType type) {
    switch (type) {
        case ValueType::Float: return 4;
        case ValueType::Double: return 8;
        case ValueType::Int32: return 4;
        case ValueType::Int64: return 8;
        case ValueType::Bool: return 1;
        case ValueType::Mask: return 0;
        case ValueType::Vec3S: return 12;
        case ValueType::Vec3D: return 24;
        case ValueType::Vec3I: return 12;
    }
    return 0;
}

GridRecord headerOf(const GridRecord& grid) {
    GridRecord out;
    out.name = grid.name;
    out.gridClass = grid.gridClass;
    out.valueType = grid.valueType;
    out.indexToWorld = grid.indexToWorld;
    out.vdbDescriptor = grid.vdbDescriptor;
    out.background = grid.background;
    out.rescale = grid.rescale;
    return out;
}

} // namespace vdbdag
