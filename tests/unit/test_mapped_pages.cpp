// releaseMappedPages looks the file's mappings up at each call: a mapping
// gone (OpenVDB unmaps the .vdb once no leaf refers to it) is never advised,
// so anonymous memory that reuses its addresses keeps its bytes.
#include <gtest/gtest.h>

#include <sys/mman.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "src/util/MappedPages.h"

namespace vdbdag {
namespace {

TEST(MappedPages, ReleasesOnlyTheMappingsThatExistNow) {
    const std::filesystem::path path = std::filesystem::temp_directory_path() / "vdbdag_mapped_pages_test.bin";
    const size_t size = size_t(4) << 20;
    std::vector<char> bytes(size);
    for (size_t i = 0; i < size; ++i) bytes[i] = char(i * 7 + 3);
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(size));
    FILE* f = std::fopen(path.c_str(), "rb");
    ASSERT_NE(f, nullptr);
    void* map = mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fileno(f), 0);
    std::fclose(f);
    ASSERT_NE(map, MAP_FAILED);
    EXPECT_EQ(std::memcmp(map, bytes.data(), size), 0);
    EXPECT_EQ(releaseMappedPages(path.string()), 1u);
    EXPECT_EQ(std::memcmp(map, bytes.data(), size), 0);  // read again from the file
    munmap(map, size);
    // The same addresses, now anonymous memory with other bytes: untouched.
    void* anon = mmap(map, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(anon, MAP_FAILED);
    std::memset(anon, 0x5A, size);
    EXPECT_EQ(releaseMappedPages(path.string()), 0u);
    EXPECT_EQ(static_cast<unsigned char*>(anon)[size / 2], 0x5A);
    munmap(anon, size);
    std::filesystem::remove(path);
}

} // namespace
} // namespace vdbdag
