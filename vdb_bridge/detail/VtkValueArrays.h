// Private: one VTK data array per grid channel, filled value by value from
// OpenVDB values: float -> Float32, double -> Float64, int32 -> Int32, int64
// -> Int64, bool -> UInt8 (0/1), vec3s/vec3d -> 3-component Float32 (normals,
// vectors), vec3i -> 3-component Int32; colour grids (isColourGrid) -> 3-component
// UInt8: float colours are taken as 0..1 (clamped, x255, rounded), integer
// colours as 0..255 (clamped). Mask grids have no values (no array).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include <openvdb/openvdb.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnsignedCharArray.h>

namespace vdbdag::bridge::detail {

template <typename T>
struct VtkValueTraits;
template <> struct VtkValueTraits<float> { using Array = vtkFloatArray; static constexpr int comps = 1; };
template <> struct VtkValueTraits<double> { using Array = vtkDoubleArray; static constexpr int comps = 1; };
template <> struct VtkValueTraits<int32_t> { using Array = vtkIntArray; static constexpr int comps = 1; };
template <> struct VtkValueTraits<int64_t> { using Array = vtkTypeInt64Array; static constexpr int comps = 1; };
template <> struct VtkValueTraits<bool> { using Array = vtkUnsignedCharArray; static constexpr int comps = 1; };
template <> struct VtkValueTraits<openvdb::Vec3s> { using Array = vtkFloatArray; static constexpr int comps = 3; };
template <> struct VtkValueTraits<openvdb::Vec3d> { using Array = vtkFloatArray; static constexpr int comps = 3; };
template <> struct VtkValueTraits<openvdb::Vec3i> { using Array = vtkIntArray; static constexpr int comps = 3; };

template <typename T>
constexpr bool kIsVec3 = VtkValueTraits<T>::comps == 3;

inline unsigned char colourByte(double v, bool unitRange) {
    if (std::isnan(v)) return 0;
    const double scaled = unitRange ? std::round(std::clamp(v, 0.0, 1.0) * 255.0) : std::clamp(v, 0.0, 255.0);
    return static_cast<unsigned char>(scaled);
}

// Appends values of type T to a VTK array named `name`.
template <typename T>
class ValueColumn {
public:
    ValueColumn(const std::string& name, bool colour, vtkIdType reserve = 0) : colour_(colour && kIsVec3<T>) {
        if (colour_) bytes_ = vtkSmartPointer<vtkUnsignedCharArray>::New();
        else typed_ = vtkSmartPointer<typename VtkValueTraits<T>::Array>::New();
        vtkDataArray* a = array();
        a->SetName(name.c_str());
        a->SetNumberOfComponents(VtkValueTraits<T>::comps);
        if (reserve > 0) a->Allocate(reserve * VtkValueTraits<T>::comps);
    }
    void push(const T& v) {
        if constexpr (kIsVec3<T>) {
            if (colour_) {
                const bool unit = std::is_floating_point_v<typename T::ValueType>;
                const unsigned char c[3] = {colourByte(double(v[0]), unit), colourByte(double(v[1]), unit), colourByte(double(v[2]), unit)};
                bytes_->InsertNextTypedTuple(c);
            } else {
                using S = typename VtkValueTraits<T>::Array::ValueType;
                const S c[3] = {S(v[0]), S(v[1]), S(v[2])};
                typed_->InsertNextTypedTuple(c);
            }
        } else if constexpr (std::is_same_v<T, bool>) {
            typed_->InsertNextValue(v ? 1 : 0);
        } else {
            typed_->InsertNextValue(v);
        }
    }
    vtkDataArray* array() const { return colour_ ? static_cast<vtkDataArray*>(bytes_.Get()) : static_cast<vtkDataArray*>(typed_.Get()); }

private:
    bool colour_;
    vtkSmartPointer<vtkUnsignedCharArray> bytes_;
    vtkSmartPointer<typename VtkValueTraits<T>::Array> typed_;
};

} // namespace vdbdag::bridge::detail
