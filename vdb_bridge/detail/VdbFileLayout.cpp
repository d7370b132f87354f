// See VdbFileLayout.h. Reads only the header, the metadata and the grid
// descriptors (a few hundred bytes of a file of any size), with pread.
#include "vdb_bridge/detail/VdbFileLayout.h"

#include <cctype>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "src/util/Error.h"
#include "src/util/InputPath.h"

namespace vdbdag::bridge::detail {
namespace {

constexpr int64_t kMagic = 0x56444220;
constexpr uint32_t kOldestVersion = 220, kNewestVersion = 224;
constexpr uint32_t kMaxMetadataEntries = 1u << 20;
constexpr uint32_t kMaxGrids = 1u << 20;
constexpr uint32_t kMaxNameBytes = 1u << 20;

// A cursor over bytes that come either from a file (pread) or from memory;
// every read is checked against the length first.
class Cursor {
public:
    Cursor(int fd, uint64_t size, std::string what) : fd_(fd), size_(size), what_(std::move(what)) {}
    Cursor(const uint8_t* data, uint64_t size, std::string what) : data_(data), size_(size), what_(std::move(what)) {}

    uint64_t position() const { return pos_; }
    uint64_t size() const { return size_; }
    void seek(uint64_t pos) { pos_ = pos; }

    void read(void* out, uint64_t n, const char* field) {
        if (n > size_ || pos_ > size_ - n)
            throw Error(what_ + ": truncated: the file ends inside " + field + " (byte " + std::to_string(pos_) + " of " + std::to_string(size_) + ")");
        if (data_) {
            std::memcpy(out, data_ + pos_, n);
        } else {
            uint64_t done = 0;
            while (done < n) {
                const ssize_t r = ::pread(fd_, static_cast<char*>(out) + done, n - done, off_t(pos_ + done));
                if (r < 0 && errno == EINTR) continue;
                if (r <= 0) throw Error(what_ + ": cannot be read (" + std::string(r < 0 ? std::strerror(errno) : "unexpected end") + ")");
                done += uint64_t(r);
            }
        }
        pos_ += n;
    }
    template <typename T>
    T get(const char* field) {
        T v{};
        read(&v, sizeof v, field);
        return v;
    }
    void skip(uint64_t n, const char* field) {
        if (n > size_ || pos_ > size_ - n)
            throw Error(what_ + ": truncated: the file ends inside " + field + " (byte " + std::to_string(pos_) + " of " + std::to_string(size_) + ")");
        pos_ += n;
    }
    std::string getString(const char* field) {
        const uint32_t n = get<uint32_t>(field);
        if (n > kMaxNameBytes)
            throw Error(what_ + ": corrupted: " + field + " claims " + std::to_string(n) + " bytes at byte " + std::to_string(pos_ - 4));
        std::string s(n, '\0');
        read(s.data(), n, field);
        return s;
    }
    [[noreturn]] void corrupted(const std::string& why) const { throw Error(what_ + ": corrupted: " + why); }

private:
    int fd_ = -1;
    const uint8_t* data_ = nullptr;
    uint64_t size_ = 0, pos_ = 0;
    std::string what_;
};

uint64_t readMetadata(Cursor& c) {
    const uint32_t count = c.get<uint32_t>("the file metadata");
    if (count > kMaxMetadataEntries) c.corrupted("the metadata claims " + std::to_string(count) + " entries");
    for (uint32_t i = 0; i < count; ++i) {
        c.getString("a metadata name");
        c.getString("a metadata type");
        const uint32_t bytes = c.get<uint32_t>("a metadata value");
        c.skip(bytes, "a metadata value");
    }
    return count;
}

} // namespace

void checkMetadataBlock(const uint8_t* data, uint64_t size, const std::string& what) {
    Cursor c(data, size, what);
    readMetadata(c);
    if (c.position() != size) c.corrupted(std::to_string(size - c.position()) + " bytes after the metadata");
}

VdbFileLayout checkVdbFileLayout(const std::string& path) {
    checkInputFile(path, "a .vdb file");  // before open: opening a FIFO blocks
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        const int err = errno;
        if (err == ENOENT) throw Error(path + ": no such file");
        throw Error(path + ": cannot be opened (" + std::strerror(err) + ")");
    }
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st{};
    if (::fstat(fd, &st) != 0) throw Error(path + ": cannot be read (" + std::strerror(errno) + ")");
    if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not a .vdb file");
    if (!S_ISREG(st.st_mode)) throw Error(path + ": is not a regular file");
    Cursor c(fd, uint64_t(st.st_size), path);

    VdbFileLayout layout;
    if (c.size() < 8) {
        char head[8]{};
        c.read(head, c.size(), "");
        if (c.size() == 0) throw Error(path + ": empty file, not a .vdb file");
        const int64_t magic = kMagic;
        if (std::memcmp(head, &magic, c.size()) == 0) throw Error(path + ": truncated: " + std::to_string(c.size()) + " bytes, shorter than a .vdb header");
        throw Error(path + ": not a .vdb file (bad magic number)");
    }
    if (c.get<int64_t>("the magic number") != kMagic) throw Error(path + ": not a .vdb file (bad magic number)");
    layout.fileVersion = c.get<uint32_t>("the header");
    if (layout.fileVersion < kOldestVersion || layout.fileVersion > kNewestVersion)
        throw Error(path + ": .vdb file format version " + std::to_string(layout.fileVersion) + " is not supported (" + std::to_string(kOldestVersion) +
                    "-" + std::to_string(kNewestVersion) + " are)");
    c.skip(8, "the header");  // library version
    const uint8_t offsets = c.get<uint8_t>("the header");
    if (offsets > 1) c.corrupted("the header's grid-offsets flag is " + std::to_string(offsets));
    layout.hasGridOffsets = offsets == 1;
    if (layout.fileVersion < 222) c.skip(1, "the header");
    char uuid[36];
    c.read(uuid, sizeof uuid, "the header");
    for (char ch : uuid)
        if (!(std::isxdigit(static_cast<unsigned char>(ch)) || ch == '-')) c.corrupted("the header's UUID is not text");
    layout.metadataEntries = readMetadata(c);
    layout.gridCount = c.get<int32_t>("the grid count");
    if (layout.gridCount < 0 || uint32_t(layout.gridCount) > kMaxGrids) c.corrupted("the grid count is " + std::to_string(layout.gridCount));
    if (!layout.hasGridOffsets) return layout;  // a stream: grids are checked as OpenVDB reads them

    for (int32_t g = 0; g < layout.gridCount; ++g) {
        VdbGridEntry e;
        e.uniqueName = c.getString("a grid name");
        e.type = c.getString("a grid type");
        e.instanceParent = c.getString("a grid's instance parent");
        e.gridPos = c.get<int64_t>("a grid's offsets");
        e.blockPos = c.get<int64_t>("a grid's offsets");
        e.endPos = c.get<int64_t>("a grid's offsets");
        const int64_t here = int64_t(c.position()), size = int64_t(c.size());
        const std::string which = "grid " + std::to_string(g) + " '" + e.uniqueName + "'";
        if (e.endPos > size)
            throw Error(path + ": truncated: " + which + " ends at byte " + std::to_string(e.endPos) + " but the file has " + std::to_string(size));
        if (e.gridPos != here || e.endPos < e.gridPos || (e.instanceParent.empty() && (e.blockPos < e.gridPos || e.endPos < e.blockPos))) c.corrupted(which + " has inconsistent offsets");
        layout.grids.push_back(std::move(e));
        c.seek(uint64_t(layout.grids.back().endPos));
    }
    return layout;
}

} // namespace vdbdag::bridge::detail
