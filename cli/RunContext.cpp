// See RunContext.h. The message is formatted when the activity is set, into
// a fixed buffer, so that the new-handler needs no allocation.
#include "cli/RunContext.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <new>

#include <dlfcn.h>
#include <unistd.h>

#include "src/util/TemporaryFiles.h"

namespace vdbdag::cli {
namespace {

char g_message[4096] = "vdbdag: out of memory\n";
size_t g_length = std::strlen(g_message);

[[noreturn]] void onOutOfMemory() { endOutOfMemory(); }

// std::terminate (an exception escaping a thread or a destructor) ends with
// one line too, and without temporaries.
[[noreturn]] void onTerminate() {
    if (const std::exception_ptr current = std::current_exception()) {
        try {
            std::rethrow_exception(current);
        } catch (const std::bad_alloc&) {
            endOutOfMemory();
        } catch (const std::exception& e) {
            removeAllTemporaries();
            std::fprintf(stderr, "vdbdag: internal error: %s\n", e.what());
            ::_exit(1);
        } catch (...) {
        }
    }
    removeAllTemporaries();
    static const char kLine[] = "vdbdag: internal error: the program terminated\n";
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kLine, sizeof kLine - 1);
    ::_exit(1);
}

} // namespace

void endOutOfMemory() {
    // Several threads may run out at once: the first one speaks and ends the
    // process, the others wait for that.
    static std::atomic_flag ending = ATOMIC_FLAG_INIT;
    if (ending.test_and_set()) for (;;) ::pause();
    removeAllTemporaries();
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, g_message, g_length);
    ::_exit(1);
}

namespace {

std::string outOfMemoryMessageFor(const std::string& path, const std::string& activity) {
    return (path.empty() ? std::string() : path + ": ") + "out of memory while " + activity;
}

} // namespace

} // namespace vdbdag::cli

// Libraries that allocate with posix_memalign and do not check the result
// (Debian's c-blosc prints "Error allocating memory!" and goes on with a null
// buffer, a segmentation fault inside OpenVDB's reader) get the same ending
// as operator new: the executable's definition comes first in the symbol
// lookup, so every caller in the process reaches this one.
extern "C" int posix_memalign(void** out, size_t alignment, size_t size) {
    using Fn = int (*)(void**, size_t, size_t);
    static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "posix_memalign"));
    if (!real) return ENOMEM;
    const int result = real(out, alignment, size);
    if (result == ENOMEM) vdbdag::cli::endOutOfMemory();
    return result;
}

namespace vdbdag::cli {

namespace {
pipeline::CubeTeam* currentTeam = nullptr;
}

void setCubeTeam(pipeline::CubeTeam& team) { currentTeam = &team; }
pipeline::CubeTeam& cubeTeam() { return currentTeam ? *currentTeam : pipeline::soloTeam(); }

void setActivity(const std::string& path, const std::string& activity) {
    const std::string text = "vdbdag: " + outOfMemoryMessageFor(path, activity) + "\n";
    const size_t n = std::min(text.size(), sizeof g_message - 1);
    std::memcpy(g_message, text.data(), n);
    g_message[n - 1] = '\n';
    g_length = n;
}

std::string outOfMemoryMessage() { return std::string(g_message + 8, g_length > 9 ? g_length - 9 : 0); }

void installFailureHandlers() {
    std::set_new_handler(onOutOfMemory);
    std::set_terminate(onTerminate);
    installInterruptCleanup();
}

} // namespace vdbdag::cli
