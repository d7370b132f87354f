// Options every command takes, before or after its name (`vdbdag -q decode
// x.ssvdag -o x.vdb` or `vdbdag decode x.ssvdag -o x.vdb -q`):
//   -q, --quiet    no progress lines and no notes (errors and warnings stay)
//   -v, --verbose  a last line on stderr: the command's time and peak memory
//   --threads N    at most N worker threads (default: one per core)
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace vdbdag::cli {

// Adds them to the top-level app (call before the subcommands are added, so
// they inherit fallthrough).
void addGlobalOptions(CLI::App& app);

// "vdbdag: note: ..." on stderr, unless --quiet.
void note(const std::string& text);

// With --verbose: the line about the command that ran (`command` names it).
void reportVerbose(const std::string& command);

} // namespace vdbdag::cli
