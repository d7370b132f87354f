// See DenseImport.h. Each slab of 4 slices is cut into 4^3 bricks (bit
// x + 4y + 16z, GridTopology.h), rows of bricks in parallel with per-row
// buffers appended in order, so the result does not depend on the thread
// count. Bricks at the volume's far faces are partial (their mask says so).
#include "vdb_bridge/DenseImport.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <fmt/core.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include "src/util/Error.h"
#include "src/util/Progress.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/DicomTags.h"
#include "vdb_bridge/MetaImageHeader.h"
#include "vdb_bridge/NiftiHeader.h"
#include "vdb_bridge/NrrdHeader.h"
#include "vdb_bridge/detail/DenseBricks.h"
#include "vdb_bridge/detail/HeaderFieldMeta.h"
#include "vdb_bridge/detail/InflateCheckpoints.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/SolidBlocks.h"

namespace vdbdag::bridge {
namespace {

constexpr int64_t kSlab = 4;

using detail::PassStats;
using detail::Thresholds;

template <typename S>
void forEachSlab(const DenseVolume& v, Progress* progress, const std::function<void(int64_t z0, int64_t nz, const S* samples)>& fn) {
    const std::unique_ptr<SliceReader> stream = openSliceReader(v);
    std::vector<uint8_t> slab;
    for (int64_t z0 = 0; z0 < v.dims[2]; z0 += kSlab) {
        const int64_t nz = std::min(kSlab, v.dims[2] - z0);
        stream->readSlices(nz, slab);
        fn(z0, nz, reinterpret_cast<const S*>(slab.data()));
        if (progress) progress->advance();
    }
}

// The grid header (OpenVDB's own serialisation of an empty grid, with the
// scan's transform and the metadata a decode back to the scan needs).
template <typename V>
void describeGrid(const DenseVolume& v, const V& background, const Thresholds* th, const ThresholdReport* report, GridRecord& record) {
    detail::initializeOpenVdb();
    using GridT = openvdb::Grid<typename openvdb::tree::Tree4<V, 5, 4, 3>::Type>;
    typename GridT::Ptr grid = GridT::create(background);
    grid->setName(v.colour ? "Cd" : !v.gridName.empty() ? v.gridName : scanNameOf(v.headerPath));
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) m(a, c) = v.axes[size_t(a)][size_t(c)];
    for (int c = 0; c < 3; ++c) m(3, c) = v.origin[size_t(c)];
    grid->setTransform(openvdb::math::Transform::Ptr(new openvdb::math::Transform(openvdb::math::MapBase::Ptr(new openvdb::math::AffineMap(m)))));
    grid->insertMeta("source_file", openvdb::StringMetadata(std::filesystem::path(v.headerPath).filename().string()));
    grid->insertMeta("source_sample_type", openvdb::StringMetadata(sampleTypeName(v.type)));
    // What `decode -o SCAN.nrrd|.nii.gz|...` needs to give the scan back as
    // it came: its full extent (thresholds may leave the borders inactive),
    // its stored samples (before any rescale) and its patient space.
    grid->insertMeta("source_dims", openvdb::Vec3IMetadata(openvdb::Vec3i(int(v.dims[0]), int(v.dims[1]), int(v.dims[2]))));
    if (v.rescaleSlope != 1 || v.rescaleIntercept != 0) {
        grid->insertMeta("source_rescale_slope", openvdb::DoubleMetadata(v.rescaleSlope));
        grid->insertMeta("source_rescale_intercept", openvdb::DoubleMetadata(v.rescaleIntercept));
    }
    grid->insertMeta("source_format", openvdb::StringMetadata(denseFormatName(v.format)));
    if (v.colour) grid->insertMeta("source_colour", openvdb::StringMetadata(v.storedComponents == 4 ? "rgba" : "rgb"));
    else if (v.storedComponents == 4) grid->insertMeta("source_colour", openvdb::StringMetadata("alpha"));  // the A of RGBA
    if (!v.space.empty()) grid->insertMeta("space", openvdb::StringMetadata(v.space));  // of the grid's world coordinates
    if (v.bitsStored) grid->insertMeta("source_bits_stored", openvdb::Int64Metadata(int64_t(v.bitsStored)));
    if (v.volumeCount > 1) {  // one volume of a 4-D file
        grid->insertMeta("source_volume", openvdb::Int64Metadata(v.volumeIndex));
        grid->insertMeta("source_volumes", openvdb::Int64Metadata(v.volumeCount));
    }
    detail::insertHeaderFields(*grid, v.headerFields);
    if (th && th->below) grid->insertMeta("background_below", openvdb::DoubleMetadata(th->belowValue));
    if (th && th->above) grid->insertMeta("background_above", openvdb::DoubleMetadata(th->aboveValue));
    if (report && report->applied) {  // what the thresholds cost, for `info` (scanProvenanceOf)
        grid->insertMeta("threshold_inactive_samples", openvdb::Int64Metadata(int64_t(report->inactive)));
        grid->insertMeta("threshold_changed_samples", openvdb::Int64Metadata(int64_t(report->changed)));
        grid->insertMeta("threshold_max_abs_change", openvdb::DoubleMetadata(report->maxAbsChange));
        grid->insertMeta("threshold_rms_change", openvdb::DoubleMetadata(report->rmsChange));
        grid->insertMeta("threshold_psnr_db", openvdb::DoubleMetadata(report->psnr));
    }
    record.name = grid->getName();
    record.gridClass = openvdb::GridBase::gridClassToString(grid->getGridClass());
    record.indexToWorld = detail::indexToWorldOf(*grid);
    record.vdbDescriptor = detail::descriptorOf(*grid);
    record.rescale = detail::rescaleOf(*grid);
    const auto* bg = reinterpret_cast<const uint8_t*>(&background);
    record.background.assign(bg, bg + sizeof(V));
}

// Vector and colour scans: every sample an active voxel whose value is its
// 3 components (C: int32 for integer samples, float, double), no thresholds.
template <typename S, typename C>
DenseImportResult importVector(const DenseVolume& v, ValueType valueType, bool showProgress) {
    using V = openvdb::math::Vec3<C>;
    openSliceReader(v);  // sizes checked before anything is reserved
    const int64_t nx = v.dims[0], ny = v.dims[1];
    const int64_t rows = (ny + 3) / 4, cols = (nx + 3) / 4;
    std::unique_ptr<Progress> progress;
    if (showProgress) progress = std::make_unique<Progress>("import " + std::filesystem::path(v.headerPath).filename().string(), uint64_t((v.dims[2] + kSlab - 1) / kSlab));
    GridRecord record;
    record.valueType = valueType;
    record.values.bricks.reserve(size_t(v.sampleCount() * sizeof(V)));
    forEachSlab<S>(v, progress.get(), [&](int64_t z0, int64_t nz, const S* s) {
        for (int64_t by = 0; by < rows; ++by)
            for (int64_t bx = 0; bx < cols; ++bx) {
                uint64_t mask = 0;
                for (int bit = 0; bit < 64; ++bit) {
                    const int64_t x = bx * 4 + (bit & 3), y = by * 4 + ((bit >> 2) & 3), z = bit >> 4;
                    if (x >= nx || y >= ny || z >= nz) continue;
                    const S* sample = s + size_t(((z * ny + y) * nx + x) * 3);
                    const V value{C(sample[0]), C(sample[1]), C(sample[2])};
                    const auto* p = reinterpret_cast<const uint8_t*>(&value);
                    record.values.bricks.insert(record.values.bricks.end(), p, p + sizeof(V));
                    mask |= uint64_t(1) << bit;
                }
                if (mask) record.topology.bricks.push_back({int32_t(bx * 4), int32_t(by * 4), int32_t(z0), mask});
            }
    });
    if (progress) progress->finish();
    DenseImportResult result;
    result.source = v;
    result.threshold.samples = v.sampleCount();
    describeGrid<V>(v, V(C(0)), nullptr, nullptr, record);
    result.volume.grids.push_back(std::move(record));
    return result;
}

// The bricks of `record` inside solid blocks leave (with their values, in
// place), and each block becomes a tile, in block order.
void replaceSolidBlocks(const detail::SolidBlocks& blocks, GridRecord& record) {
    std::vector<Brick>& bricks = record.topology.bricks;
    std::vector<uint8_t>& values = record.values.bricks;
    const size_t vs = blocks.valueSize;
    size_t keptBricks = 0, read = 0, written = 0;
    for (const Brick& b : bricks) {
        const size_t n = size_t(std::popcount(b.mask)) * vs;
        if (!blocks.covers(b.x, b.y, b.z)) {
            if (written != read) std::memmove(values.data() + written, values.data() + read, n);
            written += n;
            bricks[keptBricks++] = b;
        }
        read += n;
    }
    bricks.resize(keptBricks);
    values.resize(written);
    for (int64_t z = 0; z < blocks.slabs; ++z)
        for (int64_t y = 0; y < blocks.rows; ++y)
            for (int64_t x = 0; x < blocks.cols; ++x)
                if (blocks.covers(x << detail::kSolidBlockLog2, y << detail::kSolidBlockLog2, z << detail::kSolidBlockLog2)) {
                    record.topology.tiles.push_back(detail::solidBlockTile(x, y, z));
                    const uint8_t* p = blocks.valueOf(x, y, z);
                    record.values.tiles.insert(record.values.tiles.end(), p, p + vs);
                }
}

// `cubesNear` (a scalar scan read cube by cube, DenseImportOptions): the
// samples go to a scratch file there and the result's grid is a CubeSource.
template <typename S, typename V>
DenseImportResult importTyped(const DenseVolume& v, const Thresholds& th, ValueType valueType, bool showProgress, const std::string& cubesNear = "") {
    { openSliceReader(v); }  // the data file's size against the header, before anything is reserved
    // Stored sample -> grid value: the header's rescale (DICOM Rescale
    // Slope/Intercept, NIfTI scl_slope/scl_inter), exact in integers when
    // both are integral (importDense chose V so that the range fits).
    const detail::SampleRule<S, V> unthresholded(v, th, V(0));
    const auto missing = [&](int64_t z) { return unthresholded.missing(z); };
    const uint64_t missingSamples = uint64_t(v.missingSlices.size()) * v.sliceSamples();
    const auto convert = [&](S s) -> V { return unthresholded.convert(s); };
    const int64_t nx = v.dims[0], ny = v.dims[1];
    const int64_t slabs = (v.dims[2] + kSlab - 1) / kSlab;
    const int64_t rows = (ny + 3) / 4, cols = (nx + 3) / 4;
    const std::string name = std::filesystem::path(v.headerPath).filename().string();
    std::unique_ptr<Progress> progress;
    if (showProgress) progress = std::make_unique<Progress>("import " + name, uint64_t(slabs) * (th.any() ? 2 : 1));

    // Pass 1 (thresholds only): the removed samples' mean and the input range.
    PassStats first;
    V background = V(0);
    if (th.any()) {
        if (progress) progress->setLabel("import " + name + ": background statistics");
        forEachSlab<S>(v, progress.get(), [&](int64_t z0, int64_t nz, const S* s) {
            const uint64_t n = uint64_t(nz) * uint64_t(nx * ny);
            PassStats st;
            for (uint64_t i = 0; i < n; ++i) {
                if (missing(z0 + int64_t(i / uint64_t(nx * ny)))) continue;
                const double x = double(convert(s[i]));
                if (std::isfinite(x)) { st.min = std::min(st.min, x); st.max = std::max(st.max, x); }
                if (th.removes(x)) { ++st.removed; st.removedSum += x; }
            }
            first.add(st);
        });
        if (th.background) {
            if constexpr (std::is_integral_v<V>) {
                if (*th.background != std::trunc(*th.background) || *th.background < double(std::numeric_limits<V>::min()) ||
                    *th.background > double(std::numeric_limits<V>::max()))
                    throw Error(v.headerPath + ": --background-value " + std::to_string(*th.background) + " is not a value of this integer grid");
            }
            background = V(*th.background);
        } else if (first.removed) {
            const double mean = first.removedSum / double(first.removed);
            if constexpr (std::is_integral_v<V>) background = V(std::llround(mean));
            else background = V(mean);
        }
    }

    // Pass 2: bricks and values.
    const detail::SampleRule<S, V> rule(v, th, background);
    const bool byCubes = !cubesNear.empty();
    detail::DenseCubeScratch scratch;
    GridRecord record;
    record.valueType = valueType;
    const uint64_t expectedKept = v.sampleCount() - missingSamples - first.removed;
    if (byCubes) {
        scratch.file = std::make_shared<ScratchFile>(cubesNear);
        scratch.cols = cols;
        scratch.rows = rows;
        scratch.slabs = slabs;
        scratch.nonEmpty.assign(size_t((uint64_t(slabs) * uint64_t(rows) * uint64_t(cols) + 63) / 64), 0);
    } else {
        record.values.bricks.reserve(size_t(expectedKept * sizeof(V)));
        record.topology.bricks.reserve(size_t(uint64_t(slabs) * uint64_t(rows) * uint64_t(cols)));
    }
    PassStats second;
    struct Row {
        std::vector<Brick> bricks;
        std::vector<V> values;
        PassStats stats;
        bool integers = true;  // every value of the row an integer (float32 grids: integerLattice)
    };
    bool integers = true;
    std::vector<Row> rowOut(static_cast<size_t>(rows));
    // Solid 8^3 blocks (SolidBlocks.h): each slab's uniform bricks, paired
    // with the slab below when the slab is the upper half of a block.
    detail::SolidBlocks blocks;
    detail::SlabUniformity<V> lowerSlab, slabNow;
    if (th.solidBlocks) {
        blocks.reset(cols, rows, slabs, sizeof(V));
        lowerSlab.reset(cols, rows);
        slabNow.reset(cols, rows);
    }
    if (progress) progress->setLabel("import " + name + ": bricks");
    forEachSlab<S>(v, progress.get(), [&](int64_t z0, int64_t nz, const S* s) {
        if (byCubes) scratch.file->append(s, size_t(uint64_t(nz) * v.sliceSamples() * sizeof(S)));
        if (th.solidBlocks) std::fill(slabNow.uniform.begin(), slabNow.uniform.end(), uint8_t(0));
        tbb::parallel_for(int64_t(0), rows, [&](int64_t by) {
            Row& row = rowOut[size_t(by)];
            row.bricks.clear();
            row.values.clear();
            row.stats = PassStats{};
            for (int64_t bx = 0; bx < cols; ++bx) {
                const uint64_t mask = detail::cutBrick(rule, s + size_t((by * 4) * nx + bx * 4), size_t(nx), size_t(nx * ny), std::min<int64_t>(4, nx - bx * 4),
                                                       std::min<int64_t>(4, ny - by * 4), nz, z0, row.stats, row.values);
                if (mask) row.bricks.push_back({int32_t(bx * 4), int32_t(by * 4), int32_t(z0), mask});
                if (th.solidBlocks) slabNow.note(cols, bx, by, mask, row.values);
            }
            if constexpr (std::is_same_v<V, float>) row.integers = detail::integerLattice(row.values);
            if (byCubes) row.values.clear();  // read back cube by cube
        });
        if (th.solidBlocks) {
            if ((z0 / 4) % 2 == 0) std::swap(lowerSlab, slabNow);
            else detail::markSolidBlocks(lowerSlab, slabNow, cols, rows, z0 / 8, blocks);
        }
        for (Row& row : rowOut) {
            second.add(row.stats);
            integers = integers && row.integers;
            if (byCubes) {
                for (const Brick& b : row.bricks) scratch.add(b);
                continue;
            }
            record.topology.bricks.insert(record.topology.bricks.end(), row.bricks.begin(), row.bricks.end());
            const auto* p = reinterpret_cast<const uint8_t*>(row.values.data());
            record.values.bricks.insert(record.values.bricks.end(), p, p + row.values.size() * sizeof(V));
        }
    });
    if (progress) progress->finish();

    DenseImportResult result;
    result.source = v;
    ThresholdReport& r = result.threshold;
    r.samples = v.sampleCount() - missingSamples;  // samples with data
    if (th.any()) {
        r.applied = true;
        r.inactive = first.removed;
        r.changed = second.changed;
        r.background = double(background);
        r.inputMin = std::isfinite(first.min) ? first.min : 0;
        r.inputMax = std::isfinite(first.max) ? first.max : 0;
        r.maxAbsChange = second.maxAbs;
        r.meanAbsChange = second.sumAbs / double(r.samples);
        const double mse = second.sumSq / double(r.samples);
        r.rmsChange = std::sqrt(mse);
        auto psnrAt = [&](double peak) {
            return mse == 0 ? std::numeric_limits<double>::infinity() : (peak > 0 ? 10 * std::log10(peak * peak / mse) : 0.0);
        };
        r.psnr = psnrAt(r.inputMax - r.inputMin);
        if (isIntegerSample(v.type)) {  // peak = the stored range, in grid units
            r.storedBits = v.bitsStored ? v.bitsStored : 8 * sampleBytes(v.type);  // DICOM Bits Stored: a 12-bit CT's peak is 4095
            r.psnrStoredRange = psnrAt(std::abs(v.rescaleSlope) * (std::ldexp(1.0, int(r.storedBits)) - 1));
        }
        r.sharedBackground = th.below && th.above;
        r.backgroundChosen = th.background.has_value();
    }

    if (blocks.count) {  // the solid blocks become tiles
        if (byCubes) {
            scratch.summary.bricks -= 8 * blocks.count;
            scratch.summary.tiles = blocks.count;
            scratch.summary.largestTileLog2 = detail::kSolidBlockLog2;
            scratch.blocks = std::move(blocks);
        } else {
            replaceSolidBlocks(blocks, record);
        }
    }
    describeGrid<V>(v, background, &th, &r, record);
    if constexpr (std::is_same_v<V, float>)
        if (integers && !record.rescale) record.rescale = ValueRescale{1, 0};
    if (byCubes) result.cubes.push_back(detail::makeDenseCubes<S, V>(v, rule, std::move(scratch), record));
    result.volume.grids.push_back(std::move(record));
    return result;
}

} // namespace

namespace {

// A detached data file stays inside the header's folder tree: its name in
// the header is relative and never climbs out, and no link leads it out.
void checkDataFileLocation(const DenseVolume& v, const std::string& nameInHeader) {
    namespace fs = std::filesystem;
    const std::string refuse = v.headerPath + ": its data file '" + nameInHeader + "' ";
    const std::string hint = " (pass --allow-external-data if that is intended)";
    const fs::path name(nameInHeader);
    if (name.is_absolute()) throw Error(refuse + "is an absolute path, outside the header's folder" + hint);
    const fs::path normal = name.lexically_normal();
    if (!normal.empty() && *normal.begin() == "..") throw Error(refuse + "climbs out of the header's folder" + hint);
    std::error_code ec;
    const fs::path folder = fs::weakly_canonical(fs::absolute(fs::path(v.headerPath).parent_path().empty() ? fs::path(".") : fs::path(v.headerPath).parent_path()), ec);
    const fs::path data = fs::weakly_canonical(fs::absolute(v.dataPath), ec);
    if (ec) return;  // a missing data file is reported when it is opened
    const fs::path rel = data.lexically_relative(folder);
    if (rel.empty() || *rel.begin() == "..") throw Error(refuse + "leads out of the header's folder through a link" + hint);
}

// RAS and LAS coordinates to LPS: the axes that point the other way change
// sign (world x for R/L, world y for A/P).
void toLps(DenseVolume& v) {
    if (v.space.size() != 3 || v.space == "LPS") return;
    const double sx = v.space[0] == 'R' ? -1 : 1, sy = v.space[1] == 'A' ? -1 : 1;
    for (auto& axis : v.axes) {
        axis[0] *= sx;
        axis[1] *= sy;
    }
    v.origin[0] *= sx;
    v.origin[1] *= sy;
    v.space = "LPS";
}

} // namespace

DenseVolume describeDense(const std::string& path, const DenseImportOptions& options) {
    DenseVolume v;
    switch (denseFormatOf(path)) {
        case DenseFormat::Raw: v = describeRaw(path, options.raw); v.format = DenseFormat::Raw; return v;
        case DenseFormat::Nrrd:  // a 4-D series without --volume: described by its first volume
            v = readNrrdHeader(path, options.volume ? options.volume : std::optional<int64_t>(0));
            break;
        case DenseFormat::MetaImage: v = readMetaImageHeader(path); break;
        case DenseFormat::Nifti:  // a 4-D file without --volume: described by its first volume (importDense reads them all)
            v = readNiftiHeader(path, options.volume ? options.volume : (niftiVolumeCount(path) > 1 ? std::optional<int64_t>(0) : std::nullopt));
            break;
        case DenseFormat::Dicom: {
            std::vector<std::string> inputs{path};
            inputs.insert(inputs.end(), options.moreInputs.begin(), options.moreInputs.end());
            v = describeDicomSeries(inputs, options.series);
            v.format = DenseFormat::Dicom;
            if (options.dropPatientTags) dropIdentifyingDicomTags(v.headerFields);
            return v;
        }
        case DenseFormat::None: throw Error(path + ": not a dense volume (expected .raw, .nrrd, .nhdr, .mhd, .mha, .nii, .nii.gz, .hdr or DICOM)");
    }
    v.format = denseFormatOf(path);
    v.resume = options.resume;
    toLps(v);
    if (!options.allowExternalData && v.dataPath != v.headerPath) checkDataFileLocation(v, v.dataNameInHeader);
    return v;
}

namespace {

// Samples with a rescale: an Int32 grid when slope and intercept are
// integers and every stored value maps into int32 (CT in HU), else a Float
// grid (a Double grid for 32-bit and f64 samples, whose values float cannot
// hold).
DenseImportResult importRescaled(const DenseVolume& v, const Thresholds& th, bool p, const std::string& near) {
    const double a = v.rescaleSlope, b = v.rescaleIntercept;
    if (!std::isfinite(a) || !std::isfinite(b) || a == 0)
        throw Error(v.headerPath + ": the rescale slope " + std::to_string(a) + " / intercept " + std::to_string(b) + " is not usable");
    const auto [lo, hi] = sampleRange(v.type);  // NaN for float samples
    const bool integral = isIntegerSample(v.type) && a == std::trunc(a) && b == std::trunc(b) && std::abs(a) < 2147483648.0 &&
                          std::abs(b) < 2147483648.0;
    const double r0 = a * lo + b, r1 = a * hi + b;
    if (integral && std::min(r0, r1) >= -2147483648.0 && std::max(r0, r1) <= 2147483647.0) {
        switch (v.type) {
            case SampleType::U8: return importTyped<uint8_t, int32_t>(v, th, ValueType::Int32, p, near);
            case SampleType::I8: return importTyped<int8_t, int32_t>(v, th, ValueType::Int32, p, near);
            case SampleType::U16: return importTyped<uint16_t, int32_t>(v, th, ValueType::Int32, p, near);
            case SampleType::I16: return importTyped<int16_t, int32_t>(v, th, ValueType::Int32, p, near);
            default: break;  // 32-bit samples rescaled: as doubles
        }
    }
    switch (v.type) {
        case SampleType::U8: return importTyped<uint8_t, float>(v, th, ValueType::Float, p, near);
        case SampleType::I8: return importTyped<int8_t, float>(v, th, ValueType::Float, p, near);
        case SampleType::U16: return importTyped<uint16_t, float>(v, th, ValueType::Float, p, near);
        case SampleType::I16: return importTyped<int16_t, float>(v, th, ValueType::Float, p, near);
        case SampleType::F32: return importTyped<float, float>(v, th, ValueType::Float, p, near);
        case SampleType::U32: return importTyped<uint32_t, double>(v, th, ValueType::Double, p, near);
        case SampleType::I32: return importTyped<int32_t, double>(v, th, ValueType::Double, p, near);
        case SampleType::F64: return importTyped<double, double>(v, th, ValueType::Double, p, near);
    }
    throw Error(v.headerPath + ": unsupported sample type");
}

} // namespace

// What importing `volumes` volumes like `v` will hold at least, weighed
// against options.limits from the header alone (a forged header of a few
// hundred bytes may declare 65535x65535 pixels, a gzip NRRD of 1 MB a
// billion samples): the slab of slices read at a time, and - unless the
// samples go cube by cube to a scratch file or thresholds drop some - every
// sample as a grid value (4 bytes, 8 for 64-bit and u32 samples, per
// component), its bricks, and the caller's copies. What the data file shows
// (too short, missing) is said first: it is the more precise answer.
void checkImportLimits(const DenseVolume& v, bool thresholds, const DenseImportOptions& options, uint64_t volumes) {
    using format::saturatingAdd;
    using format::saturatingMul;
    { openSliceReader(v); }  // first what the data file itself shows (too short, missing, a gzip stream that cannot hold the samples)
    const format::ReadLimits& limits = options.limits;
    const uint64_t samples = saturatingMul(v.sampleCount(), volumes);
    format::checkVoxels(limits, samples, v.headerPath);
    const uint64_t sampleSize = sampleBytes(v.type) * std::max(1u, v.componentsInFile());
    uint64_t bytes = saturatingMul(saturatingMul(v.sliceSamples(), uint64_t(std::min<int64_t>(kSlab, std::max<int64_t>(v.dims[2], 1)))), sampleSize);
    const bool byCubes = !options.cubesNear.empty() && v.components == 1;
    if (!byCubes && !thresholds) {
        const uint64_t valueSize = uint64_t(sampleBytes(v.type) == 8 || v.type == SampleType::U32 ? 8 : 4) * std::max(1u, v.components);
        const uint64_t perSample = valueSize * (1 + limits.valueCopies) + sizeof(Brick) / 64;
        bytes = saturatingAdd(bytes, saturatingMul(samples, perSample));
    }
    format::checkMemory(limits, bytes, v.headerPath, fmt::format("its {} samples of {}x{}x{}{}", samples, v.dims[0], v.dims[1], v.dims[2],
                                                                  volumes > 1 ? fmt::format(" in {} volumes", volumes) : std::string()));
}

int64_t volumeCountOf(const std::string& path) {
    switch (denseFormatOf(path)) {
        case DenseFormat::Nifti: return niftiVolumeCount(path);
        case DenseFormat::Nrrd: return readNrrdHeader(path, 0).volumeCount;
        default: return 1;
    }
}

std::optional<ScanProvenance> scanProvenanceOf(const GridRecord& grid) {
    const openvdb::GridBase::Ptr g = detail::readDescriptor(grid.vdbDescriptor, "grid '" + grid.name + "'");
    const auto format = g->getMetadata<openvdb::StringMetadata>("source_format");
    const auto type = g->getMetadata<openvdb::StringMetadata>("source_sample_type");
    if (!type) return std::nullopt;
    ScanProvenance p;
    if (auto f = g->getMetadata<openvdb::StringMetadata>("source_file")) p.sourceFile = f->value();
    p.format = format ? format->value() : "";
    p.sampleType = type->value();
    if (auto d = g->getMetadata<openvdb::Vec3IMetadata>("source_dims")) p.dims = {d->value()[0], d->value()[1], d->value()[2]};
    if (auto s = g->getMetadata<openvdb::StringMetadata>("space")) p.space = s->value();
    if (auto b = g->getMetadata<openvdb::DoubleMetadata>("background_below")) p.below = b->value();
    if (auto a = g->getMetadata<openvdb::DoubleMetadata>("background_above")) p.above = a->value();
    if (auto n = g->getMetadata<openvdb::Int64Metadata>("threshold_inactive_samples")) {
        ThresholdReport r;
        r.applied = true;
        r.inactive = uint64_t(n->value());
        if (auto c = g->getMetadata<openvdb::Int64Metadata>("threshold_changed_samples")) r.changed = uint64_t(c->value());
        if (auto m = g->getMetadata<openvdb::DoubleMetadata>("threshold_max_abs_change")) r.maxAbsChange = m->value();
        if (auto m = g->getMetadata<openvdb::DoubleMetadata>("threshold_rms_change")) r.rmsChange = m->value();
        if (auto m = g->getMetadata<openvdb::DoubleMetadata>("threshold_psnr_db")) r.psnr = m->value();
        p.threshold = r;
    }
    return p;
}

DenseImportResult importDense(const std::string& path, const DenseImportOptions& options) {
    if (!options.volume) {
        // A 4-D NIfTI or NRRD file without --volume: one grid per volume, NAME_t0, NAME_t1, ...
        const int64_t volumes = volumeCountOf(path);
        if (volumes > 1) {
            if (options.backgroundBelow || options.backgroundAbove)
                throw Error(path + ": background thresholds apply to one volume of a 4-D file: pick it with --volume N");
            {
                DenseImportOptions first = options;
                first.volume = 0;
                checkImportLimits(describeDense(path, first), false, options, uint64_t(volumes));
            }
            DenseImportResult all;
            const auto resume = std::make_shared<detail::InflateCheckpoints>();  // each volume's reader starts where the last one ended
            for (int64_t t = 0; t < volumes; ++t) {
                DenseImportOptions one = options;
                one.volume = t;
                one.resume = resume;
                DenseImportResult r = importDense(path, one);
                if (t == 0) {
                    all.source = r.source;
                    all.threshold = r.threshold;
                } else {
                    all.threshold.samples += r.threshold.samples;
                }
                for (GridRecord& g : r.volume.grids) all.volume.grids.push_back(std::move(g));
                for (auto& c : r.cubes) all.cubes.push_back(std::move(c));
            }
            all.source.resume.reset();  // the checkpoints serve this import only
            return all;
        }
    }
    const DenseVolume v = describeDense(path, options);
    Thresholds th;
    th.solidBlocks = options.solidBlocks;
    for (auto [set, value, flag] : {std::tuple{&th.below, &th.belowValue, options.backgroundBelow},
                                    std::tuple{&th.above, &th.aboveValue, options.backgroundAbove}}) {
        if (!flag) continue;
        if (!std::isfinite(*flag)) throw Error(path + ": a background threshold must be a finite number");
        *set = true;
        *value = *flag;
    }
    if (options.backgroundValue) {
        if (!th.any()) throw Error(path + ": --background-value needs --background-below or --background-above (it is the value removed samples become)");
        if (!std::isfinite(*options.backgroundValue)) throw Error(path + ": --background-value must be a finite number");
        th.background = options.backgroundValue;
    }
    if (th.below && th.above && th.aboveValue < th.belowValue)
        throw Error(path + ": --background-above is below --background-below: every sample would become background");
    checkImportLimits(v, th.any(), options, 1);
    const bool p = options.showProgress;
    if (v.components != 1) {
        if (v.components != 3) throw Error(path + ": " + std::to_string(v.components) + " components per sample are not supported (1 and 3 are)");
        if (th.any()) throw Error(path + ": background thresholds apply to scalar scans only (this one has 3 components per sample)");
        if (v.rescaleSlope != 1 || v.rescaleIntercept != 0) throw Error(path + ": a rescaled vector scan is not supported");
        if (v.colour && v.storedComponents == 4 && v.type == SampleType::U8) {
            // RGBA (NIfTI RGBA32): the colour grid "Cd" and an Int32 grid "alpha", both every sample.
            DenseImportResult rgba = importVector<uint8_t, int32_t>(v, ValueType::Vec3I, p);
            DenseVolume alpha = v;
            alpha.colour = false;
            alpha.components = 1;
            alpha.firstComponent = 3;
            alpha.gridName = "alpha";
            DenseImportResult a = importTyped<uint8_t, int32_t>(alpha, th, ValueType::Int32, p);
            for (GridRecord& g : a.volume.grids) rgba.volume.grids.push_back(std::move(g));
            return rgba;
        }
        switch (v.type) {
            case SampleType::U8: return importVector<uint8_t, int32_t>(v, ValueType::Vec3I, p);
            case SampleType::I8: return importVector<int8_t, int32_t>(v, ValueType::Vec3I, p);
            case SampleType::U16: return importVector<uint16_t, int32_t>(v, ValueType::Vec3I, p);
            case SampleType::I16: return importVector<int16_t, int32_t>(v, ValueType::Vec3I, p);
            case SampleType::I32: return importVector<int32_t, int32_t>(v, ValueType::Vec3I, p);
            case SampleType::F32: return importVector<float, float>(v, ValueType::Vec3S, p);
            case SampleType::F64: return importVector<double, double>(v, ValueType::Vec3D, p);
            case SampleType::U32: throw Error(path + ": u32 vector samples are not supported (a Vec3I grid cannot hold them)");
        }
    }
    if (v.rescaleSlope != 1 || v.rescaleIntercept != 0) return importRescaled(v, th, p, options.cubesNear);
    switch (v.type) {
        case SampleType::U8: return importTyped<uint8_t, int32_t>(v, th, ValueType::Int32, p, options.cubesNear);
        case SampleType::I8: return importTyped<int8_t, int32_t>(v, th, ValueType::Int32, p, options.cubesNear);
        case SampleType::U16: return importTyped<uint16_t, int32_t>(v, th, ValueType::Int32, p, options.cubesNear);
        case SampleType::I16: return importTyped<int16_t, int32_t>(v, th, ValueType::Int32, p, options.cubesNear);
        case SampleType::U32: return importTyped<uint32_t, int64_t>(v, th, ValueType::Int64, p, options.cubesNear);
        case SampleType::I32: return importTyped<int32_t, int32_t>(v, th, ValueType::Int32, p, options.cubesNear);
        case SampleType::F32: return importTyped<float, float>(v, th, ValueType::Float, p, options.cubesNear);
        case SampleType::F64: return importTyped<double, double>(v, th, ValueType::Double, p, options.cubesNear);
    }
    throw Error(path + ": unsupported sample type");
}

} // namespace vdbdag::bridge
