// See RunContext.h. The message is formatted when the activity is set, into
// a fixed buffer, so that the new-handler needs no allocation.
#include "cli/RunContext.h"

#include <algorithm>
#include <cstring>
#include <new>

#include <unistd.h>

#include "src/util/TemporaryFiles.h"

namespace vdbdag::cli {
namespace {

char g_message[4096] = "vdbdag: out of memory\n";
size_t g_length = std::strlen(g_message);

[[noreturn]] void onOutOfMemory() {
    removeAllTemporaries();
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, g_message, g_length);
    ::_exit(1);
}

std::string outOfMemoryMessageFor(const std::string& path, const std::string& activity) {
    return (path.empty() ? std::string() : path + ": ") + "out of memory while " + activity;
}

} // namespace

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
    installInterruptCleanup();
}

} // namespace vdbdag::cli
