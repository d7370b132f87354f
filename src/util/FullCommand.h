// The `vdbdag` command starts fast because it links neither VTK (export,
// diff) nor GDCM (DICOM input): those cost a third of its start-up. A call
// that needs one of them runs the same command line again in `vdbdag-full`,
// the same program with every library linked, installed beside it (as git
// runs its helpers). vdb_bridge/deferred/ holds the entry points that do so.
#pragma once
#include <string>

namespace vdbdag {

// The command line to run again (saved once, from main).
void rememberCommandLine(int argc, char** argv);

// Replaces this process with the helper `program` and the same arguments
// (looked for beside the running program, then in ../lib/vdbdag from it).
// Throws vdbdag::Error naming `feature` when it is not installed or cannot
// run. The helpers: `vdbdag-full` (every library linked), `vdbdag-selftest`
// (the self-test cases, which no product links: cli/deferred/).
[[noreturn]] void runHelperCommand(const std::string& program, const std::string& feature);
[[noreturn]] inline void runFullCommand(const std::string& feature) { runHelperCommand("vdbdag-full", feature); }

// The program `runHelperCommand` would run ("" when there is none).
std::string helperCommandPath(const std::string& program);
inline std::string fullCommandPath() { return helperCommandPath("vdbdag-full"); }

} // namespace vdbdag
