// See DenseExport.h. Bricks are visited in z order (an index sorted once),
// so each 4-slice slab is filled from the bricks and tiles that reach it and
// written before the next; the samples go through one output stream, raw or
// gzip-deflated (.nii.gz), behind the header.
#include "vdb_bridge/DenseExport.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/core.h>
#include <nifti2_io.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {
namespace {

enum class OutFormat { Nrrd, Nhdr, Mha, Mhd, Nii, NiiGz, Raw };

std::optional<OutFormat> outFormatOf(const std::string& path) {
    std::string name = std::filesystem::path(path).filename().string();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const std::string ext = std::filesystem::path(name).extension().string();
    if (name.size() > 7 && name.ends_with(".nii.gz")) return OutFormat::NiiGz;
    if (ext == ".nrrd") return OutFormat::Nrrd;
    if (ext == ".nhdr") return OutFormat::Nhdr;
    if (ext == ".mha") return OutFormat::Mha;
    if (ext == ".mhd") return OutFormat::Mhd;
    if (ext == ".nii") return OutFormat::Nii;
    if (ext == ".raw") return OutFormat::Raw;
    return std::nullopt;
}

// Where the samples go and how the file describes them.
struct Layout {
    std::array<int64_t, 3> dims{0, 0, 0};
    std::array<int64_t, 3> lo{0, 0, 0};  // index coordinate of sample (0, 0, 0)
    SampleType type = SampleType::I32;
    bool rescaled = false;
    double slope = 1, intercept = 0;
    std::array<double, 3> origin{0, 0, 0};  // world position of sample (0, 0, 0)
    std::array<std::array<double, 3>, 3> axes{};
    std::string space;  // "LPS" or empty
    unsigned components = 1;  // 3 for vector and colour grids
    bool colour = false;      // RGB (NIfTI RGB24, NRRD "RGB-color")
    uint64_t sliceSamples() const { return uint64_t(dims[0]) * uint64_t(dims[1]); }
};

std::optional<SampleType> sampleTypeNamed(const std::string& name) {
    for (SampleType t : {SampleType::U8, SampleType::I8, SampleType::U16, SampleType::I16, SampleType::U32, SampleType::I32, SampleType::F32,
                         SampleType::F64})
        if (name == sampleTypeName(t)) return t;
    return std::nullopt;
}

// The active and stored-inactive voxels' bounding box [lo, hi].
bool boundsOf(const GridRecord& g, std::array<int64_t, 3>& lo, std::array<int64_t, 3>& hi) {
    bool any = false;
    auto add = [&](int64_t x, int64_t y, int64_t z, int64_t size) {
        const int64_t p[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            lo[size_t(a)] = any ? std::min(lo[size_t(a)], p[a]) : p[a];
            hi[size_t(a)] = any ? std::max(hi[size_t(a)], p[a] + size - 1) : p[a] + size - 1;
        }
        any = true;
    };
    for (const GridTopology* t : {&g.topology, &g.inactiveTopology}) {
        for (const Brick& b : t->bricks)
            for (uint64_t m = b.mask; m; m &= m - 1) {
                const int bit = std::countr_zero(m);
                add(b.x + (bit & 3), b.y + ((bit >> 2) & 3), b.z + (bit >> 4), 1);
            }
        for (const Tile& tile : t->tiles) add(tile.x, tile.y, tile.z, int64_t(1) << tile.log2Size);
    }
    return any;
}

Layout layoutOf(const GridRecord& grid, const std::string& path) {
    const std::string what = path + ": grid '" + grid.name + "'";
    const openvdb::GridBase::Ptr g = detail::readDescriptor(grid.vdbDescriptor, what);
    Layout l;
    if (auto t = g->getMetadata<openvdb::StringMetadata>("source_sample_type")) {
        const auto type = sampleTypeNamed(t->value());
        if (!type) throw Error(what + ": its source_sample_type '" + t->value() + "' is not a sample type");
        l.type = *type;
    } else {
        switch (grid.valueType) {
            case ValueType::Int32:
            case ValueType::Vec3I: l.type = SampleType::I32; break;
            case ValueType::Float:
            case ValueType::Vec3S: l.type = SampleType::F32; break;
            case ValueType::Double:
            case ValueType::Vec3D: l.type = SampleType::F64; break;
            case ValueType::Bool:
            case ValueType::Mask: l.type = SampleType::U8; break;
            default:
                throw Error(what + " holds " + valueTypeName(grid.valueType) + " values, which a scan file cannot hold (int32, float, double, bool, mask and vec3 can)");
        }
    }
    if (grid.valueType == ValueType::Vec3I || grid.valueType == ValueType::Vec3S || grid.valueType == ValueType::Vec3D) {
        l.components = 3;
        if (auto c = g->getMetadata<openvdb::StringMetadata>("source_colour"); c && c->value() == "rgb") l.colour = true;
    }
    if (auto s = g->getMetadata<openvdb::DoubleMetadata>("source_rescale_slope")) {
        l.rescaled = true;
        l.slope = s->value();
        if (auto i = g->getMetadata<openvdb::DoubleMetadata>("source_rescale_intercept")) l.intercept = i->value();
        if (!std::isfinite(l.slope) || l.slope == 0 || !std::isfinite(l.intercept)) throw Error(what + ": its rescale slope/intercept is not usable");
    }
    if (auto s = g->getMetadata<openvdb::StringMetadata>("space"); s && s->value() == "LPS") l.space = "LPS";
    std::array<int64_t, 3> lo{0, 0, 0}, hi{-1, -1, -1};
    const bool any = boundsOf(grid, lo, hi);
    if (auto d = g->getMetadata<openvdb::Vec3IMetadata>("source_dims")) {
        for (int a = 0; a < 3; ++a) l.dims[size_t(a)] = d->value()[a];
        for (int a = 0; a < 3; ++a)
            if (l.dims[size_t(a)] < 1) throw Error(what + ": its source_dims are not positive");
        if (any && (lo[0] < 0 || lo[1] < 0 || lo[2] < 0 || hi[0] >= l.dims[0] || hi[1] >= l.dims[1] || hi[2] >= l.dims[2]))
            throw Error(what + ": voxels lie outside its recorded extent " + fmt::format("{}x{}x{}", l.dims[0], l.dims[1], l.dims[2]));
    } else {
        if (!any) throw Error(what + " has no voxels, so no extent to write (and no source_dims)");
        l.lo = lo;
        for (int a = 0; a < 3; ++a) l.dims[size_t(a)] = hi[size_t(a)] - lo[size_t(a)] + 1;
    }
    for (int a = 0; a < 3; ++a)
        if (l.dims[size_t(a)] > std::numeric_limits<int32_t>::max()) throw Error(what + ": its extent is too large for a scan file");
    const auto& m = grid.indexToWorld;  // world = [i j k 1] * M
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) l.axes[size_t(a)][size_t(c)] = m[size_t(4 * a + c)];
    for (int c = 0; c < 3; ++c)
        l.origin[size_t(c)] = m[size_t(12 + c)] + double(l.lo[0]) * m[size_t(c)] + double(l.lo[1]) * m[size_t(4 + c)] + double(l.lo[2]) * m[size_t(8 + c)];
    return l;
}

// ---- samples ---------------------------------------------------------------

// Grid value -> stored sample. Values must convert exactly (a value the
// import's rescale cannot have produced is an error); the background, which
// may be a mean, is rounded to the nearest sample instead.
template <typename V, typename S>
struct ToSample {
    const Layout& l;
    bool exact(V v, S& out) const {
        if constexpr (std::is_floating_point_v<S>) {
            if (!l.rescaled) {
                if constexpr (std::is_same_v<V, S>) {
                    out = v;  // bit for bit (NaN payloads, -0)
                    return true;
                } else {
                    out = S(v);
                    return V(out) == v;
                }
            }
            out = S((double(v) - l.intercept) / l.slope);
            return forward(out) == v || (std::isnan(double(v)) && std::isnan(double(out)));
        } else {
            if constexpr (std::is_integral_v<V>) {
                int64_t x = int64_t(v);
                if (l.rescaled) {
                    const int64_t a = int64_t(l.slope), b = int64_t(l.intercept);
                    if (double(a) != l.slope || double(b) != l.intercept || (x - b) % a != 0) return false;
                    x = (x - b) / a;
                }
                if (x < int64_t(std::numeric_limits<S>::min()) || x > int64_t(std::numeric_limits<S>::max())) return false;
                out = S(x);
                return true;
            } else {
                const double x = std::nearbyint((double(v) - l.intercept) / l.slope);
                if (!(x >= double(std::numeric_limits<S>::min()) && x <= double(std::numeric_limits<S>::max()))) return false;
                out = S(x);
                return forward(out) == v;
            }
        }
    }
    V forward(S s) const {  // DenseImport's stored sample -> value
        if (!l.rescaled) return V(s);
        if constexpr (std::is_integral_v<V>) return V(int64_t(s) * int64_t(l.slope) + int64_t(l.intercept));
        else return V(double(s) * l.slope + l.intercept);
    }
    S nearest(V v) const {
        S out;
        if (exact(v, out)) return out;
        double x = l.rescaled ? (double(v) - l.intercept) / l.slope : double(v);
        if constexpr (std::is_integral_v<S>) {
            if (!std::isfinite(x)) x = 0;
            x = std::clamp(std::nearbyint(x), double(std::numeric_limits<S>::min()), double(std::numeric_limits<S>::max()));
        }
        return S(x);
    }
};

// The output stream, raw or gzip-deflated.
class SampleSink {
public:
    SampleSink(std::ostream& out, bool gzip) : out_(out), gzip_(gzip) {
        if (gzip_ && deflateInit2(&z_, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw std::bad_alloc();
    }
    ~SampleSink() {
        if (gzip_) deflateEnd(&z_);
    }
    void write(const void* data, size_t n) {
        if (!gzip_) {
            out_.write(static_cast<const char*>(data), std::streamsize(n));
            return;
        }
        z_.next_in = const_cast<Bytef*>(static_cast<const Bytef*>(data));
        z_.avail_in = uInt(n);  // callers write at most one slab (< 4 GiB)
        pump(Z_NO_FLUSH);
    }
    void finish() {
        if (gzip_) pump(Z_FINISH);
        out_.flush();
    }

private:
    void pump(int flush) {
        std::vector<uint8_t> buffer(1u << 20);
        for (;;) {
            z_.next_out = buffer.data();
            z_.avail_out = uInt(buffer.size());
            const int rc = deflate(&z_, flush);
            out_.write(reinterpret_cast<const char*>(buffer.data()), std::streamsize(buffer.size() - z_.avail_out));
            if (rc == Z_STREAM_END) return;
            if (rc != Z_OK && rc != Z_BUF_ERROR) throw Error("zlib deflate failed");
            if (flush == Z_NO_FLUSH && z_.avail_in == 0 && z_.avail_out != 0) return;
        }
    }
    std::ostream& out_;
    bool gzip_;
    z_stream z_{};
};

// Bricks of one layer sorted by z, with the offset of each one's values.
struct ZOrder {
    std::vector<uint32_t> order;
    std::vector<uint64_t> firstValue;  // by brick index (topology order)
    explicit ZOrder(const GridTopology& t) {
        if (t.bricks.size() > std::numeric_limits<uint32_t>::max()) throw Error("a grid of more than 2^32 bricks cannot be written as a scan file yet");
        order.resize(t.bricks.size());
        firstValue.resize(t.bricks.size());
        uint64_t at = 0;
        for (size_t i = 0; i < t.bricks.size(); ++i) {
            order[i] = uint32_t(i);
            firstValue[i] = at;
            at += uint64_t(std::popcount(t.bricks[i].mask));
        }
        std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return t.bricks[a].z < t.bricks[b].z; });
    }
};

// V: the value type of one component. `plane` < 0 writes every component of
// a voxel in turn (interleaved); otherwise only component `plane`.
template <typename V, typename S>
void writeSamples(const GridRecord& grid, const Layout& l, SampleSink& sink, const std::string& path, bool showProgress, int plane) {
    const ToSample<V, S> conv{l};
    const unsigned components = l.components;
    const unsigned outK = plane < 0 ? components : 1;
    std::array<S, 3> background{};
    for (unsigned k = 0; k < outK; ++k) {
        V backgroundValue{};
        const size_t at = size_t(plane < 0 ? k : unsigned(plane)) * sizeof(V);
        if (grid.background.size() >= at + sizeof(V)) std::memcpy(&backgroundValue, grid.background.data() + at, sizeof(V));
        background[k] = conv.nearest(backgroundValue);
    }
    const int64_t nx = l.dims[0], ny = l.dims[1], nz = l.dims[2];
    constexpr int64_t kSlab = 4;
    const int64_t slabs = (nz + kSlab - 1) / kSlab;
    std::optional<Progress> progress;
    if (showProgress) progress.emplace("decode " + std::filesystem::path(path).filename().string(), uint64_t(slabs));
    std::vector<S> slab(size_t(uint64_t(kSlab) * l.sliceSamples() * outK));
    const bool mask = grid.valueType == ValueType::Mask;
    struct LayerRef {
        const GridTopology* topology;
        const LayerValues* values;
        ZOrder z;
        size_t first = 0;
    };
    std::vector<LayerRef> layers;  // inactive first: active voxels win
    layers.push_back({&grid.inactiveTopology, &grid.inactiveValues, ZOrder(grid.inactiveTopology)});
    layers.push_back({&grid.topology, &grid.values, ZOrder(grid.topology)});
    std::atomic<bool> inexact{false};
    std::array<int64_t, 3> badAt{0, 0, 0};
    std::atomic_flag badTaken = ATOMIC_FLAG_INIT;
    for (int64_t s = 0; s < slabs; ++s) {
        const int64_t z0 = s * kSlab, z1 = std::min(nz, z0 + kSlab);  // sample z range [z0, z1)
        const size_t used = size_t(uint64_t(z1 - z0) * l.sliceSamples() * outK);
        for (size_t i = 0; i < used; i += outK)
            for (unsigned k = 0; k < outK; ++k) slab[i + k] = background[k];
        auto put = [&](int64_t x, int64_t y, int64_t z, const uint8_t* value, bool active) {
            // (x, y, z): sample coordinates, inside the slab
            const size_t at = size_t(((z - z0) * ny + y) * nx + x) * outK;
            for (unsigned k = 0; k < outK; ++k) {
                V v;
                if (mask) v = V(active ? 1 : 0);
                else std::memcpy(&v, value + size_t(plane < 0 ? k : unsigned(plane)) * sizeof(V), sizeof(V));
                S out;
                if (!conv.exact(v, out)) {
                    inexact = true;
                    if (!badTaken.test_and_set()) badAt = {x, y, z};
                    return;
                }
                slab[at + k] = out;
            }
        };
        for (LayerRef& layer : layers) {
            const GridTopology& t = *layer.topology;
            const uint8_t* values = layer.values->bricks.data();
            const bool active = &t == &grid.topology;
            // Bricks reaching [z0, z1): brick z in (z0 - 4, z1) in sample space.
            while (layer.first < layer.z.order.size() && int64_t(t.bricks[layer.z.order[layer.first]].z) - l.lo[2] <= z0 - 4) ++layer.first;
            size_t end = layer.first;
            while (end < layer.z.order.size() && int64_t(t.bricks[layer.z.order[end]].z) - l.lo[2] < z1) ++end;
            tbb::parallel_for(tbb::blocked_range<size_t>(layer.first, end, 256), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t k = r.begin(); k != r.end(); ++k) {
                    const uint32_t i = layer.z.order[k];
                    const Brick& b = t.bricks[i];
                    uint64_t valueIndex = layer.z.firstValue[i];
                    for (uint64_t m = b.mask; m; m &= m - 1, ++valueIndex) {
                        const int bit = std::countr_zero(m);
                        const int64_t z = int64_t(b.z) + (bit >> 4) - l.lo[2];
                        if (z < z0 || z >= z1) continue;
                        put(int64_t(b.x) + (bit & 3) - l.lo[0], int64_t(b.y) + ((bit >> 2) & 3) - l.lo[1], z,
                            mask ? nullptr : values + valueIndex * components * sizeof(V), active);
                    }
                }
            });
            const uint8_t* tileValues = layer.values->tiles.data();
            for (size_t ti = 0; ti < t.tiles.size(); ++ti) {
                const Tile& tile = t.tiles[ti];
                const int64_t size = int64_t(1) << tile.log2Size;
                const int64_t tz0 = std::max(z0, int64_t(tile.z) - l.lo[2]), tz1 = std::min(z1, int64_t(tile.z) - l.lo[2] + size);
                const int64_t tx0 = std::max<int64_t>(0, int64_t(tile.x) - l.lo[0]), tx1 = std::min(nx, int64_t(tile.x) - l.lo[0] + size);
                const int64_t ty0 = std::max<int64_t>(0, int64_t(tile.y) - l.lo[1]), ty1 = std::min(ny, int64_t(tile.y) - l.lo[1] + size);
                for (int64_t z = tz0; z < tz1; ++z)
                    for (int64_t y = ty0; y < ty1; ++y)
                        for (int64_t x = tx0; x < tx1; ++x) put(x, y, z, mask ? nullptr : tileValues + ti * components * sizeof(V), active);
            }
        }
        if (inexact)
            throw Error(path + ": the sample at (" + std::to_string(badAt[0]) + ", " + std::to_string(badAt[1]) + ", " + std::to_string(badAt[2]) +
                        ") is not a " + sampleTypeName(l.type) + " sample" + (l.rescaled ? " under the recorded rescale" : "") +
                        ": the grid was changed after import; write it as .vdb, or as a float scan");
        sink.write(slab.data(), used * sizeof(S));
        if (progress) progress->advance();
    }
    if (progress) progress->finish();
}

template <typename V>
void writeSamplesAs(const GridRecord& grid, const Layout& l, SampleSink& sink, const std::string& path, bool showProgress, int plane) {
    switch (l.type) {
        case SampleType::U8: return writeSamples<V, uint8_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::I8: return writeSamples<V, int8_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::U16: return writeSamples<V, uint16_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::I16: return writeSamples<V, int16_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::U32: return writeSamples<V, uint32_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::I32: return writeSamples<V, int32_t>(grid, l, sink, path, showProgress, plane);
        case SampleType::F32: return writeSamples<V, float>(grid, l, sink, path, showProgress, plane);
        case SampleType::F64: return writeSamples<V, double>(grid, l, sink, path, showProgress, plane);
    }
}

// Every sample; `planar`: a vector grid's components one after the other
// (NIfTI's 5th dimension), else interleaved.
void writeAllSamples(const GridRecord& grid, const Layout& l, SampleSink& sink, const std::string& path, bool showProgress, bool planar = false) {
    auto each = [&](auto component) {
        using C = decltype(component);
        if (!planar || l.components == 1) return writeSamplesAs<C>(grid, l, sink, path, showProgress, -1);
        for (int c = 0; c < int(l.components); ++c) writeSamplesAs<C>(grid, l, sink, path, showProgress, c);
    };
    switch (grid.valueType) {
        case ValueType::Int32: return each(int32_t{});
        case ValueType::Int64: return each(int64_t{});
        case ValueType::Float: return each(float{});
        case ValueType::Double: return each(double{});
        case ValueType::Vec3I: return each(int32_t{});
        case ValueType::Vec3S: return each(float{});
        case ValueType::Vec3D: return each(double{});
        case ValueType::Bool:
        case ValueType::Mask: return each(uint8_t{});
        default: throw Error(path + ": grid '" + grid.name + "' holds " + valueTypeName(grid.valueType) + " values, which a scalar scan file cannot hold");
    }
}

// ---- headers ---------------------------------------------------------------

std::string g17(double x) { return fmt::format("{:.17g}", x); }

const char* nrrdTypeName(SampleType t) {
    switch (t) {
        case SampleType::U8: return "uint8";
        case SampleType::I8: return "int8";
        case SampleType::U16: return "uint16";
        case SampleType::I16: return "int16";
        case SampleType::U32: return "uint32";
        case SampleType::I32: return "int32";
        case SampleType::F32: return "float";
        case SampleType::F64: return "double";
    }
    return "";
}

std::string nrrdHeader(const Layout& l, const std::string& dataFile) {
    std::string h = "NRRD0004\n# written by vdbdag decode\n";
    const bool vector = l.components == 3;
    h += fmt::format("type: {}\ndimension: {}\n", nrrdTypeName(l.type), vector ? 4 : 3);
    h += l.space == "LPS" ? "space: left-posterior-superior\n" : "space dimension: 3\n";
    h += fmt::format("sizes: {}{} {} {}\n", vector ? "3 " : "", l.dims[0], l.dims[1], l.dims[2]);
    h += vector ? "space directions: none" : "space directions:";
    for (const auto& a : l.axes) h += fmt::format(" ({},{},{})", g17(a[0]), g17(a[1]), g17(a[2]));
    h += fmt::format("\nkinds: {}domain domain domain\nendian: little\nencoding: raw\n", vector ? (l.colour ? "RGB-color " : "vector ") : "");
    h += fmt::format("space origin: ({},{},{})\n", g17(l.origin[0]), g17(l.origin[1]), g17(l.origin[2]));
    if (!dataFile.empty()) h += "data file: " + dataFile + "\n";
    else h += "\n";
    return h;
}

const char* metTypeName(SampleType t) {
    switch (t) {
        case SampleType::U8: return "MET_UCHAR";
        case SampleType::I8: return "MET_CHAR";
        case SampleType::U16: return "MET_USHORT";
        case SampleType::I16: return "MET_SHORT";
        case SampleType::U32: return "MET_UINT";
        case SampleType::I32: return "MET_INT";
        case SampleType::F32: return "MET_FLOAT";
        case SampleType::F64: return "MET_DOUBLE";
    }
    return "";
}

// TransformMatrix triple a = index axis a's direction; ElementSpacing its length.
std::string metaImageHeader(const Layout& l, const std::string& dataFile) {
    std::string h = "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\nTransformMatrix =";
    std::array<double, 3> spacing{};
    for (int a = 0; a < 3; ++a) {
        const auto& v = l.axes[size_t(a)];
        spacing[size_t(a)] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; ++c) h += " " + g17(v[size_t(c)] / spacing[size_t(a)]);
    }
    h += fmt::format("\nOffset = {} {} {}\nCenterOfRotation = 0 0 0\n", g17(l.origin[0]), g17(l.origin[1]), g17(l.origin[2]));
    if (l.space == "LPS") h += "AnatomicalOrientation = RAI\n";
    if (l.components != 1) h += fmt::format("ElementNumberOfChannels = {}\n", l.components);
    h += fmt::format("ElementSpacing = {} {} {}\nDimSize = {} {} {}\nElementType = {}\nElementDataFile = {}\n", g17(spacing[0]), g17(spacing[1]),
                     g17(spacing[2]), l.dims[0], l.dims[1], l.dims[2], metTypeName(l.type), dataFile.empty() ? "LOCAL" : dataFile);
    return h;
}

int niftiDatatype(SampleType t) {
    switch (t) {
        case SampleType::U8: return DT_UINT8;
        case SampleType::I8: return DT_INT8;
        case SampleType::U16: return DT_UINT16;
        case SampleType::I16: return DT_INT16;
        case SampleType::U32: return DT_UINT32;
        case SampleType::I32: return DT_INT32;
        case SampleType::F32: return DT_FLOAT32;
        case SampleType::F64: return DT_FLOAT64;
    }
    return 0;
}

// A NIfTI-1 single-file header (348 bytes) and an empty extension flag.
// NIfTI is RAS: the grid's (LPS) x and y change sign. The sform carries the
// exact affine (as float, NIfTI-1's precision); the qform too when the axes
// are orthogonal (a quaternion cannot hold a shear).
std::vector<uint8_t> niftiHeader(const Layout& l, const std::string& path) {
    for (int a = 0; a < 3; ++a)
        if (l.dims[size_t(a)] > 32767)
            throw Error(path + ": " + std::to_string(l.dims[size_t(a)]) + " samples along an axis exceed NIfTI-1's 32767; write .nrrd or .mha instead");
    nifti_1_header h;
    std::memset(&h, 0, sizeof h);
    h.sizeof_hdr = 348;
    h.dim[0] = 3;
    for (int a = 0; a < 3; ++a) h.dim[a + 1] = short(l.dims[size_t(a)]);
    for (int a = 4; a < 8; ++a) h.dim[a] = 1;
    h.datatype = short(niftiDatatype(l.type));
    h.bitpix = short(8 * sampleBytes(l.type));
    if (l.colour) {
        if (l.type != SampleType::U8) throw Error(path + ": NIfTI holds RGB colours as 8-bit samples; this grid's are " + sampleTypeName(l.type));
        h.datatype = DT_RGB24;
        h.bitpix = 24;
    } else if (l.components == 3) {  // a vector per voxel: the 5th dimension, in planes
        h.dim[0] = 5;
        h.dim[5] = 3;
        h.intent_code = NIFTI_INTENT_VECTOR;
    }
    h.vox_offset = 352;
    h.scl_slope = l.rescaled ? float(l.slope) : 0.0f;
    h.scl_inter = l.rescaled ? float(l.intercept) : 0.0f;
    h.xyzt_units = l.space.empty() ? 0 : NIFTI_UNITS_MM;
    std::snprintf(h.descrip, sizeof h.descrip, "vdbdag decode");
    // A grid without a named space is taken as LPS too, as ITK does when it
    // writes NIfTI from its (LPS) physical space: read back, it is the same.
    const double flip[3] = {-1.0, -1.0, 1.0};
    nifti_dmat44 m;
    std::memset(&m, 0, sizeof m);
    for (int r = 0; r < 3; ++r) {
        for (int a = 0; a < 3; ++a) m.m[r][a] = flip[r] * l.axes[size_t(a)][size_t(r)];
        m.m[r][3] = flip[r] * l.origin[size_t(r)];
    }
    m.m[3][3] = 1;
    float* srow[3] = {h.srow_x, h.srow_y, h.srow_z};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) srow[r][c] = float(m.m[r][c]);
    h.sform_code = short(l.space.empty() ? NIFTI_XFORM_ALIGNED_ANAT : NIFTI_XFORM_SCANNER_ANAT);
    double length[3];
    for (int a = 0; a < 3; ++a) length[a] = std::sqrt(m.m[0][a] * m.m[0][a] + m.m[1][a] * m.m[1][a] + m.m[2][a] * m.m[2][a]);
    bool orthogonal = true;
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
            const double dot = m.m[0][a] * m.m[0][b] + m.m[1][a] * m.m[1][b] + m.m[2][a] * m.m[2][b];
            if (std::abs(dot) > 1e-6 * length[a] * length[b]) orthogonal = false;
        }
    double qb, qc, qd, qx, qy, qz, dx, dy, dz, qfac;
    nifti_dmat44_to_quatern(m, &qb, &qc, &qd, &qx, &qy, &qz, &dx, &dy, &dz, &qfac);
    h.pixdim[0] = float(qfac);
    h.pixdim[1] = float(length[0]);
    h.pixdim[2] = float(length[1]);
    h.pixdim[3] = float(length[2]);
    if (orthogonal) {
        h.qform_code = h.sform_code;
        h.quatern_b = float(qb);
        h.quatern_c = float(qc);
        h.quatern_d = float(qd);
        h.qoffset_x = float(qx);
        h.qoffset_y = float(qy);
        h.qoffset_z = float(qz);
    }
    std::memcpy(h.magic, "n+1", 4);
    std::vector<uint8_t> bytes(352, 0);
    std::memcpy(bytes.data(), &h, sizeof h);  // bytes 348..351: no extensions
    return bytes;
}

} // namespace

bool isDenseOutput(const std::string& path) { return outFormatOf(path).has_value(); }

DenseExportReport exportDense(const GridRecord& grid, const std::string& path, bool showProgress) {
    const std::optional<OutFormat> format = outFormatOf(path);
    if (!format) throw Error(path + ": not a dense scan file name (.nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz, .raw)");
    const Layout l = layoutOf(grid, path);
    DenseExportReport report;
    report.dims = l.dims;
    report.type = l.type;
    report.dataPath = path;
    const bool detached = *format == OutFormat::Nhdr || *format == OutFormat::Mhd;
    std::string dataName;
    if (detached) {
        dataName = std::filesystem::path(path).stem().string() + ".raw";
        report.dataPath = (std::filesystem::path(path).parent_path() / dataName).string();
    }
    auto samplesTo = [&](std::ostream& out, bool gzip) {
        SampleSink sink(out, gzip);
        if (*format == OutFormat::NiiGz) {
            const std::vector<uint8_t> header = niftiHeader(l, path);
            sink.write(header.data(), header.size());
        }
        // NIfTI vectors are planes (the 5th dimension); RGB24 and the
        // other formats interleave a voxel's components.
        const bool nifti = *format == OutFormat::Nii || *format == OutFormat::NiiGz;
        writeAllSamples(grid, l, sink, path, showProgress, nifti && !l.colour);
        sink.finish();
    };
    switch (*format) {
        case OutFormat::Raw: writeStreamAtomically(path, [&](std::ostream& out) { samplesTo(out, false); }); break;
        case OutFormat::Nrrd:
        case OutFormat::Mha:
            writeStreamAtomically(path, [&](std::ostream& out) {
                out << (*format == OutFormat::Nrrd ? nrrdHeader(l, "") : metaImageHeader(l, ""));
                samplesTo(out, false);
            });
            break;
        case OutFormat::Nii:
            writeStreamAtomically(path, [&](std::ostream& out) {
                const std::vector<uint8_t> header = niftiHeader(l, path);
                out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
                samplesTo(out, false);
            });
            break;
        case OutFormat::NiiGz: niftiHeader(l, path); writeStreamAtomically(path, [&](std::ostream& out) { samplesTo(out, true); }); break;
        case OutFormat::Nhdr:
        case OutFormat::Mhd: {
            // The samples first, then the header that names them; if the
            // header cannot be written, the samples go too.
            writeStreamAtomically(report.dataPath, [&](std::ostream& out) { samplesTo(out, false); });
            try {
                const std::string header = *format == OutFormat::Nhdr ? nrrdHeader(l, dataName) : metaImageHeader(l, dataName);
                writeFileAtomically(path, {reinterpret_cast<const uint8_t*>(header.data()), header.size()});
            } catch (...) {
                std::error_code ec;
                std::filesystem::remove(report.dataPath, ec);
                throw;
            }
            break;
        }
    }
    return report;
}

// ---- cube by cube -----------------------------------------------------------

namespace {

// The samples of a raw-encoded output, written by offset: the whole data
// region first set to the background sample (a sparse file of zeros when it
// is 0), then each cube's runs of decoded voxels, and each solid node's rows.
template <typename V, typename S>
class CubeWriter final : public DenseCubeSink {
public:
    CubeWriter(int fd, uint64_t dataOffset, const Layout& l, const GridRecord& header, const std::string& path)
        : fd_(fd), dataOffset_(dataOffset), l_(l), conv_{l_}, path_(path), mask_(header.valueType == ValueType::Mask) {
        V backgroundValue{};
        if (header.background.size() >= sizeof(V)) std::memcpy(&backgroundValue, header.background.data(), sizeof(V));
        background_ = conv_.nearest(backgroundValue);
        const uint64_t bytes = uint64_t(l.dims[0]) * uint64_t(l.dims[1]) * uint64_t(l.dims[2]) * sizeof(S);
        if (::ftruncate(fd_, off_t(dataOffset_ + bytes)) != 0) fail("cannot size the output");
        S zero{};
        if (std::memcmp(&zero, &background_, sizeof(S)) != 0) {
            std::vector<S> chunk(size_t(1) << 20, background_);
            for (uint64_t at = 0; at < bytes; at += chunk.size() * sizeof(S))
                writeAt(dataOffset_ + at, chunk.data(), size_t(std::min<uint64_t>(chunk.size() * sizeof(S), bytes - at)));
        }
    }

    void beginCube(int64_t x, int64_t y, int64_t z, unsigned log2) override {
        const int64_t c[3] = {x, y, z}, size = int64_t(1) << log2;
        for (int a = 0; a < 3; ++a) {  // the cube's samples inside the extent
            lo_[a] = std::clamp<int64_t>(c[a] - l_.lo[size_t(a)], 0, l_.dims[size_t(a)]);
            hi_[a] = std::clamp<int64_t>(c[a] - l_.lo[size_t(a)] + size, 0, l_.dims[size_t(a)]);
        }
        const size_t n = size_t(std::max<int64_t>(0, hi_[0] - lo_[0]) * std::max<int64_t>(0, hi_[1] - lo_[1]) * std::max<int64_t>(0, hi_[2] - lo_[2]));
        cube_.resize(n);
        set_.assign((n + 63) / 64, 0);
    }

    void brick(int64_t x, int64_t y, int64_t z, uint64_t mask, const uint8_t* values) override {
        unsigned k = 0;
        for (uint64_t m = mask; m; m &= m - 1, ++k) {
            const int bit = std::countr_zero(m);
            const int64_t sx = x + (bit & 3) - l_.lo[0], sy = y + ((bit >> 2) & 3) - l_.lo[1], sz = z + (bit >> 4) - l_.lo[2];
            if (sx < lo_[0] || sx >= hi_[0] || sy < lo_[1] || sy >= hi_[1] || sz < lo_[2] || sz >= hi_[2]) outside(sx, sy, sz);
            const size_t i = size_t(((sz - lo_[2]) * (hi_[1] - lo_[1]) + (sy - lo_[1])) * (hi_[0] - lo_[0]) + (sx - lo_[0]));
            cube_[i] = sample(values, k, sx, sy, sz);
            set_[i / 64] |= uint64_t(1) << (i % 64);
        }
    }

    void solid(int64_t x, int64_t y, int64_t z, unsigned log2, const uint8_t* value) override {
        const int64_t size = int64_t(1) << log2;
        int64_t a[3], b[3];
        const int64_t c[3] = {x, y, z};
        for (int k = 0; k < 3; ++k) {
            a[k] = c[k] - l_.lo[size_t(k)];
            b[k] = a[k] + size;
            if (a[k] < 0 || b[k] > l_.dims[size_t(k)]) outside(a[0], a[1], a[2]);
        }
        const S s = sample(value, 0, a[0], a[1], a[2]);
        const std::vector<S> row(size_t(size), s);
        for (int64_t zz = a[2]; zz < b[2]; ++zz)
            for (int64_t yy = a[1]; yy < b[1]; ++yy) writeAt(offsetOf(a[0], yy, zz), row.data(), size_t(size) * sizeof(S));
    }

    void endCube() override {
        const int64_t rx = hi_[0] - lo_[0], ry = hi_[1] - lo_[1];
        for (int64_t z = lo_[2]; z < hi_[2]; ++z)
            for (int64_t y = lo_[1]; y < hi_[1]; ++y) {
                const size_t row = size_t(((z - lo_[2]) * ry + (y - lo_[1])) * rx);
                for (int64_t x = 0; x < rx;) {  // runs of decoded voxels
                    auto isSet = [&](int64_t i) { return (set_[(row + size_t(i)) / 64] >> ((row + size_t(i)) % 64)) & 1u; };
                    if (!isSet(x)) { ++x; continue; }
                    int64_t end = x + 1;
                    while (end < rx && isSet(end)) ++end;
                    writeAt(offsetOf(lo_[0] + x, y, z), cube_.data() + row + size_t(x), size_t(end - x) * sizeof(S));
                    x = end;
                }
            }
    }

private:
    S sample(const uint8_t* values, unsigned k, int64_t x, int64_t y, int64_t z) const {
        V v;
        if (mask_) v = V(1);
        else std::memcpy(&v, values + size_t(k) * sizeof(V), sizeof(V));
        S out;
        if (!conv_.exact(v, out))
            throw Error(path_ + ": the sample at (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ") is not a " +
                        sampleTypeName(l_.type) + " sample" + (l_.rescaled ? " under the recorded rescale" : "") +
                        ": the grid was changed after import; write it as .vdb, or as a float scan");
        return out;
    }
    [[noreturn]] void outside(int64_t x, int64_t y, int64_t z) const {
        throw Error(path_ + ": a voxel at sample (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                    ") lies outside the recorded extent " + fmt::format("{}x{}x{}", l_.dims[0], l_.dims[1], l_.dims[2]));
    }
    uint64_t offsetOf(int64_t x, int64_t y, int64_t z) const {
        return dataOffset_ + ((uint64_t(z) * uint64_t(l_.dims[1]) + uint64_t(y)) * uint64_t(l_.dims[0]) + uint64_t(x)) * sizeof(S);
    }
    void writeAt(uint64_t offset, const void* data, size_t n) {
        const auto* p = static_cast<const uint8_t*>(data);
        for (size_t done = 0; done < n;) {
            const ssize_t w = ::pwrite(fd_, p + done, n - done, off_t(offset + done));
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) fail("cannot write");
            done += size_t(w);
        }
    }
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(path_ + ": " + what + " (" + std::strerror(errno) + ")");
    }

    int fd_;
    uint64_t dataOffset_;
    const Layout& l_;
    ToSample<V, S> conv_;
    std::string path_;
    bool mask_;
    S background_{};
    int64_t lo_[3]{0, 0, 0}, hi_[3]{0, 0, 0};
    std::vector<S> cube_;
    std::vector<uint64_t> set_;
};

template <typename V>
std::unique_ptr<DenseCubeSink> cubeWriterFor(int fd, uint64_t offset, const Layout& l, const GridRecord& h, const std::string& path) {
    switch (l.type) {
        case SampleType::U8: return std::make_unique<CubeWriter<V, uint8_t>>(fd, offset, l, h, path);
        case SampleType::I8: return std::make_unique<CubeWriter<V, int8_t>>(fd, offset, l, h, path);
        case SampleType::U16: return std::make_unique<CubeWriter<V, uint16_t>>(fd, offset, l, h, path);
        case SampleType::I16: return std::make_unique<CubeWriter<V, int16_t>>(fd, offset, l, h, path);
        case SampleType::U32: return std::make_unique<CubeWriter<V, uint32_t>>(fd, offset, l, h, path);
        case SampleType::I32: return std::make_unique<CubeWriter<V, int32_t>>(fd, offset, l, h, path);
        case SampleType::F32: return std::make_unique<CubeWriter<V, float>>(fd, offset, l, h, path);
        case SampleType::F64: return std::make_unique<CubeWriter<V, double>>(fd, offset, l, h, path);
    }
    throw Error(path + ": unsupported sample type");
}

bool hasSourceDims(const GridRecord& header) {
    const openvdb::GridBase::Ptr g = detail::readDescriptor(header.vdbDescriptor, "grid '" + header.name + "'");
    return bool(g->getMetadata<openvdb::Vec3IMetadata>("source_dims"));
}

} // namespace

bool exportsByCubes(const GridRecord& header, const std::string& path) {
    const std::optional<OutFormat> format = outFormatOf(path);
    if (!format || *format == OutFormat::NiiGz) return false;  // a gzip stream is written in order
    switch (header.valueType) {
        case ValueType::Int32:
        case ValueType::Int64:
        case ValueType::Float:
        case ValueType::Double:
        case ValueType::Mask: break;
        default: return false;
    }
    return hasSourceDims(header);  // the extent, without walking the voxels
}

DenseExportReport exportDenseByCubes(const GridRecord& header, const std::string& path, const std::function<void(DenseCubeSink&)>& produce) {
    if (!exportsByCubes(header, path)) throw Error("internal error: " + path + " cannot be written cube by cube");
    const OutFormat format = *outFormatOf(path);
    const Layout l = layoutOf(header, path);
    DenseExportReport report;
    report.dims = l.dims;
    report.type = l.type;
    report.dataPath = path;
    const bool detached = format == OutFormat::Nhdr || format == OutFormat::Mhd;
    std::string dataName;
    if (detached) {
        dataName = std::filesystem::path(path).stem().string() + ".raw";
        report.dataPath = (std::filesystem::path(path).parent_path() / dataName).string();
    }
    std::vector<uint8_t> head;  // what precedes the samples in the data file
    if (format == OutFormat::Nrrd || format == OutFormat::Mha) {
        const std::string h = format == OutFormat::Nrrd ? nrrdHeader(l, "") : metaImageHeader(l, "");
        head.assign(h.begin(), h.end());
    } else if (format == OutFormat::Nii) {
        head = niftiHeader(l, path);
    }
    writeViaTemporary(report.dataPath, [&](const std::string& tmp) {
        const int fd = ::open(tmp.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) throw Error(path + ": cannot create " + tmp + " (" + std::strerror(errno) + ")");
        try {
            for (size_t done = 0; done < head.size();) {
                const ssize_t w = ::pwrite(fd, head.data() + done, head.size() - done, off_t(done));
                if (w < 0 && errno == EINTR) continue;
                if (w <= 0) throw Error(path + ": cannot write (" + std::strerror(errno) + ")");
                done += size_t(w);
            }
            std::unique_ptr<DenseCubeSink> sink;
            switch (header.valueType) {
                case ValueType::Int32: sink = cubeWriterFor<int32_t>(fd, head.size(), l, header, path); break;
                case ValueType::Int64: sink = cubeWriterFor<int64_t>(fd, head.size(), l, header, path); break;
                case ValueType::Float: sink = cubeWriterFor<float>(fd, head.size(), l, header, path); break;
                case ValueType::Double: sink = cubeWriterFor<double>(fd, head.size(), l, header, path); break;
                default: sink = cubeWriterFor<uint8_t>(fd, head.size(), l, header, path); break;  // mask: 0 / 1
            }
            produce(*sink);
        } catch (...) {
            ::close(fd);
            throw;
        }
        if (::close(fd) != 0) throw Error(path + ": cannot write (" + std::strerror(errno) + ")");
    });
    if (detached) {
        try {
            const std::string h = format == OutFormat::Nhdr ? nrrdHeader(l, dataName) : metaImageHeader(l, dataName);
            writeFileAtomically(path, {reinterpret_cast<const uint8_t*>(h.data()), h.size()});
        } catch (...) {
            std::error_code ec;
            std::filesystem::remove(report.dataPath, ec);
            throw;
        }
    }
    return report;
}

} // namespace vdbdag::bridge
