// The dense sample reader (vdb_bridge/DenseVolume.cpp) on data files its
// header cannot be read from: each refusal is a vdbdag::Error and leaves no
// file descriptor open (a reader whose constructor threw never closed its
// file; fuzz_scan_headers ran out of 20,000 descriptors after 1.6 million
// inputs). Counted in /proc/self/fd, in-process.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "src/util/Error.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/NrrdHeader.h"

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
