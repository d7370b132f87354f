// See NrrdHeader.h. Parsing is strict: a field whose value cannot be read is
// an error, never a silent default; fields this reader does not use and
// key/value pairs ("key:=value") are kept as header fields (nrrd_field_*,
// nrrd_key_*) for a decode back to NRRD.
#include "vdb_bridge/NrrdHeader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "vdb_bridge/detail/HeaderText.h"

namespace vdbdag::bridge {
namespace {

constexpr size_t kMaxHeaderBytes = 1u << 20;

SampleType nrrdType(const std::string& raw, const std::string& what) {
    const std::string t = detail::lower(detail::trim(raw));
    static const std::map<std::string, SampleType> types{
        {"signed char", SampleType::I8}, {"int8", SampleType::I8}, {"int8_t", SampleType::I8},
        {"uchar", SampleType::U8}, {"unsigned char", SampleType::U8}, {"uint8", SampleType::U8}, {"uint8_t", SampleType::U8},
        {"short", SampleType::I16}, {"short int", SampleType::I16}, {"signed short", SampleType::I16}, {"signed short int", SampleType::I16},
        {"int16", SampleType::I16}, {"int16_t", SampleType::I16},
        {"ushort", SampleType::U16}, {"unsigned short", SampleType::U16}, {"unsigned short int", SampleType::U16}, {"uint16", SampleType::U16},
        {"uint16_t", SampleType::U16},
        {"int", SampleType::I32}, {"signed int", SampleType::I32}, {"int32", SampleType::I32}, {"int32_t", SampleType::I32},
        {"uint", SampleType::U32}, {"unsigned int", SampleType::U32}, {"uint32", SampleType::U32}, {"uint32_t", SampleType::U32},
        {"float", SampleType::F32}, {"double", SampleType::F64}};
    const auto it = types.find(t);
    if (it == types.end()) throw Error(what + ": unsupported NRRD type '" + detail::trim(raw) + "' (8-, 16- and 32-bit integers, float and double are)");
    return it->second;
}

// "(a,b,c) (d,e,f) none" -> one entry per axis; "none" -> empty vector.
std::vector<std::vector<double>> parseVectors(const std::string& s, const std::string& what) {
    std::vector<std::vector<double>> out;
    size_t i = 0;
    while (i < s.size()) {
        if (std::isspace(static_cast<unsigned char>(s[i]))) { ++i; continue; }
        if (s[i] == '(') {
            const size_t close = s.find(')', i);
            if (close == std::string::npos) throw Error(what + ": unbalanced '(' in '" + detail::trim(s) + "'");
            std::string inner = s.substr(i + 1, close - i - 1);
            std::vector<double> v;
            size_t start = 0;
            while (true) {
                const size_t comma = inner.find(',', start);
                v.push_back(detail::parseNumber(detail::trim(inner.substr(start, comma - start)), what));
                if (comma == std::string::npos) break;
                start = comma + 1;
            }
            out.push_back(v);
            i = close + 1;
        } else if (s.compare(i, 4, "none") == 0) {
            out.emplace_back();
            i += 4;
        } else {
            throw Error(what + ": cannot read '" + detail::trim(s) + "' as vectors");
        }
    }
    return out;
}

// A 4-D NRRD whose last axis holds volumes (a time series, a list): its
// space direction is "none" while the first's is not, or, with spacings or
// no directions, its kind is not a spatial one ("domain", "space") while
// the first's is.
bool lastAxisIsVolumes(const std::map<std::string, std::string>& fields, const std::string& path) {
    if (auto dirs = fields.find("space directions"); dirs != fields.end()) {
        const auto vectors = parseVectors(dirs->second, path + ": space directions");
        return vectors.size() == 4 && vectors[3].empty() && !vectors[0].empty();
    }
    if (auto kinds = fields.find("kinds"); kinds != fields.end()) {
        const std::vector<std::string> k = detail::tokens(kinds->second);
        auto spatial = [](const std::string& kind) {
            const std::string l = detail::lower(kind);
            return l == "domain" || l == "space";
        };
        return k.size() == 4 && !spatial(k[3]) && spatial(k[0]);
    }
    return false;
}

} // namespace

DenseVolume readNrrdHeader(const std::string& path, std::optional<int64_t> volume) {
    checkInputFile(path, "a NRRD file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open");
    std::string line;
    size_t budget = kMaxHeaderBytes;
    const std::string tooLong = path + ": NRRD header longer than 1 MiB (no blank line ends it?)";
    char magic[7] = {};
    in.read(magic, sizeof magic);
    if (in.gcount() != 7 || std::string(magic, 7) != "NRRD000")
        throw Error(path + ": not a NRRD file (it does not start with the magic 'NRRD000X')");
    detail::getBoundedLine(in, line, budget, tooLong);

    std::map<std::string, std::string> fields;
    std::vector<std::pair<std::string, std::string>> keyValues;
    bool blankLineSeen = false;
    while (detail::getBoundedLine(in, line, budget, tooLong)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) { blankLineSeen = true; break; }
        if (line[0] == '#') continue;
        const size_t kv = line.find(":=");
        const size_t colon = line.find(": ");
        if (kv != std::string::npos && (colon == std::string::npos || kv < colon)) {  // key/value pair, kept for a decode
            keyValues.emplace_back(line.substr(0, kv), line.substr(kv + 2));
            continue;
        }
        if (colon == std::string::npos) throw Error(path + ": malformed NRRD header line '" + line + "' (expected 'field: value')");
        std::string key = detail::lower(detail::trim(line.substr(0, colon)));
        // Field names may be written with or without their spaces ("datafile").
        static const std::map<std::string, std::string> aliases{{"datafile", "data file"}, {"byteskip", "byte skip"}, {"lineskip", "line skip"},
                                                                {"spacedirections", "space directions"}, {"spaceorigin", "space origin"},
                                                                {"spacedimension", "space dimension"}, {"centerings", "centers"}};
        if (auto a = aliases.find(key); a != aliases.end()) key = a->second;
        if (!fields.emplace(key, line.substr(colon + 2)).second) throw Error(path + ": NRRD field '" + key + "' appears twice");
    }
    const int64_t attachedOffset = blankLineSeen ? int64_t(in.tellg()) : -1;
    auto field = [&](const std::string& key) -> const std::string* {
        auto it = fields.find(key);
        return it == fields.end() ? nullptr : &it->second;
    };
    auto required = [&](const std::string& key) -> const std::string& {
        if (const std::string* v = field(key)) return *v;
        throw Error(path + ": NRRD header has no '" + key + "' field");
    };

    DenseVolume v;
    v.headerPath = path;
    const int64_t dimension = detail::parseInteger(detail::trim(required("dimension")), path + ": dimension");
    if (dimension != 3 && dimension != 4)
        throw Error(path + ": NRRD dimension " + std::to_string(dimension) +
                    " is not supported (3-D volumes; 4-D with a leading axis of 3 components or a last, non-spatial axis of volumes)");
    v.type = nrrdType(required("type"), path);
    const std::vector<std::string> sizes = detail::tokens(required("sizes"));
    if (int64_t(sizes.size()) != dimension)
        throw Error(path + ": 'sizes' has " + std::to_string(sizes.size()) + " values, dimension is " + std::to_string(dimension));
    // 4-D: either a leading (fastest) axis of 3 components per sample, a
    // vector or an RGB colour (kinds "RGB-color"), or a last (slowest) axis
    // of volumes, a time series: the axis whose space direction is "none"
    // (or, with spacings, whose kind is not a spatial one) says which.
    const bool series = dimension == 4 && lastAxisIsVolumes(fields, path);
    const size_t first = dimension == 4 && !series ? 1 : 0;
    int64_t volumes = 1;
    if (series) {
        volumes = detail::parseInteger(sizes[3], path + ": sizes");
        if (volumes < 1) throw Error(path + ": sizes: the volume axis is empty");
        const int64_t t = volume.value_or(0);
        if (t < 0 || t >= volumes)
            throw Error(path + ": --volume " + std::to_string(t) + " is out of range: the file holds " + std::to_string(volumes) + " volumes (0.." +
                        std::to_string(volumes - 1) + ")");
        if (volumes > 1) {
            v.gridName = scanNameOf(path) + "_t" + std::to_string(t);
            v.volumeIndex = t;
            v.volumeCount = volumes;
        }
    } else if (dimension == 4) {
        const int64_t components = detail::parseInteger(sizes[0], path + ": sizes");
        if (components != 3)
            throw Error(path + ": a 4-D NRRD needs a leading axis of 3 components (a vector or RGB per sample); this one has " + sizes[0]);
        v.components = 3;
        if (const std::string* k = field("kinds")) {
            const std::vector<std::string> kinds = detail::tokens(*k);
            if (!kinds.empty() && detail::lower(kinds[0]) == "rgb-color") v.colour = true;
        }
    }
    if (!series && volume.value_or(0) != 0)  // as NIfTI's reader says it (a 3-D file was read as if asked for volume 0)
        throw Error(path + ": --volume " + std::to_string(*volume) + " is out of range: the file holds 1 volume (0..0)");
    for (int a = 0; a < 3; ++a) v.dims[size_t(a)] = detail::parseInteger(sizes[first + size_t(a)], path + ": sizes");

    const std::string encoding = detail::lower(detail::trim(required("encoding")));
    if (encoding == "raw") v.encoding = DataEncoding::Raw;
    else if (encoding == "gzip" || encoding == "gz") v.encoding = DataEncoding::Zlib;
    else throw Error(path + ": NRRD encoding '" + encoding + "' is not supported (raw and gzip are)");

    if (const std::string* e = field("endian")) {
        const std::string endian = detail::lower(detail::trim(*e));
        if (endian == "big") v.bigEndian = true;
        else if (endian == "little") v.bigEndian = false;
        else throw Error(path + ": endian '" + detail::trim(*e) + "' is neither 'little' nor 'big'");
    } else if (sampleBytes(v.type) > 1) {
        throw Error(path + ": NRRD header has no 'endian' field, required for " + std::to_string(8 * sampleBytes(v.type)) + "-bit samples");
    }

    if (const std::string* sd = field("space dimension")) {
        if (detail::parseInteger(detail::trim(*sd), path + ": space dimension") != 3)
            throw Error(path + ": space dimension " + detail::trim(*sd) + " is not supported (3 is)");
    }
    if (const std::string* sp = field("space")) {
        // The patient space, kept so that a decode writes it back and other
        // formats convert consistently (DenseVolume::space).
        static const std::map<std::string, std::string> spaces{
            {"left-posterior-superior", "LPS"}, {"lps", "LPS"}, {"right-anterior-superior", "RAS"}, {"ras", "RAS"},
            {"left-anterior-superior", "LAS"}, {"las", "LAS"}, {"scanner-xyz", ""}, {"3d-right-handed", ""}, {"3d-left-handed", ""}};
        const auto it = spaces.find(detail::lower(detail::trim(*sp)));
        if (it == spaces.end()) throw Error(path + ": NRRD space '" + detail::trim(*sp) + "' is not a 3-D space this reader knows");
        v.space = it->second;
    }
    if (const std::string* dirs = field("space directions")) {
        if (field("spacings")) throw Error(path + ": NRRD header has both 'space directions' and 'spacings'");
        auto vectors = parseVectors(*dirs, path + ": space directions");
        if (int64_t(vectors.size()) != dimension)
            throw Error(path + ": 'space directions' has " + std::to_string(vectors.size()) + " entries, dimension is " + std::to_string(dimension));
        if (first) {
            if (!vectors[0].empty()) throw Error(path + ": the component axis of a 4-D NRRD must have space direction 'none'");
            vectors.erase(vectors.begin());
        } else if (series) {
            vectors.pop_back();  // the volume axis: 'none' (lastAxisIsVolumes)
        }
        for (int a = 0; a < 3; ++a) {
            if (vectors[size_t(a)].empty()) throw Error(path + ": axis " + std::to_string(a) + " has space direction 'none' (non-spatial axes are not supported)");
            if (vectors[size_t(a)].size() != 3) throw Error(path + ": space direction of axis " + std::to_string(a) + " does not have 3 components");
            for (int c = 0; c < 3; ++c) v.axes[size_t(a)][size_t(c)] = vectors[size_t(a)][size_t(c)];
        }
    } else if (const std::string* sp = field("spacings")) {
        std::vector<std::string> t = detail::tokens(*sp);
        if (int64_t(t.size()) != dimension)
            throw Error(path + ": 'spacings' has " + std::to_string(t.size()) + " values, dimension is " + std::to_string(dimension));
        if (first) t.erase(t.begin());
        for (int a = 0; a < 3; ++a) {  // (a series' 4th spacing is its time step)
            // NRRD writes "nan" for an unknown spacing: take 1.
            const double s = detail::lower(t[size_t(a)]) == "nan" ? 1.0 : detail::parseNumber(t[size_t(a)], path + ": spacings");
            v.axes[size_t(a)] = {0, 0, 0};
            v.axes[size_t(a)][size_t(a)] = s;
        }
    }
    if (const std::string* o = field("space origin")) {
        const auto vectors = parseVectors(*o, path + ": space origin");
        if (vectors.size() != 1 || vectors[0].size() != 3) throw Error(path + ": 'space origin' must be one 3-vector '(x,y,z)'");
        for (int c = 0; c < 3; ++c) v.origin[size_t(c)] = vectors[0][size_t(c)];
    }

    int64_t byteSkip = 0, lineSkip = 0;
    if (const std::string* b = field("byte skip")) byteSkip = detail::parseInteger(detail::trim(*b), path + ": byte skip");
    if (const std::string* l = field("line skip")) lineSkip = detail::parseInteger(detail::trim(*l), path + ": line skip");
    if (byteSkip < -1) throw Error(path + ": byte skip " + std::to_string(byteSkip) + " is invalid");
    if (lineSkip < 0) throw Error(path + ": line skip " + std::to_string(lineSkip) + " is invalid");
    if (byteSkip == -1 && v.encoding != DataEncoding::Raw) throw Error(path + ": byte skip -1 is only allowed with raw encoding");
    if (lineSkip && v.encoding != DataEncoding::Raw) throw Error(path + ": line skip with compressed data is not supported");

    if (const std::string* df = field("data file")) {
        const std::string name = detail::trim(*df);
        if (name.rfind("LIST", 0) == 0 || detail::tokens(name).size() != 1)
            throw Error(path + ": multi-file NRRD data ('data file: " + name + "') is not supported");
        std::filesystem::path p(name);
        if (p.is_relative()) p = std::filesystem::path(path).parent_path() / p;
        v.dataPath = p.string();
        v.dataNameInHeader = name;
        v.dataOffset = 0;
    } else {
        if (attachedOffset < 0) throw Error(path + ": NRRD header has neither a 'data file' field nor a blank line before attached data");
        v.dataPath = path;
        v.dataOffset = attachedOffset;
    }
    if (byteSkip == -1) v.dataOffset = DenseVolume::kSkipToEnd;
    else v.decodedSkip = byteSkip;
    v.lineSkip = lineSkip;
    if (v.volumeCount > 1) {  // volume t of a series: its samples follow the t volumes before it
        if (byteSkip == -1) throw Error(path + ": byte skip -1 (data at the end of the file) is not supported for a 4-D series");
        const uint64_t volumeBytes = v.sampleCount() * sampleBytes(v.type);
        if (v.encoding == DataEncoding::Raw) v.dataOffset += int64_t(uint64_t(v.volumeIndex) * volumeBytes);
        else v.decodedSkip += int64_t(uint64_t(v.volumeIndex) * volumeBytes);
    }
    // Fields that say more than the layout above, and every key/value pair,
    // for a decode back to NRRD (docs/SCAN_METADATA.md).
    static const char* layoutFields[] = {"type", "dimension", "sizes", "encoding", "endian", "space", "space dimension", "space directions",
                                         "spacings", "space origin", "byte skip", "line skip", "data file", "kinds"};
    for (const auto& [key, value] : fields)
        if (std::find(std::begin(layoutFields), std::end(layoutFields), key) == std::end(layoutFields))
            v.headerFields.push_back({"nrrd_field_" + key, detail::trim(value)});
    for (const auto& [key, value] : keyValues) v.headerFields.push_back({"nrrd_key_" + key, value});
    v.validate();
    return v;
}

} // namespace vdbdag::bridge
