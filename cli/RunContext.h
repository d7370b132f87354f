// What the running command is doing, for the one message that cannot come
// from an exception: running out of memory. OpenVDB's and TBB's destructors
// may allocate while an earlier std::bad_alloc unwinds, which would end in
// std::terminate; so the new-handler itself removes the temporaries
// (TemporaryFiles.h), prints "vdbdag: PATH: out of memory while ACTIVITY"
// and ends the process with exit status 1.
//
// It also holds the processes the command runs on (CubeTeam.h): one, or
// those of an `mpirun` for vdbdag-mpi.
#pragma once
#include <string>

#include "src/pipeline/CubeTeam.h"

namespace vdbdag::cli {

void setCubeTeam(pipeline::CubeTeam& team);
pipeline::CubeTeam& cubeTeam();

// E.g. setActivity(opt->input, "encoding"); the first call of a command.
void setActivity(const std::string& path, const std::string& activity);

// The message for an out-of-memory ending ("PATH: out of memory while ...").
std::string outOfMemoryMessage();

// The exit status of a failure (bad input, out of memory, a crash): 1, but
// 2 for `diff`, whose 1 means "they differ" (as for diff and cmp).
void setFailureExitCode(int code);
int failureExitCode();

// Removes the temporaries, prints the out-of-memory line and ends the
// process (exit status failureExitCode()); async-signal-safe.
[[noreturn]] void endOutOfMemory();

// Installs the new-handler and the interrupt cleanup (once, from main).
void installFailureHandlers();

} // namespace vdbdag::cli
