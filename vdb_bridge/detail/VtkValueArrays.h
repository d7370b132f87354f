// Private: one VTK data array per grid channel, filled value by value from
// OpenVDB values: float -> Float32, double -> Float64, int32 -> Int32, int64
// -> Int64, bool -> UInt8 (0/1), vec3s/vec3d -> 3-component Float32 (normals,
// vectors), vec3i -> 3-component Int32; colour grids (isColourGrid) -> 3-component
// UInt8: float colours are taken as 0..1 (clamped, x255, rounded), integer
// colours as 0..255 (clamped). Mask grids have no values (no array). An
// int32 grid imported from an 8- or 16-bit scan (metadata
// source_sample_type, no rescale) keeps that width: UInt8, Int8, UInt16 or
// Int16, widened to Int32 should a value not fit.
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

// The VTK type that holds an int32 grid's values as its scan stored them
// (VTK_UNSIGNED_CHAR, VTK_SIGNED_CHAR, VTK_UNSIGNED_SHORT, VTK_SHORT), or 0.
inline int scanSampleVtkType(const openvdb::GridBase& grid) {
    const auto type = grid.getMetadata<openvdb::StringMetadata>("source_sample_type");
    if (!type || grid.getMetadata<openvdb::DoubleMetadata>("source_rescale_slope")) return 0;
    if (type->value() == "u8") return VTK_UNSIGNED_CHAR;
    if (type->value() == "i8") return VTK_SIGNED_CHAR;
    if (type->value() == "u16") return VTK_UNSIGNED_SHORT;
    if (type->value() == "i16") return VTK_SHORT;
    return 0;
}

inline unsigned char colourByte(double v, bool unitRange) {
    if (std::isnan(v)) return 0;
    const double scaled = unitRange ? std::round(std::clamp(v, 0.0, 1.0) * 255.0) : std::clamp(v, 0.0, 255.0);
    return static_cast<unsigned char>(scaled);
}

// Appends values of type T to a VTK array named `name`.
template <typename T>
class ValueColumn {
public:
    // `narrowType`: scanSampleVtkType of an int32 grid (0: the usual type).
    ValueColumn(const std::string& name, bool colour, vtkIdType reserve = 0, int narrowType = 0) : colour_(colour && kIsVec3<T>) {
        if constexpr (std::is_same_v<T, int32_t>) {
            if (narrowType) {
                narrow_.TakeReference(vtkDataArray::CreateDataArray(narrowType));
                narrowMin_ = narrow_->GetDataTypeMin();
                narrowMax_ = narrow_->GetDataTypeMax();
            }
        }
        if (colour_) bytes_ = vtkSmartPointer<vtkUnsignedCharArray>::New();
        else if (!narrow_) typed_ = vtkSmartPointer<typename VtkValueTraits<T>::Array>::New();
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
            if constexpr (std::is_same_v<T, int32_t>) {
                if (narrow_) {
                    if (double(v) >= narrowMin_ && double(v) <= narrowMax_) {
                        narrow_->InsertNextTuple1(double(v));
                        return;
                    }
                    widen();  // a value the scan's type cannot hold: Int32 after all
                }
            }
            typed_->InsertNextValue(v);
        }
    }
    vtkDataArray* array() const {
        if (colour_) return bytes_.Get();
        if (narrow_) return narrow_.Get();
        return typed_.Get();
    }

private:
    void widen() {
        typed_ = vtkSmartPointer<typename VtkValueTraits<T>::Array>::New();
        typed_->SetName(narrow_->GetName());
        typed_->SetNumberOfComponents(1);
        typed_->Allocate(narrow_->GetNumberOfTuples());
        for (vtkIdType i = 0; i < narrow_->GetNumberOfTuples(); ++i) typed_->InsertNextValue(T(narrow_->GetTuple1(i)));
        narrow_ = nullptr;
    }
    bool colour_;
    vtkSmartPointer<vtkDataArray> narrow_;
    double narrowMin_ = 0, narrowMax_ = 0;
    vtkSmartPointer<vtkUnsignedCharArray> bytes_;
    vtkSmartPointer<typename VtkValueTraits<T>::Array> typed_;
};

} // namespace vdbdag::bridge::detail
