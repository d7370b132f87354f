// Peer measurements for `vdbdag bench`; see PeerCodecs.h.
#include "vdb_bridge/PeerCodecs.h"

#include <bit>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <functional>
#include <unordered_map>

#include <fmt/core.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <fpzip.h>
#include <openvdb/openvdb.h>
#include <zfp.h>

#include "src/util/Error.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

// Largest absolute difference over the components (NaN where either is NaN).
template <typename T>
double absDiff(const T& a, const T& b) {
    if constexpr (openvdb::VecTraits<T>::IsVec) {
        double m = 0;
        for (int i = 0; i < openvdb::VecTraits<T>::Size; ++i) m = std::max(m, std::fabs(double(a[i]) - double(b[i])));
        return m;
    } else if constexpr (std::is_same_v<T, bool>) {
        return a == b ? 0.0 : 1.0;
    } else {
        return std::fabs(double(a) - double(b));
    }
}

// Max and RMS error of `read(coord)` against the grid's active values
// (tiles weighted by their voxels); exact = every value bit-identical.
template <typename GridT, typename Read>
void valueErrors(const GridT& grid, Read&& read, bench::BenchPoint& point) {
    using ValueT = typename GridT::ValueType;
    double maxError = 0, sum = 0;
    uint64_t count = 0;
    bool exact = true;
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        const ValueT original = *it;
        const ValueT decoded = ValueT(read(it.getCoord()));
        if (std::memcmp(&original, &decoded, sizeof(ValueT)) != 0) exact = false;
        const double error = absDiff(original, decoded);
        const uint64_t voxels = it.isVoxelValue() ? 1 : it.getVoxelCount();
        if (std::isfinite(error)) {
            maxError = std::max(maxError, error);
            sum += error * error * double(voxels);
        }
        count += voxels;
    }
    point.maxError = maxError;
    point.rmsError = count ? std::sqrt(sum / double(count)) : 0;
    point.exact = exact;
}

template <typename GridT>
bench::BenchPoint basePoint(const GridT& grid, const std::string& tool, const std::string& setting, const std::string& family) {
    bench::BenchPoint p;
    p.grid = grid.getName();
    p.tool = tool;
    p.setting = setting;
    p.family = family;
    p.activeVoxels = grid.activeVoxelCount();
    p.rawBytes = p.activeVoxels * sizeof(typename GridT::ValueType);
    return p;
}

template <typename GridT>
void measureOpenVdb(const GridT& grid, const PeerOptions& options, std::vector<bench::BenchPoint>& out) {
    struct Mode { const char* name; uint32_t compression; bool half; };
    std::vector<Mode> modes{{"none", openvdb::io::COMPRESS_NONE, false},
                            {"zip", openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK, false},
                            {"blosc", openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK, false}};
    if constexpr (std::is_floating_point_v<typename GridT::ValueType>)
        modes.push_back({"blosc+half", openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK, true});
    const std::filesystem::path path = std::filesystem::path(options.scratchDirectory) / "peer.vdb";
    for (const Mode& mode : modes) {
        bench::BenchPoint p = basePoint(grid, "OpenVDB", mode.name, "OpenVDB");
        typename GridT::Ptr copy = grid.deepCopy();
        copy->setSaveFloatAsHalf(mode.half);
        std::vector<double> encode, decode;
        typename GridT::Ptr readBack;
        for (int r = 0; bench::repeatAgain(r, options.repeats, bench::totalMs(encode) + bench::totalMs(decode), options.budgetMs); ++r) {
            auto start = Clock::now();
            {
                openvdb::io::File file(path.string());
                file.setCompression(mode.compression);
                file.write({copy});
                file.close();
            }
            encode.push_back(msSince(start));
            start = Clock::now();
            openvdb::io::File file(path.string());
            file.open();
            readBack = openvdb::gridPtrCast<GridT>(file.readGrid(file.beginName().gridName()));
            file.close();
            decode.push_back(msSince(start));
        }
        p.bytes = std::filesystem::file_size(path);
        p.encode = bench::summarise(encode);
        p.decode = bench::summarise(decode);
        auto acc = readBack->getConstAccessor();
        valueErrors(grid, [&](const openvdb::Coord& c) { return acc.getValue(c); }, p);
        out.push_back(p);
    }
    std::error_code ec;
    std::filesystem::remove(path, ec);
}

template <typename NanoBuildT>
void measureNano(const openvdb::FloatGrid& grid, const std::string& setting, const std::string& family, double tolerance, const PeerOptions& options,
                 std::vector<bench::BenchPoint>& out) {
    bench::BenchPoint p = basePoint(grid, "NanoVDB", setting, family);
    std::vector<double> encode, decode;
    nanovdb::GridHandle<nanovdb::HostBuffer> handle;
    for (int r = 0; bench::repeatAgain(r, options.repeats, bench::totalMs(encode) + bench::totalMs(decode), options.budgetMs); ++r) {
        auto start = Clock::now();
        nanovdb::OpenToNanoVDB<float, NanoBuildT, nanovdb::AbsDiff> convert;
        if (tolerance > 0) convert.oracle() = nanovdb::AbsDiff(float(tolerance));
        handle = convert(grid);
        encode.push_back(msSince(start));
        // Decoding a NanoVDB grid is reading it: every active value through its accessor.
        start = Clock::now();
        const auto* nano = handle.template grid<NanoBuildT>();
        auto acc = nano->getAccessor();
        double sink = 0;
        for (auto it = grid.cbeginValueOn(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            sink += acc.getValue(nanovdb::Coord(c.x(), c.y(), c.z()));
        }
        decode.push_back(msSince(start));
        if (sink == 1234.5678) p.note = "";  // keep the reads
    }
    const auto* nano = handle.template grid<NanoBuildT>();
    if (!nano) throw Error("NanoVDB conversion of '" + grid.getName() + "' failed");
    auto acc = nano->getAccessor();
    p.bytes = handle.size();
    p.traceableBytes = handle.size();
    p.encode = bench::summarise(encode);
    p.decode = bench::summarise(decode);
    valueErrors(grid, [&](const openvdb::Coord& c) { return acc.getValue(nanovdb::Coord(c.x(), c.y(), c.z())); }, p);
    if (tolerance > 0) p.note = fmt::format("FpN oracle AbsDiff({:g})", tolerance);
    out.push_back(p);
}

// fpzip (lossless) of the grid's leaves, in the better of two arrangements
// for it: the leaves' 8^3 buffers stacked into one 8 x 8 x 8N array, or the
// active values alone in leaf order as one line (what issue 40 compares the
// float values at rest with). Told the values' precision: 32 (64) bits less
// the low bits that are zero in every value (19 for a file stored as half
// floats), which it keeps exactly. Leaves and tiles cost their origin and
// mask, and tiles their value, as for ZFP below.
template <typename GridT>
void measureFpzip(const GridT& grid, const PeerOptions& options, std::vector<bench::BenchPoint>& out) {
    using ValueT = typename GridT::ValueType;
    using Bits = std::conditional_t<std::is_same_v<ValueT, float>, uint32_t, uint64_t>;
    constexpr int kBits = 8 * sizeof(ValueT), kMantissa = std::is_same_v<ValueT, float> ? 23 : 52;
    std::vector<ValueT> stacked, active;
    size_t leaves = 0;
    for (auto it = grid.tree().cbeginLeaf(); it; ++it, ++leaves) {
        stacked.insert(stacked.end(), it->buffer().data(), it->buffer().data() + 512);
        for (auto v = it->cbeginValueOn(); v; ++v) active.push_back(*v);
    }
    uint64_t tiles = 0;
    for (auto it = grid.cbeginValueOn(); it; ++it) tiles += it.isTileValue();
    if (stacked.empty()) return;
    int zeros = kMantissa;
    for (const auto* values : {&stacked, &active})
        for (const ValueT v : *values) {
            Bits b;
            std::memcpy(&b, &v, sizeof b);
            if (const Bits m = b & (~Bits(0) >> 1)) zeros = std::min(zeros, std::countr_zero(m));
        }
    const int precision = kBits - zeros;
    bench::BenchPoint p = basePoint(grid, "fpzip", fmt::format("lossless, {} bits", precision), "fpzip");
    std::vector<char> buffer(stacked.size() * sizeof(ValueT) + 65536);
    const auto code = [&](const std::vector<ValueT>& values, int nx, int ny, int nz) {
        FPZ* f = fpzip_write_to_buffer(buffer.data(), buffer.size());
        f->type = std::is_same_v<ValueT, float> ? FPZIP_TYPE_FLOAT : FPZIP_TYPE_DOUBLE;
        f->prec = precision, f->nx = nx, f->ny = ny, f->nz = nz, f->nf = 1;
        const size_t bytes = fpzip_write_header(f) ? fpzip_write(f, values.data()) : 0;
        fpzip_write_close(f);
        if (!bytes) throw Error("fpzip could not code the leaves");
        return bytes;
    };
    const bool line = code(active, int(active.size()), 1, 1) < code(stacked, 8, 8, int(8 * leaves));
    const std::vector<ValueT>& values = line ? active : stacked;
    std::vector<ValueT> back(values.size());
    std::vector<double> encode, decode;
    size_t bytes = 0;
    for (int r = 0; bench::repeatAgain(r, options.repeats, bench::totalMs(encode) + bench::totalMs(decode), options.budgetMs); ++r) {
        auto start = Clock::now();
        bytes = line ? code(active, int(active.size()), 1, 1) : code(stacked, 8, 8, int(8 * leaves));
        encode.push_back(msSince(start));
        start = Clock::now();
        FPZ* f = fpzip_read_from_buffer(buffer.data());
        const bool read = fpzip_read_header(f) && fpzip_read(f, back.data());
        fpzip_read_close(f);
        if (!read) throw Error("fpzip could not read the leaves it wrote");
        decode.push_back(msSince(start));
    }
    if (std::memcmp(back.data(), values.data(), values.size() * sizeof(ValueT)) != 0) throw Error("fpzip did not give the leaves back");
    p.bytes = bytes + tiles * (12 + sizeof(ValueT));
    p.encode = bench::summarise(encode);
    p.decode = bench::summarise(decode);
    p.maxError = p.rmsError = 0;  // checked bit for bit above; tiles stored as they are
    p.exact = true;
    p.bytes += leaves * (8 + 64);  // where each leaf is and which of its voxels are active, as for ZFP
    p.note = std::string(line ? "active values in leaf order" : "leaves stacked as 8 x 8 x 8N") + " + 72 B of origin and mask per leaf";
    out.push_back(p);
}

// ZFP over every leaf's dense 8^3 block (the leaf's origin and active mask
// stored beside it: 8 + 64 bytes), tiles as values: fixed accuracy
// `tolerance`, or with tolerance 0 its reversible (lossless) mode.
template <typename GridT>
void measureZfp(const GridT& grid, double tolerance, const PeerOptions& options, std::vector<bench::BenchPoint>& out) {
    using ValueT = typename GridT::ValueType;
    const zfp_type type = std::is_same_v<ValueT, float> ? zfp_type_float : zfp_type_double;
    const bool reversible = tolerance == 0;
    bench::BenchPoint p = basePoint(grid, "ZFP", reversible ? std::string("reversible") : fmt::format("accuracy {:g}", tolerance),
                                    reversible ? "ZFP reversible" : "ZFP");
    std::vector<const typename GridT::TreeType::LeafNodeType*> leaves;
    for (auto it = grid.tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
    uint64_t tiles = 0;
    for (auto it = grid.cbeginValueOn(); it; ++it) tiles += it.isTileValue();
    std::vector<std::vector<uint8_t>> streams(leaves.size());
    std::vector<std::array<ValueT, 512>> decoded(leaves.size());
    std::vector<double> encode, decode;
    uint64_t bytes = 0;
    for (int r = 0; bench::repeatAgain(r, options.repeats, bench::totalMs(encode) + bench::totalMs(decode), options.budgetMs); ++r) {
        auto start = Clock::now();
        bytes = tiles * (12 + sizeof(ValueT) + 1);
        for (size_t i = 0; i < leaves.size(); ++i) {
            ValueT block[512];
            for (int k = 0; k < 512; ++k) {  // OpenVDB leaf order is x-major: offset = 64x + 8y + z; ZFP wants x fastest
                const int x = k >> 6, y = (k >> 3) & 7, z = k & 7;
                block[x + 8 * y + 64 * z] = leaves[i]->getValue(k);
            }
            zfp_field* field = zfp_field_3d(block, type, 8, 8, 8);
            zfp_stream* zfp = zfp_stream_open(nullptr);
            if (reversible) zfp_stream_set_reversible(zfp);
            else zfp_stream_set_accuracy(zfp, tolerance);
            std::vector<uint8_t>& buffer = streams[i];
            buffer.resize(zfp_stream_maximum_size(zfp, field));
            bitstream* bits = stream_open(buffer.data(), buffer.size());
            zfp_stream_set_bit_stream(zfp, bits);
            zfp_stream_rewind(zfp);
            const size_t size = zfp_compress(zfp, field);
            buffer.resize(size);
            bytes += size + 8 + 64;
            zfp_field_free(field);
            zfp_stream_close(zfp);
            stream_close(bits);
        }
        encode.push_back(msSince(start));
        start = Clock::now();
        for (size_t i = 0; i < leaves.size(); ++i) {
            ValueT block[512];
            zfp_field* field = zfp_field_3d(block, type, 8, 8, 8);
            zfp_stream* zfp = zfp_stream_open(nullptr);
            if (reversible) zfp_stream_set_reversible(zfp);
            else zfp_stream_set_accuracy(zfp, tolerance);
            bitstream* bits = stream_open(streams[i].data(), streams[i].size());
            zfp_stream_set_bit_stream(zfp, bits);
            zfp_stream_rewind(zfp);
            if (!zfp_decompress(zfp, field)) throw Error("ZFP could not decompress a block it wrote");
            for (int k = 0; k < 512; ++k) decoded[i][k] = block[(k >> 6) + 8 * ((k >> 3) & 7) + 64 * (k & 7)];
            zfp_field_free(field);
            zfp_stream_close(zfp);
            stream_close(bits);
        }
        decode.push_back(msSince(start));
    }
    p.bytes = bytes;
    p.encode = bench::summarise(encode);
    p.decode = bench::summarise(decode);
    std::unordered_map<openvdb::Coord, size_t> leafIndex;
    for (size_t i = 0; i < leaves.size(); ++i) leafIndex[leaves[i]->origin()] = i;
    valueErrors(grid, [&](const openvdb::Coord& c) -> ValueT {
        const auto it = leafIndex.find(c & ~7);
        if (it == leafIndex.end()) return grid.tree().getValue(c);  // a tile: stored exactly
        return decoded[it->second][GridT::TreeType::LeafNodeType::coordToOffset(c)];
    }, p);
    p.note = "per-leaf 8^3 blocks + 72 B of origin and mask per leaf";
    out.push_back(p);
}

} // namespace

std::vector<bench::BenchPoint> measurePeers(const std::string& path, size_t gridIndex, const PeerOptions& options) {
    detail::initializeOpenVdb();
    openvdb::GridPtrVecPtr grids;
    try {
        openvdb::io::File file(path);
        file.open();
        grids = file.getGrids();
        file.close();
    } catch (const std::exception& e) {
        throw Error(path + ": " + detail::oneLine(e.what()));
    }
    if (gridIndex >= grids->size()) throw Error(path + ": no grid " + std::to_string(gridIndex));
    std::vector<bench::BenchPoint> out;
    const openvdb::GridBase::Ptr base = grids->at(gridIndex);
    detail::dispatchGridType(*base, [&](const auto& grid, ValueType type) {
        using GridT = std::decay_t<decltype(grid)>;
        if (type == ValueType::Mask) return;  // no values to compare
        measureOpenVdb(grid, options, out);
        if constexpr (std::is_same_v<GridT, openvdb::FloatGrid>) {
            measureNano<float>(grid, "float", "NanoVDB", 0, options, out);
            measureNano<nanovdb::Fp16>(grid, "Fp16", "NanoVDB Fp", 0, options, out);
            measureNano<nanovdb::Fp8>(grid, "Fp8", "NanoVDB Fp", 0, options, out);
            measureNano<nanovdb::Fp4>(grid, "Fp4", "NanoVDB Fp", 0, options, out);
            for (double tolerance : options.absTolerances)
                measureNano<nanovdb::FpN>(grid, fmt::format("FpN abs {:g}", tolerance), "NanoVDB FpN", tolerance, options, out);
        }
        if constexpr (std::is_same_v<GridT, openvdb::FloatGrid> || std::is_same_v<GridT, openvdb::DoubleGrid>) {
            measureFpzip(grid, options, out);
            measureZfp(grid, 0.0, options, out);  // reversible
            for (double tolerance : options.absTolerances) measureZfp(grid, tolerance, options, out);
        }
    });
    return out;
}

} // namespace vdbdag::bridge
