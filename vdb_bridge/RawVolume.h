// Headerless raw volumes: the user gives the layout (--dims X Y Z --type
// u16 --endian big --spacing SX SY SZ --origin X Y Z). When --dims or --type
// is missing, the file name may supply them in the common
// "NAME_XxYxZ_TYPE.raw" form (TYPE: uint8, int8, uint16, int16, uint32,
// int32, float32/float, float64/double, with an optional le/be suffix, as in
// "cranium_256x256x108_int16le.raw"); otherwise the reader refuses with an
// error saying what to pass. The file size must equal the samples' size
// exactly (a raw file has no header to skip).
#pragma once
#include <array>
#include <optional>
#include <string>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

struct RawLayout {
    std::optional<std::array<int64_t, 3>> dims;
    std::optional<SampleType> type;
    std::optional<bool> bigEndian;  // default: from the name, else little
    std::array<double, 3> spacing{1, 1, 1};
    std::array<double, 3> origin{0, 0, 0};
};

DenseVolume describeRaw(const std::string& path, const RawLayout& layout);

} // namespace vdbdag::bridge
