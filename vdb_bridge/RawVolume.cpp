// See RawVolume.h.
#include "vdb_bridge/RawVolume.h"

#include <filesystem>
#include <map>
#include <regex>

#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "vdb_bridge/detail/HeaderText.h"

namespace vdbdag::bridge {

DenseVolume describeRaw(const std::string& path, const RawLayout& layout) {
    std::error_code ec;
    checkInputFile(path, "a raw volume");
    DenseVolume v;
    v.headerPath = path;
    v.dataPath = path;
    const std::string stem = std::filesystem::path(path).stem().string();
    static const std::regex namePattern(R"((?:^|_)(\d+)x(\d+)x(\d+)(?:_([a-z]+\d*?)(le|be)?)?(?:_|$))", std::regex::icase);
    std::smatch m;
    const bool named = std::regex_search(stem, m, namePattern);
    if (layout.dims) {
        v.dims = *layout.dims;
    } else if (named) {
        for (int a = 0; a < 3; ++a) v.dims[size_t(a)] = detail::parseInteger(m[a + 1].str(), path + ": the size in the file name");
    } else {
        throw Error(path + ": a raw file needs its layout: pass --dims X Y Z --type T (or name it NAME_XxYxZ_TYPE.raw)");
    }
    if (layout.type) {
        v.type = *layout.type;
    } else if (named && m[4].matched) {
        static const std::map<std::string, SampleType> names{{"uint8", SampleType::U8},   {"int8", SampleType::I8},    {"uint16", SampleType::U16},
                                                            {"int16", SampleType::I16},  {"uint32", SampleType::U32}, {"int32", SampleType::I32},
                                                            {"float32", SampleType::F32}, {"float", SampleType::F32}, {"float64", SampleType::F64},
                                                            {"double", SampleType::F64}, {"u8", SampleType::U8},      {"i8", SampleType::I8},
                                                            {"u16", SampleType::U16},    {"i16", SampleType::I16},    {"u32", SampleType::U32},
                                                            {"i32", SampleType::I32},    {"f32", SampleType::F32},    {"f64", SampleType::F64}};
        std::string t = m[4].str();
        for (char& c : t) c = char(std::tolower(static_cast<unsigned char>(c)));
        const auto it = names.find(t);
        if (it == names.end()) throw Error(path + ": cannot tell the sample type from the name ('" + m[4].str() + "'): pass --type");
        v.type = it->second;
    } else {
        throw Error(path + ": a raw file needs its sample type: pass --type u8|i8|u16|i16|u32|i32|f32|f64");
    }
    if (layout.bigEndian) v.bigEndian = *layout.bigEndian;
    else v.bigEndian = named && m[5].matched && (m[5].str() == "be" || m[5].str() == "BE");
    for (int a = 0; a < 3; ++a) {
        v.axes[size_t(a)] = {0, 0, 0};
        v.axes[size_t(a)][size_t(a)] = layout.spacing[size_t(a)];
    }
    v.origin = layout.origin;
    v.validate();
    const uint64_t size = std::filesystem::file_size(path, ec);
    const uint64_t need = v.sampleCount() * sampleBytes(v.type);
    if (ec) throw Error(path + ": cannot read the file size");
    if (size != need)
        throw Error(path + ": holds " + std::to_string(size) + " bytes but " + std::to_string(v.dims[0]) + "x" + std::to_string(v.dims[1]) + "x" +
                    std::to_string(v.dims[2]) + " " + sampleTypeName(v.type) + " samples take " + std::to_string(need) + " bytes");
    return v;
}

} // namespace vdbdag::bridge
