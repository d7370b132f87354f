// See TemporaryFiles.h. The registry is a fixed table of slots (no
// allocation), so the signal handler can walk it: a slot's path is written
// before its state is published, and the handler reads only published slots.
// Folders are removed with openat / getdents64 / unlinkat, which are
// async-signal-safe, unlike std::filesystem.
#include "src/util/TemporaryFiles.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <random>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "src/util/Error.h"

namespace vdbdag {
namespace {

constexpr int kSlots = 64;
constexpr size_t kPathBytes = 4096;

enum : int { kFree = 0, kClaimed = 1, kFile = 2, kFolder = 3 };

struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes];
};
Slot g_slots[kSlots];

struct LinuxDirent64 {
    uint64_t ino;
    int64_t off;
    unsigned short reclen;
    unsigned char type;
    char name[1];
};

// Removes what folder `fd` holds, `depth` levels deep at most; closes `fd`.
// The folder is listed again from its start after each batch of removals.
void emptyFolder(int fd, int depth) noexcept {
    alignas(8) char buffer[4096];
    for (int pass = 0; pass < 1024; ++pass) {
        ::lseek(fd, 0, SEEK_SET);
        const long n = syscall(SYS_getdents64, fd, buffer, sizeof buffer);
        if (n <= 0) break;
        bool removed = false;
        for (long pos = 0; pos < n;) {
            const auto* entry = reinterpret_cast<const LinuxDirent64*>(buffer + pos);
            pos += entry->reclen;
            const char* name = entry->name;
            if (std::strcmp(name, ".") == 0 || std::strcmp(name, "..") == 0) continue;
            if (::unlinkat(fd, name, 0) == 0) {
                removed = true;
                continue;
            }
            if (depth > 0 && (errno == EISDIR || errno == EPERM)) {
                const int sub = ::openat(fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
                if (sub >= 0) emptyFolder(sub, depth - 1);
                if (::unlinkat(fd, name, AT_REMOVEDIR) == 0) removed = true;
            }
        }
        if (!removed) break;
    }
    ::close(fd);
}

void removeFolder(const char* path) noexcept {
    const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0) emptyFolder(fd, 4);
    ::rmdir(path);
}

void removeSlot(Slot& slot) noexcept {
    const int state = slot.state.load(std::memory_order_acquire);
    if (state == kFile) ::unlink(slot.path);
    else if (state == kFolder) removeFolder(slot.path);
}

void onInterrupt(int signal) {
    const int saved = errno;
    removeAllTemporaries();
    errno = saved;
    // End the way the signal would have ended the process (exit status 128+N).
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

} // namespace

TemporaryGuard::TemporaryGuard(const std::string& path, bool folder) : slot_(-1) {
    if (path.size() >= kPathBytes) throw Error(path + ": path too long for a temporary file");
    for (int i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kClaimed)) continue;
        std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
        g_slots[i].state.store(folder ? kFolder : kFile, std::memory_order_release);
        slot_ = i;
        return;
    }
    throw Error(path + ": more than 64 temporary files at once");
}

TemporaryGuard::~TemporaryGuard() {
    if (slot_ >= 0) g_slots[slot_].state.store(kFree, std::memory_order_release);
}

void installInterruptCleanup() {
    static std::atomic<bool> installed{false};
    if (installed.exchange(true)) return;
    struct sigaction action{};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&action.sa_mask, s);  // one cleanup at a time
    action.sa_flags = SA_RESETHAND;
    for (int s : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction old{};
        sigaction(s, nullptr, &old);
        // nohup's ignored SIGHUP stays ignored. SIGINT is also ignored in a
        // script's background jobs, but whoever sends it there means it.
        if (s == SIGHUP && old.sa_handler == SIG_IGN) continue;
        sigaction(s, &action, nullptr);
    }
}

void removeAllTemporaries() noexcept {
    for (Slot& slot : g_slots) removeSlot(slot);
}

std::string temporaryNameFor(const std::string& path, const std::string& suffix) {
    static thread_local std::mt19937_64 rng{std::random_device{}() ^ (uint64_t(getpid()) << 32)};
    const std::filesystem::path p(path);
    std::string name = ".";  // built by appending: GCC 12 warns (-Wrestrict) about "." + string
    name += p.filename().string();
    name += ".tmp.";
    name += std::to_string(getpid());
    name += '.';
    name += std::to_string(rng() & 0xFFFFFFFFFFFFull);
    name += suffix;
    return (p.parent_path() / name).string();
}

void removeStaleTemporaries(const std::string& path) noexcept {
    namespace fs = std::filesystem;
    try {
        const fs::path p(path);
        const fs::path folder = p.parent_path().empty() ? fs::path(".") : p.parent_path();
        const std::string prefix = "." + p.filename().string() + ".tmp.";
        std::error_code ec;
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
            const std::string name = it->path().filename().string();
            if (name.compare(0, prefix.size(), prefix) != 0) continue;
            const size_t digits = name.find_first_not_of("0123456789", prefix.size());
            if (digits == prefix.size() || digits == std::string::npos || name[digits] != '.') continue;
            const long pid = std::stol(name.substr(prefix.size(), digits - prefix.size()));
            if (pid <= 0 || pid == long(getpid())) continue;
            if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // still running (or not ours to judge)
            std::error_code removeError;
            fs::remove_all(it->path(), removeError);
        }
    } catch (...) {
        // Best effort: a folder that cannot be listed leaves nothing to clean.
    }
}

} // namespace vdbdag
