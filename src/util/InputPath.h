// What an input path may be: an existing regular file. Devices, FIFOs,
// sockets and folders are refused before anything is read (`info /dev/zero`
// would read forever, a FIFO would block).
#pragma once
#include <string>

namespace vdbdag {

// What a file that is not a regular one is, for messages: "a directory",
// "a symbolic link", "a FIFO", "a socket", "a device" or "a special file"
// (`mode` as stat gives it).
const char* fileKindName(unsigned mode);

// Throws vdbdag::Error ("PATH: no such file", "PATH: is a FIFO, not WHAT", ...).
void checkInputFile(const std::string& path, const std::string& what);

} // namespace vdbdag
