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
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/ScanHeaderWriters.h"

namespace vdbdag::bridge {
namespace {

using detail::OutFormat;
using detail::outFormatOf;
using detail::ScanLayout;
using Layout = ScanLayout;
using detail::layoutOf;

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

} // namespace

bool isDenseOutput(const std::string& path) { return outFormatOf(path).has_value(); }

namespace {

// One scan file from `grids`: one grid, or the volumes of a 4-D series in
// order (NIfTI, NRRD), each volume's samples after the one before.
DenseExportReport exportGrids(const std::vector<const GridRecord*>& grids, const std::string& path, const DenseExportOptions& options) {
    const std::optional<OutFormat> format = outFormatOf(path);
    if (!format) throw Error(path + ": not a dense scan file name (.nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz, .raw)");
    const bool showProgress = options.showProgress;
    DenseExportReport report;
    Layout l = layoutOf(*grids.front(), path, *format, options, report.notes);
    std::vector<Layout> layouts{l};
    for (size_t t = 1; t < grids.size(); ++t) {
        std::vector<std::string> ignored;  // the first volume's notes speak for all
        layouts.push_back(layoutOf(*grids[t], path, *format, options, ignored));
        const Layout& o = layouts.back();
        if (o.dims != l.dims || o.type != l.type || o.axes != l.axes || o.origin != l.origin || o.components != l.components)
            throw Error(path + ": grid '" + grids[t]->name + "' differs from '" + grids.front()->name +
                        "' in extent, sample type or transform, so they cannot be one 4-D file; pick one with --grid NAME");
    }
    l.volumes = int64_t(grids.size());
    report.dims = l.dims;
    report.type = l.type;
    report.dataPath = path;
    const bool detached = *format == OutFormat::Nhdr || *format == OutFormat::Mhd;
    std::string dataName;
    if (detached) {
        dataName = std::filesystem::path(path).stem().string() + ".raw";
        report.dataPath = (std::filesystem::path(path).parent_path() / dataName).string();
    }
    std::vector<uint8_t> niftiBytes;  // checked before any file is created
    if (*format == OutFormat::Nii || *format == OutFormat::NiiGz) niftiBytes = niftiHeader(l, path, &report.notes);
    auto samplesTo = [&](std::ostream& out, bool gzip) {
        SampleSink sink(out, gzip);
        if (*format == OutFormat::NiiGz) sink.write(niftiBytes.data(), niftiBytes.size());
        // NIfTI vectors are planes (the 5th dimension); RGB24 and the
        // other formats interleave a voxel's components.
        const bool nifti = *format == OutFormat::Nii || *format == OutFormat::NiiGz;
        for (size_t t = 0; t < grids.size(); ++t) writeAllSamples(*grids[t], layouts[t], sink, path, showProgress, nifti && !l.colour);
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
                out.write(reinterpret_cast<const char*>(niftiBytes.data()), std::streamsize(niftiBytes.size()));
                samplesTo(out, false);
            });
            break;
        case OutFormat::NiiGz: writeStreamAtomically(path, [&](std::ostream& out) { samplesTo(out, true); }); break;
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

} // namespace

DenseExportReport exportDense(const GridRecord& grid, const std::string& path, const DenseExportOptions& options) {
    return exportGrids({&grid}, path, options);
}

std::optional<std::vector<size_t>> volumeSeriesOf(const std::vector<GridRecord>& grids) {
    if (grids.size() < 2) return std::nullopt;
    std::vector<size_t> order(grids.size(), grids.size());
    for (size_t i = 0; i < grids.size(); ++i) {
        const openvdb::GridBase::Ptr g = detail::readDescriptor(grids[i].vdbDescriptor, "grid '" + grids[i].name + "'");
        const auto index = g->getMetadata<openvdb::Int64Metadata>("source_volume");
        const auto count = g->getMetadata<openvdb::Int64Metadata>("source_volumes");
        if (!index || !count || count->value() != int64_t(grids.size()) || index->value() < 0 || index->value() >= count->value()) return std::nullopt;
        if (order[size_t(index->value())] != grids.size()) return std::nullopt;  // an index twice
        order[size_t(index->value())] = i;
    }
    return order;
}

DenseExportReport exportDenseVolumes(const std::vector<const GridRecord*>& volumes, const std::string& path, const DenseExportOptions& options) {
    const std::optional<OutFormat> format = outFormatOf(path);
    if (volumes.empty()) throw Error(path + ": no grid to write");
    const bool holdsSeries = format == OutFormat::Nii || format == OutFormat::NiiGz || format == OutFormat::Nrrd || format == OutFormat::Nhdr;
    if (volumes.size() > 1 && !holdsSeries)
        throw Error(path + ": " + std::to_string(volumes.size()) +
                    " volumes of a 4-D scan go to one .nii, .nii.gz, .nrrd or .nhdr file; this format holds one volume: pick it with --grid NAME");
    return exportGrids(volumes, path, options);
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

DenseExportReport exportDenseByCubes(const GridRecord& header, const std::string& path, const std::function<void(DenseCubeSink&)>& produce,
                                     const DenseExportOptions& options) {
    if (!exportsByCubes(header, path)) throw Error("internal error: " + path + " cannot be written cube by cube");
    const OutFormat format = *outFormatOf(path);
    DenseExportReport report;
    const Layout l = layoutOf(header, path, format, options, report.notes);
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
        head = niftiHeader(l, path, &report.notes);
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
