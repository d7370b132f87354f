// See MetaImageHeader.h. "Key = Value" lines; ElementDataFile must be the
// last field (MetaIO's rule); for LOCAL the samples start right after its line.
// Tags this reader does not use are kept as header fields (mha_tag_*).
// TransformMatrix: MetaIO writes ITK's direction matrix D as
// M[3*i + j] = D[j][i], so the i-th written triple is the direction of
// index axis i (ITK's itkMetaImageIO).
#include "vdb_bridge/MetaImageHeader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "vdb_bridge/detail/HeaderText.h"

namespace vdbdag::bridge {
namespace {

constexpr size_t kMaxHeaderBytes = 1u << 20;

bool parseBool(const std::string& value, const std::string& what) {
    const std::string v = detail::lower(detail::trim(value));
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    throw Error(what + ": '" + detail::trim(value) + "' is neither True nor False");
}

} // namespace

DenseVolume readMetaImageHeader(const std::string& path) {
    checkInputFile(path, "a MetaImage file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open");

    std::map<std::string, std::string> fields;  // lower-case keys
    std::vector<std::pair<std::string, std::string>> tags;  // as written, in order
    std::string line;
    size_t budget = kMaxHeaderBytes;
    bool sawDataFile = false;
    while (detail::getBoundedLine(in, line, budget, path + ": MetaImage header longer than 1 MiB (no ElementDataFile line?)")) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (detail::trim(line).empty() || detail::trim(line)[0] == '#') continue;
        const size_t eq = line.find('=');
        if (eq == std::string::npos) throw Error(path + ": malformed MetaImage header line '" + line.substr(0, 80) + "' (expected 'Key = Value')");
        const std::string key = detail::lower(detail::trim(line.substr(0, eq)));
        if (key.empty()) throw Error(path + ": MetaImage header line '" + line.substr(0, 80) + "' has no key");
        if (!fields.emplace(key, detail::trim(line.substr(eq + 1))).second) throw Error(path + ": MetaImage field '" + key + "' appears twice");
        tags.emplace_back(detail::trim(line.substr(0, eq)), detail::trim(line.substr(eq + 1)));
        if (key == "elementdatafile") { sawDataFile = true; break; }
    }
    if (!sawDataFile) throw Error(path + ": MetaImage header has no ElementDataFile field");
    const int64_t localOffset = int64_t(in.tellg());
    auto field = [&](std::initializer_list<const char*> keys) -> const std::string* {
        for (const char* k : keys)
            if (auto it = fields.find(k); it != fields.end()) return &it->second;
        return nullptr;
    };

    DenseVolume v;
    v.headerPath = path;
    if (const std::string* t = field({"objecttype"}); t && detail::lower(*t) != "image")
        throw Error(path + ": MetaImage ObjectType '" + *t + "' is not an Image");
    const std::string* ndims = field({"ndims"});
    if (!ndims) throw Error(path + ": MetaImage header has no NDims field");
    if (detail::parseInteger(*ndims, path + ": NDims") != 3) throw Error(path + ": NDims " + *ndims + " is not supported (only 3-D volumes)");
    const std::string* dimSize = field({"dimsize"});
    if (!dimSize) throw Error(path + ": MetaImage header has no DimSize field");
    const std::vector<std::string> dims = detail::tokens(*dimSize);
    if (dims.size() != 3) throw Error(path + ": DimSize has " + std::to_string(dims.size()) + " values, NDims is 3");
    for (int a = 0; a < 3; ++a) v.dims[size_t(a)] = detail::parseInteger(dims[size_t(a)], path + ": DimSize");

    int64_t channels = 1;
    if (const std::string* ch = field({"elementnumberofchannels"})) channels = detail::parseInteger(*ch, path + ": ElementNumberOfChannels");
    if (channels != 1 && channels != 3)
        throw Error(path + ": ElementNumberOfChannels " + std::to_string(channels) + " is not supported (1, and 3 for vectors or RGB)");
    v.components = unsigned(channels);
    const std::string* et = field({"elementtype"});
    if (!et) throw Error(path + ": MetaImage header has no ElementType field");
    static const std::map<std::string, SampleType> types{{"MET_UCHAR", SampleType::U8}, {"MET_CHAR", SampleType::I8},
                                                         {"MET_USHORT", SampleType::U16}, {"MET_SHORT", SampleType::I16},
                                                         {"MET_UINT", SampleType::U32}, {"MET_INT", SampleType::I32},
                                                         {"MET_FLOAT", SampleType::F32}, {"MET_DOUBLE", SampleType::F64}};
    const auto type = types.find(*et);
    if (type == types.end()) throw Error(path + ": ElementType '" + *et + "' is not supported (MET_UCHAR/CHAR/USHORT/SHORT/UINT/INT/FLOAT/DOUBLE are)");
    v.type = type->second;

    if (const std::string* b = field({"binarydata"}); b && !parseBool(*b, path + ": BinaryData"))
        throw Error(path + ": ASCII MetaImage data (BinaryData = False) is not supported");
    const std::string* msb = field({"binarydatabyteordermsb"});
    const std::string* emsb = field({"elementbyteordermsb"});
    if (msb && emsb && parseBool(*msb, path) != parseBool(*emsb, path))
        throw Error(path + ": BinaryDataByteOrderMSB and ElementByteOrderMSB disagree");
    if (msb) v.bigEndian = parseBool(*msb, path + ": BinaryDataByteOrderMSB");
    else if (emsb) v.bigEndian = parseBool(*emsb, path + ": ElementByteOrderMSB");

    std::array<double, 3> spacing{1, 1, 1};
    if (const std::string* s = field({"elementspacing", "elementsize"})) {
        const auto n = detail::parseNumbers(*s, 3, path + ": ElementSpacing");
        for (int a = 0; a < 3; ++a) spacing[size_t(a)] = n[size_t(a)];
    }
    if (const std::string* o = field({"offset", "origin", "position"})) {
        const auto n = detail::parseNumbers(*o, 3, path + ": Offset");
        for (int a = 0; a < 3; ++a) v.origin[size_t(a)] = n[size_t(a)];
    }
    std::array<double, 9> matrix{1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (const std::string* m = field({"transformmatrix", "rotation", "orientation"})) {
        const auto n = detail::parseNumbers(*m, 9, path + ": TransformMatrix");
        for (size_t i = 0; i < 9; ++i) matrix[i] = n[i];
    }
    if (const std::string* c = field({"centerofrotation"}); c) detail::parseNumbers(*c, 3, path + ": CenterOfRotation");
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) v.axes[size_t(a)][size_t(c)] = matrix[size_t(3 * a + c)] * spacing[size_t(a)];

    bool compressed = false;
    if (const std::string* c = field({"compresseddata"})) compressed = parseBool(*c, path + ": CompressedData");
    v.encoding = compressed ? DataEncoding::Zlib : DataEncoding::Raw;
    int64_t headerSize = 0;
    if (const std::string* h = field({"headersize"})) headerSize = detail::parseInteger(*h, path + ": HeaderSize");
    if (headerSize < -1) throw Error(path + ": HeaderSize " + std::to_string(headerSize) + " is invalid");
    if (headerSize == -1 && compressed) throw Error(path + ": HeaderSize -1 with compressed data is not supported");

    const std::string dataFile = *field({"elementdatafile"});
    if (dataFile == "LOCAL") {
        v.dataPath = path;
        v.dataOffset = localOffset;
        if (headerSize == -1) v.dataOffset = DenseVolume::kSkipToEnd;
        else v.decodedSkip = headerSize;
    } else {
        if (dataFile.empty()) throw Error(path + ": ElementDataFile is empty");
        if (dataFile.rfind("LIST", 0) == 0 || dataFile.find('%') != std::string::npos || detail::tokens(dataFile).size() != 1)
            throw Error(path + ": multi-file MetaImage data ('ElementDataFile = " + dataFile + "') is not supported");
        std::filesystem::path p(dataFile);
        if (p.is_relative()) p = std::filesystem::path(path).parent_path() / p;
        v.dataPath = p.string();
        v.dataNameInHeader = dataFile;
        if (headerSize == -1) v.dataOffset = DenseVolume::kSkipToEnd;
        else if (compressed) v.dataOffset = headerSize;
        else v.decodedSkip = headerSize;
    }
    // Tags that say more than the layout above, as written, for a decode
    // back to MetaImage (mha_tag_*, docs/SCAN_METADATA.md).
    static const char* layoutTags[] = {"objecttype", "ndims", "dimsize", "elementnumberofchannels", "elementtype", "binarydata", "binarydatabyteordermsb",
                                       "elementbyteordermsb", "compresseddata", "compresseddatasize", "transformmatrix", "rotation", "orientation",
                                       "offset", "position", "origin", "centerofrotation", "anatomicalorientation", "elementspacing", "headersize",
                                       "elementdatafile"};
    for (const auto& [tag, value] : tags)
        if (std::find(std::begin(layoutTags), std::end(layoutTags), detail::lower(tag)) == std::end(layoutTags))
            v.headerFields.push_back({"mha_tag_" + tag, value});
    v.validate();
    return v;
}

} // namespace vdbdag::bridge
