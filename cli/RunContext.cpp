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
#include <signal.h>
#include <unistd.h>

#include "src/util/TemporaryFiles.h"

namespace vdbdag::cli {
namespace {

char g_message[4096] = "vdbdag: out of memory\n";
size_t g_length = std::strlen(g_message);
char g_crash[4096] = "vdbdag: crashed (a library failed on this input, which may be corrupted); nothing was written\n";
size_t g_crashLength = std::strlen(g_crash);
std::atomic_flag g_ending = ATOMIC_FLAG_INIT;
volatile sig_atomic_t g_failureExit = 1;

// A crash inside a library (OpenVDB's delayed loading segfaults or asserts
// on some corrupted files) ends like any bad input: one line, exit 1, and
// no temporary left. The first thread to crash speaks.
void onCrash(int) {
    if (g_ending.test_and_set()) for (;;) ::pause();
    removeAllTemporaries();
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, g_crash, g_crashLength);
    ::_exit(g_failureExit);
}

void installCrashHandlers() {
    static char altStack[64 * 1024];  // a stack overflow still gets its line
    stack_t ss{};
    ss.ss_sp = altStack;
    ss.ss_size = sizeof altStack;
    ::sigaltstack(&ss, nullptr);
    struct sigaction sa {};
    sa.sa_handler = onCrash;
    sa.sa_flags = SA_ONSTACK;
    sigemptyset(&sa.sa_mask);
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(sig, &sa, nullptr);
}

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
            ::_exit(g_failureExit);
        } catch (...) {
        }
    }
    removeAllTemporaries();
    static const char kLine[] = "vdbdag: internal error: the program terminated\n";
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kLine, sizeof kLine - 1);
    ::_exit(g_failureExit);
}

} // namespace

void setFailureExitCode(int code) { g_failureExit = code; }
int failureExitCode() { return g_failureExit; }

void endOutOfMemory() {
    // Several threads may run out at once: the first one speaks and ends the
    // process, the others wait for that.
    if (g_ending.test_and_set()) for (;;) ::pause();
    removeAllTemporaries();
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, g_message, g_length);
    ::_exit(g_failureExit);
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

// A failed assert() inside a library (Debian builds OpenVDB with them on)
// is a crash like the others, with its place in the message.
extern "C" [[noreturn]] void __assert_fail(const char* assertion, const char* file, unsigned line, const char* function) noexcept {
    (void)assertion;
    (void)function;
    char text[sizeof vdbdag::cli::g_crash + 256];
    size_t n = vdbdag::cli::g_crashLength;
    std::memcpy(text, vdbdag::cli::g_crash, n);
    if (n > 0 && text[n - 1] == '\n') --n;
    n += size_t(std::snprintf(text + n, sizeof text - n, " [internal check at %s:%u]\n", file, line));
    if (vdbdag::cli::g_ending.test_and_set()) for (;;) ::pause();
    vdbdag::removeAllTemporaries();
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, text, std::min(n, sizeof text - 1));
    ::_exit(vdbdag::cli::g_failureExit);
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
    const std::string crash = "vdbdag: " + (path.empty() ? std::string() : path + ": ") + "crashed while " + activity +
                              " (a library failed on this input, which may be corrupted); nothing was written\n";
    const size_t m = std::min(crash.size(), sizeof g_crash - 1);
    std::memcpy(g_crash, crash.data(), m);
    g_crash[m - 1] = '\n';
    g_crashLength = m;
}

std::string outOfMemoryMessage() { return std::string(g_message + 8, g_length > 9 ? g_length - 9 : 0); }

void installFailureHandlers() {
    std::set_new_handler(onOutOfMemory);
    std::set_terminate(onTerminate);
    installInterruptCleanup();
    installCrashHandlers();
}

} // namespace vdbdag::cli
