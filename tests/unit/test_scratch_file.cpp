// ScratchFile: the bytes kept in memory and those in the file read back as
// one space, against a plain vector holding the same appends.
#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>
#include <random>

#include "src/util/Error.h"
#include "src/util/ScratchFile.h"

namespace vdbdag {
namespace {

std::string nearPath() { return (std::filesystem::temp_directory_path() / "vdbdag_scratch_test.bin").string(); }

// Appends pieces of random sizes to `scratch` and to `reference`.
void fill(ScratchFile& scratch, std::vector<uint8_t>& reference, size_t total, uint32_t seed) {
    std::mt19937 rng(seed);
    while (reference.size() < total) {
        std::vector<uint8_t> piece(rng() % 5000);
        for (uint8_t& b : piece) b = uint8_t(rng());
        EXPECT_EQ(scratch.append(piece.data(), piece.size()), reference.size());
        reference.insert(reference.end(), piece.begin(), piece.end());
    }
}

TEST(ScratchFile, MemoryThenFileReadsBackAsOneSpace) {
    for (const uint64_t keep : {uint64_t(0), uint64_t(100000), uint64_t(1) << 30}) {
        SCOPED_TRACE(keep);
        ScratchFile scratch(nearPath(), keep);
        std::vector<uint8_t> reference;
        fill(scratch, reference, (size_t(17) << 20), uint32_t(keep));  // past one 16 MiB memory chunk
        ASSERT_EQ(scratch.size(), reference.size());
        // Spilled exactly when the appends outgrew what memory may keep.
        EXPECT_EQ(scratch.path().empty(), keep >= reference.size());
        if (!scratch.path().empty()) { EXPECT_TRUE(std::filesystem::exists(scratch.path())); }
        // Overwrites anywhere, also across the memory/file boundary.
        std::mt19937 rng(7);
        for (int k = 0; k < 50; ++k) {
            const uint64_t at = rng() % reference.size();
            std::vector<uint8_t> bytes(std::min<uint64_t>(rng() % 3000, reference.size() - at), uint8_t(k));
            scratch.overwrite(at, bytes.data(), bytes.size());
            std::copy(bytes.begin(), bytes.end(), reference.begin() + long(at));
        }
        // Reads and views of every alignment agree with the reference.
        std::vector<uint8_t> out, buffer;
        for (int k = 0; k < 300; ++k) {
            const uint64_t at = rng() % reference.size();
            const size_t n = size_t(std::min<uint64_t>(rng() % 10000, reference.size() - at));
            scratch.read(at, n, out);
            ASSERT_TRUE(std::equal(out.begin(), out.end(), reference.begin() + long(at)));
            const std::span<const uint8_t> view = scratch.view(at, n, buffer);
            ASSERT_EQ(view.size(), n);
            ASSERT_TRUE(std::equal(view.begin(), view.end(), reference.begin() + long(at)));
        }
        EXPECT_THROW(scratch.read(reference.size() - 10, 11, out), Error);
    }
}

TEST(ScratchFile, TheFileIsRemovedWithTheObject) {
    std::string path;
    {
        ScratchFile scratch(nearPath(), 10);
        const std::vector<uint8_t> bytes(100, 1);
        scratch.append(bytes.data(), bytes.size());
        path = scratch.path();
        ASSERT_FALSE(path.empty());
        EXPECT_TRUE(std::filesystem::exists(path));
    }
    EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ScratchFile, AnUnwritableFolderIsRefusedWhenTheFileIsNeeded) {
    EXPECT_THROW(ScratchFile("/nonexistent_vdbdag_folder/x.ssvdag"), Error);
    ScratchFile lazy("/nonexistent_vdbdag_folder/x.ssvdag", 64);
    const std::vector<uint8_t> bytes(100, 1);
    EXPECT_THROW(lazy.append(bytes.data(), bytes.size()), Error);
}

} // namespace
} // namespace vdbdag
