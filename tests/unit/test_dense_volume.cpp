// The dense sample reader (vdb_bridge/DenseVolume.cpp) on data files its
// header cannot be read from: each refusal is a vdbdag::Error and leaves no
// file descriptor open (a reader whose constructor threw never closed its
// file; fuzz_scan_headers ran out of 20,000 descriptors after 1.6 million
// inputs). Counted in /proc/self/fd, in-process.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>
#include <zlib.h>

#include "src/util/Error.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/NrrdHeader.h"
#include "vdb_bridge/detail/InflateCheckpoints.h"

namespace fs = std::filesystem;
using namespace vdbdag;
using namespace vdbdag::bridge;

namespace {

size_t openDescriptors() {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++n;
    return n;
}

} // namespace

TEST(DenseVolume, ARefusedDataFileLeavesNoDescriptorOpen) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_dense_volume_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    // 4x4x4 bytes after 5 lines to skip, in a data file of 2 lines: the
    // header reads, the reader refuses the file once it has opened it.
    std::ofstream(dir / "s.nhdr") << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: raw\nline skip: 5\ndata file: s.raw\n";
    std::ofstream(dir / "s.raw", std::ios::binary) << "one\ntwo\n";
    const DenseVolume v = readNrrdHeader((dir / "s.nhdr").string());
    const size_t before = openDescriptors();
    for (int i = 0; i < 100; ++i) {
        try {
            openSliceReader(v);
            ADD_FAILURE() << "not refused";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("ends before the 5 lines to skip"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(openDescriptors(), before);
    fs::remove_all(dir);
}

// The volumes of a 4-D gzip NRRD read one after another, each reader
// resuming the stream where the one before left it (InflateCheckpoints.h):
// every volume's samples equal the ones written (2.2 MB of gzip, so the
// readers cross the 1 MiB reads of the file), whether read in order, again,
// out of order or after a reader gave up halfway; in order, each reader
// after the first skips every byte before its volume (resumedBytes). The
// import of the whole series (one grid a volume) gives every sample too.
TEST(DenseVolume, AFourDGzipStreamResumesWhereTheLastVolumeEnded) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_dense_resume_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    constexpr int nx = 64, ny = 64, nz = 40, volumes = 9;
    const size_t perVolume = size_t(nx) * ny * nz;
    std::vector<uint16_t> samples(perVolume * volumes);
    uint32_t state = 12345;
    for (size_t i = 0; i < samples.size(); ++i) {
        state = state * 1664525u + 1013904223u;
        samples[i] = uint16_t(state >> 20);  // 12 random bits: little for gzip to take
    }
    std::vector<uint8_t> gz(compressBound(uLong(samples.size() * 2)) + 64);
    z_stream z{};
    ASSERT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);  // a gzip wrapper
    z.next_in = reinterpret_cast<Bytef*>(samples.data());
    z.avail_in = uInt(samples.size() * 2);
    z.next_out = gz.data();
    z.avail_out = uInt(gz.size());
    ASSERT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    gz.resize(z.total_out);
    deflateEnd(&z);
    ASSERT_GT(gz.size(), size_t(2) << 20);
    std::ofstream(dir / "series.raw.gz", std::ios::binary).write(reinterpret_cast<const char*>(gz.data()), std::streamsize(gz.size()));
    const fs::path header = dir / "series.nhdr";
    std::ofstream(header) << "NRRD0004\ntype: uint16\ndimension: 4\nsizes: " << nx << " " << ny << " " << nz << " " << volumes
                          << "\nspace directions: (1,0,0) (0,1,0) (0,0,1) none\nendian: little\nencoding: gzip\ndata file: series.raw.gz\n";
    const auto resume = std::make_shared<detail::InflateCheckpoints>();
    const auto check = [&](int t) {
        DenseVolume v = readNrrdHeader(header.string(), t);
        ASSERT_EQ(v.volumeCount, volumes);
        v.resume = resume;
        std::vector<uint8_t> got;
        openSliceReader(v)->readSlices(nz, got);
        ASSERT_EQ(got.size(), perVolume * 2);
        EXPECT_EQ(std::memcmp(got.data(), samples.data() + perVolume * size_t(t), got.size()), 0) << "volume " << t;
    };
    for (int t = 0; t < volumes; ++t) check(t);
    uint64_t before = 0;
    for (int t = 1; t < volumes; ++t) before += uint64_t(t) * perVolume * 2;
    EXPECT_EQ(resume->resumedBytes(), before);  // each volume's reader began at its volume
    for (const int t : {volumes - 1, 2, 0, 5, 5}) check(t);  // again, and out of order
    {
        DenseVolume v = readNrrdHeader(header.string(), 3);
        v.resume = resume;
        std::vector<uint8_t> part;
        openSliceReader(v)->readSlices(nz / 2 + 1, part);  // a reader that stops halfway
    }
    for (const int t : {3, 4, 6}) check(t);
    // The import: grid t holds volume t's samples (uint16 -> int32, every voxel active).
    const bridge::DenseImportResult imported = bridge::importDense(header.string(), {});
    ASSERT_EQ(imported.volume.grids.size(), size_t(volumes));
    for (int t = 0; t < volumes; ++t) {
        const GridRecord& g = imported.volume.grids[size_t(t)];
        size_t at = 0, wrong = 0, seen = 0;
        for (const Brick& b : g.topology.bricks)
            for (int bit = 0; bit < 64; ++bit) {
                if (!(b.mask >> bit & 1)) continue;
                const size_t i = (size_t(b.z + (bit >> 4)) * ny + size_t(b.y + ((bit >> 2) & 3))) * nx + size_t(b.x + (bit & 3));
                int32_t value;
                std::memcpy(&value, g.values.bricks.data() + 4 * at++, 4);
                wrong += value != samples[perVolume * size_t(t) + i];
                ++seen;
            }
        EXPECT_EQ(seen, perVolume) << "volume " << t;
        EXPECT_EQ(wrong, 0u) << "volume " << t;
    }
    fs::remove_all(dir);
}
